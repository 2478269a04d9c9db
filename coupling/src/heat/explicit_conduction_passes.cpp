// The forward-Euler sub-steps of a matrix-free conduction window and the change mapped back to the
// particles (explicit_conduction.hpp; Nairn et al. 2018 eqs. 37–38), with the stencils of the gather
// (explicit_conduction.cpp), and the re-projection of the kept eq. 38 sums (reproject).
#include <array>
#include "explicit_conduction_detail.hpp"

namespace frictherm::coupling {

using namespace explicit_detail;

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

#if defined(FRICTHERM_WHOLE_ROWS_SSE2)
template <int Dim>
template <int K>
bool ExplicitConduction<Dim>::flux_whole_rows(const OutOfKStencil& c, const double* t, double conductance, double* f) {
  // The per-particle sub-step of a whole particle out of K (eq. 37, f_i = −V k G'·∇T) with two nodes
  // of a row in one register: min/max lane by lane (the same extremes: only quiet_spread reads them),
  // the products G_ip T_i packed and added to g one by one in node order, each f_i's own update packed.
  static_assert(K == 2 || K == 3, "rows of 2 or 3 nodes");
  constexpr int rows = Dim == 2 ? K : K * K;
  __m128d lo2 = _mm_set1_pd(std::numeric_limits<double>::infinity()), hi2 = _mm_set1_pd(-std::numeric_limits<double>::infinity());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  double g[3] = {0.0, 0.0, 0.0};
  for (int r = 0; r < rows; ++r) {
    const int a = r * K;
    const double* tr = t + c.unknown[a];  // the row's unknowns: c.unknown[a] + 0, 1 (, 2)
    const __m128d t01 = _mm_loadu_pd(tr);
    lo2 = _mm_min_pd(t01, lo2);  // t < lo ? t : lo, as std::min(lo, t)
    hi2 = _mm_max_pd(t01, hi2);
    double t2 = 0.0;
    if constexpr (K == 3) {
      t2 = tr[2];
      lo = std::min(lo, t2);
      hi = std::max(hi, t2);
    }
    for (int d = 0; d < Dim; ++d) {
      const __m128d p = _mm_mul_pd(_mm_loadu_pd(&c.G[d][a]), t01);
      g[d] += _mm_cvtsd_f64(p);
      g[d] += _mm_cvtsd_f64(_mm_unpackhi_pd(p, p));
      if constexpr (K == 3) g[d] += c.G[d][a + 2] * t2;
    }
  }
  lo = std::min(lo, std::min(_mm_cvtsd_f64(lo2), _mm_cvtsd_f64(_mm_unpackhi_pd(lo2, lo2))));
  hi = std::max(hi, std::max(_mm_cvtsd_f64(hi2), _mm_cvtsd_f64(_mm_unpackhi_pd(hi2, hi2))));
  if (quiet_spread(lo, hi)) return true;
  for (int d = 0; d < Dim; ++d) g[d] *= conductance;
  const __m128d g0 = _mm_set1_pd(g[0]), g1 = _mm_set1_pd(g[1]), g2 = _mm_set1_pd(g[2]);
  for (int r = 0; r < rows; ++r) {  // f_i −= G·g as scatter_whole sums it: (x x' + y y') + z z'
    const int a = r * K;
    double* fr = f + c.unknown[a];
    __m128d dot = _mm_add_pd(_mm_mul_pd(_mm_loadu_pd(&c.G[0][a]), g0), _mm_mul_pd(_mm_loadu_pd(&c.G[1][a]), g1));
    if constexpr (Dim == 3) dot = _mm_add_pd(dot, _mm_mul_pd(_mm_loadu_pd(&c.G[2][a]), g2));
    _mm_storeu_pd(fr, _mm_sub_pd(_mm_loadu_pd(fr), dot));
    if constexpr (K == 3) {
      double dot2 = c.G[0][a + 2] * g[0] + c.G[1][a + 2] * g[1];
      if constexpr (Dim == 3) dot2 += c.G[2][a + 2] * g[2];
      fr[2] -= dot2;
    }
  }
  return true;
}
#endif

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
  const int threads = assembly_detail::explicit_handoff_threads(holds_heat_.size());
  const int nodes = static_cast<int>(sys.unknown.size());
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  // With the stencils kept, K at node level (use_node_operator) for every sub-step the gather's f_i
  // do not serve: made once after a gather, kept up to date by refresh().
  const bool node_level = node_operator_on_ && stencils_kept_ && (substeps > 1 || !force_ready);
  if (node_level && !node_operator_ready_) {
    assemble_node_operator<Kernel>(sys, threads);
    flux_temperature_.resize(0);  // every f_i made anew with it
  }
  for (long s = 0; s < substeps; ++s) {
    if (force_ready) {
      force_ready = false;
      T.array() += h * (force_.array() + q.array()) / sys.mass.array();  // forward Euler, packed by Eigen: the same operations
      for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
      continue;
    }
    if (node_level) {
      // f_i anew where a node within reach changed since the last sub-step (a refresh marks the rows
      // it changed); the other rows' f_i stand, as the quiet particles of the pass below.
      const bool first = flux_temperature_.size() != n;
      count_changed(sys.unknown, [&](int u) { return first || T[u] != flux_temperature_[u]; });
      flux_temperature_ = T;
      node_operator_force(sys, T, threads);
      force_ = node_force_;
      // The particles out of K (moved since the gather): their fluxes as the per-particle pass below
      // makes them (quiet ones left out), in particle order.
      // (Out of K: taken out by a refresh, or not in it at the assembly, where every heat-holding
      // particle with V_p k_p != 0 joined it; only a refresh changes V_p k_p, and it lists the particle.)
      const auto out_of_k_flux = [&](std::size_t k) { return holds_heat_[k] && !in_node_k_[k] && conductance_[k] != 0.0; };
      if (threads <= 1) {
        // One thread: a whole particle's unknowns and G_ip kept from its first sub-step out of K
        // (out_of_k_stencil): look_whole and scatter_whole's sums from them, in the same order.
        Expanded e{};
        double* const f = force_.data();
        const double* const t = T.data();
        constexpr int nodes_of = mechanics::Stencil<Dim, Kernel>::node_count;
        for (std::size_t k : out_of_k_) {  // in order, as the list the threads take below
          if (!out_of_k_flux(k)) continue;
          if (!whole_[k]) {
            expand<Kernel, true>(stencils[k], sys.unknown, e);
            if (!e.reaches() || quiet_temperatures(e, T)) continue;
            mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
            for (int a = 0; a < e.count; ++a) grad += e.g(a) * T[e.unknown[a]];
            grad *= conductance_[k];
            for (int a = 0; a < e.count; ++a) force_[e.unknown[a]] -= e.g(a).dot(grad);
            continue;
          }
          const int slot = k < out_of_k_slot_.size() ? out_of_k_slot_[k] : -1;  // made: read in place
          const OutOfKStencil& c = slot >= 0 && out_of_k_stencils_[static_cast<std::size_t>(slot)].made
                                       ? out_of_k_stencils_[static_cast<std::size_t>(slot)]
                                       : out_of_k_stencil(k, stencils[k], sys.unknown);
          if (!c.reaches) continue;
#if defined(FRICTHERM_WHOLE_ROWS_SSE2)
          if (flux_whole_rows<Kernel::K>(c, t, conductance_[k], f)) continue;
#endif
          double lo = std::numeric_limits<double>::infinity(), hi = -lo;
          double g0 = 0.0, g1 = 0.0, g2 = 0.0;
          for (int a = 0; a < nodes_of; ++a) {
            const double ta = t[c.unknown[a]];
            lo = std::min(lo, ta);
            hi = std::max(hi, ta);
            g0 += c.G[0][a] * ta;
            g1 += c.G[1][a] * ta;
            if constexpr (Dim == 3) g2 += c.G[Dim - 1][a] * ta;
          }
          if (quiet_spread(lo, hi)) continue;
          const double kc = conductance_[k];
          g0 *= kc;
          g1 *= kc;
          g2 *= kc;
          for (int a = 0; a < nodes_of; ++a) {  // G·g as scatter_whole sums it
            double dot = c.G[0][a] * g0 + c.G[1][a] * g1;
            if constexpr (Dim == 3) dot += c.G[Dim - 1][a] * g2;
            f[c.unknown[a]] -= dot;
          }
        }
      } else {
        listed_.clear();
        for (std::size_t k : out_of_k_)
          if (out_of_k_flux(k)) listed_.push_back(k);
      scatter_by_node_ranges<Expanded>(threads, nodes, listed_, [&](std::size_t k, const NodeRange& r, Expanded& e) {
        const mechanics::Stencil<Dim, Kernel>& st = stencils[k];
        if (!r.meets(node_span(st, indexer_))) return;
        if (threads <= 1 && whole_[k]) {  // the stencil walked directly, the same sums
          double lo, hi, s_kept;
          mechanics::Vec<Dim> grad;
          look_whole(st, sys.unknown, T.data(), lo, hi, s_kept, grad);
          if (!(s_kept > 0.0) || quiet_spread(lo, hi)) return;
          grad *= conductance_[k];
          scatter_whole(st, sys.unknown, grad, force_.data());
          return;
        }
        expand<Kernel, true>(st, sys.unknown, e);
        if (!e.reaches() || quiet_temperatures(e, T)) return;
        mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
        for (int a = 0; a < e.count; ++a) grad += e.g(a) * T[e.unknown[a]];
        grad *= conductance_[k];
        for (int a = 0; a < e.count; ++a)
          if (r.holds(sys.grid_node[static_cast<std::size_t>(e.unknown[a])])) force_[e.unknown[a]] -= e.g(a).dot(grad);
      });
      }
      T.array() += h * (force_.array() + q.array()) / sys.mass.array();  // forward Euler, packed by Eigen: the same operations
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
        if (whole_[k]) {  // no lumping: the stencil walked directly, the same sums
          double lo, hi, s_kept;
          mechanics::Vec<Dim> grad;
          look_whole(stencils[k], sys.unknown, T.data(), lo, hi, s_kept, grad);
          quiet_[k] = !(s_kept > 0.0) || quiet_spread(lo, hi);
          if (quiet_[k]) continue;
          grad *= conductance_[k];
          scatter_whole(stencils[k], sys.unknown, grad, force_.data());
          continue;
        }
        expand<Kernel, true>(stencils[k], sys.unknown, e);  // the unknowns and S of expand<false>, and G'
        if (!e.reaches()) {
          quiet_[k] = 1;
          continue;
        }
        quiet_[k] = quiet_temperatures(e, T);
        if (quiet_[k]) continue;
        mechanics::Vec<Dim> grad = mechanics::Vec<Dim>::Zero();
        for (int a = 0; a < e.count; ++a) grad += e.g(a) * T[e.unknown[a]];
        grad *= conductance_[k];
        for (int a = 0; a < e.count; ++a) force_[e.unknown[a]] -= e.g(a).dot(grad);
      }
      T.array() += h * (force_.array() + q.array()) / sys.mass.array();  // forward Euler, packed by Eigen: the same operations
      for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
      continue;
    }
    // Each particle's look (threads by particles), then the fluxes of those that carry flux,
    // scattered by node ranges in particle order.
    particle_scratch_.assign(holds_heat_.size(), 0.0);  // 1: carries flux
    mechanics::parallel_region(threads, [&] {
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
      quiet_[k] = quiet_temperatures(e, T);
      if (!quiet_[k]) particle_scratch_[k] = 1.0;
    }
    });
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
    T.array() += h * (force_.array() + q.array()) / sys.mass.array();  // forward Euler, packed by Eigen: the same operations
    for (const FixedNode& f : fixed) T[f.unknown] = f.temperature;
  }
}

