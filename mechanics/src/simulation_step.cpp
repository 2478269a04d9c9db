// One explicit MPM step: particle-to-grid, grid momentum update, grid-to-particle, stress update.
// Particle loops are templated on the shape-function kernel (static dispatch) and threaded with
// OpenMP; scatters go to per-thread nodal buffers that are summed afterwards.
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <omp.h>

#include <cmath>
#include <limits>
#include <sstream>

namespace frictherm::mechanics {

template <int Dim>
template <class Kernel>
std::vector<Stencil<Dim, Kernel>>& Simulation<Dim>::stencils() {
  if constexpr (std::is_same_v<Kernel, LinearKernel>) return st_linear_;
  else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return st_ugimp_;
  else return st_quadratic_;
}

template <int Dim>
double Simulation<Dim>::step(double dt_limit) {
  finalize();
  const double dt = std::min(stable_time_step(), dt_limit);
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "step " << step_ << ", t = " << time_ << " s: time step " << dt << " s is not positive and finite";
    throw SimulationError(msg.str(), step_, time_, -1);
  }
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
  threads_ = std::max(1, std::min(max_threads, static_cast<int>(p_.size() / 2000)));
  const int nthreads = threads_;
  if (static_cast<int>(thread_nodes_.size()) != nthreads - 1) {
    thread_nodes_.resize(static_cast<std::size_t>(std::max(0, nthreads - 1)));
    for (auto& t : thread_nodes_) t.resize(grid_.node_count());
  }
  stencils<Kernel>().resize(p_.size());
  const double t = time_;
  if (opt_.scheme == UpdateScheme::usf) {
    map_to_grid<Kernel>(dt, /*with_forces=*/false);
    map_rigid_particles<Kernel>(t);
    velocity_from_momentum();
    update_stress<Kernel>(nodes_.velocity, dt);
    add_internal_forces<Kernel>();
  } else {
    map_to_grid<Kernel>(dt, /*with_forces=*/true);
    map_rigid_particles<Kernel>(t);
  }
  map_external_loads<Kernel>(t);
  update_grid(dt);
  const long bad = update_particles<Kernel>(dt);
  move_rigid_particles(dt, t);
  time_ += dt;
  ++step_;
  check_particle(bad, dt);
  if (opt_.scheme == UpdateScheme::musl) {
    remap_momentum<Kernel>();
    update_stress<Kernel>(nodes_.velocity, dt);
  } else if (opt_.scheme == UpdateScheme::usl) {
    update_stress<Kernel>(nodes_.velocity, dt);
  }
}

// Particle-to-grid of mass, momentum and (USL/MUSL) internal force and body force:
// m_i = Σ S_ip m_p, p_i = Σ S_ip m_p v_p, f_i = Σ (−V_p σ_p G_ip + S_ip m_p g).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_to_grid(double /*dt*/, bool with_forces) {
  auto& st = stencils<Kernel>();
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  nodes_.clear_accumulators();
#pragma omp parallel num_threads(threads_)
  {
    const int tid = omp_get_thread_num();
    NodalFields<Dim>& acc = tid == 0 ? nodes_ : thread_nodes_[static_cast<std::size_t>(tid - 1)];
    if (tid != 0) acc.clear_accumulators();
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      if (materials_[m].is_rigid()) continue;
#pragma omp for schedule(static) nowait
      for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
        Stencil<Dim, Kernel>& s = st[k];
        s.evaluate(grid_, p_.position[k], p_.half_size[k]);
        const double mp = p_.mass[k];
        const Vec<Dim> mv = mp * p_.velocity[k];
        const Mat<Dim> Vsig = p_.volume[k] * p_.stress[k];
        const Vec<Dim> mg = mp * g;
        if (with_forces) {
          s.for_each(grid_, [&](int i, double S, const Vec<Dim>& G) {
            acc.mass[i] += S * mp;
            acc.momentum[i] += S * mv;
            acc.force[i] += S * mg - Vsig * G;
          });
        } else {
          s.for_each(grid_, [&](int i, double S, const Vec<Dim>&) {
            acc.mass[i] += S * mp;
            acc.momentum[i] += S * mv;
          });
        }
      }
    }
