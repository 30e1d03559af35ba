#pragma once
// Internal: the FEM and hybrid sides of case files (cases/fe/case_fem.cpp and case_hybrid.cpp,
// in the far-field module) and the section parsers case.cpp shares with them.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "case_keys.hpp"
#include "silentmpm/case.hpp"

namespace smpm::detail {

// Defined in case.cpp: the same parsers (and messages) the MPM sections use.
Material parse_material_at(const Ctx& ctx, const std::string& name, const ojson& j);
TimeFunction parse_time_function_at(const Ctx& ctx, const ojson& j, const std::string& path);

// Defined in case_fem.cpp: builds a case whose top level has "fem" (an FEM region).
Case build_fem_case(const Ctx& ctx, const ojson& doc, bool scatter = false, bool skeleton = false);
// The "fields" of an FEM probe (an FEM case's, or a hybrid's probe in the FEM region): the
// names listed, or `all` when the key is absent.
std::vector<std::string> fem_probe_fields(Obj& o, const std::vector<std::string>& all);

// Hybrid cases (both "bodies" and "fem"): case_hybrid.cpp.
Case build_mpm_case(const Ctx& ctx, const ojson& doc);  // case.cpp
// Reads every key of an MPM document without meshing its geometry or seeding particles (case.cpp).
void check_mpm_case(const Ctx& ctx, const ojson& doc);
Case build_hybrid_case(const Ctx& ctx, const ojson& doc);

}  // namespace smpm::detail
