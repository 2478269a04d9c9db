// The decomposed run loop (decomposed_run.hpp): the serial run loop's time stepping (CFL from each
// particle's dilatational wave speed plus its speed, DecomposedMpm::stable_time_step, the largest over
// all ranks; landing on every snapshot time and on end_time), the engine's USL step and the heat
// hand-off of DecomposedHeat every step, its windows closed by the scene's policy and at every snapshot
// time (as the serial ThermalRun::after_step); series on rank 0 (OUT.h5), particle snapshots per rank
// joined by OUT.xdmf. Checkpoints (decomposed_checkpoint.hpp) at run.checkpoint_interval, every
// --checkpoint-every wall seconds, at the end and on SIGINT/SIGTERM; a resumed run restores them and
// rewrites OUT.h5 with the checkpoint's series rows, keeping the rank files' snapshots up to it.
#include "distributed_run/decomposed_checkpoint.hpp"
#include "distributed_run/decomposed_hotspots.hpp"
#include "distributed_run/decomposed_redistribute.hpp"
#include "distributed_run/decomposed_setup.hpp"
#include "run/checkpoint_io.hpp"
#include "run/run_signals.hpp"
#include "run/runner_detail.hpp"

#include <frictherm/coupling/decomposed_heat.hpp>
#include <frictherm/coupling/decomposed_run.hpp>
#include <frictherm/coupling/distributed.hpp>
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>
#include <frictherm/mechanics/errors.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>

namespace frictherm::coupling {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// OUT.xdmf without its extension: the base of DecomposedOutput's files (OUT.rank<r>.h5, OUT.xdmf).
std::string output_base(const std::string& out) {
  const std::string x = xdmf_path_for(out);
  return x.substr(0, x.size() - 5);
}

template <int Dim>
class DecomposedRun {
 public:
  using Mpm = mechanics::DecomposedMpm<Dim>;
  DecomposedRun(MPI_Comm comm, const Scene& scene, const RunOptions& options) : comm_(comm), s_(scene), o_(options) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }

  RunResult execute() {
    const Clock::time_point t0 = Clock::now();
    if (o_.observer) throw std::invalid_argument("a decomposed run has no per-step observer");
    const detail::InterruptGuard interrupt_guard(o_.handle_signals);
    r_.output = o_.output.empty() ? s_.output.file : o_.output;
    resuming_ = !o_.resume_checkpoint.empty();
    checkpoints_ = s_.checkpoint_interval > 0.0 || o_.checkpoint_wall_interval > 0.0;
    checkpoint_file_ = o_.checkpoint_file.empty() ? checkpoint_path(r_.output) : o_.checkpoint_file;
    if (!resuming_) check_output_files();  // before anything is built: refusals cost nothing
    if (checkpoints_ && !resuming_) generation_ = detail::committed_generation(comm_, checkpoint_file_);
    build();
    if (resuming_) restore();
    open_output();
    if (!resuming_) {  // a resumed run's output has the checkpoint's rows and snapshots already
      series();
      snapshot();
    }
    detail::ProgressLine progress(std::cerr, rank_ == 0 && show_progress(), s_.end_time);
    last_flush_ = last_checkpoint_ = Clock::now();
    try {
      loop(progress);
    } catch (const mechanics::SimulationError& e) {  // agreed by every rank (one reduction)
      r_.status = RunResult::Status::failed;
      r_.message = e.what();
      write_failure(e.step(), e.time());
    }
    progress.finish();
    if (r_.status != RunResult::Status::failed) {  // as the serial run: no row or snapshot of a failed state
      // At the end, a stop at run.max_steps or an interruption: before the off-schedule row and
      // snapshot below, which an uninterrupted run does not have (a resume drops them).
      if (checkpoints_) checkpoint();
      if (last_series_step_ != step_) series();
      if (last_snapshot_step_ != step_) snapshot();
    }
    if (r_.status == RunResult::Status::interrupted) {
      r_.message = std::string("interrupted by ") + detail::signal_name(r_.signal) + " at step " + std::to_string(step_) +
                   ", t = " + format_number(time_) + " s";
      if (out_) out_->write_metadata("interruption", r_.message);
    }
    if (r_.status == RunResult::Status::stopped_at_max_steps && !o_.quiet && rank_ == 0)
      (o_.log ? *o_.log : std::cerr) << "frictherm: note: stopped at run.max_steps = " << s_.max_steps << " (t = " << time_
                                     << " s of end_time " << s_.end_time << " s)\n";
    r_.steps = step_;
    r_.time = time_;
    r_.wall_time = seconds_since(t0);
    record_phase_seconds();
    detail::record_decomposed_traffic(comm_, mpm_->traffic(), mpm_->local_particles(), out_.get(),
                                      o_.quiet ? nullptr : (o_.log ? o_.log : &std::cerr));
    r_.snapshots = static_cast<std::size_t>(snapshots_);
    if (heat_) pending_heat_ = heat_->pending_heat();  // collective
    if (out_) finish_output();
    snapshots_out_->close();
    if (heat_ && rank_ == 0 && !o_.quiet) detail::print_decomposed_books(o_.log ? *o_.log : std::cerr, heat_->books(), size_);
    return r_;
  }

