/*
 * ida_driver.c -- daeclear's compiled integrator loop.
 *
 * Compiled together with a CasADi-generated model (see daeclear/codegen.py) into one shared
 * library that links the SUNDIALS libraries of the scikit-sundae wheel. Python drives it with
 * ctypes a few calls per integration segment; every residual, Jacobian and root evaluation,
 * every IDA step, the recording of steps and the dense output at requested times happen here,
 * with no Python in the loop.
 *
 * The residual is the base residual plus the active switchable terms (contact forces); an
 * inactive term is never evaluated. The Jacobian is the base Jacobian plus the active terms'
 * Jacobians: the generated functions return their nonzeros (CasADi's compressed column
 * storage), scattered here either into SUNDIALS' dense column-major matrix (dense LU) or into a
 * SUNSparseMatrix whose fixed pattern is the union of all those patterns (SuperLU_MT), chosen
 * per session by dc_open. The union is fixed so that switching contact terms on and off never
 * changes the structure the sparse LU was ordered for (inactive terms leave explicit zeros).
 *
 * Every generated function takes the model's run-time parameters P (masses, joint points,
 * clearances, law constants, ...) as its last input: one compiled library serves every
 * scene of the same structure; the numbers arrive with dc_open.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The SUNDIALS 7.9.0 headers vendored in csrc/sundials/include (see its README): the wheel's
 * libsundials_ida is IDA, declared here by IDAS' header of the same release, whose IDA* API is
 * IDA's with sensitivity functions added (same names, signatures and constants); the link uses
 * -z defs, so a function the IDA library lacks fails the build. sundials_config.h #errors when
 * codegen's -DDC_SUNDIALS_MAJOR/_MINOR/_PATCH or -DDC_INDEX_SIZE disagree with the headers. */
#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_core.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include "dc_model.h"
#include "dc_linalg.h"
#include "dc_reduced_ls.h"

#define DC_API __attribute__((visibility("default")))

#ifndef DC_ABI_VERSION /* given by daeclear.codegen (DRIVER_ABI) */
#error "compile with -DDC_ABI_VERSION=<daeclear.codegen.DRIVER_ABI>"
#endif
#ifndef DC_HAVE_SPARSE /* 1 when the wheel's sparse matrix and SuperLU_MT libraries are linked */
#define DC_HAVE_SPARSE 0
#endif
#if !defined(DC_SUNDIALS_MAJOR) || !defined(DC_INDEX_SIZE) /* given by daeclear.codegen */
#error "compile with -DDC_SUNDIALS_MAJOR/_MINOR/_PATCH and -DDC_INDEX_SIZE as daeclear.codegen does"
#endif
_Static_assert(8 * sizeof(sunindextype) == DC_INDEX_SIZE, "sunindextype is not DC_INDEX_SIZE bits wide");
_Static_assert(sizeof(sunrealtype) == sizeof(double), "sunrealtype is not double");

#if DC_HAVE_SPARSE
/* SuperLU_MT's SUNDIALS header (sunlinsol/sunlinsol_superlumt.h) includes SuperLU_MT's own
 * headers for the solver's content structure, and neither wheel that ships SUNDIALS 7.9.0
 * (scikit-sundae: no headers; sundials4py: no SuperLU_MT) has them; this constructor is the one
 * function of it the driver calls, declared as in that header (unchanged in SUNDIALS 7.0-7.6,
 * and as scikit-sundae 1.2.0 declares it for the 7.9.0 libraries). Every other operation goes
 * through the generic SUNLinearSolver API of the vendored headers. */
SUNDIALS_EXPORT SUNLinearSolver SUNLinSol_SuperLUMT(N_Vector y, SUNMatrix A, int num_threads,
                                                    SUNContext sunctx);
#endif

/* linear solvers of dc_open */
#define DC_LS_DENSE 0   /* SUNDIALS' dense LU of the whole iteration matrix */
#define DC_LS_SPARSE 1  /* SuperLU_MT */
#define DC_LS_REDUCED 2 /* dense LU of the reduced system, dc_reduced_ls.h */
#define LIN_SPARSE(s) ((s)->lin_kind == DC_LS_SPARSE) /* IDA's matrix is sparse (CSC), else dense */

#if DC_HAVE_SPARSE && defined(DC_SUPERLUMT_OMP)
/* SuperLU_MT factors inside an OpenMP parallel loop over its num_threads (1 here) without a
 * num_threads clause, so libgomp starts a team of omp_get_max_threads() threads, one per core;
 * the idle ones spin at the barrier (measured: a third of the run time at 48 states). The team
 * size is a per-thread setting of the wheel's libgomp, set before each factorization. */
void omp_set_num_threads(int n);
#define ONE_OMP_THREAD() omp_set_num_threads(1)
#else
#define ONE_OMP_THREAD() ((void)0)
#endif

/* dc_advance store_steps flags: step times, sizes and orders; also the states y and yp */
#define DC_STORE_TIMES 1
#define DC_STORE_STATES 2

/* dc_advance return codes */
#define DC_CHUNK 0          /* buffer full: call again */
#define DC_TSTOP 1          /* reached t_stop */
#define DC_ROOT 2           /* a root was found */
#define DC_ERR_IDA (-1)     /* IDA returned an error flag */
#define DC_ERR_MAXSTEPS (-2) /* session step cap reached */
#define DC_ERR_COLLAPSE (-3) /* step size collapsed */
#define DC_ERR_USAGE (-4)   /* called in a wrong state / bad arguments */

/* statistics slots (dc_stats) */
enum {
  ST_STEPS, ST_RES, ST_JAC, ST_LSETUP, ST_NNI, ST_NCF, ST_NETF, ST_GEVALS, ST_REINITS, ST_N
};

/* A step is "tiny" when |h| < DC_TINY_REL * max(1, |t|). DC_TINY_MAX tiny steps that did not
 * grow (|h| <= DC_TINY_GROWTH * previous |h|), with no normal step in between, are a collapse of
 * the step size: the loop stops instead of creeping on forever. Tiny steps that keep growing
 * are IDA's start-up doubling after a tiny initial step (0.5 / ||y'||_wrms) and do not count. */
/* The numbers are daeclear.engine.stall_guard's, given as -D defines by the build (one home). */
#if !defined(DC_TINY_REL) || !defined(DC_TINY_MAX) || !defined(DC_TINY_GROWTH) || !defined(DC_NORMAL_STEP_FACTOR)
#error "build with daeclear.engine.stall_guard.c_defines(): -DDC_TINY_REL=... -DDC_TINY_MAX=... -DDC_TINY_GROWTH=... -DDC_NORMAL_STEP_FACTOR=..."
#endif

#define MSG_LEN 1024

/* ------------------------------------------------------------------ contact-mode automaton
 * The C mirror of daeclear/automaton.py (step): the decision of one contact pair at a root of
 * its gap. Keep the two identical, branch for branch; tests/test_automaton.py drives both
 * with the same random root sequences through dc_automaton_run. */
#define DC_NONE 0
#define DC_ONSET 1
#define DC_SEPARATION (-1)
/* two crossings of one pair closer than this, relative to t, are one instant (automaton.SAME_INSTANT) */
#define DC_SAME_INSTANT (16 * DBL_EPSILON)

typedef struct {
  int storm_events;    /* this many switches within storm_window s hold the term on (>= 1) */
  double storm_window;
  double vmin;         /* floor of the latched approach speed */
} dc_pair_rule;

typedef struct {
  int contact, held;
  double free_since;   /* start of the current flight of a held pair */
  double latched;      /* approach speed latched at the last onset (floored) */
  int n_recent;        /* entries of recent, <= storm_events */
  double* recent;      /* [storm_events] times of the last switches, oldest first */
} dc_pair_state;

typedef struct {
  int kind;            /* DC_ONSET, DC_SEPARATION or DC_NONE (nothing changes) */
  int contact, held;   /* the new mode; the term is on while contact || held */
  int watch;           /* root direction to watch next */
  double latched;
} dc_decision;

static double floor_speed(double rate, double vmin) { return rate > vmin ? rate : vmin; }

static int pair_watch(const dc_pair_state* st) { return st->held ? 0 : st->contact ? -1 : 1; }

static dc_decision decision_of(const dc_pair_state* st, int kind) {
  dc_decision d = {kind, st->contact, st->held, pair_watch(st), st->latched};
  return d;
}

/* keep the last storm_events switch times */
static void pair_push(const dc_pair_rule* r, dc_pair_state* st, double t) {
  if (st->n_recent < r->storm_events) {
    st->recent[st->n_recent++] = t;
  } else {
    memmove(st->recent, st->recent + 1, sizeof(double) * (size_t)(r->storm_events - 1));
    st->recent[r->storm_events - 1] = t;
  }
}

/* Decide a root at time t (non-decreasing per pair) crossed in direction dir (+1, -1, 0) with
 * penetration rate `rate`; update the state and return the decision. */
