#pragma once
// Parameters of the Mie-Grüneisen / J2 material (the functions are in mie_gruneisen.hpp).
#include <limits>

namespace frictherm::mechanics {

/// Parameters of one Mie-Grüneisen / J2 material (SI). Names match the JSON keys of
/// examples/materials/pbx_table1.json.
struct MieGruneisenParams {
  double density = 0.0;        // ρ0 (kg/m^3)
  double C0 = 0.0;             // bulk sound speed at the reference state (m/s)
  double S1 = 0.0;             // U_s–u_p slope (-)
  double S2 = 0.0;             // quadratic coefficient of U_s = C0 + S1 u_p + S2 u_p²/U_s (-)
  double gamma0 = 0.0;         // Grüneisen parameter γ0 (-), ρΓ = ρ0 γ0
  double shear_modulus = 0.0;  // G (Pa)
  double yield_stress = std::numeric_limits<double>::infinity();  // σ_y (Pa); infinity: no plasticity
  double hardening_modulus = 0.0;  // H (Pa): σ_y(ε̄p) = σ_y + H ε̄p (0: perfect plasticity, as table 1)
};

}  // namespace frictherm::mechanics
