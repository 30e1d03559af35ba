// Output files: history CSV round trip, the relative-L2 waveform metric against closed forms,
// and HDF5/XDMF particle snapshots read back through the plain HDF5 C API.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "silentmpm/history.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/output.hpp"
#include "silentmpm/particles.hpp"

namespace fs = std::filesystem;
using namespace smpm;

namespace {

// A fresh, empty directory per test, removed afterwards.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() /
           ("smpm_" + tag + "_" + std::string(info->name()) + "_" +
            std::to_string(static_cast<long long>(::getpid())));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string str(const std::string& leaf) const { return (path / leaf).string(); }
};

std::string slurp(const std::string& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

History sampled(double amplitude, double dt, double t_end) {
  History h;
  h.columns = {"A.sxx"};
  h.data.resize(1);
  for (long k = 0; k * dt <= t_end + 1e-12; ++k) {
    const double t = k * dt;
    h.time.push_back(t);
    h.data[0].push_back(amplitude * std::sin(t));
  }
  return h;
}

std::vector<double> read_doubles(hid_t file, const std::string& name, std::vector<hsize_t>& dims) {
  const hid_t ds = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << name;
  const hid_t space = H5Dget_space(ds);
  const int rank = H5Sget_simple_extent_ndims(space);
  dims.assign(rank, 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  hsize_t total = 1;
  for (auto d : dims) total *= d;
  std::vector<double> v(total);
  EXPECT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
  H5Sclose(space);
  H5Dclose(ds);
  return v;
}

Particles small_set(std::size_t n, double shift) {
  Particles p;
  p.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) + shift;
    p.x[i] = 0.1 * s;
    p.y[i] = -0.2 * s;
    p.x0[i] = 0.1 * static_cast<double>(i);
    p.y0[i] = -0.2 * static_cast<double>(i) + 1e-3;
    p.vx[i] = 1.0 + s;
    p.vy[i] = 2.0 - s;
    p.mass[i] = 3.0 + 0.5 * s;
    p.vol[i] = 1e-4 * (1.0 + s);
    p.sxx[i] = 1e6 * s;
    p.syy[i] = -2e6 * s;
    p.szz[i] = 0.3e6 * s;
    p.sxy[i] = 0.7e6 * s;
    p.eps_p[i] = 1e-3 * s;
    p.id[i] = static_cast<uint32_t>(100 + i);
    p.body[i] = static_cast<uint16_t>(i % 2);
    p.group[i] = 0;
  }
  return p;
}

}  // namespace

TEST(OutputHistory, CsvRoundTrip) {
  TempDir dir("hist");
  const std::string file = dir.str("history.csv");
  const std::vector<std::string> cols = {"A.sxx", "A.vx", "energy.kinetic"};
  std::vector<std::vector<double>> rows;
  std::vector<double> times;
  {
    HistoryWriter w;
    w.open(file, cols);
    for (int k = 0; k < 50; ++k) {
      const double t = 1.234567891e-6 * k;
      const std::vector<double> v = {-3.3e8 * std::sin(0.1 * k) + 1e-3, 0.5 / (k + 1.0),
                                     1.0e-12 * k * k};
      w.row(t, v);
      times.push_back(t);
      rows.push_back(v);
    }
    EXPECT_THROW(w.row(0.0, {1.0}), std::runtime_error);  // wrong number of values
    w.close();
  }
  // Header line is exactly the contract.
  std::ifstream in(file);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "time,A.sxx,A.vx,energy.kinetic");

  const History h = read_history(file);
  ASSERT_EQ(h.columns, cols);
  ASSERT_EQ(h.time.size(), times.size());
  for (std::size_t r = 0; r < times.size(); ++r) {
    EXPECT_NEAR(h.time[r], times[r], 1e-9 * std::abs(times[r]));
    for (std::size_t c = 0; c < cols.size(); ++c)
      EXPECT_NEAR(h.data[c][r], rows[r][c], 1e-9 * std::abs(rows[r][c])) << cols[c];
  }
  EXPECT_EQ(&h.column("A.vx"), &h.data[1]);
  EXPECT_THROW(h.column("B.vx"), std::runtime_error);
}

