// PBX materials (mie_gruneisen.hpp): Mie-Grüneisen pressure against the Rankine–Hugoniot relations,
// the sound speed against an isentropic finite difference, J2 radial return against the yield
// surface, the simple-shear steady state and an independent plastic-work integral, plane strain
// against 3D. Parameters: table 1 of Nairn, Bardenhagen & Smith (HMX and binder).
#include <frictherm/mechanics/mie_gruneisen.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <string>

using namespace frictherm::mechanics;

namespace {
MieGruneisenParams hmx() {
  MieGruneisenParams m;
  m.density = 1891.0, m.C0 = 3070.0, m.S1 = 1.79, m.S2 = 0.0, m.gamma0 = 0.7;
  m.shear_modulus = 4.81e9, m.yield_stress = 260e6;
  return m;
}
MieGruneisenParams binder() {
  MieGruneisenParams m;
  m.density = 935.0, m.C0 = 1222.0, m.S1 = 3.4463, m.S2 = -3.447, m.gamma0 = 0.583;
  m.shear_modulus = 1.0e9;
  return m;
}
double rel(double a, double b) { return std::fabs(a - b) / std::max(std::fabs(b), 1e-300); }

// Shock velocity from the fit U_s = C0 + S1 u_p + S2 u_p²/U_s, i.e. the positive root of
// U_s² − (C0 + S1 u_p) U_s − S2 u_p² = 0: independent of how the EOS code writes its Hugoniot.
double shock_velocity(const MieGruneisenParams& m, double up) {
  const double b = m.C0 + m.S1 * up;
  return 0.5 * (b + std::sqrt(b * b + 4.0 * m.S2 * up * up));
}
template <int Dim>
double von_mises(const Mat<Dim>& s, double szz) {
  const double p = (s.trace() + (Dim == 2 ? szz : 0.0)) / 3.0;
  Mat<Dim> d = s;
  d.diagonal().array() -= p;
  const double dz = Dim == 2 ? szz - p : 0.0;
  return std::sqrt(1.5 * (d.squaredNorm() + dz * dz));
}
}  // namespace

TEST(PbxMaterials, PressureOnTheHugoniotIsRankineHugoniot) {
  // For a shock of particle velocity u_p: mass conservation gives η = 1 − ρ0/ρ = u_p/U_s, momentum
  // p = ρ0 U_s u_p, energy e_H = u_p²/2 (= p (V0 − V)/2 per unit mass). The EOS at (J = 1 − η, e_H)
  // must return p. Tolerance 1e-12 relative: a few tens of rounded operations with O(1) condition
  // numbers (the largest d(η)⁻² amplification here is < 10) give errors ~1e-14.
  for (const MieGruneisenParams& m : {hmx(), binder()}) {
    for (double up : {10.0, 100.0, 300.0, 800.0, 1500.0}) {
      const double Us = shock_velocity(m, up);
      const double eta = up / Us, J = 1.0 - eta;
      const double p_rh = m.density * Us * up;
      const double eH = 0.5 * up * up;
      EXPECT_LT(rel(eH, p_rh * eta / (2.0 * m.density)), 1e-13);  // the two energy forms agree
      EXPECT_LT(rel(mie_gruneisen_eos(m, J, eH).pressure, p_rh), 1e-12) << "u_p = " << up;
      EXPECT_LT(rel(hugoniot_pressure(m, J), p_rh), 1e-12) << "u_p = " << up;
    }
  }
}

