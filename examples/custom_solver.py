"""A solver of your own: rk4 with a Richardson error estimate, passed to ``simulate`` as ``method``.

Every method of :func:`daeclear.simulate` is a class of one contract
(:class:`daeclear.solvers.base.Solver`: ``name``, ``formulation``, ``check``, ``run``), and
``method=`` takes such a class as well as a registered name. This one runs the registered rk4
solver (``daeclear.solvers.registry.SOLVERS["rk4"]``) twice, at the step of the options and at half
of it, and returns the finer run with its error estimated from the pair: rk4 is of order 4, so the
finer run's error is about ``(fine - coarse) / 15`` (Richardson). The script runs the ideal
slider-crank (section 4.4, no clearance, no contact) for one crank revolution and compares the
estimate of the slider position's error with the true one, against DOP853 at rtol 1e-12.

Run: ``python examples/custom_solver.py`` (about a second, plus compiling on an empty cache);
``--quick`` for a quarter revolution.

Measured: steps 2e-4 s and 1e-4 s over one revolution, 61 output times; estimated error of slider.x
3.1e-08 m, true error 3.1e-08 m (ratio 0.99; a quarter revolution: 2.5e-09 and 2.4e-09 m).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import ClassVar

import numpy as np

import daeclear as dc
from daeclear.solvers.base import step_rule
from daeclear.solvers.registry import SOLVERS

REVOLUTION = 60.0 / 5000.0  # s, one crank turn at 5000 rpm


class RichardsonRK4:
    """rk4 at ``step`` and ``step / 2`` on the same output times; the finer run, with ``estimate``
    (per output time and state, the finer run's error from the pair) kept on the solver class."""

    name: ClassVar[str] = "rk4-richardson"
    formulation: ClassVar[str] = "index1"
    estimate: ClassVar[np.ndarray | None] = None

    def check(self, settings: dc.SolverOptions) -> None:
        step_rule(self.name, settings.step, fixed=True)  # a fixed step is required, as rk4's

    def run(self, model, t_end, t0, y0, save, settings, on_failure, progress) -> dc.Result:
        if save.times is None:
            raise dc.SceneError(f"{self.name}: needs output times (save=SaveAt(times=...) or SaveAt(every=...)), "
                                "the same for both runs")
        rk4 = SOLVERS["rk4"]()
        coarse = rk4.run(model, t_end, t0, y0, save, settings.replace(method="rk4"), on_failure, progress)
        fine = rk4.run(model, t_end, t0, y0, save, settings.replace(method="rk4", step=settings.step / 2),
                       on_failure, progress)
        type(self).estimate = (fine.y - coarse.y) / (2 ** 4 - 1)
        return fine


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a quarter revolution (smoke test)")
    args = parser.parse_args(argv)
    span = REVOLUTION / 4 if args.quick else REVOLUTION

    model = dc.assemble(dc.mechanisms.slider_crank("ideal"), "index1")
    save = dc.SaveAt(every=span / 60)
    result = dc.simulate(model, span, options=dc.SolverOptions(method=RichardsonRK4, step=2e-4), save=save)
    reference = dc.simulate(model, span, method="DOP853", rtol=1e-12, save=save)
    k = model.state_names.index("slider.x")
    assert RichardsonRK4.estimate is not None
    estimated = float(np.max(np.abs(RichardsonRK4.estimate[:, k])))
    true = float(np.max(np.abs(result.y[:, k] - reference.y[:, k])))
    print(f"{RichardsonRK4.name}: steps 2e-4 s and 1e-4 s over {span:g} s, {result.t.size} output times")
    print(f"estimated error of slider.x {estimated:.2g} m, true error {true:.2g} m (ratio {estimated / true:.2f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
