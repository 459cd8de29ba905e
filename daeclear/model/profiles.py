"""Motion profiles of drivers: how a driven joint coordinate moves in time.

A :class:`~daeclear.model.scene.Driver` prescribes ``x0 + speed * f(t)`` (a :class:`Tabulated`
profile: the coordinate itself); :class:`ConstantSpeed`, :class:`Ramp`, :class:`Harmonic` and
:class:`Tabulated` are C2 in time at least, as the index reduction differentiates the constraint
twice (the formulas: docs/user_guide.md). The kind is structure, the numbers run-time parameters
(``<driver>.profile.<field>``). Plain data; :func:`motion` writes a profile as a CasADi expression.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any, ClassVar
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["Profile", "ConstantSpeed", "Ramp", "Harmonic", "Tabulated", "PROFILES", "profile_from_dict", "motion"]


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


@dataclass(frozen=True)
class Profile:
    """Base class of the motion profiles; ``kind`` is the name scene files use."""

    kind: ClassVar[str] = ""
    uses_speed: ClassVar[bool] = True  # False: the profile gives the coordinate itself (no speed, no x0)

    def problems(self, owner: str) -> list[str]:
        """Problems of the profile's numbers, each naming ``owner`` (the driver) and the field."""
        return []

    def parameters(self) -> dict[str, Any]:
        """The profile's numbers as run-time parameters (keys under ``<driver>.profile.``)."""
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out

    def _number(self, out: list[str], owner: str, name: str, unit: str, positive: bool = False) -> None:
        value = getattr(self, name)
        if not _finite(value) or (positive and value <= 0):
            rule = "a finite number > 0" if positive else "a finite number"
            out.append(f"Driver '{owner}': profile {type(self).__name__}: {name}={value!r} {unit}, must be {rule}.")


@dataclass(frozen=True)
class ConstantSpeed(Profile):
    """Constant speed: ``x(t) = speed t`` (what ``profile=None`` means)."""

    kind: ClassVar[str] = "constant"


@dataclass(frozen=True)
class Ramp(Profile):
    """From rest to the driver's ``speed`` in ``time`` seconds (quintic blend, C3 in x), then constant."""

    kind: ClassVar[str] = "ramp"
    time: float = 0.0

    def problems(self, owner: str) -> list[str]:
        out: list[str] = []
        self._number(out, owner, "time", "s", positive=True)
        return out


@dataclass(frozen=True)
class Harmonic(Profile):
    """Speed ``speed (1 + amplitude sin(2 pi frequency t + phase))``, integrated to the coordinate."""

    kind: ClassVar[str] = "harmonic"
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0

    def problems(self, owner: str) -> list[str]:
        out: list[str] = []
        self._number(out, owner, "amplitude", "")
        self._number(out, owner, "frequency", "Hz", positive=True)
        self._number(out, owner, "phase", "rad")
        return out


@dataclass(frozen=True)
class Tabulated(Profile):
    """The coordinate's history (rad, or m on a translational joint) at ``times`` (s, from 0,
    increasing): a natural cubic spline through the points, a straight line after the last one."""

    kind: ClassVar[str] = "tabulated"
    uses_speed: ClassVar[bool] = False
    times: tuple[float, ...] = ()
    values: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "times", _as_tuple(self.times))
        object.__setattr__(self, "values", _as_tuple(self.values))

    def problems(self, owner: str) -> list[str]:
        label = f"Driver '{owner}': profile Tabulated"
        t, x = self.times, self.values
        if not isinstance(t, tuple) or len(t) < 2 or not all(_finite(v) for v in t):
            return [f"{label}: times={t!r} s, must be at least two finite numbers."]
        if t[0] != 0.0 or any(b <= a for a, b in zip(t, t[1:])):
            return [f"{label}: times={list(t)!r} s, must start at 0 and increase strictly."]
        if not isinstance(x, tuple) or len(x) != len(t) or not all(_finite(v) for v in x):
            return [f"{label}: values={x!r}, must be {len(t)} finite numbers (one per time)."]
        return []

    def parameters(self) -> dict[str, Any]:
        t, x = np.asarray(self.times, dtype=float), np.asarray(self.values, dtype=float)
        return {"times": t, "values": x, "curvature": natural_spline_curvature(t, x)}


