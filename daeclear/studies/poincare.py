"""Crank periods, sampling times, phase portraits and stroboscopic Poincaré sections of a run.

The chapter reads its responses from "Poincaré maps", phase portraits of slider acceleration against
velocity (section 4.4): :func:`phase_portrait`. :func:`poincare_section` takes the true stroboscopic
section (one point per crank revolution, on output times that :func:`sampling_times` makes exact),
with the attractor size that scales every later test, and :func:`recurrence_defects` the numbers
the periodicity test reads. Only numpy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .motion_thresholds import SIZE_QUANTILES, TIME_MATCH
from ..assembly.assemble import DAEModel
from ..core.errors import DaeclearError, SceneError

if TYPE_CHECKING:
    from ..results.result import Result
    from ..model.scene import Scene

__all__ = ["CHANNELS", "PhasePortrait", "PoincareSection", "crank_period", "match_times", "phase_portrait",
           "poincare_section", "recurrence_defects", "sampling_times", "section_channels"]

CHANNELS: tuple[str, str] = ("slider.vx", "slider.ax")
"""Default channel pair: the chapter's "Poincaré maps" plot slider acceleration against velocity."""


def section_channels(scene: Scene | DAEModel) -> tuple[str, str]:
    """The default section channels of a scene: the chapter's pair (:data:`CHANNELS`) when a body is
    named ``slider``, else the angular velocity and acceleration of the last body (the output link:
    a four-bar's rocker, a double pendulum's second link)."""
    bodies = list(scene.body_names) if isinstance(scene, DAEModel) else [b.name for b in scene.bodies]
    if "slider" in bodies or not bodies:
        return CHANNELS
    return (f"{bodies[-1]}.omega", f"{bodies[-1]}.alpha")


def _scene_parameters(source: Any) -> Mapping[str, Any]:
    """The scene dictionary of a Result, DAEModel, Scene or mapping."""
    from ..model.scene import Scene

    if isinstance(source, Scene):
        return source.to_dict()
    params = getattr(source, "parameters", source)
    if isinstance(params, Mapping):
        return params.get("scene", params)
    raise TypeError(f"crank_period: cannot read a scene from a {type(source).__name__}.")


def crank_period(source: Result | DAEModel | Scene | Mapping[str, Any]) -> float:
    """Duration of one crank revolution, s: 2 pi / |speed| of the scene's driver (0.012 s at 5000 rpm).

    ``source`` is anything carrying the scene (a Result's or model's ``parameters["scene"]``).

    Raises
    ------
    DaeclearError
        If the scene has no driver, drivers of different speeds or one that is not a constant-speed
        rotation: pass ``period=`` explicitly then.
    """
    scene = _scene_parameters(source)
    elements = scene.get("elements", {}) if isinstance(scene, Mapping) else {}
    drivers = [e for e in elements.values() if isinstance(e, Mapping) and e.get("kind") == "Driver"]
    name = scene.get("name", "?") if isinstance(scene, Mapping) else "?"
    for driver in drivers:  # only a constant-speed rotation repeats every 2 pi / speed
        profile = (driver.get("profile") or {}).get("kind", "constant")
        joint = elements.get(driver.get("joint"), {})
        if profile != "constant" or (isinstance(joint, Mapping) and "Translational" in str(joint.get("kind"))):
            raise DaeclearError(f"scene {name!r}: driver {driver.get('name')!r} is not a constant-speed rotation "
                                f"(profile {profile!r} on joint {driver.get('joint')!r}), so the scene has no crank "
                                "period: pass period= (s) explicitly.")
    speeds = sorted({abs(float(e["speed"])) for e in drivers})
    if not speeds:
        raise DaeclearError(f"scene {name!r} has no driver, so no crank period: pass period= (s) explicitly.")
    if len(speeds) > 1 or speeds[0] == 0.0:
        raise DaeclearError(f"scene {name!r}: driver speeds {speeds} rad/s give no single nonzero period; "
                            "pass period= (s) explicitly.")
    return 2.0 * math.pi / speeds[0]


