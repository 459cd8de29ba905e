"""Which options of a ready mechanism apply to which variant: the options that only a clearance joint
uses (refused when the mechanism has none, left out of its ideal reference), and each mechanism's
keyword options with their defaults and the first line of their description (``daeclear run MECH
--help``)."""

from __future__ import annotations

import inspect
import re
from typing import Any
from collections.abc import Callable

from ..core.errors import SceneError

#: Options that only a clearance joint uses, per ready mechanism (chain: every pin is one, none listed).
CLEARANCE_ONLY: dict[str, tuple[str, ...]] = {
    "slider_crank": ("clearance", "law", "restitution", "friction", "bearing_radius", "material", "length",
                     "contact_model", "face_law", "reading", "pin_offset", "bearing"),
    "four_bar": ("clearance", "law", "restitution", "friction", "bearing_radius", "material", "length"),
    "double_pendulum": ("clearance", "law", "restitution", "friction", "bearing_radius", "material", "length"),
}
#: The option of each mechanism that chooses its clearance joints, and its value for "none".
CHOOSER: dict[str, tuple[str, Any]] = {"slider_crank": ("joint", "ideal"), "four_bar": ("clearance_joints", ()),
                                       "double_pendulum": ("clearance_joints", ())}


def joint_names(joints: Any) -> tuple[Any, ...]:
    """Joint names from a sequence or a comma-separated string (``"B,C"``, as the command line's --set gives)."""
    if isinstance(joints, str):
        return tuple(j.strip() for j in joints.split(",") if j.strip())
    return tuple(joints)


def _same(value: Any, default: Any) -> bool:
    try:
        return bool(value is default or (type(value) is type(default) and value == default))
    except (TypeError, ValueError):  # e.g. an array compared element-wise
        return False


def refuse_clearance_options(mechanism: str, function: Callable[..., Any], given: dict[str, Any],
                             without: str) -> None:
    """Raise SceneError when ``given`` (the call's keyword values) sets an option that only a clearance
    joint uses while the mechanism has none (``without``: the choice that made it so)."""
    defaults = {p.name: p.default for p in inspect.signature(function).parameters.values()}
    for key in CLEARANCE_ONLY[mechanism]:
        if key in given and not _same(given[key], defaults[key]):
            raise SceneError(f"{mechanism}: {key}={given[key]!r} is for a clearance joint, but {without} has none; "
                             f"leave {key} out or choose a clearance joint ({CHOOSER[mechanism][0]}=...).")


def ideal_parameters(mechanism: str, params: dict[str, Any]) -> dict[str, Any] | None:
    """The parameters of the same ready mechanism with every joint ideal (the chapter's reference run): the
    options that apply to it only (its clearance joints' options and its name left out), or None when
    ``params`` give no clearance joint or the mechanism has no ideal counterpart (chain)."""
    if mechanism not in CHOOSER:
        return None
    key, none = CHOOSER[mechanism]
    value = params.get(key, none)
    try:
        ideal = str(value).lower() == "ideal" if key == "joint" else not joint_names(value)
    except TypeError:  # a bad value: the mechanism itself says what is wrong
        ideal = False
    if ideal:
        return None
    dropped = {*CLEARANCE_ONLY[mechanism], "name"}
    return {**{k: v for k, v in params.items() if k not in dropped}, key: none}


def option_table(function: Callable[..., Any]) -> list[tuple[str, str, str]]:
    """(name, default, first sentence of its description) for each keyword option of a ready mechanism,
    read from its signature and its numpy-style docstring (units are in the description)."""
    doc = inspect.getdoc(function) or ""
    described: dict[str, str] = {}
    lines = doc.splitlines()
    for i, line in enumerate(lines):
        match = re.match(r"^(\w+(?:, \w+)*)(?: : .*)?$", line)
        if match is None or i + 1 >= len(lines) or not lines[i + 1].startswith("    "):
            continue
        text = []
        for follow in lines[i + 1:]:
            if not follow.startswith("    "):
                break
            text.append(follow.strip())
        sentence = re.split(r"\.\s+(?=[A-Z])", " ".join(text))[0].rstrip(".")  # not at "Figs. 4.15"
        for name in match.group(1).split(","):
            described.setdefault(name.strip(), sentence)
    rows = []
    for p in inspect.signature(function).parameters.values():
        if p.kind is inspect.Parameter.VAR_KEYWORD:
            continue
        default = "required" if p.default is inspect.Parameter.empty else repr(p.default)
        rows.append((p.name, default, described.get(p.name, "")))
    return rows
