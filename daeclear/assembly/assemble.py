"""Scene -> DAEModel: the symbolic equations of motion, built once per structure with CasADi.

State ``y = [q, v, lam]`` (``index1``, the chapter's) or ``[q, v, lam, mu]`` (``ggl``, the default);
ideal joints and drivers are constraints ``Phi(q, t) = 0``, clearance joints add switched force
terms. The equations of both formulations: docs/engine.md ("Formulations").
"""

from __future__ import annotations

import math
from types import MappingProxyType
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable, Mapping

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..engine.build import memo_put_bounded, memo_table
from ..engine.compiled import CompiledDAE
from ..core.errors import AssemblyError, SceneError
from ..model.elements import kept_with
from ..engine.session_base import DAEFunctions
from ..core.options import DEFAULT_FORMULATION, FORMULATIONS
from .parameters import ParameterTable, entries, structure_key
from .parameter_names import BAUMGARTE_NAMES, is_numbers, scene_names
from ..model.scene import (GROUND, Body, Driver, Revolute, RevoluteClearance, Scene, Translational,
                           TranslationalClearance)
from .revolute_joint import CONTACT_BUILDERS
from .drivers import driver_constraint, driver_load, driver_parameters
from .joint_coordinates import joint_channels
from ..model.loads import Load, load_parameters
from .load_terms import build_loads
from .contact_pairs import PairLogic
from .symbolic import AssemblyContext, Channel, Reference, Term, body_frames, rotation
from .physics import checked_channel
from .dae_model import (EXTRA_TERM0, KIND_MULTIPLIER, KIND_POSITION, KIND_VELOCITY, KIND_WORK,  # noqa: F401
                        DAEModel, StartMemo, start_parameters)


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
                     track_work: bool) -> tuple[ParameterTable, str, Mapping[str, Any]]:
    """The scene's numbers as run-time parameters, its structure key and its plain-data description.

    Pure Python: all that a scene of a known structure costs to assemble. Each element's entries are
    kept on it (with the bodies they were read from), so a sweep's shared elements are converted once.
    """
    bodies = tuple(scene.bodies)
    ref = Reference(bodies, GROUND)
    table = ParameterTable()
    if formulation == "index1":
        table.add("baumgarte.alpha", alpha)
        table.add("baumgarte.beta", beta)
    table.add("gravity", scene.gravity)
    structure: list[Any] = [formulation, bool(track_work), _ENGINE_VERSION, table.layout]
    joints = {j.name: j for j in scene.joints}
    by_name = {b.name: b for b in bodies}
    for element in scene.elements:
        named, shape = kept_with(element, "_parameter_entries", _read_objects(element, by_name, joints),
                                 lambda e: _element_parameters(ref, e, joints))
        table.extend(named)
        structure.append(shape)
    return table, structure_key(scene.elements, structure), scene.description()


def _read_objects(element: Any, bodies: Mapping[str, Body], joints: Mapping[str, Any]) -> tuple[Any, ...]:
    """The frozen objects an element's parameters are read from besides itself: the bodies it joins or
    loads (their reference poses), a driver's joint and that joint's bodies; a body reads none. So each
    element compares a few objects to reuse its kept entries, and a scene's set-up grows like N, not N^2."""
    if isinstance(element, Body):
        return ()
    if isinstance(element, Driver):
        joint = joints[element.joint]
        return (joint, *_read_objects(joint, bodies, joints))
    if hasattr(element, "body_roles"):
        names = [name for _, name in element.body_roles()]
    elif hasattr(element, "body_i") and hasattr(element, "body_j"):
        names = [element.body_i, element.body_j]
    else:
        return tuple(bodies.values())
    return tuple(bodies[name] for name in names if name in bodies)  # the ground's pose is fixed


