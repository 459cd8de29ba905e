/*
 * dc_linsol.h -- the one interface of the IDA loop's linear solvers: factor the iteration matrix
 * J = dF/dy + cj dF/dy' once, then solve with that factorisation as often as needed.
 *
 *   ls->factor(ls, values)           factor J, whose values are in the session's storage: the dense
 *                                    column-major n x n matrix (dense, reduced: it may be overwritten
 *                                    by the factors) or the nonzeros of the union pattern (sparse,
 *                                    superlu: left as they are). 0 done; > 0 J is singular (IDA then
 *                                    retries with a smaller step); < 0 failure.
 *   ls->solve(ls, x)                 x <- J^-1 x in place, with the current factorisation.
 *   ls->solve_many(ls, X, nrhs, ld)  the same for nrhs right-hand sides, column k at X + k ld.
 *   ls->cj                           the cj of the matrix last factored (set by the Jacobian callback).
 *
 * IDA reaches a dc_linsol through the SUNLinearSolver of dcls_sun_create (its setup is factor, its
 * solve is solve); a system whose Newton matrix has J on its diagonal blocks (the forward
 * sensitivities: block lower-triangular, J on every diagonal block) solves each block with the same
 * factorisation by calling solve or solve_many directly. IDA scales a solution by 2 / (1 + cj / ls->cj)
 * when its current cj differs from the factorisation's; a caller of solve does the same.
 *
 * The solvers (DC_LS_* of dc_abi.h): dense (SUNDIALS' dense LU with partial pivoting, here), reduced
 * (dc_reduced_ls.h), sparse (dc_sparse_lu.h: the plan made at code generation), superlu (SUNDIALS'
 * SuperLU_MT, here).
 */
#ifndef DAECLEAR_DC_LINSOL_H
#define DAECLEAR_DC_LINSOL_H

#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_dense.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

typedef struct dc_linsol dc_linsol;
struct dc_linsol {
  int kind;              /* DC_LS_* */
  int n;
  double cj;             /* the cj of the matrix last factored */
  long long n_fallback;  /* factorisations the sparse LU handed to dense LU (its pivot test failed) */
  void* content;
  int (*factor)(dc_linsol* ls, double* values);
  void (*solve)(dc_linsol* ls, double* x);
  void (*solve_many)(dc_linsol* ls, double* X, int nrhs, int ld);
  void (*destroy)(dc_linsol* ls);
};

/* solve_many of the solvers without a blocked one: one right-hand side after the other. */
static void dcls_solve_each(dc_linsol* ls, double* X, int nrhs, int ld) {
  for (int k = 0; k < nrhs; ++k) ls->solve(ls, X + (size_t)k * (size_t)ld);
}

/* A dc_linsol with its operations, content owned (freed by destroy); NULL when out of memory. */
static dc_linsol* dcls_new(int kind, int n, void* content, int (*factor)(dc_linsol*, double*),
                           void (*solve)(dc_linsol*, double*), void (*destroy)(dc_linsol*)) {
  dc_linsol* ls = (dc_linsol*)calloc(1, sizeof(dc_linsol));
  if (!ls) return NULL;
  ls->kind = kind;
  ls->n = n;
  ls->content = content;
  ls->factor = factor;
  ls->solve = solve;
  ls->solve_many = dcls_solve_each;
  ls->destroy = destroy;
  return ls;
}

static void dcls_free(dc_linsol* ls) {
  if (ls) ls->destroy(ls);
}

/* ------------------------------------------------------------------ dense LU (SUNDIALS') */
typedef struct {
  double** cols;       /* [n] columns of the matrix factored in place */
  sunindextype* piv;   /* [n] */
} dcls_dense;

static int dcls_dense_factor(dc_linsol* ls, double* values) {
  dcls_dense* c = (dcls_dense*)ls->content;
  for (int j = 0; j < ls->n; ++j) c->cols[j] = values + (size_t)j * (size_t)ls->n;
  return SUNDlsMat_denseGETRF(c->cols, ls->n, ls->n, c->piv) > 0 ? 1 : 0;
}

