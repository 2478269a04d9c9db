#pragma once
// Extended B-splines (EBS) built on the node-centred uniform quadratic B-spline of shape_functions.hpp,
// as used by Kakouris, Chatzis & Triantafyllou 2024 §3.3 (eqs. 19-26; after Höllig 2003 and
// Yamaguchi et al. 2021). One EbsBasis per body (discrete field), rebuilt every step from that
// body's particles. Conventions and inferences: docs/ebs.md.
//
// Cells: the B-spline of node k is centred on k with support [k - 1.5 h, k + 1.5 h]; its knot spans
// are the "dual cells" [k - 0.5 h, k + 0.5 h]. The EBS cells of the paper are these knot spans, so
// cell k means the dual cell centred on node k and cells and nodes share the grid's flat index.
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace frictherm::mechanics {

enum class EbsCell : std::uint8_t { exterior, boundary, interior };  // Kakouris 2024 eq. 20
enum class EbsNode : std::uint8_t { inactive, degenerate, stable };  // Kakouris 2024 §3.3.1 step 3

struct EbsOptions {
  double occupation = 0.75;   // C_c: a cell is interior if φ_c > C_c (eq. 20)
  double out_of_plane = 1.0;  // Ω_c = Π h_d · out_of_plane: 2D thickness (m), 1D cross-section (m²); 3D ignores it
  int search_radius = 3;      // Q_J (nearest interior cell of degenerate J) is searched in J + [-r, r]^Dim;
                              // none found: J is kept as a plain B-spline (promoted_count)
};

template <int Dim>
class EbsBasis;

/// Extended basis of one point: the quadratic B-spline weights per axis plus the id of the point's
/// cell table. for_each calls f(node, S, G) once per node with a non-zero extended function
/// N^e_I = N_I + Σ_J E_IJ N_J (eqs. 25-26); nodes are distinct, all stable. Valid until the next
/// rebuild of its basis.
template <int Dim>
struct EbsStencil {
  static constexpr int K = 3;
  static constexpr int block = Dim == 1 ? 3 : (Dim == 2 ? 9 : 27);  // B-splines non-zero at a point
  static constexpr int plain = -1;                                  // all block nodes stable: plain B-spline
  static constexpr int empty = -2;                                  // cell without particles of the body

  const EbsBasis<Dim>* basis = nullptr;
  Weights1D<K> axis[Dim];
  int table = empty;

  /// Number of (node, S, G) entries for_each produces.
  int size() const;
  template <class F>
  void for_each(F&& f) const;
  /// Same call shape as Stencil<Dim, Kernel>::for_each, so templated scatter/gather code can take either.
  template <class F>
  void for_each(const Grid<Dim>& /*grid*/, F&& f) const { for_each(static_cast<F&&>(f)); }

 private:
  void block_values(double* S, Vec<Dim>* G) const;  // OBS values, local index a = i + 3 j + 9 k
};

/// Cell volume fractions, cell and basis classification, extension coefficients and per-cell
/// extension tables of one body. rebuild() costs O(particles + cells of the body's bounding box);
/// evaluate() and EbsStencil::for_each allocate nothing and are safe to call from many threads.
template <int Dim>
class EbsBasis {
 public:
  EbsBasis() = default;
  explicit EbsBasis(const EbsOptions& opt) : opt_(opt) {}

  const EbsOptions& options() const { return opt_; }
  void set_options(const EbsOptions& opt) { opt_ = opt; }
  /// Nodes (grid flat index) with a non-zero entry in `mask` are never degenerate: they keep their
  /// own B-spline (counted in promoted_count), so that a velocity condition on them (a fixed face,
  /// a rigid boundary) still acts on the body. nullptr: none. The mask must outlive the rebuilds and
  /// have grid.node_count() entries.
  void set_kept_nodes(const std::vector<std::uint8_t>* mask) { kept_ = mask; }

  /// Rebuild from particles begin..end-1 of the body (positions x_p, current volumes Ω_p).
  /// Throws std::out_of_range if a particle lies outside [lo - h/2, hi + h/2), std::invalid_argument
  /// for a non-positive or non-finite volume, a negative C_c or a non-positive out_of_plane.
  void rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position, const std::vector<double>& volume,
               std::size_t begin, std::size_t end);
  /// Same, for the particles listed in `particles` (bodies not stored contiguously).
  void rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position, const std::vector<double>& volume,
               const std::vector<std::size_t>& particles);
  /// Same, for the particles of several index ranges [first, second) (a body made of several
  /// materials, e.g. the shared velocity field of the MPM step without contact).
  void rebuild(const Grid<Dim>& grid, const std::vector<Vec<Dim>>& position, const std::vector<double>& volume,
               const std::vector<std::pair<std::size_t, std::size_t>>& ranges);

  /// Extended basis at x. The basis lives on the cells holding the body's particles; a point in any
  /// other cell (or outside the grid) gets an empty stencil.
  EbsStencil<Dim> evaluate(const Vec<Dim>& x) const {
    EbsStencil<Dim> s;
    evaluate(x, s);
    return s;
  }
  void evaluate(const Vec<Dim>& x, EbsStencil<Dim>& out) const;

  // ---- classification, by grid flat node index (cell k = knot span centred on node k) ----
  double volume_fraction(int node) const;  // φ_c, eq. 19
  EbsCell cell_state(int node) const;
  EbsNode node_state(int node) const;
  /// f(node, state) for every stable or degenerate node of the body.
  template <class F>
  void for_each_active_node(F&& f) const;
  /// f(I, E_IJ) for the stable nodes I of the extrapolation stencil of degenerate node J (eq. 23);
  /// nothing for other nodes. Zero coefficients are skipped.
  template <class F>
  void for_each_extension(int node_J, F&& f) const;
  /// Fills the degenerate nodes of a nodal field from its stable nodes: u_J = Σ_I E_IJ u_I (eq. 22).
  template <class T>
  void extrapolate(std::vector<T>& nodal) const;

  int stable_count() const { return stable_count_; }
  int degenerate_count() const { return degenerate_count_; }
  /// Nodes that would be degenerate but are kept (set_kept_nodes) or have no interior cell within
  /// search_radius: stable with their plain B-spline, e.g. bodies thinner than about 3 cells.
  int promoted_count() const { return promoted_count_; }
  /// Cells holding particles whose block has a degenerate node (the cells where EBS differs from OBS).
  int extended_cell_count() const { return extended_cells_; }
  /// Largest number of entries of any point's stencil (27 in 3D, 9 in 2D, 3 in 1D if nothing is extended).
  int max_stencil_size() const { return max_stencil_; }
  const Grid<Dim>& grid() const { return grid_; }
  /// Box of every node whose support meets a cell holding the body's particles, in lattice
  /// coordinates counted from the first ghost node (as NodeIndexer and Stencil::first_node): the
  /// nodes of the plain B-spline stencils of the body's particles. Every node with a non-zero N^e
  /// lies in it (each is stable, so its support holds an interior cell, which holds particles).
  /// hi < lo for a body without particles.
  void node_box(IVec<Dim>& lo, IVec<Dim>& hi) const {
    for (int d = 0; d < Dim; ++d) {
      lo[d] = org_[d] + Grid<Dim>::ghost;
      hi[d] = org_[d] + ext_[d] - 1 + Grid<Dim>::ghost;
    }
  }

 private:
  friend struct EbsStencil<Dim>;
  template <class Get>
  void rebuild_impl(const Grid<Dim>& grid, std::size_t n, Get get);
  bool in_region(const IVec<Dim>& l) const {
    for (int d = 0; d < Dim; ++d)
      if (l[d] < org_[d] || l[d] >= org_[d] + ext_[d]) return false;
    return true;
  }
  int local(const IVec<Dim>& l) const {  // caller checks in_region
    int k = 0;
    for (int d = 0; d < Dim; ++d) k += (l[d] - org_[d]) * rstride_[d];
    return k;
  }
  int local_of_node(int node) const;  // -1 outside the region
  void build_table(const IVec<Dim>& c);
  void dilate();

  EbsOptions opt_;
  const std::vector<std::uint8_t>* kept_ = nullptr;
  Grid<Dim> grid_;
  // Region: node lattice box org_ .. org_+ext_-1 = the body's bounding box of cells grown by one
  // node (every node whose support meets it); everything outside is exterior / inactive / empty.
  IVec<Dim> org_{}, ext_{}, rstride_{};
  std::vector<double> volume_;             // Σ Ω_p per cell (eq. 19 numerator)
  std::vector<EbsCell> cell_;              // eq. 20
  std::vector<EbsNode> node_;              // stable / degenerate / inactive
  std::vector<std::int32_t> ext_id_;       // degenerate node -> row of ext_*, else -1
  std::vector<std::int32_t> cell_table_;   // cell -> table id, EbsStencil::plain or ::empty
  // Extension of degenerate node J = ext_node_[e] (eq. 22): u_J = Σ E_IJ u_I over the non-zero
  // terms ext_begin_[e]..ext_begin_[e+1]-1 of (I = ext_I_, E_IJ = ext_E_).
  std::vector<int> ext_node_;
  std::vector<std::int32_t> ext_begin_{0};
  std::vector<std::int32_t> ext_I_;
  std::vector<double> ext_E_;
  // Cell tables (CSR): table t has outputs table_begin_[t]..table_begin_[t+1]-1; output o is node
  // out_node_[o] with N^e = Σ_{terms k of o} term_w_[k] · N_{block node term_a_[k]} (eq. 25).
  std::vector<std::int32_t> table_begin_{0};
  std::vector<std::int32_t> out_node_;
  std::vector<std::int32_t> out_begin_{0};
  std::vector<std::uint8_t> term_a_;
  std::vector<double> term_w_;
  struct Term {
    int node;
    int a;
    double w;
  };
  std::vector<Term> scratch_;
  std::vector<std::uint8_t> flags_, flags_tmp_;
  struct Offset {
    IVec<Dim> off;
    int d2;
  };
  std::vector<Offset> offsets_;           // search offsets of Q_J by increasing distance
  double cell_measure_ = 1.0;  // Ω_c
  int stable_count_ = 0, degenerate_count_ = 0, promoted_count_ = 0, max_stencil_ = 0, extended_cells_ = 0;
};

