"""Hydrodynamic film forces of a lubricated journal bearing (docs/lubrication.md: derivation, validation).

Film ``h = c (1 + eps cos theta)``; Reynolds' equation for ``theory="short"`` (Ocvirk), ``"long"``
(Sommerfeld) or ``"finite"`` (:mod:`daeclear.contact.finite_bearing`), cavitation ``"full"`` or
``"half"`` (Guembel); every force integral in closed form on floats, numpy and CasADi.
"""

from __future__ import annotations

import math
import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar, Self

import numpy as np

from ..core.errors import SceneError
from . import _backend as B
from ._checks import check_number, set_field
from .base import NormalLaw
from .asperity import ASPERITY_CUTOFF
from .finite_bearing import finite_film_force
from .geometry import sigma_sum
from .normal import LankaraniNikravesh

__all__ = ["CAVITATION", "HydrodynamicBearing", "THEORIES", "film_integrals", "shear_torques"]

#: The film theories and the cavitation options (the first of each is the default).
THEORIES: tuple[str, ...] = ("short", "long", "finite")
CAVITATION: tuple[str, ...] = ("half", "full")
#: Largest eccentricity ratio of the symbolic film force (it diverges at 1; the dry law acts before).
EPS_CAP = 1.0 - 1e-6


def _anomaly(theta: Any, beta: Any) -> Any:
    """psi(theta), tan(psi/2) = sqrt((1-eps)/(1+eps)) tan(theta/2), continuous (beta < 1: no wrap)."""
    return theta - 2.0 * B.atan2(beta * B.sin(theta), 1.0 + beta * B.cos(theta))


def _trig(a0: Any, a1: Any, b1: Any, a2: Any, b2: Any, psi1: Any, psi2: Any) -> Any:
    """Integral over (psi1, psi2) of a0 + a1 cos + b1 sin + a2 cos 2psi + b2 sin 2psi."""
    def prim(psi: Any) -> Any:
        return (a0 * psi + a1 * B.sin(psi) - b1 * B.cos(psi) + 0.5 * a2 * B.sin(2.0 * psi)
                - 0.5 * b2 * B.cos(2.0 * psi))
    return prim(psi2) - prim(psi1)


def film_integrals(eps: Any, theta1: Any, theta2: Any) -> dict[str, Any]:
    """Integrals over (theta1, theta2) of {1, cos, sin, cos^2, sin^2, sin cos} / (1 + eps cos)^3, keys
    ``"1", "c", "s", "cc", "ss", "sc"`` (0 <= eps < 1)."""
    q = 1.0 - eps * eps
    sq = B.sqrt(q)
    beta = eps / (1.0 + sq)
    p1, p2 = _anomaly(theta1, beta), _anomaly(theta2, beta)
    q2, q3, q5 = q * q, q * sq, q * q * sq
    return {
        "1": _trig(1.0 + 0.5 * eps * eps, -2.0 * eps, 0.0, 0.5 * eps * eps, 0.0, p1, p2) / q5,
        "c": _trig(-1.5 * eps, 1.0 + eps * eps, 0.0, -0.5 * eps, 0.0, p1, p2) / q5,
        "s": _trig(0.0, 0.0, 1.0, 0.0, -0.5 * eps, p1, p2) / q2,
        "cc": _trig(0.5 + eps * eps, -2.0 * eps, 0.0, 0.5, 0.0, p1, p2) / q5,
        "ss": _trig(0.5, 0.0, 0.0, -0.5, 0.0, p1, p2) / q3,
        "sc": _trig(0.0, 0.0, -eps, 0.0, 0.5, p1, p2) / q2,
    }


def _pressure_start(eps: Any, w: Any, eps_dot: Any) -> Any:
    """theta1 = atan2(2 eps_dot, eps w), where the half film starts (0, finite, when nothing moves)."""
    x, y = eps * w, 2.0 * eps_dot
    moving = x * x + y * y > 0.0
    return B.atan2(B.if_else(moving, y, 0.0), B.if_else(moving, x, 1.0))


def _choice(owner: str, field: str, value: Any, allowed: tuple[str, ...]) -> str:
    if value not in allowed:
        raise SceneError(f"{owner}: {field}={value!r}, must be one of {', '.join(map(repr, allowed))}.")
    return str(value)


