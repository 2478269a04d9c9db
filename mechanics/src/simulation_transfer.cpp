// XPIC(m) and FMPM(k) grid velocity filters (transfer.hpp): the truncated Neumann series
// v* = Σ_{j=0}^{order−1} (I − S⁺S)^j w0 on each deformable velocity field, one grid → particle → grid
// round trip per term. Hammerquist & Nairn 2017 (XPIC), Nairn & Hammerquist 2021 (FMPM).
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/transfer/grid_to_particle.hpp>

#include <omp.h>

namespace frictherm::mechanics {

template <int Dim>
template <class Stencils>
void Simulation<Dim>::filter_grid_velocity(const Stencils& st) {
  TransferScratch& X = transfer_;
  const std::size_t n = nodes_.mass.size();
  const std::vector<Vec<Dim>>& w0 = opt_.particle_update == ParticleUpdate::xpic ? X.start : nodes_.velocity;
  X.filtered.assign(w0.begin(), w0.end());  // j = 0
  if (opt_.transfer_order <= 1) return;
  X.term.assign(w0.begin(), w0.end());
  X.round_trip.resize(n);
  if (X.thread_acc.size() != static_cast<std::size_t>(threads_.count - 1)) X.thread_acc.resize(static_cast<std::size_t>(threads_.count - 1));
  for (auto& b : X.thread_acc) b.resize(n);
  const double mmin = empty_node_mass_;
  for (int j = 1; j < opt_.transfer_order; ++j) {
    // round_trip_i = (S⁺ S term)_i = Σ_p S_ip m_p (Σ_k S_kp term_k) / m_i
    parallel_region(threads_.count, [&] {
      const int tid = omp_get_thread_num();
      std::vector<Vec<Dim>>& acc = tid == 0 ? X.round_trip : X.thread_acc[static_cast<std::size_t>(tid - 1)];
      std::fill(acc.begin(), acc.end(), Vec<Dim>::Zero());
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        const int f = layout_.field_of_material[m];
        if (f < 0 || materials_[m].is_rigid()) continue;
        const NodeIndexer<Dim> ix = fields_[static_cast<std::size_t>(f)].index;
#pragma omp for schedule(static) nowait
        for (std::size_t k = layout_.material_begin[m]; k < layout_.material_end[m]; ++k) {
          filter_round_trip<Dim>(st[k], ix, p_.mass[k], [&](int i) -> const Vec<Dim>& { return X.term[static_cast<std::size_t>(i)]; },
                                 [&](int i, const Vec<Dim>& share) { acc[static_cast<std::size_t>(i)] += share; });
        }
      }
    });
    // term ← term − S⁺S term; zero at velocity conditions (v* keeps w0 there); filtered += term.
    parallel_for(threads_.count, n, [&](std::size_t s) {
      Vec<Dim> rt = X.round_trip[s];
      for (const auto& b : X.thread_acc) rt += b[s];
      const std::size_t node = static_cast<std::size_t>(layout_.slot_node[s]);
      const std::uint8_t bc = static_cast<std::uint8_t>(conditions_.fixed_mask[node] | conditions_.rigid_mask[node]);
      const Vec<Dim> next = filter_next_term<Dim>(X.term[s], rt, nodes_.mass[s], mmin, bc);
      X.term[s] = next;
      X.filtered[s] += next;
    });
  }
  // Rigid fields keep their prescribed velocity.
  for (const VelocityField<Dim>& F : fields_)
    if (F.rigid)
      for (std::size_t s = F.first; s < F.first + F.count; ++s) X.filtered[s] = w0[s];
}

#define FRICTHERM_INSTANTIATE_TRANSFER(D)                                                            \
  template void Simulation<D>::filter_grid_velocity(const std::vector<Stencil<D, LinearKernel>>&);   \
  template void Simulation<D>::filter_grid_velocity(const std::vector<Stencil<D, UGIMPKernel>>&);    \
  template void Simulation<D>::filter_grid_velocity(const std::vector<Stencil<D, QuadraticBSplineKernel>>&); \
  template void Simulation<D>::filter_grid_velocity(const PrecomputedStencils<D>&);
FRICTHERM_INSTANTIATE_TRANSFER(2)
FRICTHERM_INSTANTIATE_TRANSFER(3)
#undef FRICTHERM_INSTANTIATE_TRANSFER

}  // namespace frictherm::mechanics
