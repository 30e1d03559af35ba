// History CSV and HDF5/XDMF particle snapshots (the contract in output.hpp).
//
// Snapshot layout, one file DIR/<base>.h5:
//   /step_000000123            group, attributes "time" (double) and "step" (int64)
//     xyz                      N x 3 double (z = 0), the XDMF geometry
//     then the fields chosen (SnapshotFields), each with an HDF5 attribute "units":
//     velocity, displacement   N x 3 double (z component 0), m/s and m
//     stress                   N x 9 double, the Cauchy stress as a full 3 x 3 tensor, row by row
//                              (xx xy 0, xy yy 0, 0 0 zz), Pa
//     J2                       N double, second invariant of the deviatoric stress, Pa^2
//     eps_p mass volume        N double (1, kg/m and m^2 per unit thickness)
//     body state layer         N int32 (state, film model: 0 elastic, 1 plastic, 2 decohesion,
//                              3 separated; layer: SnapshotLayer bits)
//     id                       N uint32 (permanent particle id; particles are re-sorted)
//     normal (N x 3), jump_n, jump_t, ubar   the film model's critical plane and jump (only when
//                              a material of the run has the film model)
//   /vertices_N                N int64 0 .. N-1: the Polyvertex connectivity of N particles
// DIR/<base>.xdmf is an XDMF 3 temporal collection of Polyvertex grids that point into the .h5
// by relative file name, so the output folder can be moved as a whole; its Domain carries an
// Information element "units". It grows by one grid per snapshot (SnapshotWriter::append_xdmf).
#include "silentmpm/output.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <iterator>
#include <string>
#include <vector>

#include "silentmpm/material.hpp"

namespace smpm {

// ------------------------------------------------------------------------------------------------
// HistoryWriter

HistoryWriter::~HistoryWriter() {
  if (f_) {
    std::fclose(f_);
    f_ = nullptr;
  }
}

void HistoryWriter::open(const std::string& path, const std::vector<std::string>& columns) {
  close();
  for (const auto& c : columns) {
    if (c.find_first_of(",\n\r") != std::string::npos)
      throw std::runtime_error("history column name '" + c + "' contains ',' or a line break");
  }
  f_ = std::fopen(path.c_str(), "w");
  if (!f_)
    throw std::runtime_error("cannot open history file '" + path +
                             "' for writing: " + std::strerror(errno));
  ncol_ = columns.size();
  path_ = path;
  std::string header = "time";
  for (const auto& c : columns) header += "," + c;
  header += "\n";
  if (std::fputs(header.c_str(), f_) < 0) {
    std::fclose(f_);
    f_ = nullptr;
    throw std::runtime_error("cannot write to history file '" + path + "'");
  }
}

void HistoryWriter::resume(const std::string& path, const std::vector<std::string>& columns,
                           const std::string& text) {
  open(path, columns);
  std::string header = "time";
  for (const auto& c : columns) header += "," + c;
  header += "\n";
  if (text.compare(0, header.size(), header) != 0) {
    close();
    throw std::runtime_error("the checkpoint's history has other columns than this case's");
  }
  const std::string rest = text.substr(header.size());
  if (std::fwrite(rest.data(), 1, rest.size(), f_) != rest.size()) flush();
}

void HistoryWriter::flush() {
  if (!f_) return;
  if (std::fflush(f_) != 0 || std::ferror(f_))
    throw std::runtime_error("cannot write the history file '" + path_ + "': " +
                             std::strerror(errno));
}

void HistoryWriter::row(double time, const std::vector<double>& values) {
  if (!f_) throw std::runtime_error("HistoryWriter::row called before open()");
  if (values.size() != ncol_)
    throw std::runtime_error("HistoryWriter::row: got " + std::to_string(values.size()) +
                             " values for " + std::to_string(ncol_) + " columns");
  std::fprintf(f_, "%.9e", time);
  for (double v : values) std::fprintf(f_, ",%.9e", v);
  std::fputc('\n', f_);
}

void HistoryWriter::close() {
  if (!f_) return;
  const bool bad = std::ferror(f_) != 0;
  const bool close_failed = std::fclose(f_) != 0;
  f_ = nullptr;
  ncol_ = 0;
  if (bad || close_failed)
    throw std::runtime_error("cannot write the history file '" + path_ + "' (disk full?)");
}

// ------------------------------------------------------------------------------------------------
// SnapshotWriter

namespace {

// Closes an HDF5 object on scope exit (so a throw in the middle of a snapshot leaks nothing).
struct H5Handle {
  hid_t id = -1;
  herr_t (*closer)(hid_t) = nullptr;
  H5Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), closer(c) {}
  ~H5Handle() {
    if (id >= 0 && closer) closer(id);
  }
  H5Handle(const H5Handle&) = delete;
  H5Handle& operator=(const H5Handle&) = delete;
};

// The innermost HDF5 error description (e.g. the OS error behind a failed create), if any.
herr_t innermost_error(unsigned n, const H5E_error2_t* e, void* out) {
  if (n == 0 && e && e->desc) *static_cast<std::string*>(out) = e->desc;
  return 0;
}

[[noreturn]] void h5_fail(const std::string& what, const std::string& file) {
  std::string detail;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost_error, &detail);
  H5Eclear2(H5E_DEFAULT);
  throw std::runtime_error("HDF5: " + what + " in '" + file + "'" +
                           (detail.empty() ? std::string() : " (" + detail + ")"));
}

