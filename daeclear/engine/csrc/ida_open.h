/*
 * ida_open.h -- session and options: dc_open, dc_reset, dc_free, the solver options, dc_reinit, the
 * sparse LU's lifetime and the first step of a run.
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_OPEN_H
#define DAECLEAR_IDA_OPEN_H

#include "ida_eval.h"

/* The first step of a run started at (y, yp): the step whose BDF1 local error in the positions,
 * h^2 / 2 * q'', has half the weighted tolerance IDA's error test allows, h = 1 / sqrt(|q''|_wrms),
 * q'' = v' the consistent accelerations; never below IDA's own estimate 0.5 / |yp|_wrms, never
 * above max_step. IDA's estimate is first order: a coordinate at zero moving fast, weighted by
 * its tiny absolute tolerance, makes it 1e-16 s on the chapter's scenes, and GGL's index-2
 * Newton iteration fails at such steps at rtol 1e-9 (the ideal four-bar, with the Jacobian
 * refreshed at a 5 % change of cj). Returns 0 (IDA's estimate) before dc_set_layout or without
 * accelerations. */
static double first_step(const dc_session* s, const double* y, const double* yp) {
  const double* atol = N_VGetArrayPointer(s->atol);
  double sum_a = 0.0, sum_yp = 0.0, h;
  if (!s->lay_ready) return 0.0;
  for (int i = 0; i < s->n; ++i) {
    const double w = 1.0 / (s->rtol * fabs(y[i]) + atol[i]);
    sum_yp += (w * yp[i]) * (w * yp[i]);
    if (i < s->lay_nq) sum_a += (w * yp[s->lay_nq + i]) * (w * yp[s->lay_nq + i]);
  }
  if (!(sum_a > 0.0) || !isfinite(sum_a) || !isfinite(sum_yp)) return 0.0;
  h = 1.0 / sqrt(sqrt(sum_a / s->n));
  if (sum_yp > 0.0) h = fmax(h, 0.5 / sqrt(sum_yp / s->n));
  return s->max_step > 0.0 ? fmin(h, s->max_step) : h;
}

/* ------------------------------------------------------------------ SuperLU_MT (linear_solver="superlu")
 * SUNDIALS' SuperLU_MT solver starts over whenever it is initialized: its next factorization
 * recomputes the column ordering and allocates new L and U storage without freeing the old
 * (measured on a chain of 8 links when IDA initialized it at every restart: resident memory grew by
 * 60 MB over 600 events, and each event paid a full symbolic factorization). Here it sits behind
 * the dc_linsol interface like every solver: IDA initializes only the wrapper (dc_linsol.h), this
 * solver is initialized once, and every factorization after the first takes SuperLU_MT's
 * refactorization path on the session's one pattern (the union of all parts). */
#if DC_HAVE_SPARSE
typedef struct {
  dc_session* s;
  SUNLinearSolver sl; /* SuperLU_MT, one thread */
  N_Vector v;         /* a vector without data of its own: the solve's x */
  int factored;       /* a Jacobian was handed to it */
} dcls_superlu;

static int superlu_factor(dc_linsol* ls, double* values) {
  dcls_superlu* c = (dcls_superlu*)ls->content;
  (void)values; /* the data of s->A, which SuperLU_MT reads itself */
  ONE_OMP_THREAD(); /* it factors on this thread */
  c->factored = 1;
  const int rc = SUNLinSolSetup(c->sl, c->s->A);
  return rc > 0 ? 1 : rc < 0 ? -1 : 0;
}

static void superlu_solve(dc_linsol* ls, double* x) {
  dcls_superlu* c = (dcls_superlu*)ls->content;
  N_VSetArrayPointer(x, c->v);
  SUNLinSolSolve(c->sl, c->s->A, c->v, c->v, 0.0);
}

/* SUNLinSolFree_SuperLUMT reads uninitialized options when the solver never factorized (a
 * session opened and closed without a step): factor an n x n identity first, so it has. */
