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

from dataclasses import dataclass, field
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.dae_model import DAEModel
from ..assembly.sensitivity import initial_sensitivities
from ..engine.ida_session import open_session
from ..engine.sensitivity_functions import augmented_functions
from . import ida
from ..results.sensitivities import SensitivityEvent as EventSensitivity
from .sensitivity_carrier import SensitivityCarrier, parameter_scales
from .tolerances import tolerance_vector

__all__ = ["EventSensitivity", "SensitivityRun", "forward_sensitivities"]


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
    names = list(parameters)
    eval_times = np.array([0.0, float(t_end)] if t_eval is None else t_eval, dtype=float)
    atol_y = tolerance_vector(model, rtol, atol)
    carrier = SensitivityCarrier(model, names, rtol, atol_y, jumps=jumps)
    W, n = carrier.width, model.n_states
    y, yp = model.initial_state(start=start, allow_penetration=allow_penetration)
    S0 = initial_sensitivities(model, carrier.names, start, allow_penetration)
    y, yp = carrier.start(0.0, y, yp, contact_state.start_state(model, 0.0, y), S0)
    pbar = parameter_scales(model, carrier.names)
    session = open_session(augmented_functions(model.functions, W), backend=backend, rtol=rtol,
                           atol=np.concatenate([atol_y, *(atol_y / p for p in pbar)]), max_step=max_step,
                           parameters=np.concatenate([model.parameter_values, carrier.ms.dP.ravel(order="F")]))
    # the run's IDA settings (daeclear.solvers.ida; the python backend has none), but GGL's tight Newton
    # coefficient: S's corrections converge linearly under the block-diagonal matrix, and 1e-3 in IDA's 4
    # iterations failed a chaotic run (S ~ 1e8) after 10 ms at rtol 1e-8 where IDA's 0.33 carries it to 24 ms
    session.set_hints(jacobian_refresh=ida.JACOBIAN_REFRESH,
                      first_step=ida.FIRST_STEP_ESTIMATE and model.formulation == "ggl")
    if eval_times[0] == 0.0:
        carrier.row(0.0, y, carrier.S)
    n_ch = len(model.channel_names)
    run = SensitivityRun(carrier.names, model.state_names, model.channel_names, np.zeros(0), np.zeros((0, n)),
                         np.zeros((0, n, W)), np.zeros((0, n_ch, W)), np.zeros((0, n_ch)), events=carrier.events)
    ys: list[NDArray] = [y] if eval_times[0] == 0.0 else []
    t = 0.0
    try:
        while True:
            session.reinit(t, np.concatenate([y, carrier.S.ravel(order="F")]),
                           np.concatenate([yp, carrier.Sp.ravel(order="F")]), carrier.active,
                           carrier.terms_stacked(), contact_state.root_directions(model, carrier.state))
            adv = session.advance(float(t_end), eval_times, store_steps=False, store_states=False)
            for te, Ye in zip(adv.eval_t.tolist(), adv.eval_y):
                ys.append(carrier.row(te, Ye[:n], Ye[n:].reshape(n, W, order="F")))
            t = adv.t
            if adv.status != "root":
                if adv.status == "error":
                    run.success, run.message = False, adv.message
                break
            y, S = adv.y[:n], adv.y[n:].reshape(n, W, order="F")
            if event_rows:
                ys.append(carrier.row(t, y, S))
            y, yp, S = _event(carrier, t, y, S, adv.roots_found)
            if event_rows:
                ys.append(carrier.row(t, y, S))
    finally:
        session.close()
    if carrier.rows_t:
        run.t = np.array(carrier.rows_t)
        run.y, run.S, run.channel_S = np.stack(ys), np.stack(carrier.rows_S), np.stack(carrier.rows_channel_S)
        run.channels = np.stack(carrier.rows_channels)
    return run


def _event(carrier: SensitivityCarrier, t: float, y: NDArray, S: NDArray, found: NDArray | None
           ) -> tuple[NDArray, NDArray, NDArray]:
    """Decide the roots at ``t`` and jump the sensitivities (the carrier's jump, as the run driver's);
    return the consistent (y, y', S) to restart from in the new mode."""
    model = carrier.model
    active, params = carrier.active, carrier.params
    new_state, events = contact_state.decide(model, carrier.state, t, y, found)
    new_active, new_params = contact_state.switches(model, new_state)
    y_m, yp_m = model.consistent_state(t, y, model.term_forces(t, y, active, params))
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
    carrier.jump(t, y, S, found, new_state, events, y_p, project)
    return y_p, yp_p, carrier.S
