// Penalty contact on boundary material points (Kakouris, Chatzis & Triantafyllou 2024 §3.4–3.7;
// docs/penalty_contact.md) as a contact method of the step (step/contact_method.hpp): the penalty
// forces join the nodal forces before the velocity conditions (K·36), and the boundary points move
// with the nodal velocity the stress update uses (simulation_penalty.cpp, move_boundary_points, says
// why). Its springs' energy goes to the energy books and its stiffness bounds the time step. The
// work itself is Simulation's (simulation_penalty.cpp); selected when some present material pair
// uses penalty contact (setup_penalty, run by the selection).
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/contact_method.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>

namespace frictherm::mechanics {

template <int Dim>
class PenaltyContactMethod final : public StepContactMethod<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "penalty"; }

  void add_phases(ContactHook at, UpdateScheme scheme, ShapeKind, Sim& sim, PhaseList& P) const override {
    using T = StepPhaseTimes;
    switch (at) {
      case ContactHook::forces:  // point forces into the nodal forces (Kakouris 2024 eq. 36)
        P.add("penalty_forces", &T::contact, [&sim](StepContext&) { sim.apply_penalty_forces(); });
        break;
      case ContactHook::stress_velocity: {  // timed with contact (USF), the particle pass (USL), the grid update (MUSL)
        double T::*timer = scheme == UpdateScheme::usf ? &T::contact : scheme == UpdateScheme::usl ? &T::grid_to_particle : &T::grid_update;
        P.add("move_boundary_points", timer, [&sim](StepContext& c) { sim.move_boundary_points(c.dt, c.t); });
        break;
      }
      case ContactHook::extrapolated:
      case ContactHook::updated:
      case ContactHook::remapped:
        break;
    }
  }

  double stored_energy(const Sim& sim) const override { return sim.penalty_state_.contact->stored_energy(); }
  double wave_speed_factor(const Sim& sim) const override { return sim.penalty_wave_factor(); }
  double time_step_limit(const Sim& sim, double wave_speed) const override { return sim.penalty_time_step_limit(wave_speed); }

  static const StepContactMethod<Dim>* select(Sim& sim) {
    static const PenaltyContactMethod method;
    if (!sim.contact_setup_.enabled) return nullptr;
    sim.setup_penalty();
    return sim.penalty_state_.contact ? &method : nullptr;
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepContactMethod, select_penalty_contact, PenaltyContactMethod)

}  // namespace frictherm::mechanics
