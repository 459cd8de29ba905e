"""Accuracy studies: error against run time (work-precision) for any set of integrators.

Errors are measured against a tight-tolerance reference from an independent method, on named channels,
over a window where that reference is converged (found by a second independent run, or given):
impacts make the late response chaotic, so later differences say nothing about a method's accuracy.
"""

from __future__ import annotations

import csv
import io
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from ..assembly.assemble import DAEModel, assemble
from ..core import options
from ..core.methods import FIXED_STEP
from ..core.errors import DaeclearError, Interrupted, SceneError
from ..core.progress import Progress
from ..results.outputs import atomic_write_text, check_file
from ..results.result import Result
from ..model.scene import Scene
from ..solvers.save_at import SaveAt
from ..solvers.solver_options import SolverOptions
from ..solvers.dispatch import simulate

FIXED_STEP_METHODS = FIXED_STEP  # run at each step of a list, not at each tolerance
COLUMNS = ("label", "method", "tolerance", "error", "event_time_error", "events", "solve_time", "wall_time",
           "n_steps", "n_res_evals", "status", "message")


@dataclass
class WorkPrecision:
    """The outcome of :func:`work_precision`: one row per run, plus the reference and window."""

    rows: list[dict[str, Any]]
    channels: list[str]
    window: tuple[float, float]
    window_reason: str
    reference: Result
    reference_options: dict[str, Any]
    assembly_time: float
    notes: list[str] = field(default_factory=list)
    timed_with_scene: bool = False  # runs timed as simulate(Scene, ...), assembly included

    @property
    def table(self) -> list[dict[str, Any]]:
        return self.rows

    def to_csv(self, path: str | Path | None = None) -> str:
        """The table as CSV (written to ``path`` when given)."""
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=list(COLUMNS) + [f"error[{c}]" for c in self.channels],
                                extrasaction="ignore")
        writer.writeheader()
        for row in self.rows:
            writer.writerow({k: _fmt(v) for k, v in row.items()})
        text = buf.getvalue()
        if path is not None:
            atomic_write_text(check_file(path, "WorkPrecision.to_csv(path)", what="a CSV file", example="table.csv"),
                              text)
        return text

    def to_markdown(self, path: str | Path | None = None) -> str:
        """The table as markdown, with the window and reference stated above it."""
        ref = ", ".join(f"{k}={v}" for k, v in self.reference_options.items())
        head = [
            f"Reference: {ref}. Error: max over the window of |x - x_ref| / range(x_ref), the largest over "
            f"channels {', '.join(self.channels)}. Window: t in [{self.window[0]:.6g}, {self.window[1]:.6g}] s "
            f"({self.window_reason}). Times: best of the repeats of the whole simulate call "
            + ("(a Scene in: assembly included)." if self.timed_with_scene else
               f"(model assembled once, {self.assembly_time * 1e3:.0f} ms, not included)."),
            "",
            "| label | tolerance / step | error | event time error (s) | events | solve time (s) | wall time (s) "
            "| steps | evaluations | status |",
            "|---|---|---|---|---|---|---|---|---|---|",
        ]
        lines = []
        for r in self.rows:
            status = "ok" if r["status"] == 0 else f"FAILED: {r['message'][:80]}"
            lines.append(f"| {r['label']} | {_fmt(r['tolerance'])} | {_fmt(r['error'])} | "
                         f"{_fmt(r['event_time_error'])} | {r['events']} | {_fmt(r['solve_time'])} | "
                         f"{_fmt(r['wall_time'])} | {r['n_steps']} | {r['n_res_evals']} | {status} |")
        text = "\n".join(head + lines + [""] + [f"- {n}" for n in self.notes]) + "\n"
        if path is not None:
            atomic_write_text(check_file(path, "WorkPrecision.to_markdown(path)", what="a markdown file",
                                         example="table.md"), text)
        return text

    def best(self, label: str, max_error: float) -> dict[str, Any] | None:
        """The fastest successful run of ``label`` whose error is at most ``max_error``."""
        ok = [r for r in self.rows if r["label"] == label and r["status"] == 0 and r["error"] <= max_error]
        return min(ok, key=lambda r: r["wall_time"]) if ok else None

    def speed_ratio(self, label: str, others: Sequence[str]) -> list[dict[str, Any]]:
        """For every successful run of ``label``: its wall time against the fastest run among
        ``others`` with an error at most as large (equal or better accuracy)."""
        out = []
        for row in self.rows:
            if row["label"] != label or row["status"] != 0:
                continue
            rivals = [r for r in (self.best(o, row["error"]) for o in others) if r is not None]
            if rivals:
                rival = min(rivals, key=lambda r: r["wall_time"])
                out.append({"tolerance": row["tolerance"], "error": row["error"], "wall_time": row["wall_time"],
                            "rival": f"{rival['label']} @ {_fmt(rival['tolerance'])}",
                            "rival_error": rival["error"], "rival_wall_time": rival["wall_time"],
                            "ratio": rival["wall_time"] / row["wall_time"]})
        return out


