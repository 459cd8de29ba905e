/*
 * bound_main.c -- the all-C bound of a daeclear IDA run (benchmarks/bench_bound.py builds and runs it).
 *
 * The same run as simulate(...) with no Python in the loop: the model library daeclear built for
 * the scene (CasADi-generated functions and the package's IDA driver, linked against the SUNDIALS
 * libraries of the scikit-sundae wheel) is opened with dlopen, and the session is set up by the
 * very calls simulate made, in its order, with its arguments (bench_bound.py recorded them from a
 * simulate call and wrote them to a setup file: tolerances, linear solver, Jacobian refresh, first
 * step, stall guard, state layout, the consistent start state, the pairs the compiled loop decides
 * itself). Then dc_advance runs to t_end, every step's time and state (y, yp) kept in memory in
 * arrays that grow as a user's program would keep them, and the contact events the loop decided
 * drained after every chunk, as daeclear's loop does. No report pass: only IDA's own states.
 *
 *   bound <model library> <setup file> [repeats]
 *
 * prints the best wall time of the whole run (dc_open to dc_free) and of the advance loop alone,
 * the stored steps, events, IDA's counters and the end state. bound_run() is the same run for a
 * caller in the same process (bench_bound.py, through ctypes).
 *
 * Written for the driver interface DC_ABI_VERSION 10 (daeclear.engine.library.DRIVER_ABI); the
 * program refuses a library of another one.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dc_abi.h" /* DC_CHUNK, DC_TSTOP, DC_ST_N: generated from daeclear/engine/abi.py (csrc on -I) */
#include "dc_api.h" /* the dc_* declarations: generated from daeclear/engine/c_api.py */

#define BOUND_ABI 10

/* the driver's entry points, as dlsym returns them: pointers of the types dc_api.h declares */
typedef struct {
  __typeof__(&dc_abi_version) abi_version;
  __typeof__(&dc_open) open;
  __typeof__(&dc_set_nonlin_conv_coef) nonlin_conv_coef;
  __typeof__(&dc_set_jacobian_refresh) jacobian_refresh;
  __typeof__(&dc_set_first_step) first_step;
  __typeof__(&dc_set_stall) stall;
  __typeof__(&dc_set_layout) layout;
  __typeof__(&dc_reinit) reinit;
  __typeof__(&dc_set_auto) set_auto;
  __typeof__(&dc_advance) advance;
  __typeof__(&dc_take_events) take_events;
  __typeof__(&dc_stats) stats;
  __typeof__(&dc_message) message;
  __typeof__(&dc_free) free_;
} driver_t;

/* One recorded call of the set-up, or the advance loop ("advance"). */
enum { OP_OPEN, OP_NONLIN, OP_JACREF, OP_FIRST, OP_STALL, OP_LAYOUT, OP_REINIT, OP_AUTO, OP_ADVANCE };
#define MAX_ARRAYS 10
typedef struct {
  int kind;
  double d[4];
  long long i[12];
  int len[MAX_ARRAYS];
  double* a[MAX_ARRAYS]; /* the recorded arrays (integer ones converted when called) */
  int* ia[MAX_ARRAYS];
} op_t;

typedef struct {
  int n, n_roots, n_ops;
  op_t ops[32];
} setup_t;

