#pragma once
// Output files of a run:
//   DIR/history.csv    first column `time`, then `<probe>.<field>` and `energy.<term>` columns
//   DIR/summary.json   steps, dt, t_end, wall_seconds, particles, particle_updates_per_second,
//                      energy {kinetic, elastic, dissipated, absorbed, external_work, ...}
//   DIR/particles.h5 + DIR/particles.xdmf   particle snapshots that open in ParaView
#include <cstdint>
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

// The fields a particle snapshot can hold (SnapshotWriter::set_fields; the layout is in
// output.cpp). kFieldFilm: the film model's plane normal and jump, written only when a material
// of the run has that model.
enum SnapshotField : unsigned {
  kFieldVelocity = 1u << 0, kFieldDisplacement = 1u << 1, kFieldStress = 1u << 2,
  kFieldJ2 = 1u << 3, kFieldEpsP = 1u << 4, kFieldMass = 1u << 5, kFieldVolume = 1u << 6,
  kFieldBody = 1u << 7, kFieldId = 1u << 8, kFieldState = 1u << 9, kFieldLayer = 1u << 10,
  kFieldFilm = 1u << 11,
  kFieldsAll = (1u << 12) - 1,
};
// The field of a name ("velocity", "displacement", "stress", "J2", "eps_p", "mass", "volume",
// "body", "id", "state", "layer", "film"); 0 for an unknown name.
unsigned snapshot_field(const std::string& name);
const std::vector<std::string>& snapshot_field_names();
// Bits of the per-particle "layer" field: the boundary conditions a particle carries.
enum SnapshotLayer : std::uint8_t {
  kLayerSilent = 1, kLayerTraction = 2, kLayerSpring = 4, kLayerDamping = 8, kLayerPml = 16,
};

// Particle snapshots: one HDF5 file with a group per snapshot ("/step_000123") holding the
// positions and the chosen fields, and an XDMF 3 sidecar (a temporal collection of Polyvertex
// grids) that grows by one grid per snapshot, so a partial run still opens.
class SnapshotWriter {
 public:
  SnapshotWriter() = default;
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;
  // Creates DIR/<base>.h5 (truncating) and remembers DIR/<base>.xdmf. Throws std::runtime_error.
  void open(const std::string& dir, const std::string& base = "particles");
  // The fields to write (SnapshotField bits); before open() or resume().
  void set_fields(unsigned fields) { fields_ = fields; }
  // Deflate level of the datasets written from now on: 0 (default) stores them as they are,
  // 1-9 in byte-shuffled, deflated chunks (OutputSpec::compression).
  void set_compression(int level) { compression_ = level; }
  // Several processes writing one file together (HDF5 over MPI-IO): comm points to the MPI
  // communicator (an MPI_Comm) of the ranks that open, write, resume and close together, info
  // to the MPI_Info for opening it (MPI_INFO_NULL); rank 0 alone writes the XDMF. Before open()
  // or resume(); null: one process (the default). Throws std::runtime_error when this HDF5 was
  // built without MPI.
  void set_ranks(const void* comm, const void* info, int rank);
  // layer: per particle (in p's order) its SnapshotLayer bits, or null (all 0).
  void write(const Particles& p, long step, double time,
             const std::vector<std::uint8_t>* layer = nullptr);
  // Several processes (set_ranks): every rank calls it at once with its particles, which fill
  // rows [offset, offset + p.size()) of the snapshot's `total` rows (the ranks' rows must not
  // overlap and must cover them all).
  void write(const Particles& p, long step, double time, const std::vector<std::uint8_t>* layer,
             std::size_t offset, std::size_t total);
  void close();
  int count() const { return static_cast<int>(times_.size()); }
  int rank() const { return rank_; }  // set_ranks' (0 on one process)
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
  const void* comm_ = nullptr;  // set_ranks
  const void* info_ = nullptr;
  int rank_ = 0;
  std::string dir_, base_;
  std::vector<double> times_;
  std::vector<long> steps_;
  std::vector<std::size_t> sizes_;
  long long xdmf_end_ = -1;  // offset of the XDMF tail on disk (-1: write the file whole next)
  unsigned fields_ = kFieldsAll;
  int compression_ = 0;
  bool film_ = false;        // the file carries the film block (fixed by the first snapshot)
  std::string xdmf_head() const;
  std::string xdmf_grid(std::size_t k) const;
  void write_xdmf();
  void append_xdmf();

