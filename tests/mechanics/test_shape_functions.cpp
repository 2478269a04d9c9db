// Shape functions: partition of unity, linear-field reproduction and gradients against finite
// differences, in 2D and 3D, including particles sitting on and next to cell edges.
#include <frictherm/mechanics/shape_functions.hpp>

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <vector>

using namespace frictherm::mechanics;

namespace {

template <int Dim>
Grid<Dim> make_grid() {
  Vec<Dim> lo, h;
  IVec<Dim> cells;
  for (int d = 0; d < Dim; ++d) {
    lo[d] = -0.3 + 0.1 * d;
    h[d] = 0.25 + 0.05 * d;  // rectangular cells
    cells[d] = 6;
  }
  return Grid<Dim>(lo, h, cells);
}

// Positions: random interior points plus points exactly on / within 1e-9 of cell edges and of the
// uGIMP transition points (distance lp and h - lp from a node), and next to the grid boundary.
template <int Dim>
std::vector<Vec<Dim>> sample_points(const Grid<Dim>& g, const Vec<Dim>& lp) {
  std::mt19937 rng(42);
  std::vector<Vec<Dim>> pts;
  const Vec<Dim> lo = g.lo(), hi = g.hi();
  for (int k = 0; k < 200; ++k) {
    Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) x[d] = std::uniform_real_distribution<double>(lo[d] + lp[d], hi[d] - lp[d])(rng);
    pts.push_back(x);
  }
  const double offsets[] = {0.0, 1e-9, -1e-9, 0.5, 0.25, 0.75};
  for (double o : offsets) {
    for (double extra : {0.0, lp[0], -lp[0]}) {
      Vec<Dim> x;
      for (int d = 0; d < Dim; ++d) x[d] = lo[d] + g.cell_size()[d] * (2.0 + o) + (d == 0 ? extra : 0.3 * g.cell_size()[d]);
      pts.push_back(x);
    }
  }
  Vec<Dim> near_lo = lo + lp, near_hi = hi - lp;  // particle domain touching the grid boundary
  pts.push_back(near_lo);
  pts.push_back(near_hi);
  return pts;
}

template <int Dim, class Kernel>
std::map<int, std::pair<double, Vec<Dim>>> nodal_values(const Grid<Dim>& g, const Vec<Dim>& x, const Vec<Dim>& lp) {
  Stencil<Dim, Kernel> s;
  s.evaluate(g, x, lp);
  std::map<int, std::pair<double, Vec<Dim>>> out;
  s.for_each(g, [&](int i, double S, const Vec<Dim>& G) {
    EXPECT_GE(i, 0);
    EXPECT_LT(i, static_cast<int>(g.node_count()));
    auto& e = out.try_emplace(i, 0.0, Vec<Dim>::Zero()).first->second;  // Eigen leaves vectors uninitialised
    e.first += S;
    e.second += G;
  });
  return out;
}

