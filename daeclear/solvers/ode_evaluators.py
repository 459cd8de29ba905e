"""Numeric evaluation of a model's ODE (:func:`~daeclear.solvers.ode_model.ode_spec`) for the non-IDA
methods: the library ``csrc/ode_driver.c`` compiled by :func:`daeclear.engine.codegen.build_ode_library`
through ctypes, or (``backend="python"``, or ``"auto"`` without a C compiler) the same CasADi
functions through ``casadi.FunctionBuffer`` and numpy.
"""

from __future__ import annotations

import ctypes
import weakref
from collections.abc import Sequence
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..assembly.assemble import DAEModel
from ..engine.codegen import (
    BuildResult,
    CompileError,
    CompilerUnavailable,
    OdeSpec,
    build_ode_library,
    densified,
)
from ..engine.abi import DCO_CNT_N, DCO_EULER, FX_CANDIDATE, FX_CHUNK, FX_ERR, FX_MAXSTEPS, FX_TSTOP, ODE_COUNTER_KEYS
from ..engine.library import OdeLibrary
from ..core.errors import DaeclearError, warn_once
from .ode_crossings import candidate
from .ode_model import ode_spec

__all__ = ["FIXED_CHUNK", "FX_CANDIDATE", "FX_CHUNK", "FX_ERR", "FX_MAXSTEPS", "FX_TSTOP", "Evaluator", "evaluator"]

# rows of the fixed-step C loop's step buffer per call; the status of a call is one of FX_* (engine.abi)
FIXED_CHUNK = 8192


class _Shared:
    """What the compiled and the python evaluation of an OdeSpec share."""

    backend = "?"

    def __init__(self, spec: OdeSpec) -> None:
        self.n, self.m, self.nx = spec.n, spec.m, 2 * spec.n
        self.nt, self.ng = len(spec.term_force), spec.n_gaps
        self.poff = np.concatenate([[0], np.cumsum(spec.n_params)]).astype(int)
        self.last_message = ""
        #: what compiled the model (None for the python evaluation)
        self.build: BuildResult | None = None


