"""How far the grazing test's tangency bound is from the errors a run makes (docs/sensitivities.md, section 4).

    python benchmarks/grazing_margin.py [--rtol 1e-6] [--cases slider-crank chain] [--differences]

For every event of a 2 ms run at ``--rtol`` (the cases of benchmarks/bench_sensitivity.py, one sensitivity
parameter) and of the same run at rtol 1e-10, matched by pair, kind and order: the gap's rate, its curvature
g'' (the pre-switch mode's, as the jump evaluates it), the tangency test's gap uncertainty
|g_y| (atol + rtol |y|) and the gap's measured error |t*(rtol) - t*(1e-10)| |rate|, the bound on the rate's
relative error that the test compares with GRAZING_ERROR (g'' gap_error / rate^2) and the same with the
measured error, the rate's measured relative error, and whether the test calls the event grazing.

``--differences`` (the slider-crank): S at ``--rtol`` with the tangency test left out (the cancellation test
kept) against central differences of runs at rtol 1e-10 (step 1e-4 of the parameter: the 13 impacts kept),
at 41 output times, per parameter and for positions and velocities: the largest error before and after the
first event the test calls grazing, relative to the largest |S| over the run. What the NaN costs: the
derivative the run would have given.
"""

from __future__ import annotations

import argparse
import warnings
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

import daeclear as dc
from daeclear.solvers import sensitivity_carrier, sensitivity_jumps

CASES = {"slider-crank": (lambda: dc.mechanisms.slider_crank("revolute"), "clearance.clearance"),
         "chain": (lambda: dc.mechanisms.chain(10, rpm=300.0), "pin2.clearance")}
T_END, REFERENCE_RTOL = 2e-3, 1e-10


@contextmanager
def recorded(rows: list[tuple[str, float, float, float, float]]) -> Iterator[None]:
    """Record each event's (label, rate, curvature, gap_error, scale) as the carrier passes them to the jump."""
    original = sensitivity_carrier.event_time_sensitivity

    def record(g_p, rate, scale, *, rtol, event, curvature=0.0, gap_error=0.0):  # type: ignore[no-untyped-def]
        rows.append((event, float(rate), float(curvature), float(gap_error), float(scale)))
        return original(g_p, rate, scale, rtol=rtol, event=event, curvature=curvature, gap_error=gap_error)

    sensitivity_carrier.event_time_sensitivity = record
    try:
        yield
    finally:
        sensitivity_carrier.event_time_sensitivity = original


@contextmanager
def without_tangency() -> Iterator[None]:
    """The grazing test with its cancellation part only (the tangency part left out)."""
    original = sensitivity_jumps.is_grazing

    def cancellation(rate: float, scale: float, rtol: float, curvature: float = 0.0, gap_error: float = 0.0) -> bool:
        return original(rate, scale, rtol)

    sensitivity_jumps.is_grazing = cancellation
    try:
        yield
    finally:
        sensitivity_jumps.is_grazing = original


def events(model: dc.DAEModel, name: str, rtol: float) -> dict[str, list[tuple[float, float, float, float, float]]]:
    """Each pair and kind's events of a run: (t, rate, curvature, gap_error, scale) in order."""
    rows: list[tuple[str, float, float, float, float]] = []
    with recorded(rows), warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        dc.simulate(model, T_END, rtol=rtol, sensitivities=[name], save=dc.SaveAt(times=[0.0, T_END], steps=False))
    out: dict[str, list[tuple[float, float, float, float, float]]] = defaultdict(list)
    for label, *terms in rows:  # "'pin3' onset at t=0.00136 s"
        key, when = label.split(" at t=")
        out[key].append((float(when.split()[0]), *terms))
    return out


def margins(case: str, rtol: float) -> None:
    scene, name = CASES[case]
    model = dc.assemble(scene())
    run, ref = events(model, name, rtol), events(model, name, REFERENCE_RTOL)
    print(f"\n{case}, rtol {rtol:g} against {REFERENCE_RTOL:g}: the tangency bound's terms and the measured errors")
    print(f"{'event':24s} {'t* s':>10s} {'rate m/s':>9s} {'g m/s2':>9s} {'gap_error':>9s} {'measured':>9s} "
          f"{'bound':>8s} {'measured':>8s} {'rate err':>8s}  grazing")
    for key in sorted(run, key=lambda k: run[k][0][0]):
        for (t, rate, curv, gap_error, scale), (t_ref, rate_ref, *_) in zip(run[key], ref.get(key, [])):
            measured = abs(t - t_ref) * abs(rate_ref)
            grazing = sensitivity_jumps.is_grazing(rate, scale, rtol, curv, gap_error)
            print(f"{key:24s} {t_ref:10.4e} {rate_ref:+9.3f} {curv:9.3g} {gap_error:9.2e} {measured:9.2e} "
                  f"{abs(curv) * gap_error / rate ** 2:8.1e} {abs(curv) * measured / rate ** 2:8.1e} "
                  f"{abs(rate - rate_ref) / abs(rate_ref):8.1e}  {grazing}")


def differences(rtol: float) -> None:
    scene, _ = CASES["slider-crank"]
    model = dc.assemble(scene())
    names, n = ["clearance.clearance", "clearance.law.restitution"], 2 * model.n_q
    times = np.linspace(0.0, T_END, 41)
    save = dc.SaveAt(times=times, steps=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        rows: list[tuple[str, float, float, float, float]] = []
        with recorded(rows):
            dc.simulate(model, T_END, rtol=rtol, save=save, sensitivities=names)
        first = min((float(label.split(" at t=")[1].split()[0]) for label, rate, curv, err, scale in rows
                     if sensitivity_jumps.is_grazing(rate, scale, rtol, curv, err)), default=T_END)
        with without_tangency():
            S = np.asarray(dc.simulate(model, T_END, rtol=rtol, save=save, sensitivities=names).sensitivities.states)
        print(f"\nslider-crank, rtol {rtol:g} without the tangency test (its first grazing event at {first:.6g} s) "
              f"against central differences at rtol {REFERENCE_RTOL:g}: largest error / largest |S|")
        for j, name in enumerate(names):
            p = model.parameter(name)[0]
            h = 1e-4 * p
            plus, minus = (dc.simulate(model.with_parameters({name: p + s * h}), T_END, rtol=REFERENCE_RTOL, save=save)
                           for s in (1, -1))
            fd = np.array([(plus[s] - minus[s]) / (2 * h) for s in model.state_names[:n]]).T
            for part, rows_ in (("positions", slice(0, n // 2)), ("velocities", slice(n // 2, n))):
                error = np.abs(S[:, rows_, j] - fd[:, rows_]).max(axis=1) / np.abs(fd[:, rows_]).max()
                print(f"  {name:27s} {part:10s} before {error[times < first].max():.1e}  after "
                      f"{error[times > first].max():.1e}  at t_end {error[-1]:.1e}  (events {len(plus.events)}, "
                      f"{len(minus.events)})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(CASES))
    parser.add_argument("--differences", action="store_true")
    args = parser.parse_args()
    for case in args.cases:
        margins(case, args.rtol)
    if args.differences:
        differences(args.rtol)


if __name__ == "__main__":
    main()
