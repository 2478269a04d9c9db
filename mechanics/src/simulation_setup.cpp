// Simulation set-up: materials, bodies filled with particles, boundary conditions and loads.
#include <frictherm/mechanics/loads/grid_loads.hpp>
#include <frictherm/mechanics/parallel_region.hpp>
#include <frictherm/mechanics/simulation.hpp>
#include <frictherm/mechanics/time_step/cfl_time_step.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace frictherm::mechanics {

UpdateScheme update_scheme_from_string(const std::string& name) {
  if (name == "usf") return UpdateScheme::usf;
  if (name == "usl") return UpdateScheme::usl;
  if (name == "musl") return UpdateScheme::musl;
  throw std::invalid_argument("unknown update scheme '" + name + "' (expected usf, usl or musl)");
}

const char* to_string(UpdateScheme s) {
  switch (s) {
    case UpdateScheme::usf: return "usf";
    case UpdateScheme::usl: return "usl";
    case UpdateScheme::musl: return "musl";
  }
  return "?";
}

template <int Dim>
Simulation<Dim>::Simulation(const Grid<Dim>& grid, const SimulationOptions& options) : grid_(grid), opt_(options) {
  if (Dim == 3) opt_.analysis = Analysis::three_d;
  if (Dim == 2 && opt_.analysis == Analysis::three_d)
    throw std::invalid_argument("a 2D simulation needs analysis plane_strain or plane_stress");
  if (!(opt_.cfl > 0.0 && opt_.cfl <= 1.0)) throw std::invalid_argument("CFL factor must be in (0, 1]");
  if (Dim == 2 && !(opt_.thickness > 0.0)) throw std::invalid_argument("thickness must be > 0");
  if (!(opt_.ebs_occupation >= 0.0) || !std::isfinite(opt_.ebs_occupation))
    throw std::invalid_argument("extended B-spline occupation parameter C_c must be finite and >= 0");
  nodes_.resize(grid_.node_count());
  conditions_.fixed_mask.assign(grid_.node_count(), 0);
  conditions_.rigid_mask.assign(grid_.node_count(), 0);
  conditions_.rigid_velocity.assign(grid_.node_count(), Vec<Dim>::Zero());
}

template <int Dim>
int Simulation<Dim>::add_material(const Material& m) {
  if (finalized_) throw std::logic_error("materials must be added before the simulation is finalized");
  if (!(m.density > 0.0)) throw std::invalid_argument("material '" + m.name + "': density must be > 0");
  if (m.is_rigid() && !m.rigid_boundary && !(m.rigid_controls[0] && m.rigid_controls[1] && m.rigid_controls[2]))
    throw std::invalid_argument("material '" + m.name + "': only a boundary rigid material may leave velocity components free");
  if (m.kind == MaterialKind::mie_gruneisen) {
    Material mg = m;
    mg.mie_gruneisen.density = m.density;
    validate(mg.mie_gruneisen, opt_.analysis, "material '" + m.name + "'");  // names the parameter
    materials_.push_back(mg);
    return static_cast<int>(materials_.size()) - 1;
  }
  if (!m.is_rigid()) {
    if (!(m.youngs_modulus > 0.0)) throw std::invalid_argument("material '" + m.name + "': E must be > 0");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      throw std::invalid_argument("material '" + m.name + "': Poisson ratio must be in (-1, 0.5)");
    if (m.kind == MaterialKind::neo_hookean && opt_.analysis == Analysis::plane_stress)
      throw std::invalid_argument("material '" + m.name + "': neo_hookean needs plane_strain or 3D");
  }
  materials_.push_back(m);
  return static_cast<int>(materials_.size()) - 1;
}

