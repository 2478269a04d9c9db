// One explicit MPM step as a list of named phases (step/phase_list.hpp), built once per scene by
// build_phases from the update scheme and the options and run by PhaseList::run, which times each
// phase; the phases read no clock. The particle loops are templated on the shape-function kernel
// (static dispatch) and threaded with OpenMP; scatters go to per-thread nodal buffers that are summed
// afterwards. Every particle scatters into the slots of its material's velocity field
// (layout_.field_of_material), so the same loops serve the shared single field and the per-material fields
// of multimaterial contact. With the extended B-spline the weights are precomputed per step
// (simulation_ebs.cpp) and the same loops read them.
#include <frictherm/mechanics/energy/energy_books.hpp>
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/step/scheme_order.hpp>

#include "stencil_access.hpp"

#include <omp.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <type_traits>

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
double Simulation<Dim>::step(double dt_limit) {
  finalize();
  // The energy books' start (EnergyBalance::initial): once, before the first step moves anything.
  if (std::isnan(work_books_.initial_energy))
    work_books_.initial_energy = kinetic_energy() + strain_energy() + contact_stored_energy();
  if (schedule_.phases.empty() || schedule_.key != phase_key()) build_phases();
  StepContext ctx;
  ctx.dt_limit = dt_limit;
  ctx.t = clock_.time;
  schedule_.phases.run(ctx, schedule_.times);
  clock_.last_dt = ctx.dt;
  return ctx.dt;
}

// What the phase lists depend on; a change rebuilds them: among it what selects the loads
// (loads/registry.cpp: resolved point loads and tractions, damping). (The contact methods are not in it:
// finalize() chooses them, before the first list is built, and nothing changes them after.)
template <int Dim>
long Simulation<Dim>::phase_key() const {
  long key = static_cast<long>(opt_.shape);
  key = key * 4 + static_cast<long>(opt_.scheme);
  key = key * 8 + static_cast<long>(opt_.particle_update);
  key = key * 2 + (opt_.damping_rate > 0.0);
  key = key * 2 + !conditions_.resolved_loads.empty();
  return key;
}

template <int Dim>
void Simulation<Dim>::build_phases() {
  schedule_.phases.clear();
  if (opt_.shape == ShapeKind::extended_bspline)
    build_phases<ExtendedBSplineKernel>();
  else
    dispatch_shape(opt_.shape, [&](auto kernel) { build_phases<decltype(kernel)>(); });
  schedule_.key = phase_key();
}

template <int Dim>
std::vector<const char*> Simulation<Dim>::step_phase_names() {
  finalize();
  if (schedule_.phases.empty() || schedule_.key != phase_key()) build_phases();
  std::vector<const char*> names;
  for (const StepPhase& p : schedule_.phases.phases()) names.push_back(p.name);
  return names;
}

