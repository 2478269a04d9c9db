// Hot-spot detection (threshold + adjacency clustering with a cell list) and tracking by overlap.
#include <frictherm/coupling/hotspots.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <map>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace frictherm::coupling {

std::vector<std::string> hotspot_table_columns(int dim) {
  std::vector<std::string> c{"time", "id", "particle_count", "peak_temperature", "mean_temperature", "size",
                             "equivalent_diameter"};
  const char* axes[3] = {"centroid_x", "centroid_y", "centroid_z"};
  for (int d = 0; d < dim; ++d) c.emplace_back(axes[d]);
  for (const char* n : {"birth_time", "duration", "excess_energy", "material_mask"}) c.emplace_back(n);
  return c;
}

std::vector<double> hotspot_table_row(const HotSpot& h, double time, int dim) {
  std::vector<double> r{time, static_cast<double>(h.id), static_cast<double>(h.particle_count), h.peak_temperature,
                        h.mean_temperature, h.size, h.equivalent_diameter};
  for (int d = 0; d < dim; ++d) r.push_back(h.centroid[static_cast<std::size_t>(d)]);
  double mask = 0.0;
  for (int m : h.materials) mask += std::ldexp(1.0, m);
  r.insert(r.end(), {h.birth_time, h.duration, h.excess_energy, mask});
  return r;
}