template <int Dim>
int Simulation<Dim>::add_body(const std::string& name, const Region<Dim>& region, int ppc, const Vec<Dim>& velocity,
                              double temperature) {
  if (finalized_) throw std::logic_error("bodies must be added before the simulation is finalized");
  if (ppc < 1) throw std::invalid_argument("body '" + name + "': particles per cell must be >= 1");
  if (bodies_.taken_ppc != 0 && bodies_.taken_ppc != ppc)
    throw std::invalid_argument("body '" + name + "': every body must use the same particles per cell");
  const Vec<Dim> blo = region.box_lo(), bhi = region.box_hi();
  const Vec<Dim>& h = grid_.cell_size();
  IVec<Dim> n_fine{};  // fine lattice: ppc points per cell per direction over the whole grid
  std::size_t total = 1;
  for (int d = 0; d < Dim; ++d) {
    n_fine[d] = grid_.cells()[d] * ppc;
    total *= static_cast<std::size_t>(n_fine[d]);
  }
  if (bodies_.taken.empty()) bodies_.taken.assign(total, 0);
  bodies_.taken_ppc = ppc;
  const int body_id = static_cast<int>(bodies_.info.size());
  Vec<Dim> lp;
  double V = grid_.cell_volume() / std::pow(static_cast<double>(ppc), Dim);
  if (Dim == 2) V *= opt_.thickness;
  for (int d = 0; d < Dim; ++d) lp[d] = 0.5 * h[d] / ppc;
  IVec<Dim> a_lo{}, a_hi{};
  for (int d = 0; d < Dim; ++d) {
    const double s = (blo[d] - grid_.lo()[d]) / h[d] * ppc - 0.5;
    const double e = (bhi[d] - grid_.lo()[d]) / h[d] * ppc - 0.5;
    a_lo[d] = std::max(0, static_cast<int>(std::floor(s)));
    a_hi[d] = std::min(n_fine[d] - 1, static_cast<int>(std::ceil(e)));
  }
  const std::size_t before = p_.size();
  IVec<Dim> a = a_lo;
  bool done = false;
  for (int d = 0; d < Dim; ++d)
    if (a_lo[d] > a_hi[d]) done = true;
  while (!done) {
    Vec<Dim> x;
    std::size_t flat = 0, stride = 1;
    for (int d = 0; d < Dim; ++d) {
      x[d] = grid_.lo()[d] + (a[d] + 0.5) * h[d] / ppc;
      flat += static_cast<std::size_t>(a[d]) * stride;
      stride *= static_cast<std::size_t>(n_fine[d]);
    }
    const int mat = region.material_at(x);
    if (mat >= 0 && !bodies_.taken[flat]) {
      if (mat >= static_cast<int>(materials_.size()))
        throw std::invalid_argument("body '" + name + "' refers to material id " + std::to_string(mat) +
                                    " that does not exist");
      bodies_.taken[flat] = 1;
      p_.add(x, lp, materials_[static_cast<std::size_t>(mat)].density * V, V, mat, body_id, temperature);
      p_.velocity.back() = velocity;
    }
    for (int d = 0; d < Dim; ++d) {  // odometer increment over the box of lattice points
      if (++a[d] <= a_hi[d]) break;
      a[d] = a_lo[d];
      if (d == Dim - 1) done = true;
    }
  }
  const std::size_t count = p_.size() - before;
  if (count == 0) {
    std::ostringstream msg;
    msg << "body '" << name << "' has no particles: its region lies outside the grid or in space already filled";
    throw std::invalid_argument(msg.str());
  }
  bodies_.info.push_back(BodyInfo{name, count});
  // Penalty contact: the region's boundary, sampled now (the region is not kept), and the body's
  // single material (−1 for several, e.g. an image).
  int body_mat = p_.material[before];
  for (std::size_t k = before; k < p_.size(); ++k)
    if (p_.material[k] != body_mat) body_mat = -1;
  const double spacing = contact_setup_.options.boundary_point_spacing(grid_.min_cell_size());
  body_loops_.loops.push_back(Dim == 2 ? region.boundary_loops(spacing) : std::vector<std::vector<Vec<2>>>{});
  body_loops_.spacing.push_back(spacing);
  body_loops_.material.push_back(body_mat);
  body_loops_.half_size.push_back(lp);
  body_loops_.velocity.push_back(velocity);
  return body_id;
}

template <int Dim>
void Simulation<Dim>::fix_face(const FixedFace& face) {
  if (face.axis < 0 || face.axis >= Dim) throw std::invalid_argument("fixed face axis out of range");
  conditions_.faces.push_back(face);
  const IVec<Dim>& nn = grid_.nodes_per_dim();
  for (std::size_t k = 0; k < grid_.node_count(); ++k) {
    const IVec<Dim> i = grid_.node_lattice(static_cast<int>(k));
    const int last = nn[face.axis] - 1 - 2 * Grid<Dim>::ghost;  // = cells[axis]
    const bool on = face.upper ? i[face.axis] >= last : i[face.axis] <= 0;
    if (!on) continue;
    for (int d = 0; d < Dim; ++d)
      if (face.components[static_cast<std::size_t>(d)]) conditions_.fixed_mask[k] |= static_cast<std::uint8_t>(1u << d);
  }
}

