// The resume subcommand: continue a run from its checkpoint ("<RUN.h5>.checkpoint", checkpoint.hpp).
#include "cli.hpp"

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <cstdio>
#include <iostream>

namespace frictherm::cli {

const char* const kResumeHelp =
    "usage: frictherm resume RUN.h5 [-o OUT.h5] [--force] [--threads N] [--quiet]\n"
    "\n"
    "Continues a run from its last checkpoint RUN.h5.checkpoint (written when the scene sets\n"
    "run.checkpoint_interval: at that interval, at the end and on SIGINT/SIGTERM). The scene is rebuilt\n"
    "from the text and --set overrides stored in the checkpoint, its state restored, and the run goes on\n"
    "to run.end_time on the same snapshot and series times; the results equal an uninterrupted run's.\n"
    "The continuation is written to OUT.h5 (default: RUN.resumed.h5), starting at the checkpoint's\n"
    "state; RUN.h5 is not changed. Mechanics-only scenes (no thermal section, no penalty contact).\n"
    "\n"
    "  -o, --output FILE     HDF5 file of the continuation (default RUN.resumed.h5)\n"
    "  -f, --force           replace OUT.h5 if it exists (else refused)\n"
    "  -t, --threads N       OpenMP threads (1 thread repeats an interrupted 1-thread run bit-for-bit)\n"
    "  -q, --quiet           no progress line and no summary\n";

int resume_command(const std::vector<std::string>& args, const std::string& command_line) {
  const ParsedArgs a = parse_args("resume", args,
                                  {{{"-o", "--output"}, true, "output"},
                                   {{"-t", "--threads"}, true, "threads"},
                                   {{"-q", "--quiet"}, false, "quiet"},
                                   kForceOption});
  if (a.help) {
    std::cout << kResumeHelp;
    return kOk;
  }
  const std::string& run = single_positional("resume", a, "RUN.h5");
  coupling::RunOptions opt;
  if (a.has("threads")) opt.threads = positive_int("resume", "--threads", a.options.at("threads"));
  std::string stem = run;
  if (stem.size() > 3 && stem.compare(stem.size() - 3, 3, ".h5") == 0) stem.resize(stem.size() - 3);
  opt.output = a.has("output") ? a.options.at("output") : stem + ".resumed.h5";
  opt.quiet = a.has("quiet");
  opt.overwrite = a.has("force");
  opt.command_line = command_line;
  opt.handle_signals = true;
  opt.resume_checkpoint = coupling::checkpoint_path(run);
  coupling::RunResult r;
  try {
    const coupling::Scene scene = coupling::checkpoint_scene(opt.resume_checkpoint);
    r = coupling::run_scene(scene, opt);
  } catch (const coupling::SceneError& e) {
    std::cerr << "frictherm: " << opt.resume_checkpoint << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {
    std::cerr << "frictherm: " << e.what() << '\n';
    return kUsage;
  } catch (const std::exception& e) {
    std::cerr << "frictherm: resume of " << run << " failed: " << e.what() << '\n';
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::failed) {
    std::cerr << "frictherm: simulation failed: " << r.message << " (kept in " << r.output << ")\n";
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::interrupted) {
    std::cerr << "frictherm: " << r.message << "; resume again from " << coupling::checkpoint_path(r.output) << '\n';
    return r.exit_code();
  }
  if (!opt.quiet)
    std::printf("wrote %s: %zu snapshots, %zu series rows; resumed to step %ld, t = %g s in %.2f s\n", r.output.c_str(),
                r.snapshots, r.series_rows, r.steps, r.time, r.wall_time);
  return kOk;
}

}  // namespace frictherm::cli
