"""Output places checked before any work, and writes that neither an error nor Ctrl-C can half-do.

:func:`check_file` and :func:`check_directory` are the one rule for every place daeclear writes, called
before a run starts so that a bad ``--out`` costs nothing; :func:`deferred_sigint` holds Ctrl-C back
while a file is written; :func:`atomic_file` is the one temporary-file-and-rename write.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import signal
import sys
import tempfile
import threading
import uuid
from collections.abc import Iterator, Sequence
from pathlib import Path
from types import FrameType
from typing import Any

from ..core.errors import DiskFull, OutputDirectoryMissing, OutputError

#: Bytes a write leaves free beyond its own data (HDF5 metadata of each append and of closing the file),
#: so that a file stopped for want of space can still be completed and read back.
SPACE_MARGIN = 1 << 20
_FULL_ERRNOS = (errno.ENOSPC, errno.EDQUOT)


def check_space(path: str | os.PathLike[str], n_bytes: int, what: str) -> None:
    """Raise :class:`DiskFull` when the file system holding ``path`` has less than ``n_bytes`` +
    :data:`SPACE_MARGIN` free: checked before each write, so the write never starts half-way."""
    p = Path(path)
    try:
        free = shutil.disk_usage(p.parent if not p.is_dir() else p).free
    except OSError:  # cannot tell: the write itself will say
        return
    if free < n_bytes + SPACE_MARGIN:
        raise DiskFull(f"{what} '{p}': no space left on the disk ({free / 1e6:.3g} MB free, about "
                       f"{(n_bytes + SPACE_MARGIN) / 1e6:.3g} MB needed to write the next part).")


def is_disk_full(exc: BaseException) -> bool:
    """Whether ``exc`` is a write that failed for want of space (ENOSPC, EDQUOT; HDF5 says so in text)."""
    if isinstance(exc, DiskFull) or (isinstance(exc, OSError) and exc.errno in _FULL_ERRNOS):
        return True
    text = str(exc)
    return "No space left on device" in text or "Disk quota exceeded" in text or "errno = 28" in text


def disk_full(path: str | os.PathLike[str], what: str, exc: BaseException) -> DiskFull:
    """The one message of a write stopped by a full disk (or quota), naming the file."""
    return DiskFull(f"{what} '{Path(path)}': no space left on the disk ({type(exc).__name__}: "
                    f"{str(exc).splitlines()[0][:200]}).")


def _probe(directory: Path, option: str, path: Path) -> None:
    """Create and remove a file in ``directory``: the only writability test that also holds for root."""
    try:
        fd, name = tempfile.mkstemp(prefix=".daeclear-probe-", dir=directory)
    except OSError as exc:
        raise OutputError(f"{option} '{path}': cannot write in directory '{directory}' "
                          f"({exc.strerror or exc}); give a writable place.") from None
    os.close(fd)
    os.unlink(name)


def check_file(path: str | os.PathLike[str], option: str, *, what: str = "an HDF5 file (.h5)",
               example: str = "result.h5") -> Path:
    """``path`` as a Path, checked that it can become (or replace) a file in an existing writable directory.

    ``option`` (how the user named it, e.g. ``--out``) and ``what`` (what is allowed) make the message;
    ``example`` is a file name suggested when ``path`` is a directory. Raises OutputError (a directory or
    other non-file, an unwritable directory) or OutputDirectoryMissing (also a FileNotFoundError).
    """
    p = Path(path)
    if str(path) == "":
        raise OutputError(f"{option} '': an empty path; must be {what}.")
    if p.is_dir():
        raise OutputError(f"{option} '{p}': is a directory; must be {what}, e.g. '{p / example}'.")
    if p.exists() and not p.is_file():
        raise OutputError(f"{option} '{p}': exists and is not a regular file; must be {what}.")
    parent = p.parent
    if not parent.exists():
        raise OutputDirectoryMissing(f"{option} '{p}': directory '{parent}' does not exist; must be {what} in an "
                                     "existing directory.")
    if not parent.is_dir():
        raise OutputError(f"{option} '{p}': '{parent}' is not a directory; must be {what} in a directory.")
    _probe(parent, option, p)
    return p


def check_directory(path: str | os.PathLike[str], option: str, *, files: Sequence[str] = (),
                    create: bool = True) -> Path:
    """Check (and create when ``create``) an output directory, and that none of ``files`` in it is a directory.

    ``path`` must be a directory or not exist yet (then its nearest existing parent must be a writable
    directory). Raises OutputError naming what is wrong.
    """
    p = Path(path)
    allowed = "a directory (created if missing)"
    if str(path) == "":
        raise OutputError(f"{option} '': an empty path; must be {allowed}.")
    if p.exists() and not p.is_dir():
        raise OutputError(f"{option} '{p}': is a file; must be {allowed}.")
    if not p.exists():
        ancestor = p.parent
        while not ancestor.exists() and ancestor != ancestor.parent:
            ancestor = ancestor.parent
        if not ancestor.is_dir():
            raise OutputError(f"{option} '{p}': '{ancestor}' is a file; must be {allowed}.")
        if not create:
            _probe(ancestor, option, p)
            return p
        try:
            p.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"{option} '{p}': cannot create the directory ({exc.strerror or exc}); must be "
                              f"{allowed} in a writable place.") from None
    _probe(p, option, p)
    for name in files:
        target = p / name
        if target.is_dir():
            raise OutputError(f"{option} '{p}': '{target}' is a directory where the file {name} is written; "
                              "remove it or choose another --out/--name.")
    return p


def _replaceable_handler() -> Any:
    """The SIGINT handler to replace, or None where none can be (not the main thread; SIGINT ignored or not
    Python's)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    previous = signal.getsignal(signal.SIGINT)
    return None if previous in (signal.SIG_IGN, None) else previous


@contextlib.contextmanager
def deferred_sigint() -> Iterator[None]:
    """Hold SIGINT back for the duration of the block; a Ctrl-C received meanwhile is raised after it
    (in the main thread only: elsewhere the block runs unshielded)."""
    previous = _replaceable_handler()
    if previous is None:
        yield
        return
    received: list[int] = []

    def hold(signum: int, frame: FrameType | None) -> None:
        received.append(signum)

    signal.signal(signal.SIGINT, hold)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if received:
        if callable(previous):
            previous(signal.SIGINT, None)  # the default handler raises KeyboardInterrupt
        else:
            raise KeyboardInterrupt


@contextlib.contextmanager
def sigint_latch() -> Iterator[list[int]]:
    """Remember every Ctrl-C received during the block (and raise KeyboardInterrupt as usual): Python drops one
    raised in a weakref callback or a destructor, a loop that checks the latch stops anyway (main thread only).
    Such a dropped KeyboardInterrupt is not printed ("Exception ignored ... Traceback"): the latch has it.
    """
    previous = _replaceable_handler()
    if previous is None:
        yield []
        return
    received: list[int] = []
    previous_hook = sys.unraisablehook

    def latch(signum: int, frame: FrameType | None) -> None:
        received.append(signum)
        raise KeyboardInterrupt

    def report_unless_latched(unraisable: Any) -> None:
        if not (received and issubclass(unraisable.exc_type, KeyboardInterrupt)):
            previous_hook(unraisable)

    signal.signal(signal.SIGINT, latch)
    sys.unraisablehook = report_unless_latched
    try:
        yield received
    finally:
        signal.signal(signal.SIGINT, previous)
        sys.unraisablehook = previous_hook


@contextlib.contextmanager
def atomic_file(path: str | os.PathLike[str], *, keep_suffix: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path`` to write; fsync'ed and renamed over ``path`` once the block completes.

    An existing file is left untouched or replaced whole; on any exception (Ctrl-C too) the temporary file is
    removed. ``keep_suffix``: the temporary name ends in ``path``'s suffix (writers that choose the format by it).
    """
    p = Path(path)
    tail = f".tmp{p.suffix}" if keep_suffix else ".tmp"
    tmp = p.with_name(f".{p.stem if keep_suffix else p.name}.{uuid.uuid4().hex[:12]}{tail}")
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, p)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        if not isinstance(exc, DiskFull) and is_disk_full(exc):  # named by the file meant, not the temporary one
            raise disk_full(p, "writing", exc) from None
        raise


def atomic_write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write text to a temporary file beside ``path`` and rename it over ``path`` (SIGINT deferred)."""
    p = Path(path)
    with deferred_sigint(), atomic_file(p) as tmp:
        tmp.write_text(text)
    return p
