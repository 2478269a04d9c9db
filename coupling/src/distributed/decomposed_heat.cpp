// Frictional heating and conduction on the decomposed mechanics (frictherm/coupling/decomposed_heat.hpp):
// the serial Coupler's windows (coupler.cpp) with the matrix-free ExplicitConduction window
// (explicit_conduction.cpp, Nairn et al. 2018 eqs. 37–38) or the assembled one (decomposed_assembled.cpp),
// their particle loops over this rank's particles and their nodal sums completed at the owners by the
// mechanics' transfers (DMLocalToGlobal ADD, DMGlobalToLocal). One template on Dim for the 2D and 3D
// mechanics; G'_ip flat, Dim values per kept entry.
#include <frictherm/coupling/decomposed_heat.hpp>
#include <frictherm/thermal/stability.hpp>
#include <frictherm/coupling/fixed_temperature.hpp>

#include "distributed/decomposed_assembled.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {
namespace {

// The serial sub-steps' quiet rule (explicit_conduction.cpp): a particle whose nodal temperatures agree
// to 256 ε relative carries no flux.
constexpr double kQuietSpread = 256.0 * 2.220446049250313e-16;

double sum_over(MPI_Comm comm, double x) {
  MPI_Allreduce(MPI_IN_PLACE, &x, 1, MPI_DOUBLE, MPI_SUM, comm);
  return x;
}

// The lattice neighbours (one node away along every axis, x fastest as the serial loops) of owned node u
// inside the ghosted box `box` that satisfy `take` (given their local node): their local nodes in cand.
// The ghosted box ends only at the grid's end, so it holds every neighbour of an owned node.
template <int Dim, class Take>
int lattice_neighbours(const std::array<int, 2 * Dim>& own, const std::array<int, 2 * Dim>& box, std::size_t u,
                       Take&& take, int* cand) {
  constexpr int neighbours = Dim == 2 ? 9 : 27;
  int idx[Dim];  // DMDA index of owned node u (x fastest over owned_nodes())
  for (int d = 0; d < Dim; ++d) {
    const auto extent = static_cast<std::size_t>(own[2 * d + 1] - own[2 * d]);
    idx[d] = own[2 * d] + static_cast<int>(u % extent);
    u /= extent;
  }
  int count = 0;
  for (int c = 0; c < neighbours; ++c) {
    int r = c, l = 0, stride = 1;
    bool inside = true;
    for (int d = 0; d < Dim; ++d) {
      const int j = idx[d] + r % 3 - 1;
      r /= 3;
      if (j < box[2 * d] || j >= box[2 * d + 1]) inside = false;
      l += (j - box[2 * d]) * stride;
      stride *= box[2 * d + 1] - box[2 * d];
    }
    if (inside && take(l)) cand[count++] = l;
  }
  return count;
}

}  // namespace

DecomposedHeat::DecomposedHeat(mechanics::DecomposedMpm<2>& mpm, DecomposedHeatOptions options)
    : mpm2_(&mpm), opt_(std::move(options)) {
  check_materials(mpm);
  select_fixed_nodes(mpm);
  interface_start(mpm);
}

DecomposedHeat::DecomposedHeat(mechanics::DecomposedMpm<3>& mpm, DecomposedHeatOptions options)
    : mpm3_(&mpm), opt_(std::move(options)) {
  check_materials(mpm);
  select_fixed_nodes(mpm);
  interface_start(mpm);
}

DecomposedHeat::~DecomposedHeat() = default;

