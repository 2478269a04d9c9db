#pragma once
// Checkpoints of the mechanics state (issue 17): every member that Simulation::visit_state lists,
// written to an HDF5 file beside the result (checkpoint_path), atomically: the state goes to
// "<path>.tmp" first and is renamed over the previous checkpoint only once complete, so a kill
// during a write keeps the previous checkpoint whole. A simulation rebuilt from the same scene and
// restored with read_mechanics_checkpoint steps on bit-for-bit (docs/checkpoints.md).
#include <frictherm/coupling/scene.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <string>

namespace frictherm::coupling {

/// The checkpoint file of a result file: "<result>.checkpoint".
std::string checkpoint_path(const std::string& result_path);

/// Writes the state of `sim` (finalized first if it is not) and the scene text it was built from.
/// Throws std::invalid_argument when the simulation cannot be checkpointed (penalty contact), and
/// std::runtime_error on HDF5 failures; the previous checkpoint at `path` is then left untouched.
template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                                const std::string& scene_text = "");

/// Restores the state written by write_mechanics_checkpoint into `sim`, which must have been built
/// from the same scene (same dimension and particle count; checked, std::runtime_error otherwise).
template <int Dim>
void read_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim);

/// As above, storing the scene's text, source path and --set overrides (for checkpoint_scene).
template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const Scene& scene);

/// The scene text stored in a checkpoint ("" if none was given).
std::string checkpoint_scene_text(const std::string& path);

/// The scene a checkpoint was written from: its text parsed again with the stored overrides, image
/// paths relative to the stored source's folder. Throws SceneError if the text does not parse.
Scene checkpoint_scene(const std::string& path);

}  // namespace frictherm::coupling
