"""Parameter sweeps: many independent classified runs on any ``concurrent.futures.Executor``.

``sweep(path, grid)`` builds one scene per parameter point (``slider_crank(**point)`` by
default), runs :func:`daeclear.analysis.classify_motion` on it in a worker, and gathers
every run in one HDF5 file. Workers only compute; the calling process is the only one
that writes files.

Robustness (a run's data is never half-written, an interrupted sweep loses no finished run):

- each finished run is first written to its own journal file ``<path>.parts/<key>.h5``
  under a temporary name, fsync'ed and renamed (atomic on POSIX);
- at the end (and on an interrupt or an error) the journal is merged into ``<path>``: a
  new file is written beside it and renamed over it, then the merged journal files are
  deleted; a crash at any point leaves either the old or the new file, plus the journal;
- a resumed sweep (the default) reads ``<path>`` and the journal, skips every finished run
  (failed runs too, unless ``retry_failed=True``) and computes only the others;
- ``<path>.lock`` keeps two sweeps from writing the same file at once.

HDF5 layout of ``<path>`` (root attributes ``format="daeclear-sweep"``, ``version=1``,
``mechanism``, ``options_json``)::

    /runs/<key>                 attrs: the run's parameters, one attribute each (None as
                                "None"), and parameters_json (the lossless copy)
    /runs/<key>/info            attrs: key, index, status ("done" | "failed"), error,
                                traceback, wall_time (s), computed_at (UTC), worker (host:pid)
    /runs/<key>/motion          attrs: label, period, reason, one attribute per evidence item
                                and evidence_json                        (done runs)
    /runs/<key>/section/t, /section/points (n, d)   attrs channels, units, size, center, period
    /runs/<key>/channels/t, /channels/<name>        the stored channels over the analysed span
                                                    (keep="channels" or "full")
    /runs/<key>/result          the reference run in the layout of daeclear.results.result
                                (keep="full"; read it with SweepResult.result)

``<key>`` is ``run-`` + the first 16 hex digits of the SHA-256 of the run's parameters as
canonical JSON: the same point always has the same key, whatever grid it came from.

Examples
--------
>>> import daeclear as dc
>>> out = dc.sweep("clearance.h5", {"clearance": [0.01e-3, 0.1e-3, 0.5e-3]},
...                fixed={"joint": "revolute"})                      # doctest: +SKIP
>>> [(r.parameters["clearance"], r.motion) for r in out.runs]         # doctest: +SKIP

On a Dask cluster::

    from dask.distributed import Client
    client = Client("tcp://scheduler:8786")            # or Client(LocalCluster(...))
    dc.sweep("big.h5", grid, executor=client.get_executor())
"""

from __future__ import annotations

import concurrent.futures as cf
import hashlib
import itertools
import json
import math
import os
import signal
import socket
import sys
import time
import traceback as tb
import uuid
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .analysis import CHANNELS, PhasePortrait, PoincareSection, section_channels
from ..errors import DaeclearError, DaeclearWarning, OutputError, SceneError
from ..progress import Progress
from ..results.outputs import check_file, deferred_sigint, sigint_latch

if TYPE_CHECKING:
    import h5py

    from ..results.result import Result

__all__ = ["FORMAT_NAME", "FORMAT_VERSION", "KEEP", "RunRecord", "SweepResult", "grid_points", "load_sweep",
           "run_key", "sweep"]

FORMAT_NAME = "daeclear-sweep"
FORMAT_VERSION = 1
KEEP: tuple[str, ...] = ("section", "channels", "full")
ANALYSIS_OPTIONS = ("channels", "revolutions", "transient", "per_revolution", "phase", "twin", "twin_revolutions",
                    "perturbation", "seed", "tol", "max_period", "decorrelation", "rtol", "atol", "max_step",
                    "formulation", "backend")


# --------------------------------------------------------------------------- parameters and keys


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
    raise SceneError(f"sweep: parameter {name!r} = {value!r} is a {type(value).__name__}; sweep parameters must be "
                     "numbers, strings, bools, None or lists of them (give a law by name, e.g. law='hertz').")


def _canonical(parameters: Mapping[str, Any]) -> str:
    return json.dumps({k: parameters[k] for k in sorted(parameters)}, sort_keys=True, separators=(",", ":"))


def run_key(parameters: Mapping[str, Any]) -> str:
    """The stable name of a run: ``run-`` + 16 hex digits of the SHA-256 of its parameters (canonical JSON)."""
    plain = {str(k): _plain_value(str(k), v) for k, v in parameters.items()}
    return "run-" + hashlib.sha256(_canonical(plain).encode()).hexdigest()[:16]


