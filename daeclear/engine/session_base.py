"""What both IDA session backends share: the DAE (:class:`DAEFunctions`), what an advance returns
(:class:`Advance`), the :class:`Session` protocol, the options' validation and :class:`SessionBase`."""

from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable
from collections.abc import Callable, Sequence

import casadi
import numpy as np

from ..core.automaton import Decision, PairState, Storm
from ..core.errors import DaeclearError
from ..core.options import LINEAR_SOLVERS
from .abi import DC_EV_CONTACT, DC_EV_HELD, DC_EV_KIND, DC_EV_WATCH, DC_STORE_STATES, DC_STORE_TIMES
from .codegen import NormalizedModel
from .stall_guard import StallGuard

__all__ = ["DAEFunctions", "AutoEvents", "StateLayout", "Advance", "Session", "SessionOptions", "check_options",
           "SessionBase", "ChunkCallback", "FLAG_MAX_STEPS", "FLAG_STEP_COLLAPSE", "OWN_FLAG_NAMES", "STORE_TIMES",
           "STORE_STATES", "output_rows"]

#: flag of an Advance that stopped because the session's step cap (max_steps) was reached
FLAG_MAX_STEPS = -1001
#: flag of an Advance that stopped because the step size collapsed (daeclear.engine.stall_guard)
FLAG_STEP_COLLAPSE = -1002
#: names of the flags that daeclear sets itself (not IDA)
OWN_FLAG_NAMES = {FLAG_MAX_STEPS: "DC_MAX_STEPS", FLAG_STEP_COLLAPSE: "DC_STEP_COLLAPSE"}


@dataclass(frozen=True)
class DAEFunctions:
    """A DAE F(t, y, y') = 0 with switchable terms, as CasADi functions.

    residual: (t[1], y[n], yp[n], P) -> r[n], always active.
    jacobian: (t, y, yp, cj[1], P) -> J[n x n] = dr/dy + cj dr/dyp (dense or sparse output).
    term_residuals[k]: (t, y, yp, p_k[n_params_k], P) -> r_k[n], added to r while term k is active.
    term_jacobians[k]: (t, y, yp, p_k, cj, P) -> J_k[n x n], added to J while term k is active.
    roots: (t, y, yp, P) -> g[n_roots], or None when the model has no events.
    extras[k]: functions with vector inputs, P last, and one output, evaluated over many points by
    :meth:`Session.eval_extra` (output channels, consistent restarts); never called by IDA.
    ``P``: the ``n_parameters`` run-time parameters (values given to :func:`open_session`); with
    ``n_parameters == 0`` the functions may leave it out. ``blocks`` > 1: the Newton matrix is block
    diagonal, ``blocks`` copies of the (n / blocks)-square matrix the Jacobian functions return (the
    stacked forward sensitivities [y; S_1; ...]): one factorisation of that block solves them all.
    ``coupling`` (with ``blocks`` > 1): (t, y, yp, cj, P, dy0) -> C dy0 (n - n / blocks), the Newton
    matrix's blocks below its first block column times the first block's solution; ``term_couplings[k]``
    (t, y, yp, p_k, cj, P, dy0) the same of term k: the solve is then the block forward substitution of
    the block lower-triangular matrix, else the block-diagonal part (IDAS' simultaneous corrector).
    ``kinks``: (t, y, yp, P) -> k[n_kinks], where a force's slope jumps (friction laws' ``kinks``), or None:
    not roots of this DAE; the stacked DAE of a run with sensitivities appends them to its roots and
    integrates S with ``locked_residuals[k]`` (t, y, yp, [p_k; piece], P), term k's residual on one piece of
    its friction law (None for a term without kinks; empty without kinks).
    A value: what a process compiles of it is kept by a :class:`~daeclear.engine.compiled.CompiledDAE`.
    """

    n: int
    residual: casadi.Function
    jacobian: casadi.Function
    term_residuals: tuple[casadi.Function, ...]
    term_jacobians: tuple[casadi.Function, ...]
    roots: casadi.Function | None
    name: str = "model"
    extras: tuple[casadi.Function, ...] = ()
    n_parameters: int = 0
    blocks: int = 1
    coupling: casadi.Function | None = None
    term_couplings: tuple[casadi.Function, ...] = ()
    kinks: casadi.Function | None = None
    locked_residuals: tuple[casadi.Function | None, ...] = ()


