"""Shared code of the sweep examples: the chapter's clearance and friction studies as sweeps.

Each ``sweep_<joint>_<parameter>.py`` script runs one study of sections 4.4 (revolute
clearance joint) and 4.5 (translational clearance joint) with :func:`daeclear.sweep`:
one classified run per parameter value, in parallel, gathered in one HDF5 file, resumed
where it stopped when run again. It writes into ``--out``:

- ``<study>.h5``: the sweep file (section points, slider velocity and acceleration over the
  analysed span, motion class and its evidence per run);
- ``sections.png``: one panel per run: phase portrait (grey, the chapter's "Poincaré map")
  and the stroboscopic section (red, once per crank revolution), titled with the class;
- ``evidence.png``: periodicity defect and twin decorrelation against the parameter;
- ``metrics.json``, ``metrics.md``: the table, with the chapter's reading beside ours.

Options: ``--quick`` (two values, 8 revolutions, no twins: a smoke run), ``--workers N``,
``--dask local|ADDRESS`` (a Dask cluster instead of the local process pool), ``--restart``,
``--revolutions``, ``--transient``, ``--per-revolution``, ``--rtol``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import _common as cm  # noqa: E402
import daeclear as dc  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402
from daeclear.studies.sweep import SweepResult  # noqa: E402

CLEARANCES = [0.5e-3, 0.2e-3, 0.1e-3, 0.01e-3]  # m (Figs. 4.16-4.18 and 4.29-4.31)
FRICTIONS = [0.01, 0.03, 0.05, 0.1]  # modified Coulomb coefficients (Figs. 4.19-4.21 and 4.32-4.34)

STUDIES: dict[str, dict[str, Any]] = {
    "revolute_clearance": {
        "title": "Section 4.4, Figs. 4.16-4.18: revolute clearance size (Lankarani-Nikravesh, c_e = 0.9)",
        "fixed": {"joint": "revolute"}, "parameter": "clearance", "values": CLEARANCES, "scale": 1e3, "unit": "mm",
        "chapter": {0.5e-3: "chaotic", 0.2e-3: "chaotic", 0.1e-3: "quasi-periodic", 0.01e-3: "periodic"},
        "figure": "Section 4.4, Figs. 4.16-4.18: revolute clearance size",
    },
    "revolute_friction": {
        "title": "Section 4.4, Figs. 4.19-4.21: friction in the revolute joint, c = 0.5 mm",
        "fixed": {"joint": "revolute", "clearance": 0.5e-3}, "parameter": "friction", "values": FRICTIONS,
        "scale": 1.0, "unit": "",
        "chapter": {0.01: "chaotic", 0.1: "tends to periodic (closer to the ideal joint)"},
        "figure": "Section 4.4, Figs. 4.19-4.21: friction in the revolute joint",
    },
    "translational_clearance": {
        "title": "Section 4.5, Figs. 4.29-4.31: translational clearance size",
        "fixed": {"joint": "translational"}, "parameter": "clearance", "values": CLEARANCES, "scale": 1e3,
        "unit": "mm", "chapter": {0.5e-3: "chaotic", 0.01e-3: "periodic or regular"},
        "figure": "Section 4.5, Figs. 4.29-4.31: translational clearance size",
    },
    "translational_friction": {
        "title": "Section 4.5, Figs. 4.32-4.34: friction in the translational joint, c = 0.5 mm",
        "fixed": {"joint": "translational", "clearance": 0.5e-3}, "parameter": "friction", "values": FRICTIONS,
        "scale": 1.0, "unit": "", "chapter": {v: "friction has no significant influence" for v in FRICTIONS},
        "figure": "Section 4.5, Figs. 4.32-4.34: friction in the translational joint",
    },
}


def parse_args(name: str, argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog=f"sweep_{name}.py", description=STUDIES[name]["title"])
    parser.add_argument("--quick", action="store_true", help="two values, 8 revolutions, no twins (smoke run)")
    parser.add_argument("--out", type=Path, default=Path("results") / f"sweep_{name}", help="output directory")
    parser.add_argument("--workers", type=int, help="worker processes (default: the CPU count)")
    parser.add_argument("--dask", metavar="ADDRESS", help="Dask scheduler address, or 'local' for a local cluster")
    parser.add_argument("--restart", action="store_true", help="discard the sweep file's runs and start over")
    parser.add_argument("--revolutions", type=int, default=30, help="revolutions analysed (default 30)")
    parser.add_argument("--transient", type=int, default=10, help="revolutions discarded first (default 10)")
    parser.add_argument("--per-revolution", type=int, default=64, help="samples per revolution (default 64)")
    parser.add_argument("--rtol", type=float, default=1e-6, help="IDA relative tolerance (default 1e-6)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def executor_for(args: argparse.Namespace) -> tuple[Any, list[Any]]:
    """(executor or None for the default process pool, objects to close afterwards)."""
    if not args.dask:
        return None, []
    from dask.distributed import Client, LocalCluster

    if args.dask == "local":
        cluster = LocalCluster(n_workers=args.workers or 2, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        return client.get_executor(), [client, cluster]
    client = Client(args.dask)
    return client.get_executor(), [client]


def run_sweep(name: str, args: argparse.Namespace, values: Sequence[Any]) -> SweepResult:
    """The study's sweep (resumed if its file exists), on the chosen executor."""
    study = STUDIES[name]
    analysis: dict[str, Any] = {"revolutions": args.revolutions, "transient": args.transient,
                                "per_revolution": args.per_revolution, "twin": True}
    if args.quick:
        analysis.update(revolutions=8, transient=2, per_revolution=16, twin=False)
    executor, closers = executor_for(args)
    try:
        return dc.sweep(args.out / f"{name}.h5", {study["parameter"]: list(values)}, fixed=study["fixed"],
                        options=dc.SolverOptions(rtol=args.rtol), executor=executor, max_workers=args.workers,
                        resume=not args.restart, **analysis)
    finally:
        for obj in closers:
            obj.close()


