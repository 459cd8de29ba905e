"""Scene description: bodies, joints, drivers and gravity of a planar mechanism.

A scene is plain data (frozen dataclasses, SI units, planar 2-vectors); it knows
nothing of CasADi or of the solver. ``Scene.validate()`` collects every problem of
the scene and raises one :class:`~daeclear.errors.SceneError` listing them all.

Conventions
-----------
* Every body has generalized coordinates ``(x, y, phi)`` of its centre of mass.
* Joints join two bodies at a world point ``at`` given in the *reference
  configuration*, i.e. with the bodies at their declared ``position`` and
  ``angle``. The body-fixed attachment points are taken from that configuration.
  Alternatively give them directly in body coordinates with ``point_i`` and
  ``point_j``; then the declared positions are only guesses that assembly corrects.
* The ground is the body named ``"ground"``: fixed at the origin, angle zero.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar, Iterator, Union

from ..errors import SceneError
from .profiles import PROFILES, ConstantSpeed, Profile

GROUND = "ground"

Vector2 = tuple[float, float]


def _is_finite_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _as_vector2(value: Any) -> Vector2 | None:
    """Return ``value`` as a tuple of two finite floats, or None if it is not one."""
    try:
        items = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return None
    if len(items) != 2 or not all(math.isfinite(v) for v in items):
        return None
    return items  # type: ignore[return-value]


# public names of the helpers above, for the elements defined in other modules (daeclear.loads)
is_finite_number, as_vector2 = _is_finite_number, _as_vector2


class Element:
    """Base class of every scene element: a name, and a list of own problems."""

    name: str
    #: fields whose effect on the equations the element's structure flags already state (the
    #: compiled engine leaves them out of the structure key: a name for numbers compiles nothing)
    NOT_STRUCTURE: ClassVar[frozenset[str]] = frozenset()

    @property
    def kind(self) -> str:
        return type(self).__name__

    def problems(self) -> list[str]:
        """Problems of this element alone (empty when valid)."""
        if not isinstance(self.name, str) or not self.name.strip():
            return [f"{self.kind}: name={self.name!r}, must be a non-empty string."]
        if "." in self.name or "/" in self.name:
            return [f"{self.kind} '{self.name}': name must not contain '.' or '/' (used in channel names)."]
        return []

    def _check_positive(self, out: list[str], field_name: str, unit: str) -> None:
        value = getattr(self, field_name)
        if not _is_finite_number(value) or value <= 0:
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be a finite number > 0.")

    def _check_vector(self, out: list[str], field_name: str, unit: str, optional: bool = False) -> None:
        value = getattr(self, field_name)
        if optional and value is None:
            return
        if _as_vector2(value) is None:
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be two finite numbers (x, y).")

    def _check_one_positive(self, out: list[str], first: str, second: str, unit: str) -> None:
        """Exactly one of two alternative fields is given, and it is > 0."""
        a, b = getattr(self, first), getattr(self, second)
        if (a is None) == (b is None):
            out.append(f"{self.kind} '{self.name}': give exactly one of {first}= or {second}= "
                       f"(got {first}={a!r}, {second}={b!r}).")
        else:
            self._check_positive(out, first if a is not None else second, unit)

    def _check_number(self, out: list[str], field_name: str, unit: str) -> None:
        value = getattr(self, field_name)
        if not _is_finite_number(value):
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be a finite number.")

    def to_dict(self) -> dict[str, Any]:
        """Plain-data description (element kind and fields) for files and HDF5 attributes."""
        out: dict[str, Any] = {"kind": self.kind}
        for f in fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if hasattr(value, "to_dict"):
                value = value.to_dict()
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out


def _body_name(body: Union[str, "Body", "Ground"]) -> str:
    return body if isinstance(body, str) else getattr(body, "name", body)


body_name = _body_name  # public name, for the elements defined in other modules


@dataclass(frozen=True)
class Body(Element):
    """A rigid body moving in the plane.

    Parameters
    ----------
    name : str
        Unique name in the scene (used by joints, channels and errors).
    mass : float
        Mass, kg (> 0).
    inertia : float
        Moment of inertia about the centre of mass, kg m^2 (> 0).
    position : (float, float)
        Initial position of the centre of mass, m (a guess when constrained).
    angle : float
        Initial angle of the body frame, rad.
    velocity : (float, float)
        Initial velocity of the centre of mass, m/s (a guess when constrained).
    angular_velocity : float
        Initial angular velocity, rad/s (a guess when constrained).
    """

    name: str
    mass: float
    inertia: float
    position: Vector2 = (0.0, 0.0)
    angle: float = 0.0
    velocity: Vector2 = (0.0, 0.0)
    angular_velocity: float = 0.0

    def __post_init__(self) -> None:
        for name in ("position", "velocity"):
            vec = _as_vector2(getattr(self, name))
            if vec is not None:
                object.__setattr__(self, name, vec)

    def problems(self) -> list[str]:
        out = super().problems()
        if self.name == GROUND:
            out.append(f"Body '{GROUND}': the name is reserved for the fixed ground; use scene.ground.")
        self._check_positive(out, "mass", "kg")
        self._check_positive(out, "inertia", "kg m^2")
        self._check_vector(out, "position", "m")
        self._check_number(out, "angle", "rad")
        self._check_vector(out, "velocity", "m/s")
        self._check_number(out, "angular_velocity", "rad/s")
        return out


@dataclass(frozen=True)
class Ground:
    """The fixed ground: the body named ``"ground"`` at the origin with angle zero."""

    name: str = GROUND


@dataclass(frozen=True)
class Joint(Element):
    """Base class of joints between two bodies ``body_i`` and ``body_j``."""

    name: str
    body_i: str
    body_j: str

    def __post_init__(self) -> None:
        object.__setattr__(self, "body_i", _body_name(self.body_i))
        object.__setattr__(self, "body_j", _body_name(self.body_j))

    @property
    def bodies(self) -> tuple[str, str]:
        return (self.body_i, self.body_j)

    def problems(self) -> list[str]:
        out = super().problems()
        if self.body_i == self.body_j:
            out.append(f"{self.kind} '{self.name}': joins body '{self.body_i}' to itself; give two different bodies.")
        return out


@dataclass(frozen=True)
class _PointJoint(Joint):
    """A joint located by a world point ``at`` or by body-fixed points ``point_i``/``point_j``."""

    at: Vector2 | None = None
    point_i: Vector2 | None = None
    point_j: Vector2 | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("at", "point_i", "point_j"):
            vec = _as_vector2(getattr(self, name)) if getattr(self, name) is not None else None
            if vec is not None:
                object.__setattr__(self, name, vec)

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_vector(out, "at", "m", optional=True)
        self._check_vector(out, "point_i", "m", optional=True)
        self._check_vector(out, "point_j", "m", optional=True)
        local = (self.point_i is not None, self.point_j is not None)
        if self.at is None and not all(local):
            out.append(
                f"{self.kind} '{self.name}': give the world point at=(x, y), "
                "or both body-fixed points point_i and point_j."
            )
        return out


@dataclass(frozen=True)
class Revolute(_PointJoint):
    """Ideal revolute (pin) joint: point P of body i coincides with point P of body j.

    Adds two constraint equations, ``r_i + A_i s_i - r_j - A_j s_j = 0``.
    """


@dataclass(frozen=True)
class Translational(_PointJoint):
    """Ideal translational (prismatic) joint: body j slides on body i along ``axis``.

    ``axis`` is a world direction in the reference configuration (fixed to body i);
    the two constraints keep the joint point of body j on the line through the joint
    point of body i along ``axis``, and keep the relative angle constant.
    """

    axis: Vector2 = (1.0, 0.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        vec = _as_vector2(self.axis)
        if vec is not None:
            object.__setattr__(self, "axis", vec)

    def problems(self) -> list[str]:
        out = super().problems()
        vec = _as_vector2(self.axis)
        if vec is None or math.hypot(*vec) < 1e-12:
            out.append(f"{self.kind} '{self.name}': axis={self.axis!r}, must be a non-zero 2-vector.")
        return out


@dataclass(frozen=True)
class Driver(Element):
    """Prescribed motion of one joint coordinate (a kinematic driver constraint).

    On a revolute joint (:class:`Revolute` or :class:`RevoluteClearance`) the coordinate is
    the relative angle ``phi_j - phi_i``; on a translational joint (:class:`Translational` or
    :class:`TranslationalClearance`) it is the displacement of point j from point i along the
    joint's axis (fixed to body i). The driver imposes ``x(t) = x0 + motion(t)`` with the
    ``profile``'s motion (constant speed by default: ``x0 + speed t``; see
    :mod:`daeclear.profiles`), where ``x0`` is the coordinate of the reference configuration
    unless ``initial_angle`` (revolute) or ``initial_position`` (translational) is given. On a
    clearance joint only this coordinate is prescribed: the journal (slider) stays free in its
    play. Channels: ``<name>.moment`` (N m, revolute) or ``<name>.force`` (N, translational),
    the load the driver applies to body j (counter-clockwise / along the axis positive), and
    ``<name>.power`` (W).

    Parameters
    ----------
    name : str
        Unique name.
    joint : str
        Name of a revolute or translational joint of the scene, with or without clearance.
    speed : float or None
        Speed of the profile, rad/s (m/s on a translational joint); None only with a
        :class:`~daeclear.profiles.Tabulated` profile, which gives the coordinate itself.
    initial_angle : float or None
        Relative angle ``phi_j - phi_i`` at t = 0, rad (revolute joints); None keeps the reference one.
    profile : Profile or None
        Motion profile (:class:`~daeclear.profiles.Ramp`, ``Harmonic``, ``Tabulated``); None: constant speed.
    initial_position : float or None
        Displacement along the axis at t = 0, m (translational joints); None keeps the reference one.
    """

    name: str
    joint: str
    speed: float | None = None
    initial_angle: float | None = None
    profile: Profile | None = None
    initial_position: float | None = None

    @property
    def motion_profile(self) -> Profile:
        """The profile, :class:`~daeclear.profiles.ConstantSpeed` when none is given."""
        return ConstantSpeed() if self.profile is None else self.profile

    def problems(self) -> list[str]:
        out = super().problems()
        profile = self.motion_profile
        if not isinstance(profile, Profile):
            out.append(f"{self.kind} '{self.name}': profile={self.profile!r}, must be None or a daeclear.profiles "
                       f"profile ({', '.join(c.__name__ for c in PROFILES.values())}).")
            return out
        if profile.uses_speed:
            self._check_number(out, "speed", "rad/s (m/s on a translational joint)")
        else:
            for name in ("speed", "initial_angle", "initial_position"):
                if getattr(self, name) is not None:
                    out.append(f"{self.kind} '{self.name}': {name}={getattr(self, name)!r} is given by the "
                               f"{type(profile).__name__} profile's values; leave it out.")
        if self.initial_angle is not None:
            self._check_number(out, "initial_angle", "rad")
        if self.initial_position is not None:
            self._check_number(out, "initial_position", "m")
        out.extend(profile.problems(self.name))
        return out


@dataclass
class Scene:
    """A planar mechanism: bodies, joints and drivers, a fixed ground and gravity.

    Parameters
    ----------
    name : str
        Scene name (results and files carry it).
    gravity : (float, float)
        Gravitational acceleration vector, m/s^2; ``(0, -9.81)`` by default.

    Examples
    --------
    >>> scene = Scene("pendulum")
    >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
    >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    >>> scene.validate()
    """

    name: str
    gravity: Vector2 = (0.0, -9.81)
    elements: list[Element] = field(default_factory=list)
    ground: Ground = field(default_factory=Ground)

    def add(self, element: Element) -> Any:
        """Add an element and return it (so ``crank = scene.add(Body(...))`` reads well)."""
        if not isinstance(element, Element):
            raise SceneError(
                f"scene '{self.name}': cannot add {element!r}; expected a Body, joint, Driver or load (daeclear.loads)."
            )
        self.elements.append(element)
        return element

    def __iter__(self) -> Iterator[Element]:
        return iter(self.elements)

    @property
    def bodies(self) -> list[Body]:
        return [e for e in self.elements if isinstance(e, Body)]

    @property
    def joints(self) -> list[Joint]:
        return [e for e in self.elements if isinstance(e, Joint)]

    @property
    def drivers(self) -> list[Driver]:
        return [e for e in self.elements if isinstance(e, Driver)]

    def with_clearance(self, joint: str, *, bearing: str | None = None, name: str | None = None,
                       **fields_: Any) -> "Scene":
        """A new scene in which the ideal revolute or translational ``joint`` has a clearance.

        The joint's bodies, point and axis are kept; ``fields_`` are the clearance joint's own
        fields (``clearance``, ``bearing_radius``, ``material``, ``law``, ``friction``, ...;
        ``length``, ``width``, ``corner_radius`` for a translational joint). ``bearing`` names
        the body holding a revolute joint's bearing (default body_i); ``name`` renames the
        joint. This scene is left unchanged (it stays the ideal reference). See
        :func:`clearance_joint`.

        >>> scene = Scene("pendulum")
        >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
        >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
        >>> from daeclear.contact import Material
        >>> steel = Material(young=207e9, poisson=0.3)
        >>> loose = scene.with_clearance("A", clearance=0.1e-3, bearing_radius=0.01, material=steel)
        >>> loose["A"].kind, scene["A"].kind
        ('RevoluteClearance', 'Revolute')
        """
        return with_clearance(self, joint, bearing=bearing, name=name, **fields_)

    def ideal(self) -> "Scene":
        """A new scene, the same mechanism with every clearance joint ideal (see :func:`ideal_joint`):
        the reference a clearance run is compared with. This scene is left unchanged."""
        elements = [ideal_joint(e) if isinstance(e, (RevoluteClearance, TranslationalClearance)) else e
                    for e in self.elements]
        return Scene(self.name, gravity=self.gravity, elements=elements, ground=self.ground)

    def without(self, *names: str) -> "Scene":
        """A new scene without the named elements (e.g. the Driver of a crank that a Motor will
        drive instead). Every name must exist; this scene is left unchanged.

        >>> scene = Scene("pendulum")
        >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
        >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
        >>> [e.name for e in scene.without("A")], [e.name for e in scene]
        (['link'], ['link', 'A'])
        """
        for name in names:
            self[name]  # KeyError naming the scene and the closest names
        elements = [e for e in self.elements if e.name not in names]
        return Scene(self.name, gravity=self.gravity, elements=elements, ground=self.ground)

    def of_type(self, cls: type) -> list[Any]:
        return [e for e in self.elements if isinstance(e, cls)]

    def __getitem__(self, name: str) -> Element:
        for element in self.elements:
            if element.name == name:
                return element
        names = [e.name for e in self.elements]
        close = difflib.get_close_matches(name, names, n=3)
        hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
        raise KeyError(f"no element '{name}' in scene '{self.name}'.{hint}")

    def problems(self) -> list[str]:
        """Every problem of the scene (empty when valid)."""
        out: list[str] = []
        if _as_vector2(self.gravity) is None:
            out.append(f"scene '{self.name}': gravity={self.gravity!r} m/s^2, must be two finite numbers.")
        seen: set[str] = set()
        for element in self.elements:
            out.extend(element.problems())
            if element.name in seen:
                out.append(f"{element.kind} '{element.name}': duplicate name; every name in a scene must be unique.")
            seen.add(element.name)
        body_names = [b.name for b in self.bodies]
        known = set(body_names) | {GROUND}
        referring = [(j, (("body_i", j.body_i), ("body_j", j.body_j))) for j in self.joints]
        referring += [(e, e.body_roles()) for e in self.elements if hasattr(e, "body_roles")]  # loads
        for joint, roles in referring:
            for role, body in roles:
                if body not in known:
                    close = difflib.get_close_matches(str(body), sorted(known), n=1)
                    hint = f" Did you mean '{close[0]}'?" if close else ""
                    out.append(
                        f"{joint.kind} '{joint.name}': {role} refers to body '{body}', "
                        f"not in scene '{self.name}'.{hint}"
                    )
        joints = {j.name: j for j in self.joints}
        driven: set[str] = set()
        for driver in self.drivers:
            coordinate = driven_coordinate(joints.get(driver.joint))
            if coordinate is None:
                drivable = sorted(name for name, j in joints.items() if driven_coordinate(j))
                out.append(f"Driver '{driver.name}': joint={driver.joint!r} is not a revolute or translational "
                           f"joint of this scene (drivable joints: {', '.join(drivable) or 'none'}).")
            elif driver.initial_angle is not None and coordinate == "translation":
                out.append(f"Driver '{driver.name}': initial_angle={driver.initial_angle!r} rad on translational "
                           f"joint '{driver.joint}'; give initial_position (m) instead.")
            elif driver.initial_position is not None and coordinate == "rotation":
                out.append(f"Driver '{driver.name}': initial_position={driver.initial_position!r} m on revolute "
                           f"joint '{driver.joint}'; give initial_angle (rad) instead.")
            if coordinate is not None and driver.joint in driven:
                out.append(f"Driver '{driver.name}': joint '{driver.joint}' already has a driver.")
            driven.add(driver.joint)
        if not self.bodies:
            out.append(f"scene '{self.name}': has no moving body; add a Body.")
        return out

    def validate(self) -> None:
        """Raise one :class:`SceneError` listing every problem of the scene."""
        problems = self.problems()
        if len(problems) == 1:
            raise SceneError(problems[0])
        if problems:
            lines = "\n".join(f"  - {p}" for p in problems)
            raise SceneError(f"scene '{self.name}' has {len(problems)} problems:\n{lines}")

    def to_dict(self) -> dict[str, Any]:
        """Plain-data description of the scene (for result files)."""
        return {
            "name": self.name,
            "gravity": list(self.gravity),
            "elements": {e.name: e.to_dict() for e in self.elements},
        }


def _default_law() -> Any:
    from ..contact import LankaraniNikravesh

    return LankaraniNikravesh(restitution=0.9)


def _law_problems(element: "RevoluteClearance") -> list[str]:
    """Resolve the joint's contact and friction laws once, reporting what is wrong."""
    from ..contact import friction_law, normal_law
    from ..contact.base import NormalLaw

    out: list[str] = []
    law = element.law
    try:
        if isinstance(law, str):
            law = normal_law(law)
        if not isinstance(law, NormalLaw):
            out.append(f"{element.kind} '{element.name}': law={law!r}, must be a daeclear.contact law or a law name.")
        else:
            element.resolved_law()
    except (SceneError, TypeError) as exc:
        out.append(f"{element.kind} '{element.name}': {exc}")
    try:
        friction_law(element.friction)
    except (SceneError, TypeError) as exc:
        out.append(f"{element.kind} '{element.name}': friction: {exc}")
    return out


