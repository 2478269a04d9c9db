#include <frictherm/mechanics/ellipse_packing.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Draws from std::mt19937_64 (whose output sequence the standard fixes) with this file's own
/// transformations, so a seed gives the same packing with every standard library.
class Draws {
 public:
  explicit Draws(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1), 53 random bits
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double normal() {  // Box–Muller, one of the pair
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

 private:
  std::mt19937_64 engine_;
};

/// Support function of an ellipse: h(n) = max_{x in E} n·(x − c) = sqrt(a² (n·u)² + b² (n·v)²).
double support(const GrainEllipse& e, double nx, double ny) {
  const double c = std::cos(e.angle), s = std::sin(e.angle);
  const double nu = nx * c + ny * s, nv = -nx * s + ny * c;
  return std::sqrt(e.a * e.a * nu * nu + e.b * e.b * nv * nv);
}

double separating_gap(const GrainEllipse& e1, const GrainEllipse& e2, double dx, double dy, double theta) {
  const double nx = std::cos(theta), ny = std::sin(theta);
  return nx * dx + ny * dy - support(e1, nx, ny) - support(e2, nx, ny);
}

/// max over θ of separating_gap, stopping early once `enough` is reached.
double separation(const GrainEllipse& e1, const GrainEllipse& e2, double dx, double dy, double enough) {
  constexpr int kSamples = 32;
  const double theta0 = std::atan2(dy, dx), step = 2.0 * kPi / kSamples;
  double best = -std::numeric_limits<double>::infinity(), best_theta = theta0;
  for (int k = 0; k < kSamples; ++k) {
    const double t = theta0 + (k <= kSamples / 2 ? k : k - kSamples) * step;  // near the centre line first
    const double f = separating_gap(e1, e2, dx, dy, t);
    if (f > best) best = f, best_theta = t;
    if (best >= enough) return best;
  }
  // Golden-section refinement around the best sample.
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = best_theta - step, hi = best_theta + step;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = separating_gap(e1, e2, dx, dy, x1), f2 = separating_gap(e1, e2, dx, dy, x2);
  for (int it = 0; it < 40 && std::max(f1, f2) < enough; ++it) {
    if (f1 > f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = separating_gap(e1, e2, dx, dy, x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = separating_gap(e1, e2, dx, dy, x2);
    }
  }
  return std::max({best, f1, f2});
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("ellipse packing: " + what);
}

void check(const EllipsePackingOptions& o) {
  require(o.width > 0.0 && o.height > 0.0 && std::isfinite(o.width) && std::isfinite(o.height),
          "width and height must be > 0");
  require(o.fraction > 0.0 && o.fraction < 0.9, "fraction must be in (0, 0.9)");
  require(o.major_min > 0.0 && o.major_max >= o.major_min && std::isfinite(o.major_max),
          "major axis bounds need 0 < major_min <= major_max");
  if (o.size_distribution == SizeDistribution::lognormal) {
    require(o.major_median > 0.0, "the log-normal median must be > 0");
    require(o.major_sigma >= 0.0 && std::isfinite(o.major_sigma), "the log-normal sigma must be >= 0");
  }
  require(o.aspect_min > 0.0 && o.aspect_min <= o.aspect_max && o.aspect_max <= 1.0,
          "aspect ratios need 0 < aspect_min <= aspect_max <= 1");
  require(o.gap >= 0.0 && o.edge_gap >= 0.0, "gap and edge_gap must be >= 0");
  require(o.max_attempts >= 1, "max_attempts must be >= 1");
  if (o.periodic)
    require(o.major_max + o.gap <= 0.5 * std::min(o.width, o.height),
            "periodic packings need major_max + gap <= half the rectangle's smaller side");
  else
    require(o.major_min + 2.0 * o.edge_gap <= std::min(o.width, o.height),
            "the smallest grain (major_min + 2 edge_gap) does not fit in the rectangle");
}

/// Grains near a point: a uniform grid of bins at least `reach` wide (reach = the largest centre
/// distance at which two grains can interact), wrapping when periodic.
class Bins {
 public:
  Bins(double w, double h, double reach, bool periodic) : w_(w), h_(h), periodic_(periodic) {
    nx_ = std::max(1, static_cast<int>(std::min(w / reach, 4096.0)));
    ny_ = std::max(1, static_cast<int>(std::min(h / reach, 4096.0)));
    bins_.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
  }
  void add(std::size_t grain, double x, double y) { bins_[index(bin(x, nx_, w_), bin(y, ny_, h_))].push_back(grain); }
  template <class F>
  bool all_of_near(double x, double y, F&& f) const {  // f(grain) for grains in the 3 x 3 bins around (x, y)
    const int bx = bin(x, nx_, w_), by = bin(y, ny_, h_);
    int seen_x[3], seen_y[3], nsx = 0, nsy = 0;
    for (int d = -1; d <= 1; ++d) {
      const int cx = wrap(bx + d, nx_), cy = wrap(by + d, ny_);
      if (cx >= 0 && std::find(seen_x, seen_x + nsx, cx) == seen_x + nsx) seen_x[nsx++] = cx;
      if (cy >= 0 && std::find(seen_y, seen_y + nsy, cy) == seen_y + nsy) seen_y[nsy++] = cy;
    }
    for (int i = 0; i < nsx; ++i)
      for (int j = 0; j < nsy; ++j)
        for (std::size_t g : bins_[index(seen_x[i], seen_y[j])])
          if (!f(g)) return false;
    return true;
  }

 private:
  static int bin(double v, int n, double len) { return std::clamp(static_cast<int>(v / len * n), 0, n - 1); }
  int wrap(int c, int n) const {
    if (c >= 0 && c < n) return c;
    return periodic_ ? (c + n) % n : -1;
  }
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x); }
  double w_, h_;
  bool periodic_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<std::size_t>> bins_;
};