static void dcls_dense_solve(dc_linsol* ls, double* x) {
  dcls_dense* c = (dcls_dense*)ls->content;
  SUNDlsMat_denseGETRS(c->cols, ls->n, c->piv, x);
}

static void dcls_dense_destroy(dc_linsol* ls) {
  dcls_dense* c = (dcls_dense*)ls->content;
  if (c) {
    free(c->cols);
    free(c->piv);
    free(c);
  }
  free(ls);
}

/* SUNDIALS' dense LU with partial pivoting (SUNLinSol_Dense's algorithm), on the matrix in place. */
static dc_linsol* dcls_dense_create(int kind, int n) {
  dcls_dense* c = (dcls_dense*)calloc(1, sizeof(dcls_dense));
  dc_linsol* ls = c ? dcls_new(kind, n, c, dcls_dense_factor, dcls_dense_solve, dcls_dense_destroy) : NULL;
  if (c) {
    c->cols = (double**)calloc((size_t)n, sizeof(double*));
    c->piv = (sunindextype*)calloc((size_t)n, sizeof(sunindextype));
  }
  if (!ls || !c->cols || !c->piv) {
    if (ls) dcls_free(ls);
    else free(c);
    return NULL;
  }
  return ls;
}

/* ------------------------------------------------------------------ IDA's SUNLinearSolver */
typedef struct {
  dc_linsol* ls;  /* not owned */
  int blocks;     /* the Newton matrix: blocks diagonal copies of ls's matrix (n = blocks ls->n) */
  /* a block lower-triangular Newton matrix: x[ls->n:] -= C x[:ls->n] after the first block's solve (NULL:
   * block diagonal) */
  void (*couple)(void* ctx, double* x);
  void* couple_ctx;
  double* values; /* the matrix storage IDA's Jacobian callback fills (stable for the session) */
  sunindextype last_flag;
} dcls_sun;

#define DCLS_SUN(S) ((dcls_sun*)(S)->content)

static SUNLinearSolver_Type dcls_sun_gettype(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_DIRECT;
}

static SUNLinearSolver_ID dcls_sun_getid(SUNLinearSolver S) {
  (void)S;
  return SUNLINEARSOLVER_CUSTOM;
}

/* IDA initializes its solver at every (re)start: the factorisation's storage and plan are the
 * session's, so there is nothing to redo. */
static SUNErrCode dcls_sun_initialize(SUNLinearSolver S) {
  DCLS_SUN(S)->last_flag = 0;
  return SUN_SUCCESS;
}

static int dcls_sun_setup(SUNLinearSolver S, SUNMatrix A) {
  dcls_sun* c = DCLS_SUN(S);
  (void)A; /* its storage is c->values */
  const int rc = c->ls->factor(c->ls, c->values);
  c->last_flag = rc;
  return rc > 0 ? SUNLS_LUFACT_FAIL : rc < 0 ? SUN_ERR_EXT_FAIL : SUN_SUCCESS;
}

static int dcls_sun_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, sunrealtype tol) {
  dcls_sun* c = DCLS_SUN(S);
  double* xx = N_VGetArrayPointer(x);
  (void)A;
  (void)tol;
  if (x != b) memcpy(xx, N_VGetArrayPointer(b), sizeof(double) * (size_t)c->blocks * (size_t)c->ls->n);
  if (c->blocks == 1) {
    c->ls->solve(c->ls, xx);
  } else if (!c->couple) {
    c->ls->solve_many(c->ls, xx, c->blocks, c->ls->n);
  } else { /* block forward substitution: x0 = J^-1 b0, then x_i = J^-1 (b_i - C_i x0) */
    c->ls->solve(c->ls, xx);
    c->couple(c->couple_ctx, xx);
    c->ls->solve_many(c->ls, xx + c->ls->n, c->blocks - 1, c->ls->n);
  }
  c->last_flag = 0;
  return SUN_SUCCESS;
}

