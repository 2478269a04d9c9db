// Checkpoints and resume of decomposed runs (docs/checkpoints.md, "Decomposed runs";
// coupling/src/distributed_run/decomposed_checkpoint.cpp, coupling/app/cli_run_mpi.cpp), on the 2D
// heated sliding block of test_cli_mpirun.cpp (tests/coupling/scenes/decomposed_sliding_block.json)
// run to 3 ms (the block stops on the base by friction after ~1.7 ms), under mpirun -n 2:
//   * Ctrl-C to mpirun after the first checkpoint, then `mpirun -n 2 frictherm resume OUT.h5`: every
//     series column, the /hotspots table, the energy books and every snapshot of every rank file equal
//     an uninterrupted run's bit-for-bit (each rank restores its particles in their swarm order, so
//     every sum runs in the same order), and the books close;
//   * a 2-rank checkpoint resumed on 3 ranks, or without mpirun, is refused (exit code 2) naming the
//     rank counts, and leaves the files alone;
//   * the ranks killed with SIGKILL at random moments of a run that checkpoints every 20 us (~7 steps,
//     150 checkpoints in all, a sizeable part of its time spent writing them): the checkpoint left
//     always resumes to the uninterrupted run's result.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using frictherm::test::read_doubles;
using frictherm::test::Result;
using frictherm::test::shell;

namespace {

std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }

std::string mpirun(int ranks) {
  std::string cmd = "env OMP_NUM_THREADS=1 mpirun --oversubscribe -n " + std::to_string(ranks);
  if (geteuid() == 0) cmd += " --allow-run-as-root";  // Open MPI refuses root otherwise
  return cmd;
}

// The block slides until friction stops it (~1.7 ms) and rests to 3 ms: ~1100 steps.
std::string scene_args(const std::string& checkpoint_interval) {
  return std::string(" '") + FRICTHERM_SOURCE_DIR + "/tests/coupling/scenes/decomposed_sliding_block.json' -q" +
         " --set run.end_time=3e-3 --set run.checkpoint_interval=" + checkpoint_interval;
}

class CliMpirunCheckpoint : public frictherm::test::ScratchDirTest {
 protected:
  CliMpirunCheckpoint() : ScratchDirTest("frictherm_mpirun_ckpt_") {}
  void SetUp() override {
    if (shell("command -v mpirun").code != 0) GTEST_SKIP() << "mpirun is not installed (Debian: openmpi-bin)";
    ScratchDirTest::SetUp();
  }

  std::string text(const std::string& name) const {
    std::ifstream in(path(name));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // The uninterrupted run into full.h5.
  void run_full(const std::string& interval) {
    const Result r = shell(mpirun(2) + " " + exe() + " run" + scene_args(interval) + " -o '" + path("full.h5") + "'");
    ASSERT_EQ(r.code, 0) << r.output;
  }

  // Starts the run into part.h5 in the background, waits for its first checkpoint, then `stop` ($pid:
  // mpirun's) after `delay` seconds; returns the run's log.
  std::string run_and_stop(const std::string& interval, const std::string& stop, double delay) {
    const std::string out = path("part.h5");
    const std::string cmd = mpirun(2) + " " + exe() + " run" + scene_args(interval) + " -o '" + out + "' > '" +
                            path("log") + "' 2>&1 & pid=$!; " + "for i in $(seq 1 1200); do [ -e '" + out +
                            ".checkpoint' ] && break; sleep 0.02; done; sleep " + std::to_string(delay) + "; " + stop +
                            "; wait $pid; exit 0";
    shell(cmd);
    return text("log");
  }

  // part.h5 (resumed) against full.h5: every series column, the /hotspots table and the books
  // bit-for-bit; every snapshot of both rank files too.
  void expect_equal_results() {
    for (const char* c : {"time", "step", "dt", "kinetic_energy", "momentum_x", "momentum_y", "friction_work_first",
                          "friction_work_second", "contact_nodes", "sliding_nodes", "heat_delivered",
                          "thermal_energy_change", "max_temperature", "hotspot_count", "hottest_hotspot_temperature",
                          "thermal_windows", "work_received", "nodal_energy_change"}) {
      const std::vector<double> a = read_doubles(path("full.h5"), std::string("/series/") + c);
      ASSERT_GT(a.size(), 10u) << c;
      const std::vector<double> b = read_doubles(path("part.h5"), std::string("/series/") + c);
      ASSERT_EQ(a.size(), b.size()) << c;
      for (std::size_t k = 0; k < a.size(); ++k)  // NaN (no hot spot) in both, or the same double
        EXPECT_TRUE(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k]))) << c << " row " << k;
    }
    for (const char* c : {"time", "id", "particle_count", "peak_temperature", "centroid_x", "excess_energy"}) {
      const std::vector<double> a = read_doubles(path("full.h5"), std::string("/hotspots/") + c);
      EXPECT_FALSE(a.empty()) << c << ": the block makes hot spots";
      EXPECT_EQ(a, read_doubles(path("part.h5"), std::string("/hotspots/") + c)) << c;
    }
    for (const char* k : {"work_received", "heat_delivered", "nodal_energy_change", "particle_energy_change", "steps",
                           "final_time", "thermal_windows"})
      EXPECT_EQ(read_doubles(path("full.h5"), std::string("/meta/") + k),
                read_doubles(path("part.h5"), std::string("/meta/") + k)) << k;
    // The books close (forward Euler: to the round-off of the sums, 1e-9 of the work as test_cli_mpirun).
    const double w = read_doubles(path("part.h5"), "/meta/work_received").at(0);
    EXPECT_GT(w, 0.1);
    for (const char* k : {"heat_delivered", "nodal_energy_change", "particle_energy_change"})
      EXPECT_NEAR(read_doubles(path("part.h5"), std::string("/meta/") + k).at(0), w, 1e-9 * w) << k;
    for (int r = 0; r < 2; ++r)
      for (int s = 0; s <= 4; ++s) {
        char snap[32];
        std::snprintf(snap, sizeof snap, "/snapshots/%06d/", s);
        const std::string rank = ".rank" + std::to_string(r) + ".h5";
        for (const char* f : {"id", "position", "velocity", "temperature"})
          EXPECT_EQ(read_doubles(path("full" + rank), snap + std::string(f)),
                    read_doubles(path("part" + rank), snap + std::string(f)))
              << rank << snap << f;
      }
    char absent[32];
    std::snprintf(absent, sizeof absent, "/snapshots/%06d/id", 5);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // the dataset is absent: no HDF5 error stack
    EXPECT_TRUE(read_doubles(path("part.rank0.h5"), absent).empty()) << "the snapshot at the interruption is dropped";
    EXPECT_EQ(text("full.xdmf").size(), text("part.xdmf").size());
  }
};

