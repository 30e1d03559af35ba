#pragma once
// Reading history.csv files back and comparing waveforms (used by studies and tests, so the
// metric has one implementation).
#include <string>
#include <vector>

namespace smpm {

struct History {
  std::string path;                          // the file it was read from (for messages)
  std::vector<std::string> columns;          // without "time"
  std::vector<double> time;
  std::vector<std::vector<double>> data;     // data[column][row]
  const std::vector<double>& column(const std::string& name) const;  // throws if missing
};

History read_history(const std::string& path);

// Relative L2 difference ||a - b|| / ||b|| of column `col` over t in [t0, t1], with b
// interpolated linearly onto a's time samples.
double relative_l2(const History& a, const History& b, const std::string& col, double t0,
                   double t1);

// The same with the norm of the reference taken over its own window [n0, n1] (a's samples there,
// b interpolated onto them): ||a - b||_[t0, t1] / ||b||_[n0, n1]. Samples are a's rows inside the
// window and inside b's time span (b is interpolated linearly, never extrapolated).
struct Difference {
  double relative = 0;   // ||a - b|| / ||b||
  double absolute = 0;   // ||a - b|| (root of the sum of squares over the samples)
  double reference = 0;  // ||b|| over the norm's window
  std::size_t samples = 0, norm_samples = 0;
};
Difference difference(const History& a, const History& b, const std::string& col, double t0,
                      double t1, double n0, double n1);

}  // namespace smpm
