"""Readings of the chapter's translational clearance joint (section 4.3) and of its Fig. 4.28 run.

The chapter's text admits several models for the slider-crank of Fig. 4.28; each one it
supports is a named *reading* here, with the sentence it comes from (``source``) and what we
had to choose where the text is silent (``note``).

Joint readings (:data:`JOINT_READINGS`, ``TranslationalClearance(reading=...)``) decide the
contact model: which stiffness the corner law (3.9) has, with which exponent, and how a face
(two adjacent corners on one surface) is treated:

============================ =========== ============================ ==========================
name                          model       corner law (3.9)              face in contact
============================ =========== ============================ ==========================
``corners``                   corners     K (3.5), R_c = 1 mm, n 1.5    two corner spheres
``pseudo-corners``            corners     K (4.27), a = 25 mm, n 1.5    two corner "spheres"
``pseudo-corners-linear``     corners     K (4.27), n 1                 two corners
``section-4.3``               section-4.3 K (3.5), n 1.5                (4.26): K (4.27) d_mean
``unified``                   section-4.3 K (3.5), n 1.5                (3.9) with K (4.27), n 1
``unified-hertz``             section-4.3 K (3.5), n 1.5                (3.9) with K (4.27), n 1.5
============================ =========== ============================ ==========================

The restitution coefficient (and the approach-speed floor) of the joint's ``law`` is kept;
stiffness and exponent come from the reading. Every number (K, n, c_e, a, R_c) is a run-time
parameter of the compiled model; only the contact model, the law classes and whether an
exponent is 1 are structure. K of (4.27) is in N/m; used with n = 1.5 its number is taken in
N/m^1.5 (the chapter does not say which units the "pseudo-stiffness" has in (3.9)).

Mechanism readings (:data:`MECHANISM_READINGS`, :func:`slider_crank_scene`) change the rest
of the Fig. 4.28 scene: gravity, the slider's mass and inertia, where the rod is pinned on the
slider, friction.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from ..errors import SceneError

__all__ = ["JointReading", "MechanismReading", "JOINT_READINGS", "MECHANISM_READINGS", "joint_reading",
           "mechanism_reading", "mechanism_options", "corner_law", "face_law", "slider_crank_scene", "STEEL_DENSITY"]

#: Corner stiffness sources: eq. (3.5) of a sphere of the corner radius on a plane, or the
#: pseudo-stiffness (4.27) of a square face of half side a.
CORNER_STIFFNESS = ("sphere", "pseudo")
#: Face laws of the ``section-4.3`` model: Lankarani's linear law (4.26), or (3.9) with (4.27).
FACE_LAWS = ("linear", "damped")


@dataclass(frozen=True)
class JointReading:
    """One reading of the contact model of section 4.3 (see the module docstring)."""

    name: str
    model: str  # TranslationalClearance model: "corners" or "section-4.3"
    corner_stiffness: str  # one of CORNER_STIFFNESS
    corner_exponent: float  # n of the corner law
    face_law: str | None  # one of FACE_LAWS; None for the "corners" model
    face_exponent: float | None  # n of a "damped" face law
    source: str  # the chapter's sentence
    note: str = ""  # what the text leaves open and we chose

    def __post_init__(self) -> None:
        if self.corner_stiffness not in CORNER_STIFFNESS or self.face_law not in (None, *FACE_LAWS):
            raise ValueError(f"JointReading {self.name!r}: corner_stiffness={self.corner_stiffness!r} must be one of "
                             f"{CORNER_STIFFNESS}, face_law={self.face_law!r} one of {(None, *FACE_LAWS)}.")
        if (self.face_law is None) != (self.model == "corners"):
            raise ValueError(f"JointReading {self.name!r}: a face law goes with the 'section-4.3' model only.")


_S35 = ("For convenience, a small radius of curvature at each slider corner is considered, in order to calculate "
        "the equivalent generalized stiffness given by (3.5).")
_S39 = ("The impact between the slider and guide surfaces is assumed to be frictionless, the Lankarani and Nikravesh "
        "contact force model expressed by (3.9) being used to compute the normal forces.")
_SCENARIOS = ("For the cases represented in Fig. 4.9, the contact forces are evaluated using the continuous contact "
              "force model.")
_UNIFIED = ("The unified contact model is obtained using the pseudo-stiffness expressed by (4.27) in the continuous "
            "force model represented by (3.9).")
_FACE = ("When two adjacent slider corners contact with the guide surface, the resulting contact force is applied at "
         "the geometric center of the penetration area, denoted as GC in Fig. 4.13a, and the contact force model "
         "given by (4.26) is used. Otherwise, when one or two opposite slider corners contact the guide surface the "
         "contact is assumed to be between a spherical surface and a plane surface, allowing for the contact model "
         "given by Hertz law with hysteretic damping factor expressed by (3.9) to be applied.")

#: The joint readings by name (``TranslationalClearance(reading=...)``).
JOINT_READINGS: dict[str, JointReading] = {r.name: r for r in (
    JointReading("corners", "corners", "sphere", 1.5, None, None, f"{_S39} {_S35} {_SCENARIOS}",
                 "Section 4.5 for Fig. 4.28: every touching corner is a sphere of R_c on a plane; a face is two "
                 "corners. daeclear's default."),
    JointReading("pseudo-corners", "corners", "pseudo", 1.5, None, None, _UNIFIED,
                 "One law for every scenario of Fig. 4.9: (3.9) with K of (4.27) (a = 25 mm) at every corner, "
                 "n = 1.5 as in Hertz's law; the N/m number of (4.27) taken in N/m^1.5."),
    JointReading("pseudo-corners-linear", "corners", "pseudo", 1.0, None, None, _UNIFIED,
                 "As pseudo-corners with n = 1, the exponent of (4.26) that (4.27) belongs to."),
    JointReading("section-4.3", "section-4.3", "sphere", 1.5, "linear", None, _FACE,
                 "A face: (4.26) with K of (4.27) on the average penetration (the sentence of Figs. 4.35-4.36: "
                 "'the average penetration is used to evaluate the magnitude of the contact force'), undamped; "
                 "one or two opposite corners: (3.9) with K of (3.5)."),
    JointReading("unified", "section-4.3", "sphere", 1.5, "damped", 1.0, f"{_FACE} {_UNIFIED}",
                 "A face: (3.9) (damped, c_e of the joint's law) with K of (4.27) and n = 1 on the average "
                 "penetration; corners as in section-4.3."),
    JointReading("unified-hertz", "section-4.3", "sphere", 1.5, "damped", 1.5, f"{_FACE} {_UNIFIED}",
                 "As unified with n = 1.5 (Hertz's exponent of (3.9)); the N/m number of (4.27) taken in N/m^1.5."),
)}


def _known(kind: str, name: Any, table: dict[str, Any]) -> Any:
    if not isinstance(name, str) or name.strip().lower() not in table:
        raise SceneError(f"{kind}={name!r} is not a reading; allowed: {', '.join(map(repr, table))}.")
    return table[name.strip().lower()]


def joint_reading(name: str) -> JointReading:
    """The joint reading called ``name``; a :class:`SceneError` listing the allowed names otherwise."""
    return _known("reading", name, JOINT_READINGS)


def _pseudo_stiffness(owner: str, face_half_width: float, materials: Any) -> float:
    """K of eq. (4.27), a / (0.475 (sigma_i + sigma_j)), N/m."""
    from ..contact.base import computed_stiffness

    return computed_stiffness(owner, "plane_face", radii=None, materials=materials, face_half_width=face_half_width)


def _stiffness_law(owner: str, law: Any) -> Any:
    """The joint's law as the base of a reading: a Hertz-type law whose stiffness and exponent are left free."""
    if not {"stiffness", "exponent"} <= {f.name for f in dataclasses.fields(law)}:
        raise SceneError(f"{owner}: law={type(law).__name__} has no stiffness and exponent to set; a reading needs "
                         "a Hertz-type law (hertz, lankarani-nikravesh, hunt-crossley, flores).")
    if law.stiffness is not None or law.exponent is not None:
        raise SceneError(f"{owner}: law has stiffness={law.stiffness!r}, exponent={law.exponent!r}; with a reading "
                         "both come from the reading: leave them None.")
    return law


