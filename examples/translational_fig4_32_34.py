"""Figs. 4.32-4.34: friction in the translational clearance joint, c_f = 0.01, 0.03, 0.05, 0.1.

Crank moment (Fig. 4.32), slider path (Fig. 4.33) and slider acceleration against velocity
(Fig. 4.34) at c = 0.5 mm with the modified Coulomb law (3.16) (v0 = 1e-4, v1 = 2e-4 m/s) at
every active corner; model ``corners``, Lankarani-Nikravesh c_e = 0.9 (Table 4.3).

Run ``python examples/translational_fig4_32_34.py`` (``--quick`` for a 5 ms smoke run).
"""

from __future__ import annotations

import argparse
import sys
from functools import partial
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import translational_common as tc  # noqa: E402
from daeclear.plot import plot_channel, plot_phase_portrait, plot_slider_path  # noqa: E402

CLEARANCE = 0.5e-3  # m
FRICTION = (0.01, 0.03, 0.05, 0.1)


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``translational_common.parse_args``."""
    return tc.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> tc.Study:
    """Simulate the ideal joint and the four friction coefficients."""
    scenes = {f"$c_f$ = {cf:g}": tc.scene(CLEARANCE, friction=cf) for cf in FRICTION}
    return tc.run_study("Figs. 4.32-4.34: friction, c = 0.5 mm, corners model, L-N c_e = 0.9", scenes, args)


def figures(study: tc.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    moment = partial(plot_channel, channel="drive.moment", label="clearance joint")
    return {
        "fig4_32.png": lambda: tc.panels(study, moment, "Fig. 4.32: driving crank moment",
                                         reference=study.ideal.window),
        "fig4_33.png": lambda: tc.panels(study, plot_slider_path, "Fig. 4.33: dimensionless slider path"),
        "fig4_34.png": lambda: tc.panels(study, plot_phase_portrait,
                                         "Fig. 4.34: slider acceleration against velocity (analysed span)",
                                         span=True, reference=study.ideal.window),
    }


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    study = run(args)
    tc.save_study(study, args)
    tc.save_figures(figures(study), args.out)
    tc.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
