"""Figures carry their parameters: captions from the scene, time windows, decimation, parameter axes.

Built on hand-made Results and a stand-in sweep, so the expected line data are known exactly;
the captions are checked on the scene descriptions of the real slider-crank scenes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from daeclear.plot import style  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402
from daeclear.plot import (  # noqa: E402
    plot_bifurcation,
    plot_channel,
    plot_journal_orbit,
    plot_motion_map,
    plot_phase_portrait,
    plot_revolute_response,
    plot_slider_path,
    plot_step_sizes,
    plot_translational_response,
    save_response_figure,
)
from daeclear.results.result import ContactEvent, Result  # noqa: E402

C = 0.5e-3  # m


@pytest.fixture(autouse=True)
def no_show(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(plt, "show", lambda *a, **k: pytest.fail("figure functions must not call plt.show"))
    yield
    plt.close("all")


def scene_parameters(**kwargs: Any) -> dict[str, Any]:
    """The parameters simulate() records, for a slider-crank scene (no simulation needed)."""
    return {"scene": slider_crank(**kwargs).to_dict(), "formulation": "index1"}


def make_result(n: int = 20001, t_end: float = 2.0, joint: str = "revolute", **scene_kw: Any) -> Result:
    """A long run (many 'revolutions') with a sharp peak, the channels of both clearance joints, steps, events."""
    t = np.linspace(0.0, t_end, n)
    phase = 2 * np.pi * 50 * t
    ax = -19000.0 * np.cos(phase)
    ax[n // 3] = 90000.0  # one impact spike that decimation must keep
    channels = {
        "slider.vx": 28.0 * np.sin(phase), "slider.ax": ax, "drive.moment": 138.0 * np.sin(2 * phase),
        "clearance.ex": 1.01 * C * np.cos(phase), "clearance.ey": 1.01 * C * np.sin(phase),
        "clearance.xi": 0.5 + 0.5 * np.sin(phase), "clearance.eta": 0.4 * np.cos(3 * phase),
    }
    units = {"slider.vx": "m/s", "slider.ax": "m/s^2", "drive.moment": "N m", "clearance.ex": "m",
             "clearance.ey": "m", "clearance.xi": "", "clearance.eta": ""}
    step_t = np.linspace(0.0, t_end, 3001)
    step_h = np.full(step_t.size, t_end / 3000)
    step_h[0] = 0.0
    events = [ContactEvent(t=a, pair="clearance", kind=k, approach_speed=1.0, y=np.zeros(1))
              for a, k in ((0.3, "onset"), (0.5, "separation"), (1.2, "onset"), (1.4, "separation"))]
    kw = {"clearance": C, "restitution": 0.9, **scene_kw}
    return Result(t=t, y=np.zeros((n, 1)), yp=np.zeros((n, 1)), state_names=["q"], channels=channels, units=units,
                  events=events, segments=[(0.0, t_end, {"clearance": "free"})], step_t=step_t, step_h=step_h,
                  step_order=np.ones(step_t.size, dtype=int), parameters=scene_parameters(joint=joint, **kw),
                  scene_name=f"slider_crank_{joint}")


# --------------------------------------------------------------------------- captions


def test_scene_parameters_keep_the_law_names() -> None:
    r = make_result(law="hunt-crossley", friction=0.05)
    clearance = r.parameters["scene"]["elements"]["clearance"]
    assert clearance["law"]["name"] == "hunt-crossley"
    assert clearance["friction"]["name"] == "modified-coulomb"
    ideal = make_result(friction=None)
    assert ideal.parameters["scene"]["elements"]["clearance"]["friction"] == {"name": "none"}


@pytest.mark.parametrize(("joint", "kw", "expected"), [
    ("revolute", {}, ["slider_crank_revolute:", "c = 0.5 mm", "5000 rpm", "Lankarani-Nikravesh $c_e$ = 0.9",
                      "frictionless"]),
    ("revolute", {"clearance": 0.1e-3, "rpm": 2500.0, "law": "hunt-crossley", "restitution": 0.7,
                  "friction": 0.03}, ["c = 0.1 mm", "2500 rpm", "Hunt-Crossley $c_e$ = 0.7",
                                      "modified Coulomb $c_f$ = 0.03"]),
    ("translational", {"clearance": 0.25e-3}, ["slider_crank_translational:", "c = 0.25 mm", "5000 rpm",
                                               "$c_e$ = 0.9", "frictionless"]),
])
def test_caption_states_clearance_speed_law_restitution_friction(joint: str, kw: dict[str, Any],
                                                                  expected: list[str]) -> None:
    text = style.caption(make_result(n=11, joint=joint, **kw))
    for part in expected:
        assert part in text, (part, text)


def test_caption_of_an_ideal_or_failed_run() -> None:
    ideal = Result(t=[0.0], y=np.zeros((1, 1)), yp=np.zeros((1, 1)), state_names=["q"], channels={}, units={},
                   parameters=scene_parameters(joint="ideal"), scene_name="slider_crank", success=False, status=-1)
    text = style.caption(ideal)
    assert text.startswith("slider_crank: 5000 rpm") and "c =" not in text and "FAILED" in text


# --------------------------------------------------------------------------- titles


def test_figure_titles_contain_the_clearance() -> None:
    r = make_result(clearance=0.37e-3)
    assert "c = 0.37 mm" in plot_channel(r, "slider.vx").get_title()
    assert "c = 0.37 mm" in plot_journal_orbit(r).get_title()
    assert "c = 0.37 mm" in plot_phase_portrait(r).get_title()
    assert "c = 0.37 mm" in plot_step_sizes(r).get_title()
    assert "c = 0.37 mm" in plot_slider_path(r).get_title()
    fig = plot_revolute_response(r)
    assert "c = 0.37 mm" in fig.get_suptitle() and "5000 rpm" in fig.get_suptitle()
    assert fig.axes[0].get_title() == "(a) slider velocity"
    fig = plot_translational_response(r, title="Fig. 4.28")
    assert fig.get_suptitle() == "Fig. 4.28"


def test_title_on_given_axes_only_when_asked() -> None:
    r = make_result(n=101)
    _, ax = plt.subplots()
    assert plot_channel(r, "slider.vx", ax=ax).get_title() == ""  # a panel of someone else's figure
    assert "c = 0.5 mm" in plot_channel(r, "slider.vx", ax=ax, title=True).get_title()
    assert plot_channel(r, "slider.vx", title=False).get_title() == ""
    assert plot_channel(r, "slider.vx", title="mine").get_title() == "mine"


def test_save_response_figure_is_titled_with_the_parameters(tmp_path, monkeypatch: pytest.MonkeyPatch) -> None:
    titles: list[str] = []
    real_savefig = matplotlib.figure.Figure.savefig

    def spy(fig: Any, *args: Any, **kwargs: Any) -> None:
        titles.append(fig.get_suptitle())
        real_savefig(fig, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    path = save_response_figure(make_result(n=2001), tmp_path / "run.png", window=(0.5, 1.0), max_points=400)
    assert path.stat().st_size > 5_000
    assert "c = 0.5 mm" in titles[0] and "5000 rpm" in titles[0]


# --------------------------------------------------------------------------- window and decimation


def test_time_plots_accept_a_window() -> None:
    r = make_result()
    ref = make_result(n=4001)
    ax = plot_channel(r, "slider.vx", reference=ref, window=(0.5, 0.75))
    for line in ax.get_lines():
        x = line.get_xdata()
        assert len(x) > 100 and x.min() >= 0.5 and x.max() <= 0.75
    inside = (r.t >= 0.5) & (r.t <= 0.75)
    np.testing.assert_array_equal(ax.get_lines()[1].get_ydata(), r["slider.vx"][inside])
    ax = plot_step_sizes(r, window=(0.4, 1.3))
    x = ax.get_lines()[0].get_xdata()
    assert x.min() >= 0.4 and x.max() <= 1.3
    spans = [p.get_x() for p in ax.patches]  # contact intervals clipped to the window
    assert min(spans) >= 0.4 and len(ax.patches) == 2
    fig = plot_revolute_response(r, window=(1.0, None))
    for panel in fig.axes[:3]:
        assert all(line.get_xdata().min() >= 1.0 for line in panel.get_lines())


def test_x_y_plots_draw_only_the_window() -> None:
    r = make_result()
    inside = (r.t >= 0.2) & (r.t <= 0.3)
    orbit = plot_journal_orbit(r, window=(0.2, 0.3)).get_lines()[0]
    np.testing.assert_allclose(orbit.get_xdata(), r["clearance.ex"][inside] * 1e6)
    portrait = plot_phase_portrait(r, window=(0.2, 0.3)).get_lines()[0]
    np.testing.assert_array_equal(portrait.get_ydata(), r["slider.ax"][inside])
    path = plot_slider_path(r, window=(0.2, 0.3)).get_lines()[0]
    np.testing.assert_array_equal(path.get_xdata(), r["clearance.xi"][inside])


def test_decimation_bounds_the_points_and_keeps_the_peaks() -> None:
    r = make_result()
    ax = plot_channel(r, "slider.ax", reference=make_result(n=30001), max_points=500)
    for line in ax.get_lines():
        assert len(line.get_xdata()) <= 500
        assert np.all(np.diff(line.get_xdata()) >= 0)  # still in time order
    assert ax.get_lines()[1].get_ydata().max() == 90000.0  # the impact spike survives
    assert ax.get_lines()[1].get_ydata().min() == r["slider.ax"].min()
    for draw in (plot_journal_orbit, plot_phase_portrait, plot_slider_path, plot_step_sizes):
        line = draw(r, max_points=300).get_lines()[0]
        assert 2 <= len(line.get_xdata()) <= 300, draw.__name__
    fig = plot_revolute_response(r, window=(0.0, 1.0), max_points=200)
    for panel in fig.axes:
        assert all(len(line.get_xdata()) <= 200 for line in panel.get_lines() if len(line.get_xdata()) != 361)
    # few points: nothing dropped
    assert len(plot_channel(r, "slider.vx", window=(0.0, 0.001), max_points=500).get_lines()[0].get_xdata()) == 11


def test_decimate_and_window_arguments_are_checked() -> None:
    r = make_result(n=101)
    with pytest.raises(ValueError, match="max_points"):
        plot_channel(r, "slider.vx", max_points=1)
    with pytest.raises(ValueError, match="t0 must not exceed t1"):
        plot_channel(r, "slider.vx", window=(1.0, 0.5))
    with pytest.raises(ValueError, match="pair"):
        plot_channel(r, "slider.vx", window=0.5)  # type: ignore[arg-type]
    index = style.decimate(np.arange(1000.0), 10)
    assert len(index) <= 10 and index[0] == 0 and index[-1] == 999


# --------------------------------------------------------------------------- sweep figures


@dataclass
class Run:
    parameters: dict[str, Any]
    motion: str = "periodic"
    period: int = 1
    ok: bool = True
    evidence: dict[str, Any] = field(default_factory=dict)


@dataclass
class Section:
    channels: tuple[str, ...] = ("slider.vx",)
    units: tuple[str, ...] = ("m/s",)


class FakeSweep:
    """What plot_bifurcation and plot_motion_map read of a SweepResult."""

    mechanism = "slider_crank"

    def __init__(self, runs: list[Run]) -> None:
        self.runs = runs

    def section(self, run: Any) -> Section:
        return Section()

    def bifurcation_data(self, parameter: str, channel: Any = 0) -> tuple[np.ndarray, np.ndarray, list[str]]:
        x = np.repeat([r.parameters[parameter] for r in self.runs], 3).astype(float)
        return x, np.sin(x * 1e3), [r.motion for r in self.runs for _ in range(3)]


def test_bifurcation_axis_has_the_unit_and_a_log_scale_for_a_geometric_grid() -> None:
    grid = np.geomspace(1e-5, 5e-4, 6)
    ax = plot_bifurcation(FakeSweep([Run({"joint": "revolute", "rpm": 5000.0, "clearance": c}) for c in grid]),
                          "clearance")
    assert ax.get_xlabel() == "clearance (mm)" and ax.get_xscale() == "log"
    np.testing.assert_allclose(np.sort(np.concatenate([ln.get_xdata() for ln in ax.get_lines()])),
                               np.repeat(grid * 1e3, 3))
    assert "5000 rpm" in ax.get_title() and "joint = revolute" in ax.get_title()
    assert "clearance" not in ax.get_title()
    linear = plot_bifurcation(FakeSweep([Run({"restitution": e}) for e in (0.5, 0.7, 0.9)]), "restitution")
    assert linear.get_xscale() == "linear" and linear.get_xlabel() == "restitution (-)"
    forced = plot_bifurcation(FakeSweep([Run({"rpm": v}) for v in (1000.0, 3000.0)]), "rpm", log=True)
    assert forced.get_xscale() == "log" and forced.get_xlabel() == "rpm (rpm)"


def test_motion_map_log_axis_for_a_geometric_grid() -> None:
    clearances = list(np.geomspace(1e-5, 1e-3, 5))
    runs = [Run({"clearance": c, "friction": f, "rpm": 5000.0}, motion="chaotic" if f else "periodic")
            for c in clearances for f in (0.0, 0.05, 0.1)]
    ax = plot_motion_map(FakeSweep(runs), "clearance", "friction")
    assert ax.get_xscale() == "log" and ax.get_yscale() == "linear"
    assert ax.get_xlabel() == "clearance (mm)" and ax.get_ylabel() == "friction (-)"
    assert [t.get_text() for t in ax.get_xticklabels()] == [f"{c * 1e3:.3g}" for c in clearances]
    np.testing.assert_allclose(ax.get_xticks(), np.array(clearances) * 1e3)
    xs = sorted({round(math.log10(t.get_position()[0]), 9) for t in ax.texts})
    np.testing.assert_allclose(xs, np.log10(np.array(clearances) * 1e3))  # labels centred on the values
    assert "5000 rpm" in ax.get_title()
    index_grid = plot_motion_map(FakeSweep(runs), "clearance", "friction", x_log=False)
    assert index_grid.get_xscale() == "linear" and list(index_grid.get_xticks()) == [0, 1, 2, 3, 4]


def test_is_geometric() -> None:
    assert style.is_geometric(np.geomspace(1e-5, 1e-3, 4))
    assert style.is_geometric([4.0, 1.0, 2.0])  # order does not matter
    assert not style.is_geometric(np.linspace(1e-5, 1e-3, 4))
    assert not style.is_geometric([1e-5, 1e-3])  # two values: no grid to recognise
    assert not style.is_geometric([None, 0.1, 0.2]) and not style.is_geometric([-1.0, -2.0, -4.0])
