// Every XDMF output read back by a second reader, meshio (Debian's python3-meshio, installed by
// scripts/setup.sh): a hybrid run's particles.xdmf (Polyvertex grids with their connectivity)
// and fem.xdmf (declared XDMF 3) open, with the particle, node and cell counts of summary.json,
// the same snapshot times in both files, and the particles' mass summing to the bodies' mass.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "silentmpm/case.hpp"
#include "silentmpm/driver.hpp"
#include "test_restart_common.hpp"

namespace smpm {
namespace {

using namespace restart_testing;

TEST(OutputReaders, MeshioReadsParticleAndFemSnapshots) {
  if (std::system("/usr/bin/python3 -c 'import meshio' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-meshio is not installed (scripts/setup.sh installs it)";
  json c = hybrid_case_testing::plate_case("hybrid");
  c["output"]["snapshots"] = 3;
  const std::string file = write_case("readers_hybrid", c);
  const fs::path out = scratch() / "readers_out";
  fs::remove_all(out);
  Case cs = load_case(file);
  double mass = 0;
  for (double m : cs.solver->p.mass) mass += m;
  run_case(cs, out.string());
  const json s = json::parse(read_file(out / "summary.json"));

  const fs::path script = scratch() / "readers.py", result = scratch() / "readers.txt";
  std::ofstream(script) << R"(import sys, meshio
d = sys.argv[1]
with open(sys.argv[2], 'w') as out:
    for name in ('particles', 'fem'):
        with meshio.xdmf.TimeSeriesReader(d + '/' + name + '.xdmf') as r:
            pts, cells = r.read_points_cells()
            out.write('%s %d %d %s %d\n' % (name, len(pts), sum(len(c.data) for c in cells),
                                             cells[0].type, r.num_steps))
            for k in range(r.num_steps):
                t, pd, cd = r.read_data(k)
                if name == 'particles':
                    sg = pd['stress']
                    out.write('%s_step %.9e %.17g %d %d %d %.17g\n' % (
                        name, t, pd['mass'].sum(), pd['velocity'].shape[1],
                        pd['displacement'].shape[1], sg.shape[1],
                        abs(sg[:, 1] - sg[:, 3]).max() + abs(sg[:, [2, 5, 6, 7]]).max()))
                else:
                    out.write('%s_step %.9e %.17g\n' % (name, t, pd['displacement'].shape[1]))
)";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script.string() + " " + out.string() + " " +
                         result.string()).c_str()),
            0);
  std::ifstream in(result);
  std::string name, type;
  long points = 0, ncells = 0, steps = 0;
  in >> name >> points >> ncells >> type >> steps;
  EXPECT_EQ(name, "particles");
  EXPECT_EQ(points, s["particles"].get<long>());
  EXPECT_EQ(ncells, points);
  EXPECT_EQ(type, "vertex");
  EXPECT_EQ(steps, s["outputs"]["snapshots"].get<long>());
  std::vector<double> tp, tf;
  for (long k = 0; k < steps; ++k) {
    std::string tag;
    double t, m, asym;
    int vel, disp, sig;
    in >> tag >> t >> m >> vel >> disp >> sig >> asym;
    tp.push_back(t);
    EXPECT_NEAR(m, mass, 1e-12 * mass) << "snapshot " << k;
    // The same kinds as the FE file: 3-vectors; the stress a symmetric 3 x 3 tensor, plane.
    EXPECT_EQ(vel, 3);
    EXPECT_EQ(disp, 3);
    EXPECT_EQ(sig, 9);
    EXPECT_EQ(asym, 0.0);
  }
  long fsteps = 0;
  in >> name >> points >> ncells >> type >> fsteps;
  EXPECT_EQ(name, "fem");
  EXPECT_EQ(points, s["fem"]["nodes"].get<long>());
  EXPECT_EQ(ncells, s["fem"]["cells"].get<long>());
  EXPECT_EQ(type, "quad");
  EXPECT_EQ(fsteps, steps);
  for (long k = 0; k < fsteps; ++k) {
    std::string tag;
    double t, comps;
    in >> tag >> t >> comps;
    tf.push_back(t);
    EXPECT_EQ(comps, 3);  // displacement as a 3-vector (z = 0)
  }
  EXPECT_EQ(tp, tf) << "the particle and FE snapshots must carry the same times";
}

