"""Base class of the normal contact laws and the ``resolve`` protocol.

A subclass (a frozen keyword-only dataclass of the law's parameters) sets ``name``, ``geometry``
(``"sphere"``, ``"cylinder"`` or ``"face"``: what it needs from a joint) and ``supported_kinds``,
and overrides ``is_resolved``, ``_resolve`` and ``_force`` (written with ``daeclear.contact._backend``:
zero for penetration <= 0, never negative, never NaN, derivatives included), and ``dissipative`` /
``needs_approach_speed`` / ``penetration_limit`` when they are not False / False / inf.
"""

from __future__ import annotations

import abc
import math
import warnings
from dataclasses import dataclass
from typing import Any, ClassVar, Literal, Self

import numpy as np

from ..core.errors import DaeclearWarning, SceneError
from . import _backend as B
from ._checks import check_number
from .geometry import (MaterialPair, internal_contact_stiffness, material_pair, plane_face_stiffness,
                       sphere_plane_stiffness)

__all__ = ["KINDS", "Geometry", "Kind", "NormalLaw", "bearing_radii", "computed_stiffness"]

Kind = Literal["internal_cylinder", "sphere_plane", "plane_face"]
Geometry = Literal["sphere", "cylinder", "face"]

#: The contact kinds a joint can pass to :meth:`NormalLaw.resolve`.
KINDS: tuple[str, ...] = ("internal_cylinder", "sphere_plane", "plane_face")


@dataclass(frozen=True, kw_only=True)
class NormalLaw(abc.ABC):
    """A normal contact force law ``F_N(delta, delta_dot, delta_dot_minus) >= 0``: penetration
    ``delta > 0`` in contact, rate ``delta_dot > 0`` approaching, ``delta_dot_minus`` the rate latched
    at contact onset."""

    name: ClassVar[str]
    geometry: ClassVar[Geometry]
    supported_kinds: ClassVar[tuple[str, ...]]
    #: The clearance joints (their ``kind``) that take the law, how a revolute joint builds its pair
    #: (the assembly's registry of journal models), and whether a joint with it can wear.
    joint_kinds: ClassVar[tuple[str, ...]] = ("RevoluteClearance", "TranslationalClearance")
    journal_model: ClassVar[str] = "dry"
    wears: ClassVar[bool] = True

    def joint_problems(self, clearance: float, journal_radius: float) -> list[str]:
        """What is wrong with this law in a revolute joint of ``clearance`` (m): nothing for a normal law."""
        return []

    @property
    def dissipative(self) -> bool:
        """True if the law dissipates energy in an impact (hysteresis or damping)."""
        return False

    @property
    def needs_approach_speed(self) -> bool:
        """True if ``force`` uses the approach speed latched at contact onset."""
        return False

    @property
    @abc.abstractmethod
    def is_resolved(self) -> bool:
        """True when every number the force needs is set (see :meth:`resolve`)."""

    @property
    def penetration_limit(self) -> float:
        """Largest penetration (m) of the law's valid range; beyond it see the class Notes."""
        return math.inf

    def resolve(self, kind: Kind, *, radii: tuple[float, ...] | float | None = None,
                materials: MaterialPair | None = None,
                face_half_width: float | None = None) -> Self:
        """A copy with every number left ``None`` computed from the joint's geometry (given ones kept).

        Parameters
        ----------
        kind : {"internal_cylinder", "sphere_plane", "plane_face"}
            A journal in a bearing; a rounded slider corner on a guide; a square slider face (side 2a).
        radii : tuple of float or float, optional
            ``(R_i, R_j)`` (bearing, journal) in m, or ``(R_c,)`` / ``R_c`` for ``"sphere_plane"``.
        materials : Material or (Material, Material), optional
            Materials of bodies i and j; one Material means both.
        face_half_width : float, optional
            Half side ``a`` (m) of the square contact area, for ``"plane_face"``.

        Raises
        ------
        SceneError
            Unknown kind, a kind this law cannot use, or a missing/invalid input.
        """
        if kind not in KINDS:
            raise SceneError(f"{type(self).__name__}.resolve: kind={kind!r} is not a contact kind; "
                             f"valid kinds: {', '.join(map(repr, KINDS))}.")
        return self._resolve(kind, radii=radii, materials=materials, face_half_width=face_half_width)

    @abc.abstractmethod
    def _resolve(self, kind: str, *, radii: Any, materials: Any, face_half_width: Any) -> Self:
        """Implementation of :meth:`resolve` (kind already validated)."""

    def force(self, penetration: Any, penetration_rate: Any = None, approach_speed: Any = None) -> Any:
        """Normal force ``F_N >= 0`` (N) on floats, numpy arrays (broadcast) or CasADi symbols.

        Parameters
        ----------
        penetration : float, array_like, casadi.SX or casadi.MX
            ``delta`` in m, > 0 in contact (force exactly 0 otherwise).
        penetration_rate : same types, optional
            ``delta_dot`` in m/s, > 0 approaching; required by dissipative laws.
        approach_speed : same types, optional
            ``delta_dot_minus`` in m/s, latched at onset; required when ``needs_approach_speed``.

        Raises
        ------
        SceneError
            If the law is not resolved: call :meth:`resolve`.
        TypeError
            If a required rate or approach speed is missing.
        """
        return self._evaluate("force", self._force, penetration, penetration_rate, approach_speed)

    def contact_force(self, penetration: Any, penetration_rate: Any = None, approach_speed: Any = None) -> Any:
        """The force inside a contact, what a contact term reads while it is on: :meth:`force`, but at
        ``penetration`` 0 its one-sided limit from inside the contact (same arguments).

        At an onset root the penetration is 0 and the term switches on: a law whose force jumps at onset
        (Kelvin-Voigt's ``D delta_dot``) gives the jump there, which the restart's accelerations and the
        sensitivities' jump (docs/sensitivities.md, section 4) need; :meth:`force`, the law's value, is 0
        there as out of contact. For a law continuous at ``delta = 0`` the two are the same."""
        return self._evaluate("contact_force", self._contact_force, penetration, penetration_rate, approach_speed)

    def _evaluate(self, method: str, law: Any, penetration: Any, penetration_rate: Any, approach_speed: Any) -> Any:
        """``law(delta, delta_dot, v_minus)`` on the arguments checked and made numeric (or symbolic)."""
        if not self.is_resolved:
            raise SceneError(f"{type(self).__name__}: some parameters are None (not resolved); give them "
                             "explicitly or call .resolve(kind, radii=..., materials=...) first.")
        if penetration_rate is None and self.dissipative:
            raise TypeError(f"{type(self).__name__}.{method} needs penetration_rate (the law is dissipative).")
        if approach_speed is None and self.needs_approach_speed:
            raise TypeError(f"{type(self).__name__}.{method} needs approach_speed (initial impact velocity).")
        scalar, (delta, delta_dot, v_minus) = B.as_numeric(penetration, penetration_rate, approach_speed)
        delta_dot = 0.0 if delta_dot is None else delta_dot
        v_minus = 0.0 if v_minus is None else v_minus
        out = law(delta, delta_dot, v_minus)
        return float(out) if scalar else out

    @abc.abstractmethod
    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        """The law, written once with ``daeclear.contact._backend`` functions."""

    def _contact_force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        """The law inside a contact, continued to ``delta = 0`` from inside: ``_force`` unless it jumps there."""
        return self._force(delta, delta_dot, v_minus)

    def check_penetration(self, penetration: Any, *, warn: bool = True) -> bool:
        """True if every penetration (e.g. of a result's channel) is inside the law's valid range; else
        a :class:`~daeclear.core.errors.DaeclearWarning` with ``warn``."""
        values = np.asarray(penetration, dtype=float)
        worst = float(np.max(values)) if values.size else -math.inf
        ok = worst <= self.penetration_limit
        if not ok and warn:
            warnings.warn(f"{type(self).__name__}: penetration {worst:.3e} m exceeds the valid range "
                          f"(penetration_limit {self.penetration_limit:.3e} m); the force there is the "
                          "documented extension, not the law.", DaeclearWarning, stacklevel=2)
        return ok


