"""SolverOptions: the settings that decide what a run computes, as one checked, immutable value (what a
call reports and does on failure are not settings: they never change the computed trajectory).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core import defaults, options
from ..core.options import fail

WHERE = "SolverOptions"


class _Unset:
    """The default of a keyword of :func:`daeclear.simulate` that the caller did not give."""

    def __repr__(self) -> str:
        return "UNSET"

    def __bool__(self) -> bool:
        return False


#: Marks a keyword not given (so that ``options`` supplies it): see :meth:`SolverOptions.merged`.
UNSET: Any = _Unset()


@dataclass(frozen=True)
class SolverOptions:
    """The solver settings of a run: ``options=`` of :func:`daeclear.simulate`.

    Checked on construction (:class:`daeclear.SceneError` naming the field, the value and what is
    allowed), names normalised (``"RK45"`` as ``"rk45"``); immutable: derive variants with :meth:`replace`.

    Parameters
    ----------
    method : str or a solver class
        "ida", "RK45", "DOP853", "Radau", "BDF", "LSODA", "rk4" or "euler" (case-insensitive), or a
        class implementing :class:`daeclear.solvers.base.Solver`, or such a class's import path
        ``"module:Class"`` (how :meth:`to_dict` stores a class).
    rtol : float
        Relative tolerance (the chapter's "integration tolerance"), in [1e-14, 1e-2].
    atol : float, mapping, array or None
        Absolute tolerance of positions and velocities: None (from the mechanism's scales, docs/engine.md),
        a number, a mapping by quantity (``{"q": 1e-9, "v": 1e-6}``, ``"position"``, ``"angle"``,
        ``"velocity"``, ``"angular_velocity"``) or an array (``2 n_q`` values or one per state).
    formulation : {"ggl", "index1"} or None
        Used when a Scene is run. None: the solver's own ("ggl" for IDA, "index1" for the others).
    backend : {"auto", "c", "python"}
        "c": generated C and the IDA loop in C; "python": scikit-sundae; "auto": C when a compiler works.
    max_step : float
        Largest step, s (0: unbounded); IDA and the scipy methods.
    max_steps : int
        Cap on the total number of steps; the run fails cleanly beyond it.
    step : float or None
        Step size, s, of "rk4" and "euler" (required there); refused by the others.
    linear_solver : {"auto", "reduced", "dense", "sparse", "superlu"}
        LU of IDA's Newton iteration in the compiled backend (docs/engine.md): "sparse" is the sparse LU
        planned when the model's C is generated, "superlu" SUNDIALS' SuperLU_MT; "auto": sparse from
        ``daeclear.engine.c_session.SPARSE_MIN_STATES`` states on, "reduced" below.
    start : {"ideal", "declared"}
        The start without ``y0``: "ideal" (the chapter's, clearance joints centred) or "declared".
    allow_penetration : bool
        Start even deeper in a wall than the physics checks allow (:mod:`daeclear.assembly.physics`).
    track_work : bool
        IDA only: integrate the work of drivers and contact forces (channel ``energy.work``).
    sensitivity_error_test : bool
        A run with sensitivities (``simulate(..., sensitivities=...)``): True holds S in IDA's error test,
        each parameter's columns scaled by its magnitude; False leaves S out of the error test and in the
        Newton convergence test only (IDAS' errconS = False; the compiled backend: docs/sensitivities.md,
        section 2): fewer steps, S only as accurate as the states' steps make it.
    quadrature_atol : float or None
        A run with integrals (``simulate(..., integrals=[...])``, ``dc.Integral``): the absolute tolerance
        of each integral Q, in the channel's unit times s (an integral below it in magnitude is held to
        this absolute error, above it to rtol relative); dQ/dp's is it over |p|. None: 1e-3 rtol.
    """

    method: str = "ida"
    rtol: float = defaults.RTOL
    atol: float | tuple[float, ...] | tuple[tuple[str, float], ...] | None = None
    formulation: str | None = None
    backend: str = "auto"
    max_step: float = 0.0
    max_steps: int = defaults.MAX_STEPS
    step: float | None = None
    linear_solver: str = "auto"
    start: str = "ideal"
    allow_penetration: bool = False
    track_work: bool = False
    sensitivity_error_test: bool = True
    quadrature_atol: float | None = None
    #: who the settings were given to, for the messages (not stored): "simulate" for its keywords
    where: dataclasses.InitVar[str] = WHERE

    def __post_init__(self, where: str = WHERE) -> None:
        values = checked({f.name: getattr(self, f.name) for f in dataclasses.fields(self)}, where=where)
        for name, value in values.items():
            object.__setattr__(self, name, value)
        from .registry import solver_class

        solver_class(self.method)().check(self)  # what the method takes: its solver's rule

    def replace(self, **changes: Any) -> SolverOptions:
        """A copy with ``changes`` (checked as on construction); unknown names are an error."""
        _check_names(changes, "replace")
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Every setting as JSON types (``atol`` a float, a list, a mapping or None): :meth:`from_dict`
        inverts it."""
        from .registry import method_path
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["method"] = method_path(self.method)  # a class as its import path "module:Class"
        out["atol"] = self.atol_value()
        if isinstance(out["atol"], np.ndarray):
            out["atol"] = out["atol"].tolist()
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> SolverOptions:
        """Options from :meth:`to_dict`'s form (missing settings take their defaults)."""
        if not isinstance(data, Mapping):
            fail(WHERE, "from_dict", data, "a mapping of setting names to values")
        _check_names(data, "from_dict")
        values = dict(data)
        if isinstance(values.get("atol"), list):
            values["atol"] = tuple(values["atol"])
        return cls(**values)

    def merged(self, *, where: str = "simulate", **keywords: Any) -> SolverOptions:
        """These options with every keyword that is not :data:`UNSET` put in its place (a bad one
        reported as given to ``where``): a keyword given to :func:`daeclear.simulate` overrides them."""
        given = {k: v for k, v in keywords.items() if v is not UNSET}
        if not given:
            return self
        _check_names(given, "merged")
        return dataclasses.replace(self, where=where, **given)  # checked once, by __post_init__

    def atol_value(self) -> float | np.ndarray | dict[str, float] | None:
        """``atol`` as the solvers take it (one value, a mapping by quantity, an array per state, or None)."""
        if isinstance(self.atol, tuple):
            return dict(self.atol) if self.atol and isinstance(self.atol[0], tuple) else np.array(self.atol)
        return self.atol


def checked(values: Mapping[str, Any], *, where: str) -> dict[str, Any]:
    """Every field of SolverOptions in ``values`` checked and normalised (:mod:`daeclear.core.options`);
    errors name ``where``."""
    from .registry import method as method_rule

    method = method_rule(values["method"], where=where)
    raw = values["atol"]
    pairs = isinstance(raw, tuple) and bool(raw) and isinstance(raw[0], tuple)  # a mapping as stored
    atol = options.atol(dict(raw) if pairs else raw, where=where)
    return {
        "method": method,
        "rtol": options.rtol(values["rtol"], where=where),
        "atol": (atol if atol is None or isinstance(atol, float) else tuple(sorted(atol.items()))
                 if isinstance(atol, dict) else tuple(float(x) for x in atol)),
        "formulation": (None if values["formulation"] is None
                        else options.formulation(values["formulation"], where=where)),
        "backend": options.backend(values["backend"], where=where),
        "max_step": options.max_step(values["max_step"], where=where),
        "max_steps": options.max_steps(values["max_steps"], where=where),
        "step": None if values["step"] is None else options.step(values["step"], where=where),
        "linear_solver": options.linear_solver(values["linear_solver"], where=where),
        "start": options.start(values["start"], where=where),
        "allow_penetration": options.flag(values["allow_penetration"], where=where, field="allow_penetration"),
        "track_work": options.flag(values["track_work"], where=where, field="track_work"),
        "sensitivity_error_test": options.flag(values["sensitivity_error_test"], where=where,
                                               field="sensitivity_error_test"),
        "quadrature_atol": _quadrature_atol(values["quadrature_atol"], where),
    }


def _quadrature_atol(value: Any, where: str) -> float | None:
    """None, or a finite number > 0: the integrals' absolute tolerance (the channel's unit times s)."""
    if value is None:
        return None
    if not (options.is_real(value) and np.isfinite(float(value)) and float(value) > 0.0):
        fail(where, "quadrature_atol", value, "None or a finite number > 0 (the integrals' absolute tolerance, in "
             "the channel's unit times s)")
    return float(value)


def _check_names(values: Mapping[str, Any], where: str) -> None:
    known = [f.name for f in dataclasses.fields(SolverOptions)]
    for name in values:
        if name not in known:
            hint = options.close_matches(str(name), known)
            fail(f"{WHERE}.{where}", str(name), values[name],
                 "left out: not a solver setting" + (f" (did you mean {', '.join(hint)}?)" if hint else "")
                 + f"; the settings are {', '.join(known)}", shown="...")