// ------------------------------------------------------------------------------------------------
// Inline hot paths.

template <int Dim>
void EbsBasis<Dim>::evaluate(const Vec<Dim>& x, EbsStencil<Dim>& out) const {
  out.basis = this;
  IVec<Dim> c;
  bool inside = true;
  for (int d = 0; d < Dim; ++d) {
    QuadraticBSplineKernel::eval(x[d], grid_.lo()[d], grid_.cell_size()[d], grid_.inverse_cell_size()[d], 0.0,
                                 out.axis[d]);
    c[d] = out.axis[d].base + 1;  // centre node = cell (knot span) holding x
    if (c[d] < 0 || c[d] > grid_.cells()[d]) inside = false;
  }
  out.table = (inside && in_region(c)) ? cell_table_[static_cast<std::size_t>(local(c))] : EbsStencil<Dim>::empty;
}

template <int Dim>
int EbsStencil<Dim>::size() const {
  if (table == plain) return block;
  if (table == empty) return 0;
  return basis->table_begin_[static_cast<std::size_t>(table) + 1] - basis->table_begin_[static_cast<std::size_t>(table)];
}

template <int Dim>
void EbsStencil<Dim>::block_values(double* S, Vec<Dim>* G) const {
  // Same products, in the same order, as Stencil<Dim, QuadraticBSplineKernel>::for_each.
  for (int a = 0; a < block; ++a) {
    [[maybe_unused]] const int i = a % 3, j = (a / 3) % 3, k = a / 9;
    if constexpr (Dim == 1) {
      S[a] = axis[0].w[i];
      G[a] = Vec<1>(axis[0].dw[i]);
    } else if constexpr (Dim == 2) {
      const double wx = axis[0].w[i], wy = axis[1].w[j];
      S[a] = wx * wy;
      G[a] = Vec<2>(axis[0].dw[i] * wy, wx * axis[1].dw[j]);
    } else {
      const double wx = axis[0].w[i], wy = axis[1].w[j], wz = axis[2].w[k];
      S[a] = wx * wy * wz;
      G[a] = Vec<3>(axis[0].dw[i] * wy * wz, wx * axis[1].dw[j] * wz, wx * wy * axis[2].dw[k]);
    }
  }
}

