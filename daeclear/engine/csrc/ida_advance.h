/*
 * ida_advance.h -- dc_advance: the one-step loop towards t_stop with dense output, step
 * recording, stall detection and roots, in one helper per stage of a step.
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_ADVANCE_H
#define DAECLEAR_IDA_ADVANCE_H

#include "ida_events.h"

/* The arguments of one dc_advance call (see there) and its progress, for the helpers below. */
typedef struct {
  double t_stop;
  const double* t_eval; /* requested output times [n_eval], sorted */
  int n_eval;
  int* i_eval;          /* next output row */
  double* eval_y;
  double* eval_yp;       /* NULL: the caller needs no yp at the output times */
  int store_steps;      /* DC_STORE_* flags, 0: no step buffers */
  int cap;              /* rows of the step buffers (else IDA calls) per call */
  double* st;
  double* sy;
  double* syp;
  double* sh;
  int* sord;
  int* n_stored;
  double* t_out;        /* the state reached */
  double* y_out;
  double* yp_out;
  int* roots_out;
  int* flag_out;
  int i_eval_start;     /* *i_eval at the call */
  int k;                /* step rows written by this call */
  int calls;            /* IDA calls made by this call */
} dc_adv;

/* One step as dc_advance handles it: IDA's flag, the step's end tret, size h and order, the
 * previous return time, the start of its dense-output interval (eval_lo, tret], and IDA's step
 * count after it (nst) and after the step before (nst_prev). */
typedef struct {
  int flag, order;
  double tret, h, t_prev, eval_lo;
  long int nst, nst_prev;
} dc_step;

/* what a stage of a step returns when the advance goes on (not a return code of dc_advance) */
#define ADV_GO_ON 100

/* End the advance with code: *t_out = t, y_out and yp_out the session's state. */
static int adv_stop(dc_session* s, const dc_adv* a, double t, int code) {
  *a->t_out = t;
  copy_state(s, a->y_out, a->yp_out);
  return code;
}

/* Record a return point of IDA (duplicates skipped) in the step buffers. */
static void adv_record(dc_session* s, dc_adv* a, double tret, double h, int order) {
  const int n = s->n, k = a->k;
  if (a->store_steps && tret > s->t_rec) {
    a->st[k] = tret;
    if (a->store_steps & DC_STORE_STATES) {
      memcpy(a->sy + (size_t)k * n, N_VGetArrayPointer(s->yy), sizeof(double) * (size_t)n);
      if (a->syp) memcpy(a->syp + (size_t)k * n, N_VGetArrayPointer(s->yp), sizeof(double) * (size_t)n);
    }
    a->sh[k] = h;
    a->sord[k] = order;
    a->k = k + 1;
    *a->n_stored = a->k;
  }
  if (tret > s->t_rec) s->t_rec = tret;
}

/* A root at the end of a step: decided in C (go on, or DC_CHUNK when a buffer is full), else
 * DC_ROOT with the root info for Python. */
static int adv_root(dc_session* s, dc_adv* a, dc_step* p, int full) {
  IDAGetRootInfo(s->ida, s->rootsfound);
  const int handled = auto_handle_root(s, p->tret, a->t_stop);
  if (handled < 0) return adv_stop(s, a, p->tret, DC_ERR_IDA);
  if (handled) {
    if (handled == 1) IDAGetNumSteps(s->ida, &p->nst_prev); /* counters restarted with IDA */
    if (full || s->ev_n + s->n_auto > s->ev_cap) return adv_stop(s, a, p->tret, DC_CHUNK);
    return ADV_GO_ON;
  }
  memcpy(a->roots_out, s->rootsfound, sizeof(int) * (size_t)s->n_roots);
  return adv_stop(s, a, p->tret, DC_ROOT);
}

/* After a root return IDA's internal time tn lies beyond the returned time. A t_stop inside
 * (t_now, tn) needs no new step: IDA_NORMAL mode checks that interval for further roots and
 * interpolates y(t_stop). (IDASetStopTime would refuse a stop time behind tn.) */
