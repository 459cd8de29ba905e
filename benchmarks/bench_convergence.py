"""Tightening rtol never breaks a run: error against a converged reference and wall time, rtol 1e-4 to 1e-12.

    python benchmarks/bench_convergence.py [--repeats 3] [--write] [--figure docs/figures/convergence.png]

Four scenes, both formulations (GGL, the default, and index-1), the default absolute tolerances
(daeclear.solvers.tolerances): the chapter's slider-crank with the 0.5 mm revolute clearance joint
(Fig. 4.15: no gravity; and with gravity), with the 0.5 mm translational clearance joint
(Fig. 4.28), two crank revolutions each, and an ideal five-link pendulum released from the
horizontal (15 constraints, no contact; its links' angular velocities pass through zero while
others are large), 1 s. Every run is a whole ``simulate(scene, ...)`` call (assembly included,
best of --repeats). The error is the largest over the channels of max |x - x_ref| / range(x_ref)
over the window where the reference (DOP853, rtol 1e-13) agrees with an independent run (IDA
index-1, rtol 1e-13) to 1e-9 of each channel's range: impacts make the late motion chaotic.

Verdicts printed at the end: no run fails; the error falls with rtol (no error more than 3x the
error at a looser rtol); GGL's wall time against index-1's at equal or better accuracy (the
cheapest index-1 run whose error is at most GGL's), target at most 1.2x.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np

import daeclear as dc
from daeclear.studies.accuracy import work_precision

REV = 60.0 / 5000.0
RTOLS = np.logspace(-4, -12, 9)
RUNS = {"GGL": {"method": "ida"}, "index1": {"method": "ida", "formulation": "index1"}}
REFERENCE = {"method": "DOP853", "rtol": 1e-13}
CHECK = {"method": "ida", "formulation": "index1", "rtol": 1e-13}
MARK_BEGIN = "<!-- bench_convergence: begin -->"
MARK_END = "<!-- bench_convergence: end -->"


def pendulum(n_links: int = 5, length: float = 0.1, mass: float = 0.2) -> dc.Scene:
    """An ideal n-link pendulum, straight along +X from the origin, released from rest under gravity."""
    scene = dc.Scene(f"pendulum{n_links}", gravity=(0.0, -9.81))
    previous = scene.ground
    for k in range(1, n_links + 1):
        link = scene.add(dc.Body(f"link{k}", mass=mass, inertia=mass * length ** 2 / 12,
                                 position=((k - 0.5) * length, 0.0)))
        scene.add(dc.Revolute(f"pin{k}", previous, link, at=((k - 1) * length, 0.0)))
        previous = link
    return scene


def scenes() -> dict[str, tuple[dc.Scene, float, list[str]]]:
    """label -> (scene, t_end, channels)."""
    sc = dc.mechanisms.slider_crank
    return {
        "revolute, no gravity (Fig. 4.15)": (sc("revolute", gravity=0.0), 2 * REV, ["slider.vx"]),
        "revolute, gravity": (sc("revolute"), 2 * REV, ["slider.vx"]),
        "translational (Fig. 4.28)": (sc("translational"), 2 * REV, ["slider.vx"]),
        "five-link pendulum, ideal": (pendulum(), 1.0, ["link5.x", "link5.omega"]),
    }


def monotonic(errors: list[float]) -> bool:
    """No error more than 3x the smallest error at a looser rtol (errors in order of falling rtol)."""
    return all(e <= 3.0 * min(errors[:i]) for i, e in enumerate(errors) if i)


def study(label: str, scene: dc.Scene, t_end: float, channels: list[str], repeats: int) -> dict:
    wp = work_precision(scene, t_end, channels=channels, rtols=RTOLS, methods=RUNS, reference=REFERENCE,
                        check=CHECK, converged_tol=1e-9, n_eval=801, repeats=repeats)
    rows = {name: [r for r in wp.rows if r["label"] == name] for name in RUNS}
    return {"label": label, "rows": rows, "window": wp.window}


def price(rows: dict) -> list[tuple[float, float, float]]:
    """(rtol, GGL wall, GGL wall / the cheapest index-1 wall at equal or better error) per GGL run."""
    out = []
    for g in rows["GGL"]:
        better = [r for r in rows["index1"] if r["status"] == 0 and r["error"] <= g["error"]]
        if g["status"] == 0 and better:
            out.append((g["tolerance"], g["wall_time"], g["wall_time"] / min(r["wall_time"] for r in better)))
    return out


def table(results: list[dict]) -> list[str]:
    lines = ["| scene | window (s) | rtol | GGL error | GGL wall | index-1 error | index-1 wall |",
             "|---|---|---|---|---|---|---|"]
    for res in results:
        for g, i in zip(res["rows"]["GGL"], res["rows"]["index1"]):
            cells = [f"{r['error']:.2e}" if r["status"] == 0 else "FAILED" for r in (g, i)]
            lines.append(f"| {res['label']} | {res['window'][1]:.4g} | {g['tolerance']:.0e} | {cells[0]} | "
                         f"{g['wall_time'] * 1e3:.1f} ms | {cells[1]} | {i['wall_time'] * 1e3:.1f} ms |")
    return lines


def verdicts(results: list[dict]) -> list[str]:
    lines = []
    failures = [(res["label"], name, r["tolerance"]) for res in results for name, rows in res["rows"].items()
                for r in rows if r["status"] != 0]
    lines.append(f"Failed runs: {len(failures)}" + (f" {failures}" if failures else " (none)."))
    for res in results:
        for name, rows in res["rows"].items():
            ok = monotonic([r["error"] for r in rows])
            lines.append(f"{res['label']}, {name}: error falls with rtol (within 3x): {'yes' if ok else 'NO'}.")
    for res in results:
        ratios = price(res["rows"])
        if ratios:
            worst = max(ratios, key=lambda x: x[2])
            median = float(np.median([x[2] for x in ratios]))
            lines.append(f"{res['label']}: GGL / index-1 wall at equal or better error: median {median:.2f}x, "
                         f"largest {worst[2]:.2f}x (rtol {worst[0]:.0e}).")
    return lines


def figure(results: list[dict], path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(2, len(results), figsize=(4.2 * len(results), 7.0), squeeze=False)
    for col, res in enumerate(results):
        for name, marker in (("GGL", "o-"), ("index1", "s--")):
            rows = [r for r in res["rows"][name] if r["status"] == 0]
            err = [r["error"] for r in rows]
            axes[0, col].loglog([r["tolerance"] for r in rows], err, marker, label=name)
            axes[1, col].loglog([r["wall_time"] * 1e3 for r in rows], err, marker, label=name)
        axes[0, col].set_title(res["label"], fontsize=9)
        axes[0, col].set_xlabel("rtol")
        axes[1, col].set_xlabel("wall time of simulate(scene), ms")
        axes[1, col].xaxis.set_minor_formatter(NullFormatter())
        axes[0, col].invert_xaxis()
        for ax in axes[:, col]:
            ax.set_ylabel("error (of range)")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write(doc: Path, lines: list[str]) -> None:
    text = doc.read_text()
    block = "\n".join([MARK_BEGIN, *lines, MARK_END])
    pattern = re.compile(re.escape(MARK_BEGIN) + ".*?" + re.escape(MARK_END), re.S)
    text = pattern.sub(block, text) if MARK_BEGIN in text else text.rstrip() + "\n\n" + block + "\n"
    doc.write_text(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--only", default=None, help="run the scenes whose label contains this text")
    parser.add_argument("--figure", type=Path, default=None, help="write the figure here (PNG)")
    parser.add_argument("--write", action="store_true", help="put the tables in docs/work_precision.md")
    args = parser.parse_args()
    results = []
    for label, (scene, t_end, channels) in scenes().items():
        if args.only and args.only not in label:
            continue
        results.append(study(label, scene, t_end, channels, args.repeats))
        print("\n".join(table(results[-1:])[2:]), flush=True)
    lines = [*table(results), "", *verdicts(results)]
    print("\n" + "\n".join(lines))
    if args.figure:
        figure(results, args.figure)
    if args.write:
        write(Path(__file__).resolve().parents[1] / "docs" / "work_precision.md", lines)


if __name__ == "__main__":
    main()
