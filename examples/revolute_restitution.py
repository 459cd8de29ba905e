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

import sys
from pathlib import Path
from typing import Sequence

import matplotlib

matplotlib.use("Agg")

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common as cm  # noqa: E402
from daeclear.mechanisms import slider_crank  # noqa: E402

RESTITUTIONS = (1.00, 0.99, 0.95, 0.90)  # c_e (Fig. 4.25 a-d)
CLEARANCE = 0.5e-3  # m


def main(argv: Sequence[str] | None = None) -> int:
    args = cm.parse_args(__file__, __doc__.splitlines()[0], argv)
    scenes = {f"$c_e$ = {ce:.2f}": (f"ce{ce:.2f}",
                                    slider_crank("revolute", clearance=CLEARANCE, restitution=ce,
                                                 gravity=cm.GRAVITY, rpm=cm.RPM))
              for ce in RESTITUTIONS}
    study = cm.run_study("Fig. 4.25: restitution, c = 0.5 mm, Lankarani-Nikravesh, frictionless", scenes, args)
    cm.save_figure(cm.channel_figure(study, "drive.moment", "Fig. 4.25: crank moment for different coefficients "
                                     "of restitution"), args.out / "fig4_25_crank_moment.png")
    cm.save_figure(cm.channel_figure(study, "clearance.normal_force", "Contact force for different coefficients "
                                     "of restitution", reference=False), args.out / "fig4_25_contact_force.png")
    cm.save_figure(cm.orbit_figure(study, "Journal centre trajectory relative to the bearing"),
                   args.out / "journal_orbits.png")
    cm.save_figure(cm.step_figure(study, "IDA step size, contact shaded"), args.out / "step_sizes.png")
    cm.save_study(study, args.out, args.rtol)
    cm.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
