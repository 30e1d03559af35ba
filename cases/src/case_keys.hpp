#pragma once
// Internal: the key walker of case files, used by every section (case.cpp: MPM, case_fem.cpp:
// FEM, case_hybrid.cpp: hybrid). Ctx carries the source name and the key paths that command-line
// overrides set; every error goes through Ctx::fail, so that a bad value set by an override says
// so ("(value set by override '...')") in every section. Obj wraps one JSON object at its key
// path: typed getters with defaults, range checks, unknown keys rejected.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace smpm {
struct OutputSpec;
}

namespace smpm::detail {

using ojson = nlohmann::ordered_json;

// Error context: the source name, and which key paths were set by command-line overrides.
struct Ctx {
  std::string source;
  std::vector<std::pair<std::string, std::string>> overridden;  // canonical path, override text

  // Throws CaseError "<source>: <path>: <what>" (no path: "<source>: <what>"), with the override
  // note when path is, or lies under, a path an override set.
  [[noreturn]] void fail(const std::string& path, const std::string& what) const;
};

// Typed reading of one value at a known path.
double as_number(const Ctx& ctx, const ojson& v, const std::string& path);
long as_integer(const Ctx& ctx, const ojson& v, const std::string& path);
std::string as_string(const Ctx& ctx, const ojson& v, const std::string& path);
std::vector<double> as_numbers(const Ctx& ctx, const ojson& v, const std::string& path,
                               std::size_t n);

// The two forms of a few messages. The MPM sections quote the options of a choice and suggest
// a close spelling ("did you mean ..."), for an unknown key too, and check an array element by
// element; the FEM sections (an FEM case, the FEM region of a hybrid and its FEM probes) list
// options plainly, suggest nothing, give one message for a whole array of numbers, and read
// integers without the MPM sections' bound of 1e12 on JSON integers (whole floats below 1e12).
// Both are kept so that every section's messages stay as they are documented and tested.
enum class Dialect { Mpm, Fem };

// One JSON object at a key path. Reads are recorded; done() rejects any key that was not read,
// and allow() rejects keys outside a list up front (before a misspelt key can show up as a
// "missing required key" of its correct spelling).
class Obj {
 public:
  Obj(const Ctx& ctx, const ojson& j, std::string path, Dialect dialect = Dialect::Mpm);

  const std::string& path() const { return path_; }
  std::string at(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const Ctx& ctx() const { return *ctx_; }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    ctx_->fail(key.empty() ? path_ : at(key), what);
  }
  bool has(const std::string& key) const { return j_->contains(key); }

  // Rejects every key not in `keys`. `where` qualifies the message ("for a fixed boundary").
  void allow(const std::vector<std::string>& keys, const std::string& where = "") const;
  // Safety net: every key present must have been read by the parser.
  void done() const;

  const ojson* find(const std::string& key) {
    read_.insert(key);
    auto it = j_->find(key);
    return it == j_->end() ? nullptr : &*it;
  }
  const ojson& need(const std::string& key) {
    const ojson* v = find(key);
    if (!v) fail(key, "missing required key");
    return *v;
  }

  double num(const std::string& key) { return as_number(*ctx_, need(key), at(key)); }
  double num(const std::string& key, double def) {
    const ojson* v = find(key);
    return v ? as_number(*ctx_, *v, at(key)) : def;
  }
  long integer(const std::string& key, long def);
  std::string str(const std::string& key) { return as_string(*ctx_, need(key), at(key)); }
  std::string str(const std::string& key, const std::string& def) {
    const ojson* v = find(key);
    return v ? as_string(*ctx_, *v, at(key)) : def;
  }
  bool boolean(const std::string& key, bool def);
  // A string from a fixed list; required when def is null.
  std::string choice(const std::string& key, const std::vector<std::string>& options,
                     const char* def = nullptr);
  std::vector<double> nums(const std::string& key, std::size_t n);
  std::vector<double> nums(const std::string& key, std::vector<double> def) {
    const ojson* v = find(key);
    return v ? as_numbers(*ctx_, *v, at(key), def.size()) : def;
  }
  // The object at `key` (required), in this object's dialect.
  Obj obj(const std::string& key) { return Obj(*ctx_, need(key), at(key), dialect_); }
  const ojson& array(const std::string& key);

  // Range checks on a value already read from `key`.
  void gt(const std::string& key, double v, double lo) const;
  void ge(const std::string& key, double v, double lo) const;
  void lt(const std::string& key, double v, double hi) const;
  void le(const std::string& key, double v, double hi) const;

 private:
  const Ctx* ctx_;
  const ojson* j_;
  std::string path_;
  Dialect dialect_;
  std::set<std::string> read_;
};

// The "output" section of every kind of case (the keys in docs/case-reference.md "output").
void parse_output_section(Obj& o, OutputSpec& out, long max_snapshots);

// The case's fingerprint for checkpoints: a hash of the whole document as validated (overrides
// applied) except the keys a restart may change (output.*, time.end, scheme.threads).
std::uint64_t case_fingerprint(const ojson& doc);

// The "parameters" object of an Obj that names a gmsh .geo (geometry.parameters,
// fem.parameters): {name: number}, names of letters, digits and _ (not h, which the size sets).
std::vector<std::pair<std::string, double>> read_geo_parameters(Obj& o);

}  // namespace smpm::detail
