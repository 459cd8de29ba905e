"""Figure functions of daeclear (matplotlib).

Each function takes data and an optional ``ax``, draws on it (a new figure when
``ax`` is None) and returns the Axes; none calls ``plt.show()``. Units on the axes are
stated in the labels. Every function draws through :mod:`daeclear.plot.style`: figures of a
run are titled with its parameters (clearance, crank speed, contact law, restitution,
friction; ``title=``), the functions that draw a run over time take a time
``window=(t0, t1)`` and ``max_points`` (min-max decimation, so a long run does not plot
as a solid band), and sweep figures show the swept parameter with its unit, on a log
axis when the grid is geometric.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from . import style

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from typing import TypeAlias

    from matplotlib.axes import Axes

    from ..contact.impact import ImpactResult
    from ..results.result import Result

    Impacts: TypeAlias = ImpactResult | Iterable[ImpactResult] | Mapping[str, ImpactResult]

__all__ = ["plot_channel", "plot_force_penetration", "plot_force_time", "save_response_figure"]

Window = tuple[float | None, float | None] | None
"""A closed time window ``(t0, t1)`` in s; None (or a None side) leaves it open."""


def _axes(ax: Axes | None) -> Axes:
    return style.new_axes(ax)


def _title(target: Any, result: Result, title: str | bool | None, created: bool) -> None:
    """Title ``target`` (Axes or Figure): the run's caption when ``title`` is True, or None and the
    function made the figure itself; the text when a str; nothing when False."""
    if isinstance(title, str):
        style.set_title(target, title)
    elif title or (title is None and created):
        style.set_title(target, style.caption(result))


def _series(result: Result, name: str, window: Window, max_points: int | None) -> tuple[Any, Any]:
    """Time and values of a channel inside ``window``, min-max decimated to ``max_points``."""
    import numpy as np

    values = np.asarray(result[name])
    index = style.select_times(result.t, values, window=window, max_points=max_points)
    return np.asarray(result.t)[index], values[index]


def _curve(result: Result, x: str, y: str, window: Window, max_points: int | None) -> tuple[Any, Any]:
    """Two channels of an x-y curve inside ``window``, evenly thinned to ``max_points``."""
    import numpy as np

    index = style.select_times(result.t, window=window, max_points=max_points)
    return np.asarray(result[x])[index], np.asarray(result[y])[index]


def _label(impact: ImpactResult) -> str:
    law = impact.law
    restitution = getattr(law, "restitution", None)
    return law.name if restitution is None else f"{law.name}, $c_e$ = {restitution:g}"


def _labelled(impacts: Impacts) -> list[tuple[str, ImpactResult]]:
    from ..contact.impact import ImpactResult

    if isinstance(impacts, ImpactResult):
        return [(_label(impacts), impacts)]
    if isinstance(impacts, Mapping):
        return [(str(k), v) for k, v in impacts.items()]
    return [(_label(i), i) for i in impacts]


def plot_force_penetration(impacts: Impacts, *, ax: Axes | None = None, **line_kw: Any) -> Axes:
    """Contact force against penetration for single impacts (hysteresis loops, Fig. 4.26b).

    Parameters
    ----------
    impacts : ImpactResult, iterable of ImpactResult, or mapping label -> ImpactResult
        From :func:`daeclear.contact.simulate_impact`, one per law; unlabelled ones
        are labelled by law name and restitution.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    **line_kw
        Passed to ``ax.plot`` for every curve.

    Returns
    -------
    matplotlib.axes.Axes
        Penetration in um on x, force in N on y. The area enclosed by a loop is the
        energy lost in the impact.
    """
    ax = _axes(ax)
    for label, impact in _labelled(impacts):
        ax.plot(impact.penetration * 1e6, impact.force, label=label, **line_kw)
    ax.set_xlabel("penetration (µm)")
    ax.set_ylabel("contact force (N)")
    ax.legend()
    return ax


def plot_force_time(impacts: Impacts, *, ax: Axes | None = None, **line_kw: Any) -> Axes:
    """Contact force against time for single impacts (Fig. 4.26a).

    Parameters
    ----------
    impacts : ImpactResult, iterable of ImpactResult, or mapping label -> ImpactResult
        As in :func:`plot_force_penetration`.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    **line_kw
        Passed to ``ax.plot`` for every curve.

    Returns
    -------
    matplotlib.axes.Axes
        Time since first contact in us on x, force in N on y.
    """
    ax = _axes(ax)
    for label, impact in _labelled(impacts):
        ax.plot(impact.t * 1e6, impact.force, label=label, **line_kw)
    ax.set_xlabel("time since contact onset (µs)")
    ax.set_ylabel("contact force (N)")
    ax.legend()
    return ax


def plot_channel(result: Result, channel: str, *, ax: Axes | None = None, reference: Result | None = None,
                 label: str | None = None, window: Window = None, max_points: int | None = None,
                 title: str | bool | None = None, **line_kw: Any) -> Axes:
    """A channel against time, with the same channel of a reference run (e.g. the ideal joint) dashed.

    Parameters
    ----------
    result : Result
        The run.
    channel : str
        Channel (or state) name.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    reference : Result, optional
        Drawn first, black dashed, over the same window.
    label : str, optional
        Legend label of the run (default its scene name).
    window : (t0, t1), optional
        Time window in s; only output times inside it are drawn.
    max_points : int, optional
        Draw at most this many points per line, keeping the lowest and highest value of each
        stretch (min-max decimation): peaks survive, a long run does not fill the axes.
    title : str or bool, optional
        Axes title: True for the run's caption (clearance, speed, law, restitution, friction),
        a str for that text, False for none; None gives the caption only on a new figure.
    **line_kw
        Passed to ``ax.plot`` for the run's line.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[0]`` is the reference when given, then the run.
    """
    created = ax is None
    ax = _axes(ax)
    unit = result.units.get(channel, "")
    if reference is not None:
        ax.plot(*_series(reference, channel, window, max_points), "k--", lw=0.8, label="ideal joint")
    ax.plot(*_series(result, channel, window, max_points), lw=0.9, label=label or result.scene_name, **line_kw)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(style.quantity_label(channel, unit))
    if reference is not None:
        ax.legend(loc="best", fontsize="small")
    _title(ax, result, title, created)
    return ax


RESPONSE_CHANNELS = ("slider.vx", "slider.ax", "drive.moment")


def _response_panels(result: Result, reference: Result | None, axes: Any, window: Window = None,
                     max_points: int | None = None) -> None:
    """Panels (a)-(c) of Figs. 4.15 and 4.28: slider velocity, acceleration, crank moment."""
    titles = ("(a) slider velocity", "(b) slider acceleration", "(c) crank moment")
    for ax, name, title in zip(axes, RESPONSE_CHANNELS, titles):
        plot_channel(result, name, ax=ax, reference=reference, label="clearance joint", window=window,
                     max_points=max_points, title=title)


def save_response_figure(result: Result, path: Any, *, reference: Result | None = None,
                         channels: Iterable[str] = RESPONSE_CHANNELS, window: Window = None,
                         max_points: int | None = None, title: str | bool = True) -> Any:
    """Write a figure of slider velocity, acceleration and driving moment (Fig. 4.15a-c) to ``path``.

    Channels missing from the result are skipped; ``window`` and ``max_points`` as in
    :func:`plot_channel`; titled with the run's caption (scene, clearance, speed, law,
    restitution, friction) unless ``title`` is False or a text. Returns the path written.
    """
    import matplotlib.pyplot as plt

    names = [c for c in channels if c in result]
    fig, axes = plt.subplots(len(names), 1, figsize=(7.0, 2.2 * len(names) + 0.6), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        plot_channel(result, name, ax=ax, reference=reference, window=window, max_points=max_points, title=False)
        if ax is not axes[-1, 0]:
            ax.set_xlabel("")
    _title(fig, result, title, True)
    fig.tight_layout()
    return save_figure(fig, path)


def save_figure(fig: Any, path: Any, dpi: int = 120) -> Any:
    """Write ``fig`` to ``path`` whole or not at all (a temporary file renamed into place), close
    it, and return the path."""
    import matplotlib.pyplot as plt
    from pathlib import Path

    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    tmp.replace(path)
    return path


# --------------------------------------------------------------------------- revolute clearance joint (section 4.4)

_LENGTH_SCALE = {"m": 1.0, "mm": 1e3, "um": 1e6}
_LENGTH_LABEL = {"m": "m", "mm": "mm", "um": "µm"}


def _contact_intervals(result: Result, pair: str | None = None) -> list[tuple[float, float]]:
    """Time intervals [t_onset, t_separation] in which ``pair`` (every pair when None) is in contact.

    Built from ``result.events``. A result that starts in contact (its first event of the
    pair is a separation, or, without events, its first segment has the pair in contact)
    gets an interval from ``result.t[0]``; one that ends in contact, an interval up to
    ``result.t[-1]``.
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


