#pragma once
// Internal to the multimaterial contact (simulation_contact.cpp, contact_extents.cpp): one material's
// nodal quantities at a contact node, and the contact normal of a pair (Nairn, Bardenhagen & Smith
// 2018 eq. 7 and §2.3). Sign convention in contact.hpp: n̂ points from material a to material b.
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/types.hpp>

#include <algorithm>
#include <limits>
#include <vector>

namespace frictherm::mechanics {

/// One material's (or a lumped virtual material's) nodal quantities at a contact node.
template <int Dim>
struct ContactSide {
  double mass = 0.0;                  // m_{i,j}; for a rigid material only a presence weight
  Vec<Dim> momentum = Vec<Dim>::Zero();
  Vec<Dim> force = Vec<Dim>::Zero();
  Vec<Dim> mass_position = Vec<Dim>::Zero();  // Σ S m x (or m Δx)
  double domain = 0.0;                        // Ω_{i,j}
  Vec<Dim> domain_gradient = Vec<Dim>::Zero();  // g_{i,j}
  bool rigid = false;
  Vec<Dim> rigid_velocity = Vec<Dim>::Zero();
  Vec<Dim> rigid_acceleration = Vec<Dim>::Zero();
  /// Extent separation: the gap between this material's particle domains and its partners' along
  /// the normal from this material to them (m, < 0 where they overlap); NaN when not measured.
  double extent_gap = std::numeric_limits<double>::quiet_NaN();
  /// The same gap measured along the coordinate axes (the largest, contact_extent.hpp
  /// extent_axis_gap; −inf: none): the detection takes the larger of the two, the closing approach
  /// (contact_pair.hpp) the normal's.
  double extent_axis_gap = -std::numeric_limits<double>::infinity();
  /// Below ContactOptions::sliver_fraction of the node's mass: kept from interpenetrating, never
  /// given friction (a sliver's contact area ~ its overlap but its mass ~ overlap², so any area-based
  /// law would stick it and its shape-function gradient would strain its particles). A deformable
  /// sliver bonded to a non-sliver rigid partner sticks to it instead (contact_pair.hpp).
  bool sliver = false;

  void add(const ContactSide& o) {
    mass += o.mass;
    momentum += o.momentum;
    force += o.force;
    mass_position += o.mass_position;
    domain += o.domain;
    domain_gradient += o.domain_gradient;
  }
};

/// The energy books' rigid work at a contact node (docs/output.md "Energy balance"): in the
/// momentum-update pass every change a deformable material gets at a node with a rigid partner comes
/// from the rigid body, whose velocity is prescribed: it does the work Δp·v_rigid, with the heaviest
/// rigid side's velocity (the one lump_partners gives the virtual material). That side, or nullptr.
/// One function for the serial and the decomposed contact passes.
template <int Dim>
inline const ContactSide<Dim>* rigid_work_side(const std::vector<ContactSide<Dim>>& sides) {
  const ContactSide<Dim>* rigid = nullptr;
  for (const auto& sd : sides)
    if (sd.rigid && (!rigid || sd.mass > rigid->mass)) rigid = &sd;
  return rigid;
}

/// The unit normal from a to b (eq. 7 and §2.3): specified, maximum or average volume gradient.
/// False when it is undefined (no volume gradient).
template <int Dim>
bool contact_normal(const ContactSide<Dim>& a, const ContactSide<Dim>& b, const ContactPairSettings& s, Vec<Dim>& n) {
  if (s.normal == NormalMethod::specified) {
    n = s.normal_vector.template head<Dim>();
    return true;
  }
  if (s.normal == NormalMethod::max_volume_gradient) {
    const double ga = a.domain_gradient.norm(), gb = b.domain_gradient.norm();
    if (!(std::max(ga, gb) > 0.0)) return false;
    n = ga >= gb ? Vec<Dim>(a.domain_gradient / ga) : Vec<Dim>(-b.domain_gradient / gb);
    return true;
  }
  n = (a.domain * a.domain_gradient - b.domain * b.domain_gradient) / (a.domain + b.domain);
  const double len = n.norm();
  if (!(len > 0.0)) return false;
  n /= len;
  return true;
}

}  // namespace frictherm::mechanics
