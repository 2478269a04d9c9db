#pragma once
// Shape functions as tensor products of 1D kernels, evaluated per particle into a compact stencil
// (base node + 1D weights and derivatives per direction). Particle loops are templated on the kernel,
// so the choice costs no virtual call: `dispatch_shape(kind, f)` calls f(Kernel{}) once per pass.
// The extended B-spline (EBS, docs/ebs.md) is built per body and per step by the MPM step itself;
// its per-particle weights are stored flattened (PrecomputedStencils) and read by the same loops.
#include <frictherm/mechanics/grid.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

namespace frictherm::mechanics {

enum class ShapeKind { linear, ugimp, quadratic_bspline, extended_bspline };

ShapeKind shape_kind_from_string(const std::string& name);  // throws std::invalid_argument
const char* to_string(ShapeKind kind);

/// Maps a node's lattice coordinates L (counted from the first ghost node) to a storage index
/// shift + Σ_d L_d stride_d: the whole grid (stride = grid strides, shift 0) or a box of it.
template <int Dim>
struct NodeIndexer {
  IVec<Dim> stride{};
  int shift = 0;
};

/// The indexer of a box of nodes [lo, lo + extent) stored contiguously (x fastest) from slot
/// `first`: slot = first + Σ (L_d − lo_d) stride_d. Returns it and sets `count` to the box's nodes.
template <int Dim>
NodeIndexer<Dim> box_indexer(const IVec<Dim>& lo, const IVec<Dim>& extent, std::size_t first, std::size_t& count) {
  NodeIndexer<Dim> ix;
  count = 1;
  int shift = static_cast<int>(first);
  for (int d = 0; d < Dim; ++d) {
    ix.stride[d] = static_cast<int>(count);
    shift -= lo[d] * ix.stride[d];
    count *= static_cast<std::size_t>(extent[d]);
  }
  ix.shift = shift;
  return ix;
}

/// ⌊s⌋ as an int for s within int range: truncation corrected for negative s. Cheaper than
/// static_cast<int>(std::floor(s)) on baseline x86-64 (no SSE4.1 rounding instruction), same result.
inline int floor_to_int(double s) {
  const int t = static_cast<int>(s);
  return t - (s < static_cast<double>(t));
}

/// 1D weights of one particle: nodes base, base+1, ..., base+K-1 along one direction.
template <int K>
struct Weights1D {
  int base = 0;
  double w[K];
  double dw[K];
};

/// Bilinear / trilinear hat functions (K = 2).
struct LinearKernel {
  static constexpr int K = 2;
  static void eval(double x, double lo, double h, double inv_h, double /*lp*/, Weights1D<K>& out) {
    const double s = (x - lo) * inv_h;
    const int j = floor_to_int(s);
    const double xi = s - j;
    out.base = j;
    out.w[0] = 1.0 - xi;
    out.w[1] = xi;
    out.dw[0] = -inv_h;
    out.dw[1] = inv_h;
    (void)h;
  }
};

/// Undeformed GIMP (Bardenhagen & Kober 2004): hat function convolved with the particle's
/// characteristic function of half-width lp <= h/2, which stays at its initial size (K = 3).
struct UGIMPKernel {
  static constexpr int K = 3;
  /// S(d) and dS/dd for a particle of half-width lp at distance d from the node; inv_h = 1/h,
  /// inv_hlp = 1/(h lp) (one division per particle and axis instead of one per branch).
  static double weight(double d, double h, double lp, double inv_h, double inv_hlp, double& grad) {
    const double a = std::fabs(d);
    const double sgn = d < 0.0 ? -1.0 : 1.0;
    if (a < lp) {
      grad = -d * inv_hlp;
      return 1.0 - 0.5 * (d * d + lp * lp) * inv_hlp;
    }
    if (a < h - lp) {
      grad = -sgn * inv_h;
      return 1.0 - a * inv_h;
    }
    if (a < h + lp) {
      const double r = h + lp - a;
      grad = -0.5 * sgn * r * inv_hlp;
      return 0.25 * r * r * inv_hlp;
    }
    grad = 0.0;
    return 0.0;
  }
  static double weight(double d, double h, double lp, double& grad) {
    return weight(d, h, lp, 1.0 / h, 1.0 / (h * lp), grad);
  }
  static void eval(double x, double lo, double h, double inv_h, double lp, Weights1D<K>& out) {
    const double s = (x - lo) * inv_h;
    const int j = floor_to_int(s);
    out.base = (s - j < 0.5) ? j - 1 : j;
    const double inv_hlp = inv_h / lp;
    for (int a = 0; a < K; ++a) {
      const double d = x - (lo + h * (out.base + a));
      out.w[a] = weight(d, h, lp, inv_h, inv_hlp, out.dw[a]);
    }
  }
};

/// Node-centred uniform quadratic B-spline, support 1.5 h (K = 3).
struct QuadraticBSplineKernel {
  static constexpr int K = 3;
  static void eval(double x, double lo, double /*h*/, double inv_h, double /*lp*/, Weights1D<K>& out) {
    const double s = (x - lo) * inv_h;
    const int k = floor_to_int(s + 0.5);
    const double xi = s - k;  // in [-0.5, 0.5)
    out.base = k - 1;
    const double a = 0.5 - xi, b = 0.5 + xi;
    out.w[0] = 0.5 * a * a;
    out.w[1] = 0.75 - xi * xi;
    out.w[2] = 0.5 * b * b;
    out.dw[0] = -a * inv_h;
    out.dw[1] = -2.0 * xi * inv_h;
    out.dw[2] = b * inv_h;
  }
};

/// Tag of the extended B-spline in the MPM step's particle loops. Its 1D kernel is the quadratic
/// B-spline: where no per-body extension applies (rigid boundary particles marking nodes) it
/// evaluates as the plain quadratic B-spline.
struct ExtendedBSplineKernel : QuadraticBSplineKernel {};

/// Tensor-product stencil of one particle: Dim sets of 1D weights.
template <int Dim, class Kernel>
struct Stencil {
  static constexpr int K = Kernel::K;
  static constexpr int node_count = (Dim == 2) ? K * K : K * K * K;
  Weights1D<K> axis[Dim];

