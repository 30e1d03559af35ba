#pragma once
// Output files of a run:
//   DIR/history.csv    first column `time`, then `<probe>.<field>` and `energy.<term>` columns
//   DIR/summary.json   steps, dt, t_end, wall_seconds, particles, particle_updates_per_second,
//                      energy {kinetic, elastic, dissipated, absorbed, external_work, ...}
//   DIR/particles.h5 + DIR/particles.xdmf   particle snapshots that open in ParaView
#include <cstdio>
#include <string>
#include <vector>

#include "silentmpm/particles.hpp"

namespace smpm {

class HistoryWriter {
 public:
  HistoryWriter() = default;
  ~HistoryWriter();
  HistoryWriter(const HistoryWriter&) = delete;
  HistoryWriter& operator=(const HistoryWriter&) = delete;
  // Opens path and writes the header line: "time," + columns joined by ','. Throws on failure.
  void open(const std::string& path, const std::vector<std::string>& columns);
  // A restart: writes `text` (the header and rows of the run before the checkpoint; its first
  // line must be this header) and continues after it. Throws on failure or another header.
  void resume(const std::string& path, const std::vector<std::string>& columns,
              const std::string& text);
  void row(double time, const std::vector<double>& values);  // %.9e, one line
  // Flushes to the file; throws when a write failed (disk full, I/O error).
  void flush();
  void close();

 private:
  std::FILE* f_ = nullptr;
  std::size_t ncol_ = 0;
  std::string path_;
};

// Particle snapshots: one HDF5 file with a group per snapshot ("/step_000123") holding datasets
// of length N (double unless noted): x, y (as a N x 3 "xyz" dataset for XDMF), vx, vy, sxx, syy,
// szz, sxy, J2, eps_p, mass, volume, body (int32), id (uint32), and the film model's state
// (int32: 0 elastic, 1 plastic, 2 decohesion, 3 separated), normal_x, normal_y, jump_n, jump_t,
// ubar. The XDMF sidecar (temporal collection of
// Polyvertex grids) is rewritten after every snapshot so a partial run still opens.
class SnapshotWriter {
 public:
  SnapshotWriter() = default;
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;
  // Creates DIR/<base>.h5 (truncating) and remembers DIR/<base>.xdmf. Throws std::runtime_error.
  void open(const std::string& dir, const std::string& base = "particles");
  void write(const Particles& p, long step, double time);
  void close();
  int count() const { return static_cast<int>(times_.size()); }
  // Restart: reopens DIR/<base>.h5 of an earlier run that wrote the snapshots listed (their
  // steps, times and particle counts), removes any later snapshot group it holds, and lists them
  // again in the XDMF. Returns how many were kept: all of them, or 0 when the file or one of the
  // listed groups is missing (the file is then started afresh). Throws std::runtime_error.
  int resume(const std::string& dir, const std::string& base, const std::vector<long>& steps,
             const std::vector<double>& times, const std::vector<std::size_t>& sizes);
  const std::vector<long>& steps() const { return steps_; }
  const std::vector<double>& times() const { return times_; }
  const std::vector<std::size_t>& sizes() const { return sizes_; }

 private:
  long long file_ = -1;  // hid_t
  std::string dir_, base_;
  std::vector<double> times_;
  std::vector<long> steps_;
  std::vector<std::size_t> sizes_;
  long long xdmf_end_ = -1;  // offset of the XDMF tail on disk (-1: write the file whole next)
  std::string xdmf_head() const;
  std::string xdmf_grid(std::size_t k) const;
  void write_xdmf();
  void append_xdmf();

 public:
  // The XDMF document as it stands (the file on disk holds exactly this after each snapshot).
  std::string xdmf_text() const;
};

}  // namespace smpm
