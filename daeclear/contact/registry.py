"""Look up contact and friction laws by name (scene files, command line, sweeps)."""

from __future__ import annotations

import dataclasses
import functools
import numbers
import re
from typing import Any

from ..core.errors import SceneError
from ..core.options import fail
from .base import NormalLaw
from .cylindrical import DubowskyFreudenstein, ESDU78035, Goldsmith
from .friction import Coulomb, FrictionLaw, ModifiedCoulomb, NoFriction
from .hydrodynamic import HydrodynamicBearing
from .normal import Flores, Hertz, HuntCrossley, KelvinVoigt, LankaraniNikravesh, LankaraniPlane

__all__ = ["FRICTION_LAWS", "JOINT_LAWS", "LAW_TYPES", "NORMAL_LAWS", "contact_law", "friction_law", "normal_law"]

#: Normal laws by registry name.
NORMAL_LAWS: dict[str, type[NormalLaw]] = {cls.name: cls for cls in (
    Hertz, KelvinVoigt, HuntCrossley, LankaraniNikravesh, Flores, DubowskyFreudenstein, Goldsmith,
    ESDU78035, LankaraniPlane)}
_NORMAL_ALIASES = {"ln": "lankarani-nikravesh", "esdu": "esdu-78035", "kv": "kelvin-voigt",
                   "hc": "hunt-crossley", "df": "dubowsky-freudenstein", "flores-2011": "flores"}

#: A clearance joint's laws besides the normal laws, by registry name: each has ``example`` (a table with
#: the numbers it needs); its table is read by :func:`contact_law`.
JOINT_LAWS: dict[str, Any] = {HydrodynamicBearing.name: HydrodynamicBearing}
#: What a clearance joint's ``law`` may be an instance of.
LAW_TYPES: tuple[type, ...] = (NormalLaw, HydrodynamicBearing)

#: Friction laws by registry name.
FRICTION_LAWS: dict[str, type[FrictionLaw]] = {cls.name: cls for cls in (NoFriction, Coulomb, ModifiedCoulomb)}
# what ``friction=None`` means, one frozen law shared by every frictionless joint (its kept values with it)
_NO_FRICTION = NoFriction()
_FRICTION_ALIASES = {"ambrosio": "modified-coulomb", "frictionless": "none"}


def _key(name: str) -> str:
    """Case-insensitive key ignoring hyphens, underscores and spaces."""
    return re.sub(r"[-_\s]+", "", name.strip().lower())


@functools.lru_cache(maxsize=8)
def _keys(names: tuple[str, ...], aliases: tuple[tuple[str, str], ...]) -> dict[str, str]:
    """Lookup key -> registered name, for the registry's names and aliases as they are now."""
    return {_key(n): n for n in names} | {_key(a): n for a, n in aliases}


def _lookup(kind: str, name: Any, table: dict[str, Any], aliases: dict[str, str]) -> Any:
    if not isinstance(name, str):
        raise SceneError(f"{kind}: name={name!r} is not a string; valid names: {', '.join(table)}.")
    found = _keys(tuple(table), tuple(aliases.items())).get(_key(name))
    if found is None:
        raise SceneError(f"{kind}: unknown name {name!r}; valid names: {', '.join(table)} "
                         f"(aliases: {', '.join(aliases)}).")
    return table[found]


def normal_law_class(name: str) -> type:
    """The class of the normal law named ``name`` (a registered name or alias, as for :func:`normal_law`)."""
    return _lookup("law", name, NORMAL_LAWS, _NORMAL_ALIASES)


