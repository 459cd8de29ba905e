"""Command line: run a mechanism and a scene file, write HDF5 and a figure; bad input fails clearly."""

import numpy as np
import pytest

import daeclear as dc
from daeclear.cli import main

PENDULUM_TOML = """
[scene]
name = "pendulum"
gravity = [0.0, -9.81]

[[body]]
name = "link"
mass = 1.0
inertia = 0.01
position = [0.5, 0.0]

[[revolute]]
name = "A"
body_i = "ground"
body_j = "link"
at = [0.0, 0.0]

[simulate]
t_end = 0.5
rtol = 1e-8
"""


def test_run_mechanism_writes_result_and_figure(tmp_path, capsys):
    code = main(["run", "slider_crank", "--set", "rpm=3000", "--t-end", "0.01", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    result = dc.load(tmp_path / "slider_crank.h5")
    assert (tmp_path / "slider_crank.png").stat().st_size > 10_000
    assert result.t[-1] == pytest.approx(0.01)
    # 3000 rpm was applied: the crank turns at 314.16 rad/s
    assert np.allclose(result["crank.omega"], 3000 * 2 * np.pi / 60)
    assert "wrote" in capsys.readouterr().out


def test_run_scene_file(tmp_path):
    path = tmp_path / "pendulum.toml"
    path.write_text(PENDULUM_TOML)
    assert main(["run", str(path), "--out", str(tmp_path), "--no-figure", "--quiet"]) == 0
    result = dc.load(tmp_path / "pendulum.h5")
    assert result.t[-1] == pytest.approx(0.5)
    assert result.parameters["simulate"]["rtol"] == 1e-8


@pytest.mark.parametrize(
    "args, text",
    [
        (["run", "four_bar"], "neither a scene file nor a mechanism"),
        (["run", "slider_crank", "--set", "rpmm=1"], "unknown option(s) rpmm"),
        (["run", "slider_crank", "--set", "rpm"], "expected KEY=VALUE"),
    ],
)
def test_bad_input_exits_with_message(args, text, capsys, tmp_path):
    assert main(args + ["--out", str(tmp_path)]) == 2
    assert text in capsys.readouterr().err


def test_scene_file_unknown_key(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(PENDULUM_TOML.replace("mass = 1.0", "mass = 1.0\nmas = 2.0"))
    assert main(["run", str(path), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "[[body]] #1: unknown key(s) mas" in err


def test_study_writes_table_and_figure(tmp_path, capsys):
    code = main(["study", "slider_crank", "--joint", "ideal", "--t-end", "0.002", "--methods", "ida,rk4",
                 "--rtols", "1e-5", "--steps", "1e-5", "--repeats", "0", "--channels", "slider.vx",
                 "--out", str(tmp_path)])
    assert code == 0
    lines = (tmp_path / "work_precision.csv").read_text().strip().splitlines()
    assert len(lines) == 3 and lines[1].startswith("ida,ida,1e-05")
    assert (tmp_path / "work_precision.png").stat().st_size > 10_000
    assert "Window: t in [0, 0.002]" in capsys.readouterr().out