// One rank's share of a dataset written by several processes at once: its rows (RowBlock) of
// `total`, written through the collective transfer list `xfer`.
struct Rows {
  RowBlock block;
  std::size_t total;
  hid_t xfer;
};

// compression: the deflate level (0: stored as is, contiguous; 1-9: chunks of up to 65 536 rows,
// byte-shuffled and deflated, which every HDF5 reader undoes). part: this rank's rows when
// several processes write the dataset together (null: all n rows are here).
void write_dataset(hid_t group, const char* name, hid_t file_type, hid_t mem_type,
                   const void* data, std::size_t n, std::size_t ncomp, const std::string& file,
                   const std::string& group_name, const char* units = nullptr,
                   int compression = 0, const Rows* part = nullptr) {
  const int rank = ncomp > 1 ? 2 : 1;
  const std::size_t rows = part ? part->total : n;
  hsize_t dims[2] = {static_cast<hsize_t>(rows), static_cast<hsize_t>(ncomp)};
  H5Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  if (space.id < 0) h5_fail("cannot create dataspace for '" + group_name + "/" + name + "'", file);
  const bool deflate = compression > 0 && rows > 0;
  // Several processes: the file space is allocated when the dataset is made, on every rank
  // alike (a rank with no rows to write would otherwise not allocate it, and the ranks' views
  // of the file would part).
  const bool own_dcpl = deflate || part;
  H5Handle dcpl(own_dcpl ? H5Pcreate(H5P_DATASET_CREATE) : H5P_DEFAULT, own_dcpl ? H5Pclose : nullptr);
  if (part && (dcpl.id < 0 || H5Pset_alloc_time(dcpl.id, H5D_ALLOC_TIME_EARLY) < 0))
    h5_fail("cannot set the allocation of '" + group_name + "/" + name + "'", file);
  if (deflate) {
    const hsize_t chunk[2] = {std::min<hsize_t>(dims[0], 65536), dims[1]};
    if (dcpl.id < 0 || H5Pset_chunk(dcpl.id, rank, chunk) < 0 || H5Pset_shuffle(dcpl.id) < 0 ||
        H5Pset_deflate(dcpl.id, static_cast<unsigned>(compression)) < 0)
      h5_fail("cannot set compression of '" + group_name + "/" + name + "'", file);
  }
  H5Handle ds(H5Dcreate2(group, name, file_type, space.id, H5P_DEFAULT, dcpl.id, H5P_DEFAULT),
              H5Dclose);
  if (ds.id < 0) h5_fail("cannot create dataset '" + group_name + "/" + name + "'", file);
  if (part && rows > 0) {
    // Every rank takes part in the collective write, one with no rows selecting none.
    const RowBlock& b = part->block;
    if (b.rows() != n)
      throw std::runtime_error("HDF5 writer: " + std::to_string(n) + " rows for a block of " +
                               std::to_string(b.rows()) + " in '" + file + "'");
    const hsize_t start[2] = {static_cast<hsize_t>(b.first), 0};
    const hsize_t stride[2] = {static_cast<hsize_t>(std::max(b.stride, b.length)), 1};
    const hsize_t count[2] = {static_cast<hsize_t>(b.count), 1};
    const hsize_t block[2] = {static_cast<hsize_t>(b.length), static_cast<hsize_t>(ncomp)};
    const hsize_t mdims[2] = {static_cast<hsize_t>(std::max<std::size_t>(n, 1)),
                              static_cast<hsize_t>(ncomp)};
    H5Handle mem(H5Screate_simple(rank, mdims, nullptr), H5Sclose);
    bool selected = mem.id >= 0;
    if (selected && n > 0)
      selected = H5Sselect_hyperslab(space.id, H5S_SELECT_SET, start, stride, count, block) >= 0;
    else if (selected)
      selected = H5Sselect_none(space.id) >= 0 && H5Sselect_none(mem.id) >= 0;
    const double none = 0;
    if (!selected || H5Dwrite(ds.id, mem_type, mem.id, space.id, part->xfer,
                              n > 0 ? data : &none) < 0)
      h5_fail("cannot write dataset '" + group_name + "/" + name + "' (" + std::to_string(n) +
                  " rows from row " + std::to_string(b.first) + " of " + std::to_string(rows) +
                  ")",
              file);
  } else if (n > 0 && H5Dwrite(ds.id, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    h5_fail("cannot write dataset '" + group_name + "/" + name + "'", file);
  }
  if (!units) return;
  H5Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Handle aspace(H5Screate(H5S_SCALAR), H5Sclose);
  if (type.id < 0 || aspace.id < 0 || H5Tset_size(type.id, std::strlen(units)) < 0)
    h5_fail("cannot make the units attribute of '" + group_name + "/" + name + "'", file);
  H5Handle attr(H5Acreate2(ds.id, "units", type.id, aspace.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (attr.id < 0 || H5Awrite(attr.id, type.id, units) < 0)
    h5_fail("cannot write attribute '" + group_name + "/" + name + "@units'", file);
}

template <class T>
void write_scalar_attribute(hid_t obj, const char* name, hid_t file_type, hid_t mem_type, T value,
                            const std::string& file, const std::string& group_name) {
  H5Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  if (space.id < 0) h5_fail("cannot create dataspace for attribute '" + std::string(name) + "'", file);
  H5Handle attr(H5Acreate2(obj, name, file_type, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (attr.id < 0 || H5Awrite(attr.id, mem_type, &value) < 0)
    h5_fail("cannot write attribute '" + group_name + "@" + name + "'", file);
}

// A snapshot file created (truncating) or opened for writing without a file lock, so that h5py
// or ParaView can look at a running simulation's snapshots (each is flushed); readers still
// lock as usual. comm: the ranks that open it together over MPI-IO (null: this process alone).
// Returns the file, or a negative id.
hid_t open_unlocked(const std::string& path, bool create, const void* comm = nullptr,
                    const void* info = nullptr) {
  H5Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.id, 0, 1);
#endif
#ifdef H5_HAVE_PARALLEL
  if (comm && H5Pset_fapl_mpio(fapl.id, *static_cast<const MPI_Comm*>(comm),
                               *static_cast<const MPI_Info*>(info)) < 0)
    return -1;
#else
  if (comm) return -1;
#endif
  return create ? H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.id)
                : H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl.id);
}

// The transfer property list of a writer's datasets: collective writes when several processes
// (comm) write the file together, else the default. Throws on failure.
H5Handle transfer_list(const void* comm, const std::string& path) {
  if (!comm) return H5Handle(H5P_DEFAULT, nullptr);
  const hid_t x = H5Pcreate(H5P_DATASET_XFER);
#ifdef H5_HAVE_PARALLEL
  if (x >= 0 && H5Pset_dxpl_mpio(x, H5FD_MPIO_COLLECTIVE) >= 0) return H5Handle(x, H5Pclose);
#endif
  if (x >= 0) H5Pclose(x);
  h5_fail("cannot set up the collective write", path);
}

std::string step_name(long step) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "step_%09ld", step);
  return buf;
}

