/*
 * ida_session.h -- the session of the compiled IDA loop: SUNDIALS headers and build checks, the session struct,
 * IDA's error handler and the small helpers every part uses.
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_SESSION_H
#define DAECLEAR_IDA_SESSION_H

#include <float.h>
#include <math.h>
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
#include "dc_api.h" /* the dc_* entry points, generated from daeclear/engine/c_api.py */
/* every exported function is declared there: one defined without a declaration is an error, one that
 * differs from its declaration too (conflicting types) */
#pragma GCC diagnostic error "-Wmissing-prototypes"
#include "dc_abi.h"
#include "dc_common.h"
#include "dc_model.h"
#include "dc_linalg.h"
#include "dc_linsol.h"
#include "dc_reduced_ls.h"
#include "dc_sparse_lu.h"
#include "ida_automaton.h"

#ifndef DC_ABI_VERSION /* given by daeclear.engine.codegen (daeclear.engine.library.DRIVER_ABI) */
#error "compile with -DDC_ABI_VERSION=<daeclear.engine.library.DRIVER_ABI>"
#endif
#ifndef DC_HAVE_SPARSE /* 1 when the wheel's sparse matrix and SuperLU_MT libraries are linked */
#define DC_HAVE_SPARSE 0
#endif
#if !defined(DC_SUNDIALS_MAJOR) || !defined(DC_INDEX_SIZE) /* given by daeclear.engine.codegen */
#error "compile with -DDC_SUNDIALS_MAJOR/_MINOR/_PATCH and -DDC_INDEX_SIZE as daeclear.engine.codegen does"
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

/* the linear solvers of dc_open (DC_LS_*), the return codes, flags and slots of the dc_* calls
 * are in dc_abi.h, generated from daeclear/engine/abi.py */
/* IDA's matrix holds the nonzeros of the union pattern (the sparse LU's values, or SuperLU_MT's
 * SUNSparseMatrix), else it is the dense n x n matrix */
#define LIN_UNION(s) ((s)->lin_kind == DC_LS_SPARSE || (s)->lin_kind == DC_LS_SUPERLU)

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

/* A step is "tiny" when |h| < DC_TINY_REL * max(1, |t|). DC_TINY_MAX tiny steps that did not
 * grow (|h| <= DC_TINY_GROWTH * previous |h|), with no normal step in between, are a collapse of
 * the step size: the loop stops instead of creeping on forever. Tiny steps that keep growing
 * are IDA's start-up doubling after a tiny initial step (0.5 / ||y'||_wrms) and do not count. */
/* The numbers are daeclear.engine.stall_guard's, given as -D defines by the build (one home). */
#if !defined(DC_TINY_REL) || !defined(DC_TINY_MAX) || !defined(DC_TINY_GROWTH) || !defined(DC_NORMAL_STEP_FACTOR)
#error "build with daeclear.engine.stall_guard.c_defines(): -DDC_TINY_REL=... -DDC_TINY_MAX=... -DDC_TINY_GROWTH=... -DDC_NORMAL_STEP_FACTOR=..."
#endif

