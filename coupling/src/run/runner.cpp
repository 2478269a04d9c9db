// The run loop: build the simulation, step to end_time landing on every snapshot time, write
// snapshots and series, and keep the failing state when the simulation breaks down.
#include "run/checkpoint_io.hpp"
#include "run/runner_detail.hpp"
#include "run/run_signals.hpp"
#include "run/runner_thermal.hpp"  // thermal coupling hooks (scenes with a `thermal` section)

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/restore_checkpoint.hpp>
#include <frictherm/coupling/microstructure.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>
#include <frictherm/coupling/thread_policy.hpp>
#include <frictherm/mechanics/errors.hpp>

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <optional>
#include <random>

namespace frictherm::coupling {

namespace detail {

std::string fresh_run_id() {
  std::random_device device;
  char text[33];
  for (int k = 0; k < 4; ++k) std::snprintf(text + 8 * k, 9, "%08x", static_cast<unsigned>(device()));
  return text;
}

}  // namespace detail

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

bool show_progress(const RunOptions& o) {
  if (o.quiet || o.progress == RunOptions::Progress::never) return false;
  if (o.progress == RunOptions::Progress::always) return true;
  return isatty(STDERR_FILENO) != 0;
}

template <int Dim>
class Run {
 public:
  Run(const Scene& scene, const RunOptions& options) : s_(scene), o_(options) {}

  // What `resume` does before its first step, alone (restore_checkpoint.hpp): the simulation and the
  // thermal run built from the scene, the checkpoint's state checked and restored.
  void restore_only() {
    sim_ = build_simulation<Dim>(s_);
    if (s_.thermal.enabled) thermal_ = std::make_unique<detail::ThermalRun<Dim>>(s_, *sim_);
    restore();
  }

