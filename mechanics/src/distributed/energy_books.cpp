// The decomposed step's mechanical energy books (DecomposedMpm::energy_balance; docs/output.md "Energy
// balance", docs/distributed_run.md): the serial Simulation::energy_balance's quantities from the same
// kernels (energy/energy_books.hpp). The work terms are booked inside the step where the serial step
// books them: the loads' work in grid_to_particle, the rigid drives' in velocity_conditions and the
// damping's in damping, the rigid contact partners' in the updated contact pass (usl_phases.cpp,
// contact_phases.cpp), each at the rank that owns the node or holds the particle, so the sum over ranks
// counts each once. What is here sums this rank's particles and reduces over ranks.
#include "distributed/decomposed_state.hpp"

#include <frictherm/mechanics/energy/energy_books.hpp>

#include <mpi.h>

#include <array>
#include <cmath>

namespace frictherm::mechanics {

// This rank's particles' share of the books in one pass over the swarm (its fields can be gotten once
// at a time): [0] ½ m v² of the deformable particles (as Simulation::kinetic_energy: a rigid wall's
// prescribed motion is not the bodies'), [1] their stored energy, [2] their plastic work.
template <int Dim>
std::array<double, 3> DecomposedMpm<Dim>::Impl::particle_books() const {
  SwarmFields f(swarm);
  std::array<double, 3> e{0.0, 0.0, 0.0};
  for (PetscInt k = 0; k < f.n; ++k) {
    const std::size_t m = static_cast<std::size_t>(f.material[k]);
    if (!materials[m].is_rigid()) e[0] += 0.5 * f.mass[k] * Eigen::Map<const Vec<Dim>>(f.velocity + Dim * k).squaredNorm();
    e[1] += particle_stored_energy<Dim>(materials[m], f.mass[k], f.volume[k], f.volume0[k],
                                        Eigen::Map<const Mat<Dim>>(f.F + Dim * Dim * k),
                                        Eigen::Map<const Mat<Dim>>(f.stress + Dim * Dim * k), f.stress_zz[k],
                                        f.internal_energy[k], f.plastic_work[k]);
    e[2] += f.plastic_work[k];
  }
  return e;
}

// The books' start, kinetic + stored energy before the first step moves anything (the serial
// Simulation::step takes it at the same point); kept in checkpoints.
template <int Dim>
void DecomposedMpm<Dim>::Impl::take_initial_energy() {
  if (!std::isnan(initial_energy)) return;
  const std::array<double, 3> p = particle_books();
  double e = p[0] + p[1];
  MPI_Allreduce(MPI_IN_PLACE, &e, 1, MPI_DOUBLE, MPI_SUM, comm);
  initial_energy = e + (penalty ? penalty->stored_energy() : 0.0);  // the springs' (the same on every rank)
}

template <int Dim>
EnergyBalance DecomposedMpm<Dim>::energy_balance(HeatingOrder order) const {
  const Impl& s = *impl_;
  const std::array<double, 3> p = s.particle_books();
  double v[10] = {p[0],
                 p[1],
                 p[2],
                 s.external_work,
                 s.rigid_work,
                 s.damping_work,
                 order == HeatingOrder::first ? s.cumulative_first : s.cumulative_second,
                 s.contact_normal_work,
                 s.boundary_stop_work,
                 s.stored_lead};
  MPI_Allreduce(MPI_IN_PLACE, v, 10, MPI_DOUBLE, MPI_SUM, s.comm);
  EnergyBalance b;
  b.kinetic = v[0];
  b.stored = v[1] + (s.penalty ? s.penalty->stored_energy() : 0.0);  // + the penalty springs' (every rank's)
  b.initial = std::isnan(s.initial_energy) ? b.kinetic + b.stored : s.initial_energy;
  b.plastic_work = v[2];
  b.external_work = v[3];
  b.rigid_work = v[4];
  b.damping_work = v[5];
  b.friction_work = v[6];
  b.contact_normal_work = v[7];
  b.boundary_stop_work = v[8];
  b.stored_lead = v[9];
  return b;
}

#define FRICTHERM_INSTANTIATE_BOOKS(D)                                     \
  template std::array<double, 3> DecomposedMpm<D>::Impl::particle_books() const; \
  template void DecomposedMpm<D>::Impl::take_initial_energy();            \
  template EnergyBalance DecomposedMpm<D>::energy_balance(HeatingOrder) const;
FRICTHERM_INSTANTIATE_BOOKS(2)
FRICTHERM_INSTANTIATE_BOOKS(3)
#undef FRICTHERM_INSTANTIATE_BOOKS

}  // namespace frictherm::mechanics
