"""The lubricated revolute clearance joint (law :class:`~daeclear.contact.HydrodynamicBearing`).

Two pairs of the contact automaton (docs/lubrication.md, "Transition"): the *regime*
``<joint>.regime``, free while the film carries (the film term on) and in contact once it has broken
down, switched by the gaps ``film_break`` (onset) and ``film_reform`` (separation) with a band
against chattering; and, in the dry regime, the dry *contact* ``<joint>``, a journal against its
bearing as in a dry joint (gap ``<joint>``): every impact an onset with its own approach speed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ..contact.asperity import asperity_load
from ..contact.hydrodynamic import shear_torques
from ..model.clearance_joints import RevoluteClearance
from ..core.events import ContactEvent
from ..core.automaton import PairState, start, step
from .contact_pairs import (ContactBuild, PairLogic, PairStates, TermSwitch, journal_contact, journal_logic,
                            journal_parameters, pair_event)
from .parameters import law_structure
from .symbolic import AssemblyContext, Channel, Reference, Term, perpendicular

__all__ = ["FILM_REGULARISATION", "LubricatedLogic", "build_lubricated_revolute", "lubricated_parameters"]

#: |e| is regularised as sqrt(e.e + (FILM_REGULARISATION c)^2) in the film's directions and rates,
#: so the film force and its Jacobian are finite at the centred journal (e = 0, the chapter's start).
FILM_REGULARISATION = 1e-4
#: The film's numbers: the scene names of the bearing's fields (``<joint>.law.<field>``).
FILM_FIELDS = ("viscosity", "length", "roughness", "film_parameter", "hysteresis", "asperity_modulus")


def lubricated_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[Any]]:
    """The joint's numbers (run-time parameters: the film's ``law.<field>``, the dry law's
    ``law.dry.<field>``) and its structure."""
    bearing, friction = joint.resolved_law(), joint.resolved_friction()
    values = journal_parameters(ref, joint, bearing.dry, friction,
                                {f"law.{key}": float(getattr(bearing, key)) for key in FILM_FIELDS},
                                law_prefix="law.dry")
    return values, [law_structure(bearing.dry), law_structure(friction), f"film:{bearing.theory}:{bearing.cavitation}"]


def build_lubricated_revolute(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                              first_root: int) -> ContactBuild:
    """Terms ``<name>`` (dry contact) and ``<name>.film``; gaps ``<name>.film_break``,
    ``<name>.film_reform`` and ``<name>`` (the dry contact's)."""
    name = joint.name
    bearing, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    dry_numeric = bearing.dry
    # the dry term: the revolute clearance joint's contact, on only in the dry regime while the journal touches
    jc = journal_contact(ctx, joint, dry_numeric, friction_numeric, law_prefix="law.dry")
    e, e_dot, ee, e_norm, c, bi, bj = jc.e, jc.e_dot, jc.ee, jc.e_norm, jc.c, jc.bi, jc.bj
    R_j = ctx.p(name, "journal_radius")
    mu, length, sigma = ctx.p(name, "law.viscosity"), ctx.p(name, "law.length"), ctx.p(name, "law.roughness")
    h_break = ctx.p(name, "law.film_parameter") * sigma
    h_reform = h_break * (1.0 + ctx.p(name, "law.hysteresis"))
    r_break, r_reform = c - h_break, c - h_reform
    gaps = [(ee - r_break * r_break) / (2.0 * r_break), (ee - r_reform * r_reform) / (2.0 * r_reform),
            (ee - c * c) / (2.0 * c)]

    # the film term: on in the film regime (regularised at e = 0, see FILM_REGULARISATION)
    reg = ca.sqrt(ee + (FILM_REGULARISATION * c) ** 2)
    n_f = e / reg
    eps = ee / (c * reg)
    eps_dot = ca.dot(e_dot, e) / (c * reg)
    gamma_dot = (e[0] * e_dot[1] - e[1] * e_dot[0]) / (reg * reg)
    wedge = bi.omega + bj.omega - 2.0 * gamma_dot
    F_r, F_t = bearing.film_force_with(mu, length, eps, wedge, eps_dot, R_j, c)
    T_j, T_b = shear_torques(mu, length, eps, bj.omega - bi.omega, F_t, R_j, c)
    W_a = asperity_load(eps, c, sigma, R_j, length, ctx.p(name, "law.asperity_modulus"))
    f_film = -F_r * n_f + F_t * perpendicular(n_f)  # pressure resultants through the two centres
    f_total = f_film - W_a * n_f  # with the asperities' load (mixed lubrication), along the line of centres
    Q_film = ctx.generalized_force([(joint.body_j, f_total, jc.P_j), (joint.body_i, -f_total, jc.P_i)],
                                   couples=[(joint.body_j, T_j), (joint.body_i, T_b)])
    p0 = ca.SX.sym("p", 0)
    film_fn = ca.Function(f"{name}_film_force", [ctx.t, ctx.q, ctx.v, p0, ctx.P], [Q_film],
                          ["t", "q", "v", "p", "P"], ["Q"])
    # the power the film (pressure and shear) takes from the mechanism: its dissipation, >= 0
    dissipation = -(ca.dot(f_film, e_dot) + T_j * bj.omega + T_b * bi.omega)

    logic = journal_logic(ctx, jc, LubricatedLogic, name, first_root, first_term, gaps, dry_numeric,
                          friction_numeric, law_prefix="law.dry")

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        (on, p_sym), (film_on, _) = switches
        return jc.channels(name, on, p_sym, friction_numeric.frictionless) + [
            Channel(f"{name}.eccentricity_ratio", "", e_norm / c),
            Channel(f"{name}.film_thickness", "m", c - e_norm),
            Channel(f"{name}.film_parameter", "", (c - e_norm) / sigma),
            Channel(f"{name}.regime", "", 1.0 - film_on),  # 0 film (with asperities below 4 sigma), 1 dry
            Channel(f"{name}.film_radial", "N", film_on * F_r),
            Channel(f"{name}.film_tangential", "N", film_on * F_t),
            Channel(f"{name}.film_torque", "N m", film_on * T_j),
            Channel(f"{name}.asperity_force", "N", film_on * W_a),
            Channel(f"{name}.film_dissipation", "W", film_on * dissipation),
        ]

    terms = [Term(name, jc.force, jc.n_params, jc.locked), Term(f"{name}.film", film_fn, 0)]
    return ContactBuild(terms=terms, gaps=gaps,
                        gap_names=[f"{name}.film_break", f"{name}.film_reform", name], channels=channels,
                        logic=logic, ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"],
                        kinks=list(jc.kinks), kink_terms=[0] * len(jc.kinks))


@dataclass(frozen=True)
class LubricatedLogic(PairLogic):
    """The regimes and the dry contacts of one lubricated joint, by the contact automaton.

    Two pairs: the regime ``<joint>.regime`` (roots ``first_root``, film_break, watched upward and
    ``first_root + 1``, film_reform, downward; contact = the dry regime) and the dry contact
    ``<joint>`` (root ``first_root + 2``, decided only in the dry regime, with its latched approach
    speed). The dry term ``pair_terms[0]`` is on in the dry regime while the journal touches (or is
    held), the film term (the next one) in the film regime. ``rate`` gives (the three gaps,
    penetration rate). The compiled loop hands these roots to Python (no simple pairs).
    """

    @property
    def roots(self) -> range:
        return range(self.first_root, self.first_root + 3)

    @property
    def n_states(self) -> int:
        return 2  # the regime and the dry contact

    def pair_index(self, root: int) -> int:
        return 0 if root < self.first_root + 2 else 1

    def pair_name(self, root: int) -> str:
        return self._names[self.pair_index(root)]

    @property
    def _names(self) -> tuple[str, str]:
        return (f"{self.pairs[0]}.regime", self.pairs[0])

    def _values(self, y: NDArray) -> tuple[float, float, float, float]:
        out = self.rate(y[:self.n_q], y[self.n_q:2 * self.n_q])
        return float(out[0][0]), float(out[1][0]), float(out[2][0]), float(out[3][0])

    def start(self, t: float, y: NDArray) -> PairStates:
        broken, _, touching, rate = self._values(y)
        regime = start(broken > 0.0, rate, self.min_approach_speed)
        return (regime, start(regime.contact and touching > 0.0, rate, self.min_approach_speed))

    def terms(self, states: PairStates) -> list[TermSwitch]:
        """The dry term in the dry regime while touching (or held), the film term in the film regime."""
        dry, k = states[0].term_on, self.pair_terms[0]
        return [(k, dry and states[1].term_on, self._params(states[1])), (k + 1, not dry, np.zeros(0))]

    def modes(self, states: PairStates) -> dict[str, str]:
        return {name: ("contact" if st.contact else "free") for name, st in zip(self._names, states)}

    def root_directions(self, states: PairStates) -> list[tuple[int, int]]:
        """The film breaks upward through film_break, forms again downward through film_reform; the
        dry contact's gap as a dry joint's."""
        return [(self.first_root, 1), (self.first_root + 1, -1), (self.first_root + 2, states[1].watch)]

    def decide(self, states: PairStates, t: float, y: NDArray, roots_found: NDArray | None
               ) -> tuple[PairStates, list[ContactEvent]]:
        if roots_found is None:
            return states, []
        up = roots_found[self.first_root] > 0
        down = roots_found[self.first_root + 1] < 0
        touch = int(roots_found[self.first_root + 2])
        if not (up or down or touch):
            return states, []
        rate = self._values(y)[3]
        regime, contact = states
        events: list[ContactEvent] = []
        if up or down:
            direction = 1 if up and not regime.contact else -1 if down else 1
            regime, decision = step(regime, t, direction, rate, storm=self.storm,
                                    min_approach_speed=self.min_approach_speed)
            events += pair_event(self._names[0], t, y, rate, decision)
        if regime.term_on and touch:
            contact, decision = step(contact, t, touch, rate, storm=self.storm,
                                     min_approach_speed=self.min_approach_speed)
            events += pair_event(self._names[1], t, y, rate, decision)
        elif not regime.term_on and contact.term_on:  # the film carries again: the dry contact is over
            contact = PairState(latched=contact.latched, recent=contact.recent)
        return (regime, contact), events

    @property
    def rate_output(self) -> int:
        """``rate`` gives (film_break, film_reform, the dry gap, the penetration rate)."""
        return 3

    def rate_index(self, root: int) -> int:
        return 0

    def term_sensitivities(self, states: PairStates, latched: Sequence[NDArray]) -> list[tuple[int, NDArray]]:
        """The dry term's parameter is the dry contact's latched speed (``latched[1]``); the film term has none."""
        k, width = self.pair_terms[0], np.size(latched[1])
        dry = np.asarray(latched[1], dtype=float)[None, :] if self.needs_approach else np.zeros((0, width))
        return [(k, dry), (k + 1, np.zeros((0, width)))]

    def simple_pairs(self) -> None:
        """None: two terms follow one pair, which the compiled loop's mirror does not do."""
        return None
