"""Friction laws: modified Coulomb (eq. 3.16) shape, sign, power, CasADi, registry.

Reference (Ambrosio 2002, eq. 3.16): F_T = -c_f c_d(|v|) F_N sign(v) with
c_d = 0 for |v| <= v0, (|v| - v0)/(v1 - v0) for v0 < |v| < v1, 1 for |v| >= v1.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from daeclear.contact import Coulomb, ModifiedCoulomb, NoFriction, friction_law
from daeclear.core.errors import SceneError


def reference_modified_coulomb(c_f: float, f_n: float, v: float, v0: float, v1: float) -> float:
    speed = abs(v)
    c_d = 0.0 if speed <= v0 else 1.0 if speed >= v1 else (speed - v0) / (v1 - v0)
    return -c_f * c_d * f_n * float(np.sign(v))


def test_defaults() -> None:
    law = ModifiedCoulomb(coefficient=0.1)
    assert (law.v0, law.v1) == (1e-4, 2e-4)
    assert law.smooth and law.name == "modified-coulomb" and not law.frictionless


@pytest.mark.parametrize(("v0", "v1"), [(1e-4, 2e-4), (0.0, 1e-3), (1e-3, 5e-2)])
def test_modified_coulomb_matches_reference(v0: float, v1: float) -> None:
    law = ModifiedCoulomb(coefficient=0.05, v0=v0, v1=v1)
    for v in np.concatenate([np.linspace(-3 * v1, 3 * v1, 301), [-v1, -v0, 0.0, v0, v1, 2.0, -2.0]]):
        assert law.friction_force(1500.0, v) == pytest.approx(
            reference_modified_coulomb(0.05, 1500.0, v, v0, v1), rel=1e-13, abs=1e-12)


def test_modified_coulomb_zero_below_v0_full_above_v1() -> None:
    law = ModifiedCoulomb(coefficient=0.1, v0=1e-4, v1=2e-4)
    slow = np.linspace(-1e-4, 1e-4, 101)
    assert np.all(law.friction_force(1000.0, slow) == 0.0)
    fast = np.concatenate([np.linspace(2e-4, 5.0, 101), -np.linspace(2e-4, 5.0, 101)])
    np.testing.assert_allclose(law.friction_force(1000.0, fast), -100.0 * np.sign(fast), rtol=1e-15)
    assert law.friction_force(1000.0, 1.5e-4) == pytest.approx(-50.0)  # half way up the ramp
    assert law.correction(-1.5e-4) == pytest.approx(0.5)


def test_modified_coulomb_is_continuous() -> None:
    law = ModifiedCoulomb(coefficient=0.1, v0=1e-4, v1=2e-4)
    v = np.linspace(-5e-4, 5e-4, 100001)
    force = law.friction_force(1000.0, v)
    max_slope = 0.1 * 1000.0 / (2e-4 - 1e-4)  # steepest part is the ramp
    assert np.max(np.abs(np.diff(force))) <= max_slope * (v[1] - v[0]) * (1 + 1e-9)


@pytest.mark.parametrize("law", [NoFriction(), Coulomb(coefficient=0.2), ModifiedCoulomb(coefficient=0.2)],
                         ids=lambda law: law.name)
def test_friction_power_never_positive(law) -> None:
    rng = np.random.default_rng(3)
    f_n = rng.uniform(0.0, 1e4, 5000)
    v = rng.normal(0.0, 1e-3, 5000) * rng.choice([1.0, 1e-2, 1e3], 5000)
    power = law.friction_force(f_n, v) * v
    assert np.all(power <= 0.0)


def test_coulomb_sign_and_discontinuity() -> None:
    law = Coulomb(coefficient=0.3)
    assert law.friction_force(100.0, 1e-12) == -30.0
    assert law.friction_force(100.0, -2.0) == 30.0
    assert law.friction_force(100.0, 0.0) == 0.0  # sign(0) = 0: documented discontinuity
    assert not law.smooth
    assert NoFriction().friction_force(100.0, 1.0) == 0.0 and NoFriction().frictionless


@pytest.mark.parametrize("symbol", [ca.SX, ca.MX], ids=["SX", "MX"])
@pytest.mark.parametrize("law", [NoFriction(), Coulomb(coefficient=0.2), ModifiedCoulomb(coefficient=0.2)],
                         ids=lambda law: law.name)
def test_casadi_matches_numpy_and_is_finite_at_zero(law, symbol) -> None:
    f_n, v = symbol.sym("f_n"), symbol.sym("v")
    expr = law.friction_force(f_n, v)
    fun = ca.Function("ft", [f_n, v], [expr, ca.jacobian(expr, ca.vertcat(f_n, v))])
    speeds = np.concatenate([np.linspace(-4e-4, 4e-4, 81), [0.0, -0.0, 1e-300, 3.0, -3.0]])
    for speed in speeds:
        value, jac = fun(750.0, speed)
        assert float(value) == law.friction_force(750.0, speed)
        assert np.all(np.isfinite(np.array(jac)))
    _, jac0 = fun(750.0, 0.0)
    assert np.all(np.array(jac0) == 0.0)


def test_friction_registry() -> None:
    assert friction_law(None) == NoFriction()
    assert friction_law(0.05) == ModifiedCoulomb(coefficient=0.05)
    assert friction_law(0.05, v0=1e-3, v1=5e-2) == ModifiedCoulomb(coefficient=0.05, v0=1e-3, v1=5e-2)
    assert friction_law("Ambrosio", coefficient=0.1) == ModifiedCoulomb(coefficient=0.1)
    assert friction_law("modified_coulomb", coefficient=0.1) == ModifiedCoulomb(coefficient=0.1)
    assert friction_law("COULOMB", coefficient=0.1) == Coulomb(coefficient=0.1)
    assert friction_law("none") == NoFriction() == friction_law("frictionless")
    law = Coulomb(coefficient=0.1)
    assert friction_law(law) is law


@pytest.mark.parametrize(("make", "pattern"), [
    (lambda: ModifiedCoulomb(coefficient=-0.1), r"ModifiedCoulomb: coefficient=-0.1, must be >= 0"),
    (lambda: ModifiedCoulomb(coefficient=0.1, v0=2e-4, v1=1e-4), r"v1=0.0001 m/s, must be > v0=0.0002 m/s"),
    (lambda: ModifiedCoulomb(coefficient=0.1, v0=-1e-4), r"v0=-0.0001 m/s, must be >= 0"),
    (lambda: Coulomb(coefficient=float("nan")), r"Coulomb: coefficient=nan"),
    (lambda: friction_law("viscous"), r"unknown name 'viscous'; valid names: none, coulomb, modified-coulomb"),
    (lambda: friction_law("coulomb"), r"missing required parameter.*coefficient"),
    (lambda: friction_law(True), r"name=True is not a string"),
    (lambda: friction_law(0.1, mu=0.2), r"unknown parameter.*mu.*valid: coefficient, v0, v1"),
])
def test_bad_parameters_raise(make, pattern: str) -> None:
    with pytest.raises(SceneError, match=pattern):
        make()
