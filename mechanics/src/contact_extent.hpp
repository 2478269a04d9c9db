#pragma once
// Extent separation's kernels (docs/contact.md, "Contact detection"), shared by the serial step
// (contact_extents.cpp, simulation_contact.cpp) and the decomposed step (distributed/contact_extents.cpp):
// the normal of each side of a contact node, one particle's domain measured along those normals, and
// the gap the detection reads. Both steps gather the node's sides and store the maxima in their own
// storage; the decomposed one completes the maxima at the owners (a maximum: the same on any number
// of ranks). Internal header.
#include "contact_pair.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace frictherm::mechanics::contact_detail {

/// The normal from each side of a contact node to its partners, as resolve_contact_node will compute
/// it (Nairn, Bardenhagen & Smith 2018 eq. 7): two sides, the pair's normal; more, each against its
/// partners lumped into a virtual material (§2.12). out(j, n̂) for each side j that has one.
template <int Dim, class PairOf, class Out>
void side_normals(const std::vector<ContactSide<Dim>>& sides, const std::vector<int>& mats, const PairOf& pair_of,
                  Out&& out) {
  const std::size_t count = sides.size();
  if (count < 2) return;
  for (std::size_t a = 0; a < count; ++a) {
    Vec<Dim> n;
    bool ok;
    if (count == 2) {
      const std::size_t b = 1 - a;
      ok = contact_normal(sides[a], sides[b], pair_of(mats[a], mats[b]), n);
    } else {
      ContactSide<Dim> rest;
      const std::size_t dominant = lump_partners(sides, mats, a, rest, pair_of);
      ok = dominant < count && contact_normal(sides[a], rest, pair_of(mats[a], mats[dominant]), n);
    }
    if (ok) out(a, n);
  }
}

/// No particle measured yet (the start of every maximum).
inline constexpr double kNoExtent = -std::numeric_limits<double>::infinity();

/// The directions each side's extents are measured along: its normal n̂, then each axis d with
/// n̂_d ≠ 0, signed as n̂_d (towards the partners). Per side, own and other hold one maximum per
/// direction, in this order.
template <int Dim>
inline constexpr int kExtentDirections = 1 + Dim;

/// One particle (centre x, half-sizes l, of velocity field `field`) that gives a contact node a
/// weight, against the node's `count` entries (entry j of field field_of(j), normal normal[j]; a zero
/// normal is skipped): along each direction e of kExtentDirections (n̂, then the signed axes) with
/// r = Σ_d l_d |e_d| its half-extent along e, own[j][e] = max(own[j][e], x·e + r) for its own field,
/// other[j][e] = max(other[j][e], r − x·e) for the others.
template <int Dim, class FieldOf>
void add_particle_extent(const Vec<Dim>& x, const Vec<Dim>& l, int field, int count, const FieldOf& field_of,
                         const Vec<Dim>* normal, double* own, double* other) {
  constexpr int S = kExtentDirections<Dim>;
  for (int j = 0; j < count; ++j) {
    const Vec<Dim>& n = normal[j];
    if (n.squaredNorm() == 0.0) continue;  // a sliver, or no normal
    // own: x·e + r; the partners': r − x·e (the sign of the centre flips)
    const bool mine = field_of(j) == field;
    const double sign = mine ? 1.0 : -1.0;
    double* m = (mine ? own : other) + S * j;
    m[0] = std::max(m[0], sign * x.dot(n) + l.cwiseProduct(n).cwiseAbs().sum());
    for (int d = 0; d < Dim; ++d)
      if (n[d] != 0.0) m[1 + d] = std::max(m[1 + d], sign * (n[d] > 0.0 ? x[d] : -x[d]) + l[d]);
  }
}

/// The gap between a side's surface and its partners' along its normal, −(own + other) (< 0 where
/// they overlap), or NaN when either was not measured (ContactSide::extent_gap). own, other: one
/// side's kExtentDirections maxima.
template <int Dim>
inline double extent_gap(const double* own, const double* other) {
  return std::isfinite(own[0]) && std::isfinite(other[0]) ? -(own[0] + other[0])
                                                          : std::numeric_limits<double>::quiet_NaN();
}

/// The largest gap along the signed axes, −(own + other) on each measured one (−inf: none): domains
/// an axis separates are apart however the normal leans (disjoint projections, disjoint sets). At a
/// body's corner facing another's across an open gap the normal leans ~45° and the projections on
/// it overlap, so the normal's gap alone called the bodies touching there (a frictionless bar impact
/// across a gap of half a cell started at once, and lost twice the energy: docs/contact.md,
/// "Contact detection"). ContactSide::extent_axis_gap.
template <int Dim>
inline double extent_axis_gap(const double* own, const double* other) {
  double gap = -std::numeric_limits<double>::infinity();
  for (int e = 1; e < kExtentDirections<Dim>; ++e)
    if (std::isfinite(own[e]) && std::isfinite(other[e])) gap = std::max(gap, -(own[e] + other[e]));
  return gap;
}

/// A side's two gaps (ContactSide::extent_gap, extent_axis_gap) from entry q's maxima in the
/// per-entry arrays own and other (kExtentDirections values each), as both steps store them.
template <int Dim, class Side>
inline void set_extent_gaps(Side& side, const double* own, const double* other, std::size_t q) {
  own += kExtentDirections<Dim> * q, other += kExtentDirections<Dim> * q;
  side.extent_gap = extent_gap<Dim>(own, other);
  side.extent_axis_gap = extent_axis_gap<Dim>(own, other);
}

}  // namespace frictherm::mechanics::contact_detail
