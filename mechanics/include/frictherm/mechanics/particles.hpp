#pragma once
// Particles in structure-of-arrays storage: one contiguous array per field.
// Particles are kept grouped by material (see Simulation::finalize), so each material owns a
// contiguous index range and constitutive updates run without a per-particle branch.
#include <frictherm/mechanics/types.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frictherm::mechanics {

template <int Dim>
struct Particles {
  std::vector<Vec<Dim>> position;          // x_p (m)
  std::vector<Vec<Dim>> initial_position;  // X_p (m)
  std::vector<Vec<Dim>> velocity;          // v_p (m/s)
  std::vector<Vec<Dim>> half_size;         // initial half-widths l_p (m), used by uGIMP
  std::vector<double> mass;                // m_p (kg)
  std::vector<double> initial_volume;      // V0_p (m^3; in 2D area times thickness)
  std::vector<double> volume;              // V_p = J V0_p
  std::vector<Mat<Dim>> deformation_gradient;  // F_p
  std::vector<Mat<Dim>> stress;            // Cauchy stress, in-plane part (Pa)
  std::vector<double> stress_zz;           // out-of-plane Cauchy stress in 2D (plane strain), 0 in 3D
  std::vector<double> temperature;         // T_p (K)
  std::vector<double> plastic_strain;      // equivalent plastic strain (0 for elastic materials)
  std::vector<double> internal_energy;     // equation of state: specific internal energy e (J/kg);
                                           // linear elastic: its stress's work per unit V0 (J/m^3)
  std::vector<double> plastic_work;        // plastic work done on the particle since the start (J)
  std::vector<std::int32_t> material;      // material id
  std::vector<std::int32_t> body;          // body id

  std::size_t size() const { return position.size(); }

  void reserve(std::size_t n);
  /// Appends one particle at rest with identity deformation and zero stress.
  void add(const Vec<Dim>& x, const Vec<Dim>& lp, double m, double V, int material_id, int body_id,
           double temperature_K);
  /// Reorders every field by `order` (new index k takes old index order[k]).
  void permute(const std::vector<std::size_t>& order);
  /// Bytes of particle storage per particle (all fields).
  static constexpr std::size_t bytes_per_particle() {
    return sizeof(Vec<Dim>) * 4 + sizeof(double) * 8 + sizeof(Mat<Dim>) * 2 + sizeof(std::int32_t) * 2;
  }
};

extern template struct Particles<2>;
extern template struct Particles<3>;

}  // namespace frictherm::mechanics
