// Matrix-free explicit conduction over one coupling window (explicit_conduction.hpp; Nairn et al.
// 2018 eqs. 37–38, as NairnMPM integrates conduction): one particle pass gathers M, T and the lumped
// gradients, each forward-Euler sub-step is one pass computing (∇T)_p and scattering f_i, and the
// change goes back to the particles with the stencils of the gather.
#include <frictherm/coupling/explicit_conduction.hpp>

#include "conductance_rows.hpp"  // NodeRange, assembly_threads

#include <algorithm>
#include <array>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stdexcept>
#include <string>

namespace frictherm::coupling {
namespace {

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
#pragma omp parallel num_threads(threads)
  {
    const NodeRange mine = NodeRange::of_thread(0, nodes);
    Scratch scratch{};
    for (std::size_t k : list) body(k, mine, scratch);
  }
}

// Relative spread of a particle's nodal temperatures below which they are taken as equal in the
// sub-steps: 256 ε, the order of the re-projection's own round-off (T_i = Σ m C T S / Σ m C S over
// ~10–30 terms). At 300 K it is 1.7e-11 K.
constexpr double kQuietSpread = 256.0 * 2.220446049250313e-16;

}  // namespace

template <int Dim>
template <class Kernel, bool WithG>
void ExplicitConduction<Dim>::expand(const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown,
                                     Expanded& e) const {
  // The sums of the gather before issue 35 (keep()), in the same order: S over the unknowns, G over
  // the other nodes.
  double s_kept = 0.0;
  double g_dropped[Dim] = {};
  int n = 0, total = 0;
  for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
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
void ExplicitConduction<Dim>::gather_with(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p,
                                          const std::vector<ThermalProperties>& materials,
                                          const AssemblyOptions& opt, NodalThermalSystem& sys,
                                          const mechanics::StencilView<Dim>& view, bool keep_stencils) {
  static_assert(mechanics::Stencil<Dim, Kernel>::node_count <= capacity, "stencil wider than the node list");
  const std::size_t n_nodes = grid.node_count();
  sys.grid_mass.assign(n_nodes, 0.0);
  sys.grid_node.clear();
  sys.particle_heat_capacity = 0.0;
  sys.dropped_mass = 0.0;
  sys.conductance.resize(0, 0);  // no K on this path
  mct_.assign(n_nodes, 0.0);
  quick_sum_.assign(n_nodes, 0.0);
  indexer_ = mechanics::NodeIndexer<Dim>{grid.strides(), 0};
  heat_capacity_.assign(p.size(), 0.0);
  conductance_.assign(p.size(), 0.0);
  rayleigh_.assign(p.size(), 0.0);
  bounds_ready_ = false;
  quiet_.assign(p.size(), 1);  // particles that hold no heat carry no flux
  flux_temperature_.resize(0);  // set with quiet_ at the end
  // The MPM step's stencils at these positions when it gives them (the same S_ip, G_ip), else our own.
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  StencilVector<Kernel>& kept_stencils = stencils_.template of<Kernel>();
  stencils_kept_ = keep_stencils || !step_stencils;
  if (stencils_kept_) {
    kept_stencils.resize(p.size());
    gathered_at_.assign(p.position.begin(), p.position.end());
    window_stencils_ = kept_stencils.data();
  } else {  // read in place for this window only; refresh() then asks for a gather
    kept_stencils.clear();
    gathered_at_.clear();
    window_stencils_ = step_stencils;
  }

  // Pass 1: M_i and M_i T_i (eq. 38), in particle order as assemble_thermal sums them, and the sums of
  // quick_bound(); each heat-holding particle's stencil kept (copied from the step's, or evaluated
  // here) when a refresh may follow.
  const int threads = assembly_detail::assembly_threads(p.size());
  holds_heat_.assign(p.size(), 0);
  listed_.clear();
  for (std::size_t k = 0; k < p.size(); ++k) {
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);  // throws here
    if (!m.conducts) continue;
    holds_heat_[k] = 1;
    listed_.push_back(k);
    const double mc = p.mass[k] * m.heat_capacity;
    sys.particle_heat_capacity += mc;
    heat_capacity_[k] = mc;
    conductance_[k] = m.conductivity > 0.0 ? p.volume[k] * m.conductivity : 0.0;
  }
  if (stencils_kept_) {
#pragma omp parallel for num_threads(threads) schedule(static)
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!holds_heat_[k]) continue;
      if (step_stencils) kept_stencils[k] = step_stencils[k];
      else kept_stencils[k].evaluate(grid, p.position[k], p.half_size[k]);
    }
  }
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  if (threads <= 1) {  // the same sums without the range checks
    for (std::size_t k : listed_) {
      const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
      const double mc = heat_capacity_[k];
      const double mct = mc * p.temperature[k];
      const double quick = quick_weight(st, conductance_[k]);
      for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
        sys.grid_mass[static_cast<std::size_t>(i)] += mc * w;
        mct_[static_cast<std::size_t>(i)] += mct * w;
        quick_sum_[static_cast<std::size_t>(i)] += quick * (std::fabs(gx) + std::fabs(gy) + std::fabs(gz));
      });
    }
  } else
  scatter_by_node_ranges<Expanded>(threads, static_cast<int>(n_nodes), listed_, [&](std::size_t k, const NodeRange& r, Expanded&) {
    const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
    if (!r.meets(node_span(st, indexer_))) return;
    const double mc = heat_capacity_[k];
    const double mct = mc * p.temperature[k];
    const double quick = quick_weight(st, conductance_[k]);
    for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
      if (!r.holds(i)) return;
      sys.grid_mass[static_cast<std::size_t>(i)] += mc * w;
      mct_[static_cast<std::size_t>(i)] += mct * w;
      quick_sum_[static_cast<std::size_t>(i)] += quick * (std::fabs(gx) + std::fabs(gy) + std::fabs(gz));
    });
  });
  if (!(sys.particle_heat_capacity > 0.0))
    throw std::invalid_argument("thermal assembly: no particle of a material with thermal properties");

  // Unknowns: the same rule as assemble_thermal.
  sys.select_unknowns(mct_, opt.active_mass_fraction);
  const auto n = static_cast<Eigen::Index>(sys.grid_node.size());
  // The eq. 38 sums the windows re-project from, kept up to date with the particles' temperatures
  // by map_back and refresh from here on.
  next_mct_.resize(n);
  for (Eigen::Index u = 0; u < n; ++u) next_mct_[u] = mct_[static_cast<std::size_t>(sys.grid_node[static_cast<std::size_t>(u)])];
  mass_peak_ = sys.mass;
  rayleigh_scale_ = 1.0;

  // Pass 2: which particles carry flux at the temperatures the window starts from (sys.temperature,
  // what the coupler advances from), as the first sub-step would find, and for those the first
  // sub-step's f_i, summed in particle order as substeps_with sums it, while the particle's G' is at
  // hand. The bounds of M⁻¹K wait until asked for (lambda_bound).
  force_.setZero(n);
  // Each particle's look (threads by particles), then the lumping terms of quick_bound() and the
  // fluxes of those that carry flux, scattered by node ranges in particle order.
  particle_scratch_.assign(p.size(), 0.0);  // 1: lumped, 2: carries flux (bits)
