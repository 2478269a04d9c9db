// `mpirun -n K frictherm run SCENE` (issue 16): the scene is loaded and validated on every rank as in
// the serial program, checked against what the decomposed engine supports (a refusal names the scene
// key; exit code 2, nothing written), then run by run_scene_decomposed. Only rank 0 speaks.
#include "cli.hpp"
#include "cli_resume.hpp"

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/result_append.hpp>

#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#ifdef FRICTHERM_DECOMPOSED_RUN
#include <frictherm/coupling/decomposed_run.hpp>
#include <frictherm/mechanics/distributed.hpp>

#include <mpi.h>
#endif

namespace frictherm::cli {

#ifdef FRICTHERM_DECOMPOSED_RUN
namespace {

// The outcome of a decomposed run on this rank, reported by rank 0.
int report(const coupling::RunResult& r, const coupling::RunOptions& opt, int rank, int ranks) {
  if (rank != 0) return r.exit_code();
  if (r.status == coupling::RunResult::Status::failed) {
    std::cerr << "frictherm: simulation failed: " << r.message << ". Kept: " << r.output << " (the time series) and "
              << r.snapshots << " snapshots per rank.\n";
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::interrupted) {
    std::cerr << "frictherm: " << r.message << ". Kept in " << r.output << ": " << r.series_rows << " series rows and "
              << r.snapshots << " snapshots (the last one at the interruption) in the rank files joined by the XDMF "
              << "file; /meta/status = interrupted.\n";
    if (std::filesystem::exists(coupling::checkpoint_path(r.output)))
      std::cerr << "frictherm: resume with: mpirun -n " << ranks << " frictherm resume " << r.output << '\n';
    return r.exit_code();
  }
  if (!opt.quiet) {
    std::printf("wrote %s (series) and %zu snapshots over %d rank files joined by the XDMF file: %zu series rows; "
                "%ld steps to t = %g s in %.2f s (%zu particles on %d ranks)\n",
                r.output.c_str(), r.snapshots, ranks, r.series_rows, r.steps, r.time, r.wall_time, r.particles, ranks);
    if (r.wall_time > 0.0 && r.steps > 0) {
      std::printf("%.3g particle-steps/s; rank 0's wall time by phase:",
                  static_cast<double>(r.particles) * r.steps / r.wall_time);
      for (const auto& [name, seconds] : r.phase_seconds)
        if (seconds > 0.0005 * r.wall_time) std::printf(" %s %.1f%%", name.c_str(), 100.0 * seconds / r.wall_time);
      std::printf("\n");
    }
    std::fflush(stdout);
  }
  return kOk;
}

int run_and_report(const coupling::Scene& scene, const std::string& path, const coupling::RunOptions& opt, int rank,
                   int ranks);

int run_decomposed(const ParsedArgs& a, const std::string& path, const coupling::RunOptions& opt, int rank, int ranks) {
  coupling::Scene scene;
  try {  // every rank loads and validates the scene (deterministic: all agree); rank 0 reports
    std::vector<coupling::SceneOverride> overrides;
    if (a.lists.count("set"))
      for (const auto& assignment : a.lists.at("set")) overrides.push_back(coupling::parse_override(assignment));
    scene = coupling::load_scene(path, overrides);
  } catch (const coupling::SceneError& e) {
    if (rank == 0) std::cerr << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  }
  if (const std::string why = coupling::decomposed_run_refusal(scene); !why.empty()) {
    if (rank == 0) std::cerr << "frictherm: " << path << ": " << why << ".\n";
    return kUsage;
  }
  return run_and_report(scene, path, opt, rank, ranks);
}

// The decomposed runs' default wall-clock checkpoint interval (RunOptions::
// decomposed_default_checkpoint_wall_interval, 600 s) from FRICTHERM_DECOMPOSED_CHECKPOINT_EVERY
// (seconds ≥ 0; 0 turns it off); empty when valid or unset, else the complaint.
std::string default_checkpoint_from_environment(coupling::RunOptions& opt) {
  const char* v = std::getenv("FRICTHERM_DECOMPOSED_CHECKPOINT_EVERY");
  if (v == nullptr) return "";
  char* end = nullptr;
  const double seconds = std::strtod(v, &end);
  if (end == v || *end != '\0' || !(seconds >= 0.0) || !std::isfinite(seconds))
    return std::string("FRICTHERM_DECOMPOSED_CHECKPOINT_EVERY: expected wall-clock seconds >= 0 (0: no default "
                       "checkpoints), got '") + v + "'";
  opt.decomposed_default_checkpoint_wall_interval = seconds;
  return "";
}

int run_and_report(const coupling::Scene& scene, const std::string& path, const coupling::RunOptions& options, int rank,
                   int ranks) {
  coupling::RunOptions opt = options;
  if (const std::string why = default_checkpoint_from_environment(opt); !why.empty()) {  // the same on every rank
    if (rank == 0) std::cerr << "frictherm: " << why << '\n';
    return kUsage;
  }
  coupling::RunResult r;
  try {
    r = coupling::run_scene_decomposed(MPI_COMM_WORLD, scene, opt);
  } catch (const coupling::SceneError& e) {  // agreed by every rank
    if (rank == 0) std::cerr << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {  // agreed by every rank
    if (rank == 0) std::cerr << "frictherm: " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::DecomposedRunError& e) {  // agreed by every rank: the result is not published
    if (rank == 0) std::cerr << "frictherm: simulation failed: " << e.what() << '\n';
    return kSimulationFailed;
  } catch (const std::exception& e) {  // perhaps on this rank alone: end every rank rather than hang
    std::cerr << "frictherm: rank " << rank << ": run of " << path << " failed: " << e.what() << '\n';
    MPI_Abort(MPI_COMM_WORLD, kSimulationFailed);
    return kSimulationFailed;
  }
  return report(r, opt, rank, ranks);
}

}  // namespace
#endif

int decomposed_run_command(const ParsedArgs& a, const std::string& path, const coupling::RunOptions& opt) {
#ifdef FRICTHERM_DECOMPOSED_RUN
  // PETSc (and MPI) for the lifetime of the run; PETSc reads no options from the command line.
  const mechanics::DecomposedPetscSession petsc(nullptr, nullptr);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks == 1) return serial_run_command(a, path, opt);  // one process: today's program
  return run_decomposed(a, path, opt, rank, ranks);
#else
  return serial_run_command(a, path, opt);  // not reached: refuse_under_launcher refused `run` before
#endif
}

int decomposed_resume_command(const ResumeRequest& q) {
#ifdef FRICTHERM_DECOMPOSED_RUN
  const mechanics::DecomposedPetscSession petsc(nullptr, nullptr);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  auto refuse = [&](const std::string& why) {
    if (rank == 0) std::cerr << "frictherm resume: " << why << '\n';
    return kUsage;
  };
  if (!std::filesystem::exists(q.checkpoint)) return refuse("no checkpoint " + q.checkpoint + " to resume " + q.run + " from");
  int written = 0;
  coupling::Scene scene;
  try {  // every rank reads the global file (read-only); all agree
    written = coupling::checkpoint_ranks(q.checkpoint);
    scene = coupling::checkpoint_scene(q.checkpoint);
  } catch (const std::exception& e) {
    return refuse(q.checkpoint + ": " + e.what());
  }
  if (written == 0)
    return refuse(q.checkpoint + " was written by a serial run: resume it without mpirun (frictherm resume " + q.run + ")");
  if (written != ranks && rank == 0 && !q.quiet)  // the particles migrate to the new decomposition
    std::cerr << "frictherm resume: note: " << q.checkpoint << " was written by " << written << " ranks, resumed on "
              << ranks << ": the particles are redistributed (results agree to round-off, not bit-for-bit)\n";
  if (q.output != q.run && !coupling::same_file(q.output, q.run))
    return refuse("-o " + q.output + ": a decomposed run resumes in place (its rank files go on); leave out -o");
  try {  // the checkpoint belongs to the result it rewrites (issue 34): never another run's rows over it
    if (std::filesystem::exists(q.run)) coupling::check_same_run(q.run, coupling::checkpoint_marks(q.checkpoint));
  } catch (const std::exception& e) {
    return refuse(std::string(e.what()) + "; nothing was changed (the checkpoint " + q.checkpoint +
                  " would replace the result's rows with another run's)");
  }
  if (const std::string why = coupling::decomposed_run_refusal(scene); !why.empty()) return refuse(why);
  coupling::RunOptions opt = resume_run_options(q);
  opt.output = q.run;
  opt.overwrite = true;
  return run_and_report(scene, q.checkpoint, opt, rank, ranks);
#else
  (void)q;
  return kUsage;  // not reached: refuse_under_launcher refused `resume` before
#endif
}

}  // namespace frictherm::cli
