#pragma once
// The particles' wave speeds of a Simulation<Dim>, for the CFL time step (Nairn 2018 eq. 45).
#include <vector>

namespace frictherm::mechanics {

/// Per particle: the dilatational wave speed of its state (J, e change only in the stress update,
/// which refreshes it); −∞ for rigid particles. stable_time_step adds |v_p| to it.
struct WaveSpeeds {
  std::vector<double> speed;
  bool ready = false;  // set by the first stress update
};

}  // namespace frictherm::mechanics