#pragma omp parallel num_threads(threads)
  {
  Expanded e{};
#pragma omp for schedule(static)
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!holds_heat_[k] || conductance_[k] == 0.0) continue;  // quiet
    expand<Kernel, false>(stencils[k], sys.unknown, e);
    if (!e.reaches()) continue;  // no heat capacity of its own reaches an unknown: no conduction
    double lo = sys.temperature[e.unknown[0]], hi = lo;
    for (int a = 1; a < e.count; ++a) {
      lo = std::min(lo, sys.temperature[e.unknown[a]]);
      hi = std::max(hi, sys.temperature[e.unknown[a]]);
    }
    quiet_[k] = hi - lo <= kQuietSpread * std::max(std::fabs(lo), std::fabs(hi));
    particle_scratch_[k] = (e.count < e.total ? 1.0 : 0.0) + (quiet_[k] ? 0.0 : 2.0);
  }
  }
  listed_.clear();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (particle_scratch_[k] != 0.0) listed_.push_back(k);
  scatter_by_node_ranges<Expanded>(threads, static_cast<int>(n_nodes), listed_, [&](std::size_t k, const NodeRange& r, Expanded& e) {
    const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
    if (!r.meets(node_span(st, indexer_))) return;
    const int what = static_cast<int>(particle_scratch_[k]);
    if (what & 2) expand<Kernel, true>(st, sys.unknown, e);  // S as expand<false> gives it
    else expand<Kernel, false>(st, sys.unknown, e);
    if (what & 1) add_quick_lumping(st, conductance_[k], sys, e, 1.0, &r);
    if (!(what & 2)) return;
    // (∇T)_p = Σ_j G'_jp T_j (eq. 37), times V_p k_p; f_i = −V k G'·∇T (as substeps_with)
    mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
    for (int a = 0; a < e.count; ++a) grad += e.g(a) * sys.temperature[e.unknown[a]];
    grad *= conductance_[k];
    for (int a = 0; a < e.count; ++a)
      if (r.holds(sys.grid_node[static_cast<std::size_t>(e.unknown[a])])) force_[e.unknown[a]] -= e.g(a).dot(grad);
  });
  flux_temperature_ = sys.temperature;  // quiet_ and force_ hold for these temperatures
  first_force_ready_ = true;
}

