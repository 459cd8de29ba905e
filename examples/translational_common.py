"""Shared helpers of the section 4.5 examples (slider-crank with a translational clearance joint).

Each ``translational_fig*.py`` script parses the same options (:func:`parse_args`), runs its
cases with :func:`run_case`, measures them with :func:`measure` and writes HDF5, PNG and
``metrics.json``/``metrics.md`` into its output directory (``results/<script name>/`` by
default).

Time span of a full run. The chapter reports "two full crank rotations" after the start; the
slider starts midway between the guide surfaces, so the first revolutions are a transient:

    0 .... transient (4 revolutions) .... analysed span (10 revolutions) .... t_end
                                          Poincaré points: once per rev.  |last 2 rev| figures

- ``--transient N`` (default 4) revolutions are simulated and discarded;
- ``--revolutions M`` (default 10) follow: phase portraits, Poincaré points (slider velocity
  and acceleration once per revolution, at crank angle 0) and the span statistics use all of
  them; the time histories, slider paths and HDF5 files the last two.

Two runs per case from one assembled model: uniform output every ``--dt`` (5 us) over the
analysed span (daeclear recomputes the multipliers there: exact crank moments), and output at
every IDA step (contact forces and penetrations at their peaks: a face impact of the
``section-4.3`` model lasts about 15 us). Both runs take the same steps.

``--quick`` simulates 5 ms from t = 0 without transient (smoke tests).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

import daeclear as dc
from daeclear.mechanisms import slider_crank

RPM = 5000.0
PERIOD = 60.0 / RPM  # s per crank revolution
DEFAULT_TRANSIENT = 4
DEFAULT_REVOLUTIONS = 10
WINDOW_REVOLUTIONS = 2  # as in the chapter
DEFAULT_DT = 5e-6  # s
QUICK_SPAN = 0.005  # s
RTOL = 1e-6  # Table 4.3's "integration tolerance"
GRAVITY = 9.81  # m/s^2 along -Y
JOINT = "clearance"  # name of the translational clearance joint in slider_crank("translational")
PAIRS = ("A_upper", "B_upper", "C_lower", "D_lower")


def parse_args(script: str, description: str, argv: Sequence[str] | None = None) -> argparse.Namespace:
    """Common options: ``--quick``, ``--out``, ``--transient``, ``--revolutions``, ``--dt``, ``--rtol``."""
    name = Path(script).stem
    parser = argparse.ArgumentParser(prog=Path(script).name, description=description)
    parser.add_argument("--quick", action="store_true",
                        help=f"simulate only {QUICK_SPAN * 1e3:g} ms from t = 0 (smoke test)")
    parser.add_argument("--out", type=Path, default=Path("results") / name,
                        help=f"output directory (default results/{name}/)")
    parser.add_argument("--transient", type=int, default=DEFAULT_TRANSIENT,
                        help=f"crank revolutions simulated and discarded (default {DEFAULT_TRANSIENT})")
    parser.add_argument("--revolutions", type=int, default=DEFAULT_REVOLUTIONS,
                        help=f"revolutions analysed after the transient, >= 2 (default {DEFAULT_REVOLUTIONS}); "
                             "time histories show the last two")
    parser.add_argument("--dt", type=float, default=DEFAULT_DT,
                        help=f"spacing of the dense output, s (default {DEFAULT_DT:g})")
    parser.add_argument("--rtol", type=float, default=RTOL, help=f"IDA relative tolerance (default {RTOL:g})")
    args = parser.parse_args(argv)
    if args.transient < 0 or args.revolutions < WINDOW_REVOLUTIONS:
        parser.error(f"--transient must be >= 0 and --revolutions >= {WINDOW_REVOLUTIONS}.")
    if not 0 < args.dt <= PERIOD / 100:
        parser.error(f"--dt must be in (0, {PERIOD / 100:g}] s.")
    args.out.mkdir(parents=True, exist_ok=True)
    return args


@dataclass(frozen=True)
class Span:
    """Where a run ends, which part is analysed and which part is plotted (s)."""

    t_end: float
    analysed: tuple[float, float]
    window: tuple[float, float]
    t_eval: np.ndarray
    revolution_times: np.ndarray  # Poincaré section times (crank angle 0); empty with --quick
    quick: bool

    def describe(self) -> str:
        if self.quick:
            return f"quick run: 0 to {self.t_end * 1e3:g} ms, no transient removed"
        n_trans = round(self.analysed[0] / PERIOD)
        n_rev = round((self.analysed[1] - self.analysed[0]) / PERIOD)
        return (f"{n_trans} revolutions of transient discarded, {n_rev} analysed "
                f"({self.analysed[0]:.3f} to {self.analysed[1]:.3f} s), time histories over the last two "
                f"({self.window[0]:.3f} to {self.window[1]:.3f} s)")


def make_span(args: argparse.Namespace) -> Span:
    """The time span of a run from the parsed options (see the module docstring)."""
    if args.quick:
        n = int(round(QUICK_SPAN / args.dt))
        return Span(QUICK_SPAN, (0.0, QUICK_SPAN), (0.0, QUICK_SPAN), np.linspace(0.0, QUICK_SPAN, n + 1),
                    np.zeros(0), True)
    t0 = args.transient * PERIOD
    t_end = (args.transient + args.revolutions) * PERIOD
    per_rev = int(round(PERIOD / args.dt))
    t_eval = t0 + PERIOD * np.arange(args.revolutions * per_rev + 1) / per_rev
    t_eval[-1] = t_end
    return Span(t_end, (t0, t_end), (t_end - WINDOW_REVOLUTIONS * PERIOD, t_end), t_eval,
                t_eval[::per_rev].copy(), False)


def _cut(result: dc.Result, window: tuple[float, float]) -> dc.Result:
    pad = 1e-9 * PERIOD
    return result.slice(window[0] - pad, window[1] + pad)


@dataclass
class Case:
    """One simulated case: dense output (``dense``, ``window``) and per-step output (``steps``...)."""

    label: str
    dense: dc.Result
    window: dc.Result
    steps: dc.Result
    steps_window: dc.Result
    wall_time: float


def run_case(label: str, scene: dc.Scene, span: Span, args: argparse.Namespace, *, verbose: bool = True) -> Case:
    """Assemble ``scene`` once, simulate it with dense and with per-step output, cut the windows."""
    start = time.perf_counter()
    model = dc.assemble(scene)
    dense = dc.simulate(model, span.t_end, t_eval=span.t_eval, rtol=args.rtol)
    per_step = dc.simulate(model, span.t_end, rtol=args.rtol)
    steps = _cut(per_step, span.analysed)
    dense = _cut(dense, span.analysed)
    case = Case(label, dense, _cut(dense, span.window), steps, _cut(steps, span.window),
                time.perf_counter() - start)
    if verbose:
        onsets = per_step.events.of(JOINT, "onset")
        print(f"  {label:<34s} {case.wall_time:6.2f} s   {len(onsets):5d} onsets over 0-{span.t_end:.3f} s, "
              f"{per_step.stats.get('n_steps', 0)} IDA steps (IDA solve {per_step.stats.get('solve_time', 0.0):.3f} s)",
              flush=True)
    return case


def run_ideal(span: Span, args: argparse.Namespace, *, verbose: bool = True) -> Case:
    """The ideal-joint slider-crank over the same span (comparison curves)."""
    return run_case("ideal joint", slider_crank("ideal", gravity=GRAVITY, rpm=RPM), span, args, verbose=verbose)


def scene(clearance: float = 0.5e-3, **kwargs: Any) -> dc.Scene:
    """``slider_crank("translational", ...)`` with the examples' gravity and speed."""
    return slider_crank("translational", clearance=clearance, gravity=GRAVITY, rpm=RPM, **kwargs)


