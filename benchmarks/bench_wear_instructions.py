"""simulate_wear in two trees, counted in instructions (callgrind): instructions a simulated cycle.

    python benchmarks/bench_wear_instructions.py OLD NEW [--cycles 20]

Wall and CPU times on a shared machine drift by more than a few percent; the instructions a call
executes do not. The scene of bench_wear_paired.py (examples/joint_wear.py's, k = 1e-13, every cycle
simulated); each tree runs a worker twice under ``valgrind --tool=callgrind`` (in its own package and
compile cache, as in bench_trees): once with the warm-up alone (``simulate_wear(scene, 2)``: the model
assembled, the library compiled or loaded), once with the warm-up and ``simulate_wear(scene, cycles)``;
the difference of the two totals over ``cycles`` is one cycle's instructions (a block of one cycle:
its profile, run, channels and spreading). BLAS runs one thread and hashing is seeded, as in
bench_instructions.py. Printed: instructions a cycle of each tree and new / old (old / new is the
speed-up when instructions are the cost). Needs valgrind; takes minutes.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from bench_instructions import work_instructions

#: the worker: argv = cycles (0: the warm-up alone)
WORKER = r"""
import sys, warnings
sys.path.insert(0, "examples")
from joint_wear import worn_scene
from daeclear.studies.wear import simulate_wear
warnings.simplefilter("ignore")
scene = worn_scene(1e-13)
simulate_wear(scene, 2)
cycles = int(sys.argv[1])
if cycles:
    simulate_wear(scene, cycles)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--cycles", type=int, default=20)
    args = parser.parse_args()
    if args.cycles < 1:
        parser.error(f"--cycles must be at least 1, got {args.cycles}")
    measured = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, tree in (("old", args.old.resolve()), ("new", args.new.resolve())):
            work, warm = work_instructions(tree, Path(tmp), label, WORKER, [], args.cycles)
            measured[label] = work / args.cycles
            print(f"{label}: {measured[label]:,.0f} instructions a simulated cycle ({args.cycles} cycles; "
                  f"warm-up {warm:,})", flush=True)
    print(f"new / old: {measured['new'] / measured['old']:.4f} (old / new: {measured['old'] / measured['new']:.3f})")


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    main()