def sampling_times(period: float, revolutions: int, *, per_revolution: int = 32,
                   offset: float = 0.0) -> NDArray[np.float64]:
    """Output times for ``simulate(t_eval=...)`` that contain every section time exactly.

    ``per_revolution`` uniform samples per revolution (they give the phase portrait, the attractor
    size and the twin separation) from t = 0 to ``revolutions * period`` (s), plus the section times
    ``offset + k * period`` when ``offset`` (s, in [0, period): the section's crank angle past the
    initial one) is not on that grid.
    """
    if not (isinstance(revolutions, (int, np.integer)) and revolutions >= 1):
        raise SceneError(f"sampling_times: revolutions={revolutions!r}, must be an integer >= 1.")
    if not (isinstance(per_revolution, (int, np.integer)) and per_revolution >= 1):
        raise SceneError(f"sampling_times: per_revolution={per_revolution!r}, must be an integer >= 1.")
    if not (period > 0 and math.isfinite(period)):
        raise SceneError(f"sampling_times: period={period!r} s, must be a finite number > 0.")
    if not 0.0 <= offset < period:
        raise SceneError(f"sampling_times: offset={offset!r} s, must be in [0, period={period:g}).")
    n = int(revolutions) * int(per_revolution)
    t = period * (np.arange(n + 1) / per_revolution)  # k * per_revolution / per_revolution is exact
    if offset == 0.0:
        return t
    section = offset + period * np.arange(int(revolutions))
    keep = np.min(np.abs(t[:, None] - section[None, :]), axis=1) > TIME_MATCH * period
    return np.union1d(t[keep], section)


@dataclass(frozen=True)
class PhasePortrait:
    """Two channels against each other over a time window (the chapter's "Poincaré maps"): samples
    at times ``t`` (s) of channels ``names`` (units ``units``) as ``x`` and ``y``."""

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    names: tuple[str, str]
    units: tuple[str, str]


def phase_portrait(result: Result, x: str = CHANNELS[0], y: str = CHANNELS[1], *, t0: float | None = None,
                   t1: float | None = None) -> PhasePortrait:
    """The samples of channels ``x`` and ``y`` (default slider velocity and acceleration) over
    [t0, t1] (s; None: the run's ends), for a phase portrait; a dense ``t_eval`` (:func:`sampling_times`)
    gives a smooth curve."""
    mask = result.window_mask(t0, t1)
    return PhasePortrait(t=np.asarray(result.t)[mask], x=np.asarray(result[x], dtype=float)[mask],
                         y=np.asarray(result[y], dtype=float)[mask], names=(x, y),
                         units=(result.units.get(x, ""), result.units.get(y, "")))


@dataclass(frozen=True)
class PoincareSection:
    """Stroboscopic Poincaré section: the channels once per crank revolution.

    Attributes
    ----------
    t, points : ndarray (n,), ndarray (n, d)
        Section times t0 + k T (s) and the channel values there, one column per channel.
    channels, units, period : tuple of str, tuple of str, float
        Channel names (d of them), their units, and T (s).
    size, center : ndarray (d,)
        Attractor size per channel, the 1 %-99 % quantile range over all output samples of the
        analysed window (nan when sampled too sparsely to tell: fewer than 4 per revolution), and
        each channel's median there.
    """

    t: NDArray[np.float64]
    points: NDArray[np.float64]
    channels: tuple[str, ...]
    units: tuple[str, ...]
    period: float
    size: NDArray[np.float64]
    center: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def normalized(self) -> NDArray[np.float64]:
        """Points minus `center`, divided by `size` (channels of zero size become 0)."""
        size = np.where(self.size > 0, self.size, np.inf)
        return (self.points - self.center) / size

    def __repr__(self) -> str:
        return (f"PoincareSection({len(self)} points of {', '.join(self.channels)}, "
                f"t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, period {self.period:.6g} s)"
                if len(self) else f"PoincareSection(empty, channels {', '.join(self.channels)})")