# --------------------------------------------------------------------------- measures


def impacts(result: dc.Result) -> int:
    """Number of impacts: onsets of corner pairs, simultaneous ones (a face landing) counted once."""
    t = np.unique(np.round([e.t for e in result.events.of(JOINT, "onset") if not e.pair.endswith("_face")], 15))
    return int(t.size)


def poincare_points(dense: dc.Result, span: Span, x: str = "slider.vx", y: str = "slider.ax") -> np.ndarray:
    """(x, y) once per crank revolution (crank angle 0) over the analysed span, shape (n, 2)."""
    if span.revolution_times.size == 0:
        return np.zeros((0, 2))
    idx = np.searchsorted(dense.t, span.revolution_times - 1e-9 * PERIOD)
    idx = idx[idx < dense.n_times]
    return np.column_stack([dense[x][idx], dense[y][idx]])


def distinct_points(points: np.ndarray, scale: np.ndarray, tol: float = 0.01) -> int:
    """Clusters of points (1 for a periodic response, n for chaos): a point is new if it differs
    from every kept point by more than ``tol * scale`` in some coordinate."""
    kept: list[np.ndarray] = []
    for p in points:
        if not any(np.all(np.abs(p - q) <= tol * scale) for q in kept):
            kept.append(p)
    return len(kept)


