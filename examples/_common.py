"""Shared helpers of the section 4.4 examples (slider-crank with a revolute clearance joint).

Each ``revolute_*.py`` script parses the same options (:func:`parse_args`), runs its cases
with :func:`run_case`, measures them with :func:`measure` and writes HDF5, PNG and
``metrics.json``/``metrics.md`` into its output directory.

Time span of a full run (the chapter reports "two full crank rotations after steady-state
has been reached"; the journal starts centred in the bearing, so the first revolutions are
a start-up transient):

    0 ........ transient (4 revolutions) ........ analysed span (20 revolutions) ........ t_end
                                                   Poincaré points: once per revolution   |last 2 rev|
                                                                                            figures

- ``--transient N`` (default 4) revolutions are simulated and discarded;
- ``--revolutions M`` (default 20) revolutions follow: the Poincaré points (slider velocity
  and acceleration once per revolution, at crank angle 0) and the per-revolution statistics
  come from all of them, the time-history figures and the HDF5 files from the last two.

Two runs per case, from the same assembled model: one with a uniform ``SaveAt.times`` over the
analysed span (``--dt``, 5 us by default), on the same grid as the ideal joint's run (moment
differences, Poincaré points at exact revolution times), and one with output at every IDA step
(``SaveAt()``, every step), used for the journal orbit with one marker per step and for the step sizes.
``times`` does not change IDA's steps, so both runs take the same steps and find the same
events (:func:`run_case` warns otherwise).

``--quick`` simulates 5 ms from t = 0, without transient and Poincaré points (smoke tests).
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import os
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from collections.abc import Callable, Mapping, Sequence

import numpy as np

import daeclear as dc
from daeclear.plot import style
from daeclear.model.mechanisms import slider_crank
from daeclear.plot.joint_figures import _contact_intervals as contact_intervals

RPM = 5000.0
PERIOD = 60.0 / RPM  # s per crank revolution (0.012 s at 5000 rpm)
DEFAULT_TRANSIENT = 4  # revolutions simulated and discarded
DEFAULT_REVOLUTIONS = 20  # revolutions analysed after the transient; figures show the last 2
WINDOW_REVOLUTIONS = 2  # as in the chapter
DEFAULT_DT = 5e-6  # s between dense output points
QUICK_SPAN = 0.005  # s simulated with --quick
RTOL = 1e-6  # Table 4.2's "integration tolerance"
GRAVITY = 9.81  # m/s^2 along -Y (slider_crank's default), stated in every summary
PAIR = "clearance"  # name of the revolute clearance joint in slider_crank("revolute")


def parse_args(script: str, description: str, argv: Sequence[str] | None = None, *,
               revolutions: int = DEFAULT_REVOLUTIONS, window_text: str = "figures",
               jobs: bool = True) -> argparse.Namespace:
    """Common options: ``--quick``, ``--out``, ``--transient``, ``--revolutions``, ``--dt``, ``--rtol``, ``--jobs``.

    ``revolutions`` is the default of ``--revolutions``, ``window_text`` what shows the last two
    revolutions (help text), ``jobs=False`` leaves ``--jobs`` out (the cases then run one by one).
    """
    name = Path(script).stem
    parser = argparse.ArgumentParser(prog=Path(script).name, description=description)
    parser.add_argument("--quick", action="store_true",
                        help=f"simulate only {QUICK_SPAN * 1e3:g} ms from t = 0 (smoke test)")
    parser.add_argument("--out", type=Path, default=Path("results") / name,
                        help=f"output directory (default results/{name}/)")
    parser.add_argument("--transient", type=int, default=DEFAULT_TRANSIENT,
                        help=f"crank revolutions simulated and discarded (default {DEFAULT_TRANSIENT})")
    parser.add_argument("--revolutions", type=int, default=revolutions,
                        help=f"revolutions analysed after the transient, >= 2 (default {revolutions}); "
                             f"{window_text} show the last two")
    parser.add_argument("--dt", type=float, default=DEFAULT_DT,
                        help=f"spacing of the dense output, s (default {DEFAULT_DT:g})")
    parser.add_argument("--rtol", type=float, default=RTOL, help=f"IDA relative tolerance (default {RTOL:g})")
    if jobs:
        parser.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                            help="cases run at once, one process each (default: 2, or 1 on a one-core machine)")
    args = parser.parse_args(argv)
    if args.transient < 0 or args.revolutions < WINDOW_REVOLUTIONS:
        parser.error(f"--transient must be >= 0 and --revolutions >= {WINDOW_REVOLUTIONS}.")
    if not 0 < args.dt <= PERIOD / 100:
        parser.error(f"--dt must be in (0, {PERIOD / 100:g}] s.")
    args.out.mkdir(parents=True, exist_ok=True)
    return args


# --------------------------------------------------------------------------- time span


@dataclass(frozen=True)
class Span:
    """Where a run ends, which part is analysed and which part is plotted (s)."""

    t_end: float
    analysed: tuple[float, float]
    window: tuple[float, float]
    t_eval: np.ndarray
    revolution_times: np.ndarray  # Poincaré section times (crank angle 0), empty with --quick
    quick: bool
    window_label: str = "figures"  # what shows the window, in describe()

    def describe(self) -> str:
        if self.quick:
            return f"quick run: 0 to {self.t_end * 1e3:g} ms, no transient removed"
        n_trans = round(self.analysed[0] / PERIOD)
        n_rev = round((self.analysed[1] - self.analysed[0]) / PERIOD)
        return (f"{n_trans} revolutions of transient discarded, {n_rev} analysed "
                f"({self.analysed[0]:.3f} to {self.analysed[1]:.3f} s), {self.window_label} over the last two "
                f"({self.window[0]:.3f} to {self.window[1]:.3f} s)")


def make_span(args: argparse.Namespace, *, window_label: str = "figures") -> Span:
    """The time span of a run from the parsed options (see the module docstring)."""
    if args.quick:
        n = int(round(QUICK_SPAN / args.dt))
        t_eval = np.linspace(0.0, QUICK_SPAN, n + 1)
        return Span(QUICK_SPAN, (0.0, QUICK_SPAN), (0.0, QUICK_SPAN), t_eval, np.zeros(0), True, window_label)
    t0 = args.transient * PERIOD
    t_end = (args.transient + args.revolutions) * PERIOD
    per_rev = int(round(PERIOD / args.dt))
    k = np.arange(args.revolutions * per_rev + 1)
    t_eval = t0 + PERIOD * k / per_rev  # revolution boundaries fall exactly on output points
    t_eval[-1] = t_end
    return Span(t_end, (t0, t_end), (t_end - WINDOW_REVOLUTIONS * PERIOD, t_end), t_eval,
                t_eval[::per_rev].copy(), False, window_label)


def _window(result: dc.Result, window: tuple[float, float]) -> dc.Result:
    pad = 1e-9 * PERIOD  # output times computed as t0 + T k/n may differ from the bounds by an ulp
    return result.slice(window[0] - pad, window[1] + pad)


# --------------------------------------------------------------------------- runs


@dataclass
class Case:
    """One simulated case.

    dense : output every ``--dt`` over the analysed span (same grid as the ideal joint's run).
    window : ``dense`` restricted to the plotted window (last two revolutions).
    steps : output at every IDA step over the analysed span (positions, forces, step sizes).
    steps_window : ``steps`` restricted to the plotted window (orbit markers, step-size figure).
    """

    label: str
    dense: dc.Result
    window: dc.Result
    steps: dc.Result
    steps_window: dc.Result
    wall_time: float  # s, both runs and the windows
    n_impacts: int  # over the whole run, transient included
    n_steps: int  # IDA steps over the whole run
    solve_time: float  # s, IDA alone (one run)

    def progress_line(self, t_end: float) -> str:
        return (f"  {self.label:<40s} {self.wall_time:6.2f} s   {self.n_impacts:4d} impacts over 0-{t_end:.3f} s, "
                f"{self.n_steps} IDA steps (IDA solve {self.solve_time:.3f} s)")


Progress = Callable[[Case, float], str]  # (case, t_end) -> progress line


def run_case(label: str, scene: dc.Scene, span: Span, args: argparse.Namespace, *, verbose: bool = True,
             check_events: bool = True, impact_pair: str | None = None, progress: Progress | None = None) -> Case:
    """Assemble ``scene`` once, simulate it twice (dense output, per-step output) and cut the windows.

    ``check_events``: warn if the two runs found different events; ``impact_pair``: the pair whose
    onsets ``Case.n_impacts`` counts (None: every pair); ``progress``: the printed line
    (default :meth:`Case.progress_line`).
    """
    start = time.perf_counter()
    model = dc.assemble(scene, "index1")  # the chapter's formulation (Tables 4.2, 4.3: Baumgarte 5, 5)
    dense = dc.simulate(model, span.t_end, rtol=args.rtol, save=dc.SaveAt(times=span.t_eval))
    per_step = dc.simulate(model, span.t_end, rtol=args.rtol)
    if check_events and not np.array_equal(dense.events.t, per_step.events.t):  # also when the counts differ
        warnings.warn(f"{label}: the dense and per-step runs found different events "
                      f"({len(dense.events)} and {len(per_step.events)}); the orbit figure may not match.",
                      stacklevel=2)
    dense = _window(dense, span.analysed)  # t_eval starts there, but the events of the transient are kept
    steps = _window(per_step, span.analysed)
    case = Case(label, dense, _window(dense, span.window), steps, _window(steps, span.window),
                time.perf_counter() - start, len(per_step.events.of(impact_pair, "onset")),
                int(per_step.stats.get("n_steps", len(per_step.step_t))),
                float(per_step.stats.get("solve_time", float("nan"))))
    if verbose:
        print(_progress_line(case, span.t_end, progress), flush=True)
    return case


def _progress_line(case: Case, t_end: float, progress: Progress | None) -> str:
    return case.progress_line(t_end) if progress is None else progress(case, t_end)


def run_cases(scenes: Mapping[str, dc.Scene], span: Span, args: argparse.Namespace, **run_kwargs: Any) -> list[Case]:
    """:func:`run_case` for every ``label -> scene``, on ``args.jobs`` processes; in the given order.

    ``run_kwargs``: keyword arguments of :func:`run_case` (``check_events``, ``impact_pair``, ``progress``).
    """
    jobs = max(1, min(int(getattr(args, "jobs", 1)), len(scenes)))
    if jobs == 1:
        return [run_case(label, scene, span, args, **run_kwargs) for label, scene in scenes.items()]
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # fork: the workers inherit the imported modules (this file is not an installed module)
    context = multiprocessing.get_context("fork")
    done: dict[str, Case] = {}
    with ProcessPoolExecutor(jobs, mp_context=context) as pool:
        futures = {pool.submit(run_case, label, scene, span, args, **{**run_kwargs, "verbose": False}): label
                   for label, scene in scenes.items()}
        for future in as_completed(futures):
            case = future.result()
            print(_progress_line(case, span.t_end, run_kwargs.get("progress")), flush=True)
            done[futures[future]] = case
    return [done[label] for label in scenes]


def parallel_map(function: Any, items: Sequence[Any], jobs: int) -> list[Any]:
    """``[function(*item) for item in items]`` on up to ``jobs`` forked processes, in order.

    ``function`` must be a module-level function of an importable module (e.g. this one).
    """
    jobs = max(1, min(int(jobs), len(items)))
    if jobs == 1:
        return [function(*item) for item in items]
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("fork")) as pool:
        return list(pool.map(function, *zip(*items)))


def first_impact(scene: dc.Scene, rtol: float, t_end: float, n_points: int) -> tuple[dc.Result, Any, Any]:
    """The first contact of ``PAIR``: the run to ``t_end`` locates its onset and separation, a second
    run of the same model with ``n_points`` output times between them resolves it.

    Returns the fine result over the impact and the onset and separation events.
    """
    model = dc.assemble(scene, "index1")  # the chapter's formulation (Table 4.2)
    coarse = dc.simulate(model, t_end, rtol=rtol)
    onset = coarse.events.of(PAIR, "onset")[0]
    separation = [e for e in coarse.events.of(PAIR, "separation") if e.t > onset.t][0]
    fine = dc.simulate(model, t_end, rtol=rtol, save=dc.SaveAt(times=np.linspace(onset.t, separation.t, n_points)))
    return fine.slice(onset.t, separation.t), onset, separation


def ideal_scene() -> dc.Scene:
    """The ideal-joint slider-crank (comparison curves)."""
    return slider_crank("ideal", gravity=GRAVITY, rpm=RPM)


def run_ideal(span: Span, args: argparse.Namespace, *, verbose: bool = True, **run_kwargs: Any) -> Case:
    """The ideal-joint slider-crank over the same span (comparison curves)."""
    return run_case("ideal joint", ideal_scene(), span, args, verbose=verbose, **run_kwargs)


# --------------------------------------------------------------------------- measures


def _intervals_in(result: dc.Result) -> tuple[list[tuple[float, float]], list[float]]:
    """Contact intervals of the window and the durations of the complete ones (onset and separation inside)."""
    intervals = contact_intervals(result, PAIR)
    onsets = set(result.events.of(PAIR, "onset").t.tolist())
    seps = set(result.events.of(PAIR, "separation").t.tolist())
    complete = [b - a for a, b in intervals if a in onsets and b in seps]
    return intervals, complete


def free_flights(result: dc.Result) -> list[float]:
    """Durations (s) of the complete free flights of the window (separation to next onset)."""
    intervals = contact_intervals(result, PAIR)
    return [b[0] - a[1] for a, b in zip(intervals[:-1], intervals[1:])]


def contact_fraction(result: dc.Result) -> float:
    """Fraction of the result's time span spent in contact (from the events)."""
    span = float(result.t[-1] - result.t[0])
    intervals, _ = _intervals_in(result)
    return sum(b - a for a, b in intervals) / span if span > 0 else float("nan")


IMPACT_PHASE = 1e-4  # s: the first 0.1 ms of a contact counts as the impact (the first impact lasts 53 us)


def step_statistics(steps: dc.Result) -> dict[str, float]:
    """IDA's steps by phase: free flight, impact (first 0.1 ms of a contact), following contact.

    A step covers (t - h, t]; it belongs to a contact interval when it lies inside it.
    For each phase: number of steps, mean step (phase duration / steps: the step size
    that matters for cost) and median step (dominated by the tiny steps IDA takes after
    every restart at an event, in both phases).
    """
    t = np.asarray(steps.step_t)
    h = np.asarray(steps.step_h)
    keep = h > 0
    t, h = t[keep], h[keep]
    phase = np.zeros(t.size, dtype=int)  # 0 free flight, 1 impact, 2 following contact
    for a, b in contact_intervals(steps, PAIR):
        inside = (t - h >= a - 1e-15) & (t <= b + 1e-15)
        phase[inside] = 2
        phase[inside & (t <= a + IMPACT_PHASE)] = 1
    out: dict[str, float] = {"n_steps": int(t.size)}
    for k, name in enumerate(("free", "impact", "following")):
        sel = phase == k
        out[f"steps_{name}_n"] = int(sel.sum())
        out[f"steps_{name}_mean_s"] = float(h[sel].sum() / sel.sum()) if sel.any() else float("nan")
        out[f"steps_{name}_median_s"] = float(np.median(h[sel])) if sel.any() else float("nan")
    contact = phase > 0
    out["steps_contact_mean_s"] = float(h[contact].sum() / contact.sum()) if contact.any() else float("nan")
    out["step_ratio_free_over_impact"] = out["steps_free_mean_s"] / out["steps_impact_mean_s"]
    out["step_ratio_free_over_contact"] = out["steps_free_mean_s"] / out["steps_contact_mean_s"]
    return out


def poincare_points(dense: dc.Result, span: Span, x: str = "slider.vx", y: str = "slider.ax") -> np.ndarray:
    """(x, y) once per crank revolution (crank angle 0) over the analysed span, shape (n, 2)."""
    if span.revolution_times.size == 0:
        return np.zeros((0, 2))
    idx = np.searchsorted(dense.t, span.revolution_times - 1e-9 * PERIOD)
    idx = idx[idx < dense.n_times]
    return np.column_stack([dense[x][idx], dense[y][idx]])


def distinct_points(points: np.ndarray, scale: np.ndarray, tol: float = 0.01) -> int:
    """Number of clusters of points: a point is new if it differs from every kept point by more
    than ``tol * scale`` in some coordinate (1 for a periodic response, n for chaos)."""
    kept: list[np.ndarray] = []
    for p in points:
        if not any(np.all(np.abs(p - q) <= tol * scale) for q in kept):
            kept.append(p)
    return len(kept)


def measure(case: Case, ideal: Case, span: Span) -> dict[str, Any]:
    """The numbers of the validation page for one case (window = last two revolutions)."""
    w, wi = case.window, ideal.window
    if w.t.shape != wi.t.shape or not np.allclose(w.t, wi.t, rtol=0, atol=1e-12):
        raise RuntimeError(f"{case.label}: the clearance and ideal runs have different output times.")
    moment, moment_ideal = np.asarray(w["drive.moment"]), np.asarray(wi["drive.moment"])
    _, complete = _intervals_in(w)
    force_peak = max(float(np.max(w["clearance.normal_force"])),
                     float(np.max(case.steps_window["clearance.normal_force"])))
    out: dict[str, Any] = {
        "case": case.label,
        "peak_moment_Nm": float(np.max(np.abs(moment))),
        "peak_moment_ideal_Nm": float(np.max(np.abs(moment_ideal))),
        "rms_moment_dev_Nm": float(np.sqrt(np.mean((moment - moment_ideal) ** 2))),
        "rms_vx_dev_m_s": float(np.sqrt(np.mean((w["slider.vx"] - wi["slider.vx"]) ** 2))),
        "peak_ax_m_s2": float(np.max(np.abs(w["slider.ax"]))),
        "impacts": len(w.events.of(PAIR, "onset")),
        "contact_fraction": contact_fraction(w),
        "mean_contact_ms": float(np.mean(complete) * 1e3) if complete else float("nan"),
        "max_contact_ms": float(np.max(complete) * 1e3) if complete else float("nan"),
        "peak_force_N": force_peak,
        "max_penetration_um": float(np.max(case.steps_window["clearance.penetration"]) * 1e6),
        **step_statistics(case.steps),  # over the analysed span (whole run with --quick)
        "wall_time_s": case.wall_time,
    }
    if not span.quick:
        d = case.dense
        per_rev_peak, per_rev_impacts, per_rev_force = [], [], []
        for a, b in zip(span.revolution_times[:-1], span.revolution_times[1:]):
            rev = _window(d, (a, b))
            per_rev_peak.append(float(np.max(np.abs(rev["drive.moment"]))))
            per_rev_impacts.append(len(rev.events.of(PAIR, "onset")))
            per_rev_force.append(float(np.max(_window(case.steps, (a, b))["clearance.normal_force"])))
        _, complete_all = _intervals_in(d)
        pts = poincare_points(d, span)
        scale = np.array([np.ptp(ideal.dense["slider.vx"]), np.ptp(ideal.dense["slider.ax"])])
        out.update({
            "span_revolutions": len(per_rev_peak),
            "span_peak_moment_median_Nm": float(np.median(per_rev_peak)),
            "span_peak_moment_max_Nm": float(np.max(per_rev_peak)),
            "span_impacts_per_rev": float(np.mean(per_rev_impacts)),
            "span_contact_fraction": contact_fraction(d),
            "span_mean_contact_ms": float(np.mean(complete_all) * 1e3) if complete_all else float("nan"),
            "span_mean_free_flight_ms": float(np.mean(free_flights(d)) * 1e3) if free_flights(d) else float("nan"),
            "span_peak_force_N": float(np.max(case.steps["clearance.normal_force"])),
            "span_peak_force_median_N": float(np.median(per_rev_force)),
            "span_max_penetration_um": float(np.max(case.steps["clearance.penetration"]) * 1e6),
            "span_rms_moment_dev_Nm": float(np.sqrt(np.mean((d["drive.moment"] - ideal.dense["drive.moment"]) ** 2))),
            "poincare_n": int(len(pts)),
            "poincare_std_vx_m_s": float(np.std(pts[:, 0])),
            "poincare_std_ax_m_s2": float(np.std(pts[:, 1])),
            "poincare_distinct": distinct_points(pts, scale),
        })
    return out


# --------------------------------------------------------------------------- output


def save_result(result: dc.Result, out: Path, name: str) -> Path:
    """``result.save(out / f"{name}.h5")``."""
    return result.save(out / f"{name}.h5")


def save_figure(fig: Any, path: Path, *, dpi: int = 110) -> Path:
    """Write a figure as PNG, its title in the PNG's ``Title`` text (readable without drawing it), and close it."""
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=dpi, metadata={"Title": figure_title(fig)})
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- titles


