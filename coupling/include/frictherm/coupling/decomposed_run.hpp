#pragma once
// `mpirun -n K frictherm run SCENE.json` (issue 16, "the same command"): a scene run on the decomposed
// engine (frictherm/mechanics/distributed.hpp: DMDA grid, DMSwarm particles, USL step with
// multimaterial contact; frictherm/coupling/decomposed_heat.hpp: heat hand-off and forward-Euler
// conduction every step; frictherm/coupling/distributed.hpp: per-rank output joined by XDMF).
// Library target frictherm::coupling_run_mpi (coupling/src/distributed_run/), built when the
// decomposed mechanics and coupling are; the frictherm program uses it when started as K > 1 processes.
//
//   if (std::string why = decomposed_run_refusal(scene); !why.empty()) → exit code 2, nothing written
//   RunResult r = run_scene_decomposed(MPI_COMM_WORLD, scene, options);
//
// What a decomposed run supports (anything else is refused by decomposed_run_refusal, naming the
// scene key and its value): 2D and 3D, linear-elastic materials, the USL update with FLIP, the
// linear, uGIMP and quadratic B-spline shapes, fixed grid faces, gravity, multimaterial contact with
// any friction law and the position, displacement or velocity_only separation; frictional and
// plastic heating with conduction (DecomposedHeat), fixed-temperature faces among its boundaries. The
// full list: docs/distributed_run.md, "What happens".
#include <frictherm/coupling/decomposed_support.hpp>  // decomposed_run_refusal
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <mpi.h>

#include <stdexcept>
#include <string>

namespace frictherm::coupling {

/// Thrown by run_scene_decomposed on every rank alike when the run ended without a published result
/// (a write into OUT.h5 failed: what was written stays under its temporary name; the message says
/// where). Exit code 1, as the serial run's failed writes.
struct DecomposedRunError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Runs a validated, supported scene over the ranks of `comm` (collective; PETSc initialised).
/// Output: OUT.h5 (rank 0: the time series and metadata, as the serial file without snapshots),
/// OUT.rank<r>.h5 (each rank's particle snapshots) and OUT.xdmf joining them. Same refusals as the
/// serial run (OutputError on every rank for an existing file without overwrite, or an input file);
/// SceneError on every rank when the particles cannot be built. options.handle_signals: SIGINT or
/// SIGTERM on any rank ends the run after the current step on every rank. Checkpoints as the serial
/// run's options say (scene.checkpoint_interval, options.checkpoint_wall_interval, at the end and on a
/// signal; options.checkpoint_file, else OUT.h5.checkpoint) and options.resume_checkpoint (by the
/// same number of ranks bit-for-bit, by another redistributed; the output goes on in place):
/// docs/checkpoints.md, "Decomposed runs".
/// Whatever throws once the output exists ends the run as a breakdown (status `failed`, the state
/// under /failure, the result published) when it was thrown on every rank alike (a rank file's or a
/// checkpoint's write failure, the heat's errors); thrown on one rank alone while the others wait in
/// a collective call, it ends every rank with MPI_Abort after rank 0 has published what it holds
/// (docs/robustness.md). The per-step observer is not supported (std::invalid_argument).
RunResult run_scene_decomposed(MPI_Comm comm, const Scene& scene, const RunOptions& options);

/// The files a decomposed run writes for output `out` with `ranks` processes: out, its XDMF files
/// (xdmf_paths_for) and every rank file.
std::vector<std::string> decomposed_output_files(const std::string& out, int ranks);

}  // namespace frictherm::coupling