@dataclass(frozen=True)
class AutoEvents:
    """The contact switches the C loop decided in one advance, in time order: ``pair`` (index in
    set_auto_events), ``info`` (kind, contact, held, watch), ``rate``, ``latched`` speed after it, ``y``."""

    t: np.ndarray
    pair: np.ndarray
    info: np.ndarray
    rate: np.ndarray
    latched: np.ndarray
    y: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)

    def decision(self, i: int) -> Decision:
        """The decision of row ``i``."""
        row = self.info[i].tolist()
        return Decision(row[DC_EV_KIND], bool(row[DC_EV_CONTACT]), bool(row[DC_EV_HELD]), float(self.latched[i]),
                        row[DC_EV_WATCH])

    @staticmethod
    def join(parts: Sequence[AutoEvents]) -> AutoEvents | None:
        """The rows of ``parts`` in order (None without any)."""
        if len(parts) < 2:
            return parts[0] if parts else None
        names = [f.name for f in dataclasses.fields(AutoEvents)]
        return AutoEvents(*(np.concatenate([getattr(p, name) for p in parts]) for name in names))


@dataclass(frozen=True)
class StateLayout:
    """Where things are in y = [q, v, lambda, mu (GGL), work (track_work)] and which extras the
    compiled loop uses to make a state consistent (see ``dc_set_layout`` in ida_driver.c)."""

    n_q: int
    n_constraints: int
    ggl: bool
    track_work: bool
    accel_extra: int
    force_extra0: int
    kinematics_extra: int
    outputs_extra: int
    project: bool  # restarts after switches decided in C are projected on the constraint manifold
    tol: float
    max_iter: int
    n_channels: int  # values the outputs extra returns per point (the model's channels)


@dataclass
class Advance:
    """What one :meth:`Session.advance` call did: ``step_*`` every point where IDA returned in one-step
    mode (each internal step's end, and a root), times increasing, the start excluded (``step_order``
    -1: python backend); ``eval_*`` the ``t_eval`` points in (t_start, t]; ``step_yp`` and ``eval_yp``
    None when the caller asked for no yp (``store_yp=False``)."""

    status: str  # "tstop" | "root" | "error" | "interrupted" (Ctrl-C between chunks: the steps so far)
    t: float
    y: np.ndarray
    yp: np.ndarray
    step_t: np.ndarray
    step_y: np.ndarray
    step_yp: np.ndarray | None
    step_h: np.ndarray
    step_order: np.ndarray
    eval_t: np.ndarray
    eval_y: np.ndarray
    eval_yp: np.ndarray | None
    roots_found: np.ndarray | None = None
    flag: int = 0
    flag_name: str = ""
    message: str = ""
    auto_events: AutoEvents | None = None

    @property
    def success(self) -> bool:
        return self.status != "error"


#: ``on_chunk(t, n_switches)`` of :meth:`Session.advance`: called between two full buffers of the compiled loop.
ChunkCallback = Callable[[float, int], None]


