#pragma once
// The MPM step as a list of named phases (issue 32): built once per scene from the update scheme
// (USF, USL, MUSL) and the options (contact method, penalty, velocity filter, loads, damping), run
// in order and timed by run_phases; the phases themselves read no clock. A phase is called once
// per step through a std::function; the particle and node loops are inside it.
#include <frictherm/mechanics/step_timing.hpp>

#include <functional>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

/// What the phases of one step hand each other.
struct StepContext {
  double dt_limit = 0.0;  // the caller's bound on the step (s)
  double dt = 0.0;        // the step, set by the time-step phase (s)
  double t = 0.0;         // the time at the start of the step (s)
  bool speed_in_scatter = false;  // the particle-to-grid scatter takes the CFL speed; dt is set after it
  long bad = -1;          // grid-to-particle: the first particle with a non-finite state or outside the grid
  long beyond = -1;       // stress update: the first compressed past its Hugoniot's limit
};

struct StepPhase {
  const char* name;
  double StepPhaseTimes::*timer;  // the StepPhaseTimes entry its wall time is added to
  std::function<void(StepContext&)> run;
};

class PhaseList {
 public:
  PhaseList& add(const char* name, double StepPhaseTimes::*timer, std::function<void(StepContext&)> run) {
    phases_.push_back({name, timer, std::move(run)});
    return *this;
  }
  /// Runs the phases in order; each one's wall time goes to its timer in `times`.
  void run(StepContext& ctx, StepPhaseTimes& times) const {
    PhaseLap lap;
    for (const StepPhase& p : phases_) {
      p.run(ctx);
      lap.to(times.*p.timer);
    }
  }
  const std::vector<StepPhase>& phases() const { return phases_; }
  bool empty() const { return phases_.empty(); }
  void clear() { phases_.clear(); }

 private:
  std::vector<StepPhase> phases_;
};

}  // namespace frictherm::mechanics
