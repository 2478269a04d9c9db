#pragma once
// Private: the checks of a checkpoint's arrays against the simulation built from the scene, before
// any state is restored (checkpoint_checks.cpp; read_checkpoint in checkpoint.cpp; issue 34).
#include <hdf5.h>

#include <string>
#include <utility>
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

// What a decomposed run's rank file must fit (decomposed_checkpoint.hpp): the decomposition built
// from the scene. Its particles' count is the file's own (/mechanics/id), its owned nodes the range
// it stores (/mechanics/owned_nodes, inside the DMDA's `nodes` per direction).
struct RankSizes {
  long particles, materials;              // all ranks' particles (ids below it), the scene's materials
  std::vector<long> nodes;                // DMDA nodes per direction (Grid::nodes_per_dim)
  long ghosted_nodes;                     // this rank's ghosted box (/gather/local_M), -1: another decomposition
  std::vector<std::pair<std::string, long>> fields;  // every real swarm field ("coor", ...), values per particle
  bool heat;                              // the heat's state (/window/..., /gather/..., /books/...)
  std::vector<bool> rigid;                // per material: its particles' wave speed is -inf
  std::vector<double> lo, hi, cell, max_half;  // as SceneSizes
};

/// The checks of check_arrays (the same functions) applied to rank file `f` of a decomposed
/// checkpoint: every swarm field (stored flat) `components` values per item of /mechanics/id, ids, materials and node ranges in
/// range, positions inside the grid, half sizes within the cell, per-node arrays as many as its owned
/// nodes, counters >= 0, the values the next step reads finite. Throws std::runtime_error naming the
/// file and the dataset.
void check_rank_file(hid_t f, const std::string& path, const RankSizes& z);

/// A decomposed run's global file: counters >= 0, the steps of the last row and snapshot up to
/// /run/step, /marks/step = /run/step, whole series rows. Throws std::runtime_error naming the dataset.
void check_global_file(hid_t f, const std::string& path);

}  // namespace frictherm::coupling::ckpt
