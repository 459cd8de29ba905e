/*
 * ida_eval.h -- model evaluation: the generated residual, Jacobian, roots and extras with the active
 * terms, IDA's callbacks, and the union pattern of the sparse Jacobian.
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_EVAL_H
#define DAECLEAR_IDA_EVAL_H

#include "ida_session.h"

/* ---------------------------------------------------------------- model evaluation ---- */

static dc_int nnz_of(const dc_fun_t* f) { return dc_sp_nnz(f->sparsity_out(0)); }

/* Evaluate an extra (one column output) into the dense vector out. The generated extras keep
 * CasADi's sparsity (a term's generalized force touches two bodies, a kinematic Jacobian a few
 * coordinates per row: dense outputs made the generated code grow like N^2 on chains): a sparse
 * output is written to nz (nnz values) and scattered, zeros elsewhere. */
static int extra_dense(const dc_fun_t* f, const double** arg, double** res, dc_int* iw, double* w, int mem,
                       double* out, double* nz) {
  const dc_int* sp = f->sparsity_out(0);
  if (dc_sp_dense(sp)) {
    res[0] = out;
    return f->eval(arg, res, iw, w, mem);
  }
  res[0] = nz;
  const int status = f->eval(arg, res, iw, w, mem);
  if (status != 0) return status;
  memset(out, 0, sizeof(double) * (size_t)(sp[0] * sp[1]));
  dc_sp_scatter(sp, nz, out, sp[0], 0);
  return 0;
}

/* The first three inputs of every generated model function: t, y, yp. */
static void point_args(dc_session* s, const double* t, const double* y, const double* yp) {
  s->arg[0] = t;
  s->arg[1] = y;
  s->arg[2] = yp;
}

static int eval_res(dc_session* s, double t, const double* y, const double* yp, double* r) {
  const dc_model_t* M = &dc_model;
  point_args(s, &t, y, yp);
  s->arg[3] = s->P;
  s->res[0] = r;
  if (M->res.eval(s->arg, s->res, s->iw, s->w, s->mem_res)) return -1;
  for (int k = 0; k < s->n_terms; ++k) {
    if (!s->active[k]) continue;
    point_args(s, &t, y, yp);
    s->arg[3] = s->params + s->param_off[k];
    s->arg[4] = s->P;
    s->res[0] = s->tmp_r;
    if (M->term_res[k].eval(s->arg, s->res, s->iw, s->w, s->mem_term_res[k])) return -(k + 2);
    /* the term's nonzeros: two bodies' rows */
    dc_sp_scatter(M->term_res[k].sparsity_out(0), s->tmp_r, r, s->n, 1);
  }
  return 0;
}

/* The generated Jacobian of part p: 0 the base Jacobian, 1 + k term k's. */
static const dc_fun_t* jac_part(int p) { return p == 0 ? &dc_model.jac : &dc_model.term_jac[p - 1]; }

/* Add the nonzeros nz of Jacobian part p to out: the dense column-major n x n matrix, or (sparse)
 * the data array of the union pattern, through the precomputed positions (no search per entry). */
static void add_part(const dc_session* s, int p, const double* nz, double* out, int sparse) {
  if (!sparse) {
    dc_sp_scatter(jac_part(p)->sparsity_out(0), nz, out, s->nj, 1);
    return;
  }
  const dc_int* map = s->jmap + s->jmap_off[p];
  const dc_int m = s->jmap_off[p + 1] - s->jmap_off[p];
  for (dc_int i = 0; i < m; ++i) out[map[i]] += nz[i];
}

/* Entries of the Jacobian (out): n * n dense, or jp_nnz in the union pattern. */
static dc_int jac_len(const dc_session* s, int sparse) {
  return sparse ? s->jp_nnz : (dc_int)s->nj * (dc_int)s->nj;
}

/* J = base Jacobian + active terms' Jacobians, into out (layout: see add_part); zeroed: J is
 * zero already (IDA zeroes a direct solver's matrix before it calls jac_cb). */
