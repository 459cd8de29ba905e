"""Joint wear over many cycles: a run's contact history, and the cycle scheme that grows the profile.

:func:`wear_history` gives the contact history of a revolute clearance joint
(:class:`daeclear.contact.wear.WearHistoryArrays`), which :func:`daeclear.contact.wear.wear_increment`
spreads over the worn profile; :func:`simulate_wear` runs the mechanism block by block, each block's
wear put into the joint's profile for the next block (Mukras et al. 2010) as new run-time numbers.
"""

from __future__ import annotations

import contextlib
import math
import os
import time
import warnings
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..assembly import contact_state
from ..assembly.assemble import assemble
from ..assembly.dae_model import DAEModel
from ..contact.geometry import sigma_sum
from ..contact.wear import MAX_DEPTH_FRACTION, ArchardWear, WearHistoryArrays, wear_increment, worn_volume
from ..core.errors import AssemblyError, DaeclearError, Interrupted, PhysicsWarning, SceneError, SolveError
from ..model.scene import RevoluteClearance, Scene
from ..core import options as opts
from ..core.progress import Progress
from ..results.outputs import check_file
from ..core.values import to_plain
from ..results.channel_eval import RunChannels
from ..results.result import Result
from ..solvers import driver
from ..solvers.base import DrivenSolver
from ..solvers.driver import Continuation
from ..solvers.registry import solver_class
from ..solvers.save_at import save_value
from ..solvers.solver_options import SolverOptions
from ..solvers.dispatch import simulate
from .poincare import crank_period
from .wear_file import WearFile, WearRow




#: The worn joint's generated channels the wear update reads (``<joint>.<name>``): functions of the
#: positions and velocities alone, read from a run's stored rows (:class:`RunChannels`).
HISTORY_CHANNELS = ("normal_force", "bearing_angle", "journal_angle", "sliding_velocity", "penetration")


def joint_channels(model: DAEModel, joint: str) -> RunChannels:
    """The reader of revolute clearance joint ``joint``'s contact history in runs of ``model``'s structure."""
    names = [f"{joint}.{q}" for q in HISTORY_CHANNELS]
    if any(name not in model.channel_names for name in names):
        worn = [e.name for e in getattr(model.scene, "elements", ()) if getattr(e, "wear", None) is not None]
        raise SceneError(f"wear_history: joint={joint!r}, must be a revolute clearance joint with wear of the run "
                         f"({', '.join(worn) or 'none has wear=ArchardWear(...)'}).")
    return RunChannels(model, names)


def history_arrays(t: NDArray[np.float64], values: dict[str, NDArray[np.float64]], joint: str) -> WearHistoryArrays:
    """The contact history from the joint's channels (:data:`HISTORY_CHANNELS`) at the times ``t``."""
    force, bearing, journal, slip, penetration = (values[f"{joint}.{q}"] for q in HISTORY_CHANNELS)
    slip = np.where(np.isfinite(slip), slip, 0.0)  # no direction at the centred journal (e = 0), far from contact
    return WearHistoryArrays(t=np.asarray(t, dtype=float), force=force, angle_bearing=np.unwrap(bearing),
                             angle_journal=np.unwrap(journal), slip_speed=slip,
                             penetration=np.clip(penetration, 0.0, None))


def wear_history(result: Result, model: DAEModel, joint: str) -> WearHistoryArrays:
    """The contact history of revolute clearance joint ``joint`` (with wear) in a run of ``model``, read from
    the joint's generated channels: normal force, the contact direction's angle in the bearing's and the
    journal's frame (``<joint>.bearing_angle``, ``.journal_angle``, unwrapped), the sliding velocity of the
    contact points (4.9) and the penetration."""
    backend = str(result.parameters.get("simulate", {}).get("backend", "auto"))
    return history_arrays(result.t, joint_channels(model, joint)(result, model, backend), joint)


@dataclass(frozen=True)
class WearHistory:
    """The profile's growth, one row per profile (the first unworn) worn over ``cycles``: ``depth``
    (profiles, nodes) or, both surfaces worn, (profiles, 2, nodes); ``volume`` (m^3), ``sliding_work``
    (integral of normal force times sliding speed, N m), ``peak_force`` (N, of the block run after
    each profile; NaN for the last)."""

    angles: NDArray[np.float64]
    cycles: NDArray[np.float64]
    depth: NDArray[np.float64]
    volume: NDArray[np.float64]
    sliding_work: NDArray[np.float64]
    peak_force: NDArray[np.float64]
    surfaces: tuple[str, ...]
    wall_time: float = 0.0
    message: str = ""  # why the history stopped before ``cycles`` (empty when it reached them)

    @property
    def max_depth(self) -> NDArray[np.float64]:
        """The deepest point of each profile, m."""
        return self.depth.reshape(self.depth.shape[0], -1).max(axis=1)


