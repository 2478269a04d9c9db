// The subcommands: run, validate, export-csv.
#include "cli.hpp"

#include <frictherm/coupling/checkpoint.hpp>

#include <frictherm/coupling/csv_export.hpp>
#include <frictherm/coupling/output_files.hpp>
#include <frictherm/coupling/runner.hpp>
#include <frictherm/coupling/scene.hpp>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

namespace frictherm::cli {

const OptionSpec kSetOption{{"-s", "--set"}, true, "set", true};
const OptionSpec kForceOption{{"-f", "--force"}, false, "force"};

namespace {

/// Loads a scene with the --set overrides; a problem becomes "frictherm: SCENE: message" and exit
/// code 2 (returned as false). With `notes`, the scene's notes (Scene::notes) go to `err`.
bool load(const std::string& path, const ParsedArgs& a, coupling::Scene& scene, std::ostream& err = std::cerr,
          bool notes = true) {
  try {
    std::vector<coupling::SceneOverride> overrides;
    if (a.lists.count("set"))
      for (const auto& assignment : a.lists.at("set")) overrides.push_back(coupling::parse_override(assignment));
    scene = coupling::load_scene(path, overrides);
    if (notes)
      for (const std::string& n : scene.notes) err << "frictherm: " << path << ": note: " << n << '\n';
    return true;
  } catch (const coupling::SceneError& e) {
    err << "frictherm: " << path << ": " << e.what() << '\n';
    return false;
  }
}

}  // namespace

int positive_int(const std::string& command, const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long v = 0;
  try {
    v = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || v < 1 || v > 1024)
    throw UsageError(command, "option '" + option + "' expects an integer in [1, 1024], got '" + text + "'");
  return static_cast<int>(v);
}

int run_command(const std::vector<std::string>& args, const std::string& command_line) {
  const ParsedArgs a = parse_args("run", args,
                                  {{{"-o", "--output"}, true, "output"},
                                   {{"-t", "--threads"}, true, "threads"},
                                   {{"-q", "--quiet"}, false, "quiet"},
                                   {{"--checkpoint-every"}, true, "checkpoint-every"},
                                   kForceOption, kSetOption});
  if (a.help) {
    if (launcher_info().rank <= 0) std::cout << kRunHelp;  // under mpirun: rank 0 only
    return kOk;
  }
  const std::string& path = single_positional("run", a, "SCENE");
  coupling::RunOptions opt;
  if (a.has("threads")) opt.threads = positive_int("run", "--threads", a.options.at("threads"));
  if (a.has("output")) opt.output = a.options.at("output");
  opt.quiet = a.has("quiet");
  opt.overwrite = a.has("force");
  opt.command_line = command_line;
  opt.handle_signals = true;
  if (a.has("checkpoint-every")) {
    const std::string& v = a.options.at("checkpoint-every");
    char* end = nullptr;
    opt.checkpoint_wall_interval = std::strtod(v.c_str(), &end);
    if (end == v.c_str() || *end != '\0' || !(opt.checkpoint_wall_interval > 0.0) || !std::isfinite(opt.checkpoint_wall_interval))
      throw UsageError("run", "--checkpoint-every: expected wall-clock seconds > 0, got '" + v + "'");
  }
  // Started as several processes by mpirun (and allowed by refuse_under_launcher): the decomposed run.
  if (several_processes(launcher_info())) return decomposed_run_command(a, path, opt);
  return serial_run_command(a, path, opt);
}

int serial_run_command(const ParsedArgs& a, const std::string& path, const coupling::RunOptions& opt) {
  coupling::Scene scene;
  if (!load(path, a, scene, std::cerr, !opt.quiet)) return kUsage;
  coupling::RunResult r;
  try {
    r = coupling::run_scene(scene, opt);
  } catch (const coupling::SceneError& e) {
    std::cerr << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {
    std::cerr << "frictherm: " << e.what() << '\n';
    return kUsage;
  } catch (const std::exception& e) {
    std::cerr << "frictherm: run of " << path << " failed: " << e.what() << '\n';
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::failed) {
    std::cerr << "frictherm: simulation failed: " << r.message << ". Kept in " << r.output << ": " << r.snapshots
              << " snapshots written before the failure, the failing state under /failure and the time series.\n";
    return kSimulationFailed;
  }
  if (r.status == coupling::RunResult::Status::interrupted) {
    std::cerr << "frictherm: " << r.message << ". Kept in " << r.output << ": " << r.snapshots
              << " snapshots (the last one at the interruption), " << r.series_rows
              << " series rows; /meta/status = interrupted.";
    if (std::filesystem::exists(coupling::checkpoint_path(r.output)))
      std::cerr << " Go on with: frictherm resume " << r.output;
    std::cerr << '\n';
    return r.exit_code();
  }
  if (!opt.quiet) {
    std::printf("wrote %s: %zu snapshots, %zu series rows; %ld steps to t = %g s in %.2f s (%zu particles)\n",
                r.output.c_str(), r.snapshots, r.series_rows, r.steps, r.time, r.wall_time, r.particles);
    if (r.wall_time > 0.0 && r.steps > 0) {
      std::printf("%.3g particle-steps/s; wall time by phase:", static_cast<double>(r.particles) * r.steps / r.wall_time);
      for (const auto& [name, seconds] : r.phase_seconds)
        if (seconds > 0.0005 * r.wall_time) std::printf(" %s %.1f%%", name.c_str(), 100.0 * seconds / r.wall_time);
      std::printf("\n");
    }
  }
  return kOk;
}

int validate_command(const std::vector<std::string>& args) {
  const ParsedArgs a = parse_args("validate", args, {kSetOption});
  // Under mpirun every rank validates (and exits alike); only rank 0 says so (issue 34: once per rank).
  std::ostream null_stream(nullptr);
  const bool speaks = launcher_info().rank <= 0;
  std::ostream& out = speaks ? std::cout : null_stream;
  std::ostream& err = speaks ? std::cerr : null_stream;
  if (a.help) {
    out << kValidateHelp;
    return kOk;
  }
  const std::string& path = single_positional("validate", a, "SCENE");
  coupling::Scene scene;
  if (!load(path, a, scene, err)) return kUsage;
  try {
    coupling::check_output_folder(scene.output.file, "output.file");  // as `run` checks it (no -o here)
    coupling::describe_scene(scene, out);
  } catch (const coupling::SceneError& e) {
    out.flush();
    err << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {
    err << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  }
  out << "ok\n";
  return kOk;
}

int export_csv_command(const std::vector<std::string>& args) {
  const ParsedArgs a = parse_args("export-csv", args, {{{"-o", "--output"}, true, "output"}, kForceOption});
  if (a.help) {
    std::cout << kExportCsvHelp;
    return kOk;
  }
  const std::string& path = single_positional("export-csv", a, "RUN.h5");
  if (!std::ifstream(path)) {
    std::cerr << "frictherm: cannot open '" << path << "'\n";
    return kUsage;
  }
  try {
    if (a.has("output")) {
      const std::string& out_path = a.options.at("output");
      coupling::check_not_of_input(out_path, path, "export-csv", true);  // --force or not (issue 34)
      coupling::check_output_path(out_path, {path}, a.has("force"), "--force");
      const std::string live = coupling::temporary_path(out_path);  // renamed onto out_path when complete
      std::ofstream out(live);
      if (!out) {
        std::cerr << "frictherm: cannot create '" << out_path << "'\n";
        return kUsage;
      }
      try {
        coupling::export_series_csv(path, out);
      } catch (...) {  // an unreadable run: no half-written CSV left under the temporary name
        out.close();
        std::remove(live.c_str());
        throw;
      }
      out.close();
      if (!out) {
        std::remove(live.c_str());
        std::cerr << "frictherm: cannot write '" << out_path << "'\n";
        return kUsage;
      }
      coupling::publish_file(live, out_path, true);
    } else {
      coupling::export_series_csv(path, std::cout);
      std::cout.flush();
    }
  } catch (const std::exception& e) {
    std::cerr << "frictherm: " << e.what() << '\n';
    return kUsage;
  }
  return kOk;
}

}  // namespace frictherm::cli
