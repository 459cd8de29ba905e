/*
 * ida_events.h -- contact events decided in C: the pairs (dc_set_auto), their decisions at a root and the
 * consistent restart after a switch, the recorded events (dc_take_events).
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_EVENTS_H
#define DAECLEAR_IDA_EVENTS_H

#include "ida_automaton.h"
#include "ida_consistent.h"

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
  s->ev_info = (int*)xcalloc(DC_EV_N * (size_t)ev_cap, sizeof(int));
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
 * info[DC_EV_N * i + DC_EV_*] = kind, contact, held, watch of event i's decision. */
DC_API int dc_take_events(void* sp, int cap, double* t, int* pair, int* info, double* rate,
                          double* latched, double* y) {
  dc_session* s = (dc_session*)sp;
  int k = s->ev_n < cap ? s->ev_n : cap;
  memcpy(t, s->ev_t, sizeof(double) * (size_t)k);
  memcpy(pair, s->ev_pair, sizeof(int) * (size_t)k);
  memcpy(info, s->ev_info, sizeof(int) * DC_EV_N * (size_t)k);
  memcpy(rate, s->ev_rate, sizeof(double) * (size_t)k);
  memcpy(latched, s->ev_latched, sizeof(double) * (size_t)k);
  memcpy(y, s->ev_y, sizeof(double) * (size_t)k * (size_t)s->n);
  s->ev_n -= k;
  if (s->ev_n > 0) { /* the rest stays, oldest first */
    memmove(s->ev_t, s->ev_t + k, sizeof(double) * (size_t)s->ev_n);
    memmove(s->ev_pair, s->ev_pair + k, sizeof(int) * (size_t)s->ev_n);
    memmove(s->ev_info, s->ev_info + DC_EV_N * k, sizeof(int) * DC_EV_N * (size_t)s->ev_n);
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

/* The automaton state of every pair the loop decides (the run's authority for them): contact, held,
 * free_since, latched and the number of recent switch times [n_auto]; recent: each pair's times,
 * oldest first, at the pair's offset in the concatenation of rings of storm_events[p] entries. */
DC_API void dc_get_pairs(void* sp, int* contact, int* held, double* free_since, double* latched, int* n_recent,
                         double* recent) {
  dc_session* s = (dc_session*)sp;
  size_t ring = 0;
  for (int p = 0; p < s->n_auto; ++p) {
    const dc_pair_state* st = &s->pair_state[p];
    contact[p] = st->contact;
    held[p] = st->held;
    free_since[p] = st->free_since;
    latched[p] = st->latched;
    n_recent[p] = st->n_recent;
    memcpy(recent + ring, st->recent, sizeof(double) * (size_t)st->n_recent);
    ring += (size_t)s->pair_rule[p].storm_events;
  }
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
  int switched = 0, guarded = 0;
  for (int i = 0; i < s->n_roots; ++i) {
    int dir = s->rootsfound[i];
    if (!dir) continue;
    int p = s->root_to_auto[i], k = s->auto_term[p];
    const double* in_rate[3] = {q, v, s->P};
    if (eval_extra1(s, s->auto_rate[p], 3, in_rate, gr) != 0) goto eval_failed;
    const int watched = dir == pair_watch(&s->pair_state[p]); /* held pairs watch 0: never */
    dc_decision d = pair_step(&s->pair_rule[p], &s->pair_state[p], t, dir, gr[1]);
    if (d.kind == DC_NONE) {
      guarded |= watched; /* the same-instant guard: restart all the same (see below) */
      continue;
    }
    int* info = s->ev_info + DC_EV_N * (size_t)s->ev_n;
    s->ev_t[s->ev_n] = t;
    s->ev_pair[s->ev_n] = p;
    info[DC_EV_KIND] = d.kind;
    info[DC_EV_CONTACT] = d.contact;
    info[DC_EV_HELD] = d.held;
    info[DC_EV_WATCH] = d.watch;
    s->ev_rate[s->ev_n] = gr[1];
    s->ev_latched[s->ev_n] = d.latched;
    memcpy(s->ev_y + (size_t)s->ev_n * (size_t)n, y, sizeof(double) * (size_t)n);
    ++s->ev_n;
    s->active[k] = d.contact || d.held;
    if (s->auto_needs[p]) s->params[s->param_off[k]] = d.latched;
    s->rootdir[i] = d.watch;
    switched = 1;
  }
  /* A root of the same-instant guard restarts IDA though nothing switched: going on from a root
   * whose gap is exactly zero, IDA fails ("root found at and very near t") when the gap is still
   * zero a root tolerance later; a restart masks such a gap until it moves (solvers/driver.py, guarded_root). */
  if (!switched && !guarded) return 2;
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
  long long cur[DC_ST_N];
  ida_counters(s, cur);
  for (int i = 0; i < DC_ST_N; ++i) s->base[i] += cur[i];
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
  s->base[DC_ST_REINITS] += 1;
  return 1;
eval_failed:
  s->ready = 0;
  set_msg(s->msg, "evaluating the generated contact functions at t=%.17g failed", t);
  return -1;
}

#endif
