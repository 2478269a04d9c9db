#pragma once
// The oscillating block of Nairn, Bardenhagen & Smith (2018), figure 6: a 40 × 15 mm block (1 mm
// thick) on a 60 × 25 mm base fixed at its bottom, 2.5 mm cells, the material of figure 2
// (E = 2500 MPa, ν = 0.33, ρ = 1 g/cm³). A normal stress is ramped slowly to 100 MPa over [0, t1];
// then rigid blocks on the top 5/6 of both side edges move with v = v_max sin ω(t − t1) (eq. 44),
// ω = 2 v_max/x_max, x_max = 0.1 mm, v_max = 0.01 % of the bar wave speed. Coulomb μ = 0.5 between
// block and base. The paper's pushers "move the edges"; here they are rigid materials bonded to the
// block (an adhesion law with strengths far above any stress: it sticks in compression and in
// tension), so both sides follow the prescribed motion. (Pushers that prescribe only the x velocity
// of the nodes they touch, Material::rigid_boundary, never make the block slip: with 0.1 mm of motion
// the 2.5 mm strip below them shears to at most G·0.1/2.5 = 38 MPa, below μ·100 MPa.) One stick–slide–stick interval lasts until the
// pushers stop at t1 + π/ω.
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>
#include <limits>
#include <memory>

namespace frictherm::verification {

/// Variants of the set-up for the spurious-heat benchmarks (test_spurious_heat.cpp). The default is
/// the paper's set-up as test_oscillating_block runs it.
struct OscillatingBlockVariant {
  /// Quasi-static preload: mass-proportional damping c = 1.5e5 /s (about critical for the column's
  /// fundamental mode, 2π/83 µs) over the 0.25 ms ramp and 0.2 ms more, pushers starting at 0.5 ms.
  /// Without it the column rings after the ramp at ~1 m/s, six times v_max, and drives real slip.
  bool settled = false;
  bool held = false;     // the pushers stay still: every joule of work after the preload is spurious
  bool pushers = true;   // false: the block is only pressed onto its base ("pressed block")
  mechanics::SeparationMethod separation = mechanics::SeparationMethod::position;
  mechanics::ParticleUpdate update = mechanics::ParticleUpdate::flip;
  mechanics::UpdateScheme scheme = mechanics::UpdateScheme::musl;
  int order = 1;
  double pic_relaxation_time = std::numeric_limits<double>::infinity();
};

struct OscillatingBlock {
  static constexpr double l = 0.040, h = 0.015, b = 0.001, cell = 0.0025;
  static constexpr double E = 2500e6, nu = 0.33, rho = 1000.0;
  static constexpr double normal_stress = 100e6, mu = 0.5, x_max = 1e-4;
  static constexpr double t1 = 0.25e-3;  // slow compared with the block's 8 µs wave transit
  /// Bulk (P-wave, plane strain) speed: 1924 m/s, the paper's v in eq. 45.
  static double wave_speed() {
    const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), G = E / (2 * (1 + nu));
    return std::sqrt((lam + 2 * G) / rho);
  }
  /// 0.01 % of the bar wave speed √(E/ρ): 0.158 m/s and a period 2π/ω = 1.987 ms, as in the paper.
  static double v_max() { return 1e-4 * std::sqrt(E / rho); }
  static double omega() { return 2.0 * v_max() / x_max; }
  static double end_time() { return t1 + M_PI / omega(); }
  static constexpr double settle_until = 0.45e-3, settled_start = 0.5e-3, settle_damping = 1.5e5;
  /// When the pushers start (the work of the oscillation is counted from there) and stop.
  static double push_start(const OscillatingBlockVariant& v) { return v.settled ? settled_start : t1; }
  static double push_end(const OscillatingBlockVariant& v) { return push_start(v) + M_PI / omega(); }

