// Multimaterial contact and frictional heating in the decomposed step (frictherm/mechanics/
// distributed.hpp; Nairn, Bardenhagen & Smith 2018 §2.2–2.12). After fields_to_owners every owned
// node that two or more materials reach holds the complete per-material sums (m, p, f, Σ S m x, Ω, g)
// of all ranks (sparse_exchange.cpp), so contact is resolved node-locally at owned nodes by the
// serial module's code (contact_pair.hpp: normal eq. 7, detection eqs. 8–10, area eq. 11, stick
// change eqs. 12–15, friction law eqs. 16–25, consistent forces eq. 19, frictional work eqs. 27, 34,
// 36, 40), and fields_to_ghosts hands the resulting per-material v, a to the ranks that sent them.
// The gathering of a node's sides follows the serial Simulation::gather_contact_sides (materials
// above min_mass_fraction of the node's mass, in material order; slivers marked).
#include "distributed/decomposed_state.hpp"

#include "contact_extent.hpp"

#include <mpi.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace frictherm::mechanics {

// Checks the contact settings (the serial enable_contact / set_contact_pair rules plus what the
// decomposed step does not support) and fills pair_settings / pair_index as the serial
// set_contact_pair does, read as the serial contact_pair(a, b):
// the default pair for pairs not set, an explicit pair (a, b) as given, (b, a) with the normal
// reversed, a specified normal made unit.
template <int Dim>
void DecomposedMpm<Dim>::Impl::setup_contact() {
  const std::size_t n = materials.size();
  if (!opt.contact) {
    if (!opt.contact_pairs.empty())
      throw std::invalid_argument("decomposed mechanics: contact_pairs given but contact is off (set contact = true)");
    return;
  }
  const ContactOptions& co = opt.contact_options;
  const std::string where = "decomposed mechanics: contact ";
  if (!(co.position_correction >= 0.0 && co.position_correction < 2.0))
    throw std::invalid_argument(where + "position_correction must be in [0, 2) cell sizes");
  if (!(co.min_mass_fraction >= 0.0 && co.min_mass_fraction < 0.5))
    throw std::invalid_argument(where + "min_mass_fraction must be in [0, 0.5)");
  // Either every pair multimaterial, or every pair penalty with the penalty contact given
  // (Options::penalty_pairs; then no grid contact, as the serial step without multimaterial pairs).
  const bool penalty_run = !opt.penalty_pairs.empty();
  auto multimaterial_only = [&](const ContactPairSettings& s, const std::string& pair) {
    if (s.method == ContactMethod::penalty && !penalty_run)
      throw std::invalid_argument(where + pair + ": method 'penalty' needs the penalty contact's points and pairs "
                                  "(Options::penalty_pairs)");
    if (s.method != ContactMethod::penalty && penalty_run)
      throw std::invalid_argument(where + pair + ": multimaterial and penalty pairs together are not supported in a "
                                  "decomposed run (expected every pair 'penalty')");
  };
  partner_field.assign(n, 0);  // with contact, field = material
  for (std::size_t m = 0; m < n; ++m) partner_field[m] = rigid_partner(static_cast<PetscInt>(m)) ? 1 : 0;
  multimaterial_only(co.default_pair, "default pair");
  pair_settings.assign(1, co.default_pair);
  pair_index.assign(opt.contact_pairs.empty() ? 0 : n * n, 0);
  for (const DecomposedContactPair& p : opt.contact_pairs) {
    const int a = p.material_a, b = p.material_b;
    const std::string pair = "pair (" + std::to_string(a) + ", " + std::to_string(b) + ")";
    if (a < 0 || b < 0 || a >= static_cast<int>(n) || b >= static_cast<int>(n) || a == b)
      throw std::invalid_argument(where + pair + ": expected two different materials in 0 … " + std::to_string(n - 1));
    multimaterial_only(p.settings, pair);
    ContactPairSettings s = p.settings;
    if (s.normal == NormalMethod::specified) {
      const double len = s.normal_vector.template head<Dim>().norm();
      if (!(len > 0.0)) throw std::invalid_argument(where + pair + ": a specified normal must be non-zero");
      s.normal_vector /= len;
    }
    ContactPairSettings flipped = s;  // seen from b: the normal points from b to a
    flipped.normal_vector = -s.normal_vector;
    pair_settings.push_back(s);
    pair_settings.push_back(flipped);
    pair_index[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)] = static_cast<int>(pair_settings.size()) - 2;
    pair_index[static_cast<std::size_t>(b) * n + static_cast<std::size_t>(a)] = static_cast<int>(pair_settings.size()) - 1;
  }
}

