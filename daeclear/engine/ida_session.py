"""The integrator backend: SUNDIALS IDA on a CasADi model, restartable between events.

``open_session(funcs, ...)`` returns a :class:`Session` that integrates ``F(t, y, y') = 0`` with IDA in
one-step mode and stops at roots of the root functions, at a stop time or at an error; the event logic
above it switches the model's *terms* (contact forces) between segments with :meth:`Session.reinit`.
Backends: ``"c"`` (:mod:`daeclear.engine.c_session`), ``"python"`` (:mod:`daeclear.engine.python_session`:
``t_eval`` values by cubic Hermite, statistics it lacks and step orders ``-1``, a non-finite residual
ends the advance with ``IDA_RES_FAIL`` at once) and ``"auto"`` (``"c"`` when a C compiler works, else
``"python"`` with one :class:`DaeclearWarning`). A stale compiled library is built again, never run.

At a restart (SUNDIALS 7.9, tests/test_ida_session.py): IDA returns a root on the far side of the
crossing, so restarting there does not report it again; a root function exactly ``0`` at ``t0`` is
inactive until it moves away from zero; one tiny but still on the *near* side and heading for zero is
reported again within a few ulps (restart from IDA's state, or mask it with ``root_directions``).
"""

from __future__ import annotations

import logging

import numpy as np

from ..core.errors import DaeclearError, warn_once
from ..core.options import BACKENDS, LINEAR_SOLVERS
from .build import CompileError, CompilerUnavailable
from .c_session import SPARSE_MIN_STATES, CSession
from .compiled import CompiledDAE
from .library import StaleLibrary
from .python_session import PythonSession
from .session_base import (FLAG_MAX_STEPS, FLAG_STEP_COLLAPSE, STORE_STATES, STORE_TIMES, Advance, AutoEvents,
                           DAEFunctions, Session, StateLayout, check_options)
from .stall_guard import TINY_STEP_COUNT, TINY_STEP_GROWTH, TINY_STEP_REL

__all__ = ["DAEFunctions", "CompiledDAE", "Advance", "Session", "open_session", "BACKENDS", "LINEAR_SOLVERS",
           "SPARSE_MIN_STATES", "StaleLibrary", "FLAG_MAX_STEPS", "FLAG_STEP_COLLAPSE", "AutoEvents", "StateLayout",
           "CSession", "PythonSession", "TINY_STEP_REL", "TINY_STEP_COUNT", "TINY_STEP_GROWTH", "STORE_TIMES",
           "STORE_STATES"]

log = logging.getLogger("daeclear")


def _warn_fallback(reason: str) -> None:
    """Name the fallback to the python backend, once per reason in a process."""
    warn_once(
        "daeclear: the compiled IDA backend is unavailable, using the pure-Python backend "
        "(scikit-sundae with CasADi FunctionBuffer callbacks), typically 10-70x slower. Its results agree with "
        "the compiled loop's to the integration tolerance, not digit for digit: on the chapter's slider-crank "
        "the same impacts at rtol <= 1e-8, but 35 against 26 over two revolutions at rtol 1e-6 (a contact "
        "sequence amplifies the small differences of the two step sequences); tighten rtol to compare runs "
        f"(docs/reliability.md). Reason: {reason}",
        stacklevel=3,
    )


def open_session(funcs: DAEFunctions | CompiledDAE, *, backend: str = "auto", rtol: float, atol: np.ndarray | float,
                 max_step: float = 0.0, max_order: int = 5, max_steps: int = 5_000_000,
                 root_directions: np.ndarray | None = None, buffer_steps: int = 4096,
                 parameters: np.ndarray | None = None, linear_solver: str = "auto") -> Session:
    """Open an IDA session on a model (see the module docstring); call reinit() before the first advance().

    funcs: the model's functions, or their :class:`~daeclear.engine.compiled.CompiledDAE`, which keeps
    what this call normalises, builds and loads for the next session (bare functions: made anew).

    backend: "auto", "c" (DaeclearError if it cannot be built) or "python"; case-insensitive.
    atol: per-variable absolute tolerances (a scalar is broadcast). max_step 0: unbounded.
    max_steps: cap on the IDA steps of the whole session. root_directions: default directions
    (-1, 0, +1 per root function; reinit may override them). buffer_steps: rows of the step buffers
    the C loop fills before returning. parameters: the model's run-time parameters P.
    linear_solver: "auto", "reduced", "dense" or "sparse" (:mod:`daeclear.engine.c_session`; the python
    backend is always dense); case-insensitive.
    """
    if not isinstance(backend, str) or backend.lower() not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}: valid backends are {', '.join(map(repr, BACKENDS))}")
    b = backend.lower()
    compiled = funcs if isinstance(funcs, CompiledDAE) else CompiledDAE(funcs)
    model = compiled.normalized()
    opts = check_options(model, rtol, atol, max_step, max_order, max_steps, root_directions, buffer_steps,
                         parameters, linear_solver)
    if b == "python":
        return PythonSession(model, opts)
    try:
        clib, build = compiled.library()
        return CSession(model, opts, clib, build)
    except (CompilerUnavailable, CompileError, OSError) as exc:
        if b == "c":
            if isinstance(exc, DaeclearError):
                raise
            raise DaeclearError(f"the compiled backend cannot be loaded: {exc}") from exc
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        if isinstance(exc, CompileError):
            reason = str(exc).strip()[:2000]
        _warn_fallback(reason)
        return PythonSession(model, opts, fallback_reason=str(exc))
