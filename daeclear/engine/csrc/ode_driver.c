/*
 * ode_driver.c -- daeclear's compiled right-hand side for the explicit and scipy integrators.
 *
 * Compiled together with CasADi-generated functions and the table of dco_model.h (see
 * daeclear.engine.codegen.build_ode_library) into one shared library, driven through ctypes by
 * daeclear/solvers/ode_evaluators.py. No SUNDIALS here.
 *
 * The index-1 mechanism is an ODE in x = (q, v): q' = v, v' = a with
 *
 *     [M  Phi_q^T] [a  ]   [Q + sum of the active terms' forces        ]
 *     [Phi_q   0 ] [lam] = [c = gamma - 2 alpha Phi' - beta^2 Phi      ]
 *
 * M is diagonal, so the system is solved by the Schur complement S = Phi_q M^-1 Phi_q^T (m x m,
 * symmetric positive definite for independent constraints) with a Cholesky factorisation:
 * lam = S^-1 (Phi_q M^-1 f - c), a = M^-1 (f - Phi_q^T lam). An inactive term is never
 * evaluated. The Jacobian d x'/dx follows by implicit differentiation of the same system:
 * d[a; lam]/dx = -K^-1 d[M a + Phi_q^T lam - f; Phi_q a - c]/dx at fixed (a, lam), with the
 * same factorisation.
 *
 * dco_fixed runs the fixed-step schemes (explicit Euler, classical RK4) step after step,
 * records every step, and returns to Python when a step may contain a gap crossing in a
 * watched direction: a sign change, or an interior maximum above zero predicted by the cubic
 * Hermite interpolant of the gap from its values and rates at the two ends of the step
 * (so a quick contact that opens and closes within one step is not stepped over).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dc_api.h" /* the dco_* entry points, generated from daeclear/engine/c_api.py */
/* every exported function is declared there: one defined without a declaration is an error, one that
 * differs from its declaration too (conflicting types) */
#pragma GCC diagnostic error "-Wmissing-prototypes"
#include "dc_abi.h"
#include "dc_common.h"
#include "dco_model.h"
#include "dc_linalg.h"

#ifndef DCO_ABI_VERSION /* given by daeclear.engine.codegen (daeclear.engine.library.ODE_DRIVER_ABI) */
#error "compile with -DDCO_ABI_VERSION=<daeclear.engine.library.ODE_DRIVER_ABI>"
#endif
/* The return codes (DCO_*, FX_*), the schemes (DCO_EULER, DCO_RK4) and the counters' slots
 * (DCO_CNT_*) are in dc_abi.h, generated from daeclear/engine/abi.py. */

typedef struct {
  int n, m, nx, nt, ng;
  const double** arg;
  double** res;
  dc_int* iw;
  double* w;
  int mem_sys, mem_sysj, mem_gaps, mem_out;
  int refd; /* the generated functions were incref'ed */
  int hermite; /* 1: also look for interior maxima of the gaps within a step (default) */
  int* mem_tf;
  int* mem_tj;
  int* active;
  double* params;
  double* P; /* run-time parameters, appended to every generated function's inputs */
  int* poff;
  double *minv, *Q, *Pq, *c, *f, *Fk, *S, *Sd, *r, *lam, *D, *Jk, *b, *zl;
  double *k1, *k2, *k3, *k4, *xt, *xcur, *g0, *gd0, *g1, *gd1;
  double* nz; /* the nonzeros of a call's sparse outputs, before call() scatters them */
  long long cnt[DCO_CNT_N];
  char msg[MSG_LEN];
} dco_session;

/* Evaluate f into the dense (column-major) outputs out[0..nout). The generated functions keep
 * CasADi's sparsity (a term's force touches two bodies of a chain, its Jacobian their columns:
 * dense outputs made the code grow like N^3 on chains); a sparse output is written to s->nz and
 * scattered, zeros elsewhere. */
