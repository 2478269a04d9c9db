// The thread partition of the particle loops (thread_partition.hpp): its ranges, the fields it
// shares, and that a multimaterial contact run gives the same particles on 1, 2 and 3 threads (to
// round-off: only a shared field's sums are split among threads) and bit for bit the same whether
// its parts run on their own threads or on fewer (a nested region), and one-thread steps inside the
// caller's own team of threads give the bits of a serial run. The particle passes' timed
// split (PassSplit) moves to equal measured cost, and the numbers do not depend on where it is.
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/thread_partition.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

using namespace frictherm::mechanics;

namespace {

struct Materials {
  std::vector<std::size_t> begin, end;
  std::vector<int> field;
};

// Materials of the given sizes laid out in order; field -1 marks one without a field.
Materials layout(const std::vector<std::size_t>& sizes, const std::vector<int>& field) {
  Materials m;
  std::size_t k = 0;
  for (std::size_t s : sizes) m.begin.push_back(k), k += s, m.end.push_back(k);
  m.field = field;
  return m;
}

}  // namespace

TEST(ThreadPartition, RangesTileTheParticlesAndBalanceTheFieldedOnes) {
  // A binder-like material between grains, a rigid wall without a field, an empty material.
  const Materials m = layout({300, 40, 1000, 500, 0, 60, 700}, {0, 1, 2, -1, 3, 4, 5});
  const std::size_t n = 2600, weighted = 2100;
  for (int threads : {1, 2, 3, 4, 7}) {
    ThreadPartition p;
    p.build(threads, m.begin, m.end, m.field, 6, n);
    ASSERT_EQ(p.begin.size(), static_cast<std::size_t>(threads) + 1);
    EXPECT_EQ(p.begin.front(), 0u);
    EXPECT_EQ(p.begin.back(), n);
    std::size_t most = 0;
    for (int t = 0; t < threads; ++t) {
      ASSERT_LE(p.begin[t], p.begin[t + 1]);
      std::size_t w = 0;  // fielded particles of thread t
      for (std::size_t j = 0; j < m.begin.size(); ++j)
        if (m.field[j] >= 0) w += std::max(p.lo(t, m.begin[j]), p.hi(t, m.end[j])) - p.lo(t, m.begin[j]);
      most = std::max(most, w);
    }
    // The largest share exceeds the even one by at most the snap (2 % of a share) and rounding.
    const double share = static_cast<double>(weighted) / threads;
    EXPECT_LE(static_cast<double>(most), share * 1.02 + 1.0) << threads << " threads";
    // A field is shared exactly when its material's particles fall in two or more ranges.
    for (std::size_t j = 0; j < m.begin.size(); ++j) {
      if (m.field[j] < 0 || m.end[j] == m.begin[j]) continue;
      int holders = 0;
      for (int t = 0; t < threads; ++t) holders += p.hi(t, m.end[j]) > p.lo(t, m.begin[j]) ? 1 : 0;
      const auto f = static_cast<std::size_t>(m.field[j]);
      const bool listed = std::count(p.shared_fields.begin(), p.shared_fields.end(), m.field[j]) > 0;
      EXPECT_EQ(listed, holders > 1) << "field " << f << ", " << threads << " threads";
      EXPECT_EQ(p.last_thread[f] - p.first_thread[f] + 1, holders);
    }
    if (threads == 1) {
      EXPECT_TRUE(p.shared_fields.empty());
    }
  }
  // A boundary within 2 % of a share of a material's end moves there: 1000 fielded particles on 2
  // threads split at 500, which lies 10 (1 %) before the end of the second material (490..500).
  const Materials near = layout({490, 10, 500}, {0, 1, 2});
  ThreadPartition p;
  p.build(2, near.begin, near.end, near.field, 3, 1000);
  EXPECT_EQ(p.begin[1], 500u);
  EXPECT_TRUE(p.shared_fields.empty());
  const Materials far = layout({200, 600, 200}, {0, 1, 2});
  p.build(2, far.begin, far.end, far.field, 3, 1000);
  EXPECT_EQ(p.begin[1], 500u);  // inside the middle material: its field is shared
  ASSERT_EQ(p.shared_fields.size(), 1u);
  EXPECT_EQ(p.shared_fields[0], 1);
}