  /// Fill from position x and particle half-widths lp (uGIMP only uses lp).
  void evaluate(const Grid<Dim>& g, const Vec<Dim>& x, const Vec<Dim>& lp) {
    for (int d = 0; d < Dim; ++d)
      Kernel::eval(x[d], g.lo()[d], g.cell_size()[d], g.inverse_cell_size()[d], lp[d], axis[d]);
  }

  /// Lowest node of the stencil along each axis, in lattice coordinates counted from the first
  /// (ghost) node: 0 .. nodes_per_dim - 1.
  IVec<Dim> first_node() const {
    IVec<Dim> b;
    for (int d = 0; d < Dim; ++d) b[d] = axis[d].base + Grid<Dim>::ghost;
    return b;
  }

  /// Calls f(node_index, S_ip, G_ip) for every node of the stencil (zero weights included).
  template <class F>
  void for_each(const Grid<Dim>& g, F&& f) const {
    for_each(NodeIndexer<Dim>{g.strides(), 0}, std::forward<F>(f));
  }

  /// Same, with node indices given by an indexer (e.g. slots of one material's velocity field).
  template <class F>
  void for_each(const NodeIndexer<Dim>& ix, F&& f) const {
    const IVec<Dim>& st = ix.stride;
    const IVec<Dim> b = first_node();
    if constexpr (Dim == 2) {
      for (int j = 0; j < K; ++j) {
        const double wy = axis[1].w[j], dwy = axis[1].dw[j];
        const int row = ix.shift + (b[1] + j) * st[1] + b[0] * st[0];
        for (int i = 0; i < K; ++i) {
          const double wx = axis[0].w[i];
          Vec<2> grad(axis[0].dw[i] * wy, wx * dwy);
          f(row + i * st[0], wx * wy, grad);
        }
      }
    } else {
      for (int k = 0; k < K; ++k) {
        const double wz = axis[2].w[k], dwz = axis[2].dw[k];
        for (int j = 0; j < K; ++j) {
          const double wy = axis[1].w[j], dwy = axis[1].dw[j];
          const int row = ix.shift + (b[2] + k) * st[2] + (b[1] + j) * st[1] + b[0] * st[0];
          for (int i = 0; i < K; ++i) {
            const double wx = axis[0].w[i], dwx = axis[0].dw[i];
            Vec<3> grad(dwx * wy * wz, wx * dwy * wz, wx * wy * dwz);
            f(row + i * st[0], wx * wy * wz, grad);
          }
        }
      }
    }
  }
};

/// One particle's entries of PrecomputedStencils: same for_each call shape as Stencil. The slots
/// were computed with the particle's own velocity field, so the indexer argument is not used.
template <int Dim>
struct PrecomputedStencil {
  const std::int32_t* slot;
  const double* S;
  const Vec<Dim>* G;
  std::size_t begin, end;

