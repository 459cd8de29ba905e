"""Forward sensitivities S = dy/dp carried beside a run's states (issue 43, docs/sensitivities.md).

:class:`SensitivityCarrier` holds what S needs between two events (the contact state it was made consistent
in, each pair's latched approach speed's sensitivity, the parameters poisoned by a grazing event) and does
the three things a run asks of it: the start's S (:meth:`~SensitivityCarrier.start`), an output row made
consistent in its mode with the channels' sensitivities (:meth:`~SensitivityCarrier.row`), and the jump at
an event (:meth:`~SensitivityCarrier.jump`: event time, differential states, latched values, grazing, a
storm hold; the formulas of :mod:`daeclear.solvers.sensitivity_jumps`). The run driver calls the jump at
every event (:meth:`daeclear.solvers.driver.Driver.jump`); the integrator of the stacked [y; S]
(:mod:`daeclear.solvers.sensitivity_ida`) restarts from what it leaves.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.dae_model import KIND_MULTIPLIER, DAEModel
from ..assembly.sensitivity import ModelSensitivity, parameter_value
from ..core.errors import PhysicsWarning
from ..core.events import ContactEvent
from ..results.sensitivities import SensitivityEvent
from .sensitivity_jumps import event_time_sensitivity, latched_sensitivity, same_event_times, state_jump

__all__ = ["SensitivityCarrier", "onset_limit", "parameter_scales"]


def parameter_scales(model: DAEModel, names: Sequence[str]) -> NDArray[np.float64]:
    """|p| of each parameter (1 at 0): S's absolute tolerance is atol / |p| (IDAS' ``pbar``)."""
    return np.array([abs(parameter_value(model, name)) or 1.0 for name in names])


#: The step along the motion (in s, times 1 + |t|) at which an onset's forces are read from inside the contact.
ONSET_STEP = 1e-12


def onset_limit(forces: Callable[[float], Any], t: float) -> NDArray:
    """The forces' limit from inside a contact that begins at ``t``, from ``forces(s)`` read a step s along the
    motion, extrapolated linearly to s = 0: 2 F(s) - F(2 s). A law gated at delta > 0 (Kelvin-Voigt) reads 0
    when the root lands exactly on delta = 0, which would drop its jump D u from y'+ and so from S+."""
    s = ONSET_STEP * (1.0 + abs(t))
    return 2.0 * np.asarray(forces(s)) - np.asarray(forces(2.0 * s))


