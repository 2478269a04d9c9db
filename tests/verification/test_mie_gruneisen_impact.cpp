// Mie-Grüneisen material in the MPM step: two bars of the PBX binder (table 1 of Nairn et al. 2018:
// C0 = 1222 m/s, S1 = 3.4463, S2 = −3.447, γ0 = 0.583, ρ0 = 935 kg/m³; shear modulus 0 so the stress
// is the pressure alone) meet head-on at ±u_p in one velocity field, in uniaxial strain (grid faces
// y_min and y_max hold v_y = 0). Rankine–Hugoniot: the interface stops and a shock runs into each bar
// at U_s − u_p relative to the grid, leaving the pressure p_H = ρ0 U_s u_p with U_s from
// U_s = C0 + S1 u_p + S2 u_p²/U_s. Without artificial viscosity MPM follows the isentrope through the
// smeared shock, which at η = u_p/U_s ≈ 4 % lies below the Hugoniot by O(η³) (≈ 1e-4 relative).
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace frictherm::mechanics;

TEST(MieGruneisenImpact, ShockPressureMatchesRankineHugoniot) {
  const double L = 0.2, h = 0.004, up = 50.0;
  SimulationOptions o;
  o.cfl = 0.4;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(h, h), IVec<2>{110, 4}), o);
  Material m;
  m.name = "binder";
  m.kind = MaterialKind::mie_gruneisen;
  m.density = 935.0;
  m.mie_gruneisen.C0 = 1222.0, m.mie_gruneisen.S1 = 3.4463, m.mie_gruneisen.S2 = -3.447, m.mie_gruneisen.gamma0 = 0.583;
  m.mie_gruneisen.shear_modulus = 0.0;
  const int mat = sim.add_material(m);
  const double x0 = 0.02, xc = x0 + L;
  sim.add_body("left", *make_box<2>(Vec<2>(x0, 0), Vec<2>(xc, 4 * h), mat), 2, Vec<2>(up, 0));
  sim.add_body("right", *make_box<2>(Vec<2>(xc, 0), Vec<2>(xc + L, 4 * h), mat), 2, Vec<2>(-up, 0));
  sim.fix_face(FixedFace{1, false, {{false, true, false}}});
  sim.fix_face(FixedFace{1, true, {{false, true, false}}});
  const double b = m.mie_gruneisen.C0 + m.mie_gruneisen.S1 * up;
  const double Us = 0.5 * (b + std::sqrt(b * b + 4.0 * m.mie_gruneisen.S2 * up * up));
  const double pH = m.density * Us * up;
  const double t_end = 0.6 * L / (Us - up);  // the shocks have run 0.6 L; nothing has reflected yet
  while (sim.time() < t_end * (1 - 1e-12)) sim.step(t_end - sim.time());
  const auto& p = sim.particles();
  double s = 0.0, v = 0.0, e = 0.0;
  int n = 0, nl = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double d = std::fabs(p.initial_position[k][0] - xc);
    if (!(d > 0.1 * L && d < 0.4 * L)) continue;
    s += -p.stress[k](0, 0), e += p.internal_energy[k], ++n;
    if (p.initial_position[k][0] < xc) v += p.velocity[k][0], ++nl;  // one bar (the two mirror each other)
  }
  s /= n, v = std::fabs(v / nl), e /= n;
  const double eH = 0.5 * up * up;  // Hugoniot energy jump e_H = u_p²/2
  std::printf("[Mie-Gruneisen impact] U_s = %.2f m/s, p_H = %.5g Pa; MPM plateau %.5g Pa (error %.2f %%), "
              "|mean v| behind the shocks %.3f m/s, e = %.2f J/kg (Hugoniot %.2f)\n",
              Us, pH, s, 100 * (s - pH) / pH, v, e, eH);
  // The single-field bar impact of the elastic solver reaches 0.4 %; the smeared shock and its
  // oscillations here are larger: 2 %.
  EXPECT_NEAR(s, pH, 0.02 * pH);
  EXPECT_LT(v, 0.05 * up);  // the shocked material is at rest (particles oscillate about it by ~10 % of u_p)
  // Compression energy ≈ e_H = u_p²/2; the rest of the impact energy is in those oscillations: 10 %.
  EXPECT_NEAR(e, eH, 0.1 * eH);
}
