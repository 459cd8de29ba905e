/*
 * ida_driver.c -- daeclear's compiled integrator loop.
 *
 * Compiled together with a CasADi-generated model (see daeclear/engine/codegen.py) into one shared
 * library that links the SUNDIALS libraries of the scikit-sundae wheel. Python drives it with
 * ctypes a few calls per integration segment; every residual, Jacobian and root evaluation,
 * every IDA step, the recording of steps and the dense output at requested times happen here,
 * with no Python in the loop.
 *
 * The residual is the base residual plus the active switchable terms (contact forces); an
 * inactive term is never evaluated. The Jacobian is the base Jacobian plus the active terms'
 * Jacobians: the generated functions return their nonzeros (CasADi's compressed column
 * storage), scattered here either into SUNDIALS' dense column-major matrix (dense LU) or into a
 * SUNSparseMatrix whose fixed pattern is the union of all those patterns (SuperLU_MT), chosen
 * per session by dc_open. The union is fixed so that switching contact terms on and off never
 * changes the structure the sparse LU was ordered for (inactive terms leave explicit zeros).
 *
 * Every generated function takes the model's run-time parameters P (masses, joint points,
 * clearances, law constants, ...) as its last input: one compiled library serves every
 * scene of the same structure; the numbers arrive with dc_open.
 *
 * The driver is one translation unit in parts, each a header of static functions included once,
 * in this order (so the compiler sees one file, as before the split, and the build compiles one):
 *   ida_session.h     SUNDIALS headers, build checks, the session struct, small helpers
 *   ida_automaton.h   the contact-mode automaton of one pair (the mirror of the Python one)
 *   ida_eval.h        the generated functions with the active terms; IDA's callbacks
 *   ida_open.h        dc_open, dc_reset, dc_free, the solver options, dc_reinit
 *   ida_consistent.h  projection onto the constraints and consistent states (dc_set_layout)
 *   ida_events.h      contact events decided in C (dc_set_auto, dc_take_events)
 *   ida_report.h      dc_eval_extra and dc_report
 *   ida_advance.h     dc_advance, the loop, a helper per stage of a step
 * and this file: the build information, model queries and evaluation entry points. The
 * constants Python shares with it are in dc_abi.h, generated from daeclear/engine/abi.py; the
 * helpers ode_driver.c shares are in dc_common.h.
 */
#include "ida_session.h"
#include "ida_automaton.h"
#include "ida_eval.h"
#include "ida_newton.h"
#include "ida_open.h"
#include "ida_consistent.h"
#include "ida_events.h"
#include "ida_report.h"
#include "ida_advance.h"

/* ---------------------------------------------------------------- API ---- */

DC_API int dc_abi_version(void) { return DC_ABI_VERSION; }

/* What this library was compiled for, as text in the file itself: Python reads it from the file
 * BEFORE loading the library (daeclear.engine.sundials.read_build_tag), so a library built for other SUNDIALS
 * headers or another index width is never even loaded. dc_build_info says the same once loaded. */
#define DC_STR_(x) #x
#define DC_STR(x) DC_STR_(x)
DC_API const char dc_build_tag[] = "daeclear-build:abi=" DC_STR(DC_ABI_VERSION)
                                   ";sundials=" DC_STR(DC_SUNDIALS_MAJOR) "." DC_STR(DC_SUNDIALS_MINOR)
                                   "." DC_STR(DC_SUNDIALS_PATCH)
                                   ";index=" DC_STR(DC_INDEX_SIZE)
                                   ";sparse=" DC_STR(DC_HAVE_SPARSE) ";";

/* SUNDIALSGetVersion of the SUNDIALS library this library actually loaded. */
DC_API int dc_sundials_version(char* buf, int len) { return SUNDIALSGetVersion(buf, len); }

/* What this library was compiled for, checked by Python before any session is opened: a
 * library built for other SUNDIALS headers or another index width must never run. out gets
 * SUNDIALS major, minor, patch, DC_INDEX_SIZE, the bits of sunindextype as compiled, and
 * DC_HAVE_SPARSE; returns how many values were written. */
