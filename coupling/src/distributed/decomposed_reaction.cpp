// The Arrhenius reaction of a decomposed run (issue 32; decomposed_heat.hpp): the serial Coupler's
// reaction (coupler.cpp: assemble's gather_reaction, advance_and_map's scatter_progress; heat_sources.cpp)
// on the decomposed grid and particles.
//
//   gather   m_i = Σ_p S_ip m_p,  λ_i = 1 − Σ_p S_ip m_p (1 − λ_p) / m_i     over the reacting particles,
//            summed at the owners (one sum_to_owned of 2 values per node); Q_i = q m_i on the unknowns
//   scatter  (1 − λ_p) = (1 − λ_p,0) Σ_i S_ip R_i,  R_i = (1 − λ_i) / (1 − λ_i,0) on the unknowns, 1
//            elsewhere (the owners' R_i to the ghosts: one owned_to_local)
//
// λ_p is the particle scalar options.progress_scalar (it migrates and is checkpointed with the swarm);
// λ_p,0 the values at the gather, kept in swarm order (a window and the continuation's intervals do
// not move the particles).
#include <frictherm/coupling/decomposed_heat.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace frictherm::coupling {

template <int Dim>
void DecomposedHeat::reaction_gather(mechanics::DecomposedMpm<Dim>& mpm) {
  if (progress_scalar_ < 0) progress_scalar_ = mpm.particle_scalar_index(opt_.progress_scalar);
  const std::size_t no = mpm.owned_local_nodes().size(), nl = static_cast<std::size_t>(mpm.local_node_count());
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  particle_progress_ref_ = mpm.particle_scalar(progress_scalar_);
  std::vector<double> local(2 * nl, 0.0), owned;
  for (std::size_t k = 0; k < particle_progress_ref_.size(); ++k) {
    if (!opt_.reaction.reacts(P.material[k])) continue;
    const double m = P.mass[k], unreacted = P.mass[k] * (1.0 - particle_progress_ref_[k]);
    for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
      const auto i = static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)]);
      const double S = st.S[static_cast<std::size_t>(a)];
      local[2 * i] += m * S;
      local[2 * i + 1] += unreacted * S;
    }
  }
  mpm.sum_to_owned(local, 2, owned);
  ++books_.exchanges;
  reacting_mass_.assign(no, 0.0);
  nodal_progress_.assign(no, 0.0);
  for (std::size_t u = 0; u < no; ++u) {
    if (!is_unknown(M_[u])) continue;  // on the unknowns, as the serial NodalReaction
    const double gm = owned[2 * u], gu = owned[2 * u + 1];
    reacting_mass_[u] = gm;
    if (gm > 0.0) nodal_progress_[u] = std::clamp(1.0 - gu / gm, 0.0, 1.0);
  }
  nodal_progress_ref_ = nodal_progress_;
}

template <int Dim>
void DecomposedHeat::reaction_scatter(mechanics::DecomposedMpm<Dim>& mpm) {
  const std::size_t no = nodal_progress_.size();
  std::vector<double> ratio(no, 1.0), local_ratio;
  for (std::size_t u = 0; u < no; ++u) {
    if (!is_unknown(M_[u])) continue;
    const double left0 = 1.0 - nodal_progress_ref_[u];
    if (!(left0 > 0.0)) continue;
    ratio[u] = std::clamp((1.0 - nodal_progress_[u]) / left0, 0.0, 1.0);
  }
  mpm.owned_to_local(ratio, 1, local_ratio);
  ++books_.exchanges;
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  std::vector<double> progress = particle_progress_ref_;
  for (std::size_t k = 0; k < progress.size(); ++k) {
    if (!opt_.reaction.reacts(P.material[k])) continue;
    double r = 0.0;
    for (int a = st.first[k]; a < st.first[k + 1]; ++a)
      r += st.S[static_cast<std::size_t>(a)] * local_ratio[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])];
    progress[k] = std::clamp(1.0 - (1.0 - particle_progress_ref_[k]) * r, 0.0, 1.0);
  }
  mpm.set_particle_scalar(progress_scalar_, progress);
}

double DecomposedHeat::max_reaction_progress() const {
  double x = 0.0;  // the serial column: 0 without particles
  if (opt_.reaction.enabled) {
    const int index = mpm3_ ? mpm3_->particle_scalar_index(opt_.progress_scalar)
                            : mpm2_->particle_scalar_index(opt_.progress_scalar);
    for (double l : mpm3_ ? mpm3_->particle_scalar(index) : mpm2_->particle_scalar(index)) x = std::max(x, l);
  }
  MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_MAX, communicator());
  return x;
}

double DecomposedHeat::particle_reaction_heat() const {
  double m = 0.0;
  if (opt_.reaction.enabled) {
    const int index = mpm3_ ? mpm3_->particle_scalar_index(opt_.progress_scalar)
                            : mpm2_->particle_scalar_index(opt_.progress_scalar);
    const std::vector<double> lam = mpm3_ ? mpm3_->particle_scalar(index) : mpm2_->particle_scalar(index);
    const mechanics::DecomposedLocalParticles P = local_particles();
    for (std::size_t k = 0; k < lam.size(); ++k)
      if (opt_.reaction.reacts(P.material[k])) m += P.mass[k] * lam[k];
  }
  MPI_Allreduce(MPI_IN_PLACE, &m, 1, MPI_DOUBLE, MPI_SUM, communicator());
  return opt_.reaction.kinetics.specific_heat_of_reaction * m;
}

#define FRICTHERM_DECOMPOSED_REACTION(D)                                                       \
  template void DecomposedHeat::reaction_gather<D>(mechanics::DecomposedMpm<D>&);              \
  template void DecomposedHeat::reaction_scatter<D>(mechanics::DecomposedMpm<D>&);
FRICTHERM_DECOMPOSED_REACTION(2)
FRICTHERM_DECOMPOSED_REACTION(3)
#undef FRICTHERM_DECOMPOSED_REACTION

}  // namespace frictherm::coupling
