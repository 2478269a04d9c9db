// Velocity fields and the grid momentum update: the layout of the fields' slots, the per-thread
// buffer reduction, velocity boundary conditions, p ← p + f dt (the rigid bodies' motion: rigids/).
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/simulation.hpp>

#include <cmath>
#include <sstream>

namespace frictherm::mechanics {

namespace {
// fn(s) for every slot of the deformable velocity fields: an orphaned worksharing loop per field (in a
// parallel region the slots are shared out, without one it runs them all), no barrier after it.
template <int Dim, class Fn>
void for_each_deformable_slot(const std::vector<VelocityField<Dim>>& fields, Fn&& fn) {
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const VelocityField<Dim>& F = fields[f];
    if (F.rigid) continue;
    const long b = static_cast<long>(F.first), e = static_cast<long>(F.first + F.count);
#pragma omp for schedule(static) nowait
    for (long ss = b; ss < e; ++ss) fn(static_cast<std::size_t>(ss));
  }
}
}  // namespace

template <int Dim>
void NodalFields<Dim>::resize(std::size_t n, bool with_contact) {
  mass.assign(n, 0.0);
  momentum.assign(n, Vec<Dim>::Zero());
  force.assign(n, Vec<Dim>::Zero());
  velocity.assign(n, Vec<Dim>::Zero());
  acceleration.assign(n, Vec<Dim>::Zero());
  const std::size_t nc = with_contact ? n : 0;
  mass_position.assign(nc, Vec<Dim>::Zero());
  domain.assign(nc, 0.0);
  domain_gradient.assign(nc, Vec<Dim>::Zero());
}

template <int Dim>
void NodalFields<Dim>::resize_slots(std::size_t n, bool with_contact) {
  mass.resize(n);
  momentum.resize(n);
  force.resize(n);
  velocity.resize(n);
  acceleration.resize(n);
  const std::size_t nc = with_contact ? n : 0;
  mass_position.resize(nc);
  domain.resize(nc);
  domain_gradient.resize(nc);
}

template <int Dim>
void Simulation<Dim>::enable_contact(const ContactOptions& options) {
  if (finalized_) throw std::logic_error("contact must be enabled before the simulation is finalized");
  if (!(options.position_correction >= 0.0 && options.position_correction < 2.0))
    throw std::invalid_argument("contact position correction must be in [0, 2) cell sizes");
  if (!(options.min_mass_fraction >= 0.0 && options.min_mass_fraction < 0.5))
    throw std::invalid_argument("contact min_mass_fraction must be in [0, 0.5)");
  if (!(options.boundary_spacing >= 0.0) || !std::isfinite(options.boundary_spacing))
    throw std::invalid_argument("contact boundary_spacing must be finite and >= 0 (0: half the cell size)");
  check_penalty_settings(options.default_pair, -1, -1);
  contact_setup_.enabled = true;
  contact_setup_.options = options;
  contact_setup_.pair_settings.assign(1, options.default_pair);
}

template <int Dim>
void Simulation<Dim>::set_contact_pair(int a, int b, const ContactPairSettings& settings) {
  if (!contact_setup_.enabled) throw std::logic_error("enable_contact() must come before set_contact_pair()");
  const int n = static_cast<int>(materials_.size());
  if (a < 0 || b < 0 || a >= n || b >= n || a == b) throw std::invalid_argument("contact pair needs two different materials");
  if (contact_setup_.pair_index.size() != static_cast<std::size_t>(n * n)) contact_setup_.pair_index.assign(static_cast<std::size_t>(n * n), 0);
  ContactPairSettings s = settings;
  check_penalty_settings(s, a, b);
  if (s.method == ContactMethod::multimaterial && s.normal == NormalMethod::specified) {
    const double len = s.normal_vector.head<Dim>().norm();
    if (!(len > 0.0)) throw std::invalid_argument("a specified contact normal must be non-zero");
    s.normal_vector /= len;
  }
  contact_setup_.pair_settings.push_back(s);
  ContactPairSettings flipped = s;  // the same pair seen from b: the normal points from b to a
  flipped.normal_vector = -s.normal_vector;
  contact_setup_.pair_settings.push_back(flipped);
  const int k = static_cast<int>(contact_setup_.pair_settings.size());
  contact_setup_.pair_index[static_cast<std::size_t>(a * n + b)] = k - 2;
  contact_setup_.pair_index[static_cast<std::size_t>(b * n + a)] = k - 1;
  contact_setup_.explicit_pairs.emplace_back(a, b);
}