// The particles of the second half cost twice as much per particle as those of the first (a grain
// yielding, a binder reading scattered nodes): the split ends where the two threads' seconds are
// equal, on a block boundary, and a rigid material without a field counts for nothing.
TEST(PassSplit, MovesToWhereTheMeasuredCostsAreEqual) {
  const Materials m = layout({1000, 1000, 256}, {0, 1, -1});
  const std::size_t n = 2256;
  auto cost_of = [&](std::size_t k) { return k < 1000 ? 1.0 : k < 2000 ? 2.0 : 0.0; };
  ThreadPartition p;
  p.build(2, m.begin, m.end, m.field, 2, n);
  PassSplit split;
  split.reset(p);
  EXPECT_EQ(split.begin[1] % PassSplit::kBlock, 0u);
  EXPECT_NEAR(static_cast<double>(split.begin[1]), 1000.0, PassSplit::kBlock / 2.0);  // even count to start
  for (int pass = 0; pass < 40; ++pass) {
    for (int t = 0; t < 2; ++t) {
      double seconds = 0.0;
      for (std::size_t k = split.begin[t]; k < split.begin[t + 1]; ++k) seconds += 1e-7 * cost_of(k);
      split.seconds[static_cast<std::size_t>(t)] = seconds;
    }
    split.rebalance(m.begin, m.end, m.field);
    ASSERT_EQ(split.begin.front(), 0u);
    ASSERT_EQ(split.begin.back(), n);
    ASSERT_EQ(split.begin[1] % PassSplit::kBlock, 0u) << "pass " << pass;
  }
  // Equal cost: 1000 + 2 (b − 1000) = 2 (2000 − b) → b = 1250, within a block of the rounding.
  EXPECT_NEAR(static_cast<double>(split.begin[1]), 1250.0, static_cast<double>(PassSplit::kBlock));
  // One pass in which the second thread was descheduled (ten times its time) moves the boundary by
  // less than a sixth of the particles, not to the far end.
  const std::size_t settled = split.begin[1];
  split.seconds[0] = 1e-7 * 1250.0, split.seconds[1] = 10.0 * 1e-7 * 1500.0;
  split.rebalance(m.begin, m.end, m.field);
  EXPECT_GT(split.begin[1], settled);
  EXPECT_LT(split.begin[1] - settled, n / 6);
  // Nothing measured (a thread ran no part): the split stays.
  const std::size_t before = split.begin[1];
  split.seconds[1] = 0.0;
  split.rebalance(m.begin, m.end, m.field);
  EXPECT_EQ(split.begin[1], before);
}

namespace {

// Five elastic blocks, each its own material, colliding with friction (Coulomb μ = 0.3) on a 2D
// grid: ~12,500 particles, enough for three threads (the step uses one per 2,000 particles).
std::unique_ptr<Simulation<2>> colliding_blocks(double gravity = 0.0) {
  SimulationOptions o;
  o.shape = ShapeKind::ugimp;
  o.scheme = UpdateScheme::usl;
  o.gravity = Vec<3>(0.0, -gravity, 0.0);
  auto sim = std::make_unique<Simulation<2>>(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(0.0125), IVec<2>{80, 40}), o);
  ContactOptions c;
  c.default_pair.law = FrictionLaw::coulomb(0.3);
  sim->enable_contact(c);
  struct Block {
    double x0, y0, x1, y1, vx, vy;
  };
  const Block blocks[] = {{0.05, 0.05, 0.30, 0.30, 4.0, 0.5},  {0.31, 0.05, 0.45, 0.25, -2.0, 0.0},
                          {0.46, 0.10, 0.70, 0.40, -1.0, -1.5}, {0.71, 0.05, 0.95, 0.20, -3.0, 1.0},
                          {0.30, 0.32, 0.45, 0.45, 1.5, -3.0}};
  for (const Block& b : blocks) {
    Material m;
    m.name = "block", m.kind = MaterialKind::linear_elastic, m.density = 1200.0, m.youngs_modulus = 2e8,
    m.poisson_ratio = 0.3;
    const int mat = sim->add_material(m);
    sim->add_body("block", *make_box<2>(Vec<2>(b.x0, b.y0), Vec<2>(b.x1, b.y1), mat), 3, Vec<2>(b.vx, b.vy));
  }
  return sim;
}

struct RunResult {
  std::vector<Vec<2>> position, velocity;
  double w1 = 0.0, w2 = 0.0;
  std::size_t particles = 0;
  double external_work = 0.0;
};

