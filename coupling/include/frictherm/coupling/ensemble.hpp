#pragma once
// Ensembles: one scene run over many random seeds (e.g. microstructures), the members' hot spots
// aggregated into one HDF5 file (issue 5, design §6).
//
//   EnsembleOptions o;  o.seed_key = "bodies[1].shape.seed";  o.members = 16;  o.output = "ens.h5";
//   auto mine = run_members("pbx.json", o);            // this process's share (o.rank of o.ranks)
//   EnsembleSummary s = aggregate_members(o, all);     // once, after every member has finished
//
// Member k (k = 0 .. members − 1) is the scene with `seed_key` set to first_seed + k, written to
// member_file(o, seed). Processes split the members round-robin (k % ranks == rank), so the same
// command runs serially or under `mpirun -n K` (the program does the MPI part; this library has
// none). A member that fails is recorded and the others go on.
//
// The aggregate file holds, as column groups readable like /series (a `columns` attribute and one
// 1-D dataset per column):
//   /members   seed, status (0 completed, 1 stopped at max_steps, 2 failed), steps, simulated_time,
//              wall_time, hotspots, max_peak_temperature, runaway, dying
//   /hotspots  seed, id, peak_temperature (highest over the run), equivalent_diameter and size (when
//              the peak was reached), birth_time, duration (last seen − birth), fate (the codes of
//              /hotspot_fates: 0 undecided or not followed, 1 dying, 2 runaway), time_to_runaway
//              (s after the end of loading; NaN if none)
//   /member_files  the member HDF5 files (strings), in /members row order
// and root attributes format = "frictherm-ensemble", format_version = 2, members, completed,
// hotspots_total, hotspots_per_member_mean/std, critical_fraction (runaway / hot spots with a known
// fate; NaN when none is known), members_with_runaway, seed_key, scene. Seeds, ids, counts, status
// and fate columns and the count attributes are int64 (H5Output::is_count_column), the rest double.
#include <frictherm/coupling/hotspot_fates.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

struct EnsembleOptions {
  std::string seed_key;        // scene key path set to each member's seed (an integer)
  long first_seed = 1;
  int members = 1;
  std::string output;          // the aggregate HDF5 file
  std::string member_prefix;   // member files are <member_prefix><seed>.h5; empty: <output without .h5>_seed
  std::vector<SceneOverride> overrides;  // applied to every member before the seed
  int threads = 0;             // OpenMP threads per member (0: the scene's, else OpenMP's default)
  bool quiet = false;
  bool overwrite = false;      // replace existing member and aggregate files (RunOptions::overwrite)
  int rank = 0, ranks = 1;     // this process's share
};

struct MemberRecord {
  long seed = 0;
  std::string file;
  int status = 2;            // 0 completed, 1 stopped at max_steps, 2 failed
  long steps = 0;
  double simulated_time = 0.0, wall_time = 0.0;
  std::string message;       // why it failed
};

/// One hot spot of one member, as aggregated.
struct EnsembleHotSpot {
  long seed = 0, id = 0;
  double peak_temperature = 0.0, equivalent_diameter = 0.0, size = 0.0;
  double birth_time = 0.0, duration = 0.0;
  int fate = 0;                   // HotSpotFate codes: 0 undecided / not followed, 1 dying, 2 runaway
  double time_to_runaway = 0.0;   // NaN when it did not run away
};

struct EnsembleSummary {
  int members = 0, completed = 0;
  long hotspots_total = 0, runaway = 0, dying = 0;
  double hotspots_per_member_mean = 0.0, hotspots_per_member_std = 0.0;
  double critical_fraction = 0.0;     // runaway / (runaway + dying); 0 when no fate is known
  int members_with_runaway = 0;
  std::vector<EnsembleHotSpot> hotspots;
};

/// Checks the options (throws std::invalid_argument naming the option).
void validate(const EnsembleOptions& o);
std::string member_file(const EnsembleOptions& o, long seed);
/// Runs the members of this process (k % ranks == rank), in order; returns their records.
std::vector<MemberRecord> run_members(const std::string& scene_path, const EnsembleOptions& o);
/// The hot spots of one member file (from its /hotspots table, and /hotspot_fates when present).
std::vector<EnsembleHotSpot> read_member_hotspots(const std::string& file, long seed);
/// Reads every member file of `records` that exists and writes o.output. Throws std::runtime_error
/// naming the file on an HDF5 failure.
EnsembleSummary aggregate_members(const std::string& scene_path, const EnsembleOptions& o,
                                  const std::vector<MemberRecord>& records);

}  // namespace frictherm::coupling
