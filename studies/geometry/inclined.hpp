#pragma once
// Extended-domain differencing for a plane P pulse meeting an inclined edge (studies/geometry,
// tests/physics/test_geometry_silent.cpp). Shared by the test and the study program.
//
// Run A: the aluminium plate of meshes/inclined_edge.geo (right edge with outward normal at
// theta from +x: silent, or free with a = b = 0), loaded on its left edge by a sin^2 pulse of
// normal traction, rollers (v_y = 0) on the bottom and top grid lines so the incident wave is
// plane (uniaxial strain). Run B: the same plate extended far to the right (a box), nothing
// returns from its end within the window. Same grid, same particle lattice where A has
// particles, identical dt. The difference D = u_A - u_B of the particle displacements on the
// particle lattice is the reflected field; div D and curl D by central differences on the
// lattice (spacing h/n), sampled every step at the receivers: particles between depth0 and
// depth1 cells inside the edge, within half_span cells of its mid-height point along it.
//   |R_PP| = max|div D| / max|div u_B|,   |R_PS| = (c_s / c_d) max|curl D| / max|div u_B|
// (docs/physics.md §4.1), the maxima over the receivers and the window. The window ends before any
// signal from the plate's corners can reach the receivers (checked; an error otherwise).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "silentmpm/lk_reflection.hpp"
#include "silentmpm/solver.hpp"

