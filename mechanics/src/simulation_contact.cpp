// Multimaterial contact at nodes that carry two or more materials (Nairn, Bardenhagen & Smith 2018
// §2.2–2.12): normal, detection, contact area, stick change and friction law, consistent forces and
// frictional work. Sign convention in contact.hpp: n̂ points from material a to material b.
#include <frictherm/mechanics/simulation.hpp>

#include "contact_side.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace frictherm::mechanics {
namespace {

/// Result of one material pair at one node: the momentum change of material a and its friction work.
template <int Dim>
struct PairChange {
  bool changed = false;
  bool sliding = false;
  Vec<Dim> dp = Vec<Dim>::Zero();  // Δp'_{i,a}
  double work_first = 0.0, work_second = 0.0;
  double reduced_mass = 0.0;
};

struct PairContext {
  const ContactPairSettings* settings;
  SeparationMethod separation;
  double position_correction;
  double extent_tolerance;
  double cell_volume;  // of the node's cell (2D: times thickness), m^3
  double dt;
  bool heat;           // the momentum-update pass: compute frictional work
  // Normal-stress regularisation (ContactOptions::regularized): this node's lagged normal traction
  // σ̃ and the step that last set it, or null; updated in the heating pass only.
  double* lagged_normal = nullptr;
  double* lagged_step = nullptr;
  double step = 0.0;
  double slip_length = 0.0, relaxation_time = 0.0;
};

/// The normal impulse the friction law sees: −σ̃ A_c dt with σ̃ the lagged normal traction,
/// dσ̃/dt = −(|v_slip|/L + 1/τ)(σ̃ − σ) (Prakash–Clifton form, Cochard & Rice 2000 eq. 3), integrated
/// exactly over the step for frozen v_slip and σ; d_n itself when the regularisation is off.
inline double regularized_normal(double d_n, double d_t, double reduced_mass, double area, const PairContext& c) {
  if (!c.lagged_normal) return d_n;
  const double sigma = std::max(0.0, -d_n) / (area * c.dt);  // N = −d_n/(A_c dt), eq. 15
  const bool fresh = std::isnan(*c.lagged_normal) || *c.lagged_step < c.step - 1.0;
  double lagged = fresh ? sigma : *c.lagged_normal;
  if (c.heat) {
    const double rate = (d_t / reduced_mass) / c.slip_length + 1.0 / c.relaxation_time;
    lagged = sigma + (lagged - sigma) * std::exp(-rate * c.dt);
    *c.lagged_normal = lagged;
    *c.lagged_step = c.step;
  }
  return -lagged * area * c.dt;
}

/// Applies a friction outcome at a node in contact: stick (stick_change) or slide (eq. 17: the normal
/// change d_n n̂ plus the sliding impulse along t̂), with the sliding's frictional work in the heating pass.
template <int Dim>
void apply_friction(const ContactSide<Dim>& a, const ContactSide<Dim>& b, const FrictionOutcome& f,
                    const Vec<Dim>& stick_change, double d_n, const Vec<Dim>& n, const Vec<Dim>& t_vec, double d_t,
                    const PairContext& c, PairChange<Dim>& out) {
  out.changed = true;
  if (f.stick || !(d_t > 0.0)) {
    out.dp = stick_change;
    return;
  }
  const Vec<Dim> t_hat = t_vec / d_t;
  out.sliding = true;
  out.dp = d_n * n + f.slide_impulse * t_hat;  // eq. 17
  if (c.heat) {
    // Relative force tangential component f_t (eqs. 29–30); rigid b: Δf_a = m_a a_b − f_a.
    const Vec<Dim> df = b.rigid ? Vec<Dim>(a.mass * b.rigid_acceleration - a.force)
                                : Vec<Dim>((a.mass * b.force - b.mass * a.force) / (a.mass + b.mass));
    out.work_first = frictional_work_first_order(f.slide_impulse, d_t, out.reduced_mass);  // eq. 27
    out.work_second =
        frictional_work_second_order(f.slide_impulse, d_t, df.dot(t_hat), out.reduced_mass, c.dt);  // eqs. 34, 36
  }
}

template <int Dim>
PairChange<Dim> pair_contact(const ContactSide<Dim>& a, const ContactSide<Dim>& b, const Vec<Dim>& h,
                             const PairContext& c) {
  PairChange<Dim> out;
  // Normal from a to b (eq. 7 and §2.3): specified, maximum or average volume gradient.
  Vec<Dim> n;
  const ContactPairSettings& s = *c.settings;
  if (!contact_normal(a, b, s, n)) return out;
  // Effective cell thickness across the interface, exact for rectangular cells: h⊥ = 1/|n ⊘ h|.
  const double h_perp = 1.0 / n.cwiseQuotient(h).norm();

  const Vec<Dim> va = a.momentum / a.mass;
  const Vec<Dim> vb = b.rigid ? b.rigid_velocity : Vec<Dim>(b.momentum / b.mass);
  const bool approaching = (vb - va).dot(n) < 0.0;
  double separation = -1.0;  // velocity-only detection: contact whenever approaching
  if (c.separation == SeparationMethod::position)  // eq. 8
    separation = (b.mass_position / b.mass - a.mass_position / a.mass).dot(n) - c.position_correction * h_perp;
  else if (c.separation == SeparationMethod::displacement)  // eqs. 9–10
    separation = (b.mass_position / b.mass - a.mass_position / a.mass).dot(n);
  else if (c.separation == SeparationMethod::extent)  // particle domains, contact_extents.cpp
    separation = std::isnan(a.extent_gap) ? -1.0 : a.extent_gap - c.extent_tolerance * h_perp;
  const bool touching = separation < 0.0;
  const bool in_contact = approaching && touching;

  // Stick momentum change and reduced mass (eqs. 12–14); a rigid b has v_c = v_b, m_red = m_a.
  Vec<Dim> dp_stick;
  if (b.rigid) {
    dp_stick = a.mass * vb - a.momentum;
    out.reduced_mass = a.mass;
  } else {
    dp_stick = (a.mass * b.momentum - b.mass * a.momentum) / (a.mass + b.mass);
    out.reduced_mass = a.mass * b.mass / (a.mass + b.mass);
  }
  const double d_n = dp_stick.dot(n);  // eq. 15
  const Vec<Dim> t_vec = dp_stick - d_n * n;
  const double d_t = t_vec.norm();
  // Eq. 11 with Ω_i = Σ_j Ω_{i,j}, the node's total extrapolated domain (a volume, so the 2D thickness
  // is already in it).
  const double area = std::sqrt(2.0 * (a.domain + b.domain) * std::min(a.domain, b.domain)) / h_perp;
  if (!(area > 0.0)) return out;

  if (!in_contact) {  // separated: only an adhesive interface with tensile strength may hold (eq. 25)
    const double N = -d_n / (area * c.dt), S_stick = d_t / (area * c.dt);
    if (s.law.holds_when_separated(S_stick, N)) {
      out.changed = true;
      out.dp = dp_stick;
      return out;
    }
    // Extent detection: domains that touch but move apart this step still rub through the law's area
    // term (adhesion S_a A_c, eq. 24 with N = 0); no normal change. Without it an area law loses its
    // traction at every touching node whose normal velocity noise points outward that step.
    if (c.separation == SeparationMethod::extent && touching && s.law.needs_area() && !(a.sliver || b.sliver) &&
        d_t > 0.0)
      apply_friction(a, b, s.law.in_contact(ContactImpulse{0.0, d_t, out.reduced_mass, area, c.dt}), t_vec, 0.0,
                     n, t_vec, d_t, c, out);
    return out;
  }
  if (a.sliver || b.sliver) {  // normal change only: no friction, no heat (ContactSide::sliver)
    out.changed = true;
    out.dp = d_n * n;
    return out;
  }
  const double d_n_law = regularized_normal(d_n, d_t, out.reduced_mass, area, c);
  apply_friction(a, b, s.law.in_contact(ContactImpulse{d_n_law, d_t, out.reduced_mass, area, c.dt}), dp_stick, d_n,
                 n, t_vec, d_t, c, out);
  return out;
}

}  // namespace