template <int Dim>
const ContactPairSettings& Simulation<Dim>::contact_pair(int a, int b) const {
  const std::size_t n = materials_.size();
  if (contact_setup_.pair_index.size() != n * n) return contact_setup_.pair_settings.at(0);
  return contact_setup_.pair_settings.at(static_cast<std::size_t>(contact_setup_.pair_index[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)]));
}

// Without contact: one field over the whole grid shared by every deformable material (slot = node),
// rigid materials act through conditions_.rigid_mask. With contact: one field per material, laid out each step.
template <int Dim>
void Simulation<Dim>::init_fields() {
  const std::size_t nm = materials_.size();
  fields_.clear();
  layout_.field_of_material.assign(nm, -1);
  if (!contact_setup_.enabled) {
    VelocityField<Dim> f;
    f.extent = grid_.nodes_per_dim();
    f.count = grid_.node_count();
    f.index = NodeIndexer<Dim>{grid_.strides(), 0};
    fields_.push_back(f);
    for (std::size_t m = 0; m < nm; ++m)
      if (!materials_[m].is_rigid()) layout_.field_of_material[m] = 0;
    layout_.slot_node.resize(grid_.node_count());
    for (std::size_t i = 0; i < layout_.slot_node.size(); ++i) layout_.slot_node[i] = static_cast<int>(i);
    layout_.slot_node_valid = false;  // (the per-material layout is not this one)
    nodes_.resize(grid_.node_count(), false);
  } else {
    for (std::size_t m = 0; m < nm; ++m) {
      if (materials_[m].is_rigid() && materials_[m].rigid_boundary) continue;  // acts through conditions_.rigid_mask
      VelocityField<Dim> f;
      f.material = static_cast<int>(m);
      f.rigid = materials_[m].is_rigid();
      layout_.field_of_material[m] = static_cast<int>(fields_.size());
      fields_.push_back(f);
    }
    if (contact_setup_.pair_index.size() != nm * nm) contact_setup_.pair_index.assign(nm * nm, 0);
    layout_.slot_node_valid = false;
    layout_.box_lo.assign(nm, IVec<Dim>{});
    layout_.box_hi.assign(nm, IVec<Dim>{});
    contact_nodes_.node_field_count.assign(grid_.node_count(), 0);
    contact_nodes_.node_entry_cursor.assign(grid_.node_count(), -1);
    contact_books_.pair_work_first.assign(nm * nm, 0.0);
    contact_books_.pair_work_second.assign(nm * nm, 0.0);
  }
  contact_books_.work_first.assign(grid_.node_count(), 0.0);
  contact_books_.work_second.assign(grid_.node_count(), 0.0);
  layout_.field_velocity.assign(fields_.size(), Vec<Dim>::Zero());
  contact_methods_ = contact_methods_for(*this);  // with their set-up (penalty: pairs, boundary points)
}

// Each material's field covers the box [lo, hi] of nodes its particles reach, stored contiguously:
// slot = first + Σ (L_d − lo_d) stride_d. Storage only grows, so steady runs do not allocate.
// The boxes move only when particles cross cells, so most steps keep the last layout: the slot-to-node
// map is then rebuilt only when some field's box changed.
template <int Dim>
void Simulation<Dim>::layout_fields(const std::vector<IVec<Dim>>& lo, const std::vector<IVec<Dim>>& hi) {
  std::size_t total = 0;
  bool changed = false;
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    VelocityField<Dim>& F = fields_[f];
    const std::size_t m = static_cast<std::size_t>(F.material);
    changed = changed || F.first != total;
    F.first = total;
    if (layout_.material_end[m] == layout_.material_begin[m]) {
      changed = changed || F.count != 0;
      F.count = 0;
      F.extent = IVec<Dim>{};
      continue;
    }
    IVec<Dim> extent;
    for (int d = 0; d < Dim; ++d) extent[d] = hi[m][d] - lo[m][d] + 1;
    changed = changed || F.lo != lo[m] || F.extent != extent;
    F.lo = lo[m];
    F.extent = extent;
    F.index = box_indexer<Dim>(F.lo, F.extent, total, F.count);
    total += F.count;
  }
  if (nodes_.mass.size() != total) {
    nodes_.resize_slots(total, true);
    for (auto& t : threads_.nodes) t.resize_slots(total, true);
  }
  if (!changed && layout_.slot_node.size() == total && layout_.slot_node_valid) return;
  layout_.slot_node_valid = true;
  layout_.slot_node.resize(total);
  const IVec<Dim>& gs = grid_.strides();
  for (const VelocityField<Dim>& F : fields_) {
    for (std::size_t s = 0; s < F.count; ++s) {
      std::size_t r = s;
      int node = 0;
      for (int d = 0; d < Dim; ++d) {
        const int local = static_cast<int>(r % static_cast<std::size_t>(F.extent[d]));
        r /= static_cast<std::size_t>(F.extent[d]);
        node += (F.lo[d] + local) * gs[d];
      }
      layout_.slot_node[F.first + s] = node;
    }
  }
}