def _element_parameters(ref: Reference, element: Any, joints: dict[str, Any]
                        ) -> tuple[tuple[tuple[str, tuple[float, ...]], ...], str]:
    """One element's parameter entries, and as text its structure: the entries' names and sizes and a
    clearance joint's structural flags."""
    flags = None
    if isinstance(element, Body):
        values = {"mass": element.mass, "inertia": element.inertia}
    elif isinstance(element, Revolute):
        values = _revolute_parameters(ref, element)
    elif isinstance(element, Translational):
        values = _translational_parameters(ref, element)
    elif isinstance(element, Driver):
        values = driver_parameters(ref, element, joints[element.joint])
    elif isinstance(element, Load):
        values = load_parameters(ref, element)
    elif type(element) in CONTACT_BUILDERS:
        values, flags = CONTACT_BUILDERS[type(element)][0](ref, element)
    else:
        raise AssemblyError(f"{element.kind} '{element.name}': element type not supported by assemble().")
    named = entries(element.name, values)
    sizes = ",".join([f"{name}:{len(value)}" for name, value in named])
    return named, "\x02".join([element.name, repr(flags), sizes])


@dataclass(frozen=True, eq=False, repr=False)
class Structure:
    """What of an assembled model depends on its structure only, built once per structure key and shared by
    every model it binds (:meth:`bind`): the CasADi functions (every number a symbol of ``P``), the names,
    and how a scene's numbers bind to them.

    The one owner of what a process keeps of a structure: what its functions were compiled and loaded into
    (``compiled``) and the consistent starts already found (``starts``, see :meth:`DAEModel.initial_state`).
    Not a value (compared by identity): the process's table of structures and its models hold it.
    """

    key: str  # the structure key (:func:`daeclear.assembly.parameters.structure_key`)
    formulation: str
    track_work: bool
    functions: DAEFunctions
    body_names: tuple[str, ...]
    constraint_names: tuple[str, ...]
    # constraints of the chapter's start: the ideal joints, then each clearance joint's ideal joint
    start_constraint_names: tuple[str, ...]
    constraint_elements: tuple[str, ...]  # the scene element of each constraint row
    driver_names: tuple[str, ...]
    has_loads: bool  # loads besides gravity
    state_names: tuple[str, ...]
    state_kinds: tuple[str, ...]
    terms: tuple[Term, ...]
    gap_names: tuple[str, ...]
    channel_names: tuple[str, ...]
    channel_units: Mapping[str, str]
    outputs: ca.Function  # (t, y, yp, switch, P) -> channel values
    kinematics: ca.Function  # (q, v, t, P) -> (Phi, Phi_q, Phi_dot, gamma)
    base_force: ca.Function  # (t, q, v, P) -> Q (gravity and applied loads)
    layout: tuple[tuple[str, int], ...]  # (name, size) of each entry of P
    # the parameters the chapter's start reads (its memo key's numbers, :func:`start_parameters`)
    start_parameters: NDArray[np.intp]
    logic: tuple[Callable[[NDArray[np.float64]], list[PairLogic]], ...]
    # (root, term, gap-rate extra, needs approach speed, index of the contact logic) of simple pairs
    auto_pairs: tuple[tuple[int, int, int, bool, int], ...]
    # the term of each friction kink (``DAEFunctions.kinks``: roots of a run with sensitivities only)
    kink_terms: tuple[int, ...] = ()
    compiled: CompiledDAE = field(init=False, repr=False)  # made empty here, filled by the engine when used
    starts: StartMemo = field(default_factory=dict, repr=False)  # bounded: START_MEMO_LIMIT

    def __post_init__(self) -> None:
        object.__setattr__(self, "compiled", CompiledDAE(self.functions))

    def __repr__(self) -> str:
        return (f"<Structure {self.key[:16]} ({self.formulation}): {len(self.state_names)} states, "
                f"{len(self.terms)} terms, {len(self.starts)} starts kept, {self.compiled!r}>")

    def bind(self, scene: Scene, table: ParameterTable, described: Mapping[str, Any], alpha: float,
             beta: float) -> DAEModel:
        """The model of ``scene`` (whose numbers are ``table``, its description ``described``) on this structure."""
        if not table.has_layout(*zip(*self.layout)):  # a structure key collision would land here
            raise AssemblyError(f"scene '{scene.name}': its parameters do not match the cached structure.")
        P = _fixed(table.vector)
        bodies = scene.bodies
        contacts = tuple(logic for make in self.logic for logic in make(P))
        auto_pairs = tuple((root, term, extra, needs, float(contacts[i].min_approach_speed))
                           for root, term, extra, needs, i in self.auto_pairs)
        return DAEModel(
            structure=self, alpha=float(alpha), beta=float(beta),
            # its own copy of the (mutable) scene
            scene=Scene(scene.name, gravity=scene.gravity, elements=list(scene.elements), ground=scene.ground),
            q_guess=_fixed([x for b in bodies for x in (*b.position, b.angle)]),
            v_guess=_fixed([x for b in bodies for x in (*b.velocity, b.angular_velocity)]),
            mass_diagonal=_fixed([x for b in bodies for x in (b.mass, b.mass, b.inertia)]),
            parameters={"scene": described, "formulation": self.formulation, "alpha": alpha, "beta": beta,
                        "track_work": self.track_work},
            contacts=contacts, auto_pairs=auto_pairs, parameter_values=P,
            clearance_joints=tuple((e.name, float(e.radial_clearance), float(getattr(e, "corner_radius", 0.0)))
                                   for e in scene.elements
                                   if isinstance(e, (RevoluteClearance, TranslationalClearance))
                                   and type(e) in CONTACT_BUILDERS),
        )

    def rebind(self, model: DAEModel, values: Mapping[str, Any]) -> DAEModel:
        """``model`` with some of its scene's numbers replaced (:meth:`DAEModel.with_parameters`)."""
        values = dict(values)
        table_names = frozenset(name for name, _ in model.parameter_layout)
        settable, structural = scene_names(model.scene, model.formulation, table_names,  # the named elements only
                                           frozenset(str(name).split(".")[0] for name in values))
        for name in values:
            if name in settable:
                continue
            nested = any(n.startswith(f"{name}.") for n in (*settable, *structural))
            if name in structural or nested or not is_numbers(values[name]):
                raise SceneError(f"with_parameters: {name!r} is structure of the model (read-only: a new value would "
                                 "change the structure of the model); set its numbers by their names (model."
                                 "parameter_names), or assemble the changed scene: "
                                 "assemble(model.scene.with_values(...)).")
            if name in BAUMGARTE_NAMES:  # even its own value: it would mean nothing
                raise SceneError(f"with_parameters: {name}={values[name]!r}, must be left out: Baumgarte's constants "
                                 f"are numbers of the index1 formulation and this model is {model.formulation} "
                                 "(assemble(scene, formulation='index1') to set them).")
            model.scene.with_values({name: values[name]})  # an unknown name: its error names the element or field
            raise SceneError(f"with_parameters: {name!r} is not one of the model's numbers: this scene leaves it to be "
                             "derived (None); give it in the scene and assemble it (nothing compiles): "
                             "assemble(model.scene.with_values(...)).")
        alpha = float(values.pop("baumgarte.alpha", model.alpha))
        beta = float(values.pop("baumgarte.beta", model.beta))
        _check_baumgarte(alpha, beta)
        alpha, beta = float(alpha), float(beta)
        scene = model.scene.with_values(values)
        table, key, described = scene_parameters(scene, model.formulation, alpha, beta, model.track_work)
        if key != self.key:
            raise SceneError(f"with_parameters: {', '.join(map(repr, values))} change the structure of the model "
                             "(which terms and laws it has, not only their numbers: e.g. friction on a "
                             "frictionless joint, or a number of a law that is compiled in); assemble the "
                             "changed scene instead: assemble(model.scene.with_values(...)).")
        return self.bind(scene, table, described, alpha, beta)


