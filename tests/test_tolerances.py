"""Tolerances per quantity from the mechanism's scales, the round-off floor, and tight rtol (issue 30).

GGL used to fail at tight rtol (the chapter's revolute scene at rtol 1e-10 and 1e-11, an ideal
four-bar from 1e-10): its Newton iteration puts positions and velocities on the constraint manifold,
so their corrections never fall below the round-off of the constraint equations, and the old
uniform atol (1e-3 * rtol) asked for less than that of the near-zero components. Each absolute
tolerance now has a floor of ROUNDOFF_FACTOR * eps times its quantity's scale.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import DaeclearWarning, SceneError
from daeclear.solvers import tolerances as tol
from daeclear.solvers.ida import steps_needed

REV = 60.0 / 5000.0


def _bench_convergence():
    """benchmarks/bench_convergence.py as a module: its five-link pendulum is the ideal scene here too."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "bench_convergence.py"
    spec = importlib.util.spec_from_file_location("bench_convergence", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def pendulum() -> dc.Scene:
    """The ideal five-link pendulum of bench_convergence.py (0.1 m links along +X, released from rest)."""
    return _bench_convergence().pendulum()


# ---------------------------------------------------------------- scales and defaults


def test_scales_of_the_chapter_slider_crank():
    """L = 0.17 m (the slider's pin), W = 5000 rpm, l = min(6e-3 L, 2 c) = 1 mm (c = 0.5 mm)."""
    s = tol.scales(dc.assemble(dc.mechanisms.slider_crank("revolute")))
    assert s.length == pytest.approx(0.17)
    assert s.rate == pytest.approx(5000 * 2 * math.pi / 60)
    assert s.resolution == pytest.approx(1e-3)
    atol = s.default_atol(1e-6)
    # the 1e-3 * rtol of earlier releases in m, rad and m/s; 5000 rpm * 1e-5 in rad/s
    assert atol["position"] == pytest.approx(1e-9, rel=1e-6, abs=0.0)
    assert atol["angle"] == pytest.approx(1e-9, rel=1e-6, abs=0.0)
    assert atol["velocity"] == pytest.approx(1e-6 * 1e-5 * 0.17 * 523.5987755982989, rel=1e-6, abs=0.0)
    assert atol["angular_velocity"] == pytest.approx(1e-6 * 1e-5 * 523.5987755982989, rel=1e-6, abs=0.0)


def test_scales_follow_the_mechanism():
    """A pendulum of 5 links of 0.1 m at rest: L = 0.45 m (the last centre), W = sqrt(g / L); a smaller
    clearance sets l."""
    s = tol.scales(dc.assemble(pendulum()))
    assert s.length == pytest.approx(0.45) and s.rate == pytest.approx(math.sqrt(9.81 / 0.45))
    assert s.resolution == pytest.approx(6e-3 * 0.45)
    tight = tol.scales(dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=1e-5)))
    assert tight.resolution == pytest.approx(2e-5)  # twice the clearance: the journal's travel
    # a body at the origin with no joint points: its radius of gyration, not a fallback
    scene = dc.Scene("disc", gravity=(0.0, 0.0))
    scene.add(dc.Body("disc", mass=2.0, inertia=0.02, angular_velocity=3.0))
    disc = tol.scales(dc.assemble(scene))
    assert disc.length == pytest.approx(0.1) and disc.rate == pytest.approx(3.0)
    # at rest, no gravity, a torque: the speed after one radian at the start's acceleration, sqrt(T / I)
    scene = dc.Scene("spun", gravity=(0.0, 0.0))
    scene.add(dc.Body("disc", mass=2.0, inertia=0.02))
    scene.add(dc.Torque("drive", "disc", 0.5))
    assert tol.scales(dc.assemble(scene)).rate == pytest.approx(math.sqrt(0.5 / 0.02))