def grid_points(grid: Mapping[str, Iterable[Any]]) -> list[dict[str, Any]]:
    """Every combination of the grid's values, the last name varying fastest.

    Parameters
    ----------
    grid : mapping of str to iterable
        Parameter name -> values, e.g. ``{"clearance": [0.1e-3, 0.5e-3], "friction": [0.01, 0.1]}``.

    Returns
    -------
    list of dict
        One dict per point, in ``itertools.product`` order.
    """
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


# --------------------------------------------------------------------------- records


@dataclass(frozen=True)
class RunRecord:
    """One run of a sweep, as stored.

    Attributes
    ----------
    key : str
        Group name under ``/runs``.
    index : int
        Position in the sweep's list of points.
    parameters : dict
        The scene parameters of the run (fixed ones included).
    status : {"done", "failed"}
    motion : str
        Motion label (:data:`daeclear.analysis.MOTION_LABELS`); "" for a failed run.
    period : int
        Period in revolutions for a periodic run, else 0.
    evidence : dict
        The classification evidence (:class:`daeclear.analysis.MotionClass`).
    reason : str
        The classification's one-line reason.
    error : str
        ``"<Exception>: <message>"`` of a failed run, else "".
    traceback : str
        Its traceback text.
    wall_time : float
        Seconds the worker spent on the run.
    computed_at : str
        UTC time the run finished (ISO 8601).
    worker : str
        ``host:pid`` of the worker process.
    """

    key: str
    index: int
    parameters: dict[str, Any]
    status: str
    motion: str = ""
    period: int = 0
    evidence: dict[str, Any] = field(default_factory=dict)
    reason: str = ""
    error: str = ""
    traceback: str = ""
    wall_time: float = float("nan")
    computed_at: str = ""
    worker: str = ""

    @property
    def ok(self) -> bool:
        return self.status == "done"

    def row(self) -> dict[str, Any]:
        """Parameters, status, motion and the main evidence as one flat dict (a table row)."""
        row: dict[str, Any] = dict(self.parameters)
        row.update(status=self.status, motion=self.motion, period=self.period)
        for name in ("periodicity_defect", "n_clusters", "spread", "decorrelation", "lyapunov",
                     "lyapunov_per_revolution", "fit_r2"):
            row[name] = self.evidence.get(name, float("nan"))
        row.update(error=self.error, wall_time=self.wall_time)
        return row


# --------------------------------------------------------------------------- the worker


def _build_scene(mechanism: str | Callable[..., Any], parameters: Mapping[str, Any]) -> Any:
    if callable(mechanism):
        return mechanism(**parameters)
    from ..model.scenefile import MECHANISMS

    if mechanism not in MECHANISMS:
        raise SceneError(f"sweep: mechanism={mechanism!r}, must be one of {', '.join(MECHANISMS)} or a callable "
                         "returning a Scene.")
    return MECHANISMS[mechanism](**parameters)


