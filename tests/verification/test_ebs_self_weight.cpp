// A column under its own weight with extended B-splines (EBS) and plain quadratic B-splines (OBS),
// after Kakouris, Chatzis & Triantafyllou 2024 §4.1 (one bar instead of two): σ_yy(y) = −ρ g (top − y).
//
// The column (ν = 0, plane stress, h = H/20, 2 particles per cell per direction) stands on an
// upward traction ρ g H on its bottom face that balances its weight, so it has no grid-fixed support
// and the whole problem moves with the grid offset. Gravity and traction rise linearly over 4
// periods T = 4H/c of the fundamental mode (an integer number of periods of every mode of the
// continuum column, so the ramp leaves almost no free vibration) and the stress is averaged over
// one more period. The traction acts as point forces on the bottom particle row; their boundary
// layer, the same for both bases, is left out of the error (the 4 cells above the bottom).
//
// Offsets that put the top particle row just above a knot-span boundary give OBS a node whose
// support holds only that row's tail, N ~ ½ε²: a tiny nodal mass whose f/m is large. USL feeds that
// nodal velocity into the stress update (MUSL remaps it away), and the top stress is off by ~2.5 %
// of ρgH. EBS makes that node degenerate and moves its weight inward.
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kH = 1.0, kE = 1e8, kRho = 2000.0, kG = 10.0, kCellSize = kH / 20;

struct ColumnResult {
  double l1_error = 0.0;   // Σ |σ − σ_an| V / Σ |σ_an| V over the particles above the boundary layer
  double top_error = 0.0;  // max |σ − σ_an| / (ρ g H) over the top 2 cells
  double mean_uy = 0.0;    // mean vertical displacement at the end (m)
  int degenerate = 0;
};

enum class Support { traction, fixed_face };

ColumnResult column(ShapeKind shape, UpdateScheme scheme, double offset, Support support = Support::traction) {
  const double h = kCellSize;
  const IVec<2> cells{8, static_cast<int>(std::lround(kH / h)) + 5};
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  o.scheme = scheme;
  Simulation<2> sim(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(h), cells), o);
  Material m;
  m.name = "column";
  m.density = kRho;
  m.youngs_modulus = kE;
  m.poisson_ratio = 0.0;
  const int mat = sim.add_material(m);
  sim.add_body("column", *make_box<2>(Vec<2>(2 * h, 0.0), Vec<2>(6 * h, kH), mat), 2, Vec<2>::Zero());
  const double T = 4.0 * kH / std::sqrt(kE / kRho), t_ramp = 4.0 * T, t_end = t_ramp + T;
  const TimeFunction ramp = TimeFunction::ramp(1.0, t_ramp);
  if (support == Support::traction) {
    EdgeTraction<2> bottom;
    bottom.body = 0;
    bottom.axis = 1;
    bottom.upper = false;
    bottom.traction = Vec<2>(0.0, kRho * kG * kH);
    bottom.scale = ramp;
    sim.add_edge_traction(bottom);
  } else {
    sim.fix_face(FixedFace{1, false, {{true, true, false}}});
  }
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) {  // off the particle lattice
    p.position[k][1] += offset;
    p.initial_position[k][1] += offset;
  }
  const double top = kH + offset;
  std::vector<double> mean_stress(p.size(), 0.0);
  double t_mean = 0.0;
  while (sim.time() < t_end) {
    const double t = sim.time();
    sim.options().gravity = Vec<3>(0.0, -kG * ramp(t), 0.0);
    const double dt = sim.step(t < t_ramp ? t_ramp - t : t_end - t);
    if (sim.time() > t_ramp) {
      for (std::size_t k = 0; k < p.size(); ++k) mean_stress[k] += p.stress[k](1, 1) * dt;
      t_mean += dt;
    }
  }
  ColumnResult r;
  if (!sim.extended_bases().empty()) r.degenerate = sim.extended_bases()[0].degenerate_count();
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double y0 = p.initial_position[k][1];
    const double exact = -kRho * kG * (top - y0), s = mean_stress[k] / t_mean;
    r.mean_uy += (p.position[k][1] - y0) / static_cast<double>(p.size());
    if (y0 > top - 2 * h) r.top_error = std::max(r.top_error, std::abs(s - exact) / (kRho * kG * kH));
    if (y0 < offset + 4 * h) continue;
    num += std::abs(s - exact) * p.volume[k];
    den += std::abs(exact) * p.volume[k];
  }
  r.l1_error = num / den;
  return r;
}

}  // namespace

