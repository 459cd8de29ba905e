"""The IDA solver (:class:`IDA`, the method "ida" of :func:`daeclear.simulate`) and its integrator
(:class:`IDAIntegrator`): an IDA session, compiled (:mod:`daeclear.engine.c_session`) or python
(:mod:`daeclear.engine.python_session`), as the run driver's :class:`~daeclear.solvers.integrator.Integrator`.

The compiled loop may decide simple pairs' switches itself and make the points consistent itself
(after ``set_layout``): its advances then carry those switches (``Advance.auto_events``), which the
driver records. Output times go to the compiled loop at most :data:`EVAL_WINDOW` at a time.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state, physics
from ..assembly.contact_state import ContactState
from ..assembly.dae_model import DAEModel
from ..core.automaton import PairState
from ..core.methods import by_key
from ..core.options import OutputTimes
from ..engine.ida_session import open_session
from ..engine.session_base import Advance, Session
from .base import DrivenSolver, step_rule
from .integrator import AutoPair, Terms, auto_pairs
from .save_at import Output
from .tolerances import tolerance_vector

if TYPE_CHECKING:
    from .solver_options import SolverOptions

__all__ = ["IDA", "IDAIntegrator", "EVAL_WINDOW", "steps_needed"]

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
#: Output times handed to the compiled loop at a time: their rows are emptied between windows.
EVAL_WINDOW = 4096
# Failures in contact that plain Coulomb friction causes when the contact sticks.
STICKING_FLAGS = ("DC_STEP_COLLAPSE", "IDA_CONV_FAIL", "IDA_ERR_FAIL")


class IDA(DrivenSolver):
    """SUNDIALS IDA on the DAE (any formulation), with root finding and consistent restarts: the compiled
    loop in C or (``backend="python"``) the same loop on scikit-sundae."""

    name: ClassVar[str] = by_key("ida").name
    formulation: ClassVar[str] = by_key("ida").formulation

    def check(self, settings: SolverOptions) -> None:
        """IDA chooses its own steps: a fixed ``step`` is refused."""
        step_rule(self.name, settings.step, fixed=False)

    def integrator(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions) -> IDAIntegrator:
        """The run's IDA session, open with the run's settings and hints."""
        return IDAIntegrator(model, t_end, output, settings)


class IDAIntegrator:
    """One run's IDA session as the driver's integrator (:class:`daeclear.solvers.integrator.Integrator`)."""

    name = "IDA"
    lazy_rows = True
    resumes_at_roots = True
    order = 0  # the start's row; IDA reports each step's own order
    fixed_step: float | None = None

    @property
    def extras(self) -> Session:
        """The session evaluates the model's extras."""
        return self.session

    @property
    def root_evaluator(self) -> Session:
        """The session evaluates the model's roots."""
        return self.session

    def __init__(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions) -> None:
        rtol = settings.rtol
        self.model, self.t_end, self.times, self.store_steps = model, t_end, output.times, output.steps
        self.session: Session = open_session(
            model.compiled, backend=settings.backend, rtol=rtol,
            atol=tolerance_vector(model, rtol, settings.atol_value()), max_step=settings.max_step,
            parameters=model.parameter_values, max_steps=settings.max_steps, linear_solver=settings.linear_solver)
        session = self.session
        try:
            session.set_hints(jacobian_refresh=JACOBIAN_REFRESH,
                              first_step=FIRST_STEP_ESTIMATE and model.formulation == "ggl")
            if model.formulation == "ggl" and model.n_constraints:  # without constraints GGL is index-1
                # never ask Newton for corrections below round-off: coef * rtol >= 1e-13
                session.set_hints(nonlin_conv_coef=min(0.33, max(GGL_NEWTON_COEF, 1e-13 / rtol)))
            session.set_stall(STALL_STEP, STALL_COUNT)
        except BaseException:
            session.close()
            raise
        self.backend = session.backend
        self.missed: list[tuple[float, float, str]] = []
        self.t_start = 0.0
        self.i_eval = 0  # the next output time
        self.c_layout = False  # the compiled loop makes the points consistent itself
        self.decides = False  # the compiled loop decides every contact switch itself
        self.auto: list[AutoPair] = []

    def start(self, t: float, y: NDArray, yp: NDArray, terms: Terms, state: ContactState) -> None:
        """Start IDA; let the compiled loop make states consistent and decide simple pairs' switches."""
        model, session = self.model, self.session
        self.t_start = t
        self.i_eval = int(self.times is not None and self.times.window(0, 1)[0] == t)  # the driver's start row
        self.c_layout = session.set_layout(model.layout(project=model.formulation == "ggl"))
        session.reinit(t, y, yp, terms.active, terms.params, terms.directions)
        if model.auto_pairs:  # simple pairs: each one's rule and start state from its logic object
            self.auto = auto_pairs(model)
            self.decides = self.c_layout and session.set_auto_events(
                model.auto_pairs, storms=[pair.logic.storm for pair in self.auto],
                states=[contact_state.pair_state(model, state, pair.root) for pair in self.auto])

    def consistent(self, t: float, y: NDArray, terms: Terms) -> tuple[NDArray, NDArray]:
        """q and v of ``y`` kept, multipliers and derivatives in the mode of ``terms`` (in the session's library)."""
        model, session = self.model, self.session
        return model.consistent_state(t, y, model.term_forces(t, y, terms.active, terms.params, session), session)

    def restart(self, t: float, y: NDArray, yp: NDArray, terms: Terms) -> None:
        """IDA re-initialised at a consistent state, with new terms and root directions."""
        self.session.reinit(t, y, yp, terms.active, terms.params, terms.directions)

    def advance(self) -> Advance:
        """One call of the session's loop, with the next window of output times (if any)."""
        session, times = self.session, self.times
        window = None
        if times is not None:  # the next output times (compiled loop: at most EVAL_WINDOW of them)
            self.i_eval, window = _eval_window(times, self.i_eval, session.eval_from,
                                               EVAL_WINDOW if self.c_layout else times.size)
        adv = session.advance(self.t_end, window, self.store_steps, store_states=times is None,
                              chunked=True, store_yp=False)
        self.i_eval += adv.eval_t.size
        if self.decides and adv.status == "root":  # the compiled loop left a root to Python: an internal error
            adv.status, adv.flag_name = "error", "DC_EVENT_MISMATCH"
            adv.message = "internal: the compiled event loop left a contact root undecided"
        return adv

    def pair_states(self) -> dict[int, PairState]:
        """The states of the pairs the compiled loop decides, read from the loop (no replay)."""
        return {pair.root: st for pair, st in zip(self.auto, self.session.pair_states())}

    def complete(self, t: NDArray, y: NDArray, switch: NDArray, *, in_place: bool
                 ) -> tuple[NDArray, NDArray, dict[str, NDArray] | None]:
        """Multipliers and accelerations recomputed from q and v (IDA does not converge them): one pass
        in C (states only: the file's reader computes the channels), else the model's functions."""
        model, session = self.model, self.session
        if self.c_layout:
            y_out, yp_out, _ = session.report(t, y, switch, channels=False,
                                              into=(y, np.empty(y.shape)) if in_place else None)
            return y_out, yp_out, None
        y_out, yp_out = model.consistent_state(t, y, model.term_forces_rows(t, y, switch, session), session)
        return y_out, yp_out, None

    def advice(self, adv: Advance, in_contact: list[str]) -> str:
        """What to try after IDA failed (each advice made the failing case of a test finish:
        tests/test_tolerances.py)."""
        model = self.model
        other = "index1" if model.formulation == "ggl" else "ggl"
        if adv.flag_name == "DC_MAX_STEPS":  # not an accuracy problem: the run needs more steps
            needed = steps_needed(self.session.max_steps, self.t_start, adv.t, self.t_end)
            return (f"The run needs more steps than max_steps allows: raise max_steps to about {needed} "
                    f"(daeclear run: --max-steps {needed}).")
        # sticking under plain Coulomb: index-1 chatters until the stall guard stops it, GGL's Newton
        # iteration fails to converge (or its error test fails) at the sticking point
        if adv.flag_name in STICKING_FLAGS and in_contact and any(
                getattr(logic, "discontinuous_friction", False) for logic in model.contacts):
            return ("The friction law is discontinuous at zero sliding speed (plain Coulomb) and the "
                    "contact is sticking: use the modified Coulomb law (friction=<coefficient> or "
                    "daeclear.contact.ModifiedCoulomb), which is continuous.")
        return f"Try formulation='{other}'."

    def stats(self) -> dict[str, Any]:
        return dict(self.session.stats())

    def close(self) -> None:
        self.session.close()


def _eval_window(times: OutputTimes, i: int, t: float, size: int) -> tuple[int, NDArray]:
    """The output times after ``t`` from index ``i`` on, at most ``size``: (index of the first, times)."""
    while i < times.size:
        window = times.window(i, i + size)
        lo = int(window.searchsorted(t, side="right"))
        if lo < window.size:
            return i + lo, window[lo:]
        i += window.size
    return i, np.zeros(0)


def steps_needed(cap: int, t0: float, t: float, t_end: float) -> int:
    """A step cap that lets a run capped at ``cap`` steps at ``t`` reach ``t_end``: the steps so far in
    proportion to the time still to go, with a margin of a half, on two significant digits."""
    estimate = 1.5 * cap * (t_end - t0) / max(t - t0, 1e-300)
    digits = max(int(math.floor(math.log10(estimate))) - 1, 0)
    return int(math.ceil(estimate / 10 ** digits) * 10 ** digits)

