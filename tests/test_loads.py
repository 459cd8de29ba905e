"""Applied loads (daeclear.loads): forces, torques, spring-dampers and motors.

Each element is checked against a closed-form solution or an independent second computation:
a mass on a spring (period, amplitude), a damped torsional oscillator (exact damped solution,
logarithmic decrement), torques and forces on free or pinned bodies (closed-form motions and
accelerations), the work of every load against the energy change (track_work), a slider-crank
driven by a motor torque law reaching its steady speed, tabulated and expression values against
their constant equivalents, the scipy and python paths, and scene files.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import daeclear as dc
from daeclear.studies.accuracy import energy_balance
from daeclear.model.loads import exp, fmax
from daeclear.model.scenefile import read_scene_file
from scene_texts import PENDULUM_LINK


def _oscillator(k: float = 800.0, m: float = 2.0, guided: bool = True, **spring) -> dc.Scene:
    """A mass on a linear spring to the ground, gravity off; stretched 0.05 m at the start."""
    scene = dc.Scene("oscillator", gravity=(0.0, 0.0))
    body = scene.add(dc.Body("mass", mass=m, inertia=0.1, position=(0.3, 0.0)))
    scene.add(dc.SpringDamper("spring", scene.ground, body, at_i=(0.0, 0.0), at_j=(0.3, 0.0), stiffness=k,
                              free_length=0.25, **spring))
    if guided:
        scene.add(dc.Translational("guide", scene.ground, body, at=(0.3, 0.0), axis=(1.0, 0.0)))
    return scene


def _upward_crossings(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    i = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])


@pytest.mark.parametrize("guided", [True, False], ids=["translational-joint", "free-body"])
def test_mass_on_a_spring_has_the_closed_form_period_and_amplitude(guided):
    k, m = 800.0, 2.0
    omega = math.sqrt(k / m)
    result = dc.simulate(_oscillator(k, m, guided), t_end=2.0, rtol=1e-9, options=dc.SolverOptions(track_work=True),
                         save=dc.SaveAt(times=np.linspace(0.0, 2.0, 8001)))
    x = result["mass.x"] - 0.25
    np.testing.assert_allclose(x, 0.05 * np.cos(omega * result.t), atol=2e-7)
    periods = np.diff(_upward_crossings(result.t, x))
    assert periods.size >= 5
    np.testing.assert_allclose(periods, 2 * math.pi / omega, rtol=1e-5)
    assert np.max(x) == pytest.approx(0.05, rel=1e-5) and np.min(x) == pytest.approx(-0.05, rel=1e-5)
    # the elastic energy is potential energy: an undamped spring conserves the mechanical energy
    np.testing.assert_allclose(result["energy.potential"], 0.5 * k * result["spring.elongation"] ** 2, rtol=1e-12)
    energy = result["energy.mechanical"]
    assert energy[0] == pytest.approx(0.5 * k * 0.05 ** 2, rel=1e-9)
    assert np.ptp(energy) < 1e-5 * energy[0]  # rtol 1e-9 over 6 periods: ~1e-6
    assert np.max(np.abs(result["energy.work"])) < 1e-12  # nothing non-conservative
    np.testing.assert_allclose(result["spring.force"], k * x, atol=1e-9)


def test_the_spring_runs_the_same_on_the_scipy_and_python_paths():
    k, m = 800.0, 2.0
    omega = math.sqrt(k / m)
    t_eval = np.linspace(0.0, 0.2, 201)
    scipy_run = dc.simulate(_oscillator(k, m), t_end=0.2, method="RK45", rtol=1e-10, atol=1e-12,
                            save=dc.SaveAt(times=t_eval))
    np.testing.assert_allclose(scipy_run["mass.x"] - 0.25, 0.05 * np.cos(omega * t_eval), atol=1e-7)
    # rtol 1e-10: the energy balance of a 1 J oscillator closes to ~1e-8 (at 1e-9 GGL's python run is at 1.4e-6)
    python_run = dc.simulate(_oscillator(k, m, damping=2.0), t_end=0.2, rtol=1e-10,
                             options=dc.SolverOptions(backend="python", track_work=True), save=dc.SaveAt(times=t_eval))
    compiled = dc.simulate(_oscillator(k, m, damping=2.0), t_end=0.2, rtol=1e-10,
                           options=dc.SolverOptions(track_work=True), save=dc.SaveAt(times=t_eval))
    np.testing.assert_allclose(python_run["mass.x"], compiled["mass.x"], atol=1e-7)
    assert energy_balance(python_run)["max_residual"] < 1e-6


def _torsion(stiffness: float, damping: float, theta0: float, inertia: float = 0.02) -> dc.Scene:
    """A disc pinned at its centre to the ground, a torsional spring-damper, deflected theta0."""
    scene = dc.Scene("torsion", gravity=(0.0, -9.81))
    disc = scene.add(dc.Body("disc", mass=1.5, inertia=inertia, position=(0.0, 0.0)))
    scene.add(dc.Revolute("pivot", scene.ground, disc, at=(0.0, 0.0)))
    scene.add(dc.RotationalSpringDamper("spring", scene.ground, disc, stiffness=stiffness, damping=damping,
                                        free_angle=-theta0))
    return scene


def test_damped_rotational_spring_follows_the_exact_damped_solution():
    k, c, inertia, theta0 = 50.0, 0.1, 0.02, 0.3
    wn = math.sqrt(k / inertia)
    zeta = c / (2.0 * math.sqrt(k * inertia))
    wd = wn * math.sqrt(1.0 - zeta ** 2)
    t = np.linspace(0.0, 0.8, 8001)
    result = dc.simulate(_torsion(k, c, theta0, inertia), t_end=0.8, rtol=1e-9,
                         options=dc.SolverOptions(track_work=True), save=dc.SaveAt(times=t))
    exact = theta0 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    np.testing.assert_allclose(result["spring.deflection"], exact, atol=1e-6 * theta0)
    # logarithmic decrement of successive maxima: 2 pi zeta / sqrt(1 - zeta^2)
    d = result["spring.deflection"]
    peaks = [i for i in range(1, d.size - 1) if d[i] > d[i - 1] and d[i] >= d[i + 1] and d[i] > 0]
    decrements = np.log(d[peaks[:-1]] / d[peaks[1:]])
    assert len(peaks) >= 4
    np.testing.assert_allclose(decrements, 2 * math.pi * zeta / math.sqrt(1 - zeta ** 2), rtol=2e-3)
    # the damper's work is the loss of mechanical energy
    np.testing.assert_allclose(result["energy.mechanical"] - result["energy.mechanical"][0], result["energy.work"],
                               atol=1e-7 * result["energy.mechanical"][0])
    assert result["energy.work"][-1] < -0.5 * result["energy.mechanical"][0]  # most of it is gone
    assert np.all(result["spring.power"] <= 0.0)


def _spinning_disc(torque, inertia: float = 0.05) -> dc.Scene:
    scene = dc.Scene("disc", gravity=(0.0, 0.0))
    disc = scene.add(dc.Body("disc", mass=1.0, inertia=inertia, position=(0.0, 0.0)))
    scene.add(dc.Revolute("pivot", scene.ground, disc, at=(0.0, 0.0)))
    scene.add(dc.Torque("torque", disc, torque, reaction=scene.ground))
    return scene


def test_work_of_an_applied_torque_equals_the_energy_change():
    T0, inertia, t_end = 2.0, 0.05, 0.5
    t = np.linspace(0.0, t_end, 101)
    result = dc.simulate(_spinning_disc(T0, inertia), t_end=t_end, rtol=1e-9, options=dc.SolverOptions(track_work=True),
                         save=dc.SaveAt(times=t))
    np.testing.assert_allclose(result["disc.omega"], T0 * t / inertia, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(result["energy.work"], (T0 * t) ** 2 / (2 * inertia), rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(result["energy.mechanical"], result["energy.work"], rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(result["torque.power"], T0 * result["disc.omega"], rtol=1e-12)
    assert energy_balance(result)["max_residual"] < 1e-7


def test_tabulated_and_expression_torques_match_their_closed_forms():
    T0, inertia, tau = 2.0, 0.05, 0.1
    t = np.linspace(0.0, 0.6, 121)
    runs = {
        "constant": dc.simulate(_spinning_disc(T0, inertia), t_end=0.6, rtol=1e-9, save=dc.SaveAt(times=t)),
        "flat table": dc.simulate(_spinning_disc(dc.Table((0.0, 1.0), (T0, T0)), inertia), t_end=0.6, rtol=1e-9,
                                  save=dc.SaveAt(times=t)),
        "flat expression": dc.simulate(_spinning_disc(dc.Expression(lambda t, s, p: p.T, T=T0), inertia),
                                       t_end=0.6, rtol=1e-9, save=dc.SaveAt(times=t)),
    }
    for name, run in runs.items():
        np.testing.assert_allclose(run["disc.omega"], T0 * t / inertia, rtol=1e-8, atol=1e-10, err_msg=name)
    # a ramp to T0 over 0.2 s, then held (and before 0: held at 0): omega = T0 t^2 / (0.4 I), then linear
    ramp = dc.simulate(_spinning_disc(dc.Table((0.0, 0.2), (0.0, T0)), inertia), t_end=0.6, rtol=1e-9,
                       save=dc.SaveAt(times=t))
    expected = np.where(t < 0.2, T0 * t ** 2 / (0.4 * inertia), T0 * 0.1 / inertia + T0 * (t - 0.2) / inertia)
    np.testing.assert_allclose(ramp["disc.omega"], expected, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(ramp["torque.torque"], np.interp(t, (0.0, 0.2), (0.0, T0)), atol=1e-12)
    # a decaying torque T0 exp(-t/tau): omega = T0 tau (1 - exp(-t/tau)) / I
    decay = dc.Expression(lambda t, s, p: p.T0 * exp(-t / p.tau), T0=T0, tau=tau)
    run = dc.simulate(_spinning_disc(decay, inertia), t_end=0.6, rtol=1e-9, options=dc.SolverOptions(track_work=True),
                      save=dc.SaveAt(times=t))
    np.testing.assert_allclose(run["disc.omega"], T0 * tau * (1 - np.exp(-t / tau)) / inertia, rtol=1e-7, atol=1e-9)
    assert energy_balance(run)["max_residual"] < 1e-6


def test_a_state_expression_equals_the_element_it_imitates():
    """A torque -c * (relative speed) - k * (relative angle - a0), written as an expression of the
    state, gives the rotational spring-damper's motion."""
    k, c, theta0 = 50.0, 0.1, 0.3
    spring = _torsion(k, c, theta0)
    imitation = dc.Scene("imitation", gravity=(0.0, -9.81))
    disc = imitation.add(dc.Body("disc", mass=1.5, inertia=0.02, position=(0.0, 0.0)))
    imitation.add(dc.Revolute("pivot", imitation.ground, disc, at=(0.0, 0.0)))
    law = dc.Expression(lambda t, s, p: -p.k * (s.angle - p.a0) - p.c * s.speed, k=k, c=c, a0=-theta0)
    imitation.add(dc.Torque("spring", disc, law, reaction=imitation.ground))
    t = np.linspace(0.0, 0.3, 301)
    a = dc.simulate(spring, t_end=0.3, rtol=1e-9, save=dc.SaveAt(times=t))
    b = dc.simulate(imitation, t_end=0.3, rtol=1e-9, save=dc.SaveAt(times=t))
    np.testing.assert_allclose(b["disc.phi"], a["disc.phi"], atol=1e-8)
    np.testing.assert_allclose(b["spring.torque"], a["spring.torque"], atol=1e-6)


