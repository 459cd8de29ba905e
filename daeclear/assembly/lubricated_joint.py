"""The lubricated revolute clearance joint (law :class:`~daeclear.contact.HydrodynamicBearing`).

One pair of the contact automaton: *film* (free mode) and *dry* (contact mode), switched by the
gaps ``film_break`` (onset) and ``film_reform`` (separation) with a band against chattering
(docs/lubrication.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..model.clearance_joints import RevoluteClearance
from ..core.events import ContactEvent
from ..core.automaton import start, step
from .contact_pairs import (ContactBuild, PairLogic, PairStates, TermSwitch, journal_contact, journal_logic,
                            journal_parameters, pair_event)
from .parameters import law_structure
from .symbolic import AssemblyContext, Channel, Reference, Term, perpendicular

__all__ = ["FILM_REGULARISATION", "LubricatedLogic", "build_lubricated_revolute", "lubricated_parameters"]

#: |e| is regularised as sqrt(e.e + (FILM_REGULARISATION c)^2) in the film's directions and rates,
#: so the film force and its Jacobian are finite at the centred journal (e = 0, the chapter's start).
FILM_REGULARISATION = 1e-4


def lubricated_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[Any]]:
    """The joint's numbers (run-time parameters, the film's under ``film.*``) and its structure."""
    bearing, friction = joint.resolved_law(), joint.resolved_friction()
    values = journal_parameters(ref, joint, bearing.dry, friction, {
        "film.viscosity": bearing.viscosity, "film.length": bearing.length,
        "film.threshold": bearing.film_threshold, "film.reform_threshold": bearing.reform_threshold})
    return values, [law_structure(bearing.dry), law_structure(friction), f"film:{bearing.theory}:{bearing.cavitation}"]


def build_lubricated_revolute(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                              first_root: int) -> ContactBuild:
    """Terms ``<name>`` (dry) and ``<name>.film``, gaps ``<name>.film_break`` and ``<name>.film_reform``."""
    name = joint.name
    bearing, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    dry_numeric = bearing.dry
    # the dry term: the revolute clearance joint's contact, on only in the dry regime (|e| >= c - threshold > 0)
    jc = journal_contact(ctx, joint, dry_numeric, friction_numeric)
    e, e_dot, ee, e_norm, c, bi, bj = jc.e, jc.e_dot, jc.ee, jc.e_norm, jc.c, jc.bi, jc.bj
    R_j = ctx.p(name, "journal_radius")
    r_break = c - ctx.p(name, "film.threshold")
    r_reform = c - ctx.p(name, "film.reform_threshold")
    gaps = [(ee - r_break * r_break) / (2.0 * r_break), (ee - r_reform * r_reform) / (2.0 * r_reform)]

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
    Q_film = ctx.generalized_force([(joint.body_j, f_film, jc.P_j), (joint.body_i, -f_film, jc.P_i)])
    p0 = ca.SX.sym("p", 0)
    film_fn = ca.Function(f"{name}_film_force", [ctx.t, ctx.q, ctx.v, p0, ctx.P], [Q_film],
                          ["t", "q", "v", "p", "P"], ["Q"])

    logic = journal_logic(ctx, jc, LubricatedLogic, name, first_root, first_term, gaps, dry_numeric, friction_numeric)

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        (on, p_sym), (film_on, _) = switches
        return jc.channels(name, on, p_sym, friction_numeric.frictionless) + [
            Channel(f"{name}.eccentricity_ratio", "", e_norm / c),
            Channel(f"{name}.film_thickness", "m", c - e_norm),
            Channel(f"{name}.regime", "", on),  # 0 film, 1 dry
            Channel(f"{name}.film_radial", "N", film_on * F_r),
            Channel(f"{name}.film_tangential", "N", film_on * F_t),
            # the power the film's forces take from the mechanism (the pressure's share of the film's losses)
            Channel(f"{name}.film_dissipation", "W", -film_on * ca.dot(f_film, e_dot)),
        ]

    return ContactBuild(terms=[Term(name, jc.force, jc.n_params), Term(f"{name}.film", film_fn, 0)], gaps=gaps,
                        gap_names=[f"{name}.film_break", f"{name}.film_reform"], channels=channels, logic=logic,
                        ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"])


@dataclass(frozen=True)
class LubricatedLogic(PairLogic):
    """Regime switching of one lubricated joint by the contact automaton (see the module docstring).

    Its one pair watches two roots: ``first_root`` (film_break) upward, ``first_root + 1``
    (film_reform) downward; the dry term ``pair_terms[0]`` is on while the automaton is in contact
    (or held), the film term (the next one) otherwise. ``rate`` gives (film_break gap, film_reform
    gap, penetration rate). The compiled loop hands these roots to Python (no simple pairs).
    """

    @property
    def roots(self) -> range:
        return range(self.first_root, self.first_root + 2)

    def pair_index(self, root: int) -> int:
        return 0

    def _values(self, y: NDArray) -> tuple[float, float, float]:
        out = self.rate(y[:self.n_q], y[self.n_q:2 * self.n_q])
        return float(out[0][0]), float(out[1][0]), float(out[2][0])

    def start(self, t: float, y: NDArray) -> PairStates:
        broken, _, rate = self._values(y)
        return (start(broken > 0.0, rate, self.min_approach_speed),)

    def terms(self, states: PairStates) -> list[TermSwitch]:
        """The dry term while the automaton is in contact (or held), the film term otherwise."""
        on, k = states[0].term_on, self.pair_terms[0]
        return [(k, on, self._params(states[0])), (k + 1, not on, np.zeros(0))]

    def root_directions(self, states: PairStates) -> list[tuple[int, int]]:
        """The film breaks upward through film_break, forms again downward through film_reform."""
        return [(self.first_root, 1), (self.first_root + 1, -1)]

    def decide(self, states: PairStates, t: float, y: NDArray, roots_found: NDArray | None
               ) -> tuple[PairStates, list[ContactEvent]]:
        if roots_found is None:
            return states, []
        up = roots_found[self.first_root] > 0
        down = roots_found[self.first_root + 1] < 0
        if not (up or down):
            return states, []
        rate = self._values(y)[2]
        direction = 1 if up and not states[0].contact else -1 if down else 1
        state, decision = step(states[0], t, direction, rate, storm=self.storm,
                               min_approach_speed=self.min_approach_speed)
        return (state,), pair_event(self.pairs[0], t, y, rate, decision)

    def simple_pairs(self) -> None:
        """None: two terms follow one pair, which the compiled loop's mirror does not do."""
        return None
