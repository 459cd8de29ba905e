"""Nonlinear-dynamics analysis of runs: phase portraits, Poincaré sections, motion classification.

The chapter reads periodic, quasi-periodic and chaotic responses from "Poincaré maps",
which are phase portraits (slider acceleration against slider velocity over many
revolutions, section 4.4). This module adds the true stroboscopic Poincaré section
(one point per crank revolution, after a transient) and a documented classification
of the motion with the evidence behind it:

1. **Periodicity** (:func:`classify_section`): the section points, each channel scaled
   by the attractor's size (its 1 %-99 % quantile range over the analysed span), are
   tested for recurrence: the motion is periodic of period k when every point is within
   ``tol`` (5 % by default) of the point k revolutions later, for the smallest
   k <= ``max_period``.
2. **Sensitivity** (:func:`twin_divergence`, :func:`twin_evidence` from arrays): twin
   trajectories are restarted on the attractor from the same state, one of them perturbed
   by ``perturbation`` (1e-8 m by default) along the constraint manifold. Their separation
   gives a largest Lyapunov exponent estimate (a straight-line fit of ln(distance) against
   time over the growth window, with its R^2, when it grew at least 100-fold), the
   amplification, and the distance of their late section points (gap, and decorrelation: the
   gap over the section's spread).
3. **Agreement** (:func:`classify_section`, the one place both tests meet): a recurring
   section whose twins show a resolved positive exponent or end apart at the section is
   "uncertain" with both numbers -- except growth >= 1000-fold with decorrelation from a
   free-flight restart, documented as chaos small in the section's channels (the
   translational joint's lateral impacts). A non-recurring section is chaotic when the twins
   decorrelate with a positive exponent, quasi-periodic when they stay together without one.
   Missing (nan) twin numbers are reported as missing, never counted as agreement.

Only numpy here (no plotting); figures are in :mod:`daeclear.plot`.
``docs/nonlinear_dynamics.md`` states the method, thresholds, limits and the measured
evidence for the chapter's cases.

Examples
--------
>>> from daeclear.model.mechanisms import slider_crank
>>> analysis = classify_motion(slider_crank("revolute", clearance=0.01e-3))   # doctest: +SKIP
>>> analysis.motion.label, analysis.motion.period                             # doctest: +SKIP
('periodic', 1)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .accuracy import energy_balance, work_precision  # re-exported: daeclear.analysis.work_precision
from ..assembly.assemble import DAEModel
from ..errors import DaeclearError, SceneError
from ..options import default_formulation

if TYPE_CHECKING:
    from ..results.result import Result
    from ..model.scene import Scene

__all__ = [
    "CHANNELS",
    "MOTION_LABELS",
    "Divergence",
    "MotionAnalysis",
    "MotionClass",
    "PhasePortrait",
    "PoincareSection",
    "TwinReading",
    "classify_motion",
    "classify_section",
    "crank_period",
    "energy_balance",
    "work_precision",
    "phase_portrait",
    "poincare_section",
    "restart_model",
    "section_channels",
    "read_twins",
    "sampling_times",
    "twin_divergence",
    "twin_evidence",
]

CHANNELS: tuple[str, str] = ("slider.vx", "slider.ax")
"""Default channel pair: the chapter's "Poincaré maps" plot slider acceleration against velocity."""


def section_channels(scene: Scene | DAEModel) -> tuple[str, str]:
    """The default section channels of a scene: the chapter's pair (:data:`CHANNELS`) when a body is
    named ``slider``, else the angular velocity and acceleration of the last body (the output link:
    a four-bar's rocker, a double pendulum's second link)."""
    bodies = list(scene.body_names) if isinstance(scene, DAEModel) else [b.name for b in scene.bodies]
    if "slider" in bodies or not bodies:
        return CHANNELS
    return (f"{bodies[-1]}.omega", f"{bodies[-1]}.alpha")

MotionLabel = Literal["periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined"]
MOTION_LABELS: tuple[str, ...] = ("periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined")

# Defaults of the classification (docs/nonlinear_dynamics.md gives the reasons and the checks).
DEFAULT_TOL = 0.05  # recurrence tolerance, fraction of the attractor size per channel
DEFAULT_MAX_PERIOD = 8  # longest period (revolutions) looked for
DEFAULT_DECORRELATION = 0.3  # twin decorrelation from which the twins count as unrelated
DEFAULT_PERTURBATION = 1e-8  # twin perturbation of the positions, m (Euclidean norm over q)
MIN_POINTS = 8  # fewer section points: "undetermined"
SIZE_QUANTILES = (0.01, 0.99)  # attractor size: this quantile range of the samples
MIN_AMPLIFICATION = 100.0  # the twin separation must grow two decades for a Lyapunov fit
SENSITIVE_AMPLIFICATION = 1e3  # growth that no stable periodic orbit gives: overrides a recurring section
MIN_FIT_R2 = 0.2  # a Lyapunov fit explaining less of ln(distance) than this resolves no exponent
SATURATION_FRACTION = 0.1  # the growth window ends where the separation reaches this x saturation
_TIME_MATCH = 1e-9  # output times match section times to this fraction of the period


# --------------------------------------------------------------------------- periods and sampling


def _scene_parameters(source: Any) -> Mapping[str, Any]:
    """The scene dictionary of a Result, DAEModel, Scene or mapping."""
    from ..model.scene import Scene

    if isinstance(source, Scene):
        return source.to_dict()
    params = getattr(source, "parameters", source)
    if isinstance(params, Mapping) and "scene" in params:
        return params["scene"]
    if isinstance(params, Mapping):
        return params
    raise TypeError(f"crank_period: cannot read a scene from a {type(source).__name__}.")