TEST(PbxMaterials, TensionBranchAndContinuityAtTheReference) {
  for (const MieGruneisenParams& m : {hmx(), binder()}) {
    const double rc2 = m.density * m.C0 * m.C0;
    for (double J : {1.001, 1.01, 1.05})
      for (double e : {0.0, 2.0e4}) {  // p = ρ0 C0² μ + γ0 ρ0 e, μ = 1/J − 1 (1e-13: a handful of operations)
        const double expect = rc2 * (1.0 / J - 1.0) + m.gamma0 * m.density * e;
        EXPECT_LT(rel(mie_gruneisen_eos(m, J, e).pressure, expect), 1e-13);
      }
    // C¹ at J = 1: both branches have p = 0 and ∂p/∂η = ρ0 C0² there, and c = C0 exactly.
    EXPECT_EQ(mie_gruneisen_eos(m, 1.0, 0.0).pressure, 0.0);
    // (at η = ±1e-12 the slopes differ from ρ0 C0² by O((4 S1 + γ0) η) ≈ 1e-11)
    EXPECT_LT(rel(mie_gruneisen_eos(m, 1.0 - 1e-12, 0.0).dp_deta, rc2), 1e-10);
    EXPECT_LT(rel(mie_gruneisen_eos(m, 1.0 + 1e-12, 0.0).dp_deta, rc2), 1e-10);
    EXPECT_LT(rel(mie_gruneisen_eos(m, 1.0, 0.0).sound_speed, m.C0), 1e-15);
  }
}

TEST(PbxMaterials, SoundSpeedIsTheIsentropicDerivative) {
  // c² = dp/dρ along an isentrope, de = (p/ρ²) dρ. Central difference in ρ with the energy moved
  // along the isentrope to first order: e(ρ ± h) = e ± (p/ρ²) h + O(h²), and the O(h²) energy terms
  // cancel in the central difference, so the error is O(h²) ≈ (1e-5)² relative plus roundoff
  // ε p/(h c²) ≈ 1e-11: tolerance 1e-7.
  for (const MieGruneisenParams& m : {hmx(), binder()})
    for (double J : {1.02, 1.0 - 1e-3, 0.95, 0.85, 0.75})
      for (double e : {0.0, 5.0e4}) {
        const double rho = m.density / J, h = 1e-5 * rho;
        const MieGruneisenState s = mie_gruneisen_eos(m, J, e);
        const double de = s.pressure / (rho * rho) * h;
        const double pp = mie_gruneisen_eos(m, m.density / (rho + h), e + de).pressure;
        const double pm = mie_gruneisen_eos(m, m.density / (rho - h), e - de).pressure;
        const double c2_fd = (pp - pm) / (2.0 * h);
        EXPECT_LT(rel(s.sound_speed * s.sound_speed, c2_fd), 1e-7) << "J = " << J << ", e = " << e;
      }
  // The CFL speed adds the shear: sqrt(C0² + 4G/(3ρ0)) at the reference.
  const MieGruneisenParams m = hmx();
  EXPECT_LT(rel(mie_gruneisen_wave_speed(m, 1.0, 0.0), std::sqrt(m.C0 * m.C0 + 4.0 * m.shear_modulus / (3.0 * m.density))),
            1e-15);
}

TEST(PbxMaterials, HugoniotLimitingCompression) {
  // HMX (S2 = 0): d(η) = 1 − 1.79 η vanishes at η = 1/1.79. Binder: S1² + 4 S2 < 0, d > 0 always.
  EXPECT_NEAR(mie_gruneisen_min_J(hmx()), 1.0 - 1.0 / 1.79, 1e-15);
  EXPECT_EQ(mie_gruneisen_min_J(binder()), 0.0);
  MieGruneisenParams q = hmx();
  q.S1 = 1.5, q.S2 = 0.5;  // 0.5 η² + 1.5 η − 1 = 0 → η = (−1.5 + sqrt(4.25))/1
  EXPECT_NEAR(mie_gruneisen_min_J(q), 1.0 - (-1.5 + std::sqrt(4.25)), 1e-15);
  Mat<3> L = Mat<3>::Zero(), s = Mat<3>::Zero();
  double szz = 0.0, ep = 0.0, e = 0.0, wp = 0.0;
  EXPECT_EQ(mie_gruneisen_update<3>(L, 1e-9, 0.4, hmx(), s, szz, ep, e, wp), MieGruneisenStatus::beyond_hugoniot_limit);
  EXPECT_EQ(mie_gruneisen_update<3>(L, 1e-9, 0.4, binder(), s, szz, ep, e, wp), MieGruneisenStatus::ok);
}

