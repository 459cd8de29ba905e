"""Finite-width journal bearing: Butenschoen's (1976) tables as corrections of the short-bearing forces.

H. J. Butenschoen, *Das hydrodynamische, zylindrische Gleitlager endlicher Breite unter
instationaerer Belastung*, Karlsruhe 1976. Each table (rotation: So_r and beta; squeeze: So_d) is
turned into its ratio to the short (Ocvirk) half film, whose logarithm is interpolated bilinearly
with branch-free hat functions (numbers and CasADi alike); docs/lubrication.md has the details.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import _backend as B

__all__ = ["B_OVER_D", "finite_film_force", "squeeze_ratio", "rotation_ratio"]

#: The tables' length-to-diameter ratios, ascending (the source lists them from 1 down to 1/8).
B_OVER_D = (1 / 8, 1 / 6, 1 / 5, 1 / 4, 1 / 3, 1 / 2.5, 1 / 2, 1.0)
_EPS_R = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.96, 0.97, 0.98, 0.99)
# rows eps, columns B/D = 1, 1/2, 1/2.5, 1/3, 1/4, 1/5, 1/6, 1/8 (the source's order)
_SO_R = """
0.1196 0.0368 0.0243 0.0171 0.0098 0.0063 0.0044 0.0025
0.2518 0.0783 0.0518 0.0366 0.0210 0.0136 0.0095 0.0054
0.4091 0.1304 0.0867 0.0615 0.0354 0.0229 0.0160 0.0091
0.6108 0.2026 0.1357 0.0968 0.0560 0.0364 0.0254 0.0144
0.8903 0.3124 0.2117 0.1522 0.0888 0.0579 0.0406 0.0231
1.3146 0.4982 0.3435 0.2496 0.1476 0.0969 0.0682 0.0390
2.0432 0.8595 0.6075 0.4492 0.2708 0.1797 0.1274 0.0732
3.5663 1.7339 1.2756 0.9687 0.6043 0.4085 0.2930 0.1706
8.4352 5.0881 4.0187 3.2201 2.1595 1.5261 1.1263 0.6776
18.7895 13.3083 11.2225 9.4993 6.9248 5.1833 3.9831 2.5202
24.1172 17.7934 15.2823 13.1525 9.8517 7.5257 5.8712 3.7907
33.1297 25.5920 22.4503 19.7034 15.2697 11.9804 9.5425 6.3397
51.4774 41.9230 37.7412 33.9523 27.5040 22.3556 18.3874 12.7695
107.7868 93.7881 87.2906 81.1597 70.0359 60.3874 52.1425 39.2568
"""
_BETA_R = """
79.410 81.767 82.119 82.299 82.481 82.561 82.608 82.653
73.858 75.142 75.283 75.344 75.287 75.406 75.414 75.422
68.264 68.493 68.423 68.368 68.204 68.261 68.238 68.211
62.571 61.778 61.544 61.382 61.208 61.115 61.062 61.007
56.705 54.993 54.603 54.348 54.069 53.922 53.863 53.784
50.536 48.049 47.521 47.191 46.825 46.647 46.554 46.449
43.859 40.803 40.156 39.756 39.326 39.108 38.983 38.865
36.235 32.938 32.216 31.761 31.249 30.988 30.840 30.692
26.482 23.566 22.849 22.368 21.790 21.476 21.289 21.089
19.450 17.265 16.648 16.207 15.632 15.291 15.075 14.832
17.609 15.660 15.089 14.669 14.109 13.768 13.547 13.262
15.484 13.818 13.313 12.929 12.299 12.062 11.838 11.570
12.903 11.598 11.178 10.850 10.375 10.057 9.835 9.558
9.416 8.587 8.301 8.066 7.703 7.440 7.242 6.975
"""
# squeeze: eps = 0 ... 0.99, closing film (eps_dot > 0) and opening film (eps_dot < 0)
_EPS_D = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.96, 0.97, 0.98)
_SO_D_CLOSING = """
2.4076 0.7224 0.4754 0.3355 0.1919 0.1238 0.0863 0.0488
3.0122 0.9305 0.6159 0.4357 0.2499 0.1614 0.1127 0.0637
3.8485 1.2236 0.8205 0.5826 0.3354 0.2171 0.1517 0.0859
5.0479 1.6904 1.1329 0.8081 0.4675 0.3033 0.2122 0.1203
6.8503 2.4202 1.6392 1.1756 0.6845 0.4455 0.3123 0.1774
9.7319 3.675 2.5206 1.8236 1.0715 0.7005 0.4923 0.2803
14.769 6.0649 4.2362 3.1002 1.8455 1.2147 0.857 0.4899
24.842 11.373 8.156 6.0733 3.6891 2.4543 1.7424 1.0027
50.349 26.676 19.94 15.282 9.6161 6.5227 4.6863 2.7312
160.25 104.75 84.39 68.484 46.559 33.102 24.5 14.77
490.18 371.98 320.59 275.76 205.15 155.23 119.99 76.315
699.59 549.66 492.49 422.2 323.24 250.15 196.59 127.78
1098.6 900.95 806.73 720.35 571.88 455.42 366.1 245.48
2073.5 1774.3 1629.4 1490.8 1239.4 1027.2 853.42 600.66
"""
_SO_D_OPENING = """
2.4076 0.7224 0.4754 0.3355 0.1919 0.1238 0.0863 0.0488
1.9579 0.5732 0.3757 0.2645 0.1509 0.0973 0.0678 0.0383
1.6134 0.4632 0.3027 0.2127 0.1212 0.078 0.0544 0.0307
1.3494 0.3803 0.2479 0.1739 0.0989 0.0637 0.0444 0.025
1.1391 0.3164 0.2058 0.1443 0.082 0.0527 0.0367 0.0207
0.971 0.2664 0.173 0.1211 0.0688 0.0442 0.0308 0.0174
0.8342 0.2265 0.1469 0.1028 0.0583 0.0375 0.0261 0.0147
0.7242 0.1944 0.126 0.0881 0.05 0.0321 0.0223 0.0126
0.6293 0.1685 0.1085 0.0761 0.0432 0.0277 0.0193 0.0109
0.5518 0.1466 0.0948 0.0663 0.0376 0.0241 0.0168 0.0095
0.5177 0.1372 0.0887 0.062 0.0351 0.0226 0.0157 0.0089
0.5113 0.1354 0.0875 0.0612 0.0347 0.0223 0.0155 0.0087
0.5049 0.1337 0.0864 0.0604 0.0342 0.022 0.0153 0.0086
0.4986 0.1319 0.0853 0.0596 0.0338 0.0217 0.0151 0.0085
"""


def _table(text: str) -> np.ndarray:
    """Rows of the source's text, columns reordered to ascending B/D."""
    return np.array([[float(x) for x in line.split()] for line in text.strip().splitlines()])[:, ::-1]


