"""The integrators of the methods other than IDA (:class:`ScipyIntegrator`, :class:`FixedStepIntegrator`):
the index-1 model as an ODE in ``x = (q, v)`` (:mod:`~daeclear.solvers.ode_model`, evaluated by
:mod:`~daeclear.solvers.ode_evaluators`) between two restarts of the run driver.

Events follow IDA's contact rules: each segment watches every gap in the direction the driver gives;
a step holds a crossing when G = direction * g changed sign over it or its cubic Hermite interpolant
has an interior maximum above zero, located to IDA's root tolerance (:mod:`~daeclear.solvers.ode_crossings`);
the advance stops at the crossing and the driver restarts the integrator there with (q, v) kept. The
state at a crossing comes from the dense output (scipy) or a re-step (rk4, euler); output times from
the dense output or, fixed-step, by cubic Hermite between the steps. An advance fails on the scheme's
failure, a non-finite state, a step-size collapse or ``max_steps`` steps.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..assembly import physics
from ..assembly.contact_state import ContactState
from ..assembly.dae_model import DAEModel
from ..core.automaton import PairState
from ..engine.hermite import cubic_hermite
from ..engine.session_base import Advance
from ..engine.stall_guard import StallGuard
from .integrator import Terms
from .ode_crossings import candidate, locate
from .ode_evaluators import FX_CHUNK, FX_ERR, FX_MAXSTEPS, FX_TSTOP, evaluator
from .save_at import Output
from .tolerances import tolerance_vector

if TYPE_CHECKING:
    from .solver_options import SolverOptions

__all__ = ["FixedStepIntegrator", "ODEIntegrator", "ScipyIntegrator", "HERMITE_GAP_CHECK", "SCIPY_CHUNK"]

# Look for gap crossings with the cubic Hermite test (True) or sign changes only (False: for measurements).
HERMITE_GAP_CHECK = True
#: a scipy advance returns after this many steps (progress, bounded memory; the scheme goes on where it was)
SCIPY_CHUNK = 256
_SCIPY_HINT = "Try a smaller max_step, a looser rtol or another method."
_FIXED_HINT = "Try a smaller step."


class ODEIntegrator:
    """What both ODE integrators share: the evaluator with the segment's terms, the output times still to
    come, the rows (q, v) completed to DAE states, the failure messages and the counters."""

    lazy_rows = False
    resumes_at_roots = False
    decides = False
    session = None
    root_evaluator = None  # the driver's restarts evaluate the roots in CasADi
    extras = None
    fixed_step: float | None = None
    takes_jacobian = False  # the scheme takes the generated Jacobian

    def __init__(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions, *, name: str,
                 order: int) -> None:
        self.model, self.t_end, self.name, self.order = model, t_end, name, order
        self.ev = evaluator(model, settings.backend)
        self.backend = self.ev.backend
        self.n, self.m = model.n_q, model.n_constraints
        self.times = output.times
        self.pending: NDArray | None = None if output.times is None else output.times.values()
        self.max_steps = settings.max_steps
        self.n_steps = 0
        self.solve_time = 0.0
        self.missed: list[tuple[float, float, str]] = []
        self.t, self.x = 0.0, np.zeros(2 * self.n)
        self.directions: NDArray | None = None
        self.error: tuple[str, str] | None = None  # a failure at a (re)start: why, advice
        self.hint = ""  # what to try after the last failure

    # ---------------------------------------------------------------- the interface
    def start(self, t: float, y: NDArray, yp: NDArray, terms: Terms, state: ContactState) -> None:
        """Start at the run's start (its output row is the driver's)."""
        self.pending_upto(t)
        self.restart(t, y, yp, terms)

    def restart(self, t: float, y: NDArray, yp: NDArray, terms: Terms) -> None:
        """A new segment from ``(q, v)`` of ``y`` with the new terms."""
        self.ev.set_terms(terms.active, terms.params)
        self.t, self.x = t, np.array(y[:2 * self.n], dtype=float)
        self.directions = terms.directions
        self.open()

    def consistent(self, t: float, y: NDArray, terms: Terms) -> tuple[NDArray, NDArray]:
        """The DAE state at (q, v) of ``y`` in the mode of ``terms`` (the evaluator's; it restarts in it)."""
        self.ev.set_terms(terms.active, terms.params)
        rows = self.dae_rows(np.array([float(t)]), np.asarray(y, dtype=float)[None, :2 * self.n])
        return rows[0][0], rows[1][0]

    def open(self) -> None:
        """What the scheme sets up at a segment's start."""

    def advance(self) -> Advance:
        """The scheme's steps to the next stop (:meth:`daeclear.solvers.integrator.Integrator.advance`), or
        the failure found when it restarted."""
        if self.error is not None:
            why, hint = self.error
            self.error = None
            none, rows = np.zeros(0), np.zeros((0, 2 * self.n))
            return self.advanced("error", none, rows, none, rows, t_prev=self.t, why=why, hint=hint)
        tic = time.perf_counter()
        try:
            with np.errstate(all="ignore"):
                return self.steps()
        finally:
            self.solve_time += time.perf_counter() - tic

    def steps(self) -> Advance:
        """The scheme's own steps from ``(self.t, self.x)`` to the next stop."""
        raise NotImplementedError

    def pair_states(self) -> dict[int, PairState]:
        return {}

    def complete(self, t: NDArray, y: NDArray, switch: NDArray, *, in_place: bool
                 ) -> tuple[NDArray, NDArray, dict[str, NDArray] | None]:
        """Multipliers, accelerations and channels of rows of the current segment (their (q, v))."""
        model = self.model
        with np.errstate(all="ignore"):
            y2, yp2 = self.dae_rows(t, y[:, :2 * self.n])
            ch = self.ev.channels(model, t, y2, yp2, switch[0])
        return y2, yp2, {k: np.ascontiguousarray(ch[:, i]) for i, k in enumerate(model.channel_names)}

    def advice(self, adv: Advance, in_contact: list[str]) -> str:
        return self.hint

    def stats(self) -> dict[str, Any]:
        stats: dict[str, Any] = {"n_steps": self.n_steps, **self.ev.counters()}
        stats.pop("n_fixed_steps", None)
        if not self.takes_jacobian:
            stats["n_jac_evals"] = 0
        build = self.ev.build
        stats.update(solve_time=self.solve_time, backend=self.ev.backend,
                     compile_time=build.compile_time if build else 0.0,
                     codegen_time=build.codegen_time if build else 0.0,
                     cache_hit=bool(build.cache_hit) if build else False)
        return stats

    def close(self) -> None:
        """Nothing to free (the evaluator is the model's)."""

    # ---------------------------------------------------------------- helpers
    def dae_rows(self, t: NDArray, X: NDArray) -> tuple[NDArray, NDArray]:
        """(y, yp) rows of the DAE at ODE states X (rows (q, v)), with the evaluator's current terms."""
        Xd, Lam = self.ev.batch(t, X)
        n2 = 2 * self.n
        y = np.zeros((t.size, self.model.n_states))
        yp = np.zeros((t.size, self.model.n_states))
        y[:, :n2], y[:, n2:n2 + self.m], yp[:, :n2] = X, Lam, Xd
        return y, yp

    def pending_upto(self, t: float) -> NDArray:
        """Output times in (previous, t] not yet produced; removes them from the pending list."""
        if self.pending is None or not self.pending.size or self.pending[0] > t:
            return np.zeros(0)
        k = int(np.searchsorted(self.pending, t, side="right"))
        chunk, self.pending = self.pending[:k], self.pending[k:]
        return chunk

    def fail(self, t: float, why: str, hint: str) -> None:
        """Remember a failure found at a (re)start: the next advance reports it."""
        self.error = (why, hint)
        self.t = t

    def advanced(self, status: str, st: NDArray, sx: NDArray, et: NDArray, ex: NDArray, *, t_prev: float,
                 roots: NDArray | None = None, why: str = "", hint: str = "") -> Advance:
        """The Advance of the steps ``st`` (states ``sx``, rows (q, v)) from ``t_prev`` on and the output
        times ``et`` (``ex``), in DAE-sized rows; the state at its end (``self.t``, ``self.x``) as a DAE
        state of the segment's mode; a failure's message with the states named."""
        n_states, n2 = self.model.n_states, 2 * self.n
        h = np.diff(np.concatenate([[t_prev], st]))
        sy = np.zeros((st.size if self.times is None else 0, n_states))
        if sy.shape[0]:
            sy[:, :n2] = sx
        ey = np.zeros((et.size, n_states))
        if et.size:
            ey[:, :n2] = ex
        y, yp = self.dae_rows(np.array([self.t]), self.x[None, :])
        self.hint = hint
        return Advance(status=status, t=self.t, y=y[0], yp=yp[0], step_t=st, step_y=sy, step_yp=None, step_h=h,
                       step_order=np.full(st.size, self.order, dtype=np.int64), eval_t=et, eval_y=ey, eval_yp=None,
                       roots_found=roots, message=self.named(why))

    def named(self, why: str) -> str:
        """A failure's reason with each state component named."""
        names = self.model.state_names

        def name(match: re.Match[str]) -> str:
            i = int(match.group(2))
            if i >= 2 * self.n:
                return match.group(0)
            label = f"d({names[i]})/dt" if match.group(1).startswith("right") else names[i]
            return f"{match.group(1)} {i} ({label})"

        return re.sub(r"(right-hand side component|state component) (\d+)", name, why).replace("-nan", "nan")


class _Watch:
    """The gap functions a segment watches (each in the direction of its next switch, 0: both, as
    IDA) and their values and rates at the last accepted step."""

    def __init__(self, dirs: NDArray | None, g: NDArray, gd: NDArray) -> None:
        self.enabled = dirs is not None
        self.n_gaps = 0 if dirs is None else len(dirs)
        self.watched = [] if dirs is None else [(i, d) for i in range(self.n_gaps) for d in (1, -1) if dirs[i] * d >= 0]
        self.g, self.gd = g, gd


class ScipyIntegrator(ODEIntegrator):
    """A scipy ``OdeSolver`` class (``scheme``) stepped segment by segment, restarted at every event; the
    implicit ones (``jacobian``) with the generated Jacobian."""

    def __init__(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions, *, name: str,
                 order: int, scheme: type, jacobian: bool) -> None:
        super().__init__(model, t_end, output, settings, name=name, order=order)
        self.scheme, self.takes_jacobian = scheme, jacobian
        atol = tolerance_vector(model, settings.rtol, settings.atol_value(), newton=False)[:2 * self.n]
        self.options: dict[str, Any] = dict(rtol=settings.rtol, atol=atol,
                                            max_step=settings.max_step if settings.max_step > 0 else np.inf)
        if jacobian:
            self.options["jac"] = self.ev.jac
        self.stall_guard = StallGuard()  # step-size collapse (daeclear.engine.stall_guard)
        self.solver: Any = None  # the scheme's OdeSolver of the current segment
        self.watch = _Watch(None, np.empty(0), np.empty(0))
        self.n_lu = self.lu0 = 0

    def open(self) -> None:
        """The segment's watch and a new solver at its start (a failure is reported by the next advance)."""
        self.close_solver()
        t, x = self.t, self.x
        if self.directions is not None:
            gg = self.ev.gaps(t, x)
            if gg is None:
                self.fail(t, self.ev.last_message, "")
                return
            self.watch = _Watch(self.directions, *gg)
        else:
            self.watch = _Watch(None, np.empty(0), np.empty(0))
        try:
            self.solver = self.scheme(self.ev.rhs, t, x, self.t_end, **self.options)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            self.fail(t, f"the solver could not start: {exc}", _SCIPY_HINT)
            return
        self.lu0 = getattr(self.solver, "nlu", 0)

    def close_solver(self) -> None:
        if self.solver is not None:
            self.n_lu += getattr(self.solver, "nlu", 0) - self.lu0
            self.solver = None

    def steps(self) -> Advance:
        """Step until an event, the end, a failure, SCIPY_CHUNK steps or Ctrl-C."""
        step_t: list[float] = []
        step_x: list[NDArray] = []
        eval_t: list[NDArray] = []
        eval_x: list[NDArray] = []
        start = self.t

        def ended(status: str, roots: NDArray | None = None, why: str = "", hint: str = "") -> Advance:
            n2, k, e = 2 * self.n, min(len(step_t), len(step_x)), min(len(eval_t), len(eval_x))  # (Ctrl-C: pairs)
            return self.advanced(status, np.array(step_t[:k], dtype=float), np.array(step_x[:k]).reshape(k, n2),
                                 np.concatenate(eval_t[:e]) if e else np.zeros(0),
                                 np.concatenate(eval_x[:e]) if e else np.zeros((0, n2)),
                                 t_prev=start, roots=roots, why=why, hint=hint)

        try:
            return self.stepped(step_t, step_x, eval_t, eval_x, ended)
        except KeyboardInterrupt:  # Ctrl-C inside a step: the steps before it are kept (the driver stops)
            return ended("interrupted")

    def stepped(self, step_t: list[float], step_x: list[NDArray], eval_t: list[NDArray], eval_x: list[NDArray],
                ended: Callable[..., Advance]) -> Advance:
        """The step loop of :meth:`steps`, filling its lists; ``ended`` makes the advance."""
        solver, watch = self.solver, self.watch
        t_prev = self.t
        next_eval = self.pending[0] if self.pending is not None and self.pending.size else math.inf
        while True:
            if self.n_steps >= self.max_steps:
                return ended("error", why=f"max_steps={self.max_steps} steps reached",
                             hint="Raise max_steps or loosen rtol.")
            try:
                msg = solver.step()
            except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
                msg = f"{type(exc).__name__}: {exc}"
                solver.status = "failed"
            if solver.status == "failed":
                why = str(msg or "the solver failed")
                if self.ev.last_message:
                    why += f" (last model error: {self.ev.last_message})"
                return ended("error", why=why, hint=_SCIPY_HINT)
            t1, x1 = float(solver.t), solver.y.copy()
            if not math.isfinite(x1.sum()):
                bad = int(np.flatnonzero(~np.isfinite(x1))[0])
                return ended("error", why=f"the state became non-finite ({self.model.state_names[bad]} = {x1[bad]})",
                             hint=_SCIPY_HINT)
            self.n_steps += 1
            if self.stall_guard.step(t1, t1 - t_prev):  # the run stops at its last step before the collapse
                return ended("error", why="the " + self.stall_guard.describe(t1, t1 - t_prev),
                             hint="Try a looser rtol, a smaller max_step or another method.")
            sol = None
            if watch.enabled:
                outcome, sol = self.event_in_step(t_prev, t1, x1, eval_t, eval_x)
                if isinstance(outcome, tuple):  # an event: its point ends the advance
                    step_t.append(outcome[0])
                    step_x.append(outcome[1])
                    self.t, self.x = outcome[0], outcome[1]
                    self.close_solver()
                    return ended("root", roots=outcome[2])
                if isinstance(outcome, str):
                    return ended("error", why=outcome, hint=_SCIPY_HINT)
            if next_eval <= t1:
                te = self.pending_upto(t1)
                if sol is None:
                    sol = solver.dense_output()
                eval_t.append(te)
                eval_x.append(np.atleast_2d(np.array(sol(te), dtype=float).T))
                next_eval = self.pending[0] if self.pending is not None and self.pending.size else math.inf
            step_t.append(t1)
            step_x.append(x1)
            t_prev = t1
            self.t, self.x = t1, x1
            if solver.status == "finished":
                self.close_solver()
                return ended("tstop")
            if len(step_t) >= SCIPY_CHUNK:
                return ended("chunk")

    def event_in_step(self, t_prev: float, t1: float, x1: NDArray, eval_t: list[NDArray],
                      eval_x: list[NDArray]) -> tuple[tuple[float, NDArray, NDArray] | str | None, Any]:
        """Look for a watched gap crossing inside the step (t_prev, t1]: (the event (t, x, roots), with the
        output times before it reported; a failure's message; or None), and the step's dense output when
        it was made. The watch moves on to t1 when there is no event."""
        ev, watch = self.ev, self.watch
        gg = ev.gaps(t1, x1)
        if gg is None:
            return ev.last_message, None
        g0, gd0, (g1, gd1) = watch.g, watch.gd, gg
        h = t1 - t_prev
        cands = [(i, d, s) for i, d in watch.watched
                 if (s := candidate(d * g0[i], d * gd0[i], d * g1[i], d * gd1[i], h, HERMITE_GAP_CHECK)) > 0.0]
        sol = None
        if cands:
            sol = self.solver.dense_output()

            def dense(tt: float, sol: Any = sol) -> NDArray:
                return np.array(sol(tt), dtype=float)

            found = locate(ev, dense, t_prev, (g0, gd0), t1, x1, (g1, gd1), cands, watch.n_gaps)
            if isinstance(found, str):
                return found, sol
            if found is not None:
                te = self.pending_upto(found[0])
                if te.size:
                    eval_t.append(te)
                    eval_x.append(np.atleast_2d(np.array(sol(te), dtype=float).T))
                return found, sol
        watch.g, watch.gd = g1, gd1
        return None, sol

    def stats(self) -> dict[str, Any]:
        stats = super().stats()
        if self.takes_jacobian:
            stats["n_lu"] = self.n_lu + (getattr(self.solver, "nlu", 0) - self.lu0 if self.solver is not None else 0)
        return stats


class FixedStepIntegrator(ODEIntegrator):
    """A fixed-step scheme (its code in the C loop: its ``order``) with the step ``settings.step``; output
    times by cubic Hermite between the steps, and the steps over which a gap changed sign without an
    event kept for the checks (:attr:`missed`)."""

    def __init__(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions, *, name: str,
                 order: int) -> None:
        super().__init__(model, t_end, output, settings, name=name, order=order)
        assert settings.step is not None  # checked with the options (step_rule)
        self.fixed_step = self.step = settings.step
        self.scheme = order

    def steps(self) -> Advance:
        """One call of the step loop: to the end, a full buffer, a failure or a step that may hold a
        crossing (confirmed and located on re-steps from its start: an event, or the loop goes on)."""
        ev, t0, x0 = self.ev, self.t, self.x
        parts_t: list[NDArray] = []
        parts_x: list[NDArray] = []
        left = self.max_steps - self.n_steps
        if left <= 0:
            return self.ended("error", parts_t, parts_x, t0, x0, why=f"max_steps={self.max_steps} steps reached",
                              hint="Raise max_steps or use a larger step.")
        out = ev.fixed(self.scheme, t0, x0, self.step, self.t_end, left, self.directions, HERMITE_GAP_CHECK)
        self.n_steps += out["st"].size
        parts_t.append(out["st"])
        parts_x.append(out["sx"])
        self.t, self.x = out["ta"], out["xa"]
        status = out["status"]
        if status == FX_TSTOP:
            return self.ended("tstop", parts_t, parts_x, t0, x0)
        if status == FX_CHUNK:
            return self.ended("chunk", parts_t, parts_x, t0, x0)
        if status == FX_MAXSTEPS:
            return self.ended("error", parts_t, parts_x, t0, x0, why=f"max_steps={self.max_steps} steps reached",
                              hint="Raise max_steps or use a larger step.")
        if status == FX_ERR:
            return self.ended("error", parts_t, parts_x, t0, x0,
                              why=ev.last_message or "the model could not be evaluated", hint=_FIXED_HINT)
        # a step that may hold a crossing: confirm and locate it on re-steps from its start
        self.n_steps += 1
        t, x = self.t, self.x
        tb, xb, sstar = out["tb"], out["xb"], out["sstar"]
        cands = [(int(i), 1 - 2 * int(j), float(sstar[i, j])) for i, j in zip(*np.nonzero(sstar > 0))]
        gg_a, gg_b = ev.gaps(t, x), ev.gaps(tb, xb)
        if gg_a is None or gg_b is None:
            return self.ended("error", parts_t, parts_x, t0, x0, why=ev.last_message, hint=_FIXED_HINT)

        def restep(tt: float, ta: float = t, xa: NDArray = x) -> NDArray | None:
            return ev.step(self.scheme, ta, xa, tt - ta)

        found = locate(ev, restep, t, gg_a, tb, xb, gg_b, cands, ev.ng)
        if isinstance(found, str):
            return self.ended("error", parts_t, parts_x, t0, x0, why=found, hint=_FIXED_HINT)
        if found is None:  # no crossing: the loop goes on from the step
            parts_t.append(np.array([tb]))
            parts_x.append(xb[None, :])
            self.t, self.x = tb, xb
            return self.ended("chunk", parts_t, parts_x, t0, x0)
        parts_t.append(np.array([found[0]]))
        parts_x.append(found[1][None, :])
        self.t, self.x = found[0], found[1]
        return self.ended("root", parts_t, parts_x, t0, x0, roots=found[2])

    def ended(self, status: str, parts_t: list[NDArray], parts_x: list[NDArray], t0: float, x0: NDArray, *,
              roots: NDArray | None = None, why: str = "", hint: str = "") -> Advance:
        """The advance from ``(t0, x0)``: output times by cubic Hermite between its points, and the gap sign
        changes over its steps (no event between them) kept for the checks."""
        n2 = 2 * self.n
        st = np.concatenate(parts_t) if parts_t else np.zeros(0)
        sx = np.concatenate(parts_x) if parts_x else np.zeros((0, n2))
        et, ex = np.zeros(0), np.zeros((0, n2))
        if st.size:
            T = np.concatenate([[t0], st])
            X = np.concatenate([x0[None, :], sx])
            if self.model.gap_names:
                self.missed += physics.sign_changes(self.model, T, X)
            te = self.pending_upto(float(T[-1]))
            if te.size:
                et, ex = te, _hermite(T, X, self.ev.batch(T, X)[0], te)
        return self.advanced(status, st, sx, et, ex, t_prev=t0, roots=roots, why=why, hint=hint)


def _hermite(T: NDArray, X: NDArray, Xd: NDArray, te: NDArray) -> NDArray:
    """Cubic Hermite interpolation of the rows of X (derivatives Xd) at times te within [T0, T-1]."""
    if T.size == 1:
        return np.repeat(X[:1], te.size, axis=0)
    k = np.clip(np.searchsorted(T, te, side="left"), 1, T.size - 1)
    return cubic_hermite(T[k - 1], X[k - 1], Xd[k - 1], T[k], X[k], Xd[k], te)
