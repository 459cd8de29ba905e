"""Friction laws: none, Coulomb, and the modified Coulomb law of Ambrosio (eq. 3.16).

``sliding_velocity`` is the tangential velocity of the body the force acts on relative to the
other (material points); the signed force opposes it. No law divides by ``|v|``: nothing is NaN
at ``v = 0``.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import Any, ClassVar

from ..core.errors import SceneError
from . import _backend as B
from ._checks import check_number, set_field

__all__ = ["Coulomb", "FrictionLaw", "ModifiedCoulomb", "NoFriction"]


@dataclass(frozen=True, kw_only=True)
class FrictionLaw(abc.ABC):
    """A tangential force law ``F_T(F_N, v_T)``: subclasses set ``name`` and ``smooth`` (continuous in
    v_T) and override ``_force`` (``_backend`` functions, finite everywhere)."""

    name: ClassVar[str]
    smooth: ClassVar[bool]

    @property
    def frictionless(self) -> bool:
        """True if the law never produces a force (the assembly may skip it)."""
        return False

    @property
    def kinks(self) -> tuple[Any, ...]:
        """The sliding speeds |v_T| (m/s), ascending, where the force is continuous but its slope in v_T
        jumps (a piecewise law's breaks; none for a smooth law). A run with sensitivities stops IDA at each
        and integrates S with the piece of the law it is on (:meth:`piece`): S' jumps there with F_y
        (docs/sensitivities.md, "Kinks")."""
        return ()

    @property
    def breakpoints(self) -> tuple[Any, ...]:
        """The signed sliding speeds of the kinks, ascending: -kinks reversed, then kinks. Piece ``r`` of
        :meth:`piece` lies above ``r`` of them."""
        return (*(-k for k in reversed(self.kinks)), *self.kinks)

    def piece(self, normal_force: Any, sliding_velocity: Any, region: Any) -> Any:
        """The formula of the law on piece ``region`` (0 ... len(breakpoints)), continued past its ends: the
        force a run with sensitivities integrates between two kinks. Without kinks, the law itself."""
        return self._force(normal_force, sliding_velocity)

    def friction_force(self, normal_force: Any, sliding_velocity: Any) -> Any:
        """Signed tangential force ``F_T`` (N), ``F_T * v_T <= 0``, from ``F_N >= 0`` (N) and the sliding
        velocity ``v_T`` (m/s), on floats, numpy arrays or CasADi symbols."""
        scalar, (f_n, v_t) = B.as_numeric(normal_force, sliding_velocity)
        out = self._force(f_n, v_t)
        return float(out) if scalar else out

    @abc.abstractmethod
    def _force(self, normal_force: Any, sliding_velocity: Any) -> Any:
        """The law, written once with ``_backend`` functions."""


@dataclass(frozen=True, kw_only=True)
class NoFriction(FrictionLaw):
    """Frictionless contact: ``F_T = 0``."""

    name: ClassVar[str] = "none"
    smooth: ClassVar[bool] = True

    @property
    def frictionless(self) -> bool:
        return True

    def _force(self, normal_force: Any, sliding_velocity: Any) -> Any:
        return 0.0 * normal_force * sliding_velocity


def _coefficient(owner: str, value: Any) -> float:
    return check_number(owner, "coefficient", value, low=0.0, low_open=False)


@dataclass(frozen=True, kw_only=True)
class Coulomb(FrictionLaw):
    """Plain Coulomb friction, ``F_T = -c_f F_N sign(v_T)``.

    ``coefficient``: c_f >= 0. Discontinuous at ``v_T = 0``: an integrator chatters across reversals;
    prefer :class:`ModifiedCoulomb`.
    """

    coefficient: float

    name: ClassVar[str] = "coulomb"
    smooth: ClassVar[bool] = False

    def __post_init__(self) -> None:
        set_field(self, "coefficient", _coefficient("Coulomb", self.coefficient))

    def _force(self, normal_force: Any, sliding_velocity: Any) -> Any:
        return -self.coefficient * normal_force * B.sign(sliding_velocity)


@dataclass(frozen=True, kw_only=True)
class ModifiedCoulomb(FrictionLaw):
    """Modified Coulomb friction of Ambrosio (2002), eq. (3.16).

    ``F_T = -c_f c_d(|v_T|) F_N sign(v_T)`` with the dynamic correction coefficient
    ``c_d = 0`` for ``|v_T| <= v0``, ``(|v_T| - v0)/(v1 - v0)`` between, 1 for ``|v_T| >= v1``.

    Parameters
    ----------
    coefficient : float
        Friction coefficient c_f >= 0 (chapter 4 sweeps 0.01, 0.03, 0.05, 0.1).
    v0 : float
        Speed below which the force is zero, m/s, >= 0. Default 1e-4.
    v1 : float
        Speed from which full Coulomb friction acts, m/s, > v0. Default 2e-4.

    Notes
    -----
    Continuous in ``v_T``, no stiction; the defaults are the Flores-attributed values (docs/contact_laws.md).
    """

    coefficient: float
    v0: float = 1e-4
    v1: float = 2e-4

    name: ClassVar[str] = "modified-coulomb"
    smooth: ClassVar[bool] = True

    def __post_init__(self) -> None:
        set_field(self, "coefficient", _coefficient("ModifiedCoulomb", self.coefficient))
        set_field(self, "v0", check_number("ModifiedCoulomb", "v0", self.v0, low=0.0, low_open=False,
                                           unit="m/s"))
        set_field(self, "v1", check_number("ModifiedCoulomb", "v1", self.v1, low=0.0, unit="m/s"))
        if self.v1 <= self.v0:
            raise SceneError(f"ModifiedCoulomb: v1={self.v1:g} m/s, must be > v0={self.v0:g} m/s.")

    @property
    def kinks(self) -> tuple[Any, ...]:
        """c_d's breaks: |v_T| = v0 and v1."""
        return (self.v0, self.v1)

    def piece(self, normal_force: Any, sliding_velocity: Any, region: Any) -> Any:
        """c_d sign(v_T) on the pieces below -v1, up to -v0, up to v0, up to v1, above: -1, the ramp
        (v_T + v0)/(v1 - v0), 0, (v_T - v0)/(v1 - v0), 1 (``region`` 0 ... 4, a number or a symbol)."""
        v, width = sliding_velocity, self.v1 - self.v0
        factors = (-1.0, (v + self.v0) / width, 0.0, (v - self.v0) / width, 1.0)
        factor = sum((region == j) * f for j, f in enumerate(factors))
        return -self.coefficient * normal_force * factor

    def correction(self, sliding_velocity: Any) -> Any:
        """Dynamic correction coefficient ``c_d(|v_T|)`` in [0, 1], any backend."""
        scalar, (v_t,) = B.as_numeric(sliding_velocity)
        out = self._correction(v_t)
        return float(out) if scalar else out

    def _correction(self, v_t: Any) -> Any:
        ramp = (B.fabs(v_t) - self.v0) / (self.v1 - self.v0)
        return B.fmin(B.fmax(ramp, 0.0), 1.0)

    def _force(self, normal_force: Any, sliding_velocity: Any) -> Any:
        return -self.coefficient * self._correction(sliding_velocity) * normal_force * B.sign(sliding_velocity)
