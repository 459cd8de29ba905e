"""The overview figure of any run (:func:`plot_run`), and the home of every figure function.

The others are drawn in :mod:`.run_panels`, :mod:`.joint_figures` and :mod:`.study_figures` and
re-exported here. Each takes data and an optional ``ax`` (a new figure when None), returns the Axes
and never calls ``plt.show()``; the style (captions, windows, decimation) is :mod:`daeclear.plot.style`.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from . import style
from .joint_figures import (plot_cases, plot_journal_orbit, plot_phase_portrait, plot_revolute_response,
                            plot_slider_path, plot_step_sizes, plot_translational_response)
from .run_panels import (RESPONSE_CHANNELS, Window, plot_channel, plot_force_penetration, plot_force_time,
                         save_figure, save_response_figure, set_run_title)
from .sensitivity_figures import plot_sensitivities, plot_sensitivity_horizon, save_sensitivity_figure
from .study_figures import (MOTION_COLORS, plot_bifurcation, plot_motion_map, plot_poincare_section,
                            plot_work_precision)

if TYPE_CHECKING:
    from ..results.result import Result

__all__ = ["CLEARANCE_PANELS", "MAX_PANELS_PER_ROW", "MOTION_COLORS", "RESPONSE_CHANNELS", "Window", "clearance_joints",
           "default_channels", "plot_bifurcation", "plot_cases", "plot_channel", "plot_force_penetration",
           "plot_force_time", "plot_journal_orbit", "plot_motion_map", "plot_phase_portrait", "plot_poincare_section",
           "plot_revolute_response", "plot_run", "plot_sensitivities", "plot_sensitivity_horizon", "plot_slider_path",
           "plot_step_sizes", "plot_translational_response", "plot_work_precision", "save_figure",
           "save_response_figure", "save_run_figure", "save_sensitivity_figure"]

#: Joint panels per row of :func:`plot_run` (a chain of many links gets several rows).
MAX_PANELS_PER_ROW = 4

#: Kinds of clearance joints and the panel each gets in :func:`plot_run`.
CLEARANCE_PANELS = {"RevoluteClearance": "journal orbit", "TranslationalClearance": "slider path"}


def clearance_joints(result: Result) -> dict[str, str]:
    """The clearance joints of the run's scene, in scene order: name -> kind (``RevoluteClearance``, ...)."""
    elements = style.scene_elements(result)
    return {name: e["kind"] for name, e in elements.items()
            if isinstance(e, dict) and e.get("kind") in CLEARANCE_PANELS}


def default_channels(result: Result) -> tuple[str, ...]:
    """Time-plot channels chosen from the run's scene, those the result has: a body ``slider``'s velocity and
    acceleration (Figs. 4.15a-b, 4.28a-b), every driver's moment (no driver: the last body's angular velocity
    and the mechanical energy), the contact force of the first four clearance joints (a lubricated one: its
    film force, its dry contact force and its eccentricity ratio).
    """
    elements = style.scene_elements(result)
    kinds = {name: e.get("kind") for name, e in elements.items() if isinstance(e, dict)}
    bodies = [name for name, kind in kinds.items() if kind == "Body"]
    drivers = [name for name, kind in kinds.items() if kind == "Driver"]
    names = ["slider.vx", "slider.ax"] if "slider" in bodies else []
    names += [f"{d}.moment" for d in drivers]
    if not drivers and bodies:
        names += [f"{bodies[-1]}.omega", "energy.mechanical"]
    for joint in list(clearance_joints(result))[:MAX_PANELS_PER_ROW]:  # a lubricated one: its film too
        names += [f"{joint}.film_radial", f"{joint}.normal_force", f"{joint}.eccentricity_ratio"]
    return tuple(dict.fromkeys(n for n in names if n in result))


