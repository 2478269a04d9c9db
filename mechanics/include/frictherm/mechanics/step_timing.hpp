#pragma once
// Wall time of each phase of the MPM step, summed over a run: where a benchmark's time goes.
// One clock read per phase boundary (~20 ns), about ten per step.
#include <chrono>

namespace frictherm::mechanics {

struct StepPhaseTimes {
  double time_step = 0.0;         // s: stable time step (CFL over the particles)
  // s: stencils, EBS rebuild, field layout, rigid-driven nodes (USL with contact: the stencils are
  // evaluated in the previous step's stress-update pass and timed there)
  double shape_functions = 0.0;
  double particle_to_grid = 0.0;  // s: mass, momentum, forces, MUSL remap, external loads
  double contact = 0.0;           // s: contact nodes, multimaterial passes (with the frictional work), penalty
  double grid_update = 0.0;       // s: momentum update, velocity conditions, nodal velocities
  double grid_to_particle = 0.0;  // s: particle velocities and positions (USF, MUSL), rigid bodies
  // s: velocity gradient, deformation gradient, constitutive update; USL: together with the particle
  // velocities and positions (one pass over the stencils, simulation_particle_pass.cpp)
  double stress_update = 0.0;
  double total() const {
    return time_step + shape_functions + particle_to_grid + contact + grid_update + grid_to_particle + stress_update;
  }
};

/// A lap clock: to(acc) adds the time since the last lap (or construction) to acc.
class PhaseLap {
 public:
  PhaseLap() : last_(Clock::now()) {}
  void to(double& accumulator) {
    const Clock::time_point now = Clock::now();
    accumulator += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point last_;
};

}  // namespace frictherm::mechanics