TEST_F(CliMpirunCheckpoint, InterruptedAndResumedRunEqualsTheUninterruptedRun) {
  run_full("2e-4");
  if (HasFatalFailure()) return;
  // Ctrl-C to mpirun (passed on to the ranks as SIGTERM) just after the first checkpoint (t = 0.2 ms).
  const std::string log = run_and_stop("2e-4", "kill -INT $pid", 0.0);
  ASSERT_THAT(log, HasSubstr("interrupted by SIG")) << "the run must be stopped before its end";
  EXPECT_THAT(log, HasSubstr("resume with: mpirun -n 2 frictherm resume"));
  const std::vector<double> t = read_doubles(path("part.h5"), "/series/time");
  ASSERT_FALSE(t.empty());
  EXPECT_LT(t.back(), 3e-3);
  std::printf("  interrupted at t = %.6g s after %zu series rows\n", t.back(), t.size());

  // Refusals of another rank count: exit code 2 naming the counts, nothing written.
  const auto before = fs::last_write_time(path("part.h5.checkpoint"));
  const Result three = shell(mpirun(3) + " " + exe() + " resume '" + path("part.h5") + "'");
  EXPECT_EQ(three.code, 2) << three.output;
  EXPECT_THAT(three.output, HasSubstr("rank count mismatch"));
  EXPECT_THAT(three.output, HasSubstr("written by 2 ranks, this is 3"));
  const Result serial = shell(exe() + " resume '" + path("part.h5") + "'");
  EXPECT_EQ(serial.code, 2) << serial.output;
  EXPECT_THAT(serial.output, HasSubstr("written by a decomposed run on 2 ranks: resume it with mpirun -n 2"));
  EXPECT_EQ(fs::last_write_time(path("part.h5.checkpoint")), before);

  const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + path("part.h5") + "'");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  expect_equal_results();
}

TEST_F(CliMpirunCheckpoint, KilledRanksLeaveACheckpointThatResumesToTheUninterruptedRun) {
  run_full("2e-5");
  if (HasFatalFailure()) return;
  std::mt19937 random(20261126);
  std::uniform_real_distribution<double> delay(0.0, 0.5);
  int inside = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    for (const auto& e : fs::directory_iterator(path("")))
      if (e.path().filename().string().rfind("part.", 0) == 0) fs::remove(e.path());
    // SIGKILL to both ranks (mpirun's children), then to mpirun.
    run_and_stop("2e-5", "pkill -KILL -P $pid; kill -KILL $pid", delay(random));
    ASSERT_TRUE(fs::exists(path("part.h5.checkpoint")));
    // A kill inside a write leaves a temporary or a rank file of a generation the global file does
    // not name yet: count the attempts that did.
    int rank_files = 0;
    bool tmp = false;
    for (const auto& e : fs::directory_iterator(path(""))) {
      const std::string n = e.path().filename().string();
      if (n.rfind("part.h5.checkpoint.", 0) == 0 && n.find(".rank") != std::string::npos) ++rank_files;
      if (n.rfind("part.h5.checkpoint.", 0) == 0 && n.size() > 4 && n.substr(n.size() - 4) == ".tmp") tmp = true;
    }
    if (tmp || rank_files > 2) ++inside;
    const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + path("part.h5") + "'");
    ASSERT_EQ(resumed.code, 0) << resumed.output;
    expect_equal_results();
    if (HasFatalFailure()) return;
  }
  std::printf("  %d of 3 kills landed inside a checkpoint write\n", inside);
}

}  // namespace
