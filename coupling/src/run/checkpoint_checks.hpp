#pragma once
// Private: the checks of a checkpoint's arrays against the simulation built from the scene, before
// any state is restored (checkpoint_checks.cpp; read_checkpoint in checkpoint.cpp; issue 34).
#include <hdf5.h>

#include <string>
#include <vector>

namespace frictherm::coupling::ckpt {

// What the checkpoint's arrays must fit: the simulation built from the scene.
struct SceneSizes {
  long particles, nodes, materials, bodies, boundary_points, penalty_pairs;
  bool contact;
  long series_pairs;         // contact pairs with a contact_heat_rate column (1 + this: /run/series_memory/work)
  std::vector<bool> rigid;   // per material: its particles' wave speed is -inf
  std::vector<double> lo, hi, cell;  // the grid's box and cell size per direction
  std::vector<double> max_half;      // the largest half size per direction: h/2, or a built particle's
};

/// Throws std::runtime_error naming the file and the dataset when an array does not fit `z` (size,
/// index range, sign, finiteness, inside the grid); the Reader then checks shapes, types and every
/// double as it restores them.
void check_arrays(hid_t f, const std::string& path, const SceneSizes& z);

}  // namespace frictherm::coupling::ckpt
