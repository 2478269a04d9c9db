// The coupling window: accumulate work, assemble (eq. 38), deliver, integrate, map back, track.
#include <frictherm/coupling/coupler.hpp>
#include <frictherm/thermal/stability.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

namespace {

// Partition of unity and zero row sums hold to round-off; anything larger is a bug, not physics.
constexpr double kAssemblyTolerance = 1e-10;

// max |v_p| over the particles whose material conducts (WindowPolicy::max_travel).
template <int Dim>
double conducting_speed_max(const std::vector<mechanics::Vec<Dim>>& velocity, const std::vector<std::int32_t>& material,
                            const std::vector<ThermalProperties>& materials) {
  double v2 = 0.0;
  for (std::size_t k = 0; k < velocity.size(); ++k) {
    const auto m = static_cast<std::size_t>(material[k]);
    if (m < materials.size() && materials[m].conducts) v2 = std::max(v2, velocity[k].squaredNorm());
  }
  return std::sqrt(v2);
}

}  // namespace

void check_window_options(const WindowPolicy& w, long matrix_free_max_substeps, const std::string& who) {
  if (w.kind == WindowPolicy::Kind::every_n_steps && w.steps < 1)
    throw std::invalid_argument(who + ": every_n_steps needs steps >= 1");
  if (w.kind == WindowPolicy::Kind::adaptive && !(w.max_temperature_rise > 0.0))
    throw std::invalid_argument(who + ": adaptive windows need max_temperature_rise > 0");
  if (!(w.max_duration > 0.0)) throw std::invalid_argument(who + ": max_duration must be > 0");
  if (!(w.max_travel >= 0.0 && std::isfinite(w.max_travel)))
    throw std::invalid_argument(who + ": max_travel must be finite and >= 0");
  if (matrix_free_max_substeps < 0) throw std::invalid_argument(who + ": matrix_free_max_substeps must be >= 0");
}

template <int Dim>
Coupler<Dim>::Coupler(const mechanics::Grid<Dim>& grid, mechanics::ShapeKind shape, CouplerOptions options)
    : grid_(grid),
      shape_(shape),
      opt_(std::move(options)),
      integrator_(thermal::make_integrator(opt_.assembled_integrator(), opt_.integrator_options)),
      pending_(grid.node_count()),
      plastic_(opt_.plastic),
      tracker_(Dim, opt_.hotspots, opt_.thickness),
      fates_(opt_.fates) {
  check_window_options(opt_.window, opt_.matrix_free_max_substeps, "Coupler");
  explicit_.use_node_operator(opt_.matrix_free_node_operator && Dim == 2);
  if (!(opt_.subgrid_relaxation_time > 0.0))
    throw std::invalid_argument("Coupler: subgrid_relaxation_time must be > 0");
  for (const FixedTemperatureFace& f : opt_.fixed_faces)
    if (f.axis < 0 || f.axis >= Dim) throw std::invalid_argument("Coupler: fixed face axis out of range");
  if (opt_.reaction.enabled) {
    const thermal::ArrheniusKinetics& k = opt_.reaction.kinetics;
    if (!(k.prefactor > 0.0 && k.activation_temperature > 0.0 && k.specific_heat_of_reaction >= 0.0) ||
        !std::isfinite(k.prefactor) || !std::isfinite(k.activation_temperature) ||
        !std::isfinite(k.specific_heat_of_reaction))
      throw std::invalid_argument("Coupler: reaction kinetics need finite Z > 0, Θ > 0 and q >= 0");
  }
}

