#pragma once
// The run loop: scene -> mechanics::Simulation -> HDF5 output.
//
//   RunOptions opt;  opt.output = "out.h5";
//   std::vector<double> ke;                                        // a diagnostic of your own:
//   opt.observer = [&](const StepView& s) { ke.push_back(s.kinetic_energy()); };
//   RunResult r = run_scene(load_scene("bar.json"), opt);
//   SeriesTable series = read_series(r.output);                    // results.hpp
//   return r.exit_code();   // 0 completed, 1 the simulation failed
//
// The loop clamps time steps so that the run lands exactly on every snapshot time and on end_time.
// A mechanics::SimulationError (a blow-up, a particle leaving the grid) ends the run: the failing
// state goes to /failure, the file is flushed and everything written before stays readable.
#include <frictherm/coupling/scene.hpp>

#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling {

/// The output file cannot be created (missing folder, no permission, ...): nothing has run.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The state a per-step observer sees (RunOptions::observer): the simulation right after a mechanics
/// step, its heat handoff and its series row, read-only. The full simulation of the run's dimension
/// is simulation<2>() or simulation<3>() (particles, grid, contact statistics, ...).
class StepView {
 public:
  template <int Dim>
  explicit StepView(const mechanics::Simulation<Dim>& sim) : dim_(Dim), sim_(&sim) {}
  /// With the run's series: its columns, its latest row (the one written to /series, not computed
  /// again) and whether this step wrote it (rows come every output.series_interval, not every step).
  template <int Dim>
  StepView(const mechanics::Simulation<Dim>& sim, const std::vector<std::string>& series_columns,
           const std::vector<double>& series_row, bool series_row_is_new)
      : dim_(Dim), sim_(&sim), columns_(&series_columns), row_(&series_row), row_is_new_(series_row_is_new) {}
  int dim() const { return dim_; }
  /// The /series column names (empty without a series); series_row() has one value per column,
  /// in this order, as written to the file (count columns hold whole numbers).
  const std::vector<std::string>& series_columns() const { return columns_ ? *columns_ : empty_names(); }
  const std::vector<double>& series_row() const { return row_ ? *row_ : empty_row(); }
  /// True when this step wrote series_row(); otherwise it is the row of an earlier step.
  bool series_row_is_new() const { return row_is_new_; }
  long step() const { return dim_ == 2 ? simulation<2>().step_count() : simulation<3>().step_count(); }
  double time() const { return dim_ == 2 ? simulation<2>().time() : simulation<3>().time(); }
  double dt() const { return dim_ == 2 ? simulation<2>().last_time_step() : simulation<3>().last_time_step(); }
  double kinetic_energy() const { return dim_ == 2 ? simulation<2>().kinetic_energy() : simulation<3>().kinetic_energy(); }
  double strain_energy() const { return dim_ == 2 ? simulation<2>().strain_energy() : simulation<3>().strain_energy(); }
  /// Throws std::logic_error when Dim is not the run's dimension.
  template <int Dim>
  const mechanics::Simulation<Dim>& simulation() const {
    if (Dim != dim_)
      throw std::logic_error("StepView::simulation<" + std::to_string(Dim) + ">() on a " + std::to_string(dim_) + "D run");
    return *static_cast<const mechanics::Simulation<Dim>*>(sim_);
  }

 private:
  static const std::vector<std::string>& empty_names() {
    static const std::vector<std::string> none;
    return none;
  }
  static const std::vector<double>& empty_row() {
    static const std::vector<double> none;
    return none;
  }
  int dim_;
  const void* sim_;
  const std::vector<std::string>* columns_ = nullptr;
  const std::vector<double>* row_ = nullptr;
  bool row_is_new_ = false;
};