// The step's phase lists, in the order step/scheme_order.hpp writes once for both engines: the serial
// engine adds its own phases (SchemePhase) and nothing at the exchange points. The contact methods
// (step/contact_method.hpp, contact_methods/) add their phases at the ContactHooks: multimaterial
// contact a pass after each momentum projection, penalty contact its forces before the velocity
// conditions and the boundary points' move where the stress update's velocity is on the grid. The
// loads (step/step_load.hpp, loads/) add theirs at the LoadHooks: point loads and tractions into the
// forces, damping after the velocity conditions; the velocity filters (step/velocity_filter.hpp,
// filters/) at the FilterHooks: XPIC's start velocity, XPIC/FMPM after nodal_velocities; the rigid
// drivers (step/rigid_driver.hpp, rigids/) at the RigidHooks: the rigid velocities onto the grid at the
// step's start, the rigid particles moved after the particle pass (or by it: refresh).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::build_phases() {
  using T = StepPhaseTimes;
  PhaseList& P = schedule_.phases;
  const UpdateScheme scheme = opt_.scheme;
  const bool usf = scheme == UpdateScheme::usf, usl = scheme == UpdateScheme::usl;
  const std::vector<const StepLoad<Dim>*> loads = loads_for(*this);                         // loads/
  const std::vector<const StepVelocityFilter<Dim>*> filters = velocity_filters_for(*this);  // filters/
  const std::vector<const StepRigidDriver<Dim>*> rigids = rigid_drivers_for(*this);         // rigids/
  // USL with contact (the velocity fields per material): the particle pass also evaluates the next
  // step's stencils and boxes and moves the rigid particles (nothing after it in the step needs this
  // step's stencils).
  const bool refresh = usl && !contact_methods_.empty() && !is_extended<Kernel>;

  // The CFL step. With the wave speeds current, the particle-to-grid scatter takes max_p c_p + |v_p|
  // (exact in any order) and the step is set at its phase's end (nothing reads it before): no pass of
  // its own (on two threads a parallel region, on one 3 % of the 1 mm twin's step).
  const auto set_step = [this](StepContext& c, double cmax) {
    c.dt = std::min(time_step_for_speed(cmax), c.dt_limit);
    if (!(c.dt > 0.0) || !std::isfinite(c.dt)) {
      std::ostringstream msg;
      msg << "step " << clock_.step << ", t = " << clock_.time << " s: time step " << c.dt << " s is not positive and finite";
      throw SimulationError(msg.str(), clock_.step, clock_.time, -1);
    }
  };
  struct SerialEngine {
    Simulation& sim;
    PhaseList& P;
    UpdateScheme scheme;
    bool usf, refresh;
    const std::vector<const StepLoad<Dim>*>& loads;
    const std::vector<const StepVelocityFilter<Dim>*>& filters;
    const std::vector<const StepRigidDriver<Dim>*>& rigids;
    decltype(set_step) set;
    void operator()(ContactHook at) {
      for (const StepContactMethod<Dim>* m : sim.contact_methods_) m->add_phases(at, scheme, sim.opt_.shape, sim, P);
    }
    void operator()(LoadHook at) {
      for (const StepLoad<Dim>* l : loads) l->add_phases(at, sim.opt_.shape, sim, P);
    }
    void operator()(FilterHook at) {
      for (const StepVelocityFilter<Dim>* f : filters) f->add_phases(at, scheme, sim.opt_.shape, sim, P);
    }
    void operator()(RigidHook at) {
      for (const StepRigidDriver<Dim>* r : rigids) r->add_phases(at, refresh, sim.opt_.shape, sim, P);
    }
    void operator()(ExchangeHook) {}  // one process: nothing to exchange
    void operator()(SchemePhase phase) {
      Simulation* const s = &sim;
      switch (phase) {
        case SchemePhase::time_step:
          P.add("time_step", &T::time_step, [s, set = set](StepContext& c) {
            c.speed_in_scatter = s->wave_speeds_current() && c.dt_limit > 0.0;
            if (!c.speed_in_scatter) set(c, s->particle_speed_max());
          });
          break;
        case SchemePhase::shape_functions:
          P.add("shape_functions", &T::shape_functions, [s](StepContext&) { s->template prepare_step<Kernel>(); });
          break;
        case SchemePhase::extended_stencils:  // per field: EBS rebuilt (keeping the driven nodes), boxes, weights
          if constexpr (is_extended<Kernel>)
            P.add("extended_stencils", &T::shape_functions, [s](StepContext&) { s->prepare_extended_stencils(); });
          break;
        case SchemePhase::particle_to_grid:
          P.add("particle_to_grid", &T::particle_to_grid, [s, usf = usf, set = set](StepContext& c) {
            s->template map_to_grid<Kernel>(!usf, c.speed_in_scatter);
            if (c.speed_in_scatter)
              set(c, *std::max_element(s->threads_.speed_max.begin(), s->threads_.speed_max.end()));
          });
          break;
        case SchemePhase::velocity_from_momentum:
          P.add("velocity_from_momentum", &T::grid_update, [s](StepContext&) { s->velocity_from_momentum(); });
          break;
        case SchemePhase::stress_update:
          P.add("stress_update", &T::stress_update, [s](StepContext& c) { s->template stress_pass<Kernel>(c.dt); });
          break;
        case SchemePhase::internal_forces:
          P.add("internal_forces", &T::particle_to_grid, [s](StepContext&) { s->template add_internal_forces<Kernel>(); });
          break;
        case SchemePhase::velocity_conditions:
          P.add("velocity_conditions", &T::grid_update, [s](StepContext& c) { s->apply_grid_velocity_conditions(c.dt); });
          break;
        case SchemePhase::momentum_update:
          P.add("momentum_update", &T::grid_update, [s](StepContext& c) { s->advance_grid_momentum(c.dt); });
          break;
        case SchemePhase::nodal_velocities:
          P.add("nodal_velocities", &T::grid_update, [s](StepContext&) { s->nodal_velocities(); });
          break;
        case SchemePhase::particle_update:  // grid-to-particle and stress update in one pass over the stencils
          P.add("particle_update", &T::stress_update, [s, refresh = refresh](StepContext& c) {
            const ParticlePassResult r = s->template particle_pass<true, true>(c.dt, s->template stencils<Kernel>(), refresh);
            c.bad = r.bad, c.beyond = r.beyond;
            advance_stored_lead(true, c.dt, r.stress_power, s->work_books_.stored_lead, s->work_books_.stress_power,
                                s->work_books_.stress_dt);
          });
          break;
        case SchemePhase::grid_to_particle:
          P.add("grid_to_particle", &T::grid_to_particle, [s](StepContext& c) {
            c.bad = s->template particle_pass<true, false>(c.dt, s->template stencils<Kernel>()).bad;
          });
          break;
        case SchemePhase::end_particle_update:
          P.add("end_particle_update", &T::grid_to_particle, [s, refresh = refresh](StepContext& c) { s->end_particle_update(c, refresh); });
          break;
        case SchemePhase::remap_momentum:
          P.add("remap_momentum", &T::particle_to_grid, [s](StepContext&) { s->template remap_momentum<Kernel>(); });
          break;
      }
    }
  };
  SerialEngine engine{*this, P, scheme, usf, refresh, loads, filters, rigids, set_step};
  add_scheme_phases(usf, scheme == UpdateScheme::musl, engine);
}

