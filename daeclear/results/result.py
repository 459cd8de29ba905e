"""What a simulation returns: time series, named channels, contact events, statistics.

A `Result` is a pure data container filled by the solver (`solvers/ida.py`,
`solvers/explicit.py`); it computes nothing about mechanics. It also owns the HDF5
round trip: `Result.save`, `ResultWriter` (the same file written while a run goes on),
`load` (whole or a time window) and `load_times`, and the hand-off to pandas and xarray
(`Result.to_pandas`, `Result.events_frame`, `Result.to_xarray`; optional
dependencies, the ``data`` extra). h5py is imported here and nowhere else in
daeclear, and only when a file is written or read; pandas and xarray only when asked for.

docs/hdf5_layout.md documents the file item by item for readers without daeclear
(a test keeps it in step with `_write`).

HDF5 layout (root attributes ``format="daeclear-result"``, ``version=1``)::

    /                     attrs: format, version, scene_name, method, formulation,
                                 success, status, message
    /t                    (n_times,)            attr units="s"
    /y, /yp               (n_times, n_states)   time first
    /state_names          (n_states,)           strings, e.g. "crank.x", "lambda.A.x"
    /state_units          (n_states,)           strings ("" when unknown)
    /channels/<name>      (n_times, ...)        attr units; one dataset per channel
    /events/t             (n_events,)
    /events/pair          (n_events,)           strings
    /events/kind          (n_events,)           "onset" | "separation"
    /events/approach_speed (n_events,)          m/s, nan where meaningless
    /events/y             (n_events, n_states)  full state at each event
    /segments/t_start, /segments/t_end  (n_segments,)
    /segments/modes       (n_segments,)         JSON object per segment: {pair: mode}
    /steps/t, /steps/h, /steps/order            IDA's internal steps (only if recorded)
    /stats                group, one attribute per statistic
    /stats_json           scalar string: the statistics as JSON (what `load` reads)
    /parameters           groups and attributes mirroring the nested parameters
    /parameters_json      scalar string: the parameters as JSON (what `load` reads)
    /warnings_json        scalar string: the physics warnings as a JSON list (absent in older files)

Channel names keep their dots (``/channels/slider.vx``): a "." is an ordinary
character in an HDF5 name. The ``/stats`` and ``/parameters`` groups are a
readable mirror for other tools (HDFView, h5dump, MATLAB): every number, string,
bool and homogeneous list becomes an attribute (a dataset when longer than
1024 items), every nested dict a group. Values that HDF5 cannot hold this way
(None, mixed lists, lists of dicts) live only in the JSON copies, which are the
lossless source `load` reads. Arrays of more than 16384 values that compress
cheaply (integers, bools, mostly-zero floats such as contact forces) are stored
chunked with shuffle + gzip level 1, which any HDF5 tool reads; other float
arrays stay contiguous and uncompressed (gzip would save ~20% at ~8x the time).
"""

from __future__ import annotations

import json
import math
import os
import uuid
from collections.abc import Iterable, Iterator, Mapping, Sequence
import warnings
from dataclasses import dataclass, fields, is_dataclass
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import DaeclearError, DaeclearWarning, MissingDependencyError
from ..options import close_matches

if TYPE_CHECKING:  # h5py, pandas and xarray are imported lazily, only where they are used
    import h5py
    import pandas as pd
    import xarray as xr

__all__ = [
    "FORMAT_NAME",
    "ResultWriter",
    "FORMAT_VERSION",
    "ChannelKeyError",
    "ContactEvent",
    "EventList",
    "Result",
    "load",
    "load_times",
]

FORMAT_NAME = "daeclear-result"
"""Value of the root ``format`` attribute of every file written by `Result.save`."""

FORMAT_VERSION = 1
"""Version of the HDF5 layout written by this daeclear; `load` reads versions <= this."""

EventKind = Literal["onset", "separation"]
EVENT_KINDS: tuple[str, ...] = ("onset", "separation")

_COMPRESS_MIN_SIZE = 16384  # values; smaller arrays are stored contiguous, uncompressed
_MIRROR_ATTR_MAX_LEN = 1024  # longer lists become datasets (HDF5 attributes are limited to 64 KiB)


class ChannelKeyError(DaeclearError, KeyError):
    """A channel or state name that the result does not hold.

    A `KeyError` (so ``except KeyError`` works) whose message is printed
    without the quotes `KeyError` normally adds.
    """

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# --------------------------------------------------------------------------- events


