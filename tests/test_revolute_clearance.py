"""Slider-crank with a revolute clearance joint (section 4.2, 4.4): conservation, dissipation, limits.

Measured (rtol 1e-8 unless said): free elastic mechanism, 0.1 s, ~260 impacts: free-flight energy
range 5.9e-6 of the initial energy (2.4e-4 at rtol 1e-6, 5.4e-8 at 1e-10). c_e = 0.9: energy lost
per impact equals the contact work to 4e-7..5e-6 (Simpson on a 0.1 us output grid). c = 0.01 mm, revolutions
3-5: slider velocity within 1.1e-3 of its range of the ideal joint's, RMS crank-moment deviation
1.2e-2 of its range, peak moment 144 N m against 138.6 N m ideal. c = 0.5 mm: in contact 70 % of
the time, contacts up to 5.8 ms (following the wall), free flights up to 0.58 ms, ~74 impacts.
"""

import numpy as np
import pytest
from scipy.integrate import simpson

import daeclear as dc
from daeclear.assembly.assemble import EXTRA_TERM0
from daeclear.core.automaton import PairState
from daeclear.core.errors import SceneError
from daeclear.model.scene import Driver, RevoluteClearance

PERIOD = 60.0 / 5000.0  # one crank revolution at 5000 rpm


def free_mechanism(restitution):
    """The chapter's mechanism without driver or gravity: only the clearance joint acts."""
    scene = dc.mechanisms.slider_crank("revolute", gravity=0.0, restitution=restitution)
    scene.elements = [e for e in scene.elements if not isinstance(e, Driver)]
    return scene


def test_model_holds_only_what_the_scene_declares():
    frictionless = dc.assemble(dc.mechanisms.slider_crank("revolute"), "index1")
    assert frictionless.summary() == {"bodies": 3, "states": 25, "constraints": 7, "terms": 1, "gaps": 1,
                                      "channels": 43 + 8}  # + angle and rate (displacement, speed) of 4 joints
    assert dc.assemble(dc.mechanisms.slider_crank("revolute")).summary()["states"] == 25 + 7  # GGL: + mu
    assert frictionless.gap_names == ("clearance",)
    assert "clearance.friction_force" not in frictionless.channel_names
    with_friction = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    assert "clearance.friction_force" in with_friction.channel_names
    # the friction law is absent from the frictionless contact force, not multiplied by zero
    n_plain = frictionless.terms[0].force.n_instructions()
    n_friction = with_friction.terms[0].force.n_instructions()
    assert n_plain < n_friction
    ideal = dc.assemble(dc.mechanisms.slider_crank())
    assert ideal.functions.roots is None and not ideal.terms


def test_energy_conserved_through_hundreds_of_elastic_impacts():
    result = dc.simulate(free_mechanism(1.0), 0.1, rtol=1e-8)
    onsets = result.events.of("clearance", kind="onset")
    assert len(onsets) > 200
    energy = result["energy.mechanical"]
    free = result["clearance.in_contact"] == 0  # no elastic energy stored in the contact there
    assert np.ptp(energy[free]) / energy[0] < 2e-5


def test_energy_lost_equals_contact_work_impact_by_impact():
    """No driver, no gravity: between two free-flight instants around an impact the mechanical
    energy changes by exactly the work of the contact force (Simpson on a 0.1 us output grid)."""
    t_eval = np.linspace(0.0, 0.004, 40001)
    result = dc.simulate(free_mechanism(0.9), 0.004, rtol=1e-10, save=dc.SaveAt(times=t_eval))
    t, energy = result.t, result["energy.mechanical"]
    power = -result["clearance.normal_force"] * result["clearance.penetration_rate"]
    onsets = result.events.of(kind="onset").t
    separations = result.events.of(kind="separation").t
    assert len(onsets) >= 5
    for t_on, t_off in zip(onsets, separations):
        i0, i1 = np.searchsorted(t, t_on) - 1, np.searchsorted(t, t_off)  # free-flight points around it
        work = simpson(power[i0:i1 + 1], x=t[i0:i1 + 1])
        lost = energy[i1] - energy[i0]
        assert lost < 0
        assert abs(lost - work) < 1e-5 * abs(lost), (t_on, lost, work)


@pytest.fixture(scope="module")
def ideal_window():
    t = np.linspace(3 * PERIOD, 5 * PERIOD, 2001)
    return t, dc.simulate(dc.mechanisms.slider_crank(), 5 * PERIOD, rtol=1e-8, save=dc.SaveAt(times=np.r_[0.0, t]))


