"""Applied loads: point forces, torques, spring-dampers and motors acting on the bodies of a scene.

A load adds no state and no constraint, only a term of the applied generalized force ``Q(t, q, v)``
(the loads, their values and channels: docs/user_guide.md, section 1.1). A point of application is a
world point ``at`` of the reference configuration or a body-fixed ``point``, one of the two.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .elements import GROUND, Element, Vector2, as_vector2, body_name, is_finite_number, store_vectors
# the values of a load and their math, re-exported: ``from daeclear.model.loads import exp`` keeps working
from .load_values import (Expression, LoadState, Table, Value, atan2, cos, exp, fabs, fmax, fmin,  # noqa: F401
                          if_else, interpolate, log, sign, sin, sqrt, tanh)

__all__ = [
    "Expression", "Force", "Load", "LoadState", "Motor", "RotationalSpringDamper", "SpringDamper", "Table",
    "Torque", "atan2", "cos", "exp", "fabs", "fmax", "fmin", "if_else", "log", "sign", "sin", "sqrt", "tanh",
]


def _value_problems(element: Element, field_name: str, unit: str) -> list[str]:
    value = getattr(element, field_name)
    where = f"{element.kind} '{element.name}': {field_name}="
    if isinstance(value, (Table, Expression)):
        return value.problems(where)
    if not is_finite_number(value):
        return [f"{where}{value!r} {unit}, must be a finite number, a daeclear.Table or a daeclear.Expression."]
    return []


def _value_parameters(field_name: str, value: Any) -> dict[str, Any]:
    """A value's numbers: ``<field>`` (a number), ``<field>.times``/``.values`` or ``<field>.<name>``."""
    if isinstance(value, Table):
        return {f"{field_name}.times": value.times, f"{field_name}.values": value.values}
    if isinstance(value, Expression):
        return {f"{field_name}.{k}": v for k, v in value.parameters}
    return {field_name: float(value)}


class Load(Element):
    """Base class of the load elements: bodies they act on, for the scene's reference checks."""

    def body_roles(self) -> tuple[tuple[str, str], ...]:
        """(field, body name) of every body the load refers to."""
        raise NotImplementedError

    def _check_distinct(self, out: list[str], first: str, second: str) -> None:
        a, b = getattr(self, first), getattr(self, second)
        if a == b:
            out.append(f"{self.kind} '{self.name}': {first} and {second} are both '{a}'; give two different bodies.")

    def _check_moving(self, out: list[str], field_name: str) -> None:
        if getattr(self, field_name) == GROUND:
            out.append(f"{self.kind} '{self.name}': {field_name}='{GROUND}', must be a moving body "
                       "(a load on the fixed ground does nothing).")

    def _check_nonnegative(self, out: list[str], field_name: str, unit: str, optional: bool = False) -> None:
        value = getattr(self, field_name)
        if (not is_finite_number(value) or value < 0) and not (optional and value is None):
            out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be a finite number >= 0.")


class BetweenBodies(Load):
    """A load between two bodies ``body_i`` and ``body_j`` (names, or the Body objects)."""

    body_i: str
    body_j: str

    def __post_init__(self) -> None:
        for name in ("body_i", "body_j"):
            object.__setattr__(self, name, body_name(getattr(self, name)))

    def body_roles(self) -> tuple[tuple[str, str], ...]:
        return (("body_i", self.body_i), ("body_j", self.body_j))

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_distinct(out, "body_i", "body_j")
        return out


#: Frames of a :class:`Force`'s components.
FORCE_FRAMES: tuple[str, ...] = ("world", "body")


