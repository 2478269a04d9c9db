#include "sundials_integrator.hpp"

#include "conservative_krylov.hpp"

#include <sunlinsol/sunlinsol_pcg.h>
#include <sunlinsol/sunlinsol_spgmr.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace frictherm::thermal::detail {

LinSolPtr make_krylov_solver(const ThermalOde& ode, LinearSolverKind lin, N_Vector y, int maxl, SUNContext ctx,
                             const std::string& who) {
  const bool pcg = lin == LinearSolverKind::Pcg && !ode.nonsymmetric();  // a consuming reaction: GMRES
  LinSolPtr ls(pcg ? SUNLinSol_PCG(y, SUN_PREC_LEFT, maxl, ctx) : SUNLinSol_SPGMR(y, SUN_PREC_LEFT, maxl, ctx));
  check_ptr(ls.get(), pcg ? "SUNLinSol_PCG" : "SUNLinSol_SPGMR", who);
  if (!ode.conserves()) return ls;
  NVectorPtr c(N_VClone(y));  // insulated: keep Σ M T exact whatever the preconditioner
  ode.fill_abstol(1.0, 0.0, c.get());  // c = M^{1/2}·1 on the symmetric form (no λ: no reaction)
  return make_conservative_krylov(std::move(ls), c.get(), ctx);
}

LinearSolverKind parse_linear_solver(const std::string& integrator, const std::string& value, bool direct) {
  const bool implicit = integrator == "cvode_bdf" || integrator == "arkode_dirk";
  const bool adams = integrator == "cvode_adams";
  if (implicit || adams) {
    if (value.empty()) return adams ? LinearSolverKind::FixedPoint : direct ? LinearSolverKind::Klu : LinearSolverKind::Pcg;
    if (value == "klu" && direct) return LinearSolverKind::Klu;
    if (value == "pcg") return LinearSolverKind::Pcg;
    if (value == "gmres" && !direct) return LinearSolverKind::Gmres;  // serial: "pcg" turns GMRES when needed
    if (adams && value == "fixed_point") return LinearSolverKind::FixedPoint;
    if (value == "klu") {
      throw std::invalid_argument(integrator + ": linear_solver \"klu\" (sparse direct) has no distributed "
                                  "counterpart (valid: pcg, gmres" + (adams ? ", fixed_point)" : ")"));
    }
    throw std::invalid_argument(integrator + ": unknown linear_solver \"" + value + "\" (valid: " +
                                (direct ? "klu, pcg" : "pcg, gmres") + (adams ? ", fixed_point)" : ")"));
  }
  if (!value.empty()) {
    throw std::invalid_argument(integrator + ": linear_solver \"" + value +
                                "\" given, but this explicit integrator uses no linear solver");
  }
  return LinearSolverKind::None;
}

SundialsIntegrator::SundialsIntegrator(std::string name, const IntegratorOptions& options,
                                       LinearSolverKind lin)
    : Scheme(std::move(name)), opt_(options), lin_(lin) {}

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

void SundialsIntegrator::advance(ThermalOde& ode, Eigen::VectorXd& T, Eigen::VectorXd* progress, double t0,
                                 double t1) {
  const auto start = std::chrono::steady_clock::now();
  if (t1 == t0) return;
  sys_ = &ode;
  who_ = ode.who(name_);

  const bool same_problem = built_ && ode.revision() == revision_ && ode.size() == ode.nodes();
  // The progress (λ = 0 without one) is part of the state (consuming) or of the RHS (zero-order).
  const Eigen::VectorXd progress_now = progress != nullptr ? *progress : Eigen::VectorXd::Zero(ode.size());
  bool renewed = false;  // a changed problem of the same shape: new M, K in the kept solver memory
  if (!same_problem && built_ && lin_ != LinearSolverKind::Klu && !conservative_ &&
      ode.all_ranks(ode.size() == ode.nodes())) {
    const Index old_size = ode.state_size();
    const bool old_reaction = ode.has_reaction(), old_nonsymmetric = ode.nonsymmetric();
    ode.build(krylov());
    // The solver set-up depends only on these (KLU's matrix has the old pattern: rebuilt below;
    // the conservative wrapper holds M^{1/2}·1).
    if (ode.all_ranks(ode.state_size() == old_size && ode.has_reaction() == old_reaction &&
                      ode.nonsymmetric() == old_nonsymmetric && !ode.conserves())) {
      absorb_counters();
      ode.fill_abstol(opt_.atol, opt_.progress_atol, abstol_.get());
      ode.to_y(T, progress, y_.get());
      sink_.last_message.clear();
      reinit(t0);  // history cleared: M and K changed under it
      revision_ = ode.revision();
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
    ode.build(krylov());  // Krylov: the symmetric form
    y_ = ode.make_vector(ctx_.get());
    abstol_ = NVectorPtr(N_VClone(y_.get()));
    // abstol_i = s_i·atol (√M_i·atol for Krylov) on T, progress_atol on λ
    ode.fill_abstol(opt_.atol, opt_.progress_atol, abstol_.get());
    ode.to_y(T, progress, y_.get());
    sink_.last_message.clear();
    create(t0);
    conservative_ = krylov() && ode.conserves();
    built_ = true;
    revision_ = ode.revision();
    offset_ = counters();
    ++reinits_;
  } else if (!renewed) {
    ode.bind();
    // Continue with the history when the state is the one this integrator left (on every process).
    const bool mine = t0 == t_last_ && T.size() == t_state_last_.size() && T == t_state_last_ &&
                      progress_now.size() == progress_last_.size() && progress_now == progress_last_;
    const bool continues = !opt_.reinit_every_window && ode.all_ranks(mine);
    if (!continues) {
      absorb_counters();
      ode.to_y(T, progress, y_.get());
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
  ode.to_T(y_.get(), out, progress);
  ode.apply_dirichlet(out);  // exact fixed values (y/s round trip)
  T = std::move(out);
  t_state_last_ = T;
  progress_last_ = progress != nullptr ? *progress : Eigen::VectorXd::Zero(ode.size());
  t_last_ = t1;
}

}  // namespace frictherm::thermal::detail