def test_small_clearance_tends_to_the_ideal_joint(ideal_window):
    t, ideal = ideal_window
    result = dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=0.01e-3), 5 * PERIOD, rtol=1e-8,
                         save=dc.SaveAt(times=np.r_[0.0, t]))
    v, v_ideal = result["slider.vx"][1:], ideal["slider.vx"][1:]
    m, m_ideal = result["drive.moment"][1:], ideal["drive.moment"][1:]
    assert np.max(np.abs(v - v_ideal)) / np.ptp(v_ideal) < 3e-3
    assert np.sqrt(np.mean((m - m_ideal) ** 2)) / np.ptp(m_ideal) < 3e-2
    assert np.max(np.abs(m)) == pytest.approx(np.max(np.abs(m_ideal)), rel=0.1)
    assert np.all(result["clearance.in_contact"][1:] == 1)  # the journal follows the bearing


def test_large_clearance_flies_impacts_and_follows(ideal_window):
    """Revolutions 3 to 8. The motion is chaotic: every formulation and rtol (1e-6 to 1e-10) leaves
    the rtol-1e-11 run before t = 0.028 s, so any two revolutions are one sample of the attractor
    (GGL at rtol 1e-8 follows the wall through revolutions 3-5, its shortest contact 1.2 ms); over
    five revolutions every run measured (index1 and GGL, rtol 1e-6 to 1e-9) shows all three."""
    _, ideal = ideal_window
    t = np.linspace(3 * PERIOD, 8 * PERIOD, 5001)
    result = dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=0.5e-3), 8 * PERIOD, rtol=1e-8,
                         save=dc.SaveAt(times=np.r_[0.0, t]))
    late = [(a, b, modes["clearance"]) for a, b, modes in result.segments if a >= 3 * PERIOD]
    contact = [b - a for a, b, mode in late if mode == "contact"]
    flight = [b - a for a, b, mode in late if mode == "free"]
    assert max(flight) > 0.2e-3  # free flight
    assert min(contact) < 0.1e-3  # impacts and rebounds
    assert max(contact) > 2e-3  # following the bearing wall
    # impacts raise the crank moment far above the ideal mechanism's
    assert np.max(np.abs(result["drive.moment"])) > 3 * np.max(np.abs(ideal["drive.moment"]))
    # the penetration stays on the Hertz scale of a 4.4 m/s impact of the slider (77 um)
    assert 0 < np.max(result["clearance.penetration"]) < 1e-4
    # events alternate onset/separation and onsets approach
    kinds = result.events.of("clearance").kind
    assert all(a != b for a, b in zip(kinds, kinds[1:]))
    assert np.all(result.events.of(kind="onset").approach_speed > 0)


def test_first_impact_matches_kinematic_estimate():
    """The slider is at rest at t = 0 while the journal accelerates at -r w^2 (1 + r/l)."""
    result = dc.simulate(dc.mechanisms.slider_crank("revolute", gravity=0.0), 0.4e-3, rtol=1e-10)
    onset = result.events.of(kind="onset")[0]
    a0 = 19419.36  # |slider acceleration| of the ideal mechanism at t = 0 (docs/contact_laws.md)
    assert onset.t == pytest.approx(np.sqrt(2 * 0.5e-3 / a0), rel=2e-2)
    assert onset.approach_speed == pytest.approx(a0 * onset.t, rel=2e-2)


