"""A prototype forward-sensitivity run (issue 43): IDA on the stacked DAE [y; S], jumps at every event.

A reference to validate against, not the fast path: IDA factors the (1 + Ns) n system
(:func:`daeclear.engine.sensitivity_functions.augmented_functions`) where the run driver will reuse the
state's factorisation, and this loop restarts at every root that Python decides (no contact switch is
decided in C). What it shares with the planned ``simulate(..., sensitivities=...)``: the generated
sensitivity functions, the consistent sensitivities and event derivatives of
:class:`daeclear.assembly.sensitivity.ModelSensitivity`, and the jump formulas of
:mod:`daeclear.solvers.sensitivity_jumps` (docs/sensitivities.md). Error control: the sensitivities are
in the test, scaled by each parameter's magnitude (IDAS' ``pbar``: atol_S = atol / |p|); multipliers out.

Every contact element: revolute joints, translational corners and faces, the lubricated joint's film
breakdown and re-formation and its dry contacts (each element's rule says which roots make its events and
how its terms' parameters follow the latched speeds); a pair held by the storm guard has no derivative
(NaN and a PhysicsWarning).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.dae_model import KIND_MULTIPLIER, DAEModel
from ..assembly.sensitivity import ModelSensitivity, initial_sensitivities, parameter_value
from ..core.errors import PhysicsWarning
from ..engine.ida_session import open_session
from ..engine.sensitivity_functions import augmented_functions
from . import ida
from .sensitivity_jumps import event_time_sensitivity, latched_sensitivity, same_event_times, state_jump
from .tolerances import tolerance_vector

__all__ = ["EventSensitivity", "SensitivityRun", "forward_sensitivities"]


@dataclass(frozen=True)
class EventSensitivity:
    """One contact switch: time, pair, kind and the event time's sensitivity to each parameter."""

    t: float
    pair: str
    kind: str
    dt_dp: NDArray[np.float64]


@dataclass
class SensitivityRun:
    """What :func:`forward_sensitivities` computed at the times ``t``: states ``y`` (n_times, n_states,
    consistent), their sensitivities ``S`` (n_times, n_states, Ns), the channels' values ``channels``
    (n_times, n_channels) and sensitivities ``channel_S`` (n_times, n_channels, Ns); NaN columns after a
    grazing event. With ``event_rows`` an event at t* adds two rows at t*, before and after the switch
    (what :mod:`daeclear.results.objectives` needs of a trajectory)."""

    names: tuple[str, ...]
    state_names: tuple[str, ...]
    channel_names: tuple[str, ...]
    t: NDArray[np.float64]
    y: NDArray[np.float64]
    S: NDArray[np.float64]
    channel_S: NDArray[np.float64]
    channels: NDArray[np.float64]
    events: list[EventSensitivity] = field(default_factory=list)
    success: bool = True
    message: str = "end of the time span reached"

    def values(self, name: str) -> NDArray[np.float64]:
        """A state's or a channel's value at every time, (n_times,)."""
        if name in self.state_names:
            return self.y[:, self.state_names.index(name)]
        if name in self.channel_names:
            return self.channels[:, self.channel_names.index(name)]
        raise KeyError(f"no state or channel {name!r}; the states are {', '.join(self.state_names)}")

    def sensitivity(self, name: str, parameter: str | None = None) -> NDArray[np.float64]:
        """d(name)/d(parameter) of a state or a channel at every time, (n_times,); every parameter
        (n_times, Ns) without one."""
        if name in self.state_names:
            column = self.S[:, self.state_names.index(name), :]
        elif name in self.channel_names:
            column = self.channel_S[:, self.channel_names.index(name), :]
        else:
            raise KeyError(f"no state or channel {name!r}; the states are {', '.join(self.state_names)}")
        if parameter is None:
            return column
        if parameter not in self.names:
            raise KeyError(f"no sensitivity to {parameter!r}; the run has {', '.join(self.names)}")
        return column[:, self.names.index(parameter)]


