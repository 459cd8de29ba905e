"""Sensitivity jumps at every kind of event (issue 43 item 3), by the Taylor remainder of the reference run
(``simulate(..., sensitivities=...)``, tests/sensitivity_runs.py) against ordinary runs.

If S = dy/dp at T is right, the first-order prediction y(p + h) ~ y(p) + S h misses by O(h^2): its remainder
falls 16-fold when h falls 4-fold. A missing or wrong term (a jump left out, a latched speed's dt*/dp) leaves
O(h): 4-fold. Each case has several events of its own kind and keeps their sequence under the steps (checked):

* revolute, dry, with friction: an oblique, spinning journal hits its bearing (Lankarani-Nikravesh, modified
  Coulomb), onset and separation;
* translational, corners: a slider tilted by 1e-4 rad drops onto the guide: the rear corner, then the front one,
  both leave;
* translational, section-4.3 faces: the same drop, the face forms when the second corner touches (the force
  jumps from the corner law to the much stiffer face law) and breaks before the first corner leaves;
* lubricated: a journal on an air film (1.8e-5 Pa s) falls through it: film breakdown, a dry impact and its
  separation, the film's re-formation (the film force switches off and on).

Without the jumps the faces' and the lubricated joint's remainders fall only as h: the jumps are tested.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.assembly.sensitivity import parameter_value
from daeclear.model.scene import TranslationalClearance
from sensitivity_runs import StackedRun as SensitivityRun, forward_sensitivities

STEEL = dcc.Material(young=207e9, poisson=0.3)
STEPS = (4e-2, 1e-2, 2.5e-3)  # relative to each parameter


def revolute_with_friction() -> dc.DAEModel:
    scene = dc.Scene("radial", gravity=(0.0, 0.0))
    journal = scene.add(dc.Body("journal", mass=1.0, inertia=0.01, velocity=(1.0, 0.3), angular_velocity=5.0))
    scene.add(dc.RevoluteClearance("clearance", scene.ground, journal, at=(0, 0), bearing_radius=1.0, clearance=0.1,
                                   law=dcc.LankaraniNikravesh(restitution=0.8, stiffness=1e7), friction=0.2))
    return dc.assemble(scene)


def tilted_drop(model: str) -> dc.DAEModel:
    """A slider of the chapter's size, tilted by 1e-4 rad, 1 um above the lower surface, falling at 0.1 m/s."""
    length, width, clearance, tilt = 0.05, 0.05, 0.5e-3, 1e-4
    scene = dc.Scene("guide", gravity=(0.0, 0.0))
    height = -clearance + 1e-6 + 0.5 * length * tilt  # the rear lower corner 1 um above the surface
    slider = scene.add(dc.Body("slider", mass=0.14, inertia=1e-4, position=(0.0, height), angle=tilt,
                               velocity=(0.0, -0.1)))
    scene.add(TranslationalClearance("g", scene.ground, slider, point_i=(0.0, 0.0), point_j=(0.0, 0.0),
                                     slider_axis=(1.0, 0.0), length=length, width=width, corner_radius=1e-3,
                                     clearance=clearance, material=STEEL, law=dcc.LankaraniNikravesh(restitution=0.9),
                                     model=model))
    return dc.assemble(scene)


def air_film() -> dc.DAEModel:
    scene = dc.Scene("journal", gravity=(0.0, -9.81))
    body = scene.add(dc.Body("journal", mass=2.0, inertia=1e-4, position=(0.0, 0.0)))
    scene.add(dc.RevoluteClearance("bearing", scene.ground, body, at=(0.0, 0.0), bearing_radius=0.01, clearance=5e-5,
                                   material=STEEL, law=dcc.HydrodynamicBearing(viscosity=1.8e-5, length=0.01,
                                                                               roughness=2e-6, hysteresis=1.0)))
    return dc.assemble(scene)


# name -> (model, T, parameters, the events' (pair, kind) in order)
CASES: dict[str, tuple[Callable[[], dc.DAEModel], float, list[str], list[tuple[str, str]]]] = {
    "revolute-friction": (revolute_with_friction, 0.25,
                          ["clearance.clearance", "clearance.law.restitution", "clearance.friction", "journal.inertia"],
                          [("clearance", "onset"), ("clearance", "separation")]),
    "translational-corners": (lambda: tilted_drop("corners"), 4e-4, ["slider.mass", "g.law.restitution"],
                              [("g.C_lower", "onset"), ("g.D_lower", "onset"), ("g.C_lower", "separation"),
                               ("g.D_lower", "separation")]),
    "translational-faces": (lambda: tilted_drop("section-4.3"), 1e-4, ["slider.mass", "g.law.restitution"],
                            [("g.C_lower", "onset"), ("g.D_lower", "onset"), ("g.lower_face", "onset"),
                             ("g.D_lower", "separation"), ("g.lower_face", "separation"), ("g.C_lower", "separation")]),
    "lubricated": (air_film, 5e-3, ["journal.mass", "bearing.law.viscosity", "bearing.law.hysteresis",
                                    "bearing.law.dry.restitution"],
                   [("bearing.regime", "onset"), ("bearing", "onset"), ("bearing", "separation"),
                    ("bearing.regime", "separation")]),
}


