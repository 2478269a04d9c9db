// Mechanics checkpoints (coupling/src/run/checkpoint.cpp, issue 17): a run restored from a checkpoint
// into a simulation rebuilt from the same set-up continues bit-for-bit (positions, velocities,
// stresses, frictional work, time); a write killed before its rename leaves the previous checkpoint
// usable; a checkpoint refuses to restore into a different set-up.
#include "../verification/sliding_block.hpp"

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

namespace {

using namespace frictherm;
using namespace frictherm::verification;
using C = SlidingBlockConstants;
using mechanics::HeatingOrder;

std::string temp_file(const std::string& name) {
  return ::testing::TempDir() + "frictherm_checkpoint_" + name + ".h5";
}

void step_to(mechanics::Simulation<2>& sim, double t) {
  while (sim.time() < t * (1 - 1e-12)) sim.step(t - sim.time());
}

// Exact equality: the restored run must repeat the same floating-point operations.
void expect_identical(const mechanics::Simulation<2>& a, const mechanics::Simulation<2>& b) {
  ASSERT_EQ(a.particles().size(), b.particles().size());
  EXPECT_EQ(a.step_count(), b.step_count());
  EXPECT_EQ(a.time(), b.time());
  long differ = 0;
  for (std::size_t k = 0; k < a.particles().size(); ++k) {
    differ += a.particles().position[k] != b.particles().position[k];
    differ += a.particles().velocity[k] != b.particles().velocity[k];
    differ += a.particles().stress[k] != b.particles().stress[k];
  }
  EXPECT_EQ(differ, 0);
  for (HeatingOrder o : {HeatingOrder::first, HeatingOrder::second})
    EXPECT_EQ(a.cumulative_frictional_work(o), b.cumulative_frictional_work(o));
  EXPECT_EQ(a.external_work(), b.external_work());
  // The energy books' cumulative sums and start (the series' energy balance) survive the resume.
  const mechanics::EnergyBalance ea = a.energy_balance(HeatingOrder::second), eb = b.energy_balance(HeatingOrder::second);
  EXPECT_EQ(ea.initial, eb.initial);
  EXPECT_EQ(ea.rigid_work, eb.rigid_work);
  EXPECT_EQ(ea.damping_work, eb.damping_work);
  EXPECT_EQ(ea.numerical_dissipation(), eb.numerical_dissipation());
}

// The block slides from t ≈ 0.25 tf on; the checkpoint is taken while it slides, the comparison
// 0.15 tf (about a thousand steps) later.
void check_resume(const SlidingBlockSetup& s, const std::string& name) {
  const double tf = C::t_final(), t_checkpoint = 0.45 * tf, t_end = 0.6 * tf;
  const std::string path = temp_file(name);
  int block = 0;
  auto uninterrupted = make_sliding_block(s, block);
  step_to(uninterrupted, t_checkpoint);
  const double W_checkpoint = uninterrupted.cumulative_frictional_work(HeatingOrder::second);
  ASSERT_GT(W_checkpoint, 0.0) << "the block must already slide at the checkpoint";
  coupling::write_mechanics_checkpoint(path, uninterrupted, "{\"scene\": \"" + name + "\"}");
  step_to(uninterrupted, t_end);
  ASSERT_GT(uninterrupted.cumulative_frictional_work(HeatingOrder::second), 1.5 * W_checkpoint);

  auto resumed = make_sliding_block(s, block);
  coupling::read_mechanics_checkpoint(path, resumed);
  EXPECT_EQ(resumed.cumulative_frictional_work(HeatingOrder::second), W_checkpoint);
  EXPECT_EQ(coupling::checkpoint_scene_text(path), "{\"scene\": \"" + name + "\"}");
  step_to(resumed, t_end);
  expect_identical(uninterrupted, resumed);
  std::remove(path.c_str());
}

TEST(Checkpoint, ResumedSlidingBlockEqualsUninterruptedBitForBit) {
  SlidingBlockSetup s;  // the paper's set-up: deformable base fixed at its bottom, edge tractions
  check_resume(s, "paper");
}

TEST(Checkpoint, ResumedRotatedBlockOnRigidBaseEqualsUninterrupted) {
  SlidingBlockSetup s;  // rigid base, loads on the particles, lattice not aligned with the grid
  s.rotated = true;
  s.angle = 0.3;
  s.law = mechanics::FrictionLaw::coulomb(0.2);
  check_resume(s, "rotated");
}

TEST(Checkpoint, KilledWriteKeepsThePreviousCheckpoint) {
  const std::string path = temp_file("killed");
  SlidingBlockSetup s;
  int block = 0;
  auto sim = make_sliding_block(s, block);
  step_to(sim, 0.3 * C::t_final());
  coupling::write_mechanics_checkpoint(path, sim);
  const long steps = sim.step_count();
  // A write killed before its rename leaves a partial "<path>.<pid>.tmp" beside the checkpoint.
  { std::ofstream(path + ".12345.tmp") << "partial HDF5 bytes"; }
  auto restored = make_sliding_block(s, block);
  coupling::read_mechanics_checkpoint(path, restored);
  EXPECT_EQ(restored.step_count(), steps);
  EXPECT_EQ(restored.time(), sim.time());
  // The next write (its own temporary) replaces the checkpoint; the stale partial file is never read.
  sim.step();
  coupling::write_mechanics_checkpoint(path, sim);
  coupling::read_mechanics_checkpoint(path, restored);
  EXPECT_EQ(restored.step_count(), steps + 1);
  std::remove(path.c_str());
  std::remove((path + ".12345.tmp").c_str());
}

TEST(Checkpoint, RefusesADifferentSetUp) {
  const std::string path = temp_file("mismatch");
  SlidingBlockSetup s;
  int block = 0;
  auto sim = make_sliding_block(s, block);
  coupling::write_mechanics_checkpoint(path, sim);
  s.cell = 0.0025;  // four times the particles
  auto other = make_sliding_block(s, block);
  try {
    coupling::read_mechanics_checkpoint(path, other);
    ADD_FAILURE() << "restored a checkpoint into a different set-up";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("particles/position"), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

// Penalty contact (Kakouris 2024): the boundary points and the slip histories (segment, β, l_ms, t_T)
// are part of the state; without them the resumed tangential springs would restart from zero.
TEST(Checkpoint, ResumedPenaltySlidingBlockEqualsUninterruptedBitForBit) {
  SlidingBlockSetup s;
  s.method = mechanics::ContactMethod::penalty;
  check_resume(s, "penalty");
}

}  // namespace

// The runner writes "<output>.checkpoint" during the run (run.checkpoint_interval) and at the end;
// the last one restores the final state into a simulation built from the stored scene text.
TEST(Checkpoint, RunnerWritesTheFinalStateAtTheEnd) {
  const std::string scene_text = R"({
    "dimension": 2,
    "grid": {"lo": [0, 0], "hi": [0.1, 0.05], "cell_size": 0.01},
    "materials": {"soft": {"type": "linear_elastic", "density": 1000, "youngs_modulus": 1e6, "poisson_ratio": 0.3}},
    "bodies": [{"name": "block", "material": "soft", "velocity": [1, 0.5],
                "shape": {"type": "rectangle", "lo": [0.02, 0.01], "hi": [0.06, 0.04]}}],
    "run": {"end_time": 0.004, "threads": 1, "checkpoint_interval": 0.001},
    "output": {"snapshot_count": 2}
  })";
  const coupling::Scene scene = coupling::parse_scene(scene_text);
  coupling::RunOptions o;
  o.output = temp_file("runner");
  o.overwrite = true;  // a fixed name in the temporary folder: a rerun replaces it
  o.quiet = true;
  const coupling::RunResult r = coupling::run_scene(scene, o);
  ASSERT_EQ(r.status, coupling::RunResult::Status::completed);
  const std::string cp = coupling::checkpoint_path(o.output);
  const coupling::Scene stored = coupling::parse_scene(coupling::checkpoint_scene_text(cp));
  auto sim = coupling::build_simulation<2>(stored);
  const auto start = sim->particles().position;
  coupling::read_mechanics_checkpoint(cp, *sim);
  EXPECT_EQ(sim->step_count(), r.steps);
  EXPECT_EQ(sim->time(), r.time);
  // The block moved freely at (1, 0.5) m/s for 4 ms: 4 mm, 2 mm (round-off of the sums only).
  for (std::size_t k = 0; k < start.size(); ++k) {
    EXPECT_NEAR(sim->particles().position[k][0] - start[k][0], 0.004, 1e-12);
    EXPECT_NEAR(sim->particles().position[k][1] - start[k][1], 0.002, 1e-12);
  }
  std::remove(o.output.c_str());
  std::remove(cp.c_str());
}

