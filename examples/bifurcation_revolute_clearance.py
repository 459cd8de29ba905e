"""Bifurcation diagram of the revolute clearance joint over the clearance, 0.01 to 0.5 mm.

Section 4.4 reads the motion from four clearances (Fig. 4.18); this sweeps the clearance on a
geometric grid (``--points``, 25 by default) with :func:`daeclear.sweep` and plots the
stroboscopic Poincaré section (slider velocity and acceleration once per crank revolution,
after the transient) against the clearance, each run's points coloured by its motion class,
plus the classification evidence (periodicity defect, twin decorrelation).

Writes into ``--out`` (default ``results/bifurcation_revolute_clearance/``):

- ``bifurcation.h5``: the sweep file (resumed when the script is run again);
- ``bifurcation.png``: section values of slider velocity (top) and acceleration (middle)
  against the clearance, log scale, and the evidence (bottom);
- ``metrics.md``, ``metrics.json``: one row per clearance.

Every distinct clearance is one compiled model (~2 s, cached on disk). Run:
``python examples/bifurcation_revolute_clearance.py`` (``--quick``: 2 clearances, 8
revolutions, no twins; ``--dask local`` for a local Dask cluster; ``--workers N``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common as cm  # noqa: E402
import daeclear as dc  # noqa: E402
import sweep_studies  # noqa: E402

C_MIN, C_MAX = 0.01e-3, 0.5e-3  # m


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="bifurcation_revolute_clearance.py", description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="2 clearances, 8 revolutions, no twins (smoke run)")
    parser.add_argument("--points", type=int, default=25, help="number of clearances (default 25)")
    parser.add_argument("--out", type=Path, default=Path("results") / "bifurcation_revolute_clearance")
    parser.add_argument("--workers", type=int, help="worker processes (default: the CPU count)")
    parser.add_argument("--dask", metavar="ADDRESS", help="Dask scheduler address, or 'local'")
    parser.add_argument("--restart", action="store_true", help="discard the sweep file's runs and start over")
    parser.add_argument("--revolutions", type=int, default=30, help="revolutions analysed (default 30)")
    parser.add_argument("--transient", type=int, default=10, help="revolutions discarded first (default 10)")
    parser.add_argument("--rtol", type=float, default=1e-6, help="IDA relative tolerance (default 1e-6)")
    args = parser.parse_args(argv)
    if args.points < 2:
        parser.error("--points must be >= 2.")
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    import matplotlib.pyplot as plt

    from daeclear.plot import style
    from daeclear.plot import plot_bifurcation

    clearances = [float(c) for c in np.geomspace(C_MIN, C_MAX, 2 if args.quick else args.points)]
    analysis = {"revolutions": args.revolutions, "transient": args.transient, "per_revolution": 32, "twin": True}
    if args.quick:
        analysis.update(revolutions=8, transient=2, per_revolution=16, twin=False)
    executor, closers = sweep_studies.executor_for(args)
    try:
        result = dc.sweep(args.out / "bifurcation.h5", {"clearance": clearances}, fixed={"joint": "revolute"},
                          options=dc.SolverOptions(rtol=args.rtol), executor=executor, max_workers=args.workers,
                          resume=not args.restart, **analysis)
    finally:
        for obj in closers:
            obj.close()

    fig, axes = plt.subplots(3, 1, figsize=(7.5, 9.0), sharex=True)
    plot_bifurcation(result, "clearance", "slider.vx", ax=axes[0], scale=1e3, unit="mm")
    plot_bifurcation(result, "clearance", "slider.ax", ax=axes[1], scale=1e3, unit="mm")
    done = [r for r in result.runs if r.ok]
    c_mm = [r.parameters["clearance"] * 1e3 for r in done]
    axes[2].semilogy(c_mm, [r.evidence.get("periodicity_defect", np.nan) for r in done], "o-", ms=3,
                     label="periodicity defect")
    axes[2].semilogy(c_mm, [r.evidence.get("decorrelation", np.nan) for r in done], "s-", ms=3,
                     label="twin decorrelation")
    axes[2].axhline(dc.analysis.DEFAULT_TOL, color="C0", ls="--", lw=0.8)
    axes[2].axhline(dc.analysis.DEFAULT_DECORRELATION, color="C1", ls="--", lw=0.8)
    axes[2].set_ylabel("evidence")
    axes[2].set_xlabel("clearance (mm)")
    axes[2].legend(fontsize="x-small")
    for ax in axes:
        ax.set_xscale("log")
    for ax in axes[:2]:
        ax.set_xlabel("")
    scenes = [dc.mechanisms.slider_crank(**r.parameters) for r in done]  # the shared parameters, from 1 µs runs
    style.set_title(fig, cm.title_of("Revolute clearance joint: Poincaré section against clearance",
                                     cm.caption_runs(scenes)))
    fig.tight_layout()
    png = args.out / "bifurcation.png"
    fig.savefig(png, dpi=120)
    plt.close(fig)

    table = [{"clearance_mm": r.parameters["clearance"] * 1e3, "motion": r.motion if r.ok else "FAILED",
              "period": r.period, **{k: r.evidence.get(k) for k in ("periodicity_defect", "spread", "decorrelation",
                                                                        "twin_amplification",
                                                                        "lyapunov_per_revolution")}}
             for r in result.runs]
    lines = ["| clearance (mm) | motion | period | defect | spread | decorrelation | amplification | λT |",
             "|---|---|---|---|---|---|---|---|"]

    def fmt(v: object) -> str:
        return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f"{v:.3g}"

    for row in table:
        lines.append(f"| {row['clearance_mm']:.4g} | {row['motion']} | {row['period'] or '-'} | "
                     f"{fmt(row['periodicity_defect'])} | {fmt(row['spread'])} | {fmt(row['decorrelation'])} | "
                     f"{fmt(row['twin_amplification'])} | {fmt(row['lyapunov_per_revolution'])} |")
    text = "\n".join(lines)
    (args.out / "metrics.md").write_text("# Revolute clearance bifurcation sweep\n\n" + text + "\n")
    (args.out / "metrics.json").write_text(json.dumps({"options": result.options, "runs": table}, indent=1,
                                                      default=str))
    print(result)
    print(text)
    print(f"wrote {args.out / 'bifurcation.h5'}, {png}, metrics.md, metrics.json")
    return 0 if all(r.ok for r in result.runs) else 1


if __name__ == "__main__":
    sys.exit(main())
