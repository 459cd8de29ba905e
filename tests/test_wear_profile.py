"""The worn profile in the joint's gap and the cycle scheme (issue 33, second part).

Checks against independent computations: the profile's series against its closed form, the impact
time of a journal flying at a worn spot against kinematics (c + h) / v, the worn volume against
k times the sliding work, a resumed history against an uninterrupted one."""

from __future__ import annotations

import math

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.contact.wear import MAX_DEPTH_FRACTION, ArchardWear, profile_coefficients, profile_depth
from daeclear.core.errors import SceneError
from daeclear.model.scene import RevoluteClearance
from daeclear.assembly.assemble import assemble
from daeclear.solvers.driver import Continuation
from daeclear.studies.wear import block_run, simulate_wear

NODES, MODES = 360, 48
THETA = 2.0 * np.pi * np.arange(NODES) / NODES
CLEARANCE, SPEED = 0.5e-3, 0.1  # m, m/s


def _bump(centre: float, depth: float = 40e-6, width: float = 0.25) -> np.ndarray:
    return depth * np.exp(-(np.angle(np.exp(1j * (THETA - centre))) / width) ** 2)


def flight(direction: float, *, surface: str = "bearing", depth=None, journal_angle: float = 0.0,
           wear: bool = True) -> dc.Scene:
    """A journal flying from the bearing's centre at SPEED along ``direction`` (no gravity)."""
    scene = dc.Scene("flight", gravity=(0.0, 0.0))
    journal = scene.add(dc.Body("journal", mass=0.1, inertia=1e-5, angle=journal_angle,
                                velocity=(SPEED * math.cos(direction), SPEED * math.sin(direction))))
    scene.add(RevoluteClearance(
        "bearing", scene.ground, journal, at=(0, 0), bearing_radius=10e-3, clearance=CLEARANCE,
        material=dcc.Material(young=207e9, poisson=0.3), law=dcc.LankaraniNikravesh(restitution=0.9),
        wear=ArchardWear(coefficient=1e-14, length=0.02, nodes=NODES, modes=MODES, surface=surface) if wear else None,
        wear_depth=depth))
    return scene


def _onset(scene: dc.Scene) -> float:
    result = dc.simulate(scene, 0.01, rtol=1e-10, options=dc.SolverOptions(start="declared"))
    return result.events.of(kind="onset")[0].t


def test_profile_series_of_a_smooth_profile():
    """The series of a + b cos 2t + c sin 3t is exactly that; a worn spot of half-width 0.1 rad is
    reproduced to 1e-3 of its depth with 48 modes, its mean (the worn volume) exactly."""
    depth = 5e-6 + 2e-6 * np.cos(2 * THETA) - 1e-6 * np.sin(3 * THETA)
    a, b = profile_coefficients(depth, MODES)
    assert a[0] == pytest.approx(5e-6, rel=1e-12, abs=0.0) and a[2] == pytest.approx(2e-6, rel=1e-9, abs=0.0)
    assert b[2] == pytest.approx(-1e-6, rel=1e-9, abs=0.0)
    assert np.max(np.abs(np.delete(a, [0, 2]))) < 1e-19 and np.max(np.abs(np.delete(b, 2))) < 1e-19  # round-off
    np.testing.assert_allclose(profile_depth(a, b, THETA), depth, rtol=0, atol=1e-18)
    spot = _bump(1.0, depth=1e-5, width=0.1)
    smooth = profile_depth(*profile_coefficients(spot, MODES), THETA)
    assert smooth.mean() == pytest.approx(spot.mean(), rel=1e-12, abs=0.0)
    assert np.max(np.abs(smooth - spot)) < 1e-3 * spot.max()
    coarse = profile_depth(*profile_coefficients(spot, 16), THETA)  # too few modes: a visible error
    assert np.max(np.abs(coarse - spot)) > 0.1 * spot.max()


