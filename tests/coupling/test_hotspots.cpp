// Hot-spot detection, geometry and tracking across updates.
#include "thermal_test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using fc::test::fill_box;
using fc::test::kPi;

namespace {

// A 20 x 10 mm plate of 0.5 mm particles (1 mm cells, 2 per cell), thickness 2 mm, at 300 K;
// materials 0 and 1 split at x = 10 mm.
constexpr double kS = 0.5e-3, kThick = 2e-3;
const std::vector<fc::ThermalProperties> kMats{{true, 1100.0, 0.45}, {true, 1500.0, 0.14}};

fm::Particles<2> plate() {
  fm::Particles<2> p;
  auto T = [](const fm::Vec<2>&) { return 300.0; };
  fill_box<2>(p, {0.0, 0.0}, {10e-3, 10e-3}, 1e-3, 2, 1900.0, 0, T, kThick);
  fill_box<2>(p, {10e-3, 0.0}, {20e-3, 10e-3}, 1e-3, 2, 1190.0, 1, T, kThick);
  return p;
}

// Sets T on the particles whose centre lies in [lo, hi]; returns how many.
int heat(fm::Particles<2>& p, const fm::Vec<2>& lo, const fm::Vec<2>& hi, double T) {
  int n = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const fm::Vec<2>& x = p.position[k];
    if (x[0] >= lo[0] && x[0] <= hi[0] && x[1] >= lo[1] && x[1] <= hi[1]) {
      p.temperature[k] = T;
      ++n;
    }
  }
  return n;
}

std::size_t particle_at(const fm::Particles<2>& p, const fm::Vec<2>& x) {
  for (std::size_t k = 0; k < p.size(); ++k)
    if ((p.position[k] - x).norm() < 1e-9) return k;
  ADD_FAILURE() << "no particle at " << x.transpose();
  return 0;
}

}  // namespace

TEST(HotSpots, TwoSeparatedClustersWithSizesCentroidsPeaks) {
  auto p = plate();
  fc::HotSpotOptions opt;
  opt.mode = fc::HotSpotOptions::Mode::absolute;
  opt.threshold = 400.0;
  fc::HotSpotTracker tr(2, opt, kThick);
  tr.set_reference(p);
  // A: 3 x 3 particles centred on (3.25, 4.25) mm at 500 K with a 900 K centre; B: 2 x 4 particles
  // straddling the material boundary at x = 10 mm, 600 K.
  ASSERT_EQ(heat(p, {2.7e-3, 3.7e-3}, {3.8e-3, 4.8e-3}, 500.0), 9);
  p.temperature[particle_at(p, {3.25e-3, 4.25e-3})] = 900.0;
  ASSERT_EQ(heat(p, {9.7e-3, 6.2e-3}, {10.3e-3, 7.8e-3}, 600.0), 8);
  tr.update(p, kMats, 1e-6);
  ASSERT_EQ(tr.hot_spots().size(), 2u);
  const fc::HotSpot& a = tr.hot_spots()[0];
  const fc::HotSpot& b = tr.hot_spots()[1];
  EXPECT_EQ(a.particle_count, 9u);
  EXPECT_NEAR(a.size, 9 * kS * kS, 1e-18);  // area: volumes over the thickness
  EXPECT_NEAR(a.equivalent_diameter, 2.0 * std::sqrt(9 * kS * kS / kPi), 1e-15);
  EXPECT_NEAR(a.centroid[0], 3.25e-3, 1e-15);
  EXPECT_NEAR(a.centroid[1], 4.25e-3, 1e-15);
  EXPECT_EQ(a.peak_temperature, 900.0);
  EXPECT_NEAR(a.mean_temperature, (8 * 500.0 + 900.0) / 9.0, 1e-12);
  EXPECT_EQ(a.materials, std::vector<int>{0});
  // Excess energy Σ m C (T − T0): 8 particles +200 K and one +600 K of material 0.
  const double mc = 1900.0 * kS * kS * kThick * 1100.0;
  EXPECT_NEAR(a.excess_energy, mc * (8 * 200.0 + 600.0), 1e-12 * mc * 2200.0);
  EXPECT_EQ(b.particle_count, 8u);
  EXPECT_NEAR(b.centroid[0], 10e-3, 1e-15);
  EXPECT_NEAR(b.centroid[1], 7e-3, 1e-15);
  EXPECT_EQ(b.materials, (std::vector<int>{0, 1}));
  EXPECT_EQ(tr.hottest(), &a);
  EXPECT_EQ(tr.max_temperature(), 900.0);
  EXPECT_NE(a.id, b.id);
  EXPECT_EQ(a.birth_time, 1e-6);
  EXPECT_EQ(a.duration, 0.0);
}

