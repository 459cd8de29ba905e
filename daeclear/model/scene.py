"""Scene: the container of a planar mechanism's bodies, joints, drivers and loads, with its gravity.

Plain data, no CasADi. ``Scene.validate()`` raises one :class:`~daeclear.core.errors.SceneError` listing
every problem (each element's own and those between elements). The elements
(:mod:`daeclear.model.elements`, :mod:`daeclear.model.clearance_joints`) are re-exported here.
"""

from __future__ import annotations

import dataclasses
import difflib
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Iterable, Iterator, Mapping

from ..core.errors import SceneError
# the elements, re-exported: ``from daeclear.model.scene import Body`` keeps working
from .clearance_joints import (RevoluteClearance, TranslationalClearance, clearance_joint,  # noqa: F401
                               driven_coordinate, ideal_joint, table_value)
from .elements import (GROUND, Body, Driver, Element, Ground, Joint, PointJoint, Revolute,  # noqa: F401
                       Translational, Vector2, as_vector2, is_finite_number, is_frozen, own_problems)

def _did_you_mean(name: str, names: Iterable[str], n: int = 3) -> str:
    close = difflib.get_close_matches(name, list(names), n=n)
    return f" Did you mean {', '.join(repr(c) for c in close)}?" if close else ""


@dataclass
class Scene:
    """A planar mechanism: bodies, joints and drivers, a fixed ground and gravity.

    Parameters
    ----------
    name : str
        Scene name (results and files carry it).
    gravity : (float, float)
        Gravitational acceleration vector, m/s^2; ``(0, -9.81)`` by default.

    Examples
    --------
    >>> scene = Scene("pendulum")
    >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
    >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    >>> scene.validate()
    """

    name: str
    gravity: Vector2 = (0.0, -9.81)
    elements: list[Element] = field(default_factory=list)
    ground: Ground = field(default_factory=Ground)

    def add(self, element: Element) -> Any:
        """Add an element and return it (so ``crank = scene.add(Body(...))`` reads well)."""
        if not isinstance(element, Element):
            raise SceneError(f"scene '{self.name}': cannot add {element!r}; expected a Body, joint, Driver or load "
                             "(daeclear.loads).")
        self.elements.append(element)
        return element

    def __iter__(self) -> Iterator[Element]:
        return iter(self.elements)

    @property
    def bodies(self) -> list[Body]:
        return [e for e in self.elements if isinstance(e, Body)]

    @property
    def joints(self) -> list[Joint]:
        return [e for e in self.elements if isinstance(e, Joint)]

    @property
    def drivers(self) -> list[Driver]:
        return [e for e in self.elements if isinstance(e, Driver)]

    def with_clearance(self, joint: str, *, bearing: str | None = None, name: str | None = None,
                       **fields_: Any) -> Scene:
        """A new scene in which the ideal revolute or translational ``joint`` has a clearance, in its
        place in the element order (see :func:`clearance_joint` for ``bearing``, ``name`` and
        ``fields_``). This scene is left unchanged: it stays the ideal reference of its variants.

        >>> scene = Scene("pendulum")
        >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
        >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
        >>> from daeclear.contact import Material
        >>> steel = Material(young=207e9, poisson=0.3)
        >>> loose = scene.with_clearance("A", clearance=0.1e-3, bearing_radius=0.01, material=steel)
        >>> loose["A"].kind, scene["A"].kind
        ('RevoluteClearance', 'Revolute')
        """
        names = [e.name for e in self.elements]
        if joint not in names:
            joints = ", ".join(repr(j.name) for j in self.joints)
            raise SceneError(f"scene '{self.name}': with_clearance: no joint named {joint!r} (joints: {joints})."
                             f"{_did_you_mean(str(joint), names)}")
        elements = list(self.elements)
        index = names.index(joint)
        elements[index] = clearance_joint(elements[index], bearing=bearing, name=name,  # type: ignore[arg-type]
                                          **fields_)
        return Scene(self.name, gravity=self.gravity, elements=elements, ground=self.ground)

    def ideal(self) -> Scene:
        """A new scene, the same mechanism with every clearance joint ideal (see :func:`ideal_joint`):
        the reference a clearance run is compared with. This scene is left unchanged."""
        elements = [ideal_joint(e) if isinstance(e, (RevoluteClearance, TranslationalClearance)) else e
                    for e in self.elements]
        return Scene(self.name, gravity=self.gravity, elements=elements, ground=self.ground)

    def without(self, *names: str) -> Scene:
        """A new scene without the named elements (e.g. the Driver of a crank that a Motor will
        drive instead). Every name must exist; this scene is left unchanged.

        >>> scene = Scene("pendulum")
        >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
        >>> _ = scene.add(Revolute("A", scene.ground, link, at=(0.0, 0.0)))
        >>> [e.name for e in scene.without("A")], [e.name for e in scene]
        (['link'], ['link', 'A'])
        """
        for name in names:
            self[name]  # KeyError naming the scene and the closest names
        elements = [e for e in self.elements if e.name not in names]
        return Scene(self.name, gravity=self.gravity, elements=elements, ground=self.ground)

    def with_values(self, values: Mapping[str, Any]) -> Scene:
        """A new, validated scene with some numbers replaced, by name: ``"<element>.<field>"`` (e.g.
        ``"crank.mass"``), ``"<element>.<field>.<field>"`` for a law, friction law or material
        (``"clearance.law.restitution"``), or ``"gravity"``. Changed elements are made again
        (``dataclasses.replace``), so what they derive follows. Raises SceneError naming an unknown
        element or field; this scene is left unchanged.

        >>> scene = Scene("pendulum")
        >>> link = scene.add(Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
        >>> scene.with_values({"link.mass": 2.0})["link"].mass, scene["link"].mass
        (2.0, 1.0)
        """
        if not isinstance(values, Mapping):
            raise SceneError(f"scene '{self.name}': values={values!r}, must be a mapping of names "
                             "('<element>.<field>', e.g. 'crank.mass') to new values.")
        gravity, elements = self.gravity, list(self.elements)
        index = {e.name: k for k, e in enumerate(elements)}
        for key, value in values.items():
            if key == "gravity" and key not in index:
                gravity = value
                continue
            name, _, path = str(key).partition(".")
            if name in index and not path:
                element: Any = elements[index[name]]
                fields_ = [f.name for f in dataclasses.fields(element) if f.name != "name"]
                raise SceneError(f"scene '{self.name}': {key!r} is an element; name one of its fields, "
                                 f"'{name}.<field>' with a field of {', '.join(fields_)}.")
            if name not in index:
                raise SceneError(f"scene '{self.name}': {key!r} names no value of the scene; a name is "
                                 f"'gravity' or '<element>.<field>' with an element of {', '.join(index)}."
                                 f"{_did_you_mean(name, index)}")
            elements[index[name]] = _replaced(elements[index[name]], path.split("."), value, key)
        scene = Scene(self.name, gravity=gravity, elements=elements, ground=self.ground)
        scene.validate()
        return scene

    def of_type(self, cls: type) -> list[Any]:
        return [e for e in self.elements if isinstance(e, cls)]

    def __getitem__(self, name: str) -> Element:
        for element in self.elements:
            if element.name == name:
                return element
        raise KeyError(f"no element '{name}' in scene '{self.name}'.{_did_you_mean(name, (e.name for e in self))}")

    def problems(self) -> list[str]:
        """Every problem of the scene (empty when valid)."""
        out: list[str] = []
        if as_vector2(self.gravity) is None:
            out.append(f"scene '{self.name}': gravity={self.gravity!r} m/s^2, must be two finite numbers.")
        seen: set[str] = set()
        for element in self.elements:
            out.extend(own_problems(element))
            if element.name in seen:
                out.append(f"{element.kind} '{element.name}': duplicate name; every name in a scene must be unique.")
            seen.add(element.name)
        known = {b.name for b in self.bodies} | {GROUND}
        referring: list[tuple[Element, Any]] = [(j, (("body_i", j.body_i), ("body_j", j.body_j)))
                                                for j in self.joints]
        referring += [(e, e.body_roles()) for e in self.elements if hasattr(e, "body_roles")]  # loads
        for joint, roles in referring:
            for role, body in roles:
                if body not in known:
                    out.append(f"{joint.kind} '{joint.name}': {role} refers to body '{body}', "
                               f"not in scene '{self.name}'.{_did_you_mean(str(body), sorted(known), n=1)}")
        joints = {j.name: j for j in self.joints}
        driven: set[str] = set()
        for driver in self.drivers:
            coordinate = driven_coordinate(joints.get(driver.joint))
            if coordinate is None:
                drivable = sorted(name for name, j in joints.items() if driven_coordinate(j))
                out.append(f"Driver '{driver.name}': joint={driver.joint!r} is not a revolute or translational "
                           f"joint of this scene (drivable joints: {', '.join(drivable) or 'none'}).")
            elif driver.initial_angle is not None and coordinate == "translation":
                out.append(f"Driver '{driver.name}': initial_angle={driver.initial_angle!r} rad on translational "
                           f"joint '{driver.joint}'; give initial_position (m) instead.")
            elif driver.initial_position is not None and coordinate == "rotation":
                out.append(f"Driver '{driver.name}': initial_position={driver.initial_position!r} m on revolute "
                           f"joint '{driver.joint}'; give initial_angle (rad) instead.")
            if coordinate is not None and driver.joint in driven:
                out.append(f"Driver '{driver.name}': joint '{driver.joint}' already has a driver.")
            driven.add(driver.joint)
        if not self.bodies:
            out.append(f"scene '{self.name}': has no moving body; add a Body.")
        return out

    def validate(self) -> None:
        """Raise one :class:`SceneError` listing every problem of the scene."""
        problems = self.problems()
        if len(problems) == 1:
            raise SceneError(problems[0])
        if problems:
            lines = "\n".join(f"  - {p}" for p in problems)
            raise SceneError(f"scene '{self.name}' has {len(problems)} problems:\n{lines}")

    def to_dict(self) -> dict[str, Any]:
        """Plain-data description of the scene (for result files)."""
        return _describe(self.name, self.gravity, self.elements)

    def description(self) -> Mapping[str, Any]:
        """:meth:`to_dict` as a read-only mapping made at its first read (a sweep's runs seldom read it)."""
        return SceneDescription(self)