TEST(OutputHistory, OpenFailureNamesThePath) {
  HistoryWriter w;
  const std::string bad = "/nonexistent_dir_smpm/sub/history.csv";
  try {
    w.open(bad, {"A.sxx"});
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST(HistoryRead, MalformedInputNamesFileAndLine) {
  TempDir dir("histbad");
  const std::string file = dir.str("bad.csv");
  {
    std::ofstream out(file);
    out << "time,A.sxx\n0.0,1.0\n1.0,abc\n";
  }
  try {
    read_history(file);
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file + ":3"), std::string::npos) << msg;
  }
  {
    std::ofstream out(file);
    out << "time,A.sxx\n0.0,1.0,2.0\n";
  }
  try {
    read_history(file);
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file + ":2"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(file);
    out << "t,A.sxx\n0.0,1.0\n";
  }
  EXPECT_THROW(read_history(file), std::runtime_error);
  EXPECT_THROW(read_history(dir.str("missing.csv")), std::runtime_error);
}

TEST(HistoryRelativeL2, ClosedForms) {
  // a = sin t, b = 1.1 sin t on different grids: ||a - b|| / ||b|| = 0.1 / 1.1.
  const History a = sampled(1.0, 0.01, 10.0);
  const History b = sampled(1.1, 0.0037, 10.0);
  EXPECT_NEAR(relative_l2(a, b, "A.sxx", 0.0, 9.5), 0.1 / 1.1, 1e-3);
  // Against itself the difference is exactly zero.
  EXPECT_EQ(relative_l2(a, a, "A.sxx", 0.0, 10.0), 0.0);
  // Same waveform, different grids: only interpolation error remains.
  EXPECT_LT(relative_l2(a, sampled(1.0, 0.0037, 10.0), "A.sxx", 0.5, 9.5), 1e-4);
  // Empty window, zero reference, missing column.
  EXPECT_THROW(relative_l2(a, b, "A.sxx", 20.0, 30.0), std::runtime_error);
  EXPECT_THROW(relative_l2(a, sampled(0.0, 0.01, 10.0), "A.sxx", 0.0, 10.0), std::runtime_error);
  EXPECT_THROW(relative_l2(a, b, "A.vx", 0.0, 10.0), std::runtime_error);
}

// The norm taken over its own window: a = sin t, b = 1.1 sin t. Over [0, pi] the difference is
// 0.1 sin t; normalised by ||b|| over [0, 2 pi] (twice the samples of the same square) the ratio is
// (0.1 / 1.1) / sqrt(2).
TEST(HistoryRelativeL2, NormWindowApart) {
  const History a = sampled(1.0, 0.001, 7.0);
  const History b = sampled(1.1, 0.001, 7.0);
  const double pi = std::acos(-1.0);
  const Difference d = difference(a, b, "A.sxx", 0.0, pi, 0.0, 2 * pi);
  EXPECT_NEAR(d.relative, 0.1 / 1.1 / std::sqrt(2.0), 1e-3);
  EXPECT_NEAR(d.norm_samples, 2.0 * d.samples, 2.0);
  EXPECT_NEAR(d.absolute / d.reference, d.relative, 1e-15);
  // The same window: relative_l2 exactly.
  EXPECT_EQ(difference(a, b, "A.sxx", 0.0, pi, 0.0, pi).relative, relative_l2(a, b, "A.sxx", 0.0, pi));
  // A norm window outside b's span names the file and the window.
  History named = b;
  named.path = "ref/history.csv";
  try {
    difference(a, named, "A.sxx", 0.0, 1.0, 20.0, 30.0);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("norm window [20, 30]"), std::string::npos) << e.what();
  }
  try {
    named.column("A.vx");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("ref/history.csv: no column 'A.vx' (columns: A.sxx)"),
              std::string::npos) << e.what();
  }
}

// The units attribute of a dataset.
std::string units_of(hid_t f, const std::string& path) {
  const hid_t ds = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (ds < 0) return "(no dataset)";
  const hid_t a = H5Aopen(ds, "units", H5P_DEFAULT);
  std::string out = "(no units)";
  if (a >= 0) {
    const hid_t t = H5Aget_type(a);
    std::string buf(H5Tget_size(t), '\0');
    H5Aread(a, t, buf.data());
    out = buf;
    H5Tclose(t);
    H5Aclose(a);
  }
  H5Dclose(ds);
  return out;
}

std::vector<int32_t> read_ints(hid_t f, const std::string& path) {
  const hid_t ds = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
  if (ds < 0) return {};
  const hid_t sp = H5Dget_space(ds);
  std::vector<int32_t> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)));
  H5Dread(ds, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(sp);
  H5Dclose(ds);
  return v;
}

