"""The python IDA session: scikit-sundae's ``IDA`` with ``casadi.FunctionBuffer`` callbacks, the fallback
when no C compiler works; its differences from the compiled session: :mod:`daeclear.engine.ida_session`.
"""

from __future__ import annotations

import contextlib
import io
import math
import time
from typing import Any
from collections.abc import Sequence

import casadi
import numpy as np

from ..core.errors import DaeclearError
from .codegen import NormalizedModel, densified
from .hermite import cubic_hermite
from .session_base import (FLAG_MAX_STEPS, FLAG_STEP_COLLAPSE, OWN_FLAG_NAMES, Advance, ChunkCallback, SessionBase,
                           SessionOptions, output_rows)

__all__ = ["PythonSession"]


class _ModelError(Exception):
    """Raised inside a scikit-sundae callback; ends the advance with a clear message."""


class _Buffered:
    """A CasADi function evaluated through FunctionBuffer on fixed numpy arrays."""

    def __init__(self, f: casadi.Function, args: list[np.ndarray]) -> None:
        self.buf, self.call = f.buffer()
        self.args = args  # kept alive: the buffer points into them
        for i, a in enumerate(args):
            # casadi's stubs want a size and a Buffer; the runtime takes a memoryview of a numpy array
            self.buf.set_arg(i, memoryview(a))  # type: ignore[call-arg, arg-type]
        self.out = np.zeros(f.nnz_out(0))
        self.buf.set_res(0, memoryview(self.out))  # type: ignore[call-arg, arg-type]


