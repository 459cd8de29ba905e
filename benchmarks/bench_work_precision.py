"""IDA against every scipy method at equal accuracy, each run a whole ``simulate(scene, ...)`` call.

    python benchmarks/bench_work_precision.py [--repeats 10] [--write]

The Fig. 4.15 scene (revolute clearance 0.5 mm, Lankarani-Nikravesh c_e = 0.9, 5000 rpm, no
gravity, from t = 0) on two windows: the first 2 ms (first impacts) and two crank revolutions.
Every run is timed as users call it: a Scene in, assembly and set-up included (best of
--repeats after a warm-up). The reference is DOP853 at rtol 1e-12; errors are measured where it
agrees with IDA at rtol 1e-12. For each IDA tolerance the table gives the fastest scipy method
(RK45, DOP853, Radau, BDF, LSODA) whose error is at most IDA's, and the ratio of wall times
(target: IDA at least 5x faster). IDA runs twice: its default formulation (GGL) and index1, the
equations the scipy methods integrate. --write puts the tables in docs/work_precision.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import daeclear as dc
from daeclear.studies.accuracy import work_precision

REV = 60.0 / 5000.0
RIVALS = {name: {"method": name} for name in ("RK45", "DOP853", "Radau", "BDF", "LSODA")}
# IDA's default formulation, and index1: the same equations as the scipy methods
IDA_RUNS = {"IDA GGL": {"method": "ida"}, "IDA index1": {"method": "ida", "formulation": "index1"}}
# window -> (t_end, channels): over two revolutions the impact spikes of the crank moment move with
# the tiniest change of an impact time, so the error is measured on the slider velocity there
WINDOWS = {"first 2 ms (first impacts)": (0.002, ["slider.vx", "drive.moment"]),
           "two crank revolutions": (2 * REV, ["slider.vx"])}
MARK_BEGIN = "<!-- bench_work_precision: begin -->"
MARK_END = "<!-- bench_work_precision: end -->"


def study(t_end: float, channels: list[str], repeats: int) -> list[str]:
    scene = dc.mechanisms.slider_crank("revolute", gravity=0.0)
    wp = work_precision(scene, t_end, channels=channels, rtols=np.logspace(-5, -9, 5),
                        methods={**IDA_RUNS, **RIVALS}, repeats=repeats, n_eval=400)
    lines = ["| IDA | rtol | IDA error | IDA wall | fastest scipy method at equal or better error | its error "
             "| its wall | ratio |",
             "|---|---|---|---|---|---|---|---|"]
    for row in (r for r in wp.rows if r["label"] in IDA_RUNS):
        rivals = [r for r in wp.rows if r["label"] in RIVALS and r["status"] == 0 and r["error"] <= row["error"]]
        head = f"| {row['label'][4:]} | {row['tolerance']:.0e} | {row['error']:.2e} | {row['wall_time'] * 1e3:.1f} ms"
        if not rivals or row["status"] != 0:
            lines.append(head + " | none | | | |")
            continue
        best = min(rivals, key=lambda r: r["wall_time"])
        lines.append(f"{head} | {best['label']} rtol {best['tolerance']:.0e} | {best['error']:.2e} | "
                     f"{best['wall_time'] * 1e3:.1f} ms | {best['wall_time'] / row['wall_time']:.1f}x |")
    lines.append("")
    lines.append(f"Error: channels {', '.join(channels)}; window t in [{wp.window[0]:.4g}, {wp.window[1]:.4g}] s. "
                 + " ".join(wp.notes))
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--write", action="store_true", help="write the tables into docs/work_precision.md")
    args = parser.parse_args()
    out = []
    for label, (t_end, channels) in WINDOWS.items():
        out += [f"### Fig. 4.15 scene, {label}, whole simulate(scene) calls", ""]
        out += study(t_end, channels, args.repeats) + [""]
        print("\n".join(out[-17:]), flush=True)
    if args.write:
        path = Path(__file__).resolve().parent.parent / "docs" / "work_precision.md"
        text = path.read_text()
        block = "\n".join([MARK_BEGIN, "", *out, MARK_END])
        if MARK_BEGIN in text:
            text = text[:text.index(MARK_BEGIN)] + block + text[text.index(MARK_END) + len(MARK_END):]
        else:
            title = "## IDA against scipy, Scene in (`python benchmarks/bench_work_precision.py`)"
            text = text.rstrip() + "\n\n" + title + "\n\n" + block + "\n"
        path.write_text(text)
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
