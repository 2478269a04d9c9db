// Plastic heat and the map back with the sub-grid relaxation in a decomposed run
// (frictherm/coupling/decomposed_heat.hpp): the serial PlasticHeatSource::collect (heat_sources.cpp)
// and add_nodal_change_to_particles / ExplicitConduction::map_back (thermal_assembly.cpp,
// explicit_conduction.cpp) over this rank's particles, their nodal sums completed at the owners by the
// mechanics' transfers.
#include <frictherm/coupling/decomposed_heat.hpp>

#include <cmath>
#include <cstddef>
#include <vector>

namespace frictherm::coupling {

// After a step: Δw_p = w_p − w_p(handed over) per particle (the handed-over value migrates with the
// particle as a scalar); β Δw_p S_ip on the nodes of its stencil at its position after the step
// (Taylor–Quinney: the stored part (1 − β) stays out), summed at the owners and added to the pending
// heat. sums: this rank's Σ Δw_p over the particles with β > 0 and Σ β Δw_p S_ip.
template <int Dim>
void DecomposedHeat::collect_plastic(mechanics::DecomposedMpm<Dim>& mpm, double sums[2]) {
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  std::vector<double> handed = mpm.particle_scalar(heated_scalar_);
  const std::vector<double>& beta_of = opt_.plastic.taylor_quinney;
  local_.assign(static_cast<std::size_t>(mpm.local_node_count()), 0.0);
  double work = 0.0, heat = 0.0;
  bool changed = false;
  for (std::size_t k = 0; k < handed.size(); ++k) {
    const double dw = P.plastic_work[k] - handed[k];
    if (dw == 0.0) continue;
    handed[k] = P.plastic_work[k];
    changed = true;
    const auto m = static_cast<std::size_t>(P.material[k]);
    const double beta = m < beta_of.size() ? beta_of[m] : 0.0;
    if (beta == 0.0) continue;
    work += dw;
    const double q = beta * dw;
    for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
      const double share = q * st.S[static_cast<std::size_t>(a)];
      local_[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])] += share;
      heat += share;
    }
  }
  if (changed) mpm.set_particle_scalar(heated_scalar_, handed);
  std::vector<double> owned;
  mpm.sum_to_owned(local_, 1, owned);  // collective: every rank, every step
  for (std::size_t u = 0; u < owned.size(); ++u) pending_[u] += owned[u];
  ++books_.exchanges;
  sums[0] = work;
  sums[1] = heat;
}

// T_p += Σ_i S_ip ΔT_i over the particle's kept unknowns (design §4: the increment), then with a
// sub-grid relaxation time τ the blend T_p ← T_p − β (T_p − Σ_i S_ip T_i / Σ_i S_ip), β = 1 − e^{−Δt/τ},
// toward the unknowns' end temperatures (docs/coupling.md "Sub-grid structure"); ghost ΔT_i (and T_i)
// from the owners in one exchange. changes: this rank's Σ_i M_i ΔT_i (owned unknowns) and
// Σ_p m_p C_v,p ΔT_p.
template <int Dim>
void DecomposedHeat::map_back(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& Tn, double dt,
                              std::vector<double>& T, double changes[2]) {
  const bool relax = std::isfinite(opt_.subgrid_relaxation_time);
  const double beta = relax ? -std::expm1(-dt / opt_.subgrid_relaxation_time) : 0.0;
  const int c = relax ? 2 : 1;  // values per node: ΔT_i (and T_i)
  const auto stride = static_cast<std::size_t>(c);
  const std::size_t no = M_.size();
  std::vector<double> owned(stride * no, 0.0);
  double nodal = 0.0;
  for (std::size_t u = 0; u < no; ++u) {
    if (!is_unknown(M_[u])) continue;
    owned[stride * u] = Tn[u] - T0_[u];
    nodal += M_[u] * owned[stride * u];
    if (relax) owned[stride * u + 1] = Tn[u];
  }
  std::vector<double> local;
  mpm.owned_to_local(owned, c, local);
  double particle = 0.0;
  for (std::size_t k = 0; k < T.size(); ++k) {
    double change = 0.0, pic = 0.0, s = 0.0;
    for (int a = kept_first_[k]; a < kept_first_[k + 1]; ++a) {
      const double S = kept_S_[static_cast<std::size_t>(a)];
      const std::size_t i = stride * static_cast<std::size_t>(kept_node_[static_cast<std::size_t>(a)]);
      change += S * local[i];
      if (relax) pic += S * local[i + 1], s += S;
    }
    const double before = T[k], flip = before + change;
    T[k] = (relax && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
    particle += capacity_[k] * (T[k] - before);
  }
  changes[0] = nodal;
  changes[1] = particle;
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(D)                                                             \
  template void DecomposedHeat::collect_plastic<D>(mechanics::DecomposedMpm<D>&, double[2]);                   \
  template void DecomposedHeat::map_back<D>(mechanics::DecomposedMpm<D>&, const std::vector<double>&, double, \
                                            std::vector<double>&, double[2]);
FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES

}  // namespace frictherm::coupling