template <int Dim>
void Coupler<Dim>::start(const mechanics::Particles<Dim>& p, double time) {
  window_start_ = time;
  window_steps_ = 0;
  max_rise_ = 0.0;
  max_speed_ = 0.0;
  pending_.clear();
  pending_plastic_ = 0.0;
  books_ = EnergyBooks{};
  initial_energy_ = particle_thermal_energy(p, opt_.materials);
  if (opt_.plastic.enabled) plastic_.start(p);
  if (opt_.reaction.enabled) particle_progress_.assign(p.size(), 0.0);  // fresh material
  fates_ = HotSpotFates(opt_.fates);
  if (matrix_free_allowed()) {
    // M and T of the start (eq. 38) without K (issue 35: assembling K cost the 3D start as much as
    // ~8 windows); the first window gathers anew, as after an assembly.
    explicit_.gather(grid_, p, shape_, opt_.materials, opt_.assembly, system_, step_stencils(), true);
    system_assembled_ = false;
    system_gathered_ = false;
    system_changed();
  } else {
    assemble(p);
  }
  nodal_temperature_ = system_.temperature;
  tracker_.set_reference(p);
  interface_.start(grid_, opt_.thickness, p, opt_.materials, opt_.interface_temperature, time);
  interface_reaction_ = InterfaceReaction{};
  if (interface_.enabled() && reaction_active()) interface_reaction_.start(p.size(), time);
  tracker_.update(p, opt_.materials, time);
}

template <int Dim>
void Coupler<Dim>::update_interface_and_hotspots(mechanics::Particles<Dim>& p, double time) {
  if (interface_.enabled()) interface_.update(p, shape_, step_stencils(), system_, nodal_temperature_, time);
  if (interface_reaction_.started() && reaction_active())
    interface_reaction_.advance(p.material, opt_.reaction, interface_.particle_temperature(), time);
  tracker_.update(p, opt_.materials, time, hotspot_temperature(p));
}

template <int Dim>
const std::vector<double>* Coupler<Dim>::hotspot_temperature(const mechanics::Particles<Dim>& p) const {
  const bool by_interface = opt_.hotspots_by_interface_temperature && interface_.enabled() &&
                            interface_.particle_temperature().size() == p.size();
  return by_interface ? &interface_.particle_temperature() : nullptr;
}

template <int Dim>
void Coupler<Dim>::assemble(const mechanics::Particles<Dim>& p) {
  NodalThermalSystem assembled = assemble_thermal(grid_, p, shape_, opt_.materials, opt_.assembly, step_stencils());
  system_.swap(assembled);
  system_assembled_ = true;
  system_gathered_ = false;
  system_changed();
  if (problem_) problem_->reset(system_.mass, system_.conductance);  // the last window's storage
  else problem_.emplace(system_.mass, system_.conductance);
  fixed_nodes_.clear();
  for_each_fixed_node(opt_.fixed_faces, grid_.cells(), system_.size(), fixed_lattice_along(),
                      [&](std::size_t u, double t) {
                        problem_->set_dirichlet(static_cast<Eigen::Index>(u), t);
                        fixed_nodes_.push_back({static_cast<int>(u), t});
                      });
  if (reaction_active()) {
    // Reacting mass and progress gathered from the particles; Q_i = q m_i (heat_sources.hpp).
    NodalReaction r = gather_reaction(grid_, p, shape_, opt_.reaction, system_, particle_progress_);
    problem_->set_reaction(thermal::make_reaction(opt_.reaction.kinetics, r.reacting_mass));
    nodal_progress_ = r.progress;
    nodal_progress_ref_ = std::move(r.progress);
    particle_progress_ref_ = particle_progress_;
  }
}

template <int Dim>
void Coupler<Dim>::system_changed() {
  has_system_ = true;
  // K·1 = 0 only where K was assembled (a matrix-free gather leaves it empty).
  const double residual = std::max(system_.mass_residual(), system_assembled_ ? system_.row_sum_residual() : 0.0);
  books_.max_assembly_residual = std::max(books_.max_assembly_residual, residual);
  if (!(residual <= kAssemblyTolerance))
    throw std::logic_error("thermal assembly: partition-of-unity / zero-row-sum residual " +
                           std::to_string(residual) + " exceeds round-off");
  min_unknown_mass_ = system_.mass.minCoeff();
  nearest_mass_.clear();
}

template <int Dim>
bool Coupler<Dim>::matrix_free_allowed() const {
  const thermal::IntegratorOptions& o = opt_.integrator_options;
  return (opt_.integrator == "forward_euler" || opt_.integrator == "auto") && opt_.matrix_free_max_substeps > 0 &&
         !reaction_active() && o.fe_stability_policy == "substep" && o.fe_limit_estimate == "gershgorin";
}

