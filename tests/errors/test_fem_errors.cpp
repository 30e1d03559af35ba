// Bad meshes and bad FEM inputs: one clear error naming the file / key path, never a crash.
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "fem_common.hpp"
#include "silentmpm/case.hpp"

using namespace smpm;
using namespace smpm::fem_testing;
using json = nlohmann::json;

namespace {

std::string write_file(const std::string& name, const std::string& text) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p) << text;
  return p.string();
}

const char* kSquare =
    "Point(1) = {0, 0, 0}; Point(2) = {0.01, 0, 0}; Point(3) = {0.01, 0.01, 0};\n"
    "Point(4) = {0, 0.01, 0};\n"
    "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
    "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n";

json base_case() {
  return json::parse(R"({
    "time": {"end": 1e-6, "cfl": 0.5},
    "materials": {"tungsten": {"model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000}},
    "fem": {"mesh": "", "size": 0.001, "regions": {"body": "tungsten"},
            "boundaries": [{"type": "dashpot", "curve": "right"},
                           {"type": "traction", "curve": 11, "normal": -1e6}]},
    "probes": [{"name": "A", "at": [0.005, 0.005]}],
    "output": {"snapshots": 0, "progress": false}
  })");
}

json good_case() {
  json c = base_case();
  c["fem"]["mesh"] = rectangle_geo("err_square", 0.01, 0.01, 0.001);
  return c;
}

// The CaseError message of building `c` ("" if it builds).
std::string error_of(const json& c) {
  try {
    build_case(c, "case.json");
  } catch (const CaseError& e) {
    return e.what();
  }
  return "";
}

std::string mesh_error(const std::string& file, double size = 0) {
  try {
    fem::load_mesh(file, size);
  } catch (const fem::FemError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_ERROR(msg, ...)                                                 \
  do {                                                                         \
    const std::string m_ = (msg);                                              \
    for (const char* part : {__VA_ARGS__})                                     \
      EXPECT_NE(m_.find(part), std::string::npos) << "message: " << m_ << "\n" \
                                                  << "missing: " << part;      \
  } while (0)

}  // namespace

TEST(FemErrors, GoodCaseBuilds) {
  const json c = good_case();
  Case k = build_case(c, "case.json");
  ASSERT_TRUE(k.fem);
  EXPECT_EQ(k.fem->cells(), 100u);
  EXPECT_EQ(k.fem->dofs(), 2u * 121u);
  EXPECT_NEAR(k.fem->dt, 0.5 * k.fem->critical_dt(), 1e-20);
}

TEST(FemErrors, BadMeshes) {
  EXPECT_ERROR(mesh_error("/nonexistent/plate.geo"), "/nonexistent/plate.geo", "not found");
  EXPECT_ERROR(mesh_error(write_file("plate.txt", "x")), "plate.txt", "expected a gmsh .geo or .msh");
  EXPECT_ERROR(mesh_error(write_file("syntax.geo", "Point(1) = {0, 0, 0;\n")), "syntax.geo",
               "gmsh cannot read it");
  // A .geo without Recombine is recombined to quads (Mesh.RecombineAll); a .msh of triangles is
  // refused.
  {
    const fem::Mesh m = fem::load_mesh(
        write_file("tri.geo", std::string(kSquare) + "Physical Surface(\"body\", 1) = {1};\n"), 0);
    EXPECT_GT(m.quads, 0u);
  }
  EXPECT_ERROR(mesh_error(write_file("tri.msh",
                                     "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
                                     "$PhysicalNames\n1\n2 1 \"body\"\n$EndPhysicalNames\n"
                                     "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n"
                                     "$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 1 3 4\n$EndElements\n")),
               "tri.msh", "triangles", "all-quad");
  // Second-order quads.
  EXPECT_ERROR(mesh_error(write_file("q2.geo", std::string(kSquare) +
                                                   "Recombine Surface{1}; Mesh.ElementOrder = 2;\n"
                                                   "Physical Surface(\"body\", 1) = {1};\n")),
               "q2.geo", "second-order");
  // No physical surface.
  EXPECT_ERROR(mesh_error(write_file("nogroup.geo", std::string(kSquare) + "Recombine Surface{1};\n")),
               "nogroup.geo", "no Physical Surface");
  // A size for a .geo that does not declare it.
  EXPECT_ERROR(mesh_error(write_file("nosize.geo", std::string(kSquare) +
                                                       "Recombine Surface{1};\n"
                                                       "Physical Surface(\"body\", 1) = {1};\n"),
                          0.002),
               "nosize.geo", "Parameters/h");
  // A geometry gmsh cannot mesh (a curve embedded on a hole's edge): it fails inside gmsh's
  // parallel surface meshing, and must still come back as an error.
  EXPECT_ERROR(mesh_error(write_file("ring_on_hole.geo",
                                     "Point(1) = {0.01, 0.01, 0, 1e-3};\n"
                                     "Point(2) = {0.018, 0.01, 0, 1e-3}; Point(3) = {0.002, 0.01, 0, 1e-3};\n"
                                     "Point(4) = {0.013, 0.01, 0, 1e-3}; Point(5) = {0.007, 0.01, 0, 1e-3};\n"
                                     "Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 2};\n"
                                     "Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 4};\n"
                                     "Curve Loop(1) = {1, 2}; Curve Loop(2) = {3, 4};\n"
                                     "Plane Surface(1) = {1, 2};\n"
                                     "Point(6) = {0.013, 0.01, 0, 1e-3}; Point(7) = {0.007, 0.01, 0, 1e-3};\n"
                                     "Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 6};\n"
                                     "Curve{5, 6} In Surface{1};\n"
                                     "Physical Surface(\"body\", 1) = {1};\n")),
               "ring_on_hole.geo", "Unable to recover the edge");
  // A file that is not a mesh.
  EXPECT_ERROR(mesh_error(write_file("junk.msh", "$MeshFormat\nnot a mesh\n")), "junk.msh");
}

TEST(FemErrors, BadInputs) {
  json c = good_case();
  // A perfectly matched layer: its keys, then what only the mesh can tell.
  c["fem"]["boundaries"].push_back({{"type", "pml"}, {"curve", "top"}, {"width", 0.002}});
  EXPECT_EQ(error_of(c), "");
  c["fem"]["boundaries"][2]["r0"] = 1.5;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].r0", "(0, 1)");
  c["fem"]["boundaries"][2].erase("r0");
  c["fem"]["boundaries"][2]["alpha"] = -1;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].alpha", ">= 0");
  c["fem"]["boundaries"][2].erase("alpha");
  c["fem"]["boundaries"][2]["beta"] = 1e-7;  // a damping layer's key
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].beta", "unknown key", "for a pml boundary");
  c["fem"]["boundaries"][2]["type"] = "damping_layer";
  EXPECT_EQ(error_of(c), "");
  c["fem"]["boundaries"][2]["beta"] = -1e-7;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].beta", ">= 0");
  c["fem"]["boundaries"][2].erase("beta");
  c["fem"]["boundaries"][2]["type"] = "pml";
  c["fem"]["boundaries"][2]["a"] = 1;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].a", "unknown key", "for a pml boundary");
  c["fem"]["boundaries"][2].erase("a");
  c["fem"]["boundaries"][2].erase("width");
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].width", "missing required key");
  c["fem"]["boundaries"][2]["width"] = 0.02;
  EXPECT_ERROR(error_of(c), "case.json: fem", "boundary \"pml2\"", "0.02 m thick",
               "extent across it (0.01 m)");
  c["fem"]["boundaries"][2]["width"] = 0.002;
  c["fem"]["boundaries"][2]["curve"] = {"top", "right"};
  EXPECT_ERROR(error_of(c), "boundary \"pml2\"", "one straight edge parallel to the x or the y axis",
               "physical curve 12 (\"right\")");
  c["fem"]["boundaries"][2]["curve"] = "top";
  c["fem"]["boundaries"][2]["parallel"] = 1.5;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].parallel", "must be < 1, got 1.5");
  c["fem"]["boundaries"][2]["parallel"] = -0.5;
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].parallel", "must be >= 0, got -0.5");
  c["fem"]["boundaries"][2].erase("parallel");
  c["fem"]["boundaries"].push_back({{"type", "pml"}, {"curve", "bottom"}, {"width", 0.002}, {"alpha", 1e5}});
  EXPECT_ERROR(error_of(c), "boundary \"pml3\"", "the same alpha");

  c = good_case();
  c["fem"]["regions"] = {{"nosuch", "tungsten"}};
  EXPECT_ERROR(error_of(c), "case.json: fem.regions.nosuch", "no physical surface \"nosuch\"",
               "1 \"body\"");

  c = good_case();
  c["fem"]["boundaries"][0]["curve"] = "middle";
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].curve", "no physical curve \"middle\"", "12 \"right\"");

  c = good_case();
  c["fem"]["regions"] = json::object();
  EXPECT_ERROR(error_of(c), "fem.regions");

  c = good_case();
  c["materials"]["tungsten"]["model"] = "von_mises";
  c["materials"]["tungsten"]["yield_stress"] = 1e9;
  EXPECT_ERROR(error_of(c), "fem.regions.body", "linear elastic");

  c = good_case();
  c["time"] = {{"end", 1e-6}, {"dt", 1e-6}};
  EXPECT_ERROR(error_of(c), "case.json: time.dt", "above the FEM stability limit");

  c = good_case();
  c["probes"][0]["at"] = {0.02, 0.005};
  EXPECT_ERROR(error_of(c), "probes[0].at", "outside the FEM mesh");

  c = good_case();
  c["probes"][0]["fields"] = {"sxx", "dvi"};
  EXPECT_ERROR(error_of(c), "probes[0].fields[1]", "div");

  c = good_case();
  c["output"]["fields"] = {"velocity"};
  EXPECT_ERROR(error_of(c), "output.fields", "an FEM case has no particles");

  c = good_case();
  c["output"]["grid"] = true;
  EXPECT_ERROR(error_of(c), "output.grid", "an FEM case has no MPM grid");

  c = good_case();
  c["probes"][0] = {{"name", "R"}, {"region", {0.0, 0.0, 0.01, 0.001}}};
  EXPECT_ERROR(error_of(c), "probes[0].region", "unknown key");

  c = good_case();
  c["fem"]["degree"] = 3;
  EXPECT_ERROR(error_of(c), "fem.degree", "1 or 2");

  c = good_case();
  c["fem"]["boundaries"][0]["type"] = "silent";
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].type", "dashpot");

  c = good_case();
  c["fem"]["boundaries"][1].erase("normal");
  EXPECT_ERROR(error_of(c), "fem.boundaries[1]", "missing the traction");

  c = good_case();
  c["fem"]["boundaries"][0]["a"] = -1;
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].a", ">= 0");

  c = good_case();
  c["fem"]["size"] = -0.001;
  EXPECT_ERROR(error_of(c), "fem.size", "> 0");

  c = good_case();
  c["fem"]["mesh"] = "/nonexistent/plate.geo";
  EXPECT_ERROR(error_of(c), "case.json: fem.mesh", "not found");

  c = good_case();
  c["fem"]["meshes"] = 1;
  EXPECT_ERROR(error_of(c), "fem.meshes", "unknown key");

  c = good_case();
  c["bodies"] = json::array();  // bodies + fem: a hybrid case, which needs a grid
  EXPECT_ERROR(error_of(c), "case.json: grid", "MPM-FEM hybrid");

  c = good_case();
  c["fem"]["boundaries"].push_back({{"type", "dashpot"}, {"curve", {12}}});
  EXPECT_ERROR(error_of(c), "fem.boundaries[2].curve", "already has a dashpot");

  c = good_case();
  c["fem"]["boundaries"][0]["type"] = "kelvin_voigt";
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].delta", "missing required key");

  c = good_case();
  c["fem"]["boundaries"][0]["type"] = "kelvin_voigt";
  c["fem"]["boundaries"][0]["delta"] = 0;
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].delta", "> 0");

  c = good_case();
  c["fem"]["boundaries"][0]["type"] = "kelvin_voigt";
  c["fem"]["boundaries"][0]["delta"] = 0.01;
  c["fem"]["boundaries"][0]["alpha_t"] = -0.5;
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].alpha_t", ">= 0");

  c = good_case();
  c["fem"]["boundaries"][0]["delta"] = 0.01;
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].delta", "unknown key");

  c = good_case();
  c["fem"]["boundaries"][0] = {{"type", "damping_layer"}, {"curve", "right"}};
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].width", "missing required key");

  c = good_case();
  c["fem"]["boundaries"][0] = {{"type", "damping_layer"}, {"curve", "right"}, {"width", -0.01}};
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].width", "> 0");

  c = good_case();
  c["fem"]["boundaries"][0] = {{"type", "damping_layer"}, {"curve", "right"}, {"width", 0.01},
                               {"r0", 0}};
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].r0", "must be in (0, 1)");

  // The boundaries, regions and probes are checked before the mesh is read or meshed: with a
  // mesh file that does not exist, their mistakes are what is reported.
  c = good_case();
  c["fem"]["mesh"] = "/nonexistent/plate.geo";
  c["fem"]["boundaries"][0]["a"] = "one";
  EXPECT_ERROR(error_of(c), "fem.boundaries[0].a", "expected a number");
  c = good_case();
  c["fem"]["mesh"] = "/nonexistent/plate.geo";
  c["fem"]["regions"] = {{"body", "tungstne"}};
  EXPECT_ERROR(error_of(c), "fem.regions.body", "no material named \"tungstne\"");
  c = good_case();
  c["fem"]["mesh"] = "/nonexistent/plate.geo";
  c["probes"][0]["fields"] = {"sxx", "dvi"};
  EXPECT_ERROR(error_of(c), "probes[0].fields[1]", "div");
}

