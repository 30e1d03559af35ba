// Loading the gmsh, far-field and MPI modules on first use (modules.hpp).
#include "modules.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>

namespace smpm::detail {

namespace {

namespace fs = std::filesystem;

// The folder of the running program ("" when /proc/self/exe cannot be read).
std::string program_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

// The entry point `entry` of module `file`: found in the process when the module is already
// there, else from the first folder that has the file. Throws naming the file and the reason.
void* module_entry(const char* file, const char* entry) {
  if (void* sym = dlsym(RTLD_DEFAULT, entry)) return sym;
  std::string tried, reason;
  for (const char* env : {"SILENTMPM_MODULE_DIR", ""}) {
    std::string dir;
    if (*env) {
      const char* v = std::getenv(env);
      if (!v || !*v) continue;
      dir = v;
    } else {
      dir = program_dir();
      if (dir.empty()) continue;
    }
    const std::string path = (fs::path(dir) / file).string();
    tried += (tried.empty() ? "" : ", ") + path;
    std::error_code ec;
    if (!fs::exists(path, ec)) continue;
    void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      throw std::runtime_error("cannot load " + path + ": " + (e ? e : "unknown reason"));
    }
    if (void* sym = dlsym(handle, entry)) return sym;
    throw std::runtime_error(path + " has no entry point " + entry + " (not a silentmpm module)");
  }
  throw std::runtime_error(std::string(file) + " not found (looked for " +
                           (tried.empty() ? std::string("it nowhere") : tried) +
                           "; it is built beside the silentmpm program, or set "
                           "SILENTMPM_MODULE_DIR to its folder)");
}

// A module's table, loaded on the first call (one per table type; a load that fails is tried
// again on the next call).
template <class Table>
const Table& load_table(const char* file, const char* entry, int api) {
  static std::mutex m;
  static const Table* table = nullptr;
  std::lock_guard<std::mutex> lock(m);
  if (table) return *table;
  using Entry = const Table* (*)();
  const Table* t = reinterpret_cast<Entry>(module_entry(file, entry))();
  if (!t || t->api != api)
    throw std::runtime_error(std::string(file) + " was built from other sources (module interface " +
                             std::to_string(t ? t->api : -1) + ", this program needs " +
                             std::to_string(api) + "): rebuild both");
  table = t;
  return *t;
}

}  // namespace

const GmshModule& gmsh_module() {
  return load_table<GmshModule>("libsilentmpm_gmsh.so", "silentmpm_gmsh_module", kGmshModuleApi);
}

const FarFieldModule& far_field_module() {
  return load_table<FarFieldModule>("libsilentmpm_fe.so", "silentmpm_fe_module",
                                    kFarFieldModuleApi);
}

const MpiModule& mpi_module() {
  return load_table<MpiModule>("libsilentmpm_mpi.so", "silentmpm_mpi_module", kMpiModuleApi);
}

}  // namespace smpm::detail

namespace smpm {

std::string fem_check_line(const Case& c) { return detail::far_field_module().fem_check_line(c); }

}  // namespace smpm
