// Point loads and tractions as a load of the step (step/step_load.hpp): resolved to particles by
// resolve_loads (simulation_setup.cpp), each scattered into the nodal forces of its material's field
// over the particle's stencil, f_i += S_ip F(t) (Nairn 2018 eq. 3 with an external force; the kernel
// add_load_to_grid, loads/grid_loads.hpp, shared with the decomposed step). Their work is booked in
// the particle pass (F(t)·Δx_p, load_work).
#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/step_load.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/step_kernel.hpp>

namespace frictherm::mechanics {

template <int Dim>
class ParticleLoads final : public StepLoad<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "particle_loads"; }

  void add_phases(LoadHook at, ShapeKind shape, Sim& sim, PhaseList& P) const override {
    if (at != LoadHook::forces) return;
    // The scatter reads the step's stencils: the kernel is chosen here, once per list.
    P.add("external_loads", &StepPhaseTimes::particle_to_grid,
          step_kernel_phase(shape, [&sim](auto kernel) -> std::function<void(StepContext&)> {
            using Kernel = decltype(kernel);
            return [&sim](StepContext& c) { map_to_grid<Kernel>(sim, c.t); };
          }));
  }

  static const StepLoad<Dim>* select(Sim& sim) {
    static const ParticleLoads load;
    return sim.conditions_.resolved_loads.empty() ? nullptr : &load;
  }

 private:
  // Each load into its material field's nodal forces over the particle's stencil of this step.
  template <class Kernel>
  static void map_to_grid(Sim& sim, double t) {
    auto& st = sim.template stencils<Kernel>();
    for (const auto& L : sim.conditions_.resolved_loads) {
      const Vec<Dim> f = load_force<Dim>(L.force, *L.scale, t);
      const int fi = sim.layout_.field_of_material[static_cast<std::size_t>(sim.p_.material[L.particle])];
      if (fi < 0) continue;
      add_load_to_grid<Dim>(st[L.particle], sim.fields_[static_cast<std::size_t>(fi)].index, f,
                            [&](int i) -> Vec<Dim>& { return sim.nodes_.force[i]; });
    }
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepLoad, select_particle_loads, ParticleLoads)

}  // namespace frictherm::mechanics