// Lists (node, slot) for every node where two or more fields have mass, grouped by node; within a
// node the slots come in material order because fields are laid out in material order.
template <int Dim>
void Simulation<Dim>::find_contact_nodes() {
  if (!any_multimaterial_) {  // every present pair uses penalty contact
    contact_entries_.clear();
    contact_groups_.assign(1, 0);
    return;
  }
  // Counting sort by node, O(slots) (no comparison sort): count the fields with mass at each node,
  // give each node with two or more a run of entries in order of first appearance, fill the runs in
  // field order (slots are laid out in field order). Only the slots with mass are visited after the
  // first pass. The counts and cursors are reset slot by slot, or over the grid when that is shorter.
  const double mmin = empty_node_mass_;
  const std::size_t total = nodes_.mass.size();
  if (total >= node_field_count_.size()) {
    std::fill(node_field_count_.begin(), node_field_count_.end(), 0);
    std::fill(node_entry_cursor_.begin(), node_entry_cursor_.end(), -1);
  } else {
    for (std::size_t s = 0; s < total; ++s) {
      const std::size_t node = static_cast<std::size_t>(slot_node_[s]);
      node_field_count_[node] = 0;
      node_entry_cursor_[node] = -1;
    }
  }
  occupied_slots_.clear();
  for (std::size_t s = 0; s < total; ++s)
    if (nodes_.mass[s] > mmin) {
      ++node_field_count_[static_cast<std::size_t>(slot_node_[s])];
      occupied_slots_.push_back(static_cast<int>(s));
    }
  int entries = 0;
  for (const int s : occupied_slots_) {
    const std::size_t node = static_cast<std::size_t>(slot_node_[static_cast<std::size_t>(s)]);
    if (node_field_count_[node] >= 2 && node_entry_cursor_[node] < 0) {
      node_entry_cursor_[node] = entries;
      entries += node_field_count_[node];
    }
  }
  contact_entries_.resize(static_cast<std::size_t>(entries));
  std::size_t f = 0;  // the field of slot s: fields are laid out in order, so f only advances
  for (const int s : occupied_slots_) {
    const std::size_t su = static_cast<std::size_t>(s);
    while (su >= fields_[f].first + fields_[f].count) ++f;
    const int node = slot_node_[su];
    if (node_field_count_[static_cast<std::size_t>(node)] >= 2)
      contact_entries_[static_cast<std::size_t>(node_entry_cursor_[static_cast<std::size_t>(node)]++)] = {
          node, s, static_cast<int>(f)};
  }
  // Node groups of contact_entries_: the start of each contact node's run, then the end.
  contact_groups_.clear();
  for (std::size_t e = 0; e < contact_entries_.size(); ++e)
    if (e == 0 || contact_entries_[e].node != contact_entries_[e - 1].node) contact_groups_.push_back(e);
  contact_groups_.push_back(contact_entries_.size());
}

