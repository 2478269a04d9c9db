// Seeded random ellipse packings: achieved fraction, no overlaps (rasterised and analytic), the
// minimum gap, determinism, size-distribution moments, periodic wrapping and the guard when the
// target cannot be reached.
#include <frictherm/mechanics/ellipse_packing.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace frictherm::mechanics;

namespace {

constexpr double kPi = 3.14159265358979323846;

// 200 x 200 pixels of 1 (length unit = pixel), major axis 8-16 px, aspect 0.5-1, 1 px gap:
// about 230 grains at 50 %.
EllipsePackingOptions base_options() {
  EllipsePackingOptions o;
  o.width = o.height = 200.0;
  o.fraction = 0.5;
  o.major_min = 8.0;
  o.major_max = 16.0;
  o.aspect_min = 0.5;
  o.aspect_max = 1.0;
  o.gap = 1.0;
  o.edge_gap = 1.0;
  o.seed = 12345;
  return o;
}

/// Offset from a to b, minimum image when periodic.
void offset(const EllipsePacking& p, const GrainEllipse& a, const GrainEllipse& b, double& dx, double& dy) {
  dx = b.x - a.x;
  dy = b.y - a.y;
  if (p.periodic) {
    dx -= p.width * std::round(dx / p.width);
    dy -= p.height * std::round(dy / p.height);
  }
}

/// Boundary points of an ellipse shifted by (sx, sy).
std::vector<std::array<double, 2>> boundary(const GrainEllipse& e, int n, double sx = 0.0, double sy = 0.0) {
  std::vector<std::array<double, 2>> pts;
  const double c = std::cos(e.angle), s = std::sin(e.angle);
  for (int k = 0; k < n; ++k) {
    const double t = 2.0 * kPi * k / n;
    const double u = e.a * std::cos(t), v = e.b * std::sin(t);
    pts.push_back({e.x + sx + c * u - s * v, e.y + sy + s * u + c * v});
  }
  return pts;
}

/// Independent overlap check: every pair of grains near each other, sampled on 360 boundary points
/// each. Asserts that no sampled point of one grain lies inside the other, that the sampled
/// distance is at least gap − 2δ (δ: an upper bound of the chord between neighbouring samples; every
/// boundary point lies within δ/2 of a sample, so sampled − δ <= true distance <= sampled), and
/// that the library's ellipse_separation is a lower bound tight to 2δ. Returns the pairs checked.
int check_pairs_apart(const EllipsePacking& p, double gap) {
  constexpr int kN = 360;
  int pairs = 0;
  for (std::size_t i = 0; i < p.grains.size(); ++i)
    for (std::size_t j = i + 1; j < p.grains.size(); ++j) {
      const GrainEllipse& a = p.grains[i];
      const GrainEllipse& b = p.grains[j];
      double dx, dy;
      offset(p, a, b, dx, dy);
      if (std::hypot(dx, dy) > a.a + b.a + gap + 1.0) continue;
      ++pairs;
      GrainEllipse bb = b;  // b's image nearest a
      bb.x = a.x + dx;
      bb.y = a.y + dy;
      const auto pa = boundary(a, kN), pb = boundary(bb, kN);
      const double delta = 2.0 * kPi * std::max(a.a, bb.a) / kN;  // chord <= arc length
      double dmin = 1e300;
      int inside = 0;
      for (const auto& q : pa) {
        inside += bb.contains(q[0], q[1]);
        for (const auto& r : pb) dmin = std::min(dmin, std::hypot(q[0] - r[0], q[1] - r[1]));
      }
      for (const auto& r : pb) inside += a.contains(r[0], r[1]);
      EXPECT_EQ(inside, 0) << "grains " << i << " and " << j << " overlap";
      EXPECT_GE(dmin, gap - 2.0 * delta) << "grains " << i << " and " << j << " closer than the gap";
      const double sep = ellipse_separation(a, bb);
      EXPECT_LE(sep, dmin + 1e-9) << "separation must be a lower bound of the distance";
      EXPECT_GE(sep, dmin - 2.0 * delta) << "separation far below the sampled distance";
    }
  return pairs;
}

/// Coverage count per pixel from each grain's own rasterisation (periodic images included).
int max_coverage(const EllipsePacking& p, int n) {
  std::vector<int> count(static_cast<std::size_t>(n) * n, 0);
  const int images = p.periodic ? 1 : 0;
  for (const GrainEllipse& g : p.grains)
    for (int ix = -images; ix <= images; ++ix)
      for (int iy = -images; iy <= images; ++iy)
        for (int r = 0; r < n; ++r)
          for (int c = 0; c < n; ++c) {
            GrainEllipse e = g;
            e.x += ix * p.width;
            e.y += iy * p.height;
            if (std::fabs(c + 0.5 - e.x) > e.a + 1 || std::fabs(r + 0.5 - e.y) > e.a + 1) continue;
            if (e.contains(c + 0.5, r + 0.5)) ++count[static_cast<std::size_t>(r) * n + c];
          }
  return *std::max_element(count.begin(), count.end());
}

double raster_fraction(const GrainLabels& l) {
  return 1.0 - static_cast<double>(l.pixel_count[0]) / static_cast<double>(l.label.size());
}

}  // namespace

