"""The jump formulas of forward sensitivities at an event (daeclear/solvers/sensitivity_jumps.py, issue 43
item 3), each against the complex-step derivative of a closed-form solution that switches at the event.

Closed forms: a falling ball (its time of flight), and a mass whose acceleration switches from a1 to a2
where its position crosses c (x'' = a1 while x < c, a2 after): the sensitivities before the switch are
closed forms too, the jump formulas carry them through it, a closed form carries them to T.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from daeclear.core.errors import PhysicsWarning
from daeclear.solvers.sensitivity_jumps import (GRAZING_ERROR, ROUNDOFF, event_time_sensitivity, grazing_limit,
                                                is_grazing, latched_sensitivity, same_event_times, state_jump)

RTOL = 1e-10


def complex_step(f, p: np.ndarray) -> np.ndarray:
    """d f / d p_j for every j (f real-analytic): Im f(p + i h e_j) / h, exact to round-off."""
    h = 1e-30
    return np.array([np.imag(f(p + 1j * h * np.eye(p.size)[j])) / h for j in range(p.size)]).T


def test_event_time_of_a_falling_ball() -> None:
    """y = h - g t^2/2 reaches 0 at t* = sqrt(2h/g): dt*/dh = 1/sqrt(2hg), dt*/dg = -t*/(2g).
    S = dy/d(h, g) = (1, -t^2/2) at t*, g_y = 1, rate y' = -g t*."""
    h, g = 2.0, 9.81
    t_star = np.sqrt(2 * h / g)
    dt = event_time_sensitivity(np.array([1.0, -t_star ** 2 / 2]), -g * t_star, g * t_star, rtol=RTOL,
                                event="'ball' onset")
    want = complex_step(lambda p: np.sqrt(2 * p[0] / p[1]), np.array([h, g]))
    assert dt == pytest.approx(want, rel=1e-14, abs=0.0)
    assert dt == pytest.approx([1 / np.sqrt(2 * h * g), -t_star / (2 * g)], rel=1e-14, abs=0.0)


# x'' = a1 for x < c, a2 after; x(0) = 0, x'(0) = v0. Parameters p = (c, v0, a1, a2), T after the switch.
T = 1.0
P0 = np.array([0.3, 0.8, -0.2, -5.0])


def switch_time(p: np.ndarray) -> complex:
    c, v0, a1, _ = p
    return (-v0 + np.sqrt(v0 ** 2 + 2 * a1 * c)) / a1  # the first root of v0 t + a1 t^2 / 2 = c


def closed_form(p: np.ndarray) -> np.ndarray:
    """(x(T), v(T), v at the switch)."""
    c, v0, a1, a2 = p
    ts = switch_time(p)
    vs = v0 + a1 * ts
    tau = T - ts
    return np.array([c + vs * tau + a2 * tau ** 2 / 2, vs + a2 * tau, vs])


def through_the_switch(jump: bool) -> tuple[np.ndarray, np.ndarray]:
    """(S(T) of (x, v), the switch speed's sensitivity) by the formulas: closed-form S before the switch,
    the event time's and the state's jump, then S' = (S_v, da2/dp) in the new mode."""
    c, v0, a1, a2 = P0
    ts = float(np.real(switch_time(P0)))
    vs = v0 + a1 * ts
    # before the switch x = v0 t + a1 t^2/2: S = d(x, v)/d(c, v0, a1, a2) at fixed t
    S_minus = np.array([[0.0, ts, ts ** 2 / 2, 0.0], [0.0, 1.0, ts, 0.0]])
    g_p = S_minus[0] - np.array([1.0, 0.0, 0.0, 0.0])  # g = x - c
    dt = event_time_sensitivity(g_p, vs, abs(vs), rtol=RTOL, event="'x' crossing c")
    S_plus = state_jump(S_minus, [vs, a1], [vs, a2], dt if jump else np.zeros(4), [True, True])
    latched = latched_sensitivity(S_minus[1], a1, dt if jump else np.zeros(4), floored=False)
    tau = T - ts
    da2 = np.array([0.0, 0.0, 0.0, 1.0])
    S_T = np.array([S_plus[0] + S_plus[1] * tau + da2 * tau ** 2 / 2, S_plus[1] + da2 * tau])
    return S_T, latched


def test_state_jump_carries_the_sensitivities_through_a_switch() -> None:
    """S+ = S- + (y'- - y'+) dt*/dp: the position's and the velocity's sensitivities at T to (c, v0, a1, a2)
    equal the complex-step derivatives of the closed form; without the jump they do not."""
    want = complex_step(closed_form, P0)
    S_T, _ = through_the_switch(jump=True)
    assert S_T == pytest.approx(want[:2], rel=1e-12, abs=1e-14)
    wrong, _ = through_the_switch(jump=False)
    assert np.abs(wrong - want[:2]).max() > 0.1 * np.abs(want[:2]).max()