def _clearance_of(result: Result, joint: str) -> float | None:
    """Radial clearance (m) of clearance joint ``joint`` from the result's scene parameters."""
    element = result.parameters.get("scene", {}).get("elements", {}).get(joint, {})
    value = element.get("clearance") if isinstance(element, dict) else None
    return float(value) if isinstance(value, (int, float)) else None


def plot_journal_orbit(result: Result, joint: str = "clearance", *, ax: Axes | None = None, markers: bool = True,
                       clearance: float | None = None, unit: str = "um", window: Window = None,
                       max_points: int | None = None, title: str | bool | None = None, **line_kw: Any) -> Axes:
    """Journal centre relative to the bearing centre, with the clearance circle (Figs. 4.15d, 4.17, 4.20, 4.24).

    Parameters
    ----------
    result : Result
        A run with the channels ``<joint>.ex`` and ``<joint>.ey`` (eccentricity vector
        e = r_journal - r_bearing, eq. 4.1).
    joint : str
        Name of the revolute clearance joint (``"clearance"`` in ``slider_crank``).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    markers : bool
        Put a marker on every output point. For one marker per IDA step, as in the
        chapter, pass a result simulated without ``t_eval`` (its output times are
        the steps): the markers crowd where the steps are small (contact) and thin out
        in free flight. Points outside the circle show the penetration.
    clearance : float, optional
        Radial clearance c (m) of the dashed circle; read from the result's scene
        parameters when None (no circle if it cannot be found).
    unit : {"um", "mm", "m"}
        Length unit of both axes.
    window : (t0, t1), optional
        Time window in s; only the orbit inside it is drawn.
    max_points : int, optional
        Draw at most this many points, evenly spaced in the output times.
    title : str or bool, optional
        As in :func:`plot_channel` (the run's caption on a new figure).
    **line_kw
        Passed to ``ax.plot`` for the orbit.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[0]`` is the orbit (x: e_x, y: e_y in ``unit``), ``ax.lines[1]`` the
        clearance circle |e| = c (dashed), when drawn. Equal aspect ratio.
    """
    if unit not in _LENGTH_SCALE:
        raise ValueError(f"plot_journal_orbit: unit={unit!r}, must be one of {', '.join(_LENGTH_SCALE)}.")
    import numpy as np

    created = ax is None
    ax = _axes(ax)
    scale = _LENGTH_SCALE[unit]
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0"}
    if markers:
        kw.update(marker=".", ms=2.5)
    kw.update(line_kw)
    ex, ey = _curve(result, f"{joint}.ex", f"{joint}.ey", window, max_points)
    ax.plot(ex * scale, ey * scale, **kw)
    c = clearance if clearance is not None else _clearance_of(result, joint)
    if c is not None:
        angle = np.linspace(0.0, 2.0 * np.pi, 361)
        ax.plot(c * scale * np.cos(angle), c * scale * np.sin(angle), "k--", lw=0.8)
    ax.set_aspect("equal", adjustable="datalim")
    label = _LENGTH_LABEL[unit]
    ax.set_xlabel(f"journal x rel. to bearing ({label})")
    ax.set_ylabel(f"journal y rel. to bearing ({label})")
    _title(ax, result, title, created)
    return ax