// The start of a step: threads for this step's particle count, the thread partition and the stencils
// (contact: with the per-material boxes of nodes and the field layout; EBS: its own phase after the
// rigid drivers', extended_stencils).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::prepare_step() {
  // Below ~2000 particles per thread the fork/join and the scatter-buffer reduction cost more than
  // the particle work they share.
  const int max_threads = omp_get_max_threads();
  threads_.count = threads_for_particles(p_.size(), max_threads);
  if (static_cast<int>(threads_.nodes.size()) != threads_.count - 1) {
    threads_.nodes.resize(static_cast<std::size_t>(std::max(0, threads_.count - 1)));
    for (auto& tn : threads_.nodes) tn.resize(nodes_.mass.size(), contact_setup_.enabled);
  }
  update_partition();
  if constexpr (!is_extended<Kernel>) {
    auto& st = stencils<Kernel>();
    if (st.size() != p_.size()) st.resize(p_.size()), stencil_store_.current = false;
    if (contact_setup_.enabled) {
      // Unless current_stencils() evaluated them after the last step (same positions, same numbers).
      if (!stencil_store_.current) evaluate_stencils<Kernel>();  // also the per-material boxes of nodes
      layout_fields(layout_.box_lo, layout_.box_hi);
    }
  }
  if (!contact_methods_.empty()) {  // the step's frictional work, of every contact method
    std::fill(contact_books_.work_first.begin(), contact_books_.work_first.end(), 0.0);
    std::fill(contact_books_.work_second.begin(), contact_books_.work_second.end(), 0.0);
  }
}

