"""Fig. 4.28: slider-crank with a translational clearance joint, c = 0.5 mm (section 4.5).

Slider velocity, slider acceleration and crank moment against the ideal joint, and the
dimensionless slider path inside the guide with the contact limits (eta = +-0.5). Table 4.3:
50 x 50 x 50 mm steel slider, 1 mm corner radius, Lankarani-Nikravesh c_e = 0.9 with the
stiffness (3.5) of a corner sphere on a plane (model ``corners``), frictionless.

Run ``python examples/translational_fig4_28.py`` (``--quick`` for a 5 ms smoke run, ``--help``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import translational_common as tc  # noqa: E402
from daeclear.plot import plot_phase_portrait, plot_translational_response  # noqa: E402

CLEARANCE = 0.5e-3  # m, Table 4.3
RESTITUTION = 0.9


def main(argv: Sequence[str] | None = None) -> int:
    args = tc.parse_args(__file__, __doc__.splitlines()[0], argv)
    study = tc.run_study(
        "Fig. 4.28: translational clearance joint, c = 0.5 mm, corners model, L-N c_e = 0.9, frictionless",
        {"c = 0.5 mm": tc.scene(CLEARANCE, restitution=RESTITUTION)}, args)
    case, ideal = study.cases[0], study.ideal
    fig = plot_translational_response(case.window, reference=ideal.window)
    fig.suptitle("Fig. 4.28: translational clearance joint, c = 0.5 mm, L-N $c_e$ = 0.9", fontsize="medium")
    fig.tight_layout()
    tc.save_figure(fig, args.out / "fig4_28.png")
    ax = plot_phase_portrait(case.dense, reference=ideal.window)
    ax.set_title("slider acceleration against velocity, analysed span", fontsize="medium")
    tc.save_figure(ax.figure, args.out / "phase_portrait.png")
    tc.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
