"""Results evaluated when read: a whole ``simulate(scene)`` call and the result file, two trees side by side.

Two revolutions of the chapter's Fig. 4.15 scene (``daeclear.mechanisms.slider_crank("revolute")``:
5000 rpm, c = 0.5 mm, 51 impacts) at rtol 1e-8, index-1 and GGL, default output (every step).
Each tree given (``--trees OLD NEW``, e.g. a worktree of main and this one) is measured in its own
interpreter (a package cannot be imported twice in one process), the trees interleaved pass by
pass so that the shared machine's load falls on both alike. Per tree and formulation: the median
wall time of ``simulate`` alone, of ``simulate`` followed by reading one channel (what a user's
script does), and the size of a streamed file of the main job's run on a 1 us grid (24 001 points;
``daeclear run``'s default grid is 2 us now).

Run: ``python benchmarks/bench_lazy.py --trees /path/to/main .`` (default: this tree alone).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

WORKER = r"""
import json, os, statistics, sys, tempfile, time
import numpy as np
import daeclear as dc
T = 2 * 60.0 / 5000.0
scene = dc.mechanisms.slider_crank("revolute")
out = {}
for form in ("index1", "ggl"):
    settings = dc.SolverOptions(formulation=form)
    dc.simulate(scene, T, rtol=1e-8, options=settings)  # builds or loads the structure
    alone, read = [], []
    for _ in range(int(sys.argv[1])):
        tic = time.perf_counter(); dc.simulate(scene, T, rtol=1e-8, options=settings)
        alone.append(time.perf_counter() - tic)
        tic = time.perf_counter(); dc.simulate(scene, T, rtol=1e-8, options=settings)["slider.vx"]
        read.append(time.perf_counter() - tic)
    out[form] = (statistics.median(alone), statistics.median(read))
with tempfile.TemporaryDirectory() as tmp:
    path = os.path.join(tmp, "run.h5")
    output = dict(times=np.linspace(0.0, T, 24001), stream_to=path, keep_data=False)
    if hasattr(dc, "SaveAt"):  # the output as one value (issue 35)
        dc.simulate(scene, T, save=dc.SaveAt(**output))
    else:  # a tree before it: the same output as keywords
        dc.simulate(scene, T, t_eval=output.pop("times"), **output)
    out["file"] = os.path.getsize(path)
print(json.dumps(out))
"""


def measure(tree: Path, repeats: int) -> dict:
    env = {**os.environ, "PYTHONPATH": str(tree.resolve()), "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, "-c", WORKER, str(repeats)], env=env, capture_output=True, text=True,
                          check=True, cwd=tempfile.gettempdir())
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", nargs="+", type=Path, default=[Path(__file__).resolve().parents[1]])
    parser.add_argument("--passes", type=int, default=3, help="interleaved passes over the trees")
    parser.add_argument("--repeats", type=int, default=7, help="calls per formulation and pass")
    args = parser.parse_args()
    runs: dict[Path, list[dict]] = {tree: [] for tree in args.trees}
    for _ in range(args.passes):
        for tree in args.trees:
            runs[tree].append(measure(tree, args.repeats))
    print(f"{'tree':<28} {'formulation':<12} {'simulate ms':>12} {'+ one channel ms':>17} {'file MB':>8}")
    for tree, passes in runs.items():
        for form in ("index1", "ggl"):
            alone = sorted(p[form][0] for p in passes)[len(passes) // 2]
            read = sorted(p[form][1] for p in passes)[len(passes) // 2]
            print(f"{str(tree)[-28:]:<28} {form:<12} {1e3 * alone:12.1f} {1e3 * read:17.1f} "
                  f"{passes[0]['file'] / 1e6:8.2f}")


if __name__ == "__main__":
    main()
