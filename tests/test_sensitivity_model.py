"""A model's sensitivity pieces (daeclear/assembly/sensitivity.py, issue 43): parameters by name, dP/dp,
the start's sensitivities, consistent algebraic sensitivities and the approach speed's derivative, each
against an independent computation (a closed form, the linear system of the DAE, or differences of the
model's own consistent states)."""

from __future__ import annotations

import dataclasses

import casadi
import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.assembly.sensitivity import ModelSensitivity, initial_sensitivities, parameter_directions
from daeclear.core.errors import SceneError


@pytest.fixture(scope="module")
def index1() -> dc.DAEModel:
    return dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="index1")


@pytest.fixture(scope="module")
def ggl() -> dc.DAEModel:
    return dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="ggl")


def entries(model: dc.DAEModel) -> list[str]:
    """The table entry of each element of P."""
    return [name for name, size in model.parameter_layout for _ in range(size)]


def test_parameter_directions_exact_and_derived(index1) -> None:
    """A number P holds itself moves P by an exact unit column; the clearance also moves the numbers derived
    from it: the journal radius R_i - c (-1) and the stiffness of eq. (3.5),
    K = 4/(3 sigma) sqrt(R_i R_j / (R_i - R_j)) with R_j = R_i - c: dK/dc = K (-1/(R_i - c) - 1/c) / 2."""
    names = ["clearance.law.restitution", "crank.mass", "baumgarte.alpha", "clearance.clearance"]
    dP = parameter_directions(index1, names)
    rows = entries(index1)
    for j, name in enumerate(names[:3]):
        assert dP[rows.index(name), j] == 1.0 and np.count_nonzero(dP[:, j]) == 1, name
    c_col = dP[:, 3]
    K, R, c = (index1.parameter(n)[0] for n in ("clearance.law.stiffness", "clearance.bearing_radius",
                                                  "clearance.clearance"))
    assert c_col[rows.index("clearance.clearance")] == 1.0
    assert c_col[rows.index("clearance.journal_radius")] == pytest.approx(-1.0, rel=1e-12, abs=0.0)
    assert c_col[rows.index("clearance.law.stiffness")] == pytest.approx(K * 0.5 * (-1 / (R - c) - 1 / c), rel=1e-10,
                                                                     abs=0.0)
    assert np.count_nonzero(c_col) == 3


@pytest.mark.parametrize(("names", "message"), [
    (["clearance.clearence"], r"parameter='clearance.clearence', must be one of model.parameter_names .* "
                              r"Close matches: 'clearance.clearance'"),
    (["gravity"], r"parameter='gravity' is \[0.0, -9.81\], must be one finite number"),
    ("clearance.clearance", r"parameters='clearance.clearance', must be a non-empty list of names"),
    ([], r"parameters=\[\], must be a non-empty list"),
    (["crank.mass", "crank.mass"], r"must name each parameter once \('crank.mass' repeated\)"),
])
def test_bad_parameter_names_are_refused(index1, names, message) -> None:
    with pytest.raises(SceneError, match=message):
        parameter_directions(index1, names)


def test_start_sensitivity_to_the_drive_speed(ggl) -> None:
    """The chapter's start moves with the crank's speed: every velocity is proportional to it (dv0/dw = v0/w),
    the positions do not move."""
    S = initial_sensitivities(ggl, ["drive.speed"])[:, 0]
    y0 = ggl.initial_state()[0]
    n, w = ggl.n_q, ggl.parameter("drive.speed")[0]
    assert S[n:2 * n] == pytest.approx(y0[n:2 * n] / w, rel=1e-9, abs=1e-12)
    assert np.abs(S[:n]).max() <= 1e-12


