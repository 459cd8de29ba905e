"""Materials and contact stiffness from materials and geometry (eqs. 3.4, 3.5, 4.27).

``sigma = (1 - nu**2) / E`` without pi (eq. 3.4; the 0.475 of 4.27 needs it); the journal-bearing
pair uses the sphere formula (3.5) with ``R_i - R_j`` (docs/contact_laws.md).

Example
-------
>>> steel = Material(young=207e9, poisson=0.3)
>>> round(internal_contact_stiffness(10.0e-3, 9.5e-3, steel) / 1e10, 3)
6.61
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.errors import SceneError
from ._checks import check_number

__all__ = [
    "Material", "MaterialPair", "external_contact_stiffness", "internal_contact_stiffness",
    "material_pair", "plane_face_stiffness", "sigma_sum", "sphere_plane_stiffness",
]


@dataclass(frozen=True, kw_only=True)
class Material:
    """Isotropic elastic material of a contacting body.

    Parameters
    ----------
    young : float
        Young's modulus E in Pa, > 0.
    poisson : float
        Poisson's ratio nu, in (-1, 0.5).

    Example
    -------
    >>> Material(young=207e9, poisson=0.3).sigma
    4.396135265700483e-12
    """

    young: float
    poisson: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "young", check_number("Material", "young", self.young, low=0.0, unit="Pa"))
        object.__setattr__(self, "poisson",
                           check_number("Material", "poisson", self.poisson, low=-1.0, high=0.5))

    @property
    def sigma(self) -> float:
        """Material parameter of eq. (3.4), ``(1 - nu**2) / E`` in 1/Pa (no pi)."""
        return (1.0 - self.poisson**2) / self.young


MaterialPair = Material | tuple[Material, Material]


def material_pair(materials: MaterialPair | None, owner: str = "contact") -> tuple[Material, Material]:
    """``(material_i, material_j)``; a single Material for both. SceneError for anything else."""
    if isinstance(materials, Material):
        return materials, materials
    if (isinstance(materials, (tuple, list)) and len(materials) == 2
            and all(isinstance(m, Material) for m in materials)):
        return materials[0], materials[1]
    raise SceneError(f"{owner}: materials={materials!r}, must be a Material or a pair (Material, Material).")


def sigma_sum(materials: MaterialPair) -> float:
    """``sigma_i + sigma_j`` of eq. (3.4), in 1/Pa."""
    m_i, m_j = material_pair(materials)
    return m_i.sigma + m_j.sigma


def _radius(owner: str, field: str, value: float) -> float:
    return check_number(owner, field, value, low=0.0, unit="m")


def internal_contact_stiffness(bearing_radius: float, journal_radius: float, materials: MaterialPair) -> float:
    """Generalized stiffness of a journal (R_j) inside a bearing (R_i > R_j > 0, m), eq. (3.5) with
    ``R_i - R_j`` as the chapter uses it with (3.9): ``K = 4 / (3 sigma_s) sqrt(R_i R_j / (R_i - R_j))``, N/m^1.5."""
    owner = "internal_contact_stiffness"
    r_i = _radius(owner, "bearing_radius", bearing_radius)
    r_j = _radius(owner, "journal_radius", journal_radius)
    if r_j >= r_i:
        raise SceneError(f"{owner}: journal_radius={r_j:g} m, must be < bearing_radius={r_i:g} m.")
    return 4.0 / (3.0 * sigma_sum(materials)) * math.sqrt(r_i * r_j / (r_i - r_j))


def external_contact_stiffness(radius_i: float, radius_j: float, materials: MaterialPair) -> float:
    """Generalized stiffness K of two convex spheres, eq. (3.5) with ``R_i + R_j``, in N/m^1.5."""
    owner = "external_contact_stiffness"
    r_i = _radius(owner, "radius_i", radius_i)
    r_j = _radius(owner, "radius_j", radius_j)
    return 4.0 / (3.0 * sigma_sum(materials)) * math.sqrt(r_i * r_j / (r_i + r_j))


def sphere_plane_stiffness(radius: float, materials: MaterialPair) -> float:
    """Generalized stiffness of a sphere (a rounded slider corner) on a plane, eq. (3.5) with
    ``R_j -> infinity``: ``K = 4 / (3 (sigma_i + sigma_j)) * sqrt(R)``, N/m^1.5."""
    r = _radius("sphere_plane_stiffness", "radius", radius)
    return 4.0 / (3.0 * sigma_sum(materials)) * math.sqrt(r)


def plane_face_stiffness(half_width: float, materials: MaterialPair) -> float:
    """Linear stiffness of two square plane surfaces, eq. (4.27) (Lankarani 1988), in N/m:
    ``K = a / (0.475 (sigma_i + sigma_j))``, ``a`` half the side of the square contact."""
    a = check_number("plane_face_stiffness", "half_width", half_width, low=0.0, unit="m")
    return a / (0.475 * sigma_sum(materials))
