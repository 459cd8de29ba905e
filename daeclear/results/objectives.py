"""Scalars of a run's response and their gradients from forward sensitivities (docs/sensitivities.md, "Gradients").

An objective names what a designer looks at: :class:`Final` (a channel at the end), :class:`Integral` (over a
window), :class:`Peak` (its largest value in a window) and :class:`EventTime` (when the k-th onset or
separation of a pair happens). :func:`evaluate` computes its value and its gradient with respect to the run's
parameters from a :class:`Trajectory`: output rows with the states' and channels' values and sensitivities,
and the events with their times' sensitivities. Any run that gives these can be evaluated: a result of
``simulate(..., sensitivities=...)`` through :class:`daeclear.results.sensitivities.RunTrajectory`.

A trajectory holds an event at t* as two rows at t*, before and after its switch: a channel that jumps there
(a Kelvin-Voigt force at onset) moves an integral by (before - after) dt*/dp, and a peak at the jump moves
with it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ..core.errors import SceneError
from ..core.options import close_matches, fail, flag

__all__ = ["Final", "Integral", "Peak", "EventTime", "Objective", "Gradient", "Trajectory", "evaluate",
           "EVENT_KINDS"]

#: The kinds of event an :class:`EventTime` can name.
EVENT_KINDS: tuple[str, ...] = ("onset", "separation")


class Trajectory(Protocol):
    """What :func:`evaluate` reads of a run with sensitivities: the parameters' ``names``, the rows' times
    ``t`` (non-decreasing; an event at t* two rows at t*, before and after), the ``events``, and per state
    or channel its ``values`` (n_times,) and ``sensitivity`` (n_times, Ns). Each event has ``t``, ``pair``,
    ``kind`` and ``dt_dp`` (Ns,), its time's sensitivity."""

    @property
    def names(self) -> tuple[str, ...]: ...
    @property
    def t(self) -> NDArray[np.float64]: ...
    @property
    def events(self) -> Sequence[Any]: ...

    def values(self, name: str) -> NDArray[np.float64]: ...
    def sensitivity(self, name: str, parameter: str | None = None) -> NDArray[np.float64]: ...


def _channel(where: str, value: Any) -> str:
    if not isinstance(value, str) or not value:
        fail(where, "channel", value, "a state's or channel's name (a non-empty string), e.g. 'crank.moment'")
    return value


def _window(where: str, value: Any) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        t0, t1 = (float(x) for x in value)
    except (TypeError, ValueError):
        fail(where, "window", value, "None or two times (t0, t1) in seconds with t0 < t1")
    if not (math.isfinite(t0) and math.isfinite(t1) and t0 < t1):
        fail(where, "window", value, "None or two finite times (t0, t1) in seconds with t0 < t1")
    return t0, t1


@dataclass(frozen=True)
class Final:
    """The channel's value at the run's end."""

    channel: str

    def __post_init__(self) -> None:
        _channel("Final", self.channel)


@dataclass(frozen=True)
class Integral:
    """The channel's integral over ``window`` (t0, t1) in seconds (None: the whole run)."""

    channel: str
    window: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        _channel("Integral", self.channel)
        object.__setattr__(self, "window", _window("Integral", self.window))


@dataclass(frozen=True)
class Peak:
    """The channel's largest value in ``window`` (its largest magnitude with ``absolute``)."""

    channel: str
    window: tuple[float, float] | None = None
    absolute: bool = False

    def __post_init__(self) -> None:
        _channel("Peak", self.channel)
        object.__setattr__(self, "window", _window("Peak", self.window))
        flag(self.absolute, where="Peak", field="absolute")


@dataclass(frozen=True)
class EventTime:
    """The time of the ``index``-th (0 the first, -1 the last) event of ``kind`` of ``pair``."""

    pair: str
    kind: str = "onset"
    index: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.pair, str) or not self.pair:
            fail("EventTime", "pair", self.pair, "a contact pair's name (a non-empty string), e.g. 'clearance'")
        if self.kind not in EVENT_KINDS:
            fail("EventTime", "kind", self.kind, f"one of {', '.join(map(repr, EVENT_KINDS))}")
        if not isinstance(self.index, (int, np.integer)) or isinstance(self.index, (bool, np.bool_)):
            fail("EventTime", "index", self.index, "an integer (0 the first event, -1 the last)")


Objective = Final | Integral | Peak | EventTime


