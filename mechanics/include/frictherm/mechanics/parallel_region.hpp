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

namespace frictherm::mechanics {

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
