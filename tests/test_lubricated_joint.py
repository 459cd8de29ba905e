"""The lubricated revolute clearance joint (RevoluteClearance with a HydrodynamicBearing law) in a run.

References, each independent of the assembled model:

- static equilibrium of a journal (radius R_j) spinning at omega under a constant load W (short bearing, half
  film, Ocvirk): W = mu omega R L^3 eps / (4 c^2 (1 - eps^2)^2) sqrt(16 eps^2 + pi^2 (1 - eps^2)),
  attitude angle tan(phi) = pi sqrt(1 - eps^2) / (4 eps), measured from the load line in the sense of
  rotation (textbook formulas, solved here by brentq);
- pure squeeze: a journal that does not turn falls along the load line, a one-degree-of-freedom
  motion m c eps'' = W - F_sq(eps, eps') with the short half-film squeeze force written here
  (mu R L^3 eps' [(1 + 2 eps^2)(pi - acos eps) + 3 eps sqrt(1 - eps^2)] / (c^2 (1 - eps^2)^(5/2)),
  checked against a finite-difference Reynolds solution in tests/test_contact_hydrodynamic.py),
  integrated by scipy;
- the regime switches are roots: at each one the minimum film thickness equals its threshold
  (the time error, gap / gap rate, below 1e-9 relative);
- energy: mechanical energy minus the work of the film and contact forces (track_work) is constant.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import daeclear as dc
from daeclear.contact import HydrodynamicBearing, Material
from daeclear.model.mechanisms import slider_crank

STEEL = Material(young=207e9, poisson=0.3)
R, C, L, G = 0.01, 5.0e-5, 0.01, 9.81
R_J = R - C  # the film forces take the journal's radius


def journal(mu: float, omega: float, mass: float, driven: bool = False, **law: float | str) -> dc.Scene:
    """A journal (centre of mass at its centre) in a bearing on the ground, under gravity, spinning at omega
    (``driven``: kept at omega by a driver ``spin``, against the film's shear)."""
    scene = dc.Scene("journal", gravity=(0.0, -G))
    body = scene.add(dc.Body("journal", mass=mass, inertia=1e-4, position=(0.0, 0.0), angular_velocity=omega))
    scene.add(dc.RevoluteClearance("bearing", scene.ground, body, at=(0.0, 0.0), bearing_radius=R, clearance=C,
                                   material=STEEL, law=HydrodynamicBearing(viscosity=mu, length=L, **law)))
    if driven:
        scene.add(dc.Driver("spin", joint="bearing", speed=omega))
    return scene


def ocvirk_load(eps: float, mu: float, omega: float) -> float:
    q = 1 - eps**2
    return mu * omega * R_J * L**3 * eps / (4 * C**2 * q**2) * math.sqrt(16 * eps**2 + math.pi**2 * q)


def test_journal_settles_at_the_static_eccentricity_and_attitude_angle() -> None:
    mu, omega, mass = 0.01, 200.0, 4.675
    W = mass * G
    eps = brentq(lambda x: ocvirk_load(x, mu, omega) - W, 1e-6, 1 - 1e-9)
    attitude = math.atan(math.pi * math.sqrt(1 - eps**2) / (4 * eps))
    run = dc.simulate(journal(mu, omega, mass, driven=True), 0.4, rtol=1e-8)
    assert run.success and not run.events  # the film carries throughout
    assert run["bearing.eccentricity_ratio"][-1] == pytest.approx(eps, rel=1e-6)
    angle = math.atan2(run["bearing.ey"][-1], run["bearing.ex"][-1]) + math.pi / 2  # from the load line (-y)
    assert angle == pytest.approx(attitude, rel=1e-6)
    # the film's resultant is the load
    assert math.hypot(run["bearing.film_radial"][-1], run["bearing.film_tangential"][-1]) == pytest.approx(W, rel=1e-6)
    assert np.all(run["bearing.regime"] == 0.0)
    # the journal's friction torque (Hamrock, Fundamentals of Fluid Film Lubrication, short bearing):
    # Petroff's 2 pi mu R^3 L omega / (c sqrt(1 - eps^2)) plus e W sin(attitude) / 2; the driver supplies it
    friction = (2 * math.pi * mu * R_J**3 * L * omega / (C * math.sqrt(1 - eps**2))
                + C * eps * W * math.sin(attitude) / 2)
    assert run["spin.moment"][-1] == pytest.approx(friction, rel=1e-6)
    assert run["bearing.film_torque"][-1] == pytest.approx(-friction, rel=1e-6)
    # the film's net power is its dissipation, here the driver's power: moment x omega
    assert run["bearing.film_dissipation"][-1] == pytest.approx(friction * omega, rel=1e-6)


def test_finite_bearing_settles_at_butenschoens_eccentricity_and_angle() -> None:
    """B/D = 1/2 (L = R_j): the load that Butenschoen's table carries at eps = 0.8 (So = 1.7339,
    beta = 32.938 deg, So = W psi^2 / (B D mu omega), psi = c / R_j)."""
    mu, omega = 0.01, 200.0
    W = 1.7339 * R_J * 2 * R_J * mu * omega / (C / R_J) ** 2
    scene = dc.Scene("journal", gravity=(0.0, -G))
    body = scene.add(dc.Body("journal", mass=W / G, inertia=1e-4, position=(0.0, 0.0), angular_velocity=omega))
    scene.add(dc.RevoluteClearance("bearing", scene.ground, body, at=(0.0, 0.0), bearing_radius=R, clearance=C,
                                   material=STEEL, law=HydrodynamicBearing(viscosity=mu, length=R_J, theory="finite")))
    scene.add(dc.Driver("spin", joint="bearing", speed=omega))  # against the film's shear
    run = dc.simulate(scene, 0.4, rtol=1e-8)
    assert run.success and not run.events
    assert run["bearing.eccentricity_ratio"][-1] == pytest.approx(0.8, rel=1e-5)
    angle = math.atan2(run["bearing.ey"][-1], run["bearing.ex"][-1]) + math.pi / 2
    assert math.degrees(angle) == pytest.approx(32.938, abs=1e-3)


def squeeze_force(eps: float, eps_dot: float, mu: float) -> float:
    q = 1 - eps**2
    if eps_dot <= 0:  # the film opening (not reached while falling)
        raise AssertionError("the reference covers the closing film only")
    return (mu * R_J * L**3 * eps_dot * ((1 + 2 * eps**2) * (math.pi - math.acos(eps)) + 3 * eps * math.sqrt(q))
            / (C**2 * q**2.5))


def test_pure_squeeze_fall_against_the_one_degree_of_freedom_solution() -> None:
    mu, mass = 0.02, 2.0
    run = dc.simulate(journal(mu, 0.0, mass), 0.05, rtol=1e-9, atol=1e-13,
                      save=dc.SaveAt(times=np.linspace(0.0, 0.05, 51)))
    assert run.success and not run.events

    def rhs(t: float, x: np.ndarray) -> list[float]:
        eps, rate = x
        force = squeeze_force(eps, rate, mu) if rate > 0 else 0.0
        return [rate, (mass * G - force) / (mass * C)]

    ref = solve_ivp(rhs, (0.0, 0.05), [0.0, 0.0], t_eval=run.t, rtol=1e-11, atol=1e-13, method="LSODA")
    eps = run["bearing.eccentricity_ratio"]
    assert eps[-1] > 0.5  # the film has been squeezed far
    np.testing.assert_allclose(eps[5:], ref.y[0][5:], rtol=2e-4)
    np.testing.assert_allclose(run["bearing.ex"], 0.0, atol=1e-15)  # straight down the load line
    np.testing.assert_allclose(run["bearing.film_tangential"], 0.0, atol=1e-9)


#: The breaking run's journal (kg). The asperities carry 68 N at the breakdown (Lambda = 1, roughness
#: 2 um): a 2 kg journal (19.6 N) comes to rest on them after three bounces; a 5 kg one (49 N) goes on
#: breaking through, bouncing dry several times in one dry regime and the film forming again between.
BREAKING_MASS = 5.0


@pytest.fixture(scope="module")
def breaking_run() -> dc.Result:
    """A film as thin as air's (1.8e-5 Pa s): it breaks, the journal hits the bearing dry, bounces, and
    the film forms again, a few times."""
    return dc.simulate(journal(1.8e-5, 0.0, BREAKING_MASS, roughness=2e-6, hysteresis=1.0), 0.03, rtol=1e-10,
                       options=dc.SolverOptions(track_work=True))


def test_transitions_are_located_roots_with_hysteresis(breaking_run: dc.Result) -> None:
    run = breaking_run
    regime = run.events.of("bearing.regime")
    kinds = [event.kind for event in regime]
    assert run.success and kinds[:2] == ["onset", "separation"] and len(kinds) >= 4
    assert all(a != b for a, b in zip(kinds, kinds[1:]))  # film and dry alternate
    for event in regime:
        x, y = event.y[0], event.y[1]  # the journal body is (x, y, phi), its centre the joint point
        vx, vy = event.y[3], event.y[4]
        e = math.hypot(x, y)
        level = 2e-6 if event.kind == "onset" else 4e-6  # the break, the re-formation threshold
        film, film_rate = C - e, -(x * vx + y * vy) / e
        assert (film - level) / film_rate == pytest.approx(0.0, abs=1e-9 * event.t)  # time error of the root
    regime = run["bearing.regime"]
    assert set(np.unique(regime)) == {0.0, 1.0}
    film = run["bearing.film_thickness"]
    assert np.all(film[regime == 0.0] > 2e-6 * (1 - 1e-6))  # the film carries only while thick enough
    assert np.all(run["bearing.film_radial"][regime == 1.0] == 0.0)
    assert np.all(run["bearing.normal_force"][regime == 0.0] == 0.0)
    assert run["bearing.normal_force"].max() > 0.0  # a dry impact happened


def lankarani_exit_speed(speed: float, mass: float, stiffness: float, restitution: float) -> float:
    """The separation speed of a journal of ``mass`` hitting its bearing straight down at ``speed``
    under gravity, by a 1-DOF integration of m delta'' = m g - K delta^1.5 (1 + 3 (1 - c_e^2) / 4
    delta' / speed) (scipy): the Lankarani-Nikravesh law with the impact's own approach speed."""
    h = 0.75 * (1 - restitution**2)

    def rhs(t: float, x: np.ndarray) -> list[float]:
        d, v = x
        force = stiffness * max(d, 0.0) ** 1.5 * (1 + h * v / speed)
        return [v, G - max(force, 0.0) / mass]

    def out(t: float, x: np.ndarray) -> float:
        return x[0] if t > 0 else 1.0
    out.terminal, out.direction = True, -1  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, speed], events=out, rtol=1e-12, atol=1e-16, method="LSODA")
    return float(-sol.y_events[0][0][1])


