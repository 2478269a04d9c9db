#pragma once
// The sliding-block problem of Nairn, Bardenhagen & Smith (2018), figure 2: a 40 × 15 mm block
// (thickness 1 mm) on a 140 × 25 mm base, 5 mm cells, E = 2500 MPa, ν = 0.33, ρ = 1 g/cm³; a normal
// stress N ramped over [0, t1] and a tangential stress ramped from t2 to tf up to R N, with
// t1 = t2 = 0.25 tf and R = 1. N is sized so that Coulomb sliding with μ = 0.2 reaches
// v_max = 31.6 m/s (2 % of the bar wave speed) after 85 mm.
//
// Two load/support variants: `paper` (base fixed at its bottom face, loads on the block's top and
// left edge particles, as in the paper) and `rotated` (the whole set-up turned by `angle`, the base
// a rigid material at rest, both loads spread equally over the block's particles so no grid-aligned
// edge is needed).
#include "rigid_block.hpp"

#include <frictherm/mechanics/simulation.hpp>

#include <cmath>
#include <vector>

namespace frictherm::verification {

struct SlidingBlockSetup {
  mechanics::FrictionLaw law = mechanics::FrictionLaw::coulomb(0.2);
  mechanics::NormalMethod normal = mechanics::NormalMethod::specified;
  mechanics::SeparationMethod separation = mechanics::SeparationMethod::position;
  mechanics::ShapeKind shape = mechanics::ShapeKind::ugimp;
  mechanics::UpdateScheme scheme = mechanics::UpdateScheme::musl;
  double cell = 0.005;
  double cfl = 0.5;
  double angle = 0.0;    // radians; rotated variant only
  bool rotated = false;
  bool single_material = false;  // block and base one material (no contact): benchmark baseline
  mechanics::ContactMethod method = mechanics::ContactMethod::multimaterial;  // or penalty (base = master)
  /// Rotated variant: scale both loads by the block's particle mass over ρ l h b, so the load per
  /// unit mass is the exact block's even when the turned lattice fills the block with a few
  /// particles more or fewer (at 45° and 5 mm cells it holds 92 particles instead of 96).
  bool mass_scaled_loads = false;
  int ppc = 2;
  double R = 1.0;  // tangential load R N (paper variant)
  double regularization_slip_length = 0.0, regularization_time = 0.0;  // ContactOptions (0: off)
  mechanics::ContactAreaMethod area = mechanics::ContactAreaMethod::surface;  // ContactOptions::area
  double stiffness_scale = 1.0;  // both bodies' Young's modulus E times this (the rigid limit as it grows)
};

struct SlidingBlockConstants {
  static constexpr double l = 0.040, h = 0.015, b = 0.001, E = 2500e6, nu = 0.33, rho = 1000.0;
  static constexpr double v_max = 31.6, slide = 0.085, mu = 0.2;
  // Coulomb with μ = 0.2 and R = 1 slides for 0.8 ts = 0.6 tf; v = ½αT², x = αT³/6 give
  // T = 3 x/v_max, α = 2 v_max/T², and N = α ρ h ts (eq. 49).
  static double slide_time() { return 3.0 * slide / v_max; }
  static double t_final() { return slide_time() / 0.6; }
  static double normal_stress() {
    const double T = slide_time(), alpha = 2.0 * v_max / (T * T), ts = 0.75 * t_final();
    return alpha * rho * h * ts;
  }
};

/// Rigid-block solution of a sliding-block set-up with the given friction parameters.
inline RigidBlock rigid_solution(double mu_s, double mu_d, double k, double S_a, double R = 1.0) {
  using C = SlidingBlockConstants;
  RigidBlock r;
  r.rho = C::rho, r.h = C::h, r.l = C::l, r.b = C::b, r.N = C::normal_stress(), r.R = R;
  r.t2 = 0.25 * C::t_final();
  r.ts = C::t_final() - r.t2;
  r.mu_s = mu_s, r.mu_d = mu_d, r.k = k, r.S_a = S_a;
  return r;
}

/// Mass of a body's particles over the exact block mass ρ l h b.
inline double block_mass_ratio(const mechanics::Simulation<2>& sim, int body) {
  using C = SlidingBlockConstants;
  const auto& p = sim.particles();
  double m = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.body[k] == body) m += p.mass[k];
  return m / (C::rho * C::l * C::h * C::b);
}

