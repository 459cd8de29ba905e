"""Andrews' squeezing mechanism built from its drawing: seven bodies, a spring and a drive torque,
given in relative angles, against the published reference solution.

The mechanism (Giles 1978; Manning 1981; Schiehlen's benchmark, in Hairer and Wanner, *Solving
Ordinary Differential Equations II*, section VII.7, and the IVP Test Set's problem "andrews"):
body 1 turns about the fixed point O under the drive torque ``mom``; body 2 hangs from its end F;
bodies 3 (pivot B), 4-5 (pivot A) and 6-7 (pivot A) close three loops at the point E of body 2; a
spring of stiffness ``c0`` and free length ``l0`` pulls body 3's point D towards the fixed point
C. No gravity. Every length and point is the drawing's, in each body's frame: joint points and the
spring's end are body-fixed (``point_i``/``point_j``), and the start is the drawing's relative
angles (``dc.place(scene, start=...)``: beta of joint O alone fixes the 1-degree-of-freedom
mechanism; the bodies are declared only roughly, every centre at the origin).

The published coordinates are joint angles (beta, Theta, gamma, Phi, delta, Omega, epsilon):
here the channels ``O.angle``, ``F.angle``, ``B.angle``, ``G.angle``, ``A5.angle``, ``H.angle``,
``A7.angle``. The script prints them at t = 0.03 s against the test set's reference (PSIDE at
rtol = atol = 1e-14) and the digits reached, and draws them over time.

Run: ``python examples/andrews_squeezer.py [FIGURE.png]`` (default ``results/andrews_squeezer.png``);
``--quick`` for a short smoke run (t = 3 ms, no comparison).

Measured: the largest error at each rtol and formulation is the table of docs/validation.md ("Andrews'
squeezing mechanism"), written by ``python benchmarks/bench_andrews.py --write-doc``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402

# the drawing's numbers (Hairer and Wanner II, VII.7; SI units)
m1, m2, m3, m4, m5, m6, m7 = 0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498
i1, i2, i3, i4, i5, i6, i7 = 2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5
xa, ya, xb, yb, xc, yc = -0.06934, -0.00227, -0.03635, 0.03273, 0.014, 0.072
d, da, e, ea, rr, ra = 0.028, 0.0115, 0.02, 0.01421, 0.007, 0.00092
ss, sa, sb, sc, sd = 0.035, 0.01874, 0.01043, 0.018, 0.02
ta, tb, u, ua, ub, zf, zt, fa = 0.02308, 0.00916, 0.04, 0.01228, 0.00449, 0.02, 0.04, 0.01421
c0, l0, mom = 4530.0, 0.07785, 0.033

BETA0 = -0.0617138900142764496358948458001  # the test set's initial crank angle, rad (at rest)
# the test set's coordinates at t = 0.03 s: beta, Theta, gamma, Phi, delta, Omega, epsilon
REFERENCE = (15.81077119629904, -15.75637105984298, 0.04082224013073101, -0.5347301163226948,
             0.5244099658805304, 0.5347301163226948, 1.048080741042263)
COORDINATES = ("O", "F", "B", "G", "A5", "H", "A7")  # the joints whose angles they are
T_END, QUICK_T_END, RTOL = 0.03, 0.003, 1e-10


def andrews_squeezer() -> dc.Scene:
    """The mechanism from its drawing: each body's frame along its drawn link, its centre of mass
    where the drawing puts it (bodies 3, 5, 7 turn about fixed pivots: only their centres'
    distances from them enter the motion); declared roughly, at the origin."""
    s = dc.Scene("andrews", gravity=(0.0, 0.0))
    rough = dict(zip(range(1, 8), (-0.06, 0.0, 0.46, 0.22 + 0.49, 0.49, -0.22 + 1.23, 1.23)))  # body angles
    b = {k: s.add(dc.Body(f"body{k}", mass=m, inertia=i, angle=rough[k]))
         for k, m, i in zip(range(1, 8), (m1, m2, m3, m4, m5, m6, m7), (i1, i2, i3, i4, i5, i6, i7))}
    c3, c5, c7 = (sa, sb), (ta, tb), (ua, ub)  # centres of mass from the pivots B, A, A

    def pin(name: str, bi: object, bj: object, pi: tuple[float, float], pj: tuple[float, float]) -> None:
        s.add(dc.Revolute(name, bi, bj, point_i=pi, point_j=pj))

    pin("O", s.ground, b[1], (0.0, 0.0), (-ra, 0.0))  # beta
    pin("F", b[1], b[2], (rr - ra, 0.0), (da, 0.0))  # Theta
    pin("B", s.ground, b[3], (xb, yb), (-c3[0], -c3[1]))  # gamma
    pin("A5", s.ground, b[5], (xa, ya), (-c5[0], -c5[1]))  # delta
    pin("G", b[5], b[4], (zt - c5[0], -c5[1]), (0.0, e - ea))  # Phi
    pin("A7", s.ground, b[7], (xa, ya), (-c7[0], -c7[1]))  # epsilon
    pin("H", b[7], b[6], (-c7[0], -u - c7[1]), (fa - zf, 0.0))  # Omega
    for k, at_e in ((3, (-c3[0], -ss - c3[1])), (4, (0.0, -ea)), (6, (fa, 0.0))):  # the loops close at E
        pin(f"E{k}", b[2], b[k], (da - d, 0.0), at_e)
    s.add(dc.SpringDamper("spring", s.ground, b[3], point_i=(xc, yc), point_j=(sd - c3[0], -sc - c3[1]),
                          stiffness=c0, free_length=l0))
    s.add(dc.Torque("drive", b[1], mom))
    return dc.place(s, start={"O": BETA0})


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("figure", nargs="?", default="results/andrews_squeezer.png")
    parser.add_argument("--quick", action="store_true", help="a 3 ms smoke run, no comparison")
    args = parser.parse_args(argv)
    scene = andrews_squeezer()
    t_end = QUICK_T_END if args.quick else T_END
    result = dc.simulate(scene, t_end, rtol=RTOL, save=dc.SaveAt(times=np.linspace(0.0, t_end, 301)))
    print(result)
    if not args.quick:
        print(f"{'joint':>6} {'daeclear':>22} {'reference':>22} {'error':>9} {'digits':>6}")
        for joint, ref in zip(COORDINATES, REFERENCE):
            value = float(result[f"{joint}.angle"][-1])
            error = abs(value - ref)
            digits = -math.log10(max(error / max(abs(ref), 1.0), 1e-17))
            print(f"{joint:>6} {value:22.15g} {ref:22.15g} {error:9.2e} {digits:6.1f}")
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    for joint in COORDINATES:
        ax.plot(result.t * 1e3, result[f"{joint}.angle"], label=joint)
    ax.set(xlabel="t (ms)", ylabel="joint angle (rad)", title="Andrews' squeezing mechanism: joint angles")
    ax.legend(ncol=4, fontsize=8)
    path = Path(args.figure)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
