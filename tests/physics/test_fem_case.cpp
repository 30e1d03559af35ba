// An FEM case through the same interface as MPM (case file -> run_case): history.csv with the
// probe fields (div and curl included), summary.json with dofs and the energy terms, and the
// HDF5 + XDMF snapshots. The physics asserted: a step load on a roller column reaches the
// uniaxial-strain plateau sigma_xx = -sigma0, sigma_yy = nu/(1-nu) sigma_xx, div u = -sigma0/M,
// v_x = sigma0/(rho c_d); the energy balance closes. The snapshots' nodal stresses (computed
// through each cell's bilinear map, without deal.II) of a uniform strain on an unstructured mesh
// of skewed quadrilaterals are its closed-form stress at every node, Q1 and Q2 (1e-10 of its
// size; a transposed Jacobian is off by O(1) there).
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fem_common.hpp"
#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "silentmpm/history.hpp"
#include "silentmpm/material.hpp"

using namespace smpm;
using namespace smpm::fem_testing;
using json = nlohmann::json;

TEST(FemCase, RunsThroughTheDriver) {
  const double h = 1e-3, sigma0 = 50e6;
  const Material w = tungsten();
  json c = json::parse(R"({
    "title": "FEM column",
    "time": {"end": 1.6e-5, "cfl": 0.5},
    "materials": {"tungsten": {"model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000}},
    "fem": {"mesh": "", "size": 0.001, "regions": {"1": "tungsten"},
            "boundaries": [
              {"type": "traction", "name": "load", "curve": "left", "normal": -50e6,
               "time": {"shape": "step", "ramp": 2e-6}},
              {"type": "roller", "curve": ["bottom", "top"], "component": "y"},
              {"type": "dashpot", "name": "end", "curve": 12}]},
    "probes": [{"name": "A", "at": [0.0405, 0.001]},
               {"name": "B", "at": [0.02, 0.0015], "fields": ["div", "curl", "vx"]}],
    "output": {"history_every": 4, "snapshots": 3, "progress": false}
  })");
  c["fem"]["mesh"] = rectangle_geo("case_column", 120 * h, 2 * h, h);
  Case k = build_case(c, "column.json");
  const fs::path out = temp_dir() / "fem_case_run";
  fs::remove_all(out);
  // FE snapshots of an earlier run in the folder (numbered with 5 digits or more) are removed;
  // other files are not touched.
  fs::create_directories(out);
  for (const char* f : {"fem_00009.h5", "fem_100000.h5", "fem_123.h5", "fem_notes.h5"})
    std::ofstream(out / f) << "earlier";
  const RunResult r = run_case(k, out.string());
  EXPECT_FALSE(fs::exists(out / "fem_00009.h5"));
  EXPECT_FALSE(fs::exists(out / "fem_100000.h5"));
  EXPECT_TRUE(fs::exists(out / "fem_123.h5"));
  EXPECT_TRUE(fs::exists(out / "fem_notes.h5"));
  EXPECT_EQ(r.dofs, 2u * 121u * 3u);
  EXPECT_GT(r.dof_updates_per_second, 0);

  // summary.json
  std::ifstream sf(out / "summary.json");
  ASSERT_TRUE(sf.good());
  const json s = json::parse(sf);
  EXPECT_EQ(s["dofs"].get<std::size_t>(), 2u * 121u * 3u);
  EXPECT_EQ(s["fem"]["cells"].get<int>(), 240);
  EXPECT_NEAR(s["cfl"].get<double>(), 0.5, 1e-12);
  const double work = s["energy"]["external_work"];
  EXPECT_GT(work, 0);
  EXPECT_LE(std::abs(s["energy"]["relative_imbalance"].get<double>()), 1e-9);
  // t = 0, every steps/3, and the last step (as the MPM driver does).
  const int snaps = s["outputs"]["snapshots"].get<int>();
  EXPECT_GE(snaps, 4);
  EXPECT_LE(snaps, 5);

  // history.csv: the uniaxial-strain plateau behind the front (A at 40.5 mm, front at 6.8 us + ramp)
  const History hst = read_history((out / "history.csv").string());
  for (const char* col : {"A.sxx", "A.syy", "A.szz", "A.sxy", "A.J2", "A.vx", "A.vy", "A.div",
                          "A.curl", "B.div", "B.curl", "B.vx", "energy.absorbed"})
    EXPECT_NO_THROW(hst.column(col)) << col;
  const std::size_t last = hst.time.size() - 1;
  const double sxx = hst.column("A.sxx")[last], syy = hst.column("A.syy")[last];
  EXPECT_NEAR(sxx, -sigma0, 0.02 * sigma0);
  EXPECT_NEAR(syy, w.nu / (1 - w.nu) * sxx, 0.02 * sigma0 * w.nu / (1 - w.nu));
  EXPECT_NEAR(hst.column("A.div")[last], -sigma0 / w.M, 0.02 * sigma0 / w.M);
  EXPECT_NEAR(hst.column("A.curl")[last], 0.0, 1e-6 * sigma0 / w.M);
  EXPECT_NEAR(hst.column("A.vx")[last], sigma0 / (w.rho * w.cd), 0.02 * sigma0 / (w.rho * w.cd));

  // Snapshots: one fem.h5 (the mesh once, a group per snapshot) listed in fem.xdmf; the last
  // one's nodal stress on the plateau behind the front is the uniaxial-strain state.
  std::ifstream xf(out / "fem.xdmf");
  ASSERT_TRUE(xf.good());
  const std::string x((std::istreambuf_iterator<char>(xf)), std::istreambuf_iterator<char>());
  for (int i = 0; i < snaps; ++i) {
    char name[40];
    std::snprintf(name, sizeof name, "fem.h5:/snapshot_%05d/stress", i);
    EXPECT_NE(x.find(name), std::string::npos) << name;
  }
  for (const char* field : {"displacement\" AttributeType=\"Vector", "velocity\" AttributeType=\"Vector",
                            "stress\" AttributeType=\"Tensor", "J2\" AttributeType=\"Scalar",
                            "material\" AttributeType=\"Scalar\" Center=\"Cell"})
    EXPECT_NE(x.find(std::string("Name=\"") + field + "\""), std::string::npos) << field;
  const hid_t f = H5Fopen((out / "fem.h5").string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  auto read = [&](const std::string& name, std::size_t n) {
    std::vector<double> v(n);
    const hid_t ds = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
    EXPECT_GE(ds, 0) << name;
    if (ds >= 0) {
      EXPECT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << name;
      H5Dclose(ds);
    }
    return v;
  };
  const std::size_t nn = 121u * 3u;
  char last_group[32];
  std::snprintf(last_group, sizeof last_group, "/snapshot_%05d/", snaps - 1);
  const auto xyz = read("/mesh/xyz", 3 * nn);
  const auto sig = read(std::string(last_group) + "stress", 9 * nn);
  const auto j2 = read(std::string(last_group) + "J2", nn);
  H5Fclose(f);
  int plateau = 0;
  for (std::size_t i = 0; i < nn; ++i) {
    const double* S = sig.data() + 9 * i;
    EXPECT_EQ(S[1], S[3]);
    EXPECT_EQ(S[2] + S[5] + S[6] + S[7], 0.0);
    EXPECT_EQ(j2[i], j2_of(S[0], S[4], S[8], S[1]));
    if (xyz[3 * i] < 0.03 || xyz[3 * i] > 0.04) continue;
    ++plateau;
    EXPECT_NEAR(S[0], -sigma0, 0.02 * sigma0) << "node at x = " << xyz[3 * i];
    EXPECT_NEAR(S[4], w.nu / (1 - w.nu) * S[0], 0.02 * sigma0 * w.nu / (1 - w.nu));
  }
  EXPECT_GE(plateau, 30);
  fs::remove_all(out);
}

TEST(FemCase, SnapshotStressOfAUniformStrainOnAnUnstructuredMesh) {
  for (const int degree : {1, 2}) {
    fem::Spec s;
    s.mesh = fem::load_mesh(std::string(SMPM_SOURCE_DIR) + "/meshes/hybrid_film_substrate_unstructured.geo", 0);
    s.degree = degree;
    s.materials = {elastic("steel", 2e11, 0.25, 7800)};
    for (const auto& g : s.mesh.surfaces) s.region_material[g.tag] = 0;
    s.threads = 1;
    fem::Solver f(s);
    const double exx = 1e-3, eyy = -4e-4, exy = 7e-4;  // u = E x (symmetric E: no rotation)
    for (std::size_t i = 0; i < f.nodes(); ++i) {
      const double x = f.node_x()[i], y = f.node_y()[i];
      f.displacement()[2 * i] = exx * x + exy * y;
      f.displacement()[2 * i + 1] = exy * x + eyy * y;
    }
    const Material& m = s.materials[0];
    const double tr = exx + eyy;
    const double want[4] = {m.lambda * tr + 2 * m.mu * exx, m.lambda * tr + 2 * m.mu * eyy,
                            m.lambda * tr, 2 * m.mu * exy};  // xx, yy, zz, xy
    const fs::path dir = temp_dir() / ("uniform_strain_q" + std::to_string(degree));
    fs::create_directories(dir);
    f.write_snapshot(dir.string(), "fem");
    f.close_snapshots();
    const hid_t h = H5Fopen((dir / "fem.h5").string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(h, 0);
    std::vector<double> sig(9 * f.nodes());
    const hid_t ds = H5Dopen2(h, "/snapshot_00000/stress", H5P_DEFAULT);
    ASSERT_GE(ds, 0);
    EXPECT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, sig.data()), 0);
    H5Dclose(ds);
    H5Fclose(h);
    double worst = 0;
    const double scale = std::fabs(want[0]);
    for (std::size_t i = 0; i < f.nodes(); ++i) {
      const double* S = sig.data() + 9 * i;
      for (const auto& [got, w] : {std::pair{S[0], want[0]}, {S[4], want[1]}, {S[8], want[2]}, {S[1], want[3]}})
        worst = std::max(worst, std::fabs(got - w));
    }
    std::printf("  Q%d, %zu nodes: largest stress error %.3e of %.3e\n", degree, f.nodes(), worst, scale);
    EXPECT_LE(worst, 1e-10 * scale);
    fs::remove_all(dir);
  }
}

// The progress line's rate counts the steps alone: with a snapshot every 2 steps, most of the run
// is output, and the line still shows steps / step_seconds (summary.json), well above
// steps / wall_seconds; it also gives the time left.
TEST(FemCase, ProgressRateIsTheSteppingRate) {
  const double h = 1e-3;
  json c = json::parse(R"({
    "time": {"end": 1.6e-5, "cfl": 0.5},
    "materials": {"tungsten": {"model": "elastic", "young": 411e9, "poisson": 0.28, "density": 15000}},
    "fem": {"mesh": "", "size": 0.001, "regions": {"1": "tungsten"},
            "boundaries": [{"type": "traction", "curve": "left", "normal": -50e6}]},
    "output": {"snapshots": 60, "progress": true}
  })");
  c["fem"]["mesh"] = rectangle_geo("progress_column", 120 * h, 2 * h, h);
  Case k = build_case(c, "progress.json");
  const fs::path out = temp_dir() / "fem_progress_run";
  fs::remove_all(out);
  testing::internal::CaptureStderr();
  const RunResult r = run_case(k, out.string());
  const std::string err = testing::internal::GetCapturedStderr();
  const std::size_t at = err.rfind(" steps/s");
  ASSERT_NE(at, std::string::npos) << err;
  const std::size_t from = err.rfind(' ', at - 1);
  const double shown = std::stod(err.substr(from + 1, at - from - 1));
  std::ifstream sf(out / "summary.json");
  const json s = json::parse(sf);
  const double stepping = r.steps / s["step_seconds"].get<double>();
  const double overall = r.steps / s["wall_seconds"].get<double>();
  std::printf("  shown %.0f steps/s, stepping %.0f, overall %.0f\n", shown, stepping, overall);
  EXPECT_NEAR(shown, stepping, 0.01 * stepping + 1);
  EXPECT_GT(stepping, 1.5 * overall);
  EXPECT_NE(err.find("s left"), std::string::npos) << err;
}
