"""The assembled model integrated by other schemes than IDA, for accuracy studies.

Solvers (:class:`daeclear.solvers.base.Solver`) of every method but ``"ida"``: scipy's ``"RK45"``,
``"DOP853"``, ``"Radau"``, ``"BDF"``, ``"LSODA"`` (the implicit ones with the generated Jacobian) and
the fixed-step ``"rk4"``, ``"euler"`` (``step=``, the loop in C). The index-1 DAE is an ODE in
``x = (q, v)`` (:mod:`~daeclear.solvers.ode_model`); GGL is IDA-only.

Events follow IDA's contact rules (:mod:`daeclear.assembly.contact_state`): each segment watches every
gap in the direction the contact state gives; a step holds a crossing when G = direction * g changed
sign over it or its cubic Hermite interpolant has an interior maximum above zero, located to IDA's
root tolerance (:mod:`~daeclear.solvers.ode_crossings`); the integrator restarts from the event with
(q, v) kept. The event state comes from the dense output (scipy) or a re-step (rk4, euler). A run
fails (``success=False``) on the scheme's failure, a non-finite state, a step-size collapse,
``max_steps`` steps or ``STALL_EVENTS`` events at one time.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.assemble import DAEModel, assemble
from ..core import options
from ..core.errors import Interrupted, SceneError, SolveError
from .recorder import Recorder, out_of_memory
from .tolerances import atol_record, tolerance_vector
from ..results.result import Result
from ..model.scene import Scene
from .ode_crossings import candidate, locate
from .ode_evaluators import FX_CHUNK, FX_ERR, FX_MAXSTEPS, FX_TSTOP, evaluator
from .ode_model import ode_spec
from ..assembly import physics
from .base import step_rule
from .ode_run import FIXED_STEP_METHODS, IMPLICIT_METHODS, METHOD_NAMES, SCIPY_METHODS, Run

if TYPE_CHECKING:
    from .save_at import Output
    from .solver_options import SolverOptions

__all__ = ["METHOD_NAMES", "SCIPY_METHODS", "FIXED_STEP_METHODS", "ODESolver", "RK45", "DOP853", "Radau", "BDF",
           "LSODA", "RK4", "Euler", "ode_spec"]

# Look for gap crossings with the cubic Hermite test (True) or sign changes only (False: for measurements).
HERMITE_GAP_CHECK = True
# an event loop that produces STALL_EVENTS events without the time advancing is a failure
STALL_EVENTS = 50


_SCIPY_HINT = "Try a smaller max_step, a looser rtol or another method."


def _run_scipy(run: Run, x0: NDArray, rtol: float, atol: NDArray, max_step: float, t0: float = 0.0) -> None:
    """Integrate segment by segment with a scipy solver, restarting it at every contact event."""
    import scipy.integrate as si

    cls = {"rk45": si.RK45, "dop853": si.DOP853, "radau": si.Radau, "bdf": si.BDF, "lsoda": si.LSODA}[run.method]
    opts: dict[str, Any] = dict(rtol=rtol, atol=atol, max_step=max_step if max_step > 0 else np.inf)
    if run.method in IMPLICIT_METHODS:
        opts["jac"] = run.ev.jac
    t, x = t0, x0
    while True:
        run.open_segment(t, x)
        watch = _Watch.start(run, t, x)
        if watch is None:
            return
        try:
            solver = cls(run.ev.rhs, t, x, run.t_end, **opts)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            run.fail(t, f"the solver could not start: {exc}", _SCIPY_HINT)
            return
        lu0 = getattr(solver, "nlu", 0)
        t_last, restart = _scipy_segment(run, solver, watch, t)
        run.t_last = t_last if restart is None else restart[0]
        assert run.seg is not None
        run.seg.t1 = run.t_last
        run.n_lu += getattr(solver, "nlu", 0) - lu0
        if not _end_segment(run, restart, False):
            return
        assert restart is not None  # _end_segment goes on only after an event
        t, x, _ = restart  # the next segment starts at the event


class _Watch:
    """The gap functions a segment watches (each in the direction of its next switch, 0: both, as
    IDA) and their values and rates at the last accepted step."""

    def __init__(self, dirs: Any, g: NDArray, gd: NDArray) -> None:
        self.enabled = dirs is not None
        self.n_gaps = 0 if dirs is None else len(dirs)
        self.watched = [(i, d) for i in range(self.n_gaps) for d in (1, -1) if dirs[i] * d >= 0]
        self.g, self.gd = g, gd

    @classmethod
    def start(cls, run: Run, t: float, x: NDArray) -> _Watch | None:
        """The watch at the segment's start; None (the run failed) when the gaps cannot be evaluated."""
        dirs = contact_state.root_directions(run.model, run.state)
        if dirs is None:
            return cls(None, np.empty(0), np.empty(0))  # g and gd are read only when enabled
        gg = run.ev.gaps(t, x)
        if gg is None:
            run.fail(t, run.ev.last_message, "")
            return None
        return cls(dirs, *gg)