// The owned nodes on fixed-temperature faces by the serial rule (for_each_fixed_node): the lattice index
// of owned node u (x fastest over owned_nodes()) is its DMDA index less Grid<Dim>::ghost. Ownership does
// not change during a run: the table is built once; a window holds those of its nodes that are unknowns.
template <int Dim>
void DecomposedHeat::select_fixed_nodes(const mechanics::DecomposedMpm<Dim>& mpm) {
  face_temperature_.clear();
  if (opt_.fixed_faces.empty()) return;
  for (const FixedTemperatureFace& f : opt_.fixed_faces)
    if (f.axis < 0 || f.axis >= Dim) throw std::invalid_argument("decomposed heat: fixed face axis out of range");
  const std::array<int, 2 * Dim> own = mpm.owned_nodes();
  const std::size_t no = mpm.owned_local_nodes().size();
  const auto lattice_along = [&own](std::size_t u, int axis) {
    for (int d = 0; d < axis; ++d) u /= static_cast<std::size_t>(own[2 * d + 1] - own[2 * d]);
    const auto extent = static_cast<std::size_t>(own[2 * axis + 1] - own[2 * axis]);
    return own[2 * axis] + static_cast<int>(u % extent) - mechanics::Grid<Dim>::ghost;
  };
  face_temperature_.assign(no, std::numeric_limits<double>::quiet_NaN());
  for_each_fixed_node(opt_.fixed_faces, mpm.grid().cells(), no, lattice_along,
                      [this](std::size_t u, double t) { face_temperature_[u] = t; });
}

template <int Dim>
void DecomposedHeat::check_materials(mechanics::DecomposedMpm<Dim>& mpm) {
  if (!(opt_.fe_safety > 0.0 && opt_.fe_safety <= 1.0))
    throw std::invalid_argument("decomposed heat: fe_safety " + std::to_string(opt_.fe_safety) +
                                " (expected a value in (0, 1])");
  check_window_options(opt_.window, opt_.matrix_free_max_substeps, "decomposed heat");  // the serial Coupler's checks
  thermal::IntegratorOptions io = opt_.integrator_options;
  io.fe_safety = opt_.fe_safety;
  // The same on every rank (all hold the same options): a bad name throws everywhere.
  assembled_ = std::make_unique<DecomposedAssembledSolve>(opt_.integrator == "auto" ? "cvode_bdf" : opt_.integrator, io,
                                                          opt_.preconditioner);
  scalar_ = mpm.particle_scalar_index(opt_.temperature);
  if (!(opt_.subgrid_relaxation_time > 0.0))
    throw std::invalid_argument("decomposed heat: subgrid_relaxation_time " +
                                std::to_string(opt_.subgrid_relaxation_time) + " s (expected > 0, or infinite: none)");
  if (opt_.plastic.enabled) {  // the serial PlasticHeatSource's check
    for (std::size_t m = 0; m < opt_.plastic.taylor_quinney.size(); ++m)
      if (!(opt_.plastic.taylor_quinney[m] >= 0.0 && opt_.plastic.taylor_quinney[m] <= 1.0))
        throw std::invalid_argument("decomposed heat: Taylor-Quinney fraction of material " + std::to_string(m) + " is " +
                                    std::to_string(opt_.plastic.taylor_quinney[m]) + " (expected a value in [0, 1])");
    heated_scalar_ = mpm.particle_scalar_index(opt_.plastic_work_heated);
  }
  // Every rank checks its own particles' materials and all agree before any window.
  int bad = -1;
  for (int m : mpm.local_particle_data().material)
    if (m < 0 || m >= static_cast<int>(opt_.materials.size())) bad = std::max(bad, m);
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_INT, MPI_MAX, mpm.communicator());
  if (bad >= 0)
    throw std::invalid_argument("decomposed heat: material " + std::to_string(bad) +
                                " has no thermal properties (expected " + std::to_string(opt_.materials.size()) +
                                " entries in materials to cover it)");
  pending_.assign(mpm.owned_local_nodes().size(), 0.0);
  // M_i and T_i of the start (eq. 38), as Coupler::start: the adaptive policy's first estimate and the
  // first snapshot's thermal nodes (thermal_nodes).
  gather_mass(mpm);
}

MPI_Comm DecomposedHeat::communicator() const { return mpm3_ ? mpm3_->communicator() : mpm2_->communicator(); }

mechanics::DecomposedLocalParticles DecomposedHeat::local_particles() const {
  return mpm3_ ? mpm3_->local_particle_data() : mpm2_->local_particle_data();
}

