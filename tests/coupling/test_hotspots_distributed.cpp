// Hot spots across rank boundaries (frictherm/coupling/distributed.hpp), under mpirun with 2 and 4
// ranks. A 40 × 10 lattice of particles numbered column by column is split into slabs of columns, one
// per rank; a hot disc centred on a slab boundary and a second one inside the first slab. Checks: the
// straddling disc is one hot spot holding particles of two ranks; every rank holds the same hot spots
// as a serial tracker given all particles (ids, members, peak, mean, size, centroid, excess energy:
// exactly, since the gathered candidates come in the serial order), also after a second update in
// which the discs grow and one more appears (tracking by overlap); the maximum temperature is the
// global one. The same in 3D: a 16 × 6 × 6 lattice split into slabs along x, a hot ball centred on the
// boundary of the first two slabs and one inside the last slab.
#include <frictherm/coupling/distributed.hpp>

#include "../mpi_ranks.hpp"
#include "../mpi_test_main.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

namespace fc = frictherm::coupling;
namespace fm = frictherm::mechanics;
using frictherm::test::comm_rank;
using frictherm::test::comm_size;

namespace {

constexpr int kColumns = 40, kRows = 10;
constexpr double kSpacing = 1e-3, kT0 = 300.0;

// Column i (0 … 39) of rank r's slab: [r·40/P, (r+1)·40/P).
int first_column(int rank, int ranks) { return rank * kColumns / ranks; }

// The temperature field at a given update: discs of 60 K above T0, centred on the boundary of the
// first two slabs and inside the first slab; at update 1 both grow by half a spacing and a third disc
// appears at the right end.
double temperature(const fm::Vec<2>& x, int update, int ranks) {
  const double boundary = first_column(1, ranks) * kSpacing;
  const double grow = 0.5 * kSpacing * update;
  auto in_disc = [&](double cx, double cy, double r) { return std::hypot(x[0] - cx, x[1] - cy) < r; };
  bool hot = in_disc(boundary, 5e-3, 2.6e-3 + grow) || in_disc(2.5e-3, 2.5e-3, 1.6e-3 + grow);
  if (update == 1) hot = hot || in_disc(38.5e-3, 8e-3, 1.2e-3);
  return kT0 + (hot ? 60.0 + 0.1 * x[0] / kSpacing : 0.0);  // a gradient so that peaks differ
}

// Particles of columns [c0, c1) in id order (id = column · rows + row).
void lattice(int c0, int c1, int update, int ranks, fm::Particles<2>& p, std::vector<std::int64_t>& ids) {
  p = fm::Particles<2>{};
  ids.clear();
  for (int i = c0; i < c1; ++i)
    for (int j = 0; j < kRows; ++j) {
      const fm::Vec<2> x((i + 0.5) * kSpacing, (j + 0.5) * kSpacing);
      p.add(x, fm::Vec<2>::Constant(0.5 * kSpacing), 1e-3, kSpacing * kSpacing, 0, 0, temperature(x, update, ranks));
      ids.push_back(static_cast<std::int64_t>(i) * kRows + j);
    }
}

void expect_same(const std::vector<fc::HotSpot>& a, const std::vector<fc::HotSpot>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].id, b[s].id);
    EXPECT_EQ(a[s].particles, b[s].particles);
    EXPECT_EQ(a[s].peak_temperature, b[s].peak_temperature);
    EXPECT_EQ(a[s].mean_temperature, b[s].mean_temperature);
    EXPECT_EQ(a[s].size, b[s].size);
    EXPECT_EQ(a[s].centroid, b[s].centroid);
    EXPECT_EQ(a[s].excess_energy, b[s].excess_energy);
    EXPECT_EQ(a[s].birth_time, b[s].birth_time);
  }
}

// One conducting material and a serial and a decomposed tracker of hot spots 20 K above T0, in `dim`.
struct Trackers {
  const std::vector<fc::ThermalProperties> materials = {{true, 1000.0, 0.5}};
  fc::HotSpotTracker serial, decomposed;
  explicit Trackers(int dim) : serial(dim, options()), decomposed(dim, options()) {}
  static fc::HotSpotOptions options() {
    fc::HotSpotOptions opt;
    opt.threshold = 20.0;
    return opt;
  }
};

// Hot spots holding particles on both sides of a slab boundary (ids below `boundary_id` on its left).
int straddling(const std::vector<fc::HotSpot>& spots, std::int64_t boundary_id) {
  int n = 0;
  for (const fc::HotSpot& h : spots) {
    bool left = false, right = false;
    for (std::size_t id : h.particles) (static_cast<std::int64_t>(id) < boundary_id ? left : right) = true;
    if (left && right) ++n;
  }
  return n;
}

// "<title> N hot spots, sizes n (id i) ..." on one line.
void print_spots(const std::string& title, const std::vector<fc::HotSpot>& spots) {
  std::cout << title << spots.size() << " hot spots, sizes";
  for (const fc::HotSpot& h : spots) std::cout << ' ' << h.particle_count << " (id " << h.id << ")";
  std::cout << '\n';
}

}  // namespace

