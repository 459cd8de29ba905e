"""Parameter checks shared by the contact laws: one message format, always a SceneError."""

from __future__ import annotations

import math
import numbers
from typing import Any

from ..core.errors import SceneError


def check_number(owner: str, field: str, value: Any, *, low: float = -math.inf, high: float = math.inf,
                 low_open: bool = True, high_open: bool = True, unit: str = "") -> float:
    """``value`` as a float, or a SceneError naming owner, field, value and range
    (``LankaraniNikravesh: restitution=1.2, must be in (0, 1].``); infinite bounds are open."""
    if type(value) is float:  # the common case first: numbers.Real is an abstract class, slow to test
        x = value
    elif isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise SceneError(f"{owner}: {field}={value!r} is not a real number.")
    else:
        x = float(value)
    suffix = f" {unit}" if unit else ""
    if math.isnan(x):
        raise SceneError(f"{owner}: {field}=nan{suffix}, must be a number.")
    below = x <= low if (low_open or low == -math.inf) else x < low
    above = x >= high if (high_open or high == math.inf) else x > high
    if below or above:
        if high == math.inf:
            rule = f"must be {'>' if low_open else '>='} {low:g}"
        elif low == -math.inf:
            rule = f"must be {'<' if high_open else '<='} {high:g}"
        else:
            rule = f"must be in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
        raise SceneError(f"{owner}: {field}={x:g}{suffix}, {rule}.")
    return x


def set_field(obj: Any, field: str, value: Any) -> None:
    """Assign in ``__post_init__`` of a frozen dataclass (normalising a validated value)."""
    object.__setattr__(obj, field, value)
