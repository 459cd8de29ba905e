"""A scene placed at chosen joint coordinates: :func:`daeclear.place` (``start=``, ``speeds=``).

Least-norm Newton from the declared poses closes every joint as at a run's start with the named
joints at their values, velocities likewise; every number the declared configuration defined is
written as the body-fixed value it stood for (docs/user_guide.md).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any
from collections.abc import Mapping

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..core.errors import AssemblyError, SceneError
from ..model.loads import Force, RotationalSpringDamper, SpringDamper, attachment
from ..model.scene import (GROUND, Body, PointJoint, Scene, Translational,
                           TranslationalClearance, driven_coordinate, is_finite_number)
from .assemble import assemble
from .dae_model import NEWTON_STEPS, POSITION_TOL, RANK_TOL, DAEModel
from .joint_coordinates import JOINT_CHANNELS, joint_coordinate
from .symbolic import Reference, body_frames


def place(scene: Scene, start: Mapping[str, float] | None = None,
              speeds: Mapping[str, float] | None = None) -> Scene:
    """The scene with its bodies at the joint coordinates ``start`` (name -> rad or m) and moving at the
    joint rates ``speeds`` (rad/s, m/s). Raises SceneError for a bad argument, AssemblyError when the
    joints cannot close or the coordinates do not fix the configuration."""
    scene.validate()
    joints = {j.name: j for j in scene.joints if driven_coordinate(j) is not None}
    start_values = _checked(scene, "start", start, joints)
    speed_values = None if speeds is None else _checked(scene, "speeds", speeds, joints)
    drivers = {d.joint: d for d in scene.drivers}
    for name in start_values:
        driver = drivers.get(name)
        if driver is not None and (driver.initial_angle is not None or driver.initial_position is not None
                                   or not driver.motion_profile.uses_speed):
            raise SceneError(f"scene '{scene.name}': place: start[{name!r}]={start_values[name]!r}, but Driver "
                             f"'{driver.name}' fixes the coordinate of joint '{name}' at t = 0 (its initial value or "
                             "tabulated profile); leave one of the two out.")
    for name in speed_values or {}:
        if name in drivers:
            raise SceneError(f"scene '{scene.name}': place: speeds[{name!r}]={speed_values[name]!r}, but joint "  # type: ignore[index]
                             f"'{name}' is driven by Driver '{drivers[name].name}', whose profile gives its speed; "
                             "leave it out of speeds.")
    model = assemble(scene)
    ref = Reference(tuple(scene.bodies), GROUND)
    n = model.n_q
    names = list(dict.fromkeys([*start_values, *(speed_values or {})]))
    coordinates = _coordinate_function(scene, ref, [joints[name] for name in names])
    replaced = {drivers[name].name for name in start_values if name in drivers}
    owners = _row_owners(model)
    keep = [i for i, owner in enumerate(owners) if owner not in replaced]
    label = f"scene '{scene.name}': place(start={dict(start_values)!r})"

    def rows(q: NDArray[np.float64], v: NDArray[np.float64], chosen: list[str]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        Phi, Phi_q, Phi_dot = model.constraints(q, v, 0.0, ideal=True)
        c, C_q = (np.asarray(x, dtype=float) for x in coordinates(q))
        index = [names.index(name) for name in chosen]
        return Phi[keep], Phi_q[keep], c.ravel()[index], C_q[index]

    q = np.array(model.q_guess, dtype=float)
    chosen = list(start_values)
    target = np.array([start_values[name] for name in chosen])
    scale = max(1.0, float(np.max(np.abs(q))))
    for _ in range(NEWTON_STEPS):
        Phi, Phi_q, c, C_q = rows(q, np.zeros(n), chosen)
        F, J = np.concatenate([Phi, c - target]), np.vstack([Phi_q, C_q])
        if F.size == 0 or np.max(np.abs(F)) < POSITION_TOL * scale:
            # one step more: the coordinates to round-off, however flat the closure is in them
            q = q + np.linalg.lstsq(J, -F, rcond=None)[0] if F.size else q
            break
        q = q + np.linalg.lstsq(J, -F, rcond=None)[0]
    else:
        row_names = [model.start_constraint_names[i] for i in keep] + [
            f"{name}.{JOINT_CHANNELS[driven_coordinate(joints[name])][0][0]}" for name in chosen]  # type: ignore[index]
        worst = np.argsort(-np.abs(F))[:4]
        detail = ", ".join(f"{row_names[i]} = {F[i]:.3g}" for i in worst)
        involved = ", ".join(dict.fromkeys(row_names[i].rsplit(".", 1)[0] for i in worst if abs(F[i]) > 1e-9))
        raise AssemblyError(f"{label}: the joints cannot all close at the chosen coordinates: after {NEWTON_STEPS} "
                            f"Newton iterations the largest residuals are {detail} (joints {involved}). Check the "
                            "chosen values (a loop that cannot reach them), the joint points and the drivers' "
                            "initial values.")
    _check_fixed(label, "start", np.vstack([Phi_q, C_q]), scene, chosen, joints)
    # no speeds: the declared velocities corrected (least norm) to the joints and drivers, as a run's start does
    v = model.assemble_velocities(q, model.v_guess, ideal=True)
    if speed_values is not None:
        _, Phi_q, Phi_t = model.constraints(q, np.zeros(n), 0.0, ideal=True)
        by_name = [names.index(name) for name in speed_values]
        C_q = np.asarray(coordinates(q)[1], dtype=float)[by_name]
        # every row of the start, the drivers' too (their profiles give their joints' speeds)
        J = np.vstack([Phi_q, C_q])
        b = np.concatenate([-Phi_t, [speed_values[name] for name in speed_values]])
        _check_fixed(f"scene '{scene.name}': place(speeds={dict(speed_values)!r})", "speeds", J, scene,
                     list(speed_values), joints)
        v = np.linalg.lstsq(J, b, rcond=None)[0]
    return _placed(scene, ref, q, v)


def _checked(scene: Scene, field_name: str, values: Mapping[str, float] | None, joints: dict[str, Any]
             ) -> dict[str, float]:
    """``values`` as a dict joint name -> float; a clear error for anything else."""
    where = f"scene '{scene.name}': place"
    if values is None:
        return {}
    if not isinstance(values, Mapping):
        raise SceneError(f"{where}: {field_name}={values!r}, must be a mapping joint name -> value "
                         "(rad for a revolute joint, m for a translational one).")
    out: dict[str, float] = {}
    for name, value in values.items():
        if name not in joints:
            raise SceneError(f"{where}: {field_name} names {name!r}, must be a revolute or translational joint of "
                             f"the scene ({', '.join(joints) or 'none'}).")
        if not is_finite_number(value):
            raise SceneError(f"{where}: {field_name}[{name!r}]={value!r}, must be a finite number.")
        out[name] = float(value)
    return out


def _row_owners(model: DAEModel) -> list[str]:
    """The element of each row of the start's constraints (joints, drivers, clearance joints)."""
    owners = list(model.constraint_elements)
    return owners + [name.rsplit(".", 1)[0] for name in model.start_constraint_names[len(owners):]]


