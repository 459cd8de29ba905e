/*
 * dc_model.h -- the table that daeclear's code generator appends to the CasADi-generated
 * model source, and that the IDA driver (ida_driver.c) reads.
 *
 * The generated functions use casadi_real = double and casadi_int = long long int (set
 * explicitly by daeclear.codegen), so the pointer types below match them exactly.
 */
#ifndef DAECLEAR_DC_MODEL_H
#define DAECLEAR_DC_MODEL_H

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
  const char* name;
} dc_model_t;

extern const dc_model_t dc_model;

/* post-processing functions (DAEFunctions.extras), evaluated point by point by dc_eval_extra */
extern const int dc_n_extras;
extern const dc_fun_t dc_extra_tab[];

#endif