RunResult run_colliding_blocks(int steps, double gravity = 0.0) {
  auto sim = colliding_blocks(gravity);
  for (int s = 0; s < steps; ++s) sim->step();
  const auto& p = sim->particles();
  return {p.position, p.velocity, sim->cumulative_frictional_work(HeatingOrder::first),
          sim->cumulative_frictional_work(HeatingOrder::second), p.size(), sim->external_work()};
}

double largest_speed(const RunResult& r) {
  double v = 0.0;
  for (const auto& x : r.velocity) v = std::max(v, x.norm());
  return v;
}

}  // namespace

TEST(ThreadPartition, CollidingBlocksAgreeOnOneTwoAndThreeThreads) {
  constexpr int steps = 150;
  omp_set_num_threads(1);
  const RunResult one = run_colliding_blocks(steps);
  ASSERT_GT(one.particles, 6000u) << "three threads need 6,000 particles";
  ASSERT_GT(one.w2, 0.0) << "the blocks must rub";
  const double v_scale = largest_speed(one);
  for (int threads : {2, 3}) {
    omp_set_num_threads(threads);
    const RunResult r = run_colliding_blocks(steps);
    double dv = 0.0, dx = 0.0;
    for (std::size_t k = 0; k < r.particles; ++k) {
      dv = std::max(dv, (r.velocity[k] - one.velocity[k]).norm());
      dx = std::max(dx, (r.position[k] - one.position[k]).norm());
    }
    std::printf("[partition] %d threads: max |dv|/v_max %.2e, max |dx|/h %.2e, W2 %.12g vs %.12g J\n", threads,
                dv / v_scale, dx / 0.0125, r.w2, one.w2);
    // Only the sums of a field shared between threads are split, and only in their order:
    // differences stay at round-off, far below the 1e-9 the PBX test allows.
    EXPECT_LT(dv, 1e-11 * v_scale) << threads;
    EXPECT_LT(dx, 1e-11 * 0.0125) << threads;
    EXPECT_NEAR(r.w1, one.w1, 1e-11 * one.w1) << threads;
    EXPECT_NEAR(r.w2, one.w2, 1e-11 * one.w2) << threads;
  }
  omp_set_num_threads(1);
}

// Inside an enclosing parallel region the step's regions get one thread each (nesting off), while
// the step still asks for three: each thread then runs all three parts, in the same arithmetic as
// three threads would, so the particles are bit-identical. Under gravity the particle pass's work
// is summed in the split's blocks: the same bits although the runs' timings, and so their splits,
// differ, and although one thread sums three parts where three threads sum one each.
TEST(ThreadPartition, FewerThreadsThanPartsGiveTheSameParticles) {
  constexpr int steps = 40;
  constexpr double gravity = 9.81;
  omp_set_num_threads(3);
  const RunResult three = run_colliding_blocks(steps, gravity);
  ASSERT_NE(three.external_work, 0.0) << "gravity must work on the blocks";
  const int saved_levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  std::vector<RunResult> nested(2);
#pragma omp parallel num_threads(2)
  nested[static_cast<std::size_t>(omp_get_thread_num())] = run_colliding_blocks(steps, gravity);
  omp_set_max_active_levels(saved_levels);
  omp_set_num_threads(1);
  for (const RunResult& r : nested) {
    ASSERT_EQ(r.particles, three.particles);
    for (std::size_t k = 0; k < r.particles; ++k) {
      ASSERT_EQ(r.velocity[k], three.velocity[k]) << k;
      ASSERT_EQ(r.position[k], three.position[k]) << k;
    }
    EXPECT_NEAR(r.w2, three.w2, 1e-12 * three.w2);
    EXPECT_EQ(r.external_work, three.external_work);
  }
}

