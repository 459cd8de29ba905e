"""Tiny math shim so each contact law is written once for floats, numpy and CasADi.

Each function uses the CasADi operation when an argument is a CasADi ``SX``, ``MX`` or ``DM``
(imported lazily), numpy otherwise. Guard every operand of a fractional power, a logarithm or a
division (``fmax(delta, 0.0) ** 1.5``); ``if_else`` evaluates both branches, so both must be finite.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "as_numeric", "atan2", "cos", "exp", "fabs", "fmax", "fmin", "if_else", "is_symbolic", "log", "log1p",
    "sign", "sin", "sqrt", "tanh",
]


def is_symbolic(*args: Any) -> bool:
    """Return True if any argument is a CasADi object (``SX``, ``MX`` or ``DM``)."""
    return any(type(a).__module__ == "casadi.casadi" for a in args)


def _ca() -> Any:
    import casadi

    return casadi


def fmax(a: Any, b: Any) -> Any:
    """Elementwise maximum."""
    return _ca().fmax(a, b) if is_symbolic(a, b) else np.maximum(a, b)


def fmin(a: Any, b: Any) -> Any:
    """Elementwise minimum."""
    return _ca().fmin(a, b) if is_symbolic(a, b) else np.minimum(a, b)


def if_else(condition: Any, if_true: Any, if_false: Any) -> Any:
    """``if_true`` where ``condition`` holds, else ``if_false`` (both branches are evaluated)."""
    if is_symbolic(condition, if_true, if_false):
        return _ca().if_else(condition, if_true, if_false)
    return np.where(condition, if_true, if_false)


def log(x: Any) -> Any:
    """Natural logarithm."""
    return _ca().log(x) if is_symbolic(x) else np.log(x)


def log1p(x: Any) -> Any:
    """``log(1 + x)``, accurate for small ``x``."""
    return _ca().log1p(x) if is_symbolic(x) else np.log1p(x)


def exp(x: Any) -> Any:
    """Exponential."""
    return _ca().exp(x) if is_symbolic(x) else np.exp(x)


def sqrt(x: Any) -> Any:
    """Square root."""
    return _ca().sqrt(x) if is_symbolic(x) else np.sqrt(x)


def sin(x: Any) -> Any:
    """Sine."""
    return _ca().sin(x) if is_symbolic(x) else np.sin(x)


def cos(x: Any) -> Any:
    """Cosine."""
    return _ca().cos(x) if is_symbolic(x) else np.cos(x)


def tanh(x: Any) -> Any:
    """Hyperbolic tangent (a smooth sign: ``tanh(x / eps)``)."""
    return _ca().tanh(x) if is_symbolic(x) else np.tanh(x)


def atan2(y: Any, x: Any) -> Any:
    """Angle of the vector (x, y), in (-pi, pi]."""
    return _ca().atan2(y, x) if is_symbolic(y, x) else np.arctan2(y, x)


def sign(x: Any) -> Any:
    """Sign, with ``sign(0) == 0`` in both backends (derivative 0 everywhere in CasADi)."""
    return _ca().sign(x) if is_symbolic(x) else np.sign(x)


def fabs(x: Any) -> Any:
    """Absolute value."""
    return _ca().fabs(x) if is_symbolic(x) else np.abs(x)


def as_numeric(*args: Any) -> tuple[bool, tuple[Any, ...]]:
    """``(scalar, converted)``: CasADi arguments unchanged, others as float arrays; ``scalar`` when
    every non-None argument is a scalar (the caller then returns a ``float``)."""
    if is_symbolic(*args):
        return False, args
    converted = tuple(None if a is None else np.asarray(a, dtype=float) for a in args)
    scalar = all(c is None or c.ndim == 0 for c in converted)
    return scalar, converted
