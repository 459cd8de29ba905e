"""Contact-impact and friction laws that run on floats, numpy arrays and CasADi symbols.

Normal laws (frozen, keyword-only dataclasses; ``law.force(penetration,
penetration_rate, approach_speed) -> F_N >= 0``), as ``class (name, geometry)``:

- :class:`Hertz` ("hertz", sphere): ``K delta^n``, elastic.
- :class:`KelvinVoigt` ("kelvin-voigt", face): ``K delta + D delta_dot``, comparison only.
- :class:`HuntCrossley` ("hunt-crossley", sphere): Hunt & Crossley 1975.
- :class:`LankaraniNikravesh` ("lankarani-nikravesh", sphere): eq. (3.9), the chapter's law.
- :class:`Flores` ("flores", sphere): Flores et al. 2011, whole range of restitution.
- :class:`DubowskyFreudenstein` ("dubowsky-freudenstein", cylinder): implicit, Fig. 4.22c.
- :class:`Goldsmith` ("goldsmith", cylinder): implicit, Fig. 4.22d; form unconfirmed.
- :class:`ESDU78035` ("esdu-78035", cylinder): implicit, Fig. 4.22e.
- :class:`LankaraniPlane` ("lankarani-plane", face): eqs. (4.26)-(4.27), elastic.

Conventions: penetration ``delta > 0`` in contact, rate ``delta_dot > 0`` approaching,
approach speed ``delta_dot_minus > 0`` latched at contact onset. The force is 0 for
``delta <= 0`` (value and CasADi derivative finite), never negative, and the approach
speed is floored at ``min_approach_speed`` (default 1e-4 m/s).

Protocol for joints (how the assembly completes and uses a law)
---------------------------------------------------------------
1. A user gives a law with some numbers left ``None`` (typically ``stiffness=None``,
   or a cylindrical law's radii and materials). ``law.is_resolved`` tells.
2. The joint calls ::

       law = law.resolve(kind, radii=..., materials=..., face_half_width=...)

   with ``kind`` one of :data:`KINDS`:

   - ``"internal_cylinder"``: revolute clearance joint, ``radii=(R_bearing,
     R_journal)``, ``materials=(bearing, journal)``. Sphere-type laws get
     K = 4/(3(sigma_i+sigma_j)) sqrt(R_i R_j/(R_i - R_j)) (3.5); cylindrical laws
     store radii and materials (their ``length=`` is required from the user).
   - ``"sphere_plane"``: a rounded slider corner, ``radii=(R_c,)``: K of (3.5) with
     R_j -> infinity.
   - ``"plane_face"``: a slider face, ``face_half_width=a``: K = a/(0.475(sigma_i+
     sigma_j)) in N/m (4.27); Hertz-type laws with ``exponent=None`` then use n = 1
     (the "unified" face model of section 4.3).

   ``resolve`` returns a copy with every number set and never overrides values the
   user gave; it raises :class:`~daeclear.errors.SceneError` for a kind the law
   cannot use (``law.supported_kinds``) or missing inputs. ``law.geometry`` says what a
   law needs: ``"sphere"`` (K from radii and materials, or given), ``"cylinder"``
   (radii, axial length L and materials), ``"face"`` (face half width and materials,
   or a given N/m stiffness). ``with_stiffness(K)`` returns a copy with K set
   (sphere and face laws).
3. ``law.needs_approach_speed``: latch ``delta_dot`` at the located onset and pass it
   as ``approach_speed``; otherwise pass nothing (or anything). ``law.dissipative``:
   False for the elastic laws (energy-conservation checks apply).
4. ``law.force(delta, delta_dot, delta_dot_minus)`` on CasADi ``SX``/``MX`` builds the
   residual term; cylindrical laws unroll a fixed safeguarded Newton solve, so the
   expression is branch-free and its Jacobian is the implicit-function derivative.
5. After a run, ``law.check_penetration(values)`` warns if a penetration left the
   law's valid range (``law.penetration_limit``, finite only for cylindrical laws).

Friction laws (``friction.friction_force(F_N, v_T)`` -> signed F_T opposing v_T):
:class:`NoFriction` ("none"), :class:`Coulomb` ("coulomb"), :class:`ModifiedCoulomb`
("modified-coulomb" / "ambrosio", eq. 3.16, ``v0=1e-4``, ``v1=2e-4`` m/s).
``friction.frictionless`` is True for NoFriction.

Registries: :func:`normal_law` ``("lankarani-nikravesh", restitution=0.9)`` and
:func:`friction_law` (``None`` -> none, a float -> ModifiedCoulomb(coefficient=...)).
Materials and stiffness: :class:`Material`, :func:`internal_contact_stiffness`,
:func:`sphere_plane_stiffness`, :func:`plane_face_stiffness`,
:func:`external_contact_stiffness`. A single impact: :func:`simulate_impact`.

Lubricated revolute joint: :class:`HydrodynamicBearing` (viscosity, length, theory "short"/"long",
cavitation "half"/"full", the dry law below ``film_threshold``); ``film_force(eps, wedge_rate,
squeeze_rate, radius, clearance) -> (radial, tangential)`` (docs/lubrication.md).

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

from . import _backend as backend  # the math of laws written once for numbers and CasADi (public name)
from .base import KINDS, NormalLaw
from .cylindrical import DubowskyFreudenstein, ESDU78035, Goldsmith
from .friction import Coulomb, FrictionLaw, ModifiedCoulomb, NoFriction
from .geometry import (
    Material, external_contact_stiffness, internal_contact_stiffness, plane_face_stiffness,
    sphere_plane_stiffness,
)
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
