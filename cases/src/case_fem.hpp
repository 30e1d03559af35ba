#pragma once
// Internal: the FEM and hybrid sides of case files (case_fem.cpp, case_hybrid.cpp) and the
// section parsers case.cpp shares with them.
#include <nlohmann/json.hpp>
#include <string>

#include "silentmpm/case.hpp"

namespace smpm::detail {

// Defined in case.cpp: the same parsers (and messages) the MPM sections use.
Material parse_material_at(const std::string& source, const std::string& name,
                           const nlohmann::ordered_json& j);
TimeFunction parse_time_function_at(const std::string& source, const nlohmann::ordered_json& j,
                                    const std::string& path);

// Defined in case_fem.cpp: builds a case whose top level has "fem" (an FEM region).
Case build_fem_case(const std::string& source, const nlohmann::ordered_json& doc);

// Hybrid cases (both "bodies" and "fem"): case_hybrid.cpp.
Case build_mpm_case(const std::string& source, const nlohmann::ordered_json& doc);  // case.cpp
Case build_hybrid_case(const std::string& source, const nlohmann::ordered_json& doc);

}  // namespace smpm::detail
