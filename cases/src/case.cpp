// Case files: parsing, validation and construction of the Solver.
//
// The format is specified in docs/case-format-spec.txt and documented for users in
// docs/case-reference.md. Every problem is reported as CaseError "<source>: <key path>: <what>",
// where the key path is written like materials.tungsten.poisson or boundaries[2].time.duration.
//
// Structure of this file:
//   * Ctx / Obj     the key walker of every section (case_keys.hpp): wraps one JSON object and
//                   its key path, gives typed getters with defaults, rejects unknown keys, and
//                   checks every key was used.
//   * parse_text    JSON text -> document (with line/column errors and duplicate-key detection).
//   * overrides     "a.b.0.c=value" edits applied before validation.
//   * build         the sections in dependency order: grid, time, scheme, output, materials,
//                   bodies, probes, seeding, boundaries, finalize, time step.
#include "silentmpm/case.hpp"
#include "case_fem.hpp"
#include "case_keys.hpp"
#include <unistd.h>

#include "case_util.hpp"
#include "modules.hpp"
#include "silentmpm/geometry.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <regex>
#include <set>
#include <sstream>
#include <unordered_map>

#include <nlohmann/json.hpp>

namespace smpm {
namespace {

// A geometry as bytes and back (sent from rank 0 to the others under an MPI launcher).
template <class T>
void put_bytes(std::string& b, const std::vector<T>& v) {
  const std::uint64_t n = v.size();
  b.append(reinterpret_cast<const char*>(&n), sizeof n);
  if (n > 0) b.append(reinterpret_cast<const char*>(v.data()), n * sizeof(T));
}
void put_bytes(std::string& b, const std::string& s) { put_bytes(b, std::vector<char>(s.begin(), s.end())); }
void put_bytes(std::string& b, int v) { b.append(reinterpret_cast<const char*>(&v), sizeof v); }

struct ByteReader {
  const std::string& b;
  std::size_t at = 0;
  void raw(void* out, std::size_t n) {
    if (n == 0) return;  // an empty array's data() may be null
    if (at + n > b.size()) throw std::logic_error("a geometry's bytes ended early");
    std::memcpy(out, b.data() + at, n);
    at += n;
  }
  template <class T>
  void get(std::vector<T>& v) {
    std::uint64_t n = 0;
    raw(&n, sizeof n);
    v.resize(n);
    raw(v.data(), n * sizeof(T));
  }
  void get(std::string& s) {
    std::vector<char> v;
    get(v);
    s.assign(v.begin(), v.end());
  }
  void get(int& v) { raw(&v, sizeof v); }
};

// A geometry's fields in one order for both directions: io(x) writes or reads x.
template <class G, class Io>
void geometry_fields(G& g, Io&& io) {
  io(g.file);
  io(g.x);
  io(g.y);
  io.count(g.surfaces);
  for (auto& s : g.surfaces) io(s.tag), io(s.name), io(s.elems);
  io.count(g.curves);
  for (auto& c : g.curves) io(c.tag), io(c.name), io(c.segs), io(c.mid);
}

struct GeometryPut {
  std::string b;
  template <class T>
  void operator()(const T& v) { put_bytes(b, v); }
  template <class T>
  void count(const std::vector<T>& v) { put_bytes(b, static_cast<int>(v.size())); }
};

struct GeometryGet {
  ByteReader r;
  template <class T>
  void operator()(T& v) { r.get(v); }
  template <class T>
  void count(std::vector<T>& v) {
    int n = 0;
    r.get(n);
    v.resize(static_cast<std::size_t>(n));
  }
};

std::string pack_geometry(const Geometry& g) {
  GeometryPut put;
  geometry_fields(g, put);
  return std::move(put.b);
}

Geometry unpack_geometry(const std::string& b) {
  GeometryGet get{ByteReader{b}};
  Geometry g;
  geometry_fields(g, get);
  return g;
}

using detail::ojson;

// Largest grid (cells) and particle count a case may ask for; beyond these the allocation alone
// would take tens of GB.
constexpr double kMaxCells = 2e8;
constexpr double kMaxParticles = 2e8;

using detail::a_type;
using detail::as_integer;
using detail::as_number;
using detail::as_numbers;
using detail::as_string;
using detail::Ctx;
using detail::parse_output_section;
using detail::fmt;
using detail::fmt_down;
using detail::index_path;
using detail::join;
using detail::Obj;
using detail::quoted_list;
using detail::suggestion;

std::string fmt_list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + fmt(v[i]);
  return s + "]";
}

// ---------------------------------------------------------------------------------------------
// JSON text -> document. Errors carry line and column; a key given twice in one object is an
// error (the JSON library would silently keep the last one).
ojson parse_text(const std::string& text, const std::string& source) {
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;
    std::size_t index = 0;
  };
  std::vector<Frame> stack;
  auto path_to = [&](const std::string& last) {
    std::string p;
    for (std::size_t i = 0; i + 1 < stack.size(); ++i) {
      if (stack[i].object)
        p += (p.empty() ? "" : ".") + stack[i].key;
      else
        p += "[" + std::to_string(stack[i].index) + "]";
    }
    return p + (p.empty() ? "" : ".") + last;
  };
  const ojson::parser_callback_t cb = [&](int, ojson::parse_event_t ev, ojson& parsed) {
    using E = ojson::parse_event_t;
    switch (ev) {
      case E::object_start: stack.push_back(Frame{true, {}, {}, 0}); break;
      case E::array_start: stack.push_back(Frame{false, {}, {}, 0}); break;
      case E::key: {
        const std::string k = parsed.get<std::string>();
        if (!stack.back().keys.insert(k).second)
          throw CaseError(source + ": " + path_to(k) + ": key given twice");
        stack.back().key = k;
        break;
      }
      case E::value:
        if (!stack.empty() && !stack.back().object) ++stack.back().index;
        break;
      case E::object_end:
      case E::array_end:
        stack.pop_back();
        if (!stack.empty() && !stack.back().object) ++stack.back().index;
        break;
    }
    return true;
  };
  try {
    return ojson::parse(text, cb, /*allow_exceptions=*/true, /*ignore_comments=*/false);
  } catch (const ojson::parse_error& e) {
    // e.what(): "[json.exception.parse_error.101] parse error at line L, column C: <message>"
    const std::string w = e.what();
    static const std::regex re(R"(at line (\d+), column (\d+): (.*))");
    std::smatch m;
    if (std::regex_search(w, m, re))
      throw CaseError(source + ": invalid JSON at line " + m[1].str() + ", column " + m[2].str() +
                      ": " + m[3].str());
    // Fallback: locate the byte offset ourselves.
    std::size_t line = 1, col = 0;
    for (std::size_t i = 0; i < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') ++line, col = 0;
      else ++col;
    }
    throw CaseError(source + ": invalid JSON at line " + std::to_string(line) + ", column " +
                    std::to_string(col) + ": " + w);
  } catch (const ojson::out_of_range& e) {
    // A number beyond the range of a double (e.g. 1e999): name the key being read.
    const std::string w = e.what();
    const std::size_t q0 = w.find('\''), q1 = q0 == std::string::npos ? q0 : w.find('\'', q0 + 1);
    const std::string num = q1 == std::string::npos ? std::string() : w.substr(q0 + 1, q1 - q0 - 1);
    std::string at = "the case";
    if (!stack.empty()) {
      std::string base = path_to("");
      if (!base.empty() && base.back() == '.') base.pop_back();
      at = stack.back().object ? path_to(stack.back().key)
                               : base + "[" + std::to_string(stack.back().index) + "]";
    }
    throw CaseError(source + ": " + at + ": number " + (num.empty() ? "" : num + " ") +
                    "is out of the range of a double (about 1.8e308)");
  }
}

// ---------------------------------------------------------------------------------------------
// Overrides: "key.path=value"; the value is parsed as JSON, or taken as a string when it is not
// valid JSON. Every element of the path but the last must exist; the last may be new (an object
// key) or one past the end of an array (appends).
void apply_override(Ctx& ctx, ojson& doc, const std::string& text) {
  const std::string where = "override '" + text + "'";
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw CaseError(ctx.source + ": " + where + ": expected key.path=value");
  const std::string keypath = text.substr(0, eq);
  const std::string raw = text.substr(eq + 1);
  std::vector<std::string> segs;
  {
    std::size_t b = 0;
    while (true) {
      const std::size_t d = keypath.find('.', b);
      segs.push_back(keypath.substr(b, d == std::string::npos ? std::string::npos : d - b));
      if (d == std::string::npos) break;
      b = d + 1;
    }
  }
  for (const auto& s : segs)
    if (s.empty()) throw CaseError(ctx.source + ": " + where + ": empty key in path \"" + keypath + "\"");

  ojson value;
  try {
    value = ojson::parse(raw);
  } catch (const ojson::parse_error&) {
    value = raw;
  } catch (const ojson::out_of_range&) {
    throw CaseError(ctx.source + ": " + where + ": a number in the value is out of the range of a "
                    "double (about 1.8e308)");
  }

  auto bad = [&](const std::string& path, const std::string& what) {
    throw CaseError(ctx.source + ": " + where + ": " + path + ": " + what);
  };
  ojson* cur = &doc;
  std::string path;  // canonical path walked so far
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const std::string& s = segs[i];
    const bool last = i + 1 == segs.size();
    if (cur->is_object()) {
      const std::string next = path.empty() ? s : path + "." + s;
      if (last) {
        (*cur)[s] = value;
        path = next;
        break;
      }
      auto it = cur->find(s);
      if (it == cur->end())
        bad(next, "does not exist" + (path.empty() ? std::string(" in the case")
                                                   : " (no key \"" + s + "\" in " + path + ")"));
      cur = &*it;
      path = next;
    } else if (cur->is_array()) {
      if (s.find_first_not_of("0123456789") != std::string::npos || s.size() > 9)
        bad(path, "is an array; \"" + s + "\" is not an index");
      const std::size_t k = std::stoul(s);
      const std::string next = index_path(path, k);
      const std::string size_note =
          " (" + path + " has " + std::to_string(cur->size()) + " element" +
          (cur->size() == 1 ? "" : "s") + ")";
      if (last) {
        if (k < cur->size()) (*cur)[k] = value;
        else if (k == cur->size()) cur->push_back(value);
        else bad(next, "does not exist" + size_note);
        path = next;
        break;
      }
      if (k >= cur->size()) bad(next, "does not exist" + size_note);
      cur = &(*cur)[k];
      path = next;
    } else {
      bad(path, "is " + a_type(*cur) + ", it has no key \"" + s + "\"");
    }
  }
  ctx.overridden.emplace_back(path, text);
}

// ---------------------------------------------------------------------------------------------
// Sections.
struct GridSpec {
  double x0 = 0, y0 = 0, h = 0;
  int nx = 0, ny = 0;
  double x1() const { return x0 + nx * h; }
  double y1() const { return y0 + ny * h; }
  std::string describe() const {
    return "[" + fmt(x0) + ", " + fmt(x1()) + "] x [" + fmt(y0) + ", " + fmt(y1()) + "]";
  }
};

struct BodySpec {
  std::string name;
  int material = 0;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int ppc = 1;
  double vx = 0, vy = 0;
  int surface = -1;  // body from a gmsh physical surface: index into Geometry::surfaces
  Solver::Seeding seeding = Solver::Seeding::Uniform;
};

const std::vector<std::string> kSides = {"left", "right", "bottom", "top"};

