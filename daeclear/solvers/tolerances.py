"""Absolute tolerances per state from the mechanism's own scales (:func:`scales`): the rule every
method shares; the formulas and the round-off floor are in docs/engine.md, "Tolerances".
Multipliers (and the work state of ``track_work``) are always out of the error test.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..assembly.assemble import KIND_MULTIPLIER, KIND_WORK, DAEModel
from ..core.errors import DaeclearWarning
from ..core.options import ATOL_QUANTITIES as QUANTITIES, atol_by_quantity, fail

# Multipliers are kept out of IDA's error test (scikit-sundae has no IDASetSuppressAlg) by
# atol = max(MULTIPLIER_ATOL_FACTOR * rtol, MULTIPLIER_ATOL_FLOOR N): below the floor impact
# multipliers (1e3..1e5 N) would be back in the test, which breaks GGL (docs/performance.md).
MULTIPLIER_ATOL_FACTOR = 1e12
MULTIPLIER_ATOL_FLOOR = 1e4
# Round-off floor of an absolute tolerance, in eps times the quantity's scale: GGL's Newton fails
# below 5-260 eps (bench_convergence.py); the ODE methods' error estimates need ~10 eps.
ROUNDOFF_FACTOR = 300.0
ODE_ROUNDOFF_FACTOR = 10.0
EPS = float(np.finfo(float).eps)
# The default absolute tolerances as fractions of each quantity's scale (per unit of rtol).
POSITION_FRACTION = 6e-3
CLEARANCE_SPAN = 2.0
ANGLE_FRACTION = 1e-3
VELOCITY_FRACTION = 1e-5

UNITS = {"position": "m", "angle": "rad", "velocity": "m/s", "angular_velocity": "rad/s"}


@dataclass(frozen=True)
class Scales:
    """A mechanism's size L (``length``, m), the length a run must resolve (``resolution``, m) and its
    angular rate W (``rate``, rad/s)."""

    length: float
    resolution: float
    rate: float

    def default_atol(self, rtol: float, *, newton: bool = True) -> dict[str, float]:
        """The default absolute tolerance of each quantity at ``rtol`` (never below round-off)."""
        raw = {"position": rtol * self.resolution, "angle": rtol * ANGLE_FRACTION,
               "velocity": rtol * VELOCITY_FRACTION * self.length * self.rate,
               "angular_velocity": rtol * VELOCITY_FRACTION * self.rate}
        lowest = self.roundoff(newton)
        return {q: max(raw[q], lowest[q]) for q in QUANTITIES}

    def roundoff(self, newton: bool = True) -> dict[str, float]:
        """The smallest absolute tolerance of each quantity that IDA's Newton corrections (``newton``)
        or the ODE methods' error estimates can meet."""
        unit = (ROUNDOFF_FACTOR if newton else ODE_ROUNDOFF_FACTOR) * EPS
        return {"position": unit * self.length, "angle": unit, "velocity": unit * self.length * self.rate,
                "angular_velocity": unit * self.rate}


def scales(model: DAEModel) -> Scales:
    """The scales L and W of an assembled mechanism, from its numbers and its declared start (docs/engine.md)."""
    n = model.n_q
    q, v = model.q_guess.tolist(), model.v_guess.tolist()
    values, offset, entries = model.parameter_values.tolist(), 0, {}
    for name, size in model.parameter_layout:  # one pass: name -> its values
        entries[name] = values[offset:offset + size]
        offset += size
    lengths = [math.hypot(q[i], q[i + 1]) for i in range(0, n, 3)]
    lengths += [math.hypot(*entries[name]) for name in entries if name.endswith((".s_i", ".s_j"))]
    lengths += [math.sqrt(entries[f"{body}.inertia"][0] / entries[f"{body}.mass"][0]) for body in model.body_names]
    length = max([*lengths, 0.0]) or 1.0
    clearances = [c for _, c, _ in model.clearance_joints]
    resolution = min([POSITION_FRACTION * length, *(CLEARANCE_SPAN * c for c in clearances)])
    rates = [abs(v[i + 2]) for i in range(0, n, 3)] + [math.hypot(v[i], v[i + 1]) / length for i in range(0, n, 3)]
    for driver in model.driver_names:
        if f"{driver}.speed" in entries:
            speed = abs(entries[f"{driver}.speed"][0])
            rates.append(speed / length if f"{driver}.axis" in entries else speed)
    if "gravity" in entries:
        rates.append(math.sqrt(math.hypot(*entries["gravity"]) / length))
    if model.has_loads:  # each body's speed after a turn of one radian (a travel of L) under the loads alone
        force = np.asarray(model.base_force(0.0, model.q_guess, model.v_guess, model.parameter_values)).ravel()
        acceleration = np.abs(force / model.mass_diagonal).tolist()
        rates += [math.sqrt(acceleration[i + 2]) for i in range(0, n, 3)]
        rates += [math.sqrt(math.hypot(acceleration[i], acceleration[i + 1]) / length) for i in range(0, n, 3)]
    rate = max([*rates, 0.0]) or 1.0
    return Scales(length=float(length), resolution=float(resolution), rate=float(rate))


