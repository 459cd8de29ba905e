"""Driver constraints: a joint coordinate prescribed in time (see :class:`daeclear.model.scene.Driver`).

The coordinate is the relative angle ``phi_j - phi_i`` of a revolute joint, or the displacement
``(P_j - P_i) . u`` of joint point j from joint point i along the axis ``u`` (fixed to body i) of
a translational joint. A clearance joint is driven the same way: its journal or slider stays
free in the play, only this coordinate is prescribed (the clearance joint adds no constraint of
its own). The constraint ``coordinate - x0 - motion(t) = 0`` (``coordinate - table(t)`` for a
tabulated profile) enters the equations with a multiplier ``lam``; the load the driver applies to
body j is ``-lam`` (moment, or force along ``u``).
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
    """The driver's numbers (run-time parameters): start value, speed, profile numbers (and the
    axis and points of a translational joint)."""
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
    def world(body: str, s: Any) -> np.ndarray:
        (x, y), phi = ref.pose[body]
        c, s_ = math.cos(phi), math.sin(phi)
        return np.array([x + c * s[0] - s_ * s[1], y + s_ * s[0] + c * s[1]])

    phi_i = ref.angle(joint.body_i)
    u = np.array([math.cos(phi_i) * u_local[0] - math.sin(phi_i) * u_local[1],
                  math.sin(phi_i) * u_local[0] + math.cos(phi_i) * u_local[1]])
    return float(np.dot(world(joint.body_j, s_j) - world(joint.body_i, s_i), u))


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
