"""Two trees of the package side by side: the same benchmark scripts, interleaved, and the ratio of their times.

    python benchmarks/bench_trees.py OLD NEW [--rounds 3] [--only overhead sweep work_precision]

OLD and NEW are two checkouts (e.g. ``git worktree add /tmp/base <rev>`` and this one). Each round
runs, for each benchmark, OLD's own script in OLD's package and NEW's own script in NEW's package
(each in its own interpreter: a package cannot be imported twice in one process), the order of the
two swapped every round so that the machine's load falls on both alike. ``work_precision`` runs the
study of ``bench_work_precision.py`` (``daeclear.studies.accuracy.work_precision``, the same calls in
both trees) and prints every run's wall time, not only the fastest rival's. Every time printed (a
number followed by ``ms`` or ``s``) is matched between the trees by its line (the line with its
times blanked, and its place among lines alike), the best of the rounds kept for each, as the
scripts themselves keep the best of their repeats. Printed per benchmark: each time, old and new,
and new / old; then the geometric mean and the largest ratio.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from collections import defaultdict
from collections.abc import Iterable
from pathlib import Path
from typing import Any

#: every run of bench_work_precision.py's study, its wall time (the script prints the fastest rival's alone)
WORK_PRECISION = r"""
import sys
import numpy as np
import daeclear as dc
from daeclear.studies.accuracy import work_precision
scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
methods = {"IDA GGL": {"method": "ida"}, "IDA index1": {"method": "ida", "formulation": "index1"},
           **{name: {"method": name} for name in ("RK45", "DOP853", "Radau", "BDF", "LSODA")}}
for window, t_end, channels in (("first 2 ms", 0.002, ["slider.vx", "drive.moment"]),
                                ("two revolutions", 0.024, ["slider.vx"])):
    wp = work_precision(scene, t_end, channels=channels, rtols=np.logspace(-5, -9, 5), methods=methods,
                        repeats=int(sys.argv[1]), n_eval=400)
    for r in wp.rows:
        print(f"{window}: {r['label']} rtol {r['tolerance']:.0e} error {r['error']:.3e} "
              f"wall {r['wall_time'] * 1e3:.2f} ms", flush=True)
"""
#: benchmark -> (its script, or the code of a worker, and the arguments): what issue 35 keeps within 10 %
BENCHMARKS: dict[str, tuple[str, list[str]]] = {
    "overhead": ("bench_overhead.py", ["--repeats", "20"]),
    "sweep": ("bench_sweep.py", ["--points", "30", "--passes", "3"]),
    "work_precision": (WORK_PRECISION, ["3"]),
}
TIME = re.compile(r"(\d+(?:\.\d+)?(?:e[-+]?\d+)?)\s*(ms|s)\b")


def times_by_line(output: str) -> dict[tuple[str, int], list[float]]:
    """Each line's times in seconds, keyed by (the line with its numbers blanked, its place among lines alike)."""
    seen: dict[str, int] = defaultdict(int)
    out: dict[tuple[str, int], list[float]] = {}
    for line in output.splitlines():
        found = [float(v) * (1e-3 if unit == "ms" else 1.0) for v, unit in TIME.findall(line)]
        if not found:
            continue
        key = " ".join(TIME.sub(r"# \2", line).split())
        out[(key, seen[key])] = found
        seen[key] += 1
    return out


def tree_env(tree: Path, cache: Path) -> dict[str, str]:
    """The environment of a process that imports ``tree``'s package, with its own compile cache."""
    return {**os.environ, "PYTHONPATH": str(tree), "DAECLEAR_CACHE_DIR": str(cache), "MPLBACKEND": "Agg"}


def start_worker(tree: Path, cache: Path, code: str) -> subprocess.Popen[str]:
    """A worker process running ``code`` in ``tree``'s package (its own compile cache): it reads one
    request a line on stdin and answers each with one line of JSON on stdout."""
    return subprocess.Popen([sys.executable, "-c", code], cwd=tree, env=tree_env(tree, cache), stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)


def ask(worker: subprocess.Popen[str], request: str) -> dict[str, Any]:
    """One request to ``worker`` (a line) and its JSON answer."""
    assert worker.stdin is not None and worker.stdout is not None
    worker.stdin.write(request + "\n")
    worker.stdin.flush()
    line = worker.stdout.readline()
    if not line:
        raise SystemExit(f"a worker stopped (exit code {worker.wait()}) at {request!r}")
    answer: dict[str, Any] = json.loads(line)
    return answer


def stop_workers(workers: Iterable[subprocess.Popen[str]]) -> None:
    """Close each worker's input and wait for it to end."""
    for worker in workers:
        if worker.stdin is not None:
            worker.stdin.close()
        worker.wait()


def run(tree: Path, script: str, args: list[str], cache: Path) -> str:
    """One benchmark script of ``tree`` (or a worker's code) in ``tree``'s package; its standard output."""
    env = tree_env(tree, cache)
    command = ["-c", script] if "\n" in script else [str(tree / "benchmarks" / script)]
    done = subprocess.run([sys.executable, *command, *args], cwd=tree, env=env, capture_output=True, text=True,
                          check=False)
    if done.returncode != 0:
        raise SystemExit(f"{tree}: {command[-1][:80]} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return done.stdout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--only", nargs="+", choices=sorted(BENCHMARKS), default=list(BENCHMARKS))
    args = parser.parse_args()
    trees = {"old": args.old.resolve(), "new": args.new.resolve()}
    with tempfile.TemporaryDirectory() as tmp:
        caches = {label: Path(tmp) / label for label in trees}
        for name in args.only:
            script, script_args = BENCHMARKS[name]
            best: dict[str, dict[tuple[str, int], list[float]]] = {"old": {}, "new": {}}
            for r in range(args.rounds):
                for label in (("old", "new") if r % 2 == 0 else ("new", "old")):
                    print(f"[{name}] round {r + 1}/{args.rounds}: {label} ({trees[label]})", file=sys.stderr,
                          flush=True)
                    for key, values in times_by_line(run(trees[label], script, script_args, caches[label])).items():
                        held = best[label].setdefault(key, values)
                        best[label][key] = [min(a, b) for a, b in zip(held, values)]
            report(name, best)


def report(name: str, best: dict[str, dict[tuple[str, int], list[float]]]) -> None:
    """Each time both trees printed, old and new, the ratio; the geometric mean and the largest ratio."""
    print(f"\n## {name}: best of the rounds, new / old\n")
    print("| line | old | new | new / old |\n|---|---:|---:|---:|")
    ratios, unmatched = [], [key for key in best["old"] if key not in best["new"]]
    for key in best["old"]:
        if key not in best["new"]:
            continue
        for old, new in zip(best["old"][key], best["new"][key]):
            if old > 0:
                ratios.append(new / old)
                print(f"| {key[0][:90]} | {old * 1e3:.2f} ms | {new * 1e3:.2f} ms | {new / old:.3f} |")
    if ratios:
        mean = math.exp(sum(math.log(r) for r in ratios) / len(ratios))
        print(f"\n{name}: {len(ratios)} times, geometric mean new / old {mean:.3f}, largest {max(ratios):.3f}"
              f"; {len(unmatched)} lines of the old tree without a match")


if __name__ == "__main__":
    main()