def mode_point(model: dc.DAEModel, seed: int) -> dict:
    """A consistent state in contact (LN term on, latched speed 0.3 m/s) and random S_q, S_v, Sk."""
    rng = np.random.default_rng(seed)
    y, _ = model.initial_state()
    n = model.n_q
    y = y.copy()
    y[3] += 0.51e-3
    y[n + 3] += 0.1
    active, params = [True], [np.array([0.3])]
    y, yp = model.consistent_state(1e-3, y, model.term_forces(1e-3, y, active, params))
    S = np.zeros((model.n_states, 2))
    S[:n] = rng.normal(size=(n, 2)) * 1e-3
    S[n:2 * n] = rng.normal(size=(n, 2))
    return dict(t=1e-3, y=y, yp=yp, S=S, active=active, params=params, Sk=[rng.normal(size=(1, 2))])


def test_consistent_sensitivities_solve_the_linear_system_of_the_dae(index1) -> None:
    """Index 1: [F_y' (differential columns) | F_y (algebraic columns)] [S'_d; S_a] = -(F_y,d S_d + F_P dP + F_p Sk),
    with F_y, F_y' from the model's iteration matrix J(cj) = F_y + cj F_y' and F_P dP, F_p Sk by differences."""
    names = ["clearance.clearance", "clearance.law.restitution"]
    ms = ModelSensitivity(index1, names)
    x = mode_point(index1, 0)
    S, Sp = ms.consistent(x["t"], x["y"], x["S"], x["active"], x["params"], x["Sk"])
    f, P, t, y, yp, p = index1.functions, index1.parameter_values, x["t"], x["y"], x["yp"], x["params"][0]

    def J(cj: float) -> np.ndarray:
        return np.array(casadi.densify(f.jacobian(t, y, yp, cj, P) + f.term_jacobians[0](t, y, yp, p, cj, P)))

    def F(Pe: np.ndarray, pe: np.ndarray) -> np.ndarray:
        return np.array(f.residual(t, y, yp, Pe) + f.term_residuals[0](t, y, yp, pe, Pe)).ravel()

    F_y, F_yp = J(0.0), J(1.0) - J(0.0)
    d = np.array([kind != "lambda" for kind in index1.state_kinds])
    for j in range(2):
        dP, dp = ms.dP[:, j], x["Sk"][0][:, j]
        central = [(F(P + h * dP, p + h * dp) - F(P - h * dP, p - h * dp)) / (2 * h) for h in (1e-8, 5e-9)]
        forcing = (4 * central[1] - central[0]) / 3  # Richardson: the penetration is 1e-5 m, c moves by 1e-8
        M = np.hstack([F_yp[:, d], F_y[:, ~d]])
        sol = np.linalg.solve(M, -(F_y[:, d] @ x["S"][d, j] + forcing))
        assert Sp[d, j] == pytest.approx(sol[:d.sum()], rel=1e-9, abs=1e-9 * np.abs(sol[:d.sum()]).max())
        assert S[~d, j] == pytest.approx(sol[d.sum():], rel=1e-9, abs=1e-9 * np.abs(sol[d.sum():]).max())
        assert np.array_equal(S[d, j], x["S"][d, j])  # the differential sensitivities are kept


