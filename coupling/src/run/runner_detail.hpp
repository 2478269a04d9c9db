#pragma once
// Private helpers of the run loop: what goes into the HDF5 file, and the progress line.
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/runner.hpp>

#include <chrono>
#include <ostream>
#include <string>
#include <vector>

namespace frictherm::coupling::detail {

/// Series columns: time, step, dt, kinetic_energy, strain_energy, total_energy, external_work,
/// momentum_x, momentum_y (, momentum_z).
std::vector<std::string> series_names(int dim);
/// With contact: cumulative frictional work (total and per listed pair, both orders), contact and
/// sliding node counts, each body's mean velocity and the contact heat rate (total and per pair).
template <int Dim>
void append_contact_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim);

/// Every run: each body's mass-weighted mean temperature and mean displacement,
/// mean_temperature.<body>, mean_displacement_x.<body>, _y (, _z).
template <int Dim>
void append_body_series_names(std::vector<std::string>& names, const mechanics::Simulation<Dim>& sim);

/// What the rate columns remember from the previous series row.
struct SeriesMemory {
  double time = 0.0;
  bool has_previous = false;
  std::vector<double> work;  // cumulative frictional work: total, then per contact pair
};

/// One series row in the order of series_names + append_body_series_names +
/// append_contact_series_names. contact_heat_rate(.pair) columns use the frictional work of `order`
/// (the one handed to the thermal solver) and `memory` (updated here).
template <int Dim>
std::vector<double> series_row(const mechanics::Simulation<Dim>& sim, SeriesMemory& memory,
                               mechanics::HeatingOrder order);

/// Writes the named per-particle fields of the current state into the open snapshot.
template <int Dim>
void write_fields(H5Output& out, const mechanics::Simulation<Dim>& sim, const std::vector<std::string>& fields);

/// Metadata known before the first step (scene text, version, command line, date, grid, ...).
template <int Dim>
void write_start_metadata(H5Output& out, const Scene& scene, const mechanics::Simulation<Dim>& sim,
                          const RunOptions& options);

/// "step N  t = ... s  (xx.x %)  NNNN steps/s  ETA mm:ss" on a terminal, redrawn about 4 times a second.
class ProgressLine {
 public:
  ProgressLine(std::ostream& out, bool enabled, double end_time);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;
  /// Cheap when nothing is drawn (one clock read).
  void update(long step, double time);
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

/// "mm:ss", or "h:mm:ss" past an hour.
std::string format_duration(double seconds);

}  // namespace frictherm::coupling::detail
