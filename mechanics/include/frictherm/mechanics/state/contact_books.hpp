#pragma once
// The contact resolution's books (Simulation<Dim>): the last step's frictional work per grid node,
// the cumulative work per material pair and the last step's counters.
#include <vector>

namespace frictherm::mechanics {

/// Counters of the last step's contact resolution.
struct ContactStats {
  long contact_nodes = 0;     // nodes with two or more materials
  long multi_nodes = 0;       // of which with three or more (lumped virtual material, eqs. 39–40)
  long sliding_nodes = 0;     // node-pairs sliding in the momentum-update pass
  long guarded = 0;           // materials left out because their mass fraction was below min_mass_fraction
  long penalty_contacts = 0;  // penalty contact: active slave point – master segment contacts
  long penalty_sliding = 0;   // of which sliding
};

/// Frictional work (J) of the first- and second-order heating (eqs. 27, 34, 36, 40) and the counters.
struct ContactBooks {
  std::vector<double> work_first, work_second;            // per grid node, last step
  std::vector<double> pair_work_first, pair_work_second;  // materials², cumulative
  ContactStats stats;                                     // last step
};

}  // namespace frictherm::mechanics
