// The sub-cell interface temperature in a decomposed run (issue 32; the model:
// frictherm/coupling/interface_temperature.hpp, design §7): the serial InterfaceTemperature on the
// nodes this rank owns. The DMDA's node ownership is fixed for the run, so each rank keeps the flux
// history of its owned heated nodes (the bins' boundaries are the steps' end times, the same on every
// rank; a slot's bins depend on that slot's heat alone, so each owned slot holds the serial values).
// After every window or continuation interval:
//
//   pass 1  Σ_p S_ip m_p per conducting material, Σ S m c, Σ S² m c on this rank's ghosted box (the
//           serial add_to_row), summed at the owners (sum_to_owned, in chunks of the transfer's
//           width); the owners' slots then run the serial update_slots: the two heaviest materials,
//           the projection factor, R_x ⊛ flux, T_int,i = T_i + correction (T_i the window's end
//           temperature of an unknown, else none);
//   pass 2  the owners' corrections to the ghosts (owned_to_local); each particle reads the largest
//           correction among the nodes its shape functions reach (S_ip > 0) as it reads ghosted nodal
//           temperatures: T_int,p = T_p + max(0, max_i correction_i), the serial pass 2;
//
// With patch_length > 0 the owners' slots report patches (interface_patches: every rank's heated
// nodes gathered), and pass 2 sends the patch corrections.
// T_int,p lives in a particle scalar (it migrates with the particle: the serial run keeps it by
// particle until the next update). The hottest node is reduced over ranks (MPI_MAX).
// Also the owned nodes' serial grid numbers (owned_grid_nodes) and the owned thermal unknowns of a
// snapshot (thermal_nodes, the serial /nodes).
#include <frictherm/coupling/decomposed_heat.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::coupling {

template <int Dim>
InterfaceTemperature<Dim>* DecomposedHeat::interface_model() {
  if constexpr (Dim == 2) return interface2_.get();
  else return interface3_.get();
}

// InterfaceTemperature::start over the ranks: ρ = Σ m / Σ V per material summed over every rank's
// particles; T_int,p = T_p until the first update (the particle scalar's initial value, set by the
// caller's particles).
template <int Dim>
void DecomposedHeat::interface_start(mechanics::DecomposedMpm<Dim>& mpm) {
  const InterfaceTemperatureOptions& o = opt_.interface_temperature;
  if (!o.enabled) return;
  interface_scalar_ = mpm.particle_scalar_index(opt_.interface_scalar);
  const std::size_t nm = opt_.materials.size();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  std::vector<double> sums(2 * nm, 0.0);  // Σ m, then Σ V, per material
  for (std::size_t k = 0; k < P.mass.size(); ++k) {
    const auto m = static_cast<std::size_t>(P.material[k]);
    if (m < nm) sums[m] += P.mass[k], sums[nm + m] += P.volume[k];
  }
  MPI_Allreduce(MPI_IN_PLACE, sums.data(), static_cast<int>(sums.size()), MPI_DOUBLE, MPI_SUM, mpm.communicator());
  const std::vector<double> mass(sums.begin(), sums.begin() + static_cast<long>(nm));
  const std::vector<double> volume(sums.begin() + static_cast<long>(nm), sums.end());
  auto model = std::make_unique<InterfaceTemperature<Dim>>();
  model->start_sides(mpm.grid(), opt_.thickness, mass, volume, opt_.materials, o, time_);
  if constexpr (Dim == 2) interface2_ = std::move(model);
  else interface3_ = std::move(model);
  owned_grid_node_ = owned_grid_nodes(mpm);
  owned_of_grid_.assign(mpm.grid().node_count(), -1);
  for (std::size_t u = 0; u < owned_grid_node_.size(); ++u)
    owned_of_grid_[static_cast<std::size_t>(owned_grid_node_[u])] = static_cast<int>(u);
  interface_max_ = -std::numeric_limits<double>::infinity();
  interface_node_max_ = interface_max_;
  if (opt_.reaction.enabled) {  // the interface reaction: from the start (during_loading) or the continuation
    interface_progress_scalar_ = mpm.particle_scalar_index(opt_.interface_progress_scalar);
    interface_rate_scalar_ = mpm.particle_scalar_index(opt_.interface_rate_scalar);
    if (opt_.reaction.during_loading) interface_reaction_start(mpm, time_);  // as the serial Coupler::start
  }
}

