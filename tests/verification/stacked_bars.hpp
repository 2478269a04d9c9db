#pragma once
// The two stacked bars of Kakouris, Chatzis & Triantafyllou (2024) §4.1 in 2D, shared by
// test_penalty_stacked_bars (the paper's C = 0.1, EBS against OBS) and test_penalty_stability
// (EBS at C = 0.5): two 0.3 m bars of 3 cells (Δh = 0.1 m), 0.4 m wide, 4 × 4 particles per cell,
// E = 50.5 GPa, ν = 0, ρ = 2783 kg/m³, plane stress, MUSL, C_c = 0.75, frictionless penalty contact
// with the bottom bar the master; the stack held by a traction ρ g 2 h_bar on its bottom row; gravity
// ramped over 50 periods T = 4 (2 h_bar)/c, the stress then averaged over 4 more. The whole stack is
// moved up by `offset` against the grid. Exact: σ_yy = −ρ g (y_top − y).
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace frictherm::verification {

struct StackedBarsConstants {
  static constexpr double h = 0.1, bar = 0.3, E = 50.5e9, rho = 2783.0, g = 9.81, width = 0.4;
  static constexpr double stack = 2 * bar;
  static constexpr double contact_stress = rho * g * bar;  // 8190.4 Pa
  static constexpr double ramp_periods = 50, mean_periods = 4;
};

struct StackedBarsResult {
  double master_top = 0.0;    // |σ̄ − σ_an| / (ρ g h_top) of the master's top particle row
  double slave_bottom = 0.0;  // same, slave's bottom row
  double mismatch = 0.0;      // |σ̄_master,top − σ̄_slave,bottom| / (ρ g h_top), σ_an subtracted
  double l1 = 0.0;            // eq. 42: Σ |σ − σ_an| V / (|W| l0)
  double force = 0.0;         // mean penalty normal force / (ρ g h_top A)
  std::string failure;        // the SimulationError's message if the run blew up (results then ∞)
};

inline StackedBarsResult run_stacked_bars(mechanics::ShapeKind shape, double offset, double cfl) {
  using namespace mechanics;
  using C = StackedBarsConstants;
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  o.scheme = UpdateScheme::musl;
  o.ebs_occupation = 0.75;  // the paper's C_c
  o.cfl = cfl;
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(C::h, C::h), IVec<2>{8, 11}), o);
  Material m;
  m.density = C::rho;
  m.youngs_modulus = C::E;
  m.poisson_ratio = 0.0;
  m.name = "bottom";
  const int bottom = sim.add_material(m);
  m.name = "top";
  const int top = sim.add_material(m);
  ContactOptions co;
  co.default_pair.method = ContactMethod::penalty;
  co.default_pair.law = FrictionLaw::frictionless();
  sim.enable_contact(co);
  ContactPairSettings pair = co.default_pair;
  pair.penalty.master = bottom;  // the paper's choice
  sim.set_contact_pair(bottom, top, pair);
  const double x0 = 2 * C::h, y0 = 0.2;
  sim.add_body("bottom", *make_box<2>(Vec<2>(x0, y0), Vec<2>(x0 + C::width, y0 + C::bar), bottom), 4, Vec<2>::Zero());
  sim.add_body("top", *make_box<2>(Vec<2>(x0, y0 + C::bar), Vec<2>(x0 + C::width, y0 + C::stack), top), 4, Vec<2>::Zero());
  const double c = std::sqrt(C::E / C::rho), T = 4.0 * C::stack / c;
  const double t_ramp = C::ramp_periods * T, t_end = t_ramp + C::mean_periods * T;
  const TimeFunction ramp = TimeFunction::ramp(1.0, t_ramp);
  EdgeTraction<2> support;
  support.body = 0;
  support.axis = 1;
  support.upper = false;
  support.traction = Vec<2>(0.0, C::rho * C::g * C::stack);
  support.scale = ramp;
  sim.add_edge_traction(support);
  sim.finalize();
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) {  // the whole stack moved off the grid by `offset`
    p.position[k][1] += offset;
    p.initial_position[k][1] += offset;
  }
  auto& bp = sim.boundary_points();
  for (std::size_t i = 0; i < bp.size(); ++i) {
    bp.position[i][1] += offset;
    bp.reference_position[i][1] += offset;
  }
  const double top_y = y0 + C::stack + offset, contact_y = y0 + C::bar + offset;
  std::vector<double> mean(p.size(), 0.0);
  double t_mean = 0.0, force = 0.0;
  StackedBarsResult r;
  try {
    while (sim.time() < t_end) {
      const double t = sim.time();
      sim.options().gravity = Vec<3>(0.0, -C::g * ramp(t), 0.0);
      const double dt = sim.step(t < t_ramp ? t_ramp - t : t_end - t);
      if (sim.time() > t_ramp) {
        for (std::size_t k = 0; k < p.size(); ++k) mean[k] += p.stress[k](1, 1) * dt;
        force += sim.penalty_contact()->books(0).normal_force * dt;
        t_mean += dt;
      }
    }
  } catch (const SimulationError& e) {
    r.failure = e.what();
    r.master_top = r.slave_bottom = r.mismatch = r.l1 = r.force = std::numeric_limits<double>::infinity();
    return r;
  }
  double num = 0.0, row_m = 0.0, row_s = 0.0;
  int nm = 0, ns = 0;
  const double row = C::h / 4;  // particle spacing
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double y = p.initial_position[k][1];
    const double err = mean[k] / t_mean + C::rho * C::g * (top_y - y);  // σ − σ_an
    num += std::fabs(err) * p.volume[k];
    if (y < contact_y && y > contact_y - row) row_m += err, ++nm;
    if (y > contact_y && y < contact_y + row) row_s += err, ++ns;
  }
  r.master_top = std::fabs(row_m / nm) / C::contact_stress;
  r.slave_bottom = std::fabs(row_s / ns) / C::contact_stress;
  r.mismatch = std::fabs(row_m / nm - row_s / ns) / C::contact_stress;
  r.l1 = num / (C::rho * C::g * C::stack * C::width * C::stack);  // |W| l0 per unit thickness
  r.force = force / t_mean / (C::contact_stress * C::width);
  return r;
}

}  // namespace frictherm::verification
