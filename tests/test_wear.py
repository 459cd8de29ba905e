"""Archard wear of a revolute clearance joint (issue 33, first part): the law spread over the profile.

Closed forms: the worn volume is k times the sliding work whatever the pressure distribution; a load
turning uniformly round the bearing wears it uniformly; a load fixed in the bearing's frame wears one
spot whose depth follows the pressure's shape.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from daeclear.contact.wear import (ArchardWear, WearHistoryArrays, half_angle_hertz, half_angle_overlap,
                                   node_weights, wear_increment, worn_volume)
from daeclear.core.errors import SceneError

R, C, L = 10e-3, 0.5e-3, 20e-3  # bearing radius, clearance, length (m)
K = 1e-13  # m^2/N


def history(n: int, force, angle_bearing, angle_journal=None, slip=0.2, penetration=2e-6, t_end=1.0):
    t = np.linspace(0.0, t_end, n)
    full = lambda x: np.broadcast_to(np.asarray(x(t) if callable(x) else x, dtype=float), t.shape).copy()  # noqa: E731
    return WearHistoryArrays(t=t, force=full(force), angle_bearing=full(angle_bearing),
                             angle_journal=full(angle_journal if angle_journal is not None else angle_bearing),
                             slip_speed=full(slip), penetration=full(penetration))


@pytest.mark.parametrize("distribution", ["elastic-foundation", "hertz"])
@pytest.mark.parametrize("surface", ["bearing", "journal", "both"])
def test_worn_volume_is_k_times_the_sliding_work(distribution, surface):
    """Any load history, any distribution: sum(depth) R dphi L = k * integral F_n |v| dt, to round-off."""
    rng = np.random.default_rng(7)
    n = 400
    h = WearHistoryArrays(t=np.sort(rng.uniform(0, 0.05, n)), force=rng.uniform(0, 3e3, n),
                          angle_bearing=rng.uniform(-10, 10, n), angle_journal=rng.uniform(-10, 10, n),
                          slip_speed=rng.normal(0, 2.0, n), penetration=rng.uniform(0, 2e-5, n))
    wear = ArchardWear(coefficient=K, length=L, nodes=360, surface=surface, distribution=distribution)
    depth, work = wear_increment(wear, h, bearing_radius=R, clearance=C, effective_modulus=113.7e9)
    force = 0.5 * (h.force[1:] + h.force[:-1])
    ds = 0.5 * (np.abs(h.slip_speed[1:]) + np.abs(h.slip_speed[:-1])) * np.diff(h.t)
    assert work == pytest.approx(float(np.sum(force * ds)), rel=1e-12) and work > 0
    for profile in depth.values():
        assert worn_volume(profile, R, L) == pytest.approx(K * work, rel=1e-9, abs=0.0)
        assert np.all(profile >= 0)
    assert set(depth) == ({"bearing", "journal"} if surface == "both" else {surface})


def test_a_load_turning_round_the_bearing_wears_it_uniformly():
    """Constant load F whose direction turns 10 times round the bearing at constant speed, sliding
    distance s: depth k F s / (2 pi R L) at every node."""
    force, turns, slip = 500.0, 10, 0.3
    h = history(20001, force, lambda t: 2 * math.pi * turns * t, slip=slip)
    depth, work = wear_increment(ArchardWear(coefficient=K, length=L), h, bearing_radius=R, clearance=C)
    expected = K * force * slip * 1.0 / (2 * math.pi * R * L)
    assert work == pytest.approx(force * slip)
    assert np.max(np.abs(depth["bearing"] / expected - 1)) < 2e-3


def test_angles_wrapped_as_a_run_gives_them_wear_the_short_way_round():
    """A run's contact angles come wrapped to (-pi, pi] (atan2): an interval from pi - 0.01 to -pi + 0.01
    crosses the wrap and wears around pi, not around 0; the turning load of the test above wears the
    bearing uniformly whether its angles are wrapped or not."""
    h = history(2, 500.0, np.array([math.pi - 0.01, -math.pi + 0.01]), slip=0.3, penetration=0.0)
    depth = wear_increment(ArchardWear(coefficient=K, length=L), h, bearing_radius=R, clearance=C)[0]["bearing"]
    assert np.argmax(depth) in (179, 180) and depth[170:191].sum() == pytest.approx(depth.sum(), rel=1e-12, abs=0.0)
    force, turns, slip = 500.0, 10, 0.3
    wrapped = history(20001, force, lambda t: np.angle(np.exp(2j * math.pi * turns * t)), slip=slip)
    depth = wear_increment(ArchardWear(coefficient=K, length=L), wrapped, bearing_radius=R, clearance=C)[0]["bearing"]
    assert np.max(np.abs(depth / (K * force * slip / (2 * math.pi * R * L)) - 1)) < 2e-3


@pytest.mark.parametrize("penetration", [2e-6, 2e-5])
def test_a_fixed_load_wears_one_spot_with_the_pressure_shape(penetration):
    """The load fixed at 1 rad in the bearing's frame, the journal sliding under it: the elastic-foundation
    depth at the spot is k F s (1 - cos phi0) / (R L 2 (sin phi0 - phi0 cos phi0)), zero off the arc."""
    force, slip = 800.0, 0.5
    wear = ArchardWear(coefficient=K, length=L, nodes=3600)
    h = history(101, force, 1.0, angle_journal=lambda t: 50 * t, slip=slip, penetration=penetration)
    depth = wear_increment(wear, h, bearing_radius=R, clearance=C)[0]["bearing"]
    phi0 = math.acos(C / (C + penetration))  # the arc where the journal's surface overlaps the bearing's
    peak = K * force * slip / (R * L) * (1 - math.cos(phi0)) / (2 * (math.sin(phi0) - phi0 * math.cos(phi0)))
    spot = int(round(1.0 / (2 * math.pi / wear.nodes)))
    assert depth.max() == pytest.approx(peak, rel=2e-3)
    assert abs(int(np.argmax(depth)) - spot) <= 1
    off_arc = np.abs(np.remainder(wear.angles - 1.0 + math.pi, 2 * math.pi) - math.pi) > phi0 + 2 * math.pi / wear.nodes
    assert np.all(depth[off_arc] == 0.0)


def test_a_fixed_load_wears_one_spot_with_the_hertz_shape():
    """The Hertz distribution: p = p0 sqrt(1 - (phi/phi0)^2) over the half-width phi0 = b / R of the line
    contact, the load F = p0 R L phi0 pi / 2, so the depth under a fixed load is k s p0 sqrt(...) with
    p0 = 2 F / (pi R L phi0), b = sqrt(4 F R_eff / (pi L E*)), R_eff = R (R - c) / c."""
    force, slip, e_star = 800.0, 0.5, 113.7e9
    wear = ArchardWear(coefficient=K, length=L, nodes=3600, distribution="hertz")
    h = history(101, force, 1.0, angle_journal=lambda t: 50 * t, slip=slip)
    depth = wear_increment(wear, h, bearing_radius=R, clearance=C, effective_modulus=e_star)[0]["bearing"]
    phi0 = math.sqrt(4 * force * (R * (R - C) / C) / (math.pi * L * e_star)) / R
    p0 = 2 * force / (math.pi * R * L * phi0)
    phi = np.remainder(wear.angles - 1.0 + math.pi, 2 * math.pi) - math.pi  # from the load's direction
    expected = K * slip * p0 * np.sqrt(np.clip(1 - (phi / phi0) ** 2, 0, None))
    assert phi0 > 10 * 2 * math.pi / wear.nodes  # the arc spans many nodes
    assert depth.max() == pytest.approx(expected.max(), rel=2e-3)
    inner = np.abs(phi) < 0.8 * phi0  # the sampled edges blur the shape's vertical ends
    np.testing.assert_allclose(depth[inner], expected[inner], rtol=5e-3)
    assert np.all(depth[np.abs(phi) > phi0 + 2 * math.pi / wear.nodes] == 0.0)


def circles_overlap_half_angle(penetration: float, clearance: float, radius: float) -> float:
    """Half-angle, seen from the bearing's centre, of the bearing's circle (radius R) inside the journal's
    (radius R - c, centre at c + delta): the law of cosines, R^2 + e^2 - 2 R e cos(phi) = (R - c)^2."""
    e = clearance + penetration
    return math.acos((radius**2 + e**2 - (radius - clearance) ** 2) / (2 * radius * e))


@pytest.mark.parametrize("penetration", [2e-6, 2e-5, 1e-4])
def test_the_contact_arc_is_the_circles_overlap(penetration):
    """The elastic foundation's arc is where the radial gap c - (c + delta) cos(phi) of the conformal
    pair is negative: the overlap of the two circles in the limit R >> c, cos(phi0) = c / (c + delta).
    The exact intersection's cosine is larger by (e^2 - c^2) / (2 R e) (e = c + delta), which makes its
    arc narrower by that over sin(phi0), about c / (2 R) relative: 5e-5 at R = 1e4 c, 2.5 % at the
    joint's R = 20 c."""
    phi0 = half_angle_overlap(penetration, C)
    e = C + penetration
    for radius in (1e4 * C, 1e5 * C, R):
        exact = circles_overlap_half_angle(penetration, C, radius)
        first_order = (e**2 - C**2) / (2 * radius * e) / math.sin(phi0)
        assert phi0 - exact == pytest.approx(first_order, rel=0.1, abs=0.0)
        assert 0 < 1 - exact / phi0 < C / radius
    # the arc's two ends, and only they, close the radial gap
    gap = lambda phi: C - e * math.cos(phi)  # noqa: E731
    assert gap(phi0) == pytest.approx(0.0, abs=1e-12 * C) and gap(0.99 * phi0) < 0 < gap(1.01 * phi0)


