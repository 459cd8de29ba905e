"""The jump of forward sensitivities at an event: pure functions on arrays (docs/sensitivities.md, "Jumps").

At a root g(t, y, p) = 0 that switches the residual (Galan, Feehery and Barton 1999; Hiskens and Pai
2000), with y' before the switch (-) and after it (+) at the same (t*, y):

* the event time moves: dt*/dp = -(g_y S- + g_p) / (g_y y'- + g_t)  (:func:`event_time_sensitivity`);
* the states continuous across the event jump in sensitivity: S+ = S- + (y'- - y'+) dt*/dp
  (:func:`state_jump`);
* a value latched at the event (the approach speed) has the sensitivity of its total derivative at
  t*: (d delta'/dy) S- + d delta'/dp + (d delta'/dt along y'-) dt*/dp  (:func:`latched_sensitivity`);
* the algebraic sensitivities are re-solved in the new mode (``assembly.sensitivity``, consistent).

Where the rate g_y y'- + g_t is near zero (a grazing contact, :func:`is_grazing`: its terms cancel, or the
gap's curvature moves it by more than itself within the gap's tolerance) dt*/dp has no meaning: NaN and a
:class:`~daeclear.core.errors.PhysicsWarning` naming the event, never a number.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import PhysicsWarning

__all__ = ["GRAZING_ERROR", "ROUNDOFF", "grazing_limit", "is_grazing", "event_time_sensitivity", "state_jump",
           "latched_sensitivity", "same_event_times"]

#: A root's rate is near zero (grazing) when its uncertainty is more than this fraction of it.
GRAZING_ERROR = 1e-2
#: The rate's uncertainty beside the run's rtol: round-off of its terms, in units of their magnitude.
ROUNDOFF = 100.0 * float(np.finfo(float).eps)


def grazing_limit(scale: float, rtol: float) -> float:
    """The smallest rate of a root whose terms do not cancel: ``(rtol + ROUNDOFF) * scale / GRAZING_ERROR``.

    ``scale`` is the magnitude of the terms the rate sums, |g_t| + sum_i |g_y,i y'_i| (the speed of the
    gap's own parts): they are known to about ``rtol`` relative, so a rate below this limit (an approach
    nearly tangential: a journal sliding round its bearing) is not known to ``GRAZING_ERROR`` of itself."""
    return (float(rtol) + ROUNDOFF) * float(scale) / GRAZING_ERROR


def is_grazing(rate: float, scale: float, rtol: float, curvature: float = 0.0, gap_error: float = 0.0) -> bool:
    """Whether a root crossed with ``rate`` is grazing (a NaN rate counts), by either test:

    * cancellation: |rate| <= :func:`grazing_limit` (``scale``, ``rtol``);
    * tangency: rate^2 <= |g''| gap_error / GRAZING_ERROR. The gap is known to ``gap_error`` (the states'
      tolerances through g_y); an error that size moves the root by gap_error / rate and so the rate by
      g'' gap_error / rate (``curvature`` g'' = d^2 g/dt^2): near an apex (a journal that barely reaches its
      wall) the crossing and its derivative may not exist for a change of the size the run resolves."""
    r = abs(float(rate))
    return not (r > grazing_limit(scale, rtol) and r * r > abs(float(curvature)) * float(gap_error) / GRAZING_ERROR)


def event_time_sensitivity(g_p: ArrayLike, rate: float, scale: float, *, rtol: float, event: str,
                           curvature: float = 0.0, gap_error: float = 0.0) -> NDArray[np.float64]:
    """dt*/dp = -g_p / rate for each parameter (``g_p`` = g_y S- + g_p, shape (Ns,)); ``rate`` = g_y y'- + g_t.

    A grazing root (:func:`is_grazing` with ``scale``, ``curvature``, ``gap_error``) gives NaN for every
    parameter and a PhysicsWarning naming ``event`` (e.g. "'C' onset at t=0.0123 s"): no derivative."""
    g_p = np.asarray(g_p, dtype=float)
    if is_grazing(rate, scale, rtol, curvature, gap_error):
        warnings.warn(f"sensitivities: {event} is grazing (its gap's rate {float(rate):.3g} is within "
                      f"{GRAZING_ERROR:g} of its own uncertainty at rtol={rtol:g}: a nearly tangential or barely "
                      "reached contact); the event time and the sensitivities it moves are NaN from here on.",
                      PhysicsWarning, stacklevel=2)
        return np.full(g_p.shape, np.nan)
    return -g_p / float(rate)


def state_jump(S: ArrayLike, yp_minus: ArrayLike, yp_plus: ArrayLike, dt_dp: ArrayLike,
               continuous: ArrayLike) -> NDArray[np.float64]:
    """S+ = S- + (y'- - y'+) dt*/dp on the ``continuous`` states (mask (n,)), the others as given.

    ``S`` (n, Ns), ``yp_minus``/``yp_plus`` (n,), ``dt_dp`` (Ns,). A state whose derivative does not jump
    keeps its sensitivity exactly (a NaN dt*/dp spreads only to the states it moves)."""
    S_plus = np.array(S, dtype=float)
    jump = np.asarray(yp_minus, dtype=float) - np.asarray(yp_plus, dtype=float)
    rows = np.asarray(continuous, dtype=bool) & (jump != 0.0)
    S_plus[rows] += np.outer(jump[rows], np.asarray(dt_dp, dtype=float))
    return S_plus


def latched_sensitivity(rate_p: ArrayLike, rate_rate: float, dt_dp: ArrayLike, floored: bool) -> NDArray[np.float64]:
    """The sensitivity of a value latched at an event, v(t*(p), y(t*(p), p), p):
    ``rate_p`` = v_y S- + v_p (Ns,), ``rate_rate`` = v_y y'- + v_t, plus ``rate_rate * dt_dp``. A value
    ``floored`` to a constant (an approach speed below the law's minimum) has none: zeros."""
    rate_p = np.asarray(rate_p, dtype=float)
    if floored:
        return np.zeros(rate_p.shape)
    return rate_p + float(rate_rate) * np.asarray(dt_dp, dtype=float)


def same_event_times(dt_dps: list[NDArray[np.float64]], rtol: float) -> bool:
    """Whether roots found at one instant move together (equal dt*/dp to ``sqrt(rtol)`` relative): if not, an
    infinitesimal change of a parameter changes their order, and no derivative crosses the instant."""
    first = dt_dps[0]
    tol = np.sqrt(rtol) * np.maximum(np.abs(first), 1e-300)
    return all(np.all(np.abs(d - first) <= tol) for d in dt_dps[1:])
