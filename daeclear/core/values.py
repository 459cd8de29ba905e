"""How a result holds what it is given: plain JSON values, read-only arrays, checked time windows (shared by
the `Result` container, its events and the HDF5 writers and reader).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import fields, is_dataclass
from typing import Any

import numpy as np

from .errors import DaeclearWarning

__all__ = ["field_names", "readonly", "time_window", "to_plain"]


def readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (the caller's array keeps its flags), or ``a`` when it is read-only already."""
    if not a.flags.writeable:
        return a
    view = a.view()
    view.flags.writeable = False
    return view


def time_window(t0: float | None, t1: float | None) -> tuple[float, float]:
    """The closed window [t0, t1] as floats (None: that side open, +-inf); ValueError if ``t0 > t1``."""
    lo = -math.inf if t0 is None else float(t0)
    hi = math.inf if t1 is None else float(t1)
    if lo > hi:
        raise ValueError(f"time window t0={t0} > t1={t1}; t0 must not exceed t1.")
    return lo, hi


# exact types to_plain returns unchanged (subclasses such as numpy.float64 take the checks below)
_PLAIN_LEAVES = frozenset({type(None), bool, str, int, float})


def to_plain(value: Any, where: str) -> Any:
    """``value`` as plain JSON-able Python (numpy values, tuples and paths converted).

    A dataclass instance (e.g. a Material) becomes the dict of its fields, headed by ``"name"`` when its
    class has one (a contact law's); anything else is stored as its ``repr`` with a DaeclearWarning naming
    ``where``, so a finished run is never lost to an odd parameter. Non-string dict keys raise TypeError.
    """
    return _plain(value, (where,))


def field_names(cls: type) -> tuple[str, ...]:
    """The field names of a dataclass class, in order."""
    return tuple(f.name for f in fields(cls))


def _location(path: tuple[Any, ...]) -> str:
    """``where[key][index]...``: where a value sits in what to_plain was given (made only for a message)."""
    return str(path[0]) + "".join(f"[{key!r}]" for key in path[1:])


def _plain_dict(value: Mapping[Any, Any], path: tuple[Any, ...]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, item in value.items():
        if type(key) is not str and not isinstance(key, str):
            raise TypeError(f"{_location(path)}: key {key!r} is a {type(key).__name__}, keys must be strings.")
        out[key] = item if type(item) in _PLAIN_LEAVES else _plain(item, (*path, key))
    return out


def _plain_list(value: list[Any] | tuple[Any, ...], path: tuple[Any, ...]) -> list[Any]:
    return [item if type(item) in _PLAIN_LEAVES else _plain(item, (*path, i)) for i, item in enumerate(value)]


def _plain(value: Any, path: tuple[Any, ...]) -> Any:
    kind = type(value)
    if kind in _PLAIN_LEAVES:  # the common cases first: plain numbers and strings stay as they are,
        return value
    if kind is dict:  # and plain dicts and lists, the bulk of a scene, are copied
        return _plain_dict(value, path)
    if kind is list:
        return _plain_list(value, path)
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value)
    if isinstance(value, Mapping):
        return _plain_dict(value, path)
    if isinstance(value, (list, tuple)):
        return _plain_list(value, path)
    # after the containers: dicts and lists, the bulk of a scene, skip these (slower ABC) checks
    if isinstance(value, np.generic):
        return _plain(value.item(), path)
    if isinstance(value, np.ndarray):
        return _plain(value.tolist(), path)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if is_dataclass(value) and not isinstance(value, type):
        out = {name: _plain(getattr(value, name), (*path, name)) for name in field_names(kind)}
        label = getattr(kind, "name", None)  # a contact law's registered name, e.g. "hunt-crossley"
        if isinstance(label, str) and "name" not in out:
            out = {"name": label, **out}
        return out
    text = repr(value)
    warnings.warn(
        f"{_location(path)}: a {kind.__name__} is not a number, string, bool, None, list or dict; "
        f"stored as its repr {text[:60]!r}.",
        DaeclearWarning,
        stacklevel=5,
    )
    return text