def corner_law(reading: JointReading, law: Any, *, corner_radius: float, face_half_width: float,
               materials: Any, owner: str = "reading") -> Any:
    """The corner law of ``reading``: ``law`` (its class and restitution) with the reading's K and n."""
    base = _stiffness_law(owner, law)
    if reading.corner_stiffness == "sphere":
        return dataclasses.replace(base, exponent=reading.corner_exponent).resolve(
            "sphere_plane", radii=(float(corner_radius),), materials=materials)
    return dataclasses.replace(base, stiffness=_pseudo_stiffness(owner, face_half_width, materials),
                               exponent=reading.corner_exponent)


def face_law(reading: JointReading, law: Any, *, face_half_width: float, materials: Any,
             owner: str = "reading") -> Any | None:
    """The face law of ``reading`` (None for the ``corners`` model): (4.26) or ``law`` with K (4.27)."""
    if reading.face_law is None:
        return None
    if reading.face_law == "linear":
        from ..contact import LankaraniPlane

        return LankaraniPlane().resolve("plane_face", face_half_width=face_half_width, materials=materials)
    base = _stiffness_law(owner, law)
    return dataclasses.replace(base, stiffness=_pseudo_stiffness(owner, face_half_width, materials),
                               exponent=reading.face_exponent)


# ---------------------------------------------------------------------------- mechanism

