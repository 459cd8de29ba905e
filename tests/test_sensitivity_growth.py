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


def _exponential_result(lam: float, y0: float, rtol: float):
    """A Result of y' = lambda y from y0 with S = dy/dy0 = exp(lambda t) (the parameter y0 itself)."""
    import daeclear as dc
    from daeclear.results.sensitivities import Sensitivities

    t = np.linspace(0.1, 0.5, 41)
    y = y0 * np.exp(lam * t)[:, None]
    sens = Sensitivities(("x.start",), ("x",), (), np.exp(lam * t)[:, None, None], np.zeros((t.size, 0, 1)),
                         values=np.array([y0]))
    return dc.Result(t=t, y=y, yp=lam * y, state_names=["x"], channels={}, units={},
                     parameters={"simulate": {"rtol": rtol}}, sensitivities=sens)


def test_result_sensitivity_horizon_of_a_known_exponential(tmp_path) -> None:
    """y = y0 exp(lambda t), S = exp(lambda t): G = S y0 / max y = exp(lambda (t - T)), lambda recovered, the
    horizon t0 + ln(1/rtol)/lambda; the same from the saved file (the parameters' values kept); the figure
    drawn from the Result puts its line there."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import daeclear as dc
    from daeclear.plot import plot_sensitivity_horizon

    lam, rtol = 30.0, 1e-8
    result = _exponential_result(lam, 0.3, rtol)
    for r in (result, dc.load(result.save(tmp_path / "exp.h5"))):
        h = r.sensitivity_horizon
        assert h.growth == pytest.approx(np.exp(lam * (h.t - 0.5)), rel=1e-12, abs=0.0)
        assert h.lyapunov == pytest.approx(lam, rel=1e-10) and h.rtol == rtol
        assert h.horizon == pytest.approx(0.1 + math.log(1 / rtol) / lam, rel=1e-12) and h.predictable
    ax = plot_sensitivity_horizon(result)
    line = [x for x in ax.lines if x.get_color() == "#d62728"]
    assert len(line) == 1 and line[0].get_xdata()[0] == pytest.approx(0.1 + math.log(1 / rtol) / lam, rel=1e-10)
    plt.close("all")
    short = _exponential_result(lam, 0.3, 1e-3)  # ln(1e3)/30 = 0.23 s from 0.1 s: inside the run
    assert not short.sensitivity_horizon.predictable
    with pytest.raises(KeyError, match="sensitivity_horizon: this run has no sensitivities"):
        _ = dc.Result(t=[0.0], y=[[0.0]], yp=[[0.0]], state_names=["x"], channels={}, units={}).sensitivity_horizon


def test_an_inverted_rod_grows_as_its_linearisation() -> None:
    """A uniform rod (m, L) pinned at its end to the ground, released upright with a tiny spin w0: its angle
    leaves at the rate lambda = sqrt(m g a / (I + m a^2)) (a = L/2), phi - pi/2 = (w0/lambda) sinh(lambda t).
    The sensitivity to w0 relative to each state's largest magnitude over T = 10/lambda: cosh(lambda t)/
    cosh(lambda T) for omega, vx, x, the pin's horizontal force, and 2 sinh(2 lambda t)/sinh(2 lambda T) for vy
    (second order in w0), times alpha = 1/(1 + a^2), the unweighted least-norm start moving vx against the pin
    when w0 alone moves. The run's G is the larger of the two, its fitted rate that of the closed form's."""
    import warnings

    import daeclear as dc

    m, length, g, w0 = 1.0, 1.0, 9.81, 1e-6
    a, inertia = length / 2, m * length ** 2 / 12
    scene = dc.Scene("inverted", gravity=(0.0, -g))
    rod = scene.add(dc.Body("rod", mass=m, inertia=inertia, position=(0.0, a), angle=math.pi / 2,
                            velocity=(-a * w0, 0.0), angular_velocity=w0))
    scene.add(dc.Revolute("A", scene.ground, rod, at=(0.0, 0.0)))
    lam = math.sqrt(m * g * a / (inertia + m * a * a))
    T = 10 / lam
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        r = dc.simulate(scene, T, rtol=1e-10, save=dc.SaveAt(times=np.linspace(0, T, 201)),
                        sensitivities=["rod.angular_velocity"])
    assert r["rod.phi"][-1] - math.pi / 2 == pytest.approx(w0 / lam * math.sinh(lam * T), rel=1e-4)
    alpha = 1 / (1 + a * a)
    h, t = r.sensitivity_horizon, r.t
    want = alpha * np.maximum(np.cosh(lam * t) / np.cosh(lam * T), 2 * np.sinh(2 * lam * t) / np.sinh(2 * lam * T))
    assert h.growth == pytest.approx(want, rel=1e-4, abs=0.0)
    fitted = np.polyfit(t, np.log(want), 1)[0]
    assert h.lyapunov == pytest.approx(fitted, rel=1e-5) and h.lyapunov == pytest.approx(lam, rel=0.02)
    assert h.horizon == pytest.approx(math.log(1e10) / fitted, rel=1e-5) and h.predictable  # 6.05 s > T = 2.6 s