def build_law(cls: type, params: dict[str, Any]) -> Any:
    """``cls(**params)`` after checking the names: unknown or missing parameters are a SceneError."""
    fields = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(params) - set(fields))
    if unknown:
        raise SceneError(f"{cls.__name__}: unknown parameter(s) {', '.join(unknown)}; "
                         f"valid: {', '.join(fields)}.")
    missing = [f.name for f in dataclasses.fields(cls) if f.name not in params
               and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    if missing:
        raise SceneError(f"{cls.__name__}: missing required parameter(s) {', '.join(missing)}.")
    return cls(**params)


def normal_law(name: str | NormalLaw, **params: Any) -> NormalLaw:
    """Build a normal contact law from its name (:data:`NORMAL_LAWS` or an alias: ln, esdu, kv, hc, df;
    case, hyphens, underscores and spaces ignored) and its constructor keywords ``params``; a NormalLaw
    instance is returned as is. Raises SceneError for an unknown name or parameter, or a bad value.

    Example
    -------
    >>> normal_law("Lankarani Nikravesh", restitution=0.9).name
    'lankarani-nikravesh'
    """
    if isinstance(name, NormalLaw):
        if params:
            raise SceneError(f"normal_law: parameters {sorted(params)} given with a law instance.")
        return name
    return build_law(_lookup("normal_law", name, NORMAL_LAWS, _NORMAL_ALIASES), params)


def friction_law(name_or_coefficient: str | float | FrictionLaw | None, **params: Any) -> FrictionLaw:
    """Build a friction law: ``None``, :class:`NoFriction`; a number, :class:`ModifiedCoulomb` with that
    coefficient; a name ("none"/"frictionless", "coulomb", "modified-coulomb"/"ambrosio") with
    ``params``; a FrictionLaw as is. Raises SceneError for an unknown name or parameter, or a bad value.

    Example
    -------
    >>> friction_law(0.05)
    ModifiedCoulomb(coefficient=0.05, v0=0.0001, v1=0.0002)
    """
    if isinstance(name_or_coefficient, FrictionLaw):
        if params:
            raise SceneError(f"friction_law: parameters {sorted(params)} given with a law instance.")
        return name_or_coefficient
    if name_or_coefficient is None:
        return build_law(NoFriction, params) if params else _NO_FRICTION
    if isinstance(name_or_coefficient, numbers.Real) and not isinstance(name_or_coefficient, bool):
        return build_law(ModifiedCoulomb, {"coefficient": float(name_or_coefficient), **params})
    return build_law(_lookup("friction_law", name_or_coefficient, FRICTION_LAWS, _FRICTION_ALIASES), params)


def contact_law(value: Any) -> Any:
    """A clearance joint's law from a law object (as is), a name, or a table ``{name = ..., parameters}``
    (scene files, ``--set law={...}``, sweeps): the normal laws (:data:`NORMAL_LAWS`) and the joint laws
    (:data:`JOINT_LAWS`: ``"hydrodynamic"``, whose table may give its ``dry`` law as a name or a table)."""
    if isinstance(value, LAW_TYPES):
        return value
    if isinstance(value, dict):
        params = dict(value)
        name = params.pop("name", None)
        if not isinstance(name, str):
            raise SceneError(f"law table {value!r}: name={name!r}, must be a law's name (one of "
                             f"{', '.join([*NORMAL_LAWS, *JOINT_LAWS])}).")
        joint_law = _keys(tuple(JOINT_LAWS), ()).get(_key(name))
        if joint_law is not None:
            return _joint_law_from_table(JOINT_LAWS[joint_law], params)
        return normal_law(name, **params)
    joint_law = _keys(tuple(JOINT_LAWS), ()).get(_key(value)) if isinstance(value, str) else None
    if joint_law is not None:
        raise SceneError(f"contact law: law={value!r} needs its numbers: give a table, e.g. "
                         f"law={JOINT_LAWS[joint_law].example} ({JOINT_LAWS[joint_law].__doc__.splitlines()[0]})")
    return normal_law(value)


def _joint_law_from_table(cls: type, params: dict[str, Any]) -> Any:
    """A joint law from its table (``name`` taken out); a ``dry`` law in it may be a name or a table."""
    params = dict(params)
    dry = params.get("dry")
    try:
        if isinstance(dry, dict):
            dry = dict(dry)
            params["dry"] = normal_law(dry.pop("name", None), **dry)
        elif isinstance(dry, str):
            params["dry"] = normal_law(dry)
    except (SceneError, TypeError) as exc:
        raise SceneError(f"{cls.__name__}: dry={dry!r}: {exc}") from None
    return build_law(cls, params)


def check_restitution(value: Any, law: Any, *, where: str, field: str = "restitution") -> None:
    """A restitution given explicitly must reach a law that has one (it is never dropped silently)."""
    if value is None:
        return
    name = law.get("name") if isinstance(law, dict) else law if isinstance(law, str) else getattr(law, "name", None)
    if name in JOINT_LAWS:
        fail(where, field, value, "left out with a lubricated law (hydrodynamic), whose dry law has the restitution; "
             "give it there, e.g. law={'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01, 'dry': "
             "{'name': 'lankarani-nikravesh', 'restitution': 0.5}}")
    if isinstance(law, dict):
        fail(where, field, value, "left out when law is a table; give it in the table, e.g. "
             "law={'name': 'hunt-crossley', 'restitution': 0.5}")
    if isinstance(law, NormalLaw):
        fail(where, field, value, f"left out when law is a law object ({type(law).__name__}); set it on the "
             "law object instead")
    cls = normal_law_class(str(law))
    if "restitution" not in getattr(cls, "__dataclass_fields__", {}):
        takes = [n for n, c in NORMAL_LAWS.items() if "restitution" in getattr(c, "__dataclass_fields__", {})]
        fail(where, field, value, f"left out with law={law!r}, which has no coefficient of restitution "
             f"(laws with one: {', '.join(takes)})")
