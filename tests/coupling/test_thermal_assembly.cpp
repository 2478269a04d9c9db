// Thermal assembly from particles (Nairn et al. 2018 eq. 38), heat handoff and the incremental
// particle update: conservation laws and exact properties of the discretisation.
#include "thermal_test_support.hpp"

#include <frictherm/coupling/heat_handoff.hpp>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using fc::test::fill_box;
using fc::test::make_grid;

namespace {

const fm::ShapeKind kShapes[] = {fm::ShapeKind::linear, fm::ShapeKind::ugimp, fm::ShapeKind::quadratic_bspline};

// Two materials (an HMX-like grain in a binder-like block) and a rigid one without thermal properties.
std::vector<fc::ThermalProperties> two_materials() {
  return {{true, 1100.0, 0.45}, {true, 1500.0, 0.14}, {false, 0.0, 0.0}};
}

// 2D: a 6 x 4 mm block of material 1 with a 2 x 2 mm inclusion of material 0, on a 10 x 8 grid of
// 1 mm cells (thickness 2 mm), temperatures varying in space; a rigid body of material 2 beside it.
fm::Particles<2> block_2d(double thickness = 2e-3) {
  fm::Particles<2> p;
  auto T = [](const fm::Vec<2>& x) { return 300.0 + 1e4 * x[0] + 30.0 * std::sin(2e3 * x[1]); };
  fill_box<2>(p, {2e-3, 2e-3}, {4e-3, 4e-3}, 1e-3, 2, 1900.0, 0, T, thickness);
  fill_box<2>(p, {4e-3, 2e-3}, {8e-3, 6e-3}, 1e-3, 2, 1190.0, 1, T, thickness);
  fill_box<2>(p, {2e-3, 4e-3}, {4e-3, 6e-3}, 1e-3, 2, 1190.0, 1, T, thickness);
  fill_box<2>(p, {8e-3, 2e-3}, {9e-3, 6e-3}, 1e-3, 2, 7800.0, 2, T, thickness);
  return p;
}

double total_heat_capacity(const fm::Particles<2>& p, const std::vector<fc::ThermalProperties>& m) {
  double s = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const auto& pr = m[static_cast<std::size_t>(p.material[k])];
    if (pr.conducts) s += p.mass[k] * pr.heat_capacity;
  }
  return s;
}

}  // namespace

TEST(ThermalAssembly, PartitionOfUnityAndZeroRowSums2D) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  const auto p = block_2d();
  const auto mats = two_materials();
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, shape, mats);
    // Σ_i M_i = Σ_p m_p C_p: partition of unity, round-off of ~1e2 terms.
    double sum = 0.0;
    for (double m : s.grid_mass) sum += m;
    EXPECT_NEAR(sum, total_heat_capacity(p, mats), 1e-13 * sum);
    EXPECT_LT(s.mass_residual(), 1e-13);
    EXPECT_EQ(s.dropped_mass, 0.0);  // the lattice fills whole cells: no tiny nodes
    // K·1 = 0 and K = Kᵀ exactly (the same products in the same order).
    EXPECT_LT(s.row_sum_residual(), 1e-13);
    const Eigen::MatrixXd K = Eigen::MatrixXd(s.conductance);
    EXPECT_EQ((K - K.transpose()).cwiseAbs().maxCoeff(), 0.0);
    // Positive semi-definite: eigenvalues >= -round-off.
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K).eigenvalues();
    EXPECT_GT(ev.minCoeff(), -1e-12 * ev.maxCoeff());
    // Eq. 38: Σ M_i T_i = Σ m_p C_p T_p (partition of unity again).
    EXPECT_NEAR(s.energy(s.temperature), fc::particle_thermal_energy(p, mats), 1e-13 * s.energy(s.temperature));
    // Units: 2D volumes carry the thickness, so K is W/K: halving the thickness halves K and M.
    const fc::NodalThermalSystem half = fc::assemble_thermal(grid, block_2d(1e-3), shape, mats);
    EXPECT_NEAR(half.conductance.diagonal().sum(), 0.5 * s.conductance.diagonal().sum(),
                1e-12 * s.conductance.diagonal().sum());
    EXPECT_NEAR(half.mass.sum(), 0.5 * s.mass.sum(), 1e-12 * s.mass.sum());
  }
}

