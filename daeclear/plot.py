"""Figure functions of daeclear (matplotlib).

Each function takes data and an optional ``ax``, draws on it (a new figure when
``ax`` is None) and returns the Axes; none calls ``plt.show()``. Units on the axes are
stated in the labels.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from typing import TypeAlias

    from matplotlib.axes import Axes

    from .contact.impact import ImpactResult
    from .result import Result

    Impacts: TypeAlias = ImpactResult | Iterable[ImpactResult] | Mapping[str, ImpactResult]

__all__ = ["plot_channel", "plot_force_penetration", "plot_force_time", "save_response_figure"]


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure().add_subplot()


def _label(impact: ImpactResult) -> str:
    law = impact.law
    restitution = getattr(law, "restitution", None)
    return law.name if restitution is None else f"{law.name}, $c_e$ = {restitution:g}"


def _labelled(impacts: Impacts) -> list[tuple[str, ImpactResult]]:
    from .contact.impact import ImpactResult

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
                 label: str | None = None, **line_kw: Any) -> Axes:
    """A channel against time, with the same channel of a reference run (e.g. the ideal joint) dashed."""
    ax = _axes(ax)
    unit = result.units.get(channel, "")
    if reference is not None:
        ax.plot(reference.t, reference[channel], "k--", lw=0.8, label="ideal joint")
    ax.plot(result.t, result[channel], lw=0.9, label=label or result.scene_name, **line_kw)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{channel} ({unit})" if unit else channel)
    if reference is not None:
        ax.legend(loc="best", fontsize="small")
    return ax


RESPONSE_CHANNELS = ("slider.vx", "slider.ax", "drive.moment")


def save_response_figure(result: Result, path: Any, *, reference: Result | None = None,
                         channels: Iterable[str] = RESPONSE_CHANNELS) -> Any:
    """Write a figure of slider velocity, acceleration and driving moment (Fig. 4.15a-c) to ``path``.

    Channels missing from the result are skipped; returns the path written.
    """
    import matplotlib.pyplot as plt
    from pathlib import Path

    names = [c for c in channels if c in result]
    fig, axes = plt.subplots(len(names), 1, figsize=(7.0, 2.2 * len(names) + 0.6), sharex=True, squeeze=False)
    for ax, name in zip(axes[:, 0], names):
        plot_channel(result, name, ax=ax, reference=reference)
        if ax is not axes[-1, 0]:
            ax.set_xlabel("")
    status = "" if result.success else "  (FAILED: partial result)"
    fig.suptitle(f"{result.scene_name}{status}", fontsize="medium")
    fig.tight_layout()
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=120)
    plt.close(fig)
    tmp.replace(path)
    return path