static int call(dco_session* s, const dc_fun_t* f, int mem, int nin, const double** in, int nout,
                double** out) {
  dc_int off = 0;
  for (int i = 0; i < nin; ++i) s->arg[i] = in[i];
  s->arg[nin] = s->P;
  for (int i = 0; i < nout; ++i) {
    const dc_int* sp = f->sparsity_out(i);
    s->res[i] = dc_sp_dense(sp) ? out[i] : s->nz + off;
    if (!dc_sp_dense(sp)) off += dc_sp_nnz(sp);
  }
  const int status = f->eval(s->arg, s->res, s->iw, s->w, mem);
  if (status != 0) return status;
  off = 0;
  for (int i = 0; i < nout; ++i) {
    const dc_int* sp = f->sparsity_out(i);
    if (dc_sp_dense(sp)) continue;
    memset(out[i], 0, sizeof(double) * (size_t)(sp[0] * sp[1]));
    dc_sp_scatter(sp, s->nz + off, out[i], sp[0], 0);
    off += dc_sp_nnz(sp);
  }
  return 0;
}

/* ------------------------------------------------------------------ linear algebra ---- */

/* ------------------------------------------------------------------ model ---- */

/* x' = (v, a) at (t, x) with the active terms; lam left in s->lam, the factorised Schur
 * complement in s->S. xdot may be NULL. */
static int accel(dco_session* s, double t, const double* x, double* xdot) {
  const dco_model_t* M = &dco_model;
  const int n = s->n, m = s->m;
  const double* q = x;
  const double* v = x + n;
  {
    const double* in[3] = {&t, q, v};
    double* out[3] = {s->Q, s->Pq, s->c};
    if (call(s, &M->sys, s->mem_sys, 3, in, 3, out)) {
      set_msg(s->msg, "the generated system function returned an error at t=%.17g", t);
      return DCO_EVAL_ERR;
    }
  }
  memcpy(s->f, s->Q, sizeof(double) * n);
  for (int k = 0; k < s->nt; ++k) {
    if (!s->active[k]) continue;
    const double* in[4] = {&t, q, v, s->params + s->poff[k]};
    double* out[1] = {s->Fk};
    if (call(s, &M->term_force[k], s->mem_tf[k], 4, in, 1, out)) {
      set_msg(s->msg, "the generated force of term %d returned an error at t=%.17g", k, t);
      return DCO_EVAL_ERR;
    }
    for (int i = 0; i < n; ++i) s->f[i] += s->Fk[i];
  }
  if (m) {
    const double* P = s->Pq; /* column-major m x n: P[i + k*m] */
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j <= i; ++j) {
        double v2 = 0.0;
        for (int k = 0; k < n; ++k) v2 += P[i + k * m] * P[j + k * m] * s->minv[k];
        s->S[i * m + j] = v2;
      }
      double r = -s->c[i];
      for (int k = 0; k < n; ++k) r += P[i + k * m] * s->minv[k] * s->f[k];
      s->lam[i] = r;
    }
    int rc = cholesky(s->S, s->Sd, m);
    if (rc) {
      set_msg(s->msg, "the constraint Jacobian is singular at t=%.17g (constraint %d depends on the "
              "others, or the state is not finite)", t, -rc - 1);
      return DCO_SINGULAR;
    }
    chol_solve(s->S, m, s->lam);
  }
  if (xdot) {
    const double* P = s->Pq;
    for (int k = 0; k < n; ++k) {
      double fk = s->f[k];
      for (int i = 0; i < m; ++i) fk -= P[i + k * m] * s->lam[i];
      xdot[k] = v[k];
      xdot[n + k] = s->minv[k] * fk;
    }
    int i = dc_first_nonfinite(xdot, s->nx);
    if (i >= 0) {
      set_msg(s->msg, "the right-hand side component %d is %g at t=%.17g (the state has diverged or "
              "is outside the model's domain)", i, xdot[i], t);
      return DCO_NONFINITE;
    }
  }
  return DCO_OK;
}

static int eval_gaps(dco_session* s, double t, const double* x, double* g, double* gd) {
  const double* in[3] = {&t, x, x + s->n};
  double* out[2] = {g, gd};
  s->cnt[DCO_CNT_GAPS]++;
  if (call(s, &dco_model.gaps, s->mem_gaps, 3, in, 2, out)) {
    set_msg(s->msg, "the generated gap function returned an error at t=%.17g", t);
    return DCO_EVAL_ERR;
  }
  int i = dc_first_nonfinite(g, s->ng);
  if (i < 0) i = dc_first_nonfinite(gd, s->ng);
  if (i >= 0) {
    set_msg(s->msg, "gap function %d (or its rate) is not finite at t=%.17g", i, t);
    return DCO_NONFINITE;
  }
  return DCO_OK;
}

