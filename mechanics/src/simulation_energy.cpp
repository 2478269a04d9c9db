// The mechanical energy books (EnergyBalance, docs/output.md "Energy balance"): the energy stored in
// the materials, the plastic work, and the books' sum. The work terms (external, rigid, damping) are
// accumulated inside the step, in passes that exist anyway (simulation_particle_pass.cpp,
// simulation_contact.cpp, simulation_fields.cpp); what is here runs when a series row asks for it.
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>

namespace frictherm::mechanics {

// Stored energy of a Mie-Grüneisen particle (J). The update integrates the specific internal energy
// by the trapezoidal pressure work plus the plastic work, m Δe = −½(p_n + p_{n+1}) ΔV + σ:Δε_p V
// (mie_gruneisen.hpp), so m e − W_p is the equation of state's share of the stress power, without a
// pass of its own: the volumetric energy (cold compression and, through γ0, the shock's). The
// deviatoric stress is hypoelastic, s = 2G ε_dev^e, whose elastic energy is V s:s/(4G) (plane strain:
// s_zz included). Closed form rather than the stress power Σ V σ:D dt: a state function, so the
// balance's remainder shows the scheme's error instead of absorbing it.
namespace {
template <int Dim>
double mie_gruneisen_stored_energy(const Material& m, double mass, double volume, double energy, double plastic_work,
                                   const Mat<Dim>& sigma, double sigma_zz) {
  const double zz = Dim == 2 ? sigma_zz : 0.0;
  const double p = -(sigma.trace() + zz) / 3.0;
  Mat<Dim> s = sigma;
  s.diagonal().array() += p;
  const double s_zz = Dim == 2 ? zz + p : 0.0;
  const double G = m.mie_gruneisen.shear_modulus;
  const double shear = G > 0.0 ? volume * (s.squaredNorm() + s_zz * s_zz) / (4.0 * G) : 0.0;
  return mass * energy - plastic_work + shear;
}
}  // namespace

template <int Dim>
double Simulation<Dim>::strain_energy() const {
  double e = 0.0;
  for (std::size_t k = 0; k < p_.size(); ++k) {
    const Material& m = materials_[static_cast<std::size_t>(p_.material[k])];
    if (m.kind == MaterialKind::neo_hookean)
      e += p_.initial_volume[k] *
           neo_hookean_energy_density<Dim>(p_.deformation_gradient[k], m.lame_lambda(), m.shear_modulus());
    else if (m.kind == MaterialKind::linear_elastic)
      e += p_.volume[k] * linear_elastic_energy_density<Dim>(p_.stress[k], p_.stress_zz[k], m.youngs_modulus,
                                                              m.poisson_ratio, opt_.analysis);
    else if (m.kind == MaterialKind::mie_gruneisen)
      e += mie_gruneisen_stored_energy<Dim>(m, p_.mass[k], p_.volume[k], p_.internal_energy[k], p_.plastic_work[k],
                                            p_.stress[k], p_.stress_zz[k]);
  }
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
  b.stored = strain_energy() + (penalty_ ? penalty_->stored_energy() : 0.0);
  b.initial = std::isnan(initial_energy_) ? b.kinetic + b.stored : initial_energy_;
  b.external_work = external_work_;
  b.rigid_work = rigid_work_;
  b.damping_work = damping_work_;
  b.plastic_work = plastic_work();
  b.friction_work = contact_ ? cumulative_frictional_work(order) : 0.0;
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