def test_defaults_are_never_below_round_off():
    s = tol.scales(dc.assemble(dc.mechanisms.slider_crank("revolute")))
    floor = s.roundoff()
    assert floor["velocity"] == pytest.approx(tol.ROUNDOFF_FACTOR * np.finfo(float).eps * 0.17 * 523.6, rel=1e-4,
                                             abs=0.0)
    atol = s.default_atol(1e-14)
    assert all(atol[q] == floor[q] for q in tol.QUANTITIES)
    loose = s.default_atol(1e-3)
    assert all(loose[q] > floor[q] for q in tol.QUANTITIES)


def test_round_off_floors_scale_with_the_mechanism():
    """docs/engine.md, Tolerances: each floor is 300 eps (IDA's Newton) or 10 eps (the ODE methods)
    times its quantity's scale: L for positions (m), 1 for angles, L W for velocities, W for angular
    velocities. The chapter's slider-crank: L = 0.17 m, W = 5000 rpm; the five-link pendulum: L =
    0.45 m, W = sqrt(g / L). A given atol below them is raised to them, position states included."""
    eps = np.finfo(float).eps
    crank, swing = dc.assemble(dc.mechanisms.slider_crank("revolute")), dc.assemble(pendulum())
    for model, L, W in ((crank, 0.17, 5000 * 2 * math.pi / 60), (swing, 0.45, math.sqrt(9.81 / 0.45))):
        for newton, factor in ((True, 300.0), (False, 10.0)):
            floor = tol.scales(model).roundoff(newton)
            expected = {"position": factor * eps * L, "angle": factor * eps, "velocity": factor * eps * L * W,
                        "angular_velocity": factor * eps * W}
            assert floor == pytest.approx(expected, rel=1e-9, abs=0.0)  # (approx's default abs 1e-12 is above them)
        with pytest.warns(DaeclearWarning, match=f"position to {300 * eps * L:.2g} m"):
            vec = tol.tolerance_vector(model, 1e-6, 1e-30)
        names = model.state_names
        assert vec[names.index("rod.x" if model is crank else "link5.y")] == pytest.approx(300 * eps * L, rel=1e-9,
                                                                                       abs=0.0)


def test_the_tolerance_vector_per_state():
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    defaults = tol.scales(model).default_atol(1e-8)
    vec = tol.tolerance_vector(model, 1e-8, None)
    names = model.state_names
    assert vec[names.index("rod.x")] == defaults["position"] and vec[names.index("rod.phi")] == defaults["angle"]
    assert vec[names.index("rod.vy")] == defaults["velocity"]
    assert vec[names.index("rod.omega")] == defaults["angular_velocity"]
    multipliers = [i for i, k in enumerate(model.state_kinds) if k == "lambda"]
    assert np.all(vec[multipliers] >= tol.MULTIPLIER_ATOL_FLOOR)


# ---------------------------------------------------------------- the forms of atol


def test_atol_as_a_mapping_by_quantity_or_group():
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    names = model.state_names
    vec = tol.tolerance_vector(model, 1e-6, {"q": 1e-8, "angular_velocity": 1e-4})
    assert vec[names.index("slider.x")] == 1e-8 and vec[names.index("slider.phi")] == 1e-8
    assert vec[names.index("crank.omega")] == 1e-4
    assert vec[names.index("crank.vx")] == tol.scales(model).default_atol(1e-6)["velocity"]  # default kept


def test_an_atol_array_never_puts_the_multipliers_into_the_error_test():
    """atol=np.full(n_states, 1e-8) used to put the multipliers in the error test and failed at t = 0."""
    scene = dc.mechanisms.slider_crank("revolute")
    model = dc.assemble(scene)
    vec = tol.tolerance_vector(model, 1e-6, np.full(model.n_states, 1e-8))
    multipliers = [i for i, k in enumerate(model.state_kinds) if k == "lambda"]
    assert np.all(vec[multipliers] >= tol.MULTIPLIER_ATOL_FLOOR) and np.all(vec[:2 * model.n_q] == 1e-8)
    short = tol.tolerance_vector(model, 1e-6, np.full(2 * model.n_q, 1e-8))
    assert np.array_equal(short, vec)
    result = dc.simulate(scene, 0.002, atol=np.full(model.n_states, 1e-8))
    assert result.success and result.events


