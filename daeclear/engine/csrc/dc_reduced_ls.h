/*
 * dc_reduced_ls.h -- IDA's dense linear solver on the reduced Newton system.
 *
 * The first nk rows of every formulation are the kinematic equations q' - v (+ Phi_q^T mu for
 * GGL) = 0, so the iteration matrix J = dF/dy + cj dF/dy' has, in its q-row block, cj I (+ the
 * q-derivative of Phi_q^T mu, zero with mu on the manifold) beside the columns of v and mu.
 * Ordering y = [q; r] (r: v, multipliers, work):
 *
 *   [ D    J_qr ] [x_q]   [b_q]        x_q = D^-1 (b_q - J_qr x_r)
 *   [ J_rq J_rr ] [x_r] = [b_r]   =>   (J_rr - J_rq D^-1 J_qr) x_r = b_r - J_rq D^-1 b_q
 *
 * with D the diagonal of the q-row block. Only the (n - nk)-square Schur complement is factored
 * (SUNDIALS' dense LU with partial pivoting): on the slider-crank with GGL, 23 unknowns instead
 * of 32. The solve is exact when the q-row block is diagonal: always for index1, and for GGL
 * wherever each body's angle enters Phi_q only through its own rotation (revolute joints,
 * drivers, guides on the ground). Otherwise (a guide on a moving body, mu off the manifold) the
 * dropped off-diagonal part only changes IDA's iteration matrix (a modified Newton method, as
 * IDA's own stale Jacobians are), never the residual it converges to. J itself is left as the
 * Jacobian callback wrote it (the plain dense solver factors it in place): the factorisation copies
 * the J_rq and J_qr blocks the solve needs. A dc_linsol (dc_linsol.h): rls_create.
 */
#ifndef DAECLEAR_DC_REDUCED_LS_H
#define DAECLEAR_DC_REDUCED_LS_H

#include <stdlib.h>
#include <string.h>
#include <sundials/sundials_dense.h>
#include "dc_linsol.h"

typedef struct {
  sunindextype n, nk;  /* system size; leading kinematic rows eliminated (0: a plain dense LU) */
  double** a;          /* [n] the columns of the matrix factored last */
  sunindextype* piv;   /* [n] pivots of the Schur complement's LU */
  double* schur;       /* [(n - nk)^2], column-major */
  double** cols;       /* [n] column pointers into schur */
  double* dinv;        /* [nk] 1 / D */
  double* rdiag;       /* [n] 1 / the diagonal of U: the solve multiplies, never divides */
  int* qr_k;           /* nonzeros of J_qr: row k, column j (within r), value */
  int* qr_j;
  double* qr_v;
  long qr_nnz;
  int* rq_start;       /* [nk + 1] nonzeros of J_rq by column (few: a coordinate enters few */
  int* rq_row;         /* equations): rows within r, values */
  double* rq_v;
} dc_reduced_ls;

#define RLS(ls) ((dc_reduced_ls*)(ls)->content)

/* Factor the Schur complement of J's kinematic block (J column-major in values, left as it is);
 * 1 (singular) lets IDA retry with a smaller step, as the plain dense solver's does. */
static int rls_factor(dc_linsol* ls, double* values) {
  dc_reduced_ls* c = RLS(ls);
  const sunindextype n = c->n, nk = c->nk, nr = n - nk;
  for (sunindextype j = 0; j < n; ++j) c->a[j] = values + (size_t)j * (size_t)n; /* a[j][i] = J(i, j) */
  double* const* a = c->a;
  long nrq = 0;
  for (sunindextype k = 0; k < nk; ++k) {
    if (a[k][k] == 0.0) return 1;
    c->dinv[k] = 1.0 / a[k][k];
    c->rq_start[k] = (int)nrq;
    const double* rq = a[k] + nk; /* column k of J_rq */
    for (sunindextype i = 0; i < nr; ++i)
      if (rq[i] != 0.0) {
        c->rq_row[nrq] = (int)i;
        c->rq_v[nrq++] = rq[i];
      }
  }
  c->rq_start[nk] = (int)nrq;
  c->qr_nnz = 0;
  for (sunindextype j = 0; j < nr; ++j) {
    double* col = c->cols[j];
    memcpy(col, a[nk + j] + nk, sizeof(double) * (size_t)nr);
    for (sunindextype k = 0; k < nk; ++k) {
      const double v = a[nk + j][k];
      if (v == 0.0) continue;
      c->qr_k[c->qr_nnz] = (int)k;
      c->qr_j[c->qr_nnz] = (int)j;
      c->qr_v[c->qr_nnz++] = v;
      const double f = v * c->dinv[k];
      for (int e = c->rq_start[k]; e < c->rq_start[k + 1]; ++e) col[c->rq_row[e]] -= c->rq_v[e] * f;
    }
  }
  if (nr && SUNDlsMat_denseGETRF(c->cols, nr, nr, c->piv) > 0) return 1;
  for (sunindextype k = 0; k < nr; ++k) c->rdiag[k] = 1.0 / c->cols[k][k];
  return 0;
}

