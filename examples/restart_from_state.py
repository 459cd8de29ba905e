"""Continue a run from a state of it, with a changed setting: the second revolution at a tighter tolerance.

The chapter's slider-crank with a 0.5 mm revolute clearance joint at the rod-slider pin (Table 4.2,
Lankarani-Nikravesh, c_e = 0.9) runs its first crank revolution at rtol 1e-6. The second revolution
is wanted at rtol 1e-9: instead of running everything again, the run continues from a state of the
first one with ``simulate(model, t_end, t0=..., y0=..., options=options.replace(rtol=1e-9))``.

The restart is taken in free flight (the middle of the last flight of the journal before the end
of the first revolution): a pair restarted in contact has its mode set from the gap, but the
approach speed latched at its onset (which scales the contact damping) is run history, not state;
in free flight nothing is lost. The script prints the restart time, the contact events of both
parts, how far the continued run is from one that ran the whole way at rtol 1e-9 (they differ by
the first revolution's rtol 1e-6 error, carried through the impacts) and, as a check of the
restart itself, how far a continuation at rtol 1e-6 is from one run at rtol 1e-6.

Run: ``python examples/restart_from_state.py`` (about 1 s, plus compiling on an empty cache);
``--quick`` for a shorter run.

Measured: restart at t = 0.011844 s in free flight; 46 events before it, 3 after it (51 in all at
rtol 1e-9 throughout); the continued run is 4.4e-4 m (0.0043 of the stroke) from the run at rtol
1e-9 throughout, and the continuation at rtol 1e-6 is 2.2e-7 m (2.2e-6 of the stroke) from the
single run at rtol 1e-6.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

import numpy as np

import daeclear as dc

REVOLUTION = 60.0 / 5000.0  # s, one crank turn at 5000 rpm


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="half revolutions (smoke test)")
    args = parser.parse_args(argv)
    span = REVOLUTION / 2 if args.quick else REVOLUTION

    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    options = dc.SolverOptions(rtol=1e-6)
    first = dc.simulate(model, span, options=options, save=dc.SaveAt(every=span / 1000))

    # the middle of the last free flight of the first part, on its output grid
    flights = [(a, b) for a, b, modes in first.segments if modes["clearance"] == "free" and b - a > 1e-5]
    if not flights:
        print("no free flight in the first part: nothing to restart from")
        return 1
    a, b = flights[-1]
    row = int(np.argmin(np.abs(first.t - 0.5 * (a + b))))
    t0, y0 = float(first.t[row]), first.y[row]

    tight = options.replace(rtol=1e-9)
    second = dc.simulate(model, 2 * span, t0=t0, y0=y0, options=tight, save=dc.SaveAt(every=span / 1000))
    whole = dc.simulate(model, 2 * span, options=tight, save=dc.SaveAt(times=second.t))

    # the restart itself: continued at the first part's settings, against one run at those settings
    same = dc.simulate(model, 2 * span, t0=t0, y0=y0, options=options, save=dc.SaveAt(every=span / 1000))
    single = dc.simulate(model, 2 * span, options=options, save=dc.SaveAt(times=same.t))

    before = sum(e.t <= t0 for e in first.events)
    stroke = float(np.ptp(whole["slider.x"]))
    gap = float(np.max(np.abs(second["slider.x"] - whole["slider.x"])))
    restart_gap = float(np.max(np.abs(same["slider.x"] - single["slider.x"])))
    print(f"restart at t = {t0:.6f} s in free flight, from rtol {options.rtol:g} to rtol {tight.rtol:g}")
    print(f"contact events: {before} before the restart, {len(second.events)} after it "
          f"(the run at rtol {tight.rtol:g} throughout: {len(whole.events)} in all)")
    print(f"slider x of the continued run against the run at rtol {tight.rtol:g} throughout: "
          f"{gap:.2g} m ({gap / stroke:.2g} of the stroke: the first part's rtol {options.rtol:g} error)")
    print(f"the restart alone (continued at rtol {options.rtol:g}, against one run at it): "
          f"{restart_gap:.2g} m ({restart_gap / stroke:.2g} of the stroke)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
