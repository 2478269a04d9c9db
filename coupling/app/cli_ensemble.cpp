// `frictherm ensemble`: one scene over many seeds, members spread over MPI processes when the
// program is built with MPI and started by mpirun, serially otherwise (coupling/ensemble.hpp).
#include "cli.hpp"

#include <cmath>
#include <string>
#include <frictherm/coupling/ensemble.hpp>
#include <frictherm/coupling/output_files.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>

#ifdef FRICTHERM_WITH_MPI
#include <mpi.h>
#endif

namespace frictherm::cli {

namespace {

long non_negative_long(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long v = -1;
  try {
    v = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || v < 0) throw UsageError("ensemble", "option '" + option + "' expects an integer >= 0, got '" + text + "'");
  return v;
}


/// Sums each member's record fields over the processes (each member is run by exactly one).
void gather_records(std::vector<coupling::MemberRecord>& all, const std::vector<coupling::MemberRecord>& mine,
                    const coupling::EnsembleOptions& o, bool mpi) {
  const std::size_t n = static_cast<std::size_t>(o.members);
  std::vector<double> local(4 * n, 0.0), total(4 * n, 0.0);
  for (const auto& r : mine) {
    const std::size_t k = static_cast<std::size_t>(r.seed - o.first_seed);
    local[4 * k] = r.status, local[4 * k + 1] = static_cast<double>(r.steps);
    local[4 * k + 2] = r.simulated_time, local[4 * k + 3] = r.wall_time;
  }
#ifdef FRICTHERM_WITH_MPI
  if (mpi) MPI_Reduce(local.data(), total.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
  else total = local;
#else
  (void)mpi;
  total = local;
#endif
  all.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    all[k].seed = o.first_seed + static_cast<long>(k);
    all[k].file = coupling::member_file(o, all[k].seed);
    all[k].status = static_cast<int>(total[4 * k]);
    all[k].steps = static_cast<long>(total[4 * k + 1]);
    all[k].simulated_time = total[4 * k + 2], all[k].wall_time = total[4 * k + 3];
  }
  for (const auto& r : mine) all[static_cast<std::size_t>(r.seed - o.first_seed)].message = r.message;
}

}  // namespace

int ensemble_command(const std::vector<std::string>& args, const std::string& /*command_line*/) {
  const ParsedArgs a = parse_args("ensemble", args,
                                  {{{"-n", "--members"}, true, "members"},
                                   {{"-k", "--seed-key"}, true, "seed-key"},
                                   {{"--first-seed"}, true, "first-seed"},
                                   {{"-o", "--output"}, true, "output"},
                                   {{"--member-prefix"}, true, "member-prefix"},
                                   {{"-t", "--threads"}, true, "threads"},
                                   {{"-q", "--quiet"}, false, "quiet"},
                                   kForceOption, kSetOption});
  if (a.help) {
    std::cout << kEnsembleHelp;
    return kOk;
  }
  const std::string& path = single_positional("ensemble", a, "SCENE");
  const LauncherInfo launch = launcher_info();
  coupling::EnsembleOptions o;
  if (!a.has("seed-key")) throw UsageError("ensemble", "missing --seed-key KEY (the scene key that takes each seed)");
  o.seed_key = a.options.at("seed-key");
  o.members = a.has("members") ? positive_int("ensemble", "--members", a.options.at("members")) : 1;
  if (a.has("first-seed")) o.first_seed = non_negative_long("--first-seed", a.options.at("first-seed"));
  o.output = a.has("output") ? a.options.at("output") : "ensemble.h5";
  if (a.has("member-prefix")) o.member_prefix = a.options.at("member-prefix");
  if (a.has("threads")) o.threads = positive_int("ensemble", "--threads", a.options.at("threads"));
  o.quiet = a.has("quiet");
  o.overwrite = a.has("force");
  try {
    if (a.lists.count("set"))
      for (const auto& s : a.lists.at("set")) o.overrides.push_back(coupling::parse_override(s));
    const coupling::Scene scene = coupling::load_scene(path, o.overrides);  // a scene error stops before any member runs
    o.overwrite = o.overwrite || scene.output.overwrite;
    // Existing results refused before any member runs (output_files.hpp).
    const std::vector<std::string> inputs = coupling::scene_input_files(scene);
    coupling::check_output_path(o.output, inputs, o.overwrite, "--force");
    for (int k = 0; k < o.members; ++k)
      coupling::check_output_path(coupling::member_file(o, o.first_seed + k), inputs, o.overwrite, "--force");
    std::vector<coupling::SceneOverride> probe = o.overrides;
    probe.push_back({o.seed_key, std::to_string(o.first_seed)});
    coupling::load_scene(path, probe);
  } catch (const coupling::SceneError& e) {
    // Every process finds the same error: only the first one (rank 0, or the only one) reports it.
    if (launch.rank <= 0) std::cerr << "frictherm: " << path << ": " << e.what() << '\n';
    return kUsage;
  } catch (const coupling::OutputError& e) {
    std::cerr << "frictherm ensemble: " << e.what() << '\n';
    return kUsage;
  }

  bool mpi = false;
#ifdef FRICTHERM_WITH_MPI
  // MPI only when a launcher started us (a singleton MPI_Init is slow and refused as root in some
  // containers; launcher_info in cli_launcher.cpp lists the variables looked at).
  if (launch.launched) {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &o.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &o.ranks);
    mpi = true;
    if (launch.size > 1 && o.ranks != launch.size) {  // e.g. MPICH's mpiexec starting an Open MPI build
      if (launch.rank <= 0)
        std::cerr << "frictherm ensemble: the launcher started " << launch.size << " processes (" << launch.evidence
                  << ") but MPI sees " << o.ranks << ": it is not the MPI this frictherm was built with, and "
                  << "every process would run every member. Use that MPI's mpirun ('frictherm --version').\n";
      MPI_Finalize();
      return kUsage;
    }
  }
#endif
  int code = kOk;
  try {
    coupling::validate(o);
    const auto mine = coupling::run_members(path, o);
    std::vector<coupling::MemberRecord> all;
    gather_records(all, mine, o, mpi);
    if (o.rank == 0) {
      const coupling::EnsembleSummary s = coupling::aggregate_members(path, o, all);
      if (!o.quiet)
        std::printf("wrote %s: %d members (%d completed, %d processes), %ld hot spots (%.2f ± %.2f per member), "
                    "%ld ran away, %ld died, critical fraction %s\n",
                    o.output.c_str(), s.members, s.completed, o.ranks, s.hotspots_total, s.hotspots_per_member_mean,
                    s.hotspots_per_member_std, s.runaway, s.dying,
                    std::isnan(s.critical_fraction) ? "undefined (no decided hot spot)"
                                                    : std::to_string(s.critical_fraction).substr(0, 5).c_str());
      if (s.completed < s.members) code = kSimulationFailed;
    }
  } catch (const std::invalid_argument& e) {  // the same on every process: rank 0 reports it
    if (o.rank == 0) std::cerr << "frictherm ensemble: " << e.what() << '\n';
    code = kUsage;
  } catch (const std::exception& e) {
    std::cerr << "frictherm ensemble: " << e.what() << '\n';
    code = kSimulationFailed;
  }
#ifdef FRICTHERM_WITH_MPI
  if (mpi) MPI_Finalize();
#endif
  return code;
}