def test_latched_value_includes_the_event_time_term() -> None:
    """The speed at the switch, v(t*(p), p): v_y S- + v_p + (v_y y'- + v_t) dt*/dp (here S-_v + a1 dt*/dp)."""
    want = complex_step(closed_form, P0)[2]
    _, latched = through_the_switch(jump=True)
    assert latched == pytest.approx(want, rel=1e-12, abs=1e-14)
    _, wrong = through_the_switch(jump=False)
    assert np.abs(wrong - want).max() > 0.1 * np.abs(want).max()
    assert not latched_sensitivity(np.ones(3), 2.0, np.ones(3), floored=True).any()  # a floored value is constant


def test_state_jump_moves_only_the_states_whose_rate_jumps() -> None:
    """A state continuous with a continuous rate keeps S exactly (even with a NaN dt*/dp); an algebraic one
    (not ``continuous``) is left for the consistent re-solve."""
    S = np.arange(6.0).reshape(3, 2)
    out = state_jump(S, [1.0, 2.0, 3.0], [1.0, 5.0, 0.0], np.array([np.nan, 1.0]), [True, True, False])
    assert np.array_equal(out[0], S[0]) and np.array_equal(out[2], S[2])
    assert np.isnan(out[1, 0]) and out[1, 1] == S[1, 1] - 3.0


def test_a_barely_reached_wall_has_no_event_time_derivative() -> None:
    """y = v0 t - g t^2/2 against a wall at c just below the apex v0^2/(2g): the crossing speed
    sqrt(v0^2 - 2 g c) -> 0 and dt*/dc = 1/speed blows up; the rate's one term does not cancel, the
    tangency test sees it (g'' = -g, the gap known to 1e-10 m). Below the limit: NaN and a PhysicsWarning
    naming the event; above it, the closed form."""
    v0, g, gap_error = 1.0, 9.81, 1e-10
    for gap, grazing in ((1e-14, True), (1e-6, False)):  # crossing speeds 4e-7 and 4e-3 m/s
        c = v0 ** 2 / (2 * g) - gap
        speed = np.sqrt(v0 ** 2 - 2 * g * c)
        assert speed > 0
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # the gap's one term: |g_y y'| = speed
            dt = event_time_sensitivity(np.array([-1.0]), speed, speed, rtol=1e-8, event="'wall' onset at t=0.1 s",
                                        curvature=-g, gap_error=gap_error)
        if grazing:
            assert np.isnan(dt).all()
            assert [w.category for w in caught] == [PhysicsWarning]
            assert "'wall' onset at t=0.1 s is grazing" in str(caught[0].message)
        else:
            assert not caught
            want = complex_step(lambda p: (v0 - np.sqrt(v0 ** 2 - 2 * g * p[0])) / g, np.array([c]))[0]
            assert dt == pytest.approx(want, rel=1e-6, abs=0.0)


def test_a_tangential_approach_has_no_event_time_derivative() -> None:
    """A journal sliding round its bearing: the gap's rate e.e'/c sums terms of 1 m/s that cancel to
    1e-9 m/s: below the run's resolution of them (rtol 1e-8), NaN; 1e-3 m/s of them is a number."""
    for rate, grazing in ((1e-9, True), (1e-3, False)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            dt = event_time_sensitivity(np.array([2.0]), rate, 2.0, rtol=1e-8, event="'C' onset")
        assert np.isnan(dt).all() == grazing and len(caught) == grazing
        if not grazing:
            assert dt[0] == -2.0 / rate


def test_grazing_limit_follows_the_tolerance() -> None:
    """A rate is transversal when its uncertainty, (rtol + round-off) times its terms' magnitude, is below
    GRAZING_ERROR of it: the limit scales with rtol and with the scale; NaN is grazing."""
    assert grazing_limit(2.0, 1e-6) == pytest.approx(2.0 * (1e-6 + ROUNDOFF) / GRAZING_ERROR, rel=1e-15, abs=0.0)
    assert grazing_limit(1.0, 1e-10) < grazing_limit(1.0, 1e-6) / 1e3
    assert is_grazing(1e-5, 1.0, 1e-6) and not is_grazing(1e-3, 1.0, 1e-6)
    assert is_grazing(float("nan"), 1.0, 1e-6) and is_grazing(0.0, 0.0, 1e-6)
    # tangency: rate^2 against |g''| gap_error / GRAZING_ERROR
    assert is_grazing(1e-3, 1e-3, 1e-12, curvature=10.0, gap_error=1.01e-9)
    assert not is_grazing(1e-3, 1e-3, 1e-12, curvature=-10.0, gap_error=0.99e-9)


def test_simultaneous_events_must_move_together() -> None:
    a = np.array([1.0, -2.0])
    assert same_event_times([a, a * (1 + 1e-9)], 1e-8)
    assert not same_event_times([a, np.array([1.0, -1.0])], 1e-8)