static dc_decision pair_step(const dc_pair_rule* r, dc_pair_state* st, double t, int dir,
                             double rate) {
  if (dir != 0 && st->held) {
    if (dir < 0) {
      st->free_since = t; /* the held pair's flight starts again */
      dir = 0;
    } else if (t - st->free_since <= r->storm_window) {
      dir = 0; /* a re-contact inside the storm: the held term stays as it is */
    } else {
      st->held = 0; /* a genuine onset after a real flight */
    }
  }
  if (dir > 0 && !st->contact) {
    st->contact = 1;
    st->latched = floor_speed(rate, r->vmin);
    pair_push(r, st, t);
    return decision_of(st, DC_ONSET);
  }
  if (dir < 0 && st->contact && rate > 0 && st->n_recent > 0 &&
      t - st->recent[st->n_recent - 1] <= fabs(t) * DC_SAME_INSTANT)
    return decision_of(st, DC_NONE); /* the restart's round-off, not a separation */
  if (dir < 0 && st->contact) {
    int count = 1;
    for (int i = 0; i < st->n_recent; ++i)
      if (t - st->recent[i] < r->storm_window) ++count;
    int hold = count >= r->storm_events;
    st->contact = 0;
    st->held = hold;
    if (hold) st->free_since = t;
    pair_push(r, st, t);
    return decision_of(st, DC_SEPARATION);
  }
  return decision_of(st, DC_NONE);
}

typedef struct {
  SUNContext ctx;
  void* ida;
  N_Vector yy, yp, atol, dky;
  SUNMatrix A;
  SUNLinearSolver LS;
  int n, n_terms, n_roots;
  /* CasADi work memory, sized for the largest function */
  const double** arg;
  double** res;
  dc_int* iw;
  double* w;
  int mem_res, mem_jac, mem_roots;
  int* mem_term_res;
  int* mem_term_jac;
  /* per-segment state */
  int* active;
  double* params;
  int* param_off;
  int* rootdir_default;
  int* rootdir;
  int* rootsfound;
  double* tmp_r;   /* n   */
  double* tmp_J;   /* nonzeros of the largest Jacobian */
  /* Jacobian pattern shared by all parts (0: base Jacobian, 1 + k: term k's): the union of
   * their CSC patterns, built once by build_jac_pattern. Nonzero i of part p lands at
   * jp_rowind/data position jmap[jmap_off[p] + i]. */
  int lin_kind;            /* DC_LS_DENSE, DC_LS_REDUCED (s->A dense) or DC_LS_SPARSE (s->A a
                            * SUNSparseMatrix, s->LS SuperLU_MT): see LIN_SPARSE */
  int lu_factored;         /* a Jacobian was handed to the sparse LS (it has factorized) */
  SUNErrCode (*lu_initialize)(SUNLinearSolver); /* SuperLU_MT's own, see keep_first_factorization */
  dc_int jp_nnz;
  sunindextype* jp_colptr; /* [n + 1] */
  sunindextype* jp_rowind; /* [jp_nnz], rows sorted within each column */
  dc_int* jmap;            /* [sum of the parts' nonzeros] */
  dc_int* jmap_off;        /* [n_terms + 2] */
  double* P;       /* run-time parameters, dc_model.n_parameters */
  double t_now;    /* time of the state in yy/yp (last return) */
  double t_rec;    /* time of the last recorded step (to skip duplicates) */
  /* A step that filled the caller's last output row with output times left inside it: dc_advance
   * returned DC_CHUNK at once and the rest of that step (its remaining output times from carry_lo
   * on, recording, stall and root handling) resumes at the next call; IDA's interpolant is kept. */
  int carry;
  int carry_flag, carry_order;
  double carry_lo, carry_t_prev, carry_h;
  long int carry_nst, carry_nst_prev;
  int ready;       /* reinit was called */
  int tiny;        /* tiny, non-growing steps since the last normal step */
  double stall_step; /* absolute tiny-step threshold (0: relative test only), see dc_set_stall */
  int stall_count;   /* tiny steps that end the advance (default DC_TINY_MAX) */
  double h_prev;   /* size of the previous step (collapse detection) */
  long long max_steps;
  double rtol, max_step; /* IDA's relative tolerance and step limit (0: none), for first_step */
  int first_step_on;     /* the first start takes first_step(), not IDA's estimate (dc_set_first_step) */
  long long base[ST_N]; /* counters accumulated over earlier reinit segments */
  char msg[MSG_LEN];    /* our own message for the last non-success return */
  char cb_msg[MSG_LEN]; /* set by a callback that refused its input (NaN, CasADi error) */
  char ida_msg[MSG_LEN]; /* last message IDA passed to the error handler */
  /* contact events decided in C (dc_set_auto): simple pairs of one root and one term */
  int n_auto;
  int* auto_root;     /* [n_auto] root index of the pair */
  int* auto_term;     /* [n_auto] term index of the pair */
  int* auto_rate;     /* [n_auto] extra: (q, v) -> [gap; penetration rate] */
  int* auto_needs;    /* [n_auto] the term's parameter is the latched approach speed */
  int* root_to_auto;  /* [n_roots] pair of a root */
  dc_pair_rule* pair_rule;   /* [n_auto] */
  dc_pair_state* pair_state; /* [n_auto] */
  double* recent;     /* storage of the pairs' rings of switch times */
  double auto_gr[2];  /* gap and penetration rate of a pair */
  int ev_cap, ev_n;   /* events recorded in C, taken by dc_take_events */
  double* ev_t;
  int* ev_pair;
  int* ev_info;       /* [ev_cap * 4] the decision: kind, contact, held, watch */
  double* ev_rate;    /* penetration rate at the event */
  double* ev_latched; /* the pair's latched approach speed after the event */
  double* ev_y;       /* [ev_cap * n] state at the event */
  /* the state layout and the extras that make states consistent in C (dc_set_layout) */
  int lay_ready;
  int lay_nq, lay_m;  /* y = [q (nq), v (nq), lambda (m), mu (m, GGL), work (1, track)] */
  int lay_ggl, lay_track;
  int lay_accel, lay_force0, lay_kin, lay_outputs; /* extras, see daeclear.assemble EXTRA_* */
  int lay_n_switch, lay_n_channels;
  int proj_on;        /* restarts after a switch decided in C: project q and v on the manifold */
  int proj_iter;
  double proj_tol;    /* |Phi| < proj_tol * max(1, |q|) ends the position Newton */
  double* lay_buf;    /* Qc, Fk (nq each), sol (nq + m + 1), K (2m + m nq), G (m m), x (m), par, channels */
  const double** xarg; /* CasADi work memory for the extras, sized for the largest (dc_set_layout) */
  double** xres;
  dc_int* xiw;
  double* xw;
  double* xnz;        /* the nonzeros of a sparse extra's output, before extra_dense scatters them */
  int* lay_on;        /* [n_terms] */
} dc_session;

static void set_msg(char* buf, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, MSG_LEN, fmt, ap);
  va_end(ap);
}

static void err_handler(int line, const char* func, const char* file, const char* msg,
                        SUNErrCode code, void* data, SUNContext ctx) {
  dc_session* s = (dc_session*)data;
  (void)line;
  (void)file;
  (void)ctx;
  if (!s) return;
  snprintf(s->ida_msg, MSG_LEN, "%s (code %d): %s", func ? func : "?", (int)code,
           msg ? msg : "");
}

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

static int eval_res(dc_session* s, double t, const double* y, const double* yp, double* r) {
  const dc_model_t* M = &dc_model;
  s->arg[0] = &t;
  s->arg[1] = y;
  s->arg[2] = yp;
  s->arg[3] = s->P;
  s->res[0] = r;
  if (M->res.eval(s->arg, s->res, s->iw, s->w, s->mem_res)) return -1;
  for (int k = 0; k < s->n_terms; ++k) {
    if (!s->active[k]) continue;
    s->arg[0] = &t;
    s->arg[1] = y;
    s->arg[2] = yp;
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
    dc_sp_scatter(jac_part(p)->sparsity_out(0), nz, out, s->n, 1);
    return;
  }
  const dc_int* map = s->jmap + s->jmap_off[p];
  const dc_int m = s->jmap_off[p + 1] - s->jmap_off[p];
  for (dc_int i = 0; i < m; ++i) out[map[i]] += nz[i];
}

/* Entries of the Jacobian (out): n * n dense, or jp_nnz in the union pattern. */
static dc_int jac_len(const dc_session* s, int sparse) {
  return sparse ? s->jp_nnz : (dc_int)s->n * (dc_int)s->n;
}

/* J = base Jacobian + active terms' Jacobians, into out (layout: see add_part); zeroed: J is
 * zero already (IDA zeroes a direct solver's matrix before it calls jac_cb). */
static int eval_jac(dc_session* s, double t, const double* y, const double* yp, double cj,
                    double* J, int sparse, int zeroed) {
  const dc_model_t* M = &dc_model;
  if (!zeroed) memset(J, 0, sizeof(double) * (size_t)jac_len(s, sparse));
  s->arg[0] = &t;
  s->arg[1] = y;
  s->arg[2] = yp;
  s->arg[3] = &cj;
  s->arg[4] = s->P;
  s->res[0] = s->tmp_J;
  if (M->jac.eval(s->arg, s->res, s->iw, s->w, s->mem_jac)) return -1;
  add_part(s, 0, s->tmp_J, J, sparse);
  for (int k = 0; k < s->n_terms; ++k) {
    if (!s->active[k]) continue;
    s->arg[0] = &t;
    s->arg[1] = y;
    s->arg[2] = yp;
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
  s->arg[0] = &t;
  s->arg[1] = y;
  s->arg[2] = yp;
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
    *row = (int)(i % s->n);
    *col = (int)(i / s->n);
    return;
  }
  int c = 0;
  while (c < s->n && (dc_int)s->jp_colptr[c + 1] <= i) ++c;
  *row = (int)s->jp_rowind[i];
  *col = c;
}

