#pragma once
// Seeded random packings of non-overlapping ellipses in a rectangle (grains of a PBX-like
// microstructure, Nairn, Bardenhagen & Smith 2018 section 3 and figure 8), and their rasterisation.
//
//   EllipsePackingOptions o;  o.width = o.height = 60e-6;  o.fraction = 0.5;
//   o.major_min = 12e-6;  o.major_max = 20e-6;  o.aspect_min = 0.5;  o.gap = 1e-6;  o.seed = 7;
//   EllipsePacking p = generate_ellipse_packing(o);          // p.fraction: achieved
//   GrainLabels l = rasterise_packing(p, 2e-6);              // label per pixel
//   write_pgm(packing_image(l, GrainGrey::labels), "grains.pgm");
//
// Random sequential addition: grain sizes are drawn until their total area is nearest the target,
// then placed largest first at uniformly random positions (and orientations), a position being
// accepted when the grain keeps at least `gap` from every grain placed before (and `edge_gap` from
// the rectangle's sides unless periodic). A grain that finds no place within `max_attempts` is
// dropped and the shortfall topped up with further draws. Deterministic for a seed on every
// platform: std::mt19937_64 feeds this file's own uniform, normal and log-normal draws (the standard
// library's distributions differ between implementations).
#include <frictherm/mechanics/image.hpp>
#include <frictherm/mechanics/microstructure.hpp>

#include <cstdint>
#include <vector>

namespace frictherm::mechanics {

/// An ellipse grain: centre, semi-axes a >= b, angle of the major axis from +x (rad, counter-clockwise).
struct GrainEllipse {
  double x = 0.0, y = 0.0;
  double a = 0.0, b = 0.0;
  double angle = 0.0;
  double area() const;
  /// (x, y) inside or on the ellipse (no periodic images).
  bool contains(double px, double py) const;
};

/// Distance between two ellipses when they are apart (the maximum over directions n of
/// n·(c2 − c1) − h1(n) − h2(n), h the support functions; a negative value when they overlap). The
/// maximisation is numerical and every value it returns is attained by some n, so the result never
/// exceeds the true distance: a pair it reports at >= g apart is at least g apart.
double ellipse_separation(const GrainEllipse& e1, const GrainEllipse& e2);

enum class SizeDistribution { uniform, lognormal };

struct EllipsePackingOptions {
  double width = 0.0, height = 0.0;  // the rectangle [0, width] x [0, height] (any length unit)
  double fraction = 0.5;             // target area fraction of grains, in (0, 0.9)
  SizeDistribution size_distribution = SizeDistribution::uniform;
  double major_min = 0.0, major_max = 0.0;  // major axis 2a: uniform range, or truncation of the log-normal
  double major_median = 0.0;                // log-normal: median of 2a
  double major_sigma = 0.0;                 // log-normal: standard deviation of ln(2a)
  double aspect_min = 1.0, aspect_max = 1.0;  // b/a, uniform in [aspect_min, aspect_max] within (0, 1]
  bool random_orientation = true;             // angle uniform in [0, π); else `orientation`
  double orientation = 0.0;                   // rad
  double gap = 0.0;       // minimum distance between grains
  double edge_gap = 0.0;  // minimum distance from a grain to the rectangle's sides (not periodic)
  bool periodic = false;  // grains may cross the sides and reappear on the opposite one
  std::uint64_t seed = 1;
  long max_attempts = 10000;  // random positions tried per grain before it is dropped
};

struct EllipsePacking {
  double width = 0.0, height = 0.0;
  bool periodic = false;
  std::vector<GrainEllipse> grains;  // in placement order (largest first); centres inside the rectangle
  double target_fraction = 0.0;
  double fraction = 0.0;  // achieved: Σ π a b / (width height)
  long dropped = 0;       // grains drawn but given up after max_attempts
};

/// Throws std::invalid_argument naming the offending option (e.g. "fraction must be in (0, 0.9)").
EllipsePacking generate_ellipse_packing(const EllipsePackingOptions& options);

/// Rasterises a packing: pixels of `pixel_size` (width and height must be whole numbers of pixels,
/// within 1e-6 of one), labelled by the grain whose ellipse holds the pixel centre (grain i -> label
/// i + 1, 0 binder; periodic images wrap). `contested`, when given, receives the number of pixel
/// centres inside two grains or more (0 for a valid packing).
GrainLabels rasterise_packing(const EllipsePacking& packing, double pixel_size, long* contested = nullptr);

/// What a grain pixel's grey level is: 255 for every grain, or its label (binder 0 either way;
/// max_value 255 when the labels fit in 8 bits, else 65535; at most 65535 grains).
enum class GrainGrey { binary, labels };
GreyImage packing_image(const GrainLabels& labels, GrainGrey grey);

}  // namespace frictherm::mechanics