std::vector<double> DecomposedHeat::temperatures() const {
  return mpm3_ ? mpm3_->particle_scalar(scalar_) : mpm2_->particle_scalar(scalar_);
}

double DecomposedHeat::heat_content() const {
  const mechanics::DecomposedLocalParticles P = local_particles();
  const std::vector<double> T = temperatures();
  double e = 0.0;
  for (std::size_t k = 0; k < T.size(); ++k) {
    const ThermalProperties& m = opt_.materials[static_cast<std::size_t>(P.material[k])];
    if (m.conducts) e += P.mass[k] * m.heat_capacity * T[k];
  }
  return sum_over(communicator(), e);
}

double DecomposedHeat::pending_heat() const {
  double w = 0.0;
  for (double x : pending_) w += x;
  return sum_over(communicator(), w);
}

thermal::IntegratorStats DecomposedHeat::integrator_stats() const { return assembled_->stats(); }

// The serial Coupler::after_step: the step's frictional work, then its plastic heat, join the pending
// heat; the policy closes the window.
bool DecomposedHeat::after_step(double dt, bool must_close) {
  const std::vector<double>& work = mpm3_ ? mpm3_->frictional_work(opt_.order) : mpm2_->frictional_work(opt_.order);
  double sums[3] = {0.0, 0.0, 0.0};  // frictional work, plastic work Δw_p, plastic heat (J)
  for (double x : work) sums[0] += x;
  for (std::size_t u = 0; u < work.size(); ++u) pending_[u] += work[u];
  if (heated_scalar_ >= 0) {
    if (mpm3_) collect_plastic(*mpm3_, sums + 1);
    else collect_plastic(*mpm2_, sums + 1);
  }
  MPI_Allreduce(MPI_IN_PLACE, sums, 3, MPI_DOUBLE, MPI_SUM, communicator());
  books_.work_received += sums[0];
  books_.plastic_work_received += sums[1];
  books_.plastic_heat_received += sums[2];
  pending_plastic_ += sums[2];
  time_ += dt;
  if (mpm3_) interface_step<3>(work);  // the frictional heat's flux history (off unless asked)
  else interface_step<2>(work);
  ++books_.steps;
  ++window_steps_;
  const WindowPolicy& p = opt_.window;
  bool close = must_close;
  switch (p.kind) {
    case WindowPolicy::Kind::every_step: close = true; break;
    case WindowPolicy::Kind::every_n_steps: close = close || window_steps_ >= p.steps; break;
    case WindowPolicy::Kind::adaptive: {
      // The step's largest rise estimate and (max_travel) conducting particle speed, over every rank.
      double largest[2] = {mpm3_ ? rise_of_step(*mpm3_, work) : rise_of_step(*mpm2_, work), 0.0};
      if (p.max_travel > 0.0) {
        if (conducting_.size() != opt_.materials.size()) {  // once: the materials do not change
          conducting_.resize(opt_.materials.size());
          for (std::size_t m = 0; m < conducting_.size(); ++m) conducting_[m] = opt_.materials[m].conducts;
        }
        largest[1] = mpm3_ ? mpm3_->local_speed_max(conducting_) : mpm2_->local_speed_max(conducting_);
      }
      MPI_Allreduce(MPI_IN_PLACE, largest, 2, MPI_DOUBLE, MPI_MAX, communicator());
      max_rise_ = std::max(max_rise_, largest[0]);
      max_speed_ = std::max(max_speed_, largest[1]);
      const double h = mpm3_ ? mpm3_->grid().min_cell_size() : mpm2_->grid().min_cell_size();
      close = close || max_rise_ >= p.max_temperature_rise || time_ - window_start_ >= p.max_duration * (1.0 - 1e-12) ||
              (p.max_steps > 0 && window_steps_ >= p.max_steps) ||
              (p.max_travel > 0.0 && max_speed_ * (time_ - window_start_) >= p.max_travel * h);
      break;
    }
  }
  return close ? close_window() : false;
}