class PythonSession(SessionBase):
    """scikit-sundae IDA with FunctionBuffer callbacks (see module docstring)."""

    backend = "python"

    def __init__(self, model: NormalizedModel, opts: SessionOptions, fallback_reason: str | None = None) -> None:
        super().__init__(model, opts)
        import sksundae  # noqa: F401  (fail early if missing)
        n = model.n
        self.fallback_reason = fallback_reason
        # shared input arrays: every function reads t, y, yp, cj from the same memory
        self._a_t = np.zeros(1)
        self._a_y = np.zeros(n)
        self._a_yp = np.zeros(n)
        self._a_cj = np.zeros(1)
        self._a_p = [np.zeros(p) for p in model.n_params]
        P = opts.parameters
        base = [self._a_t, self._a_y, self._a_yp]
        self._res = _Buffered(model.res, base + [P])
        self._jac = _Buffered(densified(model.jac), base + [self._a_cj, P])
        self._tres = [_Buffered(densified(f), base + [p, P]) for f, p in zip(model.term_res, self._a_p)]
        self._tjac = [_Buffered(densified(f), base + [p, self._a_cj, P]) for f, p in zip(model.term_jac, self._a_p)]
        self._roots_fn = _Buffered(model.roots, base + [P]) if model.roots is not None else None
        self._active_idx: list[int] = []
        self._solver: Any = None
        self._solver_dirs: np.ndarray | None = None
        self._count = dict(res=0, jac=0, roots=0, steps=0, reinits=0)
        self._pending_tn = False
        self._t_internal = 0.0

    def _at(self, t: float, y: np.ndarray, yp: np.ndarray) -> None:
        """Set the point every function reads."""
        self._a_t[0] = t
        self._a_y[:] = y
        self._a_yp[:] = yp

    def _with_terms(self, base: _Buffered, terms: list[_Buffered]) -> np.ndarray:
        """``base``'s output plus the active terms' (a copy only when a term is active)."""
        base.call()
        out = base.out
        if self._active_idx:
            out = out.copy()
            for k in self._active_idx:
                terms[k].call()
                out += terms[k].out
        return out

    def _eval_res(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._at(t, y, yp)
        return self._with_terms(self._res, self._tres)

    def _eval_jac(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray:
        self._at(t, y, yp)
        self._a_cj[0] = cj
        nj = self._model.n_jac
        return self._with_terms(self._jac, self._tjac).reshape(nj, nj, order="F")

    def _eval_roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._at(t, y, yp)
        roots = self._roots_fn
        if roots is None:  # the events callback exists only when the model has root functions
            raise _ModelError("the model has no root functions")
        roots.call()
        return roots.out

    def _make_solver(self, rd: np.ndarray) -> Any:
        from sksundae.ida import IDA

        count = self._count
        eval_res, eval_jac, eval_roots = self._eval_res, self._eval_jac, self._eval_roots
        isfinite = math.isfinite
        blocks, nj = self._model.blocks, self._model.n_jac

        def resfn(t, y, yp, res):
            count["res"] += 1
            r = eval_res(t, y, yp)
            if not isfinite(float(r.sum())):
                i = int(np.flatnonzero(~np.isfinite(r))[0])
                raise _ModelError(f"residual component {i} is {r[i]} at t={t!r} (y[{i}]={y[i]})")
            res[:] = r

        def jacfn(t, y, yp, res, cj, JJ):
            count["jac"] += 1
            J = eval_jac(t, y, yp, cj)
            if not isfinite(float(J.sum())):
                raise _ModelError(f"the Jacobian has non-finite entries at t={t!r}")
            if blocks == 1:
                JJ[:, :] = J
            else:  # the block-diagonal Newton matrix, factored whole by scikit-sundae's dense LU (slow path)
                JJ[:, :] = 0.0
                for b in range(blocks):
                    JJ[b * nj:(b + 1) * nj, b * nj:(b + 1) * nj] = J

        options: dict[str, Any] = dict(
            rtol=self._opts.rtol, atol=self._opts.atol.copy(), max_step=self._opts.max_step,
            max_order=self._opts.max_order, max_num_steps=500, jacfn=jacfn, linsolver="dense",
        )
        if self.n_roots:
            def events(t, y, yp, out):
                count["roots"] += 1
                g = eval_roots(t, y, yp)
                if not isfinite(float(g.sum())):
                    raise _ModelError(f"a root function is non-finite at t={t!r}: {g.tolist()}")
                out[:] = g

            # sksundae reads these two attributes of the events function
            events.terminal = [True] * self.n_roots  # type: ignore[attr-defined]
            events.direction = [int(d) for d in rd]  # type: ignore[attr-defined]
            options.update(eventsfn=events, num_events=self.n_roots)
            self._events = events
        return IDA(resfn, **options)

    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None:
        t0, y0, yp0, act, plist, rd = self._check_reinit(t0, y0, yp0, active, params, root_directions)
        self._apply_terms(act, plist)
        dirs = self._solver_dirs
        if self._solver is None or (self.n_roots and (dirs is None or not np.array_equal(rd, dirs))):
            # scikit-sundae sets root directions only when it builds its IDA memory
            self._solver = self._make_solver(rd)
            self._solver_dirs = rd.copy()
        try:
            self._solver.init_step(t0, y0, yp0)
        except (_ModelError, RuntimeError) as exc:
            self._ready = False
            raise DaeclearError(f"IDA reinit failed: {exc}") from exc
        self._count["reinits"] += 1
        self._t, self._y, self._yp = t0, y0.copy(), yp0.copy()
        self._t_internal = t0
        self._pending_tn = False
        self._stall.reset()
        self._ready = True

    def _apply_terms(self, act: np.ndarray, plist: list[np.ndarray]) -> None:
        for k, p in enumerate(plist):
            self._a_p[k][:] = p
        self._active_idx = [k for k in range(self._nt) if act[k]]

    def set_terms(self, active: Sequence[bool], params: Sequence[np.ndarray]) -> None:
        """Set active terms and parameters without restarting IDA (see CSession.set_terms)."""
        _, _, _, act, plist, _ = self._check_reinit(self._t, self._y, self._yp, active, params, None)
        self._apply_terms(act, plist)

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: ChunkCallback | None = None, store_states: bool = True,
                chunked: bool = False, store_yp: bool = True) -> Advance:
        t_stop = self._check_advance(t_stop)
        rows = _Rows(self._select_eval(t_eval, t_stop), self._n, self._t, store_yp)
        outcome = _Outcome()
        tic = time.perf_counter()
        try:
            if t_stop - self._t > 4.0 * np.finfo(float).eps * max(abs(t_stop), abs(self._t)):
                self._step_until(t_stop, rows, outcome, store_steps, chunked)
        finally:
            self._solve_time += time.perf_counter() - tic
        return rows.advance(outcome, self._t, self._y, self._yp)

    def _step_until(self, t_stop: float, rows: _Rows, outcome: _Outcome, store_steps: bool, chunked: bool) -> None:
        """IDA in one-step mode until t_stop, a root, a failure, the step cap or (chunked) a full buffer."""
        while True:
            if self._count["steps"] >= self._opts.max_steps:
                outcome.fail(FLAG_MAX_STEPS, OWN_FLAG_NAMES[FLAG_MAX_STEPS],
                             f"step cap reached: {self._count['steps']} IDA steps in this session "
                             f"(max_steps={self._opts.max_steps}) at t={self._t!r}")
                return
            try:
                r, interpolated = self._ida_step(t_stop)
            except _ModelError as exc:
                outcome.fail(-8, "IDA_RES_FAIL", f"IDA_RES_FAIL at t={self._t!r}: {exc}")
                return
            fl = int(r.status)
            if fl < 0:
                flag_name = _IDA_FLAG_NAMES.get(fl, f"IDA flag {fl}")
                outcome.fail(fl, flag_name, f"{flag_name} at t={float(r.t)!r}: {r.message}")
                self._t, self._y, self._yp = float(r.t), np.array(r.y, float), np.array(r.yp, float)
                return
            t_prev, y_prev, yp_prev = self._t, self._y, self._yp
            fl, new_step, h = self._take_return(r, fl, interpolated)
            filled = rows.interpolate(t_prev, y_prev, yp_prev, self._t, self._y, self._yp)
            if store_steps:
                rows.keep_step(self._t, self._y, self._yp, h)
            if new_step and fl != 1 and not math.isnan(h) and self._stall.step(self._t, h):
                outcome.fail(FLAG_STEP_COLLAPSE, OWN_FLAG_NAMES[FLAG_STEP_COLLAPSE], self._stall.describe(self._t, h))
                return
            if fl == 2:
                outcome.status, outcome.roots = "root", np.asarray(r.i_events[-1], dtype=np.int32).copy()
                ev = getattr(self, "_events", None)
                if ev is not None:  # keep scikit-sundae's event log from growing
                    for name in ("_i", "_t", "_y", "_yp"):
                        getattr(ev, name).clear()
                return
            if fl == 1:
                return  # t_stop reached: status "tstop"
            if chunked and ((rows.te.size and rows.ie == rows.te.size and filled)
                            or len(rows.st) >= self._opts.buffer_steps):
                outcome.status = "chunk"  # the caller empties the rows and calls again
                return

    def _ida_step(self, t_stop: float) -> tuple[Any, bool]:
        """One call of IDA towards t_stop: (its return, whether it only interpolated)."""
        solver = self._solver
        if not self._pending_tn:
            return solver.step(t_stop, method="onestep", tstop=t_stop), False
        # after a root return IDA's tn is beyond self._t; a t_stop inside (self._t, tn) makes
        # IDASetStopTime fail (scikit-sundae prints it): then IDA_NORMAL mode interpolates, as in C
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                return solver.step(t_stop, method="onestep", tstop=t_stop), False
        except RuntimeError as exc:
            if "IDASetStopTime" not in str(exc):
                raise
            return solver.step(t_stop, method="normal", tstop=None), True

    def _take_return(self, r: Any, fl: int, interpolated: bool) -> tuple[int, bool, float]:
        """Move to IDA's returned point: (flag, whether a new internal step was taken, its size or nan)."""
        t_new = float(r.t)
        new_step, h = False, float("nan")
        if interpolated:  # no step taken; IDA still holds tn for the next call
            if fl == 0:
                fl = 1  # y(t_stop) returned: this advance is done
        elif fl == 2:  # root
            if not self._pending_tn:
                new_step = True
                self._count["steps"] += 1
            self._pending_tn = True
        elif self._pending_tn:  # y(tn) returned after a root: no new step
            self._pending_tn = False
            h = t_new - self._t_internal
            self._t_internal = t_new
        elif t_new > self._t:
            new_step = True
            self._count["steps"] += 1
            h = t_new - self._t_internal
            self._t_internal = t_new
        self._t = t_new
        self._y = np.array(r.y, dtype=float).reshape(-1)
        self._yp = np.array(r.yp, dtype=float).reshape(-1)
        return fl, new_step, h

    def residual(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        return self._eval_res(float(t), self._vec(y, "y"), self._vec(yp, "yp")).copy()

    def jacobian(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray:
        self._check_open()
        return np.ascontiguousarray(self._eval_jac(float(t), self._vec(y, "y"), self._vec(yp, "yp"), float(cj)))

    def roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        if self._roots_fn is None:
            return np.empty(0)
        return self._eval_roots(float(t), self._vec(y, "y"), self._vec(yp, "yp")).copy()

    def stats(self) -> dict[str, int | float | str]:
        c = self._count
        unknown = dict.fromkeys(("n_lin_setups", "n_nonlin_iters", "n_nonlin_conv_fails", "n_err_test_fails"), -1)
        return {"n_steps": c["steps"], "n_res_evals": c["res"], "n_jac_evals": c["jac"], **unknown,
                "n_root_evals": c["roots"], "n_reinits": c["reinits"], "n_lu_fallbacks": 0,
                "solve_time": self._solve_time,
                "compile_time": 0.0, "codegen_time": 0.0, "cache_hit": False, "linear_solver": "dense",
                "jac_nnz": self._n * self._n}

    @property
    def linear_solver(self) -> str:
        """Always "dense": scikit-sundae is driven with its dense linear solver here."""
        return "dense"

    def close(self) -> None:
        self._closed = True
        self._solver = None


_IDA_FLAG_NAMES = {
    -1: "IDA_TOO_MUCH_WORK", -2: "IDA_TOO_MUCH_ACC", -3: "IDA_ERR_FAIL", -4: "IDA_CONV_FAIL",
    -5: "IDA_LINIT_FAIL", -6: "IDA_LSETUP_FAIL", -7: "IDA_LSOLVE_FAIL", -8: "IDA_RES_FAIL",
    -9: "IDA_REP_RES_ERR", -10: "IDA_RTFUNC_FAIL", -11: "IDA_CONSTR_FAIL",
    -12: "IDA_FIRST_RES_FAIL", -13: "IDA_LINESEARCH_FAIL", -14: "IDA_NO_RECOVERY",
    -15: "IDA_NLS_INIT_FAIL", -16: "IDA_NLS_SETUP_FAIL", -17: "IDA_NLS_FAIL",
    -20: "IDA_MEM_NULL", -21: "IDA_MEM_FAIL", -22: "IDA_ILL_INPUT", -23: "IDA_NO_MALLOC",
    -24: "IDA_BAD_EWT", -25: "IDA_BAD_K", -26: "IDA_BAD_T", -27: "IDA_BAD_DKY",
    -28: "IDA_VECTOROP_ERR", -29: "IDA_CONTEXT_ERR", -99: "IDA_UNRECOGNIZED_ERROR",
}


class _Outcome:
    """How an advance of the python session ended (``Advance.status`` and its flag)."""

    def __init__(self) -> None:
        self.status, self.flag, self.flag_name, self.message = "tstop", 0, "", ""
        self.roots: np.ndarray | None = None

    def fail(self, flag: int, flag_name: str, message: str) -> None:
        self.status, self.flag, self.flag_name, self.message = "error", flag, flag_name, message


class _Rows:
    """What one advance of the python session reports: output times (cubic Hermite) and IDA's returns."""

    def __init__(self, te: np.ndarray, n: int, t_start: float, store_yp: bool) -> None:
        self.te, self.n = te, n
        self.ev_y = np.empty((te.size, n))
        self.ev_yp = np.empty((te.size, n)) if store_yp else None  # None: no yp computed at the output times
        self.ie = 0  # output times filled so far
        self.st: list[float] = []
        self.sy: list[np.ndarray] = []
        self.syp: list[np.ndarray] = []
        self.sh: list[float] = []
        self.t_rec = t_start  # the last time kept as a step

    def interpolate(self, t_prev: float, y_prev: np.ndarray, yp_prev: np.ndarray, t_new: float,
                    y_new: np.ndarray, yp_new: np.ndarray) -> bool:
        """Fill the output times in (t_prev, t_new]; whether there was any."""
        te, ie = self.te, self.ie
        if not (ie < te.size and te[ie] <= t_new):
            return False
        j = int(np.searchsorted(te, t_new, side="right"))
        if self.ev_yp is None:
            self.ev_y[ie:j] = cubic_hermite(t_prev, y_prev, yp_prev, t_new, y_new, yp_new, te[ie:j])
        else:
            self.ev_y[ie:j], self.ev_yp[ie:j] = cubic_hermite(t_prev, y_prev, yp_prev, t_new, y_new, yp_new,
                                                              te[ie:j], derivative=True)
        self.ie = j
        return True

    def keep_step(self, t: float, y: np.ndarray, yp: np.ndarray, h: float) -> None:
        """Keep an IDA return beyond the last kept one as a step."""
        if t > self.t_rec:
            self.st.append(t)
            self.sy.append(y)
            self.syp.append(yp)
            self.sh.append(h)
            self.t_rec = t

    def advance(self, outcome: _Outcome, t: float, y: np.ndarray, yp: np.ndarray) -> Advance:
        k, n, ie, store_yp = len(self.st), self.n, self.ie, self.ev_yp is not None
        return Advance(
            status=outcome.status, t=t, y=y.copy(), yp=yp.copy(),
            step_t=np.array(self.st, dtype=float), step_y=np.array(self.sy, dtype=float).reshape(k, n),
            step_yp=np.array(self.syp, dtype=float).reshape(k, n) if store_yp else None,
            step_h=np.array(self.sh, dtype=float), step_order=np.full(k, -1, dtype=np.int32),
            eval_t=self.te[:ie].copy(), eval_y=output_rows(self.ev_y, ie),
            eval_yp=None if self.ev_yp is None else output_rows(self.ev_yp, ie), roots_found=outcome.roots,
            flag=outcome.flag, flag_name=outcome.flag_name, message=outcome.message,
        )
