// Plastic heat and the map back with the sub-grid relaxation in a decomposed run
// (frictherm/coupling/decomposed_heat.hpp): the serial PlasticHeatSource::collect (heat_sources.cpp)
// and add_nodal_change_to_particles / ExplicitConduction::map_back (thermal_assembly.cpp,
// explicit_conduction.cpp) over this rank's particles, their nodal sums completed at the owners by the
// mechanics' transfers.
#include <frictherm/coupling/decomposed_heat.hpp>
#include <frictherm/coupling/fixed_temperature.hpp>

#include <array>
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

// T_p += Σ_i S_ip ΔT_i over the particle's kept unknowns (design §4: the increment; held nodes pull
// their particles towards the face instead, FacePull in fixed_temperature.hpp, with the serial rule
// collect_face_pull_nodes), then with a sub-grid relaxation time τ the blend
// T_p ← T_p − β (T_p − Σ_i S_ip T_i / Σ_i S_ip), β = 1 − e^{−Δt/τ}, toward the unknowns' end
// temperatures (docs/coupling.md "Sub-grid structure"); ghost values from the owners in one exchange
// (two with fixed faces: the owners first read T_i of their held nodes' inward neighbours, which may
// be ghosts). changes: this rank's Σ_i M_i ΔT_i (owned unknowns) and Σ_p m_p C_v,p ΔT_p.
template <int Dim>
void DecomposedHeat::map_back(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& Tn, double dt,
                              std::vector<double>& T, double changes[2], bool from_gathered) {
  const bool relax = std::isfinite(opt_.subgrid_relaxation_time);
  const double beta = relax ? -std::expm1(-dt / opt_.subgrid_relaxation_time) : 0.0;
  const bool pull = !opt_.fixed_faces.empty() && from_gathered;
  // Values per node: ΔT_i (T_face − g·x_i at a held node), T_i with the relaxation, then with fixed
  // faces 1 at a held node and g_i.
  const int c = 1 + (relax ? 1 : 0) + (pull ? 1 + Dim : 0);
  const auto stride = static_cast<std::size_t>(c);
  const std::size_t held_at = relax ? 2 : 1;
  const std::size_t no = M_.size();
  std::vector<double> owned(stride * no, 0.0);
  double nodal = 0.0;
  for (std::size_t u = 0; u < no; ++u) {
    if (!is_unknown(M_[u])) continue;
    owned[stride * u] = Tn[u] - T0_[u];
    nodal += M_[u] * owned[stride * u];
    if (relax) owned[stride * u + 1] = Tn[u];
  }
  if (pull) {
    std::vector<typename FacePull<Dim>::Held>& held_nodes = [this]() -> auto& {
      if constexpr (Dim == 2) return held_nodes_2_;
      else return held_nodes_3_;
    }();
    mpm.owned_to_local(Tn, 1, local_T_);
    const std::array<int, 2 * Dim> own = mpm.owned_nodes(), box = mpm.ghosted_nodes();
    const std::vector<int>& local_of = mpm.owned_local_nodes();
    const mechanics::Grid<Dim>& grid = mpm.grid();
    const auto lattice_along = [&own](std::size_t u, int axis) {  // as select_fixed_nodes
      for (int d = 0; d < axis; ++d) u /= static_cast<std::size_t>(own[2 * d + 1] - own[2 * d]);
      const auto extent = static_cast<std::size_t>(own[2 * axis + 1] - own[2 * axis]);
      return own[2 * axis] + static_cast<int>(u % extent) - mechanics::Grid<Dim>::ghost;
    };
    const auto inward = [&](std::size_t u, int axis, bool upper, double& t_in, double& dx) {
      int step = 1;  // the local numbering is x fastest over the ghosted box
      for (int d = 0; d < axis; ++d) step *= box[2 * d + 1] - box[2 * d];
      const int l = local_of[u] + (upper ? -step : step);
      if (l < 0 || static_cast<std::size_t>(l) >= local_M_.size() || !is_unknown(local_M_[static_cast<std::size_t>(l)]))
        return false;
      t_in = local_T_[static_cast<std::size_t>(l)];
      dx = upper ? -grid.cell_size()[axis] : grid.cell_size()[axis];
      return true;
    };
    const auto position = [&](std::size_t u, int a) { return grid.lo()[a] + grid.cell_size()[a] * lattice_along(u, a); };
    collect_face_pull_nodes<Dim>(opt_.fixed_faces, grid.cells(), no, lattice_along, inward, position, held_nodes);
    for (const typename FacePull<Dim>::Held& h : held_nodes) {
      const auto u = static_cast<std::size_t>(h.unknown);
      if (!is_unknown(M_[u])) continue;  // a window holds the face nodes that are unknowns
      for (int d = 0; d < Dim; ++d)
        owned[stride * u + held_at + 1 + static_cast<std::size_t>(d)] = h.gradient[static_cast<std::size_t>(d)];
      nodal -= M_[u] * owned[stride * u];  // booked as the heat its pull gives (below)
      owned[stride * u] = FacePull<Dim>::offset(h);
      owned[stride * u + held_at] = 1.0;
      if (relax) owned[stride * u + 1] = 0.0;  // the blend's held term is the pull's target (FacePull::end)
    }
  }
  std::vector<double> local;
  mpm.owned_to_local(owned, c, local);
  mechanics::DecomposedLocalParticles P;
  if (pull) P = mpm.local_particle_data(true);
  double particle = 0.0;
  for (std::size_t k = 0; k < T.size(); ++k) {
    double change = 0.0, pic = 0.0, s = 0.0;
    typename FacePull<Dim>::Sums q;  // the held nodes' sums, from the exchanged channels
    for (int a = kept_first_[k]; a < kept_first_[k + 1]; ++a) {
      const double S = kept_S_[static_cast<std::size_t>(a)];
      const std::size_t i = stride * static_cast<std::size_t>(kept_node_[static_cast<std::size_t>(a)]);
      if (relax) pic += S * local[i + 1], s += S;
      if (pull && local[i + held_at] != 0.0) {  // a held node: its pull's sums (FacePull::Sums)
        q.weight += S;
        q.offset += S * local[i];
        for (int d = 0; d < Dim; ++d)
          q.gradient[static_cast<std::size_t>(d)] += S * local[i + held_at + 1 + static_cast<std::size_t>(d)];
        continue;
      }
      change += S * local[i];
    }
    const double before = T[k];
    double flip = before + change;
    if (pull && q.weight != 0.0) {  // the pull Σ_held S_ip (T_face + g_i·(x_p − x_i) − T_p)
      const double pulled = FacePull<Dim>::change(q, before, P.position.data() + Dim * k);
      flip = before + (change + pulled);
      nodal += capacity_[k] * pulled;
      if (relax) pic += FacePull<Dim>::blend_target(q, before, pulled);
    }
    T[k] = (relax && s > 0.0) ? flip - beta * (flip - pic / s) : flip;
    particle += capacity_[k] * (T[k] - before);
  }
  changes[0] = nodal;
  changes[1] = particle;
}

#define FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(D)                                                             \
  template void DecomposedHeat::collect_plastic<D>(mechanics::DecomposedMpm<D>&, double[2]);                   \
  template void DecomposedHeat::map_back<D>(mechanics::DecomposedMpm<D>&, const std::vector<double>&, double, \
                                            std::vector<double>&, double[2], bool);
FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(2)
FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES(3)
#undef FRICTHERM_INSTANTIATE_DECOMPOSED_SOURCES

}  // namespace frictherm::coupling
