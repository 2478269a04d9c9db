// Axial vibration of an elastic bar started in its first mode. With ν = 0 the 1D wave speed
// c = √(E/ρ) is exact in plane stress and in 3D.
//  * fixed at x = 0, free at x = L: v(x, 0) = v0 sin(πx/2L), T = 4L/c, and the centre-of-mass
//    velocity is v_cm(t) = (2 v0/π) cos(2πt/T);
//  * free-free: v(x, 0) = v0 cos(πx/L), T = 2L/c, and the mean velocity of the left half follows
//    the same (2 v0/π) cos(2πt/T). Used for quadratic B-splines, whose basis is not interpolatory
//    at a fixed face (fixing the face node and its ghost moves the effective support by O(h)).
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kL = 1.0, kE = 1e8, kRho = 1000.0, kV0 = 0.1;

struct VibrationResult {
  double period = 0.0;           // from upward zero crossings of v_cm
  double max_velocity_error = 0.0;  // max |v_cm − exact| / (2 v0/π)
  double energy_drift = 0.0;     // max |E(t) − E(0)| / E(0)
};

template <int Dim>
VibrationResult vibrate(ShapeKind shape, UpdateScheme scheme, double h, int periods, bool fixed = true) {
  Vec<Dim> lo = Vec<Dim>::Constant(0.0), hi = Vec<Dim>::Constant(4 * h);
  hi[0] = kL + 4 * h;
  IVec<Dim> cells;
  for (int d = 0; d < Dim; ++d) cells[d] = static_cast<int>(std::lround(hi[d] / h));
  SimulationOptions o;
  o.analysis = Dim == 2 ? Analysis::plane_stress : Analysis::three_d;
  o.shape = shape;
  o.scheme = scheme;
  o.cfl = 0.5;
  Simulation<Dim> sim(Grid<Dim>(lo, Vec<Dim>::Constant(h), cells), o);
  Material m;
  m.name = "bar";
  m.density = kRho;
  m.youngs_modulus = kE;
  m.poisson_ratio = 0.0;
  const int mat = sim.add_material(m);
  Vec<Dim> blo = Vec<Dim>::Constant(h), bhi = Vec<Dim>::Constant(3 * h);
  blo[0] = 0.0;
  bhi[0] = kL;
  sim.add_body("bar", *make_box<Dim>(blo, bhi, mat), 2, Vec<Dim>::Zero());
  if (fixed) sim.fix_face(FixedFace{0, false, {{true, false, false}}});  // x = 0: u_x = 0, free laterally
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double x = p.position[k][0];
    p.velocity[k][0] = fixed ? kV0 * std::sin(M_PI * x / (2 * kL)) : kV0 * std::cos(M_PI * x / kL);
  }
  // Tracked velocity: centre of mass (fixed-free) or left half (free-free).
  auto tracked = [&]() {
    double mv = 0.0, mass = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (fixed || p.initial_position[k][0] < 0.5 * kL) mv += p.mass[k] * p.velocity[k][0], mass += p.mass[k];
    return mv / mass;
  };
  const double c = std::sqrt(kE / kRho);
  const double T = (fixed ? 4.0 : 2.0) * kL / c, amp = 2.0 * kV0 / M_PI;
  const double E0 = sim.kinetic_energy() + sim.strain_energy();
  VibrationResult r;
  std::vector<double> crossings;
  double prev_v = tracked(), prev_t = 0.0;
  while (sim.time() < periods * T) {
    sim.step();
    const double t = sim.time(), v = tracked();
    r.max_velocity_error = std::max(r.max_velocity_error, std::abs(v - amp * std::cos(2 * M_PI * t / T)) / amp);
    r.energy_drift = std::max(r.energy_drift, std::abs(sim.kinetic_energy() + sim.strain_energy() - E0) / E0);
    if (prev_v < 0.0 && v >= 0.0) crossings.push_back(prev_t + (t - prev_t) * (-prev_v) / (v - prev_v));
    prev_v = v;
    prev_t = t;
  }
  if (crossings.size() >= 2) r.period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  std::printf("[bar vibration %dD %s %s h=%g %s] period error %.3e, max v_cm error %.3e of amplitude, energy drift %.3e\n",
              Dim, to_string(shape), to_string(scheme), h, fixed ? "fixed-free" : "free-free", r.period / T - 1.0, r.max_velocity_error, r.energy_drift);
  return r;
}

}  // namespace

// Tolerances: the issue asks for the period within 1 %. The semi-discrete error of the first mode is
// O((kh)²) ≈ (π h / 2L)² ≈ 1e-3 at h = L/50, and the time integration adds O((ω dt)²); 1 % leaves
// room for both. The centre-of-mass velocity follows from the same mode, so its error is bounded by
// the accumulated phase error 2π·periods·(period error) plus the amplitude loss; 3 % of the
// amplitude over three periods. Energy: MUSL with FLIP is nearly conservative; 2 % bounds the drift
// seen on this mesh (the figure is printed for the record).
TEST(BarVibration, Period2DUGIMPMusl) {
  const auto r = vibrate<2>(ShapeKind::ugimp, UpdateScheme::musl, 0.02, 3);
  const double T = 4.0 * kL / std::sqrt(kE / kRho);
  EXPECT_NEAR(r.period, T, 0.01 * T);
  EXPECT_LT(r.max_velocity_error, 0.03);
  EXPECT_LT(r.energy_drift, 0.02);
}

TEST(BarVibration, Period2DEveryShapeAndScheme) {
  const double T = 4.0 * kL / std::sqrt(kE / kRho);
  for (ShapeKind s : {ShapeKind::linear, ShapeKind::ugimp, ShapeKind::quadratic_bspline})
    for (UpdateScheme u : {UpdateScheme::usf, UpdateScheme::usl, UpdateScheme::musl}) {
      const bool fixed = s != ShapeKind::quadratic_bspline;
      const auto r = vibrate<2>(s, u, 0.025, 2, fixed);
      EXPECT_NEAR(r.period, fixed ? T : T / 2, 0.01 * T) << to_string(s) << " " << to_string(u);
      // Quadratic B-splines lose ~2 % of the energy over two periods (the wider kernel's MUSL
      // projection), which shows as amplitude loss in the tracked velocity: allow 5 % there.
      EXPECT_LT(r.max_velocity_error, fixed ? 0.03 : 0.05) << to_string(s) << " " << to_string(u);
    }
}

TEST(BarVibration, Period3DUGIMPMusl) {
  const auto r = vibrate<3>(ShapeKind::ugimp, UpdateScheme::musl, 0.04, 2);
  const double T = 4.0 * kL / std::sqrt(kE / kRho);
  EXPECT_NEAR(r.period, T, 0.01 * T);
  EXPECT_LT(r.max_velocity_error, 0.03);
  EXPECT_LT(r.energy_drift, 0.02);
}

TEST(BarVibration, Period3DQuadraticBSpline) {
  const auto r = vibrate<3>(ShapeKind::quadratic_bspline, UpdateScheme::musl, 0.025, 2, /*fixed=*/false);
  const double T = 2.0 * kL / std::sqrt(kE / kRho);
  EXPECT_NEAR(r.period, T, 0.01 * T);
  EXPECT_LT(r.max_velocity_error, 0.05);  // as in 2D: amplitude loss of the B-spline projection
}