namespace {

constexpr double kPi = 3.14159265358979323846;

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), std::size_t{0}); }
  std::size_t find(std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void unite(std::size_t a, std::size_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace

HotSpotTracker::HotSpotTracker(int dim, HotSpotOptions options, double thickness)
    : dim_(dim), opt_(options), thickness_(thickness) {
  if (dim != 2 && dim != 3) throw std::invalid_argument("HotSpotTracker: dim must be 2 or 3");
  if (!(opt_.link_factor > 0.0)) throw std::invalid_argument("HotSpotTracker: link_factor must be > 0");
  if (!(thickness > 0.0)) throw std::invalid_argument("HotSpotTracker: thickness must be > 0");
}

template <int Dim>
void HotSpotTracker::set_reference(const mechanics::Particles<Dim>& p) {
  reference_ = p.temperature;
}

template <int Dim>
void HotSpotTracker::update(const mechanics::Particles<Dim>& p, const std::vector<ThermalProperties>& materials,
                            double time, const std::vector<double>* criterion) {
  if (Dim != dim_) throw std::logic_error("HotSpotTracker: particles of another dimension");
  if (reference_.size() != p.size()) set_reference(p);
  double max_temperature = 0.0;
  std::vector<HotCandidate> hot = candidates(p, materials, max_temperature, nullptr, nullptr, criterion);
  update_from(std::move(hot), max_temperature, p.size(), time);
}

template <int Dim>
std::vector<HotCandidate> HotSpotTracker::candidates(const mechanics::Particles<Dim>& p,
                                                     const std::vector<ThermalProperties>& materials,
                                                     double& max_temperature,
                                                     const std::vector<std::int64_t>* ids,
                                                     const std::vector<double>* reference,
                                                     const std::vector<double>* criterion) const {
  if (Dim != dim_) throw std::logic_error("HotSpotTracker: particles of another dimension");
  if ((ids && ids->size() != p.size()) || (reference && reference->size() != p.size()) ||
      (criterion && criterion->size() != p.size()))
    throw std::invalid_argument("HotSpotTracker: one id and one reference temperature per particle");
  const std::vector<double>& T0_p = reference ? *reference : reference_;
  std::vector<HotCandidate> hot;
  // Plain pointers and local copies (this runs every window over every particle): the candidate
  // stores below may alias anything, so through the vectors and members every particle would reload
  // them. The maximum in a loop of its own: across the candidate loop's push_back (a call, after
  // which no SSE register survives) it would live on the stack, a store and a load per particle in
  // its dependency chain.
  const int* const material = p.material.data();
  const double* const level_T = criterion ? criterion->data() : p.temperature.data();
  const double* const T0_data = T0_p.data();
  const std::size_t n = p.size(), n_T0 = T0_p.size(), n_materials = materials.size();
  const ThermalProperties* const props = materials.data();
  const bool absolute = opt_.mode == HotSpotOptions::Mode::absolute;
  const double threshold = opt_.threshold;
  double T_max = -std::numeric_limits<double>::infinity();
  // The highest level (T or T − T0) as well: when none is above the threshold the candidate loop
  // finds nothing (the usual window), so it is not run. std::max leaves a NaN level out, as the
  // candidate test does.
  double level_max = -std::numeric_limits<double>::infinity();
  std::size_t k0 = 0;
#if defined(__SSE2__)
  // Every material conducts (the usual scene) and every particle has its reference: a particle counts
  // when its id is in range, and two particles go in one register (issue 35: the scalar loop took 17
  // instructions a particle every window). Out-of-range ones enter as −∞; each lane keeps
  // (x > max) ? x : max, as std::max(max, x), so a NaN level is left out as above; the lanes' maxima
  // are the same set's maximum.
  bool all_conduct = n_T0 >= n;
  for (std::size_t m = 0; m < n_materials; ++m) all_conduct = all_conduct && props[m].conducts;
  if (all_conduct) {
    const __m128d none = _mm_set1_pd(-std::numeric_limits<double>::infinity());
    const __m128i zero = _mm_setzero_si128(), count = _mm_set1_epi32(static_cast<int>(n_materials));
    __m128d t_max = none, l_max = none;
    // Every id in range (four at a time)? Then every particle counts and the maxima need no mask.
    const __m128i ones = _mm_set1_epi32(-1);
    __m128i out = zero;
    std::size_t k = 0;
    for (; k + 3 < n; k += 4) {  // id < 0, or not id < n_materials
      const __m128i id = _mm_loadu_si128(reinterpret_cast<const __m128i*>(material + k));
      out = _mm_or_si128(out, _mm_or_si128(_mm_cmplt_epi32(id, zero), _mm_andnot_si128(_mm_cmplt_epi32(id, count), ones)));
    }
    bool all_in = _mm_movemask_epi8(out) == 0;
    for (; k < n; ++k) all_in = all_in && material[k] >= 0 && static_cast<std::size_t>(material[k]) < n_materials;
    if (all_in) {
      for (; k0 + 1 < n; k0 += 2) {
        const __m128d T = _mm_loadu_pd(level_T + k0);
        t_max = _mm_max_pd(T, t_max);
        l_max = _mm_max_pd(absolute ? T : _mm_sub_pd(T, _mm_loadu_pd(T0_data + k0)), l_max);
      }
    }
    for (; k0 + 1 < n; k0 += 2) {  // some id out of range: masked
      const __m128i id = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(material + k0));
      const __m128i in32 = _mm_andnot_si128(_mm_cmplt_epi32(id, zero), _mm_cmplt_epi32(id, count));
      const __m128d in = _mm_castsi128_pd(_mm_unpacklo_epi32(in32, in32));
      const __m128d T = _mm_loadu_pd(level_T + k0);
      const __m128d level = absolute ? T : _mm_sub_pd(T, _mm_loadu_pd(T0_data + k0));
      t_max = _mm_max_pd(_mm_or_pd(_mm_and_pd(in, T), _mm_andnot_pd(in, none)), t_max);
      l_max = _mm_max_pd(_mm_or_pd(_mm_and_pd(in, level), _mm_andnot_pd(in, none)), l_max);
    }
    T_max = std::max(_mm_cvtsd_f64(t_max), _mm_cvtsd_f64(_mm_unpackhi_pd(t_max, t_max)));
    level_max = std::max(_mm_cvtsd_f64(l_max), _mm_cvtsd_f64(_mm_unpackhi_pd(l_max, l_max)));
  }
#endif
  for (std::size_t k = k0; k < n; ++k) {
    const auto id = static_cast<std::size_t>(material[k]);
    if (!(id < n_materials && props[id].conducts)) continue;
    const double T = level_T[k];
    T_max = std::max(T_max, T);
    level_max = std::max(level_max, absolute ? T : T - (k < n_T0 ? T0_data[k] : 0.0));
  }
  max_temperature = T_max;
  if (!(level_max > threshold)) return hot;
  for (std::size_t k = 0; k < n; ++k) {
    const auto id = static_cast<std::size_t>(material[k]);
    if (id >= n_materials || !props[id].conducts) continue;
    const double T = level_T[k];
    const double T0 = k < n_T0 ? T0_data[k] : 0.0;
    const double level = absolute ? T : T - T0;
    if (!(level > threshold)) continue;
    HotCandidate c{};
    c.index = ids ? static_cast<std::size_t>((*ids)[k]) : k;
    for (int d = 0; d < Dim; ++d) c.x[static_cast<std::size_t>(d)] = p.position[k][d];
    c.spacing = 2.0 * p.half_size[k].maxCoeff();
    c.temperature = T;
    c.volume = p.volume[k];
    c.excess = p.mass[k] * materials[id].heat_capacity * (p.temperature[k] - T0);
    c.material = p.material[k];
    hot.push_back(c);
  }
  return hot;
}

void HotSpotTracker::update_from(std::vector<HotCandidate> hot, double max_temperature, std::size_t particle_count,
                                 double time) {
  max_temperature_ = std::isfinite(max_temperature) ? max_temperature : 0.0;
  if (owner_.size() != particle_count) owner_.assign(particle_count, -1);
  cluster_and_match(hot, time);
}

void HotSpotTracker::cluster_and_match(std::vector<HotCandidate>& hot, double time) {
  last_time_ = time;
  const std::size_t n = hot.size();
  UnionFind uf(n);
  if (n > 1) {
    // Cell list with cells of the largest link distance: linked pairs are in neighbouring cells.
    double cell = 0.0;
    for (const HotCandidate& c : hot) cell = std::max(cell, opt_.link_factor * c.spacing);
    std::array<double, 3> lo{};
    for (int d = 0; d < dim_; ++d) {
      lo[static_cast<std::size_t>(d)] = hot[0].x[static_cast<std::size_t>(d)];
      for (const HotCandidate& c : hot) lo[static_cast<std::size_t>(d)] = std::min(lo[static_cast<std::size_t>(d)], c.x[static_cast<std::size_t>(d)]);
    }
    std::vector<std::array<std::int64_t, 3>> coord(n);
    std::array<std::int64_t, 3> extent{1, 1, 1};
    for (std::size_t k = 0; k < n; ++k)
      for (int d = 0; d < dim_; ++d) {
        const auto dd = static_cast<std::size_t>(d);
        coord[k][dd] = static_cast<std::int64_t>(std::floor((hot[k].x[dd] - lo[dd]) / cell));
        extent[dd] = std::max(extent[dd], coord[k][dd] + 2);
      }
    auto key_of = [&](const std::array<std::int64_t, 3>& c) { return (c[2] * extent[1] + c[1]) * extent[0] + c[0]; };
    std::vector<std::pair<std::int64_t, std::size_t>> sorted(n);
    for (std::size_t k = 0; k < n; ++k) sorted[k] = {key_of(coord[k]), k};
    std::sort(sorted.begin(), sorted.end());
    const int reach_z = dim_ == 3 ? 1 : 0;
    for (std::size_t a = 0; a < n; ++a) {
      for (int dz = -reach_z; dz <= reach_z; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            std::array<std::int64_t, 3> c = {coord[a][0] + dx, coord[a][1] + dy, coord[a][2] + dz};
            if (c[0] < 0 || c[1] < 0 || c[2] < 0) continue;
            const std::int64_t key = key_of(c);
            auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, std::size_t{0}));
            for (; it != sorted.end() && it->first == key; ++it) {
              const std::size_t b = it->second;
              if (b <= a) continue;
              double d2 = 0.0;
              for (int d = 0; d < dim_; ++d) {
                const double e = hot[a].x[static_cast<std::size_t>(d)] - hot[b].x[static_cast<std::size_t>(d)];
                d2 += e * e;
              }
              const double link = opt_.link_factor * std::max(hot[a].spacing, hot[b].spacing);
              if (d2 <= link * link) uf.unite(a, b);
            }
          }
    }
  }

  // Clusters (roots in order of their smallest member) -> hot spots.
  std::map<std::size_t, std::vector<std::size_t>> groups;
  for (std::size_t k = 0; k < n; ++k) groups[uf.find(k)].push_back(k);
  std::vector<HotSpot> found;
  for (auto& [root, members] : groups) {
    (void)root;
    if (members.size() < opt_.min_particles) continue;
    HotSpot h;
    h.particle_count = members.size();
    double vol = 0.0, tv = 0.0;
    std::array<double, 3> xv{};
    h.peak_temperature = -std::numeric_limits<double>::infinity();
    for (std::size_t m : members) {
      const HotCandidate& c = hot[m];
      h.particles.push_back(c.index);
      h.peak_temperature = std::max(h.peak_temperature, c.temperature);
      vol += c.volume;
      tv += c.temperature * c.volume;
      for (int d = 0; d < dim_; ++d) xv[static_cast<std::size_t>(d)] += c.x[static_cast<std::size_t>(d)] * c.volume;
      h.excess_energy += c.excess;
      if (std::find(h.materials.begin(), h.materials.end(), c.material) == h.materials.end())
        h.materials.push_back(c.material);
    }
    std::sort(h.particles.begin(), h.particles.end());
    std::sort(h.materials.begin(), h.materials.end());
    h.mean_temperature = vol > 0.0 ? tv / vol : h.peak_temperature;
    for (int d = 0; d < dim_; ++d) h.centroid[static_cast<std::size_t>(d)] = vol > 0.0 ? xv[static_cast<std::size_t>(d)] / vol : 0.0;
    h.size = dim_ == 2 ? vol / thickness_ : vol;
    h.equivalent_diameter = dim_ == 2 ? 2.0 * std::sqrt(h.size / kPi) : std::cbrt(6.0 * h.size / kPi);
    found.push_back(std::move(h));
  }

  // Overlap with the previous hot spots: (overlap, new index, old id), largest overlaps first.
  std::map<long, const HotSpot*> previous;
  for (const HotSpot& h : current_) previous[h.id] = &h;
  std::vector<std::tuple<std::size_t, std::size_t, long>> pairs;
  for (std::size_t f = 0; f < found.size(); ++f) {
    std::map<long, std::size_t> overlap;
    for (std::size_t k : found[f].particles)
      if (k < owner_.size() && owner_[k] >= 0) ++overlap[owner_[k]];
    for (const auto& [id, count] : overlap) pairs.emplace_back(count, f, id);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    if (std::get<0>(a) != std::get<0>(b)) return std::get<0>(a) > std::get<0>(b);
    if (std::get<1>(a) != std::get<1>(b)) return std::get<1>(a) < std::get<1>(b);
    return std::get<2>(a) < std::get<2>(b);
  });
  std::vector<char> assigned(found.size(), 0);
  std::map<long, char> claimed;
  for (const auto& [count, f, id] : pairs) {
    (void)count;
    if (assigned[f] || claimed[id]) continue;
    assigned[f] = 1;
    claimed[id] = 1;
    found[f].id = id;
    found[f].birth_time = previous.at(id)->birth_time;
  }
  for (std::size_t f = 0; f < found.size(); ++f) {
    if (assigned[f]) continue;
    found[f].id = next_id_++;
    found[f].birth_time = time;
  }
  for (HotSpot& h : found) h.duration = time - h.birth_time;
  std::sort(found.begin(), found.end(), [](const HotSpot& a, const HotSpot& b) { return a.id < b.id; });

  for (const HotSpot& h : current_)
    for (std::size_t k : h.particles)
      if (k < owner_.size()) owner_[k] = -1;
  for (const HotSpot& h : found)
    for (std::size_t k : h.particles)
      if (k < owner_.size()) owner_[k] = h.id;
  current_ = std::move(found);
}