template <int Dim>
template <class Kernel>
const typename ExplicitConduction<Dim>::OutOfKStencil& ExplicitConduction<Dim>::out_of_k_stencil(
    std::size_t k, const mechanics::Stencil<Dim, Kernel>& st, const std::vector<int>& unknown) {
  if (out_of_k_slot_.size() != holds_heat_.size()) out_of_k_slot_.assign(holds_heat_.size(), -1);
  int& slot = out_of_k_slot_[k];
  if (slot < 0) {
    slot = static_cast<int>(out_of_k_stencils_.size());
    out_of_k_stencils_.emplace_back();
  }
  OutOfKStencil& c = out_of_k_stencils_[static_cast<std::size_t>(slot)];
  if (c.made) return c;
  c.made = true;
  double s = 0.0;
  int a = 0;
  for_each_unknown_whole(st, indexer_, unknown.data(), [&](int u, double w, double gx, double gy, double gz) {
    s += w;
    c.unknown[a] = u;
    c.G[0][a] = gx;
    c.G[1][a] = gy;
    if constexpr (Dim == 3) c.G[Dim - 1][a] = gz;
    ++a;
  });
  c.reaches = s > 0.0;
  return c;
}

template <int Dim>
template <int K>
const unsigned char* ExplicitConduction<Dim>::changed_in_box(int nodes) {
  // Along x from the prefix counts, as counts_in_rows_from tests a row (the K nodes from g; clipped at
  // the end of the numbering, where no stencil starts), then OR-ed over K rows along each further
  // axis (zero padding past the end): reached[g] = 1 exactly when counts_in_rows_from(g) is true.
  const mechanics::IVec<Dim>& sd = indexer_.stride;
  int pad = 0;
  for (int d = 1; d < Dim; ++d) pad += (K - 1) * sd[d];
  const int span = (K - 1) * sd[0] + 1;
  const int* before = changed_before_.data();
  for (std::vector<unsigned char>& r : reach_) r.assign(static_cast<std::size_t>(nodes + pad), 0);
  unsigned char* x = reach_[0].data();
  const int full = std::max(0, nodes - span);  // runs that end inside the numbering (a loop without the clip)
  for (int g = 0; g < full; ++g) x[g] = before[g + span] != before[g];
  for (int g = full; g < nodes; ++g) x[g] = before[nodes] != before[g];
  for (int d = 1; d < Dim; ++d) {
    unsigned char* y = reach_[d % 2].data();
    const unsigned char* from = reach_[(d - 1) % 2].data();
    const int s1 = sd[d];
    for (int g = 0; g < nodes; ++g) {
      unsigned char v = from[g];
      for (int j = 1; j < K; ++j) v |= from[g + j * s1];
      y[g] = v;
    }
  }
  return reach_[(Dim - 1) % 2].data();
}

