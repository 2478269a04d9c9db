// Friction laws and frictional work (Nairn, Bardenhagen & Smith 2018 §2.6–2.10, eqs. 42–43) against
// analytic relations. Notation: N* = −d_n = N A_c dt, s = S_slide A_c dt, final speed v = (d_t − s)/m_red.
//
// Tolerances: a closed form costs O(10) roundings of 2^-53 ≈ 1.1e-16, so its residual in the implicit
// law is ~1e-15 relative; the root finder stops at a bracket 1e-14 wide (relative), so its residual is
// (1 + |dh/ds|)·1e-14 with |dh/ds| = N* |dS/dv|/(N m_red) ≤ 1 for the parameters below. Hence 1e-12
// for the implicit relations and 1e-10 between a closed form and the root finder.
#include <frictherm/mechanics/friction.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

using namespace frictherm::mechanics;

namespace {
constexpr double kImplicitTol = 1e-12;
constexpr double kSolverTol = 1e-10;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// A representative contact node: m_red = 2e-6 kg, A_c = 1e-6 m², dt = 1e-7 s, N = 1 MPa → N* = 1e-7 kg m/s.
constexpr double kM = 2e-6, kA = 1e-6, kDt = 1e-7, kN = 1e6, kNstar = kN * kA * kDt;

ContactImpulse node(double d_t, double n_star = kNstar, double m = kM, double area = kA, double dt = kDt) {
  return {-n_star, d_t, m, area, dt};
}

// Sliding outcome that satisfies eq. 21/22: s = A_c dt S(N, A_c, (d_t − s)/m_red), with 0 ≤ s < d_t.
void expect_law_at_final_speed(const FrictionLaw& law, const SlidingTraction& S, const ContactImpulse& c) {
  const FrictionOutcome o = law.in_contact(c);
  ASSERT_FALSE(o.stick) << law.describe();
  const double s = o.slide_impulse;
  EXPECT_GE(s, 0.0) << law.describe();
  EXPECT_LT(s, c.tangential) << law.describe();
  const double N = -c.normal / (c.area * c.dt);
  const double implied = c.area * c.dt * S(N, c.area, (c.tangential - s) / c.reduced_mass);
  EXPECT_NEAR(s, implied, kImplicitTol * implied) << law.describe();
}

double smooth_mu(double mu_s, double mu_d, double v_half, double v) {  // eq. 42
  return (mu_s * v_half + mu_d * v) / (v_half + v);
}

template <class F>
void expect_invalid(F&& make, const std::string& param) {
  try {
    make();
    ADD_FAILURE() << "no exception for bad " << param;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(param), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(Friction, StickAndFrictionless) {
  EXPECT_TRUE(FrictionLaw::stick().in_contact(node(1.0)).stick);
  EXPECT_TRUE(FrictionLaw().in_contact(node(1.0)).stick);  // default law sticks
  const FrictionOutcome slide = FrictionLaw::frictionless().in_contact(node(1e-7));
  EXPECT_FALSE(slide.stick);
  EXPECT_EQ(slide.slide_impulse, 0.0);
  EXPECT_TRUE(FrictionLaw::frictionless().in_contact(node(0.0)).stick);  // nothing to slide
}

TEST(Friction, CoulombSatisfiesLawAndExactThreshold) {
  const double mu = 0.3;
  expect_law_at_final_speed(FrictionLaw::coulomb(mu), [mu](double N, double, double) { return mu * N; },
                            node(3e-7));
  // d_n = −2, mu = 0.25: mu N* = 0.5 exactly. d_t = mu N* sticks (S_stick = S_slide), one ulp more slides.
  const FrictionLaw c = FrictionLaw::coulomb(0.25);
  EXPECT_TRUE(c.in_contact(node(0.5, 2.0, 1.0, 1.0, 1.0)).stick);
  const FrictionOutcome o = c.in_contact(node(std::nextafter(0.5, 1.0), 2.0, 1.0, 1.0, 1.0));
  EXPECT_FALSE(o.stick);
  EXPECT_EQ(o.slide_impulse, 0.5);  // eq. 20: Δp'_a·t̂ = −mu d_n
}

TEST(Friction, LinearVelocityClosedFormSolvesEq22) {
  const double mu0 = 0.2, k = 0.5;  // k N*/m_red = 0.025
  const SlidingTraction S = [=](double N, double, double v) { return (mu0 + k * v) * N; };
  const FrictionLaw law = FrictionLaw::linear_velocity(mu0, k);
  for (double d_t : {2.0000001e-8, 3e-7, 1e-5}) expect_law_at_final_speed(law, S, node(d_t));
  // Closed form against the generic root finder on the same S.
  const FrictionLaw generic = FrictionLaw::user(S, "linear");
  for (double d_t : {3e-7, 1e-5}) {
    const double a = law.in_contact(node(d_t)).slide_impulse, b = generic.in_contact(node(d_t)).slide_impulse;
    EXPECT_NEAR(a, b, kSolverTol * a);
  }
  // The printed eq. 23 denominator (m_red + k d_n) violates eq. 22; m_red − k d_n is the solution.
  const double d_t = 1e-5, d_n = -kNstar;
  const double printed = -d_n * (kM * mu0 + k * d_t) / (kM + k * d_n);
  const double s = law.in_contact(node(d_t)).slide_impulse;
  EXPECT_NEAR(s, -d_n * (kM * mu0 + k * d_t) / (kM - k * d_n), 1e-15 * s);
  EXPECT_GT(std::abs(printed - S(kN, kA, (d_t - printed) / kM) * kA * kDt), 1e-3 * printed);
  // Threshold: the law at v' = 0.
  EXPECT_TRUE(law.in_contact(node(mu0 * kNstar)).stick);
}

TEST(Friction, AdhesionSlidingAndThreshold) {
  const double mu = 0.2, Sa = 3e5;
  const FrictionLaw law = FrictionLaw::adhesion(mu, Sa);
  expect_law_at_final_speed(law, [=](double N, double, double) { return Sa + mu * N; }, node(1e-7));
  EXPECT_TRUE(law.needs_area());
  // Eq. 24 threshold with exactly representable numbers: S_a A dt = 2·0.25 = 0.5, mu N* = 0.5·1 = 0.5.
  const FrictionLaw exact = FrictionLaw::adhesion(0.5, 2.0);
  EXPECT_TRUE(exact.in_contact(node(1.0, 1.0, 1.0, 0.5, 0.5)).stick);
  const FrictionOutcome o = exact.in_contact(node(std::nextafter(1.0, 2.0), 1.0, 1.0, 0.5, 0.5));
  EXPECT_FALSE(o.stick);
  EXPECT_EQ(o.slide_impulse, 1.0);
}

TEST(Friction, AdhesionTensileEllipseEq25) {
  const double Sa = 2e6, Na = 5e6;
  const FrictionLaw law = FrictionLaw::adhesion(0.3, Sa, Na);
  EXPECT_TRUE(law.holds_when_separated(0.5 * Sa, -0.5 * Na));     // 0.25 + 0.25 < 1: inside
  EXPECT_TRUE(law.holds_when_separated(Sa, 0.0));                 // on the ellipse (exactly 1): holds
  EXPECT_TRUE(law.holds_when_separated(0.0, -Na));
  const double c = std::sqrt(0.5);                                // (c² + c²) = 1 within 1 ulp
  EXPECT_TRUE(law.holds_when_separated(c * (1 - 1e-9) * Sa, -c * (1 - 1e-9) * Na));
  EXPECT_FALSE(law.holds_when_separated(c * (1 + 1e-9) * Sa, -c * (1 + 1e-9) * Na));  // outside
  EXPECT_FALSE(law.holds_when_separated(Sa * (1 + 1e-12), 0.0));
  EXPECT_FALSE(law.holds_when_separated(0.0, -Na * (1 + 1e-12)));
  EXPECT_FALSE(law.holds_when_separated(kNaN, 0.0));
  // No tensile strength given, or another law: separated surfaces move freely.
  EXPECT_FALSE(FrictionLaw::adhesion(0.3, Sa).holds_when_separated(0.0, 0.0));
  EXPECT_FALSE(FrictionLaw::coulomb(0.3).holds_when_separated(0.0, 0.0));
  // S_a = 0: any shear breaks the bond, pure tension below N_a holds.
  const FrictionLaw no_shear = FrictionLaw::adhesion(0.3, 0.0, Na);
  EXPECT_FALSE(no_shear.holds_when_separated(1e-3, 0.0));
  EXPECT_TRUE(no_shear.holds_when_separated(0.0, -0.9 * Na));
}

TEST(Friction, NaiveStaticDynamic) {
  const double mu_s = 0.4, mu_d = 0.2;
  const FrictionLaw law = FrictionLaw::static_dynamic(mu_s, mu_d);
  expect_law_at_final_speed(law, [=](double N, double, double) { return mu_d * N; }, node(5e-7));
  // Stick test with mu_s (exact numbers: mu_s N* = 0.5·1 = 0.5), then slide with mu_d N*.
  const FrictionLaw exact = FrictionLaw::static_dynamic(0.5, 0.25);
  EXPECT_TRUE(exact.in_contact(node(0.5, 1.0, 1.0, 1.0, 1.0)).stick);
  const FrictionOutcome o = exact.in_contact(node(std::nextafter(0.5, 1.0), 1.0, 1.0, 1.0, 1.0));
  EXPECT_FALSE(o.stick);
  EXPECT_EQ(o.slide_impulse, 0.25);
}

TEST(Friction, SmoothStaticDynamicSolvesEq42) {
  const double mu_s = 0.4, mu_d = 0.2;
  for (double v_half : {0.01, 0.05, 1.0}) {
    const SlidingTraction S = [=](double N, double, double v) { return smooth_mu(mu_s, mu_d, v_half, v) * N; };
    const FrictionLaw law = FrictionLaw::smooth_static_dynamic(mu_s, mu_d, v_half);
    const FrictionLaw generic = FrictionLaw::user(S, "smooth");
    for (double d_t : {4.0000001e-8, 6e-8, 3e-7, 1e-5}) {  // just above mu_s N* = 4e-8 up to 5 m/s
      expect_law_at_final_speed(law, S, node(d_t));
      const double a = law.in_contact(node(d_t)).slide_impulse, b = generic.in_contact(node(d_t)).slide_impulse;
      EXPECT_NEAR(a, b, kSolverTol * a) << "v_half " << v_half << " d_t " << d_t;
    }
  }
  // Exact stick threshold with mu_s: mu_s N* = 0.5·1.
  const FrictionLaw exact = FrictionLaw::smooth_static_dynamic(0.5, 0.25, 1.0);
  EXPECT_TRUE(exact.in_contact(node(0.5, 1.0, 1.0, 1.0, 1.0)).stick);
  EXPECT_FALSE(exact.in_contact(node(std::nextafter(0.5, 1.0), 1.0, 1.0, 1.0, 1.0)).stick);
  // mu_d > mu_s (velocity strengthening) is still the root in (0, d_t).
  const SlidingTraction up = [](double N, double, double v) { return smooth_mu(0.2, 0.4, 0.05, v) * N; };
  expect_law_at_final_speed(FrictionLaw::smooth_static_dynamic(0.2, 0.4, 0.05), up, node(3e-7));
  // Double root at the stick boundary: k* = v½ m = (mu_s − mu_d) N* → v½ = 0.2·1e-7/2e-6 = 0.01 m/s.
  const FrictionOutcome o = FrictionLaw::smooth_static_dynamic(mu_s, mu_d, 0.01).in_contact(node(4e-8 * (1 + 1e-12)));
  EXPECT_FALSE(o.stick);
  EXPECT_TRUE(std::isfinite(o.slide_impulse));
  EXPECT_LT(o.slide_impulse, 4e-8 * (1 + 1e-12));
}

TEST(Friction, SmoothLawLimits) {
  // mu(v) = mu_s − (mu_s − mu_d) v/(v½ + v): |s/N* − mu_s| ≤ (mu_s − mu_d) v_max/v½ with v_max = d_t/m_red,
  // and |s/N* − mu_d| ≤ (mu_s − mu_d) v½/v_min with v_min = (d_t − mu_s N*)/m_red (s < mu_s N* when sliding).
  const double mu_s = 0.4, mu_d = 0.2, d_t = 3e-7, v_max = d_t / kM, v_min = (d_t - mu_s * kNstar) / kM;
  const double big = 1e9, tiny = 1e-9;
  const double s_big = FrictionLaw::smooth_static_dynamic(mu_s, mu_d, big).in_contact(node(d_t)).slide_impulse;
  EXPECT_NEAR(s_big, FrictionLaw::coulomb(mu_s).in_contact(node(d_t)).slide_impulse,
              (mu_s - mu_d) * v_max / big * kNstar + 1e-14 * s_big);  // + roundoff
  const double s_tiny = FrictionLaw::smooth_static_dynamic(mu_s, mu_d, tiny).in_contact(node(d_t)).slide_impulse;
  EXPECT_NEAR(s_tiny, mu_d * kNstar, (mu_s - mu_d) * tiny / v_min * kNstar + 1e-14 * s_tiny);
}

// The composite law (eq 21 with every term) reproduces each closed-form law it contains, and with all
// terms at once satisfies eq 21 at its final sliding speed.
TEST(Friction, CompositeReproducesItsPartsAndSolvesEq21) {
  for (double d_t : {6e-8, 3e-7, 1e-5}) {
    auto same = [&](const FrictionLaw& composite, const FrictionLaw& closed) {
      const FrictionOutcome a = composite.in_contact(node(d_t)), b = closed.in_contact(node(d_t));
      ASSERT_EQ(a.stick, b.stick) << composite.describe();
      EXPECT_NEAR(a.slide_impulse, b.slide_impulse, kSolverTol * b.slide_impulse) << composite.describe() << " d_t " << d_t;
    };
    same(FrictionLaw::composite(0.3, 0.3, kInf, 0.0, 0.0), FrictionLaw::coulomb(0.3));
    same(FrictionLaw::composite(0.2, 0.2, kInf, 0.05, 0.0), FrictionLaw::linear_velocity(0.2, 0.05));
    same(FrictionLaw::composite(0.2, 0.2, kInf, 0.0, 1e3), FrictionLaw::adhesion(0.2, 1e3));
    same(FrictionLaw::composite(0.4, 0.2, 0.05, 0.0, 0.0), FrictionLaw::smooth_static_dynamic(0.4, 0.2, 0.05));
    const double k = 0.02, S_a = 500.0;
    const SlidingTraction S = [=](double N, double, double v) { return (smooth_mu(0.35, 0.2, 0.05, v) + k * v) * N + S_a; };
    expect_law_at_final_speed(FrictionLaw::composite(0.35, 0.2, 0.05, k, S_a), S, node(d_t));
  }
  // Tensile strength: separated surfaces hold inside the ellipse of eq 25, as the adhesion law.
  const FrictionLaw c = FrictionLaw::composite(0.3, 0.2, 0.05, 0.0, 2.0, 4.0);
  EXPECT_TRUE(c.holds_when_separated(1.0, 2.0));
  EXPECT_FALSE(c.holds_when_separated(2.0, 2.0));
  EXPECT_FALSE(FrictionLaw::composite(0.3, 0.2, 0.05, 0.0, 2.0).holds_when_separated(1.0, 1.0));
  EXPECT_THROW(FrictionLaw::composite(0.3, 0.2, 0.0, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(FrictionLaw::composite(0.3, 0.2, 0.05, -1.0, 0.0), std::invalid_argument);
}

TEST(Friction, UserLawRootFinder) {
  // Nonlinear in speed and area-dependent: S = (0.25 + 0.15 exp(−v/0.03)) N + 2e5 √(A_c/1e-6 m²) Pa.
  const SlidingTraction S = [](double N, double A, double v) {
    return (0.25 + 0.15 * std::exp(-v / 0.03)) * N + 2e5 * std::sqrt(A / 1e-6);
  };
  const FrictionLaw law = FrictionLaw::user(S, "wear");
  EXPECT_EQ(law.kind(), FrictionKind::user);
  EXPECT_TRUE(law.needs_area());
  for (double d_t : {6.01e-8, 1e-7, 3e-7, 1e-5}) expect_law_at_final_speed(law, S, node(d_t));
  expect_law_at_final_speed(law, S, node(3e-7, kNstar, kM, 4e-6));
  // Threshold: A_c dt S(N, A_c, 0) = (0.4·1e6 + 2e5)·1e-13 = 6e-8.
  EXPECT_TRUE(law.in_contact(node(5.99e-8)).stick);
  // A law that is zero at the largest speed slides freely there.
  EXPECT_EQ(FrictionLaw::user([](double, double, double) { return 0.0; }).in_contact(node(1e-7)).slide_impulse, 0.0);
}

TEST(Friction, UserLawErrorsNameLawAndArguments) {
  const FrictionLaw negative = FrictionLaw::user([](double, double, double v) { return 1e6 - 1e8 * v; }, "broken");
  try {
    negative.in_contact(node(1e-5));  // S(v=0) > 0 passes the stick test, S(5 m/s) < 0
    ADD_FAILURE() << "negative S accepted";
  } catch (const std::domain_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'broken'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("N = "), std::string::npos) << msg;
    EXPECT_NE(msg.find("sliding speed = "), std::string::npos) << msg;
  }
  const FrictionLaw nan_law = FrictionLaw::user([](double, double, double) { return kNaN; }, "nan_law");
  EXPECT_THROW(nan_law.in_contact(node(1e-7)), std::domain_error);
  EXPECT_THROW(FrictionLaw::user([](double N, double, double) { return N; }).in_contact(node(1e-7, kNstar, kM, 0.0)),
               std::domain_error);  // area-dependent law given no area
}

TEST(Friction, TabulatedLaw) {
  // mu = 0.4 at v ≤ 0.01, linear to 0.2 at v = 0.11, constant beyond.
  const FrictionLaw law = FrictionLaw::tabulated({0.01, 0.11}, {0.4, 0.2});
  const SlidingTraction S = [](double N, double, double v) {
    const double mu = v <= 0.01 ? 0.4 : v >= 0.11 ? 0.2 : 0.4 - 2.0 * (v - 0.01);
    return mu * N;
  };
  EXPECT_EQ(law.kind(), FrictionKind::user);
  EXPECT_FALSE(law.needs_area());
  for (double d_t : {4.01e-8, 5e-8, 1e-7, 3e-7, 1e-5}) expect_law_at_final_speed(law, S, node(d_t));
  EXPECT_TRUE(law.in_contact(node(4e-8)).stick);
  EXPECT_NEAR(law.in_contact(node(1e-5)).slide_impulse, 0.2 * kNstar, 1e-14 * 0.2 * kNstar);  // beyond the table: constant (bracket 1e-14)
  // Independent of A_c (S A_c dt = mu N*), so a zero area is fine.
  EXPECT_EQ(law.in_contact(node(3e-7, kNstar, kM, 0.0)).slide_impulse, law.in_contact(node(3e-7)).slide_impulse);
}

TEST(Friction, DegenerateInputsStayFinite) {
  // A material barely present: m_red = 1e-300 with consistent impulses (d = m v).
  for (const FrictionLaw& law : {FrictionLaw::linear_velocity(0.2, 0.5), FrictionLaw::smooth_static_dynamic(0.4, 0.2, 0.05),
                                 FrictionLaw::tabulated({0.0, 1.0}, {0.4, 0.2})}) {
    const FrictionOutcome o = law.in_contact(node(1e-300 * 0.5, 1e-300 * 0.1, 1e-300));
    EXPECT_TRUE(o.stick || (std::isfinite(o.slide_impulse) && o.slide_impulse < 1e-300 * 0.5)) << law.describe();
    EXPECT_TRUE(law.in_contact(node(1e-7, kNstar, 0.0)).stick) << law.describe();  // m_red = 0: nothing to slide
  }
  EXPECT_TRUE(FrictionLaw::coulomb(0.2).in_contact(node(kNaN)).stick);
}

TEST(FrictionalWork, FirstOrderIsForceTimesFinalSpeedTimesDt) {
  const double s = 1e-7, d_t = 3e-7, m = 1e-6, dt = 1e-7;
  EXPECT_NEAR(frictional_work_first_order(s, d_t, m), (s / dt) * ((d_t - s) / m) * dt, 1e-14 * 2e-8);  // a few roundings
}

TEST(FrictionalWork, SecondOrderMatchesQuadratureOfEq31) {
  // Constant force F = s/dt, relative speed linear in time with end value v_end = (d_t − s)/m and slope
  // a = (f_t − F)/m (eqs. 28–29); sliding from the zero of v(t) if that lies inside the step, else from 0.
  // The integrand is linear on [t_s, dt], so Simpson's rule is exact up to roundoff (~1e-15 relative).
  const double s = 1e-7, d_t = 3e-7, m = 1e-6, dt = 1e-7, F = s / dt;
  for (double f_t : {2.0 /*0 < W2 < W1*/, 5.0 /*W2 > W1*/, -1.0 /*W2 < 0*/, 1.0 + 1e-9, 3.0 - 1e-9, 3.0 + 1e-9}) {
    const double v_end = (d_t - s) / m, a = (f_t - F) / m;
    const double v0 = v_end - a * dt;
    const double t_s = v0 > 0.0 ? 0.0 : dt - v_end / a;
    const int panels = 1000;
    const double h = (dt - t_s) / panels;
    double sum = 0.0;
    for (int i = 0; i < panels; ++i) {
      const double t0 = t_s + i * h;
      auto integrand = [&](double t) { return F * (v_end + a * (t - dt)); };
      sum += h / 6.0 * (integrand(t0) + 4.0 * integrand(t0 + 0.5 * h) + integrand(t0 + h));
    }
    const double w = frictional_work_second_order(s, d_t, f_t, m, dt);
    EXPECT_NEAR(w, sum, 1e-12 * sum) << "f_t = " << f_t;
  }
  // Continuity at W2 = W1 (f_t dt = d_t): both branches give W1/2.
  const double w1 = frictional_work_first_order(s, d_t, m);
  EXPECT_NEAR(frictional_work_second_order(s, d_t, d_t / dt, m, dt), 0.5 * w1, 1e-15 * w1);
}

TEST(FrictionalWork, GuardsGiveFiniteWork) {
  const double tiny = 1e-300;
  // Consistent impulses at a barely present material: W1 = s v' stays tiny and finite.
  EXPECT_NEAR(frictional_work_first_order(tiny * 0.1, tiny * 0.3, tiny), tiny * 0.1 * 0.2, 1e-14 * tiny * 0.02);
  EXPECT_TRUE(std::isfinite(frictional_work_second_order(tiny * 0.1, tiny * 0.3, 1.0, tiny, 1e-7)));
  // Inconsistent impulses that would overflow: 0, never inf.
  EXPECT_EQ(frictional_work_first_order(1e10, 1e20, tiny), 0.0);
  EXPECT_EQ(frictional_work_second_order(1e10, 1e20, 1e20, tiny, 1.0), 0.0);
  for (double m : {0.0, -1.0, kNaN, kInf}) {
    EXPECT_EQ(frictional_work_first_order(1e-7, 3e-7, m), 0.0);
    EXPECT_EQ(frictional_work_second_order(1e-7, 3e-7, 2.0, m, 1e-7), 0.0);
  }
  EXPECT_EQ(frictional_work_first_order(kNaN, 3e-7, 1e-6), 0.0);
  EXPECT_EQ(frictional_work_first_order(1e-7, kNaN, 1e-6), 0.0);
  EXPECT_EQ(frictional_work_first_order(0.0, 3e-7, 1e-6), 0.0);
  EXPECT_EQ(frictional_work_first_order(-1e-7, 3e-7, 1e-6), 0.0);
  EXPECT_EQ(frictional_work_second_order(1e-7, 3e-7, kNaN, 1e-6, 1e-7), 0.0);
  EXPECT_EQ(frictional_work_second_order(1e-7, 3e-7, 2.0, 1e-6, 0.0), 0.0);
  EXPECT_EQ(frictional_work_second_order(1e-7, 3e-7, 2.0, 1e-6, kNaN), 0.0);
}

TEST(Friction, ParameterValidationNamesTheParameter) {
  expect_invalid([] { FrictionLaw::coulomb(-0.1); }, "mu");
  expect_invalid([] { FrictionLaw::coulomb(kNaN); }, "mu");
  expect_invalid([] { FrictionLaw::linear_velocity(-1.0, 0.1); }, "mu0");
  expect_invalid([] { FrictionLaw::linear_velocity(0.1, -1.0); }, "k");
  expect_invalid([] { FrictionLaw::adhesion(0.1, -1.0); }, "shear_strength");
  expect_invalid([] { FrictionLaw::adhesion(0.1, 1.0, 0.0); }, "tensile_strength");
  expect_invalid([] { FrictionLaw::static_dynamic(0.2, 0.4); }, "mu_dynamic");
  expect_invalid([] { FrictionLaw::static_dynamic(kInf, 0.4); }, "mu_static");
  expect_invalid([] { FrictionLaw::smooth_static_dynamic(0.4, 0.2, 0.0); }, "v_half");
  expect_invalid([] { FrictionLaw::smooth_static_dynamic(0.4, -0.2, 1.0); }, "mu_dynamic");
  expect_invalid([] { FrictionLaw::tabulated({}, {}); }, "speeds");
  expect_invalid([] { FrictionLaw::tabulated({0.0, 1.0}, {0.1}); }, "mu");
  expect_invalid([] { FrictionLaw::tabulated({0.0, 0.0}, {0.1, 0.2}); }, "speeds[1]");
  expect_invalid([] { FrictionLaw::tabulated({-1.0, 1.0}, {0.1, 0.2}); }, "speeds[0]");
  expect_invalid([] { FrictionLaw::tabulated({0.0, 1.0}, {0.1, -0.2}); }, "mu[1]");
  expect_invalid([] { FrictionLaw::user(nullptr, "empty"); }, "S");
}

TEST(Friction, NamesAndDescriptions) {
  for (FrictionKind k : {FrictionKind::stick, FrictionKind::frictionless, FrictionKind::coulomb, FrictionKind::linear_velocity,
                         FrictionKind::adhesion, FrictionKind::static_dynamic, FrictionKind::smooth_static_dynamic})
    EXPECT_EQ(friction_kind_from_string(to_string(k)), k);
  EXPECT_EQ(friction_kind_from_string("tabulated"), FrictionKind::user);
  try {
    friction_kind_from_string("sticky");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("'sticky'"), std::string::npos);
    EXPECT_NE(msg.find("smooth_static_dynamic"), std::string::npos);
    EXPECT_NE(msg.find("tabulated"), std::string::npos);
  }
  EXPECT_EQ(FrictionLaw::coulomb(0.2).describe(), "coulomb(mu=0.2)");
  EXPECT_EQ(FrictionLaw::adhesion(0.2, 1e5, 2e5).describe(), "adhesion(mu=0.2, shear_strength=100000 Pa, tensile_strength=200000 Pa)");
  EXPECT_EQ(FrictionLaw::tabulated({0.0, 1.0}, {0.4, 0.2}).describe(), "tabulated(speeds=[0, 1] m/s, mu=[0.4, 0.2])");
  EXPECT_EQ(FrictionLaw::user([](double, double, double) { return 0.0; }, "mine").describe(), "user(mine)");
}
