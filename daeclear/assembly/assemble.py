"""Scene -> DAEModel: the symbolic equations of motion, built once with CasADi.

Coordinates: each moving body k has ``q_k = (x_k, y_k, phi_k)`` of its centre of
mass; the state is ``y = [q, v, lam]`` (``index1``) or ``y = [q, v, lam, mu]``
(``ggl``). Ideal joints and drivers are constraints ``Phi(q, t) = 0``; contact
elements (clearance joints) add no constraint but *terms*: generalized forces that
the solver switches on and off between integration segments.

Formulations
------------
``index1`` (the chapter's, default)::

    q' - v                                   = 0
    M v' + Phi_q^T lam - Q(q, v, t)          = 0
    Phi_q v' - gamma + 2 alpha Phi' + beta^2 Phi = 0     (Baumgarte)

``ggl`` (stabilised index 2, Gear-Gupta-Leimkuhler; drift-free)::

    q' - v + Phi_q^T mu                      = 0
    M v' + Phi_q^T lam - Q(q, v, t)          = 0
    Phi_q v + Phi_t                          = 0
    Phi(q, t)                                = 0

where ``Phi' = Phi_q v + Phi_t`` and ``gamma = -(d Phi'/dq) v - d Phi'/dt``.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, Callable, ClassVar, Literal, Sequence

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..engine.build import memo_table
from ..errors import AssemblyError, SceneError
from ..engine.session_base import DAEFunctions, StateLayout
from ..options import DEFAULT_FORMULATION, FORMULATIONS
from .parameters import ParameterTable, structure_key
from ..solvers.physics import check_start_penetration
from ..model.scene import GROUND, Body, Driver, Revolute, Scene, Translational
from .revolute_joint import CONTACT_BUILDERS
from .drivers import driver_constraint, driver_load, driver_parameters
from ..model.loads import Load, build_loads, load_parameters
from .symbolic import AssemblyContext, BodyFrame, BufferedFunction, Channel, Reference, Term, rotation

Formulation = Literal["index1", "ggl"]

# Extra functions compiled with the model (DAEFunctions.extras), evaluated over many points.
# kinematics: (q, v, t) -> [Phi; Phi_q (column-major); Phi_dot]; start kinematics: the same with
# every clearance joint's ideal joint added (the chapter's start); term k's force: EXTRA_TERM0 + k
EXTRA_OUTPUTS, EXTRA_ACCEL, EXTRA_KINEMATICS, EXTRA_START_KINEMATICS, EXTRA_TERM0 = 0, 1, 2, 3, 4


# Projection onto the constraint manifold (initial state and restarts, in Python and in C):
# |Phi| < POSITION_TOL * max(1, |q|) within NEWTON_STEPS least-norm Newton steps.
POSITION_TOL = 1e-13
NEWTON_STEPS = 50

# State kinds: how each state variable is treated by the solver's error test.
KIND_POSITION, KIND_VELOCITY, KIND_MULTIPLIER, KIND_WORK = "q", "v", "lambda", "work"


@dataclass(frozen=True)
class DAEModel:
    """An assembled mechanism: CasADi functions for the solver plus everything to interpret them.

    Build it with :func:`assemble`; it is frozen and independent of the scene object.
    ``print(model)`` summarises its sizes.
    """

    scene_name: str
    formulation: str
    alpha: float
    beta: float
    body_names: tuple[str, ...]
    constraint_names: tuple[str, ...]
    state_names: tuple[str, ...]
    state_kinds: tuple[str, ...]
    functions: DAEFunctions
    terms: tuple[Term, ...]
    gap_names: tuple[str, ...]
    channel_names: tuple[str, ...]
    channel_units: dict[str, str]
    outputs: ca.Function  # (t, y, yp, switch) -> channel values; switch: see switch_vector
    q_guess: NDArray[np.float64]
    v_guess: NDArray[np.float64]
    mass_diagonal: NDArray[np.float64]
    kinematics: ca.Function  # (q, v, t) -> (Phi, Phi_q, Phi_dot, gamma)
    base_force: ca.Function  # (t, q, v) -> Q (gravity and applied loads)
    parameters: dict[str, Any] = field(default_factory=dict)
    contacts: tuple[Any, ...] = ()  # contact elements' event logic (clearance joints)
    track_work: bool = False
    # (root, term, gap-rate extra, needs approach speed, min approach speed) of simple pairs
    auto_pairs: tuple[tuple[int, int, int, bool, float], ...] = ()
    # constraints of the chapter's start: the ideal joints, then each clearance joint's ideal joint
    start_constraint_names: tuple[str, ...] = ()
    # run-time parameters: the last input of every function above (see daeclear.assembly.parameters)
    parameter_layout: tuple[tuple[str, int], ...] = ()  # (name, size) of each entry
    parameter_values: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    # the scene element (joint or driver name) of each constraint row, for messages
    constraint_elements: tuple[str, ...] = ()
    # (name, clearance m, corner radius m or 0) of each clearance joint: the limits of the physics checks
    clearance_joints: tuple[tuple[str, float, float], ...] = ()
    driver_names: tuple[str, ...] = ()
    # False for a model that starts from a computed state (a restart), whose start is not checked
    start_is_declared: ClassVar[bool] = True

    def __post_init__(self) -> None:
        # frozen means frozen: the arrays are read-only (a copy when the caller's array is writable)
        for name in ("q_guess", "v_guess", "mass_diagonal", "parameter_values"):
            object.__setattr__(self, name, _read_only(getattr(self, name)))

    def for_run(self, *, from_state: bool = False) -> DAEModel:
        """A copy of this model for one run: the same functions and numbers, its own contact logic.

        The contact logic objects hold a run's state (each pair's mode, latched approach speed and
        storm history); a run works on its own copies, so that a model is never changed by a run
        and runs of one model (one after the other, or at the same time in threads) are
        independent. ``from_state``: the run starts from a given state of a run (``simulate(...,
        y0=...)``), whose contacts at the start are no declaration error (:mod:`daeclear.solvers.physics`).
        """
        run_model = dataclasses.replace(self, contacts=tuple(_run_copy(logic) for logic in self.contacts))
        if from_state:  # an instance value over the class's: this copy only (the class default stays)
            object.__setattr__(run_model, "start_is_declared", False)
        return run_model

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(name for name, _ in self.parameter_layout)

    def parameter(self, name: str) -> NDArray[np.float64]:
        """The value of one run-time parameter, e.g. ``model.parameter("clearance.clearance")``."""
        offset = 0
        for key, size in self.parameter_layout:
            if key == name:
                return self.parameter_values[offset:offset + size].copy()
            offset += size
        raise KeyError(f"no parameter {name!r}; the model has {', '.join(self.parameter_names)}")

    @property
    def n_q(self) -> int:
        return len(self.body_names) * 3

    @property
    def n_constraints(self) -> int:
        return len(self.constraint_names)

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    @property
    def differential(self) -> NDArray[np.bool_]:
        """True for differential states (q, v), False for algebraic ones (multipliers)."""
        return np.array([k != KIND_MULTIPLIER for k in self.state_kinds])

    def layout(self, project: bool) -> StateLayout:
        """Where q, v, the multipliers (and mu, work) are in y and which extras make a state
        consistent, for the compiled loop; ``project``: restarts on the constraint manifold."""
        return StateLayout(
            n_q=self.n_q, n_constraints=self.n_constraints, ggl=self.formulation == "ggl", track_work=self.track_work,
            accel_extra=EXTRA_ACCEL, force_extra0=EXTRA_TERM0, kinematics_extra=EXTRA_KINEMATICS,
            outputs_extra=EXTRA_OUTPUTS, project=project, tol=POSITION_TOL, max_iter=NEWTON_STEPS)

    def __str__(self) -> str:
        n_q, m = self.n_q, self.n_constraints
        extra = self.n_states - 2 * n_q - m - int(self.track_work)
        parts = (f"q {n_q} + v {n_q} + lambda {m}" + (f" + mu {extra}" if extra else "")
                 + (" + work 1" if self.track_work else ""))
        lines = [
            f"DAEModel '{self.scene_name}' ({self.formulation}"
            + (f", alpha={self.alpha:g}, beta={self.beta:g})" if self.formulation == "index1" else ")"),
            f"  bodies:      {len(self.body_names)} ({', '.join(self.body_names)})",
            f"  states:      {self.n_states} = {parts}",
            f"  constraints: {m} ({', '.join(self.constraint_names)})",
            f"  terms:       {len(self.terms)}" + (f" ({', '.join(t.name for t in self.terms)})" if self.terms else ""),
            f"  gaps:        {len(self.gap_names)}" + (f" ({', '.join(self.gap_names)})" if self.gap_names else ""),
            f"  channels:    {len(self.channel_names)}",
        ]
        return "\n".join(lines)

    def summary(self) -> dict[str, int]:
        """Sizes of the assembled DAE (what ``print(model)`` shows), for tests and logs."""
        return {
            "bodies": len(self.body_names),
            "states": self.n_states,
            "constraints": self.n_constraints,
            "terms": len(self.terms),
            "gaps": len(self.gap_names),
            "channels": len(self.channel_names),
        }

    # ---- consistent states -------------------------------------------------------------
    def constraints(self, q: NDArray[np.float64], v: NDArray[np.float64], t: float, session: Any = None,
                     ideal: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(Phi, Phi_q, Phi_dot) at one state, through the compiled library when a session is open;
        ``ideal``: with the ideal joints of the clearance joints added (the chapter's start)."""
        m, n = (len(self.start_constraint_names), self.n_q) if ideal else (self.n_constraints, self.n_q)
        flat = self.evaluate(EXTRA_START_KINEMATICS if ideal else EXTRA_KINEMATICS, [q, v, np.array([t])], 1,
                             session)[0]
        return flat[:m], flat[m:m + m * n].reshape(n, m).T, flat[m + m * n:]

    def assemble_positions(self, q_guess: NDArray[np.float64], t: float = 0.0, tol: float = POSITION_TOL,
                           max_iter: int = NEWTON_STEPS, session: Any = None, ideal: bool = False
                           ) -> NDArray[np.float64]:
        """Newton (least-norm) on Phi(q, t) = 0 from ``q_guess`` (``ideal``: the clearance joints'
        ideal joints too); raises AssemblyError if it cannot close."""
        q = np.array(q_guess, dtype=float)
        names = self.start_constraint_names if ideal else self.constraint_names
        if not names:
            return q
        scale = max(1.0, float(np.max(np.abs(q))))
        zero_v = np.zeros(self.n_q)
        for _ in range(max_iter):
            Phi, Phi_q, _ = self.constraints(q, zero_v, t, session, ideal)
            if np.max(np.abs(Phi)) < tol * scale:
                return q
            dq, *_ = np.linalg.lstsq(Phi_q, -Phi, rcond=None)
            q = q + dq
        Phi = self.constraints(q, zero_v, t, session, ideal)[0]
        worst = np.argsort(-np.abs(Phi))[:3]
        detail = ", ".join(f"'{names[i]}' = {Phi[i]:.3g}" for i in worst)
        raise AssemblyError(
            f"scene '{self.scene_name}': cannot assemble the initial positions; after {max_iter} Newton "
            f"iterations the largest constraint residuals are {detail}. Check the joint points and "
            "initial positions: the joints cannot all close."
        )

    def assemble_velocities(self, q: NDArray[np.float64], v_guess: NDArray[np.float64],
                            t: float = 0.0, session: Any = None, ideal: bool = False) -> NDArray[np.float64]:
        """Least-norm correction of ``v_guess`` so that Phi_q v + Phi_t = 0 (``ideal``: as above)."""
        v = np.array(v_guess, dtype=float)
        if not (self.start_constraint_names if ideal else self.constraint_names):
            return v
        _, Phi_q, Phi_dot = self.constraints(q, v, t, session, ideal)
        dv, *_ = np.linalg.lstsq(Phi_q, -Phi_dot, rcond=None)
        return v + dv

    def evaluate(self, k: int, inputs: Sequence[Any], n_points: int, session: Any = None) -> NDArray[np.float64]:
        """Evaluate ``functions.extras[k]`` at ``n_points`` points (inputs (n_points, size) or (size,)).

        With an open compiled ``session`` the loop runs in C (~1 us a point); otherwise CasADi.
        Every extra takes the run-time parameters as its last input; they are appended here.
        """
        if session is not None:
            return session.eval_extra(k, inputs, n_points)
        f = self.functions.extras[k]
        inputs = [*inputs, self.parameter_values]
        cols = [np.zeros((0, n_points)) if f.numel_in(j) == 0 else
                np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, f.numel_in(j)), (n_points, f.numel_in(j))).T
                for j, x in enumerate(inputs)]
        return np.array(_mapped(f, n_points)(*cols)).reshape(-1, n_points).T

    def term_forces(self, t: ArrayLike, y: NDArray[np.float64], active: Sequence[bool],
                    params: Sequence[NDArray[np.float64]], session: Any = None) -> NDArray[np.float64] | None:
        """Sum of the generalized forces of the active terms at one state (n_states,) or many (N, n_states)."""
        if not any(active):
            return None
        n = self.n_q
        y2 = np.atleast_2d(y)
        N = y2.shape[0]
        t_arr = np.asarray(t, dtype=float)
        t_col = t_arr.reshape(N, 1) if t_arr.size == N else np.full((N, 1), float(t_arr.ravel()[0]))
        total = np.zeros((N, n))
        for k, (on, p) in enumerate(zip(active, params)):
            if on:
                total += self.evaluate(EXTRA_TERM0 + k, [t_col, y2[:, :n], y2[:, n:2 * n], np.asarray(p, dtype=float)],
                                       N, session)
        return total[0] if np.ndim(y) == 1 else total

    def term_forces_rows(self, t: NDArray[np.float64], y: NDArray[np.float64], switch: NDArray[np.float64],
                         session: Any = None) -> NDArray[np.float64] | None:
        """Generalized contact forces at many rows, each with its own modes: ``switch`` holds one
        :meth:`switch_vector` per row (on/off flag and parameters of every term)."""
        if not self.terms:
            return None
        N, n = y.shape[0], self.n_q
        total = np.zeros((N, n))
        off = 0
        for k, term in enumerate(self.terms):
            rows = np.nonzero(switch[:, off] > 0)[0]
            if rows.size:
                P = np.ascontiguousarray(switch[rows, off + 1:off + 1 + term.n_params])
                total[rows] += self.evaluate(EXTRA_TERM0 + k, [t[rows].reshape(-1, 1), y[rows, :n], y[rows, n:2 * n], P],
                                             rows.size, session)
            off += 1 + term.n_params
        return total

    def accelerations(self, t: ArrayLike, q: NDArray[np.float64], v: NDArray[np.float64],
                      generalized_force: NDArray[np.float64] | None = None, session: Any = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Solve [M Phi_q^T; Phi_q 0] [v'; lam] = [Q; c] for v' and lam (generated code, see assemble).

        ``c = gamma - 2 alpha Phi' - beta^2 Phi`` (index1) or ``gamma`` (ggl). Works on one state
        (``q``, ``v`` of shape (n,)) or on many (N, n) with ``t`` of shape (N,).
        ``generalized_force`` adds contact forces to the base forces (gravity).
        """
        single = np.ndim(q) == 1
        n, m = self.n_q, self.n_constraints
        sol = self._accel_solution(t, np.atleast_2d(q), np.atleast_2d(v), generalized_force, session)
        a, lam = sol[:, :n], sol[:, n:n + m]
        return (a[0], lam[0]) if single else (a, lam)

    def _accel_solution(self, t: ArrayLike, q: NDArray, v: NDArray, generalized_force: NDArray | None,
                        session: Any) -> NDArray[np.float64]:
        """[a, lam(, work rate)] per row, from the generated Schur-complement solve."""
        N = q.shape[0]
        t_arr = np.asarray(t, dtype=float)
        t_col = t_arr.reshape(N, 1) if t_arr.size == N else np.full((N, 1), float(t_arr.ravel()[0]))
        Qc = self._zero_force if generalized_force is None else generalized_force
        return self.evaluate(EXTRA_ACCEL, [t_col, q, v, Qc], N, session)

    @property
    def _zero_force(self) -> NDArray[np.float64]:
        return np.zeros(self.n_q)

    def consistent_state(self, t: ArrayLike, y: NDArray[np.float64],
                         generalized_force: NDArray[np.float64] | None = None, session: Any = None,
                         project: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Keep q and v of ``y``; recompute multipliers and derivatives so that F(t, y, y') = 0.

        ``y`` is one state (n_states,) or many (N, n_states) with ``t`` of shape (N,).
        ``project`` (GGL restarts): first put q and v exactly on the constraint manifold, mu = 0.
        (index-1 restarts keep their Baumgarte-controlled drift: the chapter's formulation, and
        restarted twins of a run must follow it; see ``stats["max_constraint_drift"]``.)
        """
        n, m = self.n_q, self.n_constraints
        y = np.array(y, dtype=float)
        single = y.ndim == 1
        y2 = np.atleast_2d(y)
        if self.formulation == "ggl" and m and single and project:
            # restart on the constraint manifold with mu = 0, its exact value: GGL holds Phi and
            # Phi' only to Newton's tolerance, and a restart at a tight rtol must not inherit that
            t0 = float(np.ravel(t)[0])
            y2[0, :n] = self.assemble_positions(y2[0, :n], t0, session=session)
            y2[0, n:2 * n] = self.assemble_velocities(y2[0, :n], y2[0, n:2 * n], t0, session=session)
            y2[0, 2 * n + m:2 * n + 2 * m] = 0.0
        q, v = y2[:, :n], y2[:, n:2 * n]
        sol = self._accel_solution(t, q, v, generalized_force, session)
        yp = np.zeros_like(y2)
        yp[:, :n] = v
        yp[:, n:2 * n] = sol[:, :n]
        y2[:, 2 * n:2 * n + m] = sol[:, n:n + m]
        if self.track_work:
            yp[:, -1] = sol[:, n + m]
        if self.formulation == "ggl" and m:
            mu = y2[:, 2 * n + m:2 * n + 2 * m]
            N = y2.shape[0]
            t_arr = np.broadcast_to(np.atleast_1d(np.asarray(t, dtype=float)), (N,))
            flat = self.evaluate(EXTRA_KINEMATICS, [q, v, t_arr.reshape(N, 1)], N, session)
            Phi_q = flat[:, m:m + m * n].reshape(N, n, m).transpose(0, 2, 1)
            yp[:, :n] = v - np.einsum("kmn,km->kn", Phi_q, mu)
        return (y2[0], yp[0]) if single else (y2, yp)

    def initial_state(self, session: Any = None, start: str = "ideal", allow_penetration: bool = False
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Consistent (y0, yp0) at t = 0: assembled positions and velocities, then v' and lam.

        ``start="ideal"`` (the chapter's, section 4.4): positions and velocities assembled on the
        mechanism whose clearance joints are ideal (journals centred in their bearings, sliders
        on their guides' mid-lines, every velocity from the kinematics of that mechanism);
        ``"declared"``: the bodies' declared state, corrected only for the scene's ideal joints.
        With an open compiled ``session`` every evaluation runs in C. A declared start with a contact
        pair in deep penetration raises AssemblyError unless ``allow_penetration``
        (:func:`daeclear.solvers.physics.check_start_penetration`)."""
        ideal = start == "ideal"
        q = self.assemble_positions(self.q_guess, session=session, ideal=ideal)
        check_independent(self, q, session)
        v = self.assemble_velocities(q, self.v_guess, session=session, ideal=ideal)
        y = np.zeros(self.n_states)
        y[: self.n_q] = q
        y[self.n_q: 2 * self.n_q] = v
        y, yp = self.consistent_state(0.0, y, session=session)
        if not ideal and not allow_penetration:
            check_start_penetration(self, y, yp, session)
        return y, yp

    def switch_vector(self, active: Sequence[bool], params: Sequence[NDArray[np.float64]]) -> NDArray[np.float64]:
        """The contact terms' on/off flags and parameters as the outputs' ``switch`` input."""
        parts: list[NDArray[np.float64]] = []
        for on, p in zip(active, params):
            parts += [np.array([1.0 if on else 0.0]), np.asarray(p, dtype=float).ravel()]
        return np.concatenate(parts) if parts else np.zeros(0)

    def channels(self, t: NDArray[np.float64], y: NDArray[np.float64], yp: NDArray[np.float64],
                 switch: NDArray[np.float64] | None = None, session: Any = None) -> dict[str, NDArray[np.float64]]:
        """Evaluate every output channel at the rows of ``y`` and ``yp`` (time first).

        ``switch`` holds one row per time of :meth:`switch_vector` (contact terms' modes).
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if t.size == 0:
            return {name: np.zeros(0) for name in self.channel_names}
        n_s = self.outputs.size1_in(3)
        S = np.zeros((t.size, n_s)) if switch is None else np.asarray(switch, dtype=float).reshape(t.size, n_s)
        values = self.evaluate(EXTRA_OUTPUTS, [t.reshape(-1, 1), np.asarray(y), np.asarray(yp), S], t.size, session)
        return {name: np.ascontiguousarray(values[:, i]) for i, name in enumerate(self.channel_names)}


# ---- element parameters (numbers) and builders (structure) --------------------------------

def _revolute_parameters(ref: Reference, joint: Revolute) -> dict[str, Any]:
    s_i, s_j = ref.joint_points(joint)
    return {"s_i": s_i, "s_j": s_j}


def _revolute(ctx: AssemblyContext, joint: Revolute) -> tuple[list[Any], list[str]]:
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    d = bi.point(ctx.p(joint.name, "s_i")) - bj.point(ctx.p(joint.name, "s_j"))
    return [d[0], d[1]], [f"{joint.name}.x", f"{joint.name}.y"]


def _translational_parameters(ref: Reference, joint: Translational) -> dict[str, Any]:
    s_i, s_j = ref.joint_points(joint)
    u_local = ref.local_vector(joint.body_i, joint.axis)  # axis in body i's frame
    return {"s_i": s_i, "s_j": s_j, "normal": [-u_local[1], u_local[0]],
            "angle0": ref.angle(joint.body_j) - ref.angle(joint.body_i)}


def _translational(ctx: AssemblyContext, joint: Translational) -> tuple[list[Any], list[str]]:
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    n_world = ca.mtimes(rotation(bi.phi), ctx.p(joint.name, "normal"))
    d = bj.point(ctx.p(joint.name, "s_j")) - bi.point(ctx.p(joint.name, "s_i"))
    lateral = ca.dot(n_world, d)
    relative_angle = bj.phi - bi.phi - ctx.p(joint.name, "angle0")
    return [lateral, relative_angle], [f"{joint.name}.lateral", f"{joint.name}.angle"]


def scene_parameters(scene: Scene, formulation: str, alpha: float, beta: float,
                     track_work: bool) -> tuple[ParameterTable, str]:
    """The scene's numbers as run-time parameters, and the key of its structure.

    Pure Python (no CasADi): this is all that a scene of a known structure costs to assemble.
    """
    ref = Reference(scene.bodies, GROUND)
    table = ParameterTable()
    if formulation == "index1":
        table.add("baumgarte.alpha", alpha)
        table.add("baumgarte.beta", beta)
    table.add("gravity", scene.gravity)
    structure: list[Any] = [formulation, bool(track_work), _ENGINE_VERSION]
    joints = {j.name: j for j in scene.joints}
    for element in scene.elements:
        if isinstance(element, Body):
            table.update(element.name, {"mass": element.mass, "inertia": element.inertia})
        elif isinstance(element, Revolute):
            table.update(element.name, _revolute_parameters(ref, element))
        elif isinstance(element, Translational):
            table.update(element.name, _translational_parameters(ref, element))
        elif isinstance(element, Driver):
            table.update(element.name, driver_parameters(ref, element, joints[element.joint]))
        elif isinstance(element, Load):
            table.update(element.name, load_parameters(ref, element))
        elif type(element) in CONTACT_BUILDERS:
            values, flags = CONTACT_BUILDERS[type(element)][0](ref, element)
            table.update(element.name, values)
            structure.append([element.name, flags])
        else:
            raise AssemblyError(f"{element.kind} '{element.name}': element type not supported by assemble().")
    structure.append(table.layout)
    described = scene.to_dict()
    described.pop("name")  # the scene's name is no part of its structure
    for element in scene.elements:  # fields whose effect the structure flags state
        for field_name in element.NOT_STRUCTURE:
            described["elements"][element.name].pop(field_name, None)
    return table, structure_key(described, structure)


@dataclass(frozen=True)
class _Template:
    """What of an assembled model depends on the structure only, shared by every scene with that
    structure: the model built for the first such scene, and how its numbers are bound."""

    model: DAEModel  # the structure, with the numbers of the scene it was built from
    layout: tuple[tuple[str, int], ...]
    logic: tuple[Callable[[NDArray[np.float64]], list[Any]], ...]
    # (root, term, gap-rate extra, needs approach speed, index of the contact logic) of simple pairs
    auto_pairs: tuple[tuple[int, int, int, bool, int], ...]

    def bind(self, scene: Scene, table: ParameterTable, alpha: float, beta: float) -> "DAEModel":
        if table.layout != self.layout:  # a structure key collision would land here
            raise AssemblyError(f"scene '{scene.name}': its parameters do not match the cached structure.")
        P = table.vector
        P.setflags(write=False)
        bodies = scene.bodies
        contacts = tuple(logic for make in self.logic for logic in make(P))
        auto_pairs = tuple((root, term, extra, needs, float(getattr(contacts[i], "min_approach_speed", 0.0)))
                           for root, term, extra, needs, i in self.auto_pairs)
        formulation, track_work = self.model.formulation, self.model.track_work
        return dataclasses.replace(
            self.model, scene_name=scene.name, alpha=float(alpha), beta=float(beta),
            q_guess=np.concatenate([[*b.position, b.angle] for b in bodies]),
            v_guess=np.concatenate([[*b.velocity, b.angular_velocity] for b in bodies]),
            mass_diagonal=np.concatenate([[b.mass, b.mass, b.inertia] for b in bodies]),
            parameters={"scene": scene.to_dict(), "formulation": formulation, "alpha": alpha, "beta": beta,
                        "track_work": track_work},
            contacts=contacts, auto_pairs=auto_pairs, parameter_layout=self.layout, parameter_values=P,
            clearance_joints=tuple((e.name, float(e.radial_clearance), float(getattr(e, "corner_radius", 0.0)))
                                   for e in scene.elements if type(e) in CONTACT_BUILDERS),
        )


# Templates built in this process, by structure key (a scene that differs only in numbers
# reuses one: no CasADi work, and the same compiled library).
_TEMPLATES: dict[str, _Template] = memo_table()
_TEMPLATE_LIMIT = 64
# Part of every structure key: bump when the generated functions change meaning.
_ENGINE_VERSION = "engine-2"


def assemble(scene: Scene, formulation: str = DEFAULT_FORMULATION, *, alpha: float = 5.0, beta: float = 5.0,
             track_work: bool = False) -> DAEModel:
    """Assemble a validated scene into a :class:`DAEModel`.

    Only the scene's structure (bodies, joints, clearance joints and their laws) is built
    symbolically, once per process; every number is run-time parameter data
    (``model.parameter_values``), so scenes that differ only in numbers share the symbolic
    functions and the compiled library.

    Parameters
    ----------
    scene : Scene
        The mechanism; validated first (all problems reported at once).
    formulation : {"ggl", "index1"}
        ``ggl`` (the default): stabilised index-2, drift-free in positions and velocities;
        ``index1``: acceleration-level constraints with Baumgarte stabilisation (the chapter's,
        Tables 4.2 and 4.3; the only one the non-IDA methods integrate).
    alpha, beta : float
        Baumgarte parameters of ``index1`` (1/s), 5 and 5 by default (Table 4.2).
    track_work : bool
        Add the state ``work.input``: the work done on the mechanism by drivers, contact
        forces and loads (daeclear.loads; springs' elastic energy is potential energy),
        W' = driver power + contact power + load power, integrated with the equations (kept out of
        the error test, so it does not change the solution). ``energy.mechanical - work`` is then
        conserved up to the integration error: channel ``energy.work``.

    Returns
    -------
    DAEModel

    Raises
    ------
    SceneError
        Invalid scene or argument.
    AssemblyError
        Redundant constraints, unsupported elements or joints that cannot close.
    """
    formulation = str(formulation).lower()
    if formulation not in FORMULATIONS:
        raise SceneError(f"formulation={formulation!r}, must be one of {', '.join(FORMULATIONS)}.")
    for label, value in (("alpha", alpha), ("beta", beta)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise SceneError(f"{label}={value!r} 1/s, must be a finite number >= 0.")
    table, key = _validated_parameters(scene, formulation, alpha, beta, bool(track_work))
    template = _TEMPLATES.get(key)
    if template is None:
        template = _build_template(scene, formulation, bool(track_work), table, f"mechanism_{key[:16]}")
        if len(_TEMPLATES) >= _TEMPLATE_LIMIT:
            _TEMPLATES.pop(next(iter(_TEMPLATES)))
        _TEMPLATES[key] = template
    return template.bind(scene, table, alpha, beta)


# Constraint rows are dependent when the constraint Jacobian's singular value falls below RANK_TOL
# times its largest one (its entries are 1 and lever arms of 1 mm..1 m; round-off is ~1e-16).
RANK_TOL = 1e-9
# a row takes part in a dependency when its weight in a left null vector of the Jacobian is above this
NULL_WEIGHT = 1e-6


def check_independent(model: DAEModel, q: NDArray[np.float64], session: Any = None) -> None:
    """Raise AssemblyError when the constraint Jacobian is rank deficient at the initial positions ``q``.

    Redundant constraints (a joint that repeats what others already impose, a second driver of a
    one-degree-of-freedom mechanism) make the multipliers undetermined: IDA would fail at t = 0 with
    a singular matrix and unrelated advice. The message names the joints and drivers whose rows are
    dependent. Called by :meth:`DAEModel.initial_state` once the positions are assembled.
    """
    m, n = model.n_constraints, model.n_q
    if not m:
        return
    Phi_q = model.constraints(np.asarray(q, dtype=float), np.zeros(n), 0.0, session)[1]
    if not np.all(np.isfinite(Phi_q)):
        return  # not a rank question: the positions themselves are unusable (reported when they are assembled)
    U, sigma, _ = np.linalg.svd(Phi_q)
    scale = float(sigma[0]) if sigma.size else 0.0
    rank = int(np.sum(sigma > RANK_TOL * scale))
    if rank >= m:
        return
    null = U[:, rank:]
    rows = [i for i in range(m) if np.linalg.norm(null[i]) > NULL_WEIGHT]
    owners = model.constraint_elements or tuple(name.rsplit(".", 1)[0] for name in model.constraint_names)
    involved = list(dict.fromkeys(owners[i] for i in rows))

    def independent_without(element: str) -> bool:
        keep = [i for i in range(m) if owners[i] != element]
        if not keep:
            return True
        s_keep = np.linalg.svd(Phi_q[keep], compute_uv=False)
        return int(np.sum(s_keep > RANK_TOL * scale)) == len(keep)

    fixes = [e for e in involved if independent_without(e)]
    equations = ", ".join(model.constraint_names[i] for i in rows)
    advice = (f"Removing any one of {', '.join(repr(e) for e in fixes)} leaves independent constraints."
              if fixes else "Remove the joints or drivers that repeat what the others impose.")
    raise AssemblyError(
        f"scene '{model.scene_name}': redundant constraints: {', '.join(repr(e) for e in involved)} impose "
        f"dependent conditions (equations {equations}); the constraint Jacobian at the initial positions has "
        f"rank {rank} for {m} equations on {n} coordinates, so their reaction forces are undetermined and the run "
        f"cannot start. {advice} (A joint meant to have play can be a clearance joint.) If the mechanism is not "
        "over-constrained, the initial positions are a singular configuration (e.g. two links aligned): start it "
        "from another position.")


# Scenes assembled before in this process: (elements, name, gravity, ground, options) -> their
# parameters and structure key. The entry holds the very element objects (frozen dataclasses),
# so an unchanged scene is recognised by identity and a changed one (an element added, replaced,
# gravity or name reassigned) is not; validation and parameters are then skipped.
_SEEN: dict[int, tuple[Any, ...]] = memo_table()
_SEEN_LIMIT = 32


def _validated_parameters(scene: Scene, formulation: str, alpha: float, beta: float,
                          track_work: bool) -> tuple[ParameterTable, str]:
    """``scene.validate()`` then :func:`scene_parameters`, skipped for a scene seen unchanged."""
    elements = tuple(scene.elements)
    identity = (scene.name, tuple(scene.gravity), scene.ground, formulation, alpha, beta, track_work)
    seen = _SEEN.get(id(scene))
    if seen is not None and seen[1] == identity and len(seen[0]) == len(elements) \
            and all(a is b for a, b in zip(seen[0], elements)):
        return seen[2], seen[3]
    scene.validate()
    table, key = scene_parameters(scene, formulation, alpha, beta, track_work)
    if len(_SEEN) >= _SEEN_LIMIT:
        _SEEN.pop(next(iter(_SEEN)))
    _SEEN[id(scene)] = (elements, identity, table, key)
    return table, key


def _build_template(scene: Scene, formulation: str, track_work: bool, table: ParameterTable,
                    library_name: str) -> _Template:
    """The symbolic DAE of the scene's structure, every number a symbol of the parameter vector P."""
    bodies = scene.bodies
    nb = len(bodies)
    n = 3 * nb
    t = ca.SX.sym("t")
    q = ca.SX.sym("q", n)
    v = ca.SX.sym("v", n)
    a = ca.SX.sym("a", n)
    P = ca.SX.sym("P", table.vector.size)
    params = table.symbols(P)

    frames: dict[str, BodyFrame] = {
        GROUND: BodyFrame(GROUND, None, ca.DM.zeros(2), ca.DM(0.0), ca.DM.zeros(2), ca.DM(0.0))
    }
    for k, body in enumerate(bodies):
        frames[body.name] = BodyFrame(body.name, k, q[3 * k:3 * k + 2], q[3 * k + 2], v[3 * k:3 * k + 2], v[3 * k + 2])
    ctx = AssemblyContext(t, q, v, a, P, frames, params, table.offsets())

    # ---- constraints ----
    phi_list: list[Any] = []
    names: list[str] = []
    owners: list[str] = []  # the element of each constraint row
    joints = {j.name: j for j in scene.joints}
    driver_rows: dict[str, int] = {}
    contact_builds: list[Any] = []
    for element in scene.elements:
        if isinstance(element, (Body, Load)):
            continue
        if isinstance(element, Revolute):
            eqs, labels = _revolute(ctx, element)
        elif isinstance(element, Translational):
            eqs, labels = _translational(ctx, element)
        elif isinstance(element, Driver):
            driver_rows[element.name] = len(phi_list)
            eqs, labels = [driver_constraint(ctx, element, joints[element.joint])], [element.name]
        else:  # a clearance joint (scene_parameters rejected anything else)
            first_term = sum(len(b.terms) for b in contact_builds)
            first_root = sum(len(b.gaps) for b in contact_builds)
            contact_builds.append(CONTACT_BUILDERS[type(element)][1](ctx, element, first_term, first_root))
            continue
        phi_list.extend(eqs)
        names.extend(labels)
        owners.extend([element.name] * len(eqs))

    m = len(phi_list)
    Phi = ca.vertcat(*phi_list) if m else ca.SX(0, 1)
    Phi_q = ca.jacobian(Phi, q)
    Phi_t = ca.jacobian(Phi, t)
    Phi_dot = ca.mtimes(Phi_q, v) + Phi_t
    gamma = -(ca.mtimes(ca.jacobian(Phi_dot, q), v) + ca.jacobian(Phi_dot, t))
    kinematics = ca.Function("kinematics", [q, v, t, P], [Phi, ca.densify(Phi_q), Phi_dot, gamma],
                             ["q", "v", "t", "P"], ["Phi", "Phi_q", "Phi_dot", "gamma"])

    # ---- masses and applied forces ----
    g_vec = params["gravity"]
    gx, gy = g_vec[0], g_vec[1]
    mass_diag = ca.vertcat(*[ca.vertcat(params[f"{b.name}.mass"], params[f"{b.name}.mass"],
                                        params[f"{b.name}.inertia"]) for b in bodies])
    Q = ca.vertcat(*[ca.vertcat(params[f"{b.name}.mass"] * gx, params[f"{b.name}.mass"] * gy, 0.0) for b in bodies])
    loads = build_loads(ctx, scene.of_type(Load))  # applied forces, springs, motors (daeclear.loads)
    Q = Q + loads.force + 0 * t  # keep Q symbolic in t for a uniform signature
    base_force = ca.Function("base_force", [t, q, v, P], [Q], ["t", "q", "v", "P"], ["Q"])

    # ---- state vector ----
    lam = ca.SX.sym("lam", m)
    lam_p = ca.SX.sym("lam_p", m)
    q_p = ca.SX.sym("q_p", n)
    body_state = [f"{b.name}.{c}" for b in bodies for c in ("x", "y", "phi")]
    body_rate = [f"{b.name}.{c}" for b in bodies for c in ("vx", "vy", "omega")]
    state_names = body_state + body_rate + [f"lambda.{c}" for c in names]
    kinds = [KIND_POSITION] * n + [KIND_VELOCITY] * n + [KIND_MULTIPLIER] * m
    eom = mass_diag * a + ca.mtimes(Phi_q.T, lam) - Q
    if formulation == "index1":
        alpha, beta = params["baumgarte.alpha"], params["baumgarte.beta"]
        y = ca.vertcat(q, v, lam)
        yp = ca.vertcat(q_p, a, lam_p)
        res = ca.vertcat(q_p - v, eom, ca.mtimes(Phi_q, a) - gamma + 2 * alpha * Phi_dot + beta**2 * Phi)
    else:
        mu = ca.SX.sym("mu", m)
        mu_p = ca.SX.sym("mu_p", m)
        y = ca.vertcat(q, v, lam, mu)
        yp = ca.vertcat(q_p, a, lam_p, mu_p)
        res = ca.vertcat(q_p - v + ca.mtimes(Phi_q.T, mu), eom, Phi_dot, Phi)
        state_names += [f"mu.{c}" for c in names]
        kinds += [KIND_MULTIPLIER] * m
    drive_power = sum((-lam[row] * ca.mtimes(Phi_q[row, :], v) for row in driver_rows.values()), ca.SX(0.0))
    # Multipliers from (t, q, v) and extra generalized forces Fc, by the Schur complement of the
    # KKT system [M Phi_q^T; Phi_q 0][a; lam] = [Q + Fc; c] (M is diagonal). Used for consistent
    # states and for the work rate, which must not depend on IDA's unconverged multipliers.
    Minv = 1.0 / mass_diag
    rhs_c = gamma - 2 * alpha * Phi_dot - beta**2 * Phi if formulation == "index1" else gamma
    Fc = ca.SX.sym("Fc", n)
    if m:
        PMinv = Phi_q * ca.repmat(Minv.T, m, 1)  # Phi_q M^-1
        lam_sol = ca.solve(ca.mtimes(PMinv, Phi_q.T), ca.mtimes(PMinv, Q + Fc) - rhs_c)
    else:
        lam_sol = ca.SX(0, 1)
    a_sol = Minv * (Q + Fc - ca.mtimes(Phi_q.T, lam_sol))
    drive_power_of = ca.substitute(drive_power, lam, lam_sol) if m else ca.SX(0.0)  # linear in Fc
    drive_power_base = ca.substitute(drive_power_of, Fc, ca.SX.zeros(n))
    if track_work:
        W, W_p = ca.SX.sym("W"), ca.SX.sym("W_p")
        y, yp = ca.vertcat(y, W), ca.vertcat(yp, W_p)
        res = ca.vertcat(res, W_p - drive_power_base - loads.power)
        state_names.append("work.input")
        kinds.append(KIND_WORK)
    n_y = y.numel()
    cj = ca.SX.sym("cj")
    residual = ca.Function("residual", [t, y, yp, P], [res], ["t", "y", "yp", "P"], ["r"])
    jac = ca.jacobian(res, y) + cj * ca.jacobian(res, yp)
    jacobian = ca.Function("jacobian", [t, y, yp, cj, P], [jac], ["t", "y", "yp", "cj", "P"], ["J"])

    # ---- contact terms: generalized forces added to the equations of motion rows ----
    terms: list[Term] = []
    term_res: list[ca.Function] = []
    term_jac: list[ca.Function] = []
    gaps: list[Any] = []
    gap_names: list[str] = []
    contact_channels: list[Channel] = []
    switch_syms: list[Any] = []  # per term: on/off flag and parameters, inputs of the outputs
    power_channels: list[Any] = []
    for build in contact_builds:
        switches = []
        for term in build.terms:
            ident = _c_identifier(term.name)
            on_k, p_k = ca.SX.sym(f"{ident}_on"), ca.SX.sym(f"{ident}_p", term.n_params)
            switches.append((on_k, p_k))
            switch_syms += [on_k, p_k]
        contact_channels.extend(build.channels(switches))
        for term, (on_k, p_k) in zip(build.terms, switches):
            # power of the contact force on the mechanism (energy balance: dE/dt = sum of powers)
            power = ca.if_else(on_k > 0, ca.dot(term.force(t, q, v, p_k, P), v), 0.0)  # 0 (not NaN) when off
            contact_channels.append(Channel(f"{term.name}.power", "W", power))
            power_channels.append(power)
        for term in build.terms:
            p = ca.SX.sym("p", term.n_params)
            Qk = term.force(t, q, v, p, P)
            # the term's share of the work rate: its own power and the driver power it causes
            work_row = [-(ca.dot(Qk, v) + ca.substitute(drive_power_of, Fc, Qk) - drive_power_base)] if track_work else []
            r_k = ca.vertcat(ca.SX.zeros(n), -Qk, ca.SX.zeros(n_y - 2 * n - len(work_row)), *work_row)
            ident = _c_identifier(term.name)  # term names may hold dots (channel names); C may not
            term_res.append(ca.Function(f"{ident}_res", [t, y, yp, p, P], [r_k], ["t", "y", "yp", "p", "P"], ["r"]))
            j_k = ca.jacobian(r_k, y) + cj * ca.jacobian(r_k, yp)
            term_jac.append(ca.Function(f"{ident}_jac", [t, y, yp, p, cj, P], [j_k],
                                        ["t", "y", "yp", "p", "cj", "P"], ["J"]))
            terms.append(term)
        gaps.extend(build.gaps)
        gap_names.extend(build.gap_names)
    roots = None
    if gaps:
        roots = ca.Function("roots", [t, y, yp, P], [ca.vertcat(*gaps)], ["t", "y", "yp", "P"], ["g"])

    # ---- output channels ----
    channels: list[Channel] = []
    for k, b in enumerate(bodies):
        sl = slice(3 * k, 3 * k + 3)
        qk, vk, ak = q[sl], v[sl], a[sl]
        channels += [
            Channel(f"{b.name}.x", "m", qk[0]), Channel(f"{b.name}.y", "m", qk[1]),
            Channel(f"{b.name}.phi", "rad", qk[2]),
            Channel(f"{b.name}.vx", "m/s", vk[0]), Channel(f"{b.name}.vy", "m/s", vk[1]),
            Channel(f"{b.name}.omega", "rad/s", vk[2]),
            Channel(f"{b.name}.ax", "m/s^2", ak[0]), Channel(f"{b.name}.ay", "m/s^2", ak[1]),
            Channel(f"{b.name}.alpha", "rad/s^2", ak[2]),
        ]
    for name, row in driver_rows.items():
        # The driver's constraint enters body j's equation of its coordinate with +lam; the moment
        # (force along the axis) it applies to body j is therefore -lam (positive counter-clockwise).
        load, unit = driver_load(joints[scene[name].joint])
        channels.append(Channel(f"{name}.{load}", unit, -lam[row]))
        power_d = -lam[row] * ca.mtimes(Phi_q[row, :], v)  # load times relative (angular) speed
        channels.append(Channel(f"{name}.power", "W", power_d))
        power_channels.append(power_d)
    kinetic = 0.5 * ca.dot(mass_diag, v * v)
    potential = -sum(params[f"{b.name}.mass"] * (gx * q[3 * k] + gy * q[3 * k + 1]) for k, b in enumerate(bodies))
    potential = potential + loads.potential  # the springs' elastic energy
    if loads.channels:
        power_channels.append(loads.power)  # the loads' non-conservative power
    channels += [
        Channel("energy.kinetic", "J", kinetic),
        Channel("energy.potential", "J", potential),
        Channel("energy.mechanical", "J", kinetic + potential),
    ]
    if power_channels:  # drivers and contact forces: the rate of change of the mechanical energy
        channels.append(Channel("energy.input_power", "W", sum(power_channels)))
    if track_work:
        channels.append(Channel("energy.work", "J", y[n_y - 1]))
    if m:
        channels += [
            Channel("constraints.position", "m", ca.mmax(ca.fabs(Phi))),
            Channel("constraints.velocity", "m/s", ca.mmax(ca.fabs(Phi_dot))),
        ]
    channels += contact_channels + list(loads.channels)
    switch = ca.vertcat(*switch_syms) if switch_syms else ca.SX(0, 1)
    outputs = ca.Function("outputs", [t, y, yp, switch, P], [ca.vertcat(*[c.expr for c in channels])],
                          ["t", "y", "yp", "switch", "P"], ["channels"])
    # accelerations, multipliers (and work rate) from (t, q, v, contact forces) as generated code:
    # consistent states at restarts and at every reported point cost ~1 us
    work_rate = [drive_power_of + ca.dot(Fc, v) + loads.power] if track_work else []
    accel = ca.Function("accel", [t, q, v, Fc, P], [ca.densify(ca.vertcat(a_sol, lam_sol, *work_rate))],
                        ["t", "q", "v", "Qc", "P"], ["a_lam"])
    kinematics_flat = ca.Function("kinematics_flat", [q, v, t, P],
                                  [ca.densify(ca.vertcat(Phi, ca.vec(Phi_q), Phi_dot))], ["q", "v", "t", "P"], ["K"])
    start_list = phi_list + [c for build in contact_builds for c in build.ideal]
    start_names = tuple(names) + tuple(label for build in contact_builds for label in build.ideal_names)
    Phi_s = ca.vertcat(*start_list) if start_list else ca.SX(0, 1)
    Phi_s_q = ca.jacobian(Phi_s, q)
    Phi_s_dot = ca.mtimes(Phi_s_q, v) + ca.jacobian(Phi_s, t)
    start_flat = ca.Function("start_kinematics_flat", [q, v, t, P],
                             [ca.densify(ca.vertcat(Phi_s, ca.vec(Phi_s_q), Phi_s_dot))], ["q", "v", "t", "P"], ["K"])
    extras = [outputs, accel, kinematics_flat, start_flat] + [term.force for term in terms]
    # simple contact pairs whose switches the compiled loop may handle itself (see ida_driver.c)
    logic_makers = tuple(build.logic for build in contact_builds)
    sample = [logic for make in logic_makers for logic in make(table.vector)]
    auto_pairs = []
    simple = [getattr(logic, "simple_pairs", lambda: None)() for logic in sample]
    if sample and all(pairs is not None for pairs in simple):
        for index, pairs in enumerate(simple):
            for root, term_index, gap_rate, needs, _floor in pairs:
                extras.append(gap_rate)
                auto_pairs.append((root, term_index, len(extras) - 1, needs, index))
    functions = DAEFunctions(
        n=n_y, residual=residual, jacobian=jacobian, term_residuals=tuple(term_res),
        term_jacobians=tuple(term_jac), roots=roots, name=library_name, extras=tuple(extras),
        n_parameters=int(P.numel()),
    )
    model = DAEModel(
        scene_name=scene.name, formulation=formulation, alpha=0.0, beta=0.0,
        body_names=tuple(b.name for b in bodies), constraint_names=tuple(names),
        state_names=tuple(state_names), state_kinds=tuple(kinds), functions=functions,
        terms=tuple(terms), gap_names=tuple(gap_names),
        channel_names=tuple(c.name for c in channels), channel_units={c.name: c.unit for c in channels},
        outputs=outputs, q_guess=np.zeros(n), v_guess=np.zeros(n), mass_diagonal=np.ones(n),
        kinematics=kinematics, base_force=base_force, track_work=track_work, start_constraint_names=start_names,
        constraint_elements=tuple(owners), driver_names=tuple(driver_rows),
    )  # numbers are bound per scene (_Template.bind)
    return _Template(model=model, layout=table.layout, logic=logic_makers, auto_pairs=tuple(auto_pairs))


def _run_copy(logic: Any) -> Any:
    """A contact logic object for one run: a shallow copy whose lists (pair states, faces) and
    buffered functions (their input and output arrays) are its own."""
    fresh = copy.copy(logic)
    for name, value in vars(logic).items():
        if isinstance(value, list):
            setattr(fresh, name, list(value))
        elif isinstance(value, BufferedFunction):
            setattr(fresh, name, copy.copy(value))  # a new buffer (BufferedFunction.__setstate__)
    return fresh


def _read_only(values: ArrayLike) -> NDArray[np.float64]:
    """``values`` as a read-only float array (copied unless it already is one)."""
    array = np.asarray(values, dtype=float)
    if array.flags.writeable:
        array = array.copy()
        array.setflags(write=False)
    return array


def _mapped(function: ca.Function, n: int) -> ca.Function:
    """``function`` evaluated column-wise on n points (the function itself when n == 1; building a
    map costs about 0.1 ms, which matters on the per-event path)."""
    return function if n == 1 else function.map(n)


def _c_identifier(name: str) -> str:
    ident = "".join(ch if ch.isalnum() else "_" for ch in name)
    return ident if ident and not ident[0].isdigit() else f"m_{ident}"
