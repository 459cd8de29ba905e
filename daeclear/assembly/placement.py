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
    for name, value in (speed_values or {}).items():
        if name in drivers:
            raise SceneError(f"scene '{scene.name}': place: speeds[{name!r}]={value!r}, but joint "
                             f"'{name}' is driven by Driver '{drivers[name].name}', whose profile gives its speed; "
                             "leave it out of speeds.")
    model = assemble(scene)
    ref = Reference(tuple(scene.bodies), GROUND)
    names = list(dict.fromkeys([*start_values, *(speed_values or {})]))
    replaced = {drivers[name].name for name in start_values if name in drivers}
    placement = _Placement(model, _coordinate_function(scene, ref, [joints[name] for name in names]), names,
                       [i for i, owner in enumerate(_row_owners(model)) if owner not in replaced])
    label = f"scene '{scene.name}': place(start={dict(start_values)!r})"
    q = placement.positions(label, start_values, joints)
    Phi, Phi_q, c, C_q = placement.rows(q, list(start_values))
    _check_fixed(label, "start", np.vstack([Phi_q, C_q]), scene, list(start_values), joints)
    # no speeds: the declared velocities corrected (least norm) to the joints and drivers, as a run's start does
    v = model.assemble_velocities(q, model.v_guess, ideal=True)
    if speed_values is not None:
        v = placement.velocities(scene, q, speed_values, joints)
    return _placed(scene, ref, q, v)


#: First guesses when Newton from the declared pose fails: the pose moved along each of its free motions
#: (the null space of the joints' Jacobian, unit vectors in the body coordinates) by these steps, both ways.
GUESS_STEPS = (0.1, 0.3, 1.0)
#: Continuation from a first guess: the chosen coordinates moved to their values in this many equal steps.
CONTINUATION_STEPS = 16
#: Speeds are consistent when the velocity the joints allow meets each to this fraction of the largest speed.
SPEED_TOL = 1e-9