TEST(PbxMaterials, SmallStrainIsLinearElasticWithBulkModulusRhoC0Squared) {
  // One step of strain 1e-7 from rest: σ = λ tr(ε) I + 2G ε with K = ρ0 C0², λ = K − 2G/3, to first
  // order; the nonlinear terms are O(strain) relative: tolerance 1e-5.
  for (const MieGruneisenParams& m : {hmx(), binder()}) {
    Mat<2> L;
    L << 1.0, 0.4, -0.2, -0.3;
    const double dt = 1e-7;
    const double J = (Mat<2>::Identity() + dt * L).determinant();
    Mat<2> s = Mat<2>::Zero(), ref = Mat<2>::Zero();
    double szz = 0.0, rzz = 0.0, ep = 0.0, e = 0.0, wp = 0.0;
    ASSERT_EQ(mie_gruneisen_update<2>(L, dt, J, m, s, szz, ep, e, wp), MieGruneisenStatus::ok);
    const double lam = m.density * m.C0 * m.C0 - 2.0 * m.shear_modulus / 3.0;
    linear_elastic_update<2>(L, dt, lam, m.shear_modulus, Analysis::plane_strain, ref, rzz);
    const double scale = ref.norm();
    EXPECT_LT((s - ref).norm() / scale, 1e-5);
    EXPECT_LT(std::fabs(szz - rzz) / scale, 1e-5);
    EXPECT_EQ(ep, 0.0);
    EXPECT_EQ(wp, 0.0);
  }
}

TEST(PbxMaterials, ElasticStepEqualsTheElasticUpdateExactly) {
  // Below yield the J2 update is the hypoelastic deviatoric update, bit for bit.
  Mat<3> L;
  L << 0.3, 1.0, 0.0, -0.5, -0.1, 0.2, 0.1, 0.0, -0.2;
  Mat<3> s0;
  s0 << 10e6, 20e6, 0.0, 20e6, -5e6, 1e6, 0.0, 1e6, -5e6;
  Mat<3> s = s0, ref = s0;
  double szz = 0.0, rzz = 0.0;
  const J2Increment inc = j2_deviatoric_update<3>(L, 1e-5, 4.81e9, 260e6, 0.0, 0.0, s, szz);
  linear_elastic_update<3>(L, 1e-5, -2.0 * 4.81e9 / 3.0, 4.81e9, Analysis::three_d, ref, rzz);
  ASSERT_LT(von_mises<3>(ref, 0.0), 260e6);
  EXPECT_EQ(inc.plastic_strain, 0.0);
  EXPECT_EQ(inc.plastic_work, 0.0);
  EXPECT_TRUE(s == ref);
}

TEST(PbxMaterials, ReturnMappingStaysOnTheYieldSurface) {
  // Random velocity gradients, with and without hardening: after every step q ≤ σ_y(ε̄p)(1 + 1e-12)
  // (the return puts q on the surface up to a few ulps), and a plastic step lands on it.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double H : {0.0, 2e8}) {
    MieGruneisenParams m = hmx();
    m.hardening_modulus = H;
    Mat<3> s3 = Mat<3>::Zero();
    Mat<2> s2 = Mat<2>::Zero();
    double z3 = 0.0, z2 = 0.0, ep3 = 0.0, ep2 = 0.0, e3 = 0.0, e2 = 0.0, J3 = 1.0, J2 = 1.0;
    int plastic = 0;
    for (int n = 0; n < 400; ++n) {
      Mat<3> L;
      for (int i = 0; i < 9; ++i) L.data()[i] = u(rng);
      const double dt = 1e-2;  // up to ~2 % strain per step, about the yield strain
      J3 *= (Mat<3>::Identity() + dt * L).determinant();
      double wp = 0.0;
      ASSERT_EQ(mie_gruneisen_update<3>(L, dt, J3, m, s3, z3, ep3, e3, wp), MieGruneisenStatus::ok);
      EXPECT_LE(von_mises<3>(s3, 0.0), (m.yield_stress + H * ep3) * (1.0 + 1e-12));
      const Mat<2> L2 = L.topLeftCorner<2, 2>();
      J2 *= (Mat<2>::Identity() + dt * L2).determinant();
      const double ep_before = ep2;
      ASSERT_EQ(mie_gruneisen_update<2>(L2, dt, J2, m, s2, z2, ep2, e2, wp), MieGruneisenStatus::ok);
      const double q = von_mises<2>(s2, z2), sy = m.yield_stress + H * ep2;
      EXPECT_LE(q, sy * (1.0 + 1e-12));
      if (ep2 > ep_before) {
        ++plastic;
        EXPECT_LT(rel(q, sy), 1e-12);
      }
    }
    EXPECT_GT(plastic, 50);
  }
}

