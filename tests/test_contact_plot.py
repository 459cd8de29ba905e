"""Plot helpers for single impacts (Fig. 4.26): smoke tests on the Agg backend."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from daeclear.contact import Hertz, LankaraniNikravesh, simulate_impact  # noqa: E402
from daeclear.plot import plot_force_penetration, plot_force_time  # noqa: E402

K = 6.61e10


@pytest.fixture(scope="module")
def impacts():
    return [simulate_impact(LankaraniNikravesh(restitution=c, stiffness=K), mass=0.2, speed=1.0, n_points=301)
            for c in (1.0, 0.99, 0.95, 0.9)]


@pytest.fixture(autouse=True)
def no_show(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(plt, "show", lambda *a, **k: pytest.fail("plot helpers must not call plt.show"))
    yield
    plt.close("all")


@pytest.mark.parametrize("plot", [plot_force_penetration, plot_force_time])
def test_plot_helpers_draw_one_line_per_law(plot, impacts) -> None:
    ax = plot(impacts)
    assert len(ax.get_lines()) == 4
    assert [t.get_text() for t in ax.get_legend().get_texts()][0] == "lankarani-nikravesh, $c_e$ = 1"
    np.testing.assert_allclose(ax.get_lines()[3].get_ydata(), impacts[3].force)


def test_plot_helpers_accept_axes_and_mapping(impacts) -> None:
    fig, (left, right) = plt.subplots(1, 2)
    data = {"Hertz": simulate_impact(Hertz(stiffness=K), mass=0.2, speed=1.0, n_points=101), "LN 0.9": impacts[3]}
    assert plot_force_penetration(data, ax=left) is left
    assert plot_force_time(impacts[0], ax=right, color="k") is right
    assert [t.get_text() for t in left.get_legend().get_texts()] == ["Hertz", "LN 0.9"]
    assert "µm" in left.get_xlabel() and "µs" in right.get_xlabel()
    np.testing.assert_allclose(left.get_lines()[0].get_xdata(), data["Hertz"].penetration * 1e6)