def _pendulum(gravity: float) -> dc.Scene:
    scene = dc.Scene("pendulum", gravity=(0.0, -gravity))
    link = scene.add(dc.Body("link", mass=1.2, inertia=0.01, position=(0.5, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    return scene


def test_a_force_equal_to_the_weight_moves_the_pendulum_as_gravity_does():
    g = 9.81
    weighted = _pendulum(0.0)
    weighted.add(dc.Force("weight", "link", fy=-1.2 * g))  # at the centre of mass
    t = np.linspace(0.0, 1.0, 201)
    a = dc.simulate(_pendulum(g), t_end=1.0, rtol=1e-9, save=dc.SaveAt(times=t))
    b = dc.simulate(weighted, t_end=1.0, rtol=1e-9, options=dc.SolverOptions(track_work=True), save=dc.SaveAt(times=t))
    np.testing.assert_allclose(b["link.phi"], a["link.phi"], atol=1e-7)
    # with gravity a force, its work is the change of kinetic energy (there is no potential)
    scale = np.max(b["energy.kinetic"])
    np.testing.assert_allclose(b["energy.work"], b["energy.kinetic"], atol=1e-6 * scale)
    np.testing.assert_allclose(b["energy.work"], -(a["energy.potential"] - a["energy.potential"][0]), atol=1e-6 * scale)


def test_a_force_acts_at_its_point():
    """A vertical force F at the tip of a pinned link: alpha = -F L / (I + m d^2) at the start."""
    F, m, inertia = 3.0, 1.2, 0.01
    scene = _pendulum(0.0)
    scene.add(dc.Force("tip", "link", fy=-F, at=(1.0, 0.0)))
    model = dc.assemble(scene)
    y0, yp0 = model.initial_state()
    alpha = yp0[model.state_names.index("link.omega")]
    assert alpha == pytest.approx(-F * 1.0 / (inertia + m * 0.5 ** 2), rel=1e-12)


def test_a_follower_force_turns_with_its_body():
    """A free spinning body (omega0) pushed by a body-frame force F at its centre of mass:
    vx = F sin(w t) / (m w), vy = F (1 - cos(w t)) / (m w), the spin unchanged."""
    F, m, w = 2.0, 0.5, 20.0
    scene = dc.Scene("follower", gravity=(0.0, 0.0))
    scene.add(dc.Body("puck", mass=m, inertia=0.01, angular_velocity=w))
    scene.add(dc.Force("thrust", "puck", fx=F, frame="body"))
    t = np.linspace(0.0, 0.5, 101)
    result = dc.simulate(scene, t_end=0.5, rtol=1e-10, options=dc.SolverOptions(track_work=True),
                         save=dc.SaveAt(times=t))
    np.testing.assert_allclose(result["puck.vx"], F * np.sin(w * t) / (m * w), atol=1e-8)
    np.testing.assert_allclose(result["puck.vy"], F * (1 - np.cos(w * t)) / (m * w), atol=1e-8)
    np.testing.assert_allclose(result["puck.omega"], w, rtol=1e-12)
    np.testing.assert_allclose(result["thrust.fx"], F * np.cos(w * t), atol=1e-9)
    assert energy_balance(result)["max_residual"] < 1e-7


def test_a_damped_linear_spring_dissipates_what_the_work_counts():
    k, m, c = 800.0, 2.0, 4.0
    zeta = c / (2 * math.sqrt(k * m))
    wn = math.sqrt(k / m)
    wd = wn * math.sqrt(1 - zeta ** 2)
    t = np.linspace(0.0, 0.5, 501)
    result = dc.simulate(_oscillator(k, m, damping=c), t_end=0.5, rtol=1e-9, options=dc.SolverOptions(track_work=True),
                         save=dc.SaveAt(times=t))
    exact = 0.05 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta * wn / wd * np.sin(wd * t))
    np.testing.assert_allclose(result["spring.elongation"], exact, atol=1e-7)
    np.testing.assert_allclose(result["spring.power"], -c * result["mass.vx"] ** 2, atol=1e-9)
    assert energy_balance(result)["max_residual"] < 1e-6


# ---------------------------------------------------------------- a slider-crank driven by a motor

NO_LOAD_SPEED = 3000.0 * math.pi / 30.0  # rad/s


def torque_driven_crank(joint: str = "ideal", stall_torque: float = 20.0) -> dc.Scene:
    """The chapter's slider-crank started at rest, its driver replaced by a motor on the crank."""
    scene = dc.mechanisms.slider_crank(joint, rpm=0.0).without("drive")
    assert not scene.drivers
    scene.add(dc.Motor("motor", scene.ground, "crank", stall_torque=stall_torque, no_load_speed=NO_LOAD_SPEED))
    return scene


def _revolution_means(result: dc.Result) -> list[tuple[float, float]]:
    """(mean of omega, mean of omega^2) over each full crank revolution (time averages)."""
    t, phi, w = result.t, result["crank.phi"], result["crank.omega"]
    marks = np.interp(2 * np.pi * np.arange(1, int(phi[-1] / (2 * np.pi)) + 1), phi, t)
    out = []
    for a, b in zip(marks[:-1], marks[1:]):
        tt = np.linspace(a, b, 4001)
        ww = np.interp(tt, t, w)
        out.append((np.trapezoid(ww, tt) / (b - a), np.trapezoid(ww ** 2, tt) / (b - a)))
    return out


def test_a_torque_driven_crank_reaches_its_steady_speed_and_closes_the_energy_balance():
    """Started at rest; at the periodic steady state the motor's work over a revolution is zero:
    mean(T omega) = T_s (mean(omega) - mean(omega^2) / omega_0) = 0 (the linear characteristic)."""
    result = dc.simulate(torque_driven_crank(), t_end=0.35, rtol=1e-10, options=dc.SolverOptions(track_work=True))
    assert result["crank.omega"][0] == 0.0
    balance = energy_balance(result)
    assert balance["max_residual"] < 1e-7, balance
    means = _revolution_means(result)
    assert len(means) >= 12
    first, last = means[0], means[-1]
    assert abs(first[0] - first[1] / NO_LOAD_SPEED) > 1e-2 * NO_LOAD_SPEED  # accelerating: not yet
    for mean, square in means[-4:]:
        assert mean == pytest.approx(square / NO_LOAD_SPEED, rel=1e-5)
        assert mean == pytest.approx(last[0], rel=1e-5)  # steady
    assert 0.9 * NO_LOAD_SPEED < last[0] < NO_LOAD_SPEED  # below the no-load speed by var/mean
    np.testing.assert_allclose(result["motor.torque"], 20.0 * (1 - result["crank.omega"] / NO_LOAD_SPEED),
                               rtol=1e-12, atol=1e-12)


def test_a_torque_driven_crank_through_a_clearance_joint_closes_the_energy_balance():
    result = dc.simulate(torque_driven_crank("revolute"), t_end=0.1, rtol=1e-9,
                         options=dc.SolverOptions(track_work=True))
    assert len(result.events) > 0
    assert energy_balance(result)["max_residual"] < 1e-6


# ---------------------------------------------------------------- structure, validation, files

def test_an_expression_needs_the_loads_math_and_its_numbers_are_parameters():
    scene = _spinning_disc(dc.Expression(lambda t, s, p: p.T * math.sin(s.angle), T=1.0))
    with pytest.raises(dc.SceneError, match="Torque 'torque': value=Expression .* does not run on CasADi"):
        scene.validate()
    first = dc.assemble(_spinning_disc(dc.Expression(_ramped, T=1.0, rise=0.1)))
    second = dc.assemble(_spinning_disc(dc.Expression(_ramped, T=5.0, rise=0.3)))
    assert second.functions is first.functions
    assert second.parameter("torque.value.T")[0] == 5.0 and second.parameter("torque.value.rise")[0] == 0.3
    other = dc.assemble(_spinning_disc(dc.Expression(lambda t, s, p: p.T * t, T=5.0, rise=0.3)))
    assert other.functions is not first.functions  # another function: another structure


def _ramped(t, s, p):
    return p.T * fmax(1.0 - t / p.rise, 0.0)


LOADS_TOML = """
[scene]
name = "loaded"
gravity = [0.0, -9.81]
""" + PENDULUM_LINK + """
[[force]]
name = "push"
body = "link"
fx = 1.0
fy = { times = [0.0, 0.1, 0.2], values = [0.0, 2.0, 0.0] }
at = [1.0, 0.0]

[[torque]]
name = "twist"
body = "link"
value = { times = [0.0, 0.5], values = [0.0, 0.3] }
reaction = "ground"

[[spring_damper]]
name = "spring"
body_i = "ground"
body_j = "link"
at_i = [1.0, 0.5]
at_j = [1.0, 0.0]
stiffness = 40.0
damping = 0.2

[[rotational_spring_damper]]
name = "torsion"
body_i = "ground"
body_j = "link"
stiffness = 3.0
damping = 0.01
free_angle = 0.1

[[motor]]
name = "motor"
body_i = "ground"
body_j = "link"
stall_torque = 0.5
no_load_speed = 10.0
"""


def _loaded_scene() -> dc.Scene:
    scene = dc.Scene("loaded", gravity=(0.0, -9.81))
    link = scene.add(dc.Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    scene.add(dc.Force("push", "link", fx=1.0, fy=dc.Table((0.0, 0.1, 0.2), (0.0, 2.0, 0.0)), at=(1.0, 0.0)))
    scene.add(dc.Torque("twist", "link", dc.Table((0.0, 0.5), (0.0, 0.3)), reaction="ground"))
    scene.add(dc.SpringDamper("spring", "ground", "link", at_i=(1.0, 0.5), at_j=(1.0, 0.0), stiffness=40.0,
                              damping=0.2))
    scene.add(dc.RotationalSpringDamper("torsion", "ground", "link", stiffness=3.0, damping=0.01, free_angle=0.1))
    scene.add(dc.Motor("motor", "ground", "link", stall_torque=0.5, no_load_speed=10.0))
    return scene


def test_scene_file_loads_round_trip(tmp_path: Path):
    path = tmp_path / "loaded.toml"
    path.write_text(LOADS_TOML)
    from_file = read_scene_file(path).scene
    built = _loaded_scene()
    assert from_file.elements == built.elements
    assert from_file.to_dict() == built.to_dict()
    t = np.linspace(0.0, 0.5, 51)
    a = dc.simulate(from_file, t_end=0.5, rtol=1e-8, options=dc.SolverOptions(track_work=True), save=dc.SaveAt(times=t))
    b = dc.simulate(built, t_end=0.5, rtol=1e-8, options=dc.SolverOptions(track_work=True), save=dc.SaveAt(times=t))
    np.testing.assert_array_equal(a["link.phi"], b["link.phi"])
    assert energy_balance(a)["max_residual"] < 1e-6
    power = sum(a[f"{name}.power"] for name in ("push", "twist", "spring", "torsion", "motor"))
    np.testing.assert_allclose(a["energy.input_power"], power, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("table, text, expected", [
    ("force", 'name = "f"\nbody = "link"\nfz = 1.0', "unknown key(s) fz"),
    ("force", 'name = "f"\nbody = "link"\nfx = { times = [0.0, 1.0], value = [1.0, 2.0] }',
     "key fx: unknown key(s) value; allowed: times, values"),
    ("torque", 'name = "t"\nbody = "link"\nvalue = { times = [1.0, 0.0], values = [1.0, 2.0] }',
     "key value: Torque 't': value=Table: times=[1.0, 0.0] s, must be strictly increasing"),
    ("spring_damper", 'name = "s"\nbody_i = "ground"\nbody_j = "link"\nat_i = [0.0, 0.0]\nat_j = [1.0, 0.0]\n'
     'stiffness = -1.0', "key stiffness: SpringDamper 's': stiffness=-1.0 N/m, must be a finite number >= 0"),
    ("motor", 'name = "m"\nbody_i = "ground"\nbody_j = "link"\nstall_torque = 1.0\nno_load_speed = -3.0',
     "no_load_speed=-3.0 rad/s, must have the same sign"),
    ("torque", 'name = "t"\nbody = "lnk"\nvalue = 1.0', "Torque 't': body refers to body 'lnk', not in scene"),
])
def test_scene_file_load_errors_name_table_key_and_rule(tmp_path: Path, table, text, expected):
    from scene_texts import PENDULUM

    path = tmp_path / "bad.toml"
    path.write_text(PENDULUM + f"\n[[{table}]]\n{text}\n")
    with pytest.raises(dc.SceneError) as info:
        read_scene_file(path)
    message = str(info.value)
    assert str(path) in message and expected in message, message


def test_the_torque_driven_crank_example_writes_its_figure(tmp_path: Path, capsys):
    import importlib.util

    path = Path(__file__).resolve().parent.parent / "examples" / "torque_driven_crank.py"
    spec = importlib.util.spec_from_file_location("torque_driven_crank", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    figure = tmp_path / "speed.png"
    assert module.main(["--quick", str(figure)]) == 0
    assert figure.stat().st_size > 10_000
    out = capsys.readouterr().out
    assert "ideal joints" in out and "revolute clearance" in out and "energy residual" in out


SCALE = 2.0  # a number read by an expression from outside its named numbers: structure


def test_an_expression_function_and_the_numbers_it_reads_from_outside_are_structure():
    def scaled(t, s, p):
        return SCALE * p.T

    both = (dc.Expression(lambda t, s, p: p.T, T=1.0), dc.Expression(lambda t, s, p: 2.0 * p.T, T=1.0))
    keys = {dc.Torque("t", "disc", e).to_dict()["value"]["digest"] for e in both}
    assert len(keys) == 2  # two lambdas on one line differ
    first = dc.Expression(scaled, T=1.0).to_dict()["digest"]
    global SCALE
    SCALE = 3.0
    try:
        assert dc.Expression(scaled, T=1.0).to_dict()["digest"] != first
    finally:
        SCALE = 2.0
    assert dc.Expression(scaled, T=7.0).to_dict()["digest"] == first  # named numbers are not structure
    calling = dc.Expression(lambda t, s, p: scaled(t, s, p) + p.T, T=1.0).to_dict()["digest"]
    SCALE = 3.0
    try:  # a function it calls changed: another structure
        assert dc.Expression(lambda t, s, p: scaled(t, s, p) + p.T, T=1.0).to_dict()["digest"] != calling
    finally:
        SCALE = 2.0


def _pendulum_with_spring(**spring_end) -> dc.Scene:
    """A link pinned to the ground at its left end (body-fixed joint points), declared off its
    assembled pose (its centre 0.03 m too high), with a spring from the ground to the link."""
    scene = dc.Scene("sprung pendulum", gravity=(0.0, -9.81))
    link = scene.add(dc.Body("link", mass=1.0, inertia=1.0 / 12, position=(0.5, 0.03), angle=0.0))
    scene.add(dc.Revolute("pin", scene.ground, link, point_i=(0.0, 0.0), point_j=(-0.5, 0.0)))
    scene.add(dc.SpringDamper("spring", scene.ground, link, at_i=(1.0, 0.5), stiffness=5.0, damping=0.2,
                              free_length=0.4, **spring_end))
    return scene


def test_a_body_fixed_spring_end_moves_with_its_body_when_the_declared_pose_is_off():
    """point_j is a point of the link whatever its declared pose: the spring's length is the
    distance from the ground point to that body point of the assembled (and moving) link at every
    output; a world point at_j, read in the declared (wrong) pose, is another point of the link."""
    tip = (0.5, 0.0)  # the link's free end, link coordinates
    result = dc.simulate(_pendulum_with_spring(point_j=tip), t_end=0.5, rtol=1e-9, atol=1e-10,
                         save=dc.SaveAt(times=np.linspace(0.0, 0.5, 51)))
    x, y, phi = result["link.x"], result["link.y"], result["link.phi"]
    end = np.column_stack([x + np.cos(phi) * tip[0] - np.sin(phi) * tip[1],
                           y + np.sin(phi) * tip[0] + np.cos(phi) * tip[1]])
    assert abs(math.hypot(x[0] - 0.5 * math.cos(phi[0]), y[0] - 0.5 * math.sin(phi[0]))) < 1e-12  # pinned
    assert abs(y[0] - 0.03) > 1e-3  # assembly did move the link off its declared pose
    np.testing.assert_allclose(result["spring.length"], np.hypot(end[:, 0] - 1.0, end[:, 1] - 0.5), rtol=1e-12)
    assert np.ptp(phi) > 0.05  # the link swings: the end was followed, not a fixed point
    world = dc.simulate(_pendulum_with_spring(at_j=(1.0, 0.0)), t_end=1e-3, rtol=1e-9)
    assert abs(world["spring.length"][0] - result["spring.length"][0]) > 1e-3
