"""The IVP Test Set's car axis problem built with daeclear's public API, against its reference
solution and against scipy on the problem's own equations.

The problem (Schneider; Hairer and Wanner; the IVP Test Set's "caraxis", index 3, t in [0, 3]):
two wheels of mass k = M eps^2 / 2 = 5e-4 (M = 10, eps = 1e-2) joined by a rigid axle of length
L = 1; each wheel hangs on a spring (stiffness 1, free length L0 = 1/2), the left one from the
origin, the right one from the bump point (xb, yb) = (sqrt(L^2 - yb^2), r sin(w t)) (r = 0.1,
w = 10) on the unit circle; the left wheel stays on the line through the origin perpendicular to
(xb, yb) (xl xb + yl yb = 0); gravity 1 along -Y. The reference at t = 3 is the test set's (GAMD
in quadruple precision).

As a user builds it with daeclear (a planar multibody scene; no equation written by hand):

* the bump point is the tip of a ``crank`` of length L turning about the origin, its angle
  asin(r sin(w t) / L): the tip is pinned to a ``follower`` that slides horizontally on a
  ``lifter``, whose height is r sin(w t): the lifter slides vertically on a ``carriage`` with a
  ``Harmonic`` driver (speed 1 + sin(w t + pi/2)), the carriage on the ground with a constant
  speed -1 (the two speeds' constant parts cancel);
* the left wheel slides along the crank's perpendicular through the origin (a ``Translational``
  joint on the crank), the axle is a body pinned to it at distance L, its centre of mass the
  right wheel (a point mass: its own moment of inertia 1e-16 kg m^2, 2e-13 of k L^2);
* the springs are ``SpringDamper`` loads between body-fixed points; the start is given as the
  test set gives it, in the joints' coordinates: ``dc.place(scene, start={"slide": 0.5, "hinge":
  0}, speeds={"slide": 0, "hinge": -1})`` (the left wheel 0.5 from the origin, the axle
  horizontal, both wheels moving at -1/2 along X).

scipy integrates the test set's equations (positions, velocities; multipliers from the
acceleration-level constraints, index 1: scipy has no index-3 DAE solver) with Radau and DOP853.
Each method runs at rtol = atol = 1e-6, 1e-8, 1e-10, 1e-12; the digits are -log10 of the largest
relative error of the four positions at t = 3 (``digits``); the wall time is the best of
``--repeat`` runs in this process (daeclear's compiled library built before, not timed).

Run: ``python benchmarks/external/car_axis.py [--repeat 3] [--write-doc]``; it prints a Markdown table,
which ``--write-doc`` writes into docs/validation.md (block "car-axis", "External references"): the digits
(deterministic, checked by tests/test_doc_numbers.py) and each scipy method's time over daeclear's,
the three runs of a repeat made in turn so the machine's drift hits them alike.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import daeclear as dc

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from doc_tables import write_block  # noqa: E402

DOC, BLOCK = "docs/validation.md", "car-axis"

EPS, M, L, L0, R, W, G = 1e-2, 10.0, 1.0, 0.5, 0.1, 10.0, 1.0
K = M * EPS**2 / 2  # each wheel's mass
T_END = 3.0
#: The test set's reference at t = 3 (xl, yl, xr, yr, ul, vl, ur, vr), GAMD in quadruple precision.
REFERENCE = np.array([0.493455784275402809122e-1, 0.496989460230171153861, 0.104174252488542151681e1,
                      0.373911027265361256927, -0.770583684040972357970e-1, 0.744686658723778553466e-2,
                      0.175568157537232222276e-1, 0.770341043779251976443])
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)


def car_axis_scene() -> dc.Scene:
    """The car axis as a planar mechanism (see the module's docstring)."""
    s = dc.Scene("car_axis", gravity=(0.0, -G))
    carriage = s.add(dc.Body("carriage", mass=1.0, inertia=1.0))
    lifter = s.add(dc.Body("lifter", mass=1.0, inertia=1.0))
    follower = s.add(dc.Body("follower", mass=1.0, inertia=1.0, position=(L, 0.0)))
    crank = s.add(dc.Body("crank", mass=1.0, inertia=1.0))
    left = s.add(dc.Body("left_wheel", mass=K, inertia=K, position=(0.0, L0)))
    axle = s.add(dc.Body("axle", mass=K, inertia=1e-16, position=(L, L0)))  # its centre: the right wheel
    up = (0.0, 1.0)
    s.add(dc.Translational("rail", s.ground, carriage, point_i=(0.0, 0.0), point_j=(0.0, 0.0), axis=up))
    s.add(dc.Driver("sink", joint="rail", speed=-1.0))
    s.add(dc.Translational("lift", carriage, lifter, point_i=(0.0, 0.0), point_j=(0.0, 0.0), axis=up))
    s.add(dc.Driver("bump", joint="lift", speed=1.0,
                    profile=dc.profiles.Harmonic(amplitude=R * W, frequency=W / (2 * math.pi), phase=math.pi / 2)))
    s.add(dc.Translational("level", lifter, follower, point_i=(0.0, 0.0), point_j=(0.0, 0.0), axis=(1.0, 0.0)))
    s.add(dc.Revolute("pivot", s.ground, crank, point_i=(0.0, 0.0), point_j=(0.0, 0.0)))
    s.add(dc.Revolute("tip", crank, follower, point_i=(L, 0.0), point_j=(0.0, 0.0)))
    s.add(dc.Translational("slide", crank, left, point_i=(0.0, 0.0), point_j=(0.0, 0.0), axis=up))
    s.add(dc.Revolute("hinge", left, axle, point_i=(0.0, 0.0), point_j=(-L, 0.0)))
    s.add(dc.SpringDamper("left_spring", s.ground, left, point_i=(0.0, 0.0), point_j=(0.0, 0.0), stiffness=1.0,
                          free_length=L0))
    s.add(dc.SpringDamper("right_spring", crank, axle, point_i=(L, 0.0), point_j=(0.0, 0.0), stiffness=1.0,
                          free_length=L0))
    return dc.place(s, start={"slide": L0, "hinge": 0.0}, speeds={"slide": 0.0, "hinge": -R * W})


def daeclear_state(scene: dc.Scene, rtol: float) -> np.ndarray:
    result = dc.simulate(scene, T_END, rtol=rtol, atol=rtol, save=dc.SaveAt(times=[0.0, T_END]))
    names = ("left_wheel.x", "left_wheel.y", "axle.x", "axle.y", "left_wheel.vx", "left_wheel.vy", "axle.vx", "axle.vy")
    return np.array([result[n][-1] for n in names])


def _bump(t: float) -> tuple[float, float, float, float, float, float]:
    yb, yb1, yb2 = R * math.sin(W * t), R * W * math.cos(W * t), -R * W * W * math.sin(W * t)
    xb = math.sqrt(L * L - yb * yb)
    xb1 = -yb * yb1 / xb
    xb2 = -(yb1 * yb1 + yb * yb2) / xb - (yb * yb1) ** 2 / xb**3
    return xb, yb, xb1, yb1, xb2, yb2


def test_set_rhs(t: float, z: np.ndarray) -> np.ndarray:
    """The test set's equations, index 1: K a = f(q) + G^T lam with G a = c (the second derivatives
    of the two constraints)."""
    xl, yl, xr, yr, ul, vl, ur, vr = z
    xb, yb, xb1, yb1, xb2, yb2 = _bump(t)
    Ll, Lr = math.hypot(xl, yl), math.hypot(xr - xb, yr - yb)
    f = np.array([(L0 - Ll) * xl / Ll, (L0 - Ll) * yl / Ll - K * G,
                  (L0 - Lr) * (xr - xb) / Lr, (L0 - Lr) * (yr - yb) / Lr - K * G])
    dx, dy = xl - xr, yl - yr
    Gq = np.array([[xb, yb, 0.0, 0.0], [2 * dx, 2 * dy, -2 * dx, -2 * dy]])
    c = np.array([-(xb2 * xl + 2 * xb1 * ul + yb2 * yl + 2 * yb1 * vl), -2 * ((ul - ur) ** 2 + (vl - vr) ** 2)])
    A = np.block([[K * np.eye(4), -Gq.T], [Gq, np.zeros((2, 2))]])
    a = np.linalg.solve(A, np.concatenate([f, c]))[:4]
    return np.concatenate([z[4:], a])


def scipy_state(method: str, rtol: float) -> np.ndarray:
    z0 = np.array([0.0, L0, L, L0, -L0 / L, 0.0, -L0 / L, 0.0])
    sol = solve_ivp(test_set_rhs, (0.0, T_END), z0, method=method, rtol=rtol, atol=rtol)
    if not sol.success:
        raise RuntimeError(f"scipy {method} at rtol {rtol}: {sol.message}")
    return sol.y[:, -1]


def digits(state: np.ndarray) -> float:
    """-log10 of the largest error of the positions at t = 3, relative to each reference value."""
    error = np.max(np.abs(state[:4] - REFERENCE[:4]) / np.abs(REFERENCE[:4]))
    return -math.log10(max(error, 1e-17))


def timed(runs: list, repeat: int) -> list[tuple[float, np.ndarray]]:
    """(best wall time, state) of each run, the runs made in turn ``repeat`` times."""
    best = [(math.inf, np.zeros(0)) for _ in runs]
    for _ in range(repeat):
        for k, run in enumerate(runs):
            start = time.perf_counter()
            state = run()
            best[k] = min(best[k], (time.perf_counter() - start, state), key=lambda pair: pair[0])
    return best


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--write-doc", action="store_true", help=f"write the table into {DOC}")
    args = parser.parse_args(argv)
    scene = car_axis_scene()
    daeclear_state(scene, RTOLS[0])  # builds (or loads) the compiled library: not timed
    lines = ["| rtol = atol | digits: daeclear IDA (GGL, the mechanism) | scipy Radau | scipy DOP853 | "
             "time: Radau / daeclear | DOP853 / daeclear |", "|---|---:|---:|---:|---:|---:|"]
    for rtol in RTOLS:
        runs = [lambda rtol=rtol: daeclear_state(scene, rtol)]
        runs += [lambda m=m, rtol=rtol: scipy_state(m, rtol) for m in ("Radau", "DOP853")]
        (t_dc, s_dc), (t_radau, s_radau), (t_dop, s_dop) = timed(runs, args.repeat)
        lines.append(f"| {rtol:.0e} | {digits(s_dc):.1f} | {digits(s_radau):.1f} | {digits(s_dop):.1f} | "
                     f"{t_radau / t_dc:.0f} | {t_dop / t_dc:.1f} |")
        print(lines[-1], flush=True)
    if args.write_doc:
        command = "python benchmarks/external/car_axis.py" + (f" --repeat {args.repeat}" if args.repeat != 3 else "")
        print(f"wrote {write_block(DOC, BLOCK, command, lines)}")


if __name__ == "__main__":
    main()