/* d x'/dx, row-major nx x nx. */
static int eval_jac(dco_session* s, double t, const double* x, double* J) {
  const dco_model_t* M = &dco_model;
  const int n = s->n, m = s->m, nx = s->nx, nm = n + m;
  int rc = accel(s, t, x, s->xt);
  if (rc) return rc;
  {
    const double* in[5] = {&t, x, x + n, s->xt + n, s->lam};
    double* out[1] = {s->D};
    if (call(s, &M->sys_jac, s->mem_sysj, 5, in, 1, out)) {
      set_msg(s->msg, "the generated system Jacobian returned an error at t=%.17g", t);
      return DCO_EVAL_ERR;
    }
  }
  for (int k = 0; k < s->nt; ++k) {
    if (!s->active[k]) continue;
    const double* in[4] = {&t, x, x + n, s->params + s->poff[k]};
    double* out[1] = {s->Jk};
    if (call(s, &M->term_jac[k], s->mem_tj[k], 4, in, 1, out)) {
      set_msg(s->msg, "the generated Jacobian of term %d returned an error at t=%.17g", k, t);
      return DCO_EVAL_ERR;
    }
    for (int j = 0; j < nx; ++j)
      for (int i = 0; i < n; ++i) s->D[i + j * nm] -= s->Jk[i + j * n];
  }
  memset(J, 0, sizeof(double) * nx * nx);
  for (int i = 0; i < n; ++i) J[i * nx + n + i] = 1.0;
  const double* P = s->Pq;
  for (int j = 0; j < nx; ++j) {
    const double* Dj = s->D + j * nm;
    for (int i = 0; i < m; ++i) {
      double r = Dj[n + i]; /* -b2 */
      for (int k = 0; k < n; ++k) r -= P[i + k * m] * s->minv[k] * Dj[k];
      s->zl[i] = r;
    }
    if (m) chol_solve(s->S, m, s->zl);
    for (int k = 0; k < n; ++k) {
      double v = -Dj[k];
      for (int i = 0; i < m; ++i) v -= P[i + k * m] * s->zl[i];
      J[(n + k) * nx + j] = s->minv[k] * v;
    }
  }
  int i = dc_first_nonfinite(J, nx * nx);
  if (i >= 0) {
    set_msg(s->msg, "Jacobian entry (%d, %d) is %g at t=%.17g", i / nx, i % nx, J[i], t);
    return DCO_NONFINITE;
  }
  return DCO_OK;
}

/* One step of explicit Euler (DCO_EULER) or classical RK4 (DCO_RK4, any other scheme) from (t, x) of size h. */
static int scheme_step(dco_session* s, int scheme, double t, const double* x, double h, double* xn) {
  const int nx = s->nx;
  int rc;
  s->cnt[DCO_CNT_RHS]++;
  if ((rc = accel(s, t, x, s->k1))) return rc;
  if (scheme == DCO_EULER) {
    for (int i = 0; i < nx; ++i) xn[i] = x[i] + h * s->k1[i];
  } else {
    const double h2 = 0.5 * h;
    for (int i = 0; i < nx; ++i) s->xt[i] = x[i] + h2 * s->k1[i];
    s->cnt[DCO_CNT_RHS]++;
    if ((rc = accel(s, t + h2, s->xt, s->k2))) return rc;
    for (int i = 0; i < nx; ++i) s->xt[i] = x[i] + h2 * s->k2[i];
    s->cnt[DCO_CNT_RHS]++;
    if ((rc = accel(s, t + h2, s->xt, s->k3))) return rc;
    for (int i = 0; i < nx; ++i) s->xt[i] = x[i] + h * s->k3[i];
    s->cnt[DCO_CNT_RHS]++;
    if ((rc = accel(s, t + h, s->xt, s->k4))) return rc;
    const double h6 = h / 6.0;
    for (int i = 0; i < nx; ++i)
      xn[i] = x[i] + h6 * (s->k1[i] + 2.0 * s->k2[i] + 2.0 * s->k3[i] + s->k4[i]);
  }
  int i = dc_first_nonfinite(xn, nx);
  if (i >= 0) {
    set_msg(s->msg, "state component %d became %g in the step from t=%.17g (h=%g)", i, xn[i], t, h);
    return DCO_NONFINITE;
  }
  return DCO_OK;
}

