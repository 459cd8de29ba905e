"""Issue 43's acceptance case, a radial impact, against its closed form; and a run with forward
sensitivities (``simulate(..., sensitivities=...)``, tests/sensitivity_runs.py) through it, with and without the jumps.

A free journal (m = 1 kg) starts at the bearing's centre at u = 1 m/s along x; clearance z0 = 0.1 m,
Kelvin-Voigt K = 1e4 N/m, D = 20 N s/m, no gravity, start="declared", T = 0.25 s. Closed form: a = D/2m,
w_d = sqrt(K/m - a^2), onset t1 = z0/u; penetration d(s) = (u/w_d) e^(-a s) sin(w_d s) until the force
K d + D d' reaches zero at s_z = (pi - atan(D w_d / (K - D a)))/w_d, with speed v_z = -d'(s_z) and d(s_z)
left; then the journal flies back at v_z: separation at t1 + s_z + d(s_z)/v_z, x(T) = z0 - v_z (T - t_sep).
Its derivatives by the complex step. The force jumps to D u at onset: without the sensitivities' jump
there the derivatives are wrong (dx/dz0 by about 100 %), which the run without it shows.

The same run with Lankarani-Nikravesh (its force reads the approach speed latched at onset) under a
constant force is checked against central differences of ordinary runs, and by its Taylor remainder
(falling as h^2).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from sensitivity_runs import forward_sensitivities

M, U, T = 1.0, 1.0, 0.25
K, D, Z0 = 1e4, 20.0, 0.1
NAMES = ["clearance.law.stiffness", "clearance.law.damping", "clearance.clearance"]


def kelvin_voigt_radial(p: np.ndarray) -> np.ndarray:
    """(x(T), vx(T), t_separation) of the radial impact for p = (K, D, z0); complex p for the complex step."""
    k, d, z0 = p
    a = d / (2 * M)
    wd = np.sqrt(k / M - a * a)
    t1 = z0 / U
    s_z = (np.pi - np.arctan(d * wd / (k - d * a))) / wd
    depth = (U / wd) * np.exp(-a * s_z) * np.sin(wd * s_z)
    v_z = -(U / wd) * np.exp(-a * s_z) * (wd * np.cos(wd * s_z) - a * np.sin(wd * s_z))
    t_sep = t1 + s_z + depth / v_z
    return np.array([z0 - v_z * (T - t_sep), -v_z, t_sep])


def complex_step(f, p: np.ndarray) -> np.ndarray:
    """(n_out, n_p) Jacobian of a real-analytic f: Im f(p + i h_j e_j) / h_j, exact to round-off."""
    steps = 1e-30 * np.abs(p)
    return np.stack([np.imag(f(p + 1j * steps[j] * np.eye(p.size)[j])) / steps[j] for j in range(p.size)], axis=1)


P0 = np.array([K, D, Z0])
T_CONTACT = 0.11  # 10 ms into the contact, before the force reaches zero


def kelvin_voigt_force(p: np.ndarray) -> np.ndarray:
    """The normal force K d + D d' at T_CONTACT (in contact), for p = (K, D, z0)."""
    k, d, z0 = p
    a = d / (2 * M)
    wd = np.sqrt(k / M - a * a)
    s = T_CONTACT - z0 / U
    depth = (U / wd) * np.exp(-a * s) * np.sin(wd * s)
    rate = (U / wd) * np.exp(-a * s) * (wd * np.cos(wd * s) - a * np.sin(wd * s))
    return np.array([k * depth + d * rate])


def test_closed_form_gives_the_issues_values() -> None:
    """x(T) = 0.0118717966, vx(T) = -0.7440793977, separation 0.1315607532 s; d(x, vx, t_sep)/d(K, D, z0) as
    issue 43 prints them (its digits)."""
    x, vx, t_sep = kelvin_voigt_radial(P0)
    assert x == pytest.approx(0.0118717966, abs=1e-10)
    assert vx == pytest.approx(-0.7440793977, abs=1e-10)
    assert t_sep == pytest.approx(0.1315607532, abs=1e-10)
    J = complex_step(kelvin_voigt_radial, P0)
    assert J[0] == pytest.approx([-2.4112495e-6, 1.2370642e-3, 1.7440794], rel=5e-8, abs=0.0)
    assert J[1] == pytest.approx([-1.0357267e-5, 1.0357267e-2, 0.0], rel=5e-8, abs=1e-15)
    assert J[2] == pytest.approx([-1.5919572e-6, 1.3919572e-5, 1.0], rel=5e-8, abs=0.0)


