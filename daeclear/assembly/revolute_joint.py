"""The revolute clearance joint: a journal in a bearing as a contact pair (its parameters, force,
gap, output channels and event logic), and the registry of the clearance joints' builders.

The contact-pair machinery it shares with the translational joint is :mod:`daeclear.assembly.contact_pairs`.
"""

from __future__ import annotations

from typing import Any
from collections.abc import Callable, Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from .automaton import STORM_EVENTS, STORM_WINDOW  # noqa: F401  (re-exported: the storm guard's defaults)
from .parameters import law_structure, law_values, symbolic_law
from ..model.scene import RevoluteClearance
from .symbolic import AssemblyContext, BufferedFunction, Channel, Reference, Term, perpendicular
from .contact_pairs import PairLogic, ContactBuild, approach_floor
from .lubricated_joint import build_lubricated_revolute, lubricated_parameters
from ..contact.hydrodynamic import HydrodynamicBearing
from .translational_joint import (
    TranslationalClearance, build_translational_clearance, translational_clearance_parameters)


def revolute_clearance_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[str]]:
    """The joint's numbers (run-time parameters) and what of it is structure."""
    if isinstance(joint.law, HydrodynamicBearing):
        return lubricated_parameters(ref, joint)
    law, friction = joint.resolved_law(), joint.resolved_friction()
    s_i, s_j = ref.joint_points(joint)
    values: dict[str, Any] = {"s_i": s_i, "s_j": s_j, "clearance": joint.radial_clearance,
                              "bearing_radius": float(joint.bearing_radius), "journal_radius": joint.journal}
    values.update({f"law.{k}": v for k, v in law_values(law).items()})
    values.update({f"friction.{k}": v for k, v in law_values(friction).items()})
    return values, [law_structure(law), law_structure(friction)]


def build_revolute_clearance(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                             first_root: int) -> ContactBuild:
    """Journal-bearing contact (section 4.2): eqs. (4.1)-(4.13) with the joint's laws.

    Body i carries the bearing (radius R_i), body j the journal (R_j); c = R_i - R_j. Every
    number comes from the run-time parameters ``<joint>.*`` (see revolute_clearance_parameters).
    A lubricated joint (law HydrodynamicBearing) is :func:`build_lubricated_revolute`'s.
    """
    if isinstance(joint.law, HydrodynamicBearing):
        return build_lubricated_revolute(ctx, joint, first_term, first_root)
    name = joint.name
    law_numeric, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    law = symbolic_law(law_numeric, ctx.params, f"{name}.law")
    friction = symbolic_law(friction_numeric, ctx.params, f"{name}.friction")
    c = ctx.p(name, "clearance")
    R_i, R_j = ctx.p(name, "bearing_radius"), ctx.p(name, "journal_radius")
    s_i, s_j = ctx.p(name, "s_i"), ctx.p(name, "s_j")
    bi, bj = ctx.frames[joint.body_i], ctx.frames[joint.body_j]
    P_i, P_j = bi.point(s_i), bj.point(s_j)  # (4.2)
    e = P_j - P_i  # (4.1) eccentricity
    e_dot = bj.point_velocity(s_j) - bi.point_velocity(s_i)
    ee = ca.dot(e, e)
    gap = (ee - c * c) / (2.0 * c)  # smooth at e = 0; equals delta (1 + delta / 2c) near contact

    # in contact |e| >= c > 0: the normal and everything below are regular there
    e_norm = ca.sqrt(ee)
    n = e / e_norm  # (4.4)
    delta = e_norm - c  # (4.5)
    delta_dot = ca.dot(e_dot, n)  # (4.8): v_N = d|e|/dt
    t_vec = perpendicular(n)
    Q_i = P_i + R_i * n  # (4.6) contact points
    Q_j = P_j + R_j * n
    # (4.9) with the velocities of the material points at the contact (spin included)
    v_T = ca.dot(bj.world_point_velocity(Q_j) - bi.world_point_velocity(Q_i), t_vec)

    n_params = 1 if law_numeric.needs_approach_speed else 0
    p = ca.SX.sym("p", n_params)
    F_N = law.force(delta, delta_dot, p[0] if n_params else None)
    F_T = 0.0 if friction_numeric.frictionless else friction.friction_force(F_N, v_T)
    f_journal = -F_N * n + F_T * t_vec  # force on the journal (body j); the bearing gets the opposite
    Q = ctx.generalized_force([(joint.body_j, f_journal, Q_j), (joint.body_i, -f_journal, Q_i)])
    force = ca.Function(f"{name}_force", [ctx.t, ctx.q, ctx.v, p, ctx.P], [Q], ["t", "q", "v", "p", "P"], ["Q"])
    rate = ca.Function(f"{name}_rate", [ctx.q, ctx.v, ctx.P], [gap, ca.dot(e_dot, e) / ca.fmax(e_norm, 1e-300)])
    floor = approach_floor(ctx, law_numeric, f"{name}.law")
    discontinuous = not friction_numeric.frictionless and not friction_numeric.smooth
    n_q = ctx.n_q  # read once: a CasADi call costs more inside a sweep's loop than the logic it makes

    def logic(P: NDArray[np.float64]) -> list[Any]:
        return [PairLogic(name, first_root, first_term, BufferedFunction(rate, bound=(P,)), n_q,
                          law_numeric.needs_approach_speed, floor(P), discontinuous_friction=discontinuous)]

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        on, p_sym = switches[0]
        F_N_out = on * ca.substitute(F_N, p, p_sym) if n_params else on * F_N
        out = [
            Channel(f"{name}.ex", "m", e[0]),
            Channel(f"{name}.ey", "m", e[1]),
            Channel(f"{name}.eccentricity", "m", e_norm),
            Channel(f"{name}.penetration", "m", e_norm - c),
            Channel(f"{name}.penetration_rate", "m/s", ca.dot(e_dot, e) / ca.fmax(e_norm, 1e-300)),
            Channel(f"{name}.normal_force", "N", F_N_out),
            Channel(f"{name}.in_contact", "", on),
        ]
        if not friction_numeric.frictionless:
            F_T_out = on * (ca.substitute(F_T, p, p_sym) if n_params else F_T)
            out += [Channel(f"{name}.friction_force", "N", F_T_out),
                    Channel(f"{name}.sliding_velocity", "m/s", v_T)]
        return out

    return ContactBuild(terms=[Term(name, force, n_params)], gaps=[gap], gap_names=[name],
                        channels=channels, logic=logic, ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"])


#: Clearance joint type -> (parameter function, builder).
CONTACT_BUILDERS: dict[type, tuple[Callable[..., tuple[dict[str, Any], list[Any]]], Callable[..., ContactBuild]]] = {
    RevoluteClearance: (revolute_clearance_parameters, build_revolute_clearance)}

CONTACT_BUILDERS[TranslationalClearance] = (translational_clearance_parameters, build_translational_clearance)
