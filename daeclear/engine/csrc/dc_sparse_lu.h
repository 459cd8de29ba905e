/*
 * dc_sparse_lu.h -- the sparse LU of the Newton matrix on the plan made at code generation
 * (daeclear/engine/sparse_plan.py, the dc_lu_plan of dc_model.h): a fixed pivot order, the factors'
 * pattern known, so every factorisation is numerical only (no ordering, no allocation, no search)
 * and costs what the factors' nonzeros cost.
 *
 * factor: the left-looking column LU of the permuted matrix B = P J P^T: column j (J's column
 * perm[j], its rows renumbered) is scattered into a dense work vector x, the columns k of its U part
 * (ascending: each is final when reached) subtract L(:, k) U(k, j), and the column is gathered into
 * its place among the factors, L's part divided by the pivot.
 *
 * The pivots are the plan's (the diagonal of B). Each must pass two tests, both unchanged by the
 * scaling of J's columns and rows (a mechanism's rows differ by cj and by units), tol being
 * DC_LU_PIVOT_TOL (dc_abi.h):
 *   cancellation  |u_jj| > tol (|b_jj| + sum_k |L(j, k) U(k, j)|): the pivot keeps more than 8 of the
 *                 digits it was formed from (a near-singular J: dependent constraints);
 *   growth        |u_jj| s_j >= tol max_i |x_i| s_i over the column below the pivot, s the reciprocal
 *                 row maxima of J: no multiplier of the row-equilibrated factors above 1 / tol (a
 *                 small static pivot: what partial pivoting exists for).
 * A Jacobian that fails either is factored instead by dense LU with partial pivoting (SUNDIALS'),
 * counted in n_fallback; the next Jacobian tries the plan again.
 *
 * solve: x <- P^T U^-1 L^-1 P x, the two substitutions column by column over the factors' nonzeros
 * (U's diagonal as reciprocals: products, not divisions). solve_many: the same for several
 * right-hand sides in one pass over the factors (each factor entry read once for all of them, the
 * right-hand sides interleaved row by row), every one's arithmetic that of solve.
 */
#ifndef DAECLEAR_DC_SPARSE_LU_H
#define DAECLEAR_DC_SPARSE_LU_H

#include <math.h>
#include "dc_linsol.h"
#include "dc_model.h"

typedef struct {
  const dc_lu_plan* p;
  double* f;            /* [fnnz] L (multipliers, below the diagonal) and U (on and above) */
  double* rdiag;        /* [n] 1 / U's diagonal */
  double* x;            /* [n] the column being factored; zero between columns */
  double* y;            /* [n] the permuted right-hand side */
  int* prow;            /* [nnz] the pivot-order row of each union nonzero */
  double* rs;           /* [n] reciprocal row maxima of J, in pivot order */
  double* ym;           /* [n * ym_cols] solve_many's right-hand sides, row by row */
  int ym_cols;
  int dense;            /* the current factorisation is the dense fallback's */
  double* dA;           /* the fallback's n x n matrix, its columns and pivots (allocated at first use) */
  double** dcols;
  sunindextype* dpiv;
} dcls_sparse;

/* The fallback: J from the union values into a dense matrix, LU with partial pivoting. */
static int dcls_sparse_dense(dc_linsol* ls, dcls_sparse* c, const double* values) {
  const dc_lu_plan* p = c->p;
  const int n = p->n;
  if (!c->dA) {
    c->dA = (double*)calloc((size_t)n * (size_t)n, sizeof(double));
    c->dcols = (double**)calloc((size_t)n, sizeof(double*));
    c->dpiv = (sunindextype*)calloc((size_t)n, sizeof(sunindextype));
    if (!c->dA || !c->dcols || !c->dpiv) return -1;
  }
  memset(c->dA, 0, sizeof(double) * (size_t)n * (size_t)n);
  for (int col = 0; col < n; ++col) {
    double* a = c->dA + (size_t)col * (size_t)n;
    c->dcols[col] = a;
    for (int e = p->colptr[col]; e < p->colptr[col + 1]; ++e) a[p->rowind[e]] = values[e];
  }
  ++ls->n_fallback;
  c->dense = 1;
  return SUNDlsMat_denseGETRF(c->dcols, n, n, c->dpiv) > 0 ? 1 : 0;
}