const char* const kEnsembleHelp =
    "usage: frictherm ensemble SCENE --seed-key KEY [-n MEMBERS] [--first-seed S] [-o OUT.h5]\n"
    "                          [--member-prefix P] [--threads N] [--quiet] [--set KEY=VALUE ...]\n"
    "\n"
    "Runs SCENE MEMBERS times with the scene key KEY set to S, S+1, ... (e.g. the seed of a random\n"
    "microstructure, bodies[1].shape.seed), each member to its own HDF5 file (P<seed>.h5, default\n"
    "OUT_seed<seed>.h5), then aggregates the members' hot spots (count, size, peak temperature, fate\n"
    "and time to runaway) into OUT.h5 (/members, /hotspots and summary attributes such as\n"
    "critical_fraction). Draw it with examples/ensemble_figures.py OUT.h5.\n"
    "\n"
    "Built with MPI (CMake found MPI), `mpirun -n K frictherm ensemble ...` spreads the members over K\n"
    "processes (member k on process k mod K); without mpirun, or built without MPI, they run one after\n"
    "the other. Member files must be on a file system every process sees.\n"
    "\n"
    "options:\n"
    "  -k, --seed-key KEY    scene key path that takes each member's seed (required)\n"
    "  -n, --members N       number of members, 1 to 1024 (default 1)\n"
    "      --first-seed S    seed of the first member (default 1)\n"
    "  -o, --output OUT.h5   aggregate file (default ensemble.h5)\n"
    "      --member-prefix P member files are P<seed>.h5\n"
    "  -t, --threads N       OpenMP threads per member\n"
    "  -f, --force           replace existing member and aggregate files (else refused)\n"
    "  -q, --quiet           no progress lines and no summary\n"
    "  -s, --set KEY=VALUE   change a scene value for every member (repeatable)\n"
    "\n"
    "Exit codes: 0 every member completed, 1 some member failed (the others are aggregated), 2 usage\n"
    "or scene error.\n";

}  // namespace frictherm::cli
