"""Fig. 4.15: slider-crank with a revolute clearance joint, c = 0.5 mm, against the ideal joint.

The chapter's reference case (section 4.4, Tables 4.1-4.2): crank at 5000 rpm, journal (rod)
in a bearing (slider) of radius 10 mm with radial clearance 0.5 mm, steel (207 GPa, 0.3),
Lankarani-Nikravesh law (3.9) with c_e = 0.9, no friction, gravity 9.81 m/s^2, IDA at
rtol 1e-6. Two crank revolutions after the transient (see ``_common.py``).

Writes into ``--out`` (default ``results/revolute_fig4_15/``):

- ``fig4_15.png``: (a) slider velocity, (b) slider acceleration, (c) crank moment, each with
  the ideal joint dashed, (d) journal centre relative to the bearing, one marker per IDA step,
  clearance circle dashed;
- ``step_sizes.png``: IDA's step size over the two revolutions and around one impact,
  contact intervals shaded;
- ``revolutions.png``: impacts and peak crank moment in each analysed revolution (not with
  ``--quick``): the response is intermittent, two revolutions are one draw from it;
- ``revolute_c0.5mm.h5``, ``ideal.h5``: the two revolutions, dense output;
- ``metrics.json``, ``metrics.md``.

Run: ``python examples/revolute_fig4_15.py`` (``--quick`` for a 5 ms smoke run).
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
from daeclear.plot import style  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402
from daeclear.plot import plot_revolute_response, plot_step_sizes  # noqa: E402

CLEARANCE = 0.5e-3  # m (Fig. 4.15)
RESTITUTION = 0.9  # Table 4.2


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args``."""
    return cm.parse_args(__file__, __doc__.splitlines()[0], argv)


def run(args: argparse.Namespace) -> cm.Study:
    """Simulate the clearance joint and the ideal joint; a study of one case."""
    span = cm.make_span(args)
    print(f"Fig. 4.15: c = {CLEARANCE * 1e3:g} mm, Lankarani-Nikravesh c_e = {RESTITUTION}, frictionless, "
          f"gravity {cm.GRAVITY} m/s^2; {span.describe()}")
    ideal, case = cm.run_cases({"ideal joint": cm.ideal_scene(),
                                "c = 0.5 mm": slider_crank("revolute", clearance=CLEARANCE, restitution=RESTITUTION,
                                                           gravity=cm.GRAVITY, rpm=cm.RPM)}, span, args)
    return cm.Study("Fig. 4.15: revolute clearance joint, c = 0.5 mm", span, ideal, [case],
                    [cm.measure(case, ideal, span)])


def _response_figure(study: cm.Study) -> Any:
    """Fig. 4.15 (a)-(d), titled with the run's parameters."""
    case = study.cases[0]
    return plot_revolute_response(case.window, reference=study.ideal.window, orbit=case.steps_window,
                                  title=cm.title_of("Fig. 4.15: slider-crank against the ideal joint", case.window))


def figures(study: cm.Study) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure (``revolutions.png`` only for a full run)."""
    out: dict[str, Callable[[], Any]] = {"fig4_15.png": lambda: _response_figure(study),
                                         "step_sizes.png": lambda: _step_figure(study.cases[0])}
    if not study.span.quick:
        out["revolutions.png"] = lambda: _revolution_figure(study.cases[0], study.span)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    study = run(args)
    for name, draw in figures(study).items():
        cm.save_figure(draw(), args.out / name)
    case, ideal = study.cases[0], study.ideal
    cm.save_result(case.window, args.out, "revolute_c0.5mm")
    cm.save_result(ideal.window, args.out, "ideal")
    cm.write_metrics(study.rows, args.out, study.span, study.header, args.rtol)
    cm.print_written(args.out)
    return 0


def _step_figure(case: cm.Case):
    """Step sizes over the plotted window, and zoomed on the last impact of the analysed span."""
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 6.4))
    fig.suptitle(cm.title_of("IDA step size", case.window), fontsize=style.TITLE_SIZE)
    plot_step_sizes(case.steps_window, ax=top, pair=cm.PAIR)
    top.set_title("(a) IDA step size over the two revolutions, contact shaded", fontsize=style.TITLE_SIZE)
    onsets = case.steps.events.of(cm.PAIR, "onset").t
    if onsets.size:
        t0 = float(onsets[-1])
        zoom = case.steps.slice(max(float(case.steps.t[0]), t0 - 3e-4), min(float(case.steps.t[-1]), t0 + 6e-4))
        plot_step_sizes(zoom, ax=bottom, pair=cm.PAIR)
        bottom.set_title(f"(b) around the impact at t = {t0:.5f} s", fontsize=style.TITLE_SIZE)
    else:
        bottom.set_visible(False)
    fig.tight_layout()
    return fig


def _revolution_figure(case: cm.Case, span: cm.Span):
    """Impacts and peak crank moment in every analysed revolution (how intermittent the response is)."""
    import matplotlib.pyplot as plt
    import numpy as np

    edges = span.revolution_times
    n_imp, peak = [], []
    onsets = case.dense.events.of(cm.PAIR, "onset").t
    for a, b in zip(edges[:-1], edges[1:]):
        n_imp.append(int(np.sum((onsets >= a) & (onsets < b))))
        inside = (case.dense.t >= a) & (case.dense.t <= b)
        peak.append(float(np.max(np.abs(case.dense["drive.moment"][inside]))))
    rev = np.arange(len(n_imp)) + round(edges[0] / cm.PERIOD) + 1
    from matplotlib.ticker import MaxNLocator
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 5.4), sharex=True)
    fig.suptitle(cm.title_of("Impacts and peak crank moment in every revolution", case.window),
                 fontsize=style.TITLE_SIZE)
    top.bar(rev, n_imp, color="C0")
    top.set_ylabel("impacts")
    bottom.bar(rev, peak, color="C1")
    bottom.set_ylabel("peak |crank moment| (N m)")
    bottom.set_xlabel("crank revolution")
    bottom.xaxis.set_major_locator(MaxNLocator(integer=True))
    top.set_title("every analysed revolution (the figures show the last two)", fontsize=style.TITLE_SIZE)
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    sys.exit(main())