def test_events_are_located_where_the_journal_meets_the_wall():
    """Every onset and separation is a root of the gap: the penetration |e| - c at the event's state is
    zero to the root's time tolerance (rate x 1e-14 s), and the latched approach speed is the rate there."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0))
    result = dc.simulate(model, 0.012, rtol=1e-8)
    events = result.events
    assert len(events) > 20
    y = np.array([event.y for event in events])
    at_events = model.channels(events.t, y, np.zeros_like(y))
    penetration, rate = at_events["clearance.penetration"], at_events["clearance.penetration_rate"]
    np.testing.assert_allclose(penetration, 0.0, atol=1e-11)
    onset = np.array([event.kind == "onset" for event in events])
    assert 10 < onset.sum() < len(events) and np.all(rate[onset] > 0) and np.all(rate[~onset] < 0)
    np.testing.assert_allclose([event.approach_speed for event in events if event.kind == "onset"], rate[onset],
                               rtol=1e-9)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(clearance=0.0), "clearance=0.0"),
        (dict(clearance=0.02), "clearance=0.02"),
        (dict(restitution=1.5), "restitution"),
        (dict(law="spring"), "unknown name 'spring'"),
        (dict(friction=-0.1), "coefficient"),
    ],
)
def test_bad_clearance_inputs(kwargs, match):
    with pytest.raises(SceneError, match=match):
        dc.mechanisms.slider_crank("revolute", **kwargs).validate()


def test_joint_needs_material_or_stiffness():
    scene = dc.Scene("s")
    a = scene.add(dc.Body("a", mass=1.0, inertia=0.1))
    scene.add(RevoluteClearance("c", scene.ground, a, at=(0, 0), bearing_radius=0.01, clearance=1e-4))
    with pytest.raises(SceneError, match="RevoluteClearance 'c'.*materials"):
        scene.validate()


def test_sticking_with_plain_coulomb_fails_fast_with_advice():
    """Plain Coulomb is discontinuous at zero sliding speed: a sticking contact chatters with ~1e-12 s
    steps (index-1). The stall guard ends the run within a few thousand steps and says what to use
    instead. GGL (the default) fails its Newton iteration there instead, as fast, with the same advice."""
    import daeclear.contact as dcc

    scene = dc.mechanisms.slider_crank("revolute", friction=dcc.Coulomb(coefficient=0.5))
    default = dc.simulate(scene, 0.024, on_failure="return")
    assert not default.success and "'clearance' in contact" in default.message
    assert "modified Coulomb" in default.message and default.stats["n_steps"] < 20_000
    result = dc.simulate(scene, 0.024, on_failure="return", options=dc.SolverOptions(formulation="index1"))
    assert not result.success and result.status == -1
    assert "DC_STEP_COLLAPSE" in result.message and "'clearance' in contact" in result.message
    assert "modified Coulomb" in result.message
    assert result.stats["n_steps"] < 20_000
    assert np.all(np.isfinite(result.y))  # the partial result is kept
    with pytest.raises(dc.SolveError, match="modified Coulomb") as info:
        dc.simulate(scene, 0.024, options=dc.SolverOptions(formulation="index1"))
    assert info.value.result.t[-1] == pytest.approx(result.t[-1])


def bearing_drop(restitution):
    """A journal dropped under gravity into a fixed bearing: bounces, then rests on the wall."""
    import daeclear.contact as dcc

    scene = dc.Scene("drop", gravity=(0.0, -9.81))
    journal = scene.add(dc.Body("journal", mass=0.1, inertia=1e-5))
    scene.add(RevoluteClearance("bearing", scene.ground, journal, at=(0, 0), bearing_radius=10e-3,
                                clearance=0.5e-3, material=dcc.Material(young=207e9, poisson=0.3),
                                law=dcc.LankaraniNikravesh(restitution=restitution)))
    return scene


def test_bouncing_settles_into_resting_contact_at_the_static_penetration():
    result = dc.simulate(bearing_drop(0.9), 0.5, rtol=1e-8)
    law_K = 6.6102e10  # K of (3.5) for steel, R = 10 / 9.5 mm
    static = (0.1 * 9.81 / law_K) ** (2 / 3)  # Hertz: m g = K delta^1.5
    assert result["bearing.penetration"][-1] == pytest.approx(static, rel=1e-4)
    onsets = result.events.of(kind="onset")
    # a finite cascade (measured: 41 impacts, the last at 0.8 mm/s), then following contact
    assert 10 < len(onsets) < 200
    assert result.events[-1].kind == "onset" and result.events[-1].t < 0.25
    assert np.all(np.diff(onsets.approach_speed[1:]) < 0)  # every rebound slower than the last


def test_storm_guard_holds_then_releases(monkeypatch):
    """Synthetic roots: 25 switches in a microsecond hold the term on; quick re-contacts change
    nothing; a re-contact after a real flight is a new onset with a freshly latched speed."""
    from daeclear.assembly import revolute_joint as clearance

    model = dc.assemble(bearing_drop(0.9))
    logic = model.contacts[0]
    y = np.zeros(model.n_states)
    y[1] = -0.5e-3  # journal on the wall
    state = (PairState(),)  # the pair's run state, free: passed in and returned by the rule
    up, down = np.array([1], dtype=np.int32), np.array([-1], dtype=np.int32)
    t = 0.0

    def term(state):  # (on, parameters) of the pair's term
        return logic.terms(state)[0][1:]

    for _ in range(clearance.STORM_EVENTS):
        t += 1e-8
        state, _ = logic.decide(state, t, y, up if not term(state)[0] else down)
    assert state[0].held and term(state)[0]  # the separation that completed the storm kept the term on
    assert logic.root_directions(state) == [(0, 0)]
    before = term(state)[1].copy()
    state, events = logic.decide(state, t + 1e-8, y, down)
    assert events == []
    state, events = logic.decide(state, t + 2e-8, y, up)
    assert events == []  # quick re-contact: no change
    assert term(state)[0] and np.array_equal(term(state)[1], before)
    state, _ = logic.decide(state, t + 3e-8, y, down)
    state, events = logic.decide(state, t + 3e-8 + 2 * clearance.STORM_WINDOW, y, up)
    assert [e.kind for e in events] == ["onset"] and not state[0].held and term(state)[0]


def test_energy_balance_with_driver_and_dissipation():
    """dE/dt = driver power + contact power: the balance closes on a dense output grid, and the
    multipliers reported at IDA's own steps are converged (no spurious moment spikes)."""
    from daeclear.studies.accuracy import energy_balance

    scene = dc.mechanisms.slider_crank("revolute")
    dense = dc.simulate(scene, 0.012, rtol=1e-8, save=dc.SaveAt(times=np.linspace(0.0, 0.012, 24001)))
    balance = energy_balance(dense)
    assert balance["max_residual"] < 2e-5  # measured 5.8e-6
    steps = dc.simulate(scene, 0.012, rtol=1e-8)
    # the moment at IDA's steps stays within the envelope seen on the dense grid
    assert np.max(np.abs(steps["drive.moment"])) < 1.5 * np.max(np.abs(dense["drive.moment"]))