def plot_phase_portrait(result: Result, x: str = "slider.vx", y: str = "slider.ax", *, ax: Axes | None = None,
                        reference: Result | None = None, window: Window = None, max_points: int | None = None,
                        title: str | bool | None = None, **line_kw: Any) -> Axes:
    """One channel against another over the whole result (Figs. 4.18, 4.21: slider acceleration against velocity).

    The chapter calls these plots Poincaré maps: a closed curve traced again and again
    is a periodic response, a band filled by curves that never repeat a chaotic one.

    Parameters
    ----------
    result : Result
        The run; a dense ``t_eval`` gives a smooth curve.
    x, y : str
        Channel names (default slider velocity on x, slider acceleration on y).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    reference : Result, optional
        Drawn first, black dashed (e.g. the ideal joint, whose portrait is one closed curve).
    window : (t0, t1), optional
        Time window in s (e.g. the steady state after the transient).
    max_points : int, optional
        Draw at most this many points per curve, evenly spaced in the output times.
    title : str or bool, optional
        As in :func:`plot_channel` (the run's caption on a new figure).
    **line_kw
        Passed to ``ax.plot`` for the result's curve.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[0]`` is the reference curve when given, then the result's curve.
    """
    created = ax is None
    ax = _axes(ax)
    if reference is not None:
        ax.plot(*_curve(reference, x, y, window, max_points), "k--", lw=0.8, label="ideal joint")
    kw: dict[str, Any] = {"lw": 0.5, "color": "C0"}
    kw.update(line_kw)
    ax.plot(*_curve(result, x, y, window, max_points), **kw)
    for axis_label, name in ((ax.set_xlabel, x), (ax.set_ylabel, y)):
        axis_label(style.quantity_label(name, result.units.get(name, "")))
    _title(ax, result, title, created)
    return ax