std::string vertices_name(std::size_t n) { return "vertices_" + std::to_string(n); }

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

// Every field a snapshot can hold, in file order: its bit in SnapshotFields, dataset name, XDMF
// number type and precision, components (1 scalar, 3 vector, 9 tensor) and units.
struct FieldInfo {
  unsigned bit;
  const char* name;
  const char* number_type;
  int precision;
  int components;
  const char* units;
};
constexpr FieldInfo kFields[] = {
    {kFieldVelocity, "velocity", "Float", 8, 3, "m/s"},
    {kFieldDisplacement, "displacement", "Float", 8, 3, "m"},
    {kFieldStress, "stress", "Float", 8, 9, "Pa"},
    {kFieldJ2, "J2", "Float", 8, 1, "Pa^2"},
    {kFieldEpsP, "eps_p", "Float", 8, 1, "1"},
    {kFieldMass, "mass", "Float", 8, 1, "kg/m"},
    {kFieldVolume, "volume", "Float", 8, 1, "m^2"},
    {kFieldBody, "body", "Int", 4, 1, "1"},
    {kFieldId, "id", "UInt", 4, 1, "1"},
    {kFieldState, "state", "Int", 4, 1, "1"},
    {kFieldLayer, "layer", "Int", 4, 1, "1"},
    {kFieldFilm, "normal", "Float", 8, 3, "1"},
    {kFieldFilm, "jump_n", "Float", 8, 1, "m"},
    {kFieldFilm, "jump_t", "Float", 8, 1, "m"},
    {kFieldFilm, "ubar", "Float", 8, 1, "1"},
};

const char* attribute_type(int components) {
  return components == 1 ? "Scalar" : components == 3 ? "Vector" : "Tensor";
}

}  // namespace

const std::vector<std::string>& snapshot_field_names() {
  static const std::vector<std::string> names = {"velocity", "displacement", "stress", "J2",
                                                 "eps_p",    "mass",         "volume", "body",
                                                 "id",       "state",        "layer",  "film"};
  return names;
}

unsigned snapshot_field(const std::string& name) {
  const auto& names = snapshot_field_names();
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return 1u << k;
  return 0;
}

SnapshotWriter::~SnapshotWriter() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; an explicit close() reports the error.
  }
}

namespace {
// Several processes (comm) need HDF5's MPI flavour: throws naming `what` without it.
void need_mpi_flavour([[maybe_unused]] const void* comm, [[maybe_unused]] const char* what) {
#ifndef H5_HAVE_PARALLEL
  if (comm)
    throw std::runtime_error(std::string("this HDF5 library was built without MPI: ") + what +
                             " of several processes need HDF5's MPI flavour");
#endif
}
}  // namespace

void SnapshotWriter::set_ranks(const void* comm, const void* info, int rank) {
  need_mpi_flavour(comm, "particle snapshots");
  comm_ = comm;
  info_ = info;
  rank_ = comm ? rank : 0;
}

void SnapshotWriter::open(const std::string& dir, const std::string& base) {
  close();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  dir_ = dir.empty() ? std::string(".") : dir;
  base_ = base;
  times_.clear();
  steps_.clear();
  sizes_.clear();
  const std::string path = dir_ + "/" + base_ + ".h5";

  const hid_t f = open_unlocked(path, true, comm_, info_);
  if (f < 0)
    h5_fail("cannot create the snapshot file (does the output directory exist and is it "
            "writable?)",
            path);
  file_ = f;
  xdmf_end_ = -1;  // the first snapshot writes the XDMF whole
}

namespace {
herr_t collect_name(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}
}  // namespace

