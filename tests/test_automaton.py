"""The contact-mode automaton (daeclear.core.automaton) and its C mirror in the compiled IDA loop.

The randomized tests feed the same root sequences (bursts inside the storm window, random
directions and rates, varied storm constants) to the Python automaton and to the compiled one
(``dc_automaton_run``) and require identical decisions. The end-to-end tests run mechanisms with
small storm constants, so that pairs are held and released, on the compiled loop (which decides
every switch itself) and on the pure-Python backend (whose pair logic decides), and require the
same events.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest

import daeclear as dc
from daeclear.core import automaton
from daeclear.core.automaton import NONE, ONSET, SEPARATION, Decision, PairState, Storm, step
from daeclear.engine.ida_session import CSession, open_session


@pytest.fixture(scope="module")
def c_session():
    """A compiled session of the revolute slider-crank: its library carries the C automaton."""
    model = _slider_crank("revolute", None)
    session = open_session(model.functions, backend="c", rtol=1e-6, atol=1e-8, parameters=model.parameter_values)
    yield session
    session.close()


def python_run(times, directions, rates, *, storm, min_approach_speed, state):
    """The Python automaton's decisions over a root sequence."""
    out = []
    for t, d, r in zip(times, directions, rates):
        state, decision = step(state, float(t), int(d), float(r), storm=storm, min_approach_speed=min_approach_speed)
        out.append(decision)
    return out


def test_compiled_automaton_takes_the_python_decisions(c_session):
    """3000 random root sequences (60 000 roots): the C automaton decides exactly as the Python one
    (kind, mode, hold, latched speed, next direction), from every kind of starting state."""
    rng = np.random.default_rng(20240611)
    seen = {"onset": 0, "separation": 0, "none": 0, "hold": 0, "release": 0, "nan": 0, "same_instant": 0}
    for _ in range(3000):
        storm = Storm(int(rng.integers(1, 9)), float(rng.choice([0.0, 1e-9, 1e-6, 1e-3, 10 ** rng.uniform(-8, -2)])))
        vmin = float(rng.choice([0.0, 1e-4, 10 ** rng.uniform(-6, 0)]))
        held = bool(rng.random() < 0.2)
        start = PairState(contact=bool(rng.random() < 0.5) and not held, held=held, latched=float(rng.uniform(0, 2)))
        times, directions, rates = _sequence(rng, 20, start, storm, vmin)
        expected = python_run(times, directions, rates, storm=storm, min_approach_speed=vmin, state=start)
        got = c_session.automaton_run(times, directions, rates, storm=storm, min_approach_speed=vmin,
                                      contact=start.contact, held=start.held, latched=start.latched)
        assert got == expected, (storm, vmin, start, times, directions, rates)
        before = start
        for direction, r, dec in zip(directions, rates, expected):
            seen["onset"] += dec.kind == ONSET
            seen["separation"] += dec.kind == SEPARATION
            seen["none"] += dec.kind == NONE
            seen["hold"] += dec.kind == SEPARATION and dec.held
            seen["release"] += dec.kind == ONSET and before.held
            seen["nan"] += dec.kind == ONSET and math.isnan(r)
            seen["same_instant"] += dec.kind == NONE and not before.held and direction == before.watch  # the guard
            before = PairState(contact=dec.contact, held=dec.held)
    # every branch of the rule was taken many times
    assert min(seen.values()) > 50, seen


