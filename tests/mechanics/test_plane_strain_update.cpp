// The scalar plane-strain update (plane_strain_update.hpp) against the Eigen forms it replaces in the
// stress update: F ← (I + dt L) F, det, and mie_gruneisen_update<2>. They perform the same operations
// in the same order, so the test demands bitwise equality (EXPECT_EQ on doubles, tolerance 0), over
// random velocity gradients and stresses that cover elastic and plastic steps, compression and
// tension, HMX (J2) and binder (no yield), and the beyond-Hugoniot refusal; and the linear elastic update.
#include <frictherm/mechanics/constitutive/stress_update.hpp>
#include <frictherm/mechanics/plane_strain_update.hpp>
#include <frictherm/mechanics/small_products.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
MieGruneisenParams hardening() {
  MieGruneisenParams m = hmx();
  m.hardening_modulus = 2e9;
  return m;
}
}  // namespace

TEST(PlaneStrainUpdate, DeformationGradientMatchesEigenBitwise) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    VelocityGradient2 L;
    const Vec<2> v1(u(rng), u(rng)), g1(u(rng) * 1e5, u(rng) * 1e5), v2(u(rng), u(rng)), g2(u(rng) * 1e5, u(rng) * 1e5);
    L.add(v1, g1);
    L.add(v2, g2);
    Mat<2> Le = Mat<2>::Zero();
    Le.noalias() += v1 * g1.transpose();
    Le.noalias() += v2 * g2.transpose();
    ASSERT_EQ(L.matrix(), Le);
    const double dt = 1e-9 * (1.0 + u(rng));
    Mat<2> F;
    F << 1.0 + 0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng), 1.0 + 0.1 * u(rng);
    Mat<2> Fe = F;
    const double det_A = deformation_update_2d(L, dt, F);
    const Mat<2> A = Mat<2>::Identity() + dt * Le;
    Fe = (A * Fe).eval();
    for (int i = 0; i < 4; ++i) ASSERT_EQ(F(i), Fe(i)) << "trial " << trial;
    ASSERT_EQ(det_A, A.determinant());
    ASSERT_EQ(determinant_2d(F), Fe.determinant());
  }
}

TEST(PlaneStrainUpdate, MieGruneisenMatchesEigenBitwise) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const MieGruneisenParams materials[] = {hmx(), binder(), hardening()};
  int plastic = 0, elastic = 0, refused = 0;
  for (const MieGruneisenParams& m : materials) {
    const double min_J = mie_gruneisen_min_J(m);
    for (int trial = 0; trial < 3000; ++trial) {
      // Rates up to 1e6 1/s over 1 ns; stresses up to 1 GPa, so both sides of the yield surface occur.
      VelocityGradient2 L;
      L.l00 = 1e6 * u(rng), L.l01 = 1e6 * u(rng), L.l10 = 1e6 * u(rng), L.l11 = 1e6 * u(rng);
      const double dt = 1e-9 * (1.0 + 0.5 * u(rng));
      Mat<2> sigma;
      sigma << 5e8 * u(rng), 3e8 * u(rng), 0.0, 5e8 * u(rng);
      sigma(1, 0) = sigma(0, 1);
      double szz = 5e8 * u(rng), ep = trial % 3 == 0 ? 0.0 : 0.05 * (1.0 + u(rng)), e = 1e4 * u(rng);
      // J from 0.75 to 1.05, and now and then beyond the Hugoniot limit.
      double J = trial % 97 == 0 ? 0.5 * min_J : 0.9 + 0.15 * u(rng);
      Mat<2> F;
      F << 1.0, 0.0, 0.0, J;
      const double det_A = deformation_update_2d(L, dt, F);

      Mat<2> s1 = sigma, s2 = sigma;
      double z1 = szz, z2 = szz, ep1 = ep, ep2 = ep, e1 = e, e2 = e, wp1 = -1.0, wp2 = -1.0, c1 = -1.0, c2 = -1.0;
      const MieGruneisenStatus r1 = mie_gruneisen_update_plane_strain(L, dt, J, det_A, m, min_J, s1, z1, ep1, e1, wp1, c1);
      const MieGruneisenStatus r2 = mie_gruneisen_update<2>(L.matrix(), dt, J, m, s2, z2, ep2, e2, wp2, &c2);
      ASSERT_EQ(r1, r2);
      if (r1 != MieGruneisenStatus::ok) {
        ++refused;
        continue;
      }
      for (int i = 0; i < 4; ++i) ASSERT_EQ(s1(i), s2(i)) << "trial " << trial << " entry " << i;
      ASSERT_EQ(z1, z2);
      ASSERT_EQ(ep1, ep2);
      ASSERT_EQ(e1, e2);
      ASSERT_EQ(wp1, wp2);
      ASSERT_EQ(c1, c2);
      (wp1 > 0.0 ? plastic : elastic) += 1;
    }
  }
  // Both branches of the return mapping and the refusal were exercised.
  EXPECT_GT(plastic, 500);
  EXPECT_GT(elastic, 500);
  EXPECT_GT(refused, 10);
}