// output.grid: the MPM grid's snapshots (grid.xdmf) open in meshio with one node per grid node and
// one quad per cell, at the particle snapshots' times, and every snapshot's nodal mass sums to
// the particles' mass (the projection's partition of unity).
TEST(OutputReaders, MeshioReadsGridSnapshots) {
  if (std::system("/usr/bin/python3 -c 'import meshio' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-meshio is not installed (scripts/setup.sh installs it)";
  json c = hybrid_case_testing::plate_case("hybrid");
  c["output"]["snapshots"] = 3;
  c["output"]["grid"] = true;
  const std::string file = write_case("readers_grid", c);
  const fs::path out = scratch() / "readers_grid_out";
  fs::remove_all(out);
  Case cs = load_case(file);
  double mass = 0;
  for (double m : cs.solver->p.mass) mass += m;
  const long nodes = static_cast<long>(cs.solver->grid.nodes());
  const long cells = static_cast<long>(cs.solver->grid.nx) * cs.solver->grid.ny;
  run_case(cs, out.string());
  const fs::path script = scratch() / "readers_grid.py", result = scratch() / "readers_grid.txt";
  std::ofstream(script) << R"(import sys, meshio
d = sys.argv[1]
with open(sys.argv[2], 'w') as out:
    with meshio.xdmf.TimeSeriesReader(d + '/grid.xdmf') as r:
        pts, cells = r.read_points_cells()
        out.write('%d %d %s %d\n' % (len(pts), sum(len(c.data) for c in cells), cells[0].type, r.num_steps))
        for k in range(r.num_steps):
            t, pd, cd = r.read_data(k)
            out.write('%.9e %.17g %d %d\n' % (t, pd['mass'].sum(), pd['velocity'].shape[1], pd['stress'].shape[1]))
    with meshio.xdmf.TimeSeriesReader(d + '/particles.xdmf') as r:
        r.read_points_cells()
        for k in range(r.num_steps):
            out.write('%.9e\n' % r.read_data(k)[0])
)";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script.string() + " " + out.string() + " " +
                         result.string()).c_str()),
            0);
  std::ifstream in(result);
  long points = 0, ncells = 0, steps = 0;
  std::string type;
  in >> points >> ncells >> type >> steps;
  EXPECT_EQ(points, nodes);
  EXPECT_EQ(ncells, cells);
  EXPECT_EQ(type, "quad");
  EXPECT_EQ(steps, 4);  // t = 0 and 3 snapshots
  std::vector<double> tg, tp;
  for (long k = 0; k < steps; ++k) {
    double t, m;
    int v, sig;
    in >> t >> m >> v >> sig;
    tg.push_back(t);
    EXPECT_NEAR(m, mass, 1e-12 * mass) << "snapshot " << k;
    EXPECT_EQ(v, 3);
    EXPECT_EQ(sig, 9);
  }
  for (long k = 0; k < steps; ++k) {
    double t;
    in >> t;
    tp.push_back(t);
  }
  EXPECT_EQ(tg, tp) << "grid and particle snapshots at the same times";
}

