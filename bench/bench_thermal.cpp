// Thermal cost per coupling window and per node for each integrator (issue 4; prints only,
// accuracy is tested in tests/thermal, not here).
//
// Grids (bench/thermal_grids.hpp, node-centred finite volumes, adiabatic edges, HMX-like
// ρc = 2.09e6 J/(m³K), k = 0.45 W/(m K), α = 2.15e-7 m²/s, h = 1 µm):
//   2D  60×60 nodes (5-point, 3 600 nodes),  forward-Euler limit dt_FE = h²/4α = 1.16 µs;
//   3D  50×50×50 nodes (7-point, 125 000 nodes),                dt_FE = h²/6α = 0.774 µs.
// Initial condition: a hot spot, 800 K in a 300 K body, disk/sphere of radius 0.1·n·h at the
// centre (sharp edge, as a frictional hot spot mapped from particles).
// Mechanics step: a representative MPM step dt_mech = C·h/c with C = 0.5, c = 2500 m/s
// (HMX-like P-wave speed) = 0.2 ns at h = 1 µm, i.e. dt_FE ≈ 5 800 dt_mech (2D), 3 900 (3D).
// Windows of m = 1, 10, 100, 10 000 dt_mech; 4 consecutive windows each (--count-last for the
// largest, also 4 by default: the whole default run takes about 30 s on one core),
// integrated as the coupler does (coupling/src/heat/coupler.cpp): one advance() per window, and a
// freshly assembled Problem each window (new revision → the SUNDIALS integrators rebuild their
// system and restart at order 1; forward Euler only re-estimates its limit). The Problem is
// built outside the timing, as the coupler's assembly is not thermal integration.
// rtol 1e-5, atol 1e-3 K. Accuracy: max |T − T_ref| [K] against cvode_bdf at rtol = atol = 1e-10
// (klu; pcg above 20 000 nodes), one continuous solve (no source: the windows do not change it).
// Crossover: per grid, the smallest listed window at which cvode_bdf (klu and pcg separately)
// takes less wall time per window than forward_euler; if none, windows ×√10 beyond the list
// (forward_euler and cvode_bdf only, 2 windows each, up to --crossover-max mechanics steps)
// bracket it, with a log-log interpolated estimate. KLU is skipped above --klu-max-nodes
// (20 000): one KLU factorisation of the 3D 7-point matrix took 1 s at 20³ and 43 s at 30³
// nodes here (it grows like N^2.5–3), so 50³ would take hours per window.
//
// usage: bench_thermal [--grids 2d,3d] [--n2 60] [--n3 50] [--h 1e-6] [--cfl 0.5] [--c 2500]
//                      [--windows 1,10,100,10000] [--count 4] [--count-last 4]
//                      [--rtol 1e-5] [--atol 1e-3] [--fe-safety 0.9] [--mode rebuild|continue]
//                      [--integrators forward_euler,cvode_bdf/klu,...] [--crossover-max 1e8]
//                      [--klu-max-nodes 20000]
// --mode continue keeps one Problem (the SUNDIALS integrators then keep their history).
#include "frictherm/thermal/integrator.hpp"
#include "frictherm/thermal/stability.hpp"
#include "thermal_grids.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace ft = frictherm::thermal;
namespace tg = thermal_grids;

