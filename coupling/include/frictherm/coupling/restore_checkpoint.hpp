#pragma once
// The checks and the restore `frictherm resume` applies to a checkpoint before its first step, alone
// (issue 34; the checkpoint fuzzer tests/fuzz/fuzz_checkpoint.cpp): a separate header so that the
// run's headers stay as they are.
#include <frictherm/coupling/scene.hpp>

#include <string>

namespace frictherm::coupling {

/// Builds the simulation (and the thermal run) from `scene` as run_scene does and restores the state
/// of `checkpoint` into it (read_checkpoint with the run loop's state), without a step and without
/// writing anything. A checkpoint that is damaged or does not fit the scene throws OutputError naming
/// the file and the dataset (runner.hpp); a scene that cannot be built, SceneError.
void restore_checkpoint(const Scene& scene, const std::string& checkpoint);

}  // namespace frictherm::coupling
