"""The chapter's slider-crank with a lubricated rod-slider joint: orbit and crank moment against the
dry and the ideal joint, and a sweep over the oil's viscosity showing where the film breaks down.

The slider-crank of section 4.4 (5000 rpm, gravity 9.81 m/s^2, bearing radius 10 mm, radial
clearance 0.5 mm as in Fig. 4.15), the rod-slider joint ``clearance`` lubricated
(:class:`daeclear.contact.HydrodynamicBearing`, docs/lubrication.md):

- viscosity 0.1 Pa s: an SAE 30 engine oil near 40 C (about 100 mm^2/s at 900 kg/m^3);
- bearing length 10 mm: the chapter gives none; L/D = 0.5 keeps the joint inside the short
  (Ocvirk) theory's range, which is the theory used (half film, Guembel);
- composite roughness 1 um (ground steel surfaces); the film breaks down at the film parameter
  h_min / roughness = 1 (a film of 1 um), hysteresis 1 (the film forms again at 2 um); below it the
  chapter's dry law (Lankarani-Nikravesh, c_e = 0.9) acts, and under 4 um the asperities share the
  load with the film (Greenwood and Tripp, docs/lubrication.md).

The joint starts centred, as in the chapter. The sweep runs the same mechanism with thinner oils;
the summary gives, per viscosity, the smallest film thickness, the number of film breakdowns and
the RMS difference of the crank moment from the ideal mechanism's.

Run: ``python examples/lubricated_joint.py [--out results/lubricated_joint] [--revolutions 2]``
(writes ``lubricated_joint.png`` and ``viscosity_sweep.png``; a few seconds).
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
from daeclear.contact import HydrodynamicBearing  # noqa: E402

RPM = 5000.0
REVOLUTION = 60.0 / RPM  # s
CLEARANCE = 0.5e-3  # m (Fig. 4.15)
VISCOSITY = 0.1  # Pa s
LENGTH = 10e-3  # m
ROUGHNESS = 1e-6  # m, composite RMS
THRESHOLD = ROUGHNESS  # m, the film breaks down at h_min / roughness = 1
SWEEP = (0.1, 0.03, 0.01, 0.006, 0.003)  # Pa s


def lubricated(viscosity: float) -> dc.Scene:
    """slider_crank("revolute") whose rod-slider joint is lubricated by an oil of ``viscosity``."""
    law = HydrodynamicBearing(viscosity=viscosity, length=LENGTH, roughness=ROUGHNESS)
    return dc.mechanisms.slider_crank("revolute", clearance=CLEARANCE, rpm=RPM, law=law)


def run(revolutions: int, sweep: Sequence[float], points: int = 600) -> dict[str, dc.Result]:
    """Ideal, dry and lubricated mechanisms (and the sweep) on one output grid."""
    t_end = revolutions * REVOLUTION
    t = np.linspace(0.0, t_end, revolutions * points + 1)
    scenes = {"ideal": dc.mechanisms.slider_crank("ideal", rpm=RPM),
              "dry": dc.mechanisms.slider_crank("revolute", clearance=CLEARANCE, rpm=RPM)}
    scenes.update({f"mu={mu:g}": lubricated(mu) for mu in sorted({VISCOSITY, *sweep}, reverse=True)})
    return {label: dc.simulate(scene, t_end, rtol=1e-7, save=dc.SaveAt(times=t)) for label, scene in scenes.items()}


def summary(results: dict[str, dc.Result]) -> list[str]:
    ideal = results["ideal"]
    rms = lambda x: float(np.sqrt(np.mean(np.square(x))))  # noqa: E731
    lines = [f"{'case':>10} | min film (um) | breakdowns | crank moment RMS diff from ideal"]
    for label, r in results.items():
        if label == "ideal":
            continue
        film = CLEARANCE - r["clearance.eccentricity"]
        pair = "clearance" if label == "dry" else "clearance.regime"  # the dry joint's impacts, the film's breakdowns
        events = len([e for e in r.events if e.pair == pair and e.kind == "onset"])
        dm = rms(r["drive.moment"] - ideal["drive.moment"]) / rms(ideal["drive.moment"])
        lines.append(f"{label:>10} | {film.min() * 1e6:13.2f} | {events:10d} | {dm:7.1%}")
    return lines


def plot_comparison(results: dict[str, dc.Result], path: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    lube = f"mu={VISCOSITY:g}"
    colors = {"ideal": "k", "dry": "tab:red", lube: "tab:blue"}
    for label in ("ideal", "dry", lube):
        r = results[label]
        angle = np.degrees(r["crank.phi"] - r["crank.phi"][0])
        axes[0].plot(angle, r["drive.moment"], color=colors[label], lw=0.8, label=label)
    axes[0].set(xlabel="crank angle (deg)", ylabel="crank moment (N m)", title="crank moment")
    axes[0].legend()
    circle = np.linspace(0.0, 2 * math.pi, 300)
    ax = axes[1]
    for radius, style_, text in ((CLEARANCE, "k-", "eps = 1"), (CLEARANCE - THRESHOLD, "k:", "film threshold")):
        ax.plot(1e3 * radius * np.cos(circle), 1e3 * radius * np.sin(circle), style_, lw=0.8, label=text)
    for label in ("dry", lube):
        r = results[label]
        ax.plot(1e3 * r["clearance.ex"], 1e3 * r["clearance.ey"], color=colors[label], lw=0.8, label=label)
    ax.set(xlabel="e_x (mm)", ylabel="e_y (mm)", title="journal orbit (rod in the slider's bearing)", aspect="equal")
    ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(f"Slider-crank at {RPM:g} rpm, c = {CLEARANCE * 1e3:g} mm: lubricated joint "
                 f"(mu = {VISCOSITY:g} Pa s, L = {LENGTH * 1e3:g} mm, short bearing) vs dry and ideal")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_sweep(results: dict[str, dc.Result], path: Path) -> None:
    labels = [label for label in results if label.startswith("mu=")]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for label in labels:
        r = results[label]
        axes[0].semilogy(r.t * 1e3, np.maximum(1e6 * r["clearance.film_thickness"], 1e-2), lw=0.8, label=label)
    axes[0].axhline(THRESHOLD * 1e6, color="k", ls=":", lw=0.8, label="film threshold")
    axes[0].set(xlabel="t (ms)", ylabel="minimum film thickness (um, floored at 0.01)",
                title="film thickness; below the threshold the dry law acts")
    axes[0].legend(fontsize=8)
    mus = [float(label[3:]) for label in labels]
    film_min = [1e6 * float(np.min(results[label]["clearance.film_thickness"])) for label in labels]
    breakdowns = [len(results[label].events.of("clearance.regime", kind="onset")) for label in labels]
    axes[1].semilogx(mus, film_min, "o-")
    axes[1].axhline(THRESHOLD * 1e6, color="k", ls=":", lw=0.8)
    for mu, h, n in zip(mus, film_min, breakdowns):
        axes[1].annotate(f"{n} breakdowns", (mu, h), fontsize=8, textcoords="offset points", xytext=(4, 4))
    axes[1].set(xlabel="viscosity (Pa s)", ylabel="smallest film thickness (um)", title="viscosity sweep")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> list[str]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results") / "lubricated_joint",
                        help="output directory (default results/lubricated_joint/)")
    parser.add_argument("--revolutions", type=int, default=2, help="crank revolutions simulated (>= 1)")
    parser.add_argument("--quick", action="store_true", help="one revolution, a short sweep (smoke test)")
    args = parser.parse_args(argv)
    if args.revolutions < 1:
        parser.error(f"--revolutions={args.revolutions!r}, must be an integer >= 1")
    revolutions, sweep = (1, (0.1, 0.006)) if args.quick else (args.revolutions, SWEEP)
    results = run(revolutions, sweep)
    args.out.mkdir(parents=True, exist_ok=True)
    plot_comparison(results, args.out / "lubricated_joint.png")
    plot_sweep(results, args.out / "viscosity_sweep.png")
    lines = summary(results) + [f"wrote {args.out / 'lubricated_joint.png'}, {args.out / 'viscosity_sweep.png'}"]
    print("\n".join(lines))
    return lines


if __name__ == "__main__":
    main()