// The zero-row-sum check on row blocks (row_sum_extremes: a decomposed run's owned rows with global
// columns, the largest |Σ_j K_ij| and |K_ii| reduced over ranks): on a system whose K·1 is not zero
// (its diagonal scaled) the maxima over two blocks give the whole system's residual exactly (maxima
// of the same numbers), which is the one NodalThermalSystem::row_sum_residual reports.
TEST(ThermalAssembly, RowSumResidualOfRowBlocksIsTheSystems) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  fc::NodalThermalSystem s = fc::assemble_thermal(grid, block_2d(), fm::ShapeKind::ugimp, two_materials());
  const Eigen::Index n = s.conductance.rows();
  ASSERT_GT(n, 4);
  for (Eigen::Index i = 0; i < n; ++i) s.conductance.coeffRef(i, i) *= 1.0 + 1e-3 * static_cast<double>(i % 7);
  const Eigen::VectorXd r = s.conductance * Eigen::VectorXd::Ones(n);
  const double expected = r.cwiseAbs().maxCoeff() / s.conductance.diagonal().cwiseAbs().maxCoeff();
  EXPECT_GT(expected, 1e-6);  // not round-off: the check sees the scaled diagonal
  EXPECT_EQ(s.row_sum_residual(), expected);
  const Eigen::Index k = n / 3;
  const frictherm::thermal::SparseMatrix top = s.conductance.topRows(k), bottom = s.conductance.bottomRows(n - k);
  const fc::RowSumExtremes a = fc::row_sum_extremes(top, 0), b = fc::row_sum_extremes(bottom, k);
  EXPECT_EQ((fc::RowSumExtremes{std::max(a.sum, b.sum), std::max(a.diagonal, b.diagonal)}.residual()), expected);
  EXPECT_EQ(fc::row_sum_extremes(frictherm::thermal::SparseMatrix(0, n), 0).residual(), 0.0);
}

TEST(ThermalAssembly, PartitionOfUnityAndZeroRowSums3D) {
  const auto grid = make_grid<3>({0.0, 0.0, 0.0}, 1e-3, {6, 5, 5});
  fm::Particles<3> p;
  fill_box<3>(p, {1e-3, 1e-3, 1e-3}, {4e-3, 3e-3, 4e-3}, 1e-3, 2, 1900.0, 0,
              [](const fm::Vec<3>& x) { return 300.0 + 1e4 * x[2]; });
  const std::vector<fc::ThermalProperties> mats{{true, 1100.0, 0.45}};
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, shape, mats);
    EXPECT_LT(s.mass_residual(), 1e-13);
    EXPECT_LT(s.row_sum_residual(), 1e-13);
    const Eigen::MatrixXd K = Eigen::MatrixXd(s.conductance);
    EXPECT_EQ((K - K.transpose()).cwiseAbs().maxCoeff(), 0.0);
  }
}