template <int Dim>
template <class F>
void EbsStencil<Dim>::for_each(F&& f) const {
  if (table == empty) return;
  if (table == plain) {  // no degenerate node in the block: the plain quadratic B-spline,
    const Grid<Dim>& g = basis->grid_;  // products as in Stencil<Dim, QuadraticBSplineKernel>::for_each
    const IVec<Dim>& st = g.strides();
    const int b0 = axis[0].base + Grid<Dim>::ghost;
    if constexpr (Dim == 1) {
      for (int i = 0; i < K; ++i) f(b0 + i, axis[0].w[i], Vec<1>(axis[0].dw[i]));
    } else if constexpr (Dim == 2) {
      const int b1 = axis[1].base + Grid<Dim>::ghost;
      for (int j = 0; j < K; ++j) {
        const double wy = axis[1].w[j], dwy = axis[1].dw[j];
        const int row = (b1 + j) * st[1];
        for (int i = 0; i < K; ++i) {
          const double wx = axis[0].w[i];
          f(row + b0 + i, wx * wy, Vec<2>(axis[0].dw[i] * wy, wx * dwy));
        }
      }
    } else {
      const int b1 = axis[1].base + Grid<Dim>::ghost, b2 = axis[2].base + Grid<Dim>::ghost;
      for (int k = 0; k < K; ++k) {
        const double wz = axis[2].w[k], dwz = axis[2].dw[k];
        for (int j = 0; j < K; ++j) {
          const double wy = axis[1].w[j], dwy = axis[1].dw[j];
          const int row = (b2 + k) * st[2] + (b1 + j) * st[1];
          for (int i = 0; i < K; ++i) {
            const double wx = axis[0].w[i], dwx = axis[0].dw[i];
            f(row + b0 + i, wx * wy * wz, Vec<3>(dwx * wy * wz, wx * dwy * wz, wx * wy * dwz));
          }
        }
      }
    }
    return;
  }
  double S[block];  // near degenerate nodes: eq. 25-26 through the cell's table
  Vec<Dim> G[block];
  block_values(S, G);
  const EbsBasis<Dim>& B = *basis;
  const auto t = static_cast<std::size_t>(table);
  for (std::int32_t o = B.table_begin_[t]; o < B.table_begin_[t + 1]; ++o) {
    double s = 0.0;
    Vec<Dim> grad = Vec<Dim>::Zero();
    for (std::int32_t q = B.out_begin_[static_cast<std::size_t>(o)]; q < B.out_begin_[static_cast<std::size_t>(o) + 1]; ++q) {
      const double e = B.term_w_[static_cast<std::size_t>(q)];
      const int a = B.term_a_[static_cast<std::size_t>(q)];
      s += e * S[a];
      grad += e * G[a];
    }
    f(static_cast<int>(B.out_node_[static_cast<std::size_t>(o)]), s, grad);
  }
}