def forward_sensitivities(model: DAEModel, t_end: float, parameters: Sequence[str], *,
                          t_eval: NDArray[np.float64] | None = None, rtol: float = 1e-8,
                          atol: float | None = None, start: str = "ideal", allow_penetration: bool = False,
                          backend: str = "python", max_step: float = 0.0, jumps: bool = True,
                          event_rows: bool = False) -> SensitivityRun:
    """Integrate y and S = dy/dp of ``model`` from 0 to ``t_end`` for the named ``parameters``
    (``model.parameter_names``), with the sensitivity jumps at every contact switch.

    ``t_eval``: output times (default: the start and the end); ``atol`` as ``simulate``'s (None: the
    model's scales); ``backend``: the session's ("python", "c", "auto"); ``jumps=False`` leaves the jumps
    out (S carried through each event as it is, the latched values' dt*/dp term dropped): a wrong answer,
    kept to show that the tests see the jump; ``event_rows``: two output rows at each event, before and after
    its switch."""
    ms = ModelSensitivity(model, parameters)
    W, n = ms.width, model.n_states
    eval_times = np.array([0.0, float(t_end)] if t_eval is None else t_eval, dtype=float)
    y, yp = model.initial_state(start=start, allow_penetration=allow_penetration)
    S = initial_sensitivities(model, ms.names, start, allow_penetration)
    state = contact_state.start_state(model, 0.0, y)
    active, params = contact_state.switches(model, state)
    latched = [[np.zeros(W) for _ in states] for states in state]  # each pair's latched speed's sensitivity
    for i, logic in enumerate(model.contacts):  # a pair in contact at the start latched its rate there (t0 fixed)
        for root in logic.roots:
            if logic.needs_approach and contact_state.pair_state(model, state, root).contact:
                speed, rate_p, _ = ms.approach_rate(root, y, yp, S)
                latched[i][logic.pair_index(root)] = latched_sensitivity(
                    rate_p, 0.0, np.zeros(W), floored=speed <= logic.min_approach_speed)
    S_params = _term_sensitivities(model, state, latched, W)
    if any(active):
        y, yp = model.consistent_state(0.0, y, model.term_forces(0.0, y, active, params))
    S, Sp = ms.consistent(0.0, y, S, active, params, S_params)
    differential = np.array([kind != KIND_MULTIPLIER for kind in model.state_kinds])
    pbar = np.array([abs(parameter_value(model, name)) or 1.0 for name in ms.names])
    atol_y = tolerance_vector(model, rtol, atol)
    session = open_session(augmented_functions(model.functions, W), backend=backend, rtol=rtol,
                           atol=np.concatenate([atol_y, *(atol_y / p for p in pbar)]), max_step=max_step,
                           parameters=np.concatenate([model.parameter_values, ms.dP.ravel(order="F")]))
    # the run's IDA settings (daeclear.solvers.ida; the python backend has none), but GGL's tight Newton
    # coefficient: S's corrections converge linearly under the block-diagonal matrix, and 1e-3 in IDA's 4
    # iterations failed a chaotic run (S ~ 1e8) after 10 ms at rtol 1e-8 where IDA's 0.33 carries it to 24 ms
    session.set_hints(jacobian_refresh=ida.JACOBIAN_REFRESH,
                      first_step=ida.FIRST_STEP_ESTIMATE and model.formulation == "ggl")
    poisoned = np.zeros(W, dtype=bool)  # parameters whose sensitivities are NaN from a grazing event on
    rows: list[tuple[float, NDArray, NDArray, NDArray, NDArray]] = []  # (t, y, S, channels' S, channels)
    if eval_times[0] == 0.0:
        rows.append(_row(ms, 0.0, y, S, active, params, S_params, poisoned))
    n_ch = len(model.channel_names)
    run = SensitivityRun(ms.names, model.state_names, model.channel_names, np.zeros(0), np.zeros((0, n)),
                         np.zeros((0, n, W)), np.zeros((0, n_ch, W)), np.zeros((0, n_ch)))
    t = 0.0
    try:
        while True:
            session.reinit(t, np.concatenate([y, S.ravel(order="F")]), np.concatenate([yp, Sp.ravel(order="F")]),
                           active, [np.concatenate([p, s.ravel(order="F")]) for p, s in zip(params, S_params)],
                           contact_state.root_directions(model, state))
            adv = session.advance(float(t_end), eval_times, store_steps=False, store_states=False)
            for te, Ye in zip(adv.eval_t.tolist(), adv.eval_y):
                rows.append(_row(ms, te, Ye[:n], Ye[n:].reshape(n, W, order="F"), active, params, S_params, poisoned))
            t = adv.t
            if adv.status != "root":
                if adv.status == "error":
                    run.success, run.message = False, adv.message
                break
            y, S = adv.y[:n], adv.y[n:].reshape(n, W, order="F")
            if event_rows:
                rows.append(_row(ms, t, y, S, active, params, S_params, poisoned))
            state, active, params, latched, y, yp, S, Sp = _event(
                ms, state, active, params, latched, t, y, S, adv.roots_found, rtol, atol_y, jumps, differential, run)
            bad = ~np.all(np.isfinite(S), axis=0)
            poisoned |= bad
            S[:, bad] = 0.0  # integrated as zeros, reported as NaN
            Sp[:, bad] = 0.0
            for per_pair in latched:
                for value in per_pair:
                    value[poisoned] = 0.0
            S_params = _term_sensitivities(model, state, latched, W)
            if event_rows:
                rows.append(_row(ms, t, y, S, active, params, S_params, poisoned))
    finally:
        session.close()
    if rows:
        run.t = np.array([r[0] for r in rows])
        run.y, run.S, run.channel_S, run.channels = (np.stack([r[k] for r in rows]) for k in (1, 2, 3, 4))
    return run


