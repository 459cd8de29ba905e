"""The contact-mode automaton of one pair: the one definition of the event rule.

A pair is *free* or in *contact*, and may be *held* by the storm guard; at a root of its gap
:func:`step` decides onset, separation, a hold or nothing (the rule: docs/user_guide.md, "Contact
events"). :func:`step` is pure; the compiled IDA loop runs its C mirror (``pair_step`` in
``csrc/ida_driver.c``) and ``tests/test_automaton.py`` requires identical decisions from both.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field, replace
from typing import Final, Literal

#: Storm guard defaults: this many switches of one pair within STORM_WINDOW seconds hold its term on.
STORM_EVENTS: Final[int] = 20
STORM_WINDOW: Final[float] = 1e-6

#: A crossing against the rate this close to the pair's last switch, relative to t, is the gap's
#: round-off at that switch (2**20 ulps: 2.3e-11 s at t = 0.1 s; C: dc_abi.h's DC_SAME_INSTANT).
SAME_INSTANT: Final[float] = 2**20 * 2.220446049250313e-16

#: Decision kinds (the values the C loop reports) and the event kinds they make.
NONE: Final[int] = 0
ONSET: Final[int] = 1
SEPARATION: Final[int] = -1
EVENT_KINDS: Final[dict[int, Literal["onset", "separation"]]] = {ONSET: "onset", SEPARATION: "separation"}


@dataclass(frozen=True)
class Storm:
    """Storm-guard constants: ``events`` switches within ``window`` seconds hold the term on."""

    events: int = STORM_EVENTS
    window: float = STORM_WINDOW

    def __post_init__(self) -> None:
        if isinstance(self.events, bool) or not isinstance(self.events, numbers.Integral) or self.events < 1:
            raise ValueError(f"Storm: events={self.events!r}, must be an integer >= 1.")
        if not (isinstance(self.window, numbers.Real) and math.isfinite(self.window) and self.window >= 0):
            raise ValueError(f"Storm: window={self.window!r} s, must be a finite number >= 0.")
        object.__setattr__(self, "events", int(self.events))  # plain numbers for C and for equality
        object.__setattr__(self, "window", float(self.window))


#: The storm guard's default constants (frozen: every pair without its own shares them).
DEFAULT_STORM: Final[Storm] = Storm()


@dataclass(frozen=True)
class PairState:
    """What the automaton remembers of one pair: ``recent``, the times of the last ``storm.events``
    switches (oldest first); ``free_since``, the start of a held pair's flight; ``latched``, the
    approach speed latched at the last onset (floored)."""

    contact: bool = False
    held: bool = False
    free_since: float = 0.0
    latched: float = 0.0
    recent: tuple[float, ...] = field(default=())

    @property
    def term_on(self) -> bool:
        """The pair's force term is on in contact and while held."""
        return self.contact or self.held

    @property
    def watch(self) -> int:
        """Root direction to watch next: onsets (+1) while free, separations (-1) in contact, both (0) held."""
        return 0 if self.held else -1 if self.contact else 1


@dataclass(frozen=True)
class Decision:
    """The outcome of one root: event ``kind`` (ONSET, SEPARATION or NONE) and the pair's new mode."""

    kind: int
    contact: bool
    held: bool
    latched: float
    watch: int

    @property
    def term_on(self) -> bool:
        return self.contact or self.held


def floor_speed(rate: float, min_approach_speed: float) -> float:
    """The approach speed latched at an onset: the rate, floored (a NaN rate gives the floor, as C's fmax)."""
    return rate if rate > min_approach_speed else min_approach_speed


def start(in_contact: bool, rate: float, min_approach_speed: float) -> PairState:
    """A pair's state at the start of a run: its mode from the initial gap, its rate latched, no history."""
    return PairState(contact=bool(in_contact), latched=floor_speed(rate, min_approach_speed))


def decision_of(state: PairState, kind: int) -> Decision:
    """The decision that leaves the pair in ``state``."""
    return Decision(kind, state.contact, state.held, state.latched, state.watch)


def step(state: PairState, t: float, direction: int, rate: float, *, storm: Storm,
         min_approach_speed: float) -> tuple[PairState, Decision]:
    """Decide a root of the pair's gap at time ``t`` (non-decreasing per pair) crossed in
    ``direction`` with penetration rate ``rate``; return the new state and the decision."""
    if direction != 0 and state.held:
        if direction < 0:
            state, direction = replace(state, free_since=t), 0  # the held pair's flight starts again
        elif t - state.free_since <= storm.window:
            direction = 0  # a re-contact inside the storm: the held term stays as it is
        else:
            state = replace(state, held=False)  # a genuine onset after a real flight
    if direction > 0 and not state.contact and rate < 0 and _same_instant(state, t):
        return state, decision_of(state, NONE)  # the round-off of the gap after a separation, not an onset
    if direction > 0 and not state.contact:
        state = replace(state, contact=True, latched=floor_speed(rate, min_approach_speed),
                        recent=_push(state.recent, t, storm))
        return state, decision_of(state, ONSET)
    if direction < 0 and state.contact and rate > 0 and _same_instant(state, t):
        return state, decision_of(state, NONE)  # the round-off of the gap after an onset, not a separation
    if direction < 0 and state.contact:
        hold = 1 + sum(1 for s in state.recent if t - s < storm.window) >= storm.events
        state = replace(state, contact=False, held=hold, free_since=t if hold else state.free_since,
                        recent=_push(state.recent, t, storm))
        return state, decision_of(state, SEPARATION)
    return state, decision_of(state, NONE)


def recorded(state: PairState, decision: Decision) -> PairState:
    """The state after a decision taken by the compiled loop (which keeps the storm history)."""
    # the constructor, not dataclasses.replace: this runs at every event of a compiled run
    return PairState(contact=decision.contact, held=decision.held, free_since=state.free_since,
                     latched=decision.latched, recent=state.recent)


def _same_instant(state: PairState, t: float) -> bool:
    """Whether ``t`` is within round-off of the pair's last switch (``SAME_INSTANT`` relative to t)."""
    return bool(state.recent) and t - state.recent[-1] <= abs(t) * SAME_INSTANT


def _push(recent: tuple[float, ...], t: float, storm: Storm) -> tuple[float, ...]:
    """The last ``storm.events`` switch times after a switch at ``t`` (C keeps the same ring)."""
    return (recent + (t,))[-storm.events:]
