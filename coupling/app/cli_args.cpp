// Command-line argument parsing shared by the subcommands.
#include "cli.hpp"

namespace frictherm::cli {

namespace {
/// The option name of the argument `a`: "--name=VALUE" gives "--name", anything else itself.
std::string option_name(const std::string& a) {
  return a.substr(0, a.compare(0, 2, "--") == 0 ? a.find('=') : std::string::npos);
}
/// The option named by the argument `a`, or nullptr.
const OptionSpec* find_option(const std::string& a, const std::vector<OptionSpec>& spec) {
  const std::string name = option_name(a);
  const OptionSpec* match = nullptr;
  for (const auto& s : spec)
    for (const auto& n : s.names)
      if (n == name) match = &s;
  return match;
}
bool is_help(const std::string& a) { return a == "-h" || a == "--help"; }
}  // namespace

ParsedArgs parse_args(const std::string& command, const std::vector<std::string>& args,
                      const std::vector<OptionSpec>& spec) {
  ParsedArgs out;
  bool options_done = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (options_done || a.size() < 2 || a[0] != '-') {
      out.positional.push_back(a);
      continue;
    }
    if (a == "--") {
      options_done = true;
      continue;
    }
    if (is_help(a)) {
      out.help = true;
      continue;
    }
    const std::string name = option_name(a);
    const OptionSpec* match = find_option(a, spec);
    if (!match) throw UsageError(command, "unknown option '" + a + "'");
    std::string value;
    if (match->takes_value) {
      if (name.size() < a.size()) {
        value = a.substr(name.size() + 1);
      } else if (i + 1 < args.size()) {
        // `-o --force` is a forgotten value, not a file named --force (that one is ./--force).
        if (is_help(args[i + 1]) || find_option(args[i + 1], spec))
          throw UsageError(command, "option '" + a + "' needs a value, got the option '" + args[i + 1] + "'" +
                                        (a.compare(0, 2, "--") == 0 ? " (write " + a + "=VALUE for a value that starts with '-')"
                                                                    : " (a file of that name is ./" + args[i + 1] + ")"));
        value = args[++i];
      } else {
        throw UsageError(command, "option '" + a + "' needs a value");
      }
      if (value.empty()) throw UsageError(command, "option '" + name + "' needs a non-empty value");
    } else if (name.size() < a.size()) {
      throw UsageError(command, "option '" + name + "' takes no value");
    }
    if (out.has(match->key) && !match->repeatable) throw UsageError(command, "option '" + name + "' given twice");
    out.options[match->key] = value;
    if (match->repeatable) out.lists[match->key].push_back(value);
  }
  return out;
}

const std::string& single_positional(const std::string& command, const ParsedArgs& a, const std::string& what) {
  if (a.positional.empty()) throw UsageError(command, "missing " + what);
  if (a.positional.size() > 1) throw UsageError(command, "unexpected argument '" + a.positional[1] + "'");
  return a.positional.front();
}

}  // namespace frictherm::cli
