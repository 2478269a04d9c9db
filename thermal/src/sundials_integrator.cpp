#include "sundials_integrator.hpp"

#include <sunlinsol/sunlinsol_pcg.h>
#include <sunlinsol/sunlinsol_spgmr.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace frictherm::thermal::detail {

LinSolPtr make_krylov_solver(const OdeSystem& sys, N_Vector y, int maxl, SUNContext ctx, const std::string& who) {
  if (sys.nonsymmetric()) {
    LinSolPtr ls(SUNLinSol_SPGMR(y, SUN_PREC_LEFT, maxl, ctx));
    check_ptr(ls.get(), "SUNLinSol_SPGMR", who);
    return ls;
  }
  LinSolPtr ls(SUNLinSol_PCG(y, SUN_PREC_LEFT, maxl, ctx));
  check_ptr(ls.get(), "SUNLinSol_PCG", who);
  return ls;
}

LinearSolverKind parse_linear_solver(const std::string& integrator, const std::string& value) {
  const bool implicit = integrator == "cvode_bdf" || integrator == "arkode_dirk";
  const bool adams = integrator == "cvode_adams";
  if (implicit || adams) {
    if (value.empty()) return implicit ? LinearSolverKind::Klu : LinearSolverKind::FixedPoint;
    if (value == "klu") return LinearSolverKind::Klu;
    if (value == "pcg") return LinearSolverKind::Pcg;
    if (adams && value == "fixed_point") return LinearSolverKind::FixedPoint;
    throw std::invalid_argument(integrator + ": unknown linear_solver \"" + value + "\" (valid: klu, pcg" +
                                (adams ? ", fixed_point)" : ")"));
  }
  if (!value.empty()) {
    throw std::invalid_argument(integrator + ": linear_solver \"" + value +
                                "\" given, but this explicit integrator uses no linear solver");
  }
  return LinearSolverKind::None;
}

SundialsIntegrator::SundialsIntegrator(std::string name, const IntegratorOptions& options,
                                       LinearSolverKind lin)
    : name_(std::move(name)), opt_(options), lin_(lin) {}

void SundialsIntegrator::absorb_counters() {
  base_ += counters();
  base_ -= offset_;
}

void SundialsIntegrator::refresh_stats() {
  stats_ = base_;
  if (built_) {
    stats_ += counters();
    stats_ -= offset_;
  }
  stats_.reinits = reinits_;
  stats_.wall_seconds = wall_;
}

void SundialsIntegrator::on_reset_stats() {
  base_ = IntegratorStats{};
  offset_ = built_ ? counters() : IntegratorStats{};
  wall_ = 0.0;
  reinits_ = 0;
}

void SundialsIntegrator::advance_impl(const Problem& problem, Eigen::VectorXd& T, Eigen::VectorXd* progress,
                                      double t0, double t1) {
  const auto start = std::chrono::steady_clock::now();
  problem.check_state(T);
  if (!(std::isfinite(t0) && std::isfinite(t1) && t1 >= t0)) {
    std::ostringstream os;
    os << name_ << ": need finite t1 >= t0, got [" << t0 << ", " << t1 << "]";
    throw std::invalid_argument(os.str());
  }
  problem.apply_dirichlet(T);
  if (t1 == t0) return;

  const bool same_problem = built_ && problem.revision() == revision_ && problem.size() == sys_.nodes();
  // The progress (λ = 0 without one) is part of the state (consuming) or of the RHS (zero-order).
  const Eigen::VectorXd progress_now = progress != nullptr ? *progress : Eigen::VectorXd::Zero(problem.size());
  bool renewed = false;  // a changed problem of the same shape: new M, K in the kept solver memory
  if (!same_problem && built_ && lin_ != LinearSolverKind::Klu && problem.size() == sys_.nodes()) {
    const Index old_size = sys_.state_size();
    const bool old_reaction = sys_.has_reaction(), old_nonsymmetric = sys_.nonsymmetric();
    sys_.build(problem, lin_ == LinearSolverKind::Pcg);
    if (sys_.state_size() == old_size && sys_.has_reaction() == old_reaction &&
        sys_.nonsymmetric() == old_nonsymmetric) {
      // The solver set-up depends only on these (KLU's matrix has the old pattern: rebuilt below).
      absorb_counters();
      sys_.fill_abstol(opt_.atol, opt_.progress_atol, abstol_.get());
      sys_.to_y(T, progress, y_.get());
      sink_.last_message.clear();
      reinit(t0);  // history cleared: M and K changed under it
      revision_ = problem.revision();
      offset_ = counters();
      ++reinits_;
      renewed = true;
    }
  }
  if (!same_problem && !renewed) {
    if (built_) absorb_counters();
    built_ = false;
    release();
    if (!ctx_) ctx_ = make_context();
    sys_.build(problem, lin_ == LinearSolverKind::Pcg);
    y_ = make_vector(static_cast<long>(sys_.state_size()), ctx_.get());
    abstol_ = make_vector(static_cast<long>(sys_.state_size()), ctx_.get());
    // abstol_i = s_i·atol (√M_i·atol for PCG) on T, progress_atol on λ
    sys_.fill_abstol(opt_.atol, opt_.progress_atol, abstol_.get());
    sys_.to_y(T, progress, y_.get());
    sink_.last_message.clear();
    create(t0);
    built_ = true;
    revision_ = problem.revision();
    offset_ = counters();
    ++reinits_;
  } else if (!renewed) {
    sys_.bind(problem);
    const bool continues = !opt_.reinit_every_window && t0 == t_last_ && T == t_state_last_ &&
                           progress_now.size() == progress_last_.size() && progress_now == progress_last_;
    if (!continues) {
      absorb_counters();
      sys_.to_y(T, progress, y_.get());
      sink_.last_message.clear();
      reinit(t0);
      offset_ = counters();
      ++reinits_;
    }
  }

  t_last_ = std::numeric_limits<double>::quiet_NaN();  // a failed window forces a re-init
  const int flag = evolve(t1);
  refresh_stats();
  wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stats_.wall_seconds = wall_;
  if (flag < 0) {
    std::ostringstream call;
    call << evolve_call() << " from t = " << t0 << " to " << t1 << " s";
    if (flag == -1) {  // CV_TOO_MUCH_WORK == ARK_TOO_MUCH_WORK
      call << " (max_steps = " << opt_.max_steps
           << " steps per window reached; raise IntegratorOptions::max_steps, shorten the "
              "window or use an implicit integrator such as cvode_bdf)";
    }
    const std::string c = call.str();
    check(flag, c.c_str());
  }
  Eigen::VectorXd out;
  sys_.to_T(y_.get(), out, progress);
  problem.apply_dirichlet(out);  // exact fixed values (y/s round trip)
  T = std::move(out);
  t_state_last_ = T;
  progress_last_ = progress != nullptr ? *progress : Eigen::VectorXd::Zero(problem.size());
  t_last_ = t1;
}

}  // namespace frictherm::thermal::detail
