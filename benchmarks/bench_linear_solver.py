"""Reduced, dense, sparse and SuperLU_MT LU in the compiled IDA loop: chains of N links, whole ``simulate`` calls.

The mechanism is ``daeclear.mechanisms.chain(N)``: N links hanging from the ground, every pin a
revolute clearance joint, so the model has 6 N states and N contact terms. For every N the
model is compiled once (a warm-up call per solver, not timed), then ``simulate(scene, t_end,
linear_solver=...)`` is timed ``--repeats`` times per solver, the four interleaved (the machine
is shared: interleaving spreads any disturbance over all of them), and the best wall time of
each is reported with the IDA loop's own time (``stats["solve_time"]``), the steps, the Jacobian
evaluations and the nonzeros of the union Jacobian pattern the sparse solvers factor.

``red/sp`` is reduced / sparse (the plan's LU): above 1 the sparse LU is faster. ``linear_solver="auto"``
chooses between those two: the threshold ``daeclear.engine.c_session.SPARSE_MIN_STATES`` is set
from this table. ``den/red`` shows what the reduced LU gains over SUNDIALS' dense LU, ``slu/sp`` what
the plan's LU gains over SUNDIALS' SuperLU_MT (``"superlu"``).
Only public API is used (``daeclear.simulate``, ``daeclear.mechanisms.chain``). ``--write-doc`` writes
the ratios, the union pattern's nonzeros and the steps and events (deterministic, checked by
tests/test_doc_numbers.py) into docs/performance.md (block "linear-solver").

    python benchmarks/bench_linear_solver.py [--sizes 1,2,4,8,16,32] [--t-end 0.01] [--repeats 5] [--rtol 1e-6]
        [--write-doc]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import daeclear as dc
from daeclear.model.mechanisms import chain

SOLVERS = ("reduced", "dense", "sparse", "superlu")


def timed(scene: Any, t_end: float, rtol: float, solver: str) -> tuple[float, dict[str, Any]]:
    """Wall time of one whole simulate call and its statistics."""
    tic = time.perf_counter()
    result = dc.simulate(scene, t_end, rtol=rtol, options=dc.SolverOptions(backend="c", linear_solver=solver))
    wall = time.perf_counter() - tic
    if not result.success:
        raise SystemExit(f"{scene.name} with {solver} LU failed: {result.message}")
    return wall, dict(result.stats, n_events=len(result.events))


def measure(n_links: int, t_end: float, rtol: float, repeats: int) -> dict[str, Any]:
    """Best wall and IDA-loop times of each solver for a chain of n_links."""
    scene = chain(n_links)
    best: dict[str, tuple[float, dict[str, Any]]] = {}
    for solver in SOLVERS:  # warm-up: compiles the model (one library serves every solver)
        timed(scene, t_end, rtol, solver)
    for _ in range(repeats):
        for solver in SOLVERS:
            wall, stats = timed(scene, t_end, rtol, solver)
            if solver not in best or wall < best[solver][0]:
                best[solver] = (wall, stats)
    n = 6 * n_links
    return dict(N=n_links, states=n, nnz=best["sparse"][1]["jac_nnz"], density=best["sparse"][1]["jac_nnz"] / n**2,
                wall={k: v[0] for k, v in best.items()}, loop={k: v[1]["solve_time"] for k, v in best.items()},
                steps="/".join(str(best[k][1]["n_steps"]) for k in SOLVERS),
                events="/".join(str(best[k][1]["n_events"]) for k in SOLVERS))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1,2,4,8,16,32", help="comma-separated numbers of links")
    ap.add_argument("--t-end", type=float, default=0.01, help="simulated time per call, s")
    ap.add_argument("--repeats", type=int, default=5, help="timed calls per solver (best is kept)")
    ap.add_argument("--rtol", type=float, default=1e-6)
    ap.add_argument("--write-doc", action="store_true", help="write the table into docs/performance.md")
    args = ap.parse_args(argv)
    sizes = [int(x) for x in args.sizes.split(",") if x.strip()]
    print(f"chain(N), t_end={args.t_end} s, rtol={args.rtol}, best of {args.repeats}; wall = whole simulate call, "
          "loop = IDA loop in C; red/sp = reduced / sparse (above 1 sparse is faster), den/red = dense / reduced, "
          "slu/sp = superlu / sparse")
    head = (f"{'N':>3} {'states':>6} {'nnz':>6} {'dens.':>6} {'reduced':>10} {'dense':>10} {'sparse':>10} "
            f"{'superlu':>10} {'red/sp':>6} {'den/red':>7} {'slu/sp':>6} {'loop red':>10} {'loop sp':>10} "
            f"{'red/sp':>6} {'steps r/d/s/slu':>23} {'events':>15}")
    print(head)
    doc = ["| N | states | union nnz | density | reduced / sparse, whole call | dense / reduced | superlu / sparse | "
           "reduced / sparse, IDA loop | steps (reduced / dense / sparse / superlu) | events |",
           "|---|---:|---:|---:|---:|---:|---:|---:|---|---|"]
    for n_links in sizes:
        r = measure(n_links, args.t_end, args.rtol, args.repeats)
        w, lp = r["wall"], r["loop"]
        doc.append(f"| {r['N']} | {r['states']} | {r['nnz']} | {r['density']:.3f} | {w['reduced'] / w['sparse']:.2f} | "
                   f"{w['dense'] / w['reduced']:.2f} | {w['superlu'] / w['sparse']:.2f} | "
                   f"{lp['reduced'] / lp['sparse']:.2f} | {r['steps']} | {r['events']} |")
        print(f"{r['N']:>3} {r['states']:>6} {r['nnz']:>6} {r['density']:>6.3f} {w['reduced'] * 1e3:>7.1f} ms "
              f"{w['dense'] * 1e3:>7.1f} ms {w['sparse'] * 1e3:>7.1f} ms {w['superlu'] * 1e3:>7.1f} ms "
              f"{w['reduced'] / w['sparse']:>6.2f} {w['dense'] / w['reduced']:>7.2f} "
              f"{w['superlu'] / w['sparse']:>6.2f} "
              f"{lp['reduced'] * 1e3:>7.1f} ms {lp['sparse'] * 1e3:>7.1f} ms {lp['reduced'] / lp['sparse']:>6.2f} "
              f"{r['steps']:>23} {r['events']:>15}", flush=True)
    if args.write_doc:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_tables import write_block

        command = (f"python benchmarks/bench_linear_solver.py --sizes {args.sizes} --t-end {args.t_end:g} "
                   f"--repeats {args.repeats}")
        print(f"wrote {write_block('docs/performance.md', 'linear-solver', command, doc)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
