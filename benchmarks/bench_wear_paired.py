"""simulate_wear in two trees, interleaved call by call: cycles a second of each and their ratio.

    python benchmarks/bench_wear_paired.py OLD NEW [--cycles 40] [--calls 7] [--path]

The scene of examples/joint_wear.py (the chapter's slider-crank, friction 0.1, the rod-slider bearing
wearing with k = 1e-13, 360 nodes, 48 modes), ``simulate_wear(scene, cycles)``, every cycle simulated
(``extrapolate=1``); with ``--path`` each call also writes its history to a new HDF5 file. One
worker process per tree (each in its own package and compile cache, as in bench_paired.py) stays
up; the parent asks them for one call at a time, old and new in turn (the order swapped every call),
so that both see the same machine. Printed: best and median cycles a second of each tree (and per CPU
second of the worker, less sensitive to a loaded machine), new / old of each, and each tree's final
largest depth (the same physics: equal to a few digits).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

from bench_trees import ask, start_worker, stop_workers

#: one call a line on stdin ("cycles path-or-none"), its wall and CPU time and the final largest depth on stdout
WORKER = r"""
import json, sys, time, warnings
sys.path.insert(0, "examples")
from joint_wear import worn_scene
from daeclear.studies.wear import simulate_wear
warnings.simplefilter("ignore")
scene = worn_scene(1e-13)
for line in sys.stdin:
    cycles, path = line.split()
    start, cpu = time.perf_counter(), time.process_time()
    history = simulate_wear(scene, int(cycles), path=None if path == "-" else path)
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu
    print(json.dumps({"wall": wall, "cpu": cpu, "depth": float(history.max_depth[-1])}), flush=True)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--cycles", type=int, default=40)
    parser.add_argument("--calls", type=int, default=7)
    parser.add_argument("--path", action="store_true", help="write each call's history to a new HDF5 file")
    args = parser.parse_args()
    if args.calls < 1 or args.cycles < 1:
        parser.error("--calls and --cycles must be at least 1")
    with tempfile.TemporaryDirectory() as tmp:
        workers = {label: start_worker(tree.resolve(), Path(tmp) / label, WORKER)
                   for label, tree in (("old", args.old), ("new", args.new))}
        walls: dict[str, list[float]] = {"old": [], "new": []}
        cpus: dict[str, list[float]] = {"old": [], "new": []}
        depth = {}
        try:
            for label in workers:  # the first call compiles or loads the model: not counted
                ask(workers[label], "2 -")
            for k in range(args.calls):
                for label in (("old", "new") if k % 2 == 0 else ("new", "old")):
                    path = str(Path(tmp) / f"{label}{k}.h5") if args.path else "-"
                    out = ask(workers[label], f"{args.cycles} {path}")
                    walls[label].append(out["wall"])
                    cpus[label].append(out["cpu"])
                    depth[label] = out["depth"]
        finally:
            stop_workers(workers.values())
    rate = {label: (args.cycles / min(w), args.cycles / statistics.median(w)) for label, w in walls.items()}
    cpu_rate = {label: args.cycles / statistics.median(c) for label, c in cpus.items()}
    print(f"simulate_wear, {args.cycles} cycles every one simulated{', with a file' if args.path else ''}, "
          f"{args.calls} calls each tree, interleaved:")
    for label in ("old", "new"):
        print(f"  {label}: best {rate[label][0]:.1f} cycles/s, median {rate[label][1]:.1f} cycles/s "
              f"(per CPU second, median: {cpu_rate[label]:.1f}), largest depth {depth[label]:.6e} m")
    print(f"  new / old: best {rate['new'][0] / rate['old'][0]:.2f}, median {rate['new'][1] / rate['old'][1]:.2f}, "
          f"CPU time's median {cpu_rate['new'] / cpu_rate['old']:.2f}")


if __name__ == "__main__":
    main()
