// Command-line argument parsing shared by the subcommands.
#include "cli.hpp"

namespace frictherm::cli {

namespace {
/// Whether `a` is one of the command's options (its name before any "=VALUE", or -h/--help).
bool is_option(const std::string& a, const std::vector<OptionSpec>& spec) {
  const std::string name = a.substr(0, a.compare(0, 2, "--") == 0 ? a.find('=') : std::string::npos);
  if (name == "-h" || name == "--help") return true;
  for (const auto& s : spec)
    for (const auto& n : s.names)
      if (n == name) return true;
  return false;
}
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
    if (a == "-h" || a == "--help") {
      out.help = true;
      continue;
    }
    const std::size_t eq = a.find('=');
    const std::string name = (a.compare(0, 2, "--") == 0 && eq != std::string::npos) ? a.substr(0, eq) : a;
    const OptionSpec* match = nullptr;
    for (const auto& s : spec)
      for (const auto& n : s.names)
        if (n == name) match = &s;
    if (!match) throw UsageError(command, "unknown option '" + a + "'");
    std::string value;
    if (match->takes_value) {
      if (name.size() < a.size()) {
        value = a.substr(eq + 1);
      } else if (i + 1 < args.size()) {
        // `-o --force` is a forgotten value, not a file named --force (that one is ./--force).
        if (is_option(args[i + 1], spec))
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
