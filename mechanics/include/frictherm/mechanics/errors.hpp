#pragma once
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

/// Thrown when a step produces an invalid state (non-finite values, a particle leaving the grid).
/// The particle arrays hold the state at the failing step; the step number and time say where.
class SimulationError : public std::runtime_error {
 public:
  SimulationError(const std::string& what, long step, double time, long particle)
      : std::runtime_error(what), step_(step), time_(time), particle_(particle) {}
  long step() const { return step_; }
  double time() const { return time_; }
  long particle() const { return particle_; }

 private:
  long step_;
  double time_;
  long particle_;
};

}  // namespace frictherm::mechanics
