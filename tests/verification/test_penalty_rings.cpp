// Impact of two compressible Neo-Hookean rings with penalty contact and EBS (Kakouris, Chatzis &
// Triantafyllou 2024 §4.4, "K·k" = their eq. k; digest §6.5), plane strain, frictionless.
//
// μ = 26.1 MPa, λ = 104.4 MPa (E = 73.08 MPa, ν = 0.4), ρ = 1010 kg/m³, C_c = 0.5, each ring at
// 30 m/s towards the other. Ring geometry (K Fig. 23 only; the literature's, Huang 2011 /
// de Vaucorbeil & Nguyen 2021): radii 30 and 40 mm, centres 100 mm apart, so the rings touch after
// 20 mm / 60 m/s = 0.333 ms. Δh = 2.5 mm here (the paper's 1.25 mm is examples/neo_hookean_rings.json):
// the wall is 4 cells thick, 2 × 2 particles per cell.
//
// Asserted:
//  * no early contact: while the two outer boundary polylines are apart (distance > 0 and neither
//    holds a point of the other, measured at each step's start, where the contact is detected) the
//    penalty force is exactly zero and each ring keeps its momentum to round-off; the same rings in
//    one velocity field (the paper's "no penalty EBS") do exchange momentum before they touch;
//  * penetration: the most negative normal gap over the run is above −0.1 Δh;
//  * energy (K·48 plus the penalty springs): K + W + P within a bound of its initial value.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRin = 0.03, kRout = 0.04, kGap = 0.1, kV = 30.0;
constexpr double kMu = 26.1e6, kLambda = 104.4e6, kRho = 1010.0;

double segment_distance(const Vec<2>& x, const Vec<2>& a, const Vec<2>& b) {
  const Vec<2> d = b - a;
  const double t = std::clamp((x - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (x - a - t * d).norm();
}

bool inside(const Vec<2>& x, const std::vector<Vec<2>>& poly) {  // even-odd rule
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i][1] > x[1]) != (poly[j][1] > x[1]) &&
        x[0] < poly[j][0] + (x[1] - poly[j][1]) * (poly[i][0] - poly[j][0]) / (poly[i][1] - poly[j][1]))
      in = !in;
  return in;
}

/// Distance between the closed polylines A and B, 0 if they overlap.
double polyline_distance(const std::vector<Vec<2>>& A, const std::vector<Vec<2>>& B) {
  double d = 1e30;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& P = pass == 0 ? A : B;
    const auto& Q = pass == 0 ? B : A;
    for (const Vec<2>& x : P) {
      if (inside(x, Q)) return 0.0;
      for (std::size_t j = 0; j < Q.size(); ++j) d = std::min(d, segment_distance(x, Q[j], Q[(j + 1) % Q.size()]));
    }
  }
  return d;
}

struct RingResult {
  double touch_time = -1.0;     // first step start with the polylines touching (s)
  double early_force = 0.0;     // max penalty normal force before touching (N)
  double early_momentum = 0.0;  // max |ΔP_ring| / (M_ring v0) before touching
  double min_gap = 0.0;         // most negative normal gap / Δh
  double energy_drift = 0.0;    // max |T − T0| / T0, T = K + W + P
  double energy_end = 0.0;      // (T − T0) / T0 at the end
  double energy_rise = 0.0;     // max (T − T0) / T0 (a growing instability shows here first)
  double max_stored = 0.0;      // max P / T0
  double max_strain = 0.0;      // max W / T0
  double separation_speed = 0.0;  // |v_right − v_left| / (2 v0) at the end (rebound)
};