template <int Dim>
void ExplicitConduction<Dim>::add_bounds(std::size_t k, const NodalThermalSystem& sys, const Expanded& e) {
  const double conductance = conductance_[k];
  rayleigh_[k] = 0.0;
  if (conductance == 0.0 || !e.reaches()) return;  // no conduction (as assemble_thermal)
  const int n = e.count;
  // Two bounds of M⁻¹K, the smaller one is used (lambda_bound): Gershgorin with |G'_i·G'_j| ≤
  // |G'_i||G'_j|, and Cauchy–Schwarz on the Rayleigh quotient, Σ_p c_p |Σ_a G'_a x_a|² ≤
  // Σ_p c_p (Σ_a |G'_a|²/M_a)(Σ_a M_a x_a²), so λ ≤ max_i Σ_{p∋i} c_p Σ_a |G'_a|²/M_a.
  double gsum = 0.0, g2m = 0.0;
  double gnorm[capacity];
  double g2[capacity];
  int a0 = 0;
#if defined(__SSE2__)
  // Two nodes at a time (sqrtpd, divpd: the pass was bound by the divider). The same correctly
  // rounded operations in the same order as Vec::norm() (x² + y²) + z² and |G'|²/M: the same bits.
  for (; a0 + 1 < n; a0 += 2) {
    __m128d s2 = _mm_add_pd(_mm_mul_pd(_mm_loadu_pd(&e.G[0][a0]), _mm_loadu_pd(&e.G[0][a0])),
                            _mm_mul_pd(_mm_loadu_pd(&e.G[1][a0]), _mm_loadu_pd(&e.G[1][a0])));
    if constexpr (Dim == 3)
      s2 = _mm_add_pd(s2, _mm_mul_pd(_mm_loadu_pd(&e.G[2][a0]), _mm_loadu_pd(&e.G[2][a0])));
    const __m128d gn = _mm_sqrt_pd(s2);
    _mm_storeu_pd(&gnorm[a0], gn);
    const __m128d mass = _mm_set_pd(sys.mass[e.unknown[a0 + 1]], sys.mass[e.unknown[a0]]);
    _mm_storeu_pd(&g2[a0], _mm_div_pd(_mm_mul_pd(gn, gn), mass));
  }
#endif
  for (int a = a0; a < n; ++a) {
    gnorm[a] = e.g(a).norm();
    g2[a] = gnorm[a] * gnorm[a] / sys.mass[e.unknown[a]];
  }
  for (int a = 0; a < n; ++a) {  // the sums in node order
    gsum += gnorm[a];
    g2m += g2[a];
  }
  const double rayleigh = conductance * g2m;
  rayleigh_[k] = rayleigh;
  for (int a = 0; a < n; ++a) {
    row_bound_[static_cast<std::size_t>(e.unknown[a])] += conductance * gnorm[a] * gsum;
    rayleigh_bound_[static_cast<std::size_t>(e.unknown[a])] += rayleigh;
  }
}

