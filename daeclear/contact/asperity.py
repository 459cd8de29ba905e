"""Asperity contact of rough surfaces in a mixed lubricated journal bearing (Greenwood and Tripp).

Greenwood and Tripp (1970) give the mean asperity pressure of two rough surfaces a gap ``h`` apart
as ``p_a = K E' F_{5/2}(h / sigma)``, ``sigma`` the composite RMS roughness, ``E'`` the composite
modulus (``1/E' = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2``),
``K = 16 pi sqrt(2) / 15 (eta sigma beta)^2 sqrt(sigma / beta)`` and, with the fit of Hu et al.
(1994), ``F_{5/2}(x) = 4.4086e-5 (4 - x)^6.804`` for ``x < 4``, 0 beyond. Integrated over the
journal's film near its minimum, ``h ~ h_min + c eps phi^2 / 2``, the load has a closed form
(docs/lubrication.md, "Mixed lubrication"); it acts along the line of centres.
"""

from __future__ import annotations

import math
from typing import Any

from . import _backend as B

__all__ = ["ASPERITY_CUTOFF", "asperity_load", "asperity_pressure", "greenwood_tripp_k"]

#: The roughness product eta sigma beta and the asperities' sigma / beta (typical values of
#: Greenwood and Tripp 1970, used by Hu et al. 1994 and most mixed-lubrication bearing studies).
ROUGHNESS_PRODUCT = 0.04
SLOPE_RATIO = 1e-3
#: Hu et al.'s fit of F_{5/2}: FACTOR (CUTOFF - x)^EXPONENT for x < CUTOFF.
FACTOR, EXPONENT, ASPERITY_CUTOFF = 4.4086e-5, 6.804, 4.0
# the integral over the arc, int (1 - s^2)^n ds on (-1, 1) = sqrt(pi) Gamma(n + 1) / Gamma(n + 3/2)
_ARC = math.sqrt(math.pi) * math.exp(math.lgamma(EXPONENT + 1.0) - math.lgamma(EXPONENT + 1.5))
#: The smallest eccentricity ratio the arc's curvature is taken at (asperities touch only near eps = 1).
_EPS_FLOOR = 0.5


def greenwood_tripp_k() -> float:
    """K = 16 pi sqrt(2) / 15 (eta sigma beta)^2 sqrt(sigma / beta) (dimensionless)."""
    return 16.0 * math.pi * math.sqrt(2.0) / 15.0 * ROUGHNESS_PRODUCT**2 * math.sqrt(SLOPE_RATIO)


def asperity_pressure(film_parameter: Any, modulus: Any) -> Any:
    """Mean asperity pressure (Pa) at the film parameter ``h / sigma``, composite modulus ``modulus`` (Pa)."""
    u = B.fmax(ASPERITY_CUTOFF - film_parameter, 0.0)
    return greenwood_tripp_k() * modulus * FACTOR * u**EXPONENT


def asperity_load(eps: Any, clearance: Any, roughness: Any, radius: Any, length: Any, modulus: Any) -> Any:
    """The asperities' load on the journal (N, towards the bearing's centre) at eccentricity ratio ``eps``:
    the pressure integrated over the arc where ``h = c (1 - eps cos phi) < 4 sigma``, the film taken
    parabolic there: ``L R K E' A sqrt(2 sigma / (c eps)) sqrt(pi) Gamma(n+1) / Gamma(n+3/2) u^(n+1/2)``,
    ``u = 4 - c (1 - eps) / sigma``."""
    u = B.fmax(ASPERITY_CUTOFF - clearance * (1.0 - eps) / roughness, 0.0)
    curvature = clearance * B.fmax(eps, _EPS_FLOOR) / (2.0 * roughness)  # (4 - h / sigma) = u - curvature phi^2
    return (length * radius * greenwood_tripp_k() * modulus * FACTOR * _ARC * u ** (EXPONENT + 0.5)
            / B.sqrt(curvature))
