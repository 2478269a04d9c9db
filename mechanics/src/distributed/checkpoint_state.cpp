// Checkpoint state of the decomposed MPM (DecomposedMpm::checkpoint_state, restore_checkpoint_state;
// frictherm/mechanics/distributed.hpp): every registered swarm field of this rank's particles in
// swarm order (and the owned nodes' contact state), so a restored rank holds the same particles in the same order and every particle
// loop of the next step (and every sum over particles) runs as in the uninterrupted run.
#include "distributed/decomposed_state.hpp"

#include <algorithm>
#include <stdexcept>

namespace frictherm::mechanics {

using detail::petsc_check;

namespace {

// The real-valued swarm fields and their components per particle (PETSc's coordinates included).
template <int Dim>
std::vector<std::pair<const char*, int>> real_fields(int scalars) {
  std::vector<std::pair<const char*, int>> f{
      {DMSwarmPICField_coor, Dim},           {swarm_field::mass, 1},
      {swarm_field::volume, 1},              {swarm_field::volume0, 1},
      {swarm_field::velocity, Dim},          {swarm_field::half_size, Dim},
      {swarm_field::stress, Dim * Dim},      {swarm_field::stress_zz, 1},
      {swarm_field::deformation, Dim * Dim}, {swarm_field::initial_position, Dim},
      {swarm_field::plastic_strain, 1},      {swarm_field::internal_energy, 1},
      {swarm_field::plastic_work, 1},        {swarm_field::wave_speed, 1}};
  if (scalars > 0) f.emplace_back(swarm_field::scalars, scalars);
  return f;
}

// The checkpoint's name of a swarm field: without PETSc's and frictherm's prefixes.
std::string short_name(const char* field) {
  const std::string s(field);
  if (s == DMSwarmPICField_coor) return "coor";
  const std::string prefix = "frictherm_";
  return s.rfind(prefix, 0) == 0 ? s.substr(prefix.size()) : s;
}

}  // namespace

template <int Dim>
typename DecomposedMpm<Dim>::CheckpointState DecomposedMpm<Dim>::checkpoint_state() const {
  const Impl& s = *impl_;
  CheckpointState c;
  PetscInt n = 0;
  petsc_check(DMSwarmGetLocalSize(s.swarm, &n), "DMSwarmGetLocalSize");
  const auto count = static_cast<std::size_t>(n);
  for (const auto& [name, components] : real_fields<Dim>(s.scalars)) {
    double* v = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, name, nullptr, nullptr, reinterpret_cast<void**>(&v)), "DMSwarmGetField");
    c.reals.emplace_back(short_name(name), std::vector<double>(v, v + count * static_cast<std::size_t>(components)));
    DMSwarmRestoreField(s.swarm, name, nullptr, nullptr, reinterpret_cast<void**>(&v));
  }
  {
    long* id = nullptr;
    PetscInt* material = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, swarm_field::id, nullptr, nullptr, reinterpret_cast<void**>(&id)),
                "DMSwarmGetField");
    petsc_check(DMSwarmGetField(s.swarm, swarm_field::material, nullptr, nullptr, reinterpret_cast<void**>(&material)),
                "DMSwarmGetField");
    c.integers.emplace_back("id", std::vector<std::int64_t>(id, id + count));
    c.integers.emplace_back("material", std::vector<std::int64_t>(material, material + count));
    DMSwarmRestoreField(s.swarm, swarm_field::material, nullptr, nullptr, reinterpret_cast<void**>(&material));
    DMSwarmRestoreField(s.swarm, swarm_field::id, nullptr, nullptr, reinterpret_cast<void**>(&id));
  }
  c.time = s.time;
  c.cumulative_first = s.cumulative_first;
  c.cumulative_second = s.cumulative_second;
  c.external_work = s.external_work;
  c.damping_work = s.damping_work;
  c.rigid_work = s.rigid_work;
  c.contact_normal_work = s.contact_normal_work;
  c.boundary_stop_work = s.boundary_stop_work;
  c.stored_lead = s.stored_lead;
  c.stress_power = s.last_stress_power;
  c.stress_dt = s.last_stress_dt;
  c.initial_energy = s.initial_energy;
  c.empty_node_mass = s.empty_node_mass;
  c.work_first = s.work_first;
  c.work_second = s.work_second;
  c.pair_first = s.pair_first;
  c.pair_second = s.pair_second;
  c.stats = {s.stats.contact_nodes, s.stats.multi_nodes, s.stats.sliding_nodes, s.stats.guarded};
  c.lagged_normal_traction = s.lagged_normal_traction;
  c.lagged_normal_step = s.lagged_normal_step;
  c.steps_taken = s.steps_taken;
  return c;
}