DC_API int dc_build_info(int* out, int len) {
  const int info[DC_BI_N] = {[DC_BI_MAJOR] = DC_SUNDIALS_MAJOR, [DC_BI_MINOR] = DC_SUNDIALS_MINOR,
                             [DC_BI_PATCH] = DC_SUNDIALS_PATCH, [DC_BI_INDEX_SIZE] = DC_INDEX_SIZE,
                             [DC_BI_INDEX_BITS] = (int)(8 * sizeof(sunindextype)),
                             [DC_BI_SPARSE] = DC_HAVE_SPARSE};
  int k = len < DC_BI_N ? len : DC_BI_N;
  for (int i = 0; i < k; ++i) out[i] = info[i];
  return k;
}

DC_API int dc_n_parameters(void) { return dc_model.n_parameters; }

DC_API int dc_model_info(int* n, int* n_terms, int* n_roots, int* n_params) {
  *n = dc_model.n;
  *n_terms = dc_model.n_terms;
  *n_roots = dc_model.n_roots;
  if (n_params)
    for (int k = 0; k < dc_model.n_terms; ++k) n_params[k] = dc_model.n_params[k];
  return 0;
}

DC_API const char* dc_model_name(void) { return dc_model.name; }

DC_API int dc_n_extra(void) { return dc_n_extras; }


DC_API void dc_flag_name(long flag, char* buf, int len) { flag_name(flag, buf, len); }

DC_API const char* dc_message(void* sp) { return sp ? ((dc_session*)sp)->msg : ""; }


/* Cumulative statistics: earlier segments plus the current one. */
DC_API void dc_stats(void* sp, long long* out) {
  dc_session* s = (dc_session*)sp;
  long long cur[DC_ST_N];
  ida_counters(s, cur);
  if (!s->ready)
    for (int i = 0; i < DC_ST_N; ++i) cur[i] = 0;
  for (int i = 0; i < DC_ST_N; ++i) out[i] = s->base[i] + (i == DC_ST_REINITS ? 0 : cur[i]);
  out[DC_ST_LU_FALLBACKS] = s->lin ? s->lin->n_fallback : 0;
}

/* The model's sparse LU plan: out[0] 1 if it has one, out[1] the union's nonzeros, out[2] those of
 * L + U (0 without a plan); returns how many values were written. */
DC_API int dc_sparse_plan(long long* out, int len) {
  const dc_lu_plan* p = dc_model.lu;
  const long long info[3] = {p != NULL, p ? p->nnz : 0, p ? p->fnnz : 0};
  int k = len < 3 ? len : 3;
  for (int i = 0; i < k; ++i) out[i] = info[i];
  return k;
}

/* Model evaluation with the current active terms and parameters (tests, consistency). */
DC_API int dc_eval_residual(void* sp, double t, const double* y, const double* yp, double* r) {
  return eval_res((dc_session*)sp, t, y, yp, r);
}

DC_API int dc_eval_jacobian(void* sp, double t, const double* y, const double* yp, double cj,
                            double* J) {
  return eval_jac((dc_session*)sp, t, y, yp, cj, J, 0, 0);
}

/* The same Jacobian as the nonzeros of the session's union pattern (dc_jac_pattern): what the
 * sparse solver's callback fills. */
DC_API int dc_eval_jacobian_sparse(void* sp, double t, const double* y, const double* yp,
                                   double cj, double* data) {
  return eval_jac((dc_session*)sp, t, y, yp, cj, data, 1, 0);
}

/* Solve J X = B (nrhs right-hand sides, column k at B + k n, overwritten by the solutions) with a new
 * solver of the given kind (DC_LS_DENSE, DC_LS_REDUCED with nk position rows eliminated, DC_LS_SPARSE
 * on the model's plan), J the iteration matrix at (t, y, yp, cj) of the active terms, or the given
 * column-major n x n matrix A (not NULL; sparse: zero outside the union pattern). The solvers IDA
 * uses, on their own copies: a check against a plain LU. info[0]: the sparse LU's dense fallbacks.
 * 0 ok, 1 singular, -1 evaluation failed, no memory or a kind without this check, -2 A has a nonzero
 * outside the union pattern, -3 the model has no sparse plan. */