@pytest.mark.parametrize("surface", ["bearing", "journal", "both"])
def test_impact_at_a_worn_spot_comes_when_kinematics_says(surface):
    """The journal reaches the wall at |e| = c + h(theta): (c + h) / v, h the smooth profile at the
    flight's angle in each worn body's frame (the journal turned by 0.5 rad carries its profile)."""
    direction, turned = 0.3, 0.5 if surface != "bearing" else 0.0
    bearing, journal = _bump(direction), _bump(direction - turned, depth=25e-6)
    depth = {"bearing": bearing, "journal": journal, "both": np.array([bearing, journal])}[surface]
    h = 0.0
    if surface in ("bearing", "both"):
        h += profile_depth(*profile_coefficients(bearing, MODES), [direction])[0]
    if surface in ("journal", "both"):
        h += profile_depth(*profile_coefficients(journal, MODES), [direction - turned])[0]
    assert h > 20e-6
    t = _onset(flight(direction, surface=surface, depth=depth, journal_angle=turned))
    assert t == pytest.approx((CLEARANCE + h) / SPEED, rel=1e-9)
    assert _onset(flight(direction + math.pi, surface=surface, depth=depth, journal_angle=turned)) \
        == pytest.approx(CLEARANCE / SPEED, rel=1e-6)  # the unworn side: the nominal clearance


@pytest.mark.parametrize("surface", ["bearing", "journal", "both"])
def test_a_worn_contacts_force_is_its_law_at_the_gaps_own_rate_along_the_gaps_gradient(surface):
    """One state on a worn flank, the journal sliding along it and turning: the contact's generalized
    force is -F_N grad_q(delta) (frictionless: the virtual work of F_N on the gap), F_N the
    Lankarani-Nikravesh force K delta^1.5 (1 + 3 (1 - c_e^2) / 4 delta' / v-) at the gap's own rate
    delta' = grad_q(delta) . v, the gap and its gradient by central differences of the penetration
    channel (so d|e|/dt alone, or a force along e alone, would be off by the profile's slope)."""
    direction, turned, approach = 0.3, 0.5, 0.1
    bearing, journal = _bump(direction + 0.15), _bump(direction - turned + 0.15, depth=25e-6)
    depth = {"bearing": bearing, "journal": journal, "both": np.array([bearing, journal])}[surface]
    model = dc.assemble(flight(direction, surface=surface, depth=depth, journal_angle=turned))
    n_q = model.n_q
    y = np.zeros(model.n_states)
    reach = CLEARANCE + bearing.max() + journal.max() + 2e-6  # past the worn wall: in contact
    y[:n_q] = reach * math.cos(direction), reach * math.sin(direction), turned
    y[n_q:2 * n_q] = -0.2 * math.sin(direction) + 0.05 * math.cos(direction), \
        0.2 * math.cos(direction) + 0.05 * math.sin(direction), 30.0  # along the flank, outwards, turning

    def gap(states: np.ndarray) -> np.ndarray:
        return model.channels(np.zeros(len(states)), states, np.zeros_like(states))["bearing.penetration"]

    h = 1e-9  # (1e-7 leaves 1e-6 of truncation in the flank's slope)
    moved = np.repeat(y[None, :], 2 * n_q, axis=0)
    for k in range(n_q):
        moved[2 * k, k] -= h
        moved[2 * k + 1, k] += h
    delta = gap(y[None, :])[0]
    grad = (gap(moved)[1::2] - gap(moved)[0::2]) / (2 * h)
    rate = grad @ y[n_q:2 * n_q]
    slope = grad[:2] @ np.array([-math.sin(direction), math.cos(direction)])
    assert delta > 1e-6 and abs(slope) > 0.05  # a real flank: d|e|/dt is not the gap's rate
    law = model.scene["bearing"].resolved_law()
    force = law.stiffness * delta**1.5 * (1 + 0.75 * (1 - 0.9**2) * rate / approach)
    got = model.term_forces(0.0, y, [True], [np.array([approach])])[:n_q]
    np.testing.assert_allclose(got, -force * grad, rtol=1e-6, atol=1e-9 * force)


def test_an_unworn_profile_is_the_joint_without_wear():
    plain = dc.simulate(flight(0.3, wear=False), 0.01, rtol=1e-10, options=dc.SolverOptions(start="declared"))
    worn = dc.simulate(flight(0.3), 0.01, rtol=1e-10, options=dc.SolverOptions(start="declared"))
    np.testing.assert_array_equal(plain.t, worn.t)
    np.testing.assert_array_equal(plain.y, worn.y)


