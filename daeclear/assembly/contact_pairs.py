"""Clearance joints as contact elements: symbolic forces, gap functions, channels, event logic.

A clearance joint adds no constraint but *terms* (generalized contact forces, on only while a pair
is in contact), *gaps* (root functions watched by IDA, positive in penetration), *channels* and
*logic* (what a root decides: mode switch, approach speed latched at onset). The event rule, storm
guard included, is :mod:`daeclear.core.automaton`'s (docs/user_guide.md, "Contact events").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable, Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..core.automaton import DEFAULT_STORM, EVENT_KINDS, NONE, Decision, PairState, Storm, start, step
from ..core.events import ContactEvent
from .parameters import law_values, symbolic_law
from .symbolic import AssemblyContext, BufferedFunction, Channel, Reference, Term, perpendicular


#: A contact element's part of a run's contact state: the automaton state of each of its pairs.
PairStates = tuple[PairState, ...]
#: (term index, on, parameters) of each of an element's terms, as its pairs' states make them.
TermSwitch = tuple[int, bool, NDArray[np.float64]]


@dataclass(frozen=True)
class PairLogic:
    """Mode switching of contact pairs, each with one gap (root ``first_root + i``) and one term
    (``pair_terms[i]``). A rule, not a state: the run's pair states
    (:class:`~daeclear.core.automaton.PairState`) are passed in and returned
    (:mod:`daeclear.assembly.contact_state`).

    ``rate`` maps ``(q, v)`` to the gaps and the penetration rates; ``needs_approach``: a term's
    parameter is the approach speed latched at onset. Each root is decided by
    :func:`daeclear.core.automaton.step`; a term is on while its pair is in contact or held.
    """

    pairs: tuple[str, ...]
    first_root: int
    pair_terms: tuple[int, ...]
    rate: BufferedFunction  # (q, v) -> (gaps, penetration rates)
    n_q: int
    needs_approach: bool
    min_approach_speed: float
    discontinuous_friction: bool = False
    storm: Storm = DEFAULT_STORM  # frozen: shared

    @property
    def roots(self) -> range:
        """Indices of the gaps (roots) of this element."""
        return range(self.first_root, self.first_root + len(self.pairs))

    @property
    def n_states(self) -> int:
        """How many pair states this element's part of a run's contact state holds."""
        return len(self.pairs)

    def pair_index(self, root: int) -> int:
        """The pair (index in this element's states) of gap ``root``."""
        return root - self.first_root

    def pair_name(self, root: int) -> str:
        """The name of the pair of gap ``root`` (its events' ``pair``)."""
        return self.pairs[self.pair_index(root)]

    def _evaluate(self, y: NDArray) -> tuple[NDArray, NDArray]:
        gaps, rates = self.rate(y[:self.n_q], y[self.n_q:2 * self.n_q])
        return np.ravel(gaps), np.ravel(rates)

    def _params(self, state: PairState) -> NDArray:
        return np.array([state.latched]) if self.needs_approach else np.zeros(0)

    def start(self, t: float, y: NDArray) -> PairStates:
        """Each pair's state at the start of a run (mode from its gap, rate latched, no history)."""
        gaps, rates = self._evaluate(y)
        return tuple(start(gap > 0.0, float(rate), self.min_approach_speed) for gap, rate in zip(gaps, rates))

    def terms(self, states: PairStates) -> list[TermSwitch]:
        """A term is on in contact or held; its parameter the latched approach speed."""
        return [(k, st.term_on, self._params(st)) for k, st in zip(self.pair_terms, states)]

    def modes(self, states: PairStates) -> dict[str, str]:
        return {p: ("contact" if st.contact else "free") for p, st in zip(self.pairs, states)}

    def root_directions(self, states: PairStates) -> list[tuple[int, int]]:
        """While free watch onsets (+1), in contact separations (-1), held both (0)."""
        return [(self.first_root + i, st.watch) for i, st in enumerate(states)]

    def decide(self, states: PairStates, t: float, y: NDArray, roots_found: NDArray | None
               ) -> tuple[PairStates, list[ContactEvent]]:
        """Decide the roots of the pairs' gaps by the automaton: the new states and the events."""
        if roots_found is None:
            return states, []
        found = roots_found[self.first_root:self.first_root + len(self.pairs)]
        if not np.any(found):
            return states, []
        rates = self._evaluate(y)[1]
        events: list[ContactEvent] = []
        new = list(states)
        for i, direction in enumerate(int(d) for d in found):
            if direction:
                new[i], decision = step(new[i], t, direction, float(rates[i]), storm=self.storm,
                                        min_approach_speed=self.min_approach_speed)
                events += pair_event(self.pairs[i], t, y, float(rates[i]), decision)
        return tuple(new), events

    # ---- what forward sensitivities ask of the rule (docs/sensitivities.md, "Jumps at events")

    @property
    def rate_output(self) -> int:
        """The output of ``rate`` that holds the pairs' penetration rates (the approach speeds latched)."""
        return 1

    def rate_index(self, root: int) -> int:
        """The entry of output :attr:`rate_output` that is the penetration rate of the pair of gap ``root``."""
        return self.pair_index(root)

    def event_roots(self, pair: str, roots_found: NDArray) -> list[int]:
        """The roots found (``roots_found`` != 0) whose crossing made an event of ``pair``: its own gap's."""
        return [root for root in self.roots if roots_found[root] != 0 and self.pair_name(root) == pair]

    def term_sensitivities(self, states: PairStates, latched: Sequence[NDArray]) -> list[tuple[int, NDArray]]:
        """(term, dp_k/dp (n_params_k, Ns)) of each term, as :meth:`terms` makes its parameters from the
        pairs' latched speeds, whose sensitivities are ``latched[i]`` (Ns,) (zeros where floored)."""
        return [(k, np.asarray(S, dtype=float)[None, :] if self.needs_approach else np.zeros((0, np.size(S))))
                for k, S in zip(self.pair_terms, latched)]

    def simple_pairs(self) -> list[tuple[int, int, ca.Function, bool, float]] | None:
        """(root, term, (q, v, P) -> [gap; rate], needs approach speed, floor): the pairs whose
        switches the compiled IDA loop decides itself, by the C mirror of the automaton."""
        fn = self.rate.function
        q, v, P = (ca.SX.sym(label, fn.numel_in(i)) for i, label in enumerate(("q", "v", "P")))
        gaps, rates = fn(q, v, P)
        return [(self.first_root + i, k, ca.Function(f"{pair.replace('.', '_')}_gap_rate", [q, v, P],
                                                      [ca.vertcat(gaps[i], rates[i])]),
                 bool(self.needs_approach), float(self.min_approach_speed))
                for i, (pair, k) in enumerate(zip(self.pairs, self.pair_terms))]


def pair_event(pair: str, t: float, y: NDArray, rate: float, decision: Decision) -> list[ContactEvent]:
    """The event a pair's decision makes (none for NONE)."""
    if decision.kind == NONE:
        return []
    return [ContactEvent(t, pair, EVENT_KINDS[decision.kind], rate, np.array(y, dtype=float))]


@dataclass(frozen=True)
class ContactBuild:
    """What a clearance joint contributes to the assembled model; ``logic(P)`` makes its event logic
    for one parameter vector (each bound model gets its own)."""

    terms: list[Term]
    gaps: list[Any]
    gap_names: list[str]
    channels: Callable[[Sequence[tuple[Any, Any]]], list[Channel]]
    logic: Callable[[NDArray[np.float64]], list[Any]]
    # the constraints of the ideal joint it stands for (the chapter's start), with their names
    ideal: list[Any]
    ideal_names: list[str]
    # the friction laws' kinks as roots (friction_kinks) and the term of each: what a run with sensitivities
    # watches besides the gaps (docs/sensitivities.md, "Kinks")
    kinks: list[Any] = field(default_factory=list)
    kink_terms: list[int] = field(default_factory=list)  # the index in ``terms`` of each kink's term


def approach_floor(ctx: AssemblyContext, law: Any, prefix: str) -> Callable[[NDArray[np.float64]], float]:
    """The law's ``min_approach_speed`` read from a parameter vector (or the baked number)."""
    name = f"{prefix}.min_approach_speed"
    if name in ctx.params:
        index = ctx.offsets[name]
        return lambda P: float(P[index])
    floor = float(getattr(law, "min_approach_speed", 0.0))
    return lambda P: floor


@dataclass(frozen=True)
class JournalContact:
    """A journal in its bearing, eqs. (4.1)-(4.13), for the dry and the lubricated joint: the
    eccentricity and ``force``, (t, q, v, p, P) -> generalized force, ``p`` the latched approach speed."""

    e: Any
    e_dot: Any
    ee: Any
    e_norm: Any
    c: Any
    bi: Any
    bj: Any
    P_i: Any
    P_j: Any
    F_N: Any
    F_T: Any
    v_T: Any
    p: Any
    n_params: int
    force: ca.Function
    # d/dt of the worn surfaces' depth along e (0 unworn): the gap's rate is d|e|/dt minus it
    worn_rate: Any = 0.0
    # a worn joint's contact direction in the bearing's and the journal's frame (rad), for the wear study
    worn_angles: tuple[Any, Any] | None = None
    # the friction law's kinks as roots (friction_kinks; none frictionless or for a smooth law) and the force
    # on one piece of the law (Term.locked)
    kinks: tuple[Any, ...] = ()
    locked: ca.Function | None = None

    @property
    def penetration_rate(self) -> Any:
        """d(delta)/dt along the motion, the worn profile's change under the moving contact included
        (regular at e = 0, where it is 0 unworn)."""
        return ca.dot(self.e_dot, self.e) / ca.fmax(self.e_norm, 1e-300) - self.worn_rate

    def channels(self, name: str, on: Any, p_sym: Any, frictionless: bool) -> list[Channel]:
        """The contact's channels: eccentricity, penetration, the force while ``on``."""
        e, e_norm, p = self.e, self.e_norm, self.p
        F_N_out = on * ca.substitute(self.F_N, p, p_sym) if self.n_params else on * self.F_N
        out = [
            Channel(f"{name}.ex", "m", e[0]),
            Channel(f"{name}.ey", "m", e[1]),
            Channel(f"{name}.eccentricity", "m", e_norm),
            Channel(f"{name}.penetration", "m", e_norm - self.c),
            Channel(f"{name}.penetration_rate", "m/s", self.penetration_rate),
            Channel(f"{name}.normal_force", "N", F_N_out),
            Channel(f"{name}.in_contact", "", on),
        ]
        if not frictionless:
            F_T_out = on * (ca.substitute(self.F_T, p, p_sym) if self.n_params else self.F_T)
            out.append(Channel(f"{name}.friction_force", "N", F_T_out))
        if not frictionless or self.worn_angles is not None:  # what the wear study reads (studies.wear)
            out.append(Channel(f"{name}.sliding_velocity", "m/s", self.v_T))
        if self.worn_angles is not None:
            out += [Channel(f"{name}.bearing_angle", "rad", self.worn_angles[0]),
                    Channel(f"{name}.journal_angle", "rad", self.worn_angles[1])]
        return out


def journal_logic(ctx: AssemblyContext, jc: JournalContact, cls: type[PairLogic], name: str, first_root: int,
                  first_term: int, gaps: list[Any], law: Any, friction: Any, law_prefix: str = "law"
                  ) -> Callable[[NDArray[np.float64]], list[Any]]:
    """A journal's logic maker: one pair ``name`` of class ``cls``, its rate function (q, v, P) ->
    (``gaps``..., penetration rate) bound to each parameter vector; the law's numbers under
    ``<name>.<law_prefix>``."""
    rate = ca.Function(f"{name}_rate", [ctx.q, ctx.v, ctx.P], [*gaps, jc.penetration_rate])
    floor = approach_floor(ctx, law, f"{name}.{law_prefix}")
    discontinuous = not friction.frictionless and not friction.smooth
    n_q = ctx.n_q  # read once: a CasADi call costs more inside a sweep's loop than the logic it makes

    def logic(P: NDArray[np.float64]) -> list[Any]:
        return [cls((name,), first_root, (first_term,), BufferedFunction(rate, bound=(P,)), n_q,
                    law.needs_approach_speed, floor(P), discontinuous_friction=discontinuous)]
    return logic


def journal_parameters(ref: Reference, joint: Any, law: Any, friction: Any, film: dict[str, Any] | None = None,
                       law_prefix: str = "law") -> dict[str, Any]:
    """A revolute clearance joint's points, clearance and radii, ``film``'s entries, and its laws' numbers
    (the normal law's under ``law_prefix``)."""
    s_i, s_j = ref.joint_points(joint)
    values: dict[str, Any] = {"s_i": s_i, "s_j": s_j, "clearance": joint.radial_clearance,
                              "bearing_radius": float(joint.bearing_radius), "journal_radius": joint.journal,
                              **(film or {})}
    values.update({f"{law_prefix}.{k}": v for k, v in law_values(law).items()})
    values.update({f"friction.{k}": v for k, v in law_values(friction).items()})
    return values


def worn_depths(ctx: AssemblyContext, joint: Any, direction: Any, bi: Any, bj: Any) -> tuple[Any, Any, Any]:
    """The worn depths of the bearing and of the journal along the unit ``direction`` (world frame):
    each surface's profile (parameters ``<joint>.wear.<surface>_cos/_sin``), 0 if it does not wear; and
    the sum's gradient in the positions (None without wear).

    A profile is a polynomial in ``z = c + i s``, the direction's cosine and sine in the body's frame:
    ``h = a_0 + Re sum (a_m - i b_m) z^m`` (the angle-sum rule, no atan2: regular at e = 0). Its
    gradient is written out, ``dh = Re sum m (a_m - i b_m) z^(m-1) dz`` with the powers the depth
    already made, rather than differentiated through the powers' recurrence: the same numbers, and
    the contact's Jacobian then differentiates the powers once, not their derivative again."""
    wear = getattr(joint, "wear", None)
    out: list[Any] = [0.0, 0.0]
    gradient: Any = None
    for k, (surface, frame) in enumerate((("bearing", bi), ("journal", bj))):
        if wear is None or surface not in wear.surfaces:
            continue
        # cos and sin of the direction's angle in the body's frame: A(phi)^T direction
        c1 = ca.cos(frame.phi) * direction[0] + ca.sin(frame.phi) * direction[1]
        s1 = -ca.sin(frame.phi) * direction[0] + ca.cos(frame.phi) * direction[1]
        a, b = ctx.p(joint.name, f"wear.{surface}_cos"), ctx.p(joint.name, f"wear.{surface}_sin")
        depth, d_c, d_s = a[0], 0.0, 0.0
        cm, sm = 1.0, 0.0  # Re and Im of z^m, from m = 0
        for m in range(1, wear.modes + 1):
            d_c = d_c + m * (a[m] * cm + b[m - 1] * sm)  # dh/dc: Re m (a_m - i b_m) z^(m-1)
            d_s = d_s + m * (b[m - 1] * cm - a[m] * sm)  # dh/ds = i dh/dc's real part
            cm, sm = cm * c1 - sm * s1, sm * c1 + cm * s1
            depth = depth + a[m] * cm + b[m - 1] * sm
        out[k] = depth
        part = d_c * ca.jacobian(c1, ctx.q) + d_s * ca.jacobian(s1, ctx.q)
        gradient = part if gradient is None else gradient + part
    return out[0], out[1], gradient


def journal_contact(ctx: AssemblyContext, joint: Any, law_numeric: Any, friction_numeric: Any,
                    law_prefix: str = "law") -> JournalContact:
    """Journal-bearing contact (section 4.2) of ``joint``: body i the bearing (R_i), j the journal (R_j);
    the normal law's numbers under ``<joint>.<law_prefix>``."""
    name = joint.name
    law = symbolic_law(law_numeric, ctx.params, f"{name}.{law_prefix}")
    friction = symbolic_law(friction_numeric, ctx.params, f"{name}.friction")
    R_i, R_j = ctx.p(name, "bearing_radius"), ctx.p(name, "journal_radius")
    s_i, s_j = ctx.p(name, "s_i"), ctx.p(name, "s_j")
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    P_i, P_j = bi.point(s_i), bj.point(s_j)  # (4.2)
    e = P_j - P_i  # (4.1) eccentricity
    e_dot = bj.point_velocity(s_j) - bi.point_velocity(s_i)
    ee = ca.dot(e, e)
    # in contact |e| >= c > 0: the normal and everything below are regular there
    e_norm = ca.sqrt(ee)
    n = e / e_norm  # (4.4)
    # the direction of e, regular at e = 0 (where the gap is far from closing): exactly n in contact
    clearance = ctx.p(name, "clearance")
    *worn, worn_jacobian = worn_depths(ctx, joint, e / ca.fmax(e_norm, 0.5 * clearance), bi, bj)  # 0 without wear
    c_worn = worn[0] + worn[1]
    c = clearance + c_worn  # the clearance along n, worn surfaces included
    delta = e_norm - c  # (4.5)
    worn_rate = ca.mtimes(worn_jacobian, ctx.v) if worn_jacobian is not None else 0.0
    # (4.8): v_N = d|e|/dt, less the worn depth's change as the contact moves along the profile and the
    # worn bodies turn (the gap's own rate: a contact is left only when its gap closes)
    delta_dot = ca.dot(e_dot, n) - worn_rate
    t_vec = perpendicular(n)
    Q_i = P_i + (R_i + worn[0]) * n  # (4.6) contact points, on the worn surfaces
    Q_j = P_j + (R_j - worn[1]) * n
    # (4.9) with the velocities of the material points at the contact (spin included)
    v_T = ca.dot(bj.world_point_velocity(Q_j) - bi.world_point_velocity(Q_i), t_vec)
    n_params = 1 if law_numeric.needs_approach_speed else 0
    p = ca.SX.sym("p", n_params)
    F_N = law.contact_force(delta, delta_dot, p[0] if n_params else None)
    F_T = 0.0 if friction_numeric.frictionless else friction.friction_force(F_N, v_T)
    worn_angles = None
    if worn_jacobian is not None:  # the contact direction's angle in each body's frame: atan2 of A(phi)^T n
        worn_angles = tuple(ca.atan2(-ca.sin(f.phi) * e[0] + ca.cos(f.phi) * e[1],
                                     ca.cos(f.phi) * e[0] + ca.sin(f.phi) * e[1]) for f in (bi, bj))

    def generalized(F_T: Any) -> Any:
        f_journal = -F_N * n + F_T * t_vec  # force on the journal (body j); the bearing gets the opposite
        Q = ctx.generalized_force([(joint.body_j, f_journal, Q_j), (joint.body_i, -f_journal, Q_i)])
        if worn_jacobian is not None:  # the normal force along the gap's gradient: -F_N d(delta)/dq, delta's worn part
            Q = Q + F_N * worn_jacobian.T
        return Q
    force = ca.Function(f"{name}_force", [ctx.t, ctx.q, ctx.v, p, ctx.P], [generalized(F_T)],
                        ["t", "q", "v", "p", "P"], ["Q"])
    kinks: tuple[Any, ...] = ()
    locked = None
    if not friction_numeric.frictionless and friction_numeric.kinks:
        # v_T with n regular at e = 0 (a root is evaluated in free flight too): exactly v_T in contact
        n_r = e / ca.fmax(e_norm, 0.5 * clearance)
        v_T_r = ca.dot(bj.world_point_velocity(P_j + (R_j - worn[1]) * n_r)
                       - bi.world_point_velocity(P_i + (R_i + worn[0]) * n_r), perpendicular(n_r))
        kinks = friction_kinks(friction, v_T_r)
        locked = locked_force(f"{name}_locked", ctx, p, lambda piece: generalized(friction.piece(F_N, v_T, piece)))
    return JournalContact(e, e_dot, ee, e_norm, c, bi, bj, P_i, P_j, F_N, F_T, v_T, p, n_params, force, worn_rate,
                          worn_angles, kinks, locked)


def friction_kinks(friction: Any, v_T: Any) -> tuple[Any, ...]:
    """The roots v_T - b of the friction law's kinks (``FrictionLaw.breakpoints``, ascending): the piece of
    the law v_T is on is the number of them that are positive."""
    return tuple(v_T - b for b in friction.breakpoints)


def locked_force(label: str, ctx: AssemblyContext, p: Any, force: Callable[[Any], Any]) -> ca.Function:
    """(t, q, v, [p; piece], P) -> ``force(piece)``: a term's force on one piece of its friction law
    (``Term.locked``)."""
    piece = ca.SX.sym("piece")
    return ca.Function(label, [ctx.t, ctx.q, ctx.v, ca.vertcat(p, piece), ctx.P], [force(piece)],
                       ["t", "q", "v", "p", "P"], ["Q"])
