"""The sweep file: its HDF5 layout, written one run at a time and read back (``load_sweep``).

HDF5 layout of ``<path>`` (root attributes ``format="daeclear-sweep"``, ``version=1``,
``mechanism``, ``options_json``: the analysis options, ``keep``, ``store_channels`` and, under
``"solver"``, the runs' :class:`daeclear.SolverOptions` as :meth:`~daeclear.SolverOptions.to_dict`)::

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

A run's group is the same in the sweep file and in its journal file ``<path>.parts/<key>.h5``;
:func:`load_sweep` reads both, without running anything.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections import Counter
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .poincare import CHANNELS, PhasePortrait, PoincareSection
from ..core.errors import DaeclearError, DaeclearWarning

if TYPE_CHECKING:
    import h5py

    from ..results.result import Result
    from ..solvers.solver_options import SolverOptions

__all__ = ["FORMAT_NAME", "FORMAT_VERSION", "SOLVER_KEY", "RunRecord", "SweepResult", "json_default", "load_sweep",
           "part_files", "parts_dir", "read_record", "solver_options", "varying_names", "write_header", "write_run"]

FORMAT_NAME = "daeclear-sweep"
FORMAT_VERSION = 1
#: The entry of a sweep's options that holds its SolverOptions (``SolverOptions.to_dict()``).
SOLVER_KEY = "solver"
#: Solver settings that files written before SolverOptions kept among the analysis options.
_LEGACY_SOLVER_KEYS = ("rtol", "atol", "max_step", "formulation", "backend")


def solver_options(options: Mapping[str, Any]) -> SolverOptions:
    """The SolverOptions of a sweep's options (``options[SOLVER_KEY]``, rebuilt by ``from_dict``)."""
    from ..solvers.solver_options import SolverOptions

    return SolverOptions.from_dict(options.get(SOLVER_KEY, {}))


def _current_form(options: dict[str, Any]) -> dict[str, Any]:
    """A sweep's options as written now: a file made before SolverOptions kept ``rtol`` (and any of
    ``atol``, ``max_step``, ``formulation``, ``backend``) among the analysis options; they become
    its ``SOLVER_KEY`` entry, so that such a file is read, and resumed, like a new one."""
    if not options or SOLVER_KEY in options:
        return options
    legacy = {k: options[k] for k in _LEGACY_SOLVER_KEYS if k in options}
    rest = {k: v for k, v in options.items() if k not in _LEGACY_SOLVER_KEYS}
    return {**rest, SOLVER_KEY: solver_options({SOLVER_KEY: legacy}).to_dict()}


@dataclass(frozen=True)
class RunRecord:
    """One run of a sweep, as stored (the layout's fields, see the module docstring).

    ``key`` is the group name under ``/runs``, ``index`` the position in the sweep's points,
    ``parameters`` the run's scene parameters (fixed ones included), ``status`` "done" or "failed";
    a done run has ``motion`` (:data:`daeclear.analysis.MOTION_LABELS`), ``period`` (revolutions, 0
    unless periodic), ``evidence`` and ``reason`` (:class:`daeclear.analysis.MotionClass`); a failed
    one ``error`` (``"<Exception>: <message>"``) and ``traceback``. ``wall_time`` (s), ``computed_at``
    (UTC, ISO 8601) and ``worker`` (``host:pid``) say where and how long it ran.
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


def json_default(value: Any) -> Any:
    """``json.dumps(default=...)`` for numpy values (anything else as its text)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def write_run(group: h5py.Group, outcome: Mapping[str, Any], mechanism: str, options: Mapping[str, Any]) -> None:
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
    motion.attrs["evidence_json"] = json.dumps(evidence, default=json_default)
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


def parts_dir(path: Path) -> Path:
    """The journal folder of a sweep file: ``<path>.parts``."""
    return path.with_name(path.name + ".parts")


def part_files(path: Path) -> list[Path]:
    """The finished journal files of a sweep file, sorted (temporary files excluded)."""
    parts = parts_dir(path)
    if not parts.is_dir():
        return []
    return sorted(p for p in parts.glob("run-*.h5") if not p.name.startswith("."))


def write_header(f: h5py.File | h5py.Group, mechanism: str, options: Mapping[str, Any]) -> None:
    """The root attributes of a sweep file: format, version, mechanism and options."""
    f.attrs["format"] = FORMAT_NAME
    f.attrs["version"] = FORMAT_VERSION
    f.attrs["mechanism"] = mechanism
    f.attrs["options_json"] = json.dumps(options, sort_keys=True)


def varying_names(points: Sequence[Mapping[str, Any]]) -> list[str]:
    """Names of the parameters that differ between points, in first-seen order."""
    names = dict.fromkeys(k for p in points for k in p)
    return [n for n in names if len({json.dumps(p.get(n), sort_keys=True) for p in points}) > 1]


def _text(value: Any) -> str:
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def read_record(group: h5py.Group) -> RunRecord:
    """The RunRecord of one run's group (in the sweep file or a journal file)."""
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


