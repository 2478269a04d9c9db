// MPI that cannot corrupt a study (issue 14): a frictherm built without MPI refuses to start as several
// processes under a launcher (the launcher's variables are set by hand here), the MPI build refuses
// every command but ensemble and (with the decomposed engine, test_cli_mpirun.cpp) run, --version names
// the build's features, and a real `mpirun -n 2` ensemble writes the same aggregate as the serial one
// (skipped when mpirun is not installed).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using frictherm::test::read_doubles;
using frictherm::test::Result;
using frictherm::test::shell;

namespace {

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

// A small block moving slowly: a few dozen steps. The ensemble's seed key is the snapshot count, a
// harmless integer that changes each member's steps (snapshot times shorten steps).
using frictherm::test::kTinyScene;

class CliMpi : public frictherm::test::ScratchDirTest {
 protected:
  CliMpi() : ScratchDirTest("frictherm_mpi_") {}
  void SetUp() override {
    ScratchDirTest::SetUp();
    write("tiny.json", kTinyScene);
  }
};

std::string serial_exe() { return std::string("'") + FRICTHERM_SERIAL_EXE + "'"; }
std::string mpi_exe() { return std::string("'") + FRICTHERM_EXE + "'"; }

// mpirun of the MPI frictherm was built with, or "" when there is none (the test is then skipped).
std::string mpirun() {
  const Result which = shell("command -v mpirun");
  if (which.code != 0 || which.output.empty()) return "";
  // 2 processes even on a 1-core machine; waiting ranks yield their core (Open MPI polls busily unless
  // it counts more ranks than slots, and other processes may hold the cores: issue 34), over the
  // single-node transports (FRICTHERM_MPI_TEST_ENVIRONMENT in tests/CMakeLists.txt).
  std::string cmd = "env OMPI_MCA_mpi_yield_when_idle=1 OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader mpirun --oversubscribe";
  if (geteuid() == 0) cmd += " --allow-run-as-root";  // Open MPI refuses root otherwise
  return cmd;
}

}  // namespace

TEST_F(CliMpi, SerialBuildRefusesEveryLauncherWithSeveralProcesses) {
  const std::string scene = path("tiny.json");
  for (const char* env : {"OMPI_COMM_WORLD_SIZE=2", "PMI_SIZE=4", "PMIX_SIZE=3", "MV2_COMM_WORLD_SIZE=2"}) {
    const std::string out = path("run.h5");
    const Result r = shell(std::string("env ") + env + " " + serial_exe() + " run '" + scene + "' -o '" + out + "'");
    EXPECT_EQ(r.code, 2) << env << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr(std::string("started by an MPI launcher as several processes (") + env + ")"));
    EXPECT_THAT(r.output, HasSubstr("built without MPI"));
    EXPECT_FALSE(fs::exists(out)) << env << ": nothing may be written";
  }
  // The ensemble, the command the issue saw corrupted, is refused too.
  const Result e = shell("env OMPI_COMM_WORLD_SIZE=2 OMPI_COMM_WORLD_RANK=0 " + serial_exe() + " ensemble '" + scene +
                         "' --seed-key output.snapshot_count -n 2 -o '" + path("ens.h5") + "'");
  EXPECT_EQ(e.code, 2) << e.output;
  EXPECT_THAT(e.output, HasSubstr("every member of 'ensemble'"));
  EXPECT_FALSE(fs::exists(path("ens.h5")));
  // Only rank 0 explains; a rank > 0 alone (PMIx gives no size) is enough to refuse.
  const Result quiet = shell("env PMIX_RANK=1 " + serial_exe() + " run '" + scene + "' -o '" + path("q.h5") + "'");
  EXPECT_EQ(quiet.code, 2);
  EXPECT_EQ(quiet.output, "");
}

