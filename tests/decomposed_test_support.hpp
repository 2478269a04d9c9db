#pragma once
// Shared by the decomposed-run tests (tests/mechanics/test_distributed*.cpp,
// tests/coupling/test_heat_distributed*.cpp): a linear-elastic material, serial particles handed to
// the decomposed run, and the serial sliding blocks (2D, 3D) they compare with.
#include "frictherm/mechanics/distributed.hpp"
#include "frictherm/mechanics/geometry.hpp"
#include "frictherm/mechanics/simulation.hpp"

#include "mpi_ranks.hpp"

#include <memory>
#include <vector>

namespace frictherm::test {

inline mechanics::Material elastic(const char* name, double E, double nu, double rho) {
  mechanics::Material m;
  m.name = name;
  m.kind = mechanics::MaterialKind::linear_elastic;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  m.density = rho;
  return m;
}

/// Serial particles as decomposed particles (id = serial index; with `temperature` the temperature
/// as the one scalar), 2D or 3D. Only rank 0 passes them: the first migration distributes them.
template <int Dim>
std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> decomposed(const mechanics::Particles<Dim>& sp,
                                                                         bool temperature = false) {
  std::vector<typename mechanics::DecomposedMpm<Dim>::Particle> all(sp.position.size());
  for (std::size_t k = 0; k < all.size(); ++k) {
    all[k].id = static_cast<std::int64_t>(k);
    all[k].mass = sp.mass[k];
    all[k].volume = sp.volume[k];
    all[k].position = sp.position[k];
    all[k].velocity = sp.velocity[k];
    all[k].half_size = sp.half_size[k];
    all[k].material = sp.material[k];
    if (temperature) all[k].scalars = {sp.temperature[k]};
  }
  return comm_rank() == 0 ? all : decltype(all){};
}

/// Mass-weighted mean x-velocity of one material's particles (gathered decomposed ones, serial ones).
template <class Particle>
double mean_velocity_x(const std::vector<Particle>& a, int material) {
  double mv = 0.0, m = 0.0;
  for (const auto& p : a)
    if (p.material == material) mv += p.mass * p.velocity[0], m += p.mass;
  return mv / m;
}
template <int Dim>
double mean_velocity_x(const mechanics::Particles<Dim>& p, int material) {
  double mv = 0.0, m = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k)
    if (p.material[k] == material) mv += p.mass[k] * p.velocity[k][0], m += p.mass[k];
  return mv / m;
}

/// The sliding blocks' last steps: the base's bottom `face` fixed (all components), Coulomb friction μ
/// with the specified `normal` (base to block) between base and block, the serial run finalized; and
/// the decomposed run's options to match (shape, gravity, the fixed face, the contact pair).
template <int Dim>
void fix_and_slide(mechanics::Simulation<Dim>& serial, int base, int block, const mechanics::FixedFace& face,
                   const mechanics::Vec<3>& normal, double mu, mechanics::ShapeKind shape,
                   const mechanics::Vec<Dim>& gravity, typename mechanics::DecomposedMpm<Dim>::Options& options) {
  serial.fix_face(face);
  mechanics::ContactOptions co;
  co.default_pair.law = mechanics::FrictionLaw::coulomb(mu);
  co.default_pair.normal = mechanics::NormalMethod::specified;
  co.default_pair.normal_vector = normal;
  serial.enable_contact(co);
  serial.set_contact_pair(base, block, co.default_pair);
  serial.finalize();
  options.shape = shape;
  options.gravity = gravity;
  options.fixed_faces = {face};
  options.contact = true;
  options.contact_options = co;
  options.contact_pairs = {mechanics::DecomposedContactPair{base, block, co.default_pair}};
}