template <int Dim>
void Simulation<Dim>::resolve_contact(ContactPass pass, double dt) {
  const NestedPhase timed(phase_times_.contact, nested_phase_);  // called inside other phases
  const bool heat = pass == ContactPass::updated;
  const bool forces = pass == ContactPass::updated;
  const std::size_t nm = materials_.size();
  Vec<Dim> h = grid_.cell_size();
  const double cell_volume = grid_.cell_volume() * (Dim == 2 ? opt_.thickness : 1.0);
  if (heat) contact_stats_ = ContactStats{};
  const bool regularized = contact_opt_.regularized();
  if (regularized && lagged_normal_traction_.size() != grid_.node_count()) {
    lagged_normal_traction_.assign(grid_.node_count(), std::numeric_limits<double>::quiet_NaN());
    lagged_normal_step_.assign(grid_.node_count(), -2.0);
  }

  // The node groups of contact_entries_ (find_contact_nodes): each group reads and writes only its own
  // node's slots and work entries, so groups run in parallel. Stats and pair books go to per-thread
  // accumulators, summed in thread order afterwards (deterministic for a given thread count).
  const long groups = static_cast<long>(contact_groups_.size()) - 1;
  const int threads = groups >= 256 ? threads_ : 1;
  contact_thread_work_.resize(static_cast<std::size_t>(threads));
  for (auto& t : contact_thread_work_) {
    t.stats = ContactStats{};
    if (heat) t.pair_first.assign(nm * nm, 0.0), t.pair_second.assign(nm * nm, 0.0);
  }

#pragma omp parallel num_threads(threads)
  {
    ContactThreadWork& acc = contact_thread_work_[static_cast<std::size_t>(omp_get_thread_num())];
    PairContext ctx{nullptr, contact_opt_.separation, contact_opt_.position_correction, contact_opt_.extent_tolerance,
                    cell_volume, dt, heat};
    ctx.step = static_cast<double>(step_);
    ctx.slip_length = contact_opt_.regularization_slip_length;
    ctx.relaxation_time = contact_opt_.regularization_time;
    // Per-node scratch, reused from call to call (no allocation per step once grown).
    thread_local std::vector<ContactSide<Dim>> sides;
    thread_local std::vector<int> slots, mats, entries;
    thread_local std::vector<Vec<Dim>> dps;
    auto apply = [&](int slot, const Vec<Dim>& dp) {
      nodes_.momentum[static_cast<std::size_t>(slot)] += dp;
      if (forces) nodes_.force[static_cast<std::size_t>(slot)] += dp / dt;  // eq. 19
    };
    auto add_work = [&](int node, int ma, int mb, double w1, double w2) {
      if (!(std::isfinite(w1) && std::isfinite(w2))) return;  // guarded upstream; never inject NaN heat
      work_first_[static_cast<std::size_t>(node)] += w1;
      work_second_[static_cast<std::size_t>(node)] += w2;
      const std::size_t k = static_cast<std::size_t>(std::min(ma, mb)) * nm + static_cast<std::size_t>(std::max(ma, mb));
      acc.pair_first[k] += w1;
      acc.pair_second[k] += w2;
    };
    ContactStats& stats = acc.stats;

#pragma omp for schedule(static)
    for (long g = 0; g < groups; ++g) {
      const int node = contact_entries_[contact_groups_[static_cast<std::size_t>(g)]].node;
      const int guarded = gather_contact_sides(static_cast<std::size_t>(g), dt, sides, slots, mats, entries);
      if (heat) stats.guarded += guarded;
      const std::size_t count = sides.size();
      if (heat) {
        ++stats.contact_nodes;
        if (count > 2) ++stats.multi_nodes;
      }
      if (count == 2) {
        // Two materials: a is the deformable one when the other is rigid.
        std::size_t ia = 0, ib = 1;
        if (sides[0].rigid) std::swap(ia, ib);
        if (!sides[ia].rigid && contact_pair(mats[ia], mats[ib]).method == ContactMethod::multimaterial) {
          ctx.settings = &contact_pair(mats[ia], mats[ib]);
          if (regularized) {
            ctx.lagged_normal = &lagged_normal_traction_[static_cast<std::size_t>(node)];
            ctx.lagged_step = &lagged_normal_step_[static_cast<std::size_t>(node)];
          }
          const PairChange<Dim> r = pair_contact(sides[ia], sides[ib], h, ctx);
          ctx.lagged_normal = ctx.lagged_step = nullptr;
          if (r.changed) {
            apply(slots[ia], r.dp);
            if (!sides[ib].rigid) apply(slots[ib], Vec<Dim>(-r.dp));
          }
          if (r.sliding && heat) {
            ++stats.sliding_nodes;
            add_work(node, mats[ia], mats[ib], r.work_first, r.work_second);
          }
        }
      } else if (count > 2) {
        // Three or more: each material against the others lumped into one virtual material; its
        // change is applied to it alone, frictional work summed with eq. 40 (1/m_red = Σ_j 1/m_j, eq. 39).
        bool any_rigid = false;
        double inv_mred = 0.0, total = 0.0;
        for (const auto& sd : sides) {
          any_rigid = any_rigid || sd.rigid;
          if (!sd.rigid) inv_mred += 1.0 / sd.mass, total += sd.mass;
        }
        const double m_red_node = 1.0 / inv_mred;
        dps.assign(count, Vec<Dim>::Zero());
        for (std::size_t a = 0; a < count; ++a) {
          if (sides[a].rigid) continue;
          ContactSide<Dim> rest;
          const std::size_t dominant = lump_partners(sides, mats, a, rest);
          if (dominant == count) continue;  // all its partners here use penalty contact
          ctx.settings = &contact_pair(mats[a], mats[dominant]);
          const PairChange<Dim> r = pair_contact(sides[a], rest, h, ctx);
          if (r.changed) dps[a] = r.dp;
          if (r.sliding && heat) {
            ++stats.sliding_nodes;
            const double w = m_red_node / sides[a].mass;  // eq. 40
            add_work(node, mats[a], mats[dominant], w * r.work_first, w * r.work_second);
          }
        }
        if (!any_rigid) {
          // The lumped changes need not cancel; removing their mass-weighted mean keeps the node's total
          // momentum exact without changing any relative velocity (an addition to the paper's §2.12).
          Vec<Dim> residual = Vec<Dim>::Zero();
          for (const auto& d : dps) residual += d;
          for (std::size_t a = 0; a < count; ++a) dps[a] -= (sides[a].mass / total) * residual;
        }
        for (std::size_t a = 0; a < count; ++a)
          if (!sides[a].rigid) apply(slots[a], dps[a]);
      }
    }
  }
  for (const auto& t : contact_thread_work_) {
    if (!heat) continue;
    contact_stats_.contact_nodes += t.stats.contact_nodes;
    contact_stats_.multi_nodes += t.stats.multi_nodes;
    contact_stats_.sliding_nodes += t.stats.sliding_nodes;
    contact_stats_.guarded += t.stats.guarded;
    for (std::size_t k = 0; k < nm * nm; ++k) pair_work_first_[k] += t.pair_first[k], pair_work_second_[k] += t.pair_second[k];
  }
}

