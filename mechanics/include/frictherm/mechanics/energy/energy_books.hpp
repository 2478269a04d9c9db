#pragma once
// The mechanical energy books' kernels (EnergyBalance, simulation.hpp; docs/output.md "Energy
// balance"), written once for the serial Simulation (simulation_energy.cpp, simulation_fields.cpp,
// simulation_contact.cpp) and the decomposed step (distributed/usl_phases.cpp, contact_phases.cpp):
// the energy a particle stores, and the work a rigid material does on the deformable ones where it
// prescribes their nodal velocity. Each engine passes its own storage; the arithmetic is here.
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/types.hpp>

namespace frictherm::mechanics {

/// The mechanical energy books of a run (J; docs/output.md, "Energy balance"). The energy the bodies
/// lost, lost() = initial + external_work + rigid_work − kinetic − stored, pays for the damping, the
/// plastic and the frictional work, and the two stops the scheme makes at nodes: the normal contact
/// (contact_normal_work) and the velocity conditions (boundary_stop_work); what is left,
/// numerical_dissipation(), is the scheme's own loss (or, if negative, its gain): FLIP/PIC and
/// grid transfers, the explicit update's O(dt) error.
///
/// The stored energy and the kinetic energy are not of the same instant. The work the internal forces
/// do over a step, −Σ V σ_n:L̄ dt with L̄ from the mean of the step's start and end grid velocities (the
/// kinetic energy's change), and the stored energy the stress update books, ½(σ_n + σ_{n+1}):L_{n+1} V dt
/// (USL, MUSL: L from the end velocities), differ by ½ dt V (σ_{n+1}:L_{n+1} − σ_n:L_n), which sums over
/// the steps to ½ dt P, P = Σ V σ:L the stress power of the last update: the stored energy runs half a
/// step ahead. Under loading P is large (the undamped oscillating block's 100 MPa preload ramp, 2.5 mm,
/// C = 0.5: ½ dt P ≈ 3 mJ against 1.2 J stored), and lost() without it fell below the frictional heat
/// during the ramp (−1.8 mJ, heat 2.1 mJ). `stored_lead` = ½ dt P (USL, MUSL; −½ dt P for USF, whose
/// stress update uses the start velocities and so lags; summed step by step, advance_stored_lead) is
/// taken off the stored energy in lost(): the stored energy at the velocities' time, to O(dt²).
struct EnergyBalance {
  double kinetic = 0.0;        // of the deformable particles
  double stored = 0.0;         // strain_energy() (elastic and equation-of-state) + penalty springs
  double initial = 0.0;        // kinetic + stored at the start of the first step
  double external_work = 0.0;  // loads and gravity (external_work())
  double rigid_work = 0.0;     // rigid materials on the deformable bodies (rigid_work())
  double damping_work = 0.0;   // removed by the mass-proportional damping (damping_work())
  double plastic_work = 0.0;   // Σ_p σ:Δε_p V of the particles (plastic_work())
  double friction_work = 0.0;  // cumulative frictional work of the order asked for
  double contact_normal_work = 0.0;  // removed by the normal contact impulses (normal_stop_work)
  double boundary_stop_work = 0.0;   // removed by the velocity conditions of walls and fixed faces (condition_stop_work)
  double stored_lead = 0.0;    // the stored energy's lead over the velocities' time, ±½ dt P (above)
  double lost() const { return initial + external_work + rigid_work - kinetic - (stored - stored_lead); }
  double numerical_dissipation() const {
    return lost() - damping_work - plastic_work - friction_work - contact_normal_work - boundary_stop_work;
  }
};

/// The stress power Σ V σ:L (W) of a stress update's velocity gradient L with the stress before it
/// (`start`; computed where the books need it: USF) and after it (`end`).
struct StressPower {
  double start = 0.0, end = 0.0;
};

/// The books' stored_lead (above) over a stress update of step dt; `last_power`, `last_dt`: the previous
/// update's end power and step, updated here. USL, MUSL (the update used the step's end velocities):
/// the step's mismatch ½ dt (σ_{n+1}:L_{n+1} − σ_n:L_n^start) with σ_n:L_n^start ≈ the previous update's
/// end power, so lead += ½ dt (P − P_last). USF (its start velocities): the mismatch is
/// ½ dt_n (σ_n:L_n − σ_{n+1}:L_n^end), whose first term is this update's start power and whose second
/// is known only at the next update (its start power, σ_{n+1}:L_{n+1}), meanwhile −½ dt P_end. Under a
/// constant step both sum to ±½ dt P; summed step by step they also hold where the step changes (a
/// step cut short to land on an output time would otherwise move the lead by half at once: measured
/// ±2.8 mJ jumps of `energy_lost` in examples/bar_vibration.json, 2.7 J).
inline void advance_stored_lead(bool stress_after_momentum_update, double dt, StressPower p, double& lead,
                                double& last_power, double& last_dt) {
  if (stress_after_momentum_update)
    lead += 0.5 * dt * (p.end - last_power);
  else
    lead += 0.5 * last_dt * last_power + 0.5 * p.start * (dt - last_dt) - 0.5 * dt * p.end;
  last_power = p.end;
  last_dt = dt;
}

namespace energy_detail {
// Stored energy of a Mie-Grüneisen particle (J). The update integrates the specific internal energy
// by the trapezoidal pressure work plus the plastic work, m Δe = −½(p_n + p_{n+1}) ΔV + σ:Δε_p V
// (mie_gruneisen.hpp), so m e − W_p is the equation of state's share of the stress power, without a
// pass of its own: the volumetric energy (cold compression and, through γ0, the shock's). The
// deviatoric stress is hypoelastic, s = 2G ε_dev^e, whose elastic energy is V s:s/(4G) (plane strain:
// s_zz included). Closed form rather than the stress power Σ V σ:D dt: a state function, so the
// balance's remainder shows the scheme's error instead of absorbing it.
template <int Dim>
inline double mie_gruneisen_stored_energy(const Material& m, double mass, double volume, double energy,
                                          double plastic_work, const Mat<Dim>& sigma, double sigma_zz) {
  const double zz = Dim == 2 ? sigma_zz : 0.0;
  const double p = -(sigma.trace() + zz) / 3.0;
  Mat<Dim> s = sigma;
  s.diagonal().array() += p;
  const double s_zz = Dim == 2 ? zz + p : 0.0;
  const double G = m.mie_gruneisen.shear_modulus;
  const double shear = G > 0.0 ? volume * (s.squaredNorm() + s_zz * s_zz) / (4.0 * G) : 0.0;
  return mass * energy - plastic_work + shear;
}
}  // namespace energy_detail

/// One particle's share of the books' stored energy (J): the work its stress has done, V0 w (linear
/// elastic: add_stress_work, stress_update.hpp; its hypoelastic law has no closed form that is that
/// work), W(F) V0 (neo-Hookean, Kakouris 2024 eq. 46), the equation-of-state energy m e − W_p
/// plus the shear energy V s:s/(4G) (Mie-Grüneisen); 0 for a rigid material.
template <int Dim>
inline double particle_stored_energy(const Material& m, double mass, double volume,
                                     double initial_volume, const Mat<Dim>& F, const Mat<Dim>& sigma,
                                     double sigma_zz, double internal_energy, double plastic_work) {
  if (m.kind == MaterialKind::neo_hookean)
    return initial_volume * neo_hookean_energy_density<Dim>(F, m.lame_lambda(), m.shear_modulus());
  if (m.kind == MaterialKind::linear_elastic)  // the stress's work (add_stress_work, stress_update.hpp)
    return initial_volume * internal_energy;
  if (m.kind == MaterialKind::mie_gruneisen)
    return energy_detail::mie_gruneisen_stored_energy<Dim>(m, mass, volume, internal_energy, plastic_work, sigma,
                                                           sigma_zz);
  return 0.0;
}

/// The energy a velocity condition removes from one nodal momentum component in the momentum update
/// (J), the analogue of the frictional work's second order (Nairn, Bardenhagen & Smith 2018 eqs. 32–36)
/// for a stop: over the step the condition's impulse J = m v_w − (p + f dt) acts as a constant force
/// J/dt while the node's velocity relative to the wall goes linearly from its start-of-step value
/// p0/m − v_w to 0 at the end, so it does the work J (p0/m − v_w)/2 in the wall's frame: removed,
/// −½ J (p0/m − v_w). p0 is the momentum the particles brought to the node (before this step's force
/// increment, as v'(0) of eq. 32, and before the extrapolated contact pass's change, which no
/// particle receives): a node resting on the wall (p0 = m v_w) books 0 however large its force; one
/// arriving at u = p0/m − v_w with no force books ½ m u², the perfectly inelastic stop. The wall's
/// own work J v_w is rigid_work (drive_component). A fixed face books nothing: it zeroes the node's
/// momentum and force, so the particles' FLIP update never receives a stop there (their velocity
/// keeps p0; only the grid's velocity, and so their motion and strain, is held), and the energy the
/// stop would remove at the node stays in the particles (measured: a bar run into a fixed face loses
/// 0.6 % of its energy where ½ p0²/m summed over the steps is 15 % of it; test_energy_stops.cpp).
FRICTHERM_ALWAYS_INLINE double condition_stop_work(double mass, double momentum, double force, double v, double dt,
                                                   double start_momentum) {
  if (!(mass > 0.0)) return 0.0;
  const double impulse = mass * v - momentum - force * dt;
  return 0.5 * impulse * (v - start_momentum / mass);
}

/// One nodal momentum component driven by a rigid material to its velocity v in the momentum update:
/// the change is made a force, f = (m v − p)/dt, so that the particles' FLIP update receives it too.
/// Returns the work the rigid material does on the node, (m v − (p + f_old dt)) v: the impulse the
/// condition adds beyond the node's own force, times the velocity it is given at; adds the energy the
/// stop removes (condition_stop_work, from start_momentum) to `stop`.
FRICTHERM_ALWAYS_INLINE double drive_component(double mass, double momentum, double& force, double v, double dt,
                                               double start_momentum, double& stop) {
  const double target = mass * v;
  const double work = (target - momentum - force * dt) * v;
  stop += condition_stop_work(mass, momentum, force, v, dt, start_momentum);
  force = (target - momentum) / dt;
  return work;
}

/// A rigid field's nodal force (penalty contact: a slave's force on a rigid master) is removed, its
/// velocity prescribed: the reaction's work on the deformable material, −f · v dt (J).
template <int Dim, class Force>
FRICTHERM_ALWAYS_INLINE double rigid_reaction_work(const Force& force, const Vec<Dim>& v, double dt) {
  return -(force.dot(v) * dt);
}

}  // namespace frictherm::mechanics
