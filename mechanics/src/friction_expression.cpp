// Sliding traction S(N, A, v) from a muParser expression (Nairn, Bardenhagen & Smith 2018, eq. 21 with
// an arbitrary law): validation at load time and a thread-safe, allocation-free evaluation.
#include <frictherm/mechanics/friction_expression.hpp>

#include <muParser.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

namespace frictherm::mechanics {

namespace {

std::string number_text(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

bool is_variable(const std::string& name) {
  return std::any_of(std::begin(kExpressionVariables), std::end(kExpressionVariables),
                     [&](const char* v) { return name == v; });
}

/// One compiled parser reading N, A, v from its own three doubles (muParser binds variables by address).
struct Slot {
  double N = 0.0, A = 0.0, v = 0.0;
  mu::Parser parser;
  std::atomic<bool> busy{false};

  Slot(const std::string& expression, const std::map<std::string, double>& constants) {
    parser.DefineVar("N", &N);
    parser.DefineVar("A", &A);
    parser.DefineVar("v", &v);
    for (const auto& [name, value] : constants) parser.DefineConst(name, value);
    parser.SetExpr(expression);
    parser.Eval();  // the first Eval parses and builds the bytecode: later ones allocate nothing
  }
  double eval(double normal_traction, double area, double sliding_speed) {
    N = normal_traction, A = area, v = sliding_speed;
    return parser.Eval();
  }
};

/// Compiled parsers shared by every copy of one law. Slot i is meant for OpenMP thread i; a caller
/// takes the first free slot from its own with a try-lock, so two callers never share a parser even
/// when thread numbers repeat (simulations run from several threads). Slots for the threads this
/// process can run are built up front; any other is built once, on first use.
class ParserPool {
 public:
  static constexpr int kCapacity = 256;

  ParserPool(std::string expression, std::map<std::string, double> constants)
      : expression_(std::move(expression)), constants_(std::move(constants)) {
    for (auto& s : slots_) s.store(nullptr, std::memory_order_relaxed);
    const int ready = std::clamp(std::max(omp_get_max_threads(), omp_get_num_procs()), 1, kCapacity);
    for (int i = 0; i < ready; ++i) slots_[static_cast<std::size_t>(i)].store(new Slot(expression_, constants_));
  }
  ~ParserPool() {
    for (auto& s : slots_) delete s.load();
  }
  ParserPool(const ParserPool&) = delete;
  ParserPool& operator=(const ParserPool&) = delete;

  double operator()(double N, double A, double v) const {
    const int start = std::max(0, omp_get_thread_num());
    for (int k = 0; k < kCapacity; ++k) {
      Slot& s = slot((start + k) % kCapacity);
      if (s.busy.exchange(true, std::memory_order_acquire)) continue;
      struct Release {
        Slot& s;
        ~Release() { s.busy.store(false, std::memory_order_release); }
      } release{s};
      return s.eval(N, A, v);
    }
    return Slot(expression_, constants_).eval(N, A, v);  // more than kCapacity callers at once
  }

 private:
  Slot& slot(int i) const {
    std::atomic<Slot*>& p = slots_[static_cast<std::size_t>(i)];
    Slot* s = p.load(std::memory_order_acquire);
    if (s) return *s;
    auto fresh = std::make_unique<Slot>(expression_, constants_);
    if (p.compare_exchange_strong(s, fresh.get(), std::memory_order_acq_rel)) return *fresh.release();
    return *s;  // another thread built it first
  }

  const std::string expression_;
  const std::map<std::string, double> constants_;
  mutable std::array<std::atomic<Slot*>, kCapacity> slots_;
};

[[noreturn]] void refuse(const std::string& key, const std::string& message) {
  throw FrictionExpressionError(key, message);
}

void check_constants(const std::map<std::string, double>& constants) {
  for (const auto& [name, value] : constants) {
    const std::string key = "constants." + name;
    if (is_variable(name)) refuse(key, "the name '" + name + "' is a variable (N, A, v): choose another name");
    if (!std::isfinite(value)) refuse(key, "expected a finite number, got " + number_text(value));
    try {
      mu::Parser p;
      p.DefineConst(name, value);
    } catch (const mu::Parser::exception_type&) {
      refuse(key, "invalid constant name '" + name + "' (expected letters, digits and _, not starting with a digit)");
    }
  }
}

std::string list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

/// Parses `expression` and evaluates it at the sample points; refuses syntax errors, unknown names,
/// assignments, several results, and values that are negative or not finite.
void check_expression(const std::string& expression, const std::map<std::string, double>& constants) {
  const std::string key = "sliding_traction";
  // The expression as the messages quote it: a long one cut to its start and its length.
  const std::string quoted = expression.size() <= 160 ? expression
                                                      : expression.substr(0, 120) + "... (" +
                                                            std::to_string(expression.size()) + " characters)";
  if (expression.find_first_not_of(" \t\r\n") == std::string::npos)
    refuse(key, "expected an expression in N (Pa), A (m^2) and v (m/s), got an empty string");
  double N = 0.0, A = 0.0, v = 0.0;
  mu::Parser p;
  try {
    p.DefineVar("N", &N);
    p.DefineVar("A", &A);
    p.DefineVar("v", &v);
    for (const auto& [name, value] : constants) p.DefineConst(name, value);
    p.SetExpr(expression);
    std::vector<std::string> unknown;
    for (const auto& used : p.GetUsedVar())  // parses the whole expression; undefined names are listed
      if (!is_variable(used.first)) unknown.push_back(used.first);
    if (!unknown.empty()) {
      std::vector<std::string> known;
      for (const auto& c : constants) known.push_back(c.first);
      refuse(key, std::string(unknown.size() == 1 ? "unknown variable " : "unknown variables ") + list(unknown) +
                      " in \"" + quoted + "\" (the variables are N [Pa], A [m^2], v [m/s]; constants: " +
                      (known.empty() ? "none given" : list(known)) + ")");
    }
    const double Ns[] = {0.0, 1.0, 1e6, 1e9}, As[] = {1e-10, 1e-6, 1.0}, vs[] = {0.0, 1e-3, 1.0, 1e3};
    for (double n : Ns)
      for (double a : As)
        for (double s : vs) {
          N = n, A = a, v = s;
          const double S = p.Eval();
          const std::string at = "N = " + number_text(n) + " Pa, A = " + number_text(a) + " m^2, v = " + number_text(s) + " m/s";
          if (p.GetNumResults() != 1)
            refuse(key, "expected one expression, got " + std::to_string(p.GetNumResults()) +
                            " separated by commas in \"" + quoted + "\"");
          if (N != n || A != a || v != s) refuse(key, "the expression \"" + quoted + "\" assigns to a variable");
          if (!(std::isfinite(S) && S >= 0.0))
            refuse(key, "the sliding traction \"" + quoted + "\" gives S = " + number_text(S) + " Pa at " + at +
                            " (expected finite and >= 0 at the sample points N in {0, 1, 1e6, 1e9} Pa, A in "
                            "{1e-10, 1e-6, 1} m^2, v in {0, 1e-3, 1, 1e3} m/s)");
        }
  } catch (const mu::Parser::exception_type& e) {
    refuse(key, "cannot parse \"" + quoted + "\": " + e.GetMsg() + " (muParser, position " +
                    std::to_string(e.GetPos()) + " counting from 0)");
  }
}

}  // namespace

FrictionLaw expression_friction_law(const std::string& sliding_traction, const std::map<std::string, double>& constants) {
  check_constants(constants);
  check_expression(sliding_traction, constants);
  auto pool = std::make_shared<const ParserPool>(sliding_traction, constants);
  std::string name = "expression: S = " + sliding_traction;
  std::string c;
  for (const auto& [n, value] : constants) c += (c.empty() ? "; " : ", ") + n + " = " + number_text(value);
  return FrictionLaw::user([pool](double N, double A, double v) { return (*pool)(N, A, v); }, name + c);
}

}  // namespace frictherm::mechanics
