// The node-level conduction operator of the matrix-free sub-steps while the stencils are kept
// (explicit_conduction.hpp, use_node_operator; issue 35): K_ij = Σ_p V_p k_p G'_ip·G'_jp (Nairn et al.
// 2018 eq. 37 summed over the particles once), f_i = −Σ_{j≠i} K_ij (T_j − T_i).
#include "explicit_conduction_detail.hpp"

namespace frictherm::coupling {

using namespace explicit_detail;

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::assemble_node_operator(const NodalThermalSystem& sys, int threads) {
  const std::size_t n = sys.size();
  node_compact_ = false;  // the scatter below fills the full rows
  out_of_k_.clear();
  out_of_k_stencils_.clear();  // the walks kept for particles out of K (out_of_k_stencil)
  out_of_k_slot_.assign(holds_heat_.size(), -1);
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  listed_.clear();
  in_node_k_.assign(holds_heat_.size(), 0);
  for (std::size_t k = 0; k < holds_heat_.size(); ++k)
    if (holds_heat_[k] && conductance_[k] != 0.0) {
      listed_.push_back(k);
      in_node_k_[k] = 1;
    }
  node_force_.setZero(static_cast<Eigen::Index>(n));
  node_k_.resize(n * offsets);
  node_col_.resize(n * offsets);
  node_pos_.resize(n * offsets);
  row_start_.resize(n + 1);
  row_start_[0] = 0;
  // Rows [u0, u1): empty (K_ij = 0, j = i); then, after the scatter, each row's count of the slots a
  // particle joined (j ≠ i) at row_start_[u + 1]; then, from the row starts, the compacted rows: the
  // others add exactly 0 to f_i (T_i − T_i = 0, quiet), and the sum of the rest keeps the slot order,
  // so f_i keeps its bits.
  const auto clear_rows = [&](std::size_t u0, std::size_t u1) {
    std::fill(node_k_.begin() + static_cast<std::ptrdiff_t>(u0 * offsets),
              node_k_.begin() + static_cast<std::ptrdiff_t>(u1 * offsets), 0.0);
    for (std::size_t u = u0; u < u1; ++u)
      std::fill(node_col_.begin() + static_cast<std::ptrdiff_t>(u * offsets),
                node_col_.begin() + static_cast<std::ptrdiff_t>((u + 1) * offsets), static_cast<int>(u));
  };
  const auto count_rows = [&](std::size_t u0, std::size_t u1) {
    for (std::size_t u = u0; u < u1; ++u) {
      int joined = 0;
      for (std::size_t s = u * offsets; s < (u + 1) * offsets; ++s) joined += node_col_[s] != static_cast<int>(u);
      row_start_[u + 1] = joined;
    }
  };
  const auto compact_rows = [&](std::size_t u0, std::size_t u1) {
    for (std::size_t u = u0; u < u1; ++u) {
      int at = row_start_[u];
      for (std::size_t s = u * offsets; s < (u + 1) * offsets; ++s) {
        if (node_col_[s] == static_cast<int>(u)) {
          node_pos_[s] = -1;
          continue;
        }
        node_pos_[s] = at;
        node_kc_[static_cast<std::size_t>(at)] = node_k_[s];
        node_cc_[static_cast<std::size_t>(at++)] = node_col_[s];
      }
    }
  };
  const auto sum_starts = [&] {
    for (std::size_t u = 0; u < n; ++u) row_start_[u + 1] += row_start_[u];
    node_kc_.resize(static_cast<std::size_t>(row_start_[n]));
    node_cc_.resize(static_cast<std::size_t>(row_start_[n]));
  };
  // Each thread adds only into the rows of its grid nodes, over the particles in order: every K_ij
  // gets the same terms in the same order on any number of threads. The gather's node ranges when it
  // split them (first_node_ kept up to date by refresh; a range's unknowns are those of its grid
  // nodes, numbered in grid-node order), else one thread.
  if (split_.size() > 2) {
    const int ranges = static_cast<int>(split_.size()) - 1;
    const int reach = stencil_reach<Dim, Kernel::K>(indexer_);
    const auto unknowns_before = [&](int g) { return static_cast<std::size_t>(g - dropped_before_[static_cast<std::size_t>(g)]); };
    mechanics::parallel_region(split_team(ranges), [&] {
      Expanded e{};
      const int team = omp_get_num_threads();
      for (int t = omp_get_thread_num(); t < ranges; t += team) {
        const NodeRange r{split_[static_cast<std::size_t>(t)], split_[static_cast<std::size_t>(t) + 1]};
        const std::size_t u0 = unknowns_before(r.lo), u1 = unknowns_before(r.hi);
        clear_rows(u0, u1);
        for (std::size_t k : listed_) {
          const int f = first_node_[k];
          if (f >= r.hi || f + reach < r.lo) continue;
          add_to_node_operator(stencils[k], conductance_[k], sys.unknown, 1.0, e, &r);
        }
        count_rows(u0, u1);
      }
#pragma omp barrier
#pragma omp single
      sum_starts();  // (implicit barrier)
      for (int t = omp_get_thread_num(); t < ranges; t += team)
        compact_rows(unknowns_before(split_[static_cast<std::size_t>(t)]), unknowns_before(split_[static_cast<std::size_t>(t) + 1]));
    });
  } else {
    clear_rows(0, n);
    scatter_by_node_ranges<Expanded>(threads, static_cast<int>(sys.unknown.size()), listed_,
                                     [&](std::size_t k, const NodeRange& r, Expanded& e) {
                                       const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
                                       if (!r.meets(node_span(st, indexer_))) return;
                                       add_to_node_operator(st, conductance_[k], sys.unknown, 1.0, e, &r);
                                     });
    count_rows(0, n);  // the same three steps as the split path, on every row
    sum_starts();
    compact_rows(0, n);
  }
  node_compact_ = true;
  node_operator_ready_ = true;
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::split_nodes(int threads, int nodes) {
  // Cuts between rows of the slowest axis at the stencils' middle rows' quantiles: each range holds
  // ~as many stencils; only those across a cut (K − 1 rows of nodes) are walked by two threads.
  split_.clear();
  if (threads <= 1) return;
  const int row = indexer_.stride[Dim - 1];
  const int rows = nodes / row + Kernel::K;
  split_rows_.assign(static_cast<std::size_t>(rows), 0);
  std::size_t total = 0;
  for (std::size_t k = 0; k < first_node_.size(); ++k) {
    if (!holds_heat_[k]) continue;
    ++split_rows_[static_cast<std::size_t>(first_node_[k] / row + (Kernel::K - 1) / 2)];
    ++total;
  }
  split_.push_back(0);
  std::size_t below = 0;
  int r = 0;
  for (int t = 1; t < threads; ++t) {
    const std::size_t want = total * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
    while (r < rows && below + static_cast<std::size_t>(split_rows_[static_cast<std::size_t>(r)]) <= want)
      below += static_cast<std::size_t>(split_rows_[static_cast<std::size_t>(r++)]);
    split_.push_back(std::min(nodes, std::max(split_.back(), r * row)));
  }
  split_.push_back(nodes);
}

namespace {

// Σ_j K_ij (T_j − T_i) over the compacted slots [s, end) of row i in slot order, a pair at temperatures
// equal to round-off (kQuietSpread of T_i, as a quiet particle) carrying no flux. A function of its
// own (not the row lambda's captures) so the pointers stay in registers.
inline double row_flux(const double* t, double ti, const double* k_all, const int* col_all, int s, int end) {
  const double quiet = kQuietSpread * std::fabs(ti);
  double sum = 0.0;
#if defined(FRICTHERM_WHOLE_ROWS_SSE2)
  // Two slots at a time: T_j − T_i, the quiet test and K_ij (T_j − T_i) packed (each lane the scalar
  // loop's operations; a quiet pair's term is +0 as there), then added to the sum one by one in slot
  // order: the same bits.
  const __m128d tiv = _mm_set1_pd(ti), quietv = _mm_set1_pd(quiet);
  const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
  for (; s + 1 < end; s += 2) {
    const __m128d tj = _mm_set_pd(t[col_all[s + 1]], t[col_all[s]]);
    const __m128d d = _mm_sub_pd(tj, tiv);
    const __m128d still = _mm_cmple_pd(_mm_and_pd(d, abs_mask), quietv);  // |d| <= quiet (false for NaN)
    const __m128d term = _mm_andnot_pd(still, _mm_mul_pd(_mm_loadu_pd(k_all + s), d));
    sum += _mm_cvtsd_f64(term);
    sum += _mm_cvtsd_f64(_mm_unpackhi_pd(term, term));
  }
#endif
  for (; s < end; ++s) {  // the joined slots in order
    const double d = t[col_all[s]] - ti;
    // a pair at temperatures equal to round-off (relative to T_i) carries no flux
    sum += std::fabs(d) <= quiet ? 0.0 : k_all[s] * d;
  }
  return sum;
}

}  // namespace

template <int Dim>
void ExplicitConduction<Dim>::node_operator_force(const NodalThermalSystem& sys, const Eigen::VectorXd& T, int threads) {
  const auto n = static_cast<std::ptrdiff_t>(T.size());
  const double* t = T.data();
  const double* k_all = node_kc_.data();
  const int* col_all = node_cc_.data();
  const int* start = row_start_.data();
  const int* before = changed_before_.data();
  const int* grid_node = sys.grid_node.data();
  const int nodes = static_cast<int>(sys.unknown.size());
  const mechanics::IVec<Dim>& sd = indexer_.stride;  // sd[0] = 1: x fastest (for_each_unknown_whole)
  // Whether a node within ±2 along each axis changed, by grid node: first along x from the prefix
  // counts (changed_before_, a run of 5 clipped at the ends of the numbering; a run across a grid edge
  // takes in more: never fewer), then dilated by ±2 along each further axis (a centre outside the
  // numbering counts nothing: a real neighbour's centre is a grid node). A row reached recomputes
  // f_i from the same K row and T_j as it stands when none of its nodes changed, so a larger set
  // than needed changes no bit.
  const int pad = 2 * sd[Dim - 1];
  for (std::vector<unsigned char>& r : reach_) r.assign(static_cast<std::size_t>(nodes + 2 * pad), 0);
  unsigned char* x = reach_[0].data() + pad;
  // (the clipped ends apart, a loop without the clip: GCC vectorises it)
  const auto clipped = [&](int g) {
    const int lo = g < 2 ? 0 : g - 2, hi = g + 3 > nodes ? nodes : g + 3;
    x[g] = before[hi] != before[lo];
  };
  const int inner_end = std::max(2, nodes - 2);
  for (int g = 0; g < std::min(2, nodes); ++g) clipped(g);
  for (int g = 2; g < inner_end; ++g) x[g] = before[g + 3] != before[g - 2];
  for (int g = inner_end; g < nodes; ++g) clipped(g);
  for (int d = 1; d < Dim; ++d) {
    unsigned char* y = reach_[d % 2].data() + pad;
    const unsigned char* from = reach_[(d - 1) % 2].data() + pad;
    const int s1 = sd[d], s2 = 2 * sd[d];
    for (int g = 0; g < nodes; ++g) y[g] = from[g - s2] | from[g - s1] | from[g] | from[g + s1] | from[g + s2];
  }
  const unsigned char* reached = reach_[(Dim - 1) % 2].data() + pad;
  double* f = node_force_.data();
  const auto row = [&](std::ptrdiff_t u) {
    if (!reached[grid_node[u]]) return;  // f_i of the last sub-step stands: the same K row and T_j
    f[u] = -row_flux(t, t[u], k_all, col_all, start[u], start[u + 1]);  // f_i = −(K T)_i = −Σ_{j≠i} K_ij (T_j − T_i)
  };
  if (threads <= 1) {
    for (std::ptrdiff_t u = 0; u < n; ++u) row(u);
  } else {
    mechanics::parallel_region(threads, [&] {
#pragma omp for schedule(static)
      for (std::ptrdiff_t u = 0; u < n; ++u) row(u);
    });
  }
}

#define FRICTHERM_INSTANTIATE_NODE_OPERATOR(D)                                                                     \
  template void ExplicitConduction<D>::node_operator_force(const NodalThermalSystem&, const Eigen::VectorXd&, int); \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::LinearKernel>(const NodalThermalSystem&, int); \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::UGIMPKernel>(const NodalThermalSystem&, int);  \
  template void ExplicitConduction<D>::assemble_node_operator<mechanics::QuadraticBSplineKernel>(                  \
      const NodalThermalSystem&, int);                                                                            \
  template void ExplicitConduction<D>::split_nodes<mechanics::LinearKernel>(int, int);                             \
  template void ExplicitConduction<D>::split_nodes<mechanics::UGIMPKernel>(int, int);                              \
  template void ExplicitConduction<D>::split_nodes<mechanics::QuadraticBSplineKernel>(int, int);
FRICTHERM_INSTANTIATE_NODE_OPERATOR(2)
FRICTHERM_INSTANTIATE_NODE_OPERATOR(3)
#undef FRICTHERM_INSTANTIATE_NODE_OPERATOR

}  // namespace frictherm::coupling
