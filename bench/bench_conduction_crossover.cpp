// Where the "auto" integrator should switch from matrix-free forward Euler to cvode_bdf (issue 13
// item 2): the cost of one coupling window of m stable forward-Euler steps (m = 1 ... 256) on a block of
// particles (uGIMP, 2 x 2 per cell, the twin scene's k and C_v, a cosine temperature field), through
// the Coupler as a run uses it, for
//   matrix-free forward Euler (m particle passes), forward Euler on the assembled K, cvode_bdf (KLU).
// Each window moves the particles by 1e-3 cells so every window gathers/assembles anew (as with
// reuse off). Prints microseconds per window (CPU time of the process) and the ratio to matrix-free.
// Asserts nothing.
//   bench_conduction_crossover [--cells NX,NY] [--windows N]
#include "cpu_time.hpp"
#include <frictherm/coupling/coupler.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/resource.h>
#include <vector>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;

namespace {

using frictherm::bench::cpu_seconds;

constexpr double kRho = 1000.0, kC = 1000.0, kK = 0.4, kH = 0.005;  // the twin scene's block

fm::Particles<2> block(int nx, int ny) {
  fm::Particles<2> p;
  const double s = kH / 2, V = s * s * 0.001;
  for (int j = 0; j < 2 * ny; ++j)
    for (int i = 0; i < 2 * nx; ++i) {
      const fm::Vec<2> x(kH + (i + 0.5) * s, kH + (j + 0.5) * s);
      const double T = 300.0 + 20.0 * std::cos(3.14159265358979 * x[0] / (nx * kH));
      p.add(x, fm::Vec<2>::Constant(0.5 * s), kRho * V, V, 0, 0, T);
    }
  return p;
}

// CPU seconds per window for `windows` windows of `m` stable steps each; also the λ bound's step.
double per_window(const std::string& integrator, long mf_max, int nx, int ny, double window, long windows) {
  const fm::Grid<2> grid(fm::Vec<2>(0.0, 0.0), fm::Vec<2>::Constant(kH), fm::IVec<2>{nx + 3, ny + 3});
  fm::Particles<2> p = block(nx, ny);
  fc::CouplerOptions opt;
  opt.materials = {{true, kC, kK}};
  opt.integrator = integrator;
  opt.matrix_free_max_substeps = mf_max;
  opt.window.kind = fc::WindowPolicy::Kind::every_step;
  fc::Coupler<2> cp(grid, fm::ShapeKind::ugimp, opt);
  cp.start(p, 0.0);
  const double c0 = cpu_seconds();
  for (long k = 1; k <= windows; ++k) {
    for (std::size_t i = 0; i < p.size(); ++i) p.position[i][0] += 1e-3 * kH;
    cp.after_step(p, {}, window * static_cast<double>(k));
  }
  return (cpu_seconds() - c0) / static_cast<double>(windows);
}

}  // namespace

int main(int argc, char** argv) {
  int nx = 28, ny = 5;  // the twin block's base at 5 mm: 28 x 5 cells, 560 particles
  long windows = 200;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--cells" && i + 1 < argc) {
      std::sscanf(argv[++i], "%d,%d", &nx, &ny);
    } else if (a == "--windows" && i + 1 < argc) {
      windows = std::atol(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: bench_conduction_crossover [--cells NX,NY] [--windows N]\n");
      return 2;
    }
  }
  // The stable step of the matrix-free path: one window of 1 s tells how many sub-steps it needs.
  double h_stable = 0.0;
  {
    const fm::Grid<2> grid(fm::Vec<2>(0.0, 0.0), fm::Vec<2>::Constant(kH), fm::IVec<2>{nx + 3, ny + 3});
    fm::Particles<2> p = block(nx, ny);
    fc::CouplerOptions opt;
    opt.materials = {{true, kC, kK}};
    opt.integrator = "forward_euler";
    opt.matrix_free_max_substeps = 1000000000;
    fc::Coupler<2> cp(grid, fm::ShapeKind::ugimp, opt);
    cp.start(p, 0.0);
    cp.after_step(p, {}, 1000.0);
    h_stable = 1000.0 / static_cast<double>(cp.books().matrix_free_substeps);
  }
  std::printf("bench_conduction_crossover: %d x %d cells, %d particles, stable step %.4g s (matrix-free bound), "
              "%ld windows per case\n",
              nx, ny, 4 * nx * ny, h_stable, windows);
  std::printf("  %8s  %14s  %14s  %14s  %10s  %10s\n", "m steps", "matrix-free us", "assembled FE us",
              "cvode_bdf us", "FE/mf", "bdf/mf");
  for (long m : {1L, 2L, 4L, 8L, 16L, 32L, 64L, 128L, 256L}) {
    const double window = m * h_stable * 0.999;
    const long w = std::max(10L, windows / std::max(1L, m / 8));
    const double mf = per_window("forward_euler", 1000000000, nx, ny, window, w);
    const double fe = per_window("forward_euler", 0, nx, ny, window, w);
    const double bdf = per_window("cvode_bdf", 0, nx, ny, window, w);
    std::printf("  %8ld  %14.1f  %14.1f  %14.1f  %10.2f  %10.2f\n", m, 1e6 * mf, 1e6 * fe, 1e6 * bdf, fe / mf,
                bdf / mf);
    std::fflush(stdout);
  }
  return 0;
}