// Multimaterial contact after the momentum extrapolation: the contact nodes, their contact terms, the
// extents (extent separation) and the first contact pass.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::contact_at_extrapolated(double dt) {
  find_contact_nodes();
  // The contact terms of multimaterial contact, Σ S_ip m_p x_p (or the displacement x_p − x_p^(0)),
  // Ω = Σ S_ip V_p and g = Σ G_ip V_p per material (Nairn 2018 eqs. 4–6, 9). Contact reads them at
  // the contact nodes' slots only (gather_contact_sides), so only the particles whose stencil reaches
  // such a slot scatter them: each of those slots gets the same particles' terms in the same order as
  // a scatter by every particle would give it (the same bits); other slots hold partial sums or 0.
  // When most particles reached a contact node on the last step, map_to_grid scattered every
  // particle's terms instead (reach_share, terms_scattered).
  thread_local std::vector<std::uint8_t> at_contact;  // per slot: 1 at a contact node (no allocation once grown)
  at_contact.assign(nodes_.mass.size(), 0);
  for (const ContactEntry& c : contact_nodes_.entries) at_contact[static_cast<std::size_t>(c.slot)] = 1;
  const std::uint8_t* const flag = at_contact.data();
  // The reach test as one load per particle (issue 35, speed-s52): the flags dilated by the stencil's
  // box, read at the stencil's first slot, say exactly whether any of its K^Dim slots is flagged (the
  // test above it replaces walked all of them). EBS stencils have no box: they walk.
  thread_local std::vector<std::uint8_t> reach_flag, reach_tmp;
  if constexpr (!is_extended<Kernel>) step_detail::dilate_slot_flags<Kernel::K, Dim>(fields_, at_contact, reach_flag, reach_tmp);
  const std::uint8_t* const reach = reach_flag.data();
  auto& st = stencils<Kernel>();
  const bool displacement = contact_setup_.options.separation == SeparationMethod::displacement;
  // Unless map_to_grid scattered them with mass and momentum this step (every particle's). The
  // particles whose stencils reach a contact node's slot are counted on the way (reach_share: it
  // decides the next step's scatter); after a fused scatter, by a pass of one load per particle.
  const bool scattered = contact_nodes_.terms_scattered;
  contact_nodes_.terms_scattered = false;
  std::size_t reaching = 0;
  if (!scattered) {
    // On the threads the particles that reached a contact node on the last step pay for
    // (threads_for_reach): few near one interface would leave a team mate a wake and an idle wait.
    // EBS walks every stencil (no reach_share): all threads.
    scatter_phase(Accumulated{false, false, false, true}, true,
                  [&](NodalFields<Dim>& acc, const NodeIndexer<Dim>& ix, std::size_t, std::size_t kb, std::size_t ke) {
      double* const domain = acc.domain.data();
      Vec<Dim>* const mass_position = acc.mass_position.data();
      Vec<Dim>* const domain_gradient = acc.domain_gradient.data();
      decltype(auto) stk = indexable(st);
      const NodeIndexer<Dim> index = ix;
      std::size_t mine = 0;
      for (std::size_t k = kb; k < ke; ++k) {
        if constexpr (is_extended<Kernel>) {
          int reaches = 0;
          stk[k].for_each(index, [&](int i, double, const Vec<Dim>&) { reaches |= flag[i]; });
          if (!reaches) continue;
        } else {
          if (!reach[step_detail::first_slot(stk[k], index)]) continue;
        }
        ++mine;
        const double mp = p_.mass[k], Vp = p_.volume[k];
        const Vec<Dim> mx = mp * (displacement ? Vec<Dim>(p_.position[k] - p_.initial_position[k]) : p_.position[k]);
        stk[k].for_each(index, [&](int i, double S, const Vec<Dim>& G) {
          mass_position[i] += S * mx;
          domain[i] += S * Vp;
          domain_gradient[i] += Vp * G;
        });
      }
#pragma omp atomic
      reaching += mine;
    }, is_extended<Kernel> ? threads_.count : threads_for_reach(contact_nodes_.reach_share, p_.size(), threads_.count));
  }
  if constexpr (!is_extended<Kernel>) {
    std::size_t all = 0;
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const int f = layout_.field_of_material[m];
      if (f < 0) continue;
      all += layout_.material_end[m] - layout_.material_begin[m];
      if (!scattered) continue;
      const NodeIndexer<Dim> index = fields_[static_cast<std::size_t>(f)].index;
      for (std::size_t k = layout_.material_begin[m]; k < layout_.material_end[m]; ++k)
        reaching += reach[step_detail::first_slot(st[k], index)];
    }
    contact_nodes_.reach_share = all ? static_cast<double>(reaching) / static_cast<double>(all) : 0.0;
  }
  if (contact_setup_.options.separation == SeparationMethod::extent) measure_contact_extents(stencils<Kernel>());
  resolve_contact(ContactPass::extrapolated, dt);
}