def wear_joint(scene: Scene, joint: str | None) -> RevoluteClearance:
    """The scene's revolute clearance joint that wears (``joint``, or the only one with ``wear``)."""
    worn = [e for e in scene.elements if isinstance(e, RevoluteClearance) and e.wear is not None]
    if joint is None:
        if len(worn) != 1:
            raise SceneError(f"simulate_wear: joint=None, must name the worn joint when the scene has "
                             f"{len(worn)} revolute clearance joints with wear ({', '.join(e.name for e in worn)}).")
        return worn[0]
    for element in worn:
        if element.name == joint:
            return element
    raise SceneError(f"simulate_wear: joint={joint!r}, must be a revolute clearance joint with wear of scene "
                     f"'{scene.name}' ({', '.join(e.name for e in worn) or 'none has wear=ArchardWear(...)'}).")


def effective_modulus(joint: RevoluteClearance) -> float:
    """E* of the joint's materials (the Hertz arc): ``1 / (sigma_i + sigma_j)``."""
    if joint.material is None:
        raise SceneError(f"simulate_wear: joint '{joint.name}' has no material; the 'hertz' distribution needs one.")
    return 1.0 / sigma_sum(joint.material)


#: The most blocks a history may ask for (update_every x extrapolate cycles each): more has no estimate
#: of its time or file size that a user would accept.
MAX_BLOCKS = 10**7
#: The shortest cycle, as a fraction of one turn of the scene's driver.
MIN_PERIOD_FRACTION = 1e-3


