"""simulate(): checks every argument once, before any work, then hands the run to the method's solver
(:mod:`daeclear.solvers.registry`, the contract of :mod:`daeclear.solvers.base`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from numpy.typing import ArrayLike

from ..core import options as opts
from ..assembly.assemble import DAEModel, assemble
from ..model.scene import Scene
from ..results.result import Result
from .save_at import SaveAt, save_value
from .solver_options import UNSET, SolverOptions
from .base import Solver
from .registry import solver_class
from .ida import IDA
from .sensitivity_ida import SensitivityIDA
from .sensitivity_quadrature import checked_integrals
from ..assembly.sensitivity import parameter_value, table_entry

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
    sensitivities: Sequence[str] | None = None,
    integrals: Sequence[str] | None = None,
) -> Result:
    """Integrate a scene (or an assembled model) from ``t0`` to ``t_end``.

    Parameters
    ----------
    scene : Scene or DAEModel
        The mechanism; a Scene is assembled with ``options.formulation`` first. No run changes a model.
    t_end : float
        End time, s (> t0).
    t0 : float
        Start time, s (>= 0, < t_end); drivers and loads see the true time.
    y0 : array_like or None
        The full state at ``t0`` (a row of ``result.y`` of the same model); None: ``options.start``.
    method : str or a solver class
        "ida" (default), "RK45", "DOP853", "Radau", "BDF", "LSODA", "rk4" or "euler" (case-insensitive),
        or a :class:`daeclear.solvers.base.Solver` class; overrides ``options.method``.
    rtol : float
        Relative tolerance (1e-6; the chapter's "integration tolerance"); overrides ``options.rtol``.
    atol : float, mapping, array or None
        Absolute tolerance of positions and velocities (:class:`daeclear.SolverOptions`).
    options : SolverOptions or None
        The solver settings (None: the defaults).
    save : SaveAt or None
        The output (:class:`daeclear.SaveAt`; None: every internal step, in memory).
    on_failure : {"raise", "return"}
        On an integrator failure raise :class:`SolveError` (``.result``: the partial result) or
        return the partial result with ``success=False``.
    progress : bool
        Show a progress line on stderr.
    parameters : mapping or None
        New numbers for this run by name (:meth:`DAEModel.with_parameters`); nothing is compiled.
    sensitivities : list of str or None
        Names from ``model.parameter_names``: IDA integrates S = dy/dp with the states, with the jumps at
        every event (:meth:`Result.sensitivity`, docs/sensitivities.md); a streamed output
        (``SaveAt(stream_to=...)``) writes them as the run goes. IDA only; not with ``y0``. None (the
        default): no cost.
    integrals : list of str or None
        Channel names (``model.channel_names``) whose integrals from ``t0`` IDA integrates as states under
        its error control, with their sensitivities (``result.sensitivities.integrals``; ``dc.Integral``
        reads them). With ``sensitivities`` only; saved and streamed with them (docs/sensitivities.md, section 7).

    Returns
    -------
    Result
        ``result.warnings``: the physics checks' findings, each also a :class:`daeclear.PhysicsWarning`.

    Raises
    ------
    SceneError
        A bad argument (naming it, its value and what is allowed), before any work.
    AssemblyError
        The start cannot be assembled, the constraints are redundant, or it is in deep penetration.
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
    if isinstance(scene, DAEModel) and settings.formulation not in (None, scene.formulation):
        opts.fail("simulate", "options.formulation", settings.formulation,
                  f"None or the model's own, {scene.formulation!r}: the formulation is chosen when a Scene is "
                  "assembled (pass the Scene, or assemble(scene, formulation=...))")
    solver = solver_class(settings.method)()
    if parameters is not None:  # new numbers: bound to the structure (checked before any run)
        if not isinstance(parameters, Mapping):
            opts.fail("simulate", "parameters", parameters, "None or a mapping of names to numbers, "
                      "e.g. {'clearance.clearance': 2e-4}")
        if isinstance(scene, Scene):
            scene = assemble(scene, settings.formulation or solver.formulation, track_work=settings.track_work)
        scene = scene.with_parameters(parameters)
    if sensitivities is not None:
        names = checked_sensitivities(sensitivities, solver, y0)
        if not settings.sensitivity_error_test and settings.backend == "python":
            opts.fail("simulate", "options.sensitivity_error_test", False, "True with backend='python': S out of "
                      "IDA's error test needs the compiled session's own Newton test (backend='c' or 'auto')")
        if isinstance(scene, Scene):  # the names are the model's: assembled first
            scene = assemble(scene, settings.formulation or solver.formulation, track_work=settings.track_work)
        parameter_names(scene, names)
        chosen = None
        if integrals is not None:
            chosen = checked_integrals(integrals, scene)
        solver = SensitivityIDA(names, chosen)
    elif integrals is not None:
        opts.fail("simulate", "integrals", integrals, "None without sensitivities: the integrals are states of "
                  "the run with sensitivities (simulate(..., sensitivities=[...], integrals=[...]))")
    result = solver.run(scene, t_end, t0, y0, out, settings, on_failure, progress)
    if not isinstance(result, Result):  # a solver class of the user's: its contract checked where it is used
        opts.fail("simulate", "method", settings.method, "a solver whose run() returns a daeclear.Result "
                  f"(the contract of daeclear.solvers.base.Solver); it returned {type(result).__name__}")
    return result


def checked_sensitivities(value: object, solver: Solver, y0: object) -> list[str]:
    """``simulate``'s ``sensitivities``: a non-empty list of distinct names, for a run that can carry them
    (IDA, from its own start); checked before any work."""
    if isinstance(value, str) or not isinstance(value, Sequence) or not value:
        opts.fail("simulate", "sensitivities", value, "None or a non-empty list of names from "
                  "model.parameter_names, e.g. ['clearance.clearance']")
    names = list(value)
    for name in names:
        if not isinstance(name, str):
            opts.fail("simulate", "sensitivities", value, "a list of names (strings) from model.parameter_names")
    if len(set(names)) != len(names):
        opts.fail("simulate", "sensitivities", value, "a list naming each parameter once")
    if not isinstance(solver, IDA):
        opts.fail("simulate", "sensitivities", value, f"None with method={solver.name!r}: only method='ida' "
                  "carries sensitivities (the stacked [y; S] with the jumps at every event)")
    if y0 is not None:
        opts.fail("simulate", "sensitivities", value, "None when y0 is given: S starts as dy0/dp of the run's "
                  "own start (options.start), and a given state has none")
    return names


def parameter_names(model: DAEModel, names: list[str]) -> None:
    """Each name one of ``model.parameter_names`` (or an element ``"<key>[k]"`` of a vector entry of the parameter
    table, a worn profile's mode) and one finite number (SceneError naming it otherwise)."""
    known = model.parameter_names
    for name in names:
        if name not in known and table_entry(model, name) is None:
            close = opts.close_matches(name, known)
            hint = f"close matches: {', '.join(map(repr, close))}" if close else (
                f"e.g. {', '.join(map(repr, list(known)[:4]))}")
            opts.fail("simulate", "sensitivities", name, f"one of model.parameter_names ({len(known)} names; "
                      f"{hint})")
        parameter_value(model, name)  # one finite number