template <int Dim>
void Simulation<Dim>::add_point_load(const PointLoad<Dim>& load) {
  conditions_.point_loads.push_back(load);
  if (finalized_) resolve_loads();
}

template <int Dim>
void Simulation<Dim>::add_edge_traction(const EdgeTraction<Dim>& load) {
  if (load.axis < 0 || load.axis >= Dim) throw std::invalid_argument("traction axis out of range");
  conditions_.tractions.push_back(load);
  if (finalized_) resolve_loads();
}

template <int Dim>
void Simulation<Dim>::finalize() {
  if (finalized_) return;
  if (p_.size() == 0) throw std::invalid_argument("the simulation has no particles");
  // Group particles by material (stable, so body order is kept inside a material).
  std::vector<std::size_t> order(p_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [this](std::size_t a, std::size_t b) { return p_.material[a] < p_.material[b]; });
  p_.permute(order);
  layout_.material_begin.assign(materials_.size(), 0);
  layout_.material_end.assign(materials_.size(), 0);
  for (std::size_t m = 0, k = 0; m < materials_.size(); ++m) {
    layout_.material_begin[m] = k;
    while (k < p_.size() && p_.material[k] == static_cast<int>(m)) ++k;
    layout_.material_end[m] = k;
  }
  bodies_.taken.clear();
  bodies_.taken.shrink_to_fit();
  empty_node_mass_ = 1e-12 * *std::max_element(p_.mass.begin(), p_.mass.end());
  finalized_ = true;
  init_fields();
  resolve_loads();
}

template <int Dim>
void Simulation<Dim>::resolve_loads() {
  conditions_.resolved_loads.clear();
  const auto n = p_.size();
  for (const auto& L : conditions_.point_loads) {
    std::vector<std::size_t> chosen;
    if (L.use_box) {
      for (std::size_t k = 0; k < n; ++k) {
        if (L.body >= 0 && p_.body[k] != L.body) continue;
        bool in = true;
        for (int d = 0; d < Dim; ++d) in = in && p_.position[k][d] >= L.box_lo[d] && p_.position[k][d] <= L.box_hi[d];
        if (in) chosen.push_back(k);
      }
    } else {
      double best = std::numeric_limits<double>::infinity();
      std::size_t arg = n;
      for (std::size_t k = 0; k < n; ++k) {
        if (L.body >= 0 && p_.body[k] != L.body) continue;
        const double r = (p_.position[k] - L.point).squaredNorm();
        if (r < best) best = r, arg = k;
      }
      if (arg < n) chosen.push_back(arg);
    }
    if (chosen.empty()) throw std::invalid_argument("a point load selects no particle");
    for (std::size_t k : chosen)
      conditions_.resolved_loads.push_back({k, L.force / static_cast<double>(chosen.size()), &L.scale});
  }
  for (const auto& T : conditions_.tractions) {
    // Outer particle layer of the body on the chosen side: within half a particle of its extreme.
    double extreme = T.upper ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < n; ++k)
      if (p_.body[k] == T.body)
        extreme = T.upper ? std::max(extreme, p_.position[k][T.axis]) : std::min(extreme, p_.position[k][T.axis]);
    bool any = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (p_.body[k] != T.body) continue;
      if (std::fabs(p_.position[k][T.axis] - extreme) > 0.5 * p_.half_size[k][T.axis]) continue;
      double area = 1.0;
      for (int d = 0; d < Dim; ++d)
        if (d != T.axis) area *= 2.0 * p_.half_size[k][d];
      if (Dim == 2) area *= opt_.thickness;
      conditions_.resolved_loads.push_back({k, T.traction * area, &T.scale});
      any = true;
    }
    if (!any) throw std::invalid_argument("an edge traction selects no particle");
  }
}

template <int Dim>
std::vector<ParticleLoad<Dim>> Simulation<Dim>::particle_loads() const {
  std::vector<ParticleLoad<Dim>> loads;
  loads.reserve(conditions_.resolved_loads.size());
  for (const ResolvedLoad& L : conditions_.resolved_loads) {
    int source = 0;
    for (std::size_t i = 0; i < conditions_.point_loads.size(); ++i)
      if (L.scale == &conditions_.point_loads[i].scale) source = static_cast<int>(i);
    for (std::size_t j = 0; j < conditions_.tractions.size(); ++j)
      if (L.scale == &conditions_.tractions[j].scale) source = static_cast<int>(conditions_.point_loads.size() + j);
    loads.push_back({static_cast<std::int64_t>(L.particle), source, L.force, *L.scale});
  }
  return loads;
}

