"""Figs. 4.19-4.21: friction coefficient c_f = 0.01, 0.03, 0.05, 0.1 (revolute clearance joint).

Section 4.4's friction study: c = 0.5 mm, Lankarani-Nikravesh law (3.9) with c_e = 0.9 and the
modified Coulomb law (3.16) with daeclear's default thresholds v0 = 1e-4 m/s, v1 = 2e-4 m/s
(docs/contact_laws.md; the book's values are not known), sliding velocity from the
material points of journal and bearing, 5000 rpm, gravity 9.81 m/s^2, IDA at rtol 1e-6.
Transient and windows as in ``_common.py``.

Writes into ``--out`` (default ``results/revolute_friction_study/``):

- ``fig4_19_crank_moment.png``: crank moment for each friction coefficient, ideal joint dashed;
- ``fig4_20_journal_orbits.png``: journal centre relative to the bearing;
- ``fig4_21_phase_portraits.png``: slider acceleration against velocity over the analysed
  span, one red point per crank revolution;
- ``step_sizes.png``: IDA's step size, contact shaded;
- ``cf0.01.h5``, ``cf0.03.h5``, ``cf0.05.h5``, ``cf0.1.h5``, ``ideal.h5``: two revolutions;
- ``metrics.json``, ``metrics.md`` (the frictionless c = 0.5 mm case is in
  ``revolute_clearance_study``'s metrics, for comparison).

Run: ``python examples/revolute_friction_study.py`` (``--quick`` for a 5 ms smoke run).
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
from daeclear.contact import ModifiedCoulomb  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402

FRICTION = (0.01, 0.03, 0.05, 0.1)  # c_f (Figs. 4.19-4.21 a-d)
CLEARANCE = 0.5e-3  # m
RESTITUTION = 0.9
V0, V1 = 1e-4, 2e-4  # m/s, thresholds of the modified Coulomb law (3.16)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args``."""
    return cm.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> cm.Study:
    """Simulate the ideal joint and the four friction coefficients."""
    scenes = {f"$c_f$ = {cf:g}": (f"cf{cf:g}",
                                  slider_crank("revolute", clearance=CLEARANCE, restitution=RESTITUTION,
                                               friction=ModifiedCoulomb(coefficient=cf, v0=V0, v1=V1),
                                               gravity=cm.GRAVITY, rpm=cm.RPM))
              for cf in FRICTION}
    return cm.run_study("Figs. 4.19-4.21: friction, c = 0.5 mm, Lankarani-Nikravesh c_e = 0.9 + modified Coulomb",
                        scenes, args)


def figures(study: cm.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    return {
        "fig4_19_crank_moment.png": lambda: cm.channel_figure(
            study, "drive.moment", "Fig. 4.19: crank moment for different friction coefficients"),
        "fig4_20_journal_orbits.png": lambda: cm.orbit_figure(
            study, "Fig. 4.20: journal centre trajectory relative to the bearing"),
        "fig4_21_phase_portraits.png": lambda: cm.phase_figure(study,
                                                               "Fig. 4.21: slider acceleration against velocity"),
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
