"""The integrator backend: SUNDIALS IDA on a CasADi model, restartable between events.

``open_session(funcs, ...)`` returns a :class:`Session` that integrates ``F(t, y, y') = 0`` with
IDA in one-step mode and stops at roots of the model's root functions, at a hard stop time, or
at an error. The event logic above it switches the model's *terms* (contact-force
contributions) on and off between segments with :meth:`Session.reinit`; an inactive term is
never evaluated.

Two backends share one interface:

``"c"``
    The model is generated as C with CasADi, compiled with a hand-written IDA driver
    (``csrc/ida_driver.c``) into a shared library linked against the SUNDIALS libraries of the
    scikit-sundae wheel (see :mod:`daeclear.engine.codegen`), and driven through ctypes a few calls per
    segment. No Python runs per step or per model evaluation.
``"python"``
    scikit-sundae's ``IDA`` with callbacks that evaluate the CasADi functions through
    ``casadi.FunctionBuffer``. Differences: ``t_eval`` values are cubic Hermite interpolants
    between stored steps (IDA's own interpolant is not exposed by scikit-sundae; the two
    differ by far less than the integration error), statistics that scikit-sundae does not
    expose are ``-1``, step orders are ``-1``, and a non-finite residual ends the advance with
    ``IDA_RES_FAIL`` at once (the C backend lets IDA retry with smaller steps first).
``"auto"``
    ``"c"`` when a C compiler works, else ``"python"`` with one :class:`DaeclearWarning` naming
    the reason.

Linear solver of the compiled backend (``linear_solver``): IDA's Newton iteration solves with
the iteration matrix dF/dy + cj dF/dy' either by dense LU (SUNDIALS' dense matrix) or by sparse
LU (SuperLU_MT, one thread, on a SUNSparseMatrix whose pattern is the union of the base and all
term Jacobians' patterns). ``"auto"`` picks sparse from ``SPARSE_MIN_STATES`` states on (measured,
``benchmarks/bench_linear_solver.py``). The python backend is always dense.

A compiled library is used only if it was built for the SUNDIALS version and index size that
the wheel has now (its build tag, read from the file before loading, against
:func:`daeclear.engine.codegen.sundials_info`) and that the loaded SUNDIALS reports (``dc_build_info``
and ``SUNDIALSGetVersion``); a stale one is deleted and built again, never run.

Behaviour at a restart (measured with SUNDIALS 7.9, see tests/test_ida_session.py): IDA
returns a root at the end of the final bracket, so the state at a root already lies on the
far side of the crossing (``g`` has changed sign, ``|g|`` tiny). Restarting there does not
report the same crossing again. A root function exactly ``0`` at the restart point is made
inactive until it moves away from zero, so no root is reported at ``t0``. A root function
that is tiny but still on the *near* side at ``t0`` and heading for zero is reported again
within a few ulps of ``t0``: restart from the state IDA returned (or mask the direction with
``root_directions``).
"""

from __future__ import annotations

import contextlib
import ctypes
import io
import logging
import math
import re
import time
import warnings
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple, Protocol, Sequence, runtime_checkable

import casadi
import numpy as np

from . import codegen
from ..assembly.automaton import Decision, PairState, Storm
from ..options import BACKENDS, LINEAR_SOLVERS
from .codegen import (
    memo_get,
    memo_put,
    memo_table,
    BuildResult,
    CompileError,
    CompilerUnavailable,
    NormalizedModel,
    SundialsInfo,
    SundialsMismatch,
    build_model_library,
    DRIVER_ABI,
    normalize_model,
)
from ..errors import DaeclearError, DaeclearWarning

__all__ = [
    "DAEFunctions",
    "Advance",
    "Session",
    "open_session",
    "BACKENDS",
    "LINEAR_SOLVERS",
    "SPARSE_MIN_STATES",
    "StaleLibrary",
    "FLAG_MAX_STEPS",
    "FLAG_STEP_COLLAPSE",
]


#: linear_solver="auto" uses the sparse solver for models with at least this many states. Measured
#: with benchmarks/bench_linear_solver.py (chains of N links, 6 N states; docs/performance.md):
#: dense is faster up to 120 states (SuperLU_MT's fixed cost per factorization), sparse from 144
#: states on (whole simulate calls 1.1x faster at 144 states, 1.3x at 192, 1.8x at 384).
SPARSE_MIN_STATES = 144
_NORMALIZED = memo_table()  # normalize_model results by DAEFunctions identity
_LS_CODES = {"dense": 0, "sparse": 1}  # dc_open's linear_solver argument
log = logging.getLogger("daeclear")

#: flag of an Advance that stopped because the session's step cap (max_steps) was reached
FLAG_MAX_STEPS = -1001
#: flag of an Advance that stopped because the step size collapsed (see TINY_STEP_REL)
FLAG_STEP_COLLAPSE = -1002
#: a step is tiny when |h| < TINY_STEP_REL * max(1, |t|); TINY_STEP_COUNT tiny steps that did not
#: grow by more than TINY_STEP_GROWTH over the previous one, with no normal step in between, stop
#: the advance (step-size collapse). Growing tiny steps (IDA's start-up doubling) do not count.
TINY_STEP_REL = 1e-14
TINY_STEP_COUNT = 20
TINY_STEP_GROWTH = 1.5

_OWN_FLAG_NAMES = {FLAG_MAX_STEPS: "DC_MAX_STEPS", FLAG_STEP_COLLAPSE: "DC_STEP_COLLAPSE"}

_STAT_KEYS = (
    "n_steps",
    "n_res_evals",
    "n_jac_evals",
    "n_lin_setups",
    "n_nonlin_iters",
    "n_nonlin_conv_fails",
    "n_err_test_fails",
    "n_root_evals",
    "n_reinits",
)


