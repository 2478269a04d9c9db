// Thermal solve cost per integrator (prints only; accuracy is tested, not benchmarked).
// 2D 5-point grid (HMX-like, h = 1 µm, adiabatic edges) with a hot disk in the centre,
// integrated over 5 consecutive windows of m·dt_FE, m ∈ {1, 10, 100, 1000}
// (dt_FE = h²/4α, the forward-Euler limit). Columns: wall time per window, steps, RHS
// evaluations, linear iterations, and max |T − T_ref| against cvode_bdf/klu at rtol 1e-10.
//   usage: bench_thermal [n1 n2 ...]   (grid sizes n×n; default 100 300)
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/stability.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace ft = frictherm::thermal;

namespace {

constexpr double kRhoC = 2.09e6, kK = 0.45, kH = 1e-6;

ft::Problem make_grid(int n) {
  // node-centred finite volumes: half/quarter cells on edges/corners, conductance k·face/h
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd m(n * n);
  auto w = [n](int i) { return (i == 0 || i == n - 1) ? 0.5 : 1.0; };
  auto id = [n](int i, int j) { return i + n * j; };
  auto link = [&t](int a, int b, double c) {
    t.emplace_back(a, a, c);
    t.emplace_back(b, b, c);
    t.emplace_back(a, b, -c);
    t.emplace_back(b, a, -c);
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m[id(i, j)] = kRhoC * kH * kH * w(i) * w(j);
      if (i + 1 < n) link(id(i, j), id(i + 1, j), kK * w(j));
      if (j + 1 < n) link(id(i, j), id(i, j + 1), kK * w(i));
    }
  ft::SparseMatrix k(n * n, n * n);
  k.setFromTriplets(t.begin(), t.end());
  return ft::Problem(m, k);
}

Eigen::VectorXd hot_disk(int n) {
  Eigen::VectorXd t(n * n);
  const double c = 0.5 * (n - 1), r = 0.1 * n;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) t[i + n * j] = (std::hypot(i - c, j - c) < r) ? 800.0 : 300.0;
  return t;
}

struct Config {
  std::string name, ls;
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes;
  for (int a = 1; a < argc; ++a) sizes.push_back(std::atoi(argv[a]));
  if (sizes.empty()) sizes = {100, 300};
  const std::vector<Config> configs{{"forward_euler", ""}, {"cvode_bdf", "klu"}, {"cvode_bdf", "pcg"},
                                    {"cvode_adams", ""},    {"arkode_erk", ""},   {"arkode_dirk", "klu"},
                                    {"arkode_dirk", "pcg"}};
  const int windows = 5;
  std::printf("# thermal integrator cost, %d windows each; rtol 1e-5, atol 1e-3 K\n", windows);
  std::printf("%-7s %-6s %-18s %12s %9s %9s %9s %10s\n", "grid", "m", "integrator", "ms/window", "steps",
              "rhs", "lin_it", "max_err_K");
  for (int n : sizes) {
    const ft::Problem p = make_grid(n);
    const double dt_fe = ft::forward_euler_dt_limit(p);
    std::printf("# grid %dx%d: dt_FE = %.4g s\n", n, n, dt_fe);
    for (double m : {1.0, 10.0, 100.0, 1000.0}) {
      const double win = m * dt_fe;
      ft::IntegratorOptions ro;
      ro.rtol = 1e-10;
      ro.atol = 1e-10;
      ro.max_steps = 1000000;
      auto ref = ft::make_integrator("cvode_bdf", ro);
      Eigen::VectorXd tref = hot_disk(n);
      for (int w = 0; w < windows; ++w) ref->advance(p, tref, w * win, (w + 1) * win);
      for (const auto& c : configs) {
        ft::IntegratorOptions o;
        o.rtol = 1e-5;
        o.atol = 1e-3;
        o.max_steps = 1000000;
        o.linear_solver = c.ls;
        const std::string label = c.name + (c.ls.empty() ? "" : "/" + c.ls);
        // Explicit adaptive methods need ≳ m·windows steps: skip the runs that would take minutes.
        if ((c.name == "cvode_adams" || c.name == "arkode_erk") && m * n * n > 2e7) {
          std::printf("%4dx%-3d %-6g %-18s skipped (explicit, > 2e7 node-steps)\n", n, n, m, label.c_str());
          continue;
        }
        auto integ = ft::make_integrator(c.name, o);
        Eigen::VectorXd t = hot_disk(n);
        try {
          for (int w = 0; w < windows; ++w) integ->advance(p, t, w * win, (w + 1) * win);
        } catch (const std::exception& e) {
          std::printf("%4dx%-3d %-6g %-18s failed: %s\n", n, n, m, label.c_str(), e.what());
          continue;
        }
        const auto& s = integ->stats();
        std::printf("%4dx%-3d %-6g %-18s %12.3f %9ld %9ld %9ld %10.2e\n", n, n, m, label.c_str(),
                    1e3 * s.wall_seconds / windows, s.steps, s.rhs_evals, s.linear_iters,
                    (t - tref).cwiseAbs().maxCoeff());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
