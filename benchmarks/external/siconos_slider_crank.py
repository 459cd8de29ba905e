"""The translational-clearance slider-crank of Flores, Leine and Glocker (2010) built with daeclear's
public API, against the trajectories that ship with Siconos as regression files, and against scipy on
the problem's own (minimal-coordinate) formulation of the same compliant model.

The problem (P. Flores, R. Leine, C. Glocker, "Modeling and analysis of planar rigid multibody
systems with translational clearance joints based on the non-smooth dynamics approach", Multibody
Syst. Dyn. 23 (2010) 165-190, Table 1, as Siconos' example examples/Mechanics/SliderCrank gives it):
a crank (l1 = 0.153 m, m1 = 0.038 kg, J1 = 7.4e-5 kg m^2 about its centre) turning freely about the
origin, a connecting rod (l2 = 0.306 m, m2 = 0.038 kg, J2 = 5.9e-4 kg m^2), and a slider
(m3 = 0.076 kg, J3 = 2.7e-6 kg m^2) pinned at its centre to the rod's end, a rectangle 2a x 2b =
0.10 x 0.05 m in a guide 2 (b + c) high (clearance c = 1 mm each side); gravity 9.81 m/s^2 along -Y.
No drive: at t = 0 the crank and rod lie along +X, the crank turns at 150 rad/s and the rod at
-75 rad/s (the slider at rest). Each of the slider's four corners may hit the guide wall on its side:
Newton's impact law with e_N = 0.4 and Coulomb friction mu = 0.01. Siconos integrates it in the three
angles (crank, rod, slider) with Moreau-Jean time stepping (theta = 0.5, h = 1e-4 s, rigid unilateral
contacts, impulses at impacts) with two position projections, to t = 0.2 s: the regression files
``SliderCrankMoreauJeanCombinedProjectionOSI.ref`` (35 columns) and
``SliderCrankMoreauJeanDirectProjectionOSI.ref`` (32 columns), each a line "rows columns" then one row
per step: t, crank angle / 2 pi, rod angle, slider angle, their three rates, four normalised corner
heights, (x_slider - l2) / l1, y_slider / c, then gaps, gap rates, impulses and solver counters (not
used here).

daeclear builds it as a user would: three ``Body``s, ``Revolute`` joints A (ground-crank), B, C
(rod-slider at the slider's centre), a ``TranslationalClearance`` "guide" (ground, slider; ``corners``
model: each corner a contact on its wall), the start ``dc.place(scene, start={"A": 0}, speeds={"A":
150})``. Its contact is compliant: the ``Flores`` law F_N = K d^1.5 [1 + 8 (1 - c_e)/(5 c_e) d'/d'(-)]
with c_e chosen so that one impact of a mass on the law leaves at 0.4 of its entry speed (the law's
restitution depends on c_e alone), K = 1e11 N/m^1.5 (``--stiffness``), modified Coulomb friction
mu = 0.01 (zero below 1e-4 m/s of slip, full from 2e-4).

scipy integrates the same compliant model in the problem's own coordinates (the three angles: the
mass matrix and forces of the Lagrangian written out below, corner heights and their Jacobians) with
DOP853, Radau and BDF and event location on the four corner gaps (the approach speed latched at each
onset), to ``--scipy-until`` (50 ms), where daeclear is timed alongside.

Impacts make the motion sensitive (the two Siconos schemes part after the first impact), so the
comparison is over windows from t = 0 that grow to the whole run; digits are -log10 of the largest
difference over the window divided by the reference's largest magnitude there, per quantity.

Run: ``python benchmarks/external/siconos_slider_crank.py --download`` (fetches the two files at the
pinned commit into ~/.cache/daeclear-external) or ``--reference FILE.ref`` (repeatable), ``--quick``
(to 20 ms, 16 s). Prints Markdown tables (docs/validation.md, "External references") and writes
``--figure`` (default docs/figures/siconos_slider_crank.png).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import urllib.request
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import daeclear as dc
import daeclear.contact as dcc

# Table 1 of Flores, Leine and Glocker (2010), as Siconos' example gives it
L1, L2, A, B, C = 0.153, 0.306, 0.05, 0.025, 0.001  # m: crank, rod, slider half length / half width, clearance
M1, M2, M3 = 0.038, 0.038, 0.076  # kg
J1, J2, J3 = 7.4e-5, 5.9e-4, 2.7e-6  # kg m^2 about the centres of mass
GRAVITY = 9.81
RESTITUTION, FRICTION = 0.4, 0.01  # Newton e_N and Coulomb mu of every corner
CRANK_RATE, ROD_RATE = 150.0, -75.0  # rad/s at t = 0 (crank and rod along +X)
T_END, STEP = 0.2, 1e-4  # Siconos' run and time step, s
STIFFNESS = 1e11  # N/m^1.5, daeclear's (compliant) corner law
V0, V1 = 1e-4, 2e-4  # m/s, modified Coulomb thresholds (daeclear's defaults)
MIN_APPROACH = 1e-4  # m/s, floor of the approach speed (daeclear's default)
AT_WALL = 1e-12  # m: a corner this close to its wall at another corner's crossing crosses with it

SICONOS_COMMIT = "00664d315f875027ed30c83a2e5df1f20aa5e391"  # the last commit with examples/ (2018-10-04)
SICONOS_DIR = "examples/Mechanics/SliderCrank"
REFERENCES = {"Combined": "SliderCrankMoreauJeanCombinedProjectionOSI.ref",
              "Direct": "SliderCrankMoreauJeanDirectProjectionOSI.ref"}
URL = "https://raw.githubusercontent.com/siconos/siconos/{commit}/{dir}/{file}"
CACHE = Path.home() / ".cache" / "daeclear-external"
#: Compared quantities: (channel, label, unit)
QUANTITIES = (("crank.angle", "crank angle", "rad"), ("rod.angle", "rod angle", "rad"),
              ("crank.rate", "crank rate", "rad/s"), ("rod.rate", "rod rate", "rad/s"),
              ("slider.x", "slider x", "m"), ("slider.vx", "slider vx", "m/s"), ("slider.y", "slider y", "m"))
WINDOWS = (0.01, 0.02, 0.05, 0.1, 0.2)  # s, ends of the compared windows (and the first impact)

Channels = dict[str, np.ndarray]


def read_reference(path: Path) -> Channels:
    """A Siconos .ref file as channels: the header line "rows columns" (optional), then rows of
    t, crank angle / (2 pi), rod angle, slider angle, their rates, 4 corner heights, (x - l2)/l1, y/c,
    ...; 32 or 35 columns (the Direct or Combined projection example)."""
    with open(path) as stream:
        first = stream.readline().split()
    data = np.loadtxt(path, skiprows=1 if len(first) == 2 else 0, ndmin=2)
    if len(first) == 2 and data.shape != (int(first[0]), int(first[1])):
        raise ValueError(f"{path}: header says {first[0]} x {first[1]}, the file holds {data.shape[0]} x "
                         f"{data.shape[1]}.")
    if data.shape[1] not in (32, 35):
        raise ValueError(f"{path}: columns={data.shape[1]}, must be 32 or 35 (a Siconos SliderCrank .ref file).")
    crank, rod = 2.0 * math.pi * data[:, 1], data[:, 2]
    return {"t": data[:, 0], "crank.angle": crank, "rod.angle": rod, "slider.angle": data[:, 3],
            "crank.rate": data[:, 4], "rod.rate": data[:, 5], "slider.rate": data[:, 6],
            "slider.x": L2 + L1 * data[:, 11], "slider.y": C * data[:, 12],
            "slider.vx": -L1 * np.sin(crank) * data[:, 4] - L2 * np.sin(rod) * data[:, 5]}


def output_grid(t_end: float) -> np.ndarray:
    """Siconos' output times k h up to ``t_end`` (the last one clipped to it)."""
    return np.minimum(np.arange(int(round(t_end / STEP)) + 1) * STEP, t_end)


