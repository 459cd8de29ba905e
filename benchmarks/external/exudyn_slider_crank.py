"""The Fig. 4.15 slider-crank (revolute clearance joint, c = 0.5 mm) built independently in Exudyn,
side by side with daeclear's ``simulate``.

Exudyn (Gerstmayr, https://github.com/jgerstmayr/EXUDYN) is a C++ multibody code with a Python
interface; it is not a dependency of daeclear. ``--install`` installs it from PyPI into the
environment that runs this script (``pip install "exudyn>=1.13,<1.14"``; 1.13.6 measured) when it is
missing. Without it and without ``--install`` the script says so and exits with status 0.

The Exudyn model is written here from the chapter's numbers alone (Tables 4.1-4.2, section 4.4),
with no daeclear code in it:

* crank, rod, slider: ``ObjectRigidBody2D`` (Table 4.1), gravity 9.81 m/s^2 along -Y
  (``LoadMassProportional``), starting at crank angle 0 (crank and rod collinear) with the ideal
  mechanism's velocities (closed form below), journal and bearing centres coincident;
* pins A (ground-crank), B (crank-rod): ``ObjectJointRevolute2D``; the slider on the X axis:
  ``ObjectJointPrismatic2D`` (rotation locked); the crank at 5000 rpm: an ``ObjectConnectorCoordinate``
  on the crank angle with offset omega t, whose Lagrange multiplier is the crank moment;
* the clearance joint C (bearing on the slider, journal at the rod's end, bearing radius 10 mm,
  radial clearance c = 0.5 mm): an ``ObjectConnectorCartesianSpringDamper`` between the two
  centres whose Python ``springForceUserFunction`` is the Lankarani-Nikravesh law (3.9)
  F_N = K delta^1.5 [1 + 3 (1 - c_e^2)/4 delta_dot/delta_dot(-)], delta = |e| - c,
  K = 4/(3 (sigma_i + sigma_j)) sqrt(R_i R_j / (R_i - R_j)) (3.5), sigma = (1 - nu^2)/E, steel
  207 GPa, 0.3, c_e = 0.9. Exudyn locates no events: the approach speed delta_dot(-) is the rate at
  delta = 0 interpolated between the states before and after the crossing, latched by a pre-step
  function for the rest of the contact, floored at 1e-4 m/s.
  ``--friction c_f`` adds the modified Coulomb law (3.16) (v0 = 1e-4, v1 = 2e-4 m/s) on the slip
  at the contact point, its moments about both centres as ``LoadTorqueVector`` user functions.
* Exudyn's generalized-alpha integrator (index 3, spectral radius 0.9, its default) with a fixed
  step ``--step`` (0.5 us; the chapter's integration step is 10 us) and ``--step / 2`` to show Exudyn's
  own convergence (its error falls by 4 per halving of the step).

daeclear runs its ready-made scene ``slider_crank("revolute", clearance=0.5e-3, restitution=0.9)``
(IDA with event location, rtol 1e-10, and rtol 1e-9 for its own convergence). Contact runs are
chaotic: two codes, or one code at two tolerances, agree until a small difference in one impact
grows. So the comparison is over the early window where each code agrees with itself at two
resolutions, from t = 0 (no transient is discarded here, unlike the chapter's figures): the
onset times and peak forces of the first impacts, the relative L2 error of the slider velocity,
acceleration and crank moment, and the largest distance between the two journal orbits. The
ideal joint (C an ``ObjectJointRevolute2D``) is compared over the whole run: it checks the shared
mechanism, drive and moment sign before any contact.

Run: ``python benchmarks/external/exudyn_slider_crank.py`` (two revolutions, 24 ms; 30-40 s) or
``--quick`` (one quarter revolution at a 2 us step, a few seconds). Prints Markdown tables
(docs/validation.md, "External references") and writes ``--figure`` (default
docs/figures/exudyn_fig415.png).
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

EXUDYN = "exudyn>=1.13,<1.14"  # the versions measured (docs/validation.md)

try:
    import exudyn as exu
    from exudyn import itemInterface as items
except ImportError:  # an optional external package
    exu = None


def install_exudyn() -> bool:
    """Install Exudyn from PyPI into this interpreter's environment (pip) and import it; True when it imports."""
    global exu, items
    print(f"installing {EXUDYN} from PyPI ...", flush=True)
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", EXUDYN], check=False)
    try:
        import exudyn as exu
        from exudyn import itemInterface as items
    except ImportError:
        return False
    return True