// ParaView's default reader for .xdmf (Xdmf3ReaderS in 5.11) on a hybrid run's three files:
// particles with one vertex cell each, the FE mesh, the MPM grid; every snapshot listed, the same
// last time in the three, the fields with their components. Runs where ParaView's pvbatch is
// installed (Debian's paraview and python3-paraview; not by scripts/setup.sh: it is large), and is
// skipped elsewhere.
TEST(OutputReaders, ParaViewOpensEveryOutput) {
  if (std::system("test -x /usr/bin/pvbatch && /usr/bin/pvbatch --version >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "ParaView's pvbatch is not installed";
  json c = hybrid_case_testing::plate_case("hybrid");
  c["output"]["snapshots"] = 3;
  c["output"]["grid"] = true;
  const std::string file = write_case("paraview_hybrid", c);
  const fs::path out = scratch() / "paraview_out";
  fs::remove_all(out);
  Case cs = load_case(file);
  const long particles = static_cast<long>(cs.solver->p.size());
  const long nodes = static_cast<long>(cs.solver->grid.nodes());
  const long cells = static_cast<long>(cs.solver->grid.nx) * cs.solver->grid.ny;
  run_case(cs, out.string());
  const json s = json::parse(read_file(out / "summary.json"));
  const fs::path script = scratch() / "pv_readers.py", result = scratch() / "pv_readers.txt";
  std::ofstream(script) << R"(import sys
from paraview.simple import OpenDataFile, UpdatePipeline, servermanager
d, res = sys.argv[1], sys.argv[2]
with open(res, 'w') as out:
    for name in ('particles', 'fem', 'grid'):
        r = OpenDataFile(d + '/' + name + '.xdmf')
        times = list(r.TimestepValues)
        UpdatePipeline(time=times[-1], proxy=r)
        b = servermanager.Fetch(r)
        pd = b.GetPointData()
        arrays = ','.join(sorted('%s:%d' % (pd.GetArrayName(i), pd.GetArray(i).GetNumberOfComponents())
                                 for i in range(pd.GetNumberOfArrays())))
        out.write('%s %s %d %d %d %.9e %s\n' % (name, r.GetXMLName(), b.GetNumberOfPoints(),
                                                 b.GetNumberOfCells(), len(times), times[-1], arrays))
)";
  ASSERT_EQ(std::system(("cd \"" + scratch().string() + "\" && /usr/bin/pvbatch " +
                         script.string() + " " + out.string() + " " + result.string() +
                         " >/dev/null 2>&1").c_str()),
            0);
  std::ifstream in(result);
  struct Expect {
    const char* name;
    long points, cells;
    const char* arrays;
  };
  const Expect expect[] = {
      {"particles", particles, particles,
       "J2:1,body:1,displacement:3,eps_p:1,id:1,layer:1,mass:1,state:1,stress:9,velocity:3,volume:1"},
      {"fem", s["fem"]["nodes"].get<long>(), s["fem"]["cells"].get<long>(),
       "J2:1,displacement:3,stress:9,velocity:3"},
      {"grid", nodes, cells, "J2:1,mass:1,stress:9,velocity:3"}};
  double last = -1;
  for (const Expect& e : expect) {
    std::string name, reader, arrays;
    long points = 0, ncells = 0, steps = 0;
    double t = 0;
    in >> name >> reader >> points >> ncells >> steps >> t >> arrays;
    EXPECT_EQ(name, e.name);
    EXPECT_EQ(reader, "Xdmf3ReaderS") << name;
    EXPECT_EQ(points, e.points) << name;
    EXPECT_EQ(ncells, e.cells) << name;
    EXPECT_EQ(steps, 4) << name;
    EXPECT_EQ(arrays, e.arrays) << name;
    if (last >= 0) {
      EXPECT_EQ(t, last) << name << ": the last snapshot's time";
    }
    last = t;
  }
}

// output.compression: the same run written plain and deflated (level 1) holds the same values
// in every dataset of particles.h5 and fem.h5, the deflated one in shuffled, deflated chunks,
// and meshio reads it through the XDMF.
TEST(OutputReaders, CompressedSnapshotsHoldTheSameValues) {
  if (std::system("/usr/bin/python3 -c 'import meshio, h5py' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-meshio or python3-h5py is not installed (scripts/setup.sh installs them)";
  json c = hybrid_case_testing::plate_case("hybrid");
  c["output"]["snapshots"] = 3;
  fs::path out[2];
  for (int level : {0, 1}) {
    c["output"]["compression"] = level;
    const std::string file = write_case("compressed_" + std::to_string(level), c);
    out[level] = scratch() / ("compressed_out_" + std::to_string(level));
    fs::remove_all(out[level]);
    Case cs = load_case(file);
    run_case(cs, out[level].string());
  }
  const fs::path script = scratch() / "compressed.py", result = scratch() / "compressed.txt";
  std::ofstream(script) << R"(import sys, h5py, numpy, meshio
plain, packed, res = sys.argv[1], sys.argv[2], sys.argv[3]
n = same = deflated = nonempty = 0
for name in ('particles.h5', 'fem.h5'):
    with h5py.File(plain + '/' + name, 'r') as a, h5py.File(packed + '/' + name, 'r') as b:
        def visit(path, obj):
            global n, same, deflated, nonempty
            if not isinstance(obj, h5py.Dataset):
                return
            n += 1
            same += int(path in b and numpy.array_equal(obj[()], b[path][()]))
            if obj.size > 0:
                nonempty += 1
                deflated += int(b[path].compression == 'gzip' and b[path].shuffle and a[path].compression is None)
        a.visititems(visit)
with meshio.xdmf.TimeSeriesReader(packed + '/particles.xdmf') as r:
    pts, cells = r.read_points_cells()
    t, pd, cd = r.read_data(r.num_steps - 1)
    masses = pd['mass'].sum()
with open(res, 'w') as f:
    f.write('%d %d %d %d %d %.17g\n' % (n, same, nonempty, deflated, len(pts), masses))
)";
  ASSERT_EQ(std::system(("/usr/bin/python3 " + script.string() + " " + out[0].string() + " " +
                         out[1].string() + " " + result.string()).c_str()),
            0);
  std::ifstream in(result);
  long n = 0, same = 0, nonempty = 0, deflated = 0, points = 0;
  double mass = 0;
  in >> n >> same >> nonempty >> deflated >> points >> mass;
  EXPECT_GT(n, 20) << "datasets compared";
  EXPECT_EQ(same, n) << "datasets with the same values";
  EXPECT_EQ(deflated, nonempty) << "non-empty datasets stored deflated";
  const json s = json::parse(read_file(out[1] / "summary.json"));
  EXPECT_EQ(points, s["particles"].get<long>());
  EXPECT_GT(mass, 0);
}

}  // namespace
}  // namespace smpm