static void superlu_destroy(dc_linsol* ls) {
  dcls_superlu* c = (dcls_superlu*)ls->content;
  if (c && c->sl && !c->factored) {
    const int n = ls->n;
    SUNMatrix I = SUNSparseMatrix(n, n, n, CSC_MAT, c->s->ctx);
    if (I) {
      sunindextype* cp = SUNSparseMatrix_IndexPointers(I);
      sunindextype* ri = SUNSparseMatrix_IndexValues(I);
      double* d = SUNSparseMatrix_Data(I);
      for (int i = 0; i < n; ++i) {
        cp[i] = i;
        ri[i] = i;
        d[i] = 1.0;
      }
      cp[n] = n;
      ONE_OMP_THREAD();
      SUNLinSolSetup(c->sl, I);
      SUNMatDestroy(I);
    } else {
      c->sl = NULL; /* without the identity, leave the solver allocated rather than crash */
    }
  }
  if (c) {
    if (c->sl) SUNLinSolFree(c->sl);
    if (c->v) N_VDestroy(c->v);
    free(c);
  }
  free(ls);
}

/* SuperLU_MT on s->A (a SUNSparseMatrix of the union pattern), initialized once; NULL on failure. */
static dc_linsol* superlu_create(dc_session* s) {
  dcls_superlu* c = (dcls_superlu*)calloc(1, sizeof(dcls_superlu));
  dc_linsol* ls = c ? dcls_new(DC_LS_SUPERLU, s->nj, c, superlu_factor, superlu_solve, superlu_destroy) : NULL;
  if (!ls) {
    free(c);
    return NULL;
  }
  c->s = s;
  c->v = N_VMake_Serial(s->nj, N_VGetArrayPointer(s->yy), s->ctx);
  c->sl = c->v ? SUNLinSol_SuperLUMT(s->yy, s->A, 1, s->ctx) : NULL;
  if (!c->sl || SUNLinSolInitialize(c->sl) != 0) {
    if (c->sl) c->factored = 1; /* never factor the identity into a solver that did not initialize */
    superlu_destroy(ls);
    return NULL;
  }
  return ls;
}
#endif

static void release_funs(dc_session* s) {
  const dc_model_t* M = &dc_model;
  if (s->mem_res >= 0) M->res.release(s->mem_res);
  if (s->mem_jac >= 0) M->jac.release(s->mem_jac);
  if (M->n_roots > 0 && s->mem_roots >= 0) M->roots.release(s->mem_roots);
  for (int k = 0; k < M->n_terms; ++k) {
    if (s->mem_term_res && s->mem_term_res[k] >= 0) M->term_res[k].release(s->mem_term_res[k]);
    if (s->mem_term_jac && s->mem_term_jac[k] >= 0) M->term_jac[k].release(s->mem_term_jac[k]);
  }
  M->res.decref();
  M->jac.decref();
  if (M->n_roots > 0) M->roots.decref();
  for (int k = 0; k < M->n_terms; ++k) {
    M->term_res[k].decref();
    M->term_jac[k].decref();
  }
}

DC_API void dc_free(void* sp) {
  dc_session* s = (dc_session*)sp;
  if (!s) return;
  if (s->ida) IDAFree(&s->ida);
  nls_release(s); /* IDA does not own the Newton wrapper (ida_newton.h) */
  if (s->LS) SUNLinSolFree(s->LS);
  dcls_free(s->lin);
  if (s->A) SUNMatDestroy(s->A);
  if (s->yy) N_VDestroy(s->yy);
  if (s->yp) N_VDestroy(s->yp);
  if (s->atol) N_VDestroy(s->atol);
  if (s->dky) N_VDestroy(s->dky);
  if (s->ctx) SUNContext_Free(&s->ctx);
  if (s->arg) release_funs(s);
  free(s->arg);
  free(s->res);
  free(s->iw);
  free(s->w);
  free(s->mem_term_res);
  free(s->mem_term_jac);
  free(s->cpl_y);
  free(s->cpl_yp);
  free(s->cpl_out);
  free(s->cpl_tmp);
  free(s->active);
  free(s->params);
  free(s->param_off);
  free(s->rootdir_default);
  free(s->rootdir);
  free(s->rootsfound);
  free(s->tmp_r);
  free(s->tmp_J);
  free(s->jp_colptr);
  free(s->jp_rowind);
  free(s->jmap);
  free(s->jmap_off);
  free(s->P);
  free(s->auto_root);
  free(s->auto_term);
  free(s->auto_rate);
  free(s->auto_needs);
  free(s->root_to_auto);
  free(s->pair_rule);
  free(s->pair_state);
  free(s->recent);
  free(s->ev_t);
  free(s->ev_pair);
  free(s->ev_info);
  free(s->ev_rate);
  free(s->ev_latched);
  free(s->ev_y);
  free(s->lay_buf);
  free(s->lay_on);
  free(s->xarg);
  free(s->xres);
  free(s->xiw);
  free(s->xw);
  free(s->xnz);
  free(s);
}

