#pragma once
// What the two files of ExplicitConduction share (explicit_conduction.cpp: gather, bounds, refresh;
// explicit_conduction_passes.cpp: the sub-steps and the map back): the stencil walks, the scatter by
// node ranges, and the member templates both call (expand, count_changed, any_changed).
#include <frictherm/coupling/explicit_conduction.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include "conductance_rows.hpp"  // NodeRange, assembly_threads

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stdexcept>
#include <string>
#include <utility>

namespace frictherm::coupling {
namespace explicit_detail {

// The stencil's nodes in for_each's order with the same products (node index, S_ip and the
// components of G_ip as scalars: passing a Vec through memory stalled the passes on store
// forwarding). f(i, S, gx, gy, gz); gz = 0 in 2D.
template <int Dim, class Kernel, class F>
inline void for_each_node(const mechanics::Stencil<Dim, Kernel>& st, const mechanics::NodeIndexer<Dim>& ix, F&& f) {
  constexpr int K = Kernel::K;
  const mechanics::IVec<Dim>& sd = ix.stride;
  const mechanics::IVec<Dim> b = st.first_node();
  if constexpr (Dim == 2) {
    for (int j = 0; j < K; ++j) {
      const double wy = st.axis[1].w[j], dwy = st.axis[1].dw[j];
      const int row = ix.shift + (b[1] + j) * sd[1] + b[0] * sd[0];
      for (int i = 0; i < K; ++i) {
        const double wx = st.axis[0].w[i];
        f(row + i * sd[0], wx * wy, st.axis[0].dw[i] * wy, wx * dwy, 0.0);
      }
    }
  } else {
    for (int k = 0; k < K; ++k) {
      const double wz = st.axis[2].w[k], dwz = st.axis[2].dw[k];
      for (int j = 0; j < K; ++j) {
        const double wy = st.axis[1].w[j], dwy = st.axis[1].dw[j];
        const int row = ix.shift + (b[2] + k) * sd[2] + (b[1] + j) * sd[1] + b[0] * sd[0];
        for (int i = 0; i < K; ++i) {
          const double wx = st.axis[0].w[i], dwx = st.axis[0].dw[i];
          f(row + i * sd[0], wx * wy * wz, dwx * wy * wz, wx * dwy * wz, wx * wy * dwz);
        }
      }
    }
  }
}

// for_each_node over a whole stencil (every node an unknown) by unknown instead of grid node: the
// unknowns are numbered in grid-node order (select_unknowns) and a stencil row is a run of grid nodes
// (stride 1 along x), so a whole row's unknowns are un[first] + 0, 1, ..., K − 1: one index load per
// row instead of one per node (Grid numbers x fastest: stride 1). The same products in the same order. f(u, S, gx, gy, gz).
template <int Dim, class Kernel, class F>
inline void for_each_unknown_whole_from(const mechanics::Stencil<Dim, Kernel>& st, int first,
                                        const mechanics::NodeIndexer<Dim>& ix, const int* un, F&& f);

template <int Dim, class Kernel, class F>
inline void for_each_unknown_whole(const mechanics::Stencil<Dim, Kernel>& st, const mechanics::NodeIndexer<Dim>& ix,
                                   const int* un, F&& f) {
  const mechanics::IVec<Dim> b = st.first_node();
  int first = ix.shift;
  for (int d = Dim - 1; d >= 0; --d) first += b[d] * ix.stride[d];
  for_each_unknown_whole_from(st, first, ix, un, std::forward<F>(f));
}

// for_each_unknown_whole with the stencil's first grid node given (ExplicitConduction::first_node_,
// node_span's first): the same products in the same order.
template <int Dim, class Kernel, class F>
inline void for_each_unknown_whole_from(const mechanics::Stencil<Dim, Kernel>& st, int first,
                                        const mechanics::NodeIndexer<Dim>& ix, const int* un, F&& f) {
  constexpr int K = Kernel::K;
  const mechanics::IVec<Dim>& sd = ix.stride;
  if constexpr (Dim == 2) {
    for (int j = 0; j < K; ++j) {
      const double wy = st.axis[1].w[j], dwy = st.axis[1].dw[j];
      const int u0 = un[first + j * sd[1]];
      for (int i = 0; i < K; ++i) {
        const double wx = st.axis[0].w[i];
        f(u0 + i, wx * wy, st.axis[0].dw[i] * wy, wx * dwy, 0.0);
      }
    }
  } else {
    for (int k = 0; k < K; ++k) {
      const double wz = st.axis[2].w[k], dwz = st.axis[2].dw[k];
      for (int j = 0; j < K; ++j) {
        const double wy = st.axis[1].w[j], dwy = st.axis[1].dw[j];
        const int u0 = un[first + k * sd[2] + j * sd[1]];
        for (int i = 0; i < K; ++i) {
          const double wx = st.axis[0].w[i], dwx = st.axis[0].dw[i];
          f(u0 + i, wx * wy * wz, dwx * wy * wz, wx * dwy * wz, wx * wy * dwz);
        }
      }
    }
  }
}

// Packed forms of for_each_unknown_whole_from's loops (issue 35): a whole stencil's row is K
// consecutive unknowns, so two of its nodes go in one SSE2 register. Each product is the same
// correctly rounded operation as in the scalar loop (S = wx wy, in 3D (wx wy) wz, then S v), and the
// sums still take their terms one by one in node order, so the same bits. Not with FMA (a native
// build may contract the scalar loop's a b + c, the packed one not): there the scalar loops stay.
#if defined(__SSE2__) && !defined(__FMA__)
#define FRICTHERM_WHOLE_ROWS_SSE2 1
// A whole stencil's rows: each row's first unknown and its S_ip (nodes 0, 1 packed; node 2 if K = 3).
template <int Dim, int K>
struct WholeRows {
  static constexpr int rows = Dim == 2 ? K : K * K;
  int u0[rows];
  __m128d s01[rows];
  double s2[rows];
};

// Σ S_ip v_i over a whole stencil from its first grid node, in node order (as for_each_unknown_whole_from
// with f = sum += S v[u]); the rows' unknowns and S_ip into r for the scatter (add_whole_rows).
template <int Dim, class Kernel>
inline double dot_whole_rows(const mechanics::Stencil<Dim, Kernel>& st, int first, const mechanics::NodeIndexer<Dim>& ix,
                             const int* un, const double* v, WholeRows<Dim, Kernel::K>& r) {
  constexpr int K = Kernel::K;
  static_assert(K == 2 || K == 3, "rows of 2 or 3 nodes");
  const mechanics::IVec<Dim>& sd = ix.stride;
  const __m128d wx01 = _mm_loadu_pd(st.axis[0].w);
  const double wx2 = st.axis[0].w[K - 1];
  double sum = 0.0;
  const auto row = [&](int at, int u0, __m128d s01, double s2) {
    r.u0[at] = u0;
    r.s01[at] = s01;
    r.s2[at] = s2;
    const __m128d p = _mm_mul_pd(s01, _mm_loadu_pd(v + u0));
    sum += _mm_cvtsd_f64(p);
    sum += _mm_cvtsd_f64(_mm_unpackhi_pd(p, p));
    if constexpr (K == 3) sum += s2 * v[u0 + 2];
  };
  if constexpr (Dim == 2) {
    for (int j = 0; j < K; ++j) {
      const double wy = st.axis[1].w[j];
      row(j, un[first + j * sd[1]], _mm_mul_pd(wx01, _mm_set1_pd(wy)), wx2 * wy);
    }
  } else {
    for (int k = 0; k < K; ++k) {
      const double wz = st.axis[2].w[k];
      for (int j = 0; j < K; ++j) {
        const double wy = st.axis[1].w[j];
        row(k * K + j, un[first + k * sd[2] + j * sd[1]],
            _mm_mul_pd(_mm_mul_pd(wx01, _mm_set1_pd(wy)), _mm_set1_pd(wz)), wx2 * wy * wz);
      }
    }
  }
  return sum;
}

// a_i += c S_ip over the rows of dot_whole_rows (each node's own sum: packed, the same bits).
template <int Dim, int K>
inline void add_whole_rows(const WholeRows<Dim, K>& r, double c, double* a) {
  const __m128d cv = _mm_set1_pd(c);
  for (int at = 0; at < WholeRows<Dim, K>::rows; ++at) {
    double* x = a + r.u0[at];
    _mm_storeu_pd(x, _mm_add_pd(_mm_loadu_pd(x), _mm_mul_pd(cv, r.s01[at])));
    if constexpr (K == 3) x[2] += c * r.s2[at];
  }
}

// A refresh's terms of one particle with a whole 2D stencil (refresh_with: M_i ∓ m C S_ip, the eq. 38
// sums ∓ m C T S_ip by unknown, quick_sum_ + quick |G_ip|₁ when it conducts), two nodes of a row at a
// time: each array's element gets the same operation as in for_each_node's loop, so the same bits.
template <class Kernel>
inline void refresh_terms_whole(const mechanics::Stencil<2, Kernel>& st, const mechanics::NodeIndexer<2>& ix,
                                const int* un, double mc, double mct, double quick, bool conducts, bool out,
                                double* grid_mass, double* sums, double* quick_sum) {
  constexpr int K = Kernel::K;
  const mechanics::IVec<2> b = st.first_node();
  const __m128d wx = _mm_loadu_pd(st.axis[0].w), dwx = _mm_loadu_pd(st.axis[0].dw);
  const double wx2 = st.axis[0].w[K - 1], dwx2 = st.axis[0].dw[K - 1];
  const __m128d mcv = _mm_set1_pd(mc), mctv = _mm_set1_pd(mct), qv = _mm_set1_pd(quick);
  const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
  for (int j = 0; j < K; ++j) {
    const double wy = st.axis[1].w[j], dwy = st.axis[1].dw[j];
    const int row = ix.shift + (b[1] + j) * ix.stride[1] + b[0] * ix.stride[0];  // stride[0] = 1
    const __m128d S = _mm_mul_pd(wx, _mm_set1_pd(wy));
    double* const gm = grid_mass + row;
    double* const sm = sums + un[row];
    const __m128d m = _mm_mul_pd(mcv, S), t = _mm_mul_pd(mctv, S);
    _mm_storeu_pd(gm, out ? _mm_sub_pd(_mm_loadu_pd(gm), m) : _mm_add_pd(_mm_loadu_pd(gm), m));
    _mm_storeu_pd(sm, out ? _mm_sub_pd(_mm_loadu_pd(sm), t) : _mm_add_pd(_mm_loadu_pd(sm), t));
    const double S2 = wx2 * wy;
    if constexpr (K == 3) {
      if (out) {
        gm[2] -= mc * S2;
        sm[2] -= mct * S2;
      } else {
        gm[2] += mc * S2;
        sm[2] += mct * S2;
      }
    }
    if (!conducts) continue;
    const __m128d gx = _mm_mul_pd(dwx, _mm_set1_pd(wy)), gy = _mm_mul_pd(wx, _mm_set1_pd(dwy));
    const __m128d l1 = _mm_add_pd(_mm_and_pd(gx, abs_mask), _mm_and_pd(gy, abs_mask));
    double* const qs = quick_sum + row;
    _mm_storeu_pd(qs, _mm_add_pd(_mm_loadu_pd(qs), _mm_mul_pd(qv, l1)));
    if constexpr (K == 3) qs[2] += quick * (std::fabs(dwx2 * wy) + std::fabs(wx2 * dwy));
  }
}
#endif

// |G_ip|₁ of for_each_node's components (gz = 0 in 2D): in 2D |gx| + |gy| alone, the same bits
// (the sum of two magnitudes is never −0, so adding |0| = +0 changes nothing).
template <int Dim>
inline double g_l1(double gx, double gy, double gz) {
  if constexpr (Dim == 2) return std::fabs(gx) + std::fabs(gy);
  else return std::fabs(gx) + std::fabs(gy) + std::fabs(gz);
}

// V_p k_p A_p, A_p = Σ_d (Σ_j |∂w_d,j|) Π_{e≠d} (Σ_j |w_e,j|) = Σ over the stencil of |G_ip|₁
// (quick_bound).
template <int Dim, class Kernel>
inline double quick_weight(const mechanics::Stencil<Dim, Kernel>& st, double conductance) {
  double sw[Dim], sdw[Dim];
  for (int d = 0; d < Dim; ++d) {
    sw[d] = 0.0;
    sdw[d] = 0.0;
    for (int j = 0; j < Kernel::K; ++j) {
      sw[d] += std::fabs(st.axis[d].w[j]);
      sdw[d] += std::fabs(st.axis[d].dw[j]);
    }
  }
  double a_p = 0.0;
  for (int d = 0; d < Dim; ++d) {
    double t = sdw[d];
    for (int e = 0; e < Dim; ++e)
      if (e != d) t *= sw[e];
    a_p += t;
  }
  return conductance * a_p;
}

// The lowest and highest grid node of a stencil (for_each_node's numbering).
template <int Dim, class Kernel>
inline std::array<int, 2> node_span(const mechanics::Stencil<Dim, Kernel>& st, const mechanics::NodeIndexer<Dim>& ix) {
  const mechanics::IVec<Dim> b = st.first_node();
  int first = ix.shift, reach = 0;
  for (int d = 0; d < Dim; ++d) {
    first += b[d] * ix.stride[d];
    reach += (Kernel::K - 1) * ix.stride[d];
  }
  return {first, first + reach};
}

using assembly_detail::NodeRange;

// body(k, range, scratch) for every particle k of `list` in order, on `threads` threads, each with
// its own range of grid nodes (all of them on one thread) and its own Scratch: a scatter adds only
// into the nodes (or the unknowns at the nodes) of its range, so each sum gets the same terms in the
// same order on any number of threads (as thermal_assembly.cpp's passes).
template <class Scratch, class Body>
void scatter_by_node_ranges(int threads, int nodes, const std::vector<std::size_t>& list, Body&& body) {
  if (threads <= 1) {
    const NodeRange all{0, nodes};
    Scratch scratch{};
    for (std::size_t k : list) body(k, all, scratch);
    return;
  }
  mechanics::parallel_region(threads, [&] {
    const NodeRange mine = NodeRange::of_thread(0, nodes);
    Scratch scratch{};
    for (std::size_t k : list) body(k, mine, scratch);
  });
}

using assembly_detail::scatter_by_split;
using assembly_detail::split_team;
using assembly_detail::stencil_reach;

// Relative spread of a particle's nodal temperatures below which they are taken as equal in the
// sub-steps: 256 ε, the order of the re-projection's own round-off (T_i = Σ m C T S / Σ m C S over
// ~10–30 terms). At 300 K it is 1.7e-11 K.
constexpr double kQuietSpread = 256.0 * 2.220446049250313e-16;

// Whether temperatures spanning [lo, hi] are equal in that sense.
inline bool quiet_spread(double lo, double hi) {
  return hi - lo <= kQuietSpread * std::max(std::fabs(lo), std::fabs(hi));
}

// Whether an expanded stencil's unknowns (ExplicitConduction::Expanded, at least one) have equal
// temperatures T (indexed by unknown).
template <class ExpandedStencil, class Temperatures>
bool quiet_temperatures(const ExpandedStencil& e, const Temperatures& T) {
  double lo = T[e.unknown[0]], hi = lo;
  for (int a = 1; a < e.count; ++a) {
    lo = std::min(lo, T[e.unknown[a]]);
    hi = std::max(hi, T[e.unknown[a]]);
  }
  return quiet_spread(lo, hi);
}

}  // namespace explicit_detail

template <int Dim>
template <class Kernel, bool WithG>
void ExplicitConduction<Dim>::expand(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown,
                                     Expanded& e) const {
  // The sums of the gather before issue 35 (keep()), in the same order: S over the unknowns, G over
  // the other nodes.
  double s_kept = 0.0;
  double g_dropped[Dim] = {};
  int n = 0, total = 0;
  explicit_detail::for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
    ++total;
    const int u = unknown[static_cast<std::size_t>(i)];
    if (u < 0) {
      if constexpr (WithG) {
        g_dropped[0] += gx;
        g_dropped[1] += gy;
        if constexpr (Dim == 3) g_dropped[2] += gz;
      }
      return;
    }
    s_kept += w;
    e.unknown[n] = u;
    e.S[n] = w;
    if constexpr (WithG) {
      e.G[0][n] = gx;
      e.G[1][n] = gy;
      if constexpr (Dim == 3) e.G[2][n] = gz;
    }
    ++n;
  });
  e.count = n;
  e.total = total;
  e.s_kept = s_kept;
  if constexpr (WithG)
    if (n < total && e.reaches())  // lump dropped nodes (as thermal_assembly builds K)
      for (int a = 0; a < n; ++a) {
        const double share = e.S[a] / s_kept;
        for (int d = 0; d < Dim; ++d) e.G[d][a] += share * g_dropped[d];
      }
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::add_to_node_operator(const mechanics::Stencil<Dim, Kernel>& st, double conductance,
                                                   const std::vector<int>& unknown, double sign, Expanded& e,
                                                   const void* range) {
  if (conductance == 0.0) return;  // no conduction (as the sub-steps' quiet particles)
  // One walk: each node's offset code Σ_d l_d 5^d (l_d: its place along axis d in the stencil), grid
  // node, unknown and G_ip; the slot of the pair (a, b) in row a is code_b − code_a + code of (2, 2).
  constexpr int K = Kernel::K;
  constexpr int centre = Dim == 2 ? 2 + 5 * 2 : 2 + 5 * 2 + 25 * 2;
  int code[capacity], node[capacity] = {}, un[capacity];  // node: {} against a false -Wmaybe-uninitialized
  double G[Dim][capacity];
  int total = 0, kept = 0;
  double s_kept = 0.0;  // as expand: Σ S_ip over the unknowns in node order
  explicit_detail::for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
    const int l0 = total % K, l1 = (total / K) % K, l2 = total / (K * K);
    code[total] = l0 + 5 * l1 + (Dim == 3 ? 25 * l2 : 0);
    node[total] = i;
    un[total] = unknown[static_cast<std::size_t>(i)];
    G[0][total] = gx;
    G[1][total] = gy;
    if constexpr (Dim == 3) G[2][total] = gz;
    if (un[total] >= 0) {
      s_kept += w;
      ++kept;
    }
    ++total;
  });
  const double* g[Dim];
  const int* u = un;
  int count = total;
  if (kept < total) {  // G' lumps the dropped nodes' G onto the kept ones: expand's numbers
    expand<Kernel, true>(st, unknown, e);
    if (!e.reaches()) return;  // no heat capacity of its own reaches an unknown
    int c = 0;
    for (int t = 0; t < total; ++t)
      if (un[t] >= 0) {
        code[c] = code[t];
        node[c] = node[t];
        ++c;
      }
    for (int d = 0; d < Dim; ++d) g[d] = e.G[d];
    u = e.unknown;
    count = e.count;
  } else {
    if (!(s_kept > 0.0)) return;
    for (int d = 0; d < Dim; ++d) g[d] = G[d];
  }
  const auto* r = static_cast<const assembly_detail::NodeRange*>(range);
  const bool mark = r == nullptr && flux_temperature_.size() == static_cast<Eigen::Index>(node_k_.size() / offsets);
  bool mine[capacity];
  for (int a = 0; a < count; ++a) {
    mine[a] = !r || r->holds(node[a]);
    // A refresh changes row a: its f_i is made anew in the next sub-step (NaN: "changed").
    if (mark) flux_temperature_[u[a]] = std::numeric_limits<double>::quiet_NaN();
  }
  // The pairs a < b of a whole 2D stencil with their slots known when compiled (code_b − code_a +
  // centre): f(row_a, a, b, slot, term), the term as the general loops below form it.
  const auto for_each_whole_pair = [&](auto&& f) {
    constexpr int n = mechanics::Stencil<Dim, Kernel>::node_count;
#pragma GCC unroll 9
    for (int a = 0; a < n; ++a) {
      const std::size_t row_a = static_cast<std::size_t>(u[a]) * offsets;
#pragma GCC unroll 9
      for (int b = a + 1; b < n; ++b) {
        const double term = sign * (conductance * (g[0][a] * g[0][b] + g[1][a] * g[1][b]));
        f(row_a, a, b, (b % K - a % K) + 5 * (b / K - a / K) + centre, term);
      }
    }
  };
  if (node_compact_) {  // a refresh: the pairs the assembly joined, in the compacted rows
    // The pair (a, b) at `slot` of a's row and the mirror slot of b's row gets `term` in both.
    const auto add_compact_pair = [&](std::size_t row_a, int u_b, int slot, double term) {
      const int ab = node_pos_[row_a + static_cast<std::size_t>(slot)];
      const int ba = node_pos_[static_cast<std::size_t>(u_b) * offsets + static_cast<std::size_t>(2 * centre - slot)];
      if (ab < 0 || ba < 0) throw std::logic_error("ExplicitConduction: a pair outside the node operator's assembled rows");
      node_kc_[static_cast<std::size_t>(ab)] += term;
      node_kc_[static_cast<std::size_t>(ba)] += term;
    };
    if constexpr (Dim == 2) {
      if (count == total) {  // a whole stencil: the loop below with its slots known when compiled
        for_each_whole_pair([&](std::size_t row_a, int, int b, int slot, double term) {
          add_compact_pair(row_a, u[b], slot, term);
        });
        return;
      }
    }
    for (int a = 0; a < count; ++a) {
      const std::size_t row_a = static_cast<std::size_t>(u[a]) * offsets;
      for (int b = a + 1; b < count; ++b) {
        double dot = g[0][a] * g[0][b] + g[1][a] * g[1][b];  // as below: the same bits
        if constexpr (Dim == 3) dot += g[2][a] * g[2][b];
        add_compact_pair(row_a, u[b], code[b] - code[a] + centre, sign * (conductance * dot));
      }
    }
    return;
  }
  double* k_all = node_k_.data();
  int* col_all = node_col_.data();
  if constexpr (Dim == 2) {
    bool all_mine = count == total;
    for (int a = 0; a < count; ++a) all_mine = all_mine && mine[a];
    if (all_mine) {  // a whole stencil on one range: the loop below with its slots known when compiled
      for_each_whole_pair([&](std::size_t row_a, int a, int b, int slot, double term) {
        k_all[row_a + static_cast<std::size_t>(slot)] += term;
        col_all[row_a + static_cast<std::size_t>(slot)] = u[b];
        const std::size_t at = static_cast<std::size_t>(u[b]) * offsets + static_cast<std::size_t>(2 * centre - slot);
        k_all[at] += term;
        col_all[at] = u[a];
      });
      return;
    }
  }
  for (int a = 0; a < count; ++a) {
    const std::size_t row_a = static_cast<std::size_t>(u[a]) * offsets;
    for (int b = a + 1; b < count; ++b) {
      if (!mine[a] && !mine[b]) continue;
      // G'_a·G'_b, the same bits for (a, b) and (b, a): K stays symmetric bit for bit
      double dot = g[0][a] * g[0][b] + g[1][a] * g[1][b];
      if constexpr (Dim == 3) dot += g[2][a] * g[2][b];
      const double term = sign * (conductance * dot);
      const int slot = code[b] - code[a] + centre;  // of b in row a; of a in row b: 2 centre − slot
      if (mine[a]) {
        k_all[row_a + static_cast<std::size_t>(slot)] += term;
        col_all[row_a + static_cast<std::size_t>(slot)] = u[b];
      }
      if (mine[b]) {
        const std::size_t at = static_cast<std::size_t>(u[b]) * offsets + static_cast<std::size_t>(2 * centre - slot);
        k_all[at] += term;
        col_all[at] = u[a];
      }
    }
  }
}