def _same_float(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


def _readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (the caller's array keeps its own flags)."""
    view = a.view()
    view.flags.writeable = False
    return view


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
        ``"onset"`` when the gap closes (free -> contact), ``"separation"`` when
        it opens (contact -> free).
    approach_speed : float
        Relative normal velocity at the event (m/s), the initial impact speed
        used by Lankarani-Nikravesh and Hunt-Crossley at onset; ``nan`` where
        meaningless.
    y : ndarray, shape (n_states,)
        Full state at the event, ordered as `Result.state_names`. Stored as a
        read-only float64 array.

    Notes
    -----
    Two events are equal when all fields are equal, ``nan`` equal to ``nan``.
    """

    t: float
    pair: str
    kind: EventKind
    approach_speed: float
    y: NDArray[np.float64]

    def __post_init__(self) -> None:
        if self.kind not in EVENT_KINDS:
            raise ValueError(
                f"ContactEvent for pair {self.pair!r} at t={self.t}: kind={self.kind!r}, "
                f"must be 'onset' or 'separation'."
            )
        y = np.asarray(self.y, dtype=np.float64)
        if y.ndim != 1:
            raise ValueError(
                f"ContactEvent for pair {self.pair!r} at t={self.t}: y has shape {y.shape}, "
                f"must be one state vector (n_states,)."
            )
        object.__setattr__(self, "t", float(self.t))
        object.__setattr__(self, "pair", str(self.pair))
        object.__setattr__(self, "approach_speed", float(self.approach_speed))
        object.__setattr__(self, "y", _readonly(y))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ContactEvent):
            return NotImplemented
        return (
            _same_float(self.t, other.t)
            and self.pair == other.pair
            and self.kind == other.kind
            and _same_float(self.approach_speed, other.approach_speed)
            and np.array_equal(self.y, other.y, equal_nan=True)
        )

    __hash__ = None  # type: ignore[assignment]  # holds an array

    def __repr__(self) -> str:
        return (
            f"ContactEvent(t={self.t:.9g}, pair={self.pair!r}, kind={self.kind!r}, "
            f"approach_speed={self.approach_speed:.6g})"
        )


class EventList(Sequence[ContactEvent]):
    """An immutable, list-like sequence of `ContactEvent`, in the solver's (time) order.

    Indexing with an int gives one event, with a slice an `EventList`.
    The properties `t`, `approach_speed`, `pair` and `kind` give one field of
    every event; `of` filters.

    Examples
    --------
    >>> onsets = result.events.of("C", kind="onset")   # doctest: +SKIP
    >>> onsets.t, onsets.approach_speed                # doctest: +SKIP
    """

    __slots__ = ("_events",)

    def __init__(self, events: Iterable[ContactEvent] = ()) -> None:
        items = tuple(events)
        for i, event in enumerate(items):
            if not isinstance(event, ContactEvent):
                raise TypeError(f"events[{i}] is a {type(event).__name__}, expected a ContactEvent.")
        self._events: tuple[ContactEvent, ...] = items

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
        """The events of one contact pair and/or one kind.

        Parameters
        ----------
        pair : str, optional
            Pair name. Matches that pair and every pair below it in the dotted
            naming: ``"clearance"`` selects ``"clearance"`` and
            ``"clearance.A_upper"``, not ``"clearance2"``. None: every pair.
        kind : {"onset", "separation"}, optional
            None: both kinds.

        Returns
        -------
        EventList
            The matching events, in their original order (possibly empty: a
            pair that never touched has no events).

        Raises
        ------
        ValueError
            If `kind` is not ``"onset"``, ``"separation"`` or None.
        """
        if kind is not None and kind not in EVENT_KINDS:
            raise ValueError(f"EventList.of: kind={kind!r}, must be 'onset', 'separation' or None.")
        prefix = None if pair is None else pair + "."
        return EventList(
            e
            for e in self._events
            if (pair is None or e.pair == pair or e.pair.startswith(prefix))  # type: ignore[arg-type]
            and (kind is None or e.kind == kind)
        )

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


# --------------------------------------------------------------------------- plain values


# exact types _plain returns unchanged (subclasses such as numpy.float64 take the checks below)
_PLAIN_LEAVES = frozenset({type(None), bool, str, int, float})


def _plain(value: Any, where: str) -> Any:
    """``value`` as plain JSON-able Python.

    numpy scalars and arrays, tuples and paths are converted; a dataclass instance (e.g. a
    Material) becomes the dict of its fields, headed by ``"name"`` when its class has a name
    (a contact or friction law: figures and readers of the file need to know which law). Anything else is stored as its ``repr`` with a
    DaeclearWarning naming ``where``: a finished run is never lost to an odd parameter.
    Non-string dict keys raise TypeError.
    """
    if type(value) in _PLAIN_LEAVES:  # the common case first: plain numbers and strings stay as they are
        return value
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if type(value) is dict or isinstance(value, Mapping):
        out: dict[str, Any] = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise TypeError(f"{where}: key {key!r} is a {type(key).__name__}, keys must be strings.")
            out[key] = item if type(item) in _PLAIN_LEAVES else _plain(item, f"{where}[{key!r}]")
        return out
    if isinstance(value, (list, tuple)):
        return [item if type(item) in _PLAIN_LEAVES else _plain(item, f"{where}[{i}]") for i, item in enumerate(value)]
    # after the containers: dicts and lists, the bulk of a scene, skip these (slower ABC) checks
    if isinstance(value, np.generic):
        return _plain(value.item(), where)
    if isinstance(value, np.ndarray):
        return _plain(value.tolist(), where)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if is_dataclass(value) and not isinstance(value, type):
        out = {f.name: _plain(getattr(value, f.name), f"{where}[{f.name!r}]") for f in fields(value)}
        kind = getattr(type(value), "name", None)  # a contact law's registered name, e.g. "hunt-crossley"
        if isinstance(kind, str) and "name" not in out:
            out = {"name": kind, **out}
        return out
    text = repr(value)
    warnings.warn(
        f"{where}: a {type(value).__name__} is not a number, string, bool, None, list or dict; "
        f"stored as its repr {text[:60]!r}.",
        DaeclearWarning,
        stacklevel=4,
    )
    return text


# --------------------------------------------------------------------------- Result


class Result:
    """The outcome of a simulation: time series, named channels, events, statistics.

    Built by the solver; every argument is keyword-only. Arrays are kept as
    read-only views (copy before editing).

    Parameters
    ----------
    t : array_like, shape (n_times,)
        Output times (s), non-decreasing (an event time may appear twice,
        before and after a restart).
    y, yp : array_like, shape (n_times, n_states)
        States and their time derivatives, time first.
    state_names : list of str
        Name of each state, e.g. ``"crank.x"``, ``"crank.vx"``, ``"lambda.A.x"``.
    channels : mapping of str to array_like
        Named outputs ``"<object>.<quantity>"`` (e.g. ``"slider.vx"``,
        ``"motor.moment"``), each with first dimension n_times. Dtypes are kept.
        Names must not contain "/".
    units : mapping of str to str
        Unit of channels and states (e.g. ``"m/s"``). Names without a unit get
        ``""``; a name that is neither a channel nor a state is an error.
    events : sequence of ContactEvent, optional
        Contact transitions, in time order.
    segments : sequence of (t_start, t_end, modes), optional
        Integration segments between restarts; ``modes`` maps each contact pair
        to ``"free"`` or ``"contact"``.
    step_t, step_h, step_order : array_like, shape (n_steps,), optional
        IDA's internal steps: time reached, step size, BDF order. Given
        together or not at all; they differ from `t` when `t_eval` was given.
    stats : mapping, optional
        Solver statistics as given by the solver (``n_steps``,
        ``n_res_evals``, ``n_jac_evals``, ``n_events``, ``n_restarts``,
        ``setup_time``, ``solve_time``, ...).
    success : bool, default True
        False when the run failed (``status == -1``).
    status : {0, 1, -1}, default 0
        0: end time reached; 1: a terminal event stopped the run; -1: failed.
    message : str, default ""
        The solver's last word, e.g. why it failed.
    parameters : mapping, optional
        Nested parameters of the scene and the run, e.g.
        ``{"scene": {...}, "simulate": {"rtol": 1e-6, ...}}``: numbers,
        strings, bools, None, lists and dicts. numpy scalars and arrays,
        tuples and paths are converted to plain floats, ints, lists and
        strings, dataclass instances to dicts of their fields.
    scene_name, method, formulation : str, default ""
        Where the result came from: the scene's name, the integrator
        (``"ida"``, ``"DOP853"``, ...) and the DAE formulation (``"index1"``, ``"ggl"``).
    warnings : sequence of dict, optional
        What the run's physics checks found (see :mod:`daeclear.solvers.physics`): each a dict with
        ``kind``, ``quantity``, ``value``, ``limit``, ``unit``, ``where``, ``t``, ``message``.

    Raises
    ------
    ValueError
        On inconsistent shapes, names or status.
    TypeError
        If a dict in `parameters` or `stats` has a key that is not a string.

    Warns
    -----
    DaeclearWarning
        When a value in `parameters` or `stats` is none of the storable types
        (nor a dataclass, which becomes a dict of its fields); it is stored as
        its ``repr``.

    Examples
    --------
    >>> result["slider.vx"], result.units["slider.vx"]          # doctest: +SKIP
    >>> result.events.of("C", kind="onset").t                   # doctest: +SKIP
    >>> late = result.slice(0.04, 0.06)                         # doctest: +SKIP
    >>> path = result.save("run.h5"); again = load(path)        # doctest: +SKIP
    """

    def __init__(
        self,
        *,
        t: ArrayLike,
        y: ArrayLike,
        yp: ArrayLike,
        state_names: Sequence[str],
        channels: Mapping[str, ArrayLike],
        units: Mapping[str, str],
        events: Iterable[ContactEvent] = (),
        segments: Iterable[tuple[float, float, Mapping[str, str]]] = (),
        step_t: ArrayLike | None = None,
        step_h: ArrayLike | None = None,
        step_order: ArrayLike | None = None,
        stats: Mapping[str, Any] | None = None,
        success: bool = True,
        status: int = 0,
        message: str = "",
        parameters: Mapping[str, Any] | None = None,
        scene_name: str = "",
        method: str = "",
        formulation: str = "",
        warnings: Iterable[Mapping[str, Any]] = (),
    ) -> None:
        t_arr = np.asarray(t, dtype=np.float64)
        if t_arr.ndim != 1:
            raise ValueError(f"Result: t has shape {t_arr.shape}, must be (n_times,).")
        if np.any(np.diff(t_arr) < 0):
            i = int(np.argmax(np.diff(t_arr) < 0))
            raise ValueError(f"Result: t must be non-decreasing; t[{i}]={t_arr[i]} > t[{i + 1}]={t_arr[i + 1]}.")
        n_times = t_arr.shape[0]

        names = [str(n) for n in state_names]
        if len(set(names)) != len(names):
            dup = sorted({n for n in names if names.count(n) > 1})
            raise ValueError(f"Result: state names {dup} appear more than once.")
        shape = (n_times, len(names))
        y_arr = np.asarray(y, dtype=np.float64)
        yp_arr = np.asarray(yp, dtype=np.float64)
        for label, arr in (("y", y_arr), ("yp", yp_arr)):
            if arr.shape != shape:
                raise ValueError(
                    f"Result: {label} has shape {arr.shape}, expected (n_times, n_states) = {shape} "
                    f"from t and state_names."
                )

        chans: dict[str, np.ndarray] = {}
        for name, values in channels.items():
            if not isinstance(name, str) or not name or "/" in name or name == ".":
                raise ValueError(f"Result: channel name {name!r} is invalid; use '<object>.<quantity>' without '/'.")
            arr = np.asarray(values)
            if arr.ndim == 0 or arr.shape[0] != n_times:
                raise ValueError(
                    f"Result: channel {name!r} has shape {arr.shape}, its first dimension must be n_times={n_times}."
                )
            chans[name] = _readonly(arr)

        known = set(chans) | set(names)
        unit_map: dict[str, str] = {}
        for name, unit in units.items():
            if name not in known:
                close = close_matches(name, sorted(known), n=3)
                hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
                raise ValueError(f"Result: units given for {name!r}, which is neither a channel nor a state.{hint}")
            if not isinstance(unit, str):
                raise ValueError(f"Result: unit of {name!r} is {unit!r}, must be a string such as 'm/s'.")
        for name in [*names, *sorted(chans)]:
            unit_map[name] = units.get(name, "")

        event_list = EventList(events)
        for e in event_list:
            if e.y.shape != (len(names),):
                raise ValueError(
                    f"Result: event {e!r} has a state of shape {e.y.shape}, expected ({len(names)},)."
                )

        segs: list[tuple[float, float, dict[str, str]]] = []
        for i, (t_start, t_end, modes) in enumerate(segments):
            if not t_start <= t_end:
                raise ValueError(f"Result: segment {i} runs from t={t_start} to t={t_end}, must not run backwards.")
            segs.append((float(t_start), float(t_end), {str(k): str(v) for k, v in modes.items()}))

        given = [a is not None for a in (step_t, step_h, step_order)]
        if any(given) and not all(given):
            raise ValueError("Result: step_t, step_h and step_order are given together or not at all.")
        steps: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        if all(given):
            st = np.asarray(step_t, dtype=np.float64)
            sh = np.asarray(step_h, dtype=np.float64)
            so = np.asarray(step_order, dtype=np.int64)
            if st.ndim != 1 or sh.shape != st.shape or so.shape != st.shape:
                raise ValueError(
                    f"Result: step_t, step_h, step_order have shapes {st.shape}, {sh.shape}, {so.shape}; "
                    f"they must be equal and one-dimensional."
                )
            steps = (_readonly(st), _readonly(sh), _readonly(so))

        if status not in (-1, 0, 1):
            raise ValueError(f"Result: status={status!r}, must be 0 (end reached), 1 (terminal event) or -1 (failed).")
        if bool(success) != (status >= 0):
            raise ValueError(f"Result: success={success} contradicts status={status} (only status -1 is a failure).")

        self.t: NDArray[np.float64] = _readonly(t_arr)
        self.y: NDArray[np.float64] = _readonly(y_arr)
        self.yp: NDArray[np.float64] = _readonly(yp_arr)
        self.state_names: list[str] = names
        self._channels = chans
        self.units: dict[str, str] = unit_map
        self._events = event_list
        self.segments: list[tuple[float, float, dict[str, str]]] = segs
        self._steps = steps
        self.stats: dict[str, Any] = _plain(dict(stats or {}), "stats")
        self.success: bool = bool(success)
        self.status: int = int(status)
        self.message: str = str(message)
        self.parameters: dict[str, Any] = _plain(dict(parameters or {}), "parameters")
        self.scene_name: str = str(scene_name)
        self.method: str = str(method)
        self.formulation: str = str(formulation)
        self.warnings: list[dict[str, Any]] = _plain([dict(w) for w in warnings], "warnings")

    # ------------------------------------------------------------------ access

    @property
    def channels(self) -> Mapping[str, np.ndarray]:
        """Read-only mapping of channel name to array (first dimension n_times)."""
        return MappingProxyType(self._channels)

    @property
    def channel_names(self) -> list[str]:
        """Channel names, sorted (state names not included; see `state_names`)."""
        return sorted(self._channels)

    @property
    def events(self) -> EventList:
        """Contact events, in time order."""
        return self._events

    @property
    def step_t(self) -> NDArray[np.float64] | None:
        """Times reached by IDA's internal steps, or None if not recorded."""
        return None if self._steps is None else self._steps[0]

    @property
    def step_h(self) -> NDArray[np.float64] | None:
        """Sizes of IDA's internal steps (s), or None if not recorded."""
        return None if self._steps is None else self._steps[1]

    @property
    def step_order(self) -> NDArray[np.int64] | None:
        """BDF order of IDA's internal steps, or None if not recorded."""
        return None if self._steps is None else self._steps[2]

    @property
    def n_times(self) -> int:
        """Number of output times."""
        return int(self.t.shape[0])

    @property
    def n_states(self) -> int:
        """Number of states (columns of `y`)."""
        return len(self.state_names)

    def __getitem__(self, name: str) -> np.ndarray:
        """The channel, or else the state column, called `name`.

        Raises
        ------
        ChannelKeyError
            (a KeyError) if neither exists; the message lists close matches.
        """
        if not isinstance(name, str):
            raise TypeError(
                f"Result[...] takes a channel or state name (str), got {type(name).__name__}; "
                f"use result.t, result.y for the arrays."
            )
        if name in self._channels:
            return self._channels[name]
        if name in self.state_names:
            return self.y[:, self.state_names.index(name)]
        candidates = sorted(set(self._channels) | set(self.state_names))
        close = close_matches(name, candidates)
        if close:
            hint = "Close matches: " + ", ".join(repr(c) for c in close) + "."
        else:
            hint = f"See result.channel_names ({len(self._channels)}) and result.state_names ({self.n_states})."
        raise ChannelKeyError(f"no channel {name!r}. {hint}")

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and (name in self._channels or name in self.state_names)

    # A Result is not iterable: iterate over result.channel_names or result.state_names.
    __iter__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        def seconds(x: float) -> str:
            return f"{x:.3g} s"

        lines = [
            f"daeclear Result: scene {self.scene_name!r}, method {self.method!r}, formulation {self.formulation!r}",
            f"  success: {self.success} (status {self.status}): {self.message!r}",
        ]
        if self.n_times:
            lines.append(
                f"  time: {self.t[0]:.6g} to {self.t[-1]:.6g} s, {self.n_times} output times, {self.n_states} states"
            )
        else:
            lines.append(f"  time: no output times, {self.n_states} states")
        n_steps = self.stats.get("n_steps", None if self._steps is None else len(self._steps[0]))
        counts = ", ".join(f"{self._events.kind.count(k)} {k}" for k in EVENT_KINDS)
        lines.append(
            f"  steps: {n_steps if n_steps is not None else '?'}, {len(self._events)} events ({counts}), "
            f"{len(self.segments)} segments"
        )
        setup, solve = self.stats.get("setup_time"), self.stats.get("solve_time")
        wall = self.stats.get("wall_time")
        if wall is None and isinstance(setup, (int, float)) and isinstance(solve, (int, float)):
            wall = setup + solve
        if isinstance(wall, (int, float)):
            parts = [f"{label} {seconds(v)}" for label, v in (("setup", setup), ("solve", solve))
                     if isinstance(v, (int, float))]
            lines.append(f"  wall time: {seconds(wall)}" + (f" ({', '.join(parts)})" if parts else ""))
        names = self.channel_names
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        lines.append(f"  channels ({len(names)}): {shown or '-'}")
        if self.warnings:
            kinds = ", ".join(dict.fromkeys(str(w.get("kind", "?")) for w in self.warnings))
            lines.append(f"  warnings: {len(self.warnings)} ({kinds}); see result.warnings")
        return "\n".join(lines)

    # ------------------------------------------------------------------ windows

    def window_mask(self, t0: float | None = None, t1: float | None = None) -> NDArray[np.bool_]:
        """Boolean mask of the output times in the closed window [t0, t1].

        Parameters
        ----------
        t0, t1 : float, optional
            Window bounds (s); None leaves that side open.

        Returns
        -------
        ndarray of bool, shape (n_times,)

        Raises
        ------
        ValueError
            If ``t0 > t1``.
        """
        lo, hi = _window(t0, t1)
        return (self.t >= lo) & (self.t <= hi)

    def slice(self, t0: float | None = None, t1: float | None = None) -> Result:
        """A new Result restricted to the closed time window [t0, t1].

        Output times, `y`, `yp`, channels, events and internal steps inside the
        window are kept; segments overlapping it are clipped to it. `stats`,
        `parameters`, `success`, `status` and `message` describe the whole run
        and are copied unchanged.

        Parameters
        ----------
        t0, t1 : float, optional
            Window bounds (s); None leaves that side open.

        Returns
        -------
        Result

        Examples
        --------
        Two crank revolutions after the transient, at 5000 rpm:

        >>> period = 2 * np.pi / 523.6
        >>> steady = result.slice(result.t[-1] - 2 * period, None)   # doctest: +SKIP
        """
        lo, hi = _window(t0, t1)
        mask = self.window_mask(t0, t1)
        kw = self.to_dict()
        kw.update(
            t=self.t[mask],
            y=self.y[mask],
            yp=self.yp[mask],
            channels={name: arr[mask] for name, arr in self._channels.items()},
            events=[e for e in self._events if lo <= e.t <= hi],
            segments=[(max(a, lo), min(b, hi), m) for a, b, m in self.segments if a < hi and b > lo],
        )
        if self._steps is not None:
            inside = (self._steps[0] >= lo) & (self._steps[0] <= hi)
            kw.update(step_t=self._steps[0][inside], step_h=self._steps[1][inside],
                      step_order=self._steps[2][inside])
        return Result(**kw)

    def to_dict(self) -> dict[str, Any]:
        """The constructor keywords: ``Result(**result.to_dict())`` rebuilds the result.

        Returns
        -------
        dict
            Arrays are the result's own read-only arrays; `events` is a list of
            `ContactEvent`; `stats` and `parameters` are copies.
        """
        return {
            "t": self.t,
            "y": self.y,
            "yp": self.yp,
            "state_names": list(self.state_names),
            "channels": dict(self._channels),
            "units": dict(self.units),
            "events": list(self._events),
            "segments": [(a, b, dict(m)) for a, b, m in self.segments],
            "step_t": self.step_t,
            "step_h": self.step_h,
            "step_order": self.step_order,
            "stats": json.loads(json.dumps(self.stats)),
            "success": self.success,
            "status": self.status,
            "message": self.message,
            "parameters": json.loads(json.dumps(self.parameters)),
            "scene_name": self.scene_name,
            "method": self.method,
            "formulation": self.formulation,
            "warnings": json.loads(json.dumps(self.warnings)),
        }

    # ------------------------------------------------------------------ hand-off to pandas and xarray

    def _columns(self, states: bool) -> tuple[dict[str, np.ndarray], dict[str, str]]:
        """One-dimensional columns (multi-dimensional channels split as ``name[i]``) and their units."""
        cols: dict[str, np.ndarray] = {}
        units: dict[str, str] = {}
        for name in self.channel_names:
            arr = self._channels[name]
            if arr.ndim == 1:
                cols[name], units[name] = arr, self.units[name]
                continue
            flat = arr.reshape(arr.shape[0], -1)
            for k, index in enumerate(np.ndindex(*arr.shape[1:])):
                col = f"{name}[{','.join(str(i) for i in index)}]"
                cols[col], units[col] = flat[:, k], self.units[name]
        if states:
            for j, name in enumerate(self.state_names):
                if name not in cols:  # a channel of the same name wins, as in result[name]
                    cols[name], units[name] = self.y[:, j], self.units[name]
        return cols, units

    def _metadata(self) -> dict[str, Any]:
        return {"scene_name": self.scene_name, "method": self.method, "formulation": self.formulation,
                "success": self.success, "status": self.status, "message": self.message}

    def to_pandas(self, *, states: bool = False) -> pd.DataFrame:
        """The channels as a pandas DataFrame, one column per channel, indexed by time.

        The hand-off to pandas-based tools: the index is named ``"t"`` (s) and may hold an
        event time twice (before and after a restart). A channel with more than one value per
        time (shape (n_times, k)) becomes the columns ``"name[0]"`` ... ``"name[k-1]"``.
        Dtypes are kept; values are copies.

        Parameters
        ----------
        states : bool
            Also add one column per state (``y``) whose name is not already a channel.

        Returns
        -------
        pandas.DataFrame
            ``df.attrs["units"]`` maps every column and ``"t"`` to its unit (``""`` when
            unknown); ``df.attrs`` also holds scene_name, method, formulation, success,
            status and message. Events are in `events_frame`.

        Raises
        ------
        MissingDependencyError
            (an ImportError) if pandas is not installed: ``pip install "daeclear[data]"``.
        """
        pd = _optional("pandas", "Result.to_pandas")
        cols, units = self._columns(states)
        index = pd.Index(np.array(self.t), name="t")
        df = pd.DataFrame({name: np.array(arr) for name, arr in cols.items()}, index=index)
        df.attrs["units"] = {"t": "s", **units}
        df.attrs.update(self._metadata())
        return df

    def events_frame(self, *, states: bool = False) -> pd.DataFrame:
        """The contact events as a pandas DataFrame, one row per event, in time order.

        Columns ``t`` (s), ``pair``, ``kind`` (``"onset"`` or ``"separation"``) and
        ``approach_speed`` (m/s, nan where meaningless); with ``states=True`` also the state
        at each event, one column per state name. ``df.attrs["units"]`` gives the units.

        Raises
        ------
        MissingDependencyError
            (an ImportError) if pandas is not installed: ``pip install "daeclear[data]"``.
        """
        pd = _optional("pandas", "Result.events_frame")
        data: dict[str, Any] = {
            "t": self._events.t,
            "pair": pd.Series(self._events.pair, dtype=object),
            "kind": pd.Series(self._events.kind, dtype=object),
            "approach_speed": self._events.approach_speed,
        }
        units = {"t": "s", "pair": "", "kind": "", "approach_speed": "m/s"}
        if states:
            y = np.array([e.y for e in self._events], dtype=np.float64).reshape(len(self._events), self.n_states)
            for j, name in enumerate(self.state_names):
                data[f"y:{name}"] = y[:, j]
                units[f"y:{name}"] = self.units[name]
        df = pd.DataFrame(data)
        df.index.name = "event"
        df.attrs["units"] = units
        return df

    def to_xarray(self, *, states: bool = True) -> xr.Dataset:
        """The result as an xarray Dataset: channels over ``t``, events over ``event``.

        Every channel is a variable over the dimension ``t`` (extra dimensions of a
        multi-dimensional channel are named ``"<channel>_dim_1"``, ...) with its unit in
        ``attrs["units"]``; the coordinate ``t`` has ``units="s"`` and may hold an event time
        twice (select by position, ``ds.isel``). The events are the variables
        ``event_t``, ``event_pair``, ``event_kind``, ``event_approach_speed`` (and
        ``event_y`` with states) over the dimension ``event``; the segments are
        ``segment_t_start``, ``segment_t_end``, ``segment_modes`` (JSON) over ``segment``.
        Attributes are netCDF-safe: scene_name, method, formulation, success (0/1),
        status, message, every scalar statistic as ``stats.<name>``, and the full
        statistics and parameters as JSON strings ``stats_json``, ``parameters_json``.

        Parameters
        ----------
        states : bool
            Include ``y`` and ``yp`` over (``t``, ``state``), with the coordinates
            ``state`` (names) and ``state_units``.

        Returns
        -------
        xarray.Dataset

        Raises
        ------
        MissingDependencyError
            (an ImportError) if xarray is not installed: ``pip install "daeclear[data]"``.
        """
        xr = _optional("xarray", "Result.to_xarray")
        variables: dict[str, Any] = {}
        for name in self.channel_names:
            arr = np.array(self._channels[name])
            dims = ("t", *(f"{name}_dim_{k}" for k in range(1, arr.ndim)))
            variables[name] = xr.Variable(dims, arr, attrs={"units": self.units[name]})
        coords: dict[str, Any] = {"t": xr.Variable("t", np.array(self.t), attrs={"units": "s"})}
        if states:
            coords["state"] = xr.Variable("state", np.array(self.state_names, dtype=object))
            coords["state_units"] = xr.Variable("state", np.array([self.units[n] for n in self.state_names],
                                                                  dtype=object))
            variables["y"] = xr.Variable(("t", "state"), np.array(self.y))
            variables["yp"] = xr.Variable(("t", "state"), np.array(self.yp))
        ev = self._events
        variables["event_t"] = xr.Variable("event", ev.t, attrs={"units": "s"})
        variables["event_pair"] = xr.Variable("event", np.array(ev.pair, dtype=object))
        variables["event_kind"] = xr.Variable("event", np.array(ev.kind, dtype=object))
        variables["event_approach_speed"] = xr.Variable("event", ev.approach_speed, attrs={"units": "m/s"})
        if states:
            y_events = np.array([e.y for e in ev], dtype=np.float64).reshape(len(ev), self.n_states)
            variables["event_y"] = xr.Variable(("event", "state"), y_events)
        variables["segment_t_start"] = xr.Variable(
            "segment", np.array([s[0] for s in self.segments], dtype=np.float64), attrs={"units": "s"})
        variables["segment_t_end"] = xr.Variable(
            "segment", np.array([s[1] for s in self.segments], dtype=np.float64), attrs={"units": "s"})
        variables["segment_modes"] = xr.Variable(
            "segment", np.array([json.dumps(s[2], ensure_ascii=False) for s in self.segments], dtype=object))
        attrs: dict[str, Any] = {**self._metadata(), "success": int(self.success)}
        for key, value in self.stats.items():
            if isinstance(value, bool):
                attrs[f"stats.{key}"] = int(value)
            elif isinstance(value, (int, float, str)):
                attrs[f"stats.{key}"] = value
        attrs["stats_json"] = json.dumps(self.stats, ensure_ascii=False)
        attrs["parameters_json"] = json.dumps(self.parameters, ensure_ascii=False)
        return xr.Dataset(variables, coords=coords, attrs=attrs)

    # ------------------------------------------------------------------ animation

    def animate(self, path: str | os.PathLike[str], *, fps: float = 25.0,
                window: tuple[float | None, float | None] | None = None, slow_motion: float | None = None,
                size: tuple[int, int] = (720, 450), channel: str | None = None, magnify: float | None = None,
                progress: bool = False) -> Path:
        """Write an animated GIF (or MP4 with ffmpeg) of the mechanism moving; see :func:`daeclear.plot.animate.animate`.

        Frames: ``max(2, round(duration * slow_motion * fps))`` evenly spaced over the window.

        Examples
        --------
        >>> result.animate("run.gif", window=(0.010, 0.014), slow_motion=500, size=(560, 360))  # doctest: +SKIP
        """
        from ..plot.animate import animate

        return animate(self, path, fps=fps, window=window, slow_motion=slow_motion, size=size, channel=channel,
                       magnify=magnify, progress=progress)

    # ------------------------------------------------------------------ HDF5

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the result to an HDF5 file, atomically.

        The file is written under a temporary name in the same directory and
        renamed over `path` (`os.replace`) only once complete: an existing file
        at `path` is either left untouched or replaced whole, and no temporary
        file survives a failure or an interrupt. The layout is in this
        module's docstring.

        Parameters
        ----------
        path : str or path-like
            Destination file, e.g. ``"run.h5"``. Its directory must exist.

        Returns
        -------
        pathlib.Path
            `path` as a Path.

        Raises
        ------
        FileNotFoundError
            If the directory of `path` does not exist (an ``OutputDirectoryMissing``).
        OSError
            If `path` is a directory or its directory cannot be written (an ``OutputError``,
            checked before writing), or the write fails.
        """
        import h5py

        from .outputs import check_file, deferred_sigint

        path = check_file(path, "Result.save(path)")  # the one output-place rule (daeclear.results.outputs)
        tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:12]}.tmp")
        with deferred_sigint():  # a Ctrl-C during the write arrives once the file is complete
            try:
                with h5py.File(tmp, "x") as f:
                    _write(f, self)
                with open(tmp, "rb+") as fh:  # data on disk before the rename makes it visible
                    os.fsync(fh.fileno())
                os.replace(tmp, path)
            except BaseException:
                tmp.unlink(missing_ok=True)
                raise
        return path


def _optional(module: str, what: str) -> Any:
    """Import an optional dependency, or raise MissingDependencyError naming the extra that installs it."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingDependencyError(
            f"{what} needs {module}, which is not installed. Install daeclear's data extra: "
            f'pip install "daeclear[data]" (or pip install {module}).'
        ) from exc


def _window(t0: float | None, t1: float | None) -> tuple[float, float]:
    lo = -math.inf if t0 is None else float(t0)
    hi = math.inf if t1 is None else float(t1)
    if lo > hi:
        raise ValueError(f"time window t0={t0} > t1={t1}; t0 must not exceed t1.")
    return lo, hi


# --------------------------------------------------------------------------- writing


def _compress(data: np.ndarray) -> bool:
    """Whether gzip is cheap and worth it: large integer or bool arrays, large mostly-zero arrays.

    General float64 data (states, velocities) shrinks by only ~20% at ~8x the write time,
    so it is stored uncompressed; contact forces and penetrations, zero in free flight, shrink a lot.
    """
    if data.size < _COMPRESS_MIN_SIZE:
        return False
    return data.dtype.kind in "biu" or np.count_nonzero(data) <= data.size // 2


def _dataset(group: h5py.Group, name: str, data: np.ndarray) -> h5py.Dataset:
    if _compress(data):
        return group.create_dataset(name, data=data, chunks=True, compression="gzip",
                                    compression_opts=1, shuffle=True)
    return group.create_dataset(name, data=data)


def _strings(group: h5py.Group, name: str, values: Sequence[str]) -> h5py.Dataset:
    import h5py

    return group.create_dataset(name, data=np.array(list(values), dtype=object), dtype=h5py.string_dtype())


def _json_dataset(group: h5py.Group, name: str, value: Any) -> None:
    import h5py

    group.create_dataset(name, data=json.dumps(value, ensure_ascii=False), dtype=h5py.string_dtype())


def _mirror(group: h5py.Group, tree: Mapping[str, Any]) -> None:
    """Write a nested dict as groups and attributes that any HDF5 tool can read."""
    import h5py

    for key, value in tree.items():
        if not key or "/" in key or key == ".":
            continue  # not an HDF5 name; the JSON copy keeps it
        if isinstance(value, dict):
            _mirror(group.create_group(key), value)
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


def _write(f: h5py.File | h5py.Group, r: Result) -> None:
    """Write ``r`` in the layout of a result file into an open HDF5 file or group."""
    f.attrs["format"] = FORMAT_NAME
    f.attrs["version"] = FORMAT_VERSION
    f.attrs["scene_name"] = r.scene_name
    f.attrs["method"] = r.method
    f.attrs["formulation"] = r.formulation
    f.attrs["success"] = r.success
    f.attrs["status"] = r.status
    f.attrs["message"] = r.message

    _dataset(f, "t", np.asarray(r.t)).attrs["units"] = "s"
    _dataset(f, "y", np.asarray(r.y))
    _dataset(f, "yp", np.asarray(r.yp))
    _strings(f, "state_names", r.state_names)
    _strings(f, "state_units", [r.units[n] for n in r.state_names])

    channels = f.create_group("channels")
    for name in r.channel_names:
        _dataset(channels, name, np.asarray(r.channels[name])).attrs["units"] = r.units[name]

    events = f.create_group("events")
    _dataset(events, "t", r.events.t)
    _strings(events, "pair", r.events.pair)
    _strings(events, "kind", r.events.kind)
    _dataset(events, "approach_speed", r.events.approach_speed)
    y_events = np.array([e.y for e in r.events], dtype=np.float64).reshape(len(r.events), r.n_states)
    _dataset(events, "y", y_events)

    segments = f.create_group("segments")
    _dataset(segments, "t_start", np.array([s[0] for s in r.segments], dtype=np.float64))
    _dataset(segments, "t_end", np.array([s[1] for s in r.segments], dtype=np.float64))
    _strings(segments, "modes", [json.dumps(s[2], ensure_ascii=False) for s in r.segments])

    if r.step_t is not None:
        steps = f.create_group("steps")
        _dataset(steps, "t", np.asarray(r.step_t))
        _dataset(steps, "h", np.asarray(r.step_h))
        _dataset(steps, "order", np.asarray(r.step_order))

    _mirror(f.create_group("stats"), r.stats)
    _json_dataset(f, "stats_json", r.stats)
    _mirror(f.create_group("parameters"), r.parameters)
    _json_dataset(f, "parameters_json", r.parameters)
    _json_dataset(f, "warnings_json", r.warnings)


# --------------------------------------------------------------------------- streaming


_STREAM_ROWS = 1024  # rows per HDF5 chunk of a streamed 2-D array (1-D arrays: 4 times as many)
#: Root message of a streamed file while its run goes on; a file left so was stopped without a word
#: (killed): it holds the data of its last complete append.
STREAM_RUNNING = "incomplete: the run was stopped before it finished (the data are those written until then)"


class ResultWriter:
    """Writes a result to an HDF5 file while its run goes on, in the layout of `Result.save`.

    The file is created with every item of the layout (empty, extendable datasets; root
    attributes ``success=False``, ``status=-1`` and the message :data:`STREAM_RUNNING`) and each
    `append` adds rows to it, flushed to disk, with Ctrl-C held back until the rows are complete:
    between two appends `load` reads it as the run so far. `close` writes the statistics,
    warnings and the outcome. Streamed arrays are chunked (gzip only for integer and bool
    channels); `load` reads them as it reads a saved file.

    Parameters
    ----------
    path : path-like
        The file, created or replaced (check it with :func:`daeclear.results.outputs.check_file` first).
    state_names, units, parameters, scene_name, method, formulation
        As in `Result`.
    """

    def __init__(self, path: str | os.PathLike[str], *, state_names: Sequence[str], units: Mapping[str, str],
                 parameters: Mapping[str, Any], scene_name: str, method: str, formulation: str) -> None:
        import h5py

        self.path = Path(path)
        self._units = dict(units)
        self._n = len(state_names)
        self._touched: list[tuple[h5py.Dataset, int]] = []  # (dataset, rows before) of the append under way
        self._f = f = h5py.File(self.path, "w")
        try:
            f.attrs["format"] = FORMAT_NAME
            f.attrs["version"] = FORMAT_VERSION
            f.attrs["scene_name"] = str(scene_name)
            f.attrs["method"] = str(method)
            f.attrs["formulation"] = str(formulation)
            self._outcome(False, -1, STREAM_RUNNING)
            self._grow(f, "t", np.float64).attrs["units"] = "s"
            self._grow(f, "y", np.float64, (self._n,))
            self._grow(f, "yp", np.float64, (self._n,))
            _strings(f, "state_names", list(state_names))
            _strings(f, "state_units", [self._units.get(str(n), "") for n in state_names])
            f.create_group("channels")
            events = f.create_group("events")
            self._grow(events, "t", np.float64)
            self._grow(events, "pair", h5py.string_dtype())
            self._grow(events, "kind", h5py.string_dtype())
            self._grow(events, "approach_speed", np.float64)
            self._grow(events, "y", np.float64, (self._n,))
            segments = f.create_group("segments")
            self._grow(segments, "t_start", np.float64)
            self._grow(segments, "t_end", np.float64)
            self._grow(segments, "modes", h5py.string_dtype())
            steps = f.create_group("steps")
            self._grow(steps, "t", np.float64)
            self._grow(steps, "h", np.float64)
            self._grow(steps, "order", np.int64)
            f.create_group("stats")
            _json_dataset(f, "stats_json", {})
            plain = _plain(dict(parameters), "parameters")
            _mirror(f.create_group("parameters"), plain)
            _json_dataset(f, "parameters_json", plain)
            _json_dataset(f, "warnings_json", [])
            f.flush()
        except BaseException:
            f.close()
            raise

    @staticmethod
    def _grow(group: h5py.Group, name: str, dtype: Any, rest: tuple[int, ...] = (),
              compress: bool = False) -> h5py.Dataset:
        rows = _STREAM_ROWS if rest else 4 * _STREAM_ROWS
        extra = {"compression": "gzip", "compression_opts": 1, "shuffle": True} if compress else {}
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
               channels: Mapping[str, ArrayLike] | None = None, events: Sequence[ContactEvent] = (),
               segments: Sequence[tuple[float, float, Mapping[str, str]]] = (), step_t: ArrayLike = (),
               step_h: ArrayLike = (), step_order: ArrayLike = ()) -> None:
        """Add output rows (``t``, ``y``, ``yp``, ``channels``: one row per time), events, segments
        and steps; written whole (a Ctrl-C meanwhile is raised afterwards) and flushed."""
        from .outputs import deferred_sigint

        f = self._f
        t_arr = np.asarray(t, dtype=np.float64)
        self._touched = []
        with deferred_sigint():
            try:
                self._append(f, t_arr, y, yp, channels, events, segments, step_t, step_h, step_order)
            except BaseException:  # e.g. MemoryError: every dataset back to its length before, then go on
                for dataset, n in reversed(self._touched):
                    dataset.resize(n, axis=0)
                raise
            f.flush()

    def _append(self, f: h5py.File, t_arr: NDArray[np.float64], y: Any, yp: Any, channels: Any, events: Any,
                segments: Any, step_t: Any, step_h: Any, step_order: Any) -> None:
        if t_arr.size:
            self._extend(f["t"], t_arr)
            self._extend(f["y"], np.asarray(y, dtype=np.float64))
            self._extend(f["yp"], np.asarray(yp, dtype=np.float64))
            group = f["channels"]
            for name, values in (channels or {}).items():
                arr = np.asarray(values)
                if name not in group:
                    self._grow(group, name, arr.dtype, arr.shape[1:],
                               compress=arr.dtype.kind in "biu").attrs["units"] = self._units.get(name, "")
                self._extend(group[name], arr)
        if len(events):
            g = f["events"]
            self._extend(g["t"], np.array([e.t for e in events], dtype=np.float64))
            self._extend(g["pair"], np.array([e.pair for e in events], dtype=object))
            self._extend(g["kind"], np.array([e.kind for e in events], dtype=object))
            self._extend(g["approach_speed"], np.array([e.approach_speed for e in events], dtype=np.float64))
            self._extend(g["y"], np.array([e.y for e in events], dtype=np.float64).reshape(len(events), self._n))
        if len(segments):
            g = f["segments"]
            self._extend(g["t_start"], np.array([float(s[0]) for s in segments], dtype=np.float64))
            self._extend(g["t_end"], np.array([float(s[1]) for s in segments], dtype=np.float64))
            self._extend(g["modes"], np.array(
                [json.dumps({str(k): str(v) for k, v in s[2].items()}, ensure_ascii=False) for s in segments],
                dtype=object))
        st = np.asarray(step_t, dtype=np.float64)
        if st.size:
            g = f["steps"]
            self._extend(g["t"], st)
            self._extend(g["h"], np.asarray(step_h, dtype=np.float64))
            self._extend(g["order"], np.asarray(step_order, dtype=np.int64))

    def close(self, *, stats: Mapping[str, Any], success: bool, status: int, message: str,
              warnings: Iterable[Mapping[str, Any]] = ()) -> Path:
        """Write the statistics, the warnings and the outcome, and close the file."""
        from .outputs import deferred_sigint

        f = self._f
        with deferred_sigint():
            try:
                plain = _plain(dict(stats), "stats")
                del f["stats"], f["stats_json"], f["warnings_json"]
                _mirror(f.create_group("stats"), plain)
                _json_dataset(f, "stats_json", plain)
                _json_dataset(f, "warnings_json", _plain([dict(w) for w in warnings], "warnings"))
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
            self._f.close()


