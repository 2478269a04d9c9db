#pragma once
// The step of a Simulation<Dim> as a phase list (step/phase_list.hpp; simulation_step.cpp) and the
// wall time of each phase.
#include <frictherm/mechanics/step/phase_list.hpp>
#include <frictherm/mechanics/step_timing.hpp>

namespace frictherm::mechanics {

/// The phases of step(), built by the first step and again when a setting they depend on changes.
struct StepSchedule {
  StepPhaseTimes times;  // wall time per phase since the start
  PhaseList phases;      // the step (build_phases)
  long key = -1;         // phase_key() the list was built for
};

}  // namespace frictherm::mechanics
