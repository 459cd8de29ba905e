"""One validation rule per run option, shared by every entry (Python API, command line, scene files).

Each function returns the option's normalised value or raises :class:`SceneError` shaped
``<where>: <field>=<value> [unit], must be <rule>.`` (``where``: the entry, ``field``: the option as
the user wrote it there). Nothing is silently replaced: a zero or NaN is an error, never the default.
"""

from __future__ import annotations

import difflib
import math
from typing import Any, NoReturn, TypeGuard
from collections.abc import Iterable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import defaults, methods
from .errors import SceneError

METHODS: tuple[str, ...] = methods.METHODS
FORMULATIONS: tuple[str, ...] = ("index1", "ggl")
DEFAULT_FORMULATION = defaults.FORMULATION
CHAPTER_FORMULATION = methods.CHAPTER_FORMULATION
BACKENDS: tuple[str, ...] = ("auto", "c", "python")
ON_FAILURE: tuple[str, ...] = ("raise", "return")
LINEAR_SOLVERS: tuple[str, ...] = ("auto", "reduced", "dense", "sparse", "superlu")
#: How a run starts: "ideal" (the chapter's: clearance joints centred) or "declared" (the bodies' own
#: state, corrected only for the ideal joints).
STARTS: tuple[str, ...] = ("ideal", "declared")
RTOL_RANGE: tuple[float, float] = (1e-14, 1e-2)


def fail(where: str, field: str, value: Any, rule: str, unit: str = "", *, shown: str | None = None) -> NoReturn:
    """Raise the one error shape of a bad option; ``shown`` replaces ``repr(value)`` (arrays)."""
    if isinstance(value, (np.floating, np.integer)):
        value = value.item()
    shown = shown if shown is not None else repr(value)
    shown = f"{shown} {unit}" if unit else shown
    raise SceneError(f"{where}: {field}={shown}, must be {rule}.")


def close_matches(name: str, candidates: Iterable[str], n: int = 5) -> list[str]:
    """Up to `n` candidates similar to `name`, best first, ties alphabetical (the hint of a message)."""
    matcher = difflib.SequenceMatcher(b=name)
    scored = []
    for c in candidates:
        matcher.set_seq1(c)
        ratio = matcher.ratio()
        if ratio >= 0.6:
            scored.append((-ratio, c))
    return [c for _, c in sorted(scored)[:n]]