# Table 4.1 (crank, rod: length, mass, moment of inertia; slider: mass, moment of inertia) and Table 4.2
CRANK_L, CRANK_M, CRANK_J = 0.05, 0.30, 1.0e-4
ROD_L, ROD_M, ROD_J = 0.12, 0.21, 2.5e-4
SLIDER_M, SLIDER_J = 0.14, 1.0e-4
GRAVITY = 9.81
OMEGA = 5000.0 * 2.0 * math.pi / 60.0  # rad/s
BEARING_R, CLEARANCE = 10.0e-3, 0.5e-3
JOURNAL_R = BEARING_R - CLEARANCE
YOUNG, POISSON, RESTITUTION = 207e9, 0.3, 0.9
SIGMA = (1.0 - POISSON**2) / YOUNG
STIFFNESS = 4.0 / (3.0 * 2.0 * SIGMA) * math.sqrt(BEARING_R * JOURNAL_R / (BEARING_R - JOURNAL_R))  # (3.5)
MIN_APPROACH = 1e-4  # m/s, floor of delta_dot(-)
V0, V1 = 1e-4, 2e-4  # m/s, modified Coulomb thresholds
PERIOD = 2.0 * math.pi / OMEGA
#: The coordinate constraint's force sensor gives the moment on its marker 0's side (the ground); the
#: moment applied to the crank is its negative (at crank angle 0 the drive holds the horizontal links
#: up against gravity, a positive moment; the ideal joint's moment then matches daeclear's to 2e-5).
SIGN_OF_MOMENT = -1.0


def normal_force(delta: float, rate: float, approach: float) -> float:
    """Lankarani-Nikravesh (3.9): K delta^1.5 [1 + 3(1 - c_e^2)/4 rate/approach], never pulling."""
    if delta <= 0.0:
        return 0.0
    damping = 0.75 * (1.0 - RESTITUTION**2) * rate / max(approach, MIN_APPROACH)
    return max(STIFFNESS * delta**1.5 * (1.0 + damping), 0.0)


def friction_factor(slip: float) -> float:
    """Modified Coulomb (3.16): c_d(|v_T|) sign(v_T), c_d 0 below v0, 1 above v1, linear between."""
    speed = abs(slip)
    ramp = 0.0 if speed <= V0 else min((speed - V0) / (V1 - V0), 1.0)
    return math.copysign(ramp, slip)


@dataclass
class Contact:
    """The journal-bearing contact from e = r_journal - r_bearing, its rate and both angular velocities.

    Exudyn locates no events: the approach speed delta_dot(-) is the rate at delta = 0 interpolated
    linearly between the state at the start of the step in which the contact begins (``start``) and the
    state at hand; a pre-step function latches it for the rest of the contact (``approach``)."""

    friction: float
    approach: float | None = None  # delta_dot(-), latched while in contact
    start: tuple[float, float] = (-1.0, 0.0)  # (delta, rate) at the start of the current step

    def onset_rate(self, delta: float, rate: float) -> float:
        """delta_dot at delta = 0 between ``start`` (delta <= 0) and (delta, rate) (delta > 0)."""
        before, rate_before = self.start
        if before > 0.0:  # in contact since an earlier step (only without a latch: the first call)
            return rate
        return rate_before + (rate - rate_before) * (-before) / (delta - before)

    def forces(self, e: Any, e_dot: Any, omega_journal: float,
               omega_bearing: float) -> tuple[float, float, float, float]:
        """(n_x, n_y, F_N, F_T): unit normal bearing -> journal, normal force, friction force along
        t = n rotated by +90 degrees acting on the journal (minus that on the bearing)."""
        ecc = math.hypot(e[0], e[1])
        if ecc <= CLEARANCE:
            return 1.0, 0.0, 0.0, 0.0
        nx, ny = e[0] / ecc, e[1] / ecc
        rate = nx * e_dot[0] + ny * e_dot[1]
        delta = ecc - CLEARANCE
        approach = self.onset_rate(delta, rate) if self.approach is None else self.approach
        fn = normal_force(delta, rate, approach)
        # slip of the journal's contact point over the bearing's, along t = (-ny, nx)
        slip = -ny * e_dot[0] + nx * e_dot[1] + JOURNAL_R * omega_journal - BEARING_R * omega_bearing
        return nx, ny, fn, -self.friction * friction_factor(slip) * fn

    def next_step(self, e: Any, e_dot: Any) -> None:
        """At a step's start: latch the approach speed when the contact began in the last step, drop it
        when the journal is free; remember this state as the step's start."""
        ecc = math.hypot(e[0], e[1])
        delta = ecc - CLEARANCE
        rate = (e[0] * e_dot[0] + e[1] * e_dot[1]) / max(ecc, 1e-300)
        if delta <= 0.0:
            self.approach = None
        elif self.approach is None:
            self.approach = self.onset_rate(delta, rate)
        self.start = (delta, rate)


