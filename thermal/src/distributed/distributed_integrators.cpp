// Integrators of the distributed thermal solve (distributed.hpp), under the serial module's
// names and with its window logic (sundials_integrator.hpp): forward_euler (explicit, sub-stepped
// below the global Gershgorin limit, source at sub-step midpoints), cvode_bdf / cvode_adams
// (CVODE) and arkode_erk / arkode_dirk (ARKODE) on N_Vector_Parallel vectors, the Krylov solvers
// (PCG on the symmetric form, or SPGMR) preconditioned by a PETSc PC (distributed_ode.hpp).
#include "conservative_krylov.hpp"
#include "distributed_ode.hpp"

#include <arkode/arkode_arkstep.h>
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <sunlinsol/sunlinsol_pcg.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace frictherm::thermal {

namespace {

bool all_ranks(MPI_Comm comm, bool mine) {
  int in = mine ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_MIN, comm);
  DistributedProblem::count_reductions(1);
  return out == 1;
}

}  // namespace

void DistributedIntegrator::advance(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1) {
  const CommunicationStats before = problem.communication();
  std::string bad;
  if (T.size() != problem.local_size()) {
    bad = "temperature vector has " + std::to_string(T.size()) + " entries for " +
          std::to_string(problem.local_size()) + " owned nodes";
  } else if (!T.allFinite()) {
    bad = "temperature vector has a non-finite entry";
  } else if (!(std::isfinite(t0) && std::isfinite(t1) && t1 >= t0)) {
    std::ostringstream os;
    os << "need finite t1 >= t0, got [" << t0 << ", " << t1 << "]";
    bad = os.str();
  }
  // One agreement so that a rank's bad input stops every rank (none waits in a collective).
  if (!all_ranks(problem.comm(), bad.empty())) {
    throw std::invalid_argument(name() + " (distributed, rank " + std::to_string(problem.rank()) + "): " +
                                (bad.empty() ? std::string("another rank rejected its input") : bad));
  }
  problem.apply_dirichlet(T);
  if (!books_started_) {
    books_.initial_stored = problem.thermal_energy(T);
    books_started_ = true;
  }
  if (t1 > t0) {
    advance_impl(problem, T, t0, t1);
    books_.source_heat += problem.source_heat(t0, t1);
  }
  books_.stored = problem.thermal_energy(T);
  const CommunicationStats after = problem.communication();
  comm_.ghost_exchanges += after.ghost_exchanges - before.ghost_exchanges;
  comm_.reductions += after.reductions - before.reductions;
  comm_.ghosts_received = after.ghosts_received;
  comm_.ghosts_sent = after.ghosts_sent;
  comm_.neighbours = after.neighbours;
}

void DistributedIntegrator::advance(const DistributedProblem& problem, Eigen::VectorXd& T, Eigen::VectorXd& progress,
                                    double t0, double t1) {
  const bool bad = problem.has_reaction() && progress.size() != problem.local_size();
  if (!all_ranks(problem.comm(), !bad))
    throw std::invalid_argument(name() + " (distributed, rank " + std::to_string(problem.rank()) + "): " +
                                (bad ? "progress has " + std::to_string(progress.size()) + " entries for " +
                                           std::to_string(problem.local_size()) + " owned nodes"
                                     : std::string("another rank rejected its input")));
  struct Reset {
    Eigen::VectorXd*& p;
    ~Reset() { p = nullptr; }
  } reset{progress_};
  progress_ = problem.has_reaction() ? &progress : nullptr;
  advance(problem, T, t0, t1);
}

namespace detail {
namespace {

// ---------------------------------------------------------------- forward_euler
class DistForwardEuler final : public DistributedIntegrator {
 public:
  explicit DistForwardEuler(const IntegratorOptions& o) : opt_(o) {}
  std::string name() const override { return "forward_euler"; }