@runtime_checkable
class Session(Protocol):
    """An open IDA session on one DAE (:func:`daeclear.engine.ida_session.open_session`), as the run's IDA
    integrator (:mod:`daeclear.solvers.ida`) and a model's evaluations use it: exactly these members."""

    backend: str

    @property
    def max_steps(self) -> int:
        """The session's cap on the IDA steps of a run."""
        ...

    @property
    def eval_from(self) -> float:
        """Output times after this one are still to come (the current time, or the last filled row's)."""
        ...

    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None:
        """Restart IDA at a consistent state with these terms on and roots watched in these directions."""
        ...

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: ChunkCallback | None = None, store_states: bool = True,
                chunked: bool = False, store_yp: bool = True) -> Advance:
        """Integrate towards ``t_stop``, keeping the steps (``store_steps``) and their states (``store_states``;
        yp too unless not ``store_yp``); ``chunked``: return (status ``"chunk"``) when the step buffer or the
        ``t_eval`` rows are full."""
        ...

    def roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        """The root functions at one point."""
        ...

    def eval_extra(self, k: int, inputs: Sequence[np.ndarray], n_points: int) -> np.ndarray:
        """``DAEFunctions.extras[k]`` at ``n_points`` points, (n_points, n_out)."""
        ...

    def stats(self) -> dict[str, int | float | str]:
        """The session's counters and timings."""
        ...

    def set_hints(self, *, nonlin_conv_coef: float | None = None, jacobian_refresh: float | None = None,
                  first_step: bool | None = None) -> bool:
        """Solver hints; whether the backend applies them."""
        ...

    def set_stall(self, stall_step: float, count: int) -> None:
        """The step-size collapse rule's numbers (stall_guard)."""
        ...

    def set_layout(self, layout: StateLayout) -> bool:
        """Let the loop make states consistent itself; whether it does (compiled backend)."""
        ...

    def set_kinematic_rows(self, n_kinematic: int) -> bool:
        """The reduced solver's eliminated position rows without a layout; whether it applies (compiled)."""
        ...

    def set_newton_tolerances(self, atol: np.ndarray | None) -> bool:
        """Newton's convergence test weighs the rows with ``atol > 0`` by 1/(rtol |y| + atol), whatever the error
        test's tolerances (rows out of the error test kept in Newton's; None: the error test's weights
        everywhere); whether the backend does (compiled)."""
        ...

    def set_auto_events(self, pairs: Sequence[tuple[int, int, int, bool, float]], *, storms: Sequence[Storm],
                        states: Sequence[PairState], capacity: int = 256) -> bool:
        """Let the loop decide these pairs' switches itself; whether it does (compiled backend)."""
        ...

    def pair_states(self) -> list[PairState]:
        """The automaton states of the pairs the loop decides (:meth:`set_auto_events`' order)."""
        ...

    def report(self, t: np.ndarray, y: np.ndarray, switch: np.ndarray, *,
               into: tuple[np.ndarray, np.ndarray] | None = None,
               channels: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Reported points made consistent by the loop (after :meth:`set_layout` returned True)."""
        ...

    def close(self) -> None:
        """Free the session."""
        ...


@dataclass
class SessionOptions:
    """The validated options of one session (see :func:`check_options`)."""

    rtol: float
    atol: np.ndarray
    max_step: float
    max_order: int
    max_steps: int
    root_directions: np.ndarray  # int32 (n_roots,)
    buffer_steps: int
    parameters: np.ndarray  # run-time parameters P (n_parameters,)
    linear_solver: str = "auto"  # one of LINEAR_SOLVERS, as requested


def _root_dirs(model: NormalizedModel, rd: Any) -> np.ndarray:
    if rd is None:
        return np.zeros(model.n_roots, dtype=np.int32)
    arr = np.asarray(rd)
    if arr.shape != (model.n_roots,):
        raise ValueError(f"root_directions must have shape ({model.n_roots},), got {arr.shape}")
    if not all(d in (-1, 0, 1) for d in arr.tolist()):
        raise ValueError(f"root_directions values must be -1, 0 or +1, got {arr.tolist()}")
    return np.ascontiguousarray(arr, dtype=np.int32)


def check_options(model: NormalizedModel, rtol: Any, atol: Any, max_step: Any, max_order: Any,
                  max_steps: Any, root_directions: Any, buffer_steps: Any, parameters: Any,
                  linear_solver: Any = "auto") -> SessionOptions:
    """The options of :func:`daeclear.engine.ida_session.open_session`, checked (ValueError) and converted."""
    if not isinstance(linear_solver, str) or linear_solver.lower() not in LINEAR_SOLVERS:
        raise ValueError(f"linear_solver={linear_solver!r} is not a linear solver: valid values are "
                         f"{', '.join(map(repr, LINEAR_SOLVERS))}")
    rtol = float(rtol)
    if not (math.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol must be a positive number, got {rtol}")
    a = np.asarray(atol, dtype=float)
    if a.ndim == 0:
        a = np.full(model.n, float(a))
    if a.shape != (model.n,):
        raise ValueError(f"atol must be a scalar or have shape ({model.n},), got {a.shape}")
    if not (np.isfinite(a) & (a > 0)).all():
        raise ValueError(f"atol must be positive and finite, got {a.tolist()}")
    max_step = float(max_step)
    if not (max_step >= 0 and math.isfinite(max_step)):
        raise ValueError(f"max_step must be >= 0 (0: unbounded), got {max_step}")
    if int(max_order) != max_order or not 1 <= int(max_order) <= 5:
        raise ValueError(f"max_order must be an integer in [1, 5], got {max_order}")
    if int(max_steps) != max_steps or int(max_steps) < 1:
        raise ValueError(f"max_steps must be a positive integer, got {max_steps}")
    if int(buffer_steps) != buffer_steps or int(buffer_steps) < 1:
        raise ValueError(f"buffer_steps must be a positive integer, got {buffer_steps}")
    P = np.zeros(0) if parameters is None else np.ascontiguousarray(parameters, dtype=float).ravel()
    if P.size != model.n_parameters:
        raise ValueError(f"parameters must have {model.n_parameters} values (the model's run-time parameters), "
                         f"got {P.size}")
    return SessionOptions(rtol, np.ascontiguousarray(a), max_step, int(max_order), int(max_steps),
                          _root_dirs(model, root_directions), int(buffer_steps), P, linear_solver.lower())


STORE_TIMES, STORE_STATES = DC_STORE_TIMES, DC_STORE_STATES  # dc_advance's store_steps flags


_EMPTY = np.empty(0)
_EMPTY.flags.writeable = False


def output_rows(buffer: np.ndarray, n_rows: int) -> np.ndarray:
    """The first ``n_rows`` rows of an output-time buffer: the buffer itself when they fill it, else a copy
    (a kept view of a partly filled window would hold the whole buffer in memory)."""
    return buffer if n_rows == buffer.shape[0] else buffer[:n_rows].copy()


class SessionBase:
    """State, validation and the backend-independent methods of both sessions."""

    backend = "?"

    def __init__(self, model: NormalizedModel, opts: SessionOptions) -> None:
        self._model = model
        self._opts = opts
        self._n = model.n
        self._nt = len(model.term_res)
        self._ready = False
        self._closed = False
        self._t = 0.0
        self._y = np.zeros(model.n)
        self._yp = np.zeros(model.n)
        self._active = np.zeros(self._nt, dtype=np.int32)
        self._params = [np.zeros(p) for p in model.n_params]
        self._stall = StallGuard()
        self._solve_time = 0.0
        # the compiled library and its session handle: CSession's only (set_stall uses them)
        self._lib: Any
        self._h: Any

    @property
    def max_steps(self) -> int:
        """The session's cap on the number of IDA steps of a run."""
        return self._opts.max_steps

    @property
    def n(self) -> int:
        return self._n

    @property
    def n_roots(self) -> int:
        return self._model.n_roots

    @property
    def n_params(self) -> tuple[int, ...]:
        return self._model.n_params

    @property
    def t(self) -> float:
        """Time of the current state (last reinit or last advance)."""
        return self._t

    def _vec(self, v: Any, what: str) -> np.ndarray:
        a = np.ascontiguousarray(v, dtype=float)
        if a.shape != (self._n,):
            raise ValueError(f"{what} must have shape ({self._n},), got {a.shape}")
        return a

    def set_hints(self, *, nonlin_conv_coef: float | None = None, jacobian_refresh: float | None = None,
                  first_step: bool | None = None) -> bool:
        """Solver hints (see CSession.set_hints): the python backend has none, returns False."""
        return False

    def eval_extra(self, k: int, inputs: Sequence[np.ndarray], n_points: int) -> np.ndarray:
        """``DAEFunctions.extras[k]`` at ``n_points`` points, (n_points, n_out); inputs (n_points, size) or (size,)."""
        f = self._model.extras[k]
        inputs = [*inputs, self._opts.parameters]
        cols = [np.zeros((0, n_points)) if f.numel_in(j) == 0 else
                np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, f.numel_in(j)), (n_points, f.numel_in(j))).T
                for j, x in enumerate(inputs)]
        fm = f if n_points == 1 else f.map(n_points)
        return np.array(fm(*cols)).reshape(-1, n_points).T.copy()

    def set_auto_events(self, pairs: Sequence[tuple[int, int, int, bool, float]], *, storms: Sequence[Storm],
                        states: Sequence[PairState], capacity: int = 256) -> bool:
        """Only the compiled backend switches contact pairs in C; returns False here."""
        return False

    def set_layout(self, layout: StateLayout) -> bool:
        """Only the compiled backend makes states consistent in C; returns False here."""
        return False

    def set_kinematic_rows(self, n_kinematic: int) -> bool:
        """Only the compiled backend has the reduced solver; returns False here."""
        return False

    def set_newton_tolerances(self, atol: np.ndarray | None) -> bool:
        """Only the compiled backend has Newton weights of its own; returns False here."""
        return False

    def pair_states(self) -> list[PairState]:
        """No pair is decided by the loop here (:meth:`set_auto_events` returned False)."""
        return []

    def report(self, t: np.ndarray, y: np.ndarray, switch: np.ndarray, *,
               into: tuple[np.ndarray, np.ndarray] | None = None,
               channels: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Only the compiled backend makes reported points consistent itself (after set_layout)."""
        raise DaeclearError("report() needs the compiled backend's state layout (set_layout returned False)")

    def set_stall(self, stall_step: float, count: int) -> None:
        """``count`` tiny steps (below ``stall_step`` s, see stall_guard) end an advance with DC_STEP_COLLAPSE."""
        if not (stall_step >= 0.0) or count < 1:
            raise ValueError(f"set_stall: stall_step={stall_step!r} must be >= 0 and count={count!r} >= 1")
        self._check_open()
        self._stall.stall_step, self._stall.count = float(stall_step), int(count)
        if self.backend == "c":
            self._lib.dc_set_stall(self._h, self._stall.stall_step, self._stall.count)

    def _check_reinit(self, t0: Any, y0: Any, yp0: Any, active: Any, params: Any,
                      root_directions: Any) -> tuple[float, np.ndarray, np.ndarray, np.ndarray,
                                                     list[np.ndarray], np.ndarray]:
        """Validate reinit arguments (kept lean: it runs at every event)."""
        self._check_open()
        t0 = float(t0)
        nt = self._nt
        y0, yp0 = self._vec(y0, "y0"), self._vec(yp0, "yp0")
        if not (math.isfinite(t0) and math.isfinite(y0.sum()) and math.isfinite(yp0.sum())):
            raise ValueError(f"t0, y0 and yp0 must be finite (t0={t0}, y0={y0.tolist()}, yp0={yp0.tolist()})")
        if active is None:
            active = ()
        if len(active) != nt:
            raise ValueError(f"active must have {nt} entries (one per term), got {len(active)}")
        act = np.array([1 if a else 0 for a in active], dtype=np.int32)
        if params is None:
            params = (None,) * nt
        if len(params) != nt:
            raise ValueError(f"params must have {nt} entries (one per term), got {len(params)}")
        plist = []
        n_params = self._model.n_params
        for k in range(nt):
            p, npk = params[k], n_params[k]
            pa = np.zeros(npk) if p is None else np.asarray(p, dtype=float).reshape(-1)
            if pa.size != npk:
                raise ValueError(f"params[{k}] must have {npk} entries, got {pa.size}")
            if act[k] and npk and not math.isfinite(pa.sum()):
                raise ValueError(f"params[{k}] of active term {k} must be finite, got {pa.tolist()}")
            plist.append(pa)
        rd = (self._opts.root_directions if root_directions is None
              else _root_dirs(self._model, root_directions))
        return t0, y0, yp0, act, plist, rd

    @property
    def eval_from(self) -> float:
        """Output times after this are still to come: the current time, or the last filled output row's."""
        after = getattr(self, "_eval_after", None)
        return self._t if after is None else after

    def _select_eval(self, t_eval: Any, t_stop: float) -> np.ndarray:
        if t_eval is None:
            return _EMPTY
        te = np.asarray(t_eval, dtype=float).reshape(-1)
        lo, hi = te.searchsorted((self.eval_from, t_stop), side="right").tolist()
        sel = np.ascontiguousarray(te[lo:hi])
        if sel.size > 1 and (sel[1:] < sel[:-1]).any():
            raise ValueError("t_eval must be sorted in increasing order")
        return sel

    def _check_open(self) -> None:
        if self._closed:
            raise DaeclearError("the session is closed")

    def _check_advance(self, t_stop: Any) -> float:
        self._check_open()
        if not self._ready:
            raise DaeclearError("advance() called before reinit()")
        t_stop = float(t_stop)
        if math.isnan(t_stop) or t_stop < self._t:
            raise ValueError(f"t_stop={t_stop!r} is behind the current time {self._t!r}")
        if math.isinf(t_stop):
            raise ValueError("t_stop must be finite")
        return t_stop

    def close(self) -> None:
        """Free the solver; the session cannot be used afterwards."""
        raise NotImplementedError

    def __enter__(self) -> SessionBase:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"<{type(self).__name__} backend={self.backend!r} model={self._model.name!r} "
                f"n={self._n} terms={self._nt} roots={self._model.n_roots} t={self._t!r}>")