bool DecomposedHeat::close_window() {
  const double dt = time_ - window_start_;
  if (!(dt > 0.0)) return false;  // nothing to integrate; pending heat stays for the next window
  if (mpm3_) window_on(*mpm3_, pending_, window_start_, dt);
  else window_on(*mpm2_, pending_, window_start_, dt);
  std::fill(pending_.begin(), pending_.end(), 0.0);
  books_.plastic_heat_delivered += pending_plastic_;
  pending_plastic_ = 0.0;
  books_.min_window = books_.windows == 1 ? dt : std::min(books_.min_window, dt);
  books_.max_window = std::max(books_.max_window, dt);
  window_start_ = time_;
  window_steps_ = 0;
  max_rise_ = 0.0;
  max_speed_ = 0.0;
  if (mpm3_) interface_update(*mpm3_);  // as the serial Coupler::update_interface_and_hotspots
  else interface_update(*mpm2_);
  return true;
}

void DecomposedHeat::window(const std::vector<double>& joules, double dt) {
  if (mpm3_) window_on(*mpm3_, joules, time_, dt);
  else window_on(*mpm2_, joules, time_, dt);
  time_ += dt;
  window_start_ = time_;
}

// Coupler::mass_estimate on the last gather: M_i of an unknown; else the Σ M_j of the unknowns next to it
// (its heat would go to them); else the smallest unknown M_j of all ranks.
template <int Dim>
double DecomposedHeat::mass_estimate(const mechanics::DecomposedMpm<Dim>& mpm, std::size_t u) const {
  if (is_unknown(M_[u])) return M_[u];
  int cand[Dim == 2 ? 9 : 27];
  const int count = lattice_neighbours<Dim>(
      mpm.owned_nodes(), mpm.ghosted_nodes(), u,
      [this](int l) { return is_unknown(local_M_[static_cast<std::size_t>(l)]); }, cand);
  double m = 0.0;
  for (int c = 0; c < count; ++c) m += local_M_[static_cast<std::size_t>(cand[c])];
  return m > 0.0 ? m : min_unknown_mass_;
}

// This rank's largest |W_i| / M_i estimate over the nodes the step's work reached and, with plastic heat
// pending (it can sit on any node), over every node holding heat (Coupler::after_step).
template <int Dim>
double DecomposedHeat::rise_of_step(const mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& work) const {
  double rise = 0.0;
  for (std::size_t u = 0; u < work.size(); ++u)
    if (work[u] != 0.0) rise = std::max(rise, std::fabs(pending_[u]) / mass_estimate(mpm, u));
  if (pending_plastic_ != 0.0)
    for (std::size_t u = 0; u < pending_.size(); ++u)
      if (pending_[u] != 0.0) rise = std::max(rise, std::fabs(pending_[u]) / mass_estimate(mpm, u));
  return rise;
}

