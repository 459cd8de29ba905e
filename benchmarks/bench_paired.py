"""The IDA calls of the work-precision study in two trees, interleaved call by call.

    python benchmarks/bench_paired.py OLD NEW [--calls 15]

``bench_trees.py`` interleaves whole processes, minutes apart; on a shared machine whose speed
drifts by 1.5x within minutes, that cannot settle 10 % on a 20 ms call. Here one worker process
per tree (each in its own package, as in bench_trees) stays up, and the parent asks them for one
call at a time, old and new in turn (the order swapped every call), so that both see the same
machine. The calls are those of ``bench_work_precision.py``'s study for IDA: the Fig. 4.15 scene
without gravity (one Scene object per worker, as the study times it), 400 output times, the first
2 ms and two revolutions, GGL and index-1 at rtol 1e-5 ... 1e-9; after each timed call the study's
channel is read (untimed), as the study does. Printed per call: best and median of ``--calls``
for each tree, new / old of both, and each tree's IDA step count (equal: the same run).
"""

from __future__ import annotations

import argparse
import math
import statistics
import tempfile
from pathlib import Path

from bench_trees import ask, start_worker, stop_workers

#: one call a line on stdin ("formulation rtol t_end"), its wall time and steps as JSON on stdout
WORKER = r"""
import json, sys, time, warnings
import numpy as np
import daeclear as dc
warnings.simplefilter("ignore")
scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
for line in sys.stdin:
    formulation, rtol, t_end = line.split()
    t_end = float(t_end)
    times = np.linspace(0.0, t_end, 400)
    output = {"save": dc.SaveAt(times=times)} if hasattr(dc, "SaveAt") else {"t_eval": times}
    options = dc.SolverOptions(formulation=formulation, rtol=float(rtol))
    start = time.perf_counter()
    result = dc.simulate(scene, t_end, options=options, on_failure="return", **output)
    wall = time.perf_counter() - start
    result["slider.vx"]
    print(json.dumps({"wall": wall, "steps": int(result.stats["n_steps"])}), flush=True)
"""
CALLS = [(window, t_end, formulation, rtol)
         for window, t_end in (("first 2 ms", 0.002), ("two revolutions", 0.024))
         for formulation in ("ggl", "index1")
         for rtol in ("1e-5", "1e-6", "1e-7", "1e-8", "1e-9")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--calls", type=int, default=15)
    args = parser.parse_args()
    if args.calls < 1:
        parser.error(f"--calls must be at least 1, got {args.calls}")
    with tempfile.TemporaryDirectory() as tmp:
        workers = {label: start_worker(tree.resolve(), Path(tmp) / label, WORKER)
                   for label, tree in (("old", args.old), ("new", args.new))}
        print("| call | old best | new best | new / old (best) | old median | new median | "
              "new / old (median) | steps old / new |\n|---|---:|---:|---:|---:|---:|---:|---:|")
        ratios = []
        try:
            for window, t_end, formulation, rtol in CALLS:
                for label in workers:  # the first call compiles or loads the model: not counted
                    ask(workers[label], f"{formulation} {rtol} {t_end!r}")
                walls: dict[str, list[float]] = {"old": [], "new": []}
                steps = {}
                for k in range(args.calls):
                    for label in (("old", "new") if k % 2 == 0 else ("new", "old")):
                        out = ask(workers[label], f"{formulation} {rtol} {t_end!r}")
                        walls[label].append(out["wall"])
                        steps[label] = out["steps"]
                best = {label: min(w) for label, w in walls.items()}
                median = {label: statistics.median(w) for label, w in walls.items()}
                ratios.append(median["new"] / median["old"])
                print(f"| {window}, IDA {formulation} rtol {rtol} | {best['old'] * 1e3:.2f} ms | "
                      f"{best['new'] * 1e3:.2f} ms | {best['new'] / best['old']:.3f} | {median['old'] * 1e3:.2f} ms | "
                      f"{median['new'] * 1e3:.2f} ms | {median['new'] / median['old']:.3f} | "
                      f"{steps['old']} / {steps['new']} |", flush=True)
        finally:
            stop_workers(workers.values())
    mean = math.exp(sum(math.log(r) for r in ratios) / len(ratios))
    print(f"\n{len(ratios)} calls, {args.calls} each a tree: geometric mean of new / old (median) {mean:.3f}, "
          f"range {min(ratios):.3f}-{max(ratios):.3f}")


if __name__ == "__main__":
    main()