def test_a_new_profile_is_run_time_data():
    model = dc.assemble(flight(0.3))
    worn = model.with_parameters({"bearing.wear_depth": _bump(0.3)})
    assert worn.functions is model.functions
    assert not np.array_equal(worn.parameter("bearing.wear.bearing_cos"), model.parameter("bearing.wear.bearing_cos"))
    assert worn.scene["bearing"].wear_depth == tuple(_bump(0.3).tolist())


@pytest.mark.parametrize("change, words", [
    (dict(wear_depth=np.zeros(10)), ["wear_depth=an array of shape (10,)", "shape (360,)"]),
    (dict(wear_depth=-np.ones(NODES)), [">= 0"]),
    (dict(wear=None, wear_depth=np.zeros(NODES)), ["wear_depth is given without wear"]),
    (dict(wear="archard"), ["wear='archard'", "ArchardWear"]),
    (dict(law=dcc.HydrodynamicBearing(viscosity=0.04, length=0.02)), ["lubricated joint", "not modelled"]),
])
def test_bad_wear_is_refused(change, words):
    with pytest.raises(SceneError) as info:
        flight(0.3).with_values({f"bearing.{k}": v for k, v in change.items()})
    for word in words:
        assert word in str(info.value)


def test_archard_modes_are_checked():
    with pytest.raises(SceneError, match="modes=200"):
        ArchardWear(coefficient=1e-14, length=0.02, nodes=360, modes=200)


@pytest.fixture(scope="module")
def worn_crank():
    scene = dc.mechanisms.slider_crank("revolute", friction=0.1)
    return scene.with_values({"clearance.wear": ArchardWear(coefficient=1e-11, length=0.02, nodes=NODES)})


def test_cycle_scheme_keeps_the_volume_and_converges_in_the_update_interval(worn_crank):
    """Every profile's worn volume is k times the sliding work so far (round-off); the depth after
    4 cycles moves less from the every-cycle update when the update interval halves."""
    runs = {every: simulate_wear(worn_crank, 4, update_every=every) for every in (1, 2, 4)}
    for history in runs.values():
        np.testing.assert_allclose(history.volume, 1e-11 * history.sliding_work, rtol=1e-12, atol=0)
        assert history.cycles[-1] == 4 and np.all(np.diff(history.volume) > 0)
    base = runs[1].depth[-1]
    gap = {every: np.max(np.abs(runs[every].depth[-1] - base)) for every in (2, 4)}
    assert 0 < gap[2] < gap[4] < 0.05 * base.max()
    assert np.all(np.isfinite(runs[1].peak_force[:-1])) and np.isnan(runs[1].peak_force[-1])


def test_extrapolated_blocks_converge_to_simulating_every_cycle(worn_crank):
    """The depth after 8 cycles moves less from simulating every cycle when each simulated cycle
    stands for 2 than for 4 (measured: 7 % and 20 % of the largest depth; the first block carries the
    start's transient); the volume stays k times the (extrapolated) sliding work."""
    runs = {factor: simulate_wear(worn_crank, 8, extrapolate=factor) for factor in (1, 2, 4)}
    base = runs[1].depth[-1]
    gap = {factor: np.max(np.abs(runs[factor].depth[-1] - base)) for factor in (2, 4)}
    assert 0 < gap[2] < 0.5 * gap[4] and gap[4] < 0.3 * base.max()
    assert [len(runs[f].cycles) for f in (1, 2, 4)] == [9, 5, 3]
    for history in runs.values():
        np.testing.assert_allclose(history.volume, 1e-11 * history.sliding_work, rtol=1e-12, atol=0)


def test_a_stopped_history_resumes_where_it_stopped(worn_crank, tmp_path):
    path = tmp_path / "wear.h5"
    first = simulate_wear(worn_crank, 2, path=path)
    resumed = simulate_wear(worn_crank, 3, path=path)  # reads the two cycles, runs the third
    whole = simulate_wear(worn_crank, 3)
    assert first.cycles.tolist() == [0, 1, 2] and resumed.cycles.tolist() == [0, 1, 2, 3]
    np.testing.assert_array_equal(resumed.depth, whole.depth)
    np.testing.assert_array_equal(resumed.sliding_work, whole.sliding_work)
    with pytest.raises(SceneError, match="update_every=1, now 2"):
        simulate_wear(worn_crank, 4, path=path, update_every=2)


