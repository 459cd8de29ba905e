"""The same assembled model integrated by other schemes than IDA, for accuracy studies.

``simulate(..., method=...)`` dispatches here for every method but ``"ida"``:

* explicit adaptive (scipy): ``"RK45"``, ``"DOP853"``;
* implicit (scipy): ``"Radau"``, ``"BDF"``, ``"LSODA"`` (with the generated Jacobian);
* fixed step: ``"rk4"`` (classical Runge-Kutta) and ``"euler"`` (explicit Euler), with ``step=``.

The model
---------
The index-1 DAE is an ODE in ``x = (q, v)``: ``q' = v``, ``v' = a(t, q, v)`` with ``a`` and the
multipliers from the linear system of the chapter's formulation (Baumgarte, alpha = beta = 5 by
default, the values the model was assembled with)::

    [M  Phi_q^T] [a  ]   [Q + sum of the active contact terms' forces]
    [Phi_q   0 ] [lam] = [gamma - 2 alpha Phi' - beta^2 Phi          ]

The GGL formulation is IDA-only. The right-hand side, its Jacobian ``dx'/dx`` (implicit
differentiation of the same system) and the gap functions with their time derivatives are
generated as C (:func:`daeclear.engine.codegen.build_ode_library`, ``csrc/ode_driver.c``: the Schur
complement ``Phi_q M^-1 Phi_q^T`` solved by Cholesky, M diagonal) and called through ctypes,
about 1.5 us per call from Python; an inactive contact term is never evaluated. The fixed-step
schemes run their whole step loop in C. ``backend="python"`` (or ``"auto"`` without a working C
compiler) evaluates the same functions through ``casadi.FunctionBuffer`` and numpy instead.

Events
------
The same contact logic objects as IDA (``model.contacts``): each segment watches every gap in the
direction ``logic.root_directions(active)`` gives (+1 increasing, -1 decreasing, 0 both, as IDA),
and at an event ``logic.on_roots`` gets ``roots_found`` with the direction of the crossing (+1/-1)
and switches the modes. The ODE state (q, v) is kept at a restart (it is consistent by
construction) and the integrator restarts from the event time with fresh history (scipy: a new
solver object with its own initial step selection; passing the last step size instead was
measured and gained nothing).

A step may contain a crossing of a watched gap, G = direction * g from <= 0 to > 0, when G has
changed sign over the step, *or* when the cubic Hermite interpolant of G built from G and dG/dt
at the two ends of the step has an interior maximum above zero. The second test is what keeps
quick re-contacts (a contact that closes and opens again within one step, docs/performance.md)
from being stepped over: such a predicted excursion is checked on the scheme's own state at the
predicted maximum and becomes an event when it is confirmed. Residual risk: an excursion that the
cubic does not predict (a gap with large higher derivatives over the step) is still missed.
Measured on the chapter's slider-crank (benchmarks/bench_methods.py): its contacts last 40 us or
more, so over two revolutions the naive end-of-step test finds the same events as the Hermite test
with rk4 at 1e-5 and 4e-5 s, and 87 instead of 91 with DOP853 at rtol 1e-6 (72 against 74 with
RK45 at 1e-4); the test costs no measurable time.

Just after an event the newly watched G is at rounding level (|g| ~ 1e-19 m) and moving away from
zero; the error of an interpolant (or of a tiny re-step) could then fake a crossing right at the
start of the next step, which DOP853 did when one long free-flight step ended inside the bearing
wall. When G starts downwards, the bracket therefore starts where the state confirms G < 0 (at the
cubic's first minimum, or at 1/4, 1/16, ... of it).

The crossing is located by the Illinois variant of regula falsi on a bracket whose far end is
always past the crossing, down to ``100 eps (|t| + |h|)`` (IDA's root tolerance). The state at the
event is the far end of the final bracket (the gap has changed sign, as IDA returns it), taken
from

* scipy methods: the solver's dense output on the step;
* rk4 / euler: a re-step of size ``t - t_k`` from the start of the step: the scheme's own state
  at the event time. Event times are therefore not quantised to the step; after the event the
  fixed-step grid continues from the event time (the last step before ``t_end`` is shortened to
  land on it).

Output
------
Without ``t_eval`` the result holds every accepted step (and every event point); with
``t_eval`` the scipy methods use their dense output and the fixed-step schemes a cubic Hermite
interpolant between steps. Multipliers and accelerations at output points are recomputed from
(t, q, v) with the segment's active terms. Statistics: ``n_steps`` (accepted steps),
``n_res_evals`` (right-hand side evaluations: scheme stages, event location re-steps; output
points not counted), ``n_jac_evals``, ``n_root_evals`` (gap evaluations), ``n_lu`` (Radau, BDF),
``n_events``, ``n_restarts``, ``solve_time``, ``setup_time``.

Failures (``success=False`` with a message that says when, which pairs were in contact and why):
the scheme's own failure (scipy's step-size underflow, a singular Newton matrix), a non-finite
state or right-hand side, a step-size collapse (``TINY_STEP_COUNT`` steps below
``TINY_STEP_REL * max(1, |t|)``), ``max_steps`` accepted steps, or an event loop that does not
advance (``STALL_EVENTS`` events at the same time).
"""

from __future__ import annotations

import ctypes
import dataclasses
import math
import os
import re
import time
import warnings
import weakref
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..assembly.assemble import DAEModel, assemble
from ..engine.hermite import cubic_hermite
from ..engine.library import OdeLibrary
from ..engine.codegen import (BuildResult, CompileError, CompilerUnavailable, OdeSpec, build_ode_library,
                      memo_get, memo_put, memo_table)
from .. import options
from . import physics
from ..errors import DaeclearError, DaeclearWarning, Interrupted, SceneError, SolveError
from .recorder import Recorder
from ..progress import Progress
from .tolerances import tolerance_vector
from ..results.result import ContactEvent, Result
from ..model.scene import Scene

__all__ = [
    "METHOD_NAMES",
    "SCIPY_METHODS",
    "FIXED_STEP_METHODS",
    "check_step",
    "ode_spec",
    "integrate",
]

#: lower-case method name -> the name reported in Result.method
METHOD_NAMES: dict[str, str] = {
    "rk45": "RK45", "dop853": "DOP853", "radau": "Radau", "bdf": "BDF", "lsoda": "LSODA",
    "rk4": "rk4", "euler": "euler",
}
SCIPY_METHODS: tuple[str, ...] = ("rk45", "dop853", "radau", "bdf", "lsoda")
IMPLICIT_METHODS: tuple[str, ...] = ("radau", "bdf", "lsoda")
#: fixed-step methods and their C scheme codes (= their order)
FIXED_STEP_METHODS: dict[str, int] = {"rk4": 4, "euler": 1}
_ORDER = {"rk45": 5, "dop853": 8, "radau": 5, "bdf": -1, "lsoda": -1, "rk4": 4, "euler": 1}

