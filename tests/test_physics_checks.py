"""Physically impossible results are warned of (Result.warnings, the HDF5 file, PhysicsWarning, the CLI);
redundant constraints are found when the run is set up; a long t_end is no stall; scene files and
truncated sweep files get messages that name the place and the way out.

Numbers measured on the chapter's slider-crank (clearance 0.5 mm, corner radius 1 mm) are in
docs/reliability.md.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

import daeclear as dc
import daeclear.solvers.ode_integrators as integrators
import daeclear.solvers.ida as solve
from daeclear.assembly import physics
from daeclear.cli import main
from daeclear.core.errors import AssemblyError, DaeclearError, PhysicsWarning, SceneError
from daeclear.model.scene import GROUND
from daeclear.model.scenefile import read_scene_file
from daeclear.assembly.symbolic import Reference
from scene_texts import PENDULUM_LINK

CLEARANCE = 0.5e-3


def kinds(result: dc.Result) -> dict[str, dict]:
    """The result's warnings by kind (each kind at most once a joint in these scenes)."""
    return {w["kind"]: w for w in result.warnings}


def quiet_simulate(scene, t_end, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        return dc.simulate(scene, t_end, **kw)


def replace_element(scene: dc.Scene, name: str, **changes) -> dc.Scene:
    k = next(i for i, e in enumerate(scene.elements) if getattr(e, "name", None) == name)
    scene.elements[k] = dataclasses.replace(scene.elements[k], **changes)
    return scene


# ---------------------------------------------------------------- item 5: warnings


def test_penetration_beyond_the_clearance_at_50000_rpm():
    """At 50 000 rpm the journal goes 0.64 mm into a bearing with 0.5 mm clearance: success, but warned."""
    scene = dc.mechanisms.slider_crank("revolute", rpm=50000)
    with pytest.warns(PhysicsWarning, match="'clearance' penetrates .* more than the clearance") as caught:
        result = dc.simulate(scene, 0.0024)
    assert result.success
    # the warning points at the line that called simulate, not inside the package
    assert {w.filename for w in caught if w.category is PhysicsWarning} == {__file__}
    w = kinds(result)["penetration"]
    assert w["quantity"] == "penetration" and w["unit"] == "m" and w["where"] == "clearance"
    assert w["limit"] == pytest.approx(CLEARANCE)
    assert w["value"] == pytest.approx(6.38e-4, rel=0.05)
    i = int(np.argmax(result["clearance.penetration"]))
    assert w["t"] == pytest.approx(result.t[i]) and w["value"] == pytest.approx(result["clearance.penetration"][i])
    assert 3e-5 < w["t"] < 6e-5


def test_chapter_run_has_no_penetration_warning():
    result = quiet_simulate(dc.mechanisms.slider_crank("revolute"), 0.024)
    assert result.success and "penetration" not in kinds(result)
    assert np.max(result["clearance.penetration"]) < 0.2 * CLEARANCE  # 78 um measured


def test_heavy_friction_on_the_translational_joint_penetrates_beyond_the_corner():
    """Friction 0.5 on the guide: a corner 1.2 mm deep, more than the clearance (0.5 mm) and the corner
    radius (1 mm); the warning names the corner pair and the time."""
    scene = dc.mechanisms.slider_crank("translational", friction=0.5)
    result = quiet_simulate(scene, 0.024)
    assert result.success
    w = kinds(result)["penetration"]
    assert w["where"] == "clearance.D_lower"
    assert w["limit"] == pytest.approx(CLEARANCE)  # the smaller of clearance and corner radius
    assert w["value"] == pytest.approx(1.2e-3, rel=0.05) and w["value"] > 1e-3
    assert w["t"] == pytest.approx(0.00966, abs=5e-4)
    assert w["value"] == pytest.approx(np.max(result["clearance.D_lower.penetration"]))


def test_constraint_drift_is_one_of_the_warnings():
    """The drift warning (above 1e-3 of the smallest clearance) is a record like the others."""
    with pytest.warns(PhysicsWarning, match="constraints drifted"):
        result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.024,
                             options=dc.SolverOptions(formulation="index1"))
    w = kinds(result)["constraint_drift"]
    assert w["value"] == result.stats["max_constraint_drift"] and w["limit"] == pytest.approx(1e-3 * CLEARANCE)
    assert w["where"].split(".")[0] in ("A", "B", "D", "drive")  # a constraint equation of an ideal joint
    i = int(np.argmax(result["constraints.position"]))
    assert w["t"] == pytest.approx(result.t[i])
    exact = quiet_simulate(dc.mechanisms.slider_crank("revolute"), 0.024, options=dc.SolverOptions(formulation="ggl"))
    assert "constraint_drift" not in kinds(exact)