// Every field of a snapshot read back against the particles: vectors and the stress tensor in
// their XDMF shapes, units on every dataset, the layer flags, the XDMF listing each field once
// with its kind; the film block absent when no material has the film model.
TEST(OutputSnapshot, WriteAndReadBack) {
  TempDir dir("snap");
  const std::size_t n = 7;
  const Particles p0 = small_set(n, 0.0), p1 = small_set(n, 0.25);
  const double t0 = 0.0, t1 = 1.5e-5;
  std::vector<uint8_t> layer(n, 0);
  layer[2] = kLayerSilent | kLayerSpring;
  layer[5] = kLayerTraction;
  {
    SnapshotWriter w;
    w.open(dir.path.string());
    w.write(p0, 0, t0, &layer);
    w.write(p1, 123, t1, &layer);
    EXPECT_EQ(w.count(), 2);
    w.close();
  }
  const std::string h5 = dir.str("particles.h5");
  ASSERT_TRUE(fs::exists(h5));
  const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::vector<std::pair<std::string, std::string>> units = {
      {"xyz", "m"},     {"velocity", "m/s"}, {"displacement", "m"}, {"stress", "Pa"},
      {"J2", "Pa^2"},   {"eps_p", "1"},      {"mass", "kg/m"},      {"volume", "m^2"},
      {"body", "1"},    {"id", "1"},         {"state", "1"},        {"layer", "1"}};
  for (int s = 0; s < 2; ++s) {
    const Particles& p = s == 0 ? p0 : p1;
    const std::string g = s == 0 ? "/step_000000000" : "/step_000000123";
    const hid_t grp = H5Gopen2(f, g.c_str(), H5P_DEFAULT);
    ASSERT_GE(grp, 0) << g;
    const hid_t attr = H5Aopen(grp, "time", H5P_DEFAULT);
    ASSERT_GE(attr, 0);
    double t = -1;
    H5Aread(attr, H5T_NATIVE_DOUBLE, &t);
    EXPECT_EQ(t, s == 0 ? t0 : t1);
    H5Aclose(attr);
    H5Gclose(grp);
    for (const auto& [name, u] : units) EXPECT_EQ(units_of(f, g + "/" + name), u) << name;
    EXPECT_LT(H5Lexists(f, (g + "/ubar").c_str(), H5P_DEFAULT), 1) << "film block without a film model";

    std::vector<hsize_t> dims;
    const auto xyz = read_doubles(f, g + "/xyz", dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{n, 3}));
    const auto vel = read_doubles(f, g + "/velocity", dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{n, 3}));
    const auto disp = read_doubles(f, g + "/displacement", dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{n, 3}));
    const auto sig = read_doubles(f, g + "/stress", dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{n, 9}));
    const auto j2 = read_doubles(f, g + "/J2", dims);
    ASSERT_EQ(dims, (std::vector<hsize_t>{n}));
    const auto eps = read_doubles(f, g + "/eps_p", dims);
    const auto mass = read_doubles(f, g + "/mass", dims);
    const auto vol = read_doubles(f, g + "/volume", dims);
    const auto body = read_ints(f, g + "/body");
    const auto lay = read_ints(f, g + "/layer");
    ASSERT_EQ(body.size(), n);
    ASSERT_EQ(lay.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(xyz[3 * i], p.x[i]);
      EXPECT_EQ(xyz[3 * i + 1], p.y[i]);
      EXPECT_EQ(xyz[3 * i + 2], 0.0);
      EXPECT_EQ(vel[3 * i], p.vx[i]);
      EXPECT_EQ(vel[3 * i + 1], p.vy[i]);
      EXPECT_EQ(vel[3 * i + 2], 0.0);
      EXPECT_EQ(disp[3 * i], p.x[i] - p.x0[i]);
      EXPECT_EQ(disp[3 * i + 1], p.y[i] - p.y0[i]);
      EXPECT_EQ(disp[3 * i + 2], 0.0);
      const double want[9] = {p.sxx[i], p.sxy[i], 0, p.sxy[i], p.syy[i], 0, 0, 0, p.szz[i]};
      for (int q = 0; q < 9; ++q) EXPECT_EQ(sig[9 * i + q], want[q]) << "stress " << q;
      EXPECT_EQ(j2[i], j2_of(p.sxx[i], p.syy[i], p.szz[i], p.sxy[i]));
      EXPECT_EQ(eps[i], p.eps_p[i]);
      EXPECT_EQ(mass[i], p.mass[i]);
      EXPECT_EQ(vol[i], p.vol[i]);
      EXPECT_EQ(body[i], static_cast<int32_t>(p.body[i]));
      EXPECT_EQ(lay[i], layer[i]);
    }
  }
  H5Fclose(f);

  // XDMF sidecar: every field once per snapshot with its kind, the count, each time, the units.
  const std::string xdmf = slurp(dir.str("particles.xdmf"));
  ASSERT_FALSE(xdmf.empty());
  EXPECT_NE(xdmf.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(xdmf.find("Polyvertex"), std::string::npos);
  EXPECT_NE(xdmf.find("NumberOfElements=\"" + std::to_string(n) + "\""), std::string::npos);
  EXPECT_NE(xdmf.find("particles.h5:/step_000000000/xyz"), std::string::npos);
  EXPECT_NE(xdmf.find("particles.h5:/step_000000123/xyz"), std::string::npos);
  EXPECT_NE(xdmf.find("<Information Name=\"units\" Value=\"xyz m, velocity m/s,"), std::string::npos);
  EXPECT_NE(xdmf.find("Name=\"velocity\" AttributeType=\"Vector\""), std::string::npos);
  EXPECT_NE(xdmf.find("Name=\"stress\" AttributeType=\"Tensor\""), std::string::npos);
  EXPECT_NE(xdmf.find("Dimensions=\"7 9\""), std::string::npos);
  for (std::size_t k = 1; k < units.size(); ++k) {
    const std::string& name = units[k].first;
    EXPECT_NE(xdmf.find("Name=\"" + name + "\""), std::string::npos) << name;
    EXPECT_NE(xdmf.find("/step_000000123/" + name + "<"), std::string::npos) << name;
  }
  EXPECT_EQ(xdmf.find("ubar"), std::string::npos);
  for (double t : {t0, t1}) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9e", t);
    EXPECT_NE(xdmf.find("Time Value=\"" + std::string(buf) + "\""), std::string::npos) << buf;
  }
}