// USF and MUSL: the stress update from nodes_.velocity alone.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::stress_pass(double dt) {
  const ParticlePassResult r = particle_pass<false, true>(dt, stencils<Kernel>());
  advance_stored_lead(opt_.scheme != UpdateScheme::usf, dt, r.stress_power, work_books_.stored_lead,
                      work_books_.stress_power, work_books_.stress_dt);
  throw_beyond_hugoniot(r.beyond);
}

// After grid-to-particle: the step's time and count advance, a particle with a non-finite state or
// outside the grid stops the run (check_particle), then (USL) one compressed past its Hugoniot's limit.
// The stencils are current again only if the particle pass evaluated them (refreshed).
template <int Dim>
void Simulation<Dim>::end_particle_update(StepContext& ctx, bool refreshed) {
  stencil_store_.current = false;  // the particles moved; the rest of the step keeps the start-of-step stencils
  clock_.time += ctx.dt;
  ++clock_.step;
  check_particle(ctx.bad, ctx.dt);
  stencil_store_.current = refreshed;  // every particle inside the grid: the pass evaluated every stencil
  throw_beyond_hugoniot(ctx.beyond);
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
  if (!contact_setup_.enabled) {
    parallel_for(threads_.count, p_.size(), [&](std::size_t k) { stk[k].evaluate(grid, position[k], half_size[k]); });
    return;
  }
  const std::size_t nm = materials_.size();
  update_partition();
  step_detail::StencilBoxes<Dim>::clear(layout_.box_lo, layout_.box_hi);
  // One parallel region for all materials (a grain is a few hundred particles: a region per
  // material would cost more in fork/join than its particles); per-thread boxes merged at the end.
  parallel_region(threads_.count, [&] {
    thread_local step_detail::StencilBoxes<Dim> boxes;
    boxes.reset(nm);
    for_each_part(threads_.partition, [&](int t) {
      for (std::size_t m = 0; m < nm; ++m) {
        const std::size_t kb = threads_.partition.even_lo(t, layout_.material_begin[m]), ke = threads_.partition.even_hi(t, layout_.material_end[m]);
        for (std::size_t k = kb; k < ke; ++k) {
          stk[k].evaluate(grid, position[k], half_size[k]);
          boxes.extend(stk[k], boxes.lo[m], boxes.hi[m]);
        }
      }
    });
#pragma omp critical(frictherm_stencil_boxes)
    boxes.merge_into(layout_.box_lo, layout_.box_hi);
  });
}

template <int Dim>
StencilView<Dim> Simulation<Dim>::current_stencils() {
  if (!finalized_ || opt_.shape == ShapeKind::extended_bspline) return {};
  return dispatch_shape(opt_.shape, [&](auto kernel) {
    using Kernel = decltype(kernel);
    auto& st = stencils<Kernel>();
    if (!stencil_store_.current || st.size() != p_.size()) {
      PhaseLap lap;  // outside the step: timed with the step's shape_functions phase
      evaluate_stencils<Kernel>();
      stencil_store_.current = true;
      lap.to(schedule_.times.shape_functions);
    }
    return StencilView<Dim>{opt_.shape, static_cast<const void*>(st.data()), st.size()};
  });
}

