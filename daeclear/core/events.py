"""Contact events of a run: `ContactEvent` (one transition found by root finding) and `EventList`, apart from
the `Result` container (the assembly code builds them during a run, the HDF5 reader rebuilds them).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Literal, overload

import numpy as np
from numpy.typing import NDArray

from .values import readonly

__all__ = ["EVENT_KINDS", "ContactEvent", "EventKind", "EventList", "EventRows", "flatten"]

EventKind = Literal["onset", "separation"]
EVENT_KINDS: tuple[EventKind, ...] = ("onset", "separation")


def _same_float(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


@dataclass(frozen=True, eq=False, repr=False)
class ContactEvent:
    """One contact transition found by root finding.

    Parameters
    ----------
    t : float
        Time of the event (s).
    pair : str
        Name of the contact pair, e.g. ``"C"`` or ``"clearance.A_upper"``.
    kind : {"onset", "separation"}
        ``"onset"`` when the gap closes, ``"separation"`` when it opens.
    approach_speed : float
        Relative normal velocity at the event (m/s), the laws' impact speed at onset; ``nan`` where meaningless.
    y : ndarray, shape (n_states,)
        Full state at the event, ordered as `Result.state_names` (stored read-only).

    Two events are equal when all fields are, ``nan`` equal to ``nan``.
    """

    t: float
    pair: str
    kind: EventKind
    approach_speed: float
    y: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise ValueError(f"ContactEvent for pair {self.pair!r} at t={self.t}: kind={self.kind!r}, "
                             f"must be 'onset' or 'separation'.")
        y = np.asarray(self.y, dtype=np.float64)
        if y.ndim != 1:
            raise ValueError(f"ContactEvent for pair {self.pair!r} at t={self.t}: y has shape {y.shape}, "
                             f"must be one state vector (n_states,).")
        object.__setattr__(self, "t", float(self.t))
        object.__setattr__(self, "pair", str(self.pair))
        object.__setattr__(self, "approach_speed", float(self.approach_speed))
        object.__setattr__(self, "y", readonly(y))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ContactEvent):
            return NotImplemented
        return (_same_float(self.t, other.t) and self.pair == other.pair and self.kind == other.kind
                and _same_float(self.approach_speed, other.approach_speed)
                and np.array_equal(self.y, other.y, equal_nan=True))

    __hash__ = None  # type: ignore[assignment]  # holds an array

    def __repr__(self) -> str:
        return (f"ContactEvent(t={self.t:.9g}, pair={self.pair!r}, kind={self.kind!r}, "
                f"approach_speed={self.approach_speed:.6g})")


class EventRows(Sequence[ContactEvent]):
    """Events of one advance of the compiled loop kept as columns (times, pairs, kinds, approach speeds
    and the read-only block of their states), made into :class:`ContactEvent` objects when first read."""

    __slots__ = ("_columns", "_made")

    def __init__(self, t: list[float], pair: list[str], kind: list[EventKind], approach_speed: list[float],
                 y: NDArray[np.float64]) -> None:
        self._columns = (t, pair, kind, approach_speed, y)
        self._made: tuple[ContactEvent, ...] | None = None

    def _events(self) -> tuple[ContactEvent, ...]:
        if self._made is None:
            self._made = tuple(map(ContactEvent, *self._columns))
        return self._made

    def __len__(self) -> int:
        return len(self._columns[0])

    def __getitem__(self, index: Any) -> Any:
        return self._events()[index]

    def __iter__(self) -> Iterator[ContactEvent]:
        return iter(self._events())


def flatten(parts: Iterable[ContactEvent | EventRows]) -> list[ContactEvent]:
    """Events and blocks of events as one list of events, in order."""
    out: list[ContactEvent] = []
    for part in parts:
        if type(part) is EventRows:
            out.extend(part)
        else:
            out.append(part)  # type: ignore[arg-type]
    return out


class EventList(Sequence[ContactEvent]):
    """An immutable, list-like sequence of `ContactEvent`, in time order.

    A slice is an `EventList`; `t`, `approach_speed`, `pair` and `kind` give one field of every event;
    `of` filters.

    Examples
    --------
    >>> onsets = result.events.of("C", kind="onset")   # doctest: +SKIP
    >>> onsets.t, onsets.approach_speed                # doctest: +SKIP
    """

    __slots__ = ("_items", "_parts")

    def __init__(self, events: Iterable[ContactEvent] = ()) -> None:
        items = tuple(events)
        for i, event in enumerate(items):
            if not isinstance(event, ContactEvent):
                raise TypeError(f"events[{i}] is a {type(event).__name__}, expected a ContactEvent.")
        self._items: tuple[ContactEvent, ...] | None = items
        self._parts: list[ContactEvent | EventRows] | None = None

    @classmethod
    def of_parts(cls, parts: list[ContactEvent | EventRows]) -> EventList:
        """A solver's events, unchecked: events and blocks of them (:class:`EventRows`), in time order,
        made one sequence at the first read (a sweep's runs are seldom asked for every event)."""
        events = cls.__new__(cls)
        events._items, events._parts = None, parts
        return events

    @property
    def _events(self) -> tuple[ContactEvent, ...]:
        if self._items is None:
            assert self._parts is not None
            self._items, self._parts = tuple(flatten(self._parts)), None
        return self._items

    @overload
    def __getitem__(self, index: int) -> ContactEvent: ...

    @overload
    def __getitem__(self, index: slice) -> EventList: ...

    def __getitem__(self, index: int | slice) -> ContactEvent | EventList:
        if isinstance(index, slice):
            return EventList(self._events[index])
        return self._events[index]

    def __len__(self) -> int:
        return len(self._events)

    def __iter__(self) -> Iterator[ContactEvent]:
        return iter(self._events)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, EventList):
            return self._events == other._events
        if isinstance(other, (list, tuple)):
            return self._events == tuple(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        if not self._events:
            return "EventList([])"
        counts = ", ".join(f"{self.kind.count(k)} {k}" for k in EVENT_KINDS)
        pairs = ", ".join(repr(p) for p in dict.fromkeys(self.pair))
        return f"EventList({len(self)} events: {counts}; pairs {pairs})"

    def of(self, pair: str | None = None, kind: EventKind | None = None) -> EventList:
        """The events of one contact pair and/or one kind, in order (empty for a pair that never touched).

        ``pair`` matches that pair and those below it (``"clearance"``: ``"clearance.A_upper"``, not
        ``"clearance2"``); ``kind``: ``"onset"``, ``"separation"`` or None (both; anything else: ValueError).
        """
        if kind is not None and kind not in EVENT_KINDS:
            raise ValueError(f"EventList.of: kind={kind!r}, must be 'onset', 'separation' or None.")
        prefix = None if pair is None else pair + "."
        return EventList(e for e in self._events
                         if (pair is None or e.pair == pair or e.pair.startswith(prefix))  # type: ignore[arg-type]
                         and (kind is None or e.kind == kind))

    @property
    def t(self) -> NDArray[np.float64]:
        """Event times (s), shape (n_events,)."""
        return np.array([e.t for e in self._events], dtype=np.float64)

    @property
    def approach_speed(self) -> NDArray[np.float64]:
        """Approach speeds (m/s), shape (n_events,); nan where meaningless."""
        return np.array([e.approach_speed for e in self._events], dtype=np.float64)

    @property
    def pair(self) -> list[str]:
        """Pair name of every event."""
        return [e.pair for e in self._events]

    @property
    def kind(self) -> list[str]:
        """Kind (``"onset"`` or ``"separation"``) of every event."""
        return [e.kind for e in self._events]
