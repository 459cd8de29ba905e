"""Animations of a run: the mechanism moving, each clearance joint magnified, a time cursor.

:func:`animate` (and its thin method ``Result.animate``, and ``daeclear animate RESULT.h5``)
writes an animated GIF with pillow through matplotlib's ``PillowWriter`` (no external
program), or an MP4 through ffmpeg when the path ends in ``.mp4`` and ffmpeg is installed.

Everything is drawn from the result alone, so any scene animates, including one loaded back
from HDF5: the geometry comes from the scene description ``result.parameters["scene"]``
(bodies, joints and their points, clearance joints with their radii, lengths and clearance),
the motion from the body channels ``<body>.x``, ``<body>.y``, ``<body>.phi`` and the clearance
channels (``<joint>.ex/ey`` of a revolute clearance joint, ``<joint>.s/y/tilt`` of a
translational one, ``<joint>.in_contact``, ``<joint>.penetration``).

A frame shows

- the mechanism to scale: each body as a line through its joint points (a plate when it has
  three or more, a marker at its centre of mass when it has one or none), ideal revolute joints
  as small circles, the ground's joints and guides in grey, revolute clearance joints as rings
  and translational ones as the slider block between the guide surfaces, red while in contact;
- one panel per clearance joint (at most :data:`MAX_INSETS`) with the clearance magnified: the
  journal orbit inside the clearance circle (eccentricity in micrometres, Fig. 4.15d) with the
  current journal centre, or the slider in its guide with the lateral offset, tilt and
  penetration multiplied by ``magnify``; red, with the penetration, while in contact;
- a time plot of one channel (``channel``, e.g. ``drive.moment``) with a moving cursor,
  contact intervals shaded.

Frames. The window [t0, t1] of duration D plays at ``slow_motion`` times slower than real
time at ``fps`` frames per second: ``n_frames = max(2, round(D * slow_motion * fps))``,
evenly spaced from t0 to t1 inclusive, so the animation lasts ``n_frames / fps`` s. A joint
is red in a frame when it is in contact then or was since the previous frame ("impact since
last frame", with the deepest penetration), so an impact shorter than the frame spacing still
lights up.

matplotlib (and pillow, which it requires) is imported only when an animation is made.
"""

from __future__ import annotations

import math
import os
import shutil
import uuid
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .. import options
from . import style
from ..errors import MissingDependencyError, SceneError
from ..progress import Progress

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..results.result import Result

__all__ = ["DEFAULT_PLAY_TIME", "MAX_FRAMES", "MAX_INSETS", "animate", "frame_count", "frame_times"]

DEFAULT_PLAY_TIME = 5.0
"""Seconds the window plays for when ``slow_motion`` is None (then slow_motion = 5 s / D)."""

MAX_FRAMES = 3000
"""Most frames one animation may have (each frame is kept in memory until the file is written)."""

MAX_INSETS = 4
"""Most clearance-joint panels in one animation (the first ones of the scene)."""

MAX_FPS = 100.0
"""Highest frame rate: a GIF stores frame durations in hundredths of a second."""

SIZE_RANGE = (160, 4000)
"""Allowed width and height of an animation, pixels."""

FORMATS = (".gif", ".mp4")
_DPI = 100.0
_CONTACT = "C3"
_FREE = "C0"
_GROUND = "0.45"
_CURSOR_POINTS = 2000  # samples of the cursor channel drawn (min-max decimated)
_ORBIT_POINTS = 20000  # samples of a journal orbit / slider path drawn


Window = tuple[float | None, float | None] | None


# --------------------------------------------------------------------------- options


@dataclass(frozen=True)
class _Fields:
    """How the caller names each option, for error messages (Python keywords or CLI flags)."""

    where: str = "Result.animate"
    path: str = "path"
    fps: str = "fps"
    window: str = "window"
    slow_motion: str = "slow_motion"
    size: str = "size"
    channel: str = "channel"
    magnify: str = "magnify"
    progress: str = "progress"


CLI_FIELDS = _Fields(where="daeclear animate", path="--out", fps="--fps", window="--window",
                     slow_motion="--slow-motion", size="--size", channel="--channel", magnify="--magnify")


def _window(result: Result, window: Window, f: _Fields) -> tuple[float, float]:
    """The closed window [t0, t1] inside the run, t0 < t1 (None: the run's start or end)."""
    t = np.asarray(result.t, dtype=np.float64)
    if t.size < 2 or not t[-1] > t[0]:
        raise SceneError(f"{f.where}: the result has {t.size} output time(s) spanning no time; "
                         "an animation needs a run of nonzero duration.")
    start, end = float(t[0]), float(t[-1])
    sides = "" if f.window.startswith("--") else "; None for its start or end"
    rule = f"(t0, t1) in s with {start:g} <= t0 < t1 <= {end:g} (the run{sides})"
    if window is None:
        return start, end
    try:
        t0, t1 = window  # type: ignore[misc]
    except (TypeError, ValueError):
        options.fail(f.where, f.window, window, rule)
    lo = start if t0 is None else t0
    hi = end if t1 is None else t1
    for value in (lo, hi):
        if not options._real(value) or not math.isfinite(float(value)):
            options.fail(f.where, f.window, window, rule)
    # a window given from printed times (e.g. 0.004 for 0.0040000000000001) is inside the run
    slack = 1e-9 * max(abs(start), abs(end), end - start)
    lo_f, hi_f = float(lo), float(hi)
    if not (start - slack <= lo_f < hi_f <= end + slack):
        shown = ", ".join("None" if v is None else repr(float(v)) for v in (t0, t1))
        options.fail(f.where, f.window, (t0, t1), rule, "s", shown=f"({shown})")
    return max(lo_f, start), min(hi_f, end)