static int fail(char* err, int errlen, const char* what, const char* detail) {
  snprintf(err, (size_t)errlen, "%s%s%s", what, detail ? ": " : "", detail ? detail : "");
  return -1;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------------ the setup file */

/* The array `slot` of op: a count, then that many values (hexadecimal floats: exact). */
static int read_array(FILE* f, op_t* op, int slot) {
  int k;
  if (fscanf(f, "%d", &k) != 1 || k < 0) return -1;
  op->len[slot] = k;
  op->a[slot] = calloc((size_t)(k > 0 ? k : 1), sizeof(double));
  op->ia[slot] = calloc((size_t)(k > 0 ? k : 1), sizeof(int));
  if (!op->a[slot] || !op->ia[slot]) return -1;
  for (int j = 0; j < k; ++j) {
    char tok[64];
    if (fscanf(f, "%63s", tok) != 1) return -1;
    op->a[slot][j] = strtod(tok, NULL);
    op->ia[slot][j] = (int)op->a[slot][j];
  }
  return 0;
}

static int read_numbers(FILE* f, double* d, int nd, long long* i, int ni) {
  char tok[64];
  for (int j = 0; j < nd; ++j) {
    if (fscanf(f, "%63s", tok) != 1) return -1;
    d[j] = strtod(tok, NULL);
  }
  for (int j = 0; j < ni; ++j)
    if (fscanf(f, "%lld", &i[j]) != 1) return -1;
  return 0;
}

static void free_setup(setup_t* s) {
  for (int k = 0; k < s->n_ops; ++k)
    for (int j = 0; j < MAX_ARRAYS; ++j) {
      free(s->ops[k].a[j]);
      free(s->ops[k].ia[j]);
    }
  s->n_ops = 0;
}

/* Lines: "n <states> <root functions>", then one per call in simulate's order (bench_bound.py's write_setup). */
static int read_setup(const char* path, setup_t* s, char* err, int errlen) {
  FILE* f = fopen(path, "r");
  if (!f) return fail(err, errlen, "cannot open the setup file", path);
  memset(s, 0, sizeof(*s));
  char name[32];
  int rc = 0;
  if (fscanf(f, "%31s %d %d", name, &s->n, &s->n_roots) != 3 || strcmp(name, "n") != 0 || s->n < 1 || s->n_roots < 0)
    rc = -1;
  while (rc == 0 && fscanf(f, "%31s", name) == 1) {
    if (s->n_ops == 32) { rc = -1; break; }
    op_t* op = &s->ops[s->n_ops++];
    if (!strcmp(name, "open")) { /* rtol max_step | max_order max_steps linear_solver | atol rootdir P */
      op->kind = OP_OPEN;
      rc = read_numbers(f, op->d, 2, op->i, 3);
      for (int j = 0; rc == 0 && j < 3; ++j) rc = read_array(f, op, j);
    } else if (!strcmp(name, "nonlin_conv_coef") || !strcmp(name, "jacobian_refresh")) {
      op->kind = name[0] == 'n' ? OP_NONLIN : OP_JACREF;
      rc = read_numbers(f, op->d, 1, op->i, 0);
    } else if (!strcmp(name, "first_step")) {
      op->kind = OP_FIRST;
      rc = read_numbers(f, op->d, 0, op->i, 1);
    } else if (!strcmp(name, "stall")) {
      op->kind = OP_STALL;
      rc = read_numbers(f, op->d, 1, op->i, 1);
    } else if (!strcmp(name, "layout")) { /* tol | nq m ggl track_work accel force0 kin outputs project max_iter */
      op->kind = OP_LAYOUT;
      rc = read_numbers(f, op->d, 1, op->i, 10);
    } else if (!strcmp(name, "reinit")) { /* t0 | y0 yp0 active params rootdir */
      op->kind = OP_REINIT;
      rc = read_numbers(f, op->d, 1, op->i, 0);
      for (int j = 0; rc == 0 && j < 5; ++j) rc = read_array(f, op, j);
    } else if (!strcmp(name, "auto")) { /* n_pairs capacity | root term rate needs vmin storm_events
                                           storm_window contact0 held0 latched0 */
      op->kind = OP_AUTO;
      rc = read_numbers(f, op->d, 0, op->i, 2);
      for (int j = 0; rc == 0 && j < 10; ++j) rc = read_array(f, op, j);
    } else if (!strcmp(name, "advance")) { /* t_stop | store cap */
      op->kind = OP_ADVANCE;
      rc = read_numbers(f, op->d, 1, op->i, 2);
    } else {
      rc = -1;
    }
  }
  fclose(f);
  if (rc != 0) {
    free_setup(s);
    return fail(err, errlen, "malformed setup file", path);
  }
  return 0;
}

/* ------------------------------------------------------------------ the driver */

static int load_driver(const char* lib_path, driver_t* D, char* err, int errlen) {
  void* lib = dlopen(lib_path, RTLD_NOW | RTLD_LOCAL);
  if (!lib) return fail(err, errlen, "dlopen failed", dlerror());
#define SYM(field, name)                                                   \
  do {                                                                     \
    *(void**)(&D->field) = dlsym(lib, name);                               \
    if (!D->field) return fail(err, errlen, "symbol missing", name);       \
  } while (0)
  SYM(abi_version, "dc_abi_version");
  SYM(open, "dc_open");
  SYM(nonlin_conv_coef, "dc_set_nonlin_conv_coef");
  SYM(jacobian_refresh, "dc_set_jacobian_refresh");
  SYM(first_step, "dc_set_first_step");
  SYM(stall, "dc_set_stall");
  SYM(layout, "dc_set_layout");
  SYM(reinit, "dc_reinit");
  SYM(set_auto, "dc_set_auto");
  SYM(advance, "dc_advance");
  SYM(take_events, "dc_take_events");
  SYM(stats, "dc_stats");
  SYM(message, "dc_message");
  SYM(free_, "dc_free");
#undef SYM
  if (D->abi_version() != BOUND_ABI) return fail(err, errlen, "the library has another driver ABI than 10", lib_path);
  return 0;
}

/* What the program keeps of a run: every step (time, size, order, y, yp) and every event. */
typedef struct {
  long steps, cap_steps, events, cap_events;
  double *t, *h, *y, *yp, *ev_t, *ev_rate, *ev_latched, *ev_y;
  int *order, *ev_pair, *ev_info;
} run_out_t;

static int grow(void** p, long cap, size_t row) {
  void* q = realloc(*p, (size_t)cap * row);
  if (!q) return -1;
  *p = q;
  return 0;
}

static void free_out(run_out_t* o) {
  free(o->t); free(o->h); free(o->y); free(o->yp); free(o->order);
  free(o->ev_t); free(o->ev_rate); free(o->ev_latched); free(o->ev_y); free(o->ev_pair); free(o->ev_info);
  memset(o, 0, sizeof(*o));
}

static int keep_steps(run_out_t* o, int n, int k, const double* st, const double* sh, const int* so,
                      const double* sy, const double* syp) {
  if (o->steps + k > o->cap_steps) {
    long cap = o->cap_steps ? o->cap_steps : 4096;
    while (cap < o->steps + k) cap *= 2;
    size_t row = sizeof(double) * (size_t)n;
    if (grow((void**)&o->t, cap, sizeof(double)) || grow((void**)&o->h, cap, sizeof(double)) ||
        grow((void**)&o->order, cap, sizeof(int)) || grow((void**)&o->y, cap, row) || grow((void**)&o->yp, cap, row))
      return -1;
    o->cap_steps = cap;
  }
  memcpy(o->t + o->steps, st, sizeof(double) * (size_t)k);
  memcpy(o->h + o->steps, sh, sizeof(double) * (size_t)k);
  memcpy(o->order + o->steps, so, sizeof(int) * (size_t)k);
  memcpy(o->y + o->steps * n, sy, sizeof(double) * (size_t)k * (size_t)n);
  memcpy(o->yp + o->steps * n, syp, sizeof(double) * (size_t)k * (size_t)n);
  o->steps += k;
  return 0;
}

static int take_events(const driver_t* D, void* h, run_out_t* o, int n, int cap) {
  for (;;) {
    if (o->events + cap > o->cap_events) {
      long c = o->cap_events ? 2 * o->cap_events : 256;
      while (c < o->events + cap) c *= 2;
      size_t row = sizeof(double) * (size_t)n;
      if (grow((void**)&o->ev_t, c, sizeof(double)) || grow((void**)&o->ev_rate, c, sizeof(double)) ||
          grow((void**)&o->ev_latched, c, sizeof(double)) || grow((void**)&o->ev_y, c, row) ||
          grow((void**)&o->ev_pair, c, sizeof(int)) || grow((void**)&o->ev_info, c, 4 * sizeof(int)))
        return -1;
      o->cap_events = c;
    }
    long e = o->events;
    int k = D->take_events(h, cap, o->ev_t + e, o->ev_pair + e, o->ev_info + 4 * e, o->ev_rate + e,
                           o->ev_latched + e, o->ev_y + e * n);
    o->events += k;
    if (k < cap) return 0;
  }
}

/* One run: the recorded set-up calls, then dc_advance to t_stop. loop_time: the advance loop alone. */
static int run_once(const driver_t* D, const setup_t* S, run_out_t* o, double* y_end, double* t_end,
                    long long* stats, double* loop_time, char* err, int errlen) {
  const int n = S->n;
  void* h = NULL;
  int rc = 0, ev_cap = 0;
  double *st = NULL, *sh = NULL, *sy = NULL, *syp = NULL, *yout = NULL, *ypout = NULL;
  int *sord = NULL, *roots = calloc((size_t)S->n_roots + 1, sizeof(int));
  memset(o, 0, sizeof(*o));
  *loop_time = 0.0;
  for (int k = 0; k < S->n_ops && rc == 0; ++k) {
    const op_t* op = &S->ops[k];
    switch (op->kind) {
      case OP_OPEN:
        if (h) { rc = fail(err, errlen, "the setup opens two sessions", NULL); break; }
        h = D->open(op->d[0], op->a[0], op->d[1], (int)op->i[0], op->i[1], op->len[1] ? op->ia[1] : NULL,
                    op->len[2] ? op->a[2] : NULL, (int)op->i[2], err, errlen);
        if (!h) rc = -1;
        break;
      case OP_NONLIN: rc = D->nonlin_conv_coef(h, op->d[0]) < 0 ? -1 : 0; break;
      case OP_JACREF: rc = D->jacobian_refresh(h, op->d[0]) < 0 ? -1 : 0; break;
      case OP_FIRST: rc = D->first_step(h, (int)op->i[0]); break;
      case OP_STALL: rc = D->stall(h, op->d[0], (int)op->i[0]); break;
      case OP_LAYOUT:
        rc = D->layout(h, (int)op->i[0], (int)op->i[1], (int)op->i[2], (int)op->i[3], (int)op->i[4], (int)op->i[5],
                       (int)op->i[6], (int)op->i[7], (int)op->i[8], op->d[0], (int)op->i[9]);
        break;
      case OP_REINIT:
        rc = D->reinit(h, op->d[0], op->a[0], op->a[1], op->ia[2], op->a[3], op->ia[4]);
        break;
      case OP_AUTO:
        ev_cap = (int)op->i[1];
        rc = D->set_auto(h, (int)op->i[0], op->ia[0], op->ia[1], op->ia[2], op->ia[3], op->a[4], op->ia[5], op->a[6],
                         op->ia[7], op->ia[8], op->a[9], ev_cap);
        break;
      case OP_ADVANCE: {
        const int cap = (int)op->i[1];
        int i_eval = 0, n_stored = 0, flag = 0, status;
        double t_out = 0.0;
        st = malloc(sizeof(double) * (size_t)cap);
        sh = malloc(sizeof(double) * (size_t)cap);
        sord = malloc(sizeof(int) * (size_t)cap);
        sy = malloc(sizeof(double) * (size_t)cap * (size_t)n);
        syp = malloc(sizeof(double) * (size_t)cap * (size_t)n);
        yout = malloc(sizeof(double) * (size_t)n);
        ypout = malloc(sizeof(double) * (size_t)n);
        if (!roots || !st || !sh || !sord || !sy || !syp || !yout || !ypout) {
          rc = fail(err, errlen, "out of memory", NULL);
          break;
        }
        const double tic = now();
        do {
          status = D->advance(h, op->d[0], NULL, 0, &i_eval, NULL, NULL, (int)op->i[0], cap, st, sy, syp, sh, sord,
                              &n_stored, &t_out, yout, ypout, roots, &flag);
          if (n_stored && keep_steps(o, n, n_stored, st, sh, sord, sy, syp) != 0) status = -100;
          if (ev_cap && status > -100 && take_events(D, h, o, n, ev_cap) != 0) status = -100;
        } while (status == DC_CHUNK);
        *loop_time = now() - tic;
        if (status != DC_TSTOP) {
          char detail[160];
          snprintf(detail, sizeof detail, "dc_advance returned %d (2: a root left to Python) at t=%.9g: %s", status,
                   t_out, status == -100 ? "out of memory" : D->message(h));
          rc = fail(err, errlen, "the run stopped", detail);
          break;
        }
        *t_end = t_out;
        memcpy(y_end, yout, sizeof(double) * (size_t)n);
        D->stats(h, stats);
        break;
      }
      default: rc = fail(err, errlen, "unknown op", NULL);
    }
    if (rc != 0 && err[0] == 0 && h) fail(err, errlen, "a set-up call failed", D->message(h));
  }
  free(st); free(sh); free(sord); free(sy); free(syp); free(yout); free(ypout); free(roots);
  if (h) D->free_(h);
  return rc;
}

/*
 * The run `repeats` times. times[2 r], times[2 r + 1]: wall time of repeat r as a whole (dc_open to
 * dc_free, the kept arrays freed after the clock stops) and of its advance loop; counts: stored steps,
 * events, then IDA's counters (dc_stats, DC_ST_N); y_end[n] (n <= y_len) and *t_end: the end state.
 * Returns 0, or -1 with the reason in err.
 */
int bound_run(const char* lib_path, const char* setup_path, int repeats, double* times, long long* counts,
              double* y_end, int y_len, double* t_end, char* err, int errlen) {
  driver_t D;
  setup_t* S = calloc(1, sizeof(setup_t));
  err[0] = 0;
  if (!S) return fail(err, errlen, "out of memory", NULL);
  if (load_driver(lib_path, &D, err, errlen) != 0 || read_setup(setup_path, S, err, errlen) != 0) {
    free(S);
    return -1;
  }
  int rc = S->n > y_len ? fail(err, errlen, "more states than y_end holds", NULL) : 0;
  for (int r = 0; r < repeats && rc == 0; ++r) {
    run_out_t o;
    const double tic = now();
    rc = run_once(&D, S, &o, y_end, t_end, counts + 2, &times[2 * r + 1], err, errlen);
    times[2 * r] = now() - tic;
    counts[0] = o.steps;
    counts[1] = o.events;
    free_out(&o);
  }
  free_setup(S);
  free(S);
  return rc;
}

#ifndef BOUND_NO_MAIN
int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: %s <model library> <setup file> [repeats]\n", argv[0]);
    return 2;
  }
  const int repeats = argc > 3 ? atoi(argv[3]) : 5;
  if (repeats < 1) {
    fprintf(stderr, "repeats=%s, must be a positive integer\n", argv[3]);
    return 2;
  }
  double* times = calloc((size_t)(2 * repeats), sizeof(double));
  double y_end[4096], t_end = 0.0;
  long long counts[2 + DC_ST_N] = {0};
  char err[512];
  if (!times || bound_run(argv[1], argv[2], repeats, times, counts, y_end, 4096, &t_end, err, sizeof err) != 0) {
    fprintf(stderr, "bound: %s\n", times ? err : "out of memory");
    return 1;
  }
  double best = times[0], best_loop = times[1];
  for (int r = 1; r < repeats; ++r) {
    if (times[2 * r] < best) best = times[2 * r];
    if (times[2 * r + 1] < best_loop) best_loop = times[2 * r + 1];
  }
  printf("wall %.6f s (best of %d), advance loop %.6f s\n", best, repeats, best_loop);
  printf("steps %lld events %lld t_end %.17g\n", counts[0], counts[1], t_end);
  printf("ida n_steps %lld n_res_evals %lld n_jac_evals %lld\n", counts[2], counts[3], counts[4]);
  free(times);
  return 0;
}
#endif
