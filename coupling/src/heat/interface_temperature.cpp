// The sub-cell interface temperature of rubbing contacts (interface_temperature.hpp).
#include <frictherm/coupling/interface_temperature.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <array>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

template <int Dim>
void InterfaceTemperature<Dim>::start(const mechanics::Grid<Dim>& grid, double thickness,
                                      const mechanics::Particles<Dim>& p,
                                      const std::vector<ThermalProperties>& materials,
                                      const InterfaceTemperatureOptions& options, double time) {
  enabled_ = options.enabled;
  if (!enabled_) return;
  // Density per material from its particles now (ρ = Σ m / Σ V).
  std::vector<double> mass(materials.size(), 0.0), volume(materials.size(), 0.0);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const auto m = static_cast<std::size_t>(p.material[k]);
    if (m < materials.size()) mass[m] += p.mass[k], volume[m] += p.volume[k];
  }
  start_sides(grid, thickness, mass, volume, materials, options, time);
  particle_temperature_.assign(p.temperature.begin(), p.temperature.end());  // no heat yet: T_p
}

template <int Dim>
void InterfaceTemperature<Dim>::start_sides(const mechanics::Grid<Dim>& grid, double thickness,
                                            const std::vector<double>& mass, const std::vector<double>& volume,
                                            const std::vector<ThermalProperties>& materials,
                                            const InterfaceTemperatureOptions& options, double time) {
  enabled_ = options.enabled;
  if (!enabled_) return;
  grid_.emplace(grid);
  if (options.bins_per_level < 2)
    throw std::invalid_argument("interface temperature: bins_per_level must be at least 2");
  history_ = thermal::BinnedHeatHistory(static_cast<std::size_t>(options.bins_per_level));
  history_.reset(time);
  h_ = grid.min_cell_size();
  area_ = grid.cell_volume() / h_ * (Dim == 2 ? thickness : 1.0);  // h^{Dim−1} (× t in 2D)
  if (mass.size() != materials.size() || volume.size() != materials.size())
    throw std::invalid_argument("interface temperature: mass and volume sums per material expected");
  sides_.assign(materials.size(), thermal::HalfSpace{});
  heat_capacity_.assign(materials.size(), 0.0);
  for (std::size_t m = 0; m < materials.size(); ++m) {
    if (!materials[m].conducts || !(volume[m] > 0.0)) continue;
    sides_[m].conductivity = materials[m].conductivity;
    sides_[m].volumetric_heat_capacity = mass[m] / volume[m] * materials[m].heat_capacity;
    heat_capacity_[m] = materials[m].heat_capacity;
  }
  // The patch: the lattice offsets within ℓ_eff/2 of a node, and its area (node_area · ℓ_eff/h in 2D).
  patch_offsets_.clear(), patch_weights_.clear();
  patch_area_ = 0.0;
  if (options.patch_length > 0.0) {
    const double radius = 0.5 * std::max(options.patch_length, 2.0 * h_);
    if (radius > 32.0 * h_) {  // 65^Dim offsets a node: beyond that a patch is not an interface spot
      std::ostringstream msg;
      msg << "coupling.interface_temperature.patch_length: " << options.patch_length << " m is "
          << options.patch_length / h_ << " cells across; expected at most 64 cells";
      throw std::invalid_argument(msg.str());
    }
    patch_area_ = (Dim == 2 ? 2.0 * radius * thickness : 3.141592653589793 * radius * radius);
    mechanics::IVec<Dim> reach{};
    int count = 1;
    for (int d = 0; d < Dim; ++d) {
      reach[d] = static_cast<int>(std::floor(radius / grid.cell_size()[d] + 0.5));
      count *= 2 * reach[d] + 1;
    }
    for (int c = 0; c < count; ++c) {
      mechanics::IVec<Dim> o{};
      double distance2 = 0.0;
      for (int d = 0, q = c; d < Dim; ++d) {
        o[d] = q % (2 * reach[d] + 1) - reach[d];
        q /= 2 * reach[d] + 1;
        distance2 += std::pow(o[d] * grid.cell_size()[d], 2);
      }
      const double inside = std::clamp((radius - std::sqrt(distance2)) / h_ + 0.5, 0.0, 1.0);
      if (inside > 1e-12) patch_offsets_.push_back(o), patch_weights_.push_back(inside);
    }
  }
  corrections_.clear();
  slot_of_node_.assign(grid.node_count(), -1);
  nodes_.clear();
  node_correction_.clear(), node_temperature_.clear();
  patch_correction_.clear(), patch_temperature_.clear();
  particle_temperature_.clear();
  max_temperature_ = -std::numeric_limits<double>::infinity();
  max_node_temperature_ = max_temperature_;
  heat_recorded_ = 0.0;
}