def test_fixed_step_run_that_steps_through_a_contact():
    """rk4 at 4e-5 s: contacts of 30 us are crossed in one step (then the run blows up)."""
    scene = dc.mechanisms.slider_crank("revolute")
    result = quiet_simulate(scene, 0.024, on_failure="return", options=dc.SolverOptions(method="rk4", step=4e-5))
    w = kinds(result)["contact_within_one_step"]
    assert w["where"] == "clearance" and w["unit"] == "s" and w["limit"] == 4e-5
    assert w["value"] < 4e-5
    onset = [e.t for e in result.events if e.kind == "onset"]
    assert any(t == pytest.approx(w["t"]) for t in onset)
    fine = quiet_simulate(scene, 0.024, options=dc.SolverOptions(method="rk4", step=1e-5))
    assert fine.success and "contact_within_one_step" not in kinds(fine)


def test_fixed_step_gap_sign_change_without_an_event(monkeypatch):
    """A crossing the event search misses (here: made to miss) leaves a gap that changed sign between two
    steps with no event: warned as a missed contact, with the step's times."""
    monkeypatch.setattr(integrators, "locate", lambda *args, **kw: None)
    scene = dc.mechanisms.slider_crank("revolute")
    result = quiet_simulate(scene, 0.004, on_failure="return", options=dc.SolverOptions(method="rk4", step=1e-5))
    assert not result.events
    w = kinds(result)["missed_contact"]
    assert w["where"] == "clearance" and w["value"] >= 1
    p = result["clearance.penetration"]
    k = int(np.argmax(p > 0))  # the first step that ends inside the wall
    assert w["t"] == pytest.approx(result.t[k - 1]) and p[k - 1] < 0 < p[k]
    assert "penetration" in kinds(result)  # and then it goes through the wall


def journal_inside_the_wall(offset: float = 0.7e-3) -> dc.Scene:
    """The chapter's revolute clearance joint with the journal declared 0.7 mm off the bearing centre."""
    scene = dc.mechanisms.slider_crank("revolute")
    joint = next(e for e in scene.elements if e.name == "clearance")
    s_i, s_j = Reference(scene.bodies, GROUND).joint_points(joint)
    return replace_element(scene, "clearance", at=None, point_i=tuple(s_i), point_j=(s_j[0] + offset, s_j[1]))


def test_journal_that_starts_inside_the_bearing_wall():
    """0.2 mm deep (40 % of the clearance) is refused by default (tests/test_drivers.py); allowed, it runs and warns."""
    result = quiet_simulate(journal_inside_the_wall(), 0.002,
                            options=dc.SolverOptions(start="declared", allow_penetration=True))
    w = kinds(result)["initial_penetration"]
    assert w["where"] == "clearance" and w["t"] == 0.0
    assert w["value"] == pytest.approx(0.2e-3, rel=1e-6) and w["limit"] == pytest.approx(1e-2 * CLEARANCE)
    # the default start centres the journal: nothing to warn of
    assert "initial_penetration" not in kinds(quiet_simulate(journal_inside_the_wall(), 0.002))


def test_velocities_inconsistent_with_the_joint():
    """The slider declared at rest while the rod's end moves at 26 m/s: a 26 m/s artificial first impact."""
    scene = replace_element(dc.mechanisms.slider_crank("revolute", crank_angle=math.pi / 2), "slider",
                            velocity=(0.0, 0.0))
    result = quiet_simulate(scene, 0.002, options=dc.SolverOptions(start="declared"))
    w = kinds(result)["initial_velocity"]
    assert w["where"] == "clearance" and w["t"] == 0.0 and w["unit"] == "m/s"
    assert w["value"] == pytest.approx(26.18, rel=1e-3)
    assert result.events[0].approach_speed == pytest.approx(26.0, rel=0.01)
    assert "initial_velocity" not in kinds(quiet_simulate(scene, 0.002))  # start="ideal"
    declared = quiet_simulate(dc.mechanisms.slider_crank("revolute"), 0.002, options=dc.SolverOptions(start="declared"))
    assert not {"initial_velocity", "initial_penetration"} & set(kinds(declared))