def _fixed(values: list[float] | NDArray[np.float64]) -> NDArray[np.float64]:
    """``values`` (a list, or a float array made for this model) as a read-only float array: the model
    keeps it as it is."""
    array = np.asarray(values, dtype=float)
    array.setflags(write=False)
    return array


# Structures built in this process, by structure key.
_STRUCTURES: dict[str, Structure] = memo_table()
_STRUCTURE_LIMIT = 64
# Part of every structure key: bump when the generated functions change meaning.
_ENGINE_VERSION = "engine-3"


def assemble(scene: Scene, formulation: str = DEFAULT_FORMULATION, *, alpha: float | None = None,
             beta: float | None = None, track_work: bool = False) -> DAEModel:
    """Assemble a validated scene into a :class:`DAEModel`.

    Only the scene's structure is built symbolically, once per process; every number is run-time
    data (``model.parameter_values``), so scenes that differ only in numbers share the compiled library.

    Parameters
    ----------
    scene : Scene
        The mechanism; validated first (all problems reported at once).
    formulation : {"ggl", "index1"}
        ``ggl`` (default): stabilised index 2, drift-free; ``index1``: acceleration-level constraints
        with Baumgarte stabilisation (Tables 4.2-4.3; the only one the non-IDA methods integrate).
    alpha, beta : float or None
        Baumgarte parameters of ``index1`` (1/s), None: 5 and 5 (Table 4.2); refused with ``ggl``, which has none.
    track_work : bool
        Add the state ``work.input`` (channel ``energy.work``): the work of drivers, contact forces and
        loads, integrated out of the error test; ``energy.mechanical - work`` is then conserved.

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
        if value is not None and formulation != "index1":
            raise SceneError(f"assemble: {label}={value!r}, must be left out with formulation={formulation!r}: "
                             "Baumgarte's constants are numbers of the index1 formulation.")
    alpha = BAUMGARTE if alpha is None else alpha
    beta = BAUMGARTE if beta is None else beta
    _check_baumgarte(alpha, beta)
    scene.validate()
    table, key, described = scene_parameters(scene, formulation, alpha, beta, bool(track_work))
    structure = _STRUCTURES.get(key)
    if structure is None:
        structure = _build_template(scene, formulation, bool(track_work), table, key)
        memo_put_bounded(_STRUCTURES, key, structure, _STRUCTURE_LIMIT)
    return structure.bind(scene, table, described, alpha, beta)


#: Baumgarte's alpha and beta of the index1 formulation unless given (1/s, Table 4.2).
BAUMGARTE = 5.0


def _check_baumgarte(alpha: Any, beta: Any) -> None:
    for label, value in (("alpha", alpha), ("beta", beta)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise SceneError(f"{label}={value!r} 1/s, must be a finite number >= 0.")


def _build_template(scene: Scene, formulation: str, track_work: bool, table: ParameterTable,
                    key: str) -> Structure:
    """The symbolic DAE of the scene's structure, every number a symbol of the parameter vector P."""
    build = _TemplateBuilder(scene, formulation, track_work, table, key)
    build.constraints()
    build.forces()
    build.equations()
    build.contact_terms()
    build.output_channels()
    return build.template()


