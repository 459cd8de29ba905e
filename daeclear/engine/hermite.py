"""Cubic Hermite interpolation between two states with known time derivatives: output times between
steps where the integrator has no dense output (the python IDA session, :mod:`daeclear.solvers.explicit`).
"""

from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["cubic_hermite"]


@overload
def cubic_hermite(t0: ArrayLike, y0: NDArray, yp0: NDArray, t1: ArrayLike, y1: NDArray, yp1: NDArray,
                  t: NDArray, *, derivative: Literal[False] = ...) -> NDArray: ...


@overload
def cubic_hermite(t0: ArrayLike, y0: NDArray, yp0: NDArray, t1: ArrayLike, y1: NDArray, yp1: NDArray,
                  t: NDArray, *, derivative: Literal[True]) -> tuple[NDArray, NDArray]: ...


def cubic_hermite(t0: ArrayLike, y0: NDArray, yp0: NDArray, t1: ArrayLike, y1: NDArray, yp1: NDArray,
                  t: NDArray, *, derivative: bool = False) -> NDArray | tuple[NDArray, NDArray]:
    """The cubic with values ``y0``, ``y1`` and derivatives ``yp0``, ``yp1`` at ``t0``, ``t1``, at the
    times ``t`` (m points): an (m, n) array, with ``derivative=True`` also its time derivative. One
    interval for all points (scalar ``t0``, ``t1``; ``y0`` ... (n,)) or one per point ((m,) and (m, n)).
    """
    dt = np.asarray(t1, dtype=float) - t0
    u = ((t - t0) / dt)[..., None]
    h = dt[..., None]
    u2, u3 = u * u, u * u * u
    y = (2 * u3 - 3 * u2 + 1) * y0 + (u3 - 2 * u2 + u) * h * yp0 + (-2 * u3 + 3 * u2) * y1 + (u3 - u2) * h * yp1
    if not derivative:
        return y
    yp = ((6 * u2 - 6 * u) / h * y0 + (3 * u2 - 4 * u + 1) * yp0 + (-6 * u2 + 6 * u) / h * y1
          + (3 * u2 - 2 * u) * yp1)
    return y, yp