// The materials at contact node `group` above min_mass_fraction of the node's mass (lighter ones take
// no part; those under sliver_fraction are marked), with their slots, materials and entries; returns how many were left out.
template <int Dim>
int Simulation<Dim>::gather_contact_sides(std::size_t group, double dt, std::vector<ContactSide<Dim>>& sides,
                                          std::vector<int>& slots, std::vector<int>& mats, std::vector<int>& entries) const {
  const std::size_t e = contact_groups_[group], end = contact_groups_[group + 1];
  sides.clear(), slots.clear(), mats.clear(), entries.clear();
  const bool extents = contact_opt_.separation == SeparationMethod::extent && entry_extent_own_.size() == contact_entries_.size();
  double node_mass = 0.0;
  for (std::size_t q = e; q < end; ++q) node_mass += nodes_.mass[static_cast<std::size_t>(contact_entries_[q].slot)];
  int guarded = 0;
  for (std::size_t q = e; q < end; ++q) {
    const int slot = contact_entries_[q].slot;
    const std::size_t su = static_cast<std::size_t>(slot);
    if (nodes_.mass[su] < contact_opt_.min_mass_fraction * node_mass) {
      ++guarded;
      continue;
    }
    const std::size_t f = static_cast<std::size_t>(contact_entries_[q].field);
    ContactSide<Dim> sd;
    sd.mass = nodes_.mass[su];
    sd.momentum = nodes_.momentum[su];
    sd.force = nodes_.force[su];
    sd.mass_position = nodes_.mass_position[su];
    sd.domain = nodes_.domain[su];
    sd.domain_gradient = nodes_.domain_gradient[su];
    sd.rigid = fields_[f].rigid;
    sd.sliver = nodes_.mass[su] < contact_opt_.sliver_fraction * node_mass;
    if (sd.rigid) {
      const Material& mat = materials_[static_cast<std::size_t>(fields_[f].material)];
      sd.rigid_velocity = field_velocity_[f];
      sd.rigid_acceleration = (mat.rigid_velocity_at(time_ + dt).template head<Dim>() - field_velocity_[f]) / dt;
    }
    if (extents) {  // contact_extents.cpp: the gap between the surfaces, −(own + partners') extents
      const double own = entry_extent_own_[q], other = entry_extent_other_[q];
      if (std::isfinite(own) && std::isfinite(other)) sd.extent_gap = -(own + other);
    }
    sides.push_back(sd);
    slots.push_back(slot);
    mats.push_back(fields_[f].material);
    entries.push_back(static_cast<int>(q));
  }
  return guarded;
}

