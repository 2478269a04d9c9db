// Extended B-splines in the decomposed step (Kakouris, Chatzis & Triantafyllou 2024 §3.3, eqs. 19–26;
// docs/ebs.md): the serial EbsBasis, rebuilt on every rank from its velocity field's particles as the
// serial Simulation::prepare_extended_stencils rebuilds it (simulation_ebs.cpp), then every local
// particle's N^e, ∇N^e flattened in the serial order. The only additions are the exchanges:
//   * the kept nodes (fixed faces and rigid drives, EbsBasis::set_kept_nodes) OR-reduced over the grid;
//   * the field's particles (x_p, Ω_p) gathered from all ranks and put in the serial order (material,
//     then id), so that the volume fractions (eq. 19) are the serial sums, bit for bit, and the cell
//     and basis classification (eq. 20, §3.3.1) and the extension (eqs. 22–23) are the serial ones;
//   * a ghost layer of search_radius + 2 nodes (stencil_reach), so that an extended stencil, which
//     sits on the nearest interior cell of each degenerate node, lies in the rank's ghosted box.
// Cost: one allgather of (Dim + 4) doubles per particle per step and the rebuild of each body on
// every rank, O(particles + cells of the body's box); docs/distributed_run.md.
#include "distributed/decomposed_state.hpp"

#include <mpi.h>

#include <algorithm>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