@dataclass(frozen=True)
class Force(Load):
    """A point force on ``body`` at the world point ``at`` of the reference configuration or at the
    body-fixed ``point`` (the centre of mass when neither is given); the point moves with the body.

    Parameters
    ----------
    name : str
        Unique name; channels ``<name>.fx``, ``<name>.fy`` (world, N) and ``<name>.power`` (W).
    body : str or Body
        The loaded body (not the ground).
    fx, fy : float, Table or Expression
        Components, N, in the world frame or (``frame="body"``, a follower force) the body's.
    at : (float, float) or None
        World point of application in the reference (declared) configuration, m.
    frame : {"world", "body"}
    point : (float, float) or None
        Point of application in the body's frame, m (instead of ``at``).
    """

    name: str
    body: str
    fx: Value = 0.0
    fy: Value = 0.0
    at: Vector2 | None = None
    frame: str = "world"
    point: Vector2 | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", body_name(self.body))
        store_vectors(self, ("at", "point"))

    def body_roles(self) -> tuple[tuple[str, str], ...]:
        return (("body", self.body),)

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_moving(out, "body")
        self._check_vector(out, "at", "m", optional=True)
        self._check_vector(out, "point", "m", optional=True)
        self._check_not_both(out, "at", ("point",))
        if self.frame not in FORCE_FRAMES:
            out.append(f"{self.kind} '{self.name}': frame={self.frame!r}, must be one of "
                       f"{', '.join(map(repr, FORCE_FRAMES))}.")
        out += _value_problems(self, "fx", "N") + _value_problems(self, "fy", "N")
        return out


@dataclass(frozen=True)
class Torque(Load):
    """A torque ``value`` on ``body`` (counter-clockwise positive), the opposite on ``reaction`` if given
    (an Expression's ``angle`` and ``speed`` are then relative to it). Channels ``<name>.torque``
    (N m) and ``<name>.power`` (W).
    """

    name: str
    body: str
    value: Value = 0.0
    reaction: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "body", body_name(self.body))
        if self.reaction is not None:
            object.__setattr__(self, "reaction", body_name(self.reaction))

    def body_roles(self) -> tuple[tuple[str, str], ...]:
        return (("body", self.body),) + ((("reaction", self.reaction),) if self.reaction is not None else ())

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_moving(out, "body")
        if self.reaction is not None:
            self._check_distinct(out, "body", "reaction")
        return out + _value_problems(self, "value", "N m")


@dataclass(frozen=True)
class SpringDamper(BetweenBodies):
    """A linear spring-damper between a point of ``body_i`` and a point of ``body_j``, each a world
    point of the declared configuration (``at_i``, ``at_j``) or body-fixed (``point_i``, ``point_j``).

    Tension ``F = stiffness * (L - free_length) + damping * dL/dt`` along the line of the points
    (positive pulls them together); ``free_length`` None: the points' declared distance. Channels
    ``<name>.length``, ``<name>.elongation`` (m), ``<name>.force`` (N), ``<name>.elastic_energy`` (J),
    ``<name>.power`` (the damper's, W, <= 0). The points must not coincide during a run.
    """

    name: str
    body_i: str
    body_j: str
    at_i: Vector2 | None = None
    at_j: Vector2 | None = None
    stiffness: float = 0.0
    damping: float = 0.0
    free_length: float | None = None
    point_i: Vector2 | None = None
    point_j: Vector2 | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        store_vectors(self, ("at_i", "at_j", "point_i", "point_j"))

    def problems(self) -> list[str]:
        out = super().problems()
        for end in ("i", "j"):
            world, local = f"at_{end}", f"point_{end}"
            self._check_vector(out, world, "m", optional=True)
            self._check_vector(out, local, "m", optional=True)
            self._check_not_both(out, world, (local,))
            if getattr(self, world) is None and getattr(self, local) is None:
                out.append(f"{self.kind} '{self.name}': {world}=None and {local}=None, must give one: the world "
                           f"point {world} (declared configuration) or the body-fixed {local} (body coordinates).")
        self._check_nonnegative(out, "stiffness", "N/m")
        self._check_nonnegative(out, "damping", "N s/m")
        self._check_nonnegative(out, "free_length", "m", optional=True)
        a, b = as_vector2(self.at_i), as_vector2(self.at_j)
        if a is not None and b is not None and math.dist(a, b) < 1e-12:
            out.append(f"{self.kind} '{self.name}': at_i={self.at_i!r} and at_j={self.at_j!r} m coincide; the "
                       "spring's line is undefined: give two distinct points.")
        return out