GridSpec parse_grid(Obj g) {
  g.allow({"origin", "size", "cell"});
  GridSpec s;
  const auto org = g.nums("origin", std::vector<double>{0.0, 0.0});
  const auto size = g.nums("size", 2);
  for (int k = 0; k < 2; ++k)
    if (!(size[k] > 0))
      g.ctx().fail(index_path(g.at("size"), k), "must be > 0, got " + fmt(size[k]));
  const double h = g.num("cell");
  g.gt("cell", h, 0);
  int n[2];
  for (int k = 0; k < 2; ++k) {
    const double ratio = size[k] / h;
    if (ratio > kMaxCells)
      g.fail("size", "too many cells (" + fmt(ratio) + " along " + (k ? "y" : "x") + ")");
    const long c = std::lround(ratio);
    if (c < 1 || !(std::fabs(c * h - size[k]) < 1e-6 * h))
      g.fail("size", std::string(k ? "Ly" : "Lx") + " = " + fmt(size[k]) +
                         " is not a multiple of cell = " + fmt(h));
    n[k] = static_cast<int>(c);
  }
  if (static_cast<double>(n[0]) * n[1] > kMaxCells)
    g.fail("size", "too many cells: " + std::to_string(n[0]) + " x " + std::to_string(n[1]) +
                       " (the limit is " + fmt(kMaxCells) + ")");
  g.done();
  s.x0 = org[0];
  s.y0 = org[1];
  s.h = h;
  s.nx = n[0];
  s.ny = n[1];
  return s;
}

// Keys of model "j2_softening" (the tungsten film of docs/physics.md §5; docs/case-reference.md).
const std::vector<std::string> kFilmKeys = {"yield_stress", "peak_stress", "hardening_modulus",
                                            "softening_modulus", "moduli", "bifurcation",
                                            "decohesion"};

void parse_film_model(Obj& m, Material& mat) {
  J2SoftParams& j = mat.j2;
  j.sigma_y = m.num("yield_stress");
  m.gt("yield_stress", j.sigma_y, 0);
  j.sigma_peak = m.num("peak_stress");
  if (!(j.sigma_peak >= j.sigma_y))
    m.fail("peak_stress", "must be >= yield_stress = " + fmt(j.sigma_y) + ", got " + fmt(j.sigma_peak));
  j.E_h = m.num("hardening_modulus");
  m.gt("hardening_modulus", j.E_h, 0);
  j.E_s = m.num("softening_modulus");
  m.gt("softening_modulus", j.E_s, 0);
  j.reading = m.choice("moduli", {"plastic", "tangent"}, "plastic") == "plastic"
                  ? ModuliReading::Plastic
                  : ModuliReading::Tangent;
  if (j.reading == ModuliReading::Tangent) {
    const double E = m.num("young");
    if (!(j.E_h < E))
      m.fail("hardening_modulus", "must be < young = " + fmt(E) +
                                      " with moduli \"tangent\", got " + fmt(j.E_h));
  }
  mat.sigma_y = j.sigma_y;
  if (const ojson* b = m.find("bifurcation")) {
    Obj o(m.ctx(), *b, m.at("bifurcation"));
    o.allow({"enabled", "step_deg", "tie_break", "tie_tolerance"});
    mat.bif.enabled = o.boolean("enabled", true);
    mat.bif.step_deg = o.num("step_deg", 1.0);
    o.gt("step_deg", mat.bif.step_deg, 0.05);
    o.le("step_deg", mat.bif.step_deg, 10);
    mat.bif.tie = o.choice("tie_break", {"smallest_angle", "largest_angle"}, "smallest_angle") ==
                          "smallest_angle"
                      ? TieBreak::SmallestAngle
                      : TieBreak::LargestAngle;
    mat.bif.tie_tolerance = o.num("tie_tolerance", 1e-9);
    o.ge("tie_tolerance", mat.bif.tie_tolerance, 0);
    o.done();
  }
  if (const ojson* d = m.find("decohesion")) {
    Obj o(m.ctx(), *d, m.at("decohesion"));
    o.allow({"enabled", "normal_critical_jump", "tangential_critical_jump", "smear_length",
             "compressed_normal_strength", "min_strength", "snap_back_factor"});
    DecohesionParams& c = mat.coh;
    c.enabled = o.boolean("enabled", true);
    c.u_nf = o.num("normal_critical_jump", 10e-9);
    o.gt("normal_critical_jump", c.u_nf, 0);
    c.u_tf = o.num("tangential_critical_jump", 10e-9);
    o.gt("tangential_critical_jump", c.u_tf, 0);
    if (const ojson* L = o.find("smear_length")) {
      if (L->is_string()) {
        if (L->get<std::string>() != "particle")
          o.fail("smear_length", "must be a length in m or \"particle\", got \"" +
                                     L->get<std::string>() + "\"");
        c.smear_length = 0;
      } else {
        c.smear_length = o.num("smear_length");
        o.gt("smear_length", c.smear_length, 0);
      }
    }
    if (const ojson* S = o.find("compressed_normal_strength")) {
      if (S->is_string()) {
        if (S->get<std::string>() != "shear")
          o.fail("compressed_normal_strength",
                 "must be a stress in Pa or \"shear\", got \"" + S->get<std::string>() + "\"");
        c.compressed_normal_strength = 0;
      } else {
        c.compressed_normal_strength = o.num("compressed_normal_strength");
        o.gt("compressed_normal_strength", c.compressed_normal_strength, 0);
      }
    }
    c.min_strength = o.num("min_strength", 1e-3 * j.sigma_y);
    o.gt("min_strength", c.min_strength, 0);
    c.snap_back_factor = o.num("snap_back_factor", 0.5);
    o.gt("snap_back_factor", c.snap_back_factor, 0);
    o.lt("snap_back_factor", c.snap_back_factor, 1);
    o.done();
  }
}

Material parse_material(const Ctx& ctx, const std::string& name, const ojson& j) {
  Obj m(ctx, j, "materials." + name);
  const std::string model = m.choice("model", {"elastic", "von_mises", "j2_softening"});
  if (model == "elastic" && m.has("yield_stress"))
    m.fail("yield_stress", "not used by model \"elastic\" (use \"von_mises\" for plasticity)");
  std::vector<std::string> keys = {"model", "young", "poisson", "density"};
  if (model == "von_mises") keys.push_back("yield_stress");
  if (model == "j2_softening") keys.insert(keys.end(), kFilmKeys.begin(), kFilmKeys.end());
  m.allow(keys, "for model \"" + model + "\"");
  Material mat;
  mat.name = name;
  mat.model = model == "elastic"     ? Model::Elastic
              : model == "von_mises" ? Model::VonMises
                                     : Model::J2Film;
  mat.E = m.num("young");
  m.gt("young", mat.E, 0);
  mat.nu = m.num("poisson");
  m.gt("poisson", mat.nu, -1);
  m.lt("poisson", mat.nu, 0.5);
  mat.rho = m.num("density");
  m.gt("density", mat.rho, 0);
  if (mat.model == Model::VonMises) {
    mat.sigma_y = m.num("yield_stress");
    m.gt("yield_stress", mat.sigma_y, 0);
  }
  if (mat.model == Model::J2Film) parse_film_model(m, mat);
  m.done();
  mat.derive();
  return mat;
}

TimeFunction parse_time_function(Obj o) {
  const std::string shape =
      o.choice("shape", {"constant", "step", "rectangular", "triangular", "sin2", "half_sine", "table"},
               "constant");
  std::vector<std::string> keys = {"shape"};
  if (shape == "step") keys.insert(keys.end(), {"start", "ramp"});
  if (shape == "rectangular" || shape == "triangular" || shape == "half_sine")
    keys.insert(keys.end(), {"start", "duration"});
  if (shape == "sin2") keys.insert(keys.end(), {"start", "duration", "ramp"});
  if (shape == "table") keys.push_back("table");
  if ((shape == "constant" || shape == "table") && o.has("start"))
    o.fail("start", "not used by shape \"" + shape + "\"" +
                        (shape == "constant" ? " (use \"step\" for a load that starts later)"
                                             : " (the table times are absolute)"));
  o.allow(keys, "for shape \"" + shape + "\"");

  TimeFunction f;
  if (shape != "constant" && shape != "table") {
    f.start = o.num("start", 0.0);
    o.ge("start", f.start, 0);
  }
  if (shape == "constant") f.kind = TimeFunction::Kind::Constant;
  if (shape == "step") {
    f.kind = TimeFunction::Kind::Step;
    f.ramp = o.num("ramp", 0.0);
    o.ge("ramp", f.ramp, 0);
  }
  if (shape == "rectangular" || shape == "triangular" || shape == "sin2" || shape == "half_sine") {
    f.kind = shape == "rectangular"  ? TimeFunction::Kind::Rectangular
             : shape == "triangular" ? TimeFunction::Kind::Triangular
             : shape == "half_sine"  ? TimeFunction::Kind::HalfSine
                                     : TimeFunction::Kind::Sin2Pulse;
    f.duration = o.num("duration");
    o.gt("duration", f.duration, 0);
  }
  if (shape == "sin2") {
    f.ramp = o.num("ramp");
    o.gt("ramp", f.ramp, 0);
    if (!(f.ramp <= 0.5 * f.duration))
      o.fail("ramp", "must be <= duration/2 = " + fmt(0.5 * f.duration) + ", got " + fmt(f.ramp));
  }
  if (shape == "table") {
    f.kind = TimeFunction::Kind::Table;
    const ojson& t = o.array("table");
    const std::string path = o.at("table");
    if (t.size() < 2)
      o.fail("table", "needs at least 2 rows [t, value], got " + std::to_string(t.size()));
    for (std::size_t i = 0; i < t.size(); ++i) {
      const auto row = as_numbers(o.ctx(), t[i], index_path(path, i), 2);
      if (i > 0 && !(row[0] > f.table.back().first))
        o.ctx().fail(index_path(path, i), "times must be strictly increasing, got " +
                                              fmt(row[0]) + " after " + fmt(f.table.back().first));
      f.table.emplace_back(row[0], row[1]);
    }
  }
  o.done();
  return f;
}

// A point probe ("at"), a region probe ("region"), or with along_curve the keys a probe along a
// curve shares with them (the caller reads the curve keys and calls o.done()).
ProbeSpec parse_probe(Obj& o, const GridSpec& g, const std::vector<std::string>& body_names,
                      bool along_curve = false) {
  if (along_curve) {
    if (o.has("at")) o.fail("at", "give either at (a point) or curve (points along a curve), not both");
    o.allow({"name", "curve", "count", "spacing", "reverse", "fields", "body"}, "for a probe along a curve");
  } else {
    o.allow({"name", "at", "region", "curve", "fields", "body"});
    if (o.has("at") && o.has("region"))
      o.fail("region", "give either at (a point) or region (a box), not both");
  }
  ProbeSpec p;
  p.name = o.str("name");
  static const std::regex ok("[A-Za-z0-9_]+");
  if (!std::regex_match(p.name, ok))
    o.fail("name", "must be letters, digits and _ only, got \"" + p.name + "\"");
  if (!along_curve && o.has("region")) {
    const auto r = o.nums("region", 4);
    if (!(r[0] < r[2] && r[1] < r[3]))
      o.fail("region", "must be [x0, y0, x1, y1] with x0 < x1 and y0 < y1, got " + fmt_list(r));
    if (!(r[0] < g.x1() && r[2] > g.x0 && r[1] < g.y1() && r[3] > g.y0))
      o.fail("region", "outside the grid " + g.describe() + ": " + fmt_list(r));
    p.region = true;
    p.rx0 = r[0];
    p.ry0 = r[1];
    p.rx1 = r[2];
    p.ry1 = r[3];
    p.x = 0.5 * (r[0] + r[2]);
    p.y = 0.5 * (r[1] + r[3]);
  } else if (!along_curve) {
    if (!o.has("at")) o.fail("at", "missing required key (at [x, y], or region [x0, y0, x1, y1])");
    const auto at = o.nums("at", 2);
    p.x = at[0];
    p.y = at[1];
    if (!(p.x >= g.x0 && p.x < g.x1() && p.y >= g.y0 && p.y < g.y1()))
      o.fail("at", "outside the grid " + g.describe() + ": (" + fmt(p.x) + ", " + fmt(p.y) + ")");
  }
  static const std::vector<std::string> all = {"sxx", "syy", "szz", "sxy", "J2", "vx", "vy"};
  // A region probe also has the momentum and mass of its particles.
  static const std::vector<std::string> all_region = {"sxx", "syy", "szz", "sxy", "J2",  "vx",
                                                      "vy",  "px",  "py",  "mass", "fcx", "fcy"};
  if (const ojson* f = o.find("fields")) {
    const std::string path = o.at("fields");
    if (!f->is_array()) o.fail("fields", "expected an array of strings, got " + a_type(*f));
    if (f->empty()) o.fail("fields", "must name at least one field (or leave it out for all)");
    const std::vector<std::string>& allowed = p.region ? all_region : all;
    for (std::size_t i = 0; i < f->size(); ++i) {
      const std::string s = as_string(o.ctx(), (*f)[i], index_path(path, i));
      if (!p.region && std::find(all_region.begin(), all_region.end(), s) != all_region.end() &&
          std::find(all.begin(), all.end(), s) == all.end())
        o.ctx().fail(index_path(path, i), "\"" + s + "\" is a field of region probes (give "
                                          "region instead of at)");
      if (std::find(allowed.begin(), allowed.end(), s) == allowed.end())
        o.ctx().fail(index_path(path, i), "must be one of " + quoted_list(allowed) + ", got \"" +
                                              s + "\"" + suggestion(s, allowed));
      if (std::find(p.fields.begin(), p.fields.end(), s) != p.fields.end())
        o.ctx().fail(index_path(path, i), "field \"" + s + "\" listed twice");
      p.fields.push_back(s);
    }
  } else {
    p.fields = all;
  }
  if (o.has("body")) {
    const std::string b = o.str("body");
    const auto it = std::find(body_names.begin(), body_names.end(), b);
    if (it == body_names.end())
      o.fail("body", "no body named \"" + b + "\"" + suggestion(b, body_names) +
                         "; bodies: " + join(body_names));
    p.body = static_cast<int>(it - body_names.begin());
  }
  if (!along_curve) o.done();
  return p;
}

