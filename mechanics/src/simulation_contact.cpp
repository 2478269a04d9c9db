// Multimaterial contact at nodes that carry two or more materials (Nairn, Bardenhagen & Smith 2018
// §2.2–2.12): normal, detection, contact area, stick change and friction law, consistent forces and
// frictional work. Sign convention in contact.hpp: n̂ points from material a to material b.
#include <frictherm/mechanics/errors.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/parallel_region.hpp>

#include "contact_extent.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace frictherm::mechanics {

using contact_detail::PairContext;

// In a named namespace, not an anonymous one: resolve_contact's lambdas capture it, and a member of
// internal linkage in their closure types draws -Wsubobject-linkage (the template has external linkage).
namespace contact_detail {

// The first contact node group (in group order, so the same on any thread count) whose friction law threw.
struct ContactFailure {
  long group = -1;
  int node = -1, material_a = -1, material_b = -1;
  std::string what;
  void keep(long g, int n, int a, int b, const char* message) {
#pragma omp critical(frictherm_contact_failure)
    if (group < 0 || g < group) group = g, node = n, material_a = a, material_b = b, what = message;
  }
};

}  // namespace contact_detail
using contact_detail::ContactFailure;

template <int Dim>
void Simulation<Dim>::resolve_contact(ContactPass pass, double dt) {
  const bool heat = pass == ContactPass::updated;
  const bool forces = pass == ContactPass::updated;
  const std::size_t nm = materials_.size();
  Vec<Dim> h = grid_.cell_size();
  const double cell_volume = grid_.cell_volume() * (Dim == 2 ? opt_.thickness : 1.0);
  if (heat) {  // this pass's counters; penalty contact's are its own (under USF set before this pass)
    ContactStats& st = contact_books_.stats;
    st.contact_nodes = st.multi_nodes = st.sliding_nodes = st.guarded = 0;
  }
  const bool regularized = contact_setup_.options.regularized();
  if (pass == ContactPass::extrapolated) contact_nodes_.extrapolated_change.assign(nodes_.mass.size(), Vec<Dim>::Zero());
  if (regularized && contact_nodes_.lagged_normal_traction.size() != grid_.node_count()) {
    contact_nodes_.lagged_normal_traction.assign(grid_.node_count(), std::numeric_limits<double>::quiet_NaN());
    contact_nodes_.lagged_normal_step.assign(grid_.node_count(), -2.0);
  }

  // The node groups of contact_nodes_.entries (find_contact_nodes): each group reads and writes only its own
  // node's slots and work entries, so groups run in parallel. Stats are counts; the pair books'
  // entries are listed per thread and added in group order afterwards, so every number is the same
  // however many threads share the groups. (Handing the groups out in chunks as threads came free, schedule
  // dynamic, made the PBX's contact phase slower: 22.1 % of the wall time against 20.0 %.)
  const long groups = static_cast<long>(contact_nodes_.groups.size()) - 1;
  const int threads = groups >= 256 ? threads_.count : 1;
  contact_nodes_.thread_work.resize(static_cast<std::size_t>(threads));
  for (auto& t : contact_nodes_.thread_work) {
    t.stats = ContactStats{};
    t.entries.clear();
    t.rigid_work.clear();
    t.normal_work.clear();
    if (heat && t.marked.size() != nm * nm) {
      t.pair_first.assign(nm * nm, 0.0), t.pair_second.assign(nm * nm, 0.0), t.marked.assign(nm * nm, 0);
      t.touched.clear();
    }
  }

  // A friction law that throws (an expression law's negative or non-finite traction) must not leave
  // the parallel region (that would end the program): the failure at the first such group is kept
  // and thrown after it as a SimulationError, the run's ordinary breakdown.
  ContactFailure failure;
  parallel_region(threads, [&] {
    ContactThreadWork& acc = contact_nodes_.thread_work[static_cast<std::size_t>(omp_get_thread_num())];
    PairContext ctx{nullptr, contact_setup_.options.separation, contact_setup_.options.position_correction, contact_setup_.options.extent_tolerance,
                    cell_volume, contact_setup_.options.area, dt, heat};
    ctx.step = static_cast<double>(clock_.step);
    ctx.light_touch_fraction = contact_setup_.options.light_touch_fraction;
    ctx.slip_length = contact_setup_.options.regularization_slip_length;
    ctx.relaxation_time = contact_setup_.options.regularization_time;
    // Per-node scratch, reused from call to call (no allocation per step once grown).
    thread_local std::vector<ContactSide<Dim>> sides;
    thread_local std::vector<int> slots, mats, entries;
    thread_local std::vector<Vec<Dim>> dps;
    auto apply = [&](int slot, const Vec<Dim>& dp) {
      nodes_.momentum[static_cast<std::size_t>(slot)] += dp;
      if (forces) nodes_.force[static_cast<std::size_t>(slot)] += dp / dt;  // eq. 19
      if (pass == ContactPass::extrapolated) contact_nodes_.extrapolated_change[static_cast<std::size_t>(slot)] += dp;
    };
    auto add_work = [&](int node, int ma, int mb, double w1, double w2) {
      if (!(std::isfinite(w1) && std::isfinite(w2))) return;  // guarded upstream; never inject NaN heat
      contact_books_.work_first[static_cast<std::size_t>(node)] += w1;
      contact_books_.work_second[static_cast<std::size_t>(node)] += w2;
      const std::size_t k = pair_book_index(ma, mb, nm);
      acc.entries.push_back({k, w1, w2});
    };
    ContactStats& stats = acc.stats;
    auto pair_of = [this](int ma, int mb) -> const ContactPairSettings& { return contact_pair(ma, mb); };

#pragma omp for schedule(static)
    for (long g = 0; g < groups; ++g) {
      const int node = contact_nodes_.entries[contact_nodes_.groups[static_cast<std::size_t>(g)]].node;
      try {
      const int guarded = gather_contact_sides(static_cast<std::size_t>(g), dt, sides, slots, mats, entries);
      if (heat) stats.guarded += guarded;
      const std::size_t count = sides.size();
      if (heat) {
        ++stats.contact_nodes;
        if (count > 2) ++stats.multi_nodes;
      }
      double* lagged_normal = regularized ? &contact_nodes_.lagged_normal_traction[static_cast<std::size_t>(node)] : nullptr;
      double* lagged_step = regularized ? &contact_nodes_.lagged_normal_step[static_cast<std::size_t>(node)] : nullptr;
      // The energy books' rigid work, in the momentum-update pass (the changes the particles receive).
      const ContactSide<Dim>* rigid = forces ? rigid_work_side(sides) : nullptr;
      double rigid_work = 0.0, normal_work = 0.0;
      contact_detail::resolve_contact_node(
          sides, mats, h, ctx, lagged_normal, lagged_step, pair_of, dps,
          [&](std::size_t j, const Vec<Dim>& dp) {
            apply(slots[j], dp);
            if (rigid) rigid_work += dp.dot(rigid->rigid_velocity);
          },
          [&](int ma, int mb, double w1, double w2) { add_work(node, ma, mb, w1, w2); },
          [&](double e) { normal_work += e; }, stats.sliding_nodes);
      if (rigid) acc.rigid_work.push_back(rigid_work);
      // The energy books' normal stop, in the momentum-update pass (the changes the particles receive).
      if (forces && normal_work != 0.0) acc.normal_work.push_back(normal_work);
      } catch (const contact_detail::ContactPairError& e) {
        failure.keep(g, node, e.material_a, e.material_b, e.what());
      } catch (const std::exception& e) {
        failure.keep(g, node, -1, -1, e.what());
      }
    }
  });
  if (failure.group >= 0) {  // "step S, t = T s: contact.pairs[0].law (materials 'a' and 'b') at node ..."
    std::ostringstream msg;
    msg.precision(6);
    msg << "step " << clock_.step << ", t = " << clock_.time << " s: ";
    if (failure.material_a >= 0) {
      const std::string& origin = contact_pair(failure.material_a, failure.material_b).origin;
      msg << (origin.empty() ? std::string("contact") : origin) << " (materials '"
          << materials_[static_cast<std::size_t>(failure.material_a)].name << "' and '"
          << materials_[static_cast<std::size_t>(failure.material_b)].name << "')";
    } else {
      msg << "contact";
    }
    const Vec<Dim> x = grid_.node_position(failure.node);
    msg << " at node " << failure.node << " (";
    for (int d = 0; d < Dim; ++d) msg << (d ? ", " : "") << x[d];
    msg << ") m: " << failure.what;
    throw SimulationError(msg.str(), clock_.step, clock_.time, -1);
  }
  if (!heat) return;
  for (const auto& t : contact_nodes_.thread_work) {
    contact_books_.stats.contact_nodes += t.stats.contact_nodes;
    contact_books_.stats.multi_nodes += t.stats.multi_nodes;
    contact_books_.stats.sliding_nodes += t.stats.sliding_nodes;
    contact_books_.stats.guarded += t.stats.guarded;
  }
  // The pair books: every thread's entries, in thread order, summed into the first thread's books,
  // then into the run's. The static schedule gives thread t the t-th contiguous run of groups, so
  // this is group order, as on one thread (a dynamic schedule would need the lists merged by group).
  ContactThreadWork& books = contact_nodes_.thread_work.front();
  for (const auto& t : contact_nodes_.thread_work) {
    for (const auto& e : t.entries) books.add(e.k, e.w1, e.w2);
    for (const double w : t.rigid_work) work_books_.rigid += w;  // group order too: the same sum on any thread count
    for (const double w : t.normal_work) work_books_.contact_normal += w;
  }
  for (const std::size_t k : books.touched) {  // (the others add zero)
    contact_books_.pair_work_first[k] += books.pair_first[k], contact_books_.pair_work_second[k] += books.pair_second[k];
    books.pair_first[k] = books.pair_second[k] = 0.0, books.marked[k] = 0;
  }
  books.touched.clear();
}

