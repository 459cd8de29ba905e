"""Writing a `Result` to HDF5: the file layout, `save_result` (atomic) and `write_result_group`.

The one place that knows how a finished result is laid out in a file; the streaming writer
(daeclear.results.hdf5_stream) and the reader (daeclear.results.hdf5_read) follow it with the helpers
and constants here. docs/hdf5_layout.md documents the file item by item (a test keeps it in step with
`_write`). h5py is imported only when a file is written.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # h5py is imported lazily, only where a file is written
    import h5py

    from .result import Result
    from .sensitivities import Sensitivities

__all__ = ["SIDES", "FORMAT_NAME", "FORMAT_VERSION", "integral_arrays", "json_dataset", "mirror", "save_result",
           "stores_states_only", "string_dataset", "write_result_group"]

FORMAT_NAME = "daeclear-result"
"""Value of the root ``format`` attribute of every file written by `Result.save`."""

FORMAT_VERSION = 2
"""Version of the HDF5 layout written by this daeclear; `load` reads versions <= this (version 1: every
channel stored, no ``/switch``)."""

SIDES: tuple[str, ...] = ("t", "y", "values", "states", "channels")
"""The datasets of ``/sensitivities/sides``: the fields of :class:`daeclear.results.sensitivities.EventSides`."""

_COMPRESS_MIN_SIZE = 16384  # values; smaller arrays are stored contiguous, uncompressed
_MIRROR_ATTR_MAX_LEN = 1024  # longer lists become datasets (HDF5 attributes are limited to 64 KiB)


def _compress(data: np.ndarray) -> bool:
    """Whether gzip is worth it: large integer, bool or mostly-zero arrays (general floats: ~20% at ~8x the time)."""
    if data.size < _COMPRESS_MIN_SIZE:
        return False
    return bool(data.dtype.kind in "biu" or np.count_nonzero(data) <= data.size // 2)


def _dataset(group: h5py.Group, name: str, data: np.ndarray, compress: bool = False) -> h5py.Dataset:
    """A numeric dataset with a Fletcher-32 checksum per chunk (`load` refuses a damaged one by name);
    ``compress``: gzip whatever its size (the switch rows: one row repeated over a segment)."""
    if not data.size:  # HDF5 cannot chunk an empty array: nothing to check either
        return group.create_dataset(name, data=data)
    if compress or _compress(data):
        return group.create_dataset(name, data=data, chunks=True, compression="gzip",
                                    compression_opts=1, shuffle=True, fletcher32=True)
    return group.create_dataset(name, data=data, chunks=True, fletcher32=True)


def string_dataset(group: h5py.Group, name: str, values: Sequence[str]) -> h5py.Dataset:
    """Write ``values`` as a dataset of UTF-8 strings (names, units, event pairs and kinds)."""
    import h5py

    return group.create_dataset(name, data=np.array(list(values), dtype=object), dtype=h5py.string_dtype())


def json_dataset(group: h5py.Group, name: str, value: Any) -> None:
    """Write ``value`` as a scalar JSON string dataset: the lossless copy of stats, parameters, warnings."""
    import h5py

    group.create_dataset(name, data=json.dumps(value, ensure_ascii=False), dtype=h5py.string_dtype())


def mirror(group: h5py.Group, tree: Mapping[str, Any]) -> None:
    """Write a nested dict as groups and attributes that any HDF5 tool can read."""
    import h5py

    for key, value in tree.items():
        if not key or "/" in key or key == ".":
            continue  # not an HDF5 name; the JSON copy keeps it
        if isinstance(value, dict):
            mirror(group.create_group(key), value)
            continue
        if isinstance(value, (bool, int, float, str)):
            data: Any = value
        elif isinstance(value, list) and value and (
            all(isinstance(v, bool) for v in value)
            or all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        ):
            data = np.asarray(value)
        elif isinstance(value, list) and value and all(isinstance(v, str) for v in value):
            data = np.array(value, dtype=h5py.string_dtype())
        else:
            continue  # None, empty, mixed or nested lists: JSON only
        try:
            if isinstance(data, np.ndarray) and data.size > _MIRROR_ATTR_MAX_LEN:
                group.create_dataset(key, data=data)
            else:
                group.attrs[key] = data
        except OverflowError:
            continue  # an int beyond 64 bits: JSON only


def _write(f: h5py.File | h5py.Group, r: Result, channels: bool = False) -> None:
    """Write ``r`` in the layout of a result file into an open HDF5 file or group (``channels``: every
    channel and yp, even when the reader could compute them)."""
    f.attrs["format"] = FORMAT_NAME
    f.attrs["version"] = FORMAT_VERSION
    for key in ("scene_name", "method", "formulation", "success", "status", "message"):
        f.attrs[key] = getattr(r, key)

    _dataset(f, "t", np.asarray(r.t)).attrs["units"] = "s"
    _dataset(f, "y", np.asarray(r.y))
    states_only = not channels and stores_states_only(r)
    if not states_only:  # else the reader computes yp from y (the run's consistency pass)
        _dataset(f, "yp", np.asarray(r.yp))
    string_dataset(f, "state_names", r.state_names)
    string_dataset(f, "state_units", [r.units[n] for n in r.state_names])

    source = r.channel_source
    if source is not None:
        _dataset(f, "switch", np.asarray(source.switch, dtype=np.float64), compress=True)
    group = f.create_group("channels")
    if states_only:  # the reader computes the channels from the states (load)
        string_dataset(f, "channel_names", r.channel_names)
        string_dataset(f, "channel_units", [r.units[n] for n in r.channel_names])
    else:
        for name in r.channel_names:
            _dataset(group, name, np.asarray(r.channels[name])).attrs["units"] = r.units[name]

    events = f.create_group("events")
    _dataset(events, "t", r.events.t)
    string_dataset(events, "pair", r.events.pair)
    string_dataset(events, "kind", r.events.kind)
    _dataset(events, "approach_speed", r.events.approach_speed)
    y_events = np.array([e.y for e in r.events], dtype=np.float64).reshape(len(r.events), r.n_states)
    _dataset(events, "y", y_events)

    segments = f.create_group("segments")
    _dataset(segments, "t_start", np.array([s[0] for s in r.segments], dtype=np.float64))
    _dataset(segments, "t_end", np.array([s[1] for s in r.segments], dtype=np.float64))
    string_dataset(segments, "modes", [json.dumps(s[2], ensure_ascii=False) for s in r.segments])

    if r.step_t is not None:
        steps = f.create_group("steps")
        for name, values in (("t", r.step_t), ("h", r.step_h), ("order", r.step_order)):
            _dataset(steps, name, np.asarray(values))

    if r.sensitivities is not None:
        _write_sensitivities(f.create_group("sensitivities"), r.sensitivities)

    for name, tree in (("stats", r.stats), ("parameters", r.parameters)):
        mirror(f.create_group(name), tree)
        json_dataset(f, f"{name}_json", tree)
    json_dataset(f, "warnings_json", r.warnings)


def _write_sensitivities(group: h5py.Group, s: Sensitivities) -> None:
    """A run's forward sensitivities (``simulate(..., sensitivities=[...])``): names, S of the states and
    the channels at every output time, each event time's sensitivity, the rows at each event, the integrals
    integrated as states with their sensitivities at every output time."""
    string_dataset(group, "names", s.names)
    if s.values is not None:
        _dataset(group, "values", np.asarray(s.values, dtype=np.float64))
    _dataset(group, "states", np.asarray(s.states, dtype=np.float64))
    string_dataset(group, "channel_names", s.channel_names)
    _dataset(group, "channels", np.asarray(s.channels, dtype=np.float64))
    events = group.create_group("events")
    _dataset(events, "t", np.array([e.t for e in s.events], dtype=np.float64))
    string_dataset(events, "pair", [e.pair for e in s.events])
    string_dataset(events, "kind", [e.kind for e in s.events])
    _dataset(events, "dt_dp", np.array([e.dt_dp for e in s.events], dtype=np.float64).reshape(-1, len(s.names)))
    if s.sides is not None:  # each event's rows before and after its switch (the objectives read them)
        sides = group.create_group("sides")
        for name in SIDES:
            _dataset(sides, name, np.asarray(getattr(s.sides, name), dtype=np.float64))
    names, Q, dQ = integral_arrays(s, len(s.states))
    integrals = group.create_group("integrals")  # (simulate(..., integrals=[...]); none: empty)
    string_dataset(integrals, "names", names)
    _dataset(integrals, "Q", Q)
    _dataset(integrals, "dQ", dQ)


def integral_arrays(s: Sensitivities, n: int) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The integrals of ``s`` as the file keeps them: their channels' names, Q (n, n_integrals) and dQ/dp
    (n, n_integrals, Ns), one row per output row (``n`` rows: none integrated, empty columns)."""
    names = list(s.integrals)
    Q = np.zeros((n, len(names)))
    dQ = np.zeros((n, len(names), len(s.names)))
    for i, name in enumerate(names):
        Q[:, i], dQ[:, i, :] = s.integrals[name]
    return names, Q, dQ


