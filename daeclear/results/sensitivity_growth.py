"""How fast a run's sensitivities grow: a finite-time Lyapunov estimate and the predictability horizon.

In a chaotic run S = dy/dp grows like exp(lambda t): the derivative is real but the run's own errors
(about rtol, relative) grow alike, so past the horizon ln(1/rtol) / lambda neither the state nor its
derivative means anything at that tolerance (docs/sensitivities.md, "Chaos").
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["relative_growth", "finite_time_lyapunov", "predictability_horizon"]


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
