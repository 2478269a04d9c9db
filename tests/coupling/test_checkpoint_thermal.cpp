// Checkpoints of thermal runs (issue 17): examples/sliding_block_heating.json shortened (6 ms of
// loading: the block slides from 3.4 ms; 4 ms of conduction alone; hot spots above a 0.1 mK rise),
// one thread, run three ways:
// uninterrupted; stopped mid-sliding (run.max_steps) with its checkpoint; resumed from that checkpoint
// and appended to the stopped result (append_result). The appended result has the uninterrupted run's
// series (every column: energies, frictional work, heat delivered, temperatures, hot spots), hot-spot
// and fate tables row for row and bit for bit, the same end-of-loading checkpoint (byte-equal file:
// particles and coupler state), and its energy books close. A second resume from the uninterrupted
// run's end-of-loading checkpoint reruns only the continuation and repeats it bit for bit (the
// continuation starts a fresh integrator in both). The joined result's XDMF files (particles, reference
// positions, the thermal grid's nodes) list what the uninterrupted run's list.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/result_append.hpp>
#include <frictherm/coupling/results.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <gtest/gtest.h>

#include "result_compare_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

namespace {

using namespace frictherm;

// Named by process: the same test of another build tree, run at the same time on one machine, would
// write the same files in the shared temporary folder.
std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "frictherm_ckpt_thermal_" + std::to_string(getpid()) + "_" + name + ".h5";
}

using frictherm::test::expect_same_xdmf;
using frictherm::test::slurp;

