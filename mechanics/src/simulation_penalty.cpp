// Penalty contact on boundary material points inside the MPM step (Kakouris, Chatzis &
// Triantafyllou 2024 §3.4–3.7, Algorithms 1 and 3; docs/penalty_contact.md). Per step, after the
// particle-to-grid transfer and before the momentum update:
//   detection and penalty forces at the boundary points' step-start positions (K·27–34), each point
//   force added to its own field's nodal force through the point's own weights (K·36), and the
//   frictional heat to the grid nodes through the same weights (frictional_work(), both orders);
// the points move with their field's nodal velocity (PIC), rigid fields' points with the rigid body,
// and the velocity is the one the step's stress update uses (USL: v^{n+1} after the momentum update;
// MUSL: the remapped v^{n+1}; USF: the step-start velocity, before the forces). The gap then measures
// the overlap of the bodies as their strains see it: moving the points with the pre-remap v^{n+1}
// under MUSL made the penalty spring and the bodies' elasticity two springs integrated with different
// velocities, a non-conservative loop that grew slowly at any time step (see move_boundary_points).
// The weights: S_I, the step's shape function at the point (with extended B-splines the body's
// extended basis N^e wherever it is defined, i.e. in a cell holding the body's particles, else the
// plain B-spline; degenerate nodes carry no mass and drop out), renormalised over the nodes of the
// point's field that hold material: m_I > 0.25 S_I m_p, m_p the body's mean particle mass. The same
// weights scatter the force and heat and gather the velocity, so the penalty spring does no spurious
// work. The sliver test keeps the point off nodes just outside the body's edge that hold a tail of
// its particles' shape functions only: such a node would take a share S of the force over its tiny
// mass and the point would follow its velocity. Measured without it: the sliding block with uGIMP
// blew up in 19 steps (a node of 7e-18 kg with S = 0.06), and with the quadratic B-spline a bar
// impact lost 16 % of its energy (the paper's "severe errors at the contact point" with OBS); with
// it both are right (tests/verification/test_penalty_*). EBS never needs it: its degenerate nodes
// have no mass. Weighting by nodal mass instead (S_I m_I / Σ S m) is just as stable but moves the
// contact force into the body: the stacked bars' contact rows then lost the whole contact stress.
#include "penalty_weights.hpp"

#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace frictherm::mechanics {

namespace {

using namespace penalty_kernels;

/// The step's weights over the fields' current node boxes, for apply_penalty_forces and
/// move_boundary_points. The boxes are copied into `home` (kept between steps, so nothing is
/// allocated) and lent to the weights; the destructor gives them back.
template <int Dim>
struct LentStepWeights {
  StepWeights<Dim> w;
  std::vector<FieldNodes<Dim>>& boxes;
  LentStepWeights(std::vector<FieldNodes<Dim>>& home, const Grid<Dim>& grid, ShapeKind shape,
                  const std::vector<VelocityField<Dim>>& fields, const std::vector<double>& slot_mass, double min_mass,
                  const std::vector<double>& reference_mass, double sliver, const std::vector<EbsBasis<Dim>>& ebs)
      : boxes(home) {
    home.resize(fields.size());
    for (std::size_t f = 0; f < fields.size(); ++f) {
      home[f].lo = fields[f].lo;
      home[f].extent = fields[f].extent;
      home[f].index = fields[f].index;
    }
    w.plain.grid = &grid;
    w.plain.shape = shape;
    w.plain.fields.swap(home);
    w.plain.slot_mass = &slot_mass;
    w.plain.min_mass = min_mass;
    w.plain.reference_mass = &reference_mass;
    w.plain.sliver = sliver;
    if (shape == ShapeKind::extended_bspline) w.ebs = &ebs;
  }
  LentStepWeights(const LentStepWeights&) = delete;
  LentStepWeights& operator=(const LentStepWeights&) = delete;
  ~LentStepWeights() { boxes.swap(w.plain.fields); }
};

}  // namespace

