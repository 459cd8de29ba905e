"""benchmarks/external/exudyn_slider_crank.py without Exudyn: its contact law, written out for the
Exudyn model, against daeclear's laws (two independent codings of (3.5), (3.9) and (3.16)), its
interpolated approach speed, its start against the ideal mechanism's, and the skip when exudyn is
absent (the comparison itself needs the optional package: docs/validation.md)."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import pytest

import daeclear.contact as dcc
from daeclear.model.mechanisms import ideal_slider_crank_state

PATH = Path(__file__).resolve().parent.parent / "benchmarks" / "external" / "exudyn_slider_crank.py"


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("exudyn_slider_crank", PATH)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclass looks its module up while the class is made
    spec.loader.exec_module(module)
    return module


def test_contact_law_matches_daeclears_lankarani_nikravesh_and_modified_coulomb():
    script = _script()
    law = dcc.LankaraniNikravesh(restitution=0.9).resolve(
        "internal_cylinder", radii=(10.0e-3, 9.5e-3), materials=dcc.Material(young=207e9, poisson=0.3))
    assert script.STIFFNESS == pytest.approx(6.610e10, rel=1e-3)
    assert script.STIFFNESS == pytest.approx(law.stiffness, rel=1e-12)
    for delta, rate, approach in ((1e-6, 0.3, 1.0), (2e-5, -0.8, 1.2), (5e-5, -2.0, 0.5), (1e-5, 0.1, 1e-6)):
        assert script.normal_force(delta, rate, approach) == pytest.approx(float(law.force(delta, rate, approach)),
                                                                           rel=1e-12), (delta, rate, approach)
    assert script.normal_force(-1e-6, 1.0, 1.0) == 0.0
    friction = dcc.ModifiedCoulomb(coefficient=1.0)
    for slip in (5e-5, 1.5e-4, -1.5e-4, 3e-4, -2.0):
        expected = math.copysign(float(friction.correction(slip)), slip)  # c_d(|v_T|) sign(v_T)
        assert script.friction_factor(slip) == pytest.approx(expected, abs=1e-15), slip


def test_approach_speed_is_interpolated_at_the_crossing_and_latched():
    contact = _script().Contact(friction=0.0)
    contact.next_step((0.49e-3, 0.0), (0.5, 0.0))  # free: delta = -10 um, rate 0.5 m/s
    assert contact.approach is None and contact.start == pytest.approx((-10e-6, 0.5))
    # a trial state 30 um deep at 0.9 m/s: delta = 0 a quarter of the way, rate 0.5 + 0.4 / 4
    assert contact.onset_rate(30e-6, 0.9) == pytest.approx(0.6, rel=1e-12)
    contact.next_step((0.53e-3, 0.0), (0.9, 0.0))
    assert contact.approach == pytest.approx(0.6, rel=1e-12)
    contact.next_step((0.54e-3, 0.0), (-0.2, 0.0))  # still in contact: the latch holds
    assert contact.approach == pytest.approx(0.6, rel=1e-12)
    contact.next_step((0.0, 0.45e-3), (0.0, -1.0))  # free again
    assert contact.approach is None


def test_start_is_the_ideal_mechanism_at_crank_angle_zero():
    script = _script()
    ideal = ideal_slider_crank_state(0.0, script.OMEGA)
    for body, (pose, speed) in script.ideal_start().items():
        x, y, phi, vx, vy, w = ideal[body]
        assert pose == pytest.approx((x, y, phi), abs=1e-15) and speed == pytest.approx((vx, vy, w), abs=1e-12), body


def test_skips_with_a_message_when_exudyn_is_absent(capsys):
    script = _script()
    script.exu = None
    assert script.main(["--quick"]) == 0
    assert "pip install" in capsys.readouterr().out


def test_install_flag_says_when_the_install_fails(capsys, monkeypatch):
    """--install tries pip (here: a failed install, no network in tests) and skips with a message."""
    script = _script()
    script.exu = None
    monkeypatch.setattr(script, "install_exudyn", lambda: False)
    assert script.main(["--quick", "--install"]) == 0
    assert "failed" in capsys.readouterr().out
