// Checkpoints and resume of decomposed runs (docs/checkpoints.md, "Decomposed runs";
// coupling/src/distributed_run/decomposed_checkpoint.cpp, coupling/app/cli_run_mpi.cpp), on the 2D
// heated sliding block of test_cli_mpirun.cpp (tests/coupling/scenes/decomposed_sliding_block.json)
// run to 10 ms or 3 ms (the block stops on the base by friction after ~1.7 ms), under mpirun -n 2:
//   * Ctrl-C to mpirun after the first checkpoint, then `mpirun -n 2 frictherm resume OUT.h5`: every
//     series column, the /hotspots table, the energy books and every snapshot of every rank file equal
//     an uninterrupted run's bit-for-bit (each rank restores its particles in their swarm order, so
//     every sum runs in the same order), and the books close;
//   * the same 2-rank checkpoint resumed on 4 ranks (the particles redistributed by the swarm's
//     migration, the heat per node copied from its old owner): the series within 1e-9 of each column's
//     largest magnitude (temperatures: of the largest rise) of the uninterrupted 2-rank run, as
//     test_cli_mpirun's decomposed-against-serial bound (the same arithmetic, sums over particles and
//     ranks in another order), the books closed to 1e-9; resumed without mpirun it is refused (exit
//     code 2) naming the rank count, and the checkpoint is left alone;
//   * the ranks killed with SIGKILL at random moments of a run that checkpoints every 20 us (~7 steps,
//     150 checkpoints in all, a sizeable part of its time spent writing them): the checkpoint left
//     always resumes to the uninterrupted run's result.
// Skipped when mpirun is not installed. Labels verification;mpi.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "h5_test_support.hpp"

#include <algorithm>
#include <cmath>
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
constexpr auto mpirun = frictherm::test::mpirun_command;

namespace {

std::string exe() { return std::string("'") + FRICTHERM_EXE + "'"; }


// The block slides until friction stops it (~1.7 ms) and rests: ~330 steps per ms.
std::string scene_args(const std::string& checkpoint_interval, const std::string& end_time, const std::string& extra = "") {
  return std::string(" '") + FRICTHERM_SOURCE_DIR + "/tests/coupling/scenes/decomposed_sliding_block.json' -q" +
         " --set run.end_time=" + end_time + " --set run.checkpoint_interval=" + checkpoint_interval + extra;
}

class CliMpirunCheckpoint : public frictherm::test::MpirunScratchTest {
 protected:
  CliMpirunCheckpoint() : MpirunScratchTest("frictherm_mpirun_ckpt_") {}