// Bounds. EBS: the error of the quadratic spline space itself at this resolution, seen where EBS and
// OBS coincide (offsets 0.3, 0.5 and 0.7 h: the top and bottom rows fill their knot spans, so only
// the sides have degenerate nodes, which a stress uniform in x does not feel): at most 0.12 % (L1)
// and 0.42 % of ρgH (top); 0.2 % and 0.5 % bound every offset. OBS with USL at the tiny-mass offset:
// 2.5 % measured; the test asserts > 1 % (the trouble exists) and EBS below a tenth of it there.
TEST(EbsSelfWeight, StressErrorBoundedAtEveryGridOffset) {
  const double offsets[] = {0.1, 0.3, 0.5, 0.751, 0.77, 0.9};
  for (UpdateScheme u : {UpdateScheme::musl, UpdateScheme::usl}) {
    double worst_ebs = 0.0, worst_obs = 0.0;
    for (double off : offsets) {
      const ColumnResult e = column(ShapeKind::extended_bspline, u, off * kCellSize);
      const ColumnResult q = column(ShapeKind::quadratic_bspline, u, off * kCellSize);
      std::printf("[self weight %s offset %.3f h] L1 error OBS %.2e EBS %.2e; top error OBS %.2e EBS %.2e; %d degenerate\n",
                  to_string(u), off, q.l1_error, e.l1_error, q.top_error, e.top_error, e.degenerate);
      EXPECT_GT(e.degenerate, 0);
      EXPECT_LT(e.l1_error, 2e-3) << to_string(u) << " offset " << off;
      EXPECT_LT(e.top_error, 5e-3) << to_string(u) << " offset " << off;
      worst_ebs = std::max(worst_ebs, e.top_error);
      worst_obs = std::max(worst_obs, q.top_error);
      if (u == UpdateScheme::usl && off == 0.751) {
        EXPECT_GT(q.top_error, 1e-2);  // the small-cut-cell trouble of OBS
        EXPECT_LT(e.top_error, 0.1 * q.top_error);
      }
    }
    EXPECT_LT(worst_ebs, worst_obs) << to_string(u);
  }
}

// A fixed face at the grid's bottom with the column 0.93 h above it: the face node's support holds
// one particle row only, so EBS would make it degenerate and the face would hold nothing (the column
// would fall, u ~ g t²/2 ~ 0.6 m). Nodes with a velocity condition keep their B-spline, so EBS
// holds the column as OBS does: mean displacements agree within 5 % (measured: equal to 4 digits,
// −3.1e-4 m; a column clamped at its base would give −ρgH²/(3E) = −6.7e-5 m, the rest is the
// face's loose grip 0.93 h below the column); 10 ρgH²/E = 2e-3 m separates holding from falling.
TEST(EbsSelfWeight, FixedFaceHoldsWhereItsNodeWouldBeDegenerate) {
  const ColumnResult e = column(ShapeKind::extended_bspline, UpdateScheme::musl, 0.93 * kCellSize, Support::fixed_face);
  const ColumnResult q = column(ShapeKind::quadratic_bspline, UpdateScheme::musl, 0.93 * kCellSize, Support::fixed_face);
  std::printf("[fixed face] mean u_y OBS %.3e m, EBS %.3e m (static %.3e m)\n", q.mean_uy, e.mean_uy,
              -kRho * kG * kH * kH / (3 * kE));
  EXPECT_GT(e.degenerate, 0);
  EXPECT_NEAR(e.mean_uy, q.mean_uy, 0.05 * std::abs(q.mean_uy));
  EXPECT_LT(std::abs(e.mean_uy), 10.0 * kRho * kG * kH * kH / kE);
}