static int adv_inside_last_step(dc_session* s, dc_adv* a) {
  const int n = s->n;
  dc_step p = {0, 0, s->t_now, 0.0, s->t_now, s->t_now, 0, 0};
  s->cb_msg[0] = 0;
  s->ida_msg[0] = 0;
  p.flag = IDASolve(s->ida, a->t_stop, &p.tret, s->yy, s->yp, IDA_NORMAL);
  if (p.flag < 0) {
    char name[64];
    flag_name(p.flag, name, sizeof name);
    *a->flag_out = p.flag;
    set_msg(s->msg, "%s at t=%.17g (interpolating inside the last step): %s%s%s", name, s->t_now,
            s->ida_msg, s->cb_msg[0] ? "; last model error: " : "", s->cb_msg);
    return adv_stop(s, a, s->t_now, DC_ERR_IDA);
  }
  s->t_now = p.tret;
  IDAGetLastStep(s->ida, &p.h);
  IDAGetLastOrder(s->ida, &p.order);
  while (*a->i_eval < a->n_eval && a->t_eval[*a->i_eval] <= p.tret) {
    const double te = a->t_eval[*a->i_eval];
    if (te > p.t_prev) {
      if (IDAGetDky(s->ida, te, 0, s->dky) == 0)
        memcpy(a->eval_y + (size_t)(*a->i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
      if (a->eval_yp && IDAGetDky(s->ida, te, 1, s->dky) == 0)
        memcpy(a->eval_yp + (size_t)(*a->i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
    }
    ++(*a->i_eval);
  }
  adv_record(s, a, p.tret, p.h, p.order);
  *a->t_out = p.tret;
  copy_state(s, a->y_out, a->yp_out);
  if (p.flag == IDA_ROOT_RETURN) {
    IDAGetRootInfo(s->ida, s->rootsfound);
    const int handled = auto_handle_root(s, p.tret, a->t_stop);
    if (handled < 0) return DC_ERR_IDA; /* y_out keeps the state at the root */
    if (handled) return adv_stop(s, a, p.tret, DC_CHUNK); /* decided in C: call again to go on */
    memcpy(a->roots_out, s->rootsfound, sizeof(int) * (size_t)s->n_roots);
    return DC_ROOT;
  }
  s->t_now = a->t_stop; /* IDA_NORMAL returned y(tout) with tret == tout */
  *a->t_out = a->t_stop;
  return DC_TSTOP;
}

/* The next step: the one cut short at the last call (its output times from carry_lo on), or a
 * new IDA step. ADV_GO_ON, or the code that ends the advance (step cap, IDA error). */
static int adv_take_step(dc_session* s, dc_adv* a, dc_step* p) {
  p->tret = p->t_prev = s->t_now;
  p->h = 0.0;
  p->order = 0;
  if (s->carry) { /* resume the step cut short at the last call */
    s->carry = 0;
    p->flag = s->carry_flag;
    p->order = s->carry_order;
    p->h = s->carry_h;
    p->t_prev = s->carry_t_prev;
    p->eval_lo = s->carry_lo;
    p->nst = s->carry_nst;
    p->nst_prev = s->carry_nst_prev;
    return ADV_GO_ON;
  }
  if (s->base[DC_ST_STEPS] + (long long)p->nst_prev >= s->max_steps) {
    set_msg(s->msg, "step cap reached: %lld IDA steps in this session (max_steps=%lld) at t=%.17g",
            s->base[DC_ST_STEPS] + (long long)p->nst_prev, s->max_steps, s->t_now);
    return adv_stop(s, a, s->t_now, DC_ERR_MAXSTEPS);
  }
  s->cb_msg[0] = 0;
  s->ida_msg[0] = 0;
  p->flag = IDASolve(s->ida, a->t_stop, &p->tret, s->yy, s->yp, IDA_ONE_STEP);
  ++a->calls;
  if (p->flag < 0) {
    char name[64];
    flag_name(p->flag, name, sizeof name);
    *a->flag_out = p->flag;
    s->t_now = p->tret;
    set_msg(s->msg, "%s at t=%.17g%s%s%s%s", name, p->tret, s->ida_msg[0] ? ": " : "", s->ida_msg,
            s->cb_msg[0] ? "; last model error: " : "", s->cb_msg);
    return adv_stop(s, a, p->tret, DC_ERR_IDA);
  }
  p->t_prev = s->t_now;
  s->t_now = p->tret;
  IDAGetNumSteps(s->ida, &p->nst);
  IDAGetLastStep(s->ida, &p->h);
  IDAGetLastOrder(s->ida, &p->order);
  p->eval_lo = p->t_prev;
  return ADV_GO_ON;
}

/* Dense output at the requested times in (eval_lo, tret]. When that fills the last output row
 * and further output times may lie in this step, the step is kept for the next call and the
 * rows are handed over now (DC_CHUNK). */
static int adv_dense_output(dc_session* s, dc_adv* a, const dc_step* p) {
  const int n = s->n, n_eval = a->n_eval, i_before = *a->i_eval;
  while (*a->i_eval < n_eval && a->t_eval[*a->i_eval] <= p->tret) {
    const double te = a->t_eval[*a->i_eval];
    if (te > p->eval_lo) {
      const int f0 = IDAGetDky(s->ida, te, 0, s->dky);
      if (f0 == 0) memcpy(a->eval_y + (size_t)(*a->i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
      const int f1 = f0 != 0 ? f0 : a->eval_yp ? IDAGetDky(s->ida, te, 1, s->dky) : 0;
      if (f1 == 0 && a->eval_yp) memcpy(a->eval_yp + (size_t)(*a->i_eval) * n, N_VGetArrayPointer(s->dky), sizeof(double) * (size_t)n);
      if (f0 || f1) {
        *a->flag_out = f0 ? f0 : f1;
        set_msg(s->msg, "IDAGetDky failed at t=%.17g (flag %d): %s", te, *a->flag_out, s->ida_msg);
        return adv_stop(s, a, p->tret, DC_ERR_IDA);
      }
    }
    ++(*a->i_eval);
  }
  if (n_eval > 0 && i_before < n_eval && *a->i_eval == n_eval && a->t_eval[n_eval - 1] < p->tret) {
    s->carry = 1;
    s->carry_flag = p->flag;
    s->carry_order = p->order;
    s->carry_h = p->h;
    s->carry_t_prev = p->t_prev;
    s->carry_lo = a->t_eval[n_eval - 1];
    s->carry_nst = p->nst;
    s->carry_nst_prev = p->nst_prev;
    return adv_stop(s, a, p->tret, DC_CHUNK);
  }
  return ADV_GO_ON;
}

/* Step-size collapse or stall: only for genuinely new steps that did not end at t_stop. A step
 * is tiny below max(DC_TINY_REL*max(1,|t|), stall_step); the count restarts at a clearly normal
 * step (100x that threshold), so a chattering run whose steps hover around the threshold is
 * still caught. */
static int adv_stall(dc_session* s, dc_adv* a, const dc_step* p) {
  if (p->nst > p->nst_prev && p->flag != IDA_TSTOP_RETURN) {
    const double h = p->h, tret = p->tret;
    double thr = fmax(DC_TINY_REL * fmax(1.0, fabs(tret)), s->stall_step);
    if (fabs(h) >= (s->stall_step > 0.0 ? DC_NORMAL_STEP_FACTOR * thr : thr))
      s->tiny = 0;
    else if (fabs(h) < thr && !(fabs(h) > DC_TINY_GROWTH * fabs(s->h_prev)))
      ++s->tiny;
    s->h_prev = h;
    if (s->tiny >= s->stall_count) {
      set_msg(s->msg,
              "step size collapsed: %d steps with |h| < max(%g*max(1,|t|), %g s) that did not "
              "grow (last h=%.3g) at t=%.17g%s%s",
              s->tiny, DC_TINY_REL, s->stall_step, h, tret, s->cb_msg[0] ? "; last model error: " : "",
              s->cb_msg);
      return adv_stop(s, a, tret, DC_ERR_COLLAPSE);
    }
  }
  return ADV_GO_ON;
}

/* A buffer of this call is full: cap step rows (or cap IDA calls without them), or the output
 * rows filled by this call. */
static int adv_full(const dc_adv* a) {
  return (a->store_steps && a->k >= a->cap) || (!a->store_steps && a->calls >= a->cap) ||
         (*a->i_eval >= a->n_eval && *a->i_eval > a->i_eval_start);
}

/*
 * Integrate from the current time towards t_stop (hard stop) in one-step mode.
 *
 * t_eval[*i_eval .. n_eval) are the requested output times, sorted, all > current time; each
 * one reached is written (y via IDAGetDky k=0, yp via k=1 unless eval_yp is NULL) to
 * eval_y/eval_yp row *i_eval and *i_eval advances. If store_steps (DC_STORE_TIMES, with
 * DC_STORE_STATES also y and, unless syp is NULL, yp), every return point of IDA (the end of each
 * internal step; on a root return the root point; duplicates skipped) is written to the step
 * buffers, at most cap rows; *n_stored rows were written.
 *
 * Returns DC_CHUNK when cap rows were written (store_steps), cap IDA calls were made
 * (otherwise), or a step filled the last of the n_eval output rows (so that a caller can hand
 * the output times over in windows and empty the rows between calls): call again. DC_TSTOP /
 * DC_ROOT / errors < 0 otherwise; *t_out, y_out, yp_out hold the state reached, roots_out the
 * root info (DC_ROOT), *flag_out IDA's flag (DC_ERR_IDA).
 */
DC_API int dc_advance(void* sp, double t_stop, const double* t_eval, int n_eval, int* i_eval,
                      double* eval_y, double* eval_yp, int store_steps, int cap, double* st,
                      double* sy, double* syp, double* sh, int* sord, int* n_stored,
                      double* t_out, double* y_out, double* yp_out, int* roots_out,
                      int* flag_out) {
  dc_session* s = (dc_session*)sp;
  dc_adv a = {t_stop, t_eval, n_eval, i_eval, eval_y, eval_yp, store_steps, cap, st, sy, syp, sh, sord,
              n_stored, t_out, y_out, yp_out, roots_out, flag_out, *i_eval, 0, 0};
  dc_step p = {0, 0, 0.0, 0.0, 0.0, 0.0, 0, 0};
  int rc;
  *n_stored = 0;
  *flag_out = 0;
  s->msg[0] = 0;
  *t_out = s->t_now;
  if (!s->ready) {
    set_msg(s->msg, "advance called before reinit (or after a failed reinit)");
    return adv_stop(s, &a, s->t_now, DC_ERR_USAGE);
  }
  /* Nothing to integrate: IDA would refuse an interval below roundoff. */
  if (!s->carry && t_stop - s->t_now <= 4.0 * DBL_EPSILON * fmax(fabs(t_stop), fabs(s->t_now)))
    return adv_stop(s, &a, s->t_now, DC_TSTOP);
  double tn = s->t_now;
  IDAGetCurrentTime(s->ida, &tn);
  if (!s->carry && t_stop < tn) return adv_inside_last_step(s, &a);
  const int flag = s->carry ? 0 : IDASetStopTime(s->ida, t_stop);
  if (flag < 0) {
    *flag_out = flag;
    set_msg(s->msg, "IDASetStopTime(%.17g) failed: %s", t_stop, s->ida_msg);
    return adv_stop(s, &a, s->t_now, DC_ERR_IDA);
  }
  IDAGetNumSteps(s->ida, &p.nst_prev);
  for (;;) {
    if ((rc = adv_take_step(s, &a, &p)) != ADV_GO_ON) return rc;
    if ((rc = adv_dense_output(s, &a, &p)) != ADV_GO_ON) return rc;
    adv_record(s, &a, p.tret, p.h, p.order);
    if ((rc = adv_stall(s, &a, &p)) != ADV_GO_ON) return rc;
    p.nst_prev = p.nst;
    if (p.flag == IDA_ROOT_RETURN) {
      if ((rc = adv_root(s, &a, &p, adv_full(&a))) != ADV_GO_ON) return rc;
      continue;
    }
    if (p.flag == IDA_TSTOP_RETURN) return adv_stop(s, &a, p.tret, DC_TSTOP);
    if (adv_full(&a)) return adv_stop(s, &a, p.tret, DC_CHUNK);
  }
}

#endif
