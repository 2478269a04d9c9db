#pragma once
// Hot spots of a decomposed run (decomposed_hotspots.cpp): the serial run's tracker
// (hotspots.hpp) fed with every rank's particles (update_hot_spots_across_ranks, distributed.hpp) after
// every heat window, and its series columns and /hotspots rows written as the serial run writes them
// (runner_thermal.cpp).
#include <frictherm/coupling/h5_output.hpp>
#include <frictherm/coupling/hotspot_fates.hpp>
#include <frictherm/coupling/hotspots.hpp>
#include <frictherm/coupling/scene.hpp>
#include <frictherm/mechanics/distributed.hpp>

#include <mpi.h>

#include <string>
#include <vector>

namespace frictherm::coupling::detail {

template <int Dim>
class DecomposedHotSpots {
 public:
  /// The scene's coupling.hotspots settings; the particles carry the scalars `temperature` and
  /// `reference_temperature` (T0_p, K).
  DecomposedHotSpots(const Scene& scene, const mechanics::DecomposedMpm<Dim>& mpm);

  /// Collective: finds and matches the hot spots of all ranks at `time` (every rank holds the result).
  void update(const mechanics::DecomposedMpm<Dim>& mpm, double time);

  /// Series columns after the thermal ones: hotspot_count, hottest_hotspot_temperature, _size, _diameter.
  static std::vector<std::string> series_names();
  void extend_series_row(std::vector<double>& row) const;
  /// Rank 0: declares /hotspots (the serial columns) and appends the current hot spots once per update.
  void declare_table(H5Output& out) const;
  void append_table_rows(H5Output& out, double time);

  const HotSpotTracker& tracker() const { return tracker_; }

  /// The continuation's hot-spot fates (hotspot_fates.hpp): begin follows the hot spots of the last
  /// update from `time`; update_fates (collective) measures each followed spot on this rank's particles
  /// (T_p and T0_p from the swarm), reduces the measures over ranks (MPI_MAX) and lets the serial rules
  /// decide (HotSpotFates::decide), so every rank holds the same fates.
  void begin_fates(double time) { fates_.begin(tracker_, time); }
  /// `interface_progress`: λ_int,p of this rank's particles (swarm order) when the interface reaction
  /// runs, read with hot spots judged by the interface temperature (HotSpotFates::update).
  void update_fates(const mechanics::DecomposedMpm<Dim>& mpm, double time,
                    const std::vector<double>* interface_progress = nullptr);
  HotSpotFates& fates() { return fates_; }
  /// Checkpoints: the tracker's state (the same on every rank) and the update counters of /hotspots.
  template <class V> void visit_state(V&& v) {
    tracker_.visit_state(v);
    v("hotspots/updates", updates_);
    v("hotspots/updates_written", updates_written_);
    v("hotspots/table_rows", table_rows_);
  }
  /// Rank 0, resuming: the /hotspots rows written up to the checkpoint, appended again.
  void rewrite_table_rows(H5Output& out) const;
  long table_rows() const { return static_cast<long>(table_rows_.size() / (11 + Dim)); }

 private:
  std::vector<ThermalProperties> materials_;
  HotSpotTracker tracker_;
  HotSpotFates fates_;
  int temperature_ = 0, reference_ = 0, criterion_ = -1;  // criterion_: T_int,p's scalar (-1: T_p)
  int progress_ = -1;  // λ_p's scalar (-1: no reaction)
  std::size_t particle_count_ = 0;
  long updates_ = 0, updates_written_ = -1;
  mechanics::Particles<Dim> local_;  // scratch: this rank's particles as the tracker reads them
  std::vector<std::int64_t> ids_;
  std::vector<double> table_rows_;  // rank 0: every /hotspots row so far (11 + Dim columns), for checkpoints
};

}  // namespace frictherm::coupling::detail