  RunResult execute() {
    const Clock::time_point t0 = Clock::now();
    const detail::InterruptGuard interrupt_guard(o_.handle_signals);  // before the file exists
    r_.output = o_.output.empty() ? s_.output.file : o_.output;
    check_output_files();  // before anything is built: refusals cost nothing
    const OutputClaim claim(r_.output);  // a second run on this output is refused before it writes
    check_output_files();  // again under the claim: another run may have published meanwhile
    sim_ = build_simulation<Dim>(s_);
    if (s_.thermal.enabled) thermal_ = std::make_unique<detail::ThermalRun<Dim>>(s_, *sim_);  // thermal hook
    const int threads = o_.threads > 0 ? o_.threads : s_.threads;
    // No count given: not more threads than idle cores or than the particles pay for, and with
    // spinning waits fewer while another process holds a core (thread_policy.hpp).
    const std::size_t particles = sim_->particles().size();
    omp_set_num_threads(threads > 0 ? threads : default_thread_count(particles));
    const int stepping = mechanics::threads_for_particles(particles, omp_get_max_threads());  // as Simulation::step
    // Spinning waits (an MPI build: the launcher owns the process; or OMP_WAIT_POLICY=active): the
    // governor watches the threads, for a count given (--threads, run.threads) as for the default one
    // (issue 35: an explicit --threads 2 took 16.8x the 1-thread time with another process busy).
    // OMP_NUM_THREADS in the environment keeps the count fixed (ctest's bit-reproducible runs set it).
    const bool given = threads > 0;
    if (std::getenv("OMP_NUM_THREADS") == nullptr && waiting_threads_spin() && stepping >= 2) {
      governor_.emplace(stepping);
      if (given && !o_.quiet)
        (o_.log ? *o_.log : std::cerr)
            << "frictherm: " << threads << " threads with spinning waits (OMP_WAIT_POLICY "
            << (std::getenv("OMP_WAIT_POLICY") ? std::getenv("OMP_WAIT_POLICY") : "unset")
            << "): the thread governor goes on with 1 thread while another process holds a core "
               "(OMP_NUM_THREADS, OMP_WAIT_POLICY=passive or GOMP_SPINCOUNT keep the count fixed)\n";
    }
    r_.particles = sim_->particles().size();
    check_checkpoints();
    if (!o_.resume_checkpoint.empty()) restore();
    run_id_ = !o_.run_id.empty() ? o_.run_id : !base_marks_.run_id.empty() ? base_marks_.run_id : detail::fresh_run_id();
    H5Output out = open_output();
    out_ = &out;
    std::ostream& log = o_.log ? *o_.log : std::cerr;
    detail::ProgressLine progress(std::cerr, show_progress(o_), s_.end_time);
    // From here on the output exists: whatever goes wrong (a step, a coupling window, the thermal
    // continuation, writing) ends the run as a blow-up does, with the state under /failure and the
    // result published with status "failed" (issue 34).
    // Generated bodies (ellipse_packing): the image beside the output (an appended output: the result
    // has it). A refused image path is a bad output (exit code 2), not a failed run.
    if (!(o_.resume_appends && !o_.resume_checkpoint.empty())) detail::write_microstructure_images(out, s_, r_.output);
    try {
      detail::write_start_metadata<Dim>(out, s_, *sim_, o_);
      out.write_metadata("run_id", run_id_);
      series_columns_ = detail::series_names(Dim);
      detail::append_body_series_names<Dim>(series_columns_, *sim_);
      detail::append_contact_series_names<Dim>(series_columns_, *sim_);
      if (thermal_) thermal_->declare_output(out, series_columns_);  // thermal hook: columns + /hotspots
      out.declare_series(series_columns_);
      if (!(o_.resume_appends && !o_.resume_checkpoint.empty())) {  // appended output: the result has these
        series();
        snapshot();
      }
      last_flush_ = Clock::now();
      loop(progress);
      if (thermal_ && r_.status == RunResult::Status::completed) {
        if (thermal_->has_continuation()) checkpoint(true);  // end of loading: always (frictherm continue)
        continuation_started_ = true;
        const Clock::time_point c0 = Clock::now();
        thermal_->continuation(out, *sim_, s_.output.fields, series_memory_);  // thermal hook: thermal-only phase
        continuation_seconds_ = seconds_since(c0);
        if (detail::interrupt_signal() != 0) interrupted();
      }
    } catch (const mechanics::SimulationError& e) {
      fail(progress, e.step(), e.time(), e.what());
    } catch (const std::exception& e) {  // not a breakdown of the mechanics: where the run was
      fail(progress, sim_->step_count(), sim_->time(),
           std::string(continuation_started_ ? "thermal continuation after step " : "step ") +
               std::to_string(sim_->step_count()) + ", t = " + format_number(sim_->time()) + " s: " + e.what());
    }
    progress.finish();
    if (r_.status != RunResult::Status::failed) {
      // At the end and on SIGINT/SIGTERM, before the rows the schedule does not have (the state and
      // marks of an uninterrupted run at this step). After the continuation began, the end-of-loading
      // checkpoint stays: a resume reruns the continuation from it.
      // Interrupted: always, so that `frictherm resume` can go on (issue 34; it costs milliseconds).
      try {
        if ((checkpoints_ || r_.status == RunResult::Status::interrupted) && !continuation_started_) checkpoint(false);
        if (last_series_step_ != sim_->step_count()) series();
        if (last_snapshot_step_ != sim_->step_count()) snapshot();
      } catch (const std::exception& e) {
        fail(progress, sim_->step_count(), sim_->time(),
             "writing the end of the run at step " + std::to_string(sim_->step_count()) + ", t = " +
                 format_number(sim_->time()) + " s: " + e.what());
      }
    }
    if (r_.status == RunResult::Status::interrupted)
      r_.message = std::string("interrupted by ") + detail::signal_name(r_.signal) + " at step " +
                   std::to_string(sim_->step_count()) + ", t = " + format_number(sim_->time()) + " s";
    if (r_.status == RunResult::Status::stopped_at_max_steps && !o_.quiet)
      log << "frictherm: note: stopped at run.max_steps = " << s_.max_steps << " (t = " << sim_->time()
          << " s of end_time " << s_.end_time << " s)\n";
    r_.steps = sim_->step_count();
    r_.time = sim_->time();
    r_.wall_time = seconds_since(t0);
    r_.snapshots = out.snapshot_count();
    r_.series_rows = out.series_rows();
    const char* status = r_.status == RunResult::Status::failed                 ? "failed"
                         : r_.status == RunResult::Status::stopped_at_max_steps ? "stopped_at_max_steps"
                         : r_.status == RunResult::Status::interrupted          ? "interrupted"
                                                                                : "completed";
    // The last writes. A write that fails here or failed while the run was ended (a full disk) leaves
    // the result unpublished under its temporary name, its status `running`: never under its name
    // with status `running` (issue 34), and the first reason is the one reported.
    try {
      if (!write_error_.empty()) throw std::runtime_error(write_error_);
      if (r_.status == RunResult::Status::interrupted) out.write_metadata("interruption", r_.message);
      record_phase_seconds(out);
      if (checkpoints_written_ > 0) {
        out.write_metadata("checkpoints_written", checkpoints_written_);
        out.write_metadata("checkpoint_write_time", checkpoint_seconds_);  // s, all checkpoints of this run
      }
      if (thermal_) thermal_->write_metadata(out, *sim_);  // thermal hook: integrator statistics, energy books
      out.write_metadata("status", status);
      out.write_metadata("steps", r_.steps);
      out.write_metadata("final_time", r_.time);
      out.write_metadata("wall_time", r_.wall_time);
      out.sync();  // before the name: the published result is on disk
    } catch (const std::exception& e) {
      const std::string live = out.live_path();
      out_ = nullptr;
      out.abandon();
      throw std::runtime_error((r_.status == RunResult::Status::failed ? r_.message + "; then " : std::string()) +
                               "writing the result failed at step " + std::to_string(r_.steps) + ", t = " +
                               format_number(r_.time) + " s: " + e.what() + "; what was written stays in " + live +
                               " (status running), not published as " + r_.output);
    }
    out_ = nullptr;
    try {
      out.close();  // renames "<output>.<pid>.part" onto the output
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
    if (observer_error_) std::rethrow_exception(observer_error_);  // published first, as a failed run
    return r_;
  }

 private:
  // The run's failure: the state at it under /failure (fields as a snapshot) and the message. A
  // failure to write that state is added to the message; the result is still published.
  std::exception_ptr observer_error_;  // what the observer threw (rethrown once the result is out)

  void fail(detail::ProgressLine& progress, long step, double time, const std::string& message) {
    progress.finish();
    r_.status = RunResult::Status::failed;
    r_.message = message;
    detail::write_failure_record(
        *out_, step, time, r_.message, [&] { detail::write_fields<Dim>(*out_, *sim_, snapshot_field_names(Dim)); },
        [&](const char* what) {  // the end of execute() says that the result is incomplete
          if (write_error_.empty()) write_error_ = what;
        });
  }

  std::string write_error_;  // the first write that failed while the run was being ended

  // RunResult::phase_seconds, also written to /meta as time_<phase>.
  void record_phase_seconds(H5Output& out) {
    const mechanics::StepPhaseTimes& m = sim_->phase_times();
    auto& ph = r_.phase_seconds;
    ph = {{"time_step", m.time_step},
          {"shape_functions", m.shape_functions},
          {"particle_to_grid", m.particle_to_grid},
          {"contact", m.contact},
          {"grid_update", m.grid_update},
          {"grid_to_particle", m.grid_to_particle},
          {"stress_update", m.stress_update},
          {"heating", coupling_seconds_ - loading_solve_seconds_},
          {"thermal_solve", loading_solve_seconds_},
          {"continuation", continuation_seconds_},
          {"output", output_seconds_}};
    double accounted = 0.0;
    for (const auto& p : ph) accounted += p.second;
    ph.emplace_back("other", r_.wall_time - accounted);
    for (const auto& [name, seconds] : ph) out.write_metadata("time_" + name, seconds);
  }


  bool overwrite() const { return o_.overwrite || s_.output.overwrite; }

  // The output, its XDMF file and generated images never land on a file this run reads; an existing
  // output is replaced only when asked (RunOptions::overwrite, output.overwrite).
  void check_output_files() const {
    check_output_folder(r_.output, o_.output.empty() ? "output.file" : "output file");
    std::vector<std::string> inputs = scene_input_files(s_);
    if (!o_.resume_checkpoint.empty()) inputs.push_back(o_.resume_checkpoint);
    // The result and the XDMF files published with it (an existing OUT.xdmf may be another run's
    // result: `-o OUT.xdmf` names an HDF5 file so).
    check_output_path(r_.output, inputs, overwrite(), "--force or \"output\": {\"overwrite\": true}");
    for (const std::string& f : xdmf_paths_for(r_.output))
      check_companion_path(f, inputs, overwrite(), "--force or \"output\": {\"overwrite\": true}");
    {  // every run may write one: an interrupted run always does
      std::vector<std::string> others;  // a resumed run may go on replacing its own checkpoint
      for (const std::string& f : inputs)
        if (!(f == o_.resume_checkpoint && checkpoint_file() == o_.resume_checkpoint)) others.push_back(f);
      check_output_path(checkpoint_file(), others, true, "");
    }
    for (std::size_t i = 0; i < s_.bodies.size(); ++i)
      if (s_.bodies[i].shape.generated) check_output_path(generated_image_path(s_, i, r_.output), inputs, true, "");
  }

  H5Output open_output() const {
    try {
      H5OutputOptions options;
      options.via_temporary = true;
      options.replace_existing = overwrite();
      return H5Output(r_.output, Dim, options);
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
  }

  void loop(detail::ProgressLine& progress) {
    const double T = s_.end_time;
    // The next output times after the current one (t = 0, or a resumed checkpoint's time).
    const double t0 = sim_->time();
    detail::OutputSchedule schedule(T, s_.output.snapshot_interval, s_.output.series_interval, t0);
    const double eps = schedule.eps();
    if (s_.checkpoint_interval > 0.0)
      next_checkpoint_ = (std::floor(t0 / s_.checkpoint_interval + 1e-9) + 1.0) * s_.checkpoint_interval;
    while (sim_->time() < T - eps) {
      if (s_.max_steps > 0 && sim_->step_count() >= s_.max_steps) {
        r_.status = RunResult::Status::stopped_at_max_steps;
        return;
      }
      // Land exactly on the next snapshot time (or end_time); split the last stretch into two
      // similar steps rather than a full step and a sliver.
      double limit = schedule.next_snapshot() - sim_->time();
      if (sim_->step_count() == 0 || limit < 3.0 * sim_->last_time_step()) {
        const double stable = sim_->stable_time_step();
        if (limit > stable && limit < 2.0 * stable) limit *= 0.5;
      }
      const double t_before = sim_->time();
      if (governor_) governor_->step_started();
      sim_->step(limit);
      if (governor_)
        if (const std::string note = governor_->step_finished(); !note.empty()) progress.message(o_.log ? *o_.log : std::cerr, note);
      const double t = sim_->time();
      if (!(t > t_before))  // a step too small for the clock (1e-300 s at t = 1): never loop without advancing
        throw mechanics::SimulationError("step " + std::to_string(sim_->step_count()) + ", t = " + format_number(t) +
                                             " s: the time step " + format_number(sim_->last_time_step()) +
                                             " s no longer advances the time",
                                         sim_->step_count(), t, -1);
      // Thermal hook: the step's nodal frictional work (J, eqs. 27/34/36) goes to the coupler; a
      // window also closes at every snapshot time and at the end.
      if (thermal_) {
        const Clock::time_point c0 = Clock::now();
        const double solve0 = thermal_->solve_seconds();
        const double shape0 = sim_->phase_times().shape_functions;
        thermal_->after_step(*sim_, sim_->frictional_work(thermal_->heating_order()), schedule.snapshot_reached(t));
        // Less the next step's stencils the coupler had evaluated (current_stencils): timed as the
        // step's shape_functions phase.
        coupling_seconds_ += seconds_since(c0) - (sim_->phase_times().shape_functions - shape0);
        loading_solve_seconds_ += thermal_->solve_seconds() - solve0;
      }
      if (schedule.series_due(t)) series();
      if (schedule.snapshot_due(t)) snapshot();
      if (checkpoints_ && (t >= next_checkpoint_ - eps || (o_.checkpoint_wall_interval > 0.0 &&
                                                            seconds_since(last_checkpoint_) >= o_.checkpoint_wall_interval))) {
        checkpoint();
        if (s_.checkpoint_interval > 0.0)
          next_checkpoint_ = (std::floor(t / s_.checkpoint_interval + 1e-9) + 1.0) * s_.checkpoint_interval;
      }
      if (o_.observer) {  // the user's per-step diagnostics
        try {
          o_.observer(StepView(*sim_, series_columns_, last_series_row_, last_series_step_ == sim_->step_count()));
        } catch (...) {  // ends the run as a failure, then goes on to the caller (runner.hpp)
          observer_error_ = std::current_exception();
          throw;
        }
      }
      progress.update(sim_->step_count(), t);
      if (detail::interrupt_signal() != 0) return interrupted();
    }
  }

  std::string checkpoint_file() const {
    return o_.checkpoint_file.empty() ? checkpoint_path(r_.output) : o_.checkpoint_file;
  }

  void check_checkpoints() {
    checkpoints_ = s_.checkpoint_interval > 0.0 || o_.checkpoint_wall_interval > 0.0;
    next_checkpoint_ = s_.checkpoint_interval > 0.0 ? s_.checkpoint_interval : std::numeric_limits<double>::infinity();
  }

  // What the run loop keeps between steps besides the simulation (checkpoint.hpp "extra").
  template <class V> void visit_run_state(V&& v) {
    v("run/last_series_step", last_series_step_);
    v("run/last_snapshot_step", last_snapshot_step_);
    v("run/series_memory/time", series_memory_.time);
    v("run/series_memory/has_previous", series_memory_.has_previous);
    v("run/series_memory/work", series_memory_.work);
    if (thermal_) thermal_->visit_state(v, *sim_);
  }

  void restore() {
    try {  // a checkpoint that does not fit the scene is a bad input (exit code 2), refused before any step
      read_checkpoint(o_.resume_checkpoint, *sim_, [&](const ckpt::Reader& r) { visit_run_state(r); });
    } catch (const SceneError&) {
      throw;
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
    base_marks_ = checkpoint_marks(o_.resume_checkpoint);
    if (!o_.resume_appends) {  // the output starts at the checkpoint: rows count from 0
      const std::string id = base_marks_.run_id;
      base_marks_ = CheckpointMarks{};
      base_marks_.run_id = id;
    }
  }

  // Rows and snapshots of the result at this state, counted from the result this output is appended to.
  CheckpointMarks marks(bool end_of_loading) const {
    CheckpointMarks m;
    m.step = sim_->step_count();
    m.time = sim_->time();
    m.series_rows = base_marks_.series_rows + static_cast<long>(out_->series_rows());
    m.snapshots = base_marks_.snapshots + static_cast<long>(out_->snapshot_count());
    for (const char* t : {"hotspots", "hotspot_fates"}) {
      long base = 0;
      for (const auto& [name, rows] : base_marks_.table_rows)
        if (name == t) base = rows;
      m.table_rows.emplace_back(t, base + static_cast<long>(out_->table_rows(t)));
    }
    m.end_of_loading = end_of_loading;
    m.run_id = run_id_;
    return m;
  }

  void checkpoint(bool end_of_loading = false) {
    const Clock::time_point c0 = Clock::now();
    out_->sync();  // the rows the marks count are in the file and durable before the checkpoint is (issue 34)
    write_checkpoint(checkpoint_file(), *sim_, s_, marks(end_of_loading),
                     [&](const ckpt::Writer& w) { visit_run_state(w); });
    last_checkpoint_ = Clock::now();
    const double seconds = seconds_since(c0);
    output_seconds_ += seconds;
    checkpoint_seconds_ += seconds;
    ++checkpoints_written_;
  }

  void interrupted() {
    r_.status = RunResult::Status::interrupted;
    r_.signal = detail::interrupt_signal();
  }

  static std::string format_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
  }

  void series() {
    const Clock::time_point c0 = Clock::now();
    std::vector<double> row = detail::series_row<Dim>(*sim_, series_memory_, heating_order());
    if (thermal_) thermal_->extend_series_row(row, *out_, *sim_, sim_->time());  // thermal hook
    out_->append_series(row);
    last_series_row_.swap(row);  // what the observer sees (StepView::series_row), not computed again
    last_series_step_ = sim_->step_count();
    if (seconds_since(last_flush_) >= o_.flush_interval) {  // a killed run loses at most flush_interval
      out_->flush();
      last_flush_ = Clock::now();
    }
    output_seconds_ += seconds_since(c0);
  }

  void snapshot() {
    const Clock::time_point c0 = Clock::now();
    out_->begin_snapshot(sim_->step_count(), sim_->time());
    detail::write_fields<Dim>(*out_, *sim_, s_.output.fields);
    if (thermal_) thermal_->write_fields(*out_);  // thermal hook: reaction_progress
    out_->end_snapshot();
    last_snapshot_step_ = sim_->step_count();
    output_seconds_ += seconds_since(c0);
  }

  const Scene& s_;
  const RunOptions& o_;
  std::unique_ptr<mechanics::Simulation<Dim>> sim_;
  std::unique_ptr<detail::ThermalRun<Dim>> thermal_;  // only for scenes with a `thermal` section
  H5Output* out_ = nullptr;
  RunResult r_;
  long last_series_step_ = -1;
  std::vector<std::string> series_columns_;  // the /series columns
  std::vector<double> last_series_row_;      // the last row appended (StepView::series_row)
  long last_snapshot_step_ = -1;
  double coupling_seconds_ = 0.0;       // in thermal_->after_step (heating and solve)
  std::optional<ThreadGovernor> governor_;  // default thread count with spinning waits
  double loading_solve_seconds_ = 0.0;  // of which inside the integrator
  double continuation_seconds_ = 0.0;
  detail::SeriesMemory series_memory_;  // the previous series row, for the contact_heat_rate columns
  // The frictional work that becomes heat (and that the books count): the scene's heating order, also
  // without a thermal section (its default follows the update scheme, scene_parse.cpp).
  mechanics::HeatingOrder heating_order() const { return thermal_ ? thermal_->heating_order() : s_.thermal.heating_order; }
  double output_seconds_ = 0.0;         // series rows and snapshots
  Clock::time_point last_flush_ = Clock::now();  // series rows written and file flushed
  bool checkpoints_ = false;
  bool continuation_started_ = false;
  CheckpointMarks base_marks_;  // resume_appends: the result's rows and snapshots at the checkpoint
  std::string run_id_;          // /meta/run_id and every checkpoint's marks
  double checkpoint_seconds_ = 0.0;
  long checkpoints_written_ = 0;
  double next_checkpoint_ = 0.0;                      // simulated time of the next checkpoint
  Clock::time_point last_checkpoint_ = Clock::now();  // wall clock of the last checkpoint
};

}  // namespace

void restore_checkpoint(const Scene& scene, const std::string& checkpoint) {
  RunOptions o;
  o.resume_checkpoint = checkpoint;
  o.resume_appends = true;
  if (scene.dimension == 2)
    Run<2>(scene, o).restore_only();
  else
    Run<3>(scene, o).restore_only();
}

RunResult run_scene(const Scene& scene, const RunOptions& options) {
  if (scene.dimension == 2) return Run<2>(scene, options).execute();
  return Run<3>(scene, options).execute();
}

}  // namespace frictherm::coupling
