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
from pathlib import Path
from typing import Any
from collections.abc import Mapping, Sequence

import numpy as np

import _common
import daeclear as dc
from _common import (  # noqa: F401  (re-exported: the translational scripts use them as tc.*)
    DEFAULT_DT, DEFAULT_TRANSIENT, GRAVITY, PERIOD, QUICK_SPAN, RPM, RTOL, WINDOW_REVOLUTIONS, Case, Span, Study,
    distinct_points, figure_title, markdown_table, poincare_points, print_written, save_figure, save_result,
    study_title, title_of,
)
from daeclear.model.mechanisms import slider_crank

DEFAULT_REVOLUTIONS = 10  # revolutions analysed after the transient (section 4.4's examples: 20)
WINDOW_LABEL = "time histories"  # what shows the last two revolutions (Span.describe, --help)
JOINT = "clearance"  # name of the translational clearance joint in slider_crank("translational")
PAIRS = ("A_upper", "B_upper", "C_lower", "D_lower")

_cut = _common._window


def parse_args(script: str, description: str, argv: Sequence[str] | None = None) -> argparse.Namespace:
    """Common options: ``--quick``, ``--out``, ``--transient``, ``--revolutions``, ``--dt``, ``--rtol``."""
    return _common.parse_args(script, description, argv, revolutions=DEFAULT_REVOLUTIONS, window_text=WINDOW_LABEL,
                              jobs=False)


def make_span(args: argparse.Namespace) -> Span:
    """The time span of a run from the parsed options (see the module docstring)."""
    return _common.make_span(args, window_label=WINDOW_LABEL)


def _progress_line(case: Case, t_end: float) -> str:
    return (f"  {case.label:<34s} {case.wall_time:6.2f} s   {case.n_impacts:5d} onsets over 0-{t_end:.3f} s, "
            f"{case.n_steps} IDA steps (IDA solve {case.solve_time:.3f} s)")


# run_case keywords of the section 4.5 examples: onsets of the clearance joint, no event check
RUN_KWARGS: dict[str, Any] = {"check_events": False, "impact_pair": JOINT, "progress": _progress_line}


def run_case(label: str, scene: dc.Scene, span: Span, args: argparse.Namespace, *, verbose: bool = True) -> Case:
    """Assemble ``scene`` once, simulate it with dense and with per-step output, cut the windows."""
    return _common.run_case(label, scene, span, args, verbose=verbose, **RUN_KWARGS)


def run_ideal(span: Span, args: argparse.Namespace, *, verbose: bool = True) -> Case:
    """The ideal-joint slider-crank over the same span (comparison curves)."""
    return _common.run_ideal(span, args, verbose=verbose, **RUN_KWARGS)


def scene(clearance: float = 0.5e-3, **kwargs: Any) -> dc.Scene:
    """``slider_crank("translational", ...)`` with the examples' gravity and speed."""
    return slider_crank("translational", clearance=clearance, gravity=GRAVITY, rpm=RPM, **kwargs)


# --------------------------------------------------------------------------- measures


def impacts(result: dc.Result) -> int:
    """Number of impacts: onsets of corner pairs, simultaneous ones (a face landing) counted once."""
    t = np.unique(np.round([e.t for e in result.events.of(JOINT, "onset") if not e.pair.endswith("_face")], 15))
    return int(t.size)


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


# tables of metrics.md (the span table also with --quick: then only the case column)
SECTIONS: tuple[_common.Section, ...] = (
    ("Last two revolutions:", SUMMARY_COLUMNS, True),
    ("Whole analysed span:", SPAN_COLUMNS, True),
)


def write_metrics(rows: Sequence[Mapping[str, Any]], out: Path, span: Span, header: str, rtol: float) -> None:
    """Write ``metrics.json`` and ``metrics.md`` and print the tables."""
    _common.write_metrics(rows, out, span, header, rtol, sections=SECTIONS)


def run_study(header: str, scenes: Mapping[str, dc.Scene], args: argparse.Namespace) -> Study:
    """Run the ideal joint and every case ``label -> scene`` and measure them (:func:`save_study` writes them)."""
    return _common.run_study(header, {label: (_stem(label), sc) for label, sc in scenes.items()}, args,
                             span=make_span(args), measure_case=measure, **RUN_KWARGS)


def save_study(study: Study, args: argparse.Namespace) -> None:
    """HDF5 of every case and of the ideal joint over the plotted window, and the metrics, into ``args.out``."""
    _common.save_study(study, args.out, args.rtol, sections=SECTIONS)


def save_figures(figures: Mapping[str, Any], out: Path) -> None:
    """Draw and write every figure of ``file name -> function drawing it``."""
    for name, draw in figures.items():
        save_figure(draw(), out / name)


def _stem(label: str) -> str:
    keep = "".join(ch if ch.isalnum() or ch in ".-" else "_" for ch in label)
    return "_".join(part for part in keep.split("_") if part)


def panels(study: Study, draw: Any, title: str, *, dense: bool = True, span: bool = False, **kwargs: Any) -> Any:
    """One panel per case (the chapter's (a)-(d)), drawn by ``draw(result, ax=ax, **kwargs)``.

    ``title`` says what the figure shows; the parameters the cases share are added on a second
    line, the case labels (the varied parameter) title the panels. ``dense``: the dense output
    (else the per-step one) over the last two revolutions, or with ``span`` over the analysed span.
    """
    from daeclear.plot import plot_cases

    results = {case.label: (case.dense if span else case.window if dense else case.steps_window)
               for case in study.cases}
    return plot_cases(results, draw, suptitle=study_title(study, title), **kwargs)