def _ignore_sigint(parent: int | None = None) -> None:
    """Process-pool initializer: Ctrl-C goes to the sweep's own process, which stops the workers; and
    on Linux a worker dies with the sweep's process (killed hard, no cleanup) instead of lingering."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover - no prctl: workers end with their queue
            return
        if parent is not None and os.getppid() != parent:  # the parent died before prctl took effect
            os._exit(1)


def _run_task(task: Mapping[str, Any]) -> dict[str, Any]:
    """Build the scene of one point, classify its motion and return plain data (runs in a worker)."""
    from .analysis import classify_motion

    start = time.perf_counter()
    out: dict[str, Any] = {"key": task["key"], "index": task["index"], "parameters": dict(task["parameters"]),
                           "worker": f"{socket.gethostname()}:{os.getpid()}"}
    try:
        scene = _build_scene(task["mechanism"], task["parameters"])
        analysis = classify_motion(scene, **task["analysis"])
        section = analysis.section
        data: dict[str, Any] = {
            "section": {"t": np.asarray(section.t), "points": np.asarray(section.points),
                        "channels": list(section.channels), "units": list(section.units),
                        "size": np.asarray(section.size), "center": np.asarray(section.center),
                        "period": section.period},
            "motion": {"label": analysis.motion.label, "period": analysis.motion.period,
                       "reason": analysis.motion.reason, "evidence": dict(analysis.motion.evidence)},
        }
        if task["keep"] in ("channels", "full"):
            t0 = float(task["analysis"].get("transient", 10)) * section.period
            result = analysis.result
            mask = result.window_mask(t0 - 1e-9 * section.period, None)
            data["channels"] = {"t": np.asarray(result.t)[mask],
                                **{name: np.asarray(result[name])[mask] for name in task["store_channels"]}}
            data["units"] = {name: result.units.get(name, "") for name in task["store_channels"]}
        if task["keep"] == "full":
            data["result"] = analysis.result
        out.update(status="done", data=data)
    except KeyboardInterrupt:
        out.update(status="interrupted")
    except Exception as exc:  # a failed run is recorded with its error, never lost
        message = str(exc)
        if "interrupted by the user" in message:
            out.update(status="interrupted")
        else:
            out.update(status="failed", error=f"{type(exc).__name__}: {message}", traceback=tb.format_exc())
    out["wall_time"] = time.perf_counter() - start
    out["computed_at"] = datetime.now(timezone.utc).isoformat(timespec="seconds")
    return out


# --------------------------------------------------------------------------- HDF5 writing


def _attr_value(value: Any) -> Any:
    """A value HDF5 can hold as an attribute (the JSON copy keeps the exact value)."""
    if value is None:
        return "None"
    if isinstance(value, bool):
        return np.bool_(value)
    if isinstance(value, (int, float, str)):
        return value
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                          for v in value):
        return np.asarray(value, dtype=float)
    return json.dumps(value)


def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def _write_run(group: h5py.Group, outcome: Mapping[str, Any], mechanism: str, options: Mapping[str, Any]) -> None:
    """Write one run's outcome into ``group`` (the root of its journal file)."""
    import h5py

    params = outcome["parameters"]
    for name, value in params.items():
        group.attrs[name] = _attr_value(value)
    group.attrs["parameters_json"] = json.dumps(params, sort_keys=True)
    info = group.create_group("info")
    for name in ("key", "index", "status", "worker", "computed_at"):
        info.attrs[name] = outcome[name]
    info.attrs["wall_time"] = float(outcome.get("wall_time", float("nan")))
    info.attrs["error"] = outcome.get("error", "")
    info.attrs["traceback"] = outcome.get("traceback", "")
    info.attrs["mechanism"] = mechanism  # the sweep's settings, so a journal alone can be checked on resume
    info.attrs["options_json"] = json.dumps(options, sort_keys=True)
    data = outcome.get("data")
    if outcome["status"] != "done" or data is None:
        return
    motion = group.create_group("motion")
    motion.attrs["label"] = data["motion"]["label"]
    motion.attrs["period"] = int(data["motion"]["period"])
    motion.attrs["reason"] = data["motion"]["reason"]
    evidence = data["motion"]["evidence"]
    for name, value in evidence.items():
        motion.attrs[name] = _attr_value(value.item() if isinstance(value, np.generic) else value)
    motion.attrs["evidence_json"] = json.dumps(evidence, default=_json_default)
    sec = data["section"]
    section = group.create_group("section")
    section.create_dataset("t", data=sec["t"])
    section.create_dataset("points", data=sec["points"])
    section.attrs["channels"] = np.array(sec["channels"], dtype=h5py.string_dtype())
    section.attrs["units"] = np.array(sec["units"], dtype=h5py.string_dtype())
    section.attrs["size"] = sec["size"]
    section.attrs["center"] = sec["center"]
    section.attrs["period"] = float(sec["period"])
    if "channels" in data:
        channels = group.create_group("channels")
        for name, values in data["channels"].items():
            ds = channels.create_dataset(name, data=values)
            ds.attrs["units"] = "s" if name == "t" else data["units"].get(name, "")
    if "result" in data:
        from ..results.result import write_result_group  # the Result's own layout, inside this group

        write_result_group(group.create_group("result"), data["result"])


def _write_part(parts: Path, outcome: Mapping[str, Any], mechanism: str, options: Mapping[str, Any]) -> Path:
    """Write one run to ``parts/<key>.h5`` atomically (temporary name, fsync, rename)."""
    import h5py

    parts.mkdir(parents=True, exist_ok=True)
    final = parts / f"{outcome['key']}.h5"
    tmp = parts / f".{outcome['key']}.{uuid.uuid4().hex[:12]}.tmp"
    try:
        with h5py.File(tmp, "x") as f:
            _write_run(f, outcome, mechanism, options)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, final)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return final


def _parts_dir(path: Path) -> Path:
    return path.with_name(path.name + ".parts")


def _part_files(path: Path) -> list[Path]:
    parts = _parts_dir(path)
    if not parts.is_dir():
        return []
    return sorted(p for p in parts.glob("run-*.h5") if not p.name.startswith("."))


def _header(f: h5py.File | h5py.Group, mechanism: str, options: Mapping[str, Any]) -> None:
    f.attrs["format"] = FORMAT_NAME
    f.attrs["version"] = FORMAT_VERSION
    f.attrs["mechanism"] = mechanism
    f.attrs["options_json"] = json.dumps(options, sort_keys=True)


