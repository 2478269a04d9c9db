// One explicit MPM step: particle-to-grid, contact, grid momentum update, grid-to-particle, stress
// update. Particle loops are templated on the shape-function kernel (static dispatch) and threaded
// with OpenMP; scatters go to per-thread nodal buffers that are summed afterwards. Every particle
// scatters into the slots of its material's velocity field (field_of_material_), so the same loops
// serve the shared single field and the per-material fields of multimaterial contact. With the
// extended B-spline the weights are precomputed per step (simulation_ebs.cpp) and the same loops
// read them.
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include "stencil_access.hpp"

#include <omp.h>

#include <climits>
#include <cmath>
#include <limits>
#include <sstream>

namespace frictherm::mechanics {

using step_detail::indexable;
using step_detail::is_extended;

namespace {
// The parts of the thread partition this thread runs: its own, or (if the runtime gave the region
// fewer threads than asked for) every omp_get_num_threads()-th one.
template <class Fn>
void for_each_part(const ThreadPartition& partition, Fn&& fn) {
  for (int t = omp_get_thread_num(); t < partition.threads; t += omp_get_num_threads()) fn(t);
}
}  // namespace

template <int Dim>
template <class Kernel>
auto& Simulation<Dim>::stencils() {
  if constexpr (std::is_same_v<Kernel, LinearKernel>) return st_linear_;
  else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return st_ugimp_;
  else if constexpr (is_extended<Kernel>) return st_extended_;
  else return st_quadratic_;
}

template <int Dim>
double Simulation<Dim>::step(double dt_limit) {
  finalize();
  // The energy books' start (EnergyBalance::initial): once, before the first step moves anything.
  if (std::isnan(initial_energy_))
    initial_energy_ = kinetic_energy() + strain_energy() + (penalty_ ? penalty_->stored_energy() : 0.0);
  lap_ = PhaseLap{};
  nested_phase_ = 0.0;
  const double dt = std::min(stable_time_step(), dt_limit);
  lap_.to(phase_times_.time_step);
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "step " << step_ << ", t = " << time_ << " s: time step " << dt << " s is not positive and finite";
    throw SimulationError(msg.str(), step_, time_, -1);
  }
  if (opt_.shape == ShapeKind::extended_bspline)
    step_with<ExtendedBSplineKernel>(dt);
  else
    dispatch_shape(opt_.shape, [&](auto kernel) { step_with<decltype(kernel)>(dt); });
  last_dt_ = dt;
  return dt;
}

