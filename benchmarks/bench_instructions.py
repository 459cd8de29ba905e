"""Two trees of the package, the same whole ``dc.simulate`` calls, counted in instructions (callgrind).

    python benchmarks/bench_instructions.py OLD NEW [--rounds 5] [--call setup|window]

Wall times on a shared machine drift by more than the differences a refactor makes; the number of
instructions a call executes does not. Each tree runs a worker twice under ``valgrind --tool=callgrind``
(in its own package and compile cache, as in bench_trees): once with the warm-up alone (the structure
built, the library compiled or loaded, every path taken twice), once with the warm-up and ``--rounds``
rounds of the measured calls; the difference of the two totals is what the measured calls executed.
``--call setup`` (default): each round four 2 ms runs of the Fig. 4.15 scene without gravity, each
with its set-up, as a user calls them: a new Scene (of a structure seen before), a Scene seen
before, a model with new numbers (``with_parameters``) and ``simulate(model, parameters=...)``;
``--call window``: each round one run of two revolutions, index1, rtol 1e-7 (bench_paired's call).
BLAS runs one thread and hashing is seeded: a spinning BLAS thread or a new hash seed would count.
What is left between two identical trees is the C library's heap (whether ``realloc`` grows a block
where it is or copies it): a few tenths of a percent. Needs valgrind; takes minutes.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_trees import tree_env

#: the worker: argv = call kind, rounds (0: the warm-up alone)
WORKER = r"""
import sys, warnings
import numpy as np
import daeclear as dc
warnings.simplefilter("ignore")
kind, rounds = sys.argv[1], int(sys.argv[2])
seen = dc.mechanisms.slider_crank("revolute", gravity=0.0)
model = dc.assemble(seen)

def run(target, t_end, **kw):
    times = np.linspace(0.0, t_end, 400)
    output = {"save": dc.SaveAt(times=times)} if hasattr(dc, "SaveAt") else {"t_eval": times}
    dc.simulate(target, t_end, on_failure="return", **output, **kw)["slider.vx"]

def calls(k):
    if kind == "window":
        run(seen, 0.024, options=dc.SolverOptions(formulation="index1", rtol=1e-7))
        return
    run(dc.mechanisms.slider_crank("revolute", gravity=0.0), 0.002)  # a new Scene, structure seen
    run(seen, 0.002)  # a Scene seen before
    run(model.with_parameters({"clearance.clearance": 4e-4 + 1e-6 * k}), 0.002)  # new numbers
    run(model, 0.002, parameters={"clearance.law.restitution": 0.8 + 0.01 * k})

calls(0)
calls(1)  # the warm-up: every path taken, twice
for k in range(2, 2 + rounds):
    calls(k)
"""
TOTAL = re.compile(r"^(?:summary|totals):\s+(\d+)", re.MULTILINE)


def callgrind(tree: Path, cache: Path, code: str, argv: list[str], out: Path | None = None) -> int:
    """Run the worker ``code`` with ``argv`` in ``tree``'s package, under callgrind when ``out`` is given (its
    output file): the instructions it counts for the whole process, or 0 without ``out`` (a plain run, e.g.
    one that compiles into the cache)."""
    env = {**tree_env(tree, cache), "PYTHONHASHSEED": "0", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    tool = [] if out is None else ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
    done = subprocess.run([*tool, sys.executable, "-c", code, *argv], cwd=tree, env=env,
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: the worker failed ({done.returncode}):\n{done.stderr[-2000:]}")
    if out is None:
        return 0
    found = TOTAL.search(out.read_text())
    if found is None:
        raise SystemExit(f"{out}: no total in callgrind's output")
    return int(found.group(1))


def work_instructions(tree: Path, folder: Path, label: str, code: str, args: list[str], units: int
                      ) -> tuple[int, int]:
    """(instructions of ``units`` units of the worker's work, those of its warm-up) in ``tree``'s package:
    the worker run once to compile into its own cache under ``folder``, then with 0 and ``units`` units
    (its last argument) under callgrind; the work is the difference, set-up and imports cancelled."""
    cache = folder / label
    callgrind(tree, cache, code, [*args, "0"])  # compiles into the tree's cache, without callgrind
    warm = callgrind(tree, cache, code, [*args, "0"], folder / f"{label}.warm.out")
    full = callgrind(tree, cache, code, [*args, str(units)], folder / f"{label}.full.out")
    return full - warm, warm


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--call", choices=("setup", "window"), default="setup")
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error(f"--rounds must be at least 1, got {args.rounds}")
    calls = args.rounds * (4 if args.call == "setup" else 1)
    measured = {}
    with tempfile.TemporaryDirectory() as tmp:
        for label, tree in (("old", args.old.resolve()), ("new", args.new.resolve())):
            measured[label], warm = work_instructions(tree, Path(tmp), label, WORKER, [args.call], args.rounds)
            print(f"{label}: {measured[label]:,} instructions in {calls} calls ({measured[label] / calls:,.0f} a call; "
                  f"warm-up {warm:,})", flush=True)
    print(f"new / old: {measured['new'] / measured['old']:.4f}")


if __name__ == "__main__":
    os.environ.setdefault("MPLBACKEND", "Agg")
    main()