@dataclass(frozen=True)
class DAEFunctions:
    """A DAE F(t, y, y') = 0 with switchable terms, as CasADi functions.

    residual: (t[1], y[n], yp[n], P) -> r[n], always active.
    jacobian: (t, y, yp, cj[1], P) -> J[n x n] = dr/dy + cj dr/dyp (dense or sparse output).
    term_residuals[k]: (t, y, yp, p_k[n_params_k], P) -> r_k[n], added to r while term k is active.
    term_jacobians[k]: (t, y, yp, p_k, cj, P) -> J_k[n x n], added to J while term k is active.
    roots: (t, y, yp, P) -> g[n_roots], or None when the model has no events.
    extras[k]: any functions with vector inputs, P last, and one output, compiled into the same
    library and evaluated over many points at once by :meth:`Session.eval_extra` (post-processing:
    output channels, consistent restarts); never called by IDA.

    ``P`` holds the ``n_parameters`` run-time parameters (the values are given to
    :func:`open_session`); with ``n_parameters == 0`` the functions may leave it out.
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


class AutoEvent(NamedTuple):
    """A contact switch the compiled loop decided itself: pair index (in the order given to
    :meth:`CSession.set_auto_events`), the penetration rate there, the decision and the state."""

    t: float
    pair: int
    rate: float
    decision: Decision
    y: np.ndarray


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


@dataclass
class Advance:
    """What one :meth:`Session.advance` call did.

    ``step_*`` hold every point where IDA returned in one-step mode during the call: the end of
    each internal step, and on a root return the root point itself (which lies inside IDA's last
    internal step). Times strictly increase; the start point of the call is not included.
    ``step_h`` is the size of the internal step the point belongs to, ``step_order`` the BDF
    order used for it (-1 when unknown: python backend).
    ``eval_*`` hold the requested ``t_eval`` points reached in this call, in (t_start, t].
    """

    status: str  # "tstop" | "root" | "error" | "interrupted" (Ctrl-C between chunks: the steps so far)
    t: float
    y: np.ndarray
    yp: np.ndarray
    step_t: np.ndarray
    step_y: np.ndarray
    step_yp: np.ndarray
    step_h: np.ndarray
    step_order: np.ndarray
    eval_t: np.ndarray
    eval_y: np.ndarray
    eval_yp: np.ndarray
    roots_found: np.ndarray | None = None
    flag: int = 0
    flag_name: str = ""
    message: str = ""
    # contact switches the compiled loop decided itself (see CSession.set_auto_events), in time order
    auto_events: list[AutoEvent] = field(default_factory=list)

    @property
    def success(self) -> bool:
        return self.status != "error"


@runtime_checkable
class Session(Protocol):
    backend: str

    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None: ...

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: Any = None, store_states: bool = True,
                chunked: bool = False) -> Advance:
        """Integrate towards ``t_stop``; ``store_steps``: keep every step's time, size and order,
        with ``store_states`` also its y and yp (else ``step_y``/``step_yp`` have no rows).
        ``chunked``: return (status ``"chunk"``) whenever the step buffer is full or a step filled
        the last of the ``t_eval`` rows, so that the caller can empty them and call again (a run in
        bounded memory hands ``t_eval`` over in windows); the integration is not changed."""
        ...

    def residual(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray: ...

    def jacobian(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray: ...

    def roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray: ...

    def stats(self) -> dict[str, int | float | str]: ...

    def close(self) -> None: ...


# =========================================================================== options


@dataclass
class _Options:
    rtol: float
    atol: np.ndarray
    max_step: float
    max_order: int
    max_steps: int
    root_directions: np.ndarray  # int32 (n_roots,)
    buffer_steps: int
    parameters: np.ndarray  # run-time parameters P (n_parameters,)
    linear_solver: str = "auto"  # one of LINEAR_SOLVERS, as requested


def _root_dirs(model: NormalizedModel, rd: Any, what: str = "root_directions") -> np.ndarray:
    if rd is None:
        return np.zeros(model.n_roots, dtype=np.int32)
    arr = np.asarray(rd)
    if arr.shape != (model.n_roots,):
        raise ValueError(f"{what} must have shape ({model.n_roots},), got {arr.shape}")
    if arr.size and (arr.min() < -1 or arr.max() > 1 or not np.array_equal(arr, np.round(arr))):
        raise ValueError(f"{what} values must be -1, 0 or +1, got {arr.tolist()}")
    return np.ascontiguousarray(arr, dtype=np.int32)


def _options(model: NormalizedModel, rtol: Any, atol: Any, max_step: Any, max_order: Any,
             max_steps: Any, root_directions: Any, buffer_steps: Any, parameters: Any,
             linear_solver: Any = "auto") -> _Options:
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
    if not np.all(np.isfinite(a) & (a > 0)):
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
    return _Options(rtol, np.ascontiguousarray(a), max_step, int(max_order), int(max_steps),
                    _root_dirs(model, root_directions), int(buffer_steps), P, linear_solver.lower())


# =========================================================================== common base


# dc_advance's store_steps flags (csrc/ida_driver.c DC_STORE_TIMES, DC_STORE_STATES)
STORE_TIMES, STORE_STATES = 1, 2


class _NoRows(dict):
    """Empty (0, n) arrays by n: the step states of an advance that was not asked to keep them."""

    def __missing__(self, n: int) -> np.ndarray:
        self[n] = value = np.empty((0, n))
        value.flags.writeable = False
        return value


_NO_ROWS = _NoRows()

_EMPTY = np.empty(0)
_EMPTY.flags.writeable = False


def _empty_advance_arrays(n: int) -> dict[str, np.ndarray]:
    return dict(
        step_t=np.empty(0), step_y=np.empty((0, n)), step_yp=np.empty((0, n)),
        step_h=np.empty(0), step_order=np.empty(0, dtype=np.int32),
    )


class _SessionBase:
    backend = "?"

    def __init__(self, model: NormalizedModel, opts: _Options) -> None:
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
        self._stall_step, self._stall_count = 0.0, TINY_STEP_COUNT
        self._solve_time = 0.0
        self._extra_stats: dict[str, int | float | str] = {}

    # ---------------------------------------------------------------- properties
    @property
    def n(self) -> int:
        return self._n

    @property
    def n_terms(self) -> int:
        return self._nt

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

    # ---------------------------------------------------------------- validation
    def _vec(self, v: Any, what: str) -> np.ndarray:
        a = np.ascontiguousarray(v, dtype=float)
        if a.shape != (self._n,):
            raise ValueError(f"{what} must have shape ({self._n},), got {a.shape}")
        return a

    def set_hints(self, *, nonlin_conv_coef: float | None = None, init_step: float | None = None) -> bool:
        """Solver hints (see CSession.set_hints); scikit-sundae exposes neither, so the python
        backend ignores them and returns False."""
        return False

    def eval_extra(self, k: int, inputs: Sequence[np.ndarray], n_points: int) -> np.ndarray:
        """Evaluate ``DAEFunctions.extras[k]`` at ``n_points`` points: each input is an array of
        shape (n_points, size) or (size,) (the same for every point); returns (n_points, n_out).
        The compiled backend loops in C; the python backend maps the CasADi function. The
        run-time parameters are appended as the last input."""
        f = self._model.extras[k]
        inputs = [*inputs, self._opts.parameters]
        cols = [np.zeros((0, n_points)) if f.numel_in(j) == 0 else
                np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, f.numel_in(j)), (n_points, f.numel_in(j))).T
                for j, x in enumerate(inputs)]
        fm = f if n_points == 1 else f.map(n_points)
        return np.array(fm(*cols)).reshape(-1, n_points).T.copy()

    def set_auto_events(self, pairs: Sequence[Any], **kwargs: Any) -> bool:
        """Only the compiled backend switches contact pairs in C; returns False here."""
        return False

    def set_layout(self, layout: "StateLayout") -> bool:
        """Only the compiled backend makes states consistent in C; returns False here."""
        return False

    def set_stall(self, stall_step: float, count: int) -> None:
        """Stall detection: ``count`` tiny steps (below ``stall_step`` s and not growing, with no
        step 100x larger in between) end an advance with DC_STEP_COLLAPSE. Both backends."""
        if not (stall_step >= 0.0) or count < 1:
            raise ValueError(f"set_stall: stall_step={stall_step!r} must be >= 0 and count={count!r} >= 1")
        self._stall_step, self._stall_count = float(stall_step), int(count)
        if self.backend == "c":
            self._lib.dc_set_stall(self._h, self._stall_step, self._stall_count)

    def _check_reinit(self, t0: Any, y0: Any, yp0: Any, active: Any, params: Any,
                      root_directions: Any) -> tuple[float, np.ndarray, np.ndarray, np.ndarray,
                                                     list[np.ndarray], np.ndarray]:
        """Validate reinit arguments (kept lean: it runs at every event)."""
        if self._closed:
            raise DaeclearError("the session is closed")
        t0 = float(t0)
        n, nt = self._n, self._nt
        y0 = np.asarray(y0, dtype=float)
        yp0 = np.asarray(yp0, dtype=float)
        if y0.shape != (n,):
            raise ValueError(f"y0 must have shape ({n},), got {y0.shape}")
        if yp0.shape != (n,):
            raise ValueError(f"yp0 must have shape ({n},), got {yp0.shape}")
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
        """Output times after this one are still to come: the current time, or, when the last
        (chunked) advance filled its last output row inside a step, that row's time (the rest
        of the step's output times are given at the next call)."""
        after = getattr(self, "_eval_after", None)
        return self._t if after is None else after

    def _select_eval(self, t_eval: Any, t_stop: float) -> np.ndarray:
        if t_eval is None:
            return _EMPTY
        te = np.asarray(t_eval, dtype=float).reshape(-1)
        lo = int(np.searchsorted(te, self.eval_from, side="right"))
        hi = int(np.searchsorted(te, t_stop, side="right"))
        sel = np.ascontiguousarray(te[lo:hi])
        if sel.size > 1 and np.any(np.diff(sel) < 0):
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

    # ---------------------------------------------------------------- context manager
    def __enter__(self) -> "_SessionBase":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __repr__(self) -> str:
        return (f"<{type(self).__name__} backend={self.backend!r} model={self._model.name!r} "
                f"n={self._n} terms={self._nt} roots={self._model.n_roots} t={self._t!r}>")


