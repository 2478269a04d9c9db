#pragma once
// An OpenMP parallel region that a single thread runs without a team. libgomp ends every region, a
// team of one included, with a barrier whose last arrival wakes the waiters by a futex system call:
// one system call per region, about 17 per step of a 2D contact scene with heating, which on a
// paravirtualised machine cost ~6 % of a 656-particle step (perf, issue 35). With one thread the body
// is called directly, unless the caller runs in a team of two or more threads (a step inside the
// caller's own parallel region: there thread numbers and orphaned constructs would bind to the
// caller's team). Outside a region (or in a team of one) omp_get_thread_num() is 0 and
// omp_get_num_threads() 1, an orphaned `omp for` runs the whole range and an orphaned barrier returns
// at once, so the body does what it does on a team of one, in the same order. Reductions: the caller
// gives the body a local accumulator starting at the identity and combines it with its own
// afterwards, as OpenMP does with a reduction clause (see the callers). Include only in files
// compiled with OpenMP.
#include <omp.h>

#include <cstddef>

#include <frictherm/mechanics/thread_partition.hpp>

namespace frictherm::mechanics {

/// Grid slots per thread below which an element-wise loop over the nodes (p += f dt, v = p / m)
/// costs less on one thread than the wake of a sleeping team mate (OMP_WAIT_POLICY=passive: a futex
/// wake per region, 10-20 us on this paravirtualised machine, against ~1-3 ns per slot; issue 35).
/// The 1 mm twin's ~10^4 slots then run on one thread, a 3D PBX grid's ~10^5 on all.
inline constexpr std::size_t kSlotsPerThread = 16384;

/// Threads for an element-wise loop over `slots` grid slots: at most `available`, at least one.
/// Each slot is written from its own values only, so the count changes no result.
inline int threads_for_slots(std::size_t slots, int available) {
  const std::size_t wanted = slots / kSlotsPerThread;
  return wanted < 2 ? 1 : (wanted < static_cast<std::size_t>(available) ? static_cast<int>(wanted) : available);
}

/// Threads for a contact pass whose work is the particles reaching a contact node, `share` of
/// `particles` (the last step's reach_share): threads_for_particles of those only. On the 1 mm twin
/// ~10 % of the particles reach the interface, so the contact terms' scatter and the extents run on
/// one thread instead of leaving the other thread idle at the barrier (contact phase 130 us/step on
/// one thread, 230 on two; issue 35).
inline int threads_for_reach(double share, std::size_t particles, int available) {
  return threads_for_particles(static_cast<std::size_t>(share * static_cast<double>(particles)), available);
}

/// Whether a region of `threads` threads runs without a team: one thread, and the caller in no team
/// of two or more.
inline bool without_team(int threads) { return threads <= 1 && omp_get_num_threads() == 1; }

/// body() on `threads` threads (a parallel region), or called directly (without_team).
template <class Body>
inline void parallel_region(int threads, Body&& body) {
  if (without_team(threads)) {
    body();
    return;
  }
#pragma omp parallel num_threads(threads)
  body();
}

/// body(i) for i in [0, n) split statically over `threads` threads, or a plain loop (without_team).
template <class Body>
inline void parallel_for(int threads, std::size_t n, Body&& body) {
  if (without_team(threads)) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < n; ++i) body(i);
}

}  // namespace frictherm::mechanics