#pragma omp barrier
    if (!thread_nodes_.empty()) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nodes_.mass.size(); ++i)
        for (const auto& b : thread_nodes_) {
          nodes_.mass[i] += b.mass[i];
          nodes_.momentum[i] += b.momentum[i];
          nodes_.force[i] += b.force[i];
        }
    }
  }
}

// USF: internal and body forces from the freshly updated stress.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::add_internal_forces() {
  auto& st = stencils<Kernel>();
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
#pragma omp parallel num_threads(threads_)
  {
    const int tid = omp_get_thread_num();
    NodalFields<Dim>& acc = tid == 0 ? nodes_ : thread_nodes_[static_cast<std::size_t>(tid - 1)];
    if (tid != 0) std::fill(acc.force.begin(), acc.force.end(), Vec<Dim>::Zero());
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      if (materials_[m].is_rigid()) continue;
#pragma omp for schedule(static) nowait
      for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
        const Mat<Dim> Vsig = p_.volume[k] * p_.stress[k];
        const Vec<Dim> mg = p_.mass[k] * g;
        st[k].for_each(grid_, [&](int i, double S, const Vec<Dim>& G) { acc.force[i] += S * mg - Vsig * G; });
      }
    }
#pragma omp barrier
    if (!thread_nodes_.empty()) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nodes_.mass.size(); ++i)
        for (const auto& b : thread_nodes_) nodes_.force[i] += b.force[i];
    }
  }
}

// Nodes touched by a rigid material take its prescribed velocity (single velocity field).
template <int Dim>
template <class Kernel>
void Simulation<Dim>::map_rigid_particles(double t) {
  std::fill(rigid_mask_.begin(), rigid_mask_.end(), std::uint8_t{0});
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (!materials_[m].is_rigid()) continue;
    const Vec<Dim> v = materials_[m].rigid_velocity_at(t).template head<Dim>();
    for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
      Stencil<Dim, Kernel> s;
      s.evaluate(grid_, p_.position[k], p_.half_size[k]);
      s.for_each(grid_, [&](int i, double S, const Vec<Dim>&) {
        if (S > 0.0) {
          rigid_mask_[static_cast<std::size_t>(i)] = 1;
          rigid_velocity_[static_cast<std::size_t>(i)] = v;
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
    st[L.particle].for_each(grid_, [&](int i, double S, const Vec<Dim>&) { nodes_.force[i] += S * f; });
  }
}

// Fixed components are zeroed; rigid nodes take m_i v_rigid and no force.
template <int Dim>
void Simulation<Dim>::apply_velocity_bc(std::vector<Vec<Dim>>& momentum, std::vector<Vec<Dim>>* force) const {
  const std::size_t n = momentum.size();
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    if (rigid_mask_[i]) {
      momentum[i] = nodes_.mass[i] * rigid_velocity_[i];
      if (force) (*force)[i].setZero();
    }
    if (const std::uint8_t mask = fixed_mask_[i]) {
      for (int d = 0; d < Dim; ++d)
        if (mask & (1u << d)) {
          momentum[i][d] = 0.0;
          if (force) (*force)[i][d] = 0.0;
        }
    }
  }
}

// v_i = p_i / m_i after the velocity boundary conditions on p_i; empty nodes get no velocity.
template <int Dim>
void Simulation<Dim>::velocity_from_momentum() {
  apply_velocity_bc(nodes_.momentum, nullptr);
  const double mmin = empty_node_mass_;
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (std::size_t i = 0; i < nodes_.mass.size(); ++i)
    nodes_.velocity[i] = nodes_.mass[i] > mmin ? Vec<Dim>(nodes_.momentum[i] / nodes_.mass[i]) : Vec<Dim>::Zero();
}

// p_i^{n+1} = p_i^n + f_i dt; a_i = (p^{n+1} − p^n)/(m_i dt) after boundary conditions on both.
template <int Dim>
void Simulation<Dim>::update_grid(double dt) {
  apply_velocity_bc(nodes_.momentum, &nodes_.force);
  const double mmin = empty_node_mass_;
  const std::size_t n = nodes_.mass.size();
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    const double m = nodes_.mass[i];
    if (m > mmin) {
      nodes_.velocity[i] = (nodes_.momentum[i] + nodes_.force[i] * dt) / m;
      nodes_.acceleration[i] = nodes_.force[i] / m;
    } else {
      nodes_.velocity[i].setZero();
      nodes_.acceleration[i].setZero();
    }
  }
  // Boundary conditions hold for the new velocity too (rigid: v_rigid, fixed: 0). Since the force was
  // constrained consistently, only rigid nodes whose prescribed velocity changed need fixing.
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    if (rigid_mask_[i] && nodes_.mass[i] > mmin) nodes_.velocity[i] = rigid_velocity_[i];
  }
}

