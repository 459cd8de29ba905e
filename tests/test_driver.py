"""The one run driver (daeclear/solvers/driver.py, issue 42 item 2): every event passes through its jump with
the states around it; the method names come from one table; a scheme of the user's gets the events;
sessions and advances are typed in solvers/."""

from __future__ import annotations

import ast
import math
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import scipy.integrate

import daeclear as dc
import daeclear.contact as dcc
from daeclear.core import methods, options
from daeclear.core.errors import SceneError
from daeclear.engine.c_session import CSession
from daeclear.engine.python_session import PythonSession
from daeclear.engine.session_base import Session
from daeclear.model.clearance_joints import RevoluteClearance
from daeclear.solvers import driver, explicit
from daeclear.solvers.base import step_rule
from daeclear.solvers.explicit import ODESolver
from daeclear.solvers.integrator import Jump
from daeclear.solvers.registry import SOLVERS, solver_class

SOLVERS_DIR = Path(__file__).resolve().parents[1] / "daeclear" / "solvers"

# Issue 43's radial impact: a free journal (m = 1 kg) from the bearing's centre at u = 1 m/s along x,
# radial clearance z0 = 0.1 m, Kelvin-Voigt K = 1e4 N/m, D = 20 N s/m, no gravity.
MASS, SPEED, Z0, K, D = 1.0, 1.0, 0.1, 1e4, 20.0


def radial_impact() -> dc.Scene:
    scene = dc.Scene("radial impact", gravity=(0.0, 0.0))
    journal = scene.add(dc.Body("journal", mass=MASS, inertia=1e-3, velocity=(SPEED, 0.0)))
    scene.add(RevoluteClearance("bearing", scene.ground, journal, at=(0, 0), bearing_radius=1.0, clearance=Z0,
                                law=dcc.KelvinVoigt(stiffness=K, damping=D)))
    return scene


def jumps_of(method: str, **settings) -> tuple[dc.Result, list[Jump]]:
    """A run of the radial impact through the driver, with every Jump it made."""
    seen: list[Jump] = []
    options_ = dc.SolverOptions(method=method, rtol=1e-10, start="declared", formulation="index1", **settings)
    save = dc.SaveAt().plan(0.0, 0.25)
    result = driver.run(solver_class(options_.method)(), radial_impact(), 0.25, 0.0, None, save, options_,
                        "raise", False, observers=[seen.append])
    return result, seen


@pytest.mark.parametrize("method, settings", [("RK45", {}), ("ida", {"backend": "python"}), ("ida", {"backend": "c"})],
                         ids=["RK45", "ida-python", "ida-c"])
def test_every_event_passes_through_the_jump_with_the_states_around_it(method, settings):
    """Kelvin-Voigt's force jumps to D u at onset (t* = z0 / u): the journal's acceleration jumps by
    -D u / m there, positions and velocities do not; at separation the force is already zero (clamped),
    so nothing jumps. The compiled loop decides this pair itself: its jumps carry the event's state only."""
    result, seen = jumps_of(method, **settings)
    assert [e.t for j in seen for e in j.events] == list(result.events.t)
    assert [(e.pair, e.kind) for j in seen for e in j.events] == [("bearing", "onset"), ("bearing", "separation")]
    onset, separation = seen
    assert onset.t == pytest.approx(Z0 / SPEED, rel=1e-9)
    assert separation.t == pytest.approx(0.1315607532, rel=1e-8)  # issue 43's closed form
    x = result.state_names.index("journal.x")
    vx = result.state_names.index("journal.vx")
    if settings.get("backend") == "c":  # decided in C: the state at the event, nothing more
        assert onset.by_integrator and onset.y_plus is None and onset.yp_minus is None and onset.state is None
        assert onset.y_minus[x] == pytest.approx(Z0, rel=1e-9)
        return
    assert not onset.by_integrator and onset.restarted and separation.restarted
    for j in seen:
        assert np.array_equal(j.y_plus[:2 * 3], j.y_minus[:2 * 3])  # q and v kept (index-1: no projection)
        assert j.found is not None and j.found[0] == (1 if j is onset else -1)
    assert onset.y_minus[x] == pytest.approx(Z0, rel=1e-9) and onset.y_minus[vx] == pytest.approx(SPEED, rel=1e-9)
    assert onset.yp_minus[vx] == 0.0  # free flight (yp's vx row is the acceleration)
    assert onset.yp_plus[x] == onset.yp_minus[x] == onset.y_minus[vx]
    # the new mode's acceleration at y+, by the law's formula inside the contact: -max(K delta + D delta', 0) / m
    # for delta >= 0 (at delta = 0 the limit from inside: the jump D delta', not the law's 0 out of contact)
    delta, rate = onset.y_plus[x] - Z0, onset.y_plus[vx]
    assert onset.yp_plus[vx] == pytest.approx(-max(K * delta + D * rate, 0.0) / MASS if delta >= 0 else 0.0,
                                              rel=1e-9, abs=1e-12)
    if method == "RK45":  # its restart lies past the root (delta > 0)
        assert delta > 0
    else:  # IDA's root state: the gap closed to round-off (here exactly)
        assert abs(delta) < 1e-15
    assert onset.yp_plus[vx] == pytest.approx(-D * SPEED / MASS, rel=1e-9)  # the jump of the force, D u
    assert separation.yp_plus[vx] == pytest.approx(separation.yp_minus[vx], abs=1e-9) == 0.0
    pair = onset.state[0][0]  # the run's contact state after the onset: in contact, the approach speed latched
    assert pair.contact and pair.latched == pytest.approx(SPEED, rel=1e-9)


