#pragma once
// Internal to thermal_assembly.cpp: the conductance matrix K in CSR from the assembly's per-row sums,
// with its rows shared between threads, and the thread ranges of the assembly's passes and of the
// explicit hand-off's split passes (scatter_by_split).
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/thread_partition.hpp>
#include <frictherm/thermal/problem.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace frictherm::coupling::assembly_detail {

/// One thread's share [lo, hi) of a range of nodes (or rows), by the calling thread's number.
struct NodeRange {
  int lo = 0, hi = 0;
  static NodeRange of_thread(int begin, int end) {
    const mechanics::EvenShare s(begin, end, omp_get_thread_num(), omp_get_num_threads());
    return {static_cast<int>(s.lo), static_cast<int>(s.hi)};
  }
  bool holds(int i) const { return i >= lo && i < hi; }
  /// The nodes [reach[0], reach[1]] overlap the range.
  template <class Reach>
  bool meets(const Reach& reach) const { return reach[1] >= lo && reach[0] < hi; }
};

/// Threads for a pass over the particles: as the mechanics step (its particle phases, docs/step.md).
inline int assembly_threads(std::size_t particles) {
  return mechanics::threads_for_particles(particles, omp_get_max_threads());
}

/// Threads for the explicit conduction hand-off's passes (gather, sub-steps, map back): one unless
/// at least kHandoffMinThreads are available. Their one-thread loops walk a whole stencil straight
/// from its first node and keep S_ip from the first walk for the second, where the shared loops
/// expand every stencil and walk the particle list once per thread's node range: on the 1 mm twin
/// (16,400 particles, 2 threads) the shared map back cost 5x the CPU of the one-thread one and the
/// whole hand-off 780 us/step of wall time against 480 on one thread (perf, issue 35). Both give the
/// same numbers (the same sums in particle order), so the count changes no result. The node-level
/// operator's assembly after a gather is the exception: it runs on assembly_threads with node ranges
/// cut by stencil counts (ExplicitConduction::split_nodes), which pays on 2 threads (handoff-s57).
inline constexpr int kHandoffMinThreads = 3;
inline int explicit_handoff_threads(std::size_t particles) {
  const int threads = assembly_threads(particles);
  return threads >= kHandoffMinThreads ? threads : 1;
}

// node_span's last − first: the same for every stencil of a kernel.
template <int Dim, int K>
inline int stencil_reach(const mechanics::NodeIndexer<Dim>& ix) {
  int reach = 0;
  for (int d = 0; d < Dim; ++d) reach += (K - 1) * ix.stride[d];
  return reach;
}

// As explicit_detail::scatter_by_node_ranges with the node ranges of `split` (thread t:
// [split[t], split[t + 1]), cut by stencil counts: ExplicitConduction::split_nodes) and each stencil's
// grid nodes known as [first[k], first[k] + reach] without reading it: body(k, range, inside, scratch)
// for the particles that meet the range, inside when all of its nodes are in it. On fewer threads than ranges (the
// governor's count now) each thread takes the ranges t, t + team, ... in turn: the same sums.
inline int split_team(int ranges) { return std::min(ranges, omp_get_max_threads()); }

template <class Scratch, class Body>
void scatter_by_split(const std::vector<int>& split, const int* first, int reach, const std::vector<std::size_t>& list,
                      Body&& body) {
  const int ranges = static_cast<int>(split.size()) - 1;
  mechanics::parallel_region(split_team(ranges), [&] {
    Scratch scratch{};
    const int team = omp_get_num_threads();
    for (int t = omp_get_thread_num(); t < ranges; t += team) {
      const NodeRange r{split[static_cast<std::size_t>(t)], split[static_cast<std::size_t>(t) + 1]};
      for (std::size_t k : list) {
        const int f = first[k];
        if (f >= r.hi || f + reach < r.lo) continue;
        body(k, r, f >= r.lo && f + reach < r.hi, scratch);
      }
    }
  });
}

/// K's sparsity pattern of the last assembly (per dimension and kernel, per calling thread): the
/// unknowns it was built for, its CSR arrays and the row slot of every stored entry (the diagonal at
/// the centre slot). A new assembly with the same unknowns and the same slots holding non-zero
/// products has the same pattern: only the values are written.
template <int Dim, class Kernel>
struct ConductancePattern {
  static constexpr int kw = 2 * Kernel::K - 1;
  static constexpr int slots = Dim == 2 ? kw * kw : kw * kw * kw;  // lattice offsets in [-(K-1), K-1]^Dim
  static constexpr int centre = (slots - 1) / 2;
  std::vector<int> grid_node;
  std::vector<int> outer, inner, slot;  // CSR: row starts (rows + 1), columns, slots
  std::vector<int> row_size;            // scratch of a fresh build