// Which edge of a box, with its outward normal. Endpoints run counter-clockwise around the box,
// so the edge direction is the tangent s = (-n_y, n_x).
struct Edge {
  double ex0, ey0, ex1, ey1, nx, ny;
  double extent;  // body size normal to the edge
};

Edge box_edge(const BodySpec& b, const std::string& side) {
  if (side == "left") return {b.x0, b.y1, b.x0, b.y0, -1, 0, b.x1 - b.x0};
  if (side == "right") return {b.x1, b.y0, b.x1, b.y1, 1, 0, b.x1 - b.x0};
  if (side == "bottom") return {b.x0, b.y0, b.x1, b.y0, 0, -1, b.y1 - b.y0};
  return {b.x1, b.y1, b.x0, b.y1, 0, 1, b.y1 - b.y0};  // top
}

class Builder {
 public:
  // A checking builder (`checking` true) reads every key, with a gmsh geometry's physical groups
  // but without meshing it or seeding particles, and stops before the particles would be needed:
  // a case with a geometry is read so first, and its mistakes are reported before the mesh is made.
  // On several MPI ranks (`scatter`) rank 0 builds the whole case and the others (`skeleton`) the
  // case without its particles, which rank 0 then sends them (docs/parallel.md "Set-up"); the
  // checks that need the particles run on rank 0 only. With multi-field contact the material
  // groups split by body on rank 0's whole body go to the others with the split.
  Builder(const Ctx& ctx, const ojson& doc, bool checking = false, bool scatter = false,
          bool skeleton = false)
      : ctx_(ctx), doc_(doc), checking_(checking), scatter_(scatter), skeleton_(skeleton) {}

  Case build() {
    if (!doc_.is_object())
      ctx_.fail("", "a case file must be a JSON object {...}, got " + a_type(doc_));
    // A case with an FEM region is built by the far-field module (cases/fe/).
    if (doc_.contains("fem")) {
      const detail::FarFieldModule* fe = nullptr;
      try {
        fe = &detail::far_field_module();
      } catch (const std::runtime_error& e) {
        ctx_.fail("fem", std::string("the far field's module: ") + e.what());
      }
      return doc_.contains("bodies") || doc_.contains("grid")
                 ? fe->build_hybrid_case(ctx_, doc_)  // cases/fe/case_hybrid.cpp
                 : fe->build_fem_case(ctx_, doc_, scatter_, skeleton_);  // cases/fe/case_fem.cpp
    }
    if (!checking_ && doc_.contains("geometry")) Builder(ctx_, doc_, true).build();
    Obj top(ctx_, doc_, "");
    top.allow({"title", "grid", "time", "scheme", "materials", "bodies", "boundaries", "probes", "geometry",
               "output", "contact", "gravity"});
    for (const char* k : {"grid", "time", "materials", "bodies"})
      if (!top.has(k)) top.fail(k, "missing required key");

    Case c;
    c.source = ctx_.source;
    c.title = top.str("title", "");
    grid_ = parse_grid(top.obj("grid"));
    parse_time(top.obj("time"), c);
    if (const ojson* s = top.find("scheme")) parse_scheme(Obj(ctx_, *s, "scheme"));
    if (top.has("gravity")) {  // a body force per unit mass on every body (m/s^2)
      const auto g = top.nums("gravity", 2);
      s_->opt.gravity_x = g[0];
      s_->opt.gravity_y = g[1];
      c.notes.push_back("gravity (" + fmt(g[0]) + ", " + fmt(g[1]) + ") m/s^2");
    }
    if (const ojson* ct = top.find("contact")) parse_contact(Obj(ctx_, *ct, "contact"), c);
    c.scattered = scatter_;
    scattered_ = c.scattered;
    skeleton_ = skeleton_ && c.scattered;
    s_->seed_nothing = skeleton_;
    if (const ojson* o = top.find("output")) parse_output(Obj(ctx_, *o, "output"), c.output);
    parse_materials(top);
    if (const ojson* g = top.find("geometry")) parse_geometry(Obj(ctx_, *g, "geometry"));
    parse_bodies(top.array("bodies"));
    for (const auto& b : bodies_) {
      BodyInfo info{b.name, "", "", b.x0, b.y0, b.x1, b.y1};
      for (const auto& [name, index] : material_index_)
        if (index == b.material) info.material = name;
      if (b.surface >= 0)
        info.surface = Geometry::label("physical surface", geo_->surfaces[b.surface].tag,
                                       geo_->surfaces[b.surface].name);
      c.bodies.push_back(std::move(info));
    }
    if (const ojson* p = top.find("probes")) parse_probes(*p, c);
    // Boundaries select seeded particles and nodes, so they are built after seeding.
    const ojson* bnd = top.find("boundaries");
    if (bnd && !bnd->is_array()) top.fail("boundaries", "expected an array, got " + a_type(*bnd));
    top.done();

    if (!checking_) seed();
    if (bnd)
      for (std::size_t i = 0; i < bnd->size(); ++i)
        parse_boundary(Obj(ctx_, (*bnd)[i], index_path("boundaries", i)), i, c);
    // The delayed closure reads a node's whole block as its own edge's (docs/physics.md section 4).
    if (!delayed_at_.empty()) {
      bool others = !s_->dampers.empty() || !s_->pml_bands.empty();
      for (const auto& sl : s_->silents)
        others = others || (!sl.delayed && (sl.form == SilentForm::Nodal || sl.springs()));
      if (others)
        ctx_.fail(delayed_at_ + ".edge_velocity",
                  "\"delayed\" must be on every nodal silent edge of the case, with no "
                  "kelvin_voigt, damping_layer or pml (their blocks would share its nodes)");
    }
    if (checking_) return c;  // no solver: the keys are read

    if (!skeleton_) note_particles_on_grid_lines(c);
    s_->finalize();
    if (!skeleton_) note_light_nodes(c);
    // A point probe must see particles (of its body, when it names one): else it would record
    // zeros all run. (Points along a curve are checked against their bodies when placed.)
    for (std::size_t q = 0; q < c.probes.size() && !skeleton_; ++q) {
      const ProbeSpec& pr = c.probes[q];
      if (!pr.along.empty()) continue;
      if (pr.region) {
        if (!s_->region_mean(pr.rx0, pr.ry0, pr.rx1, pr.ry1, pr.body).valid)
          ctx_.fail(index_path("probes", probe_doc_[q]) + ".region",
                    fmt_list({pr.rx0, pr.ry0, pr.rx1, pr.ry1}) + " holds no particle" +
                        (pr.body >= 0 ? " of body \"" + bodies_[pr.body].name + "\"" : std::string()) +
                        ", so it would record zeros");
        continue;
      }
      const auto smp = s_->sample({{pr.x, pr.y}}, {pr.body});
      if (!smp[0].valid)
        ctx_.fail(index_path("probes", probe_doc_[q]) + ".at",
                  "(" + fmt(pr.x) + ", " + fmt(pr.y) + ") is in no body" +
                      (pr.body >= 0 ? " named \"" + bodies_[pr.body].name + "\"" : std::string()) +
                      ": no particle within a cell of it, so it would record zeros");
    }
    const long out = skeleton_ ? -1 : s_->first_particle_outside();
    if (out >= 0) {
      const auto k = static_cast<std::size_t>(out);
      const int b = s_->p.body[k];
      ctx_.fail(index_path("bodies", b) + (bodies_[b].surface >= 0 ? ".surface" : ".box"),
                "particle at (" + fmt(s_->p.x[k]) + ", " + fmt(s_->p.y[k]) +
                    ") is outside the grid " + grid_.describe());
    }
    set_time_step();
    // USL strains the particles with v+ at every node; with the wider shapes a surface that moves
    // outward at all puts a sliver of mass on the node row beyond it, a node whose v+ that
    // update cannot take (docs/physics.md section 9.3).
    if (s_->opt.scheme == Scheme::USL && s_->opt.shape != ShapeKind::Bilinear)
      c.notes.push_back(std::string("note: scheme.update \"USL\" with scheme.shape \"") +
                        shape_name(s_->opt.shape) +
                        "\": a free surface that moves outward puts a sliver of mass on the "
                        "node row beyond it, whose updated velocity USL strains the particles "
                        "with (a column under a shear traction kept about a twentieth of the "
                        "energy MUSL gives it; docs/physics.md section 9.3); with this shape "
                        "prefer \"MUSL\"");
    // Multi-field contact with bilinear shapes at 1 ppc holds only through the nodes two bodies
    // share, which a face off the grid lines leaves to a sliver of one of them (docs/physics.md
    // section 4, the gap check's limit).
    if (s_->contact.multi() && s_->opt.shape == ShapeKind::Bilinear)
      for (const BodySpec& b : bodies_)
        if (b.ppc == 1) {
          c.notes.push_back(
              "note: contact.type \"multi\" with scheme.shape \"bilinear\" and body \"" + b.name +
              "\" at 1 particle per cell: where two bodies meet off the grid lines the contact "
              "acts through a sliver of one body's particles (the 1D impact with its contact face "
              "0.25 of a cell off a grid line: 0.82 of the pressure, rebound 0.43 of the closed "
              "form, 43 % of the energy lost; on a grid line within 1 %; docs/physics.md section "
              "4); seed 4 particles per cell, or use scheme.shape \"gimp\"");
          break;
        }
    // The updated edge velocity was measured stable up to CFL 0.85 under MUSL, 0.9 under USF
    // (docs/physics.md section 4).
    const double cfl = s_->dt / s_->critical_dt();
    const double stable = s_->opt.scheme == Scheme::USF ? 0.9 : 0.85;
    for (const auto& sb : s_->silents)
      if (sb.updated_velocity && cfl > stable + 1e-12) {
        c.notes.push_back("note: edge_velocity \"updated\" at CFL " + fmt(cfl) +
                          ": measured stable up to CFL " + fmt(stable) + " only under " +
                          scheme_name(s_->opt.scheme) + " (docs/physics.md section 4); lower "
                          "time.cfl if the run blows up");
        break;
      }
    // The default edge velocity with the lumped trapezoidal mean, which multi-field contact
    // keeps (the particles' mean needs one velocity field), grew in long runs in two
    // dimensions, where its edges meet free surfaces, above CFL 0.2 at 1 ppc and 0.4 at 4 ppc
    // and more (docs/physics.md section 4). Said for runs of more than 10^4 steps (the
    // earliest stop came after 1.7 * 10^4).
    if (s_->opt.scheme != Scheme::USL && t_end_ > 1e4 * s_->dt && s_->contact.multi())
      for (const auto& sb : s_->silents) {
        if (sb.form != SilentForm::Nodal || sb.updated_velocity || sb.layer.idx.empty()) continue;
        const double h2 = s_->grid.h * s_->grid.h;
        const bool fine = s_->p.vol[sb.layer.idx[0]] < 0.5 * h2;  // 4 ppc and more
        const double bound = fine ? 0.4 : 0.2;
        if (cfl <= bound + 1e-12) continue;
        c.notes.push_back(
            "note: silent boundary \"" + sb.layer.name + "\" (edge_velocity \"remapped\", "
            "multi-field contact) under " + scheme_name(s_->opt.scheme) + " at CFL " + fmt(cfl) +
            ": in two dimensions, where such edges meet free surfaces, runs grew after "
            "10^4-10^5 steps above CFL " + fmt(bound) +
            (fine ? " at 4 particles per cell and more" : " at 1 particle per cell") +
            " (docs/physics.md section 4); for long runs lower time.cfl");
        break;
      }
    c.solver = std::move(s_);
    return c;
  }