TEST(PbxMaterials, SimpleShearSaturatesAtTheShearYieldStress) {
  // Monotonic simple shear L = γ̇ e_x ⊗ e_y, perfect plasticity. The Jaumann rotation gives normal
  // deviators ±a; the continuous steady state solves 0 = γ̇ t − 2Gλ̇ a, 0 = −γ̇ a + G γ̇ − 2Gλ̇ t and
  // 3(a² + t²) = σ_y²: a = k²/G, t = sqrt(k² − k⁴/G²), k = σ_y/√3, so t sits (k/G)²/2 ≈ 4.9e-4 below
  // σ_y/√3 for HMX (tolerance 1e-3 on that). After γ = 0.4 in steps Δγ = 1e-5 the transient has died
  // and the discrete state matches (t, a) to O(Δγ): tolerances 1e-6 on t (measured 4e-9) and 1e-4
  // on the small a (measured 4e-6).
  const MieGruneisenParams m = hmx();
  const double G = m.shear_modulus, k = m.yield_stress / std::sqrt(3.0);
  const double a_ss = k * k / G, t_ss = std::sqrt(k * k - a_ss * a_ss);
  Mat<2> L = Mat<2>::Zero();
  L(0, 1) = 1.0;
  const double dt = 1e-5;  // γ = 0.4 after 40000 steps
  Mat<2> s = Mat<2>::Zero();
  double szz = 0.0, ep = 0.0, e = 0.0, W = 0.0;
  for (int n = 0; n < 40000; ++n) {
    double wp = 0.0;
    ASSERT_EQ(mie_gruneisen_update<2>(L, dt, 1.0, m, s, szz, ep, e, wp), MieGruneisenStatus::ok);
    W += wp;
  }
  const double p = -(s.trace() + szz) / 3.0;
  EXPECT_LT(rel(s(0, 1), t_ss), 1e-6);
  EXPECT_LT(rel(s(0, 1), k), 1e-3);
  EXPECT_LT(rel(s(0, 0) + p, a_ss), 1e-4);
  // Isochoric (J = 1): the only energy is plastic work, so p = γ0 ρ0 e = γ0 Σ σ:Δε_p (roundoff: 1e-12),
  // and plane strain keeps s_zz = 0 (dε_zz = 0 and tr dε = 0): σ_zz = −p.
  EXPECT_LT(rel(p, m.gamma0 * W), 1e-12);
  EXPECT_LT(rel(szz, -p), 1e-12);
  EXPECT_LT(rel(W, m.yield_stress * ep), 1e-12);  // perfect plasticity: W = σ_y ε̄p
}

