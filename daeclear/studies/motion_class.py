"""Motion classes: the rules that read a Poincaré section and the twin evidence as one verdict.

:func:`classify_section` is the one place where the section's recurrence test and the twin test (read
once by :func:`read_twins`) meet, so that the rules, in order, read in one place
(``docs/nonlinear_dynamics.md`` gives them with their checks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .motion_thresholds import (DEFAULT_DECORRELATION, DEFAULT_MAX_PERIOD, DEFAULT_TOL, MIN_AMPLIFICATION, MIN_FIT_R2,
                                MIN_POINTS, SENSITIVE_AMPLIFICATION)
from .poincare import PoincareSection, recurrence_defects
from .twin_runs import Divergence
from ..core.errors import SceneError

__all__ = ["MOTION_LABELS", "MotionClass", "MotionLabel", "TwinReading", "classify_section", "read_twins"]

MotionLabel = Literal["periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined"]
MOTION_LABELS: tuple[str, ...] = ("periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined")


def _clusters(p: NDArray[np.float64], tol: float) -> int:
    """Leader clustering in the max-norm: a point opens a new cluster when farther than tol from every leader."""
    leaders: list[NDArray[np.float64]] = []
    for row in p:
        if not any(np.max(np.abs(row - q)) <= tol for q in leaders):
            leaders.append(row)
    return len(leaders)


@dataclass(frozen=True)
class MotionClass:
    """The motion class of a run and the evidence behind it.

    Attributes
    ----------
    label : {"periodic", "quasi-periodic", "chaotic", "non-periodic", "uncertain", "undetermined"}
        "non-periodic": no recurrence, and no (or missing, or contradictory) twin evidence to tell
        quasi-periodic from chaotic; "uncertain": the section recurs but the twin test contradicts it;
        "undetermined": too few section points or no attractor size.
    period, reason : int, str
        k for "periodic" (revolutions), else 0; one sentence with the deciding numbers.
    evidence : dict
        Plain numbers and strings: ``periodicity_defect`` (attractor units) at ``best_period``,
        ``defect_k1`` ... ``defect_kK``, ``n_clusters`` (at ``tol``), ``spread`` and, with twins,
        :meth:`Divergence.evidence`.
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

    ``complete``: amplification and decorrelation are numbers (else the twin test can neither
    confirm nor contradict); ``exponent``: a positive Lyapunov estimate from a usable fit (growth >=
    MIN_AMPLIFICATION, R^2 >= MIN_FIT_R2); ``sensitive``: an exponent with growth >=
    SENSITIVE_AMPLIFICATION; ``decorrelated``: decorrelation >= the threshold; ``apart``: the twins'
    late section points farther apart than ``tol``; ``numbers``: the twin numbers as one clause.
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

    A label never contradicts its own evidence, and missing (nan) twin numbers are reported as
    missing. Rules, in order (docs/nonlinear_dynamics.md; "exponent" and "sensitive" as in
    :class:`TwinReading`):

    1. fewer than ``min_points`` points, or unknown attractor size: "undetermined";
    2. the section recurs (smallest k <= ``max_period`` with max_j max_channel |p[j+k] - p[j]| / size
       <= ``tol``): "periodic" (k) without twins or with missing twin numbers; "chaotic" when the
       twins are sensitive and decorrelated after a free-flight restart (chaos small in the section's
       channels); "uncertain" when they are sensitive, have an exponent or end apart; else "periodic";
    3. no recurrence: "non-periodic" without twins or with missing numbers; "chaotic" when the twins
       decorrelate with an exponent, or are sensitive; "quasi-periodic" when they stay together
       without one; otherwise "non-periodic", both numbers given.

    Parameters
    ----------
    section : PoincareSection
        With a finite `size` (a densely sampled run).
    divergence : Divergence, optional
        From :func:`twin_divergence` or :func:`twin_evidence`.
    tol : float
        Recurrence tolerance, fraction of the attractor size (0.05); also the largest twins' section gap.
    max_period, decorrelation, min_points : int, float, int
        Longest period looked for (8 revolutions), decorrelation threshold (0.3), fewest points (8).

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
    defects = recurrence_defects(p, max_period)
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
            reasons: list[str] = []
            if twins.exponent:
                reasons.append(f"a positive exponent resolved over >= {MIN_AMPLIFICATION:g}-fold growth "
                           f"(R^2 >= {MIN_FIT_R2:g})")
            if twins.apart:
                reasons.append(f"section gap > tol {tol:g}")
            if twins.sensitive and twins.decorrelated:
                reasons.append("growth that would mark chaos small in the section, but the twins were restarted "
                           "in contact (not faithful copies)")
            return MotionClass("uncertain", 0, evidence,
                               f"section test says period {k} ({recurs}); twin test disagrees ({'; '.join(reasons)}): "
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