 private:
  const Ctx& ctx_;
  const ojson& doc_;
  const bool checking_;  // read the keys only (see the constructor)
  const bool scatter_;   // several ranks: rank 0 sends the others their particles
  bool skeleton_;        // this rank builds the case without its particles
  bool scattered_ = false;  // scatter_, and the case allows it
  GridSpec grid_;
  std::string delayed_at_;  // the first boundary with "edge_velocity": "delayed"
  std::unique_ptr<Solver> s_ = std::make_unique<Solver>();
  std::vector<Material> materials_;
  std::map<std::string, int> material_index_;
  std::vector<BodySpec> bodies_;
  std::unique_ptr<Geometry> geo_;  // the "geometry" key (silentmpm/geometry.hpp)
  bool use_cfl_ = false;
  double dt_or_cfl_ = 0;
  std::vector<std::size_t> probe_doc_;  // document index of each probe in c.probes
  double t_end_ = 0;

  void parse_time(Obj t, Case& c) {
    t.allow({"end", "dt", "cfl"});
    c.t_end = t.num("end");
    t.gt("end", c.t_end, 0);
    t_end_ = c.t_end;
    const bool has_dt = t.has("dt"), has_cfl = t.has("cfl");
    if (has_dt && has_cfl) t.fail("", "give either dt or cfl, not both");
    if (!has_dt && !has_cfl)
      t.fail("", "missing dt or cfl (give exactly one: a time step in s, or a fraction of the "
                 "stability limit)");
    use_cfl_ = has_cfl;
    if (has_cfl) {
      dt_or_cfl_ = t.num("cfl");
      t.gt("cfl", dt_or_cfl_, 0);
      t.le("cfl", dt_or_cfl_, 1);
    } else {
      dt_or_cfl_ = t.num("dt");
      t.gt("dt", dt_or_cfl_, 0);
    }
    t.done();
  }

  // "contact": {"type": "single" | "multi", "friction": mu}; friction only with multi.
  void parse_contact(Obj o, Case& c) {
    o.allow({"type", "friction"});
    const std::string type = o.choice("type", {"single", "multi"}, "single");
    s_->contact.type = type == "multi" ? ContactType::Multi : ContactType::Single;
    if (type == "multi" && s_->symmetric_correction())
      o.fail("type", "multi-field contact corrects each body's field on its own, which "
                     "scheme.mass_correction_form \"symmetric\" does not do yet; use "
                     "\"increment\"");
    if (type == "multi" && s_->opt.light_node_ratio > 0)
      o.fail("type", "multi-field contact keeps each body's own field, which "
                     "scheme.light_nodes \"extend\" does not extend yet; use \"keep\"");
    if (o.has("friction") && type != "multi")
      o.fail("friction", "friction needs \"type\": \"multi\" (a single velocity field has "
                         "no slip)");
    s_->contact.friction = o.num("friction", 0.0);
    o.ge("friction", s_->contact.friction, 0);
    o.done();
    if (type == "multi")
      c.notes.push_back("contact: one velocity field per body, Coulomb friction " +
                        fmt(s_->contact.friction));
  }

  void parse_scheme(Obj s) {
    s.allow({"update", "flip", "threads", "shape", "mass_correction", "mass_correction_form",
             "light_nodes", "light_node_ratio"});
    const std::string u = s.choice("update", {"USF", "USL", "MUSL"}, "MUSL");
    s_->opt.scheme = u == "USF" ? Scheme::USF : u == "USL" ? Scheme::USL : Scheme::MUSL;
    const std::string sh = s.choice("shape", {"bilinear", "gimp", "bspline"}, "bilinear");
    s_->opt.shape = sh == "gimp" ? ShapeKind::UGimp
                    : sh == "bspline" ? ShapeKind::BSpline2 : ShapeKind::Bilinear;
    if (s_->opt.shape != ShapeKind::Bilinear && (grid_.nx < 2 || grid_.ny < 2))
      s.fail("shape", "\"" + sh + "\" needs a grid of at least 2 x 2 cells, got " +
                          std::to_string(grid_.nx) + " x " + std::to_string(grid_.ny));
    s_->opt.flip = s.num("flip", 1.0);
    s.ge("flip", s_->opt.flip, 0);
    s.le("flip", s_->opt.flip, 1);
    // The consistent-mass correction of the grid's increment (docs/physics.md section 1.1).
    const long mc = s.integer("mass_correction", 0);
    s.ge("mass_correction", static_cast<double>(mc), 0);
    s.le("mass_correction", static_cast<double>(mc), 8);
    s_->opt.mass_correction = static_cast<int>(mc);
    // Its form: the series of R^-1 on the increment, or of R^-1/2 on the increment and on the
    // strain's velocity, whose energy account closes as the lumped mass's does.
    const std::string form = s.choice("mass_correction_form", {"increment", "symmetric"},
                                      "increment");
    s_->opt.mass_correction_symmetric = form == "symmetric";
    if (form == "symmetric" && s_->opt.scheme == Scheme::USL)
      s.fail("mass_correction_form", "\"symmetric\" needs scheme.update \"MUSL\" or \"USF\" "
                                     "(USL strains the particles with v+ itself, which keeps "
                                     "the lumped increment); use \"increment\" under USL");
    // Light nodes beyond a body's faces: their own velocity, or the heavy nodes' extended to
    // them (docs/physics.md section 8.7).
    const std::string ln = s.choice("light_nodes", {"keep", "extend"}, "keep");
    if (s.has("light_node_ratio") && ln != "extend")
      s.fail("light_node_ratio", "needs \"light_nodes\": \"extend\"");
    const double lr = s.num("light_node_ratio", LightNodes::kDefaultRatio);
    s.gt("light_node_ratio", lr, 0);
    s.le("light_node_ratio", lr, 0.25);
    s_->opt.light_node_ratio = ln == "extend" ? lr : 0.0;
    const long th = s.integer("threads", 0);
    s.ge("threads", static_cast<double>(th), 0);
    s.le("threads", static_cast<double>(th), 4096);
    s_->opt.threads = static_cast<int>(th);
    s.done();
  }

  void parse_output(Obj o, OutputSpec& out) {
    parse_output_section(o, out, 1000000);
    o.done();
  }

  void parse_materials(Obj& top) {
    const ojson& m = top.need("materials");
    if (!m.is_object()) top.fail("materials", "expected an object {name: {...}}, got " + a_type(m));
    if (m.empty()) top.fail("materials", "must define at least one material");
    if (m.size() > 65535) top.fail("materials", "too many materials");
    for (const auto& item : m.items()) {
      material_index_[item.key()] = static_cast<int>(materials_.size());
      materials_.push_back(parse_material(ctx_, item.key(), item.value()));
    }
  }

  std::vector<std::string> material_names() const {
    std::vector<std::string> v;
    for (const auto& m : materials_) v.push_back(m.name);
    return v;
  }
  std::vector<std::string> body_names() const {
    std::vector<std::string> v;
    for (const auto& b : bodies_) v.push_back(b.name);
    return v;
  }

  void parse_bodies(const ojson& arr) {
    if (arr.empty()) ctx_.fail("bodies", "must contain at least one body");
    if (arr.size() > 65535) ctx_.fail("bodies", "too many bodies");
    const double tol = 1e-6 * grid_.h;
    for (std::size_t i = 0; i < arr.size(); ++i) {
      Obj o(ctx_, arr[i], index_path("bodies", i));
      o.allow({"name", "material", "box", "surface", "particles_per_cell", "seeding", "velocity"});
      BodySpec b;
      b.name = o.str("name");
      if (b.name.empty()) o.fail("name", "must not be empty");
      for (const auto& other : bodies_)
        if (other.name == b.name) o.fail("name", "body name \"" + b.name + "\" is used twice");
      const std::string mat = o.str("material");
      auto it = material_index_.find(mat);
      if (it == material_index_.end())
        o.fail("material", "no material named \"" + mat + "\"" +
                               suggestion(mat, material_names()) +
                               "; defined: " + join(material_names()));
      b.material = it->second;
      std::vector<double> box;
      if (o.has("surface")) box = body_surface(o, b);  // a gmsh surface: box = its extent
      else box = o.nums("box", 4);
      b.x0 = box[0], b.y0 = box[1], b.x1 = box[2], b.y1 = box[3];
      if (!(b.x1 > b.x0)) o.fail("box", "x1 must be > x0, got " + fmt_list(box));
      if (!(b.y1 > b.y0)) o.fail("box", "y1 must be > y0, got " + fmt_list(box));
      for (int k = 0; k < 4; ++k) {
        const double x = k % 2 ? b.x1 : b.x0, y = k / 2 ? b.y1 : b.y0;
        if (x < grid_.x0 - tol || x > grid_.x1() + tol || y < grid_.y0 - tol ||
            y > grid_.y1() + tol)
          o.fail("box", "outside the grid " + grid_.describe() + ": corner (" + fmt(x) + ", " +
                            fmt(y) + ") of " + fmt_list(box));
      }
      if (const ojson* p = o.find("particles_per_cell")) {
        const long n = as_integer(ctx_, *p, o.at("particles_per_cell"));
        if (n != 1 && n != 4 && n != 9)
          o.fail("particles_per_cell", "must be 1, 4 or 9, got " + std::to_string(n));
        b.ppc = static_cast<int>(n);
      }
      // Where in each cell the particles sit (docs/physics.md section 1.1): the centres of its
      // n x n sub-cells, or its n x n Gauss points (FE's quadrature), each with its weight's
      // share of the cell.
      if (o.choice("seeding", {"uniform", "gauss"}, "uniform") == "gauss") {
        b.seeding = Solver::Seeding::Gauss;
        if (s_->opt.shape == ShapeKind::UGimp)
          o.fail("seeding", "\"gauss\" is for point particles: under scheme.shape \"gimp\" each "
                            "particle is a square of its initial size, and squares about the "
                            "Gauss points do not tile the cell");
        if (b.surface < 0) {
          // On the grid's lines: its Gauss points are then the grid cells' own.
          auto off_line = [&](double v, double origin) {
            const double c = (v - origin) / grid_.h;
            return std::abs(c - std::round(c)) > 1e-6;
          };
          if (off_line(b.x0, grid_.x0) || off_line(b.x1, grid_.x0) || off_line(b.y0, grid_.y0) ||
              off_line(b.y1, grid_.y0) || (b.x1 - b.x0) < 0.5 * grid_.h ||
              (b.y1 - b.y0) < 0.5 * grid_.h)
            o.fail("seeding", "\"gauss\" needs a box of whole grid cells, its sides on the grid's "
                              "lines (its Gauss points are the cells'), got " + fmt_list(box) +
                              " on a grid of " + fmt(grid_.h) + " m cells from (" +
                              fmt(grid_.x0) + ", " + fmt(grid_.y0) + ")");
        }
      }
      const auto v = o.nums("velocity", std::vector<double>{0.0, 0.0});
      b.vx = v[0];
      b.vy = v[1];
      // Two boxes must not overlap (their particles would double the mass there); touching
      // along an edge is fine (contact). Bodies from gmsh surfaces are separate surfaces.
      if (b.surface < 0)
        for (std::size_t k = 0; k < bodies_.size(); ++k) {
          const BodySpec& a = bodies_[k];
          if (a.surface >= 0) continue;
          const double ox = std::min(a.x1, b.x1) - std::max(a.x0, b.x0);
          const double oy = std::min(a.y1, b.y1) - std::max(a.y0, b.y0);
          if (ox > tol && oy > tol)
            o.fail("box", "overlaps body \"" + a.name + "\" (" + index_path("bodies", k) +
                              ") over " + fmt(ox) + " x " + fmt(oy) +
                              " m: bodies must not overlap (the mass there would count twice)");
        }
      o.done();
      bodies_.push_back(b);
    }
  }

