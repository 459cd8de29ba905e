"""Readings of the chapter's translational clearance joint (section 4.3) and of its Fig. 4.28 run.

Each model the chapter's text supports for Fig. 4.28 is a named *reading* with its ``source`` and
``note`` (the table: docs/validation.md). Joint readings (:data:`JOINT_READINGS`, from
:mod:`daeclear.model.joint_readings`) set the contact laws; mechanism readings
(:data:`MECHANISM_READINGS`, :func:`slider_crank_scene`) change the rest of the scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .joint_readings import (  # noqa: F401  (CORNER_STIFFNESS, FACE_LAWS: re-exported)
    CORNER_STIFFNESS, FACE_LAWS, JOINT_READINGS, JointReading, corner_law, face_law, find_reading, joint_reading)
from .mechanisms import SLIDER_LENGTH, SLIDER_THICKNESS, SLIDER_WIDTH, slider_crank

__all__ = ["JointReading", "MechanismReading", "JOINT_READINGS", "MECHANISM_READINGS", "joint_reading",
           "mechanism_reading", "mechanism_options", "corner_law", "face_law", "slider_crank_scene", "STEEL_DENSITY"]


#: Density of the steel of a solid 50 mm slider block, kg/m^3 (not in the chapter: Table 4.3
#: gives only the steel's E and nu).
STEEL_DENSITY = 7850.0


def _steel_block() -> dict[str, float]:
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
    return find_reading("mechanism reading", name, MECHANISM_READINGS)


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
    joint_reading(reading)
    kwargs: dict[str, Any] = {"clearance": 0.5e-3, **mechanism_options(mechanism), **options}
    name = kwargs.pop("name", None) or f"slider_crank_{reading}_{mechanism}".replace("-", "_").replace(
        ".", "_").replace("+", "_")
    return slider_crank("translational", reading=reading, name=name, **kwargs)
