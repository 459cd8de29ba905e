"""Archard wear of a revolute clearance joint: the law, the pressure over the contact arc, the depth.

Archard: ``dV = k F_n ds``, spread over the contact arc as ``dh = k p ds`` with an
``"elastic-foundation"`` or ``"hertz"`` pressure shape (docs/wear.md); the profile is a depth per
node (node ``k`` at ``2 pi k / nodes``) in the worn body's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..core.errors import SceneError
from ._checks import check_number

__all__ = ["ArchardWear", "DISTRIBUTIONS", "MAX_DEPTH_FRACTION", "SURFACES", "WearHistoryArrays", "half_angle_hertz",
           "half_angle_overlap", "node_weights", "profile_coefficients", "spread", "profile_depth", "wear_increment",
           "worn_volume"]

SURFACES: tuple[str, ...] = ("bearing", "journal", "both")
#: The deepest wear the gap's model takes, as a fraction of the bearing radius (it neglects the profile's
#: slope in the contact points; docs/wear.md); simulate_wear stops there.
MAX_DEPTH_FRACTION = 0.05
DISTRIBUTIONS: tuple[str, ...] = ("elastic-foundation", "hertz")
# the grid the arcs' pressure is spread on, per node spacing
SUBDIVISIONS = 4
# arcs wider than 2^WIDTH_BITS grid steps share a shape within 2^-(WIDTH_BITS + 1) of their half-width
WIDTH_BITS = 8
# contacts binned in one pass: SPREAD_SAMPLES // ARC_SAMPLES (index arrays of a few MB)
ARC_SAMPLES = 64
SPREAD_SAMPLES = 1 << 20


@dataclass(frozen=True, kw_only=True)
class ArchardWear:
    """Archard wear of a revolute clearance joint's surfaces.

    Parameters
    ----------
    coefficient : float
        Dimensional wear coefficient k, m^2/N (wear coefficient over hardness), > 0.
    length : float
        Axial length of the bearing, m, > 0: the pressure is a force over ``R dphi L``.
    nodes : int
        Nodes of the depth profile over the angle (>= 16), 360 by default.
    surface : {"bearing", "journal", "both"}
        Which surfaces wear.
    distribution : {"elastic-foundation", "hertz"}
        Shape of the pressure over the contact arc (module docstring).
    modes : int
        Fourier modes of the worn profile in the joint's gap (:func:`profile_coefficients`), >= 1 and
        below ``nodes / 2``.
    """

    coefficient: float
    length: float
    nodes: int = 360
    surface: Literal["bearing", "journal", "both"] = "bearing"
    distribution: Literal["elastic-foundation", "hertz"] = "elastic-foundation"
    modes: int = 48

    def __post_init__(self) -> None:
        check_number("ArchardWear", "coefficient", self.coefficient, low=0.0, unit="m^2/N")
        check_number("ArchardWear", "length", self.length, low=0.0, unit="m")
        if isinstance(self.nodes, bool) or not isinstance(self.nodes, (int, np.integer)) or self.nodes < 16:
            raise SceneError(f"ArchardWear: nodes={self.nodes!r}, must be an integer >= 16.")
        if self.surface not in SURFACES:
            raise SceneError(f"ArchardWear: surface={self.surface!r}, must be one of {', '.join(SURFACES)}.")
        if self.distribution not in DISTRIBUTIONS:
            raise SceneError(f"ArchardWear: distribution={self.distribution!r}, must be one of "
                             f"{', '.join(DISTRIBUTIONS)}.")
        if (isinstance(self.modes, bool) or not isinstance(self.modes, (int, np.integer))
                or not 1 <= self.modes < self.nodes / 2):
            raise SceneError(f"ArchardWear: modes={self.modes!r}, must be an integer >= 1 and < nodes / 2 "
                             f"({self.nodes / 2:g}).")

    @property
    def surfaces(self) -> tuple[str, ...]:
        """The worn surfaces: ("bearing",), ("journal",) or both."""
        return ("bearing", "journal") if self.surface == "both" else (self.surface,)

    @property
    def angles(self) -> NDArray[np.float64]:
        """The nodes' angles in the worn body's frame, rad."""
        return 2.0 * math.pi * np.arange(self.nodes) / self.nodes


def half_angle_overlap(penetration: ArrayLike, clearance: float) -> Any:
    """Half-angle (rad) of the arc where a journal at eccentricity ``c + delta`` overlaps its bearing;
    0 without penetration."""
    return np.arccos(clearance / (clearance + np.clip(penetration, 0.0, None)))


def half_angle_hertz(force: ArrayLike, bearing_radius: float, journal_radius: float, length: float,
                     effective_modulus: float) -> Any:
    """Half-angle of the Hertz line contact of a journal in its bearing, rad: ``b / R_b``,
    ``b = sqrt(4 F R_eff / (pi L E*))``, ``R_eff = R_b R_j / (R_b - R_j)``; 0 without force."""
    r_eff = bearing_radius * journal_radius / (bearing_radius - journal_radius)
    return np.sqrt(4.0 * np.clip(force, 0.0, None) * r_eff / (math.pi * length * effective_modulus)) / bearing_radius


def _shape(distribution: str, phi: NDArray[Any], half_angle: NDArray[Any]) -> NDArray[np.float64]:
    """The pressure's shape over the arc (not normalised), 0 outside it; ``half_angle`` > 0."""
    if distribution == "hertz":
        return np.sqrt(np.clip(1.0 - (phi / half_angle) ** 2, 0.0, None))
    return np.clip(np.cos(phi) - np.cos(half_angle), 0.0, None)


