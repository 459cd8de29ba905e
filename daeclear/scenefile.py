"""Scene files (TOML): a named mechanism with its parameters, or a scene element by element.

A mechanism file::

    [mechanism]
    name = "slider_crank"
    joint = "ideal"
    rpm = 5000.0

    [simulate]
    t_end = 0.024
    rtol = 1e-6

A scene file (tables map key for key onto the Python classes)::

    [scene]
    name = "pendulum"
    gravity = [0.0, -9.81]

    [[body]]
    name = "link"
    mass = 1.0
    inertia = 0.01
    position = [0.5, 0.0]

    [[revolute]]
    name = "A"
    body_i = "ground"
    body_j = "link"
    at = [0.0, 0.0]

Clearance joints (tables ``[[revolute_clearance]]`` and ``[[translational_clearance]]``) take
their materials and laws as tables::

    [[revolute_clearance]]
    name = "clearance"
    body_i = "slider"
    body_j = "rod"
    at = [0.17, 0.0]
    bearing_radius = 0.01
    clearance = 0.5e-3
    material = { young = 207e9, poisson = 0.3 }
    law = { name = "lankarani-nikravesh", restitution = 0.9 }
    friction = 0.05          # or "coulomb", or { name = "modified-coulomb", coefficient = 0.1 }

Unknown tables or keys are errors that name the file, the table and the key.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from pathlib import Path
from typing import Any, Callable

from . import mechanisms, options
from .errors import SceneError
from .contact import Material, friction_law, normal_law
from .scene import Body, Driver, Revolute, RevoluteClearance, Scene, Translational, TranslationalClearance

MECHANISMS: dict[str, Callable[..., Scene]] = {"slider_crank": mechanisms.slider_crank, "chain": mechanisms.chain}
ELEMENT_TABLES: dict[str, type] = {
    "body": Body, "revolute": Revolute, "translational": Translational, "driver": Driver,
    "revolute_clearance": RevoluteClearance, "translational_clearance": TranslationalClearance,
}
SIMULATE_KEYS = ("t_end", "rtol", "atol", "formulation", "method", "backend", "max_step", "t_eval_step")


@dataclasses.dataclass(frozen=True)
class SceneFile:
    """What a scene file declares: the scene, and the simulation options it asks for."""

    scene: Scene
    simulate: dict[str, Any]
    source: dict[str, Any]


def _law(value: Any, build: Any) -> Any:
    """A law given as a name, a number (friction coefficient) or a table {name = ..., parameters}."""
    if isinstance(value, dict):
        params = dict(value)
        return build(params.pop("name", None), **params)
    return value


def _contact_fields(entry: dict[str, Any]) -> dict[str, Any]:
    """Clearance joints: material tables -> Material, law tables -> law objects."""
    out = dict(entry)
    material = out.get("material")
    if isinstance(material, dict):
        out["material"] = Material(**material)
    elif isinstance(material, list):
        out["material"] = tuple(Material(**m) for m in material)
    for key in ("law", "face_law"):
        if key in out:
            out[key] = _law(out[key], normal_law)
    if isinstance(out.get("friction"), dict):
        out["friction"] = _law(out["friction"], friction_law)
    return out


def _element(path: Path, table: str, index: int, cls: type, entry: dict[str, Any]) -> Any:
    allowed = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(entry) - set(allowed))
    if unknown:
        raise SceneError(f"{path}: [[{table}]] #{index + 1}: unknown key(s) {', '.join(unknown)}; "
                         f"allowed: {', '.join(allowed)}.")
    try:
        if cls in (RevoluteClearance, TranslationalClearance):
            entry = _contact_fields(entry)
        return cls(**entry)
    except (TypeError, SceneError) as exc:
        raise SceneError(f"{path}: [[{table}]] #{index + 1}: {exc}") from None


def check_simulate(simulate: dict[str, Any], *, where: str) -> dict[str, Any]:
    """The [simulate] table checked by the rules simulate() applies (daeclear.options), none ignored:
    ``t_end = 0`` or ``t_eval_step = 0`` are errors, not "use the default"."""
    out = dict(simulate)
    if "t_end" in out:
        out["t_end"] = options.t_end(out["t_end"], where=where)
    if "rtol" in out:
        out["rtol"] = options.rtol(out["rtol"], where=where)
    if "atol" in out:
        atol = options.atol(out["atol"], where=where)
        out["atol"] = atol.tolist() if hasattr(atol, "tolist") else atol
    if "max_step" in out:
        out["max_step"] = options.max_step(out["max_step"], where=where)
    for key, rule in (("method", options.method), ("formulation", options.formulation),
                      ("backend", options.backend)):
        if key in out:
            out[key] = rule(out[key], where=where)
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
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SceneError(f"scene file {path} does not exist.") from None
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML ({exc}).") from None
    simulate = dict(data.get("simulate", {}))
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
        params = dict(data["mechanism"])
        name = str(params.pop("name", ""))
        if name not in MECHANISMS:
            raise SceneError(f"{path}: [mechanism] name={name!r}, must be one of {', '.join(MECHANISMS)}.")
        try:
            scene = MECHANISMS[name](**params)
        except TypeError as exc:  # a missing required parameter, e.g. chain's n_links
            raise SceneError(f"{path}: [mechanism] {exc}.") from None
        return SceneFile(scene, simulate, data)
    allowed_tables = {"scene", "simulate", *ELEMENT_TABLES}
    extra = sorted(set(data) - allowed_tables)
    if extra:
        raise SceneError(f"{path}: unknown table(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed_tables))}.")
    head = dict(data.get("scene", {}))
    unknown_head = sorted(set(head) - {"name", "gravity"})
    if unknown_head:
        raise SceneError(f"{path}: [scene]: unknown key(s) {', '.join(unknown_head)}; allowed: name, gravity.")
    scene = Scene(str(head.get("name", path.stem)), gravity=tuple(head.get("gravity", (0.0, -9.81))))
    for table, cls in ELEMENT_TABLES.items():
        for i, entry in enumerate(data.get(table, [])):
            scene.add(_element(path, table, i, cls, entry))
    scene.validate()
    return SceneFile(scene, simulate, data)
