"""The methods of :func:`daeclear.simulate`: each name and the solver class that runs it."""

from __future__ import annotations

from typing import Any

from .. import options
from .base import Solver
from .explicit import BDF, DOP853, LSODA, RK4, RK45, Euler, Radau
from .ida import IDA

#: lower-case method name -> its solver class (the names of :data:`daeclear.options.METHODS`)
SOLVERS: dict[str, type[Solver]] = {
    "ida": IDA, "rk45": RK45, "dop853": DOP853, "radau": Radau, "bdf": BDF, "lsoda": LSODA, "rk4": RK4,
    "euler": Euler,
}
_MEMBERS = ("name", "formulation", "check", "run")


def method(value: Any, *, where: str = "simulate", field: str = "method") -> str | type[Solver]:
    """``method=``: a registered name (returned in lower case) or a class implementing the protocol."""
    if isinstance(value, type):
        missing = [m for m in _MEMBERS if not hasattr(value, m)]
        if missing or not all(callable(getattr(value, m)) for m in ("run", "check")):
            options.fail(where, field, value, "a registered method name or a class implementing "
                         "daeclear.solvers.base.Solver (name, formulation, check, run)"
                         + (f"; it lacks {', '.join(missing)}" if missing else ""))
        return value
    return options.method(value, where=where, field=field)


def solver_class(value: str | type[Solver]) -> type[Solver]:
    """The class of a checked ``method`` (:func:`method`)."""
    return value if isinstance(value, type) else SOLVERS[value]