def _as_tuple(value: Any) -> Any:
    """A sequence of numbers as a tuple of floats where possible (left as given otherwise, for messages)."""
    try:
        return tuple(float(v) if _finite(v) or isinstance(v, (np.floating, np.integer)) else v for v in value)
    except TypeError:
        return value


def natural_spline_curvature(t: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Second derivatives M_k of the natural cubic spline through (t_k, x_k) (M_0 = M_n = 0)."""
    n = t.size
    M = np.zeros(n)
    if n < 3:
        return M
    h = np.diff(t)
    A = np.diag(2.0 * (h[:-1] + h[1:])) + np.diag(h[1:-1], 1) + np.diag(h[1:-1], -1)  # tridiagonal
    rhs = 6.0 * (np.diff(x[1:]) / h[1:] - np.diff(x[:-1]) / h[:-1])
    M[1:-1] = np.linalg.solve(A, rhs)
    return M


#: Scene-file name -> profile class.
PROFILES: dict[str, type[Profile]] = {cls.kind: cls for cls in (ConstantSpeed, Ramp, Harmonic, Tabulated)}


def profile_from_dict(entry: dict[str, Any]) -> Profile:
    """A profile from a scene file's table ``{kind = "ramp", time = 0.01}``; TypeError/ValueError name the key."""
    data = dict(entry)
    kind = data.pop("kind", None)
    if kind not in PROFILES:
        raise ValueError(f"kind={kind!r}, must be one of {', '.join(PROFILES)}")
    cls = PROFILES[kind]
    allowed = [f.name for f in fields(cls)]
    unknown = sorted(set(data) - set(allowed))
    if unknown:
        raise ValueError(f"profile kind {kind!r}: unknown key(s) {', '.join(unknown)}; allowed: "
                         f"{', '.join(allowed) or 'none'}")
    return cls(**data)


def motion(profile: Profile, t: Any, speed: Any, p: Callable[[str], Any]) -> Any:
    """The profile's ``x(t)`` as a CasADi expression: ``speed f(t)`` with x(0) = 0, or the table's
    spline; ``p(name)`` gives the symbol of ``<driver>.profile.<name>``."""
    import casadi as ca

    if isinstance(profile, Ramp):
        T = p("time")
        u = ca.fmin(ca.fmax(t / T, 0.0), 1.0)
        return speed * (T * (u**6 - 3.0 * u**5 + 2.5 * u**4) + ca.fmax(t - T, 0.0))
    if isinstance(profile, Harmonic):
        w = 2.0 * math.pi * p("frequency")
        phase = p("phase")
        return speed * (t + p("amplitude") * (ca.cos(phase) - ca.cos(w * t + phase)) / w)
    if isinstance(profile, Tabulated):
        return _spline(len(profile.times), t, p("times"), p("values"), p("curvature"))
    return speed * t


def _spline(n: int, t: Any, T: Any, X: Any, M: Any) -> Any:
    """Natural cubic spline through n points (second derivatives M), a straight line after the last."""
    import casadi as ca

    h_end = T[n - 1] - T[n - 2]
    slope_end = (X[n - 1] - X[n - 2]) / h_end + h_end * M[n - 2] / 6.0  # M[n-1] = 0
    out = X[n - 1] + slope_end * (t - T[n - 1])
    for k in range(n - 2, -1, -1):
        h = T[k + 1] - T[k]
        a, b = T[k + 1] - t, t - T[k]
        piece = (M[k] * a**3 + M[k + 1] * b**3) / (6.0 * h) + (X[k] / h - M[k] * h / 6.0) * a \
            + (X[k + 1] / h - M[k + 1] * h / 6.0) * b
        out = ca.if_else(t < T[k + 1], piece, out)
    return out
