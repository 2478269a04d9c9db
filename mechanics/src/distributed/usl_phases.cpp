// The phases of the decomposed USL step (frictherm/mechanics/distributed.hpp; its lists, with MUSL's
// and USF's, in phase_lists.cpp); the exchanges (sum_to_owners, exchange_field_ranges,
// fields_to_owners, ghost_velocities, fields_to_ghosts, migrate) are phases of their own, the contact
// phases are in contact_phases.cpp and the per-material exchanges in sparse_exchange.cpp. The particle loops reuse the serial module's
// Stencil (shape_functions.hpp) through a NodeIndexer onto the ghosted box, and its
// constitutive updates (material.hpp, mie_gruneisen.hpp, plane_strain_update.hpp), so they compute what the serial Simulation<Dim>'s USL
// step computes (mechanics/src/simulation_step.cpp, simulation_fields.cpp) on this rank's particles,
// in 2D and 3D alike.
#include "distributed/decomposed_state.hpp"

#include <frictherm/mechanics/constitutive/stress_update.hpp>
#include <frictherm/mechanics/energy/energy_books.hpp>
#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/transfer/grid_to_particle.hpp>

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <iterator>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

using detail::petsc_check;

namespace {

// Stencil nodes must lie in the ghosted box: holds when every particle sits with the owner of its
// nearest node and the DMDA's stencil width is the kernel's reach (stencil_reach).
template <int Dim, class Kernel>
[[noreturn]] void outside_box(const Stencil<Dim, Kernel>& st, const std::array<PetscInt, 3>& start,
                              const std::array<PetscInt, 3>& size, long id) {
  const IVec<Dim> b = st.first_node();
  std::string first, box;
  for (int d = 0; d < Dim; ++d) {
    const auto u = static_cast<std::size_t>(d);
    first += (d ? ", " : "") + std::to_string(b[d]);
    box += (d ? " x [" : "[") + std::to_string(start[u]) + ", " + std::to_string(start[u] + size[u]) + ")";
  }
  throw std::logic_error("decomposed mechanics: particle " + std::to_string(id) + " (first node " + first +
                         ") reaches nodes outside its rank's ghosted box " + box + " (not migrated?)");
}

}  // namespace