def download_reference(name: str, cache: Path = CACHE) -> Path:
    """The .ref file ``REFERENCES[name]`` at the pinned commit, downloaded into ``cache`` once."""
    target = cache / SICONOS_COMMIT[:12] / REFERENCES[name]
    if not target.exists():
        url = URL.format(commit=SICONOS_COMMIT, dir=SICONOS_DIR, file=REFERENCES[name])
        print(f"downloading {url} ...", flush=True)
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = target.with_suffix(".part")
        with urllib.request.urlopen(url, timeout=60) as response, open(partial, "wb") as out:
            out.write(response.read())
        partial.replace(target)
    return target


def first_contact(ref: Channels) -> float:
    """The first sample at which the slider's centre reaches a wall height +-c (a face in contact)."""
    hit = np.flatnonzero(np.abs(ref["slider.y"]) >= C * (1.0 - 1e-9))
    return float(ref["t"][hit[0]]) if hit.size else float(ref["t"][-1])


def calibrated_restitution(target: float = RESTITUTION) -> float:
    """The Flores law's c_e whose single impact (a mass on the law) leaves at ``target`` times its
    entry speed; for n = 1.5 that ratio depends on c_e only (docs/contact_laws.md)."""
    def ratio(ce: float) -> float:
        law = dcc.Flores(restitution=ce, stiffness=1e10)
        return dcc.simulate_impact(law, mass=0.1, speed=1.0).restitution - target
    return float(brentq(ratio, 0.2, 0.99, xtol=1e-12))