def plot_step_sizes(result: Result, *, ax: Axes | None = None, pair: str | None = None, shade: bool = True,
                    window: Window = None, max_points: int | None = None, title: str | bool | None = None,
                    **line_kw: Any) -> Axes:
    """IDA's step size against time, log scale, contact intervals shaded (section 4.4, Figs. 4.15d, 4.24).

    Parameters
    ----------
    result : Result
        A run with recorded steps (``result.step_t``, ``result.step_h``; ``simulate``
        records them by default, whatever ``t_eval``).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    pair : str, optional
        Contact pair whose contact intervals are shaded (every pair when None).
    shade : bool
        Shade the contact intervals (from ``result.events``) in grey.
    window : (t0, t1), optional
        Time window in s: steps reaching a time inside it are drawn, contact intervals are
        clipped to it.
    max_points : int, optional
        Draw at most this many steps (min-max decimation of the step size).
    title : str or bool, optional
        As in :func:`plot_channel` (the run's caption on a new figure).
    **line_kw
        Passed to ``ax.plot`` for the step sizes.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[0]``: step size h (s) against the time reached by the step (s); the
        zero-size placeholder of the initial point is left out. One patch per contact
        interval.

    Raises
    ------
    ValueError
        If the result has no recorded steps.
    """
    import numpy as np

    if result.step_t is None or result.step_h is None:
        raise ValueError(f"plot_step_sizes: result of scene {result.scene_name!r} has no recorded steps "
                         f"(simulate(..., store_steps=True) records them).")
    created = ax is None
    ax = _axes(ax)
    h = np.asarray(result.step_h)
    t = np.asarray(result.step_t)
    inside = style.window_index(t, window)
    index = style.decimate(h, max_points, inside[h[inside] > 0])
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0", "marker": ".", "ms": 1.5}
    kw.update(line_kw)
    ax.plot(t[index], h[index], **kw)
    ax.set_yscale("log")
    if shade:
        lo, hi = (None, None) if window is None else window
        lo = -np.inf if lo is None else float(lo)
        hi = np.inf if hi is None else float(hi)
        spans = [(max(a, lo), min(b, hi)) for a, b in _contact_intervals(result, pair) if b >= lo and a <= hi]
        for k, (t0, t1) in enumerate(spans):
            ax.axvspan(t0, t1, color="0.85", lw=0, zorder=0, label="contact" if k == 0 else None)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("IDA step size (s)")
    _title(ax, result, title, created)
    return ax


def plot_cases(results: Mapping[str, Result], draw: Any, *, ncols: int = 2, sharex: bool = False,
               sharey: bool = False, panel_size: tuple[float, float] = (3.8, 2.9), suptitle: str | None = None,
               **kwargs: Any) -> Any:
    """One panel per labelled result, each drawn by a figure function (Figs. 4.16-4.25).

    Parameters
    ----------
    results : mapping of str to Result
        Panel title -> result, in panel order; titles get the chapter's "(a)", "(b)", ...
    draw : callable
        A figure function called as ``draw(result, ax=ax, **kwargs)``, e.g.
        ``plot_journal_orbit``, ``plot_phase_portrait``, ``plot_step_sizes`` or
        ``functools.partial(plot_channel, channel="drive.moment")``.
    ncols : int
        Panels per row.
    sharex, sharey : bool
        Share axes between panels (as ``plt.subplots``).
    panel_size : (float, float)
        Width and height of one panel, inches.
    suptitle : str, optional
        Figure title.
    **kwargs
        Passed to every ``draw`` call (e.g. ``reference=ideal``, ``window=(t0, t1)``,
        ``max_points=4000``).

    Returns
    -------
    matplotlib.figure.Figure
        Its first ``len(results)`` axes hold the panels; unused grid cells are hidden.
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
    if suptitle:
        style.set_title(fig, suptitle)
    fig.tight_layout()
    return fig


def plot_revolute_response(result: Result, *, reference: Result | None = None, orbit: Result | None = None,
                           joint: str = "clearance", window: Window = None, max_points: int | None = None,
                           title: str | bool = True) -> Any:
    """Fig. 4.15 in four panels: slider velocity, slider acceleration, crank moment, journal orbit.

    Parameters
    ----------
    result : Result
        The clearance-joint run (a dense ``t_eval`` for panels a-c).
    reference : Result, optional
        The ideal-joint run over the same times, dashed in panels a-c.
    orbit : Result, optional
        Run whose output times are IDA's steps (``t_eval=None``), for panel d's
        one-marker-per-step orbit; ``result`` when None.
    joint : str
        Name of the revolute clearance joint.
    window : (t0, t1), optional
        Time window in s of every panel.
    max_points : int, optional
        At most this many points per line (min-max decimation in panels a-c, even spacing
        in the orbit).
    title : str or bool
        Figure title: True for the run's caption (clearance, speed, law, restitution,
        friction), a str for that text, False for none.

    Returns
    -------
    matplotlib.figure.Figure
        Axes in order (a) ``slider.vx``, (b) ``slider.ax``, (c) ``drive.moment``, (d) orbit.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10.0, 7.0))
    (a, b), (c, d) = axes
    _response_panels(result, reference, (a, b, c), window, max_points)
    plot_journal_orbit(orbit if orbit is not None else result, joint, ax=d, window=window, max_points=max_points,
                       title="(d) journal trajectory relative to the bearing")
    _title(fig, result, title, True)
    fig.tight_layout()
    return fig


__all__ += ["plot_cases", "plot_journal_orbit", "plot_phase_portrait", "plot_revolute_response", "plot_step_sizes"]