// Grid-to-particle (FLIP): v_p += dt Σ S_ip a_i, x_p += dt Σ S_ip v_i^{n+1}. Returns the first
// particle with a non-finite state or outside the grid, or -1.
template <int Dim>
template <class Kernel>
long Simulation<Dim>::update_particles(double dt) {
  auto& st = stencils<Kernel>();
  long bad = std::numeric_limits<long>::max();  // min-reduction identity
  double work = 0.0;
  const Vec<Dim> g = opt_.gravity.template head<Dim>();
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (materials_[m].is_rigid()) continue;
    const long b = static_cast<long>(material_begin_[m]), e = static_cast<long>(material_end_[m]);
#pragma omp parallel for num_threads(threads_) schedule(static) reduction(min : bad) reduction(+ : work)
    for (long kk = b; kk < e; ++kk) {
      const std::size_t k = static_cast<std::size_t>(kk);
      Vec<Dim> a = Vec<Dim>::Zero(), v = Vec<Dim>::Zero();
      st[k].for_each(grid_, [&](int i, double S, const Vec<Dim>&) {
        a += S * nodes_.acceleration[i];
        v += S * nodes_.velocity[i];
      });
      const Vec<Dim> v_mid = p_.velocity[k] + 0.5 * dt * a;
      work += p_.mass[k] * g.dot(v_mid) * dt;
      p_.velocity[k] += dt * a;
      p_.position[k] += dt * v;
      const bool ok = p_.velocity[k].allFinite() && grid_.contains(p_.position[k]);
      if (!ok) bad = std::min(bad, kk);
    }
  }
  for (const auto& L : resolved_loads_) work += (L.force * (*L.scale)(time_)).dot(p_.velocity[L.particle]) * dt;
  external_work_ += work;
  return bad == std::numeric_limits<long>::max() ? -1 : bad;
}

template <int Dim>
void Simulation<Dim>::move_rigid_particles(double dt, double t) {
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (!materials_[m].is_rigid()) continue;
    const Vec<Dim> v = materials_[m].rigid_velocity_at(t).template head<Dim>();
    const Vec<Dim> dx = ((materials_[m].rigid_velocity_at(t + dt) + materials_[m].rigid_velocity_at(t)) * 0.5 * dt)
                            .template head<Dim>();
    for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
      p_.velocity[k] = v;
      p_.position[k] += dx;
    }
  }
}

