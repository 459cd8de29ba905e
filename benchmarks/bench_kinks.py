"""Would plain runs gain from restarting at the friction kinks? (docs/sensitivities.md, "Kinks".)

A run with sensitivities restarts IDA at every kink of a friction law (|v_T| = v0, v1 of modified Coulomb); a
plain run does not watch them. This compares, on the chapter's Fig. 4.15 scene with friction 0.05 (10 ms, six
slip reversals in contact), the states of

* the plain run;
* a run with one sensitivity left out of IDA's error test (``SolverOptions(sensitivity_error_test=False)``: the
  steps are chosen for the states alone, as a plain run's) with its restarts at the kinks, and the same run with
  the kinks declared away (a subclass whose ``kinks`` is empty): what the kink restarts change in a run whose steps
  are the states';

each at rtol 1e-6 ... 1e-10: IDA's steps and error test failures, and the largest error of the positions and
velocities at the end against a plain run at rtol 1e-12 (relative to each group's largest magnitude). Counts,
not times: the machine's load does not move them.

    python benchmarks/bench_kinks.py [--end 10e-3] [--rtols 1e-6 1e-8 1e-10]
"""

from __future__ import annotations

import argparse
import warnings
from typing import Any

import numpy as np

import daeclear as dc
import daeclear.contact as dcc


class Unkinked(dcc.ModifiedCoulomb):
    """Modified Coulomb friction with its kinks declared away (another class: another structure)."""

    @property
    def kinks(self) -> tuple[Any, ...]:
        return ()


def final(result: dc.Result, model: dc.DAEModel) -> np.ndarray:
    return np.array([result[name][-1] for name in model.state_names[:2 * model.n_q]])


def error(y: np.ndarray, ref: np.ndarray, n: int) -> float:
    return max(float(np.abs(y[k] - ref[k]).max() / np.abs(ref[k]).max()) for k in (slice(0, n), slice(n, 2 * n)))


def run(model: dc.DAEModel, end: float, rtol: float, sensitivities: bool) -> tuple[np.ndarray, dict[str, Any]]:
    options = dc.SolverOptions(rtol=rtol, sensitivity_error_test=not sensitivities)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(model, end, options=options, save=dc.SaveAt(times=[0.0, end]),
                             sensitivities=["clearance.clearance"] if sensitivities else None)
    assert result.success, result.message
    return final(result, model), dict(result.stats)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end", type=float, default=10e-3)
    parser.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-8, 1e-10])
    args = parser.parse_args()
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    n = model.n_q
    ref, _ = run(model, args.end, 1e-12, False)
    print("| rtol | run | steps | error test failures | kinks | error at the end |")
    print("|---|---|---|---|---|---|")
    for rtol in args.rtols:
        rows = [("plain", *run(model, args.end, rtol, False))]
        rows.append(("S out of the test, kink restarts", *run(model, args.end, rtol, True)))
        bare = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=Unkinked(coefficient=0.05)))
        rows.append(("S out of the test, no kink restarts", *run(bare, args.end, rtol, True)))
        for label, y, stats in rows:
            print(f"| {rtol:g} | {label} | {stats['n_steps']} | {stats['n_err_test_fails']} | "
                  f"{stats.get('n_kinks', '')} | {error(y, ref, n):.1e} |")


if __name__ == "__main__":
    main()