def _value_text(study: dict[str, Any], value: Any) -> str:
    if value is None:
        return "none"
    unit = f" {study['unit']}" if study["unit"] else ""
    return f"{study['parameter']} = {value * study['scale']:g}{unit}"


def rows(name: str, result: SweepResult) -> list[dict[str, Any]]:
    study = STUDIES[name]
    out = []
    for run in result.runs:
        value = run.parameters[study["parameter"]]
        e = run.evidence
        out.append({
            "case": _value_text(study, value), study["parameter"]: value,
            "motion": (f"periodic (period {run.period})" if run.motion == "periodic" else run.motion)
            if run.ok else f"FAILED: {run.error}",
            "chapter": study["chapter"].get(value, "-"),
            "periodicity_defect": e.get("periodicity_defect", float("nan")),
            "spread": e.get("spread", float("nan")),
            "n_clusters": e.get("n_clusters", 0),
            "decorrelation": e.get("decorrelation", float("nan")),
            "amplification": e.get("twin_amplification", float("nan")),
            "lyapunov_per_revolution": e.get("lyapunov_per_revolution", float("nan")),
            "fit_r2": e.get("fit_r2", float("nan")),
            "wall_time_s": run.wall_time,
        })
    return out


COLUMNS = (("case", "{}"), ("motion", "{}"), ("chapter", "{}"), ("periodicity_defect", "{:.3g}"),
           ("spread", "{:.3g}"), ("n_clusters", "{}"), ("decorrelation", "{:.3g}"), ("amplification", "{:.3g}"),
           ("lyapunov_per_revolution", "{:.3g}"), ("fit_r2", "{:.2f}"), ("wall_time_s", "{:.1f}"))


