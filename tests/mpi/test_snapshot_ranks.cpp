// Particle snapshots written by every rank into one file at once (SnapshotWriter over MPI-IO),
// against the same particles written by one process: rank 0 writes the ranks' particles joined
// in rank order with a one-process writer, and every dataset of the two files must agree to the
// bit, and the XDMF byte for byte. Each rank holds a different count, one of them none; the
// snapshots change their total; stored as is and deflated; and a restart that keeps the first
// snapshot and removes the later ones.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mpi_testing.hpp"
#include "silentmpm/output.hpp"

namespace smpm::testing {
namespace {

namespace fs = std::filesystem;

// Rank r's particles of snapshot s: a count that differs by rank and snapshot (rank 1 has none
// in the first), each field a distinct value of (r, s, k).
Particles particles_of(int r, int s) {
  const std::size_t n = (r == 1 && s == 0) ? 0 : static_cast<std::size_t>(50 + 37 * r + 11 * s);
  Particles p;
  p.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double v = 1000.0 * r + k + 0.125 * s;
    p.x[k] = v;
    p.y[k] = -v;
    p.x0[k] = v - 0.5;
    p.y0[k] = 0.25 - v;
    p.vx[k] = 2 * v;
    p.vy[k] = 3 * v;
    p.mass[k] = 1 + v;
    p.vol[k] = 1 / (1 + v);
    p.sxx[k] = 5 * v;
    p.syy[k] = -7 * v;
    p.szz[k] = 11 * v;
    p.sxy[k] = 13 * v;
    p.eps_p[k] = 1e-3 * v;
    p.id[k] = static_cast<uint32_t>(100000 * r + k);
    p.body[k] = static_cast<uint16_t>(r % 3);
  }
  return p;
}

std::vector<std::uint8_t> layer_of(const Particles& p, int r) {
  std::vector<std::uint8_t> f(p.size());
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = static_cast<std::uint8_t>((k + r) % 5);
  return f;
}

// Every rank's particles joined in rank order (what one process writes).
Particles joined(int ranks, int s, std::vector<std::uint8_t>& layer) {
  Particles all;
  layer.clear();
  for (int r = 0; r < ranks; ++r) {
    const Particles p = particles_of(r, s);
    const std::vector<std::uint8_t> f = layer_of(p, r);
    std::vector<double> rec;
    for (std::size_t k = 0; k < p.size(); ++k) {
      rec.clear();
      p.pack(k, rec);
      all.unpack(rec.data());
    }
    layer.insert(layer.end(), f.begin(), f.end());
  }
  return all;
}

herr_t collect(hid_t, const char* name, const H5O_info_t* info, void* out) {
  if (info->type == H5O_TYPE_DATASET) static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

// Every dataset of the file, by name, read as doubles (ids and flags are exact in a double).
std::vector<std::pair<std::string, std::vector<double>>> datasets(const std::string& path) {
  std::vector<std::pair<std::string, std::vector<double>>> out;
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << path;
  if (f < 0) return out;
  std::vector<std::string> names;
  H5Ovisit(f, H5_INDEX_NAME, H5_ITER_INC, collect, &names);
  for (const std::string& n : names) {
    const hid_t ds = H5Dopen2(f, n.c_str(), H5P_DEFAULT);
    const hid_t sp = H5Dget_space(ds);
    std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)));
    EXPECT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << n;
    out.emplace_back(n, std::move(v));
    H5Sclose(sp);
    H5Dclose(ds);
  }
  H5Fclose(f);
  return out;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rank 0's verdict on the two folders: the datasets (names, sizes, every value's bits) and the
