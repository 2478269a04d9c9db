// The decomposed USL step (frictherm/mechanics/distributed.hpp) as a list of named phases; the
// exchanges (sum_to_owners, exchange_field_ranges, fields_to_owners, ghost_velocities,
// fields_to_ghosts, migrate) are phases of their own, the contact phases are in contact_phases.cpp
// and the per-material exchanges in sparse_exchange.cpp. The particle loops reuse the serial module's
// Stencil (shape_functions.hpp) through a NodeIndexer onto the ghosted box, and its
// linear_elastic_update (material.hpp), so they compute what the serial Simulation<2>'s USL step
// computes (mechanics/src/simulation_step.cpp, simulation_fields.cpp) on this rank's particles.
#include "distributed/decomposed_state.hpp"

#include <mpi.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

using detail::petsc_check;

namespace {

// Stencil nodes must lie in the ghosted box: holds when every particle sits with the owner of its
// nearest node and the DMDA's stencil width is the kernel's reach (stencil_reach).
template <class Kernel>
void check_in_box(const Stencil<2, Kernel>& st, PetscInt gxs, PetscInt gys, PetscInt gxm, PetscInt gym, long id) {
  const IVec<2> b = st.first_node();
  if (b[0] < gxs || b[1] < gys || b[0] + Kernel::K > gxs + gxm || b[1] + Kernel::K > gys + gym)
    throw std::logic_error("decomposed mechanics: particle " + std::to_string(id) + " (first node " +
                           std::to_string(b[0]) + ", " + std::to_string(b[1]) + ") reaches nodes outside its rank's " +
                           "ghosted box [" + std::to_string(gxs) + ", " + std::to_string(gxs + gxm) + ") x [" +
                           std::to_string(gys) + ", " + std::to_string(gys + gym) + ") (not migrated?)");
}

}  // namespace

// Phase 1, local: per velocity field m_i = Σ S_ip m_p, p_i = Σ S_ip m_p v_p,
// f_i = Σ (S_ip m_p g − V_p σ_p G_ip) (Nairn 2018 eqs. 1–3) and, with contact, Σ S_ip m_p x_p (or
// the displacement x_p − x_p^(0), eq. 9), Ω_i = Σ S_ip V_p and g_i = Σ G_ip V_p (eqs. 4–6), into the
// per-field values of the ghosted box, as the serial map_to_grid; each node records the range of
// fields reaching it. The stencils are kept for the later phases.
template <class Kernel>
void DecomposedMpm2D::Impl::particle_to_grid(double /*dt*/) {
  using namespace node_dof;
  SwarmFields f(swarm);
  auto& st = stencils<Kernel>();
  st.resize(static_cast<std::size_t>(f.n));
  std::fill(field_values.begin(), field_values.end(), 0.0);
  std::fill(field_lo.begin(), field_lo.end(), fields);
  std::fill(field_hi.begin(), field_hi.end(), -1);
  const NodeIndexer<2> ix = local_indexer();
  const Vec<2> g = opt.gravity;
  const bool contact = opt.contact;
  const bool displacement = opt.contact_options.separation == SeparationMethod::displacement;
  for (PetscInt k = 0; k < f.n; ++k) {
    auto& s = st[static_cast<std::size_t>(k)];
    s.evaluate(grid, Eigen::Map<const Vec<2>>(f.x + 2 * k), Eigen::Map<const Vec<2>>(f.half_size + 2 * k));
    check_in_box(s, gxs, gys, gxm, gym, f.id[k]);
    const int field = field_of(f.material[k]);
    const double mp = f.mass[k], Vp = f.volume[k];
    const Vec<2> mv = mp * Eigen::Map<const Vec<2>>(f.velocity + 2 * k);
    const Mat<2> Vsig = Vp * Eigen::Map<const Mat<2>>(f.stress + 4 * k);
    const Vec<2> mg = mp * g;
    const Eigen::Map<const Vec<2>> xp(f.x + 2 * k), x0(f.x0 + 2 * k);
    const Vec<2> mx = mp * (displacement ? Vec<2>(xp - x0) : Vec<2>(xp));
    s.for_each(ix, [&](int i, double S, const Vec<2>& G) {
      const std::size_t u = static_cast<std::size_t>(i);
      field_lo[u] = std::min<PetscInt>(field_lo[u], field);
      field_hi[u] = std::max<PetscInt>(field_hi[u], field);
      double* node = field_at(i, field);
      const Vec<2> fi = S * mg - Vsig * G;
      node[mass] += S * mp;
      node[momentum] += S * mv[0];
      node[momentum + 1] += S * mv[1];
      node[force] += fi[0];
      node[force + 1] += fi[1];
      if (contact) {
        const Vec<2> gi = Vp * G;
        node[mass_position] += S * mx[0];
        node[mass_position + 1] += S * mx[1];
        node[domain] += S * Vp;
        node[domain_gradient] += gi[0];
        node[domain_gradient + 1] += gi[1];
      }
    });
  }
}

