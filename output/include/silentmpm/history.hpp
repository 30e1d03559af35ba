#pragma once
// Reading history.csv files back and comparing waveforms (used by studies and tests, so the
// metric has one implementation).
#include <string>
#include <vector>

namespace smpm {

struct History {
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

}  // namespace smpm
