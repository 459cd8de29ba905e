"""Translational clearance joint (section 4.3): a slider free inside a guide, contact at its corners.

Body i the guide, body j the slider. The guide's mid-line runs through ``O`` (``point_i``) along the
unit vector ``t`` (4.14); ``n = perp(t)`` points to the upper surface at ``+H/2``. For a corner ``r_k``
(4.15), ``s_k = t . (r_k - O)`` along the guide and ``d_k = +-n . (r_k - O) - H/2`` the penetration
(4.16)-(4.20), > 0 in contact, at the sharp corner (R_c only sets the corner law's stiffness, 3.5);
the rate is ``(d d_k / dq) v`` (4.21); the force acts on the slider at the corner and on the guide
at the closest surface point (4.22)-(4.25). Corners A, B touch the upper surface, C, D the lower:
four pairs, each gap ``min(d_k, s_k - s_P, s_Q - s_k)`` with contact limits (s_P, s_Q).

Models (``contact_model``): ``corners``, one term per corner; ``section-4.3``, also one term per
face, on instead of its corners' while both touch: ``face_law(d_mean, d_mean_dot)`` at the centroid
of the penetrated trapezoid (docs/validation.md). Friction acts along ``t``.

Channels: ``<name>.s``, ``.y`` (m; along the guide, off the mid-line), ``.tilt`` (rad), ``.eta`` =
y / (2c), ``.xi`` (0..1 along ``stroke``, Fig. 4.28d); per pair ``<name>.A_upper`` ...
``.D_lower`` and per face ``.penetration``, ``.penetration_rate`` (pairs), ``.normal_force``,
``.in_contact`` (friction: ``.friction_force``, ``.sliding_velocity``); ``<name>.penetration``
(largest), ``.normal_force`` (sum), ``.in_contact`` (any) and ``.elastic_energy`` (J).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from .contact_pairs import ContactBuild, PairLogic, PairStates, TermSwitch, approach_floor, friction_kinks, locked_force
from .parameters import law_structure, law_values, symbolic_law
from ..core.events import ContactEvent
from ..model.scene import TranslationalClearance
from .symbolic import AssemblyContext, BufferedFunction, Channel, Reference, Term, perpendicular, rotation

#: Corners: name, sign along the slider length, sign across it, surface it can touch.
CORNERS: tuple[tuple[str, int, int, str], ...] = (
    ("A", +1, +1, "upper"), ("B", -1, +1, "upper"), ("C", -1, -1, "lower"), ("D", +1, -1, "lower"))
#: Faces: name and the indices (in CORNERS) of its two corners, rear first.
FACES: tuple[tuple[str, int, int], ...] = (("upper_face", 1, 0), ("lower_face", 2, 3))
# keeps the trapezoid's centroid finite when both penetrations vanish (only while Newton iterates), m
_CENTROID_EPS = 1e-18


def _identifier(name: str) -> str:
    """A CasADi-safe function name fragment (letters, digits, single underscores)."""
    ident = re.sub(r"_+", "_", re.sub(r"[^0-9A-Za-z]", "_", name)).strip("_")
    return ident if ident and ident[0].isalpha() else f"j_{ident}"


def _elastic_energy(numeric: Any, law: Any, d: Any) -> Any | None:
    """``K d^(n+1)/(n+1)``, the energy of a law's elastic part ``K d^n`` (None if unknown); ``numeric``
    decides, ``law`` (possibly with symbolic numbers) gives the formula."""
    if getattr(numeric, "stiffness", None) is None:
        return None
    n_value = float(getattr(numeric, "effective_exponent", 1.0 if numeric.geometry == "face" else math.nan))
    if not math.isfinite(n_value):
        return None
    n = getattr(law, "effective_exponent", n_value)
    # behind a branch: the derivative in n is 0 out of contact, not 0 * log(0) = NaN (see normal.py's _elastic)
    return law.stiffness * ca.if_else(d > 0.0, ca.fmax(d, 0.0) ** (n + 1.0), 0.0) / (n + 1.0)


@dataclass(frozen=True)
class SliderGuideLogic(PairLogic):
    """Mode switching of one translational clearance joint: its four corner pairs
    (:class:`~daeclear.assembly.contact_pairs.PairLogic`) and, in the ``section-4.3`` model, two
    faces. A face term is on while both its corners are in contact, and then their corner terms
    are off."""

    face_names: tuple[str, ...] = ()
    face_terms: tuple[int, ...] = ()
    face_corners: tuple[tuple[int, int], ...] = ()
    face_needs_approach: bool = False
    face_min_approach_speed: float = 0.0

    def _faces_on(self, states: PairStates) -> list[bool]:
        return [states[a].contact and states[b].contact for a, b in self.face_corners]

    def terms(self, states: PairStates) -> list[TermSwitch]:
        """A face's term while both its corners are in contact (parameter: their mean latched speed,
        floored); a corner's while its pair's term is on and its face is not."""
        out: list[TermSwitch] = []
        in_face = [False] * len(self.pairs)
        for f, ((a, b), on) in enumerate(zip(self.face_corners, self._faces_on(states))):
            speed = max(0.5 * (states[a].latched + states[b].latched), self.face_min_approach_speed)
            out.append((self.face_terms[f], on, np.array([speed]) if self.face_needs_approach else np.zeros(0)))
            in_face[a] = in_face[b] = on
        return out + [(k, on and not face, p) for (k, on, p), face in zip(super().terms(states), in_face)]

    def modes(self, states: PairStates) -> dict[str, str]:
        modes = super().modes(states)
        modes.update({f: ("contact" if on else "free") for f, on in zip(self.face_names, self._faces_on(states))})
        return modes

    def decide(self, states: PairStates, t: float, y: NDArray, roots_found: NDArray | None
               ) -> tuple[PairStates, list[ContactEvent]]:
        """The corners' decisions, then the events of the faces that formed or broke."""
        after, events = super().decide(states, t, y, roots_found)
        for f, (was, on) in enumerate(zip(self._faces_on(states), self._faces_on(after))):
            if on != was:
                a, b = self.face_corners[f]
                speed = 0.5 * (after[a].latched + after[b].latched) if on else float("nan")
                events.append(ContactEvent(t, self.face_names[f], "onset" if on else "separation", speed,
                                                       np.array(y, dtype=float)))
        return after, events

    def event_roots(self, pair: str, roots_found: NDArray) -> list[int]:
        """A corner's own gap; a face formed or broken by the corners whose roots were found then."""
        if pair not in self.face_names:
            return super().event_roots(pair, roots_found)
        a, b = self.face_corners[self.face_names.index(pair)]
        return [self.first_root + i for i in (a, b) if roots_found[self.first_root + i] != 0]

    def term_sensitivities(self, states: PairStates, latched: Sequence[NDArray]) -> list[tuple[int, NDArray]]:
        """A face's parameter, the mean of its corners' latched speeds, moves by the mean of their
        sensitivities (0 where the face's floor holds it); the corners' as :class:`PairLogic`'s."""
        out = []
        width = np.size(latched[0]) if len(latched) else 0
        for f, (a, b) in enumerate(self.face_corners):
            mean = 0.5 * (states[a].latched + states[b].latched)
            if not self.face_needs_approach:
                S = np.zeros((0, width))
            elif mean <= self.face_min_approach_speed:
                S = np.zeros((1, width))
            else:
                S = 0.5 * (np.asarray(latched[a], dtype=float) + np.asarray(latched[b], dtype=float))[None, :]
            out.append((self.face_terms[f], S))
        return out + super().term_sensitivities(states, latched)

    def simple_pairs(self) -> list[tuple[int, int, ca.Function, bool, float]] | None:
        """None with faces (their terms depend on two corners); else every corner's pair."""
        return None if self.face_names else super().simple_pairs()