// Through the CLI: non-zero exit, one line on stderr naming the key path.
TEST(FemErrors, ThroughTheCli) {
  json c = good_case();
  c["fem"]["regions"] = {{"nosuch", "tungsten"}};
  const std::string path = write_file("bad_fem_case.json", c.dump());
  const std::string err = (temp_dir() / "cli_err.txt").string();
  const std::string cmd = std::string(SMPM_CLI) + " check " + path + " 2> " + err + " > /dev/null";
  const int rc = std::system(cmd.c_str());
  EXPECT_NE(rc, 0);
  std::ifstream f(err);
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_ERROR(text, "silentmpm: error:", "fem.regions.nosuch");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  // And a good case checks fine.
  const std::string good = write_file("good_fem_case.json", good_case().dump());
  EXPECT_EQ(std::system((std::string(SMPM_CLI) + " check " + good + " > /dev/null").c_str()), 0);
}

// fem.parameters set a .geo's other DefineConstant numbers (as geometry.parameters does for MPM):
// a rectangle W wide meshed at h = 1 mm has 10 W / 0.01 cells along x.
TEST(FemErrors, GeoParameters) {
  const std::string geo = write_file("param_rect.geo",
      "DefineConstant[ h = {0.001, Name \"Parameters/h\"} ];\n"
      "DefineConstant[ W = {0.01, Name \"Parameters/W\"} ];\n"
      "Point(1) = {0, 0, 0}; Point(2) = {W, 0, 0}; Point(3) = {W, 0.005, 0}; Point(4) = {0, 0.005, 0};\n"
      "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
      "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
      "Transfinite Curve{1, 3} = Round(W / h) + 1; Transfinite Curve{2, 4} = Round(0.005 / h) + 1;\n"
      "Transfinite Surface{1}; Recombine Surface{1};\n"
      "Physical Surface(\"body\", 1) = {1};\n"
      "Physical Curve(\"left\", 11) = {4}; Physical Curve(\"right\", 12) = {2};\n");
  json c = base_case();
  c["fem"]["mesh"] = geo;
  c["fem"]["boundaries"] = {{{"type", "dashpot"}, {"curve", "right"}}};
  c["probes"] = json::array();
  EXPECT_EQ(build_case(c, "case.json").fem->cells(), 50u);
  c["fem"]["parameters"] = {{"W", 0.02}};
  EXPECT_EQ(build_case(c, "case.json").fem->cells(), 100u);
  c["fem"]["parameters"] = {{"h", 0.002}};
  EXPECT_ERROR(error_of(c), "case.json: fem.parameters.h", "not h");
  c["fem"]["parameters"] = {{"W", "wide"}};
  EXPECT_ERROR(error_of(c), "fem.parameters.W", "number");
  c["fem"]["parameters"] = json::array();
  EXPECT_ERROR(error_of(c), "fem.parameters", "expected an object");
}