/// Builds the simulation; returns the block's material id through `block`.
inline mechanics::Simulation<2> make_sliding_block(const SlidingBlockSetup& s, int& block_material) {
  using namespace mechanics;
  using C = SlidingBlockConstants;
  const double tf = C::t_final(), t1 = 0.25 * tf, t2 = 0.25 * tf, N = C::normal_stress();
  SimulationOptions o;
  o.analysis = Analysis::plane_strain;
  o.thickness = C::b;
  o.shape = s.shape;
  o.scheme = s.scheme;
  o.cfl = s.cfl;
  const double c = std::cos(s.angle), sn = std::sin(s.angle);
  auto rot = [&](double x, double y) { return Vec<2>(c * x - sn * y, sn * x + c * y); };
  // Grid: the paper's 150 × 45 mm box, or for the rotated variant a box holding the turned set-up.
  Vec<2> lo(0, 0);
  IVec<2> cells{static_cast<int>(std::lround(0.150 / s.cell)), static_cast<int>(std::lround(0.045 / s.cell))};
  if (s.rotated) {
    double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
    for (Vec<2> p : {rot(0, 0), rot(0.14, 0), rot(0.14, 0.04), rot(0, 0.04), rot(0, 0.025)}) {
      xmin = std::min(xmin, p[0]), xmax = std::max(xmax, p[0]);
      ymin = std::min(ymin, p[1]), ymax = std::max(ymax, p[1]);
    }
    lo = Vec<2>(std::floor(xmin / s.cell) - 1, std::floor(ymin / s.cell) - 1) * s.cell;
    cells = IVec<2>{static_cast<int>(std::ceil((xmax - lo[0]) / s.cell)) + 2,
                    static_cast<int>(std::ceil((ymax - lo[1]) / s.cell)) + 2};
  }
  Simulation<2> sim(Grid<2>(lo, Vec<2>(s.cell, s.cell), cells), o);
  Material base_m;
  base_m.name = "base";
  base_m.density = C::rho;
  base_m.youngs_modulus = C::E * s.stiffness_scale;
  base_m.poisson_ratio = C::nu;
  if (s.rotated) {
    base_m.kind = MaterialKind::rigid;
    base_m.rigid_velocity = {TimeFunction::constant(0.0), TimeFunction::constant(0.0)};
  }
  Material block_m = base_m;
  block_m.name = "block";
  block_m.kind = MaterialKind::linear_elastic;
  block_m.rigid_velocity.clear();
  const int base = sim.add_material(base_m);
  block_material = s.single_material ? base : sim.add_material(block_m);
  auto quad = [&](double x0, double y0, double x1, double y1, int mat) -> std::unique_ptr<Region<2>> {
    if (!s.rotated) return make_box<2>(Vec<2>(x0, y0), Vec<2>(x1, y1), mat);
    return make_polygon<2>({rot(x0, y0), rot(x1, y0), rot(x1, y1), rot(x0, y1)}, 0.0, 0.0, mat);
  };
  sim.add_body("base", *quad(0.0, 0.0, 0.140, 0.025, base), s.ppc, Vec<2>::Zero());
  const int blk = sim.add_body("block", *quad(0.010, 0.025, 0.010 + C::l, 0.025 + C::h, block_material), s.ppc,
                               Vec<2>::Zero());
  const TimeFunction normal_ramp = TimeFunction::ramp(1.0, t1);
  const TimeFunction tangential_ramp = TimeFunction::ramp(1.0, tf - t2, t2);
  if (!s.rotated) {
    sim.fix_face(FixedFace{1, false, {{true, true, true}}});
    EdgeTraction<2> top;
    top.body = blk, top.axis = 1, top.upper = true, top.traction = Vec<2>(0, -N), top.scale = normal_ramp;
    sim.add_edge_traction(top);
    EdgeTraction<2> side;  // F_t = R N l b spread over the left edge (height h)
    side.body = blk, side.axis = 0, side.upper = false, side.traction = Vec<2>(s.R * N * C::l / C::h, 0);
    side.scale = tangential_ramp;
    sim.add_edge_traction(side);
  } else {
    double F = N * C::l * C::b;  // total normal force; R = 1 makes the tangential one equal
    if (s.mass_scaled_loads) F *= block_mass_ratio(sim, blk);
    PointLoad<2> normal;
    normal.body = blk, normal.use_box = true, normal.box_lo = lo, normal.box_hi = sim.grid().hi();
    normal.force = -F * rot(0, 1), normal.scale = normal_ramp;
    sim.add_point_load(normal);
    PointLoad<2> tangential = normal;
    tangential.force = s.R * F * rot(1, 0), tangential.scale = tangential_ramp;
    sim.add_point_load(tangential);
  }
  if (!s.single_material) {
    ContactOptions co;
    co.default_pair.law = s.law;
    co.default_pair.normal = s.normal;
    co.default_pair.normal_vector = Vec<3>(-sn, c, 0.0);  // from base to block
    co.separation = s.separation;
    if (s.separation == SeparationMethod::extent) co.use_extent_detection();
    co.regularization_slip_length = s.regularization_slip_length;
    co.area = s.area;
    co.regularization_time = s.regularization_time;
    co.default_pair.method = s.method;
    sim.enable_contact(co);
    ContactPairSettings pair = co.default_pair;
    sim.set_contact_pair(base, block_material, pair);
  }
  return sim;
}

