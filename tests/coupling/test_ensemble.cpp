// Ensembles (coupling/src/run/ensemble.cpp): members run with their seed, the aggregate agrees with the
// members' own files, and the summary statistics follow from the per-hot-spot rows.
#include <frictherm/coupling/results.hpp>
#include <frictherm/coupling/ensemble.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace frictherm::coupling;

namespace {

const std::string kScene = std::string(FRICTHERM_SOURCE_DIR) + "/examples/sliding_block_heating.json";

EnsembleOptions options(const fs::path& dir) {
  EnsembleOptions o;
  // A harmless integer key stands in for a microstructure seed: the machinery is what is tested.
  o.seed_key = "output.snapshot_count";
  o.first_seed = 2;
  o.members = 2;
  o.output = (dir / "ens.h5").string();
  o.threads = 1;
  o.quiet = true;
  // Shorter loading and continuation keep the test fast; hot spots form at about 10.4 ms.
  o.overrides = {{"coupling.continuation.duration", "0.002"}};
  return o;
}

}  // namespace

TEST(Ensemble, AggregateMatchesMemberFiles) {
  // Per process: two test runs at once (two build folders) must not share it.
  const fs::path dir = fs::temp_directory_path() / ("frictherm_test_ensemble_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  EnsembleOptions o = options(dir);
  // Two "processes" run their shares; together they are the whole ensemble.
  std::vector<MemberRecord> all;
  for (int rank = 0; rank < 2; ++rank) {
    EnsembleOptions part = o;
    part.rank = rank, part.ranks = 2;
    const auto mine = run_members(kScene, part);
    ASSERT_EQ(mine.size(), 1u);
    EXPECT_EQ(mine[0].seed, o.first_seed + rank);
    EXPECT_EQ(mine[0].status, 0) << mine[0].message;
    EXPECT_TRUE(fs::exists(mine[0].file));
    all.insert(all.end(), mine.begin(), mine.end());
  }
  const EnsembleSummary s = aggregate_members(kScene, o, all);
  EXPECT_EQ(s.members, 2);
  EXPECT_EQ(s.completed, 2);

  // Every hot spot id of every member's /hotspots table appears once, with its highest peak.
  long expected = 0;
  for (const MemberRecord& r : all) {
    const SeriesTable t = read_table(r.file, "hotspots");
    ASSERT_GT(t.rows(), 0u) << "the sliding block must form hot spots";
    const auto& id = t.columns[1];
    const auto& peak = t.columns[3];
    ASSERT_EQ(t.names[1], "id");
    ASSERT_EQ(t.names[3], "peak_temperature");
    std::set<long> ids(id.begin(), id.end());
    expected += static_cast<long>(ids.size());
    for (const long k : ids) {
      double max_peak = 0.0;
      for (std::size_t row = 0; row < t.rows(); ++row)
        if (std::lround(id[row]) == k) max_peak = std::max(max_peak, peak[row]);
      const auto it = std::find_if(s.hotspots.begin(), s.hotspots.end(),
                                   [&](const EnsembleHotSpot& h) { return h.seed == r.seed && h.id == k; });
      ASSERT_NE(it, s.hotspots.end());
      EXPECT_EQ(it->peak_temperature, max_peak);
      EXPECT_GE(it->duration, 0.0);
    }
  }
  EXPECT_EQ(s.hotspots_total, expected);
  long runaway = 0, dying = 0;
  for (const auto& h : s.hotspots) runaway += h.fate == 2, dying += h.fate == 1;
  EXPECT_EQ(s.runaway, runaway);
  EXPECT_EQ(s.dying, dying);
  EXPECT_GT(runaway + dying, 0) << "the continuation decides the fate of the spots alive at the end of loading";
  // Inert material: nothing can run away, and the conduction-only continuation cools every spot.
  EXPECT_EQ(s.runaway, 0);
  EXPECT_DOUBLE_EQ(s.critical_fraction, 0.0);
  EXPECT_DOUBLE_EQ(s.hotspots_per_member_mean, static_cast<double>(expected) / 2.0);

  // The aggregate file holds the same rows.
  const SeriesTable members = read_table(o.output, "members"), spots = read_table(o.output, "hotspots");
  EXPECT_EQ(members.rows(), 2u);
  EXPECT_EQ(spots.rows(), static_cast<std::size_t>(expected));
  fs::remove_all(dir);
}

TEST(Ensemble, RejectsBadOptions) {
  EnsembleOptions o;
  o.output = "x.h5";
  EXPECT_THROW(validate(o), std::invalid_argument);  // no seed key
  o.seed_key = "bodies[0].shape.seed";
  o.members = 0;
  EXPECT_THROW(validate(o), std::invalid_argument);
  o.members = 3;
  EXPECT_NO_THROW(validate(o));
  EXPECT_EQ(member_file(o, 7), "x_seed7.h5");
  o.member_prefix = "runs/m";
  EXPECT_EQ(member_file(o, 7), "runs/m7.h5");
}