// For shape functions that reproduce linear fields, Σ_j G_jp T_j = ∇T at every particle, so
// (K T)_i = k ∇T · Σ_p V_p G_ip, which vanishes wherever node i's support lies inside the body
// (Σ_p V_p G_ip is the particle quadrature of ∫∇S_i dV = 0; the regular lattice makes it exact).
// For a quadratic field T = x² the same quadrature gives the discrete Laplacian's action
// (K T)_i = −k ∇²T Σ_p V_p S_ip = −2 k Σ_p V_p S_ip on interior nodes.
TEST(ThermalAssembly, LinearFieldIsInEquilibriumAndQuadraticFieldGivesLaplacian) {
  const double h = 1e-3, k = 0.45;
  const auto grid = make_grid<2>({0.0, 0.0}, h, {12, 12});
  fm::Particles<2> p;
  fill_box<2>(p, {1e-3, 1e-3}, {11e-3, 11e-3}, h, 2, 1900.0, 0, [](const fm::Vec<2>&) { return 300.0; });
  const std::vector<fc::ThermalProperties> mats{{true, 1100.0, k}};
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, shape, mats);
    const auto n = static_cast<Eigen::Index>(s.size());
    Eigen::VectorXd lin(n), quad(n), vs = Eigen::VectorXd::Zero(n);
    for (Eigen::Index u = 0; u < n; ++u) {
      const fm::Vec<2> x = grid.node_position(s.grid_node[static_cast<std::size_t>(u)]);
      lin[u] = 300.0 + 2e4 * x[0] - 7e3 * x[1];
      quad[u] = 1e6 * x[0] * x[0];
    }
    // Σ_p V_p S_ip on the unknowns: M_i / (ρ C) for a single material.
    vs = s.mass / (1900.0 * 1100.0);
    const Eigen::VectorXd KT = s.conductance * lin, KQ = s.conductance * quad;
    const double scale = s.conductance.diagonal().maxCoeff() * lin.cwiseAbs().maxCoeff();
    int interior = 0;
    double worst_lin = 0.0, worst_quad = 0.0;
    for (Eigen::Index u = 0; u < n; ++u) {
      const fm::Vec<2> x = grid.node_position(s.grid_node[static_cast<std::size_t>(u)]);
      // Interior: two cells away from the body's edges (the widest support, 1.5 h, plus a particle).
      if (x[0] < 3e-3 - 1e-9 || x[0] > 9e-3 + 1e-9 || x[1] < 3e-3 - 1e-9 || x[1] > 9e-3 + 1e-9) continue;
      ++interior;
      worst_lin = std::max(worst_lin, std::fabs(KT[u]) / scale);
      worst_quad = std::max(worst_quad, std::fabs(KQ[u] + 2e6 * k * vs[u]) / (2e6 * k * vs[u]));
    }
    EXPECT_EQ(interior, 49);
    EXPECT_LT(worst_lin, 1e-13) << "linear field not in equilibrium";
    EXPECT_LT(worst_quad, 1e-10) << "quadratic field: not the Laplacian's action";
    // Globally K T sums to zero for any T (zero column sums): no heat is created by conduction.
    EXPECT_LT(std::fabs(KQ.sum()), 1e-12 * KQ.cwiseAbs().sum());
    RecordProperty(std::string("quadratic_rel_error_") + fm::to_string(shape), std::to_string(worst_quad));
  }
}

// Nodes whose heat capacity is below active_mass_fraction·max M are dropped; K keeps zero row sums
// and stays PSD, and Σ M over the unknowns + the dropped mass is the particles' heat capacity.
TEST(ThermalAssembly, TinyNodesAreDroppedWithoutBreakingConservation) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {8, 8});
  fm::Particles<2> p;
  fill_box<2>(p, {2e-3, 2e-3}, {6e-3, 6e-3}, 1e-3, 2, 1900.0, 0, [](const fm::Vec<2>&) { return 300.0; });
  // One particle nudged just past a cell edge: with linear shape functions the far nodes get S ~ 1e-4.
  p.position[0][0] -= 0.2501e-3;
  const std::vector<fc::ThermalProperties> mats{{true, 1100.0, 0.45}};
  fc::AssemblyOptions opt;
  opt.active_mass_fraction = 1e-3;
  const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, fm::ShapeKind::linear, mats, opt);
  EXPECT_GT(s.dropped_mass, 0.0);
  EXPECT_NEAR(s.mass.sum() + s.dropped_mass, total_heat_capacity(p, mats), 1e-13 * s.mass.sum());
  EXPECT_LT(s.row_sum_residual(), 1e-13);
  const Eigen::MatrixXd K = Eigen::MatrixXd(s.conductance);
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K).eigenvalues();
  EXPECT_GT(ev.minCoeff(), -1e-12 * ev.maxCoeff());
  for (std::size_t u = 0; u < s.size(); ++u) EXPECT_GT(s.mass[static_cast<Eigen::Index>(u)], 1e-3 * s.max_mass);
}

