#pragma once
// Explicit MPM for single-velocity-field bodies (contact comes in its own module).
//
// Update schemes (Buzzi et al. 2008; Nairn 2003):
//   USF  - stress updated from the extrapolated nodal velocities before the forces are computed;
//   USL  - stress updated after the momentum update, from the new nodal velocities;
//   MUSL - USL, but the new particle velocities are mapped back to the grid first (default: it
//          removes the small-mass-node noise of USL while keeping its energy behaviour).
// Time step: dt = C * min(h) / max_p (c_p + |v_p|), with C the CFL factor and c_p the particle's
// dilatational wave speed (Nairn 2018 eq. 45 with the particle speed added).
#include <frictherm/mechanics/geometry.hpp>
#include <frictherm/mechanics/grid.hpp>
#include <frictherm/mechanics/loads.hpp>
#include <frictherm/mechanics/material.hpp>
#include <frictherm/mechanics/particles.hpp>
#include <frictherm/mechanics/shape_functions.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace frictherm::mechanics {

enum class UpdateScheme { usf, usl, musl };
UpdateScheme update_scheme_from_string(const std::string& name);  // throws std::invalid_argument
const char* to_string(UpdateScheme s);

struct SimulationOptions {
  Analysis analysis = Analysis::plane_strain;  // 2D: plane_strain or plane_stress; 3D: three_d
  double thickness = 1.0;                      // 2D out-of-plane thickness (m)
  ShapeKind shape = ShapeKind::ugimp;
  UpdateScheme scheme = UpdateScheme::musl;
  double cfl = 0.5;                            // C in (0, 1]
  double max_time_step = std::numeric_limits<double>::infinity();
  Vec<3> gravity = Vec<3>::Zero();             // body force per unit mass (m/s^2)
};

/// Nodal fields of the background grid (one velocity field).
template <int Dim>
struct NodalFields {
  std::vector<double> mass;
  std::vector<Vec<Dim>> momentum;
  std::vector<Vec<Dim>> force;
  std::vector<Vec<Dim>> velocity;      // v_i^{n+1} after the momentum update
  std::vector<Vec<Dim>> acceleration;  // (p^{n+1} - p^n) / (m dt), boundary conditions applied
  void resize(std::size_t n);
  void clear_accumulators();
};

struct BodyInfo {
  std::string name;
  std::size_t particle_count = 0;
};

template <int Dim>
class Simulation {
 public:
  explicit Simulation(const Grid<Dim>& grid, const SimulationOptions& options = {});

  // ---- set-up -----------------------------------------------------------------------------
  int add_material(const Material& m);
  /// Fills `region` with particles on a regular lattice of `ppc` points per cell per direction.
  /// Points already taken by an earlier body are skipped. Returns the body id.
  int add_body(const std::string& name, const Region<Dim>& region, int ppc, const Vec<Dim>& velocity,
               double temperature = 293.15);
  void fix_face(const FixedFace& face);
  void add_point_load(const PointLoad<Dim>& load);
  void add_edge_traction(const EdgeTraction<Dim>& load);
  /// Groups particles by material and resolves loads; called by the first step if not before.
  void finalize();

  // ---- stepping ---------------------------------------------------------------------------
  /// Stable time step from the CFL condition at the current state.
  double stable_time_step() const;
  /// Advances one step of min(stable_time_step, dt_limit); returns the step taken.
  /// Throws SimulationError if the new state has non-finite values or a particle left the grid.
  double step(double dt_limit = std::numeric_limits<double>::infinity());

  // ---- state ------------------------------------------------------------------------------
  const Grid<Dim>& grid() const { return grid_; }
  const SimulationOptions& options() const { return opt_; }
  SimulationOptions& options() { return opt_; }
  const Particles<Dim>& particles() const { return p_; }
  Particles<Dim>& particles() { return p_; }
  const NodalFields<Dim>& nodes() const { return nodes_; }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<BodyInfo>& bodies() const { return bodies_; }
  double time() const { return time_; }
  long step_count() const { return step_; }
  double last_time_step() const { return last_dt_; }

  double kinetic_energy() const;  // of deformable particles (J)
  double strain_energy() const;   // J
  Vec<Dim> linear_momentum() const;  // of deformable particles (kg m/s)
  /// Work done by external loads and body force so far (J), accumulated each step.
  double external_work() const { return external_work_; }

 private:
  template <class Kernel> void step_with(double dt);
  template <class Kernel> void map_to_grid(double dt, bool with_forces);
  template <class Kernel> void add_internal_forces();
  template <class Kernel> void map_rigid_particles(double t);
  template <class Kernel> void map_external_loads(double t);
  template <class Kernel> void remap_momentum();
  template <class Kernel> void update_stress(const std::vector<Vec<Dim>>& nodal_velocity, double dt);
  template <class Kernel> long update_particles(double dt);
  template <class Kernel> std::vector<Stencil<Dim, Kernel>>& stencils();
  void apply_velocity_bc(std::vector<Vec<Dim>>& momentum, std::vector<Vec<Dim>>* force) const;
  void update_grid(double dt);
  void velocity_from_momentum();
  void move_rigid_particles(double dt, double t);
  void check_particle(long bad, double dt) const;
  void resolve_loads();

  Grid<Dim> grid_;
  SimulationOptions opt_;
  Particles<Dim> p_;
  std::vector<Material> materials_;
  std::vector<BodyInfo> bodies_;
  std::vector<std::size_t> material_begin_, material_end_;  // particle ranges after finalize()
  NodalFields<Dim> nodes_;
  std::vector<NodalFields<Dim>> thread_nodes_;  // per-thread scatter buffers (threads 1..n-1)
  std::vector<std::uint8_t> fixed_mask_;        // bit d set: velocity component d fixed to 0
  std::vector<std::uint8_t> rigid_mask_;        // 1: node driven by a rigid material
  std::vector<Vec<Dim>> rigid_velocity_;
  std::vector<FixedFace> faces_;
  std::vector<PointLoad<Dim>> point_loads_;
  std::vector<EdgeTraction<Dim>> tractions_;
  // Resolved loads: particle index, force at scale 1, and which TimeFunction scales it.
  struct ResolvedLoad {
    std::size_t particle;
    Vec<Dim> force;
    const TimeFunction* scale;
  };
  std::vector<ResolvedLoad> resolved_loads_;
  std::vector<std::uint8_t> taken_;  // fine lattice points already filled by a body
  int taken_ppc_ = 0;
  std::vector<Stencil<Dim, LinearKernel>> st_linear_;
  std::vector<Stencil<Dim, UGIMPKernel>> st_ugimp_;
  std::vector<Stencil<Dim, QuadraticBSplineKernel>> st_quadratic_;
  bool finalized_ = false;
  double time_ = 0.0;
  long step_ = 0;
  double last_dt_ = 0.0;
  double external_work_ = 0.0;
  double empty_node_mass_ = 0.0;
  int threads_ = 1;  // OpenMP threads of this step: 1 for small problems, where threading costs more than it saves  // nodes lighter than this have no velocity (1e-12 of the heaviest particle)
};

extern template class Simulation<2>;
extern template class Simulation<3>;

}  // namespace frictherm::mechanics