RingResult rings(bool penalty, double h, double t_end, double occupation, double penalty_factor) {
  SimulationOptions o;
  o.analysis = Analysis::plane_strain;
  o.shape = ShapeKind::extended_bspline;
  o.ebs_occupation = occupation;
  o.cfl = 0.1;  // the paper's Δt = 0.1 Δt_cr
  const int nx = static_cast<int>(std::lround(0.2 / h)), ny = static_cast<int>(std::lround(0.15 / h));
  Simulation<2> sim(Grid<2>(Vec<2>(-0.1, -0.075), Vec<2>(h, h), IVec<2>{nx, ny}), o);
  Material m;
  m.kind = MaterialKind::neo_hookean;
  m.density = kRho;
  m.youngs_modulus = kMu * (3 * kLambda + 2 * kMu) / (kLambda + kMu);
  m.poisson_ratio = kLambda / (2 * (kLambda + kMu));
  m.name = "left";
  const int left = sim.add_material(m);
  m.name = "right";
  const int right = penalty ? sim.add_material(m) : left;
  if (penalty) {
    ContactOptions co;
    co.default_pair.method = ContactMethod::penalty;
    co.default_pair.law = FrictionLaw::frictionless();
    sim.enable_contact(co);
    ContactPairSettings pair = co.default_pair;
    pair.penalty.master = left;
    pair.penalty.normal_factor = penalty_factor;
    sim.set_contact_pair(left, right, pair);
  }
  sim.add_body("left", *make_annulus<2>(Vec<2>(-0.5 * kGap, 0), kRin, kRout, left), 2, Vec<2>(kV, 0));
  sim.add_body("right", *make_annulus<2>(Vec<2>(0.5 * kGap, 0), kRin, kRout, right), 2, Vec<2>(-kV, 0));
  sim.finalize();

  const auto& p = sim.particles();
  double M[2] = {0.0, 0.0};
  for (std::size_t k = 0; k < p.size(); ++k) M[p.body[k]] += p.mass[k];
  auto momentum = [&](int body) {
    double P = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.body[k] == body) P += p.mass[k] * p.velocity[k][0];
    return P;
  };
  const double P0[2] = {momentum(0), momentum(1)};
  auto energy = [&] {
    const PenaltyContact<2>* pc = sim.penalty_contact();
    return sim.kinetic_energy() + sim.strain_energy() + (pc ? pc->stored_energy() : 0.0);
  };
  const double T0 = energy();
  // Outer polylines: the boundary points' outer loops with penalty contact; without it, the same
  // circles sampled once and moved with the rings' mean velocity (rigid until they touch).
  std::vector<Vec<2>> outer[2];
  std::vector<std::size_t> outer_ids[2];
  const BoundaryPoints<2>& bp = sim.boundary_points();
  if (penalty) {
    for (std::size_t l = 0; l < bp.loop_count(); ++l) {
      if (bp.loop_signed_area2(l) <= 0.0) continue;  // holes run clockwise
      const int b = bp.loop_field[l] == bp.field[0] ? 0 : 1;
      for (std::size_t i = bp.loop_begin[l]; i < bp.loop_begin[l + 1]; ++i) outer_ids[b].push_back(i);
    }
    EXPECT_EQ(bp.field[outer_ids[0].front()], bp.field[0]);
  } else {
    for (int b = 0; b < 2; ++b)
      outer[b] = sample_ellipse_boundary(Vec<2>((b == 0 ? -0.5 : 0.5) * kGap, 0), Vec<2>(kRout, kRout), 0.0, 0.5 * h);
  }
  RingResult r;
  const PenaltyContact<2>* pc = sim.penalty_contact();
  while (sim.time() < t_end) {
    double dist = 0.0;
    if (r.touch_time < 0.0) {
      if (penalty) {
        for (int b = 0; b < 2; ++b) {
          outer[b].clear();
          for (std::size_t i : outer_ids[b]) outer[b].push_back(bp.position[i]);
        }
      }
      dist = polyline_distance(outer[0], outer[1]);
      if (dist <= 0.0) r.touch_time = sim.time();
    }
    const double dt = sim.step(t_end - sim.time());
    if (!penalty && r.touch_time < 0.0)  // rigid motion of the sampled circles
      for (int b = 0; b < 2; ++b)
        for (Vec<2>& x : outer[b]) x[0] += dt * (b == 0 ? kV : -kV);
    if (r.touch_time < 0.0) {
      if (pc)
        for (std::size_t k = 0; k < pc->pair_count(); ++k) r.early_force = std::max(r.early_force, pc->books(k).normal_force);
      for (int b = 0; b < 2; ++b)
        r.early_momentum = std::max(r.early_momentum, std::fabs(momentum(b) - P0[b]) / (M[b] * kV));
    }
    if (pc) {
      for (const auto& c : pc->contacts()) r.min_gap = std::min(r.min_gap, c.gap / h);
      r.max_stored = std::max(r.max_stored, pc->stored_energy() / T0);
    }
    const double T = energy();
    r.energy_drift = std::max(r.energy_drift, std::fabs(T - T0) / T0);
    r.energy_rise = std::max(r.energy_rise, (T - T0) / T0);
    r.max_strain = std::max(r.max_strain, sim.strain_energy() / T0);
  }
  r.energy_end = (energy() - T0) / T0;
  r.separation_speed = (momentum(1) / M[1] - momentum(0) / M[0]) / (2 * kV);
  std::printf("[neo-hookean rings %s h = %.4g mm] touch at %.4f ms (rigid approach: %.4f ms); before: max penalty force "
              "%.3g N, max |dP|/(M v0) %.2e; deepest gap %.4f h; energy K+W+P: max drift %.4f, max rise %.1e, at %.2f ms %+.4f; "
              "max W %.3f T0, max P %.2e T0; relative velocity at the end %+.3f of 2 v0\n",
              penalty ? "penalty EBS" : "one field EBS", 1e3 * h, 1e3 * r.touch_time,
              1e3 * (kGap - 2 * kRout) / (2 * kV), r.early_force, r.early_momentum, r.min_gap, r.energy_drift, r.energy_rise,
              1e3 * sim.time(), r.energy_end, r.max_strain, r.max_stored, r.separation_speed);
  return r;
}

}  // namespace