typedef struct {
  SUNContext ctx;
  void* ida;
  N_Vector yy, yp, atol, dky;
  SUNMatrix A;        /* IDA's matrix: dense (dense, reduced), the union values (sparse), SUNSparseMatrix (superlu) */
  SUNLinearSolver LS; /* IDA's solver: dcls_sun_create's wrapper of lin */
  dc_linsol* lin;     /* the factorisation IDA's setup makes and every solve uses (dc_linsol.h) */
  int n, n_terms, n_roots;
  /* The Newton matrix: blocks diagonal copies of the nj x nj iteration matrix the Jacobian functions
   * give (n = blocks nj). blocks 1: an ordinary model. blocks > 1: the forward sensitivities' stacked
   * [y; S_1; ...] (IDAS' simultaneous corrector), factored once at nj and solved block by block. */
  int nj, blocks;
  /* blocks > 1 with dc_model.cpl: the Newton matrix is block lower triangular, its blocks below the first
   * block column applied by dc_model.cpl at the point of the last Jacobian (a modified Newton's matrix) */
  int coupled;
  double cpl_t, cpl_cj;
  double* cpl_y;    /* [n] y and y' of the last Jacobian */
  double* cpl_yp;   /* [n] */
  double* cpl_out;  /* [n - nj] C dy0 */
  double* cpl_tmp;  /* [n - nj] a term's part of it */
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
  int lin_kind;            /* DC_LS_*: see LIN_UNION */
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
  long long base[DC_ST_N]; /* counters accumulated over earlier reinit segments */
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
  int* ev_info;       /* [ev_cap * DC_EV_N] the decision: kind, contact, held, watch (DC_EV_*) */
  double* ev_rate;    /* penetration rate at the event */
  double* ev_latched; /* the pair's latched approach speed after the event */
  double* ev_y;       /* [ev_cap * n] state at the event */
  /* the state layout and the extras that make states consistent in C (dc_set_layout) */
  int lay_ready;
  int lay_nq, lay_m;  /* y = [q (nq), v (nq), lambda (m), mu (m, GGL), work (1, track)] */
  int lay_ggl, lay_track;
  int lay_accel, lay_force0, lay_kin, lay_outputs; /* extras, see daeclear/assembly/dae_model.py EXTRA_* */
  int lay_n_switch, lay_n_channels;
  int proj_on;        /* restarts after a switch decided in C: project q and v on the manifold */
  int proj_iter;
  double proj_tol;    /* |Phi| < proj_tol * max(1, |q|) ends the position Newton */
  double* lay_buf;    /* Qc, a spare (nq each), sol (nq + m + 1), K (2m + m nq), G (m m), x (m), par, channels */
  const double** xarg; /* CasADi work memory for the extras, sized for the largest (dc_set_layout) */
  double** xres;
  dc_int* xiw;
  double* xw;
  double* xnz;        /* the nonzeros of a sparse extra's output, before extra_dense scatters them */
  int* lay_on;        /* [n_terms] */
  /* Newton's own weights (ida_newton.h, dc_set_newton_atol): rows out of IDA's error test kept in its
   * Newton convergence test (a run's sensitivities, as IDAS' errconS = false) */
  SUNNonlinearSolver nls;       /* the wrapper IDA calls; NULL until dc_set_newton_atol */
  SUNNonlinearSolver nls_inner; /* SUNDIALS' Newton solver it delegates to */
  N_Vector nls_w;               /* [n] the weights it passes on */
  double* nls_atol;             /* [n] > 0: that row's Newton weight is 1/(rtol |y| + atol); else IDA's */
  int nls_on;                   /* 0: the wrapper passes IDA's weights on unchanged */
} dc_session;

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

/* ---------------------------------------------------------------- helpers ---- */

static void ida_counters(dc_session* s, long long* out) {
  long int v = 0;
  for (int i = 0; i < DC_ST_N; ++i) out[i] = 0;
  if (!s->ida) return;
  if (IDAGetNumSteps(s->ida, &v) == 0) out[DC_ST_STEPS] = v;
  if (IDAGetNumResEvals(s->ida, &v) == 0) out[DC_ST_RES] = v;
  if (IDAGetNumJacEvals(s->ida, &v) == 0) out[DC_ST_JAC] = v;
  if (IDAGetNumLinSolvSetups(s->ida, &v) == 0) out[DC_ST_LSETUP] = v;
  if (IDAGetNumNonlinSolvIters(s->ida, &v) == 0) out[DC_ST_NNI] = v;
  if (IDAGetNumNonlinSolvConvFails(s->ida, &v) == 0) out[DC_ST_NCF] = v;
  if (IDAGetNumErrTestFails(s->ida, &v) == 0) out[DC_ST_NETF] = v;
  if (IDAGetNumGEvals(s->ida, &v) == 0) out[DC_ST_GEVALS] = v;
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


static void copy_state(dc_session* s, double* y_out, double* yp_out) {
  memcpy(y_out, N_VGetArrayPointer(s->yy), sizeof(double) * (size_t)s->n);
  memcpy(yp_out, N_VGetArrayPointer(s->yp), sizeof(double) * (size_t)s->n);
}

#endif