template <int Dim>
void Simulation<Dim>::update_partition() {
  if (!threads_.partition.matches(threads_.count, fields_.size(), p_.size()))
    threads_.partition.build(threads_.count, layout_.material_begin, layout_.material_end, layout_.field_of_material, fields_.size(), p_.size());
  if (!threads_.pass_split.matches(threads_.count, p_.size())) threads_.pass_split.reset(threads_.partition);
}

// Each thread clears the slots it scatters into: in the nodes, the fields whose first thread it is;
// in its buffer, the shared fields it holds particles of.
template <int Dim>
void Simulation<Dim>::clear_scatter_targets(int tid, Accumulated which) {
  auto clear = [&](NodalFields<Dim>& a, std::size_t b, std::size_t e) {
    const auto lo = static_cast<std::ptrdiff_t>(b), hi = static_cast<std::ptrdiff_t>(e);
    if (which.mass) std::fill(a.mass.begin() + lo, a.mass.begin() + hi, 0.0);
    if (which.momentum) std::fill(a.momentum.begin() + lo, a.momentum.begin() + hi, Vec<Dim>::Zero());
    if (which.force) std::fill(a.force.begin() + lo, a.force.begin() + hi, Vec<Dim>::Zero());
    if (which.contact_terms) {
      std::fill(a.mass_position.begin() + lo, a.mass_position.begin() + hi, Vec<Dim>::Zero());
      std::fill(a.domain.begin() + lo, a.domain.begin() + hi, 0.0);
      std::fill(a.domain_gradient.begin() + lo, a.domain_gradient.begin() + hi, Vec<Dim>::Zero());
    }
  };
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    const VelocityField<Dim>& F = fields_[f];
    if (F.count == 0) continue;
    const int first = threads_.partition.first_thread[f], last = threads_.partition.last_thread[f];
    if (tid == first)
      clear(nodes_, F.first, F.first + F.count);
    else if (tid > first && tid <= last)
      clear(threads_.nodes[static_cast<std::size_t>(tid - 1)], F.first, F.first + F.count);
  }
}

// The buffers of the threads sharing a field summed into its slots, in thread order; an orphaned
// worksharing loop per shared field (a scatter phase calls it after its barrier).
template <int Dim>
void Simulation<Dim>::sum_shared_fields(Accumulated which) {
  for (const int f : threads_.partition.shared_fields) {
    const VelocityField<Dim>& F = fields_[static_cast<std::size_t>(f)];
    const std::size_t t0 = static_cast<std::size_t>(threads_.partition.first_thread[static_cast<std::size_t>(f)]);
    const std::size_t t1 = static_cast<std::size_t>(threads_.partition.last_thread[static_cast<std::size_t>(f)]);
    const long b = static_cast<long>(F.first), e = static_cast<long>(F.first + F.count);
#pragma omp for schedule(static) nowait
    for (long ii = b; ii < e; ++ii) {
      const std::size_t i = static_cast<std::size_t>(ii);
      for (std::size_t t = t0 + 1; t <= t1; ++t) {
        const NodalFields<Dim>& buf = threads_.nodes[t - 1];
        if (which.mass) nodes_.mass[i] += buf.mass[i];
        if (which.momentum) nodes_.momentum[i] += buf.momentum[i];
        if (which.force) nodes_.force[i] += buf.force[i];
        if (which.contact_terms) {
          nodes_.mass_position[i] += buf.mass_position[i];
          nodes_.domain[i] += buf.domain[i];
          nodes_.domain_gradient[i] += buf.domain_gradient[i];
        }
      }
    }
  }
}