def _continued(model: dc.DAEModel, t_end: float, t_split: float):
    """The run of ``model`` from its start to ``t_end`` whole, and split at ``t_split`` into two block runs,
    the second from the first's last state and contact state."""
    whole = block_run(model, 0.0, t_end, None, None)
    carry = Continuation()
    first = block_run(model, 0.0, t_split, None, None, carry)
    latched = carry.state[0][0].latched
    return whole, first, latched, block_run(model, t_split, t_end, first.state(-1), None, carry)


def test_a_block_boundary_inside_a_contact_keeps_the_impact_s_approach_speed(worn_crank):
    """A block that starts inside an ongoing contact (the slider-crank's rod-slider journal stays in
    contact from 7.2 ms on) goes on with the approach speed its impact latched (Lankarani-Nikravesh's
    damping divides by it), as the unsplit run does: its normal force is the unsplit run's to
    integration accuracy (measured 1.5e-3 of the peak at rtol 1e-6, shrinking with rtol). Re-latched
    from the penetration rate at the block's start, as every block did before, it was 18 % off."""
    model = assemble(worn_crank)
    whole, first, latched, second = _continued(model, 0.0115, 0.009)
    segment = next(s for s in whole.segments if s[0] < 0.009 < s[1])
    assert segment[2]["clearance"] == "contact" and segment[0] < 0.0085  # the boundary is inside a contact
    onset = [e for e in first.events.of("clearance", kind="onset")][-1]
    assert latched == onset.approach_speed > 0.0  # the impact's, carried to the next block
    force = second["clearance.normal_force"]
    reference = np.interp(second.t, whole.t, whole["clearance.normal_force"])
    assert np.max(force) > 5e3 and np.max(np.abs(force - reference)) < 5e-3 * np.max(reference)


def test_blocks_split_inside_a_contact_wear_as_one_run():
    """simulate_wear's block boundaries (each turn of the crank, inside the journal's long contact) do not
    change the physics: two one-cycle blocks give the sliding work of one two-cycle block (k so small
    that the profile does not act) to integration accuracy (measured 3e-5; with each block's approach
    speed re-latched at its start, 8.5e-3)."""
    scene = dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-20, length=0.02)})
    split, whole = (simulate_wear(scene, 2, update_every=every) for every in (1, 2))
    assert whole.sliding_work[-1] > 50.0
    assert split.sliding_work[-1] == pytest.approx(whole.sliding_work[-1], rel=3e-4)


def test_simulate_wear_input_is_checked(worn_crank):
    for kwargs, word in ((dict(update_every=0), "update_every=0"), (dict(extrapolate=1.5), "extrapolate=1.5"),
                         (dict(joint="C"), "joint='C'"), (dict(period=-1.0), "period=-1.0")):
        with pytest.raises(SceneError, match=word):
            simulate_wear(worn_crank, 2, **kwargs)
    with pytest.raises(SceneError, match="cycles=0"):
        simulate_wear(worn_crank, 0)