class SensitivityCarrier:
    """S of one run between events: its contact mode, the latched values' sensitivities, the poisoned
    parameters; the rows and events it gave (``rows_t``, ``rows_S``, ``rows_channel_S``, ``events``)."""

    def __init__(self, model: DAEModel, names: Sequence[str], rtol: float, atol: NDArray) -> None:
        self.ms = ModelSensitivity(model, names)
        self.model, self.names, self.width = model, self.ms.names, self.ms.width
        self.rtol, self.atol = rtol, atol
        self.differential = np.array([kind != KIND_MULTIPLIER for kind in model.state_kinds])
        self.state: contact_state.ContactState = ()
        self.active: list[bool] = []
        self.params: list[NDArray] = []
        self.latched: list[list[NDArray]] = []
        self.S_params: list[NDArray] = []
        self.pieces: dict[int, int] = {}  # term -> the piece of its friction law S is integrated on (Term.locked)
        # the direction to watch each kink root in after a restart: back across a root crossed there (never the
        # round-off of the root just left), both ways for the others
        self.kink_watch = np.zeros(len(model.kink_terms), dtype=np.int32)
        self.n_kinks = 0  # the kinks crossed (the run's stats)
        self.S = self.Sp = np.zeros((model.n_states, self.width))
        self.poisoned = np.zeros(self.width, dtype=bool)  # NaN from a grazing event on
        self.dt_dp = np.zeros(self.width)  # the last event's time sensitivity (the quadratures' jump reads it)
        self.events: list[SensitivityEvent] = []
        self.rows_t: list[float] = []
        self.rows_S: list[NDArray] = []
        self.rows_channel_S: list[NDArray] = []
        self.rows_channels: list[NDArray] = []
        self.event_t: list[float] = []
        self.event_rows: list[tuple[NDArray, NDArray, NDArray, NDArray]] = []  # (y, S, channels' S, channels)

    def set_state(self, state: contact_state.ContactState) -> None:
        """The contact state S is integrated in, and its terms' parameters' sensitivities."""
        self.state = state
        self.active, self.params = contact_state.switches(self.model, state)
        self.S_params = self.term_sensitivities(state, self.latched)

    def start(self, t: float, y: NDArray, yp: NDArray, state: contact_state.ContactState, S0: NDArray
              ) -> tuple[NDArray, NDArray]:
        """Begin at the start ``(y, yp)`` (as ``model.initial_state`` gives it) in contact ``state`` with
        ``S0`` = dy0/dp: a pair in contact latches its rate's sensitivity (t0 fixed); return the start
        made consistent in its mode, with S and S' consistent there."""
        model, ms, W = self.model, self.ms, self.width
        self.latched = [[np.zeros(W) for _ in states] for states in state]
        for i, logic in enumerate(model.contacts):
            for root in logic.roots:
                if logic.needs_approach and contact_state.pair_state(model, state, root).contact:
                    speed, rate_p, _ = ms.approach_rate(root, y, yp, S0)
                    self.latched[i][logic.pair_index(root)] = latched_sensitivity(
                        rate_p, 0.0, np.zeros(W), floored=speed <= logic.min_approach_speed)
        self.set_state(state)
        if any(self.active):
            y, yp = model.consistent_state(t, y, model.term_forces(t, y, self.active, self.params))
        self.S, self.Sp = ms.consistent(t, y, S0, self.active, self.params, self.S_params)
        self.pieces = self.pieces_at(t, y, yp, None)
        return y, yp

    def pieces_at(self, t: float, y: NDArray, yp: NDArray, found: NDArray | None) -> dict[int, int]:
        """The piece of its friction law each term with kinks is on at ``(t, y)``: how many of its kink roots
        (v_T - b, b its law's breakpoints) are positive; a root ``found`` at ``t`` on the side it crossed to."""
        model = self.model
        if not model.kink_terms:
            return {}
        kinks = model.functions.kinks
        assert kinks is not None  # a model with kink terms has their roots
        g = np.array(kinks(t, y, yp, model.parameter_values), dtype=float).ravel() > 0.0
        if found is not None:
            crossed = np.ravel(found)[len(model.gap_names):]
            g = np.where(crossed != 0, crossed > 0, g)
        out: dict[int, int] = {}
        for term, positive in zip(model.kink_terms, g.tolist()):
            out[term] = out.get(term, 0) + int(positive)
        return out

    def restarted(self, t: float, y: NDArray, S: NDArray, Sp: NDArray, bad: NDArray) -> tuple[NDArray, NDArray]:
        """(S, S') with the ``bad`` columns (poisoned: reported NaN from here on) restarted from S_q = S_v = 0
        (GGL: moved onto the linearised constraints) and no latched sensitivity, their multipliers' and
        derivatives' sensitivities consistent with that (the response to dP from here on): zeros alone are no
        solution of F_y S + F_y' S' + F_P dP = 0 where F_P dP is not zero (a driven joint's speed), and IDA's
        error test then fails at every step size (docs/sensitivities.md, section 4)."""
        for per_pair in self.latched:
            for value in per_pair:
                value[bad] = 0.0
        self.S_params = self.term_sensitivities(self.state, self.latched)
        S = S.copy()
        S[:, bad] = 0.0
        if self.model.formulation == "ggl":
            S[:, bad] = self.ms.projected(t, y, S)[:, bad]
        S_zero, Sp_zero = self.ms.consistent(t, y, S, self.active, self.params, self.S_params)
        Sp = Sp.copy()
        S[:, bad], Sp[:, bad] = S_zero[:, bad], Sp_zero[:, bad]
        return S, Sp

    def term_sensitivities(self, state: contact_state.ContactState, latched: list[list[NDArray]]) -> list[NDArray]:
        """Each term's parameters' sensitivity (n_params_k, Ns) in ``state``, from the pairs' ``latched``."""
        out = [np.zeros((term.n_params, self.width)) for term in self.model.terms]
        for logic, states, per_pair in zip(self.model.contacts, state, latched):
            for k, S_k in logic.term_sensitivities(states, per_pair):
                out[k] = np.array(S_k, dtype=float).reshape(-1, self.width)
        return out

    def terms_stacked(self) -> list[NDArray]:
        """Each term's parameters (then the piece of its friction law, for a term with kinks) followed by their
        sensitivities: the stacked system's term parameters."""
        pieces = self.pieces
        return [np.concatenate([p, [float(pieces[k])] if k in pieces else [], s.ravel(order="F")])
                for k, (p, s) in enumerate(zip(self.params, self.S_params))]

    def rows(self, t: NDArray, y: NDArray, S: NDArray) -> None:
        """Keep output rows at ``t`` (N,) of the current mode: S of the states ``y`` (N, n) made consistent
        there (``S`` (N, n, Ns)) and the channels' sensitivities, all rows at once; NaN where poisoned."""
        if not t.size:
            return
        _, _, S, _, channel_S, values = self.evaluate_rows(t, y, S)
        S[:, :, self.poisoned] = np.nan
        channel_S[:, :, self.poisoned] = np.nan
        self.rows_t.extend(t.tolist())
        self.rows_S.extend(S)
        self.rows_channel_S.extend(channel_S)
        self.rows_channels.extend(values)

    def row(self, t: float, y: NDArray, S: NDArray) -> None:
        """Keep one output row at ``t`` (:meth:`rows`)."""
        self.rows(np.array([t], dtype=float), y[None], S[None])

    def evaluate_rows(self, t: NDArray, y: NDArray, S: NDArray
                      ) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray, NDArray]:
        """Rows at ``t`` (N,) made consistent in the current mode: (y, y', S, S', the channels' S, the channels'
        values), each with N rows first; nothing poisoned."""
        model, ms = self.model, self.ms
        single = t.size == 1
        session = ms.session
        forces = model.term_forces(t[0] if single else t, y[0] if single else y, self.active, self.params, session)
        y, yp = model.consistent_state(t[0] if single else t, y[0] if single else y, forces, session)
        y, yp = np.atleast_2d(y), np.atleast_2d(yp)
        S, Sp = ms.consistent_rows(t, y, S, self.active, self.params, self.S_params)
        switch = model.switch_vector(self.active, self.params)
        channel_S = ms.channels_rows(t, y, yp, S, Sp, switch, ms.switch_sensitivity(self.S_params))
        values = ms.outputs_rows(t, y, yp, switch)
        return y, yp, S, Sp, channel_S, values

    def kinks_found(self, found: NDArray | None) -> NDArray[np.intp]:
        """The friction kinks (roots after the gaps) among the roots ``found``."""
        n_gaps, n_kinks = len(self.model.gap_names), len(self.model.kink_pairs)
        if found is None or not n_kinks:
            return np.zeros(0, dtype=np.intp)
        return n_gaps + np.flatnonzero(np.ravel(found)[n_gaps:n_gaps + n_kinks])

    def kink_events(self, t: float, found: NDArray | None, at: Any) -> None:
        """Record each friction kink crossed at ``t`` (kind ``"kink"``, docs/sensitivities.md, "Kinks"): the
        force's slope jumps there, not the force, so S goes on continuous (S+ = S-, S' re-solved in the
        restart); its time's sensitivity -(g_y S + g_p) / g' is reported, NaN where the rate is 0."""
        n_gaps = len(self.model.gap_names)
        crossed = self.kinks_found(found)
        self.kink_watch[:] = 0  # away from their roots: either way
        if found is not None and crossed.size:
            self.kink_watch[crossed - n_gaps] = -np.sign(np.ravel(found)[crossed])
            self.n_kinks += crossed.size
        for root in crossed:
            rate = float(at.rate[root])
            dt = -at.g_p[root] / rate if rate != 0.0 else np.full(self.width, np.nan)
            self.events.append(SensitivityEvent(t, self.model.kink_pairs[root - n_gaps], "kink", dt))

    def event_row(self, t: float, y: NDArray, S: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Keep a row at an event's time (before its switch, then after): what an objective integrating or
        peaking across the event reads (:mod:`daeclear.results.objectives`). Return (y, y', S, S') consistent
        in the current mode (nothing poisoned)."""
        y_c, yp, S_c, Sp, channel_S, values = (a[0] for a in self.evaluate_rows(np.array([t], dtype=float), y[None],
                                                                                 S[None]))
        self.keep_event_row(t, y_c, S_c, channel_S, values)
        return y_c, yp, S_c, Sp

    def consistent_event_row(self, t: float, y: NDArray, yp: NDArray, S: NDArray, Sp: NDArray) -> None:
        """:meth:`event_row` of a point already consistent in the current mode (``y``, ``yp`` of
        :meth:`DAEModel.consistent_state`, ``S``, ``Sp`` of :meth:`ModelSensitivity.consistent`): the
        channels and their sensitivities only."""
        ms, model = self.ms, self.model
        T = np.array([t], dtype=float)
        switch = model.switch_vector(self.active, self.params)
        channel_S = ms.channels_rows(T, y[None], yp[None], S[None], Sp[None], switch,
                                     ms.switch_sensitivity(self.S_params))[0]
        self.keep_event_row(t, y, S, channel_S, ms.outputs_rows(T, y[None], yp[None], switch)[0])

    def keep_event_row(self, t: float, y: NDArray, S: NDArray, channel_S: NDArray, values: NDArray) -> None:
        """Keep an event's row (y, S, the channels' S and values; S's NaN where poisoned)."""
        S_row, channel_row = S.copy(), channel_S.copy()
        S_row[:, self.poisoned] = np.nan
        channel_row[:, self.poisoned] = np.nan
        self.event_rows.append((y, S_row, channel_row, values))
        self.event_t.append(t)

    def jump(self, t: float, y: NDArray, S: NDArray, found: NDArray | None, new_state: contact_state.ContactState,
             events: Sequence[ContactEvent], y_p: NDArray, projected: bool) -> None:
        """The jump at an event at ``t``: the root state ``y`` and its ``S`` in the mode before; the
        contact ``events`` decided there into ``new_state``; ``y_p`` the consistent state the run restarts
        from (``projected``: onto GGL's constraint manifold). Leaves S and S' consistent in the new mode."""
        model, ms, W, rtol = self.model, self.ms, self.width, self.rtol
        y_m, yp_m, S_m, Sp_m = self.event_row(t, y, S)
        new_active, new_params = contact_state.switches(model, new_state)
        session = ms.session
        y_c, yp_p = model.consistent_state(t, y_p, model.term_forces(t, y_p, new_active, new_params, session), session)
        new_latched = [[value.copy() for value in per_pair] for per_pair in self.latched]
        dt_dps: list[NDArray] = []
        if events and found is not None:
            at = ms.roots(t, y_m, yp_m, S_m, Sp_m, rtol, self.atol)
            for e in events:
                label = f"'{e.pair}' {e.kind} at t={t:.9g} s"
                owners = [(i, logic, root) for i, logic in enumerate(model.contacts)
                          for root in logic.event_roots(e.pair, np.ravel(found))]
                if not owners:  # no root of this instant made it: no derivative to give
                    warnings.warn(f"sensitivities: {label} was made by no root found then; its sensitivities are "
                                  "NaN from here on.", PhysicsWarning, stacklevel=3)
                    dt_dps.append(np.full(W, np.nan))
                    self.events.append(SensitivityEvent(t, e.pair, e.kind, dt_dps[-1]))
                    continue
                for i, logic, root in owners:
                    dt = event_time_sensitivity(at.g_p[root], at.rate[root], at.scale[root], rtol=rtol, event=label,
                                                curvature=at.curvature[root], gap_error=at.error[root])
                    if contact_state.pair_state(model, new_state, root).held:
                        warnings.warn(f"sensitivities: {label} is held by the storm guard (a storm of tiny "
                                      "re-contacts has no derivative); its sensitivities are NaN from here on.",
                                      PhysicsWarning, stacklevel=3)
                        dt = np.full(W, np.nan)
                    dt_dps.append(dt)
                    if e.kind == "onset" and logic.needs_approach and logic.pair_name(root) == e.pair:
                        speed, rate_p, rate_rate = ms.approach_rate(root, y_m, yp_m, S_m)
                        new_latched[i][logic.pair_index(root)] = latched_sensitivity(
                            rate_p, rate_rate, dt,
                            floored=speed <= logic.min_approach_speed)
                self.events.append(SensitivityEvent(t, e.pair, e.kind, dt_dps[-len(owners)]))
        self.kink_events(t, found, ms.roots(t, y_m, yp_m, S_m, Sp_m) if self.kinks_found(found).size else None)
        dt_dp = np.zeros(W)
        if dt_dps:
            dt_dp = dt_dps[0] if same_event_times(dt_dps, rtol) else np.full(W, np.nan)
        self.dt_dp = dt_dp
        S_p = state_jump(S_m, yp_m, yp_p, dt_dp, self.differential)
        if projected:
            S_p = ms.projected(t, y_p, S_p)
        self.latched = new_latched
        self.set_state(new_state)
        self.pieces = self.pieces_at(t, y_p, yp_p, found)
        if self.kinks_found(found).size:  # S' on the piece the run goes on with: read a step along the motion
            S_p, Sp_p = (np.asarray(a) for a in onset_limit(lambda s: np.stack(ms.consistent(
                t + s, y_p + s * yp_p, S_p, self.active, self.params, self.S_params)), t))
        else:
            S_p, Sp_p = ms.consistent(t, y_p, S_p, self.active, self.params, self.S_params)
        bad = ~np.all(np.isfinite(S_p), axis=0)  # NaN from this event (a poisoned column's S is finite until then)
        for per_pair in self.latched:
            for value in per_pair:
                bad |= ~np.isfinite(value)
        self.poisoned |= bad
        if bad.any():
            S_p, Sp_p = self.restarted(t, y_p, S_p, Sp_p, bad)
        self.S, self.Sp = S_p, Sp_p
        self.consistent_event_row(t, y_c, yp_p, S_p, Sp_p)  # y_c: y_p with its multipliers of this mode
