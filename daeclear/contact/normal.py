"""Point and face contact laws: Hertz, Kelvin-Voigt, the hysteresis laws (Hunt-Crossley,
Lankarani-Nikravesh (3.9), Flores et al. 2011) and Lankarani's plane law (4.26-4.27).

Each ``_force`` is written once with :mod:`daeclear.contact._backend`; the force is 0 for
``penetration <= 0`` (powers of ``fmax(delta, 0)``), clamped at ``F >= 0``, and the approach speed
is floored at ``min_approach_speed`` (default 1e-4 m/s).
"""

from __future__ import annotations

import abc
import dataclasses
from dataclasses import dataclass
from typing import Any, ClassVar, Self

from ..core.errors import SceneError
from . import _backend as B
from ._checks import check_number, set_field
from .base import KINDS, Geometry, NormalLaw, computed_stiffness

__all__ = [
    "Flores", "Hertz", "HuntCrossley", "KelvinVoigt", "LankaraniNikravesh", "LankaraniPlane",
]

#: Exponent of the Hertz-type laws when left ``None`` (metal surfaces, chapter 3).
DEFAULT_EXPONENT = 1.5
#: Default floor of the approach speed, in m/s.
DEFAULT_MIN_APPROACH_SPEED = 1e-4


@dataclass(frozen=True, kw_only=True)
class _StiffnessLaw(NormalLaw):
    """Hertz-type law ``K delta**n (...)``: stiffness and exponent, resolved from geometry."""

    stiffness: float | None = None
    exponent: float | None = None

    geometry: ClassVar[Geometry] = "sphere"
    supported_kinds: ClassVar[tuple[str, ...]] = KINDS

    def __post_init__(self) -> None:
        owner = type(self).__name__
        if self.stiffness is not None:
            set_field(self, "stiffness", check_number(owner, "stiffness", self.stiffness, low=0.0))
        if self.exponent is not None:
            set_field(self, "exponent",
                      check_number(owner, "exponent", self.exponent, low=1.0, high=10.0, low_open=False,
                                   high_open=False))

    @property
    def is_resolved(self) -> bool:
        return self.stiffness is not None

    @property
    def effective_exponent(self) -> float:
        """The exponent used by ``force``: ``exponent``, or 1.5 when it is None."""
        return DEFAULT_EXPONENT if self.exponent is None else self.exponent

    def with_stiffness(self, stiffness: float) -> Self:
        """Return a copy with ``stiffness`` set (N/m^n), e.g. computed by a joint."""
        return dataclasses.replace(self, stiffness=stiffness)

    def _resolve(self, kind: str, *, radii: Any, materials: Any, face_half_width: Any) -> Self:
        if self.stiffness is not None:
            return dataclasses.replace(self, exponent=self.effective_exponent)
        owner = type(self).__name__
        stiffness = computed_stiffness(owner, kind, radii=radii, materials=materials,
                                       face_half_width=face_half_width)
        if kind != "plane_face":
            return dataclasses.replace(self, stiffness=stiffness, exponent=self.effective_exponent)
        # eq. (4.27) gives N/m: the "unified" model of section 4.3 uses it in (3.9) with n = 1.
        if self.exponent not in (None, 1.0):
            raise SceneError(f"{owner}: exponent={self.exponent:g} with kind='plane_face', whose stiffness "
                             "(4.27) is in N/m, must be 1 (or None).")
        return dataclasses.replace(self, stiffness=stiffness, exponent=1.0)

    def _elastic(self, delta: Any) -> Any:
        power = B.fmax(delta, 0.0) ** self.effective_exponent
        if B.is_symbolic(delta, self.effective_exponent):
            # behind a branch: its derivative in the exponent, log(delta) delta**n, is 0 out of contact
            # (a sensitivity to n), not 0 * log(0) = NaN
            power = B.if_else(delta > 0.0, power, 0.0)
        return self.stiffness * power


@dataclass(frozen=True, kw_only=True)
class Hertz(_StiffnessLaw):
    """Hertz elastic contact law, ``F_N = K delta**n`` for ``delta > 0``, else 0 (Figs. 4.22a-4.24a).

    Parameters
    ----------
    stiffness : float or None
        K in N/m^n, > 0; None: computed by :meth:`resolve`, eq. (3.5) (or (4.27) for "plane_face").
    exponent : float or None
        n in [1, 10]; None means 1.5 (1 for a computed "plane_face" stiffness).

    Example
    -------
    >>> Hertz(stiffness=6.61e10, exponent=1.5).force(10e-6)  # doctest: +ELLIPSIS
    2090.2...
    """

    name: ClassVar[str] = "hertz"

    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        return self._elastic(delta)


