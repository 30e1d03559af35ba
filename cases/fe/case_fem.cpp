// Case files with an FEM region ("fem" at the top level): parsing, validation, and construction of
// the fem::Solver. Keys are documented in docs/case-reference.md (section "fem"). Every problem
// is a CaseError "<source>: <key path>: <what>", as for the MPM sections.
//
// Layout of an FEM-only case: title, time, scheme (threads only), materials, fem, probes, output.
// A case with both MPM bodies and an FEM region is the coupled hybrid (case_hybrid.cpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <set>

#include "case_fem.hpp"
#include "case_keys.hpp"
#include "case_util.hpp"

namespace smpm::detail {
namespace {

namespace fs = std::filesystem;
constexpr Dialect kFem = Dialect::Fem;

// Mesh paths are relative to the case file's folder (or the working directory when the case
// does not come from a file).
std::string resolve_path(const std::string& source, const std::string& file) {
  const fs::path p(file);
  if (p.is_absolute()) return file;
  std::error_code ec;
  const fs::path src(source);
  if (fs::is_regular_file(src, ec)) return (src.parent_path() / p).lexically_normal().string();
  return file;
}

std::vector<std::string> group_list(const std::vector<fem::PhysicalGroup>& gs) {
  std::vector<std::string> v;
  for (const auto& g : gs) v.push_back(std::to_string(g.tag) + (g.name.empty() ? "" : " \"" + g.name + "\""));
  return v;
}

// A physical group given as a name or a tag (string or integer).
// Without a mesh (the pass that checks the keys before meshing) only the type is checked and -1
// returned.
int group_ref(const Ctx& ctx, const ojson& v, const std::string& path, const fem::Mesh* m,
              bool surface) {
  std::string key;
  if (v.is_number_integer()) key = std::to_string(v.get<long>());
  else if (v.is_string()) key = v.get<std::string>();
  else ctx.fail(path, "expected a group name or tag, got " + a_type(v));
  if (!m) return -1;
  const fem::Mesh& mesh = *m;
  const int tag = surface ? mesh.surface_tag(key) : mesh.curve_tag(key);
  if (tag < 0)
    ctx.fail(path, "no physical " + std::string(surface ? "surface" : "curve") + " \"" + key +
                       "\" in " + mesh.file + "; it has: " +
                       join(group_list(surface ? mesh.surfaces : mesh.curves)));
  return tag;
}

// Every field an FEM probe samples.
const std::vector<std::string> kFemFields = {"sxx", "syy", "szz", "sxy", "J2",
                                             "vx",  "vy",  "div", "curl"};

}  // namespace

std::vector<std::string> fem_probe_fields(Obj& o, const std::vector<std::string>& absent) {
  const ojson* fl = o.find("fields");
  if (!fl) return absent;
  if (!fl->is_array() || fl->empty()) o.fail("fields", "expected a non-empty array of field names");
  std::vector<std::string> fields;
  for (std::size_t k = 0; k < fl->size(); ++k) {
    const std::string fp = index_path(o.at("fields"), k);
    if (!(*fl)[k].is_string()) o.ctx().fail(fp, "expected a string");
    const std::string name = (*fl)[k].get<std::string>();
    if (std::find(kFemFields.begin(), kFemFields.end(), name) == kFemFields.end())
      o.ctx().fail(fp, "must be one of " + join(kFemFields) + ", got \"" + name + "\"");
    if (std::find(fields.begin(), fields.end(), name) != fields.end())
      o.ctx().fail(fp, "field \"" + name + "\" listed twice");
    fields.push_back(name);
  }
  return fields;
}

Case build_fem_case(const Ctx& ctx, const ojson& doc, bool scatter, bool skeleton) {
  const std::string& source = ctx.source;
  Obj top(ctx, doc, "", kFem);
  if (top.has("bodies") || top.has("grid"))
    top.fail("fem", "a case with both an MPM region (grid, bodies) and an FEM region is not "
                    "supported yet (the coupled MPM-FEM hybrid); give either grid + bodies or fem");
  top.allow({"title", "time", "scheme", "materials", "fem", "probes", "output", "gravity"},
            "in an FEM case");
  for (const char* k : {"time", "materials", "fem"})
    if (!top.has(k)) top.fail(k, "missing required key");

  Case c;
  c.source = source;
  if (top.has("title")) c.title = top.str("title");

  // time
  Obj t = top.obj("time");
  t.allow({"end", "dt", "cfl"});
  c.t_end = t.num("end");
  t.gt("end", c.t_end, 0);
  if (t.has("dt") == t.has("cfl"))
    t.fail("", t.has("dt") ? "give either dt or cfl, not both"
                           : "missing dt or cfl (give exactly one: a time step in s, or a "
                             "fraction of the stability limit)");
  const bool use_cfl = t.has("cfl");
  const double dt_or_cfl = use_cfl ? t.num("cfl") : t.num("dt");
  if (use_cfl) {
    t.gt("cfl", dt_or_cfl, 0);
    t.le("cfl", dt_or_cfl, 1);
  } else {
    t.gt("dt", dt_or_cfl, 0);
  }

  // scheme: threads only
  int threads = 0;
  if (top.has("scheme")) {
    Obj s = top.obj("scheme");
    s.allow({"threads"}, "in an FEM case (update and flip are MPM settings)");
    const long th = s.integer("threads", 0);
    s.ge("threads", static_cast<double>(th), 0);
    s.le("threads", static_cast<double>(th), 4096);
    threads = static_cast<int>(th);
  }

  // output
  if (top.has("output")) {
    Obj o = top.obj("output");
    if (o.has("fields"))
      o.fail("fields", "chooses the particle snapshot's fields; an FEM case has no particles");
    if (o.has("grid") && o.boolean("grid", false))
      o.fail("grid", "writes the MPM grid's nodal snapshots; an FEM case has no MPM grid");
    parse_output_section(o, c.output, 100000);
  }

  // materials
  const ojson& mats = top.need("materials");
  if (!mats.is_object()) top.fail("materials", "expected an object {name: {...}}, got " + a_type(mats));
  if (mats.empty()) top.fail("materials", "must define at least one material");
  std::vector<Material> materials;
  std::vector<std::string> mat_names;
  for (const auto& it : mats.items()) {
    materials.push_back(parse_material_at(ctx, it.key(), it.value()));
    mat_names.push_back(it.key());
  }

  // fem
  Obj f = top.obj("fem");
  f.allow({"mesh", "size", "parameters", "degree", "regions", "boundaries"});
  fem::Spec spec;
  spec.threads = threads;
  const std::string mesh_file = resolve_path(source, f.str("mesh"));
  double size = 0;
  if (f.has("size")) {
    size = f.num("size");
    f.gt("size", size, 0);
  }
  const auto parameters = read_geo_parameters(f);
  const long degree = f.integer("degree", 1);
  if (degree != 1 && degree != 2) f.fail("degree", "must be 1 or 2, got " + std::to_string(degree));
  spec.degree = static_cast<int>(degree);
  // probes: every key before meshing (solver null), then placed in the solver.
  // On a rank set up from rank 0 (skeleton) the probes are listed unplaced: rank 0 places them
  // and sends each rank its parts.
  auto read_probes = [&](const ojson& p, fem::Solver* solver) {
    const bool place = solver && !solver->is_skeleton();
    if (!p.is_array()) top.fail("probes", "expected an array, got " + a_type(p));
    std::vector<std::string> names;
    for (std::size_t i = 0; i < p.size(); ++i) {
      Obj o(ctx, p[i], index_path("probes", i), kFem);
      o.allow({"name", "at", "fields"});
      ProbeSpec pr;
      pr.name = o.str("name");
      static const std::regex ok("[A-Za-z0-9_]+");
      if (!std::regex_match(pr.name, ok))
        o.fail("name", "must be letters, digits and _ only, got \"" + pr.name + "\"");
      if (std::count(names.begin(), names.end(), pr.name))
        o.fail("name", "probe name \"" + pr.name + "\" is used twice");
      names.push_back(pr.name);
      const auto at = o.nums("at", 2);
      pr.x = at[0];
      pr.y = at[1];
      if (place && solver->add_probe(pr.x, pr.y) < 0) {
        const auto bb = solver->bounds();
        o.fail("at", "outside the FEM mesh (bounding box [" + fmt(bb[0]) + ", " + fmt(bb[2]) +
                         "] x [" + fmt(bb[1]) + ", " + fmt(bb[3]) + "]): (" + fmt(pr.x) + ", " +
                         fmt(pr.y) + ")");
      }
      pr.fields = fem_probe_fields(o, kFemFields);
      if (solver) c.probes.push_back(std::move(pr));
    }
  };

  // regions, gravity and boundaries: read once before meshing without the mesh (every key,
  // type and value checked, so that a mistake there does not wait for the mesher), then with it.
  auto read_model = [&](fem::Spec& spec, const fem::Mesh* mesh) {
    // regions: physical surface (name or tag) -> material name; every surface needs one.
    const ojson& regs = f.need("regions");
    if (!regs.is_object() || regs.empty())
      f.fail("regions", "expected an object {physical surface: material name, ...}, got " +
                            (regs.is_object() ? std::string("an empty object") : a_type(regs)));
    std::set<std::string> used_mats;
    for (const auto& it : regs.items()) {
      const std::string path = f.at("regions") + "." + it.key();
      const int tag = group_ref(ctx, ojson(it.key()), path, mesh, true);
      if (mesh && spec.region_material.count(tag))
        ctx.fail(path, "physical surface " + std::to_string(tag) + " given twice");
      if (!it.value().is_string())
        ctx.fail(path, "expected a material name, got " + a_type(it.value()));
      const std::string mname = it.value().get<std::string>();
      auto mi = std::find(mat_names.begin(), mat_names.end(), mname);
      if (mi == mat_names.end())
        ctx.fail(path, "no material named \"" + mname + "\"; defined: " + join(mat_names));
      const Material& m = materials[mi - mat_names.begin()];
      if (m.model != Model::Elastic)
        ctx.fail(path, "material \"" + mname + "\" has model \"" + model_name(m.model) +
                           "\"; the FEM far-field is linear elastic (use \"elastic\")");
      spec.region_material[tag] = static_cast<int>(mi - mat_names.begin());
    }
    for (const auto& g : mesh ? mesh->surfaces : std::vector<fem::PhysicalGroup>())
      if (!spec.region_material.count(g.tag))
        f.fail("regions", "physical surface " + std::to_string(g.tag) +
                              (g.name.empty() ? "" : " \"" + g.name + "\"") + " of " + mesh_file +
                              " has no material");
    spec.materials = materials;
    if (top.has("gravity")) {  // a body force per unit mass on every FE node's mass (m/s^2)
      const auto g = top.nums("gravity", 2);
      spec.gravity_x = g[0];
      spec.gravity_y = g[1];
    }

    // boundaries
    if (const ojson* b = f.find("boundaries")) {
      if (!b->is_array()) f.fail("boundaries", "expected an array, got " + a_type(*b));
      for (std::size_t i = 0; i < b->size(); ++i) {
        const std::string path = index_path(f.at("boundaries"), i);
        Obj o(ctx, (*b)[i], path, kFem);
        const std::string type =
            o.choice("type", {"dashpot", "kelvin_voigt", "damping_layer", "pml", "traction", "fixed", "roller"});
        const std::string where = "for a " + type + " boundary";
        if (type == "dashpot") o.allow({"type", "name", "curve", "a", "b"}, where);
        if (type == "kelvin_voigt")
          o.allow({"type", "name", "curve", "a", "b", "delta", "alpha_n", "alpha_t"}, where);
        if (type == "traction")
          o.allow({"type", "name", "curve", "normal", "tangential", "vector", "time"}, where);
        if (type == "fixed") o.allow({"type", "name", "curve"}, where);
        if (type == "damping_layer") o.allow({"type", "name", "curve", "width", "r0", "power", "beta"}, where);
        if (type == "pml") o.allow({"type", "name", "curve", "width", "r0", "power", "alpha", "parallel"}, where);
        if (type == "roller") o.allow({"type", "name", "curve", "component"}, where);
        fem::Boundary bc;
        bc.name = o.has("name") ? o.str("name") : type + std::to_string(i);
        const ojson& cv = o.need("curve");
        if (cv.is_array()) {
          if (cv.empty()) o.fail("curve", "must name at least one physical curve");
          for (std::size_t k = 0; k < cv.size(); ++k)
            bc.curves.push_back(group_ref(ctx, cv[k], index_path(o.at("curve"), k), mesh, false));
        } else {
          bc.curves.push_back(group_ref(ctx, cv, o.at("curve"), mesh, false));
        }
        if (type == "dashpot" || type == "kelvin_voigt") {
          bc.kind = fem::Boundary::Kind::Dashpot;
          bc.a = o.num("a", 1.0);
          o.ge("a", bc.a, 0);
          bc.b = o.num("b", 1.0);
          o.ge("b", bc.b, 0);
          if (type == "kelvin_voigt") {  // the springs' stiffness enters the critical time step
            bc.delta = o.num("delta");
            o.gt("delta", bc.delta, 0);
            bc.alpha_n = o.num("alpha_n", 1.0);
            o.ge("alpha_n", bc.alpha_n, 0);
            bc.alpha_t = o.num("alpha_t", 1.0);
            o.ge("alpha_t", bc.alpha_t, 0);
          }
          for (const auto& other : spec.boundaries)
            if (mesh && other.kind == fem::Boundary::Kind::Dashpot)
              for (int cc : bc.curves)
                if (std::count(other.curves.begin(), other.curves.end(), cc))
                  o.fail("curve", "physical curve " + std::to_string(cc) + " already has a dashpot (\"" +
                                      other.name + "\")");
        } else if (type == "traction") {
          bc.kind = fem::Boundary::Kind::Traction;
          const bool scalar = o.has("normal") || o.has("tangential");
          if (scalar && o.has("vector")) o.fail("vector", "give either normal/tangential or vector, not both");
          if (!scalar && !o.has("vector"))
            o.fail("", "missing the traction: give normal and/or tangential, or vector");
          if (scalar) {
            bc.normal = o.num("normal", 0.0);
            bc.tangential = o.num("tangential", 0.0);
          } else {
            const auto v = o.nums("vector", 2);
            bc.vx = v[0];
            bc.vy = v[1];
          }
          if (const ojson* tf = o.find("time")) bc.fn = parse_time_function_at(ctx, *tf, o.at("time"));
        } else if (type == "damping_layer" || type == "pml") {
          bc.kind = type == "pml" ? fem::Boundary::Kind::Pml : fem::Boundary::Kind::Damping;
          bc.width = o.num("width");
          o.gt("width", bc.width, 0);
          bc.r0 = o.num("r0", type == "pml" ? kPmlDefaultR0 : 1e-3);
          if (!(bc.r0 > 0 && bc.r0 < 1)) o.fail("r0", "must be in (0, 1), got " + fmt(bc.r0));
          bc.power = o.num("power", 2.0);
          o.ge("power", bc.power, 0);
          if (type == "pml") {
            bc.alpha = o.num("alpha", 0.0);
            o.ge("alpha", bc.alpha, 0);
            bc.parallel = o.num("parallel", 0.0);
            o.ge("parallel", bc.parallel, 0);
            o.lt("parallel", bc.parallel, 1);
          } else {
            bc.beta = o.num("beta", 0.0);
            o.ge("beta", bc.beta, 0);
          }
        } else if (type == "fixed") {
          bc.kind = fem::Boundary::Kind::Fixed;
        } else {
          bc.kind = fem::Boundary::Kind::Roller;
          bc.component = o.choice("component", {"x", "y"}) == "x" ? 0 : 1;
        }
        spec.boundaries.push_back(std::move(bc));
      }
    }
  };
  {
    fem::Spec keys_only;
    read_model(keys_only, nullptr);
  }
  // Several ranks: the far field is built whole on rank 0 only, which sends each rank its part
  // (fem::Solver::distribute_from_root); rank 0 runs every check.
  c.scattered = scatter;
  // probes: the same (read below, placed once the solver exists).
  if (const ojson* p = top.find("probes")) read_probes(*p, nullptr);
  try {
    spec.mesh = fem::load_mesh(mesh_file, size, load_limits().mesh_cells, parameters, !c.scattered);
  } catch (const fem::FemError& e) {
    f.fail(f.has("size") && std::string(e.what()).find("size") != std::string::npos ? "size" : "mesh",
           e.what());
  }

  read_model(spec, &spec.mesh);
  if (c.scattered && skeleton) {
    c.fem = std::make_unique<fem::Solver>(spec, fem::Solver::Skeleton{});
    if (const ojson* p = top.find("probes")) read_probes(*p, c.fem.get());
    return c;
  }
  try {
    c.fem = std::make_unique<fem::Solver>(spec);
  } catch (const fem::FemError& e) {
    f.fail("", e.what());
  }
  fem::Solver& s = *c.fem;

  // time step against the element bound
  const double crit = s.critical_dt();
  if (!(crit > 0) || !std::isfinite(crit))
    t.fail("", "cannot compute the stability limit of the FEM mesh (critical dt = " + fmt(crit) + ")");
  double dt = use_cfl ? dt_or_cfl * crit : dt_or_cfl;
  if (!use_cfl && dt > crit * (1 + 1e-12))
    t.fail("dt", fmt(dt) + " s is above the FEM stability limit " + fmt_down(crit) +
                     " s (element bound, CFL " + fmt(dt / crit) + " > 1); use dt <= " +
                     fmt_down(crit) + " or set time.cfl");
  if (const std::string e = step_count_error(c.t_end, std::min(dt, crit)); !e.empty()) t.fail("", e);
  s.set_dt(std::min(dt, crit));
  s.t = 0;

  // probes
  if (const ojson* p = top.find("probes")) read_probes(*p, &s);
  c.notes = s.describe();
  return c;
}

}  // namespace smpm::detail