// examples/sliding_block.json (multimaterial Coulomb contact) run three ways on one thread:
// uninterrupted; stopped after 3000 steps with a
// checkpoint (the block already slides then: asserted); and resumed from that checkpoint to the end. The resumed run's final state and
// frictional work equal the uninterrupted run's bit-for-bit.
TEST(Checkpoint, ResumedRunEqualsUninterruptedRun) {
  const std::string file = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block.json";
  auto run = [&](long max_steps, const std::string& name, const std::string& resume) {
    const coupling::Scene scene = coupling::load_scene(
        file, {{"run.max_steps", std::to_string(max_steps)}, {"run.threads", "1"}});
    coupling::RunOptions o;
    o.output = temp_file(name);
    o.overwrite = true;  // a fixed name in the temporary folder: a rerun replaces it
    o.quiet = true;
    o.checkpoint_wall_interval = 1e9;  // checkpoints on: one at the end
    o.resume_checkpoint = resume;
    const coupling::RunResult r = coupling::run_scene(scene, o);
    auto sim = coupling::build_simulation<2>(scene);
    coupling::read_mechanics_checkpoint(coupling::checkpoint_path(o.output), *sim);
    EXPECT_EQ(sim->step_count(), r.steps);
    return std::make_pair(r, std::move(sim));
  };
  const long never = 1L << 40;
  auto [r_full, full] = run(never, "full", "");
  ASSERT_EQ(r_full.status, coupling::RunResult::Status::completed);
  auto [r_stop, stopped] = run(3000, "stopped", "");
  ASSERT_EQ(r_stop.status, coupling::RunResult::Status::stopped_at_max_steps);
  ASSERT_GT(stopped->cumulative_frictional_work(HeatingOrder::second), 0.0) << "the block must slide before the stop";
  auto [r_resumed, resumed] = run(never, "resumed", coupling::checkpoint_path(temp_file("stopped")));
  ASSERT_EQ(r_resumed.status, coupling::RunResult::Status::completed);
  EXPECT_GT(resumed->cumulative_frictional_work(HeatingOrder::second),
            2.0 * stopped->cumulative_frictional_work(HeatingOrder::second));
  expect_identical(*full, *resumed);
  for (const char* name : {"full", "stopped", "resumed"}) {
    std::remove(temp_file(name).c_str());
    std::remove(coupling::checkpoint_path(temp_file(name)).c_str());
  }
}
