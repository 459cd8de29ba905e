"""simulate(): IDA with root finding, contact-mode switches and consistent restarts.

The solver knows nothing of slider-cranks: it integrates a :class:`DAEModel` segment
by segment. Between two roots of the gap functions the set of active contact terms
is fixed; at a root each contact element's event logic decides the new modes (and
latches the approach speed), the multipliers and derivatives are made consistent
again, and IDA restarts with fresh BDF history.
"""

from __future__ import annotations

import itertools
import logging
import math
import os
import time
from typing import Any
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import options as opts
from . import physics
from ..assembly.assemble import DAEModel, assemble
from ..errors import Interrupted, SolveError
from ..engine.ida_session import open_session
from .recorder import Recorder
from ..progress import Progress
from .tolerances import tolerance_vector
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
# Failures in contact that plain Coulomb friction causes when the contact sticks.
STICKING_FLAGS = ("DC_STEP_COLLAPSE", "IDA_CONV_FAIL", "IDA_ERR_FAIL")
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
    atol: float | ArrayLike | None = UNSET,
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
) -> Result:
    """Integrate a scene (or an assembled model) from ``t0`` (0 by default) to ``t_end``.

    The solver settings (``method`` ... ``allow_penetration``, the fields of
    :class:`daeclear.SolverOptions`) come from ``options`` when given, and a keyword given
    explicitly overrides the same setting of ``options``: ``simulate(m, T, options=o, rtol=1e-8)``
    is ``simulate(m, T, options=o.replace(rtol=1e-8))``. The defaults below are SolverOptions'.

    Parameters
    ----------
    scene : Scene or DAEModel
        The mechanism; a Scene is assembled with ``formulation`` first. A model is never changed
        by a run (its contact logic is copied per run): runs of one model, one after the other or
        at the same time in threads, are independent.
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
    atol : float, array or None
        Absolute tolerance of positions and velocities (default ``1e-3 * rtol``) or one
        value per state. Multipliers are always kept out of the error test.
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
    linear_solver : {"auto", "dense", "sparse"}
        LU of IDA's Newton iteration in the compiled backend: dense, sparse (SuperLU_MT), or
        "auto" (sparse for large models, see :data:`daeclear.engine.ida_session.SPARSE_MIN_STATES`).
        The python backend and the other methods ignore it. Reported in ``result.stats``.
    start : {"ideal", "declared"}
        How the run starts without ``y0`` (ignored with ``y0``, as is ``allow_penetration``).
        "ideal" (the chapter's, section 4.4): every clearance joint centred
        and every position and velocity assembled on the mechanism whose clearance joints are
        ideal, from the declared state as a guess; "declared": the bodies' declared positions and
        velocities, corrected only for the scene's ideal joints.
    allow_penetration : bool
        Start "declared" even with a contact pair deeper in its wall than
        :data:`daeclear.solvers.physics.START_PENETRATION_FRACTION` of the clearance (refused otherwise).

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
    out = opts.output(t_eval=t_eval, t_eval_step=t_eval_step, end=t_end, stream_to=stream_to, keep_data=keep_data,
                      start=t0)
    if y0 is not None:  # checked before any work (a Scene's length: once it is assembled)
        y0 = opts.state(y0, scene.n_states if isinstance(scene, DAEModel) else None)
    from .explicit import integrate  # the non-IDA methods

    if method != "ida":
        return integrate(scene, t_end, method=method, t_eval=t_eval, rtol=rtol, atol=atol, formulation=formulation,
                         backend=backend, max_step=max_step, max_steps=max_steps, step=step,
                         store_steps=store_steps, on_failure=on_failure, progress=progress,
                         track_work=track_work, start=start, t_eval_step=t_eval_step, stream_to=out.stream_to,
                         keep_data=out.keep_data, allow_penetration=allow_penetration, t0=t0, y0=y0)

    setup_start = time.perf_counter()
    if formulation is None:
        formulation = opts.default_formulation(method)
    model = scene if isinstance(scene, DAEModel) else assemble(scene, formulation, track_work=track_work)
    if y0 is not None:
        y0 = opts.state(y0, model.n_states)
    from_state = y0 is not None
    model = model.for_run(from_state=from_state)  # this run's own contact logic: the model stays unchanged
    atol_vec = tolerance_vector(model, rtol, atol)
    session = open_session(model.functions, backend=backend, rtol=rtol, atol=atol_vec, max_step=max_step,
                           parameters=model.parameter_values, max_steps=max_steps, linear_solver=linear_solver)
    try:
        if y0 is None:
            y0, yp0 = model.initial_state(session=session, start=start, allow_penetration=allow_penetration)
        else:  # a given state: q and v kept (GGL: projected), multipliers and derivatives recomputed at t0
            y0, yp0 = model.consistent_state(t0, y0, session=session, project=True)
    except BaseException:
        session.close()
        raise
    if model.formulation == "ggl" and model.n_constraints:  # without constraints GGL is index-1
        # never ask Newton for corrections below round-off: coef * rtol >= 1e-13
        session.set_hints(nonlin_conv_coef=min(0.33, max(GGL_NEWTON_COEF, 1e-13 / rtol)))
    session.set_stall(STALL_STEP, STALL_COUNT)
    setup_time = time.perf_counter() - setup_start
    sim_params = {"method": method, "start": "state" if from_state else start,
                  "rtol": rtol, "atol": None if atol is None else np.ravel(atol).tolist(),
                  "max_step": max_step, "t_end": t_end, "backend": session.backend}
    if t0 != 0.0:
        sim_params["t0"] = t0
    try:
        rec = Recorder(model, parameters={**model.parameters, "simulate": sim_params}, method=method,
                       stream_to=out.stream_to, keep_data=out.keep_data)
    except BaseException:
        session.close()
        raise
    return _run(model, session, t0, y0, yp0, t_end, out.times, store_steps, on_failure, progress,
                setup_time, sim_params, rec)


def _run(model: DAEModel, session: Any, t0: float, y0: NDArray, yp0: NDArray, t_end: float,
         eval_times: opts.OutputTimes | None,
         store_steps: bool, on_failure: str, progress: bool, setup_time: float,
         sim_params: dict[str, Any], rec: Recorder) -> Result:
    """The segment loop: advance, handle roots, restart; always returns what was computed.

    The output goes to ``rec`` chunk by chunk (each compiled-loop buffer, each window of output
    times, each segment), so a run that streams to a file and keeps no steps runs in bounded memory.
    """
    run_start = time.perf_counter()
    progress_line = Progress(t_end, unit="s", desc="simulate", enabled=progress)
    n_terms = len(model.terms)
    active = [False] * n_terms
    params = [np.zeros(term.n_params) for term in model.terms]
    modes: dict[str, str] = {}
    for logic in model.contacts:
        modes.update(logic.initial_modes(t0, y0, active, params))
    y, yp = y0, yp0
    if any(active):
        y, yp = model.consistent_state(t0, y0, model.term_forces(t0, y0, active, params, session), session)
    switch = model.switch_vector(active, params)

    # reported points not made consistent yet (IDA's raw values, with their contact switches)
    raw: list[tuple[NDArray, NDArray, NDArray, NDArray]] = []
    rec.add_steps(np.array([t0]), np.array([0.0]), np.array([0]))
    i_eval = 0  # index of the next output time
    if eval_times is None:
        raw.append((np.array([t0]), y[None, :], yp[None, :], switch[None, :]))
    elif eval_times.window(0, 1)[0] == t0:
        raw.append((np.array([t0]), y[None, :], yp[None, :], switch[None, :]))
        i_eval = 1
    events, segments = rec.events, rec.segments
    t = t0
    success, status, message = True, 0, "end of the time span reached"
    n_restarts = 0
    interrupted = False
    c_layout = False

    def flush() -> None:
        """Make the raw points consistent and hand them, the events and the segments to the recorder.

        IDA does not converge the multipliers (out of its error test) and its interpolant of them is
        not controlled: multipliers, accelerations (and the work rate) are recomputed from every
        point's q and v with that point's contact modes (point by point: chunks change nothing)."""
        if raw:
            out_t, out_y, out_yp, out_switch = (np.concatenate(c) for c in zip(*raw))
            raw.clear()
            if c_layout:  # one pass in C
                out_y, out_yp, values = session.report(out_t, out_y, out_switch)
                channels = {name: np.ascontiguousarray(values[:, i]) for i, name in enumerate(model.channel_names)}
            else:
                out_y, out_yp = model.consistent_state(
                    out_t, out_y, model.term_forces_rows(out_t, out_y, out_switch, session), session)
                channels = model.channels(out_t, out_y, out_yp, out_switch, session)
            rec.add_points(out_t, out_y, out_yp, channels)
        rec.flush()

    try:
        # the compiled loop makes states consistent itself (restarts after its own switches, the
        # reported points); the python backend leaves that to the model's Python methods
        c_layout = session.set_layout(model.layout(project=model.formulation == "ggl"))
        session.reinit(t, y, yp, active, params, _root_directions(model, active))
        # the compiled loop may decide every contact switch itself (simple pairs): the rule and the
        # starting state of each pair come from its logic object; Python then only records
        owners: dict[int, Any] = {}
        c_decides = False
        if model.auto_pairs:
            owners = {root: logic for logic in model.contacts for root in logic.roots}
            roots = [pair[0] for pair in model.auto_pairs]
            c_decides = c_layout and session.set_auto_events(
                model.auto_pairs, storms=[owners[root].storm for root in roots],
                states=[owners[root].pair_state(root) for root in roots])

        def record(adv: Any, steps: slice, evals: slice, switch: NDArray) -> None:
            """Keep IDA's points as they are; they are made consistent by flush()."""
            step_t, eval_t = adv.step_t[steps], adv.eval_t[evals]  # each slice once: this runs at every switch
            if store_steps and step_t.size:
                rec.add_steps(step_t, adv.step_h[steps], adv.step_order[steps])
                if eval_times is None:  # the steps are the output points
                    raw.append((step_t, adv.step_y[steps], adv.step_yp[steps],
                                np.repeat(switch[None, :], step_t.size, axis=0)))
            if eval_t.size:
                raw.append((eval_t, adv.eval_y[evals], adv.eval_yp[evals],
                            np.repeat(switch[None, :], eval_t.size, axis=0)))

        seg_start = t
        while True:
            window = None
            if eval_times is not None:  # the next output times (compiled loop: at most EVAL_WINDOW of them)
                i_eval, window = _eval_window(eval_times, i_eval, session.eval_from,
                                              EVAL_WINDOW if c_layout else eval_times.size)
            adv = session.advance(t_end, window, store_steps, store_states=eval_times is None, chunked=True)
            i_eval += adv.eval_t.size
            # the C loop decided contact switches itself: split the advance at each restart and
            # record the decisions (modes, terms, latched speeds, events) in the pair logic
            s0 = e0 = 0
            ends = _split_rows(adv)  # one search for all restarts of the advance
            for t_ev, decided in itertools.groupby(adv.auto_events, key=lambda ev: ev.t):
                s1, e1 = ends[t_ev]
                record(adv, slice(s0, s1), slice(e0, e1), switch)
                segments.append((seg_start, t_ev, dict(modes)))
                for ev in decided:
                    root = model.auto_pairs[ev.pair][0]
                    for event in owners[root].record(root, t_ev, ev.y, ev.rate, ev.decision, active, params):
                        events.append(event)
                        modes[event.pair] = "contact" if event.kind == "onset" else "free"
                switch = model.switch_vector(active, params)
                seg_start, s0, e0 = t_ev, s1, e1
                n_restarts += 1
            record(adv, slice(s0, None), slice(e0, None), switch)
            if adv.auto_events and not _same_terms(session.active_terms(), active, params):
                adv.status, adv.flag_name = "error", "DC_EVENT_MISMATCH"
                adv.message = "internal: the compiled event loop and the recorded contact modes disagree"
            elif c_decides and adv.status == "root":
                adv.status, adv.flag_name = "error", "DC_EVENT_MISMATCH"
                adv.message = "internal: the compiled event loop left a contact root undecided"
            t, y, yp = adv.t, adv.y, adv.yp
            if adv.status == "interrupted":  # Ctrl-C inside the python backend's loop: its steps are kept
                raise KeyboardInterrupt
            if adv.status == "chunk":  # a buffer of the compiled loop is full: hand it over, go on
                flush()
                progress_line.update(t, f"events {rec.n_events}")
                continue
            progress_line.update(t, f"events {rec.n_events}")
            if adv.status == "error":
                segments.append((seg_start, t, dict(modes)))
                seg_start = math.nan
                success, status = False, -1
                message = _failure_message(model, adv, modes)
                break
            if adv.status == "tstop" or t >= t_end:
                segments.append((seg_start, t, dict(modes)))
                seg_start = math.nan
                break
            # a root: let every contact element decide its new modes
            before = (list(active), [p.copy() for p in params], _root_directions(model, active), dict(modes))
            for logic in model.contacts:
                new_events = logic.on_roots(t, y, yp, adv.roots_found, active, params)
                events.extend(new_events)
                for event in new_events:
                    modes[event.pair] = "contact" if event.kind == "onset" else "free"
            directions = _root_directions(model, active)
            if (before[0] == active and all(np.array_equal(a, b) for a, b in zip(before[1], params))
                    and (directions is None or (before[2] is not None and np.array_equal(before[2], directions)))):
                continue  # nothing switched: IDA goes on from the root without a restart, in the same segment
            segments.append((seg_start, t, before[3]))
            seg_start = t
            assert adv.roots_found is not None  # a root return always says which roots
            y, yp = _restart_state(model, session, t, y, yp, model.term_forces(t, y, active, params, session),
                                   adv.roots_found)
            switch = model.switch_vector(active, params)
            session.reinit(t, y, yp, active, params, _root_directions(model, active))
            n_restarts += 1
            flush()
    except KeyboardInterrupt:  # Ctrl-C: keep what was computed, then stop the caller too (Interrupted)
        success, status, message = False, -1, f"interrupted by the user at t={t:.6g} s"
        interrupted = True
    except MemoryError:  # keep (and, streamed, save) what was computed: the chunks before this one
        raw.clear()
        success, status = False, -1
        message = (f"out of memory at t={t:.6g} s. Report fewer points (t_eval_step), keep no steps "
                   "(store_steps=False) and stream the run to a file (stream_to).")
    except BaseException as exc:  # anything else: a streamed file keeps what it holds, then the error goes on
        progress_line.close()
        rec.abort(exc)
        session.close()
        raise
    if not math.isnan(seg_start):  # stopped inside a segment: it ends where the run stopped
        segments.append((seg_start, t, dict(modes)))
    stats = dict(session.stats())
    post_start = time.perf_counter()
    try:  # the session stays open through the checks: they evaluate constraints in its library, not in CasADi
        try:
            flush()
        except BaseException as exc:
            rec.abort(exc)
            raise
        progress_line.update(t_end if success else t, f"events {rec.n_events}")
        progress_line.close()
        stats.update(n_events=rec.n_events, n_restarts=n_restarts, setup_time=setup_time,
                     wall_time=setup_time + time.perf_counter() - run_start,
                     output_time=time.perf_counter() - post_start)
        if model.gap_names:  # the run's end state of the storm guard (kept in this run's logic, not in the model)
            stats["held_pairs"] = [model.gap_names[root] for logic in model.contacts for root in logic.roots
                                   if logic.pair_state(root).held]
        # the start checks concern a declared state: the chapter's start is consistent by construction
        key_t, key_y, key_channels = rec.key_rows()
        found = physics.check_run(model, key_t, key_y, key_channels,
                                  y0 if sim_params["start"] == "declared" else None, stats, session)
    finally:
        session.close()
    physics.issue(found, stacklevel=4)  # issue <- _run <- simulate <- the caller
    deep = [w for w in found if w["kind"] == "penetration" and w["t"] <= t]
    if not success and not interrupted and deep:  # the advice must fit the cause: not a tolerance problem
        w = deep[0]
        message += (f" Before it, '{w['where']}' penetrated {w['value']:.3g} m at t={w['t']:.6g} s, more than its "
                    f"limit {w['limit']:.3g} m: the contact carries more than the joint can (friction, speed or "
                    "load); tolerances will not fix that.")
    result = rec.finish(stats=stats, success=success, status=status, message=message, warnings=found)
    if interrupted or rec.interrupted:
        raise Interrupted(f"simulate: {message}; partial result in .result.", result)
    if not success and on_failure == "raise":
        raise SolveError(message + " Partial result in .result.", result)
    return result