def test_consistent_sensitivities_differentiate_the_consistent_state(ggl) -> None:
    """GGL (index 2: no linear system of the DAE gives the multipliers): the derivative of
    DAEModel.consistent_state along (S_q, S_v, Sk, dP), by central differences of its numbers."""
    names = ["clearance.law.restitution", "rod.mass"]  # numbers near 1: a step moves them by more than round-off
    ms = ModelSensitivity(ggl, names)
    x = mode_point(ggl, 1)
    S, Sp = ms.consistent(x["t"], x["y"], x["S"], x["active"], x["params"], x["Sk"])
    n, m = ggl.n_q, ggl.n_constraints
    P = ggl.parameter_values
    for j in range(2):
        def state(e: float, j: int = j) -> tuple[np.ndarray, np.ndarray]:
            moved = dataclasses.replace(ggl, parameter_values=P + e * ms.dP[:, j])
            ye = x["y"] + e * x["S"][:, j]
            pe = [x["params"][0] + e * x["Sk"][0][:, j]]
            return moved.consistent_state(x["t"], ye, moved.term_forces(x["t"], ye, x["active"], pe))
        central = []
        for h in (1e-4, 5e-5):  # round-off of the multipliers (6e4 N) wins below
            (y_plus, yp_plus), (y_minus, yp_minus) = state(h), state(-h)
            central.append(np.concatenate([y_plus - y_minus, yp_plus - yp_minus]) / (2 * h))
        both = (4 * central[1] - central[0]) / 3  # Richardson
        lam, acc = both[2 * n:2 * n + m], both[ggl.n_states + n:ggl.n_states + 2 * n]
        assert S[2 * n:2 * n + m, j] == pytest.approx(lam, rel=1e-8, abs=1e-8 * np.abs(lam).max())
        assert Sp[n:2 * n, j] == pytest.approx(acc, rel=1e-8, abs=1e-8 * np.abs(acc).max())
        assert np.array_equal(Sp[:n, j], x["S"][n:2 * n, j]) and not S[2 * n + m:, j].any()


def test_approach_rate_and_its_derivatives_closed_form() -> None:
    """A free journal at e = (x, y) moving at (u, w): the penetration rate is e.e'/|e|; its derivative in a
    direction (S_x, S_y, S_u, S_w) and its rate along (u, w, a_x, a_y), against the complex step of that formula."""
    scene = dc.Scene("radial", gravity=(0.0, 0.0))
    body = scene.add(dc.Body("journal", mass=1.0, inertia=1.0, velocity=(1.0, 0.0)))
    scene.add(dc.RevoluteClearance("clearance", scene.ground, body, at=(0, 0), bearing_radius=1.0,
                                   clearance=0.1, law=dcc.KelvinVoigt(stiffness=1e4, damping=20.0)))
    model = dc.assemble(scene)
    ms = ModelSensitivity(model, ["clearance.clearance"])
    y = np.array([0.09, 0.04, 0.3, 0.7, -0.2, 5.0])
    yp = np.array([0.7, -0.2, 5.0, -3.0, 2.0, 0.0])
    S = np.array([[0.2], [-0.5], [0.0], [1.5], [0.25], [0.0]])

    def rate(z: np.ndarray) -> complex:
        return (z[0] * z[3] + z[1] * z[4]) / np.sqrt(z[0] ** 2 + z[1] ** 2)

    def complex_step(direction: np.ndarray) -> float:
        return float(np.imag(rate(y + 1e-30j * direction)) / 1e-30)

    speed, rate_p, rate_rate = ms.approach_rate(0, y, yp, S)
    assert speed == pytest.approx(float(np.real(rate(y.astype(complex)))), rel=1e-15, abs=0.0)
    assert rate_p[0] == pytest.approx(complex_step(S[:, 0]), rel=1e-13, abs=0.0)
    assert rate_rate == pytest.approx(complex_step(yp), rel=1e-13, abs=0.0)
    at = ms.roots(0.0, y, yp, S, np.zeros_like(S), rtol=1e-8, atol=np.full(6, 1e-9))
    # the gap (|e|^2 - c^2) / 2c (smooth at e = 0): its sensitivity with c moving, its rate, terms and curvature
    def gap(z: np.ndarray, c: complex = 0.1) -> complex:
        return (z[0] ** 2 + z[1] ** 2 - c * c) / (2 * c)

    assert at.g_p[0] == pytest.approx([float(np.imag(gap(y + 1e-30j * S[:, 0], 0.1 + 1e-30j)) / 1e-30)], rel=1e-13,
                                      abs=0.0)
    assert at.rate[0] == pytest.approx((y[0] * yp[0] + y[1] * yp[1]) / 0.1, rel=1e-13, abs=0.0)
    assert at.scale[0] == pytest.approx((abs(y[0] * yp[0]) + abs(y[1] * yp[1])) / 0.1, rel=1e-13, abs=0.0)
    # d2/dt2 along q' = v, q'' = v': (|v|^2 + e.a) / c
    assert at.curvature[0] == pytest.approx((yp[0] ** 2 + yp[1] ** 2 + y[0] * yp[3] + y[1] * yp[4]) / 0.1, rel=1e-13,
                                            abs=0.0)
    assert at.error[0] == pytest.approx((abs(y[0]) * (1e-9 + 1e-8 * abs(y[0])) + abs(y[1]) * (1e-9 + 1e-8 * abs(y[1])))
                                        / 0.1, rel=1e-13, abs=0.0)


