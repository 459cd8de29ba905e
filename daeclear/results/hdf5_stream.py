"""The streaming writer `ResultWriter`: a result written to HDF5 append by append while its run goes on (a long
run never holds all its data in memory), in the layout of daeclear.results.hdf5_write, so `load` reads both alike.
"""

from __future__ import annotations

import json
import os
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .hdf5_write import FORMAT_NAME, FORMAT_VERSION, SIDES, integral_arrays, json_dataset, mirror, string_dataset
from .run_file import STREAM_ROWS, append_rows, extendable
from ..core.values import to_plain

if TYPE_CHECKING:  # h5py is imported lazily, only where a file is written
    import h5py

    from ..core.events import ContactEvent
    from .sensitivities import Sensitivities

__all__ = ["STREAM_RUNNING", "ResultWriter"]

#: The datasets of ``/sensitivities`` whose rows go with the output rows, in the order of ``_staged``.
_STAGED = ("states", "channels", "integrals/Q", "integrals/dQ")
#: Rows per chunk of the events and segments: a run has tens of them, and a chunk is written whole.
_LIST_ROWS = 64
#: Root message of a streamed file while its run goes on; a file left so was stopped without a word
#: (killed): it holds the data of its last complete append.
STREAM_RUNNING = "incomplete: the run was stopped before it finished (the data are those written until then)"