  std::string text(const std::string& name) const {
    std::ifstream in(path(name));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  // Every file of the interrupted run (part.*) into the sub-folder `dir`.
  void copy_part_files(const std::string& dir) const {
    fs::create_directory(path(dir));
    for (const auto& e : fs::directory_iterator(path("")))
      if (e.is_regular_file() && e.path().filename().string().rfind("part.", 0) == 0)
        fs::copy_file(e.path(), path(dir + "/" + e.path().filename().string()));
  }

  // The uninterrupted run into full.h5.
  void run_full(const std::string& interval, const std::string& end_time, const std::string& extra = "") {
    const Result r =
        shell(mpirun(2) + " " + exe() + " run" + scene_args(interval, end_time, extra) + " -o '" + path("full.h5") + "'");
    ASSERT_EQ(r.code, 0) << r.output;
  }

  // Starts the run into part.h5 in the background, waits for its first checkpoint, then `stop` ($pid:
  // mpirun's) after `delay` seconds; returns the run's log.
  std::string run_and_stop(const std::string& interval, const std::string& end_time, const std::string& stop,
                           double delay, const std::string& extra = "") {
    const std::string out = path("part.h5");
    const std::string cmd = mpirun(2) + " " + exe() + " run" + scene_args(interval, end_time, extra) + " -o '" + out + "' > '" +
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
  // 30 ms (~10,000 steps): Ctrl-C to mpirun just after the first checkpoint (t = 0.2 ms). mpirun passes
  // it on to the ranks as SIGTERM only after odls_base_sigkill_timeout: measured 1.9–2.0 s after the
  // signal on a machine (3 Dec) where 10 ms, the length this test had, took 2.2 s, so the run ended
  // or was killed first (empty log).
  run_full("2e-4", "3e-2");
  if (HasFatalFailure()) return;
  const std::string log = run_and_stop("2e-4", "3e-2", "kill -INT $pid", 0.0);
  ASSERT_THAT(log, HasSubstr("interrupted by SIG")) << "the run must be stopped before its end";
  EXPECT_THAT(log, HasSubstr("resume with: mpirun -n 2 frictherm resume"));
  const std::vector<double> t = read_doubles(path("part.h5"), "/series/time");
  ASSERT_FALSE(t.empty());
  EXPECT_LT(t.back(), 3e-2);
  std::printf("  interrupted at t = %.6g s after %zu series rows\n", t.back(), t.size());

  // Without mpirun: refused, exit code 2 naming the rank count, nothing written.
  const auto before = fs::last_write_time(path("part.h5.checkpoint"));
  const Result serial = shell(exe() + " resume '" + path("part.h5") + "'");
  EXPECT_EQ(serial.code, 2) << serial.output;
  EXPECT_THAT(serial.output, HasSubstr("written by a decomposed run on 2 ranks: resume it with mpirun -n 2"));
  EXPECT_EQ(fs::last_write_time(path("part.h5.checkpoint")), before);

  // A copy resumed on 4 ranks: the particles migrate to the new owners.
  fs::create_directory(path("four"));
  for (const auto& e : fs::directory_iterator(path("")))
    if (e.is_regular_file() && e.path().filename().string().rfind("part.", 0) == 0)
      fs::copy_file(e.path(), path("four/" + e.path().filename().string()));
  const Result four = shell(mpirun(4) + " " + exe() + " resume '" + path("four/part.h5") + "'");
  ASSERT_EQ(four.code, 0) << four.output;
  EXPECT_THAT(four.output, HasSubstr("written by 2 ranks, resumed on 4: the particles are redistributed"));
  EXPECT_EQ(read_doubles(path("four/part.h5"), "/meta/resumed_from_ranks"), std::vector<double>{2.0});
  // energy_lost reads the books' start kept in every rank file (/mechanics/initial_energy).
  for (const char* c : {"time", "kinetic_energy", "strain_energy", "energy_lost", "momentum_x", "momentum_y",
                        "friction_work_first", "friction_work_second", "heat_delivered", "max_temperature",
                        "hottest_hotspot_temperature"}) {
    const bool temperature = std::string(c).find("temperature") != std::string::npos;
    const std::vector<double> a = read_doubles(path("full.h5"), std::string("/series/") + c);
    const std::vector<double> b = read_doubles(path("four/part.h5"), std::string("/series/") + c);
    ASSERT_EQ(a.size(), b.size()) << c;
    double scale = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (std::isnan(a[k]) || std::isnan(b[k])) {
        EXPECT_EQ(std::isnan(a[k]), std::isnan(b[k])) << c << " row " << k;
        continue;
      }
      scale = std::max(scale, std::fabs(a[k] - (temperature ? 300.0 : 0.0)));
      diff = std::max(diff, std::fabs(a[k] - b[k]));
    }
    EXPECT_LE(diff, 1e-9 * scale) << c;
    std::printf("  4 ranks from the 2-rank checkpoint: %-28s max |difference| %.3g of %.6g\n", c, diff / scale, scale);
  }
  const double w4 = read_doubles(path("four/part.h5"), "/meta/work_received").at(0);
  for (const char* k : {"heat_delivered", "nodal_energy_change", "particle_energy_change"})
    EXPECT_NEAR(read_doubles(path("four/part.h5"), std::string("/meta/") + k).at(0), w4, 1e-9 * w4) << k;
  EXPECT_TRUE(fs::exists(path("four/part.rank3.h5")));

  const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + path("part.h5") + "'");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  expect_equal_results();
}

// Penalty contact (docs/distributed_run.md, "Penalty contact"): the boundary points and the slip
// histories, the same on every rank, are in the global checkpoint file (penalty_contact/). The heated
// block with contact.method penalty (17 points sliding, the penalty heat handed to the heat solve)
// interrupted after its first checkpoint and resumed on 2 ranks equals the uninterrupted run bit for
// bit (every series column, the penalty columns among them); resumed on 3 ranks within 1e-9 of each
// column's scale (measured: ≤ 4.3e-13, the contact counts equal). Without the penalty state in the
// checkpoint (tried by hand) the resumed run starts from the scene's points (the bodies' boundary at
// t = 0) with no slip history and no frequency bound, and (run to 3e-3 s) writes 1004 rows where the
// uninterrupted run writes 992.
TEST_F(CliMpirunCheckpoint, PenaltyContactResumesToTheUninterruptedRun) {
  const std::string penalty = " --set contact.method=penalty";
  // 2e-2 s: mpirun hands its SIGINT on to the ranks only after odls_base_sigkill_timeout (1 s), so a run
  // that ends within a second of its first checkpoint (3e-3 s took 1.2 s) finishes before the signal
  // reaches it; 1e-2 s was stopped at 8.4e-3 s in session 70, too near its end.
  run_full("2e-4", "2e-2", penalty);
  if (HasFatalFailure()) return;
  const std::string log = run_and_stop("2e-4", "2e-2", "kill -INT $pid", 0.0, penalty);
  ASSERT_THAT(log, HasSubstr("interrupted by SIG")) << "the run must be stopped before its end";
  const std::vector<double> t = read_doubles(path("part.h5"), "/series/time");
  ASSERT_FALSE(t.empty());
  std::printf("  interrupted at t = %.6g s after %zu series rows\n", t.back(), t.size());
  copy_part_files("three");  // the interrupted run's files, to resume on 3 ranks too
  const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + path("part.h5") + "'");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  const Result three = shell(mpirun(3) + " " + exe() + " resume '" + path("three/part.h5") + "'");
  ASSERT_EQ(three.code, 0) << three.output;
  for (const char* c : {"time", "step", "dt", "kinetic_energy", "strain_energy", "energy_lost", "momentum_x",
                        "momentum_y", "friction_work_first", "heat_delivered", "max_temperature", "penalty_energy",
                        "penalty_force.base.block", "penalty_contacts.base.block", "penalty_min_gap.base.block",
                        "penalty_contact_length.base.block"}) {
    const std::vector<double> a = read_doubles(path("full.h5"), std::string("/series/") + c);
    const std::vector<double> b = read_doubles(path("part.h5"), std::string("/series/") + c);
    const std::vector<double> b3 = read_doubles(path("three/part.h5"), std::string("/series/") + c);
    ASSERT_GT(a.size(), 10u) << c;
    ASSERT_EQ(a.size(), b.size()) << c;
    ASSERT_EQ(a.size(), b3.size()) << c;
    double scale = 0.0, diff3 = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k], b[k]) << c << " row " << k;
      scale = std::max(scale, std::fabs(a[k] - (std::string(c) == "max_temperature" ? 300.0 : 0.0)));
      diff3 = std::max(diff3, std::fabs(a[k] - b3[k]));
    }
    EXPECT_LE(diff3, 1e-9 * scale) << c;
    std::printf("  %-36s resumed on 2 ranks: equal; on 3 ranks: %.3g of %.6g\n", c, scale > 0 ? diff3 / scale : diff3,
                scale);
  }
  EXPECT_GT(read_doubles(path("full.h5"), "/series/penalty_contacts.base.block").back(), 0.0);
}