def test_example_joint_wear_quick(tmp_path, capsys):
    """The study's script: 40 cycles in blocks of 10, its figures, animation, history file and metrics."""
    import importlib.util
    import json
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "joint_wear.py"
    spec = importlib.util.spec_from_file_location("example_joint_wear", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--animate", "--out", str(tmp_path)]) == 0
    for name in ("wear_profile.png", "wear_impacts.png", "wear_growth.gif"):
        assert (tmp_path / name).stat().st_size > 5_000
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["cycles"] == 40 and metrics["volume_m3"] == pytest.approx(
        metrics["coefficient"] * metrics["sliding_work_Nm"], rel=1e-12, abs=0.0)
    assert "wrote" in capsys.readouterr().out


def test_wear_beyond_the_gap_model_stops_with_a_message(worn_crank):
    """A depth beyond 5 % of the bearing radius (the normal's small-slope model) ends the history with a
    warning and a message, keeping what was computed (k = 1e-8: 1 mm in the first cycle)."""
    runaway = worn_crank.with_values({"clearance.wear.coefficient": 1e-8})
    with pytest.warns(dc.PhysicsWarning, match="exceeds 0.05 of the bearing radius"):
        history = simulate_wear(runaway, 5)
    assert history.cycles[-1] < 5 and "stopped at" in history.message and history.max_depth[-1] > 5e-4
    assert simulate_wear(worn_crank, 1).message == ""


def test_a_failing_block_ends_the_history_with_what_it_computed(worn_crank):
    """A block whose run fails (a step cap too small for a cycle) ends the history with a warning;
    the profiles before it are returned."""
    tight = dc.SolverOptions(max_steps=300)
    with pytest.warns(dc.PhysicsWarning, match="the run of the next block failed"):
        history = simulate_wear(worn_crank, 3, options=tight)
    assert history.cycles.tolist() == [0.0] and "max_steps" in history.message


def test_spread_in_passes_equals_one_pass(monkeypatch):
    """Many contacts are spread in passes of bounded size (memory); the depth is the one-pass depth."""
    from daeclear.contact import wear

    rng = np.random.default_rng(3)
    centres, halves, loads = rng.uniform(0, 2 * np.pi, 500), rng.uniform(0, 0.3, 500), rng.uniform(0, 1e-9, 500)
    whole = wear.spread(centres, halves, loads, NODES)
    monkeypatch.setattr(wear, "SPREAD_SAMPLES", 1000)  # passes of a handful of contacts
    np.testing.assert_allclose(wear.spread(centres, halves, loads, NODES), whole, rtol=1e-12, atol=1e-24)
    assert whole.sum() == pytest.approx(loads.sum(), rel=1e-12, abs=0.0)


def _planted_block() -> tuple[dc.DAEModel, float, np.ndarray, float]:
    """The block that let the journal through its wall (issue 44): examples/joint_wear.py's scene at
    k = 1e-12, every cycle simulated, its profile and state after 911 cycles (tests/data)."""
    from pathlib import Path

    from daeclear.studies.poincare import crank_period

    data = np.load(Path(__file__).resolve().parent / "data" / "worn_block_912.npz")
    scene = dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02)})
    model = dc.assemble(scene).with_parameters({"clearance.wear_depth": tuple(data["depth"].tolist())})
    return model, float(data["t0"]), data["y0"], crank_period(scene)


def test_a_worn_contact_is_never_left_while_it_penetrates():
    """The planted block: its journal slides along a steep worn flank where |e| falls while the gap
    (|e| - c - h) grows. Every onset has a positive approach speed, which is the gap's own rate (a
    central difference of the penetration channel along the motion), no separation follows an onset at
    the same instant, and the penetration stays a contact's (it went 75 mm through the wall before)."""
    model, t0, y0, period = _planted_block()
    run = dc.simulate(model, t0 + period, t0=t0, y0=y0)
    assert run.success
    penetration = run["clearance.penetration"]
    assert 0.0 < penetration.max() < 0.1 * CLEARANCE
    events = list(run.events)
    assert len(events) > 4
    for before, after in zip(events, events[1:]):
        assert after.t - before.t > 1e-9 or before.kind == after.kind
    n_q, h = model.n_q, 1e-9
    for event in events:
        assert (event.approach_speed > 0) == (event.kind == "onset")
        moved = np.array([event.y, event.y])  # the state moved along its velocity: q -+ h v
        moved[0, :n_q] -= h * event.y[n_q:2 * n_q]
        moved[1, :n_q] += h * event.y[n_q:2 * n_q]
        pen = model.channels(np.full(2, event.t), moved, np.zeros_like(moved))["clearance.penetration"]
        assert event.approach_speed == pytest.approx((pen[1] - pen[0]) / (2 * h), rel=1e-4, abs=1e-6)


def test_an_unphysical_block_ends_the_wear_history():
    """A block whose run leaves the journal deeper in the wall than the clearance, or whose next start
    cannot be assembled, ends simulate_wear early with a warning, as documented (a stand-in: a block
    run with a law 1e6 times softer)."""
    scene = dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-13, length=0.02), "clearance.law.stiffness": 1e4})
    with pytest.warns(dc.PhysicsWarning, match="stopped at 0 cycles"):
        history = simulate_wear(scene, 3)
    assert history.cycles.tolist() == [0.0] and "clearance" in history.message