class _TemplateBuilder:
    """The steps of :func:`_build_template`, one method each, in order; each step's symbols are
    attributes the later steps read."""

    def __init__(self, scene: Scene, formulation: str, track_work: bool, table: ParameterTable, key: str) -> None:
        self.scene, self.formulation, self.track_work, self.table, self.key = scene, formulation, track_work, table, key
        self.bodies = scene.bodies
        self.n = n = 3 * len(self.bodies)
        t, q, v, a = ca.SX.sym("t"), ca.SX.sym("q", n), ca.SX.sym("v", n), ca.SX.sym("a", n)
        P = ca.SX.sym("P", table.vector.size)
        self.t, self.q, self.v, self.a, self.P = t, q, v, a, P
        self.params = table.symbols(P)
        frames = body_frames(self.bodies, q, v)
        self.ctx = AssemblyContext(t, q, v, a, P, frames, self.params, table.offsets())
        self.joints = {j.name: j for j in scene.joints}

    def constraints(self) -> None:
        """Ideal joints and drivers as rows of Phi(q, t) = 0; clearance joints as contact builds."""
        ctx, t, q, v, P = self.ctx, self.t, self.q, self.v, self.P
        phi_list: list[Any] = []
        names: list[str] = []
        owners: list[str] = []  # the element of each constraint row
        driver_rows: dict[str, int] = {}
        contact_builds: list[Any] = []
        for element in self.scene.elements:
            if isinstance(element, (Body, Load)):
                continue
            if isinstance(element, Revolute):
                eqs, labels = _revolute(ctx, element)
            elif isinstance(element, Translational):
                eqs, labels = _translational(ctx, element)
            elif isinstance(element, Driver):
                driver_rows[element.name] = len(phi_list)
                eqs, labels = [driver_constraint(ctx, element, self.joints[element.joint])], [element.name]
            else:  # a clearance joint (scene_parameters rejected anything else)
                first_term = sum(len(b.terms) for b in contact_builds)
                first_root = sum(len(b.gaps) for b in contact_builds)
                contact_builds.append(CONTACT_BUILDERS[type(element)][1](ctx, element, first_term, first_root))
                continue
            phi_list.extend(eqs)
            names.extend(labels)
            owners.extend([element.name] * len(eqs))
        self.phi_list, self.names, self.owners = phi_list, names, owners
        self.driver_rows, self.contact_builds = driver_rows, contact_builds
        self.m = m = len(phi_list)
        self.Phi = Phi = ca.vertcat(*phi_list) if m else ca.SX(0, 1)
        self.Phi_q = Phi_q = ca.jacobian(Phi, q)
        Phi_t = ca.jacobian(Phi, t)
        self.Phi_dot = Phi_dot = ca.mtimes(Phi_q, v) + Phi_t
        self.gamma = gamma = -(ca.mtimes(ca.jacobian(Phi_dot, q), v) + ca.jacobian(Phi_dot, t))
        self.kinematics = ca.Function("kinematics", [q, v, t, P], [Phi, ca.densify(Phi_q), Phi_dot, gamma],
                                      ["q", "v", "t", "P"], ["Phi", "Phi_q", "Phi_dot", "gamma"])

    def forces(self) -> None:
        """The diagonal mass matrix and the applied forces Q: gravity and the loads."""
        params, bodies, t, q, v, P = self.params, self.bodies, self.t, self.q, self.v, self.P
        g_vec = params["gravity"]
        self.gx, self.gy = gx, gy = g_vec[0], g_vec[1]
        self.mass_diag = ca.vertcat(*[ca.vertcat(params[f"{b.name}.mass"], params[f"{b.name}.mass"],
                                                 params[f"{b.name}.inertia"]) for b in bodies])
        Q = ca.vertcat(*[ca.vertcat(params[f"{b.name}.mass"] * gx, params[f"{b.name}.mass"] * gy, 0.0)
                         for b in bodies])
        self.loads = build_loads(self.ctx, self.scene.of_type(Load))  # applied forces, springs, motors
        self.Q = Q = Q + self.loads.force + 0 * t  # keep Q symbolic in t for a uniform signature
        self.base_force = ca.Function("base_force", [t, q, v, P], [Q], ["t", "q", "v", "P"], ["Q"])

    def equations(self) -> None:
        """The state vector, the residual of the formulation and its Jacobian; the multipliers and
        accelerations from (t, q, v, Fc) for consistent states and the work rate."""
        t, q, v, a, P, n, m = self.t, self.q, self.v, self.a, self.P, self.n, self.m
        Phi, Phi_q, Phi_dot, gamma, Q, names = self.Phi, self.Phi_q, self.Phi_dot, self.gamma, self.Q, self.names
        lam, lam_p, q_p = ca.SX.sym("lam", m), ca.SX.sym("lam_p", m), ca.SX.sym("q_p", n)
        state_names = ([f"{b.name}.{c}" for b in self.bodies for c in ("x", "y", "phi")]
                       + [f"{b.name}.{c}" for b in self.bodies for c in ("vx", "vy", "omega")]
                       + [f"lambda.{c}" for c in names])
        kinds = [KIND_POSITION] * n + [KIND_VELOCITY] * n + [KIND_MULTIPLIER] * m
        eom = self.mass_diag * a + ca.mtimes(Phi_q.T, lam) - Q
        if self.formulation == "index1":
            alpha, beta = self.params["baumgarte.alpha"], self.params["baumgarte.beta"]
            y = ca.vertcat(q, v, lam)
            yp = ca.vertcat(q_p, a, lam_p)
            res = ca.vertcat(q_p - v, eom, ca.mtimes(Phi_q, a) - gamma + 2 * alpha * Phi_dot + beta**2 * Phi)
        else:
            mu, mu_p = ca.SX.sym("mu", m), ca.SX.sym("mu_p", m)
            y = ca.vertcat(q, v, lam, mu)
            yp = ca.vertcat(q_p, a, lam_p, mu_p)
            res = ca.vertcat(q_p - v + ca.mtimes(Phi_q.T, mu), eom, Phi_dot, Phi)
            state_names += [f"mu.{c}" for c in names]
            kinds += [KIND_MULTIPLIER] * m
        drive_power = sum((-lam[row] * ca.mtimes(Phi_q[row, :], v) for row in self.driver_rows.values()), ca.SX(0.0))
        # Multipliers from (t, q, v, Fc) by the Schur complement of [M Phi_q^T; Phi_q 0][a; lam] = [Q + Fc; c]
        # (M diagonal): consistent states, and a work rate free of IDA's unconverged multipliers
        Minv = 1.0 / self.mass_diag
        rhs_c = gamma - 2 * alpha * Phi_dot - beta**2 * Phi if self.formulation == "index1" else gamma
        self.Fc = Fc = ca.SX.sym("Fc", n)
        if m:
            PMinv = Phi_q * ca.repmat(Minv.T, m, 1)  # Phi_q M^-1
            lam_sol = ca.solve(ca.mtimes(PMinv, Phi_q.T), ca.mtimes(PMinv, Q + Fc) - rhs_c)
        else:
            lam_sol = ca.SX(0, 1)
        self.a_sol, self.lam_sol = Minv * (Q + Fc - ca.mtimes(Phi_q.T, lam_sol)), lam_sol
        self.drive_power_of = ca.substitute(drive_power, lam, lam_sol) if m else ca.SX(0.0)  # linear in Fc
        self.drive_power_base = ca.substitute(self.drive_power_of, Fc, ca.SX.zeros(n))
        if self.track_work:
            W, W_p = ca.SX.sym("W"), ca.SX.sym("W_p")
            y, yp = ca.vertcat(y, W), ca.vertcat(yp, W_p)
            res = ca.vertcat(res, W_p - self.drive_power_base - self.loads.power)
            state_names.append("work.input")
            kinds.append(KIND_WORK)
        self.lam, self.y, self.yp, self.state_names, self.kinds = lam, y, yp, state_names, kinds
        self.n_y = y.numel()
        self.cj = cj = ca.SX.sym("cj")
        self.residual = ca.Function("residual", [t, y, yp, P], [res], ["t", "y", "yp", "P"], ["r"])
        jac = ca.jacobian(res, y) + cj * ca.jacobian(res, yp)
        self.jacobian = ca.Function("jacobian", [t, y, yp, cj, P], [jac], ["t", "y", "yp", "cj", "P"], ["J"])

    def contact_terms(self) -> None:
        """Each contact term's residual and Jacobian, switch inputs, channels and power; the gaps (roots)."""
        t, q, v, P, y, yp, cj = self.t, self.q, self.v, self.P, self.y, self.yp, self.cj
        self.terms: list[Term] = []
        self.term_res: list[ca.Function] = []
        self.term_jac: list[ca.Function] = []
        gaps: list[Any] = []
        self.gap_names: list[str] = []
        kinks: list[Any] = []
        self.kink_terms: list[int] = []
        self.locked_res: list[ca.Function | None] = []  # per term: its residual on one friction piece (Term.locked)
        self.contact_channels: list[Channel] = []
        self.switch_syms: list[Any] = []  # per term: on/off flag and parameters, inputs of the outputs
        self.power_channels: list[Any] = []
        for build in self.contact_builds:
            switches = []
            for term in build.terms:
                ident = _c_identifier(term.name)
                on_k, p_k = ca.SX.sym(f"{ident}_on"), ca.SX.sym(f"{ident}_p", term.n_params)
                switches.append((on_k, p_k))
                self.switch_syms += [on_k, p_k]
            self.contact_channels.extend(build.channels(switches))
            for term, (on_k, p_k) in zip(build.terms, switches):
                # power of the contact force on the mechanism (energy balance: dE/dt = sum of powers)
                power = ca.if_else(on_k > 0, ca.dot(term.force(t, q, v, p_k, P), v), 0.0)  # 0 (not NaN) when off
                self.contact_channels.append(Channel(f"{term.name}.power", "W", power))
                self.power_channels.append(power)
            for term in build.terms:
                p = ca.SX.sym("p", term.n_params)
                r_k = self.term_residual(term.force(t, q, v, p, P))
                ident = _c_identifier(term.name)  # term names may hold dots (channel names); C may not
                p_locked = ca.SX.sym("p", term.n_params + 1)  # [p; piece]
                self.locked_res.append(None if term.locked is None else ca.Function(
                    f"{ident}_locked_res", [t, y, yp, p_locked, P],
                    [self.term_residual(term.locked(t, q, v, p_locked, P))], ["t", "y", "yp", "p", "P"], ["r"]))
                self.term_res.append(ca.Function(f"{ident}_res", [t, y, yp, p, P], [r_k],
                                                 ["t", "y", "yp", "p", "P"], ["r"]))
                j_k = ca.jacobian(r_k, y) + cj * ca.jacobian(r_k, yp)
                self.term_jac.append(ca.Function(f"{ident}_jac", [t, y, yp, p, cj, P], [j_k],
                                                 ["t", "y", "yp", "p", "cj", "P"], ["J"]))
                self.terms.append(term)
            gaps.extend(build.gaps)
            self.gap_names.extend(build.gap_names)
            kinks.extend(build.kinks)
            self.kink_terms.extend(len(self.terms) - len(build.terms) + k for k in build.kink_terms)
        self.roots = None
        if gaps:
            self.roots = ca.Function("roots", [t, y, yp, P], [ca.vertcat(*gaps)], ["t", "y", "yp", "P"], ["g"])
        self.kinks = None
        if kinks:
            self.kinks = ca.Function("kinks", [t, y, yp, P], [ca.vertcat(*kinks)], ["t", "y", "yp", "P"], ["g"])

    def term_residual(self, Qk: Any) -> Any:
        """A term's residual rows from its generalized force: -Qk in the velocity rows, its work rate's row."""
        n, v = self.n, self.v
        # the term's share of the work rate: its own power and the driver power it causes
        work_row = ([-(ca.dot(Qk, v) + ca.substitute(self.drive_power_of, self.Fc, ca.densify(Qk))
                       - self.drive_power_base)] if self.track_work else [])
        return ca.vertcat(ca.SX(n, 1), -Qk, ca.SX(self.n_y - 2 * n - len(work_row), 1), *work_row)  # structural zeros

    def output_channels(self) -> None:
        """The output channels: bodies, drivers, energy, constraints, contacts, loads, joints."""
        q, v, a, params, bodies, gx, gy = self.q, self.v, self.a, self.params, self.bodies, self.gx, self.gy
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
        for name, row in self.driver_rows.items():
            # the constraint enters body j's equation with +lam: the driver's moment (force) on it is -lam
            driver = self.scene[name]
            assert isinstance(driver, Driver)  # driver_rows holds the names of the scene's drivers only
            load, unit = driver_load(self.joints[driver.joint])
            channels.append(Channel(f"{name}.{load}", unit, -self.lam[row]))
            power_d = -self.lam[row] * ca.mtimes(self.Phi_q[row, :], v)  # load times relative (angular) speed
            channels.append(Channel(f"{name}.power", "W", power_d))
            self.power_channels.append(power_d)
        kinetic = 0.5 * ca.dot(self.mass_diag, v * v)
        potential = -sum(params[f"{b.name}.mass"] * (gx * q[3 * k] + gy * q[3 * k + 1]) for k, b in enumerate(bodies))
        potential = potential + self.loads.potential  # the springs' elastic energy
        if self.loads.channels:
            self.power_channels.append(self.loads.power)  # the loads' non-conservative power
        channels += [
            Channel("energy.kinetic", "J", kinetic),
            Channel("energy.potential", "J", potential),
            Channel("energy.mechanical", "J", kinetic + potential),
        ]
        if self.power_channels:  # drivers and contact forces: the rate of change of the mechanical energy
            channels.append(Channel("energy.input_power", "W", sum(self.power_channels)))
        if self.track_work:
            channels.append(Channel("energy.work", "J", self.y[self.n_y - 1]))
        if self.m:
            channels += [
                Channel("constraints.position", "m", ca.mmax(ca.fabs(self.Phi))),
                Channel("constraints.velocity", "m/s", ca.mmax(ca.fabs(self.Phi_dot))),
            ]
        joint_readings = joint_channels(self.ctx, self.scene.joints)  # angles, displacements and their rates
        self.channels = channels + self.contact_channels + list(self.loads.channels) + joint_readings

    def template(self) -> Structure:
        """The generated functions and names of the structure (numbers bound per scene by :meth:`Structure.bind`)."""
        library_name = f"mechanism_{self.key[:16]}"
        t, q, v, P, y, yp, channels = self.t, self.q, self.v, self.P, self.y, self.yp, self.channels
        switch = ca.vertcat(*self.switch_syms) if self.switch_syms else ca.SX(0, 1)
        outputs = ca.Function("outputs", [t, y, yp, switch, P], [ca.vertcat(*[c.expr for c in channels])],
                              ["t", "y", "yp", "switch", "P"], ["channels"])
        # accelerations, multipliers (and work rate) from (t, q, v, contact forces): consistent states
        work_rate = [self.drive_power_of + ca.dot(self.Fc, v) + self.loads.power] if self.track_work else []
        accel = ca.Function("accel", [t, q, v, self.Fc, P],
                            [ca.densify(ca.vertcat(self.a_sol, self.lam_sol, *work_rate))],
                            ["t", "q", "v", "Qc", "P"], ["a_lam"])
        # sparse: the driver scatters extras into dense vectors (Phi_q has a few nonzeros a row)
        kinematics_flat = ca.Function("kinematics_flat", [q, v, t, P],
                                      [ca.vertcat(self.Phi, ca.vec(self.Phi_q), self.Phi_dot)],
                                      ["q", "v", "t", "P"], ["K"])
        builds = self.contact_builds
        start_list = self.phi_list + [c for build in builds for c in build.ideal]
        start_names = tuple(self.names) + tuple(label for build in builds for label in build.ideal_names)
        Phi_s = ca.vertcat(*start_list) if start_list else ca.SX(0, 1)
        Phi_s_q = ca.jacobian(Phi_s, q)
        Phi_s_dot = ca.mtimes(Phi_s_q, v) + ca.jacobian(Phi_s, t)
        start_flat = ca.Function("start_kinematics_flat", [q, v, t, P],
                                 [ca.vertcat(Phi_s, ca.vec(Phi_s_q), Phi_s_dot)],
                                 ["q", "v", "t", "P"], ["K"])
        checked = [c.expr for c in channels if checked_channel(c.name)]
        checks = ca.Function("checks", [t, y, yp, switch, P], [ca.vertcat(*checked) if checked else ca.SX(0, 1)],
                             ["t", "y", "yp", "switch", "P"], ["checked"])
        extras = [outputs, accel, kinematics_flat, start_flat, checks] + [term.force for term in self.terms]
        # simple contact pairs, whose switches the compiled loop may decide itself (ida_driver.c)
        logic_makers = tuple(build.logic for build in builds)
        simple = [logic.simple_pairs() for make in logic_makers for logic in make(self.table.vector)]
        given = [pairs for pairs in simple if pairs is not None]
        auto_pairs = []
        if simple and len(given) == len(simple):
            for index, pairs in enumerate(given):
                for root, term_index, gap_rate, needs, _floor in pairs:
                    extras.append(gap_rate)
                    auto_pairs.append((root, term_index, len(extras) - 1, needs, index))
        functions = DAEFunctions(
            n=self.n_y, residual=self.residual, jacobian=self.jacobian, term_residuals=tuple(self.term_res),
            term_jacobians=tuple(self.term_jac), roots=self.roots, name=library_name, extras=tuple(extras),
            n_parameters=int(P.numel()), kinks=self.kinks,
            locked_residuals=tuple(self.locked_res) if self.kinks is not None else (),
        )
        return Structure(
            key=self.key, formulation=self.formulation, track_work=self.track_work, functions=functions,
            body_names=tuple(b.name for b in self.bodies), constraint_names=tuple(self.names),
            start_constraint_names=start_names, constraint_elements=tuple(self.owners),
            driver_names=tuple(self.driver_rows), has_loads=bool(self.scene.of_type(Load)),
            state_names=tuple(self.state_names), state_kinds=tuple(self.kinds), terms=tuple(self.terms),
            gap_names=tuple(self.gap_names), channel_names=tuple(c.name for c in channels),
            channel_units=MappingProxyType({c.name: c.unit for c in channels}), outputs=outputs,
            kinematics=self.kinematics, base_force=self.base_force, layout=self.table.layout,
            start_parameters=start_parameters(functions), logic=logic_makers,
            auto_pairs=tuple(auto_pairs),
            kink_terms=tuple(self.kink_terms))  # numbers are bound per scene (Structure.bind)


def _c_identifier(name: str) -> str:
    ident = "".join(ch if ch.isalnum() else "_" for ch in name)
    return ident if ident and not ident[0].isdigit() else f"m_{ident}"
