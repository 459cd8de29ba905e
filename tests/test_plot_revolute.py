"""Figure functions of section 4.4 (journal orbit, phase portrait, step sizes, panels) draw the right data.

Built on small hand-made Results, so the expected line data are known exactly; one test draws a
real (short) clearance-joint run.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.plot.figures import (  # noqa: E402
    plot_cases,
    plot_channel,
    plot_journal_orbit,
    plot_phase_portrait,
    plot_revolute_response,
    plot_step_sizes,
)
from daeclear.plot.joint_figures import _contact_intervals  # noqa: E402
from daeclear.results.result import ContactEvent, Result  # noqa: E402

C = 0.5e-3  # m, radial clearance of the synthetic joint


@pytest.fixture(autouse=True)
def no_show(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(plt, "show", lambda *a, **k: pytest.fail("figure functions must not call plt.show"))
    yield
    plt.close("all")


def _event(t: float, kind: str, pair: str = "clearance") -> ContactEvent:
    return ContactEvent(t=t, pair=pair, kind=kind, approach_speed=1.0 if kind == "onset" else -1.0, y=np.zeros(1))


def make_result(events: tuple[tuple[float, str], ...] = ((0.3, "onset"), (0.5, "separation"), (0.7, "onset")),
                first_modes: dict[str, str] | None = None, clearance: float | None = C,
                steps: bool = True) -> Result:
    """A Result with a journal circling at radius 1.01 c, a sine velocity, events and steps."""
    t = np.linspace(0.0, 1.0, 201)
    phase = 2 * np.pi * t
    channels = {
        "clearance.ex": 1.01 * C * np.cos(phase),
        "clearance.ey": 1.01 * C * np.sin(phase),
        "slider.vx": 28.0 * np.sin(phase),
        "slider.ax": -19000.0 * np.cos(phase),
        "drive.moment": 138.0 * np.sin(2 * phase),
    }
    units = {"clearance.ex": "m", "clearance.ey": "m", "slider.vx": "m/s", "slider.ax": "m/s^2",
             "drive.moment": "N m"}
    step_kw = {}
    if steps:
        step_t = np.concatenate([[0.0], np.linspace(0.01, 1.0, 100)])
        step_h = np.concatenate([[0.0], np.full(100, 0.01)])
        step_h[31:51] = 1e-4  # smaller steps in the contact (0.3, 0.5)
        step_kw = {"step_t": step_t, "step_h": step_h, "step_order": np.ones(101, dtype=int)}
    parameters = {} if clearance is None else {"scene": {"elements": {"clearance": {"clearance": clearance}}}}
    return Result(t=t, y=np.zeros((t.size, 1)), yp=np.zeros((t.size, 1)), state_names=["q"], channels=channels,
                  units=units, events=[_event(a, k) for a, k in events],
                  segments=[(0.0, 1.0, first_modes or {"clearance": "free"})], parameters=parameters,
                  scene_name="synthetic", **step_kw)


# --------------------------------------------------------------------------- journal orbit


def test_journal_orbit_draws_eccentricity_in_micrometres_and_the_clearance_circle():
    r = make_result()
    ax = plot_journal_orbit(r)
    orbit, circle = ax.get_lines()
    np.testing.assert_allclose(orbit.get_xdata(), r["clearance.ex"] * 1e6)
    np.testing.assert_allclose(orbit.get_ydata(), r["clearance.ey"] * 1e6)
    assert orbit.get_marker() == "."  # one marker per output point
    np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), C * 1e6)
    assert circle.get_linestyle() == "--"
    assert "µm" in ax.get_xlabel() and "µm" in ax.get_ylabel()
    assert ax.get_aspect() == 1.0


def test_journal_orbit_of_a_lubricated_joint_draws_the_film_threshold():
    """A lubricated joint (law "hydrodynamic"): the eccentricity-ratio-1 circle |e| = c and the film
    threshold's |e| = c - h_threshold, inside which the film carries."""
    r = make_result()
    r.parameters["scene"]["elements"]["clearance"]["law"] = {"name": "hydrodynamic", "roughness": 1e-6,
                                                          "film_parameter": 2.0}
    ax = plot_journal_orbit(r)
    orbit, circle, threshold = ax.get_lines()
    np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), C * 1e6)
    np.testing.assert_allclose(np.hypot(threshold.get_xdata(), threshold.get_ydata()), (C - 2e-6) * 1e6)
    assert threshold.get_linestyle() == ":" and ax.get_legend() is not None


def test_journal_orbit_options_axes_unit_markers_and_clearance():
    fig, ax = plt.subplots()
    r = make_result(clearance=None)
    assert plot_journal_orbit(r, ax=ax, markers=False, unit="mm", clearance=0.2e-3, color="k") is ax
    orbit, circle = ax.get_lines()
    np.testing.assert_allclose(orbit.get_xdata(), r["clearance.ex"] * 1e3)
    assert orbit.get_marker() in ("None", "", None)
    np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), 0.2)
    # no clearance in the parameters and none given: no circle
    assert len(plot_journal_orbit(r).get_lines()) == 1
    with pytest.raises(ValueError, match="unit"):
        plot_journal_orbit(r, unit="inch")