@dataclass(frozen=True, kw_only=True)
class _HysteresisLaw(_StiffnessLaw):
    """``F_N = K delta**n [1 + h(c_e) delta_dot / delta_dot_minus]``, clamped at F >= 0."""

    restitution: float
    min_approach_speed: float = DEFAULT_MIN_APPROACH_SPEED

    def __post_init__(self) -> None:
        super().__post_init__()
        owner = type(self).__name__
        set_field(self, "restitution",
                  check_number(owner, "restitution", self.restitution, low=0.0, high=1.0, high_open=False))
        set_field(self, "min_approach_speed",
                  check_number(owner, "min_approach_speed", self.min_approach_speed, low=0.0, unit="m/s"))

    @property
    def dissipative(self) -> bool:
        """True when ``restitution < 1`` (at 1 the law is exactly Hertz)."""
        return self.restitution < 1.0

    @property
    def needs_approach_speed(self) -> bool:
        """True when ``restitution < 1``: the damping term divides by ``delta_dot_minus``."""
        return self.restitution < 1.0

    @property
    @abc.abstractmethod
    def hysteresis_factor(self) -> float:
        """Dimensionless h(c_e) multiplying ``delta_dot / delta_dot_minus``."""

    def damping(self, approach_speed: float) -> float:
        """Hysteresis damping ``chi = h K / max(delta_dot_minus, min_approach_speed)`` (N s/m^(n+1))."""
        if self.stiffness is None:
            raise SceneError(f"{type(self).__name__}: stiffness=None; call resolve(...) first.")
        return self.hysteresis_factor * self.stiffness / max(approach_speed, self.min_approach_speed)

    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        v_ref = B.fmax(v_minus, self.min_approach_speed)
        force = self._elastic(delta) * (1.0 + self.hysteresis_factor * delta_dot / v_ref)
        return B.fmax(force, 0.0)


_HYSTERESIS_NOTES = """
    Clamped at ``F >= 0``; at ``restitution = 1`` the law is exactly :class:`Hertz`.
"""


@dataclass(frozen=True, kw_only=True)
class LankaraniNikravesh(_HysteresisLaw):
    """Lankarani-Nikravesh (1990) Hertz law with hysteresis damping, eq. (3.9).

    ``F_N = K delta**n [1 + 3 (1 - c_e**2) / 4 * delta_dot / delta_dot_minus]``.

    Parameters
    ----------
    restitution : float
        Coefficient of restitution c_e in (0, 1]; 0.9 in the chapter's benchmark.
    stiffness : float or None
        K in N/m^n (> 0); None: computed by :meth:`resolve` (eq. 3.5; 4.27 with n = 1 for
        "plane_face", the "unified" face model of section 4.3).
    exponent : float or None
        n in [1, 10]; None means 1.5 (1 for a computed plane-face stiffness).
    min_approach_speed : float
        Floor of ``delta_dot_minus`` in m/s, > 0. Default 1e-4.

    Notes
    -----
    Derived for c_e close to 1: the loss is under-predicted at low c_e (effective restitution:
    docs/contact_laws.md).""" + _HYSTERESIS_NOTES

    name: ClassVar[str] = "lankarani-nikravesh"

    @property
    def hysteresis_factor(self) -> float:
        return 0.75 * (1.0 - self.restitution**2)


@dataclass(frozen=True, kw_only=True)
class HuntCrossley(_HysteresisLaw):
    """Hunt-Crossley (1975) law, ``F_N = K delta**n [1 + 3 (1 - c_e) / 2 * delta_dot / delta_dot_minus]``.

    Parameters are those of :class:`LankaraniNikravesh`.

    Notes
    -----
    Linearised about c_e = 1: a high-restitution law (docs/contact_laws.md).""" + _HYSTERESIS_NOTES

    name: ClassVar[str] = "hunt-crossley"

    @property
    def hysteresis_factor(self) -> float:
        return 1.5 * (1.0 - self.restitution)