def _size(size: Any, f: _Fields) -> tuple[int, int]:
    lo, hi = SIZE_RANGE
    rule = f"(width, height) in pixels, two integers in [{lo}, {hi}]"
    try:
        w, h = size
    except (TypeError, ValueError):
        options.fail(f.where, f.size, size, rule)
    for value in (w, h):
        if (not isinstance(value, (int, np.integer)) or isinstance(value, (bool, np.bool_))
                or not lo <= int(value) <= hi):
            options.fail(f.where, f.size, size, rule)
    return int(w), int(h)


def frame_count(duration: float, slow_motion: float, fps: float) -> int:
    """Frames of an animation: ``max(2, round(duration * slow_motion * fps))``.

    ``duration`` is the simulated time shown (s), ``slow_motion`` how many times slower than
    real time it plays, ``fps`` the frame rate; the animation lasts ``n_frames / fps`` s.
    """
    return max(2, int(round(duration * slow_motion * fps)))


def frame_times(t0: float, t1: float, n_frames: int) -> NDArray[np.float64]:
    """Simulated time of each frame: ``n_frames`` times evenly spaced from t0 to t1 inclusive."""
    return np.linspace(t0, t1, n_frames)


# --------------------------------------------------------------------------- scene geometry


def _vec(value: Any) -> NDArray[np.float64] | None:
    if value is None:
        return None
    try:
        v = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        return None
    return v if v.shape == (2,) and np.all(np.isfinite(v)) else None


def _rot(phi: Any) -> tuple[Any, Any]:
    return np.cos(phi), np.sin(phi)


@dataclass
class _Joint:
    """A joint as drawn: kind, its two bodies, body-fixed points and the element's description."""

    name: str
    kind: str
    body_i: str
    body_j: str
    s_i: NDArray[np.float64]
    s_j: NDArray[np.float64]
    spec: Mapping[str, Any]


@dataclass
class _Geometry:
    """The scene description turned into body-fixed points: what every frame is drawn from."""

    name: str
    ground: str
    bodies: dict[str, tuple[NDArray[np.float64], float]]  # reference pose: position, angle
    joints: list[_Joint] = field(default_factory=list)
    drivers: list[str] = field(default_factory=list)

    def local_point(self, body: str, world: NDArray[np.float64]) -> NDArray[np.float64]:
        """Body-fixed coordinates of a world point of the reference configuration."""
        if body == self.ground:
            return world.copy()
        (x0, y0), phi0 = self.bodies[body]
        c, s = math.cos(phi0), math.sin(phi0)
        dx, dy = world[0] - x0, world[1] - y0
        return np.array([c * dx + s * dy, -s * dx + c * dy])

    def local_vector(self, body: str, world: NDArray[np.float64]) -> NDArray[np.float64]:
        """Body-fixed components of a world direction (unit length) of the reference configuration."""
        v = world / math.hypot(*world)
        phi0 = 0.0 if body == self.ground else self.bodies[body][1]
        c, s = math.cos(phi0), math.sin(phi0)
        return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])

    def points_of(self, body: str) -> list[NDArray[np.float64]]:
        """Distinct body-fixed joint points of ``body``, in the scene's order."""
        out: list[NDArray[np.float64]] = []
        for joint in self.joints:
            for b, s in ((joint.body_i, joint.s_i), (joint.body_j, joint.s_j)):
                if b == body and not any(np.allclose(s, p, rtol=0.0, atol=1e-9) for p in out):
                    out.append(s)
        return out


def _geometry(result: Result, where: str) -> _Geometry:
    """Read the scene description of ``result``; a clear error when it has none."""
    scene = result.parameters.get("scene") if isinstance(result.parameters, Mapping) else None
    elements = scene.get("elements") if isinstance(scene, Mapping) else None
    if not isinstance(elements, Mapping):
        raise SceneError(f"{where}: the result has no scene description (parameters['scene']['elements']); "
                         "animate a result made by daeclear.simulate or loaded with daeclear.load.")
    ground = "ground"
    bodies: dict[str, tuple[NDArray[np.float64], float]] = {}
    for name, spec in elements.items():
        if isinstance(spec, Mapping) and spec.get("kind") == "Body":
            position = _vec(spec.get("position"))
            angle = spec.get("angle", 0.0)
            bodies[str(name)] = (position if position is not None else np.zeros(2),
                                 float(angle) if options._real(angle) else 0.0)
    if not bodies:
        raise SceneError(f"{where}: the scene description has no body to draw.")
    geo = _Geometry(name=str(scene.get("name", "")), ground=ground, bodies=bodies)  # type: ignore[union-attr]
    for name, spec in elements.items():
        if not isinstance(spec, Mapping):
            continue
        if spec.get("kind") == "Driver":
            geo.drivers.append(str(name))
            continue
        b_i, b_j = spec.get("body_i"), spec.get("body_j")
        if not isinstance(b_i, str) or not isinstance(b_j, str):
            continue
        if any(b != ground and b not in bodies for b in (b_i, b_j)):
            continue
        at = _vec(spec.get("at"))
        p_i, p_j = _vec(spec.get("point_i")), _vec(spec.get("point_j"))
        if p_i is None and at is None or p_j is None and at is None:
            continue
        s_i = p_i if p_i is not None else geo.local_point(b_i, at)  # type: ignore[arg-type]
        s_j = p_j if p_j is not None else geo.local_point(b_j, at)  # type: ignore[arg-type]
        geo.joints.append(_Joint(str(name), str(spec.get("kind", "")), b_i, b_j, s_i, s_j, spec))
    return geo


# --------------------------------------------------------------------------- sampling