def translational_clearance_parameters(ref: Reference,
                                       joint: TranslationalClearance) -> tuple[dict[str, Any], list[Any]]:
    """The joint's numbers (run-time parameters) and what of it is structure."""
    law = joint.resolved_law()
    face_law = joint.resolved_face_law() if joint.contact_model == "section-4.3" else None
    friction = joint.resolved_friction()
    s_i, s_j = ref.joint_points(joint)
    t_guide = ref.local_vector(joint.body_i, joint.axis)  # (4.14): t in guide coordinates
    # slider length direction, slider coordinates
    e_slider = (ref.local_vector(joint.body_j, joint.axis) if joint.slider_axis is None
                else np.asarray(joint.slider_axis, dtype=float) / math.hypot(*joint.slider_axis))
    values: dict[str, Any] = {
        "s_i": s_i, "s_j": s_j, "length": float(joint.length), "width": float(joint.width),
        "height": joint.height, "clearance": joint.radial_clearance, "t_guide": t_guide, "e_slider": e_slider,
        # angle from the guide's direction to the slider's length direction, both bodies at angle 0
        "tilt0": math.atan2(e_slider[1], e_slider[0]) - math.atan2(t_guide[1], t_guide[0]),
    }
    for surface, limits in (("upper", joint.upper_limits), ("lower", joint.lower_limits)):
        if limits is not None:
            values[f"{surface}_limits"] = limits
    stroke = joint.stroke if joint.stroke is not None else joint.upper_limits
    if stroke is not None:
        values["stroke"] = stroke
    structure: list[Any] = [joint.contact_model, law_structure(law), law_structure(friction)]
    for prefix, each in (("law", law), ("face_law", face_law), ("friction", friction)):
        if each is not None:
            values.update({f"{prefix}.{k}": v for k, v in law_values(each).items()})
    if face_law is not None:
        structure.append(law_structure(face_law))
    return values, structure


