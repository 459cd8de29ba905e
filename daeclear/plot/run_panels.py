"""Panels of one run over time: a channel, the impact force curves, the response figure, and saving.

The building blocks every other figure module draws with (:func:`plot_channel`, the run title,
x-y curves of two channels) and :func:`save_figure`; separate so the joint, study and overview
figures share them without importing each other.

Each function takes data and an optional ``ax``, draws on it (a new figure when
``ax`` is None) and returns the Axes; none calls ``plt.show()``. Units on the axes are
stated in the labels. Figures of a run are titled with its parameters (clearance, crank speed,
contact law, restitution, friction; ``title=``); functions that draw a run over time take a time
``window=(t0, t1)`` and ``max_points`` (min-max decimation, so a long run does not plot as a
solid band).
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

__all__ = ["RESPONSE_CHANNELS", "Window", "plot_channel", "plot_force_penetration", "plot_force_time",
           "response_panels", "save_figure", "save_response_figure", "set_run_title", "xy_curve"]

Window = tuple[float | None, float | None] | None
"""A closed time window ``(t0, t1)`` in s; None (or a None side) leaves it open."""


def _axes(ax: Axes | None) -> Axes:
    return style.new_axes(ax)


def set_run_title(target: Any, result: Result, title: str | bool | None, created: bool) -> None:
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


def xy_curve(result: Result, x: str, y: str, window: Window, max_points: int | None) -> tuple[Any, Any]:
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
    set_run_title(ax, result, title, created)
    return ax


RESPONSE_CHANNELS = ("slider.vx", "slider.ax", "drive.moment")


def response_panels(result: Result, reference: Result | None, axes: Any, window: Window = None,
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
    set_run_title(fig, result, title, True)
    fig.tight_layout()
    return save_figure(fig, path)


def save_figure(fig: Any, path: Any, dpi: int = 120) -> Any:
    """Write ``fig`` to ``path`` whole or not at all (:func:`daeclear.results.outputs.atomic_file`),
    close it, and return the path."""
    import matplotlib.pyplot as plt
    from pathlib import Path

    from ..results.outputs import atomic_file

    path = Path(path)
    try:
        with atomic_file(path, keep_suffix=True) as tmp:  # savefig reads the format from the suffix
            fig.savefig(tmp, dpi=dpi)
    finally:
        plt.close(fig)
    return path
