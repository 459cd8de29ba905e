"""Readings of the translational clearance joint against the chapter's description of Fig. 4.28.

The chapter says of its Fig. 4.28 (c = 0.5 mm) that the slider velocity is "smooth and close to
the ideal joint simulation", that slider and guide "are in permanent contact for long periods",
with "some sudden changes" from impacts and "visible high peaks in the crank moment". This
study runs every reading of the model the text supports (:mod:`daeclear.model.readings`: the joint
readings with Table 4.1's mechanism, and daeclear's default joint reading with every mechanism
reading), measures those statements (:mod:`daeclear.studies.response_metrics`) over the analysed span
and over the first two revolutions from the start, and says which readings meet all of
:data:`daeclear.studies.response_metrics.FIG_4_28`.

Each reading is compared with the ideal joint of the same mechanism (same gravity, slider mass
and inertia), on the same output times.

Run ``python examples/translational_readings.py`` (a few minutes; ``--quick``: 5 ms of each
reading, smoke test; ``--figures DIR`` also writes the figures there, e.g. docs/figures).
Writes ``metrics.json``, ``metrics.md`` and two PNGs into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
import warnings
from pathlib import Path
from typing import Any
from collections.abc import Sequence

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import translational_common as tc  # noqa: E402
import daeclear as dc  # noqa: E402
from daeclear.model import readings  # noqa: E402
from daeclear.model.mechanisms import slider_crank  # noqa: E402
from daeclear.studies.response_metrics import FIG_4_28, measure, verdict  # noqa: E402

JOINT = tc.JOINT
#: (joint reading, mechanism reading): every joint reading with Table 4.1's mechanism, then the
#: default joint reading with every other mechanism reading.
CASES: tuple[tuple[str, str], ...] = tuple((r, "table-4.1") for r in readings.JOINT_READINGS) + tuple(
    ("corners", m) for m in readings.MECHANISM_READINGS if m != "table-4.1") + (
    ("corners", "steel-block+friction-0.1"),  # the in-text changes that lengthen the contacts, together
)
FIRST = 2  # revolutions from the start measured as the chapter's "two full crank rotations"
IDEAL_KEYS = ("gravity", "slider_mass", "slider_inertia")  # what of a mechanism reading the ideal joint shares


def parse_args(argv: Sequence[str] | None = None) -> argparse.Namespace:
    """The options of ``translational_common.parse_args``, and ``--figures DIR`` (a copy of the PNGs)."""
    parser_args = list(argv) if argv is not None else sys.argv[1:]
    figures = None
    if "--figures" in parser_args:
        i = parser_args.index("--figures")
        if i + 1 >= len(parser_args) or parser_args[i + 1].startswith("--"):
            raise SystemExit("translational_readings.py: --figures needs a directory (e.g. docs/figures).")
        figures = Path(parser_args[i + 1])
        del parser_args[i:i + 2]
    args = tc.parse_args(__file__, __doc__.splitlines()[0], parser_args)
    args.figures = figures
    return args


def label(case: tuple[str, str]) -> str:
    return case[0] if case[1] == "table-4.1" else f"{case[0]} + {case[1]}"


def _simulate(scene: dc.Scene, t_eval: np.ndarray, rtol: float) -> tuple[dc.Result, float, list[str]]:
    """Run ``scene`` on ``t_eval``; the wall time and the physics warnings (kept in the metrics)."""
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", dc.PhysicsWarning)
        result = dc.simulate(scene, float(t_eval[-1]), rtol=rtol, save=dc.SaveAt(times=t_eval))
    found = [str(w.message) for w in caught if issubclass(w.category, dc.PhysicsWarning)]
    return result, time.perf_counter() - start, found


def run(args: argparse.Namespace) -> list[dict[str, Any]]:
    """Simulate every case and its ideal joint from t = 0; measure the windows."""
    period = tc.PERIOD
    if args.quick:
        t_end, windows = tc.QUICK_SPAN, {"span": (0.0, tc.QUICK_SPAN)}
    else:
        t_end = (args.transient + args.revolutions) * period
        windows = {"span": (args.transient * period, t_end), "first": (0.0, FIRST * period)}
    per_rev = int(round(period / args.dt))
    t_eval = np.linspace(0.0, t_end, int(round(t_end / period * per_rev)) + 1)
    ideals: dict[tuple, dc.Result] = {}
    rows = []
    for case in CASES:
        joint_name, mechanism_name = case
        options = readings.mechanism_options(mechanism_name)
        in_text = all(readings.mechanism_reading(m).in_text for m in mechanism_name.split("+"))
        scene = readings.slider_crank_scene(joint_name, mechanism_name, rpm=tc.RPM,
                                            gravity=options.get("gravity", tc.GRAVITY))
        ideal_options = {k: v for k, v in options.items() if k in IDEAL_KEYS}
        key = tuple(sorted(ideal_options.items()))
        if key not in ideals:
            ideals[key] = _simulate(slider_crank("ideal", rpm=tc.RPM, **{"gravity": tc.GRAVITY, **ideal_options}),
                                    t_eval, args.rtol)[0]
        result, wall, found = _simulate(scene, t_eval, args.rtol)
        row: dict[str, Any] = {"case": label(case), "joint_reading": joint_name, "mechanism_reading": mechanism_name,
                               "in_text": in_text, "wall_time_s": wall,
                               "n_steps": int(result.stats.get("n_steps", 0)),
                               "physics_warnings": found}
        for window, (t0, t1) in windows.items():
            numbers = measure(result, ideals[key], joint=JOINT, period=period, t0=t0, t1=t1)
            row.update({f"{window}.{k}": v for k, v in numbers.items()})
            ok, missed = verdict(numbers)
            row[f"{window}.reproduces"], row[f"{window}.missed"] = ok, missed
        row["max_penetration_um"] = float(np.max(result[f"{JOINT}.penetration"]) * 1e6)
        row["slider_in_guide"] = bool(np.all((result[f"{JOINT}.xi"] > -0.01) & (result[f"{JOINT}.xi"] < 1.01)))
        rows.append(row)
        print(f"  {row['case']:<36s} {wall:6.1f} s  contact {row['span.contact_fraction']:.3f}  long "
              f"{row['span.long_contact_fraction']:.3f}  v-rms {row['span.velocity_rms_rel']:.4f}  impacts/rev "
              f"{row['span.impacts_per_rev']:.1f}  moment x{row['span.moment_peak_ratio']:.2f}  "
              f"{'REPRODUCES' if row['span.reproduces'] else 'misses ' + ', '.join(row['span.missed'])}", flush=True)
        if not args.quick:
            row["_series"] = _series(result, ideals[key], windows["span"][1] - tc.WINDOW_REVOLUTIONS * period, t_end)
    return rows


def _series(result: dc.Result, ideal: dc.Result, t0: float, t1: float) -> dict[str, np.ndarray]:
    """The last two revolutions of what the figures draw."""
    w = (result.t >= t0 - 1e-12) & (result.t <= t1 + 1e-12)
    return {"t": result.t[w] - t0, "contact": np.asarray(result[f"{JOINT}.in_contact"])[w],
            "dv": np.asarray(result["slider.vx"])[w] - np.asarray(ideal["slider.vx"])[w],
            "eta": np.asarray(result[f"{JOINT}.eta"])[w], "xi": np.asarray(result[f"{JOINT}.xi"])[w]}


# --------------------------------------------------------------------------- output

COLUMNS = (
    ("case", "reading", "{}"),
    ("contact_fraction", "in contact", "{:.2f}"),
    ("long_contact_fraction", "in contacts >= 1/8 rev", "{:.2f}"),
    ("median_contact_ms", "median contact (ms)", "{:.2f}"),
    ("longest_contact_ms", "longest contact (ms)", "{:.2f}"),
    ("velocity_rms_rel", "RMS(v - v_ideal) / range", "{:.4f}"),
    ("velocity_rms_rel_free", "same, in flight only", "{:.4f}"),
    ("impacts_per_rev", "impacts / rev", "{:.1f}"),
    ("moment_peak_median_Nm", "median peak moment (N m)", "{:.0f}"),
    ("moment_peak_ratio", "/ ideal peak", "{:.2f}"),
    ("max_tilt_mrad", "max tilt (mrad)", "{:.2f}"),
)


def table(rows: Sequence[dict[str, Any]], window: str) -> str:
    head = [title for _, title, _ in COLUMNS] + ["meets Fig. 4.28's description"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [fmt.format(row["case"] if key == "case" else row[f"{window}.{key}"]) for key, _, fmt in COLUMNS]
        missed = row[f"{window}.missed"]
        cells.append("**yes**" if row[f"{window}.reproduces"] else "no: " + ", ".join(missed))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def criteria_table() -> str:
    lines = ["| chapter | measured as |", "|---|---|"]
    lines += [f"| \"{c.statement}\" | `{c.key}`: {c.reading} |" for c in FIG_4_28]
    return "\n".join(lines)


def write(rows: Sequence[dict[str, Any]], args: argparse.Namespace) -> None:
    plain = [{k: v for k, v in row.items() if not k.startswith("_")} for row in rows]
    (args.out / "metrics.json").write_text(json.dumps({"cases": plain, "quick": args.quick, "rtol": args.rtol,
                                                       "transient": args.transient,
                                                       "revolutions": args.revolutions}, indent=1))
    text = ["# Readings of the translational clearance joint against Fig. 4.28", "", criteria_table(), ""]
    for window, title in (("span", "Analysed span" if not args.quick else "Quick run (0-5 ms)"),
                          ("first", f"First {FIRST} revolutions from the start")):
        if f"{window}.contact_fraction" in rows[0]:
            text += [f"## {title}", "", table(rows, window), ""]
    (args.out / "metrics.md").write_text("\n".join(text))
    print("\n".join(text))


def contact_figure(rows: Sequence[dict[str, Any]]) -> Any:
    """Contact periods over the last two revolutions, one line per reading."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 0.32 * len(rows) + 1.2))
    for i, row in enumerate(rows):
        s = row["_series"]
        on = s["contact"] > 0.5
        edges = np.diff(np.r_[0, on.astype(int), 0])
        a, b = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        dt = s["t"][1] - s["t"][0]
        ax.broken_barh([(s["t"][j] * 1e3, max((k - j) * dt * 1e3, 0.02)) for j, k in zip(a, b)], (i - 0.35, 0.7),
                       color="tab:green" if row["span.reproduces"] else "tab:gray")
        ax.text(24.2, i, f"{row['span.contact_fraction']:.0%}", va="center", fontsize=7)
    ax.set_yticks(range(len(rows)), [row["case"] for row in rows], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlim(0, 26.5)
    ax.set_xlabel("time in the last two revolutions (ms)", fontsize=8)
    ax.tick_params(axis="x", labelsize=7)
    ax.set_title("Slider-guide contact periods by reading, c = 0.5 mm, 5000 rpm (right: time in contact)",
                 fontsize=8)
    fig.tight_layout()
    return fig


def velocity_figure(rows: Sequence[dict[str, Any]]) -> Any:
    """Slider velocity minus the ideal joint's, last two revolutions, per reading."""
    import matplotlib.pyplot as plt

    n = len(rows)
    cols = 3
    fig, axes = plt.subplots((n + cols - 1) // cols, cols, figsize=(8.5, 1.45 * ((n + cols - 1) // cols) + 0.6),
                             sharex=True, sharey=True, squeeze=False)
    for ax, row in zip(axes.flat, rows):
        s = row["_series"]
        ax.plot(s["t"] * 1e3, s["dv"], lw=0.6)
        ax.set_title(f"{row['case']}: RMS {row['span.velocity_rms_rel']:.2%}", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("t in the last two revolutions (ms)", fontsize=7)
    for ax in axes[:, 0]:
        ax.set_ylabel("v - v_ideal (m/s)", fontsize=7)
    fig.suptitle("Slider velocity minus the ideal joint's (RMS over the analysed span / ideal range)", fontsize=8)
    fig.tight_layout()
    return fig


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    rows = run(args)
    write(rows, args)
    if not args.quick:
        for name, draw in (("readings_contact.png", contact_figure), ("readings_velocity.png", velocity_figure)):
            path = tc.save_figure(draw(rows), args.out / name, dpi=72)
            if args.figures is not None:
                args.figures.mkdir(parents=True, exist_ok=True)
                shutil.copy(path, args.figures / name)
    tc.print_written(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
