#pragma once
// The clock of a Simulation<Dim>: time, step count and the last step's time step.

namespace frictherm::mechanics {

/// Where the simulation is in time.
struct StepClock {
  double time = 0.0;     // s
  long step = 0;         // steps taken
  double last_dt = 0.0;  // s
};

}  // namespace frictherm::mechanics
