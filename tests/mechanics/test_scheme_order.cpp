// The step's order written once for both engines (step/scheme_order.hpp): what a decomposed engine
// needs of it, checked on the order itself for USF, USL and MUSL. Each exchange must sit between the
// phases that make a value on the owned nodes and the phases that read it on every rank:
//   * the projection's sums reach the owners (ExchangeHook::projected, MUSL's remapped) before any
//     contact pass or grid update reads the nodal momenta;
//   * a grid velocity reaches the ghosts (ExchangeHook::velocities) after the last phase that sets it
//     (velocity_from_momentum, nodal_velocities, the contact and penalty phases at those points) and
//     before every phase that reads it (stress_update, the particle passes, the velocity filter);
//   * USF's forces reach the owners after internal_forces and before the momentum update;
//   * migration is the last point of the step.
// A recording engine lists the points; the serial list that tests/mechanics/test_step_phases.cpp
// checks is built from the same walk.
#include <frictherm/mechanics/step/scheme_order.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

using namespace frictherm::mechanics;

namespace {

struct Recorder {
  std::vector<std::string> points;
  void operator()(SchemePhase p) {
    static const char* const names[] = {"time_step", "shape_functions", "extended_stencils", "particle_to_grid",
                                        "velocity_from_momentum", "stress_update", "internal_forces",
                                        "velocity_conditions", "momentum_update", "nodal_velocities",
                                        "particle_update", "grid_to_particle", "end_particle_update", "remap_momentum"};
    points.emplace_back(names[static_cast<int>(p)]);
  }
  void operator()(ExchangeHook h) {
    static const char* const names[] = {"x:projected", "x:forces", "x:velocities", "x:remapped", "x:migrate"};
    points.emplace_back(names[static_cast<int>(h)]);
  }
  void operator()(ContactHook h) {
    static const char* const names[] = {"c:extrapolated", "c:stress_velocity", "c:forces", "c:updated", "c:remapped"};
    points.emplace_back(names[static_cast<int>(h)]);
  }
  void operator()(FilterHook h) { points.emplace_back(h == FilterHook::start_velocity ? "f:start" : "f:velocities"); }
  void operator()(LoadHook h) { points.emplace_back(h == LoadHook::forces ? "l:forces" : "l:conditioned"); }
  void operator()(RigidHook) { points.emplace_back("r"); }
};

std::vector<std::string> order(bool usf, bool musl) {
  Recorder r;
  add_scheme_phases(usf, musl, r);
  return r.points;
}

bool is_velocity_writer(const std::string& p) {
  return p == "velocity_from_momentum" || p == "nodal_velocities" || p == "c:updated" || p == "c:remapped";
}
bool is_velocity_reader(const std::string& p) {
  return p == "stress_update" || p == "particle_update" || p == "grid_to_particle" || p == "f:velocities";
}
bool is_momentum_reader(const std::string& p) {
  return p == "c:extrapolated" || p == "c:remapped" || p == "velocity_from_momentum" || p == "momentum_update";
}

// The checks of the file's comment on one scheme's order.
void expect_exchanges_in_place(const std::vector<std::string>& points, const char* scheme) {
  SCOPED_TRACE(scheme);
  ASSERT_FALSE(points.empty());
  EXPECT_EQ(points.back(), "x:migrate");
  bool sums_owned = false, velocity_on_ghosts = false, forces_owned = true;
  int readers = 0, writers = 0;
  for (const std::string& p : points) {
    if (p == "particle_to_grid" || p == "remap_momentum") sums_owned = false;
    if (p == "x:projected" || p == "x:remapped") sums_owned = true;
    if (is_momentum_reader(p)) {
      EXPECT_TRUE(sums_owned) << p << " reads momenta not yet summed on their owners";
    }
    if (is_velocity_writer(p)) velocity_on_ghosts = false, ++writers;
    if (p == "x:velocities") velocity_on_ghosts = true;
    if (is_velocity_reader(p)) {
      ++readers;
      EXPECT_TRUE(velocity_on_ghosts) << p << " reads a grid velocity the ghosts do not have";
    }
    if (p == "internal_forces") forces_owned = false;
    if (p == "x:forces") forces_owned = true;
    if (p == "momentum_update") {
      EXPECT_TRUE(forces_owned) << "the momentum update before the forces reach their owners";
    }
  }
  EXPECT_GE(readers, 2);
  EXPECT_GE(writers, 2);
  EXPECT_EQ(std::count(points.begin(), points.end(), "x:migrate"), 1);
}

}  // namespace

TEST(SchemeOrder, ExchangesSitBetweenWhatMakesAValueAndWhatReadsIt) {
  expect_exchanges_in_place(order(true, false), "USF");
  expect_exchanges_in_place(order(false, false), "USL");
  expect_exchanges_in_place(order(false, true), "MUSL");
}

TEST(SchemeOrder, SchemesDifferWhereThePapersSay) {
  const auto count = [](const std::vector<std::string>& v, const char* p) { return std::count(v.begin(), v.end(), p); };
  const auto usf = order(true, false), usl = order(false, false), musl = order(false, true);
  // USF: the stress from the extrapolated velocities, before the grid update; the forces exchanged.
  EXPECT_EQ(count(usf, "stress_update"), 1);
  EXPECT_EQ(count(usf, "x:forces"), 1);
  EXPECT_LT(std::find(usf.begin(), usf.end(), "stress_update"), std::find(usf.begin(), usf.end(), "momentum_update"));
  // USL: one particle pass that also updates the stress; no separate stress update, no remap.
  EXPECT_EQ(count(usl, "particle_update"), 1);
  EXPECT_EQ(count(usl, "stress_update") + count(usl, "remap_momentum") + count(usl, "x:forces"), 0);
  // MUSL: grid-to-particle, then the remap, its sums, its contact pass and the stress from it.
  EXPECT_EQ(count(musl, "remap_momentum"), 1);
  EXPECT_EQ(count(musl, "x:remapped"), 1);
  EXPECT_EQ(count(musl, "c:remapped"), 1);
  EXPECT_GT(std::find(musl.begin(), musl.end(), "stress_update"), std::find(musl.begin(), musl.end(), "remap_momentum"));
  // Every scheme: one projection exchange right after the projection, one migration at the end.
  for (const auto* v : {&usf, &usl, &musl}) {
    const auto p2g = std::find(v->begin(), v->end(), "particle_to_grid");
    ASSERT_NE(p2g, v->end());
    EXPECT_EQ(*(p2g + 1), "x:projected");
  }
}