// Phase 1, local: per velocity field m_i = Σ S_ip m_p, p_i = Σ S_ip m_p v_p,
// f_i = Σ (S_ip m_p g − V_p σ_p G_ip) (Nairn 2018 eqs. 1–3) and, with contact, Σ S_ip m_p x_p (or
// the displacement x_p − x_p^(0), eq. 9), Ω_i = Σ S_ip V_p and g_i = Σ G_ip V_p (eqs. 4–6), as the
// serial map_to_grid: with several fields first every stencil and each field's box of nodes (laid
// out as the serial layout_fields), then the scatter into the fields' slots, each node recording the
// range of fields reaching it; one field covers the ghosted box. The stencils are kept for the later
// phases.
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::particle_to_grid(double /*dt*/) {
  constexpr int mass = Dof::mass, momentum = Dof::momentum, force = Dof::force;
  constexpr int mass_position = Dof::mass_position, domain = Dof::domain, domain_gradient = Dof::domain_gradient;
  constexpr bool extended = std::is_same_v<Kernel, ExtendedBSplineKernel>;
  SwarmFields f(swarm);
  auto& st = stencils<Kernel>();
  if constexpr (!extended) st.resize(static_cast<std::size_t>(f.n));
  IVec<Dim> none_lo, none_hi;
  none_lo.fill(INT_MAX), none_hi.fill(INT_MIN);
  box_lo.assign(static_cast<std::size_t>(fields), none_lo);
  box_hi.assign(static_cast<std::size_t>(fields), none_hi);
  if (has_rigid)
    for (int d = 0; d < Dim; ++d) std::fill(driver[static_cast<std::size_t>(d)].begin(), driver[static_cast<std::size_t>(d)].end(), -1);
  const NodeIndexer<Dim> local_ix = local_indexer();
  // A rigid wall's particle marks the nodes it drives (the serial rigid_conditions: nodes with
  // S > 0, the components its material prescribes).
  const auto mark_drives = [&](PetscInt k, const auto& s) {
    const Material& m = materials[static_cast<std::size_t>(f.material[k])];
    s.for_each(local_ix, [&](int l, double S, const Vec<Dim>&) {
      if (S > 0.0)
        for (int d = 0; d < Dim; ++d)
          if (m.rigid_controls[static_cast<std::size_t>(d)]) {
            PetscInt& w = driver[static_cast<std::size_t>(d)][static_cast<std::size_t>(l)];
            w = std::max<PetscInt>(w, f.material[k]);
          }
    });
  };
  // Extended B-splines: the rigid walls mark their drives with the plain quadratic B-spline (the serial
  // rigid_conditions with ExtendedBSplineKernel's Stencil), then the bases over all ranks and every
  // other particle's entries (extended_bsplines.cpp).
  if constexpr (extended) {
    if (has_rigid) {
      Stencil<Dim, QuadraticBSplineKernel> plain;
      for (PetscInt k = 0; k < f.n; ++k) {
        if (!rigid_wall(f.material[k])) continue;
        plain.evaluate(grid, Eigen::Map<const Vec<Dim>>(f.x + Dim * k), Eigen::Map<const Vec<Dim>>(f.half_size + Dim * k));
        if (!in_box(plain)) outside_box(plain, box_start, box_size, f.id[k]);
        mark_drives(k, plain);
      }
    }
    prepare_extended(f);
  }
  // Evaluates particle k's stencil (a rigid wall's particle marks its drives and is skipped).
  const auto evaluate = [&](PetscInt k) {
    if constexpr (extended) {
      return !rigid_wall(f.material[k]);
    } else {
      auto& s = st[static_cast<std::size_t>(k)];
      s.evaluate(grid, Eigen::Map<const Vec<Dim>>(f.x + Dim * k), Eigen::Map<const Vec<Dim>>(f.half_size + Dim * k));
      if (!in_box(s)) outside_box(s, box_start, box_size, f.id[k]);
      if (!rigid_wall(f.material[k])) return true;
      mark_drives(k, s);
      return false;
    }
  };
  // One field (no contact): it covers the ghosted box and the stencils are evaluated in the scatter
  // loop. Several: each field's box from its particles' stencils first.
  const bool ranges = fields > 1;
  if (!ranges) {
    for (int d = 0; d < Dim; ++d) {
      box_lo[0][d] = static_cast<int>(box_start[static_cast<std::size_t>(d)]);
      box_hi[0][d] = static_cast<int>(box_start[static_cast<std::size_t>(d)] + box_size[static_cast<std::size_t>(d)]) - 1;
    }
  } else {
    for (PetscInt k = 0; k < f.n; ++k) {
      if (!evaluate(k)) continue;
      const std::size_t field = static_cast<std::size_t>(field_of(f.material[k]));
      if constexpr (extended) {  // the nodes of its entries
        const auto& e = st;
        for (std::size_t q = e.begin[static_cast<std::size_t>(k)]; q < e.begin[static_cast<std::size_t>(k) + 1]; ++q)
          for (int d = 0; d < Dim; ++d) {
            box_lo[field][d] = std::min(box_lo[field][d], e.node[q][d]);
            box_hi[field][d] = std::max(box_hi[field][d], e.node[q][d]);
          }
        continue;
      } else {
        const IVec<Dim> b = st[static_cast<std::size_t>(k)].first_node();
        for (int d = 0; d < Dim; ++d) {
          box_lo[field][d] = std::min(box_lo[field][d], b[d]);
          box_hi[field][d] = std::max(box_hi[field][d], b[d] + Kernel::K - 1);
        }
      }
    }
    std::fill(field_lo.begin(), field_lo.end(), fields);
    std::fill(field_hi.begin(), field_hi.end(), -1);
  }
  layout_fields();
  const Vec<Dim> g = opt.gravity;
  const bool contact = opt.contact;
  const bool displacement = opt.contact_options.separation == SeparationMethod::displacement;
  // A rigid contact partner's particles mark their presence only (mass, momentum, Σ S m x, Ω, g; no
  // force: their velocity is prescribed), as the serial map_to_grid.
  for (PetscInt k = 0; k < f.n; ++k) {
    if (ranges ? rigid_wall(f.material[k]) : !evaluate(k)) continue;
    const auto& s = st[static_cast<std::size_t>(k)];
    const int field = field_of(f.material[k]);
    const bool forces = !rigid(f.material[k]) && !opt.usf;  // USF: internal_forces, after the stress update
    const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field)].index;
    const double mp = f.mass[k], Vp = f.volume[k];
    const Vec<Dim> mv = mp * Eigen::Map<const Vec<Dim>>(f.velocity + Dim * k);
    const Mat<Dim> Vsig = Vp * Eigen::Map<const Mat<Dim>>(f.stress + Dim * Dim * k);
    const Vec<Dim> mg = mp * g;
    const Eigen::Map<const Vec<Dim>> xp(f.x + Dim * k), x0(f.x0 + Dim * k);
    const Vec<Dim> mx = mp * (displacement ? Vec<Dim>(xp - x0) : Vec<Dim>(xp));
    s.for_each(ix, [&](int slot, double S, const Vec<Dim>& G) {
      if (ranges) {
        const std::size_t u = static_cast<std::size_t>(slot_node[static_cast<std::size_t>(slot)]);
        field_lo[u] = std::min<PetscInt>(field_lo[u], field);
        field_hi[u] = std::max<PetscInt>(field_hi[u], field);
      }
      double* node = slot_values(static_cast<std::size_t>(slot));
      node[mass] += S * mp;
      for (int d = 0; d < Dim; ++d) node[momentum + d] += S * mv[d];
      if (forces) {
        const Vec<Dim> fi = S * mg - Vsig * G;
        for (int d = 0; d < Dim; ++d) node[force + d] += fi[d];
      }
      if (contact) {
        const Vec<Dim> gi = Vp * G;
        for (int d = 0; d < Dim; ++d) node[mass_position + d] += S * mx[d];
        node[domain] += S * Vp;
        for (int d = 0; d < Dim; ++d) node[domain_gradient + d] += gi[d];
      }
    });
  }
  if (loads.empty()) return;
  // This rank's loaded particles (for the loads' work in grid_to_particle) and, but under USF, their loads.
  local_loads.clear();
  for (PetscInt k = 0; k < f.n; ++k) {
    const auto [lo, hi] = std::equal_range(load_ids.begin(), load_ids.end(), static_cast<std::int64_t>(f.id[k]));
    for (auto j = lo; j != hi; ++j) local_loads.emplace_back(k, static_cast<std::size_t>(j - load_ids.begin()));
  }
  if (!opt.usf) add_loads<Kernel>(f);
}

