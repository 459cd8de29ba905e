"""Stability suite: stiff and extreme clearance cases that must finish or fail with a clear message.

A case *passes* when it finished with finite values, a bounded energy-balance residual and a
constraint drift below DRIFT_BOUND and half the clearance (more would swamp the clearance), or, with
``expect_failure``, when it failed with a message saying when (docs/stability.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable

import numpy as np

from .. import contact
from .accuracy import energy_balance
from ..core.errors import DaeclearError
from ..core.progress import Progress
from ..model.mechanisms import STEEL, slider_crank
from ..model.scene import Body, RevoluteClearance, Scene
from ..solvers.save_at import SaveAt
from ..solvers.solver_options import SolverOptions
from ..solvers.dispatch import simulate

REV = 60.0 / 5000.0
ENERGY_BOUND = 1e-3  # largest energy-balance residual, relative to the energy scale
DRIFT_BOUND = 1e-5  # largest constraint residual, m, and at most half the clearance


def grazing_scene(approach_speed: float = 1e-6) -> Scene:
    """A free journal (no gravity) reaching the bearing wall at ``approach_speed``: a contact
    that starts with almost no approach velocity (the damping term's floor is exercised)."""
    scene = Scene("grazing", gravity=(0.0, 0.0))
    c = 0.5e-3
    journal = scene.add(Body("journal", mass=0.1, inertia=1e-5, position=(c - 1e-9, 0.0),
                             velocity=(approach_speed, 0.0)))
    scene.add(RevoluteClearance("bearing", scene.ground.name, journal.name, point_i=(0.0, 0.0), point_j=(0.0, 0.0),
                                bearing_radius=10e-3, clearance=c, material=STEEL,
                                law=contact.LankaraniNikravesh(restitution=0.9)))
    return scene


def resting_scene() -> Scene:
    """A journal dropped under gravity into a fixed bearing: impacts, then following contact."""
    scene = Scene("resting", gravity=(0.0, -9.81))
    journal = scene.add(Body("journal", mass=0.1, inertia=1e-5))
    scene.add(RevoluteClearance("bearing", scene.ground.name, journal.name, at=(0.0, 0.0), bearing_radius=10e-3,
                                clearance=0.5e-3, material=STEEL, law=contact.LankaraniNikravesh(restitution=0.9)))
    return scene


@dataclass(frozen=True)
class Case:
    """One stability case: a scene factory, its time span and simulate options."""

    name: str
    group: str
    scene: Callable[[], Scene]
    t_end: float = 2 * REV
    options: dict[str, Any] = field(default_factory=dict)
    expect_failure: bool = False
    joint: str = "clearance"
    clearance: float = 0.5e-3


def _sc(**kw: Any) -> Callable[[], Scene]:
    return lambda: slider_crank("revolute", **kw)


CASES: tuple[Case, ...] = (
    Case("clearance 0.5 mm", "clearance", _sc(clearance=0.5e-3)),
    Case("clearance 0.1 mm", "clearance", _sc(clearance=0.1e-3), clearance=0.1e-3),
    Case("clearance 0.01 mm", "clearance", _sc(clearance=0.01e-3), clearance=0.01e-3),
    Case("clearance 1 um, index1", "clearance", _sc(clearance=1e-6), clearance=1e-6, options={"formulation": "index1"}),
    Case("clearance 1 um, GGL", "clearance", _sc(clearance=1e-6), clearance=1e-6, options={"formulation": "ggl"}),
    Case("restitution 1.0", "restitution", _sc(restitution=1.0)),
    Case("restitution 0.7", "restitution", _sc(restitution=0.7)),
    Case("restitution 0.5", "restitution", _sc(restitution=0.5)),
    Case("10000 rpm", "speed", _sc(rpm=10000.0), t_end=2 * REV / 2),
    Case("20000 rpm", "speed", _sc(rpm=20000.0), t_end=2 * REV / 4),
    Case("stiffness 1e12", "stiffness", _sc(law=contact.LankaraniNikravesh(restitution=0.9, stiffness=1e12))),
    Case("stiffness 1e13", "stiffness", _sc(law=contact.LankaraniNikravesh(restitution=0.9, stiffness=1e13))),
    Case("friction 0.1", "friction", _sc(friction=0.1)),
    Case("friction 0.5", "friction", _sc(friction=0.5)),
    Case("plain Coulomb 0.5 (sticking)", "friction", _sc(friction=contact.Coulomb(coefficient=0.5)),
         expect_failure=True),
    Case("index1 formulation (the chapter's)", "formulation", _sc(), options={"formulation": "index1"}),
    # the declared start: start="ideal" would centre the journal (no contact at all)
    Case("grazing onset (1 um/s), default atol", "contact", grazing_scene, t_end=0.01, joint="bearing",
         options={"start": "declared"}),
    Case("grazing onset (1 um/s), atol 1e-12", "contact", grazing_scene, t_end=0.01, joint="bearing",
         options={"atol": 1e-12, "start": "declared"}),
    Case("following contact (drop and rest)", "contact", resting_scene, t_end=0.5, joint="bearing"),
)


def run_case(case: Case, rtol: float | None = None, n_eval: int = 20001, *,
             options: SolverOptions | None = None) -> dict[str, Any]:
    """Run one case; return a row of the stability table (never raises for a solver failure).

    ``rtol`` (given) and the case's own options override ``options``; ``track_work`` is always on.
    """
    start = time.perf_counter()
    t_eval = np.linspace(0.0, case.t_end, n_eval)
    tolerance = {} if rtol is None else {"rtol": rtol}
    try:
        settings = (options or SolverOptions()).replace(track_work=True, **{**tolerance, **case.options})
        result = simulate(case.scene(), case.t_end, options=settings, on_failure="return", save=SaveAt(times=t_eval))
    except DaeclearError as exc:
        return {"case": case.name, "group": case.group, "finished": False, "passed": case.expect_failure,
                "message": f"{type(exc).__name__}: {exc}", "wall_time": time.perf_counter() - start}
    wall = time.perf_counter() - start
    finite = bool(np.all(np.isfinite(result.y)))
    row: dict[str, Any] = {
        "case": case.name, "group": case.group, "finished": result.success, "message": result.message,
        "wall_time": wall, "n_steps": int(result.stats.get("n_steps", 0)),
        "n_events": int(result.stats.get("n_events", 0)), "finite": finite,
        "max_penetration": float(np.max(result[f"{case.joint}.penetration"])) if result.t.size else math.nan,
        "drift": float(np.max(result["constraints.position"])) if "constraints.position" in result else 0.0,
        "energy_residual": energy_balance(result)["max_residual"] if result.t.size > 1 else math.nan,
    }
    row["drift_bound"] = min(DRIFT_BOUND, 0.5 * case.clearance)
    ok = (row["finished"] and finite and row["energy_residual"] < ENERGY_BOUND and row["drift"] < row["drift_bound"])
    clear_failure = (not row["finished"]) and bool(result.message) and " at t=" in result.message
    row["passed"] = clear_failure if case.expect_failure else ok
    return row


def run_suite(cases: tuple[Case, ...] = CASES, rtol: float | None = None, progress: bool = False, *,
              options: SolverOptions | None = None) -> list[dict[str, Any]]:
    """Run every case (see :data:`CASES`) with the solver settings ``options`` (default
    SolverOptions(), rtol 1e-6); ``rtol``, when given, overrides theirs."""
    rows: list[dict[str, Any]] = []
    bar = Progress(len(cases), unit="cases", desc="stability", enabled=progress)
    try:
        for case in cases:
            bar.update(len(rows), f"{case.name} ...")
            rows.append(run_case(case, rtol, options=options))
        bar.update(len(rows), "")
    finally:
        bar.close()
    return rows


def to_markdown(rows: list[dict[str, Any]], rtol: float) -> str:
    """The stability table as markdown."""
    lines = [
        f"rtol {rtol:g}; energy residual: max |E - E0 - W| over the energy scale, W the work of drivers and "
        f"contact forces integrated with the equations (track_work=True); bounds: energy {ENERGY_BOUND:g}, "
        f"constraint drift {DRIFT_BOUND:g} m and at most half the clearance.",
        "",
        "| case | passed | finished | wall (s) | steps | events | max penetration (m) | energy residual | drift (m) "
        "| message |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        msg = "" if r.get("finished") else r["message"][:160].replace("|", "/")
        lines.append(
            f"| {r['case']} | {'yes' if r['passed'] else 'NO'} | {'yes' if r.get('finished') else 'no'} | "
            f"{r['wall_time']:.2f} | {r.get('n_steps', '')} | {r.get('n_events', '')} | "
            f"{r.get('max_penetration', math.nan):.3g} | {r.get('energy_residual', math.nan):.2g} | "
            f"{r.get('drift', math.nan):.2g} | {msg} |")
    return "\n".join(lines) + "\n"
