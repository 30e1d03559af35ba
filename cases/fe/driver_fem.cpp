// The run loop's pieces for the FE region (driver_common.hpp) that call the far field.
#include "driver_common.hpp"

#include <algorithm>

namespace smpm::detail {

double probe_field(const fem::Sample& s, const std::string& f) {
  if (f == "div") return s.div;
  if (f == "curl") return s.curl;
  ProbeSample p;
  p.sxx = s.sxx; p.syy = s.syy; p.szz = s.szz; p.sxy = s.sxy; p.j2 = s.j2; p.vx = s.vx; p.vy = s.vy;
  return probe_field(p, f);
}

nlohmann::ordered_json fem_json(const fem::Solver& s) {
  return nlohmann::ordered_json{{"nodes", s.nodes()},
                                {"cells", s.cells()},
                                {"degree", s.degree()},
                                {"critical_dt", s.critical_dt()},
                                {"dashpot_nodes", s.dashpot_count()}};
}

nlohmann::ordered_json fem_traffic_json(const fem::Solver& s) {
  const fem::Solver::Traffic t = s.traffic();
  const double steps = static_cast<double>(std::max<long>(1, t.updates));
  return {{"ghost_update_seconds_per_step", t.seconds / steps},
          {"ghost_bytes_per_step", t.bytes / steps},
          {"neighbours_most", t.neighbours},
          {"own_nodes_most", t.own_nodes},
          {"ghost_nodes_most", t.ghost_nodes},
          {"held_nodes_most", t.held_nodes}};
}

}  // namespace smpm::detail
