"""The one contract every integrator of :func:`daeclear.simulate` implements (as scipy's ``OdeSolver``):
a class, named (:data:`daeclear.solvers.registry.SOLVERS`) or given (``method=MySolver``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

from numpy.typing import NDArray

from ..core.errors import SceneError
from .ode_run import FIXED_STEP_METHODS

if TYPE_CHECKING:
    from ..assembly.assemble import DAEModel
    from ..model.scene import Scene
    from ..results.result import Result
    from .save_at import Output
    from .solver_options import SolverOptions


@runtime_checkable
class Solver(Protocol):
    """An integrator of an assembled model from t0 to t_end: ``name`` is what ``result.method`` reports,
    ``formulation`` what a Scene is assembled with when the options name none."""

    name: ClassVar[str]
    formulation: ClassVar[str]

    def check(self, settings: SolverOptions) -> None:
        """Refuse (SceneError) a setting this method does not take or needs and lacks (e.g. ``step``);
        called when the SolverOptions naming the method are made."""

    def run(self, model: Scene | DAEModel, t_end: float, t0: float, y0: NDArray | None, save: Output,
            settings: SolverOptions, on_failure: str, progress: bool) -> Result:
        """Integrate ``model`` (a Scene is assembled with ``settings.formulation`` or this solver's own)
        from ``t0`` to ``t_end``; everything given is checked (``y0``'s length once the model is known).
        A failed run raises :class:`daeclear.SolveError` (``on_failure="raise"``) or returns its partial
        Result with ``success=False``."""


def step_rule(name: str, step: Any, *, fixed: bool) -> None:
    """``step`` is required by a fixed-step method and refused by the others (``name``: the method's)."""
    if fixed and step is None:
        raise SceneError(f"simulate: method={name!r} is a fixed-step scheme and needs "
                         "step=<step size in s> (the chapter uses 1e-5 s).")
    if not fixed and step is not None:
        raise SceneError(f"simulate: step={step!r} is only for the fixed-step methods "
                         f"({', '.join(repr(m) for m in FIXED_STEP_METHODS)}); method={name!r} chooses its "
                         "own steps (use max_step to bound them).")