def test_a_scheme_of_the_users_gets_the_events_recording_and_checks():
    """A subclass of ODESolver naming a scipy OdeSolver daeclear does not register (RK23) is integrated by
    the driver: the radial impact's events at their closed-form times, and a run is checked and streamed."""

    class RK23(ODESolver):
        name: ClassVar[str] = "RK23"
        scheme: ClassVar[type] = scipy.integrate.RK23
        order: ClassVar[int] = 3

    result = dc.simulate(radial_impact(), 0.25, method=RK23, rtol=1e-10, options=dc.SolverOptions(start="declared"))
    assert result.success and result.method == "RK23"
    assert result.events.t == pytest.approx([Z0 / SPEED, 0.1315607532], rel=1e-8)
    x = result.state_names.index("journal.x")
    assert result.y[-1, x] == pytest.approx(0.0118717966, rel=1e-7)  # issue 43's x(T)
    assert set(np.unique(result.step_order)) == {3}

    class NotAScheme(ODESolver):
        name: ClassVar[str] = "not-a-scheme"
        scheme: ClassVar[type] = dict

    with pytest.raises(SceneError, match=r"simulate: NotAScheme.scheme=<class 'dict'>, must be a subclass of "
                                         r"scipy.integrate.OdeSolver"):
        dc.SolverOptions(method=NotAScheme)


def test_every_list_of_method_names_comes_from_the_one_table():
    keys = tuple(m.key for m in methods.TABLE)
    assert options.METHODS == keys == tuple(SOLVERS)
    for m in methods.TABLE:
        cls = SOLVERS[m.key]
        assert cls.__name__ == m.class_name and cls.name == m.name and cls.formulation == m.formulation
        assert options.default_formulation(m.key) == m.formulation
        if m.family != "ida":
            assert getattr(explicit, m.class_name) is cls and cls.order == m.order and cls.jacobian == m.jacobian
            assert cls.fixed_step == (m.family == "fixed")
    fixed = tuple(m.key for m in methods.TABLE if m.family == "fixed")
    assert methods.FIXED_STEP == fixed == dc.studies.accuracy.FIXED_STEP_METHODS
    with pytest.raises(SceneError) as info:
        step_rule("ida", 1e-5, fixed=False)
    assert f"({', '.join(repr(k) for k in fixed)})" in str(info.value)
    with pytest.raises(TypeError):
        SOLVERS["ida"] = SOLVERS["rk4"]  # type: ignore[index]  # the registry is not a table to patch


def test_both_sessions_have_every_member_the_protocol_declares():
    members = {name for name in vars(Session) if not name.startswith("_")} | set(Session.__annotations__)
    assert members == {"backend", "max_steps", "eval_from", "reinit", "advance", "roots", "eval_extra", "stats",
                       "set_hints", "set_stall", "set_layout", "set_kinematic_rows", "set_newton_tolerances",
                       "set_auto_events", "pair_states", "report", "close"}
    for cls in (CSession, PythonSession):
        assert all(hasattr(cls, name) for name in members), cls


