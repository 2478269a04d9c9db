// The particle loops after the grid update: grid-to-particle (FLIP, PIC blend, XPIC/FMPM) and the
// stress update (velocity gradient, deformation gradient, constitutive law). One pass serves either
// or both: USL runs both in one pass over the stencils (simulation_step.cpp), which reads each
// particle's stencil and its nodes' velocities once and costs one parallel region instead of two.
// Particle by particle the arithmetic is that of the separate loops, so the results are the same.
// With `refresh` (USL with contact) the pass also evaluates each moved particle's stencil for the next
// step while its position is at hand, and moves the rigid materials' particles (by the motions the
// rigid driver set: rigids/prescribed_velocity.cpp) and evaluates theirs:
// the start of the next step and the heat hand-off after it need not pass over the particles again.
#include <frictherm/mechanics/constitutive/stress_update.hpp>
#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/transfer/grid_to_particle.hpp>

#include "stencil_access.hpp"

#include <omp.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <vector>

namespace frictherm::mechanics {

namespace {
// The parts of the split this thread runs (see simulation_step.cpp).
template <class Fn>
void for_each_part(const PassSplit& partition, Fn&& fn) {
  for (int t = omp_get_thread_num(); t < partition.threads; t += omp_get_num_threads()) fn(t);
}

// Σ_i v_i ⊗ G_ip into a velocity gradient: the scalar 2D form of the PBX path, or an Eigen matrix.
FRICTHERM_ALWAYS_INLINE void add_gradient(VelocityGradient2& L, const Vec<2>& v, const Vec<2>& G) { L.add(v, G); }
template <int Dim>
FRICTHERM_ALWAYS_INLINE void add_gradient(Mat<Dim>& L, const Vec<Dim>& v, const Vec<Dim>& G) {
  L.noalias() += v * G.transpose();
}

// σ:L in either form of the velocity gradient (stress_update.hpp's stress_power).
FRICTHERM_ALWAYS_INLINE double stress_power_of(const Mat<2>& sigma, const VelocityGradient2& L) { return stress_power(sigma, L); }
template <int Dim>
FRICTHERM_ALWAYS_INLINE double stress_power_of(const Mat<Dim>& sigma, const Mat<Dim>& L) { return stress_power<Dim>(sigma, L); }
}  // namespace

// Grid-to-particle (Kinematics; FLIP): v_p += dt Σ S_ip a_i, x_p += dt Σ S_ip v_i^{n+1}; with a PIC
// relaxation time τ, v_p ← (1 − α) v_p + α Σ S_ip v_i^{n+1}, α = 1 − e^(−dt/τ), which damps the particle
// velocity modes the grid cannot see at a rate independent of the time step; XPIC/FMPM from the
// filtered velocity. Stress update (Stress): L_p = Σ_i v_i ⊗ G_ip, F ← (I + L dt) F, V = det(F) V0,
// then the material's stress. Returns the first particle with a non-finite state or outside the grid,
// the first compressed past its Hugoniot's limit (−1: none) and the stress power Σ V σ:L after the
// update (the energy books' stored_lead, energy_books.hpp).
template <int Dim>
template <bool Kinematics, bool Stress, class Stencils>
typename Simulation<Dim>::ParticlePassResult Simulation<Dim>::particle_pass(double dt, Stencils& st, bool refresh) {
  long first_bad = std::numeric_limits<long>::max();  // min-reduction identity
  long last_beyond = -1;                              // max-reduction identity
  double external_work = 0.0;
  // Σ_p V_p σ_p:L_p of the updated particles after the update and (stress-only passes: USF's books)
  // before it: the books' stored_lead (advance_stored_lead).
  double stress_power = 0.0, stress_power_start = 0.0;
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  const double pic = pic_blend_fraction(dt, opt_.pic_relaxation_time);
  const ParticleUpdate update = opt_.particle_update;
  const bool flip = update == ParticleUpdate::flip;
  const Analysis an = opt_.analysis;
  if (Stress && wave_speeds_.speed.size() != p_.size())
    wave_speeds_.speed.assign(p_.size(), -std::numeric_limits<double>::infinity());  // rigid: never a CFL speed
  // Plain pointers (see map_to_grid): the particle stores below would otherwise reload them.
  const Vec<Dim>* const acceleration = nodes_.acceleration.data();
  const Vec<Dim>* const velocity = nodes_.velocity.data();
  const Vec<Dim>* const filtered_v = transfer_.filtered.data();  // v* of XPIC/FMPM (transfer.hpp)
  // The particles' arrays the same way: the velocity and position stores below are Eigen packet stores.
  Vec<Dim>* const xp = p_.position.data();
  Vec<Dim>* const vp = p_.velocity.data();
  const Vec<Dim>* const lp = p_.half_size.data();
  const double* const mp = p_.mass.data();
  Mat<Dim>* const Fp = p_.deformation_gradient.data();
  Mat<Dim>* const sigma_p = p_.stress.data();
  double* const Vp = p_.volume.data();
  const double* const V0p = p_.initial_volume.data();
  double* const szz_p = p_.stress_zz.data();
  double* const ep_p = p_.plastic_strain.data();
  double* const e_p = p_.internal_energy.data();
  double* const wp_p = p_.plastic_work.data();
  double* const cp = wave_speeds_.speed.data();
  decltype(auto) stk = step_detail::indexable(st);
  // The next step's stencils (refresh): Stencil arrays only; EBS builds its weights per step.
  constexpr bool refreshable = Kinematics && !std::is_same_v<Stencils, PrecomputedStencils<Dim>>;
  refresh = refresh && refreshable;
  const std::size_t nm = materials_.size();
  if (refresh) step_detail::StencilBoxes<Dim>::clear(layout_.box_lo, layout_.box_hi);
  const Grid<Dim> grid = grid_;  // a local copy (see evaluate_stencils)
  [[maybe_unused]] const auto next_stencils = [&] {
    if constexpr (refreshable) return st.data();
    else return nullptr;
  }();
  // On two or more threads each particle's external work goes to its block of the split, summed in
  // block order after the pass: the same sum wherever the split's boundaries are (thread_partition.hpp).
  const bool blocked = threads_.pass_split.threads > 1;
  if (blocked) threads_.work_blocks.assign(threads_.pass_split.blocks(), 0.0);
  if (blocked && Stress) threads_.power_blocks.assign(2 * threads_.pass_split.blocks(), 0.0);  // (end, start) per block
  // The loads' work below, force · the displacement this pass gives: the loaded particles' positions
  // before it (reused from step to step: no allocation once grown).
  // With them, the grid acceleration at each loaded particle, a_p = Σ_i S_ip a_i, from this step's
  // stencil (the pass may overwrite it with the next step's): load_work's mean displacement.
  thread_local std::vector<Vec<Dim>> load_start_position, load_acceleration;
  if constexpr (Kinematics) {
    load_start_position.resize(conditions_.resolved_loads.size());
    load_acceleration.resize(conditions_.resolved_loads.size());
    for (std::size_t j = 0; j < conditions_.resolved_loads.size(); ++j) {
      const std::size_t k = conditions_.resolved_loads[j].particle;
      load_start_position[j] = p_.position[k];
      const int f = layout_.field_of_material[static_cast<std::size_t>(p_.material[k])];
      load_acceleration[j] = f < 0 ? Vec<Dim>(Vec<Dim>::Zero())
                                   : load_point_acceleration<Dim>(stk[k], fields_[static_cast<std::size_t>(f)].index,
                                                                  [&](int i) -> const Vec<Dim>& { return acceleration[i]; });
    }
  }
  double* const work_block = threads_.work_blocks.data();
  double* const power_block = threads_.power_blocks.data();

  // The region's body: its own minimum, maximum and sum (in registers) into the reduction's.
  const auto pass = [&](long& bad_out, long& beyond_out, double& work_out, double& power_out, double& start_out) {
  long bad = std::numeric_limits<long>::max(), beyond = -1;
  double work = 0.0, power = 0.0, start = 0.0;
  thread_local step_detail::StencilBoxes<Dim> boxes;
  if (refresh) boxes.reset(nm);
  for_each_part(threads_.pass_split, [&](int t) {
    const double started = omp_get_wtime();
    std::size_t m = 0;  // the material of the particles run() is given
    auto add_work = [&](std::size_t k, double w) {
      if (blocked) work_block[k / PassSplit::kBlock] += w;
      else work += w;
    };
    [[maybe_unused]] auto add_power = [&](std::size_t k, double w, int which) {  // which: 0 end, 1 start
      if (blocked) power_block[2 * (k / PassSplit::kBlock) + static_cast<std::size_t>(which)] += w;
      else (which == 0 ? power : start) += w;
    };
    // Particle k at its new position: its stencil for the next step, and its material's box.
    [[maybe_unused]] auto refresh_stencil = [&](std::size_t k, IVec<Dim>& lo, IVec<Dim>& hi) {
      if constexpr (refreshable) {
        next_stencils[k].evaluate(grid, xp[k], lp[k]);
        boxes.extend(next_stencils[k], lo, hi);
      }
    };
    // One material's particles [kb, ke): gather from the nodes, then the kinematic and stress updates;
    // `stress(k, L)` is the material's constitutive update (false: beyond the Hugoniot's limit).
    // Defined in the parallel region: it adds to this thread's copies of bad, beyond and work.
    auto run = [&](const NodeIndexer<Dim>& ix, std::size_t kb, std::size_t ke, auto gradient_zero, auto&& stress) {
      using Gradient = decltype(gradient_zero);
      IVec<Dim> lo = step_detail::StencilBoxes<Dim>::none_lo(), hi = step_detail::StencilBoxes<Dim>::none_hi();
      for (std::size_t k = kb; k < ke; ++k) {
        Vec<Dim> a = Vec<Dim>::Zero(), v = Vec<Dim>::Zero(), vf = Vec<Dim>::Zero();
        Gradient L = gradient_zero;
        if (!Kinematics || flip) {
          stk[k].for_each(ix, [&](int i, [[maybe_unused]] double S, [[maybe_unused]] const Vec<Dim>& G) {
            if constexpr (Kinematics) {
              a += S * acceleration[i];
              v += S * velocity[i];
            }
            if constexpr (Stress) add_gradient(L, velocity[i], G);
          });
        } else {
          stk[k].for_each(ix, [&](int i, double S, [[maybe_unused]] const Vec<Dim>& G) {
            a += S * acceleration[i];
            v += S * velocity[i];
            vf += S * filtered_v[i];
            if constexpr (Stress) add_gradient(L, velocity[i], G);
          });
        }
        if constexpr (Kinematics) {
          // FLIP (PIC blend), XPIC or FMPM: the kernel shared with the decomposed step.
          add_work(k, update_particle_velocity<Dim>(update, pic, dt, mp[k], g, a, v, vf, vp[k]));
          xp[k] += dt * v;
          const bool ok = vp[k].allFinite() && grid.contains(xp[k]);
          if (!ok) bad = std::min(bad, static_cast<long>(k));
          else if (refresh) refresh_stencil(k, lo, hi);  // (a bad particle stops the run: check_particle)
        }
        if constexpr (Stress) {
          if constexpr (!Kinematics) add_power(k, Vp[k] * stress_power_of(sigma_p[k], L), 1);  // before the update
          if (!stress(k, L)) beyond = std::max(beyond, static_cast<long>(k));
          add_power(k, Vp[k] * stress_power_of(sigma_p[k], L), 0);
        }
      }
      if (refresh) boxes.merge(m, lo, hi);
    };
    for (m = 0; m < nm; ++m) {
      const Material& mat = materials_[m];
      const int f = layout_.field_of_material[m];
      if (f < 0 || mat.is_rigid()) {
        // Not updated by this pass: with refresh, this part's even share of them moved (rigid) and their
        // stencils evaluated.
        if (!refresh) continue;
        const std::size_t b = layout_.material_begin[m], n = layout_.material_end[m] - b, T = static_cast<std::size_t>(threads_.pass_split.threads);
        const std::size_t tt = static_cast<std::size_t>(t);
        for (std::size_t k = b + n * tt / T; k < b + n * (tt + 1) / T; ++k) {
          if (mat.is_rigid()) layout_.rigid_motion[m].move(vp[k], xp[k]);
          refresh_stencil(k, boxes.lo[m], boxes.hi[m]);
        }
        continue;
      }
      const NodeIndexer<Dim> ix = fields_[static_cast<std::size_t>(f)].index;
      const std::size_t kb = threads_.pass_split.lo(t, layout_.material_begin[m]), ke = threads_.pass_split.hi(t, layout_.material_end[m]);
      if (kb >= ke) continue;
      if constexpr (!Stress) {
        run(ix, kb, ke, Mat<Dim>(Mat<Dim>::Zero()), [](std::size_t, const Mat<Dim>&) { return true; });
        continue;
      }
      const StressLaw law = stress_law(mat, an);  // per material, not per particle
      const auto state = [&](std::size_t k) {
        return StressState<Dim>{Fp[k], Vp[k], V0p[k], sigma_p[k], szz_p[k], ep_p[k], e_p[k], wp_p[k], cp[k]};
      };
      if constexpr (Dim == 2) {
        if (law.mie_gruneisen()) {  // the PBX materials: plane_strain_update.hpp, on scalars (same arithmetic)
          // A local copy: no particle store can touch it, so the compiler hoists what depends on the
          // material only (ρ0 C0², −2G/3, …) out of the loop.
          const MieGruneisenParams params = mat.mie_gruneisen;
          run(ix, kb, ke, VelocityGradient2{}, [&](std::size_t k, const VelocityGradient2& L) {
            return update_stress_plane_strain(params, law.min_J, L, dt, state(k));
          });
          continue;
        }
        if (law.kind == MaterialKind::linear_elastic) {  // the sliding blocks: the same arithmetic on scalars
          const StressLaw le = law;  // a local copy, as params above
          run(ix, kb, ke, VelocityGradient2{}, [&](std::size_t k, const VelocityGradient2& L) {
            update_stress_linear_elastic_2d(le, an, L, dt, state(k));
            return true;
          });
          continue;
        }
      }
      run(ix, kb, ke, Mat<Dim>(Mat<Dim>::Zero()),
          [&](std::size_t k, const Mat<Dim>& L) { return update_stress<Dim>(mat, law, an, L, dt, state(k)); });
    }
    threads_.pass_split.seconds[static_cast<std::size_t>(t)] = omp_get_wtime() - started;
  });
  if (refresh) {
#pragma omp critical(frictherm_stencil_boxes)
    boxes.merge_into(layout_.box_lo, layout_.box_hi);
  }
  bad_out = std::min(bad_out, bad);
  beyond_out = std::max(beyond_out, beyond);
  work_out += work;
  power_out += power;
  start_out += start;
  };
  if (without_team(threads_.count)) {  // without a team (parallel_region.hpp)
    pass(first_bad, last_beyond, external_work, stress_power, stress_power_start);
  } else {
#pragma omp parallel num_threads(threads_.count) reduction(min : first_bad) reduction(max : last_beyond) reduction(+ : external_work, stress_power, stress_power_start)
    pass(first_bad, last_beyond, external_work, stress_power, stress_power_start);
  }
  double work = external_work;
  if (blocked) {
    for (const double w : threads_.work_blocks) work += w;
    if constexpr (Stress)
      for (std::size_t b = 0; b < threads_.power_blocks.size(); b += 2) {
        stress_power += threads_.power_blocks[b];
        stress_power_start += threads_.power_blocks[b + 1];
      }
    threads_.pass_split.rebalance(layout_.material_begin, layout_.material_end, layout_.field_of_material);
  }
  if constexpr (Kinematics) {
    for (std::size_t j = 0; j < conditions_.resolved_loads.size(); ++j) {
      const ResolvedLoad& L = conditions_.resolved_loads[j];
      work += load_work<Dim>(load_force<Dim>(L.force, *L.scale, clock_.time), p_.position[L.particle] - load_start_position[j],
                             load_acceleration[j], dt);
    }
    work_books_.external += work;
  }
  if constexpr (Stress) wave_speeds_.ready = true;
  return {first_bad == std::numeric_limits<long>::max() ? -1 : first_bad, last_beyond,
          StressPower{stress_power_start, stress_power}};
}

#define FRICTHERM_INSTANTIATE_PASS_FOR(D, ...)                                                          \
  template Simulation<D>::ParticlePassResult Simulation<D>::particle_pass<true, false, __VA_ARGS__>(double, __VA_ARGS__&, bool); \
  template Simulation<D>::ParticlePassResult Simulation<D>::particle_pass<false, true, __VA_ARGS__>(double, __VA_ARGS__&, bool); \
  template Simulation<D>::ParticlePassResult Simulation<D>::particle_pass<true, true, __VA_ARGS__>(double, __VA_ARGS__&, bool);
#define FRICTHERM_INSTANTIATE_PASS(D)                                          \
  FRICTHERM_INSTANTIATE_PASS_FOR(D, std::vector<Stencil<D, LinearKernel>>)     \
  FRICTHERM_INSTANTIATE_PASS_FOR(D, std::vector<Stencil<D, UGIMPKernel>>)      \
  FRICTHERM_INSTANTIATE_PASS_FOR(D, std::vector<Stencil<D, QuadraticBSplineKernel>>) \
  FRICTHERM_INSTANTIATE_PASS_FOR(D, PrecomputedStencils<D>)
FRICTHERM_INSTANTIATE_PASS(2)
FRICTHERM_INSTANTIATE_PASS(3)
#undef FRICTHERM_INSTANTIATE_PASS
#undef FRICTHERM_INSTANTIATE_PASS_FOR

}  // namespace frictherm::mechanics