/* IDA's own step cap: in one-step mode it never binds; the session's cap (max_steps) is ours. */
static long ida_max_steps(long long max_steps) {
  return 0 < max_steps && max_steps < 2000000000LL ? (long)max_steps : 2000000000L;
}

/* Every field a run changes, at its value before the run's first dc_reinit: what dc_open leaves
 * and dc_reset restores (one list for both). The arrays are allocated. */
static void clear_run_state(dc_session* s) {
  int np = 0;
  for (int k = 0; k < s->n_terms; ++k) {
    s->active[k] = 0;
    np += dc_model.n_params[k];
  }
  if (np > 0) memset(s->params, 0, sizeof(double) * (size_t)np);
  for (int i = 0; i < s->n_roots; ++i) s->rootdir[i] = s->rootsfound[i] = 0;
  memset(s->base, 0, sizeof s->base);
  if (s->lin) s->lin->n_fallback = 0;
  s->t_now = s->t_rec = 0.0;
  s->carry = s->carry_flag = s->carry_order = 0;
  s->carry_lo = s->carry_t_prev = s->carry_h = 0.0;
  s->carry_nst = s->carry_nst_prev = 0;
  s->ready = 0;
  s->tiny = 0;
  s->h_prev = 0.0;
  s->stall_step = 0.0;
  s->stall_count = DC_TINY_MAX;
  s->first_step_on = 0;
  s->n_auto = 0; /* dc_set_auto and dc_set_layout (re)allocate what they configure */
  s->ev_n = 0;
  s->lay_ready = 0;
  s->proj_on = 0;
}

/* The failure exit of dc_open's steps: the message to err, -1 to dc_open (which frees the session). */
#define OPEN_FAIL(...)                                           \
  do {                                                           \
    if (err && errlen > 0) snprintf(err, errlen, __VA_ARGS__);   \
    return -1;                                                   \
  } while (0)

/* CasADi work memory, sized for the largest function; the functions checked out. */
static int open_work_memory(dc_session* s, char* err, int errlen) {
  const dc_model_t* M = &dc_model;
  dc_int sa = 6, sr = 1, si = 0, sw = 0;
  work_max(&M->res, &sa, &sr, &si, &sw);
  work_max(&M->jac, &sa, &sr, &si, &sw);
  if (M->n_roots > 0) work_max(&M->roots, &sa, &sr, &si, &sw);
  for (int k = 0; k < M->n_terms; ++k) {
    work_max(&M->term_res[k], &sa, &sr, &si, &sw);
    work_max(&M->term_jac[k], &sa, &sr, &si, &sw);
  }
  if (M->cpl.eval) {
    work_max(&M->cpl, &sa, &sr, &si, &sw);
    for (int k = 0; k < M->n_terms; ++k) work_max(&M->term_cpl[k], &sa, &sr, &si, &sw);
  }
  s->arg = (const double**)xcalloc((size_t)sa, sizeof(double*));
  s->res = (double**)xcalloc((size_t)sr, sizeof(double*));
  s->iw = (dc_int*)xcalloc((size_t)si, sizeof(dc_int));
  s->w = (double*)xcalloc((size_t)sw, sizeof(double));
  s->mem_term_res = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
  s->mem_term_jac = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
  if (!s->arg || !s->res || !s->iw || !s->w || !s->mem_term_res || !s->mem_term_jac)
    OPEN_FAIL("out of memory");
  for (int k = 0; k < M->n_terms; ++k) s->mem_term_res[k] = s->mem_term_jac[k] = -1;
  M->res.incref();
  M->jac.incref();
  if (M->n_roots > 0) M->roots.incref();
  for (int k = 0; k < M->n_terms; ++k) {
    M->term_res[k].incref();
    M->term_jac[k].incref();
  }
  s->mem_res = M->res.checkout();
  s->mem_jac = M->jac.checkout();
  if (M->n_roots > 0) s->mem_roots = M->roots.checkout();
  for (int k = 0; k < M->n_terms; ++k) {
    s->mem_term_res[k] = M->term_res[k].checkout();
    s->mem_term_jac[k] = M->term_jac[k].checkout();
  }
  return 0;
}

