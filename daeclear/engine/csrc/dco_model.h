/*
 * dco_model.h -- the table that daeclear.engine.codegen.build_ode_library appends to the
 * CasADi-generated functions of an index-1 mechanism written as an ODE in x = (q, v),
 * and that the ODE driver (ode_driver.c) reads.
 *
 * Every function takes dense column vectors, the run-time parameters P last; its outputs keep
 * CasADi's sparsity (sparsity_out), and the driver's call() scatters them into dense arrays
 * (matrices column-major). The mass diagonal and P are given to dco_open.
 */
#ifndef DAECLEAR_DCO_MODEL_H
#define DAECLEAR_DCO_MODEL_H

#include "dc_model.h" /* dc_int, dc_fun_t */

typedef struct {
  int n;                     /* generalized coordinates (x has 2n entries) */
  int m;                     /* constraints */
  int n_terms;               /* switchable force terms */
  int n_gaps;                /* gap (root) functions, 0: none */
  int n_parameters;          /* run-time parameters P, the last input of every function */
  const int* n_params;       /* [n_terms] parameters of each term */
  dc_fun_t sys;              /* (t, q, v) -> Q[n], Phi_q[m x n], c[m] (c: Baumgarte right side) */
  dc_fun_t sys_jac;          /* (t, q, v, a, lam) -> d[Phi_q^T lam - Q; Phi_q a - c]/dx, (n+m) x 2n */
  dc_fun_t gaps;             /* (t, q, v) -> g[n_gaps], dg/dt[n_gaps]; eval == 0 when n_gaps == 0 */
  const dc_fun_t* term_force; /* [n_terms] (t, q, v, p) -> F_k[n] */
  const dc_fun_t* term_jac;   /* [n_terms] (t, q, v, p) -> dF_k/dx, n x 2n */
  int n_y, n_switch, n_channels; /* sizes of the outputs function (n_channels 0: none) */
  dc_fun_t outputs;          /* (t, y[n_y], yp[n_y], switch[n_switch]) -> channels[n_channels] */
  const char* name;
} dco_model_t;

extern const dco_model_t dco_model;

#endif