def test_every_dry_bounce_latches_its_own_approach_speed(breaking_run: dc.Result) -> None:
    """After the film breaks the journal bounces on the bearing several times; each impact is an onset
    whose approach speed is the journal's speed then (not the breakdown's), and each bounce leaves at
    the speed the dry law gives for that impact alone."""
    run = breaking_run
    dry = [e for e in run.events if e.pair == "bearing"]
    onsets = [e for e in dry if e.kind == "onset"]
    assert len(onsets) >= 4 and [e.kind for e in dry[:2]] == ["onset", "separation"]
    stiffness = journal(1.8e-5, 0.0, BREAKING_MASS)["bearing"].resolved_law().dry.stiffness
    checked = 0
    for onset, separation in zip(dry[::2], dry[1::2]):
        assert (onset.kind, separation.kind) == ("onset", "separation")
        x, y, vx, vy = onset.y[0], onset.y[1], onset.y[3], onset.y[4]
        assert onset.approach_speed == pytest.approx((x * vx + y * vy) / math.hypot(x, y), rel=1e-9)
        assert abs(x) < 1e-9 * C  # straight down: the 1-DOF reference holds
        expected = lankarani_exit_speed(onset.approach_speed, BREAKING_MASS, stiffness, 0.9)
        assert -separation.approach_speed == pytest.approx(expected, rel=1e-5)
        checked += 1
    assert checked >= 4
    # between bounces in the dry regime the journal flies freely: it comes back at the speed it left with
    in_dry = [(a, b) for a, b in zip(dry[1::2], dry[2::2]) if not any(a.t < e.t < b.t for e in run.events.of(
        "bearing.regime"))]
    assert in_dry
    for left, back in in_dry:
        assert back.approach_speed == pytest.approx(-left.approach_speed, rel=1e-6)