// Each part of the thread partition clears the slots it scatters into (its own fields in the nodes,
// its buffer for a field it shares) and scatters; after a barrier the shared fields' buffers are
// summed into the nodes. One parallel region per phase (none on one thread: parallel_region.hpp).
// `threads` may be fewer than the partition's parts: a thread then runs several parts in order
// (for_each_part), each into the same target as its own thread would, so the same sums.
template <int Dim>
template <class Scatter>
void Simulation<Dim>::scatter_phase(Accumulated which, bool include_rigid, Scatter&& scatter, int threads) {
  parallel_region(threads, [&] {
    for_each_part(threads_.partition, [&](int t) {
      clear_scatter_targets(t, which);
      for (std::size_t m = 0; m < materials_.size(); ++m) {
        const int f = layout_.field_of_material[m];
        if (f < 0 || (!include_rigid && materials_[m].is_rigid())) continue;
        const std::size_t kb = threads_.partition.lo(t, layout_.material_begin[m]), ke = threads_.partition.hi(t, layout_.material_end[m]);
        if (kb >= ke) continue;
        scatter(scatter_target(t, f), fields_[static_cast<std::size_t>(f)].index, m, kb, ke);
      }
    });
    if (!threads_.partition.shared_fields.empty()) {
#pragma omp barrier
      sum_shared_fields(which);
    }
  });
}

