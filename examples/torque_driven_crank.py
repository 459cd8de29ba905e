"""Speed fluctuation of a slider-crank driven by a motor torque law, ideal and with a clearance joint.

The chapter's slider-crank (Table 4.1) without its constant-speed driver: a motor between the
ground and the crank, with the linear torque-speed characteristic of a DC motor,
``T = T_stall (1 - omega / omega_0)`` (``daeclear.Motor``, 100 N m, 5000 rpm no-load), starts the
mechanism from rest. A flywheel on the crank raises its moment of inertia from 1e-4 to 5e-3 kg m^2
(without it the slider's inertia forces swing the speed by about 50 % within a revolution). The
crank speed is no longer prescribed: it rises to a periodic steady state whose mean lies just
below the no-load speed, and it fluctuates within each revolution as the slider's inertia forces
load the crank. Two cases: ideal joints, and the rod-slider joint with a 0.5 mm revolute clearance
(Lankarani-Nikravesh, c_e = 0.9, Table 4.2), whose impacts add their own fluctuation.

For each case the script prints the mean crank speed of the last revolution, the coefficient of
speed fluctuation ``(omega_max - omega_min) / omega_mean`` over it, and the energy balance
(``track_work=True``: E(t) - E(0) - W(t), relative to the energy scale); and it draws the crank
speed against time (start-up) and against the crank angle (last revolution).

Run: ``python examples/torque_driven_crank.py [FIGURE.png]`` (default
``results/torque_driven_crank.png``); ``--quick`` for a short smoke run. About 3 s wall time
(plus about 5 s of compiling on an empty cache; machine loaded, load average 3.6 on 2 cores).

Measured (rtol 1e-8, GGL, 0.3 s from rest): ideal joints 4996.6 rpm mean, fluctuation 0.069;
0.5 mm clearance 4992.1 rpm, fluctuation 0.072 with 261 impacts; energy residual < 2e-6.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
from pathlib import Path
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import daeclear as dc  # noqa: E402
from daeclear.studies.accuracy import energy_balance  # noqa: E402

STALL_TORQUE = 100.0  # N m
NO_LOAD_SPEED = 5000.0 * math.pi / 30.0  # rad/s (5000 rpm, the chapter's crank speed)
FLYWHEEL_INERTIA = 5e-3  # kg m^2: the crank's moment of inertia with its flywheel
CLEARANCE = 0.5e-3  # m
T_END, QUICK_T_END = 0.3, 0.02  # s
RTOL = 1e-8


def torque_driven_crank(joint: str) -> dc.Scene:
    """``slider_crank(joint)`` started at rest, its driver replaced by the motor on the crank, with a flywheel."""
    scene = dc.mechanisms.slider_crank(joint, rpm=0.0, clearance=CLEARANCE)
    scene.elements = [dataclasses.replace(e, inertia=FLYWHEEL_INERTIA) if e.name == "crank" else e
                      for e in scene.elements if not isinstance(e, dc.Driver)]
    scene.add(dc.Motor("motor", scene.ground, "crank", stall_torque=STALL_TORQUE, no_load_speed=NO_LOAD_SPEED))
    return scene


def last_revolution(result: dc.Result) -> tuple[np.ndarray, np.ndarray]:
    """Crank angle (0..2 pi) and speed over the last complete revolution (every IDA step; the
    whole run when it is shorter than a revolution)."""
    phi, omega = result["crank.phi"], result["crank.omega"]
    turns = max(int(phi[-1] // (2 * math.pi)), 1)
    inside = (phi >= 2 * math.pi * (turns - 1)) & (phi <= 2 * math.pi * turns)
    return phi[inside] - 2 * math.pi * (turns - 1), omega[inside]


def summary(result: dc.Result) -> dict[str, float]:
    """Mean speed (time average), fluctuation coefficient over the last revolution, energy balance."""
    t, phi = result.t, result["crank.phi"]
    turns = int(phi[-1] // (2 * math.pi))
    start, end = np.interp(2 * math.pi * np.array([turns - 1, turns]), phi, t) if turns else (t[0], t[-1])
    tt = np.linspace(start, end, 4001)
    omega = np.interp(tt, t, result["crank.omega"])
    mean = float(np.trapezoid(omega, tt) / (end - start))
    impacts = len(result.events.of("clearance", kind="onset")) if "clearance.penetration" in result else 0
    return {"mean_rpm": mean * 30.0 / math.pi, "fluctuation": float(np.ptp(omega)) / mean,
            "energy_residual": energy_balance(result)["max_residual"], "impacts": impacts}


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("figure", nargs="?", type=Path, default=Path("results") / "torque_driven_crank.png",
                        help="figure to write (default results/torque_driven_crank.png)")
    parser.add_argument("--quick", action="store_true", help=f"simulate {QUICK_T_END} s only (smoke test)")
    args = parser.parse_args(argv)
    t_end = QUICK_T_END if args.quick else T_END
    cases = {"ideal joints": "ideal", f"revolute clearance c = {CLEARANCE * 1e3:g} mm": "revolute"}
    fig, (ax_t, ax_phi) = plt.subplots(1, 2, figsize=(11, 4.2))
    print(f"motor: stall torque {STALL_TORQUE:g} N m, no-load speed {NO_LOAD_SPEED * 30 / math.pi:g} rpm; "
          f"crank inertia {FLYWHEEL_INERTIA:g} kg m^2; t_end {t_end:g} s, rtol {RTOL:g}, GGL")
    for label, joint in cases.items():
        result = dc.simulate(torque_driven_crank(joint), t_end=t_end, rtol=RTOL,
                             options=dc.SolverOptions(track_work=True, formulation="ggl"))
        numbers = summary(result)
        print(f"{label:32s} mean {numbers['mean_rpm']:7.1f} rpm, fluctuation {numbers['fluctuation']:.3f}, "
              f"impacts {numbers['impacts']:5d}, energy residual {numbers['energy_residual']:.1e}")
        ax_t.plot(result.t, result["crank.omega"] * 30 / math.pi, lw=0.8, label=label)
        angle, omega = last_revolution(result)
        ax_phi.plot(np.degrees(angle), omega * 30 / math.pi, lw=0.8, label=label)
    ax_t.axhline(NO_LOAD_SPEED * 30 / math.pi, color="0.5", ls=":", lw=0.8, label="no-load speed")
    ax_t.set(xlabel="time (s)", ylabel="crank speed (rpm)", title="start-up from rest")
    ax_phi.set(xlabel="crank angle (deg)", ylabel="crank speed (rpm)", title="last revolution", xlim=(0, 360))
    ax_t.legend(fontsize=8)
    title = (f"Slider-crank driven by a motor T = {STALL_TORQUE:g} N m (1 - omega / {NO_LOAD_SPEED * 30 / math.pi:g}"
             f" rpm), crank with flywheel ({FLYWHEEL_INERTIA:g} kg m$^2$)\ncrank speed fluctuation, ideal joints vs "
             f"{CLEARANCE * 1e3:g} mm revolute clearance (Lankarani-Nikravesh, $c_e$ = 0.9), gravity 9.81 m/s$^2$")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    args.figure.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.figure, dpi=110, metadata={"Title": title})
    plt.close(fig)
    print(f"wrote {args.figure}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