def measure(case: Case, ideal: Case, span: Span) -> dict[str, Any]:
    """The numbers of the validation page for one case (window: last two revolutions)."""
    w, wi = case.window, ideal.window
    if w.t.shape != wi.t.shape or not np.allclose(w.t, wi.t, rtol=0, atol=1e-12):
        raise RuntimeError(f"{case.label}: the clearance and ideal runs have different output times.")
    moment, moment_ideal = np.asarray(w["drive.moment"]), np.asarray(wi["drive.moment"])
    vx, vx_ideal = np.asarray(w["slider.vx"]), np.asarray(wi["slider.vx"])
    s = case.steps
    guide_ok = bool(np.all((s[f"{JOINT}.xi"] > -0.01) & (s[f"{JOINT}.xi"] < 1.01)))
    out: dict[str, Any] = {
        "case": case.label,
        "peak_moment_Nm": float(np.max(np.abs(moment))),
        "peak_moment_ideal_Nm": float(np.max(np.abs(moment_ideal))),
        "rms_moment_dev_Nm": float(np.sqrt(np.mean((moment - moment_ideal) ** 2))),
        "max_vx_dev_rel": float(np.max(np.abs(vx - vx_ideal)) / np.ptp(vx_ideal)),
        "peak_ax_m_s2": float(np.max(np.abs(w["slider.ax"]))),
        "impacts": impacts(case.steps_window),
        "face_onsets": len([e for e in case.steps_window.events.of(JOINT, "onset") if e.pair.endswith("_face")]),
        "contact_fraction": float(np.mean(w[f"{JOINT}.in_contact"] > 0)),
        "peak_force_N": float(np.max(case.steps_window[f"{JOINT}.normal_force"])),
        # over the whole analysed span (per-step output: the peaks are resolved)
        "span_max_penetration_um": float(np.max(s[f"{JOINT}.penetration"]) * 1e6),
        "span_peak_force_N": float(np.max(s[f"{JOINT}.normal_force"])),
        "span_max_tilt_mrad": float(np.max(np.abs(s[f"{JOINT}.tilt"])) * 1e3),
        "span_eta_min": float(np.min(s[f"{JOINT}.eta"])),
        "span_eta_max": float(np.max(s[f"{JOINT}.eta"])),
        "span_slider_in_guide": guide_ok,
        "wall_time_s": case.wall_time,
    }
    if not span.quick:
        d = case.dense
        pts = poincare_points(d, span)
        scale = np.array([np.ptp(ideal.dense["slider.vx"]), np.ptp(ideal.dense["slider.ax"])])
        per_rev_peak = [float(np.max(np.abs(_cut(d, (a, b))["drive.moment"])))
                        for a, b in zip(span.revolution_times[:-1], span.revolution_times[1:])]
        out.update({
            "span_revolutions": len(per_rev_peak),
            "span_peak_moment_median_Nm": float(np.median(per_rev_peak)),
            "span_peak_moment_max_Nm": float(np.max(per_rev_peak)),
            "span_impacts_per_rev": impacts(case.steps) / max(len(per_rev_peak), 1),
            "span_rms_moment_dev_Nm": float(np.sqrt(np.mean((d["drive.moment"] - ideal.dense["drive.moment"]) ** 2))),
            "span_max_vx_dev_rel": float(np.max(np.abs(d["slider.vx"] - ideal.dense["slider.vx"]))
                                         / np.ptp(ideal.dense["slider.vx"])),
            "poincare_n": int(len(pts)),
            "poincare_distinct": distinct_points(pts, scale),
        })
    return out


# --------------------------------------------------------------------------- output


def save_result(result: dc.Result, out: Path, name: str) -> Path:
    return result.save(out / f"{name}.h5")