// sides[a]'s multimaterial partners lumped into one virtual material (§2.12); a rigid partner
// dominates the lump. Returns the heaviest partner, or sides.size() when every partner here uses
// penalty contact.
template <int Dim>
std::size_t Simulation<Dim>::lump_partners(const std::vector<ContactSide<Dim>>& sides, const std::vector<int>& mats,
                                           std::size_t a, ContactSide<Dim>& rest) const {
  const std::size_t count = sides.size();
  rest = ContactSide<Dim>{};
  std::size_t dominant = count;
  double rigid_weight = -1.0;
  bool all_slivers = true;
  for (std::size_t j = 0; j < count; ++j) {
    if (j == a || contact_pair(mats[a], mats[j]).method == ContactMethod::penalty) continue;  // penalty pairs meet elsewhere
    rest.add(sides[j]);
    all_slivers = all_slivers && sides[j].sliver;
    if (dominant == count || sides[j].mass > sides[dominant].mass) dominant = j;
    if (sides[j].rigid && sides[j].mass > rigid_weight) {
      rigid_weight = sides[j].mass;
      rest.rigid = true;
      rest.rigid_velocity = sides[j].rigid_velocity;
      rest.rigid_acceleration = sides[j].rigid_acceleration;
    }
  }
  rest.sliver = dominant != count && all_slivers;
  return dominant;
}

