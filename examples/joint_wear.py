"""The chapter's slider-crank with Archard wear at the rod-slider joint over many cycles.

The slider-crank of section 4.4 (5000 rpm, gravity, bearing radius 10 mm, radial clearance 0.5 mm
as in Fig. 4.15, Lankarani-Nikravesh c_e = 0.9) with modified Coulomb friction 0.1 at the rod-slider
joint ``clearance``, whose bearing (on the slider) wears by Archard's law
(:class:`daeclear.contact.wear.ArchardWear`, docs/wear.md):

- bearing length 20 mm (the chapter gives none; L/D = 1);
- wear coefficient k = 1e-13 m^2/N, the upper end of a dry steel pair's (1e-14..1e-13 m^2/N):
  tens of um in 1e4 cycles; the depth scales with k at a given number of cycles while the wear is
  too small to change the dynamics (``--coefficient`` accelerates it, as wear studies do);
- elastic-foundation pressure over the contact arc; 360 nodes, 48 Fourier modes in the gap.

The profile is updated every cycle from the wear of that cycle, extrapolated over ``--extrapolate``
cycles (the block scheme of Mukras et al.). Figures: the worn depth against the angle in the
bearing's frame (polar), the largest depth and the worn volume against cycles, the largest normal
force of each simulated cycle against cycles; and, with ``--animate``, the profile's growth (GIF).

Run: ``python examples/joint_wear.py [--cycles 10000] [--extrapolate 100] [--out results/joint_wear]``
(100 simulated cycles: tens of seconds; ``--quick``: 40 cycles in blocks of 10 at k = 1e-11, seconds).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.contact.wear import ArchardWear  # noqa: E402
from daeclear.studies.wear import WearHistory, simulate_wear  # noqa: E402

COEFFICIENT = 1e-13  # m^2/N (see the module docstring)
QUICK_COEFFICIENT = 1e-11  # m^2/N, accelerated: a visible profile in 40 cycles
LENGTH = 20e-3  # m
FRICTION = 0.1


def worn_scene(coefficient: float = COEFFICIENT) -> dc.Scene:
    """slider_crank("revolute") whose rod-slider bearing wears."""
    scene = dc.mechanisms.slider_crank("revolute", friction=FRICTION)
    return scene.with_values({"clearance.wear": ArchardWear(coefficient=coefficient, length=LENGTH)})


def figures(history: WearHistory, out: Path) -> list[Path]:
    """The polar depth profiles, depth and volume against cycles, peak force against cycles."""
    written = []
    fig = plt.figure(figsize=(11, 4.2))
    polar = fig.add_subplot(1, 2, 1, projection="polar")
    picks = np.unique(np.linspace(0, len(history.cycles) - 1, 5).round().astype(int))
    angles = np.append(history.angles, history.angles[0])
    for i in picks:
        depth = np.append(history.depth[i], history.depth[i][0]) * 1e6
        polar.plot(angles, depth, label=f"{history.cycles[i]:.0f} cycles")
    polar.set_title("worn depth (um), bearing frame", fontsize=10)
    polar.legend(loc="lower left", fontsize=7, bbox_to_anchor=(-0.25, -0.15))
    ax = fig.add_subplot(1, 2, 2)
    ax.plot(history.cycles, history.max_depth * 1e6, label="largest depth (um)")
    ax.set_xlabel("cycles")
    ax.set_ylabel("largest depth (um)")
    twin = ax.twinx()
    twin.plot(history.cycles, history.volume * 1e9, "C1--", label="worn volume (mm^3)")
    twin.set_ylabel("worn volume (mm^3)")
    ax.legend(loc="upper left", fontsize=8)
    twin.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    written.append(out / "wear_profile.png")
    fig.savefig(written[-1], dpi=120)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(history.cycles[:-1], history.peak_force[:-1], "o-", ms=3)
    ax.set_xlabel("cycles worn")
    ax.set_ylabel("largest normal force of the cycle (N)")
    ax.set_title("impact peaks as the joint wears", fontsize=10)
    fig.tight_layout()
    written.append(out / "wear_impacts.png")
    fig.savefig(written[-1], dpi=120)
    plt.close(fig)
    return written


def animate(history: WearHistory, out: Path) -> Path | None:
    """The profile's growth as a GIF (needs Pillow; None without it)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    try:
        import PIL  # noqa: F401
    except ImportError:
        print("no Pillow: the animation is left out (pip install pillow)")
        return None
    fig = plt.figure(figsize=(4, 4))
    polar = fig.add_subplot(projection="polar")
    angles = np.append(history.angles, history.angles[0])
    top = float(history.max_depth.max()) * 1e6 or 1.0
    (line,) = polar.plot([], [])
    polar.set_ylim(0, top)

    def frame(i: int) -> tuple:
        line.set_data(angles, np.append(history.depth[i], history.depth[i][0]) * 1e6)
        polar.set_title(f"{history.cycles[i]:.0f} cycles, depth in um", fontsize=9)
        return (line,)

    path = out / "wear_growth.gif"
    FuncAnimation(fig, frame, frames=len(history.cycles)).save(path, writer=PillowWriter(fps=8))
    plt.close(fig)
    return path


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=float, default=10000.0, help="cycles to wear (10000)")
    parser.add_argument("--extrapolate", type=int, default=100, help="cycles each simulated cycle stands for (100)")
    parser.add_argument("--update-every", type=int, default=1, help="cycles simulated per profile update (1)")
    parser.add_argument("--coefficient", type=float, default=None, help="wear coefficient k, m^2/N (1e-13)")
    parser.add_argument("--out", type=Path, default=Path("results/joint_wear"))
    parser.add_argument("--animate", action="store_true", help="also write the profile's growth as a GIF")
    parser.add_argument("--quick", action="store_true", help="40 cycles in blocks of 10 (a smoke test)")
    args = parser.parse_args(argv)
    cycles, extrapolate = (40.0, 10) if args.quick else (args.cycles, args.extrapolate)
    if args.coefficient is None:
        args.coefficient = QUICK_COEFFICIENT if args.quick else COEFFICIENT
    args.out.mkdir(parents=True, exist_ok=True)
    history = simulate_wear(worn_scene(args.coefficient), cycles, update_every=args.update_every,
                            extrapolate=extrapolate, path=args.out / "wear_history.h5", progress=not args.quick)
    written = figures(history, args.out)
    if args.animate:
        gif = animate(history, args.out)
        written += [gif] if gif is not None else []
    metrics = {"cycles": float(history.cycles[-1]), "extrapolate": extrapolate, "coefficient": args.coefficient,
               "max_depth_m": float(history.max_depth[-1]), "volume_m3": float(history.volume[-1]),
               "sliding_work_Nm": float(history.sliding_work[-1]),
               "peak_force_first_N": float(history.peak_force[0]),
               "peak_force_last_N": float(history.peak_force[-2]), "wall_time_s": history.wall_time}
    (args.out / "metrics.json").write_text(json.dumps(metrics, indent=2))
    print(f"| cycles | largest depth (um) | worn volume (mm^3) | peak force first/last (N) | wall (s) |\n"
          f"|---|---|---|---|---|\n| {metrics['cycles']:.0f} | {metrics['max_depth_m'] * 1e6:.3g} | "
          f"{metrics['volume_m3'] * 1e9:.3g} | {metrics['peak_force_first_N']:.0f} / {metrics['peak_force_last_N']:.0f}"
          f" | {metrics['wall_time_s']:.1f} |")
    print("wrote " + ", ".join(str(p) for p in [*written, args.out / "wear_history.h5", args.out / "metrics.json"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