// Heat on nodes that are not unknowns (empty grid nodes, a rigid body's nodes) moves to unknowns
// without loss; heat on unknowns stays where it is.
TEST(HeatHandoff, HeatOnNodesWithoutUnknownsIsMovedWithoutLoss) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  const auto p = block_2d();
  const auto mats = two_materials();
  const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, fm::ShapeKind::ugimp, mats);
  std::vector<double> work(grid.node_count(), 0.0);
  const int on_body = grid.node_index({5, 4});               // an unknown
  const int next_to = grid.node_index({1, 3});               // empty, beside the block's unknowns
  const int far = grid.node_index({10, 8});                  // corner of the grid: no unknown near
  const int ghost = grid.node_index({-1, -1});               // a ghost node
  ASSERT_GE(s.unknown[static_cast<std::size_t>(on_body)], 0);
  ASSERT_LT(s.unknown[static_cast<std::size_t>(next_to)], 0);
  ASSERT_LT(s.unknown[static_cast<std::size_t>(far)], 0);
  work[static_cast<std::size_t>(on_body)] = 1.25e-3;
  work[static_cast<std::size_t>(next_to)] = 0.7;
  work[static_cast<std::size_t>(far)] = 3.3e-2;
  work[static_cast<std::size_t>(ghost)] = 1e-5;
  const fc::HeatDistribution d = fc::distribute_heat(grid, s, work);
  const double total = 1.25e-3 + 0.7 + 3.3e-2 + 1e-5;
  EXPECT_NEAR(d.total, total, 1e-16 * total);
  EXPECT_NEAR(d.joules.sum(), total, 1e-15 * total);
  EXPECT_NEAR(d.relocated, total - 1.25e-3, 1e-15 * total);
  EXPECT_EQ(d.joules[s.unknown[static_cast<std::size_t>(on_body)]], 1.25e-3);
  // The far corner's heat went to a single nearest unknown: the block's corner node (9, 6)... or
  // whichever unknown is nearest; it must be at most sqrt(1² + 2²) cells away.
  EXPECT_TRUE((d.joules.array() >= 0.0).all());
}

// The accumulator sums energy, not rates, and forgets it when cleared.
TEST(HeatHandoff, AccumulatorSumsEnergy) {
  fc::HeatAccumulator acc(20);
  std::vector<double> w(20, 0.0);
  w[3] = 1.0;
  w[7] = 0.25;
  for (int k = 0; k < 10; ++k) acc.add(w);
  acc.add(std::vector<double>{});  // no work this step
  EXPECT_DOUBLE_EQ(acc.total(), 12.5);
  EXPECT_DOUBLE_EQ(acc.work()[3], 10.0);
  acc.clear();
  EXPECT_EQ(acc.total(), 0.0);
  EXPECT_EQ(acc.work()[3], 0.0);
  EXPECT_THROW(acc.add(std::vector<double>(5, 1.0)), std::invalid_argument);
  w[2] = std::nan("");
  EXPECT_THROW(acc.add(w), std::invalid_argument);
}