def test_complex_step_agrees_with_high_order_differences() -> None:
    """The complex step against a fourth-order central difference of the same closed form (a check of the
    closed form's differentiability and of the step)."""
    J = complex_step(kelvin_voigt_radial, P0)
    for j in range(3):
        h = 1e-3 * P0[j]
        e = np.eye(3)[j] * h
        f = [np.real(kelvin_voigt_radial(P0 + s * e)) for s in (2, 1, -1, -2)]
        fd = (-f[0] + 8 * f[1] - 8 * f[2] + f[3]) / (12 * h)
        assert J[:, j] == pytest.approx(fd, rel=1e-7, abs=1e-12)


def radial_scene(law: object, gravity: tuple[float, float] = (0.0, 0.0)) -> dc.Scene:
    scene = dc.Scene("radial", gravity=gravity)
    journal = scene.add(dc.Body("journal", mass=M, inertia=1.0, velocity=(U, 0.0)))
    scene.add(dc.RevoluteClearance("clearance", scene.ground, journal, at=(0, 0), bearing_radius=1.0,
                                   clearance=Z0, law=law))
    return scene


@pytest.fixture(scope="module")
def kv_model() -> dc.DAEModel:
    return dc.assemble(radial_scene(dcc.KelvinVoigt(stiffness=K, damping=D)))


@pytest.mark.parametrize("backend", ["python", "c"])
def test_stacked_run_reproduces_the_closed_form(kv_model, backend: str) -> None:
    """S(T) of x and vx, and each event time's sensitivity, from the stacked DAE with the jumps."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)  # atol at round-off, raised
        run = forward_sensitivities(kv_model, T, NAMES, rtol=1e-10, start="declared", backend=backend,
                                    t_eval=np.array([0.0, T_CONTACT, T]))
    assert run.success
    want = complex_step(kelvin_voigt_radial, P0)
    x, vx, t_sep = kelvin_voigt_radial(P0)
    assert run.y[-1, 0] == pytest.approx(x, abs=1e-9) and run.y[-1, 3] == pytest.approx(vx, rel=1e-8, abs=0.0)
    assert run.sensitivity("journal.x")[-1] == pytest.approx(want[0], rel=1e-6, abs=0.0)
    assert run.sensitivity("journal.vx")[-1] == pytest.approx(want[1], rel=1e-6, abs=1e-9)
    assert run.sensitivity("journal.vx", "clearance.clearance")[-1] == pytest.approx(0.0, abs=1e-9)
    onset, separation = run.events
    assert (onset.kind, separation.kind) == ("onset", "separation")
    assert onset.dt_dp == pytest.approx([0.0, 0.0, 1 / U], abs=1e-12)  # dt1/dz0 = 1/u
    assert separation.t == pytest.approx(t_sep, rel=1e-9, abs=0.0)
    assert separation.dt_dp == pytest.approx(want[2], rel=1e-6, abs=0.0)
    # a channel's sensitivity, the chain rule through its function: the normal force in contact
    assert run.sensitivity("clearance.normal_force")[1] == pytest.approx(complex_step(kelvin_voigt_force, P0)[0],
                                                                         rel=1e-6, abs=0.0)
    channel = run.channel_S[:, run.channel_names.index("journal.vx"), :]  # the channel of a state is the state
    assert np.array_equal(channel, run.S[:, run.state_names.index("journal.vx"), :])


def test_the_run_without_the_jump_fails_the_test(kv_model) -> None:
    """The jump is tested, not only present: without it dx/dz0 comes out 3.51 instead of 1.74 and dvx/dz0
    14.9 instead of 0 (the stiffness and damping columns hardly move: the force is continuous at separation
    and the onset time does not depend on them)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        run = forward_sensitivities(kv_model, T, NAMES, rtol=1e-10, start="declared", jumps=False)
    want = complex_step(kelvin_voigt_radial, P0)
    got = run.sensitivity("journal.x", "clearance.clearance")[-1]
    assert abs(got - want[0, 2]) > 0.5 * abs(want[0, 2])
    assert abs(run.sensitivity("journal.vx", "clearance.clearance")[-1]) > 1.0