int SnapshotWriter::resume(const std::string& dir, const std::string& base,
                           const std::vector<long>& steps, const std::vector<double>& times,
                           const std::vector<std::size_t>& sizes) {
  close();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const std::string path = (dir.empty() ? std::string(".") : dir) + "/" + base + ".h5";
  hid_t f = -1;
  if (!steps.empty()) f = open_unlocked(path, false, comm_, info_);  // missing or unreadable: f < 0
  bool whole = f >= 0;
  for (std::size_t k = 0; whole && k < steps.size(); ++k)
    whole = H5Lexists(f, step_name(steps[k]).c_str(), H5P_DEFAULT) > 0;
  if (!whole) {
    if (f >= 0) H5Fclose(f);
    H5Eclear2(H5E_DEFAULT);
    open(dir, base);
    return 0;
  }
  dir_ = dir.empty() ? std::string(".") : dir;
  base_ = base;
  file_ = f;
  std::vector<std::string> names;
  if (H5Literate(f, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, collect_name, &names) < 0)
    h5_fail("cannot list the snapshot groups", path);
  for (const auto& n : names) {
    bool listed = n.rfind("vertices_", 0) == 0;  // connectivity, shared by the snapshots
    for (long st : steps) listed = listed || n == step_name(st);
    if (!listed && H5Ldelete(f, n.c_str(), H5P_DEFAULT) < 0)
      h5_fail("cannot remove the later snapshot '/" + n + "'", path);
  }
  if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) h5_fail("cannot flush", path);
  // The file's fields are those of its first snapshot (a restart may not change them).
  fields_ = 0;
  for (const FieldInfo& fi : kFields)
    if (H5Lexists(f, (step_name(steps[0]) + "/" + fi.name).c_str(), H5P_DEFAULT) > 0)
      fields_ |= fi.bit;
  film_ = (fields_ & kFieldFilm) != 0;
  steps_ = steps;
  times_ = times;
  sizes_ = sizes;
  if (rank_ == 0) write_xdmf();
  return static_cast<int>(steps.size());
}

void SnapshotWriter::write(const Particles& p, long step, double time,
                           const std::vector<std::uint8_t>* layer) {
  if (comm_)
    throw std::runtime_error("SnapshotWriter::write: several processes write with an offset");
  write(p, step, time, layer, 0, p.size());
}