TEST_F(CliMpirunCheckpoint, KilledRanksLeaveACheckpointThatResumesToTheUninterruptedRun) {
  run_full("2e-5", "3e-3");
  if (HasFatalFailure()) return;
  std::mt19937 random(20261126);
  std::uniform_real_distribution<double> delay(0.0, 0.5);
  int inside = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    for (const auto& e : fs::directory_iterator(path("")))
      if (e.path().filename().string().rfind("part.", 0) == 0) fs::remove(e.path());
    // SIGKILL to both ranks (mpirun's children), then to mpirun.
    run_and_stop("2e-5", "3e-3", "pkill -KILL -P $pid; kill -KILL $pid", delay(random));
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

// The normal-stress regularisation (contact.regularization, docs/contact.md) resumed: the sliding block
// with Coulomb μ = 0.5 (it slides from ≈ 8.4 ms to its end at 13.4 ms), a checkpoint at 9 ms, SIGUSR1
// right after it (mpirun forwards it at once), so the run stops while sliding and its final checkpoint
// holds every owned node's lagged normal traction σ̃ and the step count that ages it. Resumed on 2
// ranks the series equal the uninterrupted run's bit-for-bit (a resume with σ̃ restarted from the
// instantaneous traction is another arithmetic from the first sliding step); on 3 ranks (σ̃ copied node
// by node from the old owners) within 1e-9 of each column's scale, the decomposed-against-serial bound.
TEST_F(CliMpirunCheckpoint, RegularizedContactResumesToTheUninterruptedRun) {
  const std::string args = std::string(" '") + FRICTHERM_SOURCE_DIR + "/examples/sliding_block.json' -q" +
                           " --set 'contact.pairs[0].law={\"type\":\"coulomb\",\"mu\":0.5}'"
                           " --set 'contact.regularization={\"slip_length\":0.0025,\"time\":5e-5}'"
                           " --set run.checkpoint_interval=9e-3 --set output.series_interval=0";
  const Result full = shell(mpirun(2) + " " + exe() + " run" + args + " -o '" + path("full.h5") + "'");
  ASSERT_EQ(full.code, 0) << full.output;
  const std::string out = path("part.h5");
  shell(mpirun(2) + " " + exe() + " run" + args + " -o '" + out + "' > '" + path("log") + "' 2>&1 & pid=$!; " +
        "for i in $(seq 1 3000); do [ -e '" + out + ".checkpoint' ] && break; sleep 0.01; done; kill -USR1 $pid; " +
        "wait $pid; exit 0");
  ASSERT_THAT(text("log"), HasSubstr("interrupted by SIGUSR1")) << "the run must be stopped before its end";
  const std::vector<double> t = read_doubles(out, "/series/time"), sliding = read_doubles(out, "/series/sliding_nodes");
  ASSERT_FALSE(t.empty());
  std::printf("  interrupted at t = %.6g s with %g sliding nodes\n", t.back(), sliding.back());
  copy_part_files("three");  // the interrupted run's files, to resume on 3 ranks too
  const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + out + "'");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  const Result three = shell(mpirun(3) + " " + exe() + " resume '" + path("three/part.h5") + "'");
  ASSERT_EQ(three.code, 0) << three.output;
  for (const char* c : {"time", "step", "dt", "kinetic_energy", "momentum_x", "friction_work_first",
                        "friction_work_second", "contact_nodes", "sliding_nodes", "mean_displacement_y.block"}) {
    const std::vector<double> a = read_doubles(path("full.h5"), std::string("/series/") + c);
    const std::vector<double> b = read_doubles(out, std::string("/series/") + c);
    const std::vector<double> b3 = read_doubles(path("three/part.h5"), std::string("/series/") + c);
    ASSERT_GT(a.size(), 100u) << c;
    ASSERT_EQ(a.size(), b.size()) << c;
    ASSERT_EQ(a.size(), b3.size()) << c;
    double scale = 0.0, diff3 = 0.0;
    std::size_t unequal = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      unequal += a[k] != b[k];
      scale = std::max(scale, std::fabs(a[k]));
      diff3 = std::max(diff3, std::fabs(a[k] - b3[k]));
    }
    EXPECT_EQ(unequal, 0u) << c << ": rows differing from the uninterrupted run after a 2-rank resume";
    EXPECT_LE(diff3, 1e-9 * scale) << c;
    std::printf("  %-28s resumed on 2 ranks: %zu rows differ; on 3 ranks: %.3g of %.6g\n", c, unequal,
                scale > 0 ? diff3 / scale : diff3, scale);
  }
  EXPECT_GT(read_doubles(path("full.h5"), "/series/sliding_nodes").back(), 0.0) << "the block slides to the end";
}