def ideal_start() -> dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """Bodies' (x, y, phi) and velocities at crank angle 0 (crank and rod collinear along +X)."""
    rod_rate = -CRANK_L * OMEGA / ROD_L  # the rod turns back while the crank pin moves up
    pin_vy = CRANK_L * OMEGA
    return {"crank": ((CRANK_L / 2, 0.0, 0.0), (0.0, pin_vy / 2, OMEGA)),
            "rod": ((CRANK_L + ROD_L / 2, 0.0, 0.0), (0.0, pin_vy + ROD_L / 2 * rod_rate, rod_rate)),
            "slider": ((CRANK_L + ROD_L, 0.0, 0.0), (0.0, 0.0, 0.0))}


def exudyn_run(clearance: bool, t_end: float, step: float,
               friction: float = 0.0) -> tuple[dict[str, np.ndarray], float]:
    """Build and run the Exudyn model; channels on the step grid and the wall time of the solve."""
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    ground = mbs.AddObject(items.ObjectGround())
    ground_node = mbs.AddNode(items.NodePointGround())
    start = ideal_start()
    nodes, bodies = {}, {}
    for name, mass, inertia in (("crank", CRANK_M, CRANK_J), ("rod", ROD_M, ROD_J), ("slider", SLIDER_M, SLIDER_J)):
        pose, speed = start[name]
        nodes[name] = mbs.AddNode(items.NodeRigidBody2D(referenceCoordinates=list(pose), initialVelocities=list(speed)))
        bodies[name] = mbs.AddObject(items.ObjectRigidBody2D(mass=mass, inertia=inertia, nodeNumber=nodes[name]))
        mbs.AddLoad(items.LoadMassProportional(markerNumber=mbs.AddMarker(items.MarkerBodyMass(bodyNumber=bodies[name])),
                                               loadVector=[0.0, -GRAVITY, 0.0]))

    def point(body: str, x: float) -> int:
        return mbs.AddMarker(items.MarkerBodyPosition(bodyNumber=bodies[body] if body != "ground" else ground,
                                                      localPosition=[x, 0.0, 0.0]))

    mbs.AddObject(items.ObjectJointRevolute2D(markerNumbers=[point("ground", 0.0), point("crank", -CRANK_L / 2)]))
    mbs.AddObject(items.ObjectJointRevolute2D(markerNumbers=[point("crank", CRANK_L / 2), point("rod", -ROD_L / 2)]))
    slider_frame = mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=bodies["slider"]))
    mbs.AddObject(items.ObjectJointPrismatic2D(markerNumbers=[mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=ground)),
                                                              slider_frame],
                                               axisMarker0=[1.0, 0.0, 0.0], normalMarker1=[0.0, 1.0, 0.0]))
    bearing, journal = point("slider", 0.0), point("rod", ROD_L / 2)
    contact = Contact(friction)
    if clearance:
        def angular(name: str) -> float:
            return float(mbs.GetNodeOutput(nodes[name], exu.OutputVariableType.AngularVelocity)[2])

        def spring_force(mbs: Any, t: float, item: int, e: Any, e_dot: Any, *_: Any) -> list[float]:
            # Exudyn applies +f to marker 0 (bearing) and -f to marker 1 (journal); e = r_1 - r_0
            nx, ny, fn, ft = contact.forces(e, e_dot, angular("rod"), angular("slider"))
            return [fn * nx + ft * ny, fn * ny - ft * nx, 0.0]  # f = F_N n - F_T t

        joint_c = mbs.AddObject(items.ObjectConnectorCartesianSpringDamper(markerNumbers=[bearing, journal],
                                                                           springForceUserFunction=spring_force))

        def pre_step(mbs: Any, t: float) -> bool:
            contact.next_step(mbs.GetObjectOutput(joint_c, exu.OutputVariableType.Displacement),
                              mbs.GetObjectOutput(joint_c, exu.OutputVariableType.Velocity))
            return True

        mbs.SetPreStepUserFunction(pre_step)
        if friction > 0.0:  # the friction force acts at the contact point: its moments about both centres
            def moment(radius: float) -> Any:
                def load(mbs: Any, t: float, vector: Any) -> list[float]:
                    e = mbs.GetObjectOutput(joint_c, exu.OutputVariableType.Displacement)
                    e_dot = mbs.GetObjectOutput(joint_c, exu.OutputVariableType.Velocity)
                    return [0.0, 0.0, radius * contact.forces(e, e_dot, angular("rod"), angular("slider"))[3]]
                return load
            for name, radius in (("rod", JOURNAL_R), ("slider", -BEARING_R)):
                mbs.AddLoad(items.LoadTorqueVector(markerNumber=mbs.AddMarker(items.MarkerBodyRigid(bodyNumber=bodies[name])),
                                                   loadVectorUserFunction=moment(radius)))
    else:
        joint_c = mbs.AddObject(items.ObjectJointRevolute2D(markerNumbers=[bearing, journal]))
    angle = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=nodes["crank"], coordinate=2))
    drive = mbs.AddObject(items.ObjectConnectorCoordinate(
        markerNumbers=[mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0)), angle],
        offsetUserFunction=lambda mbs, t, item, offset: OMEGA * t,
        offsetUserFunction_t=lambda mbs, t, item, offset: OMEGA))
    out = exu.OutputVariableType

    def sensor(kind: Any, what: Any, **where: Any) -> int:
        return mbs.AddSensor(kind(outputVariableType=what, storeInternal=True, writeToFile=False, **where))

    sensors = {"slider.vx": sensor(items.SensorBody, out.Velocity, bodyNumber=bodies["slider"]),
               "slider.ax": sensor(items.SensorBody, out.Acceleration, bodyNumber=bodies["slider"]),
               "drive": sensor(items.SensorObject, out.Force, objectNumber=drive)}
    if clearance:
        sensors["e"] = sensor(items.SensorObject, out.Displacement, objectNumber=joint_c)
        sensors["f"] = sensor(items.SensorObject, out.Force, objectNumber=joint_c)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.endTime = t_end
    integration.numberOfSteps = int(round(t_end / step))
    integration.adaptiveStep = False
    integration.generalizedAlpha.spectralRadius = 0.9  # Exudyn's default, said here
    integration.verboseMode = 0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = step
    began = time.perf_counter()
    mbs.SolveDynamic(settings)
    wall = time.perf_counter() - began
    data = {name: mbs.GetSensorStoredData(number) for name, number in sensors.items()}
    result = {"t": data["slider.vx"][:, 0], "slider.vx": data["slider.vx"][:, 1], "slider.ax": data["slider.ax"][:, 1],
              "drive.moment": SIGN_OF_MOMENT * data["drive"][:, 1]}
    if clearance:
        result["ex"], result["ey"] = data["e"][:, 1], data["e"][:, 2]
        ecc = np.hypot(result["ex"], result["ey"])
        result["penetration"] = ecc - CLEARANCE
        safe = np.maximum(ecc, 1e-300)  # F_N = f . n (f = F_N n - F_T t)
        result["normal_force"] = (data["f"][:, 1] * result["ex"] + data["f"][:, 2] * result["ey"]) / safe
    return result, wall


