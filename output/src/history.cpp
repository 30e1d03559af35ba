// Reading history.csv back and the one waveform metric that studies and tests share.
#include "silentmpm/history.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace smpm {

namespace {

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n";
  const auto b = s.find_first_not_of(ws);
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(ws);
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos
                                                                      : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

// Parses the whole field as a double ("nan" and "inf" included, as printf writes them).
bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

}  // namespace

const std::vector<double>& History::column(const std::string& name) const {
  if (name == "time") return time;
  for (std::size_t c = 0; c < columns.size(); ++c)
    if (columns[c] == name) return data[c];
  std::string have;
  for (const auto& c : columns) have += (have.empty() ? "" : ", ") + c;
  throw std::runtime_error((path.empty() ? std::string("history") : path) + ": no column '" + name +
                           "' (columns: " + have + ")");
}

History read_history(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open history file '" + path + "'");
  History h;
  h.path = path;
  std::string line;
  long lineno = 0;
  bool have_header = false;
  std::size_t nfields = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) continue;
    const auto fields = split(line);
    const std::string where = path + ":" + std::to_string(lineno) + ": ";
    if (!have_header) {
      if (fields[0] != "time")
        throw std::runtime_error(where + "header must start with 'time', found '" + fields[0] +
                                 "'");
      for (std::size_t k = 1; k < fields.size(); ++k) {
        if (fields[k].empty()) throw std::runtime_error(where + "empty column name in header");
        for (std::size_t j = 1; j < k; ++j)
          if (fields[j] == fields[k])
            throw std::runtime_error(where + "duplicate column '" + fields[k] + "' in header");
      }
      h.columns.assign(fields.begin() + 1, fields.end());
      h.data.assign(h.columns.size(), {});
      nfields = fields.size();
      have_header = true;
      continue;
    }
    if (fields.size() != nfields)
      throw std::runtime_error(where + "expected " + std::to_string(nfields) + " fields, found " +
                               std::to_string(fields.size()));
    for (std::size_t k = 0; k < nfields; ++k) {
      double v;
      if (!parse_double(fields[k], v))
        throw std::runtime_error(where + "cannot read '" + fields[k] + "' as a number (column '" +
                                 (k == 0 ? std::string("time") : h.columns[k - 1]) + "')");
      if (k == 0)
        h.time.push_back(v);
      else
        h.data[k - 1].push_back(v);
    }
  }
  if (in.bad()) throw std::runtime_error("error reading history file '" + path + "'");
  if (!have_header) throw std::runtime_error(path + ": empty history file (no header line)");
  return h;
}

namespace {

// Sum over a's rows with t in [t0, t1] inside b's span of (a - b)^2 and b^2, b interpolated.
struct Sums {
  double diff2 = 0, ref2 = 0;
  std::size_t n = 0;
};

Sums sums(const History& a, const History& b, const std::vector<double>& ya,
          const std::vector<double>& yb, double t0, double t1) {
  const std::vector<double>& tb = b.time;
  const double lo = std::max(t0, tb.front()), hi = std::min(t1, tb.back());
  Sums s;
  std::size_t j = 0;  // segment [tb[j], tb[j+1]] of b; a's times are usually sorted
  for (std::size_t i = 0; i < a.time.size(); ++i) {
    const double t = a.time[i];
    if (!(t >= lo && t <= hi)) continue;
    if (j >= tb.size() || tb[j] > t) j = 0;
    while (j + 1 < tb.size() && tb[j + 1] < t) ++j;
    double vb;
    if (j + 1 >= tb.size()) {
      vb = yb[j];
    } else {
      const double dt = tb[j + 1] - tb[j];
      const double w = dt > 0.0 ? (t - tb[j]) / dt : 0.0;
      vb = (1.0 - w) * yb[j] + w * yb[j + 1];
    }
    const double d = ya[i] - vb;
    s.diff2 += d * d;
    s.ref2 += vb * vb;
    ++s.n;
  }
  return s;
}

std::string name_of(const History& h) { return h.path.empty() ? std::string("history") : h.path; }

}  // namespace

Difference difference(const History& a, const History& b, const std::string& col, double t0,
                      double t1, double n0, double n1) {
  const std::vector<double>& ya = a.column(col);
  const std::vector<double>& yb = b.column(col);
  const std::vector<double>& tb = b.time;
  if (ya.size() != a.time.size() || yb.size() != tb.size())
    throw std::runtime_error("column '" + col + "' and time have different lengths");
  if (tb.empty()) throw std::runtime_error(name_of(b) + ": the reference history has no rows");
  for (std::size_t k = 1; k < tb.size(); ++k)
    if (!(tb[k] >= tb[k - 1]))
      throw std::runtime_error(name_of(b) + ": the reference history's times are not increasing");
  auto none = [&](const char* what, double w0, double w1) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "' of %s in the %s [%g, %g] within the reference's span [%g, %g]",
                  name_of(a).c_str(), what, w0, w1, tb.front(), tb.back());
    return std::runtime_error("no samples of column '" + col + buf);
  };
  const Sums d = sums(a, b, ya, yb, t0, t1);
  if (d.n == 0) throw none("window", t0, t1);
  const Sums r = n0 == t0 && n1 == t1 ? d : sums(a, b, ya, yb, n0, n1);
  if (r.n == 0) throw none("norm window", n0, n1);
  if (!(r.ref2 > 0.0))
    throw std::runtime_error(name_of(b) + ": column '" + col +
                             "' is zero over the norm window, the relative error is undefined");
  Difference out;
  out.absolute = std::sqrt(d.diff2);
  out.reference = std::sqrt(r.ref2);
  out.relative = std::sqrt(d.diff2 / r.ref2);
  out.samples = d.n;
  out.norm_samples = r.n;
  return out;
}

double relative_l2(const History& a, const History& b, const std::string& col, double t0,
                   double t1) {
  return difference(a, b, col, t0, t1, t0, t1).relative;
}

}  // namespace smpm