namespace smpm::inclined {

using nlohmann::json;

struct InclinedSpec {
  double theta_deg = 30;
  double h = 1e-3;          // cell
  int ppc = 1;
  double fwhm = 16;         // pulse full width at half maximum, cells
  double height_factor = 4; // plate height at least height_factor x pulse length (see below)
  double cfl = 0.5;
  double depth0 = 3, depth1 = 8;   // receiver band: distance from the edge, cells
  double half_span = 8;     // receiver band: half length along the edge, cells
  int threads = 0;
  double a = 1, b = 1;      // LK coefficients (0, 0: a free edge)
  std::string form, anchor; // silent layer options (empty: the defaults)
  std::string edge_velocity;  // MUSL: "updated" or "remapped" (empty: the default)
  double width = 0;         // silent layer depth, cells (0: the default, one cell)
  // Measure div/curl of the displacement (docs/physics.md §4.1: R are displacement-amplitude
  // ratios) or, if false, of the velocity (weights the high frequencies one order more).
  bool displacement = true;
};

struct InclinedResult {
  double rpp = 0, rps = 0;            // measured |R_PP|, |R_PS|
  double rpp_exact = 0, rps_exact = 0;
  double incident = 0;                // max |div v| of the incident wave in the band
  long particles_a = 0, particles_b = 0, steps = 0;
  double wall_seconds = 0;            // both runs and the measurement
  int receivers = 0;
};

inline json inclined_case(const std::string& source_dir, const InclinedSpec& s, bool extended, double xb, double H, double xmax,
                   double dt, double t_end) {
  const double c = s.h, h = s.h;
  const double duration = 2 * s.fwhm * c / std::sqrt((70e9 * (1 - 0.33) / ((1 + 0.33) * (1 - 2 * 0.33))) / 2700);
  json j = {
      {"grid", {{"origin", {-2 * c, 0.0}}, {"size", {xmax + 4 * c, H}}, {"cell", c}}},
      {"time", {{"end", t_end}, {"dt", dt}}},
      {"scheme", {{"threads", s.threads}}},
      {"materials",
       {{"aluminium", {{"model", "elastic"}, {"young", 70e9}, {"poisson", 0.33}, {"density", 2700}}}}},
      {"output", {{"snapshots", 0}, {"progress", false}}},
  };
  json pulse = {{"type", "traction"}, {"body", "plate"}, {"normal", -1e6},
                {"time", {{"shape", "sin2"}, {"duration", duration}, {"ramp", duration / 2}}}};
  json rollers = json::array({{{"type", "roller"}, {"component", "y"}, {"grid_side", "bottom"}},
                              {{"type", "roller"}, {"component", "y"}, {"grid_side", "top"}}});
  if (extended) {
    j["bodies"] = {{{"name", "plate"}, {"material", "aluminium"}, {"box", {0.0, 0.0, xmax, H}},
                    {"particles_per_cell", s.ppc}}};
    pulse["side"] = "left";
    j["boundaries"] = rollers;
    j["boundaries"].push_back(pulse);
  } else {
    j["geometry"] = {{"file", source_dir + "/meshes/inclined_edge.geo"},
                     {"size", 2 * c},
                     {"parameters", {{"theta", s.theta_deg}, {"H", H}, {"xb", xb}}}};
    j["bodies"] = {{{"name", "plate"}, {"material", "aluminium"}, {"surface", 1},
                    {"particles_per_cell", s.ppc}}};
    pulse["curve"] = 11;
    j["boundaries"] = rollers;
    j["boundaries"].push_back(pulse);
    json silent = {{"type", "silent"}, {"body", "plate"}, {"curve", 12}, {"a", s.a}, {"b", s.b}};
    if (!s.form.empty()) silent["form"] = s.form;
    if (!s.anchor.empty()) silent["anchor"] = s.anchor;
    if (!s.edge_velocity.empty()) silent["edge_velocity"] = s.edge_velocity;
    if (s.width > 0) silent["width"] = s.width * h;
    j["boundaries"].push_back(silent);
  }
  return j;
}

inline InclinedResult measure_inclined(const std::string& source_dir, const InclinedSpec& s) {
  const auto clock0 = std::chrono::steady_clock::now();
  const double th = s.theta_deg * M_PI / 180, cth = std::cos(th), sth = std::sin(th);
  const double h = s.h;
  const double E = 70e9, nu = 0.33, rho = 2700;
  const double cd = std::sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho);
  const double cs = std::sqrt(E / (2 * (1 + nu)) / rho);
  const double support = 2 * s.fwhm * h;  // spatial length of the pulse
  // Plate height H and the edge position xb: the receivers sit at mid-height; H is the smallest
  // (in steps of 10 cells, at least height_factor pulse lengths) for which no signal from the
  // plate's corners reaches the receivers before the window ends. Window: until the reflected
  // SV pulse has left the deepest receivers (+10 cells); corner signals travel at most c_d.
  const double dt = s.cfl * h / cd;
  double H = std::ceil(s.height_factor * support / h) * h, xb = 0, xm = 0, t_end = 0;
  for (int iter = 0;; ++iter, H += 10 * h) {
    xb = std::ceil((H * std::tan(th) + support + 10 * h) / h) * h;
    xm = xb - 0.5 * H * std::tan(th);  // edge point at mid-height
    const double t_ref = (xm + s.half_span * h * sth) / cd;  // incident at the band's far end
    t_end = t_ref + support / cd + (s.depth1 * h / std::cos(std::asin(cs / cd * sth))) / cs +
            (s.depth1 * h) / cd + 10 * h / cd;
    const double t_corner =
        (xb - H * std::tan(th)) / cd + (0.5 * H / std::cos(th) - s.half_span * h) / cd;
    if (t_end < t_corner) break;
    if (iter > 10000) throw std::runtime_error("inclined: no plate height gives a clean window");
  }
  const double ym = 0.5 * H;
  const double xmax = std::ceil((xb + 1.5 * support + 20 * h) / h) * h;  // extended plate

  smpm::Case A = smpm::build_case(inclined_case(source_dir, s, false, xb, H, xmax, dt, t_end), "inclined_A");
  smpm::Case B = smpm::build_case(inclined_case(source_dir, s, true, xb, H, xmax, dt, t_end), "inclined_B");
  smpm::Solver& a = *A.solver;
  smpm::Solver& b = *B.solver;

