// Case files: a missing file and malformed cases fail with a message naming the key path, both
// through load_case() and through the CLI (`silentmpm check`); the valid case through the CLI.
// Valid cases through load_case() are in tests/unit/test_case_load.cpp.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "silentmpm/case.hpp"
#include "test_case_common.hpp"

#ifndef SMPM_CLI
#define SMPM_CLI ""
#endif

namespace {

namespace fs = std::filesystem;
using ojson = nlohmann::ordered_json;
using namespace smpm::case_testing;

TEST(CaseLoad, MissingFile) {
  try {
    smpm::load_case((scratch() / "does_not_exist.json").string());
    FAIL() << "no error";
  } catch (const smpm::CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("does_not_exist.json: cannot open file"),
              std::string::npos)
        << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Malformed cases: each is the valid case with one thing wrong.
struct Bad {
  std::string name;
  std::function<void(ojson&)> edit;  // applied to the valid case (unless text is given)
  std::string expect;                // must appear in the message
  std::string text;                  // verbatim file content instead of an edit
  std::vector<std::string> overrides;
  Bad(std::string n, std::function<void(ojson&)> e, std::string x, std::string t = "",
      std::vector<std::string> o = {})
      : name(std::move(n)), edit(std::move(e)), expect(std::move(x)), text(std::move(t)),
        overrides(std::move(o)) {}
};

ojson valid_doc() { return ojson::parse(kValid); }
ojson& bnd(ojson& j, int i) { return j["boundaries"][i]; }

std::vector<Bad> bad_cases() {
  return {
      {"bad_json", nullptr, "invalid JSON at line 3",
       "{\n  \"grid\": { \"size\": [1, 1], \"cell\": 0.1 },\n  \"time\": { \"end\": 1, }\n}\n"},
      {"duplicate_key", nullptr, "materials.m.young: key given twice",
       R"({"materials": {"m": {"young": 1, "young": 2}}})"},
      {"not_an_object", nullptr, "must be a JSON object", "[1, 2, 3]"},
      {"overlapping_bodies",
       [](ojson& j) {
         j["bodies"].push_back({{"name", "patch"}, {"material", "tungsten"},
                                {"box", {0.008, 0.004, 0.01, 0.006}}});
       },
       "bodies[1].box: overlaps body \"plate\" (bodies[0]) over 0.002 x 0.001 m"},
      {"probe_in_no_body", [](ojson& j) { j["probes"][0]["at"] = {0.005, 0.0085}; },
       "probes[0].at: (0.005, 0.0085) is in no body: no particle within a cell of it"},
      {"very_long_unknown_key", [](ojson& j) { j[std::string(100000, 'x')] = 1; },
       ": " + std::string(80, 'x') + "...(+99920 characters): unknown key"},
      {"key_with_a_newline", [](ojson& j) { j["mate\nrials"] = 1; },
       ": mate\\nrials: unknown key"},
      {"number_overflow", nullptr, "time.end: number 1e999 is out of the range of a double",
       R"({"grid": {"size": [1, 1], "cell": 0.1}, "time": {"end": 1e999, "cfl": 0.5}})"},
      {"number_overflow_in_array", nullptr,
       "grid.size[1]: number -2e400 is out of the range of a double",
       R"({"grid": {"size": [1, -2e400], "cell": 0.1}})"},
      {"too_many_steps", [](ojson& j) { j["time"]["end"] = 1e300; },
       "time: time.end / dt = 1e+300 s"},
      {"override_number_overflow", nullptr,
       "override 'time.end=1e999': a number in the value is out of the range of a double", "",
       {"time.end=1e999"}},
      {"unknown_top_key", [](ojson& j) { j["gird"] = 1; }, "gird: unknown key"},
      {"unknown_body_key", [](ojson& j) { j["bodies"][0]["colour"] = "red"; },
       "bodies[0].colour: unknown key"},
      {"misspelt_key_suggests",
       [](ojson& j) {
         auto& m = j["materials"]["tungsten"];
         m["poison"] = m["poisson"];
         m.erase("poisson");
       },
       "materials.tungsten.poison: unknown key for model \"elastic\" (did you mean \"poisson\"?)"},
      {"wrong_type", [](ojson& j) { j["materials"]["tungsten"]["young"] = "411e9"; },
       "materials.tungsten.young: expected a number, got a string"},
      {"poisson_half", [](ojson& j) { j["materials"]["tungsten"]["poisson"] = 0.5; },
       "materials.tungsten.poisson: must be < 0.5"},
      {"negative_density", [](ojson& j) { j["materials"]["tungsten"]["density"] = -1; },
       "materials.tungsten.density: must be > 0"},
      {"missing_grid", [](ojson& j) { j.erase("grid"); }, "grid: missing required key"},
      {"grid_not_multiple", [](ojson& j) { j["grid"]["size"] = {0.0105, 0.01}; },
       "grid.size: Lx = 0.0105 is not a multiple"},
      {"negative_cell", [](ojson& j) { j["grid"]["cell"] = -0.001; }, "grid.cell: must be > 0"},
      {"dt_above_limit",
       [](ojson& j) {
         j["time"].erase("cfl");
         j["time"]["dt"] = 1e-6;
       },
       "time.dt: 1e-06 s is above the stability limit"},
      {"dt_and_cfl", [](ojson& j) { j["time"]["dt"] = 1e-9; }, "time: give either dt or cfl"},
      {"cfl_above_one", [](ojson& j) { j["time"]["cfl"] = 1.5; }, "time.cfl: must be <= 1"},
      {"probe_outside", [](ojson& j) { j["probes"][0]["at"] = {0.02, 0.001}; },
       "probes[0].at: outside the grid"},
      {"probe_bad_field", [](ojson& j) { j["probes"][0]["fields"] = {"sxx", "syx"}; },
       "probes[0].fields[1]: must be one of"},
      {"body_outside", [](ojson& j) { j["bodies"][0]["box"] = {0, 0, 0.02, 0.005}; },
       "bodies[0].box: outside the grid"},
      {"body_box_short", [](ojson& j) { j["bodies"][0]["box"] = {0, 0, 0.01}; },
       "bodies[0].box: expected an array of 4 numbers, got an array of 3 elements"},
      {"unknown_material", [](ojson& j) { j["bodies"][0]["material"] = "steel"; },
       "bodies[0].material: no material named \"steel\""},
      {"ppc_5", [](ojson& j) { j["bodies"][0]["particles_per_cell"] = 5; },
       "bodies[0].particles_per_cell: must be 1, 4 or 9, got 5"},
      {"rectangular_without_duration",
       [](ojson& j) { bnd(j, 1)["time"] = {{"shape", "rectangular"}}; },
       "boundaries[1].time.duration: missing required key"},
      {"interval_outside_side",
       [](ojson& j) { bnd(j, 1)["interval"] = {0.002, 0.02}; },
       "boundaries[1].interval: [0.002, 0.02] is not within the top side of body \"plate\" (x from 0 to 0.01)"},
      {"interval_reversed",
       [](ojson& j) { bnd(j, 1)["interval"] = {0.004, 0.002}; },
       "boundaries[1].interval: must be [a, b] with a < b"},
      {"interval_on_silent",
       [](ojson& j) { bnd(j, 2)["interval"] = {0.002, 0.004}; },
       "boundaries[2].interval: unknown key for a silent boundary"},
      {"half_sine_with_ramp",
       [](ojson& j) { bnd(j, 1)["time"] = {{"shape", "half_sine"}, {"duration", 1e-6}, {"ramp", 1e-7}}; },
       "boundaries[1].time.ramp: unknown key for shape \"half_sine\""},
      {"half_sine_zero_duration",
       [](ojson& j) { bnd(j, 1)["time"] = {{"shape", "half_sine"}, {"duration", 0}}; },
       "boundaries[1].time.duration: must be > 0"},
      {"table_not_increasing",
       [](ojson& j) {
         bnd(j, 1)["time"] = {{"shape", "table"}, {"table", {{0, 0}, {1e-7, 1}, {1e-7, 0}}}};
       },
       "boundaries[1].time.table[2]: times must be strictly increasing"},
      {"von_mises_without_yield",
       [](ojson& j) { j["materials"]["tungsten"]["model"] = "von_mises"; },
       "materials.tungsten.yield_stress: missing required key"},
      {"elastic_with_yield",
       [](ojson& j) { j["materials"]["tungsten"]["yield_stress"] = 1e9; },
       "materials.tungsten.yield_stress: not used by model \"elastic\""},
      {"fixed_selects_no_node",
       [](ojson& j) { bnd(j, 3) = {{"type", "fixed"}, {"box", {0.0002, 0.0002, 0.0008, 0.0008}}}; },
       "boundaries[3]: selects no node"},
      {"traction_selects_no_particle", [](ojson& j) { bnd(j, 1)["width"] = 1e-5; },
       "boundaries[1]: selects no particle"},
      {"roller_without_component", [](ojson& j) { bnd(j, 0).erase("component"); },
       "boundaries[0].component: missing required key"},
      {"silent_unknown_key", [](ojson& j) { bnd(j, 2)["normal"] = 1; },
       "boundaries[2].normal: unknown key for a silent boundary"},
      {"probe_region_and_at",
       [](ojson& j) { j["probes"][0]["region"] = {0.001, 0.001, 0.002, 0.002}; },
       "probes[0].region: give either at (a point) or region (a box), not both"},
      {"probe_region_reversed",
       [](ojson& j) { j["probes"][0] = {{"name", "R"}, {"region", {0.003, 0.001, 0.002, 0.002}}}; },
       "probes[0].region: must be [x0, y0, x1, y1] with x0 < x1 and y0 < y1"},
      {"probe_region_outside_grid",
       [](ojson& j) { j["probes"][0] = {{"name", "R"}, {"region", {0.02, 0.0, 0.03, 0.001}}}; },
       "probes[0].region: outside the grid"},
      {"probe_region_empty",
       [](ojson& j) { j["probes"][0] = {{"name", "R"}, {"region", {0.002, 0.007, 0.003, 0.008}}}; },
       "probes[0].region: [0.002, 0.007, 0.003, 0.008] holds no particle"},
      {"probe_region_three_numbers",
       [](ojson& j) { j["probes"][0] = {{"name", "R"}, {"region", {0.002, 0.007, 0.003}}}; },
       "probes[0].region"},
      {"pml_selects_no_particle",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 1e-4}};
       },
       "boundaries[2].width: selects no particle"},
      {"probe_neither_at_nor_region", [](ojson& j) { j["probes"][0].erase("at"); },
       "probes[0].at: missing required key (at [x, y], or region [x0, y0, x1, y1])"},
      {"probe_contact_force_single_field",
       [](ojson& j) {
         j["probes"][0] = {{"name", "R"}, {"region", {0.0, 0.0, 0.01, 0.005}}, {"body", "plate"},
                           {"fields", {"fcx"}}};
       },
       "probes[0].fields[0]: \"fcx\" is the contact force on the probe's body: it needs \"body\" "
       "and contact.type \"multi\""},
      {"probe_point_momentum", [](ojson& j) { j["probes"][0]["fields"] = {"sxx", "px"}; },
       "probes[0].fields[1]: \"px\" is a field of region probes (give region instead of at)"},
      {"output_field_unknown", [](ojson& j) { j["output"]["fields"] = {"velocity", "stres"}; },
       "output.fields[1]: unknown field \"stres\" (did you mean \"stress\"?)"},
      {"output_field_twice", [](ojson& j) { j["output"]["fields"] = {"J2", "J2"}; },
       "output.fields[1]: \"J2\" is listed twice"},
      {"output_fields_not_a_list", [](ojson& j) { j["output"]["fields"] = "velocity"; },
       "output.fields: expected an array"},
      {"output_field_not_a_string", [](ojson& j) { j["output"]["fields"] = {1}; },
       "output.fields[0]: expected a string"},
      {"output_compression_above_9", [](ojson& j) { j["output"]["compression"] = 10; },
       "output.compression: must be <= 9, got 10"},
      {"output_compression_negative", [](ojson& j) { j["output"]["compression"] = -1; },
       "output.compression: must be >= 0, got -1"},
      {"output_compression_not_whole", [](ojson& j) { j["output"]["compression"] = 1.5; },
       "output.compression: expected an integer"},
      {"gravity_not_a_pair", [](ojson& j) { j["gravity"] = {0, -9.81, 0}; },
       "gravity: expected"},
      {"gravity_not_numbers", [](ojson& j) { j["gravity"] = {"down", 1}; },
       "gravity"},
      {"damping_layer_without_width",
       [](ojson& j) { bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"}}; },
       "boundaries[2].width: missing required key (the layer's thickness, m)"},
      {"damping_layer_r0_out_of_range",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"},
                      {"width", 0.002}, {"r0", 1.5}};
       },
       "boundaries[2].r0: must be in (0, 1), got 1.5"},
      {"damping_layer_negative_beta",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"},
                      {"width", 0.002}, {"beta", -1e-7}};
       },
       "boundaries[2].beta: must be >= 0"},
      {"damping_layer_beta_lowers_the_limit",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"},
                      {"width", 0.002}, {"beta", 1e-5}};
         j["time"].erase("cfl");
         j["time"]["dt"] = 1e-8;
       },
       "lowered by a damping_layer's beta"},
      {"damping_layer_thicker_than_body",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"}, {"width", 1.0}};
       },
       "boundaries[2].width: must be <= the size of body \"plate\""},
      {"damping_layer_unknown_key",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "damping_layer"}, {"body", "plate"}, {"side", "bottom"},
                      {"width", 0.002}, {"a", 1}};
       },
       "boundaries[2].a: unknown key for a damping_layer boundary"},
      {"pml_under_musl_at_one_particle_per_cell",
       [](ojson& j) {
         j["scheme"]["update"] = "MUSL";
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "left"}, {"width", 0.01}};
       },
       "boundaries[2].alpha: a pml on particles under scheme.update \"MUSL\" at 1 particle per "
       "cell (body \"plate\") needs alpha >= 0.04 sqrt(d0 c_d / h) = "},
      {"pml_under_musl_multi_contact",
       [](ojson& j) {
         j["scheme"]["update"] = "MUSL";
         j["contact"] = {{"type", "multi"}};
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002}};
       },
       "boundaries[2].type: a pml on particles under scheme.update \"MUSL\" is not available "
       "with multi-field contact"},
      {"pml_under_usf_at_one_particle_per_cell",
       [](ojson& j) {
         j["scheme"]["update"] = "USF";
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "left"}, {"width", 0.01}};
       },
       "boundaries[2].alpha: a pml on particles under scheme.update \"USF\" at 1 particle per "
       "cell (body \"plate\") needs alpha >= 0.04 sqrt(d0 c_d / h) = "},
      {"pml_under_usf_at_one_particle_per_cell_thin",
       [](ojson& j) {
         j["scheme"]["update"] = "USF";
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"alpha", 1e9}};
       },
       "boundaries[2].width: a pml on particles under scheme.update \"USF\" at 1 particle per "
       "cell (body \"plate\") needs width >= 10 cells ("},
      {"pml_under_usf_multi_contact",
       [](ojson& j) {
         j["scheme"]["update"] = "USF";
         j["contact"] = {{"type", "multi"}};
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002}};
       },
       "boundaries[2].type: a pml on particles under scheme.update \"USF\" is not available "
       "with multi-field contact"},
      {"pml_parallel_not_below_one",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"parallel", 1.0}};
       },
       "boundaries[2].parallel: must be < 1, got 1"},
      {"pml_parallel_negative",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"parallel", -0.1}};
       },
       "boundaries[2].parallel: must be >= 0, got -0.1"},
      {"pml_thicker_than_body",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 1.0}};
       },
       "boundaries[2].width: must be <= the size of body \"plate\""},
      {"pml_alpha_negative",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"alpha", -1}};
       },
       "boundaries[2].alpha: must be >= 0"},
      {"pml_alpha_not_auto",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"alpha", "automatic"}};
       },
       "boundaries[2].alpha: must be a number >= 0 or \"auto\", got \"automatic\""},
      {"pml_alpha_auto_differs",
       [](ojson& j) {
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "left"}, {"width", 0.01},
                      {"alpha", "auto"}};
         j["boundaries"].push_back({{"type", "pml"}, {"body", "plate"}, {"side", "right"},
                                    {"width", 0.01}, {"r0", 0.01}, {"alpha", "auto"}});
       },
       "boundaries[4].alpha: every pml must have the same alpha (\"pml2\" has "},
      {"pml_side_and_curve",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002},
                      {"curve", 3}};
       },
       "boundaries[2].side: give either side or curve, not both"},
      {"pml_two_alphas",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2) = {{"type", "pml"}, {"body", "plate"}, {"side", "bottom"}, {"width", 0.002}};
         j["boundaries"].push_back({{"type", "pml"}, {"body", "plate"}, {"side", "left"},
                                    {"width", 0.002}, {"alpha", 1e5}});
       },
       "boundaries[4].alpha: every pml must have the same alpha (\"pml2\" has 0, this one 1e+05)"},
      {"kelvin_voigt_without_delta", [](ojson& j) { bnd(j, 2)["type"] = "kelvin_voigt"; },
       "boundaries[2].delta: missing required key"},
      {"kelvin_voigt_delta_below_cell",
       [](ojson& j) { bnd(j, 2)["type"] = "kelvin_voigt"; bnd(j, 2)["delta"] = 1e-4; },
       "boundaries[2].delta: must be >= grid.cell (0.001 m), got 0.0001"},
      {"kelvin_voigt_negative_alpha",
       [](ojson& j) {
         bnd(j, 2)["type"] = "kelvin_voigt"; bnd(j, 2)["delta"] = 0.01; bnd(j, 2)["alpha_n"] = -1;
       },
       "boundaries[2].alpha_n: must be >= 0"},
      {"silent_with_delta", [](ojson& j) { bnd(j, 2)["delta"] = 0.01; },
       "boundaries[2].delta: unknown key for a silent boundary"},
      {"edge_velocity_unknown", [](ojson& j) { bnd(j, 2)["edge_velocity"] = "update"; },
       "boundaries[2].edge_velocity: must be one of \"remapped\", \"updated\", \"delayed\", got "
       "\"update\""},
      // The consistent-mass correction: 0 to 8 terms, and under MUSL or USF no silent or
      // Kelvin-Voigt edge on particles of 1 per cell.
      {"mass_correction_negative", [](ojson& j) { j["scheme"]["mass_correction"] = -1; },
       "scheme.mass_correction: must be >= 0, got -1"},
      {"mass_correction_too_many", [](ojson& j) { j["scheme"]["mass_correction"] = 9; },
       "scheme.mass_correction: must be <= 8, got 9"},
      {"mass_correction_not_integer", [](ojson& j) { j["scheme"]["mass_correction"] = 0.5; },
       "scheme.mass_correction: expected an integer, got 0.5"},
      {"mass_correction_silent_one_ppc",
       [](ojson& j) {
         j["scheme"]["mass_correction"] = 1;
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
       },
       "boundaries[2]: the silent edge \"silent2\" lies on particles of 1 per cell (the particle "
       "at (0.0005, 0.0005) fills 1 of a cell), where scheme.mass_correction under MUSL makes "
       "its dashpots reflect about 8 %"},
      {"mass_correction_kelvin_voigt_one_ppc",
       [](ojson& j) {
         j["scheme"]["mass_correction"] = 2;
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2) = {{"type", "kelvin_voigt"}, {"name", "base"}, {"body", "plate"},
                      {"side", "bottom"}, {"delta", 0.01}};
       },
       "boundaries[2]: the kelvin_voigt edge \"base\" lies on particles of 1 per cell"},
      // Its symmetric form: MUSL or USF, one velocity field, the edges' re-mapped velocity.
      {"mass_correction_form_unknown",
       [](ojson& j) { j["scheme"]["mass_correction_form"] = "half"; },
       "scheme.mass_correction_form: must be one of \"increment\", \"symmetric\", got "
       "\"half\""},
      {"mass_correction_symmetric_under_usl",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         j["scheme"]["mass_correction_form"] = "symmetric";
       },
       "scheme.mass_correction_form: \"symmetric\" needs scheme.update \"MUSL\" or \"USF\""},
      {"mass_correction_symmetric_multi_contact",
       [](ojson& j) {
         j["scheme"]["mass_correction"] = 2;
         j["scheme"]["mass_correction_form"] = "symmetric";
         j["contact"] = {{"type", "multi"}};
       },
       "contact.type: multi-field contact corrects each body's field on its own, which "
       "scheme.mass_correction_form \"symmetric\" does not do yet; use \"increment\""},
      {"mass_correction_symmetric_updated_edge",
       [](ojson& j) {
         j["scheme"]["mass_correction"] = 1;
         j["scheme"]["mass_correction_form"] = "symmetric";
         bnd(j, 2)["edge_velocity"] = "updated";
       },
       "boundaries[2].edge_velocity: \"updated\" is not available with "
       "scheme.mass_correction_form \"symmetric\""},
      // Light nodes: "keep" or "extend", a ratio in (0, 0.25] with "extend", one velocity field.
      {"light_nodes_unknown", [](ojson& j) { j["scheme"]["light_nodes"] = "merge"; },
       "scheme.light_nodes: must be one of \"keep\", \"extend\", got \"merge\""},
      {"light_node_ratio_without_extend",
       [](ojson& j) { j["scheme"]["light_node_ratio"] = 0.1; },
       "scheme.light_node_ratio: needs \"light_nodes\": \"extend\""},
      {"light_node_ratio_too_large",
       [](ojson& j) {
         j["scheme"]["light_nodes"] = "extend";
         j["scheme"]["light_node_ratio"] = 0.3;
       },
       "scheme.light_node_ratio: must be <= 0.25, got 0.3"},
      {"light_node_ratio_zero",
       [](ojson& j) {
         j["scheme"]["light_nodes"] = "extend";
         j["scheme"]["light_node_ratio"] = 0;
       },
       "scheme.light_node_ratio: must be > 0, got 0"},
      {"light_nodes_multi_contact",
       [](ojson& j) {
         j["scheme"]["light_nodes"] = "extend";
         j["contact"] = {{"type", "multi"}};
       },
       "contact.type: multi-field contact keeps each body's own field, which "
       "scheme.light_nodes \"extend\" does not extend yet; use \"keep\""},
      // Gauss seeding: a box of whole cells, point particles.
      {"seeding_unknown", [](ojson& j) { j["bodies"][0]["seeding"] = "gauss_legendre"; },
       "bodies[0].seeding: must be one of \"uniform\", \"gauss\", got \"gauss_legendre\""},
      {"seeding_gauss_part_cells",
       [](ojson& j) {
         j["bodies"][0]["seeding"] = "gauss";
         j["bodies"][0]["box"] = {0, 0, 0.01, 0.0045};
       },
       "bodies[0].seeding: \"gauss\" needs a box of whole grid cells, its sides on the grid's "
       "lines (its Gauss points are the cells'), got [0, 0, 0.01, 0.0045]"},
      {"seeding_gauss_off_the_grid_lines",
       [](ojson& j) {
         j["bodies"][0]["seeding"] = "gauss";
         j["bodies"][0]["box"] = {0.0005, 0, 0.0095, 0.005};
       },
       "bodies[0].seeding: \"gauss\" needs a box of whole grid cells, its sides on the grid's "
       "lines"},
      {"seeding_gauss_gimp",
       [](ojson& j) {
         j["scheme"]["shape"] = "gimp";
         j["bodies"][0]["seeding"] = "gauss";
       },
       "bodies[0].seeding: \"gauss\" is for point particles"},
      // The delayed closure: MUSL or USF, the nodal form, LK a = b = 1, 1 particle per cell, the
      // edge on a grid line along an axis.
      {"delayed_under_usl",
       [](ojson& j) {
         j["scheme"]["update"] = "USL";
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" applies under scheme.update \"MUSL\" or \"USF\""},
      {"delayed_lk_coefficient",
       [](ojson& j) {
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["a"] = 0.5;
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" needs a = b = 1"},
      {"delayed_springs",
       [](ojson& j) {
         bnd(j, 2) = {{"type", "kelvin_voigt"}, {"body", "plate"}, {"side", "bottom"},
                      {"delta", 0.01}, {"edge_velocity", "delayed"}};
       },
       "boundaries[2].edge_velocity: \"delayed\" is not available with Kelvin-Voigt springs"},
      {"delayed_particle_anchor",
       [](ojson& j) {
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["anchor"] = "particle";
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" needs \"anchor\": \"boundary\""},
      {"delayed_bspline",
       [](ojson& j) {
         j["scheme"]["shape"] = "bspline";
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" needs scheme.shape \"bilinear\""},
      {"delayed_with_damping_layer",
       [](ojson& j) {
         j["bodies"][0]["particles_per_cell"] = 1;
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "delayed";
         j["boundaries"].push_back(
             {{"type", "damping_layer"}, {"body", "plate"}, {"side", "top"}, {"width", 0.002}});
       },
       "boundaries[2].edge_velocity: \"delayed\" must be on every nodal silent edge of the case, "
       "with no kelvin_voigt, damping_layer or pml"},
      {"delayed_four_ppc",
       [](ojson& j) {
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" needs 1 particle per cell (the particle at "
       "(0.00025, 0.00025) fills 0.25 of a cell)"},
      {"delayed_off_grid_line",
       [](ojson& j) {
         j["bodies"][0]["particles_per_cell"] = 1;
         j["bodies"][0]["box"] = {0, 0.0003, 0.01, 0.0053};
         bnd(j, 0) = {{"type", "fixed"}, {"grid_side", "right"}};
         bnd(j, 1)["width"] = 0.001;
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "delayed";
       },
       "boundaries[2].edge_velocity: \"delayed\" needs the edge on a grid line (the edge at the "
       "particle at (0.0005, 0.0008) lies 0.3 of a cell off one)"},
      {"edge_velocity_under_usl",
       [](ojson& j) { j["scheme"]["update"] = "USL"; bnd(j, 2)["edge_velocity"] = "updated"; },
       "boundaries[2].edge_velocity: \"updated\" applies under scheme.update \"MUSL\" or \"USF\""},
      {"edge_velocity_particle_form",
       [](ojson& j) { bnd(j, 2)["form"] = "particle"; bnd(j, 2)["edge_velocity"] = "updated"; },
       "boundaries[2].edge_velocity: \"updated\" needs the nodal form"},
      {"edge_velocity_multi_contact",
       [](ojson& j) {
         j["contact"] = {{"type", "multi"}};
         bnd(j, 2)["form"] = "nodal";
         bnd(j, 2)["edge_velocity"] = "updated";
       },
       "boundaries[2].edge_velocity: \"updated\" is not available with multi-field contact"},
      {"traction_both_forms", [](ojson& j) { bnd(j, 1)["vector"] = {0, 1}; },
       "boundaries[1].vector: give either normal/tangential or vector"},
      {"unknown_boundary_body", [](ojson& j) { bnd(j, 2)["body"] = "plat"; },
       "boundaries[2].body: no body named \"plat\" (did you mean \"plate\"?)"},
      {"negative_threads", [](ojson& j) { j["scheme"]["threads"] = -2; },
       "scheme.threads: must be >= 0"},
      {"shape_grid_too_small",
       [](ojson& j) { j["grid"]["cell"] = 0.01; j["scheme"]["shape"] = "bspline"; },
       "scheme.shape: \"bspline\" needs a grid of at least 2 x 2 cells, got 1 x 1"},
      {"unknown_shape", [](ojson& j) { j["scheme"]["shape"] = "bsplines"; },
       "scheme.shape: must be one of \"bilinear\", \"gimp\", \"bspline\", got \"bsplines\""},
      {"override_missing_path", nullptr, "bodies[3]: does not exist", "",
       {"bodies.3.particles_per_cell=4"}},
      {"override_bad_value", nullptr,
       "grid.cell: must be > 0, got -1 (value set by override 'grid.cell=-1')", "",
       {"grid.cell=-1"}},
  };
}

fs::path bad_file(const Bad& b) {
  return write_file("bad_" + b.name + ".json",
                    b.text.empty() ? [&] {
                      ojson j = valid_doc();
                      if (b.edit) b.edit(j);
                      return j.dump(2);
                    }()
                                   : b.text);
}

class CaseErrors : public ::testing::TestWithParam<Bad> {};

TEST_P(CaseErrors, NamesTheKeyPath) {
  const Bad& b = GetParam();
  const fs::path file = bad_file(b);
  try {
    smpm::load_case(file.string(), b.overrides);
    FAIL() << b.name << ": no error";
  } catch (const smpm::CaseError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << "message must start with the source: "
                                                      << msg;
    EXPECT_NE(msg.find(b.expect), std::string::npos)
        << "expected \"" << b.expect << "\" in\n  " << msg;
    // One readable line, whatever the input.
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_LE(msg.size(), 2000u + file.string().size()) << msg;
  }
}

std::string param_name(const ::testing::TestParamInfo<Bad>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(CaseMalformed, CaseErrors, ::testing::ValuesIn(bad_cases()), param_name);

// ---------------------------------------------------------------------------------------------
// The same files through the CLI: non-zero exit, the message on stderr.
struct CliResult {
  int status;
  std::string out, err;
};

CliResult run_cli(const std::string& args, const std::string& tag) {
  const fs::path out = scratch() / ("cli_" + tag + ".out");
  const fs::path err = scratch() / ("cli_" + tag + ".err");
  const std::string cmd = "\"" + std::string(SMPM_CLI) + "\" " + args + " >\"" + out.string() +
                          "\" 2>\"" + err.string() + "\"";
  const int status = std::system(cmd.c_str());
  return {status, read_file(out), read_file(err)};
}

bool have_cli() { return std::string(SMPM_CLI).size() > 0 && fs::exists(SMPM_CLI); }

class CaseCli : public ::testing::TestWithParam<Bad> {};

TEST_P(CaseCli, CheckFailsWithMessage) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const Bad& b = GetParam();
  const fs::path file = bad_file(b);
  std::string args = "check \"" + file.string() + "\"";
  for (const auto& o : b.overrides) args += " --set '" + o + "'";
  const CliResult r = run_cli(args, b.name);
  EXPECT_NE(r.status, 0) << b.name << ": exit status 0; stdout:\n" << r.out;
  EXPECT_NE(r.err.find(b.expect), std::string::npos)
      << "expected \"" << b.expect << "\" on stderr, got:\n" << r.err;
}

INSTANTIATE_TEST_SUITE_P(CaseMalformed, CaseCli, ::testing::ValuesIn(bad_cases()), param_name);

TEST(CaseCliValid, CheckSucceeds) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path file = write_file("valid_cli.json", kValid);
  const CliResult r = run_cli("check \"" + file.string() + "\"", "valid");
  EXPECT_EQ(r.status, 0) << "stderr:\n" << r.err;
}


// The CLI's --threads and --quiet on a case without "scheme" and "output" sections (they are
// created; --set, in contrast, must name existing sections): the run uses the thread count given.
TEST(CaseCliValid, RunThreadsWithoutSchemeOrOutputSection) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  std::string text = kValid;
  for (const char* key : {"  \"scheme\":", "  \"output\":"}) {
    const std::size_t a = text.find(key);
    ASSERT_NE(a, std::string::npos) << key;
    const std::size_t b = text.find('\n', a);
    text.erase(a, b - a + 1);
  }
  if (text.find(",\n}") != std::string::npos) text.replace(text.find(",\n}"), 3, "\n}");
  const fs::path file = write_file("no_scheme_cli.json", text.c_str());
  const fs::path out = scratch() / "no_scheme_cli_out";
  const CliResult r = run_cli("run \"" + file.string() + "\" --out \"" + out.string() + "\" --threads 1 --quiet",
                              "no_scheme");
  ASSERT_EQ(r.status, 0) << "stderr:\n" << r.err;
  const std::string summary = read_file(out / "summary.json");
  EXPECT_NE(summary.find("\"threads\": 1"), std::string::npos) << summary;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet: nothing but errors
  EXPECT_TRUE(r.err.empty()) << r.err;
  // --shape together with --threads on the same missing section: both are set.
  const fs::path out2 = scratch() / "no_scheme_cli_shape_out";
  const CliResult r2 = run_cli("run \"" + file.string() + "\" --out \"" + out2.string() +
                                   "\" --threads 1 --shape bspline --quiet",
                               "no_scheme_shape");
  ASSERT_EQ(r2.status, 0) << "stderr:\n" << r2.err;
  const std::string summary2 = read_file(out2 / "summary.json");
  EXPECT_NE(summary2.find("\"threads\": 1"), std::string::npos) << summary2;
  EXPECT_NE(summary2.find("\"shape\": \"bspline\""), std::string::npos) << summary2;
  // A wrong shape is one error naming the key.
  const CliResult r3 = run_cli("run \"" + file.string() + "\" --out \"" + out2.string() +
                                   "\" --shape quadratic --quiet",
                               "no_scheme_bad_shape");
  EXPECT_EQ(WEXITSTATUS(r3.status), 1);
  EXPECT_NE(r3.err.find("scheme.shape: must be one of \"bilinear\", \"gimp\", \"bspline\""),
            std::string::npos) << r3.err;
}

// Command-line mistakes: one line, exit 1 (not CLI11's codes of 100 and more).
TEST(CaseCliFaults, CommandLineErrors) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path file = write_file("cli_errors.json", kValid);
  const std::string out = (scratch() / "cli_errors_out").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"run \"" + file.string() + "\" --out " + out + " --threads -3",
       "--threads: must be a whole number from 0 (all cores) to 4096, got \"-3\""},
      {"run \"" + file.string() + "\" --out " + out + " --threads four",
       "--threads: must be a whole number from 0 (all cores) to 4096, got \"four\""},
      {"chek \"" + file.string() + "\"", "unknown command \"chek\" (did you mean \"check\"?)"},
      {"run \"" + file.string() + "\"", "--out"},
  };
  const CliResult v = run_cli("--version", "cli_version");
  EXPECT_EQ(WEXITSTATUS(v.status), 0) << v.err;
  EXPECT_EQ(v.out.rfind("silentmpm 0.", 0), 0u) << v.out;
  int k = 0;
  for (const auto& [args, expect] : cases) {
    const CliResult r = run_cli(args, "cli_error_" + std::to_string(k++));
    EXPECT_EQ(WEXITSTATUS(r.status), 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(expect), std::string::npos) << args << "\n" << r.err;
  }
}