template <int Dim>
template <class Changed>
void ExplicitConduction<Dim>::count_changed(const std::vector<int>& unknown, Changed&& changed) {
  const std::size_t nodes = unknown.size();
  changed_before_.resize(nodes + 1);
  int count = 0;
  changed_before_[0] = 0;
  for (std::size_t i = 0; i < nodes; ++i) {
    const int u = unknown[i];
    count += u >= 0 && changed(u) ? 1 : 0;
    changed_before_[i + 1] = count;
  }
}

namespace explicit_detail {

// Whether a prefix count by grid node (before[i]: counted nodes < i) counts a node of the stencil.
// The stencil's rows are runs of grid nodes (for_each_node's numbering): first to first + (K-1) s_0.
template <int Dim, int K>
inline bool counts_in_rows_from(int first, const mechanics::IVec<Dim>& sd, const int* before);

template <int Dim, class Kernel>
inline bool counts_in_rows(const mechanics::Stencil<Dim, Kernel>& st, const mechanics::NodeIndexer<Dim>& ix,
                           const int* before) {
  const mechanics::IVec<Dim> b = st.first_node();
  int first = ix.shift;
  for (int d = Dim - 1; d >= 0; --d) first += b[d] * ix.stride[d];
  return counts_in_rows_from<Dim, Kernel::K>(first, ix.stride, before);
}

// counts_in_rows with the stencil's first grid node given (first_node_): its K^(Dim-1) rows of K nodes.
template <int Dim, int K>
inline bool counts_in_rows_from(int first, const mechanics::IVec<Dim>& sd, const int* before) {
  const int span = (K - 1) * sd[0] + 1;
  if constexpr (Dim == 2) {
    int row = first;
    for (int j = 0; j < K; ++j, row += sd[1])
      if (before[row + span] != before[row]) return true;
  } else {
    for (int k = 0; k < K; ++k) {
      int row = first + k * sd[2];
      for (int j = 0; j < K; ++j, row += sd[1])
        if (before[row + span] != before[row]) return true;
    }
  }
  return false;
}

template <int Dim>
inline mechanics::Vec<Dim> vec_of(double x, double y, double z) {
  if constexpr (Dim == 2) return mechanics::Vec<Dim>(x, y);
  else return mechanics::Vec<Dim>(x, y, z);
}

}  // namespace explicit_detail

