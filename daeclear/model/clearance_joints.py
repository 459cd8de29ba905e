"""Clearance joints: a revolute joint with radial play and a translational joint with a loose slider
(sections 4.2 and 4.3 of the chapter), and :func:`clearance_joint` / :func:`ideal_joint` between an
ideal joint and its clearance joint.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

from ..core.errors import SceneError

if TYPE_CHECKING:
    from numpy.typing import NDArray
from ..core.values import field_names
from .elements import (Joint, PointJoint, Revolute, Translational, Vector2, as_vector2, computed_once,
                       own_problems, store_vectors)


def _default_law() -> Any:
    from ..contact import LankaraniNikravesh

    return LankaraniNikravesh(restitution=0.9)


def _law_problems(element: RevoluteClearance | TranslationalClearance) -> list[str]:
    """Resolve the joint's contact and friction laws once, reporting what is wrong."""
    from ..contact import friction_law
    from ..contact.registry import LAW_TYPES

    out: list[str] = []
    try:
        given = _law_object(element.law)
        law: Any = given  # a NormalLaw or a joint law (contact.registry.LAW_TYPES)
        if not isinstance(given, LAW_TYPES):
            out.append(f"{element.kind} '{element.name}': law={law!r}, must be a daeclear.contact law or a law name.")
        elif element.kind not in law.joint_kinds:
            out.append(f"{element.kind} '{element.name}': law={type(law).__name__}(...), must be a normal contact "
                       f"law (a {law.name} law is a {' or '.join(law.joint_kinds)}'s law).")
        else:
            if isinstance(element, RevoluteClearance):
                problems = law.joint_problems(element.radial_clearance, element.journal)
                out.extend(f"{element.kind} '{element.name}': {p}" for p in problems)
            element.resolved_law()
    except (SceneError, TypeError) as exc:
        out.append(f"{element.kind} '{element.name}': {exc}")
    try:
        friction_law(element.friction)
    except (SceneError, TypeError) as exc:
        out.append(f"{element.kind} '{element.name}': friction: {exc}")
    return out


#: Fields of the clearance joints whose value a table (a dict, as scene files and results write it) may give.
TABLE_FIELDS: tuple[str, ...] = ("material", "law", "face_law", "friction", "wear")


def table_value(field_name: str, value: Any) -> Any:
    """A clearance joint's field given as a table (dict) as the object it stands for: ``material``
    ({young, poisson}, or a list of two), ``law``/``face_law`` ({name = ..., parameters}; "hydrodynamic"
    a HydrodynamicBearing), ``friction`` ({name = ..., parameters}), ``wear`` (ArchardWear's fields).
    Anything else is returned as given."""
    from ..contact import Material, friction_law
    from ..contact.registry import contact_law
    from ..contact.wear import ArchardWear

    if field_name == "material" and isinstance(value, list):
        return tuple(Material(**m) if isinstance(m, dict) else m for m in value)
    if not isinstance(value, dict) or field_name not in TABLE_FIELDS:
        return value
    if field_name == "material":
        return Material(**value)
    if field_name in ("law", "face_law"):
        return contact_law(value)
    if field_name == "friction":
        params = dict(value)
        return friction_law(params.pop("name", None), **params)
    return ArchardWear(**value)


def _law_object(law: Any) -> Any:
    """A law given by name as the law object (anything else as given)."""
    from ..contact.registry import contact_law

    return contact_law(law) if isinstance(law, str) else law


def _friction(joint: RevoluteClearance | TranslationalClearance) -> Any:
    from ..contact import friction_law

    return friction_law(joint.friction)


