#include "silentmpm/gmsh_session.hpp"

#include <gmsh.h>

#include <exception>
#include <vector>

namespace smpm {

namespace {

std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

std::string last_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e;
}

// First "Error" line of the gmsh log since the session started, without its prefix.
std::string first_logged_error() {
  std::vector<std::string> log;
  gmsh::logger::get(log);
  for (const auto& l : log)
    if (l.rfind("Error", 0) == 0) {
      std::size_t p = l.find(':');
      std::string m = p == std::string::npos ? l : l.substr(p + 1);
      m.erase(0, m.find_first_not_of(' '));
      return m;
    }
  return "";
}

}  // namespace

GmshSession::GmshSession() : lock_(gmsh_mutex()) {
  static char name[] = "silentmpm";
  char* argv[] = {name, nullptr};
  gmsh::initialize(1, argv, /*readConfigFiles=*/false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::clear();
  gmsh::onelab::clear();
  gmsh::finalize();
  gmsh::initialize(1, argv, /*readConfigFiles=*/false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("Mesh.MeshSizeMax", 1e22);  // gmsh's defaults
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0);
  gmsh::logger::start();
}

GmshSession::~GmshSession() {
  try {
    gmsh::onelab::clear();
    gmsh::logger::stop();
    gmsh::finalize();
  } catch (...) {
  }
}

std::string GmshSession::call_error(const std::function<void()>& call) const {
  const std::string before = last_error();
  bool threw = false;
  try {
    call();
  } catch (...) {
    threw = true;
  }
  const std::string after = last_error();
  if (threw) return after.empty() ? std::string("unknown gmsh error") : after;
  return after != before ? after : std::string();
}

std::string GmshSession::load_error(const std::function<void()>& call) const {
  std::string err;
  try {
    call();
  } catch (const std::string& s) {
    err = s;
  } catch (const std::exception& e) {
    err = e.what();
  } catch (...) {
    err = "unknown gmsh error";
  }
  if (err.empty()) err = first_logged_error();
  return err;
}

}  // namespace smpm
