/*
 * dc_linalg.h -- the small dense linear algebra both compiled drivers use: Cholesky of the
 * m x m constraint matrices (Phi_q M^-1 Phi_q^T in ode_driver.c, Phi_q Phi_q^T when ida_driver.c
 * projects a state onto the constraint manifold) and the solve with its factor.
 */
#ifndef DAECLEAR_DC_LINALG_H
#define DAECLEAR_DC_LINALG_H

#include <math.h>

/* In-place Cholesky of the lower triangle of the row-major m x m matrix S. A pivot that falls
 * below 1e-13 of its original diagonal (or is not finite) means dependent constraints. */
static int cholesky(double* S, double* d0, int m) {
  for (int j = 0; j < m; ++j) d0[j] = S[j * m + j];
  for (int j = 0; j < m; ++j) {
    double d = S[j * m + j];
    for (int k = 0; k < j; ++k) d -= S[j * m + k] * S[j * m + k];
    if (!(d > 1e-13 * fabs(d0[j]))) return -1 - j;
    d = sqrt(d);
    S[j * m + j] = d;
    for (int i = j + 1; i < m; ++i) {
      double v = S[i * m + j];
      for (int k = 0; k < j; ++k) v -= S[i * m + k] * S[j * m + k];
      S[i * m + j] = v / d;
    }
  }
  return 0;
}

static void chol_solve(const double* L, int m, double* x) {
  for (int i = 0; i < m; ++i) {
    double v = x[i];
    for (int k = 0; k < i; ++k) v -= L[i * m + k] * x[k];
    x[i] = v / L[i * m + i];
  }
  for (int i = m - 1; i >= 0; --i) {
    double v = x[i];
    for (int k = i + 1; k < m; ++k) v -= L[k * m + i] * x[k];
    x[i] = v / L[i * m + i];
  }
}

#endif
