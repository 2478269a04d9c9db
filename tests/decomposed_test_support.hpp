#pragma once
// Shared by the decomposed-run tests (tests/mechanics/test_distributed*.cpp,
// tests/coupling/test_heat_distributed.cpp): a linear-elastic material, serial particles handed to
// the decomposed run, and the serial sliding block they compare with.
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
    const mechanics::FixedFace bottom{1, false, {{true, true, true}}};
    serial->fix_face(bottom);
    mechanics::ContactOptions co;
    co.default_pair.law = mechanics::FrictionLaw::coulomb(mu);
    co.default_pair.normal = mechanics::NormalMethod::specified;
    co.default_pair.normal_vector = mechanics::Vec<3>(0.0, 1.0, 0.0);
    serial->enable_contact(co);
    serial->set_contact_pair(base, block, co.default_pair);
    serial->finalize();
    options.shape = shape;
    options.gravity = V2(0.0, -g);
    options.fixed_faces = {bottom};
    options.contact = true;
    options.contact_options = co;
    options.contact_pairs = {mechanics::DecomposedContactPair{base, block, co.default_pair}};
  }
};

}  // namespace frictherm::test