 protected:
  void advance_impl(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1) override {
    const auto start = std::chrono::steady_clock::now();
    if (problem.has_reaction())  // the same on every rank (set_reaction is collective)
      throw std::invalid_argument("forward_euler (distributed): the reaction is not distributed for forward Euler "
                                  "(use cvode_bdf, cvode_adams, arkode_erk or arkode_dirk)");
    if (problem.revision() != revision_) {
      const double lam = problem.lambda_max_gershgorin();  // global (MPI_MAX)
      dt_limit_ = lam > 0.0 ? 2.0 / lam : std::numeric_limits<double>::infinity();
      revision_ = problem.revision();
    }
    const double window = t1 - t0;
    const double h_stable = opt_.fe_safety * dt_limit_;
    long n = 1;  // as ForwardEuler::advance_impl (forward_euler.cpp)
    if (opt_.fe_max_dt > 0.0) n = static_cast<long>(std::ceil(window / opt_.fe_max_dt - 1e-12));
    n = std::max(n, 1L);
    if (opt_.fe_stability_policy == "substep") {
      if (window / static_cast<double>(n) > h_stable) n = static_cast<long>(std::ceil(window / h_stable));
    } else if (opt_.fe_stability_policy == "refuse" && window / static_cast<double>(n) > h_stable) {
      std::ostringstream os;
      os << "forward_euler (distributed): step " << window / static_cast<double>(n)
         << " s exceeds the stability limit fe_safety*dt_limit = " << h_stable
         << " s (global Gershgorin estimate); refusing (fe_stability_policy \"refuse\")";
      throw StabilityError(os.str(), window / static_cast<double>(n), dt_limit_);
    }
    const double h = window / static_cast<double>(n);
    // T_{k+1} = T_k + h M⁻¹(−K T_k + q(t_k + h/2)): one ghost exchange per sub-step, no reduction.
    const Eigen::VectorXd& m = problem.mass();
    Eigen::VectorXd work = T, w(T.size());
    for (long k = 0; k < n; ++k) {
      problem.heat_rate(t0 + (static_cast<double>(k) + 0.5) * h, work.data(), w.data());
      for (Index i = 0; i < work.size(); ++i) {
        const double dTdt = w[i] / m[i];
        work[i] += h * dTdt;
      }
    }
    stats_.steps += n;
    stats_.rhs_evals += n;
    stats_.wall_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!all_ranks(problem.comm(), work.allFinite())) {
      std::ostringstream os;
      os << "forward_euler (distributed): temperatures became non-finite with step " << h
         << " s against the stability limit " << dt_limit_ << " s";
      throw StabilityError(os.str(), h, dt_limit_);
    }
    T = std::move(work);
  }

 private:
  IntegratorOptions opt_;
  std::uint64_t revision_ = 0;
  double dt_limit_ = 0.0;
};

// ---------------------------------------------------------------- SUNDIALS integrators
enum class Method { CvodeBdf, CvodeAdams, ArkodeErk, ArkodeDirk };
enum class Linear { None, FixedPoint, Pcg, Gmres };

class DistSundials final : public DistributedIntegrator {
 public:
  DistSundials(std::string name, Method method, Linear lin, const DistributedOptions& o)
      : name_(std::move(name)), method_(method), lin_(lin), opt_(o.integrator), pc_(o.preconditioner) {}
  ~DistSundials() override { release(); }
  std::string name() const override { return name_; }

 protected:
  void advance_impl(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1) override;

 private:
  bool krylov() const { return lin_ == Linear::Pcg || lin_ == Linear::Gmres; }
  void check(int flag, const char* call) const {
    check_flag(flag, call, name_ + " (distributed)", flag_name_fn(), sink_);
  }
  FlagNameFn flag_name_fn() const {
    if (method_ == Method::ArkodeErk) return &ERKStepGetReturnFlagName;
    if (method_ == Method::ArkodeDirk) return &ARKStepGetReturnFlagName;
    return &CVodeGetReturnFlagName;
  }
  void release() {
    mem_.reset();  // *Free before the solvers it references
    nls_.reset();
    ls_.reset();
  }
  void create(double t0);
  void reinit(double t0);
  int evolve(double t1);
  IntegratorStats counters() const;

