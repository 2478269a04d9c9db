// Rigid materials with a prescribed velocity history (walls, pistons, anvils: Material::rigid_velocity_at,
// constant, ramp or sinusoid; Nairn 2018 eq. 44) as the step's rigid driver (step/rigid_driver.hpp).
//   drive (phase rigid_conditions): the velocity v(t) onto the grid. A rigid material with a velocity
//     field of its own (contact, not a boundary) gives the field v(t) (layout_.field_velocity: the
//     velocity conditions set m v there, contact reads it as a rigid side); every other one (all of
//     them without contact, boundary ones with it) marks each node its particles touch (S_ip > 0) in
//     conditions_.rigid_mask with the components it controls, v(t) in conditions_.rigid_velocity, which
//     the node loops of the velocity conditions, damping and nodal_velocities read.
//   move: the rigid particles take v(t) and move by the trapezoid ½ (v(t) + v(t + dt)) dt, in a phase
//     of their own (move_rigid_particles), or, under USL with contact, in the particle pass, which
//     evaluates their next stencils in the same loop: this driver then sets the step's motions
//     (phase rigid_motion, layout_.rigid_motion) and the pass applies them.
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/component_registry.hpp>
#include <frictherm/mechanics/step/rigid_driver.hpp>
#include <frictherm/mechanics/step/step_kernel.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>

namespace frictherm::mechanics {

template <int Dim>
class PrescribedRigidVelocity final : public StepRigidDriver<Dim> {
 public:
  using Sim = Simulation<Dim>;
  const char* name() const override { return "prescribed_velocity"; }

  void add_phases(RigidHook at, bool pass_moves, ShapeKind shape, Sim& sim, PhaseList& P) const override {
    using T = StepPhaseTimes;
    if (at == RigidHook::drive) {
      // The nodes a particle drives come from its stencil: the kernel is chosen here, once per list.
      P.add("rigid_conditions", &T::shape_functions,
            step_kernel_phase(shape, [&sim](auto kernel) -> std::function<void(StepContext&)> {
              using Kernel = decltype(kernel);
              return [&sim](StepContext& c) { drive<Kernel>(sim, c.t); };
            }));
    } else if (at == RigidHook::particle_update && pass_moves) {
      P.add("rigid_motion", &T::stress_update, [&sim](StepContext& c) { set_motions(sim, c.t, c.dt); });
    } else if (at == RigidHook::moved && !pass_moves) {
      P.add("move_rigid_particles", &T::grid_to_particle, [&sim](StepContext& c) { move(sim, c.t, c.dt); });
    }
  }

  static const StepRigidDriver<Dim>* select(Sim& sim) {
    static const PrescribedRigidVelocity driver;
    const auto& mats = sim.materials_;
    return std::any_of(mats.begin(), mats.end(), [](const Material& m) { return m.is_rigid(); }) ? &driver : nullptr;
  }

 private:
  // Material m's motion over [t, t + dt].
  static RigidBodyMotion<Dim> motion(const Material& mat, double t, double dt) {
    return {mat.rigid_velocity_at(t).template head<Dim>(),
            ((mat.rigid_velocity_at(t + dt) + mat.rigid_velocity_at(t)) * 0.5 * dt).template head<Dim>()};
  }

  template <class Kernel>
  static void drive(Sim& sim, double t) {
    for (std::size_t f = 0; f < sim.fields_.size(); ++f)
      if (sim.fields_[f].rigid)
        sim.layout_.field_velocity[f] =
            sim.materials_[static_cast<std::size_t>(sim.fields_[f].material)].rigid_velocity_at(t).template head<Dim>();
    // With contact (not EBS) from the stencils the step evaluated in shape_functions; else their own.
    const Stencil<Dim, Kernel>* evaluated = nullptr;
    if constexpr (!std::is_same_v<Kernel, ExtendedBSplineKernel>)
      if (sim.contact_setup_.enabled) evaluated = sim.template stencils<Kernel>().data();
    auto& C = sim.conditions_;
    std::fill(C.rigid_mask.begin(), C.rigid_mask.end(), std::uint8_t{0});
    for (std::size_t m = 0; m < sim.materials_.size(); ++m) {
      const Material& mat = sim.materials_[m];
      if (!mat.is_rigid() || sim.layout_.field_of_material[m] >= 0) continue;
      const Vec<Dim> v = mat.rigid_velocity_at(t).template head<Dim>();
      std::uint8_t bits = 0;
      for (int d = 0; d < Dim; ++d)
        if (mat.rigid_controls[static_cast<std::size_t>(d)]) bits |= static_cast<std::uint8_t>(1u << d);
      Stencil<Dim, Kernel> own;
      for (std::size_t k = sim.layout_.material_begin[m]; k < sim.layout_.material_end[m]; ++k) {
        if (!evaluated) own.evaluate(sim.grid_, sim.p_.position[k], sim.p_.half_size[k]);
        const Stencil<Dim, Kernel>& s = evaluated ? evaluated[k] : own;
        s.for_each(sim.grid_, [&](int i, double S, const Vec<Dim>&) {
          if (S > 0.0) {
            C.rigid_mask[static_cast<std::size_t>(i)] |= bits;
            for (int d = 0; d < Dim; ++d)
              if (bits & (1u << d)) C.rigid_velocity[static_cast<std::size_t>(i)][d] = v[d];
          }
        });
      }
    }
  }

  // USL with contact: the particle pass moves the rigid particles with these (simulation_particle_pass.cpp).
  static void set_motions(Sim& sim, double t, double dt) {
    sim.layout_.rigid_motion.resize(sim.materials_.size());
    for (std::size_t m = 0; m < sim.materials_.size(); ++m)
      if (sim.materials_[m].is_rigid()) sim.layout_.rigid_motion[m] = motion(sim.materials_[m], t, dt);
  }

  static void move(Sim& sim, double t, double dt) {
    for (std::size_t m = 0; m < sim.materials_.size(); ++m) {
      if (!sim.materials_[m].is_rigid()) continue;
      const RigidBodyMotion<Dim> r = motion(sim.materials_[m], t, dt);
      for (std::size_t k = sim.layout_.material_begin[m]; k < sim.layout_.material_end[m]; ++k)
        r.move(sim.p_.velocity[k], sim.p_.position[k]);
    }
  }
};

FRICTHERM_STEP_COMPONENT_SELECTION(StepRigidDriver, select_prescribed_velocity, PrescribedRigidVelocity)

}  // namespace frictherm::mechanics
