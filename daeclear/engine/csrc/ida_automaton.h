/*
 * ida_automaton.h -- the contact-mode automaton of one pair (pure: no SUNDIALS, no session).
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_AUTOMATON_H
#define DAECLEAR_IDA_AUTOMATON_H

#include <math.h>
#include <string.h>

#include "dc_abi.h"

/* ------------------------------------------------------------------ contact-mode automaton
 * The C mirror of daeclear/core/automaton.py (step): the decision of one contact pair at a root of
 * its gap. Keep the two identical, branch for branch; tests/test_automaton.py drives both
 * with the same random root sequences through dc_automaton_run. */
/* The decision kinds DC_NONE, DC_ONSET, DC_SEPARATION and DC_SAME_INSTANT (a crossing against the
 * rate closer than this to the pair's last switch, relative to t, is round-off) are the
 * automaton's, in dc_abi.h. */

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

/* whether t is within round-off of the pair's last switch (DC_SAME_INSTANT relative to t) */
static int same_instant(const dc_pair_state* st, double t) {
  return st->n_recent > 0 && t - st->recent[st->n_recent - 1] <= fabs(t) * DC_SAME_INSTANT;
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
  if (dir > 0 && !st->contact && rate < 0 && same_instant(st, t))
    return decision_of(st, DC_NONE); /* the round-off of the gap after a separation, not an onset */
  if (dir > 0 && !st->contact) {
    st->contact = 1;
    st->latched = floor_speed(rate, r->vmin);
    pair_push(r, st, t);
    return decision_of(st, DC_ONSET);
  }
  if (dir < 0 && st->contact && rate > 0 && same_instant(st, t))
    return decision_of(st, DC_NONE); /* the round-off of the gap after an onset, not a separation */
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

#endif
