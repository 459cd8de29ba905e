"""Twin trajectories: restart a run on its attractor, perturb one twin, measure how they separate.

:func:`restart_state` gives the (perturbed) state to restart from, :func:`twin_divergence` measures the
twins' separation and section points, and :func:`twin_evidence` turns any such pair of trajectories
into the numbers the classification (:mod:`daeclear.studies.motion_class`) reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .motion_thresholds import DEFAULT_MAX_PERIOD, MIN_AMPLIFICATION, SATURATION_FRACTION, TIME_MATCH
from .poincare import PoincareSection, match_times, recurrence_defects
from ..assembly.assemble import DAEModel
from ..core.errors import DaeclearError

if TYPE_CHECKING:
    from ..results.result import Result

__all__ = ["Divergence", "RestartState", "all_free", "restart_state", "twin_divergence", "twin_evidence"]


def _state_selection(result: Result) -> list[int]:
    """Columns of y that are positions or velocities (states with a unit; multipliers have none)."""
    return [i for i, name in enumerate(result.state_names) if result.units.get(name, "")]


class RestartState(NamedTuple):
    """Where a restarted run starts: ``simulate(model, t0 + span, t0=state.t0, y0=state.y0)``."""

    t0: float
    y0: NDArray[np.float64]


def restart_state(model: DAEModel, result: Result, index: int, *, perturbation: float = 0.0,
                  seed: int = 0) -> RestartState:
    """The time and state of ``result`` at output ``index``, optionally perturbed, to restart from.

    ``simulate(model, t0 + span, t0=t0, y0=y0)`` continues the run from there (*Restarts from a state*
    in docs/user_guide.md).

    Parameters
    ----------
    model, result, index : DAEModel, Result, int
        A run of ``model`` and the output index of the restart state.
    perturbation, seed : float, int
        Euclidean norm (over the positions q, m and rad mixed) of a random perturbation of the
        positions, projected on the null space of the constraint Jacobian so the joints stay
        closed to first order (0: none), and the seed of its direction.

    Returns
    -------
    RestartState
        The output time and a copy of the (perturbed) state.
    """
    t_restart = float(result.t[index])
    y = np.array(result.y[index], dtype=float)
    n_q = model.n_q
    if perturbation:
        rng = np.random.default_rng(seed)
        u = rng.standard_normal(n_q)
        q, v = y[:n_q], y[n_q:2 * n_q]
        if model.n_constraints:  # along the constraint manifold: project on the null space of Phi_q
            Phi_q = np.array(model.kinematics(q, v, t_restart, model.parameter_values)[1],
                             dtype=float).reshape(model.n_constraints, n_q)
            _, sv, vt = np.linalg.svd(Phi_q)
            rank = int(np.sum(sv > 1e-10 * sv[0])) if sv.size and sv[0] > 0 else 0
            null = vt[rank:].T
            u = null @ (null.T @ u)
        norm = float(np.linalg.norm(u))
        if norm <= 1e-12:
            raise DaeclearError(f"restart_state: scene {model.scene_name!r} has no free position to perturb "
                                "(its joints and drivers fix every coordinate).")
        y[:n_q] += perturbation * u / norm
    return RestartState(t_restart, y)


def all_free(result: Result, t: float) -> bool:
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
    t, distance : ndarray (m,)
        Times since the restart (s) and the RMS over positions and velocities of |a - b| / (attractor
        range of the state).
    restart_time, restart_in_contact : float, bool
        Time of the restart state in the original run (s); True when no section time was in free
        flight (the restart's latched approach speed is then the current penetration rate).
    perturbation, d0, d_start : float
        Position perturbation (m, norm over q), the separation it gives, and the separation at the
        first sample after the restart (integration noise when larger), which the growth starts from.
    d_saturation, amplification : float
        Median separation over the second half of the twin run, and d_saturation / d_start.
    lyapunov, r_squared, fit_window : float, float, (float, float)
        Slope of ln(distance) against time over the growth window (1/s), its fit's R^2 and the fitted
        times since restart; nan when the separation grew less than MIN_AMPLIFICATION times.
    section_gap, decorrelation : float
        RMS distance of the twins' late section points (attractor units), and that over sqrt(2) x the
        section's RMS spread: about 1 for unrelated points of the attractor, << 1 for twins together.
    period, twin_recurrence : float
        T (s), and the recurrence defect of the unperturbed twin's late section points.
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

    The array half of :func:`twin_divergence`, public so that any pair of trajectories (a small
    ODE, a map, measured data) is judged by the same numbers as a mechanism's twins.

    Parameters
    ----------
    t, distance : array_like (m,)
        Times since the restart (s, t[0] = 0) and the twins' normalised separation (distance[0]: the
        perturbation).
    points_a, points_b : array_like (n, d)
        The twins' section points, one row per revolution, in the units of the reference ``section``.
    restart_time, restart_in_contact, perturbation, max_period : float, bool, float, int
        Recorded as evidence; the longest period of the unperturbed twin's recurrence check.
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
        defects = recurrence_defects(na, max_period)  # {} for one point
        recurrence = min(defects.values()) if defects else float("nan")
    return Divergence(t=t, distance=distance, restart_time=float(restart_time),
                      restart_in_contact=bool(restart_in_contact), perturbation=float(perturbation), d0=d0,
                      d_start=d_start, d_saturation=d_sat, amplification=float(amplification), lyapunov=lyapunov,
                      r_squared=r2, fit_window=window, decorrelation=decorrelation, period=section.period,
                      section_gap=gap, twin_recurrence=recurrence)


def twin_divergence(twin_a: Result, twin_b: Result, section: PoincareSection, *, reference: Result,
                    restart_time: float | None = None, restart_in_contact: bool = False,
                    perturbation: float = float("nan"), offset: float = 0.0) -> Divergence:
    """Separation, Lyapunov estimate and decorrelation of two twin runs (via :func:`twin_evidence`).

    Parameters
    ----------
    twin_a, twin_b : Result
        Unperturbed and perturbed runs from one restart state (:func:`restart_state`), on the same
        output times, containing the section times ``offset + k T`` (s) from the restart on.
    section, reference : PoincareSection, Result
        The reference run's section and the run (each state's attractor range over the section's window).
    restart_time, restart_in_contact, perturbation : float, bool, float
        Recorded as evidence (``restart_time`` defaults to the twins' first output time).
    """
    if twin_a.t.shape != twin_b.t.shape or not np.allclose(twin_a.t, twin_b.t, rtol=0, atol=1e-12):
        raise DaeclearError("twin_divergence: the twin runs have different output times.")
    T = section.period
    cols = _state_selection(reference)
    window = reference.window_mask(section.t[0] if len(section) else None, None)
    y_ref = np.asarray(reference.y)[window][:, cols]
    ranges = np.ptp(y_ref, axis=0) if y_ref.shape[0] else np.zeros(len(cols))
    units = [reference.units[reference.state_names[i]] for i in cols]
    top = np.array([np.max(ranges[[v == u for v in units]]) for u in units])  # largest range of the same unit
    keep = (ranges > 1e-9 * top) & (ranges > 0)
    idx = [c for c, k in zip(cols, keep) if k]
    scale = ranges[keep]
    diff = (np.asarray(twin_a.y)[:, idx] - np.asarray(twin_b.y)[:, idx]) / scale
    distance = np.sqrt(np.mean(diff**2, axis=1)) if idx else np.zeros(twin_a.n_times)
    start = float(twin_a.t[0]) if twin_a.n_times else 0.0
    t = np.asarray(twin_a.t) - start  # times since the restart
    times: NDArray[np.floating[Any]] = np.zeros(0)
    if twin_a.n_times:  # the section times offset + k T inside [start, end]
        first = offset + T * math.ceil((start - offset) / T - TIME_MATCH)
        n_sec = int(math.floor((float(twin_a.t[-1]) - first) / T + TIME_MATCH)) + 1
        times = first + T * np.arange(max(n_sec, 0))
    pa = pb = np.zeros((0, len(section.channels)))
    if times.size >= 2:
        ia, ib = match_times(twin_a, times, T), match_times(twin_b, times, T)
        pa = np.column_stack([np.asarray(twin_a[c], dtype=float)[ia] for c in section.channels])
        pb = np.column_stack([np.asarray(twin_b[c], dtype=float)[ib] for c in section.channels])
    return twin_evidence(t, distance, pa, pb, section, restart_time=start if restart_time is None else restart_time,
                         restart_in_contact=restart_in_contact, perturbation=perturbation)

