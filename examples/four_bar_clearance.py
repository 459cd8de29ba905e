"""Multi-clearance studies: a four-bar with clearance at one, two and three joints, and the
slider-crank with clearance in both its revolute and its translational joint, each against its
ideal mechanism.

Every clearance joint is made with ``Scene.with_clearance`` from the ideal mechanism's joint (the
ready ``mechanisms.four_bar(clearance_joints=...)`` does the same), and every run starts as the
chapter's (section 4.4): journals centred, sliders on their guide's mid-line, velocities from
the ideal mechanism. Crank at 5000 rpm, 0.5 mm clearances, Lankarani-Nikravesh with c_e = 0.9,
no friction, IDA at rtol 1e-6.

Writes into ``--out`` (default ``results/four_bar_clearance/``):

- ``four_bar_clearance.png``: (a) the four-bar's crank moment, ideal (dashed) and with clearance
  at C, at B and C, at B, C and D; (b)-(d) the journal orbit of each clearance joint of the
  three-joint case;
- ``slider_crank_two_clearances.png``: the slider-crank with clearance at C (revolute) and D
  (translational): crank moment and slider velocity against the ideal mechanism, the journal
  orbit and the slider path;
- ``metrics.md``: per case, the peak crank moment (and its ratio to the ideal one), the peak
  contact force of each clearance joint, the number of impacts and the run time.

Run: ``python examples/four_bar_clearance.py [--out DIR] [--revolutions N] [--quick]``
(``--quick``: half a revolution, for smoke tests).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.model import mechanisms  # noqa: E402
from daeclear.plot import plot_channel, plot_journal_orbit, plot_run  # noqa: E402

RPM = 5000.0
PERIOD = 60.0 / RPM  # s per crank revolution
CLEARANCE = 0.5e-3  # m, every clearance joint
RTOL = 1e-6
FOUR_BAR_CASES = (("C",), ("B", "C"), ("B", "C", "D"))


def run(scene: dc.Scene, t_end: float) -> tuple[dc.Result, float]:
    """Simulate on a uniform grid (2 us); the wall time includes assembly and any compilation."""
    start = time.perf_counter()
    result = dc.simulate(scene, t_end, rtol=RTOL,
                         progress=False, save=dc.SaveAt(times=np.linspace(0.0, t_end, int(round(t_end / 2e-6)) + 1)))
    return result, time.perf_counter() - start


def metrics(label: str, result: dc.Result, ideal: dc.Result, wall: float) -> str:
    """One markdown row: peak crank moment, peak contact force per clearance joint, impacts, time."""
    from daeclear.plot import clearance_joints

    peak = float(np.max(np.abs(result["drive.moment"])))
    peak_ideal = float(np.max(np.abs(ideal["drive.moment"])))
    forces = ", ".join(f"{j} {np.max(result[f'{j}.normal_force']) / 1e3:.1f} kN" for j in clearance_joints(result))
    impacts = len(result.events.of(kind="onset"))
    return f"| {label} | {peak:.1f} | {peak / peak_ideal:.1f} | {forces} | {impacts} | {wall:.2f} |"


def four_bar_study(t_end: float, out: Path) -> list[str]:
    ideal, wall = run(mechanisms.four_bar(), t_end)
    rows = [metrics("four-bar, ideal", ideal, ideal, wall)]
    runs = {}
    for joints in FOUR_BAR_CASES:
        runs[joints], wall = run(mechanisms.four_bar(joints, clearance=CLEARANCE), t_end)
        rows.append(metrics(f"four-bar, clearance at {', '.join(joints)}", runs[joints], ideal, wall))
    fig = plt.figure(figsize=(11.0, 7.0))
    grid = fig.add_gridspec(2, 3, height_ratios=(1.0, 1.3))
    ax = fig.add_subplot(grid[0, :])
    plot_channel(ideal, "drive.moment", ax=ax, color="k", ls="--", label="ideal", title=False)
    for joints, result in runs.items():
        plot_channel(result, "drive.moment", ax=ax, label=f"clearance at {', '.join(joints)}", title=False)
    ax.legend(fontsize="small", loc="upper right")
    ax.set_title("(a) crank moment")
    three = runs[FOUR_BAR_CASES[-1]]
    for col, joint in enumerate(FOUR_BAR_CASES[-1]):
        plot_journal_orbit(three, joint, ax=fig.add_subplot(grid[1, col]), markers=False,
                           title=f"({'bcd'[col]}) joint {joint}, clearance at B, C, D")
    fig.suptitle(f"four-bar, {RPM:.0f} rpm, c = {CLEARANCE * 1e3:g} mm, $c_e$ = 0.9, frictionless")
    fig.tight_layout()
    fig.savefig(out / "four_bar_clearance.png", dpi=120)
    plt.close(fig)
    return rows


def slider_crank_study(t_end: float, out: Path) -> list[str]:
    ideal_scene = mechanisms.slider_crank()
    ideal, wall = run(ideal_scene, t_end)
    both = mechanisms.slider_crank("revolute", clearance=CLEARANCE).with_clearance(
        "D", clearance=CLEARANCE, length=mechanisms.SLIDER_LENGTH, width=mechanisms.SLIDER_WIDTH,
        thickness=mechanisms.SLIDER_THICKNESS, corner_radius=mechanisms.CORNER_RADIUS, material=mechanisms.STEEL)
    both.name = "slider_crank_C_D"  # with_clearance keeps the scene's name
    result, wall_both = run(both, t_end)
    fig = plot_run(result, reference=ideal, channels=("drive.moment", "slider.vx"))
    fig.savefig(out / "slider_crank_two_clearances.png", dpi=120)
    plt.close(fig)
    return [metrics("slider-crank, ideal", ideal, ideal, wall),
            metrics("slider-crank, clearance at C and D", result, ideal, wall_both)]


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/four_bar_clearance"), help="output directory")
    parser.add_argument("--revolutions", type=float, default=2.0, help="crank revolutions simulated (default 2)")
    parser.add_argument("--quick", action="store_true", help="half a revolution (smoke test)")
    args = parser.parse_args(argv)
    if not args.revolutions > 0:
        parser.error(f"--revolutions {args.revolutions!r}: must be > 0")
    t_end = (0.5 if args.quick else args.revolutions) * PERIOD
    args.out.mkdir(parents=True, exist_ok=True)
    rows = four_bar_study(t_end, args.out) + slider_crank_study(t_end, args.out)
    header = ["| case | peak crank moment (N m) | / ideal | peak contact force | impacts | run time (s) |",
              "|---|---|---|---|---|---|"]
    text = f"{t_end * 1e3:g} ms ({t_end / PERIOD:g} revolutions at {RPM:g} rpm), rtol {RTOL:g}\n\n"
    text += "\n".join(header + rows) + "\n"
    (args.out / "metrics.md").write_text(text)
    print(text)
    print(f"wrote {args.out / 'four_bar_clearance.png'}, {args.out / 'slider_crank_two_clearances.png'}, "
          f"{args.out / 'metrics.md'}")
    return 0




if __name__ == "__main__":
    raise SystemExit(main())