def _consolidate(path: Path, *, mechanism: str, options: Mapping[str, Any], order: Mapping[str, int]) -> None:
    """Merge ``path`` and its journal into a new file renamed over ``path``; then drop the merged journal."""
    import h5py

    parts = _part_files(path)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:12]}.tmp")
    merged: list[Path] = []
    try:
        with h5py.File(tmp, "x") as dst:
            _header(dst, mechanism, options)
            runs = dst.create_group("runs")
            part_keys = {p.stem for p in parts}
            if path.is_file():
                with h5py.File(path, "r") as src:
                    for key in src.get("runs", {}):
                        if key not in part_keys:
                            src.copy(src["runs"][key], runs, name=key)
            for part in parts:
                try:
                    with h5py.File(part, "r") as src:
                        src.copy(src["/"], runs, name=part.stem)
                    merged.append(part)
                except OSError as exc:  # unreadable journal file: keep it, say so
                    warnings.warn(f"sweep: journal file {part} cannot be read ({exc}); left in place.",
                                  DaeclearWarning, stacklevel=2)
            extra = len(order)
            for key in sorted(runs, key=lambda k: int(runs[k]["info"].attrs["index"])):
                info = runs[key]["info"]
                if key in order:
                    info.attrs["index"] = int(order[key])
                else:  # a run of an earlier grid: after the current ones, in its old order
                    info.attrs["index"] = extra
                    extra += 1
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    for part in merged:
        part.unlink(missing_ok=True)
    if _parts_dir(path).is_dir():  # half-written parts of a killed sweep (the lock is ours: no writer runs)
        for stale in _parts_dir(path).glob(".run-*.tmp"):
            stale.unlink(missing_ok=True)
    try:
        _parts_dir(path).rmdir()
    except OSError:
        pass  # not empty (an unreadable part) or absent


# --------------------------------------------------------------------------- reading


def _text(value: Any) -> str:
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def _read_record(group: h5py.Group) -> RunRecord:
    info = group["info"].attrs
    motion: dict[str, Any] = {}
    evidence: dict[str, Any] = {}
    if "motion" in group:
        m = group["motion"].attrs
        motion = {"motion": _text(m["label"]), "period": int(m["period"]), "reason": _text(m["reason"])}
        evidence = json.loads(_text(m["evidence_json"]))
    return RunRecord(key=_text(info["key"]), index=int(info["index"]),
                     parameters=json.loads(_text(group.attrs["parameters_json"])), status=_text(info["status"]),
                     evidence=evidence, error=_text(info["error"]), traceback=_text(info["traceback"]),
                     wall_time=float(info["wall_time"]), computed_at=_text(info["computed_at"]),
                     worker=_text(info["worker"]), **motion)


def _same(a: Any, b: Any) -> bool:
    """Parameter values equal, floats to 1e-12 relative (0.5e-3 typed twice may differ in the last bit)."""
    if isinstance(a, float) and isinstance(b, (int, float)) and not isinstance(b, bool):
        return math.isclose(a, float(b), rel_tol=1e-12)
    return bool(a == b)


def _check_format(f: h5py.File, path: Path) -> None:
    fmt = _text(f.attrs.get("format", ""))
    if fmt != FORMAT_NAME:
        raise DaeclearError(f"'{path}' is not a daeclear sweep file (root attribute format={fmt!r}, "
                            f"expected {FORMAT_NAME!r}).")
    if int(f.attrs.get("version", 0)) > FORMAT_VERSION:
        raise DaeclearError(f"'{path}' is a daeclear sweep of format version {int(f.attrs['version'])}; this "
                            f"daeclear reads versions up to {FORMAT_VERSION}. Upgrade daeclear.")


