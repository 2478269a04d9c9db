#pragma once
// Private helpers of the run loop: what goes into the HDF5 file, when it is written, and the progress line.
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/runner.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling::detail {

/// Series columns: time, step, dt, kinetic_energy, strain_energy, total_energy, external_work,
/// momentum_x, momentum_y (, momentum_z), then the energy balance: rigid_work, damping_work,
/// plastic_dissipation, energy_lost, numerical_dissipation.
std::vector<std::string> series_names(int dim);
/// With contact: cumulative frictional work (total and per listed pair, both orders), contact and
/// sliding node counts, each body's mean velocity and the contact heat rate (total and per pair).
template <int Dim>
void append_contact_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim);
/// The same from the bodies' names, the materials and the scene's contact pairs (without the penalty
/// columns): the serial run's and the decomposed run's names.
void append_contact_series_names(std::vector<std::string>& names, const std::vector<std::string>& bodies,
                                 const std::vector<mechanics::Material>& materials,
                                 const std::vector<std::pair<int, int>>& pairs, int dim);

/// Penalty contact (docs/penalty_contact.md), serial and decomposed runs: penalty_energy (the springs'
/// energy), then per pair (master.slave) penalty_force, penalty_contacts, penalty_min_gap and
/// penalty_contact_length (the summed length of the penetrated master segments) of the last step.
void append_penalty_series_names(std::vector<std::string>& names, const std::vector<mechanics::PenaltyPairInfo>& pairs,
                                 const std::vector<mechanics::Material>& materials);
template <int Dim>
void append_penalty_row(std::vector<double>& row, const mechanics::PenaltyContact<Dim>& contact,
                        const mechanics::BoundaryPoints<Dim>& points);

/// Every run: each body's mass-weighted mean temperature and mean displacement,
/// mean_temperature.<body>, mean_displacement_x.<body>, _y (, _z).
template <int Dim>
void append_body_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim);
void append_body_series_names(std::vector<std::string>& names, const std::vector<std::string>& bodies, int dim);

/// What the rate columns remember from the previous series row.
struct SeriesMemory {
  double time = 0.0;
  bool has_previous = false;
  std::vector<double> work;  // cumulative frictional work: total, then per contact pair
};

/// The contact_heat_rate columns: the increase of the cumulative frictional work `work` (total, then
/// per contact pair; of the order handed to the thermal solver) since the previous series row over
/// the time between them, W. The rates times the row intervals add up to the frictional work exactly
/// (a telescoping sum); 0 in the first row. Updates `memory` (serial and decomposed runs).
void append_heat_rates(std::vector<double>& row, std::vector<double> work, double time, SeriesMemory& memory);

/// One series row in the order of series_names + append_body_series_names +
/// append_contact_series_names. contact_heat_rate(.pair) columns use the frictional work of `order`
/// (the one handed to the thermal solver) and `memory` (updated here).
template <int Dim>
std::vector<double> series_row(const mechanics::Simulation<Dim>& sim, SeriesMemory& memory,
                               mechanics::HeatingOrder order);

/// A failed run's record (serial and decomposed runs): the failing state under /failure, its fields
/// written by write_state into the open snapshot, and `message` as the metadata "failure". A state
/// that cannot be written is named in `message`; a message that cannot be written goes to
/// on_write_error (the run's end then says that the result is incomplete).
template <class WriteState, class OnWriteError>
void write_failure_record(H5Output& out, long step, double time, std::string& message, WriteState&& write_state,
                          OnWriteError&& on_write_error) {
  try {
    out.begin_failure(step, time, message);
    write_state();
    out.end_snapshot();
  } catch (const std::exception& e) {
    message += std::string(" (the failing state was not written: ") + e.what() + ")";
  }
  try {
    out.write_metadata("failure", message);
  } catch (const std::exception& e) {
    on_write_error(e.what());
  }
}

/// Writes the named per-particle fields of the current state into the open snapshot.
template <int Dim>
void write_fields(H5Output& out, const mechanics::Simulation<Dim>& sim, const std::vector<std::string>& fields);

/// What the start metadata says of the mechanics: the grid, the materials and bodies (by id), the
/// solver options (shape function, scheme, CFL factor) and the particle count; the serial Simulation's
/// or a decomposed run's (its grid, the scene's materials, bodies and options, the global count).
template <int Dim>
struct RunLayout {
  const mechanics::Grid<Dim>& grid;
  const std::vector<mechanics::Material>& materials;
  std::vector<std::string> body_names;
  const mechanics::SimulationOptions& options;
  std::size_t particles;
};

