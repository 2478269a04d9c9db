// Checkpoints of a decomposed run (decomposed_checkpoint.hpp): per-rank files and the global file,
// with the serial checkpoint's HDF5 visitors (run/checkpoint_io.hpp).
#include "distributed_run/decomposed_checkpoint.hpp"

#include "run/checkpoint_checks.hpp"
#include "run/checkpoint_io.hpp"
#include "distributed_run/decomposed_setup.hpp"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <vector>

namespace frictherm::coupling::detail {

namespace {

using h5detail::check;
using h5detail::check_id;
using h5detail::Handle;

// Every integer attribute of a decomposed checkpoint is 64-bit (as before).
void write_int_attribute(hid_t obj, const std::string& file, const char* name, long value) {
  ckpt::write_int_attribute(obj, file, name, value);
}
using ckpt::read_int_attribute;

void write_text(hid_t f, const std::string& file, const char* name, const std::string& text) {
  ckpt::write_array(f, file, name, H5T_NATIVE_CHAR, text.data(), text.size(), 1);
}


// Creates `file`, calls `fill` with a writer at its root, flushes; removes the file on failure.
void write_file(const std::string& file, const std::function<void(hid_t, const ckpt::Writer&)>& fill) {
  try {
    const h5detail::Quiet quiet;
    const Handle f = ckpt::create_file(file);
    fill(f.get(), ckpt::Writer{f.get(), file});
    check(H5Fflush(f.get(), H5F_SCOPE_GLOBAL), file, "cannot flush the checkpoint");
  } catch (...) {
    std::remove(file.c_str());
    throw;
  }
}

void agree(MPI_Comm comm, const std::string& error) {
  if (const std::string why = agreed_error(comm, error); !why.empty()) throw std::runtime_error(why);
}

}  // namespace

constexpr char kGridSeparator = '\x1e';

std::string join_grids(const std::vector<std::string>& grids) {
  std::string joined;
  for (const std::string& g : grids) joined += (joined.empty() ? "" : std::string(1, kGridSeparator)) + g;
  return joined;
}

std::vector<std::string> split_grids(const std::string& joined) {
  std::vector<std::string> grids;
  for (std::size_t a = 0, b; a < joined.size(); a = b + 1) {
    b = joined.find(kGridSeparator, a);
    if (b == std::string::npos) b = joined.size();
    grids.push_back(joined.substr(a, b - a));
  }
  return grids;
}

std::string decomposed_rank_checkpoint(const std::string& path, long generation, int rank) {
  return path + "." + std::to_string(generation) + ".rank" + std::to_string(rank);
}

void write_decomposed_checkpoint(MPI_Comm comm, const std::string& path, const Scene& scene, int dim, long generation,
                                 const CheckpointMarks& marks,
                                 const std::function<void(const ckpt::Writer&)>& rank_part,
                                 const std::function<void(const ckpt::Writer&)>& global_part) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::string error;
  // 1. Every rank's file of this generation (not yet named by the global file).
  const std::string mine = decomposed_rank_checkpoint(path, generation, rank);
  try {
    write_file(mine, [&](hid_t f, const ckpt::Writer& w) {
      write_int_attribute(f, mine, "generation", generation);
      write_int_attribute(f, mine, "rank", rank);
      rank_part(w);
    });
  } catch (const std::exception& e) {
    error = e.what();
  }
  try {
    agree(comm, error);
  } catch (...) {  // a generation that is never committed leaves no file behind
    std::remove(mine.c_str());
    throw;
  }
  // 2. The commit: rank 0's global file, renamed over the previous one once complete.
  if (rank == 0) {
    const std::string tmp = path + "." + std::to_string(static_cast<long>(getpid())) + ".tmp";
    try {
      write_file(tmp, [&](hid_t f, const ckpt::Writer& w) {
        write_int_attribute(f, tmp, "format", ckpt::kFormat);  // the serial layout
        write_int_attribute(f, tmp, "dimension", dim);
        write_int_attribute(f, tmp, "ranks", size);
        write_int_attribute(f, tmp, "generation", generation);
        write_text(f, tmp, "scene", scene.text);
        write_text(f, tmp, "scene_source", scene.source);
        std::string overrides;  // one "path=value" per line, as the serial checkpoint
        for (const SceneOverride& o : scene.overrides) overrides += o.path + "=" + o.value + "\n";
        write_text(f, tmp, "scene_overrides", overrides);
        ckpt::write_marks(w, f, tmp, marks);  // as the serial checkpoint
        global_part(w);
      });
      if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw std::runtime_error("checkpoint '" + path + "': cannot rename '" + tmp + "' over it");
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  try {
    agree(comm, error);
  } catch (...) {
    std::remove(mine.c_str());
    throw;
  }
  // 3. The previous generation is no longer named: every rank removes its file.
  if (generation > 1) std::remove(decomposed_rank_checkpoint(path, generation - 1, rank).c_str());
}

long committed_generation(MPI_Comm comm, const std::string& path) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  long generation = 0;
  if (rank == 0 && ::access(path.c_str(), F_OK) == 0) {
    const h5detail::Quiet quiet;
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f >= 0) {
      if (H5Aexists(f, "generation") > 0) {
        try {
          generation = read_int_attribute(f, path, "generation");
        } catch (const std::exception&) {
          generation = 0;
        }
      }
      H5Fclose(f);
    }
  }
  MPI_Bcast(&generation, 1, MPI_LONG, 0, comm);
  return generation;
}

