#pragma once
// Helpers shared by the hybrid case-file tests (tests/cross/test_hybrid_case.cpp and
// tests/errors/test_hybrid_case_errors.cpp): the elastic plate of 60 x 30 cells as an all-MPM,
// a hybrid and an all-FEM case document, written to a per-process directory.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "test_hybrid_common.hpp"

namespace smpm::hybrid_case_testing {

using nlohmann::json;

const double h = 1e-3;
const double W = 60 * h, Hgt = 30 * h, XI = 20 * h;
const double cd = 5918.5;

inline std::filesystem::path dir() {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / ("smpm_hybrid_case_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

inline json material() {
  return {{"model", "elastic"}, {"young", 411e9}, {"poisson", 0.28}, {"density", 15000}};
}

inline json pulse_time() {
  return {{"shape", "sin2"}, {"start", 0.0}, {"duration", 40 * h / cd}, {"ramp", 20 * h / cd}};
}

inline json probes() {
  return json::array({{{"name", "A"}, {"at", {10.5 * h, 15.5 * h}}, {"fields", {"sxx", "syy", "vx"}}},
                      {{"name", "B"}, {"at", {40.5 * h, 15.5 * h}}, {"fields", {"sxx", "syy", "vx"}}}});
}

// kind: "mpm" (particles on the whole plate, silent right side), "fem" (elements on the whole
// plate, dashpot right side), "hybrid" (particles on [0, 20h], elements on [20h, 60h]).
inline json plate_case(const std::string& kind) {
  json c;
  c["title"] = "hybrid test plate (" + kind + ")";
  c["time"] = {{"end", 90 * h / cd}, {"dt", 0.3 * h / cd}};
  c["materials"] = {{"tungsten", material()}};
  c["probes"] = probes();
  c["output"] = {{"history_every", 1}, {"snapshots", kind == "hybrid" ? 2 : 0}, {"progress", false}};
  if (kind != "fem") {
    const double x1 = kind == "mpm" ? W : XI;
    c["grid"] = {{"origin", {-2 * h, -2 * h}}, {"size", {x1 + 4 * h, Hgt + 4 * h}}, {"cell", h}};
    c["scheme"] = {{"update", "MUSL"}, {"flip", 1.0}, {"threads", 1}};
    c["bodies"] = json::array({{{"name", "plate"}, {"material", "tungsten"}, {"box", {0, 0, x1, Hgt}},
                                {"particles_per_cell", 4}}});
    json b = json::array({{{"type", "traction"}, {"name", "pulse"}, {"body", "plate"}, {"side", "left"},
                           {"normal", -100e6}, {"time", pulse_time()}}});
    if (kind == "mpm")
      b.push_back({{"type", "silent"}, {"name", "right"}, {"body", "plate"}, {"side", "right"}});
    c["boundaries"] = b;
  } else {
    c["scheme"] = {{"threads", 1}};
  }
  if (kind != "mpm") {
    const double x0 = kind == "fem" ? 0 : XI;
    const std::string geo =
        hybrid_testing::box_geo("case_" + kind, x0, 0, W, Hgt, h);
    json fb = json::array({{{"type", "dashpot"}, {"name", "right"}, {"curve", "right"}}});
    if (kind == "fem")
      fb.push_back({{"type", "traction"}, {"name", "pulse"}, {"curve", "left"}, {"normal", -100e6},
                    {"time", pulse_time()}});
    c["fem"] = {{"mesh", geo}, {"size", h}, {"degree", 1}, {"regions", {{"body", "tungsten"}}},
                {"boundaries", fb}};
  }
  return c;
}

inline std::string write_case(const std::string& name, const json& c) {
  const std::filesystem::path p = dir() / (name + ".json");
  std::ofstream(p) << c.dump(2);
  return p.string();
}

}  // namespace smpm::hybrid_case_testing