def markdown(table: list[dict[str, Any]]) -> str:
    def cell(value: Any, fmt: str) -> str:
        if isinstance(value, float) and not math.isfinite(value):
            return "-"
        return fmt.format(value)

    lines = ["| " + " | ".join(c for c, _ in COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(cell(r[c], f) for c, f in COLUMNS) + " |" for r in table]
    return "\n".join(lines)


def figures(name: str, result: SweepResult, out: Path) -> list[Path]:
    import matplotlib.pyplot as plt

    from daeclear.plot import style
    from daeclear.plot import plot_poincare_section

    study = STUDIES[name]
    done = [r for r in result.runs if r.ok]
    ncols = 2
    nrows = max(1, -(-len(done) // ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.3 * nrows + 0.5), squeeze=False)
    for k, (ax, run) in enumerate(zip(axes.ravel(), done)):
        plot_poincare_section(result.section(run), portrait=result.portrait(run), ax=ax)
        label = f"periodic, period {run.period}" if run.motion == "periodic" else run.motion
        ax.set_title(f"({chr(ord('a') + k)}) {_value_text(study, run.parameters[study['parameter']])}: {label}",
                     fontsize="small")
    for ax in axes.ravel()[len(done):]:
        ax.set_visible(False)
    # the shared parameters of the runs (the varied one titles the panels), from 1 µs runs of their scenes
    title = cm.title_of(study["figure"], cm.caption_runs([slider_crank(**run.parameters) for run in done]))
    style.set_title(fig, title)
    fig.tight_layout()
    sections = out / "sections.png"
    fig.savefig(sections, dpi=110)
    plt.close(fig)

    fig, (a, b) = plt.subplots(1, 2, figsize=(9.0, 3.6))
    x = [r.parameters[study["parameter"]] * study["scale"] for r in done]
    a.semilogy(x, [r.evidence.get("periodicity_defect", float("nan")) for r in done], "o-")
    a.axhline(result.options.get("tol", dc.analysis.DEFAULT_TOL), color="k", ls="--", lw=0.8, label="tol")
    a.set_ylabel("periodicity defect (attractor units)")
    a.legend(fontsize="x-small")
    b.plot(x, [r.evidence.get("decorrelation", float("nan")) for r in done], "o-")
    b.axhline(dc.analysis.DEFAULT_DECORRELATION, color="k", ls="--", lw=0.8, label="threshold")
    b.set_ylabel("twin decorrelation")
    b.legend(fontsize="x-small")
    for ax in (a, b):
        ax.set_xlabel(f"{study['parameter']} ({study['unit']})" if study["unit"] else study["parameter"])
    style.set_title(fig, title)
    fig.tight_layout()
    evidence = out / "evidence.png"
    fig.savefig(evidence, dpi=110)
    plt.close(fig)
    return [sections, evidence]


def main(name: str, argv: Sequence[str] | None = None) -> int:
    args = parse_args(name, argv)
    study = STUDIES[name]
    values = study["values"]
    if args.quick:
        values = [values[0], values[-1]]
    result = run_sweep(name, args, values)
    table = rows(name, result)
    text = markdown(table)
    header = (f"# {study['title']}\n\n{result.options.get('revolutions')} revolutions analysed after "
              f"{result.options.get('transient')} of transient, {result.options.get('per_revolution')} samples per "
              f"revolution, rtol {result.solver_options.rtol:g}, twins: {result.options.get('twin')}. "
              f"{result.n_computed} runs computed now, {result.n_skipped} found in the sweep file.\n")
    (args.out / "metrics.md").write_text(header + "\n" + text + "\n")
    (args.out / "metrics.json").write_text(json.dumps({"about": study["title"], "options": result.options,
                                                        "runs": table}, indent=1, default=str))
    print(header)
    print(text)
    written = figures(name, result, args.out)
    print(f"wrote {args.out / (name + '.h5')}, {', '.join(p.name for p in written)}, metrics.json, metrics.md")
    return 0 if all(r.ok for r in result.runs) else 1