def _short_rotation(eps: np.ndarray, bd: float) -> np.ndarray:
    """Ocvirk's half-film So_r = (B/D)^2 eps sqrt(16 eps^2 + pi^2 (1 - eps^2)) / (2 (1 - eps^2)^2)."""
    q = 1.0 - eps**2
    return bd**2 * eps * np.sqrt(16 * eps**2 + math.pi**2 * q) / (2 * q**2)


def _short_squeeze(eps: np.ndarray, bd: float, closing: bool) -> np.ndarray:
    """The short half film's So_d = 2 (B/D)^2 X(eps), closing or opening (docs/lubrication.md)."""
    q = 1.0 - eps**2
    part = (1 + 2 * eps**2) * (math.pi - np.arccos(eps)) + 3 * eps * np.sqrt(q)
    x = part if closing else math.pi * (1 + 2 * eps**2) - part
    return 2 * bd**2 * x / q**2.5


def _ratios(values: np.ndarray, eps: tuple[float, ...], short: Any) -> np.ndarray:
    """Table / short theory, with a column B/D = 0 of ratio 1 (the short theory's limit) first."""
    e = np.array(eps)
    out = np.stack([values[:, k] / short(e, bd) for k, bd in enumerate(B_OVER_D)], axis=1)
    return np.hstack([np.ones((len(eps), 1)), out])