template <int Dim>
template <class Kernel>
void Simulation<Dim>::step_with(double dt) {
  // Below ~2000 particles per thread the fork/join and the scatter-buffer reduction cost more than
  // the particle work they share.
  const int max_threads = omp_get_max_threads();
  threads_ = threads_for_particles(p_.size(), max_threads);
  if (static_cast<int>(thread_nodes_.size()) != threads_ - 1) {
    thread_nodes_.resize(static_cast<std::size_t>(std::max(0, threads_ - 1)));
    for (auto& t : thread_nodes_) t.resize(nodes_.mass.size(), contact_);
  }
  update_partition();
  StepPhaseTimes& pt = phase_times_;
  const double t = time_;
  for (std::size_t f = 0; f < fields_.size(); ++f)
    if (fields_[f].rigid)
      field_velocity_[f] = materials_[static_cast<std::size_t>(fields_[f].material)].rigid_velocity_at(t).template head<Dim>();
  // Nodes driven by rigid boundary materials (EBS keeps them); with contact from the stencils the step
  // evaluates anyway.
  if constexpr (is_extended<Kernel>) {
    map_rigid_particles<Kernel>(t, nullptr);
    prepare_extended_stencils();  // per field: EBS rebuilt, node boxes laid out, weights flattened
  } else {
    auto& st = stencils<Kernel>();
    if (st.size() != p_.size()) st.resize(p_.size()), stencils_current_ = false;
    if (contact_) {
      // Unless current_stencils() evaluated them after the last step (same positions, same numbers).
      if (!stencils_current_) evaluate_stencils<Kernel>();  // also the per-material boxes of nodes
      layout_fields(box_lo_, box_hi_);
      map_rigid_particles<Kernel>(t, st.data());
    } else {
      map_rigid_particles<Kernel>(t, nullptr);
    }
  }
  if (contact_) {
    std::fill(work_first_.begin(), work_first_.end(), 0.0);
    std::fill(work_second_.begin(), work_second_.end(), 0.0);
  }
  lap_.to(pt.shape_functions);
  const bool usf = opt_.scheme == UpdateScheme::usf;
  map_to_grid<Kernel>(dt, /*with_forces=*/!usf);
  lap_.to(pt.particle_to_grid);
  if (contact_) {
    find_contact_nodes();
    if (contact_opt_.separation == SeparationMethod::extent) measure_contact_extents(stencils<Kernel>());
    resolve_contact(ContactPass::extrapolated, dt);
    lap_.to(pt.contact, nested_phase_);
  }
  if (usf) {
    velocity_from_momentum();
    lap_.to(pt.grid_update);
    throw_beyond_hugoniot(particle_pass<false, true>(dt, stencils<Kernel>()).beyond);
    lap_.to(pt.stress_update);
    add_internal_forces<Kernel>();
    lap_.to(pt.particle_to_grid);
    move_boundary_points(dt, t);  // penalty: the points move with the velocity the stress update used
    lap_.to(pt.contact, nested_phase_);
  }
  map_external_loads<Kernel>(t);
  lap_.to(pt.particle_to_grid);
  apply_penalty_forces();  // penalty pairs: point forces into the nodal forces (Kakouris 2024 eq. 36)
  lap_.to(pt.contact, nested_phase_);
  update_grid(dt);         // velocity conditions act on the penalty forces too
  lap_.to(pt.grid_update, nested_phase_);  // less its contact pass (resolve_contact times itself)
  if (opt_.particle_update != ParticleUpdate::flip) filter_grid_velocity(stencils<Kernel>());  // XPIC/FMPM
  // USL: the stress update from the same nodal velocities in the same pass over the stencils (timed
  // as stress_update); USF and MUSL: the grid-to-particle update alone. USL with contact also evaluates
  // the next step's stencils and boxes in that pass (and moves the rigid particles): nothing after it
  // in the step needs this step's stencils.
  const bool usl = opt_.scheme == UpdateScheme::usl;
  const bool refresh = usl && contact_ && !is_extended<Kernel>;
  const ParticlePassResult pass = usl ? particle_pass<true, true>(dt, stencils<Kernel>(), refresh)
                                      : particle_pass<true, false>(dt, stencils<Kernel>());
  lap_.to(usl ? pt.stress_update : pt.grid_to_particle);
  if (usl) move_boundary_points(dt, t);  // (see simulation_penalty.cpp)
  if (!refresh) move_rigid_particles(dt, t);
  stencils_current_ = false;  // the particles moved; the rest of the step keeps the start-of-step stencils
  lap_.to(pt.grid_to_particle);
  time_ += dt;
  ++step_;
  check_particle(pass.bad, dt);
  stencils_current_ = refresh;  // every particle inside the grid: the pass evaluated every stencil
  if (usl) {
    throw_beyond_hugoniot(pass.beyond);
  } else if (opt_.scheme == UpdateScheme::musl) {
    remap_momentum<Kernel>();
    lap_.to(pt.particle_to_grid);
    if (contact_) resolve_contact(ContactPass::remapped, dt);
    lap_.to(pt.contact, nested_phase_);
    velocity_from_momentum();
    move_boundary_points(dt, t);  // MUSL: with the remapped velocity, as the stress update
    lap_.to(pt.grid_update);
    throw_beyond_hugoniot(particle_pass<false, true>(dt, stencils<Kernel>()).beyond);
    lap_.to(pt.stress_update);
  }
}

// Every particle's stencil (rigid ones too), and with contact per material the box of nodes it reaches
// (laid out by the step: layout_fields).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::evaluate_stencils() {
  auto& st = stencils<Kernel>();
  st.resize(p_.size());
  // Local copies (see map_to_grid): the stencil stores cannot reach them, so nothing is reloaded.
  const Grid<Dim> grid = grid_;
  Stencil<Dim, Kernel>* const stk = st.data();
  const Vec<Dim>* const position = p_.position.data();
  const Vec<Dim>* const half_size = p_.half_size.data();
  if (!contact_) {
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (std::size_t k = 0; k < p_.size(); ++k) stk[k].evaluate(grid, position[k], half_size[k]);
    return;
  }
  const std::size_t nm = materials_.size();
  update_partition();
  step_detail::StencilBoxes<Dim>::clear(box_lo_, box_hi_);
  // One parallel region for all materials (a grain is a few hundred particles: a region per
  // material would cost more in fork/join than its particles); per-thread boxes merged at the end.