// The materials at contact node `group` above min_mass_fraction of the node's mass (lighter ones take
// no part; those under sliver_fraction are marked), with their slots, materials and entries; returns how many were left out.
template <int Dim>
int Simulation<Dim>::gather_contact_sides(std::size_t group, double dt, std::vector<ContactSide<Dim>>& sides,
                                          std::vector<int>& slots, std::vector<int>& mats, std::vector<int>& entries) const {
  const std::size_t e = contact_nodes_.groups[group], end = contact_nodes_.groups[group + 1];
  sides.clear(), slots.clear(), mats.clear(), entries.clear();
  const bool extents = contact_setup_.options.separation == SeparationMethod::extent &&
                       contact_nodes_.entry_extent_own.size() ==
                           contact_detail::kExtentDirections<Dim> * contact_nodes_.entries.size();
  double node_mass = 0.0;
  for (std::size_t q = e; q < end; ++q) node_mass += nodes_.mass[static_cast<std::size_t>(contact_nodes_.entries[q].slot)];
  int guarded = 0;
  for (std::size_t q = e; q < end; ++q) {
    const int slot = contact_nodes_.entries[q].slot;
    const std::size_t su = static_cast<std::size_t>(slot);
    if (nodes_.mass[su] < contact_setup_.options.min_mass_fraction * node_mass) {
      ++guarded;
      continue;
    }
    const std::size_t f = static_cast<std::size_t>(contact_nodes_.entries[q].field);
    ContactSide<Dim> sd;
    sd.mass = nodes_.mass[su];
    sd.momentum = nodes_.momentum[su];
    sd.force = nodes_.force[su];
    sd.mass_position = nodes_.mass_position[su];
    sd.domain = nodes_.domain[su];
    sd.domain_gradient = nodes_.domain_gradient[su];
    sd.rigid = fields_[f].rigid;
    sd.sliver = nodes_.mass[su] < contact_setup_.options.sliver_fraction * node_mass;
    if (sd.rigid) {
      const Material& mat = materials_[static_cast<std::size_t>(fields_[f].material)];
      sd.rigid_velocity = layout_.field_velocity[f];
      sd.rigid_acceleration = (mat.rigid_velocity_at(clock_.time + dt).template head<Dim>() - layout_.field_velocity[f]) / dt;
    }
    if (extents)  // contact_extents.cpp: the gap between the surfaces, −(own + partners') extents
      contact_detail::set_extent_gaps<Dim>(sd, contact_nodes_.entry_extent_own.data(),
                                           contact_nodes_.entry_extent_other.data(), q);
    sides.push_back(sd);
    slots.push_back(slot);
    mats.push_back(fields_[f].material);
    entries.push_back(static_cast<int>(q));
  }
  return guarded;
}