def test_node_weights_sum_to_one_and_follow_narrow_arcs():
    for half in (0.0, 1e-4, 0.05, 0.5):
        w = node_weights(0.3, half, 360)
        assert w.sum() == pytest.approx(1.0, abs=1e-14) and np.all(w >= 0)
    # a point load between two nodes splits by distance
    w = node_weights(2 * math.pi / 360 * 10.25, 0.0, 360)
    assert w[10] == pytest.approx(0.75) and w[11] == pytest.approx(0.25)
    # across angle zero
    w = node_weights(-1e-3, 0.02, 360)
    assert w[-1] > 0 and w[0] > 0 and w[1:-2].max() > 0 and w[180] == 0


def test_hertz_half_angle():
    """b = sqrt(4 F R_eff / (pi L E*)) for conformal cylinders (R_eff = R_b R_j / c)."""
    e_star = 113.7e9
    b = math.sqrt(4 * 1000.0 * (R * (R - C) / C) / (math.pi * L * e_star))
    assert half_angle_hertz(1000.0, R, R - C, L, e_star) == pytest.approx(b / R)
    assert half_angle_hertz(0.0, R, R - C, L, e_star) == 0.0 and half_angle_overlap(-1e-6, C) == 0.0


@pytest.mark.parametrize("kwargs, text", [
    ({"coefficient": -1.0, "length": L}, "coefficient=-1 m^2/N, must be > 0"),
    ({"coefficient": K, "length": 0.0}, "length=0 m, must be > 0"),
    ({"coefficient": K, "length": L, "nodes": 8}, "nodes=8, must be an integer >= 16"),
    ({"coefficient": K, "length": L, "nodes": 360.0}, "nodes=360.0, must be an integer >= 16"),
    ({"coefficient": K, "length": L, "surface": "pin"}, "surface='pin', must be one of bearing, journal, both"),
    ({"coefficient": K, "length": L, "distribution": "flat"}, "distribution='flat', must be one of"),
])
def test_bad_wear_parameters_name_the_field(kwargs, text):
    with pytest.raises(SceneError, match="ArchardWear") as info:
        ArchardWear(**kwargs)
    assert text in str(info.value)


