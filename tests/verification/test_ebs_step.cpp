// Extended B-splines (Kakouris, Chatzis & Triantafyllou 2024 §3.3) as the MPM step's shape function:
//  * with no degenerate node (C_c = 0) the step is the quadratic B-spline step, bit for bit;
//  * momentum of colliding free bodies is conserved to round-off, in one shared field and with
//    multimaterial contact (a basis per material field), in 2D and 3D: Σ_I N^e_I = 1 and
//    Σ_I ∇N^e_I = 0 wherever the body has material;
//  * an axially vibrating free-free bar keeps the analytic period and amplitude at grid offsets
//    that cut its boundary cells;
//  * a fixed face keeps holding when its nodes would be degenerate (they keep their B-spline).
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <memory>

using namespace frictherm::mechanics;

namespace {

Material elastic(const std::string& name, double rho, double E, double nu) {
  Material m;
  m.name = name;
  m.density = rho;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}

// Two disks (2D) or balls (3D) of different materials flying into each other off-centre, with a
// spin and a non-uniform velocity so that stress waves develop. Not on the grid lattice: the
// boundary cells are cut at random fractions.
template <int Dim>
std::unique_ptr<Simulation<Dim>> collision(ShapeKind shape, UpdateScheme scheme, bool contact, double occupation = 0.75,
                                           int ppc = 2) {
  const double h = Dim == 2 ? 0.05 : 0.1;
  const int n = Dim == 2 ? 40 : 16;
  IVec<Dim> cells;
  cells.fill(n);
  SimulationOptions o;
  o.shape = shape;
  o.scheme = scheme;
  o.ebs_occupation = occupation;
  auto sim = std::make_unique<Simulation<Dim>>(Grid<Dim>(Vec<Dim>::Zero(), Vec<Dim>::Constant(h), cells), o);
  const int a = sim->add_material(elastic("rubber", 1100.0, 5e6, 0.35));
  const int b = sim->add_material(elastic("stiff", 2500.0, 2e7, 0.25));
  Vec<Dim> ca = Vec<Dim>::Constant(0.37 * n * h), cb = Vec<Dim>::Constant(0.61 * n * h);
  ca[0] = 0.3 * n * h + 0.013;
  cb[0] = 0.68 * n * h;
  const double ra = 0.17 * n * h + 0.011, rb = 0.12 * n * h;
  sim->add_body("left", *make_ellipse<Dim>(ca, Vec<Dim>::Constant(ra), 0.0, a), ppc, Vec<Dim>::Zero());
  sim->add_body("right", *make_ellipse<Dim>(cb, Vec<Dim>::Constant(rb), 0.0, b), ppc, Vec<Dim>::Zero());
  if (contact) sim->enable_contact(ContactOptions{});
  auto& p = sim->particles();
  for (std::size_t k = 0; k < p.size(); ++k) {
    const bool left = p.body[k] == 0;
    const Vec<Dim> r = p.position[k] - (left ? ca : cb);
    p.velocity[k][0] = (left ? 4.0 : -3.0) - 3.0 * r[1] + 10.0 * r[0] * r[0];
    p.velocity[k][1] = (left ? 0.5 : -0.3) + 3.0 * r[0];
  }
  return sim;
}

// Worst |P − P0| / Σ m|v| over `steps` steps; P2G, the internal forces and the FLIP update conserve
// momentum to round-off (see test_momentum_conservation.cpp), contact exchanges equal and opposite
// momenta. Round-off bound as there: each step sums N particle terms, steps add linearly.
template <int Dim>
double momentum_drift(Simulation<Dim>& sim, int steps, long* contact_nodes = nullptr) {
  const auto& p = sim.particles();
  const Vec<Dim> P0 = sim.linear_momentum();
  double scale = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) scale += p.mass[k] * p.velocity[k].norm();
  double worst = 0.0;
  long most = 0;
  for (int s = 0; s < steps; ++s) {
    sim.step();
    worst = std::max(worst, (sim.linear_momentum() - P0).norm() / scale);
    most = std::max(most, sim.contact_stats().contact_nodes);
  }
  if (contact_nodes) *contact_nodes = most;
  return worst;
}

// Free-free bar (ν = 0, plane stress: c = √(E/ρ) exact) started in its first mode,
// v(x, 0) = v0 cos(π (x − x0)/L): T = 2L/c and the mean velocity of the left half is
// (2 v0/π) cos(2πt/T) (as in test_bar_vibration.cpp). The bar, two cells thick, is shifted by
// `offset` off the particle lattice so that its ends and sides cut the dual cells at fractions
// that change with the offset.
struct Vibration {
  double period = 0.0, max_velocity_error = 0.0;
  int degenerate = 0;
};

