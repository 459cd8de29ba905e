"""Files that grow while their run goes on: extendable datasets, appends made whole or not at all, and a
study's run file (rows appended to named columns, its header checked when a later call resumes it).

The streamed result (:class:`daeclear.results.hdf5_stream.ResultWriter`) and a study's history (the wear
study's, :mod:`daeclear.studies.wear_file`) both append with :func:`append_rows`: the room checked before,
Ctrl-C held back until the rows are written, flushed, and on any failure every dataset back to its
length before. A :class:`RunFile`'s layout (docs/hdf5_layout.md, the wear history file is one):

    /@format, /@version      the kind of file and the version of its layout
    /header_json             what the rows depend on, as JSON: a resume must give the same
    /header/**               its browsable mirror (groups and attributes, as a result's /parameters)
    /<column>, /<column>@units   one extendable dataset per column, the row first

A process killed in the middle of an append can leave some columns a row longer than others: a
resume keeps the rows every column has.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import OutputError, SceneError
from ..core.values import to_plain
from .hdf5_write import json_dataset, mirror
from .outputs import check_space, deferred_sigint, disk_full, is_disk_full

if TYPE_CHECKING:  # h5py is imported lazily, only where a file is written
    import h5py

__all__ = ["RunFile", "append_rows", "differences", "extendable"]

#: Rows per HDF5 chunk of a 2-D streamed array (1-D arrays: 4 times as many).
STREAM_ROWS = 1024
#: Values per chunk of a run file's column (32 kB: an append rewrites one chunk), at most 256 rows.
CHUNK_VALUES = 4096


def extendable(group: h5py.Group, name: str, dtype: Any, rest: tuple[int, ...] = (), *, compress: bool = False,
               rows: int | None = None, units: str | None = None) -> h5py.Dataset:
    """An empty dataset of rows of shape ``rest`` that appends extend: chunked by ``rows`` (default
    :data:`STREAM_ROWS`, 4 times that for 1-D), a Fletcher-32 checksum per chunk (not on strings: HDF5
    cannot), gzip when ``compress``; ``units``: its ``units`` attribute."""
    import h5py

    if rows is None:
        rows = STREAM_ROWS if rest else 4 * STREAM_ROWS
    extra: dict[str, Any] = {"compression": "gzip", "compression_opts": 1, "shuffle": True} if compress else {}
    if h5py.check_string_dtype(np.dtype(dtype)) is None:
        extra["fletcher32"] = True
    dataset = group.create_dataset(name, shape=(0, *rest), maxshape=(None, *rest), dtype=dtype,
                                   chunks=(rows, *rest), **extra)
    if units is not None:
        dataset.attrs["units"] = units
    return dataset


def append_rows(f: h5py.File, items: Sequence[tuple[h5py.Dataset, Any]], *, path: Path, what: str,
                extra_bytes: int = 0) -> None:
    """Append ``rows`` to each ``dataset`` of ``items`` (an open file's) as one change, and flush: refused
    before anything is written when the disk lacks room for them (and ``extra_bytes``), a Ctrl-C meanwhile
    raised once they are written, and on any failure every dataset back to its length before (a full
    disk named by ``what`` and ``path``)."""
    arrays = [(dataset, np.asarray(rows, dtype=dataset.dtype)) for dataset, rows in items]
    check_space(path, sum(a.nbytes for _, a in arrays) + extra_bytes, what)
    touched: list[tuple[h5py.Dataset, int]] = []
    with deferred_sigint():
        try:
            for dataset, rows in arrays:
                if len(rows):
                    n = dataset.shape[0]
                    touched.append((dataset, n))
                    dataset.resize(n + len(rows), axis=0)
                    dataset[n:n + len(rows)] = rows
            f.flush()
        except BaseException as exc:  # e.g. MemoryError or a full disk: the file as it was, then go on
            for dataset, n in reversed(touched):
                dataset.resize(n, axis=0)
            if is_disk_full(exc):
                raise disk_full(path, what, exc) from None
            raise


def differences(stored: Any, now: Any, where: str = "") -> list[str]:
    """Where two plain values (JSON) differ: ``"<path>=<stored>, now <now>"`` for each differing leaf
    (at most 5; a scene's differences are named by element and field)."""
    if isinstance(stored, dict) and isinstance(now, dict):
        out: list[str] = []
        for key in sorted(set(stored) | set(now)):
            out += differences(stored.get(key), now.get(key), f"{where}.{key}" if where else str(key))
        return out[:5]
    if stored == now:
        return []
    shown = [repr(v) if len(repr(v)) <= 60 else repr(v)[:57] + "..." for v in (stored, now)]
    return [f"{where}={shown[0]}, now {shown[1]}"]


class RunFile:
    """A study's run file (module docstring): :meth:`open` reads the rows of an existing one (its kind,
    version and header checked, the file kept open), :meth:`append` adds a row to every column (the
    first makes the file).

    Parameters
    ----------
    path : Path
        The file (its place checked by :func:`~daeclear.results.outputs.check_file` first).
    kind, version : str, int
        The file's ``format`` attribute and layout version: a file of another kind or version is refused.
    header : mapping
        What the rows depend on (plain data): a file written with another is refused, naming each difference.
    units : mapping of str to str
        The columns, in order, and the unit of each.
    where, subject : str
        Who writes it (the messages' first word, e.g. ``"simulate_wear"``) and what the header is, e.g.
        ``"scene or settings"``.
    """

    def __init__(self, path: Path, *, kind: str, version: int, header: Mapping[str, Any], units: Mapping[str, str],
                 where: str, subject: str) -> None:
        self.path, self.kind, self.version = Path(path), kind, version
        self.header = json.loads(json.dumps(to_plain(dict(header), f"{where}(header)")))  # as the file gives it back
        self.units = dict(units)
        self.where, self.subject = where, subject
        self._f: h5py.File | None = None

    def __enter__(self) -> RunFile:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the file (what was appended is on disk already)."""
        if self._f is not None:
            try:
                self._f.close()
            finally:
                self._f = None

    def _refuse(self, why: str) -> SceneError:
        return SceneError(f"{self.where}: {self.path} {why}; give a new path.")

    def open(self) -> dict[str, NDArray[Any]] | None:
        """The rows of an existing file, every column's, as many as every column has (None: no file yet,
        or one without rows); an existing file stays open for :meth:`append`."""
        import h5py

        if not self.path.exists():  # made with the first append
            return None
        try:
            self._f = h5py.File(self.path, "r+")
        except PermissionError as exc:
            raise OutputError(f"{self.where}: path='{self.path}', cannot be opened for writing "
                              f"({exc.strerror or exc}); must be a writable file.") from None
        except OSError as exc:
            raise self._refuse(f"cannot be read as HDF5 ({str(exc).splitlines()[0]})") from None
        try:
            return self._check_and_read(self._f)
        except BaseException:
            self.close()
            raise

    def _check_and_read(self, f: h5py.File) -> dict[str, NDArray[Any]] | None:
        kind, version = f.attrs.get("format"), f.attrs.get("version")
        kind = kind.decode() if isinstance(kind, bytes) else kind
        if kind != self.kind:
            raise self._refuse(f"is not a {self.kind} file (its format is {kind!r})")
        if version is None or int(version) != self.version:
            written = "1 (none written)" if version is None else int(version)
            raise self._refuse(f"is a {self.kind} file of layout version {written}, which this daeclear does not "
                               f"resume (it writes and resumes version {self.version}); the file is left as it is")
        try:
            stored = json.loads(f["header_json"].asstr()[()])
        except (KeyError, OSError, ValueError) as exc:
            raise self._refuse(f"is a damaged {self.kind} file: its header cannot be read ({exc})") from None
        changed = differences(stored, self.header)
        if changed:
            raise SceneError(f"{self.where}: {self.path} was written with another {self.subject} ("
                             + "; ".join(changed) + f"); give a new path, or the same {self.subject} to resume.")
        present = [name for name in self.units if name in f]
        if len(present) != len(self.units):  # stopped before its first row: the next append makes them
            if any(f[name].shape[0] for name in present):
                missing = [name for name in self.units if name not in f]
                raise self._refuse(f"is a damaged {self.kind} file: it lacks the column(s) {', '.join(missing)}")
            return None
        n = min(f[name].shape[0] for name in self.units)
        with deferred_sigint():  # the rows of an append a killed process left half-done are dropped
            for name in self.units:
                if f[name].shape[0] > n:
                    f[name].resize(n, axis=0)
        if n == 0:
            return None
        try:
            return {name: f[name][()] for name in self.units}
        except OSError as exc:  # a failed checksum
            raise self._refuse(f"is a damaged {self.kind} file ({str(exc).splitlines()[0]})") from None

    def _create(self) -> None:
        import h5py

        try:
            self._f = f = h5py.File(self.path, "x")
        except OSError as exc:
            raise OutputError(f"{self.where}: path='{self.path}', cannot be created ({exc}); must be a writable "
                              "file.") from None
        with deferred_sigint():
            f.attrs["format"] = self.kind
            f.attrs["version"] = self.version
            json_dataset(f, "header_json", self.header)
            mirror(f.create_group("header"), self.header)
            f.flush()

    def append(self, row: Mapping[str, ArrayLike]) -> None:
        """One row to every column (exactly the columns of ``units``), made whole or not at all; the
        columns are made with the first row, each of its row's shape."""
        if self._f is None:
            self._create()
        f = self._f
        assert f is not None
        if set(row) != set(self.units):
            raise ValueError(f"RunFile.append: the row has {sorted(row)}, must have the columns {list(self.units)}")
        values = {name: np.asarray(row[name], dtype=np.float64) for name in self.units}
        for name, value in values.items():
            if name not in f:
                extendable(f, name, np.float64, value.shape, rows=max(1, min(256, CHUNK_VALUES // max(value.size, 1))),
                           units=self.units[name])
        append_rows(f, [(f[name], value[None]) for name, value in values.items()], path=self.path,
                    what=f"{self.where}(path)")

