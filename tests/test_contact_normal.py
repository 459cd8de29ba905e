"""Normal contact laws: closed forms, restitution, loops, CasADi agreement, parameters.

Closed-form references (single degree of freedom: mass m hits the law at speed v):

- Hertz, F = K delta^n with n = 3/2. Energy: m v^2/2 = m delta_dot^2/2 + 2 K delta^(5/2)/5, so
  delta_max = (5 m v^2 / (4 K))^(2/5),  F_max = K delta_max^(3/2),
  t_c = 2 (delta_max / v) int_0^1 dx / sqrt(1 - x^(5/2)).
  With s = x^(5/2): int = (2/5) B(2/5, 1/2) = sqrt(pi) Gamma(7/5) / Gamma(9/10), so
  t_c = C delta_max / v with C = 2 sqrt(pi) Gamma(7/5) / Gamma(9/10) = 2.943275...
- Kelvin-Voigt (linear, omega = sqrt(K/m), zeta = D/(2 sqrt(K m)), omega_d = omega sqrt(1-zeta^2)):
  delta(t) = (v/omega_d) exp(-zeta omega t) sin(omega_d t) while K delta + D delta_dot >= 0;
  the clamped force vanishes at the first t* > 0 with K delta + D delta_dot = 0, and the
  mass leaves with speed -delta_dot(t*) (no force after).
- Any law: the loop integral of F d(delta) over the impact equals the kinetic energy lost.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad, trapezoid
from scipy.optimize import brentq
from scipy.special import gamma

from daeclear.contact import (
    KINDS, Flores, Hertz, HuntCrossley, KelvinVoigt, LankaraniNikravesh, LankaraniPlane, Material,
    external_contact_stiffness, internal_contact_stiffness, normal_law, plane_face_stiffness,
    simulate_impact, sphere_plane_stiffness,
)
from daeclear.contact.cylindrical import DubowskyFreudenstein, ESDU78035, Goldsmith
from daeclear.core.errors import SceneError

# ---- closed forms ------------------------------------------------------------------
HERTZ_DURATION_CONSTANT = 2.0 * math.sqrt(math.pi) * gamma(1.4) / gamma(0.9)


def hertz_max_penetration(m: float, v: float, k: float) -> float:
    return (5.0 * m * v**2 / (4.0 * k)) ** 0.4


def hertz_peak_force(m: float, v: float, k: float) -> float:
    return k * hertz_max_penetration(m, v, k) ** 1.5


def hertz_duration(m: float, v: float, k: float) -> float:
    return HERTZ_DURATION_CONSTANT * hertz_max_penetration(m, v, k) / v


def kelvin_voigt_exit_speed(m: float, v: float, k: float, d: float) -> float:
    omega = math.sqrt(k / m)
    zeta = d / (2.0 * math.sqrt(k * m))
    omega_d = omega * math.sqrt(1.0 - zeta**2)

    def delta(t: float) -> float:
        return v / omega_d * math.exp(-zeta * omega * t) * math.sin(omega_d * t)

    def rate(t: float) -> float:
        return v * math.exp(-zeta * omega * t) * (math.cos(omega_d * t)
                                                  - zeta * omega / omega_d * math.sin(omega_d * t))

    t_star = brentq(lambda t: k * delta(t) + d * rate(t), 0.5 * math.pi / omega_d, math.pi / omega_d,
                    xtol=1e-16, rtol=1e-15)
    return -rate(t_star)


STEEL = Material(young=207e9, poisson=0.3)
K_BENCH = 6.61e10  # N/m^1.5, journal 9.5 mm in bearing 10 mm, steel

#: Effective restitution exit/entry speed measured with simulate_impact (rtol 1e-12); it
#: depends on c_e only (checked below). Reported in docs/contact_laws.md.
MEASURED_RESTITUTION = {
    (LankaraniNikravesh, 0.5): 0.7252411, (LankaraniNikravesh, 0.9): 0.9131767,
    (LankaraniNikravesh, 0.95): 0.9535060, (LankaraniNikravesh, 0.99): 0.9901479,
    (HuntCrossley, 0.5): 0.6629622, (HuntCrossley, 0.9): 0.9090157,
    (HuntCrossley, 0.95): 0.9523702, (HuntCrossley, 0.99): 0.9900989,
    (Flores, 0.5): 0.4704448, (Flores, 0.9): 0.8939207,
    (Flores, 0.95): 0.9468288, (Flores, 0.99): 0.9893403,
}

#: Accuracy |e_eff / c_e - 1| each law is known for, as asserted (smallest bound that holds).
KNOWN_ACCURACY = {
    (LankaraniNikravesh, 0.9): 0.015, (LankaraniNikravesh, 0.95): 0.004, (LankaraniNikravesh, 0.99): 2e-4,
    (HuntCrossley, 0.9): 0.011, (HuntCrossley, 0.95): 0.003, (HuntCrossley, 0.99): 1e-4,
    (Flores, 0.5): 0.06, (Flores, 0.9): 0.007, (Flores, 0.95): 0.004, (Flores, 0.99): 7e-4,
}


# ---- Hertz ---------------------------------------------------------------------------
def test_hertz_duration_constant() -> None:
    # int_0^1 dx / sqrt(1 - x^(5/2)) by quadrature, singularity at x = 1 handled by quad's weight
    def smooth_part(x: float) -> float:  # 1/sqrt((1 - x^2.5)/(1 - x)), limit 1/sqrt(2.5) at x = 1
        return 1.0 / math.sqrt((1.0 - x**2.5) / (1.0 - x)) if x < 1.0 else 1.0 / math.sqrt(2.5)

    integral, _ = quad(smooth_part, 0.0, 1.0, weight="alg", wvar=(0.0, -0.5), epsabs=1e-14, epsrel=1e-14)
    assert 2.0 * integral == pytest.approx(HERTZ_DURATION_CONSTANT, rel=1e-12)
    assert HERTZ_DURATION_CONSTANT == pytest.approx(2.94328, abs=1e-5)


@pytest.mark.parametrize(("m", "v", "k"), [(1.0, 1.0, K_BENCH), (0.14, 3.7, 4.80e9), (0.21, 0.05, 1.5e11)])
def test_hertz_impact_matches_closed_form(m: float, v: float, k: float) -> None:
    result = simulate_impact(Hertz(stiffness=k, exponent=1.5), mass=m, speed=v)
    assert result.max_penetration == pytest.approx(hertz_max_penetration(m, v, k), rel=1e-6)
    assert result.peak_force == pytest.approx(hertz_peak_force(m, v, k), rel=1e-6)
    assert result.duration == pytest.approx(hertz_duration(m, v, k), rel=1e-6)
    assert result.time_of_max_penetration == pytest.approx(result.duration / 2.0, rel=1e-6)
    assert result.restitution == pytest.approx(1.0, abs=1e-9)


def test_hertz_anchor_forces() -> None:
    law = Hertz(stiffness=K_BENCH)
    for delta, force in [(1e-6, 66.1), (5e-6, 739.0), (10e-6, 2090.0), (20e-6, 5912.0)]:
        assert law.force(delta) == pytest.approx(force, rel=2e-4)


# ---- damped laws -----------------------------------------------------------------------
@pytest.mark.parametrize(("cls", "c_e"), sorted(MEASURED_RESTITUTION, key=lambda key: (key[0].name, key[1])),
                         ids=lambda x: getattr(x, "name", str(x)))
def test_effective_restitution(cls: type, c_e: float) -> None:
    result = simulate_impact(cls(restitution=c_e, stiffness=K_BENCH), mass=1.0, speed=1.0)
    assert result.restitution == pytest.approx(MEASURED_RESTITUTION[cls, c_e], abs=2e-7)
    if (cls, c_e) in KNOWN_ACCURACY:
        assert abs(result.restitution / c_e - 1.0) <= KNOWN_ACCURACY[cls, c_e]


def test_restitution_known_behaviour_at_low_restitution() -> None:
    # LN and HC were derived near c_e = 1: at 0.5 they under-predict the loss badly; Flores does not.
    errors = {cls: simulate_impact(cls(restitution=0.5, stiffness=K_BENCH), mass=1.0, speed=1.0).restitution / 0.5
              - 1.0 for cls in (LankaraniNikravesh, HuntCrossley, Flores)}
    assert errors[LankaraniNikravesh] > 0.4 and errors[HuntCrossley] > 0.3
    assert abs(errors[Flores]) < 0.06


@pytest.mark.parametrize("cls", [LankaraniNikravesh, HuntCrossley, Flores])
def test_restitution_depends_on_c_e_only(cls: type) -> None:
    a = simulate_impact(cls(restitution=0.9, stiffness=K_BENCH), mass=1.0, speed=1.0)
    b = simulate_impact(cls(restitution=0.9, stiffness=4.8e9), mass=0.14, speed=3.7)
    assert a.restitution == pytest.approx(b.restitution, abs=1e-9)


@pytest.mark.parametrize("cls", [LankaraniNikravesh, HuntCrossley, Flores])
def test_restitution_one_is_hertz_exactly(cls: type) -> None:
    law = cls(restitution=1.0, stiffness=K_BENCH)
    hertz = Hertz(stiffness=K_BENCH)
    delta = np.linspace(-1e-5, 3e-5, 101)
    rate = np.linspace(-2.0, 2.0, 101)
    assert np.array_equal(law.force(delta, rate, 0.7), hertz.force(delta))
    assert not law.dissipative and not law.needs_approach_speed
    assert law.force(1e-5) == hertz.force(1e-5)  # no approach speed needed
    a, b = (simulate_impact(x, mass=0.2, speed=0.8) for x in (law, hertz))
    assert a.exit_speed == pytest.approx(b.exit_speed, rel=1e-12)
    assert a.peak_force == pytest.approx(b.peak_force, rel=1e-12)


@pytest.mark.parametrize(("law", "rel"), [
    (LankaraniNikravesh(restitution=0.9, stiffness=K_BENCH), 1e-6),
    (LankaraniNikravesh(restitution=0.95, stiffness=K_BENCH), 1e-6),
    (HuntCrossley(restitution=0.8, stiffness=K_BENCH), 1e-6), (Flores(restitution=0.5, stiffness=K_BENCH), 1e-6),
    # KV: force jumps to D v at onset and has a kink where it is clamped: trapezoid is first order there
    (KelvinVoigt(stiffness=1e9, damping=2e4), 3e-4)], ids=lambda x: getattr(x, "name", ""))
def test_hysteresis_loop_area_is_energy_lost(law, rel: float) -> None:
    result = simulate_impact(law, mass=1.0, speed=1.0, n_points=20001)
    loop = trapezoid(result.force, result.penetration)  # clockwise loop: compression minus restitution work
    assert result.energy_lost > 0.0
    assert loop == pytest.approx(result.energy_lost, rel=rel)


def test_kelvin_voigt_exit_speed_matches_closed_form() -> None:
    m, v, k, d = 0.5, 1.2, 2e8, 3e3
    result = simulate_impact(KelvinVoigt(stiffness=k, damping=d), mass=m, speed=v)
    assert result.exit_speed == pytest.approx(kelvin_voigt_exit_speed(m, v, k, d), rel=1e-8)


def test_damped_laws_never_pull_and_floor_approach_speed() -> None:
    law = LankaraniNikravesh(restitution=0.3, stiffness=K_BENCH)
    # bracket 1 + h delta_dot / v_minus < 0 for fast restitution: clamped to 0
    assert law.force(1e-5, -10.0, 1.0) == 0.0
    assert KelvinVoigt(stiffness=1e9, damping=1e5).force(1e-6, -1.0) == 0.0
    # approach speed floored at min_approach_speed (default 1e-4 m/s): 0, negative and tiny agree
    forces = [law.force(1e-6, 1e-3, v) for v in (0.0, -1.0, 1e-12, 1e-4)]
    assert all(np.isfinite(forces)) and len(set(forces)) == 1
    floored = LankaraniNikravesh(restitution=0.9, stiffness=K_BENCH, min_approach_speed=1e-2)
    assert floored.force(1e-6, 1e-3, 0.0) == floored.force(1e-6, 1e-3, 1e-2) != floored.force(1e-6, 1e-3, 2e-2)


def test_zero_force_without_contact() -> None:
    for law in [Hertz(stiffness=K_BENCH), LankaraniNikravesh(restitution=0.9, stiffness=K_BENCH),
                KelvinVoigt(stiffness=1e9, damping=1e4), LankaraniPlane(stiffness=6e9)]:
        out = law.force(np.array([-1.0, -1e-9, 0.0]), np.array([5.0, -5.0, 5.0]), 1.0)
        assert np.array_equal(out, np.zeros(3))


def test_float_in_float_out_and_broadcasting() -> None:
    law = LankaraniNikravesh(restitution=0.9, stiffness=K_BENCH)
    assert type(law.force(1e-6, 0.1, 1.0)) is float
    out = law.force(np.linspace(0, 1e-5, 5)[:, None], np.array([0.0, 0.5]), 1.0)
    assert out.shape == (5, 2)


# ---- CasADi: same numbers, finite Jacobian -----------------------------------------
def _resolved_laws():
    geo = dict(radii=(10e-3, 9.5e-3), materials=STEEL)
    laws = [Hertz(), LankaraniNikravesh(restitution=0.9), HuntCrossley(restitution=0.8), Flores(restitution=0.5),
            DubowskyFreudenstein(length=0.01), Goldsmith(length=0.01), ESDU78035(length=0.01),
            ESDU78035(length=0.02, sigma_convention="plain")]
    laws = [law.resolve("internal_cylinder", **geo) for law in laws]
    laws += [LankaraniNikravesh(restitution=0.9).resolve("sphere_plane", radii=(1e-3,), materials=STEEL),
             LankaraniNikravesh(restitution=0.9).resolve("plane_face", face_half_width=0.025, materials=STEEL),
             KelvinVoigt(damping=1e4).resolve("plane_face", face_half_width=0.025, materials=STEEL),
             LankaraniPlane().resolve("plane_face", face_half_width=0.025, materials=STEEL)]
    return laws


LAWS = _resolved_laws()
DELTA = np.concatenate([[-1e-3, -1e-9, -1e-300, 0.0, 1e-300, 1e-100], np.logspace(-12, -4.5, 40)])
RATE = np.resize([-1.0, -0.3, 0.0, 0.2, 1.5], DELTA.size)
V_MINUS = np.resize([1.0, 0.0, 0.5, 2e-5], DELTA.size)


@pytest.mark.parametrize("symbol", [ca.SX, ca.MX], ids=["SX", "MX"])
@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.name)
def test_casadi_matches_numpy(law, symbol) -> None:
    d, r, v = symbol.sym("d"), symbol.sym("r"), symbol.sym("v")
    f_sym = law.force(d, r, v)
    jac = ca.jacobian(f_sym, ca.vertcat(d, r))
    fun = ca.Function("f", [d, r, v], [f_sym, jac])
    values, jacobians = [], []
    for x, y, z in zip(DELTA, RATE, V_MINUS):
        f, j = fun(x, y, z)
        values.append(float(f))
        jacobians.append(np.array(j).ravel())
    numeric = law.force(DELTA, RATE, V_MINUS)
    np.testing.assert_allclose(values, numeric, rtol=1e-14, atol=0.0)
    jacobians = np.array(jacobians)
    assert np.all(np.isfinite(jacobians))
    assert np.all(jacobians[DELTA < 0] == 0.0)
    assert np.all(np.array(values)[DELTA <= 0] == 0.0)
    # Jacobian against central differences of the numeric path, inside contact
    for i in np.flatnonzero(DELTA > 1e-9)[::4]:
        h = 1e-6 * DELTA[i]
        fd = (law.force(DELTA[i] + h, RATE[i], V_MINUS[i]) - law.force(DELTA[i] - h, RATE[i], V_MINUS[i])) / (2 * h)
        assert jacobians[i, 0] == pytest.approx(fd, rel=1e-6)


# ---- materials and stiffness --------------------------------------------------------
@pytest.mark.parametrize(("clearance", "k_expected"),
                         [(0.5e-3, 6.610e10), (0.2e-3, 1.062e11), (0.1e-3, 1.509e11), (0.01e-3, 4.793e11)])
def test_internal_journal_bearing_stiffness(clearance: float, k_expected: float) -> None:
    k = internal_contact_stiffness(10e-3, 10e-3 - clearance, STEEL)
    assert k == pytest.approx(k_expected, rel=5e-4)


def test_other_stiffness_anchors() -> None:
    assert STEEL.sigma == pytest.approx(4.396e-12, rel=1e-4, abs=0.0)
    assert sphere_plane_stiffness(1e-3, STEEL) == pytest.approx(4.80e9, rel=1e-3)
    assert plane_face_stiffness(0.025, (STEEL, STEEL)) == pytest.approx(5.99e9, rel=1e-3)
    # external: equal spheres of 2R behave like R on a plane
    assert external_contact_stiffness(2e-3, 2e-3, STEEL) == pytest.approx(sphere_plane_stiffness(1e-3, STEEL))


def test_resolve_protocol() -> None:
    ln = LankaraniNikravesh(restitution=0.9)
    assert not ln.is_resolved and ln.geometry == "sphere" and set(ln.supported_kinds) == set(KINDS)
    bearing = ln.resolve("internal_cylinder", radii=(10e-3, 9.5e-3), materials=(STEEL, STEEL))
    assert bearing.is_resolved and bearing.exponent == 1.5
    assert bearing.stiffness == pytest.approx(6.610e10, rel=5e-4)
    corner = ln.resolve("sphere_plane", radii=1e-3, materials=STEEL)
    assert corner.stiffness == pytest.approx(4.80e9, rel=1e-3) and corner.exponent == 1.5
    face = ln.resolve("plane_face", face_half_width=0.025, materials=STEEL)
    assert face.stiffness == pytest.approx(5.99e9, rel=1e-3) and face.exponent == 1.0
    assert ln.resolve("plane_face", face_half_width=0.025, materials=STEEL).restitution == 0.9
    # user values are never overridden; resolving twice is harmless
    given = Hertz(stiffness=1e10).resolve("internal_cylinder", radii=(10e-3, 9.5e-3), materials=STEEL)
    assert given.stiffness == 1e10 and given.resolve("sphere_plane") == given
    assert ln.with_stiffness(2e10).stiffness == 2e10
    plane = LankaraniPlane().resolve("plane_face", face_half_width=0.025, materials=STEEL)
    assert plane.force(1e-6) == pytest.approx(5.99e3, rel=1e-3)


def test_metadata() -> None:
    expected = {  # name, dissipative, needs_approach_speed
        Hertz(stiffness=1.0): ("hertz", False, False),
        KelvinVoigt(stiffness=1.0, damping=1.0): ("kelvin-voigt", True, False),
        KelvinVoigt(stiffness=1.0): ("kelvin-voigt", False, False),
        HuntCrossley(restitution=0.9): ("hunt-crossley", True, True),
        LankaraniNikravesh(restitution=0.9): ("lankarani-nikravesh", True, True),
        Flores(restitution=0.9): ("flores", True, True),
        DubowskyFreudenstein(length=0.01): ("dubowsky-freudenstein", False, False),
        Goldsmith(length=0.01): ("goldsmith", False, False),
        ESDU78035(length=0.01): ("esdu-78035", False, False),
        LankaraniPlane(): ("lankarani-plane", False, False),
    }
    for law, (name, dissipative, needs_speed) in expected.items():
        assert (law.name, law.dissipative, law.needs_approach_speed) == (name, dissipative, needs_speed)


@pytest.mark.parametrize(("name", "cls"), [
    ("lankarani-nikravesh", LankaraniNikravesh), ("Lankarani_Nikravesh", LankaraniNikravesh),
    ("lankarani nikravesh", LankaraniNikravesh), ("LN", LankaraniNikravesh), ("HERTZ", Hertz),
    ("hunt_crossley", HuntCrossley), ("flores", Flores), ("Kelvin Voigt", KelvinVoigt),
    ("dubowsky-freudenstein", DubowskyFreudenstein), ("goldsmith", Goldsmith), ("ESDU 78035", ESDU78035),
    ("esdu_78035", ESDU78035), ("lankarani-plane", LankaraniPlane)])
def test_normal_law_registry(name: str, cls: type) -> None:
    params = {LankaraniNikravesh: {"restitution": 0.9}, HuntCrossley: {"restitution": 0.9},
              Flores: {"restitution": 0.9}, DubowskyFreudenstein: {"length": 0.01}, Goldsmith: {"length": 0.01},
              ESDU78035: {"length": 0.01}}.get(cls, {})
    assert type(normal_law(name, **params)) is cls


def test_normal_law_registry_errors() -> None:
    with pytest.raises(SceneError, match="unknown name 'lankarani'.*lankarani-nikravesh.*esdu-78035"):
        normal_law("lankarani")
    with pytest.raises(SceneError, match="missing required parameter.*restitution"):
        normal_law("flores")
    with pytest.raises(SceneError, match="unknown parameter.*damping.*valid: stiffness"):
        normal_law("hertz", damping=1.0)


# ---- bad parameters -----------------------------------------------------------------
@pytest.mark.parametrize(("make", "pattern"), [
    (lambda: LankaraniNikravesh(restitution=1.2), r"LankaraniNikravesh: restitution=1.2, must be in \(0, 1\]"),
    (lambda: Flores(restitution=0.0), r"Flores: restitution=0, must be in \(0, 1\]"),
    (lambda: HuntCrossley(restitution=0.9, min_approach_speed=0.0), r"min_approach_speed=0 m/s, must be > 0"),
    (lambda: Hertz(stiffness=-1.0), r"Hertz: stiffness=-1, must be > 0"),
    (lambda: Hertz(stiffness=1e10, exponent=0.5), r"Hertz: exponent=0.5, must be in \[1, 10\]"),
    (lambda: Hertz(stiffness="big"), r"Hertz: stiffness='big' is not a real number"),
    (lambda: KelvinVoigt(stiffness=1e9, damping=-1.0), r"KelvinVoigt: damping=-1 N s/m, must be >= 0"),
    (lambda: Material(young=-1.0, poisson=0.3), r"Material: young=-1 Pa, must be > 0"),
    (lambda: Material(young=207e9, poisson=0.5), r"Material: poisson=0.5, must be in \(-1, 0.5\)"),
    (lambda: internal_contact_stiffness(9e-3, 10e-3, STEEL), r"journal_radius=0.01 m, must be < bearing_radius"),
    (lambda: plane_face_stiffness(0.0, STEEL), r"half_width=0 m, must be > 0"),
])
def test_bad_parameters_raise(make, pattern: str) -> None:
    with pytest.raises(SceneError, match=pattern):
        make()


def test_resolve_and_evaluation_errors() -> None:
    ln = LankaraniNikravesh(restitution=0.9)
    with pytest.raises(SceneError, match="kind='journal'.*valid kinds"):
        ln.resolve("journal", radii=(1.0, 0.5), materials=STEEL)
    with pytest.raises(SceneError, match="materials=None"):
        ln.resolve("internal_cylinder", radii=(10e-3, 9.5e-3))
    with pytest.raises(SceneError, match=r"radii=\(0.0095, 0.01\) m, must satisfy bearing_radius > journal_radius"):
        ln.resolve("internal_cylinder", radii=(9.5e-3, 10e-3), materials=STEEL)
    with pytest.raises(SceneError, match="face_half_width=None"):
        ln.resolve("plane_face", materials=STEEL)
    with pytest.raises(SceneError, match="exponent=1.5 with kind='plane_face'"):
        LankaraniNikravesh(restitution=0.9, exponent=1.5).resolve("plane_face", face_half_width=0.025,
                                                                   materials=STEEL)
    with pytest.raises(SceneError, match="KelvinVoigt: stiffness=None cannot be computed for kind='internal_cylinder'"):
        KelvinVoigt().resolve("internal_cylinder", radii=(10e-3, 9.5e-3), materials=STEEL)
    with pytest.raises(SceneError, match="not resolved"):
        ln.force(1e-6, 0.0, 1.0)
    with pytest.raises(TypeError, match="approach_speed"):
        ln.with_stiffness(1e10).force(1e-6, 0.0)
    with pytest.raises(TypeError, match="penetration_rate"):
        ln.with_stiffness(1e10).force(1e-6)


def test_contact_force_is_the_limit_from_inside_the_contact() -> None:
    """A term on at its onset root (delta = 0) reads the force's limit from inside: Kelvin-Voigt's jump D delta_dot
    (the law's own value there is 0, as out of contact); a law continuous at delta = 0 reads its force."""
    kv = KelvinVoigt(stiffness=1e9, damping=1e4)
    assert kv.force(0.0, 5.0) == 0.0 and kv.contact_force(0.0, 5.0) == 1e4 * 5.0
    assert kv.contact_force(1e-9, -5.0) == 0.0 and kv.contact_force(-1e-9, 5.0) == 0.0  # clamped; outside
    assert kv.contact_force(2e-6, 1.0) == kv.force(2e-6, 1.0) == pytest.approx(1e9 * 2e-6 + 1e4)
    for law in [Hertz(stiffness=K_BENCH), LankaraniNikravesh(restitution=0.9, stiffness=K_BENCH),
                LankaraniPlane(stiffness=6e9)]:
        delta = np.array([-1e-9, 0.0, 1e-6])
        assert np.array_equal(law.contact_force(delta, 5.0, 1.0), law.force(delta, 5.0, 1.0))
