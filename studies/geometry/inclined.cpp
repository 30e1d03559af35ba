// The 30-degree silent edge of studies/geometry: |R_PP| and |R_PS| measured by extended-domain
// differencing (inclined.hpp) against the closed form, for a free edge and for the silent edge.
//   geometry_inclined SOURCE_DIR OUT.csv [widths|depths|variants]
//     widths    (default) free edge, grid-aligned edge, silent edge at FWHM 8/12/16/24 cells,
//               measured on displacements (docs/physics.md §4.1) and, for comparison, on velocities
//     depths    FWHM 16: receivers from 3-6 to 16-22 cells inside the edge
//     variants  FWHM 16: the silent layer's form and anchor; LK coefficients a = b = 0.5 and 2
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "inclined.hpp"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s SOURCE_DIR OUT.csv [widths|depths|variants]\n", argv[0]);
    return 2;
  }
  const std::string mode = argc > 3 ? argv[3] : "widths";
  struct Run {
    double theta, ab, fwhm, d0, d1;
    bool displacement;
    std::string form, anchor;
  };
  std::vector<Run> runs;
  if (mode == "widths") {
    runs = {{30, 0, 16, 8, 12, true, "", ""}, {0, 1, 16, 8, 12, true, "", ""}};
    for (double w : {8.0, 12.0, 16.0, 24.0}) runs.push_back({30, 1, w, 8, 12, true, "", ""});
    for (double w : {8.0, 16.0}) runs.push_back({30, 1, w, 8, 12, false, "", ""});
  } else if (mode == "depths") {
    for (auto d : {std::pair{3.0, 6.0}, {5.0, 8.0}, {10.0, 16.0}, {16.0, 22.0}})
      runs.push_back({30, 1, 16, d.first, d.second, true, "", ""});
  } else if (mode == "variants") {
    runs = {{30, 1, 16, 8, 12, true, "nodal", "particle"}, {30, 1, 16, 8, 12, true, "particle", "particle"},
            {30, 0.5, 16, 8, 12, true, "", ""}, {30, 2, 16, 8, 12, true, "", ""}};
  } else {
    std::fprintf(stderr, "%s: unknown mode '%s' (widths, depths or variants)\n", argv[0], mode.c_str());
    return 2;
  }
  std::FILE* f = std::fopen(argv[2], "w");
  if (!f) {
    std::fprintf(stderr, "cannot write %s\n", argv[2]);
    return 1;
  }
  std::fprintf(f, "theta_deg,a,b,ppc,fwhm_cells,depth0_cells,depth1_cells,measure,form,anchor,rpp,rpp_exact,rps,"
                  "rps_exact,particles_a,particles_b,steps,receivers,wall_seconds\n");
  try {
    for (const Run& r : runs) {
      smpm::inclined::InclinedSpec s;
      s.theta_deg = r.theta;
      s.a = s.b = r.ab;
      s.ppc = 4;
      s.fwhm = r.fwhm;
      s.form = r.form;
      s.anchor = r.anchor;
      s.depth0 = r.d0;
      s.depth1 = r.d1;
      s.displacement = r.displacement;
      const auto m = smpm::inclined::measure_inclined(argv[1], s);
      const char* measure = s.displacement ? "displacement" : "velocity";
      const char* form = s.form.empty() ? "nodal" : s.form.c_str();
      const char* anchor = s.anchor.empty() ? "default" : s.anchor.c_str();
      std::printf("theta %2.0f  a=b=%g  %s, form %s anchor %s  FWHM %4.0f cells, receivers %g-%g cells: |R_PP| %.4f "
                  "(closed form %.4f)  |R_PS| %.4f (closed form %.4f)  %ld+%ld particles, %.0f s\n",
                  s.theta_deg, s.a, measure, form, anchor, s.fwhm, s.depth0, s.depth1, m.rpp, m.rpp_exact, m.rps,
                  m.rps_exact, m.particles_a, m.particles_b, m.wall_seconds);
      std::fflush(stdout);
      std::fprintf(f, "%g,%g,%g,%d,%g,%g,%g,%s,%s,%s,%.6g,%.6g,%.6g,%.6g,%ld,%ld,%ld,%d,%.3f\n", s.theta_deg, s.a,
                   s.b, s.ppc, s.fwhm, s.depth0, s.depth1, measure, form, anchor, m.rpp, m.rpp_exact, m.rps,
                   m.rps_exact, m.particles_a, m.particles_b, m.steps, m.receivers, m.wall_seconds);
      std::fflush(f);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "geometry_inclined: %s\n", e.what());
    std::fclose(f);
    std::remove(argv[2]);
    return 1;
  }
  std::fclose(f);
  return 0;
}
