"""A run with forward sensitivities through ``dc.simulate(..., sensitivities=...)`` as the sensitivity tests read
it (what the reference run of the stacked [y; S] gave them before the run driver carried sensitivities): the
times, states, S of states and channels, the events with their dt*/dp, and a run without the jumps (the
carrier's jump formulas replaced: S carried through each event as it is, the latched values' dt*/dp
term dropped), a wrong answer that shows the tests see the jumps. The run without them is a test double: the
carrier's two jump formulas replaced for the run's duration, the production code left with no switch.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import pytest

import daeclear as dc
from daeclear.solvers import sensitivity_carrier


class StackedRun:
    """A Result with sensitivities, read as arrays: ``y`` (n_times, n_states), ``S`` (n_times, n_states, Ns),
    ``channel_S`` (n_times, n_channels, Ns), the contact ``events`` with ``dt_dp``, the friction ``kinks``."""

    def __init__(self, result: dc.Result) -> None:
        sens = result.sensitivities
        assert sens is not None
        self.result = result
        self.names, self.state_names, self.channel_names = sens.names, sens.state_names, sens.channel_names
        self.t, self.y, self.S, self.channel_S = result.t, result.y, sens.states, sens.channels
        self.events = [e for e in sens.events if e.kind != "kink"]  # the contact events
        self.kinks = [e for e in sens.events if e.kind == "kink"]  # the friction kinks crossed (restarts, no jump)
        self.success, self.message = result.success, result.message

    def sensitivity(self, name: str, parameter: str | None = None) -> np.ndarray:
        return self.result.sensitivity(name, parameter)


def forward_sensitivities(model: dc.DAEModel, t_end: float, names: Sequence[str], *, rtol: float,
                          start: str = "ideal", backend: str = "python", jumps: bool = True,
                          t_eval: Sequence[float] | np.ndarray | None = None) -> StackedRun:
    """``simulate(model, t_end, sensitivities=names)`` at ``rtol`` with output at ``t_eval`` (default: the
    start and the end); a failed run is returned (``success`` False); ``jumps=False``: without the jumps."""
    times = [0.0, float(t_end)] if t_eval is None else t_eval
    with pytest.MonkeyPatch.context() as patch, warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)  # the runs' physics notes, atol at round-off
        if not jumps:
            latched = sensitivity_carrier.latched_sensitivity

            def latched_without_dt(rate_p: np.ndarray, rate_rate: float, dt_dp: np.ndarray, *,
                                   floored: bool) -> np.ndarray:
                return latched(rate_p, rate_rate, np.zeros_like(dt_dp), floored=floored)

            patch.setattr(sensitivity_carrier, "state_jump", lambda S_m, *rest: S_m)
            patch.setattr(sensitivity_carrier, "latched_sensitivity", latched_without_dt)
        result = dc.simulate(model, t_end, rtol=rtol, options=dc.SolverOptions(start=start, backend=backend),
                             save=dc.SaveAt(times=times, steps=False), sensitivities=list(names),
                             on_failure="return")
    return StackedRun(result)
