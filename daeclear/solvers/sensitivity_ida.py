"""IDA on the stacked DAE [y; S] as the run driver's integrator (``simulate(..., sensitivities=[...])``).

:class:`SensitivityIntegrator` integrates the states and S = dy/dp together (the sensitivity residual of
:func:`daeclear.engine.sensitivity_functions.augmented_functions`; IDAS' simultaneous corrector: its
Newton matrix is the state's iteration matrix on each of the 1 + Ns diagonal blocks, factored once at
n x n by the solver the state's run would use and applied block by block; :func:`stacked_reference`
makes IDA factor the (1 + Ns) n matrix instead, the reference of the tests and
benchmarks/bench_sensitivity.py) and reports the states' rows to the driver; S's rows, made consistent
in their mode with the channels' sensitivities, go to its :class:`SensitivityCarrier`. The driver decides
every root and calls the carrier's jump at every event (:meth:`daeclear.solvers.driver.Driver.jump`); a
restart then begins from the carrier's S. It restarts at every root (as the reference run did) and
decides no switch itself. Error control: S in the test, scaled by each parameter's magnitude (IDAS'
``pbar``: atol_S = atol / |p|); multipliers out.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..assembly.contact_state import ContactState
from ..assembly.dae_model import DAEModel
from ..assembly.sensitivity import parameter_value
from ..core.errors import SceneError
from ..core.automaton import PairState
from ..engine.compiled import CompiledDAE
from ..engine.ida_session import open_session
from ..engine.sensitivity_functions import augmented_functions, stacked_extras
from ..engine.session_base import Advance, Session
from . import ida
from .integrator import Jump, Terms
from ..results.result import Result, ResultWriter
from ..results.sensitivities import EventSides, Sensitivities
from .save_at import Output
from .sensitivity_carrier import SensitivityCarrier, onset_limit, parameter_scales
from .sensitivity_quadrature import Quadratures
from .tolerances import tolerance_vector

if TYPE_CHECKING:
    from .solver_options import SolverOptions

__all__ = ["SensitivityIDA", "SensitivityIntegrator", "stacked_reference", "OUT_OF_ERROR_TEST"]

#: S's absolute tolerance in IDA's error test with ``SolverOptions(sensitivity_error_test=False)``: its weight
#: 1/(rtol |S| + 1e100) leaves it out (its Newton test keeps the weights of atol / |p|: csrc/ida_newton.h).
OUT_OF_ERROR_TEST = 1e100


class SensitivityIDA(ida.IDA):
    """The "ida" method of a run with sensitivities (``simulate(..., sensitivities=names)``): its
    integrator is IDA on [y; S]."""

    def __init__(self, names: list[str], integrals: list[str] | None = None) -> None:
        self.names = list(names)
        self.integrals = list(integrals or [])

    def integrator(self, model: DAEModel, t_end: float, output: Output,  # type: ignore[override]
                   settings: SolverOptions) -> SensitivityIntegrator:
        """The run's IDA session on [y; S], open with the run's settings."""
        return SensitivityIntegrator(model, t_end, output, settings, self.names, self.integrals)


@contextmanager
def stacked_reference() -> Iterator[None]:
    """Runs with sensitivities started inside factor the (1 + Ns) n block-diagonal Newton matrix whole
    (the path before the state's factorisation was reused): a reference for tests and benchmarks only."""
    before = SensitivityIntegrator.stacked_factorisation
    SensitivityIntegrator.stacked_factorisation = True
    try:
        yield
    finally:
        SensitivityIntegrator.stacked_factorisation = before


class StackedRoots:
    """The model's roots at a point of its state y in the stacked session's C: its roots are those of y
    (:func:`~daeclear.engine.sensitivity_functions.augmented_functions`), so S's rows are given as zeros."""

    def __init__(self, stacked: Session, n: int, size: int) -> None:
        self.stacked = stacked
        self.Y, self.Yp = np.zeros(size), np.zeros(size)  # y in the first n of the stacked session's size rows
        self.n = n

    def roots(self, t: float, y: NDArray, yp: NDArray) -> NDArray:
        """The model's root functions at (t, y, yp)."""
        self.Y[:self.n], self.Yp[:self.n] = y, yp
        return self.stacked.roots(t, self.Y, self.Yp)


class SensitivityIntegrator:
    """One run's IDA session on [y; S] as the driver's :class:`~daeclear.solvers.integrator.Integrator`."""

    name = "IDA"
    lazy_rows = True  # the rows are the DAE's states, made consistent when read (as IDA's: a file keeps states only)
    resumes_at_roots = False
    decides = False
    order = 0
    fixed_step: float | None = None
    session: Session | None = None  # the model's own roots serve the driver (the stacked session is S's)
    stacked_factorisation = False  # True: the reference path of stacked_reference()
    coupling = True  # the compiled session's block forward substitution with the blocks below the diagonal

    def __init__(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions,
                 names: list[str], integrals: list[str] | None = None) -> None:
        rtol = settings.rtol
        self.model, self.t_end, self.times, self.store_steps = model, t_end, output.times, output.steps
        self.settings = settings
        atol = tolerance_vector(model, rtol, settings.atol_value())
        self.sens = SensitivityCarrier(model, names, rtol, atol)
        self.names = self.sens.names
        self.values = np.array([parameter_value(model, name) for name in self.names])  # the run's parameters
        W = self.sens.width
        pbar = parameter_scales(model, self.sens.names)
        block = not self.stacked_factorisation
        # the integrals of channels as states after y in every block (dc.Integral under error control)
        self.quad = Quadratures(model, integrals, W) if integrals else None
        funcs = model.functions if self.quad is None else self.quad.functions(model.functions)
        self.n_block = int(funcs.n)
        if self.quad is not None:
            atol = np.concatenate([atol, self.quad.atol(rtol, settings.quadrature_atol)])
        atol_S = np.concatenate([atol / p for p in pbar])  # IDAS' pbar: S |p| held to the states' atol
        tested = settings.sensitivity_error_test
        derivatives = self.sens.ms.row_derivatives(model)
        if self.quad is None:
            stacked_functions = model.compiled.stacked(W, block and self.coupling, block, derivatives)
        else:  # the DAE with the quadratures; the extras (rows, events) the model's, of its y
            stacked = augmented_functions(funcs, W, coupled=block and self.coupling, block=block)
            stacked_functions = CompiledDAE(dataclasses.replace(
                stacked, extras=stacked_extras(model.functions, W, derivatives), name=f"{stacked.name}x"))
        self.stacked = open_session(
            stacked_functions,
            backend=settings.backend, rtol=rtol,
            atol=np.concatenate([atol, atol_S if tested else np.full(atol_S.size, OUT_OF_ERROR_TEST)]),
            max_step=settings.max_step,
            max_steps=settings.max_steps,
            parameters=np.concatenate([model.parameter_values, self.sens.ms.dP.ravel(order="F")]),
            linear_solver=settings.linear_solver if block else "auto")
        self.sens.ms.session = self.stacked  # the rows' and events' pieces in its C (its extras)
        try:
            if block:  # the reduced LU eliminates the position rows, as in the state's run (its layout)
                self.stacked.set_kinematic_rows(model.n_q)
            if not tested and not self.stacked.set_newton_tolerances(np.concatenate([np.zeros(atol.size), atol_S])):
                raise SceneError("simulate: options.sensitivity_error_test=False, must be True with the python "
                                 "backend (S out of IDA's error test needs the compiled session's Newton test; "
                                 "backend='c')")
            # GGL's tight Newton coefficient left out: S's corrections converge linearly (the reference run's rule)
            self.stacked.set_hints(jacobian_refresh=ida.JACOBIAN_REFRESH,
                                   first_step=ida.FIRST_STEP_ESTIMATE and model.formulation == "ggl")
            self.stacked.set_stall(ida.STALL_STEP, ida.STALL_COUNT)
        except BaseException:
            self.stacked.close()
            raise
        self.backend = self.stacked.backend
        self.extras = self.stacked  # its extras begin with the model's (stacked_extras): the driver's restarts
        self.root_evaluator = StackedRoots(self.stacked, model.n_states, self.n_block * (1 + W))
        self.missed: list[tuple[float, float, str]] = []
        self.i_eval = 0
        self.t_start = 0.0

    def start(self, t: float, y: NDArray, yp: NDArray, terms: Terms, state: ContactState) -> None:
        """S at the start (dy0/dp of the run's start), consistent in the start's mode; IDA started."""
        settings = self.settings
        S0 = self.sens.ms.start(settings.start, settings.allow_penetration)
        self.sens.start(t, y, yp, state, S0)
        self.t_start = t
        if self.times is None or self.times.window(0, 1)[0] == t:  # the driver reports the start point
            self.sens.row(t, y, self.sens.S)
            if self.quad is not None:
                self.quad.row(self.quad.Q, self.quad.dQ, self.sens.poisoned)
            self.i_eval = int(self.times is not None)
        self.restart(t, y, yp, terms)

    def jump(self, jump: Jump) -> None:
        """The sensitivities' jump at an event the driver decided (before it restarts this integrator)."""
        n, W = self.model.n_states, self.sens.width
        assert jump.y_plus is not None and jump.state is not None  # the driver decides every switch here
        S = self.root_S.reshape(self.n_block, W, order="F")[:n]
        self.sens.jump(jump.t, jump.y_minus, S, jump.found, jump.state, jump.events, jump.y_plus, jump.projected)
        if self.quad is not None:  # the event's rows before and after its switch: the channels' jump
            before, after = self.sens.event_rows[-2][3], self.sens.event_rows[-1][3]
            if jump.yp_minus is not None and any(e.kind == "onset" for e in jump.events):  # read inside the contact
                y_p, yp_m, c = jump.y_plus, jump.yp_minus, self.sens
                after = onset_limit(lambda s: c.evaluate_rows(np.array([jump.t + s]), (y_p + s * yp_m)[None],
                                                              c.S[None])[5][0], jump.t)
            self.quad.jump(before, after, self.sens.dt_dp)

    def consistent(self, t: float, y: NDArray, terms: Terms) -> tuple[NDArray, NDArray]:
        """q and v of ``y`` kept, multipliers and derivatives in the mode of ``terms``."""
        model, extras = self.model, self.stacked
        return model.consistent_state(t, y, model.term_forces(t, y, terms.active, terms.params, extras), extras)

    def restart(self, t: float, y: NDArray, yp: NDArray, terms: Terms) -> None:
        """IDA re-initialised at ``(y, yp)`` and the carrier's S, S' (after its jump); the friction kinks,
        roots after the gaps, watched as the carrier says."""
        c, quad = self.sens, self.quad
        directions = terms.directions
        if self.model.kink_terms:
            gaps = np.zeros(len(self.model.gap_names), dtype=np.int32) if directions is None else directions
            directions = np.concatenate([gaps, c.kink_watch])
        if quad is None:
            self.stacked.reinit(t, np.concatenate([y, c.S.ravel(order="F")]),
                                np.concatenate([yp, c.Sp.ravel(order="F")]), terms.active, c.terms_stacked(),
                                directions)
            return
        channel_S, values = (a[0] for a in c.evaluate_rows(np.array([t], dtype=float), y[None], c.S[None])[4:])
        rate, rate_S = quad.rates(values, channel_S)
        switch = self.model.switch_vector(c.active, c.params)
        extra = quad.term(switch, c.ms.switch_sensitivity(c.S_params))
        self.stacked.reinit(t, np.concatenate([y, quad.Q, np.vstack([c.S, quad.dQ]).ravel(order="F")]),
                            np.concatenate([yp, rate, np.vstack([c.Sp, rate_S]).ravel(order="F")]),
                            [*terms.active, *(True for _ in extra)], [*c.terms_stacked(), *extra], directions)

    def advance(self) -> Advance:
        """Integrate [y; S] to the end or a root; the states' rows to the driver, S's rows to the carrier."""
        n, W, times, nb, quad = self.model.n_states, self.sens.width, self.times, self.n_block, self.quad
        window = None if times is None else times.window(self.i_eval, times.size)
        adv = self.stacked.advance(self.t_end, window, self.store_steps, store_states=times is None,
                                   store_yp=False)
        rows_t, rows_y = (adv.step_t, adv.step_y) if times is None else (adv.eval_t, adv.eval_y)
        if times is not None:
            self.i_eval += adv.eval_t.size
        if rows_t.size:  # every row of this advance is in one mode: one mapped evaluation for all
            S = rows_y[:, nb:].reshape(-1, W, nb).transpose(0, 2, 1)  # (rows, nb, W)
            self.sens.rows(rows_t, rows_y[:, :n], S[:, :n])
            if quad is not None:
                for k in range(rows_t.size):
                    quad.row(rows_y[k, n:nb], S[k, n:], self.sens.poisoned)
        self.root_S = adv.y[nb:]
        if quad is not None:
            quad.Q, quad.dQ = adv.y[n:nb].copy(), self.root_S.reshape(nb, W, order="F")[n:].copy()
        adv.y, adv.yp = adv.y[:n], adv.yp[:n]
        if adv.status == "root" and self.free_kinks_only(adv.roots_found):
            adv.status = "chunk"  # a kink of a term that is off: nothing to do there, IDA goes on (no restart)
        adv.step_y = adv.step_y[:, :n] if adv.step_y.ndim == 2 else adv.step_y
        adv.eval_y = adv.eval_y[:, :n] if adv.eval_y.ndim == 2 else adv.eval_y
        return adv

    def free_kinks_only(self, found: NDArray | None) -> bool:
        """Whether the roots ``found`` are all friction kinks of terms that are off (a pair in free flight,
        where its law's pieces do not matter: the onset's restart reads the piece it begins on)."""
        model = self.model
        if found is None or not model.kink_terms:
            return False
        found = np.ravel(found)
        n_gaps = len(model.gap_names)
        kinks = found[n_gaps:n_gaps + len(model.kink_terms)]
        return (not np.any(found[:n_gaps]) and bool(np.any(kinks))
                and not any(self.sens.active[k] for k, hit in zip(model.kink_terms, kinks) if hit))

    def pair_states(self) -> dict[int, PairState]:
        return {}

    def complete(self, t: NDArray, y: NDArray, switch: NDArray, *, in_place: bool
                 ) -> tuple[NDArray, NDArray, dict[str, NDArray] | None]:
        """Multipliers and accelerations recomputed from q and v in each row's mode."""
        model = self.model
        return (*model.consistent_state(t, y, model.term_forces_rows(t, y, switch, None)), None)

    def advice(self, adv: Advance, in_contact: list[str]) -> str:
        """What to try after IDA on [y; S] failed."""
        if adv.flag_name == "DC_MAX_STEPS":
            needed = ida.steps_needed(self.stacked.max_steps, self.t_start, adv.t, self.t_end)
            return f"The run needs more steps than max_steps allows: raise max_steps to about {needed}."
        return "Try a smaller rtol, or fewer sensitivities."

    def stats(self) -> dict[str, Any]:
        """The stacked session's counters, and the friction kinks crossed (``n_kinks``: each a restart)."""
        return {**self.stacked.stats(), "n_kinks": self.sens.n_kinks}

    def close(self) -> None:
        self.stacked.close()

    def attach(self, result: Result) -> None:
        """The rows' and events' sensitivities onto the run's Result (the rows it kept: after a MemoryError
        the driver drops its last unrecorded rows); a streamed run's file holds them (read back with it)."""
        if not self.streamed:
            result.sensitivities = self.collected(result.n_times)

    streamed = False  # the run streams its sensitivities to its file (stream)

    def stream(self, writer: ResultWriter) -> None:
        """A streamed run's sensitivities carried since the last call to its file (S with the output rows the
        driver appends next), then dropped: the run's memory does not grow with its length."""
        c = self.sens
        if not self.streamed:
            writer.sensitivities(c.names, self.model.channel_names, self.values,
                                 () if self.quad is None else self.quad.channels)
            self.streamed = True
        writer.stage_sensitivities(self.collected(min(len(c.rows_S), len(c.rows_channel_S))))
        for kept in (c.rows_t, c.rows_S, c.rows_channel_S, c.rows_channels, c.events, c.event_t, c.event_rows,
                     *(() if self.quad is None else (self.quad.rows_Q, self.quad.rows_dQ))):
            kept.clear()

    def collected(self, n: int) -> Sensitivities:
        """The first ``n`` rows carried, every event and its rows."""
        c, model = self.sens, self.model
        shape = (0, model.n_states, c.width), (0, len(model.channel_names), c.width)
        states = np.stack(c.rows_S[:n]) if n else np.zeros(shape[0])
        channels = np.stack(c.rows_channel_S[:n]) if n else np.zeros(shape[1])
        k = len(c.event_rows)
        n_ch = len(model.channel_names)
        sides = EventSides(np.array(c.event_t[:k]), *(
            np.stack([row[i] for row in c.event_rows]) if k else np.zeros(empty)
            for i, empty in ((0, (0, model.n_states)), (3, (0, n_ch)), (1, shape[0]), (2, shape[1]))))
        integrals = {} if self.quad is None else self.quad.collected(n)
        return Sensitivities(c.names, tuple(model.state_names), tuple(model.channel_names),
                             states, channels, tuple(c.events), sides, self.values, integrals)