namespace {

struct Args {
  std::vector<std::string> grids{"2d", "3d"};
  int n2 = 60, n3 = 50;
  double h = 1e-6, cfl = 0.5, wave_speed = 2500.0;
  std::vector<double> windows{1, 10, 100, 10000};
  int count = 4, count_last = 4;
  double rtol = 1e-5, atol = 1e-3, fe_safety = 0.9;
  std::string mode = "rebuild";
  std::vector<std::string> integrators{"forward_euler", "cvode_bdf/klu", "cvode_bdf/pcg", "cvode_adams",
                                       "arkode_erk",    "arkode_dirk/klu", "arkode_dirk/pcg"};
  double crossover_max = 1e8;
  long klu_max_nodes = 20000;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string key = argv[i];
    if (key == "-h" || key == "--help") {
      std::printf("see the header of bench/bench_thermal.cpp for the options\n");
      std::exit(0);
    }
    if (i + 1 >= argc) throw std::invalid_argument("missing value after " + key);
    const std::string v = argv[++i];
    if (key == "--grids") a.grids = thermal_grids::split_list(v);
    else if (key == "--n2") a.n2 = std::stoi(v);
    else if (key == "--n3") a.n3 = std::stoi(v);
    else if (key == "--h") a.h = std::stod(v);
    else if (key == "--cfl") a.cfl = std::stod(v);
    else if (key == "--c") a.wave_speed = std::stod(v);
    else if (key == "--windows") {
      a.windows.clear();
      for (const auto& w : thermal_grids::split_list(v)) a.windows.push_back(std::stod(w));
      std::sort(a.windows.begin(), a.windows.end());
    } else if (key == "--count") a.count = std::stoi(v);
    else if (key == "--count-last") a.count_last = std::stoi(v);
    else if (key == "--rtol") a.rtol = std::stod(v);
    else if (key == "--atol") a.atol = std::stod(v);
    else if (key == "--fe-safety") a.fe_safety = std::stod(v);
    else if (key == "--mode") a.mode = v;
    else if (key == "--integrators") a.integrators = thermal_grids::split_list(v);
    else if (key == "--crossover-max") a.crossover_max = std::stod(v);
    else if (key == "--klu-max-nodes") a.klu_max_nodes = std::stol(v);
    else throw std::invalid_argument("unknown option " + key);
  }
  if (a.mode != "rebuild" && a.mode != "continue") throw std::invalid_argument("--mode: rebuild or continue");
  if (a.windows.empty() || a.count < 1 || a.count_last < 1) throw std::invalid_argument("need windows and counts >= 1");
  return a;
}

struct Case {
  std::string name;
  Eigen::VectorXd mass;
  ft::SparseMatrix k;
  Eigen::VectorXd t_init;
  double dt_fe = 0.0, dt_mech = 0.0;
  long nodes() const { return mass.size(); }
};

constexpr double kCold = 300.0, kHot = 800.0;

Case make_2d(const Args& a) {
  const int n = a.n2;
  const auto g = tg::make_grid_2d(n, n, 0.0, 0.0, a.h, tg::hmx_like());
  Case c{std::to_string(n) + "x" + std::to_string(n), g.mass, g.k, Eigen::VectorXd(g.size())};
  const double mid = 0.5 * (n - 1), r = 0.1 * n;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) c.t_init[g.id(i, j)] = std::hypot(i - mid, j - mid) < r ? kHot : kCold;
  return c;
}

Case make_3d(const Args& a) {
  const int n = a.n3;
  const auto g = tg::make_grid_3d(n, n, n, 0.0, 0.0, 0.0, a.h, tg::hmx_like());
  Case c{std::to_string(n) + "^3", g.mass, g.k, Eigen::VectorXd(g.size())};
  const double mid = 0.5 * (n - 1), r = 0.1 * n;
  for (int l = 0; l < n; ++l)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double d = std::sqrt((i - mid) * (i - mid) + (j - mid) * (j - mid) + (l - mid) * (l - mid));
        c.t_init[g.id(i, j, l)] = d < r ? kHot : kCold;
      }
  return c;
}

struct Result {
  bool ok = false;
  std::string error;
  double wall_per_window = 0.0;  // [s]
  double steps = 0.0, rhs = 0.0, lin = 0.0;  // per window
  Eigen::VectorXd t_end;
};