/* The per-segment arrays (active terms, their parameters, root directions, scratch), the
 * run-time parameters P and the default root directions. */
static int open_run_arrays(dc_session* s, const int* rootdir, const double* P, char* err, int errlen) {
  const dc_model_t* M = &dc_model;
  int np = 0;
  s->param_off = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
  s->active = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
  if (!s->param_off || !s->active) OPEN_FAIL("out of memory");
  for (int k = 0; k < M->n_terms; ++k) {
    s->param_off[k] = np;
    np += M->n_params[k];
  }
  s->params = (double*)xcalloc((size_t)np, sizeof(double));
  s->rootdir_default = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
  s->rootdir = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
  s->rootsfound = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
  s->tmp_r = (double*)xcalloc((size_t)M->n, sizeof(double));
  dc_int nnz = nnz_of(&M->jac);
  for (int k = 0; k < M->n_terms; ++k)
    if (nnz_of(&M->term_jac[k]) > nnz) nnz = nnz_of(&M->term_jac[k]);
  s->tmp_J = (double*)xcalloc((size_t)nnz, sizeof(double));
  s->P = (double*)xcalloc((size_t)M->n_parameters, sizeof(double));
  if (!s->params || !s->rootdir_default || !s->rootdir || !s->rootsfound || !s->tmp_r ||
      !s->tmp_J || !s->P)
    OPEN_FAIL("out of memory");
  clear_run_state(s);
  if (M->n_parameters > 0) {
    if (!P) OPEN_FAIL("the model has %d run-time parameters and none were given", M->n_parameters);
    memcpy(s->P, P, sizeof(double) * (size_t)M->n_parameters);
  }
  for (int i = 0; i < M->n_roots; ++i) s->rootdir_default[i] = rootdir ? rootdir[i] : 0;
  return 0;
}

/* The Jacobian pattern (always built: small, and dc_eval_jacobian_sparse works in any session),
 * the choice of linear solver, the SUNDIALS context with our error handler, and the vectors. */