// output.fields: only the chosen fields are written and listed (positions always); a film
// model's block comes with "film".
TEST(OutputSnapshot, ChosenFieldsOnly) {
  TempDir dir("snapf");
  Particles p = small_set(5, 0.0);
  p.enable_film();
  {
    SnapshotWriter w;
    w.set_fields(snapshot_field("velocity") | snapshot_field("film"));
    w.open(dir.path.string());
    w.write(p, 0, 0.0);
  }
  const hid_t f = H5Fopen(dir.str("particles.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  for (const char* name : {"xyz", "velocity", "normal", "jump_n", "jump_t", "ubar"})
    EXPECT_GT(H5Lexists(f, (std::string("/step_000000000/") + name).c_str(), H5P_DEFAULT), 0) << name;
  for (const char* name : {"displacement", "stress", "J2", "mass", "id", "layer", "state"})
    EXPECT_LT(H5Lexists(f, (std::string("/step_000000000/") + name).c_str(), H5P_DEFAULT), 1) << name;
  H5Fclose(f);
  const std::string xdmf = slurp(dir.str("particles.xdmf"));
  EXPECT_NE(xdmf.find("Name=\"normal\" AttributeType=\"Vector\""), std::string::npos);
  EXPECT_EQ(xdmf.find("Name=\"stress\""), std::string::npos);
  EXPECT_EQ(snapshot_field("velocty"), 0u);
  EXPECT_EQ(snapshot_field_names().size(), 12u);
}

// A snapshot with no particles (every one has left the grid) keeps each dataset's type and
// columns: the float fields stay 64-bit floats with 0 rows (they came out as 32-bit integers
// once, an empty array's null data taken for a field that is not a float).
TEST(OutputSnapshot, EmptySnapshotKeepsEveryDatasetsType) {
  TempDir dir("snap0");
  {
    SnapshotWriter w;
    w.open(dir.path.string());
    w.write(Particles{}, 7, 1e-6);
  }
  const hid_t f = H5Fopen(dir.str("particles.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::vector<std::pair<std::string, int>> floats = {
      {"xyz", 3}, {"velocity", 3}, {"displacement", 3}, {"stress", 9}, {"J2", 1},
      {"eps_p", 1}, {"mass", 1}, {"volume", 1}};
  for (const auto& [name, columns] : floats) {
    const hid_t ds = H5Dopen2(f, ("/step_000000007/" + name).c_str(), H5P_DEFAULT);
    ASSERT_GE(ds, 0) << name;
    const hid_t type = H5Dget_type(ds), space = H5Dget_space(ds);
    EXPECT_EQ(H5Tget_class(type), H5T_FLOAT) << name;
    EXPECT_EQ(H5Tget_size(type), 8u) << name;
    hsize_t dims[2] = {1, 1};
    const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
    EXPECT_EQ(dims[0], 0u) << name;
    EXPECT_EQ(rank == 2 ? static_cast<int>(dims[1]) : 1, columns) << name;
    H5Sclose(space);
    H5Tclose(type);
    H5Dclose(ds);
  }
  H5Fclose(f);
}

TEST(OutputSnapshot, XdmfIsRewrittenAfterEverySnapshot) {
  TempDir dir("snapx");
  SnapshotWriter w;
  w.open(dir.path.string(), "run");
  w.write(small_set(3, 0.0), 5, 1.0);
  const std::string first = slurp(dir.str("run.xdmf"));
  EXPECT_NE(first.find("run.h5:/step_000000005/xyz"), std::string::npos);
  w.write(small_set(4, 0.0), 9, 2.0);  // before close(): a partial run still opens
  const std::string second = slurp(dir.str("run.xdmf"));
  EXPECT_NE(second.find("run.h5:/step_000000009/xyz"), std::string::npos);
  EXPECT_NE(second.find("NumberOfElements=\"4\""), std::string::npos);
  EXPECT_FALSE(fs::exists(dir.str("run.xdmf.tmp")));
  // The flushed file is readable while the writer still holds it open (the writer takes no
  // file lock, so other processes can read it too; inside this process the access property
  // lists must agree on locking).
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl, 0, 1);
#endif
  const hid_t f = H5Fopen(dir.str("run.h5").c_str(), H5F_ACC_RDONLY, fapl);
  H5Pclose(fapl);
  EXPECT_GE(f, 0);
  if (f >= 0) {
    EXPECT_GT(H5Lexists(f, "/step_000000009", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  w.close();
}

// The XDMF grows by one grid per snapshot, written over the closing tags with new ones: after
// every snapshot the file is the whole document, byte for byte what a full rewrite would write
// (xdmf_text()); a snapshot of a step already written replaces it (a full rewrite), and the next
// snapshots append again. The bytes written per snapshot do not depend on how many came before.
TEST(OutputSnapshot, XdmfGrowsByOneGridPerSnapshot) {
  TempDir dir("snapgrow");
  SnapshotWriter w;
  w.open(dir.path.string(), "run");
  std::vector<std::size_t> sizes;
  for (int k = 0; k < 40; ++k) {
    w.write(small_set(3 + k % 4, 0.0), 10 * k, 1e-6 * k);
    const std::string disk = slurp(dir.str("run.xdmf"));
    ASSERT_EQ(disk, w.xdmf_text()) << "after snapshot " << k;
    sizes.push_back(disk.size());
  }
  // Each later snapshot adds the same number of bytes as the one 4 before it (same particle
  // count, same field list): the cost of a snapshot is flat in the number of snapshots.
  for (std::size_t k = 5; k < sizes.size(); ++k)
    EXPECT_EQ(sizes[k] - sizes[k - 1], sizes[k - 4] - sizes[k - 5]) << k;
  w.write(small_set(7, 0.0), 200, 2e-5);  // step 200 again: replaced
  EXPECT_EQ(slurp(dir.str("run.xdmf")), w.xdmf_text());
  EXPECT_EQ(w.count(), 40);
  w.write(small_set(3, 0.0), 400, 4e-5);
  EXPECT_EQ(slurp(dir.str("run.xdmf")), w.xdmf_text());
  EXPECT_EQ(w.count(), 41);
  EXPECT_FALSE(fs::exists(dir.str("run.xdmf.tmp")));
  w.close();
}

TEST(OutputSnapshot, MissingDirectoryThrows) {
  SnapshotWriter w;
  const std::string bad = "/nonexistent_dir_smpm/out";
  try {
    w.open(bad);
    FAIL() << "expected a throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad + "/particles.h5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(w.write(small_set(2, 0.0), 0, 0.0), std::runtime_error);  // not open
}
