"""Figures of one clearance joint: the chapter's figure families of sections 4.4 (revolute, Figs. 4.15-4.27)
and 4.5 (translational, Figs. 4.28-4.31), built from the panels of :mod:`daeclear.plot.run_panels`.

Each draws on ``ax`` (a new figure when None), passes ``**line_kw`` to ``ax.plot`` of its main curve and
returns the Axes (the four-panel figures: the Figure).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from . import style
from .run_panels import Window, response_panels, set_run_title, xy_curve

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from matplotlib.axes import Axes

    from ..results.result import Result

__all__ = ["plot_cases", "plot_journal_orbit", "plot_phase_portrait", "plot_revolute_response", "plot_slider_path",
           "plot_step_sizes", "plot_translational_response"]

_LENGTHS = {"m": (1.0, "m"), "mm": (1e3, "mm"), "um": (1e6, "µm")}  # unit -> factor from m, axis label


def _contact_intervals(result: Result, pair: str | None = None) -> list[tuple[float, float]]:
    """Intervals [t_onset, t_separation] in which ``pair`` (every pair when None) is in contact, from the events;
    open at ``result.t[0]`` or ``result.t[-1]`` when the run starts or ends in contact.
    """
    if result.n_times == 0:
        return []
    t_first, t_last = float(result.t[0]), float(result.t[-1])
    events = result.events.of(pair)
    if len(events):
        in_contact = events[0].kind == "separation"
    else:
        modes = result.segments[0][2] if result.segments else {}
        in_contact = any(mode == "contact" for name, mode in modes.items()
                         if pair is None or name == pair or name.startswith(pair + "."))
    intervals: list[tuple[float, float]] = []
    start = t_first if in_contact else None
    for event in events:
        if event.kind == "onset" and start is None:
            start = event.t
        elif event.kind == "separation" and start is not None:
            intervals.append((start, event.t))
            start = None
    if start is not None:
        intervals.append((start, max(start, t_last)))
    return intervals


def _joint_lengths(result: Result, joint: str) -> tuple[float | None, float | None]:
    """Radial clearance (m) of ``joint`` and, for a lubricated one (law "hydrodynamic"), its film threshold (m)."""
    element = style.scene_elements(result).get(joint, {})
    element = element if isinstance(element, dict) else {}
    law = element.get("law")
    film = None
    if isinstance(law, dict) and law.get("name") == "hydrodynamic":  # h_min at breakdown: film_parameter x roughness
        parts = (law.get("film_parameter", 1.0), law.get("roughness", 1e-6))
        film = float(parts[0]) * float(parts[1]) if all(isinstance(v, (int, float)) for v in parts) else None
    clearance, threshold = (float(v) if isinstance(v, (int, float)) else None for v in (element.get("clearance"), film))
    return clearance, threshold


def plot_journal_orbit(result: Result, joint: str = "clearance", *, ax: Axes | None = None, markers: bool = True,
                       clearance: float | None = None, unit: str = "um", window: Window = None,
                       max_points: int | None = None, title: str | bool | None = None, penetration: bool = True,
                       legend: str = "inside", **line_kw: Any) -> Axes:
    """Journal centre relative to the bearing centre, with the clearance circle (Figs. 4.15d, 4.17, 4.20, 4.24).

    ``result`` has the channels ``<joint>.ex``, ``<joint>.ey`` (e = r_journal - r_bearing, eq. 4.1) of the
    revolute clearance joint ``joint``. ``markers``: one on every output point (one per IDA step, as in the
    chapter, for a run without ``t_eval``). ``clearance``: radial clearance c (m) of the dashed circle, from
    the scene parameters when None. ``unit``: "um", "mm" or "m", of both axes. ``window``, ``max_points``
    (evenly spaced) and ``title`` as in :func:`plot_channel`. ``ax.lines``: the orbit, the circle |e| = c
    when known, and for a lubricated joint the film threshold |e| = c - h_threshold (dotted). Equal axes,
    square, centred on the bearing and fitting the orbit and the circle. ``penetration`` (with the circle
    known): the points outside the circle are the contact law's penetration delta = |e| - c, said in the
    legend, and the deepest one of the window is marked (``ax.collections[0]``) and labelled with delta and t.
    ``legend``: "inside" (above the orbit, in room left for it) or "none" (the caller draws the Axes'
    labelled handles elsewhere, as :func:`daeclear.plot.plot_run` does beside a single orbit).
    """
    if legend not in ("inside", "none"):
        raise ValueError(f"plot_journal_orbit: legend={legend!r}, must be 'inside' or 'none'.")
    if unit not in _LENGTHS:
        raise ValueError(f"plot_journal_orbit: unit={unit!r}, must be one of {', '.join(_LENGTHS)}.")
    created = ax is None
    ax = style.new_axes(ax)
    scale, label = _LENGTHS[unit]
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0", **({"marker": ".", "ms": 2.5} if markers else {}), **line_kw}
    ex, ey = xy_curve(result, f"{joint}.ex", f"{joint}.ey", window, max_points)
    ax.plot(ex * scale, ey * scale, **kw)
    own, threshold = _joint_lengths(result, joint)
    c = clearance if clearance is not None else own
    reach = float(np.max(np.hypot(ex, ey), initial=0.0))
    if c is not None:
        angle = np.linspace(0.0, 2.0 * np.pi, 361)
        circle = f"|e| = c = {c * scale:.4g} {label}" + ("; outside it:\nthe penetration δ = |e| − c" if penetration
                                                          else "")
        ax.plot(c * scale * np.cos(angle), c * scale * np.sin(angle), "k--", lw=0.8, label=circle)
        if threshold is not None:
            inner = (c - threshold) * scale
            ax.plot(inner * np.cos(angle), inner * np.sin(angle), "r:", lw=0.8, label="film threshold")
        if penetration:
            _mark_deepest(ax, result, joint, c, scale, label, window)
        if (threshold is not None or penetration) and legend == "inside":
            ax.legend(loc="upper left", fontsize="x-small", framealpha=0.85)
        reach = max(reach, c)
    if reach > 0:  # square, centred on the bearing: the orbit and the circle with a margin (and the legend)
        top = 1.4 if legend == "inside" and ax.get_legend() is not None else 1.12
        ax.set_xlim(-1.12 * reach * scale, 1.12 * reach * scale)
        ax.set_ylim(-1.12 * reach * scale, top * reach * scale)
    ax.set_aspect("equal", adjustable="box")
    ax.set(xlabel=f"journal x rel. to bearing ({label})", ylabel=f"journal y rel. to bearing ({label})")
    set_run_title(ax, result, title, created)
    return ax


def _mark_deepest(ax: Axes, result: Result, joint: str, c: float, scale: float, label: str, window: Window) -> None:
    """Mark the deepest penetration of the window: its point on the orbit, delta and the time."""
    index = style.window_index(result.t, window)
    if not index.size:
        return
    ex, ey = (np.asarray(result[f"{joint}.{axis}"])[index] for axis in ("ex", "ey"))
    delta = np.hypot(ex, ey) - c
    k = int(np.argmax(delta))
    if delta[k] <= 0:
        return
    t = float(np.asarray(result.t)[index][k])
    ax.scatter([ex[k] * scale], [ey[k] * scale], s=22, color="C3", zorder=3,
               label=f"deepest penetration δ = {delta[k] * scale:.3g} {label}\nat t = {t * 1e3:.3g} ms")


def plot_phase_portrait(result: Result, x: str = "slider.vx", y: str = "slider.ax", *, ax: Axes | None = None,
                        reference: Result | None = None, window: Window = None, max_points: int | None = None,
                        title: str | bool | None = None, **line_kw: Any) -> Axes:
    """Channel ``y`` against channel ``x`` (Figs. 4.18, 4.21: slider acceleration against velocity).

    The chapter's "Poincaré maps": a closed curve traced again and again is a periodic response. A dense
    ``t_eval`` gives a smooth curve; ``reference`` (e.g. the ideal joint) is drawn first, black dashed
    (``ax.lines[0]``); ``window``, ``max_points`` (evenly spaced) and ``title`` as in :func:`plot_channel`.
    """
    created = ax is None
    ax = style.new_axes(ax)
    if reference is not None:
        ax.plot(*xy_curve(reference, x, y, window, max_points), "k--", lw=0.8, label="ideal joint")
    kw: dict[str, Any] = {"lw": 0.5, "color": "C0", **line_kw}
    ax.plot(*xy_curve(result, x, y, window, max_points), **kw)
    for axis_label, name in ((ax.set_xlabel, x), (ax.set_ylabel, y)):
        axis_label(style.quantity_label(name, result.units.get(name, "")))
    set_run_title(ax, result, title, created)
    return ax


def plot_step_sizes(result: Result, *, ax: Axes | None = None, pair: str | None = None, shade: bool = True,
                    window: Window = None, max_points: int | None = None, title: str | bool | None = None,
                    **line_kw: Any) -> Axes:
    """IDA's step size against time, log scale, contact intervals shaded (section 4.4, Figs. 4.15d, 4.24).

    ``result`` needs recorded steps (``result.step_t``, ``result.step_h``; ValueError otherwise); the
    intervals of ``pair`` (every pair when None) are shaded grey when ``shade``. ``window``, ``max_points``
    (min-max decimation) and ``title`` as in :func:`plot_channel`. ``ax.lines[0]``: step size h (s) against
    the time the step reached, without the initial zero-size placeholder; one patch per contact interval.
    """
    if result.step_t is None or result.step_h is None:
        raise ValueError(f"plot_step_sizes: result of scene {result.scene_name!r} has no recorded steps "
                         f"(simulate(..., save=SaveAt(steps=True)) records them).")
    created = ax is None
    ax = style.new_axes(ax)
    t, h = np.asarray(result.step_t), np.asarray(result.step_h)
    inside = style.window_index(t, window)
    index = style.decimate(h, max_points, inside[h[inside] > 0])
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0", "marker": ".", "ms": 1.5, **line_kw}
    ax.plot(t[index], h[index], **kw)
    ax.set_yscale("log")
    if shade:
        lo, hi = style.window_bounds(window)
        spans = [(max(a, lo), min(b, hi)) for a, b in _contact_intervals(result, pair) if b >= lo and a <= hi]
        for k, (t0, t1) in enumerate(spans):
            ax.axvspan(t0, t1, color="0.85", lw=0, zorder=0, label="contact" if k == 0 else None)
    ax.set(xlabel="time (s)", ylabel="IDA step size (s)")
    set_run_title(ax, result, title, created)
    return ax


def plot_cases(results: Mapping[str, Result], draw: Any, *, ncols: int = 2, sharex: bool = False,
               sharey: bool = False, panel_size: tuple[float, float] = (3.8, 2.9), suptitle: str | None = None,
               **kwargs: Any) -> Any:
    """One panel per labelled result, each drawn by a figure function (Figs. 4.16-4.25).

    ``results``: panel title -> result, in panel order (titles get the chapter's "(a)", "(b)", ...);
    ``draw(result, ax=ax, **kwargs)`` draws each, e.g. ``plot_journal_orbit`` or
    ``functools.partial(plot_channel, channel="drive.moment")``; ``ncols`` panels per row, ``sharex`` and
    ``sharey`` as ``plt.subplots``, ``panel_size`` (width, height) of one panel in inches. Returns the
    Figure: its first ``len(results)`` axes hold the panels, unused cells are hidden.
    """
    import matplotlib.pyplot as plt

    n = len(results)
    if n == 0:
        raise ValueError("plot_cases: no results to draw.")
    ncols = max(1, min(int(ncols), n))
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel_size[0] * ncols, panel_size[1] * nrows + 0.4),
                             sharex=sharex, sharey=sharey, squeeze=False)
    flat = list(axes.ravel())
    for k, (label, result) in enumerate(results.items()):
        draw(result, ax=flat[k], **kwargs)
        style.set_title(flat[k], f"({chr(ord('a') + k)}) {label}")
    for extra in flat[n:]:
        extra.set_visible(False)
    style.set_title(fig, suptitle or "")
    fig.tight_layout()
    return fig


def _response_figure(result: Result, reference: Result | None, window: Window, max_points: int | None,
                     title: str | bool, draw_d: Any) -> Any:
    """Four panels: (a)-(c) of :func:`response_panels`, (d) drawn by ``draw_d(ax)``."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10.0, 7.0))
    (a, b), (c, d) = axes
    response_panels(result, reference, (a, b, c), window, max_points)
    draw_d(d)
    set_run_title(fig, result, title, True)
    fig.tight_layout()
    return fig


def plot_revolute_response(result: Result, *, reference: Result | None = None, orbit: Result | None = None,
                           joint: str = "clearance", window: Window = None, max_points: int | None = None,
                           title: str | bool = True) -> Any:
    """Fig. 4.15 in four panels: slider velocity, slider acceleration, crank moment, journal orbit.

    ``result``: the clearance-joint run (a dense ``t_eval`` for panels a-c); ``reference``: the ideal-joint
    run over the same times, dashed in panels a-c; ``orbit``: a run whose output times are IDA's steps
    (``t_eval=None``) for panel d (``result`` when None); ``joint``: the revolute clearance joint;
    ``window``, ``max_points`` and ``title`` as in :func:`plot_channel` (title: the caption unless False or
    a text). Returns the Figure, axes (a) ``slider.vx``, (b) ``slider.ax``, (c) ``drive.moment``, (d) orbit.
    """
    def orbit_panel(ax: Axes) -> None:
        plot_journal_orbit(orbit if orbit is not None else result, joint, ax=ax, window=window,
                           max_points=max_points, title="(d) journal trajectory relative to the bearing")

    return _response_figure(result, reference, window, max_points, title, orbit_panel)


def plot_slider_path(result: Result, joint: str = "clearance", *, ax: Axes | None = None, limits: bool = True,
                     reference: Result | None = None, window: Window = None, max_points: int | None = None,
                     title: str | bool | None = None, **line_kw: Any) -> Axes:
    """Dimensionless path of the slider centre inside the guide (Figs. 4.28d, 4.30, 4.33).

    ``result`` has the channels ``<joint>.xi`` (0 to 1 along the stroke) and ``<joint>.eta`` (offset from
    the guide's mid-line over 2c, +-0.5 at a surface); a joint without a ``stroke`` has no ``xi`` and its
    path is drawn against ``<joint>.s`` in mm. ``limits`` draws eta = +-0.5 (dashed); ``reference`` is
    drawn first, black dotted; ``window``, ``max_points`` (evenly spaced) and ``title`` as in
    :func:`plot_channel`. ``ax.lines``: the reference path, the slider path, the two limit lines.
    """
    created = ax is None
    ax = style.new_axes(ax)
    xi, eta = f"{joint}.xi", f"{joint}.eta"
    along = xi if xi in result else f"{joint}.s"  # no stroke given: the slider centre's s, in mm
    scale = 1.0 if along == xi else 1e3
    if reference is not None:
        x_ref, y_ref = xy_curve(reference, along, eta, window, max_points)
        ax.plot(x_ref * scale, y_ref, "k:", lw=0.8, label="ideal joint")
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0", **line_kw}
    x, y = xy_curve(result, along, eta, window, max_points)
    ax.plot(x * scale, y, **kw)
    if limits:
        for level in (0.5, -0.5):
            ax.axhline(level, color="k", ls="--", lw=0.8)
    ax.set_xlabel("ξ, slider position along the stroke (-)" if along == xi
                  else "s, slider centre along the guide (mm)")
    ax.set_ylabel("η, offset across the guide (-)")
    set_run_title(ax, result, title, created)
    return ax


def plot_translational_response(result: Result, *, reference: Result | None = None,
                                joint: str = "clearance", window: Window = None, max_points: int | None = None,
                                title: str | bool = True) -> Any:
    """Fig. 4.28 in four panels: slider velocity, slider acceleration, crank moment, slider path.

    As :func:`plot_revolute_response` (``joint``: the translational clearance joint); axes (a) ``slider.vx``,
    (b) ``slider.ax``, (c) ``drive.moment``, (d) path.
    """
    def path_panel(ax: Axes) -> None:
        plot_slider_path(result, joint, ax=ax, window=window, max_points=max_points,
                         title="(d) dimensionless slider path inside the guide")

    return _response_figure(result, reference, window, max_points, title, path_panel)
