// Boundary material points (Kakouris et al. 2024 §3.4): generation from the geometry factories,
// ordering, perimeter, and motion with the grid velocity field.
#include <frictherm/mechanics/boundary_points.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace frictherm::mechanics;

namespace {

double max_chord(const std::vector<Vec<2>>& p) {
  double m = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) m = std::max(m, (p[(i + 1) % p.size()] - p[i]).norm());
  return m;
}

}  // namespace

TEST(BoundaryPoints, RectangleCountOrderPerimeter) {
  const double h = 0.025;
  const auto pts = sample_rectangle_boundary(Vec<2>(0.1, 0.2), Vec<2>(0.3, 0.3), h);
  // 0.2 / 0.025 = 8 parts on the long sides, 4 on the short ones.
  ASSERT_EQ(pts.size(), 24u);
  EXPECT_DOUBLE_EQ(pts[0][0], 0.1);
  EXPECT_DOUBLE_EQ(pts[0][1], 0.2);
  EXPECT_NEAR(pts[8][0], 0.3, 1e-15);  // second corner after 8 steps along +x: counter-clockwise
  EXPECT_NEAR(pts[8][1], 0.2, 1e-15);
  EXPECT_LE(max_chord(pts), h * (1 + 1e-12));
  BoundaryPoints<2> bp;
  bp.add_loop(3, pts, Vec<2>(h / 4, h / 4));
  EXPECT_NEAR(bp.loop_perimeter(0), 0.6, 1e-14);
  EXPECT_NEAR(bp.loop_signed_area2(0), 2 * 0.02, 1e-15);  // > 0: counter-clockwise, area 0.2 x 0.1
  EXPECT_EQ(bp.field[5], 3);
  EXPECT_EQ(bp.next[23], 0);  // closed
  EXPECT_EQ(bp.prev[0], 23);
  double trib = 0.0;
  for (std::size_t i = 0; i < bp.size(); ++i) trib += bp.tributary_length(i);
  EXPECT_NEAR(trib, 0.6, 1e-14);  // tributary lengths partition the perimeter
}

TEST(BoundaryPoints, DiskCountOrderPerimeter) {
  const double R = 0.01;
  const int n = 100;  // the Hertz disks of K §4.3.1: 100 segments
  const Vec<2> c(0.05, 0.04);
  const auto pts = sample_ellipse_boundary(c, Vec<2>(R, R), 0.3, 2 * M_PI * R / n);
  ASSERT_EQ(pts.size(), static_cast<std::size_t>(n));
  for (const auto& p : pts) EXPECT_NEAR((p - c).norm(), R, 1e-17 + 1e-15 * R);
  BoundaryPoints<2> bp;
  bp.add_loop(0, pts, Vec<2>::Constant(1e-4));
  // Inscribed regular n-gon: perimeter 2 n R sin(π/n), area n R² sin(2π/n)/2, exactly.
  EXPECT_NEAR(bp.loop_perimeter(0), 2 * n * R * std::sin(M_PI / n), 1e-15);
  EXPECT_NEAR(bp.loop_signed_area2(0), n * R * R * std::sin(2 * M_PI / n), 1e-15);
  // Equal chords (equal arc length).
  for (std::size_t i = 0; i < bp.size(); ++i) EXPECT_NEAR(bp.segment_length(i), 2 * R * std::sin(M_PI / n), 1e-15);
  // Close to the circle: relative perimeter error π²/(6 n²) = 1.6e-4.
  EXPECT_NEAR(bp.loop_perimeter(0) / (2 * M_PI * R) - 1.0, -M_PI * M_PI / (6.0 * n * n), 1e-8);
}

TEST(BoundaryPoints, EllipseEqualArcs) {
  const Vec<2> a(0.03, 0.01);
  const double spacing = 0.002;
  const auto pts = sample_ellipse_boundary(Vec<2>(0, 0), a, 0.0, spacing);
  // Ramanujan's perimeter (error ~1e-5 relative at this aspect ratio) against n chords of equal arcs.
  const double h = std::pow((a[0] - a[1]) / (a[0] + a[1]), 2);
  const double P = M_PI * (a[0] + a[1]) * (1 + 3 * h / (10 + std::sqrt(4 - 3 * h)));
  EXPECT_EQ(pts.size(), static_cast<std::size_t>(std::ceil(P / spacing)));
  for (const auto& p : pts) EXPECT_NEAR(std::pow(p[0] / a[0], 2) + std::pow(p[1] / a[1], 2), 1.0, 1e-12);
  double lo = 1e9, hi = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double l = (pts[(i + 1) % pts.size()] - pts[i]).norm();
    lo = std::min(lo, l);
    hi = std::max(hi, l);
  }
  // Equal arcs give chords equal up to the curvature sag: chord = s (1 − κ² s²/24), κ ≤ a0/a1² = 300 /m.
  EXPECT_LT((hi - lo) / hi, 300.0 * 300.0 * spacing * spacing / 24 + 1e-6);
  EXPECT_GT(polygon_signed_area2(pts), 0.0);
}

