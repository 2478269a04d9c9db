// String names of the mechanics enums: the vocabulary scenes use.
#include <frictherm/mechanics/contact.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/shape_functions.hpp>
#include <frictherm/mechanics/transfer.hpp>

#include <stdexcept>

namespace frictherm::mechanics {

ShapeKind shape_kind_from_string(const std::string& name) {
  if (name == "linear") return ShapeKind::linear;
  if (name == "ugimp") return ShapeKind::ugimp;
  if (name == "quadratic_bspline") return ShapeKind::quadratic_bspline;
  if (name == "extended_bspline" || name == "ebs") return ShapeKind::extended_bspline;
  throw std::invalid_argument("unknown shape function '" + name +
                              "' (expected linear, ugimp, quadratic_bspline or extended_bspline)");
}

const char* to_string(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::linear: return "linear";
    case ShapeKind::ugimp: return "ugimp";
    case ShapeKind::quadratic_bspline: return "quadratic_bspline";
    case ShapeKind::extended_bspline: return "extended_bspline";
  }
  return "?";
}

MaterialKind material_kind_from_string(const std::string& name) {
  if (name == "linear_elastic") return MaterialKind::linear_elastic;
  if (name == "neo_hookean") return MaterialKind::neo_hookean;
  if (name == "rigid") return MaterialKind::rigid;
  if (name == "mie_gruneisen") return MaterialKind::mie_gruneisen;
  throw std::invalid_argument("unknown material type '" + name +
                              "' (expected linear_elastic, neo_hookean, mie_gruneisen or rigid)");
}

const char* to_string(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::linear_elastic: return "linear_elastic";
    case MaterialKind::neo_hookean: return "neo_hookean";
    case MaterialKind::rigid: return "rigid";
    case MaterialKind::mie_gruneisen: return "mie_gruneisen";
  }
  return "?";
}

NormalMethod normal_method_from_string(const std::string& name) {
  if (name == "mvg") return NormalMethod::max_volume_gradient;
  if (name == "avg") return NormalMethod::average_volume_gradient;
  throw std::invalid_argument("unknown contact normal '" + name + "' (expected mvg, avg or a vector)");
}

const char* to_string(NormalMethod m) {
  switch (m) {
    case NormalMethod::max_volume_gradient: return "mvg";
    case NormalMethod::average_volume_gradient: return "avg";
    case NormalMethod::specified: return "specified";
  }
  return "?";
}

SeparationMethod separation_method_from_string(const std::string& name) {
  if (name == "position") return SeparationMethod::position;
  if (name == "displacement") return SeparationMethod::displacement;
  if (name == "velocity_only") return SeparationMethod::velocity_only;
  if (name == "extent") return SeparationMethod::extent;
  throw std::invalid_argument("unknown contact separation '" + name + "' (expected position, displacement, velocity_only or extent)");
}

const char* to_string(SeparationMethod m) {
  switch (m) {
    case SeparationMethod::position: return "position";
    case SeparationMethod::displacement: return "displacement";
    case SeparationMethod::velocity_only: return "velocity_only";
    case SeparationMethod::extent: return "extent";
  }
  return "?";
}

HeatingOrder heating_order_from_string(const std::string& name) {
  if (name == "first") return HeatingOrder::first;
  if (name == "second") return HeatingOrder::second;
  throw std::invalid_argument("unknown heating order '" + name + "' (expected first or second)");
}

const char* to_string(HeatingOrder o) { return o == HeatingOrder::first ? "first" : "second"; }

ParticleUpdate particle_update_from_string(const std::string& name) {
  if (name == "flip") return ParticleUpdate::flip;
  if (name == "xpic") return ParticleUpdate::xpic;
  if (name == "fmpm") return ParticleUpdate::fmpm;
  throw std::invalid_argument("unknown particle update '" + name + "' (expected \"flip\", \"xpic\" or \"fmpm\")");
}

const char* to_string(ParticleUpdate u) {
  switch (u) {
    case ParticleUpdate::flip: return "flip";
    case ParticleUpdate::xpic: return "xpic";
    case ParticleUpdate::fmpm: return "fmpm";
  }
  return "?";
}

}  // namespace frictherm::mechanics