  static std::unique_ptr<mechanics::Simulation<2>> make(double cfl,
                                                        mechanics::ShapeKind shape = mechanics::ShapeKind::ugimp,
                                                        const OscillatingBlockVariant& v = {}) {
    using namespace mechanics;
    SimulationOptions o;
    o.analysis = Analysis::plane_strain;
    o.thickness = b;
    o.shape = shape;
    o.cfl = cfl;
    o.particle_update = v.update;
    o.scheme = v.scheme;
    o.transfer_order = v.order;
    o.pic_relaxation_time = v.pic_relaxation_time;
    if (v.settled) o.damping_rate = settle_damping, o.damping_until = settle_until;
    auto sim = std::make_unique<Simulation<2>>(Grid<2>(Vec<2>(0, 0), Vec<2>(cell, cell), IVec<2>{24, 18}), o);
    Material elastic;
    elastic.density = rho, elastic.youngs_modulus = E, elastic.poisson_ratio = nu;
    Material base_m = elastic, block_m = elastic, pusher_m;
    base_m.name = "base", block_m.name = "block", pusher_m.name = "pusher";
    pusher_m.kind = MaterialKind::rigid;
    pusher_m.density = rho;
    pusher_m.rigid_velocity = {TimeFunction::sinusoid(v.held ? 0.0 : v_max(), omega(), push_start(v), push_end(v)),
                               TimeFunction::constant(0.0)};

    const int base = sim->add_material(base_m), block = sim->add_material(block_m),
              pusher = sim->add_material(pusher_m);
    sim->add_body("base", *make_box<2>(Vec<2>(0, 0), Vec<2>(0.060, 0.025), base), 2, Vec<2>::Zero());
    sim->add_body("block", *make_box<2>(Vec<2>(0.010, 0.025), Vec<2>(0.050, 0.040), block), 2, Vec<2>::Zero());
    const double y0 = 0.025 + h / 6.0;  // top 5/6 of the side edges
    if (v.pushers) {
      sim->add_body("left pusher", *make_box<2>(Vec<2>(0.0075, y0), Vec<2>(0.010, 0.040), pusher), 2, Vec<2>::Zero());
      sim->add_body("right pusher", *make_box<2>(Vec<2>(0.050, y0), Vec<2>(0.0525, 0.040), pusher), 2, Vec<2>::Zero());
    }
    sim->fix_face(FixedFace{1, false, {{true, true, true}}});
    ContactOptions co;
    if (v.separation == SeparationMethod::extent)
      co.use_extent_detection();  // with its companions, as a scene gets it (the pushers' law has an area term)
    co.separation = v.separation;
    co.default_pair.law = FrictionLaw::adhesion(0.0, 1e15, 1e15);  // pushers bonded to the block
    co.default_pair.normal = NormalMethod::max_volume_gradient;
    sim->enable_contact(co);
    ContactPairSettings interface;
    interface.law = FrictionLaw::coulomb(mu);
    interface.normal = NormalMethod::specified;
    interface.normal_vector = Vec<3>(0, 1, 0);  // from base to block
    sim->set_contact_pair(base, block, interface);
    EdgeTraction<2> top;
    top.body = 1, top.axis = 1, top.upper = true, top.traction = Vec<2>(0, -normal_stress);
    top.scale = TimeFunction::ramp(1.0, t1);
    sim->add_edge_traction(top);
    return sim;
  }

  struct Work {
    double first = 0.0, second = 0.0;  // J, base–block pair, over the oscillation [t1, end]
    double ramp_first = 0.0;           // J, first order, slid while the normal load was ramped on
    long steps = 0;
  };

  /// Frictional work of the oscillation, W(end) − W(t1): while the normal load is ramped on, the
  /// block's Poisson expansion slides its ends too (about 0.0026 J), which is not the heat of the
  /// stick–slide–stick interval the paper monitors.
  static Work run(double cfl, mechanics::ShapeKind shape = mechanics::ShapeKind::ugimp,
                  const OscillatingBlockVariant& v = {}) {
    using mechanics::HeatingOrder;
    auto sim = make(cfl, shape, v);
    Work w;
    const double start = push_start(v);
    for (const double stop : {start, push_end(v)}) {
      while (sim->time() < stop * (1 - 1e-12)) sim->step(stop - sim->time());
      if (stop == start) {
        w.ramp_first = sim->cumulative_frictional_work(HeatingOrder::first, 0, 1);
        w.second = -sim->cumulative_frictional_work(HeatingOrder::second, 0, 1);
      }
    }
    w.first = sim->cumulative_frictional_work(HeatingOrder::first, 0, 1) - w.ramp_first;
    w.second += sim->cumulative_frictional_work(HeatingOrder::second, 0, 1);
    w.steps = sim->step_count();
    return w;
  }
};

}  // namespace frictherm::verification