def test_a_restart_from_a_computed_state_may_start_in_contact():
    """A restart from a run's own state (twin runs, analysis.restart_state) is not a declaration."""
    from daeclear.studies.analysis import restart_state

    model = dc.assemble(journal_inside_the_wall())
    declared = quiet_simulate(model, 0.002, options=dc.SolverOptions(start="declared", allow_penetration=True),
                              save=dc.SaveAt(times=np.linspace(0.0, 0.002, 21)))
    assert "initial_penetration" in kinds(declared)
    start = restart_state(model, declared, 0)
    again = quiet_simulate(model, 0.002, t0=start.t0, y0=start.y0)
    assert again["clearance.penetration"][0] == pytest.approx(0.2e-3, rel=1e-6)
    assert not {"initial_penetration", "initial_velocity"} & set(kinds(again))


def test_an_undriven_drop_is_an_experiment_not_an_inconsistent_start():
    """Without a driver a journal thrown across its bearing is the run's initial condition: no warning."""
    scene = dc.Scene("drop", gravity=(0.0, -9.81))
    link = scene.add(dc.Body("link", mass=1.0, inertia=0.01, position=(0.0, -0.1), velocity=(0.0, -0.2)))
    scene.add(dc.RevoluteClearance("pin", scene.ground, link, at=(0.0, 0.0), bearing_radius=0.01,
                                   clearance=CLEARANCE, material=dc.mechanisms.STEEL))
    result = quiet_simulate(scene, 0.01, options=dc.SolverOptions(start="declared"))
    assert result.events and "initial_velocity" not in kinds(result)


def test_warnings_are_saved_and_loaded(tmp_path: Path):
    result = quiet_simulate(dc.mechanisms.slider_crank("revolute", rpm=50000), 0.0024,
                            options=dc.SolverOptions(formulation="index1"))
    assert result.warnings
    again = dc.load(result.save(tmp_path / "run.h5"))
    assert again.warnings == result.warnings
    kinds = list(dict.fromkeys(w["kind"] for w in result.warnings))
    assert "penetration" in kinds and f"warnings: {len(result.warnings)} ({', '.join(kinds)})" in repr(again)
    # a file written before warnings existed: no warnings
    with h5py.File(tmp_path / "run.h5", "r+") as f:
        del f["warnings_json"]
    assert dc.load(tmp_path / "run.h5").warnings == []
    assert result.slice(0.0, 1e-3).warnings == result.warnings


def test_cli_run_shows_the_warnings(tmp_path: Path, capsys):
    code = main(["run", "slider_crank", "--joint", "revolute", "--set", "rpm=50000", "--out", str(tmp_path),
                 "--quiet"])
    assert code == 0
    err = capsys.readouterr().err
    assert "daeclear: warning: penetration: 'clearance' penetrates" in err
    assert err.count("penetrates") == 1  # once, from the result, not again as a Python warning
    saved = dc.load(tmp_path / "slider_crank_revolute.h5")
    assert kinds(saved)["penetration"]["where"] == "clearance"


def test_failure_advice_fits_a_penetration_beyond_the_joint():
    """Friction 10 on the guide: IDA fails after a 7 cm penetration; the advice is not "tighter rtol"."""
    result = quiet_simulate(dc.mechanisms.slider_crank("translational", friction=10.0), 0.024, on_failure="return")
    assert not result.success
    assert "penetrated" in result.message and "tolerances will not fix that" in result.message
    assert kinds(result)["penetration"]["value"] > 0.01
    assert "defect" not in result.message  # the deep corner is past the guide's end: free by the gap IDA watches