def test_projection_puts_sensitivities_on_the_linearised_constraints(ggl) -> None:
    """GGL restarts: after ModelSensitivity.projected, Phi(q + e S_q, P + e dP) and Phi'(q + e S_q, v + e S_v,
    P + e dP) have zero derivative in e (central differences of the constraints), and the correction is the
    least-norm one (in the row space of Phi_q)."""
    ms = ModelSensitivity(ggl, ["clearance.clearance", "rod.mass"])
    x = mode_point(ggl, 2)
    S = ms.projected(x["t"], x["y"], x["S"])
    n, m, P = ggl.n_q, ggl.n_constraints, ggl.parameter_values

    def kinematics(e: float, j: int) -> np.ndarray:
        flat = np.array(ggl.functions.extras[2](x["y"][:n] + e * S[:n, j], x["y"][n:2 * n] + e * S[n:2 * n, j],
                                                x["t"], P + e * ms.dP[:, j])).ravel()
        return np.concatenate([flat[:m], flat[m + m * n:]])

    flat = np.array(ggl.functions.extras[2](x["y"][:n], x["y"][n:2 * n], x["t"], P)).ravel()
    Phi_q = flat[m:m + m * n].reshape(n, m).T
    for j in range(2):
        h = 1e-7
        d = (kinematics(h, j) - kinematics(-h, j)) / (2 * h)
        assert np.abs(d).max() < 1e-6 * np.abs(x["S"][:, j]).max()
        for rows in (slice(0, n), slice(n, 2 * n)):
            change = S[rows, j] - x["S"][rows, j]
            assert np.abs(change).max() > 0
            assert np.allclose(change, Phi_q.T @ np.linalg.lstsq(Phi_q.T, change, rcond=None)[0], atol=1e-12)