def crank_period(source: Result | DAEModel | Scene | Mapping[str, Any]) -> float:
    """Duration of one crank revolution, s: 2 pi / |speed| of the scene's driver.

    Parameters
    ----------
    source : Result, DAEModel, Scene or mapping
        Anything carrying the scene (a Result's or model's ``parameters["scene"]``).

    Returns
    -------
    float
        Period T, s (0.012 s at the chapter's 5000 rpm).

    Raises
    ------
    DaeclearError
        If the scene has no driver, or drivers of different speeds (no common period):
        pass ``period=`` explicitly then.
    """
    scene = _scene_parameters(source)
    elements = scene.get("elements", {}) if isinstance(scene, Mapping) else {}
    drivers = [e for e in elements.values() if isinstance(e, Mapping) and e.get("kind") == "Driver"]
    name = scene.get("name", "?") if isinstance(scene, Mapping) else "?"
    for driver in drivers:  # only a constant-speed rotation repeats every 2 pi / speed
        profile = (driver.get("profile") or {}).get("kind", "constant")
        joint = elements.get(driver.get("joint"), {})
        if profile != "constant" or (isinstance(joint, Mapping) and "Translational" in str(joint.get("kind"))):
            raise DaeclearError(f"scene {name!r}: driver {driver.get('name')!r} is not a constant-speed rotation "
                                f"(profile {profile!r} on joint {driver.get('joint')!r}), so the scene has no crank "
                                "period: pass period= (s) explicitly.")
    speeds = sorted({abs(float(e["speed"])) for e in drivers})
    if not speeds:
        raise DaeclearError(f"scene {name!r} has no driver, so no crank period: pass period= (s) explicitly.")
    if len(speeds) > 1 or speeds[0] == 0.0:
        raise DaeclearError(f"scene {name!r}: driver speeds {speeds} rad/s give no single nonzero period; "
                            "pass period= (s) explicitly.")
    return 2.0 * math.pi / speeds[0]


def sampling_times(period: float, revolutions: int, *, per_revolution: int = 32,
                   offset: float = 0.0) -> NDArray[np.float64]:
    """Output times for ``simulate(t_eval=...)`` that contain every section time exactly.

    ``per_revolution`` uniform samples per revolution from t = 0 to ``revolutions * period``,
    plus the section times ``offset + k * period`` (k = 0, 1, ...) when ``offset`` is not
    on the uniform grid.

    Parameters
    ----------
    period : float
        Crank period T, s.
    revolutions : int
        Number of revolutions simulated (transient included).
    per_revolution : int
        Uniform samples per revolution (>= 1); they give the phase portrait, the attractor
        size and the twin separation.
    offset : float
        Section time within the revolution, s, in [0, period): the section samples the
        crank angle ``omega * offset`` past its initial angle.

    Returns
    -------
    ndarray
        Increasing times in [0, revolutions * period].
    """
    if not (isinstance(revolutions, (int, np.integer)) and revolutions >= 1):
        raise SceneError(f"sampling_times: revolutions={revolutions!r}, must be an integer >= 1.")
    if not (isinstance(per_revolution, (int, np.integer)) and per_revolution >= 1):
        raise SceneError(f"sampling_times: per_revolution={per_revolution!r}, must be an integer >= 1.")
    if not (period > 0 and math.isfinite(period)):
        raise SceneError(f"sampling_times: period={period!r} s, must be a finite number > 0.")
    if not 0.0 <= offset < period:
        raise SceneError(f"sampling_times: offset={offset!r} s, must be in [0, period={period:g}).")
    n = int(revolutions) * int(per_revolution)
    t = period * (np.arange(n + 1) / per_revolution)  # k * per_revolution / per_revolution is exact
    if offset == 0.0:
        return t
    section = offset + period * np.arange(int(revolutions))
    keep = np.min(np.abs(t[:, None] - section[None, :]), axis=1) > _TIME_MATCH * period
    return np.union1d(t[keep], section)


# --------------------------------------------------------------------------- phase portraits


@dataclass(frozen=True)
class PhasePortrait:
    """Two channels against each other over a time window (the chapter's "Poincaré maps").

    Attributes
    ----------
    t : ndarray (n,)
        Times of the samples, s.
    x, y : ndarray (n,)
        The two channels.
    names : (str, str)
        Channel names of x and y.
    units : (str, str)
        Their units.
    """

    t: NDArray[np.float64]
    x: NDArray[np.float64]
    y: NDArray[np.float64]
    names: tuple[str, str]
    units: tuple[str, str]


def phase_portrait(result: Result, x: str = CHANNELS[0], y: str = CHANNELS[1], *, t0: float | None = None,
                   t1: float | None = None) -> PhasePortrait:
    """The samples of two channels over [t0, t1], for a phase portrait.

    Parameters
    ----------
    result : Result
        A run; a dense ``t_eval`` (:func:`sampling_times`) gives a smooth curve.
    x, y : str
        Channel (or state) names; default slider velocity and acceleration.
    t0, t1 : float, optional
        Window, s (e.g. ``t0`` = end of the transient); None: the whole run.

    Returns
    -------
    PhasePortrait
    """
    mask = result.window_mask(t0, t1)
    return PhasePortrait(t=np.asarray(result.t)[mask], x=np.asarray(result[x], dtype=float)[mask],
                         y=np.asarray(result[y], dtype=float)[mask], names=(x, y),
                         units=(result.units.get(x, ""), result.units.get(y, "")))


# --------------------------------------------------------------------------- Poincaré sections


@dataclass(frozen=True)
class PoincareSection:
    """Stroboscopic Poincaré section: the channels once per crank revolution.

    Attributes
    ----------
    t : ndarray (n,)
        Section times t0 + k T, s.
    points : ndarray (n, d)
        Channel values at those times, one column per channel.
    channels : tuple of str
        Channel names (d of them).
    units : tuple of str
        Their units.
    period : float
        T, s.
    size : ndarray (d,)
        Attractor size per channel: the 1 %-99 % quantile range of the channel over the
        analysed window (all output samples, not only the section); nan when the run was
        sampled too sparsely to tell (fewer than 4 samples per revolution).
    center : ndarray (d,)
        Median of each channel over the same window.
    """

    t: NDArray[np.float64]
    points: NDArray[np.float64]
    channels: tuple[str, ...]
    units: tuple[str, ...]
    period: float
    size: NDArray[np.float64]
    center: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.points.shape[0])

    def normalized(self) -> NDArray[np.float64]:
        """Points minus `center`, divided by `size` (channels of zero size become 0)."""
        size = np.where(self.size > 0, self.size, np.inf)
        return (self.points - self.center) / size

    def __repr__(self) -> str:
        return (f"PoincareSection({len(self)} points of {', '.join(self.channels)}, "
                f"t = {self.t[0]:.6g} .. {self.t[-1]:.6g} s, period {self.period:.6g} s)"
                if len(self) else f"PoincareSection(empty, channels {', '.join(self.channels)})")