def test_no_session_or_advance_is_typed_any_in_the_solvers():
    """Every parameter, attribute or variable named like a session or an advance in solvers/ has a type."""
    named = {"session", "adv", "advance", "integrator"}
    loose = []
    for path in sorted(SOLVERS_DIR.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.arg) and node.arg in named:
                annotation = node.annotation
            elif isinstance(node, ast.AnnAssign) and ast.unparse(node.target).split(".")[-1] in named:
                annotation = node.annotation
            else:
                continue
            if annotation is None or "Any" in ast.unparse(annotation):
                loose.append(f"{path.name}:{node.lineno}")
    assert not loose


def test_a_stuck_event_loop_fails_with_what_it_did(monkeypatch):
    """STALL_EVENTS restarts at one time: the run stops with its events and the driver's message."""
    monkeypatch.setattr(driver, "STALL_EVENTS", 1)
    result = dc.simulate(radial_impact(), 0.25, method="RK45", on_failure="return",
                         options=dc.SolverOptions(start="declared"))
    assert not result.success and len(result.events) == 1 and math.isclose(result.t[-1], Z0 / SPEED, rel_tol=1e-6)
    assert result.message.startswith("RK45 failed at t=0.1 s with 'bearing' in contact: 1 events at the same time")


def test_ctrl_c_inside_a_scipy_step_keeps_the_steps_before_it(monkeypatch):
    """A KeyboardInterrupt from the right-hand side in the middle of an advance (after 150 of the run's 374
    evaluations, some 20 of its 57 steps, fewer than an advance's SCIPY_CHUNK): the partial result holds the
    steps before it, each equal to the whole run's, and the caller is stopped (Interrupted)."""
    from daeclear.core.errors import Interrupted
    from daeclear.solvers import ode_evaluators, ode_integrators

    scene = dc.mechanisms.slider_crank("ideal", gravity=0.0)
    whole = dc.simulate(scene, 0.012, method="RK45", rtol=1e-8)
    calls = [0]
    original = ode_evaluators._CEvaluator.rhs

    def rhs(self, t, x):
        calls[0] += 1
        if calls[0] == 150:
            raise KeyboardInterrupt
        return original(self, t, x)

    monkeypatch.setattr(ode_evaluators._CEvaluator, "rhs", rhs)
    with pytest.raises(Interrupted) as info:
        dc.simulate(scene, 0.012, method="RK45", rtol=1e-8, options=dc.SolverOptions(backend="c"))
    partial = info.value.result
    k = partial.n_times
    assert 5 < k < ode_integrators.SCIPY_CHUNK and k < whole.n_times and "interrupted by the user" in partial.message
    assert np.array_equal(partial.t, whole.t[:k]) and np.array_equal(partial.y, whole.y[:k])


def test_a_run_without_checks_leaves_out_a_successful_runs_warnings_alone():
    """``checks=False`` (the wear study's blocks): the 50 000 rpm slider-crank, whose journal goes 0.64 mm
    into a 0.5 mm clearance, has no penetration record and no warning, and the same states as the checked
    run (which has both); a run that fails is still checked, for its message."""
    import warnings

    scene = dc.mechanisms.slider_crank("revolute", rpm=50000)
    settings = dc.SolverOptions()
    ida = solver_class("ida")()
    with pytest.warns(dc.PhysicsWarning, match="'clearance' penetrates"):
        checked = driver.run(ida, scene, 0.0024, 0.0, None, dc.SaveAt().plan(0.0, 0.0024), settings, "raise", False)
    assert [w["kind"] for w in checked.warnings] == ["penetration"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning fails the test
        quiet = driver.run(ida, scene, 0.0024, 0.0, None, dc.SaveAt().plan(0.0, 0.0024), settings, "raise", False,
                           checks=False)
    assert quiet.success and quiet.warnings == [] and "max_constraint_drift" not in quiet.stats
    np.testing.assert_array_equal(quiet.t, checked.t)
    np.testing.assert_array_equal(quiet.y, checked.y)
    stopped = dc.SolverOptions(max_steps=50)
    failed = driver.run(ida, scene, 0.0024, 0.0, None, dc.SaveAt().plan(0.0, 0.0024), stopped, "return", False,
                        checks=False)
    assert not failed.success and "max_constraint_drift" in failed.stats  # the checks ran (they set it)
