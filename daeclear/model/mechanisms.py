"""Ready-made scenes: the chapter's slider-crank (Tables 4.1-4.3) and its variants; a chain of N links; a
crank-rocker four-bar and a double pendulum with clearance at any subset of their joints."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ..contact import HydrodynamicBearing, Material, friction_law, normal_law
from ..contact.registry import LAW_TYPES, contact_law
from ..contact.base import NormalLaw
from ..contact.registry import check_restitution
from ..core.errors import SceneError
from .mechanism_options import joint_names, refuse_clearance_options
from .scene import (GROUND, Body, Driver, Element, Revolute, RevoluteClearance, Scene, Translational,
                    is_finite_number)

# Table 4.1: link lengths (m), masses (kg), moments of inertia (kg m^2)
CRANK_LENGTH, CRANK_MASS, CRANK_INERTIA = 0.05, 0.30, 1.0e-4
ROD_LENGTH, ROD_MASS, ROD_INERTIA = 0.12, 0.21, 2.5e-4
SLIDER_MASS, SLIDER_INERTIA = 0.14, 1.0e-4

# Table 4.2: revolute clearance joint
BEARING_RADIUS = 10.0e-3
STEEL = Material(young=207e9, poisson=0.3)

# Table 4.3: translational clearance joint (slider length x width x thickness, corner radius)
SLIDER_LENGTH = SLIDER_WIDTH = SLIDER_THICKNESS = 50.0e-3
CORNER_RADIUS = 1.0e-3
# Guide contact segment: the slider's corners stay 5 mm inside it over the whole stroke.
GUIDE_MARGIN = 5.0e-3

JOINT_KINDS = ("ideal", "revolute", "translational")


def rpm_to_rad_s(rpm: float) -> float:
    """Convert revolutions per minute to rad/s."""
    return rpm * 2.0 * math.pi / 60.0


def ideal_slider_crank_state(theta: float, omega: float, crank: float = CRANK_LENGTH,
                             rod: float = ROD_LENGTH) -> dict[str, tuple[float, float, float, float, float, float]]:
    """Positions and velocities (x, y, phi, vx, vy, omega) of the ideal slider-crank's bodies: crank at
    ``theta`` turning at ``omega``, slider on the X axis, centres of mass at link mid-lengths."""
    s, c = math.sin(theta), math.cos(theta)
    beta = math.asin(-crank * s / rod)  # rod angle (slider on the X axis)
    beta_dot = -crank * c * omega / (rod * math.cos(beta))
    bx, by = crank * c, crank * s
    bvx, bvy = -crank * s * omega, crank * c * omega
    slider_x = bx + rod * math.cos(beta)
    slider_vx = bvx - rod * math.sin(beta) * beta_dot
    return {
        "crank": (0.5 * bx, 0.5 * by, theta, 0.5 * bvx, 0.5 * bvy, omega),
        "rod": (bx + 0.5 * rod * math.cos(beta), by + 0.5 * rod * math.sin(beta), beta,
                bvx - 0.5 * rod * math.sin(beta) * beta_dot, bvy + 0.5 * rod * math.cos(beta) * beta_dot, beta_dot),
        "slider": (slider_x, 0.0, 0.0, slider_vx, 0.0, 0.0),
    }


def _check(where: str, *rows: tuple[str, Any, str, bool]) -> None:
    """Raise SceneError for the first row (field, value, rule, whether it holds) that does not hold."""
    for field_name, value, rule, ok in rows:
        if not ok:
            raise SceneError(f"{where}: {field_name}={value!r}, {rule}.")


def _link_rows(length: Any, mass: Any, inertia: Any) -> tuple[tuple[str, Any, str, bool], ...]:
    """The checks of a chain's or double pendulum's link length, mass and inertia (for :func:`_check`)."""
    return (("link_length", length, "must be a finite number > 0 m", is_finite_number(length) and length > 0),
            ("link_mass", mass, "must be a finite number > 0 kg", is_finite_number(mass) and mass > 0),
            ("link_inertia", inertia, "must be None or a finite number > 0 kg m^2",
             inertia is None or (is_finite_number(inertia) and inertia > 0)))


def _body(name: str, mass: float, inertia: float, state: Mapping[str, tuple[float, ...]]) -> Body:
    """Body ``name`` at its (x, y, phi, vx, vy, omega) in ``state``."""
    x, y, phi, vx, vy, w = state[name]
    return Body(name, mass=mass, inertia=inertia, position=(x, y), angle=phi, velocity=(vx, vy), angular_velocity=w)


DEFAULT_RESTITUTION = 0.9  # Table 4.2, for the laws that take a coefficient of restitution


def _contact_law(law: Any, restitution: float | None, length: float | None) -> NormalLaw | HydrodynamicBearing:
    """A law object from a law, a law table or a name; ``restitution``/``length`` fill the fields the law has."""
    from ..contact.registry import normal_law_class  # one source of names

    if length is not None and not (is_finite_number(length) and length > 0):
        raise SceneError(f"contact law: length={length!r}, must be None or a finite number > 0 m.")
    if isinstance(law, (*LAW_TYPES, dict)):  # a law object, or a law table (--set "law={...}")
        return contact_law(law)
    try:
        cls = normal_law_class(str(law))
    except SceneError:
        return contact_law(law)  # a joint law's name (it needs a table) or an unknown name: its message
    fields = {"restitution": DEFAULT_RESTITUTION if restitution is None else restitution, "length": length}
    accepted = set(getattr(cls, "__dataclass_fields__", {}))
    return normal_law(str(law), **{k: v for k, v in fields.items() if k in accepted and v is not None})


def _make_ideal_elements(omega: float, crank_angle: float, slider_mass: float, slider_inertia: float,
                         offset: tuple[float, ...]) -> tuple[Element, ...]:
    """Bodies crank, rod, slider; revolutes A, B, C; translational D; driver drive (see slider_crank)."""
    state = ideal_slider_crank_state(crank_angle, omega)
    crank = _body("crank", CRANK_MASS, CRANK_INERTIA, state)
    rod = _body("rod", ROD_MASS, ROD_INERTIA, state)
    if offset != (0.0, 0.0):  # the slider's centre, from the pin where the ideal mechanism has it
        state["slider"] = (state["slider"][0] - offset[0], -offset[1], *state["slider"][2:])
    slider = _body("slider", slider_mass, slider_inertia, state)
    pin_b = (CRANK_LENGTH * math.cos(crank_angle), CRANK_LENGTH * math.sin(crank_angle))
    pin_c = (state["slider"][0] + offset[0], 0.0)
    return (crank, rod, slider,
            Revolute("A", GROUND, crank.name, at=(0.0, 0.0)),
            Revolute("B", crank.name, rod.name, at=pin_b),
            Revolute("C", slider.name, rod.name, at=pin_c),  # body_i: the bearing body of a clearance at C
            # the guide's mid-line runs along X through the slider's centre (the X axis unless the pin is offset)
            Translational("D", GROUND, slider.name, point_i=(0.0, -offset[1]), point_j=(0.0, 0.0), axis=(1.0, 0.0)),
            Driver("drive", joint="A", speed=omega))


def slider_crank(joint: str = "ideal", *, gravity: float = 9.81, rpm: float = 5000.0,
                 crank_angle: float = 0.0, name: str | None = None, clearance: float = 0.5e-3,
                 law: Any = "lankarani-nikravesh", restitution: float | None = None, friction: Any = None,
                 bearing_radius: float = BEARING_RADIUS, material: Material = STEEL,
                 length: float | None = None, contact_model: str = "corners",
                 face_law: Any = "lankarani-plane", reading: str | None = None, slider_mass: float = SLIDER_MASS,
                 slider_inertia: float = SLIDER_INERTIA, pin_offset: tuple[float, float] = (0.0, 0.0),
                 bearing: str = "slider", **options: Any) -> Scene:
    """The chapter's slider-crank mechanism (Fig. 4.14, Table 4.1).

    Crank ``crank`` pinned to the ground at the origin by revolute ``A``, driven by driver ``drive``;
    rod ``rod`` joined to the crank by revolute ``B`` and to the slider by joint ``C``; slider
    ``slider`` on the X axis by translational joint ``D``. The crank turns counter-clockwise from
    the collinear position (slider at x = 0.17 m).

    Parameters
    ----------
    joint : {"ideal", "revolute", "translational"}
        Which joint has clearance, named ``clearance`` and centred at the start: "ideal" none,
        "revolute" the rod-slider pin ``C`` (Table 4.2), "translational" the slider's guide ``D``
        (Fig. 4.27, Table 4.3; its geometry in docs/validation.md).
    gravity : float
        Magnitude of gravity along -Y, m/s^2 (0 to switch it off).
    rpm : float
        Crank speed, rev/min (5000 in the chapter); counter-clockwise.
    crank_angle : float
        Initial crank angle, rad.
    name : str or None
        Scene name; defaults to ``"slider_crank"`` (+ the joint kind).
    clearance : float
        Radial clearance, m (0.5 mm in Figs. 4.15 and 4.28); translational: c = (H - W)/2.
    law : str, NormalLaw, HydrodynamicBearing (lubricated revolute joint) or a law table (dict)
        Normal contact law, stiffness computed when not given (default Lankarani-Nikravesh, 3.9).
    restitution : float or None
        Coefficient of restitution c_e for laws that take one (None: 0.9, Table 4.2); an error with
        a law that has none.
    friction : None, float, str or FrictionLaw
        None: frictionless; a float: modified Coulomb (3.16) with that coefficient.
    bearing_radius : float
        Bearing radius, m (10 mm, Table 4.2).
    material : Material
        Material of bearing and journal (steel, 207 GPa, 0.3).
    length : float or None
        Axial contact length L, m, required by the cylindrical laws.
    contact_model : {"corners", "section-4.3"}
        Translational joint only: :class:`~daeclear.model.scene.TranslationalClearance`'s ``model``.
    face_law : str or NormalLaw
        Translational joint, "section-4.3" only: the law of a face in contact (default (4.26)).
    reading : str or None
        Translational joint only: a named reading of the chapter's contact model
        (:mod:`daeclear.model.readings`); it replaces ``contact_model`` and ``face_law``.
    slider_mass, slider_inertia : float
        The slider's mass, kg, and moment of inertia, kg m^2 (Table 4.1: 0.14 and 1e-4).
    bearing : {"slider", "rod"}
        ``joint="revolute"``: the bearing body (the chapter's: the slider, ``C``'s body_i).
    pin_offset : (float, float)
        Translational joint only: the rod-slider pin in slider coordinates from the slider's
        centre, m; (0, 0): at the centre.
    """
    joint, where = str(joint).lower(), "slider_crank"
    _check(where, ("joint", joint, f"must be one of {', '.join(JOINT_KINDS)}", joint in JOINT_KINDS),
           ("gravity", gravity, "must be a finite number >= 0 m/s^2", is_finite_number(gravity) and gravity >= 0),
           ("rpm", rpm, "must be a finite number (rev/min)", is_finite_number(rpm)),
           ("crank_angle", crank_angle, "must be a finite number (rad)", is_finite_number(crank_angle)))
    if options:
        raise SceneError(f"slider_crank(joint={joint!r}): unknown option(s) {', '.join(sorted(options))}.")
    offset = tuple(pin_offset) if isinstance(pin_offset, (tuple, list)) else ()
    translational_only = "is for joint='translational' only"
    _check(where, ("pin_offset", pin_offset, "must be two finite numbers (m)",
                   len(offset) == 2 and all(is_finite_number(v) for v in offset)),
           ("pin_offset", pin_offset, "must be (0, 0) unless joint='translational'",
            joint == "translational" or offset == (0.0, 0.0)),
           ("bearing", bearing, "must be 'slider' or 'rod' (joint='revolute' only)",
            bearing == "slider" or (joint == "revolute" and bearing == "rod")),
           ("reading", reading, translational_only, joint == "translational" or reading is None),
           ("contact_model", contact_model, translational_only, joint == "translational" or contact_model == "corners"))

    omega = rpm_to_rad_s(rpm)
    scene = Scene(name or ("slider_crank" if joint == "ideal" else f"slider_crank_{joint}"), gravity=(0.0, -gravity),
                  elements=list(_make_ideal_elements(omega, crank_angle, slider_mass, slider_inertia, offset)))
    if joint == "ideal":  # an option of a clearance joint would be ignored: refused
        refuse_clearance_options("slider_crank", slider_crank, locals(), "joint='ideal'")
        return scene
    check_restitution(restitution, law, where="slider_crank")  # given for a law without one, it would be dropped
    if joint == "revolute":
        _check(where, ("clearance", clearance, "must be a number in (0, bearing_radius) m",
                       is_finite_number(clearance) and 0 < clearance < bearing_radius))
        return scene.with_clearance(
            "C", name="clearance", bearing=bearing, bearing_radius=bearing_radius, clearance=clearance,
            material=material, law=_contact_law(law, restitution, length), friction=friction_law(friction))
    _check(where, ("clearance", clearance, "must be a number in (0, slider length) m",
                   is_finite_number(clearance) and 0 < clearance < SLIDER_LENGTH))
    inner, outer = ROD_LENGTH - CRANK_LENGTH - offset[0], ROD_LENGTH + CRANK_LENGTH - offset[0]
    reach = 0.5 * SLIDER_LENGTH + GUIDE_MARGIN
    return scene.with_clearance(
        "D", name="clearance", length=SLIDER_LENGTH, width=SLIDER_WIDTH, thickness=SLIDER_THICKNESS,
        corner_radius=CORNER_RADIUS, clearance=clearance, upper_limits=(inner - reach, outer + reach),
        lower_limits=(inner - reach, outer + reach), stroke=(inner, outer), material=material,
        law=_contact_law(law, restitution, length), face_law=_contact_law(face_law, restitution, length),
        friction=friction_law(friction), model=contact_model, reading=reading)


# Chain links: steel, 0.1 m between pins, 25 x 10 mm section (7850 * 0.1 * 0.025 * 0.010 = 0.196 kg).
CHAIN_LINK_LENGTH = 0.1
CHAIN_LINK_MASS = 0.196
CHAIN_LINK_INERTIA = CHAIN_LINK_MASS * CHAIN_LINK_LENGTH ** 2 / 12.0


def chain(n_links: int, *, clearance: float = 0.1e-3, gravity: float = 9.81, rpm: float | None = None,
          angle: float = 0.0, link_length: float = CHAIN_LINK_LENGTH, link_mass: float = CHAIN_LINK_MASS,
          link_inertia: float | None = None, law: Any = "lankarani-nikravesh",
          restitution: float | None = None,
          friction: Any = None, bearing_radius: float = BEARING_RADIUS, material: Material = STEEL,
          length: float | None = None, name: str | None = None, **options: Any) -> Scene:
    """A planar chain of ``n_links`` rigid links with a revolute clearance joint at every pin.

    Links ``link1`` ... ``link<N>`` lie end to end from
    the origin along ``angle``; pin ``pin<k>`` joins link k-1 (the bearing; the ground for k = 1) to
    link k, journals centred at the start. ``rpm=None``: a free chain released from rest, every pin a
    clearance joint (6 N states, no constraint). ``rpm`` a number: ``pin1`` is an ideal revolute
    driven by driver ``drive`` (6 N + 3 states), the links start as one rigid bar turning at that
    speed.

    Parameters
    ----------
    n_links : int
        Number of links N (>= 1).
    clearance : float
        Radial clearance of every clearance joint, m (0.1 mm), in (0, bearing_radius).
    gravity : float
        Magnitude of gravity along -Y, m/s^2 (0 to switch it off).
    rpm : float or None
        None: free chain. A number: the ground pin's speed, rev/min, counter-clockwise.
    angle : float
        Initial angle of the straight chain from the X axis, rad (-pi/2: hanging at rest).
    link_length : float
        Distance between a link's pins, m (0.1).
    link_mass : float
        Mass of a link, kg (0.196: steel, 0.1 m x 25 mm x 10 mm).
    link_inertia : float or None
        Moment of inertia of a link about its centre of mass, kg m^2; None: slender bar.
    law, restitution, friction, bearing_radius, material, length
        As in :func:`slider_crank`, for every clearance joint.
    name : str or None
        Scene name; defaults to ``"chain<N>"``.

    Examples
    --------
    >>> import daeclear as dc
    >>> dc.assemble(dc.mechanisms.chain(3)).summary()["states"]
    18
    """
    if options:  # e.g. the command line's --joint, which is the slider-crank's
        raise SceneError(f"chain: unknown option(s) {', '.join(sorted(options))}.")
    _check("chain", ("n_links", n_links, "must be an integer >= 1",
                     isinstance(n_links, int) and not isinstance(n_links, bool) and n_links >= 1),
           ("gravity", gravity, "must be a finite number >= 0 m/s^2", is_finite_number(gravity) and gravity >= 0),
           ("rpm", rpm, "must be None (free chain) or a finite number (rev/min)",
            rpm is None or is_finite_number(rpm)),
           ("angle", angle, "must be a finite number (rad)", is_finite_number(angle)),
           *_link_rows(link_length, link_mass, link_inertia),
           ("bearing_radius", bearing_radius, "must be a finite number > 0 m",
            is_finite_number(bearing_radius) and bearing_radius > 0))
    _check("chain", ("clearance", clearance, f"must be a number in (0, bearing_radius={bearing_radius!r}) m",
                     is_finite_number(clearance) and 0 < clearance < bearing_radius),
           ("bearing_radius", bearing_radius, f"must be smaller than half the link length ({link_length!r} m)",
            2.0 * bearing_radius < link_length))

    inertia = link_mass * link_length ** 2 / 12.0 if link_inertia is None else float(link_inertia)
    omega = 0.0 if rpm is None else rpm_to_rad_s(rpm)
    scene = Scene(name or f"chain{n_links}", gravity=(0.0, -gravity))
    ux, uy = math.cos(angle), math.sin(angle)
    check_restitution(restitution, law, where="chain")
    contact_law = _contact_law(law, restitution, length)
    bearing: Any = scene.ground
    for k in range(1, n_links + 1):
        r = (k - 0.5) * link_length  # centre of mass: rigid rotation about the origin at omega
        link = scene.add(Body(f"link{k}", mass=link_mass, inertia=inertia, position=(r * ux, r * uy), angle=angle,
                              velocity=(-omega * r * uy, omega * r * ux), angular_velocity=omega))
        pin = ((k - 1) * link_length * ux, (k - 1) * link_length * uy)
        if k == 1 and rpm is not None:
            scene.add(Revolute("pin1", bearing, link, at=pin))
        else:
            scene.add(RevoluteClearance(f"pin{k}", bearing, link, at=pin, bearing_radius=bearing_radius,
                                        clearance=clearance, material=material, law=contact_law,
                                        friction=friction_law(friction)))
        bearing = link
    if rpm is not None:
        scene.add(Driver("drive", joint="pin1", speed=omega))
    return scene


def _clearance_of_joint(clearance: Any, joint: str, where: str) -> float:
    """The clearance of ``joint``: one number for every joint, or a mapping joint -> number."""
    value = clearance.get(joint) if isinstance(clearance, dict) else clearance
    if not is_finite_number(value) or value <= 0:
        raise SceneError(f"{where}: clearance={clearance!r}, must be a number > 0 m or a mapping joint name -> "
                         f"number (none given for joint {joint!r}).")
    return float(value)


def _with_revolute_clearances(scene: Scene, joints: Any, allowed: tuple[str, ...], where: str, *,
                              clearance: Any, law: Any, restitution: float | None, friction: Any,
                              bearing_radius: float, material: Material, length: float | None) -> Scene:
    """``scene`` with a revolute clearance joint (same bearing, material and law) at each of ``joints``."""
    try:
        chosen = joint_names(joints)
    except TypeError:
        raise SceneError(f"{where}: clearance_joints={joints!r}, must be a list of joint names from "
                         f"{', '.join(allowed)}.") from None
    bad = [j for j in chosen if j not in allowed]
    if bad or len(set(chosen)) != len(chosen):
        raise SceneError(f"{where}: clearance_joints={joints!r}, must be distinct joint names from "
                         f"{', '.join(allowed)}.")
    if isinstance(clearance, dict):
        extra = sorted(set(clearance) - set(chosen), key=str)
        if extra:
            raise SceneError(f"{where}: clearance={clearance!r} names joint(s) {', '.join(map(repr, extra))} "
                             f"not in clearance_joints={chosen!r}.")
    if not chosen:  # an option of a clearance joint would be ignored: refused
        refuse_clearance_options(where, globals()[where], {
            "clearance": clearance, "law": law, "restitution": restitution, "friction": friction,
            "bearing_radius": bearing_radius, "material": material, "length": length}, "clearance_joints=()")
        return scene
    check_restitution(restitution, law, where=where)
    contact_law = _contact_law(law, restitution, length)
    for joint in chosen:
        scene = scene.with_clearance(joint, clearance=_clearance_of_joint(clearance, joint, where),
                                     bearing_radius=bearing_radius, material=material, law=contact_law,
                                     friction=friction)
    return scene


# Four-bar (docs/mechanisms.md): a rocker of the rod's section, a crank-rocker ground link.
FOUR_BAR_CRANK, FOUR_BAR_COUPLER, FOUR_BAR_ROCKER, FOUR_BAR_GROUND = CRANK_LENGTH, ROD_LENGTH, 0.10, 0.13
ROCKER_MASS = ROD_MASS * FOUR_BAR_ROCKER / ROD_LENGTH
ROCKER_INERTIA = ROCKER_MASS * FOUR_BAR_ROCKER ** 2 / 12.0
FOUR_BAR_JOINTS = ("A", "B", "C", "D")


def grashof_crank_rocker(crank: float, coupler: float, rocker: float, ground: float) -> bool:
    """Grashof's condition for a crank-rocker: s + l <= p + q with the crank the shortest link (it then
    turns fully and the rocker oscillates)."""
    lengths = (crank, coupler, rocker, ground)
    return crank == min(lengths) and min(lengths) + max(lengths) <= sum(lengths) - min(lengths) - max(lengths)


def ideal_four_bar_state(theta: float, omega: float, crank: float = FOUR_BAR_CRANK, coupler: float = FOUR_BAR_COUPLER,
                         rocker: float = FOUR_BAR_ROCKER, ground: float = FOUR_BAR_GROUND
                         ) -> dict[str, tuple[float, float, float, float, float, float]]:
    """Positions and velocities (x, y, phi, vx, vy, omega) of the ideal four-bar's links, closed form.

    Crank pivot at the origin, rocker pivot at (``ground``, 0), crank at ``theta`` turning at ``omega``;
    the open assembly. Coupler angle beta by the law of cosines, rocker angle psi from the coupler
    pin; the rates from the loop closure a w e'(theta) + b w3 e'(beta) = c w4 e'(psi).
    """
    a, b, c, d = crank, coupler, rocker, ground
    bx, by = a * math.cos(theta), a * math.sin(theta)
    dx, dy = d - bx, -by  # from the crank pin to the rocker pivot
    span = math.hypot(dx, dy)
    cos_alpha = (b * b + span * span - c * c) / (2.0 * b * span)
    if not -1.0 <= cos_alpha <= 1.0:
        raise SceneError(f"four_bar: the links (crank {a!r}, coupler {b!r}, rocker {c!r}, ground {d!r} m) do not "
                         f"close at crank angle {theta!r} rad.")
    beta = math.atan2(dy, dx) + math.acos(cos_alpha)
    cx, cy = bx + b * math.cos(beta), by + b * math.sin(beta)
    psi = math.atan2(cy, cx - d)
    w3 = a * omega * math.sin(psi - theta) / (b * math.sin(beta - psi))
    w4 = a * omega * math.sin(beta - theta) / (c * math.sin(beta - psi))
    bvx, bvy = -a * math.sin(theta) * omega, a * math.cos(theta) * omega
    return {
        "crank": (0.5 * bx, 0.5 * by, theta, 0.5 * bvx, 0.5 * bvy, omega),
        "coupler": (bx + 0.5 * b * math.cos(beta), by + 0.5 * b * math.sin(beta), beta,
                    bvx - 0.5 * b * math.sin(beta) * w3, bvy + 0.5 * b * math.cos(beta) * w3, w3),
        "rocker": (d + 0.5 * c * math.cos(psi), 0.5 * c * math.sin(psi), psi,
                   -0.5 * c * math.sin(psi) * w4, 0.5 * c * math.cos(psi) * w4, w4),
    }


def four_bar(clearance_joints: Any = (), *, rpm: float = 5000.0, crank_angle: float = 0.0, gravity: float = 9.81,
             clearance: Any = 0.5e-3, law: Any = "lankarani-nikravesh", restitution: float | None = None,
             friction: Any = None, bearing_radius: float = BEARING_RADIUS, material: Material = STEEL,
             length: float | None = None, name: str | None = None, **options: Any) -> Scene:
    """A crank-rocker four-bar driven at constant speed, with clearance at any subset of its joints.

    Bodies ``crank``, ``coupler`` and ``rocker``; revolute joints ``A`` (ground - crank, at the
    origin, driven by driver ``drive``), ``B``, ``C`` and ``D`` (ground - rocker, at (0.13, 0) m).
    A joint named in ``clearance_joints`` becomes a RevoluteClearance of the same name (bearing on
    the joint's first body), journals centred and velocities from the ideal mechanism at the start.
    Dimensions (this package's choice): docs/mechanisms.md.

    Parameters
    ----------
    clearance_joints : sequence of {"A", "B", "C", "D"}
        Joints with clearance; () is the ideal four-bar. At ``A`` the driver still prescribes the
        crank's rotation, its journal moving in the play.
    rpm : float
        Crank speed, rev/min, counter-clockwise (5000, the chapter's crank speed).
    crank_angle : float
        Initial crank angle, rad (0: crank along the ground link).
    gravity : float
        Magnitude of gravity along -Y, m/s^2.
    clearance : float or dict
        Radial clearance of every clearance joint, m (0.5 mm), or a mapping joint name -> clearance.
    law, restitution, friction, bearing_radius, material, length
        As in :func:`slider_crank`, for every clearance joint.
    name : str or None
        Scene name; defaults to ``"four_bar"`` (+ ``_`` and the clearance joints, e.g. ``four_bar_BC``).

    Returns
    -------
    Scene
    """
    where = "four_bar"
    if options:  # e.g. the command line's --joint, which is the slider-crank's
        raise SceneError(f"{where}: unknown option(s) {', '.join(sorted(options))}.")
    _check(where, ("rpm", rpm, "must be a finite number (rev/min)", is_finite_number(rpm)),
           ("crank_angle", crank_angle, "must be a finite number (rad)", is_finite_number(crank_angle)),
           ("gravity", gravity, "must be a finite number >= 0 m/s^2", is_finite_number(gravity) and gravity >= 0),
           ("bearing_radius", bearing_radius, "must be a finite number > 0 m",
            is_finite_number(bearing_radius) and bearing_radius > 0))
    omega = rpm_to_rad_s(rpm)
    state = ideal_four_bar_state(crank_angle, omega)
    joints = joint_names(clearance_joints) if isinstance(clearance_joints, (str, tuple, list)) else ()
    suffix = "".join(str(j) for j in joints)
    scene = Scene(name or (f"four_bar_{suffix}" if suffix else "four_bar"), gravity=(0.0, -gravity))
    scene.add(_body("crank", CRANK_MASS, CRANK_INERTIA, state))
    scene.add(_body("coupler", ROD_MASS, ROD_INERTIA, state))
    scene.add(_body("rocker", ROCKER_MASS, ROCKER_INERTIA, state))
    a, b = FOUR_BAR_CRANK, FOUR_BAR_COUPLER
    pin_b = (a * math.cos(crank_angle), a * math.sin(crank_angle))
    beta = state["coupler"][2]
    pin_c = (pin_b[0] + b * math.cos(beta), pin_b[1] + b * math.sin(beta))
    scene.add(Revolute("A", scene.ground.name, "crank", at=(0.0, 0.0)))
    scene.add(Revolute("B", "crank", "coupler", at=pin_b))
    scene.add(Revolute("C", "coupler", "rocker", at=pin_c))
    scene.add(Revolute("D", scene.ground.name, "rocker", at=(FOUR_BAR_GROUND, 0.0)))
    scene.add(Driver("drive", joint="A", speed=omega))
    return _with_revolute_clearances(scene, clearance_joints, FOUR_BAR_JOINTS, where, clearance=clearance, law=law,
                                     restitution=restitution, friction=friction, bearing_radius=bearing_radius,
                                     material=material, length=length)


DOUBLE_PENDULUM_JOINTS = ("A", "B")


def double_pendulum(clearance_joints: Any = (), *, angles: Any = (0.0, 0.0), gravity: float = 9.81,
                    clearance: Any = 0.1e-3, link_length: float = CHAIN_LINK_LENGTH, link_mass: float = CHAIN_LINK_MASS,
                    link_inertia: float | None = None, law: Any = "lankarani-nikravesh",
                    restitution: float | None = None, friction: Any = None, bearing_radius: float = BEARING_RADIUS,
                    material: Material = STEEL, length: float | None = None, name: str | None = None,
                    **options: Any) -> Scene:
    """A double pendulum released from rest, with clearance at any subset of its two pins.

    Links ``link1`` and ``link2`` (the chain's), pin ``A`` from the ground (bearing) to ``link1`` at
    the origin, pin ``B`` from ``link1`` (bearing) to ``link2``; no driver. A pin named in
    ``clearance_joints`` becomes a RevoluteClearance of the same name, journal centred.

    Parameters
    ----------
    clearance_joints : sequence of {"A", "B"}
        Pins with clearance; () is the ideal double pendulum.
    angles : (float, float)
        Initial angles of the two links from the X axis, rad ((0, 0): horizontal; -pi/2: hanging).
    gravity : float
        Magnitude of gravity along -Y, m/s^2.
    clearance : float or dict
        Radial clearance of every clearance pin, m (0.1 mm), or a mapping pin name -> clearance.
    link_length, link_mass, link_inertia
        As in :func:`chain`.
    law, restitution, friction, bearing_radius, material, length
        As in :func:`chain`, for every clearance pin.
    name : str or None
        Scene name; defaults to ``"double_pendulum"`` (+ ``_`` and the clearance pins).

    Returns
    -------
    Scene
    """
    where = "double_pendulum"
    if options:
        raise SceneError(f"{where}: unknown option(s) {', '.join(sorted(options))}.")
    pair = None
    try:
        pair = tuple(float(v) for v in angles)
    except (TypeError, ValueError):
        pass
    _check(where, ("angles", angles, "must be two finite numbers (rad)",
                   pair is not None and len(pair) == 2 and all(map(math.isfinite, pair))),
           ("gravity", gravity, "must be a finite number >= 0 m/s^2", is_finite_number(gravity) and gravity >= 0),
           *_link_rows(link_length, link_mass, link_inertia))
    assert pair is not None
    inertia = link_mass * link_length ** 2 / 12.0 if link_inertia is None else float(link_inertia)
    joints = joint_names(clearance_joints) if isinstance(clearance_joints, (str, tuple, list)) else ()
    suffix = "".join(str(j) for j in joints)
    scene = Scene(name or (f"double_pendulum_{suffix}" if suffix else "double_pendulum"), gravity=(0.0, -gravity))
    pin = (0.0, 0.0)
    bearing: Any = scene.ground
    for k, (joint, angle) in enumerate(zip(DOUBLE_PENDULUM_JOINTS, pair), start=1):
        ux, uy = math.cos(angle), math.sin(angle)
        link = scene.add(Body(f"link{k}", mass=link_mass, inertia=inertia, angle=angle,
                              position=(pin[0] + 0.5 * link_length * ux, pin[1] + 0.5 * link_length * uy)))
        scene.add(Revolute(joint, bearing, link, at=pin))
        bearing, pin = link, (pin[0] + link_length * ux, pin[1] + link_length * uy)
    return _with_revolute_clearances(scene, clearance_joints, DOUBLE_PENDULUM_JOINTS, where, clearance=clearance,
                                     law=law, restitution=restitution, friction=friction,
                                     bearing_radius=bearing_radius, material=material, length=length)
