// The mechanical energy books (EnergyBalance, docs/output.md "Energy balance"): the energy stored in
// the materials (the per-particle kernel particle_stored_energy, energy/energy_books.hpp, shared with
// the decomposed step), the plastic work, and the books' sum. The work terms (external, rigid, damping) are
// accumulated inside the step, in passes that exist anyway (simulation_particle_pass.cpp,
// simulation_contact.cpp, simulation_fields.cpp); what is here runs when a series row asks for it.
#include <frictherm/mechanics/energy/energy_books.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>

namespace frictherm::mechanics {

template <int Dim>
double Simulation<Dim>::strain_energy() const {
  double e = 0.0;
  for (std::size_t k = 0; k < p_.size(); ++k)
    e += particle_stored_energy<Dim>(materials_[static_cast<std::size_t>(p_.material[k])], p_.mass[k],
                                     p_.volume[k], p_.initial_volume[k], p_.deformation_gradient[k], p_.stress[k],
                                     p_.stress_zz[k], p_.internal_energy[k], p_.plastic_work[k]);
  return e;
}

template <int Dim>
double Simulation<Dim>::plastic_work() const {
  double w = 0.0;
  for (const double x : p_.plastic_work) w += x;
  return w;
}

template <int Dim>
EnergyBalance Simulation<Dim>::energy_balance(HeatingOrder order) const {
  EnergyBalance b;
  b.kinetic = kinetic_energy();
  b.stored = strain_energy() + contact_stored_energy();
  b.initial = std::isnan(work_books_.initial_energy) ? b.kinetic + b.stored : work_books_.initial_energy;
  b.external_work = work_books_.external;
  b.rigid_work = work_books_.rigid;
  b.damping_work = work_books_.damping;
  b.contact_normal_work = work_books_.contact_normal;
  b.boundary_stop_work = work_books_.boundary_stop;
  b.stored_lead = work_books_.stored_lead;
  b.plastic_work = plastic_work();
  b.friction_work = contact_setup_.enabled ? cumulative_frictional_work(order) : 0.0;
  return b;
}

#define FRICTHERM_INSTANTIATE_ENERGY(D)                                    \
  template double Simulation<D>::strain_energy() const;                   \
  template double Simulation<D>::plastic_work() const;                    \
  template EnergyBalance Simulation<D>::energy_balance(HeatingOrder) const;
FRICTHERM_INSTANTIATE_ENERGY(2)
FRICTHERM_INSTANTIATE_ENERGY(3)
#undef FRICTHERM_INSTANTIATE_ENERGY

}  // namespace frictherm::mechanics