 private:
  bool overwrite() const { return o_.overwrite || s_.output.overwrite; }

  bool show_progress() const {
    if (o_.quiet || o_.progress == RunOptions::Progress::never) return false;
    return o_.progress == RunOptions::Progress::always || isatty(STDERR_FILENO) != 0;
  }

  // Rank 0 checks every file of every rank as the serial run checks its output (docs/robustness.md):
  // never an input, an existing file only with --force / output.overwrite; all ranks agree.
  // Rank 0 also claims the output for the run (OutputClaim, as the serial run; issue 34).
  void check_output_files() {
    std::string error;
    if (rank_ == 0) {
      try {
        check_output_folder(r_.output, o_.output.empty() ? "output.file" : "output file");
        const std::vector<std::string> inputs = scene_input_files(s_);
        claim_ = std::make_unique<OutputClaim>(r_.output);
        for (const std::string& f : decomposed_output_files(r_.output, size_))
          check_output_path(f, inputs, overwrite(), "--force or \"output\": {\"overwrite\": true}");
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
  }

  void build() {
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
      h.window = c.window;
      h.plastic = c.plastic;
      h.subgrid_relaxation_time = c.subgrid_relaxation_time;
      try {
        heat_ = std::make_unique<DecomposedHeat>(*mpm_, h);
      } catch (const std::invalid_argument& e) {
        throw SceneError(std::string("thermal.materials: ") + e.what());
      }
      hot_ = std::make_unique<detail::DecomposedHotSpots<Dim>>(s_, *mpm_);
      hot_->update(*mpm_, 0.0);  // the initial hot spots, as the serial Coupler::start
    }
  }

  void open_output() {
    std::string error;
    if (rank_ == 0) {
      try {
        H5OutputOptions options;
        options.write_xdmf = false;  // OUT.xdmf joins the rank files (DecomposedOutput)
        options.via_temporary = true;
        options.replace_existing = overwrite() || resuming_;  // a resume rewrites OUT.h5 (checkpoint's rows first)
        out_ = std::make_unique<H5Output>(r_.output, Dim, options);
        write_start_metadata();
        out_->declare_series(series_names());
        if (hot_) hot_->declare_table(*out_);
        if (resuming_) rewrite_rows();
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
    try {
      snapshots_out_ = resuming_ ? std::make_unique<DecomposedOutput>(comm_, output_base(r_.output), Dim, snapshots_,
                                                                      detail::split_grids(xdmf_grids_),
                                                                      redistributed_from_ > 0)
                                 : std::make_unique<DecomposedOutput>(comm_, output_base(r_.output), Dim, overwrite());
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
  }

  void write_start_metadata() {
    out_->write_metadata("scene", s_.text);
    out_->write_metadata("scene_json", s_.json);
    out_->write_metadata("scene_file", s_.source);
    out_->write_metadata("version", FRICTHERM_VERSION);
    out_->write_metadata("command_line", o_.command_line);
    out_->write_metadata("status", "running");
    out_->write_metadata("dimension", Dim);
    out_->write_metadata("engine", "decomposed");
    out_->write_metadata("ranks", size_);
    std::string grid;
    for (int p : mpm_->processes()) grid += (grid.empty() ? "" : " x ") + std::to_string(p);
    out_->write_metadata("process_grid", grid);
    out_->write_metadata("particle_count", r_.particles);
    out_->write_metadata("snapshots", xdmf_path_for(r_.output));
  }

  // The serial run's column names where the quantity is the same (runner_output.cpp, runner_thermal.cpp).
  std::vector<std::string> series_names() const {
    std::vector<std::string> n{"time", "step", "dt", "kinetic_energy", "external_work"};
    const char* axes[3] = {"momentum_x", "momentum_y", "momentum_z"};
    for (int d = 0; d < Dim; ++d) n.emplace_back(axes[d]);
    n.emplace_back("damping_work");
    if (s_.contact.enabled)
      n.insert(n.end(), {"friction_work_first", "friction_work_second", "contact_nodes", "sliding_nodes"});
    if (heat_) {
      n.insert(n.end(), {"heat_delivered", "thermal_energy_change", "max_temperature"});
      for (const std::string& c : detail::DecomposedHotSpots<Dim>::series_names()) n.push_back(c);
      n.insert(n.end(), {"thermal_windows", "work_received", "nodal_energy_change"});
      if (s_.thermal.coupler.plastic.enabled) n.insert(n.end(), {"plastic_work", "plastic_heat"});
    }
    return n;
  }

  // Collective: one reduction for whether any rank caught SIGINT/SIGTERM and the lowest id of a
  // particle with a non-finite state or outside the grid (the serial step's check), which becomes a
  // SimulationError on every rank; then the engine's stable step, C min(h) / max_p (c_p + |v_p|) over
  // all ranks with c_p of each particle's state (Mie-Grüneisen: its current wave speed), as the serial
  // Simulation::stable_time_step.
  void stable_time_step(double& dt, int& signal, bool& checkpoint_due) const {
    const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
    constexpr double none = -std::numeric_limits<double>::infinity();
    // max of −id: lowest id; the last: whether --checkpoint-every's wall interval has passed on some rank
    const bool wall = o_.checkpoint_wall_interval > 0.0 && seconds_since(last_checkpoint_) >= o_.checkpoint_wall_interval;
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

  // The serial loop (runner.cpp) with two reductions per step: after each mechanics step, the next
  // step's stable Δt, the interrupt flag and the state check (before the heat reads the particles).
  void loop(detail::ProgressLine& progress) {
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
      mpm_->step(dt);  // times its own phases (DecomposedTraffic::phase_seconds)
      time_ += dt;
      last_dt_ = dt;
      ++step_;
      stable_time_step(stable, signal, wall_due);  // throws SimulationError on every rank for a broken state
      const double t = time_;
      if (heat_) {
        const Clock::time_point h0 = Clock::now();
        try {
          // The serial run closes the window at every snapshot time and at the end (runner.cpp).
          if (heat_->after_step(dt, schedule.snapshot_reached(t))) hot_->update(*mpm_, time_);  // after every window
        } catch (const thermal::SolverError& e) {  // on every rank (the integrator's agreement)
          throw mechanics::SimulationError(std::string("thermal solver failed: ") + e.what(), step_, time_, -1);
        } catch (const thermal::StabilityError& e) {
          throw mechanics::SimulationError(std::string("thermal integration unstable: ") + e.what(), step_, time_, -1);
        }
        heating_seconds_ += seconds_since(h0);
      }
      if (schedule.series_due(t)) series();
      if (schedule.snapshot_due(t)) snapshot();
      if (checkpoints_ && t < T - eps && (t >= next_checkpoint - eps || wall_due)) {  // the end: after the loop
        checkpoint();
        if (ci > 0.0) next_checkpoint = (std::floor(t / ci + 1e-9) + 1.0) * ci;
      }
      progress.update(step_, t);
    }
    if (signal != 0) {  // caught during the last step: the run is complete, but say so as the serial run
      r_.status = RunResult::Status::interrupted;
      r_.signal = signal;
    }
  }

  // Collective: one row; rank 0 appends it.
  void series() {
    const Clock::time_point c0 = Clock::now();
    const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
    // Kinetic energy and momentum of the deformable particles, as Simulation::kinetic_energy and
    // linear_momentum (a rigid wall's prescribed motion is not part of the body's).
    double sums[1 + Dim] = {};
    for (std::size_t k = 0; k < p.mass.size(); ++k) {
      if (s_.materials[static_cast<std::size_t>(p.material[k])].is_rigid()) continue;
      const Eigen::Map<const mechanics::Vec<Dim>> vk(p.velocity.data() + Dim * k);
      sums[0] += 0.5 * p.mass[k] * vk.squaredNorm();
      for (int d = 0; d < Dim; ++d) sums[1 + d] += p.mass[k] * vk[d];
    }
    MPI_Allreduce(MPI_IN_PLACE, sums, 1 + Dim, MPI_DOUBLE, MPI_SUM, comm_);
    std::vector<double> row{time_, static_cast<double>(step_), last_dt_, sums[0], mpm_->external_work()};
    for (int d = 0; d < Dim; ++d) row.push_back(sums[1 + d]);
    row.push_back(mpm_->damping_work());
    if (s_.contact.enabled) {
      const double w1 = mpm_->cumulative_frictional_work(mechanics::HeatingOrder::first);
      const double w2 = mpm_->cumulative_frictional_work(mechanics::HeatingOrder::second);
      const mechanics::DecomposedContactStats cs = mpm_->contact_stats();
      row.insert(row.end(), {w1, w2, static_cast<double>(cs.contact_nodes), static_cast<double>(cs.sliding_nodes)});
    }
    if (heat_) {
      const DecomposedHeatBooks& b = heat_->books();
      // The highest temperature of the conducting particles over all ranks, from the last update.
      row.insert(row.end(), {b.heat_delivered, b.particle_energy_change, hot_->tracker().max_temperature()});
      hot_->extend_series_row(row);
      row.insert(row.end(), {static_cast<double>(b.windows), b.work_received, b.nodal_energy_change});
      if (s_.thermal.coupler.plastic.enabled) row.insert(row.end(), {b.plastic_work_received, b.plastic_heat_received});
    }
    if (out_) {
      out_->append_series(row);
      series_rows_.insert(series_rows_.end(), row.begin(), row.end());  // for checkpoints
      series_columns_ = static_cast<long>(row.size());
      if (hot_) hot_->append_table_rows(*out_, time_);
      if (seconds_since(last_flush_) >= o_.flush_interval) {
        out_->flush();
        last_flush_ = Clock::now();
      }
    }
    last_series_step_ = step_;
    output_seconds_ += seconds_since(c0);
  }

  // Collective: the failing state under /failure of OUT.h5 as the serial run writes it (every
  // particle, gathered by id: position, velocity, material; a failed run's cost is not a concern),
  // and the message in /meta/failure. A failure to write that state is added to the message.
  void write_failure(long step, double time) {
    const std::vector<typename Mpm::Particle> all = mpm_->gather();
    if (rank_ != 0 || !out_) return;
    try {
      const std::size_t n = all.size();
      std::vector<double> position(n * Dim), velocity(n * 3, 0.0);
      std::vector<std::int32_t> material(n);
      for (std::size_t k = 0; k < n; ++k) {
        for (int d = 0; d < Dim; ++d) {
          position[k * Dim + static_cast<std::size_t>(d)] = all[k].position[d];
          velocity[k * 3 + static_cast<std::size_t>(d)] = all[k].velocity[d];
        }
        material[k] = all[k].material;
      }
      out_->begin_failure(step, time, r_.message);
      out_->snapshot_field("position", position.data(), n, Dim);
      out_->snapshot_field("velocity", velocity.data(), n, 3);
      out_->snapshot_field("material", material.data(), n);
      out_->end_snapshot();
    } catch (const std::exception& e) {
      r_.message += std::string(" (the failing state was not written: ") + e.what() + ")";
    }
    out_->write_metadata("failure", r_.message);
  }

  // Collective: every rank writes its particles; rank 0 rewrites OUT.xdmf.
  void snapshot() {
    const Clock::time_point c0 = Clock::now();
    const mechanics::DecomposedLocalParticles p = mpm_->local_particle_data(true);
    DecomposedSnapshot snap;
    snap.id = p.id;
    snap.position = p.position;
    snap.velocity = p.velocity;
    snap.material = p.material;
    snap.temperature = mpm_->particle_scalar(temperature_);
    snapshots_out_->write(step_, time_, snap);
    ++snapshots_;
    last_snapshot_step_ = step_;
    output_seconds_ += seconds_since(c0);
  }

  void record_phase_seconds() {
    const mechanics::DecomposedTraffic& tr = mpm_->traffic();
    auto& ph = r_.phase_seconds;
    ph.clear();
    for (std::size_t i = 0; i < tr.phase_seconds.size(); ++i) ph.emplace_back(Mpm::phase_names()[i], tr.phase_seconds[i]);
    ph.emplace_back("heating", heating_seconds_);
    ph.emplace_back("output", output_seconds_);
    double accounted = 0.0;
    for (const auto& x : ph) accounted += x.second;
    ph.emplace_back("other", r_.wall_time - accounted);
  }

  // Rank 0: metadata and books, then OUT.h5.<pid>.part renamed onto OUT.h5.
  void finish_output() {
    r_.series_rows = out_->series_rows();
    for (const auto& [name, seconds] : r_.phase_seconds) out_->write_metadata("time_" + name, seconds);
    if (heat_)
      detail::write_decomposed_heat_metadata(*out_, s_, *heat_, pending_heat_, hot_->tracker().ids_issued());
    const char* status = r_.status == RunResult::Status::failed                 ? "failed"
                         : r_.status == RunResult::Status::stopped_at_max_steps ? "stopped_at_max_steps"
                         : r_.status == RunResult::Status::interrupted          ? "interrupted"
                                                                                : "completed";
    out_->write_metadata("status", status);
    if (checkpoints_written_ > 0) {
      out_->write_metadata("checkpoints_written", checkpoints_written_);
      out_->write_metadata("checkpoint_write_time", checkpoint_seconds_);  // s, this process's checkpoints
    }
    if (resuming_) out_->write_metadata("resumed_from", o_.resume_checkpoint);
    if (redistributed_from_ > 0) out_->write_metadata("resumed_from_ranks", redistributed_from_);
    out_->write_metadata("steps", r_.steps);
    out_->write_metadata("final_time", r_.time);
    out_->write_metadata("wall_time", r_.wall_time);
    try {
      out_->close();
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
  }

  MPI_Comm comm_;
  const Scene& s_;
  const RunOptions& o_;
  int rank_ = 0, size_ = 1;
  RunResult r_;
  std::unique_ptr<mechanics::Grid<Dim>> grid_;
  std::unique_ptr<Mpm> mpm_;
  std::unique_ptr<DecomposedHeat> heat_;  // scenes with a `thermal` section
  std::unique_ptr<detail::DecomposedHotSpots<Dim>> hot_;  // with heat_
  std::unique_ptr<OutputClaim> claim_;    // rank 0: the output claimed for the run
  std::unique_ptr<H5Output> out_;         // rank 0: series and metadata
  std::unique_ptr<DecomposedOutput> snapshots_out_;
  int temperature_ = 0;
  double time_ = 0.0, last_dt_ = 0.0;
  long step_ = 0, snapshots_ = 0;
  long last_series_step_ = -1, last_snapshot_step_ = -1;
  double heating_seconds_ = 0.0, output_seconds_ = 0.0;
  double pending_heat_ = 0.0;  // work of a window left open (a stop at run.max_steps, an interruption), J
  Clock::time_point last_flush_ = Clock::now();
  // Checkpoints: whether this run writes them, where, the generation of the last one, the clock of
  // --checkpoint-every; rank 0: every series row so far (flat) and OUT.xdmf's grids (from a resume).
  bool checkpoints_ = false, resuming_ = false;
  std::string checkpoint_file_;
  long generation_ = 0, checkpoints_written_ = 0;
  double checkpoint_seconds_ = 0.0;
  Clock::time_point last_checkpoint_ = Clock::now();
  std::vector<double> series_rows_;
  long series_columns_ = 0;
  std::string xdmf_grids_;
  typename Mpm::CheckpointState restored_;
  int redistributed_from_ = 0;  // ranks of a checkpoint resumed on another number of ranks

  // Collective: one checkpoint (decomposed_checkpoint.hpp), marks as the serial run's.
  void checkpoint() {
    const Clock::time_point c0 = Clock::now();
    CheckpointMarks m;
    m.step = step_;
    m.time = time_;
    m.series_rows = series_columns_ > 0 ? static_cast<long>(series_rows_.size()) / series_columns_ : 0;
    m.snapshots = snapshots_;
    if (hot_) m.table_rows.emplace_back("hotspots", hot_->table_rows());
    xdmf_grids_ = detail::join_grids(snapshots_out_->xdmf_grids());
    try {
      detail::write_decomposed_checkpoint(
          comm_, checkpoint_file_, s_, Dim, ++generation_, m, [&](const ckpt::Writer& w) { visit_rank_state(w); },
          [&](const ckpt::Writer& w) { visit_global_state(w); });
    } catch (const std::runtime_error& e) {  // on every rank; the previous checkpoint is whole
      throw OutputError(e.what());
    }
    if (rank_ == 0 && redistributed_from_ > size_ && checkpoints_written_ == 0)  // the resumed generation's
      for (int j = size_; j < redistributed_from_; ++j)                          // files of ranks gone
        std::remove(detail::decomposed_rank_checkpoint(checkpoint_file_, generation_ - 1, j).c_str());
    last_checkpoint_ = Clock::now();
    ++checkpoints_written_;
    checkpoint_seconds_ += seconds_since(c0);
  }

  // Collective: the state of o_.resume_checkpoint (every rank's own file and the global one; of
  // another rank count: decomposed_redistribute.hpp).
  void restore() {
    if (const int old = checkpoint_ranks(o_.resume_checkpoint); old > 0 && old != size_) {
      redistribute(old);
      return;
    }
    try {  // read errors are agreed by every rank
      generation_ = detail::read_decomposed_checkpoint(
          comm_, o_.resume_checkpoint, Dim, [&](const ckpt::Reader& r) { visit_rank_state(r); },
          [&](const ckpt::Reader& r) { visit_global_state(r); });
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
    std::string error;
    try {
      mpm_->restore_checkpoint_state(restored_);
    } catch (const std::exception& e) {
      error = o_.resume_checkpoint + ": " + e.what();
    }
    if (const std::string why = detail::agreed_error(comm_, error); !why.empty()) throw OutputError(why);
    restored_ = {};
  }

  // This rank: its particles (every swarm field, in swarm order), the mechanics' books and the heat.
  template <class V> void visit_rank_state(const V& v) {
    typename Mpm::CheckpointState st = mpm_->checkpoint_state();  // reading: the names and a template
    for (auto& [name, values] : st.reals) v(("mechanics/" + name).c_str(), values);
    for (auto& [name, values] : st.integers) v(("mechanics/" + name).c_str(), values);
    v("mechanics/time", st.time);
    v("mechanics/cumulative_work_first", st.cumulative_first);
    v("mechanics/cumulative_work_second", st.cumulative_second);
    v("mechanics/external_work", st.external_work);
    v("mechanics/damping_work", st.damping_work);
    v("mechanics/empty_node_mass", st.empty_node_mass);
    v("mechanics/work_first", st.work_first);
    v("mechanics/work_second", st.work_second);
    v("mechanics/contact_stats", st.stats);
    std::vector<long> owned;  // this rank's owned nodes (DMDA indices, [begin, end) per axis): redistribution
    if constexpr (!V::reading) for (int b : mpm_->owned_nodes()) owned.push_back(b);
    v("mechanics/owned_nodes", owned);
    if constexpr (V::reading) restored_ = std::move(st);
    if (heat_) heat_->visit_state(v);
  }

  // The same on every rank (rank 0 writes it): the run loop, the output so far, the hot spots.
  template <class V> void visit_global_state(const V& v) {
    v("run/time", time_);
    v("run/step", step_);
    v("run/last_dt", last_dt_);
    v("run/snapshots", snapshots_);
    v("run/last_series_step", last_series_step_);
    v("run/last_snapshot_step", last_snapshot_step_);
    v("output/series_rows", series_rows_);
    v("output/series_columns", series_columns_);
    v("output/xdmf_grids", xdmf_grids_);
    if (hot_) hot_->visit_state(v);
  }

  // Collective: a checkpoint of `old` ranks: rank r takes the particles of the files j ≡ r (mod K),
  // which then migrate to their owners, and the heat of its owned nodes from the files owning them.
  void redistribute(int old) {
    detail::Redistribution<Dim> re(*mpm_, heat_ != nullptr);
    try {
      generation_ = detail::read_redistributed_checkpoint(
          comm_, o_.resume_checkpoint, Dim,
          [&](const ckpt::Reader& r, int j) {
            re.take(r, j, j % size_ == rank_);
            if (heat_ && j == 0) heat_->visit_state(r);  // books and window: the same in every file
          },
          [&](const ckpt::Reader& r) { visit_global_state(r); });
    } catch (const std::exception& e) {
      throw OutputError(e.what());
    }
    re.finish(heat_.get());
    redistributed_from_ = old;
  }

  // Rank 0, resuming: the checkpoint's series and /hotspots rows into the new OUT.h5.
  void rewrite_rows() {
    const auto c = static_cast<std::size_t>(series_columns_);
    for (std::size_t a = 0; c > 0 && a + c <= series_rows_.size(); a += c)
      out_->append_series(std::vector<double>(series_rows_.begin() + static_cast<long>(a),
                                              series_rows_.begin() + static_cast<long>(a + c)));
    if (hot_) hot_->rewrite_table_rows(*out_);
    out_->write_metadata("resumed_at_step", step_);
  }
};

}  // namespace

std::vector<std::string> decomposed_output_files(const std::string& out, int ranks) {
  std::vector<std::string> files{out, xdmf_path_for(out)};
  for (int r = 0; r < ranks; ++r) files.push_back(DecomposedOutput::rank_file(output_base(out), r));
  return files;
}

RunResult run_scene_decomposed(MPI_Comm comm, const Scene& scene, const RunOptions& options) {
  if (scene.dimension == 2) return DecomposedRun<2>(comm, scene, options).execute();
  return DecomposedRun<3>(comm, scene, options).execute();
}

}  // namespace frictherm::coupling
