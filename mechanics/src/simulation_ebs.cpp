// Extended B-splines as the MPM step's shape function (Kakouris, Chatzis & Triantafyllou 2024 §3.3,
// Algorithm 2): at the start of every step, per velocity field, the cell volume fractions, the cell
// and basis classification and the extension are rebuilt from the field's particles at x^n with
// their current volumes; then N^e_I(x_p) and ∇N^e_I(x_p) (eqs. 25–26) of every particle are stored
// flattened, as slots of the particle's velocity field, and every transfer of the step reads them
// (P2G, forces, G2P, MUSL remap, velocity gradient). See docs/ebs.md.
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <omp.h>

#include <sstream>

namespace frictherm::mechanics {

template <int Dim>
void Simulation<Dim>::prepare_extended_stencils() {
  // 1. One basis per velocity field: a body's own field with contact, the shared field of every
  //    deformable material without (its particles are then one discrete field, eqs. 19–23).
  EbsOptions eo;
  eo.occupation = opt_.ebs_occupation;
  eo.out_of_plane = Dim == 2 ? opt_.thickness : 1.0;  // Ω_c in the units of Particles::volume
  if (ebs_.bases.size() != fields_.size()) ebs_.bases.resize(fields_.size());
  // Nodes with a velocity condition (fixed faces, rigid boundary materials) keep their own
  // B-spline: a degenerate node has no weight, so a condition on it would not reach the body.
  ebs_.kept.resize(grid_.node_count());
  for (std::size_t i = 0; i < ebs_.kept.size(); ++i) ebs_.kept[i] = conditions_.fixed_mask[i] | conditions_.rigid_mask[i];
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    ebs_.ranges.clear();
    for (std::size_t m = 0; m < materials_.size(); ++m)
      if (layout_.field_of_material[m] == static_cast<int>(f) && layout_.material_end[m] > layout_.material_begin[m])
        ebs_.ranges.emplace_back(layout_.material_begin[m], layout_.material_end[m]);
    ebs_.bases[f].set_options(eo);
    ebs_.bases[f].set_kept_nodes(&ebs_.kept);
    try {
      ebs_.bases[f].rebuild(grid_, p_.position, p_.volume, ebs_.ranges);
    } catch (const std::exception& e) {
      std::ostringstream msg;
      msg << "step " << clock_.step << ", t = " << clock_.time << " s: extended B-spline of velocity field " << f;
      if (fields_[f].material >= 0) msg << " (material '" << materials_[static_cast<std::size_t>(fields_[f].material)].name << "')";
      msg << ": " << e.what();
      throw SimulationError(msg.str(), clock_.step, clock_.time, -1);
    }
  }

  // 2. Contact: a material's field covers the nodes its plain B-spline stencils reach. The extension
  //    only moves weight from degenerate nodes to stable ones, whose supports hold an interior cell
  //    of the body and so lie in that box: the box is the same as with the plain quadratic B-spline.
  if (contact_setup_.enabled) {
    for (std::size_t f = 0; f < fields_.size(); ++f) {
      const auto m = static_cast<std::size_t>(fields_[f].material);
      ebs_.bases[f].node_box(layout_.box_lo[m], layout_.box_hi[m]);
    }
    layout_fields(layout_.box_lo, layout_.box_hi);
  }

  // 3. Flatten: entries per particle, prefix sum, then slots, N^e and ∇N^e. Particles without a
  //    field (rigid materials acting through conditions_.rigid_mask) get no entries.
  PrecomputedStencils<Dim>& st = stencil_store_.extended;
  const std::size_t n = p_.size();
  st.begin.resize(n + 1);
  st.begin[0] = 0;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const int f = layout_.field_of_material[m];
    const long b = static_cast<long>(layout_.material_begin[m]), e = static_cast<long>(layout_.material_end[m]);
    if (f < 0) {
      for (long k = b; k < e; ++k) st.begin[static_cast<std::size_t>(k) + 1] = 0;
      continue;
    }
    const EbsBasis<Dim>& basis = ebs_.bases[static_cast<std::size_t>(f)];
#pragma omp parallel for num_threads(threads_.count) schedule(static)
    for (long kk = b; kk < e; ++kk) {
      const auto k = static_cast<std::size_t>(kk);
      EbsStencil<Dim> s;
      basis.evaluate(p_.position[k], s);
      st.begin[k + 1] = static_cast<std::size_t>(s.size());
    }
  }
  for (std::size_t k = 0; k < n; ++k) st.begin[k + 1] += st.begin[k];
  const std::size_t total = st.begin[n];
  st.slot.resize(total);
  st.S.resize(total);
  st.G.resize(total);

  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const int f = layout_.field_of_material[m];
    if (f < 0) continue;
    const EbsBasis<Dim>& basis = ebs_.bases[static_cast<std::size_t>(f)];
    const NodeIndexer<Dim> ix = fields_[static_cast<std::size_t>(f)].index;
    const bool whole_grid = !contact_setup_.enabled;  // the shared field: slot = grid node index
    const long b = static_cast<long>(layout_.material_begin[m]), e = static_cast<long>(layout_.material_end[m]);
#pragma omp parallel for num_threads(threads_.count) schedule(static)
    for (long kk = b; kk < e; ++kk) {
      const auto k = static_cast<std::size_t>(kk);
      EbsStencil<Dim> s;
      basis.evaluate(p_.position[k], s);
      std::size_t q = st.begin[k];
      auto put = [&](int slot, double S, const Vec<Dim>& G) {
        st.slot[q] = static_cast<std::int32_t>(slot);
        st.S[q] = S;
        st.G[q] = G;
        ++q;
      };
      if (s.table == EbsStencil<Dim>::plain) {  // no degenerate node near: the plain quadratic B-spline
        Stencil<Dim, QuadraticBSplineKernel> plain;
        for (int d = 0; d < Dim; ++d) plain.axis[d] = s.axis[d];
        plain.for_each(ix, put);
      } else {  // N^e through the cell's extension table (eqs. 25–26); grid node -> field slot
        s.for_each([&](int node, double S, const Vec<Dim>& G) {
          if (whole_grid) return put(node, S, G);
          const IVec<Dim> L = grid_.node_lattice(node);
          int slot = ix.shift;
          for (int d = 0; d < Dim; ++d) slot += (L[d] + Grid<Dim>::ghost) * ix.stride[d];
          put(slot, S, G);
        });
      }
    }
  }
}

template void Simulation<2>::prepare_extended_stencils();
template void Simulation<3>::prepare_extended_stencils();

}  // namespace frictherm::mechanics