TEST(EllipsePacking, ReachesTheTargetFractionWithoutOverlap) {
  const EllipsePackingOptions o = base_options();
  const EllipsePacking p = generate_ellipse_packing(o);
  // Sizes are drawn while a grain brings the total nearer the target, so with every grain placed
  // |achieved − target| <= half the largest grain's area / rectangle = π 8² / 2 / 200² = 0.0025,
  // and a grain dropped late is topped up by further draws; 1 % absolute is the tolerance.
  // Near 50 % random sequential addition may give up on a grain or two in the last holes.
  EXPECT_LE(p.dropped, 5);
  EXPECT_NEAR(p.fraction, 0.5, 0.01);
  double area = 0.0;
  for (const auto& g : p.grains) area += g.area();
  EXPECT_NEAR(p.fraction, area / (o.width * o.height), 1e-12);
  EXPECT_GT(p.grains.size(), 150u);
  // Rasterised at 1 px: no pixel centre in two grains, by the library's own count and by an
  // independent per-grain coverage count.
  long contested = -1;
  const GrainLabels l = rasterise_packing(p, 1.0, &contested);
  EXPECT_EQ(contested, 0);
  EXPECT_EQ(max_coverage(p, 200), 1);
  // Pixel-centre area of a grain differs from π a b by lattice noise ~ perimeter^(1/2) px²; over the
  // whole image the relative difference stays well below 1 % (measured ~0.1 %).
  EXPECT_NEAR(raster_fraction(l), p.fraction, 0.005);
  // Grains stay inside the rectangle with edge_gap: the outer rows/columns of pixels are binder.
  for (int k = 0; k < 200; ++k) {
    EXPECT_EQ(l.at(k, 0), 0);
    EXPECT_EQ(l.at(k, 199), 0);
    EXPECT_EQ(l.at(0, k), 0);
    EXPECT_EQ(l.at(199, k), 0);
  }
  EXPECT_GT(check_pairs_apart(p, o.gap), 50);
  // Gap of 1 px between grains: the binary image's 4-connected grains are exactly the grains.
  const GrainLabels comp = label_grains(packing_image(l, GrainGrey::binary), 255, 255, Connectivity::four);
  EXPECT_EQ(comp.count(), static_cast<int>(p.grains.size()));
}

