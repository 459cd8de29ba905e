"""The one run driver: every method's run of :func:`daeclear.simulate`, over the narrow interface of
:mod:`daeclear.solvers.integrator` (as scipy's ``solve_ivp`` drives ``OdeSolver.step``).

:func:`run` sets a run up (the model, the checked consistent start, the output's size, the record of
the settings) and :class:`Driver` runs it: it asks the integrator to advance, records what it reports
(points chunk by chunk with the switch vector of their segment, steps, events, segments), and at a root
lets the contact rules decide (:func:`daeclear.assembly.contact_state.decide`) and restarts the
integrator from a consistent state in the new mode (:func:`consistent_restart`); every event passes
through :meth:`Driver.jump`. An integrator may decide simple pairs' switches itself (the compiled IDA
loop): the driver records them from ``Advance.auto_events`` and reads those pairs' states back. Whatever
stops the run (the end, a failure, Ctrl-C, a MemoryError, an exception), the result or the streamed
file holds what was computed; the physics checks read the finished run (:meth:`Driver.finish`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state, physics
from ..assembly.assemble import assemble
from ..assembly.dae_model import DAEModel
from ..core import options as opts
from ..core.automaton import EVENT_KINDS, ONSET
from ..core.errors import Interrupted, SolveError
from ..core.events import ContactEvent, EventRows
from ..core.progress import Progress
from ..engine.abi import DC_EV_CONTACT, DC_EV_HELD, DC_EV_KIND
from ..engine.session_base import Advance, AutoEvents, Session
from .integrator import Carried, Driven, Integrator, Jump, RootEvaluator, Terms, auto_pairs
from .recorder import Recorder, out_of_memory
from .tolerances import atol_record
from ..results.result import Result

if TYPE_CHECKING:
    from ..model.scene import Scene
    from .save_at import Output
    from .solver_options import SolverOptions

__all__ = ["STALL_EVENTS", "Continuation", "Driver", "consistent_restart", "consistent_start", "run"]

#: a run whose restarts produce STALL_EVENTS events without the time advancing fails (the event loop is stuck)
STALL_EVENTS = 50

#: Called with every :class:`Jump` of a run (:func:`run`'s ``observers``).
Observer = Callable[[Jump], None]


class Continuation:
    """The contact state carried from one run into the next that starts at its last state (the wear
    study's blocks): ``state`` is what the next run's pairs start in (None: from the start's gaps, each
    rate latched anew, as any run from a state) and, once a run ends, what its pairs ended in. A
    contact that goes on across the runs keeps its impact's approach speed, as in one run."""

    def __init__(self, state: contact_state.ContactState | None = None) -> None:
        self.state = state


def run(solver: Driven, scene: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
        settings: SolverOptions, on_failure: str, progress: bool, observers: Sequence[Observer] = (), *,
        checks: bool = True, carry: Continuation | None = None) -> Result:
    """Integrate ``scene`` (a Scene is assembled with ``settings.formulation`` or the solver's own) from
    ``t0`` to ``t_end`` with the solver's integrator (the :class:`daeclear.solvers.base.Solver` contract's
    ``run``); ``observers`` see every :class:`Jump`. An integrator that carries a quantity beside the
    states (:class:`~daeclear.solvers.integrator.Carried`: the sensitivities) has it jump at every event.
    ``checks=False``: a run that reaches its end is not checked (no warnings, no ``max_constraint_drift``;
    a caller judging each run itself, as the wear study's blocks); a failed or interrupted one is, for its
    message. ``carry``: a run that continues another from its last state (``y0``) starts its pairs in
    ``carry.state`` (:func:`~daeclear.assembly.contact_state.continued_state`: each keeps its latched approach
    speed) and leaves the state they end in there."""
    setup_start = time.perf_counter()
    if isinstance(scene, DAEModel):
        model = scene
    else:
        model = assemble(scene, settings.formulation or solver.formulation, track_work=settings.track_work)
    y0 = None if y0 is None else opts.state(y0, model.n_states)
    save.check_size(step=settings.step, n_states=model.n_states,
                    n_channels=len(model.channel_names))  # before the integrator: nothing compiled or run
    integrator = solver.integrator(model, t_end, save, settings)
    carried = integrator if isinstance(integrator, Carried) else None
    from_state = y0 is not None
    try:
        start, start_yp = consistent_start(model, t0, y0, settings, integrator.session)
        record: dict[str, Any] = {
            "method": solver.name, "start": "state" if from_state else settings.start, "rtol": settings.rtol,
            "atol": atol_record(settings.atol_value()), "max_step": settings.max_step, "t_end": t_end,
            "backend": integrator.backend}
        if settings.step is not None:
            record["step"] = settings.step
        if carried is not None:
            record["sensitivities"] = list(carried.names)
        if t0 != 0.0:
            record["t0"] = t0
        rec = Recorder(model, parameters={**model.parameters, "simulate": record}, method=solver.name,
                       stream_to=save.stream_to, keep_data=save.keep_data, lazy_rows=integrator.lazy_rows)
    except BaseException:
        integrator.close()
        raise
    declared = start if record["start"] == "declared" else None  # the start checks concern a declared state
    driver = Driver(model, integrator, rec, save, t_end, progress, observers, carried)
    driver.checks = checks
    driver.carry = carry
    return driver.run(t0, start, start_yp, declared, from_state, on_failure, time.perf_counter() - setup_start)


def consistent_start(model: DAEModel, t0: float, y0: NDArray | None, settings: SolverOptions,
                     session: Session | None) -> tuple[NDArray, NDArray]:
    """The run's consistent start: ``settings.start``'s, or a given state's q and v kept (GGL:
    projected), multipliers and derivatives recomputed at ``t0``, held to the given start's limit."""
    if y0 is None:
        return model.initial_state(session=session, start=settings.start, allow_penetration=settings.allow_penetration)
    y, yp = model.consistent_state(t0, y0, session=session, project=True)
    if not settings.allow_penetration:
        physics.check_start_penetration(model, y, yp, session, given=True)
    return y, yp


def consistent_restart(model: DAEModel, integrator: Integrator, t: float, y: NDArray, yp: NDArray, terms: Terms,
                       found: NDArray | None) -> tuple[NDArray, NDArray, bool]:
    """The consistent state to restart from at ``t`` in the mode of ``terms``: index-1 keeps q and v (the
    integrator's :meth:`~daeclear.solvers.integrator.Integrator.consistent`); GGL projects them onto the
    constraint manifold, unprojected when the projection moves a root function that did not fire across
    zero (it would never be found again: a missed contact). The compiled loop's rule (project_kept_roots)
    for the switches it decides itself. The flag: whether the state was projected (sensitivities follow it)."""
    if model.formulation != "ggl":
        return (*integrator.consistent(t, y, terms), False)
    extras = integrator.extras
    forces = model.term_forces(t, y, terms.active, terms.params, extras)
    projected = model.consistent_state(t, y, forces, extras, project=True)
    if not model.gap_names:
        return (*projected, True)
    roots = integrator.root_evaluator
    g0, g1 = _roots(model, roots, t, y, yp), _roots(model, roots, t, projected[0], yp)
    # found: the gaps, then (a run with sensitivities) its kinks, which the stacked session's roots hold too
    quiet = np.zeros(g0.shape, bool) if found is None else np.asarray(found).ravel()[:g0.size] == 0
    if np.any(quiet & (g0 != 0) & ((g0 > 0) != (g1 > 0))):
        return (*model.consistent_state(t, y, forces, extras, project=False), False)
    return (*projected, True)


def _roots(model: DAEModel, session: RootEvaluator | None, t: float, y: NDArray, yp: NDArray) -> NDArray:
    """The root functions at one point: in the integrator's library (:attr:`Integrator.root_evaluator`), else
    CasADi's."""
    if session is not None:
        return session.roots(t, y, yp)
    roots = model.functions.roots
    assert roots is not None  # a model with gap names has root functions
    return np.array(roots(t, y, yp, model.parameter_values), dtype=float).ravel()


class Driver:
    """One run's state: its contact state and what follows from it (terms, modes, switch vector), the
    current segment's start, the reported points not yet completed, the outcome."""

    def __init__(self, model: DAEModel, integrator: Integrator, rec: Recorder, save: Output, t_end: float,
                 progress: bool, observers: Sequence[Observer] = (), carried: Carried | None = None) -> None:
        self.run_start = time.perf_counter()
        self.progress_line = Progress(t_end, unit="s", desc="simulate", enabled=progress)
        self.model, self.integrator, self.rec = model, integrator, rec
        self.t_end, self.times, self.store_steps = t_end, save.times, save.steps
        self.observers = list(observers)
        self.carried = carried  # what jumps with the states at every event (sensitivities), or None
        self.state: contact_state.ContactState = ()
        self.active: list[bool] = []
        self.params: list[NDArray] = []
        self.modes: dict[str, str] = {}
        self.switch = np.zeros(0)
        # reported points not completed yet: t, the integrator's rows and each row's switch vector
        self.raw: list[tuple[NDArray, NDArray, NDArray]] = []
        self.events, self.segments = rec.events, rec.segments
        # every event, for the fixed-step checks only (a long run's memory does not grow with its events)
        self.kept_events: list[ContactEvent] | None = [] if integrator.fixed_step is not None else None
        # each pair's last switch (t, term on), for the failure message: was a deep pair carrying a force?
        self.last_terms: dict[str, tuple[float, bool]] = {}
        self.auto = auto_pairs(model)  # the pairs an integrator may decide itself, in Advance.auto_events' order
        self.checked_rows: tuple[NDArray, NDArray] = (np.zeros(0), np.zeros((0, 0)))  # (t, y) the checks read
        self.t = self.seg_start = 0.0  # seg_start: nan once the last segment is closed
        self.y = self.yp = np.zeros(0)
        self.y0: NDArray | None = None  # a declared start, for the physics checks
        self.from_state = False
        self.success, self.status, self.message = True, 0, "end of the time span reached"
        self.failure = ""  # a failure's when, where and why, without the advice
        self.n_restarts = self.stall = 0
        self.last_event_t = -math.inf
        self.interrupted = False
        self.checks = True  # False: a successful run's physics checks are left out (run's ``checks``)
        self.carry: Continuation | None = None  # the contact state to start in and to leave (run's ``carry``)

    # ---------------------------------------------------------------- the run
    def run(self, t0: float, y0: NDArray, yp0: NDArray, declared: NDArray | None, from_state: bool,
            on_failure: str, setup_time: float) -> Result:
        """Integrate from the consistent start ``(y0, yp0)`` to the end, a failure or Ctrl-C; always
        return (or attach) what was computed."""
        self.y0, self.from_state = declared, from_state
        self.t = self.seg_start = t0
        try:
            self.begin(t0, y0, yp0)
            self.advance_to_end()
        except KeyboardInterrupt:  # Ctrl-C: keep what was computed, then stop the caller too (Interrupted)
            self.success, self.status = False, -1
            self.message = f"interrupted by the user at t={self.t:.6g} s"
            self.interrupted = True
        except MemoryError:  # keep (and, streamed, save) what was computed: the chunks before this one
            self.raw.clear()
            self.success, self.status = False, -1
            self.message = out_of_memory(self.t)
        except BaseException as exc:  # anything else: a streamed file keeps what it holds, then the error goes on
            self.progress_line.close()
            self.rec.abort(exc)
            self.integrator.close()
            raise
        if not math.isnan(self.seg_start):  # stopped inside a segment: it ends where the run stopped
            self.segments.append((self.seg_start, self.t, dict(self.modes)))
        if self.carry is not None:
            self.carry.state = self.state
        return self.finish(on_failure, setup_time)

    def begin(self, t0: float, y0: NDArray, yp0: NDArray) -> None:
        """The contact modes from the state at ``t0``, the start recorded, the integrator started."""
        model = self.model
        carried = None if self.carry is None else self.carry.state
        self.set_state(contact_state.start_state(model, t0, y0) if carried is None
                       else contact_state.continued_state(model, t0, y0, carried))
        self.last_terms = {name: (t0, contact_state.pair_state(model, self.state, root).term_on)
                           for root, name in enumerate(model.gap_names)}
        y, yp = y0, yp0
        if any(self.active):  # in contact at the start: the multipliers and derivatives of that mode
            y, yp = self.integrator.consistent(t0, y0, self.terms())
        self.switch = model.switch_vector(self.active, self.params)
        if self.store_steps:  # the start is the first step kept (h = 0); without steps none, not a phantom one
            self.rec.add_steps(np.array([t0]), np.array([0.0]), np.array([self.integrator.order]))
        if self.times is None or self.times.window(0, 1)[0] == t0:  # the start point is reported
            self.raw.append((np.array([t0]), y[None, :], self.switch[None, :]))
        self.rec.session = self.integrator.extras  # the checked channels in the run's library while it is open
        self.y, self.yp = y, yp
        self.integrator.start(t0, y, yp, self.terms(), self.state)

    def advance_to_end(self) -> None:
        """Advance until the end, a failure or an exception, deciding the roots on the way."""
        integrator = self.integrator
        while True:
            adv = integrator.advance()
            self.record(adv)
            if integrator.decides:
                self.take_pair_states()
            self.t, self.y, self.yp = adv.t, adv.y, adv.yp
            if adv.status == "interrupted":  # Ctrl-C inside the integrator's loop: its steps are kept
                raise KeyboardInterrupt
            if adv.status == "chunk":  # a buffer of the integrator is full: hand it over, go on
                self.flush()
                self.progress_line.update(self.t, f"events {self.rec.n_events}")
                continue
            self.progress_line.update(self.t, f"events {self.rec.n_events}")
            if adv.status == "error":
                self.close_segment()
                in_contact = [pair for pair, mode in self.modes.items() if mode == "contact"]
                self.fail(adv.t, adv.flag_name, adv.message, integrator.advice(adv, in_contact))
                return
            if adv.status == "tstop" or self.t >= self.t_end:
                self.close_segment()
                return
            if not self.at_root(adv):
                return

    def at_root(self, adv: Advance) -> bool:
        """At a root the integrator returned let every contact element decide its new modes; restart the
        integrator from a consistent state when anything switched, when it cannot go on from a root, or
        at a guarded root; each event passes through :meth:`jump`. False: the run stopped (stalled)."""
        model, t, integrator = self.model, self.t, self.integrator
        before, before_modes = self.terms(), self.modes
        found = adv.roots_found
        state, new_events = contact_state.decide(model, self.state, t, self.y, found)
        self.events.extend(new_events)
        if self.kept_events is not None:
            self.kept_events.extend(new_events)
        self.set_state(state)
        roots = {name: root for root, name in enumerate(model.gap_names)}  # faces' events have no root
        self.last_terms.update((e.pair, (e.t, contact_state.pair_state(model, state, roots[e.pair]).term_on))
                               for e in new_events if e.pair in roots)
        terms = self.terms()
        switched = not _same_terms(before, terms)
        if not switched and integrator.resumes_at_roots and not guarded_root(before.directions, found):
            if self.observers or self.carried is not None:
                self.jump(Jump(t, self.y, self.yp, self.y, self.yp, found, tuple(new_events), state, restarted=False))
            return True  # nothing switched: the integrator goes on from the root, in the same segment
        new_segment = switched or not integrator.resumes_at_roots
        if new_segment:
            self.segments.append((self.seg_start, t, before_modes))
            self.seg_start = t
            self.n_restarts += 1  # a switch's restart (an integrator's own switches: counted by their events)
        if t > self.last_event_t:
            self.stall = 0
        self.stall += 1
        self.last_event_t = t
        if self.stall >= STALL_EVENTS:
            self.seg_start = math.nan
            self.fail(t, "", f"{self.stall} events at the same time: the event loop does not advance", "")
            return False
        self.flush()  # the rows of the segment that ends, completed in its mode
        y, yp, projected = consistent_restart(model, integrator, t, self.y, self.yp, terms, found)
        self.switch = model.switch_vector(terms.active, terms.params)
        if self.observers or self.carried is not None:
            self.jump(Jump(t, self.y, self.yp, y, yp, found, tuple(new_events), state, restarted=True,
                           projected=projected))
        integrator.restart(t, y, yp, terms)
        self.y, self.yp = y, yp
        return True

    def jump(self, jump: Jump) -> None:
        """The one place every event of the run passes (see :class:`Jump`; made only when observed or
        carried): a quantity integrated beside the states jumps here (``carried``: the sensitivities of
        :class:`~daeclear.solvers.sensitivity_carrier.SensitivityCarrier`), then the observers see it."""
        if self.carried is not None:
            self.carried.jump(jump)
        for observer in self.observers:
            observer(jump)

    # ---------------------------------------------------------------- contact state
    def set_state(self, state: contact_state.ContactState) -> None:
        """Take the run's new contact state, and the terms and modes that follow from it."""
        self.state = state
        self.active, self.params = contact_state.switches(self.model, state)
        self.modes = contact_state.modes(self.model, state)

    def take_pair_states(self) -> None:
        """The run's contact state of the pairs the integrator decides, read from it (no replay)."""
        self.set_state(contact_state.with_pairs(self.model, self.state, self.integrator.pair_states()))

    def terms(self) -> Terms:
        """What the integrator integrates with in the run's contact state."""
        return Terms(self.active, self.params, contact_state.root_directions(self.model, self.state))

    # ---------------------------------------------------------------- recording
    def close_segment(self) -> None:
        """The current segment ends where the run stopped (and no other follows)."""
        self.segments.append((self.seg_start, self.t, dict(self.modes)))
        self.seg_start = math.nan

    def record(self, adv: Advance) -> None:
        """Record the integrator's own contact switches (:meth:`record_switches`) and keep the advance's
        points, each with the switch vector of the segment it belongs to."""
        if self.store_steps and adv.step_t.size:  # the steps of every segment at once
            self.rec.add_steps(adv.step_t, adv.step_h, adv.step_order)
        rows = (adv.step_t, adv.step_y) if self.times is None else (adv.eval_t, adv.eval_y)
        if (self.times is None and not self.store_steps) or not rows[0].size:  # no points to keep
            if adv.auto_events is not None:
                self.record_switches(adv.auto_events)
            return
        if adv.auto_events is None:
            switch = np.broadcast_to(self.switch, (rows[0].size, self.switch.size))
        else:  # a row at a restart's time belongs to the segment that ends there
            times, switches = self.record_switches(adv.auto_events)
            ends = [0, *rows[0].searchsorted(times, side="right").tolist(), rows[0].size]
            switch = np.repeat(switches, [b - a for a, b in zip(ends, ends[1:])], axis=0)
        self.raw.append((*rows, switch))

    def record_switches(self, auto: AutoEvents) -> tuple[list[float], NDArray]:
        """Record the switches the integrator decided in one advance: events, modes and segments in time
        order (the pairs' states are its own, read after the advance). Return the restart times and the
        switch vectors before the first restart and after each."""
        segments, modes, info = self.segments, self.modes, self.auto
        switch = self.switch.tolist()  # plain floats while recording: one array at the end
        switches: list[list[float]] = [switch]
        times: list[float] = []
        kinds = auto.info[:, DC_EV_KIND].tolist()
        term_on = (auto.info[:, DC_EV_CONTACT] | auto.info[:, DC_EV_HELD]).tolist()
        ys = auto.y
        ys.flags.writeable = False  # the events own its rows (read-only views)
        event_t, pairs = auto.t.tolist(), auto.pair.tolist()
        names = [info[p].name for p in pairs]
        rows = EventRows(event_t, names, [EVENT_KINDS[k] for k in kinds], auto.rate.tolist(), ys)
        self.rec.add_event_rows(rows)
        for i, (t, p, latched) in enumerate(zip(event_t, pairs, auto.latched.tolist())):
            if not times or t != times[-1]:  # a restart: the segment before it ends
                segments.append((self.seg_start, t, dict(modes)))
                self.seg_start = t
                times.append(t)
                switch = switch.copy()
                switches.append(switch)
            pair = info[p]
            kind = kinds[i]
            modes[pair.name] = "contact" if kind == ONSET else "free"
            self.last_terms[pair.name] = (t, bool(term_on[i]))
            switch[pair.column] = 1.0 if term_on[i] else 0.0  # as the integrator sets its term
            if pair.needs_speed:
                switch[pair.column + 1] = latched
        if self.observers:
            self.integrator_jumps(event_t, list(rows))
        switch_rows = np.array(switches)
        self.switch = switch_rows[-1].copy()
        self.n_restarts += len(times)
        return times, switch_rows

    def integrator_jumps(self, times: list[float], events: list[ContactEvent]) -> None:
        """One :class:`Jump` for each time at which the integrator switched pairs itself."""
        k = 0
        while k < len(times):
            j = k
            while j < len(times) and times[j] == times[k]:
                j += 1
            self.jump(Jump(times[k], events[k].y, None, None, None, None, tuple(events[k:j]), None,
                           restarted=True, by_integrator=True))
            k = j

    def flush(self) -> None:
        """Hand the raw points, events and segments to the recorder; rows the integrator leaves
        incomplete are completed first (multipliers and accelerations from q and v), unless a result in
        memory makes its IDA rows consistent when they are first read."""
        raw = self.raw
        if self.carried is not None and self.rec.writer is not None:  # streamed: S goes with its rows
            self.carried.stream(self.rec.writer)
        if self.rec.consistent_when_read:  # as the integrator left them, joined once (by the recorder)
            for t, y, switch in raw:
                self.rec.add_points(t, y, None, switch)
        elif raw:
            joined = len(raw) > 1  # joined arrays are the driver's own: completed in place
            if joined:
                out_t, out_y, out_switch = (np.concatenate(column) for column in zip(*raw))
            else:
                out_t, out_y, out_switch = raw[0]
            out_y, out_yp, channels = self.integrator.complete(out_t, out_y, out_switch, in_place=joined)
            self.rec.add_points(out_t, out_y, out_yp, out_switch, channels)
        raw.clear()
        self.rec.flush()

    # ---------------------------------------------------------------- the end
    def fail(self, t: float, flag: str, why: str, advice: str) -> None:
        """The run failed at ``t``: when, where (the pairs in contact), why, and what to try."""
        in_contact = [pair for pair, mode in self.modes.items() if mode == "contact"]
        where = f" with {', '.join(repr(p) for p in in_contact)} in contact" if in_contact else ""
        detail = f": {why.rstrip('.')}" if why else ""
        self.success, self.status = False, -1
        self.failure = f"{self.integrator.name} failed at t={t:.6g} s{f' ({flag})' if flag else ''}{where}{detail}."
        self.message = f"{self.failure} {advice}".rstrip()

    def finish(self, on_failure: str, setup_time: float) -> Result:
        """Flush, check the physics, build the Result; raise (with it) on Ctrl-C or a failure when asked."""
        stats = dict(self.integrator.stats())
        found = self.checked_output(stats, setup_time)
        # issue <- finish <- Driver.run <- run <- DrivenSolver.run <- simulate <- the caller
        physics.issue(found, stacklevel=7)
        t, message = self.t, self.message
        deep = [w for w in found if w["kind"] == "penetration" and w["t"] <= t]
        if not self.success and not self.interrupted and deep and self.integrator.fixed_step is None:
            w = deep[0]  # the advice must fit the cause: not a tolerance problem, so the solver's is left out
            message = self.failure + penetration_advice(w, self.lost_onset(w["where"], w["t"]))
        result = self.rec.finish(stats=stats, success=self.success, status=self.status, message=message,
                                 warnings=found)
        if self.carried is not None:
            self.carried.attach(result)
        if self.interrupted or self.rec.interrupted:
            raise Interrupted(f"simulate: {message}; partial result in .result.", result)
        if not self.success and on_failure == "raise":
            raise SolveError(message + " Partial result in .result.", result)
        return result

    def lost_onset(self, pair: str, t: float) -> bool:
        """Whether ``pair`` was free at ``t`` (its force term off) with its gap (the root the integrator
        watches, guide ends included) in contact beyond round-off: an onset the solver did not report."""
        key_t, key_y = self.checked_rows
        rows = np.flatnonzero(key_t == t)
        if term_on_at(self.last_terms, pair, t) or not rows.size:
            return False
        gap = gap_at(self.model, pair, key_y[rows[0]])
        return gap is not None and gap > physics.GAP_ROUNDING

    def checked_output(self, stats: dict[str, Any], setup_time: float) -> list[dict[str, Any]]:
        """Hand over the last points, complete ``stats`` and run the physics checks (their findings);
        the integrator stays open through the checks: they evaluate the model in its library."""
        model, rec, integrator = self.model, self.rec, self.integrator
        post_start = time.perf_counter()
        try:
            try:
                self.flush()
            except BaseException as exc:
                rec.abort(exc)
                raise
            self.progress_line.update(self.t_end if self.success else self.t, f"events {rec.n_events}")
            self.progress_line.close()
            stats.update(n_events=rec.n_events, n_restarts=self.n_restarts, setup_time=setup_time,
                         wall_time=setup_time + time.perf_counter() - self.run_start,
                         output_time=time.perf_counter() - post_start)
            if model.gap_names:  # the run's end state of the storm guard (in the run's contact state)
                stats["held_pairs"] = [model.gap_names[root] for logic in model.contacts for root in logic.roots
                                       if contact_state.pair_state(model, self.state, root).held]
            if not self.checks and self.success and not self.interrupted and not rec.interrupted:
                return []
            key_t, key_y, key_channels = rec.key_rows()
            self.checked_rows = (key_t, key_y)  # the failure message reads the deepest pair's gap there
            found = physics.check_run(model, key_t, key_y, key_channels, self.y0, stats, integrator.extras,
                                      from_state=self.from_state)
            if self.kept_events is not None and integrator.fixed_step is not None:
                found += physics.check_fixed_steps(model, self.kept_events, integrator.fixed_step, integrator.missed)
            return found
        finally:
            rec.session = None  # the session closes: later channels open their own
            integrator.close()


def _same_terms(a: Terms, b: Terms) -> bool:
    """Whether two segments integrate with the same terms and watch the roots the same way."""
    return (a.active == b.active and all(np.array_equal(x, y) for x, y in zip(a.params, b.params))
            and (b.directions is None or (a.directions is not None and np.array_equal(a.directions, b.directions))))


def guarded_root(watched: NDArray | None, found: NDArray | None) -> bool:
    """Whether a root was found in the direction its pair watched (``watched``) and decided nothing: IDA
    restarts then (as the compiled loop), since going on from a gap exactly zero is IDA's "root found at
    and very near t" error."""
    if watched is None or found is None:
        return False
    found = np.ravel(found)
    return bool(np.any((found != 0) & (found == np.ravel(watched))))


def term_on_at(last: dict[str, tuple[float, bool]], pair: str, t: float) -> bool:
    """Whether ``pair``'s force term was on at ``t``, from its last switch (time, term on) in ``last``:
    known from that switch on; before it, or for a name that is no pair, counted as on (so that a lost
    onset is claimed only for a pair that stayed free from its last switch to ``t``)."""
    when, on = last.get(pair, (math.inf, True))
    return on if when <= t else True


def gap_at(model: DAEModel, pair: str, y: NDArray) -> float | None:
    """The gap watched for ``pair`` (> 0 in contact) at state ``y``; None for a name that is no pair."""
    for logic in model.contacts:
        for i, root in enumerate(logic.roots):
            if model.gap_names[root] == pair:
                gaps = logic.rate(y[:model.n_q], y[model.n_q:2 * model.n_q])[0]
                return float(np.ravel(gaps)[i])
    return None


def penetration_advice(warning: dict[str, Any], lost_onset: bool) -> str:
    """The failure message's sentence on a penetration beyond the joint's limit (``warning``, a physics
    record). Normally the contact carried more than the joint can; a pair inside its wall while free
    (``lost_onset``) had no force, which no load causes: the solver missed its onset, a defect."""
    w = warning
    if lost_onset:
        return (f" Before it, '{w['where']}' was {w['value']:.3g} m inside its wall at t={w['t']:.6g} s while free "
                f"(no contact force; limit {w['limit']:.3g} m): the solver lost that contact's onset, a defect of "
                "daeclear, not a load the joint cannot carry; please report it with the scene and rtol.")
    return (f" Before it, '{w['where']}' penetrated {w['value']:.3g} m at t={w['t']:.6g} s, more than "
            f"its limit {w['limit']:.3g} m: the contact carries more than the joint can (friction, speed "
            "or load); tolerances will not fix that.")