def spread(centres: ArrayLike, half_angles: ArrayLike, loads: ArrayLike, nodes: int,
           distribution: str = "elastic-foundation") -> NDArray[np.float64]:
    """Loads spread over the nodes: ``sum_i loads[i] * weights(centres[i], half_angles[i])``.

    On a grid SUBDIVISIONS times finer than the nodes, each arc's pressure shape is sampled at the grid's
    points (its half-angle rounded to the grid) and normalised; each load is split between the two grid
    points around its centre, the loads of arcs of one width summed into one histogram, and every
    histogram convolved with its arc's shape (FFT, circular); each grid point's share is then split
    between its two neighbouring nodes linearly. Work grows with the contacts only through two
    ``bincount`` passes: no per-contact samples. The FFT's round-off (1e-16 of the largest depth) is
    set to zero, so nodes off every arc stay exactly 0."""
    centre = np.asarray(centres, dtype=float).ravel()
    half = np.asarray(half_angles, dtype=float).ravel()
    load = np.asarray(loads, dtype=float).ravel()
    if not centre.size:
        return np.zeros(nodes)
    size = nodes * SUBDIVISIONS
    step = 2.0 * math.pi / size
    widths = np.rint(half / step).astype(np.int64)  # the arc's half-width in grid steps
    coarse = np.maximum(np.floor(np.log2(np.maximum(widths, 1))).astype(np.int64) - WIDTH_BITS, 0)
    widths = ((widths + (1 << coarse >> 1)) >> coarse) << coarse  # wide arcs: 2^WIDTH_BITS widths an octave
    kinds, kind = np.unique(widths, return_inverse=True)
    histogram = np.zeros(kinds.size * size)
    rows = max(1, SPREAD_SAMPLES // ARC_SAMPLES)  # contacts per pass: the index arrays stay a few MB
    for first in range(0, centre.size, rows):
        part = slice(first, first + rows)
        position = np.remainder(centre[part], 2.0 * math.pi) / step
        lower = np.floor(position)
        share = position - lower
        row = kind[part] * size
        below = lower.astype(np.int64)
        cells = np.concatenate((row + below % size, row + (below + 1) % size))  # the grid points either side
        histogram += np.bincount(cells, np.concatenate((load[part] * (1.0 - share), load[part] * share)),
                                 minlength=histogram.size)
    # every width's shape at once: row k over the offsets -widest..widest, zero beyond its own arc (a
    # width 0 is a point: its shape is nonzero at the offset 0 alone)
    offsets = np.arange(-int(kinds[-1]), int(kinds[-1]) + 1)
    values = _shape(distribution, offsets * step, np.maximum(kinds, 1)[:, None] * step)
    values[np.abs(offsets) > kinds[:, None]] = 0.0
    values /= values.sum(axis=1, keepdims=True)
    shapes = np.zeros((kinds.size, size))
    for first in range(0, offsets.size, size):  # an arc wider than the circle wraps onto itself
        shapes[:, offsets[first:first + size] % size] += values[:, first:first + size]
    fine = np.fft.irfft(np.sum(np.fft.rfft(histogram.reshape(kinds.size, size), axis=1)
                               * np.fft.rfft(shapes, axis=1), axis=0), n=size)
    fine[np.abs(fine) <= 1e-13 * np.max(np.abs(fine))] = 0.0
    node = np.arange(size) // SUBDIVISIONS
    part_up = (np.arange(size) % SUBDIVISIONS) / SUBDIVISIONS
    total = (np.bincount(node, fine * (1.0 - part_up), minlength=nodes)
             + np.bincount((node + 1) % nodes, fine * part_up, minlength=nodes))
    return np.maximum(total, 0.0)


def node_weights(centre: float, half_angle: float, nodes: int, distribution: str = "elastic-foundation"
                 ) -> NDArray[np.float64]:
    """The share of one contact's load that each node carries (they sum to 1): :func:`spread` of a unit load."""
    return spread([centre], [half_angle], [1.0], nodes, distribution)


@dataclass(frozen=True)
class WearHistoryArrays:
    """A run's contact history at each output time: time, normal force, the contact direction's angle
    in the bearing's and the journal's frame, sliding speed and penetration (SI units)."""

    t: NDArray[np.float64]
    force: NDArray[np.float64]
    angle_bearing: NDArray[np.float64]
    angle_journal: NDArray[np.float64]
    slip_speed: NDArray[np.float64]
    penetration: NDArray[np.float64]


def wear_increment(wear: ArchardWear, history: WearHistoryArrays, *, bearing_radius: float, clearance: float,
                   effective_modulus: float | None = None) -> tuple[dict[str, NDArray[np.float64]], float]:
    """({surface: depth per node} (m), sliding work (N m)) of one stretch of a run: each interval
    contributes ``k F ds`` (mean force, trapezoidal distance), spread around its mean contact angle."""
    t = np.asarray(history.t, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) < 0):
        raise SceneError("wear_increment: history.t must hold at least two increasing times.")
    force = 0.5 * (history.force[1:] + history.force[:-1])
    ds = 0.5 * (np.abs(history.slip_speed[1:]) + np.abs(history.slip_speed[:-1])) * np.diff(t)
    delta = 0.5 * (history.penetration[1:] + history.penetration[:-1])
    active = np.flatnonzero((force > 0.0) & (ds > 0.0))
    area = bearing_radius * (2.0 * math.pi / wear.nodes) * wear.length  # one node's cell, m^2
    F, d = force[active], delta[active]
    if wear.distribution == "hertz":
        if effective_modulus is None:
            raise SceneError("wear_increment: the 'hertz' distribution needs effective_modulus (Pa).")
        half = half_angle_hertz(F, bearing_radius, bearing_radius - clearance, wear.length, effective_modulus)
    else:
        half = half_angle_overlap(d, clearance)
    loads = wear.coefficient * F * ds[active] / area
    angles = {"bearing": history.angle_bearing, "journal": history.angle_journal}
    depth = {}
    for s in wear.surfaces:
        a, b = np.asarray(angles[s][:-1], dtype=float)[active], np.asarray(angles[s][1:], dtype=float)[active]
        step = b - a
        centre = a + 0.5 * (step - 2.0 * math.pi * np.round(step / (2.0 * math.pi)))  # the shorter way round
        depth[s] = spread(centre, half, loads, wear.nodes, wear.distribution)
    return depth, float(np.dot(force, ds))