def test_atol_round_trips_through_solver_options_and_records():
    options = dc.SolverOptions(atol={"q": 1e-9, "v": 1e-6})
    assert options.atol_value() == {"position": 1e-9, "angle": 1e-9, "velocity": 1e-6, "angular_velocity": 1e-6}
    assert dc.SolverOptions.from_dict(options.to_dict()) == options
    assert options.replace(rtol=1e-8).atol_value() == options.atol_value()
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.001, options=options)
    assert result.parameters["simulate"]["atol"]["velocity"] == 1e-6


@pytest.mark.parametrize("atol, names", [
    ({"lambda": 1.0}, ["atol key='lambda'", "multipliers are always out of the error test"]),
    ({"q": -1.0}, ["atol['q']=-1.0", "> 0"]),
    ({"q": 1e-9, "position": 1e-9}, ["'position' is given twice"]),
    ({"v": float("nan")}, ["atol['v']=nan"]),
    ("tight", ["atol='tight'"]),
    ([1e-9, 1e-9, 1e-9], ["atol=array of shape (3,)", "18 values", "32 (one per state)"]),
])
def test_a_bad_atol_names_the_field_and_the_value(atol, names):
    with pytest.raises(SceneError) as info:
        dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.001, atol=atol)
    assert isinstance(info.value, ValueError)
    for text in names:
        assert text in str(info.value)


def test_an_atol_below_round_off_is_raised_with_a_warning():
    scene = dc.mechanisms.slider_crank("revolute")
    with pytest.warns(DaeclearWarning, match="atol below round-off raised .*velocity to 5.9e-12 m/s"):
        result = dc.simulate(scene, 0.001, atol=1e-20)
    assert result.success
    assert result.parameters["simulate"]["atol"] == 1e-20  # what was asked is recorded


# ---------------------------------------------------------------- tight rtol finishes


@pytest.mark.parametrize("rtol", [1e-9, 1e-10, 1e-11])
@pytest.mark.parametrize("scene", ["revolute, no gravity", "revolute", "translational"])
def test_the_chapter_scenes_finish_at_tight_rtol(scene, rtol):
    """Two crank revolutions with the default settings (GGL): rtol 1e-10 and 1e-11 used to fail."""
    joint = scene.split(",")[0]
    gravity = 0.0 if "no gravity" in scene else 9.81
    result = dc.simulate(dc.mechanisms.slider_crank(joint, gravity=gravity), 2 * REV, rtol=rtol,
                         save=dc.SaveAt(times=np.linspace(0, 2 * REV, 201)))
    assert result.success and result.t[-1] == 2 * REV
    assert len(result.events.of(kind="onset")) > 10
    assert np.all(np.isfinite(result.y))


@pytest.mark.parametrize("formulation", ["ggl", "index1"])
@pytest.mark.parametrize("rtol", [1e-10, 1e-12])
def test_ideal_mechanisms_finish_at_tight_rtol(formulation, rtol):
    """The ideal four-bar failed from rtol 1e-10 (GGL) and at 1e-12 (index1); the pendulum at 1e-12."""
    four_bar = dc.simulate(dc.mechanisms.four_bar(), 0.1, rtol=rtol, options=dc.SolverOptions(formulation=formulation))
    chain = dc.simulate(pendulum(), 1.0, rtol=rtol, options=dc.SolverOptions(formulation=formulation),
                        save=dc.SaveAt(times=np.linspace(0, 1, 101)))
    assert four_bar.success and chain.success
    assert np.max(np.abs(chain["energy.mechanical"] - chain["energy.mechanical"][0])) < 1e-6