def _scipy_segment(run: Run, solver: Any, watch: _Watch, t: float) -> tuple[float, tuple[float, NDArray, Any] | None]:
    """Step one segment to its end, an event or a failure: (time of the last step, the event to
    restart from or None)."""
    seg = run.seg
    assert seg is not None
    add_t, add_x = seg.pt.append, seg.px.append
    solver_step = solver.step
    next_eval = run.pending[0] if run.pending is not None and run.pending.size else math.inf
    t_prev = t
    while True:
        if run.n_steps >= run.max_steps:
            run.fail(t_prev, f"max_steps={run.max_steps} steps reached", "Raise max_steps or loosen rtol.")
            return t_prev, None
        try:
            msg = solver_step()
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            msg = f"{type(exc).__name__}: {exc}"
            solver.status = "failed"
        if solver.status == "failed":
            why = str(msg or "the solver failed")
            if run.ev.last_message:
                why += f" (last model error: {run.ev.last_message})"
            run.fail(t_prev, why, _SCIPY_HINT)
            return t_prev, None
        t1, x1 = float(solver.t), solver.y.copy()
        if not math.isfinite(x1.sum()):
            bad = int(np.flatnonzero(~np.isfinite(x1))[0])
            run.fail(t_prev, f"the state became non-finite ({run.model.state_names[bad]} = {x1[bad]})", _SCIPY_HINT)
            return t_prev, None
        if not run.count_step(t_prev, t1):
            return t_prev, None
        sol = None
        if watch.enabled:
            outcome, sol = _event_in_step(run, solver, watch, t_prev, t1, x1)
            if isinstance(outcome, tuple):  # an event: its point ends the segment
                add_t(outcome[0])
                add_x(outcome[1])
                return t_prev, outcome
            if outcome == "failed":
                return t_prev, None
        if next_eval <= t1:
            te = run.pending_upto(t1)
            if sol is None:
                sol = solver.dense_output()
            run.add_evals(te, np.atleast_2d(np.array(sol(te), dtype=float).T))
            next_eval = run.pending[0] if run.pending is not None and run.pending.size else math.inf
        add_t(t1)
        add_x(x1)
        if run.progress:
            run._progress(t1)
        t_prev = t1
        if solver.status == "finished":
            return t_prev, None


def _event_in_step(run: Run, solver: Any, watch: _Watch, t_prev: float, t1: float,
                   x1: NDArray) -> tuple[Any, Any]:
    """Look for a watched gap crossing inside the step (t_prev, t1]: (the event (t, x, roots), with the
    output times before it reported; "failed" after run.fail; or "none"), and the step's dense
    output when it was made. The watch moves on to t1 when there is no event."""
    ev = run.ev
    gg = ev.gaps(t1, x1)
    if gg is None:
        run.fail(t1, ev.last_message, _SCIPY_HINT)
        return "failed", None
    g0, gd0, (g1, gd1) = watch.g, watch.gd, gg
    h = t1 - t_prev
    cands = [(i, d, s) for i, d in watch.watched
             if (s := candidate(d * g0[i], d * gd0[i], d * g1[i], d * gd1[i], h, HERMITE_GAP_CHECK)) > 0.0]
    sol = None
    if cands:
        sol = solver.dense_output()

        def dense(tt: float, sol: Any = sol) -> NDArray:
            return np.array(sol(tt), dtype=float)

        found = locate(ev, dense, t_prev, (g0, gd0), t1, x1, (g1, gd1), cands, watch.n_gaps)
        if isinstance(found, str):
            run.fail(t_prev, found, _SCIPY_HINT)
            return "failed", sol
        if found is not None:
            te = run.pending_upto(found[0])
            if te.size:
                run.add_evals(te, np.atleast_2d(np.array(sol(te), dtype=float).T))
            return found, sol
    watch.g, watch.gd = g1, gd1
    return "none", sol


