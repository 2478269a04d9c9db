#pragma once
// The `frictherm` command-line program: subcommands and their argument handling.
#include <map>
#include <stdexcept>
#include <iosfwd>
#include <string>
#include <vector>

namespace frictherm::coupling {
struct RunOptions;
}

namespace frictherm::cli {

/// Exit codes of the program.
enum ExitCode { kOk = 0, kSimulationFailed = 1, kUsage = 2 };

/// A mistake on the command line; `command` names the subcommand ("" for the program).
class UsageError : public std::runtime_error {
 public:
  UsageError(const std::string& command, const std::string& what) : std::runtime_error(what), command_(command) {}
  const std::string& command() const { return command_; }

 private:
  std::string command_;
};

/// An option a subcommand accepts: its spellings and whether it takes a value.
struct OptionSpec {
  std::vector<std::string> names;  // e.g. {"-o", "--output"}; the first long name is the key
  bool takes_value = false;
  std::string key;                 // name in ParsedArgs::options
  bool repeatable = false;         // may be given several times (values collected in ParsedArgs::lists)
};

struct ParsedArgs {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;  // key -> value ("" for flags); the last one if repeatable
  std::map<std::string, std::vector<std::string>> lists;  // key -> every value of a repeatable option
  bool help = false;
  bool has(const std::string& key) const { return options.count(key) != 0; }
};

/// Parses `args` (the words after the subcommand). Accepts "--name value", "--name=value", "-o value",
/// "-h"/"--help" and "--" (the rest is positional). Throws UsageError on unknown options or a
/// missing value.
ParsedArgs parse_args(const std::string& command, const std::vector<std::string>& args,
                      const std::vector<OptionSpec>& spec);

/// Exactly one positional argument named `what` (e.g. "SCENE").
const std::string& single_positional(const std::string& command, const ParsedArgs& a, const std::string& what);

/// The repeatable --set KEY=VALUE option every scene-reading command takes.
extern const OptionSpec kSetOption;
/// The --force flag of the writing commands: replace an existing output file (never an input).
extern const OptionSpec kForceOption;
/// An integer in [1, 1024] given to `option`; UsageError otherwise.
int positive_int(const std::string& command, const std::string& option, const std::string& text);

int ensemble_command(const std::vector<std::string>& args, const std::string& command_line);
int run_command(const std::vector<std::string>& args, const std::string& command_line);
/// `run` in one process: load SCENE with --set, run_scene, report (cli_commands.cpp).
int serial_run_command(const ParsedArgs& a, const std::string& path, const coupling::RunOptions& opt);
/// `run` started as several processes by an MPI launcher (cli_run_mpi.cpp): the decomposed run when
/// the program has it (MPI and PETSc), the serial run when MPI counts one process.
int decomposed_run_command(const ParsedArgs& a, const std::string& path, const coupling::RunOptions& opt);
int resume_command(const std::vector<std::string>& args, const std::string& command_line);  // cli_resume.cpp
int continue_command(const std::vector<std::string>& args, const std::string& command_line);  // cli_continue.cpp
int validate_command(const std::vector<std::string>& args);
int export_csv_command(const std::vector<std::string>& args);
int microstructure_command(const std::vector<std::string>& args);  // cli_microstructure.cpp

/// Help texts (printed to stdout by --help).
/// What an MPI launcher told this process through its environment (cli_launcher.cpp).
struct LauncherInfo {
  bool launched = false;  // some launcher variable is set
  long size = -1;         // process count announced (largest size variable), -1 if none
  long rank = -1;         // this process's rank (largest rank variable), -1 if none
  std::string evidence;   // e.g. "OMPI_COMM_WORLD_SIZE=2", for messages
};
LauncherInfo launcher_info();
bool several_processes(const LauncherInfo& info);  // size > 1 or rank > 0
/// kOk, or kUsage after a message (printed by rank 0 only) when started as several processes and
/// `command` cannot share the work: any command without MPI, any command but ensemble with MPI.
int refuse_under_launcher(const std::string& command);
/// Process set-up before anything else (OpenMP wait policy in builds without MPI).
void prepare_process(char** argv);
/// `frictherm --version`: version, git commit, MPI, OpenMP, SUNDIALS, HDF5 and Eigen.
void print_version(std::ostream& out);

extern const char* const kProgramHelp;
extern const char* const kRunHelp;
extern const char* const kResumeHelp;
extern const char* const kContinueHelp;
extern const char* const kValidateHelp;
extern const char* const kExportCsvHelp;
extern const char* const kMicrostructureHelp;
extern const char* const kEnsembleHelp;

}  // namespace frictherm::cli