// A run with a thermal-only continuation (coupling.continuation: 2 ms of conduction alone in 1500
// intervals after the 10 ms of loading, checkpoints every 2 ms, hot spots above a 0.3 K rise: two at the
// end of the loading), stopped by SIGUSR1 in its continuation
// and resumed on 2 ranks: every series column and the /hotspot_fates table equal the uninterrupted run's.
//   * The scene's matrix-free forward-Euler windows: the continuation gathers and assembles afresh from
//     the particles, so the end-of-loading checkpoint (marks/end_of_loading = 1, written just before the
//     continuation starts: the signal follows it) lets the resume rerun the continuation bit for bit.
//   * cvode_bdf windows: the continuation goes on from the last window's assembled problem and end
//     temperatures, which a decomposed checkpoint does not hold, so no end-of-loading checkpoint is
//     written (resumed from one, the hottest temperature had moved by 2 % of the rise and a hot spot's
//     decision time by 0.75 ms); the last checkpoint of the loading (8 ms) stays and the resume reruns
//     the loading's last windows and the continuation bit for bit.
TEST_F(CliMpirunCheckpoint, ContinuationInterruptedResumesToTheUninterruptedRun) {
  const std::string continuation =
      " --set 'coupling.continuation={\"duration\":2e-3,\"intervals\":1500}'"
      " --set 'coupling.hotspots={\"mode\":\"rise\",\"threshold\":0.3}'";
  const std::string cvode = " --set thermal.integrator='\"cvode_bdf\"' --set thermal.linear_solver='\"pcg\"'"
                            " --set thermal.rtol=1e-6 --set thermal.atol=1e-6 --set coupling.window='\"adaptive\"'";
  for (const bool assembled : {false, true}) {
    const std::string extra = continuation + (assembled ? cvode : "");
    for (const auto& e : fs::directory_iterator(path("")))
      if (e.is_regular_file()) fs::remove(e.path());
    run_full("2e-3", "1e-2", extra);
    if (HasFatalFailure()) return;
    // The loading's checkpoints are generations 1-4 (2, 4, 6, 8 ms); the end-of-loading one is 5.
    const std::string wait_for = path(assembled ? "part.h5.checkpoint.4.rank0" : "part.h5.checkpoint.5.rank0");
    const std::string out = path("part.h5");
    // After assembled windows the signal should land in the continuation (after the loading's last
    // checkpoint, at 8 ms): a pause lets the run get there. On an idle machine the run can finish
    // within the pause, so a run that ended uninterrupted is repeated with a shorter one.
    for (const char* pause : {"1", "0.3", "0"}) {
      for (const auto& e : fs::directory_iterator(path("")))
        if (e.is_regular_file() && e.path().filename().string().rfind("part.", 0) == 0) fs::remove(e.path());
      shell(mpirun(2) + " " + exe() + " run" + scene_args("2e-3", "1e-2", extra) + " -o '" + out + "' > '" +
            path("log") + "' 2>&1 & pid=$!; for i in $(seq 1 6000); do [ -e '" + wait_for + "' ] && break; sleep 0.01; done; " +
            (assembled ? std::string("sleep ") + pause + "; " : std::string()) + "kill -USR1 $pid; wait $pid; exit 0");
      if (!assembled || text("log").find("interrupted by SIGUSR1") != std::string::npos) break;
      std::printf("  cvode_bdf windows: the run ended within a %s s pause; again with a shorter one\n", pause);
    }
    ASSERT_THAT(text("log"), HasSubstr("interrupted by SIGUSR1")) << "the run must be stopped before its end";
    const std::vector<double> rows = read_doubles(out, "/series/time"), full = read_doubles(path("full.h5"), "/series/time");
    const std::vector<double> mark = read_doubles(path("part.h5.checkpoint"), "/marks/time"),
                              end_of_loading = read_doubles(path("part.h5.checkpoint"), "/marks/end_of_loading");
    ASSERT_EQ(mark.size(), 1u);
    ASSERT_EQ(end_of_loading.size(), 1u);
    std::printf("  %s windows: stopped at series row %zu of %zu (t = %.6g s); checkpoint at t = %.6g s, end of loading %g\n",
                assembled ? "cvode_bdf" : "forward-Euler", rows.size(), full.size(), rows.empty() ? 0.0 : rows.back(),
                mark[0], end_of_loading[0]);
    EXPECT_EQ(end_of_loading[0], assembled ? 0.0 : 1.0);
    if (!assembled) {
      EXPECT_GT(rows.back(), 1e-2) << "the signal follows the end-of-loading checkpoint: in the continuation";
    }
    const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + out + "'");
    ASSERT_EQ(resumed.code, 0) << resumed.output;
    std::size_t columns = 0;
    for (const std::string& c : frictherm::test::names_in(path("full.h5"), "/series")) {
      const std::vector<double> a = read_doubles(path("full.h5"), "/series/" + c), b = read_doubles(out, "/series/" + c);
      ASSERT_EQ(a.size(), b.size()) << c;
      for (std::size_t k = 0; k < a.size(); ++k)
        ASSERT_TRUE(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k]))) << c << " row " << k;
      ++columns;
    }
    for (const char* c : {"id", "decision_time", "final_peak_temperature", "max_peak_temperature"}) {
      const std::vector<double> a = read_doubles(path("full.h5"), std::string("/hotspot_fates/") + c);
      EXPECT_FALSE(a.empty()) << c << ": the block makes a hot spot";
      EXPECT_EQ(a, read_doubles(out, std::string("/hotspot_fates/") + c)) << c;
    }
    std::printf("  resumed: %zu series columns of %zu rows and the hot-spot fates equal the uninterrupted run's\n",
                columns, full.size());
  }
}