// The point loads and tractions of this rank's particles, f_i += S_ip F(t) into their fields' slots
// (the serial kernel): a particle is on one rank, so sum_to_owners gives the owners each load once.
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::add_loads(SwarmFields& f) {
  constexpr int force = Dof::force;
  const auto& st = stencils<Kernel>();
  for (const auto& [k, j] : local_loads) {
    if (rigid(f.material[k])) continue;  // as the serial step: a rigid particle's velocity is prescribed
    const Vec<Dim> F = load_force<Dim>(loads[j].force, loads[j].scale, time);
    add_load_to_grid<Dim>(st[static_cast<std::size_t>(k)], boxes[static_cast<std::size_t>(field_of(f.material[k]))].index, F,
                          [&](int slot) { return Eigen::Map<Vec<Dim>>(slot_values(static_cast<std::size_t>(slot)) + force); });
  }
}

// Phase 2, exchange: each local node's m, p, f summed over its fields' slots (in field order; one
// field: its values exactly) into the DMDA's local vector, and the ghost nodes' sums added into
// their owners.
template <int Dim>
void DecomposedMpm<Dim>::Impl::sum_to_owners(double /*dt*/) {
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(local, &a), "VecGetArray");
  std::fill(a, a + dof * local_count(), 0.0);
  const std::size_t slots = slot_node.size();
  for (std::size_t sl = 0; sl < slots; ++sl) {
    double* node = a + dof * slot_node[sl];
    const double* v = slot_values(sl);
    for (int c = 0; c < dof; ++c) node[c] += v[c];
  }
  petsc_check(VecRestoreArray(local, &a), "VecRestoreArray");
  petsc_check(VecZeroEntries(global), "VecZeroEntries");
  petsc_check(DMLocalToGlobalBegin(da, local, ADD_VALUES, global), "DMLocalToGlobalBegin");
  if (has_rigid) {  // the rigid materials driving each node, completed at the owner (the largest wins)
    for (int d = 0; d < Dim; ++d) root_driver[static_cast<std::size_t>(d)] = driver[static_cast<std::size_t>(d)];
    for (int d = 0; d < Dim; ++d)
      petsc_check(PetscSFReduceBegin(node_sf, MPIU_INT, driver[static_cast<std::size_t>(d)].data(),
                                     root_driver[static_cast<std::size_t>(d)].data(), MPI_MAX),
                  "PetscSFReduceBegin");
    for (int d = 0; d < Dim; ++d)
      petsc_check(PetscSFReduceEnd(node_sf, MPIU_INT, driver[static_cast<std::size_t>(d)].data(),
                                   root_driver[static_cast<std::size_t>(d)].data(), MPI_MAX),
                  "PetscSFReduceEnd");
    for (std::size_t q = 0; q < owned_local.size(); ++q) {
      const std::size_t l = static_cast<std::size_t>(owned_local[q]);
      drive_mask[q] = 0;
      for (int d = 0; d < Dim; ++d) {
        const PetscInt m = root_driver[static_cast<std::size_t>(d)][l];
        if (m < 0) continue;
        drive_mask[q] |= static_cast<std::uint8_t>(1u << d);
        drive_velocity[q][d] = materials[static_cast<std::size_t>(m)].rigid_velocity_at(time)[d];
      }
    }
  }
  petsc_check(DMLocalToGlobalEnd(da, local, ADD_VALUES, global), "DMLocalToGlobalEnd");
}