def test_hertz_needs_the_modulus():
    h = history(11, 100.0, 0.0)
    with pytest.raises(SceneError, match="effective_modulus"):
        wear_increment(ArchardWear(coefficient=K, length=L, distribution="hertz"), h, bearing_radius=R, clearance=C)


def _kinematics(result, s_i, s_j, r_i, r_j, bearing, journal):
    """The contact kinematics of a journal in its bearing computed in numpy from the bodies' states,
    apart from the generated model: n = e / |e| (4.4), contact points P + R n (4.6), the tangential
    component of v_Qj - v_Qi with each body's spin (4.9), n's angle in each body's frame."""
    def body(name):
        return (np.stack([result[f"{name}.x"], result[f"{name}.y"]], axis=1), np.asarray(result[f"{name}.phi"]),
                np.stack([result[f"{name}.vx"], result[f"{name}.vy"]], axis=1), np.asarray(result[f"{name}.omega"]))

    def rotate(angle, point):
        c, s_ = np.cos(angle), np.sin(angle)
        return np.stack([c * point[0] - s_ * point[1], s_ * point[0] + c * point[1]], axis=1)

    def cross(omega, r):
        return np.stack([-omega * r[:, 1], omega * r[:, 0]], axis=1)

    (x_i, phi_i, v_i, w_i), (x_j, phi_j, v_j, w_j) = body(bearing), body(journal)
    arm_i, arm_j = rotate(phi_i, s_i), rotate(phi_j, s_j)
    e = (x_j + arm_j) - (x_i + arm_i)
    n = e / np.maximum(np.hypot(e[:, 0], e[:, 1]), 1e-300)[:, None]
    tangent = np.stack([-n[:, 1], n[:, 0]], axis=1)
    slip = np.sum((v_j + cross(w_j, arm_j + r_j * n) - v_i - cross(w_i, arm_i + r_i * n)) * tangent, axis=1)
    direction = np.arctan2(n[:, 1], n[:, 0])
    return slip, direction - phi_i, direction - phi_j


