#pragma once
// One gmsh session: the gmsh API is one global state per process, shared by the FE meshes
// (fem/src/fem_mesh.cpp) and the MPM geometries (geometry/src/geometry.cpp). This folder sits
// below both: fem/ and geometry/ are side by side on mpm/ and neither may include the other, and
// the session needs nothing of the project, so it is its own target under both of them.
//
// A session holds the process-wide gmsh lock for its lifetime (one load at a time, from any
// thread) and starts from a fresh gmsh, initialised for it, with terminal output off and the
// log recorded; when it ends it clears the model (and with it the parser's variables) and the
// ONELAB parameters, which outlive gmsh::finalize, and finalises gmsh. Without the fresh start
// an earlier load's options (Mesh.ElementOrder, Mesh.RecombineAll, ...) and ONELAB parameters
// (DefineConstant[ h = {..., Name "Parameters/h"} ]) would be picked up, and after a syntax
// error gmsh's parser no longer defines the DefineConstant parameters; a fresh initialisation
// resets every option to its default. One initialise/finalise cycle a session: gmsh keeps
// memory with each, more as they add up (scripts/fuzz.sh). This header does not include gmsh.h.
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace smpm {

class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  // Two ways of telling that a gmsh call failed ("" if it did not). Both run the call with gmsh
  // logging its errors rather than throwing them (an error thrown inside gmsh's parallel surface
  // meshing would end the process); every other gmsh call of the session throws as the API does.
  //
  // The error of one call: the first "Error" line it logged, else, if it threw, gmsh's last
  // error (else "unknown gmsh error").
  std::string call_error(const std::function<void()>& call) const;
  // The error of a load that stops at its first failure: the text of what the call threw
  // ("unknown gmsh error" for anything but a string or an exception), else the first "Error"
  // line logged since the session started, without its prefix.
  std::string load_error(const std::function<void()>& call) const;

 private:
  std::unique_lock<std::mutex> lock_;
  // gmsh's start-up sets OpenMP's thread count to its own option (General.NumThreads, 1), under
  // which its meshers run (they are not safe on more threads in this gmsh): the process's
  // count, saved here, is restored when the session ends, so that a case read through gmsh
  // still steps on every core.
  int omp_threads_ = 1;
};

// Pre-flight checks of a gmsh input, before anything is read or meshed ("" when fine):
// the file must be a regular file (not a device such as /dev/zero, a pipe or a directory) of at
// most 256 MB.
std::string gmsh_input_problem(const std::string& file);
// After gmsh::open, before meshing at element size h (h <= 0: the file's own sizes, not checked):
// the cells a mesh of size h would have, estimated from the model's bounding box as area / h^2,
// must not exceed max_cells. The message gives the estimate and the box.
std::string gmsh_mesh_size_problem(double h, double max_cells);

// Numbers set in a .geo before it is read (a case's `parameters`, the mesh size h): a small
// wrapper .geo in the temporary folder that assigns them and then includes the file, whose
// DefineConstant keeps an already defined value. (gmsh's -setnumber is kept across sessions of
// one process, so it would leak into later loads.) path() is the file to open: the wrapper, or
// the file itself when there is nothing to set; the wrapper is removed with the object. Throws
// std::runtime_error "<file>: ..." for a parameter name that is not letters, digits and _ (or is
// h, which the mesh size sets) and when the wrapper cannot be written.
// A name GeoParameters accepts: letters, digits and _, and not h.
inline bool geo_parameter_name_ok(const std::string& name) {
  return !name.empty() && name != "h" &&
         name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_") ==
             std::string::npos;
}

class GeoParameters {
 public:
  GeoParameters(const std::string& file, double h,
                const std::vector<std::pair<std::string, double>>& parameters);
  ~GeoParameters();
  GeoParameters(const GeoParameters&) = delete;
  GeoParameters& operator=(const GeoParameters&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_, wrapper_;
};

}  // namespace smpm