def _term_sensitivities(model: DAEModel, state: contact_state.ContactState, latched: list[list[NDArray]],
                        width: int) -> list[NDArray]:
    """Each term's parameters' sensitivity (n_params_k, Ns) in ``state``, from the pairs' ``latched``."""
    out = [np.zeros((term.n_params, width)) for term in model.terms]
    for logic, states, per_pair in zip(model.contacts, state, latched):
        for k, S_k in logic.term_sensitivities(states, per_pair):
            out[k] = np.array(S_k, dtype=float).reshape(-1, width)
    return out


def _row(ms: ModelSensitivity, t: float, y: NDArray, S: NDArray, active: list[bool], params: list[NDArray],
         S_params: list[NDArray], poisoned: NDArray) -> tuple[float, NDArray, NDArray, NDArray, NDArray]:
    """An output row, made consistent in its mode: (t, y, S, the channels' sensitivities, the channels), NaN
    where poisoned."""
    model = ms.model
    y, yp = model.consistent_state(t, y, model.term_forces(t, y, active, params))
    S, Sp = ms.consistent(t, y, S, active, params, S_params)
    switch = model.switch_vector(active, params)
    channel_S = ms.channels(t, y, yp, S, Sp, switch, ms.switch_sensitivity(S_params))
    values = np.array(model.outputs(t, y, yp, switch, model.parameter_values), dtype=float).ravel()
    S[:, poisoned] = np.nan
    channel_S[:, poisoned] = np.nan
    return t, y, S, channel_S, values


