#include <frictherm/mechanics/boundary_points.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace frictherm::mechanics {

namespace {

void check_spacing(double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing))
    throw std::invalid_argument("boundary point spacing must be finite and > 0, got " + std::to_string(spacing));
}

Vec<2> rotate(const Vec<2>& v, double c, double s) { return Vec<2>(c * v[0] - s * v[1], s * v[0] + c * v[1]); }

}  // namespace

double polygon_signed_area2(const std::vector<Vec<2>>& v) {
  double a = 0.0;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) a += v[j][0] * v[i][1] - v[i][0] * v[j][1];
  return a;
}

std::vector<Vec<2>> sample_polygon_boundary(const std::vector<Vec<2>>& vertices, double spacing) {
  check_spacing(spacing);
  if (vertices.size() < 3) throw std::invalid_argument("boundary polygon needs at least 3 vertices");
  std::vector<Vec<2>> v = vertices;
  if (polygon_signed_area2(v) < 0.0) std::reverse(v.begin(), v.end());
  std::vector<Vec<2>> out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec<2>& a = v[i];
    const Vec<2>& b = v[(i + 1) % v.size()];
    const double len = (b - a).norm();
    if (!(len > 0.0)) throw std::invalid_argument("boundary polygon has two equal consecutive vertices");
    const int n = std::max(1, static_cast<int>(std::ceil(len / spacing * (1.0 - 1e-9))));
    for (int k = 0; k < n; ++k) out.push_back(a + (b - a) * (static_cast<double>(k) / n));
  }
  return out;
}

std::vector<Vec<2>> sample_rectangle_boundary(const Vec<2>& lo, const Vec<2>& hi, double spacing) {
  if (!(hi[0] > lo[0] && hi[1] > lo[1])) throw std::invalid_argument("rectangle boundary needs hi > lo");
  return sample_polygon_boundary({lo, Vec<2>(hi[0], lo[1]), hi, Vec<2>(lo[0], hi[1])}, spacing);
}

std::vector<Vec<2>> sample_ellipse_boundary(const Vec<2>& center, const Vec<2>& a, double angle, double spacing) {
  check_spacing(spacing);
  if (!(a[0] > 0.0 && a[1] > 0.0)) throw std::invalid_argument("ellipse boundary needs semi-axes > 0");
  // Arc length s(θ) of (a0 cos θ, a1 sin θ) by the midpoint rule on a fine table, then inverted.
  const int fine = 4096;
  std::vector<double> s(fine + 1, 0.0);
  for (int k = 0; k < fine; ++k) {
    const double th = 2.0 * M_PI * (k + 0.5) / fine;
    s[k + 1] = s[k] + std::hypot(a[0] * std::sin(th), a[1] * std::cos(th)) * (2.0 * M_PI / fine);
  }
  const double perimeter = a[0] == a[1] ? 2.0 * M_PI * a[0] : s[fine];
  const int n = std::max(8, static_cast<int>(std::ceil(perimeter / spacing * (1.0 - 1e-9))));
  const double c = std::cos(angle), sn = std::sin(angle);
  std::vector<Vec<2>> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double target = perimeter * k / n;
    const auto it = std::upper_bound(s.begin(), s.end(), target);
    const int j = std::clamp(static_cast<int>(it - s.begin()) - 1, 0, fine - 1);
    const double f = (target - s[j]) / (s[j + 1] - s[j]);
    const double th = a[0] == a[1] ? 2.0 * M_PI * k / n : 2.0 * M_PI * (j + f) / fine;  // disk: exact
    out.push_back(center + rotate(Vec<2>(a[0] * std::cos(th), a[1] * std::sin(th)), c, sn));
  }
  return out;
}

std::vector<std::vector<Vec<2>>> sample_annulus_boundary(const Vec<2>& center, double ri, double ro, double spacing) {
  if (!(ri > 0.0 && ro > ri)) throw std::invalid_argument("annulus boundary needs 0 < inner_radius < outer_radius");
  std::vector<std::vector<Vec<2>>> loops;
  loops.push_back(sample_ellipse_boundary(center, Vec<2>(ro, ro), 0.0, spacing));
  std::vector<Vec<2>> inner = sample_ellipse_boundary(center, Vec<2>(ri, ri), 0.0, spacing);
  std::reverse(inner.begin(), inner.end());  // hole: clockwise, material on the left
  loops.push_back(std::move(inner));
  return loops;
}

template <int Dim>
int BoundaryPoints<Dim>::add_loop(int f, const std::vector<Vec<2>>& pts, const Vec<Dim>& lp, const Vec<Dim>& v) {
  if constexpr (Dim != 2) {
    (void)f, (void)pts, (void)lp, (void)v;
    throw std::invalid_argument("boundary points: 3D (triangulated surfaces) is not implemented");
  } else {
    if (f < 0) throw std::invalid_argument("boundary loop: field id must be >= 0");
    if (pts.size() < 3) throw std::invalid_argument("boundary loop needs at least 3 points");
    for (std::size_t k = 0; k < pts.size(); ++k)
      if (!((pts[(k + 1) % pts.size()] - pts[k]).norm() > 0.0))
        throw std::invalid_argument("boundary loop has two equal consecutive points (index " + std::to_string(k) + ")");
    const int id = static_cast<int>(loop_field.size());
    const std::size_t first = size(), n = pts.size();
    for (std::size_t k = 0; k < n; ++k) {
      const auto i = static_cast<std::int32_t>(first + k);
      position.push_back(pts[k]);
      reference_position.push_back(pts[k]);
      velocity.push_back(v);
      half_size.push_back(lp);
      field.push_back(f);
      segment.push_back(i);
      next.push_back(static_cast<std::int32_t>(first + (k + 1) % n));
      prev.push_back(static_cast<std::int32_t>(first + (k + n - 1) % n));
      loop.push_back(id);
    }
    loop_field.push_back(f);
    loop_begin.push_back(size());
    return id;
  }
}

template <int Dim>
void BoundaryPoints<Dim>::add_loops(int f, const std::vector<std::vector<Vec<2>>>& loops, const Vec<Dim>& lp,
                                    const Vec<Dim>& v) {
  for (const auto& l : loops) add_loop(f, l, lp, v);
}

template <int Dim>
double BoundaryPoints<Dim>::segment_length(std::size_t i) const {
  return (position[static_cast<std::size_t>(next[i])] - position[i]).norm();
}

template <int Dim>
double BoundaryPoints<Dim>::tributary_length(std::size_t i) const {
  return 0.5 * (segment_length(i) + segment_length(static_cast<std::size_t>(prev[i])));
}

template <int Dim>
double BoundaryPoints<Dim>::loop_perimeter(std::size_t l) const {
  double p = 0.0;
  for (std::size_t i = loop_begin[l]; i < loop_begin[l + 1]; ++i) p += segment_length(i);
  return p;
}

template <int Dim>
double BoundaryPoints<Dim>::loop_signed_area2(std::size_t l) const {
  double a = 0.0;
  for (std::size_t i = loop_begin[l]; i < loop_begin[l + 1]; ++i) {
    const Vec<Dim>& p = position[i];
    const Vec<Dim>& q = position[static_cast<std::size_t>(next[i])];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return a;
}

template <int Dim>
void BoundaryPoints<Dim>::translate_field(int f, const Vec<Dim>& v, double dt) {
  for (std::size_t i = 0; i < size(); ++i)
    if (field[i] == f) {
      velocity[i] = v;
      position[i] += dt * v;
    }
}

template struct BoundaryPoints<2>;
template struct BoundaryPoints<3>;

}  // namespace frictherm::mechanics
