// The decomposed gather of a window (frictherm/coupling/decomposed_heat.hpp): M_i and T_i (eq. 38), the
// kept entries S_ip and G'_ip and the bounds of λ_max(M⁻¹K), from the particles' current stencils or,
// with coupling.reuse_distance, from those where each was last gathered, and the reuse's decisions:
// the serial Coupler::matrix_free_window with ExplicitConduction::refresh (explicit_conduction.cpp),
// its counts and maxima over all ranks so that every rank makes the serial run's decision.
//
// The serial refresh keeps each heat-holding particle's stencil, V_p k_p and Rayleigh bound term from
// its last gather and gathers again (at its position now) only a particle that moved more than
// max_shift = reuse_distance · min cell size along some axis since; more than a quarter of them moved, a
// change of the unknowns, or no reusable gather: a full gather. Here each particle carries its gather
// position, V_p and Rayleigh term in particle scalars (they migrate with it), and every window gathers
// from the stencils at the gather positions: the serial kept S_ip, G'_ip, M_i and bounds to round-off
// (its incremental sums regrouped). The bounds as the serial ones: after a gather the quick bound,
// the exact ones (made then with M now) when it allows more than one sub-step; after a refresh the
// quick bound while the exact ones are not made, else the Gershgorin bound with M now and the Rayleigh
// bound from the kept terms times max M_peak / M; a window that keeps everything keeps the bound.
#include <frictherm/coupling/decomposed_heat.hpp>
#include <frictherm/coupling/explicit_conduction.hpp>
#include <frictherm/thermal/stability.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

// Pass 1: M_i and M_i T_i (eq. 38) on the ghosted box, completed at the owners; the unknowns
// (select_unknowns' rule, max over ranks), T_i on them, M_i on the ghosted box. From the stencils `at`
// when given (the reuse: where the particles were last gathered), else the current ones.
template <int Dim>
void DecomposedHeat::gather_mass(mechanics::DecomposedMpm<Dim>& mpm,
                                 const typename mechanics::DecomposedMpm<Dim>::Stencils* at) {
  const MPI_Comm comm = mpm.communicator();
  const std::size_t no = mpm.owned_local_nodes().size(), nl = static_cast<std::size_t>(mpm.local_node_count());
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = at ? *at : mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  const std::vector<double> T = mpm.particle_scalar(scalar_);
  const std::size_t np = T.size();
  capacity_.assign(np, 0.0);
  local_.assign(2 * nl, 0.0);
  double particle_capacity = 0.0;
  for (std::size_t k = 0; k < np; ++k) {
    const ThermalProperties& m = opt_.materials[static_cast<std::size_t>(P.material[k])];
    if (!m.conducts) continue;
    const double mc = P.mass[k] * m.heat_capacity, mct = mc * T[k];
    capacity_[k] = mc;
    particle_capacity += mc;
    for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
      const auto i = static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)]);
      local_[2 * i] += mc * st.S[static_cast<std::size_t>(a)];
      local_[2 * i + 1] += mct * st.S[static_cast<std::size_t>(a)];
    }
  }
  std::vector<double> mass_temp;
  mpm.sum_to_owned(local_, 2, mass_temp);
  double sums[3] = {0.0, particle_capacity, 0.0};  // Σ M_i, Σ m C, max M
  for (std::size_t q = 0; q < no; ++q) sums[0] += mass_temp[2 * q], sums[2] = std::max(sums[2], mass_temp[2 * q]);
  double reduced[2] = {sums[0], sums[1]};
  MPI_Allreduce(MPI_IN_PLACE, reduced, 2, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, &sums[2], 1, MPI_DOUBLE, MPI_MAX, comm);
  if (!(reduced[1] > 0.0)) throw std::invalid_argument("decomposed heat: no particle of a material with thermal properties");
  books_.max_capacity_residual = std::max(books_.max_capacity_residual, std::fabs(reduced[0] - reduced[1]) / reduced[1]);
  threshold_ = opt_.assembly.active_mass_fraction * sums[2];
  M_.assign(no, 0.0);
  T0_.assign(no, 0.0);
  double least[2] = {std::numeric_limits<double>::infinity(), 0.0};  // smallest unknown M, nodes dropped
  for (std::size_t q = 0; q < no; ++q) {
    M_[q] = mass_temp[2 * q];
    if (is_unknown(M_[q])) T0_[q] = mass_temp[2 * q + 1] / M_[q], least[0] = std::min(least[0], M_[q]);
    else if (M_[q] > 0.0) least[1] += 1.0;
  }
  MPI_Allreduce(MPI_IN_PLACE, &least[0], 1, MPI_DOUBLE, MPI_MIN, comm);
  MPI_Allreduce(MPI_IN_PLACE, &least[1], 1, MPI_DOUBLE, MPI_SUM, comm);
  min_unknown_mass_ = least[0];
  books_.dropped_nodes = static_cast<long>(least[1]);
  mpm.owned_to_local(M_, 1, local_M_);  // the same values at every rank's ghosts: the same unknowns
}


