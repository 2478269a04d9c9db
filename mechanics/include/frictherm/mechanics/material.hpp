#pragma once
// Material parameters and the constitutive updates (inline: they run inside particle loops).
#include <frictherm/mechanics/mie_gruneisen_params.hpp>
#include <frictherm/mechanics/time_function.hpp>
#include <frictherm/mechanics/types.hpp>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace frictherm::mechanics {

enum class MaterialKind { linear_elastic, neo_hookean, rigid, mie_gruneisen };

MaterialKind material_kind_from_string(const std::string& name);  // throws std::invalid_argument
const char* to_string(MaterialKind kind);

struct Material {
  std::string name;
  MaterialKind kind = MaterialKind::linear_elastic;
  double density = 0.0;          // rho0 (kg/m^3)
  double youngs_modulus = 0.0;   // E (Pa)
  double poisson_ratio = 0.0;    // nu
  /// mie_gruneisen: equation of state, shear modulus and yield (density is kept equal to `density`).
  MieGruneisenParams mie_gruneisen;
  /// Rigid materials: prescribed velocity, one function of time per component (m/s).
  std::vector<TimeFunction> rigid_velocity;
  /// Rigid materials: which velocity components they prescribe (a component left free follows the
  /// deformable material). Only a boundary rigid material may leave components free.
  std::array<bool, 3> rigid_controls{{true, true, true}};
  /// Rigid materials with contact enabled: false (default) meets the other materials through contact
  /// laws; true acts as a velocity boundary condition on every node it touches, as it always does
  /// without contact (NairnMPM's rigid BC particles).
  bool rigid_boundary = false;

  bool is_rigid() const { return kind == MaterialKind::rigid; }
  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
  /// P-wave (dilatational) modulus of the analysis: lambda + 2 mu, or E/(1-nu^2) in plane stress.
  double p_wave_modulus(Analysis a) const {
    if (a == Analysis::plane_stress) return youngs_modulus / (1.0 - poisson_ratio * poisson_ratio);
    return lame_lambda() + 2.0 * shear_modulus();
  }
  /// Dilatational wave speed at the reference state (m/s).
  double p_wave_speed(Analysis a) const { return std::sqrt(p_wave_modulus(a) / density); }
  /// Wave speed of a particle at volume ratio J: for Neo-Hookean the tangent stiffens under
  /// compression, bounded here by lambda + 2 mu + 2 lambda |ln J| over the current density rho0/J.
  double wave_speed(Analysis a, double J) const {
    if (kind == MaterialKind::neo_hookean) {
      const double lam = lame_lambda();
      const double m = lam + 2.0 * shear_modulus() + 2.0 * lam * std::fabs(std::log(J));
      return std::sqrt(m * J / density);
    }
    return p_wave_speed(a);
  }
  Vec<3> rigid_velocity_at(double t) const {
    Vec<3> v = Vec<3>::Zero();
    for (std::size_t d = 0; d < rigid_velocity.size() && d < 3; ++d) v[static_cast<int>(d)] = rigid_velocity[d](t);
    return v;
  }
};

/// Hypoelastic linear elastic update with the Jaumann rate: the increment dε = sym(L) dt rotated
/// objectively, σ += λ tr(dε) I + 2 μ dε (plane stress uses λ* = 2λμ/(λ+2μ) and σ_zz = 0).
template <int Dim>
FRICTHERM_ALWAYS_INLINE void linear_elastic_update(const Mat<Dim>& L, double dt, double lambda, double mu, Analysis a,
                                  Mat<Dim>& sigma, double& sigma_zz) {
  const Mat<Dim> de = 0.5 * (L + L.transpose()) * dt;
  const Mat<Dim> w = 0.5 * (L - L.transpose()) * dt;
  const double tr = de.trace();
  const double lam = (a == Analysis::plane_stress) ? 2.0 * lambda * mu / (lambda + 2.0 * mu) : lambda;
  // σ += w σ − σ w, spelled out as Eigen evaluates that expression (a temporary w σ, minus σ w, then
  // added): GCC keeps Eigen's combined form out of line; this inlines with the same arithmetic.
  Mat<Dim> rotation;
  rotation.noalias() = w * sigma;
  rotation.noalias() -= sigma * w;
  sigma += rotation;
  sigma += 2.0 * mu * de;
  sigma.diagonal().array() += lam * tr;
  if (a == Analysis::plane_strain) sigma_zz += lambda * tr;
}

/// Compressible Neo-Hookean Cauchy stress σ = [μ (F Fᵀ − I) + λ ln J I] / J (Kakouris 2024 eq. 47;
/// in plane strain F_zz = 1 so σ_zz = λ ln J / J).
template <int Dim>
inline void neo_hookean_stress(const Mat<Dim>& F, double lambda, double mu, Mat<Dim>& sigma, double& sigma_zz) {
  const double J = F.determinant();
  const double lnJ = std::log(J);
  sigma = (mu * (F * F.transpose() - Mat<Dim>::Identity())) / J;
  sigma.diagonal().array() += lambda * lnJ / J;
  sigma_zz = (Dim == 2) ? lambda * lnJ / J : 0.0;
}

/// Neo-Hookean strain energy per reference volume (Kakouris 2024 eq. 46 with d = 3; F_zz = 1 in 2D).
template <int Dim>
inline double neo_hookean_energy_density(const Mat<Dim>& F, double lambda, double mu) {
  const double J = F.determinant();
  const double lnJ = std::log(J);
  const double Ic = (F.transpose() * F).trace() + (Dim == 2 ? 1.0 : 0.0);
  return 0.5 * mu * (Ic - 3.0) - mu * lnJ + 0.5 * lambda * lnJ * lnJ;
}

/// Linear elastic strain energy density ½ σ:ε with ε recovered from σ through the compliance.
template <int Dim>
inline double linear_elastic_energy_density(const Mat<Dim>& sigma, double sigma_zz, double E, double nu,
                                            Analysis a) {
  const double szz = (a == Analysis::plane_stress || Dim == 3) ? 0.0 : sigma_zz;
  const double tr = sigma.trace() + szz;
  const double s2 = sigma.squaredNorm() + szz * szz;
  // ½ σ:ε = (1/2E) [ (1+ν) σ:σ − ν (tr σ)² ]
  return ((1.0 + nu) * s2 - nu * tr * tr) / (2.0 * E);
}

}  // namespace frictherm::mechanics