// The grid update on the owned nodes, in the serial list's three phases (step/scheme_order.hpp):
// velocity_conditions, damping (at LoadHook::conditioned_forces) and momentum_update. Each visits
// the owned fields in the same order and does at a node what the serial phase of its name does, so
// a node's arithmetic and the books' sums are in the serial order.

// The velocity conditions on p_i and f_i: a rigid partner's field m v_rigid with no force, driven
// components the rigid velocity (the change a force, the rigid work booked), fixed components of both
// zeroed (the serial apply_velocity_bc).
template <int Dim>
void DecomposedMpm<Dim>::Impl::velocity_conditions(double dt) {
  constexpr int momentum = Dof::momentum, force = Dof::force;
  double driven_work = 0.0, stopped = 0.0;
  // The start-of-step momentum of the stops (the serial apply_velocity_bc): without the extrapolated
  // contact pass's change at a group entry.
  const double* const mt_begin = mt_values.data();
  const std::size_t per = static_cast<std::size_t>(per_field);
  const bool changed = mt_start_change.size() == mt_field.size() && !mt_field.empty();
  const auto start = [&](const double* node, int d) {
    if (changed && node >= mt_begin && node < mt_begin + mt_values.size())
      return node[Dof::momentum + d] - mt_start_change[static_cast<std::size_t>(node - mt_begin) / per][d];
    return node[Dof::momentum + d];
  };
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
    if (partner(field)) {  // a rigid partner's field: m v_rigid, no force (the serial apply_velocity_bc)
      const Vec<Dim> v = partner_velocity(field);
      driven_work += rigid_reaction_work<Dim>(Eigen::Map<const Vec<Dim>>(node + force), v, dt);
      for (int d = 0; d < Dim; ++d) node[momentum + d] = node[Dof::mass] * v[d], node[force + d] = 0.0;
      return;
    }
    const std::uint8_t fixed = fixed_mask[static_cast<std::size_t>(q)];
    const std::uint8_t driven = has_rigid ? drive_mask[static_cast<std::size_t>(q)] : 0;
    if (driven) {
      // Driven components end the step at the rigid velocity: the change made a force, (m v − p)/dt,
      // so that the particles' FLIP update receives it too, and the rigid material's work booked (the
      // serial apply_velocity_bc's kernel, energy/energy_books.hpp; owned nodes: once per node).
      for (int d = 0; d < Dim; ++d)
        if (driven & (1u << d))
          driven_work += drive_component(node[Dof::mass], node[momentum + d], node[force + d],
                                         drive_velocity[static_cast<std::size_t>(q)][d], dt, start(node, d), stopped);
    }
    for (int d = 0; d < Dim; ++d)
      if (fixed & (1u << d)) node[momentum + d] = node[force + d] = 0.0;
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
  rigid_work += driven_work;
  boundary_stop_work += stopped;
}