def match_times(result: Result, times: NDArray[np.floating[Any]], period: float) -> NDArray[np.intp]:
    """Indices of the output times equal (to 1e-9 T) to ``times``; raises naming the first missing one."""
    t = np.asarray(result.t)
    tol = TIME_MATCH * period
    idx = np.clip(np.searchsorted(t, times - tol), 0, max(t.size - 1, 0))
    if t.size == 0 or np.any(np.abs(t[idx] - times) > tol):
        bad = times[0] if t.size == 0 else times[np.argmax(np.abs(t[idx] - times) > tol)]
        raise DaeclearError(
            f"Poincaré section: the result has no output at t = {bad:.9g} s (section times t0 + k T, "
            f"T = {period:.6g} s). Simulate with save=daeclear.SaveAt(times=daeclear.analysis.sampling_times(...)) "
            "so that the section times are output points (values from IDA's interpolant, multipliers recomputed)."
        )
    return idx


def poincare_section(result: Result, channels: Sequence[str] = CHANNELS, *, t0: float | None = None,
                     t1: float | None = None, period: float | None = None) -> PoincareSection:
    """Stroboscopic Poincaré section of a run: the channels at t0, t0 + T, t0 + 2T, ...

    Parameters
    ----------
    result : Result
        Its output times contain the section times (:func:`sampling_times`); dense output in between
        gives the attractor size.
    channels : sequence of str
        Any channels or states.
    t0, t1, period : float, optional
        First section time (end of the transient plus the section's offset) and last time, s (default
        the run's ends); T, s (default :func:`crank_period`).

    Raises
    ------
    DaeclearError
        If a section time is not an output time of the result, or no period can be found.
    ChannelKeyError
        If a channel does not exist (close matches listed).
    """
    channels = tuple(str(c) for c in channels)
    if not channels:
        raise SceneError("poincare_section: give at least one channel.")
    T = float(period) if period is not None else crank_period(result)
    if result.n_times == 0:
        raise DaeclearError("poincare_section: the result has no output times.")
    start = float(result.t[0]) if t0 is None else float(t0)
    stop = float(result.t[-1]) if t1 is None else float(t1)
    n = int(math.floor((stop - start) / T + TIME_MATCH)) + 1 if stop >= start else 0
    times = start + T * np.arange(max(n, 0))
    idx = match_times(result, times, T) if times.size else np.zeros(0, dtype=np.intp)
    values = [np.asarray(result[c], dtype=float) for c in channels]
    for c, v in zip(channels, values):
        if v.ndim != 1:
            raise SceneError(f"poincare_section: channel {c!r} has shape {v.shape}; give scalar channels.")
    points = np.column_stack([v[idx] for v in values]) if times.size else np.zeros((0, len(channels)))
    window = result.window_mask(start - TIME_MATCH * T, stop + TIME_MATCH * T)
    n_window = int(np.count_nonzero(window))
    if times.size >= 2 and n_window >= 4 * (times.size - 1):
        lo, hi = SIZE_QUANTILES
        size = np.array([np.quantile(v[window], hi) - np.quantile(v[window], lo) for v in values])
        center = np.array([np.median(v[window]) for v in values])
    else:
        size = np.full(len(channels), np.nan)
        center = np.median(points, axis=0) if times.size else np.full(len(channels), np.nan)
    return PoincareSection(t=result.t[idx] if times.size else np.zeros(0), points=points, channels=channels,
                           units=tuple(result.units.get(c, "") for c in channels), period=T, size=size,
                           center=center)


def recurrence_defects(p: NDArray[np.float64], max_period: int) -> dict[int, float]:
    """d_k = max_j max_i |p[j+k, i] - p[j, i]| for k = 1..K (K <= max_period, at least 2 pairs per k)."""
    n = p.shape[0]
    k_max = min(int(max_period), (n - 1) // 2)
    return {k: float(np.max(np.abs(p[k:] - p[:-k]))) for k in range(1, k_max + 1)}

