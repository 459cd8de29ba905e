/*
 * ida_consistent.h -- projection and consistent states: a state put back on the constraint manifold, its
 * multipliers and derivatives made consistent with the terms that are on (dc_set_layout).
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_CONSISTENT_H
#define DAECLEAR_IDA_CONSISTENT_H

#include "ida_eval.h"

/* x = (J J^T)^-1 b for the m x nq matrix J (column-major), by Cholesky of G = J J^T (row-major,
 * lower); nonzero when G is singular (dependent constraints). */
static int solve_normal(const double* J, const double* b, double* G, double* x, int nq, int m) {
  for (int i = 0; i < m; ++i)
    for (int k = 0; k <= i; ++k) {
      double acc = 0.0;
      for (int j = 0; j < nq; ++j) acc += J[i + (size_t)j * m] * J[k + (size_t)j * m];
      G[i * m + k] = acc;
    }
  if (cholesky(G, x, m) != 0) return -1; /* x: scratch for the original diagonal */
  memcpy(x, b, sizeof(double) * (size_t)m);
  chol_solve(G, m, x);
  return 0;
}

/* Put q and v of y back on the constraint manifold: least-norm Newton on Phi(q, t) = 0, then the
 * least-norm correction of v to Phi_q v + Phi_t = 0 (what DAEModel.assemble_positions and
 * assemble_velocities do in Python). Removes the drift accumulated since the last restart. */
static int project_state(dc_session* s, double t, double* y) {
  const int nq = s->lay_nq, m = s->lay_m;
  double* q = y;
  double* v = y + nq;
  double* K = s->lay_buf + 3 * nq + m + 1;
  double* Jq = K + m;
  double* G = K + 2 * m + (size_t)m * nq;
  double* x = G + (size_t)m * m;
  double tt = t, scale = 1.0;
  const double* in[4] = {q, v, &tt, s->P};
  for (int j = 0; j < nq; ++j) scale = fmax(scale, fabs(q[j]));
  for (int it = 0;; ++it) {
    if (eval_extra1(s, s->lay_kin, 4, in, K) != 0) return -1;
    double worst = 0.0;
    for (int i = 0; i < m; ++i) worst = fmax(worst, fabs(K[i]));
    if (worst < s->proj_tol * scale) break;
    if (it >= s->proj_iter || solve_normal(Jq, K, G, x, nq, m) != 0) return -2;
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < m; ++i) q[j] -= Jq[i + (size_t)j * m] * x[i];
  }
  if (solve_normal(Jq, K + m + (size_t)m * nq, G, x, nq, m) != 0) return -2; /* Phi_dot at the new q */
  for (int j = 0; j < nq; ++j)
    for (int i = 0; i < m; ++i) v[j] -= Jq[i + (size_t)j * m] * x[i];
  return 0;
}

/* project_state for a restart, unless the projection moves a root function that did not fire
 * across zero: a second corner a hair from its wall (a flat slider landing) would then start its
 * segment already past the root it watches, and its contact would never be found. The restart
 * then keeps the unprojected state (off the manifold by GGL's Newton tolerance only). 0 on
 * success, -1/-2 from project_state, -3 when the root functions cannot be evaluated. */
static int project_kept_roots(dc_session* s, double t, double* y, const double* yp) {
  const int n = s->n, nr = s->n_roots;
  double* buf = (double*)xcalloc((size_t)(n + 2 * nr), sizeof(double));
  if (!buf) return -3;
  double *saved = buf, *g0 = buf + n, *g1 = buf + n + nr;
  int rc = 0;
  memcpy(saved, y, sizeof(double) * (size_t)n);
  if (nr > 0 && eval_roots(s, t, y, yp, g0) != 0) rc = -3;
  if (rc == 0) rc = project_state(s, t, y);
  if (rc == 0 && nr > 0) {
    if (eval_roots(s, t, y, yp, g1) != 0) {
      rc = -3;
    } else {
      for (int i = 0; i < nr; ++i)
        if (!s->rootsfound[i] && g0[i] != 0.0 && (g0[i] > 0.0) != (g1[i] > 0.0)) {
          memcpy(y, saved, sizeof(double) * (size_t)n);
          break;
        }
    }
  }
  free(buf);
  return rc;
}

/* Fill the multipliers lambda of y and all of yp so that the residual vanishes at (t, y): the
 * generated Schur-complement solve (accel extra) with the contact forces of the terms that are on
 * (on[k], parameters at par + param_off[k]); GGL: q' = v - Phi_q^T mu. The same as
 * DAEModel.consistent_state in Python. */