// The linear elastic (hypoelastic, Jaumann) update on scalars against linear_elastic_update<2>, plane
// strain and plane stress, bitwise; with the deformation gradient and volume as update_stress<2> does
// them (update_stress_linear_elastic_2d, the sliding blocks' stress update).
TEST(PlaneStrainUpdate, LinearElasticMatchesEigenBitwise) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Material mat;
  mat.density = 1000.0, mat.youngs_modulus = 2.5e9, mat.poisson_ratio = 0.33;
  for (const Analysis an : {Analysis::plane_strain, Analysis::plane_stress}) {
    const StressLaw law = stress_law(mat, an);
    for (int trial = 0; trial < 3000; ++trial) {
      VelocityGradient2 L;
      L.l00 = 1e4 * u(rng), L.l01 = 1e4 * u(rng), L.l10 = 1e4 * u(rng), L.l11 = 1e4 * u(rng);
      const double dt = 1e-6 * (1.0 + 0.5 * u(rng));
      Mat<2> sigma, F;
      sigma << 5e7 * u(rng), 3e7 * u(rng), 0.0, 5e7 * u(rng);
      sigma(1, 0) = sigma(0, 1) * (trial % 2 ? 1.0 : 1.0 + 1e-3 * u(rng));  // now and then not symmetric
      F << 1.0 + 0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng), 1.0 + 0.1 * u(rng);
      Mat<2> s1 = sigma, s2 = sigma, F1 = F, F2 = F;
      double z1 = 1e7 * u(rng), z2 = z1, V1 = -1.0, V2 = -1.0, c1 = -1.0, c2 = -1.0, ep1 = 0, ep2 = 0, e1 = 0, e2 = 0,
             w1 = 0, w2 = 0;
      const double V0 = 1e-9 * (1.5 + u(rng));
      update_stress_linear_elastic_2d(law, an, L, dt, StressState<2>{F1, V1, V0, s1, z1, ep1, e1, w1, c1});
      ASSERT_TRUE(update_stress<2>(mat, law, an, L.matrix(), dt, StressState<2>{F2, V2, V0, s2, z2, ep2, e2, w2, c2}));
      for (int i = 0; i < 4; ++i) {
        ASSERT_EQ(s1(i), s2(i)) << "trial " << trial << " entry " << i;
        ASSERT_EQ(F1(i), F2(i)) << "trial " << trial << " entry " << i;
      }
      ASSERT_EQ(z1, z2);
      ASSERT_EQ(V1, V2);
      ASSERT_EQ(c1, c2);
      ASSERT_NE(s1, sigma);  // the update changed the stress
    }
  }
}

// product_into (small_products.hpp, the deformation gradient update of update_stress) against Eigen's
// C.noalias() = A * B, bitwise, 2×2 and 3×3, over entries spanning six decades (so that the order of
// a three-term sum shows in the last bits).
template <int Dim>
void check_small_product(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20000; ++trial) {
    Mat<Dim> A, B, C, E;
    for (int i = 0; i < Dim * Dim; ++i) A(i) = u(rng) * std::pow(10.0, 3.0 * u(rng)), B(i) = u(rng) * std::pow(10.0, 3.0 * u(rng));
    product_into<Dim>(A, B, C);
    E.noalias() = A * B;
    for (int i = 0; i < Dim * Dim; ++i) ASSERT_EQ(C(i), E(i)) << "trial " << trial << " entry " << i;
  }
}
TEST(SmallProducts, MatchEigenBitwise2D) { check_small_product<2>(17); }
TEST(SmallProducts, MatchEigenBitwise3D) { check_small_product<3>(19); }