@dataclass(frozen=True)
class RevoluteClearance(_PointJoint):
    """Revolute joint with radial clearance: a journal (body j) inside a bearing (body i).

    The joint adds no constraint; the journal moves freely inside the bearing and a
    contact-impact force acts when the eccentricity exceeds the clearance (section 4.2,
    eqs. 4.1-4.13). ``at`` is the common centre of bearing and journal in the reference
    configuration (or give ``point_i``/``point_j`` in body coordinates).

    Parameters
    ----------
    name : str
        Unique name; channels ``<name>.ex``, ``<name>.penetration``, ... and events use it.
    body_i, body_j : str or Body
        Bearing body and journal body.
    bearing_radius : float
        Bearing radius R_i, m.
    clearance : float or None
        Radial clearance c = R_i - R_j, m (give this or ``journal_radius``).
    journal_radius : float or None
        Journal radius R_j, m.
    material : Material or (Material, Material) or None
        Materials of bearing and journal (one for both); needed when the law's stiffness
        is computed (``stiffness=None``).
    law : NormalLaw or str
        Normal contact law (default Lankarani-Nikravesh with c_e = 0.9, eq. 3.9).
    friction : None, float, str or FrictionLaw
        None: frictionless; a float: modified Coulomb (3.16) with that coefficient.
    """

    bearing_radius: float = 0.0
    clearance: float | None = None
    journal_radius: float | None = None
    material: Any = None
    law: Any = field(default_factory=lambda: _default_law())
    friction: Any = None

    @property
    def radial_clearance(self) -> float:
        if self.clearance is not None:
            return float(self.clearance)
        return float(self.bearing_radius) - float(self.journal_radius or 0.0)

    @property
    def journal(self) -> float:
        return float(self.bearing_radius) - self.radial_clearance

    def resolved_law(self) -> Any:
        """The normal law with its stiffness (or cylinder geometry) set from radii and materials."""
        from ..contact import normal_law

        law = normal_law(self.law) if isinstance(self.law, str) else self.law
        if law.is_resolved:
            return law
        return law.resolve("internal_cylinder", radii=(float(self.bearing_radius), self.journal),
                           materials=self.material)

    def resolved_friction(self) -> Any:
        from ..contact import friction_law

        return friction_law(self.friction)

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_positive(out, "bearing_radius", "m")
        self._check_one_positive(out, "clearance", "journal_radius", "m")
        if not out:
            c, R = self.radial_clearance, float(self.bearing_radius)
            if not 0.0 < c < R:
                out.append(f"{self.kind} '{self.name}': journal radius {self.journal!r} m must be in "
                           f"(0, bearing_radius={R!r} m): clearance {c!r} m, must be in (0, {R!r}).")
            else:
                out.extend(_law_problems(self))
        return out