def _match_times(result: Result, times: NDArray[np.float64], period: float) -> NDArray[np.intp]:
    """Indices of the output times equal (to 1e-9 T) to ``times``; raises naming the first missing one."""
    t = np.asarray(result.t)
    tol = _TIME_MATCH * period
    idx = np.clip(np.searchsorted(t, times - tol), 0, max(t.size - 1, 0))
    if t.size == 0 or np.any(np.abs(t[idx] - times) > tol):
        bad = times[0] if t.size == 0 else times[np.argmax(np.abs(t[idx] - times) > tol)]
        raise DaeclearError(
            f"Poincaré section: the result has no output at t = {bad:.9g} s (section times t0 + k T, "
            f"T = {period:.6g} s). Simulate with t_eval=daeclear.analysis.sampling_times(...) so that "
            "the section times are output points (values from IDA's interpolant, multipliers recomputed)."
        )
    return idx


def poincare_section(result: Result, channels: Sequence[str] = CHANNELS, *, t0: float | None = None,
                     t1: float | None = None, period: float | None = None) -> PoincareSection:
    """Stroboscopic Poincaré section of a run: the channels at t0, t0 + T, t0 + 2T, ...

    Parameters
    ----------
    result : Result
        A run whose output times contain the section times (use :func:`sampling_times`
        for ``t_eval``); dense output in between gives the attractor size.
    channels : sequence of str
        Any channels or states (two for a plot, any number for classification).
    t0 : float, optional
        First section time, s: the end of the transient (plus the section's phase offset).
        Default: the first output time.
    t1 : float, optional
        Last time, s; default the last output time.
    period : float, optional
        T, s; default from the scene's driver (:func:`crank_period`).

    Returns
    -------
    PoincareSection

    Raises
    ------
    DaeclearError
        If a section time is not an output time of the result, or no period can be found.
    ChannelKeyError
        If a channel does not exist (close matches listed).
    """
    channels = tuple(str(c) for c in channels)
    if not channels:
        raise SceneError("poincare_section: give at least one channel.")
    T = float(period) if period is not None else crank_period(result)
    if result.n_times == 0:
        raise DaeclearError("poincare_section: the result has no output times.")
    start = float(result.t[0]) if t0 is None else float(t0)
    stop = float(result.t[-1]) if t1 is None else float(t1)
    n = int(math.floor((stop - start) / T + _TIME_MATCH)) + 1 if stop >= start else 0
    times = start + T * np.arange(max(n, 0))
    idx = _match_times(result, times, T) if times.size else np.zeros(0, dtype=np.intp)
    values = [np.asarray(result[c], dtype=float) for c in channels]
    for c, v in zip(channels, values):
        if v.ndim != 1:
            raise SceneError(f"poincare_section: channel {c!r} has shape {v.shape}; give scalar channels.")
    points = np.column_stack([v[idx] for v in values]) if times.size else np.zeros((0, len(channels)))
    window = result.window_mask(start - _TIME_MATCH * T, stop + _TIME_MATCH * T)
    n_window = int(np.count_nonzero(window))
    if times.size >= 2 and n_window >= 4 * (times.size - 1):
        lo, hi = SIZE_QUANTILES
        size = np.array([np.quantile(v[window], hi) - np.quantile(v[window], lo) for v in values])
        center = np.array([np.median(v[window]) for v in values])
    else:
        size = np.full(len(channels), np.nan)
        center = np.median(points, axis=0) if times.size else np.full(len(channels), np.nan)
    return PoincareSection(t=result.t[idx] if times.size else np.zeros(0), points=points, channels=channels,
                           units=tuple(result.units.get(c, "") for c in channels), period=T, size=size,
                           center=center)