def _coordinate_function(scene: Scene, ref: Reference, joints: list[Any]) -> ca.Function:
    """q -> (the coordinates of ``joints``, their Jacobian), every number from the declared scene."""
    bodies = scene.bodies
    q, v = ca.SX.sym("q", 3 * len(bodies)), ca.SX.sym("v", 3 * len(bodies))
    frames = body_frames(bodies, q, v)
    values = []
    for joint in joints:
        kind = driven_coordinate(joint)
        bi, bj = frames[joint.body_i], frames[joint.body_j]
        if kind == "rotation":
            values.append(joint_coordinate(bi, bj, "rotation"))
        else:
            s_i, s_j = ref.joint_points(joint)
            axis = ref.local_vector(joint.body_i, joint.axis)
            values.append(joint_coordinate(bi, bj, "translation", ca.DM(s_i), ca.DM(s_j), ca.DM(axis)))
    c = ca.vertcat(*values) if values else ca.SX(0, 1)
    return ca.Function("joint_coordinates", [q], [c, ca.densify(ca.jacobian(c, q))])


def _check_fixed(label: str, field_name: str, J: NDArray[np.float64], scene: Scene, chosen: list[str],
                 joints: dict[str, Any]) -> None:
    """Raise AssemblyError unless the rows ``J`` fix every body coordinate (full column rank)."""
    n = J.shape[1]
    sigma = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
    rank = int(np.sum(sigma > RANK_TOL * float(sigma[0]))) if sigma.size else 0
    if rank >= n:
        return
    free = n - rank
    others = [name for name in joints if name not in chosen]
    raise AssemblyError(
        f"{label}: the chosen coordinates do not fix the configuration: with the joints and drivers they make "
        f"{J.shape[0]} conditions of rank {rank} on the {n} body coordinates, so {free} degree(s) of freedom remain "
        f"free. Name {free} more joint(s) in {field_name} (not named: {', '.join(others) or 'none'}), or drive them; "
        "a singular configuration (links aligned) can also lose rank.")