def test_face_and_film_rules_of_the_latched_sensitivities() -> None:
    """A section-4.3 face's parameter is the mean of its corners' latched speeds (floored by the face law's
    minimum, if the face law reads one):
    its sensitivity is the mean of theirs, 0 where the floor holds; its events are made by its corners' roots.
    The lubricated joint's dry term reads the dry contact's latched speed (its second pair), the film term
    nothing; its regime's events are made by the roots film_break and film_reform."""
    from daeclear.core.automaton import PairState
    scene = dc.mechanisms.slider_crank("translational").with_values({"clearance.model": "section-4.3"})
    built = dc.assemble(scene).contacts[0]
    assert dict(built.term_sensitivities(tuple(PairState() for _ in range(4)), [np.zeros(2)] * 4))[
        built.face_terms[0]].shape == (0, 2)  # Lankarani's plane law reads no approach speed
    # the rule of a face law that would (none built in does): the mean, floored at 0.2 m/s
    logic = dataclasses.replace(built, face_needs_approach=True, face_min_approach_speed=0.2)
    S = [np.array([1.0, 2.0]), np.array([3.0, 5.0]), np.array([7.0, 11.0]), np.array([13.0, 17.0])]
    fast = tuple(PairState(contact=True, latched=0.2 * (i + 1)) for i in range(4))
    rules = dict(logic.term_sensitivities(fast, S))
    (a, b), (c, d) = logic.face_corners
    assert rules[logic.face_terms[0]] == pytest.approx(0.5 * (S[a] + S[b])[None, :], rel=0, abs=0)
    assert rules[logic.face_terms[1]] == pytest.approx(0.5 * (S[c] + S[d])[None, :], rel=0, abs=0)
    for i, k in enumerate(logic.pair_terms):
        assert np.array_equal(rules[k], S[i][None, :])
    slow = tuple(PairState(contact=True, latched=0.5 * logic.face_min_approach_speed) for _ in range(4))
    assert np.array_equal(dict(logic.term_sensitivities(slow, S))[logic.face_terms[0]], np.zeros((1, 2)))
    found = np.zeros(len(logic.pairs))
    found[b] = 1
    first = logic.first_root
    assert logic.event_roots(logic.face_names[0], found) == [first + b]
    assert logic.event_roots(logic.pairs[b], found) == [first + b] and logic.event_roots(logic.pairs[a], found) == []
    journal = dc.Scene("journal")
    body = journal.add(dc.Body("journal", mass=1.0, inertia=1e-4))
    journal.add(dc.RevoluteClearance("bearing", journal.ground, body, at=(0.0, 0.0), bearing_radius=0.01,
                                     clearance=5e-5, material=dcc.Material(young=207e9, poisson=0.3),
                                     law=dcc.HydrodynamicBearing(viscosity=0.01, length=0.01)))
    lub = dc.assemble(journal).contacts[0]
    rules = dict(lub.term_sensitivities((PairState(), PairState()), [S[0], S[1]]))
    assert np.array_equal(rules[lub.pair_terms[0]], S[1][None, :]) and rules[lub.pair_terms[0] + 1].shape == (0, 2)
    found = np.array([0, -1, 0])
    assert lub.event_roots("bearing.regime", found) == [lub.first_root + 1]
    assert lub.event_roots("bearing", found) == []
    assert (lub.rate_output, lub.rate_index(lub.first_root + 2)) == (3, 0)


START_MOVERS = ["drive.speed", "B.s_i[0]", "A.s_j[0]", "clearance.s_i[1]", "D.s_i[1]", "rod.mass",
                "clearance.clearance"]


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_constrained_start_sensitivities_against_differences(formulation, index1, ggl) -> None:
    """The chapter's start of the slider-crank is fixed by its constraints (9 of them, 9 coordinates): its
    dy0/dp from the differentiated constraints equals the central differences of moved starts it replaces, for
    the drive's speed, joint offsets and the crank's length (which move it) and a mass and the clearance
    (which do not: exactly 0, the ideal start centres the journal)."""
    model = ggl if formulation == "ggl" else index1
    S = ModelSensitivity(model, START_MOVERS).constrained_start()
    assert S is not None
    want = initial_sensitivities(model, START_MOVERS)
    n = 2 * model.n_q
    for j, name in enumerate(START_MOVERS):
        scale = np.abs(want[:n, j]).max()
        assert np.abs(S[:n, j] - want[:n, j]).max() <= 1e-9 * max(scale, 1.0), name
    assert np.all(S[:, -2:] == 0.0) and np.all(S[n:] == 0.0)
    w = model.parameter("drive.speed")[0]
    y0 = model.initial_state()[0]
    assert S[model.n_q:n, 0] == pytest.approx(y0[model.n_q:n] / w, rel=1e-12, abs=1e-15)  # v0 proportional to w


def test_start_sensitivities_difference_a_start_its_constraints_do_not_fix() -> None:
    """An open chain (21 constraints, 30 coordinates) and a declared start: no constrained derivative; the
    run's dy0/dp is then the central differences'."""
    chain = dc.assemble(dc.mechanisms.chain(3, rpm=300.0))
    names = ["pin2.clearance", "link2.mass"]
    ms = ModelSensitivity(chain, names)
    assert len(chain.start_constraint_names) < chain.n_q and ms.constrained_start() is None
    np.testing.assert_array_equal(ms.start(), initial_sensitivities(chain, names))
    crank = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    np.testing.assert_array_equal(ModelSensitivity(crank, ["drive.speed"]).start("declared"),
                                  initial_sensitivities(crank, ["drive.speed"], start="declared"))
