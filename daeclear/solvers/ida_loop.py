"""The IDA segment loop of one run: advance, record contact switches, restart, finish.

Between two roots of the gap functions the active contact terms are fixed. The compiled loop may
decide simple pairs' switches itself (:meth:`SegmentLoop.record_advance`); any other root returns to
Python, where the contact rules decide (:func:`daeclear.assembly.contact_state.decide`) and IDA
restarts from a consistent state. Points go to the recorder chunk by chunk (bounded memory when
streamed), and whatever stops the run the result holds what was computed (:meth:`SegmentLoop.finish`).
"""

from __future__ import annotations

import itertools
import math
import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core import options as opts
from ..assembly import physics
from ..assembly.assemble import DAEModel
from ..assembly import contact_state
from ..core.automaton import EVENT_KINDS, ONSET
from ..engine.abi import DC_EV_CONTACT, DC_EV_HELD, DC_EV_KIND
from ..engine.session_base import AutoEvents
from ..core.errors import Interrupted, SolveError
from .recorder import Recorder, out_of_memory
from ..core.progress import Progress
from ..core.events import EventRows
from ..results.result import Result

#: Output times handed to the compiled loop at a time: their rows are emptied between windows.
EVAL_WINDOW = 4096
# Failures in contact that plain Coulomb friction causes when the contact sticks.
STICKING_FLAGS = ("DC_STEP_COLLAPSE", "IDA_CONV_FAIL", "IDA_ERR_FAIL")