# =========================================================================== compiled backend


class StaleLibrary(DaeclearError):
    """A cached compiled library was built for another driver ABI, SUNDIALS version or index size
    than the wheel's now (or than the SUNDIALS it loads): it must not run."""


def _unload(lib: ctypes.CDLL) -> None:
    """dlclose a library that must not be used, so that one rebuilt at the same path is really
    loaded (dlopen of a path that is still open returns the old library)."""
    import _ctypes

    _ctypes.dlclose(lib._handle)


def _version_prefix(text: str) -> str:
    m = re.match(r"\d+\.\d+\.\d+", text)
    return m.group(0) if m else text


def _staleness(built: SundialsInfo, current: SundialsInfo) -> str | None:
    """Why a library built for the SUNDIALS ``built`` must not run with the wheel's SUNDIALS
    ``current``; None if it may."""
    if (built.version, built.index_size) != (current.version, current.index_size):
        return (f"built for SUNDIALS {built.version} with {built.index_size}-bit indices, but the wheel has "
                f"SUNDIALS {current.version} with {current.index_size}-bit indices")
    if built.has_sparse != current.has_sparse:
        return (f"built {'with' if built.has_sparse else 'without'} the sparse solver libraries, which the wheel "
                f"{'has' if current.has_sparse else 'lacks'} now")
    return None


def _check_loaded(lib: ctypes.CDLL, tagged: SundialsInfo) -> tuple[SundialsInfo, str, str | None]:
    """(build info, SUNDIALSGetVersion, problem or None) of a loaded library: dc_build_info must
    say what the file's tag said, and the SUNDIALS it resolved must be the version it was built
    for (another libsundials found first, e.g. through LD_LIBRARY_PATH, would be a silent ABI
    mismatch)."""
    buf = ctypes.create_string_buffer(64)
    lib.dc_sundials_version(buf, 64)
    loaded = buf.value.decode()
    raw = (ctypes.c_int * 6)()
    lib.dc_build_info(raw, 6)
    info = SundialsInfo(f"{raw[0]}.{raw[1]}.{raw[2]}", raw[3], bool(raw[5]))
    if info != tagged or raw[4] != info.index_size:
        return info, loaded, (f"its dc_build_info ({info}, sunindextype {raw[4]} bits) contradicts its build tag "
                              f"({tagged})")
    if _version_prefix(loaded) != info.version:
        return info, loaded, f"built for SUNDIALS {info.version}, but the SUNDIALS it loads reports version {loaded!r}"
    return info, loaded, None


class _CLib:
    """ctypes view of one compiled model library (shared by all its sessions).

    Before loading, the build tag in the file must name this daeclear's driver ABI and the
    wheel's SUNDIALS version, index size and sparse libraries (:func:`_staleness`); once loaded,
    ``dc_build_info`` must agree and the SUNDIALS it resolved must report that version
    (:func:`_check_loaded`), else it is unloaded before any call into SUNDIALS. A mismatch
    raises StaleLibrary.
    """

    _cache: dict[str, "_CLib"] = {}

    def __init__(self, path: Path) -> None:
        self.path = path
        tag = codegen.read_build_tag(path)
        if tag is None:
            raise StaleLibrary(f"{path}: no daeclear build tag (built by another daeclear version)")
        abi, tagged = tag
        if abi != DRIVER_ABI:
            raise StaleLibrary(f"{path}: driver ABI version {abi} != {DRIVER_ABI}")
        why = _staleness(tagged, codegen.sundials_info())
        if why is not None:
            raise StaleLibrary(f"{path}: {why}")
        lib = ctypes.CDLL(str(path))
        P = ctypes.c_void_p
        I = ctypes.c_int
        D = ctypes.c_double
        lib.dc_abi_version.restype = I
        lib.dc_abi_version.argtypes = []
        lib.dc_build_info.restype = I
        lib.dc_build_info.argtypes = [P, I]
        lib.dc_sundials_version.restype = I
        lib.dc_sundials_version.argtypes = [ctypes.c_char_p, I]
        lib.dc_model_info.restype = I
        lib.dc_model_info.argtypes = [P, P, P, P]
        lib.dc_model_name.restype = ctypes.c_char_p
        lib.dc_model_name.argtypes = []
        lib.dc_message.restype = ctypes.c_char_p
        lib.dc_message.argtypes = [P]
        lib.dc_open.restype = P
        lib.dc_open.argtypes = [D, P, D, I, ctypes.c_longlong, P, P, I, ctypes.c_char_p, I]
        lib.dc_jac_nnz.restype = ctypes.c_longlong
        lib.dc_jac_nnz.argtypes = [P]
        lib.dc_linear_solver.restype = I
        lib.dc_linear_solver.argtypes = [P]
        lib.dc_jac_pattern.restype = None
        lib.dc_jac_pattern.argtypes = [P, P, P]
        lib.dc_eval_jacobian_sparse.restype = I
        lib.dc_eval_jacobian_sparse.argtypes = [P, D, P, P, D, P]
        lib.dc_n_parameters.restype = I
        lib.dc_n_parameters.argtypes = []
        lib.dc_set_nonlin_conv_coef.restype = I
        lib.dc_set_nonlin_conv_coef.argtypes = [P, D]
        lib.dc_n_extra.restype = I
        lib.dc_n_extra.argtypes = []
        lib.dc_eval_extra.restype = I
        lib.dc_eval_extra.argtypes = [I, I, I, P, P, P, I]
        lib.dc_set_auto.restype = I
        lib.dc_set_auto.argtypes = [P, I, P, P, P, P, P, P, P, P, P, P, I]
        lib.dc_take_events.restype = I
        lib.dc_take_events.argtypes = [P, I, P, P, P, P, P, P]
        lib.dc_automaton_run.restype = I
        lib.dc_automaton_run.argtypes = [I, P, P, P, I, D, D, I, I, D, P, P, P, P, P]
        lib.dc_pending_events.restype = I
        lib.dc_pending_events.argtypes = [P]
        lib.dc_get_active.restype = None
        lib.dc_get_active.argtypes = [P, P, P]
        lib.dc_set_layout.restype = I
        lib.dc_set_layout.argtypes = [P, I, I, I, I, I, I, I, I, I, D, I]
        lib.dc_report.restype = I
        lib.dc_report.argtypes = [P, I, P, P, P, P, P, P]
        lib.dc_set_stall.restype = I
        lib.dc_set_stall.argtypes = [P, D, I]
        lib.dc_set_init_step.restype = I
        lib.dc_set_init_step.argtypes = [P, D]
        lib.dc_free.restype = None
        lib.dc_free.argtypes = [P]
        lib.dc_reinit.restype = I
        lib.dc_reinit.argtypes = [P, D, P, P, P, P, P]
        lib.dc_advance.restype = I
        lib.dc_advance.argtypes = [P, D, P, I, P, P, P, I, I, P, P, P, P, P, P, P, P, P, P, P]
        lib.dc_stats.restype = None
        lib.dc_stats.argtypes = [P, P]
        lib.dc_eval_residual.restype = I
        lib.dc_eval_residual.argtypes = [P, D, P, P, P]
        lib.dc_eval_jacobian.restype = I
        lib.dc_eval_jacobian.argtypes = [P, D, P, P, D, P]
        lib.dc_eval_roots.restype = I
        lib.dc_eval_roots.argtypes = [P, D, P, P, P]
        lib.dc_set_terms.restype = None
        lib.dc_set_terms.argtypes = [P, P, P]
        lib.dc_flag_name.restype = None
        lib.dc_flag_name.argtypes = [ctypes.c_long, ctypes.c_char_p, I]
        self.lib = lib
        if lib.dc_abi_version() != DRIVER_ABI:
            abi = lib.dc_abi_version()
            _unload(lib)
            raise StaleLibrary(f"{path}: driver ABI version {abi} != {DRIVER_ABI} (build tag said {DRIVER_ABI})")
        info, loaded, why = _check_loaded(lib, tagged)
        if why is not None:
            _unload(lib)
            raise StaleLibrary(f"{path}: {why}")
        #: what the library was compiled for (the -D flags checked against csrc/sundials' config)
        self.build_info: SundialsInfo = info
        #: SUNDIALSGetVersion of the SUNDIALS libraries this library loaded
        self.sundials_version = loaded

    @classmethod
    def load(cls, path: Path) -> "_CLib":
        key = str(path)
        if key not in cls._cache:
            cls._cache[key] = cls(path)
        return cls._cache[key]

    def model_info(self, n_terms: int) -> tuple[int, int, int, list[int]]:
        n, nt, nr = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
        np_ = (ctypes.c_int * max(n_terms, 1))()
        self.lib.dc_model_info(ctypes.addressof(n), ctypes.addressof(nt), ctypes.addressof(nr),
                               ctypes.addressof(np_))
        return n.value, nt.value, nr.value, list(np_)[: nt.value]

    def flag_name(self, flag: int) -> str:
        buf = ctypes.create_string_buffer(64)
        self.lib.dc_flag_name(flag, buf, 64)
        return buf.value.decode()