# step-size collapse: TINY_STEP_COUNT consecutive accepted steps below TINY_STEP_REL * max(1, |t|)
TINY_STEP_REL = 1e-14
TINY_STEP_COUNT = 20
# an event loop that produces STALL_EVENTS events without the time advancing is a failure
STALL_EVENTS = 50
# Look for gap crossings inside a step from the cubic Hermite interpolant of the gap (True), or
# only from sign changes at the step ends (False: the naive check, kept for measurements).
HERMITE_GAP_CHECK = True
# rows of the fixed-step C loop's step buffer per call
FIXED_CHUNK = 8192
_EPS = float(np.finfo(float).eps)

_FX_CHUNK, _FX_TSTOP, _FX_CANDIDATE, _FX_ERR, _FX_MAXSTEPS = 0, 1, 2, -1, -2


# =========================================================================== validation


def check_step(method: str, step: Any) -> float | None:
    """Validate ``step`` for ``method`` (lower-case): required by rk4/euler, rejected otherwise."""
    if method in FIXED_STEP_METHODS:
        if step is None:
            raise SceneError(f"simulate: method={METHOD_NAMES[method]!r} is a fixed-step scheme and needs "
                             "step=<step size in s> (the chapter uses 1e-5 s).")
        return options.step(step)
    if step is not None:
        name = METHOD_NAMES.get(method, method)
        raise SceneError(f"simulate: step={step!r} is only for the fixed-step methods "
                         f"({', '.join(repr(m) for m in FIXED_STEP_METHODS)}); method={name!r} chooses its "
                         "own steps (use max_step to bound them).")
    return None


# =========================================================================== symbolic ODE


def ode_spec(model: DAEModel) -> OdeSpec:
    """The model's index-1 equations as an ODE in x = (q, v): the functions the C driver needs.

    Raises SceneError for a GGL model, or when a gap function depends on anything but (t, q).
    """
    if model.formulation != "index1":
        raise SceneError(f"simulate: formulation={model.formulation!r} is integrated by IDA only; the other "
                         "methods integrate the chapter's index-1 formulation (formulation='index1').")
    if getattr(model, "track_work", False) or model.n_states != 2 * model.n_q + model.n_constraints:
        raise SceneError(f"simulate: model '{model.scene_name}' has states besides q, v and the multipliers "
                         "(track_work); only method='ida' integrates it.")
    spec = memo_get(_SPEC_BY_FUNCTIONS, model.functions)
    if spec is None:  # once per structure: models of the same structure share their functions
        spec = _symbolic_spec(model)
        memo_put(_SPEC_BY_FUNCTIONS, model.functions, spec)
    return dataclasses.replace(spec, mass=tuple(float(mk) for mk in model.mass_diagonal),
                               parameters=tuple(float(x) for x in model.parameter_values))


_SPEC_BY_FUNCTIONS = memo_table()


def _symbolic_spec(model: DAEModel) -> OdeSpec:
    """The functions of :func:`ode_spec`, every number a run-time parameter (P last)."""
    n, m = model.n_q, model.n_constraints
    t = ca.SX.sym("t")
    q = ca.SX.sym("q", n)
    v = ca.SX.sym("v", n)
    P = ca.SX.sym("P", model.parameter_values.size)
    x = ca.vertcat(q, v)
    Phi, Phi_q, Phi_dot, gamma = model.kinematics(q, v, t, P)
    offsets = dict(zip(model.parameter_names, np.cumsum([0] + [size for _, size in model.parameter_layout])))
    alpha, beta = P[int(offsets["baumgarte.alpha"])], P[int(offsets["baumgarte.beta"])]
    c = gamma - 2.0 * alpha * Phi_dot - beta ** 2 * Phi
    Q = model.base_force(t, q, v, P)
    sys_f = ca.Function("sys", [t, q, v, P], [ca.densify(Q), ca.densify(Phi_q), ca.densify(c)])
    a = ca.SX.sym("a", n)
    lam = ca.SX.sym("lam", m)
    r = ca.vertcat(ca.mtimes(Phi_q.T, lam) - Q, ca.mtimes(Phi_q, a) - c)
    sys_jac = ca.Function("sys_jac", [t, q, v, a, lam, P], [ca.densify(ca.jacobian(r, x))])
    forces, jacs, n_params = [], [], []
    for k, term in enumerate(model.terms):
        p = ca.SX.sym("p", term.n_params)
        F = term.force(t, q, v, p, P)
        forces.append(ca.Function(f"term{k}", [t, q, v, p, P], [ca.densify(F)]))
        jacs.append(ca.Function(f"term{k}_jac", [t, q, v, p, P], [ca.densify(ca.jacobian(F, x))]))
        n_params.append(term.n_params)
    gaps = None
    if model.functions.roots is not None and model.gap_names:
        n_rest = model.n_states - 2 * n
        rest = ca.SX.sym("lam", n_rest)
        yp = ca.SX.sym("yp", model.n_states)
        g = model.functions.roots(t, ca.vertcat(q, v, rest), yp, P)
        for label, sym in (("velocities", v), ("multipliers", rest), ("derivatives", yp)):
            if sym.numel() and ca.depends_on(g, sym):
                raise SceneError(f"simulate: the gap functions of model '{model.scene_name}' depend on {label}; "
                                 "only method='ida' integrates such a model.")
        g_dot = ca.mtimes(ca.jacobian(g, q), v) + ca.jacobian(g, t)
        gaps = ca.Function("gaps", [t, q, v, P], [ca.densify(g), ca.densify(g_dot)])
    return OdeSpec(n=n, m=m, mass=tuple(float(mk) for mk in model.mass_diagonal), sys=sys_f, sys_jac=sys_jac,
                   gaps=gaps, term_force=tuple(forces), term_jac=tuple(jacs), n_params=tuple(n_params),
                   name=model.functions.name, outputs=model.outputs, n_parameters=int(P.numel()))


def _candidate(G0: float, Gd0: float, G1: float, Gd1: float, h: float, hermite: bool = True) -> float:
    """Far-side point s* in (0, h] of a possible crossing of G from <= 0 to > 0 within a step.

    h when G1 > 0, or the first interior maximum of the cubic Hermite interpolant of G that lies
    above zero (if earlier); -1 when no crossing is expected. Same rule as candidate() in
    csrc/ode_driver.c.
    """
    if G0 > 0.0:
        return -1.0
    best = h if G1 > 0.0 else -1.0
    if not hermite or max(G0, G1) + 0.15 * h * (abs(Gd0) + abs(Gd1)) <= 0.0:
        return best
    for u, is_max, p in _cubic_extrema(G0, Gd0, G1, Gd1, h):
        if is_max and p > 0.0 and (best < 0.0 or u * h < best):
            best = u * h
    return best