// `count` consecutive windows of m·dt_mech from t = 0, one advance() each (coupler-like). Runs
// shorter than 20 ms in all are repeated (fresh integrator) up to 5 times and the fastest is
// kept: the machine is shared and sub-millisecond timings are otherwise noisy.
Result run(const Case& c, const std::string& config, double m, int count, const Args& a) {
  const auto slash = config.find('/');
  ft::IntegratorOptions o;
  o.rtol = a.rtol;
  o.atol = a.atol;
  o.fe_safety = a.fe_safety;
  o.max_steps = 50000000;
  if (slash != std::string::npos) o.linear_solver = config.substr(slash + 1);
  Result r;
  if (o.linear_solver == "klu" && c.nodes() > a.klu_max_nodes) {
    r.error = "skipped (KLU above --klu-max-nodes " + std::to_string(a.klu_max_nodes) + ", see header)";
    return r;
  }
  try {
    for (int rep = 0; rep < 5; ++rep) {
      auto integ = ft::make_integrator(config.substr(0, slash), o);
      ft::Problem p(c.mass, c.k);
      Eigen::VectorXd t = c.t_init;
      const double win = m * c.dt_mech;
      for (int w = 0; w < count; ++w) {
        if (a.mode == "rebuild") p.clear_boundaries();  // a re-assembled problem: new revision
        integ->advance(p, t, w * win, (w + 1) * win);
      }
      const auto& s = integ->stats();
      if (!r.ok || s.wall_seconds / count < r.wall_per_window) r.wall_per_window = s.wall_seconds / count;
      r.ok = true;
      r.steps = double(s.steps) / count;
      r.rhs = double(s.rhs_evals) / count;
      r.lin = double(s.linear_iters) / count;
      r.t_end = std::move(t);
      if (s.wall_seconds > 0.02) break;
    }
  } catch (const std::exception& e) {
    r.ok = false;
    r.error = e.what();
  }
  return r;
}

// T at each requested end time from one continuous tight cvode_bdf solve (no source: the exact
// semi-discrete solution does not depend on the windows).
std::map<double, Eigen::VectorXd> reference(const Case& c, std::vector<double> ends, const std::string& ls) {
  ft::IntegratorOptions o;
  o.rtol = 1e-10;
  o.atol = 1e-10;
  o.max_steps = 50000000;
  o.linear_solver = ls;
  auto integ = ft::make_integrator("cvode_bdf", o);
  std::sort(ends.begin(), ends.end());
  ft::Problem p(c.mass, c.k);
  Eigen::VectorXd t = c.t_init;
  double t0 = 0.0;
  std::map<double, Eigen::VectorXd> out;
  for (double e : ends) {
    if (e > t0) integ->advance(p, t, t0, e);
    t0 = std::max(t0, e);
    out[e] = t;
  }
  std::printf("# reference cvode_bdf/%s rtol = atol = 1e-10: %ld steps, %.2f s\n", ls.c_str(),
              integ->stats().steps, integ->stats().wall_seconds);
  return out;
}

void print_row(const Case& c, double m, const std::string& config, int count, const Result& r, double err) {
  const double win = m * c.dt_mech;
  if (!r.ok) {
    const bool skipped = r.error.rfind("skipped", 0) == 0;
    std::printf("%-8s %8g %10.3e %-15s %s%s\n", c.name.c_str(), m, win, config.c_str(), skipped ? "" : "failed: ",
                r.error.c_str());
    return;
  }
  std::printf("%-8s %8g %10.3e %-15s %3d %11.4f %10.2f %9.1f %9.1f %9.1f %10.2e\n", c.name.c_str(), m, win,
              config.c_str(), count, 1e3 * r.wall_per_window, 1e9 * r.wall_per_window / c.nodes(), r.steps, r.rhs,
              r.lin, err);
  std::fflush(stdout);
}

// log-log interpolation of the window where the cost difference d = t_bdf − t_fe changes sign.
double crossover_estimate(double m_lo, double d_lo, double fe_lo, double m_hi, double d_hi, double fe_hi) {
  // compare log(t_bdf) − log(t_fe) linearly in log m
  const double g_lo = std::log((fe_lo + d_lo) / fe_lo), g_hi = std::log((fe_hi + d_hi) / fe_hi);
  const double s = g_lo / (g_lo - g_hi);
  return std::exp(std::log(m_lo) + s * (std::log(m_hi) - std::log(m_lo)));
}

