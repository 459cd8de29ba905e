"""Scene files (TOML): a named mechanism with its parameters, or a scene element by element.

The format, with examples: docs/scene_files.md. Unknown tables or keys are errors that name the
file, the table and the key.
"""

from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from pathlib import Path
from typing import Any
from collections.abc import Callable, Mapping

from . import mechanisms
from ..core import options
from ..core.errors import SceneError
from ..core.values import to_plain
from .clearance_joints import TABLE_FIELDS, table_value
from .profiles import profile_from_dict
from .loads import Force, Motor, RotationalSpringDamper, SpringDamper, Table, Torque
from .scene import (Body, Driver, Revolute, RevoluteClearance, Scene, Translational, TranslationalClearance,
                    clearance_joint)

MECHANISMS: dict[str, Callable[..., Scene]] = {
    "slider_crank": mechanisms.slider_crank, "chain": mechanisms.chain, "four_bar": mechanisms.four_bar,
    "double_pendulum": mechanisms.double_pendulum,
}
ELEMENT_TABLES: dict[str, type] = {
    "body": Body, "revolute": Revolute, "translational": Translational, "driver": Driver,
    "revolute_clearance": RevoluteClearance, "translational_clearance": TranslationalClearance,
    "force": Force, "torque": Torque, "spring_damper": SpringDamper,
    "rotational_spring_damper": RotationalSpringDamper, "motor": Motor,
}
SIMULATE_KEYS = ("t_end", "rtol", "atol", "formulation", "method", "backend", "max_step", "t_eval_step", "start",
                 "allow_penetration", "step")
#: Keys of loads whose value may be a table in time, ``{ times = [...], values = [...] }``.
LOAD_VALUE_KEYS = ("fx", "fy", "value")


@dataclasses.dataclass(frozen=True)
class SceneFile:
    """What a scene file declares: the scene, and the simulation options it asks for."""

    scene: Scene
    simulate: dict[str, Any]
    source: dict[str, Any]


def _contact_fields(entry: dict[str, Any]) -> dict[str, Any]:
    """Clearance joints: material tables -> Material, law tables -> law objects; an error names its key."""
    out = dict(entry)
    key = ""
    try:
        for key in TABLE_FIELDS:  # tables: {young, poisson}, {name = ..., parameters}, ArchardWear's fields
            if key in out:
                out[key] = table_value(key, out[key])
    except (TypeError, ValueError, SceneError) as exc:
        raise SceneError(f"key {key}: {exc}") from None
    return out


def _profile_field(entry: dict[str, Any]) -> dict[str, Any]:
    """A driver's profile table {kind = "ramp", time = 0.01} -> the profile object; an error names the key."""
    try:
        return {**entry, "profile": profile_from_dict(entry["profile"])}
    except (TypeError, ValueError) as exc:
        raise SceneError(f"key profile: {exc} (e.g. profile = {{ kind = \"ramp\", time = 0.01 }}).") from None


def _load_values(entry: dict[str, Any]) -> dict[str, Any]:
    """Loads: a value written as a table {times, values} -> a daeclear.Table; an error names its key."""
    out = dict(entry)
    for key in LOAD_VALUE_KEYS:
        value = out.get(key)
        if isinstance(value, dict):
            unknown = sorted(set(value) - {"times", "values"})
            if unknown or len(value) != 2:
                raise SceneError(f"key {key}: unknown key(s) {', '.join(unknown) or '(none)'}; allowed: times, "
                                 "values (both required).")
            out[key] = Table(value["times"], value["values"])
    return out


def _single_table(path: Path, data: dict[str, Any], table: str) -> dict[str, Any]:
    """``[table]``: one table; ``[[table]]`` or ``table = ...`` written instead is named as such."""
    value = data.get(table, {})
    if isinstance(value, dict):
        return dict(value)
    if isinstance(value, list):
        raise SceneError(f"{path}: [[{table}]] is an array of tables; {table} is a single table: write "
                         f"[{table}] (one pair of brackets), once.")
    raise SceneError(f"{path}: {table} = {value!r} is {_a(value)}; {table} is a table: write [{table}] "
                     "on its own line with its keys below it.")


def _array_of_tables(path: Path, data: dict[str, Any], table: str) -> list[dict[str, Any]]:
    """``[[table]]`` entries; a single ``[table]`` (or a value) written instead is named as such."""
    value = data.get(table, [])
    if isinstance(value, dict):
        raise SceneError(f"{path}: [{table}] is a single table; scene elements are arrays of tables: write "
                         f"[[{table}]] (two pairs of brackets) before each {table}.")
    if not isinstance(value, list) or not all(isinstance(entry, dict) for entry in value):
        raise SceneError(f"{path}: {table} = {value!r} is {_a(value)}; write each {table} as a table "
                         f"[[{table}]] with its keys below it.")
    return value


