"""The hand-off of a `Result` to pandas and xarray (the ``data`` extra, imported only when asked for): the
bodies of `Result.to_pandas`, `Result.events_frame` and `Result.to_xarray`, whose docstrings say what they hold.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.errors import MissingDependencyError

if TYPE_CHECKING:  # pandas and xarray are imported lazily, only where they are used
    import pandas as pd
    import xarray as xr

    from .result import Result

__all__ = ["events_frame", "to_pandas", "to_xarray"]


def to_pandas(r: Result, *, states: bool = False, sensitivities: bool = False) -> pd.DataFrame:
    """The channels of ``r`` as a DataFrame indexed by time: :meth:`Result.to_pandas`."""
    pd = _optional("pandas", "Result.to_pandas")
    cols, units = _columns(r, states)
    if sensitivities:
        cols, units = _sensitivity_columns(r, cols, units)
    index = pd.Index(np.array(r.t), name="t")
    df = pd.DataFrame({name: np.array(arr) for name, arr in cols.items()}, index=index)
    df.attrs["units"] = {"t": "s", **units}
    df.attrs.update(_metadata(r))
    return df


def events_frame(r: Result, *, states: bool = False) -> pd.DataFrame:
    """The contact events of ``r`` as a DataFrame, one row per event: :meth:`Result.events_frame`."""
    pd = _optional("pandas", "Result.events_frame")
    data: dict[str, Any] = {
        "t": r.events.t,
        "pair": pd.Series(r.events.pair, dtype=object),
        "kind": pd.Series(r.events.kind, dtype=object),
        "approach_speed": r.events.approach_speed,
    }
    units = {"t": "s", "pair": "", "kind": "", "approach_speed": "m/s"}
    if states:
        y = np.array([e.y for e in r.events], dtype=np.float64).reshape(len(r.events), r.n_states)
        for j, name in enumerate(r.state_names):
            data[f"y:{name}"] = y[:, j]
            units[f"y:{name}"] = r.units[name]
    df = pd.DataFrame(data)
    df.index.name = "event"
    df.attrs["units"] = units
    return df


def to_xarray(r: Result, *, states: bool = True, sensitivities: bool = True) -> xr.Dataset:
    """``r`` as an xarray Dataset, channels over ``t``, events over ``event``: :meth:`Result.to_xarray`."""
    xr = _optional("xarray", "Result.to_xarray")
    variables: dict[str, Any] = {}
    for name in r.channel_names:
        arr = np.array(r.channels[name])
        dims = ("t", *(f"{name}_dim_{k}" for k in range(1, arr.ndim)))
        variables[name] = xr.Variable(dims, arr, attrs={"units": r.units[name]})
    coords: dict[str, Any] = {"t": xr.Variable("t", np.array(r.t), attrs={"units": "s"})}
    if states:
        coords["state"] = xr.Variable("state", np.array(r.state_names, dtype=object))
        coords["state_units"] = xr.Variable("state", np.array([r.units[n] for n in r.state_names],
                                                              dtype=object))
        variables["y"] = xr.Variable(("t", "state"), np.array(r.y))
        variables["yp"] = xr.Variable(("t", "state"), np.array(r.yp))
    ev = r.events
    variables["event_t"] = xr.Variable("event", ev.t, attrs={"units": "s"})
    variables["event_pair"] = xr.Variable("event", np.array(ev.pair, dtype=object))
    variables["event_kind"] = xr.Variable("event", np.array(ev.kind, dtype=object))
    variables["event_approach_speed"] = xr.Variable("event", ev.approach_speed, attrs={"units": "m/s"})
    if states:
        y_events = np.array([e.y for e in ev], dtype=np.float64).reshape(len(ev), r.n_states)
        variables["event_y"] = xr.Variable(("event", "state"), y_events)
    for k, side in enumerate(("start", "end")):
        variables[f"segment_t_{side}"] = xr.Variable("segment", np.array([s[k] for s in r.segments], dtype=np.float64),
                                                     attrs={"units": "s"})
    variables["segment_modes"] = xr.Variable(
        "segment", np.array([json.dumps(s[2], ensure_ascii=False) for s in r.segments], dtype=object))
    if sensitivities and r.sensitivities is not None:
        coords.update(_sensitivity_variables(r, variables, states))
    attrs: dict[str, Any] = {**_metadata(r), "success": int(r.success)}
    for key, value in r.stats.items():
        if isinstance(value, bool):
            attrs[f"stats.{key}"] = int(value)
        elif isinstance(value, (int, float, str)):
            attrs[f"stats.{key}"] = value
    attrs["stats_json"] = json.dumps(r.stats, ensure_ascii=False)
    attrs["parameters_json"] = json.dumps(r.parameters, ensure_ascii=False)
    return xr.Dataset(variables, coords=coords, attrs=attrs)


def _columns(r: Result, states: bool) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """One-dimensional columns (multi-dimensional channels split as ``name[i]``) and their units."""
    cols: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    for name in r.channel_names:
        arr = r.channels[name]
        if arr.ndim == 1:
            cols[name], units[name] = arr, r.units[name]
            continue
        flat = arr.reshape(arr.shape[0], -1)
        for k, index in enumerate(np.ndindex(*arr.shape[1:])):
            col = f"{name}[{','.join(str(i) for i in index)}]"
            cols[col], units[col] = flat[:, k], r.units[name]
    if states:
        for j, name in enumerate(r.state_names):
            if name not in cols:  # a channel of the same name wins, as in result[name]
                cols[name], units[name] = r.y[:, j], r.units[name]
    return cols, units


def _sensitivity_columns(r: Result, cols: dict[str, np.ndarray], units: dict[str, str]
                         ) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """``cols`` followed by d(column)/d(parameter) of each one-dimensional channel or state among them."""
    s = r.sensitivities
    if s is None:
        from ..core.options import fail

        fail("Result.to_pandas", "sensitivities", True, "False for a run without sensitivities (run "
             "simulate(..., sensitivities=[...]))")
    out, out_units = dict(cols), dict(units)
    for name in cols:
        if name in s.state_names or name in s.channel_names:
            S = s.of(name)
            for j, parameter in enumerate(s.names):
                out[f"d({name})/d({parameter})"] = S[:, j]
                out_units[f"d({name})/d({parameter})"] = f"{units[name]} per unit of {parameter}".strip()
    return out, out_units


def _sensitivity_variables(r: Result, variables: dict[str, Any], states: bool) -> dict[str, Any]:
    """The sensitivities of ``r`` added to ``variables``; return their coordinates."""
    import xarray as xr

    s = r.sensitivities
    assert s is not None
    for i, name in enumerate(s.channel_names):
        if name in variables and variables[name].ndim == 1:
            variables[f"sensitivity_{name}"] = xr.Variable(("t", "parameter"), np.array(s.channels[:, i, :]),
                                                           attrs={"units": f"{r.units[name]} per unit of parameter"})
    if states:
        variables["sensitivity_y"] = xr.Variable(("t", "state", "parameter"), np.array(s.states))
    variables["sensitivity_event_t"] = xr.Variable("sensitivity_event", np.array([e.t for e in s.events], dtype=float),
                                                   attrs={"units": "s"})
    variables["sensitivity_event_pair"] = xr.Variable("sensitivity_event", np.array([e.pair for e in s.events],
                                                                                   dtype=object))
    variables["sensitivity_event_kind"] = xr.Variable("sensitivity_event", np.array([e.kind for e in s.events],
                                                                                   dtype=object))
    variables["sensitivity_event_dt_dp"] = xr.Variable(("sensitivity_event", "parameter"), np.array(
        [e.dt_dp for e in s.events], dtype=float).reshape(len(s.events), len(s.names)), attrs={"units": "s per unit"})
    values = np.full(len(s.names), np.nan) if s.values is None else np.asarray(s.values, dtype=float)
    return {"parameter": xr.Variable("parameter", np.array(s.names, dtype=object)),
            "parameter_value": xr.Variable("parameter", values)}


def _metadata(r: Result) -> dict[str, Any]:
    return {"scene_name": r.scene_name, "method": r.method, "formulation": r.formulation,
            "success": r.success, "status": r.status, "message": r.message}


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