def siconos_scene(stiffness: float = STIFFNESS, restitution: float | None = None,
                  friction: float = FRICTION) -> dc.Scene:
    """The mechanism with daeclear's public API: c_e ``restitution`` (None: calibrated to e_N = 0.4)."""
    ce = calibrated_restitution() if restitution is None else restitution
    s = dc.Scene("flores_leine_glocker", gravity=(0.0, -GRAVITY))
    crank = s.add(dc.Body("crank", mass=M1, inertia=J1, position=(L1 / 2, 0.0)))
    rod = s.add(dc.Body("rod", mass=M2, inertia=J2, position=(L1 + L2 / 2, 0.0)))
    slider = s.add(dc.Body("slider", mass=M3, inertia=J3, position=(L1 + L2, 0.0)))
    s.add(dc.Revolute("A", s.ground, crank, point_i=(0.0, 0.0), point_j=(-L1 / 2, 0.0)))
    s.add(dc.Revolute("B", crank, rod, point_i=(L1 / 2, 0.0), point_j=(-L2 / 2, 0.0)))
    s.add(dc.Revolute("C", rod, slider, point_i=(L2 / 2, 0.0), point_j=(0.0, 0.0)))
    s.add(dc.TranslationalClearance(
        "guide", s.ground, slider, point_i=(L1 + L2, 0.0), point_j=(0.0, 0.0), axis=(1.0, 0.0),
        length=2 * A, width=2 * B, clearance=C, corner_radius=1e-3, model="corners",
        law=dcc.Flores(restitution=ce, stiffness=stiffness), friction=friction or None))
    return dc.place(s, start={"A": 0.0}, speeds={"A": CRANK_RATE})


def daeclear_run(scene: dc.Scene, t_end: float, rtol: float) -> tuple[Channels, float, int]:
    """``simulate`` on Siconos' output grid: channels (with ``penetration``, the deepest corner's),
    wall time (assembly included, the compiled library cached before) and the number of corner onsets."""
    grid = output_grid(t_end)
    began = time.perf_counter()
    result = dc.simulate(scene, t_end, rtol=rtol, save=dc.SaveAt(times=grid))
    wall = time.perf_counter() - began
    channels = {"t": result.t, "crank.angle": result["A.angle"], "rod.angle": result["rod.phi"],
                "slider.angle": result["slider.phi"], "crank.rate": result["A.rate"],
                "rod.rate": result["rod.omega"], "slider.rate": result["slider.omega"],
                "slider.x": result["slider.x"], "slider.y": result["slider.y"], "slider.vx": result["slider.vx"],
                "penetration": np.max([result[f"guide.{pair}.penetration"] for pair in PAIRS], axis=0)}
    onsets = sum(len(result.events.of(f"guide.{pair}", "onset")) for pair in PAIRS)
    return channels, wall, onsets


