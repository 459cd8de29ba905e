"""How closely the compiler-less fallback (scikit-sundae, python backend) follows the compiled loop.

    python benchmarks/bench_backend_agreement.py [T_END] [RTOL ...]

The chapter's revolute slider-crank (0.5 mm, Lankarani-Nikravesh, 5000 rpm) run on both backends at
each rtol, in one process: impacts (contact onsets), the first onset times, and the largest
difference of the slider velocity on a common grid. The two backends integrate the same equations
with the same IDA but not the same step sequence (different Jacobian refresh and first step, dense
vs reduced LU), so their trajectories differ by about the integration error; a contact sequence
is sensitive to it (an impact a little earlier changes every later one), so at a loose rtol the
two runs drift apart, and they agree as rtol tightens. docs/reliability.md quotes its output.
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

try:
    import daeclear  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402


def main() -> None:
    args = sys.argv[1:]
    t_end = float(args[0]) if args else 0.024
    rtols = [float(a) for a in args[1:]] or [1e-6, 1e-8, 1e-9]
    scene = dc.mechanisms.slider_crank("revolute")
    grid = np.linspace(0.0, t_end, 2001)
    print(f"slider-crank, revolute clearance 0.5 mm, t_end = {t_end:g} s")
    print("rtol    | impacts c / python | first 5 onsets differ by (s) | max |dvx| (m/s) | wall c / python (s)")
    for rtol in rtols:
        runs = {}
        for backend in ("c", "python"):
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                runs[backend] = dc.simulate(scene, t_end, rtol=rtol, options=dc.SolverOptions(backend=backend),
                                            save=dc.SaveAt(times=grid))
            runs[backend].stats["wall"] = time.perf_counter() - start
        onsets = {b: r.events.of("clearance", kind="onset").t for b, r in runs.items()}
        k = min(5, onsets["c"].size, onsets["python"].size)
        first = float(np.max(np.abs(onsets["c"][:k] - onsets["python"][:k]))) if k else float("nan")
        dvx = float(np.max(np.abs(runs["c"]["slider.vx"] - runs["python"]["slider.vx"])))
        print(f"{rtol:<7g} | {onsets['c'].size:>9} / {onsets['python'].size:<6} | {first:>28.3g} | {dvx:>14.3g} | "
              f"{runs['c'].stats['wall']:.2f} / {runs['python'].stats['wall']:.2f}")


if __name__ == "__main__":
    main()
