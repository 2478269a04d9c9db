// State of the decomposed 2D MPM (frictherm/mechanics/distributed.hpp): the DMDA of the grid's nodes
// with its local (ghosted) and global vectors, the DMSwarm of the particles and a scoped view of the
// swarm's fields. Internal header.
#pragma once

#include "frictherm/mechanics/distributed.hpp"
#include "distributed/petsc_check.hpp"

#include <petscdmda.h>
#include <petscdmswarm.h>

#include <array>
#include <vector>

namespace frictherm::mechanics {

namespace swarm_field {
// Registered fields (DMSwarmRegisterPetscDatatypeField) besides PETSc's own DMSwarmPIC_coor (x_p),
// DMSwarm_pid, DMSwarm_rank and DMSwarm_cellid. Tensors are 2×2 column-major (Eigen's layout).
inline constexpr const char* id = "frictherm_id";
inline constexpr const char* mass = "frictherm_mass";
inline constexpr const char* volume = "frictherm_volume";
inline constexpr const char* volume0 = "frictherm_volume0";
inline constexpr const char* velocity = "frictherm_velocity";
inline constexpr const char* half_size = "frictherm_half_size";
inline constexpr const char* stress = "frictherm_stress";
inline constexpr const char* stress_zz = "frictherm_stress_zz";
inline constexpr const char* deformation = "frictherm_F";
}  // namespace swarm_field

/// Degrees of freedom per node in both grid exchanges: after particle_to_grid (m, p_x, p_y, f_x, f_y),
/// after grid_update (m, v_x, v_y, a_x, a_y) in the same slots.
namespace node_dof {
inline constexpr int count = 5, mass = 0, momentum = 1, force = 3, velocity = 1, acceleration = 3;
}

/// Every registered field of the swarm, gotten for the object's lifetime (no migration meanwhile).
struct SwarmFields {
  DM sw;
  PetscInt n = 0;
  double* x = nullptr;  // DMSwarmPIC_coor, 2 per particle
  long* id = nullptr;
  double *mass = nullptr, *volume = nullptr, *volume0 = nullptr, *velocity = nullptr, *half_size = nullptr;
  double *stress = nullptr, *stress_zz = nullptr, *F = nullptr;

  explicit SwarmFields(DM swarm);
  ~SwarmFields();
  /// f(name, pointer) for every field the step reads, in one list for getting and restoring.
  template <class Visit>
  void each_field(Visit&& f) {
    f(DMSwarmPICField_coor, x);
    f(swarm_field::id, id);
    f(swarm_field::mass, mass);
    f(swarm_field::volume, volume);
    f(swarm_field::volume0, volume0);
    f(swarm_field::velocity, velocity);
    f(swarm_field::half_size, half_size);
    f(swarm_field::stress, stress);
    f(swarm_field::stress_zz, stress_zz);
    f(swarm_field::deformation, F);
  }
  SwarmFields(const SwarmFields&) = delete;
  SwarmFields& operator=(const SwarmFields&) = delete;
};

struct DecomposedMpm2D::Impl {
  MPI_Comm comm = MPI_COMM_NULL;
  int rank = 0, size = 1;
  Grid<2> grid;
  Material material;
  DecomposedOptions opt;
  int width = 1;  // DMDA stencil width (stencil_reach)
  DM da = nullptr, swarm = nullptr;
  ::Vec local = nullptr, global = nullptr;  // PETSc vectors (mechanics::Vec is the Eigen one)
  PetscInt xs = 0, ys = 0, xm = 0, ym = 0;      // owned nodes
  PetscInt gxs = 0, gys = 0, gxm = 0, gym = 0;  // ghosted box
  PetscInt procs[2] = {1, 1};
  std::array<std::vector<PetscInt>, 2> starts;  // first owned node per process column / row, + end
  double empty_node_mass = 0.0;                 // 1e-12 of the largest particle mass (as the serial step)
  DecomposedTraffic traffic;
  std::vector<Stencil<2, LinearKernel>> stencils_linear;
  std::vector<Stencil<2, UGIMPKernel>> stencils_ugimp;
  std::vector<Stencil<2, QuadraticBSplineKernel>> stencils_quadratic;

  ~Impl();

  template <class Kernel>
  std::vector<Stencil<2, Kernel>>& stencils() {
    if constexpr (std::is_same_v<Kernel, LinearKernel>) return stencils_linear;
    else if constexpr (std::is_same_v<Kernel, UGIMPKernel>) return stencils_ugimp;
    else return stencils_quadratic;
  }
  /// Local-vector node index of a stencil's nodes (ghosted box, x fastest).
  NodeIndexer<2> local_indexer() const {
    return NodeIndexer<2>{{1, static_cast<int>(gxm)}, -static_cast<int>(gys * gxm + gxs)};
  }
  /// The rank owning the node nearest to x.
  int owner_of(const double* x) const;

  // The phases (usl_phases.cpp) and the migration (decomposition.cpp).
  template <class Kernel>
  void particle_to_grid(double dt);
  void sum_to_owners(double dt);
  void grid_update(double dt);
  void ghost_velocities(double dt);
  template <class Kernel>
  void grid_to_particle(double dt);
  template <class Kernel>
  void stress_update(double dt);
  void migrate(double dt);
};

}  // namespace frictherm::mechanics