// Phase 2, exchange: each local node's m, p, f summed over the fields reaching it into the DMDA's
// local vector (one field: its values exactly), and the ghost nodes' sums added into their owners.
void DecomposedMpm2D::Impl::sum_to_owners(double /*dt*/) {
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(local, &a), "VecGetArray");
  const PetscInt n = gxm * gym;
  for (PetscInt l = 0; l < n; ++l) {
    double* node = a + dof * l;
    std::fill(node, node + dof, 0.0);
    for (PetscInt fl = field_lo[static_cast<std::size_t>(l)]; fl <= field_hi[static_cast<std::size_t>(l)]; ++fl) {
      const double* v = field_at(l, static_cast<int>(fl));
      for (int c = 0; c < dof; ++c) node[c] += v[c];
    }
  }
  petsc_check(VecRestoreArray(local, &a), "VecRestoreArray");
  petsc_check(VecZeroEntries(global), "VecZeroEntries");
  petsc_check(DMLocalToGlobalBegin(da, local, ADD_VALUES, global), "DMLocalToGlobalBegin");
  petsc_check(DMLocalToGlobalEnd(da, local, ADD_VALUES, global), "DMLocalToGlobalEnd");
}

// Phase 7, owned nodes: velocity conditions of the fixed faces on p_i and f_i (the serial
// apply_velocity_bc: fixed components of both zeroed), then p_i^{n+1} = p_i^n + f_i dt.
void DecomposedMpm2D::Impl::momentum_update(double dt) {
  using namespace node_dof;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt q, double* node) {
    const std::uint8_t fixed = fixed_mask[static_cast<std::size_t>(q)];
    for (int d = 0; d < 2; ++d) {
      if (fixed & (1u << d)) node[momentum + d] = node[force + d] = 0.0;
      node[momentum + d] += node[force + d] * dt;
    }
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

// Phase 9, owned nodes: v_i = p_i^{n+1}/m_i, a_i = f_i/m_i per field, into the slots of p and f; fields
// below the empty-node mass get neither (as the serial update_grid).
void DecomposedMpm2D::Impl::nodal_velocities(double /*dt*/) {
  using namespace node_dof;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt, double* node) {
    const double m = node[mass];
    for (int d = 0; d < 2; ++d) {
      const double p = node[momentum + d], f = node[force + d];
      node[velocity + d] = m > empty_node_mass ? p / m : 0.0;
      node[acceleration + d] = m > empty_node_mass ? f / m : 0.0;
    }
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

// Phase 10, exchange: owners' v_i, a_i (the DMDA totals) copied to the ranks holding the node as a ghost.
void DecomposedMpm2D::Impl::ghost_velocities(double /*dt*/) {
  petsc_check(DMGlobalToLocalBegin(da, global, INSERT_VALUES, local), "DMGlobalToLocalBegin");
  petsc_check(DMGlobalToLocalEnd(da, global, INSERT_VALUES, local), "DMGlobalToLocalEnd");
}

// Phase 12, local (FLIP): v_p += dt Σ S_ip a_i, x_p += dt Σ S_ip v_i^{n+1} from the particle's own
// field, start-of-step stencils.
template <class Kernel>
void DecomposedMpm2D::Impl::grid_to_particle(double dt) {
  using namespace node_dof;
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(local, &a), "VecGetArrayRead");
  const NodeIndexer<2> ix = local_indexer();
  for (PetscInt k = 0; k < f.n; ++k) {
    Vec<2> acc = Vec<2>::Zero(), v = Vec<2>::Zero();
    const int field = field_of(f.material[k]);
    st[static_cast<std::size_t>(k)].for_each(ix, [&](int i, double S, const Vec<2>&) {
      const double* node = node_values(a, i, field);
      acc += S * Vec<2>(node[acceleration], node[acceleration + 1]);
      v += S * Vec<2>(node[velocity], node[velocity + 1]);
    });
    Eigen::Map<Vec<2>>(f.velocity + 2 * k) += dt * acc;
    Eigen::Map<Vec<2>>(f.x + 2 * k) += dt * v;
  }
  petsc_check(VecRestoreArrayRead(local, &a), "VecRestoreArrayRead");
}

// Phase 13, local: L_p = Σ_i v_i ⊗ G_ip, F ← (I + L dt) F, V = det(F) V0, hypoelastic σ (Jaumann).
template <class Kernel>
void DecomposedMpm2D::Impl::stress_update(double dt) {
  using namespace node_dof;
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(local, &a), "VecGetArrayRead");
  const NodeIndexer<2> ix = local_indexer();
  for (PetscInt k = 0; k < f.n; ++k) {
    const Material& material = materials[static_cast<std::size_t>(f.material[k])];
    const double lam = material.lame_lambda(), mu = material.shear_modulus();
    const int field = field_of(f.material[k]);
    Mat<2> L = Mat<2>::Zero();
    st[static_cast<std::size_t>(k)].for_each(ix, [&](int i, double, const Vec<2>& G) {
      const double* node = node_values(a, i, field);
      L.noalias() += Vec<2>(node[velocity], node[velocity + 1]) * G.transpose();
    });
    Eigen::Map<Mat<2>> F(f.F + 4 * k);
    F = ((Mat<2>::Identity() + dt * L) * F).eval();
    f.volume[k] = F.determinant() * f.volume0[k];
    Mat<2> sigma = Eigen::Map<const Mat<2>>(f.stress + 4 * k);
    linear_elastic_update<2>(L, dt, lam, mu, opt.analysis, sigma, f.stress_zz[k]);
    Eigen::Map<Mat<2>>(f.stress + 4 * k) = sigma;
  }
  petsc_check(VecRestoreArrayRead(local, &a), "VecRestoreArrayRead");
}

