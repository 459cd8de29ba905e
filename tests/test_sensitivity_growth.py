"""The growth of sensitivities (daeclear/results/sensitivity_growth.py, issue 43 item 4) on closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from daeclear.results.sensitivity_growth import finite_time_lyapunov, predictability_horizon, relative_growth


def test_exponential_growth_gives_its_rate_and_horizon() -> None:
    """y' = lambda y: S = dy/dy0 = exp(lambda t), relative to y0 by y0: the growth exp(lambda t) exactly,
    lambda recovered, the horizon ln(1/rtol)/lambda."""
    lam, y0 = 40.0, 0.3
    t = np.linspace(0.0, 0.5, 51)
    S = np.exp(lam * t)[:, None, None] * np.ones((1, 1, 1))
    growth = relative_growth(S, [y0], [y0])
    assert growth == pytest.approx(np.exp(lam * t), rel=1e-14)
    assert finite_time_lyapunov(t, growth) == pytest.approx(lam, rel=1e-12)
    assert predictability_horizon(lam, 1e-8) == pytest.approx(math.log(1e8) / lam, rel=1e-15)
    assert predictability_horizon(lam, 1e-8, t0=1.0) == pytest.approx(1.0 + math.log(1e8) / lam, rel=1e-15)


def test_growth_takes_the_largest_relative_sensitivity_and_skips_nan() -> None:
    S = np.array([[[1.0, np.nan], [2.0, 3.0]]])  # one time, 2 states, 2 parameters
    assert relative_growth(S, [1.0, 4.0], [2.0, 0.5])[0] == pytest.approx(max(1 * 2 / 1, 2 * 2 / 4, 3 * 0.5 / 4))
    assert relative_growth(np.full((1, 1, 1), np.nan), [1.0], [1.0])[0] == 0.0


def test_algebraic_growth_has_a_horizon_far_beyond_the_run() -> None:
    """A phase drift (S ~ t, a periodic run's sensitivity to its frequency): the fitted rate is of order
    1/T and the horizon at rtol 1e-8 lies well past T."""
    t = np.linspace(0.1, 1.0, 91)
    lam = finite_time_lyapunov(t, t)
    assert 0 < lam < 3.0
    assert predictability_horizon(lam, 1e-8) > 5.0


def test_nothing_grows_nothing_is_lost() -> None:
    assert predictability_horizon(-1.0, 1e-8) == math.inf
    assert predictability_horizon(math.nan, 1e-8) == math.inf
    assert math.isnan(finite_time_lyapunov([0.0, 1.0], [0.0, 0.0]))


def test_horizon_figure_draws_the_growth_its_fit_and_the_horizon() -> None:
    """Agg: G = 3 exp(50 t) is drawn as given, its fit passes through it (lambda = 50), the level 1/rtol and the
    horizon ln(1/rtol)/50 from t0 = 0.1 s; an algebraic growth (S ~ t, periodic run) has no horizon line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from daeclear.plot import plot_sensitivity_horizon

    t = np.linspace(0.1, 0.6, 41)
    growth = 3.0 * np.exp(50.0 * t)
    ax = plot_sensitivity_horizon(t, growth, 1e-8)
    measured, fit = ax.lines[0], ax.lines[1]
    assert np.array_equal(measured.get_ydata(), growth)
    assert np.asarray(fit.get_ydata()) == pytest.approx(growth, rel=1e-9)
    horizon = [line for line in ax.lines if line.get_color() == "#d62728"]
    assert len(horizon) == 1 and horizon[0].get_xdata()[0] == pytest.approx(0.1 + math.log(1e8) / 50.0, rel=1e-12)
    assert any(np.all(np.asarray(line.get_ydata()) == 1e8) for line in ax.lines)
    assert "lambda = 50 1/s" in ax.get_title()
    ax = plot_sensitivity_horizon(t, 1.0 + t - t[0], 1e-8)  # grows, but slowly: a horizon far past the run
    assert [line for line in ax.lines if line.get_color() == "#d62728"][0].get_xdata()[0] > 10 * t[-1]
    ax = plot_sensitivity_horizon(t, np.ones_like(t), 1e-8)
    assert "no horizon" in ax.get_title() and not [line for line in ax.lines if line.get_color() == "#d62728"]
    with pytest.raises(Exception, match=r"plot_sensitivity_horizon: rtol=2.0, must be a finite number > 0"):
        plot_sensitivity_horizon(t, growth, 2.0)
    plt.close("all")
