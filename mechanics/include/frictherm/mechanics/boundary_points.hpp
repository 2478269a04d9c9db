#pragma once
// Boundary material points for penalty node-to-segment contact (Kakouris, Chatzis & Triantafyllou
// 2024 §3.4, "K·" below; docs/penalty_contact.md). Each body (discrete field D) carries closed loops
// of points on its physical boundary, ordered so that the material lies to the LEFT of each loop:
// outer boundaries counter-clockwise, holes clockwise. Consecutive points form the master segments
// (K §3.5): segment i runs from point i to next[i], so its outward normal is (t_y, −t_x) with t the
// unit tangent.
//
// Here the points are tracers: they carry no mass and move with their field's grid velocity,
// x_b ← x_b + Δt Σ_I S_I(x_b) v_I (the same PIC interpolation as the bulk particles), with the weights
// renormalised over the nodes where the field has mass. The paper instead gives them 0.1 % of the
// body's mass so those nodes are never empty (K Remark 3); the renormalisation is the equivalent for
// massless points and leaves the bulk mass untouched. 2D only; 3D (triangulated surfaces) is not
// implemented.
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace frictherm::mechanics {

// ---- boundary loops of the geometry factories of geometry.hpp (2D) ---------------------------------
/// Twice the signed area of a closed polygon (> 0 counter-clockwise).
double polygon_signed_area2(const std::vector<Vec<2>>& vertices);
/// Closed polygon sampled with points no farther apart than `spacing`: every edge is cut into
/// ceil(length/spacing) equal parts and the vertices are kept. Returned counter-clockwise (the input
/// is reversed if it is clockwise), first point = first vertex, not repeated at the end.
std::vector<Vec<2>> sample_polygon_boundary(const std::vector<Vec<2>>& vertices, double spacing);
/// Rectangle [lo, hi] (make_box), counter-clockwise from lo.
std::vector<Vec<2>> sample_rectangle_boundary(const Vec<2>& lo, const Vec<2>& hi, double spacing);
/// Ellipse (make_ellipse: semi-axes along the axes turned by `angle`), n = max(8, ceil(P/spacing))
/// points at equal arc length (P the perimeter), counter-clockwise from the end of the first semi-axis.
std::vector<Vec<2>> sample_ellipse_boundary(const Vec<2>& center, const Vec<2>& semi_axes, double angle,
                                            double spacing);
/// Annulus (make_annulus): { outer circle counter-clockwise, inner circle clockwise }.
std::vector<std::vector<Vec<2>>> sample_annulus_boundary(const Vec<2>& center, double inner_radius,
                                                         double outer_radius, double spacing);

/// The nodes of one field's nodal arrays: the box lo .. lo + extent − 1 of grid lattice nodes (counted
/// from the first ghost node, as Stencil::first_node) stored at slot index.shift + Σ L_d index.stride_d.
/// Simulation's VelocityField carries exactly these three members.
template <int Dim>
struct FieldNodes {
  IVec<Dim> lo{};
  IVec<Dim> extent{};
  NodeIndexer<Dim> index;
  /// The whole grid stored from `first` on.
  static FieldNodes whole_grid(const Grid<Dim>& g, int first = 0) {
    FieldNodes f;
    f.extent = g.nodes_per_dim();
    f.index = NodeIndexer<Dim>{g.strides(), first};
    return f;
  }
};

/// A point's weights on its own field's nodes (K·36: "the points' own basis"): calls
/// visit(slot, grid_node, S) for every stencil node inside the field's box with S ≠ 0 and, when
/// slot_mass is given, mass > min_mass and, with reference_mass (per field), mass ≥ sliver · S ·
/// reference_mass[field] (a node holding only a sliver of the body compared with the share S the
/// point would load it with is left out); the weights are then renormalised to sum to one over the
/// visited nodes (so a force scattered with them keeps its total, and a velocity gathered with them
/// ignores empty nodes). Nothing is visited if no node qualifies. Any ShapeKind; a custom basis (e.g.
/// EBS) can be used instead by any callable with the same signature as operator().
template <int Dim>
struct GridWeights {
  const Grid<Dim>* grid = nullptr;
  ShapeKind shape = ShapeKind::linear;
  std::vector<FieldNodes<Dim>> fields;             // by field id
  const std::vector<double>* slot_mass = nullptr;  // optional: per slot
  double min_mass = 0.0;
  const std::vector<double>* reference_mass = nullptr;  // optional: per field, e.g. its particle mass
  double sliver = 0.0;

  /// The node qualifies: mass above min_mass and not a sliver for weight S.
  bool keeps(int field, std::size_t slot, double S) const {
    if (!slot_mass) return true;
    const double m = (*slot_mass)[slot];
    if (!(m > min_mass)) return false;
    return !reference_mass || m >= sliver * std::fabs(S) * (*reference_mass)[static_cast<std::size_t>(field)];
  }

  template <class Visit>
  void operator()(int field, const Vec<Dim>& x, const Vec<Dim>& half_size, Visit&& visit) const {
    dispatch_shape(shape, [&](auto kernel) {
      using Kernel = decltype(kernel);
      Stencil<Dim, Kernel> st;
      st.evaluate(*grid, x, half_size);
      visit_stencil(st, field, visit);
    });
  }

 private:
  template <class St, class Visit>
  void visit_stencil(const St& st, int field, Visit& visit) const {
    constexpr int K = St::K;
    constexpr int n = St::node_count;
    const FieldNodes<Dim>& F = fields.at(static_cast<std::size_t>(field));
    const IVec<Dim> b = st.first_node();
    const IVec<Dim>& gs = grid->strides();
    int slot[n], node[n];
    double S[n];
    int m = 0;
    double sum = 0.0;
    for (int a = 0; a < n; ++a) {
      int rest = a, s = F.index.shift, g = 0;
      double w = 1.0;
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        const int k = rest % K;
        rest /= K;
        const int L = b[d] + k;
        w *= st.axis[d].w[k];
        if (L < F.lo[d] || L >= F.lo[d] + F.extent[d]) inside = false;
        s += L * F.index.stride[d];
        g += L * gs[d];
      }
      if (!inside || w == 0.0) continue;
      if (!keeps(field, static_cast<std::size_t>(s), w)) continue;
      slot[m] = s;
      node[m] = g;
      S[m] = w;
      sum += w;
      ++m;
    }
    if (m == 0 || !(sum > 0.0)) return;
    const double inv = 1.0 / sum;
    for (int a = 0; a < m; ++a) visit(slot[a], node[a], S[a] * inv);
  }
};