coupling::Scene heating_scene(long max_steps, bool penalty = false, const std::string& integrator = "") {
  std::vector<coupling::SceneOverride> o{{"run.threads", "1"},
                                         {"run.end_time", "0.006"},
                                         {"run.checkpoint_interval", "0.001"},
                                         {"coupling.continuation.duration", "0.004"},
                                         {"coupling.continuation.intervals", "8"},
                                         // 0.1 mK: the shortened sliding warms the interface by ~1 mK
                                         {"coupling.hotspots.threshold", "1e-4"}};
  if (max_steps > 0) o.push_back({"run.max_steps", std::to_string(max_steps)});
  if (penalty) o.push_back({"contact.pairs[0].method", "\"penalty\""});  // Kakouris 2024 on boundary points
  if (!integrator.empty()) o.push_back({"thermal.integrator", "\"" + integrator + "\""});
  return coupling::load_scene(std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block_heating.json", o);
}

coupling::RunResult run(const coupling::Scene& scene, const std::string& output, const std::string& resume = "",
                        const std::string& checkpoint_file = "") {
  coupling::RunOptions o;
  o.output = output;
  o.overwrite = true;  // fixed names in the temporary folder: a rerun replaces them
  o.quiet = true;
  o.resume_checkpoint = resume;
  o.resume_appends = !resume.empty();
  o.checkpoint_file = checkpoint_file;
  o.run_id = "one-run";  // every run here the same result's: checkpoints compare byte for byte
  return coupling::run_scene(scene, o);
}

// Every column of a table equal bit for bit (NaN where the other has NaN: no hot spot yet).
void expect_same_table(const coupling::SeriesTable& a, const coupling::SeriesTable& b, const std::string& what) {
  ASSERT_EQ(a.names, b.names) << what;
  for (std::size_t j = 0; j < a.names.size(); ++j) {
    ASSERT_EQ(a.columns[j].size(), b.columns[j].size()) << what << " rows";
    long differ = 0;
    for (std::size_t r = 0; r < a.columns[j].size(); ++r) {
      const double x = a.columns[j][r], y = b.columns[j][r];
      differ += !(x == y || (std::isnan(x) && std::isnan(y)));
    }
    EXPECT_EQ(differ, 0) << what << " column " << a.names[j];
  }
}

void expect_same_result(const std::string& a, const std::string& b) {
  expect_same_table(coupling::read_series(a), coupling::read_series(b), "series");
  expect_same_table(coupling::read_table(a, "hotspots"), coupling::read_table(b, "hotspots"), "/hotspots");
  expect_same_table(coupling::read_table(a, "hotspot_fates"), coupling::read_table(b, "hotspot_fates"), "/hotspot_fates");
  for (const char* key : {"work_received", "heat_delivered", "nodal_energy_change", "particle_energy_change",
                          "final_time", "steps", "thermal_windows", "thermal_continuation_intervals", "hotspots_seen"})
    EXPECT_EQ(coupling::read_metadata_number(a, key), coupling::read_metadata_number(b, key)) << key;
  EXPECT_EQ(coupling::read_metadata_string(b, "status"), "completed");
  expect_same_xdmf(a, b, true);
}

void check_stopped_and_resumed(bool penalty) {
  const std::string full = temp_file(penalty ? "pfull" : "full"), stopped = temp_file(penalty ? "pstopped" : "stopped"), part = temp_file(penalty ? "ppart" : "part"),
                    joined = temp_file(penalty ? "pjoined" : "joined");
  const coupling::Scene scene = heating_scene(0, penalty);
  ASSERT_EQ(run(scene, full).status, coupling::RunResult::Status::completed);
  // Stopped at step 4500 of 4620: t ≈ 5.85 ms, while the block slides, heats and a hot spot is
  // tracked (asserted); the resumed tracker must keep its id and birth time.
  const coupling::RunResult r_stop = run(heating_scene(4500, penalty), stopped);
  ASSERT_EQ(r_stop.status, coupling::RunResult::Status::stopped_at_max_steps);
  const coupling::CheckpointMarks marks = coupling::checkpoint_marks(coupling::checkpoint_path(stopped));
  EXPECT_EQ(marks.step, 4500);
  EXPECT_FALSE(marks.end_of_loading);
  ASSERT_GT(coupling::read_metadata_number(stopped, "work_received"), 0.0) << "the block must slide before the stop";
  ASSERT_GT(coupling::read_table(stopped, "hotspots").columns.at(0).size(), 0u) << "hot spots before the stop";

  const coupling::RunResult r = run(scene, part, coupling::checkpoint_path(stopped), coupling::checkpoint_path(joined));
  ASSERT_EQ(r.status, coupling::RunResult::Status::completed);
  coupling::append_result(stopped, part, marks, joined);
  expect_same_result(joined, full);
  // The end-of-loading checkpoints (particles, coupler, books, marks) are byte-equal files.
  const std::string a = slurp(coupling::checkpoint_path(joined)), b = slurp(coupling::checkpoint_path(full));
  ASSERT_FALSE(b.empty());
  EXPECT_TRUE(a == b) << "end-of-loading checkpoints differ";
  // Energy books (adiabatic edges, no reaction): Σ_p m_p C_v ΔT_p equals the heat delivered. The
  // change is a difference of sums of ~240 J (4.1 g at 200 J/(kg K) and 293 K) over 1500 particles:
  // round-off ~1e-16 × 240 J × 1500 = 4e-11 J, against heat of ~1e-5 J.
  const double q = coupling::read_metadata_number(joined, "heat_delivered");
  EXPECT_GT(q, 1e-7);
  EXPECT_NEAR(coupling::read_metadata_number(joined, "particle_energy_change"), q, 1e-10);
  EXPECT_NEAR(coupling::read_metadata_number(joined, "work_received"), q, 1e-12 * q);
  for (const std::string& f : {full, stopped, part, joined}) {
    std::remove(f.c_str());
    std::remove(coupling::checkpoint_path(f).c_str());
    for (const std::string& x : {coupling::xdmf_path_for(f), coupling::xdmf_reference_path_for(f), coupling::xdmf_nodes_path_for(f)})
      std::remove(x.c_str());
  }
}

TEST(ThermalCheckpoint, StoppedResumedAndAppendedRunEqualsUninterruptedRun) { check_stopped_and_resumed(false); }

// The same with penalty contact between block and base: slip histories, boundary points, pair books
// and contact records (series: penalty force, contacts, minimum gap, contact length) are restored.
TEST(ThermalCheckpoint, PenaltyContactStoppedResumedAndAppendedEqualsUninterrupted) { check_stopped_and_resumed(true); }

void check_continuation_rerun(const std::string& integrator) {
  const std::string full = temp_file("full2" + integrator), part = temp_file("part2" + integrator),
                    joined = temp_file("joined2" + integrator);
  const coupling::Scene scene = heating_scene(0, false, integrator);
  ASSERT_EQ(run(scene, full).status, coupling::RunResult::Status::completed);
  const coupling::CheckpointMarks marks = coupling::checkpoint_marks(coupling::checkpoint_path(full));
  EXPECT_TRUE(marks.end_of_loading) << "a run with a continuation keeps its end-of-loading checkpoint";
  EXPECT_DOUBLE_EQ(marks.time, 0.006);
  ASSERT_EQ(run(scene, part, coupling::checkpoint_path(full), coupling::checkpoint_path(joined)).status,
            coupling::RunResult::Status::completed);
  EXPECT_EQ(coupling::read_series(part).columns.at(0).size(), 8u) << "only the 8 continuation rows are new";
  coupling::append_result(full, part, marks, joined);
  expect_same_result(joined, full);
  for (const std::string& f : {full, part, joined}) {
    std::remove(f.c_str());
    std::remove(coupling::checkpoint_path(f).c_str());
    for (const std::string& x : {coupling::xdmf_path_for(f), coupling::xdmf_reference_path_for(f), coupling::xdmf_nodes_path_for(f)})
      std::remove(x.c_str());
  }
}

TEST(ThermalCheckpoint, ContinuationRerunFromEndOfLoadingEqualsUninterruptedRun) { check_continuation_rerun(""); }

// The scene default "auto": the loading's last windows are matrix-free gathers (no assembled K), so
// the checkpointed system is not the one the restored particles assemble (on 71b95b2 a continuation
// from such a checkpoint could fail: "temperature vector has 129 entries for 138 nodes" on a small
// sliding block); the rerun reassembles as the uninterrupted run does and repeats it bit for bit.
TEST(ThermalCheckpoint, ContinuationRerunAfterMatrixFreeWindowsEqualsUninterruptedRun) {
  check_continuation_rerun("auto");
}

}  // namespace