@dataclass(frozen=True)
class RevoluteClearance(PointJoint):
    """Revolute joint with radial clearance: a journal (body j) inside a bearing (body i).

    No constraint: a contact-impact force acts when the eccentricity exceeds the clearance (section
    4.2, eqs. 4.1-4.13). ``at`` is the common centre of bearing and journal in the reference
    configuration (or give ``point_i``/``point_j``).

    Parameters
    ----------
    name : str
        Unique name; channels ``<name>.ex``, ``<name>.penetration``, ... and events use it.
    body_i, body_j : str or Body
        Bearing body and journal body.
    bearing_radius : float
        Bearing radius R_i, m.
    clearance : float or None
        Radial clearance c = R_i - R_j, m (give this or ``journal_radius``).
    journal_radius : float or None
        Journal radius R_j, m.
    material : Material or (Material, Material) or None
        Materials of bearing and journal (one for both); needed when a stiffness is computed.
    law : NormalLaw, HydrodynamicBearing or str
        Normal contact law (default Lankarani-Nikravesh with c_e = 0.9, eq. 3.9); a
        HydrodynamicBearing makes a lubricated joint (docs/lubrication.md).
    friction : None, float, str or FrictionLaw
        None: frictionless; a float: modified Coulomb (3.16) with that coefficient (in dry contact).
    wear : ArchardWear or None
        Archard wear of the joint's surfaces: the worn profile ``wear_depth`` enters the gap
        (docs/wear.md).
    wear_depth : sequence of float, or two of them, or None
        The worn depth at the profile's ``wear.nodes`` nodes (m, >= 0, node k at angle ``2 pi k /
        nodes`` in the worn body's frame); two rows (bearing, journal) for "both". None: unworn.
    """

    bearing_radius: float = 0.0
    clearance: float | None = None
    journal_radius: float | None = None
    material: Any = None
    law: Any = field(default_factory=_default_law)
    friction: Any = None
    wear: Any = None
    wear_depth: Any = None

    def __post_init__(self) -> None:
        super().__post_init__()
        surfaces = getattr(self.wear, "surfaces", None)
        if self.wear_depth is None and surfaces is not None:  # unworn: zeros (a profile is numbers, not structure)
            zeros = (0.0,) * int(self.wear.nodes)
            object.__setattr__(self, "wear_depth", zeros if len(surfaces) == 1 else (zeros,) * len(surfaces))
        if self.wear_depth is not None and not isinstance(self.wear_depth, tuple):  # frozen: no array inside
            import numpy as np  # (not at import: `import daeclear` loads no numerical library)

            try:
                depth = np.asarray(self.wear_depth, dtype=float)
            except (TypeError, ValueError):
                return  # problems() names it
            value = tuple(map(tuple, depth.tolist())) if depth.ndim == 2 else tuple(depth.ravel().tolist())
            object.__setattr__(self, "wear_depth", value)

    def worn_profiles(self) -> dict[str, NDArray[Any]]:
        """The nodal depth of each worn surface, by name ("bearing", "journal"); zeros when unworn."""
        import numpy as np

        if self.wear is None:
            return {}
        surfaces = self.wear.surfaces  # an unworn profile is zeros (__post_init__)
        depth = np.asarray(self.wear_depth, dtype=float).reshape(len(surfaces), -1)
        return dict(zip(surfaces, depth))

    @property
    def radial_clearance(self) -> float:
        if self.clearance is not None:
            return float(self.clearance)
        return float(self.bearing_radius) - float(self.journal_radius or 0.0)

    @property
    def journal(self) -> float:
        return float(self.bearing_radius) - self.radial_clearance

    @computed_once
    def resolved_law(self) -> Any:
        """The normal law with its stiffness (or cylinder geometry) set from radii and materials (a
        HydrodynamicBearing: its dry law's)."""
        law = _law_object(self.law)
        if law.is_resolved:
            return law
        return law.resolve("internal_cylinder", radii=(float(self.bearing_radius), self.journal),
                           materials=self.material)

    resolved_friction = computed_once(_friction)

    def problems(self) -> list[str]:
        out = super().problems()
        self._check_positive(out, "bearing_radius", "m")
        self._check_one_positive(out, "clearance", "journal_radius", "m")
        if not out:
            c, R = self.radial_clearance, float(self.bearing_radius)
            if not 0.0 < c < R:
                out.append(f"{self.kind} '{self.name}': journal radius {self.journal!r} m must be in "
                           f"(0, bearing_radius={R!r} m): clearance {c!r} m, must be in (0, {R!r}).")
            else:
                out.extend(_law_problems(self))
        out.extend(_wear_problems(self))
        return out