Vibration vibrate(ShapeKind shape, const Vec<2>& offset, double h = 0.025, int periods = 2) {
  constexpr double L = 1.0, E = 1e8, rho = 1000.0, v0 = 0.1;
  SimulationOptions o;
  o.analysis = Analysis::plane_stress;
  o.shape = shape;
  const IVec<2> cells{static_cast<int>(std::lround(L / h)) + 6, 7};
  Simulation<2> sim(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(h), cells), o);
  const int mat = sim.add_material(elastic("bar", rho, E, 0.0));
  const Vec<2> lo(2 * h, 2 * h);
  sim.add_body("bar", *make_box<2>(lo, lo + Vec<2>(L, 2 * h), mat), 2, Vec<2>::Zero());
  auto& p = sim.particles();
  for (std::size_t k = 0; k < p.size(); ++k) {
    p.position[k] += offset;
    p.initial_position[k] += offset;
    p.velocity[k][0] = v0 * std::cos(M_PI * (p.position[k][0] - lo[0] - offset[0]) / L);
  }
  auto tracked = [&]() {
    double mv = 0.0, m = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.initial_position[k][0] < lo[0] + offset[0] + 0.5 * L) mv += p.mass[k] * p.velocity[k][0], m += p.mass[k];
    return mv / m;
  };
  const double T = 2.0 * L / std::sqrt(E / rho), amp = 2.0 * v0 / M_PI;
  Vibration r;
  std::vector<double> crossings;
  double prev_v = tracked(), prev_t = 0.0;
  while (sim.time() < periods * T) {
    sim.step();
    const double t = sim.time(), v = tracked();
    r.max_velocity_error = std::max(r.max_velocity_error, std::abs(v - amp * std::cos(2 * M_PI * t / T)) / amp);
    if (prev_v < 0.0 && v >= 0.0) crossings.push_back(prev_t + (t - prev_t) * (-prev_v) / (v - prev_v));
    prev_v = v;
    prev_t = t;
  }
  if (crossings.size() >= 2) r.period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  r.period /= T;
  if (!sim.extended_bases().empty()) r.degenerate = sim.extended_bases()[0].degenerate_count();
  std::printf("[bar vibration %s offset (%.2f, %.2f) h] period / T - 1 = %.2e, max v error %.3f of amplitude, %d degenerate\n",
              to_string(shape), offset[0] / h, offset[1] / h, r.period - 1.0, r.max_velocity_error, r.degenerate);
  return r;
}

}  // namespace

// Tolerances as for the quadratic B-spline in test_bar_vibration.cpp: period within 1 % (the
// semi-discrete error (πh/L)² ~ 6e-3 plus the time integration), velocity within 5 % of the
// amplitude (the B-spline projection's amplitude loss over two periods).
TEST(EbsStep, FreeFreeBarVibrationMatchesAnalyticAtGridOffsets) {
  const double h = 0.025;
  for (const Vec<2>& off : {Vec<2>(0.0, 0.0), Vec<2>(0.3 * h, 0.1 * h), Vec<2>(0.77 * h, 0.6 * h), Vec<2>(0.9 * h, 0.2 * h)}) {
    const Vibration e = vibrate(ShapeKind::extended_bspline, off, h);
    const Vibration q = vibrate(ShapeKind::quadratic_bspline, off, h);
    EXPECT_GT(e.degenerate, 0);
    EXPECT_NEAR(e.period, 1.0, 0.01) << off.transpose();
    EXPECT_LT(e.max_velocity_error, 0.05) << off.transpose();
    EXPECT_NEAR(q.period, 1.0, 0.01) << off.transpose();
  }
}

TEST(EbsStep, NamesAndAlias) {
  EXPECT_EQ(shape_kind_from_string("extended_bspline"), ShapeKind::extended_bspline);
  EXPECT_EQ(shape_kind_from_string("ebs"), ShapeKind::extended_bspline);
  EXPECT_STREQ(to_string(ShapeKind::extended_bspline), "extended_bspline");
  SimulationOptions o;
  o.ebs_occupation = -0.1;
  EXPECT_THROW(Simulation<2>(Grid<2>(Vec<2>::Zero(), Vec<2>::Constant(1.0), IVec<2>{4, 4}), o), std::invalid_argument);
}

