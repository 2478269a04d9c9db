#pragma once
// Materials the verification tests build again and again.
#include <frictherm/mechanics/material.hpp>

#include <string>

namespace frictherm::verification {

inline mechanics::Material elastic_material(const std::string& name, double density, double E, double nu) {
  mechanics::Material m;
  m.name = name;
  m.density = density;
  m.youngs_modulus = E;
  m.poisson_ratio = nu;
  return m;
}

/// A 2D rigid material at rest.
inline mechanics::Material rigid_at_rest(const std::string& name, double density = 1000.0) {
  mechanics::Material m;
  m.name = name;
  m.kind = mechanics::MaterialKind::rigid;
  m.density = density;
  m.rigid_velocity = {mechanics::TimeFunction::constant(0.0), mechanics::TimeFunction::constant(0.0)};
  return m;
}

}  // namespace frictherm::verification