template <int Dim>
void DecomposedMpm<Dim>::restore_checkpoint_state(const CheckpointState& c, bool migrate) {
  Impl& s = *impl_;
  auto integers = [&](const std::string& name) -> const std::vector<std::int64_t>& {
    for (const auto& [n, v] : c.integers)
      if (n == name) return v;
    throw std::invalid_argument("decomposed mechanics: checkpoint state without '" + name + "'");
  };
  const std::vector<std::int64_t>& id = integers("id");
  const std::vector<std::int64_t>& material = integers("material");
  const std::size_t n = id.size();
  if (material.size() != n)
    throw std::invalid_argument("decomposed mechanics: checkpoint state with " + std::to_string(material.size()) +
                                " materials for " + std::to_string(n) + " ids");
  // The last step's work per owned node (empty before the first step with contact).
  const auto owned = static_cast<std::size_t>(s.owned_count());
  const std::size_t pairs = s.materials.size() * s.materials.size();
  if (c.stats.size() != 4 || (!c.work_first.empty() && c.work_first.size() != owned && !migrate) ||
      c.work_second.size() != c.work_first.size() || (!c.pair_first.empty() && c.pair_first.size() != pairs) ||
      c.pair_second.size() != c.pair_first.size() ||
      (!c.lagged_normal_traction.empty() && c.lagged_normal_traction.size() != owned) ||
      c.lagged_normal_step.size() != c.lagged_normal_traction.size())
    throw std::invalid_argument("decomposed mechanics: checkpoint state of another decomposition (owned nodes, "
                                "contact counters or lagged tractions differ)");
  const auto fields = real_fields<Dim>(s.scalars);
  for (const auto& [name, components] : fields) {
    const std::string key = short_name(name);
    const auto it = std::find_if(c.reals.begin(), c.reals.end(), [&](const auto& r) { return r.first == key; });
    if (it == c.reals.end())
      throw std::invalid_argument("decomposed mechanics: checkpoint state without '" + key + "'");
    if (it->second.size() != n * static_cast<std::size_t>(components))
      throw std::invalid_argument("decomposed mechanics: checkpoint field '" + key + "' holds " +
                                  std::to_string(it->second.size()) + " values (expected " +
                                  std::to_string(n * static_cast<std::size_t>(components)) + ")");
  }
  // Same particles on the same rank: no migration (which would reorder them).
  petsc_check(DMSwarmSetLocalSizes(s.swarm, static_cast<PetscInt>(n), 64), "DMSwarmSetLocalSizes");
  for (const auto& [name, components] : fields) {
    const std::string key = short_name(name);
    const auto& values = std::find_if(c.reals.begin(), c.reals.end(), [&](const auto& r) { return r.first == key; })->second;
    double* v = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, name, nullptr, nullptr, reinterpret_cast<void**>(&v)), "DMSwarmGetField");
    std::copy(values.begin(), values.end(), v);
    DMSwarmRestoreField(s.swarm, name, nullptr, nullptr, reinterpret_cast<void**>(&v));
  }
  {
    long* ids = nullptr;
    PetscInt* mats = nullptr;
    PetscInt* dest = nullptr;
    petsc_check(DMSwarmGetField(s.swarm, swarm_field::id, nullptr, nullptr, reinterpret_cast<void**>(&ids)),
                "DMSwarmGetField");
    petsc_check(DMSwarmGetField(s.swarm, swarm_field::material, nullptr, nullptr, reinterpret_cast<void**>(&mats)),
                "DMSwarmGetField");
    petsc_check(DMSwarmGetField(s.swarm, DMSwarmField_rank, nullptr, nullptr, reinterpret_cast<void**>(&dest)),
                "DMSwarmGetField");
    for (std::size_t k = 0; k < n; ++k) {
      ids[k] = static_cast<long>(id[k]);
      mats[k] = static_cast<PetscInt>(material[k]);
      dest[k] = s.rank;
    }
    DMSwarmRestoreField(s.swarm, DMSwarmField_rank, nullptr, nullptr, reinterpret_cast<void**>(&dest));
    DMSwarmRestoreField(s.swarm, swarm_field::material, nullptr, nullptr, reinterpret_cast<void**>(&mats));
    DMSwarmRestoreField(s.swarm, swarm_field::id, nullptr, nullptr, reinterpret_cast<void**>(&ids));
  }
  s.time = c.time;
  s.cumulative_first = c.cumulative_first;
  s.cumulative_second = c.cumulative_second;
  s.external_work = c.external_work;
  s.damping_work = c.damping_work;
  s.rigid_work = c.rigid_work;
  s.contact_normal_work = c.contact_normal_work;
  s.boundary_stop_work = c.boundary_stop_work;
  s.stored_lead = c.stored_lead;
  s.last_stress_power = c.stress_power;
  s.last_stress_dt = c.stress_dt;
  s.initial_energy = c.initial_energy;
  s.empty_node_mass = c.empty_node_mass;
  s.work_first = c.work_first;
  s.work_second = c.work_second;
  s.pair_first = c.pair_first;
  s.pair_second = c.pair_second;
  s.stats = DecomposedContactStats{c.stats[0], c.stats[1], c.stats[2], c.stats[3]};
  s.lagged_normal_traction = c.lagged_normal_traction;  // empty: resolve_contact starts them fresh (NaN)
  s.lagged_normal_step = c.lagged_normal_step;
  s.steps_taken = c.steps_taken;
  s.current_valid = false;
  if (migrate) {
    const long sent = s.traffic.particles_sent, received = s.traffic.particles_received;
    s.migrate(0.0);
    s.traffic.particles_sent = sent, s.traffic.particles_received = received;  // not a step
  }
}

#define FRICTHERM_INSTANTIATE_CHECKPOINT(D)                                                                \
  template DecomposedMpm<D>::CheckpointState DecomposedMpm<D>::checkpoint_state() const;                  \
  template void DecomposedMpm<D>::restore_checkpoint_state(const CheckpointState&, bool);
FRICTHERM_INSTANTIATE_CHECKPOINT(2)
FRICTHERM_INSTANTIATE_CHECKPOINT(3)
#undef FRICTHERM_INSTANTIATE_CHECKPOINT

}  // namespace frictherm::mechanics