# --- the problem's own formulation: minimal coordinates q = (crank, rod, slider angle) -----------------
M11 = J1 + (M1 / 4 + M2 + M3) * L1**2
M22 = J2 + (M2 / 4 + M3) * L2**2
M12 = (M2 / 2 + M3) * L1 * L2  # times cos(q1 - q2)
G1, G2 = (M1 / 2 + M2 + M3) * GRAVITY * L1, (M2 / 2 + M3) * GRAVITY * L2  # times cos(q1), cos(q2)
#: Corners in slider coordinates and their wall (+1 upper, -1 lower): daeclear's A, B, C, D
CORNERS = ((A, B, 1.0), (-A, B, 1.0), (-A, -B, -1.0), (A, -B, -1.0))
PAIRS = ("A_upper", "B_upper", "C_lower", "D_lower")


def corner_jacobians(q: np.ndarray, corner: tuple[float, float, float]) -> tuple[float, np.ndarray, np.ndarray]:
    """Penetration d of a corner into its wall (> 0 in contact) and the Jacobians of the corner's
    x and y with respect to q."""
    u, w, side = corner
    s1, c1, s2, c2 = math.sin(q[0]), math.cos(q[0]), math.sin(q[1]), math.cos(q[1])
    s3, c3 = math.sin(q[2]), math.cos(q[2])
    y = L1 * s1 + L2 * s2 + u * s3 + w * c3
    jx = np.array([-L1 * s1, -L2 * s2, -u * s3 - w * c3])
    jy = np.array([L1 * c1, L2 * c2, u * c3 - w * s3])
    return side * y - (B + C), jx, jy


def flores_force(d: float, rate: float, approach: float, stiffness: float, ce: float) -> float:
    """Flores et al. (2011): K d^1.5 [1 + 8(1 - c_e)/(5 c_e) rate/approach], >= 0, 0 for d <= 0."""
    if d <= 0.0:
        return 0.0
    factor = 1.0 + 1.6 * (1.0 - ce) / ce * rate / max(approach, MIN_APPROACH)
    return max(stiffness * d**1.5 * factor, 0.0)


def coulomb_factor(slip: float, mu: float) -> float:
    """Modified Coulomb (3.16): mu c_d(|slip|) sign(slip), c_d 0 below V0, 1 above V1, linear between."""
    ramp = min(max((abs(slip) - V0) / (V1 - V0), 0.0), 1.0)
    return math.copysign(mu * ramp, slip)


def minimal_rhs(z: np.ndarray, approach: list[float | None], stiffness: float, ce: float,
                mu: float) -> np.ndarray:
    """dz/dt of z = (q, q') for the Lagrangian of the three angles with the compliant corners (NaN for a
    trial state that is not finite: an explicit step deep into a wall, which the step control rejects)."""
    if not np.all(np.abs(z) < 1e100):
        return np.full(6, np.nan)
    q, v = z[:3], z[3:]
    gen = np.zeros(3)
    for k, corner in enumerate(CORNERS):
        d, jx, jy = corner_jacobians(q, corner)
        if d > 0.0:
            side = corner[2]
            fn = flores_force(d, side * float(jy @ v), approach[k] or 0.0, stiffness, ce)
            gen += -side * fn * jy - coulomb_factor(float(jx @ v), mu) * fn * jx  # normal: into the guide
    s, c = math.sin(q[0] - q[1]), math.cos(q[0] - q[1])
    f1 = -M12 * s * v[1] ** 2 - G1 * math.cos(q[0]) + gen[0]
    f2 = M12 * s * v[0] ** 2 - G2 * math.cos(q[1]) + gen[1]
    det = M11 * M22 - (M12 * c) ** 2
    return np.array([v[0], v[1], v[2], (M22 * f1 - M12 * c * f2) / det, (M11 * f2 - M12 * c * f1) / det, gen[2] / J3])


