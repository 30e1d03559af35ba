#include "driver_common.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <fstream>
#include <iomanip>
#include <stdexcept>

namespace smpm::detail {

namespace fs = std::filesystem;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

fs::path prepare_output_dir(const std::string& out_dir, bool resuming) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create output directory: " + ec.message());
  const fs::path dir(out_dir);
  // A run owns these names: remove what an earlier run left, so that no stale file sits beside
  // the new ones (a rerun with fewer or no snapshots). summary.json first: its presence marks a
  // complete run. Nothing else in the folder is touched.
  std::vector<const char*> owned = {"summary.json", "RUN_INCOMPLETE", "history.csv", "probes.csv",
                                    "failed.smpm"};
  // A restart keeps the snapshots (trimmed to the checkpoint later) and the checkpoint it read
  // until it writes its own.
  if (!resuming)
    owned.insert(owned.end(), {"particles.h5", "particles.xdmf", "grid.h5", "grid.xdmf",
                               "checkpoint.smpm"});
  for (const char* f : owned) {
    fs::remove(dir / f, ec);
    if (ec) throw std::runtime_error((dir / f).string() + ": cannot remove the earlier run's file: " +
                                     ec.message());
  }
  if (!resuming) remove_fem_snapshots(out_dir, 0);
  return dir;
}

void remove_fem_snapshots(const std::string& out_dir, int keep) {
  const fs::path dir(out_dir);
  std::error_code ec;
  fs::remove(dir / "fem.xdmf", ec);
  // A restart keeps fem.h5 (the FE solver reopens it and trims it to its checkpoint).
  if (keep == 0) fs::remove(dir / "fem.h5", ec);
  // Files of the earlier one-file-per-snapshot layout, fem_NNNNN.h5: five digits or more.
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.size() < 12 || n.size() > 16 || n.compare(0, 4, "fem_") != 0 ||
        n.compare(n.size() - 3, 3, ".h5") != 0)
      continue;
    const std::string digits = n.substr(4, n.size() - 7);
    if (std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
        std::stol(digits) >= keep)
      fs::remove(e.path(), ec);
  }
}

SnapshotList SnapshotList::read(const StateReader& r) {
  SnapshotList l;
  std::vector<std::int64_t> steps;
  std::vector<std::uint64_t> sizes;
  r.get("snapshots.steps", steps);
  r.get("snapshots.times", l.times, steps.size());
  r.get("snapshots.sizes", sizes, steps.size());
  l.steps.assign(steps.begin(), steps.end());
  l.sizes.assign(sizes.begin(), sizes.end());
  return l;
}

void SnapshotList::open(SnapshotWriter& w, const std::string& out_dir) const {
  if (steps.empty()) {
    w.open(out_dir, "particles");
    return;
  }
  if (w.resume(out_dir, "particles", steps, times, sizes) == 0 && w.rank() == 0)
    std::fprintf(stderr, "note: %s/particles.h5 does not hold the %zu snapshot(s) written before "
                         "the checkpoint; particles.xdmf lists the snapshots from the restart on\n",
                 out_dir.c_str(), steps.size());
}

void GridSnapshots::open(const Solver& s, const std::string& out_dir, int compression,
                         const std::vector<double>& earlier) {
  const Grid& g = s.grid;
  open(g.x0, g.y0, g.h, g.nx, g.ny, out_dir, compression, earlier);
}