#: The TOML names of value types, for messages (bool before int: True is an int).
TOML_TYPES: tuple[tuple[type | tuple[type, ...], str], ...] = (
    (bool, "boolean"), ((int, float), "number"), (str, "string"), (list, "array"), (dict, "table"))


def _a(value: Any) -> str:
    """'a number', 'an array', ...: the TOML type of a value with its article."""
    kind = next((name for types, name in TOML_TYPES if isinstance(value, types)), type(value).__name__)
    return f"an {kind}" if kind[0] in "aeiou" else f"a {kind}"


def _element(path: Path, table: str, index: int, cls: type, entry: dict[str, Any]) -> Any:
    label = f"{path}: [[{table}]] #{index + 1}"
    if cls in (Revolute, Translational) and "clearance" in entry:  # an ideal joint given a clearance
        entry = dict(entry)
        table_value = entry.pop("clearance")
        ideal = _element(path, table, index, cls, entry)
        if not isinstance(table_value, dict):
            raise SceneError(f"{label}: key clearance = {table_value!r} is {_a(table_value)}, must be a table of the "
                             "clearance joint's fields, e.g. "
                             "clearance = { clearance = 0.5e-3, bearing_radius = 0.01 }.")
        try:
            return clearance_joint(ideal, **_contact_fields(table_value))
        except (TypeError, ValueError, SceneError) as exc:
            raise SceneError(f"{label}: key clearance: {exc}") from None
    fields = dataclasses.fields(cls)
    allowed = [f.name for f in fields]
    unknown = sorted(set(entry) - set(allowed))
    if unknown:
        raise SceneError(f"{label}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(allowed)}.")
    for f in fields:  # names of the element and of the bodies and joints it refers to
        if f.type in ("str", str) and f.name in entry and not isinstance(entry[f.name], str):
            value = entry[f.name]
            raise SceneError(f"{label}: key {f.name} = {value!r} is {_a(value)}, must be a string "
                             f"(in quotes: {f.name} = \"{value}\").")
    try:
        if cls in (RevoluteClearance, TranslationalClearance):
            entry = _contact_fields(entry)
        if cls is Driver and isinstance(entry.get("profile"), dict):
            entry = _profile_field(entry)
        if cls in (Force, Torque):
            entry = _load_values(entry)
        element = cls(**entry)
    except (TypeError, ValueError, SceneError) as exc:
        text = str(exc)
        raise SceneError(f"{label}: {text if text.startswith('key ') else _with_key(text, entry)}") from None
    problems = element.problems()
    if problems:
        raise SceneError(f"{label}: " + " ".join(_with_key(p, entry) for p in problems))
    return element


def _with_key(problem: str, entry: dict[str, Any]) -> str:
    """A problem message that names the key it is about (the message names the field as ``key=``)."""
    keys = [key for key in entry if re.search(rf"\b{re.escape(key)}s?=", problem)]
    return f"key {keys[0]}: {problem}" if keys else problem


def check_simulate(simulate: dict[str, Any], *, where: str) -> dict[str, Any]:
    """The [simulate] table checked by the rules simulate() applies (daeclear.core.options), none ignored:
    ``t_end = 0`` or ``t_eval_step = 0`` are errors, not "use the default"."""
    out = dict(simulate)
    for key, rule in (("t_end", options.t_end), ("rtol", options.rtol), ("atol", options.atol),
                      ("max_step", options.max_step)):
        if key in out:
            out[key] = rule(out[key], where=where)
    if out.get("atol") is not None and not isinstance(out["atol"], (float, dict)):  # an array: a list
        out["atol"] = out["atol"].tolist()
    if "step" in out:  # the fixed step of method = "rk4" / "euler" (simulate refuses it with the others)
        out["step"] = options.step(out["step"], where=where)
        options.step_within(out["step"], 0.0, out.get("t_end", math.inf), where=where)
    if "allow_penetration" in out:
        out["allow_penetration"] = options.flag(out["allow_penetration"], where=where, field="allow_penetration")
    for key, name_rule in (("method", options.method), ("formulation", options.formulation),
                           ("backend", options.backend), ("start", options.start)):
        if key in out:
            out[key] = name_rule(out[key], where=where)
    if "t_eval_step" in out:
        # against the file's t_end when it has one (the command line checks it again against the end it runs)
        end = out.get("t_end", math.inf)
        out["t_eval_step"] = options.number(out["t_eval_step"], where=where, field="t_eval_step", unit="s", low=0.0,
                                            high=None if math.isinf(end) else end)
    return out