template <int Dim>
bool Coupler<Dim>::matrix_free_window(mechanics::Particles<Dim>& p, double dt) {
  const thermal::IntegratorOptions& o = opt_.integrator_options;
  // Far beyond the limit with the last bound (it changes slowly as the particles move): skip the gather.
  // Not on the quick bound (cruder): the gather below decides with the exact one.
  if (last_lambda_bound_ > 0.0 && !lambda_bound_is_quick_ &&
      dt / (o.fe_safety * 2.0 / last_lambda_bound_) > 2.0 * static_cast<double>(opt_.matrix_free_max_substeps))
    return false;
  using Refresh = typename ExplicitConduction<Dim>::Refresh;
  const double shift = opt_.reuse_distance * grid_.cell_size().minCoeff();
  const Refresh reuse = system_gathered_ && opt_.reuse_distance > 0.0
                            ? explicit_.refresh(grid_, p, shape_, opt_.materials, opt_.assembly, system_, shift,
                                                step_stencils())
                            : Refresh::regather;
  if (reuse == Refresh::refreshed) {  // the particles that moved were gathered again: M and the bound changed
    ++books_.matrix_free_refreshes;
    system_changed();
    lambda_bound_is_quick_ = !explicit_.has_exact_bounds();
    last_lambda_bound_ = lambda_bound_is_quick_ ? explicit_.quick_bound(system_, fixed_nodes_)
                                                : explicit_.lambda_bound(system_, fixed_nodes_);
  }
  if (reuse != Refresh::regather) {
    explicit_.reproject(p, system_);  // kept S, M and G'; T_i from the particles now
  } else {
    // Without reuse the window reads the step's stencils in place (no copy: no refresh follows).
    explicit_.gather(grid_, p, shape_, opt_.materials, opt_.assembly, system_, step_stencils(),
                     opt_.reuse_distance > 0.0);
    ++books_.matrix_free_gathers;
    system_assembled_ = false;
    system_gathered_ = true;
    system_changed();
    fixed_nodes_.clear();
    for_each_fixed_node(opt_.fixed_faces, grid_.cells(), system_.size(), fixed_lattice_along(),
                        [&](std::size_t u, double t) { fixed_nodes_.push_back({static_cast<int>(u), t}); });
    // The quick bound first (no pass of its own); the exact bounds only if it does not show that one
    // sub-step is stable (issue 35: they cost a square root and a division per node and particle).
    last_lambda_bound_ = explicit_.quick_bound(system_, fixed_nodes_);
    lambda_bound_is_quick_ = true;
  }
  // Sub-steps: the stable step from the bound of M⁻¹K (forward_euler's "substep" policy), and
  // fe_max_dt if set. n is the count the exact bound gives: the quick bound is ≥ it (with a margin of
  // 1e-6 for its round-off), so a window it finds stable in one sub-step is stable in one by the
  // exact bound too; otherwise the exact bound decides. (On the PBX scene the quick bound exceeds the
  // one-step limit in 13 of 100 windows: nodes at the edge of the material with little M, where it is
  // ~3× the exact one.)
  const auto substeps = [&](double lam) { return thermal::forward_euler_substeps(dt, lam, o.fe_safety, o.fe_max_dt); };
  long n = substeps(last_lambda_bound_);
  if (lambda_bound_is_quick_ && n > 1) {  // the window's stencils are still those of the gather
    last_lambda_bound_ = explicit_.lambda_bound(system_, fixed_nodes_);
    lambda_bound_is_quick_ = false;
    n = substeps(last_lambda_bound_);
  }
  const double lam = last_lambda_bound_;
  if (n > opt_.matrix_free_max_substeps) return false;  // the assembled path takes this window
  const HeatDistribution heat = distribute_heat(grid_, system_, pending_.work());
  books_.heat_delivered += (heat.joules / dt).sum() * dt;  // as the assembled path books ∫ Σ q dt
  books_.plastic_heat_delivered += pending_plastic_;
  books_.heat_relocated += heat.relocated;
  nodal_temperature_ = explicit_.advance(system_, system_.temperature, heat.joules, fixed_nodes_, dt, n);
  if (!nodal_temperature_.allFinite())
    throw thermal::StabilityError("matrix-free forward Euler: temperatures became non-finite", dt / n,
                                  lam > 0.0 ? 2.0 / lam : 0.0);
  const Eigen::VectorXd delta = nodal_temperature_ - system_.temperature;
  const double beta = std::isfinite(opt_.subgrid_relaxation_time)
                          ? -std::expm1(-dt / opt_.subgrid_relaxation_time)
                          : 0.0;
  const auto* held = face_pull_nodes(nodal_temperature_);
  const double face_heat =
      explicit_.map_back(p, system_, delta, beta, beta > 0.0 ? &nodal_temperature_ : nullptr, held);
  books_.nodal_energy_change += nodal_change(delta, held, face_heat);
  ++books_.matrix_free_windows;
  books_.matrix_free_substeps += n;
  return true;
}