// Fixed components are zeroed; components driven by a rigid boundary material take its velocity; rigid
// fields (contact) take m v_rigid and no force.
template <int Dim>
double Simulation<Dim>::apply_velocity_bc(std::vector<Vec<Dim>>& momentum, std::vector<Vec<Dim>>* force, double dt,
                                          double* stop) const {
  // With `force` (the momentum update) the work of the rigid bodies on the deformable material is
  // returned: the impulse a rigid velocity condition adds, m v_rigid − (p + f dt), and the reaction of
  // a force on a rigid field (penalty contact: the slave's force on a rigid master), each dotted
  // with the rigid velocity; and into *stop the energy the conditions' stops remove from the
  // deformable fields (condition_stop_work, energy/energy_books.hpp).
  double rigid_work = 0.0;
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    const VelocityField<Dim>& F = fields_[f];
    if (!F.rigid) continue;
    const Vec<Dim> v = layout_.field_velocity[f];
    for (std::size_t s = F.first; s < F.first + F.count; ++s) {
      momentum[s] = nodes_.mass[s] * v;
      if (force) {
        rigid_work += rigid_reaction_work<Dim>((*force)[s], v, dt);  // energy/energy_books.hpp
        (*force)[s].setZero();
      }
    }
  }
  // One parallel region over the deformable fields (one per grain in a PBX: a region each would
  // cost more than their few hundred slots); one thread runs it without a team (parallel_region.hpp),
  // its sum added to `work` as the reduction clause adds it.
  double field_work = 0.0, field_stop = 0.0;
  // The start-of-step momentum the stops are measured from: the particles' (p^n of the extrapolation),
  // without the extrapolated contact pass's change, which the particles never receive.
  const std::vector<Vec<Dim>>& changed = contact_nodes_.extrapolated_change;
  const bool contact_changed = changed.size() == momentum.size();
  const auto start = [&](std::size_t s, int d) { return contact_changed ? momentum[s][d] - changed[s][d] : momentum[s][d]; };
  const auto fields_pass = [&](double& work, double& stopped) {
    for_each_deformable_slot(fields_, [&](std::size_t s) {
      const std::size_t i = static_cast<std::size_t>(layout_.slot_node[s]);
      if (const std::uint8_t driven = conditions_.rigid_mask[i]) {
        // Driven components end the step at the rigid velocity. In the momentum update the change is
        // made a force, (m v_rigid − p)/dt, so that the particles' FLIP update receives it too.
        for (int d = 0; d < Dim; ++d)
          if (driven & (1u << d)) {
            if (force)  // the kernel shared with the decomposed step (energy/energy_books.hpp)
              work += drive_component(nodes_.mass[s], momentum[s][d], (*force)[s][d], conditions_.rigid_velocity[i][d], dt,
                                      start(s, d), stopped);
            else
              momentum[s][d] = nodes_.mass[s] * conditions_.rigid_velocity[i][d];
          }
      }
      if (const std::uint8_t mask = conditions_.fixed_mask[i]) {
        for (int d = 0; d < Dim; ++d)
          if (mask & (1u << d)) {
            momentum[s][d] = 0.0;
            if (force) (*force)[s][d] = 0.0;
          }
      }
    });
  };
  // Below 2 x kSlotsPerThread slots on one thread, as the other element-wise node loops
  // (threads_for_slots): on the 1 mm twin this region was a team wake per step for ~10^4 slots
  // (grid update 27 -> 80 us/step on two threads; issue 35).
  const int threads = threads_for_slots(nodes_.mass.size(), threads_.count);
  if (without_team(threads)) {
    fields_pass(field_work, field_stop);
  } else {
#pragma omp parallel num_threads(threads) reduction(+ : field_work, field_stop)
    fields_pass(field_work, field_stop);
  }
  if (stop) *stop += field_stop;
  return rigid_work + field_work;
}

// v_i = p_i / m_i after the velocity boundary conditions on p_i; empty nodes get no velocity.
template <int Dim>
void Simulation<Dim>::velocity_from_momentum() {
  apply_velocity_bc(nodes_.momentum, nullptr, 0.0);
  const double mmin = empty_node_mass_;
  parallel_for(threads_for_slots(nodes_.mass.size(), threads_.count), nodes_.mass.size(), [&](std::size_t i) {
    nodes_.velocity[i] = nodes_.mass[i] > mmin ? Vec<Dim>(nodes_.momentum[i] / nodes_.mass[i]) : Vec<Dim>::Zero();
  });
}

