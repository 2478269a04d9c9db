#pragma once
// The coupling layer of a decomposed run (issue 16): what needs every rank's particles at once —
// hot spots across rank boundaries and the output.
// Library target frictherm::coupling_mpi (coupling/src/distributed/), built when MPI is found; its
// header needs MPI only.
//
// Hot spots across rank boundaries: each rank finds its hot particles (HotSpotTracker::candidates,
// indexed by global particle id), the candidates of all ranks are gathered on every rank (one
// MPI_Allgatherv of fixed-size records: only hot particles travel) and every rank clusters the same
// list sorted by global id, so a hot spot straddling ranks is one hot spot with the same id, members
// and measures on every rank, those of a serial tracker given the particles in id order whatever the
// partition, and the tracking from one update to the next works as in a serial run. 2D and 3D; a
// decomposed run's own particles reach it through DecomposedHeat::update_hot_spots (decomposed_heat.hpp).
#include <frictherm/coupling/hotspots.hpp>

#include <mpi.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling {

/// Every rank's candidates, in rank order, on every rank (collective).
std::vector<HotCandidate> gather_hot_candidates(MPI_Comm comm, const std::vector<HotCandidate>& local);

/// One tracker update of a decomposed run (collective): this rank's particles with their global ids
/// (below `global_particle_count`) and reference temperatures T0_p; the tracker then holds the hot
/// spots of all ranks (particles named by global id) and the highest temperature over all ranks.
/// `criterion` (this rank's particles, or nullptr): the temperature each particle is judged by instead
/// of T_p (HotSpotTracker::candidates: the sub-cell interface temperature).
template <int Dim>
void update_hot_spots_across_ranks(MPI_Comm comm, HotSpotTracker& tracker, const mechanics::Particles<Dim>& local,
                                   const std::vector<std::int64_t>& global_ids,
                                   const std::vector<double>& reference_temperature,
                                   const std::vector<ThermalProperties>& materials,
                                   std::size_t global_particle_count, double time,
                                   const std::vector<double>* criterion = nullptr);

/// One rank's particles for a snapshot of a decomposed run (n particles).
struct DecomposedSnapshot {
  std::vector<std::int64_t> id;     // global ids
  std::vector<double> position;     // n × dim, m
  std::vector<double> velocity;     // n × dim, m/s
  std::vector<double> temperature;  // n, K (empty: not written)
  std::vector<int> material;        // n
  /// More per-particle fields by name (n × components each; the same names on every rank), e.g. the
  /// interface temperature or the serial snapshot's displacement and stress: datasets beside
  /// `temperature` and XDMF attributes.
  struct Field {
    Field(std::string field_name, std::vector<double> field_values, int field_components = 1)
        : name(std::move(field_name)), values(std::move(field_values)), components(field_components) {}
    std::string name;
    std::vector<double> values;
    int components = 1;
  };
  std::vector<Field> fields;
  /// Integer per-particle fields (n each), e.g. the body index.
  std::vector<std::pair<std::string, std::vector<int>>> integer_fields;
  /// The thermal grid's nodes this rank owns (the serial /nodes/<number>: position, temperature,
  /// heat_capacity, lattice; node_field as H5Output's): written to /nodes/<number> of the rank file
  /// and drawn by BASE_nodes.xdmf. Empty on every rank: no nodes (a run without heat).
  struct NodeField {
    std::string name;
    std::vector<double> values;          // n × components (integer false)
    std::vector<std::int32_t> integers;  // n × components (integer true)
    int components = 1;
    bool integer = false;
  };
  std::vector<NodeField> node_fields;
  std::size_t nodes = 0;
  void node_field(const std::string& name, const double* data, std::size_t n, int components) {
    node_fields.push_back({name, std::vector<double>(data, data + n * static_cast<std::size_t>(components)), {},
                           components, false});
    nodes = n;
  }
  void node_field(const std::string& name, const std::int32_t* data, std::size_t n, int components) {
    node_fields.push_back({name, {}, std::vector<std::int32_t>(data, data + n * static_cast<std::size_t>(components)),
                           components, true});
    nodes = n;
  }
};