static int eval_jac(dc_session* s, double t, const double* y, const double* yp, double cj,
                    double* J, int sparse, int zeroed) {
  const dc_model_t* M = &dc_model;
  if (!zeroed) memset(J, 0, sizeof(double) * (size_t)jac_len(s, sparse));
  point_args(s, &t, y, yp);
  s->arg[3] = &cj;
  s->arg[4] = s->P;
  s->res[0] = s->tmp_J;
  if (M->jac.eval(s->arg, s->res, s->iw, s->w, s->mem_jac)) return -1;
  add_part(s, 0, s->tmp_J, J, sparse);
  for (int k = 0; k < s->n_terms; ++k) {
    if (!s->active[k]) continue;
    point_args(s, &t, y, yp);
    s->arg[3] = s->params + s->param_off[k];
    s->arg[4] = &cj;
    s->arg[5] = s->P;
    s->res[0] = s->tmp_J;
    if (M->term_jac[k].eval(s->arg, s->res, s->iw, s->w, s->mem_term_jac[k])) return -(k + 2);
    add_part(s, k + 1, s->tmp_J, J, sparse);
  }
  return 0;
}

static int eval_roots(dc_session* s, double t, const double* y, const double* yp, double* g) {
  const dc_model_t* M = &dc_model;
  point_args(s, &t, y, yp);
  s->arg[3] = s->P;
  s->res[0] = g;
  return M->roots.eval(s->arg, s->res, s->iw, s->w, s->mem_roots) ? -1 : 0;
}

/* ---------------------------------------------------------------- IDA callbacks ---- */

static int res_cb(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, void* data) {
  dc_session* s = (dc_session*)data;
  double* r = N_VGetArrayPointer(rr);
  int rc = eval_res(s, t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), r);
  if (rc) {
    if (rc == -1)
      set_msg(s->cb_msg, "the generated base residual returned an error at t=%.17g", t);
    else
      set_msg(s->cb_msg, "the generated residual of term %d returned an error at t=%.17g",
              -rc - 2, t);
    return -1; /* unrecoverable */
  }
  int i = dc_first_nonfinite(r, s->n);
  if (i >= 0) {
    set_msg(s->cb_msg,
            "residual component %d is %g at t=%.17g (y[%d]=%g); IDA retried with smaller steps",
            i, r[i], t, i, N_VGetArrayPointer(yy)[i]);
    return 1; /* recoverable: IDA cuts the step */
  }
  return 0;
}

/* Row and column of entry i of the Jacobian's storage (for messages). */
static void entry_position(const dc_session* s, dc_int i, int sparse, int* row, int* col) {
  if (!sparse) {
    *row = (int)(i % s->nj);
    *col = (int)(i / s->nj);
    return;
  }
  int c = 0;
  while (c < s->nj && (dc_int)s->jp_colptr[c + 1] <= i) ++c;
  *row = (int)s->jp_rowind[i];
  *col = c;
}

/* The matrix's storage for eval_jac: the union values (sparse), the SUNSparseMatrix's data with its
 * pattern put back first (superlu: IDA zeroes the matrix before every call, SUNMatZero, and for a
 * SUNSparseMatrix that clears the index arrays too), or the dense matrix's data. */
static double* jac_storage(dc_session* s, SUNMatrix J) {
  if (s->lin_kind == DC_LS_SPARSE) return dcls_values_data(J);
#if DC_HAVE_SPARSE
  if (s->lin_kind == DC_LS_SUPERLU) {
    memcpy(SUNSparseMatrix_IndexPointers(J), s->jp_colptr, sizeof(sunindextype) * ((size_t)s->nj + 1));
    memcpy(SUNSparseMatrix_IndexValues(J), s->jp_rowind, sizeof(sunindextype) * (size_t)s->jp_nnz);
    return SUNSparseMatrix_Data(J);
  }
#endif
  return SUNDenseMatrix_Data(J);
}

/* An entry of the assembled Jacobian that is not finite (its index in the storage), or -1: in
 * the dense matrix only the positions of the base and active terms' patterns can be. */
static dc_int jac_first_nonfinite(const dc_session* s, const double* Jd) {
  if (LIN_UNION(s)) return dc_first_nonfinite(Jd, (int)s->jp_nnz);
  for (int p = 0; p <= s->n_terms; ++p) {
    if (p > 0 && !s->active[p - 1]) continue;
    const dc_int i = dc_sp_first_nonfinite(jac_part(p)->sparsity_out(0), Jd, s->nj);
    if (i >= 0) return i;
  }
  return -1;
}

