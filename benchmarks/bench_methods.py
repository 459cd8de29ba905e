"""IDA against the other integrators on the chapter's clearance slider-crank (Fig. 4.15 scene).

    python benchmarks/bench_methods.py [--repeat 3] [--quick] [--write-doc]

Scene: ``slider_crank("revolute", gravity=0.0)`` (c = 0.5 mm, Lankarani-Nikravesh, c_e = 0.9),
two crank revolutions (t_end = 0.024 s). For every method and tolerance (or step) it prints the
wall time of the whole ``simulate`` call on the assembled model (best of --repeat, compiled
libraries cached and warm), accepted steps, right-hand side / residual evaluations, Jacobian
evaluations and the number of contact events over the two revolutions, and the error of
slider.vx against an IDA reference at rtol 1e-10 over the first 5 ms only: the motion is chaotic
and later errors say nothing about the integrator (the reference itself is checked there against
DOP853 at rtol 1e-12). Then the speed ratio: for each IDA run, the fastest other method whose
error is at most IDA's (IDA at equal or worse accuracy), and how much slower it is.

``--write-doc`` writes the table (times as ratios to the IDA run at rtol 1e-6) and the speed ratios
into docs/performance.md (block "methods").

Last, the gap check of daeclear.solvers.explicit with and without its cubic Hermite test for crossings
inside a step (docs/performance.md): event counts over the first 5 ms and the two revolutions.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

try:
    import daeclear  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import daeclear as dc  # noqa: E402
import daeclear.solvers.explicit as integrators  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from doc_tables import write_block  # noqa: E402

DOC, BLOCK = "docs/performance.md", "methods"

T_END = 0.024
WINDOW = 0.005
CHANNEL = "slider.vx"

CASES_FULL = [
    ("ida", "rtol", [1e-6, 1e-8, 1e-10]),
    ("RK45", "rtol", [1e-6, 1e-8, 1e-10]),
    ("DOP853", "rtol", [1e-6, 1e-8, 1e-10]),
    ("LSODA", "rtol", [1e-6, 1e-8, 1e-10]),
    ("Radau", "rtol", [1e-6, 1e-8]),
    ("BDF", "rtol", [1e-6, 1e-8]),
    ("rk4", "step", [1e-5, 1e-6, 1e-7]),
    ("euler", "step", [1e-6, 1e-7]),
]
CASES_QUICK = [
    ("ida", "rtol", [1e-6, 1e-8]),
    ("DOP853", "rtol", [1e-6, 1e-8]),
    ("LSODA", "rtol", [1e-8]),
    ("rk4", "step", [1e-5, 1e-6]),
]


def settings(method, kind, value):
    """The solver settings of a case: ``kind`` is "rtol" or "step"."""
    return dc.SolverOptions(method=method, **{kind: value})


def run(model, method, kind, value, te, repeat):
    best, result = np.inf, None
    for _ in range(repeat):
        tic = time.perf_counter()
        result = dc.simulate(model, T_END, options=settings(method, kind, value), on_failure="return",
                             save=dc.SaveAt(times=te))
        best = min(best, time.perf_counter() - tic)
    return best, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (best wall time is kept)")
    parser.add_argument("--quick", action="store_true", help="fewer cases")
    parser.add_argument("--write-doc", action="store_true", help=f"write the table into {DOC}")
    args = parser.parse_args()

    model = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")  # every method: index-1
    # output on the accuracy window only (the runs still go to T_END); t = 0 .. 5 ms every 5 us
    te = np.linspace(0.0, WINDOW, 1001)
    ref = dc.simulate(model, T_END, rtol=1e-10, save=dc.SaveAt(times=te))
    check = dc.simulate(model, T_END, method="DOP853", rtol=1e-12, save=dc.SaveAt(times=te))
    scale = np.max(np.abs(ref[CHANNEL]))
    ref_err = np.max(np.abs(check[CHANNEL] - ref[CHANNEL]))
    n_window = int(np.sum(ref.events.t <= WINDOW))
    print(f"scene: {model.scene_name}, t_end = {T_END} s, {len(ref.events)} events in the IDA rtol 1e-10 "
          f"reference ({n_window} in the first {WINDOW * 1e3:g} ms)")
    print(f"error measure: max |{CHANNEL} - reference| over [0, {WINDOW}] s (max |{CHANNEL}| = {scale:.3g} m/s); "
          f"reference vs DOP853 rtol 1e-12 there: {ref_err:.1e} m/s")
    # warm-up: compile or load every library once
    for method, kind, values in CASES_FULL:
        dc.simulate(model, 1e-4, options=settings(method, kind, values[0]))

    rows = []
    header = (f"{'method':<7} {'tol/step':>8} {'wall s':>8} {'steps':>8} {'f evals':>8} {'J evals':>7} "
              f"{'events':>6} {'err m/s':>9}  note")
    print()
    print(header)
    print("-" * len(header))
    for method, kind, values in (CASES_QUICK if args.quick else CASES_FULL):
        for value in values:
            wall, r = run(model, method, kind, value, te, args.repeat)
            st = r.stats
            ok = r.success and r.t.size == te.size
            err = np.max(np.abs(r[CHANNEL] - ref[CHANNEL])) if ok else np.inf
            ev_window = r.events.t[r.events.t <= WINDOW] if len(r.events) else np.zeros(0)
            same = (ev_window.size == n_window and
                    np.allclose(ev_window, ref.events.t[:n_window], rtol=0, atol=1e-6))
            note = "" if r.success else r.message[:70]
            if r.success and not same:
                note = f"event times in the window differ ({ev_window.size} vs {n_window} events)"
            if method == "ida" and value == 1e-10:
                note = f"the reference itself (vs DOP853 rtol 1e-12: {ref_err:.1e})"
                err = np.nan
            elif err < ref_err:
                note = (note + "; " if note else "") + "below the reference's own uncertainty"
            rows.append(dict(method=method, value=value, wall=wall, err=err, ok=r.success, kind=kind,
                             steps=st["n_steps"], events=len(r.events), note=note))
            print(f"{method:<7} {value:>8.0e} {wall:>8.3f} {st['n_steps']:>8d} {st['n_res_evals']:>8d} "
                  f"{st.get('n_jac_evals', 0):>7d} {len(r.events):>6d} {err:>9.1e}  {note}")

    base = next(r["wall"] for r in rows if r["method"] == "ida" and r["value"] == 1e-6)
    doc = ["| method | rtol or step | steps | events | error (m/s) | wall time / IDA's at rtol 1e-6 |",
           "|---|---|---:|---:|---:|---:|"]
    for r in rows:
        setting = f"{'step ' if r['kind'] == 'step' else ''}{r['value']:.0e}"
        error = "(reference)" if np.isnan(r["err"]) else f"{r['err']:.1e}" if np.isfinite(r["err"]) else "failed"
        doc.append(f"| {r['method']} | {setting} | {r['steps']} | {r['events']} | {error} | {r['wall'] / base:.1f} |")
    doc += ["", "IDA against the fastest other method whose error is at most IDA's:", ""]
    print()
    print("IDA against the fastest other method whose error is at most IDA's (IDA at equal or worse accuracy):")
    for row in rows:
        if row["method"] != "ida" or not row["ok"] or not np.isfinite(row["err"]):
            continue
        rivals = [r for r in rows if r["method"] != "ida" and r["ok"] and r["err"] <= row["err"]]
        if not rivals:
            print(f"  ida rtol {row['value']:.0e}: error {row['err']:.1e}, no other method reaches it")
            doc.append(f"- IDA at rtol {row['value']:.0e} (error {row['err']:.1e}): no other method reaches it.")
            continue
        fast = min(rivals, key=lambda r: r["wall"])
        print(f"  ida rtol {row['value']:.0e}: {row['wall']:.3f} s, error {row['err']:.1e}; fastest other: "
              f"{fast['method']} {fast['value']:.0e} {fast['wall']:.3f} s, error {fast['err']:.1e} "
              f"-> IDA {fast['wall'] / row['wall']:.1f}x faster")
        doc.append(f"- IDA at rtol {row['value']:.0e} (error {row['err']:.1e}): {fast['wall'] / row['wall']:.1f}x "
                   f"faster than {fast['method']} at {fast['value']:.0e} (error {fast['err']:.1e}).")
    if args.write_doc:
        command = "python benchmarks/bench_methods.py" + (f" --repeat {args.repeat}" if args.repeat != 3 else "") + (
            " --quick" if args.quick else "")
        print(f"wrote {write_block(DOC, BLOCK, command, doc)}")

    print()
    print("gap check inside a step (cubic Hermite test) against sign changes at step ends only:")
    print(f"{'method':<7} {'tol/step':>8} {'check':>8} {'events':>6} {'in 5 ms':>7} {'f evals':>8}")
    cases = [("rk4", "step", 1e-5), ("rk4", "step", 4e-5), ("DOP853", "rtol", 1e-6), ("RK45", "rtol", 1e-4)]
    for method, kind, value in cases:
        for hermite in (True, False):
            integrators.HERMITE_GAP_CHECK = hermite
            try:
                r = dc.simulate(model, T_END, options=settings(method, kind, value), on_failure="return")
            finally:
                integrators.HERMITE_GAP_CHECK = True
            print(f"{method:<7} {value:>8.0e} {'hermite' if hermite else 'ends':>8} {len(r.events):>6d} "
                  f"{int(np.sum(r.events.t <= WINDOW)):>7d} {r.stats['n_res_evals']:>8d}")


if __name__ == "__main__":
    main()
