"""Smoke tests: every section 4.4 example runs with --quick and writes its HDF5, figures and metrics.

The scripts are imported and their ``main(argv)`` called in this process (the compiled models
are cached across them). Whole file: about 25 s on a fresh compile cache, a few s warm.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import daeclear as dc  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

# script -> files it must write with --quick
EXPECTED = {
    "revolute_fig4_15": ["fig4_15.png", "step_sizes.png", "revolute_c0.5mm.h5", "ideal.h5", "metrics.json",
                         "metrics.md"],
    "revolute_clearance_study": ["fig4_16_crank_moment.png", "fig4_17_journal_orbits.png",
                                 "fig4_18_phase_portraits.png", "step_sizes.png", "c0.5mm.h5", "c0.2mm.h5",
                                 "c0.1mm.h5", "c0.01mm.h5", "ideal.h5", "metrics.json", "metrics.md"],
    "revolute_friction_study": ["fig4_19_crank_moment.png", "fig4_20_journal_orbits.png",
                                "fig4_21_phase_portraits.png", "step_sizes.png", "cf0.01.h5", "cf0.03.h5",
                                "cf0.05.h5", "cf0.1.h5", "ideal.h5", "metrics.json"],
    "revolute_contact_laws": ["fig4_22_contact_force.png", "fig4_23_crank_moment.png", "fig4_24_journal_orbits.png",
                              "law_curves.png", "step_sizes.png", "hertz.h5", "lankarani_nikravesh.h5",
                              "dubowsky_freudenstein.h5", "goldsmith.h5", "esdu_78035.h5", "ideal.h5",
                              "metrics.json"],
    "revolute_restitution": ["fig4_25_crank_moment.png", "fig4_25_contact_force.png", "journal_orbits.png",
                             "step_sizes.png", "ce1.00.h5", "ce0.99.h5", "ce0.95.h5", "ce0.90.h5", "ideal.h5",
                             "metrics.json"],
    "revolute_first_impact": ["fig4_26_first_impact.png", "first_impact_ce1.00.h5", "first_impact_ce0.90.h5",
                              "metrics.json", "metrics.md"],
}


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(autouse=True)
def examples_on_path(monkeypatch):
    monkeypatch.syspath_prepend(str(EXAMPLES))
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


def test_every_revolute_example_is_listed():
    scripts = sorted(p.stem for p in EXAMPLES.glob("revolute_*.py"))
    assert scripts == sorted(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_example_quick_run_writes_its_files(name, tmp_path, capsys):
    out = tmp_path / name
    assert _load(name).main(["--quick", "--out", str(out)]) == 0
    for file in EXPECTED[name]:
        path = out / file
        assert path.is_file(), f"{name} did not write {file}"
        assert path.stat().st_size > (5_000 if file.endswith(".png") else 100), file
    printed = capsys.readouterr().out
    assert "wrote" in printed and "|" in printed  # progress, summary table, file list
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["cases"] and all("case" in row for row in metrics["cases"])


def test_quick_result_files_hold_the_window_and_the_steps(tmp_path):
    out = tmp_path / "fig"
    assert _load("revolute_fig4_15").main(["--quick", "--out", str(out)]) == 0
    result = dc.load(out / "revolute_c0.5mm.h5")
    ideal = dc.load(out / "ideal.h5")
    assert result.t[0] == pytest.approx(0.0) and result.t[-1] == pytest.approx(0.005)
    assert result.t.shape == ideal.t.shape
    assert result.step_h is not None and result.step_h.size > 10
    assert len(result.events.of("clearance", "onset")) >= 1  # the first impact is at 0.23 ms
    row = json.loads((out / "metrics.json").read_text())["cases"][0]
    assert row["impacts"] == len(result.events.of("clearance", "onset"))
    assert 0.0 < row["contact_fraction"] < 1.0


def test_common_span_windows_fall_on_revolutions(tmp_path):
    import _common as cm

    args = cm.parse_args("x.py", "test", ["--out", str(tmp_path), "--transient", "2", "--revolutions", "3"])
    span = cm.make_span(args)
    assert span.t_end == pytest.approx(5 * cm.PERIOD)
    assert span.analysed == pytest.approx((2 * cm.PERIOD, 5 * cm.PERIOD))
    assert span.window == pytest.approx((3 * cm.PERIOD, 5 * cm.PERIOD))
    assert span.revolution_times == pytest.approx([2 * cm.PERIOD, 3 * cm.PERIOD, 4 * cm.PERIOD, 5 * cm.PERIOD])
    assert span.t_eval[0] == span.analysed[0] and span.t_eval[-1] == span.t_end
    assert all(t in span.t_eval for t in span.revolution_times)


def test_common_distinct_points_counts_clusters():
    import numpy as np

    import _common as cm

    points = np.array([[0.0, 0.0], [0.001, 0.0], [1.0, 1.0], [1.0, 1.0005], [2.0, 0.0]])
    assert cm.distinct_points(points, scale=np.array([1.0, 1.0]), tol=0.01) == 3
    assert cm.distinct_points(points[:1], scale=np.array([1.0, 1.0])) == 1