// The interface reaction starts fresh (λ = 0, no rate yet) on this rank's particles, its state in the
// particle scalars that migrate with them.
template <int Dim>
void DecomposedHeat::interface_reaction_start(mechanics::DecomposedMpm<Dim>& mpm, double time) {
  interface_reaction_.start(mpm.local_particle_data().mass.size(), time);
  mpm.set_particle_scalar(interface_progress_scalar_, interface_reaction_.progress());
  mpm.set_particle_scalar(interface_rate_scalar_, interface_reaction_.rate());
}

template <int Dim>
std::vector<double> DecomposedHeat::interface_reaction_progress(const mechanics::DecomposedMpm<Dim>& mpm) const {
  return interface_reaction_.started() ? mpm.particle_scalar(interface_progress_scalar_) : std::vector<double>{};
}

// Owned node u (x fastest over owned_nodes()) -> the serial grid node (lattice = DMDA index − ghost).
template <int Dim>
std::vector<int> DecomposedHeat::owned_grid_nodes(const mechanics::DecomposedMpm<Dim>& mpm) {
  const std::array<int, 2 * Dim> own = mpm.owned_nodes();
  const mechanics::Grid<Dim>& grid = mpm.grid();
  std::vector<int> nodes(mpm.owned_local_nodes().size(), -1);
  for (std::size_t u = 0; u < nodes.size(); ++u) {
    mechanics::IVec<Dim> lattice{};
    std::size_t r = u;
    for (int d = 0; d < Dim; ++d) {
      const auto extent = static_cast<std::size_t>(own[2 * d + 1] - own[2 * d]);
      lattice[d] = own[2 * d] + static_cast<int>(r % extent) - mechanics::Grid<Dim>::ghost;
      r /= extent;
    }
    nodes[u] = grid.node_index(lattice);
  }
  return nodes;
}

// The owned unknowns of the last gather with the temperature the serial Coupler::nodal_temperature
// holds: the last window's (or interval's) end T_i, the gathered T_i (eq. 38) before any window.
DecomposedThermalNodes DecomposedHeat::thermal_nodes() const {
  DecomposedThermalNodes out;
  const std::vector<int> grid_node = mpm3_ ? owned_grid_nodes(*mpm3_) : owned_grid_nodes(*mpm2_);
  const std::vector<double>& T = last_T_.size() == M_.size() ? last_T_ : T0_;
  for (std::size_t u = 0; u < M_.size() && u < T.size() && u < grid_node.size(); ++u) {
    if (!is_unknown(M_[u])) continue;
    out.grid_node.push_back(grid_node[u]);
    out.temperature.push_back(T[u]);
    out.heat_capacity.push_back(M_[u]);
  }
  return out;
}

// InterfaceTemperature::add_step on the owned nodes: the step's frictional work per owned node, then
// the step's end (time_, the step's end time as the serial Coupler::after_step's).
template <int Dim>
void DecomposedHeat::interface_step(const std::vector<double>& work) {
  InterfaceTemperature<Dim>* model = interface_model<Dim>();
  if (!model) return;
  for (std::size_t u = 0; u < work.size(); ++u) model->add_node_heat(owned_grid_node_[u], work[u]);
  model->end_step(time_);
}

