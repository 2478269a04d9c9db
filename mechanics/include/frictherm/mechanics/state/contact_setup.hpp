#pragma once
// Contact settings of a Simulation<Dim>: whether contact is on, its options and the friction law of
// every material pair.
#include <frictherm/mechanics/contact.hpp>

#include <utility>
#include <vector>

namespace frictherm::mechanics {

/// enable_contact / set_contact_pair, resolved per material pair by finalize().
struct ContactSetup {
  bool enabled = false;                                // one velocity field per material
  ContactOptions options;
  std::vector<ContactPairSettings> pair_settings;      // [0] = default
  std::vector<int> pair_index;                         // materials² -> pair_settings index
  std::vector<std::pair<int, int>> explicit_pairs;     // set_contact_pair calls, in order
  bool any_multimaterial = true;                       // some present material pair uses multimaterial contact
};

}  // namespace frictherm::mechanics