def _wear_problems(joint: RevoluteClearance) -> list[str]:
    """What is wrong with a joint's wear and worn profile."""
    import numpy as np

    from ..contact.wear import ArchardWear

    where = f"{joint.kind} '{joint.name}'"
    if joint.wear is None:
        return [] if joint.wear_depth is None else [
            f"{where}: wear_depth is given without wear; give wear=ArchardWear(...) too."]
    if not isinstance(joint.wear, ArchardWear):
        return [f"{where}: wear={joint.wear!r}, must be None or a daeclear.contact.wear.ArchardWear."]
    if not getattr(joint.law, "wears", True):
        return [f"{where}: wear with a {joint.law.name} law ({type(joint.law).__name__}, a lubricated joint) is not "
                "modelled; give a dry contact law."]
    if joint.wear_depth is None:
        return []
    rows = len(joint.wear.surfaces)
    shape = (joint.wear.nodes,) if rows == 1 else (rows, joint.wear.nodes)
    try:
        depth = np.asarray(joint.wear_depth, dtype=float)
    except (TypeError, ValueError):
        depth = np.zeros(0)
    if depth.shape != shape:
        shown = f"an array of shape {depth.shape}" if depth.size else repr(joint.wear_depth)[:60]
        return [f"{where}: wear_depth={shown}, must be {shape[-1]} finite depths >= 0 (m)"
                + (" for each of bearing and journal" if rows == 2 else "") + f", shape {shape}."]
    from ..contact.wear import MAX_DEPTH_FRACTION

    deepest = MAX_DEPTH_FRACTION * float(joint.bearing_radius)
    bad = ~(np.isfinite(depth) & (depth >= 0) & (depth < deepest))
    if np.any(bad):
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        value = float(depth[index])
        rule = (f"must be below {deepest:g} m ({MAX_DEPTH_FRACTION:g} of the bearing radius: the gap's worn-profile "
                "model ends there)" if np.isfinite(value) and value >= 0 else "must be a finite depth >= 0 (m)")
        return [f"{where}: wear_depth{list(index)}={value!r}, {rule}."]
    return []


def _default_face_law() -> Any:
    from ..contact import LankaraniPlane

    return LankaraniPlane()


#: Contact models of :class:`TranslationalClearance` (see its docstring).
SLIDER_MODELS: tuple[str, ...] = ("corners", "section-4.3")