# --------------------------------------------------------------------------- phase portrait


def test_phase_portrait_draws_acceleration_against_velocity_with_reference():
    r = make_result()
    ref = make_result()
    ax = plot_phase_portrait(r, reference=ref)
    reference, curve = ax.get_lines()
    np.testing.assert_allclose(curve.get_xdata(), r["slider.vx"])
    np.testing.assert_allclose(curve.get_ydata(), r["slider.ax"])
    assert reference.get_linestyle() == "--" and reference.get_label() == "ideal joint"
    assert ax.get_xlabel() == "slider.vx (m/s)" and ax.get_ylabel() == "slider.ax (m/s^2)"


def test_phase_portrait_other_channels_without_reference():
    r = make_result()
    ax = plot_phase_portrait(r, x="drive.moment", y="slider.vx")
    (curve,) = ax.get_lines()
    np.testing.assert_allclose(curve.get_xdata(), r["drive.moment"])
    np.testing.assert_allclose(curve.get_ydata(), r["slider.vx"])


# --------------------------------------------------------------------------- step sizes


def test_step_sizes_log_scale_without_the_initial_placeholder_and_contact_shaded():
    r = make_result()
    ax = plot_step_sizes(r)
    (line,) = ax.get_lines()
    np.testing.assert_allclose(line.get_xdata(), r.step_t[1:])
    np.testing.assert_allclose(line.get_ydata(), r.step_h[1:])
    assert ax.get_yscale() == "log"
    # contact (0.3, 0.5) and, ending in contact, (0.7, 1.0)
    assert len(ax.patches) == 2
    assert len(plot_step_sizes(r, shade=False).patches) == 0


def test_step_sizes_need_recorded_steps():
    with pytest.raises(ValueError, match="no recorded steps"):
        plot_step_sizes(make_result(steps=False))


def test_contact_intervals_from_events_and_segments():
    assert _contact_intervals(make_result()) == [(0.3, 0.5), (0.7, 1.0)]
    # a window that starts in contact: its first event is a separation
    starts_in = make_result(events=((0.2, "separation"), (0.4, "onset"), (0.6, "separation")))
    assert _contact_intervals(starts_in) == [(0.0, 0.2), (0.4, 0.6)]
    # no events at all: the first segment's mode decides
    assert _contact_intervals(make_result(events=(), first_modes={"clearance": "contact"})) == [(0.0, 1.0)]
    assert _contact_intervals(make_result(events=())) == []
    # another pair's events are ignored when a pair is named
    assert _contact_intervals(make_result(), pair="other") == []


# --------------------------------------------------------------------------- panels


def test_plot_cases_one_titled_panel_per_result_and_hides_the_rest():
    from functools import partial

    results = {"c = 0.5 mm": make_result(), "c = 0.2 mm": make_result(clearance=0.2e-3),
               "c = 0.1 mm": make_result(clearance=0.1e-3)}
    fig = plot_cases(results, plot_journal_orbit, ncols=2, markers=False)
    axes = fig.axes
    assert len(axes) == 4 and not axes[3].get_visible()
    assert [ax.get_title() for ax in axes[:3]] == ["(a) c = 0.5 mm", "(b) c = 0.2 mm", "(c) c = 0.1 mm"]
    radius = np.hypot(*(axes[1].get_lines()[1].get_data()))
    np.testing.assert_allclose(radius, 200.0)  # each panel its own clearance
    ref = make_result()
    fig2 = plot_cases({"a": make_result()}, partial(plot_channel, channel="drive.moment"), reference=ref)
    ref_line, line = fig2.axes[0].get_lines()
    np.testing.assert_allclose(line.get_ydata(), ref["drive.moment"])
    with pytest.raises(ValueError, match="no results"):
        plot_cases({}, plot_journal_orbit)


def test_revolute_response_four_panels_and_orbit_from_its_own_result():
    r, ideal, steps = make_result(), make_result(), make_result()
    fig = plot_revolute_response(r, reference=ideal, orbit=steps)
    a, b, c, d = fig.axes
    for ax, name in zip((a, b, c), ("slider.vx", "slider.ax", "drive.moment")):
        ref_line, line = ax.get_lines()
        assert ref_line.get_linestyle() == "--"
        np.testing.assert_allclose(line.get_ydata(), r[name])
    np.testing.assert_allclose(d.get_lines()[0].get_xdata(), steps["clearance.ex"] * 1e6)


def test_figure_functions_on_a_simulated_clearance_joint():
    """A real 3 ms run: one orbit point per IDA step, step sizes from the run, contact from its events."""
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.003)
    ax = plot_journal_orbit(result)
    orbit = ax.get_lines()[0]
    assert orbit.get_xdata().size == result.n_times == result.step_t.size
    np.testing.assert_allclose(np.hypot(*ax.get_lines()[1].get_data()), 500.0)
    ax = plot_step_sizes(result)
    assert ax.get_lines()[0].get_xdata().size == np.count_nonzero(result.step_h > 0)
    n_onsets = len(result.events.of("clearance", "onset"))
    assert n_onsets >= 1 and len(ax.patches) == n_onsets