def switch_contacts(z: np.ndarray, approach: list[float | None], fired: int) -> int:
    """At a located gap crossing of corner ``fired``: that corner, and any other at its wall within
    AT_WALL moving the same way (two corners of a face reach it together when the slider is level),
    starts (latching its approach speed) or ends its contact; returns the number of onsets."""
    onsets = 0
    for k, corner in enumerate(CORNERS):
        d, _, jy = corner_jacobians(z[:3], corner)
        rate = corner[2] * float(jy @ z[3:])
        if approach[k] is None and (k == fired or (d > -AT_WALL and rate > 0.0)):
            approach[k] = rate
            onsets += 1
        elif approach[k] is not None and (k == fired or (d < AT_WALL and rate < 0.0)):
            approach[k] = None
    return onsets


def scipy_run(method: str, t_end: float, rtol: float, stiffness: float = STIFFNESS, ce: float | None = None,
              mu: float = FRICTION) -> tuple[Channels, float, int]:
    """scipy ``method`` on the minimal formulation, segment by segment between corner onsets and
    separations (located as events; the approach speed latched at the onset): channels on Siconos'
    grid, wall time, onsets."""
    ce = calibrated_restitution() if ce is None else ce
    grid = output_grid(t_end)
    approach: list[float | None] = [None] * 4
    atol = rtol * np.array([1e-3, 1e-3, 1e-4, 1.0, 1.0, 1.0])
    t, z = 0.0, np.array([0.0, 0.0, 0.0, CRANK_RATE, ROD_RATE, 0.0])
    times, states, onsets = [0.0], [z], 0
    began = time.perf_counter()
    while t < t_end:
        events = []
        for k, corner in enumerate(CORNERS):
            def gap(_t: float, y: np.ndarray, corner: tuple[float, float, float] = corner) -> float:
                return corner_jacobians(y[:3], corner)[0]
            gap.terminal, gap.direction = True, (-1.0 if approach[k] is not None else 1.0)  # type: ignore[attr-defined]
            events.append(gap)
        ahead = grid[(grid > t) & (grid <= t_end)]
        sol = solve_ivp(lambda _t, y: minimal_rhs(y, approach, stiffness, ce, mu), (t, t_end), z, method=method,
                        rtol=rtol, atol=atol, t_eval=ahead, events=events)
        if sol.status == -1:
            raise RuntimeError(f"scipy {method} at rtol {rtol}: {sol.message}")
        times.extend(sol.t)
        states.extend(np.asarray(sol.y).reshape(6, -1).T)
        if sol.status != 1:
            break
        k = next(i for i, te in enumerate(sol.t_events) if te.size)
        t, z = float(sol.t_events[k][0]), sol.y_events[k][0]
        onsets += switch_contacts(z, approach, fired=k)
    wall = time.perf_counter() - began
    tt, y = np.array(times), np.array(states)
    keep = np.isin(tt, grid)
    tt, y = tt[keep], y[keep]
    q1, q2, w1, w2 = y[:, 0], y[:, 1], y[:, 3], y[:, 4]
    deepest = np.max([[corner_jacobians(state[:3], corner)[0] for corner in CORNERS] for state in y], axis=1)
    channels = {"penetration": deepest, "t": tt, "crank.angle": q1, "rod.angle": q2, "slider.angle": y[:, 2],
                "crank.rate": w1, "rod.rate": w2, "slider.rate": y[:, 5], "slider.x": L1 * np.cos(q1) + L2 * np.cos(q2),
                "slider.y": L1 * np.sin(q1) + L2 * np.sin(q2),
                "slider.vx": -L1 * np.sin(q1) * w1 - L2 * np.sin(q2) * w2}
    return channels, wall, onsets


