"""The assembled mechanism, :class:`DAEModel`: its compiled functions and what a solver asks of them.

The state layout (``y = [q, v, lam]`` for ``index1``, ``[q, v, lam, mu]`` for ``ggl``; equations in
:mod:`daeclear.assembly.assemble`, which builds the model), consistent states, contact forces and
output channels at many points.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Protocol
from collections.abc import Mapping, Sequence

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..engine.build import memo_put_bounded
from ..engine.compiled import CompiledDAE
from ..engine.session_base import DAEFunctions, StateLayout
from ..core.errors import AssemblyError, SceneError
from ..model.scene import Scene
from .contact_pairs import PairLogic
from .physics import check_start_penetration, checked_channel
from .parameter_names import scene_names
from .symbolic import Term

if TYPE_CHECKING:
    from .assemble import Structure

Formulation = Literal["index1", "ggl"]

# Extra functions compiled with the model (DAEFunctions.extras). kinematics: (q, v, t) -> [Phi; Phi_q
# (column-major); Phi_dot]; start kinematics: the same with the clearance joints' ideal joints; checks: the
# channels the physics checks read; term k's force: EXTRA_TERM0 + k
EXTRA_OUTPUTS, EXTRA_ACCEL, EXTRA_KINEMATICS, EXTRA_START_KINEMATICS, EXTRA_CHECKS, EXTRA_TERM0 = 0, 1, 2, 3, 4, 5


# Projection onto the constraint manifold: |Phi| < POSITION_TOL * max(1, |q|) within NEWTON_STEPS steps.
POSITION_TOL = 1e-13
NEWTON_STEPS = 50

# State kinds: how each state variable is treated by the solver's error test.
KIND_POSITION, KIND_VELOCITY, KIND_MULTIPLIER, KIND_WORK = "q", "v", "lambda", "work"


class ExtrasEvaluator(Protocol):
    """What a model asks of an open session (the ``session`` arguments of its methods): the compiled
    library's evaluation of ``functions.extras[k]`` at many points (``Session.eval_extra``)."""

    def eval_extra(self, k: int, inputs: Sequence[NDArray[np.float64]], n_points: int) -> NDArray[np.float64]: ...


#: A structure's consistent starts already found (:meth:`DAEModel.initial_state`): (y0, yp0, the warning
#: of replaced velocities or "") by (start, allow_penetration, evaluator, numbers, guesses).
StartMemo = dict[tuple[str, bool, str, bytes, bytes, bytes], tuple[NDArray[np.float64], NDArray[np.float64], str]]