@dataclass(eq=False)
class SweepResult:
    """The runs of a sweep file ``path`` (and of its journal), in index order, with their data.

    ``mechanism`` is a name or the ``module:function`` of a callable; ``options`` the analysis options,
    ``keep``, the stored channels and, under ``"solver"``, the solver settings (:attr:`solver_options`);
    ``n_computed`` and ``n_skipped`` count the runs the call that returned this computed and found done.
    """

    path: Path
    runs: list[RunRecord]
    mechanism: str
    options: dict[str, Any]
    n_computed: int = 0
    n_skipped: int = 0

    def __len__(self) -> int:
        return len(self.runs)

    @property
    def solver_options(self) -> SolverOptions:
        """The solver settings of the sweep's runs (:class:`daeclear.SolverOptions`, from the file)."""
        return solver_options(self.options)

    def __iter__(self) -> Any:
        return iter(self.runs)

    def __repr__(self) -> str:
        done = sum(r.ok for r in self.runs)
        counts = Counter(r.motion for r in self.runs if r.ok)
        motions = ", ".join(f"{n} {label}" for label, n in sorted(counts.items()))
        return (f"SweepResult('{self.path}': {len(self.runs)} runs, {done} done, {len(self.runs) - done} failed"
                + (f"; {motions}" if motions else "") + ")")

    @property
    def failed(self) -> list[RunRecord]:
        """The failed runs."""
        return [r for r in self.runs if not r.ok]

    def parameter_names(self) -> list[str]:
        """Names of the parameters that vary between runs, in first-seen order."""
        return varying_names([r.parameters for r in self.runs])

    def table(self) -> list[dict[str, Any]]:
        """One flat dict per run (:meth:`RunRecord.row`), in index order."""
        return [r.row() for r in self.runs]

    def run(self, key: str | int | None = None, **parameters: Any) -> RunRecord:
        """A run by key, by index, or by (some of) its parameter values; KeyError unless exactly one matches."""
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

    @contextmanager
    def _group(self, record: RunRecord) -> Iterator[h5py.Group]:
        """The run's open group: in its journal file if present, else in the sweep file."""
        import h5py

        part = parts_dir(self.path) / f"{record.key}.h5"
        journal = part.is_file()
        with h5py.File(part if journal else self.path, "r") as f:
            yield f["/" if journal else f"/runs/{record.key}"]

    def _record(self, run: RunRecord | str | int) -> RunRecord:
        return run if isinstance(run, RunRecord) else self.run(run)

    def section(self, run: RunRecord | str | int) -> PoincareSection:
        """The Poincaré section of a run."""
        record = self._record(run)
        if not record.ok:
            raise DaeclearError(f"run {record.key} failed ({record.error}); it has no section.")
        with self._group(record) as run_group:
            g = run_group["section"]
            return PoincareSection(t=g["t"][()], points=g["points"][()],
                                   channels=tuple(_text(c) for c in g.attrs["channels"]),
                                   units=tuple(_text(u) for u in g.attrs["units"]), period=float(g.attrs["period"]),
                                   size=np.asarray(g.attrs["size"], dtype=float),
                                   center=np.asarray(g.attrs["center"], dtype=float))

    def channels(self, run: RunRecord | str | int) -> dict[str, np.ndarray]:
        """The stored channels of a run over its analysed span (``"t"`` included)."""
        record = self._record(run)
        with self._group(record) as g:
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
        with self._group(record) as g:
            units = tuple(_text(g["channels"][n].attrs.get("units", "")) for n in (x, y))
        return PhasePortrait(t=stored["t"], x=stored[x], y=stored[y], names=(x, y),
                             units=units)  # type: ignore[arg-type]

    def result(self, run: RunRecord | str | int) -> Result:
        """The full reference run (sweeps with ``keep="full"``)."""
        from ..results.result import read_result_group

        record = self._record(run)
        with self._group(record) as g:
            if "result" not in g:
                raise DaeclearError(f"run {record.key}: no full result stored (sweep keep="
                                    f"{self.options.get('keep')!r}; use keep='full').")
            return read_result_group(g["result"], self.path)

    def bifurcation_data(self, parameter: str, channel: str | int = 0) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """For a bifurcation diagram: each section point's ``parameter`` value, its value of ``channel``
        (name or column index) and its run's motion label."""
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
    journal = parts_dir(path)
    kept = len(part_files(path))
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
                records[key] = read_record(f["runs"][key])
    parts = part_files(path)
    if not path.is_file() and not parts:
        raise FileNotFoundError(f"no sweep file '{path}' (nor journal '{parts_dir(path)}').")
    for part in parts:
        try:
            with h5py.File(part, "r") as f:
                records[part.stem] = read_record(f["/"])
                if not options:  # journal only (an interrupted first invocation): the settings of its runs
                    mechanism = _text(f["info"].attrs["mechanism"])
                    options = json.loads(_text(f["info"].attrs["options_json"]))
        except (OSError, KeyError, ValueError) as exc:
            warnings.warn(f"sweep: journal file {part} cannot be read ({exc}); skipped.", DaeclearWarning,
                          stacklevel=2)
    runs = sorted(records.values(), key=lambda r: (r.index, r.key))
    return SweepResult(path, runs, mechanism, _current_form(options))