def plot_slider_path(result: Result, joint: str = "clearance", *, ax: Axes | None = None, limits: bool = True,
                     reference: Result | None = None, window: Window = None, max_points: int | None = None,
                     title: str | bool | None = None, **line_kw: Any) -> Axes:
    """Dimensionless path of the slider centre inside the guide (Figs. 4.28d, 4.30, 4.33).

    Parameters
    ----------
    result : Result
        A run with a translational clearance joint (channels ``<joint>.xi`` and
        ``<joint>.eta``: xi from 0 to 1 along the stroke, eta the offset of the slider
        centre from the guide's mid-line over 2c, +-0.5 where a parallel slider touches
        a surface). A joint without a ``stroke`` has no ``xi``: its path is drawn against
        ``<joint>.s``, the slider centre's position along the guide, in mm.
    joint : str
        Name of the translational clearance joint (``"clearance"`` in ``slider_crank``).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    limits : bool
        Draw the geometric contact limits, eta = +-0.5 (dashed): beyond them the slider
        and the guide are in contact (the chapter's horizontal lines).
    reference : Result, optional
        Drawn first, black dotted (e.g. the ideal joint: eta = 0 along the stroke).
    window : (t0, t1), optional
        Time window in s; only the path inside it is drawn.
    max_points : int, optional
        Draw at most this many points per path, evenly spaced in the output times.
    title : str or bool, optional
        As in :func:`plot_channel` (the run's caption on a new figure).
    **line_kw
        Passed to ``ax.plot`` for the path.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[0]`` is the reference path when given, then the slider path, then the
        two limit lines.
    """
    created = ax is None
    ax = _axes(ax)
    xi, eta = f"{joint}.xi", f"{joint}.eta"
    along = xi if xi in result else f"{joint}.s"  # no stroke given: the slider centre's s, in mm
    scale = 1.0 if along == xi else 1e3
    if reference is not None:
        x_ref, y_ref = _curve(reference, along, eta, window, max_points)
        ax.plot(x_ref * scale, y_ref, "k:", lw=0.8, label="ideal joint")
    kw: dict[str, Any] = {"lw": 0.6, "color": "C0"}
    kw.update(line_kw)
    x, y = _curve(result, along, eta, window, max_points)
    ax.plot(x * scale, y, **kw)
    if limits:
        for level in (0.5, -0.5):
            ax.axhline(level, color="k", ls="--", lw=0.8)
    ax.set_xlabel("ξ, slider position along the stroke (-)" if along == xi
                  else "s, slider centre along the guide (mm)")
    ax.set_ylabel("η, offset across the guide (-)")
    _title(ax, result, title, created)
    return ax


def plot_translational_response(result: Result, *, reference: Result | None = None,
                                joint: str = "clearance", window: Window = None, max_points: int | None = None,
                                title: str | bool = True) -> Any:
    """Fig. 4.28 in four panels: slider velocity, slider acceleration, crank moment, slider path.

    Parameters
    ----------
    result : Result
        The clearance-joint run (a dense ``t_eval``).
    reference : Result, optional
        The ideal-joint run over the same times, dashed in panels a-c.
    joint : str
        Name of the translational clearance joint.
    window, max_points, title
        As in :func:`plot_revolute_response`.

    Returns
    -------
    matplotlib.figure.Figure
        Axes in order (a) ``slider.vx``, (b) ``slider.ax``, (c) ``drive.moment``, (d) path.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10.0, 7.0))
    (a, b), (c, d) = axes
    _response_panels(result, reference, (a, b, c), window, max_points)
    plot_slider_path(result, joint, ax=d, window=window, max_points=max_points,
                     title="(d) dimensionless slider path inside the guide")
    _title(fig, result, title, True)
    fig.tight_layout()
    return fig


__all__ += ["plot_slider_path", "plot_translational_response"]


# --------------------------------------------------------------------------- any scene

#: Joint panels per row of :func:`plot_run` (a chain of many links gets several rows).
MAX_PANELS_PER_ROW = 4

#: Kinds of clearance joints and the panel each gets in :func:`plot_run`.
CLEARANCE_PANELS = {"RevoluteClearance": "journal orbit", "TranslationalClearance": "slider path"}


def clearance_joints(result: Result) -> dict[str, str]:
    """The clearance joints of the run's scene, in scene order: name -> kind (``RevoluteClearance``, ...)."""
    elements = result.parameters.get("scene", {}).get("elements", {})
    return {name: e["kind"] for name, e in elements.items()
            if isinstance(e, dict) and e.get("kind") in CLEARANCE_PANELS}


