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
  if (ebs_.size() != fields_.size()) ebs_.resize(fields_.size());
  // Nodes with a velocity condition (fixed faces, rigid boundary materials) keep their own
  // B-spline: a degenerate node has no weight, so a condition on it would not reach the body.
  ebs_kept_.resize(grid_.node_count());
  for (std::size_t i = 0; i < ebs_kept_.size(); ++i) ebs_kept_[i] = fixed_mask_[i] | rigid_mask_[i];
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    ebs_ranges_.clear();
    for (std::size_t m = 0; m < materials_.size(); ++m)
      if (field_of_material_[m] == static_cast<int>(f) && material_end_[m] > material_begin_[m])
        ebs_ranges_.emplace_back(material_begin_[m], material_end_[m]);
    ebs_[f].set_options(eo);
    ebs_[f].set_kept_nodes(&ebs_kept_);
    try {
      ebs_[f].rebuild(grid_, p_.position, p_.volume, ebs_ranges_);
    } catch (const std::exception& e) {
      std::ostringstream msg;
      msg << "step " << step_ << ", t = " << time_ << " s: extended B-spline of velocity field " << f;
      if (fields_[f].material >= 0) msg << " (material '" << materials_[static_cast<std::size_t>(fields_[f].material)].name << "')";
      msg << ": " << e.what();
      throw SimulationError(msg.str(), step_, time_, -1);
    }
  }

  // 2. Contact: a material's field covers the nodes its plain B-spline stencils reach. The extension
  //    only moves weight from degenerate nodes to stable ones, whose supports hold an interior cell
  //    of the body and so lie in that box: the box is the same as with the plain quadratic B-spline.
  if (contact_setup_.enabled) {
    for (std::size_t f = 0; f < fields_.size(); ++f) {
      const auto m = static_cast<std::size_t>(fields_[f].material);
      ebs_[f].node_box(box_lo_[m], box_hi_[m]);
    }
    layout_fields(box_lo_, box_hi_);
  }

  // 3. Flatten: entries per particle, prefix sum, then slots, N^e and ∇N^e. Particles without a
  //    field (rigid materials acting through rigid_mask_) get no entries.
  PrecomputedStencils<Dim>& st = st_extended_;
  const std::size_t n = p_.size();
  st.begin.resize(n + 1);
  st.begin[0] = 0;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const int f = field_of_material_[m];
    const long b = static_cast<long>(material_begin_[m]), e = static_cast<long>(material_end_[m]);
    if (f < 0) {
      for (long k = b; k < e; ++k) st.begin[static_cast<std::size_t>(k) + 1] = 0;
      continue;
    }
    const EbsBasis<Dim>& basis = ebs_[static_cast<std::size_t>(f)];
#pragma omp parallel for num_threads(threads_) schedule(static)
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
    const int f = field_of_material_[m];
    if (f < 0) continue;
    const EbsBasis<Dim>& basis = ebs_[static_cast<std::size_t>(f)];
    const NodeIndexer<Dim> ix = fields_[static_cast<std::size_t>(f)].index;
    const bool whole_grid = !contact_setup_.enabled;  // the shared field: slot = grid node index
    const long b = static_cast<long>(material_begin_[m]), e = static_cast<long>(material_end_[m]);
#pragma omp parallel for num_threads(threads_) schedule(static)
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