def _default_face_law() -> Any:
    from ..contact import LankaraniPlane

    return LankaraniPlane()


#: Contact models of :class:`TranslationalClearance` (see its docstring).
SLIDER_MODELS: tuple[str, ...] = ("corners", "section-4.3")


@dataclass(frozen=True)
class TranslationalClearance(_PointJoint):
    """Translational joint with clearance: a rectangular slider (body j) free inside a guide (body i).

    The joint adds no constraint; each slider corner that reaches a guide surface is
    pushed back by a contact-impact force (section 4.3, eqs. 4.14-4.27). The guide is two
    parallel surfaces a distance ``H`` apart, symmetric about the guide's *mid-line*; the
    slider is an ``L x W`` rectangle (``thickness`` out of plane) with rounded corners.

    Geometry and names. ``at`` is, in the reference configuration (bodies at their
    declared positions and angles), both a point of the guide's mid-line and the slider's
    centre, the slider parallel to the guide; or give ``point_i`` (a mid-line point, guide
    coordinates) and ``point_j`` (the slider centre, slider coordinates). ``axis`` is the
    guide direction (world, reference configuration), fixed to the guide, and the slider's
    length direction in the reference configuration. Coordinates along the guide, ``s``,
    are measured from the mid-line point along ``axis``; "upper" is the surface on the
    left of ``axis`` (+90 degrees). Corners, counter-clockwise from the front upper one
    (front = +axis): ``A`` (+L/2, +W/2), ``B`` (-L/2, +W/2), ``C`` (-L/2, -W/2),
    ``D`` (+L/2, -W/2). Contact pairs are named ``<name>.A_upper``, ``<name>.B_upper``,
    ``<name>.C_lower``, ``<name>.D_lower``; faces ``<name>.upper_face`` (A, B) and
    ``<name>.lower_face`` (C, D). The chapter calls the slider body i and the guide
    body j; here, as for :class:`Translational` and :class:`RevoluteClearance`, the
    outer part is body i.

    Parameters
    ----------
    name : str
        Unique name; channels and events use it.
    body_i, body_j : str or Body
        Guide body and slider body.
    axis : (float, float)
        Guide direction, world frame, reference configuration (need not be unit).
    slider_axis : (float, float) or None
        The slider's length direction in slider body coordinates; None: ``axis`` in the
        reference configuration (the slider starts parallel to the guide). Give it to
        start tilted: e.g. ``(1, 0)`` with the slider body at ``angle=tilt``.
    length, width : float
        Slider length L (along the guide) and width W (across), m.
    corner_radius : float
        Corner radius R_c, m, in (0, min(L, W)/2): the stiffness of a corner contact
        (sphere on a plane, eq. 3.5). The penetration is measured at the sharp corner
        of the L x W rectangle, as in eqs. (4.16)-(4.20).
    clearance : float or None
        c = (H - W)/2, m (give this or ``guide_height``).
    guide_height : float or None
        Distance H between the guide surfaces, m.
    thickness : float or None
        Slider thickness (out of plane), m; None means ``length``. A face in contact
        is ``length x thickness``; eq. (4.27) takes the half side of the square of the
        same area, ``a = sqrt(length * thickness) / 2`` (25 mm for Table 4.3).
    upper_limits, lower_limits : (float, float) or None
        Segment limits (P, Q) of the upper and (R, S) of the lower surface, as ``s``
        coordinates, m: a corner can touch a surface only while its projection lies
        between them. None: unbounded.
    stroke : (float, float) or None
        ``s`` coordinates of the slider centre mapped to xi = 0 and xi = 1 in the
        dimensionless path (channel ``<name>.xi``); None: ``upper_limits`` if given,
        else no ``xi`` channel.
    material : Material or (Material, Material) or None
        Materials of guide and slider; needed when a stiffness is computed.
    law : NormalLaw or str
        Corner law (sphere of radius R_c on a plane), default Lankarani-Nikravesh with
        c_e = 0.9 (eq. 3.9), stiffness from (3.5) when not given.
    face_law : NormalLaw or str
        Law of a face in contact in the ``section-4.3`` model, on the average
        penetration of its two corners; default Lankarani's linear law (4.26) with the
        stiffness (4.27). A Hertz-type law given here is resolved with n = 1 (the
        "unified" damped model). Unused by the ``corners`` model.
    friction : None, float, str or FrictionLaw
        None: frictionless; a float: modified Coulomb (3.16) with that coefficient, at
        every active contact.
    model : {"corners", "section-4.3"}
        ``"corners"``: every touching corner is a sphere on a plane, whatever the
        scenario of Fig. 4.9. ``"section-4.3"``: two adjacent corners on the same surface
        (a face) use ``face_law`` at the geometric centre of the penetrated area; one
        corner or two opposite corners use ``law``.
    reading : str or None
        A named reading of the chapter's model (:data:`daeclear.model.readings.JOINT_READINGS`:
        ``corners``, ``pseudo-corners``, ``pseudo-corners-linear``, ``section-4.3``,
        ``unified``, ``unified-hertz``): it sets the model, the corner law's stiffness
        ((3.5) or (4.27)) and exponent, and the face law, keeping the restitution of
        ``law``. None: ``model``, ``law`` and ``face_law`` as given.

    Notes
    -----
    The slider must not be able to turn over in the guide (``sqrt(L^2 + W^2) > H``):
    then the upper corners can only ever touch the upper surface and the lower corners
    the lower one, and these four pairs are all the contacts there are.

    The ``section-4.3`` model switches between two laws of very different stiffness: when
    a face forms under a corner that is already deep (a tilted slider), the stored elastic
    energy jumps up (channel ``<name>.elastic_energy``; docs/validation.md, section 4.5). It
    is the chapter's model for a slider that lands flat (frictionless, pin at the slider's
    centre, Fig. 4.35b); for tilting sliders (friction) use ``corners``.

    Example
    -------
    >>> import daeclear as dc
    >>> scene = dc.Scene("guide", gravity=(0.0, -9.81))
    >>> slider = scene.add(dc.Body("slider", mass=0.14, inertia=1e-4))
    >>> joint = scene.add(dc.TranslationalClearance(
    ...     "g", scene.ground, slider, at=(0.0, 0.0), length=0.05, width=0.05, corner_radius=1e-3,
    ...     clearance=0.5e-3, material=dc.Material(young=207e9, poisson=0.3)))
    >>> scene.validate()
    >>> round(joint.resolved_law().stiffness / 1e9, 2)  # sphere of R_c on a plane, eq. (3.5)
    4.8
    """

    axis: Vector2 = (1.0, 0.0)
    slider_axis: Vector2 | None = None
    length: float = 0.0
    width: float = 0.0
    corner_radius: float = 0.0
    clearance: float | None = None
    guide_height: float | None = None
    thickness: float | None = None
    upper_limits: Vector2 | None = None
    lower_limits: Vector2 | None = None
    stroke: Vector2 | None = None
    material: Any = None
    law: Any = field(default_factory=lambda: _default_law())
    face_law: Any = field(default_factory=lambda: _default_face_law())
    friction: Any = None
    model: str = "corners"
    reading: str | None = None
    # the structure flags state the contact model in use and the laws' structure (a reading that
    # only changes numbers compiles nothing)
    NOT_STRUCTURE: ClassVar[frozenset[str]] = frozenset({"model", "reading"})

    def __post_init__(self) -> None:
        super().__post_init__()
        for name in ("axis", "slider_axis", "upper_limits", "lower_limits", "stroke"):
            value = getattr(self, name)
            vec = _as_vector2(value) if value is not None else None
            if vec is not None:
                object.__setattr__(self, name, vec)
        for name in ("model", "reading"):
            if isinstance(getattr(self, name), str):
                object.__setattr__(self, name, getattr(self, name).strip().lower())

    @property
    def contact_model(self) -> str:
        """The contact model in use: the reading's, else ``model``."""
        from .joint_readings import joint_reading

        return self.model if self.reading is None else joint_reading(self.reading).model

    # ---- derived geometry ----------------------------------------------------------
    @property
    def radial_clearance(self) -> float:
        """c = (H - W) / 2, m."""
        if self.clearance is not None:
            return float(self.clearance)
        return 0.5 * (float(self.guide_height or 0.0) - float(self.width))

    @property
    def height(self) -> float:
        """Distance between the guide surfaces H = W + 2c, m."""
        return float(self.width) + 2.0 * self.radial_clearance

    @property
    def face_half_width(self) -> float:
        """Half side a of the square with the area of a slider face, m (eq. 4.27)."""
        thickness = float(self.length if self.thickness is None else self.thickness)
        return 0.5 * math.sqrt(float(self.length) * thickness)

    def resolved_law(self) -> Any:
        """The corner law with its stiffness set (kind ``"sphere_plane"``, radius R_c)."""
        from ..contact import normal_law

        law = normal_law(self.law) if isinstance(self.law, str) else self.law
        if self.reading is not None:
            from . import joint_readings as readings

            return readings.corner_law(readings.joint_reading(self.reading), law, owner=f"{self.kind} '{self.name}'",
                                       corner_radius=self.corner_radius, face_half_width=self.face_half_width,
                                       materials=self.material)
        if law.is_resolved:
            return law
        return law.resolve("sphere_plane", radii=(float(self.corner_radius),), materials=self.material)

    def resolved_face_law(self) -> Any:
        """The face law with its stiffness set (kind ``"plane_face"``, half side a); with a reading
        its face law (None for a reading of the ``corners`` model)."""
        from ..contact import normal_law

        if self.reading is not None:
            from . import joint_readings as readings

            return readings.face_law(readings.joint_reading(self.reading),
                                     normal_law(self.law) if isinstance(self.law, str) else self.law,
                                     owner=f"{self.kind} '{self.name}'", face_half_width=self.face_half_width,
                                     materials=self.material)
        law = normal_law(self.face_law) if isinstance(self.face_law, str) else self.face_law
        return law.resolve("plane_face", face_half_width=self.face_half_width, materials=self.material)

    def resolved_friction(self) -> Any:
        from ..contact import friction_law

        return friction_law(self.friction)

    def problems(self) -> list[str]:
        out = super().problems()
        for name in ("axis", "slider_axis"):
            value = getattr(self, name)
            vec = _as_vector2(value) if value is not None or name == "axis" else (1.0, 0.0)
            if vec is None or math.hypot(*vec) < 1e-12:
                out.append(f"{self.kind} '{self.name}': {name}={value!r}, must be a non-zero 2-vector.")
        for name in ("length", "width", "corner_radius"):
            self._check_positive(out, name, "m")
        if self.thickness is not None:
            self._check_positive(out, "thickness", "m")
        self._check_one_positive(out, "clearance", "guide_height", "m")
        for name in ("upper_limits", "lower_limits", "stroke"):
            value = getattr(self, name)
            if value is None:
                continue
            pair = _as_vector2(value)
            if pair is None or not pair[0] < pair[1]:
                out.append(f"{self.kind} '{self.name}': {name}={value!r} m, must be two finite numbers "
                           "(start, end) with start < end.")
        if self.model not in SLIDER_MODELS:
            out.append(f"{self.kind} '{self.name}': model={self.model!r}, must be one of "
                       f"{', '.join(map(repr, SLIDER_MODELS))}.")
        out.extend(_reading_problems(self))
        if out:
            return out
        L, W, R_c, c = float(self.length), float(self.width), float(self.corner_radius), self.radial_clearance
        if c <= 0:
            out.append(f"{self.kind} '{self.name}': guide_height={self.guide_height!r} m must exceed the slider "
                       f"width {W!r} m: clearance (H - W)/2 = {c!r} m, must be > 0.")
        elif math.hypot(L, W) <= self.height:
            out.append(f"{self.kind} '{self.name}': the slider ({L!r} x {W!r} m, diagonal {math.hypot(L, W):.6g} m) "
                       f"can turn over in a guide {self.height:.6g} m high; the diagonal must exceed the guide "
                       "height (reduce the clearance or lengthen the slider).")
        if R_c >= 0.5 * min(L, W):
            out.append(f"{self.kind} '{self.name}': corner_radius={R_c!r} m, must be < min(length, width)/2 "
                       f"= {0.5 * min(L, W)!r} m.")
        out.extend(_law_problems(self))
        if self.model == "section-4.3" and self.reading is None:
            out.extend(_face_law_problems(self))
        return out