/* x[i] -= c0[i] x0 + c1[i] x1 + c2[i] x2 + c3[i] x3 for i in [lo, hi): two rows at a time in
 * GCC's (and Clang's) vector extension, SSE2 on any x86-64; each row's arithmetic is the scalar
 * loop's, in the same order. */
typedef double rls_v2 __attribute__((vector_size(16), aligned(8), may_alias));

static inline void rls_axpy4(double* x, const double* c0, const double* c1, const double* c2, const double* c3,
                             double x0, double x1, double x2, double x3, sunindextype lo, sunindextype hi) {
  const rls_v2 v0 = {x0, x0}, v1 = {x1, x1}, v2 = {x2, x2}, v3 = {x3, x3};
  sunindextype i = lo;
  for (; i + 2 <= hi; i += 2) {
    const rls_v2 s = *(const rls_v2*)(c0 + i) * v0 + *(const rls_v2*)(c1 + i) * v1 + *(const rls_v2*)(c2 + i) * v2 +
                     *(const rls_v2*)(c3 + i) * v3;
    *(rls_v2*)(x + i) -= s;
  }
  if (i < hi) x[i] -= c0[i] * x0 + c1[i] * x1 + c2[i] * x2 + c3[i] * x3;
}

/* x <- (LU)^-1 P x with the factors of SUNDlsMat_denseGETRF: its GETRS, with the divisions by
 * U's diagonal (a chain of dependent divisions) replaced by products with their reciprocals, and
 * both substitutions four columns at a time: a column-by-column substitution waits at every
 * column for the previous one's update of x (a store and a load on the critical path); a block
 * of four waits once, then updates the rows below (above) with four products each, two rows at
 * a time (rls_axpy4). 160 instead of 265 ns at n = 23 (the slider-crank's GGL system), then
 * 10 % less with the vectors. */
static void rls_lu_solve(const dc_reduced_ls* c, sunindextype n, double* x) {
  double* const* a = c->cols;
  const double* r = c->rdiag;
  for (sunindextype k = 0; k < n; ++k) {
    const sunindextype pk = c->piv[k];
    if (pk != k) {
      const double tmp = x[k];
      x[k] = x[pk];
      x[pk] = tmp;
    }
  }
  sunindextype k = 0;
  for (; k + 4 <= n; k += 4) { /* L y = P x, L unit lower: columns k .. k + 3 */
    const double *c0 = a[k], *c1 = a[k + 1], *c2 = a[k + 2], *c3 = a[k + 3];
    const double x0 = x[k];
    const double x1 = x[k + 1] - c0[k + 1] * x0;
    const double x2 = x[k + 2] - c0[k + 2] * x0 - c1[k + 2] * x1;
    const double x3 = x[k + 3] - c0[k + 3] * x0 - c1[k + 3] * x1 - c2[k + 3] * x2;
    x[k + 1] = x1;
    x[k + 2] = x2;
    x[k + 3] = x3;
    rls_axpy4(x, c0, c1, c2, c3, x0, x1, x2, x3, k + 4, n);
  }
  for (; k + 1 < n; ++k) {
    const double* col = a[k];
    const double xk = x[k];
    for (sunindextype i = k + 1; i < n; ++i) x[i] -= col[i] * xk;
  }
  for (k = n - 1; k >= 3; k -= 4) { /* U x = y: columns k .. k - 3 */
    const double *c0 = a[k], *c1 = a[k - 1], *c2 = a[k - 2], *c3 = a[k - 3];
    const double x0 = x[k] * r[k];
    const double x1 = (x[k - 1] - c0[k - 1] * x0) * r[k - 1];
    const double x2 = (x[k - 2] - c0[k - 2] * x0 - c1[k - 2] * x1) * r[k - 2];
    const double x3 = (x[k - 3] - c0[k - 3] * x0 - c1[k - 3] * x1 - c2[k - 3] * x2) * r[k - 3];
    x[k] = x0;
    x[k - 1] = x1;
    x[k - 2] = x2;
    x[k - 3] = x3;
    rls_axpy4(x, c0, c1, c2, c3, x0, x1, x2, x3, 0, k - 3);
  }
  for (; k >= 0; --k) {
    const double* col = a[k];
    const double xk = (x[k] *= r[k]);
    for (sunindextype i = 0; i < k; ++i) x[i] -= col[i] * xk;
  }
}