# ---------------------------------------------------------------- a latched approach speed

LN_NAMES = ["clearance.clearance", "clearance.law.restitution", "journal.mass"]


def ln_model() -> dc.DAEModel:
    """The radial impact with Lankarani-Nikravesh (force continuous at onset: no jump of S there) under
    5 m/s^2 along x: the approach speed sqrt(u^2 + 2 g z0) latched at onset moves with the clearance only
    through the onset time (dv/dz0 = g dt1/dz0 = g / v), the term of the latched value's jump."""
    return dc.assemble(radial_scene(dcc.LankaraniNikravesh(restitution=0.8, stiffness=1e7), gravity=(5.0, 0.0)))


def final_state(model: dc.DAEModel, values: dict[str, float] | None = None) -> np.ndarray:
    """x, vx at T of an ordinary run at rtol 1e-12."""
    moved = model.with_parameters(values) if values else model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(moved, T, options=dc.SolverOptions(start="declared", rtol=1e-12),
                             save=dc.SaveAt(times=[0.0, T], steps=False))
    return np.array([result["journal.x"][-1], result["journal.vx"][-1]])


def ln_run(jumps: bool = True) -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        return forward_sensitivities(ln_model(), T, LN_NAMES, rtol=1e-11, start="declared", jumps=jumps)


def final_sensitivities(run: object) -> np.ndarray:
    """(2, Ns): d(x, vx)(T)/dp of a run."""
    return np.stack([run.sensitivity("journal.x")[-1], run.sensitivity("journal.vx")[-1]])


@pytest.fixture(scope="module")
def ln_differences() -> np.ndarray:
    """(2, Ns) central differences of ordinary runs, relative steps 1e-3 and 5e-4 combined by Richardson's
    extrapolation (smaller steps drown in the runs' own errors, ~1e-12 over the step)."""
    model, out = ln_model(), []
    for name in LN_NAMES:
        p = model.parameter(name)[0]
        central = [(final_state(model, {name: p + h}) - final_state(model, {name: p - h})) / (2 * h)
                   for h in (1e-3 * p, 5e-4 * p)]
        out.append((4 * central[1] - central[0]) / 3)
    return np.stack(out, axis=1)


def test_latched_approach_speed_sensitivities_match_differences_of_runs(ln_differences) -> None:
    """S(T) of x and vx to (clearance, restitution, mass) against central differences of ordinary runs;
    without the latched value's dt*/dp term the clearance's are off."""
    S = final_sensitivities(ln_run())
    assert S == pytest.approx(ln_differences, rel=1e-6, abs=1e-9 * np.abs(S).max())
    wrong = final_sensitivities(ln_run(jumps=False))
    assert np.abs(wrong[:, 0] - ln_differences[:, 0]).max() > 1e-2 * np.abs(ln_differences[:, 0]).max()


@pytest.mark.parametrize("name", ["clearance.clearance", "clearance.law.restitution"])
def test_taylor_remainder_falls_as_h_squared(name: str) -> None:
    """The first-order prediction y(p + h) = y(p) + S h misses by O(h^2) when S is right (a missing term
    leaves O(h)): the remainder at h and h/4 falls 16-fold (within 25 %)."""
    model = ln_model()
    base = final_state(model)
    p = model.parameter(name)[0]
    S = final_sensitivities(ln_run())[:, LN_NAMES.index(name)]
    remainder = [np.abs(final_state(model, {name: p + h}) - base - S * h).max() for h in (5e-2 * p, 1.25e-2 * p)]
    assert 16 / 1.25 < remainder[0] / remainder[1] < 16 * 1.25