TEST(HotSpotsAcrossRanks, StraddlingSpotIsOneAndAllRanksAgreeWithSerial) {
  const int rank = comm_rank(), ranks = comm_size();
  ASSERT_GE(ranks, 2);
  Trackers trackers(2);
  fc::HotSpotTracker &serial = trackers.serial, &decomposed = trackers.decomposed;
  const std::size_t total = static_cast<std::size_t>(kColumns) * kRows;
  for (int update = 0; update < 2; ++update) {
    SCOPED_TRACE(update);
    const double time = 1e-6 * update;
    fm::Particles<2> all, mine;
    std::vector<std::int64_t> all_ids, my_ids;
    lattice(0, kColumns, update, ranks, all, all_ids);
    lattice(first_column(rank, ranks), first_column(rank + 1, ranks), update, ranks, mine, my_ids);
    const std::vector<double> reference(mine.size(), kT0), all_reference(all.size(), kT0);
    double max_serial = 0.0;
    serial.update_from(serial.candidates(all, trackers.materials, max_serial, &all_ids, &all_reference), max_serial, total, time);
    fc::update_hot_spots_across_ranks(MPI_COMM_WORLD, decomposed, mine, my_ids, reference, trackers.materials, total, time);

    const auto& spots = decomposed.hot_spots();
    ASSERT_EQ(spots.size(), update == 0 ? 2u : 3u);
    expect_same(spots, serial.hot_spots());
    EXPECT_EQ(decomposed.max_temperature(), max_serial);
    // The disc on the boundary of slabs 0 and 1 holds particles of both.
    EXPECT_EQ(straddling(spots, static_cast<std::int64_t>(first_column(1, ranks)) * kRows), 1);
    if (rank == 0)
      print_spots("[hot spots across " + std::to_string(ranks) + " ranks] update " + std::to_string(update) + ": ",
                  spots);
  }
}

// ---- 3D: a ball straddling the first slab boundary, one inside the last slab ----
namespace {

constexpr int kX3 = 16, kY3 = 6, kZ3 = 6;

int first_slab3(int rank, int ranks) { return rank * kX3 / ranks; }

void lattice3(int c0, int c1, int ranks, fm::Particles<3>& p, std::vector<std::int64_t>& ids) {
  p = fm::Particles<3>{};
  ids.clear();
  const double boundary = first_slab3(1, ranks) * kSpacing;
  for (int i = c0; i < c1; ++i)
    for (int j = 0; j < kY3; ++j)
      for (int k = 0; k < kZ3; ++k) {
        const fm::Vec<3> x((i + 0.5) * kSpacing, (j + 0.5) * kSpacing, (k + 0.5) * kSpacing);
        const bool hot = (x - fm::Vec<3>(boundary, 3e-3, 3e-3)).norm() < 2.1e-3 ||
                         (x - fm::Vec<3>(15e-3, 3e-3, 3e-3)).norm() < 1.2e-3;
        p.add(x, fm::Vec<3>::Constant(0.5 * kSpacing), 1e-6, kSpacing * kSpacing * kSpacing, 0, 0,
              kT0 + (hot ? 60.0 + 0.1 * (x[0] + 2.0 * x[1] + 3.0 * x[2]) / kSpacing : 0.0));
        ids.push_back((static_cast<std::int64_t>(i) * kY3 + j) * kZ3 + k);
      }
}

}  // namespace

TEST(HotSpotsAcrossRanks, StraddlingBallIn3DIsOneAndAllRanksAgreeWithSerial) {
  const int rank = comm_rank(), ranks = comm_size();
  ASSERT_GE(ranks, 2);
  Trackers trackers(3);
  fc::HotSpotTracker &serial = trackers.serial, &decomposed = trackers.decomposed;
  const std::size_t total = static_cast<std::size_t>(kX3) * kY3 * kZ3;
  fm::Particles<3> all, mine;
  std::vector<std::int64_t> all_ids, my_ids;
  lattice3(0, kX3, ranks, all, all_ids);
  lattice3(first_slab3(rank, ranks), first_slab3(rank + 1, ranks), ranks, mine, my_ids);
  // The swarm order of a decomposed run is not the id order: this rank's particles reversed.
  std::vector<std::size_t> reverse(mine.size());
  for (std::size_t k = 0; k < reverse.size(); ++k) reverse[k] = reverse.size() - 1 - k;
  mine.permute(reverse);
  std::reverse(my_ids.begin(), my_ids.end());
  const std::vector<double> reference(mine.size(), kT0), all_reference(all.size(), kT0);
  double max_serial = 0.0;
  serial.update_from(serial.candidates(all, trackers.materials, max_serial, &all_ids, &all_reference), max_serial, total, 0.0);
  fc::update_hot_spots_across_ranks(MPI_COMM_WORLD, decomposed, mine, my_ids, reference, trackers.materials, total, 0.0);
  const auto& spots = decomposed.hot_spots();
  ASSERT_EQ(spots.size(), 2u);
  expect_same(spots, serial.hot_spots());
  EXPECT_EQ(decomposed.max_temperature(), max_serial);
  EXPECT_EQ(straddling(spots, static_cast<std::int64_t>(first_slab3(1, ranks)) * kY3 * kZ3), 1);
  if (rank == 0) print_spots("[hot spots 3D across " + std::to_string(ranks) + " ranks] ", spots);
}

int main(int argc, char** argv) { return frictherm::test::run_tests_under_mpi(argc, argv); }