  static ConductancePattern& local() {
    thread_local ConductancePattern pattern;
    return pattern;
  }
  /// Row u's non-zero products `r` (its `slots` sums) fill exactly its stored slots.
  bool row_matches(std::size_t u, const double* r) const {
    int count = 0;
    for (int s = 0; s < slots; ++s) count += s != centre && r[s] != 0.0;
    if (count + 1 != outer[u + 1] - outer[u]) return false;
    for (int e = outer[u]; e < outer[u + 1]; ++e)
      if (slot[static_cast<std::size_t>(e)] != centre && r[slot[static_cast<std::size_t>(e)]] == 0.0) return false;
    return true;
  }
  /// Row u's columns and slots from its non-zero products, at outer[u]: ascending columns, the
  /// diagonal where its column falls. The slot order is the lattice order, in which unknown numbers
  /// increase (they follow the flat node index) unless an axis has fewer than kw nodes; then sorted.
  void fill_row(std::size_t u, const double* r, const std::vector<int>& unknowns, const std::vector<int>& unknown_of,
                const mechanics::IVec<Dim>& stride) {
    int col[slots], slot_at[slots];
    int count = 0;
    for (int s = 0; s < slots; ++s) {
      if (s == centre || r[s] == 0.0) continue;
      int rem = s, j = unknowns[u];
      for (int d = 0; d < Dim; ++d) {
        j += (rem % kw - (Kernel::K - 1)) * stride[d];
        rem /= kw;
      }
      col[count] = unknown_of[static_cast<std::size_t>(j)];
      slot_at[count++] = s;
    }
    for (int a = 1; a < count; ++a)
      for (int b = a; b > 0 && col[b - 1] > col[b]; --b) std::swap(col[b - 1], col[b]), std::swap(slot_at[b - 1], slot_at[b]);
    int e = outer[u];
    bool diagonal = false;
    for (int a = 0; a < count; ++a) {
      if (!diagonal && col[a] > static_cast<int>(u)) inner[e] = static_cast<int>(u), slot[e++] = centre, diagonal = true;
      inner[e] = col[a], slot[e++] = slot_at[a];
    }
    if (!diagonal) inner[e] = static_cast<int>(u), slot[e] = centre;
  }
};

/// K (n × n, CSR) from `rows`: row u's sums over the particles' products at each lattice offset
/// (rows[u·slots + s]). Off-diagonal entries are the non-zero sums; the diagonal is minus their sum in
/// slot order, so K·1 = 0 to the round-off of that sum (exact zero row sums make the conduction part
/// conserve Σ M_i T_i exactly). The pattern is reused when every row's non-zero slots are the stored
/// ones, else rebuilt. Rows are shared between `threads`; the numbers do not depend on their count.
template <int Dim, class Kernel>
void conductance_from_rows(const std::vector<double>& rows, const std::vector<int>& unknowns,
                           const std::vector<int>& unknown_of, const mechanics::IVec<Dim>& stride, int threads,
                           ConductancePattern<Dim, Kernel>& pattern, thermal::SparseMatrix& K) {
  using Pattern = ConductancePattern<Dim, Kernel>;
  constexpr int slots = Pattern::slots, centre = Pattern::centre;
  const int n = static_cast<int>(unknowns.size());
  const bool same_unknowns = pattern.grid_node == unknowns && pattern.outer.size() == unknowns.size() + 1;
  int rebuild = same_unknowns ? 0 : 1;
  const double* sums = rows.data();
  pattern.row_size.resize(static_cast<std::size_t>(n));  // (sized here: only read and written by row below)
  mechanics::parallel_region(threads, [&] {
    const NodeRange mine = NodeRange::of_thread(0, n);
    auto row_sums = [&](int u) { return sums + static_cast<std::size_t>(u) * slots; };
    if (same_unknowns) {
      bool same = true;
      for (int u = mine.lo; u < mine.hi && same; ++u) same = pattern.row_matches(static_cast<std::size_t>(u), row_sums(u));
      if (!same) {
#pragma omp atomic write
        rebuild = 1;
      }
    }
#pragma omp barrier
    int fresh = 0;
#pragma omp atomic read
    fresh = rebuild;
    if (fresh) {  // a new pattern: row sizes, their starts, then each row's columns and slots
      for (int u = mine.lo; u < mine.hi; ++u) {
        int count = 1;
        for (int s = 0; s < slots; ++s) count += s != centre && row_sums(u)[s] != 0.0;
        pattern.row_size[static_cast<std::size_t>(u)] = count;
      }
#pragma omp barrier
#pragma omp single
      {
        pattern.grid_node = unknowns;
        pattern.outer.resize(static_cast<std::size_t>(n) + 1);
        pattern.outer[0] = 0;
        for (int u = 0; u < n; ++u) pattern.outer[static_cast<std::size_t>(u) + 1] = pattern.outer[static_cast<std::size_t>(u)] + pattern.row_size[static_cast<std::size_t>(u)];
        pattern.inner.resize(static_cast<std::size_t>(pattern.outer.back()));
        pattern.slot.resize(static_cast<std::size_t>(pattern.outer.back()));
      }  // (implicit barrier)
      for (int u = mine.lo; u < mine.hi; ++u) pattern.fill_row(static_cast<std::size_t>(u), row_sums(u), unknowns, unknown_of, stride);
    }
#pragma omp single
    {
      K.resize(n, n);
      K.resizeNonZeros(pattern.outer.back());
      K.outerIndexPtr()[n] = pattern.outer.back();
    }  // (implicit barrier)
    int* outer = K.outerIndexPtr();
    int* inner = K.innerIndexPtr();
    double* value = K.valuePtr();
    for (int u = mine.lo; u < mine.hi; ++u) {
      const double* r = row_sums(u);
      double off_sum = 0.0;  // in slot order
      for (int s = 0; s < slots; ++s)
        if (s != centre && r[s] != 0.0) off_sum += r[s];
      outer[u] = pattern.outer[static_cast<std::size_t>(u)];
      for (int e = pattern.outer[static_cast<std::size_t>(u)]; e < pattern.outer[static_cast<std::size_t>(u) + 1]; ++e) {
        const int sl = pattern.slot[static_cast<std::size_t>(e)];
        inner[e] = pattern.inner[static_cast<std::size_t>(e)];
        value[e] = sl == centre ? -off_sum : r[sl];
      }
    }
  });
}

}  // namespace frictherm::coupling::assembly_detail