def _fmt(value: Any) -> Any:
    if isinstance(value, float):
        return f"{value:.3g}" if math.isfinite(value) else str(value)
    return value


def channel_error(result: Result, reference: Result, channels: Sequence[str],
                  window: tuple[float, float]) -> dict[str, float]:
    """Max over the window of |x - x_ref| / range(x_ref) per channel (both on the same output times)."""
    if result.t.shape != reference.t.shape or not np.allclose(result.t, reference.t, rtol=0, atol=1e-12):
        raise ValueError("channel_error: the result and the reference must share their output times")
    mask = (reference.t >= window[0]) & (reference.t <= window[1])
    errors = {}
    for name in channels:
        ref = np.asarray(reference[name])[mask]
        val = np.asarray(result[name])[mask]
        scale = float(np.ptp(ref)) or float(np.max(np.abs(ref))) or 1.0
        errors[name] = float(np.max(np.abs(val - ref))) / scale if np.all(np.isfinite(val)) else math.inf
    return errors


def event_time_error(result: Result, reference: Result, window: tuple[float, float]) -> tuple[float, int]:
    """Largest onset-time difference over the reference's onsets inside the window, and their count.

    Infinite when the run found a different number of onsets there.
    """
    ref = np.array([e.t for e in reference.events if e.kind == "onset" and window[0] <= e.t <= window[1]])
    got = np.array([e.t for e in result.events if e.kind == "onset" and window[0] <= e.t <= window[1]])
    if ref.size == 0 and got.size == 0:
        return 0.0, 0
    if ref.size != got.size:
        return math.inf, int(got.size)
    return float(np.max(np.abs(got - ref))), int(got.size)


def converged_window(reference: Result, check: Result, channels: Sequence[str], tol: float) -> float:
    """The last time up to which two independent references agree within ``tol`` (relative to range)."""
    t = reference.t
    bad = np.zeros(t.size, dtype=bool)
    for name in channels:
        ref, other = np.asarray(reference[name]), np.asarray(check[name])
        scale = float(np.ptp(ref)) or 1.0
        bad |= ~(np.abs(ref - other) <= tol * scale)
    return float(t[max(int(np.argmax(bad)) - 1, 0)]) if bad.any() else float(t[-1])


Settings = Mapping[str, Any] | SolverOptions  # the options of one run: simulate keywords or a SolverOptions


def _solver_options(settings: Settings) -> SolverOptions:
    """``settings`` as the ``options`` of :func:`simulate` (a mapping: the fields of SolverOptions, checked)."""
    return settings if isinstance(settings, SolverOptions) else SolverOptions.from_dict(settings)


def _method_of(settings: Settings) -> str:
    """The method of ``settings``, lower case ("ida" when not given)."""
    return settings.method if isinstance(settings, SolverOptions) else str(settings.get("method", "ida")).lower()


def _describe(settings: Settings) -> str:
    """``settings`` as ``name=value`` items (a SolverOptions: the settings that differ from the defaults)."""
    if isinstance(settings, SolverOptions):
        default = SolverOptions().to_dict()
        items = {k: v for k, v in settings.to_dict().items() if v != default[k]}
    else:
        items = dict(settings)
    return ", ".join(f"{k}={v}" for k, v in items.items())


def _with(settings: Settings, name: str, value: float) -> Settings:
    """``settings`` with the tolerance or step ``name`` set to ``value``."""
    if isinstance(settings, SolverOptions):
        return settings.replace(**{name: value})
    return {**{k: v for k, v in settings.items() if k not in ("rtol", "step")}, name: value}


def _timed(model: Scene | DAEModel, t_end: float, t_eval: NDArray, settings: Settings, repeats: int
           ) -> tuple[Result, float]:
    """Best-of-repeats wall time of the whole ``simulate`` call, a Scene (assembled in the call,
    as users run it) or a model (first run warms the cache)."""
    best_result, best_time = None, math.inf
    solver, save = _solver_options(settings), SaveAt(times=t_eval)
    for i in range(repeats + 1):
        start = time.perf_counter()
        result = simulate(model, t_end, options=solver, on_failure="return", save=save)
        elapsed = time.perf_counter() - start
        if i == 0 and repeats > 0:
            continue  # the warm-up run compiles or loads the model
        if elapsed < best_time:
            best_result, best_time = result, elapsed
        if not result.success:
            break  # a failing run is not worth repeating
    assert best_result is not None
    return best_result, best_time