// Measured (Δh = 2.5 mm, the paper's C_c = 0.5, ε_N = 10 E/Δh, 0–2 ms: approach, impact at 0.333 ms,
// the largest compression near 1.8 ms with W = 0.87 T0; 9.9 s in Release):
//   penalty EBS: first touch at 0.3334 ms; before it zero penalty force and ΔP = 0 exactly for
//     both rings; deepest gap −0.083 Δh; K + W + P stays within 0.07 % of T0 (largest rise 6.7e-4
//     of T0: the boundary points move with the remapped velocity the stress update uses); the
//     springs hold at most 1.5 % of T0;
//   one field (the paper's "no penalty EBS"): the rings exchange 14 % of their momentum before
//     the polylines touch (they share nodes from ~1.5 Δh apart).
// C_c = 0.5 and 0.75 blew up (K + W 2015 → ~5100 J near 0.65–0.8 ms, then a particle inverted) while
// the cell volume fractions counted whole particles in the cell of their position: when a column of
// particles sat on a cell face, a cell inside the ring wall read φ = 0.5 (2 of its 4 particles),
// turned "boundary" at C_c = 0.5, its nodes became degenerate, and the extension (3, −3, 1) took the
// mass of a full cell off the stable node two cells in (0.08 m_p, velocity −1414 m/s; the particle
// beside it went from J = 1.0 to 0.38 in one step). φ is now the volume the particles' domains cover
// (docs/ebs.md); measured since: C_c = 0.5 at 2.5 mm and 1.25 mm, and 0.75 at 2.5 mm, run 2 ms within
// 0.04 % of T0. The dynamic contact pressure (ρ c v ≈ 12 MPa) over E/Δh alone is 0.16 Δh of
// penetration (measured −0.21 Δh with ε_N = E/Δh, K·40); the depth falls as ε_N^(-1/2): −0.110 Δh
// at 6 E/Δh, −0.083 Δh at 10 E/Δh, which meets the 0.1 Δh bound and costs √10 in Δt.
// Bounds: no early contact as measured (exact zeros: the rings share no field); one field > 5 %;
// gap above −0.1 Δh; |T − T0| ≤ 5 % over 2 ms (the digest proposes 10 % over 4 ms) and T ≤ T0 (1 + 1e-3).
TEST(PenaltyRings, NoEarlyContactNoDeepPenetrationEnergyKept) {
  const RingResult r = rings(true, 2.5e-3, 2.0e-3, 0.5, 10.0);
  EXPECT_NEAR(r.touch_time, 0.02 / 60.0, 2.5e-3 / 60.0);  // rigid approach: 20 mm at 60 m/s
  EXPECT_EQ(r.early_force, 0.0);
  EXPECT_LT(r.early_momentum, 1e-12);
  EXPECT_GT(r.min_gap, -0.1);
  EXPECT_LT(r.energy_drift, 0.05);
  EXPECT_LT(r.energy_rise, 1e-3);
  EXPECT_GT(r.max_strain, 0.5);  // the rings did collide and deform
  const RingResult one = rings(false, 2.5e-3, 0.4e-3, 0.5, 1.0);
  EXPECT_GT(one.early_momentum, 0.05);
}