// Mass-proportional damping after the velocity conditions, on the components they leave free (the
// serial apply_damping's kernel, loads/mass_damping.cpp); not on a rigid partner's field.
template <int Dim>
void DecomposedMpm<Dim>::Impl::damping(double dt) {
  if (!damping_active(opt.damping_rate, opt.damping_until, time)) return;
  double removed = 0.0;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
    if (partner(field)) return;
    const std::uint8_t driven = has_rigid ? drive_mask[static_cast<std::size_t>(q)] : 0;
    damp_node<Dim>(node + Dof::force, node + Dof::momentum, node[Dof::mass], driven, opt.damping_rate, dt,
                   empty_node_mass, removed);
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
  damping_work += removed;
}

// p_i^{n+1} = p_i^n + f_i dt (a rigid partner's field keeps m v_rigid).
template <int Dim>
void DecomposedMpm<Dim>::Impl::momentum_update(double dt) {
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt, double* node, int field) {
    if (partner(field)) return;
    for (int d = 0; d < Dim; ++d) node[Dof::momentum + d] += node[Dof::force + d] * dt;
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

// Phase 9, owned nodes: v_i = p_i^{n+1}/m_i, a_i = f_i/m_i per field, into the slots of p and f; fields
// below the empty-node mass get neither (as the serial nodal_velocities).
template <int Dim>
void DecomposedMpm<Dim>::Impl::nodal_velocities(double /*dt*/) {
  constexpr int mass = Dof::mass, momentum = Dof::momentum, force = Dof::force;
  constexpr int velocity = Dof::velocity, acceleration = Dof::acceleration;
  PetscScalar* a = nullptr;
  petsc_check(VecGetArray(global, &a), "VecGetArray");
  for_each_owned_field(a, [&](PetscInt q, double* node, int field) {
    const double m = node[mass];
    for (int d = 0; d < Dim; ++d) {
      const double p = node[momentum + d], f = node[force + d];
      node[velocity + d] = m > empty_node_mass ? p / m : 0.0;
      node[acceleration + d] = m > empty_node_mass ? f / m : 0.0;
    }
    if (partner(field)) {  // a rigid partner's field moves with it (the serial nodal_velocities)
      const Vec<Dim> v = partner_velocity(field);
      for (int d = 0; d < Dim; ++d) node[velocity + d] = v[d];
      return;
    }
    if (const std::uint8_t driven = has_rigid ? drive_mask[static_cast<std::size_t>(q)] : 0; driven && m > empty_node_mass)
      for (int d = 0; d < Dim; ++d)  // driven nodes keep the prescribed velocity (the serial nodal_velocities)
        if (driven & (1u << d)) node[velocity + d] = drive_velocity[static_cast<std::size_t>(q)][d];
  });
  petsc_check(VecRestoreArray(global, &a), "VecRestoreArray");
}

// Phase 10, exchange: owners' v_i, a_i (the DMDA totals) copied to the ranks holding the node as a ghost.
template <int Dim>
void DecomposedMpm<Dim>::Impl::ghost_velocities(double /*dt*/) {
  petsc_check(DMGlobalToLocalBegin(da, global, INSERT_VALUES, local), "DMGlobalToLocalBegin");
  petsc_check(DMGlobalToLocalEnd(da, global, INSERT_VALUES, local), "DMGlobalToLocalEnd");
}

// Phase 12, local: FLIP v_p += dt Σ S_ip a_i, x_p += dt Σ S_ip v_i^{n+1} from the particle's own
// field, start-of-step stencils, with a PIC relaxation time the serial FLIP/PIC blend; XPIC and FMPM
// from v* of velocity_filter (the serial kernel, transfer/grid_to_particle.hpp).
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::grid_to_particle(double dt) {
  constexpr int velocity = Dof::velocity, acceleration = Dof::acceleration;
  SwarmFields f(swarm);
  const auto& st = stencils<Kernel>();
  const PetscScalar* a = nullptr;
  petsc_check(VecGetArrayRead(local, &a), "VecGetArrayRead");
  const bool filter = filtered();
  const PetscScalar* vstar = nullptr;  // v* of XPIC/FMPM over the ghosted box
  if (filter) petsc_check(VecGetArrayRead(filter_local, &vstar), "VecGetArrayRead");
  const double pic = pic_blend_fraction(dt, opt.pic_relaxation_time);  // the serial FLIP/PIC blend
  load_start_position.resize(local_loads.size());
  for (std::size_t n = 0; n < local_loads.size(); ++n)
    load_start_position[n] = Eigen::Map<const Vec<Dim>>(f.x + Dim * local_loads[n].first);
  for (PetscInt k = 0; k < f.n; ++k) {
    if (rigid(f.material[k])) {  // the serial move_rigid_particles (rigids/): v(t), x += ½ (v(t) + v(t + dt)) dt
      const Material& m = materials[static_cast<std::size_t>(f.material[k])];
      const Vec<Dim> v0 = m.rigid_velocity_at(time).template head<Dim>();
      const Vec<Dim> dx = ((m.rigid_velocity_at(time + dt) + m.rigid_velocity_at(time)) * 0.5 * dt).template head<Dim>();
      Eigen::Map<Vec<Dim>>(f.velocity + Dim * k) = v0;
      Eigen::Map<Vec<Dim>>(f.x + Dim * k) += dx;
      continue;
    }
    Vec<Dim> acc = Vec<Dim>::Zero(), v = Vec<Dim>::Zero(), vf = Vec<Dim>::Zero();
    const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field_of(f.material[k]))].index;
    st[static_cast<std::size_t>(k)].for_each(ix, [&](int slot, double S, const Vec<Dim>&) {
      const double* node = node_values(a, static_cast<std::size_t>(slot));
      acc += S * Eigen::Map<const Vec<Dim>>(node + acceleration);
      v += S * Eigen::Map<const Vec<Dim>>(node + velocity);
      if (filter) vf += S * slot_vector_at(vstar, static_cast<std::size_t>(slot));
    });
    // The velocity, gravity's work and the position, as the serial pass.
    external_work += update_particle_velocity<Dim>(opt.particle_update, pic, dt, f.mass[k], opt.gravity, acc, v, vf,
                                                   Eigen::Map<Vec<Dim>>(f.velocity + Dim * k));
    Eigen::Map<Vec<Dim>>(f.x + Dim * k) += dt * v;
  }
  if (filter) petsc_check(VecRestoreArrayRead(filter_local, &vstar), "VecRestoreArrayRead");
  for (std::size_t n = 0; n < local_loads.size(); ++n) {  // the loads' work, F · Δx̄_p (the serial pass)
    const auto& [k, j] = local_loads[n];
    const Vec<Dim> acc = load_point_acceleration<Dim>(  // the same start-of-step stencil
        st[static_cast<std::size_t>(k)], boxes[static_cast<std::size_t>(field_of(f.material[k]))].index, [&](int slot) {
          return Eigen::Map<const Vec<Dim>>(node_values(a, static_cast<std::size_t>(slot)) + acceleration);
        });
    external_work += load_work<Dim>(load_force<Dim>(loads[j].force, loads[j].scale, time),
                                    Vec<Dim>(Eigen::Map<const Vec<Dim>>(f.x + Dim * k)) - load_start_position[n], acc, dt);
  }
  petsc_check(VecRestoreArrayRead(local, &a), "VecRestoreArrayRead");
}