void SnapshotWriter::write(const Particles& p, long step, double time,
                           const std::vector<std::uint8_t>* layer, std::size_t offset,
                           std::size_t total) {
  const std::string path = dir_ + "/" + base_ + ".h5";
  if (file_ < 0) throw std::runtime_error("SnapshotWriter::write called before open()");
  const hid_t file = static_cast<hid_t>(file_);
  const std::size_t n = p.size();
  if (offset + n > total)
    throw std::runtime_error("SnapshotWriter: rows " + std::to_string(offset) + " to " +
                             std::to_string(offset + n) + " of a snapshot of " +
                             std::to_string(total));
  // Several processes: the datasets are written collectively, each rank its rows.
  const H5Handle xfer = transfer_list(comm_, path);
  const Rows rows{RowBlock{offset, n, 1, n}, total, xfer.id};
  const Rows* part = comm_ ? &rows : nullptr;
  {
    const std::size_t sizes[] = {p.y.size(),   p.x0.size(),  p.y0.size(),  p.vx.size(),
                                 p.vy.size(),  p.mass.size(), p.vol.size(), p.sxx.size(),
                                 p.syy.size(), p.szz.size(), p.sxy.size(), p.eps_p.size(),
                                 p.id.size(),  p.body.size(), p.state.size(), p.dnx.size(),
                                 p.dny.size(), p.jump_n.size(), p.jump_t.size(), p.ubar.size()};
    for (std::size_t k = 0; k < std::size(sizes); ++k)
      if (sizes[k] != n && !(k >= 14 && !p.has_film()))  // the film block may be off
        throw std::runtime_error("SnapshotWriter: particle arrays have inconsistent sizes (" +
                                 std::to_string(sizes[k]) + " vs " + std::to_string(n) + ")");
    if (layer && layer->size() != n)
      throw std::runtime_error("SnapshotWriter: the layer flags have " +
                               std::to_string(layer->size()) + " entries for " +
                               std::to_string(n) + " particles");
  }
  if (steps_.empty()) film_ = p.has_film();  // the first snapshot fixes the file's fields

  const std::string gname = step_name(step);
  // Writing the same step twice replaces the earlier snapshot of that step.
  std::size_t slot = steps_.size();
  for (std::size_t k = 0; k < steps_.size(); ++k)
    if (steps_[k] == step) slot = k;
  if (slot < steps_.size() && H5Lexists(file, gname.c_str(), H5P_DEFAULT) > 0 &&
      H5Ldelete(file, gname.c_str(), H5P_DEFAULT) < 0)
    h5_fail("cannot replace group '/" + gname + "'", path);

  H5Handle group(H5Gcreate2(file, gname.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                 H5Gclose);
  if (group.id < 0) h5_fail("cannot create group '/" + gname + "'", path);
  write_scalar_attribute(group.id, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, time, path, gname);
  write_scalar_attribute(group.id, "step", H5T_STD_I64LE, H5T_NATIVE_INT64,
                         static_cast<int64_t>(step), path, gname);

  std::vector<double> buf;
  // An n x c array from c per-particle functions.
  auto columns = [&](int c, auto&& value) {
    buf.assign(static_cast<std::size_t>(c) * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      for (int q = 0; q < c; ++q) buf[c * i + q] = value(i, q);
    return buf.data();
  };
  auto vec3 = [&](const std::vector<double>& a, const std::vector<double>& b) {
    return columns(3, [&](std::size_t i, int q) { return q == 0 ? a[i] : q == 1 ? b[i] : 0.0; });
  };
  write_dataset(group.id, "xyz", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, vec3(p.x, p.y), n, 3, path,
                gname, "m", compression_, part);
  std::vector<int32_t> ibuf(n);
  for (const FieldInfo& f : kFields) {
    if (!(fields_ & f.bit) || (f.bit == kFieldFilm && !film_)) continue;
    const std::string name = f.name;
    const double* d = nullptr;
    if (name == "velocity") d = vec3(p.vx, p.vy);
    else if (name == "displacement")
      d = columns(3, [&](std::size_t i, int q) {
        return q == 0 ? p.x[i] - p.x0[i] : q == 1 ? p.y[i] - p.y0[i] : 0.0;
      });
    else if (name == "stress")
      d = columns(9, [&](std::size_t i, int q) {
        switch (q) {
          case 0: return p.sxx[i];
          case 1: case 3: return p.sxy[i];
          case 4: return p.syy[i];
          case 8: return p.szz[i];
          default: return 0.0;
        }
      });
    else if (name == "J2")
      d = columns(1, [&](std::size_t i, int) { return j2_of(p.sxx[i], p.syy[i], p.szz[i], p.sxy[i]); });
    else if (name == "eps_p") d = p.eps_p.data();
    else if (name == "mass") d = p.mass.data();
    else if (name == "volume") d = p.vol.data();
    else if (name == "normal") d = film_ && p.has_film() ? vec3(p.dnx, p.dny) : columns(3, [](std::size_t, int) { return 0.0; });
    else if (name == "jump_n" || name == "jump_t" || name == "ubar") {
      const std::vector<double>& v = name == "jump_n" ? p.jump_n : name == "jump_t" ? p.jump_t : p.ubar;
      d = film_ && p.has_film() ? v.data() : columns(1, [](std::size_t, int) { return 0.0; });
    }
    if (std::strcmp(f.number_type, "Float") == 0) {  // d: null when this rank has no rows
      write_dataset(group.id, f.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, d, n,
                    static_cast<std::size_t>(f.components), path, gname, f.units, compression_, part);
      continue;
    }
    if (name == "id") {
      write_dataset(group.id, f.name, H5T_STD_U32LE, H5T_NATIVE_UINT32, p.id.data(), n, 1, path,
                    gname, f.units, compression_, part);
      continue;
    }
    for (std::size_t i = 0; i < n; ++i)
      ibuf[i] = name == "body"    ? p.body[i]
                : name == "state" ? (i < p.state.size() ? p.state[i] : 0)
                                  : (layer ? (*layer)[i] : 0);
    write_dataset(group.id, f.name, H5T_STD_I32LE, H5T_NATIVE_INT32, ibuf.data(), n, 1, path,
                  gname, f.units, compression_, part);
  }

  // The vertex connectivity 0 .. N-1 of the Polyvertex topology (XDMF 3 readers and meshio need
  // it): one dataset per particle count, shared by the snapshots of that count.
  const std::string vname = vertices_name(total);
  if (H5Lexists(file, vname.c_str(), H5P_DEFAULT) <= 0) {
    std::vector<int64_t> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<int64_t>(offset + i);
    write_dataset(file, vname.c_str(), H5T_STD_I64LE, H5T_NATIVE_INT64, v.data(), n, 1, path, "",
                  nullptr, compression_, part);
  }

  if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) h5_fail("cannot flush", path);

  if (slot < steps_.size()) {
    times_[slot] = time;
    sizes_[slot] = total;
    if (rank_ == 0) write_xdmf();
  } else {
    steps_.push_back(step);
    times_.push_back(time);
    sizes_.push_back(total);
    if (rank_ == 0) append_xdmf();
  }
}

void SnapshotWriter::close() {
  if (file_ < 0) return;
  const hid_t f = static_cast<hid_t>(file_);
  file_ = -1;
  if (H5Fclose(f) < 0) h5_fail("cannot close", dir_ + "/" + base_ + ".h5");
}

// The XDMF text: head, one grid per snapshot, tail. The file is written whole once (open,
// resume, a snapshot replaced) and then grows by one grid per snapshot, written over the tail
// together with a new tail: a snapshot costs the same at the thousandth as at the first, and the
// file on disk is a complete document after every snapshot.
namespace {
const char* const kXdmfTail = "    </Grid>\n  </Domain>\n</Xdmf>\n";
}

namespace {
// The XDMF document up to its first grid: the temporal collection `base`, and the units of the
// fields ("xyz m, velocity m/s, ...") in an Information element of the Domain.
std::string xdmf_document_head(const std::string& base, const std::string& units) {
  std::string s;
  s += "<?xml version=\"1.0\" ?>\n";
  s += "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n";
  s += "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n";
  s += "  <Domain>\n";
  s += "    <Information Name=\"units\" Value=\"" + xml_escape(units) + "\"/>\n";
  s += "    <Grid Name=\"" + xml_escape(base) +
       "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  return s;
}
}  // namespace

std::string SnapshotWriter::xdmf_head() const {
  std::string units = "xyz m";
  for (const FieldInfo& f : kFields)
    if ((fields_ & f.bit) && !(f.bit == kFieldFilm && !film_))
      units += std::string(", ") + f.name + " " + f.units;
  return xdmf_document_head(base_, units);
}

std::string SnapshotWriter::xdmf_grid(std::size_t k) const {
  const std::size_t n = sizes_[k];
  if (n == 0) return {};  // an empty Polyvertex grid is not readable; the .h5 still has it
  const std::string h5 = xml_escape(base_ + ".h5");  // relative: the folder moves as a whole
  const std::string g = step_name(steps_[k]);
  std::string s;
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "      <Grid Name=\"%s\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.9e\"/>\n"
                "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" "
                "NodesPerElement=\"1\">\n"
                "          <DataItem Dimensions=\"%zu 1\" NumberType=\"Int\" Precision=\"8\" "
                "Format=\"HDF\">%s:/%s</DataItem>\n"
                "        </Topology>\n"
                "        <Geometry GeometryType=\"XYZ\">\n"
                "          <DataItem Dimensions=\"%zu 3\" NumberType=\"Float\" Precision=\"8\" "
                "Format=\"HDF\">%s:/%s/xyz</DataItem>\n"
                "        </Geometry>\n",
                g.c_str(), times_[k], n, n, h5.c_str(), vertices_name(n).c_str(), n, h5.c_str(),
                g.c_str());
  s += buf;
  for (const FieldInfo& f : kFields) {
    if (!(fields_ & f.bit) || (f.bit == kFieldFilm && !film_)) continue;
    char dims[64];
    if (f.components == 1) std::snprintf(dims, sizeof dims, "%zu", n);
    else std::snprintf(dims, sizeof dims, "%zu %d", n, f.components);
    std::snprintf(buf, sizeof buf,
                  "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n"
                  "          <DataItem Dimensions=\"%s\" NumberType=\"%s\" Precision=\"%d\" "
                  "Format=\"HDF\">%s:/%s/%s</DataItem>\n"
                  "        </Attribute>\n",
                  f.name, attribute_type(f.components), dims, f.number_type, f.precision,
                  h5.c_str(), g.c_str(), f.name);
    s += buf;
  }
  s += "      </Grid>\n";
  return s;
}