/* Far-side point s* in (0, h] of a possible crossing of G = dir * g from <= 0 to > 0 within a
 * step, from G and dG/dt at both ends: h when G1 > 0, or the first interior maximum of the cubic
 * Hermite interpolant that lies above zero (if earlier). -1: no crossing expected. Must match
 * daeclear.solvers.ode_crossings.candidate. */
static double candidate(double G0, double Gd0, double G1, double Gd1, double h, int hermite) {
  if (G0 > 0.0) return -1.0;
  double best = G1 > 0.0 ? h : -1.0;
  if (!hermite) return best;
  double hi = (G0 > G1 ? G0 : G1) + 0.15 * h * (fabs(Gd0) + fabs(Gd1));
  if (hi <= 0.0) return best;
  const double a0 = h * Gd0, a1 = h * Gd1;
  const double A = 6.0 * G0 + 3.0 * a0 - 6.0 * G1 + 3.0 * a1;
  const double B = -6.0 * G0 - 4.0 * a0 + 6.0 * G1 - 2.0 * a1;
  const double C = a0;
  double u[2];
  int nu = 0;
  if (fabs(A) <= 1e-12 * (fabs(B) + fabs(C))) {
    if (B != 0.0) u[nu++] = -C / B;
  } else {
    double disc = B * B - 4.0 * A * C;
    if (disc >= 0.0) {
      double sq = sqrt(disc);
      double qq = -0.5 * (B + (B >= 0.0 ? sq : -sq));
      u[nu++] = qq / A;
      if (qq != 0.0) u[nu++] = C / qq;
    }
  }
  for (int k = 0; k < nu; ++k) {
    double uu = u[k];
    if (!(uu > 0.0 && uu < 1.0)) continue;
    if (2.0 * A * uu + B >= 0.0) continue; /* not a maximum */
    double u2 = uu * uu, u3 = u2 * uu;
    double p = (2 * u3 - 3 * u2 + 1) * G0 + (u3 - 2 * u2 + uu) * a0 + (-2 * u3 + 3 * u2) * G1 +
               (u3 - u2) * a1;
    if (p > 0.0 && (best < 0.0 || uu * h < best)) best = uu * h;
  }
  return best;
}

/* ------------------------------------------------------------------ API ---- */

DC_API int dco_abi_version(void) { return DCO_ABI_VERSION; }

DC_API int dco_info(int* n, int* m, int* n_terms, int* n_gaps, int* n_params) {
  *n = dco_model.n;
  *m = dco_model.m;
  *n_terms = dco_model.n_terms;
  *n_gaps = dco_model.n_gaps;
  if (n_params)
    for (int k = 0; k < dco_model.n_terms; ++k) n_params[k] = dco_model.n_params[k];
  return 0;
}

DC_API const char* dco_message(void* sp) { return sp ? ((dco_session*)sp)->msg : ""; }

DC_API void dco_free(void* sp) {
  dco_session* s = (dco_session*)sp;
  const dco_model_t* M = &dco_model;
  if (!s) return;
  if (s->refd) {
    if (s->mem_sys >= 0) M->sys.release(s->mem_sys);
    if (s->mem_sysj >= 0) M->sys_jac.release(s->mem_sysj);
    if (M->n_gaps > 0 && s->mem_gaps >= 0) M->gaps.release(s->mem_gaps);
    if (M->n_channels > 0 && s->mem_out >= 0) M->outputs.release(s->mem_out);
    for (int k = 0; k < M->n_terms; ++k) {
      if (s->mem_tf && s->mem_tf[k] >= 0) M->term_force[k].release(s->mem_tf[k]);
      if (s->mem_tj && s->mem_tj[k] >= 0) M->term_jac[k].release(s->mem_tj[k]);
    }
    M->sys.decref();
    M->sys_jac.decref();
    if (M->n_gaps > 0) M->gaps.decref();
    if (M->n_channels > 0) M->outputs.decref();
    for (int k = 0; k < M->n_terms; ++k) {
      M->term_force[k].decref();
      M->term_jac[k].decref();
    }
  }
  double* bufs[] = {s->minv, s->Q, s->Pq, s->c, s->f, s->Fk, s->S, s->Sd, s->r, s->lam, s->D,
                    s->Jk, s->b, s->zl, s->k1, s->k2, s->k3, s->k4, s->xt, s->xcur, s->g0,
                    s->gd0, s->g1, s->gd1, s->params, s->w, s->nz};
  for (size_t i = 0; i < sizeof(bufs) / sizeof(bufs[0]); ++i) free(bufs[i]);
  free(s->arg);
  free(s->res);
  free(s->iw);
  free(s->mem_tf);
  free(s->mem_tj);
  free(s->active);
  free(s->poff);
  free(s->P);
  free(s);
}

