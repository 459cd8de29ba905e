"""Command line: run a mechanism and a scene file, write HDF5 and a figure; bad input fails clearly."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import daeclear as dc
from daeclear.cli import main
from scene_texts import PENDULUM

PENDULUM_TOML = PENDULUM + """
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


def test_run_scene_file_with_a_tabulated_driver_and_no_t_end(tmp_path):
    # a tabulated driver has no speed to count two revolutions by: the run lasts the 24 ms default
    path = tmp_path / "pendulum.toml"
    path.write_text(PENDULUM + '\n[[driver]]\nname = "d"\njoint = "A"\n'
                    'profile = { kind = "tabulated", times = [0.0, 0.01, 0.02], values = [0.0, 0.1, 0.3] }\n')
    assert main(["run", str(path), "--out", str(tmp_path), "--no-figure", "--quiet"]) == 0
    result = dc.load(tmp_path / "pendulum.h5")
    assert result.t[-1] == pytest.approx(0.024)
    # after the table the angle goes on along the natural spline's end slope
    spline = CubicSpline([0.0, 0.01, 0.02], [0.0, 0.1, 0.3], bc_type="natural")
    assert result["link.phi"][-1] == pytest.approx(0.3 + float(spline(0.02, 1)) * 0.004, rel=1e-6)


@pytest.mark.parametrize(
    "args, text",
    [
        (["run", "five_bar"], "neither a scene file nor a mechanism"),  # four_bar is one now
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


CLEARANCE_TOML = """
[scene]
name = "crank_with_clearance"
gravity = [0.0, -9.81]

[[body]]
name = "crank"
mass = 0.30
inertia = 1.0e-4
position = [0.025, 0.0]
velocity = [0.0, @crank_vy@]
angular_velocity = @omega@

[[body]]
name = "rod"
mass = 0.21
inertia = 2.5e-4
position = [0.11, 0.0]
velocity = [0.0, @rod_vy@]
angular_velocity = @rod_omega@

[[body]]
name = "slider"
mass = 0.14
inertia = 1.0e-4
position = [0.17, 0.0]

[[revolute]]
name = "A"
body_i = "ground"
body_j = "crank"
at = [0.0, 0.0]

[[revolute]]
name = "B"
body_i = "crank"
body_j = "rod"
at = [0.05, 0.0]

[[revolute_clearance]]
name = "clearance"
body_i = "slider"
body_j = "rod"
at = [0.17, 0.0]
bearing_radius = 0.01
clearance = 0.5e-3
material = { young = 207e9, poisson = 0.3 }
law = { name = "lankarani-nikravesh", restitution = 0.9 }
friction = 0.05

[[translational]]
name = "D"
body_i = "ground"
body_j = "slider"
at = [0.17, 0.0]

[[driver]]
name = "drive"
joint = "A"
speed = @omega@

[simulate]
t_end = 0.002
"""


def clearance_toml():
    """The chapter's mechanism as a scene file, started from the ideal kinematics like slider_crank."""
    omega = 5000 * 2 * np.pi / 60
    state = dc.mechanisms.ideal_slider_crank_state(0.0, omega)
    values = {"omega": omega, "crank_vy": state["crank"][4], "rod_vy": state["rod"][4], "rod_omega": state["rod"][5]}
    text = CLEARANCE_TOML
    for key, value in values.items():
        text = text.replace(f"@{key}@", repr(float(value)))
    return text


def test_scene_file_with_a_clearance_joint_matches_the_mechanism(tmp_path):
    path = tmp_path / "crank.toml"
    path.write_text(clearance_toml())
    assert main(["run", str(path), "--out", str(tmp_path), "--no-figure", "--quiet"]) == 0
    from_file = dc.load(tmp_path / "crank_with_clearance.h5")
    reference = dc.simulate(dc.mechanisms.slider_crank("revolute", friction=0.05), 0.002)
    assert [e.kind for e in from_file.events] == [e.kind for e in reference.events] and len(reference.events) > 2
    np.testing.assert_allclose(from_file.events.t, reference.events.t, rtol=1e-6)
    assert "clearance.friction_force" in from_file


def test_scene_file_clearance_law_errors_name_the_table(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(clearance_toml().replace('name = "lankarani-nikravesh"', 'name = "spring"'))
    assert main(["run", str(path), "--out", str(tmp_path)]) == 2
    assert "[[revolute_clearance]] #1" in capsys.readouterr().err


def test_run_with_sensitivities_writes_them_and_their_figure(tmp_path, capsys):
    """--sensitivity (repeatable): the streamed file holds S of every state and channel, those of the same run
    through the API; BASE_sensitivities.png draws one panel per parameter and the horizon."""
    import matplotlib.image

    names = ["clearance.clearance", "clearance.law.restitution"]
    argv = ["run", "slider_crank", "--joint", "revolute", "--t-end", "0.4e-3", "--out", str(tmp_path), "--quiet"]
    assert main(argv + [a for name in names for a in ("--sensitivity", name)]) == 0
    out = capsys.readouterr().out
    back = dc.load(tmp_path / "slider_crank_revolute.h5")
    assert back.sensitivity_names == tuple(names) and back.parameters["simulate"]["sensitivities"] == names
    step = back.t[1] - back.t[0]
    api = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.4e-3, rtol=1e-6, sensitivities=names,
                      save=dc.SaveAt(every=step, steps=False))
    assert np.array_equal(back.t, api.t) and len(back.sensitivities.events) == len(api.sensitivities.events) >= 2
    for name in ("slider.x", "crank.omega", "drive.moment"):
        assert back.sensitivity(name) == pytest.approx(api.sensitivity(name), rel=1e-9, abs=1e-12)
    png = tmp_path / "slider_crank_revolute_sensitivities.png"
    assert f"wrote {png}" in out and matplotlib.image.imread(png).shape[0] > 3 * 300  # three panels of 3 in


def test_run_refuses_an_unknown_sensitivity_before_any_run(tmp_path, capsys):
    argv = ["run", "slider_crank", "--joint", "revolute", "--t-end", "0.4e-3", "--out", str(tmp_path), "--quiet"]
    assert main(argv + ["--sensitivity", "clearance.clearence"]) == 2
    err = capsys.readouterr().err
    assert "sensitivities='clearance.clearence', must be one of model.parameter_names" in err
    assert "close matches: 'clearance.clearance'" in err
    assert not (tmp_path / "slider_crank_revolute.h5").exists()
