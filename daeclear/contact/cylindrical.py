"""Cylindrical (line-contact) laws for a journal in a bearing: Dubowsky-Freudenstein,
Goldsmith and ESDU 78035 (chapter 4, Figs. 4.22c-e).

Each law gives the penetration as an explicit function of the force,
``delta = s F [ln(X / F) + k]``, ``s = sigma_s / L`` (eq. 3.4), implicit in F and physical only
below its maximum; it is solved by :data:`NEWTON_STEPS` unrolled safeguarded Newton steps and
continued beyond ``penetration_limit`` as ``F_lim (delta / penetration_limit)**1.5``. The
derivation and the ``sigma_convention`` ("plain" or "pi"): docs/contact_laws.md.
"""

from __future__ import annotations

import abc
import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal, NamedTuple, Self

from ..core.errors import SceneError
from . import _backend as B
from ._checks import check_number, set_field
from .base import Geometry, NormalLaw, bearing_radii
from .geometry import MaterialPair, material_pair

__all__ = ["NEWTON_STEPS", "DubowskyFreudenstein", "ESDU78035", "Goldsmith"]

#: Newton steps of the implicit solve (3 reach round-off over the valid range; 1 spare).
NEWTON_STEPS = 4
#: Relative distance of the end of the valid range from the branch maximum, in ``eps = z - 1``.
EPS_MIN = 1e-3
#: Largest ``r = ln(delta_max / delta)`` solved; smaller penetrations use it (force ~ linear).
R_MAX = 200.0
_R_SWITCH = 2.0

SigmaConvention = Literal["plain", "pi"]


class CylinderConstants(NamedTuple):
    """Numbers of a resolved cylindrical law (SI units)."""

    s: float            # compliance factor sigma_s / L, m/N
    force_scale: float  # X, N
    k: float            # +1 or -1
    delta_max: float    # end of the physical branch, m
    force_max: float    # force at delta_max, N
    delta_lim: float    # end of the valid range (penetration_limit), m
    force_lim: float    # force at delta_lim, N
    delta_tiny: float   # below it the solve uses r = R_MAX, m


def solve_branch(r: Any) -> Any:
    """``eps > 0`` with ``eps - log1p(eps) = r`` for ``r > 0``, by unrolled safeguarded Newton steps."""
    t = B.sqrt(2.0 * r)
    series = t + t * t / 3.0 + t**3 / 36.0 - t**4 / 270.0
    asymptotic = r + B.log(1.0 + r + B.log(1.0 + r))
    eps = B.if_else(r < _R_SWITCH, series, asymptotic)
    for _ in range(NEWTON_STEPS):
        step = (1.0 + eps) * (eps - B.log1p(eps) - r) / eps
        eps = B.fmax(eps - step, 0.5 * eps)  # safeguard: stay on the physical branch eps > 0
    return eps