template <int Dim>
void ExplicitConduction<Dim>::remove_bounds(std::size_t k, const Expanded& e) {
  const double conductance = conductance_[k];
  if (conductance == 0.0 || !e.reaches()) return;  // add_bounds() added none
  double gsum = 0.0;
  double gnorm[capacity];
  for (int a = 0; a < e.count; ++a) gnorm[a] = e.g(a).norm();
  for (int a = 0; a < e.count; ++a) gsum += gnorm[a];
  for (int a = 0; a < e.count; ++a) {
    row_bound_[static_cast<std::size_t>(e.unknown[a])] -= conductance * gnorm[a] * gsum;
    rayleigh_bound_[static_cast<std::size_t>(e.unknown[a])] -= rayleigh_[k];
  }
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::add_quick_lumping(const mechanics::Stencil<Dim, Kernel>& st, double conductance,
                                                const NodalThermalSystem& sys, const Expanded& e, double sign,
                                                const void* range) {
  // |G'_ip| ≤ |G_ip|₁ + (S_ip / Σ S) |Σ_dropped G|, and |Σ_dropped G| ≤ A_p.
  const double weight = quick_weight(st, conductance);
  const double a_p = conductance > 0.0 ? weight / conductance : 0.0;
  const NodeRange* r = static_cast<const NodeRange*>(range);
  for (int a = 0; a < e.count; ++a) {
    const int i = sys.grid_node[static_cast<std::size_t>(e.unknown[a])];
    if (r && !r->holds(i)) continue;
    quick_sum_[static_cast<std::size_t>(i)] += sign * weight * a_p * (e.S[a] / e.s_kept);
  }
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::add_quick(const mechanics::Stencil<Dim, Kernel>& st, double conductance,
                                        const NodalThermalSystem& sys, const Expanded& e, double sign) {
  // The gather's terms (pass 1 and 2) of one particle, in (sign 1) or out (sign −1): e its expansion.
  if (conductance == 0.0) return;
  const double quick = sign * quick_weight(st, conductance);
  for_each_node(st, indexer_, [&](int i, double, double gx, double gy, double gz) {
    quick_sum_[static_cast<std::size_t>(i)] += quick * (std::fabs(gx) + std::fabs(gy) + std::fabs(gz));
  });
  if (e.reaches() && e.count < e.total) add_quick_lumping(st, conductance, sys, e, sign);
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::make_bounds(const NodalThermalSystem& sys) {
  row_bound_.assign(sys.size(), 0.0);
  rayleigh_bound_.assign(sys.size(), 0.0);
  mass_peak_ = sys.mass;  // every term with M now
  rayleigh_scale_ = 1.0;
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  Expanded e{};
  for (std::size_t k = 0; k < holds_heat_.size(); ++k) {
    if (!holds_heat_[k] || conductance_[k] == 0.0) continue;
    expand<Kernel, true>(stencils[k], sys.unknown, e);
    add_bounds(k, sys, e);
  }
  bounds_ready_ = true;
}

template <int Dim>
double ExplicitConduction<Dim>::quick_bound(const NodalThermalSystem& sys, const std::vector<FixedNode>& fixed) const {
  std::vector<char> held;
  if (!fixed.empty()) {
    held.assign(sys.size(), 0);
    for (const FixedNode& f : fixed) held[static_cast<std::size_t>(f.unknown)] = 1;
  }
  double bound = 0.0;
  for (std::size_t u = 0; u < sys.size(); ++u) {
    if (!held.empty() && held[u]) continue;
    bound = std::max(bound, quick_sum_[static_cast<std::size_t>(sys.grid_node[u])] / sys.mass[static_cast<Eigen::Index>(u)]);
  }
  return bound * (1.0 + 1e-6);
}

template <int Dim>
void ExplicitConduction<Dim>::gather(const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles,
                                     mechanics::ShapeKind shape, const std::vector<ThermalProperties>& materials,
                                     const AssemblyOptions& options, NodalThermalSystem& sys,
                                     const mechanics::StencilView<Dim>& stencils, bool keep_stencils) {
  kind_ = shape;
  mechanics::dispatch_shape(shape, [&](auto kernel) {
    gather_with<decltype(kernel)>(grid, particles, materials, options, sys, stencils, keep_stencils);
  });
}

template <int Dim>
template <class Kernel>
typename ExplicitConduction<Dim>::Refresh ExplicitConduction<Dim>::refresh_with(
    const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& p, const std::vector<ThermalProperties>& materials,
    const AssemblyOptions& opt, NodalThermalSystem& sys, double max_shift, const mechanics::StencilView<Dim>& view) {
  first_force_ready_ = false;
  if (!stencils_kept_ || gathered_at_.size() != p.size() || heat_capacity_.size() != p.size() ||
      stencils_.template of<Kernel>().size() != p.size())
    return Refresh::regather;
  moved_.clear();
  std::size_t holding = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!holds_heat_[k]) continue;
    ++holding;
    if (!((p.position[k] - gathered_at_[k]).cwiseAbs().maxCoeff() <= max_shift)) moved_.push_back(k);
  }
  if (moved_.empty()) return Refresh::kept;
  if (4 * moved_.size() > holding) return Refresh::regather;  // a full gather costs less

  // M_i on every node (eq. 38): each moved particle's weights at its last gather out, at its
  // position now in (the step's stencils when given: the same numbers as evaluating them here).
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  const StencilVector<Kernel>& kept_stencils = stencils_.template of<Kernel>();
  StencilVector<Kernel>& now = moved_stencils_.template of<Kernel>();
  now.resize(moved_.size());
  for (std::size_t j = 0; j < moved_.size(); ++j) {
    const std::size_t k = moved_[j];
    const double mc = heat_capacity_[k];
    kept_stencils[k].for_each(indexer_, [&](int i, double w, const mechanics::Vec<Dim>&) {
      sys.grid_mass[static_cast<std::size_t>(i)] -= mc * w;
    });
    if (step_stencils) now[j] = step_stencils[k];
    else now[j].evaluate(grid, p.position[k], p.half_size[k]);
    now[j].for_each(indexer_, [&](int i, double w, const mechanics::Vec<Dim>&) {
      sys.grid_mass[static_cast<std::size_t>(i)] += mc * w;
    });
  }

  // The unknowns must stay those of the gather (select_unknowns' rule): the kept lists, the lumping
  // of G' and the fixed nodes are numbered by them.
  const double max_mass = *std::max_element(sys.grid_mass.begin(), sys.grid_mass.end());
  const double threshold = opt.active_mass_fraction * max_mass;
  double dropped = 0.0;
  for (std::size_t i = 0; i < sys.grid_mass.size(); ++i) {
    const bool active = sys.grid_mass[i] > threshold && sys.grid_mass[i] > 0.0;
    if (active != (sys.unknown[i] >= 0)) {
      gathered_at_.clear();  // M is half refreshed: only a gather may follow
      return Refresh::regather;
    }
    if (!active) dropped += sys.grid_mass[i];
  }
  sys.max_mass = max_mass;
  sys.dropped_mass = dropped;
  double scale = 1.0;
  for (Eigen::Index u = 0; u < sys.mass.size(); ++u) {
    sys.mass[u] = sys.grid_mass[static_cast<std::size_t>(sys.grid_node[static_cast<std::size_t>(u)])];
    mass_peak_[u] = std::max(mass_peak_[u], sys.mass[u]);
    scale = std::max(scale, mass_peak_[u] / sys.mass[u]);
  }
  rayleigh_scale_ = scale;

  // The moved particles' kept state, bounds and eq. 38 sums for the next reproject(), anew: the
  // exact bounds if they were made since the gather (lambda_bound), else the quick bound's sums.
  Expanded e{};
  StencilVector<Kernel>& kept = stencils_.template of<Kernel>();
  for (std::size_t j = 0; j < moved_.size(); ++j) {
    const std::size_t k = moved_[j];
    const double mct = heat_capacity_[k] * p.temperature[k];
    // as its last gather: the unknowns have not changed
    if (bounds_ready_) expand<Kernel, true>(kept[k], sys.unknown, e);
    else expand<Kernel, false>(kept[k], sys.unknown, e);
    for (int a = 0; a < e.count; ++a) next_mct_[e.unknown[a]] -= mct * e.S[a];  // its old terms out
    if (bounds_ready_) remove_bounds(k, e);
    add_quick(kept[k], conductance_[k], sys, e, -1.0);
    kept[k] = now[j];
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    conductance_[k] = m.conductivity > 0.0 ? p.volume[k] * m.conductivity : 0.0;  // V_p now
    if (bounds_ready_) {
      expand<Kernel, true>(kept[k], sys.unknown, e);
      add_bounds(k, sys, e);
    } else {
      expand<Kernel, false>(kept[k], sys.unknown, e);
    }
    add_quick(kept[k], conductance_[k], sys, e, 1.0);
    quiet_[k] = 0;  // looked at in the next sub-step
    for (int a = 0; a < e.count; ++a) next_mct_[e.unknown[a]] += mct * e.S[a];  // and its new ones in
    gathered_at_[k] = p.position[k];
  }
  return Refresh::refreshed;
}

template <int Dim>
typename ExplicitConduction<Dim>::Refresh ExplicitConduction<Dim>::refresh(
    const mechanics::Grid<Dim>& grid, const mechanics::Particles<Dim>& particles, mechanics::ShapeKind shape,
    const std::vector<ThermalProperties>& materials, const AssemblyOptions& options, NodalThermalSystem& sys,
    double max_shift, const mechanics::StencilView<Dim>& stencils) {
  return mechanics::dispatch_shape(shape, [&](auto kernel) {
    return refresh_with<decltype(kernel)>(grid, particles, materials, options, sys, max_shift, stencils);
  });
}

template <int Dim>
void ExplicitConduction<Dim>::reproject(const mechanics::Particles<Dim>& p, NodalThermalSystem& sys) {
  if (heat_capacity_.size() != p.size()) throw std::logic_error("ExplicitConduction::reproject: no gather for these particles");
  const auto n = static_cast<Eigen::Index>(sys.size());
  if (next_mct_.size() != n) throw std::logic_error("ExplicitConduction::reproject: the sums are of other unknowns");
  first_force_ready_ = false;
  // The eq. 38 sums, kept with the particles' temperatures by the gather, refresh and map_back.
  for (Eigen::Index u = 0; u < n; ++u) sys.temperature[u] = next_mct_[u] / sys.mass[u];
}

template <int Dim>
double ExplicitConduction<Dim>::lambda_bound(const NodalThermalSystem& sys, const std::vector<FixedNode>& fixed) {
  if (!bounds_ready_)
    mechanics::dispatch_shape(kind_, [&](auto kernel) { make_bounds<decltype(kernel)>(sys); });
  // Rows of fixed nodes do not move (dT/dt = 0): they contribute λ = 0, as in lambda_max_gershgorin.
  std::vector<char> held;
  if (!fixed.empty()) {
    held.assign(row_bound_.size(), 0);
    for (const FixedNode& f : fixed) held[static_cast<std::size_t>(f.unknown)] = 1;
  }
  double gershgorin = 0.0, rayleigh = 0.0;
  const std::size_t n = row_bound_.size();
  for (std::size_t u = 0; u < n; ++u) {
    if (!held.empty() && held[u]) continue;
    gershgorin = std::max(gershgorin, row_bound_[u] / sys.mass[static_cast<Eigen::Index>(u)]);
    rayleigh = std::max(rayleigh, rayleigh_bound_[u]);
  }
  return std::min(gershgorin, rayleigh * rayleigh_scale_);  // stale M in refreshed terms: rayleigh_scale_
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

template <int Dim>
template <class Kernel>
bool ExplicitConduction<Dim>::any_changed(const mechanics::Stencil<Dim, Kernel>& st) const {
  // The stencil's rows are runs of grid nodes (for_each_node's numbering): first to first + (K-1) s_0.
  constexpr int K = Kernel::K;
  const mechanics::IVec<Dim>& sd = indexer_.stride;
  const mechanics::IVec<Dim> b = st.first_node();
  const int span = (K - 1) * sd[0] + 1;
  const int* before = changed_before_.data();
  if constexpr (Dim == 2) {
    int row = indexer_.shift + b[1] * sd[1] + b[0] * sd[0];
    for (int j = 0; j < K; ++j, row += sd[1])
      if (before[row + span] != before[row]) return true;
  } else {
    for (int k = 0; k < K; ++k) {
      int row = indexer_.shift + (b[2] + k) * sd[2] + b[1] * sd[1] + b[0] * sd[0];
      for (int j = 0; j < K; ++j, row += sd[1])
        if (before[row + span] != before[row]) return true;
    }
  }
  return false;
}

template <int Dim>
Eigen::VectorXd ExplicitConduction<Dim>::advance(const NodalThermalSystem& sys, const Eigen::VectorXd& temperature,
                                                 const Eigen::VectorXd& joules, const std::vector<FixedNode>& fixed,
                                                 double window, long substeps) {
  const auto n = static_cast<Eigen::Index>(sys.size());
  if (temperature.size() != n || joules.size() != n)
    throw std::invalid_argument("ExplicitConduction::advance: " + std::to_string(temperature.size()) +
                                " temperatures and " + std::to_string(joules.size()) + " sources for " +
                                std::to_string(sys.size()) + " unknowns");
  if (!(window > 0.0) || substeps < 1)
    throw std::invalid_argument("ExplicitConduction::advance: need a window > 0 and at least one sub-step");
  Eigen::VectorXd T = temperature;
  for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;  // Dirichlet values first
  const double h = window / static_cast<double>(substeps);
  const Eigen::VectorXd q = joules / window;  // constant over the window: ∫ q dt = W (design §4)
  mechanics::dispatch_shape(kind_, [&](auto kernel) { substeps_with<decltype(kernel)>(sys, T, q, fixed, h, substeps); });
  return T;
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::substeps_with(const NodalThermalSystem& sys, Eigen::VectorXd& T, const Eigen::VectorXd& q,
                                            const std::vector<FixedNode>& fixed, double h, long substeps) {
  const auto n = static_cast<Eigen::Index>(sys.size());
  // The gather's f_i serve the first sub-step if it starts from the temperatures they were made at
  // (no fixed node changed one): the same sums, the particle pass saved.
  bool force_ready = first_force_ready_ && force_.size() == n && flux_temperature_.size() == n &&
                     T == flux_temperature_;
  first_force_ready_ = false;
  force_.resize(n);
  const int threads = assembly_detail::assembly_threads(holds_heat_.size());
  const int nodes = static_cast<int>(sys.unknown.size());
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  for (long s = 0; s < substeps; ++s) {
    if (force_ready) {
      force_ready = false;
      for (Eigen::Index u = 0; u < n; ++u) T[u] += h * (force_[u] + q[u]) / sys.mass[u];
      for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
      continue;
    }
    force_.setZero();
    // Nodes whose temperature changed since the last sub-step, as a prefix count over the unknowns:
    // a particle whose nodes all kept theirs and that was quiet then is quiet now, and is passed over
    // reading a few bytes instead of its kept state.
    const bool first = flux_temperature_.size() != n;
    count_changed(sys.unknown, [&](int u) { return first || T[u] != flux_temperature_[u]; });
    flux_temperature_ = T;
    if (threads <= 1) {  // one pass: the same numbers in the same order, no lists
      Expanded e{};
      for (std::size_t k = 0; k < holds_heat_.size(); ++k) {
        if (!holds_heat_[k] || (quiet_[k] && !any_changed(stencils[k]))) continue;
        if (conductance_[k] == 0.0) {
          quiet_[k] = 1;
          continue;
        }
        expand<Kernel, false>(stencils[k], sys.unknown, e);
        if (!e.reaches()) {
          quiet_[k] = 1;
          continue;
        }
        double lo = T[e.unknown[0]], hi = lo;
        for (int a = 1; a < e.count; ++a) {
          lo = std::min(lo, T[e.unknown[a]]);
          hi = std::max(hi, T[e.unknown[a]]);
        }
        quiet_[k] = hi - lo <= kQuietSpread * std::max(std::fabs(lo), std::fabs(hi));
        if (quiet_[k]) continue;
        expand<Kernel, true>(stencils[k], sys.unknown, e);
        mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
        for (int a = 0; a < e.count; ++a) grad += e.g(a) * T[e.unknown[a]];
        grad *= conductance_[k];
        for (int a = 0; a < e.count; ++a) force_[e.unknown[a]] -= e.g(a).dot(grad);
      }
      for (Eigen::Index u = 0; u < n; ++u) T[u] += h * (force_[u] + q[u]) / sys.mass[u];
      for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
      continue;
    }
    // Each particle's look (threads by particles), then the fluxes of those that carry flux,
    // scattered by node ranges in particle order.
    particle_scratch_.assign(holds_heat_.size(), 0.0);  // 1: carries flux
#pragma omp parallel num_threads(threads)
    {
    Expanded e{};
#pragma omp for schedule(static)
    for (std::size_t k = 0; k < holds_heat_.size(); ++k) {
      if (!holds_heat_[k] || (quiet_[k] && !any_changed(stencils[k]))) continue;
      if (conductance_[k] == 0.0) {
        quiet_[k] = 1;  // carries no flux whatever its nodes do
        continue;
      }
      // Nodal temperatures that agree to round-off (the re-projection's own, kQuietSpread) carry no
      // flux through the particle: its terms are left out, which keeps Σ_i f_i = 0 exactly and the
      // nodes it alone touches unchanged (their ΔT_i = 0 lets the map back pass over their particles).
      expand<Kernel, false>(stencils[k], sys.unknown, e);
      if (!e.reaches()) {
        quiet_[k] = 1;  // no heat capacity of its own reaches an unknown: no conduction
        continue;
      }
      double lo = T[e.unknown[0]], hi = lo;
      for (int a = 1; a < e.count; ++a) {
        lo = std::min(lo, T[e.unknown[a]]);
        hi = std::max(hi, T[e.unknown[a]]);
      }
      quiet_[k] = hi - lo <= kQuietSpread * std::max(std::fabs(lo), std::fabs(hi));
      if (!quiet_[k]) particle_scratch_[k] = 1.0;
    }
    }
    listed_.clear();
    for (std::size_t k = 0; k < holds_heat_.size(); ++k)
      if (particle_scratch_[k] != 0.0) listed_.push_back(k);
    scatter_by_node_ranges<Expanded>(threads, nodes, listed_, [&](std::size_t k, const NodeRange& r, Expanded& e) {
      const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
      if (!r.meets(node_span(st, indexer_))) return;
      expand<Kernel, true>(st, sys.unknown, e);
      // (∇T)_p = Σ_j G'_jp T_j (eq. 37), times V_p k_p
      mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
      for (int a = 0; a < e.count; ++a) grad += e.g(a) * T[e.unknown[a]];
      grad *= conductance_[k];
      for (int a = 0; a < e.count; ++a)  // f_i = −V k G'·∇T
        if (r.holds(sys.grid_node[static_cast<std::size_t>(e.unknown[a])])) force_[e.unknown[a]] -= e.g(a).dot(grad);
    });
    for (Eigen::Index u = 0; u < n; ++u) T[u] += h * (force_[u] + q[u]) / sys.mass[u];
    for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
  }
}

template <int Dim>
void ExplicitConduction<Dim>::map_back(mechanics::Particles<Dim>& p, const NodalThermalSystem& sys,
                                       const Eigen::VectorXd& delta, double beta, const Eigen::VectorXd* end) {
  if (heat_capacity_.size() != p.size())
    throw std::logic_error("ExplicitConduction::map_back: the particles changed since the gather");
  if (next_mct_.size() != static_cast<Eigen::Index>(sys.size()))
    throw std::logic_error("ExplicitConduction::map_back: no re-projection for these unknowns");
  mechanics::dispatch_shape(kind_, [&](auto kernel) { map_back_with<decltype(kernel)>(p, sys, delta, beta, end); });
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::map_back_with(mechanics::Particles<Dim>& p, const NodalThermalSystem& sys,
                                            const Eigen::VectorXd& delta, double beta, const Eigen::VectorXd* end) {
  const bool relax = end && beta > 0.0;
  // Unknowns whose temperature changed in the window, as a prefix count by grid node: a particle with
  // none among its nodes keeps its temperature (ΔT_p = 0 exactly) and is passed over.
  count_changed(sys.unknown, [&](int u) { return relax || delta[u] != 0.0; });
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  const int threads = assembly_detail::assembly_threads(p.size());
  // Each particle's new temperature (threads by particles), then the changes of the eq. 38 sums,
  // scattered by node ranges in particle order.
  if (threads <= 1) {  // one pass: the same numbers in the same order, no lists
    Expanded c{};
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!holds_heat_[k] || !any_changed(stencils[k])) continue;
      expand<Kernel, false>(stencils[k], sys.unknown, c);
      if (c.count == 0) continue;  // reaches no unknown
      double dT = 0.0;  // design §4: the increment, not the nodal value
      for (int a = 0; a < c.count; ++a) dT += c.S[a] * delta[c.unknown[a]];
      double pic = 0.0, s = 0.0;
      if (relax) {
        for (int a = 0; a < c.count; ++a) {
          pic += c.S[a] * (*end)[c.unknown[a]];
          s += c.S[a];
        }
      }
      const double before = p.temperature[k];
      const double flip = before + dT;
      const double T = (relax && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
      if (T == before) continue;
      p.temperature[k] = T;
      const double change = heat_capacity_[k] * (T - before);
      for (int a = 0; a < c.count; ++a) next_mct_[c.unknown[a]] += change * c.S[a];
    }
    return;
  }
  particle_scratch_.assign(p.size(), 0.0);  // m_p C_v,p ΔT_p of the particles that changed
  std::vector<unsigned char>& changed = quiet_changed_;
  changed.assign(p.size(), 0);
#pragma omp parallel num_threads(threads)
  {
  Expanded c{};
#pragma omp for schedule(static)
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!holds_heat_[k] || !any_changed(stencils[k])) continue;
    expand<Kernel, false>(stencils[k], sys.unknown, c);
    if (c.count == 0) continue;  // reaches no unknown
    // design §4: the increment, not the nodal value
    double dT = 0.0;
    for (int a = 0; a < c.count; ++a) dT += c.S[a] * delta[c.unknown[a]];
    double pic = 0.0, s = 0.0;
    if (relax) {
      for (int a = 0; a < c.count; ++a) {
        pic += c.S[a] * (*end)[c.unknown[a]];
        s += c.S[a];
      }
    }
    const double before = p.temperature[k];
    const double flip = before + dT;
    const double T = (relax && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
    if (T == before) continue;  // unchanged (no heat reached its nodes): its eq. 38 terms stand
    p.temperature[k] = T;
    particle_scratch_[k] = heat_capacity_[k] * (T - before);
    changed[k] = 1;
  }
  }
  listed_.clear();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (changed[k]) listed_.push_back(k);
  // The eq. 38 sums of the next window, which re-projects from them: m_p C_v,p ΔT_p S_ip added.
  scatter_by_node_ranges<Expanded>(threads, static_cast<int>(sys.unknown.size()), listed_, [&](std::size_t k, const NodeRange& r, Expanded& c) {
    const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
    if (!r.meets(node_span(st, indexer_))) return;
    expand<Kernel, false>(st, sys.unknown, c);
    const double change = particle_scratch_[k];
    for (int a = 0; a < c.count; ++a)
      if (r.holds(sys.grid_node[static_cast<std::size_t>(c.unknown[a])])) next_mct_[c.unknown[a]] += change * c.S[a];
  });
}

template class ExplicitConduction<2>;
template class ExplicitConduction<3>;

}  // namespace frictherm::coupling