def daeclear_run(clearance: bool, t_end: float, rtol: float, grid: np.ndarray,
                 friction: float = 0.0) -> tuple[dict[str, np.ndarray], float]:
    """daeclear's ready-made scene on ``grid``; channels and the wall time of ``simulate`` (compiled before)."""
    import daeclear as dc
    from daeclear.model.mechanisms import slider_crank

    scene = (slider_crank("revolute", clearance=CLEARANCE, restitution=RESTITUTION, gravity=GRAVITY,
                          friction=friction or None)
             if clearance else slider_crank("ideal", gravity=GRAVITY))
    dc.simulate(scene, 1e-4, rtol=rtol)  # builds (or loads) the compiled library: not timed
    began = time.perf_counter()
    result = dc.simulate(scene, t_end, rtol=rtol, save=dc.SaveAt(times=grid))
    wall = time.perf_counter() - began
    channels = {"t": result.t, "slider.vx": result["slider.vx"], "slider.ax": result["slider.ax"],
                "drive.moment": result["drive.moment"]}
    if clearance:
        channels.update({"ex": result["clearance.ex"], "ey": result["clearance.ey"],
                         "penetration": result["clearance.penetration"],
                         "normal_force": result["clearance.normal_force"],
                         "onsets": np.asarray(result.events.of("clearance", "onset").t)})
    return channels, wall


