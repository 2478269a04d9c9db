#pragma once
// Node-local multimaterial contact of one node (Nairn, Bardenhagen & Smith 2018 §2.2–2.12): one
// material pair (normal, detection, contact area, stick change, friction law, frictional work) and a
// node with two or more materials (the pair, or each material against the others lumped into a
// virtual material, eqs. 39–40). Shared by the serial step (simulation_contact.cpp) and the
// decomposed step (distributed/contact_phases.cpp): both gather the node's ContactSide values and
// apply the changes to their own storage. Sign convention in contact.hpp: n̂ points from a to b.
// Internal header.
#include "contact_side.hpp"

#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/friction.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::mechanics::contact_detail {

/// Result of one material pair at one node: the momentum change of material a and its friction work.
template <int Dim>
struct PairChange {
  bool changed = false;
  bool sliding = false;
  bool counted = false;  // sliding, and counted in ContactStats::sliding_nodes (kCountedSlideFraction)
  Vec<Dim> dp = Vec<Dim>::Zero();  // Δp'_{i,a}
  double work_first = 0.0, work_second = 0.0;
  double work_normal = 0.0;  // the energy the normal change removes (normal_stop_work), where it is applied
  double reduced_mass = 0.0;
};

/// The energy the normal contact impulse removes at a node in contact (J): the normal analogue of the
/// second-order frictional work (Nairn, Bardenhagen & Smith 2018 eqs. 32–36). Over the step the normal
/// change d_n n̂ of material a (−d_n n̂ of b, eq. 15) acts as a constant force d_n n̂/dt while the
/// relative normal velocity v_n = (v_b − v_a)·n̂ goes linearly from its start-of-step value v_n(0),
/// the momenta before this step's force increment, p_j − f_j dt (as v'(0) of eq. 32, not the
/// force-updated momenta, whose f dt/m under a large pressure no particle moves with), to its end
/// value v_n(dt) = −g/dt (the approach left to close an open extent gap g, 0 otherwise). Its work on
/// the pair is d_n n̂·(v̄_a − v̄_b) dt/dt = −d_n (v_n(0) + v_n(dt))/2; removed: ½ d_n (v_n(0) + v_n(dt)),
/// ≥ 0 for an approach stopped (d_n < 0, v_n < 0), ½ m_red v_n(0)² for a stop without force, and 0
/// for a pair resting in contact (v_n(0) = 0) however large the pressure. A rigid b moves at its
/// velocity throughout. force_dt: how long the sides' forces have acted on their momenta (dt in the
/// momentum-update pass, 0 in the passes before it or after a remap).
template <int Dim>
double normal_stop_work(const ContactSide<Dim>& a, const ContactSide<Dim>& b, const Vec<Dim>& n, double d_n,
                        double closing, double reduced_mass, double force_dt) {
  const Vec<Dim> va0 = (a.momentum - a.force * force_dt) / a.mass;
  const Vec<Dim> vb0 = b.rigid ? b.rigid_velocity : Vec<Dim>((b.momentum - b.force * force_dt) / b.mass);
  const double v_start = (vb0 - va0).dot(n), v_end = -closing / reduced_mass;
  return 0.5 * d_n * (v_start + v_end);
}

/// ContactStats::sliding_nodes counts a sliding node only where its sliding impulse is above this
/// fraction of the stick tangential impulse d_t. Where a pair touches with a relative normal velocity
/// at roundoff, the approach test (v_b − v_a)·n̂ < 0 takes the sign of the roundoff, and a node found
/// "in contact" slides with s = mu |d_n| ~ 1e-19 d_t: no physics (Δp ~ 1e-21 kg m/s against 2.5e-3), but
/// a count that changes with the order of the sums (3, 4 serially against 5, 6 on 2 ranks in the first
/// steps of tests/coupling/scenes/decomposed_sliding_block.json; roundoff s/d_t up to ~1e-16 there,
/// the smallest real one 4e-10). The momentum change and the heat are unchanged.
inline constexpr double kCountedSlideFraction = 1e-12;