# --------------------------------------------------------------------------- reading


def load(path: str | os.PathLike[str], t0: float | None = None, t1: float | None = None) -> Result:
    """Read a result written by `Result.save` (or streamed by a run, ``simulate(stream_to=...)``).

    Parameters
    ----------
    path : str or path-like
        An HDF5 file with root attribute ``format="daeclear-result"``.
    t0, t1 : float, optional
        Read only the closed time window [t0, t1] (None: that side open): equal to
        ``load(path).slice(t0, t1)``, but only the window's rows are read (and the times of the
        points, events, segments and steps, 8 bytes each), so a window of a long run fits in
        memory whatever the length of the run.

    Returns
    -------
    Result
        Equal, field by field, to the result that was saved (or its window).

    Raises
    ------
    FileNotFoundError
        If `path` does not exist.
    DaeclearError
        If the file is not HDF5, not a daeclear result, written by a newer
        daeclear, or lacks an item of the layout; the message names the file
        and what is missing.
    """
    import h5py

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no result file '{path}'.")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise DaeclearError(f"'{path}' is not a daeclear result: it cannot be opened as HDF5 ({exc}).") from exc
    with f:
        fmt = f.attrs.get("format")
        if fmt is None:
            raise DaeclearError(
                f"'{path}' is not a daeclear result: the root attribute 'format' is missing "
                f"(expected {FORMAT_NAME!r}, as written by Result.save)."
            )
        if _text(fmt) != FORMAT_NAME:
            raise DaeclearError(
                f"'{path}' is not a daeclear result: root attribute format={_text(fmt)!r}, expected {FORMAT_NAME!r}."
            )
        version = f.attrs.get("version")
        if version is None:
            raise DaeclearError(f"'{path}' is a damaged daeclear result: the root attribute 'version' is missing.")
        if int(version) > FORMAT_VERSION:
            raise DaeclearError(
                f"'{path}' is a daeclear result of format version {int(version)}; this daeclear reads "
                f"versions up to {FORMAT_VERSION}. Upgrade daeclear to read it."
            )
        return _read(_Reader(f, path, _window(t0, t1)))