def test_the_film_breaks_and_forms_again(breaking_run: dc.Result) -> None:
    """The film re-forms when the gap opens past the band (a located root) and carries again after it."""
    run = breaking_run
    reformed = run.events.of("bearing.regime", kind="separation")
    assert len(reformed) >= 2
    regime = run["bearing.regime"]
    for event in reformed:
        after = np.searchsorted(run.t, event.t, side="right")
        assert regime[after] == 0.0 and run["bearing.film_radial"][after] != 0.0
        assert run["bearing.in_contact"][after] == 0.0


def test_energy_balance_with_film_dissipation(breaking_run: dc.Result) -> None:
    run = breaking_run
    balance = run["energy.mechanical"] - run["energy.work"]
    scale = np.ptp(run["energy.mechanical"])
    assert scale > 0 and np.ptp(balance) < 1e-6 * scale
    # the film's losses: its power integrated is the work the film took from the falling journal
    lost = np.trapezoid(run["bearing.film_dissipation"], run.t)
    assert lost > 0.0


def test_slider_crank_with_a_lubricated_joint_runs() -> None:
    scene = slider_crank("revolute", law=HydrodynamicBearing(viscosity=0.04, length=0.02))
    run = dc.simulate(scene, 0.012, rtol=1e-6)
    assert run.success and not run.events  # at 40 mPa s the film carries the rod at 5000 rpm
    assert 0.5 < run["clearance.eccentricity_ratio"].max() < 1.0
    dry = dc.simulate(slider_crank("revolute"), 0.012, rtol=1e-6)
    assert len(dry.events) > 2  # the dry joint's journal hits the bearing


