"""One frame of a mechanism animation: the scene's geometry, body poses at the frame times, the mechanism drawn.

:func:`scene_geometry` turns a result's scene description into body-fixed points, :class:`Sampler`
samples its channels at the frame times, :class:`MechanismPanel` draws the mechanism to scale (red
while in contact). The options and the file are :mod:`daeclear.plot.animate`'s, the magnified joint
panels :mod:`daeclear.plot.animation_panels`'.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..core import options
from . import style
from ..core.errors import SceneError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..results.result import Result

__all__ = ["CONTACT", "CONTACT_COLOR", "FREE", "FREE_COLOR", "Geometry", "IMPACT", "Joint", "MechanismPanel", "Sampler",
           "body_pose", "contact_state", "contact_text", "guide_geometry", "nice_number", "pen_line",
           "revolute_clearance", "scene_geometry", "status_text"]

CONTACT_COLOR = "C3"
"""Colour of a clearance joint in contact (or hit since the previous frame)."""
FREE_COLOR = "C0"
"""Colour of a clearance joint in free flight."""
_GROUND = "0.45"


def _vec(value: Any) -> NDArray[np.float64] | None:
    if value is None:
        return None
    try:
        v = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        return None
    return v if v.shape == (2,) and np.all(np.isfinite(v)) else None


@dataclass
class Joint:
    """A joint as drawn: kind, its two bodies, body-fixed points and the element's description."""

    name: str
    kind: str
    body_i: str
    body_j: str
    s_i: NDArray[np.float64]
    s_j: NDArray[np.float64]
    spec: Mapping[str, Any]


@dataclass
class Geometry:
    """The scene description turned into body-fixed points: what every frame is drawn from."""

    name: str
    ground: str
    bodies: dict[str, tuple[NDArray[np.float64], float]]  # reference pose: position, angle
    joints: list[Joint] = field(default_factory=list)
    drivers: list[str] = field(default_factory=list)

    def _to_body(self, body: str, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """World components ``v`` in the frame of ``body`` in the reference configuration."""
        phi0 = 0.0 if body == self.ground else self.bodies[body][1]
        c, s = math.cos(phi0), math.sin(phi0)
        return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])

    def local_point(self, body: str, world: NDArray[np.float64]) -> NDArray[np.float64]:
        """Body-fixed coordinates of a world point of the reference configuration."""
        return world.copy() if body == self.ground else self._to_body(body, world - self.bodies[body][0])

    def local_vector(self, body: str, world: NDArray[np.float64]) -> NDArray[np.float64]:
        """Body-fixed components of a world direction (unit length) of the reference configuration."""
        return self._to_body(body, world / math.hypot(*world))

    def points_of(self, body: str) -> list[NDArray[np.float64]]:
        """Distinct body-fixed joint points of ``body``, in the scene's order."""
        out: list[NDArray[np.float64]] = []
        for joint in self.joints:
            for b, s in ((joint.body_i, joint.s_i), (joint.body_j, joint.s_j)):
                if b == body and not any(np.allclose(s, p, rtol=0.0, atol=1e-9) for p in out):
                    out.append(s)
        return out


def scene_geometry(result: Result, where: str) -> Geometry:
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
                                 float(angle) if options.is_real(angle) else 0.0)
    if not bodies:
        raise SceneError(f"{where}: the scene description has no body to draw.")
    geo = Geometry(name=str(scene.get("name", "")), ground=ground, bodies=bodies)  # type: ignore[union-attr]
    for name, spec in elements.items():
        if not isinstance(spec, Mapping):
            continue
        if spec.get("kind") == "Driver":
            geo.drivers.append(str(name))
            continue
        b_i, b_j = spec.get("body_i"), spec.get("body_j")
        if not isinstance(b_i, str) or not isinstance(b_j, str) or not {b_i, b_j} <= {ground, *bodies}:
            continue
        at = _vec(spec.get("at"))
        p_i, p_j = _vec(spec.get("point_i")), _vec(spec.get("point_j"))
        if p_i is None and at is None or p_j is None and at is None:
            continue
        s_i = p_i if p_i is not None else geo.local_point(b_i, at)  # type: ignore[arg-type]
        s_j = p_j if p_j is not None else geo.local_point(b_j, at)  # type: ignore[arg-type]
        geo.joints.append(Joint(str(name), str(spec.get("kind", "")), b_i, b_j, s_i, s_j, spec))
    return geo


