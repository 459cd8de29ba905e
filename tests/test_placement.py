"""daeclear.place: a scene placed at chosen joint coordinates (issue 34, item 2).

Checked against closed-form kinematics (the slider-crank's crank and rod angles, a double
pendulum given in relative angles), against the scene the mechanism library builds at the same
crank angle, and for the same equations (the parameter vector) as the scene it came from.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import daeclear as dc
from daeclear.core.errors import AssemblyError, SceneError
from daeclear.model.mechanisms import CRANK_LENGTH as R, ROD_LENGTH as L, ideal_slider_crank_state, rpm_to_rad_s

OMEGA = rpm_to_rad_s(5000.0)


def _poses(scene: dc.Scene) -> dict[str, tuple[float, ...]]:
    return {b.name: (*b.position, b.angle, *b.velocity, b.angular_velocity) for b in scene.bodies}


def test_slider_crank_placed_at_a_crank_angle_is_the_closed_form():
    placed = dc.place(dc.mechanisms.slider_crank(), start={"A": 0.7})
    expected = ideal_slider_crank_state(0.7, OMEGA)
    for name, pose in _poses(placed).items():
        np.testing.assert_allclose(pose[:3], expected[name][:3], rtol=0, atol=1e-13)
        # no speeds: the declared velocities corrected to the joints and the driver's speed
        np.testing.assert_allclose(pose[3:], expected[name][3:], rtol=0, atol=1e-11 * OMEGA)
    # the driver starts from the new coordinate: the run is the library's at crank_angle=0.7
    t = np.linspace(0.0, 2e-3, 21)
    a = dc.simulate(placed, 2e-3, rtol=1e-9, save=dc.SaveAt(times=t))
    b = dc.simulate(dc.mechanisms.slider_crank(crank_angle=0.7), 2e-3, rtol=1e-9, save=dc.SaveAt(times=t))
    np.testing.assert_allclose(a["slider.x"], b["slider.x"], rtol=0, atol=1e-10)
    np.testing.assert_allclose(a["A.angle"], 0.7 + OMEGA * t, rtol=0, atol=1e-9)


def test_speeds_give_the_closed_form_velocities():
    free = dc.mechanisms.slider_crank().without("drive")
    placed = dc.place(free, start={"A": 0.7}, speeds={"A": OMEGA})
    expected = ideal_slider_crank_state(0.7, OMEGA)
    for name, pose in _poses(placed).items():
        np.testing.assert_allclose(pose, expected[name], rtol=0, atol=1e-10 * OMEGA)


def test_a_translational_coordinate_places_the_crank():
    """The slider's displacement along D chosen: the crank angle solves x(theta) = 0.16 m on the
    declared branch (crank above the axis)."""
    placed = dc.place(dc.mechanisms.slider_crank(crank_angle=0.5).without("drive"), start={"D": 0.16})
    theta = brentq(lambda a: R * math.cos(a) + math.sqrt(L**2 - (R * math.sin(a))**2) - 0.16, 0.0, math.pi,
                   xtol=1e-15, rtol=4 * np.finfo(float).eps)
    expected = ideal_slider_crank_state(theta, 0.0)
    for name, pose in _poses(placed).items():
        np.testing.assert_allclose(pose[:3], expected[name][:3], rtol=0, atol=1e-12)


def test_double_pendulum_in_relative_angles():
    """Pin A: link1 from the ground, pin B: link2 relative to link1 (the drawing's angles)."""
    a, b, wa, wb = -1.2, 0.5, 1.0, -2.0
    placed = dc.place(dc.mechanisms.double_pendulum(), start={"A": a, "B": b}, speeds={"A": wa, "B": wb})
    length = 0.1
    u1, u2 = np.array([math.cos(a), math.sin(a)]), np.array([math.cos(a + b), math.sin(a + b)])
    p1, p2 = 0.5 * length * u1, length * u1 + 0.5 * length * u2
    perp1, perp2 = np.array([-u1[1], u1[0]]), np.array([-u2[1], u2[0]])
    v1 = 0.5 * length * wa * perp1
    v2 = length * wa * perp1 + 0.5 * length * (wa + wb) * perp2
    poses = _poses(placed)
    np.testing.assert_allclose(poses["link1"], (*p1, a, *v1, wa), rtol=0, atol=1e-13)
    np.testing.assert_allclose(poses["link2"], (*p2, a + b, *v2, wa + wb), rtol=0, atol=1e-13)
    result = dc.simulate(placed, 1e-3, rtol=1e-9, options=dc.SolverOptions(start="declared"))
    assert result["A.angle"][0] == pytest.approx(a, abs=1e-12) and result["B.angle"][0] == pytest.approx(b, abs=1e-12)
    assert result["B.rate"][0] == pytest.approx(wb, abs=1e-9)


def test_clearance_joints_close_as_ideal_and_the_equations_are_kept():
    """World points, a free length and a free angle left None are read in the declared pose and
    kept: the placed scene has the same parameter vector but for the driver's start angle."""
    scene = dc.mechanisms.slider_crank("revolute")
    scene.add(dc.Force("push", "rod", fx=2.0, at=(0.1, 0.01)))
    scene.add(dc.SpringDamper("spring", "ground", "slider", at_i=(0.3, 0.0), at_j=(0.17, 0.0), stiffness=100.0))
    scene.add(dc.RotationalSpringDamper("torsion", "crank", "rod", stiffness=0.5))
    placed = dc.place(scene, start={"A": 0.7})
    expected = ideal_slider_crank_state(0.7, OMEGA)
    for name, pose in _poses(placed).items():
        np.testing.assert_allclose(pose[:3], expected[name][:3], rtol=0, atol=1e-13)
    before, after = dc.assemble(scene), dc.assemble(placed)
    assert before.parameter_layout == after.parameter_layout
    for name, _ in before.parameter_layout:  # the compiled table's entries, derived ones included
        if name != "drive.angle0":
            np.testing.assert_allclose(after.parameter(name), before.parameter(name), rtol=1e-13, atol=1e-15,
                                       err_msg=name)
    assert after.parameter("drive.angle0")[0] == pytest.approx(0.7, abs=1e-14)
    run = dc.simulate(placed, 1e-4, rtol=1e-8, options=dc.SolverOptions(start="declared"))
    assert run["clearance.eccentricity"][0] < 1e-12  # journal centred: the ideal joint closed


def test_coordinates_that_do_not_fix_the_configuration_are_refused():
    with pytest.raises(AssemblyError, match=r"do not fix the configuration.*1 degree\(s\) of freedom.*A, B, C, D"):
        dc.place(dc.mechanisms.slider_crank().without("drive"))
    with pytest.raises(AssemblyError, match=r"speeds.*do not fix.*1 degree"):
        dc.place(dc.mechanisms.double_pendulum(), start={"A": 0.1, "B": 0.2}, speeds={"A": 1.0})


def test_a_loop_that_cannot_close_reports_the_residual_and_the_joints():
    """The driver holds A at 0 (the slider at its outer dead centre): the rod cannot also turn by
    1 rad relative to the crank."""
    with pytest.raises(AssemblyError, match=r"cannot all close.*largest residuals are .* = .*\(joints "):
        dc.place(dc.mechanisms.slider_crank(), start={"B": 1.0})


@pytest.mark.parametrize("start, speeds, shown", [
    ({"X": 1.0}, None, "start names 'X', must be a revolute or translational joint of the scene (A, B, C, D)"),
    ({"A": math.nan}, None, "start['A']=nan, must be a finite number"),
    ([0.5], None, "start=[0.5], must be a mapping"),
    (None, {"A": 1.0}, "speeds['A']=1.0, but joint 'A' is driven by Driver 'drive'"),
])
def test_bad_arguments_name_the_field(start, speeds, shown):
    with pytest.raises(SceneError) as info:
        dc.place(dc.mechanisms.slider_crank(), start=start, speeds=speeds)
    assert shown in str(info.value)


def test_a_driver_with_an_initial_angle_and_a_start_value_conflict():
    scene = dc.mechanisms.slider_crank().without("drive")
    scene.add(dc.Driver("drive", joint="A", speed=OMEGA, initial_angle=0.2))
    with pytest.raises(SceneError, match=r"start\['A'\]=0.5, but Driver 'drive' fixes"):
        dc.place(scene, start={"A": 0.5})


def _andrews():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "andrews_squeezer.py"
    spec = importlib.util.spec_from_file_location("andrews_squeezer", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("formulation", ["ggl", "index1"])
def test_andrews_squeezer_starts_at_and_reaches_the_published_values(tmp_path, capsys, formulation):
    """The seven-body mechanism built from its drawing (body-fixed points, one relative angle in
    start) starts at the IVP Test Set's initial angles and reaches its reference at t = 0.03 s, with
    either formulation (GGL failed at rtol 1e-9 and 1e-10 before the mechanism's rate included
    what its drive torque and spring do at rest: issue 30)."""
    andrews = _andrews()
    scene = andrews.andrews_squeezer()
    initial = (andrews.BETA0, 0.0, 0.455279819163070380255912382449, 0.222668390165885884674473185609,
               0.487364979543842550225598953530, -0.222668390165885884674473185609, 1.23054744454982119249735015568)
    result = dc.simulate(scene, andrews.T_END, rtol=1e-10,
                         options=dc.SolverOptions(formulation=formulation, start="declared"))
    # docs/validation.md's table at rtol 1e-10: 1.2e-8 rad (GGL), 9.3e-8 rad (index1), within a factor of 2
    largest = {"ggl": 2 * 1.2e-8, "index1": 2 * 9.3e-8}[formulation]
    for joint, start, end in zip(andrews.COORDINATES, initial, andrews.REFERENCE):
        assert result[f"{joint}.angle"][0] == pytest.approx(start, abs=1e-12), joint
        assert result[f"{joint}.angle"][-1] == pytest.approx(end, rel=0, abs=largest), joint
    assert andrews.main([str(tmp_path / "a.png"), "--quick"]) == 0 and (tmp_path / "a.png").exists()


def test_car_axis_built_as_a_mechanism_reaches_the_test_set_reference():
    """benchmarks/external/car_axis.py: the start given as joint coordinates and rates is the
    test set's initial state, and the run reaches its reference at t = 3 to more than 5 digits
    at rtol 1e-8 (5.8 measured; 9 at rtol 1e-12: docs/validation.md)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "external" / "car_axis.py"
    spec = importlib.util.spec_from_file_location("car_axis", path)
    car_axis = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(car_axis)
    scene = car_axis.car_axis_scene()
    start = [(*scene[b].position, *scene[b].velocity) for b in ("left_wheel", "axle")]
    np.testing.assert_allclose(start, [(0.0, 0.5, -0.5, 0.0), (1.0, 0.5, -0.5, 0.0)], rtol=0, atol=1e-14)
    assert car_axis.digits(car_axis.daeclear_state(scene, 1e-8)) > 5.0


def test_contradictory_speeds_are_refused_with_what_the_mechanism_allows():
    """Issue 45: two speeds for a one-degree-of-freedom four-bar were fitted by least squares (A started at
    -2.03 rad/s, B at 3.01, neither value) without a word; now refused, both joints and values named."""
    free = dc.mechanisms.four_bar().without("drive")
    with pytest.raises(AssemblyError) as info:
        dc.place(free, start={"A": 0.5}, speeds={"A": 1.0, "B": 5.0})
    text = str(info.value)
    assert "speeds={'A': 1.0, 'B': 5.0} contradict the joints" in text and "1 degree(s) of freedom" in text
    assert "(1 given)" in text and "(5 given)" in text and "A.rate = " in text and "B.rate = " in text
    # the same two speeds when they agree with the kinematics: accepted, and both held
    placed = dc.place(free, start={"A": 0.5}, speeds={"A": 1.0})
    b_rate = dc.simulate(placed, 1e-5, options=dc.SolverOptions(start="declared"))["B.rate"][0]
    again = dc.place(free, start={"A": 0.5}, speeds={"A": 1.0, "B": b_rate})
    run = dc.simulate(again, 1e-5, options=dc.SolverOptions(start="declared"))
    assert run["A.rate"][0] == pytest.approx(1.0, abs=1e-9) and run["B.rate"][0] == pytest.approx(b_rate, abs=1e-9)


@pytest.mark.parametrize("displacement", [0.075, 0.12, 0.16, 0.169])
def test_a_start_from_a_dead_centre_declaration_finds_the_configuration(displacement):
    """Issue 45: the ready slider-crank is declared at its outer dead centre (crank along the rod), where the
    slider's displacement does not move to first order: Newton from there failed for every reachable
    displacement. Continuation from a first guess finds the closed form (crank above the axis)."""
    placed = dc.place(dc.mechanisms.slider_crank().without("drive"), start={"D": displacement})
    theta = brentq(lambda a: R * math.cos(a) + math.sqrt(L**2 - (R * math.sin(a))**2) - displacement, 0.0, math.pi,
                   xtol=1e-15, rtol=4 * np.finfo(float).eps)
    expected = ideal_slider_crank_state(theta, 0.0)
    for name, pose in _poses(placed).items():
        np.testing.assert_allclose(pose[:3], expected[name][:3], rtol=0, atol=1e-12)


def test_an_unreachable_start_from_a_dead_centre_names_the_singular_joint():
    with pytest.raises(AssemblyError) as info:
        dc.place(dc.mechanisms.slider_crank().without("drive"), start={"D": 0.2})  # beyond R + L = 0.17 m
    text = str(info.value)
    assert "cannot all close" in text and "6 first guesses" in text
    assert "D (displacement) is at a singular configuration" in text