void GridSnapshots::open(double x0, double y0, double h, int nx, int ny,
                         const std::string& out_dir, int compression,
                         const std::vector<double>& earlier, const void* comm, const void* info,
                         int rank, std::array<int, 4> own) {
  const int nnx = nx + 1, nny = ny + 1;
  // The nodes and cells this process writes: all of them, or a rank's own block.
  const std::array<int, 4> nodes = comm ? own : std::array<int, 4>{0, nx, 0, ny};
  const std::array<int, 4> cbox = {nodes[0], std::min(nodes[1], nx - 1), nodes[2],
                                   std::min(nodes[3], ny - 1)};
  auto block = [](const std::array<int, 4>& b, int width) {
    return RowBlock{static_cast<std::size_t>(b[2]) * width + b[0],
                    static_cast<std::size_t>(std::max(0, b[1] - b[0] + 1)),
                    static_cast<std::size_t>(std::max(0, b[3] - b[2] + 1)),
                    static_cast<std::size_t>(width)};
  };
  w_.set_compression(compression);
  w_.set_ranks(comm, info, rank, static_cast<std::size_t>(nnx) * nny,
               static_cast<std::size_t>(nx) * ny, block(nodes, nnx), block(cbox, nx));
  if (!earlier.empty() && w_.resume(out_dir, "grid", earlier) == static_cast<int>(earlier.size()))
    return;
  if (!earlier.empty() && rank == 0)
    std::fprintf(stderr, "note: %s/grid.h5 does not hold the %zu snapshot(s) written before the "
                         "checkpoint; grid.xdmf lists the snapshots from the restart on\n",
                 out_dir.c_str(), earlier.size());
  std::vector<double> xyz;
  for (int j = nodes[2]; j <= nodes[3]; ++j)
    for (int i = nodes[0]; i <= nodes[1]; ++i) xyz.insert(xyz.end(), {x0 + i * h, y0 + j * h, 0.0});
  std::vector<std::int64_t> cells;
  for (int j = cbox[2]; j <= cbox[3]; ++j)
    for (int i = cbox[0]; i <= cbox[1]; ++i) {
      const std::int64_t n0 = static_cast<std::int64_t>(j) * nnx + i;
      cells.insert(cells.end(), {n0, n0 + 1, n0 + 1 + nnx, n0 + nnx});  // counter-clockwise
    }
  w_.open(out_dir, "grid", xyz, cells, std::vector<std::int32_t>(cells.size() / 4, 0));
}

void GridSnapshots::write(const Solver& s) { write(s.t, s.nodal_projection()); }

void GridSnapshots::write(double t, const Solver::NodalProjection& P) {
  const std::size_t n = P.mass.size();
  std::vector<double> v(3 * n, 0.0), sig(9 * n, 0.0), j2(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[3 * i] = P.vx[i];
    v[3 * i + 1] = P.vy[i];
    double* t = &sig[9 * i];
    t[0] = P.sxx[i]; t[1] = t[3] = P.sxy[i]; t[4] = P.syy[i]; t[8] = P.szz[i];
    j2[i] = j2_of(P.sxx[i], P.syy[i], P.szz[i], P.sxy[i]);
  }
  w_.write(t, {{"mass", 1, "kg/m", P.mass.data()},
                 {"velocity", 3, "m/s", v.data()},
                 {"stress", 9, "Pa", sig.data()},
                 {"J2", 1, "Pa^2", j2.data()}});
}

void MpmSnapshots::open(const Solver& s, const OutputSpec& out, const std::string& out_dir) {
  snap_.set_fields(out.fields);
  snap_.set_compression(out.compression);
  earlier_.open(snap_, out_dir);
  grid_on_ = out.grid;
  if (grid_on_) grid_.open(s, out_dir, out.compression, earlier_.times);
}

void MpmSnapshots::write(const Solver& s) {
  const auto layer = s.layer_flags();
  snap_.write(s.p, s.steps, s.t, &layer);
  if (grid_on_) grid_.write(s);
}

void MpmSnapshots::open(const OutputSpec& out, const std::string& out_dir, double x0, double y0,
                        double h, int nx, int ny, const void* comm, const void* info,
                        int rank, std::array<int, 4> own) {
  snap_.set_ranks(comm, info, rank);
  snap_.set_fields(out.fields);
  snap_.set_compression(out.compression);
  earlier_.open(snap_, out_dir);
  grid_on_ = out.grid;
  if (grid_on_)
    grid_.open(x0, y0, h, nx, ny, out_dir, out.compression, earlier_.times, comm, info, rank, own);
}

void MpmSnapshots::write(const Particles& p, long step, double time,
                         const std::vector<std::uint8_t>& layer, std::size_t offset,
                         std::size_t total, const Solver::NodalProjection* P) {
  snap_.write(p, step, time, &layer, offset, total);
  if (grid_on_) grid_.write(time, *P);
}

void MpmSnapshots::close() {
  snap_.close();
  grid_.close();
}

void save_snapshot_list(StateWriter& w, const SnapshotWriter& snap) {
  w.put("snapshots.steps", std::vector<std::int64_t>(snap.steps().begin(), snap.steps().end()));
  w.put("snapshots.times", snap.times());
  w.put("snapshots.sizes", std::vector<std::uint64_t>(snap.sizes().begin(), snap.sizes().end()));
}