def _end_segment(run: Run, restart: Any, hermite: bool) -> bool:
    """Close the segment; on an event let the logic switch modes. True when the run goes on."""
    run.close_segment(hermite=hermite)
    if restart is None or not run.success:
        return False
    t, x, roots = restart
    run.handle_event(t, x, roots)
    if run.stall >= STALL_EVENTS:
        run.fail(t, f"{run.stall} events at the same time: the event loop does not advance", "")
        return False
    return t < run.t_end


def _run_fixed(run: Run, x0: NDArray, step: float, t0: float = 0.0) -> None:
    ev, t_end = run.ev, run.t_end
    scheme = FIXED_STEP_METHODS[run.method]
    hint = "Try a smaller step."
    t, x = t0, x0
    while True:
        run.open_segment(t, x)
        dirs = contact_state.root_directions(run.model, run.state)
        restart: tuple[float, NDArray, Any] | None = None
        while True:
            left = run.max_steps - run.n_steps
            if left <= 0:
                run.fail(t, f"max_steps={run.max_steps} steps reached", "Raise max_steps or use a larger step.")
                break
            out = ev.fixed(scheme, t, x, step, t_end, left, dirs, HERMITE_GAP_CHECK)
            run.n_steps += out["st"].size
            run.add_steps(out["st"], out["sx"])
            t, x = out["ta"], out["xa"]
            status = out["status"]
            if status == FX_TSTOP:
                break
            if status == FX_CHUNK:
                continue
            if status == FX_MAXSTEPS:
                run.fail(t, f"max_steps={run.max_steps} steps reached", "Raise max_steps or use a larger step.")
                break
            if status == FX_ERR:
                run.fail(t, ev.last_message or "the model could not be evaluated", hint)
                break
            # a step that may hold a crossing: confirm and locate it on re-steps from its start
            run.n_steps += 1
            tb, xb, sstar = out["tb"], out["xb"], out["sstar"]
            cands = [(int(i), 1 - 2 * int(j), float(sstar[i, j])) for i, j in zip(*np.nonzero(sstar > 0))]
            gg_a, gg_b = ev.gaps(t, x), ev.gaps(tb, xb)
            if gg_a is None or gg_b is None:
                run.fail(t, ev.last_message, hint)
                break

            def restep(tt: float, ta: float = t, xa: NDArray = x) -> NDArray | None:
                return ev.step(scheme, ta, xa, tt - ta)

            found = locate(ev, restep, t, gg_a, tb, xb, gg_b, cands, ev.ng)
            if isinstance(found, str):
                run.fail(t, found, hint)
                break
            if found is None:
                run.add_steps(np.array([tb]), xb[None, :])
                t, x = tb, xb
                continue
            run.add_steps(np.array([found[0]]), found[1][None, :])
            restart = found
            break
        if not _end_segment(run, restart, True):
            return
        assert restart is not None  # _end_segment goes on only after an event
        t, x, _ = restart  # the next segment starts at the event