struct Size {
  double a, b;
};

Size draw_size(const EllipsePackingOptions& o, Draws& rng) {
  double major = 0.0;
  if (o.size_distribution == SizeDistribution::uniform) {
    major = rng.uniform(o.major_min, o.major_max);
  } else {  // log-normal truncated to [major_min, major_max] by rejection
    for (int tries = 0;; ++tries) {
      require(tries < 100000, "the log-normal has almost no probability inside [major_min, major_max]");
      major = o.major_median * std::exp(o.major_sigma * rng.normal());
      if (major >= o.major_min && major <= o.major_max) break;
    }
  }
  const double aspect = rng.uniform(o.aspect_min, o.aspect_max);
  return {0.5 * major, 0.5 * major * aspect};
}

class Packer {
 public:
  Packer(const EllipsePackingOptions& o, EllipsePacking& p)
      : o_(o), p_(p), bins_(o.width, o.height, o.major_max + o.gap, o.periodic) {}

  /// Tries to place a grain of semi-axes (a, b); true when placed.
  bool place(const Size& s, Draws& rng) {
    for (long attempt = 0; attempt < o_.max_attempts; ++attempt) {
      GrainEllipse e;
      e.a = s.a;
      e.b = s.b;
      e.angle = o_.random_orientation ? rng.uniform(0.0, kPi) : o_.orientation;
      if (o_.periodic) {
        e.x = rng.uniform(0.0, o_.width);
        e.y = rng.uniform(0.0, o_.height);
      } else {
        const double c = std::cos(e.angle), sn = std::sin(e.angle);
        const double hx = std::sqrt(s.a * s.a * c * c + s.b * s.b * sn * sn) + o_.edge_gap;
        const double hy = std::sqrt(s.a * s.a * sn * sn + s.b * s.b * c * c) + o_.edge_gap;
        const double ux = rng.uniform(), uy = rng.uniform();
        if (2.0 * hx > o_.width || 2.0 * hy > o_.height) continue;  // this orientation does not fit
        e.x = hx + (o_.width - 2.0 * hx) * ux;
        e.y = hy + (o_.height - 2.0 * hy) * uy;
      }
      if (fits(e)) {
        bins_.add(p_.grains.size(), e.x, e.y);
        p_.grains.push_back(e);
        return true;
      }
    }
    return false;
  }