class _CEvaluator(_Shared):
    backend = "c"

    def __init__(self, spec: OdeSpec, clib: OdeLibrary, build: BuildResult) -> None:
        super().__init__(spec)
        lib = clib.lib
        ints = [ctypes.c_int() for _ in range(4)]
        npar = (ctypes.c_int * max(self.nt, 1))()
        lib.dco_info(*(ctypes.addressof(i) for i in ints), ctypes.addressof(npar))
        got = (ints[0].value, ints[1].value, ints[2].value, ints[3].value, tuple(npar)[:ints[2].value])
        want = (self.n, self.m, self.nt, self.ng, tuple(spec.n_params))
        if got != want:
            raise DaeclearError(f"compiled ODE library {clib.path} does not match the model: {got} != {want}")
        err = ctypes.create_string_buffer(1024)
        self._mass = np.ascontiguousarray(spec.mass, dtype=float)
        self._P = np.ascontiguousarray(spec.parameters, dtype=float)
        h = lib.dco_open(self._mass.ctypes.data, self._P.ctypes.data if self._P.size else None, err, 1024)
        if not h:
            raise DaeclearError(f"opening the compiled ODE model failed: {err.value.decode()}")
        self.lib, self.h, self.build = lib, h, build
        self._finalizer = weakref.finalize(self, lib.dco_free, h)
        nx, ng = self.nx, max(self.ng, 1)
        self._xin, self._xout, self._xa, self._xb = (np.zeros(nx) for _ in range(4))
        self._J, self._g, self._gd = np.zeros((nx, nx)), np.zeros(ng), np.zeros(ng)
        self._act = np.zeros(max(self.nt, 1), dtype=np.int32)
        self._par = np.zeros(max(int(self.poff[-1]), 1))
        self._cnt = np.zeros(DCO_CNT_N, dtype=np.int64)
        self._st, self._sx = np.zeros(FIXED_CHUNK), np.zeros((FIXED_CHUNK, nx))  # the fixed-step loop's buffers
        self._sstar, self._rd = np.zeros(2 * ng), np.zeros(ng, dtype=np.int32)
        self._nst, self._ta, self._tb = ctypes.c_int(), ctypes.c_double(), ctypes.c_double()
        self._a = {k: getattr(self, "_" + k).ctypes.data
                   for k in ("xin", "xout", "J", "g", "gd", "act", "par", "cnt", "st", "sx", "xa", "xb", "sstar", "rd")}
        self._a.update((k, ctypes.addressof(getattr(self, "_" + k))) for k in ("nst", "ta", "tb"))

    def _message(self) -> str:
        return self.lib.dco_message(self.h).decode()

    def set_terms(self, active: Sequence[bool], params: Sequence[NDArray]) -> None:
        if self.nt:
            self._act[:self.nt] = active
            if self.poff[-1]:
                self._par[:self.poff[-1]] = np.concatenate([np.asarray(p, dtype=float).ravel() for p in params])
        self.lib.dco_set_terms(self.h, self._a["act"], self._a["par"])

    def rhs(self, t: float, x: NDArray) -> NDArray:
        self._xin[:] = x
        if self.lib.dco_rhs(self.h, t, self._a["xin"], self._a["xout"]):
            self.last_message = self._message()
        return self._xout.copy()

    def jac(self, t: float, x: NDArray) -> NDArray:
        self._xin[:] = x
        if self.lib.dco_jac(self.h, t, self._a["xin"], self._a["J"]):
            self.last_message = self._message()
        return self._J.copy()

    def gaps(self, t: float, x: NDArray) -> tuple[NDArray, NDArray] | None:
        self._xin[:] = x
        if self.lib.dco_gaps(self.h, t, self._a["xin"], self._a["g"], self._a["gd"]):
            self.last_message = self._message()
            return None
        return self._g[:self.ng].copy(), self._gd[:self.ng].copy()

    def step(self, scheme: int, t: float, x: NDArray, h: float) -> NDArray | None:
        self._xin[:] = x
        if self.lib.dco_step(self.h, scheme, t, self._a["xin"], h, self._a["xout"]):
            self.last_message = self._message()
            return None
        return self._xout.copy()

    def batch(self, t: NDArray, X: NDArray) -> tuple[NDArray, NDArray]:
        t, X = (np.ascontiguousarray(a, dtype=float) for a in (t, X))
        N = t.size
        Xd = np.empty((N, self.nx))
        Lam = np.empty((N, max(self.m, 1)))
        if N:
            self.lib.dco_batch(self.h, N, t.ctypes.data, X.ctypes.data, Xd.ctypes.data, Lam.ctypes.data)
        return Xd, Lam[:, :self.m]

    def fixed(self, scheme: int, t0: float, x0: NDArray, step: float, t_stop: float, max_steps: int,
              rootdir: NDArray | None, hermite: bool) -> dict[str, Any]:
        A = self._a
        self.lib.dco_set_hermite(self.h, 1 if hermite else 0)
        self._xin[:] = x0
        if self.ng:
            self._rd[:] = 0 if rootdir is None else rootdir
        rc = self.lib.dco_fixed(self.h, scheme, t0, A["xin"], step, t_stop, max_steps, A["rd"], FIXED_CHUNK,
                                A["st"], A["sx"], A["nst"], A["ta"], A["xa"], A["tb"], A["xb"], A["sstar"])
        k = self._nst.value
        out: dict[str, Any] = dict(status=rc, st=self._st[:k].copy(), sx=self._sx[:k].copy(),
                                   ta=self._ta.value, xa=self._xa.copy())
        if rc == FX_CANDIDATE:
            out.update(tb=self._tb.value, xb=self._xb.copy(),
                       sstar=self._sstar[:2 * self.ng].reshape(self.ng, 2).copy())
        if rc == FX_ERR:
            self.last_message = self._message()
        return out

    def channels(self, model: DAEModel, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray:
        """Output channels (N, n_channels) at N points with one switch vector, in C."""
        sizes = [ctypes.c_int() for _ in range(3)]
        self.lib.dco_output_sizes(*(ctypes.addressof(c) for c in sizes))
        n_y, n_sw, n_ch = (c.value for c in sizes)
        t, y, yp = (np.ascontiguousarray(a, dtype=float) for a in (t, y, yp))
        sw = np.zeros(max(n_sw, 1))
        sw[:switch.size] = switch
        out = np.empty((t.size, n_ch))
        if n_ch == 0 or y.shape[1] != n_y or switch.size != n_sw or (t.size and self.lib.dco_outputs(
                self.h, t.size, t.ctypes.data, y.ctypes.data, yp.ctypes.data, sw.ctypes.data, out.ctypes.data)):
            return _model_channels(model, t, y, yp, switch)  # no compiled outputs, or they failed
        return out

    def counters(self) -> dict[str, int]:
        self.lib.dco_counters(self.h, self._a["cnt"])
        return dict(zip(ODE_COUNTER_KEYS, map(int, self._cnt)))


class _Buffered:
    """A CasADi function with every input and output on fixed numpy arrays (FunctionBuffer)."""

    def __init__(self, f: ca.Function, parameters: Sequence[float]) -> None:
        self.args = [np.zeros(f.nnz_in(i)) for i in range(f.n_in())]
        self.args[-1][:] = parameters  # the run-time parameters, the last input of every function
        self.outs = [np.zeros(f.nnz_out(i)) for i in range(f.n_out())]
        self.shapes = [f.size_out(i) for i in range(f.n_out())]
        self.buf, self.call = f.buffer()
        for i, a in enumerate(self.args):
            # casadi's stubs want a size and a Buffer; the runtime takes a memoryview of a numpy array
            self.buf.set_arg(i, memoryview(a))  # type: ignore[call-arg, arg-type]
        for i, o in enumerate(self.outs):
            self.buf.set_res(i, memoryview(o))  # type: ignore[call-arg, arg-type]

    def __call__(self, *inputs: Any) -> list[NDArray]:
        for a, value in zip(self.args, inputs):
            a[:] = value
        self.call()
        # dense outputs, column-major
        return [o.reshape(s[1], s[0]).T.copy() if min(s) > 1 else o.copy() for o, s in zip(self.outs, self.shapes)]


class _PyEvaluator(_Shared):
    """The same model evaluated through casadi.FunctionBuffer and numpy (no compiler needed)."""

    backend = "python"

    def __init__(self, spec: OdeSpec) -> None:
        super().__init__(spec)
        P = spec.parameters
        self._sys = _Buffered(densified(spec.sys), P)  # whole arrays (the C driver scatters instead)
        self._sys_jac = _Buffered(densified(spec.sys_jac), P)
        self._gaps = _Buffered(densified(spec.gaps), P) if spec.gaps is not None else None
        self._tf = [_Buffered(densified(f), P) for f in spec.term_force]
        self._tj = [_Buffered(densified(f), P) for f in spec.term_jac]
        self.minv = 1.0 / np.asarray(spec.mass)
        self.active = [False] * self.nt
        self.params: list[NDArray] = [np.zeros(p) for p in spec.n_params]
        self.cnt = dict.fromkeys(ODE_COUNTER_KEYS, 0)  # the C evaluator's counters

    def set_terms(self, active: Sequence[bool], params: Sequence[NDArray]) -> None:
        self.active = [bool(a) for a in active]
        self.params = [np.asarray(p, dtype=float).ravel() for p in params]

    def _accel(self, t: float, x: NDArray) -> tuple[NDArray, NDArray, Any] | None:
        n, m = self.n, self.m
        q, v = x[:n], x[n:]
        Q, P, c = self._sys(t, q, v)
        P = P.reshape(m, n)
        f = Q.ravel().copy()
        for k in range(self.nt):
            if self.active[k]:
                f += self._tf[k](t, q, v, self.params[k])[0].ravel()
        chol = None
        lam = np.zeros(m)
        if m:
            S = (P * self.minv) @ P.T
            try:
                chol = np.linalg.cholesky(S)
            except np.linalg.LinAlgError:
                self.last_message = f"the constraint Jacobian is singular at t={t:.17g}"
                return None
            lam = np.linalg.solve(chol.T, np.linalg.solve(chol, P @ (self.minv * f) - c.ravel()))
        a = self.minv * (f - P.T @ lam)
        return np.concatenate([v, a]), lam, (P, chol)

    def rhs(self, t: float, x: NDArray) -> NDArray:
        self.cnt["n_res_evals"] += 1
        with np.errstate(all="ignore"):
            out = self._accel(t, np.asarray(x, dtype=float))
        if out is None or not np.all(np.isfinite(out[0])):
            if out is not None:
                self.last_message = f"the right-hand side is not finite at t={t:.17g}"
            return np.full(self.nx, np.nan)
        return out[0]

    def jac(self, t: float, x: NDArray) -> NDArray:
        self.cnt["n_jac_evals"] += 1
        n, m, nx = self.n, self.m, self.nx
        x = np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            out = self._accel(t, x)
            if out is None:
                return np.full((nx, nx), np.nan)
            xd, lam, (P, chol) = out
            D = self._sys_jac(t, x[:n], x[n:], xd[n:], lam)[0].reshape(n + m, nx)
            for k in range(self.nt):
                if self.active[k]:
                    D[:n] -= self._tj[k](t, x[:n], x[n:], self.params[k])[0].reshape(n, nx)
            b1, b2 = -D[:n], -D[n:]
            zl = np.zeros((m, nx))
            if m:
                zl = np.linalg.solve(chol.T, np.linalg.solve(chol, P @ (self.minv[:, None] * b1) - b2))
            J = np.zeros((nx, nx))
            J[:n, n:] = np.eye(n)
            J[n:] = self.minv[:, None] * (b1 - P.T @ zl)
        return J

    def gaps(self, t: float, x: NDArray) -> tuple[NDArray, NDArray] | None:
        if self._gaps is None:
            return np.zeros(0), np.zeros(0)
        self.cnt["n_root_evals"] += 1
        g, gd = self._gaps(t, x[:self.n], x[self.n:])
        g, gd = g.ravel(), gd.ravel()
        if not (np.all(np.isfinite(g)) and np.all(np.isfinite(gd))):
            self.last_message = f"a gap function is not finite at t={t:.17g}"
            return None
        return g, gd

    def step(self, scheme: int, t: float, x: NDArray, h: float) -> NDArray | None:
        with np.errstate(all="ignore"):
            k1 = self.rhs(t, x)
            if scheme == DCO_EULER:
                xn = x + h * k1
            else:
                k2 = self.rhs(t + 0.5 * h, x + 0.5 * h * k1)
                k3 = self.rhs(t + 0.5 * h, x + 0.5 * h * k2)
                k4 = self.rhs(t + h, x + h * k3)
                xn = x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if not np.all(np.isfinite(xn)):
            if "not finite" not in self.last_message and "singular" not in self.last_message:
                self.last_message = f"the state became non-finite in the step from t={t:.17g} (h={h:g})"
            return None
        return xn

    def batch(self, t: NDArray, X: NDArray) -> tuple[NDArray, NDArray]:
        N = len(t)
        Xd = np.full((N, self.nx), np.nan)
        Lam = np.full((N, self.m), np.nan)
        with np.errstate(all="ignore"):
            for i in range(N):
                out = self._accel(float(t[i]), X[i])
                if out is not None:
                    Xd[i], Lam[i] = out[0], out[1]
        return Xd, Lam

    def fixed(self, scheme: int, t0: float, x0: NDArray, step: float, t_stop: float, max_steps: int,
              rootdir: NDArray | None, hermite: bool) -> dict[str, Any]:
        """The loop of dco_fixed (csrc/ode_driver.c) in Python."""
        watch = rootdir is not None and self.ng > 0
        ta, xa = t0, np.array(x0, dtype=float)
        st: list[float] = []
        sx: list[NDArray] = []

        def done(status: int, **extra: Any) -> dict[str, Any]:
            return dict(status=status, st=np.array(st), sx=np.array(sx).reshape(len(sx), self.nx),
                        ta=ta, xa=xa.copy(), **extra)

        if watch:
            gg = self.gaps(ta, xa)
            if gg is None:
                return done(FX_ERR)
            g0, gd0 = gg
        k = 0
        while True:
            if ta >= t_stop:
                return done(FX_TSTOP)
            if k >= max_steps:
                return done(FX_MAXSTEPS)
            if len(st) >= FIXED_CHUNK:
                return done(FX_CHUNK)
            tn = t0 + (k + 1) * step
            if tn >= t_stop - 1e-9 * step:
                tn = t_stop
            h = tn - ta
            xb = self.step(scheme, ta, xa, h)
            if xb is None:
                return done(FX_ERR)
            self.cnt["n_fixed_steps"] += 1
            k += 1
            if watch:
                gg = self.gaps(tn, xb)
                if gg is None:
                    return done(FX_ERR)
                g1, gd1 = gg
                sstar = np.full((self.ng, 2), -1.0)
                for i in range(self.ng):
                    for j, d in enumerate((1.0, -1.0)):
                        if rootdir[i] * d >= 0:  # type: ignore[index]
                            sstar[i, j] = candidate(d * g0[i], d * gd0[i], d * g1[i], d * gd1[i], h,
                                                     hermite)
                if np.any(sstar > 0):
                    return done(FX_CANDIDATE, tb=tn, xb=xb, sstar=sstar)
                g0, gd0 = g1, gd1
            st.append(tn)
            sx.append(xb)
            ta, xa = tn, xb

    def channels(self, model: DAEModel, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray:
        return _model_channels(model, t, y, yp, switch)

    def counters(self) -> dict[str, int]:
        return dict(self.cnt)


#: Either evaluation (the same methods; gaps and step return None on failure).
Evaluator = _CEvaluator | _PyEvaluator


def _model_channels(model: DAEModel, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray:
    """Output channels (N, n_channels) through CasADi (no compiled library)."""
    N = t.size
    n_ch = model.outputs.numel_out(0)
    if N == 0:
        return np.zeros((0, n_ch))
    f = model.outputs if N == 1 else model.outputs.map(N)
    S = np.repeat(np.asarray(switch, dtype=float).reshape(-1, 1), N, axis=1)
    out = f(np.asarray(t, dtype=float)[None, :], np.asarray(y).T, np.asarray(yp).T, S, model.parameter_values)
    return np.array(out).reshape(n_ch, N).T


def evaluator(model: DAEModel, backend: str) -> Evaluator:
    """The model's ODE evaluator: compiled (cached per model object and on disk) or python."""
    spec = ode_spec(model)
    compiled = model.compiled.ode_library  # one library per structure
    if backend == "python":
        return _PyEvaluator(spec)
    try:
        if compiled is None:
            build = build_ode_library(spec)
            try:
                clib = OdeLibrary.load(build.path)
            except OSError:
                build.path.unlink(missing_ok=True)  # a damaged cache entry: build once more
                build = build_ode_library(spec)
                clib = OdeLibrary.load(build.path)
            compiled = (clib, build)
            model.compiled.ode_library = compiled
        else:
            clib, build = compiled
            compiled = (clib, BuildResult(build.path, build.key, True, 0.0, 0.0))
        return _CEvaluator(spec, *compiled)
    except (CompilerUnavailable, CompileError, OSError) as exc:
        if backend == "c":
            raise DaeclearError(f"the compiled ODE backend cannot be built or loaded: {exc}") from exc
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        warn_once("daeclear: the compiled right-hand side is unavailable, using casadi.FunctionBuffer "
                  f"and numpy (several times slower). Reason: {reason}", stacklevel=5)
        return _PyEvaluator(spec)