const std::array<const char*, 14>& DecomposedMpm2D::phase_names() {
  static const std::array<const char*, 14> names{
      {"particle_to_grid", "sum_to_owners", "exchange_field_ranges", "fields_to_owners", "find_contact_nodes",
       "contact_extrapolated", "momentum_update", "contact_updated", "nodal_velocities", "ghost_velocities",
       "fields_to_ghosts", "grid_to_particle", "stress_update", "migrate"}};
  return names;
}

void DecomposedMpm2D::step(double dt) {
  Impl& s = *impl_;
  s.current_valid = false;  // the particles move: current_stencils() evaluates them again
  dispatch_shape(s.opt.shape, [&](auto kernel) {
    using Kernel = decltype(kernel);
    using Phase = void (Impl::*)(double);
    // The step, in order (names: phase_names()). Without contact (one velocity field) the per-field
    // exchanges and the contact phases have nothing to do.
    static constexpr Phase phases[14] = {
        &Impl::particle_to_grid<Kernel>, &Impl::sum_to_owners,        &Impl::exchange_field_ranges,
        &Impl::fields_to_owners,         &Impl::find_contact_nodes,   &Impl::contact_extrapolated,
        &Impl::momentum_update,          &Impl::contact_updated,      &Impl::nodal_velocities,
        &Impl::ghost_velocities,         &Impl::fields_to_ghosts,     &Impl::grid_to_particle<Kernel>,
        &Impl::stress_update<Kernel>,    &Impl::migrate};
    for (std::size_t p = 0; p < 14; ++p) {
      const double t0 = MPI_Wtime();
      (s.*phases[p])(dt);
      s.traffic.phase_seconds[p] += MPI_Wtime() - t0;
    }
  });
  ++s.traffic.steps;
}

}  // namespace frictherm::mechanics