template <int Dim>
void InterfaceTemperature<Dim>::add_step(const std::vector<double>& nodal_work, double time) {
  if (!enabled_) return;
  for (std::size_t i = 0; i < nodal_work.size(); ++i) add_node_heat(static_cast<int>(i), nodal_work[i]);
  end_step(time);
}

template <int Dim>
void InterfaceTemperature<Dim>::add_node_heat(int node, double w) {
  if (!(w > 0.0)) return;  // heat only (the books guard against non-finite work upstream)
  int& slot = slot_of_node_[static_cast<std::size_t>(node)];
  if (slot < 0) {
    slot = static_cast<int>(history_.add_slot());
    nodes_.push_back(node);
  }
  history_.add(static_cast<std::size_t>(slot), w / area_);
  heat_recorded_ += w;
}

template <int Dim>
void InterfaceTemperature<Dim>::end_step(double time) {
  if (time > history_.boundaries().back()) history_.close(time);
}

template <int Dim>
void InterfaceTemperature<Dim>::update(const mechanics::Particles<Dim>& p, mechanics::ShapeKind shape,
                                       const mechanics::StencilView<Dim>& stencils, const NodalThermalSystem& system,
                                       const Eigen::VectorXd& nodal_temperature, double time) {
  if (!enabled_) return;
  const std::size_t slots = nodes_.size();
  particle_temperature_.assign(p.temperature.begin(), p.temperature.end());
  if (slots == 0) {
    update_slots({}, {}, time);
    return;
  }

  const mechanics::Grid<Dim>& grid = *grid_;
  auto for_each_particle_node = [&](auto&& f) {
    mechanics::dispatch_shape(shape, [&](auto kernel) {
      using Kernel = decltype(kernel);
      const mechanics::Stencil<Dim, Kernel>* step = stencils.template as<Kernel>(p.size());
      mechanics::Stencil<Dim, Kernel> own;
      for (std::size_t k = 0; k < p.size(); ++k) {
        const auto m = static_cast<std::size_t>(p.material[k]);
        if (!conducting(m)) continue;
        if (!step) own.evaluate(grid, p.position[k], p.half_size[k]);
        const mechanics::Stencil<Dim, Kernel>& st = step ? step[k] : own;
        st.for_each(grid, [&](int i, double w, const mechanics::Vec<Dim>&) {
          const int s = slot_of_node_[static_cast<std::size_t>(i)];
          if (s >= 0 && w > 0.0) f(k, m, static_cast<std::size_t>(s), w);
        });
      }
    });
  };

  // Pass 1: each heated node's Σ_p S_ip m_p per conducting material, Σ S m c and Σ S² m c.
  const std::size_t stride = row_size();
  slot_material_mass_.assign(slots * stride, 0.0);
  for_each_particle_node([&](std::size_t k, std::size_t m, std::size_t s, double w) {
    add_to_row(&slot_material_mass_[s * stride], m, p.mass[k], w);
  });
  std::vector<double> grid_temperature(slots, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t s = 0; s < slots; ++s) {
    const auto node = static_cast<std::size_t>(nodes_[s]);
    const int u = node < system.unknown.size() ? system.unknown[node] : -1;
    if (u >= 0) grid_temperature[s] = nodal_temperature[u];
  }
  update_slots(slot_material_mass_, grid_temperature, time);
  const std::vector<double>& correction = slot_correction();

  // Pass 2: each particle's hottest touched interface, T_p + max correction.
  std::vector<double> best(p.size(), 0.0);
  for_each_particle_node([&](std::size_t k, std::size_t, std::size_t s, double) {
    best[k] = std::max(best[k], correction[s]);
  });
  for (std::size_t k = 0; k < p.size(); ++k) particle_temperature_[k] += best[k];
}

