"""Solvers of your own, passed to ``simulate`` as ``method``: a scheme the run driver integrates with
every contact event, and a whole run of your own (rk4 with a Richardson error estimate).

Every method of :func:`daeclear.simulate` is a class of one contract
(:class:`daeclear.solvers.base.Solver`: ``name``, ``formulation``, ``check``, ``run``), and
``method=`` takes such a class as well as a registered name.

``RK23``: a subclass of :class:`daeclear.solvers.explicit.ODESolver` names a ``scipy.integrate.OdeSolver``
subclass (here scipy's Bogacki-Shampine 3(2), which daeclear does not register; your own works the
same) as its ``scheme``; daeclear's run driver integrates the index-1 model with it as it does RK45:
the contact events located on its dense output, consistent restarts, recording, streaming, the physics
checks. The script runs the chapter's clearance slider-crank (Fig. 4.15's scene) and compares its
contact onsets with IDA's at rtol 1e-10.

``RichardsonRK4``: a class with its own ``run`` composes runs: it runs the registered rk4 solver
(``daeclear.solvers.registry.SOLVERS["rk4"]``) twice, at the step of the options and at half of it,
and returns the finer run with its error estimated from the pair: rk4 is of order 4, so the finer
run's error is about ``(fine - coarse) / 15`` (Richardson). The script runs the ideal slider-crank
(section 4.4, no clearance, no contact) for one crank revolution and compares the estimate of the
slider position's error with the true one, against DOP853 at rtol 1e-12.

Run: ``python examples/custom_solver.py`` (a few seconds, plus compiling on an empty cache);
``--quick`` for a quarter revolution.

Measured: RK23 at rtol 1e-8, 49 contact events over one revolution, the same sequence as IDA's; the
first onset 9e-13 s from IDA's, the later ones up to 4e-6 s (an impact sequence amplifies small
differences, docs/reliability.md; a quarter revolution: 16 events, up to 1.2e-8 s). Richardson:
steps 2e-4 s and 1e-4 s over one revolution, 61 output times; estimated error of slider.x 3.1e-08 m,
true error 3.1e-08 m (ratio 0.99; a quarter revolution: 2.5e-09 and 2.4e-09 m).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import ClassVar

import numpy as np
import scipy.integrate

import daeclear as dc
from daeclear.solvers.base import step_rule
from daeclear.solvers.explicit import ODESolver
from daeclear.solvers.registry import SOLVERS

REVOLUTION = 60.0 / 5000.0  # s, one crank turn at 5000 rpm


class RK23(ODESolver):
    """scipy's Bogacki-Shampine 3(2) on the index-1 model, with daeclear's contact events."""

    name: ClassVar[str] = "RK23"
    scheme: ClassVar[type] = scipy.integrate.RK23
    order: ClassVar[int] = 3  # what its steps record


def onset_gaps(span: float) -> tuple[int, float, float]:
    """RK23's contact events on the clearance slider-crank over ``span`` (the same sequence as IDA's at
    rtol 1e-10) and the difference of its first onset time and the largest of all from IDA's."""
    scene = dc.mechanisms.slider_crank("revolute")
    mine = dc.simulate(scene, span, method=RK23, rtol=1e-8)
    reference = dc.simulate(scene, span, rtol=1e-10, options=dc.SolverOptions(formulation="index1"))
    onsets, expected = mine.events.of(kind="onset").t, reference.events.of(kind="onset").t
    assert mine.success and onsets.size == expected.size, (onsets.size, expected.size)
    gaps = np.abs(onsets - expected)
    return len(mine.events), float(gaps[0]), float(np.max(gaps))


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

    events, first, largest = onset_gaps(span)
    print(f"{RK23.name}: {events} contact events over {span:g} s as IDA's; the first onset {first:.2g} s from "
          f"IDA's, the largest difference {largest:.2g} s")

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