template <int Dim, class Kernel>
void check_kernel(double lp_fraction) {
  const Grid<Dim> g = make_grid<Dim>();
  const Vec<Dim> lp = lp_fraction * g.cell_size();
  for (const Vec<Dim>& x : sample_points(g, lp)) {
    const auto vals = nodal_values<Dim, Kernel>(g, x, lp);
    double sum = 0.0;
    Vec<Dim> gsum = Vec<Dim>::Zero(), xr = Vec<Dim>::Zero();
    Mat<Dim> grad_x = Mat<Dim>::Zero();
    for (const auto& [i, v] : vals) {
      EXPECT_GE(v.first, -1e-15);
      sum += v.first;
      gsum += v.second;
      const Vec<Dim> xi = g.node_position(i);
      xr += v.first * xi;
      grad_x += xi * v.second.transpose();
    }
    // Round-off bounds: a few ulps times the number of terms (27) and the coordinate size (~2).
    EXPECT_NEAR(sum, 1.0, 1e-13) << "partition of unity at " << x.transpose();
    EXPECT_LT(gsum.norm(), 1e-11) << "gradients sum to zero at " << x.transpose();
    EXPECT_LT((xr - x).norm(), 1e-13) << "linear reproduction at " << x.transpose();
    EXPECT_LT((grad_x - Mat<Dim>::Identity()).norm(), 1e-11) << "gradient of x is I at " << x.transpose();
    // Finite-difference gradient. Central differences with eps = 1e-7 h have truncation error
    // O(eps^2 S''') ~ 1e-14 relative, but uGIMP and linear are only piecewise smooth: points within
    // eps of a kink are skipped (their one-sided slopes differ, so no FD check is meaningful there).
    for (int d = 0; d < Dim; ++d) {
      const double eps = 1e-7 * g.cell_size()[d];
      Vec<Dim> xp = x, xm = x;
      xp[d] += eps;
      xm[d] -= eps;
      const auto vp = nodal_values<Dim, Kernel>(g, xp, lp);
      const auto vm = nodal_values<Dim, Kernel>(g, xm, lp);
      for (const auto& [i, v] : vals) {
        const double sp = vp.count(i) ? vp.at(i).first : 0.0;
        const double sm = vm.count(i) ? vm.at(i).first : 0.0;
        const double fd = (sp - sm) / (2.0 * eps);
        const double gp = vp.count(i) ? vp.at(i).second[d] : 0.0, gm = vm.count(i) ? vm.at(i).second[d] : 0.0;
        const bool kink = std::abs(gp - gm) > 1e-6 / g.cell_size()[d];
        if (kink) continue;
        EXPECT_NEAR(v.second[d], fd, 1e-6 / g.cell_size()[d]) << "node " << i << " dir " << d << " at " << x.transpose();
      }
    }
  }
}

}  // namespace

TEST(ShapeFunctions, Linear2D) { check_kernel<2, LinearKernel>(0.25); }
TEST(ShapeFunctions, Linear3D) { check_kernel<3, LinearKernel>(0.25); }
TEST(ShapeFunctions, UGIMP2D) { check_kernel<2, UGIMPKernel>(0.25); }
TEST(ShapeFunctions, UGIMP3D) { check_kernel<3, UGIMPKernel>(0.25); }
TEST(ShapeFunctions, UGIMPOneParticlePerCell2D) { check_kernel<2, UGIMPKernel>(0.5); }
TEST(ShapeFunctions, UGIMPThreeParticlesPerCell3D) { check_kernel<3, UGIMPKernel>(1.0 / 6.0); }
TEST(ShapeFunctions, QuadraticBSpline2D) { check_kernel<2, QuadraticBSplineKernel>(0.25); }
TEST(ShapeFunctions, QuadraticBSpline3D) { check_kernel<3, QuadraticBSplineKernel>(0.25); }

TEST(ShapeFunctions, UGIMPValuesByHand) {
  // h = 1, lp = 1/4: particle centred on a node gives S = 1 - lp/(2h) = 0.875 there and
  // (h+lp-h)^2/(4 h lp) = 0.0625 at each neighbour.
  double g;
  EXPECT_DOUBLE_EQ(UGIMPKernel::weight(0.0, 1.0, 0.25, g), 0.875);
  EXPECT_DOUBLE_EQ(g, 0.0);
  EXPECT_DOUBLE_EQ(UGIMPKernel::weight(1.0, 1.0, 0.25, g), 0.0625);
  EXPECT_DOUBLE_EQ(g, -0.25 / 0.5);
  EXPECT_DOUBLE_EQ(UGIMPKernel::weight(0.5, 1.0, 0.25, g), 0.5);  // linear region
  EXPECT_DOUBLE_EQ(UGIMPKernel::weight(1.25, 1.0, 0.25, g), 0.0);
}

TEST(ShapeFunctions, QuadraticBSplineValuesByHand) {
  Weights1D<3> w;
  QuadraticBSplineKernel::eval(2.0, 0.0, 1.0, 1.0, 0.0, w);  // on node 2
  EXPECT_EQ(w.base, 1);
  EXPECT_DOUBLE_EQ(w.w[0], 0.125);
  EXPECT_DOUBLE_EQ(w.w[1], 0.75);
  EXPECT_DOUBLE_EQ(w.w[2], 0.125);
}

TEST(ShapeFunctions, NamesRoundTrip) {
  for (auto k : {ShapeKind::linear, ShapeKind::ugimp, ShapeKind::quadratic_bspline})
    EXPECT_EQ(shape_kind_from_string(to_string(k)), k);
  EXPECT_THROW(shape_kind_from_string("cubic"), std::invalid_argument);
}