// Extent separation: per contact entry, the normal from its material to its partners, as
// resolve_contact will compute it (two materials: the pair's normal; more: against the lump).
template <int Dim>
void Simulation<Dim>::compute_contact_normals() {
  entry_normal_.assign(contact_entries_.size(), Vec<Dim>::Zero());
  entry_extent_own_.clear();  // no gap while the normals are gathered
  const long groups = static_cast<long>(contact_groups_.size()) - 1;
  const int threads = groups >= 256 ? threads_ : 1;
#pragma omp parallel num_threads(threads)
  {
    thread_local std::vector<ContactSide<Dim>> sides;
    thread_local std::vector<int> slots, mats, entries;
#pragma omp for schedule(static)
    for (long g = 0; g < groups; ++g) {
      gather_contact_sides(static_cast<std::size_t>(g), 1.0, sides, slots, mats, entries);
      const std::size_t count = sides.size();
      if (count < 2) continue;
      for (std::size_t a = 0; a < count; ++a) {
        Vec<Dim> n;
        bool ok;
        if (count == 2) {
          const std::size_t b = 1 - a;
          ok = contact_normal(sides[a], sides[b], contact_pair(mats[a], mats[b]), n);
        } else {
          ContactSide<Dim> rest;
          const std::size_t dominant = lump_partners(sides, mats, a, rest);
          ok = dominant < count && contact_normal(sides[a], rest, contact_pair(mats[a], mats[dominant]), n);
        }
        if (ok) entry_normal_[static_cast<std::size_t>(entries[a])] = n;
      }
    }
  }
}

template <int Dim>
double Simulation<Dim>::cumulative_frictional_work(HeatingOrder order) const {
  const auto& w = order == HeatingOrder::first ? pair_work_first_ : pair_work_second_;
  double sum = 0.0;
  for (double x : w) sum += x;
  return sum;
}

template <int Dim>
double Simulation<Dim>::cumulative_frictional_work(HeatingOrder order, int a, int b) const {
  const auto& w = order == HeatingOrder::first ? pair_work_first_ : pair_work_second_;
  const std::size_t nm = materials_.size();
  if (w.size() != nm * nm || a < 0 || b < 0 || static_cast<std::size_t>(a) >= nm || static_cast<std::size_t>(b) >= nm) return 0.0;
  return w[static_cast<std::size_t>(std::min(a, b)) * nm + static_cast<std::size_t>(std::max(a, b))];
}

#define FRICTHERM_INSTANTIATE_CONTACT(D)                                              \
  template void Simulation<D>::find_contact_nodes();                                  \
  template void Simulation<D>::resolve_contact(ContactPass, double);                  \
  template void Simulation<D>::compute_contact_normals();                             \
  template int Simulation<D>::gather_contact_sides(std::size_t, double, std::vector<ContactSide<D>>&,      \
                                                   std::vector<int>&, std::vector<int>&, std::vector<int>&) const; \
  template std::size_t Simulation<D>::lump_partners(const std::vector<ContactSide<D>>&, const std::vector<int>&, \
                                                    std::size_t, ContactSide<D>&) const;                      \
  template double Simulation<D>::cumulative_frictional_work(HeatingOrder) const;      \
  template double Simulation<D>::cumulative_frictional_work(HeatingOrder, int, int) const;
FRICTHERM_INSTANTIATE_CONTACT(2)
FRICTHERM_INSTANTIATE_CONTACT(3)
#undef FRICTHERM_INSTANTIATE_CONTACT

}  // namespace frictherm::mechanics