def load_times(path: str | os.PathLike[str], of: str = "points") -> NDArray[np.float64]:
    """The times of a result file's output points, events or steps alone (8 bytes each), e.g. to
    choose the window of :func:`load` ``(path, t0, t1)`` in a file too long to read whole.

    ``of``: ``"points"`` (``/t``), ``"events"`` (``/events/t``) or ``"steps"`` (``/steps/t``;
    empty without steps)."""
    import h5py

    names = {"points": "t", "events": "events/t", "steps": "steps/t"}
    if of not in names:
        raise ValueError(f"load_times: of={of!r}, must be one of {', '.join(names)}.")
    load(path, math.inf, math.inf)  # the file's checks (format, version, items), reading no rows
    with h5py.File(path, "r") as f:
        return f[names[of]][()] if names[of] in f else np.zeros(0)


def _text(value: Any) -> str:
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


class _Reader:
    """Reads items of one file; a missing item raises DaeclearError naming file and item."""

    def __init__(self, f: h5py.File, path: Path, window: tuple[float, float] = (-math.inf, math.inf)) -> None:
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

    def array(self, name: str, rows: slice | None = None) -> np.ndarray:
        if name not in self.f:
            raise self._missing(f"dataset '/{name}'")
        return self.f[name][()] if rows is None else self.f[name][rows]

    def strings(self, name: str, rows: slice | None = None) -> list[str]:
        if name not in self.f:
            raise self._missing(f"dataset '/{name}'")
        return [str(s) for s in (self.f[name].asstr()[()] if rows is None else self.f[name].asstr()[rows])]

    def json(self, name: str) -> Any:
        if name not in self.f:
            raise self._missing(f"dataset '/{name}'")
        return json.loads(self.f[name].asstr()[()])

    def attr(self, name: str, obj: str = "/") -> Any:
        attrs = self.f[obj].attrs
        if name not in attrs:
            raise self._missing(f"attribute '{name}' of '{obj}'")
        value = attrs[name]
        return value.item() if isinstance(value, np.generic) else _text(value) if isinstance(value, bytes) else value