/// Metadata known before the first step (scene text, version, command line, date, grid, ...): the
/// serial run's and a decomposed run's (threads: OpenMP threads per process).
template <int Dim>
void write_start_metadata(H5Output& out, const Scene& scene, const RunLayout<Dim>& layout, const RunOptions& options);
template <int Dim>
void write_start_metadata(H5Output& out, const Scene& scene, const mechanics::Simulation<Dim>& sim,
                          const RunOptions& options);

/// Generated bodies (ellipse_packing): their images beside `output` (write_generated_images) and
/// /meta/microstructure_images listing them; a refused image path throws OutputError.
void write_microstructure_images(H5Output& out, const Scene& scene, const std::string& output);

/// "step N  t = ... s  (xx.x %)  NNNN steps/s  ETA mm:ss" on a terminal, redrawn about 4 times a second.
class ProgressLine {
 public:
  ProgressLine(std::ostream& out, bool enabled, double end_time);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  /// Cheap when nothing is drawn (one clock read).
  void update(long step, double time);
  /// Writes a line to log (erasing the progress line first when log is its stream).
  void message(std::ostream& log, const std::string& line);
  /// Erases the line (once).
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  std::ostream& out_;
  bool enabled_;
  double end_time_;
  Clock::time_point start_, last_draw_;
  long last_step_ = 0;
  std::size_t width_ = 0;  // characters drawn last time
};

/// When a run loop (runner.cpp, distributed_run/decomposed_runner.cpp) writes: a series row every
/// series_interval (every step when it is 0) and at end_time; a snapshot at every multiple of
/// snapshot_interval and at end_time, the times the loop lands its steps on (next_snapshot()).
/// Times within eps = 1e-10 end_time count as reached.
class OutputSchedule {
 public:
  /// From time t0: 0, or a resumed checkpoint's time (the next output times are the ones after it).
  OutputSchedule(double end_time, double snapshot_interval, double series_interval, double t0)
      : end_(end_time), eps_(1e-10 * end_time), snap_dt_(snapshot_interval), series_dt_(series_interval),
        snap_k_(static_cast<long>(std::floor(t0 / snap_dt_ + 1e-9)) + 1),
        next_snap_(std::min(static_cast<double>(snap_k_) * snap_dt_, end_)),
        next_series_(series_dt_ > 0.0 ? (std::floor(t0 / series_dt_ + 1e-9) + 1.0) * series_dt_ : 0.0) {}

  double eps() const { return eps_; }
  double next_snapshot() const { return next_snap_; }
  bool snapshot_reached(double t) const { return t >= next_snap_ - eps_; }

  /// Whether a series row is due at time t; if so the next series time moves past t.
  bool series_due(double t) {
    if (!(series_dt_ <= 0.0 || t >= next_series_ - eps_ || t >= end_ - eps_)) return false;
    if (series_dt_ > 0.0) next_series_ = (std::floor(t / series_dt_ + 1e-9) + 1.0) * series_dt_;
    return true;
  }
  /// Whether a snapshot is due at time t; if so the next snapshot time moves to the first multiple
  /// of snapshot_interval after t, in closed form (validation bounds end_time / snapshot_interval),
  /// or to end_time.
  bool snapshot_due(double t) {
    if (!snapshot_reached(t)) return false;
    snap_k_ = std::max(snap_k_ + 1, static_cast<long>(std::floor((t + eps_) / snap_dt_)) + 1);
    next_snap_ = std::min(static_cast<double>(snap_k_) * snap_dt_, end_);
    if (next_snap_ <= t + eps_ && next_snap_ < end_)
      next_snap_ = std::min(static_cast<double>(++snap_k_) * snap_dt_, end_);
    return true;
  }

 private:
  double end_, eps_, snap_dt_, series_dt_;
  long snap_k_;
  double next_snap_, next_series_;
};

/// 128 random bits in hex: a result's identity (RunOptions::run_id, /meta/run_id, every checkpoint's marks).
std::string fresh_run_id();

/// "mm:ss", or "h:mm:ss" past an hour.
std::string format_duration(double seconds);

}  // namespace frictherm::coupling::detail