/* xx <- J^-1 xx with the factorisation of rls_factor (which copied what the solve needs). */
static void rls_solve(dc_linsol* ls, double* xx) {
  dc_reduced_ls* c = RLS(ls);
  const sunindextype nk = c->nk, nr = c->n - nk;
  double* xr = xx + nk;
  for (sunindextype k = 0; k < nk; ++k) { /* b_r - J_rq D^-1 b_q */
    const double f = xx[k] * c->dinv[k];
    if (f == 0.0) continue;
    for (int e = c->rq_start[k]; e < c->rq_start[k + 1]; ++e) xr[c->rq_row[e]] -= c->rq_v[e] * f;
  }
  rls_lu_solve(c, nr, xr);
  for (long e = 0; e < c->qr_nnz; ++e) xx[c->qr_k[e]] -= c->qr_v[e] * xr[c->qr_j[e]];
  for (sunindextype k = 0; k < nk; ++k) xx[k] *= c->dinv[k];
}

static void rls_destroy(dc_linsol* ls) {
  dc_reduced_ls* c = RLS(ls);
  free(ls);
  if (!c) return;
  free(c->a);
  free(c->piv);
  free(c->schur);
  free(c->cols);
  free(c->dinv);
  free(c->rdiag);
  free(c->qr_k);
  free(c->qr_j);
  free(c->qr_v);
  free(c->rq_start);
  free(c->rq_row);
  free(c->rq_v);
  free(c);
}

/* (Re)size the solver for nk eliminated kinematic rows (0 <= nk < n); -1 when out of memory. */
static int rls_set_kinematic_rows(dc_linsol* ls, sunindextype nk) {
  dc_reduced_ls* c = RLS(ls);
  const sunindextype n = c->n, nr = n - nk;
  if (nk < 0 || nk >= n) return -1;
  free(c->schur);
  free(c->dinv);
  free(c->qr_k);
  free(c->qr_j);
  free(c->qr_v);
  free(c->rq_start);
  free(c->rq_row);
  free(c->rq_v);
  c->schur = (double*)calloc((size_t)(nr * nr), sizeof(double));
  c->dinv = (double*)calloc((size_t)(nk ? nk : 1), sizeof(double));
  c->qr_k = (int*)calloc((size_t)(nk * nr ? nk * nr : 1), sizeof(int));
  c->qr_j = (int*)calloc((size_t)(nk * nr ? nk * nr : 1), sizeof(int));
  c->qr_v = (double*)calloc((size_t)(nk * nr ? nk * nr : 1), sizeof(double));
  c->rq_start = (int*)calloc((size_t)(nk + 1), sizeof(int));
  c->rq_row = (int*)calloc((size_t)(nk * nr ? nk * nr : 1), sizeof(int));
  c->rq_v = (double*)calloc((size_t)(nk * nr ? nk * nr : 1), sizeof(double));
  if (!c->schur || !c->dinv || !c->qr_k || !c->qr_j || !c->qr_v || !c->rq_start || !c->rq_row || !c->rq_v) return -1;
  for (sunindextype j = 0; j < nr; ++j) c->cols[j] = c->schur + j * nr;
  c->nk = nk;
  c->qr_nnz = 0;
  return 0;
}

/* A reduced dense solver for n x n systems (kind: its DC_LS_* code), starting with nk = 0 (a plain
 * dense LU) until rls_set_kinematic_rows is told the state layout. NULL when out of memory. */
static dc_linsol* rls_create(int kind, sunindextype n) {
  dc_reduced_ls* c = (dc_reduced_ls*)calloc(1, sizeof(dc_reduced_ls));
  dc_linsol* ls = c ? dcls_new(kind, (int)n, c, rls_factor, rls_solve, rls_destroy) : NULL;
  if (!ls) {
    free(c);
    return NULL;
  }
  c->n = n;
  c->a = (double**)calloc((size_t)n, sizeof(double*));
  c->piv = (sunindextype*)calloc((size_t)n, sizeof(sunindextype));
  c->cols = (double**)calloc((size_t)n, sizeof(double*));
  c->rdiag = (double*)calloc((size_t)n, sizeof(double));
  if (!c->a || !c->piv || !c->cols || !c->rdiag || rls_set_kinematic_rows(ls, 0) != 0) {
    rls_destroy(ls);
    return NULL;
  }
  return ls;
}

#undef RLS
#endif
