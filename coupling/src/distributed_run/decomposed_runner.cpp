// The decomposed run loop (decomposed_run.hpp, decomposed_run_impl.hpp): the serial run loop's time
// stepping (CFL from each particle's dilatational wave speed plus its speed,
// DecomposedMpm::stable_time_step, the largest over all ranks; landing on every snapshot time and on
// end_time), the engine's USL step and the heat hand-off of DecomposedHeat every step, its windows
// closed by the scene's policy and at every snapshot time (as the serial ThermalRun::after_step), the
// state check after each step; series, snapshots and checkpoints at their times
// (decomposed_run_output.cpp, decomposed_run_checkpoint.cpp).
#include "distributed_run/decomposed_run_impl.hpp"

namespace frictherm::coupling::decomposed {

template <int Dim>
DecomposedRun<Dim>::DecomposedRun(MPI_Comm comm, const Scene& scene, const RunOptions& options) : comm_(comm), s_(scene), o_(options) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  MPI_Comm_dup(comm_, &failure_comm_);
  // Fault injection for tests (tests/coupling/test_cli_mpirun_faults.cpp): FRICTHERM_FAULT_DECOMPOSED=
  // RANK:STEP[:SECONDS] throws std::bad_alloc on rank RANK before its step STEP (the others go on
  // into the step's collective calls) and agrees on failures within SECONDS.
  if (const char* f = std::getenv("FRICTHERM_FAULT_DECOMPOSED"))
    std::sscanf(f, "%d:%ld:%lf", &fault_rank_, &fault_step_, &agreement_seconds_);
}

template <int Dim>
DecomposedRun<Dim>::~DecomposedRun() {
  if (out_) out_->abandon();  // an exception on its way out: never published with status running
  if (failure_comm_ != MPI_COMM_NULL) MPI_Comm_free(&failure_comm_);
}

// Whether a checkpoint at the end of the loading lets a resume repeat the run bit for bit: no
// continuation follows, or one whose first interval gathers afresh from the particles. After
// assembled windows (cvode_bdf, ...) the continuation goes on from the last window's problem, which a
// decomposed checkpoint does not hold: a resume from the last checkpoint during the loading reruns
// that window instead (docs/checkpoints.md).
template <int Dim>
bool DecomposedRun<Dim>::end_of_loading_checkpoint_exact() const {
  return !(heat_ && s_.thermal.continuation_duration > 0.0) || heat_->continuation_regathers();
}

