"""What the chapter reads from a run of the slider-crank, as numbers (section 4.5, Fig. 4.28).

The chapter describes Fig. 4.28 in words (a velocity "smooth and close to the ideal joint
simulation", slider and guide "in permanent contact for long periods", impacts giving "visible high
peaks in the crank moment"). :func:`measure` measures them on sampled channels (numpy only), and
:data:`FIG_4_28` with :func:`verdict` states them as thresholds and checks which are met.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ContactPeriods", "contact_periods", "relative_rms", "revolution_peaks", "onset_times", "Criterion",
           "FIG_4_28", "verdict", "measure", "LONG_CONTACT"]


@dataclass(frozen=True)
class ContactPeriods:
    """Periods of contact ``[starts[k], ends[k])`` within a sampled span of length ``span`` (s); each
    sample stands for the interval ``dt`` after it (a period cut by the span counts its part inside)."""

    starts: NDArray[np.float64]
    ends: NDArray[np.float64]
    span: float

    @property
    def durations(self) -> NDArray[np.float64]:
        return self.ends - self.starts

    @property
    def count(self) -> int:
        return int(self.starts.size)

    @property
    def fraction(self) -> float:
        """Fraction of the span in contact."""
        return float(np.sum(self.durations) / self.span) if self.span > 0 else float("nan")

    def long_fraction(self, min_duration: float) -> float:
        """Fraction of the span covered by periods lasting at least ``min_duration`` s."""
        d = self.durations
        return float(np.sum(d[d >= min_duration]) / self.span) if self.span > 0 else float("nan")

    def longest(self) -> float:
        """The longest period, s (0 without contact)."""
        return float(np.max(self.durations)) if self.count else 0.0

    def median(self) -> float:
        """The median period, s (nan without contact)."""
        return float(np.median(self.durations)) if self.count else float("nan")


def contact_periods(t: ArrayLike, in_contact: ArrayLike) -> ContactPeriods:
    """The periods where ``in_contact > 0.5`` on uniform sample times ``t`` (s).

    Raises ValueError when ``t`` is not uniformly spaced (relative 1e-6) or the arrays differ.
    """
    t = np.asarray(t, dtype=float).ravel()
    on = np.asarray(in_contact, dtype=float).ravel() > 0.5
    if t.shape != on.shape or t.size < 2:
        raise ValueError(f"contact_periods: t ({t.size}) and in_contact ({on.size}) must have the same size >= 2.")
    steps = np.diff(t)
    dt = float(np.mean(steps))
    if not dt > 0 or np.max(np.abs(steps - dt)) > 1e-6 * dt:
        raise ValueError("contact_periods: t must be uniformly spaced and increasing (dense output, t_eval).")
    edges = np.diff(np.r_[0, on.astype(np.int8), 0])
    first = np.flatnonzero(edges == 1)
    last = np.flatnonzero(edges == -1)  # one past the period's last sample
    return ContactPeriods(t[0] + first * dt, t[0] + last * dt, t.size * dt)


def relative_rms(x: ArrayLike, reference: ArrayLike) -> float:
    """RMS of ``x - reference`` over the range (peak to peak) of ``reference``."""
    x, ref = np.asarray(x, dtype=float), np.asarray(reference, dtype=float)
    if x.shape != ref.shape or x.size == 0:
        raise ValueError(f"relative_rms: shapes {x.shape} and {ref.shape} must be equal and non-empty.")
    return float(np.sqrt(np.mean((x - ref) ** 2)) / np.ptp(ref))


def revolution_peaks(t: ArrayLike, x: ArrayLike, period: float, t0: float | None = None) -> NDArray[np.float64]:
    """The largest ``|x|`` in each whole revolution ``[t0 + k period, t0 + (k+1) period)`` (t0: the first t);
    one value, over all of ``t``, when it spans less than one revolution."""
    times, size = np.asarray(t, dtype=float), np.abs(np.asarray(x, dtype=float))
    start = float(times[0]) if t0 is None else float(t0)
    n = int(np.floor((times[-1] - start) / period + 1e-9))
    if n == 0:
        return np.array([np.max(size)])
    k = np.floor((times - start) / period + 1e-9).astype(int)
    return np.array([np.max(size[k == i]) for i in range(n) if np.any(k == i)])


def onset_times(events: Any, joint: str, t0: float = -np.inf, t1: float = np.inf, *, same: float = 1e-9) -> NDArray:
    """Times of the corner onsets of clearance joint ``joint`` in ``[t0, t1)``; onsets less than
    ``same`` s apart (both corners of a face landing) count once. ``events``: a result's ``events``."""
    times = np.sort([e.t for e in events.of(joint, "onset") if not e.pair.endswith("_face") and t0 <= e.t < t1])
    if times.size == 0:
        return times
    return times[np.r_[True, np.diff(times) > same]]