def shared_caption(results: Sequence[dc.Result]) -> str:
    """The parameters every run of ``results`` shares, from :func:`daeclear.plot.style.caption`.

    For the title of a figure that compares cases: the parameter that varies is in the panel
    titles or the legend, the others once in the figure title. A part that differs only in its
    value keeps its name (``Lankarani-Nikravesh $c_e$ = 1`` and ``... = 0.9`` give
    ``Lankarani-Nikravesh``); the scene name leads when every run has the same.
    """
    if not results:
        return ""
    captions = [style.caption(r, name=False).split(", ") for r in results]
    shared: list[str] = []
    for part in captions[0]:
        if all(part in other for other in captions[1:]):
            shared.append(part)
            continue
        name, dollar, _ = part.partition(" $")
        if dollar and all(any(p.startswith(name + " $") for p in other) for other in captions[1:]):
            shared.append(name)
    text = ", ".join(shared)
    names = {r.scene_name for r in results}
    if len(names) == 1 and (scene := names.pop()):
        text = f"{scene}: {text}" if text else scene
    return text


def title_of(what: str, results: Sequence[dc.Result] | dc.Result) -> str:
    """Figure title: what it shows, then on a second line the run's parameters (:func:`daeclear.plot.style.caption`)
    or, for several runs, the ones they share (:func:`shared_caption`)."""
    if isinstance(results, dc.Result):
        return f"{what}\n{style.caption(results)}"
    return f"{what}\n{shared_caption(results)}"


