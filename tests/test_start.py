"""The chapter's start for any scene (section 4.4): clearance joints centred, positions and
velocities assembled on the mechanism whose clearance joints are ideal.

Checked against an independent second computation, the ready slider-crank, whose state is set
from the closed-form kinematics of the ideal mechanism: a hand-built copy of it with no velocity
guesses must start the same way and hit the same first impact.
"""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc


def hand_built(clearance_joint: str) -> dc.Scene:
    """The user guide's slider-crank, bodies declared at rest (no velocity guesses)."""
    steel = dcc.Material(young=207e9, poisson=0.3)
    scene = dc.Scene("hand_built", gravity=(0.0, -9.81))
    crank = scene.add(dc.Body("crank", mass=0.30, inertia=1.0e-4, position=(0.025, 0.0)))
    rod = scene.add(dc.Body("rod", mass=0.21, inertia=2.5e-4, position=(0.11, 0.0)))
    slider = scene.add(dc.Body("slider", mass=0.14, inertia=1.0e-4, position=(0.17, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, crank, at=(0.0, 0.0)))
    scene.add(dc.Revolute("B", crank, rod, at=(0.05, 0.0)))
    if clearance_joint == "revolute":
        scene.add(dc.RevoluteClearance("clearance", slider, rod, at=(0.17, 0.0), bearing_radius=10e-3,
                                       clearance=0.5e-3, material=steel, law=dcc.LankaraniNikravesh(restitution=0.9)))
        scene.add(dc.Translational("D", scene.ground, slider, at=(0.17, 0.0), axis=(1.0, 0.0)))
    scene.add(dc.Driver("drive", joint="A", speed=dc.mechanisms.rpm_to_rad_s(5000.0)))
    return scene


def test_hand_built_scene_starts_as_the_chapter():
    scene = hand_built("revolute")
    ready = dc.mechanisms.slider_crank("revolute")
    model, reference = dc.assemble(scene), dc.assemble(ready)
    y0, _ = model.initial_state()
    y_ref, _ = reference.initial_state()
    n = model.n_q
    np.testing.assert_allclose(y0[:2 * n], y_ref[:2 * n], rtol=0, atol=1e-9)  # positions and velocities
    assert y0[n + 4] == pytest.approx(13.09, rel=1e-3)  # rod's vy = crank speed * crank length
    first = dc.simulate(scene, t_end=0.0015, rtol=1e-8).events.of("clearance", kind="onset")[0]
    first_ref = dc.simulate(ready, t_end=0.0015, rtol=1e-8).events.of("clearance", kind="onset")[0]
    assert first.t == pytest.approx(first_ref.t, rel=1e-6)
    assert first.approach_speed == pytest.approx(first_ref.approach_speed, rel=1e-6)


def test_declared_start_keeps_the_declared_state():
    """start="declared" keeps the bodies' declared state (only the ideal joints corrected): the
    hand-built scene at rest then has a rod moving against a still slider, and a much harder
    first impact: the artificial start the chapter's start avoids."""
    scene = hand_built("revolute")
    chapter = dc.simulate(scene, t_end=0.0015, rtol=1e-8)
    declared = dc.simulate(scene, t_end=0.0015, rtol=1e-8, options=dc.SolverOptions(start="declared"))
    assert declared.parameters["simulate"]["start"] == "declared"
    peak = lambda r: float(np.max(r["clearance.normal_force"]))  # noqa: E731
    assert peak(declared) > 2.0 * peak(chapter)
    y_declared, _ = dc.assemble(scene).initial_state(start="declared")
    assert y_declared[9 + 6 + 1] == pytest.approx(0.0, abs=1e-12)  # the slider's vy stays as declared (0)


def test_a_journal_declared_off_centre_starts_centred():
    """Positions too: joints given by body-fixed points, the slider riding 0.3 mm above the crank
    axis, the rod's end declared on the axis: the journal is declared 0.3 mm off the bearing's
    centre. "ideal" starts it centred (the mechanism closes as if the joint were ideal);
    "declared" keeps the 0.3 mm."""
    steel = dcc.Material(young=207e9, poisson=0.3)
    scene = dc.Scene("off_centre")
    crank = scene.add(dc.Body("crank", mass=0.30, inertia=1.0e-4, position=(0.025, 0.0)))
    rod = scene.add(dc.Body("rod", mass=0.21, inertia=2.5e-4, position=(0.11, 0.0)))
    slider = scene.add(dc.Body("slider", mass=0.14, inertia=1.0e-4, position=(0.17, 0.3e-3)))
    scene.add(dc.Revolute("A", scene.ground, crank, at=(0.0, 0.0)))
    scene.add(dc.Revolute("B", crank, rod, at=(0.05, 0.0)))
    scene.add(dc.RevoluteClearance("clearance", slider, rod, point_i=(0.0, 0.0), point_j=(0.06, 0.0),
                                   bearing_radius=10e-3, clearance=0.5e-3, material=steel))
    scene.add(dc.Translational("D", scene.ground, slider, point_i=(0.0, 0.3e-3), point_j=(0.0, 0.0), axis=(1.0, 0.0)))
    scene.add(dc.Driver("drive", joint="A", speed=100.0))
    model = dc.assemble(scene)
    for start, offset in (("ideal", 0.0), ("declared", 0.3e-3)):
        y0, yp0 = model.initial_state(start=start)
        eccentricity = model.channels(np.zeros(1), y0[None, :], yp0[None, :])["clearance.eccentricity"][0]
        assert eccentricity == pytest.approx(offset, abs=1e-12), start


def test_start_is_validated():
    with pytest.raises(dc.SceneError, match="start='centred'"):
        dc.simulate(hand_built("revolute"), t_end=1e-3, options=dc.SolverOptions(start="centred"))


def _moving_journal() -> dc.Scene:
    scene = dc.Scene("drop", gravity=(0.0, -9.81))
    journal = scene.add(dc.Body("journal", mass=0.1, inertia=1e-5, velocity=(1.0, 0.0), angular_velocity=5.0))
    scene.add(dc.RevoluteClearance("bearing", scene.ground, journal, at=(0, 0), bearing_radius=10e-3,
                                   clearance=0.5e-3, material=dcc.Material(young=207e9, poisson=0.3),
                                   law=dcc.LankaraniNikravesh(restitution=0.9)))
    return scene


def test_a_declared_velocity_the_ideal_start_replaces_is_warned_of_and_a_free_one_kept():
    """Issue 45: a free journal declared at 1 m/s started at rest without a word. The ideal pin of the
    chapter's start fixes its centre (so the start moves it with the bearing: at rest) and says so,
    naming the option that keeps it; its spin, which the pin leaves free, is kept as declared."""
    scene = _moving_journal()
    with pytest.warns(dc.DaeclearWarning) as record:
        result = dc.simulate(scene, 1e-5)
    text = " ".join(str(w.message) for w in record)
    assert "Body 'journal': velocity=(1, 0) m/s declared, started at (0, 0) m/s" in text
    assert "start='declared'" in text and "angular_velocity" not in text
    assert result["journal.vx"][0] == 0.0 and result["journal.omega"][0] == pytest.approx(5.0, rel=1e-12)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", dc.DaeclearWarning)
        kept = dc.simulate(scene, 1e-5, options=dc.SolverOptions(start="declared"))
        dc.simulate(dc.mechanisms.slider_crank("revolute"), 1e-5)  # declared on its kinematics: nothing changed
    assert kept["journal.vx"][0] == pytest.approx(1.0, rel=1e-12)