def _sequence(rng: np.random.Generator, n: int, state: PairState, storm: Storm,
              vmin: float) -> tuple[list[float], list[int], list[float]]:
    """Roots with bursts inside the storm window, mostly in the watched direction (as IDA reports
    them), sometimes in the other or none; rates of either sign, at the floor, or NaN."""
    w = storm.window if storm.window > 0 else 1e-6
    t, times, directions, rates = float(rng.uniform(0, 1)), [], [], []
    burst = 0
    for _ in range(n):
        if burst == 0 and rng.random() < 0.15:
            burst = int(rng.integers(2, 3 * storm.events + 3))  # a cascade of quick switches
        if burst:
            burst -= 1
            gap = float(rng.choice([0.0, rng.uniform(0, w / storm.events), rng.uniform(0, w)]))
        else:
            gap = float(rng.choice([w, w * rng.uniform(0.9, 1.1), w * rng.uniform(1, 100), rng.uniform(0, w)]))
        t += gap
        u = rng.random()
        if u < 0.75:
            d = state.watch or int(rng.choice([-1, 1]))
        elif u < 0.95:
            d = int(rng.choice([-1, 1]))
        else:
            d = 0
        v = rng.random()
        rate = vmin if v < 0.1 else float("nan") if v < 0.13 else float(rng.normal(0, 10 * vmin + 1e-3))
        state, _ = step(state, t, d, rate, storm=storm, min_approach_speed=vmin)
        times.append(t)
        directions.append(d)
        rates.append(rate)
    return times, directions, rates


# --------------------------------------------------------------------------- the rule


RULE = dict(storm=Storm(3, 1e-6), min_approach_speed=1e-4)


def test_onset_latches_the_floored_speed_and_separation_frees():
    state, d = step(PairState(), 1.0, +1, 2e-5, **RULE)
    assert d == Decision(ONSET, True, False, 1e-4, -1) and d.term_on
    state, d = step(state, 1.1, +1, 0.5, **RULE)  # an upward crossing in contact decides nothing
    assert d.kind == NONE and d.latched == 1e-4
    state, d = step(state, 1.2, -1, -0.3, **RULE)
    assert d == Decision(SEPARATION, False, False, 1e-4, +1) and not d.term_on
    assert step(state, 1.3, 0, 1.0, **RULE)[1].kind == NONE


def test_storm_holds_ignores_quick_recontacts_and_releases_after_a_flight():
    state, t = PairState(), 0.0
    for _ in range(2):  # onset, separation, onset: three switches within the window...
        state, _ = step(state, t := t + 1e-8, +1, 1.0, **RULE)
        state, d = step(state, t := t + 1e-8, -1, -1.0, **RULE)
        if d.held:
            break
    assert d == Decision(SEPARATION, False, True, 1.0, 0) and d.term_on  # ...the third one holds
    state, d = step(state, t + 1e-8, +1, 2.0, **RULE)  # a quick re-contact changes nothing
    assert d.kind == NONE and d.held
    state, d = step(state, t + 2e-8, -1, -2.0, **RULE)  # the flight starts again
    assert d.kind == NONE and state.free_since == t + 2e-8
    state, d = step(state, t + 2e-8 + RULE["storm"].window, +1, 3.0, **RULE)  # not longer than the window
    assert d.kind == NONE and d.held
    state, d = step(state, t + 3e-8 + RULE["storm"].window, +1, 3.0, **RULE)
    assert d == Decision(ONSET, True, False, 3.0, -1)  # a genuine impact: hold ends, speed latched


@pytest.mark.parametrize("events", [2, 3, 4, 20])
def test_the_storm_holds_at_exactly_its_count_of_switches(events):
    """Storm(n, window): a separation holds the term on when it makes n switches or more within the
    window, itself included. Onsets and separations alternate a nanosecond apart, so the first held
    separation is switch number n (n even) or n + 1 (n odd: the n-th switch is an onset)."""
    rule = dict(storm=Storm(events, 1e-6), min_approach_speed=1e-4)
    state, t, switches = PairState(), 0.0, 0
    while True:
        state, d = step(state, t := t + 1e-9, +1, 1.0, **rule)
        state, d = step(state, t := t + 1e-9, -1, -1.0, **rule)
        switches += 2
        assert d.kind == SEPARATION
        if d.held:
            break
    assert switches == events + events % 2


def test_storm_constants_are_checked():
    assert (Storm().events, Storm().window) == (automaton.STORM_EVENTS, automaton.STORM_WINDOW)
    for bad in (dict(events=0), dict(events=2.0), dict(window=-1e-6), dict(window=math.inf)):
        with pytest.raises(ValueError):
            Storm(**bad)