static int dcls_sparse_factor(dc_linsol* ls, double* values) {
  dcls_sparse* c = (dcls_sparse*)ls->content;
  const dc_lu_plan* p = c->p;
  const int n = p->n;
  const int *fcol = p->fcolptr, *frow = p->frow, *fdiag = p->fdiag, *colptr = p->colptr, *prow = c->prow;
  double *f = c->f, *x = c->x, *rs = c->rs;
  c->dense = 0;
  memset(rs, 0, sizeof(double) * (size_t)n);
  for (int q = 0; q < p->nnz; ++q) {
    const double a = fabs(values[q]);
    if (a > rs[prow[q]]) rs[prow[q]] = a;
  }
  for (int i = 0; i < n; ++i) rs[i] = rs[i] > 0.0 ? 1.0 / rs[i] : 1.0;
  for (int j = 0; j < n; ++j) {
    const int b = fcol[j], d = fdiag[j], e = fcol[j + 1], col = p->perm[j];
    for (int q = colptr[col]; q < colptr[col + 1]; ++q) x[prow[q]] = values[q]; /* B(:, j); fill stays 0 */
    const double bjj = x[j];
    for (int k = b; k < d; ++k) { /* U(r, j) is final: subtract L(:, r) U(r, j) */
      const int r = frow[k];
      const double xr = x[r];
      if (xr == 0.0) continue;
      for (int l = fdiag[r] + 1; l < fcol[r + 1]; ++l) x[frow[l]] -= f[l] * xr;
    }
    const double piv = x[j];
    double mag = fabs(bjj), below = 0.0;
    for (int q = p->lrowptr[j]; q < p->lrowptr[j + 1]; ++q) mag += fabs(f[p->lrowpos[q]] * x[p->lrowcol[q]]);
    for (int k = b; k <= d; ++k) {
      f[k] = x[frow[k]];
      x[frow[k]] = 0.0;
    }
    const double inv = 1.0 / piv;
    for (int k = d + 1; k < e; ++k) {
      const double xi = x[frow[k]];
      const double scaled = fabs(xi) * rs[frow[k]];
      if (scaled > below) below = scaled;
      f[k] = xi * inv;
      x[frow[k]] = 0.0;
    }
    if (!(fabs(piv) > DC_LU_PIVOT_TOL * mag) || !(fabs(piv) * rs[j] >= DC_LU_PIVOT_TOL * below) || !isfinite(inv))
      return dcls_sparse_dense(ls, c, values); /* x is zero again: every entry set was in this column */
    c->rdiag[j] = inv;
  }
  return 0;
}

static void dcls_sparse_solve(dc_linsol* ls, double* b) {
  dcls_sparse* c = (dcls_sparse*)ls->content;
  const dc_lu_plan* p = c->p;
  const int n = p->n;
  if (c->dense) {
    SUNDlsMat_denseGETRS(c->dcols, n, c->dpiv, b);
    return;
  }
  const int *fcol = p->fcolptr, *frow = p->frow, *fdiag = p->fdiag, *perm = p->perm;
  const double* f = c->f;
  double* y = c->y;
  for (int i = 0; i < n; ++i) y[i] = b[perm[i]];
  for (int j = 0; j < n; ++j) { /* L y = P b, L unit lower, by columns */
    const double yj = y[j];
    if (yj == 0.0) continue;
    for (int l = fdiag[j] + 1; l < fcol[j + 1]; ++l) y[frow[l]] -= f[l] * yj;
  }
  for (int j = n - 1; j >= 0; --j) { /* U x = y, by columns */
    const double yj = (y[j] *= c->rdiag[j]);
    if (yj == 0.0) continue;
    for (int k = fcol[j]; k < fdiag[j]; ++k) y[frow[k]] -= f[k] * yj;
  }
  for (int i = 0; i < n; ++i) b[perm[i]] = y[i];
}