// XDMF text. Returns the differences found, for every rank.
int compare_on_root(const fs::path& one, const fs::path& ranks, std::string& why) {
  int bad = 0;
  if (mpi_testing::world_rank() == 0) {
    const auto a = datasets((one / "particles.h5").string());
    const auto b = datasets((ranks / "particles.h5").string());
    if (a.size() != b.size() || a.empty()) {
      ++bad;
      why += "dataset counts " + std::to_string(a.size()) + " and " + std::to_string(b.size()) + "; ";
    }
    for (std::size_t k = 0; k < std::min(a.size(), b.size()); ++k)
      if (a[k].first != b[k].first || a[k].second != b[k].second) {
        ++bad;
        why += a[k].first + " differs from " + b[k].first + "; ";
      }
    if (read_text(one / "particles.xdmf") != read_text(ranks / "particles.xdmf")) {
      ++bad;
      why += "the XDMF differs; ";
    }
  }
  MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return bad;
}

fs::path folder(const std::string& name) {
  return mpi_testing::scratch_folder("snapshot_ranks", name);
}

void write_both(SnapshotWriter& one, SnapshotWriter& all, int s, long step, double time) {
  const int rank = mpi_testing::world_rank(), P = mpi_testing::world_size();
  const Particles mine = particles_of(rank, s);
  std::vector<double> counts(P, 0.0);
  counts[rank] = static_cast<double>(mine.size());
  MPI_Allreduce(MPI_IN_PLACE, counts.data(), P, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  std::size_t offset = 0, total = 0;
  for (int r = 0; r < P; ++r) {
    if (r == rank) offset = total;
    total += static_cast<std::size_t>(counts[r]);
  }
  const std::vector<std::uint8_t> f = layer_of(mine, rank);
  all.write(mine, step, time, &f, offset, total);
  if (rank == 0) {
    std::vector<std::uint8_t> layer;
    const Particles whole = joined(P, s, layer);
    one.write(whole, step, time, &layer);
  }
}

TEST(SnapshotRanks, OneFileFromEveryRankAsOneProcessWritesIt) {
  const MPI_Comm comm = MPI_COMM_WORLD;
  const MPI_Info info = MPI_INFO_NULL;
  const int rank = mpi_testing::world_rank();
  for (const int level : {0, 5}) {
    const std::string tag = "deflate" + std::to_string(level);
    const fs::path a = folder(tag + "_one"), b = folder(tag + "_ranks");
    std::vector<long> steps;
    std::vector<double> times;
    std::vector<std::size_t> sizes;
    {
      SnapshotWriter one, all;
      all.set_ranks(&comm, &info, rank);
      for (SnapshotWriter* w : {&one, &all}) w->set_compression(level);
      all.open(b.string());
      if (rank == 0) one.open(a.string());
      for (int s = 0; s < 3; ++s) write_both(one, all, s, 10L * s, 1e-6 * s);
      steps = all.steps();
      times = all.times();
      sizes = all.sizes();
      all.close();
      if (rank == 0) {
        EXPECT_EQ(one.sizes(), all.sizes());
        one.close();
      }
    }
    std::string why;
    EXPECT_EQ(compare_on_root(a, b, why), 0) << tag << ": " << why;

    // A restart that keeps the first snapshot: the later groups go; one more is written.
    {
      SnapshotWriter one, all;
      all.set_ranks(&comm, &info, rank);
      EXPECT_EQ(all.resume(b.string(), "particles", {steps[0]}, {times[0]}, {sizes[0]}), 1);
      if (rank == 0) {
        EXPECT_EQ(one.resume(a.string(), "particles", {steps[0]}, {times[0]}, {sizes[0]}), 1);
      }
      write_both(one, all, 2, 99, 5e-6);
      all.close();
      if (rank == 0) one.close();
    }
    why.clear();
    EXPECT_EQ(compare_on_root(a, b, why), 0) << tag << " after the restart: " << why;
    if (rank == 0) {
      const std::string x = read_text(b / "particles.xdmf");
      EXPECT_EQ(x.find("step_000000010"), std::string::npos) << "a removed snapshot is listed";
      EXPECT_NE(x.find("step_000000099"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace smpm::testing
