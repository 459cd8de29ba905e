"""Gap crossings inside one step of the non-IDA methods: :func:`candidate` (the rule of ``candidate()``
in ``csrc/ode_driver.c``) says which steps may hold one, :func:`locate` confirms and brackets it."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from .ode_evaluators import Evaluator

__all__ = ["candidate", "cubic_extrema", "locate"]

_EPS = float(np.finfo(float).eps)


def candidate(G0: float, Gd0: float, G1: float, Gd1: float, h: float, hermite: bool = True) -> float:
    """Far-side point s* in (0, h] of a possible crossing of G from <= 0 to > 0 within a step: h when
    G1 > 0, or the first interior maximum above zero of G's cubic Hermite interpolant if earlier; -1: none."""
    if G0 > 0.0:
        return -1.0
    best = h if G1 > 0.0 else -1.0
    if not hermite or max(G0, G1) + 0.15 * h * (abs(Gd0) + abs(Gd1)) <= 0.0:
        return best
    for u, is_max, p in cubic_extrema(G0, Gd0, G1, Gd1, h):
        if is_max and p > 0.0 and (best < 0.0 or u * h < best):
            best = u * h
    return best


def cubic_extrema(G0: float, Gd0: float, G1: float, Gd1: float, h: float) -> list[tuple[float, bool, float]]:
    """Interior extrema (u in (0, 1), is_maximum, value), in order, of the cubic Hermite interpolant
    of G on a step of size h from G and dG/dt at its ends."""
    a0, a1 = h * Gd0, h * Gd1
    A = 6.0 * G0 + 3.0 * a0 - 6.0 * G1 + 3.0 * a1
    B = -6.0 * G0 - 4.0 * a0 + 6.0 * G1 - 2.0 * a1
    C = a0
    us: list[float] = []
    if abs(A) <= 1e-12 * (abs(B) + abs(C)):
        if B != 0.0:
            us.append(-C / B)
    else:
        disc = B * B - 4.0 * A * C
        if disc >= 0.0:
            sq = math.sqrt(disc)
            qq = -0.5 * (B + (sq if B >= 0.0 else -sq))
            us.append(qq / A)
            if qq != 0.0:
                us.append(C / qq)
    out = []
    for u in sorted(us):
        if 0.0 < u < 1.0 and 2.0 * A * u + B != 0.0:
            u2, u3 = u * u, u * u * u
            p = (2 * u3 - 3 * u2 + 1) * G0 + (u3 - 2 * u2 + u) * a0 + (-2 * u3 + 3 * u2) * G1 + (u3 - u2) * a1
            out.append((u, 2.0 * A * u + B < 0.0, p))
    return out


def locate(ev: Evaluator, X_of: Callable[[float], NDArray | None], ta0: float, g_a: tuple[NDArray, NDArray],
            tb_end: float, x_end: NDArray, g_end: tuple[NDArray, NDArray], cands: list[tuple[int, int, float]],
            n_gaps: int) -> tuple[float, NDArray, NDArray] | None | str:
    """The earliest confirmed crossing among ``cands`` (gap, direction, far-side point) of the step
    [ta0, tb_end] with (gaps, rates) ``g_a``, ``g_end`` at its ends: (t_event, x_event, roots_found),
    None when none is confirmed, or an error message when the model could not be evaluated."""
    h = tb_end - ta0
    ttol = 100.0 * _EPS * (abs(ta0) + abs(h))
    best: tuple[float, NDArray, list[tuple[int, int]]] | None = None
    for i, direction, s in cands:
        d = float(direction)
        G0, Gd0, G1, Gd1 = d * g_a[0][i], d * g_a[1][i], d * g_end[0][i], d * g_end[1][i]
        tb = ta0 + s
        if tb >= tb_end or s >= tb_end - ta0:
            tb, xb, Gb = tb_end, x_end, G1
        else:
            x_tb = X_of(tb)
            if x_tb is None:
                return ev.last_message or f"the state could not be computed at t={tb:.17g}"
            xb = x_tb
            gg = ev.gaps(tb, xb)
            if gg is None:
                return ev.last_message
            Gb = d * gg[0][i]
        if not Gb > 0.0:
            continue  # a predicted excursion that the scheme's state does not confirm
        ta, Ga = ta0, G0
        if Gd0 < 0.0:
            # G starts away from zero, typically just after the opposite event (|G| at rounding level,
            # where an interpolant's error can fake a crossing): start the bracket where the state
            # confirms G < 0, at the cubic's first minimum or at 1/4, 1/16, ... of it.
            ext = [u for u, is_max, _ in cubic_extrema(G0, Gd0, G1, Gd1, h)[:1] if not is_max]
            u = min(ext[0] if ext else 0.5, (tb - ta0) / h)
            while u * h > 1e3 * ttol:
                xm = X_of(ta0 + u * h)
                gg = None if xm is None else ev.gaps(ta0 + u * h, xm)
                if gg is not None and d * gg[0][i] < 0.0:
                    ta, Ga = ta0 + u * h, d * gg[0][i]
                    break
                u *= 0.25
        side = 0
        for _ in range(200):
            if tb - ta <= ttol:
                break
            tm = tb - Gb * (tb - ta) / (Gb - Ga) if Gb != Ga else 0.5 * (ta + tb)
            if not ta < tm < tb:
                tm = 0.5 * (ta + tb)
            xm = X_of(tm)
            if xm is None:
                return ev.last_message or f"the state could not be computed at t={tm:.17g}"
            gg = ev.gaps(tm, xm)
            if gg is None:
                return ev.last_message
            Gm = d * gg[0][i]
            if Gm > 0.0:
                tb, Gb, xb = tm, Gm, xm
                if side == 1:
                    Ga *= 0.5
                side = 1
            else:
                ta, Ga = tm, Gm
                if side == -1:
                    Gb *= 0.5
                side = -1
        if best is None or tb < best[0] - ttol:
            best = (tb, xb, [(i, direction)])
        elif abs(tb - best[0]) <= ttol:
            best[2].append((i, direction))
    if best is None:
        return None
    roots = np.zeros(n_gaps, dtype=np.int32)
    for i, direction in best[2]:
        roots[i] = direction
    return best[0], np.array(best[1], dtype=float), roots