template <int Dim>
template <class F>
void EbsBasis<Dim>::for_each_active_node(F&& f) const {
  for (std::size_t k = 0; k < node_.size(); ++k) {
    if (node_[k] == EbsNode::inactive) continue;
    IVec<Dim> l;
    int r = static_cast<int>(k);
    for (int d = Dim - 1; d >= 0; --d) {
      l[d] = org_[d] + r / rstride_[d];
      r %= rstride_[d];
    }
    f(grid_.node_index(l), node_[k]);
  }
}

template <int Dim>
template <class F>
void EbsBasis<Dim>::for_each_extension(int node_J, F&& f) const {
  const int loc = local_of_node(node_J);
  if (loc < 0 || ext_id_[static_cast<std::size_t>(loc)] < 0) return;
  const auto e = static_cast<std::size_t>(ext_id_[static_cast<std::size_t>(loc)]);
  for (std::int32_t q = ext_begin_[e]; q < ext_begin_[e + 1]; ++q)
    f(static_cast<int>(ext_I_[static_cast<std::size_t>(q)]), ext_E_[static_cast<std::size_t>(q)]);
}

template <int Dim>
template <class T>
void EbsBasis<Dim>::extrapolate(std::vector<T>& nodal) const {
  for (std::size_t e = 0; e < ext_node_.size(); ++e) {
    T acc{};
    bool first = true;
    for_each_extension(ext_node_[e], [&](int I, double E) {
      if (first) acc = E * nodal[static_cast<std::size_t>(I)];
      else acc += E * nodal[static_cast<std::size_t>(I)];
      first = false;
    });
    nodal[static_cast<std::size_t>(ext_node_[e])] = acc;
  }
}

extern template class EbsBasis<1>;
extern template class EbsBasis<2>;
extern template class EbsBasis<3>;

}  // namespace frictherm::mechanics
