"""simulate_wear with every cycle simulated: cycles a second, where the time goes, and the spreading
against sampling each arc, side by side.

    python benchmarks/bench_wear.py [--cycles 100] [--repeats 3]

The scene of examples/joint_wear.py (the chapter's slider-crank, friction 0.1, the rod-slider bearing
wearing with k = 1e-13, 360 nodes, 48 modes), ``simulate_wear(scene, cycles)`` with ``extrapolate=1``.
Prints, best of ``--repeats`` (interleaved with the reference runs so that a loaded machine slows all
alike): cycles a second; the same blocks' ``simulate`` alone (the floor the wear study cannot beat);
the spreading of one block's contacts by ``daeclear.contact.wear.spread`` against the former
implementation, every arc sampled at >= 64 points (kept here as the reference), with their ratio and
the largest difference of the two depths.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))

import daeclear as dc  # noqa: E402
from daeclear.contact import wear as wear_law  # noqa: E402
from daeclear.studies.poincare import crank_period  # noqa: E402
from daeclear.studies.wear import simulate_wear, wear_history  # noqa: E402
from joint_wear import worn_scene  # noqa: E402


def sampled_spread(centre: np.ndarray, half: np.ndarray, load: np.ndarray, nodes: int, distribution: str) -> np.ndarray:
    """The former spreading: each arc sampled at max(64, 16 per node spacing) points, each sample split
    between its two neighbouring nodes (the reference)."""
    spacing = 2.0 * math.pi / nodes
    count = max(64, int(math.ceil(16.0 * float(half.max()) / spacing)))
    phi = np.outer(half, (np.arange(count) + 0.5) / count * 2.0 - 1.0)
    wide = half > 0.0
    shape = np.ones_like(phi)
    shape[wide] = wear_law._shape(distribution, phi[wide], half[wide, None])
    share = (shape * (load / shape.sum(axis=1))[:, None]).ravel()
    position = ((centre[:, None] + phi) % (2.0 * math.pi)) / spacing
    lower = np.floor(position)
    up = (position - lower).ravel()
    node = lower.astype(int).ravel() % nodes
    return np.bincount(node, share * (1 - up), minlength=nodes) + np.bincount((node + 1) % nodes, share * up,
                                                                                minlength=nodes)


def block_contacts(scene: dc.Scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One simulated cycle's contact intervals as wear_increment spreads them (centres, half-angles, loads)."""
    model = dc.assemble(scene)
    run = dc.simulate(model, crank_period(scene))
    h = wear_history(run, model, "clearance")
    force = 0.5 * (h.force[1:] + h.force[:-1])
    ds = 0.5 * (np.abs(h.slip_speed[1:]) + np.abs(h.slip_speed[:-1])) * np.diff(h.t)
    active = np.flatnonzero((force > 0) & (ds > 0))
    half = wear_law.half_angle_overlap(0.5 * (h.penetration[1:] + h.penetration[:-1])[active], 0.5e-3)
    a, b = h.angle_bearing[:-1][active], h.angle_bearing[1:][active]
    step = b - a
    centre = a + 0.5 * (step - 2 * math.pi * np.round(step / (2 * math.pi)))
    return centre, half, 1e-13 * force[active] * ds[active]


def best(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        tic = time.perf_counter()
        fn()
        times.append(time.perf_counter() - tic)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    scene = worn_scene(1e-13)
    period = crank_period(scene)
    model = dc.assemble(scene)
    simulate_wear(scene, 2)  # warm-up: the library compiled or loaded
    wear_time, sim_time = math.inf, math.inf
    for _ in range(args.repeats):
        tic = time.perf_counter()
        simulate_wear(scene, args.cycles)
        wear_time = min(wear_time, time.perf_counter() - tic)
        tic = time.perf_counter()
        t0, y0 = 0.0, None
        for _k in range(args.cycles):  # the same blocks, simulate alone (the unworn profile)
            run = dc.simulate(model, t0 + period, t0=t0, y0=y0)
            t0, y0 = float(run.t[-1]), run.state(-1)  # the last state alone (no pass over every row)
        sim_time = min(sim_time, time.perf_counter() - tic)
    centre, half, load = block_contacts(scene)
    new = best(lambda: wear_law.spread(centre, half, load, 360), 5 * args.repeats)
    old = best(lambda: sampled_spread(centre, half, load, 360, "elastic-foundation"), 5 * args.repeats)
    diff = np.max(np.abs(wear_law.spread(centre, half, load, 360)
                         - sampled_spread(centre, half, load, 360, "elastic-foundation")))
    print(f"simulate_wear, {args.cycles} cycles, every cycle simulated: {args.cycles / wear_time:.1f} cycles/s "
          f"({1e3 * wear_time / args.cycles:.1f} ms a cycle)")
    print(f"simulate alone, the same blocks: {args.cycles / sim_time:.1f} cycles/s "
          f"({1e3 * sim_time / args.cycles:.1f} ms a cycle); wear study / simulate = {wear_time / sim_time:.2f}")
    print(f"spreading one cycle's {centre.size} contact intervals: {1e3 * new:.2f} ms, sampling each arc "
          f"{1e3 * old:.2f} ms (x{old / new:.1f}); largest difference {diff / np.max(np.abs(load)):.2e} of the "
          "largest load")


if __name__ == "__main__":
    main()
