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

/// The split of the particle passes (grid-to-particle and stress update: they gather from the nodes
/// and write only their own particles, so where the threads' shares meet does not change a single
/// particle's numbers). A particle's cost differs by material and state (a yielding HMX grain's J2
/// return, a binder particle without one), so an even count leaves one thread waiting for the other:
/// on the PBX the main thread waited 6.4 % of its samples at the pass's end. Each pass records the
/// seconds of every thread's share; `rebalance` moves each boundary halfway towards where the
/// measured costs (seconds per particle with a field, smoothed over passes) would be equal.
/// Boundaries sit on multiples of kBlock particles, and the pass sums its per-particle work in those
/// blocks, in block order: the sum does not depend on where the boundaries are, so a run gives the
/// same numbers whatever the timings (thread_partition.cpp).
struct PassSplit {
  static constexpr std::size_t kBlock = 128;
  int threads = 0;
  std::size_t particles = 0;
  std::vector<std::size_t> begin;  // threads + 1 entries, as ThreadPartition::begin
  std::vector<double> seconds;     // per part: the last pass's time (0: not measured)
  std::vector<double> cost;        // per part: smoothed seconds per particle with a field (0: none yet)
  std::vector<double> weight;      // scratch of rebalance: particles with a field before each boundary

  bool matches(int t, std::size_t n) const { return threads == t && particles == n; }
  /// Starts from the partition's boundaries, moved to the nearest block boundary.
  void reset(const ThreadPartition& p);
  /// Moves the boundaries after a pass that recorded `seconds` (weights as ThreadPartition::build).
  void rebalance(const std::vector<std::size_t>& material_begin, const std::vector<std::size_t>& material_end,
                 const std::vector<int>& field_of_material);
  std::size_t lo(int t, std::size_t b) const { return b > begin[static_cast<std::size_t>(t)] ? b : begin[static_cast<std::size_t>(t)]; }
  std::size_t hi(int t, std::size_t e) const {
    const std::size_t x = begin[static_cast<std::size_t>(t) + 1];
    return e < x ? e : x;
  }
  std::size_t blocks() const { return (particles + kBlock - 1) / kBlock; }
};

}  // namespace frictherm::mechanics
