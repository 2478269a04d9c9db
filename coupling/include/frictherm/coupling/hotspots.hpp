#pragma once
// Hot spots on particles (design §4, thermal-notes §3): particles above a temperature threshold,
// clustered by adjacency, followed from one update (coupling window) to the next.
//
// * Hot particle: T_p > threshold (mode absolute) or T_p − T0_p > threshold (mode rise, T0_p the
//   particle's temperature when set_reference was called). Only particles of conducting materials.
// * Adjacent: centres closer than link_factor × the larger particle spacing of the two (spacing
//   2 max_d l_p, l_p the particle half-widths; 1.5 links the diagonal neighbours of a lattice).
//   Found with a cell list (cells of the link distance) and a union-find: O(N_hot).
// * Identity: a cluster keeps the id of the previous hot spot it shares the most particles with;
//   when several clusters claim the same id, the one sharing most keeps it and the others get new
//   ids (a split); a merge keeps the id with the largest overlap (and its birth time). Birth time
//   is the update time a hot spot was first seen; duration is the time since then.
#include <frictherm/coupling/thermal_assembly.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

namespace frictherm::coupling {

struct HotSpotOptions {
  enum class Mode { absolute, rise };
  Mode mode = Mode::rise;
  double threshold = 100.0;       // K: temperature (absolute) or rise above T0_p (rise)
  double link_factor = 1.8;       // adjacency distance in particle spacings: > √3 (3D corner
                                  // diagonal), < 2 (a one-particle gap separates)
  std::size_t min_particles = 1;  // smaller clusters are ignored
};

struct HotSpot {
  long id = 0;
  std::size_t particle_count = 0;
  double peak_temperature = 0.0;     // K
  double mean_temperature = 0.0;     // K, volume-weighted
  double size = 0.0;                 // area (2D, m², volumes over the thickness) or volume (3D, m³)
  double equivalent_diameter = 0.0;  // m: 2 sqrt(A/π) in 2D, (6 V/π)^(1/3) in 3D
  std::array<double, 3> centroid{};  // volume-weighted (m)
  std::vector<int> materials;        // material ids present, ascending
  double excess_energy = 0.0;        // Σ_p m_p C_v,p (T_p − T0_p) (J)
  double birth_time = 0.0;           // s
  double duration = 0.0;             // s, time of the last update minus birth_time
  std::vector<std::size_t> particles;  // particle indices, ascending
};

/// The `/hotspots` table of a run's file, serial and decomposed alike: its columns for a `dim`-
/// dimensional run, and the row of hot spot `h` at `time` (material_mask: bit m set when material id m
/// is present, exact in a double up to id 52).
std::vector<std::string> hotspot_table_columns(int dim);
std::vector<double> hotspot_table_row(const HotSpot& h, double time, int dim);

/// One hot particle as the clustering sees it. `index` names the particle: its index in the run's
/// particles, or its global id in a decomposed run (distributed.hpp).
struct HotCandidate {
  std::size_t index;
  std::array<double, 3> x;
  double spacing, temperature, volume, excess;
  int material;
};

class HotSpotTracker {
 public:
  explicit HotSpotTracker(int dim = 2, HotSpotOptions options = {}, double thickness = 1.0);

  /// Records T0_p (the reference of mode rise and of excess_energy).
  template <int Dim>
  void set_reference(const mechanics::Particles<Dim>& particles);
  /// Finds the hot spots of the current state at `time` and matches them with the previous ones
  /// (candidates() then update_from()).
  template <int Dim>
  void update(const mechanics::Particles<Dim>& particles, const std::vector<ThermalProperties>& materials,
              double time, const std::vector<double>* criterion = nullptr);
  /// `criterion`, when given, is the temperature each particle is judged (and its peak reported) by
  /// instead of T_p: the sub-cell interface temperature (interface_temperature.hpp); the excess
  /// energy stays Σ m C_v (T_p − T0_p), the heat the particles hold.
  /// The hot particles of the current state, with `index` = ids[k] when ids are given (else k), and
  /// the highest temperature of the conducting particles (−∞ without any). T0_p from `reference`
  /// when given (a decomposed run carries it with the particles), else set_reference's.
  template <int Dim>
  std::vector<HotCandidate> candidates(const mechanics::Particles<Dim>& particles,
                                       const std::vector<ThermalProperties>& materials, double& max_temperature,
                                       const std::vector<std::int64_t>* ids = nullptr,
                                       const std::vector<double>* reference = nullptr,
                                       const std::vector<double>* criterion = nullptr) const;
  /// Clusters and matches candidates gathered from anywhere (every rank of a decomposed run: the same
  /// list in the same order on every rank gives the same hot spots and ids everywhere). Particle
  /// indices are below `particle_count`.
  void update_from(std::vector<HotCandidate> hot, double max_temperature, std::size_t particle_count, double time);

