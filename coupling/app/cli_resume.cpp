// The resume subcommand: continue a run from its checkpoint ("<RUN.h5>.checkpoint", checkpoint.hpp),
// appending to the same result (result_append.hpp); resume_from_checkpoint is shared with continue.
#include "cli.hpp"
#include "cli_resume.hpp"

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/result_append.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/xdmf.hpp>

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

namespace frictherm::cli {

const char* const kResumeHelp =
    "usage: frictherm resume RUN.h5 [-o OUT.h5] [--force] [--threads N] [--quiet] [--checkpoint-every S]\n"
    "\n"
    "Continues a run from its last checkpoint RUN.h5.checkpoint (written when the scene sets\n"
    "run.checkpoint_interval: at that interval, at the end and on SIGINT/SIGTERM; and, for scenes with a\n"
    "thermal continuation, always at the end of loading). The scene is rebuilt from the text and --set\n"
    "overrides stored in the checkpoint, its state restored (mechanics, penalty slip histories, thermal\n"
    "coupler, hot spots, energy books), and the run goes on to run.end_time and through the thermal\n"
    "continuation on the same snapshot and series times; on one thread the results equal an\n"
    "uninterrupted run's bit-for-bit. A checkpoint taken in the continuation is its start (end of\n"
    "loading): the continuation is run again from there.\n"
    "\n"
    "The result is appended to RUN.h5 (its series, hot spots and snapshots up to the checkpoint, then\n"
    "the resumed run's), so the file reads as one run; it is built beside RUN.h5 and renamed over it\n"
    "only when complete. Without RUN.h5 (a killed run leaves only RUN.h5.<pid>.part) the continuation\n"
    "is written alone, starting at the checkpoint's state.\n"
    "\n"
    "A decomposed run's checkpoint (mpirun -n K frictherm run) is resumed with mpirun -n K frictherm\n"
    "resume RUN.h5, in place: RUN.h5 is rewritten from the checkpoint's series rows, each rank file\n"
    "keeps its snapshots up to it; on the same K bit-for-bit as an uninterrupted run, on another K the\n"
    "particles are redistributed (round-off of reordered sums). -o and resuming it without mpirun are\n"
    "refused (exit code 2).\n"
    "\n"
    "  -o, --output FILE     write the appended result to FILE instead (RUN.h5 is left as it is)\n"
    "  -f, --force           replace FILE if it exists (else refused)\n"
    "  -t, --threads N       OpenMP threads (1 thread repeats an interrupted 1-thread run bit-for-bit)\n"
    "  -q, --quiet           no progress line and no summary\n"
    "  --checkpoint-every S  also checkpoint every S wall-clock seconds (not stored in the checkpoint)\n";

namespace {

bool exists(const std::string& path) { return std::filesystem::exists(path); }

void remove_quietly(const std::string& path) {
  std::error_code ec;
  std::filesystem::remove(path, ec);
}

}  // namespace

coupling::Scene checkpoint_scene_or_refuse(const std::string& checkpoint,
                                           const std::vector<coupling::SceneOverride>& more) {
  try {
    return coupling::checkpoint_scene(checkpoint, more);
  } catch (const coupling::SceneError&) {
    throw;  // a --set of `continue` the scene refuses
  } catch (const std::exception& e) {
    throw coupling::OutputError(std::string(e.what()) + " (" + checkpoint + " is not a readable checkpoint)");
  }
}

coupling::RunOptions resume_run_options(const ResumeRequest& q) {
  coupling::RunOptions opt;
  opt.threads = q.threads;
  opt.checkpoint_wall_interval = q.checkpoint_wall_interval;
  opt.quiet = q.quiet;
  opt.command_line = q.command_line;
  opt.handle_signals = true;
  opt.resume_checkpoint = q.checkpoint;
  return opt;
}

ResumeOutcome resume_from_checkpoint(const ResumeRequest& q) {
  if (const int ranks = coupling::checkpoint_ranks(q.checkpoint); ranks > 0)
    throw coupling::OutputError(q.checkpoint + " was written by a decomposed run on " + std::to_string(ranks) +
                                " ranks: resume it with mpirun -n " + std::to_string(ranks) + " frictherm resume " + q.run);
  ResumeOutcome out;
  coupling::RunOptions opt = resume_run_options(q);
  opt.checkpoint_file = coupling::checkpoint_path(q.output);
  const bool in_place = coupling::same_file(q.run, q.output);
  // Onto RUN.h5 itself: appended in place, or written anew under its name when it does not exist.
  if (!in_place && !coupling::same_path(q.run, q.output)) {  // RUN.h5's checkpoint and XDMF files, or any checkpoint: never, --force or not (issue 34)
    coupling::check_not_of_input(q.output, q.run, "resume", false);
    coupling::check_output_path(q.output, {q.run, q.checkpoint}, q.force, "--force");
  }
  const bool append = exists(q.run);
  out.appended = append;
  std::string continuation = q.output;
  if (append) {
    continuation = q.output + "." + std::to_string(static_cast<long>(getpid())) + ".continuation.h5";
    opt.resume_appends = true;
    opt.overwrite = true;
    // The resumed run's checkpoints count rows of the appended result, which exists only once it is
    // published: they stay beside the continuation until then (issue 34: a killed resume had moved
    // RUN.h5.checkpoint past RUN.h5, and the next resume was refused).
    opt.checkpoint_file = continuation + ".checkpoint";
  } else {
    opt.overwrite = q.force;
    if (!q.quiet)
      std::cerr << "frictherm: note: " << q.run << " does not exist (a killed run keeps only " << q.run
                << ".<pid>.part): the continuation goes to " << q.output << " alone, from the checkpoint's state\n";
  }
  opt.output = continuation;
  const coupling::CheckpointMarks marks = coupling::checkpoint_marks(q.checkpoint);
  if (append) {
    try {
      coupling::check_appendable(q.run, marks);
    } catch (const std::exception& e) {
      throw coupling::OutputError(std::string(e.what()) + "; the resumed run could not be appended to it (move it " +
                                  "away to write the continuation alone, from the checkpoint's state)");
    }
  }
  try {
    out.result = coupling::run_scene(q.scene, opt);
  } catch (...) {
    if (append) {
      remove_quietly(continuation);
      remove_quietly(coupling::xdmf_path_for(continuation));
      remove_quietly(coupling::xdmf_reference_path_for(continuation));
      remove_quietly(coupling::xdmf_nodes_path_for(continuation));
      remove_quietly(opt.checkpoint_file);
    }
    throw;
  }
  if (append) {
    try {
      coupling::append_result(q.run, continuation, marks, q.output, q.new_thermal_settings);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string(e.what()) + " (the resumed part is kept in " + continuation + ")");
    }
    remove_quietly(continuation);
    remove_quietly(coupling::xdmf_path_for(continuation));
    remove_quietly(coupling::xdmf_reference_path_for(continuation));
    remove_quietly(coupling::xdmf_nodes_path_for(continuation));
    // Now that the rows it counts are in the published result: the resumed run's last checkpoint.
    if (exists(opt.checkpoint_file) && std::rename(opt.checkpoint_file.c_str(), coupling::checkpoint_path(q.output).c_str()) != 0)
      throw std::runtime_error("cannot rename '" + opt.checkpoint_file + "' to '" + coupling::checkpoint_path(q.output) +
                               "': " + std::strerror(errno) + " (" + q.output + " is complete; its checkpoint is the earlier one)");
    out.result.output = q.output;
  }
  return out;
}

