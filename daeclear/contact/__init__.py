"""Contact-impact and friction laws that run on floats, numpy arrays and CasADi symbols.

Normal laws (frozen dataclasses, ``law.force(penetration, penetration_rate, approach_speed) -> F_N
>= 0``), friction laws (``friction_force(F_N, v_T)``, opposing v_T), :class:`HydrodynamicBearing`,
by name :func:`normal_law` and :func:`friction_law`; stiffness: :class:`Material` and the
``*_stiffness`` functions; a single impact: :func:`simulate_impact`.

Penetration ``delta > 0`` in contact, rate ``delta_dot > 0`` approaching, approach speed latched at
onset; the force is 0 for ``delta <= 0`` and never negative. A joint completes a law with
``law.resolve(kind, radii=..., materials=..., face_half_width=...)`` (:data:`KINDS`; the protocol,
the laws and their sources: docs/contact_laws.md).

Example
-------
>>> import daeclear.contact as dcc
>>> steel = dcc.Material(young=207e9, poisson=0.3)
>>> law = dcc.LankaraniNikravesh(restitution=0.9).resolve(
...     "internal_cylinder", radii=(10.0e-3, 9.5e-3), materials=steel)
>>> f"{law.stiffness:.4g}"
'6.61e+10'
"""

from __future__ import annotations

from . import _backend as backend  # the math of laws written once for numbers and CasADi
from .base import KINDS, NormalLaw
from .cylindrical import DubowskyFreudenstein, ESDU78035, Goldsmith
from .friction import Coulomb, FrictionLaw, ModifiedCoulomb, NoFriction
from .geometry import (Material, external_contact_stiffness, internal_contact_stiffness, plane_face_stiffness,
                       sphere_plane_stiffness)
from .hydrodynamic import HydrodynamicBearing
from .impact import ImpactResult, simulate_impact
from .normal import Flores, Hertz, HuntCrossley, KelvinVoigt, LankaraniNikravesh, LankaraniPlane
from .registry import FRICTION_LAWS, NORMAL_LAWS, friction_law, normal_law

__all__ = [
    "Coulomb", "DubowskyFreudenstein", "backend", "ESDU78035", "FRICTION_LAWS", "Flores", "FrictionLaw", "Goldsmith",
    "Hertz", "HuntCrossley", "HydrodynamicBearing", "ImpactResult",
    "KINDS", "KelvinVoigt", "LankaraniNikravesh", "LankaraniPlane",
    "Material", "ModifiedCoulomb", "NORMAL_LAWS", "NoFriction", "NormalLaw", "external_contact_stiffness",
    "friction_law", "internal_contact_stiffness", "normal_law", "plane_face_stiffness", "simulate_impact",
    "sphere_plane_stiffness",
]
