"""Figs. 4.35-4.36: contact model of the translational clearance joint, c = 0.5 mm, frictionless.

(a) model ``corners``: every touching corner a sphere of radius 1 mm on a plane,
Lankarani-Nikravesh (3.9) with c_e = 0.9; (b) model ``section-4.3``: a face in contact (two
adjacent corners) on Lankarani's linear law for two plane surfaces (4.26) with the stiffness
(4.27) on the average penetration, applied at the centroid of the penetrated area; a single
corner still on (3.9). Contact force between slider and guide (Fig. 4.35, total over the
pairs, at every IDA step) and driving crank moment (Fig. 4.36).

Run ``python examples/translational_fig4_35_36.py`` (``--quick`` for a 5 ms smoke run).
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
from daeclear.plot import plot_channel  # noqa: E402

CLEARANCE = 0.5e-3  # m


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``translational_common.parse_args``."""
    return tc.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> tc.Study:
    """Simulate the ideal joint and the two contact models."""
    scenes = {
        "Lankarani-Nikravesh (corners)": tc.scene(CLEARANCE, restitution=0.9, contact_model="corners"),
        "linear plane law (section-4.3)": tc.scene(CLEARANCE, restitution=0.9, contact_model="section-4.3",
                                                   face_law="lankarani-plane"),
    }
    return tc.run_study("Figs. 4.35-4.36: contact force model, c = 0.5 mm, frictionless", scenes, args)


def figures(study: tc.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titles: what it shows and the shared parameters)."""
    moment = partial(plot_channel, channel="drive.moment", label="clearance joint")
    return {
        "fig4_35.png": lambda: tc.panels(study, partial(plot_channel, channel=f"{tc.JOINT}.normal_force"),
                                         "Fig. 4.35: contact force between slider and guide (every IDA step)",
                                         dense=False, ncols=1, panel_size=(8.0, 2.6)),
        "fig4_36.png": lambda: tc.panels(study, moment, "Fig. 4.36: driving crank moment",
                                         reference=study.ideal.window, ncols=1, panel_size=(8.0, 2.6)),
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