def test_compiled_event_loop_matches_python_event_handling(plain_ida):
    """The compiled loop switches simple pairs itself; the python backend hands every root to the
    pair logic. Same steps, same events, same channels (index-1 and IDA's own settings: the python
    backend cannot set GGL's Newton coefficient, see test_compiled_ggl_restarts_match_python)."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")
    assert model.auto_pairs == ((0, 0, EXTRA_TERM0 + len(model.terms), True, 1e-4),)  # gap-rate extra after the forces
    fast = dc.simulate(model, 0.006, rtol=1e-8, options=dc.SolverOptions(backend="c", linear_solver=plain_ida))
    slow = dc.simulate(model, 0.006, rtol=1e-8, options=dc.SolverOptions(backend="python"))
    assert fast.stats["n_steps"] == slow.stats["n_steps"]
    assert fast.events.kind == slow.events.kind and len(fast.events) > 20
    np.testing.assert_allclose(fast.events.t, slow.events.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(fast.events.approach_speed, slow.events.approach_speed, rtol=1e-12)
    assert [m for *_, m in fast.segments] == [m for *_, m in slow.segments]
    for name in ("drive.moment", "clearance.normal_force", "slider.ax"):
        np.testing.assert_allclose(fast[name], slow[name], rtol=1e-9, atol=1e-9 * np.max(np.abs(slow[name])))


@pytest.mark.parametrize("joint", ["revolute", "translational"])
def test_compiled_ggl_restarts_match_python(joint):
    """GGL contact switches are decided in C too: its restarts project q and v onto the constraint
    manifold (least-norm Newton in C) and zero mu, as the Python restart does (lstsq). Same
    events on both backends, and the drift stays at Newton's tolerance."""
    model = dc.assemble(dc.mechanisms.slider_crank(joint, gravity=0.0), formulation="ggl")
    assert model.auto_pairs
    fast = dc.simulate(model, 0.006, rtol=1e-8, options=dc.SolverOptions(backend="c"))
    slow = dc.simulate(model, 0.006, rtol=1e-8, options=dc.SolverOptions(backend="python"))
    assert len(fast.events) > 10
    # the python backend cannot set IDA's Newton coefficient (GGL asks for 1e-3): not step for step,
    # so the contact sequences agree until the motion's sensitivity amplifies the difference
    first = slice(0, 12)
    assert fast.events.kind[first] == slow.events.kind[first]
    np.testing.assert_allclose(fast.events.t[first], slow.events.t[first], rtol=0, atol=2e-8)
    np.testing.assert_allclose(fast.events.approach_speed[first], slow.events.approach_speed[first], rtol=1e-4)
    assert fast.stats["max_constraint_drift"] < 1e-9 and slow.stats["max_constraint_drift"] < 1e-9