def test_bad_lubricated_joints() -> None:
    with pytest.raises(dc.SceneError, match=r"film_parameter \* roughness \* \(1 \+ hysteresis\)=5.4e-05 m, must be "
                                            r"< the radial clearance 5e-05 m"):
        dc.assemble(journal(0.01, 10.0, 1.0, film_parameter=3.0, roughness=6e-6, hysteresis=2.0))
    with pytest.raises(dc.SceneError, match=r"roughness=1e-05 m, must be < the radial clearance / 8"):
        dc.assemble(journal(0.01, 10.0, 1.0, roughness=1e-5, film_parameter=0.5, hysteresis=0.5))
    with pytest.raises(dc.SceneError, match="must be a normal contact law"):
        dc.assemble(slider_crank("translational", law=HydrodynamicBearing(viscosity=0.01, length=0.01)))


def test_scene_file_with_a_lubricated_joint(tmp_path) -> None:
    from daeclear.model.scenefile import read_scene_file

    path = tmp_path / "journal.toml"
    path.write_text("""
[scene]
name = "journal"
gravity = [0.0, -9.81]

[[body]]
name = "journal"
mass = 4.675
inertia = 1e-4
position = [0.0, 0.0]
angular_velocity = 200.0

[[revolute_clearance]]
name = "bearing"
body_i = "ground"
body_j = "journal"
at = [0.0, 0.0]
bearing_radius = 0.01
clearance = 5e-5
material = { young = 207e9, poisson = 0.3 }
law = { name = "hydrodynamic", viscosity = 0.01, length = 0.01, dry = { name = "hertz" } }
""")
    law = read_scene_file(path).scene["bearing"].law
    assert law == HydrodynamicBearing(viscosity=0.01, length=0.01, dry=dc.contact.Hertz())
    path.write_text(path.read_text().replace("length = 0.01,", "lenght = 0.01,"))
    with pytest.raises(dc.SceneError, match="unknown parameter.s. lenght"):
        read_scene_file(path)