#: Output times handed to the compiled loop at a time: their rows are emptied between windows.
EVAL_WINDOW = 4096


def _split_rows(adv: Any) -> dict[float, tuple[int, int]]:
    """Event time -> (steps, output points) of the advance up to and including that time."""
    if not adv.auto_events:
        return {}
    times = np.array([ev.t for ev in adv.auto_events])
    steps = np.searchsorted(adv.step_t, times, side="right").tolist()
    evals = np.searchsorted(adv.eval_t, times, side="right").tolist()
    return {t: (s, e) for t, s, e in zip(times.tolist(), steps, evals)}


def _eval_window(times: opts.OutputTimes, i: int, t: float, size: int) -> tuple[int, NDArray]:
    """The output times after ``t`` from index ``i`` on, at most ``size``: (index of the first, times)."""
    while i < times.size:
        window = times.window(i, i + size)
        lo = int(np.searchsorted(window, t, side="right"))
        if lo < window.size:
            return i + lo, window[lo:]
        i += window.size
    return i, np.zeros(0)


def smallest_clearance(model: DAEModel) -> float:
    """The smallest clearance of the model's clearance joints (inf without any)."""
    return physics.smallest_clearance(model)


def _same_terms(c_terms: tuple[list[bool], list[NDArray]], active: Sequence[bool], params: Sequence[NDArray]) -> bool:
    """The compiled loop's active terms and parameters are those recorded from its decisions."""
    return c_terms[0] == list(active) and all(np.array_equal(a, b) for a, b in zip(c_terms[1], params))


