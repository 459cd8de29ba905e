"""The streaming writer `ResultWriter`: a result written to HDF5 append by append while its run goes on (a long
run never holds all its data in memory), in the layout of daeclear.results.hdf5_write, so `load` reads both alike.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .hdf5_write import FORMAT_NAME, FORMAT_VERSION, json_dataset, mirror, string_dataset
from ..core.values import to_plain

if TYPE_CHECKING:  # h5py is imported lazily, only where a file is written
    import h5py

    from ..core.events import ContactEvent

__all__ = ["STREAM_RUNNING", "ResultWriter"]

_STREAM_ROWS = 1024  # rows per HDF5 chunk of a streamed 2-D array (1-D arrays: 4 times as many)
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
        self._touched: list[tuple[h5py.Dataset, int]] = []  # (dataset, rows before) of the append under way
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
                               rows=_STREAM_ROWS if group == "steps" else _LIST_ROWS)
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

    @staticmethod
    def _grow(group: h5py.Group, name: str, dtype: Any, rest: tuple[int, ...] = (),
              compress: bool = False, rows: int | None = None) -> h5py.Dataset:
        import h5py

        if rows is None:
            rows = _STREAM_ROWS if rest else 4 * _STREAM_ROWS
        extra: dict[str, Any] = {"compression": "gzip", "compression_opts": 1, "shuffle": True} if compress else {}
        if h5py.check_string_dtype(np.dtype(dtype)) is None:  # a checksum per chunk (not on strings: HDF5 cannot)
            extra["fletcher32"] = True
        return group.create_dataset(name, shape=(0, *rest), maxshape=(None, *rest), dtype=dtype,
                                    chunks=(rows, *rest), **extra)

    def _outcome(self, success: bool, status: int, message: str) -> None:
        self._f.attrs["success"] = bool(success)
        self._f.attrs["status"] = int(status)
        self._f.attrs["message"] = str(message)

    def _extend(self, dataset: h5py.Dataset, rows: Any) -> None:
        k = len(rows)
        if k:
            n = dataset.shape[0]
            self._touched.append((dataset, n))
            dataset.resize(n + k, axis=0)
            dataset[n:n + k] = rows

    def append(self, *, t: ArrayLike = (), y: ArrayLike | None = None, yp: ArrayLike | None = None,
               switch: ArrayLike | None = None, channels: Mapping[str, ArrayLike] | None = None,
               events: Sequence[ContactEvent] = (),
               segments: Sequence[tuple[float, float, Mapping[str, str]]] = (), step_t: ArrayLike = (),
               step_h: ArrayLike = (), step_order: ArrayLike = ()) -> None:
        """Add output rows (``t``, ``y``, ``yp``, ``switch``, ``channels``: one row per time), events,
        segments and steps; written whole (a Ctrl-C meanwhile is raised afterwards) and flushed."""
        from .outputs import check_space, deferred_sigint, disk_full, is_disk_full

        f = self._f
        t_arr = np.asarray(t, dtype=np.float64)
        self._touched = []
        size = sum(np.asarray(a).nbytes for a in (t_arr, y if y is not None else (), yp if yp is not None else (),
                                                   step_t, step_h, step_order, *(channels or {}).values()))
        # room for this append and the file's completion, or nothing is written (the file stays whole)
        check_space(self.path, size + 200 * (len(events) + len(segments)), "stream_to")
        with deferred_sigint():
            try:
                self._append(f, t_arr, y, yp, switch, channels, events, segments, step_t, step_h, step_order)
                f.flush()
            except BaseException as exc:  # e.g. MemoryError: every dataset back to its length before, then go on
                for dataset, n in reversed(self._touched):
                    dataset.resize(n, axis=0)
                if is_disk_full(exc):
                    raise disk_full(self.path, "stream_to", exc) from None
                raise

    def _append(self, f: h5py.File, t_arr: NDArray[np.float64], y: Any, yp: Any, switch: Any, channels: Any,
                events: Any, segments: Any, step_t: Any, step_h: Any, step_order: Any) -> None:
        if t_arr.size:
            self._extend(f["t"], t_arr)
            self._extend(f["y"], np.asarray(y, dtype=np.float64))
            if "yp" in f:
                self._extend(f["yp"], np.asarray(yp, dtype=np.float64))
            rows = np.asarray(switch if switch is not None else np.zeros((t_arr.size, 0)), dtype=np.float64)
            if rows.shape[1:] != (0,):  # one row per point, repeated over a segment: gzip makes it small
                if "switch" not in f:
                    self._grow(f, "switch", np.float64, rows.shape[1:], compress=True)
                self._extend(f["switch"], rows)
            group = f["channels"]
            for name, values in (channels or {}).items():
                arr = np.asarray(values)
                if name not in group:
                    self._grow(group, name, arr.dtype, arr.shape[1:],
                               compress=arr.dtype.kind in "biu").attrs["units"] = self._units.get(name, "")
                self._extend(group[name], arr)
        g = f["events"]  # no rows: each _extend does nothing
        self._extend(g["t"], np.array([e.t for e in events], dtype=np.float64))
        self._extend(g["pair"], np.array([e.pair for e in events], dtype=object))
        self._extend(g["kind"], np.array([e.kind for e in events], dtype=object))
        self._extend(g["approach_speed"], np.array([e.approach_speed for e in events], dtype=np.float64))
        self._extend(g["y"], np.array([e.y for e in events], dtype=np.float64).reshape(len(events), self._n))
        g = f["segments"]
        self._extend(g["t_start"], np.array([float(s[0]) for s in segments], dtype=np.float64))
        self._extend(g["t_end"], np.array([float(s[1]) for s in segments], dtype=np.float64))
        self._extend(g["modes"], np.array(
            [json.dumps({str(k): str(v) for k, v in s[2].items()}, ensure_ascii=False) for s in segments],
            dtype=object))
        g = f["steps"]
        self._extend(g["t"], np.asarray(step_t, dtype=np.float64))
        self._extend(g["h"], np.asarray(step_h, dtype=np.float64))
        self._extend(g["order"], np.asarray(step_order, dtype=np.int64))

    def close(self, *, stats: Mapping[str, Any], success: bool, status: int, message: str,
              warnings: Iterable[Mapping[str, Any]] = ()) -> Path:
        """Write the statistics, the warnings and the outcome, and close the file."""
        from .outputs import deferred_sigint

        f = self._f
        with deferred_sigint():
            try:
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
