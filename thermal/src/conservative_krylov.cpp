#include "conservative_krylov.hpp"

#include <sundials/sundials_linearsolver.h>

namespace frictherm::thermal::detail {
namespace {

struct Content {
  SUNLinearSolver inner = nullptr;
  N_Vector c = nullptr;
  double cc = 0.0;  // c·c
};

SUNLinearSolver inner(SUNLinearSolver s) { return static_cast<Content*>(s->content)->inner; }

SUNLinearSolver_Type get_type(SUNLinearSolver s) { return SUNLinSolGetType(inner(s)); }
SUNLinearSolver_ID get_id(SUNLinearSolver s) { return SUNLinSolGetID(inner(s)); }
int set_atimes(SUNLinearSolver s, void* data, SUNATimesFn f) { return SUNLinSolSetATimes(inner(s), data, f); }
int set_preconditioner(SUNLinearSolver s, void* data, SUNPSetupFn ps, SUNPSolveFn pv) {
  return SUNLinSolSetPreconditioner(inner(s), data, ps, pv);
}
int set_scaling(SUNLinearSolver s, N_Vector s1, N_Vector s2) { return SUNLinSolSetScalingVectors(inner(s), s1, s2); }
int set_zero_guess(SUNLinearSolver s, booleantype z) { return SUNLinSolSetZeroGuess(inner(s), z); }
int initialize(SUNLinearSolver s) { return SUNLinSolInitialize(inner(s)); }
int setup(SUNLinearSolver s, SUNMatrix a) { return SUNLinSolSetup(inner(s), a); }
int num_iters(SUNLinearSolver s) { return SUNLinSolNumIters(inner(s)); }
realtype res_norm(SUNLinearSolver s) { return SUNLinSolResNorm(inner(s)); }
sunindextype last_flag(SUNLinearSolver s) { return SUNLinSolLastFlag(inner(s)); }
int space(SUNLinearSolver s, long* lrw, long* liw) { return SUNLinSolSpace(inner(s), lrw, liw); }
N_Vector resid(SUNLinearSolver s) { return SUNLinSolResid(inner(s)); }

int solve(SUNLinearSolver s, SUNMatrix a, N_Vector x, N_Vector b, realtype tol) {
  auto* w = static_cast<Content*>(s->content);
  const int flag = SUNLinSolSolve(w->inner, a, x, b, tol);
  if (flag < 0) return flag;  // unrecoverable: leave it to the integrator
  N_Vector v[2] = {b, x};
  realtype d[2] = {0.0, 0.0};
  if (N_VDotProdMulti(2, w->c, v, d) != 0) return SUNLS_VECTOROP_ERR;  // c·b, c·x: one reduction
  N_VLinearSum(1.0, x, (d[0] - d[1]) / w->cc, w->c, x);
  return flag;
}

int free_solver(SUNLinearSolver s) {
  if (s == nullptr) return 0;
  auto* w = static_cast<Content*>(s->content);
  if (w != nullptr) {
    SUNLinSolFree(w->inner);
    N_VDestroy(w->c);
    delete w;
    s->content = nullptr;
  }
  SUNLinSolFreeEmpty(s);
  return 0;
}

}  // namespace

LinSolPtr make_conservative_krylov(LinSolPtr inner_solver, N_Vector c, SUNContext ctx) {
  SUNLinearSolver s = SUNLinSolNewEmpty(ctx);
  check_ptr(s, "SUNLinSolNewEmpty", "thermal (distributed)");
  auto* w = new Content;
  w->inner = inner_solver.release();
  w->c = N_VClone(c);
  N_VScale(1.0, c, w->c);
  w->cc = N_VDotProd(c, c);
  s->content = w;
  s->ops->gettype = get_type;
  s->ops->getid = get_id;
  s->ops->setatimes = set_atimes;
  s->ops->setpreconditioner = set_preconditioner;
  s->ops->setscalingvectors = set_scaling;
  s->ops->setzeroguess = set_zero_guess;
  s->ops->initialize = initialize;
  s->ops->setup = setup;
  s->ops->solve = solve;
  s->ops->numiters = num_iters;
  s->ops->resnorm = res_norm;
  s->ops->lastflag = last_flag;
  s->ops->space = space;
  s->ops->resid = resid;
  s->ops->free = free_solver;
  return LinSolPtr(s);
}

}  // namespace frictherm::thermal::detail
