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

/// A block sliding on a base, the serial run the decomposed tests compare with, in 2D and 3D: an
/// elastic base (E = 20 MPa, ν = 0.3) with its bottom face (axis `up` = Dim − 1, lower side) fixed in
/// every component, an elastic block (15 MPa, 0.25) on it at v0 = 10 m/s along x, g = 2e4 m/s² along
/// −up, Coulomb μ = 0.3 with the specified normal +up from base to block; ρ = 1000 kg/m³, cells of
/// h = 1 mm from the origin, 2^Dim particles per cell, USL; and the matching options of the
/// decomposed run.
template <int Dim>
struct SlidingBlockOf {
  static constexpr double h = 1e-3, rho = 1000.0, v0 = 10.0, g = 2e4, mu = 0.3;
  static constexpr int up = Dim - 1;
  mechanics::Grid<Dim> grid;
  std::vector<mechanics::Material> materials{elastic("base", 2e7, 0.3, rho), elastic("block", 1.5e7, 0.25, rho)};
  std::unique_ptr<mechanics::Simulation<Dim>> serial;
  typename mechanics::DecomposedMpm<Dim>::Options options;
  int base = 0, block = 1;

  SlidingBlockOf(mechanics::ShapeKind shape, const mechanics::IVec<Dim>& cells, const mechanics::Vec<Dim>& base_lo,
                 const mechanics::Vec<Dim>& base_hi, const mechanics::Vec<Dim>& block_lo,
                 const mechanics::Vec<Dim>& block_hi)
      : grid(mechanics::Vec<Dim>::Zero(), mechanics::Vec<Dim>::Constant(h), cells) {
    using VD = mechanics::Vec<Dim>;
    mechanics::Vec<3> gravity = mechanics::Vec<3>::Zero();
    gravity[up] = -g;
    mechanics::SimulationOptions so;
    so.shape = shape;
    so.scheme = mechanics::UpdateScheme::usl;
    so.gravity = gravity;
    serial = std::make_unique<mechanics::Simulation<Dim>>(grid, so);
    base = serial->add_material(materials[0]);
    block = serial->add_material(materials[1]);
    VD sliding = VD::Zero();
    sliding[0] = v0;
    serial->add_body("base", *mechanics::make_box<Dim>(base_lo, base_hi, base), 2, VD::Zero());
    serial->add_body("block", *mechanics::make_box<Dim>(block_lo, block_hi, block), 2, sliding);
    const mechanics::FixedFace bottom{up, false, {{true, true, true}}};
    serial->fix_face(bottom);
    mechanics::ContactOptions co;
    co.default_pair.law = mechanics::FrictionLaw::coulomb(mu);
    co.default_pair.normal = mechanics::NormalMethod::specified;
    co.default_pair.normal_vector = mechanics::Vec<3>::Unit(up);
    serial->enable_contact(co);
    serial->set_contact_pair(base, block, co.default_pair);
    serial->finalize();
    options.shape = shape;
    options.gravity = gravity.template head<Dim>();
    options.fixed_faces = {bottom};
    options.contact = true;
    options.contact_options = co;
    options.contact_pairs = {mechanics::DecomposedContactPair{base, block, co.default_pair}};
  }
};

/// The 2D sliding block (test_distributed_contact.cpp (a), test_heat_distributed.cpp (a)): base
/// 24 × 4 mm fixed at y_min, block 8 × 4 mm on it (crossing the 2-rank split), 26 × 12 cells.
struct SlidingBlock : SlidingBlockOf<2> {
  explicit SlidingBlock(mechanics::ShapeKind shape)
      : SlidingBlockOf<2>(shape, {26, 12}, mechanics::Vec<2>(1e-3, 0.0), mechanics::Vec<2>(25e-3, 4e-3),
                          mechanics::Vec<2>(6e-3, 4e-3), mechanics::Vec<2>(14e-3, 8e-3)) {}
};

/// The 3D sliding block (test_distributed_3d.cpp (d), test_heat_distributed_3d.cpp): base 10 × 4 × 2 mm
/// fixed at z_min, block 4 × 4 × 2 mm on it sliding along x (across the 2-rank cut near x = 6.5 mm),
/// 12 × 6 × 5 cells.
struct SlidingBlock3D : SlidingBlockOf<3> {
  explicit SlidingBlock3D(mechanics::ShapeKind shape)
      : SlidingBlockOf<3>(shape, {12, 6, 5}, mechanics::Vec<3>(1e-3, 1e-3, 0.0), mechanics::Vec<3>(11e-3, 5e-3, 2e-3),
                          mechanics::Vec<3>(2e-3, 1e-3, 2e-3), mechanics::Vec<3>(6e-3, 5e-3, 4e-3)) {}
};

}  // namespace frictherm::test