TEST_F(CliMpi, SingleProcessUnderALauncherRuns) {
  const Result r = shell("env OMPI_COMM_WORLD_SIZE=1 OMPI_COMM_WORLD_RANK=0 " + serial_exe() + " run '" +
                         path("tiny.json") + "' -o '" + path("one.h5") + "'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("one.h5")));
}

TEST_F(CliMpi, MpiBuildRefusesCommandsThatDoNotShareWork) {
#ifndef FRICTHERM_TEST_MPI
  GTEST_SKIP() << "frictherm was built without MPI";
#endif
  // `run` and `resume` share their work too when the decomposed engine is built (test_cli_mpirun.cpp,
  // test_cli_mpirun_checkpoint.cpp run them).
  for (const char* cmd : {"continue", "microstructure", "export-csv"}) {
    const Result r = shell(std::string("env PMI_SIZE=2 PMI_RANK=0 ") + mpi_exe() + " " + cmd + " '" + path("tiny.json") + "'");
    EXPECT_EQ(r.code, 2) << cmd << ": " << r.output;
    EXPECT_THAT(r.output, HasSubstr(std::string("every process would run '") + cmd + "' alone and write the same files"));
  }
}

TEST_F(CliMpi, VersionNamesTheBuildsFeatures) {
  for (const std::string& exe : {serial_exe(), mpi_exe()}) {
    const Result r = shell(exe + " --version");
    EXPECT_EQ(r.code, 0);
    EXPECT_THAT(r.output, HasSubstr("frictherm " FRICTHERM_VERSION "\n"));
    for (const char* feature : {"  git commit: ", "  MPI: ", "  OpenMP: 20", "  SUNDIALS: 6.", "  HDF5: 1.", "  Eigen: 3."})
      EXPECT_THAT(r.output, HasSubstr(feature)) << exe;
  }
  EXPECT_THAT(shell(serial_exe() + " --version").output, HasSubstr("  MPI: no"));
#ifdef FRICTHERM_TEST_MPI
  EXPECT_THAT(shell(mpi_exe() + " --version").output, HasSubstr("  MPI: yes, MPI 3."));
#endif
}

TEST_F(CliMpi, MpirunEnsembleMatchesTheSerialOneAndReportsSceneErrorsOnce) {
#ifndef FRICTHERM_TEST_MPI
  GTEST_SKIP() << "frictherm was built without MPI";
#endif
  const std::string launcher = mpirun();
  if (launcher.empty()) GTEST_SKIP() << "mpirun is not installed (Debian: openmpi-bin)";
  const std::string args = " ensemble '" + path("tiny.json") + "' --seed-key output.snapshot_count --first-seed 2 -n 3 --threads 1";
  const Result serial = shell(mpi_exe() + args + " -o '" + path("serial.h5") + "'");
  ASSERT_EQ(serial.code, 0) << serial.output;
  const Result par = shell(launcher + " -n 2 " + mpi_exe() + args + " -o '" + path("par.h5") + "'");
  ASSERT_EQ(par.code, 0) << par.output;
  EXPECT_THAT(par.output, HasSubstr("3 members (3 completed, 2 processes)"));
  EXPECT_EQ(count_of(par.output, "wrote "), 1u) << "only process 0 aggregates";
  // Member k on process k mod 2, each member once: the aggregate equals the serial run's (the members
  // are deterministic, so steps and simulated times agree exactly).
  for (const char* column : {"seed", "status", "steps", "simulated_time", "hotspots"}) {
    const std::string where = std::string("/members/") + column;
    EXPECT_EQ(read_doubles(path("par.h5"), where), read_doubles(path("serial.h5"), where)) << column;
  }
  EXPECT_EQ(read_doubles(path("par.h5"), "/members/seed"), (std::vector<double>{2, 3, 4}));
  for (int seed : {2, 3, 4}) EXPECT_TRUE(fs::exists(path("par_seed" + std::to_string(seed) + ".h5"))) << seed;

  // A scene error: both processes find it, one reports it, the exit code is 2.
  std::ofstream(path("bad.json")) << R"({"dimension": 2, "gird": {}})";
  const Result bad = shell(launcher + " -n 2 " + mpi_exe() + " ensemble '" + path("bad.json") +
                           "' --seed-key output.snapshot_count -n 2 -o '" + path("bad.h5") + "'");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_EQ(count_of(bad.output, "bad.json: "), 1u) << bad.output;
}
