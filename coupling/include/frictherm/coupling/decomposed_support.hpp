#pragma once
// Which scenes `mpirun -n K frictherm run` runs on the domain-decomposed engine (docs/distributed_run.md):
// every feature DecomposedMpm and DecomposedHeat implement, checked key by key. Pure (no MPI): the
// decomposed run refuses with it before any step, and `frictherm validate` says it.
#include <frictherm/coupling/scene.hpp>

#include <string>

namespace frictherm::coupling {

/// "" when the decomposed engine runs `scene`; otherwise why not: the first unsupported scene key with
/// its value ("contact.method: \"penalty\" is not supported in a decomposed run ...; the serial run
/// (without mpirun, or with -n 1) supports it").
std::string decomposed_run_refusal(const Scene& scene);

}  // namespace frictherm::coupling