@dataclass(frozen=True, kw_only=True)
class Flores(_HysteresisLaw):
    """Flores, Machado, Silva & Martins (2011) law for the whole range of restitution.

    ``F_N = K delta**n [1 + 8 (1 - c_e) / (5 c_e) * delta_dot / delta_dot_minus]``
    (Multibody Syst. Dyn. 25:357-375). Not used in chapter 4 (it came later).

    Parameters are those of :class:`LankaraniNikravesh`.

    Notes
    -----
    It slightly over-predicts the loss (docs/contact_laws.md).""" + _HYSTERESIS_NOTES

    name: ClassVar[str] = "flores"

    @property
    def hysteresis_factor(self) -> float:
        return 1.6 * (1.0 - self.restitution) / self.restitution


@dataclass(frozen=True, kw_only=True)
class _FaceLaw(NormalLaw):
    """Linear law with a stiffness in N/m, computed from eq. (4.27) when None."""

    stiffness: float | None = None

    geometry: ClassVar[Geometry] = "face"
    supported_kinds: ClassVar[tuple[str, ...]] = ("plane_face",)

    def __post_init__(self) -> None:
        if self.stiffness is not None:
            set_field(self, "stiffness",
                      check_number(type(self).__name__, "stiffness", self.stiffness, low=0.0, unit="N/m"))

    @property
    def is_resolved(self) -> bool:
        return self.stiffness is not None

    def with_stiffness(self, stiffness: float) -> Self:
        """Return a copy with ``stiffness`` set (N/m)."""
        return dataclasses.replace(self, stiffness=stiffness)

    def _resolve(self, kind: str, *, radii: Any, materials: Any, face_half_width: Any) -> Self:
        if self.stiffness is not None:
            return self
        owner = type(self).__name__
        if kind not in self.supported_kinds:
            raise SceneError(f"{owner}: stiffness=None cannot be computed for kind={kind!r} (a linear "
                             "stiffness in N/m exists only for 'plane_face', eq. 4.27); give stiffness=.")
        return dataclasses.replace(self, stiffness=computed_stiffness(
            owner, kind, radii=radii, materials=materials, face_half_width=face_half_width))


@dataclass(frozen=True, kw_only=True)
class LankaraniPlane(_FaceLaw):
    """Lankarani (1988) linear law for two square plane surfaces, eqs. (4.26)-(4.27).

    ``F_N = K delta``, ``stiffness`` K in N/m (> 0), or None: ``K = a / (0.475 (sigma_i + sigma_j))``
    from ``resolve(kind="plane_face", face_half_width=a, materials=...)``. Elastic; the translational
    joint applies it to a face (Fig. 4.13a). The damped "unified" face model is
    ``LankaraniNikravesh(restitution=...).resolve(kind="plane_face", ...)``.
    """

    name: ClassVar[str] = "lankarani-plane"

    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        return self.stiffness * B.fmax(delta, 0.0)


@dataclass(frozen=True, kw_only=True)
class KelvinVoigt(_FaceLaw):
    """Kelvin-Voigt linear spring-damper, ``F_N = max(K delta + D delta_dot, 0)`` for ``delta > 0``.

    Parameters
    ----------
    stiffness : float or None
        K in N/m (> 0); None is only computable for ``kind="plane_face"`` (eq. 4.27).
    damping : float
        D in N s/m, >= 0. Default 0.

    Notes
    -----
    For comparison only (it "does not represent the overall nonlinear nature of impact"). The
    force jumps to ``D delta_dot_minus`` at first contact and is clamped at 0 near separation:
    :meth:`force` is 0 at ``delta = 0``, :meth:`contact_force` (what a contact term reads) the jump.
    """

    damping: float = 0.0

    name: ClassVar[str] = "kelvin-voigt"

    def __post_init__(self) -> None:
        super().__post_init__()
        set_field(self, "damping", check_number("KelvinVoigt", "damping", self.damping, low=0.0,
                                                low_open=False, unit="N s/m"))

    @property
    def dissipative(self) -> bool:
        """True when ``damping > 0``."""
        return self.damping > 0.0

    def _force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        return B.if_else(delta > 0.0, self._contact_force(delta, delta_dot, v_minus), 0.0)

    def _contact_force(self, delta: Any, delta_dot: Any, v_minus: Any) -> Any:
        # inside a contact (at its onset, delta = 0, too): the jump to D delta_dot, clamped at 0
        return B.if_else(delta >= 0.0, B.fmax(self.stiffness * delta + self.damping * delta_dot, 0.0), 0.0)