template <int Dim>
void InterfaceTemperature<Dim>::update_slots(const std::vector<double>& rows, const std::vector<double>& grid_temperature,
                                             double time, bool own_patches) {
  const std::size_t slots = nodes_.size(), nm = sides_.size();
  node_correction_.assign(slots, 0.0);
  node_temperature_.assign(slots, 0.0);
  max_temperature_ = -std::numeric_limits<double>::infinity();
  max_node_temperature_ = max_temperature_;
  patch_correction_.clear(), patch_temperature_.clear();
  if (slots == 0) return;
  const std::size_t stride = nm + 2;
  if (rows.size() != slots * stride || grid_temperature.size() != slots)
    throw std::invalid_argument("interface temperature: " + std::to_string(rows.size()) + " row values and " +
                                std::to_string(grid_temperature.size()) + " grid temperatures for " +
                                std::to_string(slots) + " heated nodes");

  // Each heated node's two heaviest conducting materials (Σ_p S_ip m_p per material) and its
  // projection factor f = (Σ S² m c / Σ S m c)^{1/Dim} (per axis; exact for a regular lattice).
  std::vector<int> group_of_slot(slots, -1);
  std::vector<const thermal::SubcellCorrection*> groups;
  std::map<std::array<int, 3>, int> group_index;
  for (std::size_t s = 0; s < slots; ++s) {
    const double* row = &rows[s * stride];
    int first = -1, second = -1;
    for (std::size_t m = 0; m < nm; ++m) {
      const double x = row[m];
      if (!(x > 0.0)) continue;
      if (first < 0 || x > row[first]) {
        second = first, first = static_cast<int>(m);
      } else if (second < 0 || x > row[second]) {
        second = static_cast<int>(m);
      }
    }
    if (first < 0) continue;  // no conducting material reaches the node now: no interface there
    if (second < 0) second = first;
    const double f = std::pow(row[nm + 1] / row[nm], 1.0 / Dim);
    const int f_percent = std::clamp(static_cast<int>(std::lround(100.0 * f)), 5, 100);
    const std::array<int, 3> key{std::min(first, second), std::max(first, second), f_percent};
    auto [it, fresh] = group_index.emplace(key, static_cast<int>(groups.size()));
    if (fresh) groups.push_back(&correction(key));
    group_of_slot[s] = it->second;
  }

  // The correction R_x ⊛ flux per slot: R_x at every bin boundary, once per material pair.
  const auto& boundaries = history_.boundaries();
  std::vector<std::vector<double>> responses(groups.size() + 1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    responses[g].resize(boundaries.size());
    for (std::size_t j = 0; j < boundaries.size(); ++j) responses[g][j] = groups[g]->step_response(time - boundaries[j]);
  }
  responses.back().assign(boundaries.size(), 0.0);  // slots without a pair now: no correction
  for (auto& g : group_of_slot)
    if (g < 0) g = static_cast<int>(groups.size());
  history_.convolve(responses, group_of_slot, node_correction_);

  for (std::size_t s = 0; s < slots; ++s) {
    if (std::isnan(grid_temperature[s]) || group_of_slot[s] == static_cast<int>(groups.size())) {
      node_temperature_[s] = std::numeric_limits<double>::quiet_NaN();  // not a thermal node now
      continue;
    }
    node_temperature_[s] = grid_temperature[s] + node_correction_[s];
    max_node_temperature_ = std::max(max_node_temperature_, node_temperature_[s]);
  }
  max_temperature_ = max_node_temperature_;
  if (patch_area_ > 0.0 && own_patches)
    update_patches([this](std::size_t node) { return slot_of_node_[node]; }, node_correction_, node_temperature_);
}