def is_real(value: Any) -> TypeGuard[float]:
    """A real number (numpy scalars included), not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def number(value: Any, *, where: str, field: str, unit: str = "", low: float | None = None,
           low_open: bool = True, high: float | None = None) -> float:
    """A finite real number in (low, high] (or [low, high] when ``low_open`` is False)."""
    ok = is_real(value) and math.isfinite(float(value))
    if ok and low is not None:
        ok = float(value) > low if low_open else float(value) >= low
    if ok and high is not None:
        ok = float(value) <= high
    if not ok:
        parts = [f"{'>' if low_open else '>='} {low:g}"] if low is not None else []
        if high is not None:
            parts.append(f"<= {high:g}")
        fail(where, field, value, "a finite number" + (" " + " and ".join(parts) if parts else ""), unit)
    return float(value)


def integer(value: Any, *, where: str, field: str, low: int) -> int:
    """An integer >= low (a float with an integer value, e.g. 3.0 from a scene file, is not one)."""
    if not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_)) or int(value) < low:
        fail(where, field, value, f"an integer >= {low}")
    return int(value)


def flag(value: Any, *, where: str = "simulate", field: str) -> bool:
    """A switch: True or False (a string such as "no" would otherwise count as True)."""
    if not isinstance(value, (bool, np.bool_)):
        fail(where, field, value, "True or False")
    return bool(value)


def choice(value: Any, allowed: Sequence[str], *, where: str, field: str) -> str:
    """One of ``allowed`` (case-insensitive), returned in lower case."""
    text = value.lower() if isinstance(value, str) else None
    if text not in allowed:
        fail(where, field, value, f"one of {', '.join(allowed)} (case-insensitive)")
    return text  # type: ignore[return-value]


def t_end(value: Any, *, where: str = "simulate", field: str = "t_end") -> float:
    """End time of a run: a finite number > 0, s."""
    return number(value, where=where, field=field, unit="s", low=0.0)


def t0(value: Any, end: float, *, where: str = "simulate", field: str = "t0") -> float:
    """Start time of a run: a finite number >= 0 and < t_end, s."""
    ok = is_real(value) and math.isfinite(float(value)) and 0.0 <= float(value) < end
    if not ok:
        fail(where, field, value, f"a finite number >= 0 and < t_end={end:g} s", "s")
    return float(value)


def state(value: Any, size: int | None, *, where: str = "simulate", field: str = "y0") -> NDArray[np.float64]:
    """A full state vector: ``size`` finite numbers (None: any length, checked once the model is known)."""
    rule = (f"{size} finite numbers (a row of result.y of the same model: model.n_states = {size})" if size is not None
            else "finite numbers (a row of result.y of the same model)")
    try:
        values = np.array(value, dtype=float)
    except (TypeError, ValueError):
        fail(where, field, value, rule)
    shown = f"array of shape {values.shape}" if values.ndim != 1 or values.size > 6 else repr(values.tolist())
    if values.ndim != 1 or values.size == 0 or (size is not None and values.size != size):
        fail(where, field, value, rule + f", not shape {values.shape}", shown=shown)
    bad = ~np.isfinite(values)
    if bad.any():
        index = int(np.argmax(bad))
        fail(where, field, value, rule + f" ({float(values[index])!r} at index {index})", shown=shown)
    return values


def rtol(value: Any, *, where: str = "simulate", field: str = "rtol") -> float:
    """Relative tolerance: a finite number in [1e-14, 1e-2]."""
    lo, hi = RTOL_RANGE
    ok = is_real(value) and math.isfinite(float(value)) and lo <= float(value) <= hi
    if not ok:
        fail(where, field, value, f"a finite number in [{lo:g}, {hi:g}]")
    return float(value)


#: The quantities of the positions and velocities, and the ``atol`` keys that name them.
ATOL_QUANTITIES: tuple[str, ...] = ("position", "angle", "velocity", "angular_velocity")
#: ``atol`` keys for groups: "q" (positions and angles), "v" (velocities and angular velocities).
ATOL_GROUPS: dict[str, tuple[str, ...]] = {"q": ("position", "angle"), "v": ("velocity", "angular_velocity")}


def atol(value: Any, *, where: str = "simulate", field: str = "atol"
         ) -> float | dict[str, float] | NDArray[np.float64] | None:
    """Absolute tolerance: None, a number > 0, a mapping by quantity (ATOL_GROUPS, ATOL_QUANTITIES) or
    finite values > 0 (per state)."""
    if value is None:
        return None
    if is_real(value):
        return number(value, where=where, field=field, low=0.0)
    if isinstance(value, Mapping):
        return atol_by_quantity(value, where=where, field=field)
    rule = "a finite number > 0, a mapping by quantity ({'q': ..., 'v': ...}) or a list of numbers > 0"
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        fail(where, field, value, rule)
    if values.ndim != 1:  # a table is not flattened: which order was meant?
        fail(where, field, value, "one-dimensional (2 n_q values or one per state): " + rule,
             shown=f"array of shape {values.shape}")
    if values.size == 0 or not np.all(np.isfinite(values)) or np.any(values <= 0):
        fail(where, field, value, rule)
    return values.copy()


def atol_by_quantity(value: Mapping[Any, Any], *, where: str, field: str) -> dict[str, float]:
    """An ``atol`` mapping as {quantity: value}: each group key expanded, each quantity given once."""
    out: dict[str, float] = {}
    allowed = ", ".join(repr(k) for k in (*ATOL_GROUPS, *ATOL_QUANTITIES))
    for key, item in value.items():
        if key not in ATOL_GROUPS and key not in ATOL_QUANTITIES:
            fail(where, f"{field} key", key, f"one of {allowed} (multipliers are always out of the error test)")
        given = number(item, where=where, field=f"{field}[{key!r}]", low=0.0)
        for quantity in ATOL_GROUPS.get(key, (key,)):
            if quantity in out:
                fail(where, field, dict(value), f"one value per quantity ({quantity!r} is given twice)")
            out[quantity] = given
    return out


def max_step(value: Any, *, where: str = "simulate", field: str = "max_step") -> float:
    """Largest step: a finite number >= 0, s (0: unbounded)."""
    return number(value, where=where, field=field, unit="s", low=0.0, low_open=False)


def max_steps(value: Any, *, where: str = "simulate", field: str = "max_steps") -> int:
    """Cap on the number of steps: an integer >= 1."""
    return integer(value, where=where, field=field, low=1)


def step(value: Any, *, where: str = "simulate", field: str = "step") -> float:
    """Step size of a fixed-step method: a finite number > 0, s."""
    return number(value, where=where, field=field, unit="s", low=0.0)


def step_within(value: float | None, t0: float, end: float, *, where: str = "simulate", field: str = "step") -> None:
    """A fixed step no longer than the run (one stride would step over every contact)."""
    if value is not None and value > end - t0:
        fail(where, field, value, f"at most the run's length t_end - t0 = {end - t0:g} s (t_end={end:g} s)", "s")


def t_eval(value: ArrayLike | None, end: float | None, *, where: str = "simulate",
           field: str = "t_eval", start: float = 0.0) -> NDArray[np.float64] | None:
    """Output times: None, or finite, strictly increasing values in [start, end] (``end`` None: any)."""
    if value is None:
        return None
    low = '0' if start == 0 else f't0={start:g}'
    rule = (f"finite, strictly increasing values in [{low}, t_end={end:g}]" if end is not None
            else f"finite, strictly increasing values >= {low}")
    top = math.inf if end is None else end
    try:
        times = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        fail(where, field, value, rule)
    if times.ndim > 1:  # a table of times is not flattened: which order was meant?
        fail(where, field, value, "a 1-D sequence of times, " + rule, shown=f"array of shape {times.shape}")
    times = times.reshape(-1)
    if times.size == 0:
        fail(where, field, value, "at least one time: " + rule)
    # the common case in one pass (a NaN or inf fails a comparison); anything else is looked at for the message
    if start <= times[0] and times[-1] <= top and times[-1] < math.inf and bool((times[1:] > times[:-1]).all()):
        return times
    bad = ~np.isfinite(times)
    if bad.any():
        index = int(np.argmax(bad))
        fail(where, field, value, rule + f" ({float(times[index])!r} at index {index})", shown=_show(times))
    if np.any(np.diff(times) <= 0) or times[0] < start or times[-1] > top:  # (inf: caught above as not finite)
        fail(where, field, value, rule, shown=_show(times))
    return times


def _show(times: NDArray[np.float64]) -> str:
    """A short text of an array of times for a message."""
    if times.size <= 6:
        return "[" + ", ".join(repr(float(x)) for x in times) + "]"
    return f"array of {times.size} times from {float(times[0])!r} to {float(times[-1])!r}"


def t_eval_step(value: Any, end: float, *, where: str, field: str = "t_eval_step") -> float:
    """Spacing of uniform output times: a finite number in (0, t_end], s."""
    return number(value, where=where, field=field, unit="s", low=0.0, high=end)


MAX_OUTPUT_POINTS = defaults.MAX_OUTPUT_POINTS


def max_output_points(value: Any, *, where: str = "simulate", field: str = "max_output_points") -> int | None:
    """The cap on a run's output points: an integer >= 1, or None (no cap)."""
    return None if value is None else integer(value, where=where, field=field, low=1)