class SweepResult:
    """The runs of a sweep file (and its journal of runs not yet merged), with their data.

    Attributes
    ----------
    path : pathlib.Path
        The sweep file.
    runs : list of RunRecord
        Every run, in index order.
    mechanism : str
        The mechanism (name, or ``module:function`` of a callable).
    options : dict
        The analysis options of the sweep (:func:`daeclear.analysis.classify_motion`), ``keep``
        and the stored channels.
    n_computed, n_skipped : int
        Runs computed and runs found finished by the call that returned this (0 from `load_sweep`).
    """

    def __init__(self, path: Path, runs: list[RunRecord], mechanism: str, options: dict[str, Any],
                 n_computed: int = 0, n_skipped: int = 0) -> None:
        self.path = path
        self.runs = runs
        self.mechanism = mechanism
        self.options = options
        self.n_computed = n_computed
        self.n_skipped = n_skipped

    def __len__(self) -> int:
        return len(self.runs)

    def __iter__(self) -> Any:
        return iter(self.runs)

    def __repr__(self) -> str:
        done = sum(r.ok for r in self.runs)
        counts: dict[str, int] = {}
        for r in self.runs:
            if r.ok:
                counts[r.motion] = counts.get(r.motion, 0) + 1
        motions = ", ".join(f"{n} {label}" for label, n in sorted(counts.items()))
        return (f"SweepResult('{self.path}': {len(self.runs)} runs, {done} done, {len(self.runs) - done} failed"
                + (f"; {motions}" if motions else "") + ")")

    @property
    def failed(self) -> list[RunRecord]:
        """The failed runs."""
        return [r for r in self.runs if not r.ok]

    def parameter_names(self) -> list[str]:
        """Names of the parameters that vary between runs, in first-seen order."""
        names: dict[str, None] = {}
        for r in self.runs:
            names.update(dict.fromkeys(r.parameters))
        return [n for n in names if len({json.dumps(r.parameters.get(n), sort_keys=True) for r in self.runs}) > 1]

    def table(self) -> list[dict[str, Any]]:
        """One flat dict per run (:meth:`RunRecord.row`), in index order."""
        return [r.row() for r in self.runs]

    def run(self, key: str | int | None = None, **parameters: Any) -> RunRecord:
        """A run by key, by index, or by (some of) its parameter values.

        Raises
        ------
        KeyError
            If no run, or more than one, matches.
        """
        if isinstance(key, str):
            found = [r for r in self.runs if r.key == key]
        elif isinstance(key, int):
            found = [r for r in self.runs if r.index == key]
        else:
            found = [r for r in self.runs if all(k in r.parameters and _same(r.parameters[k], v)
                                                 for k, v in parameters.items())]
        if len(found) != 1:
            what = key if key is not None else parameters
            raise KeyError(f"sweep '{self.path}': {len(found)} runs match {what!r}; give a key, an index or "
                           "enough parameter values to pick one.")
        return found[0]

    def _open(self, record: RunRecord) -> tuple[Any, str]:
        """(open h5py.File, group path) holding the run: the journal file if present, else the sweep file."""
        import h5py

        part = _parts_dir(self.path) / f"{record.key}.h5"
        if part.is_file():
            return h5py.File(part, "r"), "/"
        return h5py.File(self.path, "r"), f"/runs/{record.key}"

    def _record(self, run: RunRecord | str | int) -> RunRecord:
        return run if isinstance(run, RunRecord) else self.run(run)

    def section(self, run: RunRecord | str | int) -> PoincareSection:
        """The Poincaré section of a run."""
        record = self._record(run)
        if not record.ok:
            raise DaeclearError(f"run {record.key} failed ({record.error}); it has no section.")
        f, where = self._open(record)
        with f:
            g = f[where]["section"]
            return PoincareSection(t=g["t"][()], points=g["points"][()],
                                   channels=tuple(_text(c) for c in g.attrs["channels"]),
                                   units=tuple(_text(u) for u in g.attrs["units"]), period=float(g.attrs["period"]),
                                   size=np.asarray(g.attrs["size"], dtype=float),
                                   center=np.asarray(g.attrs["center"], dtype=float))

    def channels(self, run: RunRecord | str | int) -> dict[str, np.ndarray]:
        """The stored channels of a run over its analysed span (``"t"`` included)."""
        record = self._record(run)
        f, where = self._open(record)
        with f:
            g = f[where]
            if "channels" not in g:
                raise DaeclearError(f"run {record.key}: no channels stored (sweep keep={self.options.get('keep')!r}; "
                                    "use keep='channels' or 'full').")
            return {name: g["channels"][name][()] for name in g["channels"]}

    def portrait(self, run: RunRecord | str | int, x: str | None = None, y: str | None = None) -> PhasePortrait:
        """Phase portrait of two stored channels (default: the section channels) over the analysed span."""
        record = self._record(run)
        stored = self.channels(record)
        section_channels = list(self.options.get("channels", CHANNELS))
        x = x or section_channels[0]
        y = y or section_channels[1 if len(section_channels) > 1 else 0]
        for name in (x, y):
            if name not in stored:
                raise DaeclearError(f"run {record.key}: channel {name!r} not stored; stored: "
                                    f"{', '.join(n for n in stored if n != 't')}.")
        f, where = self._open(record)
        with f:
            units = tuple(_text(f[where]["channels"][n].attrs.get("units", "")) for n in (x, y))
        return PhasePortrait(t=stored["t"], x=stored[x], y=stored[y], names=(x, y),
                             units=units)  # type: ignore[arg-type]

    def result(self, run: RunRecord | str | int) -> Result:
        """The full reference run (sweeps with ``keep="full"``)."""
        from ..results.result import read_result_group

        record = self._record(run)
        f, where = self._open(record)
        with f:
            g = f[where]
            if "result" not in g:
                raise DaeclearError(f"run {record.key}: no full result stored (sweep keep="
                                    f"{self.options.get('keep')!r}; use keep='full').")
            return read_result_group(g["result"], self.path)

    def bifurcation_data(self, parameter: str, channel: str | int = 0) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """Section values of one channel against a swept parameter, for a bifurcation diagram.

        Returns
        -------
        x : ndarray
            The parameter value of each section point.
        y : ndarray
            The section values of ``channel`` (name or column index).
        labels : list of str
            The motion label of the run of each point.
        """
        xs, ys, labels = [], [], []
        for r in self.runs:
            if not r.ok:
                continue
            sec = self.section(r)
            col = sec.channels.index(channel) if isinstance(channel, str) else int(channel)
            value = r.parameters.get(parameter)
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise DaeclearError(f"bifurcation_data: parameter {parameter!r} of run {r.key} is {value!r}, "
                                    "not a number.")
            xs.append(np.full(len(sec), float(value)))
            ys.append(sec.points[:, col])
            labels += [r.motion] * len(sec)
        return (np.concatenate(xs) if xs else np.zeros(0), np.concatenate(ys) if ys else np.zeros(0), labels)