class ODESolver:
    """A method that integrates the index-1 model as an ODE in (q, v) with the contact events of
    the module docstring; a subclass names the scheme (``name``: scipy's class, or "rk4"/"euler")."""

    name: ClassVar[str]
    formulation: ClassVar[str] = options.CHAPTER_FORMULATION
    fixed_step: ClassVar[bool] = False  # rk4, euler: the step is the option ``step``

    def check(self, settings: SolverOptions) -> None:
        """``step`` is required by the fixed-step schemes and refused by the others."""
        step_rule(self.name, settings.step, fixed=self.fixed_step)

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate from ``t0`` to ``t_end`` (the :class:`daeclear.solvers.base.Solver` contract).

        Output goes to a :class:`daeclear.solvers.recorder.Recorder` segment by segment (streamed: memory
        grows with the longest segment and the events, not with the run)."""
        return _integrate(self, model, t_end, t0, y0, save, settings, on_failure, progress)


def _solver(key: str, doc: str, *, fixed: bool = False) -> type[ODESolver]:
    """The solver class of the method ``key`` (a subclass of ODESolver named as the method)."""
    name = METHOD_NAMES[key]
    return type(name, (ODESolver,), {"name": name, "fixed_step": fixed, "__doc__": doc, "__module__": __name__})


RK45 = _solver("rk45", "scipy's explicit Runge-Kutta 5(4).")
DOP853 = _solver("dop853", "scipy's explicit Runge-Kutta 8(5,3).")
Radau = _solver("radau", "scipy's implicit Radau IIA (order 5), with the generated Jacobian.")
BDF = _solver("bdf", "scipy's implicit BDF (orders 1-5), with the generated Jacobian.")
LSODA = _solver("lsoda", "scipy's LSODA (Adams / BDF switching), with the generated Jacobian.")
RK4 = _solver("rk4", "Classical fixed-step Runge-Kutta (order 4), its step loop in C.", fixed=True)
Euler = _solver("euler", "Explicit Euler with a fixed step, its step loop in C.", fixed=True)


def _integrate(solver: ODESolver, scene: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None,
               out: Output, settings: SolverOptions, on_failure: str, progress: bool) -> Result:
    """The run of an :class:`ODESolver`: checks that need the model, set-up, the loop, the Result."""
    method_l, name = solver.name.lower(), solver.name
    rtol, atol, step, max_step = settings.rtol, settings.atol_value(), settings.step, settings.max_step
    start, allow_penetration = settings.start, settings.allow_penetration
    if settings.track_work:
        raise SceneError(f"simulate: track_work=True is supported by method='ida' only, not by method={name!r}.")
    formulation = scene.formulation if isinstance(scene, DAEModel) else settings.formulation or solver.formulation
    if formulation != "index1":
        raise SceneError(f"simulate: formulation={formulation!r} is integrated by IDA only; method={name!r} "
                         "integrates the chapter's index-1 formulation (formulation='index1').")
    setup_start = time.perf_counter()
    model = scene if isinstance(scene, DAEModel) else assemble(scene, formulation)
    y0 = None if y0 is None else options.state(y0, model.n_states)
    out.check_size(step=step, n_states=model.n_states, n_channels=len(model.channel_names))  # before the grid
    from_state = y0 is not None
    eval_times = None if out.times is None else out.times.values()  # checked by SaveAt.plan
    n = model.n_q
    atol_x = tolerance_vector(model, rtol, atol, newton=False)[:2 * n]
    ev = evaluator(model, settings.backend)
    if y0 is not None:  # q and v as given (index-1: no projection), multipliers recomputed at t0
        y0, yp0 = model.consistent_state(t0, y0)
        if not allow_penetration:  # held to the declared start's limit
            physics.check_start_penetration(model, y0, yp0, given=True)
    else:
        y0, _ = model.initial_state(start=start, allow_penetration=allow_penetration)
    x0 = np.array(y0[:2 * n])
    sim_params = {"method": name, "rtol": rtol, "atol": atol_record(atol),
                  "max_step": max_step, "t_end": t_end, "backend": ev.backend, "step": step}
    if from_state:
        sim_params["start"] = "state"
    if t0 != 0.0:
        sim_params["t0"] = t0
    rec = Recorder(model, parameters={**model.parameters, "simulate": sim_params}, method=name,
                   stream_to=out.stream_to, keep_data=out.keep_data)
    run = Run(model, ev, method_l, t_end, eval_times, out.steps, progress, settings.max_steps, rec)
    run.y0, run.step = (y0 if start == "declared" and not from_state else None), step  # declared starts only
    run.from_state, run.t_last = from_state, t0
    run.set_state(contact_state.start_state(model, t0, y0))
    setup_time = time.perf_counter() - setup_start
    tic = time.perf_counter()
    interrupted = False
    try:
        with np.errstate(all="ignore"):
            if method_l in FIXED_STEP_METHODS:
                _run_fixed(run, x0, step, t0)  # type: ignore[arg-type]
            else:
                _run_scipy(run, x0, rtol, atol_x, max_step, t0)
    except KeyboardInterrupt:  # Ctrl-C: keep what was computed, then stop the caller too (Interrupted)
        run.success, run.status = False, -1
        run.message = f"interrupted by the user at t={run.t_last:.6g} s"
        run.close_segment(hermite=method_l in FIXED_STEP_METHODS)
        interrupted = True
    except MemoryError:  # keep (and, streamed, save) the segments closed before
        run.success, run.status = False, -1
        run.message = out_of_memory(run.t_last)
        if run.seg is not None:
            run.seg.st, run.seg.sx, run.seg.pt, run.seg.px, run.seg.et, run.seg.ex = [], [], [], [], [], []
    except BaseException as exc:  # anything else: a streamed file keeps what it holds, then the error goes on
        run.bar.close()
        rec.abort(exc)
        raise
    solve_time = time.perf_counter() - tic
    if run.progress:
        run._progress(t_end if run.success else run.t_last)
    run.bar.close()
    result = run.result(setup_time, solve_time)
    if interrupted or rec.interrupted:
        raise Interrupted(f"simulate: {result.message}; partial result in .result.", result)
    if not result.success and on_failure == "raise":
        raise SolveError(result.message + " Partial result in .result.", result)
    return result
