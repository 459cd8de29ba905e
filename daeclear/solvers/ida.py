"""The IDA solver: root finding, contact-mode switches and consistent restarts.

The solver knows nothing of slider-cranks: it integrates a :class:`DAEModel` segment
by segment. Between two roots of the gap functions the set of active contact terms
is fixed; at a root each contact element's event logic decides the new modes (and
latches the approach speed), the multipliers and derivatives are made consistent
again, and IDA restarts with fresh BDF history. This module sets the run up (:class:`IDA`, the
method "ida" of :func:`daeclear.simulate`); the segment loop itself is
:class:`daeclear.solvers.ida_loop.SegmentLoop`.
"""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Any, ClassVar

from numpy.typing import NDArray

from .. import options as opts
from . import physics
from ..assembly.assemble import DAEModel, assemble
from ..engine.ida_session import open_session
from .base import step_rule
from .ida_loop import SegmentLoop
from .recorder import Recorder
from .tolerances import atol_record, tolerance_vector
from ..results.result import Result
from ..model.scene import Scene

if TYPE_CHECKING:
    from ..save_at import Output
    from ..solver_options import SolverOptions

log = logging.getLogger("daeclear")
# Constraint drift (largest |Phi| of a run) above this fraction of the smallest clearance is warned of.
DRIFT_FRACTION = physics.DRIFT_FRACTION
# GGL holds Phi = 0 only as tightly as IDA's Newton test (safety factor 0.33 by default). 1e-3
# keeps the pendulum's constraint residual at 1e-12 instead of 3e-11 (rtol 1e-10) and, measured,
# halves the steps; index1 is better off with IDA's default. The python backend cannot set it.
GGL_NEWTON_COEF = 1e-3
# IDA evaluates a new Jacobian when cj (alpha / h) has changed by this fraction (IDA's default 0.25).
# Contact runs change h often: with 0.25 a stale iteration matrix costs the GGL runs 2.2 Newton
# iterations per step and a convergence failure every 25 steps; with 0.05, measured on the Fig. 4.15
# scene, 1.3 iterations and none, 20-25 % less CPU for both formulations (docs/engine.md).
JACOBIAN_REFRESH = 0.05
IDA_JACOBIAN_REFRESH = 0.25  # IDA's own, what the python backend (scikit-sundae) runs with
# The first step of a GGL run: True takes the second-order estimate of the compiled driver
# (first_step in ida_driver.c) over IDA's first-order one, which is 1e-16 s on the chapter's scenes
# and lets GGL's Newton iteration fail there at rtol 1e-9 with the fresher Jacobians above. index1
# keeps IDA's: the longer first step put its first onset 7e-3 (relative) late at c = 0.01 mm and
# rtol 1e-6 (Baumgarte drift over a step that long; with IDA's first step 8e-7, docs/engine.md).
FIRST_STEP_ESTIMATE = True
# Stall guard: STALL_COUNT steps shorter than STALL_STEP seconds that do not grow (and no step a
# hundred times longer in between) end the run with a clear message instead of creeping on
# (e.g. plain Coulomb friction chattering at zero sliding speed takes ~1e-12 s order-1 steps).
# Contact steps of the chapter's runs are 1e-9..1e-6 s; restarts' start-up steps grow and do not count.
# The threshold is absolute: it used to be 1e-10 * t_end, which at t_end = 100 s (1e-8 s) called
# ordinary contact steps a stall. 2.4e-12 s is what it was for the chapter's 0.024 s runs.
STALL_STEP = 2.4e-12
STALL_COUNT = 2000


class IDA:
    """SUNDIALS IDA on the DAE (any formulation), with root finding and consistent restarts: the
    compiled loop in C or, with ``backend="python"`` (or "auto" without a working compiler), the same
    loop on scikit-sundae; the backend is one of the settings (:class:`daeclear.SolverOptions`)."""

    name: ClassVar[str] = "ida"
    formulation: ClassVar[str] = opts.DEFAULT_FORMULATION

    def check(self, settings: SolverOptions) -> None:
        """IDA chooses its own steps: a fixed ``step`` is refused."""
        step_rule(self.name, settings.step, fixed=False)

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate from ``t0`` to ``t_end`` (the :class:`daeclear.solvers.base.Solver` contract)."""
        setup_start = time.perf_counter()
        rtol, atol, start = settings.rtol, settings.atol_value(), settings.start
        if not isinstance(model, DAEModel):
            model = assemble(model, settings.formulation or self.formulation, track_work=settings.track_work)
        if y0 is not None:
            y0 = opts.state(y0, model.n_states)
        save.check_size(step=None, n_states=model.n_states,
                        n_channels=len(model.channel_names))  # before the session: nothing compiled or run
        from_state = y0 is not None
        session, y0, yp0 = _start_session(model, t0, y0, rtol=rtol, atol=atol, backend=settings.backend,
                                          max_step=settings.max_step, max_steps=settings.max_steps,
                                          linear_solver=settings.linear_solver, start=start,
                                          allow_penetration=settings.allow_penetration)
        setup_time = time.perf_counter() - setup_start
        sim_params = {"method": self.name, "start": "state" if from_state else start,
                      "rtol": rtol, "atol": atol_record(atol),
                      "max_step": settings.max_step, "t_end": t_end, "backend": session.backend}
        if t0 != 0.0:
            sim_params["t0"] = t0
        try:
            rec = Recorder(model, parameters={**model.parameters, "simulate": sim_params}, method=self.name,
                           stream_to=save.stream_to, keep_data=save.keep_data)
        except BaseException:
            session.close()
            raise
        return SegmentLoop(model, session, rec, t0, y0, yp0, t_end, save.times, save.steps, progress).run(
            on_failure, setup_time, sim_params)


def _start_session(model: DAEModel, t0: float, y0: NDArray | None, *, rtol: float, atol: Any, backend: str,
                   max_step: float, max_steps: int, linear_solver: str, start: str,
                   allow_penetration: bool) -> tuple[Any, NDArray, NDArray]:
    """Open one run's IDA session and find its consistent start (the session is closed if that fails)."""
    atol_vec = tolerance_vector(model, rtol, atol)
    session = open_session(model.functions, backend=backend, rtol=rtol, atol=atol_vec, max_step=max_step,
                           parameters=model.parameter_values, max_steps=max_steps, linear_solver=linear_solver)
    try:
        if y0 is None:
            y0, yp0 = model.initial_state(session=session, start=start, allow_penetration=allow_penetration)
        else:  # a given state: q and v kept (GGL: projected), multipliers and derivatives recomputed at t0
            y0, yp0 = model.consistent_state(t0, y0, session=session, project=True)
            if not allow_penetration:  # held to the declared start's limit
                physics.check_start_penetration(model, y0, yp0, session, given=True)
    except BaseException:
        session.close()
        raise
    session.set_hints(jacobian_refresh=JACOBIAN_REFRESH,
                      first_step=FIRST_STEP_ESTIMATE and model.formulation == "ggl")
    if model.formulation == "ggl" and model.n_constraints:  # without constraints GGL is index-1
        # never ask Newton for corrections below round-off: coef * rtol >= 1e-13
        session.set_hints(nonlin_conv_coef=min(0.33, max(GGL_NEWTON_COEF, 1e-13 / rtol)))
    session.set_stall(STALL_STEP, STALL_COUNT)
    return session, y0, yp0


def smallest_clearance(model: DAEModel) -> float:
    """The smallest clearance of the model's clearance joints (inf without any)."""
    return physics.smallest_clearance(model)