def _unreadable(path: Path, exc: OSError) -> DaeclearError:
    """The error for a sweep file HDF5 cannot open, with the recovery that fits: a truncated file (a
    copy or a write cut short) is a damaged sweep, anything else is not a sweep file."""
    if "truncated file" not in str(exc):
        return DaeclearError(f"'{path}' cannot be opened as HDF5 ({exc}); it is not a daeclear sweep file. "
                             "Give another path (or delete it to start over).")
    journal = _parts_dir(path)
    kept = len(_part_files(path))
    return DaeclearError(
        f"'{path}' is a truncated daeclear sweep file ({path.stat().st_size} bytes; HDF5: {exc}): a copy or a write "
        "that was cut short, whose runs cannot be read. To recover: restore the file from a copy if you have one; "
        f"otherwise move it aside (e.g. rename it to '{path.name}.damaged') and run the same sweep again: the "
        f"{kept} run(s) in its journal '{journal}' are kept, the others are computed again.")


def load_sweep(path: str | os.PathLike[str]) -> SweepResult:
    """Read a sweep file, with the runs of its journal that are not merged yet.

    Raises
    ------
    FileNotFoundError
        If neither the file nor its journal exists.
    DaeclearError
        If the file is not a daeclear sweep.
    """
    import h5py

    path = Path(path)
    records: dict[str, RunRecord] = {}
    mechanism, options = "", {}
    if path.is_file():
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise _unreadable(path, exc) from None
        with f:
            _check_format(f, path)
            mechanism = _text(f.attrs["mechanism"])
            options = json.loads(_text(f.attrs["options_json"]))
            for key in f.get("runs", {}):
                records[key] = _read_record(f["runs"][key])
    parts = _part_files(path)
    if not path.is_file() and not parts:
        raise FileNotFoundError(f"no sweep file '{path}' (nor journal '{_parts_dir(path)}').")
    for part in parts:
        try:
            with h5py.File(part, "r") as f:
                records[part.stem] = _read_record(f["/"])
                if not options:  # journal only (an interrupted first invocation): the settings of its runs
                    mechanism = _text(f["info"].attrs["mechanism"])
                    options = json.loads(_text(f["info"].attrs["options_json"]))
        except (OSError, KeyError, ValueError) as exc:
            warnings.warn(f"sweep: journal file {part} cannot be read ({exc}); skipped.", DaeclearWarning,
                          stacklevel=2)
    runs = sorted(records.values(), key=lambda r: (r.index, r.key))
    return SweepResult(path, runs, mechanism, options)


# --------------------------------------------------------------------------- locking and progress


def _lock_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _acquire_lock(path: Path, meta: Mapping[str, Any]) -> Path:
    """Create ``<path>.lock`` (pid, host); a lock left by a dead process on this host is taken over."""
    lock = _lock_path(path)
    text = json.dumps({"pid": os.getpid(), "host": socket.gethostname(), **meta}, default=_json_default)
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            try:
                owner = json.loads(lock.read_text())
            except (OSError, ValueError):
                owner = {}
            same_host = owner.get("host") == socket.gethostname()
            if same_host and isinstance(owner.get("pid"), int) and not _pid_alive(owner["pid"]):
                lock.unlink(missing_ok=True)  # stale: its sweep was killed
                continue
            raise DaeclearError(f"sweep '{path}' is in use by process {owner.get('pid', '?')} on "
                                f"{owner.get('host', '?')} (lock file '{lock}'). Wait for it, or delete the lock "
                                "file if that process is gone.") from None
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        return lock
    raise DaeclearError(f"sweep '{path}': cannot take the lock file '{lock}'.")


# --------------------------------------------------------------------------- the sweep


def _mechanism_name(mechanism: str | Callable[..., Any]) -> str:
    if isinstance(mechanism, str):
        return mechanism
    return f"{getattr(mechanism, '__module__', '?')}:{getattr(mechanism, '__qualname__', repr(mechanism))}"


