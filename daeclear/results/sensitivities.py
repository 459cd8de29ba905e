"""A run's forward sensitivities as its Result keeps them (``simulate(..., sensitivities=[...])``).

:class:`Sensitivities`: the parameters' names, S = dy/dp of every state and the channels' d/dp at every
output row of the result (NaN for a parameter after a grazing event), and each contact event's time
sensitivity dt*/dp. Read through :meth:`daeclear.Result.sensitivity`; saved and read by
:mod:`daeclear.results.hdf5_write` and :mod:`daeclear.results.hdf5_read` (docs/hdf5_layout.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Sensitivities", "SensitivityEvent", "sensitivity_events"]


@dataclass(frozen=True)
class SensitivityEvent:
    """One contact switch: time, pair, kind and the event time's sensitivity to each parameter (Ns,)."""

    t: float
    pair: str
    kind: str
    dt_dp: NDArray[np.float64]


@dataclass(frozen=True)
class Sensitivities:
    """``names`` (the parameters), ``states`` (n_times, n_states, Ns) and ``channels`` (n_times,
    n_channels, Ns) in the order of ``state_names`` and ``channel_names``, ``events``."""

    names: tuple[str, ...]
    state_names: tuple[str, ...]
    channel_names: tuple[str, ...]
    states: NDArray[np.float64]
    channels: NDArray[np.float64]
    events: tuple[SensitivityEvent, ...] = ()

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
                             self.channels[rows], tuple(e for e in self.events if lo <= e.t <= hi))


def sensitivity_events(t: Sequence[float], pairs: Sequence[str], kinds: Sequence[str],
                       dt_dp: NDArray[np.float64]) -> tuple[SensitivityEvent, ...]:
    """Events from their columns (as a file stores them)."""
    return tuple(SensitivityEvent(float(a), str(b), str(c), np.asarray(d, dtype=float))
                 for a, b, c, d in zip(t, pairs, kinds, dt_dp))
