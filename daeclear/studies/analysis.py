"""Nonlinear-dynamics analysis of runs, ``daeclear.analysis``: the pipeline and its re-exported parts.

:func:`classify_motion` samples a run (:func:`sampling_times`), takes its Poincaré section after a
transient, restarts twin runs on the attractor (one perturbed) and classifies the motion
(:func:`classify_section`). ``docs/nonlinear_dynamics.md`` states the method, thresholds and limits.

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

from .accuracy import energy_balance, work_precision
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
from ..core.errors import DaeclearError, SceneError  # noqa: F401  (DaeclearError: re-exported as before)
from ..core.options import default_formulation, integer
from ..solvers.solver_options import UNSET, SolverOptions

if TYPE_CHECKING:
    from ..results.result import Result
    from ..model.scene import Scene

__all__ = ["CHANNELS", "MOTION_LABELS", "Divergence", "MotionAnalysis", "MotionClass", "PhasePortrait",
           "PoincareSection", "RestartState", "TwinReading", "classify_motion", "classify_section", "crank_period",
           "energy_balance", "work_precision", "phase_portrait", "poincare_section", "restart_state",
           "section_channels", "read_twins", "sampling_times", "twin_divergence", "twin_evidence"]


@dataclass(frozen=True)
class MotionAnalysis:
    """Everything :func:`classify_motion` computed: the reference run from t = 0 (``result``), its
    ``section`` after the transient, the ``motion`` class, the twin evidence and runs (``divergence``,
    ``twins``: unperturbed and perturbed, from the restart time on; None without twins) and the
    analysis ``options`` (with ``rtol`` and, under ``"solver"``, :meth:`daeclear.SolverOptions.to_dict`)."""

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


def classify_motion(scene: Scene | DAEModel, *, channels: Sequence[str] | None = None, revolutions: int = 30,
                    transient: int = 10, per_revolution: int = 32, phase: float = 0.0, twin: bool | str = True,
                    twin_revolutions: int = 20, perturbation: float = DEFAULT_PERTURBATION, seed: int = 0,
                    tol: float = DEFAULT_TOL, max_period: int = DEFAULT_MAX_PERIOD,
                    decorrelation: float = DEFAULT_DECORRELATION, rtol: float = UNSET,
                    options: SolverOptions | None = None, **simulate_options: Any) -> MotionAnalysis:
    """Simulate a scene, take its Poincaré section after a transient and classify the motion.

    Parameters
    ----------
    scene, channels : Scene or DAEModel, sequence of str
        A driven mechanism (its driver sets the period T) and the section channels (default
        :func:`section_channels`).
    revolutions, transient, per_revolution : int
        Revolutions analysed (30: revolutions + 1 section points), after ``transient`` discarded ones
        (10); output samples per revolution (32).
    phase : float
        Crank angle of the section past the initial crank angle, rad.
    twin : {True, "auto", False}
        Run the twin trajectories (two more runs of ``twin_revolutions``, 20) that tell quasi-periodic
        from chaotic motion: always, only when the section does not recur, or never.
    perturbation, seed : float, int
        Position perturbation of the twin, m (1e-8), and the seed of its direction.
    tol, max_period, decorrelation : float, int, float
        Classification thresholds (:func:`classify_section`).
    rtol, options : float, SolverOptions
        The runs' solver settings; explicit solver keywords override ``options``, as in :func:`daeclear.simulate`.
    **simulate_options
        Passed to :func:`daeclear.simulate`: solver settings, ``store_steps`` (SaveAt's ``steps``), ``progress``.

    Returns
    -------
    MotionAnalysis

    Raises
    ------
    SolveError
        If a run fails (partial result in ``.result``).
    """
    from ..assembly.assemble import assemble
    from ..solvers.save_at import SaveAt
    from ..solvers.dispatch import simulate

    revolutions = integer(revolutions, where="classify_motion", field="revolutions", low=2)
    transient = integer(transient, where="classify_motion", field="transient", low=0)
    per_revolution = integer(per_revolution, where="classify_motion", field="per_revolution", low=4)
    twin_revolutions = integer(twin_revolutions, where="classify_motion", field="twin_revolutions", low=2)
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