def caption_runs(scenes: Sequence[dc.Scene]) -> list[dc.Result]:
    """A 1 µs run of every scene: Results that record the scenes' parameters, for the titles of figures
    drawn from data that carry none (a sweep's sections)."""
    return [dc.simulate(scene, 1e-6) for scene in scenes]


def study_title(study: Study, what: str) -> str:
    """:func:`title_of` the cases of ``study`` (the ideal joint left out)."""
    return title_of(what, [case.window for case in study.cases])


def figure_title(fig: Any) -> str:
    """The text of a figure's title: its suptitle, else the title of its first Axes ("" when none)."""
    if fig.get_suptitle():
        return str(fig.get_suptitle())
    for ax in fig.axes:
        if ax.get_title():
            return str(ax.get_title())
    return ""


# columns of the printed summary: (key, header, format)
SUMMARY_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("case", "case", "{}"),
    ("peak_moment_Nm", "peak moment (N m)", "{:.0f}"),
    ("rms_moment_dev_Nm", "RMS moment - ideal (N m)", "{:.1f}"),
    ("impacts", "impacts", "{}"),
    ("contact_fraction", "time in contact", "{:.3f}"),
    ("mean_contact_ms", "mean contact (ms)", "{:.3f}"),
    ("peak_force_N", "peak contact force (N)", "{:.0f}"),
    ("max_penetration_um", "max penetration (µm)", "{:.1f}"),
)
SPAN_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("case", "case", "{}"),
    ("span_peak_moment_median_Nm", "median of per-rev peak moment (N m)", "{:.0f}"),
    ("span_peak_moment_max_Nm", "max peak moment (N m)", "{:.0f}"),
    ("span_rms_moment_dev_Nm", "RMS moment - ideal (N m)", "{:.1f}"),
    ("span_impacts_per_rev", "impacts / rev", "{:.1f}"),
    ("span_contact_fraction", "time in contact", "{:.3f}"),
    ("span_mean_contact_ms", "mean contact (ms)", "{:.3f}"),
    ("span_mean_free_flight_ms", "mean free flight (ms)", "{:.3f}"),
    ("span_peak_force_median_N", "median of per-rev peak force (N)", "{:.0f}"),
    ("span_peak_force_N", "max peak force (N)", "{:.0f}"),
    ("span_max_penetration_um", "max penetration (µm)", "{:.1f}"),
    ("poincare_distinct", "distinct Poincaré points", "{}"),
    ("poincare_std_vx_m_s", "Poincaré std v (m/s)", "{:.2f}"),
    ("poincare_std_ax_m_s2", "Poincaré std a (m/s²)", "{:.0f}"),
)
STEP_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("case", "case", "{}"),
    ("steps_free_mean_s", "mean h free flight (s)", "{:.2e}"),
    ("steps_impact_mean_s", "mean h impact (s)", "{:.2e}"),
    ("steps_following_mean_s", "mean h following contact (s)", "{:.2e}"),
    ("step_ratio_free_over_impact", "free / impact", "{:.1f}"),
    ("steps_free_median_s", "median h free (s)", "{:.2e}"),
    ("steps_impact_median_s", "median h impact (s)", "{:.2e}"),
    ("steps_following_median_s", "median h following (s)", "{:.2e}"),
)