// C_c = 0: every cell holding material is interior, no node is degenerate, and EBS is the plain
// quadratic B-spline: the same products summed in the same order, so the states agree exactly.
TEST(EbsStep, WithoutDegenerateNodesEqualsQuadraticBSplineExactly) {
  for (bool contact : {false, true}) {
    auto ebs = collision<2>(ShapeKind::extended_bspline, UpdateScheme::musl, contact, 0.0);
    auto obs = collision<2>(ShapeKind::quadratic_bspline, UpdateScheme::musl, contact);
    for (int s = 0; s < 60; ++s) {
      ebs->step();
      obs->step();
    }
    for (const auto& B : ebs->extended_bases()) EXPECT_EQ(B.degenerate_count(), 0);
    const auto &pe = ebs->particles(), &po = obs->particles();
    for (std::size_t k = 0; k < pe.size(); ++k) {
      ASSERT_EQ(pe.position[k], po.position[k]) << "particle " << k << (contact ? " (contact)" : "");
      ASSERT_EQ(pe.stress[k], po.stress[k]) << "particle " << k << (contact ? " (contact)" : "");
    }
  }
}

TEST(EbsStep, FreeCollisionConservesMomentumOneField) {
  for (UpdateScheme u : {UpdateScheme::usf, UpdateScheme::usl, UpdateScheme::musl}) {
    auto sim = collision<2>(ShapeKind::extended_bspline, u, /*contact=*/false);
    const double drift = momentum_drift(*sim, 300);
    ASSERT_EQ(sim->extended_bases().size(), 1u);  // the shared field: one discrete field
    const EbsBasis<2>& B = sim->extended_bases()[0];
    std::printf("[EBS momentum 2D one field %s] drift %.2e; %d degenerate nodes, %d extended cells\n", to_string(u),
                drift, B.degenerate_count(), B.extended_cell_count());
    EXPECT_GT(B.degenerate_count(), 0);  // the extension is really in use
    EXPECT_LT(drift, 300.0 * sim->particles().size() * 1.1e-16) << to_string(u);
  }
}

TEST(EbsStep, ContactCollisionConservesMomentumPerMaterialBases) {
  auto sim = collision<2>(ShapeKind::extended_bspline, UpdateScheme::musl, /*contact=*/true);
  long contact_nodes = 0;
  const double drift = momentum_drift(*sim, 300, &contact_nodes);
  ASSERT_EQ(sim->extended_bases().size(), 2u);  // one basis per material field
  std::printf("[EBS momentum 2D contact] drift %.2e, up to %ld contact nodes; degenerate %d / %d\n", drift,
              contact_nodes, sim->extended_bases()[0].degenerate_count(), sim->extended_bases()[1].degenerate_count());
  EXPECT_GT(contact_nodes, 0);  // the bodies did meet
  for (const auto& B : sim->extended_bases()) EXPECT_GT(B.degenerate_count(), 0);
  EXPECT_LT(drift, 300.0 * sim->particles().size() * 1.1e-16);
}

TEST(EbsStep, FreeCollisionConservesMomentum3D) {
  for (bool contact : {false, true}) {
    auto sim = collision<3>(ShapeKind::extended_bspline, UpdateScheme::musl, contact);
    const double drift = momentum_drift(*sim, 100);
    std::printf("[EBS momentum 3D %s] drift %.2e, %zu particles\n", contact ? "contact" : "one field", drift,
                sim->particles().size());
    EXPECT_GT(sim->extended_bases()[0].degenerate_count(), 0);
    EXPECT_LT(drift, 100.0 * sim->particles().size() * 1.1e-16);
  }
}

// Two threads (the step threads above ~2000 particles per thread: 6 particles per cell per
// direction here, about 8000 particles): the basis is rebuilt serially, the flattened weights are
// filled in parallel. 10 steps: on the loaded shared machine, two threads are slow.
TEST(EbsStep, FreeCollisionConservesMomentumTwoThreads) {
  omp_set_num_threads(2);
  for (bool contact : {false, true}) {
    auto sim = collision<2>(ShapeKind::extended_bspline, UpdateScheme::musl, contact, 0.75, 6);
    const double drift = momentum_drift(*sim, 10);
    std::printf("[EBS momentum 2D two threads %s] drift %.2e, %zu particles\n", contact ? "contact" : "one field", drift,
                sim->particles().size());
    EXPECT_GT(sim->extended_bases()[0].degenerate_count(), 0);
    EXPECT_LT(drift, 10.0 * sim->particles().size() * 1.1e-16);
  }
  omp_set_num_threads(1);
}
