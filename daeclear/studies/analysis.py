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

This module runs the whole pipeline (:func:`classify_motion`) and is the public face of the
analysis (``daeclear.analysis``): it re-exports the parts, each in a module of its own job --
:mod:`~daeclear.studies.poincare` (periods, sampling, phase portraits, sections),
:mod:`~daeclear.studies.twin_runs` (restarts and twin evidence),
:mod:`~daeclear.studies.motion_class` (the rules) and :mod:`~daeclear.studies.motion_thresholds`
(their numbers). Only numpy here (no plotting); figures are in :mod:`daeclear.plot`.
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
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .accuracy import energy_balance, work_precision  # re-exported: daeclear.analysis.work_precision
# The parts of the analysis, re-exported: daeclear.analysis.<name> keeps working for every name it had.
from .motion_class import (  # noqa: F401
    MOTION_LABELS, MotionClass, MotionLabel, TwinReading, classify_section, read_twins)
from .motion_thresholds import (  # noqa: F401
    DEFAULT_DECORRELATION, DEFAULT_MAX_PERIOD, DEFAULT_PERTURBATION, DEFAULT_TOL, MIN_AMPLIFICATION, MIN_FIT_R2,
    MIN_POINTS, SATURATION_FRACTION, SENSITIVE_AMPLIFICATION, SIZE_QUANTILES, TIME_MATCH)
from .poincare import (CHANNELS, PhasePortrait, PoincareSection, crank_period, match_times, phase_portrait,
                       poincare_section, sampling_times, section_channels)
from .twin_runs import Divergence, RestartState, all_free, restart_state, twin_divergence, twin_evidence
from ..assembly.assemble import DAEModel
from ..errors import DaeclearError, SceneError  # noqa: F401  (DaeclearError: re-exported as before)
from ..options import default_formulation
from ..solver_options import UNSET, SolverOptions

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
    "RestartState",
    "TwinReading",
    "classify_motion",
    "classify_section",
    "crank_period",
    "energy_balance",
    "work_precision",
    "phase_portrait",
    "poincare_section",
    "restart_state",
    "section_channels",
    "read_twins",
    "sampling_times",
    "twin_divergence",
    "twin_evidence",
]


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
        The unperturbed and perturbed restarted runs (from the restart time on, at their true times).
    options : dict
        The options of the analysis (revolutions, transient, ...), with ``rtol`` and, under
        ``"solver"``, every solver setting of the runs (:meth:`daeclear.SolverOptions.to_dict`).
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
                    decorrelation: float = DEFAULT_DECORRELATION, rtol: float = UNSET,
                    options: SolverOptions | None = None, **simulate_options: Any) -> MotionAnalysis:
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
        Relative tolerance (default that of ``options``, 1e-6 without it).
    options : SolverOptions, optional
        The solver settings of every run (:class:`daeclear.SolverOptions`); a solver keyword given
        explicitly (``rtol``, ``atol``, ``method``, ...) overrides the same setting, as in
        :func:`daeclear.simulate`. ``formulation`` is used when ``scene`` is a Scene.
    **simulate_options
        Passed to :func:`daeclear.simulate`: solver settings (``atol``, ``max_step``, ``backend``,
        ``formulation``, ...), ``store_steps`` (:class:`daeclear.SaveAt`'s ``steps``) and ``progress``.

    Returns
    -------
    MotionAnalysis

    Raises
    ------
    SolveError
        If a run fails (partial result in ``.result``).
    """
    from ..assembly.assemble import assemble
    from ..save_at import SaveAt
    from ..solvers.dispatch import simulate

    revolutions = _check_int("revolutions", revolutions, 2)
    transient = _check_int("transient", transient, 0)
    per_revolution = _check_int("per_revolution", per_revolution, 4)
    twin_revolutions = _check_int("twin_revolutions", twin_revolutions, 2)
    if twin not in ("auto", True, False):
        raise SceneError(f"classify_motion: twin={twin!r}, must be 'auto', True or False.")
    for key in ("t_eval", "t_eval_step", "on_failure", "t0", "y0"):
        if key in simulate_options:
            raise SceneError(f"classify_motion: {key} is set by the analysis; it cannot be passed.")
    if options is not None and not isinstance(options, SolverOptions):
        raise SceneError(f"classify_motion: options={options!r}, must be None or a daeclear.SolverOptions.")
    solver_keys = {f.name for f in dataclasses.fields(SolverOptions)}
    given = {k: simulate_options.pop(k) for k in list(simulate_options) if k in solver_keys}
    settings = (options or SolverOptions()).merged(where="classify_motion", rtol=rtol, **given)
    formulation = settings.formulation or default_formulation(settings.method)
    model = scene if isinstance(scene, DAEModel) else assemble(scene, formulation, track_work=settings.track_work)
    channels = section_channels(model) if channels is None else channels
    T = crank_period(model)
    offset = (float(phase) % (2.0 * math.pi)) / (2.0 * math.pi) * T
    if offset > T * (1.0 - TIME_MATCH):
        offset = 0.0
    output = {"steps": simulate_options.pop("store_steps", False)}  # what SaveAt takes besides the times
    output.update({k: simulate_options.pop(k) for k in ("stream_to", "keep_data", "max_points")
                   if k in simulate_options})
    n_total = transient + revolutions
    result = simulate(model, n_total * T, options=settings, **simulate_options,
                      save=SaveAt(times=sampling_times(T, n_total, per_revolution=per_revolution, offset=offset),
                                  **output))
    t0 = transient * T + offset
    section = poincare_section(result, channels, t0=t0, period=T)
    recorded = {"channels": list(section.channels), "revolutions": revolutions, "transient": transient,
               "per_revolution": per_revolution, "phase": float(phase),
               "twin": twin if isinstance(twin, str) else bool(twin), "twin_revolutions": twin_revolutions,
               "perturbation": float(perturbation), "seed": int(seed), "tol": float(tol),
               "max_period": int(max_period), "decorrelation": float(decorrelation), "rtol": settings.rtol,
               "solver": settings.to_dict()}
    divergence, twins = None, None
    motion = classify_section(section, None, tol=tol, max_period=max_period, decorrelation=decorrelation)
    if twin is True or (twin == "auto" and motion.label == "non-periodic"):
        whole = transient * T + T * np.arange(revolutions)  # restart candidates: whole periods
        idx = match_times(result, whole, T)
        free = [i for i, t in zip(idx, whole) if all_free(result, float(t))]
        index = int(free[0]) if free else int(idx[0])
        t_r = float(result.t[index])  # the twins continue the run from t_r, at the true time
        grid = t_r + sampling_times(T, twin_revolutions, per_revolution=per_revolution, offset=offset)
        t_end = max(t_r + twin_revolutions * T, float(grid[-1]))
        runs = []
        for p in (0.0, perturbation):
            start = restart_state(model, result, index, perturbation=p, seed=seed)
            runs.append(simulate(model, t_end, t0=start.t0, y0=start.y0, options=settings, **simulate_options,
                                 save=SaveAt(times=grid, **output)))
        twins = (runs[0], runs[1])
        divergence = twin_divergence(runs[0], runs[1], section, reference=result, restart_time=t_r,
                                     restart_in_contact=not free, perturbation=perturbation, offset=offset)
        motion = classify_section(section, divergence, tol=tol, max_period=max_period, decorrelation=decorrelation)
    return MotionAnalysis(result=result, section=section, motion=motion, divergence=divergence, twins=twins,
                          options=recorded)

