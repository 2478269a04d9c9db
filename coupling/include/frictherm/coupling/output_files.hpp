#pragma once
// Files a command writes, kept safe (issue 15): an output never lands on a file the run reads (the
// scene, its images, a checkpoint being resumed), an existing result is replaced only when asked
// (--force or the scene's output.overwrite: true), and a result is written under a temporary name
// in the same folder and renamed onto its final name only when complete (docs/scenes.md, "Output
// files"), so a second run writing the same file cannot destroy the first one's.
#include <frictherm/coupling/runner.hpp>  // OutputError
#include <frictherm/coupling/scene.hpp>

#include <string>
#include <vector>

namespace frictherm::coupling {

/// Every file a scene reads: the scene file (unless the scene came from a string) and its images.
std::vector<std::string> scene_input_files(const Scene& scene);

/// True when both paths name the same existing file (same device and inode: symbolic and hard
/// links and different spellings of one path count as the same file).
bool same_file(const std::string& a, const std::string& b);

/// same_file, or the same path once symbolic links, "." and ".." are resolved as far as it exists
/// ("./RUN.h5" and "RUN.h5" before RUN.h5 exists).
bool same_path(const std::string& a, const std::string& b);

/// Refuses (OutputError) to write `path` when it is one of `inputs`, when it is a folder, or when it
/// exists and `overwrite` is false; `how_to_overwrite` is said in that last message (e.g. "--force").
void check_output_path(const std::string& path, const std::vector<std::string>& inputs, bool overwrite,
                       const std::string& how_to_overwrite);

/// check_output_path for the XDMF files published with a result (xdmf_paths_for): an existing one that
/// is an XDMF text (what a run leaves beside its result) is replaced without `overwrite`, as before;
/// anything else there (another run's HDF5 result named OUT.xdmf, a user's file) is refused unless
/// `overwrite`, and an input always.
void check_companion_path(const std::string& path, const std::vector<std::string>& inputs, bool overwrite,
                          const std::string& how_to_overwrite);

/// What an existing file holds, read from its content (not its name): a checkpoint of frictherm
/// (root attribute "format" with /marks or /mechanics), a result (root "format" with /meta or
/// /series), another HDF5 file (a decomposed run's rank file, a foreign file), or none of these.
enum class StoredFileKind { none, hdf5, result, checkpoint };
StoredFileKind stored_file_kind(const std::string& path);

/// The output of `command` (continue, resume, export-csv) reading the result `run` (issue 34):
/// refused (OutputError naming the path and why), --force or not, when it is `run` itself or one of
/// the files that belong to it (RUN.h5.checkpoint, RUN.xdmf, RUN_reference.xdmf, RUN_nodes.xdmf;
/// compared as canonical paths and by inode, so "./RUN.h5" and links count), when it is an existing
/// checkpoint of any run, and, with `csv`, when it is any existing HDF5 file (a result, a rank file).
void check_not_of_input(const std::string& output, const std::string& run, const std::string& command, bool csv);

/// A name in the folder of `path` that no file has yet: "<path>.<pid>.part" (a counter is added if
/// that exists).
std::string temporary_path(const std::string& path);

/// Renames the complete file `temporary` onto `path`. With `overwrite` false an existing `path` (one
/// that appeared while the file was written, e.g. by a second run) is left alone and
/// std::runtime_error says that the result stays under `temporary`.
void publish_file(const std::string& temporary, const std::string& path, bool overwrite);

/// The result `path` can be created: its folder exists and is a folder, and `path` is not a folder.
/// Else OutputError "<what>: ..." (`what`: the scene key output.file, or the option -o) naming the
/// path (issue 34: `validate` accepted both, `run` then named its temporary file).
void check_output_folder(const std::string& path, const std::string& what);

/// publish_file for a result with its XDMF files (`xdmf` for xdmf_path_for(path), `reference_xdmf`
/// for xdmf_reference_path_for(path); an empty text: none). Both are written completely first;
/// replacing, the earlier result's XDMF files are removed before the result takes the name; then
/// they take theirs. Whenever the process is killed, an XDMF file beside a result describes that
/// result, or there is none (issue 34).
void publish_with_xdmf(const std::string& temporary, const std::string& path, bool overwrite, const std::string& xdmf,
                       const std::string& reference_xdmf, const std::string& nodes_xdmf = "");

/// The output claimed for one run (issue 34): an advisory lock (flock) on "<output>.lock", held until
/// destruction, so a second run on the same output is refused (OutputError naming the output) before
/// it writes anything, not at publication after it had replaced the XDMF and checkpoint. The kernel
/// drops the lock when the process ends, killed or not; a leftover lock file claims nothing.
class OutputClaim {
 public:
  explicit OutputClaim(const std::string& output);
  ~OutputClaim();
  OutputClaim(const OutputClaim&) = delete;
  OutputClaim& operator=(const OutputClaim&) = delete;

 private:
  std::string lock_path_;
  int fd_ = -1;
};

}  // namespace frictherm::coupling