  void parse_probes(const ojson& arr, Case& c) {
    if (!arr.is_array()) ctx_.fail("probes", "expected an array, got " + a_type(arr));
    for (std::size_t i = 0; i < arr.size(); ++i) {
      Obj o(ctx_, arr[i], index_path("probes", i));
      const bool along = o.has("curve");
      ProbeSpec p = parse_probe(o, grid_, body_names(), along);
      for (std::size_t f = 0; f < p.fields.size(); ++f)
        if ((p.fields[f] == "fcx" || p.fields[f] == "fcy") &&
            (p.body < 0 || s_->contact.type != ContactType::Multi))
          ctx_.fail(index_path(o.at("fields"), f),
                    "\"" + p.fields[f] + "\" is the contact force on the probe's body: it needs "
                    "\"body\" and contact.type \"multi\"");
      std::vector<ProbeSpec> points;
      if (along) points = curve_probe(o, p);
      else points.push_back(std::move(p));
      for (const auto& pt : points)
        for (const auto& q : c.probes)
          if (q.name == pt.name)
            o.fail("name", "probe name \"" + pt.name + "\" is used twice" +
                               (along ? " (a point of this probe along a curve)" : ""));
      if (along && points.size() >= 2) {
        const ProbeSpec &a = points.front(), &z = points.back();
        c.notes.push_back("probe \"" + a.along + "\" along the " + a.curve + ": " +
                          std::to_string(points.size()) + " points " + a.name + " (" + fmt(a.x) +
                          ", " + fmt(a.y) + ") ... " + z.name + " (" + fmt(z.x) + ", " + fmt(z.y) +
                          "), every " + fmt(points[1].s - a.s) + " m of arc length");
      }
      for (auto& pt : points) {
        probe_doc_.push_back(i);
        c.probes.push_back(std::move(pt));
      }
    }
  }

  // probes[i] with "curve": points evenly spaced by arc length along a physical curve, named
  // <name>_00, <name>_01, ... (geometry_probes.cpp). Each must lie in its body (or in a body).
  std::vector<ProbeSpec> curve_probe(Obj& o, const ProbeSpec& base) {
    const int ci = geometry_group(o, "curve", false);
    const auto& C = geo_->curves[ci];
    const std::string label = Geometry::label("physical curve", C.tag, C.name);
    const bool has_count = o.has("count"), has_spacing = o.has("spacing");
    if (has_count == has_spacing)
      o.fail("", has_count ? "give either count or spacing, not both"
                           : "needs count (number of points) or spacing (m) along the curve");
    long count = 0;
    double spacing = 0;
    if (has_count) {
      count = o.integer("count", 0);
      if (count < 2) o.fail("count", "must be >= 2 (the points include both ends), got " + std::to_string(count));
      if (count > 100000) o.fail("count", "must be <= 100000, got " + std::to_string(count));
    } else {
      spacing = o.num("spacing");
      o.gt("spacing", spacing, 0);
    }
    const bool reverse = o.boolean("reverse", false);
    o.done();
    if (checking_) return {};  // the points need the mesh
    CurvePoints cp;
    try {
      cp = curve_points(*geo_, C, static_cast<int>(count), spacing, reverse);
    } catch (const GeometryError& e) {
      o.fail(has_count ? "curve" : "spacing", e.what());
    }
    const std::size_t n = cp.points.size();
    const int width = std::max<int>(2, static_cast<int>(std::to_string(n - 1).size()));
    const double tol = 1e-6 * grid_.h;
    std::vector<ProbeSpec> out;
    for (std::size_t k = 0; k < n; ++k) {
      const CurvePoint& q = cp.points[k];
      ProbeSpec p = base;
      std::string idx = std::to_string(k);
      p.name = base.name + "_" + std::string(width - idx.size(), '0') + idx;
      p.x = q.x;
      p.y = q.y;
      p.along = base.name;
      p.curve = label;
      p.s = q.s;
      // Inside the body: its surface's elements (tested at the point's place on the meshed
      // segment) or its box.
      auto inside = [&](const BodySpec& b) {
        if (b.surface >= 0) return geo_->contains(geo_->surfaces[b.surface], q.cx, q.cy, tol);
        return q.x >= b.x0 - tol && q.x <= b.x1 + tol && q.y >= b.y0 - tol && q.y <= b.y1 + tol;
      };
      bool ok = false;
      if (p.body >= 0) ok = inside(bodies_[p.body]);
      else for (const auto& b : bodies_) ok = ok || inside(b);
      if (!ok)
        o.fail("curve", geo_->file + ": " + label + ": point " + p.name + " at (" + fmt(q.x) + ", " +
                            fmt(q.y) + ") (arc length " + fmt(q.s) + " of " + fmt(cp.length) +
                            ") is outside " +
                            (p.body >= 0 ? "body \"" + bodies_[p.body].name + "\"" : "every body"));
      out.push_back(std::move(p));
    }
    return out;
  }