template <int Dim>
double ExplicitConduction<Dim>::map_back(mechanics::Particles<Dim>& p, const NodalThermalSystem& sys,
                                         const Eigen::VectorXd& delta, double beta, const Eigen::VectorXd* end,
                                         const std::vector<typename FacePull<Dim>::Held>* held) {
  if (heat_capacity_.size() != p.size())
    throw std::logic_error("ExplicitConduction::map_back: the particles changed since the gather");
  if (next_mct_.size() != static_cast<Eigen::Index>(sys.size()))
    throw std::logic_error("ExplicitConduction::map_back: no re-projection for these unknowns");
  face_pull_.build(delta.data(), end && beta > 0.0 ? end->data() : nullptr, sys.size(), held);
  face_heat_ = 0.0;
  mechanics::dispatch_shape(kind_, [&](auto kernel) { map_back_with<decltype(kernel)>(p, sys, delta, beta, end); });
  return face_heat_;
}

template <int Dim>
template <class Kernel>
void ExplicitConduction<Dim>::map_back_with(mechanics::Particles<Dim>& p, const NodalThermalSystem& sys,
                                            const Eigen::VectorXd& delta, double beta, const Eigen::VectorXd* end) {
  const bool relax = end && beta > 0.0;
  // Held nodes pull their particles towards the face (FacePull, fixed_temperature.hpp).
  const bool pull = face_pull_.active();
  const double* const dl = face_pull_.increment(delta.data());
  // Unknowns whose temperature changed in the window, as a prefix count by grid node: a particle with
  // none among its nodes keeps its temperature (ΔT_p = 0 exactly) and is passed over.
  count_changed(sys.unknown, [&](int u) {
    return relax || delta[u] != 0.0 || (pull && face_pull_.held(static_cast<std::size_t>(u)));
  });
  const mechanics::Stencil<Dim, Kernel>* stencils = window_stencils<Kernel>();
  const int threads = assembly_detail::explicit_handoff_threads(p.size());
  // The eq. 38 sums of the next reproject(): only a refresh can lead to one, and without kept
  // stencils the next window gathers anew (and sums them anew), so they are not kept up to date.
  const bool keep_sums = stencils_kept_;
  // A particle's temperature after the window: T_p + Σ S_ip ΔT_i (design §4: the increment, not the
  // nodal value) plus the held nodes' pull, relaxed towards Σ S_ip T_i / Σ S_ip with the sub-grid blend β.
  const auto blend = [&](double before, double dT, double pulled, double pic, double s) {
    const double flip = pull ? before + (dT + pulled) : before + dT;
    return (relax && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
  };
  const double* const te = relax ? face_pull_.end(end->data()) : nullptr;
  // The pull's change of particle k (0 without held nodes), the heat it brings and its held nodes'
  // term of the blend's Σ S_ip T_i (FacePull).
  const auto pulled_change = [&](const typename FacePull<Dim>::Sums& q, std::size_t k, double& heat, double& pic) {
    if (!pull || q.weight == 0.0) return 0.0;
    const double change = FacePull<Dim>::change(q, p.temperature[k], p.position[k]);
    heat += heat_capacity_[k] * change;
    if (relax) pic += FacePull<Dim>::blend_target(q, p.temperature[k], change);
    return change;
  };
  const auto new_temperature = [&](double before, const Expanded& c, std::size_t k, double& heat) {
    double dT = 0.0;
    for (int a = 0; a < c.count; ++a) dT += c.S[a] * dl[c.unknown[a]];
    typename FacePull<Dim>::Sums q;
    if (pull)
      for (int a = 0; a < c.count; ++a) face_pull_.add(q, static_cast<std::size_t>(c.unknown[a]), c.S[a]);
    double pic = 0.0, s = 0.0;
    if (relax) {
      for (int a = 0; a < c.count; ++a) {
        pic += c.S[a] * te[c.unknown[a]];
        s += c.S[a];
      }
    }
    const double pulled = pulled_change(q, k, heat, pic);
    return blend(before, dT, pulled, pic, s);
  };
  // One thread, a particle whose stencil is not whole (lumped onto its unknowns): both one-thread
  // loops below take it here (the same numbers whether the window pulls or blends or not).
  const auto map_back_lumped = [&](std::size_t k, Expanded& c) {
    expand<Kernel, false>(stencils[k], sys.unknown, c);
    if (c.count == 0) return;  // reaches no unknown
    const double before = p.temperature[k];
    const double T = new_temperature(before, c, k, face_heat_);
    if (T == before) return;
    p.temperature[k] = T;
    if (!keep_sums) return;
    const double change = heat_capacity_[k] * (T - before);
    for (int a = 0; a < c.count; ++a) next_mct_[c.unknown[a]] += change * c.S[a];
  };
  // Each particle's new temperature (threads by particles), then the changes of the eq. 38 sums,
  // scattered by node ranges in particle order.
  if (threads <= 1 && !pull && !relax) {
    // The usual window (no held face, no sub-grid blend): T_p + Σ S_ip ΔT_i, as blend() gives it
    // then. A whole particle's S_ip and unknowns are kept from the first walk for the second (the
    // same products, so the same sums), and the loop has no per-node tests.
    Expanded c{};
    const int* un = sys.unknown.data();
    double* const temperature = p.temperature.data();
    double* const sums = next_mct_.data();
    const int* first = first_node_.data();
    const unsigned char* reached = changed_in_box<Kernel::K>(static_cast<int>(sys.unknown.size()));
    for (std::size_t k = 0; k < p.size(); ++k) {
      // any_changed, from the stencil's first grid node kept with it: one flag (a particle that holds
      // no heat has its first node past the grid, where no flag is set)
      if (!reached[first[k]]) continue;
      const double before = temperature[k];
      if (whole_[k]) {
#if defined(FRICTHERM_WHOLE_ROWS_SSE2)
        // Σ S_ip ΔT_i and the eq. 38 sums' m_p C_v,p ΔT_p S_ip, two nodes of a row at a time
        // (dot_whole_rows, add_whole_rows: the same products and sums in the same order).
        WholeRows<Dim, Kernel::K> rows;
        const double after = before + dot_whole_rows(stencils[k], first[k], indexer_, un, dl, rows);
        if (after == before) continue;
        temperature[k] = after;
        if (keep_sums) add_whole_rows(rows, heat_capacity_[k] * (after - before), sums);
        continue;
#else
        constexpr int nodes = mechanics::Stencil<Dim, Kernel>::node_count;
        double w[nodes];
        int at[nodes];
        int a = 0;
        double dT = 0.0;
        for_each_unknown_whole_from(stencils[k], first[k], indexer_, un, [&](int u, double s, double, double, double) {
          dT += s * dl[u];
          w[a] = s;
          at[a] = u;
          ++a;
        });
        const double T = before + dT;
        if (T == before) continue;
        temperature[k] = T;
        if (!keep_sums) continue;
        const double change = heat_capacity_[k] * (T - before);
        for (int b = 0; b < nodes; ++b) sums[at[b]] += change * w[b];
        continue;
#endif
      }
      map_back_lumped(k, c);
    }
    return;
  }
  if (threads <= 1) {  // one pass: the same numbers in the same order, no lists
    Expanded c{};
    const int* un = sys.unknown.data();
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (!holds_heat_[k] || !any_changed(stencils[k])) continue;
      if (whole_[k]) {  // no lumping: the stencil walked directly, the same sums
        double dT = 0.0, pic = 0.0, s = 0.0;
        typename FacePull<Dim>::Sums q;
        for_each_unknown_whole(stencils[k], indexer_, un, [&](int u, double w, double, double, double) {
          dT += w * dl[u];
          if (pull) face_pull_.add(q, static_cast<std::size_t>(u), w);
          if (relax) {
            pic += w * te[u];
            s += w;
          }
        });
        const double before = p.temperature[k];
        const double pulled = pulled_change(q, k, face_heat_, pic);
        const double T = blend(before, dT, pulled, pic, s);
        if (T == before) continue;
        p.temperature[k] = T;
        if (!keep_sums) continue;
        const double change = heat_capacity_[k] * (T - before);
        for_each_unknown_whole(stencils[k], indexer_, un, [&](int u, double w, double, double, double) { next_mct_[u] += change * w; });
        continue;
      }
      map_back_lumped(k, c);
    }
    return;
  }
  particle_scratch_.assign(p.size(), 0.0);  // m_p C_v,p ΔT_p of the particles that changed
  std::vector<unsigned char>& changed = quiet_changed_;
  changed.assign(p.size(), 0);
  double face_heat = 0.0;
  mechanics::parallel_region(threads, [&] {
  Expanded c{};
  // Each thread's own sum, added below (a reduction clause on this orphaned loop would name a variable
  // the lambda captures, which clang refuses); on one thread 0 + the same sum, as the clause gave.
  double my_face_heat = 0.0;
#pragma omp for schedule(static)
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!holds_heat_[k] || !any_changed(stencils[k])) continue;
    expand<Kernel, false>(stencils[k], sys.unknown, c);
    if (c.count == 0) continue;  // reaches no unknown
    const double before = p.temperature[k];
    const double T = new_temperature(before, c, k, my_face_heat);
    if (T == before) continue;  // unchanged (no heat reached its nodes): its eq. 38 terms stand
    p.temperature[k] = T;
    particle_scratch_[k] = heat_capacity_[k] * (T - before);
    changed[k] = 1;
  }
#pragma omp atomic
  face_heat += my_face_heat;
  });
  face_heat_ = face_heat;
  if (!keep_sums) return;
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