// Phase 5, owned nodes: the multi-material ones where two or more fields have mass (the serial
// find_contact_nodes); the step's frictional work per owned node starts at zero.
template <int Dim>
void DecomposedMpm<Dim>::Impl::find_contact_nodes(double /*dt*/) {
  const PetscInt owned = owned_count();
  work_first.assign(static_cast<std::size_t>(owned), 0.0);
  work_second.assign(static_cast<std::size_t>(owned), 0.0);
  contact_nodes.clear();
  if (!opt.contact || !opt.penalty_pairs.empty()) return;  // penalty contact only: no grid contact
  for (std::size_t g = 0; g < mt_q.size(); ++g) {
    int present = 0;
    for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e)
      if (mt_at(e)[Dof::mass] > empty_node_mass) ++present;
    if (present >= 2) contact_nodes.push_back({static_cast<std::size_t>(mt_q[g]), g});
  }
}

// Phase 6: contact on the extrapolated momenta (momentum changes only); it opens the step's contact.
template <int Dim>
void DecomposedMpm<Dim>::Impl::contact_extrapolated(double dt) {
  contact_failure.clear();
  mt_start_change.assign(mt_field.size(), Vec<Dim>::Zero());
  recording_start_change = true;
  resolve_contact(false, dt);
  recording_start_change = false;
}

// Phase 8: contact on p^{n+1}, forces kept consistent (eq. 19), frictional work (eqs. 27, 34, 36, 40).
template <int Dim>
void DecomposedMpm<Dim>::Impl::contact_updated(double dt) {
  resolve_contact(true, dt);
}

// MUSL: contact on the momenta remapped from the updated particles, after their exchange to the owners
// (the serial ContactPass::remapped: momentum changes only, as phase 6). The contact nodes and groups
// are those of phase 5: the remap refills the same slots (particle_to_grid's masses, forces and
// contact terms with the new momenta), so fields_to_owners rebuilds the same groups with the same
// sums of m, Σ S m x, Ω, g, and the extents measured for them still apply.
template <int Dim>
void DecomposedMpm<Dim>::Impl::contact_remapped(double dt) {
  resolve_contact(false, dt);
}

// The serial gather_contact_sides on the owner's complete group g: the fields with mass, those
// under min_mass_fraction of the node's mass left out, slivers marked, a rigid partner's prescribed
// velocity at the step's start and its change over the step.
template <int Dim>
long DecomposedMpm<Dim>::Impl::gather_sides(std::size_t g, double dt, std::vector<ContactSide<Dim>>& sides,
                                            std::vector<int>& mats, std::vector<std::size_t>& entries) const {
  constexpr int mass = Dof::mass, momentum = Dof::momentum, force = Dof::force;
  constexpr int mass_position = Dof::mass_position, domain = Dof::domain, domain_gradient = Dof::domain_gradient;
  const ContactOptions& co = opt.contact_options;
  const bool extents = co.separation == SeparationMethod::extent &&
                       mt_extent_own.size() == contact_detail::kExtentDirections<Dim> * mt_field.size();
  auto at = [&](std::size_t e) { return mt_values.data() + e * static_cast<std::size_t>(per_field); };
  double node_mass = 0.0;
  for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e) {
    const double m = at(e)[mass];
    if (m > empty_node_mass) node_mass += m;
  }
  sides.clear(), mats.clear(), entries.clear();
  long guarded = 0;
  for (std::size_t e = mt_first[g]; e < mt_first[g + 1]; ++e) {  // in material order
    const double* v = at(e);
    const double m = v[mass];
    if (!(m > empty_node_mass)) continue;
    if (m < co.min_mass_fraction * node_mass) {
      ++guarded;
      continue;
    }
    ContactSide<Dim> sd;
    sd.mass = m;
    sd.momentum = Eigen::Map<const Vec<Dim>>(v + momentum);
    sd.force = Eigen::Map<const Vec<Dim>>(v + force);
    sd.mass_position = Eigen::Map<const Vec<Dim>>(v + mass_position);
    sd.domain = v[domain];
    sd.domain_gradient = Eigen::Map<const Vec<Dim>>(v + domain_gradient);
    sd.sliver = m < co.sliver_fraction * node_mass;
    const int material = mt_field[e];  // with contact, field = material
    if (partner_field[static_cast<std::size_t>(material)]) {
      const Material& mat = materials[static_cast<std::size_t>(material)];
      sd.rigid = true;
      sd.rigid_velocity = mat.rigid_velocity_at(time).template head<Dim>();
      sd.rigid_acceleration = (mat.rigid_velocity_at(time + dt).template head<Dim>() - sd.rigid_velocity) / dt;
    }
    if (extents)  // contact_extents.cpp: the gap between the surfaces
      contact_detail::set_extent_gaps<Dim>(sd, mt_extent_own.data(), mt_extent_other.data(), e);
    sides.push_back(sd);
    mats.push_back(material);
    entries.push_back(e);
  }
  return guarded;
}

