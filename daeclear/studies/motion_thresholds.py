"""The numbers of the motion analysis in one place (its section, twin and classification modules all
read them); ``docs/nonlinear_dynamics.md`` gives the reason and the check behind each."""

from __future__ import annotations

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
TIME_MATCH = 1e-9  # output times match section times to this fraction of the period
