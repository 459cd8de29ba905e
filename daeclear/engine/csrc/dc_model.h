/*
 * dc_model.h -- the table that daeclear's code generator appends to the CasADi-generated
 * model source, and that the IDA driver (ida_driver.c) reads.
 *
 * The generated functions use casadi_real = double and casadi_int = long long int (set
 * explicitly by daeclear.engine.codegen), so the pointer types below match them exactly.
 */
#ifndef DAECLEAR_DC_MODEL_H
#define DAECLEAR_DC_MODEL_H

#include <math.h>

typedef long long int dc_int;

typedef int (*dc_eval_fn)(const double** arg, double** res, dc_int* iw, double* w, int mem);
typedef int (*dc_work_fn)(dc_int* sz_arg, dc_int* sz_res, dc_int* sz_iw, dc_int* sz_w);
typedef int (*dc_checkout_fn)(void);
typedef void (*dc_release_fn)(int mem);
typedef void (*dc_ref_fn)(void);
typedef const dc_int* (*dc_sparsity_fn)(dc_int i);

typedef struct {
  dc_eval_fn eval;
  dc_work_fn work;
  dc_checkout_fn checkout;
  dc_release_fn release;
  dc_ref_fn incref;
  dc_ref_fn decref;
  dc_sparsity_fn sparsity_out; /* CasADi compressed column storage: nrow, ncol, colind[ncol+1], row[nnz] */
  const char* name;
} dc_fun_t;

/* The sparse LU's plan of the Newton matrix, made by daeclear/engine/sparse_plan.py when the model's C
 * is generated (csrc/dc_sparse_lu.h factors numerically on it). Pivot k is unknown perm[k]; the
 * factors L + U of the permuted matrix are stored by columns in pivot order (rows ascending: U above
 * the diagonal at fdiag[j], unit L's multipliers below it); row j of L is the pairs (lrowcol,
 * lrowpos) from lrowptr[j]: the column k < j and the position of L(j, k). */
typedef struct {
  int n, nnz, fnnz;           /* size, nonzeros of the union pattern and of L + U */
  const int* colptr;          /* [n + 1] the union pattern (CSC, rows ascending), checked at dc_open */
  const int* rowind;          /* [nnz] */
  const int* perm;            /* [n] */
  const int* fcolptr;         /* [n + 1] */
  const int* frow;            /* [fnnz] */
  const int* fdiag;           /* [n] */
  const int* lrowptr;         /* [n + 1] */
  const int* lrowcol;         /* [nnz of L] */
  const int* lrowpos;         /* [nnz of L] */
} dc_lu_plan;

typedef struct {
  int n;                      /* state size */
  int n_terms;                /* number of switchable terms */
  int n_roots;                /* number of root functions (0: none) */
  int n_parameters;           /* size of the run-time parameter vector P, the last input of every function */
  const int* n_params;        /* [n_terms] parameter count of each term */
  dc_fun_t res;               /* (t, y, yp, P) -> r[n] */
  dc_fun_t jac;               /* (t, y, yp, cj, P) -> J (sparse, n x n, see sparsity_out) */
  dc_fun_t roots;             /* (t, y, yp, P) -> g[n_roots]; eval == 0 when n_roots == 0 */
  const dc_fun_t* term_res;   /* [n_terms] (t, y, yp, p, P) -> r_k[n] */
  const dc_fun_t* term_jac;   /* [n_terms] (t, y, yp, p, cj, P) -> J_k (sparse, n x n) */
  const dc_lu_plan* lu;       /* the sparse LU's plan, NULL when its static pivots are structurally singular */
  const char* name;
  /* a Newton matrix of blocks (jac nj x nj, n = blocks nj: the stacked sensitivities) that is block lower
   * triangular: (t, y, yp, cj, P, dy0) -> C dy0 [n - nj], its blocks below the first block column times
   * the first block's solution; eval == 0: none (the block-diagonal part is solved) */
  dc_fun_t cpl;
  const dc_fun_t* term_cpl;   /* [n_terms] (t, y, yp, p, cj, P, dy0) -> the same of term k */
} dc_model_t;

