"""The absolute-tolerance rule shared by every method of :func:`daeclear.simulate`.

IDA (``solvers.ida``) and the explicit and scipy methods (``solvers.explicit``) both turn the
user's ``atol`` into one value per state here, so that neither solver module imports the other
for it.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..assembly.assemble import KIND_MULTIPLIER, KIND_WORK, DAEModel
from ..errors import SceneError

# Multipliers are kept out of IDA's error test by a huge absolute tolerance (scikit-sundae has
# no IDASetSuppressAlg): atol = MULTIPLIER_ATOL_FACTOR * rtol, see docs/performance.md.
MULTIPLIER_ATOL_FACTOR = 1e12
# ... and never below this floor (N or N m): at rtol 1e-11, 1e12 * rtol = 10 N would put impact
# multipliers of 1e3..1e5 N back into the error test, which breaks the index-2 GGL runs.
MULTIPLIER_ATOL_FLOOR = 1e4
# Default absolute tolerance of positions and velocities, relative to rtol: contact runs resolve
# micrometre penetrations, so positions need an absolute floor well below the clearance.
DEFAULT_ATOL_FACTOR = 1e-3


def positive(name: str, value: Any, unit: str, allow_zero: bool = False) -> float:
    """``value`` as a float if it is a finite number > 0 (>= 0 with ``allow_zero``), else a
    SceneError naming ``name``, the value and the rule."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    ok = ok and (value >= 0 if allow_zero else value > 0)
    if not ok:
        rule = ">= 0" if allow_zero else "> 0"
        raise SceneError(f"simulate: {name}={value!r} {unit}, must be a finite number {rule}.")
    return float(value)


def tolerance_vector(model: DAEModel, rtol: float, atol: float | ArrayLike | None) -> NDArray[np.float64]:
    """Absolute tolerances per state: q and v from ``atol``; multipliers out of the error test."""
    if atol is None:
        vec = np.full(model.n_states, DEFAULT_ATOL_FACTOR * rtol)
    elif np.ndim(atol) == 0:
        vec = np.full(model.n_states, positive("atol", float(atol), ""))  # type: ignore[arg-type]
    else:
        vec = np.asarray(atol, dtype=float).copy()
        if vec.shape != (model.n_states,) or not np.all(np.isfinite(vec)) or np.any(vec <= 0):
            raise SceneError(
                f"simulate: atol has shape {vec.shape}; give a positive number or {model.n_states} "
                f"positive values (one per state: {', '.join(model.state_names[:4])}, ...)."
            )
        return vec
    multipliers, work = _out_of_error_test(model.state_kinds)
    vec[multipliers] = max(MULTIPLIER_ATOL_FACTOR * rtol, MULTIPLIER_ATOL_FLOOR)
    vec[work] = 1e30  # a pure quadrature: out of the error test, the solution is unchanged
    return vec


@functools.lru_cache(maxsize=16)
def _out_of_error_test(kinds: tuple[str, ...]) -> tuple[list[int], list[int]]:
    """Indices of the multipliers and of the work state (a structure's, kept: a sweep's runs share them)."""
    return [i for i, k in enumerate(kinds) if k == KIND_MULTIPLIER], [i for i, k in enumerate(kinds) if k == KIND_WORK]