template <int Dim>
void Simulation<Dim>::check_penalty_settings(const ContactPairSettings& s, int a, int b) const {
  if (s.method != ContactMethod::penalty) return;
  const std::string what = a < 0 ? std::string("default contact pair") :
                                   "contact pair (" + materials_[static_cast<std::size_t>(a)].name + ", " +
                                       materials_[static_cast<std::size_t>(b)].name + ")";
  const auto bad = [&](const std::string& m) { throw std::invalid_argument(what + ": penalty contact " + m); };
  if (Dim != 2) bad("is 2D only (boundary segments; 3D surfaces are not implemented)");
  if (s.law.kind() != FrictionKind::coulomb && s.law.kind() != FrictionKind::frictionless)
    bad("takes a coulomb or frictionless law (Kakouris 2024 eq. 32), got " + s.law.describe());
  const PenaltySettings& p = s.penalty;
  if (!(p.normal_penalty >= 0.0) || !std::isfinite(p.normal_penalty)) bad("normal penalty must be finite and >= 0 (0: E/h)");
  if (!(p.normal_factor > 0.0) || !std::isfinite(p.normal_factor)) bad("normal penalty factor must be finite and > 0");
  if (!(p.tangential_penalty >= 0.0) || !std::isfinite(p.tangential_penalty))
    bad("tangential penalty must be finite and >= 0 (0: the normal penalty)");
  if (!(p.search_radius >= 0.0) || !std::isfinite(p.search_radius)) bad("search radius must be finite and >= 0");
  if (a < 0 && p.master >= 0) bad("master belongs to a listed pair, not the default");
  if (a >= 0 && p.master >= 0 && p.master != a && p.master != b) bad("master must be one of the pair's two materials");
}

template <int Dim>
void Simulation<Dim>::set_body_boundary(int body, const std::vector<std::vector<Vec<2>>>& loops) {
  if (finalized_) throw std::logic_error("body boundaries must be set before the simulation is finalized");
  if (body < 0 || body >= static_cast<int>(bodies_.info.size())) throw std::invalid_argument("set_body_boundary: no such body");
  for (const auto& l : loops)
    if (l.size() < 3) throw std::invalid_argument("body '" + bodies_.info[static_cast<std::size_t>(body)].name + "': a boundary loop needs at least 3 points");
  body_loops_.loops[static_cast<std::size_t>(body)] = loops;
  body_loops_.spacing[static_cast<std::size_t>(body)] = -1.0;  // given, not sampled
}

