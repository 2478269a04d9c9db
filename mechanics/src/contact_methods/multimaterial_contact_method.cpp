// Multimaterial contact on the grid (Nairn, Bardenhagen & Smith 2018 §2.2–2.12) as a contact method
// of the step (step/contact_method.hpp): at the nodes two or more materials' velocity fields share,
// a contact pass after each momentum projection (§2.12: contact after the extrapolation and after the
// update, so the forces stay consistent; MUSL also after the remap). The passes themselves are
// Simulation's: contact_at_extrapolated (simulation_step.cpp: contact nodes, contact terms, extents,
// first pass) and resolve_contact (simulation_contact.cpp). Selected whenever contact is enabled, so
// the fields are per material; a scene whose every present pair uses penalty contact keeps the
// passes (find_contact_nodes then lists no node), as the step did before the interface.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/contact_method.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/step_kernel.hpp>

namespace frictherm::mechanics {

template <int Dim>
class MultimaterialContactMethod final : public StepContactMethod<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "multimaterial"; }

  void add_phases(ContactHook at, UpdateScheme, ShapeKind shape, Sim& sim, PhaseList& P) const override {
    using T = StepPhaseTimes;
    switch (at) {
      case ContactHook::extrapolated:
        P.add("contact_extrapolated", &T::contact, extrapolated_pass(sim, shape));
        break;
      case ContactHook::updated:
        P.add("contact_updated", &T::contact, [&sim](StepContext& c) { sim.resolve_contact(Sim::ContactPass::updated, c.dt); });
        break;
      case ContactHook::remapped:
        P.add("contact_remapped", &T::contact, [&sim](StepContext& c) { sim.resolve_contact(Sim::ContactPass::remapped, c.dt); });
        break;
      case ContactHook::stress_velocity:
      case ContactHook::forces:
        break;
    }
  }

  static const StepContactMethod<Dim>* select(Sim& sim) {
    static const MultimaterialContactMethod method;
    return sim.contact_setup_.enabled ? &method : nullptr;
  }

 private:
  // The first pass reads the step's stencils: the kernel is chosen here, once per scene.
  static std::function<void(StepContext&)> extrapolated_pass(Sim& sim, ShapeKind shape) {
    return step_kernel_phase(shape, [&sim](auto kernel) -> std::function<void(StepContext&)> {
      using Kernel = decltype(kernel);
      return [&sim](StepContext& c) { sim.template contact_at_extrapolated<Kernel>(c.dt); };
    });
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepContactMethod, select_multimaterial_contact, MultimaterialContactMethod)

}  // namespace frictherm::mechanics