@dataclass(frozen=True, kw_only=True)
class HydrodynamicBearing:
    """A lubricated revolute clearance joint's law: a hydrodynamic film, and a dry law below it.

    Parameters
    ----------
    viscosity : float
        Dynamic viscosity mu of the oil in Pa s, > 0 (SAE 30 at 60 C: about 0.03).
    length : float
        Axial length L of the bearing in m, > 0.
    theory : {"short", "long", "finite"}
        Ocvirk's short, Sommerfeld's long, or a finite bearing (L / (2 R) <= 1, Butenschoen's tables).
    cavitation : {"half", "full"}
        "half": only the half of the film where pressure builds (Guembel); "full": the whole film.
    dry : NormalLaw
        The contact law once the film has broken down (stiffness from the joint's materials if None).
    roughness : float
        Composite RMS roughness sigma = sqrt(sigma_bearing^2 + sigma_journal^2) of the two surfaces, m (> 0).
    film_parameter : float
        The film parameter Lambda = h_min / sigma at which the film breaks down and the dry law takes
        over (> 0; 1 by default, the start of boundary lubrication); below Lambda = 4 the asperities
        carry a share of the load with the film (Greenwood and Tripp: the mixed regime).
    hysteresis : float
        The film forms again above ``film_parameter * (1 + hysteresis)``; >= 0.
    asperity_modulus : float or None
        Composite modulus E' of the asperity contact (1/E' = sum (1 - nu^2)/E), Pa; None: from the
        joint's materials.
    """

    viscosity: float
    length: float
    theory: str = "short"
    cavitation: str = "half"
    dry: NormalLaw = LankaraniNikravesh(restitution=0.9)
    roughness: float = 1.0e-6
    film_parameter: float = 1.0
    hysteresis: float = 1.0
    asperity_modulus: float | None = None

    name: ClassVar[str] = "hydrodynamic"
    #: A revolute clearance joint's law only, assembled as a lubricated journal; wear is not modelled with it.
    joint_kinds: ClassVar[tuple[str, ...]] = ("RevoluteClearance",)
    journal_model: ClassVar[str] = "lubricated"
    wears: ClassVar[bool] = False
    #: A table with the numbers the law needs (error messages).
    example: ClassVar[str] = "{'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01}"

    def __post_init__(self) -> None:
        owner = type(self).__name__
        set_field(self, "viscosity", check_number(owner, "viscosity", self.viscosity, low=0.0, unit="Pa s"))
        set_field(self, "length", check_number(owner, "length", self.length, low=0.0, unit="m"))
        set_field(self, "theory", _choice(owner, "theory", self.theory, THEORIES))
        set_field(self, "cavitation", _choice(owner, "cavitation", self.cavitation, CAVITATION))
        if self.theory == "finite" and self.cavitation != "half":
            raise SceneError(f"{owner}: cavitation={self.cavitation!r} with theory='finite', must be 'half' "
                             "(Butenschoen's tables have the Reynolds cavitation condition).")
        if not isinstance(self.dry, NormalLaw):
            raise SceneError(f"{owner}: dry={self.dry!r}, must be a normal contact law (a NormalLaw, e.g. "
                             "LankaraniNikravesh(restitution=0.9)).")
        set_field(self, "roughness", check_number(owner, "roughness", self.roughness, low=0.0, unit="m"))
        set_field(self, "film_parameter", check_number(owner, "film_parameter", self.film_parameter, low=0.0,
                                                       high=ASPERITY_CUTOFF))
        set_field(self, "hysteresis", check_number(owner, "hysteresis", self.hysteresis, low=0.0, low_open=False))
        if self.asperity_modulus is not None:
            set_field(self, "asperity_modulus",
                      check_number(owner, "asperity_modulus", self.asperity_modulus, low=0.0, unit="Pa"))

    @property
    def film_threshold(self) -> float:
        """Minimum film thickness (m) below which the film has broken down: film_parameter x roughness."""
        return self.film_parameter * self.roughness

    @property
    def reform_threshold(self) -> float:
        """Minimum film thickness (m) above which the film forms again after a dry contact."""
        return self.film_threshold * (1.0 + self.hysteresis)

    @property
    def is_resolved(self) -> bool:
        """True when the dry law and the asperity modulus have every number (see :meth:`resolve`)."""
        return self.dry.is_resolved and self.asperity_modulus is not None

    @property
    def needs_approach_speed(self) -> bool:
        """The dry law's flag: its approach speed is latched when the film breaks down."""
        return self.dry.needs_approach_speed

    def resolve(self, kind: str, *, radii: Any = None, materials: Any = None, face_half_width: Any = None) -> Self:
        """A copy whose dry law is resolved for the journal bearing (``kind="internal_cylinder"`` only)."""
        if kind != "internal_cylinder":
            raise SceneError(f"{type(self).__name__}.resolve: kind={kind!r}, must be 'internal_cylinder' "
                             "(a lubricated journal bearing is a revolute clearance joint).")
        dry, modulus = self.dry, self.asperity_modulus
        if not dry.is_resolved:
            dry = dry.resolve("internal_cylinder", radii=radii, materials=materials)
        if modulus is None:
            if materials is None:
                raise SceneError(f"{type(self).__name__}: asperity_modulus=None and the joint has no material; "
                                 "give the joint's material or asperity_modulus (Pa).")
            modulus = 1.0 / sigma_sum(materials)  # 1/E' = sum (1 - nu^2) / E (Material.sigma, no pi)
        return dataclasses.replace(self, dry=dry, asperity_modulus=modulus)

    def joint_problems(self, clearance: float, journal_radius: float) -> list[str]:
        """What is wrong with this law in a joint of radial clearance ``clearance`` (m)."""
        owner = type(self).__name__
        out = []
        if not self.reform_threshold < clearance:
            out.append(f"{owner}: film_parameter * roughness * (1 + hysteresis)={self.reform_threshold:g} m, must be "
                       f"< the radial clearance {clearance:g} m (the film must be able to form).")
        if not ASPERITY_CUTOFF * self.roughness < 0.5 * clearance:
            out.append(f"{owner}: roughness={self.roughness:g} m, must be < the radial clearance / 8 = "
                       f"{clearance / 8:g} m (asperities touch below a film of 4 x roughness, which must stay "
                       "thin against the clearance).")
        if self.theory == "finite" and self.length > 2.0 * journal_radius:
            out.append(f"{owner}: length={self.length:g} m with theory='finite', must be <= the journal's diameter "
                       f"{2.0 * journal_radius:g} m (Butenschoen's tables end at B/D = 1).")
        return out

    def film_force(self, eccentricity_ratio: Any, wedge_rate: Any, squeeze_rate: Any, radius: Any,
                   clearance: Any) -> tuple[Any, Any]:
        """The film's force on the journal, (radial, tangential) in N: radial > 0 towards the bearing's
        centre, tangential along the eccentricity turned by +90 degrees.

        ``eccentricity_ratio`` eps in [0, 1) (a symbol is clamped to [0, 1 - 1e-6]), ``wedge_rate``
        (omega_journal + omega_bearing - 2 x the line of centres' rate, rad/s), ``squeeze_rate``
        (d eps / dt, 1/s, > 0 while the film thins): floats, arrays or CasADi symbols; journal
        ``radius`` and radial ``clearance`` in m.

        Example
        -------
        >>> law = HydrodynamicBearing(viscosity=0.04, length=0.02)
        >>> fr, ft = law.film_force(0.5, 100.0, 0.0, radius=0.01, clearance=5e-5)
        >>> round(fr, 3), round(ft, 3)  # mu w R L^3 eps^2/(c^2 (1-eps^2)^2), pi mu w R L^3 eps/(4 c^2 (1-eps^2)^1.5)
        (56.889, 77.389)
        """
        owner = f"{type(self).__name__}.film_force"
        if not B.is_symbolic(eccentricity_ratio, wedge_rate, squeeze_rate, radius, clearance):
            check_number(owner, "radius", radius, low=0.0, unit="m")
            check_number(owner, "clearance", clearance, low=0.0, unit="m")
            if not clearance < radius:
                raise SceneError(f"{owner}: clearance={clearance:g} m, must be < radius={radius:g} m (a radial "
                                 "clearance, far smaller than the journal).")
            for field, value, unit in (("wedge_rate", wedge_rate, "rad/s"), ("squeeze_rate", squeeze_rate, "1/s")):
                raw = np.asarray(value)
                if raw.dtype.kind not in "iuf":
                    raise SceneError(f"{owner}: {field}={value!r} is not a real number ({unit}).")
                bad = ~np.isfinite(raw)
                if np.any(bad):
                    raise SceneError(f"{owner}: {field}={raw[bad].flat[0]}, must be a finite number ({unit}).")
            eps_values = np.asarray(eccentricity_ratio, dtype=float)
            bad = ~((eps_values >= 0.0) & (eps_values < 1.0))
            if np.any(bad):
                raise SceneError(f"{owner}: eccentricity_ratio={eps_values[bad].flat[0]:g}, must be in [0, 1).")
        scalar, (eps, w, eps_dot) = B.as_numeric(eccentricity_ratio, wedge_rate, squeeze_rate)
        radial, tangential = self.film_force_with(self.viscosity, self.length, eps, w, eps_dot, radius, clearance)
        if scalar:
            return float(radial), float(tangential)
        return radial, tangential

    def film_force_with(self, viscosity: Any, length: Any, eps: Any, w: Any, eps_dot: Any, R: Any,
                        c: Any) -> tuple[Any, Any]:
        """:meth:`film_force` with viscosity and length given (run-time symbols), no checks."""
        if B.is_symbolic(eps):
            eps = B.fmin(B.fmax(eps, 0.0), EPS_CAP)
        if self.cavitation == "full":
            theta1, theta2 = 0.0 * eps, 2.0 * math.pi + 0.0 * eps
        else:
            theta1 = _pressure_start(eps, w, eps_dot)
            theta2 = theta1 + math.pi
        mu, L = viscosity, length
        I = film_integrals(eps, theta1, theta2)
        if self.theory != "long":
            # p = 3 mu (L^2/4 - z^2) (eps w sin - 2 eps_dot cos) / (c^2 (1 + eps cos)^3): wedge and squeeze parts
            k = mu * R * L ** 3 / (2.0 * c * c)
            wedge = (-k * eps * w * I["sc"], k * eps * w * I["ss"])  # (radial, tangential)
            squeeze = (2.0 * k * eps_dot * I["cc"], -2.0 * k * eps_dot * I["sc"])
            if self.theory == "finite":
                return finite_film_force(wedge, squeeze, eps, w, eps_dot, L / (2.0 * R))
            return wedge[0] + squeeze[0], wedge[1] + squeeze[1]
        # dp/dtheta = mu R^2 (6 eps w cos + 12 eps_dot sin + m) / (c^2 (1 + eps cos)^3), m from
        # p = 0 at both ends (half) or periodicity (full); the forces by parts (p = 0 or periodic there)
        m = -(6.0 * eps * w * I["c"] + 12.0 * eps_dot * I["s"]) / I["1"]
        k = mu * L * R ** 3 / (c * c)
        f_x = -k * (6.0 * eps * w * I["sc"] + 12.0 * eps_dot * I["ss"] + m * I["s"])
        f_y = k * (6.0 * eps * w * I["cc"] + 12.0 * eps_dot * I["sc"] + m * I["c"])
        # f_x is along the eccentricity (the widest film is at theta = 0, opposite to it)
        return -f_x, f_y


def shear_torques(viscosity: Any, length: Any, eps: Any, relative_speed: Any, tangential: Any, radius: Any,
                  clearance: Any) -> tuple[Any, Any]:
    """The film's shear torques (journal, bearing), N m, about each one's centre (floats or symbols).

    The wall shear ``mu (U_b - U_j) / h - (h / 2) dp/(R dtheta)`` integrated over the journal: Couette
    (Petroff's term, over the whole circumference: ``2 pi mu R^3 L (w_j - w_b) / (c sqrt(1 - eps^2))``)
    and Poiseuille, ``-(e / 2) F_t`` by parts for any pressure field; the bearing's makes the film's
    torques balance, ``T_j + T_b + e F_t = 0``. ``relative_speed`` = omega_journal - omega_bearing,
    ``tangential`` the film's tangential force (:meth:`HydrodynamicBearing.film_force`).
    """
    if B.is_symbolic(eps):
        eps = B.fmin(B.fmax(eps, 0.0), EPS_CAP)
    couette = 2.0 * math.pi * viscosity * radius**3 * length * relative_speed / (clearance * B.sqrt(1.0 - eps * eps))
    poiseuille = -0.5 * eps * clearance * tangential
    return -couette + poiseuille, couette + poiseuille
