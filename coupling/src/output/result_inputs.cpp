// The files of a result that continue, resume and export-csv read, and what an existing file holds
// (output_files.hpp): their outputs never land on them, --force or not (issue 34).
#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include "output/h5_util.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <system_error>
#include <utility>

namespace frictherm::coupling {

bool same_path(const std::string& a, const std::string& b) {
  if (same_file(a, b)) return true;
  std::error_code ea, eb;
  const std::filesystem::path ca = std::filesystem::weakly_canonical(a, ea);
  const std::filesystem::path cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

StoredFileKind stored_file_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return StoredFileKind::none;
  const h5detail::Quiet quiet;
  if (H5Fis_hdf5(path.c_str()) <= 0) return StoredFileKind::none;
  const h5detail::Handle f{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  if (f.get() < 0) return StoredFileKind::hdf5;  // e.g. open for writing by a run (HDF5's file lock)
  const auto has = [&](const char* name) { return H5Lexists(f.get(), name, H5P_DEFAULT) > 0; };
  // Layouts: docs/checkpoints.md (root "format", /marks, /mechanics) and docs/output.md (root
  // "format" = "frictherm-output", /meta); a decomposed run's rank file holds /snapshots alone.
  if (H5Aexists(f.get(), "format") > 0) {
    if (has("marks") || has("mechanics")) return StoredFileKind::checkpoint;
    if (has("meta") || has("series")) return StoredFileKind::result;
  }
  return StoredFileKind::hdf5;
}

namespace {
const char* describe(StoredFileKind kind) {
  switch (kind) {
    case StoredFileKind::checkpoint: return "a checkpoint of frictherm (read by resume and continue)";
    case StoredFileKind::result: return "a result of frictherm";
    case StoredFileKind::hdf5: return "an HDF5 file";
    case StoredFileKind::none: break;
  }
  return "a file";
}
}  // namespace

void check_not_of_input(const std::string& output, const std::string& run, const std::string& command, bool csv) {
  // RUN.h5 as spelled and, when it is a symbolic link, as the file it names: both names' companions.
  std::vector<std::string> runs = {run};
  std::error_code ec;
  const std::filesystem::path target = std::filesystem::canonical(run, ec);
  if (!ec && target.string() != run) runs.push_back(target.string());
  for (const std::string& r : runs) {
    const std::pair<std::string, const char*> files[] = {{r, "the input"},
                                                         {checkpoint_path(r), "the checkpoint"},
                                                         {xdmf_path_for(r), "the XDMF file"},
                                                         {xdmf_reference_path_for(r), "the reference XDMF file"},
                                                         {xdmf_nodes_path_for(r), "the nodes' XDMF file"}};
    for (const auto& [file, what] : files)
      if (same_path(output, file))
        throw OutputError("refusing to write '" + output + "': it is " + what + " of '" + run + "'" +
                          (file == r ? "" : " ('" + file + "')") + ", which " + command +
                          " reads and never replaces (--force or not); choose another output file");
  }
  // By content, whatever its name: a checkpoint belongs to its run; a CSV replaces no HDF5 file.
  const StoredFileKind found = stored_file_kind(output);
  if (found == StoredFileKind::checkpoint || (csv && found != StoredFileKind::none))
    throw OutputError("refusing to write '" + output + "': it is " + describe(found) + ", which " +
                      (found == StoredFileKind::checkpoint ? std::string("belongs to its run")
                                                           : command + " never replaces with a CSV file") +
                      " (--force or not); choose another output file");
}

}  // namespace frictherm::coupling
