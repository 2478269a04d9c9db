// The step's phase lists (step/phase_list.hpp, simulation_step.cpp): which phases each update scheme
// and option runs, in which order, and that their timers account for the steps' wall time.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

using namespace frictherm::mechanics;

namespace {
Material elastic(const std::string& name) {
  Material m;
  m.name = name;
  m.density = 1000;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  return m;
}

// Two blocks approaching each other; with `contact` in multimaterial contact.
std::vector<std::string> names(UpdateScheme scheme, bool contact, double damping = 0.0) {
  SimulationOptions o;
  o.scheme = scheme;
  o.damping_rate = damping;
  o.damping_until = 1.0;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
  const int a = sim.add_material(elastic("a")), b = sim.add_material(elastic("b"));
  sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.45, 0.6), a), 2, Vec<2>(1.0, 0.0));
  sim.add_body("b", *make_box<2>(Vec<2>(0.55, 0.2), Vec<2>(0.8, 0.6), b), 2, Vec<2>(-1.0, 0.0));
  if (contact) sim.enable_contact(ContactOptions{});
  std::vector<std::string> out;
  for (const char* n : sim.step_phase_names()) out.emplace_back(n);
  return out;
}
using Names = std::vector<std::string>;
}  // namespace

TEST(StepPhases, ListsPerScheme) {
  const Names grid = {"velocity_conditions", "momentum_update", "nodal_velocities"};
  auto join = [](Names a, const Names& b) { return a.insert(a.end(), b.begin(), b.end()), a; };
  EXPECT_EQ(names(UpdateScheme::usl, false),
            join(join({"time_step", "shape_functions", "particle_to_grid"}, grid),
                 {"particle_update", "end_particle_update"}));
  EXPECT_EQ(names(UpdateScheme::usf, false),
            join(join({"time_step", "shape_functions", "particle_to_grid", "velocity_from_momentum", "stress_update",
                       "internal_forces"},
                      grid),
                 {"grid_to_particle", "end_particle_update"}));
  EXPECT_EQ(names(UpdateScheme::musl, false),
            join(join({"time_step", "shape_functions", "particle_to_grid"}, grid),
                 {"grid_to_particle", "end_particle_update", "remap_momentum",
                  "velocity_from_momentum", "stress_update"}));
  // Contact: a pass after each momentum projection. (No rigid material: no rigid driver's phases.)
  EXPECT_EQ(names(UpdateScheme::usl, true),
            Names({"time_step", "shape_functions", "particle_to_grid", "contact_extrapolated", "velocity_conditions",
                   "momentum_update", "contact_updated", "nodal_velocities", "particle_update",
                   "end_particle_update"}));
  EXPECT_EQ(names(UpdateScheme::musl, true),
            Names({"time_step", "shape_functions", "particle_to_grid", "contact_extrapolated", "velocity_conditions",
                   "momentum_update", "contact_updated", "nodal_velocities", "grid_to_particle",
                   "end_particle_update", "remap_momentum", "contact_remapped",
                   "velocity_from_momentum", "stress_update"}));
  // Damping: one phase between the velocity conditions and the momentum update.
  const Names damped = names(UpdateScheme::usl, false, 100.0);
  ASSERT_EQ(damped.size(), 9u);
  EXPECT_EQ(damped[4], "damping");
}

// The contact methods (step/contact_method.hpp) at their hooks: penalty contact between b and c, and
// between a and b either multimaterial contact (both methods in one scene) or penalty too.
Names names_with_penalty(UpdateScheme scheme, bool multimaterial_pair) {
  SimulationOptions o;
  o.scheme = scheme;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
  const int a = sim.add_material(elastic("a")), b = sim.add_material(elastic("b")), c = sim.add_material(elastic("c"));
  ContactPairSettings penalty;
  penalty.method = ContactMethod::penalty;
  penalty.law = FrictionLaw::frictionless();
  ContactOptions options;
  if (!multimaterial_pair) options.default_pair = penalty;
  sim.enable_contact(options);  // before the bodies: their boundary points
  sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.35, 0.6), a), 2, Vec<2>(1.0, 0.0));
  sim.add_body("b", *make_box<2>(Vec<2>(0.45, 0.2), Vec<2>(0.6, 0.6), b), 2, Vec<2>(0.0, 0.0));
  sim.add_body("c", *make_box<2>(Vec<2>(0.7, 0.2), Vec<2>(0.85, 0.6), c), 2, Vec<2>(-1.0, 0.0));
  sim.set_contact_pair(b, c, penalty);
  Names out;
  for (const char* n : sim.step_phase_names()) out.emplace_back(n);
  EXPECT_NE(sim.penalty_contact(), nullptr);
  return out;
}