template <int Dim>
void ExplicitConduction<Dim>::reproject(const mechanics::Particles<Dim>& p, NodalThermalSystem& sys) {
  if (heat_capacity_.size() != p.size()) throw std::logic_error("ExplicitConduction::reproject: no gather for these particles");
  const auto n = static_cast<Eigen::Index>(sys.size());
  if (next_mct_.size() != n) throw std::logic_error("ExplicitConduction::reproject: the sums are of other unknowns");
  first_force_ready_ = false;
  // The eq. 38 sums, kept with the particles' temperatures by the gather, refresh and map_back.
  for (Eigen::Index u = 0; u < n; ++u) sys.temperature[u] = next_mct_[u] / sys.mass[u];
}

#define FRICTHERM_INSTANTIATE_EXPLICIT_PASSES(D)                                                                    \
  template Eigen::VectorXd ExplicitConduction<D>::advance(const NodalThermalSystem&, const Eigen::VectorXd&,      \
                                                          const Eigen::VectorXd&, const std::vector<FixedNode>&,  \
                                                          double, long);                                          \
  template double ExplicitConduction<D>::map_back(mechanics::Particles<D>&, const NodalThermalSystem&,            \
                                                const Eigen::VectorXd&, double, const Eigen::VectorXd*,         \
                                                const std::vector<FacePull<D>::Held>*);           \
  template void ExplicitConduction<D>::reproject(const mechanics::Particles<D>&, NodalThermalSystem&);
FRICTHERM_INSTANTIATE_EXPLICIT_PASSES(2)
FRICTHERM_INSTANTIATE_EXPLICIT_PASSES(3)
#undef FRICTHERM_INSTANTIATE_EXPLICIT_PASSES

}  // namespace frictherm::coupling
