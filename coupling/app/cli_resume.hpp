#pragma once
// Shared by `frictherm resume` and `frictherm continue` (cli_resume.cpp, cli_continue.cpp).
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <functional>
#include <string>
#include <vector>

namespace frictherm::cli {

struct ResumeRequest {
  std::string run;         // the result the checkpoint belongs to
  std::string checkpoint;  // RUN.h5.checkpoint
  std::string output;      // where the appended result goes (may be `run`)
  coupling::Scene scene;   // rebuilt from the checkpoint (with continue's --set)
  int threads = 0;
  double checkpoint_wall_interval = 0.0;  // --checkpoint-every (resume)
  bool quiet = false;
  bool force = false;      // replace an existing output that is not `run`
  bool new_thermal_settings = false;  // continue: series columns may differ from the loading's (append_result)
  std::string command_line;
};

struct ResumeOutcome {
  coupling::RunResult result;
  bool appended = false;  // to the interrupted result (else written alone: no RUN.h5)
};

/// Runs the scene from the checkpoint and appends the output to `run` (result_append.hpp) into
/// `output`; without `run` writes `output` alone. Throws OutputError when `output` is refused,
/// SceneError / std::runtime_error as run_scene and append_result do.
/// The run options every resume starts from: threads, wall-clock checkpoints, quiet, command line,
/// signals handled, resuming from request.checkpoint.
coupling::RunOptions resume_run_options(const ResumeRequest& request);

/// coupling::checkpoint_scene, with a checkpoint that does not read (empty, truncated, not HDF5)
/// refused as a bad input (OutputError: exit code 2) rather than a failed run.
coupling::Scene checkpoint_scene_or_refuse(const std::string& checkpoint,
                                           const std::vector<coupling::SceneOverride>& more = {});
ResumeOutcome resume_from_checkpoint(const ResumeRequest& request);

/// The exit code and message of a resumed run ("resumed" / "continued").
int report_resumed(const char* command, const ResumeOutcome& outcome, bool quiet);

/// `prepare` (which fills request.scene and may throw), then resume_from_checkpoint and
/// report_resumed: scene and output errors exit kUsage with their message, others kSimulationFailed.
/// `command` is "resume" or "continue".
int run_from_checkpoint(ResumeRequest& request, const char* command, const std::function<void()>& prepare);

/// `mpirun -n K frictherm resume RUN.h5` (cli_run_mpi.cpp): a decomposed run's checkpoint resumed on
/// the same K ranks, in place (no -o); a serial checkpoint or another K is refused (kUsage).
int decomposed_resume_command(const ResumeRequest& request);

}  // namespace frictherm::cli
