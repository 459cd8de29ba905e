"""Compiling generated C into a cached shared library: the C compiler, the cache directory and key,
the per-key file lock, and the in-process memos. The key: the SHA-256 of the generated source, the
driver sources, the compiler command and version and what the caller adds. A build compiles in a
temporary directory and moves the result into place under the key's file lock (safe across processes).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sysconfig
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Iterator

from ..core.errors import DaeclearError

__all__ = ["CSRC", "CompilerUnavailable", "CompileError", "BuildResult", "compiler_command", "cache_dir",
           "compile_cached", "driver_files", "MemoTable", "memo_table", "clear_memos"]

#: The hand-written C drivers and the vendored SUNDIALS headers (on the include path of every build).
CSRC = Path(__file__).resolve().parent / "csrc"


class CompilerUnavailable(DaeclearError):
    """No working C compiler (or no SUNDIALS libraries) for the compiled backend."""


class CompileError(DaeclearError):
    """The C compiler failed on the generated model; the message holds its output."""


_LOCAL_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def driver_files(driver: str) -> tuple[Path, ...]:
    """``csrc/<driver>`` and every ``csrc/`` file it includes, also indirectly, sorted (for the cache key)."""
    seen: dict[str, Path] = {}
    todo = [driver]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        path = CSRC / name
        seen[name] = path
        todo += [inc for inc in _LOCAL_INCLUDE.findall(path.read_text()) if (CSRC / inc).is_file()]
    return tuple(seen[name] for name in sorted(seen))


def compiler_command() -> list[str]:
    """The C compiler command: $CC, else sysconfig's CC, else cc/gcc. Raises CompilerUnavailable."""
    env_cc = os.environ.get("CC")
    candidates: list[tuple[str, str]] = []
    if env_cc is not None and env_cc.strip():
        candidates.append((env_cc, "$CC"))
    else:
        cfg = sysconfig.get_config_var("CC")
        if cfg:
            candidates.append((cfg, "sysconfig CC"))
        candidates += [("cc", "default"), ("gcc", "default")]
    tried = []
    for cmd, origin in candidates:
        parts = shlex.split(cmd)
        if not parts:
            continue
        exe = shutil.which(parts[0])
        if exe is not None:
            return [exe, *parts[1:]]
        tried.append(f"{parts[0]!r} ({origin})")  # an explicit $CC is the only candidate
    raise CompilerUnavailable(f"no C compiler found: tried {', '.join(tried)}")


@functools.lru_cache(maxsize=16)
def _compiler_version(exe: str) -> str:
    try:
        out = subprocess.run([exe, "--version"], capture_output=True, text=True, timeout=30)
        return (out.stdout or out.stderr).strip().splitlines()[0] if (out.stdout or out.stderr) else ""
    except (OSError, subprocess.SubprocessError) as exc:
        raise CompilerUnavailable(f"C compiler {exe!r} does not run: {exc}") from exc


def cache_dir() -> Path:
    """``$DAECLEAR_CACHE_DIR``, else ``~/.cache/daeclear``."""
    d = os.environ.get("DAECLEAR_CACHE_DIR")
    return Path(d).expanduser() if d else Path.home() / ".cache" / "daeclear"


@dataclass(frozen=True)
class BuildResult:
    path: Path
    key: str
    cache_hit: bool
    compile_time: float   # s spent in the compiler (0 on a cache hit)
    codegen_time: float   # s spent generating C and hashing


@contextlib.contextmanager
def _file_lock(path: Path) -> Iterator[None]:
    try:
        import fcntl
    except ImportError:  # pragma: no cover - non-POSIX
        yield
        return
    with open(path, "a+") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


MemoTable = dict[Any, Any]
_MEMO_TABLES: list[MemoTable] = []


def memo_table() -> MemoTable:
    """A new in-process memo (by any key); :func:`clear_memos` empties them all."""
    table: MemoTable = {}
    _MEMO_TABLES.append(table)
    return table


def clear_memos() -> None:
    """Forget every structure of this process (and with each its ``CompiledDAE``, what was made of it):
    the next run generates and loads again, e.g. after changing ``$CC``; the disk cache stays."""
    for table in _MEMO_TABLES:
        table.clear()


def memo_put_bounded(table: MemoTable, key: Any, value: Any, limit: int) -> None:
    """``table[key] = value``, the oldest entries dropped while the table holds ``limit``; an eviction
    that loses a race with another thread is skipped."""
    while len(table) >= limit:
        try:
            table.pop(next(iter(table)), None)
        except (RuntimeError, StopIteration):  # the table changed under the iterator
            break
    table[key] = value


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _intact(library: Path, digest: Path) -> bool:
    """The cached library is byte for byte the one built (a damaged one would crash when loaded)."""
    try:
        return library.is_file() and digest.read_text().strip() == _sha256(library)
    except OSError:
        return False


def compile_cached(prefix: str, what: str, source: str, driver: str, driver_text: str, flags: list[str],
                   link: list[str], extra_key: list[str], t0: float) -> BuildResult:
    """Compile ``source`` with ``csrc/<driver>`` into a cached shared library, whose SHA-256 is checked
    before it is used (a damaged one is built again). ``t0``: when code generation started.
    """
    cc = compiler_command()
    version = _compiler_version(cc[0])
    flags = [*flags, f"-I{CSRC}"]
    h = hashlib.sha256()
    for part in (prefix, source, driver_text, shlex.join(cc + flags + link), version, *extra_key):
        h.update(part.encode())
        h.update(b"\0")
    key = h.hexdigest()
    codegen_time = time.perf_counter() - t0

    root = cache_dir()
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CompilerUnavailable(f"cache directory {root} cannot be created: {exc}") from exc
    stem = f"{prefix}_{key[:40]}"
    target = root / f"{stem}.so"
    digest = root / f"{stem}.sha256"
    if _intact(target, digest):
        return BuildResult(target, key, True, 0.0, codegen_time)
    with _file_lock(root / f"{stem}.lock"):
        if _intact(target, digest):  # built by another process meanwhile
            return BuildResult(target, key, True, 0.0, codegen_time)
        target.unlink(missing_ok=True)  # absent, truncated or altered: never loaded, built again
        t1 = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix=f"{stem}-", dir=root) as tmp:
            tmpd = Path(tmp)
            (tmpd / "model.c").write_text(source)
            out = tmpd / "lib.so"
            cmd = [*cc, *flags, str(tmpd / "model.c"), str(CSRC / driver), "-o", str(out), *link]
            try:
                proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
            except (OSError, subprocess.SubprocessError) as exc:
                raise CompilerUnavailable(f"running the C compiler {cc[0]!r} failed: {exc}") from exc
            if proc.returncode != 0 or not out.is_file():
                msg = (proc.stderr or proc.stdout or "").strip()
                if len(msg) > 4000:
                    msg = msg[:2000] + "\n...\n" + msg[-2000:]
                raise CompileError(f"compiling {what} failed (exit {proc.returncode}):\n$ {shlex.join(cmd)}\n{msg}")
            os.replace(tmpd / "model.c", root / f"{stem}.c")  # the source beside the library, for debugging
            digest_tmp = tmpd / "lib.sha256"
            digest_tmp.write_text(_sha256(out))
            os.replace(digest_tmp, digest)  # the digest first: a library is never there without it
            os.replace(out, target)
        return BuildResult(target, key, False, time.perf_counter() - t1, codegen_time)