namespace {

// Opens the global file and checks it (format, a decomposed run's, dimension); `ranks` and
// `generation` from its attributes.
Handle open_global(const std::string& path, int dim, long& ranks, long& generation) {
  Handle f{check_id(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), path, "cannot open the checkpoint"), H5Fclose};
  if (const long format = read_int_attribute(f.get(), path, "format"); format != ckpt::kFormat)
    throw std::runtime_error("checkpoint '" + path + "': format " + std::to_string(format) + " (expected " +
                             std::to_string(ckpt::kFormat) +
                             (ckpt::older_format_reason(format).empty()
                                  ? std::string("; written by another frictherm version)")
                                  : ": " + ckpt::older_format_reason(format) +
                                        "; resume it with the version that wrote it, or run the scene again)"));
  if (H5Aexists(f.get(), "ranks") <= 0)
    throw std::runtime_error("checkpoint '" + path + "' was written by a serial run: resume it without mpirun");
  ckpt::check_objects(f.get(), path);
  if (read_int_attribute(f.get(), path, "dimension") != dim)
    throw std::runtime_error("checkpoint '" + path + "': of another dimension than the scene");
  ranks = read_int_attribute(f.get(), path, "ranks");
  generation = read_int_attribute(f.get(), path, "generation");
  return f;
}

// Opens rank r's file of the generation and checks its attributes.
Handle open_rank_file(const std::string& path, long generation, int r) {
  const std::string file = decomposed_rank_checkpoint(path, generation, r);
  Handle g{check_id(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), file,
                    "cannot open the rank's checkpoint (named by '" + path + "')"),
           H5Fclose};
  if (read_int_attribute(g.get(), file, "generation") != generation || read_int_attribute(g.get(), file, "rank") != r)
    throw std::runtime_error("checkpoint '" + file + "': of another generation or rank than its name says");
  ckpt::check_objects(g.get(), file);
  return g;
}

}  // namespace

long read_decomposed_checkpoint(MPI_Comm comm, const std::string& path, int dim, const ckpt::RankSizes& sizes,
                                const std::function<void(const ckpt::Reader&)>& rank_part,
                                const std::function<void(const ckpt::Reader&)>& global_part) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::string error;
  long generation = 0, ranks = 0;
  try {
    const h5detail::Quiet quiet;
    const Handle f = open_global(path, dim, ranks, generation);
    if (ranks != size)
      throw std::runtime_error("checkpoint '" + path + "' was written by " + std::to_string(ranks) +
                               " ranks, resumed on " + std::to_string(size) + ": run mpirun -n " +
                               std::to_string(ranks));
    ckpt::check_global_file(f.get(), path);
    global_part(ckpt::Reader{f.get(), path, 0, "/", true});
    const Handle g = open_rank_file(path, generation, rank);
    const std::string file = decomposed_rank_checkpoint(path, generation, rank);
    ckpt::check_rank_file(g.get(), file, sizes);  // this rank's file, before any state is restored
    rank_part(ckpt::Reader{g.get(), file, 0, "/", true});
  } catch (const std::exception& e) {
    error = e.what();
  }
  agree(comm, error);
  return generation;
}

long read_redistributed_checkpoint(MPI_Comm comm, const std::string& path, int dim, const ckpt::RankSizes& sizes,
                                   const std::function<void(const ckpt::Reader&, int)>& file_part,
                                   const std::function<void(const ckpt::Reader&)>& global_part) {
  std::string error;
  long generation = 0, ranks = 0;
  try {
    const h5detail::Quiet quiet;
    const Handle f = open_global(path, dim, ranks, generation);
    ckpt::check_global_file(f.get(), path);
    global_part(ckpt::Reader{f.get(), path, 0, "/", true});
    for (int j = 0; j < static_cast<int>(ranks); ++j) {
      const Handle g = open_rank_file(path, generation, j);
      const std::string file = decomposed_rank_checkpoint(path, generation, j);
      ckpt::check_rank_file(g.get(), file, sizes);  // every file this rank reads, before any state is restored
      file_part(ckpt::Reader{g.get(), file, 0, "/", true}, j);
    }
  } catch (const std::exception& e) {
    error = e.what();
  }
  agree(comm, error);
  return generation;
}

}  // namespace frictherm::coupling::detail
