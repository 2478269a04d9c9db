#pragma once
// One result from an interrupted run and its resumption (issue 17, frictherm resume/continue): the
// rows and snapshots the interrupted result had at the checkpoint (CheckpointMarks), then everything
// the resumed run wrote (RunOptions::resume_appends), so the file reads as one run.
#include <frictherm/coupling/checkpoint.hpp>

#include <string>

namespace frictherm::coupling {

/// Writes `output` = `original` cut at `marks` (its first marks.series_rows series rows, the first
/// rows of each table, the first marks.snapshots snapshots, no /failure) followed by `continuation`'s
/// series and table rows and snapshots (renumbered after the kept ones, /failure if it has one);
/// /meta keys the continuation wrote replace the original's. The file is built as
/// "<output>.<pid>.part" (a copy of `original`) and renamed onto `output` only when complete, so
/// `original` (which may be `output` itself) stays whole if anything fails; `output`'s XDMF files
/// (RUN.xdmf, RUN_reference.xdmf and RUN_nodes.xdmf, xdmf_documents_of_result) are rebuilt. Throws std::runtime_error naming the file and what does not fit (columns differ, fewer
/// rows than the marks). `join_columns` (frictherm continue, whose thermal settings may differ from
/// the loading's, issue 34): a series or table column only one part has (a reaction switched on adds
/// reaction_heat and max_reaction_progress) is kept instead of refused, filled in the other part's
/// rows: 0 in the loading's rows for the reaction and plastic-heat columns (nothing released there,
/// λ = 0), NaN otherwise; the group's `columns` attribute lists the union.
void append_result(const std::string& original, const std::string& continuation, const CheckpointMarks& marks,
                   const std::string& output, bool join_columns = false);

/// /meta/run_id of the result `result` ("" for results of older versions, which have none); throws
/// std::runtime_error naming the file when it does not open.
std::string result_run_id(const std::string& result);

/// Throws std::runtime_error naming both runs when the checkpoint (`marks`) belongs to another run than
/// the result `result` (issue 34: a later run on the same output that did not finish, or files of two
/// runs put together). Files without an identity (older versions) are not refused.
void check_same_run(const std::string& result, const CheckpointMarks& marks);

/// Throws std::runtime_error naming the file and the defect when `original` cannot take the append
/// (not an HDF5 file, truncated, not a frictherm result, fewer series rows or snapshots than `marks`):
/// resume checks it before running, so a damaged result costs no run time.
void check_appendable(const std::string& original, const CheckpointMarks& marks);

/// The XDMF document of every snapshot (and /failure) in `h5_path`, pointing at `h5_name`.
std::string xdmf_of_result(const std::string& h5_path, const std::string& h5_name);

/// The XDMF files of a result as H5Output writes them: `current` (RUN.xdmf: the particles at their
/// positions), `reference` (RUN_reference.xdmf: the particles at initial_position; empty when no
/// snapshot has it) and `nodes` (RUN_nodes.xdmf: the thermal grid's nodes; empty without /nodes).
struct XdmfDocuments {
  std::string current;
  std::string reference;
  std::string nodes;
};
XdmfDocuments xdmf_documents_of_result(const std::string& h5_path, const std::string& h5_name);

}  // namespace frictherm::coupling
