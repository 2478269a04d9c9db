#pragma once
// The energy books of a Simulation<Dim> that accumulate step by step (simulation_energy.cpp):
// the work done on the deformable bodies from outside and the energy they started with.
#include <limits>

namespace frictherm::mechanics {

/// Work (J) since the start: external_work(), rigid_work(), damping_work(), contact_normal_work(),
/// boundary_stop_work(); and the initial energy.
struct WorkBooks {
  double external = 0.0;  // external loads and body force
  double rigid = 0.0;     // rigid materials on the deformable bodies
  double damping = 0.0;   // removed by the mass-proportional damping (≥ 0)
  double contact_normal = 0.0;  // removed by the normal contact impulses (normal_stop_work)
  double boundary_stop = 0.0;   // removed by the velocity conditions (condition_stop_work)
  double initial_energy = std::numeric_limits<double>::quiet_NaN();  // kinetic + stored before the first step
  double stored_lead = 0.0;     // the stored energy ahead of the velocities (EnergyBalance, advance_stored_lead)
  double stress_power = 0.0;    // Σ V σ:L after the last stress update (W; advance_stored_lead)
  double stress_dt = 0.0;       // that update's step (s)
};

}  // namespace frictherm::mechanics