class _Sampler:
    """A result's channels at the frame times (linear interpolation, events' repeated times allowed)."""

    def __init__(self, result: Result, times: NDArray[np.float64], t0: float, t1: float) -> None:
        self.result = result
        self.t = np.asarray(result.t, dtype=np.float64)
        self.times = times
        # last sample at or before each frame time, and the one after it
        right = np.searchsorted(self.t, times, side="right")
        self.last = np.clip(right - 1, 0, self.t.size - 1)
        self.next = np.clip(right, 0, self.t.size - 1)
        span = self.t[self.next] - self.t[self.last]
        with np.errstate(invalid="ignore", divide="ignore"):
            self.weight = np.where(span > 0, (times - self.t[self.last]) / np.where(span > 0, span, 1.0), 0.0)
        inside = style.window_index(self.t, (t0, t1))
        self.first = int(inside[0]) if inside.size else int(self.last[0])

    def at(self, name: str) -> NDArray[np.float64]:
        """The channel at each frame time."""
        v = np.asarray(self.result[name], dtype=np.float64)
        return v[self.last] + self.weight * (v[self.next] - v[self.last])

    def since_previous(self, name: str, reduce: Callable[[NDArray[np.float64]], float]) -> NDArray[np.float64]:
        """``reduce`` of the samples after the previous frame's time up to this frame's (the sample at
        or before it when there is none in between), so a contact shorter than the frame spacing is
        not missed."""
        v = np.asarray(self.result[name], dtype=np.float64)
        out = np.empty(self.times.size)
        for k in range(self.times.size):
            hi = int(self.last[k])
            lo = min(int(self.last[k - 1]) + 1, hi) if k else hi
            out[k] = reduce(v[lo:hi + 1])
        return out


def _pose(sampler: _Sampler, body: str, geo: _Geometry, where: str) -> NDArray[np.float64]:
    """(n_frames, 3) array of x, y, phi of ``body`` (zeros for the ground)."""
    if body == geo.ground:
        return np.zeros((sampler.times.size, 3))
    names = [f"{body}.x", f"{body}.y", f"{body}.phi"]
    missing = [n for n in names if n not in sampler.result]
    if missing:
        raise SceneError(f"{where}: the result has no channel {missing[0]!r}; an animation needs x, y and phi "
                         "of every body of the scene.")
    return np.column_stack([sampler.at(n) for n in names])


def _world(pose: NDArray[np.float64], s: NDArray[np.float64]) -> NDArray[np.float64]:
    """(n_frames, 2) world positions of the body-fixed point ``s``."""
    c, si = _rot(pose[:, 2])
    return np.column_stack([pose[:, 0] + c * s[0] - si * s[1], pose[:, 1] + si * s[0] + c * s[1]])