template <int Dim>
double Simulation<Dim>::stable_time_step() const {
  return time_step_for_speed(particle_speed_max());
}

// Whether the last stress update's wave speeds are every particle's: then the CFL speed is
// max_p (c_p + |v_p|) over them, which the step's particle-to-grid scatter takes on its way (it reads
// every particle with a field; the others are rigid, c_p = −∞), without a pass of its own.
template <int Dim>
bool Simulation<Dim>::wave_speeds_current() const {
  return finalized_ && wave_speeds_.ready && wave_speeds_.speed.size() == p_.size();
}

// The largest c_p + |v_p| of the deformable particles (0 without any).
template <int Dim>
double Simulation<Dim>::particle_speed_max() const {
  double cmax = 0.0;
  const std::size_t n = p_.size();
  if (wave_speeds_current()) {
    // The wave speeds of the last stress update (rigid particles: −∞; the rigid loop below counts them).
    // One thread: no team (parallel_region.hpp); a maximum is exact in any order.
    if (without_team(threads_.count)) {
      for (std::size_t k = 0; k < n; ++k) cmax = std::max(cmax, wave_speeds_.speed[k] + p_.velocity[k].norm());
    } else {
#pragma omp parallel for num_threads(threads_.count) schedule(static) reduction(max : cmax)
      for (std::size_t k = 0; k < n; ++k) cmax = std::max(cmax, wave_speeds_.speed[k] + p_.velocity[k].norm());
    }
  } else {
    // One parallel region for all materials (grains are small: see evaluate_stencils).
#pragma omp parallel num_threads(threads_.count) reduction(max : cmax)
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const Material& mat = materials_[m];
      const std::size_t b = finalized_ ? layout_.material_begin[m] : 0, e = finalized_ ? layout_.material_end[m] : n;
      if (mat.is_rigid()) continue;
#pragma omp for schedule(static) nowait
      for (std::size_t k = b; k < e; ++k) {
        if (!finalized_ && p_.material[k] != static_cast<int>(m)) continue;
        const double c = particle_wave_speed(mat, opt_.analysis, p_.volume[k] / p_.initial_volume[k], p_.internal_energy[k]);
        cmax = std::max(cmax, c + p_.velocity[k].norm());
      }
    }
  }
  return cmax;
}

// The CFL step (Nairn 2018 eq. 45) for the particles' largest c_p + |v_p|, with the rigid materials'
// speeds, the contact methods' bounds and factors and the damping bound.
template <int Dim>
double Simulation<Dim>::time_step_for_speed(double cmax) const {
  cmax = with_rigid_speeds(cmax, materials_, clock_.time);
  // The contact methods' bounds (penalty: light nodes under its springs) and wave-speed factors (a
  // penalty stiffer than the bodies), step/contact_method.hpp.
  double dt_contact = std::numeric_limits<double>::infinity(), contact_factor = 1.0;
  for (const StepContactMethod<Dim>* m : contact_methods_) {
    dt_contact = std::min(m->time_step_limit(*this, cmax), dt_contact);
    contact_factor *= m->wave_speed_factor(*this);
  }
  cmax *= contact_factor;
  const double dt_damping = damping_active(opt_.damping_rate, opt_.damping_until, clock_.time)
                                ? damping_time_step_limit(opt_.damping_rate)
                                : std::numeric_limits<double>::infinity();
  const double dt = cfl_time_step(opt_.cfl, grid_.min_cell_size(), cmax, opt_.max_time_step);
  if (cmax <= 0.0) return std::min(dt, dt_damping);
  return std::min({dt, dt_contact, dt_damping});
}

template <int Dim>
double Simulation<Dim>::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t k = 0; k < p_.size(); ++k)
    if (!materials_[static_cast<std::size_t>(p_.material[k])].is_rigid()) e += 0.5 * p_.mass[k] * p_.velocity[k].squaredNorm();
  return e;
}

template <int Dim>
Vec<Dim> Simulation<Dim>::linear_momentum() const {
  Vec<Dim> P = Vec<Dim>::Zero();
  for (std::size_t k = 0; k < p_.size(); ++k)
    if (!materials_[static_cast<std::size_t>(p_.material[k])].is_rigid()) P += p_.mass[k] * p_.velocity[k];
  return P;
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace frictherm::mechanics