  template <class F>
  void for_each(const NodeIndexer<Dim>& /*ix*/, F&& f) const {
    for (std::size_t e = begin; e < end; ++e) f(static_cast<int>(slot[e]), S[e], G[e]);
  }
  std::size_t size() const { return end - begin; }
};

/// Shape function values of every particle for one step, flattened (CSR): particle k owns entries
/// begin[k] .. begin[k+1]-1, each a nodal slot of its velocity field with S_ip and G_ip. Filled
/// once per step; the arrays keep their capacity, so steady runs do not allocate.
template <int Dim>
struct PrecomputedStencils {
  std::vector<std::size_t> begin{0};
  std::vector<std::int32_t> slot;
  std::vector<double> S;
  std::vector<Vec<Dim>> G;

  std::size_t particles() const { return begin.size() - 1; }
  std::size_t entries() const { return begin.back(); }
  PrecomputedStencil<Dim> operator[](std::size_t k) const {
    return {slot.data(), S.data(), G.data(), begin[k], begin[k + 1]};
  }
};

/// The ShapeKind of a kernel (extended_bspline has no Stencil: its weights are built per field).
template <class Kernel>
constexpr ShapeKind shape_kind_of() {
  if constexpr (std::is_same_v<Kernel, LinearKernel>) return ShapeKind::linear;
  else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return ShapeKind::ugimp;
  else return ShapeKind::quadratic_bspline;
}

/// Read-only view of every particle's stencil (by particle index) at the particles' current
/// positions, as the MPM step evaluates them: a plain array of Stencil<Dim, Kernel> for the kernel
/// named by `kind`. Empty (data == nullptr) when there is none to give.
template <int Dim>
struct StencilView {
  ShapeKind kind = ShapeKind::extended_bspline;
  const void* data = nullptr;
  std::size_t count = 0;
  /// The stencils if they are of this kernel and there are `particles` of them, else nullptr.
  template <class Kernel>
  const Stencil<Dim, Kernel>* as(std::size_t particles) const {
    if (data == nullptr || count != particles || kind != shape_kind_of<Kernel>()) return nullptr;
    return static_cast<const Stencil<Dim, Kernel>*>(data);
  }
};

/// Calls f(Kernel{}) with the kernel type named by kind: the one runtime switch per pass.
/// extended_bspline gives its underlying QuadraticBSplineKernel: code outside the MPM step (the
/// thermal assembly, the heat hand-off) uses the plain quadratic B-spline; Simulation::step builds
/// the extension itself (docs/ebs.md).
template <class F>
decltype(auto) dispatch_shape(ShapeKind kind, F&& f) {
  switch (kind) {
    case ShapeKind::linear: return f(LinearKernel{});
    case ShapeKind::ugimp: return f(UGIMPKernel{});
    case ShapeKind::quadratic_bspline:
    case ShapeKind::extended_bspline: return f(QuadraticBSplineKernel{});
  }
  throw std::logic_error("unknown shape function kind");
}

}  // namespace frictherm::mechanics