TEST(PbxMaterials, PlasticWorkIsTheIntegralOfStressTimesPlasticStrainRate) {
  // A non-proportional path (stretch, shear, rotation). Independently of the return map, each step's
  // plastic strain is what elasticity does not explain: Δε_p = dev(Δε) − (s_{n+1} − s_n^rot)/(2G)
  // (s_n^rot the Jaumann-rotated old deviator, zz components included in plane strain), and the
  // rectangle rule Σ s_{n+1}:Δε_p must equal the returned increments summed; the cancellation in
  // Δε_p costs ~ε|Δε|/|Δε_p| per step, far below the 1e-10 tolerance. Perfect plasticity also gives
  // W = σ_y ε̄p exactly (each step's work is σ_y Δε̄p): 1e-12.
  for (double H : {0.0, 5e8}) {
    MieGruneisenParams m = hmx();
    m.hardening_modulus = H;
    const double G = m.shear_modulus;
    Mat<2> s = Mat<2>::Zero();
    double szz = 0.0, ep = 0.0, W = 0.0, W_indep = 0.0, dep_indep = 0.0, sum_dep2 = 0.0;
    const int N = 20000;
    const double dt = 1e-5;  // shear γ = 0.2 in all
    for (int n = 0; n < N; ++n) {
      const double t = n * dt;
      Mat<2> L;
      L << 0.5 * std::cos(40.0 * t), 1.0, -0.3 + std::sin(25.0 * t), -0.2;
      const Mat<2> de = 0.5 * (L + L.transpose()) * dt, w = 0.5 * (L - L.transpose()) * dt;
      const Mat<2> s_rot = s + w * s - s * w;
      const double zz_old = szz;
      const J2Increment inc = j2_deviatoric_update<2>(L, dt, G, m.yield_stress, H, ep, s, szz);
      ep += inc.plastic_strain;
      W += inc.plastic_work;
      sum_dep2 += inc.plastic_strain * inc.plastic_strain;
      const double tr = de.trace();
      Mat<2> dp = de - (s - s_rot) / (2.0 * G);
      dp.diagonal().array() -= tr / 3.0;
      const double dpzz = -tr / 3.0 - (szz - zz_old) / (2.0 * G);
      W_indep += (s.cwiseProduct(dp)).sum() + szz * dpzz;
      dep_indep += std::sqrt(2.0 / 3.0 * (dp.squaredNorm() + dpzz * dpzz));
    }
    ASSERT_GT(ep, 0.05);
    EXPECT_LT(rel(W, W_indep), 1e-10);
    EXPECT_LT(rel(ep, dep_indep), 1e-8);  // ε̄p increments recovered from elasticity (cancellation)
    if (H == 0.0) {
      EXPECT_LT(rel(W, m.yield_stress * ep), 1e-12);
    }
    // With hardening each step's work is σ_y(ε̄p_{n+1}) Δε̄p (backward Euler), so the sum is exactly
    // ∫σ_y dε̄p = σ_y ε̄p + H ε̄p²/2 plus H Σ Δε̄p²/2 (telescoping): 1e-12.
    if (H > 0.0) {
      EXPECT_LT(rel(W, m.yield_stress * ep + 0.5 * H * (ep * ep + sum_dep2)), 1e-12);
    }
  }
}