class SegmentLoop:
    """One run's loop state: its contact state and what follows from it (active terms, modes, the switch
    vector), the current segment's start and the reported points not yet made consistent."""

    def __init__(self, model: DAEModel, session: Any, rec: Recorder, t0: float, y0: NDArray, yp0: NDArray,
                 t_end: float, eval_times: opts.OutputTimes | None, store_steps: bool, progress: bool) -> None:
        """Set the contact modes from the state at ``t0`` and record the start point."""
        self.run_start = time.perf_counter()
        self.progress_line = Progress(t_end, unit="s", desc="simulate", enabled=progress)
        self.model, self.session, self.rec = model, session, rec
        self.t_end, self.eval_times, self.store_steps = t_end, eval_times, store_steps
        self.active: list[bool] = []
        self.params: list[NDArray] = []
        self.modes: dict[str, str] = {}
        self.checked_rows: tuple[NDArray, NDArray] = (np.zeros(0), np.zeros((0, 0)))  # (t, y) the checks read
        self.set_state(contact_state.start_state(model, t0, y0))
        # each pair's last switch (t, term on), for the failure message: was a deep pair carrying a force?
        # (one entry a pair: a long run's memory does not grow with its events)
        self.last_terms = {name: (t0, contact_state.pair_state(model, self.state, root).term_on)
                           for root, name in enumerate(model.gap_names)}
        y, yp = y0, yp0
        if any(self.active):
            y, yp = model.consistent_state(t0, y0, model.term_forces(t0, y0, self.active, self.params, session),
                                           session)
        self.switch = model.switch_vector(self.active, self.params)
        # reported points not made consistent yet: t, IDA's raw y (no yp) and each row's switch vector
        self.raw: list[tuple[NDArray, NDArray, NDArray]] = []
        rec.add_steps(np.array([t0]), np.array([0.0]), np.array([0]))
        self.i_eval = int(eval_times is not None and eval_times.window(0, 1)[0] == t0)  # the next output time
        if eval_times is None or self.i_eval:  # the start point is reported
            self.raw.append((np.array([t0]), y[None, :], self.switch[None, :]))
        self.events, self.segments = rec.events, rec.segments
        rec.session = session  # the checked channels in the run's library while it is open
        self.t, self.y, self.yp, self.y0 = t0, y, yp, y0
        self.t_start = t0
        self.seg_start = t0  # nan once the last segment is closed
        self.success, self.status, self.message = True, 0, "end of the time span reached"
        self.failure = ""  # a failure's when, where and why, without the advice
        self.n_restarts = 0
        self.interrupted = False
        self.c_layout = False  # the compiled loop makes the points consistent itself
        self.c_decides = False  # the compiled loop decides every contact switch itself
        # per pair the compiled loop decides: (its logic, root, name, switch vector column of its term, the
        # term's parameter is the latched approach speed)
        self.auto_info: list[tuple[Any, int, str, int, bool]] = []

    def set_state(self, state: contact_state.ContactState) -> None:
        """Take the run's new contact state, and the terms and modes that follow from it."""
        self.state = state
        self.active, self.params = contact_state.switches(self.model, state)
        self.modes = contact_state.modes(self.model, state)

    def run(self, on_failure: str, setup_time: float, sim_params: dict[str, Any]) -> Result:
        """Integrate to the end, a failure or Ctrl-C; always return (or attach) what was computed."""
        try:
            self.prepare()
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
            self.session.close()
            raise
        if not math.isnan(self.seg_start):  # stopped inside a segment: it ends where the run stopped
            self.segments.append((self.seg_start, self.t, dict(self.modes)))
        return self.finish(on_failure, setup_time, sim_params)

    def prepare(self) -> None:
        """Start IDA; let the compiled loop make states consistent and decide simple pairs' switches."""
        model, session = self.model, self.session
        self.c_layout = session.set_layout(model.layout(project=model.formulation == "ggl"))
        session.reinit(self.t, self.y, self.yp, self.active, self.params,
                       contact_state.root_directions(model, self.state))
        if model.auto_pairs:  # simple pairs: each one's rule and start state from its logic object
            owners = {root: logic for logic in model.contacts for root in logic.roots}
            columns = list(itertools.accumulate((1 + term.n_params for term in model.terms), initial=0))
            self.auto_info = [(owners[root], root, owners[root].pair_name(root), columns[term], bool(needs))
                              for root, term, _, needs, _ in model.auto_pairs]
            self.c_decides = self.c_layout and session.set_auto_events(
                model.auto_pairs, storms=[logic.storm for logic, *_ in self.auto_info],
                states=[contact_state.pair_state(model, self.state, root) for _, root, *_ in self.auto_info])

    def advance_to_end(self) -> None:
        """Advance chunk by chunk and segment by segment until the end, a failure or an exception."""
        while True:
            adv = self.advance()
            self.record_advance(adv)
            if self.c_decides:
                self.take_pair_states()
            self.check_decisions(adv)
            self.t, self.y, self.yp = adv.t, adv.y, adv.yp
            if adv.status == "interrupted":  # Ctrl-C inside the python backend's loop: its steps are kept
                raise KeyboardInterrupt
            if adv.status == "chunk":  # a buffer of the compiled loop is full: hand it over, go on
                self.flush()
                self.progress_line.update(self.t, f"events {self.rec.n_events}")
                continue
            self.progress_line.update(self.t, f"events {self.rec.n_events}")
            if adv.status == "error":
                self.close_segment()
                self.success, self.status = False, -1
                self.failure, advice = _failure_message(
                    self.model, adv, self.modes, steps_needed(self.session.max_steps, self.t_start, adv.t, self.t_end))
                self.message = f"{self.failure} {advice}"
                return
            if adv.status == "tstop" or self.t >= self.t_end:
                self.close_segment()
                return
            self.decide_roots(adv)

    def advance(self) -> Any:
        """One call of the session's loop, with the next window of output times (if any)."""
        window = None
        if self.eval_times is not None:  # the next output times (compiled loop: at most EVAL_WINDOW of them)
            self.i_eval, window = _eval_window(self.eval_times, self.i_eval, self.session.eval_from,
                                               EVAL_WINDOW if self.c_layout else self.eval_times.size)
        adv = self.session.advance(self.t_end, window, self.store_steps, store_states=self.eval_times is None,
                                   chunked=True, store_yp=False)
        self.i_eval += adv.eval_t.size
        return adv

    def close_segment(self) -> None:
        """The current segment ends where the run stopped (and no other follows)."""
        self.segments.append((self.seg_start, self.t, dict(self.modes)))
        self.seg_start = math.nan

    def record_advance(self, adv: Any) -> None:
        """Record the compiled loop's own contact switches (:meth:`record_switches`) and keep the
        advance's points, each with the switch vector of the segment it belongs to."""
        if self.store_steps and adv.step_t.size:  # the steps of every segment at once
            self.rec.add_steps(adv.step_t, adv.step_h, adv.step_order)
        rows = (adv.step_t, adv.step_y) if self.eval_times is None else (adv.eval_t, adv.eval_y)
        if (self.eval_times is None and not self.store_steps) or not rows[0].size:  # no points to keep
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
        """Record the switches the compiled loop decided in one advance: events, modes and segments
        in time order (the pairs' states are the loop's, read by :meth:`take_pair_states`). Return the
        restart times and the switch vectors before the first restart and after each."""
        segments, modes, info = self.segments, self.modes, self.auto_info
        switch = self.switch.tolist()  # plain floats while recording: one array at the end
        switches: list[list[float]] = [switch]
        times: list[float] = []
        kinds = auto.info[:, DC_EV_KIND].tolist()
        term_on = (auto.info[:, DC_EV_CONTACT] | auto.info[:, DC_EV_HELD]).tolist()
        ys = auto.y
        ys.flags.writeable = False  # the events own its rows (read-only views)
        event_t, pairs = auto.t.tolist(), auto.pair.tolist()
        names = [info[p][2] for p in pairs]
        self.rec.add_event_rows(EventRows(event_t, names, [EVENT_KINDS[k] for k in kinds], auto.rate.tolist(), ys))
        for i, (t, p, latched) in enumerate(zip(event_t, pairs, auto.latched.tolist())):
            if not times or t != times[-1]:  # a restart: the segment before it ends
                segments.append((self.seg_start, t, dict(modes)))
                self.seg_start = t
                times.append(t)
                switch = switch.copy()
                switches.append(switch)
            _, _, name, column, needs = info[p]
            kind = kinds[i]
            modes[name] = "contact" if kind == ONSET else "free"
            self.last_terms[name] = (t, bool(term_on[i]))
            switch[column] = 1.0 if term_on[i] else 0.0  # as the compiled loop sets its term
            if needs:
                switch[column + 1] = latched
        rows = np.array(switches)
        self.switch = rows[-1].copy()
        self.n_restarts += len(times)
        return times, rows

    def take_pair_states(self) -> None:
        """The run's contact state of the pairs the compiled loop decides, read from the loop (no replay)."""
        pairs = self.session.pair_states()
        self.set_state(contact_state.with_pairs(self.model, self.state,
                                                {root: st for (_, root, *_), st in zip(self.auto_info, pairs)}))

    def check_decisions(self, adv: Any) -> None:
        """Turn the advance into an internal error when the compiled loop left a root to Python."""
        if self.c_decides and adv.status == "root":
            adv.status, adv.flag_name = "error", "DC_EVENT_MISMATCH"
            adv.message = "internal: the compiled event loop left a contact root undecided"

    def decide_roots(self, adv: Any) -> None:
        """At a root returned to Python let every contact element decide its new modes; restart IDA
        from a consistent state when anything switched (else it goes on in the same segment)."""
        model, t = self.model, self.t
        before = (self.active, self.params, contact_state.root_directions(model, self.state), self.modes)
        state, new_events = contact_state.decide(model, self.state, t, self.y, adv.roots_found)
        self.events.extend(new_events)
        self.set_state(state)
        roots = {name: root for root, name in enumerate(model.gap_names)}  # faces' events have no root
        self.last_terms.update((e.pair, (e.t, contact_state.pair_state(model, state, roots[e.pair]).term_on))
                               for e in new_events if e.pair in roots)
        active, params = self.active, self.params
        directions = contact_state.root_directions(model, state)
        assert adv.roots_found is not None  # a root return always says which roots
        unchanged = (before[0] == active and all(np.array_equal(a, b) for a, b in zip(before[1], params))
                     and (directions is None or (before[2] is not None and np.array_equal(before[2], directions))))
        if unchanged and not guarded_root(before[2], adv.roots_found):
            return  # nothing switched: IDA goes on from the root without a restart, in the same segment
        if not unchanged:
            self.segments.append((self.seg_start, t, before[3]))
            self.seg_start = t
        self.y, self.yp = _restart_state(model, self.session, t, self.y, self.yp,
                                         model.term_forces(t, self.y, active, params, self.session),
                                         adv.roots_found)
        self.switch = model.switch_vector(active, params)
        self.session.reinit(t, self.y, self.yp, active, params, directions)
        self.n_restarts += not unchanged  # a switch's restart (the compiled loop counts them by its events)
        self.flush()

    def flush(self) -> None:
        """Hand the raw points, events and segments to the recorder; points for a file are made consistent
        first (multipliers and accelerations recomputed from q and v: IDA does not converge them)."""
        model, session, raw = self.model, self.session, self.raw
        if self.rec.consistent_when_read:  # as IDA left them, joined once (by the recorder)
            for t, y, switch in raw:
                self.rec.add_points(t, y, None, switch)
        elif raw:
            joined = len(raw) > 1  # joined arrays are the loop's own: made consistent in place
            if joined:
                out_t, out_y, out_switch = (np.concatenate(column) for column in zip(*raw))
            else:
                out_t, out_y, out_switch = raw[0]
            if self.c_layout:  # one pass in C, states only (the file's reader computes the channels)
                out_y, out_yp, _ = session.report(out_t, out_y, out_switch, channels=False,
                                                  into=(out_y, np.empty(out_y.shape)) if joined else None)
            else:
                out_y, out_yp = model.consistent_state(
                    out_t, out_y, model.term_forces_rows(out_t, out_y, out_switch, session), session)
            self.rec.add_points(out_t, out_y, out_yp, out_switch)
        raw.clear()
        self.rec.flush()

    def finish(self, on_failure: str, setup_time: float, sim_params: dict[str, Any]) -> Result:
        """Flush, check the physics, build the Result; raise (with it) on Ctrl-C or a failure when asked."""
        stats = dict(self.session.stats())
        found = self.checked_output(stats, setup_time, sim_params)
        physics.issue(found, stacklevel=6)  # issue <- finish <- run <- IDA.run <- simulate <- the caller
        t, message = self.t, self.message
        deep = [w for w in found if w["kind"] == "penetration" and w["t"] <= t]
        if not self.success and not self.interrupted and deep:  # the advice must fit the cause: not a tolerance problem
            w = deep[0]  # the solver's advice is left out: it would not help
            message = self.failure + penetration_advice(w, self.lost_onset(w["where"], w["t"]))
        result = self.rec.finish(stats=stats, success=self.success, status=self.status, message=message,
                                 warnings=found)
        if self.interrupted or self.rec.interrupted:
            raise Interrupted(f"simulate: {message}; partial result in .result.", result)
        if not self.success and on_failure == "raise":
            raise SolveError(message + " Partial result in .result.", result)
        return result

    def lost_onset(self, pair: str, t: float) -> bool:
        """Whether ``pair`` was free at ``t`` (its force term off) with its gap (the root IDA watches,
        guide ends included) in contact beyond round-off: an onset the solver did not report."""
        key_t, key_y = self.checked_rows
        rows = np.flatnonzero(key_t == t)
        if term_on_at(self.last_terms, pair, t) or not rows.size:
            return False
        gap = gap_at(self.model, pair, key_y[rows[0]])
        return gap is not None and gap > physics.GAP_ROUNDING

    def checked_output(self, stats: dict[str, Any], setup_time: float, sim_params: dict[str, Any]) -> list[dict]:
        """Hand over the last points, complete ``stats`` and run the physics checks (their findings);
        the session stays open through the checks: they evaluate constraints in its library, not in CasADi."""
        model, session, rec = self.model, self.session, self.rec
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
            # the start checks concern a declared state: the chapter's start is consistent by construction
            key_t, key_y, key_channels = rec.key_rows()
            self.checked_rows = (key_t, key_y)  # the failure message reads the deepest pair's gap there
            return physics.check_run(model, key_t, key_y, key_channels,
                                     self.y0 if sim_params["start"] == "declared" else None, stats, session,
                                     from_state=sim_params["start"] == "state")
        finally:
            rec.session = None  # the session closes: later channels open their own
            session.close()


