"""Work-precision studies: errors against an independent reference, the converged window, failures kept."""

import math

import numpy as np
import pytest

import daeclear as dc
from daeclear.studies.accuracy import channel_error, converged_window, event_time_error, work_precision
from daeclear.core.errors import SceneError

REV = 60.0 / 5000.0


@pytest.fixture(scope="module")
def ideal_study():
    return work_precision(dc.mechanisms.slider_crank(), REV / 2, channels=["slider.vx", "drive.moment"],
                          # IDA on the index-1 ODE the other methods integrate (its errors shrink
                          # 100x from rtol 1e-4 to 1e-7; GGL's are already 50x smaller at 1e-4)
                          methods={"IDA": {"method": "ida", "formulation": "index1"}, "RK4": {"method": "rk4"}},
                          rtols=(1e-4, 1e-7), steps=(2e-5, 1e-5), n_eval=301, repeats=1)


def test_errors_shrink_with_tolerance_and_step(ideal_study):
    rows = {(r["label"], r["tolerance"]): r for r in ideal_study.rows}
    assert all(r["status"] == 0 for r in ideal_study.rows)
    assert rows[("IDA", 1e-7)]["error"] < rows[("IDA", 1e-4)]["error"] / 100
    # RK4: fourth order, halving the step divides the error by about 16
    ratio = rows[("RK4", 2e-5)]["error"] / rows[("RK4", 1e-5)]["error"]
    assert 10 < ratio < 24
    # ideal mechanism: the reference is converged over the whole span
    assert ideal_study.window == (0.0, pytest.approx(REV / 2))


def test_tables_and_speed_ratio(ideal_study, tmp_path):
    csv_text = ideal_study.to_csv(tmp_path / "wp.csv")
    assert csv_text.splitlines()[0].startswith("label,method,tolerance,error")
    assert len(csv_text.strip().splitlines()) == 1 + len(ideal_study.rows)
    md = ideal_study.to_markdown(tmp_path / "wp.md")
    assert "Window: t in [0," in md and "| IDA | 0.0001 |" in md
    ratios = ideal_study.speed_ratio("IDA", ["RK4"])
    for r in ratios:
        assert r["rival_error"] <= r["error"]
        assert r["ratio"] == pytest.approx(r["rival_wall_time"] / r["wall_time"])


def test_failed_runs_stay_in_the_table():
    study = work_precision(dc.mechanisms.slider_crank("revolute", gravity=0.0), 0.4e-3, channels=["slider.vx"],
                           methods={"Euler coarse": {"method": "euler"}}, steps=(2e-4,), n_eval=41, repeats=0,
                           window=(0.0, 0.4e-3))
    (row,) = study.rows
    if row["status"] != 0:
        assert row["message"] and math.isinf(row["error"])
    else:  # a run that finishes but is wrong is reported with its (large) error
        assert row["error"] > 1e-2
    assert study.window_reason == "given"


def test_window_ends_where_independent_references_part():
    t = np.linspace(0, 1, 101)
    ref = dc.Result(t=t, y=np.zeros((101, 1)), yp=np.zeros((101, 1)), state_names=["s"],
                    channels={"x": np.sin(t)}, units={"x": ""})
    other_x = np.sin(t) + np.where(t > 0.5, 1e-3, 0.0)
    other = dc.Result(t=t, y=np.zeros((101, 1)), yp=np.zeros((101, 1)), state_names=["s"],
                      channels={"x": other_x}, units={"x": ""})
    assert converged_window(ref, other, ["x"], 1e-6) == pytest.approx(0.5)
    assert channel_error(other, ref, ["x"], (0.0, 0.5))["x"] == 0.0
    assert channel_error(other, ref, ["x"], (0.0, 1.0))["x"] == pytest.approx(1e-3 / np.ptp(np.sin(t)))
    assert event_time_error(ref, other, (0.0, 1.0)) == (0.0, 0)


def test_bad_channel_is_rejected():
    with pytest.raises(SceneError, match="no channel 'slider.v'"):
        work_precision(dc.mechanisms.slider_crank(), 0.001, channels=["slider.v"])


def test_a_failed_check_run_is_an_error_not_the_whole_window():
    """The converged window needs the check run: when it fails, the study says so instead of
    measuring errors over a window where nothing says the reference is right."""
    with pytest.raises(dc.DaeclearError, match=r"check run .*max_steps=5.* failed.*window="):
        work_precision(dc.mechanisms.slider_crank("revolute", gravity=0.0), 0.4e-3, channels=["slider.vx"],
                       methods={"IDA": {"method": "ida"}}, rtols=(1e-6,), n_eval=41, repeats=0,
                       check={"method": "ida", "rtol": 1e-12, "max_steps": 5})


def test_the_default_check_is_the_index1_formulation():
    """The documented default check: IDA on the index-1 formulation at rtol 1e-12 (independent of
    the GGL default of the runs it judges); with it the Fig. 4.15 scene's window over two crank
    revolutions ends where the motion becomes sensitive to the impact sequence, before the end."""
    study = work_precision(dc.mechanisms.slider_crank("revolute", gravity=0.0), 2 * REV, channels=["slider.vx"],
                           methods={"IDA": {"method": "ida"}}, rtols=(1e-7,), n_eval=201, repeats=0)
    assert 0.002 < study.window[1] < 2 * REV
    assert study.notes and "diverge" in study.notes[0]
    (row,) = study.rows
    assert row["status"] == 0 and row["error"] < 1e-2