def uniform_times(spacing: float, end: float, start: float = 0.0) -> NDArray[np.float64]:
    """Output times from ``start`` to ``end`` (both included) in ``floor((end - start) / spacing)`` intervals."""
    return np.linspace(start, end, int(math.floor((end - start) / spacing)) + 1)


class OutputTimes:
    """The reported times of a run: given values, or the grid of :func:`uniform_times` made window by
    window (``window(i, j)`` equals ``uniform_times(spacing, end)[i:j]``)."""

    def __init__(self, values: NDArray[np.float64] | None = None, *, spacing: float = 0.0, end: float = 0.0,
                 start: float = 0.0) -> None:
        self._values = values
        self._intervals = 0 if values is not None else int(math.floor((end - start) / spacing))
        self._start, self._end = start, end
        self.size: int = values.size if values is not None else self._intervals + 1

    def window(self, start: int, stop: int) -> NDArray[np.float64]:
        """The times of indices [start, stop) (fewer at the end)."""
        if self._values is not None:
            return self._values[start:stop]
        stop = min(stop, self.size)
        span = self._end - self._start
        out = np.arange(start, max(start, stop), dtype=float) * (span / self._intervals) + self._start  # as np.linspace
        if stop == self.size and out.size:
            out[-1] = self._end
        return out

    def values(self) -> NDArray[np.float64]:
        """Every time (the whole array)."""
        return self.window(0, self.size)