def read_scene_file(path: str | Path) -> SceneFile:
    """Read and validate a TOML scene file; raise SceneError naming the file, table and key."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SceneError(f"scene file {path} does not exist.") from None
    except UnicodeDecodeError as exc:  # a binary file, or another encoding
        raise SceneError(f"{path}: not a text file in UTF-8 (byte {exc.start}: {exc.reason}); a scene file is "
                         "TOML text.") from None
    except OSError as exc:  # a folder, no permission
        raise SceneError(f"scene file {path} cannot be read ({exc.strerror or exc}).") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc}).") from None
    simulate = _single_table(path, data, "simulate")
    unknown_sim = sorted(set(simulate) - set(SIMULATE_KEYS))
    if unknown_sim:
        raise SceneError(f"{path}: [simulate]: unknown key(s) {', '.join(unknown_sim)}; "
                         f"allowed: {', '.join(SIMULATE_KEYS)}.")
    simulate = check_simulate(simulate, where=f"{path}: [simulate]")
    if "mechanism" in data:
        extra = sorted(set(data) - {"mechanism", "simulate"})
        if extra:
            raise SceneError(f"{path}: a [mechanism] file takes only [mechanism] and [simulate]; "
                             f"found {', '.join(extra)}.")
        params = _single_table(path, data, "mechanism")
        name = params.pop("name", "")
        if name not in MECHANISMS:
            raise SceneError(f"{path}: [mechanism]: key name = {name!r}, must be one of {', '.join(MECHANISMS)}.")
        try:
            scene = MECHANISMS[name](**params)
        except TypeError as exc:  # a missing required parameter, e.g. chain's n_links
            raise SceneError(f"{path}: [mechanism] {exc}.") from None
        except SceneError as exc:  # a parameter's value: the rule, with the file and the table
            raise SceneError(f"{path}: [mechanism]: {_with_key(str(exc), params)}") from None
        return SceneFile(scene, simulate, data)
    allowed_tables = {"scene", "simulate", *ELEMENT_TABLES}
    extra = sorted(set(data) - allowed_tables)
    if extra:
        raise SceneError(f"{path}: unknown table(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed_tables))}.")
    head = _single_table(path, data, "scene")
    unknown_head = sorted(set(head) - {"name", "gravity"})
    if unknown_head:
        raise SceneError(f"{path}: [scene]: unknown key(s) {', '.join(unknown_head)}; allowed: name, gravity.")
    name = head.get("name", path.stem)
    if not isinstance(name, str):
        raise SceneError(f"{path}: [scene]: key name = {name!r} is {_a(name)}, must be a string "
                         f"(in quotes: name = \"{name}\").")
    gravity = head.get("gravity", [0.0, -9.81])
    if not isinstance(gravity, list):
        raise SceneError(f"{path}: [scene]: key gravity = {gravity!r} is {_a(gravity)}, must be an array "
                         "of two numbers (m/s^2), e.g. gravity = [0.0, -9.81].")
    try:
        scene = Scene(name, gravity=tuple(gravity))
    except SceneError as exc:
        raise SceneError(f"{path}: [scene]: key gravity: {exc}") from None
    try:
        for table, cls in ELEMENT_TABLES.items():
            for i, entry in enumerate(_array_of_tables(path, data, table)):
                scene.add(_element(path, table, i, cls, entry))
        scene.validate()
    except SceneError as exc:  # the scene as a whole (names, references): the file, then the rule
        text = str(exc)
        if text.startswith(f"scene {name!r}: gravity="):
            text = f"[scene]: key gravity: {text}"
        raise SceneError(text if text.startswith(str(path)) else f"{path}: {text}") from None
    return SceneFile(scene, simulate, data)


def scene_from_description(description: Mapping[str, Any]) -> Scene:
    """The scene that :meth:`Scene.to_dict` described (a result file's ``parameters["scene"]``), element
    by element as a scene file's tables; SceneError when an element cannot be rebuilt from plain data
    (its kind unknown, or a value that was not plain data, such as a Python callable)."""
    tables = {cls.__name__: (table, cls) for table, cls in ELEMENT_TABLES.items()}
    where = Path(f"scene '{description.get('name', '')}'")
    scene = Scene(str(description["name"]), gravity=tuple(description["gravity"]))
    for i, entry in enumerate(description["elements"].values()):
        entry = dict(entry)
        kind = entry.pop("kind", None)
        if kind not in tables:
            raise SceneError(f"{where}: element {entry.get('name')!r} has kind={kind!r}, must be one of "
                             f"{', '.join(tables)} to be rebuilt.")
        table, cls = tables[kind]
        if cls is Driver and entry.get("profile") is None:
            entry.pop("profile", None)
        scene.add(_element(where, table, i, cls, entry))
    scene.validate()
    if to_plain(scene.to_dict(), "scene") != to_plain(dict(description), "scene"):
        raise SceneError(f"{where}: the scene rebuilt from its description differs from it (a value that is "
                         "not plain data).")
    return scene
