"""The IDA solver (:class:`IDA`, the method "ida" of :func:`daeclear.simulate`): sets a run up for
its segment loop (:class:`daeclear.solvers.ida_loop.SegmentLoop`)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, ClassVar

from numpy.typing import NDArray

from ..core import options as opts
from ..assembly import physics
from ..assembly.assemble import DAEModel, assemble
from ..engine.ida_session import open_session
from .base import step_rule
from .ida_loop import SegmentLoop
from .recorder import Recorder
from .tolerances import atol_record, tolerance_vector
from ..results.result import Result
from ..model.scene import Scene

if TYPE_CHECKING:
    from .save_at import Output
    from .solver_options import SolverOptions

DRIFT_FRACTION = physics.DRIFT_FRACTION  # physics' limit, named here too
# IDA's settings (docs/engine.md): GGL's Newton test coefficient (IDA's default 0.33; the python backend
# cannot set it), a new Jacobian when cj = alpha / h changed by JACOBIAN_REFRESH (IDA's own 0.25, which
# costs contact runs stale-matrix failures), and for GGL the compiled driver's second-order first step.
GGL_NEWTON_COEF = 1e-3
JACOBIAN_REFRESH = 0.05
IDA_JACOBIAN_REFRESH = 0.25  # IDA's own, what the python backend (scikit-sundae) runs with
FIRST_STEP_ESTIMATE = True
# Stall guard: STALL_COUNT steps shorter than STALL_STEP seconds that do not grow end the run with a
# clear message (e.g. plain Coulomb friction sticking; contact steps are 1e-9..1e-6 s; docs/reliability.md).
STALL_STEP = 2.4e-12
STALL_COUNT = 2000


class IDA:
    """SUNDIALS IDA on the DAE (any formulation), with root finding and consistent restarts: the compiled
    loop in C or (``backend="python"``) the same loop on scikit-sundae."""

    name: ClassVar[str] = "ida"
    formulation: ClassVar[str] = opts.DEFAULT_FORMULATION

    def check(self, settings: SolverOptions) -> None:
        """IDA chooses its own steps: a fixed ``step`` is refused."""
        step_rule(self.name, settings.step, fixed=False)

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate from ``t0`` to ``t_end`` (the :class:`daeclear.solvers.base.Solver` contract)."""
        setup_start = time.perf_counter()
        if not isinstance(model, DAEModel):
            model = assemble(model, settings.formulation or self.formulation, track_work=settings.track_work)
        y0 = None if y0 is None else opts.state(y0, model.n_states)
        save.check_size(step=None, n_states=model.n_states,
                        n_channels=len(model.channel_names))  # before the session: nothing compiled or run
        from_state = y0 is not None
        session, y0, yp0 = _start_session(model, t0, y0, settings)
        setup_time = time.perf_counter() - setup_start
        sim_params = {"method": self.name, "start": "state" if from_state else settings.start,
                      "rtol": settings.rtol, "atol": atol_record(settings.atol_value()),
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


def _start_session(model: DAEModel, t0: float, y0: NDArray | None,
                   settings: SolverOptions) -> tuple[Any, NDArray, NDArray]:
    """Open one run's IDA session and find its consistent start (the session is closed if that fails)."""
    rtol, allow_penetration = settings.rtol, settings.allow_penetration
    session = open_session(model.compiled, backend=settings.backend, rtol=rtol,
                           atol=tolerance_vector(model, rtol, settings.atol_value()), max_step=settings.max_step,
                           parameters=model.parameter_values, max_steps=settings.max_steps,
                           linear_solver=settings.linear_solver)
    try:
        if y0 is None:
            y0, yp0 = model.initial_state(session=session, start=settings.start, allow_penetration=allow_penetration)
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