static int open_vectors(dc_session* s, const double* atol, int linear_solver, char* err, int errlen) {
  const int n = s->nj;
  int rc = build_jac_pattern(s);
  if (rc == -1) OPEN_FAIL("out of memory");
  if (rc == -2) OPEN_FAIL("a generated Jacobian is not %d x %d", n, n);
  if (rc == -3) OPEN_FAIL("the Jacobian has too many nonzeros for the wheel's 32-bit sunindextype");
  if (linear_solver != DC_LS_DENSE && linear_solver != DC_LS_SPARSE && linear_solver != DC_LS_REDUCED &&
      linear_solver != DC_LS_SUPERLU)
    OPEN_FAIL("unknown linear solver %d (%d: dense, %d: sparse, %d: reduced, %d: superlu)", linear_solver,
              DC_LS_DENSE, DC_LS_SPARSE, DC_LS_REDUCED, DC_LS_SUPERLU);
  if (linear_solver == DC_LS_SUPERLU && !DC_HAVE_SPARSE)
    OPEN_FAIL("this library was built without SuperLU_MT (the wheel lacks "
              "libsundials_sunmatrixsparse or libsundials_sunlinsolsuperlumt)");
  if (linear_solver == DC_LS_SPARSE) {
    const dc_lu_plan* plan = dc_model.lu;
    if (!plan) OPEN_FAIL("the model has no sparse LU plan (a multiplier's pivot stays structurally zero)");
    int same = plan->n == n && plan->nnz == (int)s->jp_nnz;
    for (int c = 0; same && c <= n; ++c) same = plan->colptr[c] == (int)s->jp_colptr[c];
    for (dc_int k = 0; same && k < s->jp_nnz; ++k) same = plan->rowind[k] == (int)s->jp_rowind[k];
    if (!same) OPEN_FAIL("the sparse LU plan was made for another Jacobian pattern than the library's");
  }
  s->lin_kind = linear_solver;

  if (SUNContext_Create(SUN_COMM_NULL, &s->ctx) != 0 || !s->ctx)
    OPEN_FAIL("SUNContext_Create failed");
  SUNContext_ClearErrHandlers(s->ctx); /* IDA must not print; we build our own messages */
  SUNContext_PushErrHandler(s->ctx, err_handler, s);
  s->yy = N_VNew_Serial(s->n, s->ctx);
  s->yp = N_VNew_Serial(s->n, s->ctx);
  s->atol = N_VNew_Serial(s->n, s->ctx);
  s->dky = N_VNew_Serial(s->n, s->ctx);
  if (!s->yy || !s->yp || !s->atol || !s->dky) OPEN_FAIL("N_VNew_Serial failed");
  /* IDA clones its vectors from yy: with fused operations its predictor, corrector and error
   * norms make one pass (N_VLinearCombination, ...) instead of one call per term */
  if (N_VEnableFusedOps_Serial(s->yy, SUNTRUE) != SUN_SUCCESS) OPEN_FAIL("N_VEnableFusedOps_Serial failed");
  memset(N_VGetArrayPointer(s->yy), 0, sizeof(double) * (size_t)s->n);
  memset(N_VGetArrayPointer(s->yp), 0, sizeof(double) * (size_t)s->n);
  memcpy(N_VGetArrayPointer(s->atol), atol, sizeof(double) * (size_t)s->n);
  return 0;
}

/* IDA's matrix and the linear solver behind the dc_linsol interface (dc_linsol.h): the sparse LU on
 * the union values, SuperLU_MT on a SUNSparseMatrix of the union pattern (one thread), else a dense
 * matrix with the reduced or the plain dense LU. */