// Pass 1 (gather_mass) and pass 2: each heat-holding particle's kept nodes (unknowns), the lumped
// gradients G' and V_p k_p, and the bound of λ_max(M⁻¹K) over all ranks (the smaller of the two bounds
// of ExplicitConduction::keep). What a window and the continuation's first assembly start from. With
// the reuse (gather_volume_ set) also quick_bound()'s bound and the Rayleigh bound of the kept terms
// (rayleigh_kept_, NaN: this gather's), all four in bounds_.
template <int Dim>
double DecomposedHeat::gather_window(mechanics::DecomposedMpm<Dim>& mpm,
                                     const typename mechanics::DecomposedMpm<Dim>::Stencils* at) {
  using Vec = mechanics::Vec<Dim>;
  using GMap = Eigen::Map<Vec>;
  const MPI_Comm comm = mpm.communicator();
  const std::size_t no = mpm.owned_local_nodes().size(), nl = static_cast<std::size_t>(mpm.local_node_count());
  gather_mass(mpm, at);  // pass 1: M_, T0_, local_M_, capacity_
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = at ? *at : mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  const std::size_t np = capacity_.size();
  const std::vector<double>& M = M_;
  auto unknown = [this](double m) { return is_unknown(m); };
  const bool reuse = gather_volume_ != nullptr;
  const std::vector<double>& volume = reuse ? *gather_volume_ : P.volume;
  const std::size_t nc = reuse ? 4 : 2;  // sums per node: Gershgorin, Rayleigh[, quick, kept Rayleigh]
  if (reuse) rayleigh_fresh_.assign(np, 0.0);

  // Pass 2: each heat-holding particle's kept nodes (unknowns), the lumped gradients G' and the two
  // bounds of λ_max(M⁻¹K) of ExplicitConduction::keep (Gershgorin row sums and Cauchy–Schwarz).
  const std::size_t entries = st.node.size();  // at most every stencil entry is kept
  kept_first_.resize(np + 1);
  kept_first_[0] = 0;
  kept_node_.resize(entries);
  kept_S_.resize(entries);
  kept_G_.resize(Dim * entries);
  kept_norm_.resize(entries);
  auto G = [this](std::size_t a) { return GMap(kept_G_.data() + Dim * a); };
  conductance_.assign(np, 0.0);
  local_.assign(nc * nl, 0.0);
  std::size_t kept = 0;
  for (std::size_t k = 0; k < np; ++k) {
    const std::size_t begin = kept;
    if (capacity_[k] > 0.0) {
      double s_kept = 0.0;
      Vec g_dropped = Vec::Zero();
      for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
        const auto ua = static_cast<std::size_t>(a);
        const int i = st.node[ua];
        if (unknown(local_M_[static_cast<std::size_t>(i)])) {
          s_kept += st.S[ua];
          kept_node_[kept] = i;
          kept_S_[kept] = st.S[ua];
          G(kept) = st.G[ua];
          ++kept;
        } else {
          g_dropped += st.G[ua];
        }
      }
      const ThermalProperties& m = opt_.materials[static_cast<std::size_t>(P.material[k])];
      const std::size_t end = kept;
      double quick = 0.0;  // quick_bound()'s V_p k_p A_p, A_p = Σ over the stencil of |G_ip|₁ (pass 1 there)
      if (reuse && m.conductivity > 0.0) {
        for (int a = st.first[k]; a < st.first[k + 1]; ++a) quick += st.G[static_cast<std::size_t>(a)].template lpNorm<1>();
        const double c = volume[k] * m.conductivity;
        for (int a = st.first[k]; a < st.first[k + 1]; ++a)
          local_[nc * static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)]) + 2] +=
              c * quick * st.G[static_cast<std::size_t>(a)].template lpNorm<1>();
        quick *= c;
      }
      if (m.conductivity > 0.0 && end > begin && s_kept > 0.0) {
        const bool lumped = end - begin < static_cast<std::size_t>(st.first[k + 1] - st.first[k]);
        if (lumped)
          for (std::size_t a = begin; a < end; ++a) G(a) += (kept_S_[a] / s_kept) * g_dropped;  // lump
        conductance_[k] = volume[k] * m.conductivity;  // V_p k_p (with the reuse: at its gather)
        if (reuse && lumped)  // quick_bound()'s lumping terms (add_quick_lumping)
          for (std::size_t a = begin; a < end; ++a)
            local_[nc * static_cast<std::size_t>(kept_node_[a]) + 2] += quick * (quick / conductance_[k]) * (kept_S_[a] / s_kept);
        double gsum = 0.0, g2m = 0.0;
        for (std::size_t a = begin; a < end; ++a) {
          const double g = G(a).norm();
          kept_norm_[a] = g;
          gsum += g;
          g2m += g * g / local_M_[static_cast<std::size_t>(kept_node_[a])];
        }
        double kept_rayleigh = 0.0;  // the Rayleigh term the serial refresh keeps (made with M of its time)
        if (reuse) {
          rayleigh_fresh_[k] = conductance_[k] * g2m;
          kept_rayleigh = k < rayleigh_kept_.size() && !std::isnan(rayleigh_kept_[k]) ? rayleigh_kept_[k] : rayleigh_fresh_[k];
        }
        for (std::size_t a = begin; a < end; ++a) {
          const auto i = static_cast<std::size_t>(kept_node_[a]);
          local_[nc * i] += conductance_[k] * kept_norm_[a] * gsum;
          local_[nc * i + 1] += conductance_[k] * g2m;
          if (reuse) local_[nc * i + 3] += kept_rayleigh;
        }
      }
    }
    kept_first_[k + 1] = static_cast<int>(kept);
  }
  std::vector<double> bounds;
  mpm.sum_to_owned(local_, static_cast<int>(nc), bounds);
  double lam[4] = {0.0, 0.0, 0.0, 0.0};  // Gershgorin, Rayleigh, quick, kept Rayleigh: maxima over the unknowns of all ranks
  for (std::size_t q = 0; q < no; ++q) {
    if (!unknown(M[q]) || is_held(q)) continue;  // rows of fixed nodes do not move: λ = 0 (as the serial bounds)
    lam[0] = std::max(lam[0], bounds[nc * q] / M[q]);
    lam[1] = std::max(lam[1], bounds[nc * q + 1]);
    if (reuse) lam[2] = std::max(lam[2], bounds[nc * q + 2] / M[q]), lam[3] = std::max(lam[3], bounds[nc * q + 3]);
  }
  MPI_Allreduce(MPI_IN_PLACE, lam, reuse ? 4 : 2, MPI_DOUBLE, MPI_MAX, comm);
  for (int c = 0; c < 4; ++c) bounds_[c] = lam[c];
  bounds_[2] *= 1.0 + 1e-6;  // as quick_bound()
  return std::min(lam[0], lam[1]);
}