// Particle-to-grid of mass, momentum and (USL/MUSL) internal force and body force:
// m_i = Σ S_ip m_p, p_i = Σ S_ip m_p v_p, f_i = Σ (−V_p σ_p G_ip + S_ip m_p g) (Nairn 2018 eqs. 1–3).
// Rigid materials only mark their presence (mass; with contact, position and domain): their velocity
// is prescribed. The contact terms follow once the contact nodes are known (contact_at_extrapolated).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_to_grid(bool with_forces, bool take_speeds) {
  auto& st = stencils<Kernel>();
  // take_speeds: each part's largest c_p + |v_p| (as stable_time_step, from 0) into threads_.speed_max.
  threads_.speed_max.assign(static_cast<std::size_t>(threads_.partition.threads), 0.0);
  double* const speed_max = threads_.speed_max.data();
  const std::size_t speed_count = threads_.speed_max.size();
  const double* const wave_speed = wave_speeds_.speed.data();
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  const bool prepared = stencil_store_.current;  // by current_stencils() since the last step
  // The contact terms with mass, momentum and force, by every particle (the same sums in every slot
  // the separate scatter of contact_at_extrapolated gives a contact node's slot, and full sums in the
  // others), when most particles reached a contact node on the last step: then the separate scatter
  // would walk most stencils a second time. 3D PBX (pbx_3d.json, nearly every particle reaches): 634 M
  // instructions of the separate scatter in 10 steps became 463 M more in this one, and 38 steps
  // took 7-9 % less CPU (docs/performance.md, speed-s52); the 2D twin (a third reach) keeps the separate scatter (fused: +64 M in
  // 1540 steps). EBS stencils keep the separate scatter (no reach share is measured for them).
  const bool fused = contact_setup_.enabled && !is_extended<Kernel> && contact_nodes_.reach_share > 0.5;
  contact_nodes_.terms_scattered = fused;
  const bool displacement = contact_setup_.options.separation == SeparationMethod::displacement;
  const bool weightless = !is_extended<Kernel> && (g.array() == 0.0).all();
  scatter_phase(Accumulated{true, true, true, fused}, true,
                [&](NodalFields<Dim>& acc, const NodeIndexer<Dim>& ix, std::size_t m, std::size_t kb, std::size_t ke) {
    if (take_speeds) {  // the part holding [kb, ke): the one whose range starts at or before kb
      std::size_t part = 0;
      while (part + 1 < speed_count && threads_.partition.begin[part + 1] <= kb) ++part;
      double c = speed_max[part];
      for (std::size_t k = kb; k < ke; ++k) c = std::max(c, wave_speed[k] + p_.velocity[k].norm());
      speed_max[part] = c;
    }
    if (!contact_setup_.enabled) {
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
    Vec<Dim>* const momentum = acc.momentum.data();
    Vec<Dim>* const force = acc.force.data();
    decltype(auto) stk = indexable(st);
    const NodeIndexer<Dim> index = ix;  // a local copy, kept in registers
    // The loop twice, with and without the forces (a rigid material's particles): no test per node.
    double* const domain = acc.domain.data();
    Vec<Dim>* const mass_position = acc.mass_position.data();
    Vec<Dim>* const domain_gradient = acc.domain_gradient.data();
    // Without gravity (3D PBX) the body force S m_p g is +0 and f_i + (+0 − V σ G) = f_i − V σ G in
    // every bit: the sums start at +0 and never become −0, and the kernels' S are ≥ 0 (not EBS's,
    // which keeps the full form). 3 multiplications and 3 additions less per node.
    const auto scatter = [&](auto with_forces_here, auto with_contact_terms, auto with_gravity) {
      for (std::size_t k = kb; k < ke; ++k) {
        const double mp = p_.mass[k];
        const Vec<Dim> mv = mp * p_.velocity[k];
        const Mat<Dim> Vsig = p_.volume[k] * p_.stress[k];
        const Vec<Dim> mg = mp * g;
        const double Vp = p_.volume[k];
        Vec<Dim> mx = Vec<Dim>::Zero();
        if constexpr (decltype(with_contact_terms)::value)
          mx = mp * (displacement ? Vec<Dim>(p_.position[k] - p_.initial_position[k]) : p_.position[k]);
        stk[k].for_each(index, [&](int i, double S, const Vec<Dim>& G) {
          mass[i] += S * mp;
          momentum[i] += S * mv;
          if constexpr (decltype(with_forces_here)::value) {
            if constexpr (decltype(with_gravity)::value) force[i] += S * mg - Vsig * G;
            else force[i] -= Vsig * G;
          }
          if constexpr (decltype(with_contact_terms)::value) {  // as contact_at_extrapolated scatters them
            mass_position[i] += S * mx;
            domain[i] += S * Vp;
            domain_gradient[i] += Vp * G;
          }
        });
      }
    };
    const std::true_type yes;
    const std::false_type no;
    if (fused) {
      if (!forces) scatter(no, yes, yes);
      else if (weightless) scatter(yes, yes, no);
      else scatter(yes, yes, yes);
    } else {
      if (!forces) scatter(no, no, yes);
      else if (weightless) scatter(yes, no, no);
      else scatter(yes, no, yes);
    }
  }, threads_.count);
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
  }, threads_.count);
}

// MUSL: nodal momentum rebuilt from the updated particle velocities, p_i = Σ S_ip m_p v_p (the MUSL
// list then resolves contact again on the remapped momenta).
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
  }, threads_.count);
}

#define FRICTHERM_INSTANTIATE_STEP(D) \
  template double Simulation<D>::step(double); \
  template std::vector<const char*> Simulation<D>::step_phase_names(); \
  template void Simulation<D>::build_phases(); \
  template long Simulation<D>::phase_key() const; \
  template void Simulation<D>::end_particle_update(StepContext&, bool); \
  template StencilView<D> Simulation<D>::current_stencils(); \
  template void Simulation<D>::contact_at_extrapolated<LinearKernel>(double); \
  template void Simulation<D>::contact_at_extrapolated<UGIMPKernel>(double); \
  template void Simulation<D>::contact_at_extrapolated<QuadraticBSplineKernel>(double); \
  template void Simulation<D>::contact_at_extrapolated<ExtendedBSplineKernel>(double);
FRICTHERM_INSTANTIATE_STEP(2)
FRICTHERM_INSTANTIATE_STEP(3)
#undef FRICTHERM_INSTANTIATE_STEP

}  // namespace frictherm::mechanics
