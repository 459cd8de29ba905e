"""Symbolic building blocks of the assembly (CasADi SX): body kinematics, switchable force terms,
output channels and the context handed to element builders.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..model.elements import GROUND


def rotation(phi: Any) -> Any:
    """Planar rotation matrix A(phi) as a CasADi expression."""
    c, s = ca.cos(phi), ca.sin(phi)
    return ca.vertcat(ca.horzcat(c, -s), ca.horzcat(s, c))


def perpendicular(u: Any) -> Any:
    """Vector ``u`` rotated by +90 degrees."""
    return ca.vertcat(-u[1], u[0])


@dataclass(frozen=True)
class BodyFrame:
    """Symbolic kinematics of one body (or of the ground) inside an assembly."""

    name: str
    index: int | None  # position in the body list; None for the ground
    r: Any  # centre of mass (2x1)
    phi: Any
    v: Any  # velocity of the centre of mass (2x1)
    omega: Any

    def point(self, s_local: Any) -> Any:
        """World position of the body-fixed point ``s_local``."""
        return self.r + ca.mtimes(rotation(self.phi), s_local)

    def point_velocity(self, s_local: Any) -> Any:
        """World velocity of the body-fixed point ``s_local`` (material point)."""
        return self.v + self.omega * perpendicular(ca.mtimes(rotation(self.phi), s_local))

    def world_point_velocity(self, point: Any) -> Any:
        """Velocity of the body's material point at the world position ``point``."""
        return self.v + self.omega * perpendicular(point - self.r)


def body_frames(bodies: Sequence[Any], q: Any, v: Any) -> dict[str, BodyFrame]:
    """The symbolic frames of the ground and of ``bodies``, body k at ``q[3k:3k+3]``, ``v[3k:3k+3]``."""
    frames = {GROUND: BodyFrame(GROUND, None, ca.DM.zeros(2), ca.DM(0.0), ca.DM.zeros(2), ca.DM(0.0))}
    for k, body in enumerate(bodies):
        frames[body.name] = BodyFrame(body.name, k, q[3 * k:3 * k + 2], q[3 * k + 2], v[3 * k:3 * k + 2], v[3 * k + 2])
    return frames


@dataclass(frozen=True)
class Term:
    """A switchable generalized force (e.g. one contact pair): ``force`` maps ``(t, q, v, p, P)`` to
    the generalized force (length n_q), ``p`` of size ``n_params`` (e.g. the latched approach speed)."""

    name: str
    force: ca.Function
    n_params: int
    # (t, q, v, [p; piece], P) -> the force with its friction law's piece ``piece`` (FrictionLaw.piece), for a
    # friction law with kinks: what a run with sensitivities integrates between two kinks; else None
    locked: ca.Function | None = None


@dataclass(frozen=True)
class Channel:
    """A named output quantity with its unit and symbolic expression in (t, y, yp)."""

    name: str
    unit: str
    expr: Any