@dataclass(frozen=True)
class TranslationalClearance(PointJoint):
    """Translational joint with clearance: a rectangular slider (body j) free inside a guide (body i).

    No constraint: each slider corner that reaches a guide surface (two parallel surfaces ``H``
    apart) is pushed back by a contact-impact force (section 4.3, eqs. 4.14-4.27). ``at`` is a point
    of the guide's mid-line and the slider's centre (or give ``point_i`` and ``point_j``); ``s`` runs
    from it along ``axis``, "upper" is left of ``axis``. Corners A (+L/2, +W/2), B (-L/2, +W/2),
    C (-L/2, -W/2), D (+L/2, -W/2); pairs ``<name>.A_upper`` ... ``<name>.D_lower``, faces
    ``<name>.upper_face``/``lower_face`` (docs/validation.md). The guide is body i.

    Parameters
    ----------
    name : str
        Unique name; channels and events use it.
    body_i, body_j : str or Body
        Guide body and slider body.
    axis : (float, float)
        Guide direction, world frame, reference configuration (need not be unit).
    slider_axis : (float, float) or None
        The slider's length direction in slider coordinates; None: ``axis`` (starts parallel).
    length, width : float
        Slider length L (along the guide) and width W (across), m.
    corner_radius : float
        Corner radius R_c, m, in (0, min(L, W)/2), for the corner stiffness (eq. 3.5).
    clearance : float or None
        c = (H - W)/2, m (give this or ``guide_height``).
    guide_height : float or None
        Distance H between the guide surfaces, m.
    thickness : float or None
        Slider thickness (out of plane), m; None means ``length`` (eq. 4.27's a = sqrt(L t) / 2).
    upper_limits, lower_limits : (float, float) or None
        ``s`` limits of the upper and lower surfaces, m, between which a corner touches; None: unbounded.
    stroke : (float, float) or None
        ``s`` of the slider centre at xi = 0 and 1 (channel ``<name>.xi``); None: ``upper_limits``.
    material : Material or (Material, Material) or None
        Materials of guide and slider; needed when a stiffness is computed.
    law : NormalLaw or str
        Corner law, default Lankarani-Nikravesh with c_e = 0.9 (eq. 3.9), stiffness (3.5).
    face_law : NormalLaw or str
        ``section-4.3`` model: a face's law on its corners' mean penetration; default Lankarani's
        linear law (4.26) with the stiffness (4.27).
    friction : None, float, str or FrictionLaw
        None: frictionless; a float: modified Coulomb (3.16) with that coefficient.
    model : {"corners", "section-4.3"}
        ``"corners"``: every touching corner is a sphere on a plane. ``"section-4.3"``: a face (two
        adjacent corners on one surface) uses ``face_law``, other contacts ``law``.
    reading : str or None
        A named reading of the chapter's model (:data:`daeclear.model.readings.JOINT_READINGS`):
        it sets the model and the laws' stiffness and exponent, keeping the restitution of ``law``.

    Notes
    -----
    The slider must not be able to turn over (``sqrt(L^2 + W^2) > H``). ``section-4.3`` is for a
    slider that lands flat (Fig. 4.35b); for tilting sliders use ``corners`` (docs/validation.md).

    Example
    -------
    >>> import daeclear as dc
    >>> scene = dc.Scene("guide", gravity=(0.0, -9.81))
    >>> slider = scene.add(dc.Body("slider", mass=0.14, inertia=1e-4))
    >>> joint = scene.add(dc.TranslationalClearance(
    ...     "g", scene.ground, slider, at=(0.0, 0.0), length=0.05, width=0.05, corner_radius=1e-3,
    ...     clearance=0.5e-3, material=dc.Material(young=207e9, poisson=0.3)))
    >>> scene.validate()
    >>> round(joint.resolved_law().stiffness / 1e9, 2)  # sphere of R_c on a plane, eq. (3.5)
    4.8
    """

    axis: Vector2 = (1.0, 0.0)
    slider_axis: Vector2 | None = None
    length: float = 0.0
    width: float = 0.0
    corner_radius: float = 0.0
    clearance: float | None = None
    guide_height: float | None = None
    thickness: float | None = None
    upper_limits: Vector2 | None = None
    lower_limits: Vector2 | None = None
    stroke: Vector2 | None = None
    material: Any = None
    law: Any = field(default_factory=_default_law)
    face_law: Any = field(default_factory=_default_face_law)
    friction: Any = None
    model: str = "corners"
    reading: str | None = None
    # a reading that only changes numbers compiles nothing
    NOT_STRUCTURE: ClassVar[frozenset[str]] = frozenset({"model", "reading"})

    def __post_init__(self) -> None:
        super().__post_init__()
        store_vectors(self, ("axis", "slider_axis", "upper_limits", "lower_limits", "stroke"))
        for name in ("model", "reading"):
            if isinstance(getattr(self, name), str):
                object.__setattr__(self, name, getattr(self, name).strip().lower())

    @property
    def contact_model(self) -> str:
        """The contact model in use: the reading's, else ``model``."""
        from .joint_readings import joint_reading

        return self.model if self.reading is None else joint_reading(self.reading).model

    @property
    def radial_clearance(self) -> float:
        """c = (H - W) / 2, m."""
        if self.clearance is not None:
            return float(self.clearance)
        return 0.5 * (float(self.guide_height or 0.0) - float(self.width))

    @property
    def height(self) -> float:
        """Distance between the guide surfaces H = W + 2c, m."""
        return float(self.width) + 2.0 * self.radial_clearance

    @property
    def face_half_width(self) -> float:
        """Half side a of the square with the area of a slider face, m (eq. 4.27)."""
        thickness = float(self.length if self.thickness is None else self.thickness)
        return 0.5 * math.sqrt(float(self.length) * thickness)

    @computed_once
    def resolved_law(self) -> Any:
        """The corner law with its stiffness set (kind ``"sphere_plane"``, radius R_c)."""
        law = _law_object(self.law)
        if self.reading is not None:
            from . import joint_readings as readings

            return readings.corner_law(readings.joint_reading(self.reading), law, owner=f"{self.kind} '{self.name}'",
                                       corner_radius=self.corner_radius, face_half_width=self.face_half_width,
                                       materials=self.material)
        if law.is_resolved:
            return law
        return law.resolve("sphere_plane", radii=(float(self.corner_radius),), materials=self.material)

    @computed_once
    def resolved_face_law(self) -> Any:
        """The face law with its stiffness set (kind ``"plane_face"``, half side a); with a reading
        its face law (None for a reading of the ``corners`` model)."""
        if self.reading is not None:
            from . import joint_readings as readings

            return readings.face_law(readings.joint_reading(self.reading), _law_object(self.law),
                                     owner=f"{self.kind} '{self.name}'", face_half_width=self.face_half_width,
                                     materials=self.material)
        return _law_object(self.face_law).resolve("plane_face", face_half_width=self.face_half_width,
                                                  materials=self.material)

    resolved_friction = computed_once(_friction)

    def problems(self) -> list[str]:
        out = super().problems()
        for name in ("axis", "slider_axis"):
            value = getattr(self, name)
            vec = as_vector2(value) if value is not None or name == "axis" else (1.0, 0.0)
            if vec is None or math.hypot(*vec) < 1e-12:
                out.append(f"{self.kind} '{self.name}': {name}={value!r}, must be a non-zero 2-vector.")
        for name in ("length", "width", "corner_radius"):
            self._check_positive(out, name, "m")
        self._check_positive(out, "thickness", "m", optional=True)
        self._check_one_positive(out, "clearance", "guide_height", "m")
        for name in ("upper_limits", "lower_limits", "stroke"):
            value = getattr(self, name)
            if value is None:
                continue
            pair = as_vector2(value)
            if pair is None or not pair[0] < pair[1]:
                out.append(f"{self.kind} '{self.name}': {name}={value!r} m, must be two finite numbers "
                           "(start, end) with start < end.")
        if self.model not in SLIDER_MODELS:
            out.append(f"{self.kind} '{self.name}': model={self.model!r}, must be one of "
                       f"{', '.join(map(repr, SLIDER_MODELS))}.")
        out.extend(_reading_problems(self))
        if out:
            return out
        L, W, R_c, c = float(self.length), float(self.width), float(self.corner_radius), self.radial_clearance
        if c <= 0:
            out.append(f"{self.kind} '{self.name}': guide_height={self.guide_height!r} m must exceed the slider "
                       f"width {W!r} m: clearance (H - W)/2 = {c!r} m, must be > 0.")
        elif math.hypot(L, W) <= self.height:
            out.append(f"{self.kind} '{self.name}': the slider ({L!r} x {W!r} m, diagonal {math.hypot(L, W):.6g} m) "
                       f"can turn over in a guide {self.height:.6g} m high; the diagonal must exceed the guide "
                       "height (reduce the clearance or lengthen the slider).")
        if R_c >= 0.5 * min(L, W):
            out.append(f"{self.kind} '{self.name}': corner_radius={R_c!r} m, must be < min(length, width)/2 "
                       f"= {0.5 * min(L, W)!r} m.")
        out.extend(_law_problems(self))
        if self.model == "section-4.3" and self.reading is None:
            out.extend(_face_law_problems(self))
        return out