TEST(HotSpots, DiagonalNeighboursLinkButAGapOfOneParticleSeparates) {
  auto p = plate();
  fc::HotSpotOptions opt;
  opt.mode = fc::HotSpotOptions::Mode::absolute;
  opt.threshold = 400.0;
  fc::HotSpotTracker tr(2, opt, kThick);
  // A diagonal chain (distance √2 spacings < link_factor): one hot spot.
  for (int i = 0; i < 5; ++i) p.temperature[particle_at(p, {(2.25 + 0.5 * i) * 1e-3, (2.25 + 0.5 * i) * 1e-3})] = 500.0;
  tr.update(p, kMats, 0.0);
  EXPECT_EQ(tr.hot_spots().size(), 1u);
  // Two particles two spacings apart: separate.
  auto q = plate();
  q.temperature[particle_at(q, {5.25e-3, 5.25e-3})] = 500.0;
  q.temperature[particle_at(q, {6.25e-3, 5.25e-3})] = 500.0;
  tr.update(q, kMats, 1.0);
  EXPECT_EQ(tr.hot_spots().size(), 2u);
}

TEST(HotSpots, IdsPersistAcrossUpdatesWithBirthAndDuration) {
  auto p = plate();
  fc::HotSpotOptions opt;
  opt.mode = fc::HotSpotOptions::Mode::absolute;
  opt.threshold = 400.0;
  fc::HotSpotTracker tr(2, opt, kThick);
  heat(p, {2.0e-3, 2.0e-3}, {3.0e-3, 3.0e-3}, 500.0);    // A: 2 x 2
  heat(p, {15.0e-3, 5.0e-3}, {16.0e-3, 6.0e-3}, 500.0);  // B: 2 x 2
  tr.update(p, kMats, 1.0);
  ASSERT_EQ(tr.hot_spots().size(), 2u);
  const long idA = tr.hot_spots()[0].id, idB = tr.hot_spots()[1].id;
  // t = 2: A grows to the right (shares particles), B cools away, C appears.
  heat(p, {3.0e-3, 2.0e-3}, {4.0e-3, 3.0e-3}, 500.0);
  heat(p, {15.0e-3, 5.0e-3}, {16.0e-3, 6.0e-3}, 300.0);
  heat(p, {6.0e-3, 8.0e-3}, {6.5e-3, 8.5e-3}, 700.0);
  tr.update(p, kMats, 2.0);
  ASSERT_EQ(tr.hot_spots().size(), 2u);
  const fc::HotSpot& a = tr.hot_spots()[0];
  const fc::HotSpot& c = tr.hot_spots()[1];
  EXPECT_EQ(a.id, idA);
  EXPECT_EQ(a.particle_count, 8u);
  EXPECT_EQ(a.birth_time, 1.0);
  EXPECT_EQ(a.duration, 1.0);
  EXPECT_NE(c.id, idA);
  EXPECT_NE(c.id, idB);  // a dead id is never reused
  EXPECT_EQ(c.birth_time, 2.0);
  EXPECT_EQ(c.duration, 0.0);
  EXPECT_EQ(tr.ids_issued(), 3);
  // t = 3: A splits in two (its middle column cools): the larger part keeps the id and the birth
  // time, the other is new.
  const long idC = c.id;
  heat(p, {3.2e-3, 2.0e-3}, {3.3e-3, 3.0e-3}, 300.0);  // the x = 3.25 mm column: 4 + 2 particles left
  tr.update(p, kMats, 3.0);
  long kept = 0, fresh = 0;
  for (const fc::HotSpot& h : tr.hot_spots()) {
    if (h.id == idA) {
      ++kept;
      EXPECT_EQ(h.particle_count, 4u);
      EXPECT_EQ(h.birth_time, 1.0);
      EXPECT_EQ(h.duration, 2.0);
    } else if (h.id != idC) {
      EXPECT_EQ(h.particle_count, 2u);
      ++fresh;
      EXPECT_EQ(h.birth_time, 3.0);
    }
  }
  EXPECT_EQ(kept, 1);
  EXPECT_EQ(fresh, 1);
}

