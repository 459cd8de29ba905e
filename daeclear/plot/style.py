"""The one style of daeclear's figures: captions with the run's parameters, time windows and min-max
decimation for long runs, parameter axes with units and log scales (matplotlib imported only for an Axes).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..results.result import Result

__all__ = ["PARAMETER_AXES", "TITLE_SIZE", "caption", "decimate", "format_parameter", "is_geometric", "new_axes",
           "parameter_axis", "parameter_display", "quantity_label", "run_parameters", "scene_elements",
           "select_times", "set_title", "stride", "sweep_caption", "window_bounds", "window_index"]

TITLE_SIZE = "medium"
"""Font size of every figure and panel title."""

PARAMETER_AXES: dict[str, tuple[float, str]] = {
    **dict.fromkeys(("clearance", "bearing_radius", "journal_radius", "length", "width", "corner_radius"), (1e3, "mm")),
    "rpm": (1.0, "rpm"), "gravity": (1.0, "m/s²"), "crank_angle": (1.0, "rad"),
    **dict.fromkeys(("restitution", "friction", "rtol"), (1.0, "-"))}
"""How a swept parameter (of the mechanisms' builders, in SI units) is shown: name -> (factor, unit of the axis)."""

_LAW_NAMES = {"lankarani-nikravesh": "Lankarani-Nikravesh", "hunt-crossley": "Hunt-Crossley", "flores": "Flores",
              "hertz": "Hertz", "esdu-78035": "ESDU-78035", "goldsmith": "Goldsmith",
              "dubowsky-freudenstein": "Dubowsky-Freudenstein", "lankarani-plane": "Lankarani plane",
              "kelvin-voigt": "Kelvin-Voigt"}
_FRICTION_NAMES = {"coulomb": "Coulomb", "modified-coulomb": "modified Coulomb"}


def new_axes(ax: Axes | None = None) -> Axes:
    """``ax``, or the Axes of a new figure when None."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure().add_subplot()


def set_title(target: Any, text: str) -> None:
    """Title of an Axes, or the suptitle of a Figure, in the common size (nothing for empty text)."""
    if text:
        (target.suptitle if hasattr(target, "suptitle") else target.set_title)(text, fontsize=TITLE_SIZE)


def quantity_label(name: str, unit: str) -> str:
    """Axis label ``"name (unit)"``, or the name alone when there is no unit."""
    return f"{name} ({unit})" if unit else name


def _number(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _law_text(law: Any) -> str:
    if isinstance(law, str):
        return _LAW_NAMES.get(law, law)
    if not isinstance(law, Mapping):
        return ""
    name = law.get("name")
    if name == "hydrodynamic":  # a lubricated joint: the oil, the bearing's length and the film theory
        mu, length = _number(law.get("viscosity")), _number(law.get("length"))
        oil = [f"oil $\\mu$ = {mu:g} Pa s" if mu is not None else "oil",
               f"L = {length * 1e3:g} mm" if length is not None else "", f"{law.get('theory', 'short')} bearing"]
        return ", ".join(part for part in oil if part)
    text = _LAW_NAMES.get(name, str(name)) if isinstance(name, str) else "contact law"
    restitution = _number(law.get("restitution"))
    return f"{text} $c_e$ = {restitution:g}" if restitution is not None else text


def _friction_text(friction: Any) -> str:
    if friction is None or friction == {} or friction is False or friction == "none":
        return "frictionless"
    if isinstance(friction, str):
        return _FRICTION_NAMES.get(friction, friction)
    name = friction.get("name") if isinstance(friction, Mapping) else None
    if name == "none":
        return "frictionless"
    coefficient = _number(friction.get("coefficient") if isinstance(friction, Mapping) else friction)
    text = _FRICTION_NAMES.get(name, str(name)) if isinstance(name, str) else "friction"
    if coefficient is not None:
        return "frictionless" if coefficient == 0 else f"{text} $c_f$ = {coefficient:g}"
    return text if isinstance(friction, Mapping) else ""


def scene_elements(result: Result) -> Mapping[str, Any]:
    """The element descriptions of the run's scene, ``result.parameters["scene"]["elements"]`` (empty if none)."""
    scene = result.parameters.get("scene") if isinstance(result.parameters, Mapping) else None
    elements = scene.get("elements", {}) if isinstance(scene, Mapping) else {}
    return elements if isinstance(elements, Mapping) else {}


def run_parameters(result: Result) -> dict[str, Any]:
    """The parameters a figure of ``result`` states, from its scene: ``"rpm"`` (first driver, rev/min) and
    ``"joints"``, per clearance joint ``{"name", "kind", "clearance" (m), "law" (text), "restitution",
    "friction" (text)}``; what the scene lacks is left out.
    """
    out: dict[str, Any] = {}
    joints: list[dict[str, Any]] = []
    for name, element in scene_elements(result).items():
        if not isinstance(element, Mapping):
            continue
        speed = _number(element.get("speed"))
        if element.get("kind") == "Driver" and speed is not None and "rpm" not in out:
            out["rpm"] = speed * 60.0 / (2.0 * math.pi)
        clearance = _number(element.get("clearance"))
        if clearance is None:
            continue
        joint: dict[str, Any] = {"name": str(name), "kind": str(element.get("kind", "")), "clearance": clearance}
        law = element.get("law")
        if law is not None:
            joint["law"] = _law_text(law)
            if isinstance(law, Mapping) and _number(law.get("restitution")) is not None:
                joint["restitution"] = float(law["restitution"])
        if "friction" in element:
            joint["friction"] = _friction_text(element.get("friction"))
        joints.append(joint)
    if joints:
        out["joints"] = joints
    return out


def _joint_text(joint: Mapping[str, Any]) -> str:
    return ", ".join([f"c = {joint['clearance'] * 1e3:g} mm"] + [joint[k] for k in ("law", "friction") if joint.get(k)])


def caption(result: Result, *, name: bool = True) -> str:
    """One line naming the run: scene, clearance, crank speed, law and restitution, friction.

    E.g. ``"slider_crank_revolute: c = 0.5 mm, 5000 rpm, Lankarani-Nikravesh $c_e$ = 0.9, frictionless"``;
    joints with different settings are listed by name, a failed run ends in ``(FAILED: partial result)``.
    """
    info = run_parameters(result)
    joints = info.get("joints", [])
    texts = list(dict.fromkeys(_joint_text(j) for j in joints))
    rpm = [f"{info['rpm']:.4g} rpm"] if "rpm" in info else []
    if len(texts) == 1:  # the clearance first, then the speed, then the law and friction
        first, _, rest = texts[0].partition(", ")
        parts = [first, *rpm, rest]
    else:
        parts = rpm + [f"{j['name']}: {_joint_text(j)}" for j in joints]
    text = ", ".join(p for p in parts if p)
    if name and result.scene_name:
        text = f"{result.scene_name}: {text}" if text else result.scene_name
    if not result.success:
        text += "  (FAILED: partial result)"
    return text


def format_parameter(name: str, value: Any) -> str:
    """``"name = value unit"`` in the display unit of :data:`PARAMETER_AXES`."""
    number = _number(value)
    if number is None:
        return _friction_text(value) if name == "friction" else f"{name} = {value}"
    scale, unit = PARAMETER_AXES.get(name, (1.0, ""))
    if unit == name:  # "5000 rpm", not "rpm = 5000 rpm"
        return f"{number * scale:g} {unit}"
    unit = "" if unit == "-" else unit
    return f"{name} = {number * scale:g}" + (f" {unit}" if unit else "")


def sweep_caption(sweep: Any, exclude: Iterable[str] = ()) -> str:
    """The mechanism and the parameters every run of a sweep shares (the ones not on an axis)."""
    runs = list(getattr(sweep, "runs", ()))
    skip = set(exclude)
    first = runs[0].parameters if runs else {}
    fixed = {k: v for k, v in first.items() if k not in skip and all(r.parameters.get(k, object()) == v for r in runs)}
    mechanism = str(getattr(sweep, "mechanism", "") or "")
    text = ", ".join(format_parameter(k, v) for k, v in fixed.items())
    return f"{mechanism}: {text}" if mechanism and text else mechanism or text


def _check_max_points(max_points: int | None) -> None:
    if max_points is not None and (isinstance(max_points, bool) or int(max_points) != max_points
                                   or max_points < 2):
        raise ValueError(f"max_points={max_points!r}, must be an integer >= 2 (or None: every point).")


def decimate(y: ArrayLike, max_points: int | None, index: NDArray[np.intp] | None = None) -> NDArray[np.intp]:
    """Indices of at most ``max_points`` samples of ``y`` (or ``y[index]``) that keep its envelope.

    Min-max decimation: the lowest and highest point of each of ``max_points // 2`` runs of samples, in
    time order, so peaks (impacts) survive; ``max_points=None`` keeps every point.
    """
    _check_max_points(max_points)
    values = np.asarray(y)
    idx = np.arange(values.shape[0]) if index is None else np.asarray(index, dtype=np.intp)
    if max_points is None or idx.size <= max_points:
        return idx
    v = values[idx].astype(np.float64)
    v = v.reshape(v.shape[0], -1)[:, 0] if v.ndim > 1 else v
    edges = np.linspace(0, idx.size, max_points // 2 + 1).astype(np.intp)  # max_points // 2 runs
    keep: list[int] = []
    for a, b in zip(edges[:-1], edges[1:]):
        if b <= a:
            continue
        chunk = np.where(np.isfinite(v[a:b]), v[a:b], np.nan)
        if np.isnan(chunk).all():
            keep.append(a)
        else:
            keep.extend(sorted({a + int(np.nanargmin(chunk)), a + int(np.nanargmax(chunk))}))
    return idx[np.asarray(keep, dtype=np.intp)]


def stride(index: NDArray[np.intp], max_points: int | None) -> NDArray[np.intp]:
    """At most ``max_points`` of ``index``, evenly spaced, first and last kept (for x-y curves)."""
    _check_max_points(max_points)
    if max_points is None or index.size <= max_points:
        return index
    picks = np.unique(np.linspace(0, index.size - 1, max_points).round().astype(np.intp))
    return index[picks]


def window_bounds(window: tuple[float | None, float | None] | None) -> tuple[float, float]:
    """``window = (t0, t1)`` as floats, a None side (or None) open (+-inf); ValueError if not a pair or t0 > t1."""
    if window is None:
        return -math.inf, math.inf
    try:
        t0, t1 = window
    except (TypeError, ValueError):
        raise ValueError(f"window={window!r}, must be a pair (t0, t1) in s (either may be None).") from None
    lo = -math.inf if t0 is None else float(t0)
    hi = math.inf if t1 is None else float(t1)
    if lo > hi:
        raise ValueError(f"window=({t0}, {t1}): t0 must not exceed t1.")
    return lo, hi


def window_index(t: ArrayLike, window: tuple[float | None, float | None] | None) -> NDArray[np.intp]:
    """Indices of the times inside the closed ``window = (t0, t1)`` (None: every time, or an open side)."""
    times = np.asarray(t, dtype=np.float64)
    if window is None:
        return np.arange(times.shape[0])
    lo, hi = window_bounds(window)
    return np.flatnonzero((times >= lo) & (times <= hi))


def select_times(t: ArrayLike, y: ArrayLike | None = None, *, window: tuple[float | None, float | None] | None = None,
                 max_points: int | None = None) -> NDArray[np.intp]:
    """Indices to plot: inside ``window``, min-max decimated on ``y`` to ``max_points`` (strided without ``y``)."""
    index = window_index(t, window)
    if y is None:
        return stride(index, max_points)
    return decimate(y, max_points, index)


def is_geometric(values: Iterable[Any], rtol: float = 1e-6) -> bool:
    """True for three or more distinct positive numbers in constant ratio (a ``geomspace`` grid)."""
    try:
        x = np.unique(np.asarray([float(v) for v in values if _number(v) is not None], dtype=np.float64))
    except (TypeError, ValueError):
        return False
    if x.size < 3 or not np.all(np.isfinite(x)) or np.any(x <= 0):
        return False
    ratios = x[1:] / x[:-1]
    return bool(np.allclose(ratios, ratios[0], rtol=rtol, atol=0.0)) and ratios[0] > 1 + 1e-9


def parameter_display(name: str, scale: float | None = None, unit: str | None = None) -> tuple[float, str]:
    """Factor and unit of a parameter axis: the given ones, else :data:`PARAMETER_AXES`, else (1, "")."""
    default_scale, default_unit = PARAMETER_AXES.get(name, (1.0, ""))
    if scale is None and unit is None:
        return default_scale, default_unit
    if scale is None:
        return (default_scale if unit == default_unit else 1.0), unit or ""
    if unit is None:
        return float(scale), (default_unit if scale == default_scale else "")
    return float(scale), unit


def parameter_axis(ax: Axes, which: str, name: str, values: Iterable[Any], unit: str,
                   log: bool | None = None) -> bool:
    """Label the x or y axis with the parameter and its unit; log scale when ``log`` or, if None, when
    ``values`` form a geometric grid. Returns whether the axis is logarithmic."""
    use_log = is_geometric(values) if log is None else bool(log)
    axis = "x" if which == "x" else "y"
    getattr(ax, f"set_{axis}label")(quantity_label(name, unit))
    if use_log:
        getattr(ax, f"set_{axis}scale")("log")
    return use_log
