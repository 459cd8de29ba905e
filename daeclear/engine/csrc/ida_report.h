/*
 * ida_report.h -- the reported points: extras at many points (dc_eval_extra) and a run's points made
 * consistent with their output channels in one pass (dc_report).
 *
 * Part of ida_driver.c's translation unit (it includes every part once, in order; see the
 * overview there): static functions and the dc_* entry points of this job.
 */
#ifndef DAECLEAR_IDA_REPORT_H
#define DAECLEAR_IDA_REPORT_H

#include "ida_consistent.h"

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

#endif
