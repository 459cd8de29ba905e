"""Dense against sparse LU in the compiled IDA loop: chains of N links, whole ``simulate`` calls.

The mechanism is ``daeclear.mechanisms.chain(N)``: N links hanging from the ground, every pin a
revolute clearance joint, so the model has 6 N states and N contact terms. For every N the
model is compiled once (a warm-up call per solver, not timed), then ``simulate(scene, t_end,
linear_solver=...)`` is timed ``--repeats`` times per solver, dense and sparse interleaved (the
machine is shared: interleaving spreads any disturbance over both), and the best wall time of
each is reported with the IDA loop's own time (``stats["solve_time"]``), the steps, the Jacobian
evaluations and the nonzeros of the union Jacobian pattern the sparse solver factors.

``ratio`` is dense wall / sparse wall: above 1 the sparse solver is faster. The threshold
``daeclear.engine.c_session.SPARSE_MIN_STATES`` of ``linear_solver="auto"`` is set from this table.
Only public API is used (``daeclear.simulate``, ``daeclear.mechanisms.chain``).

    python benchmarks/bench_linear_solver.py [--sizes 1,2,4,8,16,32] [--t-end 0.01] [--repeats 5] [--rtol 1e-6]
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import daeclear as dc
from daeclear.model.mechanisms import chain

SOLVERS = ("dense", "sparse")


def timed(scene: Any, t_end: float, rtol: float, solver: str) -> tuple[float, dict[str, Any]]:
    """Wall time of one whole simulate call and its statistics."""
    tic = time.perf_counter()
    result = dc.simulate(scene, t_end, rtol=rtol, backend="c", linear_solver=solver)
    wall = time.perf_counter() - tic
    if not result.success:
        raise SystemExit(f"{scene.name} with {solver} LU failed: {result.message}")
    return wall, dict(result.stats, n_events=len(result.events))


def measure(n_links: int, t_end: float, rtol: float, repeats: int) -> dict[str, Any]:
    """Best wall and IDA-loop times of each solver for a chain of n_links."""
    scene = chain(n_links)
    best: dict[str, tuple[float, dict[str, Any]]] = {}
    for solver in SOLVERS:  # warm-up: compiles the model (one library serves both solvers)
        timed(scene, t_end, rtol, solver)
    for _ in range(repeats):
        for solver in SOLVERS:
            wall, stats = timed(scene, t_end, rtol, solver)
            if solver not in best or wall < best[solver][0]:
                best[solver] = (wall, stats)
    dense, sparse = best["dense"], best["sparse"]
    n = 6 * n_links
    return dict(N=n_links, states=n, nnz=sparse[1]["jac_nnz"], density=sparse[1]["jac_nnz"] / n**2,
                dense_wall=dense[0], sparse_wall=sparse[0], ratio=dense[0] / sparse[0],
                dense_loop=dense[1]["solve_time"], sparse_loop=sparse[1]["solve_time"],
                loop_ratio=dense[1]["solve_time"] / sparse[1]["solve_time"],
                steps=f"{dense[1]['n_steps']}/{sparse[1]['n_steps']}",
                jacs=f"{dense[1]['n_jac_evals']}/{sparse[1]['n_jac_evals']}",
                events=f"{dense[1]['n_events']}/{sparse[1]['n_events']}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1,2,4,8,16,32", help="comma-separated numbers of links")
    ap.add_argument("--t-end", type=float, default=0.01, help="simulated time per call, s")
    ap.add_argument("--repeats", type=int, default=5, help="timed calls per solver (best is kept)")
    ap.add_argument("--rtol", type=float, default=1e-6)
    args = ap.parse_args(argv)
    sizes = [int(x) for x in args.sizes.split(",") if x.strip()]
    print(f"chain(N), t_end={args.t_end} s, rtol={args.rtol}, best of {args.repeats}; "
          "wall = whole simulate call, loop = IDA loop in C; ratio = dense / sparse")
    head = (f"{'N':>3} {'states':>6} {'nnz':>6} {'dens.':>6} {'dense wall':>11} {'sparse wall':>11} {'ratio':>6} "
            f"{'dense loop':>11} {'sparse loop':>11} {'ratio':>6} {'steps d/s':>12} {'Jacs d/s':>11} {'events':>7}")
    print(head)
    for n_links in sizes:
        r = measure(n_links, args.t_end, args.rtol, args.repeats)
        print(f"{r['N']:>3} {r['states']:>6} {r['nnz']:>6} {r['density']:>6.3f} {r['dense_wall'] * 1e3:>8.1f} ms "
              f"{r['sparse_wall'] * 1e3:>8.1f} ms {r['ratio']:>6.2f} {r['dense_loop'] * 1e3:>8.1f} ms "
              f"{r['sparse_loop'] * 1e3:>8.1f} ms {r['loop_ratio']:>6.2f} {r['steps']:>12} {r['jacs']:>11} "
              f"{r['events']:>7}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
