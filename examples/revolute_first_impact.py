"""Fig. 4.26: the first impact for c_e = 1.00, 0.99, 0.95, 0.90 (Lankarani-Nikravesh law).

The slider-crank of section 4.4 (c = 0.5 mm, no friction, 5000 rpm, gravity 9.81 m/s^2, IDA at
rtol 1e-6) starts with the journal centred; the first contact closes at t = 0.23 ms. For each
c_e the full mechanism is simulated to 1 ms; the events give the first onset and separation,
and a second run of the same model with a fine ``t_eval`` (2001 points) between them gives the
contact force and penetration. The motion before the first contact does not depend on c_e, so
all four impacts start at the same time with the same approach speed.

Writes into ``--out`` (default ``results/revolute_first_impact/``):

- ``fig4_26_first_impact.png``: (a) contact force against time, (b) force against
  penetration (hysteresis loops; none for c_e = 1, the pure Hertz law);
- ``first_impact_ce1.00.h5``, ... ``first_impact_ce0.90.h5``: the first impact, 2001 points;
- ``metrics.json``, ``metrics.md``: approach and separation speed, their ratio (the
  effective restitution in the mechanism), peak force, maximum penetration, duration and the
  energy dissipated (area of the loop).

Run: ``python examples/revolute_first_impact.py`` (``--quick`` runs the same: it is short).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

import matplotlib

matplotlib.use("Agg")

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import _common as cm  # noqa: E402
import daeclear as dc  # noqa: E402
from daeclear.plot import style  # noqa: E402
from daeclear.contact import ImpactResult  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402
from daeclear.plot import plot_force_penetration, plot_force_time  # noqa: E402

RESTITUTIONS = (1.00, 0.99, 0.95, 0.90)  # c_e (Fig. 4.26)
CLEARANCE = 0.5e-3  # m
T_END = 1e-3  # s: the first impact is over by 0.28 ms
N_POINTS = 2001  # output points over the first impact


def first_impacts(restitutions: Sequence[float], rtol: float, jobs: int) -> list[tuple[dc.Result, ImpactResult]]:
    """The mechanism's first impact for each c_e: a Result (fine output) and an ImpactResult for the plot helpers."""
    scenes = [slider_crank("revolute", clearance=CLEARANCE, restitution=ce, gravity=cm.GRAVITY, rpm=cm.RPM)
              for ce in restitutions]
    runs = cm.parallel_map(cm.first_impact, [(scene, rtol, T_END, N_POINTS) for scene in scenes], jobs)
    out = []
    for scene, (impact, onset, separation) in zip(scenes, runs):
        t = impact.t - onset.t
        delta = np.asarray(impact["clearance.penetration"])
        force = np.asarray(impact["clearance.normal_force"])
        k = int(np.argmax(delta))
        summary = ImpactResult(
            t=t, penetration=delta, rate=np.asarray(impact["clearance.penetration_rate"]), force=force,
            law=scene[cm.PAIR].law,  # as given (unresolved): the plot helpers only use it for labels
            mass=float("nan"), entry_speed=onset.approach_speed, exit_speed=-separation.approach_speed,
            max_penetration=float(delta[k]), time_of_max_penetration=float(t[k]), peak_force=float(force.max()),
            duration=separation.t - onset.t)
        out.append((impact, summary))
    return out


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The common options of ``_common.parse_args`` (``--quick`` changes nothing: the run is short)."""
    return cm.parse_args(__file__, __doc__.splitlines()[0], argv)


@dataclass
class Impacts:
    """The first impact of every c_e: label -> fine Result, label -> ImpactResult, and the measured rows."""

    results: dict[str, dc.Result]
    impacts: dict[str, ImpactResult]
    rows: list[dict[str, Any]]


def run(args: argparse.Namespace) -> Impacts:
    """Simulate the first impact for every c_e and measure it."""
    print(f"Fig. 4.26: first impact, c = {CLEARANCE * 1e3:g} mm, Lankarani-Nikravesh, frictionless, "
          f"gravity {cm.GRAVITY} m/s^2, rtol {args.rtol:g}", flush=True)
    out = Impacts({}, {}, [])
    for ce, (result, imp) in zip(RESTITUTIONS, first_impacts(RESTITUTIONS, args.rtol, args.jobs)):
        label = f"$c_e$ = {ce:.2f}"
        out.results[label], out.impacts[label] = result, imp
        loop = float(np.trapezoid(imp.force, imp.penetration))  # J: area of the loop = energy dissipated
        out.rows.append({"case": label, "onset_ms": float(result.t[0] * 1e3), "entry_speed_m_s": imp.entry_speed,
                         "exit_speed_m_s": imp.exit_speed, "effective_restitution": imp.restitution,
                         "peak_force_N": imp.peak_force, "max_penetration_um": imp.max_penetration * 1e6,
                         "duration_us": imp.duration * 1e6, "dissipated_J": loop})
        print(f"  {label:<16s} onset {result.t[0] * 1e3:.4f} ms, {imp.entry_speed:.3f} -> {imp.exit_speed:.3f} m/s "
              f"(ratio {imp.restitution:.4f}), peak {imp.peak_force:.0f} N, max penetration "
              f"{imp.max_penetration * 1e6:.2f} um, {imp.duration * 1e6:.1f} us, loop {loop:.4f} J", flush=True)
    return out


def impact_figure(data: Impacts) -> Any:
    """Fig. 4.26 (a) force against time, (b) force against penetration; c_e in the legend, the rest in the title."""
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11.0, 4.6))
    plot_force_time(data.impacts, ax=left)
    style.set_title(left, "(a) contact force against time")
    plot_force_penetration(data.impacts, ax=right)
    style.set_title(right, "(b) force against penetration")
    style.set_title(fig, cm.title_of("Fig. 4.26: first impact of the slider-crank", list(data.results.values())))
    fig.tight_layout()
    return fig


def figures(data: Impacts) -> dict[str, Callable[[], Any]]:
    """File name -> function drawing that figure."""
    return {"fig4_26_first_impact.png": lambda: impact_figure(data)}


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    data = run(args)
    for ce, result in zip(RESTITUTIONS, data.results.values()):
        cm.save_result(result, args.out, f"first_impact_ce{ce:.2f}")
    for name, draw in figures(data).items():
        cm.save_figure(draw(), args.out / name)
    rows = data.rows

    columns = (("case", "case", "{}"), ("entry_speed_m_s", "approach speed (m/s)", "{:.3f}"),
               ("exit_speed_m_s", "separation speed (m/s)", "{:.3f}"),
               ("effective_restitution", "ratio", "{:.4f}"), ("peak_force_N", "peak force (N)", "{:.0f}"),
               ("max_penetration_um", "max penetration (µm)", "{:.2f}"), ("duration_us", "duration (µs)", "{:.1f}"),
               ("dissipated_J", "loop area (J)", "{:.4f}"))
    header = "Fig. 4.26: first impact, c = 0.5 mm, Lankarani-Nikravesh"
    (args.out / "metrics.json").write_text(json.dumps({"about": header, "rtol": args.rtol, "cases": rows}, indent=1))
    (args.out / "metrics.md").write_text(f"# {header}\n\n{cm.markdown_table(rows, columns)}\n")
    print(cm.markdown_table(rows, columns))
    cm.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