def digits(run: Channels, ref: Channels, until: float) -> dict[str, float]:
    """Per quantity: -log10(max |run - ref| / max |ref|) over the samples with t <= until (common
    times of the two)."""
    t = np.intersect1d(np.round(run["t"], 10), np.round(ref["t"], 10))
    t = t[t <= until + 1e-12]
    ia = np.searchsorted(np.round(run["t"], 10), t)
    ib = np.searchsorted(np.round(ref["t"], 10), t)
    out = {}
    for name, _, _ in QUANTITIES:
        error = np.max(np.abs(run[name][ia] - ref[name][ib]))
        scale = np.max(np.abs(ref[name][ib]))
        out[name] = -math.log10(max(error / scale, 1e-17)) if scale > 0.0 else float("nan")
    return out


def mechanical_energy(run: Channels) -> np.ndarray:
    """Kinetic plus potential energy of the three-angle model, J (zero height at y = 0); a compliant run's
    contact energy is not in it. Newton's law with e_N <= 1 and friction can only lower it."""
    q1, q2, w1, w2 = run["crank.angle"], run["rod.angle"], run["crank.rate"], run["rod.rate"]
    kinetic = (0.5 * M11 * w1**2 + 0.5 * M22 * w2**2 + M12 * np.cos(q1 - q2) * w1 * w2
               + 0.5 * J3 * run["slider.rate"] ** 2)
    return kinetic + G1 * np.sin(q1) + G2 * np.sin(q2)


def table(rows: list[tuple[str, Channels, Channels]], windows: list[float]) -> list[str]:
    """Markdown: one line per compared pair and window end."""
    lines = ["| compared | window (ms) | " + " | ".join(label for _, label, _ in QUANTITIES) + " |",
             "|---|---|" + "---|" * len(QUANTITIES)]
    for label, run, ref in rows:
        for until in windows:
            if until > min(run["t"][-1], ref["t"][-1]) + 1e-12:
                continue  # past one of the two runs
            got = digits(run, ref, until)
            cells = " | ".join(f"{got[n]:.1f}" for n, _, _ in QUANTITIES)
            lines.append(f"| {label} | 0 to {until * 1e3:.1f} | {cells} |")
    return lines


