"""The lubricated rod-slider joint over the oil's viscosity: peak joint force and crank moment.

The chapter's slider-crank (section 4.4, 5000 rpm, gravity, R = 10 mm), its rod-slider joint
lubricated (:class:`daeclear.contact.HydrodynamicBearing`: short bearing, half film, L = 10 mm,
composite roughness 1 um, breakdown at the film parameter 1, Greenwood-Tripp asperities below 4 um)
at radial clearances 0.1 and 0.5 mm, for viscosities from 1e-4 to 1 Pa s, two revolutions from the
chapter's centred start; against the dry joint (Lankarani-Nikravesh, c_e = 0.9) at each clearance.

For each case: the largest force the joint carries (film and asperities in the film regime, the
dry law's normal and friction forces in the dry one), the largest crank moment, the number of film
breakdowns and the smallest film thickness. One model per clearance: every viscosity is a new
number of the same compiled model (``model.with_parameters``).

Run: ``python examples/lubricated_viscosity_study.py [--out results/lubricated_viscosity]``
(writes ``viscosity_study.png`` and ``viscosity_study.md``; about a minute).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.contact import HydrodynamicBearing  # noqa: E402

RPM = 5000.0
LENGTH = 10e-3  # m
CLEARANCES = (0.1e-3, 0.5e-3)  # m
VISCOSITIES = tuple(float(x) for x in np.logspace(-4, 0, 9))  # Pa s
QUICK_VISCOSITIES = (1e-3, 1e-1)


def joint_force(result: dc.Result) -> np.ndarray:
    """The magnitude of the force the joint carries at each output time (film, asperities or dry)."""
    film = np.hypot(result["clearance.film_radial"] + result["clearance.asperity_force"],
                    result["clearance.film_tangential"])
    dry = np.hypot(result["clearance.normal_force"], result["clearance.friction_force"]) \
        if "clearance.friction_force" in result.channel_names else result["clearance.normal_force"]
    return np.maximum(film, dry)


def study(viscosities: Sequence[float], revolutions: int = 2) -> list[dict[str, float]]:
    """One row per clearance and viscosity (viscosity NaN: the dry joint)."""
    t_end = revolutions * 60.0 / RPM
    rows = []
    for c in CLEARANCES:
        dry = dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=c, rpm=RPM), t_end)
        rows.append({"clearance": c, "viscosity": float("nan"),
                     "peak_force": float(dry["clearance.normal_force"].max()),
                     "peak_moment": float(np.abs(dry["drive.moment"]).max()),
                     "breakdowns": float("nan"), "min_film": float("nan")})
        law = HydrodynamicBearing(viscosity=viscosities[0], length=LENGTH)
        model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=c, rpm=RPM, law=law))
        for mu in viscosities:
            run = dc.simulate(model.with_parameters({"clearance.law.viscosity": mu}), t_end)
            rows.append({"clearance": c, "viscosity": mu, "peak_force": float(joint_force(run).max()),
                         "peak_moment": float(np.abs(run["drive.moment"]).max()),
                         "breakdowns": float(len(run.events.of("clearance.regime", kind="onset"))),
                         "min_film": float(run["clearance.film_thickness"].min())})
    return rows


def table(rows: list[dict[str, float]]) -> list[str]:
    lines = ["| c (mm) | viscosity (Pa s) | peak joint force (kN) | peak crank moment (N m) | breakdowns | "
             "smallest film (um) |", "|---|---|---|---|---|---|"]
    for r in rows:
        dry = np.isnan(r["viscosity"])
        lines.append(f"| {r['clearance'] * 1e3:g} | {'dry' if dry else format(r['viscosity'], '.3g')} | "
                     f"{r['peak_force'] / 1e3:.3g} | {r['peak_moment']:.4g} | "
                     f"{'-' if dry else int(r['breakdowns'])} | {'-' if dry else format(r['min_film'] * 1e6, '.3g')} |")
    return lines


def figure(rows: list[dict[str, float]], path: Path) -> None:
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for k, c in enumerate(CLEARANCES):
        mine = [r for r in rows if r["clearance"] == c]
        dry = next(r for r in mine if np.isnan(r["viscosity"]))
        lube = [r for r in mine if not np.isnan(r["viscosity"])]
        mu = [r["viscosity"] for r in lube]
        for ax, key, scale in ((axes[0], "peak_force", 1e-3), (axes[1], "peak_moment", 1.0)):
            ax.loglog(mu, [r[key] * scale for r in lube], "o-", color=f"C{k}", label=f"lubricated, c = {c * 1e3:g} mm")
            ax.axhline(dry[key] * scale, color=f"C{k}", ls="--", lw=0.9, label=f"dry, c = {c * 1e3:g} mm")
            broke = [r for r in lube if r["breakdowns"] > 0]
            ax.loglog([r["viscosity"] for r in broke], [r[key] * scale for r in broke], "x", color="k", ms=8)
    axes[0].set(xlabel="viscosity (Pa s)", ylabel="peak joint force (kN)", title="largest force in the joint")
    axes[1].set(xlabel="viscosity (Pa s)", ylabel="peak crank moment (N m)", title="largest crank moment")
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Slider-crank at {RPM:g} rpm, lubricated rod-slider joint (L = {LENGTH * 1e3:g} mm, short "
                 "bearing, roughness 1 um); x: the film broke down", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> list[str]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results") / "lubricated_viscosity",
                        help="output directory (default results/lubricated_viscosity/)")
    parser.add_argument("--quick", action="store_true", help="two viscosities (smoke test)")
    args = parser.parse_args(argv)
    rows = study(QUICK_VISCOSITIES if args.quick else VISCOSITIES)
    args.out.mkdir(parents=True, exist_ok=True)
    figure(rows, args.out / "viscosity_study.png")
    lines = table(rows)
    (args.out / "viscosity_study.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return lines


if __name__ == "__main__":
    main()