/* The matrix's storage for eval_jac. A sparse matrix gets its pattern back first: IDA zeroes the
 * matrix before every call (SUNMatZero), and for a SUNSparseMatrix that clears the index arrays
 * too. */
static double* jac_storage(dc_session* s, SUNMatrix J) {
#if DC_HAVE_SPARSE
  if (LIN_SPARSE(s)) {
    memcpy(SUNSparseMatrix_IndexPointers(J), s->jp_colptr, sizeof(sunindextype) * ((size_t)s->n + 1));
    memcpy(SUNSparseMatrix_IndexValues(J), s->jp_rowind, sizeof(sunindextype) * (size_t)s->jp_nnz);
    return SUNSparseMatrix_Data(J);
  }
#endif
  return SUNDenseMatrix_Data(J);
}

/* An entry of the assembled Jacobian that is not finite (its index in the storage), or -1: in
 * the dense matrix only the positions of the base and active terms' patterns can be. */
static dc_int jac_first_nonfinite(const dc_session* s, const double* Jd) {
  if (LIN_SPARSE(s)) return dc_first_nonfinite(Jd, (int)s->jp_nnz);
  for (int p = 0; p <= s->n_terms; ++p) {
    if (p > 0 && !s->active[p - 1]) continue;
    const dc_int i = dc_sp_first_nonfinite(jac_part(p)->sparsity_out(0), Jd, s->n);
    if (i >= 0) return i;
  }
  return -1;
}

static int jac_cb(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp, N_Vector rr,
                  SUNMatrix J, void* data, N_Vector t1, N_Vector t2, N_Vector t3) {
  dc_session* s = (dc_session*)data;
  double* Jd = jac_storage(s, J);
  (void)rr;
  (void)t1;
  (void)t2;
  (void)t3;
  int rc = eval_jac(s, t, N_VGetArrayPointer(yy), N_VGetArrayPointer(yp), cj, Jd, LIN_SPARSE(s), 1);
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
    entry_position(s, i, LIN_SPARSE(s), &row, &col);
    set_msg(s->cb_msg, "Jacobian entry (%d, %d) is %g at t=%.17g", row, col, Jd[i], t);
    return 1;
  }
#if DC_HAVE_SPARSE
  if (LIN_SPARSE(s)) {
    ONE_OMP_THREAD(); /* IDA factors the matrix next, on this thread */
    s->lu_factored = 1; /* see free_superlumt */
  }
#endif
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

/* ---------------------------------------------------------------- helpers ---- */

static void ida_counters(dc_session* s, long long* out) {
  long int v = 0;
  for (int i = 0; i < ST_N; ++i) out[i] = 0;
  if (!s->ida) return;
  if (IDAGetNumSteps(s->ida, &v) == 0) out[ST_STEPS] = v;
  if (IDAGetNumResEvals(s->ida, &v) == 0) out[ST_RES] = v;
  if (IDAGetNumJacEvals(s->ida, &v) == 0) out[ST_JAC] = v;
  if (IDAGetNumLinSolvSetups(s->ida, &v) == 0) out[ST_LSETUP] = v;
  if (IDAGetNumNonlinSolvIters(s->ida, &v) == 0) out[ST_NNI] = v;
  if (IDAGetNumNonlinSolvConvFails(s->ida, &v) == 0) out[ST_NCF] = v;
  if (IDAGetNumErrTestFails(s->ida, &v) == 0) out[ST_NETF] = v;
  if (IDAGetNumGEvals(s->ida, &v) == 0) out[ST_GEVALS] = v;
}

static void flag_name(long int flag, char* buf, int len) {
  char* name = IDAGetReturnFlagName(flag);
  if (name) {
    snprintf(buf, len, "%s", name);
    free(name);
  } else {
    snprintf(buf, len, "IDA flag %ld", flag);
  }
}

static void* xcalloc(size_t n, size_t sz) { return calloc(n ? n : 1, sz); }

/* ------------------------------------------------------------------ sparse LU (SuperLU_MT)
 * SUNDIALS' SuperLU_MT solver starts over whenever it is initialized, which IDA does at the
 * first step after every IDAReInit, i.e. at every contact event: the next factorization then
 * recomputes the column ordering and allocates new L and U storage without freeing the old
 * (measured on a chain of 8 links: resident memory grew by 60 MB over 600 events, and each
 * event paid a full symbolic factorization). The session's pattern never changes (the union of
 * all parts), so the ordering and storage of the first factorization stay valid for all later
 * ones: dc_open initializes the solver once and replaces its initialize operation by a no-op,
 * so every later factorization takes SuperLU_MT's refactorization path (as within a segment). */
#if DC_HAVE_SPARSE
static SUNErrCode keep_factorization(SUNLinearSolver S) {
  (void)S;
  return 0;
}

/* Initialize the solver once (its first factorization sets the ordering and storage), then
 * replace the initialize operation in this solver's own operations table (every
 * SUNLinearSolver has its own, so no other solver is affected) by keep_factorization. The
 * original operation is kept in the session for free_superlumt. Returns the initialize result. */
static int keep_first_factorization(dc_session* s) {
  SUNErrCode (*init)(SUNLinearSolver) = s->LS->ops->initialize;
  if (!init) return -1;
  s->lu_initialize = init;
  if (init(s->LS) != 0) return -1;
  s->LS->ops->initialize = keep_factorization;
  return 0;
}

/* SUNLinSolFree_SuperLUMT reads uninitialized options when the solver never factorized (a
 * session opened and closed without a step): factor an n x n identity first, so it has. */
static void free_superlumt(dc_session* s) {
  if (!s->lu_factored) {
    SUNMatrix I = SUNSparseMatrix(s->n, s->n, s->n, CSC_MAT, s->ctx);
    if (!I) return; /* leave the solver allocated rather than crash */
    if (s->lu_initialize) s->lu_initialize(s->LS); /* the real one: a first factorization */
    sunindextype* cp = SUNSparseMatrix_IndexPointers(I);
    sunindextype* ri = SUNSparseMatrix_IndexValues(I);
    double* d = SUNSparseMatrix_Data(I);
    for (int i = 0; i < s->n; ++i) {
      cp[i] = i;
      ri[i] = i;
      d[i] = 1.0;
    }
    cp[s->n] = s->n;
    ONE_OMP_THREAD();
    SUNLinSolSetup(s->LS, I);
    SUNMatDestroy(I);
  }
  SUNLinSolFree(s->LS);
}
#endif

static void free_linear_solver(dc_session* s) {
  if (!s->LS) return;
#if DC_HAVE_SPARSE
  if (LIN_SPARSE(s)) {
    free_superlumt(s);
    return;
  }
#endif
  SUNLinSolFree(s->LS);
}

/* ---------------------------------------------------------------- API ---- */

DC_API int dc_abi_version(void) { return DC_ABI_VERSION; }

/* What this library was compiled for, as text in the file itself: Python reads it from the file
 * BEFORE loading the library (codegen.read_build_tag), so a library built for other SUNDIALS
 * headers or another index width is never even loaded. dc_build_info says the same once loaded. */
#define DC_STR_(x) #x
#define DC_STR(x) DC_STR_(x)
DC_API const char dc_build_tag[] = "daeclear-build:abi=" DC_STR(DC_ABI_VERSION)
                                   ";sundials=" DC_STR(DC_SUNDIALS_MAJOR) "." DC_STR(DC_SUNDIALS_MINOR)
                                   "." DC_STR(DC_SUNDIALS_PATCH)
                                   ";index=" DC_STR(DC_INDEX_SIZE)
                                   ";sparse=" DC_STR(DC_HAVE_SPARSE) ";";

/* SUNDIALSGetVersion of the SUNDIALS library this library actually loaded. */
DC_API int dc_sundials_version(char* buf, int len) { return SUNDIALSGetVersion(buf, len); }

/* What this library was compiled for, checked by Python before any session is opened: a
 * library built for other SUNDIALS headers or another index width must never run. out gets
 * SUNDIALS major, minor, patch, DC_INDEX_SIZE, the bits of sunindextype as compiled, and
 * DC_HAVE_SPARSE; returns how many values were written. */
DC_API int dc_build_info(int* out, int len) {
  const int info[6] = {DC_SUNDIALS_MAJOR, DC_SUNDIALS_MINOR, DC_SUNDIALS_PATCH, DC_INDEX_SIZE,
                       (int)(8 * sizeof(sunindextype)), DC_HAVE_SPARSE};
  int k = len < 6 ? len : 6;
  for (int i = 0; i < k; ++i) out[i] = info[i];
  return k;
}

DC_API int dc_n_parameters(void) { return dc_model.n_parameters; }

DC_API int dc_model_info(int* n, int* n_terms, int* n_roots, int* n_params) {
  *n = dc_model.n;
  *n_terms = dc_model.n_terms;
  *n_roots = dc_model.n_roots;
  if (n_params)
    for (int k = 0; k < dc_model.n_terms; ++k) n_params[k] = dc_model.n_params[k];
  return 0;
}