_BD_NODES = (0.0,) + B_OVER_D
# the logarithms of the ratios are interpolated: they vary far less between the coarse B/D nodes
_ROTATION = np.log(_ratios(_table(_SO_R), _EPS_R, _short_rotation))
_OCVIRK_BETA = np.degrees(np.arctan2(math.pi * np.sqrt(1 - np.square(_EPS_R)), 4 * np.array(_EPS_R)))
_BETA = np.hstack([_OCVIRK_BETA[:, None], _table(_BETA_R)])  # B/D = 0: Ocvirk's attitude angle
_CLOSING = np.log(_ratios(_table(_SO_D_CLOSING), _EPS_D, lambda e, bd: _short_squeeze(e, bd, True)))
_OPENING = np.log(_ratios(_table(_SO_D_OPENING), _EPS_D, lambda e, bd: _short_squeeze(e, bd, False)))


def _hats(x: Any, nodes: tuple[float, ...]) -> list[Any]:
    """Piecewise-linear interpolation weights of x (clamped to the nodes' range) on ``nodes``."""
    x = B.fmin(B.fmax(x, nodes[0]), nodes[-1])
    out = []
    for i, node in enumerate(nodes):
        rise = (x - nodes[i - 1]) / (node - nodes[i - 1]) if i > 0 else 1.0 + 0.0 * x
        fall = (nodes[i + 1] - x) / (nodes[i + 1] - node) if i + 1 < len(nodes) else 1.0 + 0.0 * x
        out.append(B.fmax(B.fmin(rise, fall), 0.0))
    return out


def _interpolate(table: np.ndarray, eps_nodes: tuple[float, ...], eps: Any, bd: Any) -> Any:
    """Bilinear interpolation of ``table`` (rows eps_nodes, columns _BD_NODES)."""
    h_eps, h_bd = _hats(eps, eps_nodes), _hats(bd, _BD_NODES)
    return sum(float(table[i, j]) * h_eps[i] * h_bd[j] for i in range(len(eps_nodes)) for j in range(len(_BD_NODES))
               if table[i, j] != 0.0) + 0.0 * eps


def rotation_ratio(eps: Any, bd: Any) -> tuple[Any, Any]:
    """(Butenschoen's So_r / the short theory's, attitude angle in rad) at (eps, B/D)."""
    return B.exp(_interpolate(_ROTATION, _EPS_R, eps, bd)), _interpolate(_BETA, _EPS_R, eps, bd) * (math.pi / 180.0)


def squeeze_ratio(eps: Any, bd: Any, closing: Any) -> Any:
    """Butenschoen's So_d / the short half film's at (eps, B/D); ``closing`` a 0/1 flag (or bool)."""
    return (closing * B.exp(_interpolate(_CLOSING, _EPS_D, eps, bd))
            + (1.0 - closing) * B.exp(_interpolate(_OPENING, _EPS_D, eps, bd)))


def finite_film_force(wedge: tuple[Any, Any], squeeze: tuple[Any, Any], eps: Any, w: Any, eps_dot: Any,
                      bd: Any) -> tuple[Any, Any]:
    """(radial, tangential) of a finite bearing from the short half film's wedge and squeeze parts:
    the wedge part scaled to So_r and turned to Butenschoen's attitude angle, the squeeze part scaled
    to So_d (closing or opening film)."""
    k_rot, beta = rotation_ratio(eps, bd)
    turn = beta - B.atan2(math.pi * B.sqrt(1.0 - eps * eps), 4.0 * eps)  # minus Ocvirk's attitude angle
    sense = B.sign(w)
    (r, t), (sq_r, sq_t) = wedge, squeeze
    k_sq = squeeze_ratio(eps, bd, B.if_else(eps_dot >= 0.0, 1.0, 0.0))
    radial = k_rot * (r * B.cos(turn) - sense * t * B.sin(turn)) + k_sq * sq_r
    tangential = k_rot * (t * B.cos(turn) + sense * r * B.sin(turn)) + k_sq * sq_t
    return radial, tangential
