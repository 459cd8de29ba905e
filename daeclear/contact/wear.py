"""Archard wear of a revolute clearance joint: the law, the pressure over the contact arc, the depth.

Archard's law: the worn volume is ``dV = k F_n ds``, with ``k`` the dimensional wear coefficient
(the wear coefficient over the hardness, m^2/N; published joint studies use about 1e-14 to 1e-13)
and ``ds`` the sliding distance of the contacting material points. Spread over the contact arc with
a pressure ``p(phi)`` (phi measured from the contact point), the depth worn at each material point
is ``dh = k p ds``. Whatever the distribution, the worn volume is ``k`` times the sliding work
``integral of F_n |v_slip| dt``: :func:`wear_increment` spreads each load onto the profile's nodes
so that this holds to round-off on the discrete profile (tests/test_wear.py checks it).

Two pressure shapes over the arc ``|phi| < phi0`` (docs/wear.md):

- ``"elastic-foundation"`` (Winkler): ``p ~ cos(phi) - cos(phi0)``, the overlap of journal and
  bearing along each direction; ``phi0 = arccos(c / (c + delta))`` from the penetration ``delta``;
- ``"hertz"``: ``p ~ sqrt(1 - (phi / phi0)^2)``, the Hertz line contact of conformal cylinders,
  ``phi0 = b / R`` with ``b = sqrt(4 F R_eff / (pi L E*))`` and ``R_eff = R_b R_j / (R_b - R_j)``.

The profile is a depth per node over the angle in the worn body's frame (the bearing's, the
journal's or both); the nodes are equally spaced, node ``k`` at ``2 pi k / nodes``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import SceneError
from ._checks import check_number

__all__ = ["ArchardWear", "DISTRIBUTIONS", "SURFACES", "WearHistoryArrays", "half_angle_hertz",
           "half_angle_overlap", "node_weights", "wear_increment", "worn_volume"]

SURFACES: tuple[str, ...] = ("bearing", "journal", "both")
DISTRIBUTIONS: tuple[str, ...] = ("elastic-foundation", "hertz")
# samples of the pressure over one contact arc when it is spread onto the nodes (at least this many,
# and at least 8 per node the arc covers): the spread weights are exact in sum whatever the number
ARC_SAMPLES = 64


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
    """

    coefficient: float
    length: float
    nodes: int = 360
    surface: Literal["bearing", "journal", "both"] = "bearing"
    distribution: Literal["elastic-foundation", "hertz"] = "elastic-foundation"

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

    @property
    def angles(self) -> NDArray[np.float64]:
        """The nodes' angles in the worn body's frame, rad."""
        return 2.0 * math.pi * np.arange(self.nodes) / self.nodes


def half_angle_overlap(penetration: float, clearance: float) -> float:
    """Half-angle of the arc where a journal at eccentricity ``c + delta`` overlaps its bearing, rad."""
    if penetration <= 0.0:
        return 0.0
    return math.acos(clearance / (clearance + penetration))


def half_angle_hertz(force: float, bearing_radius: float, journal_radius: float, length: float,
                     effective_modulus: float) -> float:
    """Half-angle of the Hertz line contact of a journal in its bearing, rad: ``b / R_b``,
    ``b = sqrt(4 F R_eff / (pi L E*))``, ``R_eff = R_b R_j / (R_b - R_j)``."""
    if force <= 0.0:
        return 0.0
    r_eff = bearing_radius * journal_radius / (bearing_radius - journal_radius)
    return math.sqrt(4.0 * force * r_eff / (math.pi * length * effective_modulus)) / bearing_radius


def _shape(distribution: str, phi: NDArray[np.float64], half_angle: float) -> NDArray[np.float64]:
    """The pressure's shape over the arc (not normalised), 0 outside it."""
    if distribution == "hertz":
        return np.sqrt(np.clip(1.0 - (phi / half_angle) ** 2, 0.0, None))
    return np.clip(np.cos(phi) - math.cos(half_angle), 0.0, None)


