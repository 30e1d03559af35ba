// The tungsten film's "j2_softening" case keys (studies/film) are read and validated with the key
// path in every message. (The film through the whole solver: tests/physics/test_film_study.cpp.)
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "test_film_common.hpp"

using namespace smpm;
using smpm::film_testing::case_path;

namespace {
nlohmann::json film_doc() {
  std::ifstream f(case_path("silent"));
  nlohmann::json d = nlohmann::json::parse(f);
  // The document is built under the name "film.json": give the gmsh file's path absolute.
  d["geometry"]["file"] = (case_path("silent").parent_path() / d["geometry"]["file"].get<std::string>()).string();
  return d;
}
std::string error_of(const nlohmann::json& doc) {
  try {
    build_case(doc, "film.json");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(FilmCase, KeysAreReadAndValidated) {
  {
    nlohmann::json d = film_doc();
    d["grid"]["cell"] = 2.5e-7;
    d["time"]["dt"] = 8e-12;
    d["materials"]["tungsten"]["moduli"] = "tangent";
    d["materials"]["tungsten"]["bifurcation"]["tie_break"] = "largest_angle";
    d["materials"]["tungsten"]["decohesion"]["smear_length"] = 5e-8;
    d["materials"]["tungsten"]["decohesion"]["compressed_normal_strength"] = 2e9;
    Case c = build_case(d, "film.json");
    const Material& m = c.solver->materials[c.solver->materials[0].name == "tungsten" ? 0 : 1];
    ASSERT_EQ(m.model, Model::J2Film);
    EXPECT_NEAR(m.j2.H_h, 411e9 * 64e9 / (411e9 - 64e9), 1.0);
    EXPECT_EQ(m.bif.tie, TieBreak::LargestAngle);
    EXPECT_DOUBLE_EQ(m.coh.smear_length, 5e-8);
    EXPECT_DOUBLE_EQ(m.coh.compressed_normal_strength, 2e9);
    EXPECT_DOUBLE_EQ(m.coh.u_nf, 10e-9);
    EXPECT_DOUBLE_EQ(m.coh.min_strength, 1.5e6);
  }
  struct Bad {
    const char* key;
    nlohmann::json value;
    const char* expect;
  };
  const std::vector<Bad> bad = {
      {"peak_stress", 1.0e9, "materials.tungsten.peak_stress: must be >= yield_stress"},
      {"softening_modulus", -1.0, "materials.tungsten.softening_modulus: must be > 0"},
      {"moduli", "secant", "materials.tungsten.moduli: must be one of"},
      {"hardening", 1.0, "materials.tungsten.hardening: unknown key"},
  };
  for (const auto& b : bad) {
    nlohmann::json d = film_doc();
    d["materials"]["tungsten"][b.key] = b.value;
    const std::string msg = error_of(d);
    EXPECT_NE(msg.find(b.expect), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind("film.json: ", 0), 0u) << msg;
  }
  const std::vector<std::pair<std::vector<std::string>, nlohmann::json>> nested = {
      {{"bifurcation", "tie_break"}, "random"},
      {{"bifurcation", "step_deg"}, 0.0},
      {{"decohesion", "smear_length"}, "cell"},
      {{"decohesion", "normal_critical_jump"}, 0.0},
      {{"decohesion", "snap_back_factor"}, 1.0},
      {{"decohesion", "compressed_normal_strength"}, "tension"},
      {{"decohesion", "opening"}, 1e-9},
  };
  for (const auto& [path, value] : nested) {
    nlohmann::json d = film_doc();
    d["materials"]["tungsten"][path[0]][path[1]] = value;
    const std::string msg = error_of(d);
    const std::string key = "materials.tungsten." + path[0] + "." + path[1] + ":";
    EXPECT_NE(msg.find(key), std::string::npos) << msg;
  }
  // A probe restricted to a body names an existing body.
  {
    nlohmann::json d = film_doc();
    d["probes"][0]["body"] = "substrat";
    const std::string msg = error_of(d);
    EXPECT_NE(msg.find("probes[0].body: no body named \"substrat\" (did you mean \"substrate\"?)"),
              std::string::npos)
        << msg;
  }
  // Film keys are rejected on other models.
  nlohmann::json d = film_doc();
  d["materials"]["silicon"]["peak_stress"] = 9e9;
  EXPECT_NE(error_of(d).find("materials.silicon.peak_stress: unknown key for model \"von_mises\""),
            std::string::npos)
      << error_of(d);
}

// A particle PML under MUSL at 1 ppc in the film (a body seeded from a gmsh surface, whose
// boundaries are read before the grid and the materials reach the solver): the 10-cell layer
// (1 um of 0.1 um cells) passes the width check and is asked for its frequency shift, with the
// shift the substrate's own c_d and the case's cell give (it had been checked against cells of
// 1 m and read the solver's still empty materials); "auto" builds.
TEST(FilmCase, PmlUnderMuslAtOnePpcChecksWithTheCasesCell) {
  std::ifstream f(case_path("pml"));
  nlohmann::json d = nlohmann::json::parse(f);
  d["geometry"]["file"] =
      (case_path("pml").parent_path() / d["geometry"]["file"].get<std::string>()).string();
  d["scheme"]["update"] = "MUSL";
  nlohmann::json* pml = nullptr;
  for (auto& b : d["boundaries"])
    if (b["type"] == "pml") pml = &b;
  ASSERT_NE(pml, nullptr);
  ASSERT_DOUBLE_EQ((*pml)["width"].get<double>(), 10 * d["grid"]["cell"].get<double>());
  const std::string e = error_of(d);
  EXPECT_NE(e.find(".alpha: a pml on particles under scheme.update \"MUSL\" at 1 particle per "
                   "cell (body \"substrate\") needs alpha >= 0.04 sqrt(d0 c_d / h) = "),
            std::string::npos)
      << e;
  // "auto" takes 0.04 sqrt(d0 c_d / h), d0 = 3 c_d ln(1 / r0) / (2 width), with the
  // substrate's c_d and the case's cell (1e-7 m): 3.07e9 1/s here.
  (*pml)["alpha"] = "auto";
  Case c = build_case(d, "film.json");
  ASSERT_TRUE(c.solver);
  const Solver& s = *c.solver;
  double cd = 0;
  for (const Material& m : s.materials)
    if (m.name == "silicon") cd = m.cd;
  ASSERT_GT(cd, 0.0);
  const double want = pml_one_ppc_alpha(cd, (*pml)["r0"].get<double>(), 2.0,
                                        (*pml)["width"].get<double>(), s.grid.h);
  EXPECT_DOUBLE_EQ(s.grid.h, 1e-7);
  EXPECT_NEAR(s.pml.alpha, want, 1e-12 * want);
  EXPECT_GT(want, 1e9);
}