 public:
  // The XDMF document as it stands (the file on disk holds exactly this after each snapshot).
  std::string xdmf_text() const;
};

// The rows of a dataset that one of several processes writes: `count` runs of `length` rows,
// the first from row `first`, each `stride` rows after the one before (a block of nodes or cells
// of a row-major grid: its rows' runs).
struct RowBlock {
  std::size_t first = 0, length = 0, count = 1, stride = 0;
  std::size_t rows() const { return length * count; }
};

// Snapshots of a fixed mesh of quadrilaterals (the FE far field): DIR/<base>.h5 holds the mesh
// once (/mesh/xyz N x 3, /mesh/cells M x 4 int64 counter-clockwise, /mesh/material M int32) and a
// group /snapshot_NNNNN per snapshot (attribute "time") with node fields of N rows; DIR/<base>.xdmf
// is an XDMF 3 temporal collection that grows by one grid per snapshot (as SnapshotWriter's).
// Every dataset has an HDF5 attribute "units".
class MeshSnapshotWriter {
 public:
  struct Field {
    const char* name;
    int components;  // 1 scalar, 3 vector, 9 tensor (row by row)
    const char* units;
    const double* data;  // N x components
  };
  MeshSnapshotWriter() = default;
  ~MeshSnapshotWriter();
  MeshSnapshotWriter(const MeshSnapshotWriter&) = delete;
  MeshSnapshotWriter& operator=(const MeshSnapshotWriter&) = delete;
  // Creates DIR/<base>.h5 (truncating) with the mesh. Throws std::runtime_error.
  void open(const std::string& dir, const std::string& base, const std::vector<double>& xyz,
            const std::vector<std::int64_t>& cells, const std::vector<std::int32_t>& material);
  // Restart: reopens an earlier run's file, keeps its first `times.size()` snapshots and removes
  // later ones; returns how many were kept: all, or 0 when the file or one of them is missing
  // (then nothing is open: call open()). The fields of every snapshot are those of the first.
  int resume(const std::string& dir, const std::string& base, const std::vector<double>& times);
  bool is_open() const { return file_ >= 0; }
  void set_compression(int level) { compression_ = level; }  // as SnapshotWriter's
  int compression() const { return compression_; }
  // Several processes writing one file together (as SnapshotWriter::set_ranks): the mesh has
  // `nodes` nodes and `cells` cells in all, of which this rank writes the rows `own_nodes` and
  // `own_cells`; open()'s arrays and write()'s fields then hold those rows only, in order.
  // Before open() or resume().
  void set_ranks(const void* comm, const void* info, int rank, std::size_t nodes,
                 std::size_t cells, const RowBlock& own_nodes, const RowBlock& own_cells);
  void write(double time, const std::vector<Field>& fields);
  void close();
  int count() const { return static_cast<int>(times_.size()); }

 private:
  long long file_ = -1;  // hid_t
  const void* comm_ = nullptr;  // set_ranks
  const void* info_ = nullptr;
  int rank_ = 0;
  RowBlock own_nodes_, own_cells_;
  std::string dir_, base_;
  std::size_t nodes_ = 0, cells_ = 0;
  std::vector<double> times_;
  std::vector<std::string> names_, units_;  // the fields, as the first snapshot wrote them
  std::vector<int> components_;
  int compression_ = 0;
  long long xdmf_end_ = -1;
  std::string xdmf_grid(std::size_t k) const;
  std::string xdmf_text() const;
};

}  // namespace smpm