DC_API void* dco_open(const double* mass, const double* P, char* err, int errlen) {
  const dco_model_t* M = &dco_model;
  dco_session* s = (dco_session*)calloc(1, sizeof(dco_session));
  if (!s) {
    if (err && errlen > 0) snprintf(err, errlen, "out of memory");
    return NULL;
  }
  const int n = M->n, m = M->m, nx = 2 * M->n, nt = M->n_terms, ng = M->n_gaps;
  s->n = n;
  s->m = m;
  s->nx = nx;
  s->nt = nt;
  s->ng = ng;
  s->mem_sys = s->mem_sysj = s->mem_gaps = s->mem_out = -1;
  s->hermite = 1;
  dc_int sa = 6, sr = 3, si = 0, sw = 0;
  work_max(&M->sys, &sa, &sr, &si, &sw);
  work_max(&M->sys_jac, &sa, &sr, &si, &sw);
  if (ng > 0) work_max(&M->gaps, &sa, &sr, &si, &sw);
  if (M->n_channels > 0) work_max(&M->outputs, &sa, &sr, &si, &sw);
  for (int k = 0; k < nt; ++k) {
    work_max(&M->term_force[k], &sa, &sr, &si, &sw);
    work_max(&M->term_jac[k], &sa, &sr, &si, &sw);
  }
  s->arg = (const double**)xcalloc((size_t)sa, sizeof(double*));
  s->res = (double**)xcalloc((size_t)sr, sizeof(double*));
  s->iw = (dc_int*)xcalloc((size_t)si, sizeof(dc_int));
  s->w = (double*)xcalloc((size_t)sw, sizeof(double));
  s->mem_tf = (int*)xcalloc((size_t)nt, sizeof(int));
  s->mem_tj = (int*)xcalloc((size_t)nt, sizeof(int));
  s->active = (int*)xcalloc((size_t)nt, sizeof(int));
  s->poff = (int*)xcalloc((size_t)nt + 1, sizeof(int));
  int np = 0;
  for (int k = 0; k < nt; ++k) {
    s->poff[k] = np;
    np += M->n_params[k];
  }
  if (nt) s->poff[nt] = np;
  s->params = (double*)xcalloc((size_t)np, sizeof(double));
  s->P = (double*)xcalloc((size_t)M->n_parameters, sizeof(double));
  if (s->P && M->n_parameters > 0) memcpy(s->P, P, sizeof(double) * (size_t)M->n_parameters);
#define ALLOC(field, count) s->field = (double*)xcalloc((size_t)(count), sizeof(double))
  ALLOC(minv, n);
  ALLOC(Q, n);
  ALLOC(Pq, m * n);
  ALLOC(c, m);
  ALLOC(f, n);
  ALLOC(Fk, n);
  ALLOC(S, m * m);
  ALLOC(Sd, m);
  ALLOC(r, m);
  ALLOC(lam, m);
  ALLOC(D, (n + m) * nx);
  ALLOC(Jk, n * nx);
  ALLOC(b, n + m);
  ALLOC(zl, m);
  ALLOC(k1, nx);
  ALLOC(k2, nx);
  ALLOC(k3, nx);
  ALLOC(k4, nx);
  ALLOC(xt, nx);
  ALLOC(xcur, nx);
  ALLOC(g0, ng);
  ALLOC(gd0, ng);
  ALLOC(g1, ng);
  ALLOC(gd1, ng);
  { /* the outputs of one call at most: every function's outputs are no larger than these */
    dc_int most = (dc_int)(n + m) * nx + n + m * n + m + 2 * ng + M->n_channels;
    ALLOC(nz, most);
  }
#undef ALLOC
  if (!s->arg || !s->res || !s->iw || !s->w || !s->mem_tf || !s->mem_tj || !s->active ||
      !s->poff || !s->params || !s->P || !s->minv || !s->D || !s->Jk || !s->gd1 || !s->nz) {
    if (err && errlen > 0) snprintf(err, errlen, "out of memory");
    dco_free(s);
    return NULL;
  }
  for (int k = 0; k < n; ++k) {
    if (!(mass[k] > 0.0)) {
      if (err && errlen > 0)
        snprintf(err, errlen, "mass matrix diagonal entry %d is %g; it must be > 0", k, mass[k]);
      dco_free(s);
      return NULL;
    }
    s->minv[k] = 1.0 / mass[k];
  }
  for (int k = 0; k < nt; ++k) s->mem_tf[k] = s->mem_tj[k] = -1;
  s->refd = 1;
  M->sys.incref();
  M->sys_jac.incref();
  if (ng > 0) M->gaps.incref();
  if (M->n_channels > 0) M->outputs.incref();
  for (int k = 0; k < nt; ++k) {
    M->term_force[k].incref();
    M->term_jac[k].incref();
  }
  s->mem_sys = M->sys.checkout();
  s->mem_sysj = M->sys_jac.checkout();
  if (ng > 0) s->mem_gaps = M->gaps.checkout();
  if (M->n_channels > 0) s->mem_out = M->outputs.checkout();
  for (int k = 0; k < nt; ++k) {
    s->mem_tf[k] = M->term_force[k].checkout();
    s->mem_tj[k] = M->term_jac[k].checkout();
  }
  return s;
}