 private:
  void offset(const GrainEllipse& from, const GrainEllipse& to, double& dx, double& dy) const {
    dx = to.x - from.x;
    dy = to.y - from.y;
    if (o_.periodic) {  // minimum image (unique: interaction reach <= half the rectangle, see check())
      dx -= o_.width * std::round(dx / o_.width);
      dy -= o_.height * std::round(dy / o_.height);
    }
  }
  bool fits(const GrainEllipse& e) const {
    // Cheap tests on every neighbour first (inscribed disks closer than the gap: reject), then the
    // support-function separation for the undecided ones.
    std::vector<std::size_t>& undecided = undecided_;
    undecided.clear();
    const bool clear = bins_.all_of_near(e.x, e.y, [&](std::size_t g) {
      const GrainEllipse& q = p_.grains[g];
      double dx, dy;
      offset(q, e, dx, dy);
      const double d = std::hypot(dx, dy);
      if (d >= q.a + e.a + o_.gap) return true;
      if (d < q.b + e.b + o_.gap) return false;
      undecided.push_back(g);
      return true;
    });
    if (!clear) return false;
    for (std::size_t g : undecided) {
      double dx, dy;
      offset(p_.grains[g], e, dx, dy);
      if (separation(p_.grains[g], e, dx, dy, o_.gap) < o_.gap) return false;
    }
    return true;
  }
  const EllipsePackingOptions& o_;
  EllipsePacking& p_;
  Bins bins_;
  mutable std::vector<std::size_t> undecided_;
};

}  // namespace

double GrainEllipse::area() const { return kPi * a * b; }

bool GrainEllipse::contains(double px, double py) const {
  const double c = std::cos(angle), s = std::sin(angle);
  const double dx = px - x, dy = py - y;
  const double u = (c * dx + s * dy) / a, v = (-s * dx + c * dy) / b;
  return u * u + v * v <= 1.0;
}

double ellipse_separation(const GrainEllipse& e1, const GrainEllipse& e2) {
  return separation(e1, e2, e2.x - e1.x, e2.y - e1.y, std::numeric_limits<double>::infinity());
}

EllipsePacking generate_ellipse_packing(const EllipsePackingOptions& o) {
  check(o);
  EllipsePacking p;
  p.width = o.width;
  p.height = o.height;
  p.periodic = o.periodic;
  p.target_fraction = o.fraction;
  const double target = o.fraction * o.width * o.height;
  Draws rng(o.seed);
  // 1. Sizes until the total area is nearest the target: a grain is taken while it brings the total
  //    closer (area < 2 × what is missing).
  std::vector<Size> sizes;
  double drawn = 0.0;
  for (;;) {
    const Size s = draw_size(o, rng);
    const double area = kPi * s.a * s.b;
    if (!(area < 2.0 * (target - drawn))) break;
    sizes.push_back(s);
    drawn += area;
    require(sizes.size() <= 10000000, "more than 10^7 grains: the grains are too small for the rectangle");
  }
  // 2. Largest first (stable: ties keep draw order).
  std::vector<std::size_t> order(sizes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t i, std::size_t j) { return sizes[i].a * sizes[i].b > sizes[j].a * sizes[j].b; });
  Packer packer(o, p);
  double placed = 0.0;
  for (std::size_t i : order) {
    if (packer.place(sizes[i], rng))
      placed += kPi * sizes[i].a * sizes[i].b;
    else
      ++p.dropped;
  }
  // 3. Top up what dropped grains left missing, with further draws, until 50 in a row find no place.
  for (int failures = 0; failures < 50;) {
    const Size s = draw_size(o, rng);
    const double area = kPi * s.a * s.b;
    if (!(area < 2.0 * (target - placed))) break;
    if (packer.place(s, rng)) {
      placed += area;
      failures = 0;
    } else {
      ++p.dropped;
      ++failures;
    }
  }
  p.fraction = placed / (o.width * o.height);
  return p;
}

