#pragma once
// Helpers shared by the case-file tests (tests/unit/test_case_load.cpp: valid cases build;
// tests/errors/test_case.cpp: malformed cases fail): a per-process scratch directory, reading and
// writing its files, and the small valid case.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

#include <unistd.h>

namespace smpm::case_testing {

// A per-process scratch directory, removed at exit.
struct Scratch {
  std::filesystem::path dir = std::filesystem::temp_directory_path() /
                              ("smpm_test_case_" + std::to_string(static_cast<long>(::getpid())));
  Scratch() { std::filesystem::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

inline std::filesystem::path scratch() {
  static const Scratch s;
  return s.dir;
}

inline std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path p = scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

// 10 x 10 cells of 1 mm; a 10 mm x 5 mm tungsten plate (4 particles per cell) on the bottom half;
// rollers under it, the left grid side fixed, a pulse on its top, a silent layer at its bottom.
inline constexpr const char* kValid = R"({
  "title": "small valid case",
  "grid": { "origin": [0, 0], "size": [0.01, 0.01], "cell": 0.001 },
  "time": { "end": 1e-6, "cfl": 0.5 },
  "scheme": { "update": "MUSL", "flip": 1.0, "threads": 1 },
  "materials": {
    "tungsten": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 },
    "soft": { "model": "von_mises", "young": 70e9, "poisson": 0.3, "density": 2700,
              "yield_stress": 300e6 }
  },
  "bodies": [
    { "name": "plate", "material": "tungsten", "box": [0, 0, 0.01, 0.005],
      "particles_per_cell": 4 }
  ],
  "boundaries": [
    { "type": "roller", "component": "y", "body": "plate", "side": "bottom" },
    { "type": "traction", "name": "load", "body": "plate", "side": "top", "width": 0.0005,
      "normal": -1e8, "time": { "shape": "sin2", "start": 0, "duration": 2e-7, "ramp": 5e-8 } },
    { "type": "silent", "body": "plate", "side": "bottom", "form": "particle" },
    { "type": "fixed", "grid_side": "left" }
  ],
  "probes": [ { "name": "A", "at": [0.005, 0.0025], "fields": ["sxx", "vy"] } ],
  "output": { "history_every": 2, "snapshots": 0, "progress": false }
})";

}  // namespace smpm::case_testing