def _recurrence_defects(p: NDArray[np.float64], max_period: int) -> dict[int, float]:
    """d_k = max_j max_i |p[j+k, i] - p[j, i]| for k = 1..K (K <= max_period, at least 2 pairs per k)."""
    n = p.shape[0]
    k_max = min(int(max_period), (n - 1) // 2)
    return {k: float(np.max(np.abs(p[k:] - p[:-k]))) for k in range(1, k_max + 1)}


def _clusters(p: NDArray[np.float64], tol: float) -> int:
    """Leader clustering in the max-norm: a point opens a new cluster when farther than tol from every leader."""
    leaders: list[NDArray[np.float64]] = []
    for row in p:
        if not any(np.max(np.abs(row - q)) <= tol for q in leaders):
            leaders.append(row)
    return len(leaders)


# --------------------------------------------------------------------------- twin trajectories


def _state_selection(result: Result) -> list[int]:
    """Columns of y that are positions or velocities (states with a unit; multipliers have none)."""
    return [i for i, name in enumerate(result.state_names) if result.units.get(name, "")]


@dataclass(frozen=True)
class _RestartModel(DAEModel):
    """A DAEModel whose run starts from a given state (positions and velocities kept as given)."""

    start_state: tuple[float, ...] = ()
    start_is_declared = False  # a state of a run: starting in contact is no declaration error (daeclear.solvers.physics)

    def initial_state(self, session: Any = None, start: str = "declared", allow_penetration: bool = True
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        # index-1: no Newton projection (consistent_state ignores it): the stored state carries the
        # run's own (Baumgarte-controlled) constraint drift, and projecting it away would move a
        # journal by up to that drift. GGL: projected, as every GGL restart is; its run holds the
        # joints to Newton's tolerance, but a stored output point is IDA's interpolant (and a
        # perturbed one is on the manifold only to first order), and GGL cannot start off it.
        return self.consistent_state(0.0, np.array(self.start_state, dtype=float), session=session, project=True)


def restart_model(model: DAEModel, result: Result, index: int, *, perturbation: float = 0.0,
                  seed: int = 0) -> DAEModel:
    """A model whose run starts at t = 0 from the state of ``result`` at output ``index``.

    The scene is T-periodic in time (drivers at one speed, constant gravity), so a state
    at t = j T is a valid initial state at t = 0 once every body angle is unwound by the
    whole turns it made since t = 0. Positions and velocities are kept as they are (no
    re-assembly), multipliers and accelerations recomputed. Contact modes are set from
    the gaps at the restart (restart in free flight to avoid re-latching an approach speed).

    Parameters
    ----------
    model : DAEModel
        The model of ``result``.
    result : Result
        A run of ``model`` whose output ``index`` is at a whole number of periods.
    index : int
        Output index of the restart state.
    perturbation : float
        Size (Euclidean norm over the positions q, m and rad mixed) of a random
        perturbation of the positions, projected on the constraint manifold's tangent
        space so the joints stay closed to first order; 0 for none.
    seed : int
        Seed of the perturbation's random direction.

    Returns
    -------
    DAEModel
        A subclass instance usable wherever a model is (``simulate(model, ...)``).
    """
    T = crank_period(model)
    t_restart = float(result.t[index])
    turns = t_restart / T
    if abs(turns - round(turns)) > 1e-6:
        raise DaeclearError(f"restart_model: t = {t_restart:.9g} s is not a whole number of periods "
                            f"(T = {T:.6g} s); a restart needs the driver at its initial angle.")
    y = np.array(result.y[index], dtype=float)
    n_q = model.n_q
    for i, name in enumerate(result.state_names[:n_q]):
        if result.units.get(name) == "rad":  # unwind whole turns: rotation matrices and drivers are 2 pi periodic
            y[i] -= 2.0 * math.pi * round((y[i] - float(result.y[0, i])) / (2.0 * math.pi))
    if perturbation:
        rng = np.random.default_rng(seed)
        u = rng.standard_normal(n_q)
        q, v = y[:n_q], y[n_q:2 * n_q]
        if model.n_constraints:  # along the constraint manifold: project on the null space of Phi_q
            Phi_q = np.array(model.kinematics(q, v, 0.0, model.parameter_values)[1], dtype=float).reshape(model.n_constraints, n_q)
            _, sv, vt = np.linalg.svd(Phi_q)
            rank = int(np.sum(sv > 1e-10 * sv[0])) if sv.size and sv[0] > 0 else 0
            null = vt[rank:].T
            u = null @ (null.T @ u)
        norm = float(np.linalg.norm(u))
        if norm <= 1e-12:
            raise DaeclearError(f"restart_model: scene {model.scene_name!r} has no free position to perturb "
                                "(its joints and drivers fix every coordinate).")
        y[:n_q] += perturbation * u / norm
    kw = {f.name: getattr(model, f.name) for f in dataclasses.fields(model) if f.name != "start_state"}
    return _RestartModel(**kw, start_state=tuple(float(x) for x in y))


def _all_free(result: Result, t: float) -> bool:
    """True when every contact pair is free (not in contact) strictly inside a segment containing t."""
    for a, b, modes in result.segments:
        if a < t < b:
            return all(mode == "free" for mode in modes.values())
    return False


@dataclass(frozen=True)
class Divergence:
    """Separation of twin trajectories restarted on the attractor, one of them perturbed.

    Attributes
    ----------
    t : ndarray (m,)
        Times since the restart, s.
    distance : ndarray (m,)
        RMS over positions and velocities of |twin a - twin b| / (attractor range of the state).
    restart_time : float
        Time of the restart state in the original run, s.
    restart_in_contact : bool
        True when no section time of the analysed span was in free flight, so the restart is
        in contact (the approach speed latched at the last impact is replaced by the current
        penetration rate for that contact: the twins are then a slightly different system).
    perturbation : float
        Size of the position perturbation, m (Euclidean norm over q).
    d0 : float
        Normalised separation at the restart (the perturbation).
    d_start : float
        Separation at the first sample after the restart: the integration noise of two runs
        whose steps differ (about rtol) when it exceeds d0; the growth is measured from it.
    d_saturation : float
        Median separation over the second half of the twin run.
    amplification : float
        d_saturation / d_start.
    lyapunov : float
        Largest Lyapunov exponent estimate, 1/s: slope of ln(distance) against time over the
        growth window; nan when the separation grew less than MIN_AMPLIFICATION times.
    r_squared : float
        Coefficient of determination of that straight-line fit (nan without a fit).
    fit_window : (float, float)
        Times since restart (s) of the fitted samples.
    decorrelation : float
        RMS distance between the twins' section points over the second half of the twin run,
        in units of the attractor's size, divided by sqrt(2) x the section's RMS spread: about 1
        when the twins are as far apart as two unrelated points of the attractor, << 1 when
        they stay together.
    period : float
        T, s.
    section_gap : float
        The numerator of the decorrelation alone: RMS distance between the twins' late section
        points in units of the attractor size, the recurrence test's own yardstick (a periodic
        section's spread is integration noise, so its decorrelation is a ratio to noise; the gap
        is compared with ``tol`` instead). nan when not measured.
    twin_recurrence : float
        Recurrence defect of the unperturbed twin's late section points (smallest over k, attractor
        units): a faithful restart of a periodic run recurs as the reference does. nan when not measured.
    """

    t: NDArray[np.float64]
    distance: NDArray[np.float64]
    restart_time: float
    restart_in_contact: bool
    perturbation: float
    d0: float
    d_start: float
    d_saturation: float
    amplification: float
    lyapunov: float
    r_squared: float
    fit_window: tuple[float, float]
    decorrelation: float
    period: float
    section_gap: float = float("nan")
    twin_recurrence: float = float("nan")

    @property
    def lyapunov_per_revolution(self) -> float:
        """Lyapunov exponent times T: growth in nepers per crank revolution."""
        return self.lyapunov * self.period

    def evidence(self) -> dict[str, Any]:
        """The scalar fields as a plain dict (for reports and HDF5 attributes)."""
        return {
            "decorrelation": self.decorrelation,
            "lyapunov": self.lyapunov,
            "lyapunov_per_revolution": self.lyapunov_per_revolution,
            "fit_r2": self.r_squared,
            "fit_window_start": self.fit_window[0],
            "fit_window_end": self.fit_window[1],
            "twin_d0": self.d0,
            "twin_d_start": self.d_start,
            "twin_d_saturation": self.d_saturation,
            "twin_amplification": self.amplification,
            "twin_perturbation": self.perturbation,
            "twin_section_gap": self.section_gap,
            "twin_recurrence": self.twin_recurrence,
            "restart_time": self.restart_time,
            "restart_in_contact": self.restart_in_contact,
        }


def twin_evidence(t: ArrayLike, distance: ArrayLike, points_a: ArrayLike, points_b: ArrayLike,
                  section: PoincareSection, *, restart_time: float = 0.0, restart_in_contact: bool = False,
                  perturbation: float = float("nan"), max_period: int = DEFAULT_MAX_PERIOD) -> Divergence:
    """Twin evidence from arrays: Lyapunov fit, amplification, decorrelation and section gap.

    The array-level half of :func:`twin_divergence`, public so that any pair of trajectories
    (a small ODE, a map, measured data) is judged by exactly the numbers a mechanism's twins are.

    Parameters
    ----------
    t : array_like (m,)
        Times since the restart, s (t[0] = 0: the restart).
    distance : array_like (m,)
        Normalised separation of the twins at those times (e.g. RMS over the states of
        |a - b| / attractor range); distance[0] is the perturbation.
    points_a, points_b : array_like (n, d)
        The twins' section points (one row per revolution from the restart), in the units of
        ``section.points``.
    section : PoincareSection
        Section of the reference run: attractor size, centre and spread.
    restart_time, restart_in_contact, perturbation : float, bool, float
        Recorded as evidence.
    max_period : int
        Longest period of the unperturbed twin's recurrence check.

    Returns
    -------
    Divergence
    """
    t = np.asarray(t, dtype=float)
    distance = np.asarray(distance, dtype=float)
    d0 = float(distance[0]) if distance.size else float("nan")
    d_start = float(distance[1]) if distance.size > 1 else float("nan")
    late = t >= 0.5 * t[-1] if t.size else np.zeros(0, dtype=bool)
    d_sat = float(np.median(distance[late])) if np.any(late) else float("nan")
    floor = max(d_start, d0) if math.isfinite(d0) else d_start
    amplification = d_sat / floor if floor > 0 else float("nan")
    lyapunov, r2, window = float("nan"), float("nan"), (float("nan"), float("nan"))
    if math.isfinite(amplification) and amplification >= MIN_AMPLIFICATION:
        above = np.nonzero(distance[1:] >= SATURATION_FRACTION * d_sat)[0]
        end = int(above[0]) + 1 if above.size else distance.size - 1
        end = min(max(end, 4), distance.size - 1)
        tt, ld = t[1:end + 1], np.log(np.maximum(distance[1:end + 1], np.finfo(float).tiny))
        A = np.column_stack([tt, np.ones_like(tt)])
        coef, *_ = np.linalg.lstsq(A, ld, rcond=None)
        resid = ld - A @ coef
        total = float(np.sum((ld - ld.mean()) ** 2))
        lyapunov = float(coef[0])
        r2 = 1.0 - float(np.sum(resid**2)) / total if total > 0 else float("nan")
        window = (float(tt[0]), float(tt[-1]))

    # decorrelation and gap of the twins' late section points, in the reference section's units
    pa = np.asarray(points_a, dtype=float).reshape(-1, len(section.channels))
    pb = np.asarray(points_b, dtype=float).reshape(-1, len(section.channels))
    decorrelation = gap = recurrence = float("nan")
    if pa.shape == pb.shape and pa.shape[0] >= 2 and len(section) >= 2 and np.all(np.isfinite(section.size)):
        size = np.where(section.size > 0, section.size, np.inf)
        half = pa.shape[0] // 2
        na, nb = (pa[half:] - section.center) / size, (pb[half:] - section.center) / size
        gap = float(np.sqrt(np.mean(np.sum((na - nb) ** 2, axis=1))))
        p = section.normalized()
        spread = float(np.sqrt(np.mean(np.sum((p - p.mean(axis=0)) ** 2, axis=1))))
        decorrelation = gap / (math.sqrt(2.0) * spread) if spread > 0 else float("nan")
        defects = _recurrence_defects(na, max_period) if na.shape[0] >= 2 else {}
        recurrence = min(defects.values()) if defects else float("nan")
    return Divergence(t=t, distance=distance, restart_time=float(restart_time),
                      restart_in_contact=bool(restart_in_contact), perturbation=float(perturbation), d0=d0,
                      d_start=d_start, d_saturation=d_sat, amplification=float(amplification), lyapunov=lyapunov,
                      r_squared=r2, fit_window=window, decorrelation=decorrelation, period=section.period,
                      section_gap=gap, twin_recurrence=recurrence)


def twin_divergence(twin_a: Result, twin_b: Result, section: PoincareSection, *, reference: Result,
                    restart_time: float = 0.0, restart_in_contact: bool = False, perturbation: float = float("nan"),
                    offset: float = 0.0) -> Divergence:
    """Separation, Lyapunov estimate and decorrelation of two twin runs.

    Measures the separation of the states and the twins' section points, then hands them to
    :func:`twin_evidence` (the same numbers for any pair of trajectories).

    Parameters
    ----------
    twin_a, twin_b : Result
        Unperturbed and perturbed runs from the same restart state, on the same output times,
        which contain the section times ``offset + k T``.
    section : PoincareSection
        Section of the reference run: gives the channels, the attractor size and the spread.
    reference : Result
        The reference run: the attractor range of each state over the section's window.
    restart_time, restart_in_contact, perturbation : float, bool, float
        Recorded as evidence.
    offset : float
        Section time within the revolution, s.

    Returns
    -------
    Divergence
    """
    if twin_a.t.shape != twin_b.t.shape or not np.allclose(twin_a.t, twin_b.t, rtol=0, atol=1e-12):
        raise DaeclearError("twin_divergence: the twin runs have different output times.")
    T = section.period
    cols = _state_selection(reference)
    window = reference.window_mask(section.t[0] if len(section) else None, None)
    y_ref = np.asarray(reference.y)[window][:, cols]
    ranges = np.ptp(y_ref, axis=0) if y_ref.shape[0] else np.zeros(len(cols))
    units = [reference.units[reference.state_names[i]] for i in cols]
    keep = np.zeros(len(cols), dtype=bool)
    for unit in set(units):
        same = np.array([u == unit for u in units])
        top = float(np.max(ranges[same])) if np.any(same) else 0.0
        keep |= same & (ranges > 1e-9 * top) & (ranges > 0)
    idx = [c for c, k in zip(cols, keep) if k]
    scale = ranges[keep]
    diff = (np.asarray(twin_a.y)[:, idx] - np.asarray(twin_b.y)[:, idx]) / scale
    distance = np.sqrt(np.mean(diff**2, axis=1)) if idx else np.zeros(twin_a.n_times)
    t = np.asarray(twin_a.t) - float(twin_a.t[0])

    n_sec = int(math.floor((float(twin_a.t[-1]) - offset) / T + _TIME_MATCH)) + 1 if twin_a.n_times else 0
    times = (float(twin_a.t[0]) if twin_a.n_times else 0.0) + offset + T * np.arange(max(n_sec, 0))
    d = len(section.channels)
    pa = pb = np.zeros((0, d))
    if times.size >= 2:
        ia, ib = _match_times(twin_a, times, T), _match_times(twin_b, times, T)
        pa = np.column_stack([np.asarray(twin_a[c], dtype=float)[ia] for c in section.channels])
        pb = np.column_stack([np.asarray(twin_b[c], dtype=float)[ib] for c in section.channels])
    return twin_evidence(t, distance, pa, pb, section, restart_time=restart_time,
                         restart_in_contact=restart_in_contact, perturbation=perturbation)


# --------------------------------------------------------------------------- classification


@dataclass(frozen=True)
class MotionClass:
    """The motion class of a run and the evidence behind it.

    Attributes
    ----------
    label : {"periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined"}
        "non-periodic": the section does not recur, and no twin evidence (or missing or
        contradictory twin evidence) to tell quasi-periodic from chaotic. "uncertain": the
        section recurs but the twin test contradicts it (a positive exponent, growth beyond
        1000-fold, or twins ending apart at the section); the reason gives both tests'
        numbers. "undetermined": too few section points or no attractor size.
    period : int
        k for "periodic" (revolutions), else 0.
    evidence : dict
        Plain numbers and strings: ``n_points``, ``tol``, ``periodicity_defect`` (the
        recurrence distance at the period found, else the smallest over k, in units of the
        attractor size), ``best_period`` (its k),
        ``defect_k1`` ... ``defect_kK``, ``n_clusters`` (distinct section points at ``tol``),
        ``spread`` (RMS distance of the section points from their mean, attractor units) and,
        with twins, the fields of :meth:`Divergence.evidence`.
    reason : str
        One sentence with the deciding numbers.
    """

    label: MotionLabel
    period: int
    evidence: dict[str, Any] = field(default_factory=dict)
    reason: str = ""

    def __str__(self) -> str:
        head = f"periodic (period {self.period})" if self.label == "periodic" else self.label
        return f"{head}: {self.reason}"


def _num(x: float, fmt: str = ".3g") -> str:
    """A number for a reason sentence; nan is written as "missing", never as a value."""
    return format(x, fmt) if math.isfinite(x) else "missing"


@dataclass(frozen=True)
class TwinReading:
    """What the twin evidence says, decided once for every rule of :func:`classify_section`.

    Attributes
    ----------
    complete : bool
        Amplification and decorrelation (and, for a recurring section, the section gap) are
        numbers; otherwise the twin test is *missing* and can neither confirm nor contradict.
    exponent : bool
        A positive exponent resolved by a usable fit: amplification >= MIN_AMPLIFICATION (100),
        Lyapunov estimate > 0 (a finite slope; nan is never positive) and R^2 >= MIN_FIT_R2 (0.2).
    sensitive : bool
        Sensitive dependence beyond doubt: amplification >= SENSITIVE_AMPLIFICATION (1000) and a
        positive exponent.
    decorrelated : bool
        Decorrelation >= the threshold (0.3).
    apart : bool
        The twins' late section points are farther apart than ``tol`` (attractor units): they do
        not recur onto each other at the recurrence test's own resolution.
    numbers : str
        The twin numbers as one clause (nan written as "missing").
    """

    complete: bool
    exponent: bool
    sensitive: bool
    decorrelated: bool
    apart: bool
    numbers: str


def read_twins(divergence: Divergence, *, tol: float = DEFAULT_TOL,
               decorrelation: float = DEFAULT_DECORRELATION) -> TwinReading:
    """The twin test's verdicts (thresholds of docs/nonlinear_dynamics.md) and its numbers as text."""
    A, lam, D, gap = divergence.amplification, divergence.lyapunov, divergence.decorrelation, divergence.section_gap
    r2 = divergence.r_squared
    usable = math.isfinite(r2) and r2 >= MIN_FIT_R2
    exponent = math.isfinite(A) and A >= MIN_AMPLIFICATION and math.isfinite(lam) and lam > 0 and usable
    lam_text = (f"Lyapunov {lam:.3g} 1/s ({lam * divergence.period:.3g} per revolution, R^2 "
                f"{_num(r2, '.2f')}{'' if usable else f' < {MIN_FIT_R2:g}: fit unusable'})" if math.isfinite(lam)
                else f"Lyapunov missing (growth < {MIN_AMPLIFICATION:g}-fold: no fit)" if math.isfinite(A)
                else "Lyapunov missing")
    span = float(divergence.t[-1]) / divergence.period if divergence.t.size and divergence.period > 0 else 0.0
    over = f" over {span:.0f} revolutions" if span > 0 else ""
    numbers = (f"twins{over}: separation grew {_num(A)}-fold, {lam_text}, decorrelation {_num(D)}, "
               f"section gap {_num(gap)}" + (", restarted in contact" if divergence.restart_in_contact else ""))
    return TwinReading(complete=math.isfinite(A) and math.isfinite(D),
                       exponent=exponent, sensitive=exponent and A >= SENSITIVE_AMPLIFICATION,
                       decorrelated=math.isfinite(D) and D >= decorrelation,
                       apart=math.isfinite(gap) and gap > tol, numbers=numbers)


def classify_section(section: PoincareSection, divergence: Divergence | None = None, *, tol: float = DEFAULT_TOL,
                     max_period: int = DEFAULT_MAX_PERIOD, decorrelation: float = DEFAULT_DECORRELATION,
                     min_points: int = MIN_POINTS) -> MotionClass:
    """Classify the motion from a Poincaré section and, optionally, twin-trajectory evidence.

    The one place where the section test and the twin test are combined: a label never
    contradicts its own evidence, and missing (nan) twin numbers are reported as missing,
    never counted as agreement. Rules, in order (docs/nonlinear_dynamics.md, with the checks
    behind each threshold); "exponent" means amplification >= 100 with a positive Lyapunov
    fit (R^2 >= 0.2), "sensitive" an exponent with amplification >= 1000 (:func:`read_twins`):

    1. fewer than ``min_points`` section points, or unknown attractor size: "undetermined";
    2. the section recurs: smallest k <= ``max_period`` whose defect
       max_j max_channel |p[j+k] - p[j]| / size <= ``tol``. Then
       a. no twins, or twin numbers missing: "periodic" (k), the reason saying the
          sensitivity was not tested or its evidence is missing;
       b. twins sensitive and decorrelated (>= ``decorrelation``), restarted in free flight:
          "chaotic" -- chaos small in the section's channels (the translational joint);
       c. twins sensitive, or with an exponent, or ending apart at the section (gap > ``tol``):
          "uncertain", with both tests' numbers;
       d. otherwise (no resolved growth, twins within ``tol``): "periodic" (k);
    3. without twins: "non-periodic";
    4. twin numbers missing: "non-periodic" (missing evidence named);
    5. twins decorrelated with an exponent, or sensitive: "chaotic";
    6. twins not decorrelated and no exponent: "quasi-periodic";
    7. otherwise (decorrelated without resolved growth, or together with a positive
       exponent): "non-periodic", both numbers given.

    Parameters
    ----------
    section : PoincareSection
        With a finite `size` (a densely sampled run).
    divergence : Divergence, optional
        From :func:`twin_divergence` or :func:`twin_evidence`.
    tol : float
        Recurrence tolerance, fraction of the attractor size (0.05); also the largest section
        gap of twins that agree with a recurring section.
    max_period : int
        Longest period looked for, revolutions (8).
    decorrelation : float
        Decorrelation threshold (0.3).
    min_points : int
        Fewest section points to classify (8).

    Returns
    -------
    MotionClass
    """
    if not 0 < tol < 1:
        raise SceneError(f"classify_section: tol={tol!r}, must be in (0, 1) (fraction of the attractor size).")
    if not (isinstance(max_period, (int, np.integer)) and max_period >= 1):
        raise SceneError(f"classify_section: max_period={max_period!r}, must be an integer >= 1.")
    n = len(section)
    evidence: dict[str, Any] = {"n_points": n, "channels": ",".join(section.channels), "tol": float(tol),
                                "max_period": int(max_period), "decorrelation_threshold": float(decorrelation)}
    if divergence is not None:
        evidence.update(divergence.evidence())
    if n < min_points or not np.all(np.isfinite(section.size)):
        why = (f"{n} section points, fewer than {min_points}" if n < min_points
               else "unknown attractor size (sample the run densely: sampling_times(per_revolution=32))")
        return MotionClass("undetermined", 0, evidence, why + ".")
    p = section.normalized()
    defects = _recurrence_defects(p, max_period)
    best_k = min(defects, key=lambda k: (defects[k], k)) if defects else 0
    defect = defects[best_k] if defects else float("nan")
    spread = float(np.sqrt(np.mean(np.sum((p - p.mean(axis=0)) ** 2, axis=1))))
    evidence.update({"periodicity_defect": defect, "best_period": int(best_k), "n_clusters": _clusters(p, tol),
                     "spread": spread, **{f"defect_k{k}": v for k, v in defects.items()}})
    twins = read_twins(divergence, tol=tol, decorrelation=decorrelation) if divergence is not None else None
    periodic = [k for k, v in defects.items() if v <= tol]
    if periodic:
        k = periodic[0]
        evidence.update(periodicity_defect=defects[k], best_period=int(k))
        recurs = (f"every section point is within {defects[k]:.3g} of the point {k} revolution"
                  f"{'s' if k > 1 else ''} later (<= tol {tol:g} of the attractor size), "
                  f"{n} points, {evidence['n_clusters']} cluster(s)")
        if divergence is None or twins is None:
            return MotionClass("periodic", k, evidence, recurs + "; sensitivity not tested (no twin run).")
        if not (twins.complete and math.isfinite(divergence.section_gap)):
            return MotionClass("periodic", k, evidence,
                               f"{recurs}; twin evidence missing, sensitivity not tested ({twins.numbers}).")
        if twins.sensitive and twins.decorrelated and not divergence.restart_in_contact:
            return MotionClass("chaotic", 0, evidence,
                               f"{recurs}, but {twins.numbers} (>= {SENSITIVE_AMPLIFICATION:g}-fold, "
                               f"decorrelated >= {decorrelation:g}, restarted in free flight): chaotic motion "
                               f"that is small in {', '.join(section.channels)}.")
        if twins.sensitive or twins.exponent or twins.apart:
            why = []
            if twins.exponent:
                why.append(f"a positive exponent resolved over >= {MIN_AMPLIFICATION:g}-fold growth "
                           f"(R^2 >= {MIN_FIT_R2:g})")
            if twins.apart:
                why.append(f"section gap > tol {tol:g}")
            if twins.sensitive and twins.decorrelated:
                why.append("growth that would mark chaos small in the section, but the twins were restarted "
                           "in contact (not faithful copies)")
            return MotionClass("uncertain", 0, evidence,
                               f"section test says period {k} ({recurs}); twin test disagrees ({'; '.join(why)}): "
                               f"{twins.numbers}; unperturbed twin's own recurrence defect "
                               f"{_num(divergence.twin_recurrence)}.")
        return MotionClass("periodic", k, evidence,
                           f"{recurs}; twins agree: no exponent resolved and section gap <= tol {tol:g} "
                           f"({twins.numbers}).")
    not_periodic = (f"no period <= {max(defects)} revolutions recurs (smallest defect {defect:.3g} at k = {best_k} "
                    f"> tol {tol:g}; spread {spread:.3g}, {evidence['n_clusters']} clusters of {n} points)")
    if divergence is None or twins is None:
        return MotionClass("non-periodic", 0, evidence, not_periodic + "; no twin run to test sensitivity.")
    if not twins.complete:
        return MotionClass("non-periodic", 0, evidence,
                           f"{not_periodic}; twin evidence missing, cannot tell quasi-periodic from chaotic "
                           f"({twins.numbers}).")
    D = divergence.decorrelation
    if (twins.decorrelated and twins.exponent) or twins.sensitive:
        how = (f"twins decorrelate ({D:.3g} >= {decorrelation:g})" if twins.decorrelated else
               f"twins stay correlated ({D:.3g}) but diverge exponentially "
               f"(>= {SENSITIVE_AMPLIFICATION:g}-fold)")
        return MotionClass("chaotic", 0, evidence, f"{not_periodic}; {how}; {twins.numbers}.")
    if not twins.decorrelated and not twins.exponent:
        return MotionClass("quasi-periodic", 0, evidence,
                           f"{not_periodic}; twins stay together (decorrelation {D:.3g} < {decorrelation:g}, "
                           f"no positive exponent resolved); {twins.numbers}.")
    return MotionClass("non-periodic", 0, evidence,
                       f"{not_periodic}; twin evidence inconclusive ("
                       + ("decorrelated without a resolved positive exponent" if twins.decorrelated
                          else "together but with a positive exponent") + f"): {twins.numbers}.")


# --------------------------------------------------------------------------- the whole pipeline


@dataclass(frozen=True)
class MotionAnalysis:
    """Everything :func:`classify_motion` computed.

    Attributes
    ----------
    result : Result
        The reference run from t = 0, sampled by :func:`sampling_times`.
    section : PoincareSection
        Its section over the analysed span (after the transient).
    motion : MotionClass
        The classification and its evidence.
    divergence : Divergence or None
        Twin evidence (None with ``twin=False``).
    twins : (Result, Result) or None
        The unperturbed and perturbed restarted runs.
    options : dict
        The options of the analysis (revolutions, transient, ...).
    """

    result: Result
    section: PoincareSection
    motion: MotionClass
    divergence: Divergence | None = None
    twins: tuple[Result, Result] | None = None
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def t0(self) -> float:
        """First section time (end of the transient plus the section offset), s."""
        return float(self.section.t[0]) if len(self.section) else float("nan")


def _check_int(name: str, value: Any, low: int) -> int:
    if not (isinstance(value, (int, np.integer)) and not isinstance(value, bool) and value >= low):
        raise SceneError(f"classify_motion: {name}={value!r}, must be an integer >= {low}.")
    return int(value)


def classify_motion(scene: Scene | DAEModel, *, channels: Sequence[str] | None = None, revolutions: int = 30,
                    transient: int = 10, per_revolution: int = 32, phase: float = 0.0, twin: bool | str = True,
                    twin_revolutions: int = 20, perturbation: float = DEFAULT_PERTURBATION, seed: int = 0,
                    tol: float = DEFAULT_TOL, max_period: int = DEFAULT_MAX_PERIOD,
                    decorrelation: float = DEFAULT_DECORRELATION, rtol: float = 1e-6,
                    **simulate_options: Any) -> MotionAnalysis:
    """Simulate a scene, take its Poincaré section after a transient and classify the motion.

    Parameters
    ----------
    scene : Scene or DAEModel
        A driven mechanism (its driver sets the period T).
    channels : sequence of str, optional
        Section channels; default :func:`section_channels` (slider velocity and acceleration, as
        the chapter, or the last body's angular velocity and acceleration without a slider).
    revolutions : int
        Revolutions analysed after the transient (30): revolutions + 1 section points.
    transient : int
        Revolutions simulated and discarded first (10).
    per_revolution : int
        Output samples per revolution (32): attractor size, phase portrait, twin separation.
    phase : float
        Crank angle of the section past the initial crank angle, rad (0: the chapter's
        initial collinear position).
    twin : {True, "auto", False}
        Run the twin trajectories (two more runs of ``twin_revolutions``): they separate
        quasi-periodic from chaotic motion and catch chaos that is small in the section's
        channels. True (default): always; "auto": only when the section does not recur
        (cheaper; a recurring section is then "periodic" without the sensitivity check);
        False: never (a non-periodic run is then "non-periodic").
    twin_revolutions : int
        Length of the twin runs, revolutions (20).
    perturbation : float
        Position perturbation of the twin, m (1e-8).
    seed : int
        Seed of the perturbation direction.
    tol, max_period, decorrelation : float, int, float
        Classification thresholds (:func:`classify_section`).
    rtol : float
        IDA relative tolerance (1e-6).
    **simulate_options
        Passed to :func:`daeclear.simulate` (``atol``, ``max_step``, ``backend``,
        ``formulation`` when ``scene`` is a Scene, ...).

    Returns
    -------
    MotionAnalysis

    Raises
    ------
    SolveError
        If a run fails (partial result in ``.result``).
    """
    from ..assembly.assemble import assemble
    from ..solvers.ida import simulate

    revolutions = _check_int("revolutions", revolutions, 2)
    transient = _check_int("transient", transient, 0)
    per_revolution = _check_int("per_revolution", per_revolution, 4)
    twin_revolutions = _check_int("twin_revolutions", twin_revolutions, 2)
    if twin not in ("auto", True, False):
        raise SceneError(f"classify_motion: twin={twin!r}, must be 'auto', True or False.")
    for key in ("t_eval", "on_failure"):
        if key in simulate_options:
            raise SceneError(f"classify_motion: {key} is set by the analysis; it cannot be passed.")
    formulation = simulate_options.pop("formulation", None) or default_formulation(simulate_options.get("method", "ida"))
    model = scene if isinstance(scene, DAEModel) else assemble(scene, formulation)
    channels = section_channels(model) if channels is None else channels
    T = crank_period(model)
    offset = (float(phase) % (2.0 * math.pi)) / (2.0 * math.pi) * T
    if offset > T * (1.0 - _TIME_MATCH):
        offset = 0.0
    simulate_options.setdefault("store_steps", False)
    n_total = transient + revolutions
    result = simulate(model, n_total * T, t_eval=sampling_times(T, n_total, per_revolution=per_revolution,
                                                                offset=offset), rtol=rtol, **simulate_options)
    t0 = transient * T + offset
    section = poincare_section(result, channels, t0=t0, period=T)
    options = {"channels": list(section.channels), "revolutions": revolutions, "transient": transient,
               "per_revolution": per_revolution, "phase": float(phase),
               "twin": twin if isinstance(twin, str) else bool(twin), "twin_revolutions": twin_revolutions,
               "perturbation": float(perturbation), "seed": int(seed), "tol": float(tol),
               "max_period": int(max_period), "decorrelation": float(decorrelation), "rtol": float(rtol)}
    divergence, twins = None, None
    motion = classify_section(section, None, tol=tol, max_period=max_period, decorrelation=decorrelation)
    if twin is True or (twin == "auto" and motion.label == "non-periodic"):
        whole = transient * T + T * np.arange(revolutions)  # restart candidates: whole periods
        idx = _match_times(result, whole, T)
        free = [i for i, t in zip(idx, whole) if _all_free(result, float(t))]
        index = int(free[0]) if free else int(idx[0])
        grid = sampling_times(T, twin_revolutions, per_revolution=per_revolution, offset=offset)
        runs = [simulate(restart_model(model, result, index, perturbation=p, seed=seed), twin_revolutions * T,
                         t_eval=grid, rtol=rtol, **simulate_options) for p in (0.0, perturbation)]
        twins = (runs[0], runs[1])
        divergence = twin_divergence(runs[0], runs[1], section, reference=result,
                                     restart_time=float(result.t[index]), restart_in_contact=not free,
                                     perturbation=perturbation, offset=offset)
        motion = classify_section(section, divergence, tol=tol, max_period=max_period, decorrelation=decorrelation)
    return MotionAnalysis(result=result, section=section, motion=motion, divergence=divergence, twins=twins,
                          options=options)
