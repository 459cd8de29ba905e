"""The assembled model integrated by other schemes than IDA, for accuracy studies.

Solvers (:class:`daeclear.solvers.base.Solver`) of every method but ``"ida"``, one class a row of
:data:`daeclear.core.methods.TABLE`: scipy's ``"RK45"``, ``"DOP853"``, ``"Radau"``, ``"BDF"``,
``"LSODA"`` (the implicit ones with the generated Jacobian) and the fixed-step ``"rk4"``, ``"euler"``
(``step=``, the loop in C). The index-1 DAE is an ODE in ``x = (q, v)`` (:mod:`~daeclear.solvers.ode_model`);
GGL is IDA-only. Their runs are the driver's (:mod:`daeclear.solvers.driver`); what they integrate
between two restarts: :mod:`daeclear.solvers.ode_integrators`.

A scheme of your own: a subclass of :class:`ODESolver` naming a ``scipy.integrate.OdeSolver`` subclass
as its ``scheme`` is integrated the same way, with the events, the recording and the checks.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

from ..assembly.dae_model import DAEModel
from ..core import methods
from ..core.errors import SceneError
from ..core.methods import CHAPTER_FORMULATION, Method
from .base import DrivenSolver, step_rule
from .ode_integrators import FixedStepIntegrator, ODEIntegrator, ScipyIntegrator
from .ode_model import ode_spec
from .save_at import Output

if TYPE_CHECKING:
    from .solver_options import SolverOptions

__all__ = ["ODESolver", "RK45", "DOP853", "Radau", "BDF", "LSODA", "RK4", "Euler", "ode_spec", "solver_class"]


class ODESolver(DrivenSolver):
    """A method that integrates the index-1 model as an ODE in (q, v) with IDA's contact rules. A subclass
    names the method (``name``) and its ``scheme``: a ``scipy.integrate.OdeSolver`` subclass (or its name
    in ``scipy.integrate``), stepped with ``rtol``, ``atol``, ``max_step`` and, ``jacobian = True``, the
    generated Jacobian; or (``fixed_step = True``) the code of a fixed-step scheme of the C loop, its
    ``order``. ``order``: what its steps record (-1: unknown or varying)."""

    name: ClassVar[str]
    formulation: ClassVar[str] = CHAPTER_FORMULATION
    scheme: ClassVar[type | str | None] = None
    jacobian: ClassVar[bool] = False
    order: ClassVar[int] = -1
    fixed_step: ClassVar[bool] = False  # rk4, euler: the step is the option ``step``

    def check(self, settings: SolverOptions) -> None:
        """``step`` is required by the fixed-step schemes and refused by the others; what IDA alone does
        is refused: its ``linear_solver``, ``track_work``, the GGL formulation; and a ``scheme`` that is no
        ``scipy.integrate.OdeSolver``."""
        step_rule(self.name, settings.step, fixed=self.fixed_step)
        if settings.linear_solver != "auto":
            raise SceneError(f"simulate: linear_solver={settings.linear_solver!r}, must be 'auto' with "
                             f"method={self.name!r}: it chooses the LU of IDA's Newton iteration, which "
                             f"{self.name} does not run.")
        if settings.track_work:
            raise SceneError(f"simulate: track_work=True is supported by method='ida' only, not by "
                             f"method={self.name!r}.")
        if settings.formulation not in (None, CHAPTER_FORMULATION):
            raise _formulation_refused(settings.formulation, self.name)
        if not self.fixed_step and not isinstance(self.scheme, (str, type(None))):  # a scheme of the user's
            import scipy.integrate

            if not (isinstance(self.scheme, type) and issubclass(self.scheme, scipy.integrate.OdeSolver)):
                raise SceneError(f"simulate: {type(self).__name__}.scheme={self.scheme!r}, must be a subclass of "
                                 "scipy.integrate.OdeSolver (or its name in scipy.integrate), or fixed_step = True "
                                 "with the order of a scheme of the C loop.")

    def integrator(self, model: DAEModel, t_end: float, output: Output, settings: SolverOptions) -> ODEIntegrator:
        """The run's integrator of the model's ODE (SceneError for a model of another formulation)."""
        if model.formulation != CHAPTER_FORMULATION:
            raise _formulation_refused(model.formulation, self.name)
        if self.fixed_step:
            return FixedStepIntegrator(model, t_end, output, settings, name=self.name, order=self.order)
        scheme = self.scheme
        if scheme is None or isinstance(scheme, str):
            import scipy.integrate

            scheme = getattr(scipy.integrate, scheme or self.name)
        return ScipyIntegrator(model, t_end, output, settings, name=self.name, order=self.order, scheme=scheme,
                               jacobian=self.jacobian)


def _formulation_refused(formulation: str, name: str) -> SceneError:
    return SceneError(f"simulate: formulation={formulation!r} is integrated by IDA only; method={name!r} "
                      f"integrates the chapter's index-1 formulation (formulation='{CHAPTER_FORMULATION}').")


def solver_class(method: Method) -> type[ODESolver]:
    """The solver class of a row of the method table (a subclass of ODESolver named as the row says)."""
    fixed = method.family == "fixed"
    cls = type(method.class_name, (ODESolver,),
               {"name": method.name, "fixed_step": fixed, "scheme": None if fixed else method.name,
                "jacobian": method.jacobian, "order": method.order, "__doc__": method.doc, "__module__": __name__})
    return cls


#: the table's rows but IDA's, in its order (tests/test_solver_contract.py: each is its row's class)
RK45, DOP853, Radau, BDF, LSODA, RK4, Euler = (solver_class(m) for m in methods.TABLE if m.family != "ida")
