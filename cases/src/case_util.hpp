#pragma once
// Internal: small formatting helpers shared by the case parsers (case.cpp, case_fem.cpp,
// case_hybrid.cpp) and their key walker (case_keys.hpp), so that every section prints numbers,
// lists and types the same way.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace smpm::detail {

// Shortest form that reads back as v (so a value the user typed prints as typed), else 6 digits.
inline std::string fmt(double v) {
  char b[40];
  // Whole digits of a number below 10^4 are all printed (10, not 1e+01).
  int p0 = 1;
  for (double a = std::fabs(v); a >= 10 && a < 1e4; a /= 10) ++p0;
  for (int p = p0; p <= 12; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, v);
    if (std::strtod(b, nullptr) == v) return b;
  }
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

// 6 significant digits, rounded towards zero (a limit the user can copy without exceeding it,
// e.g. a dt that is safe to paste back).
inline std::string fmt_down(double v) {
  if (!(v > 0) || !std::isfinite(v)) return fmt(v);
  const double scale = std::pow(10.0, 5 - std::floor(std::log10(v)));
  return fmt(std::floor(v * scale + 1e-9) / scale);
}

// A run takes ceil(time.end / dt) steps; beyond kMaxSteps it is refused (a typo in time.end or
// time.dt, and a count that would overflow the step counter). Empty when the count is fine.
constexpr double kMaxSteps = 1e10;
inline std::string step_count_error(double t_end, double dt) {
  const double n = std::ceil(t_end / dt - 1e-9);
  if (n <= kMaxSteps) return {};
  char b[160];
  std::snprintf(b, sizeof b, "time.end / dt = %.6g s / %.6g s is %.3g steps; at most %.0e are supported",
                t_end, dt, n, kMaxSteps);
  return b;
}

inline std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

// "\"a\", \"b\"" for the options of a choice.
inline std::string quoted_list(const std::vector<std::string>& v) {
  std::vector<std::string> q;
  for (const auto& s : v) q.push_back("\"" + s + "\"");
  return join(q);
}

// Edits between a and b (letters compared case-insensitively).
inline std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// " (did you mean \"poisson\"?)" when a candidate is close to `word`, else "".
inline std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  if (word.size() > 64) return "";  // no name is that long; and the search stays bounded
  std::string best;
  std::size_t best_d = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_d) best_d = d, best = c;
  }
  return best.empty() ? "" : " (did you mean \"" + best + "\"?)";
}

// "a string", "an array", ... for messages like "expected a number, got a string".
inline std::string a_type(const nlohmann::ordered_json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return "a boolean";
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return "an unsupported value";
}

// "path[i]"
inline std::string index_path(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

}  // namespace smpm::detail