#pragma omp parallel num_threads(threads_)
  {
    thread_local step_detail::StencilBoxes<Dim> boxes;
    boxes.reset(nm);
    for_each_part(partition_, [&](int t) {
      for (std::size_t m = 0; m < nm; ++m) {
        const std::size_t kb = partition_.even_lo(t, material_begin_[m]), ke = partition_.even_hi(t, material_end_[m]);
        for (std::size_t k = kb; k < ke; ++k) {
          stk[k].evaluate(grid, position[k], half_size[k]);
          boxes.extend(stk[k], boxes.lo[m], boxes.hi[m]);
        }
      }
    });
#pragma omp critical(frictherm_stencil_boxes)
    boxes.merge_into(box_lo_, box_hi_);
  }
}

template <int Dim>
StencilView<Dim> Simulation<Dim>::current_stencils() {
  if (!finalized_ || opt_.shape == ShapeKind::extended_bspline) return {};
  return dispatch_shape(opt_.shape, [&](auto kernel) {
    using Kernel = decltype(kernel);
    auto& st = stencils<Kernel>();
    if (!stencils_current_ || st.size() != p_.size()) {
      PhaseLap lap;
      evaluate_stencils<Kernel>();
      stencils_current_ = true;
      lap.to(phase_times_.shape_functions);
    }
    return StencilView<Dim>{opt_.shape, static_cast<const void*>(st.data()), st.size()};
  });
}

// Each part of the thread partition clears the slots it scatters into (its own fields in the nodes,
// its buffer for a field it shares) and scatters; after a barrier the shared fields' buffers are
// summed into the nodes. One parallel region per phase.
template <int Dim>
template <class Scatter>
void Simulation<Dim>::scatter_phase(Accumulated which, bool include_rigid, Scatter&& scatter) {
#pragma omp parallel num_threads(threads_)
  {
    for_each_part(partition_, [&](int t) {
      clear_scatter_targets(t, which);
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        const int f = field_of_material_[m];
        if (f < 0 || (!include_rigid && materials_[m].is_rigid())) continue;
        const std::size_t kb = partition_.lo(t, material_begin_[m]), ke = partition_.hi(t, material_end_[m]);
        if (kb >= ke) continue;
        scatter(scatter_target(t, f), fields_[static_cast<std::size_t>(f)].index, m, kb, ke);
      }
    });
    if (!partition_.shared_fields.empty()) {
#pragma omp barrier
      sum_shared_fields(which);
    }
  }
}

// Particle-to-grid of mass, momentum and (USL/MUSL) internal force and body force:
// m_i = Σ S_ip m_p, p_i = Σ S_ip m_p v_p, f_i = Σ (−V_p σ_p G_ip + S_ip m_p g) (Nairn 2018 eqs. 1–3);
// with contact also Σ S_ip m_p x_p (or the displacement x_p − x_p^(0)), Ω = Σ S_ip V_p and
// g = Σ G_ip V_p per material (eqs. 4–6, 9). Rigid materials only mark their presence (mass,
// position, domain): their velocity is prescribed.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_to_grid(double /*dt*/, bool with_forces) {
  auto& st = stencils<Kernel>();
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  const bool displacement = contact_opt_.separation == SeparationMethod::displacement;
  const bool prepared = stencils_current_;  // by current_stencils() since the last step
  scatter_phase(Accumulated{true, true, true, contact_}, true,
                [&](NodalFields<Dim>& acc, const NodeIndexer<Dim>& ix, std::size_t m, std::size_t kb, std::size_t ke) {
    if (!contact_) {
      for (std::size_t k = kb; k < ke; ++k) {
        if constexpr (!is_extended<Kernel>)
          if (!prepared) st[k].evaluate(grid_, p_.position[k], p_.half_size[k]);
        const auto& s = st[k];  // EBS: a view of the precomputed entries
        const double mp = p_.mass[k];
        const Vec<Dim> mv = mp * p_.velocity[k];
        const Mat<Dim> Vsig = p_.volume[k] * p_.stress[k];
        const Vec<Dim> mg = mp * g;
        if (with_forces) {
          s.for_each(ix, [&](int i, double S, const Vec<Dim>& G) {
            acc.mass[i] += S * mp;
            acc.momentum[i] += S * mv;
            acc.force[i] += S * mg - Vsig * G;
          });
        } else {
          s.for_each(ix, [&](int i, double S, const Vec<Dim>&) {
            acc.mass[i] += S * mp;
            acc.momentum[i] += S * mv;
          });
        }
      }
      return;
    }
    const bool forces = with_forces && !materials_[m].is_rigid();
    // Plain pointers, held in registers: Eigen's vector stores may alias anything, so through the
    // std::vectors every store would reload every array's address.
    double* const mass = acc.mass.data();
    double* const domain = acc.domain.data();
    Vec<Dim>* const momentum = acc.momentum.data();
    Vec<Dim>* const force = acc.force.data();
    Vec<Dim>* const mass_position = acc.mass_position.data();
    Vec<Dim>* const domain_gradient = acc.domain_gradient.data();
    decltype(auto) stk = indexable(st);
    for (std::size_t k = kb; k < ke; ++k) {
      const double mp = p_.mass[k], Vp = p_.volume[k];
      const Vec<Dim> mv = mp * p_.velocity[k];
      const Vec<Dim> mx = mp * (displacement ? Vec<Dim>(p_.position[k] - p_.initial_position[k]) : p_.position[k]);
      const Mat<Dim> Vsig = Vp * p_.stress[k];
      const Vec<Dim> mg = mp * g;
      stk[k].for_each(ix, [&](int i, double S, const Vec<Dim>& G) {
        mass[i] += S * mp;
        momentum[i] += S * mv;
        if (forces) force[i] += S * mg - Vsig * G;
        mass_position[i] += S * mx;
        domain[i] += S * Vp;
        domain_gradient[i] += Vp * G;
      });
    }
  });
}

