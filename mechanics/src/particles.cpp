#include <frictherm/mechanics/particles.hpp>

namespace frictherm::mechanics {

template <int Dim>
void Particles<Dim>::reserve(std::size_t n) {
  position.reserve(n);
  initial_position.reserve(n);
  velocity.reserve(n);
  half_size.reserve(n);
  mass.reserve(n);
  initial_volume.reserve(n);
  volume.reserve(n);
  deformation_gradient.reserve(n);
  stress.reserve(n);
  stress_zz.reserve(n);
  temperature.reserve(n);
  plastic_strain.reserve(n);
  internal_energy.reserve(n);
  plastic_work.reserve(n);
  material.reserve(n);
  body.reserve(n);
}

template <int Dim>
void Particles<Dim>::add(const Vec<Dim>& x, const Vec<Dim>& lp, double m, double V, int material_id, int body_id,
                         double temperature_K) {
  position.push_back(x);
  initial_position.push_back(x);
  velocity.push_back(Vec<Dim>::Zero());
  half_size.push_back(lp);
  mass.push_back(m);
  initial_volume.push_back(V);
  volume.push_back(V);
  deformation_gradient.push_back(Mat<Dim>::Identity());
  stress.push_back(Mat<Dim>::Zero());
  stress_zz.push_back(0.0);
  temperature.push_back(temperature_K);
  plastic_strain.push_back(0.0);
  internal_energy.push_back(0.0);
  plastic_work.push_back(0.0);
  material.push_back(material_id);
  body.push_back(body_id);
}

namespace {
template <class T>
void permute_field(std::vector<T>& v, const std::vector<std::size_t>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (std::size_t k : order) out.push_back(v[k]);
  v.swap(out);
}
}  // namespace

template <int Dim>
void Particles<Dim>::permute(const std::vector<std::size_t>& order) {
  permute_field(position, order);
  permute_field(initial_position, order);
  permute_field(velocity, order);
  permute_field(half_size, order);
  permute_field(mass, order);
  permute_field(initial_volume, order);
  permute_field(volume, order);
  permute_field(deformation_gradient, order);
  permute_field(stress, order);
  permute_field(stress_zz, order);
  permute_field(temperature, order);
  permute_field(plastic_strain, order);
  permute_field(internal_energy, order);
  permute_field(plastic_work, order);
  permute_field(material, order);
  permute_field(body, order);
}

template struct Particles<2>;
template struct Particles<3>;

}  // namespace frictherm::mechanics