@pytest.mark.slow
def test_a_thousand_cycles_at_k_1e_12_every_one_simulated_finish():
    """Issue 44's case (it stopped at cycle 912, the journal through its wall): examples/joint_wear.py's
    scene at k = 1e-12, 1000 cycles, every one simulated. Every block runs, without a warning; the worn
    volume is k times the sliding work at every profile; the depth grows every cycle and stays within
    the gap model's range."""
    import warnings

    scene = dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02)})
    with warnings.catch_warnings():
        warnings.simplefilter("error", dc.PhysicsWarning)
        history = simulate_wear(scene, 1000)
    assert history.message == "" and history.cycles.tolist() == list(range(1001))
    np.testing.assert_allclose(history.volume, 1e-12 * history.sliding_work, rtol=1e-12, atol=0.0)
    assert np.all(np.diff(history.max_depth) > 0)
    joint = next(e for e in scene.elements if e.name == "clearance")
    mean_depth = history.volume[-1] / (2 * math.pi * joint.bearing_radius * 0.02)  # the volume spread evenly
    assert 2 * mean_depth < history.max_depth[-1] < MAX_DEPTH_FRACTION * joint.bearing_radius  # a worn spot


@pytest.mark.parametrize("surface", ["bearing", "journal", "both"])
def test_the_worn_depth_s_written_out_gradient_is_its_derivative(surface):
    """worn_depths writes the profile's gradient out (the polynomial's derivative in z = c + i s); it must
    be CasADi's derivative of the depth itself, in contact (a unit direction) and off it (shorter, and
    zero: the centred journal), for random profiles and body angles."""
    import casadi as ca
    from types import SimpleNamespace

    from daeclear.assembly.contact_pairs import worn_depths

    modes = 12
    q = ca.SX.sym("q", 4)  # the two bodies' angles, the direction's two components
    symbols = {f"wear.{s}_{k}": ca.SX.sym(f"{s}_{k}", modes + 1 if k == "cos" else modes)
               for s in ("bearing", "journal") for k in ("cos", "sin")}
    ctx = SimpleNamespace(q=q, p=lambda name, key: symbols[key])
    joint = SimpleNamespace(name="j", wear=ArchardWear(coefficient=1e-13, length=0.02, modes=modes, surface=surface))
    bi, bj = SimpleNamespace(phi=q[0]), SimpleNamespace(phi=q[1])
    h_bearing, h_journal, gradient = worn_depths(ctx, joint, q[2:], bi, bj)
    p = ca.vertcat(*symbols.values())
    f = ca.Function("f", [q, p], [gradient, ca.jacobian(h_bearing + h_journal, q)])
    rng = np.random.default_rng(7)
    for direction in ([0.6, 0.8], [0.21, -0.13], [0.0, 0.0]):
        x = np.concatenate([rng.uniform(-3, 3, 2), direction])
        written, derived = (np.array(v).ravel() for v in f(x, rng.normal(0.0, 1e-5, p.numel())))
        assert np.max(np.abs(derived)) > 0
        np.testing.assert_allclose(written, derived, rtol=1e-12, atol=1e-12 * np.max(np.abs(derived)))


def test_a_carried_pair_keeps_its_state_only_where_its_gap_agrees(worn_crank):
    """continued_state: a pair carried in contact keeps its latched speed where the start's gap is in
    contact; where the gap is open (new numbers moved it) it starts from its gap, as any run."""
    from daeclear.assembly import contact_state
    from daeclear.core.automaton import PairState

    model = assemble(worn_crank)
    run = block_run(model, 0.0, 0.0115, None, None)
    rows = {mode: next(i for i, t in enumerate(run.t) if any(a < t < b and m["clearance"] == mode
                                                                for a, b, m in run.segments))
            for mode in ("contact", "free")}
    carried = ((PairState(contact=True, latched=0.37, recent=(0.001,)),),)
    t, y = run.t[rows["contact"]], run.state(rows["contact"])
    assert contact_state.continued_state(model, t, y, carried) == carried
    t, y = run.t[rows["free"]], run.state(rows["free"])
    assert contact_state.continued_state(model, t, y, carried) == contact_state.start_state(model, t, y)
    assert not contact_state.start_state(model, t, y)[0][0].contact
    shape = contact_state.state_shape(model)
    assert contact_state.array_state(contact_state.state_array(carried, shape), carried) == carried