def test_the_history_of_a_run_matches_the_joint_s_own_channels():
    """wear_history reads the worn joint's generated channels: the sliding speed and the contact
    directions equal an independent numpy computation from the bodies' states, the penetration and the
    force the joint's channels."""
    import daeclear as dc
    from daeclear.studies.wear import wear_history

    scene = dc.mechanisms.slider_crank("revolute", friction=0.05).with_values(
        {"clearance.wear": ArchardWear(coefficient=K, length=L)})
    model = dc.assemble(scene)
    result = dc.simulate(model, 0.006, save=dc.SaveAt(times=np.linspace(0, 0.006, 601)))
    h = wear_history(result, model, "clearance")
    contact = result["clearance.in_contact"] > 0
    assert contact.sum() > 20
    off_centre = result["clearance.eccentricity"] > 0  # the start is centred: no direction there
    assert off_centre[1:].all()
    joint = scene["clearance"]
    slip, bearing, journal = _kinematics(result, model.parameter("clearance.s_i"), model.parameter("clearance.s_j"),
                                         joint.bearing_radius, joint.journal, "slider", "rod")
    np.testing.assert_allclose(h.slip_speed[off_centre], slip[off_centre], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(h.penetration[contact], result["clearance.penetration"][contact], rtol=1e-9, atol=1e-15)
    for angle, reference in ((h.angle_bearing, bearing), (h.angle_journal, journal)):
        np.testing.assert_allclose(np.cos(angle[off_centre]), np.cos(reference[off_centre]), atol=1e-12)
        np.testing.assert_allclose(np.sin(angle[off_centre]), np.sin(reference[off_centre]), atol=1e-12)
        assert np.max(np.abs(np.diff(angle[off_centre]))) < np.pi  # unwrapped
    assert np.array_equal(h.force, result["clearance.normal_force"])
    with pytest.raises(SceneError, match="joint=.B., must be a revolute clearance joint with wear of the run "
                                         ".clearance."):
        wear_history(result, model, "B")
