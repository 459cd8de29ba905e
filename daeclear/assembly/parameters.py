"""Run-time parameters of an assembled model: what is compiled versus what is data.

The compiled engine depends only on a scene's *structure*; every number is an entry of the vector
``P``, the last input of every generated function, so a scene with other numbers compiles nothing.

* :class:`ParameterTable`: the named entries of ``P``;
* :func:`structure_key`: the scene with every number masked, which picks the compiled library;
* :func:`law_values` / :func:`symbolic_law`: a law's numbers as parameters, and a twin of the law
  whose numbers are symbols. A law whose formula cannot run on symbols is *baked*: its numbers
  join the structure key (checked once per law class).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from typing import Any
from collections.abc import Iterable

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..model.elements import kept
from ..core.values import field_names

__all__ = ["ParameterTable", "entries", "floats", "structure_key", "element_structure", "law_values", "symbolic_law",
           "law_structure", "is_parametric"]


class ParameterTable:
    """Ordered named parameters (a float or a short vector each): ``layout`` (names and sizes) is
    structure, ``vector`` the run-time data."""

    def __init__(self) -> None:
        # plain floats (one array at the end): a scene's table is made at every assembly
        self._values: dict[str, tuple[float, ...]] = {}

    def add(self, name: str, value: Any) -> None:
        """Add one entry; ``value`` is a number or a sequence of numbers."""
        self.extend(((name, floats(value)),))

    def extend(self, named: Iterable[tuple[str, tuple[float, ...]]]) -> None:
        """Add entries made by :func:`entries` (kept entries of a shared element are added as they are)."""
        for name, value in named:
            if name in self._values:
                raise KeyError(f"parameter {name!r} added twice")
            self._values[name] = value

    @property
    def layout(self) -> tuple[tuple[str, int], ...]:
        return tuple((name, len(v)) for name, v in self._values.items())

    def has_layout(self, names: tuple[str, ...], sizes: tuple[int, ...]) -> bool:
        """The entries' names and sizes are these (:attr:`layout` compared without building it)."""
        return tuple(self._values) == names and tuple(map(len, self._values.values())) == sizes

    @property
    def vector(self) -> NDArray[np.float64]:
        return np.array([x for v in self._values.values() for x in v], dtype=float)

    def value(self, name: str) -> NDArray[np.float64]:
        return np.array(self._values[name], dtype=float)

    def symbols(self, P: Any) -> dict[str, Any]:
        """Name -> the slice of the symbol vector ``P`` that holds it (scalars as 1x1)."""
        offsets = self.offsets()
        return {name: P[offsets[name]:offsets[name] + size] for name, size in self.layout}

    def offsets(self) -> dict[str, int]:
        """Name -> index of the entry's first element in :attr:`vector`."""
        out, offset = {}, 0
        for name, size in self.layout:
            out[name] = offset
            offset += size
        return out


def floats(value: Any) -> tuple[float, ...]:
    """A parameter entry's values: a number or a sequence of numbers as a tuple of floats."""
    kind = type(value)
    if kind is float or kind is int:
        return (float(value),)
    if (kind is tuple or kind is list) and all(type(v) is float or type(v) is int for v in value):
        return tuple(map(float, value))  # a point or a vector: numpy is slower on a few numbers
    return tuple(np.asarray(value, dtype=float).ravel().tolist())


def entries(prefix: str, values: dict[str, Any]) -> tuple[tuple[str, tuple[float, ...]], ...]:
    """``values`` as parameter entries named ``prefix.<key>`` (see :meth:`ParameterTable.extend`)."""
    return tuple((f"{prefix}.{key}", floats(value)) for key, value in values.items())


# ---- structure -------------------------------------------------------------------------

