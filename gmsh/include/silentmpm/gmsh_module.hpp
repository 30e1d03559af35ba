#pragma once
// The gmsh module's table (libsilentmpm_gmsh.so; the loader is cases/src/modules.cpp): the
// functions of the module the rest of the program calls. A process loads the module, and gmsh
// with it, only when a case reads a geometry or an FE mesh.
#include <string>
#include <utility>
#include <vector>

#include "silentmpm/geometry.hpp"

namespace smpm {

// Bumped whenever the table or a signature in it changes: a module built from other sources is
// refused rather than called.
inline constexpr int kGmshModuleApi = 1;

struct GmshModule {
  int api;
  Geometry (*load_geometry)(const std::string& file, double size,
                            const std::vector<std::pair<std::string, double>>& parameters,
                            double max_cells);
  Geometry (*load_geometry_groups)(const std::string& file, double size,
                                   const std::vector<std::pair<std::string, double>>& parameters);
};

}  // namespace smpm

extern "C" const smpm::GmshModule* silentmpm_gmsh_module();  // gmsh/src/geometry_load.cpp
