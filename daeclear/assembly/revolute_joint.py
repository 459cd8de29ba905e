"""The revolute clearance joint as a contact pair (parameters, force, gap, channels, logic), and the
registry of the clearance joints' builders.
"""

from __future__ import annotations

from typing import Any
from collections.abc import Callable, Sequence

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from .automaton import STORM_EVENTS, STORM_WINDOW  # noqa: F401  (re-exported: the storm guard's defaults)
from .parameters import law_structure
from ..model.scene import RevoluteClearance
from .symbolic import AssemblyContext, BufferedFunction, Channel, Reference, Term
from .contact_pairs import PairLogic, ContactBuild, approach_floor, journal_contact, journal_parameters
from .lubricated_joint import build_lubricated_revolute, lubricated_parameters
from ..contact.hydrodynamic import HydrodynamicBearing
from ..contact.wear import profile_coefficients
from .translational_joint import (
    TranslationalClearance, build_translational_clearance, translational_clearance_parameters)


def revolute_clearance_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[str]]:
    """The joint's numbers (run-time parameters) and what of it is structure."""
    if isinstance(joint.law, HydrodynamicBearing):
        return lubricated_parameters(ref, joint)
    law, friction = joint.resolved_law(), joint.resolved_friction()
    values = journal_parameters(ref, joint, law, friction)
    structure = [law_structure(law), law_structure(friction)]
    if joint.wear is not None:  # the worn profiles' Fourier coefficients; how many is structure
        for surface, depth in joint.worn_profiles().items():
            a, b = profile_coefficients(depth, joint.wear.modes)
            values[f"wear.{surface}_cos"], values[f"wear.{surface}_sin"] = a, b
        structure.append(f"wear:{','.join(joint.wear.surfaces)}:{joint.wear.modes}")
    return values, structure


def build_revolute_clearance(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                             first_root: int) -> ContactBuild:
    """Journal-bearing contact (section 4.2), eqs. (4.1)-(4.13); a lubricated joint is
    :func:`build_lubricated_revolute`'s."""
    if isinstance(joint.law, HydrodynamicBearing):
        return build_lubricated_revolute(ctx, joint, first_term, first_root)
    name = joint.name
    law_numeric, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    jc = journal_contact(ctx, joint, law_numeric, friction_numeric)
    e, e_dot, e_norm, c = jc.e, jc.e_dot, jc.e_norm, jc.c
    gap = (jc.ee - c * c) / (2.0 * c)  # smooth at e = 0; equals delta (1 + delta / 2c) near contact
    rate = ca.Function(f"{name}_rate", [ctx.q, ctx.v, ctx.P], [gap, ca.dot(e_dot, e) / ca.fmax(e_norm, 1e-300)])
    floor = approach_floor(ctx, law_numeric, f"{name}.law")
    discontinuous = not friction_numeric.frictionless and not friction_numeric.smooth
    n_q = ctx.n_q  # read once: a CasADi call costs more inside a sweep's loop than the logic it makes

    def logic(P: NDArray[np.float64]) -> list[Any]:
        return [PairLogic((name,), first_root, (first_term,), BufferedFunction(rate, bound=(P,)), n_q,
                          law_numeric.needs_approach_speed, floor(P), discontinuous_friction=discontinuous)]

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        on, p_sym = switches[0]
        return jc.channels(name, on, p_sym, friction_numeric.frictionless)

    return ContactBuild(terms=[Term(name, jc.force, jc.n_params)], gaps=[gap], gap_names=[name],
                        channels=channels, logic=logic, ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"])


#: Clearance joint type -> (parameter function, builder).
CONTACT_BUILDERS: dict[type, tuple[Callable[..., tuple[dict[str, Any], list[Any]]], Callable[..., ContactBuild]]] = {
    RevoluteClearance: (revolute_clearance_parameters, build_revolute_clearance)}

CONTACT_BUILDERS[TranslationalClearance] = (translational_clearance_parameters, build_translational_clearance)