  // Lattice of particle positions (n per cell side), on the grid of both runs.
  const int n = s.ppc == 1 ? 1 : s.ppc == 4 ? 2 : 3;
  const double sp = h / n;
  const double gx0 = a.grid.x0, gy0 = a.grid.y0;
  const long NI = static_cast<long>(std::lround((xmax + 4 * h) / sp)), NJ = static_cast<long>(std::lround(H / sp));
  auto lattice = [&](const smpm::Solver& sol, std::vector<long>& cell_of_id) {
    cell_of_id.assign(sol.p.size(), -1);
    for (std::size_t k = 0; k < sol.p.size(); ++k) {
      const long i = std::lround((sol.p.x[k] - gx0) / sp - 0.5), j = std::lround((sol.p.y[k] - gy0) / sp - 0.5);
      cell_of_id[sol.p.id[k]] = j * NI + i;
    }
  };
  std::vector<long> cell_a, cell_b;
  lattice(a, cell_a);
  lattice(b, cell_b);
  std::vector<char> in_a(NI * NJ, 0);
  for (long c : cell_a) in_a[c] = 1;
  // Receivers: lattice points of A at distance [depth0, depth1] from the edge, within half_span
  // of mid-height along it, with their four neighbours in A.
  std::vector<long> rec;
  for (long j = 1; j + 1 < NJ; ++j)
    for (long i = 1; i + 1 < NI; ++i) {
      const long c = j * NI + i;
      if (!in_a[c] || !in_a[c - 1] || !in_a[c + 1] || !in_a[c - NI] || !in_a[c + NI]) continue;
      const double x = gx0 + (i + 0.5) * sp, y = gy0 + (j + 0.5) * sp;
      const double dist = (xm - x) * cth + (ym - y) * sth;  // depth below the edge
      const double along = -(x - xm) * sth + (y - ym) * cth;
      if (dist >= s.depth0 * h && dist <= s.depth1 * h && std::fabs(along) <= s.half_span * h)
        rec.push_back(c);
    }
  if (rec.size() < 10) throw std::runtime_error("inclined: fewer than 10 receivers");

  std::vector<double> va_x(NI * NJ), va_y(NI * NJ), vb_x(NI * NJ), vb_y(NI * NJ);
  auto fill = [&](const smpm::Solver& sol, const std::vector<long>& cell, std::vector<double>& vx,
                  std::vector<double>& vy) {
    for (std::size_t k = 0; k < sol.p.size(); ++k) {
      const long c = cell[sol.p.id[k]];
      if (s.displacement) {  // u = x - X, X the particle's lattice point
        vx[c] = sol.p.x[k] - (gx0 + (c % NI + 0.5) * sp);
        vy[c] = sol.p.y[k] - (gy0 + (c / NI + 0.5) * sp);
      } else {
        vx[c] = sol.p.vx[k];
        vy[c] = sol.p.vy[k];
      }
    }
  };
  double max_div_b = 0, max_div_d = 0, max_curl_d = 0;
  while (a.t < t_end - 0.5 * dt) {
    a.step();
    b.step();
    fill(a, cell_a, va_x, va_y);
    fill(b, cell_b, vb_x, vb_y);
    for (long c : rec) {
      auto dx = [&](const std::vector<double>& f) { return (f[c + 1] - f[c - 1]) / (2 * sp); };
      auto dy = [&](const std::vector<double>& f) { return (f[c + NI] - f[c - NI]) / (2 * sp); };
      const double div_b = dx(vb_x) + dy(vb_y);
      const double div_d = dx(va_x) - dx(vb_x) + dy(va_y) - dy(vb_y);
      const double curl_d = dx(va_y) - dx(vb_y) - (dy(va_x) - dy(vb_x));
      max_div_b = std::max(max_div_b, std::fabs(div_b));
      max_div_d = std::max(max_div_d, std::fabs(div_d));
      max_curl_d = std::max(max_curl_d, std::fabs(curl_d));
    }
  }
  InclinedResult r;
  r.incident = max_div_b;
  r.rpp = max_div_d / max_div_b;
  r.rps = (cs / cd) * max_curl_d / max_div_b;
  const smpm::LKReflection ex = smpm::lk_reflection(nu, s.a, s.b, th);
  r.rpp_exact = std::abs(ex.rpp);
  r.rps_exact = std::abs(ex.rps);
  r.particles_a = static_cast<long>(a.p.size());
  r.particles_b = static_cast<long>(b.p.size());
  r.steps = a.steps;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock0).count();
  r.receivers = static_cast<int>(rec.size());
  return r;
}

}  // namespace smpm::inclined