TEST(EllipsePacking, EightConnectedComponentsMatchGrainsWithATwoPixelGap) {
  // Pixel centres of two grains 2 px apart are >= 2 px apart, farther than any 8-neighbour (√2).
  EllipsePackingOptions o = base_options();
  o.gap = 2.0;
  o.fraction = 0.4;
  const EllipsePacking p = generate_ellipse_packing(o);
  const GrainLabels l = rasterise_packing(p, 1.0);
  const GrainLabels comp = label_grains(packing_image(l, GrainGrey::binary), 128, 255, Connectivity::eight);
  ASSERT_EQ(comp.count(), static_cast<int>(p.grains.size()));
  std::vector<std::size_t> a(l.pixel_count.begin() + 1, l.pixel_count.end());
  std::vector<std::size_t> b(comp.pixel_count.begin() + 1, comp.pixel_count.end());
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);  // the same grains, pixel for pixel
  check_pairs_apart(p, o.gap);
}

TEST(EllipsePacking, DeterministicForASeed) {
  EllipsePackingOptions o = base_options();
  const EllipsePacking p1 = generate_ellipse_packing(o), p2 = generate_ellipse_packing(o);
  ASSERT_EQ(p1.grains.size(), p2.grains.size());
  for (std::size_t i = 0; i < p1.grains.size(); ++i) {
    EXPECT_EQ(p1.grains[i].x, p2.grains[i].x);
    EXPECT_EQ(p1.grains[i].y, p2.grains[i].y);
    EXPECT_EQ(p1.grains[i].a, p2.grains[i].a);
    EXPECT_EQ(p1.grains[i].angle, p2.grains[i].angle);
  }
  const GreyImage i1 = packing_image(rasterise_packing(p1, 1.0), GrainGrey::labels);
  EXPECT_EQ(i1.pixels, packing_image(rasterise_packing(p2, 1.0), GrainGrey::labels).pixels);
  o.seed += 1;
  const GreyImage i3 = packing_image(rasterise_packing(generate_ellipse_packing(o), 1.0), GrainGrey::binary);
  const GreyImage i1b = packing_image(rasterise_packing(p1, 1.0), GrainGrey::binary);
  long differ = 0;
  for (std::size_t k = 0; k < i3.pixels.size(); ++k) differ += i3.pixels[k] != i1b.pixels[k];
  // Two independent 50 % packings disagree on about half the pixels (2 f (1 − f) = 0.5).
  EXPECT_GT(differ, static_cast<long>(0.3 * i3.pixels.size()));
}

TEST(EllipsePacking, UniformSizeMoments) {
  // With no grain dropped, the placed grains are the i.i.d. draws: major axis 2a ~ U(8, 16)
  // (mean 12, variance 64/12), aspect ~ U(0.5, 1) (mean 0.75, sd 0.144), angle ~ U(0, π). Tolerances
  // are 4 standard errors for N ≈ 180 grains. At 40 % no grain is dropped (dropping favours small
  // grains near jamming, which would bias the moments).
  EllipsePackingOptions o = base_options();
  o.fraction = 0.4;
  const EllipsePacking p = generate_ellipse_packing(o);
  ASSERT_EQ(p.dropped, 0);
  const double n = static_cast<double>(p.grains.size());
  double m1 = 0, m2 = 0, asp = 0, c2 = 0, s2 = 0;
  for (const auto& g : p.grains) {
    m1 += 2 * g.a / n;
    m2 += 4 * g.a * g.a / n;
    asp += g.b / g.a / n;
    c2 += std::cos(2 * g.angle) / n;
    s2 += std::sin(2 * g.angle) / n;
  }
  const double var = m2 - m1 * m1, var0 = 64.0 / 12.0;
  EXPECT_NEAR(m1, 12.0, 4 * std::sqrt(var0 / n));
  EXPECT_NEAR(var / var0, 1.0, 4 * std::sqrt(2.0 / n - 1.2 / n));  // var of s² for a uniform: σ⁴ (2/n − 1.2/n)
  EXPECT_NEAR(asp, 0.75, 4 * 0.5 / std::sqrt(12.0 * n));
  EXPECT_NEAR(c2, 0.0, 4 / std::sqrt(2 * n));  // cos 2θ has variance 1/2
  EXPECT_NEAR(s2, 0.0, 4 / std::sqrt(2 * n));
  for (const auto& g : p.grains) {
    ASSERT_GE(2 * g.a, 8.0);
    ASSERT_LE(2 * g.a, 16.0);
    ASSERT_GE(g.b / g.a, 0.5 - 1e-12);
  }
}

