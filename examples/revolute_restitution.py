"""Fig. 4.25: coefficient of restitution c_e = 1.00, 0.99, 0.95, 0.90 (Lankarani-Nikravesh law).

Section 4.4's restitution study: c = 0.5 mm, Lankarani-Nikravesh law (3.9) with hysteresis factor
3(1 - c_e^2)/4 = 0, 0.0149, 0.0731, 0.1425 (c_e = 1 is the pure Hertz law), no friction,
5000 rpm, gravity 9.81 m/s^2, IDA at rtol 1e-6. Transient and windows as in ``_common.py``.

Writes into ``--out`` (default ``results/revolute_restitution/``):

- ``fig4_25_crank_moment.png``: crank moment for each c_e, ideal joint dashed;
- ``fig4_25_contact_force.png``, ``journal_orbits.png``: contact force and journal orbits (not in
  the chapter; they show where the moment peaks come from);
- ``step_sizes.png``: IDA's step size, contact shaded;
- ``ce1.00.h5``, ``ce0.99.h5``, ``ce0.95.h5``, ``ce0.90.h5``, ``ideal.h5``: two revolutions;
- ``metrics.json``, ``metrics.md``.

Run: ``python examples/revolute_restitution.py`` (``--quick`` for a 5 ms smoke run).
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

RESTITUTIONS = (1.00, 0.99, 0.95, 0.90)  # c_e (Fig. 4.25 a-d)
CLEARANCE = 0.5e-3  # m


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args``."""
    return cm.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> cm.Study:
    """Simulate the ideal joint and the four coefficients of restitution."""
    scenes = {f"$c_e$ = {ce:.2f}": (f"ce{ce:.2f}",
                                    slider_crank("revolute", clearance=CLEARANCE, restitution=ce,
                                                 gravity=cm.GRAVITY, rpm=cm.RPM))
              for ce in RESTITUTIONS}
    return cm.run_study("Fig. 4.25: restitution, c = 0.5 mm, Lankarani-Nikravesh, frictionless", scenes, args)


def figures(study: cm.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    return {
        "fig4_25_crank_moment.png": lambda: cm.channel_figure(
            study, "drive.moment", "Fig. 4.25: crank moment for different coefficients of restitution"),
        "fig4_25_contact_force.png": lambda: cm.channel_figure(
            study, "clearance.normal_force", "Contact force for different coefficients of restitution",
            reference=False),
        "journal_orbits.png": lambda: cm.orbit_figure(study, "Journal centre trajectory relative to the bearing"),
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
