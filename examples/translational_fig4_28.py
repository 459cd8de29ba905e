"""Fig. 4.28: slider-crank with a translational clearance joint, c = 0.5 mm (section 4.5).

Slider velocity, slider acceleration and crank moment against the ideal joint, and the
dimensionless slider path inside the guide with the contact limits (eta = +-0.5). Table 4.3:
50 x 50 x 50 mm steel slider, 1 mm corner radius, Lankarani-Nikravesh c_e = 0.9 with the
stiffness (3.5) of a corner sphere on a plane (model ``corners``), frictionless.

Run ``python examples/translational_fig4_28.py`` (``--quick`` for a 5 ms smoke run, ``--help``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import translational_common as tc  # noqa: E402
from daeclear.plot import plot_phase_portrait, plot_translational_response  # noqa: E402

CLEARANCE = 0.5e-3  # m, Table 4.3
RESTITUTION = 0.9


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``translational_common.parse_args``."""
    return tc.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> tc.Study:
    """Simulate the ideal joint and the clearance joint."""
    return tc.run_study(
        "Fig. 4.28: translational clearance joint, c = 0.5 mm, corners model, L-N c_e = 0.9, frictionless",
        {"c = 0.5 mm": tc.scene(CLEARANCE, restitution=RESTITUTION)}, args)


def _response_figure(study: tc.Study) -> Any:
    case = study.cases[0]
    fig = plot_translational_response(case.window, reference=study.ideal.window,
                                      title=tc.title_of("Fig. 4.28: slider-crank against the ideal joint",
                                                        case.window))
    fig.tight_layout()
    return fig


def _phase_figure(study: tc.Study) -> Any:
    case = study.cases[0]
    ax = plot_phase_portrait(case.dense, reference=study.ideal.window,
                             title=tc.title_of("Slider acceleration against velocity, analysed span", case.dense))
    ax.figure.tight_layout()
    return ax.figure


def figures(study: tc.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (titled with the run's parameters)."""
    return {"fig4_28.png": lambda: _response_figure(study), "phase_portrait.png": lambda: _phase_figure(study)}


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    study = run(args)
    tc.save_study(study, args)
    tc.save_figures(figures(study), args.out)
    tc.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
