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

namespace {
// The block boundary nearest to particle index k (n, the end, counts as one).
std::size_t nearest_block(std::size_t k, std::size_t n) {
  const std::size_t b = PassSplit::kBlock;
  const std::size_t down = k / b * b;
  const std::size_t up = std::min(n, down + b);
  return k - down <= up - k ? down : up;
}
}  // namespace

void PassSplit::reset(const ThreadPartition& p) {
  threads = p.threads;
  particles = p.particles;
  begin = p.begin;
  for (std::size_t t = 1; t < static_cast<std::size_t>(threads); ++t)
    begin[t] = std::max(begin[t - 1], nearest_block(begin[t], particles));
  seconds.assign(static_cast<std::size_t>(threads), 0.0);
  cost.assign(static_cast<std::size_t>(threads), 0.0);
}

void PassSplit::rebalance(const std::vector<std::size_t>& material_begin, const std::vector<std::size_t>& material_end,
                          const std::vector<int>& field_of_material) {
  if (threads < 2) return;
  const std::size_t T = static_cast<std::size_t>(threads), nm = material_begin.size();
  // Particles with a field before index k (materials are stored in order, ThreadPartition::build).
  auto weight_at = [&](std::size_t k) {
    std::size_t w = 0;
    for (std::size_t m = 0; m < nm && material_begin[m] < k; ++m)
      if (field_of_material[m] >= 0) w += std::min(k, material_end[m]) - material_begin[m];
    return static_cast<double>(w);
  };
  // The first index with `w` particles with a field before it.
  auto index_at = [&](double w) {
    double before = 0.0;
    for (std::size_t m = 0; m < nm; ++m) {
      if (field_of_material[m] < 0) continue;
      const double count = static_cast<double>(material_end[m] - material_begin[m]);
      if (before + count >= w) return material_begin[m] + static_cast<std::size_t>(std::llround(std::max(0.0, w - before)));
      before += count;
    }
    return particles;
  };
  weight.resize(T + 1);
  for (std::size_t t = 0; t <= T; ++t) weight[t] = weight_at(begin[t]);
  // Seconds per particle with a field in each part, smoothed: a pass that a descheduled thread
  // stretched moves the boundaries a little, not all the way.
  constexpr double keep = 0.75;
  for (std::size_t t = 0; t < T; ++t) {
    const double w = weight[t + 1] - weight[t];
    if (!(w > 0.0) || !(seconds[t] > 0.0)) return;  // nothing measured to balance by
    const double c = seconds[t] / w;
    cost[t] = cost[t] > 0.0 ? keep * cost[t] + (1.0 - keep) * c : c;
  }
  // The cumulative cost over the weight coordinate, linear within each part; boundary t moves halfway
  // towards where it reaches t / T of the total.
  double total = 0.0;
  for (std::size_t t = 0; t < T; ++t) total += cost[t] * (weight[t + 1] - weight[t]);
  std::size_t part = 0;
  double reached = 0.0;  // the cost before part `part`
  for (std::size_t t = 1; t < T; ++t) {
    const double goal = total * static_cast<double>(t) / static_cast<double>(T);
    while (part + 1 < T && reached + cost[part] * (weight[part + 1] - weight[part]) < goal)
      reached += cost[part] * (weight[part + 1] - weight[part]), ++part;
    const double target = weight[part] + (goal - reached) / cost[part];
    const std::size_t k = index_at(0.5 * (weight[t] + target));
    begin[t] = std::max(begin[t - 1], std::min(particles, nearest_block(k, particles)));
  }
}

}  // namespace frictherm::mechanics
