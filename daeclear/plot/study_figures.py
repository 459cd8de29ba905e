"""Figures of studies (:mod:`daeclear.studies`): work-precision, Poincaré sections, bifurcation diagrams,
motion maps; a swept parameter is shown with its unit, on a log axis when the grid is geometric.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from . import style

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from matplotlib.axes import Axes

__all__ = ["MOTION_COLORS", "plot_bifurcation", "plot_motion_map", "plot_poincare_section", "plot_work_precision"]


def plot_work_precision(study: Any, *, ax: Axes | None = None) -> Axes:
    """Error against wall time (log-log) of a :class:`daeclear.studies.accuracy.WorkPrecision`, one line per
    method, failed runs marked with x at the top."""
    ax = style.new_axes(ax)
    labels = list(dict.fromkeys(r["label"] for r in study.rows))
    ok_errors = [r["error"] for r in study.rows if r["status"] == 0 and math.isfinite(r["error"])]
    top = max(ok_errors) * 3 if ok_errors else 1.0
    for label in labels:
        rows = [r for r in study.rows if r["label"] == label]
        good = [r for r in rows if r["status"] == 0 and math.isfinite(r["error"]) and r["error"] > 0]
        line = ax.loglog([r["wall_time"] for r in good], [r["error"] for r in good], "o-", label=label)[0]
        for r in good:
            ax.annotate(f"{r['tolerance']:g}", (r["wall_time"], r["error"]), fontsize=6,
                        textcoords="offset points", xytext=(3, 3))
        bad = [r for r in rows if r not in good and math.isfinite(r.get("wall_time", math.nan))]
        if bad:
            ax.loglog([r["wall_time"] for r in bad], [top] * len(bad), "x", color=line.get_color())
    ax.set(xlabel="wall time (s)", ylabel=f"max error / range ({', '.join(study.channels)})")
    style.set_title(ax, f"error over t in [{study.window[0]:.3g}, {study.window[1]:.3g}] s")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", lw=0.3)
    return ax


MOTION_COLORS = {"periodic": "#2ca02c", "quasi-periodic": "#1f77b4", "chaotic": "#d62728",
                 "non-periodic": "#ff7f0e", "uncertain": "#9467bd", "undetermined": "#7f7f7f",
                 "failed": "#000000"}
"""Colour of each motion class (:data:`daeclear.analysis.MOTION_LABELS`) in the sweep figures."""


def plot_poincare_section(section: Any, *, ax: Axes | None = None, portrait: Any = None, label: str | None = None,
                          **marker_kw: Any) -> Axes:
    """Stroboscopic Poincaré section (one point per crank revolution), over the phase portrait.

    ``section`` (:class:`daeclear.analysis.PoincareSection`): its first two channels are drawn (x, y), a
    single channel against the revolution. ``portrait`` (a :class:`~daeclear.analysis.PhasePortrait`, or a
    Result whose same channels are drawn from the section's first time on) is drawn first, thin grey.
    ``label``: of the points (default "once per revolution (n points)"), drawn with ``**marker_kw`` as
    ``ax.lines[-1]`` on ``ax`` (a new figure when None). Returns the Axes.
    """
    ax = style.new_axes(ax)
    points = np.asarray(section.points)
    if points.shape[1] >= 2 and portrait is not None:
        if hasattr(portrait, "x") and hasattr(portrait, "y"):
            px, py = portrait.x, portrait.y
        else:  # a Result: its channels from the section's first time on
            mask = portrait.window_mask(section.t[0] if len(section) else None, None)
            px, py = (np.asarray(portrait[name])[mask] for name in section.channels[:2])
        ax.plot(px, py, color="0.6", lw=0.4, label="phase portrait")
    kw: dict[str, Any] = {"ls": "none", "marker": "o", "ms": 3.5, "color": "C3", **marker_kw}
    text = label or f"once per revolution ({len(points)} points)"
    if points.shape[1] >= 2:
        ax.plot(points[:, 0], points[:, 1], label=text, **kw)
        ax.set(xlabel=style.quantity_label(section.channels[0], section.units[0]),
               ylabel=style.quantity_label(section.channels[1], section.units[1]))
    else:
        ax.plot(np.arange(len(points)), points[:, 0], label=text, **kw)
        ax.set(xlabel="revolution after the transient",
               ylabel=style.quantity_label(section.channels[0], section.units[0]))
    ax.legend(loc="best", fontsize="x-small")
    return ax


def plot_bifurcation(sweep: Any, parameter: str, channel: str | int = 0, *, ax: Axes | None = None,
                     scale: float | None = None, unit: str | None = None, log: bool | None = None,
                     color_by_motion: bool = True, title: str | bool | None = None, **marker_kw: Any) -> Axes:
    """Bifurcation diagram: the Poincaré-section values of one channel against a swept parameter.

    Parameters
    ----------
    sweep : daeclear.sweep.SweepResult or mapping of float to PoincareSection
        A sweep over ``parameter`` (other parameters fixed), or parameter value -> section.
    parameter : str
        The swept parameter (x axis), e.g. ``"clearance"``.
    channel : str or int
        Section channel on the y axis (name or column).
    scale, unit : optional
        Factor applied to the parameter values and their unit; when neither is given, both from
        :data:`daeclear.plot.style.PARAMETER_AXES` (clearance in mm).
    log : bool, optional
        Logarithmic x axis; None: when the values form a geometric grid (three or more).
    color_by_motion : bool
        Colour each run's points by its motion class (:data:`MOTION_COLORS`), with a legend.
    title : str or bool, optional
        True: the mechanism and the parameters every run shares; a str: that text; False: none;
        None: the caption only on a new figure.

    Drawn on ``ax`` (a new figure when None) with ``**marker_kw``; returns the Axes, one line per motion class.
    """
    created = ax is None
    ax = style.new_axes(ax)
    scale, unit = style.parameter_display(parameter, scale, unit)
    if isinstance(sweep, Mapping):
        xs, ys = [], []
        for value, sec in sweep.items():
            col = sec.channels.index(channel) if isinstance(channel, str) else int(channel)
            xs.append(np.full(len(sec), float(value)))
            ys.append(np.asarray(sec.points)[:, col])
        x = np.concatenate(xs) if xs else np.zeros(0)
        y = np.concatenate(ys) if ys else np.zeros(0)
        first: Any = next(iter(sweep.values()), None)
        name = channel if isinstance(channel, str) else first.channels[int(channel)]
        y_unit = first.units[first.channels.index(name)] if first is not None and first.units else ""
        color_by_motion = False
    else:
        x, y, labels = sweep.bifurcation_data(parameter, channel)
        ok = [r for r in sweep.runs if r.ok]
        sec = sweep.section(ok[0]) if ok else None
        name = channel if isinstance(channel, str) else (sec.channels[int(channel)] if sec else str(channel))
        y_unit = sec.units[sec.channels.index(name)] if sec else ""
    kw: dict[str, Any] = {"ls": "none", "marker": ".", "ms": 3.0, **marker_kw}
    x = x * scale
    if color_by_motion:
        motions = np.array(labels)
        for motion, color in MOTION_COLORS.items():
            sel = motions == motion
            if np.any(sel):
                ax.plot(x[sel], y[sel], label=motion, **{**kw, "color": color})
        ax.legend(loc="best", fontsize="x-small", title="motion", title_fontsize="x-small")
    else:
        kw.setdefault("color", "k")
        ax.plot(x, y, **kw)
    values = list(sweep) if isinstance(sweep, Mapping) else [r.parameters.get(parameter) for r in sweep.runs]
    style.parameter_axis(ax, "x", parameter, values, unit, log)
    ax.set_ylabel(f"{style.quantity_label(name, y_unit)} once per revolution")
    if not isinstance(sweep, Mapping) or isinstance(title, str):
        _sweep_title(ax, sweep, title, created, (parameter,))
    return ax


def _sweep_title(ax: Axes, sweep: Any, title: str | bool | None, created: bool, exclude: tuple[str, ...]) -> None:
    """A str as given; the mechanism and the parameters every run shares when True, or None and ``created``."""
    if isinstance(title, str):
        style.set_title(ax, title)
    elif title or (title is None and created):
        style.set_title(ax, style.sweep_caption(sweep, exclude=exclude))


def plot_motion_map(sweep: Any, x: str, y: str, *, ax: Axes | None = None, x_scale: float | None = None,
                    y_scale: float | None = None, x_unit: str | None = None, y_unit: str | None = None,
                    x_log: bool | None = None, y_log: bool | None = None, annotate: bool = True,
                    title: str | bool | None = None) -> Axes:
    """Map of the motion class over two swept parameters ``x`` and ``y`` of ``sweep`` (one cell per run).

    ``x_scale``, ``y_scale``, ``x_unit``, ``y_unit``, ``x_log``, ``y_log`` and ``title`` as ``scale``,
    ``unit``, ``log`` and ``title`` of :func:`plot_bifurcation`, per axis (log: cell edges at geometric
    midpoints). ``annotate`` writes "P<k>" in periodic cells, "C" chaotic, "Q" quasi-periodic, "N"
    non-periodic, "U" uncertain, "?" undetermined, "x" failed. Returns the Axes: cells coloured by
    :data:`MOTION_COLORS`, ticks labelled with the values, one legend entry per class present.
    ValueError if two runs share a cell.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    created = ax is None
    ax = style.new_axes(ax)
    x_scale, x_unit = style.parameter_display(x, x_scale, x_unit)
    y_scale, y_unit = style.parameter_display(y, y_scale, y_unit)
    runs = [r for r in sweep.runs if x in r.parameters and y in r.parameters]

    def key(v: Any) -> tuple[int, Any]:  # numbers in order, then anything else by its text
        return (0, float(v)) if isinstance(v, (int, float)) and not isinstance(v, bool) else (1, str(v))

    xs = sorted({r.parameters[x] for r in runs}, key=key)
    ys = sorted({r.parameters[y] for r in runs}, key=key)
    classes = list(MOTION_COLORS)
    grid = np.full((len(ys), len(xs)), np.nan)
    text: dict[tuple[int, int], str] = {}
    short = {"chaotic": "C", "quasi-periodic": "Q", "non-periodic": "N", "uncertain": "U", "undetermined": "?",
             "failed": "x"}
    for r in runs:
        i, j = ys.index(r.parameters[y]), xs.index(r.parameters[x])
        if not np.isnan(grid[i, j]):
            raise ValueError(f"plot_motion_map: two runs at {x}={r.parameters[x]!r}, {y}={r.parameters[y]!r}; "
                             "fix the other parameters.")
        motion = r.motion if r.ok else "failed"
        grid[i, j] = classes.index(motion)
        text[(i, j)] = f"P{r.period}" if motion == "periodic" else short.get(motion, "")

    def positive(values: list[Any]) -> bool:  # a log axis needs numbers > 0 only
        return bool(values) and all(key(v)[0] == 0 and float(v) > 0 for v in values)

    x_log = style.is_geometric(xs) if x_log is None else bool(x_log) and positive(xs)
    y_log = style.is_geometric(ys) if y_log is None else bool(y_log) and positive(ys)
    x_centres, x_edges = _cells(xs, x_scale, x_log)
    y_centres, y_edges = _cells(ys, y_scale, y_log)
    ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(grid), cmap=ListedColormap(list(MOTION_COLORS.values())),
                  vmin=-0.5, vmax=len(classes) - 0.5, edgecolors="w", linewidth=0.5)
    if annotate:
        for (i, j), label in text.items():
            ax.text(x_centres[j], y_centres[i], label, ha="center", va="center", fontsize="x-small", color="w")

    def fmt(v: Any, scale: float) -> str:
        return f"{float(v) * scale:.3g}" if isinstance(v, (int, float)) and not isinstance(v, bool) else str(v)

    from matplotlib.ticker import NullLocator

    if x_log:
        ax.set_xscale("log")
        ax.xaxis.set_minor_locator(NullLocator())
    if y_log:
        ax.set_yscale("log")
        ax.yaxis.set_minor_locator(NullLocator())
    ax.set_xticks(x_centres, [fmt(v, x_scale) for v in xs], rotation=45 if len(xs) > 8 else 0)
    ax.set_yticks(y_centres, [fmt(v, y_scale) for v in ys])
    ax.set(xlim=(x_edges[0], x_edges[-1]), ylim=(y_edges[0], y_edges[-1]))
    ax.set(xlabel=style.quantity_label(x, x_unit), ylabel=style.quantity_label(y, y_unit))
    _sweep_title(ax, sweep, title, created, (x, y))
    present = sorted({int(v) for v in grid[np.isfinite(grid)]})
    ax.legend(handles=[Patch(color=MOTION_COLORS[classes[k]], label=classes[k]) for k in present],
              loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small", title="motion",
              title_fontsize="x-small")
    return ax


def _cells(values: list[Any], scale: float, log: bool) -> tuple[Any, Any]:
    """Cell centres and edges of one motion-map axis: an index grid, or the scaled values on a log axis
    (edges at the geometric midpoints, the outer cells as wide as their neighbours in ratio)."""
    if not log:
        return np.arange(len(values), dtype=float), np.arange(len(values) + 1) - 0.5
    centres = np.array([float(v) * scale for v in values])
    if centres.size == 1:
        return centres, centres * np.array([10 ** -0.5, 10 ** 0.5])
    inner = np.sqrt(centres[1:] * centres[:-1])
    first = centres[0] ** 2 / inner[0]
    last = centres[-1] ** 2 / inner[-1]
    return centres, np.concatenate([[first], inner, [last]])

