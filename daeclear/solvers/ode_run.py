"""The record of one non-IDA run (:class:`Run`): its segments, contact modes, events and failure,
handed to the :class:`~daeclear.solvers.recorder.Recorder`; and the table of the methods."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.assemble import DAEModel
from ..engine.hermite import cubic_hermite
from ..engine.abi import DCO_EULER, DCO_RK4
from ..engine.stall_guard import StallGuard
from ..core.progress import Progress
from ..core.events import ContactEvent
from ..results.result import Result
from ..assembly import physics
from .ode_evaluators import Evaluator
from .recorder import Recorder

__all__ = ["FIXED_STEP_METHODS", "IMPLICIT_METHODS", "METHOD_NAMES", "SCIPY_METHODS", "Run", "Segment"]

#: lower-case method name -> the name reported in Result.method
METHOD_NAMES: dict[str, str] = {
    "rk45": "RK45", "dop853": "DOP853", "radau": "Radau", "bdf": "BDF", "lsoda": "LSODA",
    "rk4": "rk4", "euler": "euler",
}
SCIPY_METHODS: tuple[str, ...] = ("rk45", "dop853", "radau", "bdf", "lsoda")
IMPLICIT_METHODS: tuple[str, ...] = ("radau", "bdf", "lsoda")
#: fixed-step methods and their C scheme codes (= their order)
FIXED_STEP_METHODS: dict[str, int] = {"rk4": DCO_RK4, "euler": DCO_EULER}
_ORDER = {"rk45": 5, "dop853": 8, "radau": 5, "bdf": -1, "lsoda": -1, "rk4": 4, "euler": 1}


@dataclass
class Segment:
    """One integration segment: its modes and terms, start state, steps and output points."""

    t0: float
    x0: NDArray
    active: list[bool]
    params: list[NDArray]
    modes: dict[str, str]
    include_start: bool  # the first segment also outputs its start point
    st: list[NDArray] = field(default_factory=list)  # chunks of step times
    sx: list[NDArray] = field(default_factory=list)  # chunks of step states
    pt: list[float] = field(default_factory=list)  # single step times (scipy methods)
    px: list[NDArray] = field(default_factory=list)
    et: list[NDArray] = field(default_factory=list)  # chunks of t_eval times (scipy: dense output)
    ex: list[NDArray] = field(default_factory=list)
    t1: float = 0.0


class Run:
    """State of one integrate() call: model, evaluator, logic, records; builds the Result."""

    def __init__(self, model: DAEModel, ev: Evaluator, method: str, t_end: float, eval_times: NDArray | None,
                 store_steps: bool, progress: bool, max_steps: int, rec: Recorder) -> None:
        self.model, self.ev, self.method, self.t_end = model, ev, method, t_end
        self.rec = rec  # where each closed segment's output goes (kept, or streamed to a file)
        self._handed = 0  # events handed to rec so far
        self.eval_times = self.pending = eval_times
        self.store_steps = store_steps
        self.max_steps = max_steps
        self.progress = progress
        self.bar = Progress(t_end, unit="s", desc="simulate", enabled=progress)
        self.n, self.m = model.n_q, model.n_constraints
        self.state: contact_state.ContactState = ()  # the run's contact state (set by start)
        self.active: list[bool] = [False] * len(model.terms)
        self.params: list[NDArray] = [np.zeros(term.n_params) for term in model.terms]
        self.modes: dict[str, str] = {}
        self.events: list[ContactEvent] = []
        self.n_segments = self.n_steps = self.n_restarts = self.n_lu = self.stall = 0
        self.stall_guard = StallGuard()  # step-size collapse (daeclear.engine.stall_guard)
        self.last_event_t = -math.inf
        self.seg: Segment | None = None
        self.t_last = 0.0
        self.success, self.status, self.message = True, 0, "end of the time span reached"
        self.y0: NDArray | None = None  # a declared state at t = 0, for the physics checks
        self.from_state = False  # the run starts from a given state of a run (physics checks)
        self.step: float | None = None  # the fixed step (rk4, euler)
        self.missed: list[tuple[float, float, str]] = []  # steps over which a gap changed sign, no event

    def set_state(self, state: contact_state.ContactState) -> None:
        """Take the run's new contact state, and the terms and modes that follow from it."""
        self.state = state
        self.active, self.params = contact_state.switches(self.model, state)
        self.modes = contact_state.modes(self.model, state)

    def open_segment(self, t0: float, x0: NDArray) -> None:
        self.ev.set_terms(self.active, self.params)
        self.seg = Segment(t0, np.array(x0, dtype=float), list(self.active), [p.copy() for p in self.params],
                            dict(self.modes), include_start=not self.n_segments, t1=t0)
        self.n_segments += 1
        if self.seg.include_start and self.pending is not None and self.pending.size and self.pending[0] <= t0:
            self.seg.et.append(self.pending[:1].copy())
            self.seg.ex.append(self.seg.x0[None, :].copy())
            self.pending = self.pending[1:]
        self.t_last = t0

    def add_steps(self, t: NDArray, X: NDArray) -> None:
        seg = self.seg
        assert seg is not None
        if t.size:
            seg.st.append(t)
            seg.sx.append(X)
            seg.t1 = float(t[-1])
            self.t_last = seg.t1
            if self.progress:
                self._progress(seg.t1)

    def add_evals(self, t: NDArray, X: NDArray) -> None:
        assert self.seg is not None
        if t.size:
            self.seg.et.append(t)
            self.seg.ex.append(X)

    def pending_upto(self, t: float) -> NDArray:
        """Output times in (previous, t] not yet produced; removes them from the pending list."""
        if self.pending is None or not self.pending.size or self.pending[0] > t:
            return np.zeros(0)
        k = int(np.searchsorted(self.pending, t, side="right"))
        chunk, self.pending = self.pending[:k], self.pending[k:]
        return chunk

    def close_segment(self, hermite: bool) -> None:
        """Multipliers, accelerations and channels of the segment's output points."""
        seg = self.seg
        if seg is None:
            return
        self.seg = None
        ev, n = self.ev, self.n
        ev.set_terms(seg.active, seg.params)
        if seg.pt:
            seg.st.append(np.array(seg.pt))
            seg.sx.append(np.array(seg.px).reshape(len(seg.px), 2 * n))
            seg.pt, seg.px = [], []
        st = np.concatenate(seg.st) if seg.st else np.zeros(0)
        sx = np.concatenate(seg.sx) if seg.sx else np.zeros((0, 2 * n))
        T = np.concatenate([[seg.t0], st])
        X = np.concatenate([seg.x0[None, :], sx])
        if hermite and self.model.gap_names:  # fixed step: a gap that changed sign inside a segment has no event
            self.missed += physics.sign_changes(self.model, T, X)
        if hermite and self.eval_times is not None:
            # fixed step: t_eval by cubic Hermite interpolation between the segment's steps
            te = self.pending_upto(seg.t1)
            if te.size:
                Xd = ev.batch(T, X)[0]
                seg.et.append(te)
                seg.ex.append(_hermite(T, X, Xd, te))
        # recorded steps: every step (the first segment's start too, h = 0); store_steps=False: the start only
        if seg.include_start:
            kt, kx, kh = T, X, np.concatenate([[0.0], np.diff(T)])
        else:
            kt, kx, kh = st, sx, np.diff(T)
        if not self.store_steps:
            k = 1 if seg.include_start else 0
            kt, kx, kh = kt[:k], kx[:k], kh[:k]
        self.rec.add_steps(kt, kh, np.full(kt.size, _ORDER[self.method], dtype=np.int64))
        if self.eval_times is None:
            ot, ox = kt, kx
        else:
            ot = np.concatenate(seg.et) if seg.et else np.zeros(0)
            ox = np.concatenate(seg.ex) if seg.ex else np.zeros((0, 2 * n))
        if ot.size:
            y, yp = self.dae_rows(ot, ox)
            sw = self.model.switch_vector(seg.active, seg.params)
            ch = ev.channels(self.model, ot, y, yp, sw)
            self.rec.add_points(ot, y, yp, np.broadcast_to(sw, (ot.size, sw.size)),
                                {k: np.ascontiguousarray(ch[:, i]) for i, k in enumerate(self.model.channel_names)})
        seg.st, seg.sx, seg.et, seg.ex = [], [], [], []  # handed over: a long run keeps no segment's data
        self.hand_over(seg)
        ev.set_terms(self.active, self.params)

    def hand_over(self, seg: Segment | None) -> None:
        """Give the recorder a segment (its times and modes) and the events so far, and flush it."""
        if seg is not None:
            self.rec.segments.append((seg.t0, seg.t1, seg.modes))
        self.rec.events.extend(self.events[self._handed:])
        self._handed = len(self.events)
        self.rec.flush()

    def dae_rows(self, t: NDArray, X: NDArray) -> tuple[NDArray, NDArray]:
        """(y, yp) rows of the DAE at ODE states X (rows (q, v)), with the evaluator's current terms."""
        Xd, Lam = self.ev.batch(t, X)
        n2 = 2 * self.n
        y = np.zeros((t.size, self.model.n_states))
        yp = np.zeros((t.size, self.model.n_states))
        y[:, :n2], y[:, n2:n2 + self.m], yp[:, :n2] = X, Lam, Xd
        return y, yp

    def handle_event(self, t: float, x: NDArray, roots_found: NDArray) -> None:
        y = self.dae_rows(np.array([t]), x[None, :])[0][0]
        state, new_events = contact_state.decide(self.model, self.state, t, y, roots_found)
        self.events.extend(new_events)
        self.set_state(state)
        self.n_restarts += 1
        if t > self.last_event_t:
            self.stall = 0
        self.stall += 1
        self.last_event_t = t

    def fail(self, t: float, why: str, hint: str) -> None:
        names = self.model.state_names

        def name(match: re.Match[str]) -> str:
            i = int(match.group(2))
            if i >= 2 * self.n:
                return match.group(0)
            label = f"d({names[i]})/dt" if match.group(1).startswith("right") else names[i]
            return f"{match.group(1)} {i} ({label})"

        why = re.sub(r"(right-hand side component|state component) (\d+)", name, why).replace("-nan", "nan")
        in_contact = [pair for pair, mode in self.modes.items() if mode == "contact"]
        where = f" with {', '.join(repr(p) for p in in_contact)} in contact" if in_contact else ""
        self.success, self.status = False, -1
        self.message = f"{METHOD_NAMES[self.method]} failed at t={t:.6g} s{where}: {why}. {hint}".rstrip()

    def count_step(self, t_old: float, t_new: float) -> bool:
        """Count an accepted step; False (after fail()) on a step-size collapse."""
        self.n_steps += 1
        if self.stall_guard.step(t_new, t_new - t_old):
            self.fail(t_new, "the " + self.stall_guard.describe(t_new, t_new - t_old),
                      "Try a looser rtol, a smaller max_step or another method.")
            return False
        return True

    def _progress(self, t: float) -> None:
        self.bar.update(t, f"events {len(self.events)}")

    def result(self, setup_time: float, solve_time: float) -> Result:
        self.hand_over(self.seg)  # a segment left open by a failure at its start has no output points
        self.seg = None
        stats: dict[str, Any] = {"n_steps": self.n_steps, **self.ev.counters()}
        stats.pop("n_fixed_steps", None)
        if self.method in ("radau", "bdf"):
            stats["n_lu"] = self.n_lu
        if self.method not in IMPLICIT_METHODS:
            stats["n_jac_evals"] = 0
        build = self.ev.build
        stats.update(n_events=len(self.events), n_restarts=self.n_restarts, solve_time=solve_time,
                     setup_time=setup_time, backend=self.ev.backend,
                     compile_time=build.compile_time if build else 0.0,
                     codegen_time=build.codegen_time if build else 0.0,
                     cache_hit=bool(build.cache_hit) if build else False)
        key_t, key_y, key_channels = self.rec.key_rows()
        found = physics.check_run(self.model, key_t, key_y, key_channels, self.y0, stats,
                                  from_state=self.from_state)
        if self.step is not None:
            found += physics.check_fixed_steps(self.model, self.events, self.step, self.missed)
        physics.issue(found, stacklevel=6)  # issue <- result <- _integrate <- ODESolver.run <- simulate <- the caller
        return self.rec.finish(stats=stats, success=self.success, status=self.status, message=self.message,
                               warnings=found)


def _hermite(T: NDArray, X: NDArray, Xd: NDArray, te: NDArray) -> NDArray:
    """Cubic Hermite interpolation of the rows of X (derivatives Xd) at times te within [T0, T-1]."""
    if T.size == 1:
        return np.repeat(X[:1], te.size, axis=0)
    k = np.clip(np.searchsorted(T, te, side="left"), 1, T.size - 1)
    return cubic_hermite(T[k - 1], X[k - 1], Xd[k - 1], T[k], X[k], Xd[k], te)