template <int Dim>
template <class Kernel>
bool ExplicitConduction<Dim>::any_changed(const mechanics::Stencil<Dim, Kernel>& st) const {
  return explicit_detail::counts_in_rows(st, indexer_, changed_before_.data());
}

template <int Dim>
template <class Kernel>
bool ExplicitConduction<Dim>::whole(const mechanics::Stencil<Dim, Kernel>& st) const {
  return !explicit_detail::counts_in_rows(st, indexer_, dropped_before_.data());
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::look_whole(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown,
                                         const double* T, double& lo, double& hi, double& s,
                                         mechanics::Vec<Dim>& grad) const {
  // As expand<Kernel, true> and the passes' loops over its lists: min/max are exact, and s and grad
  // get the same terms in node order.
  // The components as scalars (a Vec through memory stalls on store forwarding): each the sum
  // Eigen's grad += G t makes, component by component.
  const int* un = unknown.data();
  double l = std::numeric_limits<double>::infinity(), h = -l, sum = 0.0;
  double g0 = 0.0, g1 = 0.0, g2 = 0.0;
  explicit_detail::for_each_unknown_whole(st, indexer_, un, [&](int u, double w, double gx, double gy, double gz) {
    const double t = T[u];
    l = std::min(l, t);
    h = std::max(h, t);
    sum += w;
    g0 += gx * t;
    g1 += gy * t;
    if constexpr (Dim == 3) g2 += gz * t;
  });
  lo = l;
  hi = h;
  s = sum;
  grad = explicit_detail::vec_of<Dim>(g0, g1, g2);
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::scatter_whole(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown,
                                            const mechanics::Vec<Dim>& g, double* force) const {
  // G·g as Eigen's dot sums it: (x x' + y y') + z z'.
  const int* un = unknown.data();
  const double g0 = g[0], g1 = g[1], g2 = Dim == 3 ? g[Dim - 1] : 0.0;
  explicit_detail::for_each_unknown_whole(st, indexer_, un, [&](int u, double, double gx, double gy, double gz) {
    double dot = gx * g0 + gy * g1;
    if constexpr (Dim == 3) dot += gz * g2;
    force[u] -= dot;
  });
}

}  // namespace frictherm::coupling
