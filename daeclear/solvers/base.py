"""The one contract every solver of :func:`daeclear.simulate` implements: a class, named
(:data:`daeclear.solvers.registry.SOLVERS`) or given (``method=MySolver``), with a ``run``
(:class:`Solver`). The registered ones are :class:`DrivenSolver` s: their ``run`` is the one run
driver's (:mod:`daeclear.solvers.driver`) over the integrator they make, so a subclass that makes an
integrator gets events, recording, checks and partial results from the driver."""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

from numpy.typing import NDArray

from ..core.errors import SceneError
from ..core.methods import FIXED_STEP
from . import driver

if TYPE_CHECKING:
    from ..assembly.dae_model import DAEModel
    from ..model.scene import Scene
    from ..results.result import Result
    from .integrator import Integrator
    from .save_at import Output
    from .solver_options import SolverOptions


@runtime_checkable
class Solver(Protocol):
    """An integrator of an assembled model from t0 to t_end: ``name`` is what ``result.method`` reports,
    ``formulation`` what a Scene is assembled with when the options name none."""

    name: ClassVar[str]
    formulation: ClassVar[str]

    def check(self, settings: SolverOptions) -> None:
        """Refuse (SceneError) a setting this method does not take (e.g. ``step``) or needs and lacks;
        called when the SolverOptions naming the method are made."""

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate ``model`` (a Scene is assembled with ``settings.formulation`` or this solver's own)
        from ``t0`` to ``t_end``; everything given is checked (``y0``'s length once the model is known).
        A failed run raises :class:`daeclear.SolveError` (``on_failure="raise"``) or returns its partial
        Result with ``success=False``."""


class DrivenSolver:
    """A :class:`Solver` whose run is the driver's (:func:`daeclear.solvers.driver.run`): a subclass
    names itself (``name``, ``formulation``), refuses what it does not take (``check``) and makes the
    run's integrator (``integrator``, the interface of :class:`daeclear.solvers.integrator.Integrator`)."""

    name: ClassVar[str]
    formulation: ClassVar[str]

    def check(self, settings: SolverOptions) -> None:
        """Refuse a setting this method does not take (SceneError); none by default."""

    def integrator(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions) -> Integrator:
        """The run's integrator, open; SceneError (before any work) for a model it cannot integrate."""
        raise NotImplementedError(f"{type(self).__name__} makes no integrator")

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate from ``t0`` to ``t_end`` (the :class:`Solver` contract): the driver's run."""
        return driver.run(self, model, t_end, t0, y0, save, settings, on_failure, progress)


def step_rule(name: str, step: float | None, *, fixed: bool) -> None:
    """``step`` is required by a fixed-step method and refused by the others (``name``: the method's)."""
    if fixed and step is None:
        raise SceneError(f"simulate: method={name!r} is a fixed-step scheme and needs "
                         "step=<step size in s> (the chapter uses 1e-5 s).")
    if not fixed and step is not None:
        raise SceneError(f"simulate: step={step!r} is only for the fixed-step methods "
                         f"({', '.join(repr(m) for m in FIXED_STEP)}); method={name!r} chooses its "
                         "own steps (use max_step to bound them).")
