"""Driver constraints: a joint coordinate (:mod:`daeclear.assembly.joint_coordinates`) prescribed in time.

The constraint ``coordinate - x0 - motion(t) = 0`` (``coordinate - table(t)`` for a tabulated
profile; a clearance joint's play stays free) has the multiplier ``lam``; the driver's load on
body j is ``-lam`` (moment, or force along the axis).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..model.profiles import motion
from ..model.scene import Driver, driven_coordinate
from .joint_coordinates import joint_coordinate
from .symbolic import AssemblyContext, Reference

#: Channel of the driver's load, by driven coordinate: (channel suffix, unit).
LOADS: dict[str, tuple[str, str]] = {"rotation": ("moment", "N m"), "translation": ("force", "N")}


def driver_load(joint: Any) -> tuple[str, str]:
    """(channel suffix, unit) of the load a driver of ``joint`` applies: moment or force."""
    return LOADS[driven_coordinate(joint)]  # type: ignore[index]


def driver_parameters(ref: Reference, driver: Driver, joint: Any) -> dict[str, Any]:
    """The driver's numbers: start value, speed, profile numbers (a translational joint's axis, points)."""
    profile = driver.motion_profile
    values: dict[str, Any] = {}
    if driven_coordinate(joint) == "translation":
        s_i, s_j = ref.joint_points(joint)
        u = ref.local_vector(joint.body_i, joint.axis)
        values.update({"s_i": s_i, "s_j": s_j, "axis": u})
        if profile.uses_speed:
            start = driver.initial_position
            values["position0"] = _reference_displacement(ref, joint, s_i, s_j, u) if start is None else start
    elif profile.uses_speed:
        start = driver.initial_angle
        values["angle0"] = ref.angle(joint.body_j) - ref.angle(joint.body_i) if start is None else start
    if profile.uses_speed:
        values["speed"] = float(driver.speed)  # type: ignore[arg-type]
    values.update({f"profile.{k}": v for k, v in profile.parameters().items()})
    return values


def _reference_displacement(ref: Reference, joint: Any, s_i: Any, s_j: Any, u_local: Any) -> float:
    """(P_j - P_i) . u in the reference configuration (0 when the joint is given by ``at``)."""
    phi_i = ref.angle(joint.body_i)
    u = np.array([math.cos(phi_i) * u_local[0] - math.sin(phi_i) * u_local[1],
                  math.sin(phi_i) * u_local[0] + math.cos(phi_i) * u_local[1]])
    return float(np.dot(np.subtract(ref.world_point(joint.body_j, s_j), ref.world_point(joint.body_i, s_i)), u))


def driver_constraint(ctx: AssemblyContext, driver: Driver, joint: Any) -> Any:
    """The driver's constraint equation Phi(q, t) (one row)."""
    name = driver.name
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    profile = driver.motion_profile
    if driven_coordinate(joint) == "translation":
        coordinate = joint_coordinate(bi, bj, "translation", ctx.p(name, "s_i"), ctx.p(name, "s_j"),
                                      ctx.p(name, "axis"))
        start = "position0"
    else:
        coordinate = joint_coordinate(bi, bj, "rotation")
        start = "angle0"
    speed = ctx.p(name, "speed") if profile.uses_speed else None
    x = motion(profile, ctx.t, speed, lambda key: ctx.p(name, f"profile.{key}"))
    return coordinate - (ctx.p(name, start) + x if profile.uses_speed else x)
