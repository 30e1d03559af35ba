// The far-field module's entry point (libsilentmpm_fe.so; cases/src/modules.hpp): the table of
// what the core calls in it.
#include <cmath>
#include <cstdio>

#include "case_fem.hpp"
#include "modules.hpp"

namespace smpm::detail {

namespace {

std::string fem_check_line(const Case& c) {
  const fem::Solver& f = *c.fem;
  char line[320];
  std::snprintf(line, sizeof line,
                "FEM: %zu cells, Q%d, %zu dofs, dt %g s (CFL %.3f of the element bound), %ld steps, "
                "%zu probe(s)",
                f.cells(), f.degree(), f.dofs(), f.dt, f.dt / f.critical_dt(),
                static_cast<long>(std::ceil(c.t_end / f.dt - 1e-9)), c.probes.size());
  return line;
}

}  // namespace

}  // namespace smpm::detail

extern "C" const smpm::detail::FarFieldModule* silentmpm_fe_module() {
  using namespace smpm::detail;
  static const FarFieldModule table{kFarFieldModuleApi, &build_fem_case, &build_hybrid_case,
                                    &fem_region, &hybrid_region, &fem_check_line};
  return &table;
}
