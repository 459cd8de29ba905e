"""Single-degree-of-freedom impact on a normal contact law (the Fig. 4.26 experiment):
``m delta_ddot = -F_N(delta, delta_dot, v)`` from ``delta = 0``, ``delta_dot = v``, until ``delta``
is 0 again; scipy's DOP853, independent of the DAE machinery.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from ..core.errors import SceneError
from ._checks import check_number
from .base import NormalLaw

__all__ = ["ImpactResult", "simulate_impact"]


@dataclass(frozen=True)
class ImpactResult:
    """Outcome of :func:`simulate_impact` (SI units; time 0 at first contact): uniform samples ``t``,
    ``penetration``, ``rate``, ``force`` over the contact; ``entry_speed`` and ``exit_speed`` (> 0);
    ``max_penetration`` at ``time_of_max_penetration`` (rate 0); ``peak_force`` (refined between
    samples); ``duration`` of the contact."""

    t: NDArray[np.float64]
    penetration: NDArray[np.float64]
    rate: NDArray[np.float64]
    force: NDArray[np.float64]
    law: NormalLaw
    mass: float
    entry_speed: float
    exit_speed: float
    max_penetration: float
    time_of_max_penetration: float
    peak_force: float
    duration: float
    stats: dict[str, Any] = field(default_factory=dict)

    @property
    def restitution(self) -> float:
        """Effective coefficient of restitution, ``exit_speed / entry_speed``."""
        return self.exit_speed / self.entry_speed

    @property
    def energy_lost(self) -> float:
        """Kinetic energy dissipated in the impact, ``m (v_in**2 - v_out**2) / 2`` (J)."""
        return 0.5 * self.mass * (self.entry_speed**2 - self.exit_speed**2)

    def __repr__(self) -> str:
        return (f"ImpactResult(law={self.law.name!r}, entry_speed={self.entry_speed:g}, "
                f"exit_speed={self.exit_speed:.6g}, restitution={self.restitution:.6f}, "
                f"max_penetration={self.max_penetration:.4e}, peak_force={self.peak_force:.6g}, "
                f"duration={self.duration:.4e})")


def _penetration_scale(law: NormalLaw, mass: float, speed: float) -> float:
    """Penetration where the force times delta equals m v^2 (a scale only)."""
    energy = mass * speed**2
    lo, hi = 1e-15, 1e-15
    while law.force(hi, 0.0, speed) * hi < energy:
        lo, hi = hi, hi * 10.0
        if hi > 1e6:
            raise SceneError(f"simulate_impact: {type(law).__name__} never stops a {mass:g} kg mass at "
                             f"{speed:g} m/s.")
    for _ in range(60):  # bisection in log space, 1e-3 is plenty for a scale
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if law.force(mid, 0.0, speed) * mid < energy else (lo, mid)
    return hi


def simulate_impact(law: NormalLaw, *, mass: float, speed: float, rtol: float = 1e-12,
                    n_points: int = 2001) -> ImpactResult:
    """Simulate one impact of a ``mass`` (kg) at ``speed`` (m/s, also the law's approach speed) on a
    resolved ``law``; ``rtol`` of DOP853 (absolute: ``rtol`` times the penetration and speed scales),
    ``n_points`` uniform samples. Raises SceneError for a bad argument or no separation.

    Example
    -------
    >>> from daeclear.contact import LankaraniNikravesh
    >>> law = LankaraniNikravesh(restitution=0.9, stiffness=6.61e10)
    >>> round(simulate_impact(law, mass=1.0, speed=1.0).restitution, 3)
    0.913
    """
    mass = check_number("simulate_impact", "mass", mass, low=0.0, unit="kg")
    speed = check_number("simulate_impact", "speed", speed, low=0.0, unit="m/s")
    if not law.is_resolved:
        raise SceneError(f"simulate_impact: {type(law).__name__} is not resolved; give its stiffness or call "
                         "resolve(...) first.")
    if n_points < 2:
        raise SceneError(f"simulate_impact: n_points={n_points}, must be >= 2.")
    delta_scale = _penetration_scale(law, mass, speed)
    t_scale = delta_scale / speed

    def rhs(_t: float, y: NDArray[np.float64]) -> list[float]:
        return [y[1], -law.force(y[0], y[1], speed) / mass]

    def separation(_t: float, y: NDArray[np.float64]) -> float:
        return y[0]

    separation.terminal = True  # type: ignore[attr-defined]
    separation.direction = -1  # type: ignore[attr-defined]

    def turning(_t: float, y: NDArray[np.float64]) -> float:
        return y[1]

    turning.direction = -1  # type: ignore[attr-defined]

    sol = solve_ivp(rhs, (0.0, 1e4 * t_scale), [0.0, speed], method="DOP853", rtol=rtol,
                    atol=[rtol * delta_scale, rtol * speed], events=[separation, turning],
                    dense_output=True, max_step=t_scale / 4.0)
    if sol.status != 1 or not len(sol.t_events[0]):
        raise SceneError(f"simulate_impact: no separation within {1e4 * t_scale:.3g} s ({sol.message}).")
    duration = float(sol.t_events[0][0])
    exit_speed = -float(sol.y_events[0][0][1])
    t_turn = float(sol.t_events[1][0])
    max_penetration = float(sol.y_events[1][0][0])

    t = np.linspace(0.0, duration, n_points)
    y = sol.sol(t)
    y[:, -1] = sol.y_events[0][0]
    y[0, -1] = 0.0
    force = np.asarray(law.force(y[0], y[1], speed), dtype=float)

    def negative_force(s: float) -> float:
        state = sol.sol(s)
        return -law.force(state[0], state[1], speed)

    i = int(np.argmax(force))
    lo, hi = t[max(i - 1, 0)], t[min(i + 1, n_points - 1)]
    refined = minimize_scalar(negative_force, bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-10 * duration})
    at_turn = law.force(max_penetration, 0.0, speed)
    peak_force = max(float(force[i]), -float(refined.fun), at_turn)
    return ImpactResult(t=t, penetration=y[0], rate=y[1], force=force, law=law, mass=mass,
                        entry_speed=speed, exit_speed=exit_speed, max_penetration=max_penetration,
                        time_of_max_penetration=t_turn, peak_force=peak_force, duration=duration,
                        stats={"nfev": int(sol.nfev), "n_steps": int(len(sol.t))})