def work_precision(
    scene: Scene | DAEModel,
    t_end: float,
    *,
    channels: Sequence[str] = ("slider.vx",),
    methods: Mapping[str, Settings] | None = None,
    rtols: Sequence[float] = (1e-4, 1e-6, 1e-8),
    steps: Sequence[float] = (1e-5, 5e-6),
    reference: Settings | None = None,
    check: Settings | None = None,
    window: tuple[float, float] | None = None,
    converged_tol: float = 1e-6,
    n_eval: int = 2001,
    repeats: int = 3,
    progress: bool = False,
) -> WorkPrecision:
    """Error against run time for every method and tolerance (or fixed step).

    Parameters
    ----------
    scene, t_end : Scene or DAEModel, float
        The mechanism (a Scene is timed with its assembly, as users call it) and the runs' end, s.
    channels : sequence of str
        Channels whose error is measured (relative to the reference's range).
    methods : mapping label -> simulate options or SolverOptions
        E.g. ``{"IDA": {"method": "ida"}, "IDA sparse": SolverOptions(linear_solver="sparse")}``; adaptive
        methods run at every ``rtols``, fixed-step ones (rk4, euler) at every ``steps``. Default: IDA,
        DOP853, LSODA and RK4.
    reference, check : mapping, SolverOptions or None
        The reference run (default DOP853 at rtol 1e-12) and the one that finds the converged window
        (default IDA index-1 at rtol 1e-12): the error ``window`` (None) ends where they stop agreeing
        to ``converged_tol`` of each channel's range.
    n_eval, repeats : int
        Output times (uniform over [0, t_end]) where runs are compared; timed repeats per run (best
        kept, after one warm-up run).

    Returns
    -------
    WorkPrecision
        One row per run (error, event time error, solve/wall time, steps, status), the window and its
        reason, the reference result.
    """
    if methods is None:
        methods = {"IDA": {"method": "ida"}, "DOP853": {"method": "DOP853"}, "LSODA": {"method": "LSODA"},
                   "RK4": {"method": "rk4"}}
    if not channels:
        raise SceneError("work_precision: give at least one channel.")
    t_end = options.t_end(t_end, where="work_precision")
    rtols = options.rtols(rtols)
    steps = options.steps(steps, t_end)
    repeats = options.repeats(repeats)
    n_eval = options.n_eval(n_eval)
    for label, opts in methods.items():
        if not isinstance(opts, (Mapping, SolverOptions)):
            options.fail("work_precision", f"methods[{label!r}]", opts,
                         "a mapping of simulate options or a SolverOptions")
        if not isinstance(opts, SolverOptions):  # a SolverOptions was checked when it was made
            options.method(opts.get("method", "ida"), where="work_precision", field=f"methods[{label!r}]['method']")
    start = time.perf_counter()
    model = scene if isinstance(scene, DAEModel) else assemble(scene)
    assembly_time = time.perf_counter() - start
    for name in channels:
        if name not in model.channel_names:
            raise SceneError(f"work_precision: no channel {name!r} in the model; channels are "
                             f"{', '.join(model.channel_names[:8])}, ...")
    t_eval = np.linspace(0.0, t_end, n_eval)
    ref_settings = reference if reference is not None else {"method": "DOP853", "rtol": 1e-12}
    check_settings = check if check is not None else {"method": "ida", "rtol": 1e-12, "formulation": "index1"}
    ref_options = ref_settings.to_dict() if isinstance(ref_settings, SolverOptions) else dict(ref_settings)
    scene_for_ref = scene if isinstance(scene, Scene) else model
    ref = simulate(scene_for_ref, t_end, options=_solver_options(ref_settings), on_failure="raise",
                   save=SaveAt(times=t_eval))
    notes = []
    if window is None:
        other = simulate(scene_for_ref, t_end, options=_solver_options(check_settings), on_failure="return",
                         save=SaveAt(times=t_eval))
        if not other.success:  # without the check nothing says where the reference is converged
            raise DaeclearError(
                f"work_precision: the check run ({_describe(check_settings)}) that finds where the reference is "
                f"converged failed: {other.message} Give check= with other options, or the error window with "
                "window=(t0, t1).")
        t_conv = converged_window(ref, other, channels, converged_tol)
        window = (0.0, t_conv)
        reason = (f"the reference agrees with an independent run ({_describe(check_settings)}) "
                  f"to {converged_tol:g} of each channel's range up to there")
        if t_conv < t_end:
            notes.append(f"After t = {t_conv:.6g} s the two references diverge (sensitive dependence on the "
                         "impact sequence); errors beyond are not meaningful.")
    else:
        reason = "given"
    out = WorkPrecision(rows=[], channels=list(channels), window=window, window_reason=reason, reference=ref,
                        reference_options=ref_options, assembly_time=assembly_time, notes=notes,
                        timed_with_scene=isinstance(scene, Scene))
    try:
        _measure(out.rows, scene_for_ref, ref, methods, rtols, steps, t_end, t_eval, channels, window, repeats,
                 progress)
    except KeyboardInterrupt as exc:  # Ctrl-C: stop, with the finished rows in .result (never a "failed" row)
        n = len(out.rows)
        out.notes.append(f"Interrupted by the user after {n} runs; the table is incomplete.")
        raise Interrupted(f"work_precision: interrupted by the user after {n} runs; the finished rows "
                          "are in .result.", out) from exc
    return out


