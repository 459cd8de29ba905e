"""The revolute clearance joint as a contact pair (parameters, force, gap, channels, logic), and the
registry of the clearance joints' builders.
"""

from __future__ import annotations

from typing import Any
from collections.abc import Callable, Sequence

from ..core.automaton import STORM_EVENTS, STORM_WINDOW  # noqa: F401  (re-exported: the storm guard's defaults)
from .parameters import law_structure
from ..model.scene import RevoluteClearance
from .symbolic import AssemblyContext, Channel, Reference, Term
from .contact_pairs import PairLogic, ContactBuild, journal_contact, journal_logic, journal_parameters
from .lubricated_joint import build_lubricated_revolute, lubricated_parameters
from ..contact.wear import profile_coefficients
from .translational_joint import (
    TranslationalClearance, build_translational_clearance, translational_clearance_parameters)


def revolute_clearance_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[Any]]:
    """The joint's numbers (run-time parameters) and what of it is structure, by its law's journal model
    (:data:`JOURNAL_MODELS`)."""
    return JOURNAL_MODELS[joint.resolved_law().journal_model][0](ref, joint)


def dry_journal_parameters(ref: Reference, joint: RevoluteClearance) -> tuple[dict[str, Any], list[Any]]:
    """A dry journal's numbers (run-time parameters) and what of it is structure."""
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
    """A revolute clearance joint by its law's journal model (:data:`JOURNAL_MODELS`)."""
    return JOURNAL_MODELS[joint.resolved_law().journal_model][1](ctx, joint, first_term, first_root)


def build_dry_journal(ctx: AssemblyContext, joint: RevoluteClearance, first_term: int,
                      first_root: int) -> ContactBuild:
    """Journal-bearing contact (section 4.2), eqs. (4.1)-(4.13)."""
    name = joint.name
    law_numeric, friction_numeric = joint.resolved_law(), joint.resolved_friction()
    jc = journal_contact(ctx, joint, law_numeric, friction_numeric)
    e, c = jc.e, jc.c
    gap = (jc.ee - c * c) / (2.0 * c)  # smooth at e = 0; equals delta (1 + delta / 2c) near contact
    logic = journal_logic(ctx, jc, PairLogic, name, first_root, first_term, [gap], law_numeric, friction_numeric)

    def channels(switches: Sequence[tuple[Any, Any]]) -> list[Channel]:
        on, p_sym = switches[0]
        return jc.channels(name, on, p_sym, friction_numeric.frictionless)

    return ContactBuild(terms=[Term(name, jc.force, jc.n_params, jc.locked)], gaps=[gap], gap_names=[name],
                        channels=channels, logic=logic, ideal=[e[0], e[1]], ideal_names=[f"{name}.x", f"{name}.y"],
                        kinks=list(jc.kinks), kink_terms=[0] * len(jc.kinks))


#: A revolute clearance joint's law's ``journal_model`` -> (parameter function, builder): a normal law makes
#: a dry journal, a HydrodynamicBearing a lubricated one (daeclear.assembly.lubricated_joint).
JOURNAL_MODELS: dict[str, tuple[Callable[..., tuple[dict[str, Any], list[Any]]], Callable[..., ContactBuild]]] = {
    "dry": (dry_journal_parameters, build_dry_journal),
    "lubricated": (lubricated_parameters, build_lubricated_revolute),
}

#: Clearance joint type -> (parameter function, builder).
CONTACT_BUILDERS: dict[type, tuple[Callable[..., tuple[dict[str, Any], list[Any]]], Callable[..., ContactBuild]]] = {
    RevoluteClearance: (revolute_clearance_parameters, build_revolute_clearance),
    TranslationalClearance: (translational_clearance_parameters, build_translational_clearance)}