/* active[n_terms] flags and the terms' parameters concatenated in term order. */
DC_API void dco_set_terms(void* sp, const int* active, const double* params) {
  dco_session* s = (dco_session*)sp;
  for (int k = 0; k < s->nt; ++k) s->active[k] = active[k] ? 1 : 0;
  int np = s->nt ? s->poff[s->nt] : 0;
  if (np) memcpy(s->params, params, sizeof(double) * np);
}

/* 1 (default): a step may hold a crossing when the cubic Hermite interpolant of a gap has an
 * interior maximum above zero; 0: sign changes at the step ends only (for measurements). */
DC_API void dco_set_hermite(void* sp, int on) { ((dco_session*)sp)->hermite = on ? 1 : 0; }

/* x' at (t, x): 0 on success, else a DCO_* code (message in dco_message; xdot may hold NaN). */
DC_API int dco_rhs(void* sp, double t, const double* x, double* xdot) {
  dco_session* s = (dco_session*)sp;
  s->cnt[DCO_CNT_RHS]++;
  int rc = accel(s, t, x, xdot);
  if (rc && rc != DCO_NONFINITE)
    for (int i = 0; i < s->nx; ++i) xdot[i] = NAN;
  return rc;
}

DC_API int dco_jac(void* sp, double t, const double* x, double* J) {
  dco_session* s = (dco_session*)sp;
  s->cnt[DCO_CNT_JAC]++;
  int rc = eval_jac(s, t, x, J);
  if (rc && rc != DCO_NONFINITE)
    for (int i = 0; i < s->nx * s->nx; ++i) J[i] = NAN;
  return rc;
}

DC_API int dco_gaps(void* sp, double t, const double* x, double* g, double* gd) {
  dco_session* s = (dco_session*)sp;
  if (s->ng == 0) return 0;
  return eval_gaps(s, t, x, g, gd);
}

DC_API int dco_step(void* sp, int scheme, double t, const double* x, double h, double* xn) {
  return scheme_step((dco_session*)sp, scheme, t, x, h, xn);
}

/* x' and lam at N points (row-major N x nx and N x m), uncounted. Returns the index of the first
 * point that failed (its row holds NaN), or -1. */
DC_API int dco_batch(void* sp, int N, const double* t, const double* X, double* Xdot, double* Lam) {
  dco_session* s = (dco_session*)sp;
  int bad = -1;
  for (int p = 0; p < N; ++p) {
    int rc = accel(s, t[p], X + (size_t)p * s->nx, Xdot + (size_t)p * s->nx);
    if (rc) {
      for (int i = 0; i < s->nx; ++i) Xdot[(size_t)p * s->nx + i] = NAN;
      for (int i = 0; i < s->m; ++i) Lam[(size_t)p * s->m + i] = NAN;
      if (bad < 0) bad = p;
    } else {
      for (int i = 0; i < s->m; ++i) Lam[(size_t)p * s->m + i] = s->lam[i];
    }
  }
  return bad;
}