// The particle book differences two sums of Σ m C T. Early in a 3D run (pbx_3d.json after 100 steps)
// the heat is 1/5000 of that sum over 85,000 particles of equal mass at 293.15 or 300 K, and a plain
// loop's rounding (its terms alike, so it adds up: about 1e-12 of the sum) was 8.6e-9 of the heat.
// Here the same: 120,000 such particles, heat 1/5000 of Σ m C T, spread unevenly; the book's change
// must be the particles' exact Σ m C (T1 − T0) to 1e-10 (a plain loop misses by 6e-9 here, the
// compensated sum by about 1e-14).
TEST(IncrementalMapping, ParticleEnergyBookKeepsSmallHeatAgainstLargeContent) {
  const std::vector<fc::ThermalProperties> mats{{true, 950.0, 0.4}, {true, 2280.0, 0.2}};
  fm::Particles<3> p;
  const std::size_t n = 120000;
  for (std::size_t k = 0; k < n; ++k) {
    p.add(fm::Vec<3>::Zero(), fm::Vec<3>::Constant(5e-7), 1e-14, 1e-18, static_cast<int>(k % 5 == 0), 0,
          k % 3 == 0 ? 293.15 : 300.0);
  }
  const double e0 = fc::particle_thermal_energy(p, mats);
  std::vector<double> T0(p.temperature.begin(), p.temperature.end());
  for (std::size_t k = 0; k < n; ++k) {  // ΔT from 0 to 0.54 K
    const double x = static_cast<double>(k);
    p.temperature[k] += 0.18 * std::pow(std::sin(0.011 * x), 8) * (k % 7 == 0 ? 3.0 : 1.0);
  }
  long double exact = 0.0L;  // each T1 − T0 is exact (Sterbenz); long double for the sum
  for (std::size_t k = 0; k < n; ++k)
    exact += static_cast<long double>(p.mass[k] * mats[static_cast<std::size_t>(p.material[k])].heat_capacity *
                                      (p.temperature[k] - T0[k]));
  const double heat = static_cast<double>(exact);
  ASSERT_GT(heat, 1.5e-4 * e0);
  ASSERT_LT(heat, 3e-4 * e0);
  EXPECT_NEAR(fc::particle_thermal_energy(p, mats) - e0, heat, 1e-10 * heat);
}

// T_p += Σ_i S_ip ΔT_i conserves Σ m_p C_p T_p exactly: Σ_p m_p C_p ΔT_p = Σ_i M_i ΔT_i.
TEST(IncrementalMapping, ParticleEnergyChangeEqualsNodalEnergyChange) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  const auto mats = two_materials();
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    auto p = block_2d();
    const fc::NodalThermalSystem s = fc::assemble_thermal(grid, p, shape, mats);
    Eigen::VectorXd dT(static_cast<Eigen::Index>(s.size()));
    for (Eigen::Index u = 0; u < dT.size(); ++u) dT[u] = 5.0 * std::sin(0.7 * static_cast<double>(u)) + 2.0;
    const double e0 = fc::particle_thermal_energy(p, mats);
    const std::vector<double> rigid_before(p.temperature.end() - 8, p.temperature.end());
    fc::add_nodal_change_to_particles(grid, p, shape, mats, s, dT);
    const double de = fc::particle_thermal_energy(p, mats) - e0;
    const double expected = s.mass.dot(dT);
    // Round-off: e0 ~ 1e3 J carries ~1e-13 J of error, the change is ~4 J.
    EXPECT_NEAR(de, expected, 1e-12 * e0);
    // The rigid body (no thermal properties) keeps its temperatures.
    EXPECT_EQ(std::vector<double>(p.temperature.end() - 8, p.temperature.end()), rigid_before);
  }
}

namespace {

// Exact equality of two systems: unknowns, M, T and K's CSR arrays and values.
void expect_identical(const fc::NodalThermalSystem& a, const fc::NodalThermalSystem& b) {
  EXPECT_EQ(a.grid_node, b.grid_node);
  EXPECT_EQ(a.grid_mass, b.grid_mass);
  EXPECT_TRUE(a.mass == b.mass);
  EXPECT_TRUE(a.temperature == b.temperature);
  ASSERT_EQ(a.conductance.nonZeros(), b.conductance.nonZeros());
  ASSERT_EQ(a.conductance.rows(), b.conductance.rows());
  const auto nnz = static_cast<std::size_t>(a.conductance.nonZeros());
  const auto rows = static_cast<std::size_t>(a.conductance.rows());
  EXPECT_TRUE(std::equal(a.conductance.outerIndexPtr(), a.conductance.outerIndexPtr() + rows + 1,
                         b.conductance.outerIndexPtr()));
  EXPECT_TRUE(std::equal(a.conductance.innerIndexPtr(), a.conductance.innerIndexPtr() + nnz,
                         b.conductance.innerIndexPtr()));
  EXPECT_TRUE(std::equal(a.conductance.valuePtr(), a.conductance.valuePtr() + nnz, b.conductance.valuePtr()));
}

// The particles of block_2d with material 1 moved by `shift` along x.
fm::Particles<2> shifted_block(double shift) {
  fm::Particles<2> p = block_2d();
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == 1) p.position[k][0] += shift;
  return p;
}

}  // namespace