DC_API const char* dc_model_name(void) { return dc_model.name; }

DC_API int dc_n_extra(void) { return dc_n_extras; }

/* Evaluate extra function k at n_points points. Input j of point i is read from
 * inputs[j] + i * in_strides[j] (stride 0: the same values for every point); the output of
 * point i is written to out + i * out_stride. Returns 0, or -1 (bad k / out of memory) or the
 * function's nonzero status. No session needed: the functions are pure. */
DC_API int dc_eval_extra(int k, int n_points, int n_in, const double* const* inputs,
                         const int* in_strides, double* out, int out_stride) {
  if (k < 0 || k >= dc_n_extras || n_points < 0) return -1;
  const dc_fun_t* f = &dc_extra_tab[k];
  dc_int sz_arg = 0, sz_res = 0, sz_iw = 0, sz_w = 0;
  if (f->work(&sz_arg, &sz_res, &sz_iw, &sz_w)) return -1;
  const double** arg = (const double**)calloc((size_t)sz_arg + 1, sizeof(double*));
  double** res = (double**)calloc((size_t)sz_res + 1, sizeof(double*));
  dc_int* iw = (dc_int*)calloc((size_t)sz_iw + 1, sizeof(dc_int));
  double* w = (double*)calloc((size_t)sz_w + 1, sizeof(double));
  double* nz = (double*)calloc((size_t)nnz_of(f) + 1, sizeof(double));
  int status = (arg && res && iw && w && nz && n_in <= sz_arg) ? 0 : -1;
  if (status == 0) {
    f->incref();
    int mem = f->checkout();
    for (int i = 0; i < n_points && status == 0; ++i) {
      for (int j = 0; j < n_in; ++j) arg[j] = inputs[j] ? inputs[j] + (size_t)i * (size_t)in_strides[j] : 0;
      status = extra_dense(f, arg, res, iw, w, mem, out + (size_t)i * (size_t)out_stride, nz);
    }
    f->release(mem);
    f->decref();
  }
  free(arg);
  free(res);
  free(iw);
  free(w);
  free(nz);
  return status;
}

/* One evaluation of extra k (inputs in order, one output) with the session's preallocated work
 * memory: the per-point path of restarts and reports (dc_eval_extra allocates per call). The
 * generated SX functions keep no state between calls (their checkout is a constant). */
static int eval_extra1(dc_session* s, int k, int n_in, const double* const* in, double* out) {
  for (int j = 0; j < n_in; ++j) s->xarg[j] = in[j];
  return extra_dense(&dc_extra_tab[k], s->xarg, s->xres, s->xiw, s->xw, 0, out, s->xnz);
}

DC_API void dc_flag_name(long flag, char* buf, int len) { flag_name(flag, buf, len); }

DC_API const char* dc_message(void* sp) { return sp ? ((dc_session*)sp)->msg : ""; }

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
  free_linear_solver(s);
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

static void work_max(const dc_fun_t* f, dc_int* a, dc_int* r, dc_int* iw, dc_int* w) {
  dc_int sa = 0, sr = 0, si = 0, sw = 0;
  f->work(&sa, &sr, &si, &sw);
  if (sa > *a) *a = sa;
  if (sr > *r) *r = sr;
  if (si > *iw) *iw = si;
  if (sw > *w) *w = sw;
}

static int cmp_index(const void* a, const void* b) {
  sunindextype x = *(const sunindextype*)a, y = *(const sunindextype*)b;
  return (x > y) - (x < y);
}

/* The union of the CSC patterns of all Jacobian parts (base and every term), rows sorted within
 * each column as SUNSparseMatrix and SuperLU_MT expect, and each part's nonzero -> position map.
 * Once per session, O(nonzeros log): a row marker per column, no n x n scratch. Returns 0, or -1
 * out of memory, -2 a pattern that is not n x n, -3 too many nonzeros for sunindextype. */
