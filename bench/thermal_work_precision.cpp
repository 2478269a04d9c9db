// Work–precision data for the thermal integrators (issue 4, chart b): a hot spot cooling by
// conduction, integrated over a fixed end time split into coupling windows, for each
// integrator across tolerances. Writes CSV; examples/thermal_work_precision.py draws it.
//
// Problem: the 2D Gaussian pulse (thermal-notes §4), exact in an infinite medium,
//   T = T0 + A (σ0²/σ²) exp(−r²/2σ²),   σ² = σ0² + 2αt,
// HMX-like (ρc = 2.09e6 J/(m³K), k = 0.45 W/(m K)), T0 = 300 K, A = 500 K, σ0 = 4 µm, on the
// 61×61 node-centred 5-point grid of bench/thermal_grids.hpp (h = 1 µm, ±30 µm, adiabatic
// edges: the pulse's tail there is exp(−30²/2·6²) ≈ 4e-6 of its peak at the end) up to
// σ = 6 µm, t_end = (σ²−σ0²)/2α = 46 µs = 40 dt_FE (dt_FE = h²/4α = 1.16 µs).
// Windows: t_end split into 1, 10, 100, 1000 equal coupling windows, one advance() each with a
// freshly assembled Problem per window, as the coupler does (the SUNDIALS integrators rebuild
// and restart at order 1 every window). Tolerances: rtol 1e-3 … 1e-9 with atol = rtol·1 K;
// forward_euler has no tolerance: its sub-step is set by fe_safety (0.9 … 0.01 of dt_FE,
// capped by the window), which is written in the tolerance column with option "fe_safety".
// Errors at t_end, max-norm and energy-weighted L2 (√(Σ M_i e_i² / Σ M_i), the RMS weighted by
// heat capacity), in K, against
//   * the semi-discrete reference: the same grid ODE solved by cvode_bdf/klu at rtol = atol
//     = 1e-12 in one window: the integration error alone;
//   * the analytic solution: integration plus spatial discretisation error (the 5-point
//     grid's error is a floor no integrator can go below).
// The first data rows, integrator "reference", give the reference's own error (its difference
// from an rtol 1e-11 solve, in the semi columns) and the discretisation floor (analytic cols).
//
// usage: thermal_work_precision [--out FILE.csv] [--windows 1,10,100,1000]
//          [--rtols 1e-3,...,1e-9] [--fe-safety 0.9,0.5,0.2,0.1,0.05,0.02,0.01]
//          [--integrators forward_euler,cvode_bdf/klu,cvode_bdf/pcg,cvode_adams,arkode_erk,arkode_dirk/klu]
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/stability.hpp"
#include "thermal_grids.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ft = frictherm::thermal;
namespace tg = thermal_grids;

namespace {

struct Args {
  std::string out;
  std::vector<double> windows{1, 10, 100, 1000};
  std::vector<double> rtols{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9};
  std::vector<double> fe_safety{0.9, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01};
  std::vector<std::string> integrators{"forward_euler", "cvode_bdf/klu", "cvode_bdf/pcg",
                                       "cvode_adams",   "arkode_erk",    "arkode_dirk/klu"};
};

std::vector<double> numbers(const std::string& s) {
  std::vector<double> out;
  for (const auto& x : thermal_grids::split_list(s)) out.push_back(std::stod(x));
  return out;
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (i + 1 >= argc) throw std::invalid_argument("missing value after " + key + " (see the file header)");
    const std::string v = argv[++i];
    if (key == "--out") a.out = v;
    else if (key == "--windows") a.windows = numbers(v);
    else if (key == "--rtols") a.rtols = numbers(v);
    else if (key == "--fe-safety") a.fe_safety = numbers(v);
    else if (key == "--integrators") a.integrators = thermal_grids::split_list(v);
    else throw std::invalid_argument("unknown option " + key);
  }
  return a;
}

// The Gaussian pulse on its grid.
struct Pulse {
  tg::Material mat = tg::hmx_like();
  double h = 1e-6, half_width = 30e-6, t0 = 300.0, amp = 500.0, sigma0 = 4e-6, sigma_end = 6e-6;
  tg::Grid2D g;
  Pulse() {
    const int n = static_cast<int>(std::lround(2 * half_width / h)) + 1;
    g = tg::make_grid_2d(n, n, -half_width, -half_width, h, mat);
  }
  double t_end() const { return (sigma_end * sigma_end - sigma0 * sigma0) / (2 * mat.alpha()); }
  Eigen::VectorXd exact(double t) const {  // thermal-notes §4, instantaneous source shifted by σ0²/2α
    const double s2 = sigma0 * sigma0 + 2 * mat.alpha() * t;
    Eigen::VectorXd v(g.size());
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double r2 = g.x(i) * g.x(i) + g.y(j) * g.y(j);
        v[g.id(i, j)] = t0 + amp * sigma0 * sigma0 / s2 * std::exp(-r2 / (2 * s2));
      }
    return v;
  }
};

struct Outcome {
  bool ok = false;
  std::string status = "ok";
  Eigen::VectorXd t_end;
  double wall = 0.0;
  long steps = 0, rhs = 0;
};

