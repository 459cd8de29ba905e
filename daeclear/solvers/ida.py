"""simulate(): IDA with root finding, contact-mode switches and consistent restarts.

The solver knows nothing of slider-cranks: it integrates a :class:`DAEModel` segment
by segment. Between two roots of the gap functions the set of active contact terms
is fixed; at a root each contact element's event logic decides the new modes (and
latches the approach speed), the multipliers and derivatives are made consistent
again, and IDA restarts with fresh BDF history. This module checks the options and sets the
run up; the segment loop itself is :class:`daeclear.solvers.ida_loop.SegmentLoop`.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping
from typing import Any

from numpy.typing import ArrayLike, NDArray

from .. import options as opts
from . import physics
from ..assembly.assemble import DAEModel, assemble
from ..engine.ida_session import open_session
from .ida_loop import SegmentLoop
from .recorder import Recorder
from .tolerances import atol_record, tolerance_vector
from ..results.result import Result
from ..model.scene import Scene
from ..solver_options import UNSET, SolverOptions

DEFAULTS = SolverOptions()

log = logging.getLogger("daeclear")

METHODS: tuple[str, ...] = opts.METHODS
ON_FAILURE: tuple[str, ...] = opts.ON_FAILURE
# Constraint drift (largest |Phi| of a run) above this fraction of the smallest clearance is warned of.
DRIFT_FRACTION = physics.DRIFT_FRACTION
# GGL holds Phi = 0 only as tightly as IDA's Newton test (safety factor 0.33 by default). 1e-3
# keeps the pendulum's constraint residual at 1e-12 instead of 3e-11 (rtol 1e-10) and, measured,
# halves the steps; index1 is better off with IDA's default. The python backend cannot set it.
GGL_NEWTON_COEF = 1e-3
# IDA evaluates a new Jacobian when cj (alpha / h) has changed by this fraction (IDA's default 0.25).
# Contact runs change h often: with 0.25 a stale iteration matrix costs the GGL runs 2.2 Newton
# iterations per step and a convergence failure every 25 steps; with 0.05, measured on the Fig. 4.15
# scene, 1.3 iterations and none, 20-25 % less CPU for both formulations (docs/engine.md).
JACOBIAN_REFRESH = 0.05
IDA_JACOBIAN_REFRESH = 0.25  # IDA's own, what the python backend (scikit-sundae) runs with
# The first step of a GGL run: True takes the second-order estimate of the compiled driver
# (first_step in ida_driver.c) over IDA's first-order one, which is 1e-16 s on the chapter's scenes
# and lets GGL's Newton iteration fail there at rtol 1e-9 with the fresher Jacobians above. index1
# keeps IDA's: the longer first step put its first onset 7e-3 (relative) late at c = 0.01 mm and
# rtol 1e-6 (Baumgarte drift over a step that long; with IDA's first step 8e-7, docs/engine.md).
FIRST_STEP_ESTIMATE = True
# Stall guard: STALL_COUNT steps shorter than STALL_STEP seconds that do not grow (and no step a
# hundred times longer in between) end the run with a clear message instead of creeping on
# (e.g. plain Coulomb friction chattering at zero sliding speed takes ~1e-12 s order-1 steps).
# Contact steps of the chapter's runs are 1e-9..1e-6 s; restarts' start-up steps grow and do not count.
# The threshold is absolute: it used to be 1e-10 * t_end, which at t_end = 100 s (1e-8 s) called
# ordinary contact steps a stall. 2.4e-12 s is what it was for the chapter's 0.024 s runs.
STALL_STEP = 2.4e-12
STALL_COUNT = 2000


def simulate(
    scene: Scene | DAEModel,
    t_end: float,
    *,
    options: SolverOptions | None = None,
    t0: float = 0.0,
    y0: ArrayLike | None = None,
    t_eval: ArrayLike | None = None,
    t_eval_step: float | None = None,
    rtol: float = UNSET,
    atol: float | Mapping[str, float] | ArrayLike | None = UNSET,
    method: str = UNSET,
    formulation: str | None = UNSET,
    backend: str = UNSET,
    max_step: float = UNSET,
    max_steps: int = UNSET,
    store_steps: bool = True,
    on_failure: str = "raise",
    progress: bool = False,
    step: float | None = UNSET,
    track_work: bool = UNSET,
    linear_solver: str = UNSET,
    start: str = UNSET,
    allow_penetration: bool = UNSET,
    stream_to: str | os.PathLike[str] | None = None,
    keep_data: bool = True,
    max_output_points: int | None = opts.MAX_OUTPUT_POINTS,
    parameters: Mapping[str, Any] | None = None,
) -> Result:
    """Integrate a scene (or an assembled model) from ``t0`` (0 by default) to ``t_end``.

    The solver settings (``method`` ... ``allow_penetration``, the fields of
    :class:`daeclear.SolverOptions`) come from ``options`` when given, and a keyword given
    explicitly overrides the same setting of ``options``: ``simulate(m, T, options=o, rtol=1e-8)``
    is ``simulate(m, T, options=o.replace(rtol=1e-8))``. The defaults below are SolverOptions'.

    Parameters
    ----------
    scene : Scene or DAEModel
        The mechanism; a Scene is assembled with ``formulation`` first. A model is a value that no
        run changes (a run's contact state is its own, :mod:`daeclear.assembly.contact_state`): runs of
        one model, one after the other or at the same time in threads, are independent.
    t_end : float
        End time, s (> t0).
    options : SolverOptions or None
        The solver settings as one checked value (None: the defaults).
    t0 : float
        Start time, s (finite, >= 0, < t_end). Drivers and time-dependent loads are evaluated at
        the true time: a run from t0 continues a run that reached t0.
    y0 : array_like or None
        The full state at ``t0`` (a row of ``result.y`` of a run of the same model, ``model.n_states``
        values): positions and velocities are kept as given (GGL: projected onto the constraint
        manifold, as at every restart), multipliers and accelerations recomputed, the contact
        modes set from the gaps at ``t0`` (a pair starting in contact latches its penetration
        rate there). None: the start of ``start``. Restarting from the last state of a run
        continues it to the integration tolerance; a run's history (contact storm guard, BDF
        history) starts afresh.
    t_eval : array_like or None
        Output times in [t0, t_end] (increasing). None: every internal IDA step.
    t_eval_step : float or None
        Output times every ``t_eval_step`` seconds from t0 to t_end (both included; the spacing is
        ``(t_end - t0) / floor((t_end - t0) / t_eval_step)``), made window by window as the run goes
        (a long run never holds the whole grid). Give this or ``t_eval``, not both.
    rtol : float
        Relative tolerance (1e-6; the chapter's "integration tolerance").
    atol : float, mapping, array or None
        Absolute tolerance of positions and velocities. None: per quantity from the mechanism's
        scales (:mod:`daeclear.solvers.tolerances`; on the chapter's slider-crank ``1e-3 * rtol``
        in m, rad and m/s, ``5e-3 * rtol`` in rad/s). A number: every position and velocity. A
        mapping by quantity, e.g. ``{"q": 1e-9, "v": 1e-6}`` or ``{"position": ..., "angle": ...,
        "velocity": ..., "angular_velocity": ...}`` (the others keep their defaults). An array:
        ``2 n_q`` values (positions, then velocities) or one per state. Values below the
        round-off of their quantity are raised to it, with a warning. Multipliers are always kept
        out of the error test.
    method : {"ida", "RK45", "DOP853", "Radau", "BDF", "LSODA", "rk4", "euler"}
        Integrator (case-insensitive). "ida": SUNDIALS IDA on the DAE. The others integrate the
        same model as an ODE in (q, v) (index-1 formulation only) with the same contact events
        (see :mod:`daeclear.solvers.explicit`): scipy's explicit RK45/DOP853 and implicit
        Radau/BDF/LSODA, fixed-step classical Runge-Kutta "rk4" and explicit "euler".
    formulation : {"ggl", "index1"} or None
        Used when ``scene`` is a Scene. None: "ggl" (stabilised index 2, drift-free) for IDA,
        "index1" (the chapter's, Baumgarte alpha = beta = 5) for the other methods, which
        integrate that one only (:func:`daeclear.options.default_formulation`).
    backend : {"auto", "c", "python"}
        "c": generated C and an IDA loop in C (fast); "python": scikit-sundae with CasADi
        callbacks; "auto": C when a compiler works, else python with a warning.
    max_step : float
        Largest step, s (0: unbounded); IDA and the scipy methods.
    max_steps : int
        Cap on the total number of steps; the run fails cleanly beyond it.
    store_steps : bool
        Keep every internal step's time, size and order (``result.step_t``...). Without ``t_eval``
        the steps are also the output points; False then reports the start point only. With
        ``t_eval``/``t_eval_step``, False keeps the run's memory from growing with its length.
    on_failure : {"raise", "return"}
        On an integrator failure raise :class:`SolveError` (its ``.result`` holds the
        partial result) or return the partial result with ``success=False``.
    progress : bool
        Show a progress line on stderr.
    track_work : bool
        Used when ``scene`` is a Scene: integrate the work of drivers and contact forces as the
        state ``work.input`` (channel ``energy.work``), see :func:`daeclear.assemble`.
    step : float or None
        Step size, s, of the fixed-step methods "rk4" and "euler" (required there, e.g. the
        chapter's 1e-5); rejected by the other methods.
    linear_solver : {"auto", "reduced", "dense", "sparse"}
        LU of IDA's Newton iteration in the compiled backend: "reduced" (dense LU of the system
        left after eliminating the position rows, 23 unknowns instead of 32 on the slider-crank),
        "dense" (dense LU of the whole system, what the python backend does), "sparse"
        (SuperLU_MT), or "auto" (sparse for large models, see
        :data:`daeclear.engine.ida_session.SPARSE_MIN_STATES`, reduced below).
        The python backend and the other methods ignore it. Reported in ``result.stats``.
    start : {"ideal", "declared"}
        How the run starts without ``y0`` (ignored with ``y0``).
        "ideal" (the chapter's, section 4.4): every clearance joint centred
        and every position and velocity assembled on the mechanism whose clearance joints are
        ideal, from the declared state as a guess; "declared": the bodies' declared positions and
        velocities, corrected only for the scene's ideal joints.
    allow_penetration : bool
        Start "declared" even with a contact pair deeper in its wall than
        :data:`daeclear.solvers.physics.START_PENETRATION_FRACTION` of the clearance, or from a ``y0``
        deeper than :data:`~daeclear.solvers.physics.GIVEN_PENETRATION_FRACTION` clearances (refused otherwise).

    stream_to : str, path or None
        Write the result to this HDF5 file while the run goes on (the layout of
        :meth:`Result.save`, docs/hdf5_layout.md), chunk by chunk, and drop each chunk from memory.
        The file is checked before any work and holds what was computed whatever stops the run:
        a failure, an exception, Ctrl-C, running out of memory (its root ``message`` says why).
    keep_data : bool
        With ``stream_to``: return the result read back from the file (True, as
        ``daeclear.load(stream_to)``), or (False) a Result of the outcome alone (success, message,
        statistics, warnings; no time series, events or segments), so that not even the end of a
        long run holds its data in memory.
    max_output_points : int or None
        The most output points the run may report (:data:`daeclear.options.MAX_OUTPUT_POINTS`, 1e6,
        about 1 GB for the chapter's slider-crank); more (``t_eval``, ``t_eval_step``, or a fixed
        ``step`` without them) is refused before the run with the estimated size. None: no cap.
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
    AssemblyError
        The initial positions cannot be assembled, the constraints are redundant (the
        message names the joints and drivers), or a declared start is in deep penetration.
    """
    if not isinstance(scene, (Scene, DAEModel)):  # e.g. a mechanism's name: say what is wanted
        opts.fail("simulate", "scene", scene, "a daeclear.Scene or an assembled model, e.g. "
                  "dc.mechanisms.slider_crank('revolute') (a mechanism's name is not a scene)")
    if options is not None and not isinstance(options, SolverOptions):
        opts.fail("simulate", "options", options, "None or a daeclear.SolverOptions")
    settings = (DEFAULTS if options is None else options).merged(
        method=method, rtol=rtol, atol=atol, formulation=formulation, backend=backend, max_step=max_step,
        max_steps=max_steps, step=step, linear_solver=linear_solver, start=start,
        allow_penetration=allow_penetration, track_work=track_work)
    method, rtol, atol, formulation = settings.method, settings.rtol, settings.atol_value(), settings.formulation
    step, linear_solver, start = settings.step, settings.linear_solver, settings.start
    allow_penetration = settings.allow_penetration
    t_end, rtol, max_step, max_steps, t_eval, backend, on_failure, store_steps, progress, track_work = opts.run(
        t_end=t_end, t0=t0, rtol=rtol, atol=atol, max_step=settings.max_step, max_steps=settings.max_steps,
        t_eval=t_eval, backend=settings.backend, on_failure=on_failure, store_steps=store_steps, progress=progress,
        track_work=settings.track_work)
    t0 = float(t0)  # checked by opts.run
    opts.step_within(step, t0, t_end)
    out = opts.output(t_eval=t_eval, t_eval_step=t_eval_step, end=t_end, stream_to=stream_to, keep_data=keep_data,
                      start=t0)
    limit = opts.max_output_points(max_output_points)
    if y0 is not None:  # checked before any work (a Scene's length: once it is assembled)
        y0 = opts.state(y0, scene.n_states if isinstance(scene, DAEModel) else None)
    if parameters is not None:  # new numbers: bound to the structure (checked before any run)
        if not isinstance(parameters, Mapping):
            opts.fail("simulate", "parameters", parameters, "None or a mapping of names to numbers, "
                      "e.g. {'clearance.clearance': 2e-4}")
        if isinstance(scene, Scene):
            scene = assemble(scene, formulation or opts.default_formulation(method), track_work=track_work)
        scene = scene.with_parameters(parameters)
    from .explicit import integrate  # the non-IDA methods

    if method != "ida":
        return integrate(scene, t_end, method=method, t_eval=t_eval, rtol=rtol, atol=atol, formulation=formulation,
                         backend=backend, max_step=max_step, max_steps=max_steps, step=step,
                         store_steps=store_steps, on_failure=on_failure, progress=progress,
                         track_work=track_work, start=start, t_eval_step=t_eval_step, stream_to=out.stream_to,
                         keep_data=out.keep_data, allow_penetration=allow_penetration, t0=t0, y0=y0,
                         max_output_points=limit)

    setup_start = time.perf_counter()
    if formulation is None:
        formulation = opts.default_formulation(method)
    model = scene if isinstance(scene, DAEModel) else assemble(scene, formulation, track_work=track_work)
    if y0 is not None:
        y0 = opts.state(y0, model.n_states)
    opts.output_size(out, limit, t_eval_step=t_eval_step, step=None, start=t0, end=t_end, n_states=model.n_states,
                     n_channels=len(model.channel_names))  # before the session: nothing compiled or run
    from_state = y0 is not None
    session, y0, yp0 = _start_session(model, t0, y0, rtol=rtol, atol=atol, backend=backend, max_step=max_step,
                                      max_steps=max_steps, linear_solver=linear_solver, start=start,
                                      allow_penetration=allow_penetration)
    setup_time = time.perf_counter() - setup_start
    sim_params = {"method": method, "start": "state" if from_state else start,
                  "rtol": rtol, "atol": atol_record(atol),
                  "max_step": max_step, "t_end": t_end, "backend": session.backend}
    if t0 != 0.0:
        sim_params["t0"] = t0
    try:
        rec = Recorder(model, parameters={**model.parameters, "simulate": sim_params}, method=method,
                       stream_to=out.stream_to, keep_data=out.keep_data)
    except BaseException:
        session.close()
        raise
    return SegmentLoop(model, session, rec, t0, y0, yp0, t_end, out.times, store_steps, progress).run(
        on_failure, setup_time, sim_params)


def _start_session(model: DAEModel, t0: float, y0: NDArray | None, *, rtol: float, atol: Any, backend: str,
                   max_step: float, max_steps: int, linear_solver: str, start: str,
                   allow_penetration: bool) -> tuple[Any, NDArray, NDArray]:
    """Open one run's IDA session and find its consistent start (the session is closed if that fails)."""
    atol_vec = tolerance_vector(model, rtol, atol)
    session = open_session(model.functions, backend=backend, rtol=rtol, atol=atol_vec, max_step=max_step,
                           parameters=model.parameter_values, max_steps=max_steps, linear_solver=linear_solver)
    try:
        if y0 is None:
            y0, yp0 = model.initial_state(session=session, start=start, allow_penetration=allow_penetration)
        else:  # a given state: q and v kept (GGL: projected), multipliers and derivatives recomputed at t0
            y0, yp0 = model.consistent_state(t0, y0, session=session, project=True)
            if not allow_penetration:  # held to the declared start's limit
                physics.check_start_penetration(model, y0, yp0, session, given=True)
    except BaseException:
        session.close()
        raise
    session.set_hints(jacobian_refresh=JACOBIAN_REFRESH,
                      first_step=FIRST_STEP_ESTIMATE and model.formulation == "ggl")
    if model.formulation == "ggl" and model.n_constraints:  # without constraints GGL is index-1
        # never ask Newton for corrections below round-off: coef * rtol >= 1e-13
        session.set_hints(nonlin_conv_coef=min(0.33, max(GGL_NEWTON_COEF, 1e-13 / rtol)))
    session.set_stall(STALL_STEP, STALL_COUNT)
    return session, y0, yp0


def smallest_clearance(model: DAEModel) -> float:
    """The smallest clearance of the model's clearance joints (inf without any)."""
    return physics.smallest_clearance(model)