def _cubic_extrema(G0: float, Gd0: float, G1: float, Gd1: float, h: float) -> list[tuple[float, bool, float]]:
    """Interior extrema (u in (0, 1), is_maximum, value), in order, of the cubic Hermite interpolant
    of G on a step of size h from G and dG/dt at its ends."""
    a0, a1 = h * Gd0, h * Gd1
    A = 6.0 * G0 + 3.0 * a0 - 6.0 * G1 + 3.0 * a1
    B = -6.0 * G0 - 4.0 * a0 + 6.0 * G1 - 2.0 * a1
    C = a0
    us: list[float] = []
    if abs(A) <= 1e-12 * (abs(B) + abs(C)):
        if B != 0.0:
            us.append(-C / B)
    else:
        disc = B * B - 4.0 * A * C
        if disc >= 0.0:
            sq = math.sqrt(disc)
            qq = -0.5 * (B + (sq if B >= 0.0 else -sq))
            us.append(qq / A)
            if qq != 0.0:
                us.append(C / qq)
    out = []
    for u in sorted(us):
        if 0.0 < u < 1.0 and 2.0 * A * u + B != 0.0:
            u2, u3 = u * u, u * u * u
            p = (2 * u3 - 3 * u2 + 1) * G0 + (u3 - 2 * u2 + u) * a0 + (-2 * u3 + 3 * u2) * G1 + (u3 - u2) * a1
            out.append((u, 2.0 * A * u + B < 0.0, p))
    return out


# =========================================================================== evaluators


#: ctypes view of one compiled ODE library (opened, declared and checked in daeclear.engine.library)
_CLib = OdeLibrary


class _Evaluator:
    """Common interface of the compiled and the python evaluation of an OdeSpec."""

    backend = "?"

    def __init__(self, spec: OdeSpec) -> None:
        self.spec = spec
        self.n, self.m = spec.n, spec.m
        self.nx = 2 * spec.n
        self.nt = len(spec.term_force)
        self.ng = spec.n_gaps
        self.poff = np.concatenate([[0], np.cumsum(spec.n_params)]).astype(int)
        self.last_message = ""

    def _pcat(self, params: Sequence[NDArray]) -> NDArray:
        out = np.zeros(max(int(self.poff[-1]), 1))
        for k in range(self.nt):
            if self.poff[k + 1] > self.poff[k]:
                out[self.poff[k]:self.poff[k + 1]] = np.asarray(params[k], dtype=float).ravel()
        return out


