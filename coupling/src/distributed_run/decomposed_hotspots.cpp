// Hot spots of a decomposed run (decomposed_hotspots.hpp).
#include "distributed_run/decomposed_hotspots.hpp"

#include <frictherm/coupling/distributed.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace frictherm::coupling::detail {

template <int Dim>
DecomposedHotSpots<Dim>::DecomposedHotSpots(const Scene& scene, const mechanics::DecomposedMpm<Dim>& mpm)
    : materials_(scene.thermal.coupler.materials),
      tracker_(Dim, scene.thermal.coupler.hotspots, scene.thermal.coupler.thickness),
      fates_(scene.thermal.coupler.fates),
      temperature_(mpm.particle_scalar_index("temperature")),
      reference_(mpm.particle_scalar_index("reference_temperature")),
      // hotspots.temperature "interface": judged by T_int,p (the serial Coupler::hotspot_temperature)
      criterion_(scene.thermal.coupler.hotspots_by_interface_temperature
                     ? mpm.particle_scalar_index("interface_temperature")
                     : -1),
      particle_count_(static_cast<std::size_t>(mpm.global_particles())) {
  if (scene.thermal.coupler.reaction.enabled) progress_ = mpm.particle_scalar_index("reaction_progress");
}

template <int Dim>
void DecomposedHotSpots<Dim>::update(const mechanics::DecomposedMpm<Dim>& mpm, double time) {
  const mechanics::DecomposedLocalParticles p = mpm.local_particle_data(true);
  const std::size_t n = p.mass.size();
  // The fields HotSpotTracker::candidates reads: x_p, l_p, V_p, m_p, material, T_p.
  local_.position.resize(n);
  local_.half_size.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    local_.position[k] = Eigen::Map<const mechanics::Vec<Dim>>(p.position.data() + Dim * k);
    local_.half_size[k] = Eigen::Map<const mechanics::Vec<Dim>>(p.half_size.data() + Dim * k);
  }
  local_.volume = p.volume;
  local_.mass = p.mass;
  local_.material.assign(p.material.begin(), p.material.end());
  local_.temperature = mpm.particle_scalar(temperature_);
  ids_ = p.id;
  const std::vector<double> criterion = criterion_ >= 0 ? mpm.particle_scalar(criterion_) : std::vector<double>{};
  update_hot_spots_across_ranks<Dim>(mpm.communicator(), tracker_, local_, ids_, mpm.particle_scalar(reference_),
                                     materials_, particle_count_, time, criterion_ >= 0 ? &criterion : nullptr);
  ++updates_;
}

template <int Dim>
void DecomposedHotSpots<Dim>::update_fates(const mechanics::DecomposedMpm<Dim>& mpm, double time,
                                           const std::vector<double>* interface_progress) {
  const mechanics::DecomposedLocalParticles p = mpm.local_particle_data();
  // The temperature a spot is judged by: T_int,p with hotspots.temperature "interface" (HotSpotFates::update).
  const std::vector<double> T = mpm.particle_scalar(criterion_ >= 0 ? criterion_ : temperature_),
                            T0 = mpm.particle_scalar(reference_);
  const std::vector<double> lambda = progress_ >= 0 ? mpm.particle_scalar(progress_) : std::vector<double>{};
  std::vector<long> local_of(particle_count_, -1);  // global id -> this rank's index
  for (std::size_t k = 0; k < p.id.size(); ++k) local_of[static_cast<std::size_t>(p.id[k])] = static_cast<long>(k);
  const std::vector<HotSpotFateRecord>& records = fates_.records();
  std::vector<double> v(3 * records.size());  // per spot: peak, progress, hot (maxima over ranks)
  for (std::size_t j = 0; j < records.size(); ++j) {
    HotSpotFateMeasure m;
    for (std::size_t id : records[j].particles) {
      const long k = id < particle_count_ ? local_of[id] : -1;
      if (k < 0) continue;
      const auto uk = static_cast<std::size_t>(k);
      double lam = progress_ >= 0 ? lambda[uk] : 0.0;  // λ_p, and λ_int,p when judged by T_int (HotSpotFates::update)
      if (criterion_ >= 0 && interface_progress && uk < interface_progress->size()) lam = std::max(lam, (*interface_progress)[uk]);
      m.add(T[uk], lam, tracker_.is_hot_against(T[uk], T0[uk]));
    }
    v[3 * j] = m.peak_temperature, v[3 * j + 1] = m.progress, v[3 * j + 2] = m.hot ? 1.0 : 0.0;
  }
  MPI_Allreduce(MPI_IN_PLACE, v.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_MAX, mpm.communicator());
  std::vector<HotSpotFateMeasure> measures(records.size());
  for (std::size_t j = 0; j < records.size(); ++j)
    measures[j].peak_temperature = v[3 * j], measures[j].progress = v[3 * j + 1], measures[j].hot = v[3 * j + 2] > 0.0;
  fates_.decide(measures, time);
}

template <int Dim>
std::vector<std::string> DecomposedHotSpots<Dim>::series_names() {
  return {"hotspot_count", "hottest_hotspot_temperature", "hottest_hotspot_size", "hottest_hotspot_diameter"};
}

template <int Dim>
void DecomposedHotSpots<Dim>::extend_series_row(std::vector<double>& row) const {
  const HotSpot* hot = tracker_.hottest();
  const double none = std::numeric_limits<double>::quiet_NaN();  // no hot spot: NaN, as the serial run
  row.insert(row.end(), {static_cast<double>(tracker_.hot_spots().size()), hot ? hot->peak_temperature : none,
                         hot ? hot->size : none, hot ? hot->equivalent_diameter : none});
}

template <int Dim>
void DecomposedHotSpots<Dim>::declare_table(H5Output& out) const {
  out.declare_table("hotspots", hotspot_table_columns(Dim));
}

template <int Dim>
void DecomposedHotSpots<Dim>::append_table_rows(H5Output& out, double time) {
  if (updates_ == updates_written_) return;
  updates_written_ = updates_;
  for (const HotSpot& h : tracker_.hot_spots()) {
    const std::vector<double> r = hotspot_table_row(h, time, Dim);
    out.append_table_row("hotspots", r);
    table_rows_.insert(table_rows_.end(), r.begin(), r.end());
  }
}

template <int Dim>
void DecomposedHotSpots<Dim>::rewrite_table_rows(H5Output& out) const {
  constexpr std::size_t columns = 11 + Dim;
  for (std::size_t a = 0; a + columns <= table_rows_.size(); a += columns)
    out.append_table_row("hotspots", std::vector<double>(table_rows_.begin() + static_cast<long>(a),
                                                          table_rows_.begin() + static_cast<long>(a + columns)));
}

template class DecomposedHotSpots<2>;
template class DecomposedHotSpots<3>;

}  // namespace frictherm::coupling::detail