def _root_directions(model: DAEModel, active: Sequence[bool]) -> NDArray | None:
    """Root directions for the next segment: each contact pair watches only its next switch."""
    if not model.gap_names:
        return None
    directions = np.zeros(len(model.gap_names), dtype=np.int32)
    for logic in model.contacts:
        for index, direction in logic.root_directions(active):
            directions[index] = direction
    return directions


def _restart_state(model: DAEModel, session: Any, t: float, y: NDArray, yp: NDArray, forces: NDArray | None,
                   found: Any) -> tuple[NDArray, NDArray]:
    """Consistent restart after a contact switch (GGL: projected onto the constraint manifold),
    unprojected when the projection moves a root function that did not fire across zero (it
    would never be found again: a missed contact). The compiled loop's rule (project_kept_roots)."""
    projected = model.consistent_state(t, y, forces, session, project=True)
    if model.formulation != "ggl" or not model.gap_names:
        return projected
    g0, g1 = session.roots(t, y, yp), session.roots(t, projected[0], yp)
    quiet = np.zeros(g0.shape, bool) if found is None else np.asarray(found).ravel() == 0
    if np.any(quiet & (g0 != 0) & ((g0 > 0) != (g1 > 0))):
        return model.consistent_state(t, y, forces, session, project=False)
    return projected


