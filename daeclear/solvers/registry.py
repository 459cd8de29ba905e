"""The methods of :func:`daeclear.simulate`: each name and the solver class that runs it."""

from __future__ import annotations

import functools
import importlib
from typing import Any

from types import MappingProxyType

from ..core import methods, options
from . import explicit
from .base import Solver
from .ida import IDA

#: lower-case method name -> its solver class: a row of :data:`daeclear.core.methods.TABLE` each
SOLVERS: MappingProxyType[str, type[Solver]] = MappingProxyType(
    {m.key: IDA if m.family == "ida" else getattr(explicit, m.class_name) for m in methods.TABLE})
_MEMBERS = ("name", "formulation", "check", "run")


def method(value: Any, *, where: str = "simulate", field: str = "method") -> str | type[Solver]:
    """``method=``: a registered name (returned in lower case), a class implementing the protocol, or
    such a class by its import path ``"module:Class"`` (:func:`method_path`: how a file stores it)."""
    if isinstance(value, str) and ":" in value:
        module, _, qualname = value.partition(":")
        try:
            found = functools.reduce(getattr, qualname.split("."), importlib.import_module(module))
        except Exception as exc:  # whatever the module raises on import (a bug in it), said with the path
            options.fail(where, field, value, "a registered method name or the import path 'module:Class' of a "
                         f"solver class that can be imported here ({type(exc).__name__}: {exc})")
        if not isinstance(found, type):
            options.fail(where, field, value, "an import path 'module:Class' naming a class")
        return method(found, where=where, field=field)
    if isinstance(value, type):
        missing = [m for m in _MEMBERS if not hasattr(value, m)]
        if missing or not all(callable(getattr(value, m)) for m in ("run", "check")):
            options.fail(where, field, value, "a registered method name or a class implementing "
                         "daeclear.solvers.base.Solver (name, formulation, check, run)"
                         + (f"; it lacks {', '.join(missing)}" if missing else ""))
        name, formulation = value.name, value.formulation  # type: ignore[attr-defined]
        if not isinstance(name, str) or not name:
            options.fail(where, field, value, f"a solver class whose name is a non-empty string, not {name!r}")
        if formulation not in options.FORMULATIONS:
            options.fail(where, field, value, f"a solver class whose formulation is one of "
                         f"{', '.join(options.FORMULATIONS)}, not {formulation!r}")
        return value
    return options.method(value, where=where, field=field)


def method_path(value: str | type[Solver]) -> str:
    """A checked ``method`` as text (JSON): its name, or a class as ``"module:Class"`` (:func:`method` reads it)."""
    return value if isinstance(value, str) else f"{value.__module__}:{value.__qualname__}"


def solver_class(value: str | type[Solver]) -> type[Solver]:
    """The class of a checked ``method`` (:func:`method`)."""
    return value if isinstance(value, type) else SOLVERS[value]
