"""The methods of :func:`daeclear.simulate`: each name and the solver class that runs it."""

from __future__ import annotations

import functools
import importlib
from typing import Any

from ..core import options
from .base import Solver
from .explicit import BDF, DOP853, LSODA, RK4, RK45, Euler, Radau
from .ida import IDA

#: lower-case method name -> its solver class (the names of :data:`daeclear.core.options.METHODS`)
SOLVERS: dict[str, type[Solver]] = {
    "ida": IDA, "rk45": RK45, "dop853": DOP853, "radau": Radau, "bdf": BDF, "lsoda": LSODA, "rk4": RK4,
    "euler": Euler,
}
_MEMBERS = ("name", "formulation", "check", "run")


def method(value: Any, *, where: str = "simulate", field: str = "method") -> str | type[Solver]:
    """``method=``: a registered name (returned in lower case), a class implementing the protocol, or
    such a class by its import path ``"module:Class"`` (:func:`method_path`: how a file stores it)."""
    if isinstance(value, str) and ":" in value:
        module, _, qualname = value.partition(":")
        try:
            found = functools.reduce(getattr, qualname.split("."), importlib.import_module(module))
        except (ImportError, AttributeError, ValueError) as exc:
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
        return value
    return options.method(value, where=where, field=field)


def method_path(value: str | type[Solver]) -> str:
    """A checked ``method`` as text (JSON): its name, or a class as ``"module:Class"`` (:func:`method` reads it)."""
    return value if isinstance(value, str) else f"{value.__module__}:{value.__qualname__}"


def solver_class(value: str | type[Solver]) -> type[Solver]:
    """The class of a checked ``method`` (:func:`method`)."""
    return value if isinstance(value, type) else SOLVERS[value]
