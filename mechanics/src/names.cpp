// String names of the mechanics enums: the vocabulary scenes use.
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <stdexcept>

namespace frictherm::mechanics {

ShapeKind shape_kind_from_string(const std::string& name) {
  if (name == "linear") return ShapeKind::linear;
  if (name == "ugimp") return ShapeKind::ugimp;
  if (name == "quadratic_bspline") return ShapeKind::quadratic_bspline;
  throw std::invalid_argument("unknown shape function '" + name + "' (expected linear, ugimp or quadratic_bspline)");
}

const char* to_string(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::linear: return "linear";
    case ShapeKind::ugimp: return "ugimp";
    case ShapeKind::quadratic_bspline: return "quadratic_bspline";
  }
  return "?";
}

MaterialKind material_kind_from_string(const std::string& name) {
  if (name == "linear_elastic") return MaterialKind::linear_elastic;
  if (name == "neo_hookean") return MaterialKind::neo_hookean;
  if (name == "rigid") return MaterialKind::rigid;
  throw std::invalid_argument("unknown material type '" + name + "' (expected linear_elastic, neo_hookean or rigid)");
}

const char* to_string(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::linear_elastic: return "linear_elastic";
    case MaterialKind::neo_hookean: return "neo_hookean";
    case MaterialKind::rigid: return "rigid";
  }
  return "?";
}

}  // namespace frictherm::mechanics