def _short(parameters: Mapping[str, Any], names: Sequence[str]) -> str:
    return " ".join(f"{n}={parameters[n]:g}" if isinstance(parameters[n], float) else f"{n}={parameters[n]}"
                    for n in names if n in parameters)


def _terminate(executor: cf.Executor) -> None:
    """Stop our own process pool's workers now (their running tasks are abandoned, not recorded)."""
    processes = getattr(executor, "_processes", None) or {}
    for process in list(processes.values()):
        try:
            process.terminate()
        except Exception:  # already gone
            pass


def sweep(path: str | os.PathLike[str], grid: Mapping[str, Iterable[Any]] | None = None, *,
          runs: Iterable[Mapping[str, Any]] | None = None, mechanism: str | Callable[..., Any] = "slider_crank",
          fixed: Mapping[str, Any] | None = None, channels: Sequence[str] | None = None,
          store_channels: Sequence[str] | None = None, keep: str = "channels", revolutions: int = 30,
          transient: int = 10, per_revolution: int = 32, twin: bool | str = True, rtol: float = 1e-6,
          analysis: Mapping[str, Any] | None = None, executor: cf.Executor | None = None,
          max_workers: int | None = None, resume: bool = True, retry_failed: bool = False, progress: bool = True,
          on_run: Callable[[RunRecord], None] | None = None) -> SweepResult:
    """Run and classify one scene per parameter point, in parallel, into one HDF5 file.

    Parameters
    ----------
    path : str or path-like
        The sweep file (``.h5``); its directory must exist. With ``resume=True`` an existing
        file (and its journal ``<path>.parts/``) is continued.
    grid : mapping of str to list, optional
        Parameter name -> values; every combination is run (:func:`grid_points`).
    runs : iterable of dict, optional
        Explicit parameter points, instead of or after the grid's.
    mechanism : str or callable
        Name of a ready mechanism (``"slider_crank"``) or a picklable top-level function
        ``f(**parameters) -> Scene``.
    fixed : mapping, optional
        Parameters common to every run (e.g. ``{"joint": "revolute"}``); part of each run's
        parameters and key.
    channels : sequence of str, optional
        Poincaré-section channels; default those of the first point's scene
        (:func:`daeclear.analysis.section_channels`: slider velocity and acceleration, or the last
        body's angular velocity and acceleration in a mechanism without a slider).
    store_channels : sequence of str, optional
        Channels stored over the analysed span with ``keep="channels"``; default ``channels``.
    keep : {"section", "channels", "full"}
        What each run stores beyond its classification and section: nothing, the stored
        channels (default), or also the full reference Result.
    revolutions, transient, per_revolution, twin, rtol
        Passed to :func:`daeclear.analysis.classify_motion`.
    analysis : mapping, optional
        Further options of :func:`~daeclear.analysis.classify_motion` (``phase``, ``tol``,
        ``max_period``, ``decorrelation``, ``perturbation``, ``seed``, ``twin_revolutions``,
        ``atol``, ``max_step``, ``formulation``, ``backend``).
    executor : concurrent.futures.Executor, optional
        Where runs go. Default: a local process pool (spawned processes, ``max_workers``
        of them, the platform's start method: on macOS and Windows a script must call
        sweep under ``if __name__ == "__main__":``) created and shut down here. A Dask
        cluster: ``client.get_executor()``.
    max_workers : int, optional
        Size of the default pool (default: the CPU count, at most the number of runs).
    resume : bool
        Continue an existing file, skipping its finished runs (default). False deletes the
        file's runs and journal first.
    retry_failed : bool
        On resume, run the recorded failed runs again.
    progress : bool
        Progress line on stderr.
    on_run : callable, optional
        Called with each new RunRecord as soon as it is saved (e.g. live monitoring).

    Returns
    -------
    SweepResult
        Every run of the file (earlier ones included), in index order.

    Raises
    ------
    SceneError
        Bad arguments (unknown option, non-plain parameter value, no points).
    DaeclearError
        The file belongs to another sweep (different mechanism or options: the message says
        which), is locked by a running sweep, or the process pool broke (finished runs are
        saved; run again to resume).
    KeyboardInterrupt
        Re-raised after the finished runs are saved.
    """
    from .. import options as check

    path = check_file(path, "sweep(path)", what="a sweep file (.h5)", example="sweep.h5")  # before any work
    if _parts_dir(path).exists() and not _parts_dir(path).is_dir():
        raise OutputError(f"sweep(path) '{path}': its journal '{_parts_dir(path)}' is a file; it must be a "
                          "directory (move the file away).")
    if _lock_path(path).is_dir():
        raise OutputError(f"sweep(path) '{path}': its lock '{_lock_path(path)}' is a directory; remove it.")
    if keep not in KEEP:
        raise SceneError(f"sweep: keep={keep!r}, must be one of {', '.join(KEEP)}.")
    check.revolutions(revolutions)
    check.transient(transient)
    check.per_revolution(per_revolution)
    check.rtol(rtol, where="sweep")
    check.workers(max_workers)
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
    if not isinstance(mechanism, str) and not callable(mechanism):
        raise SceneError(f"sweep: mechanism={mechanism!r}, must be a mechanism name or a callable.")
    base = {str(k): _plain_value(str(k), v) for k, v in (fixed or {}).items()}
    points = grid_points(grid) if grid else []
    points += [dict(p) for p in (runs or [])]
    if not points:
        raise SceneError("sweep: no parameter points; give grid= and/or runs=.")
    if channels is None:  # from what the mechanism holds (every point has its bodies)
        first = {**base, **{str(k): _plain_value(str(k), v) for k, v in points[0].items()}}
        channels = section_channels(_build_scene(mechanism, first))
    options = {"channels": [str(c) for c in channels], "revolutions": revolutions, "transient": transient,
               "per_revolution": per_revolution, "twin": twin, "rtol": rtol, **extra}
    stored = [str(c) for c in (store_channels if store_channels is not None else channels)]
    file_options = {**{k: _plain_value(k, v) for k, v in options.items()}, "keep": keep, "store_channels": stored}
    mech_name = _mechanism_name(mechanism)
    tasks: list[dict[str, Any]] = []
    order: dict[str, int] = {}
    for point in points:
        params = {**base, **{str(k): _plain_value(str(k), v) for k, v in point.items()}}
        key = run_key(params)
        if key in order:
            continue  # the same point twice: one run
        order[key] = len(tasks)
        tasks.append({"key": key, "index": len(tasks), "parameters": params, "mechanism": mechanism,
                      "analysis": {k: (tuple(v) if k == "channels" else v) for k, v in options.items()},
                      "keep": keep, "store_channels": stored})
    varying = [n for n in dict.fromkeys(k for t in tasks for k in t["parameters"])
               if len({json.dumps(t["parameters"].get(n)) for t in tasks}) > 1]

    lock = _acquire_lock(path, {"mechanism": mech_name})
    n_computed = n_skipped = 0
    checked = False  # the file is merged only once it is known to belong to this sweep
    try:
        if not resume:
            path.unlink(missing_ok=True)
            for part in _part_files(path):
                part.unlink()
        existing: dict[str, RunRecord] = {}
        if path.is_file() or _part_files(path):
            previous = load_sweep(path)
            if previous.options and (previous.mechanism, previous.options) != (mech_name, file_options):
                diffs = [f"{k}: file {previous.options.get(k)!r}, now {file_options.get(k)!r}"
                         for k in sorted(set(previous.options) | set(file_options))
                         if previous.options.get(k) != file_options.get(k)]
                if previous.mechanism != mech_name:
                    diffs.insert(0, f"mechanism: file {previous.mechanism!r}, now {mech_name!r}")
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
            if checked and (path.is_file() or _part_files(path)):
                with deferred_sigint():  # a second Ctrl-C waits for the merge (atomic anyway: the journal stays)
                    _consolidate(path, mechanism=mech_name, options=file_options, order=order)
        finally:
            lock.unlink(missing_ok=True)
    out = load_sweep(path) if path.is_file() else SweepResult(path, [], mech_name, file_options)
    out.n_computed, out.n_skipped = n_computed, n_skipped
    return out


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
        executor = cf.ProcessPoolExecutor(max_workers=workers, initializer=_ignore_sigint, initargs=(os.getpid(),))
    assert executor is not None
    parts = _parts_dir(path)
    done = failed = 0
    futures: dict[cf.Future[Any], dict[str, Any]] = {}
    with sigint_latch() as interrupted:  # every Ctrl-C, even one Python drops, stops the sweep
        try:
            futures = {executor.submit(_run_task, task): task for task in todo}
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
                               "computed_at": datetime.now(timezone.utc).isoformat(timespec="seconds")}
                if outcome["status"] == "interrupted":
                    continue  # not recorded: computed again on resume
                _write_part(parts, outcome, mechanism, options)
                done += 1
                failed += outcome["status"] == "failed"
                data = outcome.get("data") or {}
                label = data.get("motion", {}).get("label", "FAILED") if outcome["status"] == "done" else "FAILED"
                line.update(done, note(failed, f"{_short(outcome['parameters'], varying)} -> {label}"))
                if on_run is not None:
                    import h5py

                    with h5py.File(parts / f"{outcome['key']}.h5", "r") as f:
                        record = _read_record(f["/"])
                    on_run(record)
            if interrupted:
                raise KeyboardInterrupt
            line.close()
        except BaseException:
            line.close()
            for future in futures:
                future.cancel()
            if own:
                _terminate(executor)
            raise
        finally:
            if own:
                executor.shutdown(wait=True, cancel_futures=True)
    return done