#: A "long" contact period, in crank revolutions (1/8: 45 degrees of crank, 1.5 ms at 5000 rpm).
LONG_CONTACT = 0.125


def measure(run: Any, ideal: Any, *, joint: str, period: float, t0: float, t1: float) -> dict[str, float]:
    """The numbers of :data:`FIG_4_28` (and a few more) of ``run`` against ``ideal`` (results on the same
    uniform output times) over ``[t0, t1]``, a window of whole crank periods ``period`` (s)."""
    t, ti = np.asarray(run.t), np.asarray(ideal.t)
    pad = 1e-9 * period
    w, wi = (t >= t0 - pad) & (t <= t1 + pad), (ti >= t0 - pad) & (ti <= t1 + pad)
    if w.sum() != wi.sum() or not np.allclose(t[w], ti[wi], rtol=0.0, atol=1e-12):
        raise ValueError("measure: the run and the ideal run must have the same output times in the window.")
    tw = t[w]
    contact = np.asarray(run[f"{joint}.in_contact"])[w] > 0.5
    periods = contact_periods(tw[:-1], contact[:-1])  # [t0, t1)
    revolutions = (tw[-1] - tw[0]) / period
    v, vi = np.asarray(run["slider.vx"])[w], np.asarray(ideal["slider.vx"])[wi]
    moment, moment_ideal = np.asarray(run["drive.moment"])[w], np.asarray(ideal["drive.moment"])[wi]
    peaks = revolution_peaks(tw, moment, period)
    impacts = onset_times(run.events, joint, tw[0], tw[-1])
    return {
        "revolutions": float(revolutions),
        "contact_fraction": periods.fraction,
        "long_contact_fraction": periods.long_fraction(LONG_CONTACT * period),
        "contact_periods_per_rev": periods.count / revolutions,
        "median_contact_ms": periods.median() * 1e3,
        "longest_contact_ms": periods.longest() * 1e3,
        "velocity_rms_rel": relative_rms(v, vi),
        "velocity_max_rel": float(np.max(np.abs(v - vi)) / np.ptp(vi)),
        # the same RMS over the samples in free flight only: is a smooth velocity evidence of contact?
        "velocity_rms_rel_free": (float(np.sqrt(np.mean((v - vi)[~contact] ** 2)) / np.ptp(vi))
                                  if np.any(~contact) else float("nan")),
        "impacts_per_rev": impacts.size / revolutions,
        "moment_peak_median_Nm": float(np.median(peaks)),
        "moment_peak_max_Nm": float(np.max(peaks)),
        "moment_peak_ideal_Nm": float(np.max(np.abs(moment_ideal))),
        "moment_peak_ratio": float(np.median(peaks) / np.max(np.abs(moment_ideal))),
        "max_tilt_mrad": float(np.max(np.abs(np.asarray(run[f"{joint}.tilt"])[w])) * 1e3),
        "max_abs_eta": float(np.max(np.abs(np.asarray(run[f"{joint}.eta"])[w]))),
    }


@dataclass(frozen=True)
class Criterion:
    """One statement of the chapter as a threshold on a measured number."""

    key: str  # the measured number it reads
    low: float  # it must be >= low ...
    high: float  # ... and <= high
    statement: str  # the chapter's words
    reading: str  # how we measure them

    def met(self, value: float) -> bool:
        return bool(np.isfinite(value) and self.low <= value <= self.high)


#: Fig. 4.28 (c = 0.5 mm), section 4.5's description as numbers over the analysed span.
FIG_4_28: tuple[Criterion, ...] = (
    Criterion("velocity_rms_rel", 0.0, 0.02, "The slider velocity diagram is smooth and close to the ideal joint "
              "simulation.", "RMS(v - v_ideal) <= 2 % of the ideal's range"),
    Criterion("contact_fraction", 0.5, 1.0, "[...] the slider and guide surfaces are in permanent contact for long "
              "periods.", "in contact >= 50 % of the time"),
    Criterion("long_contact_fraction", 0.25, 1.0, "[...] in permanent contact for long periods.",
              ">= 25 % of the time in contacts lasting >= 1/8 revolution"),
    Criterion("impacts_per_rev", 1.0, np.inf, "Some sudden changes in the velocity are due to the impacts between "
              "the slider and guide surfaces.", ">= 1 impact per revolution"),
    Criterion("moment_peak_ratio", 1.2, np.inf, "[...] leading to visible high peaks in the crank moment diagram.",
              "median per-revolution peak crank moment >= 1.2 x the ideal's peak"),
)


def verdict(measured: Mapping[str, float], criteria: Sequence[Criterion] = FIG_4_28) -> tuple[bool, list[str]]:
    """Whether ``measured`` meets every criterion, and the keys of those it misses."""
    missed = [c.key for c in criteria if not c.met(float(measured.get(c.key, np.nan)))]
    return not missed, missed