  // With bilinear shapes a particle exactly on a grid line takes its gradients from whichever
  // cell round-off puts it in, and a node beside it can get stiffness without mass: a
  // degenerate MPM (docs/physics.md section 4). Such bodies run, with a note saying so.
  void note_particles_on_grid_lines(Case& c) const {
    if (s_->opt.shape != ShapeKind::Bilinear) return;
    const Particles& p = s_->p;
    const Grid& g = s_->grid;
    std::vector<std::size_t> count(bodies_.size(), 0);
    auto on_line = [&](double x, double x0) {
      const double r = (x - x0) * g.inv_h;
      return std::abs(r - std::round(r)) < 1e-9;
    };
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.body[k] < count.size() && (on_line(p.x[k], g.x0) || on_line(p.y[k], g.y0)))
        ++count[p.body[k]];
    for (std::size_t b = 0; b < bodies_.size(); ++b)
      if (count[b] > 0)
        c.notes.push_back("note: body \"" + bodies_[b].name + "\": " + std::to_string(count[b]) +
                          " particles lie on grid lines, where bilinear shape functions are "
                          "degenerate (docs/physics.md section 4): shift the body by a fraction "
                          "of a cell, or use scheme.shape \"gimp\" or \"bspline\"");
  }

  // A bilinear body whose face lies just past a grid line leaves the node row beyond it a sliver
  // of mass, whose soft mode rings (docs/physics.md section 8.7). With scheme.light_nodes "keep"
  // a note counts the nodes the default extension would take at the start.
  void note_light_nodes(Case& c) const {
    if (s_->opt.light_node_ratio > 0) return;
    const std::size_t n = s_->light_nodes_at_start(LightNodes::kDefaultRatio);
    if (n > 0)
      c.notes.push_back("note: " + std::to_string(n) + " grid nodes beyond the bodies' faces "
                        "hold a sliver of their particles (a face just past a grid line), whose "
                        "surface layer rings there (docs/physics.md section 8.7): "
                        "scheme.light_nodes \"extend\" takes them out");
  }

  void seed() {
    double estimate = 0;
    for (const auto& b : bodies_) {
      const double n = std::sqrt(static_cast<double>(b.ppc));
      estimate += std::max(1.0, std::round((b.x1 - b.x0) / grid_.h * n)) *
                  std::max(1.0, std::round((b.y1 - b.y0) / grid_.h * n));
    }
    if (estimate > kMaxParticles)
      ctx_.fail("bodies", "too many particles (about " + fmt(estimate) + "; the limit is " +
                              fmt(kMaxParticles) + ")");
    // Memory before allocating: the grid's 14 nodal arrays (and 13 more per body with
    // multi-field contact) and the particle arrays with the film block, against the machine's
    // physical memory.
    {
      const double nodes = (grid_.nx + 1.0) * (grid_.ny + 1.0);
      const double per_node = 15 * 8.0 + (s_->contact.multi() ? 16 * 8.0 * bodies_.size() : 0.0);
      const double per_particle = Particles::bytes_per_particle() + Particles::film_bytes_per_particle();
      const double bytes = nodes * per_node + estimate * per_particle;
      const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
      const double phys = pages > 0 && page > 0 ? static_cast<double>(pages) * page : 0.0;
      const double cap = load_limits().memory_bytes;
      if (cap > 0 && bytes > cap)
        ctx_.fail("grid", "the run would need about " + fmt_down(bytes / 1e9) + " GB (" +
                              fmt(nodes) + " grid nodes, about " + fmt(estimate) +
                              " particles); the limit set is " + fmt_down(cap / 1e9) +
                              " GB: use larger cells or a smaller grid");
      if (phys > 0 && bytes > 0.8 * phys)
        ctx_.fail("grid", "the run would need about " + fmt_down(bytes / 1e9) + " GB (" +
                              fmt(nodes) + " grid nodes, about " + fmt(estimate) +
                              " particles); this machine has " + fmt_down(phys / 1e9) +
                              " GB of memory: use larger cells or a smaller grid");
    }
    // Split from the start (scatter): the ranks' windows hold the nodal fields, not this grid.
    s_->grid.init(grid_.x0, grid_.y0, grid_.h, grid_.nx, grid_.ny, !scattered_);
    s_->materials = materials_;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const auto& b = bodies_[i];
      const int n = b.ppc == 1 ? 1 : b.ppc == 4 ? 2 : 3;
      const std::size_t added =
          b.surface >= 0 ? seed_body_surface(i, n)
                         : s_->seed_rectangle(b.x0, b.y0, b.x1, b.y1, n, b.material,
                                              static_cast<int>(i), b.vx, b.vy, b.seeding);
      if (added == 0)
        ctx_.fail(index_path("bodies", i) + (b.surface >= 0 ? ".surface" : ".box"),
                  "seeds no particle");
    }
  }

  int body_ref(Obj& o) {
    const std::string name = o.str("body");
    for (std::size_t i = 0; i < bodies_.size(); ++i)
      if (bodies_[i].name == name) return static_cast<int>(i);
    o.fail("body", "no body named \"" + name + "\"" + suggestion(name, body_names()) +
                       "; bodies: " + join(body_names()));
  }

  // Nodes for fixed / roller: exactly one of grid_side, box, body + side.
  std::vector<uint32_t> select_nodes(Obj& o) {
    const int forms = o.has("grid_side") + o.has("box") + o.has("body") + o.has("curve");
    if (forms == 0)
      o.fail("", "needs a node selection: one of grid_side, box, body + side, or curve");
    if (forms > 1)
      o.fail("", "give only one node selection: grid_side, box, body + side, or curve");
    if (o.has("side") && !o.has("body"))
      o.fail("side", "only used with body (use grid_side for an edge of the grid)");
    const double tol = 1e-6 * grid_.h;
    double x0, y0, x1, y1;
    std::string what;
    if (o.has("curve")) return curve_nodes(o);  // a gmsh physical curve (silentmpm/geometry.hpp)
    if (o.has("grid_side")) {
      const std::string side = o.choice("grid_side", kSides);
      x0 = side == "right" ? grid_.x1() : grid_.x0;
      x1 = side == "left" ? grid_.x0 : grid_.x1();
      y0 = side == "top" ? grid_.y1() : grid_.y0;
      y1 = side == "bottom" ? grid_.y0 : grid_.y1();
      what = "grid side " + side;
    } else if (o.has("box")) {
      const auto box = o.nums("box", 4);
      if (!(box[2] >= box[0])) o.fail("box", "x1 must be >= x0, got " + fmt_list(box));
      if (!(box[3] >= box[1])) o.fail("box", "y1 must be >= y0, got " + fmt_list(box));
      x0 = box[0], y0 = box[1], x1 = box[2], y1 = box[3];
      what = "box " + fmt_list(box);
    } else {
      const BodySpec& b = bodies_[body_ref(o)];
      const std::string side = o.choice("side", kSides);
      const Edge e = box_edge(b, side);
      // The grid line nearest the edge; the edge must lie on it.
      const bool vertical = e.nx != 0;
      const double coord = vertical ? e.ex0 : e.ey0;
      const double origin = vertical ? grid_.x0 : grid_.y0;
      const double line = origin + std::round((coord - origin) / grid_.h) * grid_.h;
      if (std::fabs(line - coord) > tol)
        o.fail("side", "the " + side + " edge of body \"" + b.name + "\" (" +
                           (vertical ? "x" : "y") + " = " + fmt(coord) +
                           ") is not on a grid line (nearest: " + fmt(line) + ")");
      x0 = vertical ? line : b.x0;
      x1 = vertical ? line : b.x1;
      y0 = vertical ? b.y0 : line;
      y1 = vertical ? b.y1 : line;
      what = side + " edge of body \"" + b.name + "\"";
    }
    if (checking_) return {};  // no grid yet
    auto nodes = s_->nodes_in_box(x0, y0, x1, y1);
    if (nodes.empty()) o.fail("", "selects no node (" + what + ")");
    return nodes;
  }

  // Particle layer for traction / silent: body, side, width.
  BoundaryLayer select_layer(Obj& o, const std::string& name, std::string& what) {
    const int bi = body_ref(o);
    const BodySpec& b = bodies_[bi];
    if (o.has("interval") && (o.has("curve") || b.surface >= 0))
      o.fail("interval", "is for a side of a box body (on a gmsh body, name a physical curve for "
                         "the part to load)");
    if (o.has("curve") || b.surface >= 0) return curve_layer(o, bi, name, what);
    const std::string side = o.choice("side", kSides);
    Edge e = box_edge(b, side);
    const double width = o.num("width", grid_.h);
    o.gt("width", width, 0);
    if (!(width <= e.extent * (1 + 1e-12)))
      o.fail("width", "must be <= the size of body \"" + b.name + "\" normal to its " + side +
                          " side (" + fmt(e.extent) + "), got " + fmt(width));
    // traction "interval": [a, b], the part of the side between two coordinates along it (x on
    // the top and bottom sides, y on the left and right).
    std::string part;
    if (o.has("interval")) {
      const auto iv = o.nums("interval", 2);
      const bool along_x = e.nx == 0;
      const double lo = along_x ? b.x0 : b.y0, hi = along_x ? b.x1 : b.y1;
      const double tol = 1e-9 * grid_.h;
      if (!(iv[1] > iv[0]))
        o.fail("interval", "must be [a, b] with a < b, got " + fmt_list(iv));
      if (iv[0] < lo - tol || iv[1] > hi + tol)
        o.fail("interval", fmt_list(iv) + " is not within the " + side + " side of body \"" +
                               b.name + "\" (" + (along_x ? "x" : "y") + " from " + fmt(lo) +
                               " to " + fmt(hi) + ")");
      // The edge runs counter-clockwise around the box: keep its direction.
      const double from = (along_x ? e.ex1 > e.ex0 : e.ey1 > e.ey0) ? iv[0] : iv[1];
      const double to = from == iv[0] ? iv[1] : iv[0];
      (along_x ? e.ex0 : e.ey0) = from;
      (along_x ? e.ex1 : e.ey1) = to;
      part = std::string(" over ") + (along_x ? "x" : "y") + " in " + fmt_list(iv);
    }
    if (checking_) return {};  // no particles yet
    BoundaryLayer layer = s_->select_layer(name, bi, e.ex0, e.ey0, e.ex1, e.ey1, e.nx, e.ny, width);
    what = side + " side of body \"" + b.name + "\"" + part + ", width " + fmt(width);
    if (layer.ids.empty() && !skeleton_) o.fail("", "selects no particle (" + what + ")");
    return layer;
  }

  void parse_boundary(Obj o, std::size_t i, Case& c) {
    const std::string type =
        o.choice("type", {"fixed", "roller", "traction", "silent", "kelvin_voigt", "damping_layer", "pml"});
    const std::string where = "for a " + type + " boundary";
    if (type == "fixed" || type == "roller") {
      std::vector<std::string> keys = {"type", "name", "grid_side", "box", "body", "side", "curve"};
      if (type == "roller") keys.push_back("component");
      o.allow(keys, where);
    } else if (type == "traction") {
      o.allow({"type", "name", "body", "side", "curve", "width", "normal", "tangential", "vector",
               "time", "anchor", "interval"},
              where);
    } else if (type == "damping_layer") {
      o.allow({"type", "name", "body", "side", "curve", "width", "r0", "power", "beta"}, where);
    } else if (type == "pml") {
      o.allow({"type", "name", "body", "side", "curve", "width", "r0", "power", "alpha", "parallel"}, where);
    } else if (type == "silent") {
      o.allow({"type", "name", "body", "side", "curve", "width", "a", "b", "form", "anchor",
               "edge_velocity"},
              where);
    } else {
      o.allow({"type", "name", "body", "side", "curve", "width", "a", "b", "form", "anchor",
               "edge_velocity", "delta", "alpha_n", "alpha_t"},
              where);
    }
    const std::string name = o.str("name", type + std::to_string(i));
    if (name.empty()) o.fail("name", "must not be empty");

    if (type == "fixed" || type == "roller") {
      NodalConstraint nc;
      nc.name = name;
      nc.mask = 3;
      if (type == "roller") nc.mask = o.choice("component", {"x", "y"}) == "x" ? 1 : 2;
      nc.nodes = select_nodes(o);
      o.done();
      s_->constraints.push_back(std::move(nc));
      return;
    }

    if (type == "traction") {
      const bool scalar = o.has("normal") || o.has("tangential");
      if (scalar && o.has("vector"))
        o.fail("vector", "give either normal/tangential or vector, not both");
      if (!scalar && !o.has("vector"))
        o.fail("", "missing the traction: give normal and/or tangential, or vector");
      TractionLoad t;
      std::string what;
      t.layer = select_layer(o, name, what);
      std::string amp;
      if (scalar) {
        t.normal = o.num("normal", 0.0);
        t.tangential = o.num("tangential", 0.0);
        amp = "normal " + fmt(t.normal) + " Pa, tangential " + fmt(t.tangential) + " Pa";
      } else {
        const auto v = o.nums("vector", 2);
        t.vx = v[0];
        t.vy = v[1];
        amp = "vector (" + fmt(t.vx) + ", " + fmt(t.vy) + ") Pa";
      }
      if (const ojson* tf = o.find("time")) t.fn = parse_time_function(Obj(ctx_, *tf, o.at("time")));
      t.anchor = o.choice("anchor", {"boundary", "particle"}, "boundary") == "boundary"
                     ? Anchor::Boundary
                     : Anchor::Particle;
      o.done();
      c.notes.push_back("traction \"" + name + "\" on the " + what + " (" +
                        std::to_string(t.layer.ids.size()) + " particles): " + amp + " x " +
                        t.fn.describe());
      s_->tractions.push_back(std::move(t));
      return;
    }

    if (type == "pml") {
      // A band inside a side of a box body: the stretching acts along the side's normal, which
      // must be an axis (docs/physics.md section 9.3). USL, or MUSL and USF with one velocity
      // field (the layer damps its particles), at 1 particle per cell only with enough cells and
      // a frequency shift (below).
      const bool damps = s_->opt.scheme != Scheme::USL;
      const std::string scheme = scheme_name(s_->opt.scheme);
      if (damps && s_->contact.multi())
        o.fail("type", "a pml on particles under scheme.update \"" + scheme + "\" is not "
                       "available with multi-field contact (use \"USL\")");
      PmlBand band;
      band.name = name;
      band.body = body_ref(o);
      const BodySpec& b = bodies_[band.body];
      std::string side;  // "left side" or the physical curve's label
      double extent = 0;
      if (o.has("curve") || b.surface >= 0) {
        pml_curve(o, b, band, side, extent);
      } else {
        const std::string s = o.choice("side", kSides);
        const Edge e = box_edge(b, s);
        band.axis = e.nx != 0 ? 0 : 1;
        band.side = (e.nx + e.ny) > 0 ? 1 : -1;
        band.c = band.axis == 0 ? e.ex0 : e.ey0;
        extent = e.extent;
        side = s + " side";
      }
      band.width = o.num("width");
      o.gt("width", band.width, 0);
      if (!(band.width <= extent * (1 + 1e-12)))
        o.fail("width", "must be <= the size of body \"" + b.name + "\" normal to its " + side +
                            " (" + fmt(extent) + "), got " + fmt(band.width));
      band.r0 = o.num("r0", kPmlDefaultR0);
      if (!(band.r0 > 0 && band.r0 < 1)) o.fail("r0", "must be in (0, 1), got " + fmt(band.r0));
      band.power = o.num("power", 2.0);
      o.ge("power", band.power, 0);
      // "auto": the least shift the scheme needs (below), 0 where it needs none.
      const ojson* given_alpha = o.find("alpha");
      const bool auto_alpha = given_alpha && given_alpha->is_string();
      if (auto_alpha) {
        const std::string a = o.str("alpha");
        if (a != "auto") o.fail("alpha", "must be a number >= 0 or \"auto\", got \"" + a + "\"");
      } else {
        band.alpha = o.num("alpha", 0.0);
        o.ge("alpha", band.alpha, 0);
      }
      if (damps && b.ppc < 4) {
        // At 1 particle per cell MUSL and USF carry slow backward waves (the odd-even branch
        // near the grid's shortest wavelength), which a stretching amplifies; a layer of enough
        // cells with a frequency shift above their frequencies leaves them alone
        // (docs/physics.md section 9.3).
        const std::string why = "a pml on particles under scheme.update \"" + scheme +
                                "\" at 1 particle per cell (body \"" + b.name + "\") needs ";
        const std::string or_else = " (slow backward waves of the scheme grow in a thinner or "
                                    "unshifted layer; put LK behind it), or give the body "
                                    "\"particles_per_cell\": 4, or use scheme.update \"USL\" "
                                    "(docs/physics.md section 9.3)";
        const double h = grid_.h;
        if (!(band.width >= kPmlOnePpcCells * h * (1 - 1e-9)))
          o.fail("width", why + "width >= " + std::to_string(kPmlOnePpcCells) + " cells (" +
                              fmt(kPmlOnePpcCells * h) + " m), got " + fmt(band.width) + or_else);
        const double cd = materials_[static_cast<std::size_t>(b.material)].cd;
        const double need = pml_one_ppc_alpha(cd, band.r0, band.power, band.width, h);
        if (auto_alpha) band.alpha = need;
        if (!(band.alpha >= need))
          o.fail("alpha", why + "alpha >= " + fmt(kPmlOnePpcShift) + " sqrt(d0 c_d / h) = " +
                              fmt(need) + " 1/s for this layer (\"auto\" takes it), got " +
                              fmt(band.alpha) + or_else);
      }
      band.parallel = o.num("parallel", 0.0);
      o.ge("parallel", band.parallel, 0);
      o.lt("parallel", band.parallel, 1);
      for (const PmlBand& other : s_->pml_bands)
        if (other.alpha != band.alpha)
          o.fail("alpha", "every pml must have the same alpha (\"" + other.name + "\" has " +
                              fmt(other.alpha) + ", this one " + fmt(band.alpha) +
                              (auto_alpha ? " from \"auto\"; give every pml the larger number" : "") +
                              ")");
      o.done();
      std::size_t inside = 0;  // particles inside the band (its depth > 0 at their centre)
      if (!checking_ && !skeleton_) {
        const Particles& P = s_->p;
        for (std::size_t k = 0; k < P.size(); ++k) {
          if (P.body[k] != band.body) continue;
          const double pos = band.axis == 0 ? P.x[k] : P.y[k];
          if ((pos - (band.c - band.side * band.width)) * band.side > 0) ++inside;
        }
        if (inside == 0)
          o.fail("width", "selects no particle: no particle centre of body \"" + b.name +
                              "\" lies within " + fmt(band.width) + " m of its " + side);
      }
      c.notes.push_back("pml \"" + name + "\" inside the " + side + " of body \"" + b.name +
                        "\": " + fmt(band.width) + " m, r0 " + fmt(band.r0) + ", power " +
                        fmt(band.power) + ", alpha " + fmt(band.alpha) + " 1/s" +
                        (auto_alpha ? " (auto)" : "") + ", " +
                        (band.parallel > 0 ? "multi-axial share " + fmt(band.parallel) + ", " : "") +
                        std::to_string(inside) + " particles");
      s_->pml_bands.push_back(std::move(band));
      return;
    }

    if (type == "damping_layer") {
      if (!o.has("width")) o.fail("width", "missing required key (the layer's thickness, m)");
      DampingLayer dl;
      std::string what;
      dl.layer = select_layer(o, name, what);
      dl.r0 = o.num("r0", 1e-3);
      if (!(dl.r0 > 0 && dl.r0 < 1)) o.fail("r0", "must be in (0, 1), got " + fmt(dl.r0));
      dl.power = o.num("power", 2.0);
      o.ge("power", dl.power, 0);
      dl.beta0 = o.num("beta", 0.0);
      o.ge("beta", dl.beta0, 0);
      o.done();
      c.notes.push_back("damping_layer \"" + name + "\" on the " + what + " (" +
                        std::to_string(dl.layer.ids.size()) + " particles): alpha = alpha0 s^" +
                        fmt(dl.power) + ", alpha0 = -(" + fmt(dl.power) + " + 1) c_d ln(" +
                        fmt(dl.r0) + ") / width" +
                        (dl.beta0 > 0 ? ", beta = " + fmt(dl.beta0) + " s^" + fmt(dl.power) + " s"
                                      : std::string()));
      s_->dampers.push_back(std::move(dl));
      return;
    }

    // silent, kelvin_voigt (the same dashpots with springs)
    SilentBoundary sb;
    std::string what;
    sb.layer = select_layer(o, name, what);
    // At 1 particle per cell under MUSL and USF the mass correction made a column's silent end
    // reflect 8 % (0.7 % without it; docs/physics.md section 1.1): the correction doubles the
    // increment of the grid's pattern that such particles do not map back, which the dashpots'
    // solve leaves out. (Under USL, whose dashpots solve nothing, it reflects less than without.)
    if (s_->opt.mass_correction > 0 && s_->opt.scheme != Scheme::USL)
      for (const std::uint32_t k : sb.layer.idx)
        if (s_->p.body[k] < bodies_.size() && bodies_[s_->p.body[k]].ppc == 1)
          o.fail("", "the " + type + " edge \"" + name + "\" lies on particles of 1 per cell "
                     "(the particle at (" + fmt(s_->p.x[k]) + ", " + fmt(s_->p.y[k]) +
                     ") fills " + fmt(s_->p.vol[k] / (grid_.h * grid_.h)) + " of a cell), "
                     "where scheme.mass_correction under " + scheme_name(s_->opt.scheme) +
                     " makes its dashpots reflect about 8 %: seed 2 or more particles per cell "
                     "side, use scheme.update \"USL\", or set scheme.mass_correction to 0");
    sb.a = o.num("a", 1.0);
    o.ge("a", sb.a, 0);
    sb.b = o.num("b", 1.0);
    o.ge("b", sb.b, 0);
    if (type == "kelvin_voigt") {
      sb.delta = o.num("delta");
      // The spring is explicit: stiffer than one cell of the material it would cut the time step.
      if (!(sb.delta >= grid_.h))
        o.fail("delta", "must be >= grid.cell (" + fmt(grid_.h) + " m), got " + fmt(sb.delta));
      sb.alpha_n = o.num("alpha_n", 1.0);
      o.ge("alpha_n", sb.alpha_n, 0);
      sb.alpha_t = o.num("alpha_t", 1.0);
      o.ge("alpha_t", sb.alpha_t, 0);
      c.notes.push_back("kelvin_voigt \"" + name + "\" on the " + what + " (" +
                        std::to_string(sb.layer.ids.size()) + " particles): dashpots a " +
                        fmt(sb.a) + ", b " + fmt(sb.b) + "; springs alpha_n rho c_d^2 / delta, " +
                        "alpha_t rho c_s^2 / delta with delta " + fmt(sb.delta) + " m, alpha_n " +
                        fmt(sb.alpha_n) + ", alpha_t " + fmt(sb.alpha_t));
    }
    sb.form = o.choice("form", {"nodal", "particle"}, "nodal") == "nodal" ? SilentForm::Nodal
                                                                         : SilentForm::Particle;
    // The paper's lagged form is stable only when mapped at the particle (see README).
    const std::string anchor_default = sb.form == SilentForm::Nodal ? "boundary" : "particle";
    sb.anchor = o.choice("anchor", {"boundary", "particle"}, anchor_default.c_str()) == "boundary"
                    ? Anchor::Boundary
                    : Anchor::Particle;
    // Which velocity MUSL and USF strain the particles with at the dashpots' nodes
    // (docs/physics.md section 4): the particles' own (MUSL's re-mapped one, USF's start-of-step
    // one; default) or the updated one the dashpots produced (USF: the last step's).
    const std::string edge_velocity =
        o.choice("edge_velocity", {"remapped", "updated", "delayed"}, "remapped");
    if (edge_velocity != "remapped" && s_->symmetric_correction())
      o.fail("edge_velocity", "\"" + edge_velocity + "\" is not available with "
                              "scheme.mass_correction_form \"symmetric\" (whose strain velocity is "
                              "the corrected re-mapped one); use \"remapped\" or the form "
                              "\"increment\"");
    if (edge_velocity == "delayed") {
      auto need = [&](bool ok, const std::string& why) {
        if (!ok) o.fail("edge_velocity", "\"delayed\" " + why);
      };
      need(s_->opt.scheme != Scheme::USL,
           "applies under scheme.update \"MUSL\" or \"USF\" (USL's end reflects 0.2 % without it)");
      need(sb.form == SilentForm::Nodal, "needs the nodal form");
      need(!s_->contact.multi(), "is not available with multi-field contact");
      need(type == "silent", "is not available with Kelvin-Voigt springs");
      need(sb.a == 1 && sb.b == 1, "needs a = b = 1 (its delay is the waves' travel time over a "
                                   "cell, h / c_d and h / c_s)");
      need(sb.anchor == Anchor::Boundary, "needs \"anchor\": \"boundary\"");
      need(s_->opt.shape == ShapeKind::Bilinear, "needs scheme.shape \"bilinear\"");
      // Its derivation holds for 1 particle per cell and an edge on a grid line along an axis
      // (docs/physics.md section 4): checked at each of the layer's particles.
      const Particles& P = s_->p;
      const double h = grid_.h, cell = h * h;
      for (std::size_t q = 0; q < sb.layer.idx.size(); ++q) {
        const std::uint32_t k = sb.layer.idx[q];
        const double nx = sb.layer.nx[q], ny = sb.layer.ny[q];
        const std::string at = "the particle at (" + fmt(P.x[k]) + ", " + fmt(P.y[k]) + ")";
        need(std::abs(P.vol[k] - cell) <= 1e-6 * cell,
             "needs 1 particle per cell (" + at + " fills " + fmt(P.vol[k] / cell) + " of a cell)");
        const bool along_x = std::abs(std::abs(nx) - 1) < 1e-12;
        const bool along_y = std::abs(std::abs(ny) - 1) < 1e-12;
        need(along_x || along_y, "needs an edge along the grid's axes (" + at + " has the normal (" +
                                     fmt(nx) + ", " + fmt(ny) + "))");
        const double e = along_x ? (P.x[k] + sb.layer.d[q] * nx - grid_.x0) / h
                                 : (P.y[k] + sb.layer.d[q] * ny - grid_.y0) / h;
        const double off = std::abs(e - std::round(e));
        need(off <= 1e-6, "needs the edge on a grid line (the edge at " + at + " lies " + fmt(off) +
                              " of a cell off one)");
        need(materials_[P.group[k]].cs > 0, "needs a material with a shear wave speed (" + at +
                                                   " has none)");
        // The blocks exactly on the axes (the closure runs where C_xy is 0).
        sb.layer.nx[q] = along_x ? std::copysign(1.0, nx) : 0.0;
        sb.layer.ny[q] = along_x ? 0.0 : std::copysign(1.0, ny);
      }
      delayed_at_ = o.path();
      sb.delayed = true;
    }
    if (edge_velocity == "updated") {
      if (s_->opt.scheme == Scheme::USL)
        o.fail("edge_velocity", "\"updated\" applies under scheme.update \"MUSL\" or \"USF\" "
                                "(USL strains the particles with the updated velocity "
                                "everywhere)");
      if (sb.form != SilentForm::Nodal)
        o.fail("edge_velocity", "\"updated\" needs the nodal form (the particle form puts no "
                                "dashpot on the nodes)");
      if (s_->contact.multi())
        o.fail("edge_velocity", "\"updated\" is not available with multi-field contact (each "
                                "body's field keeps its re-mapped velocity)");
      sb.updated_velocity = true;
    }
    o.done();
    if (type == "silent")
      c.notes.push_back("silent \"" + name + "\" on the " + what + " (" +
                        std::to_string(sb.layer.ids.size()) + " particles): LK dashpots a " +
                        fmt(sb.a) + " rho c_d, b " + fmt(sb.b) + " rho c_s, " +
                        (sb.form == SilentForm::Nodal ? "nodal" : "particle") + " form, at the " +
                        (sb.anchor == Anchor::Boundary ? "boundary" : "particles") +
                        (sb.updated_velocity ? ", strained with the updated velocity" : "") +
                        (sb.delayed ? ", the delayed closure of 1 particle per cell" : ""));
    // The impedances a rho c_d and b rho c_s of each particle's material are set by
    // Solver::finalize().
    s_->silents.push_back(std::move(sb));
  }

  // ---- gmsh geometry: the "geometry" key, bodies from physical surfaces, boundaries from
  // physical curves (the work is done in geometry.cpp / geometry_mpm.cpp).
  void parse_geometry(Obj o) {
    o.allow({"file", "size", "parameters"});
    std::string file = o.str("file");
    if (file.empty()) o.fail("file", "must not be empty");
    namespace fs = std::filesystem;
    if (fs::path(file).is_relative()) file = (fs::path(ctx_.source).parent_path() / file).string();
    const double size = o.num("size", 0.5 * grid_.h);
    o.gt("size", size, 0);
    const auto params = read_geo_parameters(o);
    o.done();
    const GmshModule* gm = nullptr;
    try {
      gm = &detail::gmsh_module();
    } catch (const std::runtime_error& e) {
      o.fail("file", std::string("the gmsh module: ") + e.what());
    }
    auto load = [&] {
      return checking_ ? gm->load_geometry_groups(file, size, params)
                       : gm->load_geometry(file, size, params, load_limits().mesh_cells);
    };
    // Under an MPI launcher rank 0 alone reads (and meshes) the file and sends the geometry,
    // or its error, to the others: every rank then fails with rank 0's message.
    const detail::MpiModule* mpi = detail::mpi();
    if (mpi && mpi->size() > 1) {
      std::string bytes, why;
      if (mpi->rank() == 0) {
        try {
          bytes = pack_geometry(load());
        } catch (const std::exception& e) {
          why = e.what();
          if (why.empty()) why = file + ": the geometry could not be read";
        }
      }
      mpi->broadcast(why);
      if (!why.empty()) o.fail("file", why);
      mpi->broadcast(bytes);
      geo_ = std::make_unique<Geometry>(unpack_geometry(bytes));
      return;
    }
    try {
      geo_ = std::make_unique<Geometry>(load());
    } catch (const GeometryError& e) {
      o.fail("file", e.what());
    }
  }

  // A physical group named by its tag (integer) or its name (string); returns its index.
  int geometry_group(Obj& o, const std::string& key, bool surface) {
    const char* kind = surface ? "physical surface" : "physical curve";
    if (!geo_) o.fail(key, "needs the top-level key \"geometry\" (the gmsh file that defines the " + std::string(kind) + ")");
    const ojson& v = o.need(key);
    int idx = -1;
    std::string what;
    if (v.is_string()) {
      const std::string name = v.get<std::string>();
      idx = surface ? geo_->find_surface(name) : geo_->find_curve(name);
      what = std::string(kind) + " named \"" + name + "\"";
    } else {
      const long tag = as_integer(ctx_, v, o.at(key));
      idx = surface ? geo_->find_surface(static_cast<int>(tag)) : geo_->find_curve(static_cast<int>(tag));
      what = std::string(kind) + " " + std::to_string(tag);
    }
    if (idx < 0)
      o.fail(key, geo_->file + ": no " + what + "; defined: " +
                      (surface ? geo_->list_surfaces() : geo_->list_curves()));
    return idx;
  }

  // bodies[i].surface: returns the surface's extent [x0, y0, x1, y1].
  std::vector<double> body_surface(Obj& o, BodySpec& b) {
    if (o.has("box")) o.fail("surface", "give either box or surface, not both");
    b.surface = geometry_group(o, "surface", true);
    if (checking_) return {grid_.x0, grid_.y0, grid_.x1(), grid_.y1()};  // no mesh yet
    const auto& S = geo_->surfaces[b.surface];
    const auto e = geo_->bounds(S);
    const double tol = 1e-6 * grid_.h;
    if (e[0] < grid_.x0 - tol || e[2] > grid_.x1() + tol || e[1] < grid_.y0 - tol ||
        e[3] > grid_.y1() + tol)
      o.fail("surface", geo_->file + ": " + Geometry::label("physical surface", S.tag, S.name) +
                            " is partly outside the grid " + grid_.describe() + ": its extent is " +
                            fmt_list({e[0], e[1], e[2], e[3]}));
    return {e[0], e[1], e[2], e[3]};
  }

  std::size_t seed_body_surface(std::size_t i, int n) {
    const BodySpec& b = bodies_[i];
    try {
      return seed_surface(*s_, *geo_, geo_->surfaces[b.surface], n, b.material,
                          static_cast<int>(i), b.vx, b.vy, b.seeding);
    } catch (const GeometryError& e) {
      ctx_.fail(index_path("bodies", i) + ".surface", e.what());
    }
  }

  // Fixed / roller on a curve: the grid nodes within h/2 of it.
  std::vector<uint32_t> curve_nodes(Obj& o) {
    const int ci = geometry_group(o, "curve", false);
    if (checking_) return {};
    const auto& C = geo_->curves[ci];
    auto nodes = nodes_near_curve(*s_, *geo_, C, 0.5 * grid_.h);
    if (nodes.empty())
      o.fail("curve", geo_->file + ": " + Geometry::label("physical curve", C.tag, C.name) +
                          " selects no grid node (nodes within h/2 = " + fmt(0.5 * grid_.h) +
                          " of the curve)");
    return nodes;
  }

  // Traction / silent layer on a curve: the particles of the body within `width` of it.
  // A pml along a physical curve of a body from a gmsh surface: the curve must be one straight
  // line parallel to an axis, on the edge of the body's bounding box and spanning it, so that
  // the band is every particle of the body within its width of that line (the stretching acts
  // along the line's normal only; docs/physics.md section 9.3).
  void pml_curve(Obj& o, const BodySpec& b, PmlBand& band, std::string& label, double& extent) {
    if (!o.has("curve"))
      o.fail("side", "body \"" + b.name + "\" comes from a gmsh surface: give its boundary as "
                     "\"curve\" (a physical curve) instead of \"side\"");
    if (o.has("side")) o.fail("side", "give either side or curve, not both");
    const auto& C = geo_->curves[geometry_group(o, "curve", false)];
    label = Geometry::label("physical curve", C.tag, C.name);
    extent = std::numeric_limits<double>::infinity();
    if (checking_) return;  // the geometry's lines are not read yet
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const auto& sg : C.segs)
      for (const int n : sg) {
        x0 = std::min(x0, geo_->x[n]);
        x1 = std::max(x1, geo_->x[n]);
        y0 = std::min(y0, geo_->y[n]);
        y1 = std::max(y1, geo_->y[n]);
      }
    for (const auto& m : C.mid) {  // a curved segment bulges off its chord
      x0 = std::min(x0, m[0]);
      x1 = std::max(x1, m[0]);
      y0 = std::min(y0, m[1]);
      y1 = std::max(y1, m[1]);
    }
    const double tol = 1e-9 * std::max(b.x1 - b.x0, b.y1 - b.y0);
    const bool vertical = x1 - x0 <= tol, horizontal = y1 - y0 <= tol;
    if (!vertical && !horizontal)
      o.fail("curve", geo_->file + ": " + label + " is not a straight line parallel to the x or "
                      "the y axis (it spans x " + fmt(x0) + " to " + fmt(x1) + ", y " + fmt(y0) +
                      " to " + fmt(y1) + "): a pml on particles stretches along an axis only");
    band.axis = vertical ? 0 : 1;
    band.c = vertical ? x0 : y0;
    const double lo = vertical ? b.x0 : b.y0, hi = vertical ? b.x1 : b.y1;
    if (std::abs(band.c - lo) <= tol) band.side = -1;
    else if (std::abs(band.c - hi) <= tol) band.side = 1;
    else
      o.fail("curve", geo_->file + ": " + label + " (" + (vertical ? "x = " : "y = ") +
                          fmt(band.c) + ") is not on the edge of body \"" + b.name +
                          "\"'s bounding box: a pml is a band along an outer edge of the body");
    const double a0 = vertical ? y0 : x0, a1 = vertical ? y1 : x1;
    const double b0 = vertical ? b.y0 : b.x0, b1 = vertical ? b.y1 : b.x1;
    if (a0 > b0 + tol || a1 < b1 - tol)
      o.fail("curve", geo_->file + ": " + label + " covers " + (vertical ? "y" : "x") + " from " +
                          fmt(a0) + " to " + fmt(a1) + ", not the whole edge of body \"" + b.name +
                          "\" (" + fmt(b0) + " to " + fmt(b1) + "): a pml spans its body's edge");
    extent = hi - lo;
  }

  BoundaryLayer curve_layer(Obj& o, int bi, const std::string& name, std::string& what) {
    const BodySpec& b = bodies_[bi];
    if (!o.has("curve"))
      o.fail("side", "body \"" + b.name + "\" comes from a gmsh surface: give its boundary as "
                     "\"curve\" (a physical curve) instead of \"side\"");
    if (o.has("side")) o.fail("side", "give either side or curve, not both");
    const int ci = geometry_group(o, "curve", false);
    const auto& C = geo_->curves[ci];
    const double width = o.num("width", grid_.h);
    o.gt("width", width, 0);
    if (checking_) return {};  // no particles yet
    BodyRegion region;
    if (b.surface >= 0) region.surface = &geo_->surfaces[b.surface];
    region.x0 = b.x0, region.y0 = b.y0, region.x1 = b.x1, region.y1 = b.y1;
    const std::string label = Geometry::label("physical curve", C.tag, C.name);
    BoundaryLayer layer;
    try {
      layer = select_curve_layer(*s_, *geo_, C, region, bi, width, name);
    } catch (const GeometryError& e) {
      o.fail("curve", std::string(e.what()) + " (body \"" + b.name + "\")");
    }
    what = label + " of body \"" + b.name + "\", width " + fmt(width);
    if (layer.ids.empty() && !skeleton_)
      o.fail("curve", geo_->file + ": " + label + " selects no particle of body \"" + b.name +
                          "\" (none within width " + fmt(width) + " of the curve)");
    return layer;
  }

  void set_time_step() {
    const double crit = s_->critical_dt();
    if (!(crit > 0) || !std::isfinite(crit))
      ctx_.fail("time", "cannot compute the stability limit (critical dt = " + fmt(crit) + ")");
    double dt;
    if (use_cfl_) {
      dt = dt_or_cfl_ * crit;
    } else {
      dt = dt_or_cfl_;
      bool viscous = false;  // a damping layer's stiffness part lowers the limit
      for (const auto& dl : s_->dampers) viscous = viscous || dl.beta0 > 0;
      if (dt > crit * (1 + 1e-12))
        ctx_.fail("time.dt", fmt(dt) + " s is above the stability limit " + fmt_down(crit) +
                                 (viscous ? " s (h / max c_d, lowered by a damping_layer's beta)"
                                          : " s = h / max c_d") +
                                 " (CFL " + fmt(dt / crit) + " > 1); use dt <= " +
                                 fmt_down(crit) + " or set time.cfl");
    }
    const std::string e = detail::step_count_error(t_end_, dt);
    if (!e.empty()) ctx_.fail("time", e);
    s_->dt = dt;
    s_->t = 0;
  }
};

