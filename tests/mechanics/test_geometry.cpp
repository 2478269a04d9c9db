// Geometry regions, PGM images and particle filling.
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

using namespace frictherm::mechanics;

namespace {
Material solid(double rho = 1000.0) {
  Material m;
  m.name = "solid";
  m.density = rho;
  m.youngs_modulus = 1e7;
  m.poisson_ratio = 0.3;
  return m;
}
Grid<2> grid2() { return Grid<2>(Vec<2>(0, 0), Vec<2>(0.1, 0.1), IVec<2>{20, 20}); }
}  // namespace

TEST(Geometry, RectangleFillIsExact) {
  SimulationOptions o;
  o.thickness = 0.01;
  Simulation<2> sim(grid2(), o);
  const int m = sim.add_material(solid());
  sim.add_body("block", *make_box<2>(Vec<2>(0.2, 0.3), Vec<2>(1.2, 0.8), m), 2, Vec<2>::Zero());
  // 10 x 5 cells, 4 particles each
  EXPECT_EQ(sim.particles().size(), 200u);
  double mass = 0.0;
  for (double mp : sim.particles().mass) mass += mp;
  EXPECT_NEAR(mass, 1000.0 * 1.0 * 0.5 * 0.01, 1e-12);
}

TEST(Geometry, DiskAreaConverges) {
  // Lattice count of a disk: the area error of a lattice of spacing s is O(s^(3/2))-ish; with
  // s = r/40 the relative error is well under 1 %.
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.05, 0.05), IVec<2>{40, 40}));
  const int m = sim.add_material(solid());
  sim.add_body("disk", *make_ellipse<2>(Vec<2>(1, 1), Vec<2>(0.5, 0.5), 0.0, m), 4, Vec<2>::Zero());
  double V = 0.0;
  for (double v : sim.particles().initial_volume) V += v;
  EXPECT_NEAR(V, M_PI * 0.25, 0.01 * M_PI * 0.25);
}

TEST(Geometry, AnnulusAndEllipseMembership) {
  auto ring = make_annulus<2>(Vec<2>(0, 0), 1.0, 2.0, 3);
  EXPECT_EQ(ring->material_at(Vec<2>(1.5, 0)), 3);
  EXPECT_EQ(ring->material_at(Vec<2>(0.5, 0)), -1);
  EXPECT_EQ(ring->material_at(Vec<2>(2.5, 0)), -1);
  auto ell = make_ellipse<2>(Vec<2>(0, 0), Vec<2>(2.0, 1.0), M_PI / 2, 1);  // long axis along y
  EXPECT_EQ(ell->material_at(Vec<2>(0, 1.9)), 1);
  EXPECT_EQ(ell->material_at(Vec<2>(1.9, 0)), -1);
  auto ball = make_ellipse<3>(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1), 0.0, 0);
  EXPECT_EQ(ball->material_at(Vec<3>(0.5, 0.5, 0.5)), 0);
  EXPECT_EQ(ball->material_at(Vec<3>(0.6, 0.6, 0.6)), -1);
}

TEST(Geometry, PolygonEvenOdd) {
  // L-shaped polygon
  std::vector<Vec<2>> v{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  auto poly = make_polygon<2>(v, 0, 0, 0);
  EXPECT_EQ(poly->material_at(Vec<2>(0.5, 1.5)), 0);
  EXPECT_EQ(poly->material_at(Vec<2>(1.5, 0.5)), 0);
  EXPECT_EQ(poly->material_at(Vec<2>(1.5, 1.5)), -1);
  auto prism = make_polygon<3>(v, 0.0, 0.5, 0);
  EXPECT_EQ(prism->material_at(Vec<3>(0.5, 0.5, 0.25)), 0);
  EXPECT_EQ(prism->material_at(Vec<3>(0.5, 0.5, 0.75)), -1);
}

TEST(Geometry, PgmImageMapsGreyLevelsToMaterials) {
  const std::string path = ::testing::TempDir() + "frictherm_test.pgm";
  {
    std::ofstream f(path);
    f << "P2\n# two phases\n4 2\n255\n0 0 200 200\n0 0 200 200\n";
  }
  const GreyImage img = read_pgm(path);
  EXPECT_EQ(img.width, 4);
  EXPECT_EQ(img.height, 2);
  Simulation<2> sim(Grid<2>(Vec<2>(0, 0), Vec<2>(0.5, 0.5), IVec<2>{8, 4}));
  const int a = sim.add_material(solid(1000.0));
  const int b = sim.add_material(solid(2000.0));
  auto region = make_image_region<2>(img, Vec<2>(0, 0), 1.0, {{0, 100, a}, {101, 255, b}}, 0, 0);
  sim.add_body("image", *region, 2, Vec<2>::Zero());
  int na = 0, nb = 0;
  for (std::size_t k = 0; k < sim.particles().size(); ++k) {
    const bool left = sim.particles().position[k][0] < 2.0;
    const int mat = sim.particles().material[k];
    EXPECT_EQ(mat, left ? a : b);
    (mat == a ? na : nb)++;
  }
  EXPECT_EQ(na, 64);  // left half of the 4 x 2 m grid: 4 x 4 cells of 0.5 m, 4 particles each
  EXPECT_EQ(nb, na);
  std::remove(path.c_str());
}

TEST(Geometry, PgmBinaryAndErrors) {
  const std::string path = ::testing::TempDir() + "frictherm_test_p5.pgm";
  {
    std::ofstream f(path, std::ios::binary);
    f << "P5 3 1 255\n";
    const unsigned char px[3] = {0, 128, 255};
    f.write(reinterpret_cast<const char*>(px), 3);
  }
  const GreyImage img = read_pgm(path);
  EXPECT_EQ(img.at(1, 0), 128);
  EXPECT_EQ(img.at(2, 0), 255);
  {
    std::ofstream f(path, std::ios::binary);
    f << "P5 3 1 255\n";
    f.put('\x01');
  }
  EXPECT_THROW(read_pgm(path), std::runtime_error);
  EXPECT_THROW(read_pgm(path + ".missing"), std::runtime_error);
  std::remove(path.c_str());
}

TEST(Geometry, FirstBodyWinsOverlap) {
  Simulation<2> sim(grid2());
  const int m = sim.add_material(solid());
  sim.add_body("a", *make_box<2>(Vec<2>(0, 0), Vec<2>(1, 1), m), 2, Vec<2>::Zero());
  sim.add_body("b", *make_box<2>(Vec<2>(0.5, 0), Vec<2>(1.5, 1), m), 2, Vec<2>::Zero());
  EXPECT_EQ(sim.bodies()[0].particle_count, 400u);
  EXPECT_EQ(sim.bodies()[1].particle_count, 200u);
  EXPECT_THROW(sim.add_body("c", *make_box<2>(Vec<2>(0, 0), Vec<2>(1, 1), m), 2, Vec<2>::Zero()),
               std::invalid_argument);
}
