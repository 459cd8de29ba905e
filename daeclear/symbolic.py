"""Symbolic building blocks shared by the assembly and the contact elements (CasADi SX).

Body kinematics, switchable force terms, output channels and the context handed to
element builders. Nothing here knows a particular joint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray


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


@dataclass(frozen=True)
class Term:
    """A switchable generalized force (e.g. one contact pair), added to the equations of motion.

    ``force`` maps ``(t, q, v, p)`` to the generalized force vector (length n_q);
    ``n_params`` is the size of ``p`` (e.g. the approach speed latched at onset).
    """

    name: str
    force: ca.Function
    n_params: int


@dataclass(frozen=True)
class Channel:
    """A named output quantity with its unit and symbolic expression in (t, y, yp)."""

    name: str
    unit: str
    expr: Any


@dataclass
class AssemblyContext:
    """Symbols and per-body kinematics handed to element builders during assembly."""

    t: Any
    q: Any
    v: Any
    a: Any  # accelerations (v')
    frames: dict[str, BodyFrame]
    reference: dict[str, tuple[tuple[float, float], float]]  # body -> (position, angle)

    @property
    def n_q(self) -> int:
        return int(self.q.numel())

    def generalized_force(self, loads: Sequence[tuple[str, Any, Any]]) -> Any:
        """Generalized force vector (length n_q) of point loads ``(body, force (2x1), point (2x1))``.

        Each force acts at a world point; it is transported to the body's centre of mass with
        its moment m = (x_P - x) f_y - (y_P - y) f_x (eqs. 4.10-4.13, 4.22-4.25). Loads on the
        ground are dropped.
        """
        Q = ca.SX.zeros(self.n_q)
        for body, force, point in loads:
            frame = self.frames[body]
            if frame.index is None:
                continue
            arm = point - frame.r
            k = 3 * frame.index
            Q[k] += force[0]
            Q[k + 1] += force[1]
            Q[k + 2] += arm[0] * force[1] - arm[1] * force[0]
        return Q

    def local_point(self, body: str, world: Sequence[float]) -> NDArray[np.float64]:
        """Body-fixed coordinates of a world point of the reference configuration."""
        (x0, y0), phi0 = self.reference[body]
        c, s = math.cos(phi0), math.sin(phi0)
        dx, dy = world[0] - x0, world[1] - y0
        return np.array([c * dx + s * dy, -s * dx + c * dy])




class BufferedFunction:
    """A CasADi Function called through a FunctionBuffer on fixed numpy arrays (~1 us a call
    instead of ~50-100 us for a plain call): for small functions on the per-event path."""

    def __init__(self, function: ca.Function) -> None:
        self.function = function
        self._inputs = [np.zeros(function.numel_in(i)) for i in range(function.n_in())]
        self._outputs = [np.zeros(function.numel_out(i)) for i in range(function.n_out())]
        self._buffer, self._eval = function.buffer()
        for i, a in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(a))
        for i, r in enumerate(self._outputs):
            self._buffer.set_res(i, memoryview(r))

    def __call__(self, *args: Any) -> tuple[NDArray[np.float64], ...]:
        for a, x in zip(self._inputs, args):
            a[:] = np.ravel(x)
        self._eval()
        return tuple(r.copy() for r in self._outputs)

    def __getstate__(self) -> dict[str, Any]:  # picklable for process pools: rebuild the buffer
        return {"function": self.function}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__init__(state["function"])  # type: ignore[misc]
