// Bad gmsh inputs: each gives one clear error naming the case file, the key, the geometry file
// and the physical group, through load_case() and through the CLI (non-zero exit).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "silentmpm/case.hpp"
#include "test_geometry_common.hpp"


namespace {

using namespace smpm::geotest;

const char* kRect = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0, 0, 0, h}; Point(2) = {0.02, 0, 0, h};
Point(3) = {0.02, 0.01, 0, h}; Point(4) = {0, 0.01, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1}; Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {1}; Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {3}; Physical Curve("top", 14) = {4};
)";

// A second, separate square (surface 2) whose edge (curve 15) does not touch the plate.
const char* kTwo = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0, 0, 0, h}; Point(2) = {0.02, 0, 0, h};
Point(3) = {0.02, 0.01, 0, h}; Point(4) = {0, 0.01, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1}; Plane Surface(1) = {1};
Point(5) = {0, 0.012, 0, h}; Point(6) = {0.005, 0.012, 0, h};
Point(7) = {0.005, 0.015, 0, h}; Point(8) = {0, 0.015, 0, h};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Physical Surface("plate", 1) = {1}; Physical Surface("lid", 2) = {2};
Physical Curve("right", 12) = {2}; Physical Curve("lid_bottom", 15) = {5};
)";

// A right triangle: its hypotenuse (curve 16) is inclined.
const char* kTri = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0, 0, 0, h}; Point(2) = {0.02, 0, 0, h}; Point(3) = {0, 0.01, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 1};
Curve Loop(1) = {1, 2, 3}; Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("bottom", 13) = {1}; Physical Curve("slope", 16) = {2};
)";

// The plate of kRect with its bottom in two lines; curve 17 is the left half.
const char* kSplit = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0, 0, 0, h}; Point(2) = {0.01, 0, 0, h}; Point(3) = {0.02, 0, 0, h};
Point(4) = {0.02, 0.01, 0, h}; Point(5) = {0, 0.01, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5}; Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("bottom", 13) = {1, 2}; Physical Curve("bottom_left", 17) = {1};
)";

// An annulus with a curve embedded on its hole: gmsh cannot mesh it (it fails inside its
// parallel surface meshing, which must still come back as an error, not end the process).
const char* kRingOnHole = R"(
DefineConstant[ h = 0.001 ];
Point(1) = {0.01, 0.01, 0, h};
Point(2) = {0.018, 0.01, 0, h}; Point(3) = {0.002, 0.01, 0, h};
Point(4) = {0.013, 0.01, 0, h}; Point(5) = {0.007, 0.01, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 2};
Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 4};
Curve Loop(1) = {1, 2}; Curve Loop(2) = {3, 4};
Plane Surface(1) = {1, 2};
Point(6) = {0.013, 0.01, 0, h}; Point(7) = {0.007, 0.01, 0, h};
Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 6};
Curve{5, 6} In Surface{1};
Physical Surface("plate", 1) = {1};
Physical Curve("hole", 15) = {3, 4};
)";

// A case under USL (the particle pml needs it).
std::string usl(std::string json) {
  const std::string at = R"("time": {)";
  return json.replace(json.find(at), at.size(), R"("scheme": { "update": "USL" }, )" + at);
}

std::string case_json(const std::string& geo_file, const std::string& body,
                      const std::string& boundaries = "", const std::string& grid_size = "[0.03, 0.02]",
                      const std::string& geometry_extra = "", const std::string& probes = "") {
  return R"({
  "grid": { "origin": [-0.004, -0.004], "size": )" + grid_size + R"(, "cell": 0.001 },
  "time": { "end": 1e-6, "cfl": 0.3 },
  "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
  "geometry": { "file": ")" + geo_file + "\"" + geometry_extra + R"( },
  "bodies": [ )" + body + R"( ],
  "boundaries": [ )" + boundaries + R"( ],
  "probes": [ )" + probes + R"( ]
})";
}

const std::string kBody = R"({ "name": "plate", "material": "w", "surface": 1 })";

struct Bad {
  std::string name;
  std::string geo_name, geo_text;  // written next to the case (empty name: none)
  std::string json;
  std::vector<std::string> expect;  // substrings of the message
};