def state_quantities(model: DAEModel) -> list[str]:
    """The quantity of each position and velocity state (bodies' x, y, phi, then vx, vy, omega)."""
    per_body = ("position", "position", "angle")
    q = [per_body[i % 3] for i in range(model.n_q)]
    return q + [{"position": "velocity", "angle": "angular_velocity"}[k] for k in q]


def tolerance_vector(model: DAEModel, rtol: float, atol: float | Mapping[str, float] | ArrayLike | None,
                     *, newton: bool = True) -> NDArray[np.float64]:
    """Absolute tolerances per state from ``atol`` (None: :class:`Scales`' defaults, a number, a mapping
    by quantity, ``2 n_q`` or ``n_states`` values); given values below round-off are raised, with a warning."""
    n = 2 * model.n_q
    vec = np.empty(model.n_states)
    quantities = state_quantities(model)
    mine = scales(model)
    defaults = mine.default_atol(rtol, newton=newton)
    if atol is None or isinstance(atol, Mapping):  # a mapping: the quantities it does not name keep their defaults
        given = defaults if atol is None else {**defaults, **atol_by_quantity(atol, where="simulate", field="atol")}
        vec[:n] = [given[k] for k in quantities]
    elif np.ndim(atol) == 0:  # values checked by options.atol (SolverOptions)
        vec[:n] = float(atol)  # type: ignore[arg-type]
    else:
        given_vec = np.asarray(atol, dtype=float)  # checked by options.atol but for its length
        if given_vec.shape not in ((n,), (model.n_states,)):
            fail("simulate", "atol", atol, f"a finite number > 0, a mapping by quantity, or {n} values > 0 "
                 f"(positions and velocities: {', '.join(model.state_names[:3])}, ...) or {model.n_states} "
                 "(one per state)", shown=f"array of shape {given_vec.shape}")
        vec[:n] = given_vec[:n]
    if atol is not None:
        _raise_to_roundoff(vec[:n], quantities, mine.roundoff(newton))
    kinds = np.array(model.state_kinds)
    vec[kinds == KIND_MULTIPLIER] = max(MULTIPLIER_ATOL_FACTOR * rtol, MULTIPLIER_ATOL_FLOOR)
    vec[kinds == KIND_WORK] = 1e30  # a pure quadrature: out of the error test, the solution is unchanged
    return vec


def _raise_to_roundoff(vec: NDArray[np.float64], quantities: list[str], floor: dict[str, float]) -> None:
    """Raise each given absolute tolerance below its quantity's round-off to it, and say so."""
    raised = {}
    for i, quantity in enumerate(quantities):
        if vec[i] < floor[quantity]:
            raised[quantity] = vec[i] = floor[quantity]
    if raised:
        parts = ", ".join(f"{q} to {v:.2g} {UNITS[q]}" for q, v in raised.items())
        warnings.warn(f"simulate: atol below round-off raised ({parts}): Newton's corrections cannot be "
                      "smaller (docs/engine.md, Tolerances).", DaeclearWarning, stacklevel=5)


def atol_record(atol: float | Mapping[str, float] | ArrayLike | None) -> Any:
    """``atol`` as a run's parameters record it (JSON types: None, a number, a mapping or a list)."""
    if atol is None or isinstance(atol, float):
        return atol
    if isinstance(atol, Mapping):
        return {str(k): float(v) for k, v in atol.items()}
    return np.ravel(atol).tolist()