def simulate_wear(scene: Scene | DAEModel, cycles: float, *, joint: str | None = None, update_every: int = 1,
                  extrapolate: int = 1, period: float | None = None, path: str | os.PathLike[str] | None = None,
                  options: SolverOptions | None = None, progress: bool = False) -> WearHistory:
    """Wear a revolute clearance joint over ``cycles`` cycles of the mechanism.

    Each block runs ``update_every`` cycles with the current profile; its Archard wear times
    ``extrapolate`` is added to the profile (counting ``update_every * extrapolate`` cycles), and the
    next block continues from its last state and contact state (a contact going on across the boundary
    keeps its impact's approach speed) with the new profile (nothing is compiled).

    Parameters
    ----------
    scene, cycles : Scene or DAEModel, float
        The mechanism (a scene, or an assembled model: its formulation is kept), whose joint ``joint``
        has ``wear=ArchardWear(...)``, and the cycles to wear (> 0; the last block may run past it).
    update_every, extrapolate : int
        Cycles simulated per profile update, and the factor each block's wear is extrapolated by (>= 1).
    period : float or None
        One cycle, s; None: one turn of the scene's driver (at least a thousandth of it when given).
    path : str, path or None
        An HDF5 file the history is appended to after every block (checked before any work): a call with
        the same file, scene and settings resumes where a stopped one ended; any difference is an error
        naming it.
    options, progress : SolverOptions or None, bool
        The runs' solver settings; a progress line on stderr.

    A failed block (its run fails, its start cannot be assembled, or it leaves the journal deeper in
    the wall than the clearance), or a depth beyond :data:`MAX_DEPTH_FRACTION` of the bearing radius,
    ends the history early with a :class:`~daeclear.PhysicsWarning`; ``WearHistory.message`` says why.
    Ctrl-C raises :class:`~daeclear.errors.Interrupted` whose ``.result`` is the history so far (and the
    file has it). With ``surface="both"`` each surface wears by Archard's law with the coefficient, so
    the worn volume is twice k times the sliding work (docs/wear.md).
    """
    model = scene if isinstance(scene, DAEModel) else None
    if model is not None:
        if model.scene is None:
            raise SceneError("simulate_wear: scene is a model that was not made by assemble(); give its scene.")
        scene = model.scene
    if not isinstance(scene, Scene):
        raise SceneError(f"simulate_wear: scene={scene!r}, must be a daeclear.Scene or a model made by assemble().")
    for label, value in (("update_every", update_every), ("extrapolate", extrapolate)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise SceneError(f"simulate_wear: {label}={value!r}, must be an integer >= 1.")
    if isinstance(cycles, bool) or not (isinstance(cycles, (int, float)) and math.isfinite(cycles) and cycles > 0):
        raise SceneError(f"simulate_wear: cycles={cycles!r}, must be a finite number > 0.")
    if not isinstance(progress, bool):
        raise SceneError(f"simulate_wear: progress={progress!r}, must be True or False.")
    if options is not None and not isinstance(options, SolverOptions):
        raise SceneError(f"simulate_wear: options={options!r}, must be None or a daeclear.SolverOptions.")
    element = wear_joint(scene, joint)
    wear = element.wear
    period = _checked_period(scene, period)
    blocks = math.ceil(cycles / (update_every * extrapolate))
    if blocks > MAX_BLOCKS:
        size = blocks * 8 * (len(wear.surfaces) * wear.nodes + 4 + 6 * len(scene.bodies))  # a row: profile, state
        raise SceneError(f"simulate_wear: cycles={cycles:g} with update_every={update_every}, "
                         f"extrapolate={extrapolate} "
                         f"is {blocks:.3g} blocks, must be at most {MAX_BLOCKS:.0e} (at about 10 ms a simulated cycle "
                         f"that is {blocks * update_every * 0.01 / 3.15e7:.3g} years, and a history of "
                         f"{size / 1e9:.3g} GB); raise extrapolate or ask fewer cycles.")
    if path is not None:
        path = check_file(path, "simulate_wear(path)", what="a wear history file (.h5)", example="wear.h5")
    if wear.distribution == "hertz":
        effective_modulus(element)  # the materials it needs, checked before any work
    settings = {"joint": element.name, "update_every": update_every, "extrapolate": extrapolate, "period": period,
                "formulation": model.formulation if model is not None else "default",
                "options": None if options is None else options.to_dict(),
                "scene": to_plain(scene.to_dict(), "simulate_wear(scene)")}
    store = WearFile(path, settings) if path is not None else None
    tic = time.perf_counter()
    with store if store is not None else contextlib.nullcontext():
        rows = store.open() if store is not None else None  # checked against the settings before any work
        model = assemble(scene) if model is None else model
        if rows is None:
            rows = [WearRow(cycles=0.0, depth=element.worn_profiles(), work=0.0, block_peak=math.nan, t=0.0, y=None,
                            contact=None)]
            if store is not None:
                store.append(rows[0], model.n_states, contact_state.state_shape(model))
        history, interrupted = _blocks(model, rows, store, element, cycles, (update_every, extrapolate, period),
                                       options, progress)
    if interrupted:  # Ctrl-C: the history so far is kept (and in the file), then the caller stops
        raise Interrupted(f"simulate_wear: interrupted by the user at {history.cycles[-1]:g} cycles; the history so "
                          "far is in .result" + (f" and in {path}" if path is not None else ""),
                          result=replace(history, wall_time=time.perf_counter() - tic)) from None
    if history.message:
        warnings.warn(f"simulate_wear: {history.message}", PhysicsWarning, stacklevel=2)
    return replace(history, wall_time=time.perf_counter() - tic)


def _blocks(model: DAEModel, rows: list[WearRow], store: WearFile | None, element: RevoluteClearance,
            cycles: float, scheme: tuple[int, int, float], options: SolverOptions | None,
            progress: bool) -> tuple[WearHistory, bool]:
    """simulate_wear's blocks from the last of ``rows`` on, each appended to ``rows`` and ``store``
    (``scheme``: update interval, extrapolation, period): the history (its message says why it stopped
    early) and whether Ctrl-C stopped it."""
    update_every, extrapolate, period = scheme
    wear = element.wear
    assert wear is not None
    modulus = effective_modulus(element) if wear.distribution == "hertz" else None
    last = rows[-1]
    depth, done, work, t0, y0 = last.depth, last.cycles, last.work, last.t, last.y
    # the pairs' contact states carried from block to block (a resumed history: the file's last row's)
    carry = Continuation(None if y0 is None or last.contact is None else
                         contact_state.array_state(last.contact, contact_state.start_state(model, t0, y0)))
    shape = contact_state.state_shape(model)
    bar = Progress(float(cycles), unit="cycles", desc="wear", enabled=progress)
    name, radius, clearance = element.name, float(element.bearing_radius), element.radial_clearance
    history_of = joint_channels(model, name)
    backend = (options or SolverOptions()).backend  # the runs' (resolved alike by every session)
    message = ""
    try:
        with warnings.catch_warnings():  # a block beyond its contact law is judged below, once
            warnings.simplefilter("ignore", PhysicsWarning)
            while done < cycles:
                deepest = max(float(d.max()) for d in depth.values())
                if deepest > MAX_DEPTH_FRACTION * radius:
                    message = (f"stopped at {done:g} cycles: the worn depth {deepest:.3g} m exceeds "
                               f"{MAX_DEPTH_FRACTION:g} of the bearing radius {radius:g} m, where the gap's "
                               "small-slope model no longer holds; a smaller wear coefficient, or fewer cycles.")
                    break
                model = model.with_parameters({f"{name}.wear_depth": _depth_value(depth, wear.surfaces)})
                try:
                    result = block_run(model, t0, t0 + update_every * period, y0, options, carry)
                except (SolveError, AssemblyError) as exc:  # the history so far is the result (and in the file)
                    message = f"stopped at {done:g} cycles: the run of the next block failed: {exc}"
                    break
                channels = history_of(result, model, backend)
                deepest_run = float(np.max(channels[f"{name}.penetration"]))
                if deepest_run > clearance:
                    message = (f"stopped at {done:g} cycles: the next block's run left joint '{name}' "
                               f"{deepest_run:.3g} m inside its wall, more than its clearance {clearance:g} m (beyond "
                               "what its contact law describes); its wear is not taken. A tighter rtol, or a smaller "
                               "wear coefficient.")
                    break
                increment, block_work = wear_increment(wear, history_arrays(result.t, channels, name),
                                                       bearing_radius=radius, clearance=clearance,
                                                       effective_modulus=modulus)
                depth = {s: depth[s] + extrapolate * increment[s] for s in depth}
                done += update_every * extrapolate
                work += extrapolate * block_work
                t0, y0 = float(result.t[-1]), result.state(-1)
                peak = float(np.max(channels[f"{name}.normal_force"]))
                rows.append(WearRow(cycles=done, depth=depth, work=work, block_peak=peak, t=t0, y=y0,
                                    contact=None if carry.state is None else
                                    contact_state.state_array(carry.state, shape)))
                if store is not None:  # a Ctrl-C meanwhile arrives once the row is written whole
                    store.append(rows[-1], model.n_states, shape)
                bar.update(min(done, cycles), f"max depth {max(float(d.max()) for d in depth.values()):.3g} m")
    except KeyboardInterrupt:  # Ctrl-C: the history so far is kept (and in the file)
        return _history(rows, wear, radius, f"interrupted at {done:g} cycles"), True
    finally:
        bar.close()
    return _history(rows, wear, radius, message), False


def block_run(model: DAEModel, t0: float, t_end: float, y0: NDArray[np.float64] | None,
              options: SolverOptions | None, carry: Continuation | None = None) -> Result:
    """One block's run: ``simulate(model, t_end, t0=t0, y0=y0, options=options)`` without the physics
    checks of a run that reaches its end (the block judges its penetration itself; their warnings were
    ignored), 5-10 % of a block; its pairs start in ``carry``'s contact state (the previous block's end:
    a contact that goes on across the blocks keeps its impact's approach speed, as in one run) and
    leave theirs there (:class:`~daeclear.solvers.driver.Continuation`)."""
    settings = options or SolverOptions()
    opts.step_within(settings.step, t0, t_end)  # as simulate checks it
    solver = solver_class(settings.method)()
    if not isinstance(solver, DrivenSolver):  # a solver class of the user's: its own run, checked, from the gaps
        if carry is not None:
            carry.state = None
        return simulate(model, t_end, t0=t0, y0=y0, options=options)
    return driver.run(solver, model, t_end, t0, y0, save_value(None).plan(t0, t_end), settings, "raise", False,
                      checks=False, carry=carry)


def _checked_period(scene: Scene, period: float | None) -> float:
    """One cycle (s): the driver's turn, or ``period`` checked against it."""
    if period is None:
        return crank_period(scene)
    if isinstance(period, bool) or not (isinstance(period, (int, float)) and math.isfinite(period) and period > 0):
        raise SceneError(f"simulate_wear: period={period!r} s, must be a finite number > 0.")
    try:
        turn = crank_period(scene)
    except DaeclearError:  # no driver: nothing to compare with
        return float(period)
    if period < MIN_PERIOD_FRACTION * turn:
        raise SceneError(f"simulate_wear: period={period!r} s, must be at least {MIN_PERIOD_FRACTION:g} of one turn of "
                         f"the driver ({turn:.6g} s): a cycle is a turn of the mechanism (leave period=None).")
    return float(period)


def _depth_value(depth: dict[str, NDArray[np.float64]], surfaces: tuple[str, ...]) -> Any:
    """The joint's ``wear_depth`` value of a profile by surface."""
    return tuple(depth[surfaces[0]].tolist()) if len(surfaces) == 1 else tuple(
        tuple(depth[s].tolist()) for s in surfaces)


def _history(rows: list[WearRow], wear: ArchardWear, radius: float, message: str) -> WearHistory:
    """The history of ``rows``; a profile's peak force is that of the block run with it (the next row's)."""
    surfaces = wear.surfaces
    depth = np.array([[row.depth[s] for s in surfaces] for row in rows])
    volume = np.array([sum(worn_volume(row.depth[s], radius, wear.length) for s in surfaces) for row in rows])
    return WearHistory(angles=wear.angles, cycles=np.array([row.cycles for row in rows]),
                       depth=depth[:, 0] if len(surfaces) == 1 else depth, volume=volume,
                       sliding_work=np.array([row.work for row in rows]),
                       peak_force=np.array([row.block_peak for row in rows[1:]] + [math.nan]),
                       surfaces=surfaces, message=message)