TEST(PbxMaterials, AdiabaticCompressionFollowsTheIsentrope) {
  // Hydrostatic compression to J ≈ 0.8: no shear, so e must follow de/dJ = −p(J, e)/ρ0. Reference:
  // RK4 with 40000 steps to the same J (error < 1e-14). The update's trapezoidal rule is second order:
  // 2000 steps err by ~1e-7 relative (tolerance 1e-6) and halving the step divides the error by 4
  // (asserted within [3.6, 4.4]).
  for (const MieGruneisenParams& m : {hmx(), binder()}) {
    double err[2] = {0.0, 0.0};
    for (int pass = 0; pass < 2; ++pass) {
      const int N = 1000 << pass;
      const double rate = -std::log(0.8) / 3.0, dt = 1.0 / N;  // L = −rate I over unit time
      const Mat<3> L = -rate * Mat<3>::Identity();
      Mat<3> s = Mat<3>::Zero();
      double J = 1.0, szz = 0.0, ep = 0.0, e = 0.0, wp = 0.0;
      for (int n = 0; n < N; ++n) {
        J *= (Mat<3>::Identity() + dt * L).determinant();
        ASSERT_EQ(mie_gruneisen_update<3>(L, dt, J, m, s, szz, ep, e, wp), MieGruneisenStatus::ok);
      }
      auto f = [&](double Jx, double ex) { return -mie_gruneisen_eos(m, Jx, ex).pressure / m.density; };
      const int M = 40000;
      double Jr = 1.0, er = 0.0;
      const double h = (J - 1.0) / M;
      for (int n = 0; n < M; ++n) {
        const double k1 = f(Jr, er), k2 = f(Jr + h / 2, er + h / 2 * k1), k3 = f(Jr + h / 2, er + h / 2 * k2),
                     k4 = f(Jr + h, er + h * k3);
        er += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        Jr += h;
      }
      err[pass] = rel(e, er);
      const double p = -s.trace() / 3.0;
      EXPECT_LT(rel(p, mie_gruneisen_eos(m, J, er).pressure), 1e-6);
      EXPECT_LT((s + p * Mat<3>::Identity()).norm(), 1e-9 * p);  // stays hydrostatic
      EXPECT_LT(p, hugoniot_pressure(m, J));  // the isentrope lies below the Hugoniot (a shock adds entropy)
    }
    EXPECT_LT(err[1], 1e-6);
    EXPECT_GT(err[0] / err[1], 3.6);
    EXPECT_LT(err[0] / err[1], 4.4);
  }
}

TEST(PbxMaterials, PlaneStrainIsThe3DUpdateWithZeroOutOfPlaneVelocity) {
  // Embedding L in 3D with a zero third row and column must give the 3D stress with σ_33 = σ_zz, the
  // same ε̄p, energy and plastic work (only the summation order differs: 1e-12).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const MieGruneisenParams m = hmx();
  Mat<2> s2 = Mat<2>::Zero();
  Mat<3> s3 = Mat<3>::Zero();
  double z2 = 0.0, z3 = 0.0, ep2 = 0.0, ep3 = 0.0, e2 = 0.0, e3 = 0.0, J = 1.0, W2 = 0.0, W3 = 0.0;
  for (int n = 0; n < 300; ++n) {
    Mat<2> L2;
    for (int i = 0; i < 4; ++i) L2.data()[i] = u(rng);
    Mat<3> L3 = Mat<3>::Zero();
    L3.topLeftCorner<2, 2>() = L2;
    const double dt = 2e-3;
    J *= (Mat<2>::Identity() + dt * L2).determinant();
    double wp2 = 0.0, wp3 = 0.0;
    ASSERT_EQ(mie_gruneisen_update<2>(L2, dt, J, m, s2, z2, ep2, e2, wp2), MieGruneisenStatus::ok);
    ASSERT_EQ(mie_gruneisen_update<3>(L3, dt, J, m, s3, z3, ep3, e3, wp3), MieGruneisenStatus::ok);
    W2 += wp2, W3 += wp3;
  }
  const double scale = s3.norm();
  EXPECT_LT((s2 - s3.topLeftCorner<2, 2>()).norm() / scale, 1e-12);
  EXPECT_LT(std::fabs(z2 - s3(2, 2)) / scale, 1e-12);
  EXPECT_LT(std::fabs(s3(0, 2)) + std::fabs(s3(1, 2)), 1e-12 * scale);
  EXPECT_EQ(z3, 0.0);
  EXPECT_GT(ep2, 0.0);
  EXPECT_LT(rel(ep2, ep3), 1e-12);
  EXPECT_LT(rel(e2, e3), 1e-12);
  EXPECT_LT(rel(W2, W3), 1e-12);
}