def _reading_problems(element: TranslationalClearance) -> list[str]:
    """A reading must be known, and ``model`` and ``face_law`` left to it."""
    from .joint_readings import joint_reading

    if element.reading is None:
        return []
    where = f"{element.kind} '{element.name}'"
    try:
        reading = joint_reading(element.reading)
    except SceneError as exc:
        return [f"{where}: {exc}"]
    out = []
    if element.model not in ("corners", reading.model):
        out.append(f"{where}: model={element.model!r} with reading={reading.name!r}, whose model is "
                   f"{reading.model!r}; give one of them.")
    if element.face_law != _default_face_law():
        out.append(f"{where}: face_law={element.face_law!r} with reading={reading.name!r}, which sets the face "
                   "law; leave face_law at its default.")
    return out


def _face_law_problems(element: TranslationalClearance) -> list[str]:
    from ..contact.base import NormalLaw

    try:
        law = _law_object(element.face_law)
        if not isinstance(law, NormalLaw):
            return [f"{element.kind} '{element.name}': face_law={law!r}, must be a daeclear.contact law or a "
                    "law name."]
        element.resolved_face_law()
    except (SceneError, TypeError) as exc:
        return [f"{element.kind} '{element.name}': face_law: {exc}"]
    return []


#: The clearance joint each ideal joint becomes, and the fields it needs besides the shared ones.
_CLEARANCE_OF: dict[type, tuple[type, tuple[tuple[str, ...], ...]]] = {
    Revolute: (RevoluteClearance, (("bearing_radius",), ("clearance", "journal_radius"))),
    Translational: (TranslationalClearance, (("length",), ("width",), ("corner_radius",),
                                             ("clearance", "guide_height"))),
}