void bench_case(const Case& c, const Args& a) {
  std::printf("\n# grid %s: %ld nodes, h = %g m, dt_mech = %.4g s, dt_FE = %.4g s = %.0f dt_mech\n",
              c.name.c_str(), c.nodes(), a.h, c.dt_mech, c.dt_fe, c.dt_fe / c.dt_mech);
  std::vector<double> ends;
  for (double m : a.windows) ends.push_back(m * c.dt_mech * (m == a.windows.back() ? a.count_last : a.count));
  const auto ref = reference(c, ends, c.nodes() > a.klu_max_nodes ? "pcg" : "klu");
  std::printf("%-8s %8s %10s %-15s %3s %11s %10s %9s %9s %9s %10s\n", "grid", "m", "window_s", "integrator", "nw",
              "ms/window", "ns/node/w", "steps/w", "rhs/w", "lin/w", "max_err_K");
  std::map<std::string, std::map<double, double>> wall;  // config → m → s per window
  for (double m : a.windows) {
    const int count = m == a.windows.back() ? a.count_last : a.count;
    const Eigen::VectorXd& t_ref = ref.at(m * c.dt_mech * count);
    for (const auto& config : a.integrators) {
      const Result r = run(c, config, m, count, a);
      print_row(c, m, config, count, r, r.ok ? (r.t_end - t_ref).cwiseAbs().maxCoeff() : 0.0);
      if (r.ok) wall[config][m] = r.wall_per_window;
    }
  }
  // crossover against forward Euler
  for (const std::string bdf : {"cvode_bdf/klu", "cvode_bdf/pcg"}) {
    if (!wall.count(bdf) || !wall.count("forward_euler")) continue;
    auto& fe = wall["forward_euler"];
    auto& bd = wall[bdf];
    double found = 0.0, prev = 0.0;
    for (double m : a.windows) {
      if (bd.count(m) && fe.count(m) && bd[m] < fe[m]) {
        found = m;
        break;
      }
      prev = m;
    }
    double m = a.windows.back();
    const double step = std::sqrt(10.0);  // half a decade
    while (found == 0.0 && m * step <= a.crossover_max * (1 + 1e-9)) {  // extend beyond the list
      m *= step;
      if (!fe.count(m)) {  // shared by the klu and pcg searches
        const Result rf = run(c, "forward_euler", m, 2, a);
        if (!rf.ok) break;
        fe[m] = rf.wall_per_window;
        print_row(c, m, "forward_euler", 2, rf, NAN);
      }
      const Result rb = run(c, bdf, m, 2, a);
      print_row(c, m, bdf, 2, rb, NAN);
      if (!rb.ok) break;
      bd[m] = rb.wall_per_window;
      if (bd[m] < fe[m]) found = m;
      else prev = m;
    }
    if (found == 0.0) {
      std::printf("# crossover %s: %s never cheaper than forward_euler up to m = %g dt_mech\n", c.name.c_str(),
                  bdf.c_str(), m);
    } else if (prev == 0.0) {
      std::printf("# crossover %s: %s cheaper than forward_euler already at m = %g\n", c.name.c_str(), bdf.c_str(),
                  found);
    } else {
      const double est = crossover_estimate(prev, bd[prev] - fe[prev], fe[prev], found, bd[found] - fe[found],
                                            fe[found]);
      std::printf(
          "# crossover %s: %s cheaper than forward_euler from m = %g dt_mech (%.3g s, %.0f dt_FE); "
          "not at m = %g; log-interpolated m* ≈ %.2g dt_mech = %.0f dt_FE\n",
          c.name.c_str(), bdf.c_str(), found, found * c.dt_mech, found * c.dt_mech / c.dt_fe, prev, est,
          est * c.dt_mech / c.dt_fe);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  try {
    a = parse(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_thermal: %s\n", e.what());
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  std::printf("# thermal cost per coupling window; rtol %g, atol %g K, mode %s, dt_mech = %g·h/%g m/s\n", a.rtol,
              a.atol, a.mode.c_str(), a.cfl, a.wave_speed);
  std::printf("# m = window in mechanics steps, nw = windows run, per-window averages; "
              "max_err_K vs cvode_bdf rtol 1e-10\n");
  for (const auto& gname : a.grids) {
    if (gname != "2d" && gname != "3d") {
      std::fprintf(stderr, "bench_thermal: --grids takes 2d and/or 3d\n");
      return 2;
    }
    Case c = gname == "2d" ? make_2d(a) : make_3d(a);
    c.dt_mech = a.cfl * a.h / a.wave_speed;
    c.dt_fe = ft::forward_euler_dt_limit(ft::Problem(c.mass, c.k));
    bench_case(c, a);
  }
  std::printf("\n# total %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return 0;
}