def _read(r: _Reader) -> Result:
    state_names = r.strings("state_names")
    state_units = r.strings("state_units")
    units = dict(zip(state_names, state_units))
    if "channels" not in r.f:
        raise r._missing("group '/channels'")
    points = r.rows("t")
    channels: dict[str, np.ndarray] = {}
    for name in r.f["channels"]:
        channels[name] = r.array(f"channels/{name}", points)
        units[name] = r.attr("units", f"/channels/{name}")

    rows = r.rows("events/t")
    columns = (r.array("events/t", rows), r.strings("events/pair", rows), r.strings("events/kind", rows),
               r.array("events/approach_speed", rows), r.array("events/y", rows))
    if len({len(c) for c in columns}) != 1:
        raise DaeclearError(
            f"'{r.path}' is a damaged daeclear result: the datasets of '/events' have different lengths "
            f"{[len(c) for c in columns]}."
        )
    events = [
        ContactEvent(t=t, pair=pair, kind=kind, approach_speed=speed, y=y)  # type: ignore[arg-type]
        for t, pair, kind, speed, y in zip(*columns)
    ]
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

    return Result(
        t=r.array("t", points),
        y=r.array("y", points),
        yp=r.array("yp", points),
        state_names=state_names,
        channels=channels,
        units=units,
        events=events,
        segments=segments,
        stats=r.json("stats_json"),
        success=bool(r.attr("success")),
        status=int(r.attr("status")),
        message=str(r.attr("message")),
        parameters=r.json("parameters_json"),
        scene_name=str(r.attr("scene_name")),
        method=str(r.attr("method")),
        formulation=str(r.attr("formulation")),
        warnings=r.json("warnings_json") if r.has("warnings_json") else [],  # older files: no warnings
        **steps,
    )


def write_result_group(group: h5py.Group, r: Result) -> None:
    """Write ``r`` in the layout of a result file (:meth:`Result.save`) into ``group``, an open group
    of another HDF5 file: a sweep keeps its full reference runs inside its own file this way
    (:func:`read_result_group` reads them back)."""
    _write(group, r)


class _GroupAsFile:
    """Lets the reader read a Result stored inside a group (absolute names become relative)."""

    def __init__(self, group: h5py.Group) -> None:
        self._group = group

    def _name(self, name: str) -> str:
        return name.lstrip("/") or "."

    def __getitem__(self, name: str) -> Any:
        return self._group[self._name(name)]

    def __contains__(self, name: str) -> bool:
        return self._name(name) in self._group

    @property
    def attrs(self) -> Any:
        return self._group.attrs


def read_result_group(group: h5py.Group, path: Path) -> Result:
    """The Result that :func:`write_result_group` wrote into ``group``, an open group of the file at
    ``path`` (named in the messages about a damaged result)."""
    return _read(_Reader(_GroupAsFile(group), path))  # type: ignore[arg-type]