std::string SnapshotWriter::xdmf_text() const {
  std::string s = xdmf_head();
  for (std::size_t k = 0; k < steps_.size(); ++k) s += xdmf_grid(k);
  return s + kXdmfTail;
}

namespace {

// The XDMF document `text` written whole through a temporary file and a rename; returns the
// offset of its tail (the last tail_size bytes). Throws std::runtime_error.
long long write_xdmf_whole(const std::string& path, const std::string& text, std::size_t tail_size) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (!f)
    throw std::runtime_error("cannot open XDMF file '" + tmp + "' for writing: " +
                             std::strerror(errno));
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size() && std::fflush(f) == 0;
  const int err = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    const std::string why = std::strerror(ok ? errno : err);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write XDMF file '" + tmp + "': " + why);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string err2 = std::strerror(errno);
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot rename '" + tmp + "' to '" + path + "': " + err2);
  }
  return static_cast<long long>(text.size() - tail_size);
}

// One more grid written over the tail at `end`, with the tail after it; `end` moves past the grid.
// Returns false when the file is gone (write it whole instead). Throws std::runtime_error.
bool append_xdmf_grid(const std::string& path, long long& end, const std::string& grid) {
  const std::string s = grid + kXdmfTail;
  std::FILE* f = std::fopen(path.c_str(), "r+b");
  if (!f) return false;
  const bool ok = std::fseek(f, static_cast<long>(end), SEEK_SET) == 0 &&
                  std::fwrite(s.data(), 1, s.size(), f) == s.size() && std::fflush(f) == 0;
  const int err = errno;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !closed) {
    end = -1;  // the next snapshot rewrites the file whole
    throw std::runtime_error("cannot write XDMF file '" + path + "': " +
                             std::strerror(ok ? errno : err));
  }
  end += static_cast<long long>(grid.size());
  return true;
}

}  // namespace

void SnapshotWriter::write_xdmf() {
  xdmf_end_ = -1;
  xdmf_end_ = write_xdmf_whole(dir_ + "/" + base_ + ".xdmf", xdmf_text(), std::strlen(kXdmfTail));
}

void SnapshotWriter::append_xdmf() {
  if (xdmf_end_ < 0 ||
      !append_xdmf_grid(dir_ + "/" + base_ + ".xdmf", xdmf_end_, xdmf_grid(steps_.size() - 1)))
    write_xdmf();
}

// ------------------------------------------------------------------------------------------------
// MeshSnapshotWriter