template <int Dim>
void DecomposedHeat::interface_update(mechanics::DecomposedMpm<Dim>& mpm) {
  InterfaceTemperature<Dim>* model = interface_model<Dim>();
  if (!model) return;
  const std::size_t no = mpm.owned_local_nodes().size(), nl = static_cast<std::size_t>(mpm.local_node_count());
  const typename mechanics::DecomposedMpm<Dim>::Stencils& st = mpm.current_stencils();
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data();
  const std::size_t np = P.mass.size(), stride = model->row_size();
  auto conducting = [&](std::size_t k) {
    return P.material[k] >= 0 && model->conducting(static_cast<std::size_t>(P.material[k]));
  };

  // Pass 1 on the ghosted box, summed at the owners in chunks of the transfer's width.
  std::vector<double> rows(nl * stride, 0.0);
  for (std::size_t k = 0; k < np; ++k) {
    if (!conducting(k)) continue;
    const auto m = static_cast<std::size_t>(P.material[k]);
    for (int a = st.first[k]; a < st.first[k + 1]; ++a) {
      const double w = st.S[static_cast<std::size_t>(a)];
      if (w > 0.0) model->add_to_row(&rows[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)]) * stride], m,
                                     P.mass[k], w);
    }
  }
  const auto width = static_cast<std::size_t>(mechanics::DecomposedMpm<Dim>::max_transfer_components);
  std::vector<double> owned_rows(no * stride, 0.0), chunk, summed;
  for (std::size_t c0 = 0; c0 < stride; c0 += width) {
    const std::size_t c = std::min(width, stride - c0);
    chunk.assign(nl * c, 0.0);
    for (std::size_t i = 0; i < nl; ++i)
      for (std::size_t j = 0; j < c; ++j) chunk[i * c + j] = rows[i * stride + c0 + j];
    mpm.sum_to_owned(chunk, static_cast<int>(c), summed);
    for (std::size_t u = 0; u < no; ++u)
      for (std::size_t j = 0; j < c; ++j) owned_rows[u * stride + c0 + j] = summed[u * c + j];
    ++books_.exchanges;
  }

  // The owners' slots: their rows and grid temperatures (the window's end T_i of an unknown), the serial update.
  const std::vector<int>& nodes = model->nodes();
  const std::size_t slots = nodes.size();
  std::vector<double> slot_rows(slots * stride), grid_temperature(slots, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t s = 0; s < slots; ++s) {
    const auto u = static_cast<std::size_t>(owned_of_grid_[static_cast<std::size_t>(nodes[s])]);
    std::copy_n(owned_rows.begin() + static_cast<long>(u * stride), stride, slot_rows.begin() + static_cast<long>(s * stride));
    if (u < M_.size() && u < last_T_.size() && is_unknown(M_[u])) grid_temperature[s] = last_T_[u];
  }
  // The patches (patch_length > 0) reach nodes another rank owns: formed once, from the gathered nodes.
  model->update_slots(slot_rows, grid_temperature, time_, /*own_patches=*/false);
  if (model->patches()) interface_patches(*model, mpm.communicator());
  interface_max_ = model->max_temperature();
  interface_node_max_ = model->max_node_temperature();
  double maxima[2] = {interface_max_, interface_node_max_};
  MPI_Allreduce(MPI_IN_PLACE, maxima, 2, MPI_DOUBLE, MPI_MAX, mpm.communicator());
  interface_max_ = maxima[0], interface_node_max_ = maxima[1];
  interface_heat_ = model->heat_recorded();
  MPI_Allreduce(MPI_IN_PLACE, &interface_heat_, 1, MPI_DOUBLE, MPI_SUM, mpm.communicator());

  // Pass 2: the corrections to the ghosts; T_int,p = T_p + the largest correction the particle reaches.
  std::vector<double> correction(no, 0.0), local_correction;
  const std::vector<double>& per_slot = model->slot_correction();
  for (std::size_t s = 0; s < slots; ++s)
    correction[static_cast<std::size_t>(owned_of_grid_[static_cast<std::size_t>(nodes[s])])] = per_slot[s];
  mpm.owned_to_local(correction, 1, local_correction);
  ++books_.exchanges;
  std::vector<double> t_int = mpm.particle_scalar(scalar_);
  for (std::size_t k = 0; k < np; ++k) {
    if (!conducting(k)) continue;
    double best = 0.0;
    for (int a = st.first[k]; a < st.first[k + 1]; ++a)
      if (st.S[static_cast<std::size_t>(a)] > 0.0)
        best = std::max(best, local_correction[static_cast<std::size_t>(st.node[static_cast<std::size_t>(a)])]);
    t_int[k] += best;
  }
  mpm.set_particle_scalar(interface_scalar_, t_int);
  // The interface reaction at T_int,p (Coupler::update_interface_and_hotspots), this rank's particles.
  if (interface_reaction_.started()) {  // this update's particles' λ_int,p and k from their scalars
    const std::vector<std::int32_t> material(P.material.begin(), P.material.end());
    interface_reaction_.assign(mpm.particle_scalar(interface_progress_scalar_), mpm.particle_scalar(interface_rate_scalar_));
    interface_reaction_.advance(material, opt_.reaction, t_int, time_);
    mpm.set_particle_scalar(interface_progress_scalar_, interface_reaction_.progress());
    mpm.set_particle_scalar(interface_rate_scalar_, interface_reaction_.rate());
    interface_reaction_max_ = interface_reaction_.max_progress();
    MPI_Allreduce(MPI_IN_PLACE, &interface_reaction_max_, 1, MPI_DOUBLE, MPI_MAX, mpm.communicator());
  }
}

