"""A lubricated rod-slider joint against the dry one: wall time of two crank revolutions, side by side.

    python benchmarks/bench_lubricated.py [--repeats 5] [--revolutions 2]

The chapter's slider-crank (5000 rpm, c = 0.5 mm, GGL, rtol 1e-6), the rod-slider joint dry
(Lankarani-Nikravesh, c_e = 0.9) and lubricated (``HydrodynamicBearing``, 0.1 Pa s, L = 10 mm, short
theory; and 0.006 Pa s, where the film breaks down), run as users call it, ``simulate(scene, ...)``
(assembly and set-up included, libraries compiled in a warm-up). Each time is the best of
``--repeats``, the cases interleaved so that a loaded machine slows all of them alike. Prints wall
time, IDA steps and events per case and the ratio lubricated / dry.
"""

from __future__ import annotations

import argparse
import time

import daeclear as dc
from daeclear.contact import HydrodynamicBearing

REVOLUTION = 60.0 / 5000.0


def scenes() -> dict[str, dc.Scene]:
    def lubricated(mu: float) -> dc.Scene:
        return dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(viscosity=mu, length=10e-3))

    return {"dry": dc.mechanisms.slider_crank("revolute"), "lubricated 0.1 Pa s": lubricated(0.1),
            "lubricated 0.006 Pa s": lubricated(0.006)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--revolutions", type=int, default=2)
    args = parser.parse_args()
    t_end = args.revolutions * REVOLUTION
    cases = scenes()
    best = {label: float("inf") for label in cases}
    info: dict[str, tuple[int, int]] = {}
    for scene in cases.values():  # warm-up: compile and load every library
        dc.simulate(scene, t_end, rtol=1e-6)
    for _ in range(args.repeats):
        for label, scene in cases.items():
            start = time.perf_counter()
            result = dc.simulate(scene, t_end, rtol=1e-6)
            best[label] = min(best[label], time.perf_counter() - start)
            info[label] = (int(result.stats["n_steps"]), len(result.events))
    print(f"{args.revolutions} revolutions, best of {args.repeats} (wall time, simulate(scene) as called by users)")
    for label, wall in best.items():
        steps, events = info[label]
        print(f"  {label:<24s} {wall * 1e3:8.1f} ms  {steps:6d} steps  {events:4d} events  "
              f"{wall / best['dry']:5.2f} x dry")


if __name__ == "__main__":
    main()