def test_failure_message_calls_a_pair_deep_in_its_wall_while_free_a_solver_defect(monkeypatch):
    """A lost onset (the automaton made to ignore every onset after the first separation, as the
    same-instant guard once did for one corner of the Siconos slider-crank): a corner goes 9 cm into
    its wall with no force and IDA fails at its step cap. The message says the solver lost the onset,
    not that the joint carries too much load."""
    from daeclear.assembly import contact_pairs
    from daeclear.core import automaton

    seen: list[int] = []

    def lossy(state, t, direction, rate, **kw):
        new, decision = automaton.step(state, t, direction, rate, **kw)
        if decision.kind == automaton.ONSET and seen:
            return state, automaton.decision_of(state, automaton.NONE)
        if decision.kind == automaton.SEPARATION:
            seen.append(1)
        return new, decision

    monkeypatch.setattr(contact_pairs, "step", lossy)  # the corners' decisions: PairLogic.decide
    model = dc.assemble(dc.mechanisms.slider_crank("translational"), "index1")
    result = quiet_simulate(model, 0.02, rtol=1e-8, on_failure="return",
                            options=dc.SolverOptions(backend="python", max_steps=800))
    assert not result.success and "DC_MAX_STEPS" in result.message and seen
    deep = kinds(result)["penetration"]
    assert deep["value"] > 0.01 and result[f"{deep['where']}.in_contact"][result.t == deep["t"]].max() == 0.0
    assert f"'{deep['where']}' was {deep['value']:.3g} m inside its wall" in result.message
    assert "while free" in result.message and "a defect of daeclear" in result.message
    assert "load the joint cannot carry" in result.message and "tolerances will not fix" not in result.message


# ---------------------------------------------------------------- item 6: redundant constraints


def four_bar(extra_revolute: bool = False, second_driver: bool = False) -> dc.Scene:
    """A crank-rocker four-bar pinned at O, A, B, D and driven at O."""
    scene = dc.Scene("four_bar")
    a, b, d = (0.1, 0.0), (0.25, 0.15), (0.3, 0.0)
    crank = scene.add(dc.Body("crank", mass=1.0, inertia=0.01, position=(0.05, 0.0)))
    coupler = scene.add(dc.Body("coupler", mass=1.0, inertia=0.01, position=(0.175, 0.075)))
    rocker = scene.add(dc.Body("rocker", mass=1.0, inertia=0.01, position=(0.275, 0.075)))
    scene.add(dc.Revolute("O", scene.ground, crank, at=(0.0, 0.0)))
    scene.add(dc.Revolute("A", crank, coupler, at=a))
    scene.add(dc.Revolute("B", coupler, rocker, at=b))
    scene.add(dc.Revolute("D", rocker, scene.ground, at=d))
    if extra_revolute:
        scene.add(dc.Revolute("E", coupler, scene.ground, at=(0.175, 0.075)))
    scene.add(dc.Driver("drive", joint="O", speed=10.0))
    if second_driver:
        scene.add(dc.Driver("drive_D", joint="D", speed=5.0))
    return scene


def test_four_bar_runs():
    assert dc.simulate(four_bar(), 0.1).success


@pytest.mark.parametrize("method", ["ida", "rk4"])
def test_four_bar_with_an_extra_revolute_is_redundant(method):
    with pytest.raises(AssemblyError, match="redundant constraints") as info:
        dc.simulate(four_bar(extra_revolute=True), 0.1,
                    options=dc.SolverOptions(method=method, step=1e-4 if method == "rk4" else None))
    text = str(info.value)
    assert "'E'" in text and "Removing any one of 'O', 'A', 'E'" in text
    assert "rank 9 for 11 equations on 9 coordinates" in text
    assert "IDA" not in text and "rtol" not in text  # no integrator advice


def test_two_drivers_for_one_degree_of_freedom_are_redundant():
    with pytest.raises(AssemblyError, match="'drive', 'drive_D'") as info:
        dc.simulate(four_bar(second_driver=True), 0.1)
    assert "rank 9 for 10 equations" in str(info.value)


def test_two_drivers_on_one_joint_are_refused_by_the_scene():
    scene = four_bar()
    scene.add(dc.Driver("drive2", joint="O", speed=10.0))
    with pytest.raises(SceneError, match="Driver 'drive2': joint 'O' already has a driver"):
        dc.assemble(scene)


