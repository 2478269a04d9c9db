#pragma once
// Arrhenius progress at the sub-cell interface temperature (issue 31 item 2): the verdict of a hot
// spot that lives below the grid.
//
// The thermal module integrates the reaction on the nodes, at the grid temperature, and its heat goes
// into the conduction problem. A rubbing contact's interface is hotter than the grid by the sub-cell
// correction (interface_temperature.hpp), and a first-order Arrhenius rate is dominated by the
// hottest material, so each reacting particle also integrates its own progress at its interface
// temperature T_int,p:
//     dλ/dt = (1 − λ) Z exp(−Θ / T_int)            (first-order global kinetics, reaction.hpp)
// with the rate taken by the trapezoidal rule between two updates,
//     λ(t₁) = 1 − (1 − λ(t₀)) exp(−½ (k(T₀) + k(T₁)) (t₁ − t₀)).
// This progress is a diagnostic and a verdict: its heat does not enter the thermal problem (the heat a
// sub-cell reaction would release stays unmodelled; docs/coupling.md says so). Hot-spot fates read it
// when `coupling.hotspots.temperature` is "interface".
#include <frictherm/coupling/heat_sources.hpp>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace frictherm::coupling {

class InterfaceReaction {
 public:
  /// Follows `particles` particles from `time` on, fresh (λ = 0).
  void start(std::size_t particles, double time);
  /// Advances every particle whose material reacts to `time` at its interface temperature
  /// `temperature[k]` (K), with the kinetics of `reaction`.
  void advance(const std::vector<std::int32_t>& material, const ReactionOptions& reaction,
               const std::vector<double>& temperature, double time);

  bool started() const { return started_; }
  const std::vector<double>& progress() const { return progress_; }
  /// k(T_int,p) at the last update (1/s; −1: no reading yet), per particle as progress().
  const std::vector<double>& rate() const { return rate_; }
  /// For a caller whose particles change between updates (a decomposed run: they migrate between
  /// ranks with their progress and rate as particle scalars): this update's particles' λ and k.
  void assign(std::vector<double> progress, std::vector<double> rate) {
    progress_ = std::move(progress), rate_ = std::move(rate);
  }
  /// The time of the last update (started() only).
  double time() const { return time_; }
  void restore_time(bool started, double time) { started_ = started, time_ = time; }
  double max_progress() const;

  /// Checkpoints (state_visit.hpp).
  template <class V> void visit_state(V&& v) {
    std::vector<double> rate = rate_, state{started_ ? 1.0 : 0.0, time_};
    v("interface_reaction/progress", progress_);
    v("interface_reaction/rate", rate);
    v("interface_reaction/state", state);
    if constexpr (std::decay_t<V>::reading) {
      rate_ = std::move(rate);
      started_ = state.size() == 2 && state[0] != 0.0;
      time_ = state.size() == 2 ? state[1] : 0.0;
    }
  }

 private:
  std::vector<double> progress_;  // λ_p at the interface temperature
  std::vector<double> rate_;      // k(T_int,p) at the last update (1/s)
  double time_ = 0.0;
  bool started_ = false;
};

}  // namespace frictherm::coupling