def _reading_problems(element: TranslationalClearance) -> list[str]:
    """A reading must be known, and ``model`` and ``face_law`` left to it."""
    from .joint_readings import joint_reading

    if element.reading is None:
        return []
    where = f"{element.kind} '{element.name}'"
    try:
        reading = joint_reading(element.reading)
    except SceneError as exc:
        return [f"{where}: {exc}"]
    out = []
    if element.model not in ("corners", reading.model):
        out.append(f"{where}: model={element.model!r} with reading={reading.name!r}, whose model is "
                   f"{reading.model!r}; give one of them.")
    if element.face_law != _default_face_law():
        out.append(f"{where}: face_law={element.face_law!r} with reading={reading.name!r}, which sets the face "
                   "law; leave face_law at its default.")
    return out


def _face_law_problems(element: TranslationalClearance) -> list[str]:
    from ..contact import normal_law
    from ..contact.base import NormalLaw

    law = element.face_law
    try:
        if isinstance(law, str):
            law = normal_law(law)
        if not isinstance(law, NormalLaw):
            return [f"{element.kind} '{element.name}': face_law={law!r}, must be a daeclear.contact law or a "
                    "law name."]
        element.resolved_face_law()
    except (SceneError, TypeError) as exc:
        return [f"{element.kind} '{element.name}': face_law: {exc}"]
    return []


