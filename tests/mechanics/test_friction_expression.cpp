// Friction laws written as muParser expressions S(N, A, v) (mechanics/src/friction_expression.cpp):
// the expression of a built-in law gives that law's outcome; bad expressions are refused naming the
// input; evaluation is thread-safe and allocates nothing.
//
// Tolerance 1e-10 relative between a closed form (or the composite law) and the expression solved
// by the bracketed root finder, as in test_friction.cpp: both stop at a bracket 1e-14 wide, and the
// expression's own roundoff (S computed in a different order, N = N*/(A_c dt) then times A_c dt) is a
// few ulp.
#include <frictherm/mechanics/friction_expression.hpp>

#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <new>
#include <map>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

using namespace frictherm::mechanics;

// Counts every operator new of this process (muParser's included: the executable's definition
// interposes the library's), to show that evaluating an expression law allocates nothing.
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
// GCC cannot see that the replaced operator new above allocates with malloc:
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace {
constexpr double kSolverTol = 1e-10;
// A contact node: m_red = 2e-6 kg, A_c = 1e-6 m², dt = 1e-7 s, N = 1 MPa → N* = 1e-7 kg m/s.
constexpr double kM = 2e-6, kA = 1e-6, kDt = 1e-7, kNstar = 1e6 * kA * kDt;

ContactImpulse node(double d_t, double n_star = kNstar) { return {-n_star, d_t, kM, kA, kDt}; }

/// Tangential impulses from well below the stick limit μ N* to 100 times it (a factor 1.05 apart,
/// so no d_t sits on a stick boundary within roundoff).
std::vector<double> sweep() {
  std::vector<double> d;
  for (double d_t = 0.01 * kNstar; d_t < 100 * kNstar; d_t *= 1.05) d.push_back(d_t);
  return d;
}

void expect_same(const FrictionLaw& expr, const FrictionLaw& law, double n_star = kNstar) {
  int slides = 0;
  for (double d_t : sweep()) {
    const FrictionOutcome a = expr.in_contact(node(d_t, n_star)), b = law.in_contact(node(d_t, n_star));
    ASSERT_EQ(a.stick, b.stick) << expr.describe() << " vs " << law.describe() << " at d_t = " << d_t;
    EXPECT_NEAR(a.slide_impulse, b.slide_impulse, kSolverTol * b.slide_impulse)
        << expr.describe() << " vs " << law.describe() << " at d_t = " << d_t;
    slides += !b.stick;
  }
  EXPECT_GT(slides, 10) << law.describe();  // the sweep reaches sliding, not only sticking
}

/// The FrictionExpressionError of building the law; its key and message.
std::pair<std::string, std::string> refusal(const std::string& expr, const std::map<std::string, double>& c = {}) {
  try {
    expression_friction_law(expr, c);
  } catch (const FrictionExpressionError& e) {
    return {e.key(), e.what()};
  }
  ADD_FAILURE() << "accepted \"" << expr << "\"";
  return {};
}
bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
}  // namespace

TEST(FrictionExpression, ReproducesBuiltInLaws) {
  expect_same(expression_friction_law("mu_s*N", {{"mu_s", 0.35}}), FrictionLaw::coulomb(0.35));
  expect_same(expression_friction_law("(0.2 + 0.05*v)*N"), FrictionLaw::linear_velocity(0.2, 0.05));
  expect_same(expression_friction_law("S_a + 0.2*N", {{"S_a", 1e5}}), FrictionLaw::adhesion(0.2, 1e5));
  // The naive static/dynamic law of §2.8: the stick test uses S at v = 0, sliding uses v > 0.
  expect_same(expression_friction_law("v > 0 ? 0.2*N : 0.4*N"), FrictionLaw::static_dynamic(0.4, 0.2));
  expect_same(expression_friction_law("(0.4*0.05 + 0.2*v)/(0.05 + v)*N"), FrictionLaw::smooth_static_dynamic(0.4, 0.2, 0.05));
}

TEST(FrictionExpression, ReproducesCompositeLaw) {
  // Eq 21 with every term: S = N (μ(v) + k v) + S_a, μ(v) of eq 42.
  const std::map<std::string, double> c{{"mu_s", 0.35}, {"mu_d", 0.2}, {"v_half", 0.05}, {"k", 0.02}, {"S_a", 3e5}};
  const FrictionLaw e = expression_friction_law("((mu_s*v_half + mu_d*v)/(v_half + v) + k*v)*N + S_a", c);
  const FrictionLaw law = FrictionLaw::composite(0.35, 0.2, 0.05, 0.02, 3e5);
  for (double n_star : {0.0, 0.3 * kNstar, kNstar, 20 * kNstar}) expect_same(e, law, n_star);
  EXPECT_TRUE(e.needs_area());
  EXPECT_EQ(e.kind(), FrictionKind::user);
  EXPECT_EQ(e.describe(), "user(expression: S = ((mu_s*v_half + mu_d*v)/(v_half + v) + k*v)*N + S_a; "
                          "S_a = 300000, k = 0.02, mu_d = 0.2, mu_s = 0.35, v_half = 0.05)");
}

TEST(FrictionExpression, AreaEntersAsA) {
  // S = 0.2 N + 1e5 Pa · (A / 1e-6 m²): at A_c = 1e-6 m² this is adhesion(0.2, 1e5); at 4e-6 m² the
  // adhesion term is four times larger, so the stick limit moves from 0.2 N* + 1e5 A dt accordingly.
  const FrictionLaw e = expression_friction_law("0.2*N + 1e5*A/1e-6");
  const double a = 4e-6, n_star = kNstar, limit = 0.2 * n_star + 4e5 * a * kDt;
  EXPECT_TRUE(e.in_contact({-n_star, 0.999 * limit, kM, a, kDt}).stick);
  const FrictionOutcome o = e.in_contact({-n_star, 1.001 * limit, kM, a, kDt});
  ASSERT_FALSE(o.stick);
  EXPECT_NEAR(o.slide_impulse, limit, kSolverTol * limit);
}

