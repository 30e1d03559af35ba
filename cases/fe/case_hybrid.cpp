// Hybrid case files: both an MPM region ("grid", "bodies", ...) and an FEM region ("fem"), coupled
// through shared nodes (silentmpm/hybrid.hpp). The two regions are built by the MPM and the FEM
// parsers from the same document (so every key keeps its messages), then coupled; probes are
// read from whichever region holds their point. Keys: docs/case-reference.md, "Hybrid cases".
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>

#include "case_fem.hpp"
#include "case_keys.hpp"
#include "case_util.hpp"

namespace smpm::detail {
namespace {

std::string probe_path(std::size_t i) { return "probes[" + std::to_string(i) + "]"; }

// The error context of the MPM region's document, whose probes are the document's MPM probes
// renumbered (doc_index[k]: the document index of MPM probe k): an override of a probe names it
// by its index in the MPM document, one of an FEM probe is dropped.
Ctx mpm_context(const Ctx& ctx, const std::vector<std::size_t>& doc_index) {
  Ctx m{ctx.source, {}};
  for (const auto& [path, text] : ctx.overridden) {
    if (path.rfind("probes[", 0) != 0) {
      m.overridden.emplace_back(path, text);
      continue;
    }
    const std::size_t close = path.find(']');
    const std::size_t i = std::stoul(path.substr(7, close - 7));
    const auto k = std::find(doc_index.begin(), doc_index.end(), i);
    if (k != doc_index.end())
      m.overridden.emplace_back(probe_path(k - doc_index.begin()) + path.substr(close + 1), text);
  }
  return m;
}

}  // namespace

Case build_hybrid_case(const Ctx& ctx, const ojson& doc) {
  static const std::vector<std::string> allowed = {"title",  "grid",       "time",   "scheme",
                                                   "materials", "bodies",  "boundaries", "probes",
                                                   "geometry", "output",   "contact", "fem",
                                                   "gravity"};
  const Obj top(ctx, doc, "", Dialect::Fem);
  top.allow(allowed, "in a hybrid (MPM + FEM) case");
  for (const char* k : {"grid", "bodies", "time", "materials", "fem"})
    if (!top.has(k))
      top.fail(k, "missing required key (a case with both \"bodies\" and \"fem\" is an MPM-FEM "
                  "hybrid and needs grid, bodies, time, materials and fem)");

  // The MPM region's keys but its probes first, before either region is meshed (which probes
  // are the MPM region's depends on the FE mesh).
  {
    ojson dk = doc;
    dk.erase("fem");
    dk.erase("probes");
    check_mpm_case(mpm_context(ctx, {}), dk);
  }

  // FEM region: the FEM parser on the FEM keys (no probes yet).
  ojson dfe = ojson::object();
  for (const char* k : {"title", "time", "materials", "fem", "output", "gravity"})
    if (doc.contains(k)) dfe[k] = doc[k];
  // The particle snapshot's fields and the MPM grid's snapshots are the MPM region's keys (its
  // parser below reads them).
  if (dfe.contains("output") && dfe["output"].is_object())
    for (const char* k : {"fields", "grid"}) dfe["output"].erase(k);
  // The FEM region gets the materials its regions name (the particles' may be plastic).
  if (doc["fem"].is_object() && doc["fem"].contains("regions") && doc["fem"]["regions"].is_object() &&
      doc["materials"].is_object()) {
    ojson used = ojson::object();
    for (const auto& it : doc["fem"]["regions"].items())
      if (it.value().is_string() && doc["materials"].contains(it.value().get<std::string>()))
        used[it.value().get<std::string>()] = doc["materials"][it.value().get<std::string>()];
    if (!used.empty()) dfe["materials"] = used;
  }
  if (doc.contains("scheme") && doc["scheme"].is_object() && doc["scheme"].contains("threads"))
    dfe["scheme"] = ojson{{"threads", doc["scheme"]["threads"]}};
  Case cf = build_fem_case(ctx, dfe);
  fem::Solver& fe = *cf.fem;

  // Probes: a point inside the FEM mesh is an FEM probe, any other one is read from particles.
  std::vector<int> fem_probe;  // per probe in the document: FEM probe index or -1
  const ojson* probes = doc.contains("probes") ? &doc["probes"] : nullptr;
  if (probes && !probes->is_array()) ctx.fail("probes", "expected an array");
  ojson mpm_probes = ojson::array();
  std::vector<std::size_t> mpm_origin;  // document index of each MPM probe
  if (probes)
    for (std::size_t i = 0; i < probes->size(); ++i) {
      const ojson& p = (*probes)[i];
      if (!p.is_object()) ctx.fail(probe_path(i), "expected an object");
      // A probe along a curve is read from the particles: its curve is a physical curve of the
      // MPM region's geometry, and every point must lie in one of its bodies (the MPM parser
      // checks both), hence outside the FE cells.
      const ojson* at = p.contains("at") && !p.contains("curve") ? &p["at"] : nullptr;
      int idx = -1;
      if (at && at->is_array() && at->size() == 2 && (*at)[0].is_number() && (*at)[1].is_number())
        idx = fe.add_probe((*at)[0].get<double>(), (*at)[1].get<double>());
      fem_probe.push_back(idx);
      if (idx < 0) {
        mpm_probes.push_back(p);
        mpm_origin.push_back(i);
      }
    }

  // MPM region: the MPM parser on everything but "fem", with the probes that lie outside the mesh.
  ojson dm = doc;
  dm.erase("fem");
  dm.erase("probes");
  if (!mpm_probes.empty()) dm["probes"] = mpm_probes;
  Case c;
  try {
    c = build_mpm_case(mpm_context(ctx, mpm_origin), dm);
  } catch (const CaseError& e) {
    // Report MPM probe errors at their index in the document.
    std::string msg = e.what();
    for (std::size_t k = mpm_origin.size(); k-- > 0;) {
      const std::string from = ctx.source + ": " + probe_path(k);
      if (msg.rfind(from, 0) == 0) {
        msg = ctx.source + ": " + probe_path(mpm_origin[k]) + msg.substr(from.size());
        break;
      }
    }
    throw CaseError(msg);
  }

  // FEM probes: the same checks as the FEM parser's.
  std::vector<ProbeSpec> all;
  std::vector<std::size_t> origin;  // document index of each entry of all
  std::size_t next_mpm = 0;
  if (probes)
    for (std::size_t i = 0; i < probes->size(); ++i) {
      if (fem_probe[i] < 0) {
        // One entry for a point probe; the points of a probe along a curve (named after it in
        // `along`, consecutive).
        all.push_back(c.probes.at(next_mpm++));
        origin.push_back(i);
        const std::string along = all.back().along;
        while (!along.empty() && next_mpm < c.probes.size() && c.probes[next_mpm].along == along) {
          all.push_back(c.probes[next_mpm++]);
          origin.push_back(i);
        }
        continue;
      }
      const ojson& p = (*probes)[i];
      Obj o(ctx, p, probe_path(i), Dialect::Fem);
      for (const auto& it : p.items())
        if (it.key() != "name" && it.key() != "at" && it.key() != "fields")
          o.fail(it.key(), it.key() == "body"
                               ? "the point lies in the FEM region, which has no bodies"
                               : "unknown key; allowed: name, at, fields");
      ProbeSpec pr;
      if (!p.contains("name") || !p["name"].is_string())
        o.fail("name", "missing required key (a string)");
      pr.name = p["name"].get<std::string>();
      static const std::regex ok("[A-Za-z0-9_]+");
      if (!std::regex_match(pr.name, ok))
        o.fail("name", "must be letters, digits and _ only, got \"" + pr.name + "\"");
      pr.x = p["at"][0].get<double>();
      pr.y = p["at"][1].get<double>();
      pr.fem_index = fem_probe[i];
      pr.fields = fem_probe_fields(o, {"sxx", "syy", "szz", "sxy", "J2", "vx", "vy"});
      all.push_back(std::move(pr));
      origin.push_back(i);
    }
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (all[i].name == all[j].name)
        ctx.fail(probe_path(origin[i]) + ".name",
                 "probe name \"" + all[i].name + "\" is used twice");
  c.probes = std::move(all);

  // Couple.
  c.fem = std::move(cf.fem);
  try {
    c.hybrid = std::make_unique<Hybrid>(*c.solver, *c.fem);
  } catch (const HybridError& e) {
    if (!e.key.empty()) ctx.fail(e.key, e.detail);
    ctx.fail("fem", e.what());
  }
  // Time step: time.dt, or time.cfl times the smaller of both regions' limits.
  const ojson& t = doc["time"];
  const double crit = c.hybrid->critical_dt();
  double dt = 0;
  if (t.contains("cfl")) {
    dt = t["cfl"].get<double>() * crit;
  } else {
    dt = t["dt"].get<double>();
    if (dt > crit * (1 + 1e-12))
      ctx.fail("time.dt",
               fmt(dt) + " s is above the stability limit of the hybrid, " + fmt_down(crit) +
                   " s (the smaller of the MPM limit h / c_d = " +
                   fmt_down(c.solver->critical_dt()) + " s and the FEM element bound " +
                   fmt_down(c.fem->critical_dt()) + " s)");
  }
  if (const std::string e = step_count_error(c.t_end, dt); !e.empty()) ctx.fail("time", e);
  try {
    c.hybrid->set_dt(dt);
  } catch (const HybridError& e) {
    ctx.fail("time", e.what());
  }
  for (const auto& n : cf.notes) c.notes.push_back("FEM: " + n);
  char line[256];
  std::snprintf(line, sizeof line,
                "hybrid: %zu nodes shared with the FEM mesh, %zu of them on the interface with the "
                "particles; dt %g s (%.3f of the hybrid limit)",
                c.hybrid->shared().size(), c.hybrid->interface_nodes(), dt, dt / crit);
  c.notes.push_back(line);
  return c;
}

}  // namespace smpm::detail
