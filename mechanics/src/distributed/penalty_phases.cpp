// Penalty contact in the decomposed step (Kakouris, Chatzis & Triantafyllou 2024 §3.4–3.7, eqs. 27–36;
// docs/penalty_contact.md, docs/distributed_run.md "Penalty contact"). The boundary points (a few
// hundred per body) are replicated on every rank, and every rank runs the serial kernels
// (penalty_weights.hpp: StepWeights, apply_penalty, move_points, the time-step limits) on all of them,
// so the contact, its slip histories and its books are the same on every rank with no exchange of
// their own. What the points read is completed first:
//   penalty_forces        (after the extrapolated contact, before momentum_update) each field's complete
//                         nodal mass over the whole grid, written by the owners (a DMDA total at a
//                         single-material node, the group's entry at a multi-material one) into zeros
//                         and summed over the ranks (one MPI_Allreduce: each value has one writer, so
//                         the sum is the owner's value exactly); then detection, the forces and heat
//                         through the points' weights into whole-grid arrays, and each rank adds them
//                         to the nodes it owns only (each node once, as the serial nodal force);
//   move_boundary_points  (where the serial step moves them: after velocity_from_momentum under MUSL
//                         and USF (then before penalty_forces: the masses gathered first), after the
//                         grid-to-particle update under USL) each field's nodal velocity over
//                         the grid the same way, then the serial motion of every point.
// Cost per step: two reductions of fields × grid nodes × (1 + Dim) doubles; fine for the EBS benchmark
// scenes (about 10^4 nodes), a limit for large grids (then: the values at the points' stencil nodes only).
#include "distributed/decomposed_state.hpp"
#include "penalty_weights.hpp"

#include <mpi.h>

#include <sstream>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

using detail::petsc_check;

namespace {

// The serial PenaltyContactState::sliver: a node keeps a point's weight S only with m_I ≥ 0.25 S m_p
// (simulation_penalty.cpp, "sliver test").
constexpr double kSliver = 0.25;

}  // namespace

// The step's penalty weights over every field's whole grid, as the serial step builds them: the
// field boxes are lent to it (give them back with w.plain.fields.swap(s.penalty_boxes) after use).
template <int Dim, class State>
penalty_kernels::StepWeights<Dim> lend_penalty_weights(State& s) {
  penalty_kernels::StepWeights<Dim> w;
  w.plain.grid = &s.grid;
  w.plain.shape = s.opt.shape;
  w.plain.fields.swap(s.penalty_boxes);
  w.plain.slot_mass = &s.penalty_mass;
  w.plain.min_mass = s.empty_node_mass;
  w.plain.reference_mass = &s.opt.penalty_reference_mass;
  w.plain.sliver = kSliver;
  if (s.opt.shape == ShapeKind::extended_bspline) w.ebs = &s.ebs;
  return w;
}

template <int Dim>
void DecomposedMpm<Dim>::Impl::setup_penalty() {
  if (opt.penalty_pairs.empty()) return;
  if (Dim != 2) throw std::invalid_argument("decomposed mechanics: penalty contact is 2D only");
  if (!opt.contact) throw std::invalid_argument("decomposed mechanics: penalty pairs given but contact is off");
  const std::size_t n = materials.size();
  if (opt.penalty_materials.size() != opt.penalty_pairs.size() || opt.penalty_reference_mass.size() != n)
    throw std::invalid_argument("decomposed mechanics: penalty contact needs the pairs' materials and each "
                                "material's reference mass");
  penalty.emplace(grid, PenaltyOptions{Dim == 2 ? opt.thickness : 1.0});
  for (const PenaltyPairSettings& p : opt.penalty_pairs) penalty->add_pair(p);
  boundary = opt.penalty_points;
  opt.penalty_points = BoundaryPoints<Dim>{};
  for (std::size_t i = 0; i < boundary.size(); ++i)
    if (boundary.field[i] < 0 || static_cast<std::size_t>(boundary.field[i]) >= n)
      throw std::invalid_argument("decomposed mechanics: a boundary point's field is not a material");
  const std::size_t N = grid.node_count();
  penalty_boxes.clear();
  for (std::size_t f = 0; f < n; ++f) penalty_boxes.push_back(FieldNodes<Dim>::whole_grid(grid, static_cast<int>(f * N)));
}