class _CEvaluator(_Evaluator):
    backend = "c"

    def __init__(self, spec: OdeSpec, clib: _CLib, build: BuildResult) -> None:
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
        self._xin = np.zeros(nx)
        self._xout = np.zeros(nx)
        self._J = np.zeros((nx, nx))
        self._g = np.zeros(ng)
        self._gd = np.zeros(ng)
        self._act = np.zeros(max(self.nt, 1), dtype=np.int32)
        self._par = np.zeros(max(int(self.poff[-1]), 1))
        self._cnt = np.zeros(4, dtype=np.int64)
        self._a = {k: getattr(self, "_" + k).ctypes.data for k in ("xin", "xout", "J", "g", "gd", "act", "par", "cnt")}
        # fixed-step loop buffers
        self._st = np.zeros(FIXED_CHUNK)
        self._sx = np.zeros((FIXED_CHUNK, nx))
        self._xa = np.zeros(nx)
        self._xb = np.zeros(nx)
        self._sstar = np.zeros(2 * ng)
        self._rd = np.zeros(ng, dtype=np.int32)
        self._nst = ctypes.c_int()
        self._ta = ctypes.c_double()
        self._tb = ctypes.c_double()
        for k in ("st", "sx", "xa", "xb", "sstar", "rd"):
            self._a[k] = getattr(self, "_" + k).ctypes.data
        self._a["nst"] = ctypes.addressof(self._nst)
        self._a["ta"] = ctypes.addressof(self._ta)
        self._a["tb"] = ctypes.addressof(self._tb)

    def message(self) -> str:
        return self.lib.dco_message(self.h).decode()

    def set_terms(self, active: Sequence[bool], params: Sequence[NDArray]) -> None:
        if self.nt:
            self._act[:self.nt] = [1 if a else 0 for a in active]
            self._par[:] = self._pcat(params)
        self.lib.dco_set_terms(self.h, self._a["act"], self._a["par"])

    def rhs(self, t: float, x: NDArray) -> NDArray:
        self._xin[:] = x
        if self.lib.dco_rhs(self.h, t, self._a["xin"], self._a["xout"]):
            self.last_message = self.message()
        return self._xout.copy()

    def jac(self, t: float, x: NDArray) -> NDArray:
        self._xin[:] = x
        if self.lib.dco_jac(self.h, t, self._a["xin"], self._a["J"]):
            self.last_message = self.message()
        return self._J.copy()

    def gaps(self, t: float, x: NDArray) -> tuple[NDArray, NDArray] | None:
        self._xin[:] = x
        if self.lib.dco_gaps(self.h, t, self._a["xin"], self._a["g"], self._a["gd"]):
            self.last_message = self.message()
            return None
        return self._g[:self.ng].copy(), self._gd[:self.ng].copy()

    def step(self, scheme: int, t: float, x: NDArray, h: float) -> NDArray | None:
        self._xin[:] = x
        if self.lib.dco_step(self.h, scheme, t, self._a["xin"], h, self._a["xout"]):
            self.last_message = self.message()
            return None
        return self._xout.copy()

    def batch(self, t: NDArray, X: NDArray) -> tuple[NDArray, NDArray]:
        t = np.ascontiguousarray(t, dtype=float)
        X = np.ascontiguousarray(X, dtype=float)
        N = t.size
        Xd = np.empty((N, self.nx))
        Lam = np.empty((N, max(self.m, 1)))
        if N:
            self.lib.dco_batch(self.h, N, t.ctypes.data, X.ctypes.data, Xd.ctypes.data, Lam.ctypes.data)
        return Xd, Lam[:, :self.m]

    def fixed(self, scheme: int, t0: float, x0: NDArray, step: float, t_stop: float, max_steps: int,
              rootdir: NDArray | None) -> dict[str, Any]:
        A = self._a
        self.lib.dco_set_hermite(self.h, 1 if HERMITE_GAP_CHECK else 0)
        self._xin[:] = x0
        if self.ng:
            self._rd[:] = 0 if rootdir is None else rootdir
        rc = self.lib.dco_fixed(self.h, scheme, t0, A["xin"], step, t_stop, max_steps, A["rd"], FIXED_CHUNK,
                                A["st"], A["sx"], A["nst"], A["ta"], A["xa"], A["tb"], A["xb"], A["sstar"])
        k = self._nst.value
        out: dict[str, Any] = dict(status=rc, st=self._st[:k].copy(), sx=self._sx[:k].copy(),
                                   ta=self._ta.value, xa=self._xa.copy())
        if rc == _FX_CANDIDATE:
            out.update(tb=self._tb.value, xb=self._xb.copy(), sstar=self._sstar[:2 * self.ng].reshape(self.ng, 2).copy())
        if rc == _FX_ERR:
            self.last_message = self.message()
        return out

    def channels(self, model: DAEModel, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray:
        """Output channels (N, n_channels) at N points with one switch vector, in C."""
        sizes = [ctypes.c_int() for _ in range(3)]
        self.lib.dco_output_sizes(*(ctypes.addressof(c) for c in sizes))
        n_y, n_sw, n_ch = (c.value for c in sizes)
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        yp = np.ascontiguousarray(yp, dtype=float)
        sw = np.zeros(max(n_sw, 1))
        sw[:switch.size] = switch
        out = np.empty((t.size, n_ch))
        if n_ch == 0 or y.shape[1] != n_y or switch.size != n_sw:
            return _model_channels(model, t, y, yp, switch)
        if t.size and self.lib.dco_outputs(self.h, t.size, t.ctypes.data, y.ctypes.data, yp.ctypes.data,
                                           sw.ctypes.data, out.ctypes.data):
            return _model_channels(model, t, y, yp, switch)
        return out

    def counters(self) -> dict[str, int]:
        self.lib.dco_counters(self.h, self._a["cnt"])
        return dict(zip(("n_res_evals", "n_jac_evals", "n_root_evals", "n_fixed_steps"), map(int, self._cnt)))


class _Buffered:
    """A CasADi function with every input and output on fixed numpy arrays (FunctionBuffer)."""

    def __init__(self, f: ca.Function, parameters: Sequence[float]) -> None:
        self.args = [np.zeros(f.nnz_in(i)) for i in range(f.n_in())]
        self.args[-1][:] = parameters  # the run-time parameters, the last input of every function
        self.outs = [np.zeros(f.nnz_out(i)) for i in range(f.n_out())]
        self.shapes = [f.size_out(i) for i in range(f.n_out())]
        self.buf, self.call = f.buffer()
        for i, a in enumerate(self.args):
            self.buf.set_arg(i, memoryview(a))
        for i, o in enumerate(self.outs):
            self.buf.set_res(i, memoryview(o))

    def __call__(self, *inputs: Any) -> list[NDArray]:
        for a, value in zip(self.args, inputs):
            a[:] = value
        self.call()
        # dense outputs, column-major
        return [o.reshape(s[1], s[0]).T.copy() if min(s) > 1 else o.copy() for o, s in zip(self.outs, self.shapes)]


class _PyEvaluator(_Evaluator):
    """The same model evaluated through casadi.FunctionBuffer and numpy (no compiler needed)."""

    backend = "python"

    def __init__(self, spec: OdeSpec) -> None:
        super().__init__(spec)
        self.build = None
        P = spec.parameters
        self._sys = _Buffered(spec.sys, P)
        self._sys_jac = _Buffered(spec.sys_jac, P)
        self._gaps = _Buffered(spec.gaps, P) if spec.gaps is not None else None
        self._tf = [_Buffered(f, P) for f in spec.term_force]
        self._tj = [_Buffered(f, P) for f in spec.term_jac]
        self.minv = 1.0 / np.asarray(spec.mass)
        self.active = [False] * self.nt
        self.params: list[NDArray] = [np.zeros(p) for p in spec.n_params]
        self.cnt = dict(n_res_evals=0, n_jac_evals=0, n_root_evals=0, n_fixed_steps=0)

    def message(self) -> str:
        return self.last_message

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
            if scheme == 1:
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
              rootdir: NDArray | None) -> dict[str, Any]:
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
                return done(_FX_ERR)
            g0, gd0 = gg
        k = 0
        while True:
            if ta >= t_stop:
                return done(_FX_TSTOP)
            if k >= max_steps:
                return done(_FX_MAXSTEPS)
            if len(st) >= FIXED_CHUNK:
                return done(_FX_CHUNK)
            tn = t0 + (k + 1) * step
            if tn >= t_stop - 1e-9 * step:
                tn = t_stop
            h = tn - ta
            xb = self.step(scheme, ta, xa, h)
            if xb is None:
                return done(_FX_ERR)
            self.cnt["n_fixed_steps"] += 1
            k += 1
            if watch:
                gg = self.gaps(tn, xb)
                if gg is None:
                    return done(_FX_ERR)
                g1, gd1 = gg
                sstar = np.full((self.ng, 2), -1.0)
                for i in range(self.ng):
                    for j, d in enumerate((1.0, -1.0)):
                        if rootdir[i] * d >= 0:  # type: ignore[index]
                            sstar[i, j] = _candidate(d * g0[i], d * gd0[i], d * g1[i], d * gd1[i], h,
                                                     HERMITE_GAP_CHECK)
                if np.any(sstar > 0):
                    return done(_FX_CANDIDATE, tb=tn, xb=xb, sstar=sstar)
                g0, gd0 = g1, gd1
            st.append(tn)
            sx.append(xb)
            ta, xa = tn, xb

    def channels(self, model: DAEModel, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray:
        return _model_channels(model, t, y, yp, switch)

    def counters(self) -> dict[str, int]:
        return dict(self.cnt)


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


_warned: set[str] = set()
_LIB_BY_FUNCTIONS = memo_table()


def _evaluator(model: DAEModel, backend: str) -> _Evaluator:
    """The model's ODE evaluator: compiled (cached per model object and on disk) or python."""
    spec = ode_spec(model)
    compiled = memo_get(_LIB_BY_FUNCTIONS, model.functions)  # one library per structure
    if backend == "python":
        return _PyEvaluator(spec)
    try:
        if compiled is None:
            build = build_ode_library(spec)
            try:
                clib = _CLib.load(build.path)
            except OSError:
                build.path.unlink(missing_ok=True)  # a damaged cache entry: build once more
                build = build_ode_library(spec)
                clib = _CLib.load(build.path)
            compiled = (clib, build)
            memo_put(_LIB_BY_FUNCTIONS, model.functions, compiled)
        else:
            clib, build = compiled
            compiled = (clib, BuildResult(build.path, build.key, True, 0.0, 0.0))
        return _CEvaluator(spec, *compiled)
    except (CompilerUnavailable, CompileError, OSError) as exc:
        if backend == "c":
            raise DaeclearError(f"the compiled ODE backend cannot be built or loaded: {exc}") from exc
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        if reason not in _warned:
            _warned.add(reason)
            warnings.warn("daeclear: the compiled right-hand side is unavailable, using casadi.FunctionBuffer "
                          f"and numpy (several times slower). Reason: {reason}", DaeclearWarning, stacklevel=4)
        return _PyEvaluator(spec)


# =========================================================================== the run


@dataclass
class _Segment:
    """One integration segment: its modes and terms, start state, steps and output points."""

    t0: float
    x0: NDArray
    active: list[bool]
    params: list[NDArray]
    modes: dict[str, str]
    include_start: bool  # the first segment also outputs its start point
    st: list[NDArray] = field(default_factory=list)  # chunks of step times
    sx: list[NDArray] = field(default_factory=list)  # chunks of step states
    pt: list[float] = field(default_factory=list)  # single step times (scipy methods)
    px: list[NDArray] = field(default_factory=list)
    et: list[NDArray] = field(default_factory=list)  # chunks of t_eval times (scipy: dense output)
    ex: list[NDArray] = field(default_factory=list)
    t1: float = 0.0


class _Run:
    """State of one integrate() call: model, evaluator, logic, records; builds the Result."""

    def __init__(self, model: DAEModel, ev: _Evaluator, method: str, t_end: float, eval_times: NDArray | None,
                 store_steps: bool, progress: bool, max_steps: int, rec: Recorder) -> None:
        self.model, self.ev, self.method, self.t_end = model, ev, method, t_end
        self.rec = rec  # where each closed segment's output goes (kept, or streamed to a file)
        self._handed = 0  # events handed to rec so far
        self.eval_times = eval_times
        self.pending = eval_times
        self.store_steps = store_steps
        self.max_steps = max_steps
        self.progress = progress
        self.bar = Progress(t_end, unit="s", desc="simulate", enabled=progress)
        self.n = model.n_q
        self.m = model.n_constraints
        nt = len(model.terms)
        self.active = [False] * nt
        self.params: list[NDArray] = [np.zeros(term.n_params) for term in model.terms]
        self.modes: dict[str, str] = {}
        self.events: list[ContactEvent] = []
        self.segments: list[_Segment] = []
        self.n_steps = 0
        self.n_restarts = 0
        self.n_lu = 0
        self.tiny = 0
        self.stall = 0
        self.last_event_t = -math.inf
        self.seg: _Segment | None = None
        self.t_last = 0.0
        self.success, self.status, self.message = True, 0, "end of the time span reached"
        self.y0: NDArray | None = None  # a declared state at t = 0, for the physics checks
        self.step: float | None = None  # the fixed step (rk4, euler)
        self.missed: list[tuple[float, float, str]] = []  # steps over which a gap changed sign, no event

    # ---------------------------------------------------------------- segments
    def directions(self) -> NDArray | None:
        if not self.model.gap_names:
            return None
        d = np.zeros(len(self.model.gap_names), dtype=np.int32)
        for logic in self.model.contacts:
            for index, direction in logic.root_directions(self.active):
                d[index] = direction
        return d

    def open_segment(self, t0: float, x0: NDArray) -> None:
        self.ev.set_terms(self.active, self.params)
        self.seg = _Segment(t0, np.array(x0, dtype=float), list(self.active), [p.copy() for p in self.params],
                            dict(self.modes), include_start=not self.segments)
        self.segments.append(self.seg)
        if self.seg.include_start and self.pending is not None and self.pending.size and self.pending[0] <= t0:
            self.seg.et.append(self.pending[:1].copy())
            self.seg.ex.append(self.seg.x0[None, :].copy())
            self.pending = self.pending[1:]
        self.seg.t1 = t0
        self.t_last = t0

    def add_steps(self, t: NDArray, X: NDArray) -> None:
        seg = self.seg
        assert seg is not None
        if t.size:
            seg.st.append(t)
            seg.sx.append(X)
            seg.t1 = float(t[-1])
            self.t_last = seg.t1
            if self.progress:
                self._progress(seg.t1)

    def add_evals(self, t: NDArray, X: NDArray) -> None:
        assert self.seg is not None
        if t.size:
            self.seg.et.append(t)
            self.seg.ex.append(X)

    def pending_upto(self, t: float) -> NDArray:
        """Output times in (previous, t] not yet produced; removes them from the pending list."""
        if self.pending is None or not self.pending.size or self.pending[0] > t:
            return np.zeros(0)
        k = int(np.searchsorted(self.pending, t, side="right"))
        chunk, self.pending = self.pending[:k], self.pending[k:]
        return chunk

    def close_segment(self, hermite: bool) -> None:
        """Multipliers, accelerations and channels of the segment's output points."""
        seg = self.seg
        if seg is None:
            return
        self.seg = None
        ev, n, m = self.ev, self.n, self.m
        ev.set_terms(seg.active, seg.params)
        if seg.pt:
            seg.st.append(np.array(seg.pt))
            seg.sx.append(np.array(seg.px).reshape(len(seg.px), 2 * n))
            seg.pt, seg.px = [], []
        st = np.concatenate(seg.st) if seg.st else np.zeros(0)
        sx = np.concatenate(seg.sx) if seg.sx else np.zeros((0, 2 * n))
        T = np.concatenate([[seg.t0], st])
        X = np.concatenate([seg.x0[None, :], sx])
        if hermite and self.model.gap_names:  # fixed step: a gap that changed sign inside a segment has no event
            self.missed += physics.sign_changes(self.model, T, X)
        if hermite and self.eval_times is not None:
            # fixed step: t_eval by cubic Hermite interpolation between the segment's steps
            te = self.pending_upto(seg.t1)
            if te.size:
                Xd = ev.batch(T, X)[0]
                seg.et.append(te)
                seg.ex.append(_hermite(T, X, Xd, te))
        # recorded steps: every step (the first segment also its start point, with h = 0, as
        # IDA's results); with store_steps=False only the start point of the run
        if seg.include_start:
            kt, kx, kh = T, X, np.concatenate([[0.0], np.diff(T)])
        else:
            kt, kx, kh = st, sx, np.diff(T)
        if not self.store_steps:
            k = 1 if seg.include_start else 0
            kt, kx, kh = kt[:k], kx[:k], kh[:k]
        self.rec.add_steps(kt, kh, np.full(kt.size, _ORDER[self.method], dtype=np.int64))
        if self.eval_times is None:
            ot, ox = kt, kx
        else:
            ot = np.concatenate(seg.et) if seg.et else np.zeros(0)
            ox = np.concatenate(seg.ex) if seg.ex else np.zeros((0, 2 * n))
        if ot.size:
            Xd, Lam = ev.batch(ot, ox)
            N = ot.size
            y = np.zeros((N, self.model.n_states))
            yp = np.zeros((N, self.model.n_states))
            y[:, :2 * n] = ox
            y[:, 2 * n:2 * n + m] = Lam
            yp[:, :2 * n] = Xd
            sw = self.model.switch_vector(seg.active, seg.params)
            ch = ev.channels(self.model, ot, y, yp, sw)
            self.rec.add_points(ot, y, yp, {name: np.ascontiguousarray(ch[:, i])
                                            for i, name in enumerate(self.model.channel_names)})
        seg.st, seg.sx, seg.et, seg.ex = [], [], [], []  # handed over: a long run keeps no segment's data
        self.hand_over(seg)
        ev.set_terms(self.active, self.params)

    def hand_over(self, seg: _Segment | None) -> None:
        """Give the recorder a segment (its times and modes) and the events so far, and flush it."""
        if seg is not None:
            self.rec.segments.append((seg.t0, seg.t1, seg.modes))
        self.rec.events.extend(self.events[self._handed:])
        self._handed = len(self.events)
        self.rec.flush()

    # ---------------------------------------------------------------- events
    def full_state(self, t: float, x: NDArray) -> tuple[NDArray, NDArray]:
        """(y, yp) of the DAE at one ODE state, with the current terms."""
        Xd, Lam = self.ev.batch(np.array([t]), x[None, :])
        y = np.zeros(self.model.n_states)
        yp = np.zeros(self.model.n_states)
        n2 = 2 * self.n
        y[:n2], y[n2:n2 + self.m], yp[:n2] = x, Lam[0], Xd[0]
        return y, yp

    def handle_event(self, t: float, x: NDArray, roots_found: NDArray) -> None:
        y, yp = self.full_state(t, x)
        for logic in self.model.contacts:
            new_events = logic.on_roots(t, y, yp, roots_found, self.active, self.params)
            self.events.extend(new_events)
            for event in new_events:
                self.modes[event.pair] = "contact" if event.kind == "onset" else "free"
        self.n_restarts += 1
        if t > self.last_event_t:
            self.stall = 0
        self.stall += 1
        self.last_event_t = t

    def fail(self, t: float, why: str, hint: str) -> None:
        names = self.model.state_names

        def name(match: "re.Match[str]") -> str:
            i = int(match.group(2))
            if i >= 2 * self.n:
                return match.group(0)
            label = f"d({names[i]})/dt" if match.group(1).startswith("right") else names[i]
            return f"{match.group(1)} {i} ({label})"

        why = re.sub(r"(right-hand side component|state component) (\d+)", name, why).replace("-nan", "nan")
        in_contact = [pair for pair, mode in self.modes.items() if mode == "contact"]
        where = f" with {', '.join(repr(p) for p in in_contact)} in contact" if in_contact else ""
        self.success, self.status = False, -1
        self.message = f"{METHOD_NAMES[self.method]} failed at t={t:.6g} s{where}: {why}. {hint}".rstrip()

    def count_step(self, t_old: float, t_new: float) -> bool:
        """Count an accepted step; False (after fail()) on a step-size collapse."""
        self.n_steps += 1
        if t_new - t_old < TINY_STEP_REL * max(1.0, abs(t_new)):
            self.tiny += 1
            if self.tiny >= TINY_STEP_COUNT:
                self.fail(t_new, f"the step size collapsed ({TINY_STEP_COUNT} steps below "
                          f"{TINY_STEP_REL:g} * max(1, |t|), last h={t_new - t_old:.3g} s)",
                          "Try a looser rtol, a smaller max_step or another method.")
                return False
        else:
            self.tiny = 0
        return True

    def _progress(self, t: float) -> None:
        self.bar.update(t, f"events {len(self.events)}")

    # ---------------------------------------------------------------- result
    def result(self, setup_time: float, solve_time: float) -> Result:
        self.hand_over(self.seg)  # a segment left open by a failure at its start has no output points
        self.seg = None
        stats: dict[str, Any] = {"n_steps": self.n_steps}
        stats.update(self.ev.counters())
        stats.pop("n_fixed_steps", None)
        if self.method in ("radau", "bdf"):
            stats["n_lu"] = self.n_lu
        if self.method not in IMPLICIT_METHODS:
            stats["n_jac_evals"] = 0
        build = self.ev.build
        stats.update(n_events=len(self.events), n_restarts=self.n_restarts, solve_time=solve_time,
                     setup_time=setup_time, backend=self.ev.backend,
                     compile_time=build.compile_time if build else 0.0,
                     codegen_time=build.codegen_time if build else 0.0,
                     cache_hit=bool(build.cache_hit) if build else False)
        key_t, key_y, key_channels = self.rec.key_rows()
        found = physics.check_run(self.model, key_t, key_y, key_channels, self.y0, stats)
        if self.step is not None:
            found += physics.check_fixed_steps(self.model, self.events, self.step, self.missed)
        physics.issue(found, stacklevel=5)  # issue <- result <- integrate <- simulate <- the caller
        return self.rec.finish(stats=stats, success=self.success, status=self.status, message=self.message,
                               warnings=found)


def _hermite(T: NDArray, X: NDArray, Xd: NDArray, te: NDArray) -> NDArray:
    """Cubic Hermite interpolation of the rows of X (derivatives Xd) at times te within [T0, T-1]."""
    if T.size == 1:
        return np.repeat(X[:1], te.size, axis=0)
    k = np.clip(np.searchsorted(T, te, side="left"), 1, T.size - 1)
    return cubic_hermite(T[k - 1], X[k - 1], Xd[k - 1], T[k], X[k], Xd[k], te)


def _locate(ev: _Evaluator, X_of: Callable[[float], NDArray | None], ta0: float, g_a: tuple[NDArray, NDArray],
            tb_end: float, x_end: NDArray, g_end: tuple[NDArray, NDArray], cands: list[tuple[int, int, float]],
            n_gaps: int) -> tuple[float, NDArray, NDArray] | None | str:
    """Locate the earliest confirmed crossing among the candidates of one step [ta0, tb_end].

    ``g_a`` and ``g_end`` are (gaps, rates) at the ends of the step; ``cands`` (gap, direction,
    far-side point) from _candidate. Returns (t_event, x_event,
    roots_found), None when no candidate is confirmed, or an error message when the model could
    not be evaluated.
    """
    h = tb_end - ta0
    ttol = 100.0 * _EPS * (abs(ta0) + abs(h))
    best: tuple[float, NDArray, list[tuple[int, int]]] | None = None
    for i, direction, s in cands:
        d = float(direction)
        G0, Gd0, G1, Gd1 = d * g_a[0][i], d * g_a[1][i], d * g_end[0][i], d * g_end[1][i]
        tb = ta0 + s
        if tb >= tb_end or s >= tb_end - ta0:
            tb, xb, Gb = tb_end, x_end, G1
        else:
            xb = X_of(tb)
            if xb is None:
                return ev.last_message or f"the state could not be computed at t={tb:.17g}"
            gg = ev.gaps(tb, xb)
            if gg is None:
                return ev.last_message
            Gb = d * gg[0][i]
        if not Gb > 0.0:
            continue  # a predicted excursion that the scheme's state does not confirm
        ta, Ga = ta0, G0
        if Gd0 < 0.0:
            # G starts by moving away from zero: typically just after the opposite event, where
            # |G| is at rounding level and the error of an interpolant (or of a tiny re-step) can
            # fake a crossing right at the start. Start the bracket where the state confirms G < 0
            # on the way down: at the cubic's first minimum, or closer to the start (1/4, 1/16, ...).
            ext = [u for u, is_max, _ in _cubic_extrema(G0, Gd0, G1, Gd1, h)[:1] if not is_max]
            u = min(ext[0] if ext else 0.5, (tb - ta0) / h)
            while u * h > 1e3 * ttol:
                xm = X_of(ta0 + u * h)
                gg = None if xm is None else ev.gaps(ta0 + u * h, xm)
                if gg is not None and d * gg[0][i] < 0.0:
                    ta, Ga = ta0 + u * h, d * gg[0][i]
                    break
                u *= 0.25
        side = 0
        for _ in range(200):
            if tb - ta <= ttol:
                break
            tm = tb - Gb * (tb - ta) / (Gb - Ga) if Gb != Ga else 0.5 * (ta + tb)
            if not ta < tm < tb:
                tm = 0.5 * (ta + tb)
            xm = X_of(tm)
            if xm is None:
                return ev.last_message or f"the state could not be computed at t={tm:.17g}"
            gg = ev.gaps(tm, xm)
            if gg is None:
                return ev.last_message
            Gm = d * gg[0][i]
            if Gm > 0.0:
                tb, Gb, xb = tm, Gm, xm
                if side == 1:
                    Ga *= 0.5
                side = 1
            else:
                ta, Ga = tm, Gm
                if side == -1:
                    Gb *= 0.5
                side = -1
        if best is None or tb < best[0] - ttol:
            best = (tb, xb, [(i, direction)])
        elif abs(tb - best[0]) <= ttol:
            best[2].append((i, direction))
    if best is None:
        return None
    roots = np.zeros(n_gaps, dtype=np.int32)
    for i, direction in best[2]:
        roots[i] = direction
    return best[0], np.array(best[1], dtype=float), roots


def _run_scipy(run: _Run, x0: NDArray, rtol: float, atol: NDArray, max_step: float, t0: float = 0.0) -> None:
    import scipy.integrate as si

    cls = {"rk45": si.RK45, "dop853": si.DOP853, "radau": si.Radau, "bdf": si.BDF, "lsoda": si.LSODA}[run.method]
    ev, t_end = run.ev, run.t_end
    opts: dict[str, Any] = dict(rtol=rtol, atol=atol, max_step=max_step if max_step > 0 else np.inf)
    if run.method in IMPLICIT_METHODS:
        opts["jac"] = ev.jac
    hint = "Try a smaller max_step, a looser rtol or another method."
    t, x = t0, x0
    while True:
        run.open_segment(t, x)
        dirs = run.directions()
        watch = dirs is not None  # every gap, in its direction (0: both, as IDA)
        g0 = gd0 = None
        if watch:
            gg = ev.gaps(t, x)
            if gg is None:
                run.fail(t, ev.last_message, "")
                return
            g0, gd0 = gg
        try:
            solver = cls(ev.rhs, t, x, t_end, **opts)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            run.fail(t, f"the solver could not start: {exc}", hint)
            return
        lu0 = getattr(solver, "nlu", 0)
        seg = run.seg
        assert seg is not None
        add_t, add_x = seg.pt.append, seg.px.append
        solver_step = solver.step
        n_gaps = 0 if dirs is None else len(dirs)
        watched = [(i, d) for i in range(n_gaps) for d in (1, -1) if dirs[i] * d >= 0]  # type: ignore[index]
        next_eval = run.pending[0] if run.pending is not None and run.pending.size else math.inf
        t_prev = t
        restart = None
        while True:
            if run.n_steps >= run.max_steps:
                run.fail(t_prev, f"max_steps={run.max_steps} steps reached", "Raise max_steps or loosen rtol.")
                break
            try:
                msg = solver_step()
            except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
                msg = f"{type(exc).__name__}: {exc}"
                solver.status = "failed"
            if solver.status == "failed":
                why = str(msg or "the solver failed")
                if ev.last_message:
                    why += f" (last model error: {ev.last_message})"
                run.fail(t_prev, why, hint)
                break
            t1, x1 = float(solver.t), solver.y.copy()
            if not math.isfinite(x1.sum()):
                bad = int(np.flatnonzero(~np.isfinite(x1))[0])
                run.fail(t_prev, f"the state became non-finite ({run.model.state_names[bad]} = {x1[bad]})", hint)
                break
            run.n_steps += 1
            if t1 - t_prev < TINY_STEP_REL * max(1.0, abs(t1)):
                run.n_steps -= 1
                if not run.count_step(t_prev, t1):
                    break
            else:
                run.tiny = 0
            sol = None
            if watch:
                gg = ev.gaps(t1, x1)
                if gg is None:
                    run.fail(t1, ev.last_message, hint)
                    break
                g1, gd1 = gg
                h = t1 - t_prev
                cands = []
                for i, d in watched:
                    s = _candidate(d * g0[i], d * gd0[i], d * g1[i], d * gd1[i], h, HERMITE_GAP_CHECK)
                    if s > 0.0:
                        cands.append((i, d, s))
                if cands:
                    sol = solver.dense_output()
                    found = _locate(ev, lambda tt: np.array(sol(tt), dtype=float), t_prev, (g0, gd0), t1, x1,
                                    (g1, gd1), cands, n_gaps)
                    if isinstance(found, str):
                        run.fail(t_prev, found, hint)
                        break
                    if found is not None:
                        t_ev, x_ev, roots = found
                        te = run.pending_upto(t_ev)
                        if te.size:
                            run.add_evals(te, np.atleast_2d(np.array(sol(te), dtype=float).T))
                        add_t(t_ev)
                        add_x(x_ev)
                        restart = (t_ev, x_ev, roots)
                        break
                g0, gd0 = g1, gd1
            if next_eval <= t1:
                te = run.pending_upto(t1)
                if sol is None:
                    sol = solver.dense_output()
                run.add_evals(te, np.atleast_2d(np.array(sol(te), dtype=float).T))
                next_eval = run.pending[0] if run.pending is not None and run.pending.size else math.inf
            add_t(t1)
            add_x(x1)
            if run.progress:
                run._progress(t1)
            t_prev = t1
            if solver.status == "finished":
                break
        seg.t1 = t_prev if restart is None else restart[0]
        run.t_last = seg.t1
        run.n_lu += getattr(solver, "nlu", 0) - lu0
        if not _end_segment(run, restart, False, t_end):
            return
        t, x, _ = restart  # the next segment starts at the event


def _end_segment(run: _Run, restart: Any, hermite: bool, t_end: float) -> bool:
    """Close the segment; on an event let the logic switch modes. True when the run goes on."""
    run.close_segment(hermite=hermite)
    if restart is None or not run.success:
        return False
    t, x, roots = restart
    run.handle_event(t, x, roots)
    if run.stall >= STALL_EVENTS:
        run.fail(t, f"{run.stall} events at the same time: the event loop does not advance", "")
        return False
    return t < t_end


def _run_fixed(run: _Run, x0: NDArray, step: float, t0: float = 0.0) -> None:
    ev, t_end = run.ev, run.t_end
    scheme = FIXED_STEP_METHODS[run.method]
    hint = "Try a smaller step."
    t, x = t0, x0
    while True:
        run.open_segment(t, x)
        dirs = run.directions()
        restart = None
        while True:
            left = run.max_steps - run.n_steps
            if left <= 0:
                run.fail(t, f"max_steps={run.max_steps} steps reached", "Raise max_steps or use a larger step.")
                break
            out = ev.fixed(scheme, t, x, step, t_end, left, dirs)
            st, sx = out["st"], out["sx"]
            run.n_steps += st.size
            run.add_steps(st, sx)
            t, x = out["ta"], out["xa"]
            status = out["status"]
            if status == _FX_TSTOP:
                break
            if status == _FX_CHUNK:
                continue
            if status == _FX_MAXSTEPS:
                run.fail(t, f"max_steps={run.max_steps} steps reached", "Raise max_steps or use a larger step.")
                break
            if status == _FX_ERR:
                run.fail(t, ev.last_message or "the model could not be evaluated", hint)
                break
            # a step that may hold a crossing: confirm and locate it on re-steps from its start
            run.n_steps += 1
            tb, xb, sstar = out["tb"], out["xb"], out["sstar"]
            cands = [(int(i), 1 - 2 * int(j), float(sstar[i, j])) for i, j in zip(*np.nonzero(sstar > 0))]
            gg_a, gg_b = ev.gaps(t, x), ev.gaps(tb, xb)
            if gg_a is None or gg_b is None:
                run.fail(t, ev.last_message, hint)
                break
            ta, xa = t, x
            found = _locate(ev, lambda tt: ev.step(scheme, ta, xa, tt - ta), ta, gg_a, tb, xb, gg_b,
                            cands, ev.ng)  # type: ignore[arg-type]
            if isinstance(found, str):
                run.fail(t, found, hint)
                break
            if found is None:
                run.add_steps(np.array([tb]), xb[None, :])
                t, x = tb, xb
                continue
            t_ev, x_ev, roots = found
            run.add_steps(np.array([t_ev]), x_ev[None, :])
            restart = (t_ev, x_ev, roots)
            break
        if not _end_segment(run, restart, True, t_end):
            return
        t, x, _ = restart  # the next segment starts at the event


def integrate(
    scene: Scene | DAEModel,
    t_end: float,
    *,
    method: str,
    t_eval: ArrayLike | None = None,
    rtol: float = 1e-6,
    atol: float | ArrayLike | None = None,
    formulation: str | None = None,
    backend: str = "auto",
    max_step: float = 0.0,
    max_steps: int = 5_000_000,
    step: float | None = None,
    store_steps: bool = True,
    on_failure: str = "raise",
    progress: bool = False,
    track_work: bool = False,
    start: str = "ideal",
    allow_penetration: bool = False,
    t_eval_step: float | None = None,
    stream_to: str | os.PathLike[str] | None = None,
    keep_data: bool = True,
    t0: float = 0.0,
    y0: ArrayLike | None = None,
) -> Result:
    """Integrate with a non-IDA method; the arguments are those of :func:`daeclear.simulate`.

    Output (``t_eval``/``t_eval_step``, ``store_steps``, ``stream_to``, ``keep_data``) goes to a
    :class:`daeclear.solvers.recorder.Recorder` segment by segment (a segment runs between two contact
    events): streamed, each segment's points are written when it ends and dropped, so memory
    grows with the longest segment and the events (kept for the fixed-step checks), not with
    the run; the grid of ``t_eval_step`` is built whole (8 bytes per point).

    ``method`` is one of RK45, DOP853, Radau, BDF, LSODA, rk4, euler (case-insensitive);
    ``step`` (s) is required by rk4 and euler and rejected by the others; ``max_step`` bounds
    the scipy methods' steps (0: unbounded); ``backend`` "c" (generated C), "python"
    (FunctionBuffer) or "auto". See the module docstring for events, outputs and failures.
    """
    method_l = str(method).lower()
    if method_l not in METHOD_NAMES:
        valid = ", ".join(["ida", *METHOD_NAMES.values()])
        raise SceneError(f"simulate: method={method!r}, must be one of {valid} (case-insensitive).")
    step = check_step(method_l, step)
    t_end, rtol, max_step, max_steps, t_eval, backend, on_failure, store_steps, progress, track_work = options.run(
        t_end=t_end, t0=t0, rtol=rtol, atol=atol, max_step=max_step, max_steps=max_steps, t_eval=t_eval,
        backend=backend, on_failure=on_failure, store_steps=store_steps, progress=progress, track_work=track_work)
    t0 = float(t0)  # checked by options.run
    out = options.output(t_eval=t_eval, t_eval_step=t_eval_step, end=t_end, stream_to=stream_to, keep_data=keep_data,
                         start=t0)
    name = METHOD_NAMES[method_l]
    if track_work:
        raise SceneError(f"simulate: track_work=True is supported by method='ida' only, not by method={name!r}.")
    if formulation is None:
        formulation = options.default_formulation(method_l)
    if isinstance(scene, DAEModel):
        model = scene
    else:
        if str(formulation).lower() == "ggl":
            raise SceneError(f"simulate: formulation={formulation!r} is integrated by IDA only; method={name!r} "
                             "integrates the chapter's index-1 formulation (formulation='index1').")
        model = None
    setup_start = time.perf_counter()
    if model is None:
        model = assemble(scene, formulation)  # type: ignore[arg-type]  # validates the name
    if model.formulation != "index1":
        raise SceneError(f"simulate: formulation={model.formulation!r} is integrated by IDA only; method={name!r} "
                         "integrates the chapter's index-1 formulation (formulation='index1').")
    from_state = y0 is not None
    if from_state:
        y0 = options.state(y0, model.n_states)
    model = model.for_run(from_state=from_state)  # this run's own contact logic: the model stays unchanged
    eval_times = None if out.times is None else out.times.values()  # checked by options.output
    n = model.n_q
    atol_x = tolerance_vector(model, rtol, atol)[:2 * n]
    ev = _evaluator(model, backend)
    if from_state:  # q and v as given (index-1: no projection), multipliers recomputed at t0
        y0, _ = model.consistent_state(t0, y0)
    else:
        y0, _ = model.initial_state(start=start, allow_penetration=allow_penetration)
    x0 = np.array(y0[:2 * n])
    sim_params = {"method": name, "rtol": rtol, "atol": None if atol is None else np.ravel(atol).tolist(),
                  "max_step": max_step, "t_end": t_end, "backend": ev.backend, "step": step}
    if from_state:
        sim_params["start"] = "state"
    if t0 != 0.0:
        sim_params["t0"] = t0
    rec = Recorder(model, parameters={**model.parameters, "simulate": sim_params}, method=name,
                   stream_to=out.stream_to, keep_data=out.keep_data)
    run = _Run(model, ev, method_l, t_end, eval_times, store_steps, progress, max_steps, rec)
    run.y0, run.step = (y0 if start == "declared" and not from_state else None), step  # declared starts only
    run.t_last = t0
    for logic in model.contacts:
        run.modes.update(logic.initial_modes(t0, y0, run.active, run.params))
    setup_time = time.perf_counter() - setup_start
    tic = time.perf_counter()
    interrupted = False
    try:
        with np.errstate(all="ignore"):
            if method_l in FIXED_STEP_METHODS:
                _run_fixed(run, x0, step, t0)  # type: ignore[arg-type]
            else:
                _run_scipy(run, x0, rtol, atol_x, max_step, t0)
    except KeyboardInterrupt:  # Ctrl-C: keep what was computed, then stop the caller too (Interrupted)
        run.success, run.status = False, -1
        run.message = f"interrupted by the user at t={run.t_last:.6g} s"
        run.close_segment(hermite=method_l in FIXED_STEP_METHODS)
        interrupted = True
    except MemoryError:  # keep (and, streamed, save) the segments closed before
        run.success, run.status = False, -1
        run.message = (f"out of memory at t={run.t_last:.6g} s. Report fewer points (t_eval_step), keep no "
                       "steps (store_steps=False) and stream the run to a file (stream_to).")
        if run.seg is not None:
            run.seg.st, run.seg.sx, run.seg.pt, run.seg.px, run.seg.et, run.seg.ex = [], [], [], [], [], []
    except BaseException as exc:  # anything else: a streamed file keeps what it holds, then the error goes on
        run.bar.close()
        rec.abort(exc)
        raise
    solve_time = time.perf_counter() - tic
    if run.progress:
        run._progress(t_end if run.success else run.t_last)
    run.bar.close()
    result = run.result(setup_time, solve_time)
    if interrupted or rec.interrupted:
        raise Interrupted(f"simulate: {result.message}; partial result in .result.", result)
    if not result.success and on_failure == "raise":
        raise SolveError(result.message + " Partial result in .result.", result)
    return result
