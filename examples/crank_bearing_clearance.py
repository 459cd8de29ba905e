"""A crank driven through a clearance bearing: the chapter's slider-crank with clearance at the
rod-slider joint only, and with clearance at the crank pivot too.

The slider-crank of section 4.4 (5000 rpm, gravity 9.81 m/s^2, Lankarani-Nikravesh law with
c_e = 0.9, no friction) in three versions, each started the chapter's way (clearance joints
centred):

- ``ideal``: every joint ideal (the reference);
- ``rod-slider``: the rod-slider joint ``clearance`` with clearance ``--clearance`` (Fig. 4.15);
- ``both``: also the crank-ground pivot ``A`` as a clearance joint (the chapter's 10 mm bearing,
  same clearance), the crank still driven at constant speed by the driver ``drive``: the driver
  prescribes the crank's rotation, and the crank journal moves freely in its bearing.

The figure shows, over ``--revolutions`` crank revolutions, the slider velocity, the crank moment
(the driving moment ``drive.moment``) and the journal orbits of both bearings; the summary printed
gives the RMS difference from the ideal mechanism and the contact events of each joint.

Run: ``python examples/crank_bearing_clearance.py [figure.png] [--clearance 0.5e-3] [--revolutions 2]``
(default figure: ``results/crank_bearing_clearance.png``; about a second of simulation).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402

RPM = 5000.0
REVOLUTION = 60.0 / RPM  # s
BEARING_RADIUS = 10e-3  # m, the chapter's bearing (Table 4.2), used at the crank pivot too


def crank_bearing_clearance(clearance: float) -> dc.Scene:
    """slider_crank("revolute") with the crank pivot ``A`` made a clearance joint with the same bodies
    and point (bearing on the ground); the driver ``drive`` on ``A`` then drives the crank through it."""
    scene = dc.mechanisms.slider_crank("revolute", clearance=clearance, rpm=RPM)
    return scene.with_clearance("A", bearing_radius=BEARING_RADIUS, clearance=clearance, material=dc.mechanisms.STEEL)


def run(clearance: float, revolutions: int, points: int = 400) -> dict[str, dc.Result]:
    """The three mechanisms on one output grid."""
    t_end = revolutions * REVOLUTION
    t = np.linspace(0.0, t_end, revolutions * points + 1)
    scenes = {"ideal": dc.mechanisms.slider_crank("ideal", rpm=RPM),
              "rod-slider": dc.mechanisms.slider_crank("revolute", clearance=clearance, rpm=RPM),
              "both": crank_bearing_clearance(clearance)}
    return {label: dc.simulate(scene, t_end, rtol=1e-7, save=dc.SaveAt(times=t)) for label, scene in scenes.items()}


def summary(results: dict[str, dc.Result]) -> list[str]:
    """RMS differences from the ideal mechanism, relative to the ideal's RMS, and the events."""
    ideal = results["ideal"]
    rms = lambda x: float(np.sqrt(np.mean(np.square(x))))  # noqa: E731
    lines = []
    for label in ("rod-slider", "both"):
        r = results[label]
        dv = rms(r["slider.vx"] - ideal["slider.vx"]) / rms(ideal["slider.vx"])
        dm = rms(r["drive.moment"] - ideal["drive.moment"]) / rms(ideal["drive.moment"])
        onsets = {pair: len(r.events.of(pair, kind="onset")) for pair in ("clearance", "A")
                  if f"{pair}.penetration" in r.channel_names}
        lines.append(f"{label:>10}: slider velocity {dv:6.1%}, crank moment {dm:6.1%} (RMS difference from the "
                     f"ideal); impacts {', '.join(f'{p}: {n}' for p, n in onsets.items())}")
    return lines


def plot(results: dict[str, dc.Result], clearance: float, path: Path) -> None:
    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    colors = {"ideal": "k", "rod-slider": "tab:blue", "both": "tab:red"}
    for label, r in results.items():
        angle = np.degrees(r["crank.phi"] - r["crank.phi"][0])
        axes[0, 0].plot(angle, r["slider.vx"], color=colors[label], lw=1, label=label)
        axes[0, 1].plot(angle, r["drive.moment"], color=colors[label], lw=0.8, label=label)
    axes[0, 0].set(xlabel="crank angle (deg)", ylabel="slider velocity (m/s)")
    axes[0, 1].set(xlabel="crank angle (deg)", ylabel="crank moment (N m)")
    axes[0, 0].legend()
    circle = np.linspace(0.0, 2 * math.pi, 200)
    for ax, pair, title in ((axes[1, 0], "clearance", "rod-slider journal"), (axes[1, 1], "A", "crank journal")):
        ax.plot(1e3 * clearance * np.cos(circle), 1e3 * clearance * np.sin(circle), "k:", lw=0.8)
        for label in ("rod-slider", "both"):
            r = results[label]
            if f"{pair}.ex" in r.channel_names:
                ax.plot(1e3 * r[f"{pair}.ex"], 1e3 * r[f"{pair}.ey"], color=colors[label], lw=0.8, label=label)
        ax.set(xlabel="e_x (mm)", ylabel="e_y (mm)", title=f"{title} in its bearing", aspect="equal")
    fig.suptitle(f"Slider-crank at {RPM:g} rpm, clearance {clearance * 1e3:g} mm: "
                 "rod-slider joint only vs both bearings")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> list[str]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("figure", nargs="?", type=Path, default=Path("results") / "crank_bearing_clearance.png",
                        help="figure to write (default results/crank_bearing_clearance.png)")
    parser.add_argument("--clearance", type=float, default=0.5e-3, help="radial clearance of both joints, m")
    parser.add_argument("--revolutions", type=int, default=2, help="crank revolutions simulated (>= 1)")
    args = parser.parse_args(argv)
    if not 0 < args.clearance < BEARING_RADIUS:
        parser.error(f"--clearance={args.clearance!r} m, must be in (0, {BEARING_RADIUS}) m")
    if args.revolutions < 1:
        parser.error(f"--revolutions={args.revolutions!r}, must be an integer >= 1")
    results = run(args.clearance, args.revolutions)
    plot(results, args.clearance, args.figure)
    lines = summary(results) + [f"figure: {args.figure}"]
    print("\n".join(lines))
    return lines


if __name__ == "__main__":
    main()