TEST(EllipsePacking, LogNormalMomentsAndPeriodicWrap) {
  // ln(2a) ~ N(ln 11, 0.25²) truncated to [4, 24] (3.9 and 3.1 σ: < 0.1 % of the mass cut). Periodic:
  // grains cross the sides; overlaps are checked through the minimum image.
  EllipsePackingOptions o = base_options();
  o.size_distribution = SizeDistribution::lognormal;
  o.major_median = 11.0;
  o.major_sigma = 0.25;
  o.major_min = 4.0;
  o.major_max = 24.0;
  o.periodic = true;
  const EllipsePacking p = generate_ellipse_packing(o);
  ASSERT_EQ(p.dropped, 0);
  EXPECT_NEAR(p.fraction, 0.5, 0.01);
  const double n = static_cast<double>(p.grains.size());
  double mean = 0, m2 = 0;
  for (const auto& g : p.grains) {
    mean += std::log(2 * g.a) / n;
    m2 += std::pow(std::log(2 * g.a), 2) / n;
  }
  const double sd = std::sqrt(m2 - mean * mean);
  EXPECT_NEAR(mean, std::log(11.0), 4 * 0.25 / std::sqrt(n));
  EXPECT_NEAR(sd, 0.25, 4 * 0.25 / std::sqrt(2 * n));
  bool crosses = false;
  for (const auto& g : p.grains) crosses = crosses || g.x < g.a || g.x > o.width - g.a;
  EXPECT_TRUE(crosses);
  long contested = -1;
  const GrainLabels l = rasterise_packing(p, 1.0, &contested);
  EXPECT_EQ(contested, 0);
  EXPECT_EQ(max_coverage(p, 200), 1);
  // Periodic: wrapped pieces are rasterised too, so the pixel fraction matches the analytic one.
  EXPECT_NEAR(raster_fraction(l), p.fraction, 0.005);
  check_pairs_apart(p, o.gap);
}

TEST(EllipsePacking, UnreachableTargetIsReportedNotFaked) {
  // Random sequential addition jams near 55 % for these grains and a 1 px gap: asking 70 % gives
  // less, with the dropped grains counted, and still no overlap.
  EllipsePackingOptions o = base_options();
  o.width = o.height = 100.0;
  o.fraction = 0.7;
  o.max_attempts = 2000;
  const EllipsePacking p = generate_ellipse_packing(o);
  EXPECT_LT(p.fraction, 0.65);
  EXPECT_GT(p.fraction, 0.45);
  EXPECT_GT(p.dropped, 0);
  long contested = -1;
  rasterise_packing(p, 1.0, &contested);
  EXPECT_EQ(contested, 0);
  check_pairs_apart(p, o.gap);
}

TEST(EllipsePacking, BadOptionsAreNamed) {
  auto message = [](const EllipsePackingOptions& o) {
    try {
      generate_ellipse_packing(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EllipsePackingOptions o = base_options();
  o.fraction = 0.95;
  EXPECT_NE(message(o).find("fraction must be in (0, 0.9)"), std::string::npos);
  o = base_options();
  o.aspect_max = 1.5;
  EXPECT_NE(message(o).find("aspect"), std::string::npos);
  o = base_options();
  o.periodic = true;
  o.major_max = 150.0;
  EXPECT_NE(message(o).find("half the rectangle"), std::string::npos);
  o = base_options();
  o.major_min = o.major_max = 250.0;
  EXPECT_NE(message(o).find("does not fit"), std::string::npos);
  const EllipsePacking p = generate_ellipse_packing(base_options());
  EXPECT_THROW(rasterise_packing(p, 0.3), std::invalid_argument);  // 200 / 0.3 is not whole
}
