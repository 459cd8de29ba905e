"""Events of the compiled and python backends on one slider-crank run with given storm constants.

    python benchmarks/storm_backends.py EVENTS WINDOW [revolute|translational] [T_END]

Small constants (e.g. ``4 5e-4 revolute``) make the storm guard hold and release pairs; the two
backends must report the same events (tests/test_automaton.py checks a few such runs).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

try:
    import daeclear  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import daeclear as dc  # noqa: E402
from daeclear.core.automaton import Storm  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("events", type=int, help="storm guard: switches ...")
    parser.add_argument("window", type=float, help="... within this many seconds hold the term on")
    parser.add_argument("joint", nargs="?", default="revolute", choices=("revolute", "translational"))
    parser.add_argument("t_end", nargs="?", type=float, default=0.012, help="end time, s")
    args = parser.parse_args()
    scene = (dc.mechanisms.slider_crank("revolute", gravity=0.0) if args.joint == "revolute"
             else dc.mechanisms.slider_crank("translational"))
    model = dc.assemble(scene)  # its contact rules are frozen: a model with other storm constants is a new value
    storm = Storm(args.events, args.window)
    contacts = tuple(dataclasses.replace(logic, storm=storm) for logic in model.contacts)
    model = dataclasses.replace(model, contacts=contacts)
    for backend in ("c", "python"):
        tic = time.perf_counter()
        r = dc.simulate(model, args.t_end, rtol=1e-8, on_failure="return", options=dc.SolverOptions(backend=backend))
        onsets = sum(e.kind == "onset" for e in r.events)
        print(f"{args.joint} {Storm(args.events, args.window)} {backend:6s}: success={r.success} "
              f"events={len(r.events)} onsets={onsets} steps={r.stats['n_steps']} "
              f"{time.perf_counter() - tic:.1f} s  {r.message}")


if __name__ == "__main__":
    main()