template <int Dim>
RunResult DecomposedRun<Dim>::execute() {
  const Clock::time_point t0 = Clock::now();
  if (o_.observer) throw std::invalid_argument("a decomposed run has no per-step observer");
  const detail::InterruptGuard interrupt_guard(o_.handle_signals);
  r_.output = o_.output.empty() ? s_.output.file : o_.output;
  resuming_ = !o_.resume_checkpoint.empty();
  checkpoints_ = s_.checkpoint_interval > 0.0 || o_.checkpoint_wall_interval > 0.0;
  // Without a checkpoint setting: every decomposed_default_checkpoint_wall_interval wall seconds where
  // a decomposed checkpoint is supported (issue 34: two SIGTERMs to mpirun kill the ranks at once).
  wall_interval_ = o_.checkpoint_wall_interval;
  if (!checkpoints_)
    wall_interval_ = std::max(0.0, o_.decomposed_default_checkpoint_wall_interval);
  checkpoint_file_ = o_.checkpoint_file.empty() ? checkpoint_path(r_.output) : o_.checkpoint_file;
  if (!resuming_) check_output_files();  // before anything is built: refusals cost nothing
  // An interrupted run writes one too (below), so the generation is known whether or not it checkpoints.
  if (!resuming_) generation_ = detail::committed_generation(comm_, checkpoint_file_);
  build();
  if (resuming_) restore();
  if (rank_ == 0)  // the result's identity (/meta/run_id, every checkpoint's marks): a resume keeps its checkpoint's
    run_id_ = !o_.run_id.empty() ? o_.run_id : resuming_ ? checkpoint_marks(o_.resume_checkpoint).run_id : "";
  if (rank_ == 0 && run_id_.empty()) run_id_ = detail::fresh_run_id();
  open_output();
  detail::ProgressLine progress(std::cerr, rank_ == 0 && show_progress(), s_.end_time);
  last_flush_ = last_checkpoint_ = Clock::now();
  // From here on the output exists: whatever throws ends the run as a breakdown does, the state
  // under /failure and the result published with status "failed" (issue 34), as the serial run.
  try {
    if (!resuming_) {  // a resumed run's output has the checkpoint's rows and snapshots already
      series();
      snapshot();
    }
    loop(progress);
    if (heat_ && r_.status == RunResult::Status::completed && s_.thermal.continuation_duration > 0.0) {
      // The end-of-loading checkpoint, always where supported (as the serial run): a run interrupted in
      // its continuation resumes from it and reruns the whole continuation (docs/checkpoints.md).
      if (end_of_loading_checkpoint_exact()) checkpoint(true);
      continuation_started_ = true;
      const Clock::time_point c0 = Clock::now();
      continuation();
      continuation_seconds_ = seconds_since(c0);
    }
  } catch (const mechanics::SimulationError& e) {  // agreed by every rank (one reduction)
    fail(e.step(), e.time(), e.what());
  } catch (const std::exception& e) {  // agreed (an output's, a checkpoint's, the heat's) or this rank's alone
    fail(step_, time_, "step " + std::to_string(step_) + ", t = " + format_number(time_) + " s: " + agreed(e.what()));
  }
  progress.finish();
  if (r_.status != RunResult::Status::failed) {  // as the serial run: no row or snapshot of a failed state
    // At the end, a stop at run.max_steps or an interruption: before the off-schedule row and
    // snapshot below, which an uninterrupted run does not have (a resume drops them).
    // Interrupted (SIGINT/SIGTERM): a checkpoint also without run.checkpoint_interval, so that `mpirun
    // -n K frictherm resume` goes on (issue 34, as the serial run). Once a continuation began, the
    // end-of-loading checkpoint stays: a resume reruns the continuation from it.
    const bool interrupted = r_.status == RunResult::Status::interrupted;
    try {
      if ((checkpoints_ || interrupted) && !continuation_started_ &&
          (!loading_complete_ || end_of_loading_checkpoint_exact()))
        checkpoint();
      if (last_series_step_ != step_) series();
      if (last_snapshot_step_ != step_) snapshot();
    } catch (const std::exception& e) {
      fail(step_, time_, "writing the end of the run at step " + std::to_string(step_) + ", t = " +
                             format_number(time_) + " s: " + agreed(e.what()));
    }
  }
  if (r_.status == RunResult::Status::interrupted)
    r_.message = std::string("interrupted by ") + detail::signal_name(r_.signal) + " at step " + std::to_string(step_) +
                 ", t = " + format_number(time_) + " s";
  if (r_.status == RunResult::Status::stopped_at_max_steps && !o_.quiet && rank_ == 0)
    (o_.log ? *o_.log : std::cerr) << "frictherm: note: stopped at run.max_steps = " << s_.max_steps << " (t = " << time_
                                   << " s of end_time " << s_.end_time << " s)\n";
  r_.steps = step_;
  r_.time = time_;
  r_.wall_time = seconds_since(t0);
  record_phase_seconds();
  try {  // rank 0 writes its metadata after the reductions: a failure there is rank 0's alone
    detail::record_decomposed_traffic(comm_, mpm_->traffic(), mpm_->local_particles(), out_.get(),
                                      o_.quiet ? nullptr : (o_.log ? o_.log : &std::cerr));
  } catch (const std::exception& e) {
    note_write_error(e.what());
  }
  r_.snapshots = static_cast<std::size_t>(snapshots_);
  if (heat_) pending_heat_ = heat_->pending_heat();  // collective
  if (heat_) particle_reaction_heat_ = heat_->particle_reaction_heat();  // collective
  finish_output();  // agreed by every rank
  snapshots_out_->close();
  if (heat_ && rank_ == 0 && !o_.quiet) detail::print_decomposed_books(o_.log ? *o_.log : std::cerr, heat_->books(), size_);
  return r_;
}