def plot_run(result: Result, *, reference: Result | None = None, channels: Iterable[str] | None = None,
             joints: Iterable[str] | None = None, window: Window = None, max_points: int | None = None,
             title: str | bool = True) -> Any:
    """A run of any scene: time plots of its channels, then one panel per clearance joint.

    A revolute clearance joint gets its journal orbit, a translational one its slider path, four to a row
    under the time plots. ``reference`` (e.g. the ideal mechanism's run) is dashed in the time plots that
    have its channel; ``channels`` default to :func:`default_channels` (missing ones skipped), ``joints`` to
    every clearance joint; ``window``, ``max_points`` and ``title`` as in :func:`plot_revolute_response`.
    Returns the Figure: the time plots' axes, then the joint panels'.
    """
    import matplotlib.pyplot as plt

    names = [c for c in (default_channels(result) if channels is None else channels) if c in result]
    kinds = clearance_joints(result)
    panels = list(kinds if joints is None else joints)
    unknown = [j for j in panels if j not in kinds]
    if unknown:
        raise ValueError(f"plot_run: joints={unknown!r} are not clearance joints of the run's scene "
                         f"(clearance joints: {', '.join(kinds) or 'none'}).")
    if not names and not panels:
        raise ValueError(f"plot_run: nothing to draw: none of channels={list(channels or [])!r} is in the result "
                         "and the scene has no clearance joint.")
    n_cols = max(1, min(len(panels), MAX_PANELS_PER_ROW))
    panel_rows = -(-len(panels) // n_cols)
    height = 2.2 * len(names) + 3.8 * panel_rows + 0.6
    fig = plt.figure(figsize=(max(7.0, 3.6 * n_cols), height))
    grid = fig.add_gridspec(len(names) + panel_rows, n_cols, height_ratios=[1.0] * len(names) + [2.0] * panel_rows)
    first = None
    steady_from = start_transient(result, window)
    for row, name in enumerate(names):
        ax = fig.add_subplot(grid[row, :], sharex=first)
        first = first or ax
        ref = reference if reference is not None and name in reference else None
        accelerating = name.rsplit(".", 1)[-1] in ACCELERATIONS  # their start spike would flatten the panel
        plot_channel(result, name, ax=ax, reference=ref, window=window, max_points=max_points, title=False,
                     steady_from=steady_from if accelerating else None)
        if row < len(names) - 1:
            ax.set_xlabel("")
    beside: tuple[Any, Any] | None = None  # a single orbit's legend goes into the room beside it
    for k, joint in enumerate(panels):
        cell = grid[len(names) + k // n_cols, k % n_cols]
        if kinds[joint] == "RevoluteClearance" and n_cols == 1:
            halves = cell.subgridspec(1, 2, width_ratios=(1.15, 1.0))
            beside = (fig.add_subplot(halves[0, 0]), halves[0, 1])
            plot_journal_orbit(result, joint, ax=beside[0], window=window, max_points=max_points, markers=False,
                               title=f"{joint}: journal orbit", legend="none")
            continue
        ax = fig.add_subplot(cell)
        if kinds[joint] == "RevoluteClearance":
            plot_journal_orbit(result, joint, ax=ax, window=window, max_points=max_points, markers=False,
                               title=f"{joint}: journal orbit")
        else:
            plot_slider_path(result, joint, ax=ax, window=window, max_points=max_points,
                             title=f"{joint}: slider path")
    set_run_title(fig, result, title, True)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 1.0 - 0.4 / height))  # 0.4 in at the top for the title
    if beside is not None and beside[0].get_legend_handles_labels()[0]:
        box = beside[1].get_position(fig)
        fig.legend(*beside[0].get_legend_handles_labels(), loc="center left", fontsize="small", frameon=False,
                   bbox_to_anchor=(box.x0, 0.5 * (box.y0 + box.y1)))
    return fig


#: The channels whose time plot :func:`plot_run` fits to the steady range (accelerations: the first impact of a
#: journal started centred is several times any later one).
ACCELERATIONS = ("ax", "ay", "alpha")
#: The start transient of :func:`plot_run`'s time plots: this fraction of the run (their y axes fit what follows).
START_TRANSIENT = 0.05


def start_transient(result: Result, window: Window) -> float | None:
    """The end of the start transient when the window shows the run's start (None otherwise)."""
    if result.n_times < 2:
        return None
    t0, t1 = float(result.t[0]), float(result.t[-1])
    if window is not None and window[0] is not None and window[0] > t0:
        return None
    return t0 + START_TRANSIENT * (t1 - t0)


def save_run_figure(result: Result, path: Any, **options: Any) -> Any:
    """Write :func:`plot_run`'s figure to ``path`` (whole or not at all); returns the path."""
    return save_figure(plot_run(result, **options), path)