def _free_c_session(lib: Any, handle: int) -> None:
    lib.dc_free(handle)


def _ptr(a: np.ndarray | None) -> int | None:
    return None if a is None or a.size == 0 else a.ctypes.data


class CSession(_SessionBase):
    """Compiled backend: IDA, callbacks and the step loop in C (see module docstring)."""

    backend = "c"

    def __init__(self, model: NormalizedModel, opts: _Options, clib: _CLib, build: BuildResult) -> None:
        super().__init__(model, opts)
        n, nt, nr, npar = clib.model_info(self._nt)
        if (n, nt, nr, tuple(npar)) != (model.n, self._nt, model.n_roots, model.n_params) \
                or clib.lib.dc_n_parameters() != model.n_parameters:
            raise DaeclearError(
                f"compiled library {clib.path} does not match the model: (n, terms, roots, params) = "
                f"{(n, nt, nr, npar)} != {(model.n, self._nt, model.n_roots, list(model.n_params))}"
            )
        self._clib = clib
        self._lib = clib.lib
        self._build = build
        self._linear_solver = _resolve_linear_solver(opts.linear_solver, n, clib.build_info.has_sparse)
        err = ctypes.create_string_buffer(1024)

        def dc_open() -> Any:
            return self._lib.dc_open(opts.rtol, opts.atol.ctypes.data, opts.max_step, opts.max_order,
                                     opts.max_steps, _ptr(opts.root_directions), _ptr(opts.parameters),
                                     _LS_CODES[self._linear_solver], err, 1024)

        h = dc_open()
        if not h and self._linear_solver == "sparse" and opts.linear_solver == "auto":
            log.info("daeclear: sparse linear solver unavailable, using dense LU: %s", err.value.decode())
            self._linear_solver = "dense"
            h = dc_open()
        if not h:
            raise DaeclearError(f"opening the compiled IDA session failed: {err.value.decode()}")
        self._h = h
        self._finalizer = weakref.finalize(self, _free_c_session, self._lib, h)
        self._jac_nnz = int(self._lib.dc_jac_nnz(h))
        cap = opts.buffer_steps
        self._cap = cap
        # persistent buffers (addresses cached: ctypes calls stay cheap)
        self._st = np.empty(cap)
        self._sy = np.empty((cap, n))
        self._syp = np.empty((cap, n))
        self._sh = np.empty(cap)
        self._sord = np.empty(cap, dtype=np.int32)
        self._yout = np.empty(n)
        self._ypout = np.empty(n)
        self._roots = np.zeros(max(nr, 1), dtype=np.int32)
        self._i_eval = ctypes.c_int()
        self._n_stored = ctypes.c_int()
        self._t_out = ctypes.c_double()
        self._flag = ctypes.c_int()
        self._addr = dict(
            st=self._st.ctypes.data, sy=self._sy.ctypes.data, syp=self._syp.ctypes.data,
            sh=self._sh.ctypes.data, sord=self._sord.ctypes.data, yout=self._yout.ctypes.data,
            ypout=self._ypout.ctypes.data, roots=self._roots.ctypes.data,
            i_eval=ctypes.addressof(self._i_eval), n_stored=ctypes.addressof(self._n_stored),
            t_out=ctypes.addressof(self._t_out), flag=ctypes.addressof(self._flag),
        )
        self._statbuf = np.zeros(len(_STAT_KEYS), dtype=np.int64)
        self._extra_meta: dict[int, tuple[Any, ...]] = {}
        # reinit inputs: copied into fixed arrays whose addresses are known
        self._y0b = np.zeros(n)
        self._yp0b = np.zeros(n)
        self._actb = np.zeros(max(self._nt, 1), dtype=np.int32)
        self._rdb = np.zeros(max(nr, 1), dtype=np.int32)
        self._pcat = np.zeros(max(sum(model.n_params), 1))
        self._poff = np.concatenate([[0], np.cumsum(model.n_params)]).astype(int).tolist()
        for name in ("y0b", "yp0b", "actb", "rdb", "pcat"):
            self._addr[name] = getattr(self, "_" + name).ctypes.data

    def set_hints(self, *, nonlin_conv_coef: float | None = None, init_step: float | None = None) -> bool:
        """Solver hints: Newton convergence factor (IDA default 0.33) and the first step of the
        next restart (0: IDA's estimate). Returns True (the compiled backend applies them)."""
        if nonlin_conv_coef is not None and self._lib.dc_set_nonlin_conv_coef(self._h, nonlin_conv_coef) < 0:
            raise DaeclearError(f"nonlin_conv_coef={nonlin_conv_coef!r} rejected by IDA; must be > 0.")
        if init_step is not None and self._lib.dc_set_init_step(self._h, init_step) < 0:
            raise DaeclearError(f"init_step={init_step!r} rejected by IDA.")
        return True

    def set_auto_events(self, pairs: Sequence[tuple[int, int, int, bool, float]], *, storms: Sequence[Storm],
                        states: Sequence[PairState], capacity: int = 256) -> bool:
        """Let the C loop decide every contact switch itself (after :meth:`set_layout`, see ida_driver.c).

        ``pairs``: (root index, term index, gap-rate extra, needs approach speed, min speed), one
        per root function; ``storms``: each pair's storm-guard constants; ``states``: each pair's
        :class:`daeclear.assembly.automaton.PairState` to start from (its history is not carried over).
        Each advance then returns the switches it made in ``Advance.auto_events``.
        """
        np_ = len(pairs)
        if len(storms) != np_ or len(states) != np_:
            raise ValueError(f"set_auto_events: {np_} pairs, {len(storms)} storms, {len(states)} states")
        capacity = max(int(capacity), np_)

        def arr(values: Any, dt: Any) -> np.ndarray:
            return np.ascontiguousarray(list(values) or [0], dtype=dt)

        self._auto_arrays = [
            arr((p[0] for p in pairs), np.int32), arr((p[1] for p in pairs), np.int32),
            arr((p[2] for p in pairs), np.int32), arr((p[3] for p in pairs), np.int32),
            arr((p[4] for p in pairs), np.float64), arr((st.events for st in storms), np.int32),
            arr((st.window for st in storms), np.float64), arr((st.contact for st in states), np.int32),
            arr((st.held for st in states), np.int32), arr((st.latched for st in states), np.float64)]
        ptr = [a.ctypes.data for a in self._auto_arrays]
        rc = self._lib.dc_set_auto(self._h, np_, *ptr, capacity)
        if rc != 0:
            raise DaeclearError("configuring the events decided in C failed")
        self._auto_cap = capacity
        self._auto_buf = (np.empty(capacity), np.empty(capacity, dtype=np.int32),
                          np.empty((capacity, 4), dtype=np.int32), np.empty(capacity), np.empty(capacity),
                          np.empty((capacity, self._n)))
        return True

    def set_layout(self, layout: StateLayout) -> bool:
        """The model's state layout and extras, so that C makes states consistent itself: restarts
        after the switches it decides (GGL: projected on the constraint manifold) and :meth:`report`."""
        L = layout
        rc = self._lib.dc_set_layout(self._h, L.n_q, L.n_constraints, int(L.ggl), int(L.track_work), L.accel_extra,
                                     L.force_extra0, L.kinematics_extra, L.outputs_extra, int(L.project), L.tol,
                                     L.max_iter)
        if rc != 0:
            raise DaeclearError("configuring the state layout of the compiled model failed")
        self._n_channels = int(self._model.extras[L.outputs_extra].numel_out(0))
        return True

    def report(self, t: np.ndarray, y: np.ndarray, switch: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The reported points made consistent in one C pass: (y with recomputed multipliers, yp,
        output channels), one row per time (see ``dc_report``); after :meth:`set_layout`."""
        t = np.ascontiguousarray(t, dtype=float)
        y = np.ascontiguousarray(y, dtype=float)
        switch = np.ascontiguousarray(switch, dtype=float)
        N = t.size
        y_out, yp_out = np.empty((N, self._n)), np.empty((N, self._n))
        channels = np.empty((N, self._n_channels))
        if N and self._lib.dc_report(self._h, N, t.ctypes.data, y.ctypes.data, switch.ctypes.data,
                                     y_out.ctypes.data, yp_out.ctypes.data, channels.ctypes.data) != 0:
            raise DaeclearError("making the reported points consistent in the compiled model failed")
        return y_out, yp_out, channels

    def _take_auto_events(self) -> list[AutoEvent]:
        buf = getattr(self, "_auto_buf", None)
        if buf is None:
            return []
        t, pair, info, rate, latched, y = buf
        k = self._lib.dc_take_events(self._h, self._auto_cap, t.ctypes.data, pair.ctypes.data, info.ctypes.data,
                                     rate.ctypes.data, latched.ctypes.data, y.ctypes.data)
        return [AutoEvent(float(t[i]), int(pair[i]), float(rate[i]),
                          Decision(int(info[i, 0]), bool(info[i, 1]), bool(info[i, 2]), float(latched[i]),
                                   int(info[i, 3])), y[i].copy()) for i in range(k)]

    def automaton_run(self, times: Sequence[float], directions: Sequence[int], rates: Sequence[float], *,
                      storm: Storm, min_approach_speed: float, contact: bool = False, held: bool = False,
                      latched: float = 0.0) -> list[Decision]:
        """Run the compiled loop's pair automaton over a root sequence from the given state with no
        history (a test hook: the decisions must be those of :func:`daeclear.assembly.automaton.step`)."""
        t = np.ascontiguousarray(times, dtype=np.float64)
        d = np.ascontiguousarray(directions, dtype=np.int32)
        r = np.ascontiguousarray(rates, dtype=np.float64)
        n = t.size
        if d.size != n or r.size != n:
            raise ValueError("automaton_run: times, directions and rates differ in length")
        out_i = np.zeros((4, max(n, 1)), dtype=np.int32)
        out_l = np.zeros(max(n, 1))
        rc = self._lib.dc_automaton_run(n, t.ctypes.data, d.ctypes.data, r.ctypes.data, storm.events,
                                        float(storm.window), float(min_approach_speed), int(contact), int(held),
                                        float(latched), *(out_i[j].ctypes.data for j in range(4)),
                                        out_l.ctypes.data)
        if rc != 0:
            raise DaeclearError("dc_automaton_run rejected its arguments")
        return [Decision(int(out_i[0, i]), bool(out_i[1, i]), bool(out_i[2, i]), float(out_l[i]), int(out_i[3, i]))
                for i in range(n)]

    def active_terms(self) -> tuple[list[bool], list[np.ndarray]]:
        """The active flags and parameters the C loop integrates with now."""
        act = np.zeros(max(self._nt, 1), dtype=np.int32)
        par = np.zeros(max(sum(self._model.n_params), 1))
        self._lib.dc_get_active(self._h, act.ctypes.data, par.ctypes.data)
        off = self._poff
        return [bool(a) for a in act[:self._nt]], [par[off[k]:off[k + 1]].copy() for k in range(self._nt)]

    def eval_extra(self, k: int, inputs: Sequence[np.ndarray], n_points: int) -> np.ndarray:
        inputs = [*inputs, self._opts.parameters]
        meta = self._extra_meta.get(k)
        if meta is None:  # input sizes, output size and reusable ctypes arrays, once per function
            f = self._model.extras[k]
            sizes = [f.numel_in(j) for j in range(f.n_in())]
            meta = (sizes, f.numel_out(0), (ctypes.c_void_p * max(len(sizes), 1))(),
                    (ctypes.c_int * max(len(sizes), 1))())
            self._extra_meta[k] = meta
        sizes, n_out, ptrs, strides = meta
        keep = []
        for j, x in enumerate(inputs):
            a = x if (type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous) \
                else np.ascontiguousarray(x, dtype=float)
            size = sizes[j]
            if a.size == size:
                strides[j] = 0
            elif a.size == n_points * size:
                strides[j] = size
            else:
                raise ValueError(f"eval_extra({k}): input {j} has shape {a.shape}, expected ({n_points}, {size}) or ({size},)")
            ptrs[j] = a.__array_interface__["data"][0]
            keep.append(a)
        out = np.empty((n_points, n_out))
        rc = self._lib.dc_eval_extra(k, n_points, len(sizes), ptrs, strides, out.__array_interface__["data"][0], n_out)
        if rc != 0:
            raise DaeclearError(f"evaluating {self._model.extras[k].name()} in the compiled model failed (status {rc}).")
        return out

    # ---------------------------------------------------------------- core
    def _load_terms(self, act: np.ndarray, plist: list[np.ndarray]) -> None:
        nt = self._nt
        if nt:
            self._actb[:nt] = act
            off = self._poff
            for k in range(nt):
                if off[k + 1] > off[k]:
                    self._pcat[off[k]:off[k + 1]] = plist[k]

    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None:
        t0, y0, yp0, act, plist, rd = self._check_reinit(t0, y0, yp0, active, params, root_directions)
        A = self._addr
        self._y0b[:] = y0
        self._yp0b[:] = yp0
        self._load_terms(act, plist)
        if self.n_roots:
            self._rdb[:] = rd
        rc = self._lib.dc_reinit(self._h, t0, A["y0b"], A["yp0b"], A["actb"], A["pcat"], A["rdb"])
        if rc != 0:
            self._ready = False
            raise DaeclearError(f"IDA reinit failed: {self._lib.dc_message(self._h).decode()}")
        self._t, self._y, self._yp = t0, self._y0b.copy(), self._yp0b.copy()
        self._eval_after = None  # the C side drops a step cut short (dc_reinit)
        self._active = act
        self._params = plist
        self._ready = True

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: Any = None, store_states: bool = True,
                chunked: bool = False) -> Advance:
        t_stop = self._check_advance(t_stop)
        n = self._n
        te = self._select_eval(t_eval, t_stop)
        m = te.size
        ev_y = np.empty((m, n))
        ev_yp = np.empty((m, n))
        te_p, evy_p, evyp_p = (te.ctypes.data, ev_y.ctypes.data, ev_yp.ctypes.data) if m else (None, None, None)
        A = self._addr
        self._i_eval.value = 0
        chunks: list[tuple[np.ndarray, ...]] = []
        auto_events: list[AutoEvent] = []
        store = (STORE_TIMES | (STORE_STATES if store_states else 0)) if store_steps else 0
        lib, h = self._lib, self._h
        tic = time.perf_counter()
        interrupted = False
        try:
            while True:
                rc = lib.dc_advance(h, t_stop, te_p, m, A["i_eval"], evy_p, evyp_p,
                                    store, self._cap, A["st"], A["sy"], A["syp"], A["sh"], A["sord"],
                                    A["n_stored"], A["t_out"], A["yout"], A["ypout"], A["roots"],
                                    A["flag"])
                k = self._n_stored.value
                if k:
                    states = (self._sy[:k].copy(), self._syp[:k].copy()) if store_states else (_NO_ROWS[n],) * 2
                    chunks.append((self._st[:k].copy(), *states, self._sh[:k].copy(), self._sord[:k].copy()))
                auto_events += self._take_auto_events()  # drained at every chunk: the C buffer never overflows
                if rc != 0 or chunked:
                    break
                # buffer full: back in Python between chunks, so Ctrl-C works here
                if on_chunk is not None:  # time reached, and contact switches made in C so far
                    on_chunk(self._t_out.value, len(auto_events))
        except KeyboardInterrupt:  # between chunks: return the steps taken so far, marked "interrupted"
            interrupted, rc = True, 1
        finally:
            self._solve_time += time.perf_counter() - tic
            # also after an interrupt between chunks: the C side stopped at a valid state
            self._t = self._t_out.value
            self._y = self._yout.copy()  # shared with the Advance: the session only reads it
            self._yp = self._ypout.copy()
        if len(chunks) == 1:
            st, sy, syp, sh, so = chunks[0]
        elif chunks:
            st, sy, syp, sh, so = (np.concatenate(c) for c in zip(*chunks))
        else:
            e = _empty_advance_arrays(n)
            st, sy, syp, sh, so = e["step_t"], e["step_y"], e["step_yp"], e["step_h"], e["step_order"]
        ne = self._i_eval.value
        # the C loop stopped inside a step that has output times after the last row (see dc_advance)
        self._eval_after = float(te[-1]) if rc == 0 and m and ne == m and te[-1] < self._t else None
        adv = Advance(status="tstop", t=self._t, y=self._y, yp=self._yp, step_t=st,
                      step_y=sy, step_yp=syp, step_h=sh, step_order=so, eval_t=te[:ne].copy(),
                      eval_y=ev_y[:ne], eval_yp=ev_yp[:ne], auto_events=auto_events)
        if interrupted:
            adv.status = "interrupted"
            return adv
        if rc == 0:  # chunked: a buffer is full, the integration goes on at the next call
            adv.status = "chunk"
            return adv
        if rc == 1:
            return adv
        if rc == 2:
            adv.status = "root"
            adv.roots_found = self._roots[: self.n_roots].copy()
            return adv
        adv.status = "error"
        msg = self._lib.dc_message(h).decode()
        if rc == -2:
            adv.flag, adv.flag_name = FLAG_MAX_STEPS, _OWN_FLAG_NAMES[FLAG_MAX_STEPS]
        elif rc == -3:
            adv.flag, adv.flag_name = FLAG_STEP_COLLAPSE, _OWN_FLAG_NAMES[FLAG_STEP_COLLAPSE]
        else:
            adv.flag = self._flag.value
            adv.flag_name = self._clib.flag_name(adv.flag) if adv.flag else "DC_USAGE"
        adv.message = msg
        return adv

    # ---------------------------------------------------------------- model evaluation
    def residual(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty(self._n)
        self._sync_terms()
        if self._lib.dc_eval_residual(self._h, float(t), y.ctypes.data, yp.ctypes.data, out.ctypes.data):
            raise DaeclearError(f"the generated residual failed at t={t}")
        return out

    def sparse_jacobian(self, t: float, y: np.ndarray, yp: np.ndarray,
                        cj: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The iteration matrix as the sparse solver sees it: CSC (data, row indices, column
        pointers) on the union of the base and all term Jacobians' patterns (explicit zeros for
        inactive terms), whatever the session's linear solver."""
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        colptr = np.empty(self._n + 1, dtype=np.int64)
        rowind = np.empty(max(self._jac_nnz, 1), dtype=np.int64)
        data = np.empty(max(self._jac_nnz, 1))
        self._lib.dc_jac_pattern(self._h, colptr.ctypes.data, rowind.ctypes.data)
        self._sync_terms()
        if self._lib.dc_eval_jacobian_sparse(self._h, float(t), y.ctypes.data, yp.ctypes.data, float(cj),
                                             data.ctypes.data):
            raise DaeclearError(f"the generated Jacobian failed at t={t}")
        return data[:self._jac_nnz], rowind[:self._jac_nnz], colptr

    def jacobian(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty((self._n, self._n), order="F")
        self._sync_terms()
        if self._lib.dc_eval_jacobian(self._h, float(t), y.ctypes.data, yp.ctypes.data, float(cj),
                                      out.ctypes.data):
            raise DaeclearError(f"the generated Jacobian failed at t={t}")
        return np.ascontiguousarray(out)

    def roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._check_open()
        y, yp = self._vec(y, "y"), self._vec(yp, "yp")
        out = np.empty(self.n_roots)
        if self.n_roots and self._lib.dc_eval_roots(self._h, float(t), y.ctypes.data, yp.ctypes.data,
                                                    out.ctypes.data):
            raise DaeclearError(f"the generated root function failed at t={t}")
        return out

    def set_terms(self, active: Sequence[bool], params: Sequence[np.ndarray]) -> None:
        """Set active terms and parameters without restarting IDA (for residual/jacobian checks).

        The next advance() without reinit() integrates with them; prefer reinit() in event logic.
        """
        _, _, _, act, plist, _ = self._check_reinit(self._t, self._y, self._yp, active, params, None)
        self._active, self._params = act, plist
        self._sync_terms()

    def _sync_terms(self) -> None:
        self._load_terms(self._active, self._params)
        self._lib.dc_set_terms(self._h, self._addr["actb"], self._addr["pcat"])

    # ---------------------------------------------------------------- stats and lifetime
    def stats(self) -> dict[str, int | float | str]:
        self._check_open()
        self._lib.dc_stats(self._h, self._statbuf.ctypes.data)
        out: dict[str, int | float | str] = {k: int(v) for k, v in zip(_STAT_KEYS, self._statbuf)}
        out["solve_time"] = self._solve_time
        out["compile_time"] = self._build.compile_time
        out["codegen_time"] = self._build.codegen_time
        out["cache_hit"] = bool(self._build.cache_hit)
        out["linear_solver"] = "sparse" if self._lib.dc_linear_solver(self._h) else "dense"
        out["jac_nnz"] = self._jac_nnz
        return out

    @property
    def linear_solver(self) -> str:
        """"dense" or "sparse": the LU IDA's Newton iteration uses in this session."""
        return self._linear_solver

    @property
    def library_path(self) -> Path:
        return self._build.path

    @property
    def cache_hit(self) -> bool:
        return self._build.cache_hit

    @property
    def sundials_version(self) -> str:
        return self._clib.sundials_version

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._finalizer()


# =========================================================================== python backend


class _ModelError(Exception):
    """Raised inside a scikit-sundae callback; ends the advance with a clear message."""


class _Buffered:
    """A CasADi function evaluated through FunctionBuffer on fixed numpy arrays."""

    def __init__(self, f: casadi.Function, args: list[np.ndarray]) -> None:
        self.buf, self.call = f.buffer()
        self.args = args  # kept alive: the buffer points into them
        for i, a in enumerate(args):
            self.buf.set_arg(i, memoryview(a))
        self.out = np.zeros(f.nnz_out(0))
        self.buf.set_res(0, memoryview(self.out))


def _hermite(t0: float, y0: np.ndarray, yp0: np.ndarray, t1: float, y1: np.ndarray,
             yp1: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    h = t1 - t0
    s = ((t - t0) / h)[:, None]
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    y = h00 * y0 + h10 * h * yp0 + h01 * y1 + h11 * h * yp1
    d00 = (6 * s**2 - 6 * s) / h
    d10 = 3 * s**2 - 4 * s + 1
    d01 = (-6 * s**2 + 6 * s) / h
    d11 = 3 * s**2 - 2 * s
    yp = d00 * y0 + d10 * yp0 + d01 * y1 + d11 * yp1
    return y, yp


class PythonSession(_SessionBase):
    """scikit-sundae IDA with FunctionBuffer callbacks (see module docstring)."""

    backend = "python"

    def __init__(self, model: NormalizedModel, opts: _Options, fallback_reason: str | None = None) -> None:
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
        self._jac = _Buffered(model.dense(model.jac), base + [self._a_cj, P])
        self._tres = [_Buffered(f, base + [p, P]) for f, p in zip(model.term_res, self._a_p)]
        self._tjac = [_Buffered(model.dense(f), base + [p, self._a_cj, P]) for f, p in zip(model.term_jac, self._a_p)]
        self._roots_fn = _Buffered(model.roots, base + [P]) if model.roots is not None else None
        self._active_idx: list[int] = []
        self._solver: Any = None
        self._solver_dirs: np.ndarray | None = None
        self._count = dict(res=0, jac=0, roots=0, steps=0, reinits=0)
        self._pending_tn = False
        self._t_internal = 0.0
        self._tiny = 0
        self._h_prev = 0.0

    # ---------------------------------------------------------------- evaluation
    def _eval_res(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._a_t[0] = t
        self._a_y[:] = y
        self._a_yp[:] = yp
        self._res.call()
        r = self._res.out
        if self._active_idx:
            r = r.copy()
            for k in self._active_idx:
                self._tres[k].call()
                r += self._tres[k].out
        return r

    def _eval_jac(self, t: float, y: np.ndarray, yp: np.ndarray, cj: float) -> np.ndarray:
        self._a_t[0] = t
        self._a_y[:] = y
        self._a_yp[:] = yp
        self._a_cj[0] = cj
        self._jac.call()
        J = self._jac.out
        if self._active_idx:
            J = J.copy()
            for k in self._active_idx:
                self._tjac[k].call()
                J += self._tjac[k].out
        return J.reshape(self._n, self._n, order="F")

    def _eval_roots(self, t: float, y: np.ndarray, yp: np.ndarray) -> np.ndarray:
        self._a_t[0] = t
        self._a_y[:] = y
        self._a_yp[:] = yp
        self._roots_fn.call()
        return self._roots_fn.out

    def _make_solver(self, rd: np.ndarray) -> Any:
        from sksundae.ida import IDA

        count = self._count
        eval_res, eval_jac, eval_roots = self._eval_res, self._eval_jac, self._eval_roots
        isfinite = math.isfinite

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
            JJ[:, :] = J

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

            events.terminal = [True] * self.n_roots
            events.direction = [int(d) for d in rd]
            options.update(eventsfn=events, num_events=self.n_roots)
            self._events = events
        return IDA(resfn, **options)

    # ---------------------------------------------------------------- core
    def reinit(self, t0: float, y0: np.ndarray, yp0: np.ndarray, active: Sequence[bool],
               params: Sequence[np.ndarray], root_directions: np.ndarray | None = None) -> None:
        t0, y0, yp0, act, plist, rd = self._check_reinit(t0, y0, yp0, active, params, root_directions)
        self._apply_terms(act, plist)
        if self._solver is None or (self.n_roots and not np.array_equal(rd, self._solver_dirs)):
            # scikit-sundae sets root directions only when it builds its IDA memory
            self._solver = self._make_solver(rd)
            self._solver_dirs = rd.copy()
        try:
            self._solver.init_step(t0, y0, yp0)
        except _ModelError as exc:
            self._ready = False
            raise DaeclearError(f"IDA reinit failed: {exc}") from exc
        except RuntimeError as exc:
            self._ready = False
            raise DaeclearError(f"IDA reinit failed: {exc}") from exc
        self._count["reinits"] += 1
        self._t, self._y, self._yp = t0, y0.copy(), yp0.copy()
        self._t_internal = t0
        self._pending_tn = False
        self._tiny = 0
        self._h_prev = 0.0
        self._ready = True

    def _apply_terms(self, act: np.ndarray, plist: list[np.ndarray]) -> None:
        self._active = act
        self._params = plist
        for k, p in enumerate(plist):
            self._a_p[k][:] = p
        self._active_idx = [k for k in range(self._nt) if act[k]]

    def set_terms(self, active: Sequence[bool], params: Sequence[np.ndarray]) -> None:
        """Set active terms and parameters without restarting IDA (see CSession.set_terms)."""
        _, _, _, act, plist, _ = self._check_reinit(self._t, self._y, self._yp, active, params, None)
        self._apply_terms(act, plist)

    def advance(self, t_stop: float, t_eval: np.ndarray | None = None,
                store_steps: bool = True, on_chunk: Any = None, store_states: bool = True,
                chunked: bool = False) -> Advance:
        t_stop = self._check_advance(t_stop)
        n = self._n
        te = self._select_eval(t_eval, t_stop)
        ev_y = np.empty((te.size, n))
        ev_yp = np.empty((te.size, n))
        ie = 0
        st: list[float] = []
        sy: list[np.ndarray] = []
        syp: list[np.ndarray] = []
        sh: list[float] = []
        t_rec = self._t
        status, flag, flag_name, message, roots = "tstop", 0, "", "", None
        solver = self._solver
        max_steps = self._opts.max_steps
        tic = time.perf_counter()
        try:
            if t_stop - self._t <= 4.0 * np.finfo(float).eps * max(abs(t_stop), abs(self._t)):
                status = "tstop"
            else:
                while True:
                    if self._count["steps"] >= max_steps:
                        status, flag = "error", FLAG_MAX_STEPS
                        flag_name = _OWN_FLAG_NAMES[flag]
                        message = (f"step cap reached: {self._count['steps']} IDA steps in this session "
                                   f"(max_steps={max_steps}) at t={self._t!r}")
                        break
                    interpolated = False
                    try:
                        if self._pending_tn:
                            # after a root return IDA's internal time tn is beyond self._t; a
                            # t_stop inside (self._t, tn) makes IDASetStopTime fail (scikit-sundae
                            # prints that error): then IDA_NORMAL mode interpolates, as in C
                            try:
                                with contextlib.redirect_stdout(io.StringIO()):
                                    r = solver.step(t_stop, method="onestep", tstop=t_stop)
                            except RuntimeError as exc:
                                if "IDASetStopTime" not in str(exc):
                                    raise
                                r = solver.step(t_stop, method="normal", tstop=None)
                                interpolated = True
                        else:
                            r = solver.step(t_stop, method="onestep", tstop=t_stop)
                    except _ModelError as exc:
                        status, flag, flag_name = "error", -8, "IDA_RES_FAIL"
                        message = f"IDA_RES_FAIL at t={self._t!r}: {exc}"
                        break
                    fl = int(r.status)
                    if fl < 0:
                        status, flag = "error", fl
                        flag_name = _IDA_FLAG_NAMES.get(fl, f"IDA flag {fl}")
                        message = f"{flag_name} at t={float(r.t)!r}: {r.message}"
                        self._t, self._y, self._yp = float(r.t), np.array(r.y, float), np.array(r.yp, float)
                        break
                    t_prev, y_prev, yp_prev = self._t, self._y, self._yp
                    t_new = float(r.t)
                    y_new = np.array(r.y, dtype=float).reshape(-1)
                    yp_new = np.array(r.yp, dtype=float).reshape(-1)
                    # was a new internal step taken in this call?
                    new_step = False
                    h = float("nan")
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
                    elif t_new > t_prev:
                        new_step = True
                        self._count["steps"] += 1
                        h = t_new - self._t_internal
                        self._t_internal = t_new
                    self._t, self._y, self._yp = t_new, y_new, yp_new
                    # t_eval points in (t_prev, t_new]: cubic Hermite on the two return points
                    filled = ie < te.size and te[ie] <= t_new
                    if filled:
                        j = int(np.searchsorted(te, t_new, side="right"))
                        yy, yyp = _hermite(t_prev, y_prev, yp_prev, t_new, y_new, yp_new, te[ie:j])
                        ev_y[ie:j], ev_yp[ie:j] = yy, yyp
                        ie = j
                    if store_steps and t_new > t_rec:
                        st.append(t_new)
                        sy.append(y_new)
                        syp.append(yp_new)
                        sh.append(h)
                        t_rec = t_new
                    if new_step and fl != 1 and not math.isnan(h):
                        thr = max(TINY_STEP_REL * max(1.0, abs(t_new)), self._stall_step)
                        if abs(h) >= (100.0 * thr if self._stall_step > 0 else thr):
                            self._tiny = 0
                        elif abs(h) < thr and not abs(h) > TINY_STEP_GROWTH * abs(self._h_prev):
                            self._tiny += 1
                        self._h_prev = h
                        if self._tiny >= self._stall_count:
                            status, flag = "error", FLAG_STEP_COLLAPSE
                            flag_name = _OWN_FLAG_NAMES[flag]
                            message = (f"step size collapsed: {self._tiny} steps with |h| < "
                                       f"max({TINY_STEP_REL}*max(1,|t|), {self._stall_step} s) that did "
                                       f"not grow (last h={h:.3g}) "
                                       f"at t={t_new!r}")
                            break
                    if fl == 2:
                        status = "root"
                        roots = np.asarray(r.i_events[-1], dtype=np.int32).copy()
                        ev = getattr(self, "_events", None)
                        if ev is not None:  # keep scikit-sundae's event log from growing
                            for name in ("_i", "_t", "_y", "_yp"):
                                getattr(ev, name).clear()
                        break
                    if fl == 1:
                        status = "tstop"
                        break
                    if chunked and ((te.size and ie == te.size and filled)
                                    or len(st) >= self._opts.buffer_steps):
                        status = "chunk"  # the caller empties the rows and calls again
                        break
        finally:
            self._solve_time += time.perf_counter() - tic
        k = len(st)
        adv = Advance(
            status=status, t=self._t, y=self._y.copy(), yp=self._yp.copy(),
            step_t=np.array(st, dtype=float), step_y=np.array(sy, dtype=float).reshape(k, n),
            step_yp=np.array(syp, dtype=float).reshape(k, n), step_h=np.array(sh, dtype=float),
            step_order=np.full(k, -1, dtype=np.int32), eval_t=te[:ie].copy(), eval_y=ev_y[:ie],
            eval_yp=ev_yp[:ie], roots_found=roots, flag=flag, flag_name=flag_name, message=message,
        )
        return adv

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
        return {
            "n_steps": c["steps"],
            "n_res_evals": c["res"],
            "n_jac_evals": c["jac"],
            "n_lin_setups": -1,
            "n_nonlin_iters": -1,
            "n_nonlin_conv_fails": -1,
            "n_err_test_fails": -1,
            "n_root_evals": c["roots"],
            "n_reinits": c["reinits"],
            "solve_time": self._solve_time,
            "compile_time": 0.0,
            "codegen_time": 0.0,
            "cache_hit": False,
            "linear_solver": "dense",
            "jac_nnz": self._n * self._n,
        }

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


# =========================================================================== factory

_warned: set[str] = set()


def _warn_once(reason: str) -> None:
    if reason in _warned:
        return
    _warned.add(reason)
    warnings.warn(
        "daeclear: the compiled IDA backend is unavailable, using the pure-Python backend "
        f"(scikit-sundae with CasADi FunctionBuffer callbacks), typically 10-30x slower. Reason: {reason}",
        DaeclearWarning,
        stacklevel=3,
    )


def _resolve_linear_solver(requested: str, n: int, has_sparse: bool) -> str:
    """The linear solver a compiled session uses: "auto" is sparse from SPARSE_MIN_STATES states on
    (when the library has the sparse solver)."""
    if requested == "auto":
        return "sparse" if has_sparse and n >= SPARSE_MIN_STATES else "dense"
    if requested == "sparse" and not has_sparse:
        raise DaeclearError("linear_solver='sparse' is not available: the scikit-sundae wheel lacks "
                            f"lib{codegen.SPARSE_LIBS[0]} or lib{codegen.SPARSE_LIBS[1]}; use 'dense' or 'auto'")
    return requested


def _file_id(path: Path) -> tuple[int, int] | None:
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_ino, st.st_mtime_ns


def _remove_if_unchanged(path: Path, seen: tuple[int, int] | None) -> None:
    """Delete a rejected cache entry, unless another process has replaced it meanwhile (by a
    good build: deleting that would only make it build once more)."""
    if seen is not None and _file_id(path) == seen:
        path.unlink(missing_ok=True)


def _load_library(funcs: DAEFunctions, model: NormalizedModel) -> tuple[_CLib, BuildResult]:
    """Build (or find in the cache) the model's library and load it. A damaged cache entry, or
    a stale one (other driver ABI, SUNDIALS version or index size), is deleted and built once
    more, never run; SundialsMismatch if even the fresh build does not fit the loaded SUNDIALS."""
    build = build_model_library(funcs, model=model)
    seen = _file_id(build.path)
    try:
        return _CLib.load(build.path), build
    except (OSError, StaleLibrary) as exc:
        log.info("daeclear: rebuilding the compiled model %r: %s", model.name, exc)
        _remove_if_unchanged(build.path, seen)
    build = build_model_library(funcs, model=model)
    seen = _file_id(build.path)
    try:
        return _CLib.load(build.path), build
    except StaleLibrary as exc:
        _remove_if_unchanged(build.path, seen)
        raise SundialsMismatch(f"{exc} (even freshly built: the SUNDIALS libraries the library loads are not "
                               "those of the scikit-sundae wheel)") from exc


def open_session(funcs: DAEFunctions, *, backend: str = "auto", rtol: float, atol: np.ndarray | float,
                 max_step: float = 0.0, max_order: int = 5, max_steps: int = 5_000_000,
                 root_directions: np.ndarray | None = None, buffer_steps: int = 4096,
                 parameters: np.ndarray | None = None, linear_solver: str = "auto") -> Session:
    """Open an IDA session on a model; see the module docstring.

    backend: "auto" (compiled if a C compiler works, else python with one DaeclearWarning),
    "c" (DaeclearError if it cannot be built) or "python"; case-insensitive.
    atol: per-variable absolute tolerances (a scalar is broadcast). max_step 0: unbounded.
    max_steps: cap on the IDA steps of the whole session (all segments). root_directions:
    default directions (-1, 0, +1 per root function; reinit may override them per segment).
    buffer_steps: rows of the step buffers the C loop fills before returning to Python.
    parameters: the run-time parameters P of the model (``funcs.n_parameters`` values).
    linear_solver: "auto" (sparse from SPARSE_MIN_STATES states on), "dense" or "sparse"
    (SuperLU_MT on the union of the Jacobians' patterns); case-insensitive. Compiled backend
    only: the python backend always uses scikit-sundae's dense solver.
    Call reinit() before the first advance().
    """
    if not isinstance(backend, str) or backend.lower() not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}: valid backends are {', '.join(map(repr, BACKENDS))}")
    b = backend.lower()
    model = memo_get(_NORMALIZED, funcs)
    if model is None:
        model = normalize_model(funcs)
        memo_put(_NORMALIZED, funcs, model)
    opts = _options(model, rtol, atol, max_step, max_order, max_steps, root_directions, buffer_steps, parameters,
                    linear_solver)
    if b == "python":
        return PythonSession(model, opts)
    try:
        clib, build = _load_library(funcs, model)
        return CSession(model, opts, clib, build)
    except (CompilerUnavailable, CompileError, OSError) as exc:
        if b == "c":
            if isinstance(exc, DaeclearError):
                raise
            raise DaeclearError(f"the compiled backend cannot be loaded: {exc}") from exc
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        if isinstance(exc, CompileError):
            reason = str(exc).strip()[:2000]
        _warn_once(reason)
        return PythonSession(model, opts, fallback_reason=str(exc))