@dataclass(frozen=True, kw_only=True)
class _CylindricalLaw(NormalLaw):
    """``delta = s F [ln(X/F) + k]`` solved for F; see the module docstring."""

    length: float
    bearing_radius: float | None = None
    journal_radius: float | None = None
    materials: MaterialPair | None = None
    sigma_convention: SigmaConvention = "plain"

    geometry: ClassVar[Geometry] = "cylinder"
    supported_kinds: ClassVar[tuple[str, ...]] = ("internal_cylinder",)
    branch_constant: ClassVar[float]

    def __post_init__(self) -> None:
        owner = type(self).__name__
        set_field(self, "length", check_number(owner, "length", self.length, low=0.0, unit="m"))
        for field in ("bearing_radius", "journal_radius"):
            value = getattr(self, field)
            if value is not None:
                set_field(self, field, check_number(owner, field, value, low=0.0, unit="m"))
        if (self.bearing_radius is not None and self.journal_radius is not None
                and self.journal_radius >= self.bearing_radius):
            raise SceneError(f"{owner}: journal_radius={self.journal_radius:g} m, must be < "
                             f"bearing_radius={self.bearing_radius:g} m.")
        if self.materials is not None:
            set_field(self, "materials", material_pair(self.materials, owner))
        if self.sigma_convention not in ("plain", "pi"):
            raise SceneError(f"{owner}: sigma_convention={self.sigma_convention!r}, must be 'plain' "
                             "((1-nu^2)/E) or 'pi' ((1-nu^2)/(pi E)).")

    @property
    def is_resolved(self) -> bool:
        return None not in (self.bearing_radius, self.journal_radius, self.materials)

    def _resolve(self, kind: str, *, radii: Any, materials: Any, face_half_width: Any) -> Self:
        owner = type(self).__name__
        if kind != "internal_cylinder":
            raise SceneError(f"{owner}: a line-contact law for a journal in a bearing; kind={kind!r} is not "
                             "supported (use 'internal_cylinder').")
        changes: dict[str, Any] = {}
        if self.bearing_radius is None or self.journal_radius is None:
            r_i, r_j = bearing_radii(owner, radii)
            if self.bearing_radius is None:
                changes["bearing_radius"] = r_i
            if self.journal_radius is None:
                changes["journal_radius"] = r_j
        if self.materials is None:
            if materials is None:
                raise SceneError(f"{owner}.resolve(kind='internal_cylinder'): materials=None; pass "
                                 "materials=(bearing material, journal material).")
            changes["materials"] = material_pair(materials, owner)
        return dataclasses.replace(self, **changes) if changes else self

    @property
    def sigma_sum(self) -> float:
        """``sigma_i + sigma_j`` in the law's ``sigma_convention`` (1/Pa)."""
        if self.materials is None:
            raise SceneError(f"{type(self).__name__}: materials=None; call resolve(...) first.")
        material_i, material_j = material_pair(self.materials, type(self).__name__)
        total = material_i.sigma + material_j.sigma
        return total / math.pi if self.sigma_convention == "pi" else total

    @abc.abstractmethod
    def _force_scale(self, sigma_s: float, length: float, r_i: float, r_j: float) -> float:
        """The constant X (N) inside ``ln(X / F)``."""

    def constants(self) -> CylinderConstants:
        """The law's constants (requires a resolved law)."""
        if not self.is_resolved:
            raise SceneError(f"{type(self).__name__}: bearing_radius, journal_radius or materials is None; "
                             "call resolve(kind='internal_cylinder', radii=..., materials=...) first.")
        assert self.bearing_radius is not None and self.journal_radius is not None  # is_resolved
        sigma_s = self.sigma_sum
        s = sigma_s / self.length
        x = self._force_scale(sigma_s, self.length, self.bearing_radius, self.journal_radius)
        k = self.branch_constant
        delta_max = s * x * math.exp(k - 1.0)
        delta_lim = delta_max * math.exp(-(EPS_MIN - math.log1p(EPS_MIN)))
        return CylinderConstants(s=s, force_scale=x, k=k, delta_max=delta_max, force_max=x * math.exp(k - 1.0),
                                 delta_lim=delta_lim, force_lim=delta_lim / (s * (1.0 + EPS_MIN)),
                                 delta_tiny=delta_max * math.exp(-R_MAX))

    @property
    def max_penetration(self) -> float:
        """``delta_max`` (m), where the physical branch ends (dF/d delta infinite)."""
        return self.constants().delta_max

    @property
    def penetration_limit(self) -> float:
        """End of the valid range (m); beyond it the Hertz-like extension is used."""
        return self.constants().delta_lim

    def penetration_from_force(self, force: Any) -> Any:
        """The explicit law ``delta(F) = s F [ln(X / F) + k]`` (0 for F <= 0; physical for F <= F_max)."""
        c = self.constants()
        scalar, (f,) = B.as_numeric(force)
        f_safe = B.fmax(f, c.force_max * math.exp(-R_MAX))
        delta = c.s * f_safe * (B.log(c.force_scale / f_safe) + c.k)
        out = B.if_else(f > 0.0, delta, 0.0)
        return float(out) if scalar else out

    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        c = self.constants()
        delta_pos = B.fmax(delta, 0.0)
        delta_in = B.fmin(B.fmax(delta, c.delta_tiny), c.delta_lim)  # keeps every operand finite
        eps = solve_branch(B.log(c.delta_max / delta_in))
        on_law = B.fmin(delta_pos, c.delta_lim) / (c.s * (1.0 + eps))
        extension = c.force_lim * (delta_pos / c.delta_lim) ** 1.5
        return B.if_else(delta > c.delta_lim, extension, on_law)


