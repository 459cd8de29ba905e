"""A run's forward sensitivities as its Result keeps them (``simulate(..., sensitivities=[...])``).

:class:`Sensitivities`: the parameters' names, S = dy/dp of every state and the channels' d/dp at every
output row of the result (NaN for a parameter after a grazing event), and each contact event's time
sensitivity dt*/dp. Read through :meth:`daeclear.Result.sensitivity`; saved and read by
:mod:`daeclear.results.hdf5_write` and :mod:`daeclear.results.hdf5_read` (docs/hdf5_layout.md).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["EventSides", "RunTrajectory", "Sensitivities", "SensitivityEvent", "sensitivity_events"]


@dataclass(frozen=True)
class SensitivityEvent:
    """One contact switch (kind "onset" or "separation") or friction kink crossed ("kink": a restart without a
    jump, docs/sensitivities.md): time, pair, kind and the event time's sensitivity to each parameter (Ns,)."""

    t: float
    pair: str
    kind: str
    dt_dp: NDArray[np.float64]


@dataclass(frozen=True)
class EventSides:
    """The rows at each event's time, before and after its switch, in time order: ``t`` (2 k,), the states
    ``y`` (2 k, n_states), the channels' ``values`` (2 k, n_channels), their sensitivities ``states``
    and ``channels`` (2 k, n, Ns). What an objective that integrates or peaks across a jump reads."""

    t: NDArray[np.float64]
    y: NDArray[np.float64]
    values: NDArray[np.float64]
    states: NDArray[np.float64]
    channels: NDArray[np.float64]

    def within(self, lo: float, hi: float) -> EventSides:
        """The rows of the events in [lo, hi] (a window of the result)."""
        rows = (self.t >= lo) & (self.t <= hi)
        return EventSides(self.t[rows], self.y[rows], self.values[rows], self.states[rows], self.channels[rows])


@dataclass(frozen=True)
class Sensitivities:
    """``names`` (the parameters), ``states`` (n_times, n_states, Ns) and ``channels`` (n_times,
    n_channels, Ns) in the order of ``state_names`` and ``channel_names``, ``events``; ``sides``: the rows
    before and after each event; ``values``: the parameters' values in the run (None in a file written
    before either was kept); ``integrals``: {channel: (Q (n_times,), dQ/dp (n_times, Ns))}, the integrals
    from the run's start integrated as states under error control (``simulate(..., integrals=[...])``)."""

    names: tuple[str, ...]
    state_names: tuple[str, ...]
    channel_names: tuple[str, ...]
    states: NDArray[np.float64]
    channels: NDArray[np.float64]
    events: tuple[SensitivityEvent, ...] = ()
    sides: EventSides | None = None
    values: NDArray[np.float64] | None = None
    integrals: Mapping[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(default_factory=dict)

    def of(self, name: str, parameter: str | None = None) -> NDArray[np.float64]:
        """d(name)/d(parameter) at every output time, (n_times,); every parameter (n_times, Ns) without one."""
        if name in self.state_names:
            column = self.states[:, self.state_names.index(name), :]
        elif name in self.channel_names:
            column = self.channels[:, self.channel_names.index(name), :]
        else:
            raise KeyError(f"Result.sensitivity: name={name!r}, must be a state or a channel of the run, e.g. "
                           f"{', '.join(map(repr, self.state_names[:3]))}.")
        if parameter is None:
            return column
        if parameter not in self.names:
            raise KeyError(f"Result.sensitivity: parameter={parameter!r}, must be one of the run's sensitivity "
                           f"parameters ({', '.join(self.names)}).")
        return column[:, self.names.index(parameter)]

    def take(self, rows: NDArray[np.bool_], lo: float, hi: float) -> Sensitivities:
        """The rows ``rows`` and the events in [lo, hi] (a window of the result)."""
        return Sensitivities(self.names, self.state_names, self.channel_names, self.states[rows],
                             self.channels[rows], tuple(e for e in self.events if lo <= e.t <= hi),
                             None if self.sides is None else self.sides.within(lo, hi), self.values,
                             {c: (Q[rows], dQ[rows]) for c, (Q, dQ) in self.integrals.items()})


def sensitivity_events(t: Sequence[float], pairs: Sequence[str], kinds: Sequence[str],
                       dt_dp: NDArray[np.float64]) -> tuple[SensitivityEvent, ...]:
    """Events from their columns (as a file stores them)."""
    return tuple(SensitivityEvent(float(a), str(b), str(c), np.asarray(d, dtype=float))
                 for a, b, c, d in zip(t, pairs, kinds, dt_dp))


class RunTrajectory:
    """A run's rows with sensitivities and its events' two rows as :func:`daeclear.results.objectives.evaluate`
    reads them (its ``Trajectory``): ``t`` the output times with each event's time twice (before and after
    its switch; an output row at that time gives way to them), ``values`` and ``sensitivity`` by name.
    ``t``, ``read`` (a state's or channel's values at ``t``) and ``sens`` are a Result's."""

    def __init__(self, t: NDArray[np.float64], read: Callable[[str], NDArray[np.float64]], sens: Sensitivities) -> None:
        if sens.sides is None:
            raise ValueError("RunTrajectory: the sensitivities have no rows at the events (a file written before "
                             "they were saved: run it again)")
        self.sides, self.sens, self.read, self.rows_t = sens.sides, sens, read, t
        self.keep = ~np.isin(t, self.sides.t)
        joined = np.concatenate([t[self.keep], self.sides.t])
        self.order = np.argsort(joined, kind="stable")  # an event's two rows stay in their order
        self.t = joined[self.order]
        self.names, self.events = sens.names, sens.events
        self.state_names, self.channel_names = sens.state_names, sens.channel_names

    def quadrature(self, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]] | None:
        """The run's integral of channel ``name`` from its start at the output rows: (t, Q, dQ/dp), or None
        when the run did not integrate it (``simulate(..., integrals=[...])``)."""
        if name not in self.sens.integrals:
            return None
        Q, dQ = self.sens.integrals[name]
        return self.rows_t, Q, dQ

    def _joined(self, rows: NDArray, at_events: NDArray) -> NDArray[np.float64]:
        return np.concatenate([rows[self.keep], at_events])[self.order]

    def values(self, name: str) -> NDArray[np.float64]:
        """A state's or a channel's value at every time, (n_times,)."""
        if name in self.state_names:
            return self._joined(np.asarray(self.read(name), dtype=float), self.sides.y[:, self.state_names.index(name)])
        if name in self.channel_names:
            return self._joined(np.asarray(self.read(name), dtype=float),
                                self.sides.values[:, self.channel_names.index(name)])
        raise KeyError(name)

    def sensitivity(self, name: str, parameter: str | None = None) -> NDArray[np.float64]:
        """d(name)/d(parameter) at every time, (n_times,); every parameter (n_times, Ns) without one."""
        if name in self.state_names:
            sides = self.sides.states[:, self.state_names.index(name), :]
        elif name in self.channel_names:
            sides = self.sides.channels[:, self.channel_names.index(name), :]
        else:
            raise KeyError(name)
        column = self._joined(self.sens.of(name), sides)
        return column if parameter is None else column[:, self.names.index(parameter)]