def _fmt(value: Any, fmt: str) -> str:
    if isinstance(value, float) and not math.isfinite(value):
        return "-"
    return fmt.format(value)


def markdown_table(rows: Sequence[Mapping[str, Any]], columns: Sequence[tuple[str, str, str]]) -> str:
    """Rows as a Markdown table (columns missing from the rows are left out)."""
    cols = [c for c in columns if all(c[0] in r for r in rows)]
    lines = ["| " + " | ".join(h for _, h, _ in cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(r[k], f) for k, _, f in cols) + " |")
    return "\n".join(lines)


# tables of metrics.md: (title, columns, also with --quick)
Section = tuple[str, Sequence[tuple[str, str, str]], bool]
SECTIONS: tuple[Section, ...] = (
    ("Last two revolutions:", SUMMARY_COLUMNS, True),
    ("Whole analysed span:", SPAN_COLUMNS, False),
    ("IDA step sizes by phase (impact: first 0.1 ms of a contact):", STEP_COLUMNS, True),
)


def write_metrics(rows: Sequence[Mapping[str, Any]], out: Path, span: Span, header: str, rtol: float = RTOL, *,
                  sections: Sequence[Section] = SECTIONS) -> None:
    """Write ``metrics.json`` and ``metrics.md`` (one table per section) and print the summary tables."""
    meta = {"span": span.describe(), "rtol": rtol, "gravity_m_s2": GRAVITY, "rpm": RPM}
    (out / "metrics.json").write_text(json.dumps({"about": header, **meta, "cases": list(rows)}, indent=1))
    text = [f"# {header}", "", span.describe() + f"; rtol {rtol:g}, gravity {GRAVITY} m/s², {RPM:g} rpm."]
    for title, columns, with_quick in sections:
        if with_quick or not span.quick:
            text += ["", title, "", markdown_table(rows, columns)]
    (out / "metrics.md").write_text("\n".join(text) + "\n")
    print("\n".join(text[2:]))


