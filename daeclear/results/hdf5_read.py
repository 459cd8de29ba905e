"""Reading result files: the `Result` keywords from an HDF5 file, group or window, the file checked item by
item (keywords, so that daeclear.results.result offers `load` without an import circle).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.errors import DaeclearError, SceneError
from ..core.events import ContactEvent
from .hdf5_write import FORMAT_NAME, FORMAT_VERSION, SIDES
from .lazy_channels import LazyChannels, rebuilt_evaluator
from .sensitivities import EventSides, Sensitivities, sensitivity_events
from ..core.values import time_window

if TYPE_CHECKING:  # h5py is imported lazily, only where a file is read
    import h5py

__all__ = ["read_dataset", "read_file", "read_group"]


def read_file(path: str | os.PathLike[str], t0: float | None = None, t1: float | None = None, *,
              within: bool = True) -> dict[str, Any]:
    """The `Result` keywords of the result file at ``path``, of the window [t0, t1]; see :func:`daeclear.load`.
    ``within``: a window that misses the run's output times is an error (it would read nothing)."""
    import h5py

    path = Path(path)
    window = time_window(t0, t1, "load")  # checked before the file is opened
    if path.is_dir():
        raise IsADirectoryError(f"load: '{path}' is a directory; give a result file (.h5) in it, e.g. "
                                f"'{path / 'run.h5'}'.")
    if not path.is_file():
        raise FileNotFoundError(f"no result file '{path}'.")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise DaeclearError(f"'{path}' is not a daeclear result: it cannot be opened as HDF5 ({exc}).") from exc
    with f:
        fmt = f.attrs.get("format")
        if fmt is None:
            raise DaeclearError(f"'{path}' is not a daeclear result: the root attribute 'format' is missing "
                                f"(expected {FORMAT_NAME!r}, as written by Result.save).")
        if _text(fmt) != FORMAT_NAME:
            raise DaeclearError(f"'{path}' is not a daeclear result: root attribute format={_text(fmt)!r}, "
                                f"expected {FORMAT_NAME!r}.")
        version = f.attrs.get("version")
        if version is None:
            raise DaeclearError(f"'{path}' is a damaged daeclear result: the root attribute 'version' is missing.")
        if int(version) > FORMAT_VERSION:
            raise DaeclearError(f"'{path}' is a daeclear result of format version {int(version)}; this daeclear "
                                f"reads versions up to {FORMAT_VERSION}. Upgrade daeclear to read it.")
        if within and (t0 is not None or t1 is not None) and "t" in f and f["t"].shape[0]:
            first, last = float(f["t"][0]), float(f["t"][-1])
            if window[0] > last or window[1] < first:
                raise SceneError(f"load('{path}'): t0={t0!r}, t1={t1!r} s, must overlap the run's output times "
                                 f"[{first:g}, {last:g}] s (the window would read no point).")
        try:
            return _read(_Reader(f, path, window))
        except DaeclearError:
            raise
        except (OSError, RuntimeError, KeyError, ValueError) as exc:  # damaged metadata: named, not raw
            raise DaeclearError(f"'{path}' is a damaged daeclear result ({type(exc).__name__}: "
                                f"{str(exc).splitlines()[0] if str(exc) else 'unreadable'}).") from None


def read_dataset(path: str | os.PathLike[str], name: str) -> np.ndarray:
    """The dataset ``name`` of the file at ``path``, or an empty array if the file has none."""
    import h5py

    with h5py.File(path, "r") as f:
        return f[name][()] if name in f else np.zeros(0)


def _text(value: Any) -> str:
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


class _Reader:
    """Reads items of one file; a missing item raises DaeclearError naming file and item."""

    def __init__(self, f: h5py.Group, path: Path, window: tuple[float, float] = (-math.inf, math.inf)) -> None:
        self.f = f
        self.path = path
        self.window = window

    def rows(self, times: str) -> slice:
        """The rows of the time-ordered dataset ``times`` inside the window (all without one)."""
        lo, hi = self.window
        if lo == -math.inf and hi == math.inf:
            return slice(None)
        t = self.array(times)
        return slice(int(np.searchsorted(t, lo, side="left")), int(np.searchsorted(t, hi, side="right")))

    def _missing(self, what: str) -> DaeclearError:
        return DaeclearError(f"'{self.path}' is a damaged daeclear result: {what} is missing.")

    def has(self, name: str) -> bool:
        return name in self.f

    def _get(self, name: str) -> Any:
        if name not in self.f:
            raise self._missing(f"dataset '/{name}'")
        return self.f[name]

    def array(self, name: str, rows: slice | None = None) -> np.ndarray:
        data = self._get(name)
        try:
            return data[()] if rows is None else data[rows]
        except (OSError, RuntimeError) as exc:  # a failed checksum (Fletcher-32) or a damaged chunk index
            raise DaeclearError(f"'{self.path}' is a damaged daeclear result: dataset '/{name}' cannot be read "
                                f"({str(exc).splitlines()[0]}).") from None

    def strings(self, name: str, rows: slice | None = None) -> list[str]:
        text = self._get(name).asstr()
        return [str(s) for s in (text[()] if rows is None else text[rows])]

    def json(self, name: str) -> Any:
        return json.loads(self._get(name).asstr()[()])

    def attr(self, name: str, obj: str = "/") -> Any:
        attrs = self.f[obj.lstrip("/") or "."].attrs  # relative: a file's root, or a group holding a result
        if name not in attrs:
            raise self._missing(f"attribute '{name}' of '{obj}'")
        value = attrs[name]
        return value.item() if isinstance(value, np.generic) else _text(value) if isinstance(value, bytes) else value