/// The sliding block both decomposed tests compare with: base 24 × 4 mm fixed at y_min, block 8 × 4 mm
/// on it at v0 = 10 m/s (crossing the 2-rank split), g = 2e4 m/s², Coulomb μ = 0.3 with the
/// specified normal (0, 1), 1 mm cells, 2 × 2 particles per cell, USL; and the matching options of
/// the decomposed run.
struct SlidingBlock {
  static constexpr double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4, mu = 0.3;
  mechanics::Grid<2> grid{mechanics::Vec<2>(0.0, 0.0), mechanics::Vec<2>(h, h), {26, 12}};
  std::vector<mechanics::Material> materials{elastic("base", 2e7, 0.3, rho), elastic("block", 1.5e7, 0.25, rho)};
  std::unique_ptr<mechanics::Simulation<2>> serial;
  mechanics::DecomposedOptions options;
  int base = 0, block = 1;

  explicit SlidingBlock(mechanics::ShapeKind shape) {
    using V2 = mechanics::Vec<2>;
    mechanics::SimulationOptions so;
    so.shape = shape;
    so.scheme = mechanics::UpdateScheme::usl;
    so.gravity = mechanics::Vec<3>(0.0, -g, 0.0);
    serial = std::make_unique<mechanics::Simulation<2>>(grid, so);
    base = serial->add_material(materials[0]);
    block = serial->add_material(materials[1]);
    serial->add_body("base", *mechanics::make_box<2>(V2(1e-3, 0.0), V2(25e-3, 4e-3), base), 2, V2::Zero());
    serial->add_body("block", *mechanics::make_box<2>(V2(6e-3, 4e-3), V2(14e-3, 8e-3), block), 2, V2(v0, 0.0));
    fix_and_slide(*serial, base, block, {1, false, {{true, true, true}}}, mechanics::Vec<3>(0.0, 1.0, 0.0), mu, shape,
                  V2(0.0, -g), options);
  }
};

/// The 3D sliding block (test_distributed_3d.cpp (d), test_heat_distributed_3d.cpp): base 10 × 4 × 2 mm
/// fixed at z_min (all components), block 4 × 4 × 2 mm on it sliding along x at v0 = 10 m/s (across
/// the 2-rank cut near x = 6.5 mm), pressed by g = 2e4 m/s² along −z, Coulomb μ = 0.3 with the
/// specified normal (0, 0, 1) from base to block; 12 × 6 × 5 cells of 1 mm, 2³ particles per cell,
/// USL; and the matching options of the decomposed run.
struct SlidingBlock3D {
  static constexpr double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4, mu = 0.3;
  mechanics::Grid<3> grid{mechanics::Vec<3>::Zero(), mechanics::Vec<3>::Constant(h), {12, 6, 5}};
  std::vector<mechanics::Material> materials{elastic("base", 2e7, 0.3, rho), elastic("block", 1.5e7, 0.25, rho)};
  std::unique_ptr<mechanics::Simulation<3>> serial;
  mechanics::DecomposedMpm3D::Options options;
  int base = 0, block = 1;

  explicit SlidingBlock3D(mechanics::ShapeKind shape) {
    using V3 = mechanics::Vec<3>;
    mechanics::SimulationOptions so;
    so.shape = shape;
    so.scheme = mechanics::UpdateScheme::usl;
    so.gravity = V3(0.0, 0.0, -g);
    serial = std::make_unique<mechanics::Simulation<3>>(grid, so);
    base = serial->add_material(materials[0]);
    block = serial->add_material(materials[1]);
    serial->add_body("base", *mechanics::make_box<3>(V3(1e-3, 1e-3, 0.0), V3(11e-3, 5e-3, 2e-3), base), 2, V3::Zero());
    serial->add_body("block", *mechanics::make_box<3>(V3(2e-3, 1e-3, 2e-3), V3(6e-3, 5e-3, 4e-3), block), 2,
                     V3(v0, 0.0, 0.0));
    fix_and_slide(*serial, base, block, {2, false, {{true, true, true}}}, V3(0.0, 0.0, 1.0), mu, shape,
                  V3(0.0, 0.0, -g), options);
  }
};

}  // namespace frictherm::test