def node_weights(centre: float, half_angle: float, nodes: int, distribution: str = "elastic-foundation"
                 ) -> NDArray[np.float64]:
    """The share of a contact's load that each node carries (they sum to 1).

    The pressure's shape is sampled at the midpoints of equal pieces of the arc ``centre +- half_angle``
    and each sample is split between its two neighbouring nodes in proportion to its distance
    (linear interpolation's weights), so that an arc narrower than a node's spacing still loads
    the nodes around it smoothly. An arc of zero width puts the load on the nodes around ``centre``.
    """
    spacing = 2.0 * math.pi / nodes
    if half_angle <= 0.0:
        phi, shape = np.zeros(1), np.ones(1)
    else:
        count = max(ARC_SAMPLES, int(math.ceil(16.0 * half_angle / spacing)))
        phi = (np.arange(count) + 0.5) / count * 2.0 * half_angle - half_angle
        shape = _shape(distribution, phi, half_angle)
    position = ((centre + phi) % (2.0 * math.pi)) / spacing
    lower = np.floor(position).astype(int) % nodes
    upper_share = position - np.floor(position)
    weights = np.bincount(lower, shape * (1.0 - upper_share), minlength=nodes)
    weights += np.bincount((lower + 1) % nodes, shape * upper_share, minlength=nodes)
    return weights / weights.sum()


@dataclass(frozen=True)
class WearHistoryArrays:
    """What a run gives the wear computation, at each output time: time (s), normal force (N), the
    contact direction's angle in the bearing's and in the journal's frame (rad), the sliding speed of
    the contact points (m/s) and the penetration (m)."""

    t: NDArray[np.float64]
    force: NDArray[np.float64]
    angle_bearing: NDArray[np.float64]
    angle_journal: NDArray[np.float64]
    slip_speed: NDArray[np.float64]
    penetration: NDArray[np.float64]


def wear_increment(wear: ArchardWear, history: WearHistoryArrays, *, bearing_radius: float, clearance: float,
                   effective_modulus: float | None = None) -> tuple[dict[str, NDArray[np.float64]], float]:
    """The depth worn at each node (m) by one stretch of a run, and its sliding work (N m).

    Each interval between output times contributes ``k F ds`` of volume, ``F`` the mean of its end
    forces and ``ds`` the trapezoid of the sliding speed, spread over the nodes around the
    interval's mean contact angle by :func:`node_weights`. Returns ({surface: depth per node},
    sliding work); the worn volume of each surface is ``sum(depth) * R dphi * L = k * work``.
    """
    t = np.asarray(history.t, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) < 0):
        raise SceneError("wear_increment: history.t must hold at least two increasing times.")
    force = 0.5 * (history.force[1:] + history.force[:-1])
    ds = 0.5 * (np.abs(history.slip_speed[1:]) + np.abs(history.slip_speed[:-1])) * np.diff(t)
    delta = 0.5 * (history.penetration[1:] + history.penetration[:-1])
    active = np.flatnonzero((force > 0.0) & (ds > 0.0))
    area = bearing_radius * (2.0 * math.pi / wear.nodes) * wear.length  # one node's cell, m^2
    surfaces = ("bearing", "journal") if wear.surface == "both" else (wear.surface,)
    depth = {s: np.zeros(wear.nodes) for s in surfaces}
    angles = {"bearing": history.angle_bearing, "journal": history.angle_journal}
    for i in active.tolist():
        if wear.distribution == "hertz":
            if effective_modulus is None:
                raise SceneError("wear_increment: the 'hertz' distribution needs effective_modulus (Pa).")
            half = half_angle_hertz(force[i], bearing_radius, bearing_radius - clearance, wear.length,
                                    effective_modulus)
        else:
            half = half_angle_overlap(delta[i], clearance)
        for s in surfaces:
            a, b = angles[s][i], angles[s][i + 1]
            centre = a + 0.5 * math.remainder(b - a, 2.0 * math.pi)  # the shorter way round
            depth[s] += wear.coefficient * force[i] * ds[i] / area * node_weights(centre, half, wear.nodes,
                                                                                 wear.distribution)
    return depth, float(np.dot(force, ds))


def worn_volume(depth: ArrayLike, bearing_radius: float, length: float) -> float:
    """The volume of a depth profile over equally spaced nodes, m^3."""
    values = np.asarray(depth, dtype=float)
    return float(values.sum()) * bearing_radius * (2.0 * math.pi / values.size) * length