def test_compiled_events_with_tiny_step_buffers(monkeypatch):
    """Chunk boundaries of the C loop's step buffer falling on contact events (buffers of 3 steps)
    change nothing: same steps, same events (a regression test for a buffer overrun)."""
    import functools

    import daeclear.solvers.ida as solve_module
    from daeclear.engine.ida_session import open_session

    for scene in (dc.mechanisms.slider_crank("revolute", gravity=0.0), dc.mechanisms.slider_crank("translational")):
        model = dc.assemble(scene)
        assert model.auto_pairs  # the compiled loop switches these pairs itself
        normal = dc.simulate(model, 0.006, rtol=1e-8)
        monkeypatch.setattr(solve_module, "open_session", functools.partial(open_session, buffer_steps=3))
        chunked = dc.simulate(model, 0.006, rtol=1e-8)
        monkeypatch.undo()
        assert chunked.stats["n_steps"] == normal.stats["n_steps"]
        assert chunked.events.kind == normal.events.kind and len(normal.events) > 5
        np.testing.assert_array_equal(chunked.events.t, normal.events.t)
        np.testing.assert_array_equal(chunked.t, normal.t)


def test_runs_with_output_times_come_back_in_long_pieces(monkeypatch):
    """With output times the C loop stores the steps' times alone, in buffers 16 times longer than
    the state buffers: the 4200 steps of two revolutions come back in one advance (each piece is
    made consistent and checked apart); tiny buffers (48 rows) give the same run in many pieces."""
    import functools

    import daeclear.solvers.ida as solve_module
    from daeclear.engine.c_session import CSession
    from daeclear.engine.ida_session import open_session

    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    calls = []
    advance = CSession.advance
    monkeypatch.setattr(CSession, "advance", lambda self, *a, **k: calls.append(1) or advance(self, *a, **k))
    t_eval = np.linspace(0.0, 0.024, 129)
    whole = dc.simulate(model, 0.024, save=dc.SaveAt(times=t_eval))
    assert whole.stats["n_steps"] > 4096 and len(whole.events) > 20 and len(calls) == 1
    calls.clear()
    monkeypatch.setattr(solve_module, "open_session", functools.partial(open_session, buffer_steps=3))
    pieces = dc.simulate(model, 0.024, save=dc.SaveAt(times=t_eval))
    assert len(calls) > 80
    assert pieces.stats["n_steps"] == whole.stats["n_steps"]
    np.testing.assert_array_equal(pieces.step_t, whole.step_t)
    np.testing.assert_array_equal(pieces.events.t, whole.events.t)
    np.testing.assert_array_equal(pieces.y, whole.y)
    for name in ("clearance.normal_force", "drive.moment"):
        np.testing.assert_array_equal(pieces.channels[name], whole.channels[name])


# ---------------------------------------------------------------- where the contact force acts (issue 47)

G, R_B, C_B, MASS, INERTIA, MU, SPIN = 9.81, 10e-3, 0.5e-3, 0.1, 1e-5, 0.1, 200.0
SIGMA = (1 - 0.3**2) / 207e9  # steel, eq. (3.4)
STEEL_K = 4 / (3 * 2 * SIGMA) * np.sqrt(R_B * (R_B - C_B) / C_B)  # (3.5), journal in bearing: 6.61e10 N/m^1.5


def braked_journal(bearing_free: bool = False) -> dc.Scene:
    """A journal spinning at 200 rad/s dropped into its bearing (on the ground, or a free ring) with
    modified Coulomb friction 0.1: the friction at the contact point brakes the spin."""
    from daeclear.contact import LankaraniNikravesh, Material, ModifiedCoulomb

    scene = dc.Scene("brake", gravity=(0.0, 0.0 if bearing_free else -G))
    bearing = scene.add(dc.Body("ring", mass=1.0, inertia=1e-4)) if bearing_free else scene.ground
    journal = scene.add(dc.Body("journal", mass=MASS, inertia=INERTIA, angular_velocity=SPIN))
    scene.add(RevoluteClearance("bearing", bearing, journal, at=(0, 0), bearing_radius=R_B, clearance=C_B,
                                material=Material(young=207e9, poisson=0.3),
                                law=LankaraniNikravesh(restitution=0.5), friction=ModifiedCoulomb(coefficient=MU)))
    return scene