class Sampler:
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


def body_pose(sampler: Sampler, body: str, geo: Geometry, where: str) -> NDArray[np.float64]:
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
    c, si = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.column_stack([pose[:, 0] + c * s[0] - si * s[1], pose[:, 1] + si * s[0] + c * s[1]])


def _direction(pose: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
    """(n_frames, 2) world components of the body-fixed direction ``u``."""
    return _world(pose * [0.0, 0.0, 1.0], u)


def nice_number(value: float) -> float:
    """The 1-2-5 number nearest below ``value`` (a readable magnification)."""
    if value <= 0 or not math.isfinite(value):
        return 1.0
    exponent = math.floor(math.log10(value))
    base = value / 10 ** exponent
    step = 5.0 if base >= 5 else 2.0 if base >= 2 else 1.0
    return step * 10 ** exponent


def _float(spec: Mapping[str, Any], key: str) -> float | None:
    value = spec.get(key)
    return float(value) if options.is_real(value) and math.isfinite(float(value)) else None


def revolute_clearance(spec: Mapping[str, Any]) -> float | None:
    """Radial clearance of a revolute clearance joint's description (given, or bearing minus journal radius)."""
    c = _float(spec, "clearance")
    if c is not None:
        return c
    R_i, R_j = _float(spec, "bearing_radius"), _float(spec, "journal_radius")
    return R_i - R_j if R_i is not None and R_j is not None else None


def guide_geometry(joint: Joint, geo: Geometry) -> dict[str, Any] | None:
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


def pen_line(ax: Axes, color: str, **kw: Any) -> Any:
    """An empty line on ``ax`` that a frame update fills with data."""
    (line,) = ax.plot([], [], color=color, **kw)
    return line


class MechanismPanel:
    """The mechanism panel: bodies, joints, ground and guides, updated frame by frame."""

    def __init__(self, ax: Axes, geo: Geometry, sampler: Sampler, contact: dict[str, NDArray[np.float64]],
                 where: str) -> None:
        self.poses = {b: body_pose(sampler, b, geo, where) for b in geo.bodies}
        pose = {**self.poses, geo.ground: np.zeros((sampler.times.size, 3))}
        self.updates: list[Callable[[int], None]] = []
        extent: list[NDArray[np.float64]] = []
        static: list[NDArray[np.float64]] = []  # points fixed to the ground

        for body, p in self.poses.items():  # bodies
            points = geo.points_of(body)
            tracks = [_world(p, s) for s in points]
            com = p[:, :2]
            extent += tracks + [com]
            line = pen_line(ax, "0.15", lw=2.2, solid_capstyle="round", zorder=3)
            if len(points) >= 3:  # a plate: its joint points around their centroid
                centre = np.mean(points, axis=0)
                order = np.argsort([math.atan2(s[1] - centre[1], s[0] - centre[0]) for s in points])
                tracks = [tracks[i] for i in order] + [tracks[order[0]]]
            elif len(points) == 1:
                tracks = [tracks[0], com]
            sliding = any(j.kind == "Translational" and body in (j.body_i, j.body_j) for j in geo.joints)
            com_marker = (pen_line(ax, "0.15", ls="none", marker="s" if sliding else "o", ms=9 if sliding else 4,
                               mfc="0.85" if sliding else "0.15", zorder=4) if len(points) <= 1 else None)
            self.updates.append(self._body_update(line, tracks, com_marker, com))

        ideal_pins: list[NDArray[np.float64]] = []
        for joint in geo.joints:
            pi, pj = pose[joint.body_i], pose[joint.body_j]
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
                guide = pen_line(ax, _GROUND, lw=1.0, ls="--", zorder=1)
                self.updates.append(self._guide_update(guide, pi, joint.s_i, u, [reach], 0.0))
                if on_ground:
                    extent += [np.array([joint.s_i + r * u for r in reach])]
            elif joint.kind == "RevoluteClearance":
                track = _world(pi, joint.s_i)
                if on_ground:
                    static.append(track[0])
                ring = pen_line(ax, FREE_COLOR, ls="none", marker="o", ms=9, mfc="none", mew=1.8, zorder=6)
                self.updates.append(self._ring_update(ring, track, contact.get(joint.name)))
            elif joint.kind == "TranslationalClearance":
                g = guide_geometry(joint, geo)
                if g is None:
                    continue
                centre = _world(pj, joint.s_j)
                along = (centre - _world(pi, joint.s_i)) @ _direction(pi[:1], g["t_guide"])[0]
                limits = g["limits"] or [(float(along.min()) - g["L"], float(along.max()) + g["L"])]
                half = 0.5 * g["W"] + g["c"]
                for side in (1.0, -1.0):
                    surface = pen_line(ax, _GROUND, lw=1.2, zorder=1)
                    self.updates.append(self._guide_update(surface, pi, joint.s_i, g["t_guide"], limits, side * half))
                block = ax.fill([], [], fc="0.85", ec=FREE_COLOR, lw=1.5, zorder=2)[0]
                a = _direction(pj, g["e_slider"])
                self.updates.append(self._block_update(block, centre, a, g["L"], g["W"], contact.get(joint.name)))
                extent.append(centre)
                normal = np.array([-g["t_guide"][1], g["t_guide"][0]])
                extent += [_world(pi, joint.s_i + r * g["t_guide"] + side * half * normal)
                           for lim in limits for r in lim for side in (1.0, -1.0)]
        if ideal_pins:
            pins = pen_line(ax, "0.1", ls="none", marker="o", ms=5, mfc="white", mew=1.2, zorder=5)
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
        figure = ax.get_figure(root=True)
        assert figure is not None  # the axes were made on a figure (layout_frame)
        width, height = figure.get_size_inches()
        shape = (box.width * width) / max(box.height * height, 1e-9)
        dx, dy = hi - lo
        centre = 0.5 * (lo + hi)
        if dx / dy < shape:
            dx = dy * shape
        else:
            dy = dx / shape
        ax.set(xlim=(centre[0] - 0.5 * dx, centre[0] + 0.5 * dx), ylim=(centre[1] - 0.5 * dy, centre[1] + 0.5 * dy))
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
            ring.set_color(CONTACT_COLOR if contact is not None and contact[k] > 0 else FREE_COLOR)
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
            block.set_edgecolor(CONTACT_COLOR if contact is not None and contact[k] > 0 else FREE_COLOR)
        return update

    def update(self, k: int) -> None:
        for each in self.updates:
            each(k)


def status_text(ax: Axes) -> Any:
    """The text at the top left of a panel that says what its joint does in the frame."""
    return ax.text(0.03, 0.96, "", transform=ax.transAxes, va="top", ha="left", fontsize="small", zorder=10)


FREE, IMPACT, CONTACT = 0.0, 1.0, 2.0  # contact state of a clearance joint in a frame


def contact_state(sampler: Sampler, joint: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
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


def contact_text(state: float, depth: float) -> str:
    """What a panel says about its joint in this frame."""
    known = math.isfinite(depth)
    if state == CONTACT:
        return f"contact, δ = {depth * 1e6:.3g} µm" if known else "contact"
    if state == IMPACT:
        return f"impact since last frame, δ max {depth * 1e6:.3g} µm" if known else "impact since last frame"
    return "free flight"