// The MPM step's stencils handed in as a StencilView (Simulation::current_stencils) give the system,
// the map back and the matrix-free gather of a fresh evaluation bit for bit; a view of another
// kernel or particle count is not used.
TEST(ThermalAssembly, StencilsOfTheStepGiveTheSameNumbers) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  const auto mats = two_materials();
  const fm::Particles<2> p = block_2d();
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    fm::dispatch_shape(shape, [&](auto kernel) {
      using Kernel = decltype(kernel);
      std::vector<fm::Stencil<2, Kernel>> st(p.size());
      for (std::size_t k = 0; k < p.size(); ++k) st[k].evaluate(grid, p.position[k], p.half_size[k]);
      const fm::StencilView<2> view{shape, st.data(), st.size()};
      const fm::StencilView<2> wrong_size{shape, st.data(), st.size() - 1};
      const fc::NodalThermalSystem own = fc::assemble_thermal(grid, p, shape, mats);
      expect_identical(own, fc::assemble_thermal(grid, p, shape, mats, {}, view));
      expect_identical(own, fc::assemble_thermal(grid, p, shape, mats, {}, wrong_size));
      // Map back with the stencils (the assembly's kept lists made stale by assembling elsewhere).
      fc::assemble_thermal(grid, shifted_block(0.3e-3), shape, mats);
      Eigen::VectorXd delta(own.mass.size());
      for (Eigen::Index u = 0; u < delta.size(); ++u) delta[u] = 0.01 * static_cast<double>(u % 7) - 0.02;
      fm::Particles<2> pa = p, pb = p;
      fc::add_nodal_change_to_particles(grid, pa, shape, mats, own, delta);
      fc::add_nodal_change_to_particles(grid, pb, shape, mats, own, delta, 0.0, nullptr, view);
      EXPECT_EQ(pa.temperature, pb.temperature);
      EXPECT_NE(pa.temperature, p.temperature);
      // Matrix-free gather and one sub-step.
      fc::ExplicitConduction<2> ea, eb;
      fc::NodalThermalSystem sa, sb;
      ea.gather(grid, p, shape, mats, {}, sa);
      eb.gather(grid, p, shape, mats, {}, sb, view);
      EXPECT_EQ(sa.grid_mass, sb.grid_mass);
      EXPECT_TRUE(sa.temperature == sb.temperature);
      const Eigen::VectorXd q = Eigen::VectorXd::Constant(sa.mass.size(), 1e-6);
      EXPECT_TRUE(ea.advance(sa, sa.temperature, q, {}, 1e-6, 1) == eb.advance(sb, sb.temperature, q, {}, 1e-6, 1));
    });
  }
}

// K's pattern is kept per layout: an assembly whose unknowns and non-zero products sit where the last
// one's did only refills the values, and equals a fresh build bit for bit; a changed layout (a
// particle moved into another cell) is built afresh.
TEST(ThermalAssembly, RefilledConductanceEqualsFreshBuild) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {10, 8});
  const auto other_grid = make_grid<2>({0.0, 0.0}, 1e-3, {12, 9});  // other node numbers: forgets the pattern
  const auto mats = two_materials();
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    const fm::Particles<2> small = shifted_block(1e-6), moved = shifted_block(0.6e-3);
    fc::assemble_thermal(grid, block_2d(), shape, mats);
    const fc::NodalThermalSystem refilled = fc::assemble_thermal(grid, small, shape, mats);  // same layout
    const fc::NodalThermalSystem after_refill = fc::assemble_thermal(grid, moved, shape, mats);  // new layout
    fc::assemble_thermal(other_grid, small, shape, mats);
    expect_identical(refilled, fc::assemble_thermal(grid, small, shape, mats));
    fc::assemble_thermal(other_grid, small, shape, mats);
    expect_identical(after_refill, fc::assemble_thermal(grid, moved, shape, mats));
    EXPECT_NE(refilled.conductance.nonZeros(), 0);
  }
}