# ---------------------------------------------------------------- item 6: long runs are no stall


def test_stall_threshold_does_not_scale_with_t_end(monkeypatch):
    seen: list[tuple[float, int]] = []
    real = solve.open_session

    def spy(*args, **kw):
        session = real(*args, **kw)
        original = session.set_stall
        session.set_stall = lambda step, count: (seen.append((step, count)), original(step, count))[1]
        return session

    monkeypatch.setattr(solve, "open_session", spy)
    scene = dc.mechanisms.slider_crank("ideal")
    dc.simulate(scene, 0.01, save=dc.SaveAt(steps=False, times=[0.0, 0.01]))
    # the setting only
    dc.simulate(scene, 1.0, on_failure="return", options=dc.SolverOptions(max_steps=200),
                save=dc.SaveAt(steps=False, times=[0.0, 1.0]))
    assert seen[0] == seen[1] == (solve.STALL_STEP, solve.STALL_COUNT)


def test_long_smooth_run_is_not_a_stall():
    """The ideal slider-crank for 100 s (8333 revolutions) with a coarse output: no 'collapsed'."""
    scene = dc.mechanisms.slider_crank("ideal")
    result = dc.simulate(scene, 100.0, save=dc.SaveAt(steps=False, times=np.linspace(0.0, 100.0, 101)))
    assert result.success, result.message
    assert result.t[-1] == 100.0 and "collapsed" not in result.message


def test_long_clearance_run_is_not_a_stall_in_contact():
    """t_end = 100 s used to set a 1e-8 s stall threshold, in the range of contact steps (1e-9..1e-6 s).
    The first 0.3 s of such a run (max_steps ends it, 0.1 s wall) are in and out of contact: the run ends
    on max_steps, never on a collapse."""
    scene = dc.mechanisms.slider_crank("revolute")
    result = quiet_simulate(scene, 100.0, on_failure="return", options=dc.SolverOptions(max_steps=60_000),
                            save=dc.SaveAt(steps=False, times=np.linspace(0.0, 100.0, 1001)))
    assert "collapsed" not in result.message and "max_steps" in result.message


def test_genuine_stall_is_still_caught():
    import daeclear.contact as dcc

    scene = dc.mechanisms.slider_crank("revolute", friction=dcc.Coulomb(coefficient=0.5))
    # the stall guard: index-1 chatters (GGL fails Newton, same advice)
    result = dc.simulate(scene, 100.0, on_failure="return", options=dc.SolverOptions(formulation="index1"),
                         save=dc.SaveAt(steps=False, times=np.linspace(0.0, 100.0, 11)))
    assert not result.success and "DC_STEP_COLLAPSE" in result.message and "modified Coulomb" in result.message


# ---------------------------------------------------------------- item 6: scene-file messages


BODY = PENDULUM_LINK.lstrip()

