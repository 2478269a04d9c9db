// The particle ranges of the threads and the fields they share (thread_partition.hpp).
#include <frictherm/mechanics/thread_partition.hpp>

#include <algorithm>
#include <cmath>

namespace frictherm::mechanics {

void ThreadPartition::build(int thread_count, const std::vector<std::size_t>& material_begin,
                            const std::vector<std::size_t>& material_end, const std::vector<int>& field_of_material,
                            std::size_t fields, std::size_t particle_count, double snap_fraction) {
  threads = std::max(1, thread_count);
  particles = particle_count;
  const std::size_t nm = material_begin.size();
  // Weighted position: only particles of materials with a field count (in material order).
  std::vector<std::size_t> weight_before(nm + 1, 0);
  for (std::size_t m = 0; m < nm; ++m)
    weight_before[m + 1] = weight_before[m] + (field_of_material[m] >= 0 ? material_end[m] - material_begin[m] : 0);
  const std::size_t total = weight_before[nm];
  const double share = static_cast<double>(total) / threads;
  begin.assign(static_cast<std::size_t>(threads) + 1, particle_count);
  begin[0] = 0;
  for (int t = 1; t < threads; ++t) {
    const std::size_t target = static_cast<std::size_t>(std::llround(share * t));
    // The material in which the target weight falls (the first whose cumulative weight reaches it).
    std::size_t m = 0;
    while (m < nm && weight_before[m + 1] < target) ++m;
    if (m == nm) {
      begin[static_cast<std::size_t>(t)] = particle_count;
      continue;
    }
    const std::size_t into = target - weight_before[m];
    std::size_t split = field_of_material[m] >= 0 ? material_begin[m] + into : material_end[m];
    // Snap to the nearer end of that material if it is close enough.
    const std::size_t to_begin = split - material_begin[m], to_end = material_end[m] - split;
    const double tolerance = snap_fraction * share;
    if (to_begin <= to_end && static_cast<double>(to_begin) <= tolerance) split = material_begin[m];
    else if (to_end < to_begin && static_cast<double>(to_end) <= tolerance) split = material_end[m];
    begin[static_cast<std::size_t>(t)] = std::max(split, begin[static_cast<std::size_t>(t) - 1]);
  }
  even_begin.resize(static_cast<std::size_t>(threads) + 1);
  for (int t = 0; t <= threads; ++t)
    even_begin[static_cast<std::size_t>(t)] = particle_count * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
  first_thread.assign(fields, 0);
  last_thread.assign(fields, 0);
  std::vector<char> seen(fields, 0);
  for (std::size_t m = 0; m < nm; ++m) {
    const int f = field_of_material[m];
    if (f < 0 || material_end[m] == material_begin[m]) continue;
    // Threads holding the first and the last particle of the material.
    auto thread_of = [&](std::size_t k) {
      return static_cast<int>(std::upper_bound(begin.begin(), begin.end(), k) - begin.begin()) - 1;
    };
    const int a = thread_of(material_begin[m]), b = thread_of(material_end[m] - 1);
    const std::size_t fu = static_cast<std::size_t>(f);
    if (!seen[fu]) first_thread[fu] = a, last_thread[fu] = b, seen[fu] = 1;
    else first_thread[fu] = std::min(first_thread[fu], a), last_thread[fu] = std::max(last_thread[fu], b);
  }
  shared_fields.clear();
  for (std::size_t f = 0; f < fields; ++f)
    if (first_thread[f] < last_thread[f]) shared_fields.push_back(static_cast<int>(f));
}

}  // namespace frictherm::mechanics
