// Optional Arrhenius reaction heat for thermal::Problem (design §3, issue 5 item 4).
//
// Single-step, first-order global kinetics with a per-node reaction progress λ_i ∈ [0, 1]
// (0 = fresh, 1 = fully reacted):
//
//   M_i dT_i/dt = −(K T)_i + … + Q_i (1 − λ_i) k(T_i),     dλ_i/dt = (1 − λ_i) k(T_i),
//   k(T) = Z exp(−Θ/T),  Θ = E_a/R,
//
// with Q_i [J] the heat the reacting material at node i releases on full reaction:
// Q_i = m_i^reacting · q (reacting mass at the node times the specific heat of reaction).
// A node with Q_i = 0 (binder, empty of explosive) releases nothing and carries no progress.
// Σ_i M_i T_i + Σ_i Q_i (1 − λ_i) is then conserved up to sources and boundary heat.
// With consume = false the reaction is zero-order (λ held fixed, no depletion): the
// Frank-Kamenetskii thermal-explosion model.
#pragma once

#include <Eigen/Core>

namespace frictherm::thermal {

inline constexpr double kGasConstant = 8.314462618;  // R [J/(mol K)]
inline constexpr double kThermochemicalCalorie = 4.184;  // [J]

// Global one-step kinetic constants of a material.
struct ArrheniusKinetics {
  double prefactor = 0.0;               // Z [1/s]
  double activation_temperature = 0.0;  // Θ = E_a/R [K]
  double specific_heat_of_reaction = 0.0;  // q [J/kg] released on full reaction
};

// HMX, one-step first-order global decomposition kinetics of R. N. Rogers,
// "Thermochemistry of explosives", Thermochimica Acta 11 (1975) 131–139, as commonly quoted:
//   Z = 5.0e19 1/s, E_a = 52.7 kcal/mol (220.5 kJ/mol, Θ = 26 520 K), q = 500 cal/g (2.09 MJ/kg).
// (docs/thermal.md lists an alternative global fit, Henson et al. LA-UR-01-3499.)
ArrheniusKinetics hmx_kinetics_rogers1975();

// The reaction of a Problem (set with Problem::set_reaction).
struct Reaction {
  Eigen::VectorXd heat;                 // Q_i [J] (per unit area/depth in 1D/2D, like M); ≥ 0
  double prefactor = 0.0;               // Z [1/s], > 0
  double activation_temperature = 0.0;  // Θ = E_a/R [K], > 0
  bool consume = true;                  // false: zero-order, λ held fixed (Frank-Kamenetskii)

  // k(T) = Z exp(−Θ/T) [1/s]; 0 for T ≤ 0 (the limit T → 0⁺; never reached physically).
  double rate_constant(double temperature) const;
  // dk/dT = k Θ/T² [1/(s K)]; 0 for T ≤ 0.
  double rate_constant_derivative(double temperature) const;
};

// Q_i = reacting_mass_i · kinetics.specific_heat_of_reaction, with the kinetics' Z and Θ.
Reaction make_reaction(const ArrheniusKinetics& kinetics, const Eigen::VectorXd& reacting_mass,
                       bool consume = true);

}  // namespace frictherm::thermal