// Pairs of present materials that use penalty contact, their master/slave choice and penalties, and
// the boundary points of every body in such a pair.
template <int Dim>
void Simulation<Dim>::setup_penalty() {
  penalty_state_.contact.reset();
  penalty_state_.pairs.clear();
  penalty_state_.boundary = BoundaryPoints<Dim>{};
  const std::size_t nm = materials_.size();
  std::vector<double> mass(nm, 0.0);
  for (std::size_t k = 0; k < p_.size(); ++k) mass[static_cast<std::size_t>(p_.material[k])] += p_.mass[k];
  const auto present = [&](std::size_t m) { return layout_.field_of_material[m] >= 0 && layout_.material_end[m] > layout_.material_begin[m]; };
  contact_setup_.any_multimaterial = false;
  std::vector<std::uint8_t> in_penalty(nm, 0);
  std::vector<PenaltyPairSettings> settings;
  const double h = grid_.min_cell_size();
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = a + 1; b < nm; ++b) {
      if (!present(a) || !present(b) || (materials_[a].is_rigid() && materials_[b].is_rigid())) continue;
      const ContactPairSettings& s = contact_pair(static_cast<int>(a), static_cast<int>(b));
      if (s.method != ContactMethod::penalty) {
        contact_setup_.any_multimaterial = true;
        continue;
      }
      check_penalty_settings(s, static_cast<int>(a), static_cast<int>(b));
      // Master: as set; else the rigid one, else the stiffer, else the heavier, else the first.
      const Material &A = materials_[a], &B = materials_[b];
      int master = s.penalty.master;
      if (master < 0) {
        const double Ea = modulus_for_penalty(A), Eb = modulus_for_penalty(B);
        if (Ea != Eb) master = Ea > Eb ? static_cast<int>(a) : static_cast<int>(b);
        else master = mass[b] > mass[a] ? static_cast<int>(b) : static_cast<int>(a);
      }
      const int slave = master == static_cast<int>(a) ? static_cast<int>(b) : static_cast<int>(a);
      PenaltyPairSettings ps;
      ps.master = layout_.field_of_material[static_cast<std::size_t>(master)];
      ps.slave = layout_.field_of_material[static_cast<std::size_t>(slave)];
      ps.mu = s.law.kind() == FrictionKind::coulomb ? s.law.mu() : 0.0;
      ps.normal_penalty = s.penalty.normal_penalty;
      if (ps.normal_penalty == 0.0) {
        try {
          ps.normal_penalty = s.penalty.normal_factor * default_penalty(modulus_for_penalty(A), modulus_for_penalty(B), h);
        } catch (const std::invalid_argument&) {
          throw std::invalid_argument("contact pair (" + A.name + ", " + B.name +
                                      "): neither material has a finite Young's modulus > 0; set the normal penalty");
        }
      }
      ps.tangential_penalty = s.penalty.tangential_penalty;
      ps.law = s.penalty.law;
      ps.search_radius = s.penalty.search_radius;
      ps.paper_correction_terms = s.penalty.paper_correction_terms;
      settings.push_back(ps);
      penalty_state_.pairs.push_back(PenaltyPairInfo{master, slave});
      in_penalty[a] = in_penalty[b] = 1;
    }
  if (settings.empty()) return;
  penalty_state_.reference_mass.assign(fields_.size(), 0.0);
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    const auto m = static_cast<std::size_t>(fields_[f].material);
    const std::size_t n = layout_.material_end[m] - layout_.material_begin[m];
    if (n > 0) penalty_state_.reference_mass[f] = mass[m] / static_cast<double>(n);
  }
  penalty_state_.contact.emplace(grid_, PenaltyOptions{Dim == 2 ? opt_.thickness : 1.0});
  for (const PenaltyPairSettings& ps : settings) penalty_state_.contact->add_pair(ps);

  const double spacing = contact_setup_.options.boundary_point_spacing(h);
  for (std::size_t i = 0; i < bodies_.info.size(); ++i) {
    const int m = body_loops_.material[i];
    const std::string& name = bodies_.info[i].name;
    if (m < 0) {
      bool any = false;  // a body of several materials: does one of them use penalty contact?
      for (std::size_t k = 0; k < p_.size() && !any; ++k)
        if (p_.body[k] == static_cast<int>(i) && in_penalty[static_cast<std::size_t>(p_.material[k])]) any = true;
      if (any)
        throw std::invalid_argument("body '" + name + "' has several materials; penalty contact needs one material per body");
      continue;
    }
    if (!in_penalty[static_cast<std::size_t>(m)]) continue;
    if (body_loops_.loops[i].empty())
      throw std::invalid_argument("body '" + name + "': penalty contact needs its boundary, and its shape gives none "
                                  "(images; set one with set_body_boundary)");
    if (body_loops_.spacing[i] >= 0.0 && std::fabs(body_loops_.spacing[i] - spacing) > 1e-12 * spacing)
      throw std::logic_error("body '" + name + "': the contact boundary spacing changed after the body was added "
                             "(enable_contact must come before add_body)");
    try {
      penalty_state_.boundary.add_loops(layout_.field_of_material[static_cast<std::size_t>(m)], body_loops_.loops[i], body_loops_.half_size[i], body_loops_.velocity[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("body '" + name + "': " + e.what());
    }
  }
}

template <int Dim>
void Simulation<Dim>::apply_penalty_forces() {
  if (!penalty_state_.contact) return;
  LentStepWeights<Dim> lent(penalty_state_.fields, grid_, opt_.shape, fields_, nodes_.mass, empty_node_mass_,
                            penalty_state_.reference_mass, penalty_state_.sliver, ebs_.bases);
  apply_penalty(*penalty_state_.contact, penalty_state_.boundary, lent.w, nodes_.mass, empty_node_mass_, nodes_.force, contact_books_.work_first, contact_books_.work_second);
  const PenaltyContact<Dim>& pc = *penalty_state_.contact;
  for (std::size_t k = 0; k < penalty_state_.pairs.size(); ++k) {
    const std::size_t i = pair_book_index(penalty_state_.pairs[k].master_material, penalty_state_.pairs[k].slave_material, materials_.size());
    contact_books_.pair_work_first[i] += pc.books(k).heat_step;
    contact_books_.pair_work_second[i] += pc.books(k).heat_step;
  }
  // The step's counters, from the detection just made (under USF the boundary points move before it).
  contact_books_.stats.penalty_contacts = contact_books_.stats.penalty_sliding = 0;
  for (std::size_t k = 0; k < pc.pair_count(); ++k) {
    contact_books_.stats.penalty_contacts += pc.books(k).active;
    contact_books_.stats.penalty_sliding += pc.books(k).sliding;
  }
}

// With the weights of the step's start (those the forces go out with): a rigid field's points move as
// its particles do; the others with v_b = Σ_I w_I v_I, x_b += Δt v_b, where v_I is the nodal velocity
// the stress update of the step uses (simulation_step.cpp calls this at that point of the step):
//   USL  v^{n+1} = (p^n + Δt f)/m after the momentum update;
//   MUSL the remapped v̂^{n+1} = Σ_p S_Ip m_p v_p^{n+1} / m_I (after the remap);
//   USF  the step-start v̂^n (after the stress update, before the penalty forces).
// Why (docs/penalty_contact.md, "Stability"): the contact is a penalty spring in series with the
// bodies' elasticity. With MUSL the strains follow v̂ but the points followed v^{n+1}; per step the
// gap then moves with Δt B·M⁻¹f while the bodies keep only Δt B·M⁻¹ M_C M⁻¹ f of it (M_C the
// consistent mass), and the loop is not conservative. The stacked bars with EBS at C = 0.5 blew up at
// three of six grid offsets that way (growth per step ∝ Δt², so C = 0.1 only delayed it); moved with
// v̂ all six hold the contact stress to 0.2 % (tests/verification/test_penalty_stability.cpp).
template <int Dim>
void Simulation<Dim>::move_boundary_points(double dt, double t) {
  if (!penalty_state_.contact) return;
  LentStepWeights<Dim> lent(penalty_state_.fields, grid_, opt_.shape, fields_, nodes_.mass, empty_node_mass_,
                            penalty_state_.reference_mass, penalty_state_.sliver, ebs_.bases);  // USF: before apply_penalty_forces
  BoundaryPoints<Dim>& bp = penalty_state_.boundary;
  const long bad = move_points(bp, lent.w, grid_, dt, [&](int field, Vec<Dim>& v) {
    const auto f = static_cast<std::size_t>(field);
    if (!fields_[f].rigid) return false;
    const Material& m = materials_[static_cast<std::size_t>(fields_[f].material)];
    v = (0.5 * (m.rigid_velocity_at(t) + m.rigid_velocity_at(t + dt))).template head<Dim>();
    return true;
  }, [&](int slot) -> const Vec<Dim>& { return nodes_.velocity[static_cast<std::size_t>(slot)]; });
  if (bad >= 0) {
    const auto i = static_cast<std::size_t>(bad);
    const int m = fields_[static_cast<std::size_t>(bp.field[i])].material;
    std::ostringstream msg;
    msg << "step " << clock_.step << ", t = " << clock_.time << " s: boundary point " << i << " of material '"
        << materials_[static_cast<std::size_t>(m)].name << "' "
        << (bp.position[i].allFinite() ? "left the grid" : "has a non-finite position")
        << " (penalty contact; the step blew up: try a smaller CFL factor or penalty)";
    throw SimulationError(msg.str(), clock_.step, clock_.time, -1);
  }
}

// The penalty spring of a boundary point (stiffness ε A_s against a tributary mass ~ ρ A_s Δh) rings
// at √(ε/(ρ Δh)); with ε = E/Δh (K·40) that is c/Δh, inside the CFL limit. A stiffer penalty raises
// the frequency by √(ε/(E/Δh)), and the time step shrinks by the same factor.
template <int Dim>
double Simulation<Dim>::penalty_wave_factor() const {
  if (!penalty_state_.contact) return 1.0;
  return penalty_kernels::penalty_wave_factor(*penalty_state_.contact, penalty_state_.pairs, materials_, grid_.min_cell_size());
}

// Time-step guard (docs/penalty_contact.md, "Stability"): forward Euler on the bodies plus the
// penalty springs is stable while Δt ≤ 2/√(ω_el² + ω_p²), ω_el = 2 c/Δh the elastic bound behind the
// CFL condition (c = `wave_speed`, the largest wave plus particle speed) and ω_p² the Gershgorin bound
// of the last step's springs on the last step's nodal masses (PenaltyContact::update_frequency_bound,
// from apply_penalty_forces). ε above E/Δh is already in penalty_wave_factor; this catches light
// nodes carrying a point's force (a stable EBS node whose support barely holds material, a node the
// sliver test keeps) that the CFL condition does not see. Infinite without contacts.
template <int Dim>
double Simulation<Dim>::penalty_time_step_limit(double wave_speed) const {
  if (!penalty_state_.contact) return std::numeric_limits<double>::infinity();
  return penalty_kernels::penalty_time_step_limit(penalty_state_.contact->frequency_bound_squared(), wave_speed, grid_.min_cell_size());
}

#define FRICTHERM_INSTANTIATE_PENALTY(D)                                                              \
  template void Simulation<D>::check_penalty_settings(const ContactPairSettings&, int, int) const;    \
  template void Simulation<D>::set_body_boundary(int, const std::vector<std::vector<Vec<2>>>&);       \
  template void Simulation<D>::setup_penalty();                                                       \
  template void Simulation<D>::apply_penalty_forces();                                                \
  template void Simulation<D>::move_boundary_points(double, double);                                  \
  template double Simulation<D>::penalty_wave_factor() const;                                         \
  template double Simulation<D>::penalty_time_step_limit(double) const;
FRICTHERM_INSTANTIATE_PENALTY(2)
FRICTHERM_INSTANTIATE_PENALTY(3)
#undef FRICTHERM_INSTANTIATE_PENALTY

}  // namespace frictherm::mechanics
