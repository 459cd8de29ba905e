/*
 * dc_common.h -- the helpers both compiled drivers (ida_driver.c, ode_driver.c) share: their
 * messages, allocation, and the CasADi work memory sized for the largest generated function.
 */
#ifndef DAECLEAR_DC_COMMON_H
#define DAECLEAR_DC_COMMON_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "dc_model.h" /* dc_int, dc_fun_t */

/* length of a session's message buffers (text for Python after a non-success return) */
#define MSG_LEN 1024

/* Format a message into buf (MSG_LEN bytes). */
static void set_msg(char* buf, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_msg(char* buf, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, MSG_LEN, fmt, ap);
  va_end(ap);
}

/* calloc that never asks for zero bytes (a NULL then always means out of memory) */
static void* xcalloc(size_t n, size_t sz) { return calloc(n ? n : 1, sz); }

/* Raise the CasADi work sizes (arguments, results, integer and real work) to those of f. */
static void work_max(const dc_fun_t* f, dc_int* a, dc_int* r, dc_int* iw, dc_int* w) {
  dc_int sa = 0, sr = 0, si = 0, sw = 0;
  f->work(&sa, &sr, &si, &sw);
  if (sa > *a) *a = sa;
  if (sr > *r) *r = sr;
  if (si > *iw) *iw = si;
  if (sw > *w) *w = sw;
}

#endif
