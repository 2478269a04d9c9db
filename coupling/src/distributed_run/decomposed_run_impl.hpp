#pragma once
// The decomposed run (decomposed_run.hpp) as one class, its members defined by job in
// decomposed_runner.cpp (the run loop: time stepping, the engine's step, the heat hand-off, the state
// check), decomposed_run_output.cpp (OUT.h5's series and metadata, the rank files' snapshots, the
// publication with OUT.xdmf), decomposed_run_failure.cpp (how a failure on some or all ranks ends the
// run) and decomposed_run_checkpoint.cpp (checkpoints, restore, redistribution). Each instantiates its
// members for 2D and 3D.
#include "distributed_run/decomposed_checkpoint.hpp"
#include "distributed_run/decomposed_failure.hpp"
#include "distributed_run/decomposed_hotspots.hpp"
#include "distributed_run/decomposed_redistribute.hpp"
#include "distributed_run/decomposed_setup.hpp"
#include "run/checkpoint_io.hpp"
#include "run/run_signals.hpp"
#include "run/particle_output.hpp"
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
#include <cstdlib>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <new>
#include <optional>

namespace frictherm::coupling::decomposed {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

inline std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// How long a rank that caught an exception waits for the others to catch it too (an error thrown on
// every rank alike arrives within the same collective call's return) before it ends them all.
constexpr double kFailureAgreementSeconds = 30.0;

// OUT.xdmf without its extension: the base of DecomposedOutput's files (OUT.rank<r>.h5, OUT.xdmf).
inline std::string output_base(const std::string& out) {
  const std::string x = xdmf_path_for(out);
  return x.substr(0, x.size() - 5);
}

template <int Dim>
class DecomposedRun {
 public:
  using Mpm = mechanics::DecomposedMpm<Dim>;
  DecomposedRun(MPI_Comm comm, const Scene& scene, const RunOptions& options);
  ~DecomposedRun();
  DecomposedRun(const DecomposedRun&) = delete;
  DecomposedRun& operator=(const DecomposedRun&) = delete;

  RunResult execute();

 private:
  bool overwrite() const { return o_.overwrite || s_.output.overwrite; }
  bool end_of_loading_checkpoint_exact() const;  // decomposed_runner.cpp

  bool show_progress() const {
    if (o_.quiet || o_.progress == RunOptions::Progress::never) return false;
    return o_.progress == RunOptions::Progress::always || isatty(STDERR_FILENO) != 0;
  }

  // Rank 0 checks every file of every rank as the serial run checks its output (docs/robustness.md):
  // never an input, an existing file only with --force / output.overwrite; all ranks agree.
  // Rank 0 also claims the output for the run (OutputClaim, as the serial run; issue 34).
  void check_output_files();

  void build();

  void open_output();

  void write_start_metadata();

  // The serial run's column names where the quantity is the same (runner_output.cpp, runner_thermal.cpp).
  std::vector<std::string> series_names() const;
  // The scene's body names and contact pairs (the serial Simulation's bodies() and contact_pairs()).
  std::vector<std::string> body_names() const;
  std::vector<std::pair<int, int>> contact_pairs() const;
  // Collective: each body's mass-weighted sums over all ranks' particles (p: this rank's, kinematics).
  detail::BodySums<Dim> body_sums(const mechanics::DecomposedLocalParticles& p) const;

  // Collective: one reduction for whether any rank caught SIGINT/SIGTERM and the lowest id of a
  // particle with a non-finite state or outside the grid (the serial step's check), which becomes a
  // SimulationError on every rank; then the engine's stable step, C min(h) / max_p (c_p + |v_p|) over
  // all ranks with c_p of each particle's state (Mie-Grüneisen: its current wave speed), as the serial
  // Simulation::stable_time_step.
  void stable_time_step(double& dt, int& signal, bool& checkpoint_due) const;

  // The serial loop (runner.cpp) with two reductions per step: after each mechanics step, the next
  // step's stable Δt, the interrupt flag and the state check (before the heat reads the particles).
  void loop(detail::ProgressLine& progress);

  // Collective: one row; rank 0 appends it. `time` (NaN: the run's) replaces the time column, the
  // mechanics columns staying at their last values (the continuation's rows, as the serial run's).
  void series(double time = std::numeric_limits<double>::quiet_NaN());
  // The serial snapshot's other particle fields (scene output.fields) into `snap`.
  void snapshot_fields(const mechanics::DecomposedLocalParticles& p, DecomposedSnapshot& snap) const;

  // Collective: the thermal-only continuation after the loading (coupling.continuation; the serial
  // ThermalRun::continuation): one interval of DecomposedHeat::continue_thermal, one hot-spot update and
  // one update of their fates per series row; then the fates and a snapshot at its end.
  void continuation();

  // Collective: the failing state under /failure of OUT.h5 as the serial run writes it (every
  // particle, gathered by id: position, velocity, material; a failed run's cost is not a concern),
  // and the message in /meta/failure. A failure to write that state is added to the message.
  void write_failure(long step, double time);