// dense[(field·N + node)·components + c] = value(node values, field, c) at the nodes this rank owns,
// zeros elsewhere, then summed over the ranks: every rank gets the owners' values exactly.
template <int Dim>
template <class Visit>
void DecomposedMpm<Dim>::Impl::gather_owned_fields(int components, std::vector<double>& dense, Visit&& value) {
  const std::size_t N = grid.node_count(), c = static_cast<std::size_t>(components);
  if (owned_grid_node.size() != owned_local.size()) {
    const IVec<Dim>& gs = grid.strides();
    owned_grid_node.clear();
    for (PetscInt k = owned_start[2]; k < owned_start[2] + owned_size[2]; ++k)
      for (PetscInt j = owned_start[1]; j < owned_start[1] + owned_size[1]; ++j)
        for (PetscInt i = owned_start[0]; i < owned_start[0] + owned_size[0]; ++i) {
          PetscInt g = i * gs[0] + j * gs[1];
          if constexpr (Dim == 3) g += k * gs[2];
          owned_grid_node.push_back(static_cast<std::size_t>(g));
        }
  }
  dense.assign(static_cast<std::size_t>(fields) * N * c, 0.0);
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
    if (field < 0 || field >= fields) return;  // a node no field reaches
    double* out = dense.data() + (static_cast<std::size_t>(field) * N + owned_grid_node[static_cast<std::size_t>(q)]) * c;
    for (std::size_t k = 0; k < c; ++k) out[k] = value(node, static_cast<int>(k));
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
  MPI_Allreduce(MPI_IN_PLACE, dense.data(), static_cast<int>(dense.size()), MPI_DOUBLE, MPI_SUM, comm);
}

// Each field's complete nodal mass over the grid (the weights' sliver test), once per step.
template <int Dim>
void DecomposedMpm<Dim>::Impl::gather_penalty_mass() {
  if (penalty_mass_current) return;
  gather_owned_fields(1, penalty_mass, [](const double* node, int) { return node[Dof::mass]; });
  penalty_mass_current = true;
}

// Detection and penalty forces at the points' step-start positions (K·27–34), the forces into the
// owned nodes' force (K·36) before the momentum update, the heat into the step's frictional work.
template <int Dim>
void DecomposedMpm<Dim>::Impl::penalty_forces(double /*dt*/) {
  if (!penalty) return;
  if constexpr (Dim == 2) {
    gather_penalty_mass();
    const std::size_t N = grid.node_count();
    penalty_force.assign(static_cast<std::size_t>(fields) * N, Vec<Dim>::Zero());
    penalty_heat_first.assign(N, 0.0);
    penalty_heat_second.assign(N, 0.0);
    penalty_kernels::StepWeights<Dim> w = lend_penalty_weights<Dim>(*this);
    penalty_kernels::apply_penalty(*penalty, boundary, w, penalty_mass, empty_node_mass, penalty_force,
                                   penalty_heat_first, penalty_heat_second);
    w.plain.fields.swap(penalty_boxes);
    PetscScalar* a = nullptr;
    petsc_check(VecGetArray(global, &a), "VecGetArray");
    for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
      if (field < 0 || field >= fields) return;
      const Vec<Dim>& f = penalty_force[static_cast<std::size_t>(field) * N + owned_grid_node[static_cast<std::size_t>(q)]];
      for (int d = 0; d < Dim; ++d) node[Dof::force + d] += f[d];
    });
    petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
    for (std::size_t q = 0; q < owned_grid_node.size(); ++q) {
      const double w1 = penalty_heat_first[owned_grid_node[q]], w2 = penalty_heat_second[owned_grid_node[q]];
      work_first[q] += w1, work_second[q] += w2;
      cumulative_first += w1, cumulative_second += w2;
    }
    // The pairs' heat of the step (the same on every rank: every rank runs the kernels on all the
    // points) into rank 0's pair books, so their sum over ranks counts it once (the serial
    // apply_penalty_forces's books).
    if (rank == 0)
      for (std::size_t k = 0; k < penalty->pair_count(); ++k)
        add_pair_work(opt.penalty_materials[k][0], opt.penalty_materials[k][1], penalty->books(k).heat_step,
                      penalty->books(k).heat_step);
  }
}