GrainLabels rasterise_packing(const EllipsePacking& p, double px, long* contested) {
  if (!(px > 0.0)) throw std::invalid_argument("rasterise_packing: pixel size must be > 0");
  const double fx = p.width / px, fy = p.height / px;
  const double nx = std::round(fx), ny = std::round(fy);
  if (nx < 1.0 || ny < 1.0 || std::fabs(fx - nx) > 1e-6 * std::max(1.0, fx) || std::fabs(fy - ny) > 1e-6 * std::max(1.0, fy))
    throw std::invalid_argument("rasterise_packing: the rectangle (" + std::to_string(p.width) + " x " +
                                std::to_string(p.height) + ") is not a whole number of pixels of " + std::to_string(px));
  if (nx * ny > 4e8) throw std::invalid_argument("rasterise_packing: more than 4e8 pixels");
  GrainLabels l;
  l.width = static_cast<int>(nx);
  l.height = static_cast<int>(ny);
  l.label.assign(static_cast<std::size_t>(l.width) * static_cast<std::size_t>(l.height), 0);
  l.pixel_count.assign(p.grains.size() + 1, 0);
  long clash = 0;
  const int images = p.periodic ? 1 : 0;
  for (std::size_t g = 0; g < p.grains.size(); ++g) {
    const GrainEllipse& e0 = p.grains[g];
    for (int ix = -images; ix <= images; ++ix)
      for (int iy = -images; iy <= images; ++iy) {
        GrainEllipse e = e0;
        e.x += ix * p.width;
        e.y += iy * p.height;
        // Pixel columns/rows whose centres may lie inside (bounding circle of radius a).
        const int c0 = std::max(0, static_cast<int>(std::floor((e.x - e.a) / px - 0.5)));
        const int c1 = std::min(l.width - 1, static_cast<int>(std::ceil((e.x + e.a) / px - 0.5)));
        const int r0 = std::max(0, static_cast<int>(std::floor((e.y - e.a) / px - 0.5)));  // rows from the bottom
        const int r1 = std::min(l.height - 1, static_cast<int>(std::ceil((e.y + e.a) / px - 0.5)));
        for (int rb = r0; rb <= r1; ++rb)
          for (int c = c0; c <= c1; ++c) {
            if (!e.contains((c + 0.5) * px, (rb + 0.5) * px)) continue;
            int& lab = l.label[static_cast<std::size_t>(l.height - 1 - rb) * static_cast<std::size_t>(l.width) +
                               static_cast<std::size_t>(c)];
            if (lab != 0) {
              ++clash;
              continue;  // the earlier grain keeps the pixel
            }
            lab = static_cast<int>(g) + 1;
            ++l.pixel_count[g + 1];
          }
      }
  }
  l.pixel_count[0] = l.label.size() - std::accumulate(l.pixel_count.begin() + 1, l.pixel_count.end(), std::size_t{0});
  if (contested) *contested = clash;
  return l;
}

GreyImage packing_image(const GrainLabels& labels, GrainGrey grey) {
  if (grey == GrainGrey::labels && labels.count() > 65535)
    throw std::invalid_argument("packing_image: " + std::to_string(labels.count()) +
                                " grains do not fit in 16-bit grey levels (at most 65535)");
  GreyImage img;
  img.width = labels.width;
  img.height = labels.height;
  img.max_value = (grey == GrainGrey::labels && labels.count() > 255) ? 65535 : 255;
  img.pixels.resize(labels.label.size());
  for (std::size_t k = 0; k < labels.label.size(); ++k) {
    const int l = labels.label[k];
    img.pixels[k] = static_cast<std::uint16_t>(l == 0 ? 0 : grey == GrainGrey::binary ? 255 : l);
  }
  return img;
}

}  // namespace frictherm::mechanics