@dataclass(frozen=True)
class RotationalSpringDamper(BetweenBodies):
    """A torsional spring-damper: torque ``-stiffness * (theta - free_angle) - damping * dtheta/dt`` on
    body j (the opposite on body i), ``theta = phi_j - phi_i``; ``free_angle`` None: the reference
    one. Channels ``<name>.deflection`` (rad), ``<name>.torque`` (N m), ``<name>.elastic_energy``
    (J), ``<name>.power`` (W, <= 0).
    """

    name: str
    body_i: str
    body_j: str
    stiffness: float = 0.0
    damping: float = 0.0
    free_angle: float | None = None

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_nonnegative(out, "stiffness", "N m/rad")
        self._check_nonnegative(out, "damping", "N m s/rad")
        self._check_number(out, "free_angle", "rad", optional=True)
        return out


@dataclass(frozen=True)
class Motor(BetweenBodies):
    """A DC motor between a stator ``body_i`` and a rotor ``body_j``: ``T = stall_torque * (1 -
    omega_rel / no_load_speed)`` on body j (-T on body i), ``omega_rel = omega_j - omega_i``; both
    constants of one sign (negative: clockwise). Channels ``<name>.torque`` (N m), ``<name>.speed``
    (rad/s), ``<name>.power`` (W).
    """

    name: str
    body_i: str
    body_j: str
    stall_torque: float = 0.0
    no_load_speed: float = 0.0

    def problems(self) -> list[str]:
        out = super().problems()
        for field_name, unit in (("stall_torque", "N m"), ("no_load_speed", "rad/s")):
            value = getattr(self, field_name)
            if not is_finite_number(value) or value == 0:
                out.append(f"{self.kind} '{self.name}': {field_name}={value!r} {unit}, must be a finite "
                           "number other than 0.")
        if not out and (self.stall_torque > 0) != (self.no_load_speed > 0):
            out.append(f"{self.kind} '{self.name}': stall_torque={self.stall_torque!r} N m and no_load_speed="
                       f"{self.no_load_speed!r} rad/s, must have the same sign (the motor's direction).")
        return out


def attachment(ref: Any, body: str, world: Vector2 | None, local: Vector2 | None) -> tuple[float, float]:
    """Body-fixed coordinates of a load's point: ``local`` when given, else the world point
    ``world`` of the reference configuration ``ref``, else the centre of mass."""
    if local is not None:
        return (float(local[0]), float(local[1]))
    if world is not None:
        s = ref.local_point(body, world)
        return (float(s[0]), float(s[1]))
    return (0.0, 0.0)


def load_parameters(ref: Any, load: Load) -> dict[str, Any]:
    """The load's numbers as run-time parameters (``ref``: the scene's reference configuration)."""
    out: dict[str, Any] = {}
    if isinstance(load, Force):
        out["point"] = attachment(ref, load.body, load.at, load.point)
        out.update(_value_parameters("fx", load.fx) | _value_parameters("fy", load.fy))
    elif isinstance(load, Torque):
        out.update(_value_parameters("value", load.value))
    elif isinstance(load, SpringDamper):
        s_i = attachment(ref, load.body_i, load.at_i, load.point_i)
        s_j = attachment(ref, load.body_j, load.at_j, load.point_j)
        free = (math.dist(ref.world_point(load.body_i, s_i), ref.world_point(load.body_j, s_j))
                if load.free_length is None else load.free_length)
        out.update(s_i=s_i, s_j=s_j, stiffness=load.stiffness, damping=load.damping, free_length=free)
    elif isinstance(load, RotationalSpringDamper):
        free = ref.angle(load.body_j) - ref.angle(load.body_i) if load.free_angle is None else load.free_angle
        out.update(stiffness=load.stiffness, damping=load.damping, free_angle=free)
    elif isinstance(load, Motor):
        out.update(stall_torque=load.stall_torque, no_load_speed=load.no_load_speed)
    else:
        raise TypeError(f"load_parameters: {load.kind} '{load.name}' is not a known load kind")
    return out