  // Collective: the run's failure, agreed by every rank: the state at it and the message.
  void fail(long step, double time, const std::string& message);

  // Rank 0: the first write into OUT.h5 that failed; the result then stays unpublished (finish_output).
  void note_write_error(const std::string& what);

  // `what` this rank caught, once every rank has caught it (an error thrown on every rank alike): the
  // lowest rank's message. Caught on this rank alone (the others wait in a collective call of the
  // step), it cannot be agreed: rank 0 publishes what it holds as failed, and every rank ends
  // (MPI_Abort) rather than waiting for ever (issue 34).
  std::string agreed(const std::string& what);

  // Collective: every rank writes its particles; rank 0 rewrites OUT.xdmf. `time` as series().
  void snapshot(double time = std::numeric_limits<double>::quiet_NaN());

  void record_phase_seconds();

  // Collective: rank 0 publishes the result (publish), every rank learns how that went. A write
  // that failed leaves the result unpublished under its temporary name (status running; exit code 1,
  // as the serial run); another file under the result's name meanwhile is a refusal (OutputError).
  void finish_output();

  // Rank 0: metadata and books, then OUT.h5.<pid>.part renamed onto OUT.h5. Returns "" when published,
  // else why not (a write failed: the result stays under its temporary name); throws when the
  // publication itself is refused.
  std::string publish();

  void write_end_metadata();

  MPI_Comm comm_;
  MPI_Comm failure_comm_ = MPI_COMM_NULL;  // the failure agreement's alone (decomposed_failure.hpp)
  double agreement_seconds_ = kFailureAgreementSeconds;
  int fault_rank_ = -1;  // FRICTHERM_FAULT_DECOMPOSED
  long fault_step_ = -1;
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
  std::string write_error_;               // rank 0: the first write into out_ that failed
  std::string run_id_;                    // rank 0: /meta/run_id and every checkpoint's marks
  std::unique_ptr<DecomposedOutput> snapshots_out_;
  int temperature_ = 0;
  double time_ = 0.0, last_dt_ = 0.0;
  long step_ = 0, snapshots_ = 0;
  long last_series_step_ = -1, last_snapshot_step_ = -1;
  double heating_seconds_ = 0.0, output_seconds_ = 0.0, continuation_seconds_ = 0.0;
  double loading_solve_seconds_ = 0.0;  // of heating_seconds_, inside the integrator (rank's wall time)
  double pending_heat_ = 0.0;  // work of a window left open (a stop at run.max_steps, an interruption), J
  double particle_reaction_heat_ = 0.0;  // q Σ m_p λ_p over ranks at the end (J)
  Clock::time_point last_flush_ = Clock::now();
  // Checkpoints: whether this run writes them, where, the generation of the last one, the clock of
  // --checkpoint-every; rank 0: every series row so far (flat) and OUT.xdmf's grids (from a resume).
  bool checkpoints_ = false, resuming_ = false;
  bool continuation_started_ = false;  // the thermal continuation after the loading has begun
  bool loading_complete_ = false;      // the loop reached the end time
  double wall_interval_ = 0.0;  // wall seconds between checkpoints (--checkpoint-every, or the decomposed default)
  std::string checkpoint_file_;
  long generation_ = 0, checkpoints_written_ = 0;
  double checkpoint_seconds_ = 0.0;
  Clock::time_point last_checkpoint_ = Clock::now();
  std::vector<double> series_rows_;
  long series_columns_ = 0;
  detail::SeriesMemory series_memory_;  // the previous series row, for the contact_heat_rate columns
  std::string xdmf_grids_, xdmf_reference_grids_, xdmf_node_grids_;
  typename Mpm::CheckpointState restored_;
  int redistributed_from_ = 0;  // ranks of a checkpoint resumed on another number of ranks

  // Collective: one checkpoint (decomposed_checkpoint.hpp), marks as the serial run's; `end_of_loading`
  // for the one before a continuation (CheckpointMarks::end_of_loading).
  void checkpoint(bool end_of_loading = false);
  // Collective: what a rank file must fit (decomposed_run_checkpoint.cpp).
  ckpt::RankSizes rank_sizes(bool ghosted) const;

  // Collective: the state of o_.resume_checkpoint (every rank's own file and the global one; of
  // another rank count: decomposed_redistribute.hpp).
  void restore();

  // This rank: its particles (every swarm field, in swarm order), the mechanics' books and the heat.
  template <class V> void visit_rank_state(const V& v);

  // The same on every rank (rank 0 writes it): the run loop, the output so far, the hot spots.
  template <class V> void visit_global_state(const V& v);

  // Collective: a checkpoint of `old` ranks: rank r takes the particles of the files j ≡ r (mod K),
  // which then migrate to their owners, and the heat of its owned nodes from the files owning them.
  void redistribute(int old);

  // Rank 0, resuming: the checkpoint's series and /hotspots rows into the new OUT.h5.
  void rewrite_rows();
};

}  // namespace frictherm::coupling::decomposed