  std::string name_;
  Method method_;
  Linear lin_;
  IntegratorOptions opt_;
  std::string pc_;
  ContextPtr ctx_;
  NVectorPtr y_, abstol_;
  MemPtr mem_;
  LinSolPtr ls_;
  NonlinSolPtr nls_;
  DistributedOde sys_;
  ErrorSink sink_;
  bool built_ = false;
  std::uint64_t revision_ = 0;
  double t_last_ = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd t_state_last_, progress_last_;
  IntegratorStats base_, offset_;
  long reinits_ = 0;
  double wall_ = 0.0;
};

void DistSundials::create(double t0) {
  SUNContext ctx = ctx_.get();
  N_Vector y = y_.get();
  void* mem = nullptr;
  if (method_ == Method::CvodeBdf || method_ == Method::CvodeAdams) {
    mem_ = MemPtr(CVodeCreate(method_ == Method::CvodeBdf ? CV_BDF : CV_ADAMS, ctx), MemDeleter{&CVodeFree});
    check_ptr(mem_.get(), "CVodeCreate", name_);
    mem = mem_.get();
    check(CVodeSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "CVodeSetErrHandlerFn");
    check(CVodeInit(mem, &DistributedOde::rhs, t0, y), "CVodeInit");
    check(CVodeSVtolerances(mem, opt_.rtol, abstol_.get()), "CVodeSVtolerances");
    check(CVodeSetUserData(mem, &sys_), "CVodeSetUserData");
    check(CVodeSetMaxNumSteps(mem, opt_.max_steps), "CVodeSetMaxNumSteps");
  } else if (method_ == Method::ArkodeErk) {
    mem_ = MemPtr(ERKStepCreate(&DistributedOde::rhs, t0, y, ctx), MemDeleter{&ERKStepFree});
    check_ptr(mem_.get(), "ERKStepCreate", name_);
    mem = mem_.get();
    check(ERKStepSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "ERKStepSetErrHandlerFn");
    check(ERKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ERKStepSVtolerances");
    check(ERKStepSetUserData(mem, &sys_), "ERKStepSetUserData");
    check(ERKStepSetMaxNumSteps(mem, opt_.max_steps), "ERKStepSetMaxNumSteps");
    return;
  } else {
    mem_ = MemPtr(ARKStepCreate(nullptr, &DistributedOde::rhs, t0, y, ctx), MemDeleter{&ARKStepFree});
    check_ptr(mem_.get(), "ARKStepCreate", name_);
    mem = mem_.get();
    check(ARKStepSetErrHandlerFn(mem, &ErrorSink::handler, &sink_), "ARKStepSetErrHandlerFn");
    check(ARKStepSetTableNum(mem, ARKODE_ESDIRK324L2SA_4_2_3, ARKODE_ERK_NONE), "ARKStepSetTableNum");  // as serial
    check(ARKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ARKStepSVtolerances");
    check(ARKStepSetUserData(mem, &sys_), "ARKStepSetUserData");
    check(ARKStepSetMaxNumSteps(mem, opt_.max_steps), "ARKStepSetMaxNumSteps");
  }
  const bool cvode = method_ != Method::ArkodeDirk;
  if (lin_ == Linear::FixedPoint) {  // cvode_adams: functional iteration
    nls_ = NonlinSolPtr(SUNNonlinSol_FixedPoint(y, 0, ctx));
    check_ptr(nls_.get(), "SUNNonlinSol_FixedPoint", name_);
    check(CVodeSetNonlinearSolver(mem, nls_.get()), "CVodeSetNonlinearSolver");
    return;
  }
  // Krylov: exact J·v (one ghost exchange), left preconditioner from PETSc (with a reaction: the
  // serial 2×2 block Jacobi). A consuming reaction makes the Newton matrix non-symmetric: GMRES, as
  // the serial make_krylov_solver.
  const bool pcg = lin_ == Linear::Pcg && !sys_.nonsymmetric();
  ls_ = LinSolPtr(pcg ? SUNLinSol_PCG(y, SUN_PREC_LEFT, opt_.krylov_maxl, ctx)
                      : SUNLinSol_SPGMR(y, SUN_PREC_LEFT, opt_.krylov_maxl, ctx));
  check_ptr(ls_.get(), pcg ? "SUNLinSol_PCG" : "SUNLinSol_SPGMR", name_);
  if (sys_.conserves()) {  // insulated: keep Σ M T exact whatever the preconditioner
    NVectorPtr c(N_VClone(y));
    sys_.to_y(Eigen::VectorXd::Ones(sys_.nodes()), nullptr, c.get());  // c = M^{1/2}·1
    ls_ = make_conservative_krylov(std::move(ls_), c.get(), ctx);
  }
  if (cvode) {
    check(CVodeSetLinearSolver(mem, ls_.get(), nullptr), "CVodeSetLinearSolver");
    check(CVodeSetJacTimes(mem, nullptr, &DistributedOde::jtimes), "CVodeSetJacTimes");
    check(CVodeSetPreconditioner(mem, &DistributedOde::psetup, &DistributedOde::psolve), "CVodeSetPreconditioner");
  } else {
    check(ARKStepSetLinearSolver(mem, ls_.get(), nullptr), "ARKStepSetLinearSolver");
    check(ARKStepSetJacTimes(mem, nullptr, &DistributedOde::jtimes), "ARKStepSetJacTimes");
    check(ARKStepSetPreconditioner(mem, &DistributedOde::psetup, &DistributedOde::psolve), "ARKStepSetPreconditioner");
    if (!sys_.reacts()) check(ARKStepSetLinear(mem, 0), "ARKStepSetLinear");  // f linear in y, constant J
  }
}

void DistSundials::reinit(double t0) {
  void* mem = mem_.get();
  if (method_ == Method::ArkodeErk) {
    check(ERKStepReInit(mem, &DistributedOde::rhs, t0, y_.get()), "ERKStepReInit");
    check(ERKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ERKStepSVtolerances");
  } else if (method_ == Method::ArkodeDirk) {
    check(ARKStepReInit(mem, nullptr, &DistributedOde::rhs, t0, y_.get()), "ARKStepReInit");
    check(ARKStepSVtolerances(mem, opt_.rtol, abstol_.get()), "ARKStepSVtolerances");
  } else {
    check(CVodeReInit(mem, t0, y_.get()), "CVodeReInit");
    check(CVodeSVtolerances(mem, opt_.rtol, abstol_.get()), "CVodeSVtolerances");
  }
}

int DistSundials::evolve(double t1) {
  void* mem = mem_.get();
  sunrealtype tret = 0.0;
  if (method_ == Method::ArkodeErk) {
    check(ERKStepSetStopTime(mem, t1), "ERKStepSetStopTime");
    return ERKStepEvolve(mem, t1, y_.get(), &tret, ARK_NORMAL);
  }
  if (method_ == Method::ArkodeDirk) {
    check(ARKStepSetStopTime(mem, t1), "ARKStepSetStopTime");
    return ARKStepEvolve(mem, t1, y_.get(), &tret, ARK_NORMAL);
  }
  check(CVodeSetStopTime(mem, t1), "CVodeSetStopTime");  // 6.4.1: set every window
  return CVode(mem, t1, y_.get(), &tret, CV_NORMAL);
}

IntegratorStats DistSundials::counters() const {
  IntegratorStats s;
  void* mem = mem_.get();
  if (mem == nullptr) return s;
  long a = 0, b = 0, c = 0;
  if (method_ == Method::ArkodeErk) {
    ERKStepGetNumSteps(mem, &s.steps);
    ERKStepGetNumRhsEvals(mem, &s.rhs_evals);
    ERKStepGetNumErrTestFails(mem, &s.error_test_failures);
  } else if (method_ == Method::ArkodeDirk) {
    ARKStepGetNumSteps(mem, &s.steps);
    ARKStepGetNumRhsEvals(mem, &a, &b);
    ARKStepGetNumErrTestFails(mem, &s.error_test_failures);
    ARKStepGetNonlinSolvStats(mem, &s.nonlinear_iters, &s.convergence_failures);
    ARKStepGetNumLinIters(mem, &s.linear_iters);
    ARKStepGetNumLinRhsEvals(mem, &c);
    s.rhs_evals = a + b + c;
  } else {
    CVodeGetNumSteps(mem, &s.steps);
    CVodeGetNumRhsEvals(mem, &s.rhs_evals);
    CVodeGetNumErrTestFails(mem, &s.error_test_failures);
    CVodeGetNonlinSolvStats(mem, &s.nonlinear_iters, &s.convergence_failures);
    if (krylov()) {
      CVodeGetNumLinIters(mem, &s.linear_iters);
      CVodeGetNumLinRhsEvals(mem, &c);
      s.rhs_evals += c;
    }
  }
  s.jac_evals = sys_.preconditioner_setups();  // P = I − γJ assemblies (J itself is constant)
  return s;
}

void DistSundials::advance_impl(const DistributedProblem& problem, Eigen::VectorXd& T, double t0, double t1) {
  const auto start = std::chrono::steady_clock::now();
  auto absorb = [&] {
    base_ += counters();
    base_ -= offset_;
  };
  if (!built_ || problem.revision() != revision_) {
    if (built_) absorb();
    built_ = false;
    release();
    if (!ctx_) ctx_ = make_context();
    sys_.build(problem, krylov(), krylov() ? pc_ : std::string());  // Krylov: symmetric form
    const MPI_Comm comm = problem.comm();
    long local = static_cast<long>(sys_.state_size()), global = 0;  // [s ⊙ T; λ of the reacting nodes]
    MPI_Allreduce(&local, &global, 1, MPI_LONG, MPI_SUM, comm);
    DistributedProblem::count_reductions(1);
    y_ = make_parallel_vector(comm, sys_.state_size(), static_cast<Index>(global), ctx_.get());
    abstol_ = make_parallel_vector(comm, sys_.state_size(), static_cast<Index>(global), ctx_.get());
    // s_i·atol (√M_i·atol on the symmetric form) on T, progress_atol on λ
    sys_.fill_abstol(opt_.atol, opt_.progress_atol, abstol_.get());
    sys_.to_y(T, progress_, y_.get());
    sink_.last_message.clear();
    create(t0);
    built_ = true;
    revision_ = problem.revision();
    offset_ = counters();
    ++reinits_;
  } else {
    sys_.bind(problem);
    // Continue with the history when the state is the one this integrator left (all ranks agree).
    bool mine = t0 == t_last_ && T.size() == t_state_last_.size() && T == t_state_last_;
    if (progress_) mine = mine && progress_->size() == progress_last_.size() && *progress_ == progress_last_;
    if (opt_.reinit_every_window || !all_ranks(problem.comm(), mine)) {
      absorb();
      sys_.to_y(T, progress_, y_.get());
      sink_.last_message.clear();
      reinit(t0);
      offset_ = counters();
      ++reinits_;
    }
  }
  t_last_ = std::numeric_limits<double>::quiet_NaN();  // a failed window forces a re-init
  const int flag = evolve(t1);
  stats_ = base_;
  stats_ += counters();
  stats_ -= offset_;
  stats_.reinits = reinits_;
  wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats_.wall_seconds = wall_;
  if (flag < 0) {
    std::ostringstream call;
    call << (method_ == Method::ArkodeErk ? "ERKStepEvolve" : method_ == Method::ArkodeDirk ? "ARKStepEvolve" : "CVode")
         << " from t = " << t0 << " to " << t1 << " s";
    if (flag == -1) call << " (max_steps = " << opt_.max_steps << " steps per window reached)";
    const std::string c = call.str();
    check(flag, c.c_str());
  }
  Eigen::VectorXd out;
  sys_.to_T(y_.get(), out, progress_);
  problem.apply_dirichlet(out);  // exact fixed values (y/s round trip)
  T = std::move(out);
  t_state_last_ = T;
  if (progress_) progress_last_ = *progress_;
  t_last_ = t1;
}

}  // namespace
}  // namespace detail

std::unique_ptr<DistributedIntegrator> make_distributed_integrator(const std::string& name,
                                                                   const DistributedOptions& options) {
  // The serial factory checks the name and the shared options (it throws with the valid list).
  (void)make_integrator(name, [&] {
    IntegratorOptions o = options.integrator;
    o.linear_solver.clear();  // checked below: the distributed set differs (no klu)
    return o;
  }());
  const IntegratorOptions& o = options.integrator;
  const std::string& ls = o.linear_solver;
  auto bad = [&](const std::string& what) {
    throw std::invalid_argument("make_distributed_integrator(\"" + name + "\"): " + what);
  };
  const std::string& pc = options.preconditioner;
  if (pc != "jacobi" && pc != "bjacobi" && pc != "hypre") {
    bad("unknown preconditioner \"" + pc + "\" (valid: jacobi, bjacobi, hypre)");
  }
  if (o.fe_limit_estimate != "gershgorin") {
    bad("fe_limit_estimate \"" + o.fe_limit_estimate + "\" is not distributed yet (valid: gershgorin)");
  }
  using detail::DistSundials;
  using detail::Linear;
  using detail::Method;
  auto krylov = [&](Linear fallback, bool allow_fixed_point) {
    if (ls.empty()) return fallback;
    if (ls == "pcg") return Linear::Pcg;
    if (ls == "gmres") return Linear::Gmres;
    if (allow_fixed_point && ls == "fixed_point") return Linear::FixedPoint;
    if (ls == "klu") bad("linear_solver \"klu\" (sparse direct) has no distributed counterpart (valid: pcg, gmres)");
    bad("unknown linear_solver \"" + ls + "\" (valid: pcg, gmres" + (allow_fixed_point ? ", fixed_point)" : ")"));
    return fallback;
  };
  if (name == "forward_euler" || name == "arkode_erk") {
    if (!ls.empty()) bad("linear_solver \"" + ls + "\" given, but this explicit integrator uses no linear solver");
    if (name == "forward_euler") return std::make_unique<detail::DistForwardEuler>(o);
    return std::make_unique<DistSundials>(name, Method::ArkodeErk, Linear::None, options);
  }
  if (name == "cvode_bdf") return std::make_unique<DistSundials>(name, Method::CvodeBdf, krylov(Linear::Pcg, false), options);
  if (name == "cvode_adams") {
    return std::make_unique<DistSundials>(name, Method::CvodeAdams, krylov(Linear::FixedPoint, true), options);
  }
  return std::make_unique<DistSundials>(name, Method::ArkodeDirk, krylov(Linear::Pcg, false), options);
}

}  // namespace frictherm::thermal