template <int Dim>
void DecomposedMpm<Dim>::Impl::resolve_contact(bool updated, double dt) {
  constexpr int momentum = Dof::momentum, force = Dof::force;
  if (updated) stats = DecomposedContactStats{};
  if (contact_nodes.empty()) return;
  const ContactOptions& co = opt.contact_options;
  const Vec<Dim> h = grid.cell_size();
  const double cell_volume = grid.cell_volume() * (Dim == 2 ? opt.thickness : 1.0);  // as the serial step
  contact_detail::PairContext ctx{nullptr, co.separation, co.position_correction, co.extent_tolerance, cell_volume,
                                  co.area, dt, updated};
  const bool regularized = co.regularized();  // as the serial resolve_contact (simulation_contact.cpp)
  if (regularized && lagged_normal_traction.size() != static_cast<std::size_t>(owned_count())) {  // fresh: NaN
    lagged_normal_traction.assign(static_cast<std::size_t>(owned_count()), std::numeric_limits<double>::quiet_NaN());
    lagged_normal_step.assign(static_cast<std::size_t>(owned_count()), -2.0);
  }
  ctx.step = steps_taken;
  ctx.slip_length = co.regularization_slip_length;
  ctx.relaxation_time = co.regularization_time;
  ctx.light_touch_fraction = co.light_touch_fraction;
  auto pair_of = [this](int x, int y) -> const ContactPairSettings& { return this->pair_of(x, y); };
  // Per-node scratch, reused from call to call (no allocation per step once grown).
  thread_local std::vector<ContactSide<Dim>> sides;
  thread_local std::vector<int> mats;
  thread_local std::vector<std::size_t> entries;
  thread_local std::vector<Vec<Dim>> dps;
  for (const auto& [q, g] : contact_nodes) {
    const long guarded = gather_sides(g, dt, sides, mats, entries);
    if (updated) {
      stats.guarded += guarded;
      ++stats.contact_nodes;
      if (sides.size() > 2) ++stats.multi_nodes;
    }
    const std::size_t uq = q;
    // The energy books' rigid work in the updated pass, as the serial pass (contact_side.hpp): at
    // owned nodes only, so each node's counts once over the ranks.
    const ContactSide<Dim>* rigid_side = updated ? rigid_work_side(sides) : nullptr;
    try {
    contact_detail::resolve_contact_node(
        sides, mats, h, ctx, regularized ? &lagged_normal_traction[uq] : nullptr,
        regularized ? &lagged_normal_step[uq] : nullptr, pair_of, dps,
        [&](std::size_t j, const Vec<Dim>& dp) {
          double* v = mt_at(entries[j]);
          for (int d = 0; d < Dim; ++d) {
            v[momentum + d] += dp[d];
            if (updated) v[force + d] += dp[d] / dt;  // eq. 19
          }
          if (recording_start_change) mt_start_change[entries[j]] += dp;
          if (rigid_side) rigid_work += dp.dot(rigid_side->rigid_velocity);
        },
        [&](int ma, int mb, double w1, double w2) {
          if (!(std::isfinite(w1) && std::isfinite(w2))) return;  // never inject NaN heat (as the serial step)
          work_first[uq] += w1;
          work_second[uq] += w2;
          cumulative_first += w1;
          cumulative_second += w2;
          add_pair_work(ma, mb, w1, w2);
        },
        [&](double e) {
          if (updated) contact_normal_work += e;  // the changes the particles receive (as the serial books)
        },
        stats.sliding_nodes);
    } catch (const std::exception& e) {  // kept, not thrown: the other ranks would wait in the next collective
      if (!contact_failure.empty()) continue;
      const auto* pe = dynamic_cast<const contact_detail::ContactPairError*>(&e);
      if (pe && pe->material_a >= 0 && pe->material_b >= 0) {
        const std::string& origin = pair_of(pe->material_a, pe->material_b).origin;
        contact_failure = (origin.empty() ? std::string("contact") : origin) + " (materials '" +
                          materials[static_cast<std::size_t>(pe->material_a)].name + "' and '" +
                          materials[static_cast<std::size_t>(pe->material_b)].name + "'): " + e.what();
      } else {
        contact_failure = std::string("contact: ") + e.what();
      }
    }
  }
}