DC_API int dc_solve_linear(void* sp, int kind, int nk, double t, const double* y, const double* yp, double cj,
                           const double* A, double* B, int nrhs, long long* info) {
  dc_session* s = (dc_session*)sp;
  const int n = s->nj;
  const int dense = kind != DC_LS_SPARSE;
  const size_t len = dense ? (size_t)n * (size_t)n : (size_t)(s->jp_nnz ? s->jp_nnz : 1);
  dc_linsol* ls = NULL;
  int rc = -1;
  if (info) info[0] = 0;
  if (kind == DC_LS_SPARSE && !dc_model.lu) return -3;
  if (kind == DC_LS_DENSE) ls = dcls_dense_create(kind, n);
  else if (kind == DC_LS_REDUCED) ls = rls_create(kind, n);
  else if (kind == DC_LS_SPARSE) ls = dcls_sparse_create(kind, dc_model.lu);
  double* values = ls ? (double*)calloc(len, sizeof(double)) : NULL;
  if (ls && values && (kind != DC_LS_REDUCED || rls_set_kinematic_rows(ls, nk) == 0)) {
    if (!A) {
      rc = eval_jac(s, t, y, yp, cj, values, !dense, 0) == 0 ? 0 : -1;
    } else if (dense) {
      memcpy(values, A, sizeof(double) * len);
      rc = 0;
    } else { /* A onto the union pattern, every nonzero of A on it */
      dc_int count = 0;
      rc = 0;
      for (int c = 0; c < n; ++c)
        for (sunindextype k = s->jp_colptr[c]; k < s->jp_colptr[c + 1]; ++k)
          values[k] = A[(size_t)c * (size_t)n + (size_t)s->jp_rowind[k]];
      for (size_t i = 0; i < (size_t)n * (size_t)n; ++i) count += A[i] != 0.0;
      for (dc_int k = 0; k < s->jp_nnz; ++k) count -= values[k] != 0.0;
      if (count != 0) rc = -2;
    }
    if (rc == 0) rc = ls->factor(ls, values);
    if (rc == 0) ls->solve_many(ls, B, nrhs, n);
    if (rc < 0 && rc != -2) rc = -1;
    if (info) info[0] = ls->n_fallback;
  }
  free(values);
  dcls_free(ls);
  return rc;
}

/* Nonzeros of the union pattern. */
DC_API long long dc_jac_nnz(void* sp) { return (long long)((dc_session*)sp)->jp_nnz; }

/* The step IDA tried first after the latest (re)start (first_step() or IDA's estimate). */
DC_API double dc_first_step(void* sp) {
  double h = 0.0;
  return IDAGetActualInitStep(((dc_session*)sp)->ida, &h) < 0 ? 0.0 : h;
}

/* The session's linear solver: DC_LS_DENSE, DC_LS_SPARSE, DC_LS_REDUCED or DC_LS_SUPERLU. */
DC_API int dc_linear_solver(void* sp) { return ((dc_session*)sp)->lin_kind; }

/* The union pattern as 64-bit CSC arrays: colptr[n + 1], rowind[dc_jac_nnz]. */
DC_API void dc_jac_pattern(void* sp, long long* colptr, long long* rowind) {
  dc_session* s = (dc_session*)sp;
  for (int c = 0; c <= s->nj; ++c) colptr[c] = (long long)s->jp_colptr[c];
  for (dc_int k = 0; k < s->jp_nnz; ++k) rowind[k] = (long long)s->jp_rowind[k];
}

DC_API int dc_eval_roots(void* sp, double t, const double* y, const double* yp, double* g) {
  dc_session* s = (dc_session*)sp;
  if (s->n_roots == 0) return 0;
  return eval_roots(s, t, y, yp, g);
}

/* Set active terms and parameters without restarting IDA (for residual/jacobian checks). */
DC_API void dc_set_terms(void* sp, const int* active, const double* params) {
  dc_session* s = (dc_session*)sp;
  int np = 0;
  for (int k = 0; k < s->n_terms; ++k) {
    s->active[k] = active ? (active[k] != 0) : 0;
    np += dc_model.n_params[k];
  }
  if (np > 0 && params) memcpy(s->params, params, sizeof(double) * (size_t)np);
}