def _failure_message(model: DAEModel, adv: Any, modes: dict[str, str]) -> str:
    """Say when, where (contact modes) and why IDA failed, and what to try."""
    in_contact = [pair for pair, mode in modes.items() if mode == "contact"]
    where = f" with {', '.join(repr(p) for p in in_contact)} in contact" if in_contact else ""
    flag = f" ({adv.flag_name})" if adv.flag_name else ""
    detail = f": {adv.message}" if adv.message else ""
    advice = "Try a smaller max_step, a tighter rtol" + (", or formulation='ggl'." if model.formulation != "ggl"
                                                         else ".")
    if adv.flag_name == "DC_MAX_STEPS":  # not an accuracy problem: the run needs more steps
        advice = ("The run needs more steps than max_steps allows: raise max_steps (daeclear run: --max-steps) "
                  "in proportion to the time still to go.")
    # sticking under plain Coulomb: index-1 chatters until the stall guard stops it, GGL's Newton
    # iteration fails to converge (or its error test fails) at the sticking point
    elif adv.flag_name in STICKING_FLAGS and in_contact and any(
            getattr(logic, "discontinuous_friction", False) for logic in model.contacts):
        advice = ("The friction law is discontinuous at zero sliding speed (plain Coulomb) and the "
                  "contact is sticking: use the modified Coulomb law (friction=<coefficient> or "
                  "daeclear.contact.ModifiedCoulomb), which is continuous.")
    return f"IDA failed at t={adv.t:.6g} s{flag}{where}{detail}. {advice}"
