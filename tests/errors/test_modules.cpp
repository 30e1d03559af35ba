// The two modules (cases/src/modules.hpp) and HDF5 (output/src/hdf5_lazy.cpp): an MPM case on
// boxes and --help start without gmsh, deal.II or HDF5; a case with a geometry loads gmsh only;
// an FE case loads both modules; the first snapshot loads HDF5. A
// program that cannot find a module says which file it looked for, where, and how to point it
// there, and exits 1 (a case error).
//
// What a process loads is read from the dynamic loader's own account (LD_DEBUG=files, glibc),
// which names every shared library as it is opened.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_common.hpp"

namespace {

namespace fs = std::filesystem;
using namespace smpm::case_testing;
using namespace smpm::cli_testing;

// Runs `exe args` with the environment assignments `env` ("A=1 B=2 ").
Proc run(const std::string& env, const std::string& exe, const std::string& args,
         const std::string& tag) {
  return run_shell(env + "\"" + exe + "\" " + args, "modules_" + tag);
}

bool loaded(const Proc& r, const std::string& lib) {
  return r.err.find("file=" + lib) != std::string::npos;
}

TEST(Modules, EachCommandLoadsOnlyWhatItsCaseNeeds) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  const fs::path box = write_file("modules_box.json", kValid);
  struct Expect {
    std::string tag, args;
    bool gmsh, fe, hdf5;
  };
  const std::string box_run =
      "run \"" + box.string() + "\" --out \"" + (scratch() / "modules_box_out").string() + "\" -q";
  const Expect cases[] = {
      {"help", "--help", false, false, false},
      {"box", "check \"" + box.string() + "\"", false, false, false},
      {"box_run", box_run, false, false, false},
      // A snapshot loads HDF5 (and the MPI libraries it links), nothing else.
      {"box_snapshot", box_run + " --set output.snapshots=1", false, false, true},
      {"geometry", "check \"" + source_file("studies/film/cases/fixed.json") + "\"", true, false, false},
      // deal.II links HDF5.
      {"fem", "check \"" + source_file("studies/pulse/cases/shear_fem_dashpot.json") + "\"", true, true,
       true},
      {"hybrid", "check \"" + source_file("studies/hybrid/cases/film_hybrid_dashpot.json") + "\"", true,
       true, true},
  };
  for (const Expect& e : cases) {
    const Proc r = run("LD_DEBUG=files ", SMPM_CLI, e.args, e.tag);
    EXPECT_EQ(r.status, 0) << e.tag << ":\n" << r.err.substr(r.err.size() > 2000 ? r.err.size() - 2000 : 0);
    EXPECT_EQ(loaded(r, "libgmsh.so"), e.gmsh) << e.tag;
    EXPECT_EQ(loaded(r, "libdeal.ii.so"), e.fe) << e.tag;
    // The modules themselves are opened by path.
    EXPECT_EQ(r.err.find("libsilentmpm_gmsh.so") != std::string::npos, e.gmsh) << e.tag;
    EXPECT_EQ(r.err.find("libsilentmpm_fe.so") != std::string::npos, e.fe) << e.tag;
    EXPECT_EQ(r.err.find("libhdf5_openmpi.so") != std::string::npos, e.hdf5) << e.tag;
    EXPECT_EQ(loaded(r, "libmpi.so"), e.hdf5) << e.tag;
  }
}

TEST(Modules, AProgramWithoutItsModulesSaysWhereItLooked) {
  if (!have_cli()) GTEST_SKIP() << "CLI binary not built: " << SMPM_CLI;
  // The program alone in a folder of its own: its modules are not beside it.
  const fs::path bin = scratch() / "modules_bin";
  fs::create_directories(bin);
  const fs::path exe = bin / "silentmpm";
  fs::copy_file(SMPM_CLI, exe, fs::copy_options::overwrite_existing);
  const std::string fem = source_file("studies/pulse/cases/shear_fem_dashpot.json");

  // An MPM case on boxes needs no module.
  const fs::path box = write_file("modules_box2.json", kValid);
  EXPECT_EQ(run("", exe.string(), "check \"" + box.string() + "\"", "alone_box").status, 0);

  const Proc r = run("SILENTMPM_MODULE_DIR= ", exe.string(), "check \"" + fem + "\"", "alone_fem");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("shear_fem_dashpot.json: fem: the far field's module: libsilentmpm_fe.so "
                       "not found (looked for " + (bin / "libsilentmpm_fe.so").string()),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("set SILENTMPM_MODULE_DIR"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line:\n" << r.err;

  const Proc g = run("SILENTMPM_MODULE_DIR= ", exe.string(),
                    "check \"" + source_file("studies/film/cases/fixed.json") + "\"", "alone_geo");
  EXPECT_EQ(g.status, 1);
  EXPECT_NE(g.err.find("geometry.file: the gmsh module: libsilentmpm_gmsh.so not found"),
            std::string::npos) << g.err;

  // Pointed at the folder of the modules, it runs.
  const std::string dir = fs::path(SMPM_CLI).parent_path().string();
  const Proc ok = run("SILENTMPM_MODULE_DIR=\"" + dir + "\" ", exe.string(), "check \"" + fem + "\"",
                     "alone_fem_dir");
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(ok.out.find("FEM: "), std::string::npos) << ok.out;
}

}  // namespace