template <int Dim>
const std::vector<typename FacePull<Dim>::Held>* Coupler<Dim>::face_pull_nodes(const Eigen::VectorXd& T) {
  if (opt_.fixed_faces.empty()) return nullptr;
  // The unknown one cell inward from node u along the face's axis, and its offset.
  const auto inward = [&](std::size_t u, int axis, bool upper, double& t_in, double& dx) {
    mechanics::IVec<Dim> li = grid_.node_lattice(system_.grid_node[u]);
    li[axis] += upper ? -1 : 1;
    if (li[axis] < 0 || li[axis] > grid_.cells()[axis]) return false;
    const int v = system_.unknown[static_cast<std::size_t>(grid_.node_index(li))];
    if (v < 0) return false;
    t_in = T[v];
    dx = upper ? -grid_.cell_size()[axis] : grid_.cell_size()[axis];
    return true;
  };
  const auto position = [&](std::size_t u, int a) { return grid_.node_position(system_.grid_node[u])[a]; };
  collect_face_pull_nodes<Dim>(opt_.fixed_faces, grid_.cells(), system_.size(), fixed_lattice_along(), inward, position,
                       face_pull_);
  return &face_pull_;
}

template <int Dim>
double Coupler<Dim>::nodal_change(const Eigen::VectorXd& delta, const std::vector<typename FacePull<Dim>::Held>* held,
                                  double face_heat) const {
  double change = system_.mass.dot(delta);
  if (!held) return change;
  for (const typename FacePull<Dim>::Held& h : *held) change -= system_.mass[h.unknown] * delta[h.unknown];
  return change + face_heat;
}

template <int Dim>
double Coupler<Dim>::mass_estimate(std::size_t node) const {
  const int u = system_.unknown[node];
  if (u >= 0) return system_.mass[u];
  // Not an unknown: its heat will go to the unknowns around it (distribute_heat), so their M counts.
  const mechanics::IVec<Dim> li = grid_.node_lattice(static_cast<int>(node));
  const auto& npd = grid_.nodes_per_dim();
  double m = 0.0;
  for (int c = 0; c < (Dim == 2 ? 9 : 27); ++c) {
    int rem = c, j = 0;
    bool inside = true;
    for (int d = 0; d < Dim; ++d) {
      const int l = li[static_cast<std::size_t>(d)] + rem % 3 - 1 + mechanics::Grid<Dim>::ghost;
      rem /= 3;
      inside = inside && l >= 0 && l < npd[static_cast<std::size_t>(d)];
      j += l * grid_.strides()[d];
    }
    if (!inside) continue;
    const int v = system_.unknown[static_cast<std::size_t>(j)];
    if (v >= 0) m += system_.mass[v];
  }
  if (m > 0.0) return m;
  // No unknown next to it: the nearest unknown takes the heat (distribute_heat). Rare; cached.
  const auto hit = nearest_mass_.find(node);
  if (hit != nearest_mass_.end()) return hit->second;
  const mechanics::Vec<Dim> x = grid_.node_position(static_cast<int>(node));
  double best = std::numeric_limits<double>::infinity();
  m = min_unknown_mass_;
  for (std::size_t v = 0; v < system_.size(); ++v) {
    const double d2 = (grid_.node_position(system_.grid_node[v]) - x).squaredNorm();
    if (d2 < best) {
      best = d2;
      m = system_.mass[static_cast<Eigen::Index>(v)];
    }
  }
  nearest_mass_.emplace(node, m);
  return m;
}