def _direction(pose: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
    c, si = _rot(pose[:, 2])
    return np.column_stack([c * u[0] - si * u[1], si * u[0] + c * u[1]])


def _default_channel(result: Result, geo: _Geometry, clearance: Sequence[_Joint]) -> str:
    """Driver moment, else the first clearance joint's force, else the mechanical energy, else a body angle."""
    candidates = [f"{d}.moment" for d in geo.drivers]
    candidates += [f"{j.name}.normal_force" for j in clearance]
    candidates += ["energy.mechanical", f"{next(iter(geo.bodies))}.phi"]
    return next(c for c in candidates if c in result)


def _check_channel(result: Result, channel: Any, f: _Fields) -> str:
    if not isinstance(channel, str) or channel not in result:
        names = sorted(set(result.channel_names) | set(result.state_names))
        close = options.close_matches(str(channel), names, n=3) if isinstance(channel, str) else []
        hint = f" (close: {', '.join(close)})" if close else ""
        options.fail(f.where, f.channel, channel, f"a channel of the result{hint}, e.g. {names[0]!r}"
                     if names else "a channel of the result")
    if np.asarray(result[channel]).ndim != 1:
        options.fail(f.where, f.channel, channel, "a channel with one value per time")
    return channel


def _nice(value: float) -> float:
    """The 1-2-5 number nearest below ``value`` (a readable magnification)."""
    if value <= 0 or not math.isfinite(value):
        return 1.0
    exponent = math.floor(math.log10(value))
    base = value / 10 ** exponent
    step = 5.0 if base >= 5 else 2.0 if base >= 2 else 1.0
    return step * 10 ** exponent


def _float(spec: Mapping[str, Any], key: str) -> float | None:
    value = spec.get(key)
    return float(value) if options._real(value) and math.isfinite(float(value)) else None


def _revolute_clearance(spec: Mapping[str, Any]) -> float | None:
    c = _float(spec, "clearance")
    if c is not None:
        return c
    R_i, R_j = _float(spec, "bearing_radius"), _float(spec, "journal_radius")
    return R_i - R_j if R_i is not None and R_j is not None else None


def _guide_geometry(joint: _Joint, geo: _Geometry) -> dict[str, Any] | None:
    """Length, width, clearance, guide and slider directions of a translational clearance joint."""
    spec = joint.spec
    L, W = _float(spec, "length"), _float(spec, "width")
    c = _float(spec, "clearance")
    if c is None and _float(spec, "guide_height") is not None and W is not None:
        c = 0.5 * (_float(spec, "guide_height") - W)  # type: ignore[operator]
    axis = _vec(spec.get("axis"))
    if None in (L, W, c) or axis is None or not c > 0:  # type: ignore[operator]
        return None
    t_guide = geo.local_vector(joint.body_i, axis)
    slider_axis = _vec(spec.get("slider_axis"))
    e_slider = (slider_axis / math.hypot(*slider_axis) if slider_axis is not None
                else geo.local_vector(joint.body_j, axis))
    limits = [_vec(spec.get(k)) for k in ("upper_limits", "lower_limits")]
    return {"L": L, "W": W, "c": c, "t_guide": t_guide, "e_slider": e_slider,
            "limits": [lim for lim in limits if lim is not None]}


# --------------------------------------------------------------------------- the figure


def _pen(ax: Axes, color: str, **kw: Any) -> Any:
    (line,) = ax.plot([], [], color=color, **kw)
    return line


class _Scene:
    """The mechanism panel: bodies, joints, ground and guides, updated frame by frame."""

    def __init__(self, ax: Axes, geo: _Geometry, sampler: _Sampler, contact: dict[str, NDArray[np.float64]],
                 where: str) -> None:
        self.ax, self.geo = ax, geo
        n = sampler.times.size
        self.poses = {b: _pose(sampler, b, geo, where) for b in geo.bodies}
        ground_pose = np.zeros((n, 3))
        pose = lambda b: ground_pose if b == geo.ground else self.poses[b]  # noqa: E731
        self.updates: list[Callable[[int], None]] = []
        extent: list[NDArray[np.float64]] = []
        static: list[NDArray[np.float64]] = []  # points fixed to the ground

        for body, p in self.poses.items():  # bodies
            points = geo.points_of(body)
            tracks = [_world(p, s) for s in points]
            com = p[:, :2]
            extent += tracks + [com]
            line = _pen(ax, "0.15", lw=2.2, solid_capstyle="round", zorder=3)
            if len(points) >= 3:  # a plate: its joint points around their centroid
                centre = np.mean(points, axis=0)
                order = np.argsort([math.atan2(s[1] - centre[1], s[0] - centre[0]) for s in points])
                tracks = [tracks[i] for i in order] + [tracks[order[0]]]
            elif len(points) == 1:
                tracks = [tracks[0], com]
            sliding = any(j.kind == "Translational" and body in (j.body_i, j.body_j) for j in geo.joints)
            com_marker = (_pen(ax, "0.15", ls="none", marker="s" if sliding else "o", ms=9 if sliding else 4,
                               mfc="0.85" if sliding else "0.15", zorder=4) if len(points) <= 1 else None)
            self.updates.append(self._body_update(line, tracks, com_marker, com))

        ideal_pins: list[NDArray[np.float64]] = []
        for joint in geo.joints:
            pi, pj = pose(joint.body_i), pose(joint.body_j)
            on_ground = geo.ground in (joint.body_i, joint.body_j)
            if joint.kind == "Revolute":
                track = _world(pi, joint.s_i)
                ideal_pins.append(track)
                if on_ground:
                    static.append(track[0])
            elif joint.kind == "Translational":
                axis = _vec(joint.spec.get("axis"))
                if axis is None:
                    continue
                u = geo.local_vector(joint.body_i, axis)
                travel = _world(pj, joint.s_j) - _world(pi, joint.s_i)
                along = np.sum(travel * _direction(pi, u), axis=1)
                reach = (float(along.min()), float(along.max()))
                guide = _pen(ax, _GROUND, lw=1.0, ls="--", zorder=1)
                self.updates.append(self._guide_update(guide, pi, joint.s_i, u, [reach], 0.0))
                if on_ground:
                    extent += [np.array([joint.s_i + r * u for r in reach])]
            elif joint.kind == "RevoluteClearance":
                track = _world(pi, joint.s_i)
                if on_ground:
                    static.append(track[0])
                ring = _pen(ax, _FREE, ls="none", marker="o", ms=9, mfc="none", mew=1.8, zorder=6)
                self.updates.append(self._ring_update(ring, track, contact.get(joint.name)))
            elif joint.kind == "TranslationalClearance":
                g = _guide_geometry(joint, geo)
                if g is None:
                    continue
                centre = _world(pj, joint.s_j)
                along = (centre - _world(pi, joint.s_i)) @ _direction(pi[:1], g["t_guide"])[0]
                reach = g["limits"] or [(float(along.min()) - g["L"], float(along.max()) + g["L"])]
                half = 0.5 * g["W"] + g["c"]
                for side in (1.0, -1.0):
                    surface = _pen(ax, _GROUND, lw=1.2, zorder=1)
                    self.updates.append(self._guide_update(surface, pi, joint.s_i, g["t_guide"], reach, side * half))
                block = ax.fill([], [], fc="0.85", ec=_FREE, lw=1.5, zorder=2)[0]
                a = _direction(pj, g["e_slider"])
                self.updates.append(self._block_update(block, centre, a, g["L"], g["W"], contact.get(joint.name)))
                extent.append(centre)
                normal = np.array([-g["t_guide"][1], g["t_guide"][0]])
                extent += [_world(pi, joint.s_i + r * g["t_guide"] + side * half * normal)
                           for lim in reach for r in lim for side in (1.0, -1.0)]
        if ideal_pins:
            pins = _pen(ax, "0.1", ls="none", marker="o", ms=5, mfc="white", mew=1.2, zorder=5)
            stacked = np.stack(ideal_pins, axis=1)  # (n, n_pins, 2)
            self.updates.append(lambda k: pins.set_data(stacked[k, :, 0], stacked[k, :, 1]))
        everything = np.concatenate([e.reshape(-1, 2) for e in extent] + ([np.array(static)] if static else []))
        lo, hi = everything.min(axis=0), everything.max(axis=0)
        span = max(float((hi - lo).max()), 1e-6)
        lo, hi = lo - 0.08 * span, hi + 0.08 * span
        if static:  # the ground: a grey triangle under each of its joint points
            pts = np.array(static)
            ax.plot(pts[:, 0], pts[:, 1] - 0.025 * span, ls="none", marker="^", ms=9, color=_GROUND, zorder=0)
        # equal scales: widen the shorter side of the data to the panel's shape
        box = ax.get_position()
        width, height = ax.figure.get_size_inches()
        shape = (box.width * width) / max(box.height * height, 1e-9)
        dx, dy = hi - lo
        centre = 0.5 * (lo + hi)
        if dx / dy < shape:
            dx = dy * shape
        else:
            dy = dx / shape
        ax.set_xlim(centre[0] - 0.5 * dx, centre[0] + 0.5 * dx)
        ax.set_ylim(centre[1] - 0.5 * dy, centre[1] + 0.5 * dy)
        ax.set_aspect("equal", adjustable="box")
        ax.tick_params(labelsize="small")
        ax.set_title(f"{geo.name or 'mechanism'} (x, y in m)", fontsize=style.TITLE_SIZE)

    @staticmethod
    def _body_update(line: Any, tracks: list[NDArray[np.float64]], marker: Any,
                     com: NDArray[np.float64]) -> Callable[[int], None]:
        stacked = np.stack(tracks, axis=1) if tracks else np.zeros((com.shape[0], 0, 2))

        def update(k: int) -> None:
            line.set_data(stacked[k, :, 0], stacked[k, :, 1])
            if marker is not None:
                marker.set_data([com[k, 0]], [com[k, 1]])
        return update

    @staticmethod
    def _guide_update(line: Any, pose: NDArray[np.float64], origin: NDArray[np.float64], u: NDArray[np.float64],
                      reaches: Sequence[Any], offset: float) -> Callable[[int], None]:
        n = np.array([-u[1], u[0]])
        local = [origin + r * u + offset * n for reach in reaches for r in (reach[0], reach[1])]
        tracks = np.stack([_world(pose, s) for s in local], axis=1)

        def update(k: int) -> None:
            line.set_data(tracks[k, :, 0], tracks[k, :, 1])
        return update

    @staticmethod
    def _ring_update(ring: Any, track: NDArray[np.float64], contact: NDArray[np.float64] | None
                     ) -> Callable[[int], None]:
        def update(k: int) -> None:
            ring.set_data([track[k, 0]], [track[k, 1]])
            ring.set_color(_CONTACT if contact is not None and contact[k] > 0 else _FREE)
        return update

    @staticmethod
    def _block_update(block: Any, centre: NDArray[np.float64], a: NDArray[np.float64], L: float, W: float,
                      contact: NDArray[np.float64] | None) -> Callable[[int], None]:
        def update(k: int) -> None:
            u = a[k]
            v = np.array([-u[1], u[0]])
            corners = [centre[k] + sa * 0.5 * L * u + sb * 0.5 * W * v
                       for sa, sb in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
            block.set_xy(np.array(corners))
            block.set_edgecolor(_CONTACT if contact is not None and contact[k] > 0 else _FREE)
        return update

    def update(self, k: int) -> None:
        for each in self.updates:
            each(k)


def _status(ax: Axes) -> Any:
    return ax.text(0.03, 0.96, "", transform=ax.transAxes, va="top", ha="left", fontsize="small", zorder=10)


FREE, IMPACT, CONTACT = 0.0, 1.0, 2.0  # contact state of a clearance joint in a frame


def _contact_state(sampler: _Sampler, joint: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per frame: CONTACT (in contact at the frame's time), IMPACT (a contact since the previous frame,
    over by now) or FREE; and the penetration to show (the current one, or the deepest of the impact)."""
    n = sampler.times.size
    flag, pen = f"{joint}.in_contact", f"{joint}.penetration"
    if flag not in sampler.result:
        return np.zeros(n), np.full(n, np.nan)
    now = np.asarray(sampler.result[flag], dtype=np.float64)[sampler.last] > 0
    since = sampler.since_previous(flag, np.max) > 0
    state = np.where(now, CONTACT, np.where(since, IMPACT, FREE))
    if pen not in sampler.result:
        return state, np.full(n, np.nan)
    return state, np.where(now, sampler.at(pen), sampler.since_previous(pen, np.max))


def _contact_text(state: float, depth: float) -> str:
    """What a panel says about its joint in this frame."""
    known = math.isfinite(depth)
    if state == CONTACT:
        return f"contact, δ = {depth * 1e6:.3g} µm" if known else "contact"
    if state == IMPACT:
        return f"impact since last frame, δ max {depth * 1e6:.3g} µm" if known else "impact since last frame"
    return "free flight"


class _RevoluteInset:
    """Journal orbit inside the clearance circle (µm), current journal centre, contact in red."""

    def __init__(self, ax: Axes, joint: _Joint, sampler: _Sampler, contact: NDArray[np.float64] | None,
                 depth: NDArray[np.float64] | None) -> None:
        r = sampler.result
        name = joint.name
        self.ok = f"{name}.ex" in r and f"{name}.ey" in r
        c = _revolute_clearance(joint.spec)
        ax.set_title(f"{name}: journal orbit (µm)", fontsize="small")
        ax.set_aspect("equal", adjustable="box")
        ax.tick_params(labelsize="x-small")
        self.status = _status(ax)
        self.contact, self.depth = contact, depth
        if not self.ok:
            self.status.set_text(f"no channels {name}.ex/ey")
            return
        scale = 1e6
        ex, ey = np.asarray(r[f"{name}.ex"]) * scale, np.asarray(r[f"{name}.ey"]) * scale
        self.ex, self.ey, self.first = ex, ey, sampler.first
        self.last = sampler.last
        self.x, self.y = sampler.at(f"{name}.ex") * scale, sampler.at(f"{name}.ey") * scale
        radius = c * scale if c is not None else float(np.max(np.hypot(ex, ey)))
        angle = np.linspace(0.0, 2.0 * np.pi, 241)
        ax.plot(radius * np.cos(angle), radius * np.sin(angle), "k--", lw=0.8)
        end = int(sampler.last[-1]) + 1
        whole = style.stride(np.arange(self.first, end), _ORBIT_POINTS)
        ax.plot(ex[whole], ey[whole], color="0.8", lw=0.5)
        self.trail = _pen(ax, _FREE, lw=0.8)
        self.dot = _pen(ax, _FREE, ls="none", marker="o", ms=5, zorder=5)
        self.arm = _pen(ax, "0.4", lw=0.6)
        reach = 1.2 * max(radius, float(np.max(np.hypot(ex[whole], ey[whole]))) if whole.size else radius)
        ax.set_xlim(-reach, reach)
        ax.set_ylim(-reach, reach)

    def update(self, k: int) -> None:
        if not self.ok:
            return
        hit = self.contact is not None and self.contact[k] > 0
        colour = _CONTACT if hit else _FREE
        stop = int(self.last[k]) + 1
        idx = style.stride(np.arange(self.first, stop), _ORBIT_POINTS)
        self.trail.set_data(np.append(self.ex[idx], self.x[k]), np.append(self.ey[idx], self.y[k]))
        self.dot.set_data([self.x[k]], [self.y[k]])
        self.dot.set_color(colour)
        self.arm.set_data([0.0, self.x[k]], [0.0, self.y[k]])
        state = float(self.contact[k]) if self.contact is not None else FREE
        self.status.set_text(_contact_text(state, float(self.depth[k]) if self.depth is not None else math.nan))
        self.status.set_color(colour)


class _TranslationalInset:
    """The slider in its guide: lateral offset, tilt and penetration magnified, corners in contact in red."""

    CORNERS = (("A_upper", 1, 1), ("B_upper", -1, 1), ("C_lower", -1, -1), ("D_lower", 1, -1))

    def __init__(self, ax: Axes, joint: _Joint, geo: _Geometry, sampler: _Sampler, magnify: float | None,
                 contact: NDArray[np.float64] | None, depth: NDArray[np.float64] | None) -> None:
        r = sampler.result
        name = joint.name
        g = _guide_geometry(joint, geo)
        self.ok = g is not None and all(f"{name}.{q}" in r for q in ("s", "y", "tilt"))
        ax.tick_params(labelsize="x-small")
        self.status = _status(ax)
        self.contact, self.depth = contact, depth
        if not self.ok:
            ax.set_title(f"{name}: slider in guide", fontsize="small")
            self.status.set_text(f"no channels {name}.s/y/tilt")
            return
        L, W, c = g["L"], g["W"], g["c"]  # type: ignore[index]
        # default: the magnified clearance 2 c M spans a quarter of the slider width
        self.M = float(magnify) if magnify is not None else max(1.0, _nice(W / (8.0 * c)))
        mm = 1e3
        ax.set_title(f"{name}: slider in guide (mm, across × {self.M:g})", fontsize="small")
        s, y, tilt = (sampler.at(f"{name}.{q}") for q in ("s", "y", "tilt"))
        cos, sin = np.cos(tilt), np.sin(tilt)
        self.quad = np.empty((s.size, 4, 2))
        for i, (_, sa, sb) in enumerate(self.CORNERS):
            a, b = sa * 0.5 * L, sb * 0.5 * W
            along = s + a * cos - b * sin
            lateral = y + a * sin + b * cos
            self.quad[:, i, 0] = along * mm
            self.quad[:, i, 1] = (b + self.M * (lateral - b)) * mm  # deviation from the centred slider, magnified
        self.centre = np.column_stack([s, self.M * y]) * mm
        self.corner_contact = [sampler.since_previous(f"{name}.{p}.in_contact", np.max)
                               if f"{name}.{p}.in_contact" in r else None for p, _, _ in self.CORNERS]
        half = (0.5 * W + self.M * c) * mm
        reach = g["limits"] or [(float(np.min(s)) - L, float(np.max(s)) + L)]  # type: ignore[index]
        lo = min(lim[0] for lim in reach) * mm
        hi = max(lim[1] for lim in reach) * mm
        for side in (1.0, -1.0):
            ax.plot([lo, hi], [side * half, side * half], color="0.2", lw=1.2)
            ax.axhline(side * 0.5 * W * mm, color="0.75", lw=0.6, ls=":")
        ss = np.asarray(r[f"{name}.s"]) * mm
        yy = np.asarray(r[f"{name}.y"]) * self.M * mm
        end = int(sampler.last[-1]) + 1
        whole = style.stride(np.arange(sampler.first, end), _ORBIT_POINTS)
        ax.plot(ss[whole], yy[whole], color="0.8", lw=0.5)
        self.ss, self.yy, self.first, self.last = ss, yy, sampler.first, sampler.last
        self.trail = _pen(ax, _FREE, lw=0.8)
        self.block = ax.fill([], [], fc="0.9", ec=_FREE, lw=1.2, zorder=3)[0]
        self.hits = _pen(ax, _CONTACT, ls="none", marker="o", ms=4, zorder=5)
        margin = 0.25 * half
        ax.set_xlim(lo - 0.02 * (hi - lo), hi + 0.02 * (hi - lo))
        ax.set_ylim(-half - margin, half + margin)

    def update(self, k: int) -> None:
        if not self.ok:
            return
        hit = self.contact is not None and self.contact[k] > 0
        colour = _CONTACT if hit else _FREE
        self.block.set_xy(self.quad[k])
        self.block.set_edgecolor(colour)
        stop = int(self.last[k]) + 1
        idx = style.stride(np.arange(self.first, stop), _ORBIT_POINTS)
        self.trail.set_data(np.append(self.ss[idx], self.centre[k, 0]), np.append(self.yy[idx], self.centre[k, 1]))
        touching = [i for i, on in enumerate(self.corner_contact) if on is not None and on[k] > 0]
        self.hits.set_data(self.quad[k, touching, 0], self.quad[k, touching, 1])
        state = float(self.contact[k]) if self.contact is not None else FREE
        self.status.set_text(_contact_text(state, float(self.depth[k]) if self.depth is not None else math.nan))
        self.status.set_color(colour)


class _Cursor:
    """The chosen channel over the window, contact intervals shaded, a moving vertical line."""

    def __init__(self, ax: Axes, result: Result, channel: str, t0: float, t1: float, scale: float, unit: str,
                 contact_names: Sequence[str], sampler: _Sampler) -> None:
        t = np.asarray(result.t, dtype=np.float64)
        values = np.asarray(result[channel], dtype=np.float64)
        index = style.select_times(t, values, window=(t0, t1), max_points=_CURSOR_POINTS)
        ax.plot(t[index] * scale, values[index], color=_FREE, lw=0.8)
        inside = style.window_index(t, (t0, t1))
        if contact_names and inside.size:
            touching = np.zeros(inside.size, dtype=bool)
            for name in contact_names:
                touching |= np.asarray(result[name])[inside] > 0
            ax.fill_between(t[inside] * scale, 0, 1, where=touching, transform=ax.get_xaxis_transform(),
                            color=_CONTACT, alpha=0.15, lw=0, step="post")
        ax.set_xlim(t0 * scale, t1 * scale)
        ax.set_xlabel(f"t ({unit})", fontsize="small")
        ax.set_ylabel(style.quantity_label(channel, result.units.get(channel, "")), fontsize="small")
        ax.tick_params(labelsize="x-small")
        self.value = sampler.at(channel)
        self.times = sampler.times * scale
        self.line = ax.axvline(self.times[0], color="k", lw=1.0)
        self.dot = _pen(ax, "k", ls="none", marker="o", ms=4, zorder=5)

    def update(self, k: int) -> None:
        self.line.set_xdata([self.times[k], self.times[k]])
        self.dot.set_data([self.times[k]], [self.value[k]])


# --------------------------------------------------------------------------- writing


def _writer(path: Path, fps: float, f: _Fields) -> Any:
    """PillowWriter for a GIF; FFMpegWriter for an MP4, or a clear error when ffmpeg is missing."""
    import matplotlib
    from matplotlib import animation

    if path.suffix.lower() == ".gif":
        from PIL import Image

        class _Compact(animation.PillowWriter):
            """PillowWriter keeping each frame as a 256-colour image (what a GIF stores): a third of the memory."""

            def grab_frame(self, **savefig_kwargs: Any) -> None:
                super().grab_frame(**savefig_kwargs)
                self._frames[-1] = self._frames[-1].convert("RGB").convert("P", palette=Image.Palette.ADAPTIVE)

        return _Compact(fps=fps)
    program = str(matplotlib.rcParams["animation.ffmpeg_path"])
    if shutil.which(program) is None:
        raise MissingDependencyError(
            f"{f.where}: {f.path}={str(path)!r}: writing an MP4 needs the program ffmpeg, which was not found "
            f"(matplotlib rcParams['animation.ffmpeg_path'] = {program!r}); install ffmpeg, or write a .gif "
            "(pillow, no external program needed).")
    # libx264 with yuv420p needs even width and height
    return animation.FFMpegWriter(fps=fps, codec="h264", extra_args=["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])


def _check_path(path: Any, f: _Fields) -> Path:
    from ..results.outputs import check_file

    what = "an animation file ending in .gif (or .mp4 when ffmpeg is installed)"
    if not isinstance(path, (str, os.PathLike)):
        options.fail(f.where, f.path, path, what)
    p = Path(path)
    if p.is_dir() or str(path) == "":  # check_file says so, with a file name to use
        check_file(p if str(path) else "", f"{f.where} {f.path}", what=what, example="run.gif")
    if p.suffix.lower() not in FORMATS:
        options.fail(f.where, f.path, str(path), what)
    return check_file(p, f"{f.where} {f.path}", what=what, example="run.gif")


def animate(result: Result, path: str | os.PathLike[str], *, fps: float = 25.0, window: Window = None,
            slow_motion: float | None = None, size: tuple[int, int] = (720, 450), channel: str | None = None,
            magnify: float | None = None, progress: bool = False) -> Path:
    """Write an animation of ``result``: the mechanism moving, its clearance joints magnified, a time cursor.

    Parameters
    ----------
    result : Result
        A run with its scene description (``result.parameters["scene"]``, as every result
        of :func:`daeclear.simulate` or :func:`daeclear.load` has) and the x, y, phi channels
        of every body.
    path : str or path-like
        ``*.gif`` (pillow through matplotlib's PillowWriter, no external program) or
        ``*.mp4`` (needs the program ffmpeg). Written atomically: a failure or Ctrl-C leaves
        no partial file.
    fps : float
        Frames per second, in (0, 100].
    window : (t0, t1), optional
        Simulated time shown, s, inside the run with t0 < t1 (None, or a None side: the
        run's start or end).
    slow_motion : float, optional
        How many times slower than real time the window plays (> 0; < 1 plays faster).
        None: the window plays in :data:`DEFAULT_PLAY_TIME` = 5 s.
    size : (int, int)
        Width and height, pixels, each in [160, 4000].
    channel : str, optional
        Channel of the time plot with the moving cursor (e.g. ``"drive.moment"``,
        ``"slider.vx"``). None: the first driver's moment, else the first clearance joint's
        normal force, else the mechanical energy.
    magnify : float, optional
        Magnification (> 0) of the lateral offset, tilt and penetration of the slider in the
        panel of a translational clearance joint. None: the magnified clearance 2 c M spans a
        quarter of the slider width (a 1-2-5 number; 10 for Table 4.3). The panel of a
        revolute clearance joint plots the eccentricity in micrometres and needs none.
    progress : bool
        Show the frames rendered on stderr (a tqdm bar on a terminal, else a few plain lines).

    Returns
    -------
    pathlib.Path
        ``path``.

    Notes
    -----
    ``n_frames = max(2, round(D * slow_motion * fps))`` for a window of duration D,
    evenly spaced from t0 to t1 inclusive (:func:`frame_count`, :func:`frame_times`);
    at most :data:`MAX_FRAMES`.

    Raises
    ------
    SceneError
        A bad option (the message names it, its value and what is allowed), or a result
        without a scene description or body channels.
    MissingDependencyError
        An MP4 asked for without ffmpeg.
    OutputError
        ``path`` cannot be written (checked before rendering).
    """
    return render(result, path, fps=fps, window=window, slow_motion=slow_motion, size=size, channel=channel,
                    magnify=magnify, progress=progress)


def render(result: Result, path: Any, *, fps: Any, window: Window, slow_motion: Any, size: Any,
           channel: Any, magnify: Any, progress: Any, fields: _Fields = _Fields()) -> Path:
    """:func:`animate` with the option names of the caller (``fields``) in its messages."""
    f = fields
    fps_v = options.number(fps, where=f.where, field=f.fps, low=0.0, high=MAX_FPS)
    t0, t1 = _window(result, window, f)
    duration = t1 - t0
    speed = (DEFAULT_PLAY_TIME / duration if slow_motion is None
             else options.number(slow_motion, where=f.where, field=f.slow_motion, low=0.0))
    width, height = _size(size, f)
    if magnify is not None:
        options.number(magnify, where=f.where, field=f.magnify, low=0.0)
    show = options.flag(progress, where=f.where, field=f.progress)
    n_frames = frame_count(duration, speed, fps_v)
    if n_frames > MAX_FRAMES:
        raise SceneError(f"{f.where}: {n_frames} frames (duration {duration:g} s x {f.slow_motion} {speed:g} x "
                         f"{f.fps} {fps_v:g}), must be at most {MAX_FRAMES}; shorten {f.window} or lower "
                         f"{f.slow_motion} or {f.fps}.")
    geo = _geometry(result, f.where)
    clearance = [j for j in geo.joints if j.kind in ("RevoluteClearance", "TranslationalClearance")]
    channel_v = _default_channel(result, geo, clearance) if channel is None else _check_channel(result, channel, f)
    target = _check_path(path, f)
    writer = _writer(target, fps_v, f)  # an MP4 without ffmpeg fails here, before any rendering

    import matplotlib
    import matplotlib.pyplot as plt

    times = frame_times(t0, t1, n_frames)
    sampler = _Sampler(result, times, t0, t1)
    for body in geo.bodies:
        _pose(sampler, body, geo, f.where)  # every body's channels exist, before a figure is made
    contact: dict[str, NDArray[np.float64]] = {}
    depth: dict[str, NDArray[np.float64]] = {}
    for j in clearance:
        contact[j.name], depth[j.name] = _contact_state(sampler, j.name)
    shown = clearance[:MAX_INSETS]

    scale, unit = (1e3, "ms") if max(abs(t0), abs(t1)) < 1.0 else (1.0, "s")
    spacing = (t1 - t0) / (n_frames - 1) * scale
    decimals = min(9, max(0, math.ceil(-math.log10(spacing)))) + 1 if spacing > 0 else 3

    font = float(np.clip(height / 55.0, 5.5, 11.0))
    with matplotlib.rc_context({"font.size": font, "savefig.bbox": None}):
        fig = plt.figure(figsize=(width / _DPI, height / _DPI), dpi=_DPI)
        try:
            updates = _layout(fig, result, geo, sampler, shown, contact, depth, magnify, channel_v, t0, t1,
                              scale, unit, f.where)
            clock = fig.text(0.99, 0.985, "", ha="right", va="top", fontsize="small", family="monospace")
            caption = style.caption(result)
            fig.text(0.01, 0.985, caption, ha="left", va="top", fontsize="small")
            if len(clearance) > len(shown):
                fig.text(0.99, 0.01, f"{len(clearance) - len(shown)} more clearance joint(s) not shown",
                         ha="right", va="bottom", fontsize="x-small", color="0.4")
            _write(fig, writer, target, n_frames, updates, clock, times * scale, unit, decimals, show)
        finally:
            plt.close(fig)
    return target


def _layout(fig: Figure, result: Result, geo: _Geometry, sampler: _Sampler, shown: Sequence[_Joint],
            contact: dict[str, NDArray[np.float64]], depth: dict[str, NDArray[np.float64]], magnify: float | None,
            channel: str, t0: float, t1: float, scale: float, unit: str, where: str) -> list[Callable[[int], None]]:
    """Make the panels (mechanism, one per clearance joint, time cursor); their frame updates."""
    grid = fig.add_gridspec(2, 2 if shown else 1, width_ratios=[1.7, 1] if shown else None, height_ratios=[3, 1],
                            left=0.08, right=0.98, bottom=0.1, top=0.9, hspace=0.35, wspace=0.25)
    main = fig.add_subplot(grid[0, 0])
    updates: list[Callable[[int], None]] = [_Scene(main, geo, sampler, contact, where).update]
    if shown:
        column = grid[0, 1].subgridspec(len(shown), 1, hspace=0.55)
        for i, joint in enumerate(shown):
            ax = fig.add_subplot(column[i, 0])
            if joint.kind == "RevoluteClearance":
                inset: Any = _RevoluteInset(ax, joint, sampler, contact.get(joint.name), depth.get(joint.name))
            else:
                inset = _TranslationalInset(ax, joint, geo, sampler, magnify, contact.get(joint.name),
                                            depth.get(joint.name))
            updates.append(inset.update)
    cursor_ax = fig.add_subplot(grid[1, :])
    contact_names = [f"{j.name}.in_contact" for j in shown if f"{j.name}.in_contact" in result]
    updates.append(_Cursor(cursor_ax, result, channel, t0, t1, scale, unit, contact_names, sampler).update)
    return updates


def _write(fig: Figure, writer: Any, target: Path, n_frames: int, updates: Sequence[Callable[[int], None]],
           clock: Any, times: NDArray[np.float64], unit: str, decimals: int, show: bool) -> None:
    """Render every frame into a temporary file beside ``target``, renamed over it once complete."""
    from ..results.outputs import deferred_sigint

    tmp = target.with_name(f".{target.stem}.{uuid.uuid4().hex[:12]}.tmp{target.suffix}")
    bar = Progress(n_frames, unit="frames", desc=f"animating {target.name}", enabled=show)
    try:
        writer.setup(fig, str(tmp), dpi=_DPI)
        try:
            for k in range(n_frames):
                for update in updates:
                    update(k)
                clock.set_text(f"t = {times[k]:.{decimals}f} {unit}")
                writer.grab_frame()
                bar.update(k + 1)
        finally:
            bar.close()
        with deferred_sigint():
            writer.finish()
            os.replace(tmp, target)
    except BaseException:
        proc = getattr(writer, "_proc", None)  # ffmpeg, when it was started
        if proc is not None and proc.poll() is None:
            proc.kill()
        tmp.unlink(missing_ok=True)
        raise