@pytest.mark.parametrize("angle", [-np.pi / 2, 0.4, 2.5])
def test_friction_acts_at_the_contact_points_moment_by_hand(angle):
    """One state in contact, by hand: eccentricity c + delta along n = (cos a, sin a), journal spinning
    at w_j, bearing ring at w_b, centres still. F_N = K delta^1.5 (no penetration rate), the sliding
    velocity of the contact points v_T = w_j R_j - w_b R_b along t (n turned +90 deg), F_T = -mu F_N
    sign(v_T); the journal gets -F_N n + F_T t and the moment R_j F_T about its centre, the ring the
    opposite force and the moment -R_b F_T (the force at the contact points Q, not at the centres)."""
    model = dc.assemble(braked_journal(bearing_free=True))
    names = model.state_names
    delta, w_j, w_b = 3e-6, SPIN, 50.0
    n, t = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    y = np.zeros(model.n_states)
    y[names.index("journal.x")], y[names.index("journal.y")] = (C_B + delta) * n
    y[names.index("journal.omega")], y[names.index("ring.omega")] = w_j, w_b
    Q = model.term_forces(0.0, y, [True], [np.array([1.0])])  # the latched approach speed: no rate, no damping
    R_j = R_B - C_B
    v_T = w_j * R_j - w_b * R_B
    F_N = STEEL_K * delta**1.5
    F_T = -MU * F_N * np.sign(v_T)
    f = -F_N * n + F_T * t
    journal = [names.index(f"journal.{k}") for k in ("x", "y", "phi")]
    ring = [names.index(f"ring.{k}") for k in ("x", "y", "phi")]
    np.testing.assert_allclose(Q[journal], [*f, R_j * F_T], rtol=1e-4)
    np.testing.assert_allclose(Q[ring], [*-f, -R_B * F_T], rtol=1e-4)
    assert abs(R_j * F_T) == pytest.approx(MU * F_N * R_j, rel=1e-4) and F_N > 0.5  # the moment mu F_N R


@pytest.fixture(scope="module")
def braked_run():
    return dc.simulate(braked_journal(), 0.2, rtol=1e-8, save=dc.SaveAt(times=np.linspace(0.0, 0.2, 20001)))


def test_friction_brakes_a_spinning_journal_angular_momentum_and_energy(braked_run):
    """After the last impact the journal slides on the wall (it swings about the friction angle).
    Angular momentum about its centre: I (w(t) - w(t_a)) = integral of R_j F_T dt; energy: the
    mechanical energy changes by the work of the contact forces at the contact points, integral of
    (-F_N d delta/dt + F_T v_T) dt, friction work included (channels: normal and friction force,
    penetration rate, sliding velocity). Force at the centres instead: the spin stays 200 rad/s."""
    from scipy.integrate import cumulative_trapezoid

    run = braked_run
    assert run.success
    t_a = run.events[-1].t
    assert run.events[-1].kind == "onset" and t_a < 0.1
    k = run.t > t_a
    assert np.all(run["bearing.in_contact"][k] > 0)  # sliding contact from t_a on
    t, w = run.t[k], run["journal.omega"][k]
    F_N, F_T = run["bearing.normal_force"][k], run["bearing.friction_force"][k]
    v_T, rate = run["bearing.sliding_velocity"][k], run["bearing.penetration_rate"][k]
    R_j = R_B - C_B
    assert np.all(v_T > 1.5) and np.all(F_T == pytest.approx(-MU * F_N, rel=1e-12))
    moment = cumulative_trapezoid(R_j * F_T, t, initial=0.0)
    assert w[-1] < w[0] - 10.0  # measured: 200 -> 180.9 rad/s in 0.2 s
    np.testing.assert_allclose(INERTIA * (w - w[0]), moment, rtol=0, atol=1e-5 * abs(moment[-1]))
    energy = run["energy.mechanical"][k]
    work = cumulative_trapezoid(-F_N * rate + F_T * v_T, t, initial=0.0)
    friction_work = cumulative_trapezoid(F_T * v_T, t, initial=0.0)[-1]
    assert friction_work < -0.02  # J, most of the change
    np.testing.assert_allclose(energy - energy[0], work, rtol=0, atol=1e-5 * abs(friction_work))
