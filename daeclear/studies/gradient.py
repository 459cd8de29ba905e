"""``dc.gradient``: the gradient of a scalar of the response w.r.t. named parameters (docs/sensitivities.md).

The objective (:mod:`daeclear.results.objectives`: Final, Integral, Peak, EventTime) is evaluated on a run with
forward sensitivities, the jumps at every event included: ``simulate(..., sensitivities=...)``'s result, with
each event's rows before and after its switch (:class:`daeclear.results.sensitivities.RunTrajectory`); IDA
on the stacked [y; S], for small models and short spans. ``method="fd"`` is the cross-check: central
differences of the objective over separate runs, one step per parameter.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..assembly.assemble import DAEModel, assemble
from ..assembly.sensitivity import moved_parameter, parameter_value
from ..core import options
from ..core.errors import SolveError
from ..model.scene import Scene
from ..results.objectives import EventTime, Final, Gradient, Integral, Objective, Peak
from ..results.result import Result
from ..solvers.dispatch import simulate
from ..solvers.save_at import SaveAt
from ..solvers.solver_options import SolverOptions

__all__ = ["gradient", "METHODS", "DEFAULT_SAMPLES"]

#: ``sensitivities``: from S = dy/dp; ``fd``: central differences of separate runs (the cross-check).
METHODS: tuple[str, ...] = ("sensitivities", "fd")
#: Output intervals over the run for an Integral or a Peak (the quadrature's and the peak's rows).
DEFAULT_SAMPLES = 2000


def gradient(scene_or_model: Scene | DAEModel, t_end: float, *, of: Objective, parameters: Sequence[str],
             method: str = "sensitivities", rtol: float = 1e-8, atol: Any = None, start: str = "ideal",
             formulation: str | None = None, samples: int = DEFAULT_SAMPLES, backend: str = "auto",
             quadrature_atol: float | None = None) -> Gradient:
    """The value of the objective ``of`` over a run to ``t_end`` and its gradient {name: d value/d name} w.r.t.
    ``parameters`` (names of ``model.parameter_names``).

    ``samples``: output intervals for an Integral or a Peak (trapezoidal rule, parabolic peak: errors
    O(1/samples^2)); ``rtol``, ``atol``, ``start``, ``formulation``, ``backend`` as ``simulate``'s;
    ``quadrature_atol``: an Integral's absolute tolerance (``SolverOptions.quadrature_atol``). ``method="fd"``:
    central differences with the step rtol^(1/3) |p| (|p| = 1 at 0), 2 Ns + 1 runs. A run that fails raises
    :class:`~daeclear.core.errors.SolveError`."""
    where = "gradient"
    settings = SolverOptions(rtol=1e-8, atol=atol, start=start, backend=backend, quadrature_atol=quadrature_atol,
                             where=where)  # checked before any work (rtol: below)
    if not isinstance(of, (Final, Integral, Peak, EventTime)):
        options.fail(where, "of", of, "an objective: dc.Final, dc.Integral, dc.Peak or dc.EventTime")
    end = options.t_end(t_end, where=where)
    tol = options.rtol(rtol, where=where)
    chosen = options.choice(method, METHODS, where=where, field="method")
    count = options.integer(samples, where=where, field="samples", low=2)
    if isinstance(scene_or_model, Scene):
        model = assemble(scene_or_model) if formulation is None else assemble(scene_or_model, formulation)
    elif isinstance(scene_or_model, DAEModel):
        model = scene_or_model
        if formulation is not None and formulation != model.formulation:
            options.fail(where, "formulation", formulation, f"None or the model's own ({model.formulation!r}); "
                         "assemble the model with the formulation you want")
    else:
        options.fail(where, "scene_or_model", scene_or_model, "a Scene or an assembled DAEModel")
    if isinstance(parameters, str) or not isinstance(parameters, Sequence) or not parameters:
        options.fail(where, "parameters", parameters, "a non-empty list of names from model.parameter_names, "
                     "e.g. ['clearance.clearance']")
    names = list(parameters)
    values = {name: parameter_value(model, name) for name in names}  # checks each name before any run
    times = _output_times(of, end, count)

    settings = settings.replace(rtol=tol)
    save = SaveAt(times=times, steps=False)

    integrals = [of.channel] if isinstance(of, Integral) else None  # a quadrature state under error control

    def run(m: DAEModel, wanted: Sequence[str]) -> Result:
        out = simulate(m, end, options=settings, save=save, sensitivities=wanted, integrals=integrals,
                       on_failure="return")
        if not out.success:
            raise SolveError(f"gradient: the run failed at t={out.t[-1] if out.t.size else 0.0:.6g} s "
                             f"({out.message}).", out)
        return out

    if chosen == "sensitivities":
        return run(model, names).gradient(of)
    base = run(model, names[:1]).gradient(of).value
    grad: dict[str, float] = {}
    for name, p in values.items():
        h = tol ** (1.0 / 3.0) * (abs(p) or 1.0)
        plus, minus = (run(moved_parameter(model, name, p + s * h), names[:1]).gradient(of).value for s in (1, -1))
        grad[name] = (plus - minus) / (2.0 * h)
    return Gradient(of, base, grad, "fd")


def _output_times(of: Objective, end: float, samples: int) -> NDArray[np.float64]:
    """The start and the end; for an Integral or a Peak ``samples`` intervals and the window's ends."""
    if isinstance(of, (Final, EventTime)):
        return np.array([0.0, end])
    times = np.linspace(0.0, end, samples + 1)
    if of.window is not None:
        t0, t1 = of.window
        if not (0.0 <= t0 and t1 <= end):
            options.fail(type(of).__name__, "window", of.window, f"inside the run [0, {end:g}] s")
        times = np.union1d(times, [t0, t1])
    return times