template <int Dim>
void DecomposedMpm<Dim>::Impl::prepare_extended(SwarmFields& f) {
  const std::size_t n = static_cast<std::size_t>(f.n);
  const IVec<Dim>& gs = grid.strides();
  // Grid node index of DMDA node (i, j, k): the DMDA index is the serial lattice from the first ghost node.
  const auto grid_node = [&](PetscInt i, PetscInt j, PetscInt k) {
    PetscInt g = i * gs[0] + j * gs[1];
    if constexpr (Dim == 3) g += k * gs[2];
    return static_cast<std::size_t>(g);
  };

  // 1. Kept nodes, the serial conditions_.fixed_mask | conditions_.rigid_mask: this rank's owned fixed nodes and the nodes
  //    its rigid walls' particles drive (particle_to_grid marked them), OR-reduced over the ranks.
  ebs_keeps = !opt.fixed_faces.empty() || has_rigid;
  if (ebs_keeps) {
    ebs_kept.assign(grid.node_count(), 0);
    std::size_t q = 0;
    for (PetscInt k = owned_start[2]; k < owned_start[2] + owned_size[2]; ++k)
      for (PetscInt j = owned_start[1]; j < owned_start[1] + owned_size[1]; ++j)
        for (PetscInt i = owned_start[0]; i < owned_start[0] + owned_size[0]; ++i, ++q) ebs_kept[grid_node(i, j, k)] |= fixed_mask[q];
    if (has_rigid)
      for (PetscInt k = box_start[2]; k < box_start[2] + box_size[2]; ++k)
        for (PetscInt j = box_start[1]; j < box_start[1] + box_size[1]; ++j)
          for (PetscInt i = box_start[0]; i < box_start[0] + box_size[0]; ++i) {
            const auto l = static_cast<std::size_t>(local_node(i, j, k));
            for (int d = 0; d < Dim; ++d)
              if (driver[static_cast<std::size_t>(d)][l] >= 0) ebs_kept[grid_node(i, j, k)] |= static_cast<std::uint8_t>(1u << d);
          }
    MPI_Allreduce(MPI_IN_PLACE, ebs_kept.data(), static_cast<int>(ebs_kept.size()), MPI_UINT8_T, MPI_BOR, comm);
  }

  // 2. Every field's particles from all ranks, one allgather of (field, material, id, x_p, Ω_p) each
  //    (a rigid wall has no field, as in the serial step), ordered as the serial particle arrays.
  constexpr int unit = 3 + Dim + 1;
  ebs_send.clear();
  for (std::size_t k = 0; k < n; ++k) {
    if (rigid_wall(f.material[k])) continue;
    ebs_send.push_back(field_of(f.material[k]));
    ebs_send.push_back(static_cast<double>(f.material[k]));
    ebs_send.push_back(static_cast<double>(f.id[k]));
    for (int d = 0; d < Dim; ++d) ebs_send.push_back(f.x[Dim * k + static_cast<std::size_t>(d)]);
    ebs_send.push_back(f.volume[k]);
  }
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size), 0);
  const int mine = static_cast<int>(ebs_send.size());
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) displs[r] = displs[r - 1] + counts[r - 1];
  ebs_all.resize(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(ebs_send.data(), mine, MPI_DOUBLE, ebs_all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  const std::size_t total = ebs_all.size() / unit;
  const auto at = [&](std::size_t p, int c) { return ebs_all[p * unit + static_cast<std::size_t>(c)]; };
  ebs_order.resize(total);
  std::iota(ebs_order.begin(), ebs_order.end(), std::size_t{0});
  std::sort(ebs_order.begin(), ebs_order.end(), [&](std::size_t a, std::size_t b) {
    for (int c = 0; c < 3; ++c)
      if (at(a, c) != at(b, c)) return at(a, c) < at(b, c);
    return false;
  });

  // 3. One basis per velocity field, the serial rebuild on the gathered particles (eqs. 19–23).
  EbsOptions eo;
  eo.occupation = opt.ebs_occupation;
  eo.out_of_plane = Dim == 2 ? opt.thickness : 1.0;  // Ω_c in the units of the particle volumes
  ebs.resize(static_cast<std::size_t>(fields));
  std::size_t next = 0;
  for (int field = 0; field < fields; ++field) {
    ebs_position.clear(), ebs_volume.clear();
    for (; next < total && at(ebs_order[next], 0) == field; ++next) {
      Vec<Dim> x;
      for (int d = 0; d < Dim; ++d) x[d] = at(ebs_order[next], 3 + d);
      ebs_position.push_back(x);
      ebs_volume.push_back(at(ebs_order[next], 3 + Dim));
    }
    EbsBasis<Dim>& basis = ebs[static_cast<std::size_t>(field)];
    basis.set_options(eo);
    basis.set_kept_nodes(ebs_keeps ? &ebs_kept : nullptr);
    try {
      basis.rebuild(grid, ebs_position, ebs_volume, 0, ebs_position.size());
    } catch (const std::exception& e) {  // the same data on every rank: every rank throws
      std::ostringstream msg;
      msg << "decomposed mechanics: step " << traffic.steps << ", t = " << time << " s: extended B-spline of velocity field "
          << field;
      if (opt.contact) msg << " (material '" << materials[static_cast<std::size_t>(field)].name << "')";
      msg << ": " << e.what();
      throw std::runtime_error(msg.str());
    }
  }

  // 4. This rank's particles' entries, as the serial flattening: a cell without a degenerate node
  //    gives the plain quadratic B-spline's products, one with gives its table's sums (eqs. 25–26);
  //    nodes as DMDA lattice coordinates, inside the ghosted box.
  auto& st = stencils_extended;
  st.begin.assign(n + 1, 0);
  st.node.clear(), st.S.clear(), st.G.clear();
  const NodeIndexer<Dim> flat{gs, 0};
  EbsStencil<Dim> s;
  Stencil<Dim, QuadraticBSplineKernel> plain;
  for (std::size_t k = 0; k < n; ++k) {
    if (!rigid_wall(f.material[k])) {
      ebs[static_cast<std::size_t>(field_of(f.material[k]))].evaluate(Eigen::Map<const Vec<Dim>>(f.x + Dim * k), s);
      const auto put = [&](int node, double S, const Vec<Dim>& G) {
        IVec<Dim> L = grid.node_lattice(node);
        for (int d = 0; d < Dim; ++d) {
          L[d] += Grid<Dim>::ghost;
          const auto u = static_cast<std::size_t>(d);
          if (L[d] < box_start[u] || L[d] >= box_start[u] + box_size[u])
            throw std::logic_error("decomposed mechanics: particle " + std::to_string(f.id[k]) +
                                   "'s extended B-spline reaches a node outside its rank's ghosted box (ghost width " +
                                   std::to_string(width) + ")");
        }
        st.node.push_back(L), st.S.push_back(S), st.G.push_back(G);
      };
      if (s.table == EbsStencil<Dim>::plain) {
        for (int d = 0; d < Dim; ++d) plain.axis[d] = s.axis[d];
        plain.for_each(flat, put);
      } else {
        s.for_each(put);
      }
    }
    st.begin[k + 1] = st.node.size();
  }
}

template void DecomposedMpm<2>::Impl::prepare_extended(SwarmFields&);
template void DecomposedMpm<3>::Impl::prepare_extended(SwarmFields&);

}  // namespace frictherm::mechanics