// Extent separation: per contact entry, the normal from its material to its partners, as
// resolve_contact will compute it (two materials: the pair's normal; more: against the lump).
template <int Dim>
void Simulation<Dim>::compute_contact_normals() {
  contact_nodes_.entry_normal.assign(contact_nodes_.entries.size(), Vec<Dim>::Zero());
  contact_nodes_.entry_extent_own.clear();  // no gap while the normals are gathered
  const long groups = static_cast<long>(contact_nodes_.groups.size()) - 1;
  const int threads = groups >= 256 ? threads_.count : 1;
  parallel_region(threads, [&] {
    thread_local std::vector<ContactSide<Dim>> sides;
    thread_local std::vector<int> slots, mats, entries;
    auto pair_of = [this](int ma, int mb) -> const ContactPairSettings& { return contact_pair(ma, mb); };
#pragma omp for schedule(static)
    for (long g = 0; g < groups; ++g) {
      gather_contact_sides(static_cast<std::size_t>(g), 1.0, sides, slots, mats, entries);
      contact_detail::side_normals(sides, mats, pair_of, [&](std::size_t a, const Vec<Dim>& n) {
        contact_nodes_.entry_normal[static_cast<std::size_t>(entries[a])] = n;
      });
    }
  });
}

template <int Dim>
double Simulation<Dim>::cumulative_frictional_work(HeatingOrder order) const {
  const auto& w = order == HeatingOrder::first ? contact_books_.pair_work_first : contact_books_.pair_work_second;
  double sum = 0.0;
  for (double x : w) sum += x;
  return sum;
}

