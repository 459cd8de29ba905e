"""The checks of a `Result`'s constructor: shapes, names, units, events, segments, steps and status.

Kept apart from daeclear.results.result (the container) so that the container reads as what it
holds; each check raises ValueError with the field, the value and the rule.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..core.options import close_matches
from ..core.events import ContactEvent, EventList
from .lazy_channels import LazyChannels

__all__ = ["checked_fields"]


def checked_fields(t: ArrayLike, y: ArrayLike, yp: ArrayLike | None, state_names: Sequence[str],
                   channels: Mapping[str, ArrayLike] | LazyChannels, units: Mapping[str, str],
                   events: Iterable[ContactEvent], segments: Iterable[tuple[float, float, Mapping[str, str]]],
                   step_t: ArrayLike | None, step_h: ArrayLike | None, step_order: ArrayLike | None,
                   success: bool, status: int) -> tuple[Any, ...]:
    """The constructor's arguments checked and converted: (t, y, yp, names, channels, events, segments,
    steps), as `Result._assign` takes them; ValueError on inconsistent shapes, names or status."""
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
    yp_arr = None if yp is None else np.asarray(yp, dtype=np.float64)
    if yp is None and not isinstance(channels, LazyChannels):
        raise ValueError("Result: yp=None, must be given (computed only by lazy channels' consistency pass).")
    for label, arr in (("y", y_arr), ("yp", y_arr if yp_arr is None else yp_arr)):
        if arr.shape != shape:
            raise ValueError(f"Result: {label} has shape {arr.shape}, expected (n_times, n_states) = {shape} "
                             "from t and state_names.")

    chans: dict[str, np.ndarray] | LazyChannels = {}
    for name, values in ({} if isinstance(channels, LazyChannels) else channels).items():
        if not isinstance(name, str) or not name or "/" in name or name == ".":
            raise ValueError(f"Result: channel name {name!r} is invalid; use '<object>.<quantity>' without '/'.")
        arr = np.asarray(values)
        if arr.ndim == 0 or arr.shape[0] != n_times:
            raise ValueError(f"Result: channel {name!r} has shape {arr.shape}, its first dimension must be "
                             f"n_times={n_times}.")
        chans[name] = arr  # type: ignore[index]
    if isinstance(channels, LazyChannels):
        if channels.t.shape != (n_times,) or channels.y.shape != shape:
            raise ValueError(f"Result: the lazy channels' states have {channels.t.shape[0]} rows, must have "
                             f"n_times={n_times}.")
        chans = channels

    known = {*(chans.names if isinstance(chans, LazyChannels) else chans), *names}
    for name, unit in units.items():
        if name not in known:
            close = close_matches(name, sorted(known), n=3)
            hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
            raise ValueError(f"Result: units given for {name!r}, which is neither a channel nor a state.{hint}")
        if not isinstance(unit, str):
            raise ValueError(f"Result: unit of {name!r} is {unit!r}, must be a string such as 'm/s'.")

    event_list = EventList(events)
    for e in event_list:
        if e.y.shape != (len(names),):
            raise ValueError(f"Result: event {e!r} has a state of shape {e.y.shape}, expected ({len(names)},).")

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
            raise ValueError(f"Result: step_t, step_h, step_order have shapes {st.shape}, {sh.shape}, "
                             f"{so.shape}; they must be equal and one-dimensional.")
        steps = (st, sh, so)

    if status not in (-1, 0, 1):
        raise ValueError(f"Result: status={status!r}, must be 0 (end reached), 1 (terminal event) or -1 (failed).")
    if bool(success) != (status >= 0):
        raise ValueError(f"Result: success={success} contradicts status={status} (only status -1 is a failure).")
    return t_arr, y_arr, yp_arr, names, chans, event_list, segs, steps