/// Particle snapshots of a decomposed run (issue 16 item 3): one HDF5 file per rank,
/// BASE.rank<r>.h5, written by that rank alone with the serial HDF5 library, and one XDMF file,
/// BASE.xdmf, written by rank 0, that joins them: per snapshot a spatial collection of the ranks'
/// grids inside one temporal collection, which ParaView (Xdmf3ReaderS) opens as one data set per
/// time (one block per rank with particles; the global ids as a 64-bit attribute; tests/coupling/
/// vtk_decomposed.py opens it with ParaView's reader). Vectors are written with 3 components in 2D
/// too (ParaView's vector filters need 3). The
/// XDMF is rewritten atomically after each snapshot and each rank file flushed, so a run stopped at
/// any point leaves readable files of what it wrote; with `write_xdmf` false it is not written at all
/// and xdmf_text() is published by the caller with its result (a decomposed run's OUT.xdmf goes with
/// OUT.h5, issue 34: never an XDMF beside a result it does not belong to). Every call is collective; a failure on one rank
/// (e.g. a file that exists without `overwrite`) makes every rank throw.
class DecomposedOutput {
 public:
  DecomposedOutput(MPI_Comm comm, std::string base, int dim, bool overwrite, bool write_xdmf = true);
  /// Resuming a checkpointed run: opens the existing rank files (each rank its own), removes their
  /// snapshots from number `kept` on (written after the checkpoint) and goes on after the kept ones;
  /// `grids` (rank 0) is xdmf_grids() at the checkpoint, and OUT.xdmf is rewritten from it.
  /// `create_missing` (a checkpoint of fewer ranks): a rank without a file starts one.
  DecomposedOutput(MPI_Comm comm, std::string base, int dim, long kept, std::vector<std::string> grids,
                   bool create_missing = false, bool write_xdmf = true);
  /// Rank 0: the XDMF text of every snapshot so far (checkpoints store it); snapshots written.
  const std::vector<std::string>& xdmf_grids() const { return grids_; }
  /// Rank 0: the XDMF document joining every snapshot so far (what BASE.xdmf holds).
  std::string xdmf_text() const;
  /// Rank 0: the same grids drawn at the particles' reference positions (geometry initial_position,
  /// the serial RUN_reference.xdmf) for the snapshots that hold initial_position; "" without any.
  /// Checkpoints store reference_grids(); a resumed run gives them back (restore_reference_grids).
  const std::vector<std::string>& reference_grids() const { return reference_grids_; }
  void restore_reference_grids(std::vector<std::string> grids) { reference_grids_ = std::move(grids); }
  std::string reference_xdmf_text() const;
  /// Rank 0: the thermal grid's nodes of every snapshot that has them (the serial RUN_nodes.xdmf,
  /// collection "thermal_nodes": a spatial collection of the ranks' /nodes/<number> per snapshot);
  /// "" without any. Checkpoints store node_grids(); a resumed run gives them back.
  const std::vector<std::string>& node_grids() const { return node_grids_; }
  void restore_node_grids(std::vector<std::string> grids) { node_grids_ = std::move(grids); }
  std::string nodes_xdmf_text() const;
  long snapshots() const { return snapshots_; }
  ~DecomposedOutput();
  DecomposedOutput(const DecomposedOutput&) = delete;
  DecomposedOutput& operator=(const DecomposedOutput&) = delete;

  void write(long step, double time, const DecomposedSnapshot& particles);
  /// Closes the rank files (also done by the destructor).
  void close();

  const std::string& xdmf_path() const { return xdmf_path_; }
  std::string rank_file(int rank) const;
  static std::string rank_file(const std::string& base, int rank);

 private:
  /// The constructors' end: every rank learns whether any failed; on failure the files are closed.
  void agree_or_close(const std::string& error);
  /// write's thermal nodes (collective): /nodes/<index> of each rank file and their XDMF grids.
  void write_nodes(long step, double time, const std::string& index, const DecomposedSnapshot& snapshot);
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1, dim_ = 2;
  std::string base_, xdmf_path_;
  long long file_ = -1;              // hid_t of this rank's file
  std::vector<std::string> grids_;  // rank 0: the XDMF text of every snapshot so far
  std::vector<std::string> reference_grids_;  // rank 0: the same at the reference positions
  std::vector<std::string> node_grids_;       // rank 0: the thermal nodes' grids
  bool write_xdmf_ = true;          // rank 0 rewrites BASE.xdmf after every snapshot
  long snapshots_ = 0;
};

}  // namespace frictherm::coupling