// Hot spots of a given size (patch_length > 0): a patch sums the heated nodes within ℓ/2 of its node,
// which another rank may own. Every rank's heated nodes with their corrections and interface
// temperatures are gathered to every rank (a few per contact node row: small beside the particles),
// and each rank's patches are then the serial sums over the same nodes in the same order.
template <int Dim>
void DecomposedHeat::interface_patches(InterfaceTemperature<Dim>& model, MPI_Comm comm) {
  const int count = static_cast<int>(model.nodes().size());
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(static_cast<std::size_t>(ranks), 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  const auto total = static_cast<std::size_t>(offsets.back() + counts.back());
  std::vector<int> nodes(total);
  std::vector<double> correction(total), temperature(total);
  MPI_Allgatherv(model.nodes().data(), count, MPI_INT, nodes.data(), counts.data(), offsets.data(), MPI_INT, comm);
  MPI_Allgatherv(model.node_correction().data(), count, MPI_DOUBLE, correction.data(), counts.data(), offsets.data(),
                 MPI_DOUBLE, comm);
  MPI_Allgatherv(model.node_temperature().data(), count, MPI_DOUBLE, temperature.data(), counts.data(),
                 offsets.data(), MPI_DOUBLE, comm);
  books_.exchanges += 3;
  model.update_patches_from(nodes, correction, temperature);
}

#define FRICTHERM_DECOMPOSED_INTERFACE(D)                                                      \
  template std::vector<int> DecomposedHeat::owned_grid_nodes<D>(const mechanics::DecomposedMpm<D>&); \
  template InterfaceTemperature<D>* DecomposedHeat::interface_model<D>();                      \
  template void DecomposedHeat::interface_start<D>(mechanics::DecomposedMpm<D>&);              \
  template void DecomposedHeat::interface_step<D>(const std::vector<double>&);                 \
  template void DecomposedHeat::interface_update<D>(mechanics::DecomposedMpm<D>&);              \
  template void DecomposedHeat::interface_patches<D>(InterfaceTemperature<D>&, MPI_Comm);                 \
  template void DecomposedHeat::interface_reaction_start<D>(mechanics::DecomposedMpm<D>&, double);       \
  template std::vector<double> DecomposedHeat::interface_reaction_progress<D>(const mechanics::DecomposedMpm<D>&) const;
FRICTHERM_DECOMPOSED_INTERFACE(2)
FRICTHERM_DECOMPOSED_INTERFACE(3)
#undef FRICTHERM_DECOMPOSED_INTERFACE

}  // namespace frictherm::coupling
