#pragma once
// The coupling layer of a decomposed run (issue 16): what needs every rank's particles at once.
// Library target frictherm::coupling_mpi (coupling/src/distributed/), built when MPI is found; its
// header needs MPI only.
//
// Hot spots across rank boundaries: each rank finds its hot particles (HotSpotTracker::candidates,
// indexed by global particle id), the candidates of all ranks are gathered on every rank (one
// MPI_Allgatherv of fixed-size records: only hot particles travel) and every rank clusters the same
// list in the same order, so a hot spot straddling ranks is one hot spot with the same id, members
// and measures on every rank, and the tracking from one update to the next works as in a serial run.
#include <frictherm/coupling/hotspots.hpp>

#include <mpi.h>

#include <cstdint>
#include <vector>

namespace frictherm::coupling {

/// Every rank's candidates, in rank order, on every rank (collective).
std::vector<HotCandidate> gather_hot_candidates(MPI_Comm comm, const std::vector<HotCandidate>& local);

/// One tracker update of a decomposed run (collective): this rank's particles with their global ids
/// (below `global_particle_count`) and reference temperatures T0_p; the tracker then holds the hot
/// spots of all ranks (particles named by global id) and the highest temperature over all ranks.
template <int Dim>
void update_hot_spots_across_ranks(MPI_Comm comm, HotSpotTracker& tracker, const mechanics::Particles<Dim>& local,
                                   const std::vector<std::int64_t>& global_ids,
                                   const std::vector<double>& reference_temperature,
                                   const std::vector<ThermalProperties>& materials,
                                   std::size_t global_particle_count, double time);

}  // namespace frictherm::coupling