# ---- clearance as a property of a joint ------------------------------------------------

#: The clearance joint each ideal joint becomes, and the fields it needs besides the shared ones.
_CLEARANCE_OF: dict[type, tuple[type, tuple[tuple[str, ...], ...]]] = {
    Revolute: (RevoluteClearance, (("bearing_radius",), ("clearance", "journal_radius"))),
    Translational: (TranslationalClearance, (("length",), ("width",), ("corner_radius",),
                                             ("clearance", "guide_height"))),
}


def clearance_joint(joint: Joint, *, bearing: str | None = None, name: str | None = None,
                    **fields_: Any) -> Joint:
    """The clearance joint that replaces the ideal ``joint``: same bodies, point and axis.

    Perfect and clearance joints share their kinematic data (Ambrósio and Pombo, "A unified
    formulation for mechanical joints with and without clearances/bushings and/or stops",
    Multibody Syst. Dyn. 42, 2018): a :class:`Revolute` becomes a :class:`RevoluteClearance`
    whose bearing and journal centres are the joint's point (``at`` or ``point_i``/``point_j``);
    a :class:`Translational` becomes a :class:`TranslationalClearance` whose guide is body i,
    slider body j, with the joint's ``axis`` as the guide direction and the joint's point as
    both the mid-line point and the slider centre. ``fields_`` are the clearance fields only
    (clearance, geometry, material, law, friction, ...), never the shared ones.

    Parameters
    ----------
    joint : Revolute or Translational
        The ideal joint.
    bearing : str or None
        Revolute only: the body that holds the bearing (body_i or body_j of the joint); None
        keeps body i, the other body carries the journal.
    name : str or None
        Name of the clearance joint (its channels are ``<name>.ex``, ...); None keeps the joint's.
    **fields_
        Fields of the clearance joint, e.g. ``clearance=0.5e-3, bearing_radius=10e-3,
        material=Material(...), law="lankarani-nikravesh", friction=0.05``.

    Raises
    ------
    SceneError
        A joint that is not an ideal revolute or translational one (e.g. already a clearance
        joint), an unknown or shared field, a missing one, or an invalid value.
    """
    label = f"clearance on joint '{getattr(joint, 'name', joint)}'"
    if isinstance(joint, (RevoluteClearance, TranslationalClearance)):
        raise SceneError(f"{label}: it is already a {joint.kind}; change its fields with "
                         "dataclasses.replace, or start from the ideal joint.")
    if type(joint) not in _CLEARANCE_OF:
        kind = getattr(joint, "kind", type(joint).__name__)
        raise SceneError(f"{label}: it is a {kind}; only an ideal Revolute or Translational joint can get a "
                         "clearance.")
    cls, required = _CLEARANCE_OF[type(joint)]
    shared = {f.name for f in fields(type(joint))}
    allowed = [f.name for f in fields(cls) if f.name not in shared]
    unknown = sorted(set(fields_) - set(allowed))
    if unknown:
        hints = [f"{key} (shared with the ideal joint)" if key in shared else key for key in unknown]
        raise SceneError(f"{label}: unknown field(s) {', '.join(hints)} for a {cls.__name__}; "
                         f"allowed: {', '.join(allowed)}.")
    missing = [" or ".join(group) for group in required if all(fields_.get(k) is None for k in group)]
    if missing:
        raise SceneError(f"{label}: missing {', '.join(missing)} (m), needed by a {cls.__name__}.")
    shared_values = {f.name: getattr(joint, f.name) for f in fields(type(joint))}
    if bearing is not None:
        if cls is not RevoluteClearance:
            raise SceneError(f"{label}: bearing={bearing!r} applies to a revolute joint only; a translational "
                             "joint's guide is its body_i.")
        if bearing not in joint.bodies:
            raise SceneError(f"{label}: bearing={bearing!r}, must be one of the joint's bodies "
                             f"{joint.body_i!r} or {joint.body_j!r}.")
        if bearing == joint.body_j:  # the journal on body i: the two bodies and their points change roles
            shared_values.update(body_i=joint.body_j, body_j=joint.body_i, point_i=joint.point_j,
                                 point_j=joint.point_i)
    if name is not None:
        shared_values["name"] = name
    element = cls(**shared_values, **fields_)
    problems = element.problems()
    if problems:
        raise SceneError(f"{label}: " + " ".join(problems))
    return element