def figure(path: Path, refs: dict[str, Channels], runs: dict[str, Channels], window: float) -> None:
    """Crank rate, slider height, mechanical energy and the slider's angle against t, all runs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10.0, 6.4))
    panels = (("crank.rate", "crank rate (rad/s)", 1.0), ("slider.y", "slider y / c", 1.0 / C),
              ("energy", "mechanical energy (J)", 1.0), ("slider.angle", "slider angle (mrad)", 1e3))

    def values(run: Channels, name: str) -> np.ndarray:
        return mechanical_energy(run) if name == "energy" else run[name]

    styles = {"Combined": "k-", "Direct": "C2:"}
    for ax, (name, label, scale), tag in zip(axes.flat, panels, "abcd"):
        for key, ref in refs.items():
            ax.plot(ref["t"] * 1e3, values(ref, name) * scale, styles.get(key, "k-"), lw=1.0, label=f"Siconos {key}")
        for (key, run), style in zip(runs.items(), ("C0--", "C3-.")):
            ax.plot(run["t"] * 1e3, values(run, name) * scale, style, lw=0.9, label=key)
        ax.axvspan(0.0, window * 1e3, color="0.92", zorder=0)
        ax.set_xlabel("t (ms)")
        ax.set_ylabel(label)
        ax.set_title(f"({tag}) {label.split(' (')[0]}", fontsize=9)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Flores-Leine-Glocker slider-crank (c = 1 mm, e_N = 0.4, mu = 0.01): Siconos (rigid, h = 0.1 ms)\n"
                 "against daeclear and scipy (compliant); shaded: the window of the headline digits", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def timed(run: Callable[[], tuple[Channels, float, int]], repeat: int) -> tuple[Channels, float, int]:
    """The best wall time of ``repeat`` runs (channels and onsets of the last)."""
    best, out = math.inf, None
    for _ in range(repeat):
        out = run()
        best = min(best, out[1])
    assert out is not None
    return out[0], best, out[2]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, action="append", default=[],
                        help="a Siconos SliderCrank .ref file (repeatable)")
    parser.add_argument("--download", action="store_true",
                        help=f"download the two .ref files at Siconos commit {SICONOS_COMMIT[:12]} into --cache")
    parser.add_argument("--cache", type=Path, default=CACHE, help=f"download directory (default {CACHE})")
    parser.add_argument("--quick", action="store_true", help="to 20 ms only, one repeat (smoke run)")
    parser.add_argument("--t-end", type=float, default=T_END, help="end of the run, s (default 0.2, Siconos')")
    parser.add_argument("--rtol", type=float, default=1e-8, help="rtol of daeclear and scipy (default 1e-8)")
    parser.add_argument("--tight-rtol", type=float, default=1e-9,
                        help="daeclear's rtol for the compliant model's reference solution (default 1e-9)")
    parser.add_argument("--stiffness", type=float, default=STIFFNESS, help="K of the corner law, N/m^1.5")
    parser.add_argument("--window", type=float, default=0.02, help="headline window end, s (default 0.02)")
    parser.add_argument("--repeat", type=int, default=2, help="runs per method; the best wall time counts")
    parser.add_argument("--no-scipy", action="store_true", help="skip the scipy runs")
    parser.add_argument("--scipy-until", type=float, default=0.05,
                        help="end of the scipy runs (and of a daeclear run timed alongside), s (default 0.05)")
    parser.add_argument("--figure", type=Path, default=Path("docs/figures/siconos_slider_crank.png"))
    args = parser.parse_args(argv)
    refs: dict[str, Channels] = {}
    try:
        paths = list(args.reference) or ([download_reference(n, args.cache) for n in REFERENCES] if args.download
                                         else [])
    except OSError as error:
        print(f"downloading the Siconos reference failed ({error}): the comparison is skipped. Give the files "
              f"with --reference FILE.ref ({SICONOS_DIR} at Siconos commit {SICONOS_COMMIT}).")
        return 0
    if not paths:
        print(f"no reference: run with --download, or --reference FILE.ref ({SICONOS_DIR}/{REFERENCES['Combined']} "
              f"at Siconos commit {SICONOS_COMMIT}).")
        return 0
    for path in paths:
        key = next((k for k in REFERENCES if k in path.name), path.stem)
        refs[key] = read_reference(path)
    if args.quick:
        args.t_end, args.repeat, args.window = min(args.t_end, 0.02), 1, min(args.window, 0.01)
    ce = calibrated_restitution()
    first_ref = next(iter(refs.values()))
    impact = first_contact(first_ref)
    print(f"Flores-Leine-Glocker slider-crank to {args.t_end * 1e3:g} ms; Flores law c_e = {ce:.6f} (single-impact "
          f"restitution {RESTITUTION}), K = {args.stiffness:g} N/m^1.5, mu = {FRICTION}; rtol {args.rtol:g}\n")
    scene = siconos_scene(args.stiffness, ce)
    began = time.perf_counter()
    dc.simulate(scene, 1e-4, rtol=args.rtol)  # builds (or loads) the compiled library
    print(f"first simulate (compiles the model unless cached): {time.perf_counter() - began:.2f} s")
    plan: dict[str, tuple[float, Callable[[], tuple[Channels, float, int]], int]] = {
        "daeclear": (args.rtol, lambda: daeclear_run(scene, args.t_end, args.rtol), args.repeat),
        "daeclear tight": (args.tight_rtol, lambda: daeclear_run(scene, args.t_end, args.tight_rtol), args.repeat)}
    for factor in (0.1, 10.0):  # a new stiffness is a parameter: nothing compiles
        plan[f"daeclear K x {factor:g}"] = (args.rtol, lambda f=factor: daeclear_run(
            siconos_scene(args.stiffness * f, ce), args.t_end, args.rtol), 1)
    if not args.no_scipy:
        short = min(args.scipy_until, args.t_end)
        plan[f"daeclear to {short * 1e3:g} ms"] = (args.rtol, lambda: daeclear_run(scene, short, args.rtol),
                                                   args.repeat)
        for method in ("DOP853", "Radau", "BDF"):
            plan[f"scipy {method} to {short * 1e3:g} ms"] = (
                args.rtol, lambda m=method: scipy_run(m, short, args.rtol, args.stiffness, ce), 1)
    runs: dict[str, tuple[Channels, float, int]] = {}
    lines: list[str | tuple[str, float]] = []
    for label, (rtol, run, repeat) in plan.items():
        try:
            runs[label] = timed(run, repeat)
        except dc.SolveError as error:  # reported, left out of the comparisons
            lines.append(f"| {label} | {rtol:g} | failed: {str(error).splitlines()[0][:300]} | | | |")
            continue
        lines.append((label, rtol))
    if "daeclear" not in runs:
        print("\n".join(line for line in lines if isinstance(line, str)))
        return 1
    main_run = runs["daeclear"][0]
    free = min(impact, float(main_run["t"][np.argmax(main_run["penetration"] > 0.0)]))
    edge = int(round(free / STEP)) - 1  # the last sample before the first contact of Siconos or daeclear
    windows = sorted({round(edge * STEP, 6), *[w for w in WINDOWS if w < args.t_end], round(args.t_end, 6)})
    print(f"first contact: Siconos {impact * 1e3:.1f} ms, daeclear {free * 1e3:.2f} ms")
    print("\n| run | rtol | wall time (s) | corner onsets | deepest corner penetration (um) | mechanical energy (J) at "
          f"0, {edge * STEP * 1e3:.1f} ms, the end |\n|---|---|---|---|---|---|")
    end = int(round(args.t_end / STEP))
    for key, ref in refs.items():
        energy = mechanical_energy(ref)
        print(f"| Siconos {key} | h = {STEP:g} s | | | 0 (projected) | {energy[0]:.4f}, {energy[edge]:.4f}, "
              f"{energy[min(end, energy.size - 1)]:.4f} |")
    for line in lines:
        if isinstance(line, str):
            print(line)
            continue
        label, rtol = line
        channels, wall, onsets = runs[label]
        energy = mechanical_energy(channels)
        print(f"| {label} | {rtol:g} | {wall:.3g} | {onsets} | {np.max(channels['penetration']) * 1e6:.2f} | "
              f"{energy[0]:.4f}, {energy[edge]:.4f}, {energy[-1]:.4f} |")
    rows = [(f"daeclear vs Siconos {key}", main_run, ref) for key, ref in refs.items()]
    if len(refs) == 2:
        rows.append(("Siconos Direct vs Combined", refs["Direct"], refs["Combined"]))
    if "daeclear tight" in runs:  # the compliant model's solution, which daeclear and scipy approximate
        tight = runs["daeclear tight"][0]
        rows.append((f"daeclear vs daeclear rtol {args.tight_rtol:g}", main_run, tight))
        rows += [(f"{label.split(' to ')[0]} vs daeclear rtol {args.tight_rtol:g}", run, tight)
                 for label, (run, _, _) in runs.items() if label.startswith("scipy")]
    rows += [(f"{label} vs daeclear", run, main_run) for label, (run, _, _) in runs.items() if " K x " in label]
    print("\ndigits: -log10(largest difference over the window / the second's largest magnitude there)\n")
    print("\n".join(table(rows, windows)))
    print("\nlargest |slider angle| (rad): " + ", ".join(
        f"{k} {np.max(np.abs(r['slider.angle'])):.1e}" for k, r in {**{f'Siconos {k}': r for k, r in refs.items()},
                                                                 **{k: r[0] for k, r in runs.items()}}.items()))
    figure(args.figure, refs, {k: runs[k][0] for k in runs if k == "daeclear" or k.startswith("scipy DOP853")},
           args.window)
    print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
