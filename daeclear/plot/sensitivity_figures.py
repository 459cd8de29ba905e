"""The sensitivity horizon figure: how fast a run's sensitivities grow and past when they mean nothing
(docs/sensitivities.md, "Chaos and the predictability horizon")."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.options import fail, number
from ..results.sensitivity_growth import SensitivityHorizon, finite_time_lyapunov, predictability_horizon
from . import style

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from matplotlib.axes import Axes

__all__ = ["plot_sensitivities", "plot_sensitivity_horizon", "save_sensitivity_figure"]


def plot_sensitivity_horizon(t: ArrayLike | SensitivityHorizon | Any, growth: ArrayLike | None = None,
                             rtol: float | None = None, *, ax: Axes | None = None,
                             label: str = "largest relative sensitivity") -> Axes:
    """The growth G(t) of a run's sensitivities (log scale; ``relative_growth`` of
    :mod:`daeclear.results.sensitivity_growth`) with its least-squares exponential (the finite-time Lyapunov
    estimate lambda, dashed), the level 1/rtol (errors of the run's ``rtol`` grown to 1) and the predictability
    horizon t0 + ln(1/rtol)/lambda (a vertical line, when it is finite). Returns the Axes (a new figure when
    ``ax`` is None). ``t`` may be a run's Result with sensitivities or its ``sensitivity_horizon`` alone
    (``growth`` and ``rtol`` then theirs)."""
    given: Any = t.sensitivity_horizon if hasattr(t, "sensitivity_horizon") else t  # a Result: its horizon
    if isinstance(given, SensitivityHorizon):
        if growth is not None or rtol is not None:
            fail("plot_sensitivity_horizon", "growth", growth, "None with a Result or a SensitivityHorizon (theirs)")
        t, growth, rtol = given.t, given.growth, given.rtol
    if growth is None or rtol is None:
        fail("plot_sensitivity_horizon", "rtol" if growth is not None else "growth", rtol if growth is not None
             else growth, "given with the times t (or pass a Result with sensitivities)")
    times, values = np.asarray(t, dtype=float), np.asarray(growth, dtype=float)
    if times.ndim != 1 or values.shape != times.shape or times.size < 2:
        fail("plot_sensitivity_horizon", "growth", f"shape {values.shape}", f"one value per time ({times.size} times)")
    tol = number(rtol, where="plot_sensitivity_horizon", field="rtol", low=0.0, high=1.0)
    ax = style.new_axes(ax)
    keep = np.isfinite(values) & (values > 0)
    ax.semilogy(times[keep], values[keep], lw=1.0, label=label)
    lam = finite_time_lyapunov(times, values)
    horizon = predictability_horizon(lam, tol, float(times[0]))
    if math.isfinite(lam):
        intercept = float(np.mean(np.log(values[keep]) - lam * times[keep]))  # the same least-squares line
        ax.semilogy(times, np.exp(intercept + lam * times), "--", lw=0.8, label=f"fit: lambda = {lam:.3g} 1/s")
    ax.axhline(1.0 / tol, color="0.4", lw=0.8, ls=":", label=f"1/rtol = {1.0 / tol:.3g}")
    if math.isfinite(horizon):
        ax.axvline(horizon, color="#d62728", lw=1.0, label=f"horizon {horizon:.4g} s")
        title = f"sensitivity growth: lambda = {lam:.3g} 1/s\nhorizon {horizon:.4g} s at rtol {tol:g}"
    else:
        title = f"sensitivity growth: not exponential\nno horizon at rtol {tol:g}"
    ax.set(xlabel="t (s)", ylabel="max |S| |p| / scale")
    style.set_title(ax, title)
    ax.legend(fontsize="small")
    ax.grid(True, which="both", lw=0.3)
    return ax


def plot_sensitivities(result: Any, parameter: str, *, ax: Axes | None = None, top: int = 6) -> Axes:
    """The ``top`` states most sensitive to ``parameter`` over the run: |dy_i/dp| |p| / max|y_i| against t (log
    scale; how many times a relative change of p shows in the state), a run's Result with sensitivities."""
    if result.sensitivities is None:
        fail("plot_sensitivities", "result", "a run without sensitivities",
             "a result of simulate(..., sensitivities=[...]) (or daeclear run --sensitivity NAME)")
    s = result.sensitivities
    if parameter not in s.names:
        fail("plot_sensitivities", "parameter", parameter, f"one of the run's ({', '.join(s.names)})")
    j = s.names.index(parameter)
    value = 1.0 if s.values is None or s.values[j] == 0 else abs(float(s.values[j]))
    scale = np.abs(np.asarray(result.y, dtype=float)).max(axis=0, initial=0.0)
    shown = np.abs(s.states[:, :, j]) * value / np.where(scale > 1e-12, scale, np.inf)  # as the horizon's growth
    peak = np.nanmax(np.where(np.isfinite(shown), shown, 0.0), axis=0, initial=0.0)
    ax = style.new_axes(ax)
    for i in [int(k) for k in np.argsort(peak)[::-1][:top] if peak[k] > 0]:
        keep = np.isfinite(shown[:, i]) & (shown[:, i] > 0)
        ax.semilogy(result.t[keep], shown[keep, i], lw=0.9, label=s.state_names[i])
    ax.set(xlabel="t (s)", ylabel="|dy/dp| |p| / max|y|")
    style.set_title(ax, f"sensitivity to {parameter} (p = {value:.4g})")
    if ax.lines:
        ax.legend(fontsize="small")
    ax.grid(True, which="both", lw=0.3)
    return ax


def save_sensitivity_figure(result: Any, path: Any) -> Any:
    """A run's sensitivities over time, one panel per parameter (:func:`plot_sensitivities`), and their growth
    with the predictability horizon (:func:`plot_sensitivity_horizon`), written to ``path``."""
    import matplotlib.pyplot as plt

    from .run_panels import save_figure

    names = () if result.sensitivities is None else result.sensitivities.names
    fig, axes = plt.subplots(len(names) + 1, 1, figsize=(8.0, 3.0 * (len(names) + 1)), squeeze=False)
    for ax, name in zip(axes[:-1, 0], names):
        plot_sensitivities(result, name, ax=ax)
    plot_sensitivity_horizon(result, ax=axes[-1, 0])
    fig.tight_layout()
    return save_figure(fig, path)