// The points move with their field's nodal velocity as the stress update uses it (the serial
// move_boundary_points: MUSL the remapped v̂^{n+1}, USL v^{n+1}), through the step's weights; a rigid
// field's points with the rigid body.
template <int Dim>
void DecomposedMpm<Dim>::Impl::move_boundary_points(double dt) {
  if (!penalty) return;
  if constexpr (Dim == 2) {
    gather_penalty_mass();  // USF moves the points before the forces
    gather_owned_fields(Dim, penalty_gather, [](const double* node, int d) { return node[Dof::velocity + d]; });
    penalty_kernels::StepWeights<Dim> w = lend_penalty_weights<Dim>(*this);
    const long bad = penalty_kernels::move_points(boundary, w, grid, dt, [&](int field, Vec<Dim>& v) {
      const Material& m = materials[static_cast<std::size_t>(field)];
      if (!m.is_rigid()) return false;
      v = (0.5 * (m.rigid_velocity_at(time) + m.rigid_velocity_at(time + dt))).template head<Dim>();
      return true;
    }, [&](int slot) { return Vec<Dim>(Eigen::Map<const Vec<Dim>>(penalty_gather.data() + static_cast<std::size_t>(slot) * Dim)); });
    w.plain.fields.swap(penalty_boxes);
    if (bad >= 0) {  // the same on every rank: all throw
      const auto i = static_cast<std::size_t>(bad);
      std::ostringstream msg;
      msg << "decomposed mechanics: step " << traffic.steps << ", t = " << time << " s: boundary point " << i
          << " of material '" << materials[static_cast<std::size_t>(boundary.field[i])].name << "' "
          << (boundary.position[i].allFinite() ? "left the grid" : "has a non-finite position")
          << " (penalty contact; the step blew up: try a smaller CFL factor or penalty)";
      throw std::runtime_error(msg.str());
    }
  }
}

// The penalty springs' time-step limit of the last step's contacts and the factor on the wave speed
// (the serial stable_time_step's, penalty_weights.hpp); the same on every rank.
template <int Dim>
double DecomposedMpm<Dim>::Impl::penalty_time_step(double& cmax) const {
  if (!penalty) return std::numeric_limits<double>::infinity();
  const double h = grid.min_cell_size();
  const double dt = penalty_kernels::penalty_time_step_limit(penalty->frequency_bound_squared(), cmax, h);
  std::vector<PenaltyPairInfo> pairs;
  for (const auto& m : opt.penalty_materials) pairs.push_back(PenaltyPairInfo{m[0], m[1]});
  cmax *= penalty_kernels::penalty_wave_factor(*penalty, pairs, materials, h);
  return dt;
}

template <int Dim>
const PenaltyContact<Dim>* DecomposedMpm<Dim>::penalty_contact() const {
  return impl_->penalty ? &*impl_->penalty : nullptr;
}

template <int Dim>
const BoundaryPoints<Dim>& DecomposedMpm<Dim>::boundary_points() const {
  return impl_->boundary;
}

template <int Dim>
PenaltyContact<Dim>* DecomposedMpm<Dim>::penalty_contact() {
  return impl_->penalty ? &*impl_->penalty : nullptr;
}

template <int Dim>
BoundaryPoints<Dim>& DecomposedMpm<Dim>::boundary_points() {
  return impl_->boundary;
}

#define FRICTHERM_INSTANTIATE_PENALTY_PHASES(D)                                   \
  template void DecomposedMpm<D>::Impl::setup_penalty();                          \
  template void DecomposedMpm<D>::Impl::penalty_forces(double);                   \
  template void DecomposedMpm<D>::Impl::gather_penalty_mass();                    \
  template void DecomposedMpm<D>::Impl::move_boundary_points(double);             \
  template double DecomposedMpm<D>::Impl::penalty_time_step(double&) const;       \
  template const PenaltyContact<D>* DecomposedMpm<D>::penalty_contact() const;    \
  template const BoundaryPoints<D>& DecomposedMpm<D>::boundary_points() const;  \
  template PenaltyContact<D>* DecomposedMpm<D>::penalty_contact();              \
  template BoundaryPoints<D>& DecomposedMpm<D>::boundary_points();
FRICTHERM_INSTANTIATE_PENALTY_PHASES(2)
FRICTHERM_INSTANTIATE_PENALTY_PHASES(3)
#undef FRICTHERM_INSTANTIATE_PENALTY_PHASES

}  // namespace frictherm::mechanics
