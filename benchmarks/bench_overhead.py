"""What a ``simulate(scene, ...)`` call costs above its IDA loop, once the structure is built.

For the Fig. 4.15 scene (revolute clearance 0.5 mm, 5000 rpm, no gravity) on a 2 ms window and
on two crank revolutions (400 output points), side by side, best of --repeats:

* ``same scene``: the same Scene object again (validation and parameters are remembered);
* ``new numbers``: a new Scene with another clearance each call (what a sweep does);
* ``model``: a pre-assembled DAEModel (no assembly at all).

Columns: whole-call wall time, the IDA loop in C (``stats["solve_time"]``), and their difference,
the set-up (assembly, initial state, session) and the rest (event recording, report pass, Result).
Target: about 1 ms above the IDA loop for a scene seen before or differing only in numbers.

    python benchmarks/bench_overhead.py [--repeats 20]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import daeclear as dc

REV = 60.0 / 5000.0


def measure(label: str, make, t_end: float, repeats: int) -> None:
    t_eval = np.linspace(0.0, t_end, 400)
    dc.simulate(make(0), t_end=t_end, rtol=1e-7, t_eval=t_eval)  # builds or loads the structure
    rows = []
    for i in range(repeats):
        target = make(i + 1)
        start = time.perf_counter()
        result = dc.simulate(target, t_end=t_end, rtol=1e-7, t_eval=t_eval)
        wall = time.perf_counter() - start
        rows.append((wall, result.stats["solve_time"], result.stats["setup_time"]))
    wall, solve, setup = min(rows)
    print(f"  {label:<12} wall {wall * 1e3:7.2f} ms  IDA loop {solve * 1e3:7.2f} ms  above it {(wall - solve) * 1e3:6.2f} ms "
          f"(set-up {setup * 1e3:5.2f} ms, rest {(wall - solve - setup) * 1e3:5.2f} ms)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    args = parser.parse_args()
    warnings.simplefilter("ignore", dc.DaeclearWarning)
    scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
    model = dc.assemble(scene)
    for window, t_end in (("first 2 ms", 0.002), ("two revolutions", 2 * REV)):
        print(f"Fig. 4.15 scene, {window}, rtol 1e-7, 400 output points")
        measure("same scene", lambda i: scene, t_end, args.repeats)
        measure("new numbers", lambda i: dc.mechanisms.slider_crank("revolute", gravity=0.0,
                                                                      clearance=0.5e-3 * (1 + 1e-3 * i)),
                t_end, args.repeats)
        measure("model", lambda i: model, t_end, args.repeats)


if __name__ == "__main__":
    main()