template <int Dim>
bool Coupler<Dim>::after_step(mechanics::Particles<Dim>& p, const std::vector<double>& nodal_work, double time) {
  ++books_.steps;
  ++window_steps_;
  const double before = pending_.total();
  pending_.add(nodal_work);
  books_.work_received += pending_.total() - before;
  interface_.add_step(nodal_work, time);  // the frictional heat's flux history (off unless asked)
  if (opt_.plastic.enabled) {
    double dw = 0.0;
    const double heat = plastic_.collect(grid_, p, shape_, pending_, dw);  // β Δw_p S_ip on the nodes
    pending_plastic_ += heat;
    books_.plastic_heat_received += heat;
    books_.plastic_work_received += dw;
  }
  const WindowPolicy& w = opt_.window;
  bool close = false;
  switch (w.kind) {
    case WindowPolicy::Kind::every_step: close = true; break;
    case WindowPolicy::Kind::every_n_steps: close = window_steps_ >= w.steps; break;
    case WindowPolicy::Kind::adaptive: {
      const std::vector<double>& acc = pending_.work();
      for (std::size_t i = 0; i < nodal_work.size(); ++i)
        if (nodal_work[i] != 0.0) max_rise_ = std::max(max_rise_, std::fabs(acc[i]) / mass_estimate(i));
      if (pending_plastic_ != 0.0)  // plastic heat can sit on any node: scan them all
        for (std::size_t i = 0; i < acc.size(); ++i)
          if (acc[i] != 0.0) max_rise_ = std::max(max_rise_, std::fabs(acc[i]) / mass_estimate(i));
      if (w.max_travel > 0.0) max_speed_ = std::max(max_speed_, conducting_speed_max(p.velocity, p.material, opt_.materials));
      close = max_rise_ >= w.max_temperature_rise || time - window_start_ >= w.max_duration * (1.0 - 1e-12) ||
              (w.max_steps > 0 && window_steps_ >= w.max_steps) ||
              (w.max_travel > 0.0 && max_speed_ * (time - window_start_) >= w.max_travel * grid_.min_cell_size());
      break;
    }
  }
  return close ? close_window(p, time) : false;
}

template <int Dim>
bool Coupler<Dim>::close_window(mechanics::Particles<Dim>& p, double time) {
  const double dt = time - window_start_;
  if (!(dt > 0.0)) return false;  // nothing to integrate; pending heat stays for the next window
  if (!matrix_free_allowed() || !matrix_free_window(p, dt)) {
    assemble(p);
    const HeatDistribution heat = distribute_heat(grid_, system_, pending_.work());
    const Eigen::VectorXd q = heat.joules / dt;  // constant over the window: ∫ q dt = W (design §4)
    problem_->set_source(q);
    books_.heat_delivered += q.sum() * dt;
    books_.plastic_heat_delivered += pending_plastic_;
    books_.heat_relocated += heat.relocated;
    nodal_temperature_ = system_.temperature;
    advance_and_map(p, window_start_, time, true);
  }
  pending_.clear();
  pending_plastic_ = 0.0;
  ++books_.windows;
  books_.min_window = std::min(books_.min_window, dt);
  books_.max_window = std::max(books_.max_window, dt);
  window_start_ = time;
  window_steps_ = 0;
  max_rise_ = 0.0;
  max_speed_ = 0.0;
  update_interface_and_hotspots(p, time);
  return true;
}

