"""What a sweep's workers run (:func:`run_task`: plain data back, no files), and the local pool's lifecycle."""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import dataclasses
import os
import signal
import socket
import sys
import time
import traceback as tb
from collections.abc import Callable, Mapping
from datetime import datetime, UTC
from typing import Any

import numpy as np

from .sweep_file import SOLVER_KEY
from ..core.errors import SceneError

__all__ = ["build_scene", "ignore_sigint", "run_task", "terminate_pool"]


def build_scene(mechanism: str | Callable[..., Any], parameters: Mapping[str, Any]) -> Any:
    """The scene of one parameter point: ``mechanism(**options)`` with the point's scene values set (a
    name with a dot, :meth:`daeclear.Scene.with_values`; any other is an option of the mechanism)."""
    options = {k: v for k, v in parameters.items() if "." not in k}
    values = {k: v for k, v in parameters.items() if "." in k}
    if callable(mechanism):
        scene = mechanism(**options)
    else:
        from ..model.scenefile import MECHANISMS

        if mechanism not in MECHANISMS:
            raise SceneError(f"sweep: mechanism={mechanism!r}, must be one of {', '.join(MECHANISMS)} or a callable "
                             "returning a Scene.")
        scene = MECHANISMS[mechanism](**options)
    return scene.with_values(values) if values else scene


def ignore_sigint(parent: int | None = None) -> None:
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


def run_task(task: Mapping[str, Any]) -> dict[str, Any]:
    """Build the scene of one point, classify its motion and return plain data (runs in a worker)."""
    from .analysis import classify_motion
    from ..solvers.solver_options import SolverOptions

    start = time.perf_counter()
    out: dict[str, Any] = {"key": task["key"], "index": task["index"], "parameters": dict(task["parameters"]),
                           "worker": f"{socket.gethostname()}:{os.getpid()}"}
    try:
        scene = build_scene(task["mechanism"], task["parameters"])
        options = SolverOptions.from_dict(task[SOLVER_KEY])  # plain data across the executor
        analysis = classify_motion(scene, options=options, **task["analysis"])
        section = analysis.section
        data: dict[str, Any] = {
            "section": dataclasses.asdict(section),  # t, points, channels, units, period, size, center
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
    out.update(wall_time=time.perf_counter() - start, computed_at=datetime.now(UTC).isoformat(timespec="seconds"))
    return out


def terminate_pool(executor: cf.Executor) -> None:
    """Stop our own process pool's workers now (their running tasks are abandoned, not recorded)."""
    processes = getattr(executor, "_processes", None) or {}
    for process in list(processes.values()):
        with contextlib.suppress(Exception):  # already gone
            process.terminate()