namespace {
std::string snapshot_group(std::size_t k) {
  char b[32];
  std::snprintf(b, sizeof b, "snapshot_%05zu", k);
  return b;
}

// Rows and columns of a dataset (columns 1 for a 1-D one); false when it is missing.
bool dataset_shape(hid_t f, const std::string& name, hsize_t& rows, hsize_t& cols) {
  if (H5Lexists(f, name.c_str(), H5P_DEFAULT) <= 0) return false;
  H5Handle ds(H5Dopen2(f, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (ds.id < 0) return false;
  H5Handle sp(H5Dget_space(ds.id), H5Sclose);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_dims(sp.id, dims, nullptr);
  if (rank < 1 || rank > 2) return false;
  rows = dims[0];
  cols = rank == 2 ? dims[1] : 1;
  return true;
}
}  // namespace

MeshSnapshotWriter::~MeshSnapshotWriter() {
  try {
    close();
  } catch (...) {
  }
}

void MeshSnapshotWriter::set_ranks(const void* comm, const void* info, int rank,
                                   std::size_t nodes, std::size_t cells,
                                   const RowBlock& own_nodes, const RowBlock& own_cells) {
  need_mpi_flavour(comm, "mesh snapshots");
  comm_ = comm;
  info_ = info;
  rank_ = comm ? rank : 0;
  nodes_ = nodes;
  cells_ = cells;
  own_nodes_ = own_nodes;
  own_cells_ = own_cells;
}

void MeshSnapshotWriter::open(const std::string& dir, const std::string& base,
                              const std::vector<double>& xyz, const std::vector<std::int64_t>& cells,
                              const std::vector<std::int32_t>& material) {
  close();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  dir_ = dir.empty() ? std::string(".") : dir;
  base_ = base;
  times_.clear();
  names_.clear();
  units_.clear();
  components_.clear();
  const std::size_t my_nodes = xyz.size() / 3, my_cells = cells.size() / 4;
  if (!comm_) {
    nodes_ = my_nodes;
    cells_ = my_cells;
  }
  if (material.size() != my_cells)
    throw std::runtime_error("MeshSnapshotWriter: " + std::to_string(material.size()) +
                             " materials for " + std::to_string(my_cells) + " cells");
  const std::string path = dir_ + "/" + base_ + ".h5";
  const hid_t f = open_unlocked(path, true, comm_, info_);
  if (f < 0) h5_fail("cannot create the snapshot file (does the output directory exist?)", path);
  try {  // the writer counts as open only with the mesh written
    const H5Handle xfer = transfer_list(comm_, path);
    const Rows node_rows{own_nodes_, nodes_, xfer.id}, cell_rows{own_cells_, cells_, xfer.id};
    H5Handle mesh(H5Gcreate2(f, "mesh", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    if (mesh.id < 0) h5_fail("cannot create group '/mesh'", path);
    write_dataset(mesh.id, "xyz", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, xyz.data(), my_nodes, 3,
                  path, "mesh", "m", compression_, comm_ ? &node_rows : nullptr);
    write_dataset(mesh.id, "cells", H5T_STD_I64LE, H5T_NATIVE_INT64, cells.data(), my_cells, 4,
                  path, "mesh", "1", compression_, comm_ ? &cell_rows : nullptr);
    write_dataset(mesh.id, "material", H5T_STD_I32LE, H5T_NATIVE_INT32, material.data(),
                  my_cells, 1, path, "mesh", "1", compression_, comm_ ? &cell_rows : nullptr);
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) h5_fail("cannot flush", path);
  } catch (...) {
    H5Fclose(f);
    if (rank_ == 0) std::remove(path.c_str());
    throw;
  }
  file_ = f;
  xdmf_end_ = -1;
}

int MeshSnapshotWriter::resume(const std::string& dir, const std::string& base,
                               const std::vector<double>& times) {
  close();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const std::string path = (dir.empty() ? std::string(".") : dir) + "/" + base + ".h5";
  if (times.empty()) return 0;
  hid_t f = open_unlocked(path, false, comm_, info_);
  hsize_t rows = 0, cols = 0, crow = 0;
  bool whole = f >= 0 && dataset_shape(f, "/mesh/xyz", rows, cols) &&
               dataset_shape(f, "/mesh/cells", crow, cols);
  for (std::size_t k = 0; whole && k < times.size(); ++k)
    whole = H5Lexists(f, snapshot_group(k).c_str(), H5P_DEFAULT) > 0;
  if (!whole) {
    if (f >= 0) H5Fclose(f);
    H5Eclear2(H5E_DEFAULT);
    return 0;
  }
  dir_ = dir.empty() ? std::string(".") : dir;
  base_ = base;
  file_ = f;
  nodes_ = rows;
  cells_ = crow;
  for (std::size_t k = times.size();; ++k) {  // the later snapshots of the run that stopped
    const std::string g = snapshot_group(k);
    if (H5Lexists(f, g.c_str(), H5P_DEFAULT) <= 0) break;
    if (H5Ldelete(f, g.c_str(), H5P_DEFAULT) < 0) h5_fail("cannot remove '/" + g + "'", path);
  }
  // The fields, from the first snapshot, with their units: H5Literate goes by name, the order
  // in which write() lists them.
  names_.clear();
  units_.clear();
  components_.clear();
  std::vector<std::string> names;
  H5Handle g0(H5Gopen2(f, snapshot_group(0).c_str(), H5P_DEFAULT), H5Gclose);
  if (g0.id < 0 || H5Literate(g0.id, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, collect_name, &names) < 0)
    h5_fail("cannot list the fields of '/" + snapshot_group(0) + "'", path);
  for (const auto& n : names) {
    hsize_t r = 0, c = 0;
    if (!dataset_shape(f, "/" + snapshot_group(0) + "/" + n, r, c)) continue;
    names_.push_back(n);
    components_.push_back(static_cast<int>(c));
    std::string u;
    H5Handle ds(H5Dopen2(f, ("/" + snapshot_group(0) + "/" + n).c_str(), H5P_DEFAULT), H5Dclose);
    if (ds.id >= 0 && H5Aexists(ds.id, "units") > 0) {
      H5Handle a(H5Aopen(ds.id, "units", H5P_DEFAULT), H5Aclose);
      H5Handle t(H5Aget_type(a.id), H5Tclose);
      u.assign(H5Tget_size(t.id), '\0');
      if (H5Aread(a.id, t.id, u.data()) < 0) u.clear();
      u.resize(std::strlen(u.c_str()));
    }
    units_.push_back(u);
  }
  if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) h5_fail("cannot flush", path);
  times_ = times;
  if (rank_ == 0)
    xdmf_end_ = write_xdmf_whole(dir_ + "/" + base_ + ".xdmf", xdmf_text(), std::strlen(kXdmfTail));
  return static_cast<int>(times.size());
}

void MeshSnapshotWriter::write(double time, const std::vector<Field>& fields) {
  const std::string path = dir_ + "/" + base_ + ".h5";
  if (file_ < 0) throw std::runtime_error("MeshSnapshotWriter::write called before open()");
  const hid_t f = static_cast<hid_t>(file_);
  if (times_.empty() && names_.empty()) {  // listed by name, as resume() finds them
    std::vector<const Field*> order;
    for (const Field& fd : fields) order.push_back(&fd);
    std::sort(order.begin(), order.end(),
              [](const Field* a, const Field* b) { return std::strcmp(a->name, b->name) < 0; });
    for (const Field* fd : order) {
      names_.push_back(fd->name);
      units_.push_back(fd->units);
      components_.push_back(fd->components);
    }
  }
  const std::string g = snapshot_group(times_.size());
  H5Handle grp(H5Gcreate2(f, g.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  if (grp.id < 0) h5_fail("cannot create group '/" + g + "'", path);
  write_scalar_attribute(grp.id, "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, time, path, g);
  const H5Handle xfer = transfer_list(comm_, path);
  const Rows node_rows{own_nodes_, nodes_, xfer.id};
  for (const Field& fd : fields)
    write_dataset(grp.id, fd.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, fd.data,
                  comm_ ? own_nodes_.rows() : nodes_, static_cast<std::size_t>(fd.components),
                  path, g, fd.units, compression_, comm_ ? &node_rows : nullptr);
  if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) h5_fail("cannot flush", path);
  times_.push_back(time);
  if (rank_ != 0) return;
  const std::string xpath = dir_ + "/" + base_ + ".xdmf";
  if (xdmf_end_ < 0 || !append_xdmf_grid(xpath, xdmf_end_, xdmf_grid(times_.size() - 1))) {
    xdmf_end_ = -1;
    xdmf_end_ = write_xdmf_whole(xpath, xdmf_text(), std::strlen(kXdmfTail));
  }
}

void MeshSnapshotWriter::close() {
  if (file_ < 0) return;
  const hid_t f = static_cast<hid_t>(file_);
  file_ = -1;
  if (H5Fclose(f) < 0) h5_fail("cannot close", dir_ + "/" + base_ + ".h5");
}

std::string MeshSnapshotWriter::xdmf_grid(std::size_t k) const {
  const std::string h5 = xml_escape(base_ + ".h5");
  const std::string g = snapshot_group(k);
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "      <Grid Name=\"%s\" GridType=\"Uniform\">\n"
                "        <Time Value=\"%.9e\"/>\n"
                "        <Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"%zu\">\n"
                "          <DataItem Dimensions=\"%zu 4\" NumberType=\"Int\" Precision=\"8\" "
                "Format=\"HDF\">%s:/mesh/cells</DataItem>\n"
                "        </Topology>\n"
                "        <Geometry GeometryType=\"XYZ\">\n"
                "          <DataItem Dimensions=\"%zu 3\" NumberType=\"Float\" Precision=\"8\" "
                "Format=\"HDF\">%s:/mesh/xyz</DataItem>\n"
                "        </Geometry>\n"
                "        <Attribute Name=\"material\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
                "          <DataItem Dimensions=\"%zu\" NumberType=\"Int\" Precision=\"4\" "
                "Format=\"HDF\">%s:/mesh/material</DataItem>\n"
                "        </Attribute>\n",
                g.c_str(), times_[k], cells_, cells_, h5.c_str(), nodes_, h5.c_str(), cells_,
                h5.c_str());
  std::string s = buf;
  for (std::size_t q = 0; q < names_.size(); ++q) {
    const int c = components_[q];
    char dims[64];
    if (c == 1) std::snprintf(dims, sizeof dims, "%zu", nodes_);
    else std::snprintf(dims, sizeof dims, "%zu %d", nodes_, c);
    std::snprintf(buf, sizeof buf,
                  "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n"
                  "          <DataItem Dimensions=\"%s\" NumberType=\"Float\" Precision=\"8\" "
                  "Format=\"HDF\">%s:/%s/%s</DataItem>\n"
                  "        </Attribute>\n",
                  names_[q].c_str(), attribute_type(c), dims, h5.c_str(), g.c_str(),
                  names_[q].c_str());
    s += buf;
  }
  return s + "      </Grid>\n";
}

std::string MeshSnapshotWriter::xdmf_text() const {
  std::string units = "xyz m";
  for (std::size_t q = 0; q < names_.size(); ++q)
    if (!units_[q].empty()) units += ", " + names_[q] + " " + units_[q];
  std::string s = xdmf_document_head(base_, units);
  for (std::size_t k = 0; k < times_.size(); ++k) s += xdmf_grid(k);
  return s + kXdmfTail;
}

}  // namespace smpm