Case build_ordered(const Ctx& ctx, const ojson& doc, bool checking = false, bool scatter = false,
                   bool skeleton = false) {
  try {
    return Builder(ctx, doc, checking, scatter, skeleton).build();
  } catch (const CaseError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw CaseError(ctx.source + ": not enough memory to build the case");
  } catch (const std::exception& e) {
    throw CaseError(ctx.source + ": error while building the case: " + e.what());
  }
}

}  // namespace

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  return detail::suggestion(word, candidates);
}

namespace {
std::string read_case_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw CaseError(path + ": cannot open file (it is a directory)");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw CaseError(path + ": cannot open file");
  std::ostringstream ss;
  ss << f.rdbuf();
  if (f.bad()) throw CaseError(path + ": cannot read file");
  return ss.str();
}

Case load_text(const std::string& text, const std::string& source,
               const std::vector<std::string>& overrides, bool scatter, bool skeleton) {
  Ctx ctx{source, {}};
  ojson doc = parse_text(text, source);
  for (const auto& o : overrides) apply_override(ctx, doc, o);
  Case c = build_ordered(ctx, doc, false, scatter, skeleton);
  c.fingerprint = detail::case_fingerprint(doc);
  return c;
}
}  // namespace

Case load_case(const std::string& path, const std::vector<std::string>& overrides) {
  return load_text(read_case_file(path), path, overrides, false, false);
}

