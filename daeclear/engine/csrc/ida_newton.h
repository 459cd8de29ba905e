/*
 * ida_newton.h -- IDA's Newton solver with its own convergence-test weights (dc_set_newton_atol).
 *
 * Plain IDA weighs its error test and its Newton convergence test with the same vector ewt = 1/(rtol |y| +
 * atol). A run's sensitivities left out of the error test (their atol there is huge, as the multipliers')
 * would then be out of the Newton test too: their corrections never checked. IDAS keeps them in the Newton
 * test (errconS = false); so does this wrapper: a SUNNonlinearSolver that hands SUNDIALS' own Newton solver
 * the weights 1/(rtol |y0| + nls_atol) for the rows with nls_atol > 0 (y0: IDA's predicted state) and IDA's
 * for the others. Everything else is the Newton solver's: IDA sets its callbacks and iteration limit on the
 * wrapper, which forwards them.
 */
#ifndef DAECLEAR_IDA_NEWTON_H
#define DAECLEAR_IDA_NEWTON_H

#include <sunnonlinsol/sunnonlinsol_newton.h> /* SUNDIALS' Newton solver (its code is in the IDA library) */

static dc_session* nls_session(SUNNonlinearSolver NLS) { return (dc_session*)NLS->content; }

static SUNNonlinearSolver_Type nls_gettype(SUNNonlinearSolver NLS) {
  return SUNNonlinSolGetType(nls_session(NLS)->nls_inner);
}
static SUNErrCode nls_initialize(SUNNonlinearSolver NLS) {
  return SUNNonlinSolInitialize(nls_session(NLS)->nls_inner);
}
static SUNErrCode nls_setsysfn(SUNNonlinearSolver NLS, SUNNonlinSolSysFn f) {
  return SUNNonlinSolSetSysFn(nls_session(NLS)->nls_inner, f);
}
static SUNErrCode nls_setlsetupfn(SUNNonlinearSolver NLS, SUNNonlinSolLSetupFn f) {
  return SUNNonlinSolSetLSetupFn(nls_session(NLS)->nls_inner, f);
}
static SUNErrCode nls_setlsolvefn(SUNNonlinearSolver NLS, SUNNonlinSolLSolveFn f) {
  return SUNNonlinSolSetLSolveFn(nls_session(NLS)->nls_inner, f);
}
static SUNErrCode nls_setctestfn(SUNNonlinearSolver NLS, SUNNonlinSolConvTestFn f, void* data) {
  return SUNNonlinSolSetConvTestFn(nls_session(NLS)->nls_inner, f, data);
}
static SUNErrCode nls_setmaxiters(SUNNonlinearSolver NLS, int maxiters) {
  return SUNNonlinSolSetMaxIters(nls_session(NLS)->nls_inner, maxiters);
}
static SUNErrCode nls_getnumiters(SUNNonlinearSolver NLS, long int* n) {
  return SUNNonlinSolGetNumIters(nls_session(NLS)->nls_inner, n);
}
static SUNErrCode nls_getcuriter(SUNNonlinearSolver NLS, int* iter) {
  return SUNNonlinSolGetCurIter(nls_session(NLS)->nls_inner, iter);
}
static SUNErrCode nls_getnumconvfails(SUNNonlinearSolver NLS, long int* n) {
  return SUNNonlinSolGetNumConvFails(nls_session(NLS)->nls_inner, n);
}
static SUNErrCode nls_free(SUNNonlinearSolver NLS) {
  (void)NLS; /* dc_free frees the wrapper and the Newton solver (nls_release) */
  return SUN_SUCCESS;
}

/* The Newton solve with the session's weights: IDA's w, or 1/(rtol |y0| + nls_atol) where nls_atol > 0. */
static int nls_solve(SUNNonlinearSolver NLS, N_Vector y0, N_Vector ycor, N_Vector w, sunrealtype tol,
                     sunbooleantype callLSetup, void* mem) {
  dc_session* s = nls_session(NLS);
  N_Vector weights = w;
  if (s->nls_on) {
    const double* wi = N_VGetArrayPointer(w);
    const double* y = N_VGetArrayPointer(y0);
    double* wo = N_VGetArrayPointer(s->nls_w);
    for (int i = 0; i < s->n; ++i)
      wo[i] = s->nls_atol[i] > 0.0 ? 1.0 / (s->rtol * fabs(y[i]) + s->nls_atol[i]) : wi[i];
    weights = s->nls_w;
  }
  return SUNNonlinSolSolve(s->nls_inner, y0, ycor, weights, tol, callLSetup, mem);
}

/* Free the wrapper and its Newton solver (after IDAFree: IDA does not own them). */
static void nls_release(dc_session* s) {
  if (s->nls) SUNNonlinSolFreeEmpty(s->nls);
  if (s->nls_inner) SUNNonlinSolFree(s->nls_inner);
  if (s->nls_w) N_VDestroy(s->nls_w);
  free(s->nls_atol);
  s->nls = s->nls_inner = NULL;
  s->nls_w = NULL;
  s->nls_atol = NULL;
}

/* Install the wrapper on first use. 0 done, -1 out of memory or refused by IDA (message in s->msg). */
static int nls_install(dc_session* s) {
  if (s->nls) return 0;
  s->nls_inner = SUNNonlinSol_Newton(s->yy, s->ctx);
  s->nls = SUNNonlinSolNewEmpty(s->ctx);
  s->nls_w = N_VClone(s->yy);
  s->nls_atol = (double*)calloc((size_t)s->n, sizeof(double));
  if (!s->nls_inner || !s->nls || !s->nls_w || !s->nls_atol) {
    nls_release(s);
    set_msg(s->msg, "the Newton solver's weights: out of memory");
    return -1;
  }
  s->nls->content = s;
  s->nls->ops->gettype = nls_gettype;
  s->nls->ops->initialize = nls_initialize;
  s->nls->ops->solve = nls_solve;
  s->nls->ops->free = nls_free;
  s->nls->ops->setsysfn = nls_setsysfn;
  s->nls->ops->setlsetupfn = nls_setlsetupfn;
  s->nls->ops->setlsolvefn = nls_setlsolvefn;
  s->nls->ops->setctestfn = nls_setctestfn;
  s->nls->ops->setmaxiters = nls_setmaxiters;
  s->nls->ops->getnumiters = nls_getnumiters;
  s->nls->ops->getcuriter = nls_getcuriter;
  s->nls->ops->getnumconvfails = nls_getnumconvfails;
  int flag = IDASetNonlinearSolver(s->ida, s->nls);
  if (flag < 0) {
    set_msg(s->msg, "IDASetNonlinearSolver failed with flag %d: %s", flag, s->ida_msg);
    return -1;
  }
  return 0;
}

/* The Newton test's absolute tolerances, one per row (n): a row with atol > 0 is weighed 1/(rtol |y| + atol)
 * in Newton's convergence test whatever IDA's error test gives it; atol <= 0 keeps IDA's weight. NULL: IDA's
 * weights everywhere (what dc_reset restores). 0 done, -1 on failure (dc_message). */
DC_API int dc_set_newton_atol(void* sp, const double* atol) {
  dc_session* s = (dc_session*)sp;
  if (!atol) {
    s->nls_on = 0;
    return 0;
  }
  if (nls_install(s) != 0) return -1;
  memcpy(s->nls_atol, atol, sizeof(double) * (size_t)s->n);
  s->nls_on = 1;
  return 0;
}

#endif