// Checkpoint layout of one hot spot: id, particle_count, peak, mean, size, diameter, centroid (3),
// excess_energy, birth_time, duration, 0 (kScalars = 13).
void HotSpotTracker::flatten(std::vector<double>& scalars, std::vector<long>& particles, std::vector<long>& particle_end,
                             std::vector<long>& materials, std::vector<long>& material_end) const {
  for (const HotSpot& h : current_) {
    scalars.insert(scalars.end(), {static_cast<double>(h.id), static_cast<double>(h.particle_count), h.peak_temperature,
                                   h.mean_temperature, h.size, h.equivalent_diameter, h.centroid[0], h.centroid[1],
                                   h.centroid[2], h.excess_energy, h.birth_time, h.duration, 0.0});
    particles.insert(particles.end(), h.particles.begin(), h.particles.end());
    particle_end.push_back(static_cast<long>(particles.size()));
    materials.insert(materials.end(), h.materials.begin(), h.materials.end());
    material_end.push_back(static_cast<long>(materials.size()));
  }
}

void HotSpotTracker::unflatten(const std::vector<double>& scalars, const std::vector<long>& particles,
                               const std::vector<long>& particle_end, const std::vector<long>& materials,
                               const std::vector<long>& material_end) {
  const std::size_t n = particle_end.size();
  if (scalars.size() != n * kScalars || material_end.size() != n ||
      (n > 0 && (static_cast<std::size_t>(particle_end.back()) != particles.size() ||
                 static_cast<std::size_t>(material_end.back()) != materials.size())))
    throw std::runtime_error("checkpoint: the hot-spot arrays /hotspots/current_scalars (13 per hot spot), "
                             "/hotspots/current_particles, /hotspots/current_particle_end, /hotspots/current_materials "
                             "and /hotspots/current_material_end do not fit together; the checkpoint is damaged");
  current_.assign(n, HotSpot{});
  long p0 = 0, m0 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double* s = &scalars[i * kScalars];
    HotSpot& h = current_[i];
    h.id = static_cast<long>(s[0]);
    h.particle_count = static_cast<std::size_t>(s[1]);
    h.peak_temperature = s[2];
    h.mean_temperature = s[3];
    h.size = s[4];
    h.equivalent_diameter = s[5];
    h.centroid = {s[6], s[7], s[8]};
    h.excess_energy = s[9];
    h.birth_time = s[10];
    h.duration = s[11];
    if (particle_end[i] < p0 || material_end[i] < m0)
      throw std::runtime_error("checkpoint: the offsets /hotspots/current_particle_end or /hotspots/current_material_end "
                               "decrease; the checkpoint is damaged");
    h.particles.assign(particles.begin() + p0, particles.begin() + particle_end[i]);
    h.materials.assign(materials.begin() + m0, materials.begin() + material_end[i]);
    p0 = particle_end[i];
    m0 = material_end[i];
  }
}