static void dcls_sparse_solve_many(dc_linsol* ls, double* X, int nrhs, int ld) {
  dcls_sparse* c = (dcls_sparse*)ls->content;
  const dc_lu_plan* p = c->p;
  const int n = p->n;
  if (!c->dense && nrhs > c->ym_cols && nrhs > 1) {
    double* grown = (double*)realloc(c->ym, sizeof(double) * (size_t)n * (size_t)nrhs);
    if (grown) {
      c->ym = grown;
      c->ym_cols = nrhs;
    }
  }
  if (c->dense || nrhs < 2 || nrhs > c->ym_cols) { /* the dense fallback's, or no memory: one at a time */
    dcls_solve_each(ls, X, nrhs, ld);
    return;
  }
  const int *fcol = p->fcolptr, *frow = p->frow, *fdiag = p->fdiag, *perm = p->perm;
  const double* f = c->f;
  double* Y = c->ym;
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < nrhs; ++k) Y[(size_t)i * nrhs + k] = X[(size_t)k * ld + perm[i]];
  for (int j = 0; j < n; ++j) { /* L Y = P B */
    const double* yj = Y + (size_t)j * nrhs;
    for (int l = fdiag[j] + 1; l < fcol[j + 1]; ++l) {
      double* yr = Y + (size_t)frow[l] * nrhs;
      for (int k = 0; k < nrhs; ++k) yr[k] -= f[l] * yj[k];
    }
  }
  for (int j = n - 1; j >= 0; --j) { /* U X = Y */
    double* yj = Y + (size_t)j * nrhs;
    for (int k = 0; k < nrhs; ++k) yj[k] *= c->rdiag[j];
    for (int q = fcol[j]; q < fdiag[j]; ++q) {
      double* yr = Y + (size_t)frow[q] * nrhs;
      for (int k = 0; k < nrhs; ++k) yr[k] -= f[q] * yj[k];
    }
  }
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < nrhs; ++k) X[(size_t)k * ld + perm[i]] = Y[(size_t)i * nrhs + k];
}

static void dcls_sparse_destroy(dc_linsol* ls) {
  dcls_sparse* c = (dcls_sparse*)ls->content;
  if (c) {
    free(c->f);
    free(c->rdiag);
    free(c->x);
    free(c->y);
    free(c->prow);
    free(c->rs);
    free(c->ym);
    free(c->dA);
    free(c->dcols);
    free(c->dpiv);
    free(c);
  }
  free(ls);
}

/* The sparse LU of a plan (the model's, see dc_model.h); NULL when out of memory. */
static dc_linsol* dcls_sparse_create(int kind, const dc_lu_plan* plan) {
  const int n = plan->n;
  dcls_sparse* c = (dcls_sparse*)calloc(1, sizeof(dcls_sparse));
  dc_linsol* ls = c ? dcls_new(kind, n, c, dcls_sparse_factor, dcls_sparse_solve, dcls_sparse_destroy) : NULL;
  if (c) {
    c->p = plan;
    c->f = (double*)calloc((size_t)(plan->fnnz ? plan->fnnz : 1), sizeof(double));
    c->rdiag = (double*)calloc((size_t)n, sizeof(double));
    c->x = (double*)calloc((size_t)n, sizeof(double));
    c->y = (double*)calloc((size_t)n, sizeof(double));
    c->prow = (int*)calloc((size_t)(plan->nnz ? plan->nnz : 1), sizeof(int));
    c->rs = (double*)calloc((size_t)n, sizeof(double));
  }
  if (!ls || !c->f || !c->rdiag || !c->x || !c->y || !c->prow || !c->rs) {
    if (ls) dcls_free(ls);
    else free(c);
    return NULL;
  }
  int* pinv = (int*)calloc((size_t)n, sizeof(int));
  if (!pinv) {
    dcls_free(ls);
    return NULL;
  }
  ls->solve_many = dcls_sparse_solve_many;
  for (int k = 0; k < n; ++k) pinv[plan->perm[k]] = k;
  for (int q = 0; q < plan->nnz; ++q) c->prow[q] = pinv[plan->rowind[q]];
  free(pinv);
  return ls;
}

#endif