def print_written(out: Path) -> None:
    files = sorted(p.name for p in out.iterdir() if p.is_file())
    print(f"wrote {len(files)} files to {out}/: {', '.join(files)}")


# --------------------------------------------------------------------------- studies (several cases)


@dataclass
class Study:
    """The cases of one figure family, their ideal-joint reference and their measures."""

    header: str
    span: Span
    ideal: Case
    cases: list[Case]
    rows: list[dict[str, Any]]
    files: dict[str, str] = field(default_factory=dict)  # case label -> HDF5 file stem


def run_study(header: str, scenes: Mapping[str, tuple[str, dc.Scene]], args: argparse.Namespace, *,
              span: Span | None = None, measure_case: Callable[[Case, Case, Span], dict[str, Any]] | None = None,
              **run_kwargs: Any) -> Study:
    """Run the ideal joint and every case ``label -> (file stem, scene)``, print progress, measure them.

    ``span`` defaults to ``make_span(args)``, ``measure_case`` to :func:`measure`; ``run_kwargs`` go
    to :func:`run_case`.
    """
    span = make_span(args) if span is None else span
    measure_case = measure if measure_case is None else measure_case
    print(f"{header}\n{span.describe()}; rtol {args.rtol:g}, gravity {GRAVITY} m/s^2, {RPM:g} rpm", flush=True)
    all_cases = run_cases({"ideal joint": ideal_scene(), **{label: scene for label, (_, scene) in scenes.items()}},
                          span, args, **run_kwargs)
    ideal, cases = all_cases[0], all_cases[1:]
    rows = [measure_case(case, ideal, span) for case in cases]
    return Study(header, span, ideal, cases, rows, {label: stem for label, (stem, _) in scenes.items()})


