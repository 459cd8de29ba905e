"""Clearance as a property of a joint, and the ready four-bar and double pendulum.

Checked: ``Scene.with_clearance`` gives the scene a user would build by hand (same elements, same
assembled equations at a random state, same run); the four-bar's ideal kinematics against its
closed-form position solution and the rocker's limit angles (Grashof crank-rocker); clearance runs
tend to the ideal mechanism as the clearance shrinks; a conservative double pendulum keeps its
energy; the chapter's start makes the first impact independent of the declared velocities.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.model import mechanisms as M
from scene_texts import PENDULUM_LINK

STEEL = dcc.Material(young=207e9, poisson=0.3)


def residual_at(model: dc.DAEModel, seed: int) -> np.ndarray:
    """The assembled residual (every contact term on) at a random state: the equations themselves."""
    rng = np.random.default_rng(seed)
    y = np.concatenate([model.q_guess, model.v_guess, np.zeros(model.n_states - 2 * model.n_q)])
    y = y + 1e-4 * rng.standard_normal(y.size)
    yp = rng.standard_normal(y.size)
    return np.array(model.functions.residual(1.3e-3, y, yp, model.parameter_values)).ravel()


# ---------------------------------------------------------------------------------------------- with_clearance

def hand_built_four_bar(clearance: float) -> dc.Scene:
    """The ready four-bar with clearance at B, written element by element as a user would."""
    ideal = M.four_bar()
    scene = dc.Scene("four_bar_B", gravity=(0.0, -9.81))
    for element in ideal:
        if element.name == "B":
            element = dc.RevoluteClearance("B", "crank", "coupler", at=element.at, bearing_radius=10e-3,
                                           clearance=clearance, material=STEEL,
                                           law=dcc.LankaraniNikravesh(restitution=0.9))
        scene.add(element)
    return scene


def test_with_clearance_equals_the_hand_built_scene():
    ideal = M.four_bar()
    converted = ideal.with_clearance("B", clearance=0.3e-3, bearing_radius=10e-3, material=STEEL,
                                     law=dcc.LankaraniNikravesh(restitution=0.9))
    converted.name = "four_bar_B"
    by_hand = hand_built_four_bar(0.3e-3)
    assert converted == by_hand
    assert ideal["B"].kind == "Revolute"  # the ideal scene is left as it was
    assert M.four_bar(("B",), clearance=0.3e-3) == by_hand  # the ready mechanism takes the same path
    a, b = dc.assemble(converted), dc.assemble(by_hand)
    np.testing.assert_array_equal(a.parameter_values, b.parameter_values)
    for seed in (1, 2):
        np.testing.assert_array_equal(residual_at(a, seed), residual_at(b, seed))
    run_a, run_b = (dc.simulate(s, t_end=1.5e-3, rtol=1e-7) for s in (converted, by_hand))
    np.testing.assert_array_equal(run_a.t, run_b.t)
    np.testing.assert_array_equal(run_a["B.normal_force"], run_b["B.normal_force"])


def test_slider_crank_through_with_clearance_is_the_scene_it_built_before():
    """slider_crank now converts its ideal joints C and D; the scenes are the ones it built element by
    element before (bearing on the slider, journal on the rod; the chapter's guide), and its ideal
    guide D, now given by the origin on the X axis, has the same equations as one given at the pin."""
    ready = M.slider_crank("revolute")
    pin_c = ready["clearance"].at
    assert ready["clearance"] == dc.RevoluteClearance(
        "clearance", "slider", "rod", at=pin_c, bearing_radius=10e-3, clearance=0.5e-3, material=STEEL,
        law=dcc.LankaraniNikravesh(restitution=0.9), friction=dcc.friction_law(None))
    guide = M.slider_crank("translational")["clearance"]
    assert (guide.body_i, guide.body_j, guide.point_i, guide.point_j, guide.axis) == \
        ("ground", "slider", (0.0, 0.0), (0.0, 0.0), (1.0, 0.0))
    assert guide.stroke == pytest.approx((0.07, 0.17)) and guide.upper_limits == pytest.approx((0.04, 0.20))
    ideal = M.slider_crank()
    at_pin = dc.Scene(ideal.name, gravity=ideal.gravity, elements=[
        dc.Translational("D", "ground", "slider", at=pin_c, axis=(1.0, 0.0)) if e.name == "D" else e for e in ideal])
    a, b = dc.assemble(ideal), dc.assemble(at_pin)
    np.testing.assert_allclose(residual_at(a, 3), residual_at(b, 3), rtol=0, atol=1e-12)


def test_translational_joint_gets_a_clearance():
    scene = dc.Scene("slide", gravity=(0.0, -9.81))
    block = scene.add(dc.Body("block", mass=0.14, inertia=1e-4, position=(0.1, 0.0)))
    scene.add(dc.Translational("G", scene.ground, block, at=(0.1, 0.0), axis=(1.0, 0.0)))
    loose = scene.with_clearance("G", clearance=0.2e-3, length=0.05, width=0.05, corner_radius=1e-3,
                                 material=STEEL)
    assert loose["G"] == dc.TranslationalClearance("G", "ground", "block", at=(0.1, 0.0), axis=(1.0, 0.0),
                                                   clearance=0.2e-3, length=0.05, width=0.05, corner_radius=1e-3,
                                                   material=STEEL)
    run = dc.simulate(loose, t_end=0.01, rtol=1e-7)
    # the block falls through the clearance onto the lower surface (eta = -0.5) and bounces
    first = run.events.of("G", kind="onset")[0]
    assert first.t == pytest.approx(math.sqrt(2 * 0.2e-3 / 9.81), rel=0.02)  # free fall through c
    assert -0.52 < np.min(run["G.eta"]) < -0.5  # a few micrometres into the surface


def test_ideal_is_the_inverse_of_with_clearance():
    loose = M.four_bar(("B", "C", "D"))
    ideal = loose.ideal()
    ideal.name = "four_bar"
    assert ideal == M.four_bar()
    assert loose["B"].kind == "RevoluteClearance"  # left unchanged
    guide = M.slider_crank("translational").ideal()["clearance"]
    assert (guide.kind, guide.point_i, guide.point_j, guide.axis) == ("Translational", (0.0, 0.0), (0.0, 0.0),
                                                                      (1.0, 0.0))
    with pytest.raises(dc.SceneError, match="'B': it is a Revolute, not a clearance joint"):
        dc.model.scene.ideal_joint(M.four_bar()["B"])


def test_bearing_body_and_name():
    ideal = M.four_bar()
    flipped = ideal.with_clearance("C", bearing="rocker", name="pinC", clearance=0.2e-3, bearing_radius=8e-3,
                                   material=STEEL)
    joint = flipped["pinC"]
    assert (joint.body_i, joint.body_j, joint.at) == ("rocker", "coupler", ideal["C"].at)
    assert [e.name for e in flipped] == [e.name if e.name != "C" else "pinC" for e in ideal]  # same place


@pytest.mark.parametrize("call, message", [
    (lambda s: s.with_clearance("BB", clearance=1e-4, bearing_radius=0.01), "no joint named 'BB'.*Did you mean 'B'"),
    (lambda s: s.with_clearance("coupler", clearance=1e-4, bearing_radius=0.01), "is a Body"),
    (lambda s: s.with_clearance("drive", clearance=1e-4, bearing_radius=0.01), "is a Driver"),
    (lambda s: s.with_clearance("B", clearance=1e-4), "missing bearing_radius"),
    (lambda s: s.with_clearance("B", bearing_radius=0.01), "missing clearance or journal_radius"),
    (lambda s: s.with_clearance("B", clearance=1e-4, bearing_radius=0.01, at=(0, 0)), "at \\(shared"),
    (lambda s: s.with_clearance("B", clearance=1e-4, bearing_radius=0.01, radius=1), "unknown field.*radius"),
    (lambda s: s.with_clearance("B", clearance=0.02, bearing_radius=0.01), "clearance 0.02 m, must be in"),
    (lambda s: s.with_clearance("B", bearing="rocker", clearance=1e-4, bearing_radius=0.01),
     "bearing='rocker', must be one of the joint's bodies 'crank' or 'coupler'"),
    (lambda s: s.with_clearance("B", clearance=1e-4, bearing_radius=0.01, material=STEEL)
     .with_clearance("B", clearance=1e-4, bearing_radius=0.01), "already a RevoluteClearance"),
    (lambda s: s.with_clearance("B", clearance=1e-4, bearing_radius=0.01), "materials=None"),
])
def test_with_clearance_bad_input(call, message):
    with pytest.raises(dc.SceneError, match=message):
        call(M.four_bar())


def test_scene_file_clearance_table(tmp_path):
    from daeclear.model.scenefile import read_scene_file

    text = """
[scene]
name = "loose"
""" + PENDULUM_LINK + ("clearance = { clearance = 0.1e-3, bearing_radius = 0.01, "
                       "material = { young = 207e9, poisson = 0.3 }, "
                       'law = { name = "lankarani-nikravesh", restitution = 0.9 } }\n')
    path = tmp_path / "loose.toml"
    path.write_text(text)
    scene = read_scene_file(path).scene
    expected = dc.Scene("loose")
    expected.add(dc.Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
    expected.add(dc.Revolute("A", "ground", "link", at=(0.0, 0.0)))
    assert scene == expected.with_clearance("A", clearance=0.1e-3, bearing_radius=0.01, material=STEEL,
                                            law=dcc.LankaraniNikravesh(restitution=0.9))
    for bad, message in (("clearance = 0.1e-3", "key clearance = 0.0001 is a number, must be a table"),
                         ("clearance = { clearance = 0.1e-3 }", "key clearance:.*missing bearing_radius"),
                         ("clearance = { clearance = 0.1e-3, bearing_radius = 0.01, radius = 2 }",
                          "key clearance:.*unknown field.*radius")):
        path.write_text(text.replace(text.splitlines()[-1], bad))
        with pytest.raises(dc.SceneError, match=rf"\[\[revolute\]\] #1: {message}"):
            read_scene_file(path)


# ---------------------------------------------------------------------------------------------- four-bar

def test_four_bar_is_a_grashof_crank_rocker_with_closed_form_kinematics():
    a, b, c, d = M.FOUR_BAR_CRANK, M.FOUR_BAR_COUPLER, M.FOUR_BAR_ROCKER, M.FOUR_BAR_GROUND
    assert M.grashof_crank_rocker(a, b, c, d)
    assert not M.grashof_crank_rocker(0.05, 0.12, 0.05, 0.20)  # s + l > p + q: no link turns fully
    assert not M.grashof_crank_rocker(0.10, 0.12, 0.05, 0.13)  # the shortest link is the rocker
    # the closed form closes the loop, and its velocities are the derivatives of its positions
    w, h = 2.0, 1e-6
    for theta in np.linspace(0.0, 2 * np.pi, 7):
        s = M.ideal_four_bar_state(theta, w)
        pin_b = np.array([a * np.cos(theta), a * np.sin(theta)])
        pin_c = pin_b + b * np.array([np.cos(s["coupler"][2]), np.sin(s["coupler"][2])])
        assert np.linalg.norm(pin_c - [d, 0.0]) == pytest.approx(c, rel=1e-12)
        assert np.allclose(s["rocker"][:2], 0.5 * (pin_c + [d, 0.0]), atol=1e-15)
        ahead, behind = (M.ideal_four_bar_state(theta + sgn * w * h, w) for sgn in (1, -1))
        for body in ("crank", "coupler", "rocker"):
            rates = (np.array(ahead[body][:3]) - np.array(behind[body][:3])) / (2 * h)
            np.testing.assert_allclose(rates, s[body][3:], rtol=1e-6, atol=1e-8)


def test_ideal_four_bar_follows_the_closed_form_and_the_rocker_limits():
    scene = M.four_bar()
    w = M.rpm_to_rad_s(5000.0)
    t = np.linspace(0.0, 2 * np.pi / w, 721)
    run = dc.simulate(scene, t_end=float(t[-1]), rtol=1e-9, save=dc.SaveAt(times=t))
    exact = np.array([[M.ideal_four_bar_state(w * ti, w)[body][k] for body, k in
                       (("coupler", 2), ("rocker", 2), ("rocker", 5))] for ti in run.t])
    np.testing.assert_allclose(np.unwrap(run["coupler.phi"]), np.unwrap(exact[:, 0]), atol=2e-6)
    np.testing.assert_allclose(np.unwrap(run["rocker.phi"]), np.unwrap(exact[:, 1]), atol=2e-6)
    np.testing.assert_allclose(run["rocker.omega"], exact[:, 2], atol=2e-3 * w)
    # limit positions: crank and coupler collinear, the coupler pin at a + b (extended) or b - a (folded)
    a, b, c, d = M.FOUR_BAR_CRANK, M.FOUR_BAR_COUPLER, M.FOUR_BAR_ROCKER, M.FOUR_BAR_GROUND
    limits = sorted(math.pi - math.acos((c * c + d * d - r * r) / (2 * c * d)) for r in (a + b, b - a))
    psi = np.asarray(run["rocker.phi"])
    assert psi.min() == pytest.approx(limits[0], abs=1e-4) and psi.max() == pytest.approx(limits[1], abs=1e-4)


def test_four_bar_clearance_tends_to_the_ideal_mechanism():
    """Every clearance joint alone and B and C together: the rocker's angle departs from the ideal
    one by less as the clearance shrinks, in proportion (a few times c over the rocker length)."""
    t_end = 3e-3
    t = np.linspace(0.0, t_end, 301)
    ideal = dc.simulate(M.four_bar(), t_end=t_end, rtol=1e-8, save=dc.SaveAt(times=t))["rocker.phi"]
    clearances = (0.4e-3, 0.1e-3, 0.025e-3)
    for joints in (("B",), ("C",), ("D",), ("B", "C")):
        errors = []
        for clearance in clearances:
            run = dc.simulate(M.four_bar(joints, clearance=clearance), t_end=t_end, rtol=1e-8, save=dc.SaveAt(times=t))
            assert run.success
            errors.append(float(np.max(np.abs(run["rocker.phi"] - ideal))))
        assert errors[1] < 0.5 * errors[0] and errors[2] < 0.5 * errors[1], (joints, errors)
        assert errors[2] < 6 * clearances[2] / M.FOUR_BAR_ROCKER, (joints, errors)


def test_four_bar_starts_as_the_chapter_whatever_the_declared_velocities():
    """Declared at rest or with the exact ideal velocities: the same first impact (section 4.4)."""
    exact = M.four_bar(("B", "C"))
    at_rest = dc.Scene(exact.name, gravity=exact.gravity, elements=[
        dataclasses.replace(e, velocity=(0.0, 0.0), angular_velocity=0.0) if isinstance(e, dc.Body) else e
        for e in exact])
    assert at_rest != exact
    firsts = []
    for scene in (exact, at_rest):
        run = dc.simulate(scene, t_end=1e-3, rtol=1e-8)
        onset = run.events.of(kind="onset")[0]
        firsts.append((onset.pair, onset.t, onset.approach_speed, float(np.max(run["B.normal_force"]))))
    assert firsts[0][0] == firsts[1][0]
    np.testing.assert_allclose(firsts[0][1:], firsts[1][1:], rtol=1e-6)


def test_four_bar_bad_input():
    for kwargs, message in ((dict(clearance_joints=("B", "E")), "clearance_joints=.*from A, B, C, D"),
                            (dict(clearance_joints=("B", "B")), "must be distinct"),
                            (dict(clearance_joints=("B",), clearance={"C": 1e-4}), "not in clearance_joints"),
                            (dict(clearance_joints=("B", "C"), clearance={"B": 1e-4}), "none given for joint 'C'"),
                            (dict(rpm=float("nan")), "rpm=nan"),
                            (dict(joint="revolute"), "unknown option")):
        with pytest.raises(dc.SceneError, match=message):
            M.four_bar(**kwargs)
    scene = M.four_bar("B,C", clearance={"B": 0.1e-3, "C": 0.3e-3})  # as the command line's --set gives it
    assert (scene["B"].clearance, scene["C"].clearance) == (0.1e-3, 0.3e-3)


# ---------------------------------------------------------------------------------------------- double pendulum

def test_conservative_double_pendulum_keeps_its_energy():
    """Restitution 1, no friction, no driver, both pins loose: the mechanical energy dips while the
    contacts store energy (the journals hit their bearings) and the energy balance closes."""
    run = dc.simulate(M.double_pendulum(("A", "B"), restitution=1.0), t_end=0.2, rtol=1e-8,
                      options=dc.SolverOptions(track_work=True))
    assert len(run.events.of("A", kind="onset")) > 3 and len(run.events.of("B", kind="onset")) > 3
    mechanical = np.asarray(run["energy.mechanical"])
    balance = mechanical - np.asarray(run["energy.work"])
    swing = float(np.ptp(run["energy.kinetic"]))  # about 0.1 J of potential turned into motion
    assert swing > 0.05
    assert np.max(np.abs(mechanical - mechanical[0])) > 1e-5  # the contacts hold energy at times
    assert np.max(np.abs(balance - balance[0])) < 1e-6
    lossy = dc.simulate(M.double_pendulum(("A", "B"), restitution=0.5), t_end=0.2, rtol=1e-8,
                        options=dc.SolverOptions(track_work=True))
    assert lossy["energy.mechanical"][-1] < mechanical[0] - 1e-5  # the same check sees a dissipating law


def test_double_pendulum_with_tiny_clearance_follows_the_ideal_one():
    t = np.linspace(0.0, 0.3, 301)
    ideal = dc.simulate(M.double_pendulum(), t_end=0.3, rtol=1e-8, save=dc.SaveAt(times=t))
    assert abs(ideal["link2.phi"][-1]) > 1.0  # rad: the links swing through a large angle
    errors = []
    for clearance in (50e-6, 5e-6):
        run = dc.simulate(M.double_pendulum(("A", "B"), clearance=clearance), t_end=0.3, rtol=1e-8,
                          save=dc.SaveAt(times=t))
        errors.append(max(float(np.max(np.abs(run[f"link{k}.phi"] - ideal[f"link{k}.phi"]))) for k in (1, 2)))
    assert errors[1] < 0.2 * errors[0]  # about in proportion to the clearance
    assert errors[1] < 1e-3


def test_double_pendulum_bad_input():
    with pytest.raises(dc.SceneError, match="angles=\\(0.0,\\), must be two finite numbers"):
        M.double_pendulum(angles=(0.0,))
    with pytest.raises(dc.SceneError, match="clearance_joints=.*from A, B"):
        M.double_pendulum(("C",))


# ---------------------------------------------------------------------------------------------- figures, command line

def test_default_channels_and_panels_follow_the_scene():
    from daeclear.plot import clearance_joints, default_channels, plot_run

    import matplotlib.pyplot as plt

    runs = {
        "four_bar": dc.simulate(M.four_bar(("B", "C")), t_end=1e-3, rtol=1e-6),
        "pendulum": dc.simulate(M.double_pendulum(("B",)), t_end=0.01, rtol=1e-6),
        "slider_crank": dc.simulate(M.slider_crank("translational"), t_end=1e-3, rtol=1e-6),
    }
    expected = {
        "four_bar": (("drive.moment", "B.normal_force", "C.normal_force"), {"B": "RevoluteClearance",
                                                                             "C": "RevoluteClearance"}),
        "pendulum": (("link2.omega", "energy.mechanical", "B.normal_force"), {"B": "RevoluteClearance"}),
        "slider_crank": (("slider.vx", "slider.ax", "drive.moment", "clearance.normal_force"),
                         {"clearance": "TranslationalClearance"}),
    }
    for key, run in runs.items():
        channels, joints = expected[key]
        assert default_channels(run) == channels
        assert clearance_joints(run) == joints
        fig = plot_run(run)
        assert len(fig.axes) == len(channels) + len(joints)
        assert fig.axes[len(channels)].get_title() in ("B: journal orbit", "clearance: slider path")
        plt.close(fig)
    fig = plot_run(runs["four_bar"], channels=["rocker.phi", "no.such"], joints=["C"])
    assert [ax.get_ylabel().split(" ")[0] for ax in fig.axes[:1]] == ["rocker.phi"] and len(fig.axes) == 2
    plt.close(fig)
    chain = dc.simulate(M.chain(6), t_end=1e-3, rtol=1e-6)  # six clearance joints: two rows of panels
    assert default_channels(chain) == ("link6.omega", "energy.mechanical", "pin1.normal_force", "pin2.normal_force",
                                       "pin3.normal_force", "pin4.normal_force")
    fig = plot_run(chain)
    panels = fig.axes[6:]
    assert len(panels) == 6 and len({round(ax.get_position().y0, 3) for ax in panels}) == 2
    plt.close(fig)
    with pytest.raises(ValueError, match="joints=\\['A'\\] are not clearance joints.*B, C"):
        plot_run(runs["four_bar"], joints=["A"])


def test_slider_path_without_a_stroke_is_drawn_along_the_guide():
    from daeclear.plot import plot_slider_path

    import matplotlib.pyplot as plt

    scene = dc.Scene("slide", gravity=(0.0, -9.81))
    block = scene.add(dc.Body("block", mass=0.14, inertia=1e-4, position=(0.1, 0.0), velocity=(1.0, 0.0)))
    scene.add(dc.Translational("G", scene.ground, block, at=(0.1, 0.0), axis=(1.0, 0.0)))
    run = dc.simulate(scene.with_clearance("G", clearance=0.2e-3, length=0.05, width=0.05, corner_radius=1e-3,
                                           material=STEEL), t_end=0.01, rtol=1e-7)
    assert "G.xi" not in run
    ax = plot_slider_path(run, "G")
    x, y = ax.lines[0].get_data()
    np.testing.assert_allclose(x, np.asarray(run["G.s"]) * 1e3)  # mm along the guide
    assert ax.get_xlabel().startswith("s, slider centre along the guide (mm)")
    plt.close(ax.figure)


PENDULUM_ON_A_LOOSE_PIN = """
[scene]
name = "loose_pendulum"
""" + PENDULUM_LINK + """
[revolute.clearance]
clearance = 0.1e-3
bearing_radius = 0.01
material = { young = 207e9, poisson = 0.3 }

[simulate]
t_end = 0.02
"""


def test_cli_runs_scenes_without_slider_or_driver(tmp_path, capsys, monkeypatch):
    import daeclear.plot
    from daeclear.cli import main
    from daeclear.results.result import load

    references = []
    save = daeclear.plot.save_run_figure

    def recording(result, path, **options):
        references.append(options.get("reference"))
        return save(result, path, **options)

    monkeypatch.setattr(daeclear.plot, "save_run_figure", recording)

    path = tmp_path / "loose.toml"
    path.write_text(PENDULUM_ON_A_LOOSE_PIN)
    assert main(["run", str(path), "--out", str(tmp_path), "--quiet"]) == 0
    assert (tmp_path / "loose_pendulum.png").stat().st_size > 10_000
    assert load(tmp_path / "loose_pendulum.h5").events.of("A", kind="onset")  # the link fell onto its pin
    reference = references[-1]  # the scene file's ideal mechanism: the pendulum on an ideal pin
    assert reference is not None and "A.ex" not in reference and reference.t[-1] == pytest.approx(0.02)
    assert main(["run", "double_pendulum", "--set", "clearance_joints=A,B", "--t-end", "0.02", "--out",
                 str(tmp_path), "--quiet"]) == 0
    result = load(tmp_path / "double_pendulum_AB.h5")
    assert result.t[-1] == pytest.approx(0.02) and "B.ex" in result
    assert (tmp_path / "double_pendulum_AB.png").stat().st_size > 10_000
    assert references[-1].scene_name == "double_pendulum"  # the ready mechanism with ideal joints
    assert main(["run", "four_bar", "--set", "clearance_joints=C", "--out", str(tmp_path), "--quiet"]) == 0
    assert load(tmp_path / "four_bar_C.h5").t[-1] == pytest.approx(2 * 60.0 / 5000.0)  # two crank turns
    capsys.readouterr()
    assert main(["run", "four_bar", "--set", "clearance_joints=B,E", "--out", str(tmp_path), "--quiet"]) == 2
    assert "clearance_joints='B,E', must be distinct joint names from A, B, C, D" in capsys.readouterr().err


def test_four_bar_example_runs(tmp_path):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "four_bar_clearance.py"
    spec = importlib.util.spec_from_file_location("four_bar_clearance", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--out", str(tmp_path)]) == 0
    for name in ("four_bar_clearance.png", "slider_crank_two_clearances.png"):
        assert (tmp_path / name).stat().st_size > 20_000
    table = (tmp_path / "metrics.md").read_text()
    assert "four-bar, clearance at B, C, D" in table and "slider-crank, clearance at C and D" in table


def test_formulations_and_methods_agree_on_the_four_bars_first_impacts():
    """Index-1 (IDA), GGL (IDA) and DOP853 (explicit, the ODE driver) on the four-bar with clearance at
    B and C: the same first three impacts (joint, time, approach speed)."""
    scene = M.four_bar(("B", "C"))
    firsts = []
    for options in (dc.SolverOptions(formulation="index1"), dc.SolverOptions(formulation="ggl"),
                    dc.SolverOptions(method="DOP853")):
        run = dc.simulate(scene, t_end=0.6e-3, rtol=1e-8, options=options)
        assert run.success, options
        firsts.append([(e.pair, e.t, e.approach_speed) for e in run.events.of(kind="onset")[:3]])
    assert [pair for pair, _, _ in firsts[0]] == ["B", "C", "B"]
    for other in firsts[1:]:
        assert [pair for pair, _, _ in other] == ["B", "C", "B"]
        np.testing.assert_allclose([(t, v) for _, t, v in other], [(t, v) for _, t, v in firsts[0]], rtol=1e-4)


def test_cli_figure_without_reference_when_the_ideal_mechanism_cannot_run(tmp_path, capsys):
    """A bar pinned at both ends, one pin loose: it runs, but its ideal mechanism is over-constrained;
    the run still writes its result and figure, and says why the figure has no ideal reference."""
    from daeclear.cli import main

    text = PENDULUM_ON_A_LOOSE_PIN.replace("[revolute.clearance]", """[[revolute]]
name = "B"
body_i = "ground"
body_j = "link"
at = [1.0, 0.0]

[revolute.clearance]""").replace("t_end = 0.02", "t_end = 0.005")
    path = tmp_path / "redundant.toml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path), "--quiet"]) == 0
    assert (tmp_path / "loose_pendulum.png").is_file() and (tmp_path / "loose_pendulum.h5").is_file()
    assert "no ideal-mechanism reference in the figure: scene 'loose_pendulum': redundant constraints" \
        in capsys.readouterr().err


def test_one_bearing_convention_for_both_routes_to_a_clearance_at_C():
    """slider_crank("revolute") and slider_crank().with_clearance("C") put the bearing on the same
    body (the slider, the chapter's: C's body_i), so they run the same mechanism with the same
    signs of ex/ey (journal centre minus bearing centre); bearing="rod" flips them."""
    from daeclear.model.mechanisms import STEEL

    library = M.slider_crank("revolute")
    by_hand = M.slider_crank().with_clearance("C", name="clearance", bearing_radius=10e-3, clearance=0.5e-3,
                                                material=STEEL)
    flipped = M.slider_crank("revolute", bearing="rod")
    assert (library["clearance"].body_i, by_hand["clearance"].body_i, flipped["clearance"].body_i) == (
        "slider", "slider", "rod")
    t = np.linspace(0.0, 4e-3, 81)
    runs = [dc.simulate(scene, 4e-3, rtol=1e-9, save=dc.SaveAt(times=t)) for scene in (library, by_hand, flipped)]
    assert np.max(np.abs(runs[0]["clearance.ex"])) > 1e-4  # the journal moves in its play
    for channel in ("clearance.ex", "clearance.ey"):
        np.testing.assert_allclose(runs[1][channel], runs[0][channel], rtol=0, atol=1e-12)
        np.testing.assert_allclose(runs[2][channel], -runs[0][channel], rtol=0, atol=2e-6)
    with pytest.raises(dc.SceneError, match="bearing='crank', must be 'slider' or 'rod'"):
        M.slider_crank("revolute", bearing="crank")