def onsets(run: dict[str, np.ndarray]) -> np.ndarray:
    """Contact onset times: daeclear's located events, or delta's upward zero crossings on the step grid
    (linear interpolation)."""
    if "onsets" in run:
        return run["onsets"]
    t, d = run["t"], run["penetration"]
    k = np.flatnonzero((d[:-1] <= 0.0) & (d[1:] > 0.0))
    return t[k] - d[k] * (t[k + 1] - t[k]) / (d[k + 1] - d[k])


def impact_peaks(run: dict[str, np.ndarray], times: np.ndarray) -> np.ndarray:
    """Largest normal force on the grid from each onset to the next."""
    t, f = run["t"], run["normal_force"]
    edges = np.append(times, t[-1] + 1.0)
    return np.array([f[(t >= a) & (t < b)].max(initial=0.0) for a, b in zip(edges[:-1], edges[1:])])


def orbit_distance(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> np.ndarray:
    """|e_a - e_b| / c on the common grid."""
    return np.hypot(a["ex"] - b["ex"], a["ey"] - b["ey"]) / CLEARANCE


def agree_until(a: dict[str, np.ndarray], b: dict[str, np.ndarray], tolerance: float) -> float:
    """First time the two journal orbits are more than ``tolerance`` c apart (the end if never)."""
    far = np.flatnonzero(orbit_distance(a, b) > tolerance)
    return float(a["t"][far[0]]) if far.size else float(a["t"][-1])


def relative_l2(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / np.linalg.norm(b))


def compare(exu_run: dict[str, np.ndarray], dc_run: dict[str, np.ndarray], until: float) -> dict[str, float]:
    """Relative L2 errors of Exudyn against daeclear over [0, until] and the largest orbit distance."""
    inside = exu_run["t"] <= until + 1e-12
    row = {name: relative_l2(exu_run[name][inside], dc_run[name][inside])
           for name in ("slider.vx", "slider.ax", "drive.moment")}
    if "ex" in exu_run:
        row["orbit"] = float(orbit_distance(exu_run, dc_run)[inside].max())
    return row


def figure(path: Path, exu_fine: dict[str, np.ndarray], dc_fine: dict[str, np.ndarray],
           exu_ideal: dict[str, np.ndarray], until: float) -> None:
    """(a) slider velocity, (b) crank moment, (c) penetration, over the run; (d) orbits over the window."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11.0, 7.5))
    ms = 1e3
    panels = (("slider.vx", "slider velocity (m/s)", 1.0), ("drive.moment", "crank moment (N m)", 1.0),
              ("penetration", "|e| - c (um)", 1e6))
    for ax, (name, label, scale), tag in zip(axes.flat, panels, "abc"):
        if name in exu_ideal:
            ax.plot(exu_ideal["t"] * ms, exu_ideal[name] * scale, "k:", lw=0.8, label="ideal joint (Exudyn)")
        ax.plot(dc_fine["t"] * ms, dc_fine[name] * scale, "C0", lw=1.0, label="daeclear (IDA)")
        ax.plot(exu_fine["t"] * ms, exu_fine[name] * scale, "C3--", lw=1.0, label="Exudyn (gen.-alpha)")
        ax.axvspan(0.0, until * ms, color="0.9", zorder=0)
        ax.set_xlabel("t (ms)")
        ax.set_ylabel(label)
        ax.set_title(f"({tag}) {label.split(' (')[0]}; shaded: both codes converged", fontsize=9)
    axes[0, 0].legend(fontsize=8)
    ax = axes[1, 1]
    circle = np.linspace(0.0, 2.0 * math.pi, 200)
    ax.plot(CLEARANCE * 1e6 * np.cos(circle), CLEARANCE * 1e6 * np.sin(circle), "k:", lw=0.8)
    for run, style, label in ((dc_fine, "C0", "daeclear"), (exu_fine, "C3--", "Exudyn")):
        inside = run["t"] <= until
        ax.plot(run["ex"][inside] * 1e6, run["ey"][inside] * 1e6, style, lw=0.8, label=label)
    ax.set_aspect("equal")
    ax.set_xlabel("e_x (um)")
    ax.set_ylabel("e_y (um)")
    ax.set_title(f"(d) journal centre in the bearing, 0 to {until * ms:.2f} ms", fontsize=9)
    ax.legend(fontsize=8)
    fig.suptitle("Fig. 4.15 scene (c = 0.5 mm, L-N c_e = 0.9, 5000 rpm): daeclear against Exudyn, from t = 0",
                 fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a quarter revolution at a 2 us step (smoke run)")
    parser.add_argument("--revolutions", type=float, default=2.0, help="crank revolutions from t = 0 (default 2)")
    parser.add_argument("--step", type=float, default=5e-7, help="Exudyn's fixed step, s (default 5e-7)")
    parser.add_argument("--rtol", type=float, default=1e-10, help="daeclear's rtol (default 1e-10)")
    parser.add_argument("--agree", type=float, default=0.02,
                        help="orbit distance (fraction of c) that ends a converged window (default 0.02)")
    parser.add_argument("--friction", type=float, default=0.0, help="c_f of (3.16) in both codes (default 0)")
    parser.add_argument("--figure", type=Path, default=Path("docs/figures/exudyn_fig415.png"))
    parser.add_argument("--install", action="store_true", help=f"install {EXUDYN} from PyPI (pip) when it is missing")
    args = parser.parse_args(argv)
    if exu is None and args.install and not install_exudyn():
        print(f"installing {EXUDYN} failed (no network, or no wheel for this platform): the comparison is skipped.")
        return 0
    if exu is None:
        print(f"exudyn is not installed: this comparison is skipped. Run with --install, or pip install "
              f"\"{EXUDYN}\", and run again.")
        return 0
    if args.quick:
        args.revolutions, args.step = 0.25, 2e-6
    t_end = args.revolutions * PERIOD
    grid = np.linspace(0.0, t_end, int(round(t_end / args.step)) + 1)
    print(f"Fig. 4.15 scene, {args.revolutions:g} revolutions ({t_end * 1e3:.1f} ms) from t = 0; Exudyn "
          f"{exu.__version__}, step {args.step:g} s and {args.step / 2:g} s; daeclear rtol {args.rtol:g} and "
          f"{10 * args.rtol:g}; friction c_f = {args.friction:g}\n")
    exu_ideal, wall_exu_ideal = exudyn_run(False, t_end, args.step)
    dc_ideal, wall_dc_ideal = daeclear_run(False, t_end, args.rtol, grid)
    runs = {"exudyn": exudyn_run(True, t_end, args.step, args.friction),
            "exudyn/2": exudyn_run(True, t_end, args.step / 2, args.friction),
            "daeclear": daeclear_run(True, t_end, args.rtol, grid, args.friction),
            "daeclear*10": daeclear_run(True, t_end, 10 * args.rtol, grid, args.friction)}
    for name in ("exudyn/2",):  # on the coarse step's grid
        runs[name] = ({k: v[::2] for k, v in runs[name][0].items()}, runs[name][1])
    exu_c, exu_f, dc_f, dc_c = (runs[n][0] for n in ("exudyn", "exudyn/2", "daeclear", "daeclear*10"))
    own_exu, own_dc = agree_until(exu_c, exu_f, args.agree), agree_until(dc_c, dc_f, args.agree)
    window = min(own_exu, own_dc)
    both = agree_until(exu_f, dc_f, args.agree)
    print(f"orbits within {args.agree:g} c: Exudyn with itself (two steps) to {own_exu * 1e3:.3f} ms, daeclear with "
          f"itself (two rtols) to {own_dc * 1e3:.3f} ms; Exudyn ({args.step / 2:g} s) with daeclear to "
          f"{both * 1e3:.3f} ms. Compared window: 0 to {window * 1e3:.3f} ms "
          f"({window / PERIOD:.2f} revolutions)\n")
    print("| run | window | slider velocity (rel. L2) | slider acceleration | crank moment "
          "| largest orbit distance / c | wall time (s) |")
    print("|---|---|---|---|---|---|---|")
    row = compare(exu_ideal, dc_ideal, t_end)
    print(f"| ideal joint, Exudyn {args.step:g} s vs daeclear | 0 to {t_end * 1e3:.1f} ms | {row['slider.vx']:.1e} | "
          f"{row['slider.ax']:.1e} | {row['drive.moment']:.1e} | - | {wall_exu_ideal:.2f} / {wall_dc_ideal:.3f} |")
    for label, a, b, walls in ((f"Exudyn {args.step:g} s vs {args.step / 2:g} s", exu_c, exu_f,
                                (runs["exudyn"][1], runs["exudyn/2"][1])),
                               (f"daeclear rtol {10 * args.rtol:g} vs {args.rtol:g}", dc_c, dc_f,
                                (runs["daeclear*10"][1], runs["daeclear"][1])),
                               (f"Exudyn {args.step / 2:g} s vs daeclear {args.rtol:g}", exu_f, dc_f,
                                (runs["exudyn/2"][1], runs["daeclear"][1]))):
        for until in sorted({window, t_end}):  # the compared window, then the whole run (past it: not converged)
            row = compare(a, b, until)
            print(f"| clearance, {label} | 0 to {until * 1e3:.3f} ms | {row['slider.vx']:.1e} | "
                  f"{row['slider.ax']:.1e} | {row['drive.moment']:.1e} | {row['orbit']:.1e} | "
                  f"{walls[0]:.2f} / {walls[1]:.3f} |")
    print("\n| impact | onset daeclear (ms) | onset Exudyn (ms) | difference (us) | peak F_N daeclear (N) | "
          "peak F_N Exudyn (N) | difference |")
    print("|---|---|---|---|---|---|---|")
    t_dc, t_exu = onsets(dc_f), onsets(exu_f)
    peaks_dc, peaks_exu = impact_peaks(dc_f, t_dc), impact_peaks(exu_f, t_exu)
    for k in range(min(t_dc.size, t_exu.size)):
        if max(t_dc[k], t_exu[k]) > window:
            break
        print(f"| {k + 1} | {t_dc[k] * 1e3:.5f} | {t_exu[k] * 1e3:.5f} | {(t_exu[k] - t_dc[k]) * 1e6:+.2f} | "
              f"{peaks_dc[k]:.0f} | {peaks_exu[k]:.0f} | {peaks_exu[k] / peaks_dc[k] - 1:+.1%} |")
    print(f"\nimpacts over the whole run: daeclear {t_dc.size}, Exudyn {t_exu.size}")
    figure(args.figure, exu_f, dc_f, exu_ideal, window)
    print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