TEST(FrictionExpression, RefusesBadExpressions) {
  auto [key, msg] = refusal("mu_s*N +", {{"mu_s", 0.3}});
  EXPECT_EQ(key, "sliding_traction");
  EXPECT_TRUE(has(msg, "cannot parse \"mu_s*N +\": Unexpected end of expression") && has(msg, "position 9")) << msg;
  std::tie(key, msg) = refusal("2*(N");
  EXPECT_TRUE(has(msg, "Missing parenthesis") && has(msg, "position")) << msg;
  std::tie(key, msg) = refusal("mu*N + x", {{"mu_s", 0.3}});
  EXPECT_EQ(key, "sliding_traction");
  EXPECT_TRUE(has(msg, "unknown variables mu, x") && has(msg, "constants: mu_s")) << msg;
  std::tie(key, msg) = refusal("0.3*N - 0.01*v*N");  // negative for v > 30 m/s
  EXPECT_TRUE(has(msg, "gives S = -9.7 Pa at N = 1 Pa, A = 1e-10 m^2, v = 1000 m/s")) << msg;
  std::tie(key, msg) = refusal("sqrt(N - 1)");  // NaN at N = 0
  EXPECT_TRUE(has(msg, "nan Pa at N = 0 Pa")) << msg;
  std::tie(key, msg) = refusal("0.2*N + 1e3/v");  // infinite at v = 0
  EXPECT_TRUE(has(msg, "gives S = inf Pa at N = 0 Pa, A = 1e-10 m^2, v = 0 m/s")) << msg;
  EXPECT_TRUE(has(refusal("  ").second, "got an empty string"));
  EXPECT_TRUE(has(refusal("0.2*N, v").second, "expected one expression, got 2"));
  EXPECT_TRUE(has(refusal("v = 0.2*N").second, "assigns to a variable"));
  std::tie(key, msg) = refusal("N", {{"N", 1.0}});
  EXPECT_EQ(key, "constants.N");
  std::tie(key, msg) = refusal("N", {{"2mu", 1.0}});
  EXPECT_EQ(key, "constants.2mu");
  EXPECT_TRUE(has(msg, "invalid constant name")) << msg;
  std::tie(key, msg) = refusal("N", {{"mu", std::nan("")}});
  EXPECT_EQ(key, "constants.mu");
}

// One parser per thread: many threads evaluating at once, with thread numbers repeated across
// std::threads (two OpenMP teams), give exactly the serial results. A shared parser would mix up
// the variables of different nodes (muParser reads N, A, v by address) and its evaluation stack.
TEST(FrictionExpression, ThreadSafe) {
  const FrictionLaw e = expression_friction_law("((0.35*0.05 + 0.2*v)/(0.05 + v) + 0.02*v)*N + 3e5*A/1e-6");
  const int n = 4000;
  std::vector<double> d_t(n), serial(n);
  for (int i = 0; i < n; ++i) {
    d_t[static_cast<std::size_t>(i)] = kNstar * (0.5 + 0.01 * i);
    serial[static_cast<std::size_t>(i)] = e.in_contact(node(d_t[static_cast<std::size_t>(i)], kNstar * (1 + i % 7))).slide_impulse;
  }
  auto team = [&](std::vector<double>& out) {
#pragma omp parallel for num_threads(4) schedule(dynamic, 7)
    for (int i = 0; i < n; ++i) {
      try {  // a shared parser typically makes the root finder throw (no bracket): record NaN
        out[static_cast<std::size_t>(i)] = e.in_contact(node(d_t[static_cast<std::size_t>(i)], kNstar * (1 + i % 7))).slide_impulse;
      } catch (const std::exception&) {
        out[static_cast<std::size_t>(i)] = std::nan("");
      }
    }
  };
  // With one parser shared by all threads, 5 rounds of 5 failed in our runs; 20 rounds make a pass by chance unlikely.
  for (int round = 0; round < 20; ++round) {
    std::vector<double> a(n), b(n);
    std::thread ta(team, std::ref(a)), tb(team, std::ref(b));
    ta.join(), tb.join();
    for (int i = 0; i < n; ++i) {
      ASSERT_EQ(a[static_cast<std::size_t>(i)], serial[static_cast<std::size_t>(i)]) << "i = " << i;
      ASSERT_EQ(b[static_cast<std::size_t>(i)], serial[static_cast<std::size_t>(i)]) << "i = " << i;
    }
  }
}

TEST(FrictionExpression, EvaluationAllocatesNothing) {
  const long before_make = g_allocations.load();
  const FrictionLaw e = expression_friction_law("((mu_s*0.05 + 0.2*v)/(0.05 + v) + 0.02*v)*N + 3e5", {{"mu_s", 0.35}});
  EXPECT_GT(g_allocations.load(), before_make);  // the counter sees muParser's allocations
  double sum = 0.0;
  const long before = g_allocations.load();
  for (int i = 0; i < 1000; ++i) sum += e.in_contact(node(kNstar * (0.2 + 0.01 * i))).slide_impulse;
  const long during = g_allocations.load() - before;
  EXPECT_EQ(during, 0) << "operator new calls during 1000 contact evaluations";
  EXPECT_GT(sum, 0.0);
}
