"""Figs. 4.29-4.31: clearance size in the translational clearance joint, c = 0.5, 0.2, 0.1, 0.01 mm.

Crank moment (Fig. 4.29), dimensionless slider path (Fig. 4.30) and the chapter's "Poincaré
maps", slider acceleration against velocity (Fig. 4.31), for four clearances; model
``corners``, Lankarani-Nikravesh c_e = 0.9, frictionless (Table 4.3).

Run ``python examples/translational_fig4_29_31.py`` (``--quick`` for a 5 ms smoke run).
"""

from __future__ import annotations

import sys
from functools import partial
from pathlib import Path
from typing import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import translational_common as tc  # noqa: E402
from daeclear.plot import plot_cases, plot_channel, plot_phase_portrait, plot_slider_path  # noqa: E402

CLEARANCES = (0.5e-3, 0.2e-3, 0.1e-3, 0.01e-3)  # m


def main(argv: Sequence[str] | None = None) -> int:
    args = tc.parse_args(__file__, __doc__.splitlines()[0], argv)
    scenes = {f"c = {c * 1e3:g} mm": tc.scene(c) for c in CLEARANCES}
    study = tc.run_study("Figs. 4.29-4.31: clearance size, corners model, L-N c_e = 0.9, frictionless", scenes, args)
    ref = study.ideal.window
    tc.save_figure(tc.panels(study, partial(plot_channel, channel="drive.moment"),
                             "Fig. 4.29: driving crank moment", reference=ref), args.out / "fig4_29.png")
    tc.save_figure(tc.panels(study, plot_slider_path, "Fig. 4.30: dimensionless slider path"),
                   args.out / "fig4_30.png")
    dense = {case.label: case.dense for case in study.cases}
    tc.save_figure(plot_cases(dense, plot_phase_portrait, reference=study.ideal.window,
                              suptitle="Fig. 4.31: slider acceleration against velocity (analysed span)"),
                   args.out / "fig4_31.png")
    tc.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