/* The block lower-triangular solve's coupling (dcls_sun_set_coupling): x[nj:] -= C x[:nj], C the blocks
 * below the first block column at the last Jacobian's point (base and active terms, dc_model.cpl). Where C
 * is not finite (a force without a second derivative there: Hertz's delta^1.5 at onset) or its evaluation
 * fails, that solve keeps the block-diagonal part (IDAS' simultaneous corrector), as IDA's modified Newton
 * may. The generated SX functions keep no state between calls (memory 0, as the extras). */
static void couple_cb(void* data, double* x) {
  dc_session* s = (dc_session*)data;
  const dc_model_t* M = &dc_model;
  const int m = s->n - s->nj;
  point_args(s, &s->cpl_t, s->cpl_y, s->cpl_yp);
  s->arg[3] = &s->cpl_cj;
  s->arg[4] = s->P;
  s->arg[5] = x;
  s->res[0] = s->cpl_out;
  if (M->cpl.eval(s->arg, s->res, s->iw, s->w, 0)) return;
  for (int k = 0; k < s->n_terms; ++k) {
    if (!s->active[k]) continue;
    point_args(s, &s->cpl_t, s->cpl_y, s->cpl_yp);
    s->arg[3] = s->params + s->param_off[k];
    s->arg[4] = &s->cpl_cj;
    s->arg[5] = s->P;
    s->arg[6] = x;
    s->res[0] = s->cpl_tmp;
    if (M->term_cpl[k].eval(s->arg, s->res, s->iw, s->w, 0)) return;
    for (int i = 0; i < m; ++i) s->cpl_out[i] += s->cpl_tmp[i];
  }
  if (dc_first_nonfinite(s->cpl_out, m) >= 0) return;
  for (int i = 0; i < m; ++i) x[s->nj + i] -= s->cpl_out[i];
}

static int jac_cb(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp, N_Vector rr,
                  SUNMatrix J, void* data, N_Vector t1, N_Vector t2, N_Vector t3) {
  dc_session* s = (dc_session*)data;
  double* Jd = jac_storage(s, J);
  (void)rr;
  (void)t1;
  (void)t2;
  (void)t3;
  int rc = eval_jac(s, t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), cj, Jd, LIN_UNION(s), 1);
  if (rc) {
    if (rc == -1)
      set_msg(s->cb_msg, "the generated base Jacobian returned an error at t=%.17g", t);
    else
      set_msg(s->cb_msg, "the generated Jacobian of term %d returned an error at t=%.17g",
              -rc - 2, t);
    return -1;
  }
  const dc_int i = jac_first_nonfinite(s, Jd);
  if (i >= 0) {
    int row, col;
    entry_position(s, i, LIN_UNION(s), &row, &col);
    set_msg(s->cb_msg, "Jacobian entry (%d, %d) is %g at t=%.17g", row, col, Jd[i], t);
    return 1;
  }
  s->lin->cj = cj; /* IDA factors this matrix next */
  if (s->coupled) { /* the coupling's point: the same modified Newton matrix */
    s->cpl_t = t;
    s->cpl_cj = cj;
    memcpy(s->cpl_y, N_VGetArrayPointer(yy), sizeof(double) * (size_t)s->n);
    memcpy(s->cpl_yp, N_VGetArrayPointer(yp), sizeof(double) * (size_t)s->n);
  }
  return 0;
}

static int root_cb(sunrealtype t, N_Vector yy, N_Vector yp, sunrealtype* g, void* data) {
  dc_session* s = (dc_session*)data;
  if (eval_roots(s, t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), g)) {
    set_msg(s->cb_msg, "the generated root function returned an error at t=%.17g", t);
    return -1;
  }
  int i = dc_first_nonfinite(g, s->n_roots);
  if (i >= 0) {
    set_msg(s->cb_msg, "root function %d is %g at t=%.17g", i, g[i], t);
    return -1;
  }
  return 0;
}

static int cmp_index(const void* a, const void* b) {
  sunindextype x = *(const sunindextype*)a, y = *(const sunindextype*)b;
  return (x > y) - (x < y);
}

/* The union of the CSC patterns of all Jacobian parts (base and every term), rows sorted within
 * each column as SUNSparseMatrix and SuperLU_MT expect, and each part's nonzero -> position map.
 * Once per session, O(nonzeros log): a row marker per column, no n x n scratch. Returns 0, or -1
 * out of memory, -2 a pattern that is not nj x nj, -3 too many nonzeros for sunindextype. */
