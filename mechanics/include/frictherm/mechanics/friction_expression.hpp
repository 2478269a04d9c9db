#pragma once
// A friction law whose sliding traction is written as a text expression (parsed by muParser):
// the generalized law S(N, A_c, |Δv'|) of Nairn, Bardenhagen & Smith 2018 (§2.8–2.9, eq. 21), solved
// per contact node by FrictionLaw::user. Variables: N the normal traction (Pa), A the contact area
// A_c (m^2), v the final sliding speed |Δv'| (m/s); plus named constants. The stick limit is the same
// expression at v = 0 (stick while d_t ≤ S(N, A_c, 0) A_c dt, §2.6), so a naive static/dynamic law
// is written "v > 0 ? mu_d*N : mu_s*N". See docs/contact.md, "Friction laws".
//
// muParser binds variables by pointer and keeps its evaluation stack inside the parser, so a parser
// is never shared by two threads: the law holds a pool of compiled parsers, one per OpenMP thread,
// each taken with a try-lock (safe for any caller, ensemble threads included). The pool is filled
// and compiled when the law is made; evaluation allocates nothing.
#include <frictherm/mechanics/friction.hpp>

#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace frictherm::mechanics {

/// A sliding-traction expression that cannot be used. `key` says which input is wrong:
/// "sliding_traction" or "constants.<name>"; what() says why (muParser's message and position for
/// syntax errors, the unknown names, or the sample point where S is negative or not finite).
class FrictionExpressionError : public std::invalid_argument {
 public:
  FrictionExpressionError(std::string key, const std::string& message)
      : std::invalid_argument(message), key_(std::move(key)) {}
  const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// The variable names of a sliding-traction expression: N (Pa), A (m^2), v (m/s).
inline constexpr const char* kExpressionVariables[] = {"N", "A", "v"};

/// Parses, compiles and checks `sliding_traction`, and returns the law (kind() == user,
/// describe() == "user(expression: S = <text>; <constants>)"). The expression is evaluated at sample
/// points N ∈ {0, 1, 1e6, 1e9} Pa, A ∈ {1e-10, 1e-6, 1} m^2, v ∈ {0, 1e-3, 1, 1e3} m/s and must be
/// finite and ≥ 0 at every one. Constants need valid names (letters, digits, _, not starting with a
/// digit), finite values, and may not be N, A or v. Throws FrictionExpressionError.
FrictionLaw expression_friction_law(const std::string& sliding_traction,
                                    const std::map<std::string, double>& constants = {});

}  // namespace frictherm::mechanics