def test_pair_logic_and_slider_corners_decide_by_the_automaton():
    """PairLogic and each corner of SliderGuideLogic make exactly the automaton's decisions: events,
    terms, latched speeds and watched directions, through holds and releases."""
    rng = np.random.default_rng(7)
    storm = Storm(3, 1e-6)
    for kind in ("revolute", "translational"):
        model = _slider_crank(kind, storm)
        logic = model.contacts[0]
        names = [term.name for term in model.terms]
        y0 = model.initial_state()[0]
        own = logic.start(0.0, y0)  # the element's part of a run's contact state: passed in, returned
        states = {root: own[logic.pair_index(root)] for root in logic.roots}
        t, kinds = 0.0, set()
        for _ in range(400):
            root = int(rng.choice(list(logic.roots)))
            t += float(rng.choice([1e-9, 3e-7, 2e-6]))  # many switches inside the storm window
            y = y0 + rng.normal(0, 1e-5, y0.size)
            rate = float(np.ravel(logic.rate(y[:model.n_q], y[model.n_q:2 * model.n_q])[1])[root - logic.roots[0]])
            direction = states[root].watch or int(rng.choice([-1, 1]))
            found = np.zeros(len(model.gap_names), dtype=np.int32)
            found[root] = direction
            own, events = logic.decide(own, t, y, found)
            states[root], decision = step(states[root], t, direction, rate, storm=storm,
                                          min_approach_speed=logic.min_approach_speed)
            expected = {ONSET: ["onset"], SEPARATION: ["separation"]}.get(decision.kind, [])
            assert [e.kind for e in events if e.pair == model.gap_names[root]] == expected
            assert own[logic.pair_index(root)] == states[root]  # the very state of the automaton
            term = names.index(model.gap_names[root])
            switches = {k: (on, p) for k, on, p in logic.terms(own)}
            assert switches[term][0] == decision.term_on
            assert dict(logic.root_directions(own))[root] == decision.watch
            if logic.needs_approach:
                assert switches[term][1][0] == states[root].latched
            kinds.add((decision.kind, decision.held))
        assert {(ONSET, False), (SEPARATION, False), (SEPARATION, True), (NONE, True)} <= kinds


# --------------------------------------------------------------------------- end to end


def _slider_crank(kind: str, storm: Storm | None) -> dc.DAEModel:
    scene = dc.mechanisms.slider_crank(kind, gravity=0.0) if kind == "revolute" else dc.mechanisms.slider_crank(kind)
    model = dc.assemble(scene, "index1")  # step for step on both backends (GGL's Newton coefficient: C only)
    if storm is not None:  # the rules are frozen: a model with other rules is a new value
        contacts = tuple(dataclasses.replace(logic, storm=storm) for logic in model.contacts)
        model = dataclasses.replace(model, contacts=contacts)
    return model


@pytest.mark.parametrize("kind, storm", [("revolute", Storm(4, 5e-4)), ("revolute", Storm(2, 1e-4)),
                                         ("translational", Storm(2, 1e-3))])
