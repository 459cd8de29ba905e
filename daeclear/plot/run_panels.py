"""Panels of one run over time (a channel, impact force curves, the response figure) and :func:`save_figure`:
the building blocks the joint, study and overview figures share.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

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


def set_run_title(target: Any, result: Result, title: str | bool | None, created: bool) -> None:
    """Title ``target`` (Axes or Figure): a str as given; the run's caption when True, or None and ``created``."""
    if isinstance(title, str):
        style.set_title(target, title)
    elif title or (title is None and created):
        style.set_title(target, style.caption(result))


def _series(result: Result, name: str, window: Window, max_points: int | None) -> tuple[Any, Any]:
    """Time and values of a channel inside ``window``, min-max decimated to ``max_points``."""
    values = np.asarray(result[name])
    index = style.select_times(result.t, values, window=window, max_points=max_points)
    return np.asarray(result.t)[index], values[index]


def xy_curve(result: Result, x: str, y: str, window: Window, max_points: int | None) -> tuple[Any, Any]:
    """Two channels of an x-y curve inside ``window``, evenly thinned to ``max_points``."""
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


def _force_against(impacts: Impacts, ax: Axes | None, x: str, x_label: str, line_kw: Any) -> Axes:
    """Contact force of each impact against ``impact.<x>`` (in millionths), labelled."""
    ax = style.new_axes(ax)
    for label, impact in _labelled(impacts):
        ax.plot(getattr(impact, x) * 1e6, impact.force, label=label, **line_kw)
    ax.set(xlabel=x_label, ylabel="contact force (N)")
    ax.legend()
    return ax


def plot_force_penetration(impacts: Impacts, *, ax: Axes | None = None, **line_kw: Any) -> Axes:
    """Contact force against penetration for single impacts (hysteresis loops, Fig. 4.26b).

    ``impacts``: ImpactResults of :func:`daeclear.contact.simulate_impact` (one, several, or a mapping
    label -> impact; unlabelled ones are labelled by law and restitution), drawn on ``ax`` (a new figure when
    None) with ``**line_kw``. Returns the Axes: penetration in µm on x, force in N on y; a loop's area is
    the energy lost in the impact.
    """
    return _force_against(impacts, ax, "penetration", "penetration (µm)", line_kw)


def plot_force_time(impacts: Impacts, *, ax: Axes | None = None, **line_kw: Any) -> Axes:
    """Contact force against time since first contact, µs, for single impacts (Fig. 4.26a).

    ``impacts``, ``ax`` and ``line_kw`` as in :func:`plot_force_penetration`; returns the Axes.
    """
    return _force_against(impacts, ax, "t", "time since contact onset (µs)", line_kw)


#: An extreme of the start transient counts as off the steady scale when it lies further than this many
#: steady spans beyond the steady range (:func:`plot_channel`'s ``steady_from``).
OFF_SCALE = 0.5


def plot_channel(result: Result, channel: str, *, ax: Axes | None = None, reference: Result | None = None,
                 label: str | None = None, window: Window = None, max_points: int | None = None,
                 title: str | bool | None = None, steady_from: float | None = None, **line_kw: Any) -> Axes:
    """A channel against time, with the same channel of a reference run (e.g. the ideal joint) dashed.

    Parameters
    ----------
    result : Result
        The run.
    channel : str
        Channel (or state) name.
    reference : Result, optional
        Drawn first (``ax.lines[0]``), black dashed, over the same window.
    label : str, optional
        Legend label of the run (default its scene name).
    window : (t0, t1), optional
        Time window in s.
    max_points : int, optional
        At most this many points per line, min-max decimated (peaks survive).
    title : str or bool, optional
        True: the run's caption (clearance, speed, law, restitution, friction); a str: that text;
        False: none; None: the caption only on a new figure.
    steady_from : float, optional
        The end of the start transient, s: the y axis fits the values from then on, and an extreme of the
        transient further than ``OFF_SCALE`` steady spans beyond them is left off the scale and annotated
        with its value and time at the panel's edge (e.g. the first impact of a journal started centred).

    Drawn on ``ax`` (a new figure when None), ``**line_kw`` passed to ``ax.plot`` for the run's line;
    returns the Axes.
    """
    created = ax is None
    ax = style.new_axes(ax)
    unit = result.units.get(channel, "")
    if reference is not None:
        ax.plot(*_series(reference, channel, window, max_points), "k--", lw=0.8, label="ideal joint")
    t, values = _series(result, channel, window, max_points)
    ax.plot(t, values, lw=0.9, label=label or result.scene_name, **line_kw)
    ax.set(xlabel="time (s)", ylabel=style.quantity_label(channel, unit))
    if steady_from is not None:
        _fit_steady(ax, np.asarray(t), np.asarray(values), steady_from, unit)
    if reference is not None:
        ax.legend(loc="best", fontsize="small")
    set_run_title(ax, result, title, created)
    return ax


def _fit_steady(ax: Axes, t: Any, values: Any, steady_from: float, unit: str) -> None:
    """Fit the y axis to the values from ``steady_from`` on, an extreme of the start off that scale annotated."""
    late = t >= steady_from
    if values.ndim != 1 or late.sum() < 2 or late.all():
        return
    lo, hi = float(np.min(values[late])), float(np.max(values[late]))
    span = hi - lo
    early = values[~late]
    below = span > 0 and float(np.min(early)) < lo - OFF_SCALE * span
    above = span > 0 and float(np.max(early)) > hi + OFF_SCALE * span
    if not (below or above):
        return
    bottom = lo if below else min(lo, float(np.min(early)))
    top = hi if above else max(hi, float(np.max(early)))
    margin = 0.08 * (top - bottom)
    ax.set_ylim(bottom - margin, top + margin)
    for off, pick, edge in ((below, np.argmin, bottom - margin), (above, np.argmax, top + margin)):
        if off:
            k = int(pick(early))
            at = float(t[~late][k])
            text = f"start: {float(early[k]):.3g} {unit} at t = {at * 1e3:.3g} ms, off scale".replace("  ", " ")
            ax.annotate(text, xy=(at, edge), xytext=(0.08, 0.1 if edge < lo else 0.9), textcoords="axes fraction",
                        va="center", fontsize="x-small", color="C3", zorder=5,
                        bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "C3", "lw": 0.5, "alpha": 0.9},
                        arrowprops={"arrowstyle": "->", "color": "C3", "lw": 0.8})


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
    """Write a figure of slider velocity, acceleration and driving moment (Fig. 4.15a-c) to ``path``; returns it.

    Missing channels are skipped; ``window``, ``max_points`` and ``title`` as in :func:`plot_channel`.
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