@dataclass(frozen=True)
class Gradient:
    """An objective's ``value`` and its ``gradient`` {parameter name: d value / d parameter}."""

    objective: Objective
    value: float
    gradient: dict[str, float]
    method: str = "sensitivities"


def evaluate(objective: Objective, trajectory: Trajectory) -> Gradient:
    """The value of ``objective`` on ``trajectory`` and its gradient w.r.t. ``trajectory.names``."""
    t = np.asarray(trajectory.t, dtype=float)
    if t.size == 0:
        raise SceneError("evaluate: the trajectory has no rows (the run computed nothing).")
    if isinstance(objective, EventTime):
        value, grad = _event_time(objective, trajectory)
    else:
        f, S = _read(objective.channel, trajectory)
        if isinstance(objective, Final):
            value, grad = float(f[-1]), S[-1]
        elif isinstance(objective, Integral):
            window = _window_of(objective.window, t, "Integral")
            found = _quadrature(objective.channel, window, trajectory)
            value, grad = found if found is not None else _integral(t, f, S, window, trajectory, objective.channel)
        elif isinstance(objective, Peak):
            value, grad = _peak(t, f, S, _window_of(objective.window, t, "Peak"), objective.absolute, trajectory)
        else:
            fail("evaluate", "objective", objective, "a Final, Integral, Peak or EventTime")
    return Gradient(objective, float(value), {name: float(g) for name, g in zip(trajectory.names, grad)})


def _read(name: str, trajectory: Trajectory) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    try:
        f = np.asarray(trajectory.values(name), dtype=float)
        S = np.asarray(trajectory.sensitivity(name), dtype=float).reshape(f.size, -1)
    except KeyError:
        known = [*getattr(trajectory, "state_names", ()), *getattr(trajectory, "channel_names", ())]
        close = close_matches(name, known)
        hint = f" Close matches: {', '.join(map(repr, close))}." if close else ""
        raise SceneError(f"objective: channel={name!r}, must be a state or channel of the run.{hint}") from None
    return f, S


def _window_of(window: tuple[float, float] | None, t: NDArray[np.float64], where: str) -> tuple[float, float]:
    if window is None:
        return float(t[0]), float(t[-1])
    if window[0] < t[0] or window[1] > t[-1]:
        fail(where, "window", window, f"inside the run's times [{t[0]:g}, {t[-1]:g}] s")
    return window


def _event_time(objective: EventTime, trajectory: Trajectory) -> tuple[float, NDArray[np.float64]]:
    chosen = [e for e in trajectory.events if e.pair == objective.pair and e.kind == objective.kind]
    if not -len(chosen) <= objective.index < len(chosen):
        pairs = sorted({e.pair for e in trajectory.events})
        fail("EventTime", "index", objective.index,
             f"within the run's {len(chosen)} {objective.kind} event(s) of {objective.pair!r} (pairs with events: "
             f"{', '.join(map(repr, pairs)) or 'none'})")
    event = chosen[objective.index]
    return float(event.t), np.asarray(event.dt_dp, dtype=float)


def _event_rows(t: NDArray[np.float64], at: float) -> tuple[int, int]:
    """The rows before and after the switch of an event at ``at`` (its two rows), or ValueError."""
    rows = np.flatnonzero(t == at)
    if rows.size < 2:
        raise SceneError(f"objective: the trajectory has no rows before and after the event at t={at:.9g} s "
                         "(a run with sensitivities gives two rows at each event).")
    return int(rows[0]), int(rows[-1])


def _nodes(t: NDArray[np.float64], i: int, lo: int, hi: int, count: int) -> list[int]:
    """Up to ``count`` rows around rows i, i + 1 within rows lo..hi, strictly increasing in time (one smooth
    piece: never across an event's two rows), centred as the rows allow."""
    nodes = [i, i + 1]
    while len(nodes) < count:
        grown = False
        for k in (nodes[0] - 1, nodes[-1] + 1):
            if len(nodes) < count and lo <= k <= hi and (t[k] < t[nodes[0]] if k < nodes[0] else t[k] > t[nodes[-1]]):
                nodes = sorted([*nodes, k])
                grown = True
        if not grown:
            break
    return nodes


def _basis(x: NDArray[np.float64]) -> list[np.polynomial.Polynomial]:
    """The Lagrange basis polynomials of the nodes ``x``."""
    out = []
    for k in range(x.size):
        others = np.delete(x, k)
        out.append(np.polynomial.Polynomial.fromroots(others) / np.prod(x[k] - others))
    return out


