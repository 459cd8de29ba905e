"""DAEModel -> Result: :func:`simulate` (dispatch) hands a run to its method's solver (the contract:
base; the methods: registry, from core.methods), whose run is the one run driver's (driver) over the
method's integrator (integrator: the interface; ida: IDA; explicit and ode_integrators: the scipy and
fixed-step methods); the driver checks every finished run (assembly.physics).
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