def _eval_window(times: opts.OutputTimes, i: int, t: float, size: int) -> tuple[int, NDArray]:
    """The output times after ``t`` from index ``i`` on, at most ``size``: (index of the first, times)."""
    while i < times.size:
        window = times.window(i, i + size)
        lo = int(window.searchsorted(t, side="right"))
        if lo < window.size:
            return i + lo, window[lo:]
        i += window.size
    return i, np.zeros(0)


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


def guarded_root(watched: NDArray | None, found: NDArray) -> bool:
    """Whether a root was found in the direction its pair watched (``watched``) and decided nothing: IDA
    restarts then (as the compiled loop), since going on from a gap exactly zero is IDA's "root found at
    and very near t" error."""
    if watched is None:
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
    """The gap IDA watches for ``pair`` (> 0 in contact) at state ``y``; None for a name that is no pair."""
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


def steps_needed(cap: int, t0: float, t: float, t_end: float) -> int:
    """A step cap that lets a run capped at ``cap`` steps at ``t`` reach ``t_end``: the steps so far in
    proportion to the time still to go, with a margin of a half, on two significant digits."""
    estimate = 1.5 * cap * (t_end - t0) / max(t - t0, 1e-300)
    digits = max(int(math.floor(math.log10(estimate))) - 1, 0)
    return int(math.ceil(estimate / 10 ** digits) * 10 ** digits)


