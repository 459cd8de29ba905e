"""The wear history file of :func:`daeclear.studies.wear.simulate_wear`: its layout and rows.

A run file of results' writer (:class:`daeclear.results.run_file.RunFile`; docs/hdf5_layout.md, "The
wear history file"): root attributes ``format = "daeclear-wear"`` and ``version = 3``; the header (what a
resume must match) is the study's settings: the worn joint, update interval, extrapolation, period,
formulation, solver options and the scene (every element, the wear law's numbers included). One row per
profile, the unworn first:

    cycles            the cycles worn
    depth             m, (surfaces, nodes): each worn surface's nodal depth
    sliding_work      N m, the (extrapolated) sliding work so far
    block_peak_force  N, the largest normal force of the block run that made this profile (NaN for the first)
    t, y              s, and the mechanism's state (columns as model.state_names) the next block starts
                      from; the first row's y is NaN: the scene's own start
    contact           the contact pairs' automaton states at t (one row per pair, model order: contact, held,
                      free_since, latched approach speed, the last switch times NaN-padded), which the next
                      block's pairs start in; NaN for the first row

A file of an earlier layout (version 2: no contact states, its blocks started from the gaps; before it, no
version and the state kept apart) is refused with a message saying so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..results.run_file import RunFile

FORMAT = "daeclear-wear"
VERSION = 3
#: The columns, in order, and their units.
COLUMNS = {"cycles": "", "depth": "m", "sliding_work": "N m", "block_peak_force": "N", "t": "s", "y": "",
           "contact": ""}


@dataclass(frozen=True)
class WearRow:
    """One profile of a wear history: cycles worn, depth by surface, sliding work, the peak normal force of
    the block run that made it (NaN for the unworn profile), and the state (time, y; None: the scene's
    start) the next block starts from, with its contact pairs' states
    (:func:`daeclear.assembly.contact_state.state_array`; None: from the start's gaps)."""

    cycles: float
    depth: dict[str, NDArray[np.float64]]
    work: float
    block_peak: float
    t: float
    y: NDArray[np.float64] | None
    contact: NDArray[np.float64] | None


class WearFile:
    """A wear history file (module docstring): :meth:`open` reads its rows (checked against ``settings``)
    or creates it, :meth:`append` adds one profile."""

    def __init__(self, path: Path, settings: dict[str, Any]) -> None:
        wear = settings["scene"]["elements"][settings["joint"]]["wear"]
        self.surfaces = ("bearing", "journal") if wear["surface"] == "both" else (wear["surface"],)
        self.file = RunFile(path, kind=FORMAT, version=VERSION, header=settings, units=COLUMNS,
                            where="simulate_wear", subject="scene or settings")

    def open(self) -> list[WearRow] | None:
        """The file's rows (None: a new file, or one stopped before its first row)."""
        columns = self.file.open()
        if columns is None:
            return None
        cycles, depth, work, peak, t, y, contact = (columns[name] for name in COLUMNS)
        return [WearRow(cycles=float(cycles[i]), depth=dict(zip(self.surfaces, depth[i])), work=float(work[i]),
                        block_peak=float(peak[i]), t=float(t[i]), y=None if np.all(np.isnan(y[i])) else y[i],
                        contact=None if np.all(np.isnan(contact[i])) else contact[i])
                for i in range(cycles.shape[0])]

    def append(self, row: WearRow, n_states: int, contact_shape: tuple[int, int]) -> None:
        """Add one profile's row (whole or not at all; ``n_states``: the width of a state, ``contact_shape``:
        the shape of the pairs' contact states)."""
        y = np.full(n_states, math.nan) if row.y is None else row.y
        contact = np.full(contact_shape, math.nan) if row.contact is None else row.contact
        self.file.append({"cycles": row.cycles, "depth": np.array([row.depth[s] for s in self.surfaces]),
                          "sliding_work": row.work, "block_peak_force": row.block_peak, "t": row.t, "y": y,
                          "contact": contact})

    def close(self) -> None:
        self.file.close()

    def __enter__(self) -> WearFile:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