def default_channels(result: Result) -> tuple[str, ...]:
    """Time-plot channels chosen from what the run's scene holds.

    A body named ``slider`` gives its velocity and acceleration (Figs. 4.15a-b, 4.28a-b); every
    driver its moment (Figs. 4.15c, 4.28c); a scene without a driver the angular velocity of
    its last body and the mechanical energy; every clearance joint its contact force (the first
    four clearance joints of a larger scene). Only channels the result has are returned.
    """
    elements = result.parameters.get("scene", {}).get("elements", {})
    kinds = {name: e.get("kind") for name, e in elements.items() if isinstance(e, dict)}
    bodies = [name for name, kind in kinds.items() if kind == "Body"]
    drivers = [name for name, kind in kinds.items() if kind == "Driver"]
    names = ["slider.vx", "slider.ax"] if "slider" in bodies else []
    names += [f"{d}.moment" for d in drivers]
    if not drivers and bodies:
        names += [f"{bodies[-1]}.omega", "energy.mechanical"]
    names += [f"{joint}.normal_force" for joint in list(clearance_joints(result))[:MAX_PANELS_PER_ROW]]
    return tuple(dict.fromkeys(n for n in names if n in result))


def plot_run(result: Result, *, reference: Result | None = None, channels: Iterable[str] | None = None,
             joints: Iterable[str] | None = None, window: Window = None, max_points: int | None = None,
             title: str | bool = True) -> Any:
    """A run of any scene: time plots of its channels, then one panel per clearance joint.

    Every revolute clearance joint gets its journal orbit (:func:`plot_journal_orbit`), every
    translational one its slider path (:func:`plot_slider_path`), side by side under the time
    plots, four to a row.

    Parameters
    ----------
    result : Result
        The run.
    reference : Result, optional
        E.g. the ideal mechanism's run: dashed in the time plots (channels it lacks, such as a
        clearance joint's contact force, are drawn without it).
    channels : iterable of str, optional
        Channels plotted against time; :func:`default_channels` when None. Missing ones are skipped.
    joints : iterable of str, optional
        Clearance joints given a panel; every clearance joint of the scene when None.
    window, max_points, title
        As in :func:`plot_revolute_response`.

    Returns
    -------
    matplotlib.figure.Figure
        Axes in order: the time plots, then the joint panels.
    """
    import matplotlib.pyplot as plt

    names = [c for c in (default_channels(result) if channels is None else channels) if c in result]
    kinds = clearance_joints(result)
    panels = [j for j in (kinds if joints is None else joints)]
    unknown = [j for j in panels if j not in kinds]
    if unknown:
        raise ValueError(f"plot_run: joints={unknown!r} are not clearance joints of the run's scene "
                         f"(clearance joints: {', '.join(kinds) or 'none'}).")
    if not names and not panels:
        raise ValueError(f"plot_run: nothing to draw: none of channels={list(channels or [])!r} is in the result "
                         "and the scene has no clearance joint.")
    n_cols = max(1, min(len(panels), MAX_PANELS_PER_ROW))
    panel_rows = -(-len(panels) // n_cols)
    n_rows = len(names) + panel_rows
    heights = [1.0] * len(names) + [2.0] * panel_rows
    height = 2.2 * len(names) + 3.8 * panel_rows + 0.6
    fig = plt.figure(figsize=(max(7.0, 3.6 * n_cols), height))
    grid = fig.add_gridspec(n_rows, n_cols, height_ratios=heights)
    first = None
    for row, name in enumerate(names):
        ax = fig.add_subplot(grid[row, :], sharex=first)
        first = first or ax
        ref = reference if reference is not None and name in reference else None
        plot_channel(result, name, ax=ax, reference=ref, window=window, max_points=max_points, title=False)
        if row < len(names) - 1:
            ax.set_xlabel("")
    for k, joint in enumerate(panels):
        ax = fig.add_subplot(grid[len(names) + k // n_cols, k % n_cols])
        if kinds[joint] == "RevoluteClearance":
            plot_journal_orbit(result, joint, ax=ax, window=window, max_points=max_points, markers=False,
                               title=f"{joint}: journal orbit")
        else:
            plot_slider_path(result, joint, ax=ax, window=window, max_points=max_points,
                             title=f"{joint}: slider path")
    _title(fig, result, title, True)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.4 / height))  # 0.4 in at the top for the title
    return fig


def save_run_figure(result: Result, path: Any, **options: Any) -> Any:
    """Write :func:`plot_run`'s figure to ``path`` (whole or not at all); returns the path."""
    return save_figure(plot_run(result, **options), path)


__all__ += ["clearance_joints", "default_channels", "plot_run", "save_figure", "save_run_figure"]


def plot_work_precision(study: Any, *, ax: Axes | None = None) -> Axes:
    """Error against wall time (log-log), one line per method, failed runs marked with x at the top.

    ``study`` is a :class:`daeclear.studies.accuracy.WorkPrecision`.
    """
    import math

    ax = _axes(ax)
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
    ax.set_xlabel("wall time (s)")
    ax.set_ylabel(f"max error / range ({', '.join(study.channels)})")
    style.set_title(ax, f"error over t in [{study.window[0]:.3g}, {study.window[1]:.3g}] s")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", lw=0.3)
    return ax


# --------------------------------------------------------------------------- Poincaré sections and sweeps

MOTION_COLORS = {"periodic": "#2ca02c", "quasi-periodic": "#1f77b4", "chaotic": "#d62728",
                 "non-periodic": "#ff7f0e", "uncertain": "#9467bd", "undetermined": "#7f7f7f",
                 "failed": "#000000"}
"""Colour of each motion class (:data:`daeclear.analysis.MOTION_LABELS`) in the sweep figures."""


def _channel_label(name: str, unit: str) -> str:
    return style.quantity_label(name, unit)


def plot_poincare_section(section: Any, *, ax: Axes | None = None, portrait: Any = None, label: str | None = None,
                          **marker_kw: Any) -> Axes:
    """Stroboscopic Poincaré section (one point per crank revolution), over the phase portrait.

    Parameters
    ----------
    section : daeclear.analysis.PoincareSection
        Its first two channels are drawn (x, y); with one channel, the value against the
        revolution number.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    portrait : PhasePortrait or Result, optional
        Drawn first as a thin grey curve (the chapter's "Poincaré map"): a
        :class:`~daeclear.analysis.PhasePortrait`, or a Result whose same two channels are
        plotted from the section's first time on.
    label : str, optional
        Legend label of the points (default "once per revolution (n points)").
    **marker_kw
        Passed to ``ax.plot`` for the points.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.lines[-1]`` holds the section points.
    """
    import numpy as np

    ax = _axes(ax)
    points = np.asarray(section.points)
    if points.shape[1] >= 2 and portrait is not None:
        if hasattr(portrait, "x") and hasattr(portrait, "y"):
            px, py = portrait.x, portrait.y
        else:
            t0 = section.t[0] if len(section) else None
            mask = portrait.window_mask(t0, None)
            px = np.asarray(portrait[section.channels[0]])[mask]
            py = np.asarray(portrait[section.channels[1]])[mask]
        ax.plot(px, py, color="0.6", lw=0.4, label="phase portrait")
    kw: dict[str, Any] = {"ls": "none", "marker": "o", "ms": 3.5, "color": "C3"}
    kw.update(marker_kw)
    text = label or f"once per revolution ({len(points)} points)"
    if points.shape[1] >= 2:
        ax.plot(points[:, 0], points[:, 1], label=text, **kw)
        ax.set_xlabel(_channel_label(section.channels[0], section.units[0]))
        ax.set_ylabel(_channel_label(section.channels[1], section.units[1]))
    else:
        ax.plot(np.arange(len(points)), points[:, 0], label=text, **kw)
        ax.set_xlabel("revolution after the transient")
        ax.set_ylabel(_channel_label(section.channels[0], section.units[0]))
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
        Section channel on the y axis (name or column; default the first, slider velocity).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    scale : float, optional
        Factor applied to the parameter values (e.g. 1e3 for a clearance in mm).
    unit : str, optional
        Unit of the scaled parameter, shown in the x label. With neither `scale` nor
        `unit`, both come from :data:`daeclear.plot.style.PARAMETER_AXES` (clearance in mm,
        rpm, restitution and friction dimensionless).
    log : bool, optional
        Logarithmic x axis; None: when the parameter values form a geometric grid
        (``numpy.geomspace``, three values or more).
    color_by_motion : bool
        Colour each run's points by its motion class (:data:`MOTION_COLORS`), with a legend.
    title : str or bool, optional
        Axes title: True for the mechanism and the parameters every run shares, a str for
        that text, False for none; None gives the caption only on a new figure.
    **marker_kw
        Passed to ``ax.plot``.

    Returns
    -------
    matplotlib.axes.Axes
        One line (markers only) per motion class present, or a single one.
    """
    import numpy as np

    created = ax is None
    ax = _axes(ax)
    scale, unit = style.parameter_display(parameter, scale, unit)
    if isinstance(sweep, Mapping):
        xs, ys, labels = [], [], []
        for value, sec in sweep.items():
            col = sec.channels.index(channel) if isinstance(channel, str) else int(channel)
            xs.append(np.full(len(sec), float(value)))
            ys.append(np.asarray(sec.points)[:, col])
            labels += ["" for _ in range(len(sec))]
        x = np.concatenate(xs) if xs else np.zeros(0)
        y = np.concatenate(ys) if ys else np.zeros(0)
        name = channel if isinstance(channel, str) else next(iter(sweep.values())).channels[int(channel)]
        units = next(iter(sweep.values())).units if sweep else ()
        y_unit = units[next(iter(sweep.values())).channels.index(name)] if units else ""
        color_by_motion = False
    else:
        x, y, labels = sweep.bifurcation_data(parameter, channel)
        ok = [r for r in sweep.runs if r.ok]
        sec = sweep.section(ok[0]) if ok else None
        name = channel if isinstance(channel, str) else (sec.channels[int(channel)] if sec else str(channel))
        y_unit = sec.units[sec.channels.index(name)] if sec else ""
    kw: dict[str, Any] = {"ls": "none", "marker": ".", "ms": 3.0}
    kw.update(marker_kw)
    x = x * scale
    if color_by_motion:
        labels_arr = np.array(labels)
        for motion, color in MOTION_COLORS.items():
            sel = labels_arr == motion
            if np.any(sel):
                ax.plot(x[sel], y[sel], label=motion, **{**kw, "color": color})
        ax.legend(loc="best", fontsize="x-small", title="motion", title_fontsize="x-small")
    else:
        kw.setdefault("color", "k")
        ax.plot(x, y, **kw)
    values = list(sweep) if isinstance(sweep, Mapping) else [r.parameters.get(parameter) for r in sweep.runs]
    style.parameter_axis(ax, "x", parameter, values, unit, log)
    ax.set_ylabel(f"{_channel_label(name, y_unit)} once per revolution")
    if isinstance(title, str):
        style.set_title(ax, title)
    elif (title or (title is None and created)) and not isinstance(sweep, Mapping):
        style.set_title(ax, style.sweep_caption(sweep, exclude=(parameter,)))
    return ax


def plot_motion_map(sweep: Any, x: str, y: str, *, ax: Axes | None = None, x_scale: float | None = None,
                    y_scale: float | None = None, x_unit: str | None = None, y_unit: str | None = None,
                    x_log: bool | None = None, y_log: bool | None = None, annotate: bool = True,
                    title: str | bool | None = None) -> Axes:
    """Map of the motion class over two swept parameters (one cell per run).

    Parameters
    ----------
    sweep : daeclear.sweep.SweepResult
        A sweep over a grid of ``x`` and ``y`` (other parameters fixed).
    x, y : str
        Parameter names of the horizontal and vertical axes.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    x_scale, y_scale : float, optional
        Factors applied to the parameter values (e.g. 1e3 for mm).
    x_unit, y_unit : str, optional
        Units of the scaled values, in the axis labels. Without scale and unit, both come
        from :data:`daeclear.plot.style.PARAMETER_AXES`.
    x_log, y_log : bool, optional
        Logarithmic axis (cells centred on the values, edges at geometric midpoints);
        None: when the values of that axis form a geometric grid (three or more).
    annotate : bool
        Write the period k in periodic cells ("P1", "P2", ...), "C" chaotic, "Q"
        quasi-periodic, "N" non-periodic, "U" uncertain, "?" undetermined, "x" failed.
    title : str or bool, optional
        As in :func:`plot_bifurcation` (the parameters every run shares).

    Returns
    -------
    matplotlib.axes.Axes
        Cells coloured by :data:`MOTION_COLORS`, ticks labelled with the values; on an index
        grid, or on the values themselves along a log axis; one legend entry per class present.

    Raises
    ------
    ValueError
        If two runs share the same (x, y) cell.
    """
    import numpy as np
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    created = ax is None
    ax = _axes(ax)
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
    cmap = ListedColormap([MOTION_COLORS[c] for c in classes])

    def positive(values: list[Any]) -> bool:  # a log axis needs numbers > 0 only
        return bool(values) and all(key(v)[0] == 0 and float(v) > 0 for v in values)

    x_log = style.is_geometric(xs) if x_log is None else bool(x_log) and positive(xs)
    y_log = style.is_geometric(ys) if y_log is None else bool(y_log) and positive(ys)
    x_centres, x_edges = _cells(xs, x_scale, x_log)
    y_centres, y_edges = _cells(ys, y_scale, y_log)
    ax.pcolormesh(x_edges, y_edges, np.ma.masked_invalid(grid), cmap=cmap,
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
    ax.set_xlim(x_edges[0], x_edges[-1])
    ax.set_ylim(y_edges[0], y_edges[-1])
    ax.set_xlabel(style.parameter_label(x, x_unit))
    ax.set_ylabel(style.parameter_label(y, y_unit))
    if isinstance(title, str):
        style.set_title(ax, title)
    elif title or (title is None and created):
        style.set_title(ax, style.sweep_caption(sweep, exclude=(x, y)))
    present = sorted({int(v) for v in grid[np.isfinite(grid)]})
    ax.legend(handles=[Patch(color=MOTION_COLORS[classes[k]], label=classes[k]) for k in present],
              loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="x-small", title="motion",
              title_fontsize="x-small")
    return ax


def _cells(values: list[Any], scale: float, log: bool) -> tuple[Any, Any]:
    """Cell centres and edges of one motion-map axis: an index grid, or the scaled values on a log axis
    (edges at the geometric midpoints, the outer cells as wide as their neighbours in ratio)."""
    import numpy as np

    if not log:
        return np.arange(len(values), dtype=float), np.arange(len(values) + 1) - 0.5
    centres = np.array([float(v) * scale for v in values])
    if centres.size == 1:
        return centres, centres * np.array([10 ** -0.5, 10 ** 0.5])
    inner = np.sqrt(centres[1:] * centres[:-1])
    first = centres[0] ** 2 / inner[0]
    last = centres[-1] ** 2 / inner[-1]
    return centres, np.concatenate([[first], inner, [last]])


__all__ += ["MOTION_COLORS", "plot_bifurcation", "plot_motion_map", "plot_poincare_section"]