template <int Dim>
void Coupler<Dim>::continue_thermal(mechanics::Particles<Dim>& p, double time) {
  if (pending_.total() != 0.0)
    throw std::logic_error("Coupler::continue_thermal: close the window with pending heat first");
  if (!(time > window_start_)) return;
  const bool reaction_starts = opt_.reaction.enabled && !continuing_;
  if (!continuing_) {  // a fresh integrator: the continuation depends only on the end-of-loading state
    stats_offset_ += integrator_->stats();
    integrator_ = thermal::make_integrator(opt_.assembled_integrator(), opt_.integrator_options);
  }
  continuing_ = true;
  bool gathered = false;  // this interval starts from the particles' temperatures
  if (!system_assembled_ || reaction_starts) {  // a reaction held back during loading joins the problem now
    assemble(p);
    nodal_temperature_ = system_.temperature;
    gathered = true;
  }
  problem_->clear_source();
  if (!fates_.started()) fates_.begin(tracker_, window_start_);  // the hot spots at the end of loading
  if (interface_.enabled() && opt_.reaction.enabled && !interface_reaction_.started())
    interface_reaction_.start(p.size(), window_start_);  // a reaction held back until the continuation
  advance_and_map(p, window_start_, time, gathered);
  ++books_.continuation_intervals;
  window_start_ = time;
  window_steps_ = 0;
  update_interface_and_hotspots(p, time);
  // The verdict reads the hot-spot temperature: the interface's, with its Arrhenius progress, when the
  // scene judges hot spots by it (interface_reaction.hpp).
  const std::vector<double>* criterion = hotspot_temperature(p);
  const bool interface_progress = criterion && interface_reaction_.started();
  fates_.update(p, particle_progress_, tracker_, time, criterion,
                interface_progress ? &interface_reaction_.progress() : nullptr);
}

template <int Dim>
void Coupler<Dim>::advance_and_map(mechanics::Particles<Dim>& p, double t0, double t1, bool from_gathered) {
  const Eigen::VectorXd start = nodal_temperature_;
  if (reaction_active()) {
    const double released0 = problem_->released_heat(nodal_progress_);
    integrator_->advance(*problem_, nodal_temperature_, nodal_progress_, t0, t1);  // T and λ
    books_.reaction_heat_released += problem_->released_heat(nodal_progress_) - released0;
    scatter_progress(grid_, p, shape_, opt_.reaction, system_, nodal_progress_ref_, nodal_progress_,
                     particle_progress_ref_, particle_progress_);
  } else {
    integrator_->advance(*problem_, nodal_temperature_, t0, t1);  // writes Dirichlet values first
  }
  const Eigen::VectorXd delta = nodal_temperature_ - start;
  const double beta = std::isfinite(opt_.subgrid_relaxation_time)
                          ? -std::expm1(-(t1 - t0) / opt_.subgrid_relaxation_time)
                          : 0.0;
  const auto* held = from_gathered ? face_pull_nodes(nodal_temperature_) : nullptr;
  const double face_heat = add_nodal_change_to_particles(grid_, p, shape_, opt_.materials, system_, delta, beta,
                                                         &nodal_temperature_, step_stencils(), held);  // design §4
  books_.nodal_energy_change += nodal_change(delta, held, face_heat);
}

template <int Dim>
thermal::IntegratorStats Coupler<Dim>::integrator_stats() const {
  thermal::IntegratorStats s = stats_offset_;
  s += integrator_->stats();
  return s;
}

template <int Dim>
double Coupler<Dim>::particle_reaction_heat(const mechanics::Particles<Dim>& p) const {
  double m = 0.0;
  for (std::size_t k = 0; k < particle_progress_.size() && k < p.size(); ++k)
    if (opt_.reaction.reacts(p.material[k])) m += p.mass[k] * particle_progress_[k];
  return opt_.reaction.kinetics.specific_heat_of_reaction * m;
}

template <int Dim>
double Coupler<Dim>::particle_energy_change(const mechanics::Particles<Dim>& p) const {
  return particle_thermal_energy(p, opt_.materials) - initial_energy_;
}

template class Coupler<2>;
template class Coupler<3>;

}  // namespace frictherm::coupling
