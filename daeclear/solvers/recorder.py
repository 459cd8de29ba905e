"""Where a run's output goes while it runs: kept in memory, or streamed to an HDF5 file.

The run driver hands a :class:`Recorder` the reported points chunk by chunk, each with the switch
vector of its segment, and their steps, events and segments. IDA's points come without channels
and, kept in memory, as IDA left them: the run's `Result` makes their multipliers and yp consistent
and computes the channels at the first read (:class:`~daeclear.results.lazy_channels.LazyChannels`).
In memory, a run of several chunks is kept in :class:`~daeclear.solvers.row_store.RowStore` columns
that grow in place, so each point is copied once, into the Result's own arrays (joining the chunks at
the end copied it twice, into fresh pages each time). Streamed (``stream_to``), each chunk is appended
to the file and dropped, so the run's memory does not grow with its length and the file holds what
was computed whatever stops the run. Either way
the physics checks read the few rows of :func:`daeclear.assembly.physics.key_rows`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from ..assembly import physics
from ..assembly.dae_model import DAEModel, ExtrasEvaluator
from ..results.channel_eval import ModelEvaluator, rebuildable
from ..core.errors import OutputError
from ..core.events import EventRows, flatten
from ..results.lazy_channels import LazyChannels
from ..core.events import ContactEvent
from ..results.result import Result, ResultWriter, load
from .row_store import RowStore

#: a chunk of points: t, y, yp (None: IDA's raw points), switch rows, the channels when the solver computed them
Points = tuple[NDArray, NDArray, NDArray | None, NDArray, dict[str, NDArray] | None]


def out_of_memory(t: float) -> str:
    """The message of a run stopped by a MemoryError at time ``t`` (any method): what to change in its output."""
    return (f"out of memory at t={t:.6g} s. Report fewer points (SaveAt.every), keep no steps "
            "(SaveAt.steps=False) and stream the run to a file (SaveAt.stream_to).")


class Recorder:
    """The output of one run. ``events`` and ``segments`` are the lists the solver appends to
    (:meth:`flush` writes and, streamed, empties them); :attr:`session` is the run's open session,
    in whose library the checked channels are evaluated while it is open."""

    def __init__(self, model: DAEModel, *, parameters: Mapping[str, Any], method: str,
                 stream_to: Path | None = None, keep_data: bool = True, lazy_rows: bool = False) -> None:
        self.model = model
        self.keep_data = keep_data
        self.events: list[ContactEvent | EventRows] = []  # events, and blocks of the compiled loop's
        self._in_blocks = 0  # events in the blocks of ``events`` beyond one a block
        self.segments: list[tuple[float, float, dict[str, str]]] = []
        self._written_events = 0
        self.interrupted = False  # a Ctrl-C arrived while finish() completed the file
        self._header: dict[str, Any] = dict(state_names=list(model.state_names), units=dict(model.channel_units),
                            parameters=parameters, scene_name=model.scene_name, method=method,
                            formulation=model.formulation)
        self.session: ExtrasEvaluator | None = None  # the run's extras in C while it is open
        #: ``lazy_rows``: the integrator's points are the DAE's own states (IDA's, its multipliers not
        #: converged), their channels made again from them alone (the model's output function): kept in
        #: memory as they are, the Result makes them consistent when first read; a file stores consistent points
        self._lazy_rows = lazy_rows
        self.consistent_when_read = lazy_rows and stream_to is None
        self._backend = str(parameters.get("simulate", {}).get("backend", "auto"))
        # the states alone make the channels again (IDA's output function; the scene rebuilt from its
        # description): decided at the first need (a streamed file, a saved result)
        self._rebuildable: bool | None = None
        self.writer = None if stream_to is None else ResultWriter(
            stream_to, **self._header, channel_names=list(model.channel_names) if self.rebuildable() else None)
        self._points: list[Points] = []  # the first chunk kept as given; from the second, in self._store
        self._store: tuple[RowStore, ...] = ()  # t, y, switch (and yp when the chunks have it): each row stored once
        self._channels: list[dict[str, NDArray] | None] = []  # the chunks' channels, when in self._store
        self._steps: list[tuple[NDArray, NDArray, NDArray]] = []
        n = model.n_states
        self._key: tuple[NDArray, NDArray, dict[str, NDArray]] = (np.zeros(0), np.zeros((0, n)), {})

    @property
    def n_events(self) -> int:
        """Events of the run so far (written and pending)."""
        return self._written_events + len(self.events) + self._in_blocks

    def add_event_rows(self, rows: EventRows) -> None:
        """A block of events (the compiled loop's of one advance), kept as columns."""
        self.events.append(rows)
        self._in_blocks += len(rows) - 1

    def rebuildable(self) -> bool:
        """Whether the result's channels can be made again from its states and parameters alone: an
        IDA run (its output function) of a scene that its description rebuilds."""
        if self._rebuildable is None:
            self._rebuildable = self._lazy_rows and rebuildable(self._header["parameters"])
        return self._rebuildable

    def add_points(self, t: NDArray, y: NDArray, yp: NDArray | None, switch: NDArray,
                   channels: dict[str, NDArray] | None = None) -> None:
        """Reported points, consistent (unless :attr:`consistent_when_read`: IDA's own y, no yp), one row per
        time of ``t``, with its switch vector and, when the solver computed them, its channels."""
        if not t.size:
            return
        if self.writer is not None:
            assert yp is not None, "a file stores consistent points, with their yp"
            if channels is None and not self.rebuildable():  # the file stores every channel
                channels = self._evaluated(t, y, yp, switch)
            self._keep_key_rows(t, y, self._checked(t, y, switch, channels))
            self.writer.append(t=t, y=y, yp=yp, switch=switch, channels=None if self.rebuildable() else channels)
        elif not self._points and not self._store:
            self._points.append((t, y, yp, switch, channels))
        else:
            self._stored((t, y, yp, switch, channels))

    def add_steps(self, t: NDArray, h: NDArray, order: NDArray) -> None:
        """The integrator's steps: time, size and order of each."""
        if not t.size:
            return
        if self.writer is not None:
            self.writer.append(step_t=t, step_h=h, step_order=order)
        else:
            self._steps.append((t, h, order))

    def flush(self) -> None:
        """Write the events and segments added since the last flush (streamed only)."""
        if self.writer is not None and (self.events or self.segments):
            events = flatten(self.events)
            self.writer.append(events=events, segments=self.segments)
            self._written_events += len(events)
            self.events.clear()
            self._in_blocks = 0
            self.segments.clear()

    def _checked(self, t: NDArray, y: NDArray, switch: NDArray,
                 channels: dict[str, NDArray] | None) -> dict[str, NDArray]:
        """The channels the physics checks read at the rows: taken from ``channels`` when given, else
        the model's checks function (in the run's session while it is open)."""
        if channels is not None:
            return {c: channels[c] for c in self.model.checked_names}
        return self.model.checks(t, y, switch, self.session)

    def _keep_key_rows(self, t: NDArray, y: NDArray, channels: dict[str, NDArray]) -> None:
        names = self.model.checked_names
        kt, ky, kc = self._key
        if kt.size:  # the rows kept so far compete with the new ones
            t2, y2 = np.concatenate([kt, t]), np.concatenate([ky, y])
            c2 = {c: np.concatenate([kc[c], channels[c]]) if c in kc else channels[c] for c in names}
        else:
            t2, y2, c2 = t, y, {c: channels[c] for c in names}
        rows = physics.key_rows(t2, c2)
        self._key = (t2[rows], y2[rows], {c: v[rows] for c, v in c2.items()})

    def _evaluated(self, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> dict[str, NDArray]:
        if self.session is not None:
            return self.model.channels(t, y, yp, switch, self.session)
        out = ModelEvaluator(self.model, self._backend).channels(t, y, yp, switch)
        return {name: np.ascontiguousarray(out[name]) for name in self.model.channel_names}

    def _stored(self, chunk: Points) -> None:
        """Append a chunk of points to the stores (made at the second chunk, with the first)."""
        if not self._store:
            first = self._points.pop()
            t, y, yp, switch, _ = first
            columns = (t, y, switch) if yp is None else (t, y, switch, yp)
            self._store = tuple(RowStore(c.shape[1:], c.dtype) for c in columns)
            self._stored(first)
        t, y, yp, switch, channels = chunk
        for store, column in zip(self._store, (t, y, switch) if yp is None else (t, y, switch, yp)):
            store.append(column)
        self._channels.append(channels)

    def _joined(self) -> tuple[NDArray, NDArray, NDArray | None, NDArray, dict[str, NDArray] | None]:
        """The points kept in memory as one chunk, with their channels when the solver gave them (else
        None: the Result computes them when they are first read)."""
        n = self.model.n_states
        points = self._points
        channels: dict[str, NDArray] | None
        if self._store:  # several chunks: stored once, as they came
            t, y, switch, *rest = (store.array() for store in self._store)
            yp = rest[0] if rest else None
            given = self._channels
            channels = None
            if all(g is not None for g in given):
                chunks = [g for g in given if g is not None]
                channels = {c: np.concatenate([g[c] for g in chunks]) for c in chunks[0]}
            self._store, self._channels = (), []
        elif points:  # one chunk (a short run): nothing to join
            t, y, yp, switch, channels = points[0]
        else:
            n_switch = self.model.outputs.size1_in(3)
            t, y, yp, switch = np.zeros(0), np.zeros((0, n)), np.zeros((0, n)), np.zeros((0, n_switch))
            channels = {c: np.zeros(0) for c in self.model.channel_names}
        self._points[:] = [(t, y, yp, switch, channels)]
        return t, y, yp, switch, channels

    def key_rows(self) -> tuple[NDArray, NDArray, dict[str, NDArray]]:
        """(t, y, channels) of the rows the physics checks read (:func:`daeclear.assembly.physics.key_rows`);
        in memory, the checked channels are computed at every point for them (the others are not)."""
        if self.writer is None:
            t, y, yp, switch, channels = self._joined()
            checked = self._checked(t, y, switch, channels)
            rows = physics.key_rows(t, checked)
            return t[rows], y[rows], {c: v[rows] for c, v in checked.items()}
        return self._key

    def finish(self, *, stats: Mapping[str, Any], success: bool, status: int, message: str,
               warnings: list[dict[str, Any]]) -> Result:
        """The run's Result: in memory, the chunks joined; streamed, the file completed and read back
        (``keep_data``) or a Result of the outcome alone (no time series, events or segments)."""
        outcome: dict[str, Any] = dict(stats=stats, success=success, status=status, message=message,
                                       warnings=warnings)
        if self.writer is not None:
            self.flush()
            try:
                path = self.writer.close(**outcome)
            except KeyboardInterrupt:  # held back while the file was completed: it is complete
                self.interrupted = True
                path = self.writer.path
            if self.keep_data:
                return load(path)
            n = self.model.n_states
            header = {**self._header, "units": {s: u for s, u in self._header["units"].items()
                                                if s in self._header["state_names"]}}
            # the outcome's summary tells what the file holds, read from it (the outcome holds no data)
            outcome["stats"] = {**outcome["stats"], "file": getattr(self.writer, "counts", {"path": str(path)})}
            return Result(t=np.zeros(0), y=np.zeros((0, n)), yp=np.zeros((0, n)), channels={}, **header, **outcome)
        t, y, yp, switch, channels = self._joined()
        self._points.clear()
        evaluator = ModelEvaluator(self.model, self._backend)
        raw = self.consistent_when_read
        kept_yp = None if raw else yp  # raw: none kept, made consistent with y when either is first read
        lazy = LazyChannels(self.model.channel_names, evaluator.channels, t, y, kept_yp,
                            np.asarray(switch), consistent=evaluator.consistent, raw=raw, values=channels,
                            recomputed=slice(2 * self.model.n_q, 2 * self.model.n_q + self.model.n_constraints),
                            rebuildable=self.rebuildable)
        steps = [np.concatenate(c) for c in zip(*self._steps)] if self._steps else [
            np.zeros(0), np.zeros(0), np.zeros(0, dtype=np.int64)]
        return Result.of_run(t=t, y=y, yp=kept_yp, channels=lazy, events=self.events, segments=self.segments,
                             step_t=steps[0], step_h=steps[1], step_order=steps[2].astype(np.int64, copy=False),
                             **self._header, **outcome)

    def abort(self, error: BaseException) -> None:
        """After an unexpected error: a streamed file is closed with what it holds and the error as its message."""
        if self.writer is not None:
            try:
                self.flush()
            except OutputError:  # no room for the last events: the file keeps what it holds
                pass
            finally:
                self.writer.abort(f"stopped by {type(error).__name__}: {error}")
