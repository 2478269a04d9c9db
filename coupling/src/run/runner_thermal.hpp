#pragma once
// The thermal side of a run (scenes with a `thermal` section): owns the Coupler and writes its
// series columns, the /hotspots table and the thermal metadata. The run loop (runner.cpp) calls it
// at a handful of places; without a `thermal` section it is never created.
#include "run/runner_detail.hpp"

#include <frictherm/coupling/coupler.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace frictherm::coupling::detail {

/// What the thermal /meta entries report: the coupler's settings, heating order, energy books and
/// integrator counts, the particles' reaction heat and energy change (J), the heat of a window left
/// open (J) and the hot-spot ids issued; a serial run's Coupler or a decomposed run's (sums over ranks).
struct ThermalMetadata {
  const CouplerOptions& options;
  HeatingOrder heating_order;
  EnergyBooks books;
  thermal::IntegratorStats stats;
  double particle_reaction_heat = 0.0;
  double pending_heat = 0.0;
  double particle_energy_change = 0.0;
  std::int64_t hotspots_seen = 0;
};
/// Integrator statistics, energy books and the heat's settings into /meta (thermal_*, heat_*, ...):
/// the serial run's and the decomposed run's entries, by this one writer.
void write_thermal_metadata(H5Output& out, const ThermalMetadata& metadata);

template <int Dim>
class ThermalRun {
 public:
  /// Starts the coupler on the initial state. Throws SceneError if no particle conducts heat.
  ThermalRun(const Scene& scene, mechanics::Simulation<Dim>& sim);

  /// Appends the thermal series columns to `names` and declares the /hotspots table.
  void declare_output(H5Output& out, std::vector<std::string>& names);
  /// Appends the thermal values to a series row; writes the hot spots to /hotspots when a window
  /// closed since the last row.
  void extend_series_row(std::vector<double>& row, H5Output& out, const mechanics::Simulation<Dim>& sim,
                         double time);
  /// After a mechanics step: hands its nodal work (J by grid node; empty for none) to the coupler
  /// and closes the window when `must_close` (a snapshot time or the end). Thermal failures become
  /// a mechanics::SimulationError so the run keeps its last good state.
  void after_step(mechanics::Simulation<Dim>& sim, const std::vector<double>& nodal_work, bool must_close);
  /// Thermal-only continuation after the mechanics (scene coupling.continuation): one series row per
  /// interval and a final snapshot at its end time.
  void continuation(H5Output& out, mechanics::Simulation<Dim>& sim, const std::vector<std::string>& fields,
                    SeriesMemory& memory);
  /// Particle fields of the thermal side into the open snapshot (reaction_progress with a reaction).
  void write_fields(H5Output& out) const;  // and write_nodes
  void write_nodes(H5Output& out) const;   // /nodes of the open snapshot
  /// Integrator statistics and energy books into /meta (thermal_*).
  void write_metadata(H5Output& out, const mechanics::Simulation<Dim>& sim) const;

  /// Checkpoints: the coupler's state (Coupler::visit_state) and which windows' hot spots are written.
  template <class V> void visit_state(V&& v, const mechanics::Simulation<Dim>& sim) {
    coupler_.visit_state(v, sim.particles());
    v("run/hotspot_windows_written", hotspot_windows_written_);
  }
  /// A thermal-only continuation follows the mechanics (coupling.continuation).
  bool has_continuation() const { return spec_.continuation_duration > 0.0; }

  HeatingOrder heating_order() const { return spec_.heating_order; }
  const Coupler<Dim>& coupler() const { return coupler_; }
  /// Wall time spent inside the thermal integrator so far (s).
  double solve_seconds() const { return coupler_.integrator_stats().wall_seconds; }

 private:
  template <class F>
  void guarded(const mechanics::Simulation<Dim>& sim, double time, F&& f);

  ThermalSceneSpec spec_;
  Coupler<Dim> coupler_;
  long hotspot_windows_written_ = -1;  // windows + intervals at the last /hotspots write
};

extern template class ThermalRun<2>;
extern template class ThermalRun<3>;

}  // namespace frictherm::coupling::detail
