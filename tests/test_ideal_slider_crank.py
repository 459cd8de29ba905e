"""Ideal slider-crank against closed-form kinematics and the power balance.

Closed forms (crank r, rod l, crank angle theta = omega t, D = sqrt(l^2 - r^2 sin^2 theta)):
    x      = r cos(theta) + D
    dx/dθ  = -r sin - r^2 sin cos / D
    d2x/dθ2 = -r cos - r^2 (cos^2 - sin^2) / D - r^4 sin^2 cos^2 / D^3
Driving moment from the power balance M omega = dT/dt + dV/dt with T = omega^2 I(theta) / 2:
    M = omega^2 I'(theta) / 2 + dV/dtheta,
I(theta) the generalized inertia (evaluated independently below, differentiated by complex step).
"""

import numpy as np
import pytest

import daeclear as dc
from daeclear.model.mechanisms import (CRANK_INERTIA, CRANK_LENGTH as R, CRANK_MASS, ROD_INERTIA, ROD_LENGTH as L,
                                 ROD_MASS, SLIDER_MASS, rpm_to_rad_s)

OMEGA = rpm_to_rad_s(5000.0)


def slider_kinematics(theta):
    s, c = np.sin(theta), np.cos(theta)
    D = np.sqrt(L**2 - R**2 * s**2)
    x = R * c + D
    dx = -R * s - R**2 * s * c / D
    ddx = -R * c - R**2 * (c**2 - s**2) / D - R**4 * s**2 * c**2 / D**3
    return x, OMEGA * dx, OMEGA**2 * ddx


def generalized_inertia(theta):
    """I(theta) with T = omega^2 I / 2, from link velocities per unit crank speed (complex-safe)."""
    s, c = np.sin(theta), np.cos(theta)
    sin_b = -R * s / L
    cos_b = np.sqrt(1 - sin_b**2)
    db = -R * c / (L * cos_b)  # d beta / d theta
    # rod centre of mass velocity per unit crank speed
    vx_rod = -R * s - 0.5 * L * sin_b * db
    vy_rod = R * c + 0.5 * L * cos_b * db
    dx_slider = -R * s - L * sin_b * db
    return (CRANK_MASS * (R / 2) ** 2 + CRANK_INERTIA + ROD_MASS * (vx_rod**2 + vy_rod**2)
            + ROD_INERTIA * db**2 + SLIDER_MASS * dx_slider**2)


def potential_slope(theta, g):
    """dV/dtheta for gravity g along -Y (crank and rod centres of mass rise with theta)."""
    c = np.cos(theta)
    # y_crank = R s / 2, y_rod = R s / 2 (mid-point between B at R s and C at 0)
    return g * (CRANK_MASS * R * c / 2 + ROD_MASS * R * c / 2)


def moment_closed_form(theta, g):
    h = 1e-20
    dI = np.imag(generalized_inertia(theta + 1j * h)) / h
    return 0.5 * OMEGA**2 * dI + potential_slope(theta, g)


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
@pytest.mark.parametrize("gravity", [0.0, 9.81])
def test_one_revolution_matches_closed_form(formulation, gravity):
    period = 2 * np.pi / OMEGA
    t = np.linspace(0.0, period, 721)
    result = dc.simulate(dc.mechanisms.slider_crank(gravity=gravity), period, rtol=1e-9,
                         options=dc.SolverOptions(formulation=formulation), save=dc.SaveAt(times=t))
    assert result.success
    theta = OMEGA * t
    x, vx, ax = slider_kinematics(theta)
    moment = moment_closed_form(theta, gravity)
    for name, ref in (("slider.x", x), ("slider.vx", vx), ("slider.ax", ax), ("drive.moment", moment)):
        err = np.max(np.abs(result[name] - ref)) / np.ptp(ref)
        assert err < 1e-5, f"{name}: relative error {err:.2e}"
    # the extreme values of docs/contact_laws.md (computed independently there)
    assert ax[0] == pytest.approx(-19419.36, abs=0.05)
    if gravity == 0.0:
        assert np.max(result["drive.moment"]) == pytest.approx(138.5, abs=0.1)