extern const dc_model_t dc_model;

/* CasADi's compressed column storage, the patterns of sparsity_out: nrow, ncol, colind[ncol+1],
 * row[nnz]; a dense pattern is written as just nrow, ncol, 1 (a sparse one has colind[0] == 0).
 * The generated functions keep their sparsity; both drivers scatter the nonzeros with these. */
static inline int dc_sp_dense(const dc_int* sp) { return sp[2] == 1; }
static inline dc_int dc_sp_nnz(const dc_int* sp) { return dc_sp_dense(sp) ? sp[0] * sp[1] : sp[2 + sp[1]]; }
/* Nonzeros of column c are [dc_sp_begin, dc_sp_end) of the value array; dc_sp_row gives their
 * rows. A dense pattern stores every entry, column-major. */
static inline dc_int dc_sp_begin(const dc_int* sp, dc_int c) { return dc_sp_dense(sp) ? c * sp[0] : sp[2 + c]; }
static inline dc_int dc_sp_end(const dc_int* sp, dc_int c) { return dc_sp_dense(sp) ? (c + 1) * sp[0] : sp[3 + c]; }
static inline dc_int dc_sp_row(const dc_int* sp, dc_int k) { return dc_sp_dense(sp) ? k % sp[0] : sp[3 + sp[1] + k]; }

/* Write (add == 0) or add (add != 0) the nonzeros nz of pattern sp into the column-major array
 * out with leading dimension ld (>= nrow); entries outside the pattern are left as they are. */
static inline void dc_sp_scatter(const dc_int* sp, const double* nz, double* out, dc_int ld, int add) {
  const dc_int nrow = sp[0], ncol = sp[1];
  if (dc_sp_dense(sp)) {
    for (dc_int c = 0; c < ncol; ++c)
      for (dc_int i = 0; i < nrow; ++i) {
        if (add) out[c * ld + i] += nz[c * nrow + i];
        else out[c * ld + i] = nz[c * nrow + i];
      }
    return;
  }
  const dc_int *colind = sp + 2, *row = sp + 3 + ncol;
  for (dc_int c = 0; c < ncol; ++c)
    for (dc_int k = colind[c]; k < colind[c + 1]; ++k) {
      if (add) out[c * ld + row[k]] += nz[k];
      else out[c * ld + row[k]] = nz[k];
    }
}

/* The index of the first entry of v[0..m) that is not finite, or -1 (the drivers' check of every
 * evaluated output: a NaN or inf is reported by name, never integrated). */
static inline int dc_first_nonfinite(const double* v, int m) {
  for (int i = 0; i < m; ++i)
    if (!isfinite(v[i])) return i;
  return -1;
}

/* The column-major index (c * ld + row) of an entry of out at a position of pattern sp that is
 * not finite, or -1: an array assembled from generated nonzeros is zero elsewhere, so checking
 * the patterns is checking it (a 32 x 32 Jacobian has about 100 of them). */
static inline dc_int dc_sp_first_nonfinite(const dc_int* sp, const double* out, dc_int ld) {
  for (dc_int c = 0; c < sp[1]; ++c)
    for (dc_int k = dc_sp_begin(sp, c); k < dc_sp_end(sp, c); ++k)
      if (!isfinite(out[c * ld + dc_sp_row(sp, k)])) return c * ld + dc_sp_row(sp, k);
  return -1;
}

/* post-processing functions (DAEFunctions.extras), evaluated point by point by dc_eval_extra */
extern const int dc_n_extras;
extern const dc_fun_t dc_extra_tab[];

/* the forward sensitivity functions' table, defined when the model is built with sensitivities */
#include "dc_sens.h"

#endif