template <int Dim>
void InterfaceTemperature<Dim>::update_patches_from(const std::vector<int>& nodes, const std::vector<double>& correction,
                                                    const std::vector<double>& temperature) {
  if (!(patch_area_ > 0.0)) return;
  if (correction.size() != nodes.size() || temperature.size() != nodes.size())
    throw std::invalid_argument("interface temperature: " + std::to_string(correction.size()) + " corrections and " +
                                std::to_string(temperature.size()) + " temperatures for " +
                                std::to_string(nodes.size()) + " heated nodes");
  patch_index_.resize(grid_->node_count(), -1);
  for (std::size_t e = 0; e < nodes.size(); ++e) patch_index_[static_cast<std::size_t>(nodes[e])] = static_cast<int>(e);
  update_patches([this](std::size_t node) { return patch_index_[node]; }, correction, temperature);
  for (const int node : nodes) patch_index_[static_cast<std::size_t>(node)] = -1;
}

// A hot spot of size ℓ: the heat of the heated nodes within ℓ/2 of node s, Σ_t A q_t ⊛ R_x, spread
// over the patch's area on their mean grid temperature. The correction is linear in the flux, so this
// is the flash temperature of the patch's mean flux; the total heat in a patch converges with the cell
// as the frictional work does, where one node's flux keeps growing as the cell resolves sharper slip.
template <int Dim>
template <class Index>
void InterfaceTemperature<Dim>::update_patches(const Index& index, const std::vector<double>& correction,
                                               const std::vector<double>& temperature) {
  const mechanics::Grid<Dim>& grid = *grid_;
  const std::size_t slots = nodes_.size();
  patch_correction_.assign(slots, 0.0);
  patch_temperature_.assign(slots, std::numeric_limits<double>::quiet_NaN());
  max_temperature_ = -std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < slots; ++s) {
    if (!std::isfinite(node_temperature_[s])) continue;
    const mechanics::IVec<Dim> centre = grid.node_lattice(nodes_[s]);
    double heat_per_area = 0.0, grid_temperature = 0.0, weight = 0.0;
    for (std::size_t j = 0; j < patch_offsets_.size(); ++j) {
      const mechanics::IVec<Dim>& o = patch_offsets_[j];
      mechanics::IVec<Dim> q{};
      bool inside = true;
      for (int d = 0; d < Dim; ++d) {
        q[d] = centre[d] + o[d];
        inside = inside && q[d] >= -mechanics::Grid<Dim>::ghost && q[d] <= grid.cells()[d] + mechanics::Grid<Dim>::ghost;
      }
      if (!inside) continue;
      const int t = index(static_cast<std::size_t>(grid.node_index(q)));
      if (t < 0 || !std::isfinite(temperature[static_cast<std::size_t>(t)])) continue;
      const auto u = static_cast<std::size_t>(t);
      heat_per_area += patch_weights_[j] * correction[u];
      grid_temperature += patch_weights_[j] * (temperature[u] - correction[u]);
      weight += patch_weights_[j];
    }
    patch_correction_[s] = heat_per_area * area_ / patch_area_;
    patch_temperature_[s] = grid_temperature / weight + patch_correction_[s];
    max_temperature_ = std::max(max_temperature_, patch_temperature_[s]);
  }
}

template <int Dim>
const thermal::SubcellCorrection& InterfaceTemperature<Dim>::correction(const std::array<int, 3>& key) {
  auto it = corrections_.find(key);
  if (it == corrections_.end()) {
    const thermal::HalfSpace& a = sides_[static_cast<std::size_t>(key[0])];
    const thermal::HalfSpace& b = sides_[static_cast<std::size_t>(key[1])];
    it = corrections_.emplace(key, thermal::SubcellCorrection(a, b, h_, 0.01 * key[2])).first;
  }
  return it->second;
}

template class InterfaceTemperature<2>;
template class InterfaceTemperature<3>;

}  // namespace frictherm::coupling