const HotSpot* HotSpotTracker::hottest() const {
  const HotSpot* best = nullptr;
  for (const HotSpot& h : current_)
    if (!best || h.peak_temperature > best->peak_temperature) best = &h;
  return best;
}

template void HotSpotTracker::set_reference<2>(const mechanics::Particles<2>&);
template void HotSpotTracker::set_reference<3>(const mechanics::Particles<3>&);
template std::vector<HotCandidate> HotSpotTracker::candidates<2>(const mechanics::Particles<2>&,
                                                                  const std::vector<ThermalProperties>&, double&,
                                                                  const std::vector<std::int64_t>*,
                                                                  const std::vector<double>*,
                                                                  const std::vector<double>*) const;
template std::vector<HotCandidate> HotSpotTracker::candidates<3>(const mechanics::Particles<3>&,
                                                                  const std::vector<ThermalProperties>&, double&,
                                                                  const std::vector<std::int64_t>*,
                                                                  const std::vector<double>*,
                                                                  const std::vector<double>*) const;
template void HotSpotTracker::update<2>(const mechanics::Particles<2>&, const std::vector<ThermalProperties>&, double,
                                        const std::vector<double>*);
template void HotSpotTracker::update<3>(const mechanics::Particles<3>&, const std::vector<ThermalProperties>&, double,
                                        const std::vector<double>*);

}  // namespace frictherm::coupling