template <int Dim>
void Simulation<Dim>::check_particle(long bad, double /*dt*/) const {
  long k = bad;
  for (std::size_t j = 0; k < 0 && j < p_.size(); ++j)  // rigid particles are checked here
    if (materials_[static_cast<std::size_t>(p_.material[j])].is_rigid() && !grid_.contains(p_.position[j]))
      k = static_cast<long>(j);
  if (k < 0) return;
  const std::size_t u = static_cast<std::size_t>(k);
  std::ostringstream msg;
  msg.precision(6);
  const bool finite = p_.velocity[u].allFinite() && p_.position[u].allFinite();
  msg << "step " << step_ << ", t = " << time_ << " s: particle " << k << " of body '"
      << bodies_[static_cast<std::size_t>(p_.body[u])].name << "' ";
  if (!finite) {
    msg << "has a non-finite velocity or position (the step blew up; try a smaller CFL factor)";
  } else {
    msg << "left the grid at (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << p_.position[u][d];
    msg << ") m; grid spans (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << grid_.lo()[d];
    msg << ") to (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << grid_.hi()[d];
    msg << ") m";
  }
  throw SimulationError(msg.str(), step_, time_, k);
}

// MUSL: nodal momentum rebuilt from the updated particle velocities, p_i = Σ S_ip m_p v_p.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::remap_momentum() {
  auto& st = stencils<Kernel>();
#pragma omp parallel num_threads(threads_)
  {
    const int tid = omp_get_thread_num();
    NodalFields<Dim>& acc = tid == 0 ? nodes_ : thread_nodes_[static_cast<std::size_t>(tid - 1)];
    std::fill(acc.momentum.begin(), acc.momentum.end(), Vec<Dim>::Zero());
#pragma omp barrier
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      if (materials_[m].is_rigid()) continue;
#pragma omp for schedule(static) nowait
      for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
        const Vec<Dim> mv = p_.mass[k] * p_.velocity[k];
        st[k].for_each(grid_, [&](int i, double S, const Vec<Dim>&) { acc.momentum[i] += S * mv; });
      }
    }
#pragma omp barrier
    if (!thread_nodes_.empty()) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nodes_.mass.size(); ++i)
        for (const auto& b : thread_nodes_) nodes_.momentum[i] += b.momentum[i];
    }
  }
  velocity_from_momentum();
}

// Velocity gradient L_p = Σ_i v_i ⊗ G_ip, F ← (I + L dt) F, V = det(F) V0, then the material's stress.
template <int Dim>
template <class Kernel>
void Simulation<Dim>::update_stress(const std::vector<Vec<Dim>>& v, double dt) {
  auto& st = stencils<Kernel>();
  const Analysis an = opt_.analysis;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const Material& mat = materials_[m];
    if (mat.is_rigid()) continue;
    const double lam = mat.lame_lambda(), mu = mat.shear_modulus();
    const bool nh = mat.kind == MaterialKind::neo_hookean;
#pragma omp parallel for num_threads(threads_) schedule(static)
    for (std::size_t k = material_begin_[m]; k < material_end_[m]; ++k) {
      Mat<Dim> L = Mat<Dim>::Zero();
      st[k].for_each(grid_, [&](int i, double, const Vec<Dim>& G) { L.noalias() += v[static_cast<std::size_t>(i)] * G.transpose(); });
      Mat<Dim>& F = p_.deformation_gradient[k];
      F = (Mat<Dim>::Identity() + dt * L) * F;
      p_.volume[k] = F.determinant() * p_.initial_volume[k];
      if (nh)
        neo_hookean_stress<Dim>(F, lam, mu, p_.stress[k], p_.stress_zz[k]);
      else
        linear_elastic_update<Dim>(L, dt, lam, mu, an, p_.stress[k], p_.stress_zz[k]);
    }
  }
}

#define FRICTHERM_INSTANTIATE_STEP(D)                                                                \
  template double Simulation<D>::step(double);                                                       \
  template void Simulation<D>::apply_velocity_bc(std::vector<Vec<D>>&, std::vector<Vec<D>>*) const;  \
  template void Simulation<D>::update_grid(double);                                                  \
  template void Simulation<D>::velocity_from_momentum();                                                  \
  template void Simulation<D>::move_rigid_particles(double, double);                                 \
  template void Simulation<D>::check_particle(long, double) const;
FRICTHERM_INSTANTIATE_STEP(2)
FRICTHERM_INSTANTIATE_STEP(3)
#undef FRICTHERM_INSTANTIATE_STEP

}  // namespace frictherm::mechanics
