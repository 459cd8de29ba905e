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


# --------------------------------------------------------------------------- the run figure (issue 45)


@pytest.fixture(scope="module")
def two_revolutions() -> dc.Result:
    """The main job's run (`daeclear run slider_crank --joint revolute`) on a 10 us grid."""
    return dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.024, save=dc.SaveAt(every=1e-5, steps=False))


def test_run_figure_marks_the_penetration_on_square_axes_that_fit_the_orbit(two_revolutions):
    """The orbit drew the journal up to 80 um outside the clearance circle unexplained, on an axis twice
    too wide: now square, centred, fitting the orbit; the circle and the deepest penetration labelled."""
    from daeclear.plot import plot_run

    r = two_revolutions
    fig = plot_run(r)
    orbit = next(ax for ax in fig.axes if ax.get_title() == "clearance: journal orbit")
    e = np.hypot(r["clearance.ex"], r["clearance.ey"])
    reach = 1e6 * max(C, float(e.max()))
    assert orbit.get_aspect() == 1.0
    assert orbit.get_xlim() == pytest.approx((-1.12 * reach, 1.12 * reach))
    assert orbit.get_ylim() == pytest.approx((-1.12 * reach, 1.12 * reach))
    k = int(np.argmax(e))  # the deepest penetration, |e| - c, found here from the orbit alone
    np.testing.assert_allclose(orbit.collections[0].get_offsets()[0],
                               1e6 * np.array([r["clearance.ex"][k], r["clearance.ey"][k]]))
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert texts[0].startswith("|e| = c = 500 µm") and "penetration δ = |e| − c" in texts[0]
    assert f"δ = {(e[k] - C) * 1e6:.3g} µm" in texts[1] and f"t = {r.t[k] * 1e3:.3g} ms" in texts[1]
    assert 60 < (e[k] - C) * 1e6 < 100  # the chapter's hardest impacts: ~80 um (docs/user_guide.md, 1.3)
    plt.close(fig)


def test_run_figure_fits_the_acceleration_panel_to_the_steady_range(two_revolutions):
    """The first impact of the journal started centred (-3.3e5 m/s^2) flattened the acceleration panel:
    now it fits the values after the first 5 % of the run, the spike annotated with its value and time."""
    from daeclear.plot import plot_run

    r = two_revolutions
    fig = plot_run(r)
    panel = next(ax for ax in fig.axes if ax.get_ylabel().startswith("slider.ax"))
    a, t = r["slider.ax"], r.t
    late = t >= 0.05 * t[-1]
    low, high = panel.get_ylim()
    assert low <= a[late].min() and high >= a[late].max()  # every steady value is on the scale
    assert a.min() < low  # the start spike is not
    k = int(np.argmin(a))
    assert t[k] < 0.05 * t[-1]
    (note,) = panel.texts
    assert f"start: {a[k]:.3g} m/s^2 at t = {t[k] * 1e3:.3g} ms, off scale" == note.get_text()
    # the other panels keep their whole range (the first impact's force stays on the scale)
    force = next(ax for ax in fig.axes if ax.get_ylabel().startswith("clearance.normal_force"))
    assert force.get_ylim()[1] >= r["clearance.normal_force"].max() and not force.texts
    plt.close(fig)


def test_plot_channel_steady_range_leaves_a_steady_signal_alone():
    t = np.linspace(0.0, 1.0, 1001)
    r = make_result()
    values = np.sin(2 * np.pi * 5 * t)
    r2 = Result(t=t, y=np.zeros((t.size, 1)), yp=np.zeros((t.size, 1)), state_names=["q"],
                channels={"x.ax": values}, units={"x.ax": "m/s^2"}, scene_name="synthetic")
    ax = plot_channel(r2, "x.ax", steady_from=0.05)
    assert not ax.texts and ax.get_ylim()[0] <= -1.0 and ax.get_ylim()[1] >= 1.0
    spiked = values.copy()
    spiked[10] = -9.0
    r3 = Result(t=t, y=np.zeros((t.size, 1)), yp=np.zeros((t.size, 1)), state_names=["q"],
                channels={"x.ax": spiked}, units={"x.ax": "m/s^2"}, scene_name="synthetic")
    ax = plot_channel(r3, "x.ax", steady_from=0.05)
    assert ax.get_ylim() == pytest.approx((-1.16, 1.16), abs=1e-3) and "-9 m/s^2 at t = 10 ms" in ax.texts[0].get_text()
    with pytest.raises(ValueError, match="legend='below'"):
        plot_journal_orbit(r, legend="below")
