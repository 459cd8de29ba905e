"""simulate(): checks every argument once, before any work, then hands the run to the method's solver
(:mod:`daeclear.solvers.registry`, the contract of :mod:`daeclear.solvers.base`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from numpy.typing import ArrayLike

from .. import options as opts
from ..assembly.assemble import DAEModel, assemble
from ..model.scene import Scene
from ..results.result import Result
from ..save_at import SaveAt, save_value
from ..solver_options import UNSET, SolverOptions
from .base import Solver
from .registry import solver_class

DEFAULTS = SolverOptions()


def simulate(
    scene: Scene | DAEModel,
    t_end: float,
    *,
    t0: float = 0.0,
    y0: ArrayLike | None = None,
    method: str | type[Solver] = UNSET,
    rtol: float = UNSET,
    atol: float | Mapping[str, float] | ArrayLike | None = UNSET,
    options: SolverOptions | None = None,
    save: SaveAt | None = None,
    on_failure: str = "raise",
    progress: bool = False,
    parameters: Mapping[str, Any] | None = None,
) -> Result:
    """Integrate a scene (or an assembled model) from ``t0`` to ``t_end``.

    ``method``, ``rtol`` and ``atol`` override the same settings of ``options`` (every other solver
    setting is a field of :class:`daeclear.SolverOptions`); what the run reports is ``save``.

    Parameters
    ----------
    scene : Scene or DAEModel
        The mechanism; a Scene is assembled with ``options.formulation`` first. No run changes a
        model: runs of one model (also in threads) are independent.
    t_end : float
        End time, s (> t0).
    t0 : float
        Start time, s (>= 0, < t_end); drivers and loads see the true time.
    y0 : array_like or None
        The full state at ``t0`` (a row of ``result.y`` of the same model): positions and velocities
        kept (GGL: projected), multipliers and accelerations recomputed, contact modes set from the
        gaps. None: the start of ``options.start``. A run's history (storm guard, BDF) starts afresh.
    method : str or a solver class
        "ida" (default), "RK45", "DOP853", "Radau", "BDF", "LSODA", "rk4" or "euler" (case-insensitive),
        or a class implementing :class:`daeclear.solvers.base.Solver`. All but "ida" integrate the
        index-1 model as an ODE in (q, v) (:mod:`daeclear.solvers.explicit`); "rk4", "euler" need ``step``.
    rtol : float
        Relative tolerance (1e-6; the chapter's "integration tolerance").
    atol : float, mapping, array or None
        Absolute tolerance of positions and velocities (:class:`daeclear.SolverOptions`; None: from the
        mechanism's scales, :mod:`daeclear.solvers.tolerances`).
    options : SolverOptions or None
        The solver settings (None: the defaults).
    save : SaveAt or None
        The output (:class:`daeclear.SaveAt`; None: every internal step, in memory).
    on_failure : {"raise", "return"}
        On an integrator failure raise :class:`SolveError` (``.result`` holds the partial result) or
        return the partial result with ``success=False``.
    progress : bool
        Show a progress line on stderr.
    parameters : mapping or None
        New numbers for this run by name, as :meth:`DAEModel.with_parameters` (e.g.
        ``{"clearance.clearance": 2e-4}``); nothing is compiled, the model is unchanged.

    Returns
    -------
    Result
        ``result.warnings`` lists the physics checks' findings (:mod:`daeclear.solvers.physics`), each
        also issued as a :class:`daeclear.PhysicsWarning`.

    Raises
    ------
    SceneError
        A bad argument (naming it, its value and what is allowed), before any work.
    AssemblyError
        The initial positions cannot be assembled, the constraints are redundant, or a declared
        start is in deep penetration.
    """
    if not isinstance(scene, (Scene, DAEModel)):  # e.g. a mechanism's name: say what is wanted
        opts.fail("simulate", "scene", scene, "a daeclear.Scene or an assembled model, e.g. "
                  "dc.mechanisms.slider_crank('revolute') (a mechanism's name is not a scene)")
    if options is not None and not isinstance(options, SolverOptions):
        opts.fail("simulate", "options", options, "None or a daeclear.SolverOptions")
    settings = (DEFAULTS if options is None else options).merged(method=method, rtol=rtol, atol=atol)
    t_end = opts.t_end(t_end)
    t0 = opts.t0(t0, t_end)
    on_failure = opts.on_failure(on_failure)
    progress = opts.flag(progress, field="progress")
    opts.step_within(settings.step, t0, t_end)
    out = save_value(save).plan(t0, t_end)
    if y0 is not None:  # checked before any work (a Scene's length: once it is assembled)
        y0 = opts.state(y0, scene.n_states if isinstance(scene, DAEModel) else None)
    solver = solver_class(settings.method)()
    if parameters is not None:  # new numbers: bound to the structure (checked before any run)
        if not isinstance(parameters, Mapping):
            opts.fail("simulate", "parameters", parameters, "None or a mapping of names to numbers, "
                      "e.g. {'clearance.clearance': 2e-4}")
        if isinstance(scene, Scene):
            scene = assemble(scene, settings.formulation or solver.formulation, track_work=settings.track_work)
        scene = scene.with_parameters(parameters)
    return solver.run(scene, t_end, t0, y0, out, settings, on_failure, progress)