def _placed(scene: Scene, ref: Reference, q: NDArray[np.float64], v: NDArray[np.float64]) -> Scene:
    """The scene with the bodies at ``q`` (and ``v``), every reference-dependent number kept."""
    index = {b.name: k for k, b in enumerate(scene.bodies)}
    elements = []
    for element in scene.elements:
        changes: dict[str, Any] = {}
        if isinstance(element, Body):
            k = 3 * index[element.name]
            changes.update(position=(float(q[k]), float(q[k + 1])), angle=float(q[k + 2]),
                           velocity=(float(v[k]), float(v[k + 1])), angular_velocity=float(v[k + 2]))
        elif isinstance(element, PointJoint):
            if element.at is not None:
                s_i, s_j = ref.joint_points(element)
                changes.update(at=None, point_i=_pair(s_i), point_j=_pair(s_j))
            if isinstance(element, (Translational, TranslationalClearance)):
                u = ref.local_vector(element.body_i, element.axis)
                phi = float(q[3 * index[element.body_i] + 2]) if element.body_i in index else 0.0
                c, s = math.cos(phi), math.sin(phi)
                changes["axis"] = (c * u[0] - s * u[1], s * u[0] + c * u[1])
                if isinstance(element, TranslationalClearance) and element.slider_axis is None:
                    changes["slider_axis"] = _pair(ref.local_vector(element.body_j, element.axis))
        elif isinstance(element, Force) and element.at is not None:
            changes.update(at=None, point=attachment(ref, element.body, element.at, None))
        elif isinstance(element, SpringDamper):
            end_i = attachment(ref, element.body_i, element.at_i, element.point_i)
            end_j = attachment(ref, element.body_j, element.at_j, element.point_j)
            changes.update(at_i=None, at_j=None, point_i=end_i, point_j=end_j)
            if element.free_length is None:
                changes["free_length"] = math.dist(ref.world_point(element.body_i, end_i),
                                                   ref.world_point(element.body_j, end_j))
        elif isinstance(element, RotationalSpringDamper) and element.free_angle is None:
            changes["free_angle"] = ref.angle(element.body_j) - ref.angle(element.body_i)
        # drivers (an initial value None: the new coordinate), torques, motors: unchanged
        elements.append(dataclasses.replace(element, **changes) if changes else element)  # type: ignore[type-var]
    return Scene(scene.name, gravity=scene.gravity, elements=elements, ground=scene.ground)


def _pair(values: Any) -> tuple[float, float]:
    return (float(values[0]), float(values[1]))