def _replaced(obj: Any, path: list[str], value: Any, key: str) -> Any:
    """``obj`` (a frozen element, law or material) made again with the field at ``path`` set to ``value``."""
    names = [f.name for f in dataclasses.fields(obj)] if dataclasses.is_dataclass(obj) else []
    field_name = path[0]
    if field_name not in names or field_name == "name":
        allowed = ", ".join(n for n in names if n != "name") or "none"
        raise SceneError(f"scene value {key!r}: {type(obj).__name__} has no field {field_name!r} "
                         f"(its fields: {allowed}).")
    if len(path) > 1:
        value = _replaced(getattr(obj, field_name), path[1:], value, key)
    elif isinstance(value, (dict, list)) and isinstance(obj, (RevoluteClearance, TranslationalClearance)):
        try:  # a law, friction, material or wear given as a table, as scene files write them
            value = table_value(field_name, value)
        except (TypeError, ValueError) as exc:
            raise SceneError(f"scene value {key!r}={value!r}: {exc}") from None
    try:
        return dataclasses.replace(obj, **{field_name: value})
    except (TypeError, ValueError) as exc:
        raise SceneError(f"scene value {key!r}={value!r}: {exc}") from None


def _describe(name: str, gravity: Any, elements: Iterable[Element]) -> dict[str, Any]:
    return {"name": name, "gravity": list(gravity), "elements": {e.name: e.to_dict() for e in elements}}


class SceneDescription(Mapping[str, Any]):
    """A scene's :meth:`Scene.to_dict`, made at the first read from the scene as it was (at once when an
    element is not frozen): a later change of the scene does not show in it."""

    def __init__(self, scene: Scene) -> None:
        self._parts: tuple[str, tuple[float, ...], tuple[Element, ...]] | None = (
            scene.name, tuple(scene.gravity), tuple(scene.elements))
        self._value: dict[str, Any] | None = None
        if not all(is_frozen(e) for e in scene.elements):
            self._described()

    def _described(self) -> dict[str, Any]:
        if self._value is None:
            assert self._parts is not None
            self._value, self._parts = _describe(*self._parts), None
        return self._value

    def __getitem__(self, key: str) -> Any:
        return self._described()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._described())

    def __len__(self) -> int:
        return len(self._described())

    def __repr__(self) -> str:
        return repr(self._described())

