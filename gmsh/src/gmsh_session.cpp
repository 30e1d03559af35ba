#include "silentmpm/gmsh_session.hpp"

#include <omp.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <unistd.h>
#include <filesystem>

#include <gmsh.h>

#include <exception>
#include <vector>

namespace smpm {

namespace {

std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

// Whether the last session cleared the model and the ONELAB parameters when it ended (under
// the lock).
bool& cleared_at_end() {
  static bool cleared = false;
  return cleared;
}

// What outlives gmsh::finalize: the model (and with it the parser's variables, h of the last
// .geo) and the ONELAB parameters.
void clear_leftovers() {
  gmsh::clear();
  gmsh::onelab::clear();
}

std::string last_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e;
}

// The "Error" lines of the gmsh log since the session started, without their prefix.
std::vector<std::string> logged_errors() {
  std::vector<std::string> log, out;
  try {
    gmsh::logger::get(log);
  } catch (...) {
  }
  for (const auto& l : log)
    if (l.rfind("Error", 0) == 0) {
      std::size_t p = l.find(':');
      std::string m = p == std::string::npos ? l : l.substr(p + 1);
      m.erase(0, m.find_first_not_of(' '));
      out.push_back(m);
    }
  return out;
}

// Runs a checked call with gmsh logging its errors instead of throwing them: gmsh meshes
// surfaces in an OpenMP region (also when a .geo says "Mesh 2;"), out of which a thrown error
// cannot pass (the process would end). The option is restored after the call.
void logging_errors(const std::function<void()>& call) {
  double abort_on_error = 0;
  gmsh::option::getNumber("General.AbortOnError", abort_on_error);
  gmsh::option::setNumber("General.AbortOnError", 0);
  struct Restore {
    double v;
    ~Restore() {
      try {
        gmsh::option::setNumber("General.AbortOnError", v);
      } catch (...) {
      }
    }
  } restore{abort_on_error};
  call();
}

std::string first_of(const std::vector<std::string>& errors, std::size_t from) {
  return errors.size() > from ? errors[from] : std::string();
}

}  // namespace

GmshSession::GmshSession() : lock_(gmsh_mutex()), omp_threads_(omp_get_max_threads()) {
  static char name[] = "silentmpm";
  char* argv[] = {name, nullptr};
  try {
    // The last session cleared what outlives gmsh::finalize (the model and the parser's
    // variables, the ONELAB parameters) before it finalised; nothing else starts gmsh. Where
    // that failed (or this is the process's first session), a cycle to clear them first.
    if (!cleared_at_end()) {
      gmsh::initialize(1, argv, /*readConfigFiles=*/false);
      gmsh::option::setNumber("General.Terminal", 0);
      clear_leftovers();
      gmsh::finalize();
    }
    cleared_at_end() = false;
    gmsh::initialize(1, argv, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);  // gmsh's defaults
    gmsh::option::setNumber("Mesh.MeshSizeMin", 0);
    gmsh::logger::start();
  } catch (...) {  // no destructor runs: restore the thread count here
    omp_set_num_threads(omp_threads_);
    throw;
  }
}

GmshSession::~GmshSession() {
  try {
    clear_leftovers();
    cleared_at_end() = true;
  } catch (...) {
  }
  try {
    gmsh::logger::stop();
    gmsh::finalize();
  } catch (...) {
  }
  omp_set_num_threads(omp_threads_);
}

std::string GmshSession::call_error(const std::function<void()>& call) const {
  const std::size_t before = logged_errors().size();
  bool threw = false;
  try {
    logging_errors(call);
  } catch (...) {
    threw = true;
  }
  const std::string first = first_of(logged_errors(), before);
  if (!first.empty()) return first;
  if (!threw) return "";
  const std::string last = last_error();
  return last.empty() ? std::string("unknown gmsh error") : last;
}

std::string GmshSession::load_error(const std::function<void()>& call) const {
  std::string err;
  try {
    logging_errors(call);
  } catch (const std::string& s) {
    err = s;
  } catch (const std::exception& e) {
    err = e.what();
  } catch (...) {
    err = "unknown gmsh error";
  }
  if (err.empty()) err = first_of(logged_errors(), 0);
  return err;
}

std::string gmsh_input_problem(const std::string& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(file, ec);
  if (ec || !fs::exists(st)) return "cannot open file (it does not exist)";
  if (fs::is_directory(st)) return "cannot open file (it is a directory)";
  if (!fs::is_regular_file(st))
    return "is not a regular file (a device, a pipe or a socket): give a gmsh .geo or .msh file";
  const auto bytes = fs::file_size(file, ec);
  constexpr std::uintmax_t kMax = 256u << 20;
  if (!ec && bytes > kMax)
    return "is " + std::to_string(bytes >> 20) + " MB; gmsh inputs over 256 MB are refused";
  return {};
}

std::string gmsh_mesh_size_problem(double h, double max_cells) {
  if (!(h > 0)) return {};
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  try {
    gmsh::model::getBoundingBox(-1, -1, x0, y0, z0, x1, y1, z1);
  } catch (...) {
    return {};  // no entities: the meshing reports it
  }
  const double w = x1 - x0, hh = y1 - y0;
  if (!(w > 0) || !(hh > 0)) return {};
  const double cells = w * hh / (h * h);
  if (cells <= max_cells) return {};
  char b[256];
  std::snprintf(b, sizeof b,
                "a mesh of size %g would have about %.3g cells (bounding box %g x %g m); at most "
                "%.3g are allowed: use a larger size",
                h, cells, w, hh, max_cells);
  return b;
}

namespace {
std::string fmt17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}
}  // namespace

GeoParameters::GeoParameters(const std::string& file, double h,
                             const std::vector<std::pair<std::string, double>>& parameters)
    : path_(file) {
  namespace fs = std::filesystem;
  std::string preamble;
  if (h > 0) preamble += "h = " + fmt17(h) + ";\n";
  for (const auto& [name, value] : parameters) {
    if (!geo_parameter_name_ok(name))
      throw std::runtime_error(file + ": parameter name \"" + name +
                               "\" must be letters, digits and _ (and not h: use size)");
    preamble += name + " = " + fmt17(value) + ";\n";
  }
  if (preamble.empty()) return;
  static std::atomic<int> counter{0};
  std::error_code ec;
  const fs::path abs = fs::absolute(file, ec);
  wrapper_ = (fs::temp_directory_path(ec) /
              ("silentmpm_" + std::to_string(static_cast<long>(::getpid())) + "_" +
               std::to_string(++counter) + "_" + abs.filename().string()))
                 .string();
  std::ofstream w(wrapper_);
  w << preamble << "Include \"" << abs.string() << "\";\n";
  if (!w) throw std::runtime_error(file + ": cannot write a temporary file " + wrapper_);
  path_ = wrapper_;
}

GeoParameters::~GeoParameters() {
  std::error_code ec;
  if (!wrapper_.empty()) std::filesystem::remove(wrapper_, ec);
}

}  // namespace smpm
