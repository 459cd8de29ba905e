"""A run's contact state: one value, passed in and returned, never kept by the model.

A :data:`ContactState` holds each pair's automaton state, one tuple per contact element of
``model.contacts`` (rules, no state); :func:`decide` returns the new state and the events, and
:func:`with_pairs` reads back the compiled loop's own decisions.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..core.events import ContactEvent
from ..core.automaton import PairState

if TYPE_CHECKING:
    from .dae_model import DAEModel

#: One tuple of pair states per contact element of the model, in ``model.contacts`` order.
ContactState = tuple[tuple[PairState, ...], ...]


def start_state(model: DAEModel, t: float, y: NDArray) -> ContactState:
    """Every pair's state at a run's start ``(t, y)``: its mode from its gap, its rate latched, no history."""
    return tuple(logic.start(t, y) for logic in model.contacts)


def switches(model: DAEModel, state: ContactState) -> tuple[list[bool], list[NDArray]]:
    """Which of the model's terms are on, and each term's parameters, in this state."""
    active = [False] * len(model.terms)
    params = [np.zeros(term.n_params) for term in model.terms]
    for logic, states in zip(model.contacts, state):
        for index, on, p in logic.terms(states):
            active[index], params[index] = on, p
    return active, params


def modes(model: DAEModel, state: ContactState) -> dict[str, str]:
    """``"contact"`` or ``"free"`` of every pair (and face) by name."""
    out: dict[str, str] = {}
    for logic, states in zip(model.contacts, state):
        out.update(logic.modes(states))
    return out


def root_directions(model: DAEModel, state: ContactState) -> NDArray | None:
    """The direction to watch of every root (+1 up, -1 down, 0 both); None without roots."""
    if not model.gap_names:
        return None
    d = np.zeros(len(model.gap_names), dtype=np.int32)
    for logic, states in zip(model.contacts, state):
        for index, direction in logic.root_directions(states):
            d[index] = direction
    return d


def decide(model: DAEModel, state: ContactState, t: float, y: NDArray, roots_found: NDArray | None
           ) -> tuple[ContactState, list[ContactEvent]]:
    """Decide the roots found at ``t`` (each element those of its gaps): the new state and the events."""
    new: list[tuple[PairState, ...]] = []
    events: list[ContactEvent] = []
    for logic, states in zip(model.contacts, state):
        after, found = logic.decide(states, t, y, roots_found)
        new.append(after)
        events += found
    return tuple(new), events


def pair_state(model: DAEModel, state: ContactState, root: int) -> PairState:
    """The state of the pair of gap ``root``."""
    for logic, states in zip(model.contacts, state):
        if root in logic.roots:
            return states[logic.pair_index(root)]
    raise IndexError(f"no contact pair watches root {root}")


def with_pairs(model: DAEModel, state: ContactState, pairs: Mapping[int, PairState]) -> ContactState:
    """The state with the pairs of the given roots replaced (the compiled loop's, which it decides)."""
    new = [list(states) for states in state]
    for k, logic in enumerate(model.contacts):
        for root in logic.roots:
            if root in pairs:
                new[k][logic.pair_index(root)] = pairs[root]
    return tuple(tuple(states) for states in new)


def continued_state(model: DAEModel, t: float, y: NDArray, carried: ContactState) -> ContactState:
    """Every pair's state at the start of a run that continues another (``carried``: the pairs' states
    where it ended): each pair keeps its carried state (its latched approach speed, its history) when
    its mode is the one its gap gives at ``(t, y)``; a pair whose mode the start's gap contradicts (new
    numbers moved its gap across zero) starts as :func:`start_state` starts it."""
    fresh = start_state(model, t, y)
    return tuple(tuple(old if old.contact == new.contact else new for old, new in zip(olds, news))
                 for olds, news in zip(carried, fresh))


#: The numbers of one pair's state in :func:`state_array`'s rows before its switch times.
PAIR_FIELDS = ("contact", "held", "free_since", "latched")


def state_array(state: ContactState, shape: tuple[int, int]) -> NDArray:
    """The state as numbers, one row per pair in model order: :data:`PAIR_FIELDS`, then the last switch
    times (oldest first), NaN up to the columns of ``shape`` (:func:`state_shape`; to keep it in a file)."""
    pairs = [pair for states in state for pair in states]
    out = np.full(shape, np.nan)
    for row, pair in zip(out, pairs):
        row[:4] = (float(pair.contact), float(pair.held), pair.free_since, pair.latched)
        row[4:4 + len(pair.recent)] = pair.recent
    return out


def array_state(values: NDArray, like: ContactState) -> ContactState:
    """The state :func:`state_array` wrote, in the structure of ``like`` (a state of the same model)."""
    rows = iter(np.asarray(values, dtype=float))
    out = []
    for states in like:
        element = []
        for _ in states:
            row = next(rows)
            recent = row[4:]
            element.append(PairState(contact=bool(row[0]), held=bool(row[1]), free_since=float(row[2]),
                                     latched=float(row[3]), recent=tuple(recent[~np.isnan(recent)].tolist())))
        out.append(tuple(element))
    return tuple(out)


def state_shape(model: DAEModel) -> tuple[int, int]:
    """The shape of :func:`state_array` for any state of ``model``: its pairs, and the fields and the
    longest switch history."""
    return (sum(logic.n_states for logic in model.contacts),
            len(PAIR_FIELDS) + max((logic.storm.events for logic in model.contacts), default=0))
