"""New numbers without a new structure: Scene.with_values, DAEModel.with_parameters and
simulate(..., parameters=...) (issue 35, item 1).

Each check compares with an independent second computation: the scene built with the same numbers
by the mechanism library (or by Scene.with_values), assembled on its own."""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
from daeclear.contact import ModifiedCoulomb
from daeclear.core.errors import SceneError

T_END = 0.004  # two impacts' worth of the Fig. 4.15 scene at c = 0.5 mm


@pytest.fixture(scope="module")
def scene():
    return dc.mechanisms.slider_crank("revolute")


def test_scene_with_values_replaces_and_derives(scene):
    new = scene.with_values({"clearance.clearance": 2e-4, "clearance.law.restitution": 0.5, "crank.mass": 0.4,
                             "gravity": (0.0, 0.0)})
    joint = new["clearance"]
    assert joint.clearance == 2e-4 and joint.law.restitution == 0.5 and new["crank"].mass == 0.4
    assert new.gravity == (0.0, 0.0)
    assert joint.journal == pytest.approx(joint.bearing_radius - 2e-4, abs=1e-15)  # derived follows
    assert scene["clearance"].clearance == 5e-4 and scene["crank"].mass == 0.3  # the old scene unchanged
    assert [e.name for e in new] == [e.name for e in scene]


@pytest.mark.parametrize("values, words", [
    ({"clerance.clearance": 1e-4}, ["'clerance.clearance'", "Did you mean 'clearance'"]),
    ({"clearance.radius": 1e-4}, ["RevoluteClearance has no field 'radius'", "bearing_radius"]),
    ({"clearance.law.stiff": 1e9}, ["LankaraniNikravesh has no field 'stiff'", "stiffness"]),
    ({"crank": 1.0}, ["'crank' is an element", "mass"]),
    ({"clearance.clearance": -1e-4}, ["clearance=-0.0001", "> 0"]),
    ({"crank.mass": float("nan")}, ["mass=nan"]),
])
def test_scene_with_values_bad_names_and_values(scene, values, words):
    with pytest.raises(SceneError) as info:
        scene.with_values(values)
    for word in words:
        assert word in str(info.value)


def test_model_with_parameters_equals_the_assembled_scene(scene):
    model = dc.assemble(scene)
    values = {"clearance.clearance": 2e-4, "clearance.law.restitution": 0.5, "drive.speed": 300.0}
    new = model.with_parameters(values)
    built = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=2e-4, restitution=0.5,
                                                   rpm=300.0 * 60 / (2 * np.pi)))
    assert new.parameter_layout == built.parameter_layout
    np.testing.assert_allclose(new.parameter_values, built.parameter_values, rtol=1e-14, atol=0)
    # what the model derives from the numbers: stiffness from the new radii, the physics checks' limit
    assert new.parameter("clearance.law.stiffness")[0] != model.parameter("clearance.law.stiffness")[0]
    assert new.clearance_joints == (("clearance", 2e-4, 0.0),)
    assert new.structure is model.structure and new.functions is model.functions  # nothing rebuilt
    assert model.parameter("clearance.clearance")[0] == 5e-4  # the model is a value: unchanged
    mutable = dc.mechanisms.slider_crank("revolute")
    held = dc.assemble(mutable)
    mutable.elements.clear()  # the caller's scene changes afterwards: the model's copy does not
    assert held.with_parameters({"crank.mass": 0.4}).parameter("crank.mass")[0] == 0.4
    for name in ("clearance", "drive"):  # (the bodies' declared velocities follow rpm, not the driver alone)
        assert new.parameters["scene"]["elements"][name] == built.parameters["scene"]["elements"][name]


def test_with_parameters_refuses_a_change_of_structure(scene):
    model = dc.assemble(scene)
    with pytest.raises(SceneError, match="change the structure"):
        model.with_parameters({"clearance.friction": ModifiedCoulomb(coefficient=0.1)})


def test_baumgarte_parameters_of_index1_only(scene):
    index1 = dc.assemble(scene, "index1")
    new = index1.with_parameters({"baumgarte.alpha": 10.0})
    assert (new.alpha, new.beta) == (10.0, 5.0) and new.parameter("baumgarte.alpha")[0] == 10.0
    with pytest.raises(SceneError, match="index1"):
        dc.assemble(scene).with_parameters({"baumgarte.alpha": 10.0})
    with pytest.raises(SceneError, match="alpha=-1"):
        index1.with_parameters({"baumgarte.alpha": -1.0})


def test_simulate_with_parameters_is_the_run_of_the_changed_scene(scene):
    values = {"clearance.clearance": 2e-4, "clearance.law.restitution": 0.6}
    given = dc.simulate(scene, T_END, parameters=values)
    built = dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=2e-4, restitution=0.6), T_END)
    assert given.n_times == built.n_times and len(given.events) == len(built.events) > 0
    np.testing.assert_array_equal(given.t, built.t)
    np.testing.assert_array_equal(given.y, built.y)
    assert given.parameters["scene"]["elements"] == built.parameters["scene"]["elements"]
    model = dc.assemble(scene)
    again = dc.simulate(model, T_END, parameters=values)  # a model: its own formulation
    np.testing.assert_array_equal(again.y, built.y)


def test_simulate_parameters_checked_before_any_work(scene):
    with pytest.raises(ValueError, match="parameters"):
        dc.simulate(scene, T_END, parameters=[("clearance.clearance", 1e-4)])
    with pytest.raises(SceneError, match="no field 'clearnce'"):
        dc.simulate(scene, T_END, parameters={"clearance.clearnce": 1e-4})