template <int Dim>
void DecomposedRun<Dim>::check_output_files() {
  std::string error;
  if (rank_ == 0) {
    try {
      check_output_folder(r_.output, o_.output.empty() ? "output.file" : "output file");
      const std::vector<std::string> inputs = scene_input_files(s_);
      claim_ = std::make_unique<OutputClaim>(r_.output);
      const std::vector<std::string> companions = xdmf_paths_for(r_.output);
      for (const std::string& f : decomposed_output_files(r_.output, size_))
        (std::find(companions.begin(), companions.end(), f) != companions.end() ? check_companion_path : check_output_path)(
            f, inputs, overwrite(), "--force or \"output\": {\"overwrite\": true}");
      check_output_path(checkpoint_file_, inputs, true, "");  // every run may write one: an interrupted run does
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
}

template <int Dim>
void DecomposedRun<Dim>::build() {
  grid_ = std::make_unique<mechanics::Grid<Dim>>(detail::scene_grid<Dim>(s_));
  typename Mpm::Options options = detail::decomposed_options<Dim>(s_);
  // The particles first: the serial build resolves the loads to them.
  std::vector<typename Mpm::Particle> particles = detail::scene_particles<Dim>(comm_, s_, options.loads);
  try {
    mpm_ = std::make_unique<Mpm>(comm_, *grid_, s_.materials, options);
  } catch (const std::invalid_argument& e) {  // thrown on every rank alike: all hold the same scene
    throw SceneError(e.what());
  }
  mpm_->add_particles(particles);
  particles = {};
  r_.particles = static_cast<std::size_t>(mpm_->global_particles());
  temperature_ = mpm_->particle_scalar_index("temperature");
  if (s_.thermal.enabled) {
    const CouplerOptions& c = s_.thermal.coupler;
    DecomposedHeatOptions h;
    h.materials = c.materials;
    h.assembly = c.assembly;
    h.fe_safety = c.integrator_options.fe_safety;
    h.order = s_.thermal.heating_order;
    h.integrator = c.integrator;
    h.integrator_options = c.integrator_options;
    h.preconditioner = s_.thermal.preconditioner;
    h.matrix_free_max_substeps = c.matrix_free_max_substeps;
    h.reuse_distance = detail::gather_reuse(s_) ? c.reuse_distance : 0.0;
    h.window = c.window;
    h.plastic = c.plastic;
    h.subgrid_relaxation_time = c.subgrid_relaxation_time;
    h.fixed_faces = c.fixed_faces;
    h.interface_temperature = c.interface_temperature;
    h.reaction = c.reaction;
    h.thickness = c.thickness;
    try {
      heat_ = std::make_unique<DecomposedHeat>(*mpm_, h);
    } catch (const std::invalid_argument& e) {
      throw SceneError::at_key("thermal.materials", e.what());
    }
    hot_ = std::make_unique<detail::DecomposedHotSpots<Dim>>(s_, *mpm_);
    hot_->update(*mpm_, 0.0);  // the initial hot spots, as the serial Coupler::start
  }
}

template <int Dim>
void DecomposedRun<Dim>::stable_time_step(double& dt, int& signal, bool& checkpoint_due) const {
  const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
  constexpr double none = -std::numeric_limits<double>::infinity();
  // max of −id: lowest id; the last: whether --checkpoint-every's wall interval has passed on some rank
  const bool wall = wall_interval_ > 0.0 && seconds_since(last_checkpoint_) >= wall_interval_;
  // v[4]: the highest rank whose friction law threw in the step (-1: none).
  double v[5] = {static_cast<double>(detail::interrupt_signal()), none, none, wall ? 1.0 : 0.0,
                 mpm_->contact_failure().empty() ? -1.0 : static_cast<double>(rank_)};
  for (std::size_t k = 0; k < p.mass.size(); ++k) {
    const Eigen::Map<const mechanics::Vec<Dim>> vk(p.velocity.data() + Dim * k), xk(p.position.data() + Dim * k);
    if (!(vk.allFinite() && xk.allFinite()))
      v[1] = std::max(v[1], -static_cast<double>(p.id[k]));
    else if (!grid_->contains(xk))
      v[2] = std::max(v[2], -static_cast<double>(p.id[k]));
  }
  MPI_Allreduce(MPI_IN_PLACE, v, 5, MPI_DOUBLE, MPI_MAX, comm_);
  signal = static_cast<int>(v[0]);
  checkpoint_due = v[3] > 0.0;
  if (v[4] >= 0.0) {  // every rank: the failing rank's message, then the run's ordinary breakdown
    const int from = static_cast<int>(v[4]);
    std::string what = mpm_->contact_failure();
    long length = static_cast<long>(what.size());
    MPI_Bcast(&length, 1, MPI_LONG, from, comm_);
    what.resize(static_cast<std::size_t>(length));
    MPI_Bcast(what.data(), static_cast<int>(length), MPI_CHAR, from, comm_);
    throw mechanics::SimulationError("step " + std::to_string(step_) + ", t = " + format_number(time_) + " s: " +
                                         what + " (on rank " + std::to_string(from) + ")",
                                     step_, time_, -1);
  }
  const std::string at = "step " + std::to_string(step_) + ", t = " + format_number(time_) + " s: particle ";
  if (v[1] > none)
    throw mechanics::SimulationError(at + format_number(-v[1]) + " has a non-finite velocity or position (the step "
                                          "blew up; try a smaller CFL factor)", step_, time_, static_cast<long>(-v[1]));
  if (v[2] > none) {
    std::string span;
    for (int d = 0; d < Dim; ++d) span += (d ? ", " : "") + format_number(grid_->lo()[d]);
    span += ") to (";
    for (int d = 0; d < Dim; ++d) span += (d ? ", " : "") + format_number(grid_->hi()[d]);
    throw mechanics::SimulationError(at + format_number(-v[2]) + " left the grid; grid spans (" + span + ") m", step_,
                                     time_, static_cast<long>(-v[2]));
  }
  dt = mpm_->stable_time_step(s_.options.cfl, s_.options.max_time_step);
}

template <int Dim>
void DecomposedRun<Dim>::loop(detail::ProgressLine& progress) {
  const double T = s_.end_time;
  detail::OutputSchedule schedule(T, s_.output.snapshot_interval, s_.output.series_interval, time_);
  const double eps = schedule.eps();
  const double ci = s_.checkpoint_interval;  // the next multiple after the start (as the serial loop)
  double next_checkpoint = ci > 0.0 ? (std::floor(time_ / ci + 1e-9) + 1.0) * ci : std::numeric_limits<double>::infinity();
  double stable = 0.0;
  int signal = 0;
  bool wall_due = false;
  stable_time_step(stable, signal, wall_due);
  while (time_ < T - eps) {
    if (signal != 0) {
      r_.status = RunResult::Status::interrupted;
      r_.signal = signal;
      return;
    }
    if (s_.max_steps > 0 && step_ >= s_.max_steps) {
      r_.status = RunResult::Status::stopped_at_max_steps;
      return;
    }
    // As the serial loop: land on the next snapshot time, the last stretch in two similar steps.
    double limit = schedule.next_snapshot() - time_;
    if (step_ == 0 || limit < 3.0 * last_dt_)
      if (limit > stable && limit < 2.0 * stable) limit *= 0.5;
    const double dt = std::min(stable, limit);
    if (!(dt > 0.0) || !std::isfinite(dt) || !(time_ + dt > time_))
      throw mechanics::SimulationError("step " + std::to_string(step_) + ", t = " + format_number(time_) +
                                           " s: the time step " + format_number(dt) + " s does not advance the time",
                                       step_, time_, -1);
    if (rank_ == fault_rank_ && step_ == fault_step_) throw std::bad_alloc();  // FRICTHERM_FAULT_DECOMPOSED
    mpm_->step(dt);  // times its own phases (DecomposedTraffic::phase_seconds)
    time_ += dt;
    last_dt_ = dt;
    ++step_;
    stable_time_step(stable, signal, wall_due);  // throws SimulationError on every rank for a broken state
    const double t = time_;
    if (heat_) {
      const Clock::time_point h0 = Clock::now();
      const double solve0 = heat_->integrator_stats().wall_seconds;  // this rank's, as the serial runner's
      try {
        // The serial run closes the window at every snapshot time and at the end (runner.cpp).
        if (heat_->after_step(dt, schedule.snapshot_reached(t))) hot_->update(*mpm_, time_);  // after every window
      } catch (const thermal::SolverError& e) {  // on every rank (the integrator's agreement)
        throw mechanics::SimulationError(std::string("thermal solver failed: ") + e.what(), step_, time_, -1);
      } catch (const thermal::StabilityError& e) {
        throw mechanics::SimulationError(std::string("thermal integration unstable: ") + e.what(), step_, time_, -1);
      }
      heating_seconds_ += seconds_since(h0);
      loading_solve_seconds_ += heat_->integrator_stats().wall_seconds - solve0;
    }
    if (schedule.series_due(t)) series();
    if (schedule.snapshot_due(t)) snapshot();
    if ((checkpoints_ || wall_due) && t < T - eps && (t >= next_checkpoint - eps || wall_due)) {  // the end: after the loop
      checkpoints_ = true;  // a default wall-clock checkpoint makes the run one that checkpoints (also at its end)
      checkpoint();
      if (ci > 0.0) next_checkpoint = (std::floor(t / ci + 1e-9) + 1.0) * ci;
    }
    progress.update(step_, t);
  }
  loading_complete_ = !(time_ < T - eps);
  if (signal != 0) {  // caught during the last step: the run is complete, but say so as the serial run
    r_.status = RunResult::Status::interrupted;
    r_.signal = signal;
  }
}

template <int Dim>
void DecomposedRun<Dim>::continuation() {
  const ThermalSceneSpec& spec = s_.thermal;
  const auto thermal_failure = [this](const char* what, const std::exception& e, double t) {
    return mechanics::SimulationError(std::string(what) + e.what(), step_, t, -1);
  };
  heat_->close_window();  // a no-op after the loading's last step (closed at the end)
  const double t0 = time_;
  const long n = spec.continuation_intervals;
  double t = t0;
  for (long k = 1; k <= n; ++k) {
    t = t0 + spec.continuation_duration * static_cast<double>(k) / static_cast<double>(n);
    if (k == 1) hot_->begin_fates(t0);  // the hot spots at the end of loading
    try {
      heat_->continue_thermal(t);
    } catch (const thermal::SolverError& e) {  // on every rank (the integrator's agreement)
      throw thermal_failure("thermal solver failed: ", e, t);
    } catch (const thermal::StabilityError& e) {
      throw thermal_failure("thermal integration unstable: ", e, t);
    }
    hot_->update(*mpm_, t);
    const std::vector<double> interface_progress = heat_->interface_reaction_progress(*mpm_);
    hot_->update_fates(*mpm_, t, heat_->interface_reaction().started() ? &interface_progress : nullptr);
    series(t);  // the mechanics columns stay at their final values
    const HotSpotFates& f = hot_->fates();
    if (spec.stop_when_decided && !f.records().empty() && f.all_decided()) break;
    int signal = detail::interrupt_signal();  // SIGINT/SIGTERM on any rank: every rank ends with this interval
    MPI_Allreduce(MPI_IN_PLACE, &signal, 1, MPI_INT, MPI_MAX, comm_);
    if (signal != 0) {
      r_.status = RunResult::Status::interrupted;
      r_.signal = signal;
      break;
    }
  }
  hot_->fates().finish();
  std::string error;
  if (out_) {
    try {
      for (const HotSpotFateRecord& r : hot_->fates().records())
        out_->append_table_row("hotspot_fates", hotspot_fate_row(r));
    } catch (const std::exception& e) {
      note_write_error(e.what());
      error = std::string("writing '") + out_->live_path() + "': " + e.what();
    }
  }
  if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw std::runtime_error(why);
  snapshot(t);
}

template <int Dim>
void DecomposedRun<Dim>::record_phase_seconds() {
  const mechanics::DecomposedTraffic& tr = mpm_->traffic();
  auto& ph = r_.phase_seconds;
  ph.clear();
  for (std::size_t i = 0; i < tr.phase_seconds.size(); ++i) ph.emplace_back(Mpm::phase_names()[i], tr.phase_seconds[i]);
  // The serial run's split of the heat's time: the rest, inside the integrator, the continuation.
  ph.emplace_back("heating", heating_seconds_ - loading_solve_seconds_);
  ph.emplace_back("thermal_solve", loading_solve_seconds_);
  ph.emplace_back("continuation", continuation_seconds_);
  ph.emplace_back("output", output_seconds_);
  double accounted = 0.0;
  for (const auto& x : ph) accounted += x.second;
  ph.emplace_back("other", r_.wall_time - accounted);
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(D) \
  template DecomposedRun<D>::DecomposedRun(MPI_Comm comm, const Scene& scene, const RunOptions& options); \
  template DecomposedRun<D>::~DecomposedRun(); \
  template RunResult DecomposedRun<D>::execute(); \
  template void DecomposedRun<D>::check_output_files(); \
  template void DecomposedRun<D>::build(); \
  template void DecomposedRun<D>::stable_time_step(double& dt, int& signal, bool& checkpoint_due) const; \
  template void DecomposedRun<D>::loop(detail::ProgressLine& progress); \
  template void DecomposedRun<D>::continuation(); \
  template void DecomposedRun<D>::record_phase_seconds();
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_RUN(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_RUN

}  // namespace frictherm::coupling::decomposed

namespace frictherm::coupling {

std::vector<std::string> decomposed_output_files(const std::string& out, int ranks) {
  std::vector<std::string> files{out};
  for (const std::string& f : xdmf_paths_for(out)) files.push_back(f);
  for (int r = 0; r < ranks; ++r) files.push_back(DecomposedOutput::rank_file(decomposed::output_base(out), r));
  return files;
}

RunResult run_scene_decomposed(MPI_Comm comm, const Scene& scene, const RunOptions& options) {
  if (scene.dimension == 2) return decomposed::DecomposedRun<2>(comm, scene, options).execute();
  return decomposed::DecomposedRun<3>(comm, scene, options).execute();
}

}  // namespace frictherm::coupling