/* Fixed-step loop from (t0, x0) with step hstep towards t_stop (the last step lands on t_stop).
 * Records every step end in st/sx (at most cap). Watches every gap in the direction rootdir[i]
 * (+1 increasing, -1 decreasing, 0 both, as IDA). On return (ta, xa) is the current state; on
 * FX_CANDIDATE (ta, xa) is the start and (tb, xb) the end of the step that may hold a crossing,
 * sstar[2i] (increasing) and sstar[2i+1] (decreasing) the far-side points (step-relative) of
 * gap i, or -1. */
DC_API int dco_fixed(void* sp, int scheme, double t0, const double* x0, double hstep,
                     double t_stop, long long max_steps, const int* rootdir, int cap, double* st,
                     double* sx, int* n_stored, double* ta, double* xa, double* tb, double* xb,
                     double* sstar) {
  dco_session* s = (dco_session*)sp;
  const int nx = s->nx, ng = s->ng;
  const int watch = ng > 0;
  *n_stored = 0;
  *ta = t0;
  memcpy(xa, x0, sizeof(double) * nx);
  if (watch && eval_gaps(s, t0, xa, s->g0, s->gd0)) return FX_ERR;
  long long k = 0;
  for (;;) {
    if (*ta >= t_stop) return FX_TSTOP;
    if (k >= max_steps) return FX_MAXSTEPS;
    if (*n_stored >= cap) return FX_CHUNK;
    double tn = t0 + (double)(k + 1) * hstep;
    if (tn >= t_stop - 1e-9 * hstep) tn = t_stop;
    const double h = tn - *ta;
    if (scheme_step(s, scheme, *ta, xa, h, xb)) return FX_ERR;
    s->cnt[DCO_CNT_STEPS]++;
    ++k;
    if (watch) {
      if (eval_gaps(s, tn, xb, s->g1, s->gd1)) {
        return FX_ERR;
      }
      int found = 0;
      for (int i = 0; i < ng; ++i) {
        for (int j = 0; j < 2; ++j) {
          const double d = j == 0 ? 1.0 : -1.0;
          double* out = sstar + 2 * i + j;
          *out = -1.0;
          if (rootdir[i] * d < 0) continue; /* the other direction only */
          *out = candidate(d * s->g0[i], d * s->gd0[i], d * s->g1[i], d * s->gd1[i], h, s->hermite);
          if (*out > 0.0) found = 1;
        }
      }
      if (found) {
        *tb = tn;
        return FX_CANDIDATE;
      }
      double* tmp = s->g0;
      s->g0 = s->g1;
      s->g1 = tmp;
      tmp = s->gd0;
      s->gd0 = s->gd1;
      s->gd1 = tmp;
    }
    st[*n_stored] = tn;
    memcpy(sx + (size_t)(*n_stored) * nx, xb, sizeof(double) * nx);
    ++*n_stored;
    *ta = tn;
    memcpy(xa, xb, sizeof(double) * nx);
  }
}

/* Output channels at N points: Y, YP row-major (N x n_y), one switch vector for all points,
 * out row-major (N x n_channels). Returns 0, -1 without an outputs function, or 1 + the index of
 * the first point that failed. */
DC_API int dco_outputs(void* sp, int N, const double* t, const double* Y, const double* YP,
                       const double* sw, double* out) {
  dco_session* s = (dco_session*)sp;
  const dco_model_t* M = &dco_model;
  if (M->n_channels <= 0) return -1;
  for (int p = 0; p < N; ++p) {
    const double* in[4] = {t + p, Y + (size_t)p * M->n_y, YP + (size_t)p * M->n_y, sw};
    double* o[1] = {out + (size_t)p * M->n_channels};
    if (call(s, &M->outputs, s->mem_out, 4, in, 1, o)) return 1 + p;
  }
  return 0;
}

DC_API void dco_output_sizes(int* n_y, int* n_switch, int* n_channels) {
  *n_y = dco_model.n_y;
  *n_switch = dco_model.n_switch;
  *n_channels = dco_model.n_channels;
}

/* counters: rhs evaluations, Jacobians, gap evaluations, fixed steps */
DC_API void dco_counters(void* sp, long long* out) {
  dco_session* s = (dco_session*)sp;
  for (int i = 0; i < DCO_CNT_N; ++i) out[i] = s->cnt[i];
}
