"""What a ``simulate(scene, ...)`` call costs above its IDA loop, once the structure is built.

For the Fig. 4.15 scene (revolute clearance 0.5 mm, 5000 rpm, no gravity) on a 2 ms window and
on two crank revolutions (400 output points), side by side, best of --repeats:

* ``same scene``: the same Scene object again (validation and parameters are remembered);
* ``new numbers``: a new Scene with another clearance each call (what a sweep does);
* ``model``: a pre-assembled DAEModel (no assembly at all).

Columns: whole-call wall time, the IDA loop in C (``stats["solve_time"]``), and their difference,
the set-up (assembly, initial state, session) and the rest (event recording, report pass, Result).
Target: about 1 ms above the IDA loop for a scene seen before or differing only in numbers.
``--parts`` then times the pieces of that overhead one by one in a quiet loop (best of --repeats,
each call repeated 50 times): inside a run the same calls take longer (the run's other pieces
evict their code and data from the caches), so the pieces add up to less than the column "above it".

``--write-doc`` writes the time above the IDA loop as a fraction of the loop into docs/engine.md
(block "overhead").

    python benchmarks/bench_overhead.py [--repeats 20] [--parts] [--write-doc]
"""

from __future__ import annotations

import argparse
import time
import timeit
import warnings

import numpy as np

import daeclear as dc
from daeclear.assembly import contact_state
from daeclear.core import automaton
from daeclear.assembly import physics
from daeclear.solvers import ida as solve
from daeclear.engine.ida_session import open_session

REV = 60.0 / 5000.0


def measure(label: str, make, t_end: float, repeats: int) -> tuple[float, float, float]:
    t_eval = np.linspace(0.0, t_end, 400)
    dc.simulate(make(0), t_end=t_end, rtol=1e-7, save=dc.SaveAt(times=t_eval))  # builds or loads the structure
    rows = []
    for i in range(repeats):
        target = make(i + 1)
        start = time.perf_counter()
        result = dc.simulate(target, t_end=t_end, rtol=1e-7, save=dc.SaveAt(times=t_eval))
        wall = time.perf_counter() - start
        rows.append((wall, result.stats["solve_time"], result.stats["setup_time"]))
    wall, solve, setup = min(rows)
    print(f"  {label:<12} wall {wall * 1e3:7.2f} ms  IDA loop {solve * 1e3:7.2f} ms  "
          f"above it {(wall - solve) * 1e3:6.2f} ms "
          f"(set-up {setup * 1e3:5.2f} ms, rest {(wall - solve - setup) * 1e3:5.2f} ms)")
    return wall, solve, setup


def parts(repeats: int) -> None:
    """The pieces of a call's overhead, each timed alone (best of ``repeats`` rounds of 50 calls)."""
    def best(call) -> float:
        return min(timeit.repeat(call, number=50, repeat=repeats)) / 50

    scenes = iter([dc.mechanisms.slider_crank("revolute", gravity=0.0, clearance=0.5e-3 * (1 + 1e-4 * i))
                   for i in range(50 * repeats + 1)])
    model = dc.assemble(next(scenes))
    atol = solve.tolerance_vector(model, 1e-7, None)

    def session():
        return open_session(model.functions, backend="c", rtol=1e-7, atol=atol, parameters=model.parameter_values)

    open_one = session()
    y0, _ = model.initial_state(session=open_one)
    onset = automaton.Decision(kind=automaton.ONSET, contact=True, held=False, latched=0.3, watch=-1)
    state = contact_state.start_state(model, 0.0, y0)
    active, params = contact_state.switches(model, state)
    result = dc.simulate(model, t_end=0.002, rtol=1e-7, save=dc.SaveAt(times=np.linspace(0.0, 0.002, 400)))
    # three output rows, their constraint drift set to 1 m: the checks take the drift warning's path,
    # which evaluates the constraints at the worst row to name the equation
    key = (result.t[:3], result.y[:3], {name: values[:3] for name, values in result.channels.items()}
           | {"constraints.position": np.ones(3)})
    rows = {
        "assemble a new scene": lambda: dc.assemble(next(scenes)),
        "open and close a session": lambda: session().close(),
        "initial state": lambda: model.initial_state(session=open_one),
        "physics checks, drift warned": lambda: physics.check_run(model, *key, None, {}, open_one),
        "record one contact switch": lambda: contact_state.switches(
            model, contact_state.with_decisions(model, state, [(0, onset)])),
        "switch vector": lambda: model.switch_vector(active, params),
        "Result of 400 points": lambda: dc.Result(
            t=result.t, y=result.y, yp=result.yp, state_names=result.state_names, channels=result.channels,
            units=result.units, events=result.events, segments=result.segments, stats=result.stats,
            parameters=result.parameters),
    }
    print("Pieces of the overhead, each alone (quiet loop)")
    for label, call in rows.items():
        print(f"  {label:<28} {best(call) * 1e6:8.1f} us")
    open_one.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--parts", action="store_true", help="also time the pieces of the overhead one by one")
    parser.add_argument("--write-doc", action="store_true", help="write the ratios into docs/engine.md")
    args = parser.parse_args()
    warnings.simplefilter("ignore", dc.DaeclearWarning)
    scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
    model = dc.assemble(scene)
    doc = ["| window | same Scene again | new numbers (a sweep) | pre-assembled model |", "|---|---:|---:|---:|"]
    for window, t_end in (("first 2 ms", 0.002), ("two revolutions", 2 * REV)):
        print(f"Fig. 4.15 scene, {window}, rtol 1e-7, 400 output points")
        cells = [measure("same scene", lambda i: scene, t_end, args.repeats),
                 measure("new numbers", lambda i: dc.mechanisms.slider_crank("revolute", gravity=0.0,
                                                                               clearance=0.5e-3 * (1 + 1e-3 * i)),
                         t_end, args.repeats),
                 measure("model", lambda i: model, t_end, args.repeats)]
        doc.append(f"| {window} | " + " | ".join(f"{(w - s) / s:.2f} (set-up {u / s:.2f})" for w, s, u in cells) + " |")
    if args.write_doc:
        import sys
        from pathlib import Path

        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_tables import write_block

        command = "python benchmarks/bench_overhead.py" + (f" --repeats {args.repeats}" if args.repeats != 20 else "")
        print(f"wrote {write_block('docs/engine.md', 'overhead', command, doc)}")
    if args.parts:
        parts(args.repeats)


if __name__ == "__main__":
    main()