// Phase 13, local: L_p = Σ_i v_i ⊗ G_ip, then the serial particle pass's stress update
// (constitutive/stress_update.hpp: F, V, the material's stress, ε̄p, e, the plastic work and the wave
// speed of the CFL step). A particle compressed past its Hugoniot's limit stops the run on every rank
// (one reduction, here).
template <int Dim>
template <class Kernel>
void DecomposedMpm<Dim>::Impl::stress_update(double dt) {
  constexpr int velocity = Dof::velocity;
  const Analysis an = opt.analysis;
  beyond = -1;
  StressPower power;  // Σ V σ:L before and after the update, as the serial particle pass (the books' stored_lead)
  {
    SwarmFields f(swarm);
    const auto& st = stencils<Kernel>();
    const PetscScalar* a = nullptr;
    petsc_check(VecGetArrayRead(local, &a), "VecGetArrayRead");
    for (PetscInt k = 0; k < f.n; ++k) {
      const std::size_t m = static_cast<std::size_t>(f.material[k]);
      const Material& mat = materials[m];
      if (mat.is_rigid()) continue;
      const NodeIndexer<Dim> ix = boxes[static_cast<std::size_t>(field_of(f.material[k]))].index;
      const auto& sk = st[static_cast<std::size_t>(k)];
      // The particle's F and σ in locals, updated by the serial kernel, then stored.
      Mat<Dim> F = Eigen::Map<const Mat<Dim>>(f.F + Dim * Dim * k);
      Mat<Dim> sigma = Eigen::Map<const Mat<Dim>>(f.stress + Dim * Dim * k);
      const StressState<Dim> state{F, f.volume[k], f.volume0[k], sigma, f.stress_zz[k], f.plastic_strain[k],
                                   f.internal_energy[k], f.plastic_work[k], f.wave_speed[k]};
      bool ok = true;
      if constexpr (Dim == 2) {
        if (laws[m].mie_gruneisen()) {  // the serial 2D Mie-Grüneisen path, on scalars
          VelocityGradient2 L;
          sk.for_each(ix, [&](int slot, double, const Vec<2>& G) {
            L.add(Vec<2>(Eigen::Map<const Vec<2>>(node_values(a, static_cast<std::size_t>(slot)) + velocity)), G);
          });
          power.start += f.volume[k] * stress_power(sigma, L);
          ok = update_stress_plane_strain(mat.mie_gruneisen, laws[m].min_J, L, dt, state);
          power.end += f.volume[k] * stress_power(sigma, L);
        }
      }
      if (Dim != 2 || !laws[m].mie_gruneisen()) {
        Mat<Dim> L = Mat<Dim>::Zero();
        sk.for_each(ix, [&](int slot, double, const Vec<Dim>& G) {
          L.noalias() += Vec<Dim>(Eigen::Map<const Vec<Dim>>(node_values(a, static_cast<std::size_t>(slot)) + velocity)) *
                         G.transpose();
        });
        power.start += f.volume[k] * stress_power<Dim>(sigma, L);
        ok = update_stress<Dim>(mat, laws[m], an, L, dt, state);
        power.end += f.volume[k] * stress_power<Dim>(sigma, L);
      }
      if (!ok) beyond = std::max(beyond, static_cast<long>(f.id[k]));
      Eigen::Map<Mat<Dim>>(f.F + Dim * Dim * k) = F;
      Eigen::Map<Mat<Dim>>(f.stress + Dim * Dim * k) = sigma;
    }
    petsc_check(VecRestoreArrayRead(local, &a), "VecRestoreArrayRead");
  }
  advance_stored_lead(!opt.usf, dt, power, stored_lead, last_stress_power, last_stress_dt);
  if (!has_mie_gruneisen) return;
  long worst = beyond;
  MPI_Allreduce(MPI_IN_PLACE, &worst, 1, MPI_LONG, MPI_MAX, comm);
  if (worst >= 0)
    throw std::runtime_error("decomposed mechanics: step " + std::to_string(traffic.steps) + ": particle " +
                             std::to_string(worst) +
                             " is compressed past the limit of its Hugoniot (try a smaller CFL factor)");
}

