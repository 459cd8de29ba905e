"""What a simulation returns: the `Result` container (time series, named channels, events, statistics).

A pure data container filled by the solvers; its HDF5 round trip and hand-off to pandas and xarray
live in the other modules of daeclear.results (one job each), whose public names are re-exported
here. The file layout: docs/hdf5_layout.md.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import DaeclearError
from ..core.options import close_matches
from . import export
from ..core.events import EVENT_KINDS, ContactEvent, EventKind, EventList, EventRows
from .hdf5_read import read_dataset, read_file, read_group
from .hdf5_stream import STREAM_RUNNING, ResultWriter
from .hdf5_write import FORMAT_NAME, FORMAT_VERSION, save_result, write_result_group
from .lazy_channels import LazyChannels
from .result_checks import checked_fields
from .objectives import Gradient, Objective, evaluate
from .sensitivities import RunTrajectory, Sensitivities
from .sensitivity_growth import SensitivityHorizon, sensitivity_horizon
from ..core.values import readonly, time_window, to_plain

if TYPE_CHECKING:  # h5py, pandas and xarray are imported lazily, only where they are used
    import h5py
    import pandas as pd
    import xarray as xr

__all__ = ["EVENT_KINDS", "FORMAT_NAME", "FORMAT_VERSION", "STREAM_RUNNING", "ChannelKeyError", "ContactEvent",
           "EventKind", "EventList", "Result", "ResultWriter", "load", "load_times", "read_result_group",
           "write_result_group"]


class ChannelKeyError(DaeclearError, KeyError):
    """A channel or state name that the result does not hold.

    A `KeyError` (so ``except KeyError`` works) whose message is printed
    without the quotes `KeyError` normally adds.
    """

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# --------------------------------------------------------------------------- Result


class Result:
    """The outcome of a simulation: time series, named channels, events, statistics.

    Built by the solver; every argument is keyword-only. Arrays are kept as
    read-only views (copy before editing).

    Parameters
    ----------
    t : array_like, shape (n_times,)
        Output times (s), non-decreasing (an event time may appear twice: before and after a restart).
    y, yp : array_like, shape (n_times, n_states)
        States and their time derivatives. ``yp`` may be None with lazy channels that compute it
        (the run's consistency pass).
    state_names : list of str
        Name of each state, e.g. ``"crank.x"``, ``"crank.vx"``, ``"lambda.A.x"``.
    channels : mapping of str to array_like, or LazyChannels
        Named outputs ``"<object>.<quantity>"`` (no "/"), each with first dimension n_times; a run's
        :class:`~daeclear.results.lazy_channels.LazyChannels` computes them at their first read.
    units : mapping of str to str
        Unit of channels and states (``""`` when not given); a name that is neither is an error.
    events : sequence of ContactEvent, optional
        Contact transitions, in time order.
    segments : sequence of (t_start, t_end, modes), optional
        Integration segments between restarts; ``modes``: contact pair -> ``"free"`` or ``"contact"``.
    step_t, step_h, step_order : array_like, shape (n_steps,), optional
        IDA's internal steps (time reached, size, BDF order), given together or not at all.
    stats : mapping, optional
        Solver statistics (``n_steps``, ``n_res_evals``, ``n_events``, ``solve_time``, ...).
    success : bool, default True
        False when the run failed (``status == -1``).
    status : {0, 1, -1}, default 0
        0: end time reached; 1: a terminal event stopped the run; -1: failed.
    message : str, default ""
        The solver's last word, e.g. why it failed.
    parameters : mapping, optional
        Nested parameters of the scene and the run (``{"scene": {...}, "simulate": {...}}``), made plain
        data (numpy values, tuples, paths and dataclasses converted).
    scene_name, method, formulation : str, default ""
        The scene's name, the integrator (``"ida"``, ``"DOP853"``, ...) and the formulation.
    warnings : sequence of dict, optional
        What the run's physics checks found (see :mod:`daeclear.assembly.physics`): each a dict with
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
        When a value in `parameters` or `stats` is none of the storable types (stored as its ``repr``).

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
        yp: ArrayLike | None,
        state_names: Sequence[str],
        channels: Mapping[str, ArrayLike] | LazyChannels,
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
        sensitivities: Sensitivities | None = None,
    ) -> None:
        t_arr, y_arr, yp_arr, names, chans, event_list, segs, steps = checked_fields(
            t, y, yp, state_names, channels, units, events, segments, step_t, step_h, step_order, success, status)
        self._assign(t_arr, y_arr, yp_arr, names, chans, units, event_list, segs, steps, dict(
            stats=stats, success=success, status=status, message=message, scene_name=scene_name, method=method,
            formulation=formulation, warnings=warnings, parameters=to_plain(dict(parameters or {}), "parameters")))
        if sensitivities is not None and sensitivities.states.shape[:2] != (t_arr.size, len(names)):
            raise ValueError(f"Result: sensitivities of shape {sensitivities.states.shape} do not match "
                             f"{t_arr.size} times and {len(names)} states")
        self.sensitivities = sensitivities

    @classmethod
    def of_run(cls, *, t: NDArray, y: NDArray, yp: NDArray | None, state_names: Sequence[str],
               channels: Mapping[str, NDArray] | LazyChannels,
               units: Mapping[str, str], events: Iterable[ContactEvent | EventRows],
               segments: list[tuple[float, float, dict[str, str]]], step_t: NDArray, step_h: NDArray,
               step_order: NDArray, **outcome: Any) -> Result:
        """A solver's Result, from the data its recorder joined: float64 arrays of matching shapes,
        channels and units of the model, events (and blocks of them) in time order, segments as (float, float, modes);
        ``outcome``: every other keyword of the constructor (stats ... warnings). The constructor's
        checks are skipped, and ``parameters`` (the solver's plain data) are copied at their first read."""
        result = cls.__new__(cls)
        result._assign(t, y, yp, list(state_names), channels, units, EventList.of_parts(list(events)), segments,
                       (step_t, step_h, step_order), {**outcome, "parameters": (outcome["parameters"],)})
        result.sensitivities = None
        return result

    def _assign(self, t: NDArray, y: NDArray, yp: NDArray | None, names: list[str],
                channels: Mapping[str, NDArray] | LazyChannels,
                units: Mapping[str, str], events: EventList, segments: list[tuple[float, float, dict[str, str]]],
                steps: tuple[NDArray, NDArray, NDArray] | None, outcome: Mapping[str, Any]) -> None:
        """Set the fields from checked data: arrays as read-only views, values as plain data."""
        self.t: NDArray[np.float64] = readonly(t)
        # the channels: arrays, or computed from the states at their first read (_channel_values)
        self._lazy = channels if isinstance(channels, LazyChannels) else None
        self._y = None if self._lazy is not None and self._lazy.raw else readonly(y)  # None: made consistent when read
        self._yp = None if yp is None else readonly(yp)
        self.state_names: list[str] = names
        self._channels: dict[str, np.ndarray] | None = None if isinstance(channels, LazyChannels) else {
            name: readonly(values) for name, values in channels.items()}
        self._names = frozenset(channels.names if isinstance(channels, LazyChannels) else channels)
        self.units: dict[str, str] = {name: units.get(name, "") for name in [*names, *sorted(self._names)]}
        self._events = events
        self.segments: list[tuple[float, float, dict[str, str]]] = segments
        self._steps = None if steps is None else (readonly(steps[0]), readonly(steps[1]), readonly(steps[2]))
        self.stats: dict[str, Any] = to_plain(dict(outcome["stats"] or {}), "stats")
        self.success: bool = bool(outcome["success"])
        self.status: int = int(outcome["status"])
        self.message: str = str(outcome["message"])
        self._parameters: dict[str, Any] | tuple[Mapping[str, Any] | None] = outcome["parameters"]  # or (a run's,)
        self.scene_name: str = str(outcome["scene_name"])
        self.method: str = str(outcome["method"])
        self.formulation: str = str(outcome["formulation"])
        self.warnings: list[dict[str, Any]] = to_plain([dict(w) for w in outcome["warnings"]], "warnings")

    # ------------------------------------------------------------------ access

    @property
    def parameters(self) -> dict[str, Any]:
        """Nested parameters of the scene and the run (plain data: the result's own copy)."""
        if isinstance(held := self._parameters, tuple):  # a solver's Result: copied at the first read
            held = self._parameters = to_plain(dict(held[0] or {}), "parameters")
        return held

    @property
    def y(self) -> NDArray[np.float64]:
        """States (n_times, n_states); a run's multipliers (IDA does not converge them) are made
        consistent at the first read of ``y`` or ``yp`` (the run's consistency pass) and kept."""
        if self._y is None:
            assert self._lazy is not None
            self._y = self._lazy.y
        return self._y

    @property
    def yp(self) -> NDArray[np.float64]:
        """Time derivatives of the states (n_times, n_states); a run's and a loaded file's are computed
        at the first read from `y` (the run's consistency pass) and kept."""
        if self._yp is None:
            assert self._lazy is not None
            self._yp = self._lazy.yp
        return self._yp

    @property
    def sensitivity_names(self) -> tuple[str, ...]:
        """The parameters of the run's sensitivities (``simulate(..., sensitivities=[...])``); () without."""
        return () if self.sensitivities is None else self.sensitivities.names

    def sensitivity(self, name: str, parameter: str | None = None) -> NDArray[np.float64]:
        """d(name)/dp of a state or channel ``name`` at every output time: (n_times, Ns) in the order of
        :attr:`sensitivity_names`, or (n_times,) for one ``parameter``; NaN after a grazing event
        (docs/sensitivities.md). KeyError for a run without sensitivities or a name it does not hold."""
        if self.sensitivities is None:
            raise KeyError("Result.sensitivity: this run has no sensitivities; run "
                           "simulate(..., sensitivities=[names from model.parameter_names]).")
        return self.sensitivities.of(name, parameter)

    @property
    def sensitivity_horizon(self) -> SensitivityHorizon:
        """How fast the run's sensitivities grow: G(t), the largest |dy_i/dp_j| |p_j| / max|y_i| over the states
        and parameters, its finite-time Lyapunov estimate (the slope of ln G) and the predictability horizon
        t0 + ln(1/rtol)/lambda at the run's rtol, past which a derivative means nothing (docs/sensitivities.md,
        "Chaos"). Drawn by ``daeclear.plot.plot_sensitivity_horizon(result)``."""
        if self.sensitivities is None:
            raise KeyError("Result.sensitivity_horizon: this run has no sensitivities; run "
                           "simulate(..., sensitivities=[names from model.parameter_names]).")
        s = self.sensitivities
        rtol = float(self.parameters.get("simulate", {}).get("rtol", math.nan))
        if not 0.0 < rtol < 1.0:
            raise KeyError("Result.sensitivity_horizon: the result does not record its run's rtol "
                           "(parameters['simulate']['rtol']).")
        values = np.ones(len(s.names)) if s.values is None else s.values  # an older file: relative to 1
        return sensitivity_horizon(self.t, self.y, s.states, values, rtol)

    def gradient(self, of: Objective) -> Gradient:
        """The objective ``of`` (``dc.Final``, ``dc.Integral``, ``dc.Peak``, ``dc.EventTime``) on this run and
        its gradient w.r.t. :attr:`sensitivity_names`, as ``dc.gradient`` computes it: a run's result or a
        loaded one alike (the file keeps each event's rows). An Integral or a Peak reads the output rows:
        give the run enough of them (``SaveAt(times=...)``)."""
        if self.sensitivities is None:
            raise KeyError("Result.gradient: this run has no sensitivities; run "
                           "simulate(..., sensitivities=[names from model.parameter_names]).")
        return evaluate(of, RunTrajectory(self.t, self.__getitem__, self.sensitivities))

    def state(self, i: int) -> NDArray[np.float64]:
        """Row ``i`` of :attr:`y` (e.g. -1: the state to continue a run from), without making every row
        consistent when only this one is wanted (a run kept in memory: that row alone; bit for bit ``y[i]``)."""
        if self._y is None and self._lazy is not None:
            return self._lazy.row(i)
        return self.y[i]

    def _channel_values(self) -> dict[str, np.ndarray]:
        """The channels: a run's computed from its states at the first read, in one call, and kept."""
        if self._channels is None:
            assert self._lazy is not None
            self._channels = self._lazy.values()
        return self._channels

    @property
    def channels(self) -> Mapping[str, np.ndarray]:
        """Read-only mapping of channel name to array (first dimension n_times); a run's channels
        are computed from its states at the first read of any (all at once) and kept."""
        return MappingProxyType(self._channel_values())

    @property
    def channel_source(self) -> LazyChannels | None:
        """What the channels are computed from (states, switch rows, the model's output function),
        or None when they were given as arrays."""
        return self._lazy

    @property
    def channel_names(self) -> list[str]:
        """Channel names, sorted (state names not included; see `state_names`)."""
        return sorted(self._names)

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
        if self._channels is None and self._lazy is not None and name in self.state_names:
            # a state before any channel is read (a channel of that name holds the same values): no pass
            return self._lazy.state_column(self.state_names.index(name))
        if name in self._names:
            return self._channel_values()[name]
        if name in self.state_names:
            return self.y[:, self.state_names.index(name)]
        candidates = sorted(self._names | set(self.state_names))
        close = close_matches(name, candidates)
        if close:
            hint = "Close matches: " + ", ".join(repr(c) for c in close) + "."
        else:
            hint = f"See result.channel_names ({len(self._names)}) and result.state_names ({self.n_states})."
        raise ChannelKeyError(f"no channel {name!r}. {hint}")

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and (name in self._names or name in self.state_names)

    # A Result is not iterable: iterate over result.channel_names or result.state_names.
    __iter__ = None

    def __repr__(self) -> str:
        def seconds(x: float) -> str:
            return f"{x:.3g} s"

        lines = [
            f"daeclear Result: scene {self.scene_name!r}, method {self.method!r}, formulation {self.formulation!r}",
            f"  success: {self.success} (status {self.status}): {self.message!r}",
        ]
        file = self.stats.get("file") if not self.n_times else None  # a streamed run's outcome: data in its file
        if self.n_times:
            lines.append(
                f"  time: {self.t[0]:.6g} to {self.t[-1]:.6g} s, {self.n_times} output times, {self.n_states} states"
            )
        elif isinstance(file, Mapping) and "n_points" in file:
            lines.append(f"  time: no output times in memory (keep_data=False): {file['n_points']} points in "
                         f"{file['path']!r}, {self.n_states} states")
        else:
            lines.append(f"  time: no output times, {self.n_states} states")
        n_steps = self.stats.get("n_steps", None if self._steps is None else len(self._steps[0]))
        if isinstance(file, Mapping) and "n_events" in file:
            kinds, n_events, n_segments = file["events_by_kind"], file["n_events"], file["n_segments"]
        else:
            kinds = {k: self._events.kind.count(k) for k in EVENT_KINDS}
            n_events, n_segments = len(self._events), len(self.segments)
        counts = ", ".join(f"{kinds.get(k, 0)} {k}" for k in EVENT_KINDS)
        lines.append(
            f"  steps: {n_steps if n_steps is not None else '?'}, {n_events} events ({counts}), {n_segments} segments"
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
        """Boolean mask of the output times in the closed window [t0, t1] (s; None: that side open).
        ValueError if ``t0 > t1``."""
        lo, hi = time_window(t0, t1, "Result.window_mask")
        return (self.t >= lo) & (self.t <= hi)

    def slice(self, t0: float | None = None, t1: float | None = None) -> Result:
        """A new Result restricted to the closed time window [t0, t1] (s; None: that side open).

        Points, channels, events and steps inside the window are kept, overlapping segments
        clipped; `stats`, `parameters` and the outcome describe the whole run and are copied.

        Examples
        --------
        Two crank revolutions after the transient, at 5000 rpm:

        >>> period = 2 * np.pi / 523.6
        >>> steady = result.slice(result.t[-1] - 2 * period, None)   # doctest: +SKIP
        """
        lo, hi = time_window(t0, t1, "Result.slice")
        mask = self.window_mask(t0, t1)
        kw = self.to_dict(channels=False)
        kw.update(
            t=self.t[mask],
            y=self.y[mask],
            yp=None if self._yp is None else self._yp[mask],
            channels=self._lazy.take(mask) if self._lazy is not None else {
                name: arr[mask] for name, arr in self._channel_values().items()},
            events=[e for e in self._events if lo <= e.t <= hi],
            segments=[(max(a, lo), min(b, hi), m) for a, b, m in self.segments if a < hi and b > lo],
            sensitivities=None if self.sensitivities is None else self.sensitivities.take(mask, lo, hi),
        )
        if self._steps is not None:
            inside = (self._steps[0] >= lo) & (self._steps[0] <= hi)
            kw.update(step_t=self._steps[0][inside], step_h=self._steps[1][inside],
                      step_order=self._steps[2][inside])
        return Result(**kw)

    def to_dict(self, *, channels: bool = True) -> dict[str, Any]:
        """The constructor keywords: ``Result(**result.to_dict())`` rebuilds the result. Arrays are the
        result's own (the channels computed; ``channels=False``: its channel source); `stats` and
        `parameters` are copies."""
        return {
            "t": self.t,
            "y": self.y,
            "yp": self.yp,
            "state_names": list(self.state_names),
            "channels": dict(self._channel_values()) if channels or self._lazy is None else self._lazy,
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
            "sensitivities": self.sensitivities,
        }

    # ------------------------------------------------------------------ hand-off to pandas and xarray

    def to_pandas(self, *, states: bool = False, sensitivities: bool = False) -> pd.DataFrame:
        """The channels as a pandas DataFrame (copies), one column per channel, indexed by time ``"t"``.

        An event time may appear twice (before and after a restart); a channel of shape (n_times, k)
        becomes the columns ``"name[0]"`` ... ``"name[k-1]"``; ``states=True`` adds the states that
        are not channels. ``df.attrs`` holds ``"units"`` (per column and ``"t"``), scene_name, method,
        formulation, success, status and message. ``sensitivities=True`` (a run with them) adds the column
        ``"d(name)/d(parameter)"`` of each channel (and state) and parameter. MissingDependencyError (an
        ImportError) without pandas: ``pip install "daeclear[data]"``.
        """
        return export.to_pandas(self, states=states, sensitivities=sensitivities)

    def events_frame(self, *, states: bool = False) -> pd.DataFrame:
        """The contact events as a pandas DataFrame in time order: ``t`` (s), ``pair``, ``kind`` and
        ``approach_speed`` (m/s, nan where meaningless), with ``states=True`` the state at each event;
        ``df.attrs["units"]``. MissingDependencyError (an ImportError) without pandas."""
        return export.events_frame(self, states=states)

    def to_xarray(self, *, states: bool = True, sensitivities: bool = True) -> xr.Dataset:
        """The result as an xarray Dataset: channels over ``t``, events over ``event``.

        Each channel is a variable over ``t`` (more dimensions named ``"<channel>_dim_1"``, ...) with
        ``attrs["units"]``; ``t`` may hold an event time twice (select by position, ``ds.isel``). The
        events are ``event_t``, ``event_pair``, ``event_kind``, ``event_approach_speed`` (and
        ``event_y`` with states) over ``event``; the segments ``segment_t_start``, ``segment_t_end``,
        ``segment_modes`` (JSON) over ``segment``. Attributes are netCDF-safe (success as 0/1, each
        scalar statistic as ``stats.<name>``, ``stats_json``, ``parameters_json``). ``states=True``
        adds ``y`` and ``yp`` over (``t``, ``state``). A run with sensitivities (``sensitivities=True``) adds
        ``sensitivity_<channel>`` over (``t``, ``parameter``), with states ``sensitivity_y`` over (``t``, ``state``,
        ``parameter``), and its events' ``sensitivity_event_t``, ``_pair``, ``_kind``, ``_dt_dp``; coordinates
        ``parameter`` and ``parameter_value``. MissingDependencyError (an ImportError) without xarray:
        ``pip install "daeclear[data]"``.
        """
        return export.to_xarray(self, states=states, sensitivities=sensitivities)

    # ------------------------------------------------------------------ HDF5

    def save(self, path: str | os.PathLike[str], *, channels: bool = False) -> Path:
        """Write the result to an HDF5 file, atomically.

        A run's result is stored as its states (``t``, ``y``, each point's switch vector) when
        its scene can be rebuilt from its description: `load` computes the channels and ``yp``
        when they are first read, equal bit for bit. ``channels=True`` stores them too (for
        tools without daeclear: MATLAB, h5py); a result built from arrays always stores them.

        The file is written under a temporary name in the same directory and
        renamed over `path` (`os.replace`) only once complete: an existing file
        at `path` is either left untouched or replaced whole, and no temporary
        file survives a failure or an interrupt. The layout is in
        docs/hdf5_layout.md.

        Parameters
        ----------
        path : str or path-like
            Destination file, e.g. ``"run.h5"``. Its directory must exist.
        channels : bool
            Store every channel and ``yp`` even when `load` could compute them.

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
        return save_result(self, path, channels)


# --------------------------------------------------------------------------- reading


def load(path: str | os.PathLike[str], t0: float | None = None, t1: float | None = None) -> Result:
    """Read a result written by `Result.save` (or streamed by a run, ``simulate(save=SaveAt(stream_to=...))``).

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
        If `path` does not exist (IsADirectoryError: it is a directory).
    SceneError
        If `t0` or `t1` is not None or a number (NaN), or ``t0 > t1``; checked before the file is read.
    DaeclearError
        If the file is not HDF5, not a daeclear result, written by a newer daeclear, or lacks an
        item of the layout (the message names the file and what is missing); SceneError if the
        window [t0, t1] misses the run's output times.
    """
    return Result(**read_file(path, t0, t1))


def load_times(path: str | os.PathLike[str], of: str = "points") -> NDArray[np.float64]:
    """The times of a result file's output points, events or steps alone (8 bytes each), e.g. to
    choose the window of :func:`load` ``(path, t0, t1)`` in a file too long to read whole.

    ``of``: ``"points"`` (``/t``), ``"events"`` (``/events/t``) or ``"steps"`` (``/steps/t``;
    empty without steps)."""
    names = {"points": "t", "events": "events/t", "steps": "steps/t"}
    if of not in names:
        raise ValueError(f"load_times: of={of!r}, must be one of {', '.join(names)}.")
    read_file(path, math.inf, math.inf, within=False)  # the file's checks (format, version, items), no rows
    return read_dataset(path, names[of])


def read_result_group(group: h5py.Group, path: Path) -> Result:
    """The Result that :func:`write_result_group` wrote into ``group``, an open group of the file at
    ``path`` (named in the messages about a damaged result)."""
    return Result(**read_group(group, path))