  const HotSpotOptions& options() const { return opt_; }
  /// Forgets the hot spots (keeping T0_p) and finds them again at `time` under the current options,
  /// with ids from 0: a checkpoint restored under another threshold (frictherm continue).
  template <int Dim>
  void redetect(const mechanics::Particles<Dim>& particles, const std::vector<ThermalProperties>& materials,
                double time) {
    current_.clear();
    owner_.clear();
    next_id_ = 0;
    update(particles, materials, time);
  }
  /// The hot spots of the last update, ascending id.
  const std::vector<HotSpot>& hot_spots() const { return current_; }
  /// The one with the highest peak temperature; nullptr if there is none.
  const HotSpot* hottest() const;
  /// Ids handed out so far (every hot spot ever seen).
  long ids_issued() const { return next_id_; }
  /// After a restore (visit_state): the checkpoint was written under other options.
  bool options_changed() const { return options_changed_; }
  /// Highest particle temperature at the last update (conducting materials; K).
  double max_temperature() const { return max_temperature_; }
  double last_time() const { return last_time_; }
  /// Whether particle k at `temperature` counts as hot (threshold and mode; the reference is the one of
  /// set_reference, none counting as 0 K).
  bool is_hot(std::size_t k, double temperature) const {
    return is_hot_against(temperature, k < reference_.size() ? reference_[k] : 0.0);
  }
  /// The same with the reference T0_p given (a decomposed run carries it with the particles).
  bool is_hot_against(double temperature, double reference) const {
    const double level = opt_.mode == HotSpotOptions::Mode::absolute ? temperature : temperature - reference;
    return level > opt_.threshold;
  }

  /// Checkpoints (state_visit.hpp): T0_p, the current hot spots (matched by the next update), the
  /// particle owners, the id counter and the last maximum and time.
  template <class V> void visit_state(V&& v) {
    v("hotspots/reference", reference_);
    v("hotspots/owner", owner_);
    v("hotspots/next_id", next_id_);
    v("hotspots/max_temperature", max_temperature_);
    v("hotspots/last_time", last_time_);
    double options[4] = {opt_.mode == HotSpotOptions::Mode::absolute ? 1.0 : 0.0, opt_.threshold, opt_.link_factor,
                         static_cast<double>(opt_.min_particles)};
    std::vector<double> written(options, options + 4);
    v("hotspots/options", written);  // reading: those of the run that wrote the checkpoint
    if constexpr (std::decay_t<V>::reading) options_changed_ = written != std::vector<double>(options, options + 4);
    // current_, flattened: scalars (kScalars per hot spot), then particles and materials with offsets.
    std::vector<double> scalars;
    std::vector<long> particles, particle_end, materials, material_end;
    if constexpr (!std::decay_t<V>::reading) flatten(scalars, particles, particle_end, materials, material_end);
    v("hotspots/current_scalars", scalars);
    v("hotspots/current_particles", particles);
    v("hotspots/current_particle_end", particle_end);
    v("hotspots/current_materials", materials);
    v("hotspots/current_material_end", material_end);
    if constexpr (std::decay_t<V>::reading) unflatten(scalars, particles, particle_end, materials, material_end);
  }

 private:
  static constexpr std::size_t kScalars = 13;
  void flatten(std::vector<double>& scalars, std::vector<long>& particles, std::vector<long>& particle_end,
               std::vector<long>& materials, std::vector<long>& material_end) const;
  /// Throws std::runtime_error when the arrays do not fit together.
  void unflatten(const std::vector<double>& scalars, const std::vector<long>& particles,
                 const std::vector<long>& particle_end, const std::vector<long>& materials,
                 const std::vector<long>& material_end);
  void cluster_and_match(std::vector<HotCandidate>& hot, double time);

  int dim_;
  HotSpotOptions opt_;
  double thickness_;
  std::vector<double> reference_;        // T0_p
  std::vector<HotSpot> current_;
  std::vector<long> owner_;              // particle -> id of its hot spot at the last update (-1)
  long next_id_ = 0;
  double max_temperature_ = 0.0;
  double last_time_ = 0.0;
  bool options_changed_ = false;
};

}  // namespace frictherm::coupling