template <int Dim>
const std::vector<double>& DecomposedMpm<Dim>::frictional_work(HeatingOrder order) const {
  return order == HeatingOrder::first ? impl_->work_first : impl_->work_second;
}

template <int Dim>
double DecomposedMpm<Dim>::cumulative_frictional_work(HeatingOrder order) const {
  double w = order == HeatingOrder::first ? impl_->cumulative_first : impl_->cumulative_second;
  MPI_Allreduce(MPI_IN_PLACE, &w, 1, MPI_DOUBLE, MPI_SUM, impl_->comm);
  return w;
}

template <int Dim>
std::vector<double> DecomposedMpm<Dim>::cumulative_pair_work(HeatingOrder order) const {
  const std::size_t n = impl_->materials.size();
  std::vector<double> w = order == HeatingOrder::first ? impl_->pair_first : impl_->pair_second;
  w.resize(n * n, 0.0);
  MPI_Allreduce(MPI_IN_PLACE, w.data(), static_cast<int>(w.size()), MPI_DOUBLE, MPI_SUM, impl_->comm);
  return w;
}

template <int Dim>
const std::string& DecomposedMpm<Dim>::contact_failure() const {
  return impl_->contact_failure;
}

template <int Dim>
DecomposedContactStats DecomposedMpm<Dim>::contact_stats() const {
  const DecomposedContactStats& s = impl_->stats;
  long v[4] = {s.contact_nodes, s.multi_nodes, s.sliding_nodes, s.guarded};
  MPI_Allreduce(MPI_IN_PLACE, v, 4, MPI_LONG, MPI_SUM, impl_->comm);
  return DecomposedContactStats{v[0], v[1], v[2], v[3]};
}

#define FRICTHERM_INSTANTIATE_CONTACT(D)                                                \
  template void DecomposedMpm<D>::Impl::setup_contact();                                \
  template void DecomposedMpm<D>::Impl::find_contact_nodes(double);                     \
  template void DecomposedMpm<D>::Impl::contact_extrapolated(double);                   \
  template void DecomposedMpm<D>::Impl::contact_updated(double);                        \
  template void DecomposedMpm<D>::Impl::contact_remapped(double);                       \
  template void DecomposedMpm<D>::Impl::resolve_contact(bool, double);                  \
  template long DecomposedMpm<D>::Impl::gather_sides(std::size_t, double, std::vector<ContactSide<D>>&,         \
                                                     std::vector<int>&, std::vector<std::size_t>&) const;     \
  template const std::vector<double>& DecomposedMpm<D>::frictional_work(HeatingOrder) const; \
  template double DecomposedMpm<D>::cumulative_frictional_work(HeatingOrder) const;     \
  template std::vector<double> DecomposedMpm<D>::cumulative_pair_work(HeatingOrder) const; \
  template DecomposedContactStats DecomposedMpm<D>::contact_stats() const;               \
  template const std::string& DecomposedMpm<D>::contact_failure() const;
FRICTHERM_INSTANTIATE_CONTACT(2)
FRICTHERM_INSTANTIATE_CONTACT(3)
#undef FRICTHERM_INSTANTIATE_CONTACT

}  // namespace frictherm::mechanics