def _failure_message(model: DAEModel, adv: Any, modes: dict[str, str], max_steps_needed: int) -> tuple[str, str]:
    """When, where (contact modes) and why IDA failed; and what to try (each advice made the failing
    case of a test finish: tests/test_tolerances.py)."""
    in_contact = [pair for pair, mode in modes.items() if mode == "contact"]
    where = f" with {', '.join(repr(p) for p in in_contact)} in contact" if in_contact else ""
    flag = f" ({adv.flag_name})" if adv.flag_name else ""
    detail = f": {adv.message.rstrip('.')}" if adv.message else ""
    other = "index1" if model.formulation == "ggl" else "ggl"
    advice = f"Try formulation='{other}'."
    if adv.flag_name == "DC_MAX_STEPS":  # not an accuracy problem: the run needs more steps
        advice = (f"The run needs more steps than max_steps allows: raise max_steps to about {max_steps_needed} "
                  f"(daeclear run: --max-steps {max_steps_needed}).")
    # sticking under plain Coulomb: index-1 chatters until the stall guard stops it, GGL's Newton
    # iteration fails to converge (or its error test fails) at the sticking point
    elif adv.flag_name in STICKING_FLAGS and in_contact and any(
            getattr(logic, "discontinuous_friction", False) for logic in model.contacts):
        advice = ("The friction law is discontinuous at zero sliding speed (plain Coulomb) and the "
                  "contact is sticking: use the modified Coulomb law (friction=<coefficient> or "
                  "daeclear.contact.ModifiedCoulomb), which is continuous.")
    return f"IDA failed at t={adv.t:.6g} s{flag}{where}{detail}.", advice
