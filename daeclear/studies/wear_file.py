"""The history of :func:`daeclear.studies.wear.simulate_wear` in an HDF5 file: appended, and read to resume.

Layout: root attributes ``format = "daeclear-wear"`` and the settings (joint, update interval,
extrapolation, period, wear coefficient, nodes, surface) as JSON; datasets ``cycles`` (n),
``depth`` (n, surfaces, nodes, m), ``sliding_work`` (n, N m), ``peak_force`` (n, N; the block run
after each profile), and the state to continue from, ``t0`` (attribute) and ``y0`` (dataset). Every
update appends one row and flushes, the state last: a run stopped anywhere resumes from the last
complete row (rows beyond the shortest dataset are ignored).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.errors import SceneError

FORMAT = "daeclear-wear"
Row = tuple[float, dict[str, NDArray[np.float64]], float, float]  # cycles, depth by surface, work, peak force


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


class WearFile:
    """One wear history file (see the module docstring); ``settings`` must match the file's to resume."""

    def __init__(self, path: str | os.PathLike[str], settings: dict[str, Any]) -> None:
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise SceneError(f"simulate_wear: path={str(path)!r}, its directory does not exist.")
        self.settings = json.loads(json.dumps(settings))  # as the file gives them back (lists, not tuples)
        wear = self.settings["scene"]["elements"][settings["joint"]]["wear"]
        self.surfaces = ("bearing", "journal") if wear["surface"] == "both" else (wear["surface"],)
        self.t0 = 0.0
        self.y0: NDArray[np.float64] | None = None

    def read(self) -> list[Row] | None:
        """The rows of an existing file (and its state to continue from), None without a file."""
        import h5py

        if not self.path.exists():
            return None
        try:
            with h5py.File(self.path, "r") as f:
                if f.attrs.get("format") != FORMAT:
                    raise SceneError(f"simulate_wear: {self.path} is not a wear history file (format "
                                     f"{f.attrs.get('format')!r}); give a new path.")
                changed = differences(json.loads(f.attrs["settings_json"]), self.settings)
                if changed:
                    raise SceneError(f"simulate_wear: {self.path} was written with another scene or settings ("
                                     + "; ".join(changed) + "); give a new path, or the same scene and settings "
                                     "to resume.")
                n = min(f[name].shape[0] for name in ("cycles", "depth", "sliding_work", "peak_force"))
                if n == 0:
                    return None
                cycles, depth = f["cycles"][:n], f["depth"][:n]
                work, peak = f["sliding_work"][:n], f["peak_force"][:n]
                self.t0 = float(f.attrs["t0"])
                y0 = f["y0"][()]
                self.y0 = y0 if y0.size else None
        except OSError as exc:
            raise SceneError(f"simulate_wear: {self.path} cannot be read ({exc}); give a new path.") from None
        return [(float(cycles[i]), dict(zip(self.surfaces, depth[i])), float(work[i]), float(peak[i]))
                for i in range(n)]

    def append(self, cycles: float, depth: dict[str, NDArray[np.float64]], work: float, peak: float, *, t0: float,
               y0: NDArray[np.float64] | None, peak_before: float | None = None) -> None:
        """Add one profile's row; ``peak_before``: the peak force of the block run with the previous one."""
        import h5py

        nodes = len(next(iter(depth.values())))
        with h5py.File(self.path, "a") as f:
            if "cycles" not in f:
                f.attrs["format"] = FORMAT
                f.attrs["settings_json"] = json.dumps(self.settings)
                for name in ("cycles", "sliding_work", "peak_force"):
                    f.create_dataset(name, shape=(0,), maxshape=(None,), dtype="f8", chunks=(256,))
                rows = len(self.surfaces)
                f.create_dataset("depth", shape=(0, rows, nodes), maxshape=(None, rows, nodes), dtype="f8",
                                 chunks=(16, rows, nodes))
            n = f["cycles"].shape[0]
            if peak_before is not None and n:
                f["peak_force"][n - 1] = peak_before
            for name, value in (("depth", np.array([depth[s] for s in self.surfaces])), ("sliding_work", work),
                                ("peak_force", peak), ("cycles", cycles)):
                f[name].resize(n + 1, axis=0)
                f[name][n] = value
            f.attrs["t0"] = t0
            if "y0" in f:
                del f["y0"]
            f.create_dataset("y0", data=np.zeros(0) if y0 is None else np.asarray(y0, dtype=float))
            f.flush()
        self.t0, self.y0 = t0, y0
