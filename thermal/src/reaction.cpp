#include "frictherm/thermal/reaction.hpp"

#include <cmath>
#include <stdexcept>

namespace frictherm::thermal {

ArrheniusKinetics hmx_kinetics_rogers1975() {
  ArrheniusKinetics k;
  k.prefactor = 5.0e19;                                                   // Z [1/s]
  k.activation_temperature = 52.7e3 * kThermochemicalCalorie / kGasConstant;  // 52.7 kcal/mol / R
  k.specific_heat_of_reaction = 500.0 * kThermochemicalCalorie * 1e3;     // 500 cal/g [J/kg]
  return k;
}

double Reaction::rate_constant(double temperature) const {
  if (!(temperature > 0.0)) return 0.0;
  return prefactor * std::exp(-activation_temperature / temperature);
}

double Reaction::rate_constant_derivative(double temperature) const {
  if (!(temperature > 0.0)) return 0.0;
  return rate_constant(temperature) * activation_temperature / (temperature * temperature);
}

Reaction make_reaction(const ArrheniusKinetics& kinetics, const Eigen::VectorXd& reacting_mass, bool consume) {
  if (!reacting_mass.allFinite() || (reacting_mass.size() > 0 && reacting_mass.minCoeff() < 0.0)) {
    throw std::invalid_argument("thermal::make_reaction: reacting masses must be finite and >= 0 (kg)");
  }
  Reaction r;
  r.heat = kinetics.specific_heat_of_reaction * reacting_mass;
  r.prefactor = kinetics.prefactor;
  r.activation_temperature = kinetics.activation_temperature;
  r.consume = consume;
  return r;
}

}  // namespace frictherm::thermal