#: Density of the steel of a solid 50 mm slider block, kg/m^3 (not in the chapter: Table 4.3
#: gives only the steel's E and nu).
STEEL_DENSITY = 7850.0


def _steel_block() -> dict[str, float]:
    from .mechanisms import SLIDER_LENGTH, SLIDER_THICKNESS, SLIDER_WIDTH

    mass = STEEL_DENSITY * SLIDER_LENGTH * SLIDER_WIDTH * SLIDER_THICKNESS
    return {"slider_mass": mass, "slider_inertia": mass * (SLIDER_LENGTH ** 2 + SLIDER_WIDTH ** 2) / 12.0}


@dataclass(frozen=True)
class MechanismReading:
    """One reading of the rest of the Fig. 4.28 scene: ``options`` of
    :func:`daeclear.mechanisms.slider_crank` (its numbers are run-time parameters)."""

    name: str
    options: dict[str, Any] = field(default_factory=dict)
    source: str = ""
    note: str = ""
    in_text: bool = True  # False: a sensitivity the text neither states nor excludes


#: The mechanism readings by name (:func:`slider_crank_scene`).
MECHANISM_READINGS: dict[str, MechanismReading] = {r.name: r for r in (
    MechanismReading("table-4.1", {}, "The geometric and inertia properties of each body are listed in Table 4.1. "
                     "[...] the initial velocities and positions are those used in Sect. 4.4.",
                     "Slider 0.14 kg, 1e-4 kg m^2 (Table 4.1), rod pinned at the slider's centre, gravity 9.81 "
                     "m/s^2 along -Y, frictionless. daeclear's default."),
    MechanismReading("no-gravity", {"gravity": 0.0}, "Tables 4.1-4.3 list no gravity; the chapter never names it.",
                     "The same scene without gravity."),
    MechanismReading("steel-block", _steel_block(), "Table 4.3: slider length, width and thickness 50.0 mm; "
                     "Young's modulus 207 GPa, Poisson's ratio 0.3 (a steel slider).",
                     "A solid steel block (7850 kg/m^3): 0.981 kg and m (L^2 + W^2)/12 = 4.09e-4 kg m^2, "
                     "instead of Table 4.1's 0.14 kg and 1e-4 kg m^2."),
    MechanismReading("pin-rear", {"pin_offset": (-25e-3, 0.0)},
                     "The chapter does not say where the rod is pinned on the slider (Fig. 4.27 draws it).",
                     "Rod pinned at the centre of the slider's rear face (towards the crank), 25 mm behind its "
                     "centre of mass: its lateral force turns the slider.", in_text=False),
    MechanismReading("friction-0.01", {"friction": 0.01}, "[...] four different values for the friction "
                     "coefficient are used, namely, 0.01, 0.03, 0.05 and 0.1. (Figs. 4.32-4.34)",
                     "Modified Coulomb (3.16), v0 = 1e-4, v1 = 2e-4 m/s, at every active contact. Fig. 4.28 "
                     "itself is 'assumed to be frictionless'."),
    MechanismReading("friction-0.1", {"friction": 0.1}, "[...] namely, 0.01, 0.03, 0.05 and 0.1. (Figs. 4.32-4.34)",
                     "As friction-0.01 with c_f = 0.1."),
)}


def mechanism_reading(name: str) -> MechanismReading:
    """The mechanism reading called ``name``; a :class:`SceneError` listing the allowed names otherwise."""
    return _known("mechanism reading", name, MECHANISM_READINGS)


def mechanism_options(mechanism: str) -> dict[str, Any]:
    """The :func:`~daeclear.mechanisms.slider_crank` options of a mechanism reading, or of several
    joined by ``+`` (e.g. ``"steel-block+friction-0.1"``; a later one wins on a shared option)."""
    out: dict[str, Any] = {}
    for name in str(mechanism).split("+"):
        out.update(mechanism_reading(name).options)
    return out


def slider_crank_scene(reading: str = "corners", mechanism: str = "table-4.1", **options: Any) -> Any:
    """The Fig. 4.28 slider-crank (c = 0.5 mm, c_e = 0.9, 5000 rpm) under a joint and a mechanism reading.

    ``mechanism``: a mechanism reading's name, or several joined by ``+``; ``options`` are further
    :func:`daeclear.mechanisms.slider_crank` keywords (they win over the mechanism reading's).
    """
    from .mechanisms import slider_crank

    joint_reading(reading)
    kwargs: dict[str, Any] = {"clearance": 0.5e-3, **mechanism_options(mechanism), **options}
    name = kwargs.pop("name", None) or f"slider_crank_{reading}_{mechanism}".replace("-", "_").replace(
        ".", "_").replace("+", "_")
    return slider_crank("translational", reading=reading, name=name, **kwargs)