def _measure(rows: list[dict[str, Any]], scene_for_ref: Scene | DAEModel, ref: Result,
             methods: Mapping[str, Settings], rtols: Sequence[float], steps: Sequence[float], t_end: float,
             t_eval: NDArray, channels: Sequence[str], window: tuple[float, float], repeats: int,
             progress: bool) -> None:
    """The timed runs of every method and tolerance, appended to ``rows`` as each finishes."""
    total = sum(len(steps if _method_of(m) in FIXED_STEP_METHODS else rtols) for m in methods.values())
    bar = Progress(total, unit="runs", desc="work-precision", enabled=progress)
    try:
        for label, method_options in methods.items():
            method = _method_of(method_options)
            fixed = method in FIXED_STEP_METHODS
            for value in steps if fixed else rtols:
                bar.update(len(rows), f"{label} {'step' if fixed else 'rtol'}={value:g} ...")
                try:
                    result, wall = _timed(scene_for_ref, t_end, t_eval,
                                          _with(method_options, "step" if fixed else "rtol", value), repeats)
                except Exception as exc:  # a run that cannot even start stays in the table
                    rows.append({"label": label, "method": method, "tolerance": value, "error": math.inf,
                                 "event_time_error": math.inf, "events": 0, "solve_time": math.nan,
                                 "wall_time": math.nan, "n_steps": 0, "n_res_evals": 0, "status": -1,
                                 "message": f"{type(exc).__name__}: {exc}"})
                    continue
                if result.success:
                    errors = channel_error(result, ref, channels, window)
                    ev_err, n_events = event_time_error(result, ref, window)
                else:
                    errors, ev_err, n_events = {c: math.inf for c in channels}, math.inf, 0
                rows.append({
                    "label": label, "method": method, "tolerance": value, "error": max(errors.values()),
                    **{f"error[{c}]": e for c, e in errors.items()}, "event_time_error": ev_err, "events": n_events,
                    "solve_time": float(result.stats.get("solve_time", math.nan)), "wall_time": wall,
                    "n_steps": int(result.stats.get("n_steps", 0)),
                    "n_res_evals": int(result.stats.get("n_res_evals", 0)),
                    "status": 0 if result.success else -1, "message": result.message,
                })
        bar.update(total, "")
    finally:
        bar.close()


def energy_balance(result: Result) -> dict[str, float]:
    """How well the run keeps dE/dt = input power (drivers and contact forces; gravity is in E).

    Uses the work state of a run with ``track_work=True`` (exact up to the integration error);
    otherwise integrates ``energy.input_power`` over the output times (cumulative trapezoid,
    limited by the quadrature: use dense outputs). Returns the largest and the final residual
    of E - E0 - W, relative to the energy scale (the larger of the energy's range and |W|).
    """
    t = np.asarray(result.t)
    energy = np.asarray(result["energy.mechanical"])
    if "energy.work" in result:  # integrated with the equations (simulate(..., track_work=True))
        work = np.asarray(result["energy.work"]) - result["energy.work"][0]
    else:
        power = np.asarray(result["energy.input_power"]) if "energy.input_power" in result else np.zeros_like(t)
        work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    residual = (energy - energy[0]) - work
    scale = max(float(np.ptp(energy)), float(np.max(np.abs(work))), 1e-300)
    return {"max_residual": float(np.max(np.abs(residual))) / scale,
            "final_residual": float(abs(residual[-1])) / scale, "scale": scale}