struct RunOptions {
  std::string output;        // HDF5 file; empty: the scene's output.file
  /// Replace an existing output file (so does the scene's output.overwrite: true); otherwise an
  /// existing one is refused before anything runs (OutputError). Files the run reads (the scene, its
  /// images, the checkpoint resumed from) are never written, whatever this says. The file is written
  /// as "<output>.<pid>.part" and renamed onto `output` at the end (output_files.hpp).
  bool overwrite = false;
  int threads = 0;           // OpenMP threads; 0: the scene's run.threads, else OpenMP's default
  bool quiet = false;        // no progress line and no notes
  enum class Progress { automatic, always, never };
  Progress progress = Progress::automatic;  // automatic: only when stderr is a terminal
  std::string command_line;  // stored in the metadata
  std::ostream* log = nullptr;  // notes (e.g. "stopped at max_steps"); nullptr: std::cerr
  /// Catch SIGINT/SIGTERM during the run: the first one ends the run after the current step (or
  /// continuation interval) with its series, a final snapshot and status `interrupted`; a second
  /// one ends the process at once. Off by default (a library should not take over signals); the
  /// frictherm program turns it on.
  bool handle_signals = false;
  /// Buffered series rows are written and the file flushed at least this often (wall seconds).
  double flush_interval = 2.0;
  /// Wall seconds between checkpoints ("<output>.checkpoint", checkpoint.hpp); 0: only the scene's
  /// run.checkpoint_interval. With either, a checkpoint is also written at the end and on SIGINT/SIGTERM.
  /// A scene with a thermal continuation always gets one at the end of loading (frictherm continue).
  double checkpoint_wall_interval = 0.0;
  /// A decomposed run (mpirun) given neither run.checkpoint_interval nor checkpoint_wall_interval
  /// checkpoints every this many wall seconds where its checkpoints are supported (not with
  /// coupling.interface_temperature or coupling.continuation): a second SIGTERM to mpirun within 5 s
  /// ends every rank at once (docs/robustness.md, "Signals"), so this bounds what that loses. Once
  /// one is written the run checkpoints as with --checkpoint-every (also at its end); a shorter run
  /// writes none. 0: off. The serial run does not need it (it absorbs a repeated signal).
  double decomposed_default_checkpoint_wall_interval = 600.0;
  /// A checkpoint (checkpoint.hpp) to start from instead of t = 0: the simulation (and the thermal
  /// coupler) is built from the scene, the checkpoint's state restored, and the run continues to
  /// end_time (and through the thermal continuation) landing on the same snapshot, series and
  /// checkpoint times as an uninterrupted run; the output file starts at the checkpoint's state.
  std::string resume_checkpoint;
  /// With resume_checkpoint: the output holds only what an uninterrupted run writes after the
  /// checkpoint (no first row and snapshot at its state), to be appended to the interrupted result
  /// (append_result, result_append.hpp); the checkpoints it writes count rows from that result.
  bool resume_appends = false;
  /// Where checkpoints go; empty: "<output>.checkpoint". May be resume_checkpoint itself (a resumed
  /// run goes on replacing the checkpoint it started from, atomically).
  std::string checkpoint_file;
  /// The result's identity, /meta/run_id, also stored in every checkpoint it writes (issue 34: a
  /// resume refuses a checkpoint of another result). Empty: the resumed checkpoint's, else a fresh
  /// random one.
  std::string run_id;
  /// Called after every mechanics step (not during the thermal-only continuation), after the step's
  /// heat handoff and series row, so diagnostics need no copy of the run loop. The StepView carries
  /// the latest series row as written (series_row(), series_row_is_new()). An exception thrown
  /// by the observer ends the run and propagates out of run_scene once the result is published (status
  /// "failed", the state under /failure).
  std::function<void(const StepView&)> observer;
};

struct RunResult {
  enum class Status { completed, stopped_at_max_steps, failed, interrupted };
  Status status = Status::completed;
  std::string output;        // the HDF5 file written
  long steps = 0;
  double time = 0.0;         // simulated time reached (s)
  double wall_time = 0.0;    // s
  std::size_t snapshots = 0; // regular snapshots written (the failure state not counted)
  std::size_t series_rows = 0;
  std::size_t particles = 0;
  std::string message;       // the SimulationError's message when failed
  int signal = 0;            // interrupted: the signal that stopped the run (SIGINT, SIGTERM)
  /// Wall time (s) by phase, in this order: the mechanics step's phases (time_step, shape_functions,
  /// particle_to_grid, contact, grid_update, grid_to_particle, stress_update; with USL the particle
  /// velocities and positions are updated in the stress update's pass and timed there, and with USL and
  /// contact also the next step's stencils and the rigid particles' motion), heating (the coupler
  /// outside the integrator: work accumulated, heat mapped, temperatures back, hot spots),
  /// thermal_solve (the integrator during loading), continuation (thermal-only phase), output
  /// (series and snapshots) and other (the rest of wall_time: set-up, progress, metadata).
  std::vector<std::pair<std::string, double>> phase_seconds;
  /// 0 completed (or stopped at max_steps), 1 failed, 128 + signal when interrupted (130: SIGINT).
  int exit_code() const {
    if (status == Status::interrupted) return 128 + signal;
    return status == Status::failed ? 1 : 0;
  }
};

/// Runs a validated scene. Throws SceneError if the simulation cannot be built (e.g. a body with no
/// particles), OutputError if the output file cannot be created, and std::runtime_error if writing
/// fails later; a failing simulation is not an exception: it is reported in the result.
RunResult run_scene(const Scene& scene, const RunOptions& options = {});

}  // namespace frictherm::coupling
