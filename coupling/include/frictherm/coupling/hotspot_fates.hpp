#pragma once
// The fate of each hot spot in the thermal-only continuation (design §4, issue 5): does it die by
// conduction or run away?
//
// The hot spots alive when the continuation starts (the end of loading) are followed by their own
// particles (the set they had then; ids may later merge or split, the particles do not). After every
// continuation interval, over those particles:
//
// * runaway: the largest reaction progress reaches `runaway_progress` (default 0.5: half the
//   explosive at the hottest point has reacted, far past the induction time — see docs/coupling.md),
//   or the peak temperature reaches `runaway_temperature` (optional). The runaway time is the end of
//   the interval in which this is first seen (so it is late by less than one interval).
// * dying: no particle of the set is hot any more (the tracker's threshold and mode): conduction
//   has taken the spot below the threshold. Decided at the end of that interval.
// * At the end of the continuation an undecided spot whose peak temperature is below its starting
//   peak and fell over the last interval is also `dying`; otherwise it stays `undecided`.
//
// A decided fate never changes.
#include <frictherm/coupling/hotspots.hpp>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace frictherm::coupling {

struct HotSpotFateOptions {
  double runaway_progress = 0.5;                                        // in (0, 1]
  double runaway_temperature = std::numeric_limits<double>::infinity();  // K
};

enum class HotSpotFate { undecided = 0, dying = 1, runaway = 2 };
const char* to_string(HotSpotFate fate);

struct HotSpotFateRecord {
  long id = 0;                              // the hot spot's id at the start of the continuation
  std::vector<std::size_t> particles;       // its particles then
  double start_time = 0.0;                  // s, start of the continuation
  double initial_peak_temperature = 0.0;    // K
  double peak_temperature = 0.0;            // K, now (over its particles)
  double max_peak_temperature = 0.0;        // K, highest seen
  double max_progress = 0.0;                // largest reaction progress among its particles, now
  double previous_peak_temperature = 0.0;   // K, at the previous update
  HotSpotFate fate = HotSpotFate::undecided;
  double decision_time = std::numeric_limits<double>::quiet_NaN();  // s: runaway or cooled below threshold
  double runaway_time = std::numeric_limits<double>::quiet_NaN();   // s (absolute)
};

/// What one update reads of a followed spot over some of its particles: the largest temperature and
/// progress and whether any is hot. Maxima and "any": a decomposed run measures on each rank and
/// reduces the measures over ranks (MPI_MAX) before the one verdict (HotSpotFates::decide).
struct HotSpotFateMeasure {
  double peak_temperature = 0.0;  // K
  double progress = 0.0;
  bool hot = false;
  void add(double temperature, double lam, bool is_hot) {
    peak_temperature = std::max(peak_temperature, temperature);
    progress = std::max(progress, lam);
    hot = hot || is_hot;
  }
};

/// The /hotspot_fates table (docs/output.md): its columns and one record's row.
std::vector<std::string> hotspot_fate_columns();
std::vector<double> hotspot_fate_row(const HotSpotFateRecord& record);

class HotSpotFates {
 public:
  explicit HotSpotFates(HotSpotFateOptions options = {});

  /// Starts following the hot spots of `tracker`'s last update at `time`.
  void begin(const HotSpotTracker& tracker, double time);
  bool started() const { return started_; }
  /// After a continuation interval ending at `time`. `progress` is the particles' reaction progress
  /// (empty without a reaction). `criterion`, when given, replaces T_p as each particle's temperature
  /// (the interface temperature); `criterion_progress`, when given, is a second progress (the one at
  /// that temperature, interface_reaction.hpp) and the larger of the two decides.
  template <int Dim>
  void update(const mechanics::Particles<Dim>& particles, const std::vector<double>& progress,
              const HotSpotTracker& tracker, double time, const std::vector<double>* criterion = nullptr,
              const std::vector<double>* criterion_progress = nullptr);
  /// The verdict of one update from each record's measure (records() order) at `time`: what update()
  /// does after measuring; a decomposed run calls it with the measures reduced over ranks.
  void decide(const std::vector<HotSpotFateMeasure>& measures, double time);
  /// End of the continuation: the falling-and-below-start rule for undecided spots.
  void finish();
  /// Every followed spot has a fate (true with no spot).
  bool all_decided() const;

  const std::vector<HotSpotFateRecord>& records() const { return records_; }
  const HotSpotFateOptions& options() const { return opt_; }

 private:
  HotSpotFateOptions opt_;
  std::vector<HotSpotFateRecord> records_;
  bool started_ = false;
  double last_time_ = 0.0;  // of the last update
};

}  // namespace frictherm::coupling