class ResultWriter:
    """Writes a result to an HDF5 file while its run goes on, in the layout of `Result.save`.

    The file is created with every item of the layout (empty, extendable datasets; the outcome
    :data:`STREAM_RUNNING`); each `append` adds rows, flushed, with Ctrl-C held back until they are
    complete, so between two appends `load` reads the run so far; `close` writes the statistics, warnings
    and the outcome. ``path`` is created or replaced (check it with :func:`~daeclear.results.outputs.check_file`
    first); the other parameters are as in `Result`, and with ``channel_names`` the file keeps the states
    alone (`load` computes the channels and yp) and `append` takes no channels.
    """

    def __init__(self, path: str | os.PathLike[str], *, state_names: Sequence[str], units: Mapping[str, str],
                 parameters: Mapping[str, Any], scene_name: str, method: str, formulation: str,
                 channel_names: Sequence[str] | None = None) -> None:
        import h5py

        self.path = Path(path)
        self._units = dict(units)
        self._n = len(state_names)
        self._staged: list[NDArray[np.float64]] = []  # the sensitivities of rows not yet appended (states, channels)
        self._f = f = h5py.File(self.path, "w")
        try:
            f.attrs["format"] = FORMAT_NAME
            f.attrs["version"] = FORMAT_VERSION
            for key, value in (("scene_name", scene_name), ("method", method), ("formulation", formulation)):
                f.attrs[key] = str(value)
            self._outcome(False, -1, STREAM_RUNNING)
            self._grow(f, "t", np.float64).attrs["units"] = "s"
            self._grow(f, "y", np.float64, (self._n,))
            if channel_names is None:  # every item kept: yp too (channels as they come)
                self._grow(f, "yp", np.float64, (self._n,))
            string_dataset(f, "state_names", list(state_names))
            string_dataset(f, "state_units", [self._units.get(str(n), "") for n in state_names])
            f.create_group("channels")
            if channel_names is not None:  # states only: the reader computes the channels
                string_dataset(f, "channel_names", list(channel_names))
                string_dataset(f, "channel_units", [self._units.get(str(n), "") for n in channel_names])
            text = h5py.string_dtype()
            layout = {"events": {"t": np.float64, "pair": text, "kind": text, "approach_speed": np.float64,
                                 "y": np.float64},
                      "segments": {"t_start": np.float64, "t_end": np.float64, "modes": text},
                      "steps": {"t": np.float64, "h": np.float64, "order": np.int64}}
            for group, columns in layout.items():
                g = f.create_group(group)
                for name, dtype in columns.items():
                    self._grow(g, name, dtype, (self._n,) if (group, name) == ("events", "y") else (),
                               rows=STREAM_ROWS if group == "steps" else _LIST_ROWS)
            f.create_group("stats")
            json_dataset(f, "stats_json", {})
            plain = to_plain(dict(parameters), "parameters")
            mirror(f.create_group("parameters"), plain)
            json_dataset(f, "parameters_json", plain)
            json_dataset(f, "warnings_json", [])
            f.flush()
        except BaseException:
            f.close()
            raise

    def sensitivities(self, names: Sequence[str], channel_names: Sequence[str], values: ArrayLike,
                      integrals: Sequence[str] = ()) -> None:
        """Add the ``/sensitivities`` group of a run with sensitivities (docs/hdf5_layout.md; the parameters'
        ``names`` and ``values``, the ``integrals``' channels, the arrays empty), which
        :meth:`stage_sensitivities` fills as the run goes."""
        import h5py

        g = self._f.create_group("sensitivities")
        string_dataset(g, "names", list(names))
        g.create_dataset("values", data=np.asarray(values, dtype=np.float64))
        string_dataset(g, "channel_names", list(channel_names))
        width, n_ch, text = len(names), len(channel_names), h5py.string_dtype()
        self._grow(g, "states", np.float64, (self._n, width))
        self._grow(g, "channels", np.float64, (n_ch, width))
        for group, columns in (("events", {"t": (np.float64, ()), "pair": (text, ()), "kind": (text, ()),
                                           "dt_dp": (np.float64, (width,))}),
                               ("sides", {"t": (np.float64, ()), "y": (np.float64, (self._n,)),
                                          "values": (np.float64, (n_ch,)), "states": (np.float64, (self._n, width)),
                                          "channels": (np.float64, (n_ch, width))})):
            sub = g.create_group(group)
            for name, (dtype, rest) in columns.items():
                self._grow(sub, name, dtype, rest, rows=_LIST_ROWS)
        sub = g.create_group("integrals")
        string_dataset(sub, "names", list(integrals))
        for name, rest in (("Q", (len(integrals),)), ("dQ", (len(integrals), width))):
            if integrals:
                self._grow(sub, name, np.float64, rest)
            else:  # no column: HDF5 cannot chunk it, and no append adds to it
                sub.create_dataset(name, shape=(0, *rest), dtype=np.float64)
        self._f.flush()
        self._staged = [np.zeros((0, self._n, width)), np.zeros((0, n_ch, width)),
                        np.zeros((0, len(integrals))), np.zeros((0, len(integrals), width))]

    def stage_sensitivities(self, s: Sensitivities) -> None:
        """The sensitivities carried since the last call: the events and their rows appended now; S of the
        states and channels (``s.states``, ``s.channels``, one row per output row) and the integrals' Q and
        dQ/dp (``s.integrals``, in the order given to :meth:`sensitivities`) appended with the output rows of
        the next :meth:`append`, in the same change (the file's rows of ``/t`` and of S never differ)."""
        _, Q, dQ = integral_arrays(s, len(s.states))
        self._staged = [np.concatenate([staged, rows])
                        for staged, rows in zip(self._staged, (s.states, s.channels, Q, dQ))]
        g = self._f["sensitivities"]
        items = [(g["events/t"], np.array([e.t for e in s.events], dtype=np.float64)),
                 (g["events/pair"], np.array([e.pair for e in s.events], dtype=object)),
                 (g["events/kind"], np.array([e.kind for e in s.events], dtype=object)),
                 (g["events/dt_dp"], np.array([e.dt_dp for e in s.events], dtype=np.float64).reshape(
                     len(s.events), len(s.names)))]
        if s.sides is not None:
            items += [(g[f"sides/{name}"], getattr(s.sides, name)) for name in SIDES]
        append_rows(self._f, items, path=self.path, what="stream_to")

    @staticmethod
    def _grow(group: h5py.Group, name: str, dtype: Any, rest: tuple[int, ...] = (),
              compress: bool = False, rows: int | None = None) -> h5py.Dataset:
        return extendable(group, name, dtype, rest, compress=compress, rows=rows)

    def _outcome(self, success: bool, status: int, message: str) -> None:
        self._f.attrs["success"] = bool(success)
        self._f.attrs["status"] = int(status)
        self._f.attrs["message"] = str(message)

    def append(self, *, t: ArrayLike = (), y: ArrayLike | None = None, yp: ArrayLike | None = None,
               switch: ArrayLike | None = None, channels: Mapping[str, ArrayLike] | None = None,
               events: Sequence[ContactEvent] = (),
               segments: Sequence[tuple[float, float, Mapping[str, str]]] = (), step_t: ArrayLike = (),
               step_h: ArrayLike = (), step_order: ArrayLike = ()) -> None:
        """Add output rows (``t``, ``y``, ``yp``, ``switch``, ``channels``: one row per time), events,
        segments and steps; written whole (a Ctrl-C meanwhile is raised afterwards) and flushed
        (:func:`~daeclear.results.run_file.append_rows`)."""
        f = self._f
        items = self._points(f, np.asarray(t, dtype=np.float64), y, yp, switch, channels)
        g = f["events"]
        items += [(g["t"], np.array([e.t for e in events], dtype=np.float64)),
                  (g["pair"], np.array([e.pair for e in events], dtype=object)),
                  (g["kind"], np.array([e.kind for e in events], dtype=object)),
                  (g["approach_speed"], np.array([e.approach_speed for e in events], dtype=np.float64)),
                  (g["y"], np.array([e.y for e in events], dtype=np.float64).reshape(len(events), self._n))]
        g = f["segments"]
        items += [(g["t_start"], np.array([float(s[0]) for s in segments], dtype=np.float64)),
                  (g["t_end"], np.array([float(s[1]) for s in segments], dtype=np.float64)),
                  (g["modes"], np.array([json.dumps({str(k): str(v) for k, v in s[2].items()}, ensure_ascii=False)
                                         for s in segments], dtype=object))]
        g = f["steps"]
        items += [(g["t"], np.asarray(step_t, dtype=np.float64)), (g["h"], np.asarray(step_h, dtype=np.float64)),
                  (g["order"], np.asarray(step_order, dtype=np.int64))]
        # room for this append and the file's completion, or nothing is written (the file stays whole)
        append_rows(f, items, path=self.path, what="stream_to", extra_bytes=200 * (len(events) + len(segments)))

    def _points(self, f: h5py.File, t_arr: NDArray[np.float64], y: Any, yp: Any, switch: Any,
                channels: Any) -> list[tuple[h5py.Dataset, Any]]:
        """The output rows' (dataset, rows), a dataset made at its first rows (switch, channels)."""
        if not t_arr.size:
            return []
        items: list[tuple[h5py.Dataset, Any]] = [(f["t"], t_arr), (f["y"], np.asarray(y, dtype=np.float64))]
        if "yp" in f:
            items.append((f["yp"], np.asarray(yp, dtype=np.float64)))
        if self._staged:  # a run with sensitivities: S of these rows (NaN for a row the run did not give S)
            k = t_arr.size
            for name, staged in zip(_STAGED, self._staged):
                if not staged.shape[1]:  # no integral: the empty dataset stays
                    continue
                rows = staged[:k] if staged.shape[0] >= k else np.concatenate(
                    [staged, np.full((k - staged.shape[0], *staged.shape[1:]), np.nan)])
                items.append((f[f"sensitivities/{name}"], rows))
            self._staged = [staged[k:] for staged in self._staged]
        rows = np.asarray(switch if switch is not None else np.zeros((t_arr.size, 0)), dtype=np.float64)
        if rows.shape[1:] != (0,):  # one row per point, repeated over a segment: gzip makes it small
            if "switch" not in f:
                self._grow(f, "switch", np.float64, rows.shape[1:], compress=True)
            items.append((f["switch"], rows))
        group = f["channels"]
        for name, values in (channels or {}).items():
            arr = np.asarray(values)
            if name not in group:
                self._grow(group, name, arr.dtype, arr.shape[1:],
                           compress=arr.dtype.kind in "biu").attrs["units"] = self._units.get(name, "")
            items.append((group[name], arr))
        return items

    def close(self, *, stats: Mapping[str, Any], success: bool, status: int, message: str,
              warnings: Iterable[Mapping[str, Any]] = ()) -> Path:
        """Write the statistics, the warnings and the outcome, and close the file (``counts``: what it holds)."""
        from .outputs import deferred_sigint

        f = self._f
        with deferred_sigint():
            try:
                kinds = Counter(str(k) for k in f["events/kind"].asstr()[()])
                #: what the file holds, read from it: a summary of a run kept only in its file says these
                self.counts: dict[str, Any] = {
                    "path": str(self.path), "n_points": int(f["t"].shape[0]), "n_events": sum(kinds.values()),
                    "events_by_kind": dict(kinds), "n_segments": int(f["segments/t_start"].shape[0])}
                plain = to_plain(dict(stats), "stats")
                del f["stats"], f["stats_json"], f["warnings_json"]
                mirror(f.create_group("stats"), plain)
                json_dataset(f, "stats_json", plain)
                json_dataset(f, "warnings_json", to_plain([dict(w) for w in warnings], "warnings"))
                self._outcome(success, status, message)
            finally:
                f.close()
        return self.path

    def abort(self, message: str) -> None:
        """Close the file after an unexpected error: its data so far, ``success=False`` and ``message``."""
        if not self._f:  # closed already
            return
        try:
            self._outcome(False, -1, message)
        finally:
            try:
                self._f.close()
            except (OSError, RuntimeError):  # the disk is full: the file keeps its last complete append
                pass