_COMMON = """
    Parameters
    ----------
    length : float
        Axial contact length L in m, > 0. Required (the chapter does not state the
        value used in Fig. 4.22); the slider-crank examples state theirs.
    bearing_radius, journal_radius : float or None
        R_i > R_j in m; None: set by :meth:`resolve` from the revolute clearance joint.
    materials : Material or (Material, Material) or None
        Bearing and journal materials; None: set by :meth:`resolve`.
    sigma_convention : {"plain", "pi"}
        sigma = (1-nu^2)/E or (1-nu^2)/(pi E) in the formula (see module docstring).

    Notes
    -----
    Elastic; implicit in F (:mod:`daeclear.contact.cylindrical`). Beyond ``penetration_limit`` the
    force is continued as ``F_lim (delta / penetration_limit)**1.5`` and :meth:`check_penetration` warns.
"""


@dataclass(frozen=True, kw_only=True)
class DubowskyFreudenstein(_CylindricalLaw):
    """Dubowsky-Freudenstein (1971) internal cylinder law.

    ``delta = F sigma_s / L [ln(L^3 (R_i - R_j) / (F sigma_s R_i R_j)) + 1]``,
    the ``L^3`` reading (the only dimensionless one) of docs/contact_laws.md.
    """ + _COMMON

    name: ClassVar[str] = "dubowsky-freudenstein"
    branch_constant: ClassVar[float] = 1.0

    def _force_scale(self, sigma_s: float, length: float, r_i: float, r_j: float) -> float:
        return length**3 * (r_i - r_j) / (sigma_s * r_i * r_j)


@dataclass(frozen=True, kw_only=True)
class Goldsmith(_CylindricalLaw):
    """Goldsmith (1960) internal cylinder law -- form UNCONFIRMED.

    ``delta = F sigma_s / L [ln(L^3 / (F sigma_s (R_i - R_j))) + 1]``.

    Warning: the book's printed form was not available; this is a plausible reading with the radial
    clearance in place of ``R_i R_j / (R_i - R_j)`` (docs/contact_laws.md).
    """ + _COMMON

    name: ClassVar[str] = "goldsmith"
    branch_constant: ClassVar[float] = 1.0

    def _force_scale(self, sigma_s: float, length: float, r_i: float, r_j: float) -> float:
        return length**3 / (sigma_s * (r_i - r_j))


@dataclass(frozen=True, kw_only=True)
class ESDU78035(_CylindricalLaw):
    """ESDU 78035 internal cylinder law (Johnson-consistent reading).

    ``delta = F sigma'_s / L [ln(4 L (R_i - R_j) / (F sigma'_s)) - 1]`` with
    ``sigma' = (1 - nu^2)/(pi E)`` by default: Johnson's conforming-cylinder solution
    (docs/contact_laws.md 8.5a).
    """ + _COMMON

    sigma_convention: SigmaConvention = "pi"

    name: ClassVar[str] = "esdu-78035"
    branch_constant: ClassVar[float] = -1.0

    def _force_scale(self, sigma_s: float, length: float, r_i: float, r_j: float) -> float:
        return 4.0 * length * (r_i - r_j) / sigma_s
