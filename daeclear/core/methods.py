"""The methods of :func:`daeclear.simulate`, one row each: every list of method names is derived from
this table (the names the options accept, the solver classes of :mod:`daeclear.solvers.registry`,
the fixed-step methods, the scipy classes and the orders the steps record).

>>> [m.key for m in TABLE if m.family == "fixed"]
['rk4', 'euler']
>>> METHODS[0], by_key("DOP853").name, by_key("radau").jacobian
('ida', 'DOP853', True)
"""

from __future__ import annotations

from typing import Literal, NamedTuple

from . import defaults

__all__ = ["Method", "TABLE", "METHODS", "FIXED_STEP", "CHAPTER_FORMULATION", "by_key"]

#: ``"ida"``: SUNDIALS IDA on the DAE; ``"scipy"``: a scipy ``OdeSolver`` on the index-1 DAE as an
#: ODE in (q, v); ``"fixed"``: a fixed-step scheme on that ODE, its step loop in C.
Family = Literal["ida", "scipy", "fixed"]


class Method(NamedTuple):
    """One method: ``key`` (lower case, what the options accept case-insensitively), ``name`` (what
    ``result.method`` reports; for scipy, its class in ``scipy.integrate``), ``family``, the name of
    its solver class (``daeclear.solvers.ida``, ``daeclear.solvers.explicit``), the ``order``
    its steps record (-1: the scheme varies it; a fixed-step scheme's order is also its code in the
    C loop, ``engine.abi.DCO_*``), whether it takes the generated ``jacobian`` and the ``formulation``
    a Scene is assembled with when the options name none."""

    key: str
    name: str
    family: Family
    class_name: str
    order: int
    jacobian: bool
    formulation: str
    doc: str


#: The chapter's formulation (Tables 4.2, 4.3: index-1, Baumgarte alpha = beta = 5), the only one of the
#: methods other than IDA.
CHAPTER_FORMULATION = "index1"
_ODE = CHAPTER_FORMULATION
TABLE: tuple[Method, ...] = (
    Method("ida", "ida", "ida", "IDA", 0, True, defaults.FORMULATION,
           "SUNDIALS IDA on the DAE (any formulation), with root finding and consistent restarts."),
    Method("rk45", "RK45", "scipy", "RK45", 5, False, _ODE, "scipy's explicit Runge-Kutta 5(4)."),
    Method("dop853", "DOP853", "scipy", "DOP853", 8, False, _ODE, "scipy's explicit Runge-Kutta 8(5,3)."),
    Method("radau", "Radau", "scipy", "Radau", 5, True, _ODE,
           "scipy's implicit Radau IIA (order 5), with the generated Jacobian."),
    Method("bdf", "BDF", "scipy", "BDF", -1, True, _ODE,
           "scipy's implicit BDF (orders 1-5), with the generated Jacobian."),
    Method("lsoda", "LSODA", "scipy", "LSODA", -1, True, _ODE,
           "scipy's LSODA (Adams / BDF switching), with the generated Jacobian."),
    Method("rk4", "rk4", "fixed", "RK4", 4, False, _ODE,
           "Classical fixed-step Runge-Kutta (order 4), its step loop in C."),
    Method("euler", "euler", "fixed", "Euler", 1, False, _ODE, "Explicit Euler with a fixed step, its step loop in C."),
)

#: The method names :func:`daeclear.core.options.method` accepts (lower case).
METHODS: tuple[str, ...] = tuple(m.key for m in TABLE)
#: The fixed-step methods (they need ``step``, the others refuse it).
FIXED_STEP: tuple[str, ...] = tuple(m.key for m in TABLE if m.family == "fixed")


def by_key(name: str) -> Method:
    """The row of a method name (case-insensitive); KeyError for another."""
    key = name.lower()
    for m in TABLE:
        if m.key == key:
            return m
    raise KeyError(name)
