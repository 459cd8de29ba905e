"""Exceptions and warnings of daeclear, one hierarchy for the whole package."""

from __future__ import annotations

from typing import Any


class DaeclearError(Exception):
    """Base class of every daeclear error."""


class SceneError(DaeclearError, ValueError):
    """A scene, a scene element or a user argument is invalid."""


class AssemblyError(DaeclearError, ValueError):
    """The scene is valid but its equations cannot be assembled (e.g. joints that cannot close)."""


class SolveError(DaeclearError, RuntimeError):
    """The integrator failed; ``.result`` holds everything computed up to the failure."""

    def __init__(self, message: str, result: Any = None) -> None:
        super().__init__(message)
        self.result = result


class DaeclearWarning(UserWarning):
    """A daeclear warning: something was changed or a slower path was taken."""


class PhysicsWarning(DaeclearWarning):
    """A finished run is not physical (penetration beyond the clearance, drift, a contact stepped
    over, an impossible start); the same finding is recorded in ``Result.warnings``."""


class MissingDependencyError(DaeclearError, ImportError):
    """An optional dependency is not installed; the message names the pip extra that brings it."""


class OutputError(DaeclearError, OSError):
    """An output place (file or directory) cannot be written; found before any work starts."""


class DiskFull(OutputError):
    """The disk (or quota) has no room for a write; the message names the file. What was written
    before stays readable (a streamed result: marked incomplete)."""


class OutputDirectoryMissing(OutputError, FileNotFoundError):
    """The directory an output file should go into does not exist."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a run or a study; ``.result`` holds what was computed. A KeyboardInterrupt, so that
    loops catching only errors (``except Exception``) stop too."""

    def __init__(self, message: str, result: Any = None) -> None:
        super().__init__(message)
        self.result = result


_WARNED: set[str] = set()  # the messages warn_once has issued in this process


def warn_once(message: str, stacklevel: int = 2) -> None:
    """Issue a :class:`DaeclearWarning` the first time this process meets ``message`` (a fallback
    named once, not at every run of a sweep); ``stacklevel`` counts from the caller of warn_once."""
    if message in _WARNED:
        return
    _WARNED.add(message)
    import warnings

    warnings.warn(message, DaeclearWarning, stacklevel=stacklevel + 1)