template <int Dim>
double Simulation<Dim>::cumulative_frictional_work(HeatingOrder order, int a, int b) const {
  const auto& w = order == HeatingOrder::first ? contact_books_.pair_work_first : contact_books_.pair_work_second;
  const std::size_t nm = materials_.size();
  if (w.size() != nm * nm || a < 0 || b < 0 || static_cast<std::size_t>(a) >= nm || static_cast<std::size_t>(b) >= nm) return 0.0;
  return w[pair_book_index(a, b, nm)];
}

#define FRICTHERM_INSTANTIATE_CONTACT(D)                                              \
  template void Simulation<D>::resolve_contact(ContactPass, double);                  \
  template void Simulation<D>::compute_contact_normals();                             \
  template int Simulation<D>::gather_contact_sides(std::size_t, double, std::vector<ContactSide<D>>&,      \
                                                   std::vector<int>&, std::vector<int>&, std::vector<int>&) const; \
  template double Simulation<D>::cumulative_frictional_work(HeatingOrder) const;      \
  template double Simulation<D>::cumulative_frictional_work(HeatingOrder, int, int) const;
FRICTHERM_INSTANTIATE_CONTACT(2)
FRICTHERM_INSTANTIATE_CONTACT(3)
#undef FRICTHERM_INSTANTIATE_CONTACT

}  // namespace frictherm::mechanics