def method(value: Any, *, where: str = "simulate", field: str = "method") -> str:
    """Integrator name (case-insensitive)."""
    return choice(value, METHODS, where=where, field=field)


def formulation(value: Any, *, where: str = "simulate", field: str = "formulation") -> str:
    """DAE formulation (case-insensitive)."""
    return choice(value, FORMULATIONS, where=where, field=field)


def default_formulation(method_name: Any) -> str:
    """The formulation used when none is given: IDA's :data:`DEFAULT_FORMULATION`, the chapter's for
    the other methods, a solver class's own ``formulation``."""
    if isinstance(method_name, type):
        return str(getattr(method_name, "formulation", DEFAULT_FORMULATION))
    return methods.by_key(str(method_name)).formulation


def backend(value: Any, *, where: str = "simulate", field: str = "backend") -> str:
    """Where the model is evaluated (case-insensitive)."""
    return choice(value, BACKENDS, where=where, field=field)


def on_failure(value: Any, *, where: str = "simulate", field: str = "on_failure") -> str:
    """What a failed run does (case-insensitive)."""
    return choice(value, ON_FAILURE, where=where, field=field)


def linear_solver(value: Any, *, where: str = "simulate", field: str = "linear_solver") -> str:
    """LU of IDA's Newton iteration (case-insensitive)."""
    return choice(value, LINEAR_SOLVERS, where=where, field=field)


def start(value: Any, *, where: str = "simulate", field: str = "start") -> str:
    """How a run starts (case-insensitive), see :data:`STARTS`."""
    return choice(value, STARTS, where=where, field=field)


def repeats(value: Any, *, where: str = "work_precision", field: str = "repeats") -> int:
    """Timed repeats per run: an integer >= 0 (0: one untimed-warm-up-free run)."""
    return integer(value, where=where, field=field, low=0)


def n_eval(value: Any, *, where: str = "work_precision", field: str = "n_eval") -> int:
    """Number of comparison times: an integer >= 2."""
    return integer(value, where=where, field=field, low=2)


def rtols(values: Any, *, where: str = "work_precision", field: str = "rtols") -> list[float]:
    """A non-empty list of relative tolerances, each by :func:`rtol`."""
    items = _list(values, where=where, field=field)
    return [rtol(v, where=where, field=f"{field}[{i}]") for i, v in enumerate(items)]


def steps(values: Any, end: float, *, where: str = "work_precision", field: str = "steps") -> list[float]:
    """A non-empty list of fixed steps, each a finite number in (0, t_end], s."""
    items = _list(values, where=where, field=field)
    return [number(v, where=where, field=f"{field}[{i}]", unit="s", low=0.0, high=end) for i, v in enumerate(items)]


def names(values: Any, *, where: str, field: str) -> list[str]:
    """A non-empty list of non-empty names (channels, methods)."""
    items = _list(values, where=where, field=field)
    for i, v in enumerate(items):
        if not isinstance(v, str) or not v.strip():
            fail(where, f"{field}[{i}]", v, "a non-empty name")
    return [v.strip() for v in items]


def _list(values: Any, *, where: str, field: str) -> list[Any]:
    if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple, np.ndarray)) or len(values) == 0:
        fail(where, field, values, "a non-empty list")
    return list(values)


def revolutions(value: Any, *, where: str = "sweep", field: str = "revolutions") -> int:
    """Revolutions analysed: an integer >= 1."""
    return integer(value, where=where, field=field, low=1)


def transient(value: Any, *, where: str = "sweep", field: str = "transient") -> int:
    """Revolutions discarded first: an integer >= 0."""
    return integer(value, where=where, field=field, low=0)


def per_revolution(value: Any, *, where: str = "sweep", field: str = "per_revolution") -> int:
    """Output samples per revolution: an integer >= 1."""
    return integer(value, where=where, field=field, low=1)


def workers(value: Any, *, where: str = "sweep", field: str = "max_workers") -> int | None:
    """Worker processes: None (the CPU count) or an integer >= 1."""
    return None if value is None else integer(value, where=where, field=field, low=1)