template <int Dim>
double DecomposedMpm<Dim>::external_work() const {
  double w = impl_->external_work;
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return w;
}

template <int Dim>
double DecomposedMpm<Dim>::damping_work() const {
  double w = impl_->damping_work;
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return w;
}

// The members defined here, for both dimensions and every kernel (the phase lists are in phase_lists.cpp).
#define FRICTHERM_INSTANTIATE_USL_KERNEL(D, K)                                  \
  template void DecomposedMpm<D>::Impl::particle_to_grid<K>(double);            \
  template void DecomposedMpm<D>::Impl::grid_to_particle<K>(double);            \
  template void DecomposedMpm<D>::Impl::stress_update<K>(double);              \
  template void DecomposedMpm<D>::Impl::add_loads<K>(SwarmFields&);
#define FRICTHERM_INSTANTIATE_USL(D)                                   \
  FRICTHERM_INSTANTIATE_USL_KERNEL(D, LinearKernel)                    \
  FRICTHERM_INSTANTIATE_USL_KERNEL(D, UGIMPKernel)                     \
  FRICTHERM_INSTANTIATE_USL_KERNEL(D, QuadraticBSplineKernel)          \
  FRICTHERM_INSTANTIATE_USL_KERNEL(D, ExtendedBSplineKernel)           \
  template double DecomposedMpm<D>::external_work() const;             \
  template double DecomposedMpm<D>::damping_work() const;              \
  template void DecomposedMpm<D>::Impl::sum_to_owners(double);         \
  template void DecomposedMpm<D>::Impl::velocity_conditions(double);   \
  template void DecomposedMpm<D>::Impl::damping(double);               \
  template void DecomposedMpm<D>::Impl::momentum_update(double);       \
  template void DecomposedMpm<D>::Impl::nodal_velocities(double);      \
  template void DecomposedMpm<D>::Impl::ghost_velocities(double);
FRICTHERM_INSTANTIATE_USL(2)
FRICTHERM_INSTANTIATE_USL(3)
#undef FRICTHERM_INSTANTIATE_USL
#undef FRICTHERM_INSTANTIATE_USL_KERNEL

}  // namespace frictherm::mechanics