// The sub-cell interface temperature (coupling.interface_temperature) resumed: each rank's checkpoint
// holds the flux histories of its owned heated nodes (the serial InterfaceTemperature::visit_state), so
// the heated sliding block stopped by SIGUSR1 right after its first checkpoint (0.2 ms, while it slides
// and heats) resumes on 2 ranks to the uninterrupted run bit for bit, max_interface_temperature
// included (a history restarted empty gives another interface temperature from the next window on).
// On 3 ranks each heated node's history goes to the node's new owner (decomposed_redistribute.hpp):
// every series column within 1e-9 of its own scale (max_interface_temperature's scale: its rise above
// the 300 K start) and the heat the histories recorded the same to 1e-12 of itself.
TEST_F(CliMpirunCheckpoint, InterfaceTemperatureResumesToTheUninterruptedRun) {
  const std::string extra = " --set coupling.interface_temperature=true";
  run_full("2e-4", "3e-3", extra);
  if (HasFatalFailure()) return;
  const std::string out = path("part.h5");
  shell(mpirun(2) + " " + exe() + " run" + scene_args("2e-4", "3e-3", extra) + " -o '" + out + "' > '" + path("log") +
        "' 2>&1 & pid=$!; for i in $(seq 1 6000); do [ -e '" + out + ".checkpoint' ] && break; sleep 0.01; done; " +
        "kill -USR1 $pid; wait $pid; exit 0");
  ASSERT_THAT(text("log"), HasSubstr("interrupted by SIGUSR1")) << "the run must be stopped before its end";
  const std::vector<double> rows = read_doubles(out, "/series/time");
  ASSERT_FALSE(rows.empty());
  std::printf("  interrupted at t = %.6g s\n", rows.back());
  copy_part_files("three");  // the interrupted run's files, to resume on 3 ranks too
  const Result three = shell(mpirun(3) + " " + exe() + " resume '" + path("three/part.h5") + "'");
  ASSERT_EQ(three.code, 0) << three.output;
  const Result resumed = shell(mpirun(2) + " " + exe() + " resume '" + out + "'");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  const std::vector<double> Tint = read_doubles(path("full.h5"), "/series/max_interface_temperature");
  ASSERT_GT(Tint.size(), 100u);
  double peak = 0.0;  // NaN before the first heat
  for (const double t : Tint)
    if (!std::isnan(t)) peak = std::max(peak, t);
  std::printf("  hottest interface node %.4g K, heat recorded in the histories %.4g J\n", peak,
              read_doubles(path("full.h5"), "/meta/interface_heat_recorded").at(0));
  EXPECT_GT(peak, 300.3) << "the interface heats (the block starts at 300 K)";
  for (const std::string& c : frictherm::test::names_in(path("full.h5"), "/series")) {
    const std::vector<double> a = read_doubles(path("full.h5"), "/series/" + c), b = read_doubles(out, "/series/" + c);
    ASSERT_EQ(a.size(), b.size()) << c;
    for (std::size_t k = 0; k < a.size(); ++k)
      ASSERT_TRUE(a[k] == b[k] || (std::isnan(a[k]) && std::isnan(b[k]))) << c << " row " << k;
  }
  for (const char* k : {"interface_heat_recorded", "work_received", "heat_delivered"})
    EXPECT_EQ(read_doubles(path("full.h5"), std::string("/meta/") + k), read_doubles(out, std::string("/meta/") + k)) << k;
  // Resumed on 3 ranks: the histories redistributed by node.
  const std::string out3 = path("three/part.h5");
  for (const std::string& c : frictherm::test::names_in(path("full.h5"), "/series")) {
    const std::vector<double> a = read_doubles(path("full.h5"), "/series/" + c), b3 = read_doubles(out3, "/series/" + c);
    ASSERT_EQ(a.size(), b3.size()) << c;
    const double base = c == "max_temperature" || c == "max_interface_temperature" ? 300.0 : 0.0;
    double scale = 0.0, diff = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (std::isnan(a[k]) || std::isnan(b3[k])) {
        EXPECT_TRUE(std::isnan(a[k]) && std::isnan(b3[k])) << c << " row " << k;
        continue;
      }
      scale = std::max(scale, std::fabs(a[k] - base));
      diff = std::max(diff, std::fabs(a[k] - b3[k]));
    }
    EXPECT_LE(diff, 1e-9 * scale) << c;
    if (c == "max_interface_temperature" || c == "max_temperature" || c == "heat_delivered")
      std::printf("  %-28s resumed on 3 ranks: %.3g of its scale %.6g\n", c.c_str(), scale > 0 ? diff / scale : diff, scale);
  }
  const double rec = read_doubles(path("full.h5"), "/meta/interface_heat_recorded").at(0);
  EXPECT_NEAR(read_doubles(out3, "/meta/interface_heat_recorded").at(0), rec, 1e-12 * rec);
}

}  // namespace
