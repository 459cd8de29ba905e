"""IDA on the chapter's Fig. 4.15 and Fig. 4.28 runs, and its speed against the other integrators.

    python benchmarks/bench_figures.py [--repeats 3] [--write]

For each scene (revolute clearance 0.5 mm, Fig. 4.15; translational clearance 0.5 mm, Fig. 4.28;
Lankarani-Nikravesh c_e = 0.9, gravity, 5000 rpm) it prints:

1. the chapter's run, five crank revolutions (three of transient, two shown) at rtol 1e-6 and
   1e-8: IDA's wall time of the whole ``simulate`` call (best of --repeats, model compiled and
   cached), accepted steps, residual and Jacobian evaluations and contact events;
2. a work-precision study over one revolution (``daeclear.studies.accuracy.work_precision``: reference
   DOP853 at rtol 1e-12, error window where it agrees with IDA at rtol 1e-12), and IDA's speed
   ratio against the fastest explicit method (RK45, DOP853, rk4, euler) and the fastest scipy
   implicit method (Radau, BDF, LSODA) whose error is at most IDA's (equal or better accuracy).

With --write the tables go to their block of docs/work_precision.md (the rest of the page stays)
and the work-precision figures to docs/figures/.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import daeclear as dc
from daeclear.studies.accuracy import work_precision

REV = 60.0 / 5000.0
MARK_BEGIN = "<!-- bench_figures: begin -->"
MARK_END = "<!-- bench_figures: end -->"
HEADER = ("# Work-precision: IDA against explicit and scipy integrators\n\n"
          "Produced by `python benchmarks/bench_figures.py --write` on the project's 2-core machine, shared "
          "with other work. Wall times are best of the repeats of the whole `simulate` call with the model "
          "compiled and cached; compare them as ratios (the speed ratios below), not as absolute times. "
          "The chapter runs' counts are checked by tests/test_doc_numbers.py (within 5 %).\n\n")
EXPLICIT = {"RK45": {"method": "RK45"}, "DOP853": {"method": "DOP853"}, "rk4": {"method": "rk4"},
            "euler": {"method": "euler"}}
IMPLICIT = {"LSODA": {"method": "LSODA"}, "BDF": {"method": "BDF"}, "Radau": {"method": "Radau"}}
SCENES = {
    "Fig. 4.15 (revolute clearance)": lambda: dc.mechanisms.slider_crank("revolute"),
    "Fig. 4.28 (translational clearance)": lambda: dc.mechanisms.slider_crank("translational"),
}


def chapter_run(scene: dc.Scene, rtol: float, repeats: int) -> dict[str, float]:
    model = dc.assemble(scene, "index1")  # the chapter's run: its formulation (Table 4.2)
    dc.simulate(model, 5 * REV, rtol=rtol)  # compile or load, warm up
    best, best_result = math.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = dc.simulate(model, 5 * REV, rtol=rtol)
        elapsed = time.perf_counter() - start
        if elapsed < best:
            best, best_result = elapsed, result
    s = best_result.stats
    return {"wall": best, "solve": s["solve_time"], "steps": s["n_steps"], "res": s["n_res_evals"],
            "jac": s["n_jac_evals"], "events": s["n_events"],
            "events_shown": sum(1 for e in best_result.events if e.t >= 3 * REV)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--write", action="store_true",
                        help="write the tables into docs/work_precision.md, the figures into docs/figures")
    args = parser.parse_args()
    out: list[str] = []

    def say(line: str = "") -> None:
        print(line, flush=True)
        out.append(line)

    for label, make in SCENES.items():
        say(f"## {label}")
        say()
        say("Chapter run, 5 revolutions (3 transient + 2 shown), IDA, whole simulate call:")
        say()
        say("| rtol | whole call / IDA loop | steps | residuals | Jacobians | events (in the 2 shown) |")
        say("|---|---|---|---|---|---|")
        for rtol in (1e-6, 1e-8):
            r = chapter_run(make(), rtol, args.repeats)
            say(f"| {rtol:g} | {r['wall'] / r['solve']:.2f} | {r['steps']} | {r['res']} | {r['jac']} | "
                f"{r['events']} ({r['events_shown']}) |")
        say()
        methods = {"IDA": {"method": "ida"}, **EXPLICIT, **IMPLICIT}
        study = work_precision(make(), REV, channels=["slider.vx", "drive.moment"], methods=methods,
                               rtols=(1e-5, 1e-6, 1e-7, 1e-8, 1e-9), steps=(1e-5, 2.5e-6, 1e-6),
                               repeats=args.repeats, n_eval=2001)
        say("Work-precision over one revolution:")
        say()
        say(study.to_markdown())
        for group, names in (("explicit", list(EXPLICIT)), ("scipy implicit", list(IMPLICIT))):
            for row in study.speed_ratio("IDA", names):
                say(f"- IDA rtol {row['tolerance']:g} (error {row['error']:.2g}) vs fastest "
                    f"{group} at equal or better accuracy, {row['rival']} (error {row['rival_error']:.2g}): "
                    f"IDA {row['ratio']:.1f}x faster")
        say()
        if args.write:
            import matplotlib

            matplotlib.use("Agg")
            import matplotlib.pyplot as plt

            from daeclear.plot import plot_work_precision

            figdir = Path(__file__).resolve().parents[1] / "docs" / "figures"
            figdir.mkdir(parents=True, exist_ok=True)
            fig, ax = plt.subplots(figsize=(7.0, 5.0))
            plot_work_precision(study, ax=ax)
            ax.set_title(f"{label}: {ax.get_title()}", fontsize="small")
            fig.tight_layout()
            name = "work_precision_fig4_15.png" if "4.15" in label else "work_precision_fig4_28.png"
            fig.savefig(figdir / name, dpi=110)
            plt.close(fig)
            say(f"![work-precision {label}](figures/{name})")
            say()
    if args.write:
        path = Path(__file__).resolve().parents[1] / "docs" / "work_precision.md"
        block = "\n".join([MARK_BEGIN, "", *out, MARK_END])
        text = path.read_text() if path.exists() else ""
        if MARK_BEGIN in text:  # only this script's block: the rest of the page (other studies) stays
            text = text[:text.index(MARK_BEGIN)] + block + text[text.index(MARK_END) + len(MARK_END):]
        else:
            text = HEADER + block + "\n" + text
        path.write_text(text)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