TEST(PbxMaterials, ValidationNamesTheParameter) {
  EXPECT_NO_THROW(validate(hmx(), Analysis::plane_strain));
  EXPECT_NO_THROW(validate(binder(), Analysis::three_d));
  auto message = [](MieGruneisenParams m, Analysis a = Analysis::plane_strain) {
    try {
      validate(m, a, "materials.hmx");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  auto with = [](double MieGruneisenParams::*field, double value) {
    MieGruneisenParams m = hmx();
    m.*field = value;
    return m;
  };
  const struct { double MieGruneisenParams::*field; double value; const char* name; } cases[] = {
      {&MieGruneisenParams::density, 0.0, "materials.hmx.density"},
      {&MieGruneisenParams::C0, -1.0, "materials.hmx.C0"},
      {&MieGruneisenParams::S1, std::nan(""), "materials.hmx.S1"},
      {&MieGruneisenParams::S1, 20.0, "materials.hmx.S1"},  // Hugoniot singular at 5 % compression
      {&MieGruneisenParams::S2, INFINITY, "materials.hmx.S2"},
      {&MieGruneisenParams::gamma0, -0.1, "materials.hmx.gamma0"},
      {&MieGruneisenParams::shear_modulus, -1.0, "materials.hmx.shear_modulus"},
      {&MieGruneisenParams::yield_stress, 0.0, "materials.hmx.yield_stress"},
      {&MieGruneisenParams::hardening_modulus, -5.0, "materials.hmx.hardening_modulus"},
  };
  for (const auto& c : cases) EXPECT_NE(message(with(c.field, c.value)).find(c.name), std::string::npos) << message(with(c.field, c.value));
  EXPECT_NE(message(hmx(), Analysis::plane_stress).find("plane_stress"), std::string::npos);
}

TEST(PbxMaterials, LibraryFileHoldsTable1) {
  // examples/materials/pbx_table1.json: the keys are the parameter names; values must be table 1's
  // (SI) and pass validation; every key of a material is a known parameter.
  std::ifstream in(std::string(FRICTHERM_SOURCE_DIR) + "/examples/materials/pbx_table1.json");
  ASSERT_TRUE(in.good());
  const nlohmann::json lib = nlohmann::json::parse(in, nullptr, true, true);
  auto load = [&](const std::string& name) {
    MieGruneisenParams m;
    for (const auto& [key, v] : lib.at("materials").at(name).items()) {
      if (key == "type") EXPECT_EQ(v.get<std::string>(), "mie_gruneisen");
      else if (key == "density") m.density = v.get<double>();
      else if (key == "C0") m.C0 = v.get<double>();
      else if (key == "S1") m.S1 = v.get<double>();
      else if (key == "S2") m.S2 = v.get<double>();
      else if (key == "gamma0") m.gamma0 = v.get<double>();
      else if (key == "shear_modulus") m.shear_modulus = v.get<double>();
      else if (key == "yield_stress") m.yield_stress = v.get<double>();
      else if (key == "hardening_modulus") m.hardening_modulus = v.get<double>();
      else ADD_FAILURE() << "unknown key " << key;
    }
    validate(m, Analysis::plane_strain, "materials." + name);
    return m;
  };
  auto same = [](const MieGruneisenParams& a, const MieGruneisenParams& b) {
    return a.density == b.density && a.C0 == b.C0 && a.S1 == b.S1 && a.S2 == b.S2 && a.gamma0 == b.gamma0 &&
           a.shear_modulus == b.shear_modulus && a.yield_stress == b.yield_stress &&
           a.hardening_modulus == b.hardening_modulus;
  };
  EXPECT_TRUE(same(load("hmx"), hmx()));
  EXPECT_TRUE(same(load("binder"), binder()));
  const auto& th = lib.at("thermal").at("materials");
  EXPECT_EQ(th.at("hmx").at("heat_capacity").get<double>(), 950.0);
  EXPECT_EQ(th.at("binder").at("heat_capacity").get<double>(), 2280.0);
  EXPECT_GT(th.at("hmx").at("conductivity").get<double>(), 0.0);
  EXPECT_GT(th.at("binder").at("conductivity").get<double>(), 0.0);
}