@dataclass(frozen=True)
class DAEModel:
    """An assembled mechanism, a value: its :class:`~daeclear.assembly.assemble.Structure` (the CasADi
    functions and names, shared by every scene of that structure) and the numbers of one scene bound to it
    (the run-time parameters ``parameter_values`` and what follows from them).

    Made by :func:`~daeclear.assembly.assemble.assemble` (and :meth:`with_parameters`); frozen, its arrays
    read-only; it keeps nothing: what a process keeps of a structure (compiled libraries, consistent
    starts) is its structure's. ``print(model)`` summarises its sizes.
    """

    structure: Structure
    scene: Scene = field(compare=False, repr=False)  # the model's own copy of the scene whose numbers are bound
    alpha: float  # Baumgarte's constants (numbers of index1 only)
    beta: float
    # run-time parameters, the last input of every function: one entry per parameter_layout row
    parameter_values: NDArray[np.float64]
    q_guess: NDArray[np.float64]  # the bodies' declared positions and velocities
    v_guess: NDArray[np.float64]
    mass_diagonal: NDArray[np.float64]
    parameters: dict[str, Any]  # the scene's description and the options
    contacts: tuple[PairLogic, ...]  # contact elements' event rules (clearance joints; no run state)
    # (root, term, gap-rate extra, needs approach speed, min approach speed) of simple pairs
    auto_pairs: tuple[tuple[int, int, int, bool, float], ...]
    # (name, clearance m, corner radius m or 0) of each clearance joint: the limits of the physics checks
    clearance_joints: tuple[tuple[str, float, float], ...]

    def __post_init__(self) -> None:
        for name in _ARRAY_FIELDS:
            object.__setattr__(self, name, _read_only(getattr(self, name)))

    def with_parameters(self, values: Mapping[str, Any]) -> DAEModel:
        """A new model with new numbers, compiling nothing:
        ``model.with_parameters({"clearance.clearance": 2e-4, "clearance.law.restitution": 0.5})``.

        Names are the scene's values (:meth:`daeclear.Scene.with_values`) and, for ``index1``,
        ``"baumgarte.alpha"`` and ``"baumgarte.beta"``; the changed elements are made again from their
        fields and validated. Raises SceneError for an unknown name, a bad value, or a change of the
        structure (e.g. friction on a frictionless joint): assemble that scene instead."""
        if not isinstance(values, Mapping):
            raise SceneError(f"with_parameters: values={values!r}, must be a mapping of names to numbers, "
                             "e.g. {'clearance.clearance': 2e-4}.")
        return self.structure.rebind(self, values)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """The model's numbers by their scene names: exactly what :meth:`with_parameters`,
        ``simulate(parameters=)`` and sweeps accept (:mod:`daeclear.assembly.parameter_names`)."""
        return self._names()[0]

    @property
    def structural_names(self) -> tuple[str, ...]:
        """The scene's values that are structure (text, flags, counts, a baked law's numbers): read-only."""
        return self._names()[1]

    def _names(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        if self.scene is None:  # a model not made by assemble(): its table is all it has
            return tuple(name for name, _ in self.parameter_layout), ()
        return scene_names(self.scene, self.formulation, frozenset(name for name, _ in self.parameter_layout))

    def parameter(self, name: str) -> NDArray[np.float64]:
        """The value of one entry of the compiled parameter table, e.g. ``model.parameter("clearance.clearance")``
        (a scene's number, or one derived from them such as ``"clearance.s_i"``)."""
        offset = 0
        for key, size in self.parameter_layout:
            if key == name:
                return self.parameter_values[offset:offset + size].copy()
            offset += size
        raise KeyError(f"no parameter {name!r}; the model's table has {', '.join(k for k, _ in self.parameter_layout)}")

    @property
    def n_q(self) -> int:
        return len(self.body_names) * 3

    @property
    def n_constraints(self) -> int:
        return len(self.constraint_names)

    @property
    def n_states(self) -> int:
        return len(self.state_names)

    # ---- the structure's, read through the model

    @property
    def scene_name(self) -> str:
        return self.scene.name

    @property
    def formulation(self) -> str:
        return self.structure.formulation

    @property
    def track_work(self) -> bool:
        return self.structure.track_work

    @property
    def functions(self) -> DAEFunctions:
        """The CasADi functions of the structure (P their last input)."""
        return self.structure.functions

    @property
    def compiled(self) -> CompiledDAE:
        """What this process compiled and loaded of the functions: the structure's, shared by its models."""
        return self.structure.compiled

    @property
    def body_names(self) -> tuple[str, ...]:
        return self.structure.body_names

    @property
    def constraint_names(self) -> tuple[str, ...]:
        return self.structure.constraint_names

    @property
    def start_constraint_names(self) -> tuple[str, ...]:
        """The constraints of the chapter's start: the ideal joints, then each clearance joint's ideal joint."""
        return self.structure.start_constraint_names

    @property
    def constraint_elements(self) -> tuple[str, ...]:
        """The scene element of each constraint row."""
        return self.structure.constraint_elements

    @property
    def driver_names(self) -> tuple[str, ...]:
        return self.structure.driver_names

    @property
    def has_loads(self) -> bool:
        """Loads besides gravity."""
        return self.structure.has_loads

    @property
    def state_names(self) -> tuple[str, ...]:
        return self.structure.state_names

    @property
    def state_kinds(self) -> tuple[str, ...]:
        return self.structure.state_kinds

    @property
    def terms(self) -> tuple[Term, ...]:
        return self.structure.terms

    @property
    def gap_names(self) -> tuple[str, ...]:
        return self.structure.gap_names

    @property
    def kink_terms(self) -> tuple[int, ...]:
        """The term of each friction kink, the roots a run with sensitivities watches after the gaps."""
        return self.structure.kink_terms

    @property
    def kink_pairs(self) -> tuple[str, ...]:
        """The pair (or face) of each friction kink: its term's name."""
        return tuple(self.structure.terms[k].name for k in self.structure.kink_terms)

    @property
    def channel_names(self) -> tuple[str, ...]:
        return self.structure.channel_names

    @property
    def channel_units(self) -> Mapping[str, str]:
        return self.structure.channel_units

    @property
    def outputs(self) -> ca.Function:
        """(t, y, yp, switch, P) -> channel values; switch: see :meth:`switch_vector`."""
        return self.structure.outputs

    @property
    def kinematics(self) -> ca.Function:
        """(q, v, t, P) -> (Phi, Phi_q, Phi_dot, gamma)."""
        return self.structure.kinematics

    @property
    def base_force(self) -> ca.Function:
        """(t, q, v, P) -> Q (gravity and applied loads)."""
        return self.structure.base_force

    @property
    def parameter_layout(self) -> tuple[tuple[str, int], ...]:
        """(name, size) of each entry of ``parameter_values``."""
        return self.structure.layout

    @property
    def start_parameters(self) -> NDArray[np.intp]:
        """The parameters the chapter's start depends on: its memo key's numbers (:func:`start_parameters`)."""
        return self.structure.start_parameters

    def layout(self, project: bool) -> StateLayout:
        """The state layout and the extras of consistent states, for the compiled loop; ``project``:
        restarts on the constraint manifold."""
        return StateLayout(
            n_q=self.n_q, n_constraints=self.n_constraints, ggl=self.formulation == "ggl", track_work=self.track_work,
            accel_extra=EXTRA_ACCEL, force_extra0=EXTRA_TERM0, kinematics_extra=EXTRA_KINEMATICS,
            outputs_extra=EXTRA_OUTPUTS, project=project, tol=POSITION_TOL, max_iter=NEWTON_STEPS,
            n_channels=len(self.channel_names))

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

    def constraints(self, q: NDArray[np.float64], v: NDArray[np.float64], t: float,
                    session: ExtrasEvaluator | None = None, ideal: bool = False
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(Phi, Phi_q, Phi_dot) at one state, through the compiled library when a session is open;
        ``ideal``: with the ideal joints of the clearance joints added (the chapter's start)."""
        m, n = (len(self.start_constraint_names), self.n_q) if ideal else (self.n_constraints, self.n_q)
        flat = self.evaluate(EXTRA_START_KINEMATICS if ideal else EXTRA_KINEMATICS, [q, v, np.array([t])], 1,
                             session)[0]
        return flat[:m], flat[m:m + m * n].reshape(n, m).T, flat[m + m * n:]

    def assemble_positions(self, q_guess: NDArray[np.float64], t: float = 0.0, tol: float = POSITION_TOL,
                           max_iter: int = NEWTON_STEPS, session: ExtrasEvaluator | None = None, ideal: bool = False
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
                            t: float = 0.0, session: ExtrasEvaluator | None = None, ideal: bool = False
                            ) -> NDArray[np.float64]:
        """Least-norm correction of ``v_guess`` so that Phi_q v + Phi_t = 0 (``ideal``: as above)."""
        v = np.array(v_guess, dtype=float)
        if not (self.start_constraint_names if ideal else self.constraint_names):
            return v
        _, Phi_q, Phi_dot = self.constraints(q, v, t, session, ideal)
        dv, *_ = np.linalg.lstsq(Phi_q, -Phi_dot, rcond=None)
        return v + dv

    def evaluate(self, k: int, inputs: Sequence[NDArray[np.float64]], n_points: int,
                 session: ExtrasEvaluator | None = None) -> NDArray[np.float64]:
        """Evaluate ``functions.extras[k]`` at ``n_points`` points (inputs (n_points, size) or (size,)),
        in C with an open compiled ``session``, else CasADi; the parameters are appended as last input."""
        if session is not None:
            return session.eval_extra(k, inputs, n_points)
        f = self.functions.extras[k]
        inputs = [*inputs, self.parameter_values]
        cols = [np.zeros((0, n_points)) if f.numel_in(j) == 0 else
                np.broadcast_to(np.asarray(x, dtype=float).reshape(-1, f.numel_in(j)), (n_points, f.numel_in(j))).T
                for j, x in enumerate(inputs)]
        # a map costs ~0.1 ms to build: none for one point (the per-event path)
        return np.array((f if n_points == 1 else f.map(n_points))(*cols)).reshape(-1, n_points).T

    def term_forces(self, t: ArrayLike, y: NDArray[np.float64], active: Sequence[bool],
                    params: Sequence[NDArray[np.float64]], session: ExtrasEvaluator | None = None
                    ) -> NDArray[np.float64] | None:
        """Sum of the generalized forces of the active terms at one state (n_states,) or many (N, n_states)."""
        if not any(active):
            return None
        n = self.n_q
        y2 = np.atleast_2d(y)
        N = y2.shape[0]
        t_col = _time_column(t, N)
        total = np.zeros((N, n))
        for k, (on, p) in enumerate(zip(active, params)):
            if on:
                total += self.evaluate(EXTRA_TERM0 + k, [t_col, y2[:, :n], y2[:, n:2 * n], np.asarray(p, dtype=float)],
                                       N, session)
        return total[0] if np.ndim(y) == 1 else total

    def term_forces_rows(self, t: NDArray[np.float64], y: NDArray[np.float64], switch: NDArray[np.float64],
                         session: ExtrasEvaluator | None = None) -> NDArray[np.float64] | None:
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
                inputs = [t[rows].reshape(-1, 1), y[rows, :n], y[rows, n:2 * n], P]
                total[rows] += self.evaluate(EXTRA_TERM0 + k, inputs, rows.size, session)
            off += 1 + term.n_params
        return total

    def accelerations(self, t: ArrayLike, q: NDArray[np.float64], v: NDArray[np.float64],
                      generalized_force: NDArray[np.float64] | None = None, session: ExtrasEvaluator | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Solve [M Phi_q^T; Phi_q 0] [v'; lam] = [Q + generalized_force; c] for v' and lam, at one state
        or many ((N, n), ``t`` of shape (N,)); ``c = gamma - 2 alpha Phi' - beta^2 Phi`` (index1) or
        ``gamma`` (ggl)."""
        single = np.ndim(q) == 1
        n, m = self.n_q, self.n_constraints
        sol = self._accel_solution(t, np.atleast_2d(q), np.atleast_2d(v), generalized_force, session)
        a, lam = sol[:, :n], sol[:, n:n + m]
        return (a[0], lam[0]) if single else (a, lam)

    def _accel_solution(self, t: ArrayLike, q: NDArray, v: NDArray, generalized_force: NDArray | None,
                        session: ExtrasEvaluator | None) -> NDArray[np.float64]:
        """[a, lam(, work rate)] per row, from the generated Schur-complement solve."""
        Qc = np.zeros(self.n_q) if generalized_force is None else generalized_force
        return self.evaluate(EXTRA_ACCEL, [_time_column(t, q.shape[0]), q, v, Qc], q.shape[0], session)

    def consistent_state(self, t: ArrayLike, y: NDArray[np.float64],
                         generalized_force: NDArray[np.float64] | None = None, session: ExtrasEvaluator | None = None,
                         project: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Keep q and v of ``y`` (one state or (N, n_states)); recompute multipliers and derivatives so
        that F(t, y, y') = 0. ``project`` (GGL restarts): first put q and v on the constraint manifold,
        mu = 0 (index-1 restarts keep their Baumgarte-controlled drift, the chapter's formulation)."""
        n, m = self.n_q, self.n_constraints
        y = np.array(y, dtype=float)
        single = y.ndim == 1
        y2 = np.atleast_2d(y)
        if self.formulation == "ggl" and m and single and project:
            # GGL holds Phi and Phi' only to Newton's tolerance: a restart at a tight rtol must not inherit that
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
            flat = self.evaluate(EXTRA_KINEMATICS, [q, v, _time_column(t, N)], N, session)
            Phi_q = flat[:, m:m + m * n].reshape(N, n, m).transpose(0, 2, 1)
            yp[:, :n] = v - np.einsum("kmn,km->kn", Phi_q, mu)
        return (y2[0], yp[0]) if single else (y2, yp)

    def initial_state(self, session: ExtrasEvaluator | None = None, start: str = "ideal",
                      allow_penetration: bool = False) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Consistent (y0, yp0) at t = 0: assembled positions and velocities, then v' and lam.

        ``start="ideal"`` (section 4.4): assembled with the clearance joints ideal (journals centred,
        sliders on their mid-lines); ``"declared"``: the bodies' declared state, corrected for the ideal
        joints only; with a pair in deep penetration it raises AssemblyError unless ``allow_penetration``."""
        ideal = start == "ideal"
        # a declared start is checked against the gaps (penetration): every number is in its key
        numbers = self.parameter_values[self.start_parameters] if ideal else self.parameter_values
        key = (start, bool(allow_penetration), "casadi" if session is None else type(session).__name__,
               numbers.tobytes(), self.q_guess.tobytes(), self.v_guess.tobytes())
        starts = self.structure.starts
        known = starts.get(key)
        if known is None:
            q = self.assemble_positions(self.q_guess, session=session, ideal=ideal)
            check_independent(self, q, session)
            v = self.assemble_velocities(q, self.v_guess, session=session, ideal=ideal)
            y, yp = self.consistent_state(0.0, np.concatenate([q, v, np.zeros(self.n_states - 2 * self.n_q)]),
                                          session=session)
            if not ideal and not allow_penetration:
                check_start_penetration(self, y, yp, session)
            # the declared velocities the clearance joints' ideal joints change (start="declared" keeps them)
            replaced = replaced_velocities(self, v, self.assemble_velocities(q, self.v_guess, session=session)) \
                if ideal else ""
            known = (_read_only(y), _read_only(yp), replaced)
            memo_put_bounded(starts, key, known, START_MEMO_LIMIT)
        if known[2]:
            import warnings

            from ..core.errors import DaeclearWarning

            warnings.warn(known[2], DaeclearWarning, stacklevel=4)
        return known[0].copy(), known[1].copy()

    def switch_vector(self, active: Sequence[bool], params: Sequence[NDArray[np.float64]]) -> NDArray[np.float64]:
        """The contact terms' on/off flags and parameters as the outputs' ``switch`` input."""
        values: list[float] = []  # plain floats, one array at the end: this runs at every contact switch
        for on, p in zip(active, params):
            values.append(1.0 if on else 0.0)
            values.extend(np.asarray(p, dtype=float).ravel().tolist())
        return np.array(values, dtype=float)

    def channels(self, t: NDArray[np.float64], y: NDArray[np.float64], yp: NDArray[np.float64],
                 switch: NDArray[np.float64] | None = None, session: ExtrasEvaluator | None = None
                 ) -> dict[str, NDArray[np.float64]]:
        """Every output channel at the rows of ``y`` and ``yp``; ``switch`` holds one
        :meth:`switch_vector` per row (contact terms' modes; None: all off)."""
        return self._rows(EXTRA_OUTPUTS, self.channel_names, t, y, yp, switch, session)

    @property
    def checked_names(self) -> tuple[str, ...]:
        """The channels the physics checks read (:func:`daeclear.assembly.physics.checked_channel`), in order."""
        return tuple(name for name in self.channel_names if checked_channel(name))

    def checks(self, t: NDArray[np.float64], y: NDArray[np.float64], switch: NDArray[np.float64],
               session: ExtrasEvaluator | None = None) -> dict[str, NDArray[np.float64]]:
        """The channels the physics checks read (as :meth:`channels`, bit for bit), without the others:
        penetrations and position constraints, functions of q alone (zeros go in for the yp input)."""
        return self._rows(EXTRA_CHECKS, self.checked_names, t, y, np.zeros(self.n_states), switch, session)

    def _rows(self, k: int, names: tuple[str, ...], t: ArrayLike, y: ArrayLike, yp: ArrayLike,
              switch: ArrayLike | None, session: ExtrasEvaluator | None) -> dict[str, NDArray[np.float64]]:
        """The channels ``names`` of the outputs' extra ``k`` at the rows of ``y`` and ``yp``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if t.size == 0 or not names:
            return {name: np.zeros(t.size) for name in names}
        n_s = self.outputs.size1_in(3)
        S = np.zeros((t.size, n_s)) if switch is None else np.asarray(switch, dtype=float).reshape(t.size, n_s)
        values = self.evaluate(k, [t.reshape(-1, 1), np.asarray(y), np.asarray(yp), S], t.size, session)
        return {name: np.ascontiguousarray(values[:, i]) for i, name in enumerate(names)}


# Starts kept per structure (Structure.starts, see DAEModel.initial_state); a start is ~0.3 ms to compute again.
START_MEMO_LIMIT = 256


def start_parameters(functions: DAEFunctions) -> NDArray[np.intp]:
    """Indices of the run-time parameters the chapter's start reads (the kinematics' and the
    accelerations' dependencies, from CasADi's sparsity): no clearance, radius or law number."""
    used = np.zeros(functions.n_parameters, dtype=bool)
    for k in (EXTRA_ACCEL, EXTRA_KINEMATICS, EXTRA_START_KINEMATICS):
        f = functions.extras[k]
        used |= np.asarray(f.which_depends(f.name_in(f.n_in() - 1), f.name_out(), 1, False), dtype=bool)
    index = np.flatnonzero(used)
    index.setflags(write=False)
    return index


# Constraint rows are dependent below RANK_TOL times the Jacobian's largest singular value
RANK_TOL = 1e-9
# a row takes part in a dependency when its weight in a left null vector of the Jacobian is above this
NULL_WEIGHT = 1e-6


#: A declared body velocity counts as replaced by the ideal start when it moves by more than this fraction of it.
REPLACED_VELOCITY = 1e-6


def replaced_velocities(model: DAEModel, ideal: NDArray[np.float64], declared: NDArray[np.float64]) -> str:
    """The warning that the chapter's start changed declared velocities, or "": each body whose non-zero declared
    velocity (as ``start="declared"`` would start it, ``declared``) the start ``ideal`` changed (its clearance
    joints' ideal joints constrain it: a free journal declared moving starts with its bearing). A velocity they
    leave free is kept; a body declared at rest takes its kinematics silently (the chapter's start)."""
    guess = np.asarray(model.v_guess, dtype=float)
    linear = np.ones(guess.size, dtype=bool)
    linear[2::3] = False
    scales = {"m/s": float(np.max(np.abs(declared[linear]), initial=0.0)),
              "rad/s": float(np.max(np.abs(declared[~linear]), initial=0.0))}  # round-off is relative to these
    changed = []
    for k, body in enumerate(model.body_names):
        for part, name, unit in ((slice(3 * k, 3 * k + 2), "velocity", "m/s"),
                                 (slice(3 * k + 2, 3 * k + 3), "angular_velocity", "rad/s")):
            d, s = declared[part], ideal[part]
            if np.any(guess[part] != 0.0) and np.max(np.abs(s - d)) > REPLACED_VELOCITY * scales[unit]:
                shown = ", ".join(f"{x:.6g}" for x in d)
                started = ", ".join(f"{x:.6g}" for x in s)
                if d.size > 1:
                    shown, started = f"({shown})", f"({started})"
                changed.append(f"Body '{body}': {name}={shown} {unit} declared, started at {started} {unit}")
    if not changed:
        return ""
    return ("simulate: the chapter's start (start='ideal': every clearance joint as its ideal joint, centred) "
            f"changed declared velocities: {'; '.join(changed)}. SolverOptions(start='declared') keeps them.")


def check_independent(model: DAEModel, q: NDArray[np.float64], session: ExtrasEvaluator | None = None) -> None:
    """Raise AssemblyError, naming the joints and drivers involved, when the constraint Jacobian is rank
    deficient at the initial positions ``q`` (redundant constraints: undetermined multipliers)."""
    m, n = model.n_constraints, model.n_q
    if not m:
        return
    Phi_q = model.constraints(np.asarray(q, dtype=float), np.zeros(n), 0.0, session)[1]
    if not np.all(np.isfinite(Phi_q)):
        return  # not a rank question: the positions themselves are unusable (reported when they are assembled)
    sigma = np.linalg.svd(Phi_q, compute_uv=False)  # the singular vectors only when there is a null space
    scale = float(sigma[0]) if sigma.size else 0.0
    rank = int(np.sum(sigma > RANK_TOL * scale))
    if rank >= m:
        return
    null = np.linalg.svd(Phi_q)[0][:, rank:]
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


def _time_column(t: ArrayLike, n: int) -> NDArray[np.float64]:
    """``t`` as a column of n times (one time repeated, or n of them)."""
    t_arr = np.asarray(t, dtype=float)
    return t_arr.reshape(n, 1) if t_arr.size == n else np.full((n, 1), float(t_arr.ravel()[0]))


_ARRAY_FIELDS = ("q_guess", "v_guess", "mass_diagonal", "parameter_values")


def _read_only(values: ArrayLike) -> NDArray[np.float64]:
    """``values`` as a read-only float array (copied unless it already is one)."""
    array = np.asarray(values, dtype=float)
    if array.flags.writeable:
        array = array.copy()
        array.setflags(write=False)
    return array
