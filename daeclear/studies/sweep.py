"""Parameter sweeps: many independent classified runs on any ``concurrent.futures.Executor``.

``sweep(path, grid)`` classifies one scene per parameter point (:func:`daeclear.analysis.classify_motion`)
in workers and gathers every run in one HDF5 file, written by the calling process alone: each finished
run is journalled atomically, so an interrupted sweep resumes without losing one
(docs/nonlinear_dynamics.md, *Sweeps*). This module plans and drives the runs.

Examples
--------
>>> import daeclear as dc
>>> out = dc.sweep("clearance.h5", {"clearance": [0.01e-3, 0.1e-3, 0.5e-3]},
...                fixed={"joint": "revolute"})                      # doctest: +SKIP
>>> [(r.parameters["clearance"], r.motion) for r in out.runs]         # doctest: +SKIP
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import hashlib
import itertools
import json
import math
import os
import traceback as tb
from collections.abc import Callable, Iterable, Mapping, Sequence
from datetime import datetime, UTC
from pathlib import Path
from typing import Any

import numpy as np

from .poincare import section_channels
from .sweep_file import (FORMAT_NAME, FORMAT_VERSION, SOLVER_KEY, RunRecord, SweepResult, load_sweep, part_files,
                         parts_dir, read_record, varying_names)
from .sweep_journal import acquire_lock, consolidate, lock_path, write_part
from .sweep_workers import build_scene, ignore_sigint, run_task, terminate_pool
from ..core.errors import DaeclearError, OutputError, SceneError
from ..core.progress import Progress
from ..results.outputs import check_file, deferred_sigint, sigint_latch
from ..solvers.solver_options import UNSET, SolverOptions

__all__ = ["FORMAT_NAME", "FORMAT_VERSION", "KEEP", "RunRecord", "SweepResult", "grid_points", "load_sweep",
           "run_key", "sweep"]

KEEP: tuple[str, ...] = ("section", "channels", "full")
ANALYSIS_OPTIONS = ("channels", "revolutions", "transient", "per_revolution", "phase", "twin", "twin_revolutions",
                    "perturbation", "seed", "tol", "max_period", "decorrelation", "rtol", "atol", "max_step",
                    "formulation", "backend")
#: The solver settings analysis= may still give (the keyword form); they go into the sweep's SolverOptions.
SOLVER_ANALYSIS_OPTIONS = ("atol", "max_step", "formulation", "backend")


def _plain_value(name: str, value: Any) -> Any:
    """A parameter value as plain JSON (numbers, strings, bools, None, lists of them)."""
    if isinstance(value, np.generic):
        value = value.item()
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            raise SceneError(f"sweep: parameter {name!r} = {value!r} is not finite.")
        return value
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain_value(name, v) for v in value]
    if isinstance(value, dict) and all(isinstance(k, str) for k in value):  # a law table {name = ..., ...}
        return {k: _plain_value(f"{name}.{k}", v) for k, v in value.items()}
    raise SceneError(f"sweep: parameter {name!r} = {value!r} is a {type(value).__name__}; sweep parameters must be "
                     "numbers, strings, bools, None, lists of them or tables (dicts) of them (give a law by name, "
                     "e.g. law='hertz', or by a table, law={'name': 'hydrodynamic', 'viscosity': 0.1, "
                     "'length': 0.01}).")


def _plain(parameters: Mapping[Any, Any]) -> dict[str, Any]:
    """Parameters with str names and plain JSON values (:func:`_plain_value`)."""
    return {str(k): _plain_value(str(k), v) for k, v in parameters.items()}


def run_key(parameters: Mapping[str, Any]) -> str:
    """The stable name of a run: ``run-`` + 16 hex digits of the SHA-256 of its parameters (canonical JSON)."""
    canonical = json.dumps(_plain(parameters), sort_keys=True, separators=(",", ":"))
    return "run-" + hashlib.sha256(canonical.encode()).hexdigest()[:16]


def grid_points(grid: Mapping[str, Iterable[Any]]) -> list[dict[str, Any]]:
    """Every combination of the grid's values (name -> values, e.g. ``{"clearance": [0.1e-3, 0.5e-3],
    "friction": [0.01, 0.1]}``), one dict per point in ``itertools.product`` order."""
    names = list(grid)
    values = []
    for name in names:
        v = grid[name]
        if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
            raise SceneError(f"sweep: grid[{name!r}] = {v!r}, must be a list of values (use fixed= for one value).")
        v = list(v)
        if not v:
            raise SceneError(f"sweep: grid[{name!r}] is empty.")
        values.append(v)
    return [dict(zip(names, combo)) for combo in itertools.product(*values)]


def _mechanism_name(mechanism: str | Callable[..., Any]) -> str:
    if isinstance(mechanism, str):
        return mechanism
    return f"{getattr(mechanism, '__module__', '?')}:{getattr(mechanism, '__qualname__', repr(mechanism))}"


def _short(parameters: Mapping[str, Any], names: Sequence[str]) -> str:
    return " ".join(f"{n}={parameters[n]:g}" if isinstance(parameters[n], float) else f"{n}={parameters[n]}"
                    for n in names if n in parameters)


def _differences(previous: SweepResult, mechanism: str, file_options: Mapping[str, Any],
                 solver: SolverOptions) -> list[str]:
    """What differs between a sweep file's settings and this call's (``"<name>: file <a>, now <b>"``);
    the solver settings are compared as SolverOptions rebuilt from the file (``solver.rtol: ...``)."""
    diffs = [f"mechanism: file {previous.mechanism!r}, now {mechanism!r}"] if previous.mechanism != mechanism else []
    old = {k: v for k, v in previous.options.items() if k != SOLVER_KEY}
    new = {k: v for k, v in file_options.items() if k != SOLVER_KEY}
    diffs += [f"{k}: file {old.get(k)!r}, now {new.get(k)!r}" for k in sorted(set(old) | set(new))
              if old.get(k) != new.get(k)]
    before = previous.solver_options
    diffs += [f"{SOLVER_KEY}.{f.name}: file {getattr(before, f.name)!r}, now {getattr(solver, f.name)!r}"
              for f in dataclasses.fields(SolverOptions) if getattr(before, f.name) != getattr(solver, f.name)]
    return diffs


def sweep(path: str | os.PathLike[str], grid: Mapping[str, Iterable[Any]] | None = None, *,
          runs: Iterable[Mapping[str, Any]] | None = None, mechanism: str | Callable[..., Any] = "slider_crank",
          fixed: Mapping[str, Any] | None = None, channels: Sequence[str] | None = None,
          store_channels: Sequence[str] | None = None, keep: str = "channels", revolutions: int = 30,
          transient: int = 10, per_revolution: int = 32, twin: bool | str = True, rtol: float = UNSET,
          options: SolverOptions | None = None, analysis: Mapping[str, Any] | None = None,
          executor: cf.Executor | None = None,
          max_workers: int | None = None, resume: bool = True, retry_failed: bool = False, progress: bool = True,
          on_run: Callable[[RunRecord], None] | None = None) -> SweepResult:
    """Run and classify one scene per parameter point, in parallel, into one HDF5 file.

    Parameters
    ----------
    path : str or path-like
        The sweep file (``.h5``) in an existing directory.
    grid, runs : mapping of str to list, iterable of dict, optional
        Parameter name -> values, every combination run (:func:`grid_points`), and explicit points
        after them. A name is an option of ``mechanism`` or, with a dot, a value of the built scene
        (``"clearance.law.restitution"``).
    mechanism : str or callable
        A ready mechanism's name or a picklable top-level function ``f(**parameters) -> Scene``.
    fixed : mapping, optional
        Parameters common to every run (part of each run's parameters and key).
    channels, store_channels : sequence of str, optional
        Poincaré-section channels (default :func:`daeclear.analysis.section_channels` of the first
        point) and those stored over the analysed span (default ``channels``).
    keep : {"section", "channels", "full"}
        What each run stores beyond its classification and section: nothing more, the stored
        channels (default), or also the full reference Result.
    revolutions, transient, per_revolution, twin
        Passed to :func:`daeclear.analysis.classify_motion`.
    rtol, options : float, SolverOptions
        The solver settings of every run; ``rtol=`` and the solver settings of ``analysis=`` override
        ``options``, as in :func:`daeclear.simulate`. Stored in the file (``SweepResult.solver_options``);
        a resume with other settings is refused.
    analysis : mapping, optional
        Further :func:`~daeclear.analysis.classify_motion` options (``phase``, ``tol``, ``max_period``,
        ``decorrelation``, ``perturbation``, ``seed``, ``twin_revolutions``) and the solver settings
        ``atol``, ``max_step``, ``formulation``, ``backend``.
    executor : concurrent.futures.Executor, optional
        Where runs go; default a local process pool of ``max_workers`` (default the CPU count, at most
        the number of runs); a Dask cluster: ``client.get_executor()``. On macOS and Windows a script
        must call sweep under ``if __name__ == "__main__":``.
    resume, retry_failed, progress : bool
        Continue an existing file and its journal, skipping finished runs (False deletes them first); on
        resume, run the failed runs again; a progress line on stderr.
    on_run : callable, optional
        Called with each new RunRecord as soon as it is saved.

    Returns
    -------
    SweepResult
        Every run of the file (earlier ones included), in index order.

    Raises
    ------
    SceneError
        Bad arguments (unknown option, non-plain parameter value, no points).
    DaeclearError
        The file belongs to another sweep (each difference named), is locked by a running sweep, or
        the process pool broke (finished runs are saved; run again to resume).
    KeyboardInterrupt
        Re-raised after the finished runs are saved.
    """
    from ..core import options as check

    path = check_file(path, "sweep(path)", what="a sweep file (.h5)", example="sweep.h5")  # before any work
    if parts_dir(path).exists() and not parts_dir(path).is_dir():
        raise OutputError(f"sweep(path) '{path}': its journal '{parts_dir(path)}' is a file; it must be a "
                          "directory (move the file away).")
    if lock_path(path).is_dir():
        raise OutputError(f"sweep(path) '{path}': its lock '{lock_path(path)}' is a directory; remove it.")
    if keep not in KEEP:
        raise SceneError(f"sweep: keep={keep!r}, must be one of {', '.join(KEEP)}.")
    check.revolutions(revolutions)
    check.transient(transient)
    check.per_revolution(per_revolution)
    check.workers(max_workers)
    if options is not None and not isinstance(options, SolverOptions):
        check.fail("sweep", "options", options, "None or a daeclear.SolverOptions")
    if channels is not None:
        check.names(list(channels) if not isinstance(channels, str) else channels, where="sweep", field="channels")
    if not isinstance(twin, bool) and twin != "auto":
        check.fail("sweep", "twin", twin, "True, False or 'auto'")
    extra = dict(analysis or {})
    unknown = sorted(set(extra) - set(ANALYSIS_OPTIONS))
    if unknown:
        raise SceneError(f"sweep: unknown analysis option(s) {', '.join(unknown)}; allowed: "
                         f"{', '.join(ANALYSIS_OPTIONS)}.")
    overlap = sorted(set(extra) & {"channels", "revolutions", "transient", "per_revolution", "twin", "rtol"})
    if overlap:
        raise SceneError(f"sweep: give {', '.join(overlap)} as sweep() keywords, not in analysis=.")
    solver = (options or SolverOptions()).merged(  # one object: the keywords override options, as in simulate
        where="sweep", rtol=rtol, **{k: extra.pop(k) for k in SOLVER_ANALYSIS_OPTIONS if k in extra})
    if not isinstance(mechanism, str) and not callable(mechanism):
        raise SceneError(f"sweep: mechanism={mechanism!r}, must be a mechanism name or a callable.")
    base = _plain(fixed or {})
    points = grid_points(grid) if grid else []
    points += [dict(p) for p in (runs or [])]
    if not points:
        raise SceneError("sweep: no parameter points; give grid= and/or runs=.")
    first = {**base, **_plain(points[0])}
    first_scene = build_scene(mechanism, first)  # a bad fixed parameter fails here, before any run
    if channels is None:  # from what the mechanism holds (every point has its bodies)
        channels = section_channels(first_scene)
    analysis_options = {"channels": [str(c) for c in channels], "revolutions": revolutions, "transient": transient,
                        "per_revolution": per_revolution, "twin": twin, **extra}
    stored = [str(c) for c in (store_channels if store_channels is not None else channels)]
    _preflight(first_scene, first, {"channels": analysis_options["channels"], "store_channels": stored}, solver)
    file_options = {**{k: _plain_value(k, v) for k, v in analysis_options.items()}, "keep": keep,
                    "store_channels": stored, SOLVER_KEY: solver.to_dict()}
    mech_name = _mechanism_name(mechanism)
    task_analysis = {k: (tuple(v) if k == "channels" else v) for k, v in analysis_options.items()}
    tasks: list[dict[str, Any]] = []
    order: dict[str, int] = {}
    for point in points:
        params = {**base, **_plain(point)}
        key = run_key(params)
        if key in order:
            continue  # the same point twice: one run
        order[key] = len(tasks)
        tasks.append({"key": key, "index": len(tasks), "parameters": params, "mechanism": mechanism,
                      "analysis": task_analysis, SOLVER_KEY: file_options[SOLVER_KEY], "keep": keep,
                      "store_channels": stored})
    varying = varying_names([t["parameters"] for t in tasks])

    lock = acquire_lock(path, {"mechanism": mech_name})
    n_computed = n_skipped = 0
    checked = False  # the file is merged only once it is known to belong to this sweep
    try:
        if not resume:
            path.unlink(missing_ok=True)
            for part in part_files(path):
                part.unlink()
        existing: dict[str, RunRecord] = {}
        if path.is_file() or part_files(path):
            previous = load_sweep(path)
            diffs = _differences(previous, mech_name, file_options, solver) if previous.options else []
            if diffs:
                raise DaeclearError(f"sweep '{path}' was made with other settings ({'; '.join(diffs)}). Use another "
                                    "file, or resume=False to start it over.")
            existing = {r.key: r for r in previous.runs}
        checked = True
        todo = [t for t in tasks if not (t["key"] in existing and (existing[t["key"]].ok or not retry_failed))]
        n_skipped = len(tasks) - len(todo)
        n_computed = _execute(path, todo, executor, max_workers, progress, len(tasks), n_skipped, varying, on_run,
                              mech_name, file_options)
    finally:
        try:
            if checked and (path.is_file() or part_files(path)):
                with deferred_sigint():  # a second Ctrl-C waits for the merge (atomic anyway: the journal stays)
                    consolidate(path, mechanism=mech_name, options=file_options, order=order)
        finally:
            lock.unlink(missing_ok=True)
    out = load_sweep(path) if path.is_file() else SweepResult(path, [], mech_name, file_options)
    out.n_computed, out.n_skipped = n_computed, n_skipped
    return out


def _preflight(scene: Any, first: Mapping[str, Any], channels: Mapping[str, Sequence[str]],
               solver: SolverOptions) -> None:
    """What every run of a sweep needs, checked on the first point before any run: a crank period (one
    constant-speed driver: the motion is classified revolution by revolution) and the channels' names.
    Without it, every run would fail the same way after the whole sweep's work."""
    from .poincare import crank_period
    from ..assembly.assemble import assemble
    from ..core.options import close_matches, default_formulation, fail

    try:
        crank_period(scene)
    except DaeclearError as exc:
        reason = str(exc).split(", so no crank period")[0].split(": pass period=")[0]
        raise SceneError(f"sweep: mechanism at the first point {dict(first)!r}: {reason}, so no crank period; a "
                         "sweep classifies the motion revolution by revolution and needs one constant-speed "
                         "driver.") from None
    model = assemble(scene, solver.formulation or default_formulation("ida"))
    known = set(model.channel_names)
    for field, names in channels.items():
        for name in names:
            if name not in known:
                hint = close_matches(name, known)
                fail("sweep", field, name, "channels of the mechanism (checked on the first point)"
                           + (f"; close matches: {', '.join(hint)}" if hint else ""))


def _execute(path: Path, todo: list[dict[str, Any]], executor: cf.Executor | None, max_workers: int | None,
             progress: bool, total: int, skipped: int, varying: Sequence[str],
             on_run: Callable[[RunRecord], None] | None, mechanism: str, options: Mapping[str, Any]) -> int:
    """Submit the runs, save each as it finishes; returns the number saved."""
    line = Progress(total - skipped, unit="runs", desc="sweep", enabled=progress)

    def note(failed: int, last: str = "") -> str:
        return " | ".join(part for part in (f"{failed} failed" if failed else "",
                                            f"{skipped} already done" if skipped else "", last) if part)

    line.update(0, note(0))
    if not todo:
        line.close(note(0, "nothing to do"))
        return 0
    own = executor is None
    if own:  # the platform's start method: fork on Linux (scripts need no __main__ guard), spawn elsewhere
        workers = max(1, min(max_workers or os.cpu_count() or 1, len(todo)))
        executor = cf.ProcessPoolExecutor(max_workers=workers, initializer=ignore_sigint, initargs=(os.getpid(),))
    assert executor is not None
    parts = parts_dir(path)
    done = failed = 0
    futures: dict[cf.Future[Any], dict[str, Any]] = {}
    with sigint_latch() as interrupted:  # every Ctrl-C, even one Python drops, stops the sweep
        try:
            futures = {executor.submit(run_task, task): task for task in todo}
            for future in cf.as_completed(futures):
                if interrupted:  # a Ctrl-C that Python dropped (raised inside a weakref callback) still stops
                    raise KeyboardInterrupt
                task = futures[future]
                try:
                    outcome = future.result()
                except cf.BrokenExecutor as exc:
                    raise DaeclearError(f"sweep '{path}': the executor broke ({exc}): a worker died (out of "
                                        f"memory or a crash). {done} runs were saved; run the sweep again to "
                                        "resume.") from exc
                except cf.CancelledError:
                    continue
                except Exception as exc:  # raised by the executor itself (pickling, a killed Dask worker, ...)
                    outcome = {**{k: task[k] for k in ("key", "index", "parameters")}, "status": "failed",
                               "error": f"{type(exc).__name__}: {exc}", "traceback": tb.format_exc(),
                               "worker": "?", "wall_time": float("nan"),
                               "computed_at": datetime.now(UTC).isoformat(timespec="seconds")}
                if outcome["status"] == "interrupted":
                    continue  # not recorded: computed again on resume
                write_part(parts, outcome, mechanism, options)
                done += 1
                failed += outcome["status"] == "failed"
                data = outcome.get("data") or {}
                label = data.get("motion", {}).get("label", "FAILED") if outcome["status"] == "done" else "FAILED"
                line.update(done, note(failed, f"{_short(outcome['parameters'], varying)} -> {label}"))
                if on_run is not None:
                    import h5py

                    with h5py.File(parts / f"{outcome['key']}.h5", "r") as f:
                        record = read_record(f["/"])
                    on_run(record)
            if interrupted:
                raise KeyboardInterrupt
            line.close()
        except BaseException:
            line.close()
            for future in futures:
                future.cancel()
            if own:
                terminate_pool(executor)
            raise
        finally:
            if own:
                executor.shutdown(wait=True, cancel_futures=True)
    return done
