// scripts/plot.py, the plot helper for one's own runs: it draws the columns asked for, and every
// mistake (a run that is not there, a column no run has) is one line naming the file, exit 1,
// and no figure written.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_common.hpp"

namespace {

namespace fs = std::filesystem;
using namespace smpm::case_testing;
using namespace smpm::cli_testing;

Proc plot(const std::string& args, const std::string& tag) {
  return run_shell("/usr/bin/python3 \"" + source_file("scripts/plot.py") + "\" " + args,
                   "plot_" + tag);
}

bool have_matplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

// A run folder with a history.csv of a sine in A.syy and summary.json with a title.
fs::path make_run(const std::string& name) {
  const fs::path dir = scratch() / name;
  fs::create_directories(dir);
  std::ofstream h(dir / "history.csv");
  h << "time,A.syy,A.vy\n";
  for (int i = 0; i <= 100; ++i)
    h << i * 1e-7 << ',' << -1e8 * std::sin(0.1 * i) << ',' << 0.5 * i << '\n';
  std::ofstream(dir / "summary.json") << R"({"title": "a sine"})";
  return dir;
}

// Width and height from a PNG's IHDR chunk (0 when the file is not a PNG).
std::pair<std::uint32_t, std::uint32_t> png_size(const fs::path& p) {
  const std::string s = read_file(p);
  if (s.size() < 24 || s.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || s.compare(12, 4, "IHDR") != 0)
    return {0, 0};
  auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(s[at + k]);
    return v;
  };
  return {be32(16), be32(20)};
}

TEST(PlotHelper, DrawsOnePanelPerColumn) {
  if (!have_matplotlib()) GTEST_SKIP() << "no matplotlib under /usr/bin/python3";
  const fs::path run = make_run("plot_run");
  const fs::path one = scratch() / "plot_one.png", two = scratch() / "plot_two.png";
  const Proc a = plot("\"" + run.string() + "\" -c A.syy -o \"" + one.string() + "\"", "one");
  ASSERT_EQ(a.status, 0) << a.err;
  const Proc b = plot("\"" + (run / "history.csv").string() + "\" -c 'A.*' -o \"" + two.string() + "\"",
                      "two");
  ASSERT_EQ(b.status, 0) << b.err;
  const auto s1 = png_size(one), s2 = png_size(two);
  ASSERT_GT(s1.first, 0u) << "not a PNG: " << one;
  ASSERT_GT(s2.first, 0u) << "not a PNG: " << two;
  // Two panels (A.syy, A.vy) stack to about 2.6 + 2.6 + 0.8 inches against 2.6 + 0.8.
  EXPECT_NEAR(static_cast<double>(s2.second) / s1.second, 6.0 / 3.4, 0.25)
      << s1.second << " and " << s2.second << " pixels high";
}

TEST(PlotHelper, MistakesAreOneLineNamingTheFile) {
  if (!have_matplotlib()) GTEST_SKIP() << "no matplotlib under /usr/bin/python3";
  const fs::path run = make_run("plot_run_bad");
  const fs::path png = scratch() / "plot_bad.png";
  const Proc c = plot("\"" + run.string() + "\" -c B.sxx -o \"" + png.string() + "\"", "bad_column");
  EXPECT_EQ(c.status, 1);
  EXPECT_NE(c.err.find((run / "history.csv").string() + ": no column matches \"B.sxx\"; columns: "
                       "A.syy, A.vy"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(png));
  const Proc m = plot("\"" + (scratch() / "no_such_run").string() + "\" -c A.syy -o \"" +
                          png.string() + "\"", "missing");
  EXPECT_EQ(m.status, 1);
  EXPECT_NE(m.err.find((scratch() / "no_such_run").string() + ": no such file"), std::string::npos)
      << m.err;
  EXPECT_EQ(std::count(m.err.begin(), m.err.end(), '\n'), 1) << m.err;
  EXPECT_FALSE(fs::exists(png));
}

}  // namespace