static int build_jac_pattern(dc_session* s) {
  const int n = s->n, parts = s->n_terms + 1;
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

/* Open a session: IDA memory, linear solver (DC_LS_DENSE: dense LU; DC_LS_SPARSE: SuperLU_MT on
 * the union pattern, one thread), tolerances, options and root functions.
 * IDAInit is called here with a zero state; dc_reinit then (re)starts with IDAReInit.
 * Returns NULL on failure with a message in err. */
DC_API void* dc_open(double rtol, const double* atol, double max_step, int max_order,
                     long long max_steps, const int* rootdir, const double* P, int linear_solver,
                     char* err, int errlen) {
  const dc_model_t* M = &dc_model;
  dc_session* s = (dc_session*)calloc(1, sizeof(dc_session));
  int n = M->n, flag;
#define FAIL(...)                          \
  do {                                     \
    if (err && errlen > 0) snprintf(err, errlen, __VA_ARGS__); \
    dc_free(s);                            \
    return NULL;                           \
  } while (0)
  if (!s) {
    if (err && errlen > 0) snprintf(err, errlen, "out of memory");
    return NULL;
  }
  s->n = n;
  s->n_terms = M->n_terms;
  s->n_roots = M->n_roots;
  s->max_steps = max_steps;
  s->rtol = rtol;
  s->max_step = max_step;
  s->mem_res = s->mem_jac = s->mem_roots = -1;

  /* CasADi work memory */
  {
    dc_int sa = 6, sr = 1, si = 0, sw = 0;
    work_max(&M->res, &sa, &sr, &si, &sw);
    work_max(&M->jac, &sa, &sr, &si, &sw);
    if (M->n_roots > 0) work_max(&M->roots, &sa, &sr, &si, &sw);
    for (int k = 0; k < M->n_terms; ++k) {
      work_max(&M->term_res[k], &sa, &sr, &si, &sw);
      work_max(&M->term_jac[k], &sa, &sr, &si, &sw);
    }
    s->arg = (const double**)xcalloc((size_t)sa, sizeof(double*));
    s->res = (double**)xcalloc((size_t)sr, sizeof(double*));
    s->iw = (dc_int*)xcalloc((size_t)si, sizeof(dc_int));
    s->w = (double*)xcalloc((size_t)sw, sizeof(double));
    s->mem_term_res = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
    s->mem_term_jac = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
    if (!s->arg || !s->res || !s->iw || !s->w || !s->mem_term_res || !s->mem_term_jac)
      FAIL("out of memory");
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
  }

  /* per-segment state */
  {
    int np = 0;
    s->param_off = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
    s->active = (int*)xcalloc((size_t)M->n_terms, sizeof(int));
    if (!s->param_off || !s->active) FAIL("out of memory");
    for (int k = 0; k < M->n_terms; ++k) {
      s->param_off[k] = np;
      np += M->n_params[k];
    }
    s->params = (double*)xcalloc((size_t)np, sizeof(double));
  s->rootdir_default = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
    s->rootdir = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
    s->rootsfound = (int*)xcalloc((size_t)M->n_roots, sizeof(int));
    s->tmp_r = (double*)xcalloc((size_t)n, sizeof(double));
    dc_int nnz = nnz_of(&M->jac);
    for (int k = 0; k < M->n_terms; ++k)
      if (nnz_of(&M->term_jac[k]) > nnz) nnz = nnz_of(&M->term_jac[k]);
    s->tmp_J = (double*)xcalloc((size_t)nnz, sizeof(double));
    s->P = (double*)xcalloc((size_t)M->n_parameters, sizeof(double));
    if (!s->params || !s->rootdir_default || !s->rootdir || !s->rootsfound || !s->tmp_r ||
        !s->tmp_J || !s->P)
      FAIL("out of memory");
    clear_run_state(s);
    if (M->n_parameters > 0) {
      if (!P) FAIL("the model has %d run-time parameters and none were given", M->n_parameters);
      memcpy(s->P, P, sizeof(double) * (size_t)M->n_parameters);
    }
    for (int i = 0; i < M->n_roots; ++i) s->rootdir_default[i] = rootdir ? rootdir[i] : 0;
  }

  /* Jacobian pattern: always built (small), so dc_eval_jacobian_sparse works in any session */
  {
    int rc = build_jac_pattern(s);
    if (rc == -1) FAIL("out of memory");
    if (rc == -2) FAIL("a generated Jacobian is not %d x %d", n, n);
    if (rc == -3) FAIL("the Jacobian has too many nonzeros for the wheel's 32-bit sunindextype");
  }
  if (linear_solver != DC_LS_DENSE && linear_solver != DC_LS_SPARSE && linear_solver != DC_LS_REDUCED)
    FAIL("unknown linear solver %d (0: dense, 1: sparse, 2: reduced)", linear_solver);
  if (linear_solver == DC_LS_SPARSE && !DC_HAVE_SPARSE)
    FAIL("this library was built without the sparse solver (the wheel lacks "
         "libsundials_sunmatrixsparse or libsundials_sunlinsolsuperlumt)");
  s->lin_kind = linear_solver;

  /* SUNDIALS objects */
  if (SUNContext_Create(SUN_COMM_NULL, &s->ctx) != 0 || !s->ctx)
    FAIL("SUNContext_Create failed");
  SUNContext_ClearErrHandlers(s->ctx); /* IDA must not print; we build our own messages */
  SUNContext_PushErrHandler(s->ctx, err_handler, s);
  s->yy = N_VNew_Serial(n, s->ctx);
  s->yp = N_VNew_Serial(n, s->ctx);
  s->atol = N_VNew_Serial(n, s->ctx);
  s->dky = N_VNew_Serial(n, s->ctx);
  if (!s->yy || !s->yp || !s->atol || !s->dky) FAIL("N_VNew_Serial failed");
  /* IDA clones its vectors from yy: with fused operations its predictor, corrector and error
   * norms make one pass (N_VLinearCombination, ...) instead of one call per term */
  if (N_VEnableFusedOps_Serial(s->yy, SUNTRUE) != SUN_SUCCESS) FAIL("N_VEnableFusedOps_Serial failed");
  memset(N_VGetArrayPointer(s->yy), 0, sizeof(double) * (size_t)n);
  memset(N_VGetArrayPointer(s->yp), 0, sizeof(double) * (size_t)n);
  memcpy(N_VGetArrayPointer(s->atol), atol, sizeof(double) * (size_t)n);
  if (LIN_SPARSE(s)) {
#if DC_HAVE_SPARSE
    /* one thread: the factorizations are small and the machine is shared; more threads cost
     * more in OpenMP start-up than they save */
    s->A = SUNSparseMatrix(n, n, s->jp_nnz > 0 ? (sunindextype)s->jp_nnz : 1, CSC_MAT, s->ctx);
    if (!s->A) FAIL("SUNSparseMatrix(%d, %d, nnz=%lld) failed", n, n, (long long)s->jp_nnz);
    (void)jac_storage(s, s->A); /* a valid pattern from the start */
    s->LS = SUNLinSol_SuperLUMT(s->yy, s->A, 1, s->ctx);
    if (!s->LS) FAIL("SUNLinSol_SuperLUMT failed");
    if (keep_first_factorization(s) != 0)
      FAIL("the SuperLU_MT solver of this SUNDIALS build could not be initialized; "
           "use linear_solver='dense'");
#endif
  } else {
    s->A = SUNDenseMatrix(n, n, s->ctx);
    if (!s->A) FAIL("SUNDenseMatrix failed");
    s->LS = linear_solver == DC_LS_REDUCED ? rls_create(n, s->ctx) : SUNLinSol_Dense(s->yy, s->A, s->ctx);
    if (!s->LS) FAIL("the dense linear solver could not be created (out of memory)");
  }
  s->ida = IDACreate(s->ctx);
  if (!s->ida) FAIL("IDACreate failed");
#define CHECK(call)                                                      \
  do {                                                                   \
    flag = (call);                                                       \
    if (flag < 0) FAIL("%s failed with flag %d: %s", #call, flag, s->ida_msg); \
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
#undef FAIL
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

/* (Re)start IDA at (t0, y0, yp0) with fresh BDF history; set active terms, their parameters
 * (concatenated) and the root directions (NULL: the directions given to dc_open). */
DC_API int dc_reinit(void* sp, double t0, const double* y0, const double* yp0,
                     const int* active, const double* params, const int* rootdir) {
  dc_session* s = (dc_session*)sp;
  long long cur[ST_N];
  int flag, np = 0;
  s->msg[0] = 0;
  if (s->ready) {
    ida_counters(s, cur);
    for (int i = 0; i < ST_N; ++i) s->base[i] += cur[i];
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
  s->base[ST_REINITS] += 1;
  return 0;
}

static void copy_state(dc_session* s, double* y_out, double* yp_out) {
  memcpy(y_out, N_VGetArrayPointer(s->yy), sizeof(double) * (size_t)s->n);
  memcpy(yp_out, N_VGetArrayPointer(s->yp), sizeof(double) * (size_t)s->n);
}

/* ------------------------------------------------------------------ events decided in C
 * Simple contact pairs (one root function, one term; index-1 layout y = [q, v, lam(, W)]) are
 * decided entirely in C once dc_set_auto has configured them (every root must be a pair's): at
 * a root the loop runs each pair's automaton (pair_step, storm guard and holds included), sets
 * the pair's term, latched approach speed and root direction from the decision, and, when any
 * pair switched, recomputes the multipliers and derivatives with the generated functions
 * (extras: term forces and the accelerations' Schur-complement solve) and restarts IDA; a root
 * that switched nothing lets IDA go on. Each switch is recorded with its decision for Python,
 * which only records it (modes, terms, events). dc_advance returns DC_CHUNK before the event
 * buffer could overflow, so Python drains it between chunks.
 *
 * Per pair: root, term, rate (extra), needs (latched speed is the term's parameter), vmin,
 * storm_events, storm_window (the rule) and contact0, held0, latched0 (the state to start from). */
DC_API int dc_set_auto(void* sp, int n_auto, const int* root, const int* term, const int* rate,
                       const int* needs, const double* vmin, const int* storm_events,
                       const double* storm_window, const int* contact0, const int* held0,
                       const double* latched0, int ev_cap) {
  dc_session* s = (dc_session*)sp;
  size_t ring = 0;
  if (n_auto < 0 || (n_auto > 0 && n_auto != s->n_roots) || ev_cap < (n_auto > 0 ? n_auto : 1))
    return -1;
  for (int p = 0; p < n_auto; ++p) {
    if (storm_events[p] < 1 || !(storm_window[p] >= 0.0)) return -1;
    ring += (size_t)storm_events[p];
  }
  s->n_auto = 0;
  free(s->auto_root); free(s->auto_term); free(s->auto_rate); free(s->auto_needs);
  free(s->root_to_auto); free(s->pair_rule); free(s->pair_state); free(s->recent);
  free(s->ev_t); free(s->ev_pair); free(s->ev_info); free(s->ev_rate);
  free(s->ev_latched); free(s->ev_y);
  s->auto_root = (int*)xcalloc((size_t)n_auto + 1, sizeof(int));
  s->auto_term = (int*)xcalloc((size_t)n_auto + 1, sizeof(int));
  s->auto_rate = (int*)xcalloc((size_t)n_auto + 1, sizeof(int));
  s->auto_needs = (int*)xcalloc((size_t)n_auto + 1, sizeof(int));
  s->root_to_auto = (int*)xcalloc((size_t)s->n_roots + 1, sizeof(int));
  s->pair_rule = (dc_pair_rule*)xcalloc((size_t)n_auto + 1, sizeof(dc_pair_rule));
  s->pair_state = (dc_pair_state*)xcalloc((size_t)n_auto + 1, sizeof(dc_pair_state));
  s->recent = (double*)xcalloc(ring + 1, sizeof(double));
  s->ev_t = (double*)xcalloc((size_t)ev_cap, sizeof(double));
  s->ev_pair = (int*)xcalloc((size_t)ev_cap, sizeof(int));
  s->ev_info = (int*)xcalloc(4 * (size_t)ev_cap, sizeof(int));
  s->ev_rate = (double*)xcalloc((size_t)ev_cap, sizeof(double));
  s->ev_latched = (double*)xcalloc((size_t)ev_cap, sizeof(double));
  s->ev_y = (double*)xcalloc((size_t)ev_cap * (size_t)s->n, sizeof(double));
  if (!s->auto_root || !s->auto_term || !s->auto_rate || !s->auto_needs || !s->root_to_auto ||
      !s->pair_rule || !s->pair_state || !s->recent || !s->ev_t || !s->ev_pair ||
      !s->ev_info || !s->ev_rate || !s->ev_latched || !s->ev_y)
    return -1;
  for (int i = 0; i < s->n_roots; ++i) s->root_to_auto[i] = -1;
  ring = 0;
  for (int p = 0; p < n_auto; ++p) {
    if (root[p] < 0 || root[p] >= s->n_roots || term[p] < 0 || term[p] >= s->n_terms) return -1;
    if (needs[p] && dc_model.n_params[term[p]] < 1) return -1;
    if (s->root_to_auto[root[p]] >= 0) return -1;
    s->auto_root[p] = root[p];
    s->auto_term[p] = term[p];
    s->auto_rate[p] = rate[p];
    s->auto_needs[p] = needs[p];
    s->root_to_auto[root[p]] = p;
    dc_pair_rule r = {storm_events[p], storm_window[p], vmin[p]};
    dc_pair_state st = {contact0[p] != 0, held0[p] != 0, 0.0, latched0[p], 0, s->recent + ring};
    s->pair_rule[p] = r;
    s->pair_state[p] = st;
    ring += (size_t)storm_events[p];
  }
  s->ev_cap = ev_cap;
  s->ev_n = 0;
  s->n_auto = n_auto;
  return 0;
}

/* Move the events recorded in C to the caller's buffers (at most cap); returns their count.
 * info[4 * i ...] = kind, contact, held, watch of event i's decision. */
DC_API int dc_take_events(void* sp, int cap, double* t, int* pair, int* info, double* rate,
                          double* latched, double* y) {
  dc_session* s = (dc_session*)sp;
  int k = s->ev_n < cap ? s->ev_n : cap;
  memcpy(t, s->ev_t, sizeof(double) * (size_t)k);
  memcpy(pair, s->ev_pair, sizeof(int) * (size_t)k);
  memcpy(info, s->ev_info, sizeof(int) * 4 * (size_t)k);
  memcpy(rate, s->ev_rate, sizeof(double) * (size_t)k);
  memcpy(latched, s->ev_latched, sizeof(double) * (size_t)k);
  memcpy(y, s->ev_y, sizeof(double) * (size_t)k * (size_t)s->n);
  s->ev_n -= k;
  if (s->ev_n > 0) { /* the rest stays, oldest first */
    memmove(s->ev_t, s->ev_t + k, sizeof(double) * (size_t)s->ev_n);
    memmove(s->ev_pair, s->ev_pair + k, sizeof(int) * (size_t)s->ev_n);
    memmove(s->ev_info, s->ev_info + 4 * k, sizeof(int) * 4 * (size_t)s->ev_n);
    memmove(s->ev_rate, s->ev_rate + k, sizeof(double) * (size_t)s->ev_n);
    memmove(s->ev_latched, s->ev_latched + k, sizeof(double) * (size_t)s->ev_n);
    memmove(s->ev_y, s->ev_y + (size_t)k * (size_t)s->n, sizeof(double) * (size_t)s->ev_n * (size_t)s->n);
  }
  return k;
}

DC_API int dc_pending_events(void* sp) { return ((dc_session*)sp)->ev_n; }

DC_API void dc_get_active(void* sp, int* active, double* params) {
  dc_session* s = (dc_session*)sp;
  int np = 0;
  for (int k = 0; k < s->n_terms; ++k) {
    active[k] = s->active[k];
    np += dc_model.n_params[k];
  }
  memcpy(params, s->params, sizeof(double) * (size_t)np);
}

/* Test hook: run one pair's automaton (pair_step, exactly as the loop does) over a root sequence
 * t[i], dir[i], rate[i] from the state (contact0, held0, latched0) with no history; write each
 * decision to kind, contact, held, watch, latched [n]. Returns 0, or -1 for bad arguments. */
DC_API int dc_automaton_run(int n, const double* t, const int* dir, const double* rate,
                            int storm_events, double storm_window, double vmin, int contact0,
                            int held0, double latched0, int* kind, int* contact, int* held,
                            int* watch, double* latched) {
  if (n < 0 || storm_events < 1 || !(storm_window >= 0.0)) return -1;
  double* ring = (double*)xcalloc((size_t)storm_events, sizeof(double));
  if (!ring) return -1;
  dc_pair_rule r = {storm_events, storm_window, vmin};
  dc_pair_state st = {contact0 != 0, held0 != 0, 0.0, latched0, 0, ring};
  for (int i = 0; i < n; ++i) {
    dc_decision d = pair_step(&r, &st, t[i], dir[i], rate[i]);
    kind[i] = d.kind;
    contact[i] = d.contact;
    held[i] = d.held;
    watch[i] = d.watch;
    latched[i] = d.latched;
  }
  free(ring);
  return 0;
}

/* Decide every root found at (t, yy) by the pairs' automata and record the switches. When any
 * pair switched, restart IDA consistently and return 1; return 2 when nothing switched (IDA
 * goes on without a restart), 0 without configured pairs (Python decides), -1 on failure. */
/* below, with dc_set_layout */
static int project_state(dc_session* s, double t, double* y);
static int project_kept_roots(dc_session* s, double t, double* y, const double* yp);
static int make_consistent(dc_session* s, double t, double* y, double* yp, const int* on, const double* par);

static int auto_handle_root(dc_session* s, double t, double t_stop) {
  if (s->n_auto == 0) return 0;
  if (s->ev_n + s->n_auto > s->ev_cap || !s->lay_ready) {
    s->ready = 0;
    set_msg(s->msg, "internal: the contact event buffer was not drained or the layout not set (t=%.17g)", t);
    return -1;
  }
  const int n = s->n, nq = s->lay_nq, m = s->lay_m;
  double* y = N_VGetArrayPointer(s->yy);
  double* yp = N_VGetArrayPointer(s->yp);
  const double* q = y;
  const double* v = y + nq;
  double* gr = s->auto_gr;
  int switched = 0;
  for (int i = 0; i < s->n_roots; ++i) {
    int dir = s->rootsfound[i];
    if (!dir) continue;
    int p = s->root_to_auto[i], k = s->auto_term[p];
    const double* in_rate[3] = {q, v, s->P};
    if (eval_extra1(s, s->auto_rate[p], 3, in_rate, gr) != 0) goto eval_failed;
    dc_decision d = pair_step(&s->pair_rule[p], &s->pair_state[p], t, dir, gr[1]);
    if (d.kind == DC_NONE) continue;
    int* info = s->ev_info + 4 * (size_t)s->ev_n;
    s->ev_t[s->ev_n] = t;
    s->ev_pair[s->ev_n] = p;
    info[0] = d.kind;
    info[1] = d.contact;
    info[2] = d.held;
    info[3] = d.watch;
    s->ev_rate[s->ev_n] = gr[1];
    s->ev_latched[s->ev_n] = d.latched;
    memcpy(s->ev_y + (size_t)s->ev_n * (size_t)n, y, sizeof(double) * (size_t)n);
    ++s->ev_n;
    s->active[k] = d.contact || d.held;
    if (s->auto_needs[p]) s->params[s->param_off[k]] = d.latched;
    s->rootdir[i] = d.watch;
    switched = 1;
  }
  if (!switched) return 2;
  /* consistent restart: GGL on the constraint manifold with mu = 0; then multipliers and
   * derivatives from the generated solve with the new set of contact forces */
  if (s->proj_on) {
    int pr = project_kept_roots(s, t, y, yp);
    if (pr == -3) goto eval_failed;
    if (pr != 0) {
      s->ready = 0;
      set_msg(s->msg, "projecting the state onto the constraints after a contact event at t=%.17g failed "
              "(dependent constraints, or no convergence in %d Newton steps)", t, s->proj_iter);
      return -1;
    }
  }
  if (s->lay_ggl) memset(y + 2 * nq + m, 0, sizeof(double) * (size_t)m);
  if (make_consistent(s, t, y, yp, s->active, s->params) != 0) goto eval_failed;
  (void)n;
  long long cur[ST_N];
  ida_counters(s, cur);
  for (int i = 0; i < ST_N; ++i) s->base[i] += cur[i];
  if (IDASetInitStep(s->ida, 0.0) < 0 || IDAReInit(s->ida, t, s->yy, s->yp) < 0 ||
      IDASetRootDirection(s->ida, s->rootdir) < 0 ||
      IDASetStopTime(s->ida, t_stop) < 0) {
    s->ready = 0;
    set_msg(s->msg, "restarting IDA after a contact event at t=%.17g failed: %s", t, s->ida_msg);
    return -1;
  }
  s->t_now = t;
  s->t_rec = t;
  s->tiny = 0;
  s->h_prev = 0.0;
  s->base[ST_REINITS] += 1;
  return 1;
eval_failed:
  s->ready = 0;
  set_msg(s->msg, "evaluating the generated contact functions at t=%.17g failed", t);
  return -1;
}

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

/* Fill the multipliers lambda of y and all of yp so that the residual vanishes at (t, y): the
 * generated Schur-complement solve (accel extra) with the contact forces of the terms that are on
 * (on[k], parameters at par + param_off[k]); GGL: q' = v - Phi_q^T mu. The same as
 * DAEModel.consistent_state in Python. */
static int make_consistent(dc_session* s, double t, double* y, double* yp, const int* on, const double* par) {
  const int n = s->n, nq = s->lay_nq, m = s->lay_m;
  double* Qc = s->lay_buf;
  double* Fk = Qc + nq;
  double* sol = Fk + nq;
  double* K = sol + nq + m + 1;
  const double* q = y;
  const double* v = y + nq;
  double tt = t;
  memset(Qc, 0, sizeof(double) * (size_t)nq);
  for (int k = 0; k < s->n_terms; ++k) {
    if (!on[k]) continue;
    const double* in_f[5] = {&tt, q, v, par + s->param_off[k], s->P};
    if (eval_extra1(s, s->lay_force0 + k, 5, in_f, Fk) != 0) return -1;
    for (int j = 0; j < nq; ++j) Qc[j] += Fk[j];
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

/* The model's state layout and extras (daeclear.assemble: EXTRA_ACCEL, EXTRA_TERM0 + k,
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
  if (s->lin_kind == DC_LS_REDUCED && rls_set_kinematic_rows(s->LS, nq) != 0) return -1;
  s->lay_ready = 1;
  return 0;
}

/* The reported points of a run, made consistent in one pass: for each of the n_points rows of y
 * (IDA's states) with its switch row (per term: on flag, then its parameters), write the state
 * with recomputed multipliers to y_out (which may be y itself), its derivative to yp_out and the
 * output channels to channels_out, channel by channel: channel c of point i at c * n_points + i,
 * so that each channel is one contiguous row (dc_set_layout first); channels_out NULL: states only. */
DC_API int dc_report(void* sp, int n_points, const double* t, const double* y, const double* sw, double* y_out,
                     double* yp_out, double* channels_out) {
  dc_session* s = (dc_session*)sp;
  if (!s->lay_ready || n_points < 0) return -1;
  const int n = s->n, ns = s->lay_n_switch, nc = s->lay_n_channels;
  double* par = s->lay_buf + 3 * s->lay_nq + 3 * s->lay_m + 1 + s->lay_m * s->lay_nq + s->lay_m * s->lay_m + s->lay_m;
  double* row = par + s->lay_n_switch - s->n_terms; /* one point's channels (after the parameters) */
  for (int i = 0; i < n_points; ++i) {
    double* yi = y_out + (size_t)i * n;
    double* ypi = yp_out + (size_t)i * n;
    const double* si = sw + (size_t)i * ns;
    if (yi != y + (size_t)i * n) memcpy(yi, y + (size_t)i * n, sizeof(double) * (size_t)n);
    for (int k = 0, off = 0; k < s->n_terms; ++k) {
      s->lay_on[k] = si[off] > 0.0;
      memcpy(par + s->param_off[k], si + off + 1, sizeof(double) * (size_t)dc_model.n_params[k]);
      off += 1 + dc_model.n_params[k];
    }
    if (make_consistent(s, t[i], yi, ypi, s->lay_on, par) != 0) return -1;
    if (!channels_out) continue; /* states only: the channels are computed when read */
    const double* in_o[5] = {t + i, yi, ypi, si, s->P};
    if (eval_extra1(s, s->lay_outputs, 5, in_o, row) != 0) return -1;
    for (int c = 0; c < nc; ++c) channels_out[(size_t)c * (size_t)n_points + (size_t)i] = row[c];
  }
  return 0;
}

/*
 * Integrate from the current time towards t_stop (hard stop) in one-step mode.
 *
 * t_eval[*i_eval .. n_eval) are the requested output times, sorted, all > current time; each
 * one reached is written (y via IDAGetDky k=0, yp via k=1) to eval_y/eval_yp row *i_eval and
 * *i_eval advances. If store_steps (DC_STORE_TIMES, with DC_STORE_STATES also y and yp), every
 * return point of IDA (the end of each internal step;
 * on a root return the root point; duplicates skipped) is written to the step buffers, at most
 * cap rows; *n_stored rows were written.
 *
 * Returns DC_CHUNK when cap rows were written (store_steps), cap IDA calls were made
 * (otherwise), or a step filled the last of the n_eval output rows (so that a caller can hand
 * the output times over in windows and empty the rows between calls): call again. DC_TSTOP / DC_ROOT / errors < 0 otherwise; *t_out, y_out, yp_out
 * hold the state reached, roots_out the root info (DC_ROOT), *flag_out IDA's flag (DC_ERR_IDA).
 */
DC_API int dc_advance(void* sp, double t_stop, const double* t_eval, int n_eval, int* i_eval,
                      double* eval_y, double* eval_yp, int store_steps, int cap, double* st,
                      double* sy, double* syp, double* sh, int* sord, int* n_stored,
                      double* t_out, double* y_out, double* yp_out, int* roots_out,
                      int* flag_out) {
  dc_session* s = (dc_session*)sp;
  const int n = s->n;
  int k = 0, calls = 0;
  const int i_eval_start = *i_eval;
  long int nst = 0, nst_prev = 0;
  *n_stored = 0;
  *flag_out = 0;
  s->msg[0] = 0;
  *t_out = s->t_now;
  if (!s->ready) {
    set_msg(s->msg, "advance called before reinit (or after a failed reinit)");
    copy_state(s, y_out, yp_out);
    return DC_ERR_USAGE;
  }
  /* Nothing to integrate: IDA would refuse an interval below roundoff. */
  if (!s->carry && t_stop - s->t_now <= 4.0 * DBL_EPSILON * fmax(fabs(t_stop), fabs(s->t_now))) {
    copy_state(s, y_out, yp_out);
    return DC_TSTOP;
  }
  /* After a root return IDA's internal time tn lies beyond the returned time. A t_stop inside
   * (t_now, tn) needs no new step: IDA_NORMAL mode checks that interval for further roots and
   * interpolates y(t_stop). (IDASetStopTime would refuse a stop time behind tn.) */
  double tn = s->t_now;
  IDAGetCurrentTime(s->ida, &tn);
  if (!s->carry && t_stop < tn) {
    double tret = s->t_now, h = 0.0, t_prev = s->t_now;
    int order = 0;
    s->cb_msg[0] = 0;
    s->ida_msg[0] = 0;
    int fl = IDASolve(s->ida, t_stop, &tret, s->yy, s->yp, IDA_NORMAL);
    if (fl < 0) {
      char name[64];
      flag_name(fl, name, sizeof name);
      *flag_out = fl;
      *t_out = s->t_now;
      copy_state(s, y_out, yp_out);
      set_msg(s->msg, "%s at t=%.17g (interpolating inside the last step): %s%s%s", name, s->t_now,
              s->ida_msg, s->cb_msg[0] ? "; last model error: " : "", s->cb_msg);
      return DC_ERR_IDA;
    }
    s->t_now = tret;
    IDAGetLastStep(s->ida, &h);
    IDAGetLastOrder(s->ida, &order);
    while (*i_eval < n_eval && t_eval[*i_eval] <= tret) {
      double te = t_eval[*i_eval];
      if (te > t_prev) {
        if (IDAGetDky(s->ida, te, 0, s->dky) == 0)
          memcpy(eval_y + (size_t)(*i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
        if (IDAGetDky(s->ida, te, 1, s->dky) == 0)
          memcpy(eval_yp + (size_t)(*i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
      }
      ++(*i_eval);
    }
    if (store_steps && tret > s->t_rec) {
      st[0] = tret;
      if (store_steps & DC_STORE_STATES) {
        memcpy(sy, N_VGetArrayPointer(s->yy), sizeof(double) * (size_t)n);
        memcpy(syp, N_VGetArrayPointer(s->yp), sizeof(double) * (size_t)n);
      }
      sh[0] = h;
      sord[0] = order;
      *n_stored = 1;
    }
    if (tret > s->t_rec) s->t_rec = tret;
    *t_out = tret;
    copy_state(s, y_out, yp_out);
    if (fl == IDA_ROOT_RETURN) {
      IDAGetRootInfo(s->ida, s->rootsfound);
      int handled = auto_handle_root(s, tret, t_stop);
      if (handled < 0) return DC_ERR_IDA;
      if (handled) {
        copy_state(s, y_out, yp_out);
        return DC_CHUNK; /* decided in C: call again to go on towards t_stop */
      }
      memcpy(roots_out, s->rootsfound, sizeof(int) * (size_t)s->n_roots);
      return DC_ROOT;
    }
    s->t_now = t_stop; /* IDA_NORMAL returned y(tout) with tret == tout */
    *t_out = t_stop;
    return DC_TSTOP;
  }
  int flag = s->carry ? 0 : IDASetStopTime(s->ida, t_stop);
  if (flag < 0) {
    *flag_out = flag;
    set_msg(s->msg, "IDASetStopTime(%.17g) failed: %s", t_stop, s->ida_msg);
    copy_state(s, y_out, yp_out);
    return DC_ERR_IDA;
  }
  IDAGetNumSteps(s->ida, &nst_prev);

  for (;;) {
    double tret = s->t_now, h = 0.0, t_prev = s->t_now, eval_lo;
    int order = 0, i_before;
    if (s->carry) { /* resume the step cut short at the last call */
      s->carry = 0;
      flag = s->carry_flag;
      order = s->carry_order;
      h = s->carry_h;
      t_prev = s->carry_t_prev;
      eval_lo = s->carry_lo;
      nst = s->carry_nst;
      nst_prev = s->carry_nst_prev;
      goto step_taken;
    }
    if (s->base[ST_STEPS] + (long long)nst_prev >= s->max_steps) {
      set_msg(s->msg,
              "step cap reached: %lld IDA steps in this session (max_steps=%lld) at t=%.17g",
              s->base[ST_STEPS] + (long long)nst_prev, s->max_steps, s->t_now);
      copy_state(s, y_out, yp_out);
      *t_out = s->t_now;
      return DC_ERR_MAXSTEPS;
    }
    s->cb_msg[0] = 0;
    s->ida_msg[0] = 0;
    flag = IDASolve(s->ida, t_stop, &tret, s->yy, s->yp, IDA_ONE_STEP);
    ++calls;
    if (flag < 0) {
      char name[64];
      flag_name(flag, name, sizeof name);
      *flag_out = flag;
      s->t_now = tret;
      *t_out = tret;
      copy_state(s, y_out, yp_out);
      set_msg(s->msg, "%s at t=%.17g%s%s%s%s", name, tret, s->ida_msg[0] ? ": " : "",
              s->ida_msg, s->cb_msg[0] ? "; last model error: " : "", s->cb_msg);
      return DC_ERR_IDA;
    }
    t_prev = s->t_now;
    s->t_now = tret;
    IDAGetNumSteps(s->ida, &nst);
    IDAGetLastStep(s->ida, &h);
    IDAGetLastOrder(s->ida, &order);
    eval_lo = t_prev;

  step_taken:
    /* dense output at requested times in (eval_lo, tret] */
    i_before = *i_eval;
    while (*i_eval < n_eval && t_eval[*i_eval] <= tret) {
      double te = t_eval[*i_eval];
      if (te > eval_lo) {
        int f0 = IDAGetDky(s->ida, te, 0, s->dky);
        if (f0 == 0) memcpy(eval_y + (size_t)(*i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
        int f1 = f0 == 0 ? IDAGetDky(s->ida, te, 1, s->dky) : f0;
        if (f1 == 0) memcpy(eval_yp + (size_t)(*i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
        if (f0 || f1) {
          *flag_out = f0 ? f0 : f1;
          set_msg(s->msg, "IDAGetDky failed at t=%.17g (flag %d): %s", te, *flag_out, s->ida_msg);
          *t_out = tret;
          copy_state(s, y_out, yp_out);
          return DC_ERR_IDA;
        }
      }
      ++(*i_eval);
    }
    if (n_eval > 0 && i_before < n_eval && *i_eval == n_eval && t_eval[n_eval - 1] < tret) {
      /* the rows are full and further output times may lie in this step: hand the rows over now */
      s->carry = 1;
      s->carry_flag = flag;
      s->carry_order = order;
      s->carry_h = h;
      s->carry_t_prev = t_prev;
      s->carry_lo = t_eval[n_eval - 1];
      s->carry_nst = nst;
      s->carry_nst_prev = nst_prev;
      *t_out = tret;
      copy_state(s, y_out, yp_out);
      return DC_CHUNK;
    }

    /* record the return point */
    if (store_steps && tret > s->t_rec) {
      st[k] = tret;
      if (store_steps & DC_STORE_STATES) {
        memcpy(sy + (size_t)k * n, N_VGetArrayPointer(s->yy), sizeof(double) * (size_t)n);
        memcpy(syp + (size_t)k * n, N_VGetArrayPointer(s->yp), sizeof(double) * (size_t)n);
      }
      sh[k] = h;
      sord[k] = order;
      ++k;
      *n_stored = k;
    }
    if (tret > s->t_rec) s->t_rec = tret;

    /* step-size collapse or stall: only for genuinely new steps that did not end at t_stop.
     * A step is tiny below max(DC_TINY_REL*max(1,|t|), stall_step); the count restarts at a
     * clearly normal step (100x that threshold), so a chattering run whose steps hover around
     * the threshold is still caught. */
    if (nst > nst_prev && flag != IDA_TSTOP_RETURN) {
      double thr = fmax(DC_TINY_REL * fmax(1.0, fabs(tret)), s->stall_step);
      if (fabs(h) >= (s->stall_step > 0.0 ? DC_NORMAL_STEP_FACTOR * thr : thr))
        s->tiny = 0;
      else if (fabs(h) < thr && !(fabs(h) > DC_TINY_GROWTH * fabs(s->h_prev)))
        ++s->tiny;
      s->h_prev = h;
      if (s->tiny >= s->stall_count) {
        *t_out = tret;
        copy_state(s, y_out, yp_out);
        set_msg(s->msg,
                "step size collapsed: %d steps with |h| < max(%g*max(1,|t|), %g s) that did not "
                "grow (last h=%.3g) at t=%.17g%s%s",
                s->tiny, DC_TINY_REL, s->stall_step, h, tret, s->cb_msg[0] ? "; last model error: " : "",
                s->cb_msg);
        return DC_ERR_COLLAPSE;
      }
    }
    nst_prev = nst;

    if (flag == IDA_ROOT_RETURN) {
      IDAGetRootInfo(s->ida, s->rootsfound);
      int handled = auto_handle_root(s, tret, t_stop);
      if (handled < 0) {
        *t_out = tret;
        copy_state(s, y_out, yp_out);
        return DC_ERR_IDA;
      }
      if (handled) {
        if (handled == 1) IDAGetNumSteps(s->ida, &nst_prev); /* counters restarted with IDA */
        if ((store_steps && k >= cap) || (!store_steps && calls >= cap) ||
            s->ev_n + s->n_auto > s->ev_cap || (*i_eval >= n_eval && *i_eval > i_eval_start)) { /* a buffer full */
          *t_out = tret;
          copy_state(s, y_out, yp_out);
          return DC_CHUNK;
        }
        continue;
      }
      memcpy(roots_out, s->rootsfound, sizeof(int) * (size_t)s->n_roots);
      *t_out = tret;
      copy_state(s, y_out, yp_out);
      return DC_ROOT;
    }
    if (flag == IDA_TSTOP_RETURN) {
      *t_out = tret;
      copy_state(s, y_out, yp_out);
      return DC_TSTOP;
    }
    if ((store_steps && k >= cap) || (!store_steps && calls >= cap) ||
        (*i_eval >= n_eval && *i_eval > i_eval_start)) {
      *t_out = tret;
      copy_state(s, y_out, yp_out);
      return DC_CHUNK;
    }
  }
}

/* Cumulative statistics: earlier segments plus the current one. */
DC_API void dc_stats(void* sp, long long* out) {
  dc_session* s = (dc_session*)sp;
  long long cur[ST_N];
  ida_counters(s, cur);
  if (!s->ready)
    for (int i = 0; i < ST_N; ++i) cur[i] = 0;
  for (int i = 0; i < ST_N; ++i) out[i] = s->base[i] + (i == ST_REINITS ? 0 : cur[i]);
}

/* Model evaluation with the current active terms and parameters (tests, consistency). */
DC_API int dc_eval_residual(void* sp, double t, const double* y, const double* yp, double* r) {
  return eval_res((dc_session*)sp, t, y, yp, r);
}

DC_API int dc_eval_jacobian(void* sp, double t, const double* y, const double* yp, double cj,
                            double* J) {
  return eval_jac((dc_session*)sp, t, y, yp, cj, J, 0, 0);
}

/* The same Jacobian as the nonzeros of the session's union pattern (dc_jac_pattern): what the
 * sparse solver's callback fills. */
DC_API int dc_eval_jacobian_sparse(void* sp, double t, const double* y, const double* yp,
                                   double cj, double* data) {
  return eval_jac((dc_session*)sp, t, y, yp, cj, data, 1, 0);
}

/* Solve J x = b with the reduced dense solver (nk position rows eliminated), J the iteration
 * matrix at (t, y, yp, cj) of the active terms, or the given column-major n x n matrix A (not
 * NULL); b is overwritten by x. The solver IDA uses, on its own copy: a check against a plain
 * LU. 0 ok, 1 singular, -1 evaluation failed or no memory. */
DC_API int dc_solve_reduced(void* sp, int nk, double t, const double* y, const double* yp, double cj,
                            const double* A, double* b) {
  dc_session* s = (dc_session*)sp;
  SUNMatrix J = SUNDenseMatrix(s->n, s->n, s->ctx);
  SUNLinearSolver LS = J ? rls_create(s->n, s->ctx) : NULL;
  N_Vector x = N_VMake_Serial(s->n, b, s->ctx);
  int rc = -1;
  if (J && A) memcpy(SUNDenseMatrix_Data(J), A, sizeof(double) * (size_t)s->n * (size_t)s->n);
  if (J && LS && x && rls_set_kinematic_rows(LS, nk) == 0 &&
      (A || eval_jac(s, t, y, yp, cj, SUNDenseMatrix_Data(J), 0, 0) == 0)) {
    rc = SUNLinSolSetup(LS, J) != SUN_SUCCESS;
    if (rc == 0) rc = SUNLinSolSolve(LS, J, x, x, 0.0) != SUN_SUCCESS ? -1 : 0;
  }
  if (x) N_VDestroy(x);
  if (LS) SUNLinSolFree(LS);
  if (J) SUNMatDestroy(J);
  return rc;
}

/* Nonzeros of the union pattern. */
DC_API long long dc_jac_nnz(void* sp) { return (long long)((dc_session*)sp)->jp_nnz; }

/* The step IDA tried first after the latest (re)start (first_step() or IDA's estimate). */
DC_API double dc_first_step(void* sp) {
  double h = 0.0;
  return IDAGetActualInitStep(((dc_session*)sp)->ida, &h) < 0 ? 0.0 : h;
}

/* The session's linear solver: DC_LS_DENSE, DC_LS_SPARSE or DC_LS_REDUCED. */
DC_API int dc_linear_solver(void* sp) { return ((dc_session*)sp)->lin_kind; }

/* The union pattern as 64-bit CSC arrays: colptr[n + 1], rowind[dc_jac_nnz]. */
DC_API void dc_jac_pattern(void* sp, long long* colptr, long long* rowind) {
  dc_session* s = (dc_session*)sp;
  for (int c = 0; c <= s->n; ++c) colptr[c] = (long long)s->jp_colptr[c];
  for (dc_int k = 0; k < s->jp_nnz; ++k) rowind[k] = (long long)s->jp_rowind[k];
}

DC_API int dc_eval_roots(void* sp, double t, const double* y, const double* yp, double* g) {
  dc_session* s = (dc_session*)sp;
  if (s->n_roots == 0) return 0;
  return eval_roots(s, t, y, yp, g);
}

/* Set active terms and parameters without restarting IDA (for residual/jacobian checks). */
DC_API void dc_set_terms(void* sp, const int* active, const double* params) {
  dc_session* s = (dc_session*)sp;
  int np = 0;
  for (int k = 0; k < s->n_terms; ++k) {
    s->active[k] = active ? (active[k] != 0) : 0;
    np += dc_model.n_params[k];
  }
  if (np > 0 && params) memcpy(s->params, params, sizeof(double) * (size_t)np);
}