def save_figure(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


SUMMARY_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("case", "case", "{}"),
    ("peak_moment_Nm", "peak moment (N m)", "{:.0f}"),
    ("rms_moment_dev_Nm", "RMS moment - ideal (N m)", "{:.1f}"),
    ("max_vx_dev_rel", "max dev. of v / range of v_ideal", "{:.2e}"),
    ("impacts", "impacts", "{}"),
    ("face_onsets", "face contacts", "{}"),
    ("contact_fraction", "time in contact", "{:.3f}"),
    ("peak_force_N", "peak contact force (N)", "{:.0f}"),
)
SPAN_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("case", "case", "{}"),
    ("span_peak_moment_median_Nm", "median per-rev peak moment (N m)", "{:.0f}"),
    ("span_peak_moment_max_Nm", "max peak moment (N m)", "{:.0f}"),
    ("span_rms_moment_dev_Nm", "RMS moment - ideal (N m)", "{:.1f}"),
    ("span_max_vx_dev_rel", "max dev. of v / range of v_ideal", "{:.2e}"),
    ("span_impacts_per_rev", "impacts / rev", "{:.1f}"),
    ("span_peak_force_N", "peak contact force (N)", "{:.0f}"),
    ("span_max_penetration_um", "max penetration (um)", "{:.1f}"),
    ("span_max_tilt_mrad", "max tilt (mrad)", "{:.2f}"),
    ("span_eta_min", "min eta", "{:.3f}"),
    ("span_eta_max", "max eta", "{:.3f}"),
    ("poincare_distinct", "distinct Poincaré points", "{}"),
)


def _fmt(value: Any, fmt: str) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return "-"
    return fmt.format(value)


def markdown_table(rows: Sequence[Mapping[str, Any]], columns: Sequence[tuple[str, str, str]]) -> str:
    cols = [c for c in columns if all(c[0] in r for r in rows)]
    lines = ["| " + " | ".join(h for _, h, _ in cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    lines += ["| " + " | ".join(_fmt(r[k], f) for k, _, f in cols) + " |" for r in rows]
    return "\n".join(lines)


def write_metrics(rows: Sequence[Mapping[str, Any]], out: Path, span: Span, header: str, rtol: float) -> None:
    """Write ``metrics.json`` and ``metrics.md`` and print the tables."""
    meta = {"span": span.describe(), "rtol": rtol, "gravity_m_s2": GRAVITY, "rpm": RPM}
    (out / "metrics.json").write_text(json.dumps({"about": header, **meta, "cases": list(rows)}, indent=1))
    text = [f"# {header}", "", span.describe() + f"; rtol {rtol:g}, gravity {GRAVITY} m/s², {RPM:g} rpm.", "",
            "Last two revolutions:", "", markdown_table(rows, SUMMARY_COLUMNS), "",
            "Whole analysed span:", "", markdown_table(rows, SPAN_COLUMNS)]
    (out / "metrics.md").write_text("\n".join(text) + "\n")
    print("\n".join(text[2:]))


def print_written(out: Path) -> None:
    files = sorted(p.name for p in out.iterdir() if p.is_file())
    print(f"wrote {len(files)} files to {out}/: {', '.join(files)}")


@dataclass
class Study:
    """The cases of one figure family, their ideal-joint reference and their measures."""

    header: str
    span: Span
    ideal: Case
    cases: list[Case]
    rows: list[dict[str, Any]]


def run_study(header: str, scenes: Mapping[str, dc.Scene], args: argparse.Namespace) -> Study:
    """Run the ideal joint and every case ``label -> scene``, measure them, save HDF5 and metrics."""
    span = make_span(args)
    print(f"{header}\n{span.describe()}; rtol {args.rtol:g}, gravity {GRAVITY} m/s^2, {RPM:g} rpm", flush=True)
    ideal = run_ideal(span, args)
    cases = [run_case(label, sc, span, args) for label, sc in scenes.items()]
    rows = [measure(case, ideal, span) for case in cases]
    for case in cases:
        save_result(case.window, args.out, _stem(case.label))
    save_result(ideal.window, args.out, "ideal")
    write_metrics(rows, args.out, span, header, args.rtol)
    return Study(header, span, ideal, cases, rows)


def _stem(label: str) -> str:
    keep = "".join(ch if ch.isalnum() or ch in ".-" else "_" for ch in label)
    return "_".join(part for part in keep.split("_") if part)


def panels(study: Study, draw: Any, title: str, *, dense: bool = True, **kwargs: Any) -> Any:
    """One panel per case (the chapter's (a)-(d)), drawn by ``draw(result, ax=ax, **kwargs)``."""
    from daeclear.plot import plot_cases

    results = {case.label: (case.window if dense else case.steps_window) for case in study.cases}
    return plot_cases(results, draw, suptitle=title, **kwargs)
