// The continue subcommand: rerun only the thermal continuation of a run from its end-of-loading
// checkpoint with other thermal settings (issue 17), into a new result that keeps the loading.
#include "cli.hpp"
#include "cli_resume.hpp"

#include <frictherm/coupling/checkpoint.hpp>
#include <frictherm/coupling/output_files.hpp>

#include <filesystem>
#include <iostream>

namespace frictherm::cli {

const char* const kContinueHelp =
    "usage: frictherm continue RUN.h5 [-o OUT.h5] [--force] [--threads N] [--quiet] [--set KEY=VALUE ...]\n"
    "\n"
    "Reruns the thermal-only continuation of RUN.h5 from its end-of-loading checkpoint\n"
    "RUN.h5.checkpoint (written by every run with coupling.continuation) with other thermal settings,\n"
    "without rerunning the mechanics: the work-precision loop over integrators, tolerances, reaction\n"
    "parameters and hot-spot thresholds on one loading. OUT.h5 holds RUN.h5's loading (series, hot\n"
    "spots, snapshots up to the end of loading) followed by the new continuation and its hot-spot fates;\n"
    "its metadata (wall_time, thermal_*) are the continuation's. A changed hot-spot threshold finds the\n"
    "end-of-loading hot spots again (ids from 0). A reaction the loading did not have starts from\n"
    "lambda = 0; series columns only one part has are kept (0 or NaN in the other's rows:\n"
    "docs/checkpoints.md). OUT.h5.checkpoint is its end-of-loading checkpoint.\n"
    "\n"
    "  -o, --output FILE     result (default RUN.continued.h5)\n"
    "  -f, --force           replace FILE if it exists (else refused; never RUN.h5 itself)\n"
    "  -s, --set KEY=VALUE   a thermal setting (repeatable): thermal.* (integrator, rtol, atol,\n"
    "                        linear_solver, reaction.*, stability, ...; not thermal.materials),\n"
    "                        coupling.continuation.* (duration, intervals, stop_when_decided),\n"
    "                        coupling.hotspots.* (threshold, mode, runaway_progress, ...), run.threads\n"
    "  -t, --threads N       OpenMP threads\n"
    "  -q, --quiet           no progress line and no summary\n";

namespace {

// Keys that change only the continuation: the loading in the checkpoint stays valid.
bool continuation_key(const std::string& key) {
  const auto starts = [&](const char* p) { return key.rfind(p, 0) == 0; };
  if (starts("thermal.materials")) return false;  // M and K of the loading, and the particles' energies
  return starts("thermal.") || starts("coupling.continuation.") || starts("coupling.continuation") ||
         starts("coupling.hotspots.") || key == "run.threads";
}

}  // namespace

int continue_command(const std::vector<std::string>& args, const std::string& command_line) {
  const ParsedArgs a = parse_args("continue", args,
                                  {{{"-o", "--output"}, true, "output"},
                                   {{"-t", "--threads"}, true, "threads"},
                                   {{"-q", "--quiet"}, false, "quiet"},
                                   kForceOption, kSetOption});
  if (a.help) {
    std::cout << kContinueHelp;
    return kOk;
  }
  ResumeRequest q;
  q.run = single_positional("continue", a, "RUN.h5");
  q.checkpoint = coupling::checkpoint_path(q.run);
  std::string stem = q.run;
  if (stem.size() > 3 && stem.compare(stem.size() - 3, 3, ".h5") == 0) stem.resize(stem.size() - 3);
  q.output = a.has("output") ? a.options.at("output") : stem + ".continued.h5";
  if (a.has("threads")) q.threads = positive_int("continue", "--threads", a.options.at("threads"));
  q.quiet = a.has("quiet");
  q.force = a.has("force");
  q.command_line = command_line;
  q.new_thermal_settings = true;  // e.g. a reaction the loading did not have: columns joined (issue 34)
  std::vector<coupling::SceneOverride> overrides;
  if (a.lists.count("set"))
    for (const auto& assignment : a.lists.at("set")) {
      coupling::SceneOverride o;
      try {
        o = coupling::parse_override(assignment);
      } catch (const std::exception& e) {
        throw UsageError("continue", e.what());
      }
      if (!continuation_key(o.path))
        throw UsageError("continue", "--set " + o.path +
                                         ": continue changes only the thermal continuation (expected a key under "
                                         "thermal.* but not thermal.materials, coupling.continuation.*, "
                                         "coupling.hotspots.* or run.threads; rerun the scene to change the loading)");
      overrides.push_back(o);
    }
  return run_from_checkpoint(q, "continue", [&] {
    // The continued run is a new result: it never replaces RUN.h5 or its checkpoint, --force or not
    // (resume appends in place; continue would lose the continuation it started from).
    coupling::check_not_of_input(q.output, q.run, "continue", false);
    if (!std::filesystem::exists(q.checkpoint))
      throw coupling::OutputError("no checkpoint " + q.checkpoint + " (runs with coupling.continuation write one at the end of loading)");
    q.scene = checkpoint_scene_or_refuse(q.checkpoint, overrides);  // first: refuses an unreadable checkpoint
    // The sub-cell interface temperature is the loading's frictional heat kept below the cell: a
    // loading without it has none to continue from (its checkpoint had been called damaged, issue 34).
    if (q.scene.thermal.coupler.interface_temperature.enabled &&
        !checkpoint_scene_or_refuse(q.checkpoint).thermal.coupler.interface_temperature.enabled)
      throw coupling::SceneError("coupling.hotspots.temperature: \"interface\" needs the sub-cell interface temperature "
                                 "of the loading, which " + q.run + " ran without (coupling.interface_temperature off); "
                                 "expected \"grid\", or rerun the scene with coupling.interface_temperature");
    const coupling::CheckpointMarks marks = coupling::checkpoint_marks(q.checkpoint);
    if (!marks.end_of_loading)
      throw coupling::OutputError(q.checkpoint + " was taken at t = " + std::to_string(marks.time) +
                                  " s, before the end of loading: finish the run first (frictherm resume " + q.run + ")");
    if (!(q.scene.thermal.enabled && q.scene.thermal.continuation_duration > 0.0))
      throw coupling::SceneError("coupling.continuation: the scene has no thermal continuation (expected a duration > 0)");
  });
}

}  // namespace frictherm::cli
