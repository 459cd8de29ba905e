"""SaveAt: what a run reports and where it goes, as one checked, immutable value (as diffrax's SaveAt).

Fields are checked on construction; what needs the run's span by :meth:`SaveAt.plan`, and the size
estimate by :meth:`Output.check_size` once the model is known: all before any work.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from ..core import options
from ..core.options import MAX_OUTPUT_POINTS, OutputTimes, fail

WHERE = "SaveAt"


@dataclass(frozen=True, eq=False)
class SaveAt:
    """The output of a run (see :func:`daeclear.simulate`).

    Parameters
    ----------
    times : array_like or None
        Output times (finite, strictly increasing, inside ``[t0, t_end]``). None: every internal step.
    every : float or None
        Output times every ``every`` seconds from t0 to t_end, both included. Not with ``times``.
    steps : bool
        Keep every internal step's time, size and order (``result.step_t``...); without ``times`` and
        ``every`` False keeps the start point only.
    stream_to : str, path or None
        Write the result to this HDF5 file chunk by chunk during the run (docs/hdf5_layout.md).
    keep_data : bool
        With ``stream_to``: return the result read back (True) or the outcome alone (False).
    max_points : int or None
        The most output points a run may report (:data:`daeclear.core.options.MAX_OUTPUT_POINTS`), refused
        before the run with the estimated size. None: no cap.
    """

    times: ArrayLike | None = None
    every: float | None = None
    steps: bool = True
    stream_to: str | os.PathLike[str] | None = None
    keep_data: bool = True
    max_points: int | None = MAX_OUTPUT_POINTS

    def __post_init__(self) -> None:
        times = options.t_eval(self.times, None, where=WHERE, field="times")
        if times is not None:
            times = np.array(times)  # a private copy, read-only: the value cannot change after its check
            times.flags.writeable = False
        every = (None if self.every is None
                 else options.number(self.every, where=WHERE, field="every", unit="s", low=0.0))
        if times is not None and every is not None:
            fail(WHERE, "every", self.every, "left out when times is given (give one or the other)")
        stream = self.stream_to
        if stream is not None and not isinstance(stream, (str, os.PathLike)):
            fail(WHERE, "stream_to", stream, "None or the path of an HDF5 file (str or pathlib.Path), e.g. 'run.h5'")
        keep = options.flag(self.keep_data, where=WHERE, field="keep_data")
        if stream is None and not keep:
            fail(WHERE, "keep_data", self.keep_data, "True when stream_to is not given (the data would be lost)")
        values = {"times": times, "every": every, "steps": options.flag(self.steps, where=WHERE, field="steps"),
                  "stream_to": None if stream is None else Path(stream), "keep_data": keep,
                  "max_points": options.max_output_points(self.max_points, where=WHERE, field="max_points")}
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def plan(self, t0: float, t_end: float, *, where: str = "simulate") -> Output:
        """The output of a run from ``t0`` to ``t_end`` (both checked): the checks that need the span."""
        times = None
        if self.times is not None:
            times = OutputTimes(options.t_eval(self.times, t_end, where=where, field="save.times", start=t0))
        elif self.every is not None:
            spacing = options.number(self.every, where=where, field="save.every", unit="s", low=0.0, high=t_end - t0)
            times = OutputTimes(spacing=spacing, end=t_end, start=t0)
        path = None
        if self.stream_to is not None:
            from ..results.outputs import check_file

            path = check_file(self.stream_to, f"{where}: save.stream_to")
        return Output(times=times, stream_to=path, keep_data=bool(self.keep_data), steps=bool(self.steps),
                      every=self.every, max_points=self.max_points, start=t0, end=t_end)


class Output(NamedTuple):
    """A :class:`SaveAt` planned for one run (:meth:`SaveAt.plan`): what the solvers read."""

    times: OutputTimes | None  # None: every integrator step
    stream_to: Path | None
    keep_data: bool
    steps: bool
    every: float | None
    max_points: int | None
    start: float
    end: float

    def check_size(self, *, step: float | None, n_states: int, n_channels: int, where: str = "simulate") -> None:
        """Refuse, before the run, more than ``max_points`` points (those of ``times``/``every``, or of a
        kept fixed ``step``), with the estimate of their size (t, states, derivatives, channels: 8 bytes each)."""
        limit, start, end = self.max_points, self.start, self.end
        if limit is None:
            return
        if self.times is not None:
            points = self.times.size
            source = (("save.every", self.every, repr(self.every)) if self.every is not None
                      else ("save.times", None, f"array of {points} times"))
        elif step is not None and self.steps:
            points = int(math.floor((end - start) / step)) + 2
            source = ("step", step, f"{step!r} (every step reported, no save.every)")
        else:
            return
        if points <= limit:
            return
        per_point = 8 * (1 + 2 * n_states + n_channels)
        place = ("in the file and in memory" if self.stream_to is not None and self.keep_data
                 else "in the file" if self.stream_to is not None else "in memory")
        field, value, shown = source
        fail(where, field, value,
             f"coarser: it gives {points:.4g} output points over {end - start:g} s, about {_size(points * per_point)} "
             f"{place} ({per_point} bytes a point: t, {n_states} states and their derivatives, {n_channels} "
             f"channels), more than save.max_points={limit}; or raise max_points (daeclear run: "
             "--max-points; None: no limit) to run it anyway", shown=shown)


def _size(n_bytes: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= scale:
            return f"{n_bytes / scale:.3g} {unit}"
    return f"{n_bytes:.0f} bytes"


def save_value(value: Any, *, where: str = "simulate", field: str = "save") -> SaveAt:
    """``save=`` of a run: None (the default output: every step, in memory) or a :class:`SaveAt`."""
    if value is None:
        return DEFAULT
    if not isinstance(value, SaveAt):
        fail(where, field, value, "None or a daeclear.SaveAt, e.g. daeclear.SaveAt(every=1e-4)")
    return value


DEFAULT = SaveAt()