class Reference:
    """The scene's declared configuration (numbers only), to turn world data into body-fixed parameters."""

    def __init__(self, bodies: Sequence[Any], ground: str) -> None:
        self.pose: dict[str, tuple[tuple[float, float], float]] = {ground: ((0.0, 0.0), 0.0)}
        for body in bodies:
            self.pose[body.name] = (tuple(body.position), float(body.angle))

    def angle(self, body: str) -> float:
        return self.pose[body][1]

    def local_point(self, body: str, world: Sequence[float]) -> NDArray[np.float64]:
        """Body-fixed coordinates of a world point of the reference configuration."""
        (x0, y0), phi0 = self.pose[body]
        c, s = math.cos(phi0), math.sin(phi0)
        dx, dy = world[0] - x0, world[1] - y0
        return np.array([c * dx + s * dy, -s * dx + c * dy])

    def world_point(self, body: str, local: Sequence[float]) -> tuple[float, float]:
        """World position of the body-fixed point ``local`` in the reference configuration."""
        (x0, y0), phi0 = self.pose[body]
        c, s = math.cos(phi0), math.sin(phi0)
        return (x0 + c * local[0] - s * local[1], y0 + s * local[0] + c * local[1])

    def local_vector(self, body: str, world: Sequence[float]) -> NDArray[np.float64]:
        """Body-fixed components of a world direction (unit length) of the reference configuration."""
        phi0 = self.pose[body][1]
        v = np.asarray(world, dtype=float) / math.hypot(*world)
        c, s = math.cos(phi0), math.sin(phi0)
        return np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])

    def joint_points(self, joint: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body-fixed joint points of bodies i and j: ``point_i``/``point_j`` when given, else
        the world point ``at`` of the reference configuration."""
        s_i = (np.asarray(joint.point_i, dtype=float) if joint.point_i is not None
               else self.local_point(joint.body_i, joint.at))
        s_j = (np.asarray(joint.point_j, dtype=float) if joint.point_j is not None
               else self.local_point(joint.body_j, joint.at))
        return s_i, s_j


@dataclass
class AssemblyContext:
    """Symbols and per-body kinematics handed to element builders. Builders read every number from
    ``params`` (run-time parameters), never from the scene: one build serves a whole structure."""

    t: Any
    q: Any
    v: Any
    a: Any  # accelerations (v')
    P: Any  # the parameter vector, last input of every generated function
    frames: dict[str, BodyFrame]
    params: dict[str, Any]  # parameter name -> its slice of P
    offsets: dict[str, int]  # parameter name -> index of its first element in P

    @property
    def n_q(self) -> int:
        return int(self.q.numel())

    def p(self, owner: str, key: str) -> Any:
        """The parameter ``<owner>.<key>`` (a scalar symbol for one-element entries)."""
        value = self.params[f"{owner}.{key}"]
        return value[0] if value.numel() == 1 else value

    def generalized_force(self, loads: Sequence[tuple[str, Any, Any]],
                          couples: Sequence[tuple[str, Any]] = ()) -> Any:
        """Generalized force (length n_q) of point loads ``(body, force, world point)``, moved to the
        centres of mass with m = (x_P - x) f_y - (y_P - y) f_x (eqs. 4.10-4.13, 4.22-4.25), and of pure
        ``couples`` ``(body, torque)``; none on the ground."""
        Q = ca.SX(self.n_q, 1)  # structural zeros: only the loaded bodies' entries are nonzeros
        for body, force, point in loads:
            frame = self.frames[body]
            if frame.index is None:
                continue
            arm = point - frame.r
            k = 3 * frame.index
            Q[k] += force[0]
            Q[k + 1] += force[1]
            Q[k + 2] += arm[0] * force[1] - arm[1] * force[0]
        for body, torque in couples:
            frame = self.frames[body]
            if frame.index is not None:
                Q[3 * frame.index + 2] += torque
        return Q


class _FunctionBuffer:
    """One thread's CasADi FunctionBuffer of one Function, on fixed numpy arrays."""

    def __init__(self, function: ca.Function) -> None:
        self.function = function  # kept: the table below is keyed by its id
        self.inputs = [np.zeros(function.numel_in(i)) for i in range(function.n_in())]
        self.outputs = [np.zeros(function.numel_out(i)) for i in range(function.n_out())]
        self.buffer, self.evaluate = function.buffer()
        # (the ignores: CasADi's stub asks a size the binding takes from the memoryview)
        for i, a in enumerate(self.inputs):
            self.buffer.set_arg(i, memoryview(a))  # type: ignore[call-arg, arg-type]
        for i, r in enumerate(self.outputs):
            self.buffer.set_res(i, memoryview(r))  # type: ignore[call-arg, arg-type]
        self.bound_by: Any = None  # the BufferedFunction whose bound inputs the arrays hold


# per thread: id(Function) -> its _FunctionBuffer, shared by every BufferedFunction of that Function
_BUFFERS = threading.local()
_BUFFER_LIMIT = 256


class BufferedFunction:
    """A CasADi Function called through a FunctionBuffer on fixed arrays (~1 us a call instead of
    ~50-100 us): small functions on the per-event path. ``bound`` fills its last inputs (the model
    parameters). Each thread has one buffer per Function, shared by the models of one structure."""

    def __init__(self, function: ca.Function, bound: Sequence[Any] = ()) -> None:
        self.function = function
        self.bound = tuple(np.asarray(b, dtype=float).ravel() for b in bound)

    def _arrays(self) -> _FunctionBuffer:
        """This thread's buffer of the function, holding this object's bound inputs."""
        table = getattr(_BUFFERS, "table", None)
        if table is None or len(table) >= _BUFFER_LIMIT:  # a process of many structures: start afresh
            table = _BUFFERS.table = {}
        entry = table.get(id(self.function))
        if entry is None:
            entry = table[id(self.function)] = _FunctionBuffer(self.function)
        if entry.bound_by is not self:
            for a, x in zip(entry.inputs[len(entry.inputs) - len(self.bound):], self.bound):
                a[:] = x
            entry.bound_by = self
        return entry

    def __call__(self, *args: Any) -> tuple[NDArray[np.float64], ...]:
        entry = self._arrays()
        for a, x in zip(entry.inputs, args):
            a[:] = np.ravel(x)
        entry.evaluate()
        return tuple(r.copy() for r in entry.outputs)