def save_study(study: Study, out: Path, rtol: float, *, sections: Sequence[Section] = SECTIONS) -> None:
    """HDF5 of every case and of the ideal joint over the plotted window, and the metrics."""
    for case in study.cases:
        save_result(case.window, out, study.files[case.label])
    save_result(study.ideal.window, out, "ideal")
    write_metrics(study.rows, out, study.span, study.header, rtol, sections=sections)


def channel_figure(study: Study, channel: str, title: str, *, reference: bool = True) -> Any:
    """One panel per case: ``channel`` over the plotted window, the ideal joint dashed.

    ``title`` says what the figure shows; the parameters the cases share are added (:func:`study_title`),
    the case labels (the varied parameter) title the panels. The same for the figures below.
    """
    from functools import partial

    from daeclear.plot import plot_cases, plot_channel

    kw: dict[str, Any] = {"reference": study.ideal.window} if reference else {}
    return plot_cases({c.label: c.window for c in study.cases}, partial(plot_channel, channel=channel),
                      sharey=True, suptitle=study_title(study, title), label="clearance joint", **kw)


def orbit_figure(study: Study, title: str) -> Any:
    """One panel per case: journal centre relative to the bearing, one marker per IDA step."""
    from daeclear.plot import plot_cases, plot_journal_orbit

    return plot_cases({c.label: c.steps_window for c in study.cases}, plot_journal_orbit,
                      suptitle=study_title(study, title), panel_size=(3.8, 3.6))


def phase_figure(study: Study, title: str) -> Any:
    """One panel per case: slider acceleration against velocity over the analysed span, ideal dashed,
    with the Poincaré points (once per revolution) in red."""
    from daeclear.plot import plot_cases, plot_phase_portrait

    fig = plot_cases({c.label: c.dense for c in study.cases}, plot_phase_portrait, reference=study.ideal.window,
                     sharex=True, sharey=True, suptitle=study_title(study, title))
    for ax, case in zip(fig.axes, study.cases):
        pts = poincare_points(case.dense, study.span)
        if len(pts):
            ax.plot(pts[:, 0], pts[:, 1], "o", color="C3", ms=3.5, label="once per revolution")
    fig.axes[0].legend(loc="lower left", fontsize="x-small")
    return fig


def step_figure(study: Study, title: str) -> Any:
    """One panel per case: IDA's step size over the plotted window, contact shaded."""
    from daeclear.plot import plot_cases, plot_step_sizes

    return plot_cases({c.label: c.steps_window for c in study.cases}, plot_step_sizes, sharey=True,
                      suptitle=study_title(study, title), pair=PAIR)
