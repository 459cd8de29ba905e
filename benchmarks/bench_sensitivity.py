"""The cost of forward sensitivities: whole ``simulate(scene, t_end, sensitivities=...)`` calls against the
plain run, and the state's factorisation against the (1 + Ns) n reference, side by side in one process.

    python benchmarks/bench_sensitivity.py [--repeats 5] [--rtol 1e-6] [--times 0] [--cases slider-crank chain]
        [--fresh-starts]

Each call is a whole user call, set-up included (the Scene assembled, the sessions opened, the start's
dy0/dp): ``simulate(scene, t_end, rtol=..., sensitivities=names)`` with Ns = 0 (the plain run), 1, 3 and
5 parameters, each with the state's n x n factorisation reused for every block (what ``simulate`` does)
and with the reference that factors the (1 + Ns) n block-diagonal Newton matrix whole
(:func:`daeclear.solvers.sensitivity_ida.stacked_reference`). A first round compiles every library
(untimed); then ``--repeats`` rounds call every variant once each, in an order rotated every round, so
that every variant sees the same machine. Printed per case: the median and best wall time of each
variant, its ratio to the plain run's median, and the reference's ratio to the state's factorisation; the
same for the time inside IDA's advances (``stats["solve_time"]``: the integration of [y; S] in C, where the
linear algebra is; the rest of a call is set-up, the jumps at events and the output rows, in Python).
"NaN S rows": the share of the first call's output rows whose S is NaN (from a grazing event on: the run
goes on, those columns are integrated but mean nothing; docs/sensitivities.md, section 4).
``--times 0`` (the default): every step an output row, as ``simulate``'s default ``SaveAt``; ``--times N``:
N output times (fewer rows: what each row costs beside the integration shows). ``--fresh-starts``: the
structure's kept starts dropped before every call (plain and with sensitivities alike), as a call with new
parameter values (a sweep, a gradient's next point) finds them: each start, and the moved models' starts
of dy0/dp where they are differenced, assembled again.

Cases: the chapter's slider-crank (Fig. 4.15: revolute clearance, c = 0.5 mm, GGL; its first 2 ms, the
impacts of the start) and a driven chain of 10 links with a clearance at every pin
(``dc.mechanisms.chain(10, rpm=300)``, 63 states: the sparse LU's size; 2 ms).

    python benchmarks/bench_sensitivity.py --table [--repeats 3] [--accuracy 1e-3] [--widths 1 2 4 8 16]
        [--table-cases fig415-2ms fig415-2rev chain16]

The issue's table (``--table``, :mod:`bench_sensitivity_table`): Ns = 1, 2, 4, 8, 16 on the Fig. 4.15 scene
(2 ms and two revolutions) and a 16-link chain, whole calls on the assembled model against the plain run and
against central differences (2 Ns + 1 runs) at equal accuracy: each method's cheapest setting (the run's
rtol; for central differences rtol and step) whose S(t_end) is within ``--accuracy`` of a tight reference.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings
from collections.abc import Callable

import numpy as np

import bench_sensitivity_table
import daeclear as dc
from daeclear.solvers.sensitivity_ida import stacked_reference

#: case -> (scene factory, t_end, its five sensitivity parameters in the order they are taken)
CASES: dict[str, tuple[Callable[[], dc.Scene], float, list[str]]] = {
    "slider-crank": (lambda: dc.mechanisms.slider_crank("revolute"), 2e-3,
                     ["clearance.clearance", "clearance.law.restitution", "crank.mass", "rod.mass", "slider.mass"]),
    "chain": (lambda: dc.mechanisms.chain(10, rpm=300.0), 2e-3,
              ["pin2.clearance", "pin5.clearance", "pin2.law.restitution", "link3.mass", "link7.mass"]),
}
WIDTHS = (1, 3, 5)


def call(scene: dc.Scene, t_end: float, rtol: float, names: list[str] | None, reference: bool,
         times: int, fresh: bool = False) -> tuple[float, int, float, float]:
    """One whole simulate call: its wall time, the IDA steps, the time inside IDA's advances and the share of
    its S rows that are NaN (a grazing event's; ``fresh``: the kept starts dropped first)."""
    save = dc.SaveAt() if times == 0 else dc.SaveAt(times=np.linspace(0.0, t_end, times), steps=False)
    if fresh:
        dc.assemble(scene).structure.starts.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        start = time.perf_counter()
        if reference:
            with stacked_reference():
                result = dc.simulate(scene, t_end, rtol=rtol, save=save, sensitivities=names)
        else:
            result = dc.simulate(scene, t_end, rtol=rtol, save=save, sensitivities=names)
        wall = time.perf_counter() - start
    if not result.success:
        raise SystemExit(f"bench_sensitivity: a run failed: {result.message}")
    S = None if result.sensitivities is None else np.asarray(result.sensitivities.states)
    nan = 0.0 if S is None else float(np.isnan(S).any(axis=(1, 2)).mean())
    return wall, int(result.stats["n_steps"]), float(result.stats["solve_time"]), nan


def bench(case: str, repeats: int, rtol: float, times: int, fresh: bool = False) -> None:
    """Every variant of one case, interleaved; the table of medians, bests and ratios."""
    make, t_end, names = CASES[case]
    scene = make()
    variants: list[tuple[str, list[str] | None, bool]] = [("plain", None, False)]
    for k in WIDTHS:
        variants += [(f"Ns={k} state", names[:k], False), (f"Ns={k} stacked", names[:k], True)]
    first = {label: call(scene, t_end, rtol, sens, ref, times) for label, sens, ref in variants}  # compiles
    steps = {label: c[1] for label, c in first.items()}
    walls: dict[str, list[float]] = {label: [] for label, _, _ in variants}
    solves: dict[str, list[float]] = {label: [] for label, _, _ in variants}
    for r in range(repeats):
        order = variants[r % len(variants):] + variants[:r % len(variants)]
        for label, sens, ref in order:
            wall, _, solve, _ = call(scene, t_end, rtol, sens, ref, times, fresh)
            walls[label].append(wall)
            solves[label].append(solve)
    med = {label: statistics.median(w) for label, w in walls.items()}
    ida = {label: statistics.median(w) for label, w in solves.items()}
    rows = "every step" if times == 0 else f"{times} output times"
    starts = ", fresh starts" if fresh else ""
    print(f"\n{case}: t_end {t_end * 1e3:g} ms, rtol {rtol:g}, {rows}{starts}, {repeats} rounds (shared machine: "
          "ratios only)")
    print(f"{'variant':<16} {'median s':>9} {'best s':>9} {'/ plain':>8} {'steps':>7} {'stacked/state':>14} "
          f"{'IDA s':>8} {'IDA / plain':>12} {'IDA stacked/state':>18} {'NaN S rows':>11}")
    for label, _, _ in variants:
        other = label.replace("stacked", "state")
        stacked = label.endswith("stacked")
        vs = f"{med[label] / med[other]:14.2f}" if stacked else " " * 14
        ida_vs = f"{ida[label] / ida[other]:18.2f}" if stacked else " " * 18
        print(f"{label:<16} {med[label]:9.4f} {min(walls[label]):9.4f} {med[label] / med['plain']:8.2f} "
              f"{steps[label]:7d} {vs} {ida[label]:8.4f} {ida[label] / ida['plain']:12.2f} {ida_vs} "
              f"{first[label][3]:11.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--times", type=int, default=0)
    parser.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(CASES))
    parser.add_argument("--fresh-starts", action="store_true", help="drop the kept starts before every call")
    parser.add_argument("--table", action="store_true", help="the issue's table against central differences")
    parser.add_argument("--accuracy", type=float, default=1e-3, help="--table: the error both methods reach")
    parser.add_argument("--widths", type=int, nargs="+", default=list(bench_sensitivity_table.WIDTHS))
    parser.add_argument("--table-cases", nargs="+", choices=sorted(bench_sensitivity_table.CASES),
                        default=list(bench_sensitivity_table.CASES))
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    if args.times < 0 or args.times == 1:
        parser.error(f"--times must be 0 (every step) or at least 2, got {args.times}")
    if args.table:
        if not 0.0 < args.accuracy < 1.0 or any(not 1 <= k <= 16 for k in args.widths):
            parser.error("--accuracy must be in (0, 1) and --widths between 1 and 16")
        for case in args.table_cases:
            bench_sensitivity_table.table(case, sorted(set(args.widths)), args.accuracy, args.repeats)
        return
    for case in args.cases:
        bench(case, args.repeats, args.rtol, args.times, args.fresh_starts)


if __name__ == "__main__":
    main()
