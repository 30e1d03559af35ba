#include "case_keys.hpp"

#include "silentmpm/case.hpp"
#include "silentmpm/gmsh_session.hpp"
#include "silentmpm/output.hpp"
#include "silentmpm/state_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "case_util.hpp"
#include "silentmpm/case.hpp"

namespace smpm::detail {

namespace {
bool starts_with(const std::string& s, const std::string& p) {
  return s.size() >= p.size() && s.compare(0, p.size(), p) == 0;
}
}  // namespace

}  // namespace smpm::detail

namespace smpm {
namespace {
std::string one_line(const std::string& m) {
  std::string s;
  s.reserve(m.size());
  for (const char ch : m) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') s += "\\n";
    else if (c == '\t') s += "\\t";
    else if (c == '\r') s += "\\r";
    else if (c < 0x20 || c == 0x7f) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02x", c);
      s += b;
    } else {
      s += ch;
    }
  }
  // Words (runs without spaces) over 200 characters: the first 80 and the count left out.
  std::string out;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t j = std::min(s.find(' ', i), s.size());
    if (j - i > 200) {
      // The word's last character stays when it is punctuation (the ':' after a key).
      const char last = s[j - 1];
      const bool keep = std::ispunct(static_cast<unsigned char>(last)) != 0;
      out += s.substr(i, 80) + "...(+" + std::to_string(j - i - 80 - keep) + " characters)";
      if (keep) out += last;
    } else
      out.append(s, i, j - i);
    if (j < s.size()) out += ' ';
    i = j + 1;
  }
  if (out.size() > 2000)
    out = out.substr(0, 1500) + " ...(" + std::to_string(out.size() - 1800) +
          " characters left out)... " + out.substr(out.size() - 300);
  return out;
}
}  // namespace

CaseError::CaseError(const std::string& what) : std::runtime_error(one_line(what)) {}

}  // namespace smpm

namespace smpm::detail {

void Ctx::fail(const std::string& path, const std::string& what) const {
  std::string m = source + ": " + (path.empty() ? "" : path + ": ") + what;
  for (const auto& [p, text] : overridden)
    if (!path.empty() && (path == p || starts_with(path, p + ".") || starts_with(path, p + "["))) {
      m += " (value set by override '" + text + "')";
      break;
    }
  throw CaseError(m);
}

double as_number(const Ctx& ctx, const ojson& v, const std::string& path) {
  if (!v.is_number()) ctx.fail(path, "expected a number, got " + a_type(v));
  const double d = v.get<double>();
  if (!std::isfinite(d)) ctx.fail(path, "expected a finite number");
  return d;
}

long as_integer(const Ctx& ctx, const ojson& v, const std::string& path) {
  if (v.is_number_integer()) {  // signed or unsigned
    if (v.is_number_unsigned() && v.get<std::uint64_t>() > 1000000000000ULL)
      ctx.fail(path, "integer too large");
    return static_cast<long>(v.get<std::int64_t>());
  }
  if (v.is_number_float()) {  // 1e3 parses as a float; accept it when it is a whole number
    const double d = v.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) <= 1e12) return static_cast<long>(d);
    ctx.fail(path, "expected an integer, got " + fmt(d));
  }
  ctx.fail(path, "expected an integer, got " + a_type(v));
}

std::string as_string(const Ctx& ctx, const ojson& v, const std::string& path) {
  if (!v.is_string()) ctx.fail(path, "expected a string, got " + a_type(v));
  return v.get<std::string>();
}

std::vector<double> as_numbers(const Ctx& ctx, const ojson& v, const std::string& path,
                               std::size_t n) {
  const std::string want = "expected an array of " + std::to_string(n) + " numbers";
  if (!v.is_array()) ctx.fail(path, want + ", got " + a_type(v));
  if (v.size() != n)
    ctx.fail(path, want + ", got an array of " + std::to_string(v.size()) + " element" +
                       (v.size() == 1 ? "" : "s"));
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(as_number(ctx, v[i], index_path(path, i)));
  return out;
}

Obj::Obj(const Ctx& ctx, const ojson& j, std::string path, Dialect dialect)
    : ctx_(&ctx), j_(&j), path_(std::move(path)), dialect_(dialect) {
  if (!j.is_object()) ctx.fail(path_, "expected an object, got " + a_type(j));
}

void Obj::allow(const std::vector<std::string>& keys, const std::string& where) const {
  for (const auto& item : j_->items()) {
    if (std::find(keys.begin(), keys.end(), item.key()) != keys.end()) continue;
    fail(item.key(), "unknown key" + (where.empty() ? "" : " " + where) +
                         (dialect_ == Dialect::Mpm ? suggestion(item.key(), keys) : "") +
                         "; allowed: " + join(keys));
  }
}

void Obj::done() const {
  std::vector<std::string> known(read_.begin(), read_.end());
  for (const auto& item : j_->items())
    if (!read_.count(item.key())) fail(item.key(), "unknown key" + suggestion(item.key(), known));
}

long Obj::integer(const std::string& key, long def) {
  const ojson* v = find(key);
  if (!v) return def;
  if (dialect_ == Dialect::Mpm) return as_integer(*ctx_, *v, at(key));
  if (v->is_number_integer()) return static_cast<long>(v->get<std::int64_t>());
  if (v->is_number_float() && v->get<double>() == std::floor(v->get<double>()) &&
      std::fabs(v->get<double>()) < 1e12)
    return static_cast<long>(v->get<double>());
  fail(key, "expected an integer, got " + (v->is_number() ? fmt(v->get<double>()) : a_type(*v)));
}