static int make_consistent(dc_session* s, double t, double* y, double* yp, const int* on, const double* par) {
  const int n = s->n, nq = s->lay_nq, m = s->lay_m;
  double* Qc = s->lay_buf;
  double* sol = Qc + 2 * nq;
  double* K = sol + nq + m + 1;
  const double* q = y;
  const double* v = y + nq;
  double tt = t;
  memset(Qc, 0, sizeof(double) * (size_t)nq);
  for (int k = 0; k < s->n_terms; ++k) {
    if (!on[k]) continue;
    const double* in_f[5] = {&tt, q, v, par + s->param_off[k], s->P};
    if (add_extra1(s, s->lay_force0 + k, 5, in_f, Qc) != 0) return -1; /* its nonzeros: two bodies' */
  }
  const double* in_a[5] = {&tt, q, v, Qc, s->P};
  if (eval_extra1(s, s->lay_accel, 5, in_a, sol) != 0) return -1;
  memcpy(y + 2 * nq, sol + nq, sizeof(double) * (size_t)m);
  memcpy(yp, v, sizeof(double) * (size_t)nq);
  if (s->lay_ggl && m > 0) {
    const double* mu = y + 2 * nq + m;
    const double* in_k[4] = {q, v, &tt, s->P};
    if (eval_extra1(s, s->lay_kin, 4, in_k, K) != 0) return -1;
    for (int j = 0; j < nq; ++j)
      for (int i = 0; i < m; ++i) yp[j] -= K[m + i + (size_t)j * m] * mu[i];
  }
  memcpy(yp + nq, sol, sizeof(double) * (size_t)nq);
  memset(yp + 2 * nq, 0, sizeof(double) * (size_t)(n - 2 * nq));
  if (s->lay_track) yp[n - 1] = sol[nq + m];
  return 0;
}

/* The model's state layout and extras (daeclear/assembly/dae_model.py: EXTRA_ACCEL, EXTRA_TERM0 + k,
 * EXTRA_KINEMATICS, EXTRA_OUTPUTS), for consistent states made in C: restarts after the
 * switches the loop decides (project: GGL restarts on the constraint manifold, Newton to
 * tol * max(1, |q|) in at most max_iter steps) and dc_report. */
DC_API int dc_set_layout(void* sp, int nq, int m, int ggl, int track_work, int accel_extra, int force_extra0,
                         int kin_extra, int outputs_extra, int project, double tol, int max_iter) {
  dc_session* s = (dc_session*)sp;
  const int last = force_extra0 + s->n_terms - 1;
  if (nq < 1 || m < 0 || 2 * nq + (ggl ? 2 : 1) * m + (track_work ? 1 : 0) != s->n || !(tol > 0.0) ||
      max_iter < 1 || accel_extra < 0 || accel_extra >= dc_n_extras || kin_extra < 0 ||
      kin_extra >= dc_n_extras || outputs_extra < 0 || outputs_extra >= dc_n_extras || force_extra0 < 0 ||
      last >= dc_n_extras)
    return -1;
  free(s->lay_buf);
  free(s->lay_on);
  int np = 0;
  for (int k = 0; k < s->n_terms; ++k) np += dc_model.n_params[k];
  const dc_int* sp_out = dc_extra_tab[outputs_extra].sparsity_out(0);
  const int nc = (int)(sp_out[0] * sp_out[1]);
  s->lay_buf = (double*)xcalloc((size_t)(3 * nq + m + 1 + 2 * m + m * nq + m * m + m + np + nc), sizeof(double));
  s->lay_on = (int*)xcalloc((size_t)s->n_terms, sizeof(int));
  if (!s->lay_buf || !s->lay_on) return -1;
  s->lay_nq = nq;
  s->lay_m = m;
  s->lay_ggl = ggl;
  s->lay_track = track_work;
  s->lay_accel = accel_extra;
  s->lay_force0 = force_extra0;
  s->lay_kin = kin_extra;
  s->lay_outputs = outputs_extra;
  s->lay_n_switch = s->n_terms + np;
  s->proj_on = project && m > 0;
  s->proj_tol = tol;
  s->proj_iter = max_iter;
  {
    dc_int sa = 5, sr = 1, si = 0, sw = 0, snz = 1;
    for (int k = 0; k < dc_n_extras; ++k) {
      work_max(&dc_extra_tab[k], &sa, &sr, &si, &sw);
      if (nnz_of(&dc_extra_tab[k]) > snz) snz = nnz_of(&dc_extra_tab[k]);
    }
    free(s->xarg);
    free(s->xres);
    free(s->xiw);
    free(s->xw);
    free(s->xnz);
    s->xarg = (const double**)xcalloc((size_t)sa, sizeof(double*));
    s->xres = (double**)xcalloc((size_t)sr, sizeof(double*));
    s->xiw = (dc_int*)xcalloc((size_t)si, sizeof(dc_int));
    s->xw = (double*)xcalloc((size_t)sw, sizeof(double));
    s->xnz = (double*)xcalloc((size_t)snz, sizeof(double));
    if (!s->xarg || !s->xres || !s->xiw || !s->xw || !s->xnz) return -1;
  }
  s->lay_n_channels = nc;
  if (s->lin_kind == DC_LS_REDUCED && rls_set_kinematic_rows(s->lin, nq) != 0) return -1;
  s->lay_ready = 1;
  return 0;
}

#endif