def ideal_joint(joint: Joint) -> Joint:
    """The ideal joint a clearance joint stands for: same name, bodies, point and axis (the inverse of
    :func:`clearance_joint` up to the clearance fields)."""
    shared = {"name": joint.name, "body_i": joint.body_i, "body_j": joint.body_j,
              "at": getattr(joint, "at", None), "point_i": getattr(joint, "point_i", None),
              "point_j": getattr(joint, "point_j", None)}
    if isinstance(joint, RevoluteClearance):
        return Revolute(**shared)
    if isinstance(joint, TranslationalClearance):
        return Translational(**shared, axis=joint.axis)
    raise SceneError(f"ideal joint of '{getattr(joint, 'name', joint)}': it is a "
                     f"{getattr(joint, 'kind', type(joint).__name__)}, not a clearance joint.")


def with_clearance(scene: Scene, joint: str, *, bearing: str | None = None, name: str | None = None,
                   **fields_: Any) -> Scene:
    """A new scene in which the ideal joint named ``joint`` is a clearance joint (see :func:`clearance_joint`).

    The scene itself is left unchanged: one ideal mechanism serves as the reference of its
    clearance variants (the chapter plots every clearance run against the ideal one) and a
    sweep builds many variants from one scene. Elements are frozen, so the new scene shares
    them; the clearance joint takes the ideal joint's place in the element order.
    """
    names = [e.name for e in scene.elements]
    if joint not in names:
        close = difflib.get_close_matches(str(joint), names, n=3)
        hint = f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""
        joints = ", ".join(repr(j.name) for j in scene.joints)
        raise SceneError(f"scene '{scene.name}': with_clearance: no joint named {joint!r} (joints: {joints}).{hint}")
    index = names.index(joint)
    element = clearance_joint(scene.elements[index], bearing=bearing, name=name, **fields_)  # type: ignore[arg-type]
    elements = list(scene.elements)
    elements[index] = element
    return Scene(scene.name, gravity=scene.gravity, elements=elements, ground=scene.ground)


def driven_coordinate(joint: Any) -> str | None:
    """What a :class:`Driver` prescribes on ``joint``: "rotation" (revolute joints, with or without
    clearance), "translation" (translational joints, with or without clearance) or None (not drivable)."""
    if isinstance(joint, (Revolute, RevoluteClearance)):
        return "rotation"
    if isinstance(joint, (Translational, TranslationalClearance)):
        return "translation"
    return None