def bearing_radii(owner: str, radii: Any) -> tuple[float, float]:
    """``(R_i, R_j)`` for kind ``"internal_cylinder"``, checked ``R_i > R_j > 0``."""
    if not (isinstance(radii, (tuple, list)) and len(radii) == 2):
        raise SceneError(f"{owner}.resolve(kind='internal_cylinder'): radii={radii!r}, must be "
                         "(bearing_radius, journal_radius) in m.")
    where = f"{owner}.resolve(kind='internal_cylinder')"
    r_i = check_number(where, "bearing_radius", radii[0], low=0.0, unit="m")
    r_j = check_number(where, "journal_radius", radii[1], low=0.0, unit="m")
    if not r_j < r_i:
        raise SceneError(f"{owner}.resolve(kind='internal_cylinder'): radii=({r_i:g}, {r_j:g}) m, "
                         "must satisfy bearing_radius > journal_radius > 0.")
    return r_i, r_j


def _corner_radius(owner: str, radii: Any) -> float:
    value = radii[0] if isinstance(radii, (tuple, list)) and len(radii) == 1 else radii
    if value is None or isinstance(value, (tuple, list)):
        raise SceneError(f"{owner}.resolve(kind='sphere_plane'): radii={radii!r}, must be (R_c,) "
                         "with the corner radius R_c > 0 in m.")
    return check_number(f"{owner}.resolve(kind='sphere_plane')", "radii", value, low=0.0, unit="m")


def computed_stiffness(owner: str, kind: str, *, radii: Any, materials: Any, face_half_width: Any) -> float:
    """Stiffness from materials and geometry: eq. (3.5) for the two sphere-type kinds
    (N/m^1.5), eq. (4.27) for ``"plane_face"`` (N/m)."""
    if materials is None:
        raise SceneError(f"{owner}.resolve(kind={kind!r}): materials=None; pass materials= or give "
                         "stiffness= explicitly.")
    pair = material_pair(materials, owner)
    if kind == "internal_cylinder":
        r_i, r_j = bearing_radii(owner, radii)
        return internal_contact_stiffness(r_i, r_j, pair)
    if kind == "sphere_plane":
        return sphere_plane_stiffness(_corner_radius(owner, radii), pair)
    if face_half_width is None:
        raise SceneError(f"{owner}.resolve(kind='plane_face'): face_half_width=None; pass the half side "
                         "a (m) of the square contact area.")
    return plane_face_stiffness(face_half_width, pair)
