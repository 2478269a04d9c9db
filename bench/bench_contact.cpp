// Contact throughput: particle-steps per second on the Coulomb sliding block (Nairn, Bardenhagen &
// Smith 2018, figure 2) at 5 mm cells (656 particles) and 1 mm cells (16,400 particles), on 1 and 2
// threads, against the same scene run as one material (block and base one velocity field, no
// contact). Prints a table with the contact overhead; asserts nothing.
//   bench_contact [--quick] [--steps N] [--costs]   (--costs: the second table only)
// 5 mm: the whole run to t_f (every phase: loading, sticking, sliding). 1 mm: N steps (default 2000)
// after 100 warm-up steps; contact nodes exist from the first step (the block rests on the base).
// The simulation uses at most one thread per 2000 particles, so the 5 mm block runs on one thread
// whatever is asked; the "used" column says how many it had.
// Second table: the cost of the extended B-spline (EBS) and of penalty contact per particle-step,
// relative to the quadratic B-spline without contact (block and base one material), at 2.5 mm and
// 1.25 mm cells: quadratic B-spline and EBS without contact, each with penalty contact, and uGIMP with
// multimaterial contact; N steps (default 1000 at 2.5 mm, 500 at 1.25 mm) after 100 warm-up steps, in
// the normal-load ramp (the block rests on the base, every bottom boundary point in contact).
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

Timing run(double cell, bool single, int threads, long steps,
           mechanics::ShapeKind shape = mechanics::ShapeKind::ugimp,
           mechanics::ContactMethod method = mechanics::ContactMethod::multimaterial) {
  omp_set_num_threads(threads);
  SlidingBlockSetup s;
  s.cell = cell;
  s.single_material = single;
  s.shape = shape;
  s.method = method;
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
  t.contact_nodes = method == mechanics::ContactMethod::penalty ? sim.contact_stats().penalty_contacts
                                                                  : sim.contact_stats().contact_nodes;
  return t;
}

struct Case {
  const char* name;
  mechanics::ShapeKind shape;
  bool single;
  mechanics::ContactMethod method;
};

void shape_and_method_table(bool quick, long steps_override, int max_threads) {
  using mechanics::ContactMethod;
  using mechanics::ShapeKind;
  const Case cases[] = {{"quadratic B-spline, no contact", ShapeKind::quadratic_bspline, true, ContactMethod::multimaterial},
                        {"EBS, no contact", ShapeKind::extended_bspline, true, ContactMethod::multimaterial},
                        {"quadratic B-spline + penalty", ShapeKind::quadratic_bspline, false, ContactMethod::penalty},
                        {"EBS + penalty", ShapeKind::extended_bspline, false, ContactMethod::penalty},
                        {"uGIMP + multimaterial", ShapeKind::ugimp, false, ContactMethod::multimaterial}};
  std::printf("\nshape function and contact method, relative to the quadratic B-spline without contact\n");
  std::printf("%8s %9s %7s %5s %6s  %-32s %8s %8s %9s\n", "cells", "particles", "threads", "used", "steps", "case",
              "Mp-s/s", "cost", "contacts");
  for (double cell : {0.0025, 0.00125}) {
    if (quick && cell < 0.002) break;
    const long n = steps_override > 0 ? steps_override : (quick ? 200 : (cell > 0.002 ? 1000 : 500));
    for (int t = 1; t <= max_threads; ++t) {
      double base = 0.0;
      for (const Case& c : cases) {
        const Timing r = run(cell, c.single, t, n, c.shape, c.method);
        if (base == 0.0) base = r.rate;
        const int used = std::max(1, std::min(t, static_cast<int>(r.particles / 2000)));
        std::printf("%5.2f mm %9zu %7d %5d %6ld  %-32s %8.3f %7.2fx %9ld\n", cell * 1e3, r.particles, t, used, r.steps,
                    c.name, r.rate / 1e6, base / r.rate, r.contact_nodes);
        std::fflush(stdout);
      }
    }
  }
  std::printf("cost: time per particle-step over the first line's (the quadratic B-spline without contact); contacts: "
              "contact nodes (multimaterial) or active penalty contacts, last step\n");
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, only_costs = false;
  long steps = 2000, cost_steps = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) steps = cost_steps = std::atol(argv[++i]);
    else if (!std::strcmp(argv[i], "--costs")) only_costs = true;
    else {
      std::printf("usage: bench_contact [--quick] [--steps N] [--costs]\n");
      return std::strcmp(argv[i], "--help") ? 2 : 0;
    }
  }
  if (quick) steps = std::min(steps, 200L);
  const int max_threads = omp_get_num_procs() >= 2 ? 2 : 1;
  if (only_costs) {
    shape_and_method_table(quick, cost_steps, max_threads);
    return 0;
  }
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
  shape_and_method_table(quick, cost_steps, max_threads);
  return 0;
}
