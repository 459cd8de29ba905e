"""Compiled (C) versus pure-Python IDA backend on two models with events.

1. Bouncing ball (n = 2): Hertz contact term switched on at impact and off at separation,
   5 s, 12 events.
2. Chain of 5 pendulums (n = 25: 10 positions, 10 velocities, 5 multipliers, index-1 with
   Baumgarte, dense Jacobian) swinging against a wall: Lankarani-Nikravesh contact term on
   the last mass with the approach velocity as its parameter.

Both are driven by the same hand-written event loop (root -> toggle the term -> reinit).
3. The Fig. 4.15 scene (``slider_crank("revolute", gravity=0.0)``), two revolutions at rtol 1e-8,
   whole ``simulate`` calls with ``backend="python"`` and ``"c"`` (the fallback a user without a
   C compiler gets).

Prints wall time of the whole loop (best of --repeat, the backends interleaved), IDA statistics and
the python/c ratio, and the compile time of the 25-state model in a fresh cache directory;
``--write-doc`` writes the ratios into docs/performance.md (block "fallback").

    python benchmarks/bench_session.py [--repeat 3] [--t-end-chain 5.0] [--write-doc]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np

try:
    import daeclear  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from daeclear.engine.ida_session import DAEFunctions, open_session  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from doc_tables import write_block  # noqa: E402

G = 9.81
DOC, BLOCK = "docs/performance.md", "fallback"


def _J(r, y, yp, cj):
    return ca.jacobian(r, y) + cj * ca.jacobian(r, yp)


def ball_model(K=1e7):
    t, y, yp, cj, p = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj"), ca.SX.sym("p", 1)
    r = ca.vertcat(yp[0] - y[1], yp[1] + G)
    rt = ca.vertcat(0, -K * ca.fmax(-y[0], 0) ** 1.5)
    return DAEFunctions(
        2, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
        (ca.Function("contact", [t, y, yp, p], [rt]),),
        (ca.Function("contact_J", [t, y, yp, p, cj], [_J(rt, y, yp, cj)]),),
        ca.Function("gap", [t, y, yp], [y[0]]), "bench_ball",
    )


def chain_model(links=5, L=0.2, m=1.0, wall=0.2, K=1e9, ce=0.9, alpha=5.0, beta=5.0):
    """Chain of point masses on rigid rods, index-1 with Baumgarte; a wall at x = -wall*links*L."""
    nq = 2 * links
    n = 2 * nq + links
    t, y, yp, cj, p = ca.SX.sym("t"), ca.SX.sym("y", n), ca.SX.sym("yp", n), ca.SX.sym("cj"), ca.SX.sym("p", 1)
    q, v, lam = y[:nq], y[nq:2 * nq], y[2 * nq:]
    qd, vd = yp[:nq], yp[nq:2 * nq]
    phis = []
    for i in range(links):
        xi, yi = q[2 * i], q[2 * i + 1]
        xp, ypv = (q[2 * i - 2], q[2 * i - 1]) if i else (0, 0)
        phis.append(((xi - xp) ** 2 + (yi - ypv) ** 2 - L**2) / 2)
    phi = ca.vertcat(*phis)
    phi_q = ca.jacobian(phi, q)
    dphi = phi_q @ v
    gam = ca.jacobian(dphi, q) @ v
    f_ext = ca.vertcat(*[ca.vertcat(0, -m * G) for _ in range(links)])
    r = ca.vertcat(qd - v, m * vd + phi_q.T @ lam - f_ext, phi_q @ vd + gam + 2 * alpha * dphi + beta**2 * phi)
    w = wall * links * L
    x_last, u_last = q[nq - 2], v[nq - 2]
    delta = ca.fmax(-(x_last + w), 0)
    force = K * delta**1.5 * (1 + 3 * (1 - ce**2) / 4 * (-u_last) / p[0])
    rt = ca.vertcat(ca.DM.zeros(nq), ca.DM.zeros(nq - 2), -force, 0, ca.DM.zeros(links))
    funcs = DAEFunctions(
        n, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
        (ca.Function("wall", [t, y, yp, p], [rt]),), (ca.Function("wall_J", [t, y, yp, p, cj], [_J(rt, y, yp, cj)]),),
        ca.Function("gap", [t, y, yp], [x_last + w]), "bench_chain",
    )
    # consistent start: horizontal chain at rest; v' and lambda from the linear system
    y0 = np.zeros(n)
    y0[0:nq:2] = L * np.arange(1, links + 1)
    yp0 = np.zeros(n)
    unknowns = ca.vertcat(vd, lam)
    r_dyn = r[nq:]  # equations of motion and constraints: linear in (v', lambda)
    known = ca.vertcat(y0[:nq], y0[nq:2 * nq], y0[nq:2 * nq])
    res_fn = ca.Function("r0", [unknowns], [ca.substitute(r_dyn, ca.vertcat(q, v, qd), known)])
    A = np.array(ca.densify(ca.Function("A", [unknowns], [ca.jacobian(res_fn(unknowns), unknowns)])(0)))
    b = -np.array(res_fn(np.zeros(nq + links))).ravel()
    sol = np.linalg.solve(A, b)
    yp0[nq:2 * nq] = sol[:nq]
    y0[2 * nq:] = sol[nq:]
    yp0[:nq] = y0[nq:2 * nq]
    atol = np.concatenate([np.full(nq, 1e-10), np.full(nq, 1e-8), np.full(links, 1e4)])
    return funcs, y0, yp0, atol, nq


def run_events(session, y0, yp0, t_end, approach_index=None):
    """Event loop: free -> watch gap closing (-1); contact -> watch opening (+1)."""
    active = False
    p = np.ones(1)
    session.reinit(0.0, y0, yp0, [False], [p], root_directions=[-1])
    events = 0
    while True:
        a = session.advance(t_end)
        if a.status == "error":
            raise RuntimeError(a.message)
        if a.status != "root":
            return events, a
        events += 1
        active = not active
        if active and approach_index is not None:
            p = np.array([max(abs(a.y[approach_index]), 1e-3)])
        session.reinit(a.t, a.y, a.yp, [active], [p], root_directions=[1 if active else -1])


def bench(name, funcs, y0, yp0, atol, rtol, t_end, repeat, approach_index=None):
    best = {}
    for _ in range(repeat):  # the backends interleaved: the machine's drift hits both
        for backend in ("c", "python"):
            s = open_session(funcs, backend=backend, rtol=rtol, atol=atol)
            tic = time.perf_counter()
            events, last = run_events(s, y0, yp0, t_end, approach_index)
            wall = time.perf_counter() - tic
            st = s.stats()
            if backend not in best or wall < best[backend][0]:
                best[backend] = (wall, events, st, last)
            s.close()
    print(f"\n{name}: n={funcs.n}, t_end={t_end}, rtol={rtol:g}")
    print(f"  {'backend':8s} {'wall [s]':>10s} {'solve [s]':>10s} {'events':>7s} {'steps':>8s} {'res evals':>10s} "
          f"{'jac evals':>10s} {'root evals':>10s}")
    for backend, (wall, events, st, _last) in best.items():
        print(f"  {backend:8s} {wall:10.4f} {st['solve_time']:10.4f} {events:7d} {st['n_steps']:8d} "
              f"{st['n_res_evals']:10d} {st['n_jac_evals']:10d} {st['n_root_evals']:10d}")
    ratio = best["python"][0] / best["c"][0]
    dy = np.max(np.abs(best["python"][3].y - best["c"][3].y))
    print(f"  python / c wall-time ratio: {ratio:.1f}x   (max |y_python - y_c| at t_end: {dy:.2e})")
    return f"| {name} | {funcs.n} | {best['c'][1]} / {best['python'][1]} | {ratio:.0f} |"


def bench_simulate(repeat):
    """Whole simulate calls on the Fig. 4.15 scene, python against compiled backend."""
    import daeclear as dc

    scene, t_end, rtol = dc.mechanisms.slider_crank("revolute", gravity=0.0), 0.024, 1e-8
    model = dc.assemble(scene)
    best = {}
    for _ in range(repeat + 1):  # the first round compiles (or hits the cache) and is not counted
        for backend in ("c", "python"):
            tic = time.perf_counter()
            result = dc.simulate(model, t_end, rtol=rtol, options=dc.SolverOptions(backend=backend))
            wall = time.perf_counter() - tic
            if _ and (backend not in best or wall < best[backend][0]):
                best[backend] = (wall, len(result.events))
    ratio = best["python"][0] / best["c"][0]
    print(f"\nsimulate, Fig. 4.15 scene, two revolutions, rtol 1e-8: python / c {ratio:.1f}x "
          f"(events {best['c'][1]} / {best['python'][1]})")
    return f"| simulate, Fig. 4.15 scene, two revolutions, rtol 1e-8 | {model.n_states} | " \
           f"{best['c'][1]} / {best['python'][1]} | {ratio:.0f} |"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--t-end-chain", type=float, default=5.0)
    ap.add_argument("--write-doc", action="store_true", help=f"write the ratios into {DOC}")
    args = ap.parse_args(argv)

    # compile time of the 25-state model, in a fresh cache directory
    funcs, y0, yp0, atol, nq = chain_model()
    with tempfile.TemporaryDirectory() as tmp:
        old = os.environ.get("DAECLEAR_CACHE_DIR")
        os.environ["DAECLEAR_CACHE_DIR"] = tmp
        try:
            tic = time.perf_counter()
            s = open_session(funcs, backend="c", rtol=1e-8, atol=atol)
            total = time.perf_counter() - tic
            st = s.stats()
            print(f"25-state model, fresh cache: open_session {total:.2f} s "
                  f"(code generation {st['codegen_time']:.3f} s, "
                  f"compiler {st['compile_time']:.2f} s); SUNDIALS {s.sundials_version}")
            s.close()
            tic = time.perf_counter()
            s = open_session(funcs, backend="c", rtol=1e-8, atol=atol)
            print(f"25-state model, cache hit:   open_session {time.perf_counter() - tic:.3f} s "
                  f"(cache_hit={s.stats()['cache_hit']})")
            s.close()
        finally:
            if old is None:
                os.environ.pop("DAECLEAR_CACHE_DIR", None)
            else:
                os.environ["DAECLEAR_CACHE_DIR"] = old

    rows = ["| model | states | events (compiled / python) | python / compiled wall time |", "|---|---:|---|---:|"]
    rows.append(bench("bouncing ball, 5 s, rtol 1e-9", ball_model(), np.array([1.0, 0.0]), np.array([0.0, -G]),
                      np.array([1e-12, 1e-10]), 1e-9, 5.0, args.repeat))
    rows.append(bench(f"pendulum chain against a wall, {args.t_end_chain:g} s, rtol 1e-8", funcs, y0, yp0, atol, 1e-8,
                      args.t_end_chain, args.repeat, approach_index=2 * nq - 2))  # u of the last mass
    rows.append(bench_simulate(args.repeat))
    print("\n".join(["", *rows]))
    if args.write_doc:
        command = "python benchmarks/bench_session.py" + (f" --repeat {args.repeat}" if args.repeat != 3 else "")
        print(f"wrote {write_block(DOC, BLOCK, command, rows)}")


if __name__ == "__main__":
    main()