static int open_linear_solver(dc_session* s, char* err, int errlen) {
  const int n = s->nj; /* the iteration matrix's size: blocks of them make the Newton matrix */
  if (s->lin_kind == DC_LS_SPARSE) {
    s->A = dcls_values_create((size_t)s->jp_nnz, s->ctx);
    if (!s->A) OPEN_FAIL("the sparse LU's matrix could not be allocated (nnz=%lld)", (long long)s->jp_nnz);
    s->lin = dcls_sparse_create(DC_LS_SPARSE, dc_model.lu);
  } else if (s->lin_kind == DC_LS_SUPERLU) {
#if DC_HAVE_SPARSE
    /* one thread: the factorizations are small and the machine is shared; more threads cost
     * more in OpenMP start-up than they save */
    s->A = SUNSparseMatrix(n, n, s->jp_nnz > 0 ? (sunindextype)s->jp_nnz : 1, CSC_MAT, s->ctx);
    if (!s->A) OPEN_FAIL("SUNSparseMatrix(%d, %d, nnz=%lld) failed", n, n, (long long)s->jp_nnz);
    (void)jac_storage(s, s->A); /* a valid pattern from the start */
    s->lin = superlu_create(s);
    if (!s->lin)
      OPEN_FAIL("the SuperLU_MT solver of this SUNDIALS build could not be created or initialized; "
                "use linear_solver='sparse'");
#endif
  } else {
    s->A = SUNDenseMatrix(n, n, s->ctx);
    if (!s->A) OPEN_FAIL("SUNDenseMatrix failed");
    s->lin = s->lin_kind == DC_LS_REDUCED ? rls_create(DC_LS_REDUCED, n) : dcls_dense_create(DC_LS_DENSE, n);
  }
  if (!s->lin) OPEN_FAIL("the linear solver could not be created (out of memory)");
  s->LS = dcls_sun_create(s->lin, jac_storage(s, s->A), s->blocks, s->ctx);
  if (!s->LS) OPEN_FAIL("the linear solver could not be created (out of memory)");
  if (s->blocks > 1 && dc_model.cpl.eval) {
    const size_t m = (size_t)(s->n - s->nj);
    s->cpl_y = (double*)xcalloc((size_t)s->n, sizeof(double));
    s->cpl_yp = (double*)xcalloc((size_t)s->n, sizeof(double));
    s->cpl_out = (double*)xcalloc(m, sizeof(double));
    s->cpl_tmp = (double*)xcalloc(m, sizeof(double));
    if (!s->cpl_y || !s->cpl_yp || !s->cpl_out || !s->cpl_tmp) OPEN_FAIL("out of memory");
    s->coupled = 1;
    dcls_sun_set_coupling(s->LS, couple_cb, s);
  }
  return 0;
}