// Steps asked for one thread inside the caller's own team of two (each of its threads runs a
// simulation of its own): a step's regions run without an OpenMP team only outside any team of two or
// more (parallel_region.hpp). Called directly there, their thread numbers and orphaned `omp for`
// would bind to the caller's team and leave parts of the particles to the other thread; opened as
// regions of one thread, each run gives the bits of a run outside any region.
TEST(ThreadPartition, OneThreadStepsInsideACallersTeamGiveTheSerialBits) {
  constexpr int steps = 40;
  constexpr double gravity = 9.81;
  omp_set_num_threads(1);
  const RunResult serial = run_colliding_blocks(steps, gravity);
  std::vector<RunResult> inside(2);
  int team = 0;
#pragma omp parallel num_threads(2)
  {
    omp_set_num_threads(1);  // this thread's steps: one thread
#pragma omp single
    team = omp_get_num_threads();
    inside[static_cast<std::size_t>(omp_get_thread_num())] = run_colliding_blocks(steps, gravity);
  }
  if (team < 2) GTEST_SKIP() << "the runtime gave the enclosing region one thread";
  for (const RunResult& r : inside) {
    ASSERT_EQ(r.particles, serial.particles);
    for (std::size_t k = 0; k < r.particles; ++k) {
      ASSERT_EQ(r.velocity[k], serial.velocity[k]) << k;
      ASSERT_EQ(r.position[k], serial.position[k]) << k;
    }
    EXPECT_EQ(r.w2, serial.w2);
    EXPECT_EQ(r.external_work, serial.external_work);
  }
}

namespace {

// A slider pressed onto a base and dragged along it over 320 cells: ~640 contact nodes, enough for
// the contact pass to use threads (it needs 256 node groups), all of one material pair.
double sliding_interface_work(int steps) {
  SimulationOptions o;
  o.shape = ShapeKind::ugimp;
  o.scheme = UpdateScheme::usl;
  Simulation<2> sim(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(0.0125), IVec<2>{324, 12}), o);
  ContactOptions c;
  c.default_pair.law = FrictionLaw::coulomb(0.3);
  sim.enable_contact(c);
  Material m;
  m.name = "block", m.kind = MaterialKind::linear_elastic, m.density = 1200.0, m.youngs_modulus = 2e8, m.poisson_ratio = 0.3;
  const int base = sim.add_material(m), slider = sim.add_material(m);
  sim.add_body("base", *make_box<2>(Vec<2>(0.025, 0.025), Vec<2>(4.025, 0.075), base), 2, Vec<2>(0.0, 0.0));
  sim.add_body("slider", *make_box<2>(Vec<2>(0.025, 0.075), Vec<2>(4.025, 0.125), slider), 2, Vec<2>(2.0, -0.5));
  for (int s = 0; s < steps; ++s) sim.step();
  return sim.cumulative_frictional_work(HeatingOrder::second, base, slider);
}

}  // namespace

// The contact pass adds the pair's work in node-group order after its threads have listed it: three
// threads and one thread running the three parts give the same bits (summed per thread and then
// over threads, as before, they differed in the last digits).
TEST(ThreadPartition, PairWorkIsTheSameBitsWhicheverThreadResolvesAGroup) {
  constexpr int steps = 20;
  omp_set_num_threads(3);
  const double three = sliding_interface_work(steps);
  ASSERT_GT(three, 0.0) << "the slider must rub";
  const int saved_levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  double nested = 0.0;
#pragma omp parallel num_threads(2)
  {
    const double w = sliding_interface_work(steps);
    if (omp_get_thread_num() == 0) nested = w;
  }
  omp_set_max_active_levels(saved_levels);
  omp_set_num_threads(1);
  const double one = sliding_interface_work(steps);
  std::printf("[pair work] 3 threads %.17g J, one thread per region %.17g J, 1 thread %.17g J\n", three, nested, one);
  EXPECT_EQ(nested, three);
}

// The thresholds that keep small passes off the team (issue 35, threads-s55): element-wise node loops
// below 2 x kSlotsPerThread slots, contact passes on the particles that reach a contact node.
TEST(ThreadPartition, SmallNodeLoopsAndOneSidedContactRunOnOneThread) {
  EXPECT_EQ(threads_for_slots(2 * kSlotsPerThread - 1, 2), 1);
  EXPECT_EQ(threads_for_slots(2 * kSlotsPerThread, 2), 2);
  EXPECT_EQ(threads_for_slots(100 * kSlotsPerThread, 4), 4);
  EXPECT_EQ(threads_for_slots(3 * kSlotsPerThread, 8), 3);
  EXPECT_EQ(threads_for_slots(0, 2), 1);
  // The 1 mm twin: ~10 % of 16,400 particles reach the interface; a PBX with contact everywhere.
  EXPECT_EQ(threads_for_reach(0.1, 16400, 2), 1);
  EXPECT_EQ(threads_for_reach(0.6, 16400, 2), 2);
  EXPECT_EQ(threads_for_reach(0.0, 100000, 2), 1);
}