// USF: internal and body forces from the freshly updated stress.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::add_internal_forces() {
  auto& st = stencils<Kernel>();
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  scatter_phase(Accumulated{false, false, true, false}, false,
                [&](NodalFields<Dim>& acc, const NodeIndexer<Dim>& ix, std::size_t, std::size_t kb, std::size_t ke) {
    for (std::size_t k = kb; k < ke; ++k) {
      const Mat<Dim> Vsig = p_.volume[k] * p_.stress[k];
      const Vec<Dim> mg = p_.mass[k] * g;
      st[k].for_each(ix, [&](int i, double S, const Vec<Dim>& G) { acc.force[i] += S * mg - Vsig * G; });
    }
  });
}

// Rigid materials without a velocity field of their own (all of them without contact, boundary ones
// with contact): every node they touch takes their prescribed velocity components.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_rigid_particles(double t, const Stencil<Dim, Kernel>* evaluated) {
  std::fill(rigid_mask_.begin(), rigid_mask_.end(), std::uint8_t{0});
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (!materials_[m].is_rigid() || field_of_material_[m] >= 0) continue;
    const Vec<Dim> v = materials_[m].rigid_velocity_at(t).template head<Dim>();
    std::uint8_t bits = 0;
    for (int d = 0; d < Dim; ++d)
      if (materials_[m].rigid_controls[static_cast<std::size_t>(d)]) bits |= static_cast<std::uint8_t>(1u << d);
    Stencil<Dim, Kernel> own;
    for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
      if (!evaluated) own.evaluate(grid_, p_.position[k], p_.half_size[k]);
      const Stencil<Dim, Kernel>& s = evaluated ? evaluated[k] : own;
      s.for_each(grid_, [&](int i, double S, const Vec<Dim>&) {
        if (S > 0.0) {
          rigid_mask_[static_cast<std::size_t>(i)] |= bits;
          for (int d = 0; d < Dim; ++d)
            if (bits & (1u << d)) rigid_velocity_[static_cast<std::size_t>(i)][d] = v[d];
        }
      });
    }
  }
}

template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_external_loads(double t) {
  auto& st = stencils<Kernel>();
  for (const auto& L : resolved_loads_) {
    const Vec<Dim> f = L.force * (*L.scale)(t);
    const int fi = field_of_material_[static_cast<std::size_t>(p_.material[L.particle])];
    if (fi < 0) continue;
    st[L.particle].for_each(fields_[static_cast<std::size_t>(fi)].index,
                            [&](int i, double S, const Vec<Dim>&) { nodes_.force[i] += S * f; });
  }
}

// MUSL: nodal momentum rebuilt from the updated particle velocities, p_i = Σ S_ip m_p v_p (step_with
// then resolves contact again on the remapped momenta).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::remap_momentum() {
  auto& st = stencils<Kernel>();
  scatter_phase(Accumulated{false, true, false, false}, false,
                [&](NodalFields<Dim>& acc, const NodeIndexer<Dim>& ix, std::size_t, std::size_t kb, std::size_t ke) {
    for (std::size_t k = kb; k < ke; ++k) {
      const Vec<Dim> mv = p_.mass[k] * p_.velocity[k];
      st[k].for_each(ix, [&](int i, double S, const Vec<Dim>&) { acc.momentum[i] += S * mv; });
    }
  });
}

#define FRICTHERM_INSTANTIATE_STEP(D) \
  template double Simulation<D>::step(double); \
  template StencilView<D> Simulation<D>::current_stencils();
FRICTHERM_INSTANTIATE_STEP(2)
FRICTHERM_INSTANTIATE_STEP(3)
#undef FRICTHERM_INSTANTIATE_STEP

}  // namespace frictherm::mechanics
