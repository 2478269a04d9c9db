// Constitutive models against stresses computed by hand.
#include <frictherm/mechanics/material.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace frictherm::mechanics;

namespace {
Material elastic(double E, double nu) {
  Material m;
  m.name = "test";
  m.density = 1000.0;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}
}  // namespace

TEST(Materials, LameConstantsAndWaveSpeeds) {
  const Material m = elastic(200e9, 0.25);
  EXPECT_NEAR(m.shear_modulus(), 80e9, 1.0);
  EXPECT_NEAR(m.lame_lambda(), 80e9, 1.0);  // E nu / ((1+nu)(1-2nu)) = 200e9*0.25/(1.25*0.5)
  EXPECT_NEAR(m.p_wave_speed(Analysis::plane_strain), std::sqrt(240e9 / 1000.0), 1e-6);
  EXPECT_NEAR(m.p_wave_speed(Analysis::plane_stress), std::sqrt(200e9 / (1 - 0.0625) / 1000.0), 1e-6);
}

TEST(Materials, LinearElasticUniaxialStrainPlaneStrain) {
  // L = diag(1e-3, 0)/dt over one step: ε_xx = 1e-3 → σ_xx = (λ+2μ) ε, σ_yy = σ_zz = λ ε.
  const Material m = elastic(100e6, 0.3);
  const double lam = m.lame_lambda(), mu = m.shear_modulus();
  Mat<2> L = Mat<2>::Zero();
  L(0, 0) = 1.0;
  Mat<2> s = Mat<2>::Zero();
  double szz = 0.0;
  linear_elastic_update<2>(L, 1e-3, lam, mu, Analysis::plane_strain, s, szz);
  EXPECT_NEAR(s(0, 0), (lam + 2 * mu) * 1e-3, 1e-6);
  EXPECT_NEAR(s(1, 1), lam * 1e-3, 1e-6);
  EXPECT_NEAR(szz, lam * 1e-3, 1e-6);
  EXPECT_NEAR(s(0, 1), 0.0, 1e-9);
}

TEST(Materials, LinearElasticPlaneStressUniaxialStress) {
  // ε_xx = e, ε_yy = −ν e (uniaxial stress) → σ_xx = E e, σ_yy = 0 in plane stress.
  const Material m = elastic(100e6, 0.3);
  Mat<2> L = Mat<2>::Zero();
  L(0, 0) = 1.0;
  L(1, 1) = -0.3;
  Mat<2> s = Mat<2>::Zero();
  double szz = 0.0;
  linear_elastic_update<2>(L, 1e-4, m.lame_lambda(), m.shear_modulus(), Analysis::plane_stress, s, szz);
  EXPECT_NEAR(s(0, 0), 100e6 * 1e-4, 1e-6);
  EXPECT_NEAR(s(1, 1), 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(szz, 0.0);
}

TEST(Materials, LinearElasticSimpleShear3D) {
  // L_xy = 1 over dt = 2e-4: γ = 2e-4, σ_xy = μ γ, and the Jaumann rotation of a zero stress adds nothing.
  const Material m = elastic(100e6, 0.3);
  Mat<3> L = Mat<3>::Zero();
  L(0, 1) = 1.0;
  Mat<3> s = Mat<3>::Zero();
  double szz = 0.0;
  linear_elastic_update<3>(L, 2e-4, m.lame_lambda(), m.shear_modulus(), Analysis::three_d, s, szz);
  EXPECT_NEAR(s(0, 1), m.shear_modulus() * 2e-4, 1e-6);  // engineering shear γ = 2e-4
  EXPECT_NEAR(s(1, 0), m.shear_modulus() * 2e-4, 1e-6);
  EXPECT_NEAR(s(0, 0), 0.0, 1e-9);
}

TEST(Materials, LinearElasticEnergyDensity) {
  // Uniaxial stress σ: W = σ²/(2E).
  Mat<3> s = Mat<3>::Zero();
  s(0, 0) = 2e6;
  EXPECT_NEAR(linear_elastic_energy_density<3>(s, 0.0, 1e9, 0.3, Analysis::three_d), 4e12 / 2e9, 1e-9);
}

TEST(Materials, NeoHookeanUniaxialStretch3D) {
  // F = diag(1.1, 1, 1): J = 1.1, σ_xx = [μ(1.21 − 1) + λ ln 1.1]/1.1, σ_yy = σ_zz = λ ln 1.1 / 1.1.
  const double lam = 104.4e6, mu = 26.1e6;
  Mat<3> F = Mat<3>::Identity();
  F(0, 0) = 1.1;
  Mat<3> s;
  double szz;
  neo_hookean_stress<3>(F, lam, mu, s, szz);
  EXPECT_NEAR(s(0, 0), (mu * 0.21 + lam * std::log(1.1)) / 1.1, 1e-3);
  EXPECT_NEAR(s(1, 1), lam * std::log(1.1) / 1.1, 1e-3);
  EXPECT_NEAR(s(2, 2), lam * std::log(1.1) / 1.1, 1e-3);
  // Energy: ½μ(1.21 + 2 − 3) − μ ln 1.1 + ½λ (ln 1.1)².
  const double W = 0.5 * mu * 0.21 - mu * std::log(1.1) + 0.5 * lam * std::pow(std::log(1.1), 2);
  EXPECT_NEAR(neo_hookean_energy_density<3>(F, lam, mu), W, 1e-3);
}

TEST(Materials, NeoHookeanPlaneStrainMatches3D) {
  const double lam = 104.4e6, mu = 26.1e6;
  Mat<2> F2;
  F2 << 1.05, 0.1, -0.02, 0.97;
  Mat<3> F3 = Mat<3>::Identity();
  F3.topLeftCorner<2, 2>() = F2;
  Mat<2> s2;
  Mat<3> s3;
  double szz2, szz3;
  neo_hookean_stress<2>(F2, lam, mu, s2, szz2);
  neo_hookean_stress<3>(F3, lam, mu, s3, szz3);
  EXPECT_LT((s2 - s3.topLeftCorner<2, 2>()).norm(), 1e-6);
  EXPECT_NEAR(szz2, s3(2, 2), 1e-6);
  EXPECT_NEAR(neo_hookean_energy_density<2>(F2, lam, mu), neo_hookean_energy_density<3>(F3, lam, mu), 1e-6);
}

TEST(Materials, NeoHookeanSmallStrainIsLinearElastic) {
  // For small strain the Neo-Hookean stress approaches λ tr(ε) I + 2 μ ε.
  const double lam = 1e9, mu = 0.5e9, e = 1e-7;
  Mat<3> F = Mat<3>::Identity();
  F(0, 0) += e;
  Mat<3> s;
  double szz;
  neo_hookean_stress<3>(F, lam, mu, s, szz);
  EXPECT_NEAR(s(0, 0), (lam + 2 * mu) * e, 1e-5 * (lam + 2 * mu) * e);  // O(e) nonlinearity + round-off
}

TEST(Materials, KindsByName) {
  EXPECT_EQ(material_kind_from_string("neo_hookean"), MaterialKind::neo_hookean);
  EXPECT_THROW(material_kind_from_string("steel"), std::invalid_argument);
}