def test_power_balance_from_simulated_channels():
    """M omega = d(T + V)/dt using only the simulated energy channel (independent of the closed form)."""
    period = 2 * np.pi / OMEGA
    t = np.linspace(0.0, period, 4001)
    result = dc.simulate(dc.mechanisms.slider_crank(), period, rtol=1e-10, save=dc.SaveAt(times=t))
    energy = result["energy.mechanical"]
    dEdt = np.gradient(energy, t, edge_order=2)
    power = result["drive.moment"] * OMEGA
    err = np.max(np.abs(dEdt - power)[5:-5]) / np.ptp(power)
    assert err < 1e-4


def test_joint_channels_match_the_closed_form():
    """<joint>.angle/.rate (body j relative to body i) and <joint>.displacement/.speed against the
    closed-form kinematics: crank angle theta = omega t, rod angle beta = asin(-R sin(theta) / L),
    beta' = -R cos(theta) omega / (L cos(beta)), slider x and x' from slider_kinematics."""
    period = 2 * np.pi / OMEGA
    t = np.linspace(0.0, 1.5 * period, 541)
    scene = dc.mechanisms.slider_crank()
    result = dc.simulate(scene, 1.5 * period, rtol=1e-10, save=dc.SaveAt(times=t))
    theta = OMEGA * t
    beta = np.arcsin(-R * np.sin(theta) / L)
    beta_dot = -R * np.cos(theta) * OMEGA / (L * np.cos(beta))
    angle = {"ground": (0.0 * t, 0.0 * t), "crank": (theta, OMEGA + 0.0 * t), "rod": (beta, beta_dot),
             "slider": (0.0 * t, 0.0 * t)}
    for joint in ("A", "B", "C"):
        (phi_i, w_i), (phi_j, w_j) = angle[scene[joint].body_i], angle[scene[joint].body_j]
        np.testing.assert_allclose(result[f"{joint}.angle"], phi_j - phi_i, rtol=0, atol=1e-7)
        np.testing.assert_allclose(result[f"{joint}.rate"], w_j - w_i, rtol=0, atol=1e-7 * OMEGA)
    assert result["A.angle"][-1] == pytest.approx(3 * np.pi, rel=1e-7)  # not wrapped: counts turns
    x, vx, _ = slider_kinematics(theta)
    np.testing.assert_allclose(result["D.displacement"], x, rtol=0, atol=1e-8)
    np.testing.assert_allclose(result["D.speed"], vx, rtol=0, atol=1e-8 * np.ptp(vx))
    assert result.units["D.displacement"] == "m" and result.units["C.rate"] == "rad/s"


@pytest.mark.parametrize("joint", ["revolute", "translational"])
def test_joint_channels_of_clearance_joints(joint):
    """A clearance joint has the same coordinate: the journal body's angle relative to the bearing
    body's; the slider centre's displacement along the guide, which is the joint's own `.s`."""
    scene = dc.mechanisms.slider_crank(joint)
    result = dc.simulate(scene, 2e-3, rtol=1e-8, save=dc.SaveAt(times=np.linspace(0.0, 2e-3, 41)))
    clearance = scene["clearance"]
    if joint == "revolute":
        expected = result[f"{clearance.body_j}.phi"] - result[f"{clearance.body_i}.phi"]
        np.testing.assert_allclose(result["clearance.angle"], expected, rtol=0, atol=1e-14)
        rate = result[f"{clearance.body_j}.omega"] - result[f"{clearance.body_i}.omega"]
        np.testing.assert_allclose(result["clearance.rate"], rate, rtol=0, atol=1e-12)
    else:
        np.testing.assert_allclose(result["clearance.displacement"], result["clearance.s"], rtol=0, atol=1e-14)
        # the guide is the ground along X from the origin, the slider's centre its centre of mass
        np.testing.assert_allclose(result["clearance.displacement"], result["slider.x"], rtol=0, atol=1e-14)
        np.testing.assert_allclose(result["clearance.speed"], result["slider.vx"], rtol=0, atol=1e-12)