namespace {

// ~6000 particles (enough for the assembly to use two threads: one per 2000), jittered off the
// lattice, of two conducting materials and a rigid strip without thermal properties, on 40 x 30 cells.
fm::Particles<2> large_block(double shift) {
  fm::Particles<2> p;
  auto T = [](const fm::Vec<2>& x) { return 300.0 + 2e3 * x[0] + 20.0 * std::cos(500.0 * x[1]); };
  fill_box<2>(p, {3e-3, 3e-3}, {33e-3, 23e-3}, 1e-3, 3, 1190.0, 1, T, 2e-3);
  fill_box<2>(p, {12e-3, 8e-3}, {20e-3, 16e-3}, 1e-3, 2, 1900.0, 0, T, 2e-3);
  fill_box<2>(p, {33e-3, 3e-3}, {35e-3, 23e-3}, 1e-3, 2, 7800.0, 2, T, 2e-3);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double a = static_cast<double>(k);
    p.position[k][0] += 0.1e-3 * std::sin(1.7 * a) + (p.material[k] == 1 ? shift : 0.0);
    p.position[k][1] += 0.1e-3 * std::cos(2.3 * a);
  }
  return p;
}

}  // namespace

// The assembly's passes, K's rows and the map back share their nodes, rows and particles between
// threads, each thread adding only into its own in particle order: the system is the same bit for bit
// on one and two threads, for a fresh pattern, a refilled one and a rebuilt one.
TEST(ThermalAssembly, SameNumbersOnOneAndTwoThreads) {
  const auto grid = make_grid<2>({0.0, 0.0}, 1e-3, {40, 30});
  const auto other_grid = make_grid<2>({0.0, 0.0}, 1e-3, {41, 30});  // forgets the kept pattern
  const auto mats = two_materials();
  const fm::Particles<2> first = large_block(0.0), nudged = large_block(1e-7), moved = large_block(0.4e-3);
  ASSERT_GE(first.size(), 4000u);
  const int threads_before = omp_get_max_threads();
  for (fm::ShapeKind shape : kShapes) {
    SCOPED_TRACE(fm::to_string(shape));
    std::vector<fc::NodalThermalSystem> systems[2];
    std::vector<double> mapped[2];
    for (int threads = 1; threads <= 2; ++threads) {
      omp_set_num_threads(threads);
      fc::assemble_thermal(other_grid, first, shape, mats);
      auto& s = systems[threads - 1];
      s.push_back(fc::assemble_thermal(grid, first, shape, mats));   // fresh pattern
      s.push_back(fc::assemble_thermal(grid, nudged, shape, mats));  // same layout: refilled
      s.push_back(fc::assemble_thermal(grid, moved, shape, mats));   // new layout: rebuilt
      Eigen::VectorXd delta(s.back().mass.size());
      for (Eigen::Index u = 0; u < delta.size(); ++u) delta[u] = 0.03 * static_cast<double>(u % 11) - 0.1;
      fm::Particles<2> p = moved;
      fc::add_nodal_change_to_particles(grid, p, shape, mats, s.back(), delta);
      mapped[threads - 1] = p.temperature;
    }
    omp_set_num_threads(threads_before);
    for (std::size_t i = 0; i < systems[0].size(); ++i) {
      SCOPED_TRACE(i);
      expect_identical(systems[0][i], systems[1][i]);
    }
    EXPECT_EQ(mapped[0], mapped[1]);
    EXPECT_NE(mapped[0], moved.temperature);
    // Not a vacuous comparison: the three systems differ from each other (nodal heat capacities on the
    // same grid; K's sizes may differ, so it is not compared across them).
    EXPECT_NE(systems[0][0].grid_mass, systems[0][1].grid_mass);
    EXPECT_NE(systems[0][1].grid_mass, systems[0][2].grid_mass);
  }
}
