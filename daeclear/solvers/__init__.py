"""DAEModel -> Result: :func:`simulate` (dispatch) hands a run to its method's solver (the contract:
base; the methods: registry), IDA (ida, ida_loop) or the explicit and scipy methods (explicit), and
checks every finished run (physics).
"""

from __future__ import annotations

from typing import Any

__all__ = ["simulate"]


def __getattr__(name: str) -> Any:
    """``simulate`` on first use: importing the package must not load the IDA loop, which imports
    the assembly, which uses this package's run checks (physics)."""
    if name == "simulate":
        from .dispatch import simulate

        return simulate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