int report_resumed(const char* command, const ResumeOutcome& o, bool quiet) {
  const coupling::RunResult& r = o.result;
  if (r.status == coupling::RunResult::Status::failed) {
    std::cerr << "frictherm: simulation failed: " << r.message << " (kept in " << r.output << ")\n";
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::interrupted) {
    std::cerr << "frictherm: " << r.message << "; resume again: frictherm resume " << r.output << '\n';
    return r.exit_code();
  }
  if (!quiet)
    std::printf("%s %s: to step %ld, t = %g s in %.2f s (%zu snapshots, %zu series rows %s)\n", command,
                r.output.c_str(), r.steps, r.time, r.wall_time, r.snapshots, r.series_rows,
                o.appended ? "appended" : "written");
  return kOk;
}

int resume_command(const std::vector<std::string>& args, const std::string& command_line) {
  const ParsedArgs a = parse_args("resume", args,
                                  {{{"-o", "--output"}, true, "output"},
                                   {{"-t", "--threads"}, true, "threads"},
                                   {{"-q", "--quiet"}, false, "quiet"},
                                   {{"--checkpoint-every"}, true, "checkpoint-every"},
                                   kForceOption});
  if (a.help) {
    std::cout << kResumeHelp;
    return kOk;
  }
  ResumeRequest q;
  q.run = single_positional("resume", a, "RUN.h5");
  q.checkpoint = coupling::checkpoint_path(q.run);
  q.output = a.has("output") ? a.options.at("output") : q.run;
  if (a.has("threads")) q.threads = positive_int("resume", "--threads", a.options.at("threads"));
  q.quiet = a.has("quiet");
  q.force = a.has("force");
  q.command_line = command_line;
  if (a.has("checkpoint-every")) {
    const std::string& v = a.options.at("checkpoint-every");
    char* end = nullptr;
    q.checkpoint_wall_interval = std::strtod(v.c_str(), &end);
    if (end == v.c_str() || *end != '\0' || !(q.checkpoint_wall_interval > 0.0) || !std::isfinite(q.checkpoint_wall_interval))
      throw UsageError("resume", "--checkpoint-every: expected wall-clock seconds > 0, got '" + v + "'");
  }
  if (several_processes(launcher_info())) return decomposed_resume_command(q);  // mpirun -n K (K > 1)
  return run_from_checkpoint(q, "resume", [&q] {
    if (!exists(q.checkpoint)) throw coupling::OutputError("no checkpoint " + q.checkpoint + " to resume " + q.run + " from");
    q.scene = checkpoint_scene_or_refuse(q.checkpoint);
  });
}

int run_from_checkpoint(ResumeRequest& q, const char* command, const std::function<void()>& prepare) {
  ResumeOutcome o;
  try {
    prepare();
    o = resume_from_checkpoint(q);
  } catch (const coupling::SceneError& e) {
    std::cerr << "frictherm: " << q.checkpoint << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {
    std::cerr << "frictherm: " << e.what() << '\n';
    return kUsage;
  } catch (const std::exception& e) {
    std::cerr << "frictherm: " << command << " of " << q.run << " failed: " << e.what() << '\n';
    return kSimulationFailed;
  }
  return report_resumed(std::string(command) == "resume" ? "resumed" : "continued", o, q.quiet);
}

}  // namespace frictherm::cli