/// Boundary material points of all fields, structure of arrays. Points of one loop are contiguous.
template <int Dim>
struct BoundaryPoints {
  std::vector<Vec<Dim>> position;            // x_b (m)
  std::vector<Vec<Dim>> reference_position;  // X_b (m), at creation
  std::vector<Vec<Dim>> velocity;            // v_b (m/s), last interpolated
  std::vector<Vec<Dim>> half_size;           // l_p for uGIMP weights (m)
  std::vector<std::int32_t> field;           // owning discrete field (body)
  std::vector<std::int32_t> segment;         // the master segment the point starts (= its own index in 2D)
  std::vector<std::int32_t> next, prev;      // neighbours along the loop
  std::vector<std::int32_t> loop;            // loop id
  std::vector<std::size_t> loop_begin{0};    // points of loop l: loop_begin[l] .. loop_begin[l + 1] − 1
  std::vector<std::int32_t> loop_field;

  std::size_t size() const { return position.size(); }
  std::size_t loop_count() const { return loop_field.size(); }

  /// Appends one closed loop (material on its left) for `field`; returns the loop id. Throws
  /// std::invalid_argument for fewer than 3 points, a negative field or repeated consecutive points.
  int add_loop(int field, const std::vector<Vec<2>>& points, const Vec<Dim>& half_size,
               const Vec<Dim>& velocity = Vec<Dim>::Zero());
  /// Convenience: every loop of `loops`.
  void add_loops(int field, const std::vector<std::vector<Vec<2>>>& loops, const Vec<Dim>& half_size,
                 const Vec<Dim>& velocity = Vec<Dim>::Zero());

  /// Current length of segment i (point i → next[i]).
  double segment_length(std::size_t i) const;
  /// Current tributary length of point i: half of its two segments (K §3.4; docs: tributary area).
  double tributary_length(std::size_t i) const;
  /// Current perimeter of loop l.
  double loop_perimeter(std::size_t l) const;
  /// Twice the signed area enclosed by loop l (> 0 for a counter-clockwise loop).
  double loop_signed_area2(std::size_t l) const;

  /// Moves every point with its field's grid velocity (PIC, like the bulk particles):
  /// v_b = Σ_I S_I(x_b) v_I and x_b += Δt v_b, weights from `weights(field, x, half_size, visit)`
  /// (GridWeights or any callable of that shape) at the positions of the step's start.
  template <class Weights>
  void update_positions(const Weights& weights, const std::vector<Vec<Dim>>& nodal_velocity, double dt) {
    for (std::size_t i = 0; i < size(); ++i) {
      Vec<Dim> v = Vec<Dim>::Zero();
      weights(field[i], position[i], half_size[i], [&](int slot, int /*node*/, double S) {
        v += S * nodal_velocity[static_cast<std::size_t>(slot)];
      });
      velocity[i] = v;
    }
    for (std::size_t i = 0; i < size(); ++i) position[i] += dt * velocity[i];
  }
  /// Rigid motion of one field (prescribed-velocity bodies and standalone tests): x += Δt v.
  void translate_field(int f, const Vec<Dim>& v, double dt);
};

extern template struct BoundaryPoints<2>;
extern template struct BoundaryPoints<3>;

}  // namespace frictherm::mechanics