def profile_coefficients(depth: ArrayLike, modes: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A nodal depth's Fourier series to ``modes`` (least squares on the nodes; the mean, so the worn
    volume, kept exactly): (a_0..a_modes, b_1..b_modes) of ``a_0 + sum a_m cos(m theta) + b_m sin(m theta)``."""
    h = np.asarray(depth, dtype=float)
    series = np.fft.rfft(h)[1:modes + 1] * (2.0 / h.size)  # sum h_k exp(-i m theta_k): a_m - i b_m, scaled
    return np.concatenate([[h.mean()], series.real]), -series.imag


def profile_depth(a: ArrayLike, b: ArrayLike, angles: ArrayLike) -> NDArray[np.float64]:
    """The smooth profile's depth at ``angles`` (rad), from :func:`profile_coefficients`' output."""
    a, b, theta = np.asarray(a, dtype=float), np.asarray(b, dtype=float), np.asarray(angles, dtype=float)
    m = np.arange(1, b.size + 1)
    return a[0] + np.cos(np.multiply.outer(theta, m)) @ a[1:] + np.sin(np.multiply.outer(theta, m)) @ b


def worn_volume(depth: ArrayLike, bearing_radius: float, length: float) -> float:
    """The volume of a depth profile over equally spaced nodes, m^3."""
    values = np.asarray(depth, dtype=float)
    return float(values.sum()) * bearing_radius * (2.0 * math.pi / values.size) * length