std::vector<std::string> history_columns(const std::vector<ProbeSpec>& probes) {
  std::vector<std::string> cols;
  for (const auto& pr : probes)
    for (const auto& f : pr.fields) cols.push_back(pr.name + "." + f);
  for (const char* e : {"kinetic", "elastic", "dissipated", "absorbed", "external_work", "imbalance"})
    cols.push_back(std::string("energy.") + e);
  return cols;
}

void put_energies(const Energies& e, std::vector<double>& row, std::size_t& k) {
  for (double v : {e.kinetic, e.elastic, e.dissipated, e.absorbed, e.external_work, e.imbalance()})
    row[k++] = v;
}

double probe_field(const ProbeSample& s, const std::string& f) {
  if (f == "sxx") return s.sxx;
  if (f == "syy") return s.syy;
  if (f == "szz") return s.szz;
  if (f == "sxy") return s.sxy;
  if (f == "J2") return s.j2;
  if (f == "vx") return s.vx;
  if (f == "vy") return s.vy;
  if (f == "px") return s.px;
  if (f == "py") return s.py;
  if (f == "mass") return s.mass;
  if (f == "fcx") return s.fcx;
  if (f == "fcy") return s.fcy;
  throw std::runtime_error("unknown probe field " + f);
}

Progress::Progress(bool on, long total, Clock::time_point t0, long first)
    : on_(on), total_(total), first_(first), tty_(isatty(2)), t0_(t0) {}

void Progress::update(long step, double step_seconds) {
  if (!on_) return;
  const double el = seconds_since(t0_);
  const bool last = step >= total_;
  const double every = tty_ ? 0.5 : 5.0;
  if (el - last_ < every && !last) return;
  if (el < 2.0 && !last) return;  // short runs stay quiet
  last_ = el;
  const double done = static_cast<double>(step - first_);
  const double rate = done / std::max(step_seconds, 1e-9);
  const double left = (total_ - step) * el / std::max(done, 1.0);
  std::fprintf(stderr, "%s  %5.1f%%  step %ld/%ld  %.0f steps/s  %.1f s left%s",
               tty_ ? "\r" : "", 100.0 * step / total_, step, total_, rate, left,
               tty_ ? "   " : "\n");
  if (last && tty_) std::fprintf(stderr, "\n");
}

nlohmann::ordered_json summary_head(const Case& c, const RunResult& r, double dt, double t_end,
                                    double cfl, double step_seconds) {
  nlohmann::ordered_json j;
  j["title"] = c.title;
  j["case"] = c.source;
  j["steps"] = r.steps;
  j["dt"] = dt;
  j["t_end"] = t_end;
  j["cfl"] = cfl;
  j["wall_seconds"] = r.wall_seconds;
  j["step_seconds"] = step_seconds;
  return j;
}

nlohmann::ordered_json energy_json(const Energies& e) {
  const double scale = std::abs(e.initial) + std::abs(e.external_work);
  nlohmann::ordered_json j{{"kinetic", e.kinetic},
                           {"elastic", e.elastic},
                           {"dissipated", e.dissipated},
                           {"absorbed", e.absorbed},
                           {"external_work", e.external_work},
                           {"initial", e.initial},
                           {"imbalance", e.imbalance()}};
  // Relative to the energy put in (initial + external work); null when nothing was put in (an
  // unloaded region of a hybrid, whose energy all crossed the interface).
  if (scale > 0) j["relative_imbalance"] = e.imbalance() / scale;
  else j["relative_imbalance"] = nullptr;
  return j;
}

nlohmann::ordered_json silents_json(const Solver& s) {
  nlohmann::ordered_json sil = nlohmann::ordered_json::array();
  for (const auto& sl : s.silents)
    sil.push_back({{"name", sl.layer.name},
                   {"particles", sl.layer.idx.size()},
                   {"form", sl.form == SilentForm::Nodal ? "nodal" : "particle"},
                   {"a", sl.a},
                   {"b", sl.b},
                   {"layer_width", sl.layer.width}});
  return sil;
}

void put_mpm_scheme(nlohmann::ordered_json& j, const Solver& s) {
  j["scheme"] = scheme_name(s.opt.scheme);
  j["shape"] = shape_name(s.opt.shape);
  j["flip"] = s.opt.flip;
  j["mass_correction"] = s.opt.mass_correction;
  if (s.opt.mass_correction > 0)
    j["mass_correction_form"] = s.opt.mass_correction_symmetric ? "symmetric" : "increment";
  if (s.opt.light_node_ratio > 0)  // the light nodes' extension, and how many the last step had
    j["light_nodes"] = {{"ratio", s.opt.light_node_ratio},
                        {"extended", s.light_nodes.count()}};
  j["grid"] = {{"origin", {s.grid.x0, s.grid.y0}}, {"cells", {s.grid.nx, s.grid.ny}}, {"cell", s.grid.h}};
}