// The unknowns' global ids: this rank's owned unknowns in owned-node order after those of the lower
// ranks (the row ranges DistributedProblem needs), and the owners' ids on the ghosted box.
template <int Dim>
void DecomposedHeat::number_unknowns(mechanics::DecomposedMpm<Dim>& mpm) {
  if (!ids_) ids_ = std::make_unique<UnknownNumbering>();
  UnknownNumbering& n = *ids_;
  const MPI_Comm comm = mpm.communicator();
  n.count = 0;
  for (double M : M_) n.count += is_unknown(M) ? 1 : 0;
  long first = 0;
  MPI_Exscan(&n.count, &first, 1, MPI_LONG, MPI_SUM, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  n.first = rank == 0 ? 0 : first;  // MPI_Exscan leaves rank 0's result undefined
  MPI_Allreduce(&n.count, &n.global, 1, MPI_LONG, MPI_SUM, comm);
  n.owned_id.assign(M_.size(), -1);
  std::vector<double> id(M_.size(), -1.0);
  long next = n.first;
  for (std::size_t u = 0; u < M_.size(); ++u)
    if (is_unknown(M_[u])) n.owned_id[u] = next, id[u] = static_cast<double>(next), ++next;
  mpm.owned_to_local(id, 1, n.local_id);
  // Forward Euler's "power" estimate starts from the serial vector, indexed by the serial numbering.
  n.serial_id.clear();
  if (opt_.integrator == "forward_euler" && opt_.integrator_options.fe_limit_estimate == "power")
    number_serially(comm, owned_grid_nodes(mpm), n);
}

template <int Dim>
void DecomposedHeat::window_on(mechanics::DecomposedMpm<Dim>& mpm, const std::vector<double>& joules, double t0,
                               double dt) {
  using Vec = mechanics::Vec<Dim>;
  using GMap = Eigen::Map<Vec>;
  const MPI_Comm comm = mpm.communicator();
  const std::size_t no = mpm.owned_local_nodes().size(), nl = static_cast<std::size_t>(mpm.local_node_count());
  if (joules.size() != no)
    throw std::invalid_argument("decomposed heat: " + std::to_string(joules.size()) + " nodal heats for " +
                                std::to_string(no) + " owned nodes");
  if (!(dt > 0.0)) throw std::invalid_argument("decomposed heat: window " + std::to_string(dt) + " s (expected > 0)");
  std::vector<double> T;
  const std::vector<double>& M = M_;
  auto unknown = [this](double m) { return is_unknown(m); };
  auto G = [this](std::size_t a) { return GMap(kept_G_.data() + Dim * a); };

  // The serial Coupler's choice (close_window, matrix_free_window): matrix-free forward Euler for
  // "forward_euler" and "auto" when the window needs at most matrix_free_max_substeps stable sub-steps
  // (skipped without looking when the last bound puts it beyond twice that), else the assembled path.
  // Only with the "substep" policy and the Gershgorin estimate: "refuse", "unguarded" and "power" run
  // the serial Scheme on the assembled rows, as the serial Coupler.
  // With coupling.reuse_distance the serial reuse of the last gather decides (reuse_window,
  // decomposed_gather.cpp); it leaves the kept entries at the positions the window integrates from.
  const auto limit = static_cast<double>(opt_.matrix_free_max_substeps);
  bool matrix_free = false;
  long n = 1;
  if (reuse_on()) {
    matrix_free = reuse_window(mpm, dt, n);
  } else {
    const double lambda = gather_window(mpm);  // passes 1 and 2: M_, T0_, local_M_, capacity_, kept entries
    matrix_free = matrix_free_allowed() && !(last_lambda_ > 0.0 && dt / (opt_.fe_safety * 2.0 / last_lambda_) > 2.0 * limit);
    if (matrix_free) {
      last_lambda_ = lambda;
      n = thermal::forward_euler_substeps(dt, lambda, opt_.fe_safety, opt_.integrator_options.fe_max_dt);  // as the serial window
      matrix_free = n <= opt_.matrix_free_max_substeps;
    }
  }
  T = mpm.particle_scalar(scalar_);
  const std::size_t np = T.size();

  // The heat: q_i = W_i / Δt on the owned unknowns. Work on a node that is not an unknown goes, as the
  // serial distribute_heat moves it, to the unknowns among its lattice neighbours (one node away along
  // every axis, so inside this rank's ghosted box) in proportion to their M_i, the last share taking the
  // remainder; the shares are completed at the owners by one more sum_to_owned. Work on a node with no
  // unknown next to it (the serial code gives it to the nearest unknown anywhere) is refused.
  const std::array<int, 2 * Dim> own = mpm.owned_nodes(), box = mpm.ghosted_nodes();
  double moved[3] = {0.0, 0.0, 0.0};  // |work| off the unknowns, the same signed, of it with no unknown next to it
  std::vector<double> shares;         // on the ghosted box
  for (std::size_t u = 0; u < no; ++u) {
    const double w = joules[u];
    if (w == 0.0 || unknown(M[u])) continue;
    if (shares.empty()) shares.assign(nl, 0.0);
    moved[0] += std::fabs(w);
    moved[1] += w;
    int cand[Dim == 2 ? 9 : 27];
    const int count = lattice_neighbours<Dim>(
        own, box, u, [&](int l) { return unknown(local_M_[static_cast<std::size_t>(l)]); }, cand);
    if (count == 0) {
      moved[2] += std::fabs(w);
      continue;
    }
    double wsum = 0.0;
    for (int c = 0; c < count; ++c) wsum += local_M_[static_cast<std::size_t>(cand[c])];
    double given = 0.0;
    for (int c = 0; c + 1 < count; ++c) {
      const double share = w * (local_M_[static_cast<std::size_t>(cand[c])] / wsum);
      shares[static_cast<std::size_t>(cand[c])] += share;
      given += share;
    }
    shares[static_cast<std::size_t>(cand[count - 1])] += w - given;
  }
  MPI_Allreduce(MPI_IN_PLACE, moved, 3, MPI_DOUBLE, MPI_SUM, comm);
  if (moved[2] > 0.0)
    throw std::runtime_error("decomposed heat: " + std::to_string(moved[2]) +
                             " J of work on nodes with no thermal unknown next to them (not relocated in a "
                             "decomposed run)");
  std::vector<double> relocated;
  if (moved[0] > 0.0) {  // every rank takes part in the exchange
    if (shares.empty()) shares.assign(nl, 0.0);
    mpm.sum_to_owned(shares, 1, relocated);
    books_.heat_relocated += moved[1];
    ++books_.exchanges;
  }
  double delivered = 0.0;
  std::vector<double> q(no, 0.0);
  for (std::size_t u = 0; u < no; ++u) {
    if (!unknown(M[u])) continue;
    const double w = relocated.empty() ? joules[u] : joules[u] + relocated[u];
    if (w != 0.0) q[u] = w / dt, delivered += q[u];
  }

  std::vector<double> Tn = T0_;
  if (matrix_free) {
    for (std::size_t u = 0; u < no; ++u)  // Dirichlet values first (ExplicitConduction::advance)
      if (unknown(M[u]) && is_held(u)) Tn[u] = face_temperature_[u];
    // Forward-Euler sub-steps: ghost T_j from the owners, f_i = −Σ_p V_p k_p G'_ip·(∇T)_p summed at the owners.
    const double h = dt / static_cast<double>(n);
    std::vector<double> f;
    for (long s = 0; s < n; ++s) {
      mpm.owned_to_local(Tn, 1, local_T_);
      force_.assign(nl, 0.0);
      for (std::size_t k = 0; k < np; ++k) {
        if (conductance_[k] == 0.0) continue;
        const auto b = static_cast<std::size_t>(kept_first_[k]), e = static_cast<std::size_t>(kept_first_[k + 1]);
        double lo = local_T_[static_cast<std::size_t>(kept_node_[b])], hi = lo;
        for (std::size_t a = b + 1; a < e; ++a) {
          lo = std::min(lo, local_T_[static_cast<std::size_t>(kept_node_[a])]);
          hi = std::max(hi, local_T_[static_cast<std::size_t>(kept_node_[a])]);
        }
        if (hi - lo <= kQuietSpread * std::max(std::fabs(lo), std::fabs(hi))) continue;  // quiet
        Vec grad = Vec::Zero();  // (∇T)_p, eq. 37
        for (std::size_t a = b; a < e; ++a) grad += G(a) * local_T_[static_cast<std::size_t>(kept_node_[a])];
        grad *= conductance_[k];
        for (std::size_t a = b; a < e; ++a) force_[static_cast<std::size_t>(kept_node_[a])] -= G(a).dot(grad);
      }
      mpm.sum_to_owned(force_, 1, f);
      for (std::size_t u = 0; u < no; ++u)
        if (unknown(M[u]) && !is_held(u)) Tn[u] += h * (f[u] + q[u]) / M[u];
    }
    books_.substeps += n;
    books_.exchanges += 4 + 2 * n;  // M and Σ m C T, M back, the bounds, per sub-step T and f, ΔT
  } else {
    // Assembled: K's rows at their owners, the distributed integrator over [t0, t0 + Δt].
    number_unknowns(mpm);
    KeptEntries entries_of{Dim, {1, 1, 1}, &kept_first_, &kept_node_, &kept_G_, &conductance_};
    for (int d = 0; d < Dim; ++d) entries_of.box[static_cast<std::size_t>(d)] = box[2 * d + 1] - box[2 * d];
    if (reaction_active()) {  // the serial assemble's reaction, advance_and_map's T and λ, scatter_progress
      assembled_->assemble(comm, *ids_, entries_of, M, face_temperature_);
      reaction_gather(mpm);
      assembled_->set_reaction(*ids_, opt_.reaction.kinetics, reacting_mass_);
      books_.reaction_heat_released += assembled_->integrate_reacting(*ids_, &q, Tn, nodal_progress_, t0, t0 + dt);
      reaction_scatter(mpm);
    } else {
      assembled_->advance(comm, *ids_, entries_of, M, q, face_temperature_, Tn, t0, t0 + dt);
    }
    ++books_.assembled_windows;
    books_.max_row_sum_residual = std::max(books_.max_row_sum_residual, assembled_->row_sum_residual());
    books_.exchanges += 5;  // M and Σ m C T, M back, the bounds, the ids, ΔT
  }

  // Back to the particles incrementally (design §4), with the sub-grid relaxation (decomposed_sources.cpp).
  double changes[2];
  map_back(mpm, Tn, dt, T, changes, true);
  mpm.set_particle_scalar(scalar_, T);
  last_T_ = std::move(Tn);  // where a continuation goes on from (the serial Coupler's nodal_temperature_)
  last_assembled_ = !matrix_free;
  double b[3] = {delivered * dt, changes[0], changes[1]};
  MPI_Allreduce(MPI_IN_PLACE, b, 3, MPI_DOUBLE, MPI_SUM, comm);
  books_.heat_delivered += b[0];
  books_.nodal_energy_change += b[1];
  books_.particle_energy_change += b[2];
  ++books_.windows;
}

DecomposedSnapshot DecomposedHeat::snapshot() const {
  mechanics::DecomposedLocalParticles P =
      mpm3_ ? mpm3_->local_particle_data(true) : mpm2_->local_particle_data(true);  // with x_p, v_p
  DecomposedSnapshot s;
  s.id = std::move(P.id);
  s.position = std::move(P.position);
  s.velocity = std::move(P.velocity);
  s.temperature = temperatures();
  s.material = std::move(P.material);
  return s;
}

template <int Dim>
void DecomposedHeat::hot_spots_on(const mechanics::DecomposedMpm<Dim>& mpm, HotSpotTracker& tracker,
                                  const std::string& reference, double time) const {
  // This rank's particles as the serial tracker reads them (x_p, l_p, m_p, V_p, material, T_p).
  const mechanics::DecomposedLocalParticles P = mpm.local_particle_data(true);
  const std::vector<double> T = mpm.particle_scalar(scalar_);
  const std::vector<double> T0 = mpm.particle_scalar(mpm.particle_scalar_index(reference));
  mechanics::Particles<Dim> local;
  local.reserve(T.size());
  for (std::size_t k = 0; k < T.size(); ++k)
    local.add(Eigen::Map<const mechanics::Vec<Dim>>(P.position.data() + Dim * k),
              Eigen::Map<const mechanics::Vec<Dim>>(P.half_size.data() + Dim * k), P.mass[k], P.volume[k], P.material[k],
              0, T[k]);
  const auto count = static_cast<std::size_t>(mpm.global_particles());
  update_hot_spots_across_ranks(mpm.communicator(), tracker, local, P.id, T0, opt_.materials, count, time);
}

void DecomposedHeat::update_hot_spots(HotSpotTracker& tracker, const std::string& reference, double time) const {
  if (mpm3_) hot_spots_on(*mpm3_, tracker, reference, time);
  else hot_spots_on(*mpm2_, tracker, reference, time);
}

}  // namespace frictherm::coupling