TEST(StepPhases, ContactMethodsAtTheirHooks) {
  // Both methods: the multimaterial passes after the momentum projections, the penalty forces before
  // the velocity conditions, the boundary points moved with the stress update's velocity.
  EXPECT_EQ(names_with_penalty(UpdateScheme::usl, true),
            Names({"time_step", "shape_functions", "particle_to_grid", "contact_extrapolated", "penalty_forces",
                   "velocity_conditions", "momentum_update", "contact_updated", "nodal_velocities", "particle_update",
                   "move_boundary_points", "end_particle_update"}));
  EXPECT_EQ(names_with_penalty(UpdateScheme::usf, true),
            Names({"time_step", "shape_functions", "particle_to_grid", "contact_extrapolated", "velocity_from_momentum",
                   "move_boundary_points", "stress_update", "internal_forces", "penalty_forces", "velocity_conditions",
                   "momentum_update", "contact_updated", "nodal_velocities", "grid_to_particle",
                   "end_particle_update"}));
  const Names musl = {"time_step", "shape_functions", "particle_to_grid", "contact_extrapolated", "penalty_forces",
                      "velocity_conditions", "momentum_update", "contact_updated", "nodal_velocities",
                      "grid_to_particle", "end_particle_update", "remap_momentum",
                      "contact_remapped", "velocity_from_momentum", "move_boundary_points", "stress_update"};
  EXPECT_EQ(names_with_penalty(UpdateScheme::musl, true), musl);
  // Every pair in penalty contact: the same list (the multimaterial passes find no contact node).
  EXPECT_EQ(names_with_penalty(UpdateScheme::musl, false), musl);
}

TEST(StepPhases, TimersAccountForTheSteps) {
  SimulationOptions o;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
  const int a = sim.add_material(elastic("a")), b = sim.add_material(elastic("b"));
  sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.45, 0.6), a), 2, Vec<2>(1.0, 0.0));
  sim.add_body("b", *make_box<2>(Vec<2>(0.55, 0.2), Vec<2>(0.8, 0.6), b), 2, Vec<2>(-1.0, 0.0));
  sim.enable_contact(ContactOptions{});
  sim.finalize();
  const auto start = std::chrono::steady_clock::now();
  for (int s = 0; s < 50; ++s) sim.step();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const StepPhaseTimes& t = sim.phase_times();
  // Every phase is timed once and nothing twice: the timers sum to the steps' wall time less what
  // runs outside the phases (the loop, the energy books' start: well below half here).
  EXPECT_GT(t.total(), 0.5 * wall);
  EXPECT_LE(t.total(), wall);
  for (double x : {t.time_step, t.shape_functions, t.particle_to_grid, t.contact, t.grid_update, t.stress_update})
    EXPECT_GT(x, 0.0);
}

// The loads (step/step_load.hpp) at their hooks and selected by what the scene applies: point loads
// into the forces (USF: after the internal forces, before the penalty forces), damping after the
// velocity conditions.
TEST(StepPhases, LoadsAtTheirHooks) {
  SimulationOptions o;
  o.scheme = UpdateScheme::usf;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
  const int a = sim.add_material(elastic("a"));
  sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.45, 0.6), a), 2, Vec<2>(0.0, 0.0));
  const auto load_names = [&] {
    Names out;
    for (const StepLoad<2>* l : loads_for(sim)) out.emplace_back(l->name());
    return out;
  };
  sim.finalize();
  EXPECT_EQ(load_names(), Names{});
  PointLoad<2> p;
  p.point = Vec<2>(0.3, 0.4);
  p.force = Vec<2>(1.0, 0.0);
  sim.add_point_load(p);
  sim.options().damping_rate = 100.0;  // the lists are built again when what they depend on changes
  sim.options().damping_until = 1.0;
  Names steps;
  for (const char* n : sim.step_phase_names()) steps.emplace_back(n);
  EXPECT_EQ(load_names(), Names({"particle_loads", "mass_damping"}));
  EXPECT_EQ(steps, Names({"time_step", "shape_functions", "particle_to_grid", "velocity_from_momentum", "stress_update",
                          "internal_forces", "external_loads", "velocity_conditions", "damping", "momentum_update",
                          "nodal_velocities", "grid_to_particle", "end_particle_update"}));
}

// The grid-velocity filters (step/velocity_filter.hpp): XPIC keeps the start velocity before the
// velocity conditions and filters after nodal_velocities; FMPM filters only; FLIP has none.
TEST(StepPhases, VelocityFiltersAtTheirHooks) {
  const auto run = [](ParticleUpdate update) {
    SimulationOptions o;
    o.scheme = UpdateScheme::usl;  // the scenes' default (the library's is MUSL)
    o.particle_update = update;
    o.transfer_order = 2;
    Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
    const int a = sim.add_material(elastic("a"));
    sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.45, 0.6), a), 2, Vec<2>(1.0, 0.0));
    Names steps, filters;
    for (const char* n : sim.step_phase_names()) steps.emplace_back(n);
    for (const StepVelocityFilter<2>* f : velocity_filters_for(sim)) filters.emplace_back(f->name());
    return std::make_pair(filters, steps);
  };
  const auto [xpic, xpic_steps] = run(ParticleUpdate::xpic);
  EXPECT_EQ(xpic, Names{"xpic"});
  EXPECT_EQ(xpic_steps, Names({"time_step", "shape_functions", "particle_to_grid", "start_velocity", "velocity_conditions",
                               "momentum_update", "nodal_velocities", "velocity_filter", "particle_update",
                               "end_particle_update"}));
  const auto [fmpm, fmpm_steps] = run(ParticleUpdate::fmpm);
  EXPECT_EQ(fmpm, Names{"fmpm"});
  EXPECT_EQ(fmpm_steps, Names({"time_step", "shape_functions", "particle_to_grid", "velocity_conditions",
                               "momentum_update", "nodal_velocities", "velocity_filter", "particle_update",
                               "end_particle_update"}));
  EXPECT_EQ(run(ParticleUpdate::flip).first, Names{});
}