bool DecomposedHeat::matrix_free_allowed() const {
  const thermal::IntegratorOptions& io = opt_.integrator_options;
  return (opt_.integrator == "forward_euler" || opt_.integrator == "auto") && opt_.matrix_free_max_substeps > 0 &&
         !reaction_active() && io.fe_stability_policy == "substep" && io.fe_limit_estimate == "gershgorin";
}

// Coupler::matrix_free_window's decisions with the reuse (reuse_distance > 0): whether the window is
// matrix-free and its sub-steps. Leaves the kept entries, M_ and T0_ of the window: at the gather
// positions (matrix-free) or at the positions now (assembled; the next window gathers anew).
template <int Dim>
bool DecomposedHeat::reuse_window(mechanics::DecomposedMpm<Dim>& mpm, double dt, long& n) {
  const MPI_Comm comm = mpm.communicator();
  const double limit = static_cast<double>(opt_.matrix_free_max_substeps);
  const auto assembled = [&] {  // the assembled path gathers at the positions now, as the serial assemble
    gather_window(mpm);
    reuse_gathered_ = false;
    return false;
  };
  // Far beyond the limit with the last exact bound: no look (the serial skip).
  if (last_lambda_ > 0.0 && !reuse_quick_ && dt / (opt_.fe_safety * 2.0 / last_lambda_) > 2.0 * limit) return assembled();
  if (reuse_scalars_.empty()) {
    for (const char* s : {"_0", "_1", "_2", "_volume", "_rayleigh"})
      if (s[1] != '2' || Dim == 3) reuse_scalars_.push_back(mpm.particle_scalar_index(opt_.reuse_scalar + s));
  }
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data(true);
  const std::size_t np = P.mass.size(), no = M_.size();
  std::vector<double> at(Dim * np);
  for (int d = 0; d < Dim; ++d) {
    const std::vector<double> x = mpm.particle_scalar(reuse_scalars_[static_cast<std::size_t>(d)]);
    for (std::size_t k = 0; k < np; ++k) at[Dim * k + static_cast<std::size_t>(d)] = x[k];
  }
  std::vector<double> volume = mpm.particle_scalar(reuse_scalars_[Dim]);
  std::vector<double> rayleigh = mpm.particle_scalar(reuse_scalars_[Dim + 1]);
  const auto holds = [&](std::size_t k) { return opt_.materials[static_cast<std::size_t>(P.material[k])].conducts; };

  // ExplicitConduction::refresh's decision, its count over all ranks.
  using Conduction = ExplicitConduction<Dim>;
  enum class Refresh { kept, refreshed, regather } r = Refresh::regather;
  std::vector<char> moved(np, 0);
  if (reuse_gathered_) {
    const double shift = opt_.reuse_distance * mpm.grid().cell_size().minCoeff();
    long count = 0;
    for (std::size_t k = 0; k < np; ++k)
      if (Conduction::moved_beyond(P.position.data() + Dim * k, at.data() + Dim * k, shift) && holds(k))
        moved[k] = 1, ++count;
    MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_LONG, MPI_SUM, comm);
    if (count == 0) r = Refresh::kept;
    else if (!Conduction::too_many_moved(static_cast<std::size_t>(count), static_cast<std::size_t>(reuse_holding_)))
      r = Refresh::refreshed;
  }
  // The window's gather from the stencils at the gather positions, the moved particles' (all: a full
  // gather) set to their positions and V_p now with their Rayleigh terms anew.
  const auto gather_at = [&](bool all) {
    rayleigh_kept_.assign(np, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < np; ++k) {
      if (!all && !moved[k]) {
        rayleigh_kept_[k] = rayleigh[k];
        continue;
      }
      for (int d = 0; d < Dim; ++d) at[Dim * k + static_cast<std::size_t>(d)] = P.position[Dim * k + static_cast<std::size_t>(d)];
      volume[k] = P.volume[k];
    }
    gather_volume_ = &volume;
    if (all) {
      gather_window(mpm);  // the current stencils: at the positions now
    } else {
      const typename mechanics::DecomposedMpm<Dim>::Stencils st = mpm.stencils_at(at);
      gather_window(mpm, &st);
    }
    gather_volume_ = nullptr;
  };
  if (r != Refresh::regather) {
    gather_at(false);
    if (r == Refresh::refreshed) {  // the unknowns must stay those of the gather (any rank: a full gather)
      int changed = 0;
      for (std::size_t q = 0; q < no; ++q) changed |= (is_unknown(M_[q]) ? 1.0 : 0.0) != gathered_unknown_[q] ? 1 : 0;
      MPI_Allreduce(MPI_IN_PLACE, &changed, 1, MPI_INT, MPI_MAX, comm);
      if (changed) r = Refresh::regather;
    }
  }
  const auto keep_rayleigh = [&](bool all) {  // the exact bounds' terms as made now (add_bounds)
    for (std::size_t k = 0; k < np; ++k)
      if (all || moved[k]) rayleigh[k] = rayleigh_fresh_[k];
  };
  if (r == Refresh::regather) {
    gather_at(true);
    ++books_.gathers;
    reuse_gathered_ = reuse_quick_ = true;
    reuse_exact_ = false;
    double holding = 0.0;
    for (std::size_t k = 0; k < np; ++k) holding += holds(k) ? 1.0 : 0.0;
    MPI_Allreduce(MPI_IN_PLACE, &holding, 1, MPI_DOUBLE, MPI_SUM, comm);
    reuse_holding_ = holding;
    gathered_unknown_.assign(no, 0.0);
    for (std::size_t q = 0; q < no; ++q) gathered_unknown_[q] = is_unknown(M_[q]) ? 1.0 : 0.0;
    mass_peak_ = M_;
    rayleigh_scale_ = 1.0;
    last_lambda_ = bounds_[2];  // the quick bound first
  } else if (r == Refresh::refreshed) {
    ++books_.refreshes;
    double scale = 1.0;  // max M_peak / M over the unknowns: the stale M of the kept Rayleigh terms
    for (std::size_t q = 0; q < no; ++q) {
      if (gathered_unknown_[q] == 0.0) continue;
      mass_peak_[q] = std::max(mass_peak_[q], M_[q]);
      scale = std::max(scale, mass_peak_[q] / M_[q]);
    }
    MPI_Allreduce(MPI_IN_PLACE, &scale, 1, MPI_DOUBLE, MPI_MAX, comm);
    rayleigh_scale_ = scale;
    reuse_quick_ = !reuse_exact_;
    if (reuse_exact_) keep_rayleigh(false);
    last_lambda_ = reuse_quick_ ? bounds_[2] : std::min(bounds_[0], bounds_[3] * rayleigh_scale_);
  }  // kept: the last bound stays
  const auto substeps = [&](double lam) {
    return thermal::forward_euler_substeps(dt, lam, opt_.fe_safety, opt_.integrator_options.fe_max_dt);
  };
  n = substeps(last_lambda_);
  if (reuse_quick_ && n > 1) {  // the exact bounds (not made since the gather: the quick bound implies it)
    reuse_quick_ = false;
    reuse_exact_ = true;
    mass_peak_ = M_;
    rayleigh_scale_ = 1.0;
    keep_rayleigh(true);
    last_lambda_ = std::min(bounds_[0], bounds_[1]);
    n = substeps(last_lambda_);
  }
  if (r != Refresh::kept) {  // the particles' kept state
    for (int d = 0; d < Dim; ++d) {
      std::vector<double> x(np);
      for (std::size_t k = 0; k < np; ++k) x[k] = at[Dim * k + static_cast<std::size_t>(d)];
      mpm.set_particle_scalar(reuse_scalars_[static_cast<std::size_t>(d)], x);
    }
    mpm.set_particle_scalar(reuse_scalars_[Dim], volume);
  }
  mpm.set_particle_scalar(reuse_scalars_[Dim + 1], rayleigh);
  if (n > opt_.matrix_free_max_substeps) return assembled();
  return true;
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_GATHER(D)                                                                \
  template void DecomposedHeat::gather_mass<D>(mechanics::DecomposedMpm<D>&,                                    \
                                               const typename mechanics::DecomposedMpm<D>::Stencils*);          \
  template double DecomposedHeat::gather_window<D>(mechanics::DecomposedMpm<D>&,                                \
                                                   const typename mechanics::DecomposedMpm<D>::Stencils*);      \
  template bool DecomposedHeat::reuse_window<D>(mechanics::DecomposedMpm<D>&, double, long&);
FRICTHERM_INSTANTIATE_DECOMPOSED_GATHER(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_GATHER(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_GATHER

}  // namespace frictherm::coupling