def _event(ms: ModelSensitivity, state: contact_state.ContactState, active: list[bool], params: list[NDArray],
           latched: list[list[NDArray]], t: float, y: NDArray, S: NDArray, found: NDArray | None, rtol: float,
           atol: NDArray, jumps: bool, differential: NDArray, run: SensitivityRun) -> tuple:
    """Decide the roots at ``t``, jump the sensitivities (docs/sensitivities.md) and return the new mode
    with the pairs' latched sensitivities and its consistent (y, y', S, S')."""
    model, W = ms.model, ms.width
    S_params = _term_sensitivities(model, state, latched, W)
    new_state, events = contact_state.decide(model, state, t, y, found)
    new_active, new_params = contact_state.switches(model, new_state)
    # y' and S' before the switch, exact for the old mode at (t, y)
    y_m, yp_m = model.consistent_state(t, y, model.term_forces(t, y, active, params))
    S_m, Sp_m = ms.consistent(t, y_m, S, active, params, S_params)
    project = model.formulation == "ggl"  # as the run's restarts: on the constraint manifold, mu = 0
    y_p, yp_p = model.consistent_state(t, y_m, model.term_forces(t, y_m, new_active, new_params), project=project)
    roots_of = model.functions.roots
    if project and roots_of is not None:  # unless that moves a root that did not fire across zero (a lost event)
        g0 = np.array(roots_of(t, y_m, yp_m, model.parameter_values)).ravel()
        g1 = np.array(roots_of(t, y_p, yp_p, model.parameter_values)).ravel()
        quiet = np.zeros(g0.shape, bool) if found is None else np.ravel(found) == 0
        if np.any(quiet & (g0 != 0) & ((g0 > 0) != (g1 > 0))):
            project = False
            y_p, yp_p = model.consistent_state(t, y_m, model.term_forces(t, y_m, new_active, new_params))
    new_latched = [[value.copy() for value in per_pair] for per_pair in latched]
    dt_dps = []
    if events and found is not None:
        at = ms.roots(t, y_m, yp_m, S_m, Sp_m, rtol, atol)
        for e in events:
            label = f"'{e.pair}' {e.kind} at t={t:.9g} s"
            owners = [(i, logic, root) for i, logic in enumerate(model.contacts)
                      for root in logic.event_roots(e.pair, np.ravel(found))]
            if not owners:  # no root of this instant made it: no derivative to give
                warnings.warn(f"sensitivities: {label} was made by no root found then; its sensitivities are NaN "
                              "from here on.", PhysicsWarning, stacklevel=3)
                dt_dps.append(np.full(W, np.nan))
                run.events.append(EventSensitivity(t, e.pair, e.kind, dt_dps[-1]))
                continue
            for i, logic, root in owners:
                dt = event_time_sensitivity(at.g_p[root], at.rate[root], at.scale[root], rtol=rtol, event=label,
                                            curvature=at.curvature[root], gap_error=at.error[root])
                if contact_state.pair_state(model, new_state, root).held:
                    warnings.warn(f"sensitivities: {label} is held by the storm guard (a storm of tiny re-contacts "
                                  "has no derivative); its sensitivities are NaN from here on.", PhysicsWarning,
                                  stacklevel=3)
                    dt = np.full(W, np.nan)
                dt_dps.append(dt)
                if e.kind == "onset" and logic.needs_approach and logic.pair_name(root) == e.pair:
                    speed, rate_p, rate_rate = ms.approach_rate(root, y_m, yp_m, S_m)
                    new_latched[i][logic.pair_index(root)] = latched_sensitivity(
                        rate_p, rate_rate, dt if jumps else np.zeros(W), floored=speed <= logic.min_approach_speed)
            run.events.append(EventSensitivity(t, e.pair, e.kind, dt_dps[-len(owners)]))
    new_S_params = _term_sensitivities(model, new_state, new_latched, W)
    dt_dp = np.zeros(W)
    if dt_dps:
        dt_dp = dt_dps[0] if same_event_times(dt_dps, rtol) else np.full(W, np.nan)
    S_p = state_jump(S_m, yp_m, yp_p, dt_dp, differential) if jumps else S_m
    if project:
        S_p = ms.projected(t, y_p, S_p)
    S_p, Sp_p = ms.consistent(t, y_p, S_p, new_active, new_params, new_S_params)
    return new_state, new_active, new_params, new_latched, y_p, yp_p, S_p, Sp_p
