"""Scene validation: every problem named with element, field, value and rule."""

import math

import pytest

import daeclear as dc
from daeclear.core.errors import AssemblyError, SceneError


def pendulum_scene(**body_kw):
    scene = dc.Scene("pendulum")
    kw = dict(mass=1.0, inertia=0.01, position=(0.5, 0.0))
    kw.update(body_kw)
    link = scene.add(dc.Body("link", **kw))
    scene.add(dc.Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    return scene


def test_valid_scene_passes():
    pendulum_scene().validate()


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("mass", -1.0, r"Body 'link': mass=-1.0 kg, must be a finite number > 0"),
        ("mass", 0.0, r"mass=0.0 kg"),
        ("inertia", math.nan, r"inertia=nan kg m\^2"),
        ("position", (1.0,), r"position=\(1.0,\) m, must be two finite numbers"),
        ("angle", "up", r"angle='up' rad"),
    ],
)
def test_bad_body_fields(field, value, match):
    with pytest.raises(SceneError, match=match):
        pendulum_scene(**{field: value}).validate()


def test_unknown_body_name_suggests_close_match():
    scene = pendulum_scene()
    scene.add(dc.Revolute("B", "lnk", scene.ground, at=(1.0, 0.0)))
    with pytest.raises(SceneError, match=r"Revolute 'B': body_i refers to body 'lnk', not in scene 'pendulum'. "
                                         r"Did you mean 'link'\?"):
        scene.validate()


def test_duplicate_names_and_all_problems_at_once():
    scene = pendulum_scene(mass=-2.0)
    scene.add(dc.Body("link", mass=1.0, inertia=1.0))
    scene.add(dc.Driver("motor", joint="E", speed=1.0))
    with pytest.raises(SceneError) as info:
        scene.validate()
    text = str(info.value)
    assert "has 3 problems" in text
    assert "duplicate name" in text
    assert "mass=-2.0 kg" in text
    assert "Driver 'motor': joint='E' is not a revolute or translational joint of this scene" in text


def test_joint_needs_location_and_two_bodies():
    scene = pendulum_scene()
    scene.add(dc.Revolute("B", "link", "link"))
    with pytest.raises(SceneError) as info:
        scene.validate()
    assert "joins body 'link' to itself" in str(info.value)
    assert "give the world point at=(x, y)" in str(info.value)


def test_ground_name_reserved_and_bad_translational_axis():
    scene = dc.Scene("s")
    scene.add(dc.Body("ground", mass=1.0, inertia=1.0))
    scene.add(dc.Translational("T", "ground", "ground", at=(0, 0), axis=(0.0, 0.0)))
    with pytest.raises(SceneError) as info:
        scene.validate()
    assert "reserved for the fixed ground" in str(info.value)
    assert "axis=(0.0, 0.0), must be a non-zero 2-vector" in str(info.value)


def test_add_rejects_non_elements_and_lookup_suggests():
    scene = pendulum_scene()
    with pytest.raises(SceneError, match="cannot add"):
        scene.add("link")
    with pytest.raises(KeyError, match="Did you mean 'link'"):
        scene["lnk"]


def test_joint_points_that_cannot_close_fail_assembly():
    # a two-link chain whose far end must sit on a line it cannot reach
    scene = dc.Scene("unreachable", gravity=(0.0, 0.0))
    a = scene.add(dc.Body("a", mass=1.0, inertia=0.1, position=(0.5, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, a, point_i=(0.0, 0.0), point_j=(-0.5, 0.0)))
    # the tip of 'a' (1 m from the pivot) pinned to a ground point 3 m away
    scene.add(dc.Revolute("B", a, scene.ground, point_i=(0.5, 0.0), point_j=(3.0, 0.0)))
    model = dc.assemble(scene)
    with pytest.raises(AssemblyError, match="cannot assemble the initial positions.*'B.x'"):
        model.initial_state()


def test_bad_formulation_and_mechanism_options():
    with pytest.raises(SceneError, match="formulation='index3', must be one of index1, ggl"):
        dc.assemble(pendulum_scene(), "index3")
    with pytest.raises(SceneError, match="joint='cam'"):
        dc.mechanisms.slider_crank("cam")
    with pytest.raises(SceneError, match="gravity=-1"):
        dc.mechanisms.slider_crank(gravity=-1)
    with pytest.raises(SceneError, match="unknown option"):
        dc.mechanisms.slider_crank(clearence=1e-3)


def test_without_returns_a_new_scene_without_the_named_elements():
    scene = dc.mechanisms.slider_crank("revolute")
    free = scene.without("drive", "D")
    assert [e.name for e in free] == [e.name for e in scene if e.name not in ("drive", "D")]
    assert scene["drive"] is not None and scene["D"] is not None  # unchanged
    assert free.name == scene.name and free.gravity == scene.gravity
    with pytest.raises(KeyError, match="no element 'driev'.*'drive'"):
        scene.without("driev")


def test_a_clearance_joint_resolves_its_laws_once():
    """resolved_law() of a frozen clearance joint is computed at the first call and kept; a joint
    with other numbers (dataclasses.replace) resolves its own; equality, to_dict and pickling see
    the fields only."""
    import dataclasses
    import pickle

    scene = dc.mechanisms.slider_crank("revolute", clearance=0.5e-3)
    joint = next(e for e in scene.elements if e.name == "clearance")
    law = joint.resolved_law()
    assert joint.resolved_law() is law and joint.resolved_friction() is joint.resolved_friction()
    tighter = dataclasses.replace(joint, clearance=0.1e-3)
    assert tighter.resolved_law() is not law
    assert tighter.resolved_law().stiffness != law.stiffness  # the journal radius enters the stiffness
    assert tighter.resolved_law() == dataclasses.replace(joint, clearance=0.1e-3).resolved_law()
    fresh = dataclasses.replace(joint)
    assert fresh == joint and fresh.to_dict() == joint.to_dict() and "_computed_resolved_law" not in vars(fresh)
    assert pickle.loads(pickle.dumps(joint)).resolved_law() == law
