#pragma once
// Checkpoints (issue 17, docs/checkpoints.md): every member that Simulation::visit_state lists, the
// run's output marks and, through `extra`, the run loop's own state (the thermal coupler, series
// memory), written to an HDF5 file beside the result (checkpoint_path), atomically: the state goes
// to "<path>.<pid>.tmp" first and is renamed over the previous checkpoint only once complete, so a
// kill during a write keeps the previous checkpoint whole. A simulation rebuilt from the same scene
// and restored with read_checkpoint steps on bit-for-bit.
#include <frictherm/coupling/scene.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling {

namespace ckpt {
struct Writer;  // checkpoint visitors (coupling/src/run/checkpoint_io.hpp)
struct Reader;
}  // namespace ckpt

/// The checkpoint file of a result file: "<result>.checkpoint".
std::string checkpoint_path(const std::string& result_path);

/// Where the result file stood when the checkpoint was taken: the rows and snapshots an
/// uninterrupted run has at that state (a resumed run's output is appended after them).
struct CheckpointMarks {
  long step = 0;
  double time = 0.0;
  long series_rows = 0;
  long snapshots = 0;
  std::vector<std::pair<std::string, long>> table_rows;  // /hotspots, /hotspot_fates, ...
  bool end_of_loading = false;  // taken after the last mechanics step, before the thermal continuation
  /// The result this checkpoint belongs to: /meta/run_id of the result (issue 34). A run draws a
  /// fresh one; resume and continue keep their checkpoint's. Empty in checkpoints of older versions.
  std::string run_id;
};

/// Writes the state of `sim` (finalized first if it is not), the scene's text, source path and --set
/// overrides (for checkpoint_scene), `marks` and what `extra` writes (names relative to the file's
/// root, e.g. "coupler/..."). Throws std::runtime_error on HDF5 failures; the previous checkpoint at
/// `path` is then left untouched.
template <int Dim>
void write_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim, const Scene& scene,
                      const CheckpointMarks& marks, const std::function<void(const ckpt::Writer&)>& extra = {});

/// Restores the state written by write_checkpoint into `sim`, which must have been built from the
/// same scene (same dimension and particle count; checked, std::runtime_error otherwise), then calls
/// `extra` to read the rest.
template <int Dim>
void read_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                     const std::function<void(const ckpt::Reader&)>& extra = {});

/// The number of ranks of the decomposed run that wrote the checkpoint (its root attribute `ranks`;
/// docs/checkpoints.md, "Decomposed runs"), 0 for a serial run's checkpoint.
int checkpoint_ranks(const std::string& path);

/// The output marks stored in a checkpoint.
CheckpointMarks checkpoint_marks(const std::string& path);

/// Mechanics only, no scene: the state of `sim` and `scene_text` (tests, library use).
template <int Dim>
void write_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim,
                                const std::string& scene_text = "");
template <int Dim>
void read_mechanics_checkpoint(const std::string& path, mechanics::Simulation<Dim>& sim);

/// The scene text stored in a checkpoint ("" if none was given).
std::string checkpoint_scene_text(const std::string& path);

/// The --set overrides stored in a checkpoint, in order.
std::vector<SceneOverride> checkpoint_overrides(const std::string& path);

/// The scene a checkpoint was written from: its text parsed again with the stored overrides and then
/// `more` (later ones win), image paths relative to the stored source's folder. Throws SceneError if
/// the text does not parse.
Scene checkpoint_scene(const std::string& path, const std::vector<SceneOverride>& more = {});

}  // namespace frictherm::coupling
