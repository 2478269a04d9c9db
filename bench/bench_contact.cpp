// Contact throughput: particle-steps per second on the Coulomb sliding block (Nairn, Bardenhagen &
// Smith 2018, figure 2) at 5 mm cells (656 particles) and 1 mm cells (16,400 particles), on 1 and 2
// threads, against the same scene run as one material (block and base one velocity field, no
// contact). Prints a table with the contact overhead; asserts nothing.
//   bench_contact [--quick] [--steps N]
// 5 mm: the whole run to t_f (every phase: loading, sticking, sliding). 1 mm: N steps (default 2000)
// after 100 warm-up steps; contact nodes exist from the first step (the block rests on the base).
// The simulation uses at most one thread per 2000 particles, so the 5 mm block runs on one thread
// whatever is asked; the "used" column says how many it had.
#include "../tests/verification/sliding_block.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace frictherm;
using namespace frictherm::verification;

namespace {

struct Timing {
  double rate = 0.0;  // particle-steps per second
  long steps = 0;
  std::size_t particles = 0;
  long contact_nodes = 0;
};

Timing run(double cell, bool single, int threads, long steps) {
  omp_set_num_threads(threads);
  SlidingBlockSetup s;
  s.cell = cell;
  s.single_material = single;
  int block = 0;
  mechanics::Simulation<2> sim = make_sliding_block(s, block);
  const double tf = SlidingBlockConstants::t_final();
  Timing t;
  t.particles = sim.particles().size();
  if (steps > 0)
    for (int k = 0; k < 100; ++k) sim.step();  // warm-up: allocations, first touch, loads on
  else
    sim.step();
  const auto t0 = std::chrono::steady_clock::now();
  if (steps > 0) {
    for (long k = 0; k < steps; ++k) sim.step();
    t.steps = steps;
  } else {
    const long before = sim.step_count();
    while (sim.time() < tf * (1 - 1e-12)) sim.step(tf - sim.time());
    t.steps = sim.step_count() - before;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.rate = static_cast<double>(t.particles) * static_cast<double>(t.steps) / wall;
  t.contact_nodes = sim.contact_stats().contact_nodes;
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  long steps = 2000;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) steps = std::atol(argv[++i]);
    else {
      std::printf("usage: bench_contact [--quick] [--steps N]\n");
      return std::strcmp(argv[i], "--help") ? 2 : 0;
    }
  }
  if (quick) steps = std::min(steps, 200L);
  const int max_threads = omp_get_num_procs() >= 2 ? 2 : 1;
  std::printf("frictherm contact benchmark: Coulomb sliding block (mu = 0.2), uGIMP, MUSL, 2 particles per cell per "
              "direction\n");
  std::printf("%6s %9s %7s %5s %8s %14s %14s %9s %8s\n", "cells", "particles", "threads", "used", "steps",
              "contact Mp-s/s", "single Mp-s/s", "overhead", "c.nodes");
  for (double cell : {0.005, 0.001}) {
    // 5 mm: the whole run (one step in --quick is too few: then 2000 steps after warm-up).
    const long n = cell > 0.002 ? (quick ? 2000 : 0) : steps;
    for (int t = 1; t <= max_threads; ++t) {
      const Timing c = run(cell, false, t, n), one = run(cell, true, t, n);
      const int used = std::max(1, std::min(t, static_cast<int>(c.particles / 2000)));
      std::printf("%4.0f mm %9zu %7d %5d %8ld %14.3f %14.3f %8.1f%% %8ld\n", cell * 1e3, c.particles, t, used, c.steps,
                  c.rate / 1e6, one.rate / 1e6, 100.0 * (one.rate / c.rate - 1.0), c.contact_nodes);
      std::fflush(stdout);
    }
  }
  return 0;
}