def _read(r: _Reader) -> dict[str, Any]:
    """The `Result` keywords read by ``r``."""
    state_names = r.strings("state_names")
    state_units = r.strings("state_units")
    units = dict(zip(state_names, state_units))
    if "channels" not in r.f:
        raise r._missing("group '/channels'")
    points = r.rows("t")
    t, y = r.array("t", points), r.array("y", points)
    yp = r.array("yp", points) if r.has("yp") or not r.has("channel_names") else None  # None: computed
    parameters = r.json("parameters_json")
    channels: dict[str, np.ndarray] | LazyChannels = {}
    if r.has("channel_names"):  # states only (version 2): the channels are computed when read
        names = r.strings("channel_names")
        switch = r.array("switch", points) if r.has("switch") else np.zeros((t.size, 0))  # no point written
        units.update(zip(names, r.strings("channel_units")))
        evaluate, consistent = rebuilt_evaluator(parameters)
        channels = LazyChannels(names, evaluate, t, y, yp, switch, consistent=consistent, rebuildable=True)
    for name in r.f["channels"]:
        channels[name] = r.array(f"channels/{name}", points)  # type: ignore[index]
        units[name] = r.attr("units", f"/channels/{name}")

    rows = r.rows("events/t")
    columns = (r.array("events/t", rows), r.strings("events/pair", rows), r.strings("events/kind", rows),
               r.array("events/approach_speed", rows), r.array("events/y", rows))
    if len({len(c) for c in columns}) != 1:
        raise DaeclearError(f"'{r.path}' is a damaged daeclear result: the datasets of '/events' have different "
                            f"lengths {[len(c) for c in columns]}.")
    events = [ContactEvent(t=t, pair=pair, kind=kind, approach_speed=speed, y=y)  # type: ignore[arg-type]
              for t, pair, kind, speed, y in zip(*columns)]
    lo, hi = r.window
    starts, ends = r.array("segments/t_start"), r.array("segments/t_end")
    keep = np.flatnonzero((starts < hi) & (ends > lo))  # the segments overlapping the window, clipped to it
    first = int(keep[0]) if keep.size else 0
    modes = r.strings("segments/modes", slice(first, int(keep[-1]) + 1 if keep.size else 0))
    segments = [(max(float(starts[i]), lo), min(float(ends[i]), hi), json.loads(modes[i - first])) for i in keep]
    steps: dict[str, Any] = {}
    if r.has("steps"):
        rows = r.rows("steps/t")
        steps = {"step_t": r.array("steps/t", rows), "step_h": r.array("steps/h", rows),
                 "step_order": r.array("steps/order", rows)}

    sensitivities = None
    if r.has("sensitivities"):  # a run with sensitivities: its rows of the window, its events in it
        parameters_s = tuple(r.strings("sensitivities/names"))
        ev_t = r.array("sensitivities/events/t")
        inside = [i for i, at in enumerate(ev_t.tolist()) if lo <= at <= hi]
        pairs, kinds = r.strings("sensitivities/events/pair"), r.strings("sensitivities/events/kind")
        dt_dp = r.array("sensitivities/events/dt_dp").reshape(-1, len(parameters_s))
        sensitivities = Sensitivities(
            parameters_s, tuple(state_names), tuple(r.strings("sensitivities/channel_names")),
            r.array("sensitivities/states", points), r.array("sensitivities/channels", points),
            sensitivity_events([float(ev_t[i]) for i in inside], [pairs[i] for i in inside],
                               [kinds[i] for i in inside], dt_dp[inside]), _sides(r),
            r.array("sensitivities/values") if r.has("sensitivities/values") else None, _integrals(r, points))
    return dict(t=t, y=y, yp=yp, state_names=state_names, channels=channels, units=units, events=events,
                sensitivities=sensitivities,
                segments=segments, stats=r.json("stats_json"), success=bool(r.attr("success")),
                status=int(r.attr("status")), message=str(r.attr("message")), parameters=parameters,
                scene_name=str(r.attr("scene_name")), method=str(r.attr("method")),
                formulation=str(r.attr("formulation")),
                warnings=r.json("warnings_json") if r.has("warnings_json") else [],  # older files: no warnings
                **steps)


def _sides(r: _Reader) -> EventSides | None:
    """The rows at each event inside the window (None in a file written before they were kept)."""
    if not r.has("sensitivities/sides"):
        return None
    t = r.array("sensitivities/sides/t")
    lo, hi = r.window
    rows = (t >= lo) & (t <= hi)
    return EventSides(*(r.array(f"sensitivities/sides/{name}")[rows] for name in SIDES))


def _integrals(r: _Reader, points: slice) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The integrals integrated as states at the window's rows (none in a file written before they were kept)."""
    if not r.has("sensitivities/integrals"):
        return {}
    names = r.strings("sensitivities/integrals/names")
    if not names:  # none integrated (a streamed file's empty arrays have no rows either)
        return {}
    Q, dQ = r.array("sensitivities/integrals/Q", points), r.array("sensitivities/integrals/dQ", points)
    return {name: (Q[:, i], dQ[:, i, :]) for i, name in enumerate(names)}


def read_group(group: h5py.Group, path: Path) -> dict[str, Any]:
    """The `Result` keywords of what :func:`write_result_group` wrote into ``group``, an open group of
    the file at ``path`` (named in the messages about a damaged result)."""
    return _read(_Reader(group, path))
