"""simulate(): a scene or model, the run's span and start, the solver settings and the output ->
a Result. Checks every argument once, before any work, then hands the run to the method's solver
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
    """Integrate a scene (or an assembled model) from ``t0`` (0 by default) to ``t_end``.

    ``method``, ``rtol`` and ``atol`` are the settings most often changed; every other solver setting
    (formulation, backend, max_step, max_steps, step, track_work, linear_solver, start,
    allow_penetration) is a field of ``options``, and a keyword given explicitly overrides the same
    setting of ``options``: ``simulate(m, T, options=o, rtol=1e-8)`` is
    ``simulate(m, T, options=o.replace(rtol=1e-8))``. What the run reports and where it goes is ``save``.

    Parameters
    ----------
    scene : Scene or DAEModel
        The mechanism; a Scene is assembled with ``options.formulation`` first. A model is a value that
        no run changes (a run's contact state is its own, :mod:`daeclear.assembly.contact_state`): runs
        of one model, one after the other or at the same time in threads, are independent.
    t_end : float
        End time, s (> t0).
    t0 : float
        Start time, s (finite, >= 0, < t_end). Drivers and time-dependent loads are evaluated at
        the true time: a run from t0 continues a run that reached t0.
    y0 : array_like or None
        The full state at ``t0`` (a row of ``result.y`` of a run of the same model, ``model.n_states``
        values): positions and velocities are kept as given (GGL: projected onto the constraint
        manifold, as at every restart), multipliers and accelerations recomputed, the contact
        modes set from the gaps at ``t0`` (a pair starting in contact latches its penetration
        rate there). None: the start of ``options.start``. Restarting from the last state of a run
        continues it to the integration tolerance; a run's history (contact storm guard, BDF
        history) starts afresh.
    method : str or a solver class
        "ida" (default), "RK45", "DOP853", "Radau", "BDF", "LSODA", "rk4" or "euler" (case-insensitive;
        :data:`daeclear.solvers.registry.SOLVERS`), or a class implementing
        :class:`daeclear.solvers.base.Solver`. "ida": SUNDIALS IDA on the DAE. The others integrate
        the same model as an ODE in (q, v) (index-1 formulation only) with the same contact events
        (:mod:`daeclear.solvers.explicit`); "rk4" and "euler" need ``options.step``.
    rtol : float
        Relative tolerance (1e-6; the chapter's "integration tolerance").
    atol : float, mapping, array or None
        Absolute tolerance of positions and velocities (see :class:`daeclear.SolverOptions`). None
        (the default): per quantity from the mechanism's scales (:mod:`daeclear.solvers.tolerances`).
    options : SolverOptions or None
        The solver settings as one checked value (None: the defaults).
    save : SaveAt or None
        The output: times or a grid, the steps kept or not, a file streamed to, the cap on points
        (:class:`daeclear.SaveAt`; None: every internal step, in memory).
    on_failure : {"raise", "return"}
        On an integrator failure raise :class:`SolveError` (its ``.result`` holds the
        partial result) or return the partial result with ``success=False``.
    progress : bool
        Show a progress line on stderr.
    parameters : mapping or None
        New numbers for this run, by name, as :meth:`DAEModel.with_parameters` (e.g.
        ``{"clearance.clearance": 2e-4, "clearance.law.restitution": 0.5}``): the scene is assembled
        (a model is taken as it is) and run with them; nothing is compiled, the model is unchanged.

    Returns
    -------
    Result
        ``result.warnings`` lists what the physics checks found (penetration beyond the
        clearance, an impossible start, constraint drift, contacts stepped over by a fixed step);
        each is also issued as a :class:`daeclear.PhysicsWarning`. See :mod:`daeclear.solvers.physics`.

    Raises
    ------
    SceneError
        A bad argument (naming it, its value and what is allowed), before any work.
    AssemblyError
        The initial positions cannot be assembled, the constraints are redundant (the
        message names the joints and drivers), or a declared start is in deep penetration.
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