/// Mass-weighted mean velocity of a material's particles along the unit direction t.
inline double mean_velocity(const mechanics::Simulation<2>& sim, int material, const mechanics::Vec<2>& t) {
  const auto& p = sim.particles();
  double mv = 0.0, m = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == material) mv += p.mass[k] * p.velocity[k].dot(t), m += p.mass[k];
  return mv / m;
}

/// Mass-weighted mean displacement of a material's particles along n (m).
inline double mean_normal_displacement(const mechanics::Simulation<2>& sim, int material, const mechanics::Vec<2>& n) {
  const auto& p = sim.particles();
  double mu = 0.0, m = 0.0;
  for (std::size_t q = 0; q < p.size(); ++q)
    if (p.material[q] == material) {
      mu += p.mass[q] * (p.position[q] - p.initial_position[q]).dot(n);
      m += p.mass[q];
    }
  return mu / m;
}

struct SlidingHistory {
  std::vector<double> time, velocity, work_first, work_second;
  std::vector<double> lift;  // the block's mean displacement normal to the surface (m)
  double mass_ratio = 1.0;  // the block's particle mass over ρ l h b
};

/// Runs to tf, sampling the block's mean velocity along the surface and the cumulative frictional
/// work every `sample` seconds.
inline SlidingHistory run_sliding_block(const SlidingBlockSetup& s, double sample = 1e-4) {
  int block = 0;
  mechanics::Simulation<2> sim = make_sliding_block(s, block);
  const double tf = SlidingBlockConstants::t_final();
  const mechanics::Vec<2> t(std::cos(s.angle), std::sin(s.angle));
  SlidingHistory h;
  h.mass_ratio = block_mass_ratio(sim, 1);  // the block is the second body
  auto record = [&] {
    h.time.push_back(sim.time());
    h.velocity.push_back(mean_velocity(sim, block, t));
    h.lift.push_back(mean_normal_displacement(sim, block, mechanics::Vec<2>(-t[1], t[0])));
    h.work_first.push_back(sim.cumulative_frictional_work(mechanics::HeatingOrder::first));
    h.work_second.push_back(sim.cumulative_frictional_work(mechanics::HeatingOrder::second));
  };
  record();
  double next = sample;
  while (sim.time() < tf * (1 - 1e-12)) {
    const double target = std::min(next, tf);
    sim.step(target - sim.time());
    if (sim.time() >= target * (1 - 1e-12)) {
      record();
      next += sample;
    }
  }
  return h;
}

}  // namespace frictherm::verification
