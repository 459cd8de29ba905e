"""The panels of an animation frame beside the mechanism: each clearance joint magnified, and the time cursor.

:func:`layout_frame` places them with the mechanism (:mod:`daeclear.plot.mechanism_frame`) in one figure.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from . import style
from .mechanism_frame import (CONTACT_COLOR, FREE, FREE_COLOR, Geometry, Joint, MechanismPanel, Sampler,
                              contact_text, guide_geometry, nice_number, pen_line, revolute_clearance, status_text)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..results.result import Result

__all__ = ["layout_frame"]

_CURSOR_POINTS = 2000  # samples of the cursor channel drawn (min-max decimated)
_ORBIT_POINTS = 20000  # samples of a journal orbit / slider path drawn


class _Inset:
    """A clearance joint's panel: a trail of its path so far and a status text, red while in contact."""

    def __init__(self, ax: Axes, sampler: Sampler, contact: NDArray[np.float64] | None,
                 depth: NDArray[np.float64] | None) -> None:
        ax.tick_params(labelsize="x-small")
        self.status = status_text(ax)
        self.contact, self.depth = contact, depth
        self.first, self.last = sampler.first, sampler.last

    def trail_index(self, k: int) -> NDArray[np.intp]:
        """Samples of the trail up to frame ``k`` (the whole window for k = -1)."""
        return style.stride(np.arange(self.first, int(self.last[k]) + 1), _ORBIT_POINTS)

    def show_state(self, k: int) -> str:
        """Write the joint's state in frame ``k``; returns its colour."""
        colour = CONTACT_COLOR if self.contact is not None and self.contact[k] > 0 else FREE_COLOR
        state = float(self.contact[k]) if self.contact is not None else FREE
        self.status.set_text(contact_text(state, float(self.depth[k]) if self.depth is not None else math.nan))
        self.status.set_color(colour)
        return colour


class _RevoluteInset(_Inset):
    """Journal orbit inside the clearance circle (µm), current journal centre, contact in red."""

    def __init__(self, ax: Axes, joint: Joint, sampler: Sampler, contact: NDArray[np.float64] | None,
                 depth: NDArray[np.float64] | None) -> None:
        super().__init__(ax, sampler, contact, depth)
        r = sampler.result
        name = joint.name
        self.ok = f"{name}.ex" in r and f"{name}.ey" in r
        c = revolute_clearance(joint.spec)
        ax.set_title(f"{name}: journal orbit (µm)", fontsize="small")
        ax.set_aspect("equal", adjustable="box")
        if not self.ok:
            self.status.set_text(f"no channels {name}.ex/ey")
            return
        scale = 1e6
        ex, ey = np.asarray(r[f"{name}.ex"]) * scale, np.asarray(r[f"{name}.ey"]) * scale
        self.ex, self.ey = ex, ey
        self.x, self.y = sampler.at(f"{name}.ex") * scale, sampler.at(f"{name}.ey") * scale
        radius = c * scale if c is not None else float(np.max(np.hypot(ex, ey)))
        angle = np.linspace(0.0, 2.0 * np.pi, 241)
        ax.plot(radius * np.cos(angle), radius * np.sin(angle), "k--", lw=0.8)
        whole = self.trail_index(-1)
        ax.plot(ex[whole], ey[whole], color="0.8", lw=0.5)
        self.trail = pen_line(ax, FREE_COLOR, lw=0.8)
        self.dot = pen_line(ax, FREE_COLOR, ls="none", marker="o", ms=5, zorder=5)
        self.arm = pen_line(ax, "0.4", lw=0.6)
        reach = 1.2 * max(radius, float(np.max(np.hypot(ex[whole], ey[whole]))) if whole.size else radius)
        ax.set(xlim=(-reach, reach), ylim=(-reach, reach))

    def update(self, k: int) -> None:
        if not self.ok:
            return
        idx = self.trail_index(k)
        self.trail.set_data(np.append(self.ex[idx], self.x[k]), np.append(self.ey[idx], self.y[k]))
        self.dot.set_data([self.x[k]], [self.y[k]])
        self.dot.set_color(self.show_state(k))
        self.arm.set_data([0.0, self.x[k]], [0.0, self.y[k]])


