// One checkpoint written by every rank at once (parallel/state_write.hpp), on 1, 2 and 4 ranks:
//   * the file is byte for byte the one a single process writes with the ranks' parts joined
//     in rank order, whatever the pieces each write carries;
//   * a write that fails on the ranks is one error on every rank, and leaves no file and no
//     open descriptor; a file system without fsync is no error, as on one process;
//   * the MPM solver's parts hold every particle and every layer entry of every rank, bit for
//     bit, and the file restarts a solver on one process.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <cerrno>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common.hpp"
#include "mpi_testing.hpp"
#include "silentmpm/distributed.hpp"
#include "silentmpm/solver.hpp"
#include "silentmpm/state_io.hpp"
#include "silentmpm/state_write.hpp"

namespace smpm::testing {
namespace {

namespace fs = std::filesystem;

fs::path folder(const std::string& name) { return mpi_testing::scratch_folder("state_ranks", name); }

// The error of a write on every rank ("" if none).
std::string write_error(const StateWriter& w, const fs::path& file) {
  try {
    write_state_collectively(w, file.string(), MPI_COMM_WORLD);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Rank r's part of block "a" (doubles) and "b" (uint32): counts that differ by rank, one rank
// with none; every value names its rank and place.
std::vector<double> part_a(int r) {
  std::vector<double> v(std::vector<std::size_t>{0, 7, 23, 100}[r % 4]);
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = 1000.0 * r + k + 0.25;
  return v;
}
std::vector<std::uint32_t> part_b(int r) {
  std::vector<std::uint32_t> v(static_cast<std::size_t>(3 * r + 1));
  for (std::size_t k = 0; k < v.size(); ++k) v[k] = static_cast<std::uint32_t>(100 * r + k);
  return v;
}

// The file from every rank against one process's bytes with the parts joined, with writes of
// at most 7 bytes and of the default size; rank 0 alone puts one whole block, every rank the
// others (the other ranks' values of a whole block are not used).
TEST(StateRanks, OneFileFromEveryRankAsOneProcessWritesIt) {
  const int rank = mpi_testing::world_rank(), P = mpi_testing::world_size();
  const fs::path dir = folder("file");
  const std::size_t kept = state_write_piece();
  for (const std::size_t piece : {std::size_t{7}, kept}) {
    set_state_write_piece(piece);
    StateWriter w;
    w.put_string("run.version", "test");
    if (rank == 0) w.put_string("run.history", std::string(1000, 'h'));
    w.put("scalar", 3.5 + rank);  // rank 0's value is the one written
    w.put_part("a", part_a(rank));
    w.put("middle", std::vector<std::int32_t>{1, 2, 3});
    w.put_part("b", part_b(rank));
    w.put_part("empty", std::vector<double>{});
    const fs::path file = dir / "state.smpm";
    write_state_collectively(w, file.string(), MPI_COMM_WORLD);
    set_state_write_piece(kept);
    if (rank == 0) {
      StateWriter one;
      one.put_string("run.version", "test");
      one.put_string("run.history", std::string(1000, 'h'));
      one.put("scalar", 3.5);
      std::vector<double> a;
      std::vector<std::uint32_t> b;
      for (int r = 0; r < P; ++r) {
        const auto ar = part_a(r);
        const auto br = part_b(r);
        a.insert(a.end(), ar.begin(), ar.end());
        b.insert(b.end(), br.begin(), br.end());
      }
      one.put_part("a", a);
      one.put("middle", std::vector<std::int32_t>{1, 2, 3});
      one.put_part("b", b);
      one.put_part("empty", std::vector<double>{});
      const std::string got = read_bytes(file), want = one.bytes();
      EXPECT_EQ(got.size(), want.size()) << "pieces of " << piece << " bytes";
      EXPECT_TRUE(got == want) << "pieces of " << piece << " bytes: the bytes differ";
      const StateReader r(got, file.string());  // its checksum holds
      std::vector<double> ra;
      r.get("a", ra);
      EXPECT_EQ(ra, a);
      EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
    }
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

// A folder that does not exist: every rank gets the same error naming the file; no file is left.
TEST(StateRanks, AFailedWriteIsOneErrorOnEveryRank) {
  const fs::path file = folder("fail") / "missing" / "state.smpm";
  StateWriter w;
  w.put_part("a", part_a(mpi_testing::world_rank()));
  const std::string what = write_error(w, file);
  EXPECT_NE(what.find(file.string() + ": cannot create state.smpm.tmp"), std::string::npos) << what;
  EXPECT_EQ(what, mpi_testing::root_string(what)) << "the same message on every rank";
  EXPECT_FALSE(fs::exists(file));
}

// A full disk (the temporary file linked to /dev/full): every rank gets the same error naming
// the file and the cause; no checkpoint is left.
TEST(StateRanks, AFullDiskIsOneErrorOnEveryRank) {
  const fs::path dir = folder("full"), file = dir / "state.smpm";
  if (mpi_testing::world_rank() == 0) fs::create_symlink("/dev/full", dir / "state.smpm.tmp");
  MPI_Barrier(MPI_COMM_WORLD);
  StateWriter w;
  w.put_part("a", std::vector<double>(1000, 1.0));
  const std::string what = write_error(w, file);
  EXPECT_EQ(what.rfind(file.string() + ": cannot ", 0), 0u) << what;
  EXPECT_EQ(what, mpi_testing::root_string(what)) << "the same message on every rank";
  EXPECT_FALSE(fs::exists(file));
  if (mpi_testing::world_rank() == 0) std::printf("  a full disk: %s\n", what.c_str());
}

// An open that fails on one rank only (a test's fault on the last rank): every rank gets that
// rank's error, no file is left, and no rank keeps a descriptor of the temporary file open (a
// collective open would leave it open on the ranks where it succeeded); the next write works.
TEST(StateRanks, AnOpenFailingOnOneRankLeavesNothingOpen) {
  const int rank = mpi_testing::world_rank(), P = mpi_testing::world_size();
  const fs::path dir = folder("open"), file = dir / "state.smpm";
  StateWriter w;
  w.put_part("a", part_a(rank));
  write_state_collectively(w, file.string(), MPI_COMM_WORLD);  // MPI-IO's own set-up done
  auto descriptors = [] {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator("/proc/self/fd")) n += !e.path().empty();
    return n;
  };
  const std::size_t before = descriptors();
  set_state_write_open_fault(P - 1);
  const std::string what = write_error(w, file);
  set_state_write_open_fault(-1);
  EXPECT_EQ(what, file.string() + ": cannot create state.smpm.tmp: a fault set by a test (rank " +
                      std::to_string(P - 1) + " of " + std::to_string(P) + ")");
  EXPECT_EQ(what, mpi_testing::root_string(what)) << "the same message on every rank";
  EXPECT_EQ(descriptors(), before) << "rank " << rank << " kept a descriptor open";
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_FALSE(fs::exists(file.string() + ".tmp"));
  w.put_part("b", part_b(rank));
  EXPECT_NO_THROW(write_state_collectively(w, file.string(), MPI_COMM_WORLD));
  if (rank == 0) {
    std::vector<std::uint32_t> b;
    StateReader(read_bytes(file), file.string()).get("b", b);
    std::size_t n = 0;
    for (int r = 0; r < P; ++r) n += part_b(r).size();
    EXPECT_EQ(b.size(), n);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A file system without fsync (the temporary file linked to /dev/null, whose fsync fails with
// EINVAL): as on one process, not an error; the write goes through.
TEST(StateRanks, AFileSystemWithoutFsyncIsNoError) {
  const int null = ::open("/dev/null", O_WRONLY);
  ASSERT_GE(null, 0);
  const int synced = ::fsync(null), why = errno;
  ::close(null);
  ASSERT_TRUE(synced != 0 && why == EINVAL) << "fsync of /dev/null is an error EINVAL here";
  const fs::path dir = folder("nosync"), file = dir / "state.smpm";
  if (mpi_testing::world_rank() == 0) fs::create_symlink("/dev/null", dir / "state.smpm.tmp");
  MPI_Barrier(MPI_COMM_WORLD);
  StateWriter w;
  w.put_part("a", part_a(mpi_testing::world_rank()));
  const std::string what = write_error(w, file);
  EXPECT_EQ(what, "") << "a device without fsync is not an error";
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(file)) && fs::read_symlink(file) == "/dev/null")
      << "the link renamed into place";
  MPI_Barrier(MPI_COMM_WORLD);
}

// A temporary file left as a link to a longer file (as a one-process write follows a link and
// truncates its target): the file behind it is cut to the checkpoint's length and reads back.
TEST(StateRanks, ALinkedLongerTemporaryFileIsCutToLength) {
  const fs::path dir = folder("linked"), file = dir / "state.smpm", big = dir / "big";
  if (mpi_testing::world_rank() == 0) {
    std::ofstream(big, std::ios::binary) << std::string(100000, 'x');
    fs::create_symlink(big, dir / "state.smpm.tmp");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  StateWriter w;
  w.put_part("a", part_a(mpi_testing::world_rank()));
  write_state_collectively(w, file.string(), MPI_COMM_WORLD);
  if (mpi_testing::world_rank() == 0) {
    const std::string b = read_bytes(file);
    EXPECT_LT(b.size(), 100000u);
    EXPECT_NO_THROW(StateReader(b, file.string()));
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A plate with a pulse, its layers carrying state (Kelvin-Voigt springs on LK edges; a damping
// band with a stiffness part and a PML band), stepped on the ranks in slabs: the file the
// ranks write holds each rank's particles and layer entries bit for bit, the energy account
// summed, and loads into the same case built on one process.
std::unique_ptr<Solver> plate(bool bands) {
  const double h = 1e-3;
  auto s = std::make_unique<Solver>();
  s->materials.push_back(tungsten());
  s->grid.init(-3 * h, -3 * h, h, 26, 40);
  const double W = 20 * h, H = 34 * h;
  s->seed_rectangle(0, 0, W, H, 2, 0, 0, 0, 0);
  TractionLoad tl;
  tl.layer = s->select_layer("top", 0, W, H, 0, H, 0, 1, h);
  tl.normal = -100e6;
  const double dur = 12 * h / s->materials[0].cd;
  tl.fn = sin2_pulse(dur, 0.5 * dur);
  s->tractions.push_back(tl);
  if (bands) {
    DampingLayer dl;
    dl.layer = s->select_layer("band", 0, 0, H, 0, 0, -1, 0, 5 * h);
    dl.beta0 = 0.3 * h / s->materials[0].cd;
    s->dampers.push_back(dl);
    PmlBand band;
    band.name = "pml";
    band.axis = 1;
    band.side = -1;
    band.width = 5 * h;
    s->pml_bands.push_back(band);
    s->opt.scheme = Scheme::USL;
  } else {
    for (int side = 0; side < 2; ++side) {
      SilentBoundary sb;
      const double x = side ? W : 0;
      sb.layer = s->select_layer(side ? "right" : "left", 0, x, side ? 0 : H, x, side ? H : 0,
                                 side ? 1 : -1, 0, h);
      sb.delta = 10 * h;
      sb.updated_velocity = true;
      s->silents.push_back(sb);
    }
    s->opt.scheme = Scheme::USF;
  }
  s->opt.threads = 1;
  s->dt = 0.3 * h / s->materials[0].cd;
  s->finalize();
  return s;
}

// Block NAME's values by particle id, from the ids block IDS (stride values per entry).
template <class T>
std::map<std::uint32_t, std::vector<T>> by_id(const StateReader& r, const std::string& ids_block,
                                              const std::string& name, std::size_t stride) {
  std::vector<std::uint32_t> ids;
  std::vector<T> v;
  r.get(ids_block, ids);
  r.get(name, v, stride * ids.size());
  std::map<std::uint32_t, std::vector<T>> m;
  for (std::size_t q = 0; q < ids.size(); ++q) {
    EXPECT_TRUE(m.count(ids[q]) == 0) << name << ": id " << ids[q] << " twice";
    m[ids[q]] = std::vector<T>(v.begin() + stride * q, v.begin() + stride * (q + 1));
  }
  return m;
}

long total(long n) {
  MPI_Allreduce(MPI_IN_PLACE, &n, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return n;
}

TEST(StateRanks, SolverPartsHoldEveryParticleAndLayerEntryBitForBit) {
  for (const bool bands : {false, true}) {
    const std::string what = bands ? "damping and PML bands, USL" : "springs, USF updated edges";
    auto s = plate(bands);
    const std::size_t n = s->p.size();
    Distributed d(*s, MPI_COMM_WORLD, 1);
    for (int k = 0; k < 150; ++k) s->step();
    s->update_energies();
    const fs::path file = folder(bands ? "bands" : "springs") / "checkpoint.smpm";
    StateWriter w;
    s->save_state_parts(w, "mpm.");
    write_state_collectively(w, file.string(), MPI_COMM_WORLD);
    const StateReader r(read_bytes(file), file.string());

    // Every particle once, each rank's bit for bit.
    const auto x = by_id<double>(r, "mpm.p.id", "mpm.p.x", 1);
    const auto sxy = by_id<double>(r, "mpm.p.id", "mpm.p.sxy", 1);
    const auto vy = by_id<double>(r, "mpm.p.id", "mpm.p.vy", 1);
    EXPECT_EQ(x.size(), n) << what;
    long same = 0;
    for (std::size_t k = 0; k < s->p.size(); ++k) {
      const auto id = s->p.id[k];
      same += x.count(id) && x.at(id)[0] == s->p.x[k] && sxy.at(id)[0] == s->p.sxy[k] &&
              vy.at(id)[0] == s->p.vy[k];
    }
    EXPECT_EQ(total(same), static_cast<long>(n)) << what << ": particles as the ranks hold them";

    // Every layer entry once, with its particle's id, bit for bit.
    long entries = 0, equal = 0, in_file = 0;
    auto layer = [&](const std::string& name, const BoundaryLayer& L, const std::vector<double>& v,
                     std::size_t stride) {
      const auto m = by_id<double>(r, name + ".ids", name + "." + (stride == 3 ? "sv" : stride == 4 ? "H" : "ux"), stride);
      in_file += static_cast<long>(m.size());
      for (std::size_t q = 0; q < L.idx.size(); ++q) {
        const auto id = s->p.id[L.idx[q]];
        ++entries;
        equal += m.count(id) && std::memcmp(m.at(id).data(), v.data() + stride * q,
                                            stride * sizeof(double)) == 0;
      }
    };
    for (std::size_t k = 0; k < s->silents.size(); ++k)
      layer("mpm.silent" + std::to_string(k), s->silents[k].layer, s->silents[k].ux, 1);
    for (std::size_t k = 0; k < s->dampers.size(); ++k)
      layer("mpm.damper" + std::to_string(k), s->dampers[k].layer, s->dampers[k].sv, 3);
    if (!s->pml_bands.empty()) layer("mpm.pml", s->pml.layer, s->pml.H, 4);
    const long all_entries = total(entries);
    EXPECT_GT(all_entries, 0) << what;
    EXPECT_EQ(total(equal), all_entries) << what << ": layer entries";
    EXPECT_EQ(in_file, all_entries) << what << ": entries in the file";

    // The account over the ranks.
    const Energies e = s->total_energy(), f = r.get<Energies>("mpm.energy");
    EXPECT_EQ(std::memcmp(&e, &f, sizeof e), 0) << what << ": energies";
    EXPECT_GT(f.external_work, 0) << what;

    // One process reads it: the same particles, re-sorted.
    auto one = plate(bands);
    EXPECT_FALSE(one->load_state(r, "mpm."));
    EXPECT_EQ(one->p.size(), n);
    long found = 0;
    for (std::size_t k = 0; k < one->p.size(); ++k)
      found += x.at(one->p.id[k])[0] == one->p.x[k];
    EXPECT_EQ(found, static_cast<long>(n)) << what << ": loaded on one process";
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

}  // namespace
}  // namespace smpm::testing
