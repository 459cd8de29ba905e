"""How fast a run's sensitivities grow: a finite-time Lyapunov estimate and the predictability horizon.

In a chaotic run S = dy/dp grows like exp(lambda t): the derivative is real but the run's own errors
(about rtol, relative) grow alike, so past the horizon ln(1/rtol) / lambda neither the state nor its
derivative means anything at that tolerance (docs/sensitivities.md, "Chaos").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["SensitivityHorizon", "STATE_FLOOR", "relative_growth", "finite_time_lyapunov", "predictability_horizon",
           "sensitivity_horizon"]

#: A state whose magnitude stays below this over the run (a multiplier of a free flight, GGL's mu) has no
#: relative size: left out of the growth.
STATE_FLOOR = 1e-12


def relative_growth(S: ArrayLike, state_scale: ArrayLike, parameter_scale: ArrayLike) -> NDArray[np.float64]:
    """The largest relative sensitivity at each time, max over states i and parameters j of
    |S_ij| |p_j| / scale_i: how many times a relative change of a parameter is amplified in the states.

    ``S`` (n_times, n_states, Ns); ``state_scale`` (n_states,) > 0 (e.g. each state's magnitude over the
    run); ``parameter_scale`` (Ns,) (the parameters' values). NaN sensitivities are left out."""
    p = np.asarray(parameter_scale, dtype=float)[None, None, :]
    ratio = np.abs(np.asarray(S, dtype=float)) * p / np.asarray(state_scale, dtype=float)[None, :, None]
    return np.max(np.where(np.isfinite(ratio), ratio, 0.0), axis=(1, 2), initial=0.0)


def finite_time_lyapunov(t: ArrayLike, growth: ArrayLike) -> float:
    """lambda, the slope of the least-squares line through (t, ln growth) over the times where the growth
    is positive and finite (at least two of them, else NaN): the finite-time Lyapunov estimate, 1/s."""
    t, growth = np.asarray(t, dtype=float), np.asarray(growth, dtype=float)
    keep = np.isfinite(growth) & (growth > 0)
    if np.count_nonzero(keep) < 2 or np.ptp(t[keep]) == 0.0:
        return math.nan
    slope, _ = np.polyfit(t[keep], np.log(growth[keep]), 1)
    return float(slope)


def predictability_horizon(lyapunov: float, rtol: float, t0: float = 0.0) -> float:
    """The time after ``t0`` at which errors of relative size ``rtol`` have grown to 1 at the rate
    ``lyapunov``: t0 + ln(1/rtol) / lambda; infinite when nothing grows (lambda <= 0 or NaN)."""
    if not (lyapunov > 0.0) or not (0.0 < rtol < 1.0):
        return math.inf
    return t0 + math.log(1.0 / rtol) / lyapunov


@dataclass(frozen=True)
class SensitivityHorizon:
    """How a run's sensitivities grow (``result.sensitivity_horizon``): the growth G(t) at the output times
    ``t`` (:func:`relative_growth`), the finite-time Lyapunov estimate ``lyapunov`` (1/s, NaN when G never
    grows), the predictability ``horizon`` (s; inf when nothing grows exponentially) at the run's ``rtol``.
    ``predictable``: the horizon lies past the run's last time."""

    t: NDArray[np.float64]
    growth: NDArray[np.float64]
    lyapunov: float
    horizon: float
    rtol: float

    @property
    def predictable(self) -> bool:
        return bool(self.t.size == 0 or self.horizon > self.t[-1])


def sensitivity_horizon(t: ArrayLike, y: ArrayLike, S: ArrayLike, parameter_scale: ArrayLike,
                        rtol: float) -> SensitivityHorizon:
    """The growth of ``S`` (n_times, n_states, Ns) relative to each state's largest magnitude over the rows
    ``y`` (states below :data:`STATE_FLOOR` left out) and to the parameters' magnitudes (0 counts as 1), its
    rate and the horizon from the first time at ``rtol``."""
    times, states = np.asarray(t, dtype=float), np.abs(np.asarray(y, dtype=float))
    scale = states.max(axis=0, initial=0.0) if times.size else np.zeros(states.shape[1])
    scale = np.where(scale > STATE_FLOOR, scale, np.inf)  # left out: |S| / inf = 0
    p = np.abs(np.asarray(parameter_scale, dtype=float))
    growth = relative_growth(S, scale, np.where(p > 0, p, 1.0))
    lam = finite_time_lyapunov(times, growth)
    return SensitivityHorizon(times, growth, lam, predictability_horizon(lam, rtol, float(times[0]) if times.size
                                                                         else 0.0), float(rtol))