SCENE_FILE_CASES = [
    ("body_table", "[scene]\nname = \"p\"\n" + BODY.replace("[[body]]", "[body]"),
     ["[body] is a single table", "write [[body]]"]),
    ("simulate_array", BODY + "[[simulate]]\nt_end = 1.0\n",
     ["[[simulate]] is an array of tables", "write [simulate]"]),
    ("mechanism_array", "[[mechanism]]\nname = \"slider_crank\"\n", ["[[mechanism]]", "write [mechanism]"]),
    ("scene_value", "scene = \"p\"\n" + BODY, ["scene = 'p' is a string", "write [scene]"]),
    ("mass_string", BODY.replace("mass = 1.0", "mass = \"heavy\""), ["[[body]] #1", "key mass", "mass='heavy'"]),
    ("position_number", BODY.replace("position = [0.5, 0.0]", "position = 0.5"),
     ["[[body]] #1", "key position", "position=0.5"]),
    ("name_number", BODY.replace("name = \"link\"", "name = 3"), ["[[body]] #1", "key name = 3 is a number"]),
    ("body_ref_number", BODY.replace("body_j = \"link\"", "body_j = 2"), ["[[revolute]] #1", "key body_j = 2"]),
    ("scene_name_number", "[scene]\nname = 3\n" + BODY, ["[scene]", "key name = 3 is a number"]),
    ("gravity_string", "[scene]\ngravity = \"down\"\n" + BODY, ["[scene]", "key gravity = 'down' is a string"]),
    ("gravity_short", "[scene]\ngravity = [1.0]\n" + BODY, ["[scene]", "key gravity", "gravity=(1.0,)"]),
    ("driver_speed", BODY + "[[driver]]\nname = \"d\"\njoint = \"A\"\nspeed = \"fast\"\n",
     ["[[driver]] #1", "key speed", "speed='fast'"]),
    ("material_value", BODY + "[[revolute_clearance]]\nname = \"c\"\nbody_i = \"ground\"\nbody_j = \"link\"\n"
     "at = [1.0, 0.0]\nbearing_radius = 0.01\nclearance = 1e-4\nmaterial = { young = \"x\", poisson = 0.3 }\n",
     ["[[revolute_clearance]] #1", "key material", "young='x'"]),
    ("law_key", BODY + "[[revolute_clearance]]\nname = \"c\"\nbody_i = \"ground\"\nbody_j = \"link\"\n"
     "at = [1.0, 0.0]\nbearing_radius = 0.01\nclearance = 1e-4\nmaterial = { young = 2e11, poisson = 0.3 }\n"
     "law = { name = \"hertz\", stiff = 3 }\n", ["[[revolute_clearance]] #1", "key law", "stiff"]),
    ("mechanism_rpm", "[mechanism]\nname = \"slider_crank\"\nrpm = \"fast\"\n",
     ["[mechanism]", "key rpm", "rpm='fast'"]),
]


@pytest.mark.parametrize("name, text, expected", SCENE_FILE_CASES, ids=[c[0] for c in SCENE_FILE_CASES])
def test_scene_file_messages_name_file_table_and_key(tmp_path: Path, capsys, name, text, expected):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        read_scene_file(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    for part in expected:
        assert part in message
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("daeclear: error: ") and "Traceback" not in err and expected[0] in err


# ---------------------------------------------------------------- item 6: truncated sweep files


def test_truncated_sweep_file_says_how_to_recover(tmp_path: Path):
    from daeclear.studies.sweep import load_sweep, sweep

    fast = dict(revolutions=8, transient=2, per_revolution=16, twin=False, progress=False)
    path = tmp_path / "s.h5"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicsWarning)
        sweep(path, {"clearance": [0.5e-3]}, fixed={"joint": "revolute"}, max_workers=1, **fast)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    for attempt in (lambda: load_sweep(path),
                    lambda: sweep(path, {"clearance": [0.5e-3]}, fixed={"joint": "revolute"}, max_workers=1, **fast)):
        with pytest.raises(DaeclearError) as info:
            attempt()
        text = str(info.value)
        assert "is a truncated daeclear sweep file" in text and "not a daeclear sweep" not in text
        assert "rename it to 's.h5.damaged'" in text and "run the same sweep again" in text
    not_hdf5 = tmp_path / "text.h5"
    not_hdf5.write_text("hello")
    with pytest.raises(DaeclearError, match="not a daeclear sweep file"):
        load_sweep(not_hdf5)


def test_physics_limits_are_the_documented_ones():
    assert physics.PENETRATION_FRACTION == 1.0 and physics.DRIFT_FRACTION == solve.DRIFT_FRACTION == 1e-3
    assert set(physics.KINDS) == {"penetration", "initial_penetration", "initial_velocity", "constraint_drift",
                                  "contact_within_one_step", "missed_contact"}


def test_term_on_at_knows_a_pair_from_its_last_switch_on():
    """The failure message's record of the terms keeps one switch a pair (bounded memory): from the
    switch on its state is known; before it, or for a name that is no pair, the term counts as on, so
    that no lost onset is claimed."""
    from daeclear.solvers.driver import term_on_at

    last = {"A": (0.5, False), "B": (0.2, True)}
    assert term_on_at(last, "A", 0.7) is False and term_on_at(last, "A", 0.5) is False
    assert term_on_at(last, "A", 0.4) is True  # before its last switch: not known
    assert term_on_at(last, "B", 0.3) is True and term_on_at(last, "C", 1.0) is True
