"""The values of a load (a number, a :class:`Table` in time or an :class:`Expression`) and their math,
written once for numbers and CasADi symbols; :mod:`daeclear.model.loads` re-exports everything here.
"""

from __future__ import annotations

import hashlib
import inspect
import math
import types
from dataclasses import dataclass
from typing import Any
from collections.abc import Callable, Sequence

from ..contact import backend
from .elements import is_finite_number

# the math of expressions, written once for numbers and CasADi symbols
atan2, cos, exp, fabs, fmax, fmin = backend.atan2, backend.cos, backend.exp, backend.fabs, backend.fmax, backend.fmin
if_else, log, sign = backend.if_else, backend.log, backend.sign
sin, sqrt, tanh = backend.sin, backend.sqrt, backend.tanh

__all__ = [
    "Expression", "LoadState", "Table", "Value", "atan2", "cos", "exp", "fabs", "fmax", "fmin", "if_else",
    "interpolate", "log", "sign", "sin", "sqrt", "tanh",
]


@dataclass(frozen=True)
class Table:
    """A value tabulated in time: linear interpolation between ``(times[k], values[k])``, held at the
    end values outside them. Times and values are run-time parameters, their number is structure."""

    times: tuple[float, ...]
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        for name in ("times", "values"):
            try:
                object.__setattr__(self, name, tuple(float(x) for x in getattr(self, name)))
            except (TypeError, ValueError):
                pass  # reported by problems()

    def problems(self, where: str) -> list[str]:
        """Problems of the table, each headed by ``where`` (e.g. ``"Torque 't': value="``)."""
        times, values = self.times, self.values
        for name, seq in (("times", times), ("values", values)):
            if not isinstance(seq, tuple) or not all(math.isfinite(x) for x in seq):
                shown = list(seq) if isinstance(seq, tuple) else seq
                return [f"{where}Table: {name}={shown!r}, must be a sequence of finite numbers."]
        if len(times) < 2 or len(times) != len(values):
            return [f"{where}Table: {len(times)} times and {len(values)} values, must be as many (at least 2)."]
        if any(b <= a for a, b in zip(times, times[1:])):
            return [f"{where}Table: times={list(times)!r} s, must be strictly increasing."]
        return []

    def __call__(self, t: Any) -> Any:
        """The interpolated value at ``t`` (numbers or CasADi symbols)."""
        return interpolate(self.times, self.values, t)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "Table", "times": list(self.times), "values": list(self.values)}


def interpolate(times: Sequence[Any], values: Sequence[Any], t: Any) -> Any:
    """Piecewise-linear interpolation, constant outside the table, branch-free:
    ``v0 + sum_k (s_k - s_{k-1}) max(t - t_k, 0)`` with ``s_k`` the slope after ``t_k``."""
    n = len(times)
    slopes = [(values[k + 1] - values[k]) / (times[k + 1] - times[k]) for k in range(n - 1)] + [0.0]
    out = values[0] + 0.0 * t
    previous: Any = 0.0
    for k in range(n):
        out = out + (slopes[k] - previous) * fmax(t - times[k], 0.0)
        previous = slopes[k]
    return out


@dataclass(frozen=True)
class LoadState:
    """What an :class:`Expression` sees of the loaded body: its centre of mass ``(x, y)``, angle
    ``phi``, velocities ``(vx, vy)``, ``omega``; and ``angle``, ``speed``: the rotation relative to
    the reaction body of a :class:`Torque` (``phi`` and ``omega`` when there is none)."""

    x: Any
    y: Any
    phi: Any
    vx: Any
    vy: Any
    omega: Any
    angle: Any
    speed: Any


