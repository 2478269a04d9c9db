#pragma once
// Checkpoints of a decomposed run (docs/checkpoints.md, "Decomposed runs"): one HDF5 file per rank
// and one global file, written collectively and committed atomically.
//
//   OUT.h5.checkpoint                 rank 0 writes it, every rank reads it: the serial checkpoint's
//                                     root attributes (format, dimension) plus `ranks` (K) and
//                                     `generation` (g), the scene text, source and --set overrides
//                                     (checkpoint_scene), /marks (checkpoint_marks) and the global
//                                     state the caller writes (run loop, series rows, hot spots)
//   OUT.h5.checkpoint.<g>.rank<r>     rank r's state (particles in swarm order, heat per owned node)
//
// Writing generation g: every rank writes its file of generation g; once all succeeded (one
// reduction), rank 0 writes the global file to OUT.h5.checkpoint.<pid>.tmp and renames it over the
// previous one (the commit: until then the global file names generation g − 1, whose rank files are
// untouched); then every rank removes its file of generation g − 1. A kill at any moment leaves a
// global file whose rank files are all whole.
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/scene.hpp>

#include "run/checkpoint_checks.hpp"

#include <mpi.h>

#include <functional>
#include <string>
#include <vector>

namespace frictherm::coupling::detail {

/// Rank r's file of generation g beside the global checkpoint `path`.
std::string decomposed_rank_checkpoint(const std::string& path, long generation, int rank);

/// Collective: writes generation `generation` (> 0) as described above; `rank_part` on every rank
/// into its file, `global_part` on rank 0 into the global file (names relative to the file's root).
/// Throws std::runtime_error on every rank if any rank failed; the previous checkpoint stays whole.
void write_decomposed_checkpoint(MPI_Comm comm, const std::string& path, const Scene& scene, int dim, long generation,
                                 const CheckpointMarks& marks,
                                 const std::function<void(const ckpt::Writer&)>& rank_part,
                                 const std::function<void(const ckpt::Writer&)>& global_part);

/// Collective: checks the global file (format, dimension, ranks = the communicator's size), reads it
/// on every rank with `global_part` and this rank's file with `rank_part` once it passed the serial
/// checks' check_rank_file against `sizes` (issue 34); every double read must be finite but for the
/// serial sentinels. Returns the generation. Throws std::runtime_error on every rank if any rank
/// failed (the lowest failing rank's message, naming its file and the dataset).
long read_decomposed_checkpoint(MPI_Comm comm, const std::string& path, int dim, const ckpt::RankSizes& sizes,
                                const std::function<void(const ckpt::Reader&)>& rank_part,
                                const std::function<void(const ckpt::Reader&)>& global_part);

/// Collective, for a checkpoint written by another number of ranks: reads the global file on every
/// rank with `global_part`, then every rank file j of the checkpoint with `file_part(reader, j)` (each
/// rank takes what it needs: some files' particles, the heat of its owned nodes). Returns the
/// generation; throws std::runtime_error on every rank if any rank failed. Every file is checked as
/// above (`sizes.ghosted_nodes` -1: the files' ghosted boxes are another decomposition's).
long read_redistributed_checkpoint(MPI_Comm comm, const std::string& path, int dim, const ckpt::RankSizes& sizes,
                                   const std::function<void(const ckpt::Reader&, int)>& file_part,
                                   const std::function<void(const ckpt::Reader&)>& global_part);

/// Collective: the generation the global file at `path` names (rank 0 reads it), 0 if there is none or
/// it is not a decomposed checkpoint. A new run starts after it, so that it never rewrites the rank
/// files a committed checkpoint names (a run replacing an earlier one's output with --force).
long committed_generation(MPI_Comm comm, const std::string& path);

/// OUT.xdmf's per-snapshot text (DecomposedOutput::xdmf_grids) as one string of the global file and
/// back (separated by the ASCII record separator, which XML text does not hold).
std::string join_grids(const std::vector<std::string>& grids);
std::vector<std::string> split_grids(const std::string& joined);

}  // namespace frictherm::coupling::detail
