"""What the one run driver (:mod:`daeclear.solvers.driver`) needs of an integrator, as scipy's
``solve_ivp`` needs ``OdeSolver.step``: :class:`Integrator`. The driver owns the run (the contact
state and its decisions at roots, consistent restarts, recording, checks, progress, interrupts); an
integrator integrates between two restarts and says where it stopped (an
:class:`~daeclear.engine.session_base.Advance`). IDA (:mod:`daeclear.solvers.ida`, compiled or
python session) and the ODE methods (:mod:`daeclear.solvers.ode_integrators`) implement it.

Also here: :class:`Terms` (what a segment integrates with), :class:`Jump` (what the driver knows at
each event: the one place for a quantity that jumps there) and :class:`AutoPair` (a pair an
integrator decides itself).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, NamedTuple, Protocol, runtime_checkable

from numpy.typing import NDArray

from ..assembly.contact_pairs import PairLogic
from ..assembly.contact_state import ContactState
from ..assembly.dae_model import ExtrasEvaluator
from ..core.automaton import PairState
from ..core.events import ContactEvent
from ..engine.session_base import Advance, Session

if TYPE_CHECKING:
    from ..assembly.dae_model import DAEModel
    from .save_at import Output
    from .solver_options import SolverOptions

__all__ = ["AutoPair", "Carried", "Driven", "Integrator", "Jump", "Terms", "auto_pairs"]


class Terms(NamedTuple):
    """What a segment integrates with: which contact terms act (``active``), each term's parameters, and
    the direction each root is watched in (+1 up, -1 down, 0 both; None: the model has no roots)."""

    active: list[bool]
    params: list[NDArray]
    directions: NDArray | None


@dataclass(frozen=True)
class Jump:
    """One event time of a run as the driver handles it: where a quantity integrated beside the states
    jumps (the one place: :meth:`daeclear.solvers.driver.Driver.jump`).

    ``y_minus``, ``yp_minus``: the state and its derivative at the root ``t`` in the mode before;
    ``y_plus``, ``yp_plus``: the consistent state the integrator restarts from in the new mode (the
    same arrays when nothing switched and it goes on). IDA's root state has the gap closed to round-off,
    where a law whose force jumps at contact (Kelvin-Voigt) still gives zero: ``yp_plus`` is then not the
    right limit (the ODE methods restart past the root, where it is). ``found``: the roots found (+1 up, -1 down, 0
    none); ``events``: the contact events decided at ``t``; ``state``: the run's contact state after
    them (each pair's mode, hold and latched approach speed). Switches the integrator decided itself
    (``by_integrator``, the compiled loop's simple pairs) carry the state at the event only:
    ``yp_minus``, ``y_plus``, ``yp_plus``, ``found`` and ``state`` are None."""

    t: float
    y_minus: NDArray
    yp_minus: NDArray | None
    y_plus: NDArray | None
    yp_plus: NDArray | None
    found: NDArray | None
    events: tuple[ContactEvent, ...]
    state: ContactState | None
    restarted: bool
    by_integrator: bool = False
    projected: bool = False  # y_plus was projected onto GGL's constraint manifold


@runtime_checkable
class Carried(Protocol):
    """An integrator that carries a quantity beside a run's states, which jumps at its events (the
    sensitivities of :mod:`daeclear.solvers.sensitivity_ida`, its parameters ``names``): the driver
    calls :meth:`jump` at every event, before the integrator restarts, :meth:`stream` before it hands rows
    to a streamed file, and :meth:`attach` with the finished Result."""

    names: tuple[str, ...]

    def jump(self, jump: Jump) -> None:
        """Jump at the event ``jump`` (the driver decided its switches)."""
        ...

    def attach(self, result: Any) -> None:
        """Put what was carried on the run's Result."""
        ...

    def stream(self, writer: Any) -> None:
        """A streamed run: what was carried since the last call to the run's file (its ResultWriter), before
        the driver appends the rows it goes with."""
        ...


class AutoPair(NamedTuple):
    """A pair whose switches an integrator may decide itself (``model.auto_pairs``, in that order):
    its contact element, root, name, switch-vector column of its term and whether the term's
    parameter is the latched approach speed."""

    logic: PairLogic
    root: int
    name: str
    column: int
    needs_speed: bool


def auto_pairs(model: DAEModel) -> list[AutoPair]:
    """The model's simple pairs (:class:`AutoPair`), in the order of ``model.auto_pairs``."""
    owners = {root: logic for logic in model.contacts for root in logic.roots}
    columns = list(itertools.accumulate((1 + term.n_params for term in model.terms), initial=0))
    return [AutoPair(owners[root], root, owners[root].pair_name(root), columns[term], bool(needs))
            for root, term, _, needs, _ in model.auto_pairs]


class RootEvaluator(Protocol):
    """Evaluates the model's root functions at one point in C (a session, or the stacked session of a run
    with sensitivities through its states' rows)."""

    def roots(self, t: float, y: NDArray, yp: NDArray) -> NDArray:
        """The root functions at (t, y, yp) of the model's state y."""
        ...


class Integrator(Protocol):
    """An integrator of one run (made by :meth:`Driven.integrator`), between restarts.

    Rows: the states it reports (``Advance.step_y``, ``eval_y``) are rows of the DAE's state; it may
    leave what it does not integrate (an ODE in (q, v): the multipliers) for :meth:`complete`."""

    @property
    def name(self) -> str:
        """The subject of its failure messages ("IDA", "RK45", ...)."""
        ...

    @property
    def backend(self) -> str:
        """Where the model is evaluated: "c" or "python"."""
        ...

    @property
    def session(self) -> Session | None:
        """The run's open IDA session (the model's functions in C for the checks and restarts), or None."""
        ...

    @property
    def root_evaluator(self) -> RootEvaluator | None:
        """What evaluates the model's roots in C at the driver's restarts: the session, or (a run with
        sensitivities) the stacked session through its states' rows; None: CasADi's."""
        ...

    @property
    def extras(self) -> ExtrasEvaluator | None:
        """What evaluates the model's extras in C for the driver's restarts: the session, or (a run with
        sensitivities) the stacked session, whose extras begin with the model's; None: CasADi's."""
        ...

    @property
    def lazy_rows(self) -> bool:
        """Its rows are the DAE's own states: kept as they are in memory, made consistent when first read
        (IDA); else the driver has them completed (:meth:`complete`) before they are recorded."""
        ...

    @property
    def resumes_at_roots(self) -> bool:
        """It goes on from a root with no restart when nothing switched (IDA); else the driver restarts it
        at every root, and each such restart begins a segment."""
        ...

    @property
    def decides(self) -> bool:
        """It decides the switches of the model's simple pairs itself (``Advance.auto_events``; set by start)."""
        ...

    @property
    def order(self) -> int:
        """The order recorded with the start point's step (the steps after it come with their own)."""
        ...

    @property
    def fixed_step(self) -> float | None:
        """The step (s) of a fixed-step scheme, else None (the fixed-step checks read it)."""
        ...

    @property
    def missed(self) -> list[tuple[float, float, str]]:
        """The steps over which it saw a gap change sign without an event (t_start, t_end, pair)."""
        ...

    def start(self, t: float, y: NDArray, yp: NDArray, terms: Terms, state: ContactState) -> None:
        """Initialise at the run's consistent start (``state``: the run's contact state there, for the
        pairs it decides itself); the start itself is recorded by the driver."""
        ...

    def restart(self, t: float, y: NDArray, yp: NDArray, terms: Terms) -> None:
        """Re-initialise at a consistent state after a root (the driver has completed the rows before)."""
        ...

    def consistent(self, t: float, y: NDArray, terms: Terms) -> tuple[NDArray, NDArray]:
        """The DAE state with the positions and velocities of ``y`` and its derivative, consistent in the
        mode of ``terms`` (multipliers and accelerations recomputed), as this integrator evaluates the model."""
        ...

    def advance(self) -> Advance:
        """Integrate towards the run's end: stop there (``"tstop"``), at a root (``"root"``: its time,
        the state there in the mode before, the roots found), on a failure (``"error"``: flag and
        message), with a full buffer (``"chunk"``) or on Ctrl-C (``"interrupted"``: what it computed).
        Reports its steps since the last advance (their states when the run's output is its steps; none
        needed when the output keeps no steps) and its dense output at the run's output times it passed."""
        ...

    def pair_states(self) -> dict[int, PairState]:
        """The automaton state of each pair it decides, by root (read after every advance)."""
        ...

    def complete(self, t: NDArray, y: NDArray, switch: NDArray, *, in_place: bool
                 ) -> tuple[NDArray, NDArray, dict[str, NDArray] | None]:
        """Reported rows made consistent (y with multipliers, yp; the channels when it computes them),
        each with its switch vector; ``in_place``: ``y`` is the driver's own copy (may be overwritten)."""
        ...

    def advice(self, adv: Advance, in_contact: list[str]) -> str:
        """What to try after a failed advance (``in_contact``: the pairs in contact then)."""
        ...

    def stats(self) -> dict[str, Any]:
        """Its counters and timings."""
        ...

    def close(self) -> None:
        """Free what it holds (the session returns to its pool)."""
        ...


class Driven(Protocol):
    """A solver class whose run is the driver's (:class:`daeclear.solvers.base.DrivenSolver`): it makes
    the integrator of a run."""

    name: ClassVar[str]
    formulation: ClassVar[str]

    def check(self, settings: SolverOptions) -> None:
        """Refuse a setting the method does not take (SceneError)."""
        ...

    def integrator(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions) -> Integrator:
        """The run's integrator, open (SceneError: a model it cannot integrate, before any work)."""
        ...