/// Frictional heat: the least mass, as a fraction of the node's, with which a material's own force
/// accelerates its slip within the step (apply_friction). Measured: the excess heat of the 3D oblique
/// impact came from nodes below 3 % (docs/contact.md, "Frictional work in impacts").
inline constexpr double kHeatMassFloor = 0.03;

/// The tractions that would hold the surfaces together this step: the stick change dp_stick (eqs.
/// 12–14) over `area` and dt, normal N (eq. 15, > 0 compressive) and tangential S.
struct StickTractions {
  double N, S;
};
template <int Dim>
StickTractions stick_tractions(const Vec<Dim>& dp_stick, const Vec<Dim>& n, double d_t, double area, double dt) {
  return {-dp_stick.dot(n) / (area * dt), d_t / (area * dt)};
}

/// A deformable sliver against a rigid partner is bonded to it when the pair's law is stick, or an
/// adhesive law with a tensile strength that holds the sliver's tractions (eq. 25, the normal one
/// counted only when tensile) on area `area`.
template <int Dim>
bool bonded_sliver(const FrictionLaw& law, const Vec<Dim>& dp_stick, const Vec<Dim>& n, double d_t, double area, double dt) {
  if (law.kind() == FrictionKind::stick) return true;
  const StickTractions held = stick_tractions(dp_stick, n, d_t, area, dt);
  return law.holds_when_separated(held.S, std::min(held.N, 0.0));
}

struct PairContext {
  const ContactPairSettings* settings;
  SeparationMethod separation;
  double position_correction;
  double extent_tolerance;
  double cell_volume;
  ContactAreaMethod area_method;  // of the node's cell (2D: times thickness), m^3
  double dt;
  bool heat;           // the momentum-update pass: compute frictional work
  double light_touch_fraction = 0.0;  // ContactOptions::light_touch_fraction
  // Normal-stress regularisation (ContactOptions::regularized): this node's lagged normal traction
  // σ̃ and the step that last set it, or null; updated in the heating pass only.
  double* lagged_normal = nullptr;
  double* lagged_step = nullptr;
  double step = 0.0;
  double slip_length = 0.0, relaxation_time = 0.0;
};

/// Whether the node's lagged traction carries on from the previous step (it was in contact then).
inline bool has_lagged_history(const PairContext& c) {
  return !std::isnan(*c.lagged_normal) && *c.lagged_step >= c.step - 1.0;
}

