#pragma once
// How a step's particle loops are shared among OpenMP threads (thread_partition.cpp).
//
// Particles are stored grouped by material, and with contact every material scatters into its own
// velocity field (a contiguous run of slots). Thread t takes the contiguous particles
// [begin[t], begin[t+1]), so most fields receive the particles of one thread only: that thread
// clears and scatters into the nodal arrays directly. Only a field whose particles fall in two or
// more threads' ranges (at most threads − 1 of them with contact; the one shared field without
// contact) goes through per-thread buffers, cleared and summed over its own slots. A PBX with 59
// materials on two threads then sums one field's slots per scatter instead of every field's.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace frictherm::mechanics {

/// Particles per thread below which a loop over particles costs more in fork/join and buffer sums
/// than the work it shares: the step, the coupler's assembly and the default thread count use it.
inline constexpr std::size_t kParticlesPerThread = 2000;

/// Threads for a loop over `particles`: at most `available`, at least one.
inline int threads_for_particles(std::size_t particles, int available) {
  return std::max(1, std::min(available, static_cast<int>(std::min<std::size_t>(particles / kParticlesPerThread, 1 << 20))));
}

/// Thread t's share [lo, hi) of [begin, end) split evenly among T threads (a loop over nodes or rows).
struct EvenShare {
  long lo = 0, hi = 0;
  EvenShare(long begin, long end, int t, int T) {
    const long span = std::max(0L, end - begin);
    lo = begin + span * t / T;
    hi = begin + span * (t + 1) / T;
  }
};

struct ThreadPartition {
  int threads = 0;
  std::vector<std::size_t> begin;   // threads + 1 entries; begin[0] = 0, begin[threads] = particle count
  std::vector<int> first_thread;    // per field: the lowest thread holding its particles (0 if none)
  std::vector<int> last_thread;     // per field: the highest
  std::vector<int> shared_fields;   // fields with first_thread < last_thread
  // An even split over every particle (rigid ones and those without a field too), for loops that
  // scatter nothing and visit every particle (the stencils): thread t takes [even_begin[t], even_begin[t+1]).
  std::vector<std::size_t> even_begin;
  std::size_t particles = 0;

  /// Balanced over the particles of materials that have a velocity field (field_of_material >= 0;
  /// the others are skipped by every loop). A boundary between threads that falls inside a material
  /// moves to the nearest material boundary when that changes the thread's share by at most
  /// `snap_fraction` of it (a split field costs a buffer clear and sum of its slots).
  void build(int threads, const std::vector<std::size_t>& material_begin, const std::vector<std::size_t>& material_end,
             const std::vector<int>& field_of_material, std::size_t fields, std::size_t particles,
             double snap_fraction = 0.02);
  bool matches(int t, std::size_t fields, std::size_t n) const {
    return threads == t && first_thread.size() == fields && particles == n;
  }
  /// Thread t's particles of a material whose particles are [b, e): [lo, hi), empty when lo >= hi.
  std::size_t lo(int t, std::size_t b) const { return b > begin[static_cast<std::size_t>(t)] ? b : begin[static_cast<std::size_t>(t)]; }
  std::size_t hi(int t, std::size_t e) const {
    const std::size_t x = begin[static_cast<std::size_t>(t) + 1];
    return e < x ? e : x;
  }
  /// The same for the even split.
  std::size_t even_lo(int t, std::size_t b) const {
    const std::size_t x = even_begin[static_cast<std::size_t>(t)];
    return b > x ? b : x;
  }
  std::size_t even_hi(int t, std::size_t e) const {
    const std::size_t x = even_begin[static_cast<std::size_t>(t) + 1];
    return e < x ? e : x;
  }
};

}  // namespace frictherm::mechanics
