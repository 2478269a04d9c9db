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

/// One particle (centre x, half-sizes l, of velocity field `field`) that gives a contact node a
/// weight, against the node's `count` entries (entry j of field field_of(j), normal normal[j]; a zero
/// normal is skipped): with r = Σ_d l_d |n̂_d| its half-extent along n̂,
/// own[j] = max(own[j], x·n̂ + r) for its own field, other[j] = max(other[j], r − x·n̂) for the others.
template <int Dim, class FieldOf>
void add_particle_extent(const Vec<Dim>& x, const Vec<Dim>& l, int field, int count, const FieldOf& field_of,
                         const Vec<Dim>* normal, double* own, double* other) {
  for (int j = 0; j < count; ++j) {
    const Vec<Dim>& n = normal[j];
    if (n.squaredNorm() == 0.0) continue;  // a sliver, or no normal
    const double centre = x.dot(n), half = l.cwiseProduct(n).cwiseAbs().sum();
    if (field_of(j) == field)
      own[j] = std::max(own[j], centre + half);
    else
      other[j] = std::max(other[j], half - centre);
  }
}

/// The gap between a side's surface and its partners' along its normal, −(own + other) (< 0 where
/// they overlap), or NaN when either was not measured (ContactSide::extent_gap).
inline double extent_gap(double own, double other) {
  return std::isfinite(own) && std::isfinite(other) ? -(own + other) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace frictherm::mechanics::contact_detail