// The rigid drivers (step/rigid_driver.hpp): a rigid wall with a prescribed velocity puts its velocity
// onto the grid after shape_functions (EBS: before the basis, which keeps the driven nodes) and moves
// its particles after the particle pass, or under USL with contact sets the motions the particle pass
// applies; a scene without rigid materials has no driver.
TEST(StepPhases, RigidDriversAtTheirHooks) {
  const auto run = [](UpdateScheme scheme, bool contact, ShapeKind shape, bool wall) {
    SimulationOptions o;
    o.scheme = scheme;
    o.shape = shape;
    Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{10, 10}), o);
    const int a = sim.add_material(elastic("a"));
    sim.add_body("a", *make_box<2>(Vec<2>(0.2, 0.2), Vec<2>(0.45, 0.6), a), 2, Vec<2>(0.0, 0.0));
    if (wall) {
      Material rigid = elastic("wall");
      rigid.kind = MaterialKind::rigid;
      rigid.rigid_velocity = {TimeFunction::constant(-1.0), TimeFunction::constant(0.0)};
      const int w = sim.add_material(rigid);
      sim.add_body("wall", *make_box<2>(Vec<2>(0.55, 0.2), Vec<2>(0.7, 0.6), w), 2, Vec<2>(-1.0, 0.0));
    }
    if (contact) sim.enable_contact(ContactOptions{});
    Names steps, drivers;
    for (const char* n : sim.step_phase_names()) steps.emplace_back(n);
    for (const StepRigidDriver<2>* r : rigid_drivers_for(sim)) drivers.emplace_back(r->name());
    return std::make_pair(drivers, steps);
  };
  const auto [usl, usl_steps] = run(UpdateScheme::usl, false, ShapeKind::ugimp, true);
  EXPECT_EQ(usl, Names{"prescribed_velocity"});
  EXPECT_EQ(usl_steps, Names({"time_step", "shape_functions", "rigid_conditions", "particle_to_grid", "velocity_conditions",
                              "momentum_update", "nodal_velocities", "particle_update", "move_rigid_particles",
                              "end_particle_update"}));
  // USL with contact: the particle pass moves the wall's particles by the motions set before it.
  EXPECT_EQ(run(UpdateScheme::usl, true, ShapeKind::ugimp, true).second,
            Names({"time_step", "shape_functions", "rigid_conditions", "particle_to_grid", "contact_extrapolated",
                   "velocity_conditions", "momentum_update", "contact_updated", "nodal_velocities", "rigid_motion",
                   "particle_update", "end_particle_update"}));
  EXPECT_EQ(run(UpdateScheme::musl, true, ShapeKind::ugimp, true).second,
            Names({"time_step", "shape_functions", "rigid_conditions", "particle_to_grid", "contact_extrapolated",
                   "velocity_conditions", "momentum_update", "contact_updated", "nodal_velocities", "grid_to_particle",
                   "move_rigid_particles", "end_particle_update", "remap_momentum", "contact_remapped",
                   "velocity_from_momentum", "stress_update"}));
  // EBS: the driven nodes before the basis is rebuilt (extended_stencils keeps them).
  EXPECT_EQ(run(UpdateScheme::usl, false, ShapeKind::extended_bspline, true).second,
            Names({"time_step", "shape_functions", "rigid_conditions", "extended_stencils", "particle_to_grid",
                   "velocity_conditions", "momentum_update", "nodal_velocities", "particle_update",
                   "move_rigid_particles", "end_particle_update"}));
  EXPECT_EQ(run(UpdateScheme::usl, false, ShapeKind::extended_bspline, false).second,
            Names({"time_step", "shape_functions", "extended_stencils", "particle_to_grid", "velocity_conditions",
                   "momentum_update", "nodal_velocities", "particle_update", "end_particle_update"}));
  const auto [none, none_steps] = run(UpdateScheme::usl, false, ShapeKind::ugimp, false);
  EXPECT_EQ(none, Names{});
  EXPECT_EQ(none_steps, Names({"time_step", "shape_functions", "particle_to_grid", "velocity_conditions", "momentum_update",
                               "nodal_velocities", "particle_update", "end_particle_update"}));
}