// A rerun into the same folder removes what the earlier run wrote and it will own (here its
// snapshots, which the rerun does not write) and leaves other files alone.
TEST(CaseCliFaults, RerunLeavesNoStaleOutputs) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path file = write_file("rerun.json", kValid);
  const fs::path out = scratch() / "rerun_out";
  fs::remove_all(out);
  const std::string run = "run \"" + file.string() + "\" --out \"" + out.string() + "\" --quiet";
  const CliResult a = run_cli(run + " --set output.snapshots=2", "rerun_a");
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_TRUE(fs::exists(out / "particles.h5"));
  ASSERT_TRUE(fs::exists(out / "particles.xdmf"));
  std::ofstream(out / "notes.txt") << "mine\n";
  const CliResult b = run_cli(run, "rerun_b");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_FALSE(fs::exists(out / "particles.h5"));
  EXPECT_FALSE(fs::exists(out / "particles.xdmf"));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(fs::exists(out / "history.csv"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
}

// Disk full while writing summary.json (its temporary file is a link to /dev/full): one error
// naming the file and the cause, exit 2 (the run failed), no summary.json (nothing that looks
// complete) and RUN_INCOMPLETE saying why.
TEST(CaseCliFaults, DiskFullWritingSummary) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path file = write_file("disk_full.json", kValid);
  const fs::path out = scratch() / "disk_full_out";
  fs::remove_all(out);
  fs::create_directories(out);
  fs::create_symlink("/dev/full", out / "summary.json.tmp");
  const CliResult r = run_cli("run \"" + file.string() + "\" --out \"" + out.string() + "\" --quiet",
                              "disk_full");
  EXPECT_EQ(WEXITSTATUS(r.status), 2);
  EXPECT_NE(r.err.find("summary.json: cannot write: No space left on device"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  EXPECT_NE(read_file(out / "RUN_INCOMPLETE").find("No space left on device"), std::string::npos);
  EXPECT_FALSE(fs::exists(fs::symlink_status(out / "summary.json.tmp")));
}

}  // namespace

// silentmpm compare: one column prints the bare number, several a table, --json every figure;
// errors name the file (exit 1).
TEST(CompareCli, ColumnsTableJsonAndErrors) {
  if (!have_cli()) GTEST_SKIP() << "CLI not built";
  const fs::path a = scratch() / "cmp_a.csv", b = scratch() / "cmp_b.csv";
  {
    std::ofstream fa(a), fb(b);
    fa << "time,A.sxx,A.vx\n";
    fb << "time,A.sxx,A.vx\n";
    for (int k = 0; k <= 100; ++k) {
      const double t = 0.01 * k;
      fa << t << "," << 1.0 * t << "," << 2.0 * t << "\n";
      fb << t << "," << 1.0 * t << "," << 2.5 * t << "\n";
    }
  }
  const std::string files = "\"" + a.string() + "\" \"" + b.string() + "\"";
  CliResult r = run_cli("compare " + files + " -c A.vx", "cmp_one");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NEAR(std::stod(r.out), 0.2, 1e-12);  // |2 - 2.5| / 2.5
  r = run_cli("compare " + files + " --all", "cmp_all");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("column"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("A.sxx   0.000000e+00"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("A.vx    2.000000e-01"), std::string::npos) << r.out;
  r = run_cli("compare " + files + " -c A.sxx,A.vx --json --from 0 --to 0.5 --norm-to 1", "cmp_json");
  EXPECT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // ||a - b|| over [0, 0.5] / ||b|| over [0, 1]: 0.5 sqrt(sum_{k<=50} t^2 / sum_{k<=100} t^2).
  double s50 = 0, s100 = 0;
  for (int k = 0; k <= 100; ++k) (k <= 50 ? s50 : s100) += 1e-4 * k * k;
  s100 += s50;
  EXPECT_NEAR(j["columns"]["A.vx"]["relative"].get<double>(), 0.2 * std::sqrt(s50 / s100), 1e-9);
  EXPECT_EQ(j["columns"]["A.vx"]["samples"].get<int>(), 51);
  EXPECT_EQ(j["columns"]["A.vx"]["norm_samples"].get<int>(), 101);
  EXPECT_EQ(j["b"].get<std::string>(), b.string());
  r = run_cli("compare " + files + " -c A.vy", "cmp_missing");
  EXPECT_EQ(WEXITSTATUS(r.status), 1);
  EXPECT_NE(r.err.find(a.string() + ": no column 'A.vy' (columns: A.sxx, A.vx)"), std::string::npos) << r.err;
  r = run_cli("compare " + files, "cmp_none");
  EXPECT_EQ(WEXITSTATUS(r.status), 1);
  EXPECT_NE(r.err.find("give --column (one or more) or --all"), std::string::npos) << r.err;
}
