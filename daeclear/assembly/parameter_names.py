"""The one name space of a model's numbers (docs/user_guide.md, section 2).

A number is named by where it is in the scene: ``"<element>.<field>"``, ``"<element>.<field>.<field>..."``
through a law, friction law, material, wear law or driver profile (``"clearance.law.dry.restitution"``),
``"gravity"``, and for ``index1`` ``"baumgarte.alpha"``/``"baumgarte.beta"``. :func:`scene_names` lists
them: the *settable* ones (every number the scene has, of a law that runs on symbols) are exactly what
``DAEModel.with_parameters``, ``simulate(parameters=)``, sweeps and ``daeclear sweep --grid`` accept;
the *structural* ones (text, flags, counts such as a wear profile's ``nodes``, a baked law's numbers)
are listed apart and read-only. The compiled parameter table may hold more entries, derived from these
(``<joint>.s_i``, a stiffness computed from the materials): ``model.parameter(name)`` reads them.
"""

from __future__ import annotations

import dataclasses
import numbers
from typing import Any

import numpy as np

from ..model.load_values import Expression

__all__ = ["BAUMGARTE_NAMES", "is_numbers", "scene_names"]

#: The index1 formulation's numbers, beside the scene's.
BAUMGARTE_NAMES = ("baumgarte.alpha", "baumgarte.beta")


def scene_names(scene: Any, formulation: str, table: frozenset[str], elements: frozenset[str] | None = None
                ) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(settable, structural) value names of ``scene`` assembled with ``formulation`` into a model whose
    parameter table has the entries ``table`` (a law's numbers are settable when the table has them:
    its formula runs on symbols), in scene order; ``elements``: those of these elements only."""
    settable: list[str] = ["gravity"]
    structural: list[str] = []
    for element in scene.elements:
        if elements is not None and element.name not in elements:
            continue
        free: frozenset[str] = getattr(element, "NOT_STRUCTURE", frozenset())
        for f in dataclasses.fields(element):
            if f.name == "name":
                continue
            path = f"{element.name}.{f.name}"
            value = getattr(element, f.name)
            if f.name in free and value is not None:  # e.g. a slider's reading: it changes numbers only
                settable.append(path)
            else:
                _walk(value, path, str(f.type), True, table, settable, structural)
    if formulation == "index1":
        settable.extend(BAUMGARTE_NAMES)
    return tuple(settable), tuple(structural)


def _is_number(value: Any) -> bool:
    return type(value) is float or isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_numbers(value: Any) -> bool:
    """A number, or a (nested) sequence of them: a point, a vector, a table's values, a worn profile."""
    if _is_number(value):
        return True
    if isinstance(value, np.ndarray):
        return value.size > 0 and value.dtype.kind in "iuf"
    if not isinstance(value, (tuple, list)) or not value:
        return False
    # a flat run of floats (a worn profile's hundreds of nodes) without a call an entry
    return set(map(type, value)) == {float} or all(is_numbers(v) for v in value)


def _walk(value: Any, path: str, annotation: str, parametric: bool, table: frozenset[str], settable: list[str],
          structural: list[str]) -> None:
    """File ``value`` (at ``path``) as settable or structural, into a dataclass's fields."""
    if value is None:
        return  # left to be derived (a stiffness from the materials): give it in the scene to set it
    if is_numbers(value):
        count = annotation == "int" or annotation.startswith("int ")  # a count (nodes, modes) shapes the model
        (settable if parametric and not count else structural).append(path)
    elif dataclasses.is_dataclass(value) and not isinstance(value, (type, Expression)):
        is_law = hasattr(value, "force") or hasattr(value, "friction_force")  # a baked law's numbers are structure
        inner = parametric and (not is_law or any(name.startswith(path + ".") for name in table))
        for f in dataclasses.fields(value):
            _walk(getattr(value, f.name), f"{path}.{f.name}", str(f.type), inner, table, settable, structural)
    else:
        structural.append(path)  # text, flags, a function, a pair of materials
