"""SolverOptions: the settings that decide what a run computes, as one checked, immutable value.

:func:`daeclear.simulate`, the studies (:func:`daeclear.studies.accuracy.work_precision`, the
stability suite) and sweeps take the same settings; an options object carries them from one to
the other, is checked once on construction (by the one rule per option of :mod:`daeclear.options`)
and round-trips through a plain dict (``to_dict``/``from_dict``: JSON types only, for files).

What belongs: every setting that decides the model assembled and the trajectory computed (method,
tolerances, formulation, backend, step bounds, linear solver, how the run starts, the work state).
What does not: what a call reports and where it goes (``t_eval``, ``t_eval_step``, ``store_steps``,
``stream_to``, ``keep_data``, ``progress``) and what it does on failure (``on_failure``): a study
or a sweep sets those per call, and they never change the computed trajectory.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import options
from .options import fail

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
    """The solver settings of a run (see :func:`daeclear.simulate` for each one's meaning).

    Checked on construction: a bad value raises :class:`daeclear.SceneError` naming the field,
    the value and what is allowed. Names are normalised (``method="RK45"`` is stored as
    ``"rk45"``), ``atol`` as a float, a tuple of floats or a tuple of (quantity, value) pairs
    (a mapping by quantity). Immutable: derive variants with
    :meth:`replace`. Combinations that depend on the model (a GGL model with a non-IDA method,
    ``track_work`` with a non-IDA method) are checked by ``simulate`` before any work.
    """

    method: str = "ida"
    rtol: float = 1e-6
    atol: float | tuple[float, ...] | tuple[tuple[str, float], ...] | None = None
    formulation: str | None = None
    backend: str = "auto"
    max_step: float = 0.0
    max_steps: int = 5_000_000
    step: float | None = None
    linear_solver: str = "auto"
    start: str = "ideal"
    allow_penetration: bool = False
    track_work: bool = False

    def __post_init__(self) -> None:
        values = checked({f.name: getattr(self, f.name) for f in dataclasses.fields(self)}, where=WHERE)
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def replace(self, **changes: Any) -> SolverOptions:
        """A copy with ``changes`` (checked as on construction); unknown names are an error."""
        _check_names(changes, "replace")
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Every setting as JSON types (``atol`` a float, a list, a mapping or None): :meth:`from_dict`
        inverts it."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
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
        """These options with every keyword that is not :data:`UNSET` put in its place; a bad
        keyword is reported as given to ``where`` (``simulate: rtol=2.0, must be ...``).

        The rule of :func:`daeclear.simulate`: a keyword given explicitly overrides the options object."""
        given = {k: v for k, v in keywords.items() if v is not UNSET}
        if not given:
            return self
        _check_names(given, "merged")
        return dataclasses.replace(self, **checked({**self.to_dict(), **given}, where=where))

    def atol_value(self) -> float | np.ndarray | dict[str, float] | None:
        """``atol`` as the solvers take it (one value, a mapping by quantity, an array per state, or None)."""
        if isinstance(self.atol, tuple):
            return dict(self.atol) if self.atol and isinstance(self.atol[0], tuple) else np.array(self.atol)
        return self.atol


def checked(values: Mapping[str, Any], *, where: str) -> dict[str, Any]:
    """Every setting of ``values`` (all of SolverOptions' fields) checked and normalised by the rules
    of :mod:`daeclear.options`; errors name ``where``."""
    from .solvers.explicit import check_step  # the fixed-step rule, defined once

    method = options.method(values["method"], where=where)
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
        "step": check_step(method, values["step"]),
        "linear_solver": options.linear_solver(values["linear_solver"], where=where),
        "start": options.start(values["start"], where=where),
        "allow_penetration": options.flag(values["allow_penetration"], where=where, field="allow_penetration"),
        "track_work": options.flag(values["track_work"], where=where, field="track_work"),
    }


def _check_names(values: Mapping[str, Any], where: str) -> None:
    known = [f.name for f in dataclasses.fields(SolverOptions)]
    for name in values:
        if name not in known:
            hint = options.close_matches(str(name), known)
            fail(f"{WHERE}.{where}", str(name), values[name],
                 "left out: not a solver setting" + (f" (did you mean {', '.join(hint)}?)" if hint else "")
                 + f"; the settings are {', '.join(known)}", shown="...")
