"""Figs. 4.16-4.18: clearance size c = 0.5, 0.2, 0.1, 0.01 mm (revolute clearance joint).

Section 4.4's clearance study: Lankarani-Nikravesh law (3.9) with c_e = 0.9, no friction,
bearing radius 10 mm (the journal radius is 10 mm - c, so the stiffness K of eq. 3.5 grows as c
shrinks: 6.61e10, 1.06e11, 1.51e11, 4.79e11 N/m^1.5), 5000 rpm, gravity 9.81 m/s^2, IDA at
rtol 1e-6. Transient and windows as in ``_common.py``.

Writes into ``--out`` (default ``results/revolute_clearance_study/``):

- ``fig4_16_crank_moment.png``: crank moment for each clearance, ideal joint dashed;
- ``fig4_17_journal_orbits.png``: journal centre relative to the bearing, clearance circle dashed;
- ``fig4_18_phase_portraits.png``: slider acceleration against velocity (the chapter's
  "Poincaré maps") over the analysed span, with one red point per crank revolution;
- ``step_sizes.png``: IDA's step size, contact shaded;
- ``c0.5mm.h5``, ``c0.2mm.h5``, ``c0.1mm.h5``, ``c0.01mm.h5``, ``ideal.h5``: two revolutions;
- ``metrics.json``, ``metrics.md``.

Run: ``python examples/revolute_clearance_study.py`` (``--quick`` for a 5 ms smoke run).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

import matplotlib

matplotlib.use("Agg")

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common as cm  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402

CLEARANCES = (0.5e-3, 0.2e-3, 0.1e-3, 0.01e-3)  # m (Figs. 4.16-4.18 a-d)
RESTITUTION = 0.9


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args``."""
    return cm.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> cm.Study:
    """Simulate the ideal joint and the four clearances."""
    scenes = {f"c = {c * 1e3:g} mm": (f"c{c * 1e3:g}mm",
                                      slider_crank("revolute", clearance=c, restitution=RESTITUTION,
                                                   gravity=cm.GRAVITY, rpm=cm.RPM))
              for c in CLEARANCES}
    return cm.run_study("Figs. 4.16-4.18: clearance size, Lankarani-Nikravesh c_e = 0.9, frictionless",
                        scenes, args)


def figures(study: cm.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    return {
        "fig4_16_crank_moment.png": lambda: cm.channel_figure(study, "drive.moment",
                                                              "Fig. 4.16: crank moment for different clearances"),
        "fig4_17_journal_orbits.png": lambda: cm.orbit_figure(
            study, "Fig. 4.17: journal centre trajectory relative to the bearing"),
        "fig4_18_phase_portraits.png": lambda: cm.phase_figure(study,
                                                               "Fig. 4.18: slider acceleration against velocity"),
        "step_sizes.png": lambda: cm.step_figure(study, "IDA step size, contact shaded"),
    }


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    study = run(args)
    for name, draw in figures(study).items():
        cm.save_figure(draw(), args.out / name)
    cm.save_study(study, args.out, args.rtol)
    cm.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
