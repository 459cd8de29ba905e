"""The joint readings of the chapter's translational clearance joint (section 4.3): each reading's
contact laws (see :mod:`daeclear.model.readings`, which re-exports everything here and adds the
mechanism readings; the clearance joints import this module, so the scene stays out of the
mechanism library's imports).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from ..core.errors import SceneError

__all__ = ["JointReading", "JOINT_READINGS", "joint_reading", "corner_law", "face_law", "find_reading"]

#: Corner stiffness sources: eq. (3.5) of a sphere of the corner radius on a plane, or the
#: pseudo-stiffness (4.27) of a square face of half side a.
CORNER_STIFFNESS = ("sphere", "pseudo")
#: Face laws of the ``section-4.3`` model: Lankarani's linear law (4.26), or (3.9) with (4.27).
FACE_LAWS = ("linear", "damped")


@dataclass(frozen=True)
class JointReading:
    """One reading of the contact model of section 4.3 (see :mod:`daeclear.model.readings`)."""

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


def find_reading(kind: str, name: Any, table: dict[str, Any]) -> Any:
    """``table[name]`` (name case- and blank-insensitive); a :class:`SceneError` naming ``kind``, the
    value and the allowed names otherwise."""
    if not isinstance(name, str) or name.strip().lower() not in table:
        raise SceneError(f"{kind}={name!r} is not a reading; allowed: {', '.join(map(repr, table))}.")
    return table[name.strip().lower()]


def joint_reading(name: str) -> JointReading:
    """The joint reading called ``name``; a :class:`SceneError` listing the allowed names otherwise."""
    return find_reading("reading", name, JOINT_READINGS)


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