std::vector<Bad> bad_cases() {
  std::vector<Bad> v;
  v.push_back({"missing_surface", "rect_a.geo", kRect,
               case_json("rect_a.geo", R"({ "name": "plate", "material": "w", "surface": 7 })"),
               {"bodies[0].surface", "rect_a.geo", "no physical surface 7", "1 \"plate\""}});
  v.push_back({"missing_surface_name", "rect_b.geo", kRect,
               case_json("rect_b.geo", R"({ "name": "plate", "material": "w", "surface": "steel" })"),
               {"bodies[0].surface", "rect_b.geo", "no physical surface named \"steel\""}});
  v.push_back({"missing_curve", "rect_c.geo", kRect,
               case_json("rect_c.geo", kBody, R"({ "type": "silent", "body": "plate", "curve": 19 })"),
               {"boundaries[0].curve", "rect_c.geo", "no physical curve 19", "11 \"left\""}});
  v.push_back({"missing_file", "", "", case_json("nowhere.geo", kBody),
               {"geometry.file", "nowhere.geo", "cannot open file"}});
  v.push_back({"directory", "", "", case_json(".", kBody), {"geometry.file", "cannot open file"}});
  v.push_back({"empty_geo", "empty.geo", "", case_json("empty.geo", kBody),
               {"geometry.file", "empty.geo", "the file is empty"}});
  v.push_back({"empty_msh", "empty.msh", "  \n", case_json("empty.msh", kBody),
               {"geometry.file", "empty.msh", "the file is empty"}});
  v.push_back({"syntax_error", "broken.geo", "Point(1) = {0, 0, 0\n", case_json("broken.geo", kBody),
               {"geometry.file", "broken.geo", "gmsh could not read the geometry"}});
  v.push_back({"unmeshable", "ring_on_hole.geo", kRingOnHole,
               case_json("ring_on_hole.geo", kBody, "", "[0.03, 0.03]"),
               {"geometry.file", "ring_on_hole.geo", "gmsh could not mesh the geometry",
                "on curve 3"}});
  v.push_back({"no_groups", "nogroups.geo",
               "Point(1) = {0,0,0,1e-3}; Point(2) = {1e-2,0,0,1e-3}; Line(1) = {1,2};\n",
               case_json("nogroups.geo", kBody),
               {"geometry.file", "nogroups.geo", "defines no physical surface or physical curve"}});
  v.push_back({"second_order", "order2.geo", std::string(kRect) + "Mesh.ElementOrder = 2;\n",
               case_json("order2.geo", kBody),
               {"geometry.file", "order2.geo", "physical surface 1 \"plate\"", "second-order element"}});
  v.push_back({"unsupported_type", "shape.stl", "solid x\nendsolid x\n", case_json("shape.stl", kBody),
               {"geometry.file", "shape.stl", "unsupported file type \".stl\""}});
  v.push_back({"outside_grid", "rect_d.geo", kRect,
               case_json("rect_d.geo", kBody, "", "[0.02, 0.02]"),
               {"bodies[0].surface", "rect_d.geo", "physical surface 1 \"plate\"", "partly outside the grid"}});
  v.push_back({"no_particle", "rect_e.geo", kRect,
               case_json("rect_e.geo", kBody,
                         R"({ "type": "silent", "body": "plate", "curve": 12, "width": 1e-5 })"),
               {"boundaries[0].curve", "rect_e.geo", "physical curve 12 \"right\"", "selects no particle"}});
  v.push_back({"curve_off_body", "two.geo", kTwo,
               case_json("two.geo", kBody,
                         R"({ "type": "traction", "body": "plate", "curve": 15, "normal": 1 })"),
               {"boundaries[0].curve", "two.geo", "physical curve 15 \"lid_bottom\"",
                "is not on the boundary of physical surface 1 \"plate\""}});
  v.push_back({"side_on_surface_body", "rect_f.geo", kRect,
               case_json("rect_f.geo", kBody, R"({ "type": "silent", "body": "plate", "side": "right" })"),
               {"boundaries[0].side", "comes from a gmsh surface"}});
  v.push_back({"box_and_surface", "rect_g.geo", kRect,
               case_json("rect_g.geo",
                         R"({ "name": "plate", "material": "w", "surface": 1, "box": [0, 0, 0.01, 0.01] })"),
               {"bodies[0].surface", "either box or surface"}});
  v.push_back({"bad_size", "rect_h.geo", kRect, case_json("rect_h.geo", kBody, "", "[0.03, 0.02]", R"(, "size": -1)"),
               {"geometry.size", "must be > 0"}});
  // Every key is read before the mesh is made: with a size whose mesh would exceed the cell
  // limit (checked just before meshing), a mistake in a body, boundary or probe is still the one
  // reported. The last entry is the control: the same geometry without a mistake.
  const std::string tiny = R"(, "size": 1e-7)";
  v.push_back({"body_key_before_mesh", "rect_i.geo", kRect,
               case_json("rect_i.geo", R"({ "name": "plate", "material": "w", "surface": 1, "particles_per_cel": 4 })",
                         "", "[0.03, 0.02]", tiny),
               {"bodies[0].particles_per_cel", "unknown key", "particles_per_cell"}});
  v.push_back({"surface_before_mesh", "rect_j.geo", kRect,
               case_json("rect_j.geo", R"({ "name": "plate", "material": "w", "surface": "plat" })",
                         "", "[0.03, 0.02]", tiny),
               {"bodies[0].surface", "no physical surface named \"plat\"", "1 \"plate\""}});
  v.push_back({"boundary_key_before_mesh", "rect_k.geo", kRect,
               case_json("rect_k.geo", kBody, R"({ "type": "silent", "body": "plate", "curve": 12, "widht": 0.001 })",
                         "[0.03, 0.02]", tiny),
               {"boundaries[0].widht", "unknown key"}});
  v.push_back({"boundary_curve_before_mesh", "rect_l.geo", kRect,
               case_json("rect_l.geo", kBody, R"({ "type": "fixed", "curve": "rigth" })", "[0.03, 0.02]", tiny),
               {"boundaries[0].curve", "no physical curve named \"rigth\"", "12 \"right\""}});
  v.push_back({"boundary_value_before_mesh", "rect_m.geo", kRect,
               case_json("rect_m.geo", kBody, R"({ "type": "silent", "body": "plate", "curve": 12, "a": -1 })",
                         "[0.03, 0.02]", tiny),
               {"boundaries[0].a", ">= 0"}});
  v.push_back({"probe_key_before_mesh", "rect_n.geo", kRect,
               case_json("rect_n.geo", kBody, "", "[0.03, 0.02]", tiny,
                         R"({ "name": "top", "curve": 14, "count": 5, "spacing": 0.001 })"),
               {"probes[0]", "either count or spacing"}});
  v.push_back({"probe_curve_before_mesh", "rect_o.geo", kRect,
               case_json("rect_o.geo", kBody, "", "[0.03, 0.02]", tiny,
                         R"({ "name": "top", "curve": 99, "count": 5 })"),
               {"probes[0].curve", "no physical curve 99"}});
  v.push_back({"mesh_too_large", "rect_p.geo", kRect,
               case_json("rect_p.geo", kBody, R"({ "type": "silent", "body": "plate", "curve": 12 })",
                         "[0.03, 0.02]", tiny, R"({ "name": "top", "curve": 14, "count": 5 })"),
               {"geometry.file", "rect_p.geo", "would have about 2e+10 cells"}});
  // A pml along a physical curve: one straight line along an axis, on the body's bounding box,
  // spanning it; the control case below is accepted.
  v.push_back({"pml_inclined_curve", "tri_a.geo", kTri,
               usl(case_json("tri_a.geo", kBody,
                             R"({ "type": "pml", "body": "plate", "curve": "slope", "width": 0.002 })")),
               {"boundaries[0].curve", "tri_a.geo", "physical curve 16 \"slope\"",
                "is not a straight line parallel to the x or the y axis"}});
  v.push_back({"pml_curve_inside", "two_b.geo", kTwo,
               usl(case_json("two_b.geo", kBody,
                             R"({ "type": "pml", "body": "plate", "curve": 15, "width": 0.002 })")),
               {"boundaries[0].curve", "two_b.geo", "physical curve 15 \"lid_bottom\"",
                "is not on the edge of body \"plate\"'s bounding box"}});
  v.push_back({"pml_curve_part_of_edge", "split_a.geo", kSplit,
               usl(case_json("split_a.geo", kBody,
                             R"({ "type": "pml", "body": "plate", "curve": 17, "width": 0.002 })")),
               {"boundaries[0].curve", "split_a.geo", "physical curve 17 \"bottom_left\"",
                "not the whole edge of body \"plate\" (0 to 0.02)"}});
  v.push_back({"pml_curve_too_wide", "split_b.geo", kSplit,
               usl(case_json("split_b.geo", kBody,
                             R"({ "type": "pml", "body": "plate", "curve": 13, "width": 0.02 })")),
               {"boundaries[0].width", "must be <= the size of body \"plate\" normal to its physical "
                "curve 13 \"bottom\" (0.01), got 0.02"}});
  v.push_back({"pml_side_and_curve", "split_c.geo", kSplit,
               usl(case_json("split_c.geo", kBody,
                             R"({ "type": "pml", "body": "plate", "curve": 13, "side": "bottom", "width": 0.002 })")),
               {"boundaries[0].side", "either side or curve, not both"}});
  // No geometry key at all.
  v.push_back({"no_geometry", "", "", R"({
  "grid": { "size": [0.03, 0.02], "cell": 0.001 }, "time": { "end": 1e-6, "cfl": 0.3 },
  "materials": { "w": { "model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000 } },
  "bodies": [ { "name": "plate", "material": "w", "surface": 1 } ] })",
               {"bodies[0].surface", "needs the top-level key \"geometry\""}});
  return v;
}

void PrintTo(const Bad& b, std::ostream* os) { *os << b.name; }

fs::path write_bad(const Bad& b) {
  if (!b.geo_name.empty()) write_file(b.geo_name, b.geo_text);
  return write_file("bad_" + b.name + ".json", b.json);
}

class GeometryErrors : public ::testing::TestWithParam<Bad> {};

TEST_P(GeometryErrors, LibraryMessage) {
  const Bad& b = GetParam();
  expect_case_error(write_bad(b), b.expect, b.name);
}

TEST_P(GeometryErrors, CliExitAndMessage) {
  const Bad& b = GetParam();
  expect_cli_error(write_bad(b), b.expect, b.name);
}

std::string bad_name(const ::testing::TestParamInfo<Bad>& info) { return info.param.name; }
INSTANTIATE_TEST_SUITE_P(Bad, GeometryErrors, ::testing::ValuesIn(bad_cases()), bad_name);

}  // namespace