// The grid update p_i^{n+1} = p_i^n + f_i dt after the velocity conditions on both, in phases (the
// step's lists, simulation_step.cpp); with contact, contact is resolved on p^{n+1} with consistent
// forces (Nairn 2018 eq. 19) between advance_grid_momentum and nodal_velocities, which then gives
// v_i^{n+1} = p_i^{n+1}/m_i, a_i = f_i/m_i.

// XPIC filters v^n, the velocity p^n/m the momentum update starts from.
template <int Dim>
void Simulation<Dim>::save_start_velocity() {
  const double mmin = empty_node_mass_;
  const std::size_t n = nodes_.mass.size();
  transfer_.start.resize(n);
  parallel_for(threads_for_slots(n, threads_.count), n, [&](std::size_t i) {
    transfer_.start[i] = nodes_.mass[i] > mmin ? Vec<Dim>(nodes_.momentum[i] / nodes_.mass[i]) : Vec<Dim>::Zero();
  });
}

template <int Dim>
void Simulation<Dim>::apply_grid_velocity_conditions(double dt) {
  work_books_.rigid += apply_velocity_bc(nodes_.momentum, &nodes_.force, dt, &work_books_.boundary_stop);
}

// Mass-proportional damping force −c m_i v_i = −c p_i, taken at the step's start momentum
// (explicit: stable for c dt < 2; the scene checks c dt_max < 1). After the velocity conditions,
// on the components they leave free (the same forces as damping first: the conditions replace the
// force of the components they set, and fixed ones have p = 0), so that its work, c p²/m dt per
// component, is the energy it removes. The node's kernel is damp_node (loads/grid_loads.hpp), shared
// with the decomposed step.
template <int Dim>
void Simulation<Dim>::apply_damping(double dt) {
  if (!damping_active(opt_.damping_rate, opt_.damping_until, clock_.time)) return;
  const double c = opt_.damping_rate, mmin_damped = empty_node_mass_;
  double damped = 0.0;
  const auto damp_pass = [&](double& removed) {
    for_each_deformable_slot(fields_, [&](std::size_t s) {
      const std::uint8_t driven = conditions_.rigid_mask[static_cast<std::size_t>(layout_.slot_node[s])];
      damp_node<Dim>(nodes_.force[s], nodes_.momentum[s], nodes_.mass[s], driven, c, dt, mmin_damped, removed);
    });
  };
  const int threads = threads_for_slots(nodes_.mass.size(), threads_.count);  // as apply_velocity_bc
  if (without_team(threads)) {  // without a team (parallel_region.hpp)
    damp_pass(damped);
  } else {
#pragma omp parallel num_threads(threads) reduction(+ : damped)
    damp_pass(damped);
  }
  work_books_.damping += damped;
}

template <int Dim>
void Simulation<Dim>::advance_grid_momentum(double dt) {
  const std::size_t n = nodes_.mass.size();
  parallel_for(threads_for_slots(n, threads_.count), n, [&](std::size_t i) { nodes_.momentum[i] += nodes_.force[i] * dt; });
}

template <int Dim>
void Simulation<Dim>::nodal_velocities() {
  const double mmin = empty_node_mass_;
  const std::size_t n = nodes_.mass.size();
  // Nodes driven by a rigid boundary material keep its prescribed velocity components (the force was
  // zeroed consistently, so only the velocity needs resetting when the prescribed velocity changes).
  parallel_for(threads_for_slots(n, threads_.count), n, [&](std::size_t s) {
    const double m = nodes_.mass[s];
    if (m > mmin) {
      nodes_.velocity[s] = nodes_.momentum[s] / m;
      nodes_.acceleration[s] = nodes_.force[s] / m;
      const std::size_t i = static_cast<std::size_t>(layout_.slot_node[s]);
      if (const std::uint8_t driven = conditions_.rigid_mask[i])
        for (int d = 0; d < Dim; ++d)
          if (driven & (1u << d)) nodes_.velocity[s][d] = conditions_.rigid_velocity[i][d];
    } else {
      nodes_.velocity[s].setZero();
      nodes_.acceleration[s].setZero();
    }
  });
  for (std::size_t f = 0; f < fields_.size(); ++f)
    if (fields_[f].rigid)
      for (std::size_t s = fields_[f].first; s < fields_[f].first + fields_[f].count; ++s) nodes_.velocity[s] = layout_.field_velocity[f];
}