def final_state(model: dc.DAEModel, T: float, values: dict[str, float] | None = None
                ) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Positions and velocities at T of an ordinary run at rtol 1e-12, and its events."""
    moved = model.with_parameters(values) if values else model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(moved, T, options=dc.SolverOptions(start="declared", rtol=1e-12),
                             save=dc.SaveAt(times=[0.0, T], steps=False))
    y = np.array([result[name][-1] for name in model.state_names[:2 * model.n_q]])
    return y, [(e.pair, e.kind) for e in result.events]


def reference(model: dc.DAEModel, T: float, names: list[str], jumps: bool = True) -> SensitivityRun:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        return forward_sensitivities(model, T, names, rtol=1e-11, start="declared", backend="auto", jumps=jumps)


def remainders(model: dc.DAEModel, T: float, run: SensitivityRun, events: list[tuple[str, str]]) -> np.ndarray:
    """(n_params, len(STEPS)): max |y(p + h) - y(p) - S h| over the positions and velocities at T."""
    base, seen = final_state(model, T)
    assert seen == events
    n = 2 * model.n_q
    out = np.zeros((len(run.names), len(STEPS)))
    for j, name in enumerate(run.names):
        p = parameter_value(model, name)
        for k, step in enumerate(STEPS):
            moved, seen = final_state(model, T, {name: p + step * p})
            assert seen == events, (name, step)  # the same sequence: a derivative exists
            out[j, k] = np.abs(moved - base - run.S[-1, :n, j] * step * p).max()
    return out


@pytest.mark.parametrize("case", list(CASES))
def test_taylor_remainder_falls_as_h_squared(case: str) -> None:
    make, T, names, events = CASES[case]
    model = make()
    run = reference(model, T, names)
    assert run.success and [(e.pair, e.kind) for e in run.events] == events
    assert all(np.all(np.isfinite(e.dt_dp)) for e in run.events)
    ratios = (lambda r: r[:, :-1] / r[:, 1:])(remainders(model, T, run, events))
    assert np.all((16 / 1.25 < ratios) & (ratios < 16 * 1.25)), ratios


@pytest.mark.parametrize("case", ["translational-faces", "lubricated"])
def test_without_the_jumps_the_remainder_falls_only_as_h(case: str) -> None:
    """The face's switch of law and the film's switching off and on make y' jump: S must jump with it."""
    make, T, names, events = CASES[case]
    model = make()
    ratios = (lambda r: r[:, :-1] / r[:, 1:])(remainders(model, T, reference(model, T, names, jumps=False), events))
    assert np.any(ratios[:, -1] < 8.0), ratios


def event_times(model: dc.DAEModel, T: float, values: dict[str, float]) -> tuple[np.ndarray, list[tuple[str, str]]]:
    moved = model.with_parameters(values)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(moved, T, options=dc.SolverOptions(start="declared", rtol=1e-12),
                             save=dc.SaveAt(times=[0.0, T], steps=False))
    return np.array([e.t for e in result.events]), [(e.pair, e.kind) for e in result.events]


@pytest.mark.parametrize("case", ["translational-faces", "lubricated"])
def test_event_times_sensitivities_against_central_differences(case: str) -> None:
    """Every event's dt*/dp (a face's is the time of the corner root that made it; the film's breakdown and
    re-formation are the roots film_break and film_reform) against central differences of the event times of
    ordinary runs, relative step 1e-4 (O(h^2) ~ 1e-8, the runs' time errors ~ 1e-12 s over the step)."""
    make, T, names, events = CASES[case]
    model = make()
    run = reference(model, T, names)
    dt_dp = np.array([e.dt_dp for e in run.events])  # (n_events, Ns)
    for j, name in enumerate(names):
        p, h = parameter_value(model, name), 1e-4 * parameter_value(model, name)
        (plus, seen_plus), (minus, seen_minus) = (event_times(model, T, {name: p + s * h}) for s in (1, -1))
        assert seen_plus == seen_minus == events
        fd = (plus - minus) / (2 * h)
        assert dt_dp[:, j] == pytest.approx(fd, rel=1e-4, abs=1e-6 * np.abs(fd).max()), name
