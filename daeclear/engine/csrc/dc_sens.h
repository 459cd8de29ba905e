/*
 * dc_sens.h -- the table of the forward sensitivity functions (issue 43) that daeclear's code
 * generator appends to a model's generated source when it is built with sensitivities
 * (daeclear.engine.codegen.generate_source(model, sensitivity=...)). Each function handles
 * `width` parameters at once: its matrix inputs and outputs are n x width, column-major.
 * See daeclear/engine/sensitivity_functions.py and docs/sensitivities.md.
 */
#ifndef DAECLEAR_DC_SENS_H
#define DAECLEAR_DC_SENS_H

#include "dc_model.h"

typedef struct {
  int width;                 /* parameters (columns) per call */
  int n_terms;               /* as dc_model.n_terms */
  int n_extras;              /* directional derivatives of extras in `extras` */
  dc_fun_t res;              /* (t, y, yp, P, S, Sp, dP) -> F_y S + F_yp Sp + F_P dP (n x width) */
  const dc_fun_t* term_res;  /* [n_terms] (t, y, yp, p, P, S, Sp, Sp_k, dP) -> term k's part (n x width) */
  dc_fun_t root_jac;         /* (t, y, yp, P) -> [g_t | g_y | g_yp | g_P] (n_roots x (1 + 2n + n_P)); eval == 0
                                without roots */
  dc_fun_t root_curv;        /* (t, y, yp, ypp, P) -> d2g/dt2 along (yp, ypp) (n_roots): the grazing test */
  const dc_fun_t* extras;    /* [n_extras] (inputs of extra k, their seeds (numel x width)) -> d out (numel x width) */
  const int* extra_index;    /* [n_extras] k of each: dc_extra_tab[k] */
} dc_sens_t;

extern const dc_sens_t dc_sens;

#endif