class _TranslationalInset(_Inset):
    """The slider in its guide: lateral offset, tilt and penetration magnified, corners in contact in red."""

    CORNERS = (("A_upper", 1, 1), ("B_upper", -1, 1), ("C_lower", -1, -1), ("D_lower", 1, -1))

    def __init__(self, ax: Axes, joint: Joint, geo: Geometry, sampler: Sampler, magnify: float | None,
                 contact: NDArray[np.float64] | None, depth: NDArray[np.float64] | None) -> None:
        super().__init__(ax, sampler, contact, depth)
        r = sampler.result
        name = joint.name
        g = guide_geometry(joint, geo)
        self.ok = g is not None and all(f"{name}.{q}" in r for q in ("s", "y", "tilt"))
        if not self.ok:
            ax.set_title(f"{name}: slider in guide", fontsize="small")
            self.status.set_text(f"no channels {name}.s/y/tilt")
            return
        L, W, c = g["L"], g["W"], g["c"]  # type: ignore[index]
        # default: the magnified clearance 2 c M spans a quarter of the slider width
        self.M = float(magnify) if magnify is not None else max(1.0, nice_number(W / (8.0 * c)))
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
        whole = self.trail_index(-1)
        ax.plot(ss[whole], yy[whole], color="0.8", lw=0.5)
        self.ss, self.yy = ss, yy
        self.trail = pen_line(ax, FREE_COLOR, lw=0.8)
        self.block = ax.fill([], [], fc="0.9", ec=FREE_COLOR, lw=1.2, zorder=3)[0]
        self.hits = pen_line(ax, CONTACT_COLOR, ls="none", marker="o", ms=4, zorder=5)
        margin = 0.25 * half
        ax.set(xlim=(lo - 0.02 * (hi - lo), hi + 0.02 * (hi - lo)), ylim=(-half - margin, half + margin))

    def update(self, k: int) -> None:
        if not self.ok:
            return
        self.block.set_xy(self.quad[k])
        self.block.set_edgecolor(self.show_state(k))
        idx = self.trail_index(k)
        self.trail.set_data(np.append(self.ss[idx], self.centre[k, 0]), np.append(self.yy[idx], self.centre[k, 1]))
        touching = [i for i, on in enumerate(self.corner_contact) if on is not None and on[k] > 0]
        self.hits.set_data(self.quad[k, touching, 0], self.quad[k, touching, 1])


class _Cursor:
    """The chosen channel over the window, contact intervals shaded, a moving vertical line."""

    def __init__(self, ax: Axes, result: Result, channel: str, t0: float, t1: float, scale: float, unit: str,
                 contact_names: Sequence[str], sampler: Sampler) -> None:
        t = np.asarray(result.t, dtype=np.float64)
        values = np.asarray(result[channel], dtype=np.float64)
        index = style.select_times(t, values, window=(t0, t1), max_points=_CURSOR_POINTS)
        ax.plot(t[index] * scale, values[index], color=FREE_COLOR, lw=0.8)
        inside = style.window_index(t, (t0, t1))
        if contact_names and inside.size:
            touching = np.zeros(inside.size, dtype=bool)
            for name in contact_names:
                touching |= np.asarray(result[name])[inside] > 0
            ax.fill_between(t[inside] * scale, 0, 1, where=touching, transform=ax.get_xaxis_transform(),
                            color=CONTACT_COLOR, alpha=0.15, lw=0, step="post")
        ax.set_xlim(t0 * scale, t1 * scale)
        ax.set_xlabel(f"t ({unit})", fontsize="small")
        ax.set_ylabel(style.quantity_label(channel, result.units.get(channel, "")), fontsize="small")
        ax.tick_params(labelsize="x-small")
        self.value = sampler.at(channel)
        self.times = sampler.times * scale
        self.line = ax.axvline(self.times[0], color="k", lw=1.0)
        self.dot = pen_line(ax, "k", ls="none", marker="o", ms=4, zorder=5)

    def update(self, k: int) -> None:
        self.line.set_xdata([self.times[k], self.times[k]])
        self.dot.set_data([self.times[k]], [self.value[k]])


def layout_frame(fig: Figure, result: Result, geo: Geometry, sampler: Sampler, shown: Sequence[Joint],
                 contact: dict[str, NDArray[np.float64]], depth: dict[str, NDArray[np.float64]],
                 magnify: float | None, channel: str, t0: float, t1: float, scale: float, unit: str,
                 where: str) -> list[Callable[[int], None]]:
    """Make the panels (mechanism, one per clearance joint, time cursor); their frame updates."""
    grid = fig.add_gridspec(2, 2 if shown else 1, width_ratios=[1.7, 1] if shown else None, height_ratios=[3, 1],
                            left=0.08, right=0.98, bottom=0.1, top=0.9, hspace=0.35, wspace=0.25)
    main = fig.add_subplot(grid[0, 0])
    updates: list[Callable[[int], None]] = [MechanismPanel(main, geo, sampler, contact, where).update]
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