def build_translational_clearance(ctx: AssemblyContext, joint: TranslationalClearance, first_term: int,
                                  first_root: int) -> ContactBuild:
    """Slider-guide contact, eqs. (4.14)-(4.27): terms A_upper, B_upper, C_lower, D_lower (then
    upper_face, lower_face in ``section-4.3``), gaps the four corners; numbers from ``<joint>.*``."""
    name, ident = joint.name, _identifier(joint.name)
    law_numeric = joint.resolved_law()
    face_numeric = joint.resolved_face_law() if joint.contact_model == "section-4.3" else None
    friction_numeric = joint.resolved_friction()
    law = symbolic_law(law_numeric, ctx.params, f"{name}.law")
    face_law = None if face_numeric is None else symbolic_law(face_numeric, ctx.params, f"{name}.face_law")
    friction = symbolic_law(friction_numeric, ctx.params, f"{name}.friction")
    L, W = ctx.p(name, "length"), ctx.p(name, "width")
    H, c = ctx.p(name, "height"), ctx.p(name, "clearance")
    guide, slider = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    s_i, s_j = ctx.p(name, "s_i"), ctx.p(name, "s_j")
    t_guide, e_slider = ctx.p(name, "t_guide"), ctx.p(name, "e_slider")
    w_slider = perpendicular(e_slider)

    O = guide.point(s_i)  # a point of the mid-line
    t_vec = ca.mtimes(rotation(guide.phi), t_guide)
    n_vec = perpendicular(t_vec)  # towards the upper surface
    centre = slider.point(s_j)
    rel_centre = centre - O
    limits = {surface: ctx.p(name, f"{surface}_limits") if f"{name}.{surface}_limits" in ctx.params else None
              for surface in ("upper", "lower")}
    side = {"upper": 1.0, "lower": -1.0}

    def surface_point(s: Any, surface: str) -> Any:
        return O + s * t_vec + side[surface] * 0.5 * H * n_vec  # (4.16) on the surface line

    terms: list[Term] = []
    forces: list[tuple[Any, Any, Any, Any]] = []  # per term: (F_N, F_T, v_T, p)

    def add_term(label: str, law_: Any, n_p: int, d: Any, d_dot: Any, point_slider: Any, point_guide: Any,
                 surface: Any) -> None:
        """The term of ``law_``'s force on the slider at ``point_slider`` (and friction), its opposite
        on the guide at ``point_guide``, (4.22)-(4.25)."""
        p = ca.SX.sym("p", n_p)
        F_N = law_.contact_force(d, d_dot, p[0] if n_p else None)
        n_in = -side[surface] * n_vec  # surface normal pointing into the guide
        v_T = ca.dot(slider.world_point_velocity(point_guide) - guide.world_point_velocity(point_guide), t_vec)
        F_T = 0.0 if friction_numeric.frictionless else friction.friction_force(F_N, v_T)

        def generalized(F_T: Any) -> Any:
            f_slider = F_N * n_in + F_T * t_vec
            return ctx.generalized_force([(joint.body_j, f_slider, point_slider),
                                          (joint.body_i, -f_slider, point_guide)])
        locked = None
        if not friction_numeric.frictionless and friction_numeric.kinks:
            locked = locked_force(f"{ident}_{label}_locked", ctx, p,
                                  lambda piece: generalized(friction.piece(F_N, v_T, piece)))
        terms.append(Term(f"{name}.{label}", ca.Function(f"{ident}_{label}_force", [ctx.t, ctx.q, ctx.v, p, ctx.P],
                                                          [generalized(F_T)], ["t", "q", "v", "p", "P"], ["Q"]), n_p,
                          locked))
        forces.append((F_N, F_T, v_T, p))

    corner_s, corner_d, corner_gap, corner_rate = [], [], [], []
    pair_names: list[str] = []
    energies: list[Any | None] = []  # per term: elastic energy stored while the term is on
    n_params = 1 if law_numeric.needs_approach_speed else 0
    for label, sign_l, sign_w, surface in CORNERS:
        local = s_j + sign_l * 0.5 * L * e_slider + sign_w * 0.5 * W * w_slider
        r_k = slider.point(local)  # (4.15)
        u = r_k - O
        s_k = ca.dot(t_vec, u)
        d_k = side[surface] * ca.dot(n_vec, u) - 0.5 * H  # (4.17)-(4.20): -n^T delta
        d_dot = ca.jtimes(d_k, ctx.q, ctx.v)  # (4.21) along the normal
        limit = limits[surface]
        gap = d_k if limit is None else ca.fmin(d_k, ca.fmin(s_k - limit[0], limit[1] - s_k))
        corner_s.append(s_k)
        corner_d.append(d_k)
        corner_gap.append(gap)
        corner_rate.append(d_dot)
        pair_names.append(f"{name}.{label}_{surface}")
        add_term(f"{label}_{surface}", law, n_params, d_k, d_dot, r_k, surface_point(s_k, surface), surface)
        energies.append(_elastic_energy(law_numeric, law, d_k))

    face_names: list[str] = []
    face_corners: list[tuple[int, int]] = []
    face_params = 0
    if face_law is not None and face_numeric is not None:
        face_params = 1 if face_numeric.needs_approach_speed else 0
        for face, a, b in FACES:
            surface = CORNERS[a][3]
            d_1, d_2, s_1, s_2 = corner_d[a], corner_d[b], corner_s[a], corner_s[b]
            d_mean = 0.5 * (d_1 + d_2)  # average penetration
            d_mean_dot = 0.5 * (corner_rate[a] + corner_rate[b])
            w_1, w_2 = ca.fmax(d_1, 0.0), ca.fmax(d_2, 0.0)
            # centroid of the penetrated trapezoid (sides d_1, d_2), measured along the guide
            s_gc = 0.5 * (s_1 + s_2) + (s_2 - s_1) * (w_2 - w_1) / (6.0 * (w_1 + w_2) + _CENTROID_EPS)
            point = surface_point(s_gc, surface)
            add_term(face, face_law, face_params, d_mean, d_mean_dot, point, point, surface)
            # Winkler potential of the linear law at the trapezoid's centroid (see module docstring)
            linear = getattr(face_numeric, "effective_exponent", 1.0) == 1.0 and face_numeric.stiffness is not None
            energies.append(face_law.stiffness * (w_1 * w_1 + w_1 * w_2 + w_2 * w_2) / 6.0 if linear else None)
            face_names.append(f"{name}.{face}")
            face_corners.append((a, b))

    rate = ca.Function(f"{ident}_rates", [ctx.q, ctx.v, ctx.P], [ca.vertcat(*corner_gap), ca.vertcat(*corner_rate)])
    n_corners = len(CORNERS)
    floor = approach_floor(ctx, law_numeric, f"{name}.law")
    face_floor = approach_floor(ctx, face_numeric, f"{name}.face_law") if face_numeric is not None else None

    n_q = ctx.n_q  # read once (a CasADi call), not at every binding

    def logic(P: NDArray[np.float64]) -> list[Any]:
        return [SliderGuideLogic(
            pairs=tuple(pair_names), first_root=first_root, pair_terms=tuple(first_term + i for i in range(n_corners)),
            face_names=tuple(face_names), face_terms=tuple(first_term + n_corners + f for f in range(len(face_names))),
            face_corners=tuple(face_corners), rate=BufferedFunction(rate, bound=(P,)), n_q=n_q,
            needs_approach=law_numeric.needs_approach_speed, min_approach_speed=floor(P),
            face_needs_approach=bool(face_numeric is not None and face_numeric.needs_approach_speed),
            face_min_approach_speed=face_floor(P) if face_floor is not None else 0.0,
        )]

    y_centre = ca.dot(n_vec, rel_centre)
    s_centre = ca.dot(t_vec, rel_centre)
    tilt = slider.phi - guide.phi + ctx.p(name, "tilt0")
    stroke = ctx.p(name, "stroke") if f"{name}.stroke" in ctx.params else None

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        def switched(k: int, expr: Any) -> Any:
            on, p_sym = switches[k]
            p = forces[k][3]
            return on * (ca.substitute(expr, p, p_sym) if p.numel() else expr)

        def friction_channels(prefix: str, k: int) -> list[Channel]:
            if friction.frictionless:
                return []
            return [Channel(f"{prefix}.friction_force", "N", switched(k, forces[k][1])),
                    Channel(f"{prefix}.sliding_velocity", "m/s", forces[k][2])]

        out = [
            Channel(f"{name}.s", "m", s_centre),
            Channel(f"{name}.y", "m", y_centre),
            Channel(f"{name}.tilt", "rad", tilt),
            Channel(f"{name}.eta", "", y_centre / (2.0 * c)),
        ]
        if stroke is not None:
            out.append(Channel(f"{name}.xi", "", (s_centre - stroke[0]) / (stroke[1] - stroke[0])))
        total = 0.0
        any_contact = 0.0
        in_face = [0.0] * n_corners
        for f, (a, b) in enumerate(face_corners):
            on_f = switches[n_corners + f][0]
            in_face[a] = in_face[a] + on_f
            in_face[b] = in_face[b] + on_f
        for k, label in enumerate(pair_names + face_names):  # the corners, then the faces
            F_N = switched(k, forces[k][0])
            total = total + F_N
            if k < n_corners:
                in_contact = switches[k][0] + in_face[k]
                any_contact = ca.fmax(any_contact, in_contact)
                out += [Channel(f"{label}.penetration", "m", corner_d[k]),
                        Channel(f"{label}.penetration_rate", "m/s", corner_rate[k])]
            else:
                a, b = face_corners[k - n_corners]
                in_contact = switches[k][0]
                out.append(Channel(f"{label}.penetration", "m", 0.5 * (corner_d[a] + corner_d[b])))
            out += [Channel(f"{label}.normal_force", "N", F_N), Channel(f"{label}.in_contact", "", in_contact),
                    *friction_channels(label, k)]
        if all(e is not None for e in energies):
            stored = sum(switches[k][0] * e for k, e in enumerate(energies))
            out.append(Channel(f"{name}.elastic_energy", "J", stored))
        out += [
            Channel(f"{name}.penetration", "m", ca.mmax(ca.vertcat(*corner_d))),
            Channel(f"{name}.normal_force", "N", total),
            Channel(f"{name}.in_contact", "", any_contact),
        ]
        return out

    # each term's friction kinks (a corner's or a face's)
    kinks = [(k, g) for k, (term, force) in enumerate(zip(terms, forces)) if term.locked is not None
             for g in friction_kinks(friction, force[2])]
    return ContactBuild(terms=terms, gaps=corner_gap, gap_names=pair_names, channels=channels, logic=logic,
                        ideal=[y_centre, tilt], ideal_names=[f"{name}.lateral", f"{name}.angle"],
                        kinks=[g for _, g in kinks], kink_terms=[k for k, _ in kinks])