def _mask(value: Any) -> Any:
    """A plain-data copy of ``value`` with every number replaced by ``'#'``."""
    kind = type(value)  # the exact plain types first: this runs on every field of a scene
    if kind is str or kind is bool or value is None:
        return value
    if kind is float or kind is int:
        return "#"
    if kind is dict:
        return {str(k): _mask(v) for k, v in value.items()}
    if kind is list or kind is tuple:
        return [_mask(v) for v in value]
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float, np.floating, np.integer)):
        return "#"
    if isinstance(value, dict):
        return {str(k): _mask(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_mask(v) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):  # a law or a material: kept on it
        return kept(value, "_masked", _mask_fields)
    return repr(value)


def _mask_fields(value: Any) -> list[Any]:
    return [type(value).__name__, {name: _mask(getattr(value, name)) for name in field_names(type(value))}]


def element_structure(element: Any) -> str:
    """An element's class and fields (but its ``NOT_STRUCTURE``) as text, every number masked; kept on
    the frozen element, so a sweep's shared elements are described once."""
    return kept(element, "_structure_text", _element_structure)


def _element_structure(element: Any) -> str:
    skip = element.NOT_STRUCTURE
    return "\x02".join([type(element).__name__, *(f"{name}={_masked_text(getattr(element, name))}"
                                                   for name in field_names(type(element)) if name not in skip)])


def _masked_text(value: Any) -> str:
    """One field of an element as text with every number masked (a law's or a body's kept on it)."""
    kind = type(value)
    if kind is float or kind is int or isinstance(value, (np.floating, np.integer)):
        return "#"
    if kind is str or kind is bool or value is None:
        return repr(value)
    if kind is tuple or kind is list:
        if value and set(map(type, value)) == {float}:  # a flat run of floats (a worn profile): one mask an entry
            return "[" + ",".join("#" * len(value)) + "]"
        return "[" + ",".join(map(_masked_text, value)) + "]"
    if hasattr(value, "to_dict") or (dataclasses.is_dataclass(value) and not isinstance(value, type)):
        return kept(value, "_masked_text", _described_text)
    return repr(_mask(value))


def _described_text(value: Any) -> str:
    """A value with a description (``to_dict``) or a dataclass (a law, a material) as masked text."""
    return repr(_mask(value.to_dict() if hasattr(value, "to_dict") else value))


def structure_key(elements: Iterable[Any], extra: Iterable[Any]) -> str:
    """SHA-256 of a scene's structure: each element's name and :func:`element_structure`, plus
    ``extra`` (formulation, options, the laws' structural flags); no name or number is part of it."""
    text = "\x00".join([f"{e.name}\x01{element_structure(e)}" for e in elements] + [str(x) for x in extra])
    return hashlib.sha256(text.encode()).hexdigest()


# ---- laws ------------------------------------------------------------------------------

def _numeric_fields(law: Any) -> list[str]:
    return [name for name in field_names(type(law))
            if isinstance(value := getattr(law, name), (int, float)) and not isinstance(value, bool)]


_PARAMETRIC: dict[type, bool] = {}


def is_parametric(law: Any) -> bool:
    """True when the law's formula runs with symbolic numbers and agrees with the numeric law
    (checked once per class, at a few penetrations and rates)."""
    cls = type(law)
    if cls not in _PARAMETRIC:
        _PARAMETRIC[cls] = _check_parametric(law)
    return _PARAMETRIC[cls]


def _evaluate(law: Any, x: Any, y: Any, z: Any) -> Any:
    if hasattr(law, "friction_force"):
        return law.friction_force(x, y)
    return law.force(x, y, z) if law.needs_approach_speed else law.force(x, y)


#: Properties the assembly branches on: a twin answers them with the numeric law's values.
_FLAGS = ("needs_approach_speed", "dissipative", "is_resolved", "frictionless")


def _fixed_flag(flag: str) -> property:
    """A read-only attribute ``flag`` answered from the twin's ``_fixed_flags``."""
    return property(lambda self: self._fixed_flags[flag])


def _check_parametric(law: Any) -> bool:
    names = _numeric_fields(law)
    if not names:
        return True
    P = ca.SX.sym("P", len(names))
    try:
        twin = _twin(law, {name: P[i] for i, name in enumerate(names)})
        a, b, c = ca.SX.sym("a"), ca.SX.sym("b"), ca.SX.sym("c")
        f = ca.Function("law_check", [a, b, c, P], [_evaluate(twin, a, b, c)])
        if f.has_free():
            return False
    except Exception:  # a formula that needs numbers (math.*, comparisons): bake its numbers
        return False
    values = [float(getattr(law, name)) for name in names]
    for x, y, z in ((1e-6, 0.3, 0.5), (3e-5, -0.2, 1.2), (2e-4, 1.5, 2.0), (-1e-6, 0.1, 0.5)):
        try:
            expected = float(_evaluate(law, x, y, z))
        except Exception:
            return False
        got = float(f(x, y, z, values))
        if not (math.isclose(got, expected, rel_tol=1e-9, abs_tol=1e-12) or (math.isnan(got) and math.isnan(expected))):
            return False
    return True


def _twin(law: Any, symbols: dict[str, Any]) -> Any:
    """A copy of ``law`` with some numeric fields replaced by symbols (not validated again; its
    structural flags kept as values)."""
    cls = type(law)  # a subclass whose structural flags are fixed values, not expressions of its fields
    twin: Any = object.__new__(type(cls.__name__, (cls,), {f: _fixed_flag(f) for f in _FLAGS if hasattr(cls, f)}))
    object.__setattr__(twin, "_fixed_flags", {flag: getattr(law, flag) for flag in _FLAGS if hasattr(law, flag)})
    for f in dataclasses.fields(law):
        object.__setattr__(twin, f.name, symbols.get(f.name, getattr(law, f.name)))
    return twin


def law_values(law: Any) -> dict[str, float]:
    """The law's numbers as run-time parameters (empty for a baked law)."""
    if not is_parametric(law):
        return {}
    return {name: float(getattr(law, name)) for name in _numeric_fields(law)}


def symbolic_law(law: Any, symbols: dict[str, Any], prefix: str) -> Any:
    """The law with its numbers taken from ``symbols[prefix.<field>]`` (the law itself if baked)."""
    if not is_parametric(law):
        return law
    return _twin(law, {name: symbols[f"{prefix}.{name}"][0] for name in _numeric_fields(law)})


def law_structure(law: Any) -> str:
    """What of a law decides the equations' shape, as text: its class, the flags the assembly branches
    on, which fields are set, and all its numbers when it is baked (kept on the frozen law)."""
    return kept(law, "_law_structure", lambda each: repr(_law_structure(each)))


def _law_structure(law: Any) -> list[Any]:
    flags: list[Any] = [type(law).__name__]
    for attr in ("needs_approach_speed", "dissipative", "frictionless", "smooth", "geometry"):
        if hasattr(law, attr):
            flags.append((attr, getattr(law, attr)))
    exponent = getattr(law, "effective_exponent", None)
    if exponent is not None:
        flags.append(("linear", exponent == 1.0))
    flags.append(_mask(law) if is_parametric(law) else repr(law))
    return flags