def test_example_lubricated_joint_quick(tmp_path) -> None:
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "lubricated_joint.py"
    spec = importlib.util.spec_from_file_location("example_lubricated_joint", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    lines = module.main(["--quick", "--out", str(tmp_path)])
    for name in ("lubricated_joint.png", "viscosity_sweep.png"):
        assert (tmp_path / name).stat().st_size > 5_000
    rows = {line.split("|")[0].strip(): line for line in lines if "|" in line}
    assert int(rows["mu=0.1"].split("|")[2]) == 0  # the reference oil carries the joint
    assert int(rows["mu=0.006"].split("|")[2]) >= 1  # the thinnest one breaks down


def test_command_line_with_a_lubricant(tmp_path) -> None:
    from daeclear.cli import main

    law = "law={'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01, 'roughness': 2e-6}"
    assert main(["run", "slider_crank", "--joint", "revolute", "--set", law, "--t-end", "0.003", "--out",
                 str(tmp_path), "--no-figure", "--quiet"]) == 0
    result = dc.load(tmp_path / "slider_crank_revolute.h5")
    assert result.success and result["clearance.regime"].max() == 0.0
    assert result["clearance.film_radial"].max() > 0.0


# ---------------------------------------------------------------- the bearing's rotation in the wedge (issue 47)
#
# Reynolds' equation in the frame of the line of centres (turning at dgamma/dt): the surfaces slide at
# R (w_journal - dgamma/dt) and R (w_bearing - dgamma/dt), and the pressure's wedge term is their sum,
# so the film's pressure force is the journal's alone at the wedge rate w = w_journal + w_bearing - 2 dgamma/dt.
# Hence: a bearing spinning under a still journal carries it as a journal spinning at the same rate in a
# still bearing; both spinning with the centres still, twice the rate; spinning against each other, no
# wedge; the whole joint turning rigidly (centres included), no film force at all; and the mirror image
# of a spin (-w) mirrors the attitude.
#
# The film's shear (issue 44) acts apart from the pressure: the wall shear mu (U_b - U_j) / h - (h / 2)
# dp/(R dtheta) gives the journal, about its centre, Petroff's Couette torque -2 pi mu R^3 L (w_journal -
# w_bearing) / (c sqrt(1 - eps^2)), which follows the surfaces' *difference*, plus the Poiseuille torque
# -(e / 2) F_t of the pressure (Hamrock, Fundamentals of Fluid Film Lubrication, short bearing); the
# bearing gets +Couette - (e / 2) F_t, so that the film's moments about the bearing's centre balance.


def ring(mu: float, w_bearing: float, w_journal: float, mass: float, gravity: float = G,
         driven: bool = False) -> dc.Scene:
    """A bearing ring pinned to the ground at its centre and spinning at w_bearing; a journal (centre of
    mass at its centre) spinning at w_journal inside it, under gravity (``driven``: the ring kept at
    w_bearing by the driver ``ring_spin`` on the pivot, the journal at w_journal by ``journal_spin`` on
    the clearance joint, at the relative speed w_journal - w_bearing, against the film's shear)."""
    scene = dc.Scene("ring", gravity=(0.0, -gravity))
    bearing = scene.add(dc.Body("ring", mass=1.0, inertia=1e-4, angular_velocity=w_bearing))
    scene.add(dc.Revolute("pivot", scene.ground, bearing, at=(0.0, 0.0)))
    body = scene.add(dc.Body("journal", mass=mass, inertia=1e-4, angular_velocity=w_journal))
    scene.add(dc.RevoluteClearance("bearing", bearing, body, at=(0.0, 0.0), bearing_radius=R, clearance=C,
                                   material=STEEL, law=HydrodynamicBearing(viscosity=mu, length=L)))
    if driven:
        scene.add(dc.Driver("ring_spin", joint="pivot", speed=w_bearing))
        scene.add(dc.Driver("journal_spin", joint="bearing", speed=w_journal - w_bearing))
    return scene


def ocvirk_force(eps: float, mu: float, omega: float) -> tuple[float, float]:
    """Short bearing, half film, rotation part: (F_r, F_t), the force on the journal -F_r n + F_t t
    (n along the eccentricity, t turned +90 deg from it)."""
    q = 1 - eps**2
    return (mu * omega * R_J * L**3 * eps**2 / (C**2 * q**2),
            math.pi * mu * omega * R_J * L**3 * eps / (4 * C**2 * q**1.5))


def petroff_torque(eps: float, mu: float, relative_speed: float) -> float:
    """Petroff's Couette torque of the whole film, 2 pi mu R^3 L (w_journal - w_bearing) / (c sqrt(1 - eps^2))."""
    return 2 * math.pi * mu * R_J**3 * L * relative_speed / (C * math.sqrt(1 - eps**2))


@pytest.mark.parametrize("angle", [-math.pi / 2, 0.7])
def test_film_force_of_the_two_surfaces_rotations(angle: float) -> None:
    """One state each, the film's pressure force on the journal against the closed form at the wedge rate
    the two rotations make (centres still unless said), and its shear torques on the journal and the
    bearing against Petroff's torque of the surfaces' difference plus the pressure's -(e/2) F_t."""
    mu, omega, eps = 0.01, 200.0, 0.6
    model = dc.assemble(ring(mu, 0.0, 0.0, 1.0, gravity=0.0))
    names = model.state_names
    n = np.array([math.cos(angle), math.sin(angle)])
    t = np.array([-n[1], n[0]])
    journal = [names.index(f"journal.{k}") for k in ("x", "y", "phi")]
    bearing = [names.index(f"ring.{k}") for k in ("x", "y", "phi")]
    film = [i for i, term in enumerate(model.terms) if term.name == "bearing.film"]
    assert len(film) == 1

    def forces(w_bearing: float, w_journal: float, centre_velocity=(0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """The film's generalized forces (x, y, phi) on the journal and on the ring."""
        y = np.zeros(model.n_states)
        y[names.index("journal.x")], y[names.index("journal.y")] = eps * C * n
        y[names.index("journal.vx")], y[names.index("journal.vy")] = centre_velocity
        y[names.index("ring.omega")], y[names.index("journal.omega")] = w_bearing, w_journal
        active = [i == film[0] for i in range(len(model.terms))]
        params = [np.zeros(term.n_params) if i == film[0] else np.ones(term.n_params)
                  for i, term in enumerate(model.terms)]
        total = model.term_forces(0.0, y, active, params)
        return total[journal], total[bearing]

    def closed_form(w_bearing: float, w_journal: float) -> tuple[np.ndarray, float, float]:
        """The pressure force on the journal and the shear torques (journal, bearing) about each centre."""
        wedge = w_bearing + w_journal
        F_r, F_t = ocvirk_force(eps, mu, abs(wedge))
        F_t = math.copysign(F_t, wedge)
        couette = petroff_torque(eps, mu, w_journal - w_bearing)
        poiseuille = -0.5 * eps * C * F_t
        return -F_r * n + F_t * t, -couette + poiseuille, couette + poiseuille

    scale = math.hypot(*ocvirk_force(eps, mu, omega))
    torque_scale = petroff_torque(eps, mu, omega)

    def check(w_bearing: float, w_journal: float) -> None:
        (*f_j, m_j), (*f_b, m_b) = forces(w_bearing, w_journal)
        force, torque_j, torque_b = closed_form(w_bearing, w_journal)
        # the pressure's resultant passes through the two centres, equal and opposite on the two bodies
        np.testing.assert_allclose(f_j, force, rtol=0, atol=1e-6 * scale)
        np.testing.assert_allclose(f_b, -force, rtol=0, atol=1e-6 * scale)
        np.testing.assert_allclose([m_j, m_b], [torque_j, torque_b], rtol=0, atol=1e-6 * torque_scale)
        # the film is internal: its moments about the bearing's centre (the journal's centre at e = eps c n) balance
        moment = m_j + m_b + eps * C * (n[0] * f_j[1] - n[1] * f_j[0])
        assert abs(moment) < 1e-9 * torque_scale

    check(0.0, omega)  # the journal spins
    check(omega, 0.0)  # the bearing spins: the same pressure force (the shear's Couette part reversed)
    check(-omega, 0.0)  # the mirror image: the tangential part reversed
    check(omega, omega)  # both, centres still: twice the wedge, no Couette shear
    check(omega, -omega)  # against each other: no wedge, twice the Couette shear
    f_j, f_b = forces(omega, -omega)
    np.testing.assert_allclose(f_j[:2], 0.0, atol=1e-9 * scale)
    np.testing.assert_allclose(f_b[:2], 0.0, atol=1e-9 * scale)
    # the whole joint turning rigidly at omega (the journal's centre too): no relative motion, no film
    rigid_j, rigid_b = forces(omega, omega, omega * eps * C * t)
    assert max(np.max(np.abs(rigid_j[:2])), np.max(np.abs(rigid_b[:2]))) < 1e-6 * scale  # (the film's
    assert max(abs(rigid_j[2]), abs(rigid_b[2])) < 1e-6 * torque_scale  # regularisation leaves 1e-8 eps^-2)


@pytest.mark.parametrize("w_bearing, w_journal, wedge", [(200.0, 0.0, 200.0), (-200.0, 0.0, -200.0),
                                                         (200.0, 200.0, 400.0)])
def test_a_spinning_bearing_carries_the_journal_like_a_spinning_journal(w_bearing: float, w_journal: float,
                                                                          wedge: float) -> None:
    """The ring spins (a journal that does not turn inside it, or turns with it), both kept at their
    speeds by drivers against the film's shear: the journal settles at Ocvirk's static eccentricity and
    attitude angle of the wedge rate w_bearing + w_journal, measured from the load line in the sense of
    that rate (mirrored for -200 rad/s). The drivers' moments: the journal's balances the film's shear
    torque on it, Petroff's of the relative speed plus (e/2) F_t = W e_x / 2 (the film carries the weight:
    F_t = W sin(attitude)); the ring's balances gravity's moment about the pivot, W e_x (statics of the
    whole: the film is internal)."""
    mu, mass = 0.01, 4.675
    W = mass * G
    eps = brentq(lambda x: ocvirk_load(x, mu, abs(wedge)) - W, 1e-6, 1 - 1e-9)
    attitude = math.copysign(math.atan(math.pi * math.sqrt(1 - eps**2) / (4 * eps)), wedge)
    run = dc.simulate(ring(mu, w_bearing, w_journal, mass, driven=True), 0.4, rtol=1e-8)
    assert run.success and not run.events
    assert run["bearing.eccentricity_ratio"][-1] == pytest.approx(eps, rel=1e-6)
    angle = math.atan2(run["bearing.ey"][-1], run["bearing.ex"][-1]) + math.pi / 2  # from the load line (-y)
    assert angle == pytest.approx(attitude, rel=1e-6)
    assert run["ring.omega"][-1] == pytest.approx(w_bearing, abs=1e-9)
    assert run["journal.omega"][-1] == pytest.approx(w_journal, abs=1e-9)
    e_x = eps * C * math.sin(attitude)  # the journal's centre, right of the load line for a positive rate
    journal_moment = petroff_torque(eps, mu, w_journal - w_bearing) + W * e_x / 2
    assert run["journal_spin.moment"][-1] == pytest.approx(journal_moment, rel=1e-6)
    assert run["ring_spin.moment"][-1] == pytest.approx(W * e_x, rel=1e-6)


# ---------------------------------------------------------------- the mixed regime (issue 44)
#
# Below a film parameter h_min / sigma of 4 the asperities touch and carry a share of the load with the film
# (Greenwood and Tripp 1970): mean pressure K E' F_5/2(h / sigma), K = 16 pi sqrt(2) / 15 (eta sigma beta)^2
# sqrt(sigma / beta) with eta sigma beta = 0.04, sigma / beta = 1e-3, and Hu et al.'s (1994) fit F_5/2(x) =
# 4.4086e-5 (4 - x)^6.804; E' the composite modulus, 1 / E' = 2 (1 - nu^2) / E for two steel surfaces. The
# load is that pressure over the journal's length and arc, along the line of centres.

SIGMA = 1e-6  # the default composite roughness, m
E_COMPOSITE = 1.0 / (2 * (1 - 0.3**2) / 207e9)


def greenwood_tripp(film_parameter: float) -> float:
    """The mean asperity pressure (Pa) at h / sigma (written here from the sources)."""
    k = 16 * math.pi * math.sqrt(2) / 15 * 0.04**2 * math.sqrt(1e-3)
    return k * E_COMPOSITE * 4.4086e-5 * max(4.0 - film_parameter, 0.0) ** 6.804


def asperity_reference(eps: float, parabolic: bool) -> float:
    """The asperities' load (N) by quadrature over the arc where h < 4 sigma: the exact film h = c (1 -
    eps cos phi) projected on the line of centres, or (``parabolic``) the film near its minimum, h = c (1 -
    eps) + c eps phi^2 / 2, unprojected (the model's closed form takes that one)."""
    from scipy.integrate import quad

    if parabolic:
        edge = math.sqrt(2 * (4 * SIGMA - C * (1 - eps)) / (C * eps))
        pressure = lambda phi: greenwood_tripp((C * (1 - eps) + C * eps * phi**2 / 2) / SIGMA)  # noqa: E731
    else:
        edge = math.acos((1 - 4 * SIGMA / C) / eps)
        pressure = lambda phi: greenwood_tripp(C * (1 - eps * math.cos(phi)) / SIGMA) * math.cos(phi)  # noqa: E731
    return L * R_J * quad(pressure, -edge, edge, epsabs=0.0, epsrel=1e-12, limit=200)[0]


def test_asperities_carry_their_share_in_the_mixed_regime() -> None:
    """One state each at h_min = 2 sigma (the mixed regime: the film still on, Lambda = 1 breaks it): a
    journal at rest feels the asperities' load alone, towards the bearing's centre; a spinning one
    Ocvirk's film force plus that load, and the film's shear torque (the asperities' friction is not
    modelled)."""
    mu, omega, eps = 0.01, 200.0, 1 - 2 * SIGMA / C
    load = asperity_reference(eps, parabolic=True)
    # the closed form's parabolic film against the exact one: the arc's half-width ~0.2 rad
    assert load == pytest.approx(asperity_reference(eps, parabolic=False), rel=2e-3)
    assert load > 1.0  # a real share (N)
    model = dc.assemble(journal(mu, 0.0, 1.0))
    names = model.state_names
    film = [i for i, term in enumerate(model.terms) if term.name == "bearing.film"]
    coordinates = [names.index(f"journal.{k}") for k in ("x", "y", "phi")]
    angle = 0.7
    n = np.array([math.cos(angle), math.sin(angle)])
    t = np.array([-n[1], n[0]])

    def force(w_journal: float) -> np.ndarray:
        y = np.zeros(model.n_states)
        y[names.index("journal.x")], y[names.index("journal.y")] = eps * C * n
        y[names.index("journal.omega")] = w_journal
        active = [i == film[0] for i in range(len(model.terms))]
        params = [np.zeros(term.n_params) if i == film[0] else np.ones(term.n_params)
                  for i, term in enumerate(model.terms)]
        return model.term_forces(0.0, y, active, params)[coordinates]

    # (the film's regularisation moves h_min by c (1e-4)^2 / (2 eps) ~ 3e-13 m: 1e-6 of the load)
    np.testing.assert_allclose(force(0.0), [*(-load * n), 0.0], rtol=0, atol=1e-5 * load)
    F_r, F_t = ocvirk_force(eps, mu, omega)
    torque = -petroff_torque(eps, mu, omega) - 0.5 * eps * C * F_t
    got = force(omega)
    np.testing.assert_allclose(got[:2], -(F_r + load) * n + F_t * t, rtol=0, atol=1e-6 * math.hypot(F_r, F_t))
    assert got[2] == pytest.approx(torque, rel=1e-6)


def test_a_driven_journal_settles_where_film_and_asperities_carry_its_weight() -> None:
    """A heavy journal kept at 20 rad/s settles in the mixed regime: Ocvirk's film force plus the
    asperities' load along the line of centres balance its weight, |(F_r + W_a) n - F_t t| = W, at the
    attitude tan(phi) = F_t / (F_r + W_a); the driver supplies the film's shear torque, Petroff's plus
    (e/2) F_t = W e_x / 2."""
    mu, omega, mass = 0.01, 20.0, 12.7
    W = mass * G

    def carried(eps: float) -> tuple[float, float]:
        F_r, F_t = ocvirk_force(eps, mu, omega)
        return F_r + (asperity_reference(eps, parabolic=True) if C * (1 - eps) < 4 * SIGMA else 0.0), F_t

    eps = brentq(lambda x: math.hypot(*carried(x)) - W, 0.5, 1 - 1.01 * SIGMA / C, xtol=1e-15, rtol=1e-15)
    radial, tangential = carried(eps)
    assert 1.0 < C * (1 - eps) / SIGMA < 4.0 and radial - ocvirk_force(eps, mu, omega)[0] > 0.01 * W  # mixed
    run = dc.simulate(journal(mu, omega, mass, driven=True), 0.4, rtol=1e-8)
    assert run.success and not run.events
    assert run["bearing.eccentricity_ratio"][-1] == pytest.approx(eps, rel=1e-6)
    angle = math.atan2(run["bearing.ey"][-1], run["bearing.ex"][-1]) + math.pi / 2  # from the load line (-y)
    assert angle == pytest.approx(math.atan2(tangential, radial), rel=1e-6)
    assert run["bearing.asperity_force"][-1] == pytest.approx(radial - ocvirk_force(eps, mu, omega)[0], rel=1e-5)
    e_x = eps * C * tangential / W
    assert run["spin.moment"][-1] == pytest.approx(petroff_torque(eps, mu, omega) + W * e_x / 2, rel=1e-6)


def test_example_viscosity_study_quick(tmp_path) -> None:
    """The viscosity study's script: its table and figure; a thick oil carries the joint below the dry
    joint's peak force, a thin one breaks down."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "lubricated_viscosity_study.py"
    spec = importlib.util.spec_from_file_location("example_viscosity_study", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    lines = module.main(["--quick", "--out", str(tmp_path)])
    assert (tmp_path / "viscosity_study.png").stat().st_size > 5_000
    rows = [[cell.strip() for cell in line.strip("|").split("|")] for line in lines[2:]]
    for c in ("0.1", "0.5"):
        dry = next(float(r[2]) for r in rows if r[0] == c and r[1] == "dry")
        thick = next(r for r in rows if r[0] == c and r[1] == "0.1")
        assert float(thick[2]) < dry and thick[4] == "0"
        assert int(next(r for r in rows if r[0] == c and r[1] == "0.001")[4]) >= 1