@dataclass(frozen=True, init=False)
class Expression:
    """A load value written as a function ``function(t, s, p)`` of time, the :class:`LoadState`
    ``s`` and the named numbers ``p`` (attributes: ``p.T0``), e.g.::

        Expression(lambda t, s, p: p.T0 * exp(-t / p.tau), T0=10.0, tau=0.2)

    The function is structure, traced with CasADi symbols: write it with the math functions of
    :mod:`daeclear.loads`, not ``math`` or Python ``if`` on the state. The named numbers are
    run-time parameters.
    """

    function: Callable[..., Any]
    parameters: tuple[tuple[str, float], ...]

    def __init__(self, function: Callable[..., Any], /, **parameters: Any) -> None:
        object.__setattr__(self, "function", function)
        object.__setattr__(self, "parameters", tuple(parameters.items()))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.parameters)

    def __call__(self, t: Any, state: LoadState, numbers: dict[str, Any] | None = None) -> Any:
        """The value at ``t`` and ``state``, with ``numbers`` (name -> value or symbol) or the declared ones."""
        values = dict(self.parameters) if numbers is None else numbers
        return self.function(t, state, types.SimpleNamespace(**values))

    def problems(self, where: str) -> list[str]:
        if not callable(self.function):
            return [f"{where}Expression: function={self.function!r}, must be a function (t, s, p) -> value."]
        out = [f"{where}Expression: {name}={value!r}, must be a finite number (named numbers are run-time "
               "parameters)." for name, value in self.parameters if not is_finite_number(value)]
        if out:
            return out
        return self._trace_problems(where)

    def _trace_problems(self, where: str) -> list[str]:
        """Run the function on numbers and on CasADi symbols at one sample point: both must give
        the same number (``math.sin`` of a symbol, for one, gives NaN)."""
        import casadi as ca
        import numpy as np

        label = f"{where}Expression {getattr(self.function, '__qualname__', self.function)!r}"
        sample = (0.0123, 0.1, -0.2, 0.3, 0.4, -0.5, 0.6, 0.25, 0.35)
        try:
            with np.errstate(all="ignore"):
                value = self(np.float64(sample[0]), LoadState(*map(np.float64, sample[1:])))
                number = float(np.asarray(value, dtype=float).reshape(()))
        except Exception as exc:  # a user function: any failure is reported, not raised
            return [f"{label} does not return one number ({type(exc).__name__}: {exc})."]
        sym = ca.SX.sym("x", len(sample) + len(self.parameters))
        try:
            value = ca.SX(self(sym[0], LoadState(*[sym[k] for k in range(1, len(sample))]),
                               {name: sym[len(sample) + k] for k, name in enumerate(self.names)}))
            if value.numel() != 1:
                raise ValueError(f"it has {value.numel()} elements")
            traced = float(ca.Function("trace", [sym], [value])([*sample, *(v for _, v in self.parameters)]))
        except Exception as exc:
            traced = math.nan
            detail = f" ({type(exc).__name__}: {exc})"
        else:
            detail = ""
        same = math.isclose(traced, number, rel_tol=1e-9, abs_tol=1e-12) or (math.isnan(traced) and math.isnan(number))
        if not same:
            return [f"{label} does not run on CasADi symbols as on numbers{detail}; write it with the functions of "
                    "daeclear.loads (sin, cos, exp, fmax, if_else, ...), not math or Python 'if' on the state."]
        return []

    def to_dict(self) -> dict[str, Any]:
        """The function's identity (name and a digest of its source and captured numbers) and the numbers."""
        return {"kind": "Expression", "function": getattr(self.function, "__qualname__", repr(self.function)),
                "digest": _function_digest(self.function), "parameters": dict(self.parameters)}


def _function_digest(function: Any, seen: frozenset[int] = frozenset()) -> str:
    """A digest of what is structure in a function: its code, the numbers it reads from outside, and the
    Python functions it calls (by a global or closure name, recursively)."""
    code = getattr(function, "__code__", None)
    try:
        text = inspect.getsource(function)
    except (OSError, TypeError):
        text = repr(function) if code is None else ""
    captured: list[Any] = []
    if code is not None:  # the bytecode too: two lambdas on one source line differ by it
        consts = [c for c in code.co_consts if not inspect.iscode(c)]  # a code object's repr holds an address
        text += repr((code.co_code, consts, code.co_names))
        globs = getattr(function, "__globals__", {})
        outside = [c.cell_contents for c in getattr(function, "__closure__", None) or () if _has_contents(c)]
        outside += [(name, globs[name]) for name in code.co_names if name in globs]
        seen = seen | {id(function)}
        for item in outside:
            value = item[1] if isinstance(item, tuple) else item
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                captured.append(item)
            elif inspect.isfunction(value) and id(value) not in seen:
                captured.append(_function_digest(value, seen))
    return hashlib.sha256(f"{text}\n{captured!r}".encode()).hexdigest()[:20]


def _has_contents(cell: Any) -> bool:
    try:
        _ = cell.cell_contents
    except ValueError:  # an empty cell (a name not yet bound)
        return False
    return True


Value = float | Table | Expression
