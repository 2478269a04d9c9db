// Matrix-free explicit conduction over one coupling window (explicit_conduction.hpp; Nairn et al.
// 2018 eqs. 37–38, as NairnMPM integrates conduction): one particle pass gathers M, T and the lumped
// gradients, each forward-Euler sub-step is one pass computing (∇T)_p and scattering f_i, and the
// change goes back to the particles with the stencils of the gather.
#include <frictherm/coupling/explicit_conduction.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include "explicit_conduction_detail.hpp"  // the passes' helpers, expand, any_changed

#include <algorithm>
#include <iterator>

namespace frictherm::coupling {

using namespace explicit_detail;

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
  bounds_ready_ = false;  // rayleigh_ made with the bounds (make_bounds)
  node_operator_ready_ = false;  // made anew by the first sub-step that takes it
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
  const int threads = assembly_detail::explicit_handoff_threads(p.size());
  holds_heat_.assign(p.size(), 0);
  holding_ = 0;
  listed_.clear();
  const std::size_t n_materials = materials.size();
  for (std::size_t k = 0; k < p.size(); ++k) {
    const int id = p.material[k];
    const ThermalProperties& m = id >= 0 && static_cast<std::size_t>(id) < n_materials
                                     ? materials[static_cast<std::size_t>(id)]
                                     : thermal_properties_of(materials, id);  // throws here
    if (!m.conducts) continue;
    holds_heat_[k] = 1;
    ++holding_;
    listed_.push_back(k);
    const double mc = p.mass[k] * m.heat_capacity;
    sys.particle_heat_capacity += mc;
    heat_capacity_[k] = mc;
    conductance_[k] = m.conductivity > 0.0 ? p.volume[k] * m.conductivity : 0.0;
  }
  split_.clear();  // one thread, unless split below
  if (threads <= 1 && stencils_kept_) {
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!holds_heat_[k]) continue;
      if (step_stencils) kept_stencils[k] = step_stencils[k];
      else kept_stencils[k].evaluate(grid, p.position[k], p.half_size[k]);
    }
  }
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  const int reach = stencil_reach<Dim, Kernel::K>(indexer_);
  if (threads > 1) {  // the stencils kept and each one's first node, then the threads' node ranges
    first_node_.assign(p.size(), static_cast<int>(n_nodes));  // past the grid: in no range
    mechanics::parallel_for(threads, p.size(), [&](std::size_t k) {
      if (!holds_heat_[k]) return;
      if (stencils_kept_) {
        if (step_stencils) kept_stencils[k] = step_stencils[k];
        else kept_stencils[k].evaluate(grid, p.position[k], p.half_size[k]);
      }
      first_node_[k] = node_span(stencils[k], indexer_)[0];
    });
    split_nodes<Kernel>(threads, static_cast<int>(n_nodes));
  }
  if (threads <= 1) {  // the same sums without the range checks
    // The three sums of a node side by side (one or two cache lines per stencil row instead of three
    // to six: the three grid arrays together outgrow L2 in 3D), copied out after the pass.
    // (particle_scratch_, a scratch of the threaded passes, holds them: M, M T, quick by node.)
    particle_scratch_.assign(3 * n_nodes, 0.0);
    double* sums = particle_scratch_.data();
    for (std::size_t k : listed_) {
      const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
      const double mc = heat_capacity_[k];
      const double mct = mc * p.temperature[k];
      const double quick = quick_weight(st, conductance_[k]);
      for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
        double* a = sums + 3 * static_cast<std::size_t>(i);
        a[0] += mc * w;
        a[1] += mct * w;
        a[2] += quick * g_l1<Dim>(gx, gy, gz);
      });
    }
    for (std::size_t i = 0; i < n_nodes; ++i) {
      sys.grid_mass[i] = sums[3 * i];
      mct_[i] = sums[3 * i + 1];
      quick_sum_[i] = sums[3 * i + 2];
    }
  } else {
    double* const grid_mass = sys.grid_mass.data();
    double* const mct = mct_.data();
    double* const quick_sum = quick_sum_.data();
    scatter_by_split<char>(split_, first_node_.data(), reach, listed_, [&](std::size_t k, const NodeRange& r, bool inside, char&) {
      const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
      const double mc = heat_capacity_[k];
      const double mct_p = mc * p.temperature[k];
      const double quick = quick_weight(st, conductance_[k]);
      for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
        if (!inside && !r.holds(i)) return;
        grid_mass[i] += mc * w;
        mct[i] += mct_p * w;
        quick_sum[i] += quick * g_l1<Dim>(gx, gy, gz);
      });
    });
  }
  if (!(sys.particle_heat_capacity > 0.0))
    throw std::invalid_argument("thermal assembly: no particle of a material with thermal properties");

  // Unknowns: the same rule as assemble_thermal.
  sys.select_unknowns(mct_, opt.active_mass_fraction);
  const auto n = static_cast<Eigen::Index>(sys.grid_node.size());
  dropped_before_.resize(n_nodes + 1);
  dropped_before_[0] = 0;
  for (std::size_t i = 0; i < n_nodes; ++i) dropped_before_[i + 1] = dropped_before_[i] + (sys.unknown[i] < 0 ? 1 : 0);
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
  if (threads <= 1) {
    // One pass, one expansion per particle (issue 35: the look and the scatter below expanded every
    // conducting particle twice): the same S, quiet flags, lumping terms and f_i, summed in the same
    // particle order as the two passes below, so the same numbers.
    Expanded e{};
    whole_.assign(p.size(), 0);
    first_node_.assign(p.size(), static_cast<int>(n_nodes));  // past the grid: no flag set there
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!holds_heat_[k]) continue;
      const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
      whole_[k] = whole(st);  // read by the sub-steps and the map back
      first_node_[k] = node_span(st, indexer_)[0];
      if (conductance_[k] == 0.0) continue;  // quiet
      if (whole_[k]) {  // no lumping: the stencil walked directly, the same sums
        double lo, hi, s_kept;
        mechanics::Vec<Dim> grad;
        look_whole(st, sys.unknown, sys.temperature.data(), lo, hi, s_kept, grad);
        if (!(s_kept > 0.0)) continue;  // reaches no unknown with its own heat capacity
        quiet_[k] = quiet_spread(lo, hi);
        if (quiet_[k]) continue;
        grad *= conductance_[k];
        scatter_whole(st, sys.unknown, grad, force_.data());
        continue;
      }
      expand<Kernel, true>(st, sys.unknown, e);  // S as expand<false> gives it
      if (!e.reaches()) continue;  // no heat capacity of its own reaches an unknown: no conduction
      quiet_[k] = quiet_temperatures(e, sys.temperature);
      if (e.count < e.total) add_quick_lumping(st, conductance_[k], sys, e, 1.0);
      if (quiet_[k]) continue;
      // (∇T)_p = Σ_j G'_jp T_j (eq. 37), times V_p k_p; f_i = −V k G'·∇T (as substeps_with)
      mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
      for (int a = 0; a < e.count; ++a) grad += e.g(a) * sys.temperature[e.unknown[a]];
      grad *= conductance_[k];
      for (int a = 0; a < e.count; ++a) force_[e.unknown[a]] -= e.g(a).dot(grad);
    }
    flux_temperature_ = sys.temperature;
    first_force_ready_ = true;
    // The node ranges of the node-level operator's assembly on 2 threads (assemble_node_operator).
    if (stencils_kept_ && node_operator_on_)
      split_nodes<Kernel>(assembly_detail::assembly_threads(p.size()), static_cast<int>(n_nodes));
    return;
  }
  // Each particle's look (threads by particles), then the lumping terms of quick_bound() and the
  // fluxes of those that carry flux, scattered by node ranges in particle order.
  particle_scratch_.assign(p.size(), 0.0);  // 1: lumped, 2: carries flux (bits)
  whole_.assign(p.size(), 0);
  first_node_.assign(p.size(), static_cast<int>(n_nodes));  // past the grid: no flag set there
  mechanics::parallel_region(threads, [&] {
  Expanded e{};
#pragma omp for schedule(static)
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!holds_heat_[k]) continue;
    whole_[k] = whole(stencils[k]);  // for one-thread windows that may follow (the governor)
    first_node_[k] = node_span(stencils[k], indexer_)[0];
    if (conductance_[k] == 0.0) continue;  // quiet
    expand<Kernel, false>(stencils[k], sys.unknown, e);
    if (!e.reaches()) continue;  // no heat capacity of its own reaches an unknown: no conduction
    quiet_[k] = quiet_temperatures(e, sys.temperature);
    particle_scratch_[k] = (e.count < e.total ? 1.0 : 0.0) + (quiet_[k] ? 0.0 : 2.0);
  }
  });
  listed_.clear();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (particle_scratch_[k] != 0.0) listed_.push_back(k);
  scatter_by_split<Expanded>(split_, first_node_.data(), reach, listed_, [&](std::size_t k, const NodeRange& r, bool inside, Expanded& e) {
    const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
    const int what = static_cast<int>(particle_scratch_[k]);
    if (inside && what == 2 && whole_[k]) {  // the stencil walked directly, as on one thread: the same sums
      double lo, hi, s_kept;
      mechanics::Vec<Dim> grad;
      look_whole(st, sys.unknown, sys.temperature.data(), lo, hi, s_kept, grad);
      grad *= conductance_[k];
      scatter_whole(st, sys.unknown, grad, force_.data());
      return;
    }
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
    quick_sum_[static_cast<std::size_t>(i)] += quick * g_l1<Dim>(gx, gy, gz);
  });
  if (e.reaches() && e.count < e.total) add_quick_lumping(st, conductance, sys, e, sign);
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::make_bounds(const NodalThermalSystem& sys) {
  row_bound_.assign(sys.size(), 0.0);
  rayleigh_bound_.assign(sys.size(), 0.0);
  rayleigh_.assign(holds_heat_.size(), 0.0);
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
void ExplicitConduction<Dim>::restencil(std::size_t k, mechanics::Stencil<Dim, Kernel>& kept,
                                        const mechanics::Stencil<Dim, Kernel>& fresh, const std::vector<int>& unknown,
                                        Expanded& e) {
  if (node_operator_ready_ && in_node_k_[k]) {  // its K terms out (its old conductance); its flux particle by particle
    add_to_node_operator(kept, conductance_[k], unknown, -1.0, e);
    in_node_k_[k] = 0;
  }
  kept = fresh;
  if (k < out_of_k_slot_.size() && out_of_k_slot_[k] >= 0)  // its kept walk is of the old stencil
    out_of_k_stencils_[static_cast<std::size_t>(out_of_k_slot_[k])].made = false;
  whole_[k] = whole(kept);
  first_node_[k] = node_span(kept, indexer_)[0];
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
  {
    // Moved: a coordinate shifted by more than max_shift since its gather (the largest |shift| >
    // max_shift), as scalars without a branch per particle for the usual unmoved one.
    const mechanics::Vec<Dim>* at = gathered_at_.data();
    const mechanics::Vec<Dim>* now_at = p.position.data();
    const unsigned char* holds = holds_heat_.data();
    std::size_t k = 0;
#if defined(__SSE2__)
    if constexpr (Dim == 2) {  // both coordinates in one register: the same differences and tests
      const __m128d abs_mask = _mm_castsi128_pd(_mm_set1_epi64x(0x7fffffffffffffffLL));
      const __m128d limit = _mm_set1_pd(max_shift);
      for (; k < p.size(); ++k) {
        const __m128d shift = _mm_sub_pd(_mm_loadu_pd(now_at[k].data()), _mm_loadu_pd(at[k].data()));
        const bool within = _mm_movemask_pd(_mm_cmple_pd(_mm_and_pd(shift, abs_mask), limit)) == 3;
        if (!within && holds[k]) moved_.push_back(k);
      }
    }
#endif
    for (; k < p.size(); ++k)
      if (moved_beyond(now_at[k].data(), at[k].data(), max_shift) && holds[k]) moved_.push_back(k);
  }
  if (moved_.empty()) return Refresh::kept;
  if (too_many_moved(moved_.size(), holding_)) return Refresh::regather;  // a full gather costs less

  // M_i on every node (eq. 38): each moved particle's weights at its last gather out, at its
  // position now in (the step's stencils when given: the same numbers as evaluating them here).
  const mechanics::Stencil<Dim, Kernel>* step_stencils = view.template as<Kernel>(p.size());
  StencilVector<Kernel>& kept_stencils = stencils_.template of<Kernel>();
  StencilVector<Kernel>& now = moved_stencils_.template of<Kernel>();
  now.resize(moved_.size());
  // Without the exact bounds (which need M after every moved particle's terms), each moved particle's
  // whole update is made here, in one walk of its old and one of its new stencil when both are whole
  // (issue 35): M_i, the eq. 38 sums and the quick bound's sums each get the same terms in the same
  // particle and node order as the two loops below give them (each array alone), so the same bits.
  // If the unknowns would change, the gather that follows makes all of them anew.
  const bool fused = !bounds_ready_;
  Expanded e{};
  double* const grid_mass = sys.grid_mass.data();
  for (std::size_t j = 0; j < moved_.size(); ++j) {
    const std::size_t k = moved_[j];
    const double mc = heat_capacity_[k];
    if (step_stencils) now[j] = step_stencils[k];
    else now[j].evaluate(grid, p.position[k], p.half_size[k]);
    if (!fused) {
      kept_stencils[k].for_each(indexer_, [&](int i, double w, const mechanics::Vec<Dim>&) {
        sys.grid_mass[static_cast<std::size_t>(i)] -= mc * w;
      });
      now[j].for_each(indexer_, [&](int i, double w, const mechanics::Vec<Dim>&) {
        sys.grid_mass[static_cast<std::size_t>(i)] += mc * w;
      });
      continue;
    }
    const double mct = mc * p.temperature[k];
    const ThermalProperties& m = thermal_properties_of(materials, p.material[k]);
    const double conductance_now = m.conductivity > 0.0 ? p.volume[k] * m.conductivity : 0.0;  // V_p now
    const mechanics::Stencil<Dim, Kernel>& old_st = kept_stencils[k];
    // One particle's terms out (sign −1, its old stencil and conductance) or in (+1, its new ones).
    const auto terms = [&](const mechanics::Stencil<Dim, Kernel>& st, bool is_whole, double conductance, double sign) {
      if (is_whole) {  // S_ip, G_ip and the unknowns of one walk: expand's, add_quick's and M's terms
        const double quick = conductance == 0.0 ? 0.0 : sign * quick_weight(st, conductance);
        double* const sums = next_mct_.data();
        const int* const un = sys.unknown.data();
#if defined(FRICTHERM_WHOLE_ROWS_SSE2)
        if constexpr (Dim == 2) {  // rows packed: the same bits
          refresh_terms_whole(st, indexer_, un, mc, mct, quick, conductance != 0.0, sign < 0.0, grid_mass, sums,
                              quick_sum_.data());
          return;
        }
#endif
        for_each_node(st, indexer_, [&](int i, double w, double gx, double gy, double gz) {
          const auto g = static_cast<std::size_t>(i);
          if (sign < 0.0) {
            grid_mass[g] -= mc * w;
            sums[un[g]] -= mct * w;
          } else {
            grid_mass[g] += mc * w;
            sums[un[g]] += mct * w;
          }
          if (conductance != 0.0) quick_sum_[g] += quick * g_l1<Dim>(gx, gy, gz);
        });
        return;
      }
      st.for_each(indexer_, [&](int i, double w, const mechanics::Vec<Dim>&) {
        if (sign < 0.0) sys.grid_mass[static_cast<std::size_t>(i)] -= mc * w;
        else sys.grid_mass[static_cast<std::size_t>(i)] += mc * w;
      });
      expand<Kernel, false>(st, sys.unknown, e);
      if (sign < 0.0)
        for (int a = 0; a < e.count; ++a) next_mct_[e.unknown[a]] -= mct * e.S[a];
      add_quick(st, conductance, sys, e, sign);
      if (sign > 0.0)
        for (int a = 0; a < e.count; ++a) next_mct_[e.unknown[a]] += mct * e.S[a];
    };
    terms(old_st, whole_[k] != 0, conductance_[k], -1.0);
    restencil(k, kept_stencils[k], now[j], sys.unknown, e);
    conductance_[k] = conductance_now;
    terms(kept_stencils[k], whole_[k] != 0, conductance_now, 1.0);
    quiet_[k] = 0;  // looked at in the next sub-step
    gathered_at_[k] = p.position[k];
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
  StencilVector<Kernel>& kept = stencils_.template of<Kernel>();
  for (std::size_t j = 0; j < moved_.size() && !fused; ++j) {
    const std::size_t k = moved_[j];
    const double mct = heat_capacity_[k] * p.temperature[k];
    // as its last gather: the unknowns have not changed
    if (bounds_ready_) expand<Kernel, true>(kept[k], sys.unknown, e);
    else expand<Kernel, false>(kept[k], sys.unknown, e);
    for (int a = 0; a < e.count; ++a) next_mct_[e.unknown[a]] -= mct * e.S[a];  // its old terms out
    if (bounds_ready_) remove_bounds(k, e);
    add_quick(kept[k], conductance_[k], sys, e, -1.0);
    restencil(k, kept[k], now[j], sys.unknown, e);
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
  if (node_operator_ready_) {  // the sub-steps' list of particles out of K, in particle order (moved_ is)
    std::vector<std::size_t>& merged = out_of_k_merge_;
    merged.clear();
    std::set_union(out_of_k_.begin(), out_of_k_.end(), moved_.begin(), moved_.end(), std::back_inserter(merged));
    out_of_k_.swap(merged);
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

template class ExplicitConduction<2>;
template class ExplicitConduction<3>;

}  // namespace frictherm::coupling