static sunindextype dcls_sun_lastflag(SUNLinearSolver S) { return DCLS_SUN(S)->last_flag; }

static SUNErrCode dcls_sun_free(SUNLinearSolver S) {
  if (!S) return SUN_SUCCESS;
  free(S->content);
  S->content = NULL;
  SUNLinSolFreeEmpty(S);
  return SUN_SUCCESS;
}

/* The SUNLinearSolver IDA calls: setup factors ls on values, solve solves with it, each of the
 * Newton matrix's blocks diagonal blocks (the stacked forward sensitivities, IDAS' simultaneous
 * corrector: one factorisation of the n x n iteration matrix for all 1 + Ns blocks). */
static SUNLinearSolver dcls_sun_create(dc_linsol* ls, double* values, int blocks, SUNContext ctx) {
  SUNLinearSolver S = SUNLinSolNewEmpty(ctx);
  if (!S) return NULL;
  dcls_sun* c = (dcls_sun*)calloc(1, sizeof(dcls_sun));
  if (!c) {
    SUNLinSolFreeEmpty(S);
    return NULL;
  }
  c->ls = ls;
  c->blocks = blocks;
  c->values = values;
  S->content = c;
  S->ops->gettype = dcls_sun_gettype;
  S->ops->getid = dcls_sun_getid;
  S->ops->initialize = dcls_sun_initialize;
  S->ops->setup = dcls_sun_setup;
  S->ops->solve = dcls_sun_solve;
  S->ops->lastflag = dcls_sun_lastflag;
  S->ops->free = dcls_sun_free;
  return S;
}

/* Make the solver of dcls_sun_create block lower triangular: couple(ctx, x) subtracts the blocks below the
 * first block column times x's first block from the rest of x. */
static void dcls_sun_set_coupling(SUNLinearSolver S, void (*couple)(void*, double*), void* ctx) {
  DCLS_SUN(S)->couple = couple;
  DCLS_SUN(S)->couple_ctx = ctx;
}

#undef DCLS_SUN

/* ------------------------------------------------------------------ the union-pattern matrix */
/* IDA's matrix for the sparse LU: the nonzeros of the union pattern, nothing else (the pattern is the
 * plan's). IDA zeroes it before each Jacobian: nnz values, never n x n. */
typedef struct {
  double* data;
  size_t nnz;
} dcls_values;

static SUNMatrix_ID dcls_values_getid(SUNMatrix A) {
  (void)A;
  return SUNMATRIX_CUSTOM;
}

static SUNErrCode dcls_values_zero(SUNMatrix A) {
  dcls_values* c = (dcls_values*)A->content;
  memset(c->data, 0, sizeof(double) * c->nnz);
  return SUN_SUCCESS;
}

static void dcls_values_destroy(SUNMatrix A) {
  if (!A) return;
  dcls_values* c = (dcls_values*)A->content;
  if (c) {
    free(c->data);
    free(c);
  }
  A->content = NULL;
  SUNMatFreeEmpty(A);
}

static SUNMatrix dcls_values_create(size_t nnz, SUNContext ctx) {
  SUNMatrix A = SUNMatNewEmpty(ctx);
  if (!A) return NULL;
  dcls_values* c = (dcls_values*)calloc(1, sizeof(dcls_values));
  if (c) c->data = (double*)calloc(nnz ? nnz : 1, sizeof(double));
  if (!c || !c->data) {
    free(c);
    SUNMatFreeEmpty(A);
    return NULL;
  }
  c->nnz = nnz;
  A->content = c;
  A->ops->getid = dcls_values_getid;
  A->ops->zero = dcls_values_zero;
  A->ops->destroy = dcls_values_destroy;
  return A;
}

static double* dcls_values_data(SUNMatrix A) { return ((dcls_values*)A->content)->data; }

#endif