TEST(HotSpots, RiseModeMeasuresFromEachParticlesInitialTemperature) {
  auto p = plate();
  // Material 1 starts 150 K hotter: in absolute mode (threshold 400) it is not hot, in rise mode
  // (threshold 50) neither; heating a patch of each by 60 K makes both hot in rise mode only.
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == 1) p.temperature[k] = 450.0 - 100.0;  // 350 K
  fc::HotSpotOptions rise;
  rise.mode = fc::HotSpotOptions::Mode::rise;
  rise.threshold = 50.0;
  fc::HotSpotOptions absolute;
  absolute.mode = fc::HotSpotOptions::Mode::absolute;
  absolute.threshold = 380.0;
  fc::HotSpotTracker tr_rise(2, rise, kThick), tr_abs(2, absolute, kThick);
  tr_rise.set_reference(p);
  tr_abs.set_reference(p);
  tr_rise.update(p, kMats, 0.0);
  tr_abs.update(p, kMats, 0.0);
  EXPECT_EQ(tr_rise.hot_spots().size(), 0u);
  EXPECT_EQ(tr_abs.hot_spots().size(), 0u);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const fm::Vec<2>& x = p.position[k];
    if (x[1] < 1e-3 && (x[0] < 1e-3 || (x[0] > 12e-3 && x[0] < 13e-3))) p.temperature[k] += 60.0;
  }
  tr_rise.update(p, kMats, 1.0);
  tr_abs.update(p, kMats, 1.0);
  EXPECT_EQ(tr_rise.hot_spots().size(), 2u);  // 300 -> 360 and 350 -> 410: both rose by 60 K
  ASSERT_EQ(tr_abs.hot_spots().size(), 1u);   // only 410 K > 380 K
  EXPECT_EQ(tr_abs.hot_spots()[0].materials, std::vector<int>{1});
}

// The cell list finds the same clusters as the all-pairs definition on a random field.
TEST(HotSpots, CellListMatchesAllPairsClustering) {
  auto p = plate();
  unsigned seed = 12345;
  auto rnd = [&] {
    seed = seed * 1103515245u + 12345u;
    return static_cast<double>((seed >> 8) & 0xffff) / 65536.0;
  };
  for (double& T : p.temperature) T = rnd() < 0.3 ? 500.0 : 300.0;
  fc::HotSpotOptions opt;
  opt.mode = fc::HotSpotOptions::Mode::absolute;
  opt.threshold = 400.0;
  fc::HotSpotTracker tr(2, opt, kThick);
  tr.update(p, kMats, 0.0);
  // Reference: O(N²) flood fill with the same link distance (1.5 spacings).
  std::vector<std::size_t> hot;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.temperature[k] > 400.0) hot.push_back(k);
  std::vector<int> label(hot.size(), -1);
  int clusters = 0;
  for (std::size_t s = 0; s < hot.size(); ++s) {
    if (label[s] >= 0) continue;
    std::vector<std::size_t> stack{s};
    label[s] = clusters;
    while (!stack.empty()) {
      const std::size_t a = stack.back();
      stack.pop_back();
      for (std::size_t b = 0; b < hot.size(); ++b)
        if (label[b] < 0 && (p.position[hot[a]] - p.position[hot[b]]).norm() <= 1.5 * kS) {
          label[b] = clusters;
          stack.push_back(b);
        }
    }
    ++clusters;
  }
  EXPECT_EQ(static_cast<int>(tr.hot_spots().size()), clusters);
  std::size_t total = 0;
  for (const fc::HotSpot& h : tr.hot_spots()) total += h.particle_count;
  EXPECT_EQ(total, hot.size());
}

// Issue 14 item 8: in 3D the corner-diagonal neighbour is √3 = 1.73 spacings away; the default
// link_factor must join it, and a one-particle gap (2 spacings) must still separate.
TEST(HotSpots, CornerDiagonalNeighboursLinkIn3D) {
  fm::Particles<3> p;
  auto T = [](const fm::Vec<3>&) { return 300.0; };
  fill_box<3>(p, {0.0, 0.0, 0.0}, {4e-3, 4e-3, 4e-3}, 1e-3, 2, 1900.0, 0, T);
  auto at = [&](const fm::Vec<3>& x) {
    for (std::size_t k = 0; k < p.size(); ++k)
      if ((p.position[k] - x).norm() < 1e-9) return k;
    ADD_FAILURE() << "no particle at " << x.transpose();
    return std::size_t{0};
  };
  fc::HotSpotOptions opt;
  opt.mode = fc::HotSpotOptions::Mode::absolute;
  opt.threshold = 400.0;
  opt.min_particles = 1;
  fc::HotSpotTracker tr(3, opt, 1.0);
  // A body-diagonal chain of 4 particles, each √3 spacings from the next: one hot spot of 4.
  for (int i = 0; i < 4; ++i) p.temperature[at(fm::Vec<3>::Constant((1.25 + 0.5 * i) * 1e-3))] = 500.0;
  tr.update(p, {{true, 1100.0, 0.45}}, 0.0);
  ASSERT_EQ(tr.hot_spots().size(), 1u);
  EXPECT_EQ(tr.hot_spots()[0].particles.size(), 4u);
  // Two particles two spacings apart along x: separate.
  for (auto& t : p.temperature) t = 300.0;
  p.temperature[at({1.25e-3, 1.25e-3, 1.25e-3})] = 500.0;
  p.temperature[at({2.25e-3, 1.25e-3, 1.25e-3})] = 500.0;
  tr.update(p, {{true, 1100.0, 0.45}}, 1.0);
  EXPECT_EQ(tr.hot_spots().size(), 2u);
}