template <int Dim>
void Simulation<Dim>::check_particle(long bad, double /*dt*/) const {
  long k = bad;
  // Rigid particles are checked here; particles are grouped by material (finalize), so only the rigid
  // materials' ranges are visited, and the first one found is the lowest index as before.
  for (std::size_t m = 0; k < 0 && m < materials_.size(); ++m) {
    if (!materials_[m].is_rigid()) continue;
    for (std::size_t j = layout_.material_begin[m]; j < layout_.material_end[m]; ++j)
      if (!grid_.contains(p_.position[j]) && (k < 0 || static_cast<long>(j) < k)) {
        k = static_cast<long>(j);
        break;
      }
  }
  if (k < 0) return;
  const std::size_t u = static_cast<std::size_t>(k);
  std::ostringstream msg;
  msg.precision(6);
  const bool finite = p_.velocity[u].allFinite() && p_.position[u].allFinite();
  msg << "step " << clock_.step << ", t = " << clock_.time << " s: particle " << k << " of body '"
      << bodies_.info[static_cast<std::size_t>(p_.body[u])].name << "' ";
  if (!finite) {
    msg << "has a non-finite velocity or position (the step blew up; try a smaller CFL factor)";
  } else {
    msg << "left the grid at (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << p_.position[u][d];
    msg << ") m; grid spans (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << grid_.lo()[d];
    msg << ") to (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << grid_.hi()[d];
    msg << ") m";
  }
  throw SimulationError(msg.str(), clock_.step, clock_.time, k);
}

// A particle compressed past the limit of its Hugoniot in the stress update (simulation_step.cpp).
template <int Dim>
void Simulation<Dim>::throw_beyond_hugoniot(long beyond) const {
  if (beyond >= 0) {
    const std::size_t k = static_cast<std::size_t>(beyond);
    std::ostringstream msg;
    msg << "step " << clock_.step << ", t = " << clock_.time << " s: particle " << beyond << " of material '"
        << materials_[static_cast<std::size_t>(p_.material[k])].name
        << "' is compressed past the limit of its Hugoniot (J = " << p_.volume[k] / p_.initial_volume[k]
        << "; try a smaller CFL factor)";
    throw SimulationError(msg.str(), clock_.step, clock_.time, beyond);
  }
}

template struct NodalFields<2>;
template struct NodalFields<3>;
#define FRICTHERM_INSTANTIATE_FIELDS(D)                                                                       \
  template void Simulation<D>::enable_contact(const ContactOptions&);                                         \
  template void Simulation<D>::set_contact_pair(int, int, const ContactPairSettings&);                        \
  template const ContactPairSettings& Simulation<D>::contact_pair(int, int) const;                            \
  template void Simulation<D>::init_fields();                                                                 \
  template void Simulation<D>::layout_fields(const std::vector<IVec<D>>&, const std::vector<IVec<D>>&);      \
  template void Simulation<D>::update_partition();                                                            \
  template void Simulation<D>::clear_scatter_targets(int, Accumulated);                                      \
  template void Simulation<D>::sum_shared_fields(Accumulated);                                               \
  template double Simulation<D>::apply_velocity_bc(std::vector<Vec<D>>&, std::vector<Vec<D>>*, double, double*) const;       \
  template void Simulation<D>::velocity_from_momentum();                                                      \
  template void Simulation<D>::save_start_velocity();                                                         \
  template void Simulation<D>::apply_grid_velocity_conditions(double);                                        \
  template void Simulation<D>::apply_damping(double);                                                         \
  template void Simulation<D>::advance_grid_momentum(double);                                                 \
  template void Simulation<D>::nodal_velocities();                                                            \
  template void Simulation<D>::check_particle(long, double) const;                                            \
  template void Simulation<D>::throw_beyond_hugoniot(long) const;
FRICTHERM_INSTANTIATE_FIELDS(2)
FRICTHERM_INSTANTIATE_FIELDS(3)
#undef FRICTHERM_INSTANTIATE_FIELDS

}  // namespace frictherm::mechanics