def _quadrature(name: str, window: tuple[float, float], trajectory: Trajectory
                ) -> tuple[float, NDArray[np.float64]] | None:
    """The integral over ``window`` from the run's quadrature state (Q(t1) - Q(t0) and its sensitivity), when
    the run integrated the channel and has rows at both ends; else None."""
    quadrature = getattr(trajectory, "quadrature", None)
    found = quadrature(name) if quadrature is not None else None
    if found is None:
        return None
    tq, Q, dQ = (np.asarray(a, dtype=float) for a in found)
    ends = [np.flatnonzero(tq == end) for end in window]
    if any(rows.size == 0 for rows in ends):
        return None
    i0, i1 = int(ends[0][-1]), int(ends[1][0])
    return float(Q[i1] - Q[i0]), dQ[i1] - dQ[i0]


def _integral(t: NDArray[np.float64], f: NDArray[np.float64], S: NDArray[np.float64], window: tuple[float, float],
              trajectory: Trajectory, name: str) -> tuple[float, NDArray[np.float64]]:
    """Each interval between rows within ``window`` integrated by the cubic through four rows about it (of the
    same smooth piece; fewer where the piece is shorter): error O(dt^4); with each event's jump
    (before - after) dt*/dp inside the window."""
    t0, t1 = window
    value, grad = 0.0, np.zeros(S.shape[1])
    for i in range(t.size - 1):
        a, b = max(t[i], t0), min(t[i + 1], t1)
        if b <= a:
            continue
        nodes = _nodes(t, i, 0, t.size - 1, 4)
        x = (t[nodes] - t[i]) / (t[i + 1] - t[i])  # scaled: a well-conditioned basis
        scale = t[i + 1] - t[i]
        weights = np.array([(q.integ()((b - t[i]) / scale) - q.integ()((a - t[i]) / scale)) * scale
                            for q in _basis(x)])
        value += float(weights @ f[nodes])
        grad += weights @ S[nodes]
    for at in sorted({float(e.t) for e in trajectory.events if t0 < e.t < t1}):
        before, after = _event_rows(t, at)
        dt = next(np.asarray(e.dt_dp, dtype=float) for e in trajectory.events if e.t == at)
        if f[before] != f[after]:
            grad = grad + (f[before] - f[after]) * dt
    return value, grad


def _peak(t: NDArray[np.float64], f: NDArray[np.float64], S: NDArray[np.float64], window: tuple[float, float],
          absolute: bool, trajectory: Trajectory) -> tuple[float, NDArray[np.float64]]:
    """The largest row in ``window``, refined by the quartic through it and two rows either side (of the same
    smooth piece): the root of its rate between them, where dF_max/dp = dF/dp (dF/dt = 0), S interpolated by
    the same quartic. A peak at a window's end has the end's sensitivity; at an event (a jump) it moves with
    the event: + F' dt*/dp, F' by the one-sided difference beside it (first order)."""
    sign = np.sign(f) if absolute else np.ones_like(f)
    g = sign * f
    inside = np.flatnonzero((t >= window[0]) & (t <= window[1]))
    i = int(inside[np.argmax(g[inside])])
    if inside[0] < i < inside[-1] and t[i - 1] < t[i] < t[i + 1]:
        nodes = _nodes(t, i, int(inside[0]), int(inside[-1]), 5)
        nodes = _nodes(t, i - 1, int(inside[0]), int(inside[-1]), 5) if len(nodes) < 5 else nodes
        scale = t[i + 1] - t[i]
        x = (t[nodes] - t[i]) / scale
        basis = _basis(x)
        curve = sum((q * g[k] for q, k in zip(basis, nodes)), np.polynomial.Polynomial([0.0]))
        roots = curve.deriv().roots()
        real = [float(r.real) for r in roots if abs(r.imag) < 1e-9 and x[0] <= r.real <= x[-1]]
        if real:
            s = max(real, key=curve)
            if curve(s) >= g[i]:
                weights = np.array([q(s) for q in basis])
                return float(curve(s)), sign[i] * (weights @ S[nodes])
    grad = sign[i] * S[i]
    on_event = [e for e in trajectory.events if e.t == t[i]]
    if on_event:
        before, after = _event_rows(t, float(t[i]))
        other = after + 1 if i == after else before - 1
        if 0 <= other < t.size and t[other] != t[i]:
            rate = (g[other] - g[i]) / (t[other] - t[i])
            grad = grad + rate * np.asarray(on_event[0].dt_dp, dtype=float)
    return float(g[i]), grad