// windows equal coupling windows over [0, t_end], one advance() each on a re-assembled Problem.
Outcome integrate(const Pulse& pulse, const std::string& config, const ft::IntegratorOptions& base, int windows) {
  const auto slash = config.find('/');
  ft::IntegratorOptions o = base;
  o.max_steps = 10000000;
  if (slash != std::string::npos) o.linear_solver = config.substr(slash + 1);
  Outcome r;
  try {
    auto integ = ft::make_integrator(config.substr(0, slash), o);
    ft::Problem p = pulse.g.problem();
    Eigen::VectorXd t = pulse.exact(0.0);
    const double te = pulse.t_end();
    for (int w = 0; w < windows; ++w) {
      p.clear_boundaries();  // a freshly assembled problem (new revision), as coupler.cpp does
      integ->advance(p, t, te * w / windows, w + 1 == windows ? te : te * (w + 1) / windows);
    }
    r.ok = true;
    r.t_end = std::move(t);
    r.wall = integ->stats().wall_seconds;
    r.steps = integ->stats().steps;
    r.rhs = integ->stats().rhs_evals;
  } catch (const std::exception& e) {
    r.status = std::string("failed: ") + e.what();
    for (char& c : r.status)
      if (c == ',' || c == '\n') c = ';';
  }
  return r;
}

struct Errors {
  double max = NAN, l2 = NAN;
};

Errors errors(const Eigen::VectorXd& t, const Eigen::VectorXd& ref, const Eigen::VectorXd& mass) {
  const Eigen::VectorXd e = t - ref;
  return {e.cwiseAbs().maxCoeff(), std::sqrt(mass.dot(e.cwiseAbs2()) / mass.sum())};
}

void row(std::ostream& os, const std::string& integ, const std::string& option, int windows, double tol,
         const Errors& semi, const Errors& exact, const Outcome& r) {
  os << integ << ',' << option << ',' << windows << ',' << tol << ',' << semi.max << ',' << semi.l2 << ','
     << exact.max << ',' << exact.l2 << ',' << r.wall << ',' << r.steps << ',' << r.rhs << ',' << r.status << '\n';
  os.flush();
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  try {
    a = parse(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "thermal_work_precision: %s\n", e.what());
    return 2;
  }
  std::ofstream file;
  if (!a.out.empty()) {
    file.open(a.out);
    if (!file) {
      std::fprintf(stderr, "thermal_work_precision: cannot write %s\n", a.out.c_str());
      return 2;
    }
  }
  std::ostream& os = a.out.empty() ? std::cout : file;
  os.precision(6);

  const Pulse pulse;
  const Eigen::VectorXd& mass = pulse.g.mass;
  const Eigen::VectorXd exact = pulse.exact(pulse.t_end());
  const double dt_fe = ft::forward_euler_dt_limit(pulse.g.problem());
  std::fprintf(stderr, "# Gaussian pulse, %d nodes, t_end = %.4g s = %.1f dt_FE\n", pulse.g.size(), pulse.t_end(),
               pulse.t_end() / dt_fe);

  os << "integrator,option,windows,tolerance,err_semi_max_K,err_semi_l2_K,err_analytic_max_K,err_analytic_l2_K,"
        "wall_s,steps,rhs_evals,status\n";
  ft::IntegratorOptions tight;
  tight.rtol = tight.atol = 1e-12;
  const Outcome ref = integrate(pulse, "cvode_bdf/klu", tight, 1);
  tight.rtol = tight.atol = 1e-11;
  const Outcome check = integrate(pulse, "cvode_bdf/klu", tight, 1);
  if (!ref.ok || !check.ok) {
    std::fprintf(stderr, "thermal_work_precision: reference failed: %s\n", (ref.ok ? check : ref).status.c_str());
    return 1;
  }
  row(os, "reference", "cvode_bdf/klu", 1, 1e-12, errors(check.t_end, ref.t_end, mass),
      errors(ref.t_end, exact, mass), ref);

  for (double windows : a.windows) {
    const int nw = static_cast<int>(windows);
    for (const auto& config : a.integrators) {
      const bool fe = config == "forward_euler";
      const std::string name = config.substr(0, config.find('/'));
      std::string option = config.find('/') == std::string::npos ? "" : config.substr(config.find('/') + 1);
      if (fe) option = "fe_safety";
      if (name == "cvode_adams" && option.empty()) option = "fixed_point";  // its default
      for (double tol : fe ? a.fe_safety : a.rtols) {
        ft::IntegratorOptions o;
        if (fe) {
          o.fe_safety = tol;
        } else {
          o.rtol = tol;
          o.atol = tol * 1.0;  // atol = rtol·1 K
        }
        const Outcome r = integrate(pulse, config, o, nw);
        const Errors semi = r.ok ? errors(r.t_end, ref.t_end, mass) : Errors{};
        const Errors ex = r.ok ? errors(r.t_end, exact, mass) : Errors{};
        row(os, name, option, nw, tol, semi, ex, r);
        std::fprintf(stderr, "%5d %-16s %-9s tol %-7g err %.3e K  %8.4f s %s\n", nw, config.c_str(), option.c_str(),
                     tol, semi.max, r.wall, r.ok ? "" : r.status.c_str());
      }
    }
  }
  return 0;
}
