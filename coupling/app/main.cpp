// frictherm: the command-line program (run, validate, export-csv, ensemble).
#include "cli.hpp"

#include <frictherm/coupling/h5_output.hpp>

#include <exception>
#include <iostream>
#include <string>
#include <vector>

namespace {

std::string quote_arg(const std::string& a) {
  if (!a.empty() && a.find_first_of(" \t\"'\\$") == std::string::npos) return a;
  std::string q = "'";
  for (char c : a) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

const char* help_of(const std::string& command) {
  if (command == "run") return frictherm::cli::kRunHelp;
  if (command == "resume") return frictherm::cli::kResumeHelp;
  if (command == "continue") return frictherm::cli::kContinueHelp;
  if (command == "validate") return frictherm::cli::kValidateHelp;
  if (command == "export-csv") return frictherm::cli::kExportCsvHelp;
  if (command == "microstructure") return frictherm::cli::kMicrostructureHelp;
  if (command == "ensemble") return frictherm::cli::kEnsembleHelp;
  return nullptr;
}

int dispatch(const std::vector<std::string>& words, const std::string& command_line) {
  using namespace frictherm::cli;
  if (words.empty()) throw UsageError("", "missing command");
  const std::string& cmd = words.front();
  const std::vector<std::string> rest(words.begin() + 1, words.end());
  if (cmd == "--help" || cmd == "-h") {
    std::cout << kProgramHelp;
    return kOk;
  }
  if (cmd == "--version" || cmd == "-V") {
    print_version(std::cout);
    return kOk;
  }
  if (cmd == "help") {
    if (rest.empty()) {
      std::cout << kProgramHelp;
      return kOk;
    }
    const char* h = help_of(rest.front());
    if (!h || rest.size() > 1) throw UsageError("", "no help for '" + rest.back() + "'");
    std::cout << h;
    return kOk;
  }
  if (cmd == "run" || cmd == "resume" || cmd == "continue" || cmd == "export-csv" || cmd == "microstructure" || cmd == "ensemble") {
    if (const int refused = refuse_under_launcher(cmd); refused != kOk) return refused;
  }
  if (cmd == "run") return run_command(rest, command_line);
  if (cmd == "resume") return resume_command(rest, command_line);
  if (cmd == "continue") return continue_command(rest, command_line);
  if (cmd == "validate") return validate_command(rest);
  if (cmd == "export-csv") return export_csv_command(rest);
  if (cmd == "microstructure") return microstructure_command(rest);
  if (cmd == "ensemble") return ensemble_command(rest, command_line);
  throw UsageError("", (cmd[0] == '-' ? "unknown option '" : "unknown command '") + cmd + "'");
}

}  // namespace

int main(int argc, char** argv) {
  frictherm::coupling::hdf5_program_setup();
  frictherm::cli::prepare_process(argv);
  std::vector<std::string> words(argv + 1, argv + argc);
  std::string command_line;
  for (int i = 0; i < argc; ++i) command_line += (i ? " " : "") + quote_arg(argv[i]);
  try {
    return dispatch(words, command_line);
  } catch (const frictherm::cli::UsageError& e) {
    const std::string who = e.command().empty() ? "frictherm" : "frictherm " + e.command();
    if (frictherm::cli::launcher_info().rank > 0) return frictherm::cli::kUsage;  // rank 0 reports it
    std::cerr << who << ": " << e.what() << " (see '" << who << " --help')\n";
    return frictherm::cli::kUsage;
  } catch (const std::exception& e) {
    std::cerr << "frictherm: " << e.what() << '\n';
    return frictherm::cli::kSimulationFailed;
  }
}