bool Obj::boolean(const std::string& key, bool def) {
  const ojson* v = find(key);
  if (!v) return def;
  if (!v->is_boolean()) fail(key, "expected true or false, got " + a_type(*v));
  return v->get<bool>();
}

std::string Obj::choice(const std::string& key, const std::vector<std::string>& options,
                        const char* def) {
  const bool mpm = dialect_ == Dialect::Mpm;
  const std::string list = mpm ? quoted_list(options) : join(options);
  const ojson* v = find(key);
  if (!v) {
    if (!def) fail(key, "missing required key (one of " + list + ")");
    return def;
  }
  const std::string s = as_string(*ctx_, *v, at(key));
  if (std::find(options.begin(), options.end(), s) == options.end())
    fail(key, "must be one of " + list + ", got \"" + s + "\"" +
                  (mpm ? suggestion(s, options) : ""));
  return s;
}

std::vector<double> Obj::nums(const std::string& key, std::size_t n) {
  const ojson& v = need(key);
  if (dialect_ == Dialect::Mpm) return as_numbers(*ctx_, v, at(key), n);
  const std::string want = "expected an array of " + std::to_string(n) + " numbers";
  if (!v.is_array() || v.size() != n) fail(key, want + ", got " + a_type(v));
  std::vector<double> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (!v[i].is_number()) fail(key, want);
    out.push_back(v[i].get<double>());
  }
  return out;
}

const ojson& Obj::array(const std::string& key) {
  const ojson& v = need(key);
  if (!v.is_array()) fail(key, "expected an array, got " + a_type(v));
  return v;
}

void Obj::gt(const std::string& key, double v, double lo) const {
  if (!(v > lo)) fail(key, "must be > " + fmt(lo) + ", got " + fmt(v));
}
void Obj::ge(const std::string& key, double v, double lo) const {
  if (!(v >= lo)) fail(key, "must be >= " + fmt(lo) + ", got " + fmt(v));
}
void Obj::lt(const std::string& key, double v, double hi) const {
  if (!(v < hi)) fail(key, "must be < " + fmt(hi) + ", got " + fmt(v));
}
void Obj::le(const std::string& key, double v, double hi) const {
  if (!(v <= hi)) fail(key, "must be <= " + fmt(hi) + ", got " + fmt(v));
}

void parse_output_section(Obj& o, OutputSpec& out, long max_snapshots) {
  o.allow({"history_every", "snapshots", "progress", "checkpoint_every", "checkpoint_time",
           "fields", "compression", "grid"});
  out.history_every = o.integer("history_every", 1);
  o.ge("history_every", static_cast<double>(out.history_every), 1);
  const long snaps = o.integer("snapshots", 10);
  o.ge("snapshots", static_cast<double>(snaps), 0);
  o.le("snapshots", static_cast<double>(snaps), static_cast<double>(max_snapshots));
  out.snapshots = static_cast<int>(snaps);
  out.progress = o.boolean("progress", true);
  if (o.has("checkpoint_every") && o.has("checkpoint_time"))
    o.fail("checkpoint_time", "give checkpoint_every (steps) or checkpoint_time (seconds), not both");
  out.checkpoint_every = o.integer("checkpoint_every", 0);
  o.ge("checkpoint_every", static_cast<double>(out.checkpoint_every), 0);
  out.checkpoint_time = o.num("checkpoint_time", 0.0);
  o.ge("checkpoint_time", out.checkpoint_time, 0);
  const long level = o.integer("compression", 0);
  o.ge("compression", static_cast<double>(level), 0);
  o.le("compression", static_cast<double>(level), 9);
  out.compression = static_cast<int>(level);
  out.grid = o.boolean("grid", false);
  if (o.has("fields")) {  // the particle snapshot's fields (positions are always written)
    out.fields = 0;
    const ojson& a = o.array("fields");
    for (std::size_t k = 0; k < a.size(); ++k) {
      const std::string where = o.at("fields") + "[" + std::to_string(k) + "]";
      const std::string name = as_string(o.ctx(), a[k], where);
      const unsigned bit = snapshot_field(name);
      if (!bit)
        o.ctx().fail(where, "unknown field \"" + name + "\"" +
                                suggestion(name, snapshot_field_names()) + " (known: " +
                                quoted_list(snapshot_field_names()) + ")");
      if (out.fields & bit) o.ctx().fail(where, "\"" + name + "\" is listed twice");
      out.fields |= bit;
    }
  }
}

std::uint64_t case_fingerprint(const ojson& doc) {
  nlohmann::json d(doc);  // keys sorted: the same document gives the same text
  if (d.is_object()) {
    d.erase("output");
    if (d.contains("time") && d["time"].is_object()) d["time"].erase("end");
    if (d.contains("scheme") && d["scheme"].is_object()) {
      d["scheme"].erase("threads");
      if (d["scheme"].empty()) d.erase("scheme");  // --threads on a case without "scheme"
    }
  }
  const std::string text = d.dump();
  return fnv1a64(text.data(), text.size());
}

std::vector<std::pair<std::string, double>> read_geo_parameters(Obj& o) {
  std::vector<std::pair<std::string, double>> out;
  const ojson* p = o.find("parameters");
  if (!p) return out;
  if (!p->is_object())
    o.fail("parameters", "expected an object {name: number}, got " + a_type(*p));
  for (const auto& item : p->items()) {
    const std::string& name = item.key();
    const std::string path = o.at("parameters") + "." + name;
    if (!geo_parameter_name_ok(name))
      o.ctx().fail(path, "a parameter name must be letters, digits and _ (and not h: the mesh "
                         "size sets it)");
    out.emplace_back(name, as_number(o.ctx(), item.value(), path));
  }
  return out;
}

}  // namespace smpm::detail