def test_compiled_and_python_backends_decide_the_same_storms(kind, storm, plain_ida):
    """Small storm constants hold and release pairs; the compiled loop (deciding every switch itself)
    and the python backend (the pair logic deciding) take the same decisions, so the runs agree:
    same events, times, approach speeds, steps and modes. (Before the automaton was shared, the
    revolute run with Storm(4, 5e-4) gave 8 events compiled and 12 in Python, both successful.)"""
    model = _slider_crank(kind, storm)
    assert model.auto_pairs
    fast = dc.simulate(model, 0.012, rtol=1e-8, options=dc.SolverOptions(backend="c", linear_solver=plain_ida))
    held_fast = fast.stats["held_pairs"]  # pairs held at the end (a run's state: the model keeps none)
    slow = dc.simulate(model, 0.012, rtol=1e-8, options=dc.SolverOptions(backend="python"))
    held_slow = slow.stats["held_pairs"]
    unguarded = dc.simulate(_slider_crank(kind, None), 0.012, rtol=1e-8, options=dc.SolverOptions(backend="c"))
    assert len(fast.events) < len(unguarded.events)  # the storm guard held pairs through bounces
    assert fast.success and slow.success and held_fast == held_slow
    assert len(fast.events) == len(slow.events) > 5
    assert fast.events.kind == slow.events.kind
    assert [e.pair for e in fast.events] == [e.pair for e in slow.events]
    np.testing.assert_allclose(fast.events.t, slow.events.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(fast.events.approach_speed, slow.events.approach_speed, rtol=1e-12)
    assert fast.stats["n_steps"] == slow.stats["n_steps"]
    assert fast.stats["n_restarts"] == slow.stats["n_restarts"]
    assert [m for *_, m in fast.segments] == [m for *_, m in slow.segments]
    # every reported point carries its segment's contact terms and latched speeds (the compiled
    # loop's switch vectors, recorded per restart): the contact forces agree point for point
    np.testing.assert_allclose(fast.t, slow.t, rtol=0, atol=1e-15)
    forces = [name for name in fast.channels if name.endswith(("normal_force", "in_contact"))]
    assert forces and max(np.max(fast.channels[name]) for name in forces) > 100.0
    for name in [*forces, "drive.moment"]:
        scale = np.max(np.abs(slow.channels[name]))
        np.testing.assert_allclose(fast.channels[name], slow.channels[name], rtol=0, atol=1e-6 * scale, err_msg=name)


@pytest.mark.parametrize("kind, storm", [("revolute", Storm(4, 5e-4)), ("translational", Storm(2, 1e-3))])
def test_the_run_state_read_from_the_compiled_loop_gives_its_terms(kind, storm, monkeypatch):
    """The compiled loop holds the states of the pairs it decides and the IDA loop reads them (no
    replay): after every advance the terms and latched speeds that state implies are the loop's
    own (dc_get_active), and the recorded switch vector is the same."""
    from daeclear.assembly import contact_state
    from daeclear.solvers.driver import Driver

    model = _slider_crank(kind, storm)
    checked: list[int] = []
    take = Driver.take_pair_states

    def take_and_check(loop):
        take(loop)
        active, params = contact_state.switches(model, loop.state)
        implied = model.switch_vector(active, params)
        assert loop.integrator.session.active_switch().tolist() == implied.tolist() == loop.switch.tolist()
        checked.append(sum(st.contact or st.held for states in loop.state for st in states))

    monkeypatch.setattr(Driver, "take_pair_states", take_and_check)
    monkeypatch.setattr(CSession, "set_auto_events",  # the loop returns after every switch: many checks
                        functools.partialmethod(CSession.set_auto_events, capacity=1))
    result = dc.simulate(model, 0.012, rtol=1e-8, options=dc.SolverOptions(backend="c"))
    assert result.success and len(result.events) > 5 and len(checked) > 5 and max(checked) >= 1


def test_a_small_event_buffer_is_drained_between_chunks(monkeypatch):
    """An event buffer of one event per pair makes the C loop return after every switch; the run
    is the same."""
    model = _slider_crank("translational", Storm(2, 1e-3))
    normal = dc.simulate(model, 0.012, rtol=1e-8)
    monkeypatch.setattr(CSession, "set_auto_events",
                        functools.partialmethod(CSession.set_auto_events, capacity=1))
    small = dc.simulate(model, 0.012, rtol=1e-8)
    assert small.events.kind == normal.events.kind and len(normal.events) > 5
    np.testing.assert_array_equal(small.events.t, normal.events.t)
    np.testing.assert_array_equal(small.t, normal.t)


@pytest.mark.parametrize("second_rate, gap, expected", [
    (1.36, 1, [ONSET, NONE, NONE]),  # issue 34: logged onset, separation, onset 1-2 ulps apart while approaching
    (-0.5, 1, [ONSET, SEPARATION, ONSET]),  # receding: a separation, however soon
    (1.36, None, [ONSET, SEPARATION, ONSET]),  # later than round-off of t can tell: decided as before
], ids=["round-off", "receding", "later"])
def test_a_crossing_at_the_instant_of_an_onset_while_approaching_is_no_separation(c_session, second_rate, gap,
                                                                                    expected):
    """A closing joint's gap at the restart after its onset is zero to round-off and may cross zero
    again one ulp of t later: that downward root, with the pair still approaching, decides nothing
    (Python and C alike), so the impact is counted once. (``gap`` None: twice the same-instant window.)"""
    t0 = 1.4e-3
    t1 = t0
    if gap is None:
        t1 = t0 * (1 + 2 * automaton.SAME_INSTANT)
    else:
        for _ in range(gap):
            t1 = float(np.nextafter(t1, 1.0))
    t2 = float(np.nextafter(t1, 1.0))
    times, directions, rates = [t0, t1, t2], [1, -1, 1], [1.36, second_rate, 1.36]
    start = PairState()
    python = python_run(times, directions, rates, storm=Storm(), min_approach_speed=0.0, state=start)
    compiled = c_session.automaton_run(times, directions, rates, storm=Storm(), min_approach_speed=0.0,
                                       contact=False, held=False, latched=0.0)
    assert [d.kind for d in python] == expected
    assert compiled == python
    assert python[-1].contact and python[-1].latched == 1.36


#: Root sequences of one corner of the Siconos slider-crank at rtol 1e-10 (benchmarks/external/
#: siconos_slider_crank.py), as the compiled loop located them: (t, direction, penetration rate).
SICONOS_ROOTS = {
    # guide.C_lower: an onset, then a downward root 51 ulps later still approaching. Decided as a
    # separation (the window was 16 ulps), it left the corner free inside its wall; IDA masked the
    # gap (exactly zero at the restart) and never found the onset again: 3.25 mm deep, no force.
    "onset, then round-off 51 ulps later": ([0.0665368513406839, 0.06653685134068461],
                                            [1, -1], [0.029805673014679044, 0.02980567302584971]),
    # guide.C_lower: a separation, then an upward root 137 ulps later still receding (logged as an
    # onset, and a separation again 253 ulps after it: one crossing reported three times)
    "separation, then round-off 137 ulps later": ([0.0663809579436353, 0.06638095794363667],
                                                  [-1, 1], [-0.027258451787577267, -0.02725845178598483]),
    # a slow separation (0.3 mm/s): the gap's round-off lasts longer, 7196 and then 47913 ulps
    "slow separation, round-off 7196 ulps later": ([0.17266575234803297, 0.1726657523482327],
                                                   [-1, 1], [-0.00030044001237379217, -0.000300440012913553]),
}


@pytest.mark.parametrize("case", sorted(SICONOS_ROOTS))
def test_a_crossing_against_the_rate_at_the_instant_of_a_switch_decides_nothing(c_session, case):
    """Within the same instant of its last switch (``SAME_INSTANT`` relative to t), a root against the
    sign of the pair's rate (downward while approaching, upward while receding) is the gap's
    round-off: no event, the mode stays (Python and C alike), and the genuine crossing a window later
    is decided."""
    times, directions, rates = SICONOS_ROOTS[case]
    first_contact = directions[0] < 0  # the first root is the pair's switch: onset from free, separation from contact
    start = PairState(contact=first_contact, latched=0.5)
    later = times[-1] * (1 + 2 * automaton.SAME_INSTANT)
    times, directions, rates = [*times, later], [*directions, directions[-1]], [*rates, rates[-1]]
    python = python_run(times, directions, rates, storm=Storm(), min_approach_speed=1e-4, state=start)
    compiled = c_session.automaton_run(times, directions, rates, storm=Storm(), min_approach_speed=1e-4,
                                       contact=start.contact, held=False, latched=start.latched)
    assert compiled == python
    switch = SEPARATION if first_contact else ONSET
    assert [d.kind for d in python] == [switch, NONE, -switch]
    assert python[1].contact == (not first_contact)  # the round-off root left the mode as the switch set it