/// The normal impulse the friction law sees: −σ̃ A_c dt with σ̃ the lagged normal traction,
/// dσ̃/dt = −(|v_slip|/L + 1/τ)(σ̃ − σ) (Prakash–Clifton form, Cochard & Rice 2000 eq. 3), integrated
/// exactly over the step for frozen v_slip and σ = −d_n/(A_c dt) (eq. 15; 0 at a touching node whose
/// surfaces move apart this step); d_n itself when the regularisation is off. Both contact passes see
/// the step's relaxed σ̃, so σ̃ → σ (the law of eq. 15) as τ → 0; the momentum-update pass keeps it.
inline double regularized_normal(double d_n, double d_t, double reduced_mass, double area, const PairContext& c) {
  if (!c.lagged_normal) return d_n;
  const double sigma = std::max(0.0, -d_n) / (area * c.dt);  // N = −d_n/(A_c dt), eq. 15
  double lagged = sigma;
  if (has_lagged_history(c)) {
    const double rate = (d_t / reduced_mass) / c.slip_length + 1.0 / c.relaxation_time;
    lagged = sigma + (*c.lagged_normal - sigma) * std::exp(-rate * c.dt);
  }
  if (c.heat) {
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
  out.counted = f.slide_impulse > kCountedSlideFraction * d_t;
  out.dp = d_n * n + f.slide_impulse * t_hat;  // eq. 17
  if (c.heat) {
    // Relative force tangential component f_t (eqs. 29–30); rigid b: Δf_a = m_a a_b − f_a.
    const Vec<Dim> df = b.rigid ? Vec<Dim>(a.mass * b.rigid_acceleration - a.force)
                                : Vec<Dim>((a.mass * b.force - b.mass * a.force) / (a.mass + b.mass));
    double f_t = df.dot(t_hat), d_t_heat = d_t;
    // The slip at the end of the step, (d_t − s)/m_red, holds each material's own acceleration f_j/m_j
    // (f_t/m_red = t̂·(f_b/m_b − f_a/m_a)). Where a material only reaches the node with the tails of its
    // particles' shape functions, m_j → 0 faster than f_j = −Σ V σ G: the small-mass node's velocity,
    // which no particle moves with (MUSL remaps it away for the particles). The heat would take it as
    // slip: in the 3D oblique impact (test_contact_3d, C = 0.4) the nodes where one material held less
    // than 3 % of the mass gave 0.023 J of the 0.035 J first-order work while their slip at the start of
    // the step paid 0.0015 J. So the heat gives each material an acceleration f_j / max(m_j, φ m_node),
    // φ = kHeatMassFloor: unchanged wherever both hold φ of the node's mass (the sliding blocks' contact
    // rows), the start-of-step slip kept (eq. 32), and the same limit as dt → 0 (docs/contact.md,
    // "Frictional work in impacts").
    const double mass_floor = kHeatMassFloor * (a.mass + (b.rigid ? 0.0 : b.mass));
    if (a.mass < mass_floor || (!b.rigid && b.mass < mass_floor)) {
      const Vec<Dim> acc_a = a.force / std::max(a.mass, mass_floor);
      const Vec<Dim> acc_b = b.rigid ? b.rigid_acceleration : Vec<Dim>(b.force / std::max(b.mass, mass_floor));
      const double f_resolved = out.reduced_mass * t_hat.dot(acc_b - acc_a);
      d_t_heat = d_t + (f_resolved - f_t) * c.dt;  // m_red v'(0) + f dt with v'(0) of eq. 32 unchanged
      f_t = f_resolved;
    }
    out.work_first = frictional_work_first_order(f.slide_impulse, d_t_heat, out.reduced_mass);  // eq. 27
    out.work_second =
        frictional_work_second_order(f.slide_impulse, d_t_heat, f_t, out.reduced_mass, c.dt);  // eqs. 34, 36
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
    separation = std::isnan(a.extent_gap) ? -1.0
                                          : std::max(a.extent_gap, a.extent_axis_gap) - c.extent_tolerance * h_perp;
  // A material holding under light_touch_fraction of the pair's mass at the node reaches it with the
  // tails of its particles' shape functions only: its mass centroid there sits about a cell from its
  // surface, so eqs. 8–10 call it separated however far it has pressed into its partner's cell. Left
  // free, its field takes its own stress's force alone, f_j = −Σ V σ G, pushing its surface into the
  // partner unopposed; under MUSL the particles take that push while the stress is updated from the
  // stopped velocities where the pair is in contact, and an impact gains energy (docs/contact.md,
  // "Where the frictionless impact creates energy"). With the option such a material is touching
  // whenever the pair approaches, and gets normal contact only there (as a sliver: no friction, no
  // heat at a node the position test calls open).
  const bool light = c.light_touch_fraction > 0.0 && !b.rigid &&
                     (c.separation == SeparationMethod::position || c.separation == SeparationMethod::displacement) &&
                     std::min(a.mass, b.mass) < c.light_touch_fraction * (a.mass + b.mass);
  const bool light_only = light && !(separation < 0.0);  // touching by the light rule alone
  const bool touching = separation < 0.0 || light;

  // Stick momentum change and reduced mass (eqs. 12–14); a rigid b has v_c = v_b, m_red = m_a.
  Vec<Dim> dp_stick;
  if (b.rigid) {
    dp_stick = a.mass * vb - a.momentum;
    out.reduced_mass = a.mass;
  } else {
    dp_stick = (a.mass * b.momentum - b.mass * a.momentum) / (a.mass + b.mass);
    out.reduced_mass = a.mass * b.mass / (a.mass + b.mass);
  }
  // Extent detection lets the surfaces close an open gap g ≥ 0 this step: the stop leaves them the
  // normal approach g/dt (an impulse m_red g/dt), so they end the step touching instead of held apart.
  // A full stop anywhere in the tolerance band held the surfaces up to 0.01 h⊥ apart, and under sliding
  // the interface's grid-scale vibration pumped the block up to it (Coulomb mu = 0.2 at 5 mm: 18.9 um;
  // docs/contact.md, "Extent detection"). The approach is stopped in full where the domains overlap.
  const double closing = c.separation == SeparationMethod::extent && a.extent_gap > 0.0
                             ? out.reduced_mass * a.extent_gap / c.dt : 0.0;
  const double d_n = dp_stick.dot(n) + closing;  // eq. 15, less the closing approach
  const bool in_contact = approaching && touching && d_n < 0.0;
  const Vec<Dim> t_vec = dp_stick - dp_stick.dot(n) * n;
  const double d_t = t_vec.norm();
  // Eq. 11 with Ω_i = Σ_j Ω_{i,j}, the node's total extrapolated domain (a volume, so the 2D thickness
  // is already in it).
  const double domain_area = std::sqrt(2.0 * (a.domain + b.domain) * std::min(a.domain, b.domain)) / h_perp;
  if (!(domain_area > 0.0)) return out;
  // The surface form (ContactAreaMethod::surface): ∫_Γ S_i dA of the smaller contact surface, eq. 11
  // where that is zero (a node inside both materials' domains has no surface term).
  double area = domain_area;
  if (c.area_method == ContactAreaMethod::surface) {
    const double surface = std::min(std::fabs(a.domain_gradient.dot(n)), std::fabs(b.domain_gradient.dot(n)));
    if (surface > 0.0) area = surface;
  }

  // Booked in the momentum-update pass only (the heating pass: the changes the particles receive), so
  // evaluated there only.
  if (in_contact && c.heat) out.work_normal = normal_stop_work(a, b, n, d_n, closing, out.reduced_mass, c.dt);
  // Slivers (ContactSide::sliver), one rule: a deformable sliver takes its rigid partner's bonded
  // outcome, every other sliver (and a light-only touch) the normal change only; no friction, no heat,
  // and the same outcome whether the pair is found in contact or separated.
  // - Bonded: the rigid body holds most of the node's mass, and the pair's law bonds the surfaces
  //   (stick, or an adhesive law whose tensile strength holds the sliver's own tractions, eq. 25, on
  //   the domain area of eq. 11: the surface form vanishes at a rigid body's interior nodes). Left free
  //   tangentially, the sliver's field moved with its own force over its own mass, f/m ~ 1/overlap, and
  //   that velocity entered its particles' velocity gradient through G ~ overlap: the bonded surface's
  //   shear relaxed at a rate proportional to dt, a Maxwell element whose loss grows as the time step
  //   shrinks (the undamped oscillating block at 1.25 mm, one material, over the load ramp: 1.0 / 10.3
  //   mJ at the pushers at C = 0.5 / 0.025; docs/contact.md, "Slivers bonded to a rigid partner").
  // - Not switching with the approach's sign: letting a separated sliver hold by adhesion only when
  //   separated made the constraint switch between "stick" and "normal only" from step to step; at a
  //   node a rigid body barely reaches (the oscillating block's pushers, moved by a fraction of a cell)
  //   that pinned the heavy block field there on some steps and not on others, and the block's
  //   particles gained kinetic energy without bound at small time steps.
  if (a.sliver || b.sliver || light_only) {
    if (a.sliver && b.rigid && !b.sliver && bonded_sliver(s.law, dp_stick, n, d_t, domain_area, c.dt)) {
      out.changed = true;
      out.dp = in_contact ? Vec<Dim>(dp_stick + closing * n) : dp_stick;
      return out;
    }
    if (in_contact) {
      out.changed = true;
      out.dp = d_n * n;
    }
    return out;
  }
  if (!in_contact) {  // separated: only an adhesive interface with tensile strength may hold (eq. 25)
    const StickTractions held = stick_tractions(dp_stick, n, d_t, area, c.dt);
    if (s.law.holds_when_separated(held.S, held.N)) {
      out.changed = true;
      out.dp = dp_stick;
      return out;
    }
    // Extent detection: domains that touch (gap below the tolerance) but move apart this step, or
    // approach too slowly to close their gap, still rub through the law's area term (adhesion S_a A_c,
    // eq. 24 with N = 0); no normal change. Without it an area law loses its traction at every touching node whose normal
    // velocity noise points outward that step.
    // Regularised: touching surfaces that move apart this step keep the friction of their lagged normal
    // traction (σ relaxing towards 0), tangentially only. Without it a node whose normal velocity
    // noise points outward lost its friction that step, while σ̃, unlike the instantaneous N, does not
    // make it up on the next (the normal impulse that closes the gap again): the linear rate law on the
    // sliding block ran 2.7 % of v_max fast at 2.5 mm (docs/contact.md, "Normal-stress regularisation").
    // Extent detection only: there `touching` says the particle domains meet; the position tests call a
    // node touching within a band of a cell, and friction there floated Coulomb μ = 0.5 (MUSL, position
    // separation, 2.5 mm: 176 µm). A node with no history (not in contact on the previous step) has no
    // lagged traction to keep.
    if (c.lagged_normal && c.separation == SeparationMethod::extent && touching && d_t > 0.0 &&
        has_lagged_history(c)) {
      const double d_n_law = regularized_normal(0.0, d_t, out.reduced_mass, area, c);
      apply_friction(a, b, s.law.in_contact(ContactImpulse{d_n_law, d_t, out.reduced_mass, area, c.dt}), t_vec, 0.0,
                     n, t_vec, d_t, c, out);
      return out;
    }
    if (c.separation == SeparationMethod::extent && touching && s.law.needs_area() && d_t > 0.0)
      apply_friction(a, b, s.law.in_contact(ContactImpulse{0.0, d_t, out.reduced_mass, area, c.dt}), t_vec, 0.0,
                     n, t_vec, d_t, c, out);
    return out;
  }
  const double d_n_law = regularized_normal(d_n, d_t, out.reduced_mass, area, c);
  apply_friction(a, b, s.law.in_contact(ContactImpulse{d_n_law, d_t, out.reduced_mass, area, c.dt}),
                 Vec<Dim>(dp_stick + closing * n), d_n, n, t_vec, d_t, c, out);
  return out;
}

/// sides[a]'s multimaterial partners lumped into one virtual material (§2.12); a rigid partner
/// dominates the lump. Returns the heaviest partner, or sides.size() when every partner here uses
/// penalty contact. pair_of(a, b) gives the settings of the material pair (a, b).
template <int Dim, class PairOf>
std::size_t lump_partners(const std::vector<ContactSide<Dim>>& sides, const std::vector<int>& mats, std::size_t a,
                          ContactSide<Dim>& rest, const PairOf& pair_of) {
  const std::size_t count = sides.size();
  rest = ContactSide<Dim>{};
  std::size_t dominant = count;
  double rigid_weight = -1.0;
  bool all_slivers = true;
  for (std::size_t j = 0; j < count; ++j) {
    if (j == a || pair_of(mats[a], mats[j]).method == ContactMethod::penalty) continue;  // penalty pairs meet elsewhere
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

/// Contact at one node whose materials (above min_mass_fraction, material order) are `sides` with
/// material ids `mats`. Two materials: the pair (a the deformable one when the other is rigid).
/// Three or more: each material against the others lumped into one virtual material; its change is
/// applied to it alone, frictional work summed with eq. 40 (1/m_red = Σ_j 1/m_j, eq. 39). Calls
/// apply(j, Δp) for the momentum change of sides[j] and, in the heating pass (ctx.heat), add_work(a, b,
/// A friction law that failed at a contact node (FrictionLaw::in_contact threw: an expression law
/// returning a negative, NaN or infinite traction), with the material pair whose law it is.
struct ContactPairError : std::runtime_error {
  ContactPairError(const std::string& what, int a, int b) : std::runtime_error(what), material_a(a), material_b(b) {}
  int material_a, material_b;
};

template <int Dim>
PairChange<Dim> pair_contact_of(const ContactSide<Dim>& a, const ContactSide<Dim>& b, const Vec<Dim>& h, PairContext& ctx,
                                int ma, int mb) {
  try {
    return pair_contact(a, b, h, ctx);
  } catch (const std::exception& e) {
    throw ContactPairError(e.what(), ma, mb);
  }
}

/// W1, W2) for the frictional work of the material pair (a, b), counting sliding pairs in
/// sliding_nodes, and add_normal(E) for the energy a normal change removes (normal_stop_work; with
/// three or more materials weighted as eq. 40, weights that sum to 1 for two). lagged_normal / lagged_step: the node's regularisation state (null when off), used
/// by two-material nodes only. dps: scratch.
template <int Dim, class PairOf, class Apply, class AddWork, class AddNormal>
void resolve_contact_node(const std::vector<ContactSide<Dim>>& sides, const std::vector<int>& mats,
                          const Vec<Dim>& h, PairContext& ctx, double* lagged_normal, double* lagged_step,
                          const PairOf& pair_of, std::vector<Vec<Dim>>& dps, Apply&& apply, AddWork&& add_work,
                          AddNormal&& add_normal, long& sliding_nodes) {
  const std::size_t count = sides.size();
  const bool heat = ctx.heat;
  if (count == 2) {
    std::size_t ia = 0, ib = 1;
    if (sides[0].rigid) std::swap(ia, ib);
    if (!sides[ia].rigid && pair_of(mats[ia], mats[ib]).method == ContactMethod::multimaterial) {
      ctx.settings = &pair_of(mats[ia], mats[ib]);
      ctx.lagged_normal = lagged_normal;
      ctx.lagged_step = lagged_step;
      const PairChange<Dim> r = pair_contact_of(sides[ia], sides[ib], h, ctx, mats[ia], mats[ib]);
      ctx.lagged_normal = ctx.lagged_step = nullptr;
      if (r.changed) {
        apply(ia, r.dp);
        if (!sides[ib].rigid) apply(ib, Vec<Dim>(-r.dp));
        if (r.work_normal != 0.0) add_normal(r.work_normal);
      }
      if (r.sliding && heat) {
        if (r.counted) ++sliding_nodes;
        add_work(mats[ia], mats[ib], r.work_first, r.work_second);
      }
    }
  } else if (count > 2) {
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
      const std::size_t dominant = lump_partners(sides, mats, a, rest, pair_of);
      if (dominant == count) continue;  // all its partners here use penalty contact
      ctx.settings = &pair_of(mats[a], mats[dominant]);
      const PairChange<Dim> r = pair_contact_of(sides[a], rest, h, ctx, mats[a], mats[dominant]);
      if (r.changed) dps[a] = r.dp;
      if (r.changed && r.work_normal != 0.0) add_normal((m_red_node / sides[a].mass) * r.work_normal);  // eq. 40
      if (r.sliding && heat) {
        if (r.counted) ++sliding_nodes;
        const double w = m_red_node / sides[a].mass;  // eq. 40
        add_work(mats[a], mats[dominant], w * r.work_first, w * r.work_second);
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
      if (!sides[a].rigid) apply(a, dps[a]);
  }
}

}  // namespace frictherm::mechanics::contact_detail