def stores_states_only(r: Result) -> bool:
    """Whether ``r``'s file keeps its states without the channels: a run's result whose model its
    parameters rebuild (else, e.g. a scene holding a Python callable, the channels are written)."""
    source = r.channel_source
    return source is not None and source.can_rebuild()


def save_result(r: Result, path: str | os.PathLike[str], channels: bool = False) -> Path:
    """Write ``r`` to an HDF5 file, atomically: what :meth:`Result.save` does (see its docstring)."""
    import h5py

    from .outputs import atomic_file, check_file, check_space, deferred_sigint, disk_full, is_disk_full

    path = check_file(path, "Result.save(path)")  # the one output-place rule (daeclear.results.outputs)
    size = sum(np.asarray(a).nbytes for a in (r.t, r.y)) + (
        8 * r.n_times * (r.n_states + len(r.channel_names)) if channels or not stores_states_only(r) else 0)
    check_space(path, size + 200 * len(r.events) * (1 + r.n_states), "Result.save(path)")  # before writing
    # a Ctrl-C during the write arrives once the file is complete (and renamed into place)
    try:
        with deferred_sigint(), atomic_file(path) as tmp, h5py.File(tmp, "x") as f:
            if channels:
                _write(f, r, channels=True)
            else:
                _write(f, r)
    except (OSError, RuntimeError) as exc:  # a full disk meanwhile: any file at path is left as it was
        if is_disk_full(exc):
            raise disk_full(path, "Result.save(path)", exc) from None
        raise
    return path


def write_result_group(group: h5py.Group, r: Result) -> None:
    """Write ``r`` in the layout of a result file (:meth:`Result.save`) into ``group``, an open group
    of another HDF5 file: a sweep keeps its full reference runs inside its own file this way
    (:func:`read_result_group` reads them back)."""
    _write(group, r)