static int build_jac_pattern(dc_session* s) {
  const int n = s->nj, parts = s->n_terms + 1;
  dc_int total = 0;
  s->jmap_off = (dc_int*)xcalloc((size_t)parts + 1, sizeof(dc_int));
  if (!s->jmap_off) return -1;
  for (int p = 0; p < parts; ++p) {
    const dc_int* sp = jac_part(p)->sparsity_out(0);
    if (sp[0] != n || sp[1] != n) return -2;
    s->jmap_off[p] = total;
    total += nnz_of(jac_part(p));
  }
  s->jmap_off[parts] = total;
  const dc_int cap = total < (dc_int)n * n ? total : (dc_int)n * n; /* the union's size at most */
  if (sizeof(sunindextype) < sizeof(dc_int) && cap > (dc_int)INT32_MAX) return -3;
  s->jmap = (dc_int*)xcalloc((size_t)total, sizeof(dc_int));
  s->jp_colptr = (sunindextype*)xcalloc((size_t)n + 1, sizeof(sunindextype));
  s->jp_rowind = (sunindextype*)xcalloc((size_t)cap, sizeof(sunindextype));
  dc_int* pos = (dc_int*)xcalloc((size_t)n, sizeof(dc_int)); /* row -> position, -1: not seen */
  if (!s->jmap || !s->jp_colptr || !s->jp_rowind || !pos) {
    free(pos);
    return -1;
  }
  for (int i = 0; i < n; ++i) pos[i] = -1;
  dc_int nnz = 0;
  for (dc_int c = 0; c < n; ++c) {
    const dc_int start = nnz;
    for (int p = 0; p < parts; ++p) { /* collect the column's distinct rows */
      const dc_int* sp = jac_part(p)->sparsity_out(0);
      for (dc_int k = dc_sp_begin(sp, c); k < dc_sp_end(sp, c); ++k) {
        dc_int r = dc_sp_row(sp, k);
        if (pos[r] < 0) {
          pos[r] = 0;
          s->jp_rowind[nnz++] = (sunindextype)r;
        }
      }
    }
    qsort(s->jp_rowind + start, (size_t)(nnz - start), sizeof(sunindextype), cmp_index);
    for (dc_int k = start; k < nnz; ++k) pos[s->jp_rowind[k]] = k;
    for (int p = 0; p < parts; ++p) { /* where each part's nonzeros of this column go */
      const dc_int* sp = jac_part(p)->sparsity_out(0);
      for (dc_int k = dc_sp_begin(sp, c); k < dc_sp_end(sp, c); ++k)
        s->jmap[s->jmap_off[p] + k] = pos[dc_sp_row(sp, k)];
    }
    for (dc_int k = start; k < nnz; ++k) pos[s->jp_rowind[k]] = -1;
    s->jp_colptr[c + 1] = (sunindextype)nnz;
  }
  s->jp_nnz = nnz;
  free(pos);
  return 0;
}


/* One evaluation of extra k (inputs in order, one output) with the session's preallocated work
 * memory: the per-point path of restarts and reports (dc_eval_extra allocates per call). The
 * generated SX functions keep no state between calls (their checkout is a constant). */
static int eval_extra1(dc_session* s, int k, int n_in, const double* const* in, double* out) {
  for (int j = 0; j < n_in; ++j) s->xarg[j] = in[j];
  return extra_dense(&dc_extra_tab[k], s->xarg, s->xres, s->xiw, s->xw, 0, out, s->xnz);
}

/* eval_extra1 added into out (the output's length) instead of written: a sparse output's nonzeros
 * only (a contact term's generalized force touches two bodies of a long chain). */
static int add_extra1(dc_session* s, int k, int n_in, const double* const* in, double* out) {
  const dc_fun_t* f = &dc_extra_tab[k];
  const dc_int* sp = f->sparsity_out(0);
  for (int j = 0; j < n_in; ++j) s->xarg[j] = in[j];
  s->xres[0] = s->xnz;
  if (f->eval(s->xarg, s->xres, s->xiw, s->xw, 0) != 0) return -1;
  dc_sp_scatter(sp, s->xnz, out, sp[0], 1);
  return 0;
}

#endif