Case load_case_on_ranks(const std::string& path, const std::vector<std::string>& overrides) {
  const detail::MpiModule* mpi = detail::mpi();
  if (!mpi || mpi->size() <= 1) return load_case(path, overrides);
  const bool root = mpi->rank() == 0;
  std::string error;
  Case c;
  try {
    c = load_text(read_case_file(path), path, overrides, true, !root);
  } catch (const std::exception& e) {
    error = e.what();
    if (error.empty()) error = path + ": the case could not be built";
  }
  // Every rank learns whether any failed, then takes rank 0's message (rank 0 built the whole
  // case and ran every check; a rank whose skeleton failed alone names its rank).
  if (!mpi->any(!error.empty())) return c;
  std::string verdict = error;
  mpi->broadcast(verdict);
  if (verdict.empty())
    verdict = error.empty() ? path + ": the case could not be built on another rank"
                            : error + " (rank " + std::to_string(mpi->rank()) + ")";
  throw CaseError(verdict);
}

Case load_case_text(const std::string& text, const std::string& source,
                    const std::vector<std::string>& overrides) {
  return load_text(text, source, overrides, false, false);
}

namespace {
LoadLimits g_limits;
}
void set_load_limits(const LoadLimits& limits) { g_limits = limits; }
const LoadLimits& load_limits() { return g_limits; }

Case build_case(const nlohmann::json& doc, const std::string& source) {
  Ctx ctx{source, {}};
  const ojson ordered(doc);  // nlohmann::json keeps keys sorted; material groups follow that order
  Case c = build_ordered(ctx, ordered);
  c.fingerprint = detail::case_fingerprint(ordered);
  return c;
}

// Shared with case_fem.cpp and case_hybrid.cpp (the FEM sections use the same material and
// time-function keys; a hybrid builds its MPM region with this parser).
namespace detail {
Case build_mpm_case(const Ctx& ctx, const ojson& doc) { return build_ordered(ctx, doc); }
void check_mpm_case(const Ctx& ctx, const ojson& doc) { build_ordered(ctx, doc, true); }
Material parse_material_at(const Ctx& ctx, const std::string& name, const ojson& j) {
  return parse_material(ctx, name, j);
}
TimeFunction parse_time_function_at(const Ctx& ctx, const ojson& j, const std::string& path) {
  return parse_time_function(Obj(ctx, j, path));
}
}  // namespace detail

}  // namespace smpm
