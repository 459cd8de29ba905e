"""Crash-safe writing of a sweep file: per-run journal files, their merge, and the file's lock.

Journal files (:func:`write_part`) and the merged file (:func:`consolidate`) are written through
:func:`daeclear.results.outputs.atomic_file`, so a crash at any point leaves the old or the new file
plus the journal; ``<path>.lock`` (:func:`acquire_lock`) keeps two sweeps from writing one file.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .sweep_file import json_default, part_files, parts_dir, write_header, write_run
from ..core.errors import DaeclearError, DaeclearWarning
from ..results.outputs import atomic_file

__all__ = ["acquire_lock", "consolidate", "lock_path", "write_part"]


def write_part(parts: Path, outcome: Mapping[str, Any], mechanism: str, options: Mapping[str, Any]) -> Path:
    """Write one run to ``parts/<key>.h5`` atomically (removed on any exception, Ctrl-C included)."""
    import h5py

    parts.mkdir(parents=True, exist_ok=True)
    final = parts / f"{outcome['key']}.h5"
    with atomic_file(final) as tmp, h5py.File(tmp, "x") as f:  # closed before atomic_file's fsync and rename
        write_run(f, outcome, mechanism, options)
    return final


def consolidate(path: Path, *, mechanism: str, options: Mapping[str, Any], order: Mapping[str, int]) -> None:
    """Merge ``path`` and its journal into a new file renamed over ``path``; then drop the merged journal."""
    import h5py

    parts = part_files(path)
    merged: list[Path] = []
    with atomic_file(path) as tmp:
        with h5py.File(tmp, "x") as dst:
            write_header(dst, mechanism, options)
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
    for part in merged:
        part.unlink(missing_ok=True)
    for stale in parts_dir(path).glob(".run-*.tmp"):  # a killed sweep's half-written parts (the lock is ours)
        stale.unlink(missing_ok=True)
    with contextlib.suppress(OSError):  # not empty (an unreadable part) or absent
        parts_dir(path).rmdir()


def lock_path(path: Path) -> Path:
    """The lock file of a sweep file: ``<path>.lock``."""
    return path.with_name(path.name + ".lock")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        pass
    return True


def acquire_lock(path: Path, meta: Mapping[str, Any]) -> Path:
    """Create ``<path>.lock`` (pid, host); a lock left by a dead process on this host is taken over."""
    lock = lock_path(path)
    text = json.dumps({"pid": os.getpid(), "host": socket.gethostname(), **meta}, default=json_default)
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
