"""The lubricated revolute clearance joint (law :class:`~daeclear.contact.HydrodynamicBearing`): its
parameters, film and dry terms, gap functions, channels and regime logic.

Two regimes, one pair of the contact automaton (:mod:`daeclear.assembly.automaton`):

* *film* (the automaton's free mode): the film term acts, the dry term is off;
* *dry* (contact mode): the dry contact law (and friction) acts, the film term is off.

Two gap functions, both positive once the film is thinner than their level: ``film_break`` at the
minimum film thickness ``c - |e| = film_threshold`` and ``film_reform`` at
``film_threshold (1 + hysteresis)``. An upward crossing of ``film_break`` is the automaton's onset
(film -> dry, the dry law's approach speed latched there), a downward crossing of ``film_reform``
its separation (dry -> film); IDA locates both. The band between the two levels keeps the regimes
from chattering; the storm guard holds the dry regime in a cascade, as for a dry joint.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any
from collections.abc import Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..model.clearance_joints import RevoluteClearance
from ..results.result import ContactEvent
from .automaton import DEFAULT_STORM, EVENT_KINDS, NONE, ONSET, Decision, PairState, Storm, recorded, start, step
from .contact_pairs import ContactBuild, approach_floor
from .parameters import law_structure, law_values, symbolic_law
from .symbolic import AssemblyContext, BufferedFunction, Channel, Reference, Term, perpendicular

__all__ = ["FILM_REGULARISATION", "LubricatedLogic", "build_lubricated_revolute", "lubricated_parameters"]

#: |e| is regularised as sqrt(e.e + (FILM_REGULARISATION c)^2) in the film's directions and rates,
#: so the film force and its Jacobian are finite at the centred journal (e = 0, the chapter's start).
FILM_REGULARISATION = 1e-4


def lubricated_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[Any]]:
    """The joint's numbers (run-time parameters, the film's under ``film.*``) and its structure."""
    bearing, friction = joint.resolved_law(), joint.resolved_friction()
    s_i, s_j = ref.joint_points(joint)
    values: dict[str, Any] = {
        "s_i": s_i, "s_j": s_j, "clearance": joint.radial_clearance,
        "bearing_radius": float(joint.bearing_radius), "journal_radius": joint.journal,
        "film.viscosity": bearing.viscosity, "film.length": bearing.length,
        "film.threshold": bearing.film_threshold, "film.reform_threshold": bearing.reform_threshold}
    values.update({f"law.{k}": v for k, v in law_values(bearing.dry).items()})
    values.update({f"friction.{k}": v for k, v in law_values(friction).items()})
    return values, [law_structure(bearing.dry), law_structure(friction), f"film:{bearing.theory}:{bearing.cavitation}"]


def build_lubricated_revolute(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                              first_root: int) -> ContactBuild:
    """Terms ``<name>`` (dry) and ``<name>.film``, gaps ``<name>.film_break`` and ``<name>.film_reform``."""
    name = joint.name
    bearing, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    dry_numeric = bearing.dry
    dry = symbolic_law(dry_numeric, ctx.params, f"{name}.law")
    friction = symbolic_law(friction_numeric, ctx.params, f"{name}.friction")
    c = ctx.p(name, "clearance")
    R_i, R_j = ctx.p(name, "bearing_radius"), ctx.p(name, "journal_radius")
    s_i, s_j = ctx.p(name, "s_i"), ctx.p(name, "s_j")
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    P_i, P_j = bi.point(s_i), bj.point(s_j)
    e = P_j - P_i
    e_dot = bj.point_velocity(s_j) - bi.point_velocity(s_i)
    ee = ca.dot(e, e)
    r_break = c - ctx.p(name, "film.threshold")
    r_reform = c - ctx.p(name, "film.reform_threshold")
    gaps = [(ee - r_break * r_break) / (2.0 * r_break), (ee - r_reform * r_reform) / (2.0 * r_reform)]

    # the dry term: the revolute clearance joint's contact (4.1)-(4.13); on only in the dry regime,
    # where |e| >= c - film_threshold > 0
    e_norm = ca.sqrt(ee)
    n = e / e_norm
    delta, delta_dot = e_norm - c, ca.dot(e_dot, n)
    t_vec = perpendicular(n)
    Q_i, Q_j = P_i + R_i * n, P_j + R_j * n
    v_T = ca.dot(bj.world_point_velocity(Q_j) - bi.world_point_velocity(Q_i), t_vec)
    n_params = 1 if dry_numeric.needs_approach_speed else 0
    p = ca.SX.sym("p", n_params)
    F_N = dry.force(delta, delta_dot, p[0] if n_params else None)
    F_T = 0.0 if friction_numeric.frictionless else friction.friction_force(F_N, v_T)
    f_dry = -F_N * n + F_T * t_vec
    Q_dry = ctx.generalized_force([(joint.body_j, f_dry, Q_j), (joint.body_i, -f_dry, Q_i)])
    dry_fn = ca.Function(f"{name}_force", [ctx.t, ctx.q, ctx.v, p, ctx.P], [Q_dry], ["t", "q", "v", "p", "P"], ["Q"])

    # the film term: on in the film regime (regularised at e = 0, see FILM_REGULARISATION)
    reg = ca.sqrt(ee + (FILM_REGULARISATION * c) ** 2)
    n_f = e / reg
    eps = ee / (c * reg)
    eps_dot = ca.dot(e_dot, e) / (c * reg)
    gamma_dot = (e[0] * e_dot[1] - e[1] * e_dot[0]) / (reg * reg)
    wedge = bi.omega + bj.omega - 2.0 * gamma_dot
    F_r, F_t = bearing.film_force_with(ctx.p(name, "film.viscosity"), ctx.p(name, "film.length"),
                                       eps, wedge, eps_dot, R_j, c)
    f_film = -F_r * n_f + F_t * perpendicular(n_f)  # pressure resultants through the two centres
    Q_film = ctx.generalized_force([(joint.body_j, f_film, P_j), (joint.body_i, -f_film, P_i)])
    p0 = ca.SX.sym("p", 0)
    film_fn = ca.Function(f"{name}_film_force", [ctx.t, ctx.q, ctx.v, p0, ctx.P], [Q_film],
                          ["t", "q", "v", "p", "P"], ["Q"])

    rate = ca.Function(f"{name}_rate", [ctx.q, ctx.v, ctx.P],
                       [gaps[0], gaps[1], ca.dot(e_dot, e) / ca.fmax(e_norm, 1e-300)])
    floor = approach_floor(ctx, dry_numeric, f"{name}.law")
    n_q = ctx.n_q

    def logic(P: NDArray[np.float64]) -> list[Any]:
        return [LubricatedLogic(name, first_root, first_term, BufferedFunction(rate, bound=(P,)), n_q,
                                dry_numeric.needs_approach_speed, floor(P))]

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        (on, p_sym), (film_on, _) = switches
        F_N_out = on * ca.substitute(F_N, p, p_sym) if n_params else on * F_N
        out = [
            Channel(f"{name}.ex", "m", e[0]),
            Channel(f"{name}.ey", "m", e[1]),
            Channel(f"{name}.eccentricity", "m", e_norm),
            Channel(f"{name}.eccentricity_ratio", "", e_norm / c),
            Channel(f"{name}.film_thickness", "m", c - e_norm),
            Channel(f"{name}.penetration", "m", e_norm - c),
            Channel(f"{name}.penetration_rate", "m/s", ca.dot(e_dot, e) / ca.fmax(e_norm, 1e-300)),
            Channel(f"{name}.normal_force", "N", F_N_out),
            Channel(f"{name}.in_contact", "", on),
            Channel(f"{name}.regime", "", on),  # 0 film, 1 dry
            Channel(f"{name}.film_radial", "N", film_on * F_r),
            Channel(f"{name}.film_tangential", "N", film_on * F_t),
            # the power the film's forces take from the mechanism (the pressure's share of the film's losses)
            Channel(f"{name}.film_dissipation", "W", -film_on * ca.dot(f_film, e_dot)),
        ]
        if not friction_numeric.frictionless:
            F_T_out = on * (ca.substitute(F_T, p, p_sym) if n_params else F_T)
            out += [Channel(f"{name}.friction_force", "N", F_T_out),
                    Channel(f"{name}.sliding_velocity", "m/s", v_T)]
        return out

    return ContactBuild(terms=[Term(name, dry_fn, n_params), Term(f"{name}.film", film_fn, 0)], gaps=gaps,
                        gap_names=[f"{name}.film_break", f"{name}.film_reform"], channels=channels, logic=logic,
                        ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"])


@dataclass
class LubricatedLogic:
    """Regime switching of one lubricated joint by the contact automaton (see the module docstring).

    Root ``root_index`` (film_break) is watched upward, ``root_index + 1`` (film_reform) downward; the
    dry term ``term_index`` is on while the automaton is in contact (or held), the film term
    ``term_index + 1`` otherwise. The compiled loop hands these roots to Python (no simple pairs).
    """

    pair: str
    root_index: int
    term_index: int
    rate: BufferedFunction  # (q, v) -> (film_break gap, film_reform gap, penetration rate)
    n_q: int
    needs_approach: bool
    min_approach_speed: float
    storm: Storm = DEFAULT_STORM
    state: PairState = field(default_factory=PairState)

    @property
    def held(self) -> bool:
        return self.state.held

    @property
    def roots(self) -> range:
        return range(self.root_index, self.root_index + 2)

    def pair_state(self, root: int) -> PairState:
        return self.state

    def pair_name(self, root: int) -> str:
        return self.pair

    def _values(self, y: NDArray) -> tuple[float, float, float]:
        out = self.rate(y[:self.n_q], y[self.n_q:2 * self.n_q])
        return float(out[0][0]), float(out[1][0]), float(out[2][0])

    def _switch(self, active: list[bool], params: list[NDArray], term_on: bool, onset: bool) -> None:
        active[self.term_index], active[self.term_index + 1] = term_on, not term_on
        if onset:
            params[self.term_index] = np.array([self.state.latched]) if self.needs_approach else np.zeros(0)

    def initial_modes(self, t: float, y: NDArray, active: list[bool], params: list[NDArray]) -> dict[str, str]:
        broken, _, rate = self._values(y)
        self.state = start(broken > 0.0, rate, self.min_approach_speed)
        self._switch(active, params, self.state.term_on, True)
        return {self.pair: "contact" if self.state.contact else "free"}

    def root_directions(self, active: Sequence[bool]) -> list[tuple[int, int]]:
        """The film breaks upward through film_break, forms again downward through film_reform."""
        return [(self.root_index, 1), (self.root_index + 1, -1)]

    def on_roots(self, t: float, y: NDArray, yp: NDArray, roots_found: NDArray | None,
                 active: list[bool], params: list[NDArray]) -> list[ContactEvent]:
        if roots_found is None:
            return []
        up = roots_found[self.root_index] > 0
        down = roots_found[self.root_index + 1] < 0
        if not (up or down):
            return []
        rate = self._values(y)[2]
        direction = 1 if up and not self.state.contact else -1 if down else 1
        self.state, decision = step(self.state, t, direction, rate, storm=self.storm,
                                    min_approach_speed=self.min_approach_speed)
        return self.record(self.root_index, t, y, rate, decision, active, params)

    def record(self, root: int, t: float, y: NDArray, rate: float, decision: Decision,
               active: list[bool], params: list[NDArray]) -> list[ContactEvent]:
        if decision.kind == NONE:
            return []
        self.apply(root, t, y, decision, active, params)
        return [ContactEvent.from_solver(t, self.pair, EVENT_KINDS[decision.kind], rate, np.array(y, dtype=float))]

    def apply(self, root: int, t: float, y: NDArray, decision: Decision, active: list[bool],
              params: list[NDArray]) -> None:
        self.state = recorded(self.state, decision)
        self._switch(active, params, decision.term_on, decision.kind == ONSET)

    def simple_pairs(self) -> None:
        """None: two terms follow one pair, which the compiled loop's mirror does not do."""
        return None