/* IDA's memory, initialized at the zero state, with the tolerances, options and root functions. */
static int open_ida(dc_session* s, double rtol, double max_step, int max_order, long long max_steps,
                    char* err, int errlen) {
  const dc_model_t* M = &dc_model;
  int flag;
  s->ida = IDACreate(s->ctx);
  if (!s->ida) OPEN_FAIL("IDACreate failed");
#define CHECK(call)                                                                  \
  do {                                                                               \
    flag = (call);                                                                   \
    if (flag < 0) OPEN_FAIL("%s failed with flag %d: %s", #call, flag, s->ida_msg); \
  } while (0)
  CHECK(IDAInit(s->ida, res_cb, 0.0, s->yy, s->yp));
  CHECK(IDASetUserData(s->ida, s));
  CHECK(IDASVtolerances(s->ida, rtol, s->atol));
  CHECK(IDASetLinearSolver(s->ida, s->LS, s->A));
  CHECK(IDASetJacFn(s->ida, jac_cb));
  CHECK(IDASetMaxOrd(s->ida, max_order));
  CHECK(IDASetMaxStep(s->ida, max_step));
  CHECK(IDASetMaxNumSteps(s->ida, ida_max_steps(max_steps)));
  if (M->n_roots > 0) {
    CHECK(IDARootInit(s->ida, M->n_roots, root_cb));
    CHECK(IDASetRootDirection(s->ida, s->rootdir_default));
    CHECK(IDASetNoInactiveRootWarn(s->ida));
  }
#undef CHECK
  return 0;
}
#undef OPEN_FAIL

/* Open a session: IDA memory, linear solver (DC_LS_DENSE: dense LU; DC_LS_SPARSE: the sparse LU on
 * the model's plan; DC_LS_REDUCED: dense LU of the reduced system; DC_LS_SUPERLU: SuperLU_MT on the
 * union pattern, one thread), tolerances, options and root functions. IDAInit is called here with a zero state; dc_reinit then
 * (re)starts with IDAReInit. Returns NULL on failure with a message in err. */
DC_API void* dc_open(double rtol, const double* atol, double max_step, int max_order,
                     long long max_steps, const int* rootdir, const double* P, int linear_solver,
                     char* err, int errlen) {
  const dc_model_t* M = &dc_model;
  dc_session* s = (dc_session*)calloc(1, sizeof(dc_session));
  if (!s) {
    if (err && errlen > 0) snprintf(err, errlen, "out of memory");
    return NULL;
  }
  s->n = M->n;
  s->nj = (int)M->jac.sparsity_out(0)[0];
  s->blocks = s->nj > 0 && M->n % s->nj == 0 ? M->n / s->nj : 0;
  if (s->blocks < 1) {
    if (err && errlen > 0) snprintf(err, errlen, "the generated Jacobian has %d rows, must divide n=%d", s->nj, M->n);
    free(s);
    return NULL;
  }
  s->n_terms = M->n_terms;
  s->n_roots = M->n_roots;
  s->max_steps = max_steps;
  s->rtol = rtol;
  s->max_step = max_step;
  s->mem_res = s->mem_jac = s->mem_roots = -1;
  if (open_work_memory(s, err, errlen) != 0 || open_run_arrays(s, rootdir, P, err, errlen) != 0 ||
      open_vectors(s, atol, linear_solver, err, errlen) != 0 || open_linear_solver(s, err, errlen) != 0 ||
      open_ida(s, rtol, max_step, max_order, max_steps, err, errlen) != 0) {
    dc_free(s);
    return NULL;
  }
  return s;
}

/* IDA's default Newton convergence coefficient (EPCON of ida.c), restored by dc_reset. */
#define DC_IDA_EPCON 0.33

/* Re-arm the session of a finished run for another run of the same library, as dc_open would
 * open it with these settings: tolerances, step limits, default root directions and run-time
 * parameters are set, every field a run changes goes back to its value after dc_open, and the
 * IDA options a run may set (dc_set_nonlin_conv_coef, dc_set_jacobian_refresh) back to IDA's
 * defaults. Kept: what depends on the library, the linear solver and max_order alone (IDA
 * memory, vectors, matrix, linear solver, Jacobian pattern, CasADi work memory), so a reset
 * session runs step for step as a new one. dc_reinit starts it. Returns 0, or an IDA flag < 0
 * with a message (dc_message); the session is then unusable (free it). */
DC_API int dc_reset(void* sp, double rtol, const double* atol, double max_step, long long max_steps,
                    const int* rootdir, const double* P) {
  dc_session* s = (dc_session*)sp;
  const dc_model_t* M = &dc_model;
  int flag;
  s->msg[0] = s->cb_msg[0] = s->ida_msg[0] = 0;
  if (M->n_parameters > 0) {
    if (!P) {
      set_msg(s->msg, "the model has %d run-time parameters and none were given", M->n_parameters);
      return -1;
    }
    memcpy(s->P, P, sizeof(double) * (size_t)M->n_parameters);
  }
  s->rtol = rtol;
  s->max_step = max_step;
  s->max_steps = max_steps;
  for (int i = 0; i < s->n_roots; ++i) s->rootdir_default[i] = rootdir ? rootdir[i] : 0;
  clear_run_state(s);
  s->nls_on = 0; /* IDA's own weights in the Newton test (dc_set_newton_atol) */
  memcpy(N_VGetArrayPointer(s->atol), atol, sizeof(double) * (size_t)s->n);
  flag = IDASVtolerances(s->ida, rtol, s->atol);
  if (flag >= 0) flag = IDASetMaxStep(s->ida, max_step);
  if (flag >= 0) flag = IDASetMaxNumSteps(s->ida, ida_max_steps(max_steps));
  if (flag >= 0) flag = IDAClearStopTime(s->ida); /* dc_advance sets it */
  if (flag >= 0) flag = IDASetNonlinConvCoef(s->ida, DC_IDA_EPCON);
  if (flag >= 0) flag = IDASetDeltaCjLSetup(s->ida, -1.0); /* out of [0, 1): IDA's default */
  if (flag >= 0 && s->n_roots > 0) flag = IDASetRootDirection(s->ida, s->rootdir_default);
  if (flag < 0) set_msg(s->msg, "resetting the session failed with flag %d: %s", flag, s->ida_msg);
  return flag < 0 ? flag : 0;
}

/* Solver hints applied from the next step or restart on: the safety factor of IDA's
 * Newton convergence test (default 0.33; smaller solves the algebraic equations tighter). */
DC_API int dc_set_nonlin_conv_coef(void* sp, double coef) {
  return IDASetNonlinConvCoef(((dc_session*)sp)->ida, coef);
}

/* The relative change of cj (IDA's coefficient of yp in the iteration matrix) from which IDA
 * evaluates a new Jacobian (IDA's default 0.25). */
DC_API int dc_set_jacobian_refresh(void* sp, double dcj) {
  return IDASetDeltaCjLSetup(((dc_session*)sp)->ida, dcj);
}

/* Stall detection: steps below stall_step seconds (0: only the relative collapse test) that do
 * not grow; count of them that ends the advance. */
DC_API int dc_set_stall(void* sp, double stall_step, int count) {
  dc_session* s = (dc_session*)sp;
  if (!(stall_step >= 0.0) || count < 1) return -1;
  s->stall_step = stall_step;
  s->stall_count = count;
  return 0;
}

/* 1: the run's first start takes first_step() (restarts after contact switches keep IDA's own
 * estimate: a longer first step after a switch lets the error grow at a given rtol); 0: IDA's. */
DC_API int dc_set_first_step(void* sp, int on) {
  ((dc_session*)sp)->first_step_on = on != 0;
  return 0;
}

/* The reduced solver's eliminated kinematic rows (the q rows, 0 <= nk < nj) without a state layout:
 * a session on the stacked sensitivities [y; S] factors the state's iteration matrix as the state's
 * own run does (dc_set_layout sets them there). 0 done (also for another solver: nothing to do),
 * -1 out of range or out of memory. */
DC_API int dc_set_kinematic_rows(void* sp, int nk) {
  dc_session* s = (dc_session*)sp;
  if (s->lin_kind != DC_LS_REDUCED) return 0;
  return nk >= 0 && nk < s->nj && rls_set_kinematic_rows(s->lin, nk) == 0 ? 0 : -1;
}

/* (Re)start IDA at (t0, y0, yp0) with fresh BDF history; set active terms, their parameters
 * (concatenated) and the root directions (NULL: the directions given to dc_open). */
DC_API int dc_reinit(void* sp, double t0, const double* y0, const double* yp0,
                     const int* active, const double* params, const int* rootdir) {
  dc_session* s = (dc_session*)sp;
  long long cur[DC_ST_N];
  int flag, np = 0;
  s->msg[0] = 0;
  if (s->ready) {
    ida_counters(s, cur);
    for (int i = 0; i < DC_ST_N; ++i) s->base[i] += cur[i];
  }
  memcpy(N_VGetArrayPointer(s->yy), y0, sizeof(double) * (size_t)s->n);
  memcpy(N_VGetArrayPointer(s->yp), yp0, sizeof(double) * (size_t)s->n);
  flag = IDASetInitStep(s->ida, s->ready || !s->first_step_on ? 0.0 : first_step(s, y0, yp0));
  if (flag >= 0) flag = IDAReInit(s->ida, t0, s->yy, s->yp);
  if (flag < 0) {
    s->ready = 0;
    set_msg(s->msg, "IDAReInit failed with flag %d: %s", flag, s->ida_msg);
    return flag;
  }
  for (int k = 0; k < s->n_terms; ++k) {
    s->active[k] = active ? (active[k] != 0) : 0;
    np += dc_model.n_params[k];
  }
  if (np > 0 && params) memcpy(s->params, params, sizeof(double) * (size_t)np);
  if (s->n_roots > 0) {
    for (int i = 0; i < s->n_roots; ++i)
      s->rootdir[i] = rootdir ? rootdir[i] : s->rootdir_default[i];
    flag = IDASetRootDirection(s->ida, s->rootdir);
    if (flag < 0) {
      s->ready = 0;
      set_msg(s->msg, "IDASetRootDirection failed with flag %d: %s", flag, s->ida_msg);
      return flag;
    }
  }
  s->t_now = t0;
  s->t_rec = t0;
  s->carry = 0;
  s->tiny = 0;
  s->h_prev = 0.0;
  s->ready = 1;
  s->base[DC_ST_REINITS] += 1;
  return 0;
}

#endif