def test_without_the_floor_ggl_collapses_and_the_advice_makes_the_run_finish(monkeypatch):
    """The root cause, shown: with the old uniform atol (1e-3 * rtol) and no round-off floor, GGL fails
    its Newton iteration in contact (the step collapsing to 1e-22 s); the message's advice
    (formulation='index1') makes the same case finish, and so does the floor. (Three revolutions at
    rtol 3e-10: since the contact automaton's same-instant guard spans 2**20 ulps and restarts IDA,
    two at rtol 1e-10 finish without the floor too; three fail at 3e-10 and 3e-11 alike.)"""
    scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
    old = {q: 1e-13 for q in tol.QUANTITIES}
    monkeypatch.setattr(tol, "ROUNDOFF_FACTOR", 0.0)
    failed = dc.simulate(scene, 3 * REV, rtol=3e-10, atol=old, on_failure="return")
    assert not failed.success and "IDA_CONV_FAIL" in failed.message and "in contact" in failed.message
    assert failed.message.endswith("Try formulation='index1'.")
    advised = dc.simulate(scene, 3 * REV, rtol=3e-10, atol=old, options=dc.SolverOptions(formulation="index1"))
    assert advised.success
    monkeypatch.undo()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DaeclearWarning)  # the atol raised to the floor
        floored = dc.simulate(scene, 3 * REV, rtol=3e-10, atol=old)
    assert floored.success


def test_the_step_cap_advice_is_enough_to_finish():
    """A run that hits max_steps is told a cap that lets it finish; the cap it names does."""
    scene = dc.mechanisms.slider_crank("revolute")
    capped = dc.simulate(scene, REV, on_failure="return", options=dc.SolverOptions(max_steps=800))
    assert not capped.success and "DC_MAX_STEPS" in capped.message
    cap = int(capped.message.split("raise max_steps to about ")[1].split(" ")[0])
    assert cap == steps_needed(800, 0.0, capped.t[-1], REV) and cap > 800
    assert f"--max-steps {cap}" in capped.message
    assert dc.simulate(scene, REV, options=dc.SolverOptions(max_steps=cap)).success


def test_steps_needed_rounds_up_on_two_digits():
    assert steps_needed(1000, 0.0, 0.5, 1.0) == 3000
    assert steps_needed(2000, 0.0, 0.00780662, 0.012) == 4700  # 4611 up to two digits
    assert steps_needed(10, 1.0, 1.5, 2.0) == 30


def test_the_sticking_advice_makes_the_run_finish():
    """Plain Coulomb sticking fails with the advice to use modified Coulomb; with it the run finishes."""
    import daeclear.contact as dcc

    failed = dc.simulate(dc.mechanisms.slider_crank("revolute", friction=dcc.Coulomb(coefficient=0.5)), 0.024,
                         on_failure="return")
    assert not failed.success and "modified Coulomb law (friction=<coefficient>" in failed.message
    assert dc.simulate(dc.mechanisms.slider_crank("revolute", friction=0.5), 0.024).success


def test_a_comparison_the_default_abs_would_widen_is_refused():
    """tests/conftest.py: pytest.approx(5.9e-12, rel=1e-4) would pass anything within 1e-12 (17 %): refused;
    with abs= given, or values the default abs does not widen, it compares as pytest's."""
    with pytest.raises(ValueError, match="default abs=1e-12 makes this comparison up to 0.17 relative"):
        pytest.approx(5.9e-12, rel=1e-4)
    assert 5.9e-12 == pytest.approx(5.9e-12, rel=1e-4, abs=0.0) and 6.5e-12 != pytest.approx(5.9e-12, rel=1e-4, abs=0)
    assert 1.0 == pytest.approx(1.0) and 1e-3 == pytest.approx(1e-3, rel=1e-6) and 0.0 == pytest.approx(0.0)
    assert {"a": 1e-9} == pytest.approx({"a": 1e-9}, rel=1e-3)  # 1e-12 / 1e-9 = 1e-3: not widened