def clearance_joint(joint: Joint, *, bearing: str | None = None, name: str | None = None,
                    **fields_: Any) -> Joint:
    """The clearance joint that replaces the ideal ``joint``: same bodies, point and axis.

    Ideal and clearance joints share their kinematic data (Ambrósio and Pombo, Multibody Syst. Dyn.
    42, 2018).

    Parameters
    ----------
    joint : Revolute or Translational
        The ideal joint.
    bearing : str or None
        Revolute only: the body that holds the bearing (one of the joint's); None: body i.
    name : str or None
        Name of the clearance joint; None keeps the joint's.
    **fields_
        The clearance joint's own fields, e.g. ``clearance=0.5e-3, bearing_radius=10e-3``.

    Raises
    ------
    SceneError
        Not an ideal revolute or translational joint, an unknown, shared or missing field, or an
        invalid value.
    """
    label = f"clearance on joint '{getattr(joint, 'name', joint)}'"
    if isinstance(joint, (RevoluteClearance, TranslationalClearance)):
        raise SceneError(f"{label}: it is already a {joint.kind}; change its fields with "
                         "dataclasses.replace, or start from the ideal joint.")
    if not isinstance(joint, PointJoint) or type(joint) not in _CLEARANCE_OF:  # (both keys are PointJoints)
        kind = getattr(joint, "kind", type(joint).__name__)
        raise SceneError(f"{label}: it is a {kind}; only an ideal Revolute or Translational joint can get a "
                         "clearance.")
    cls, required = _CLEARANCE_OF[type(joint)]
    shared = field_names(type(joint))
    allowed = [name for name in field_names(cls) if name not in shared]
    unknown = sorted(set(fields_) - set(allowed))
    if unknown:
        hints = [f"{key} (shared with the ideal joint)" if key in shared else key for key in unknown]
        raise SceneError(f"{label}: unknown field(s) {', '.join(hints)} for a {cls.__name__}; "
                         f"allowed: {', '.join(allowed)}.")
    missing = [" or ".join(group) for group in required if all(fields_.get(k) is None for k in group)]
    if missing:
        raise SceneError(f"{label}: missing {', '.join(missing)} (m), needed by a {cls.__name__}.")
    shared_values = {name: getattr(joint, name) for name in shared}
    if bearing is not None:
        if cls is not RevoluteClearance:
            raise SceneError(f"{label}: bearing={bearing!r} applies to a revolute joint only; a translational "
                             "joint's guide is its body_i.")
        if bearing not in joint.bodies:
            raise SceneError(f"{label}: bearing={bearing!r}, must be one of the joint's bodies "
                             f"{joint.body_i!r} or {joint.body_j!r}.")
        if bearing == joint.body_j:  # the journal on body i: the two bodies and their points change roles
            shared_values.update(body_i=joint.body_j, body_j=joint.body_i, point_i=joint.point_j,
                                 point_j=joint.point_i)
    if name is not None:
        shared_values["name"] = name
    element = cls(**shared_values, **fields_)
    problems = own_problems(element)  # kept: the scene's validation does not check it again
    if problems:
        raise SceneError(f"{label}: " + " ".join(problems))
    return element


def ideal_joint(joint: Joint) -> Joint:
    """The ideal joint a clearance joint stands for: same name, bodies, point and axis (the inverse of
    :func:`clearance_joint` up to the clearance fields)."""
    shared: dict[str, Any] = {"name": joint.name, "body_i": joint.body_i, "body_j": joint.body_j,
              "at": getattr(joint, "at", None), "point_i": getattr(joint, "point_i", None),
              "point_j": getattr(joint, "point_j", None)}
    if isinstance(joint, RevoluteClearance):
        return Revolute(**shared)
    if isinstance(joint, TranslationalClearance):
        return Translational(**shared, axis=joint.axis)
    raise SceneError(f"ideal joint of '{getattr(joint, 'name', joint)}': it is a "
                     f"{getattr(joint, 'kind', type(joint).__name__)}, not a clearance joint.")


def driven_coordinate(joint: Any) -> str | None:
    """What a :class:`Driver` prescribes on ``joint``: "rotation" (revolute joints, with or without
    clearance), "translation" (translational joints, with or without clearance) or None (not drivable)."""
    if isinstance(joint, (Revolute, RevoluteClearance)):
        return "rotation"
    if isinstance(joint, (Translational, TranslationalClearance)):
        return "translation"
    return None
