"""Figs. 4.29-4.31: clearance size in the translational clearance joint, c = 0.5, 0.2, 0.1, 0.01 mm.

Crank moment (Fig. 4.29), dimensionless slider path (Fig. 4.30) and the chapter's "Poincaré
maps", slider acceleration against velocity (Fig. 4.31), for four clearances; model
``corners``, Lankarani-Nikravesh c_e = 0.9, frictionless (Table 4.3).

Run ``python examples/translational_fig4_29_31.py`` (``--quick`` for a 5 ms smoke run).
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

CLEARANCES = (0.5e-3, 0.2e-3, 0.1e-3, 0.01e-3)  # m


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``translational_common.parse_args``."""
    return tc.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> tc.Study:
    """Simulate the ideal joint and the four clearances."""
    scenes = {f"c = {c * 1e3:g} mm": tc.scene(c) for c in CLEARANCES}
    return tc.run_study("Figs. 4.29-4.31: clearance size, corners model, L-N c_e = 0.9, frictionless", scenes, args)


def figures(study: tc.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    moment = partial(plot_channel, channel="drive.moment", label="clearance joint")
    return {
        "fig4_29.png": lambda: tc.panels(study, moment, "Fig. 4.29: driving crank moment",
                                         reference=study.ideal.window),
        "fig4_30.png": lambda: tc.panels(study, plot_slider_path, "Fig. 4.30: dimensionless slider path"),
        "fig4_31.png": lambda: tc.panels(study, plot_phase_portrait,
                                         "Fig. 4.31: slider acceleration against velocity (analysed span)",
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
