// Arrhenius progress at the sub-cell interface temperature (interface_reaction.hpp).
#include <frictherm/coupling/interface_reaction.hpp>

#include <algorithm>
#include <cmath>

namespace frictherm::coupling {

namespace {
// k(T) = Z exp(−Θ/T); 0 for T ≤ 0 or not finite (a particle with no interface reading).
double rate_constant(const thermal::ArrheniusKinetics& kin, double temperature) {
  return temperature > 0.0 && std::isfinite(temperature)
             ? kin.prefactor * std::exp(-kin.activation_temperature / temperature)
             : 0.0;
}
}  // namespace

void InterfaceReaction::start(std::size_t particles, double time) {
  progress_.assign(particles, 0.0);
  rate_.assign(particles, -1.0);  // no reading yet: the first interval takes its end's rate
  time_ = time;
  started_ = true;
}

void InterfaceReaction::advance(const std::vector<std::int32_t>& material, const ReactionOptions& reaction,
                                const std::vector<double>& temperature, double time) {
  if (!started_) return;
  const double dt = time - time_;
  const std::size_t n = std::min({progress_.size(), temperature.size(), rate_.size(), material.size()});
  for (std::size_t k = 0; k < n; ++k) {
    if (!reaction.reacts(material[k])) continue;
    const double rate = rate_constant(reaction.kinetics, temperature[k]);
    if (dt > 0.0) {
      const double before = rate_[k] < 0.0 ? rate : rate_[k];
      const double exposure = 0.5 * (before + rate) * dt;  // ∫ k dt, trapezoidal
      progress_[k] = 1.0 - (1.0 - progress_[k]) * std::exp(-exposure);
    }
    rate_[k] = rate;
  }
  time_ = std::max(time_, time);
}

double InterfaceReaction::max_progress() const {
  return progress_.empty() ? 0.0 : *std::max_element(progress_.begin(), progress_.end());
}

}  // namespace frictherm::coupling