void put_mpm_blocks(nlohmann::ordered_json& j, const Case& c, const Solver& s, const MpmRanks& ranks) {
  j["silent_boundaries"] = silents_json(s);
  j["loads"] = c.notes;
  j["bodies"] = bodies_json(c, s);
  ranks.total_counts(j);
  j["curve_probes"] = curve_probes_json(c.probes);
  if (const auto& d = s.dashpot_solve; d.steps > 0)  // the silent layers' consistent mean
    j["dashpot_solve"] = {{"steps", d.steps},
                          {"iterations_per_step", static_cast<double>(d.iterations) / d.steps},
                          {"max_iterations", d.max_iterations},
                          {"unconverged_steps", d.unconverged},
                          {"zone_rescans", d.rescans}};
}

void write_probe_table(const fs::path& dir, const std::vector<ProbeSpec>& probes) {
  std::ofstream f(dir / "probes.csv");
  if (!f) throw std::runtime_error((dir / "probes.csv").string() + ": cannot write");
  f << "name,x,y,along,s\n" << std::setprecision(17);
  for (const auto& p : probes) {
    f << p.name << ',' << p.x << ',' << p.y << ',' << p.along << ',';
    if (!p.along.empty()) f << p.s;
    f << '\n';
  }
}

nlohmann::ordered_json curve_probes_json(const std::vector<ProbeSpec>& probes) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < probes.size(); ++k) {
    if (probes[k].along.empty() || (k > 0 && probes[k - 1].along == probes[k].along)) continue;
    std::size_t e = k;
    while (e + 1 < probes.size() && probes[e + 1].along == probes[k].along) ++e;
    a.push_back({{"name", probes[k].along},
                 {"curve", probes[k].curve},
                 {"points", e - k + 1},
                 {"first", probes[k].name},
                 {"last", probes[e].name},
                 {"spacing", probes[k + 1].s - probes[k].s},
                 {"last_arc_length", probes[e].s}});
  }
  return a;
}

nlohmann::ordered_json bodies_json(const Case& c, const Solver& s) {
  std::vector<std::size_t> count(c.bodies.size(), 0);
  for (std::size_t k = 0; k < s.p.size(); ++k)
    if (s.p.body[k] < count.size()) ++count[s.p.body[k]];
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (std::size_t b = 0; b < c.bodies.size(); ++b) {
    const BodyInfo& i = c.bodies[b];
    a.push_back({{"name", i.name},
                 {"material", i.material},
                 {"surface", i.surface},
                 {"extent", {i.x0, i.y0, i.x1, i.y1}},
                 {"particles", count[b]}});
  }
  return a;
}

// Whole or not at all: into a temporary file, every write, the flush, fsync and close checked,
// then renamed. A failure (disk full, an I/O error) removes the temporary file and is an error
// naming the file and the cause.
void write_file_atomically(const fs::path& dst, const std::string& s) {
  const fs::path tmp = dst.string() + ".tmp";
  auto fail = [&](const std::string& what, int err) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error(dst.string() + ": " + what + ": " + std::strerror(err));
  };
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f) fail("cannot create " + tmp.filename().string(), errno);
  const bool wrote = std::fwrite(s.data(), 1, s.size(), f) == s.size() && std::fflush(f) == 0;
  const int werr = errno;
  const bool synced = wrote && ::fsync(::fileno(f)) == 0;
  const int serr = errno;
  const bool closed = std::fclose(f) == 0;
  if (!wrote) fail("cannot write", werr);
  if (!synced && serr != EINVAL && serr != EROFS) fail("cannot sync", serr);  // EINVAL: no fsync here
  if (!closed) fail("cannot close", errno);
  std::error_code ec;
  fs::rename(tmp, dst, ec);
  if (ec) fail("cannot rename " + tmp.filename().string() + " to it", ec.value());
}

// summary.json marks a complete run, so it is written last and whole or not at all.
void write_summary(const fs::path& dir, const nlohmann::ordered_json& j) {
  std::ostringstream text;
  text << std::setw(2) << j << "\n";
  write_file_atomically(dir / "summary.json", text.str());
}

}  // namespace smpm::detail
