"""Wall time, steps and evaluations of the chapter's slider-crank runs on IDA.

Prints one row per case: the ideal mechanism (one revolution at rtol 1e-6 and 1e-9) and the
Fig. 4.15 scene (revolute clearance 0.5 mm, Lankarani-Nikravesh c_e = 0.9, two revolutions after
a transient of three) at rtol 1e-6 and 1e-8. Times: the whole ``simulate`` call
(best of ``--repeats``; model compiled and cached beforehand, assembly and compile time printed
apart) and, within it, the compiled IDA loop.

    python benchmarks/bench_slider_crank.py [--repeats 5] [--backend c|python]
"""

from __future__ import annotations

import argparse
import time

import daeclear as dc

REV = 60.0 / 5000.0


def run(label: str, scene: dc.Scene, t_end: float, rtol: float, repeats: int, backend: str,
        t_window: float = 0.0) -> None:
    start = time.perf_counter()
    model = dc.assemble(scene)
    assembly = time.perf_counter() - start
    first = dc.simulate(model, t_end, rtol=rtol,
                        options=dc.SolverOptions(backend=backend))  # compiles (or hits the cache)
    best, best_wall = None, float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        result = dc.simulate(model, t_end, rtol=rtol, options=dc.SolverOptions(backend=backend))
        wall = time.perf_counter() - start
        if wall < best_wall:
            best, best_wall = result, wall
    s = best.stats
    events_window = sum(1 for e in best.events if e.t >= t_window)
    print(f"{label:<38} rtol {rtol:<6.0e} wall {best_wall * 1e3:8.2f} ms  "
          f"IDA loop {s['solve_time'] * 1e3:8.2f} ms  steps {s['n_steps']:6d}  "
          f"res {s['n_res_evals']:6d}  jac {s['n_jac_evals']:5d}  events {s['n_events']:4d} "
          f"({events_window} in the last two revolutions)  assembly {assembly * 1e3:.0f} ms  "
          f"compile {first.stats.get('compile_time', 0.0):.2f} s  backend {best.parameters['simulate']['backend']}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", "--repeat", type=int, default=5)
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()
    for rtol in (1e-6, 1e-9):
        run("ideal slider-crank, one revolution", dc.mechanisms.slider_crank(), REV, rtol, args.repeats, args.backend)
    for rtol in (1e-6, 1e-8):
        run("Fig. 4.15, 5 revolutions (3 transient)", dc.mechanisms.slider_crank("revolute"), 5 * REV, rtol,
            args.repeats, args.backend, t_window=3 * REV)
        run("Fig. 4.15 scene, 2 revolutions from t=0", dc.mechanisms.slider_crank("revolute", gravity=0.0),
            2 * REV, rtol, args.repeats, args.backend)


if __name__ == "__main__":
    main()