class _Placement:
    """The start's conditions on the body coordinates: the joints and drivers closed as at a run's start
    (``keep``: the rows of the drivers of named joints left out) and the named joints' coordinates."""

    def __init__(self, model: DAEModel, coordinates: ca.Function, names: list[str], keep: list[int]) -> None:
        self.model, self.coordinates, self.names, self.keep = model, coordinates, names, keep
        self.zero = np.zeros(model.n_q)

    def rows(self, q: NDArray[np.float64], chosen: list[str]
             ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(Phi, Phi_q, c, C_q): the kept joint rows and the ``chosen`` coordinates at ``q``."""
        Phi, Phi_q, _ = self.model.constraints(q, self.zero, 0.0, ideal=True)
        c, C_q = (np.asarray(x, dtype=float) for x in self.coordinates(q))
        index = [self.names.index(name) for name in chosen]
        return Phi[self.keep], Phi_q[self.keep], c.ravel()[index], C_q[index]

    def newton(self, q: NDArray[np.float64], chosen: list[str], target: NDArray[np.float64], scale: float
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
        """Least-norm Newton on the joints and the ``chosen`` coordinates at ``target``: (q, residual, closed)."""
        F = np.zeros(0)
        for _ in range(NEWTON_STEPS):
            Phi, Phi_q, c, C_q = self.rows(q, chosen)
            F, J = np.concatenate([Phi, c - target]), np.vstack([Phi_q, C_q])
            if F.size == 0 or np.max(np.abs(F)) < POSITION_TOL * scale:
                # one step more: the coordinates to round-off, however flat the closure is in them
                return (q + np.linalg.lstsq(J, -F, rcond=None)[0] if F.size else q), F, True
            if not np.all(np.isfinite(F)):
                break
            q = q + np.linalg.lstsq(J, -F, rcond=None)[0]
        return q, F, False

    def continued(self, q: NDArray[np.float64], chosen: list[str], target: NDArray[np.float64], scale: float
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], bool]:
        """From ``q``: close the joints, then move the coordinates to ``target`` step by step (each step's
        Newton starts at the previous pose, so the branch of ``q`` is kept)."""
        q, F, closed = self.newton(q, [], np.zeros(0), scale)
        if not closed:
            return q, F, False
        start = self.rows(q, chosen)[2]
        for k in range(1, CONTINUATION_STEPS + 1):
            q, F, closed = self.newton(q, chosen, start + k / CONTINUATION_STEPS * (target - start), scale)
            if not closed:
                return q, F, False
        return q, F, True

    def positions(self, label: str, start_values: dict[str, float], joints: dict[str, Any]) -> NDArray[np.float64]:
        """The body coordinates with the joints closed and the named coordinates at their values: Newton from
        the declared pose; failing that, continuation from it and from first guesses around it (a declared
        pose at a dead centre, where the coordinate does not move to first order). AssemblyError if none closes."""
        chosen = list(start_values)
        target = np.array([start_values[name] for name in chosen])
        declared = np.array(self.model.q_guess, dtype=float)
        scale = max(1.0, float(np.max(np.abs(declared))))
        q, F, closed = self.newton(declared, chosen, target, scale)
        guesses = [] if closed else [declared, *first_guesses(declared, self.rows(declared, [])[1])]
        for guess in guesses:
            found = self.continued(guess, chosen, target, scale)
            if found[2]:
                return found[0]
        if closed:
            return q
        row_names = [self.model.start_constraint_names[i] for i in self.keep] + [
            f"{name}.{_channels(joints[name])[0][0]}" for name in chosen]
        worst = np.argsort(-np.abs(F))[:4]
        detail = ", ".join(f"{row_names[i]} = {F[i]:.3g}" for i in worst)
        involved = ", ".join(dict.fromkeys(row_names[i].rsplit(".", 1)[0] for i in worst if abs(F[i]) > 1e-9))
        _, Phi_q, _, C_q = self.rows(declared, chosen)
        raise AssemblyError(f"{label}: the joints cannot all close at the chosen coordinates: Newton from the "
                            f"declared pose and continuation from it and from {len(guesses) - 1} first guesses "
                            f"around it fail; the largest residuals are {detail} (joints {involved}). "
                            + stationary(Phi_q, C_q, chosen, joints)
                            + "Check the chosen values (a loop that cannot reach them), the joint points and the "
                            "drivers' initial values.")

    def velocities(self, scene: Scene, q: NDArray[np.float64], speed_values: dict[str, float],
                   joints: dict[str, Any]) -> NDArray[np.float64]:
        """The velocity with the joints' rates ``speed_values``: every row of the start held (the drivers' too:
        their profiles give their joints' speeds), the speeds met exactly or refused (AssemblyError)."""
        _, Phi_q, Phi_t = self.model.constraints(q, self.zero, 0.0, ideal=True)
        C_q = np.asarray(self.coordinates(q)[1], dtype=float)[[self.names.index(name) for name in speed_values]]
        given = np.array([speed_values[name] for name in speed_values])
        _check_fixed(f"scene '{scene.name}': place(speeds={dict(speed_values)!r})", "speeds",
                     np.vstack([Phi_q, C_q]), scene, list(speed_values), joints)
        # the velocities the joints allow, v_p + N z; the speeds fit in z alone, so a miss is theirs
        v_p = np.linalg.lstsq(Phi_q, -Phi_t, rcond=None)[0]
        free = _free_motions(Phi_q)
        v = v_p + free.T @ np.linalg.lstsq(C_q @ free.T, given - C_q @ v_p, rcond=None)[0]
        got = C_q @ v
        if np.max(np.abs(got - given)) > SPEED_TOL * max(1.0, float(np.max(np.abs(given)))):
            rates = [_channels(joints[name])[1] for name in speed_values]
            detail = ", ".join(f"{name}.{rate} = {closest:.6g} {unit} ({value:.6g} given)" for name, value, closest,
                               (rate, unit) in zip(speed_values, given, got, rates))
            raise AssemblyError(
                f"scene '{scene.name}': assembled: speeds={dict(speed_values)!r} contradict the joints: the mechanism "
                f"has {free.shape[0]} degree(s) of freedom, {len(speed_values)} speeds given, and no velocity it "
                f"allows has them all; the closest has {detail}. Give {free.shape[0]} independent speed(s), or values "
                "the kinematics allow.")
        return v


def _channels(joint: Any) -> tuple[tuple[str, str], tuple[str, str]]:
    """The (coordinate, unit) and (rate, unit) channel names of a revolute or translational joint."""
    kind = driven_coordinate(joint)
    assert kind is not None  # the joints named in start and speeds are checked to have one
    return JOINT_CHANNELS[kind]


def _free_motions(Phi_q: NDArray[np.float64]) -> NDArray[np.float64]:
    """An orthonormal basis of the motions the rows ``Phi_q`` allow (their null space), one per row."""
    if not Phi_q.size:
        return np.eye(Phi_q.shape[1])
    _, sigma, vt = np.linalg.svd(Phi_q)
    return vt[int(np.sum(sigma > RANK_TOL * float(sigma[0]))):]


def first_guesses(q: NDArray[np.float64], Phi_q: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Poses around ``q`` along its free motions, nearest first (the positive direction before the negative)."""
    free = _free_motions(Phi_q)
    return [q + sign * step * direction for step in GUESS_STEPS for direction in free for sign in (1.0, -1.0)]


def stationary(Phi_q: NDArray[np.float64], C_q: NDArray[np.float64], chosen: list[str],
               joints: dict[str, Any]) -> str:
    """The sentence naming the chosen joints whose coordinate no motion the joints allow changes at the
    declared pose (a singular configuration, e.g. a slider-crank at a dead centre), or ""."""
    free = _free_motions(Phi_q)
    stuck = [name for name, row in zip(chosen, C_q)
             if free.size == 0 or np.linalg.norm(free @ row) <= 1e-8 * max(1.0, float(np.linalg.norm(row)))]
    if not stuck:
        return ""
    words = ", ".join(f"{name} ({_channels(joints[name])[0][0]})" for name in stuck)
    return (f"At the declared pose {words} is at a singular configuration: no motion the joints allow changes "
            "its coordinate to first order (links aligned, e.g. a dead centre); declare the bodies away from it, "
            "on the branch wanted. ")


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