TEST(BoundaryPoints, PolygonIsMadeCounterClockwiseAndAnnulusHoleClockwise) {
  const std::vector<Vec<2>> cw{{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  const auto pts = sample_polygon_boundary(cw, 0.5);
  ASSERT_EQ(pts.size(), 8u);
  EXPECT_GT(polygon_signed_area2(pts), 0.0);
  const auto loops = sample_annulus_boundary(Vec<2>(0, 0), 0.3, 0.4, 0.01);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_NEAR(polygon_signed_area2(loops[0]) / 2, M_PI * 0.16, 1e-3 * 0.5);
  EXPECT_NEAR(polygon_signed_area2(loops[1]) / 2, -M_PI * 0.09, 1e-3 * 0.3);  // hole: material on the left
  EXPECT_THROW(sample_rectangle_boundary(Vec<2>(0, 0), Vec<2>(1, 1), 0.0), std::invalid_argument);
  BoundaryPoints<2> bp;
  EXPECT_THROW(bp.add_loop(-1, pts, Vec<2>::Zero()), std::invalid_argument);
  EXPECT_THROW(bp.add_loop(0, {{0, 0}, {1, 0}}, Vec<2>::Zero()), std::invalid_argument);
}

// Points follow the grid velocity: exact for a uniform field (partition of unity, renormalised over
// nodes with mass) and for a linear field (linear reproduction) with every kernel.
TEST(BoundaryPoints, MoveWithGridVelocity) {
  const Grid<2> grid(Vec<2>(0, 0), Vec<2>(0.01, 0.01), IVec<2>{20, 20});
  const Mat<2> L = (Mat<2>() << 0.3, -1.2, 0.7, 0.1).finished();
  const Vec<2> v0(0.5, -0.25);
  for (ShapeKind kind : {ShapeKind::linear, ShapeKind::ugimp, ShapeKind::quadratic_bspline}) {
    BoundaryPoints<2> bp;
    bp.add_loop(0, sample_ellipse_boundary(Vec<2>(0.1, 0.1), Vec<2>(0.043, 0.043), 0.0, 0.004), Vec<2>::Constant(0.0025));
    GridWeights<2> w{&grid, kind, {FieldNodes<2>::whole_grid(grid)}};
    std::vector<Vec<2>> nv(grid.node_count());
    for (std::size_t k = 0; k < nv.size(); ++k) nv[k] = v0 + L * grid.node_position(static_cast<int>(k));
    const std::vector<Vec<2>> x0 = bp.position;
    const double dt = 1e-3;
    bp.update_positions(w, nv, dt);
    for (std::size_t i = 0; i < bp.size(); ++i) {
      const Vec<2> v = v0 + L * x0[i];
      EXPECT_NEAR((bp.velocity[i] - v).norm(), 0.0, 1e-14) << to_string(kind);
      EXPECT_NEAR((bp.position[i] - (x0[i] + dt * v)).norm(), 0.0, 1e-16) << to_string(kind);
    }
    // Only half of the nodes carry mass: a uniform field is still gathered exactly (renormalised).
    std::vector<double> mass(grid.node_count(), 0.0);
    for (std::size_t k = 0; k < mass.size(); ++k) mass[k] = grid.node_position(static_cast<int>(k))[0] < 0.1 ? 1.0 : 0.0;
    std::fill(nv.begin(), nv.end(), v0);
    w.slot_mass = &mass;
    bp.update_positions(w, nv, dt);
    for (std::size_t i = 0; i < bp.size(); ++i)
      if (bp.position[i][0] < 0.095) {
        EXPECT_NEAR((bp.velocity[i] - v0).norm(), 0.0, 1e-15) << to_string(kind);
      }
  }
}
