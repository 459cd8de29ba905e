"""The elements of a scene: the :class:`Element` base and its checks, bodies, ideal joints and drivers.

Plain data (frozen dataclasses, SI units, planar 2-vectors), no CasADi; each element lists its own
problems. Every body has coordinates ``(x, y, phi)`` of its centre of mass. A joint's point is a
world point ``at`` of the reference configuration (the bodies at their declared ``position`` and
``angle``), or body-fixed ``point_i``/``point_j`` (then the declared poses are guesses that assembly
corrects). The ground is the body named ``"ground"``: fixed at the origin, angle zero.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, fields
from typing import Any, ClassVar, TypeGuard

from .profiles import PROFILES, ConstantSpeed, Profile

GROUND = "ground"

Vector2 = tuple[float, float]


def kept(element: Any, slot: str, compute: Callable[[Any], Any]) -> Any:
    """``compute(element)``, kept on a frozen dataclass element under ``slot`` (not a field: equality,
    ``to_dict`` and ``dataclasses.replace`` ignore it); computed anew on any other element."""
    if not is_frozen(element):
        return compute(element)
    try:
        return element.__dict__[slot]
    except KeyError:
        value = compute(element)
        object.__setattr__(element, slot, value)
        return value


def kept_with(element: Any, slot: str, inputs: tuple[Any, ...], compute: Callable[[Any], Any]) -> Any:
    """``compute(element)`` of a frozen element that also reads other frozen objects ``inputs`` (e.g. the
    scene's bodies): kept and reused while it is given the very same objects."""
    held = getattr(element, "__dict__", {}).get(slot)  # kept only on frozen objects (below)
    if held is not None and len(held[0]) == len(inputs) and all(a is b for a, b in zip(held[0], inputs)):
        return held[1]
    value = compute(element)
    if is_frozen(element) and all(is_frozen(x) for x in inputs):
        object.__setattr__(element, slot, (inputs, value))
    return value


def is_frozen(value: Any) -> bool:
    """True for an instance of a frozen dataclass (its fields cannot change) that can hold kept values."""
    params = getattr(type(value), "__dataclass_params__", None)
    return bool(params is not None and params.frozen and hasattr(value, "__dict__"))


def computed_once(method: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """A method of a frozen element whose result follows from its fields alone, kept (see :func:`kept`)."""
    slot = f"_computed_{method.__name__}"

    @functools.wraps(method)
    def once(self: Any) -> Any:
        return kept(self, slot, method)

    return once


def own_problems(element: Element) -> tuple[str, ...]:
    """``element.problems()``, kept on a frozen element (a sweep's scenes share their elements)."""
    return kept(element, "_own_problems", lambda e: tuple(e.problems()))


def is_finite_number(value: Any) -> TypeGuard[float]:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def as_vector2(value: Any) -> Vector2 | None:
    """Return ``value`` as a tuple of two finite floats, or None if it is not one."""
    try:
        if any(isinstance(v, bool) for v in value):  # True is not a coordinate
            return None
        items = tuple(float(v) for v in value)
    except (TypeError, ValueError):
        return None
    if len(items) != 2 or not all(math.isfinite(v) for v in items):
        return None
    return items


def store_vectors(element: Any, names: Iterable[str]) -> None:
    """Store each named field that is a 2-vector as a tuple of two floats (anything else is kept as
    given, for problems())."""
    for name in names:
        vec = as_vector2(getattr(element, name))
        if vec is not None:
            object.__setattr__(element, name, vec)


class Element:
    """Base class of every scene element: a name, and a list of own problems."""

    name: str
    #: fields the element's structure flags already state (left out of the compiled structure key)
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

    def _check_positive(self, out: list[str], field_name: str, unit: str, optional: bool = False) -> None:
        value = getattr(self, field_name)
        if (not is_finite_number(value) or value <= 0) and not (optional and value is None):
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be a finite number > 0.")

    def _check_vector(self, out: list[str], field_name: str, unit: str, optional: bool = False) -> None:
        value = getattr(self, field_name)
        if as_vector2(value) is None and not (optional and value is None):
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be two finite numbers (x, y).")

    def _check_one_positive(self, out: list[str], first: str, second: str, unit: str) -> None:
        """Exactly one of two alternative fields is given, and it is > 0."""
        a, b = getattr(self, first), getattr(self, second)
        if (a is None) == (b is None):
            out.append(f"{self.kind} '{self.name}': give exactly one of {first}= or {second}= "
                       f"(got {first}={a!r}, {second}={b!r}).")
        else:
            self._check_positive(out, first if a is not None else second, unit)

    def _check_not_both(self, out: list[str], world: str, body: tuple[str, ...]) -> None:
        """A world point and a body-fixed point are two ways to give one attachment: at most one."""
        given = [name for name in body if getattr(self, name) is not None]
        if getattr(self, world) is not None and given:
            shown = " and ".join(f"{name}={getattr(self, name)!r}" for name in (world, *given))
            out.append(f"{self.kind} '{self.name}': {shown} m given together, must be one of the two: the "
                       f"world point {world} (declared configuration) or the body-fixed {' and '.join(body)} "
                       "(body coordinates).")

    def _check_number(self, out: list[str], field_name: str, unit: str, optional: bool = False) -> None:
        value = getattr(self, field_name)
        if not is_finite_number(value) and not (optional and value is None):
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


def body_name(body: str | Body | Ground) -> str:
    """The name of a body given by name or as the element (anything else is kept, for problems())."""
    given: Any = body
    return given if isinstance(given, str) else getattr(given, "name", given)


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
        store_vectors(self, ("position", "velocity"))

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
        object.__setattr__(self, "body_i", body_name(self.body_i))
        object.__setattr__(self, "body_j", body_name(self.body_j))

    @property
    def bodies(self) -> tuple[str, str]:
        return (self.body_i, self.body_j)

    def problems(self) -> list[str]:
        out = super().problems()
        if self.body_i == self.body_j:
            out.append(f"{self.kind} '{self.name}': joins body '{self.body_i}' to itself; give two different bodies.")
        return out


@dataclass(frozen=True)
class PointJoint(Joint):
    """A joint located by a world point ``at`` or by body-fixed points ``point_i``/``point_j``."""

    at: Vector2 | None = None
    point_i: Vector2 | None = None
    point_j: Vector2 | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        store_vectors(self, ("at", "point_i", "point_j"))

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_vector(out, "at", "m", optional=True)
        self._check_vector(out, "point_i", "m", optional=True)
        self._check_vector(out, "point_j", "m", optional=True)
        local = (self.point_i is not None, self.point_j is not None)
        self._check_not_both(out, "at", ("point_i", "point_j"))
        if self.at is None and not all(local):
            out.append(f"{self.kind} '{self.name}': give the world point at=(x, y), "
                       "or both body-fixed points point_i and point_j.")
        return out


@dataclass(frozen=True)
class Revolute(PointJoint):
    """Ideal revolute (pin) joint: point P of body i coincides with point P of body j.

    Adds two constraint equations, ``r_i + A_i s_i - r_j - A_j s_j = 0``.
    """


@dataclass(frozen=True)
class Translational(PointJoint):
    """Ideal translational (prismatic) joint: body j slides on body i along ``axis`` (a world direction
    of the reference configuration, fixed to body i); the relative angle stays constant."""

    axis: Vector2 = (1.0, 0.0)

    def __post_init__(self) -> None:
        super().__post_init__()
        store_vectors(self, ("axis",))

    def problems(self) -> list[str]:
        out = super().problems()
        vec = as_vector2(self.axis)
        if vec is None or math.hypot(*vec) < 1e-12:
            out.append(f"{self.kind} '{self.name}': axis={self.axis!r}, must be a non-zero 2-vector.")
        return out


@dataclass(frozen=True)
class Driver(Element):
    """Prescribed motion of one joint coordinate (a kinematic driver constraint).

    The coordinate is a revolute joint's relative angle ``phi_j - phi_i`` or a translational joint's
    displacement of point j from point i along its axis (with or without clearance: a clearance
    joint's journal or slider stays free in its play). The driver imposes ``x(t) = x0 +
    motion(t)`` (constant speed by default; :mod:`daeclear.profiles`), ``x0`` the reference
    configuration's coordinate unless ``initial_angle`` or ``initial_position`` is given. Channels:
    ``<name>.moment`` (N m) or ``<name>.force`` (N) on body j, and ``<name>.power`` (W).

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
        self._check_number(out, "initial_angle", "rad", optional=True)
        self._check_number(out, "initial_position", "m", optional=True)
        out.extend(profile.problems(self.name))
        return out

