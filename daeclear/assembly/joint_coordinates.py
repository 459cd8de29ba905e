"""Joint coordinates and their rates, one definition for drivers, joint channels and placement.

Body j relative to body i, ideal and clearance joints alike: revolute ``theta = phi_j - phi_i``
(not wrapped); translational ``s = (P_j - P_i) . u``, along the axis ``u`` fixed to body i.
"""

from __future__ import annotations

from typing import Any
from collections.abc import Iterable

import casadi as ca

from ..model.scene import Revolute, RevoluteClearance, Translational, TranslationalClearance, driven_coordinate
from .symbolic import AssemblyContext, BodyFrame, Channel, rotation

#: Channels of a joint's coordinate and its rate, by driven coordinate: ((suffix, unit), (suffix, unit)).
JOINT_CHANNELS: dict[str, tuple[tuple[str, str], tuple[str, str]]] = {
    "rotation": (("angle", "rad"), ("rate", "rad/s")),
    "translation": (("displacement", "m"), ("speed", "m/s")),
}


def joint_coordinate(bi: BodyFrame, bj: BodyFrame, kind: str, s_i: Any = None, s_j: Any = None,
                     axis: Any = None) -> Any:
    """The coordinate of body j relative to body i: ``kind`` "rotation" or "translation" (of the
    body-fixed point ``s_j`` from ``s_i`` along ``axis``, a unit vector in body i's frame)."""
    if kind == "rotation":
        return bj.phi - bi.phi
    u = ca.mtimes(rotation(bi.phi), axis)
    return ca.dot(bj.point(s_j) - bi.point(s_i), u)


def joint_axis(ctx: AssemblyContext, joint: Any) -> Any:
    """A translational joint's unit axis in body i's frame, from its own parameters."""
    if isinstance(joint, TranslationalClearance):
        return ctx.p(joint.name, "t_guide")
    normal = ctx.p(joint.name, "normal")
    return ca.vertcat(normal[1], -normal[0])


def joint_channels(ctx: AssemblyContext, joints: Iterable[Any]) -> list[Channel]:
    """``<joint>.angle``/``.rate`` of every revolute joint, ``<joint>.displacement``/``.speed`` of
    every translational one."""
    out: list[Channel] = []
    for joint in joints:
        if not isinstance(joint, (Revolute, RevoluteClearance, Translational, TranslationalClearance)):
            continue
        kind = driven_coordinate(joint)
        assert kind is not None  # every revolute and translational joint has a coordinate
        bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
        if kind == "rotation":
            value = joint_coordinate(bi, bj, kind)
        else:
            value = joint_coordinate(bi, bj, kind, ctx.p(joint.name, "s_i"), ctx.p(joint.name, "s_j"),
                                     joint_axis(ctx, joint))
        (name, unit), (rate_name, rate_unit) = JOINT_CHANNELS[kind]
        out += [Channel(f"{joint.name}.{name}", unit, value),
                Channel(f"{joint.name}.{rate_name}", rate_unit, ca.jtimes(value, ctx.q, ctx.v))]
    return out
