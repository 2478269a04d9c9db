// MPM throughput: particle-steps per second and bytes per particle for elastic blocks in 2D and 3D,
// each shape function, on 1 and 2 threads. Prints a table; asserts nothing. The extended B-spline
// (EBS) line also gives its cost relative to the quadratic B-spline: the per-step rebuild of the
// basis and the flattened weights (the block's faces cut their knot spans in half, so every face has
// degenerate nodes).
//   bench_mpm [--quick] [--steps N]
#include <frictherm/mechanics/simulation.hpp>

#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

using namespace frictherm::mechanics;

namespace {

template <int Dim>
std::size_t stencil_bytes(ShapeKind s) {
  if (s == ShapeKind::extended_bspline)  // flattened entries: slot, N^e, ∇N^e, 3^Dim per particle + offset
    return (Dim == 2 ? 9 : 27) * (sizeof(std::int32_t) + sizeof(double) + sizeof(Vec<Dim>)) + sizeof(std::size_t);
  return dispatch_shape(s, [](auto k) { return sizeof(Stencil<Dim, decltype(k)>); });
}

// A block of `target` particles (2 per cell per direction) in a grid with a one-cell margin,
// moving and vibrating so that stresses are non-trivial. Returns particle-steps per second.
template <int Dim>
double run_case(long target, ShapeKind shape, int threads, int steps, double quadratic_rate = 0.0) {
  omp_set_num_threads(threads);
  const int ppc = 2;
  const long cells_total = target / static_cast<long>(std::pow(ppc, Dim));
  const int n = static_cast<int>(std::lround(std::pow(static_cast<double>(cells_total), 1.0 / Dim)));
  const double h = 0.01;
  IVec<Dim> cells;
  cells.fill(n + 4);
  SimulationOptions o;
  o.analysis = Dim == 2 ? Analysis::plane_strain : Analysis::three_d;
  o.shape = shape;
  Simulation<Dim> sim(Grid<Dim>(Vec<Dim>::Zero(), Vec<Dim>::Constant(h), cells), o);
  Material m;
  m.name = "elastic";
  m.density = 1000.0;
  m.youngs_modulus = 1e8;
  m.poisson_ratio = 0.3;
  const int mat = sim.add_material(m);
  sim.add_body("block", *make_box<Dim>(Vec<Dim>::Constant(2 * h), Vec<Dim>::Constant((n + 2) * h), mat), ppc,
               Vec<Dim>::Zero());
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) p.velocity[k][0] = 0.5 * std::sin(10.0 * p.position[k][1]);
  sim.step();  // warm-up: allocations, first touch
  const auto t0 = std::chrono::steady_clock::now();
  for (int s = 0; s < steps; ++s) sim.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = static_cast<double>(p.size()) * steps / wall;
  const std::size_t nodes = sim.grid().node_count();
  const std::size_t node_bytes = nodes * (sizeof(double) + 4 * sizeof(Vec<Dim>)) * static_cast<std::size_t>(threads);
  const std::size_t bytes = Particles<Dim>::bytes_per_particle() + stencil_bytes<Dim>(shape) + node_bytes / p.size();
  std::printf("%dD  %-18s %8zu particles  %d thread%s  %7.2f M particle-steps/s  (%5.2f M per thread)  %4zu B/particle",
              Dim, to_string(shape), p.size(), threads, threads > 1 ? "s" : " ", rate / 1e6, rate / 1e6 / threads,
              bytes);
  if (shape == ShapeKind::extended_bspline && quadratic_rate > 0.0) {
    const auto& B = sim.extended_bases()[0];
    std::printf("  cost %.2fx quadratic_bspline (%d degenerate nodes, %d extended cells)", quadratic_rate / rate,
                B.degenerate_count(), B.extended_cell_count());
  }
  std::printf("\n");
  std::fflush(stdout);
  return rate;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  int steps = 0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--steps") && i + 1 < argc) steps = std::atoi(argv[++i]);
    else {
      std::printf("usage: bench_mpm [--quick] [--steps N]\n");
      return std::strcmp(argv[i], "--help") ? 2 : 0;
    }
  }
  const int max_threads = omp_get_num_procs() >= 2 ? 2 : 1;
  std::printf("frictherm MPM benchmark: elastic block, MUSL, 2 particles per cell per direction\n");
  for (long target : {10000L, 100000L}) {
    if (quick && target > 10000L) break;
    const int nsteps = steps > 0 ? steps : static_cast<int>(std::max(20L, 4000000L / target));
    const ShapeKind shapes[] = {ShapeKind::linear, ShapeKind::ugimp, ShapeKind::quadratic_bspline,
                                ShapeKind::extended_bspline};
    double quadratic[2][3] = {};  // [dim 2/3][threads]
    for (ShapeKind s : shapes)
      for (int t = 1; t <= max_threads; ++t) {
        const double r = run_case<2>(target, s, t, nsteps, quadratic[0][t]);
        if (s == ShapeKind::quadratic_bspline) quadratic[0][t] = r;
      }
    for (ShapeKind s : shapes)
      for (int t = 1; t <= max_threads; ++t) {
        const double r = run_case<3>(target, s, t, std::max(10, nsteps / 3), quadratic[1][t]);
        if (s == ShapeKind::quadratic_bspline) quadratic[1][t] = r;
      }
  }
  return 0;
}
