"""The integrator backend (daeclear.engine.ida_session, daeclear.engine.codegen): compiled C and pure Python.

Every model here is built by hand with CasADi. Compiled libraries go to a per-run temporary
cache directory (DAECLEAR_CACHE_DIR), so each distinct model compiles once per run.
"""

from __future__ import annotations

import os
import threading
import warnings

import casadi as ca
import numpy as np
import pytest

from daeclear.engine import codegen
from daeclear.core.errors import DaeclearError, DaeclearWarning
from daeclear.engine.ida_session import (
    FLAG_MAX_STEPS,
    FLAG_STEP_COLLAPSE,
    TINY_STEP_COUNT,
    DAEFunctions,
    open_session,
)

BACKENDS = ["c", "python"]
G = 9.81


@pytest.fixture(scope="module", autouse=True)
def _cache_dir(tmp_path_factory):
    old = os.environ.get("DAECLEAR_CACHE_DIR")
    os.environ["DAECLEAR_CACHE_DIR"] = str(tmp_path_factory.mktemp("dccache"))
    yield
    if old is None:
        os.environ.pop("DAECLEAR_CACHE_DIR", None)
    else:
        os.environ["DAECLEAR_CACHE_DIR"] = old


def _J(r, y, yp, cj):
    return ca.jacobian(r, y) + cj * ca.jacobian(r, yp)


# --------------------------------------------------------------------------- models


def linear_model(k=2.0, sym=ca.SX, name="linear"):
    """y' = -k y."""
    t, y, yp, cj = sym.sym("t"), sym.sym("y", 1), sym.sym("yp", 1), sym.sym("cj")
    r = yp + k * y
    return DAEFunctions(1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
                        (), (), None, name)


def ball_model(K=1e7):
    """Bouncing ball y = [x, v]: x' = v, v' = -g (+ K max(-x, 0)^1.5 while the contact term is on)."""
    t, y, yp, cj, p = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj"), ca.SX.sym("p", 1)
    r = ca.vertcat(yp[0] - y[1], yp[1] + G)
    rt = ca.vertcat(0, -K * ca.fmax(-y[0], 0) ** 1.5 * p[0])  # p[0] = 1: a parameter that matters
    return DAEFunctions(
        2, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
        (ca.Function("contact", [t, y, yp, p], [rt]),),
        (ca.Function("contact_J", [t, y, yp, p, cj], [_J(rt, y, yp, cj)]),),
        ca.Function("gap", [t, y, yp], [y[0]]), "ball",
    )


def pendulum_model(alpha=5.0, beta=5.0):
    """Planar pendulum, index-1 with Baumgarte: y = [x, y, u, v, lambda]."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 5), ca.SX.sym("yp", 5), ca.SX.sym("cj")
    x, z, u, v, lam = (y[i] for i in range(5))
    phi = (x**2 + z**2 - 1) / 2
    dphi = x * u + z * v
    r = ca.vertcat(
        yp[0] - u,
        yp[1] - v,
        yp[2] + lam * x,
        yp[3] + lam * z + G,
        x * yp[2] + z * yp[3] + u**2 + v**2 + 2 * alpha * dphi + beta**2 * phi,
    )
    return DAEFunctions(5, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
                        (), (), None, "pendulum")


def nan_model():
    """y' = -1 - 1e-3 sqrt(y - 1/2): the residual is NaN once y < 1/2 (near t = 0.5)."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 1), ca.SX.sym("yp", 1), ca.SX.sym("cj")
    r = yp + 1 + 1e-3 * ca.sqrt(y - 0.5)
    return DAEFunctions(1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
                        (), (), None, "nan_model")


def hertz_max_penetration(H, K):
    """delta with 0.4 K delta^2.5 = g (H + delta) (energy balance, gravity included)."""
    d = (2.5 * G * H / K) ** 0.4
    for _ in range(50):
        d = (2.5 * G * (H + d) / K) ** 0.4
    return d


def bounce(session, H=1.0, t_end=5.0, t_eval=None):
    """Drive the event loop by hand: root -> toggle the contact term -> reinit."""
    active = False
    session.reinit(0.0, [H, 0.0], [0.0, -G], [active], [np.ones(1)])
    roots, segs = [], []
    while True:
        a = session.advance(t_end, t_eval=t_eval)
        segs.append(a)
        if a.status != "root":
            break
        roots.append((a.t, int(a.roots_found[0]), a.y.copy(), active))
        active = not active
        session.reinit(a.t, a.y, a.yp, [active], [np.ones(1)])
    return roots, segs


# --------------------------------------------------------------------------- 1. linear ODE


@pytest.mark.parametrize("backend", BACKENDS)
def test_linear_ode_matches_exponential(backend):
    k, rtol = 2.0, 1e-8
    s = open_session(linear_model(k), backend=backend, rtol=rtol, atol=1e-12)
    assert s.backend == backend
    s.reinit(0.0, [1.0], [-k], [], [])
    te = np.linspace(0.0, 3.0, 31)
    a = s.advance(3.0, t_eval=te)
    assert a.status == "tstop" and a.t == 3.0
    assert a.flag == 0 and a.roots_found is None
    assert abs(a.y[0] - np.exp(-k * 3.0)) < 20 * rtol * 1.0
    np.testing.assert_allclose(a.step_y[:, 0], np.exp(-k * a.step_t), rtol=0, atol=20 * rtol)
    np.testing.assert_allclose(a.step_yp[:, 0], -k * np.exp(-k * a.step_t), rtol=0, atol=200 * rtol)
    # t_eval: points in (0, 3]; t = 0 is the caller's own initial state
    np.testing.assert_array_equal(a.eval_t, te[1:])
    np.testing.assert_allclose(a.eval_y[:, 0], np.exp(-k * te[1:]), rtol=0, atol=20 * rtol)
    assert np.all(np.diff(a.step_t) > 0) and a.step_t[-1] == 3.0
    assert np.all(a.step_h > 0)
    st = s.stats()
    assert st["n_steps"] == len(a.step_t) and st["n_reinits"] == 1
    assert st["n_res_evals"] > st["n_steps"] and st["solve_time"] > 0
    s.close()


def test_linear_ode_backends_agree_and_chunking_is_transparent():
    outs = {}
    for backend, buf in [("c", 4096), ("c", 7), ("python", 4096)]:
        # "dense": the LU the python backend uses, so that both take the same steps
        with open_session(linear_model(), backend=backend, rtol=1e-8, atol=1e-12, buffer_steps=buf,
                          linear_solver="dense") as s:
            s.reinit(0.0, [1.0], [-2.0], [], [])
            outs[backend, buf] = s.advance(2.0), s.stats()
    ref, ref_stats = outs["c", 4096]
    for a, st in outs.values():
        np.testing.assert_array_equal(a.step_t, ref.step_t)  # same IDA, same steps
        np.testing.assert_allclose(a.step_y, ref.step_y, rtol=1e-13, atol=0)
        assert st["n_steps"] == ref_stats["n_steps"] and st["n_res_evals"] == ref_stats["n_res_evals"]
    np.testing.assert_array_equal(outs["c", 7][0].step_order, ref.step_order)
    assert set(np.unique(ref.step_order)) <= {1, 2, 3, 4, 5}
    assert np.all(outs["python", 4096][0].step_order == -1)


def test_mx_functions_compile():
    s = open_session(linear_model(sym=ca.MX, name="linear_mx"), backend="c", rtol=1e-8, atol=1e-12)
    s.reinit(0.0, [1.0], [-2.0], [], [])
    a = s.advance(1.0)
    assert abs(a.y[0] - np.exp(-2.0)) < 1e-7


# --------------------------------------------------------------------------- 2. bouncing ball


@pytest.fixture(scope="module")
def bounces():
    out = {}
    for backend in BACKENDS:
        s = open_session(ball_model(), backend=backend, rtol=1e-9, atol=np.array([1e-12, 1e-10]))
        roots, segs = bounce(s, t_eval=np.linspace(0, 5, 501))
        out[backend] = (roots, segs, s.stats())
    return out


@pytest.mark.parametrize("backend", BACKENDS)
def test_ball_energy_and_penetration(bounces, backend):
    H, K = 1.0, 1e7
    roots, segs, stats = bounces[backend]
    assert segs[-1].status == "tstop" and segs[-1].t == 5.0
    assert len(roots) == 12  # 6 impacts in 5 s (period 2 sqrt(2H/g) plus contact time)
    # directions alternate (onset -1, separation +1): no root is reported twice at a restart
    assert [r[1] for r in roots] == [-1, +1] * 6
    for t, direction, y, _active in roots:
        energy = 0.5 * y[1] ** 2 + G * y[0]
        assert abs(energy - G * H) < 1e-5 * G * H, (t, energy)
        assert abs(y[0]) < 1e-12  # IDA's root is within roundoff of the crossing...
        assert np.sign(y[0]) in (0.0, float(direction))  # ...and on its far side
    xs = np.concatenate([a.step_y[:, 0] for a in segs])
    dmax = hertz_max_penetration(H, K)
    assert xs.min() >= -dmax * (1 + 1e-4)
    assert xs.min() <= -dmax * (1 - 1e-3)  # and the contact does reach it
    # t_eval across segments: each point exactly once, all on the trajectory
    eval_t = np.concatenate([a.eval_t for a in segs])
    np.testing.assert_array_equal(eval_t, np.linspace(0, 5, 501)[1:])


def test_ball_root_times_agree_between_backends(bounces):
    tc = np.array([r[0] for r in bounces["c"][0]])
    tp = np.array([r[0] for r in bounces["python"][0]])
    np.testing.assert_allclose(tc, tp, rtol=0, atol=1e-8)
    # free flight from rest: first impact at sqrt(2H/g)
    assert abs(tc[0] - np.sqrt(2 / G)) < 1e-7


@pytest.mark.parametrize("backend", BACKENDS)
def test_ball_stats_are_cumulative(bounces, backend):
    roots, segs, stats = bounces[backend]
    assert stats["n_reinits"] == len(roots) + 1
    # every recorded point is one IDA step (root points: the step that contains the root)
    assert stats["n_steps"] == sum(len(a.step_t) for a in segs)
    assert stats["n_res_evals"] > stats["n_steps"]
    assert stats["n_root_evals"] > stats["n_steps"]
    assert stats["n_jac_evals"] > len(segs)


def test_stats_grow_across_reinits():
    s = open_session(ball_model(), backend="c", rtol=1e-8, atol=np.array([1e-12, 1e-10]))
    s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.ones(1)])
    history = []
    for _ in range(4):
        a = s.advance(5.0)
        history.append(s.stats())
        s.reinit(a.t, a.y, a.yp, [a.y[1] < 0], [np.ones(1)])
    for key in ("n_steps", "n_res_evals", "n_jac_evals", "n_lin_setups", "n_nonlin_iters", "n_root_evals"):
        vals = [h[key] for h in history]
        assert all(b > a for a, b in zip(vals, vals[1:])), (key, vals)
    assert s.stats()["n_reinits"] == 5


# --------------------------------------------------------------------------- restart behaviour of IDA


@pytest.mark.parametrize("backend", BACKENDS)
def test_root_at_restart_point(backend):
    """What IDA (SUNDIALS 7.9) does with a root function at or near 0 at t0 (the event logic relies on it)."""
    s = open_session(ball_model(), backend=backend, rtol=1e-9, atol=np.array([1e-12, 1e-10]))

    def run(x0, v0, rd=None):
        s.reinit(0.0, [x0, v0], [v0, -G], [False], [np.ones(1)], root_directions=rd)
        return s.advance(0.5)

    # exactly 0 at t0: inactive until it leaves 0, no root at t0 (moving down: none at all)
    a = run(0.0, -1.0)
    assert a.status == "tstop"
    # exactly 0 moving up: the next crossing (down, at 2 v0 / g) is reported
    a = run(0.0, 1.0)
    assert a.status == "root" and a.roots_found[0] == -1 and abs(a.t - 2 / G) < 1e-9
    # tiny on the far side of the crossing already (what a root return gives): nothing
    a = run(-1e-15, -1.0)
    assert a.status == "tstop"
    # tiny on the near side and heading for 0: reported again right away
    a = run(1e-15, -1.0)
    assert a.status == "root" and a.t < 1e-12
    # ... unless that direction is masked for this segment
    a = run(1e-15, -1.0, rd=[1])
    assert a.status == "tstop"


# --------------------------------------------------------------------------- 3. index-1 DAE


@pytest.fixture(scope="module")
def pendulum_runs():
    rtol = 1e-8
    atol = np.array([1e-10] * 4 + [1e12 * rtol])  # multiplier out of the error test
    y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.0])
    yp0 = np.array([0.0, 0.0, 0.0, -G, 0.0])
    out = {}
    for backend in BACKENDS:
        s = open_session(pendulum_model(), backend=backend, rtol=rtol, atol=atol, linear_solver="dense")
        s.reinit(0.0, y0, yp0, [], [])
        a = s.advance(3.0)
        # same run again with t_eval: IDA is deterministic, so the steps are identical
        s.reinit(0.0, y0, yp0, [], [])
        te = np.concatenate([a.step_t[5:200:7], np.linspace(0.001, 2.999, 97)])
        te.sort()
        b = s.advance(3.0, t_eval=te)
        out[backend] = (a, b, te, s)
    return out


def test_dae_backends_agree(pendulum_runs):
    a_c, _, _, _ = pendulum_runs["c"]
    a_p, _, _, _ = pendulum_runs["python"]
    np.testing.assert_array_equal(a_c.step_t, a_p.step_t)
    np.testing.assert_allclose(a_c.step_y[:, :4], a_p.step_y[:, :4], rtol=0, atol=1e-10)
    np.testing.assert_allclose(a_c.y, a_p.y, rtol=1e-8, atol=1e-8)
    # the constraint stays satisfied; lambda is the rod tension (> 0 while swinging)
    x, z = a_c.step_y[:, 0], a_c.step_y[:, 1]
    assert np.max(np.abs(x**2 + z**2 - 1)) < 1e-6
    assert np.median(a_c.step_y[:, 4]) > 0


@pytest.mark.parametrize("backend", BACKENDS)
def test_dae_t_eval_matches_steps(pendulum_runs, backend):
    a, b, te, s = pendulum_runs[backend]
    np.testing.assert_array_equal(b.step_t, a.step_t)
    np.testing.assert_array_equal(b.eval_t, te)
    on_steps = np.isin(te, a.step_t)
    idx = np.searchsorted(a.step_t, te[on_steps])
    # at a step time the interpolant returns the step itself
    np.testing.assert_allclose(b.eval_y[on_steps], a.step_y[idx], rtol=0, atol=1e-12)
    # between steps: agrees with a cubic Hermite interpolation of the stored steps
    t_all = np.concatenate([[0.0], a.step_t])
    y_all = np.vstack([[1.0, 0, 0, 0, 0], a.step_y])
    yp_all = np.vstack([[0.0, 0, 0, -G, 0], a.step_yp])
    j = np.clip(np.searchsorted(t_all, te) - 1, 0, len(t_all) - 2)
    h = t_all[j + 1] - t_all[j]
    u = ((te - t_all[j]) / h)[:, None]
    herm = ((2 * u**3 - 3 * u**2 + 1) * y_all[j] + (u**3 - 2 * u**2 + u) * h[:, None] * yp_all[j]
            + (-2 * u**3 + 3 * u**2) * y_all[j + 1] + (u**3 - u**2) * h[:, None] * yp_all[j + 1])
    np.testing.assert_allclose(b.eval_y[:, :4], herm[:, :4], rtol=0, atol=1e-7)
    # yp from the interpolant: consistent with the kinematics x' = u
    np.testing.assert_allclose(b.eval_yp[:, 0], b.eval_y[:, 2], rtol=0, atol=1e-5)


@pytest.mark.parametrize("backend", BACKENDS)
def test_no_yp_when_not_asked(pendulum_runs, backend):
    """store_yp=False: the same run (steps and output rows bit for bit) without yp at the steps or the
    output times; output rows that fill their buffer are handed over as it, a partial window as a copy."""
    a, b, te, s = pendulum_runs[backend]
    y0, yp0 = np.array([1.0, 0, 0, 0, 0]), np.array([0.0, 0, 0, -G, 0])
    s.reinit(0.0, y0, yp0, [], [])
    c = s.advance(3.0, t_eval=te, store_yp=False)
    assert c.step_yp is None and c.eval_yp is None
    np.testing.assert_array_equal(c.step_t, b.step_t)
    np.testing.assert_array_equal(c.step_y, b.step_y)
    np.testing.assert_array_equal(c.eval_y, b.eval_y)
    assert c.eval_y.shape == (te.size, 5) and c.eval_y.base is None  # every row filled: the buffer itself
    partial = []
    for store_yp in (False, True):  # stops before the last output times: the rows so far
        s.reinit(0.0, y0, yp0, [], [])
        partial.append(s.advance(1.5, t_eval=te, store_yp=store_yp))
    n = int(np.searchsorted(te, 1.5, side="right"))
    d, e = partial
    assert 0 < n < te.size and d.eval_y.shape == (n, 5) and d.eval_y.base is None  # a copy of the rows
    assert d.eval_yp is None and e.eval_yp.shape == (n, 5) and e.eval_yp.base is None
    np.testing.assert_array_equal(d.eval_y, e.eval_y)
    np.testing.assert_array_equal(d.step_y, e.step_y)


# --------------------------------------------------------------------------- 4. residual / Jacobian


@pytest.mark.parametrize("backend", BACKENDS)
def test_residual_and_jacobian(backend):
    funcs = ball_model()
    s = open_session(funcs, backend=backend, rtol=1e-8, atol=1e-10)
    y, yp, t, cj = np.array([-3e-3, -2.0]), np.array([-2.0, 5.0]), 0.3, 123.0
    for active, p in [(False, 1.0), (True, 1.0), (True, 0.5)]:
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [active], [np.array([p])])
        direct = np.array(funcs.residual(t, y, yp)).ravel()
        if active:
            direct = direct + np.array(funcs.term_residuals[0](t, y, yp, p)).ravel()
        np.testing.assert_allclose(s.residual(t, y, yp), direct, rtol=1e-14, atol=1e-12)
        J = s.jacobian(t, y, yp, cj)
        assert J.shape == (2, 2)
        J_direct = np.array(ca.densify(funcs.jacobian(t, y, yp, cj)))
        if active:
            J_direct = J_direct + np.array(ca.densify(funcs.term_jacobians[0](t, y, yp, p, cj)))
        np.testing.assert_allclose(J, J_direct, rtol=1e-14, atol=1e-12)
        # finite differences: J = dr/dy + cj dr/dyp
        fd = np.zeros((2, 2))
        for j in range(2):
            e = np.zeros(2)
            e[j] = 1e-7
            fd[:, j] = (s.residual(t, y + e, yp) - s.residual(t, y - e, yp)) / 2e-7
            fd[:, j] += cj * (s.residual(t, y, yp + e) - s.residual(t, y, yp - e)) / 2e-7
        np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-6 * np.abs(J).max())
        assert s.roots(t, y, yp).tolist() == [y[0]]


def test_dense_jacobian_from_sparse_pattern():
    """A model whose Jacobian has structural zeros and a row-vector output still densifies correctly."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 3), ca.SX.sym("yp", 3), ca.SX.sym("cj")
    r = ca.vertcat(yp[0] + y[2], yp[1] - y[0] * y[1], y[2] - y[0] ** 2)
    J = _J(r, y, yp, cj)
    assert J.nnz() < 9
    funcs = DAEFunctions(3, ca.Function("res", [t, y, yp], [r.T]),  # row-vector output
                         ca.Function("Jac", [t, y, yp, cj], [J]), (), (), None, "sparse3")
    s = open_session(funcs, backend="c", rtol=1e-8, atol=1e-10)
    yv, ypv = np.array([0.5, 2.0, 0.25]), np.array([0.1, -0.2, 0.3])
    J_ref = np.array(ca.densify(funcs.jacobian(0.0, yv, ypv, 7.0)))
    np.testing.assert_allclose(s.jacobian(0.0, yv, ypv, 7.0), J_ref, rtol=1e-14)
    np.testing.assert_allclose(s.residual(0.0, yv, ypv), np.array(funcs.residual(0.0, yv, ypv)).ravel(), rtol=1e-14)


# --------------------------------------------------------------------------- 5. cache


def test_cache_hit_and_miss():
    s1 = open_session(ball_model(K=3.3e6), backend="c", rtol=1e-8, atol=1e-10)
    st1 = s1.stats()
    assert st1["cache_hit"] is False and st1["compile_time"] > 0
    s2 = open_session(ball_model(K=3.3e6), backend="c", rtol=1e-6, atol=1e-9)  # same model
    st2 = s2.stats()
    assert st2["cache_hit"] is True and st2["compile_time"] == 0.0
    assert s2.library_path == s1.library_path
    s3 = open_session(ball_model(K=3.4e6), backend="c", rtol=1e-8, atol=1e-10)  # different model
    assert s3.stats()["cache_hit"] is False
    assert s3.library_path != s1.library_path
    # the two libraries live side by side, both usable in one process
    for s in (s1, s3):
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.ones(1)])
        assert s.advance(1.0).status == "root"


def test_concurrent_builds_of_one_model(tmp_path, monkeypatch):
    monkeypatch.setenv("DAECLEAR_CACHE_DIR", str(tmp_path))
    funcs = linear_model(k=7.25, name="concurrent")
    results, errors = [], []

    def build():
        try:
            results.append(codegen.build_model_library(funcs))
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=build) for _ in range(3)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    assert len({r.path for r in results}) == 1
    assert sorted(r.cache_hit for r in results) == [False, True, True]  # compiled once
    assert len(list(tmp_path.glob("*.so"))) == 1
    assert not [p for p in tmp_path.iterdir() if p.is_dir()]  # no temporary build directory left


# --------------------------------------------------------------------------- 6. errors


@pytest.mark.parametrize("backend", BACKENDS)
def test_nan_residual_is_an_error_not_a_hang(backend):
    s = open_session(nan_model(), backend=backend, rtol=1e-8, atol=1e-10)
    s.reinit(0.0, [1.0], [-1 - 1e-3 * np.sqrt(0.5)], [], [])
    a = s.advance(2.0)
    assert a.status == "error"
    assert 0.45 < a.t < 0.51
    assert np.all(np.isfinite(a.y)) and np.all(np.isfinite(a.step_y))
    assert a.flag != 0 and a.flag_name
    assert "nan" in a.message.lower() or "inf" in a.message.lower()
    assert a.flag_name in ("IDA_RES_FAIL", "IDA_REP_RES_ERR", "IDA_CONV_FAIL", "IDA_ERR_FAIL", "DC_STEP_COLLAPSE")
    if a.flag == FLAG_STEP_COLLAPSE:
        assert "collapsed" in a.message


@pytest.mark.parametrize("backend", BACKENDS)
def test_step_cap(backend):
    s = open_session(linear_model(), backend=backend, rtol=1e-8, atol=1e-12, max_steps=5)
    s.reinit(0.0, [1.0], [-2.0], [], [])
    a = s.advance(1.0)
    assert a.status == "error" and a.flag == FLAG_MAX_STEPS and a.flag_name == "DC_MAX_STEPS"
    assert "max_steps=5" in a.message
    assert len(a.step_t) == 5 and a.t == a.step_t[-1] < 1.0
    assert s.stats()["n_steps"] == 5


@pytest.mark.parametrize("backend", BACKENDS)
def test_usage_errors(backend):
    s = open_session(ball_model(), backend=backend, rtol=1e-8, atol=1e-10)
    with pytest.raises(DaeclearError, match="before reinit"):
        s.advance(1.0)
    with pytest.raises(ValueError, match="active"):
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [True, False], [np.ones(1)])
    with pytest.raises(ValueError, match="params"):
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [True], [np.ones(2)])
    with pytest.raises(ValueError, match="y0"):
        s.reinit(0.0, [1.0], [0.0, -G], [True], [np.ones(1)])
    with pytest.raises(ValueError, match="root_directions"):
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.ones(1)], root_directions=[2])
    s.reinit(0.5, [1.0, 0.0], [0.0, -G], [False], [None])
    a = s.advance(0.5)  # nothing to do
    assert a.status == "tstop" and a.t == 0.5 and len(a.step_t) == 0
    with pytest.raises(ValueError, match="behind"):
        s.advance(0.25)
    s.close()
    with pytest.raises(DaeclearError, match="closed"):
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [None])


def test_option_validation():
    with pytest.raises(ValueError, match="valid backends are 'auto', 'c', 'python'"):
        open_session(linear_model(), backend="fortran", rtol=1e-6, atol=1e-8)
    with pytest.raises(ValueError, match="atol"):
        open_session(linear_model(), backend="python", rtol=1e-6, atol=[1e-8, 1e-8])
    with pytest.raises(ValueError, match="max_order"):
        open_session(linear_model(), backend="python", rtol=1e-6, atol=1e-8, max_order=6)
    assert open_session(linear_model(), backend="PYTHON", rtol=1e-6, atol=1e-8).backend == "python"


# --------------------------------------------------------------------------- 7. fallback


def test_fallback_without_compiler(monkeypatch, tmp_path):
    missing = str(tmp_path / "no-such-cc")
    monkeypatch.setenv("CC", missing)
    with pytest.warns(DaeclearWarning, match="no-such-cc") as rec:
        s = open_session(linear_model(), backend="auto", rtol=1e-8, atol=1e-12)
    assert "slower" in str(rec[0].message)
    assert s.backend == "python"
    s.reinit(0.0, [1.0], [-2.0], [], [])
    assert abs(s.advance(1.0).y[0] - np.exp(-2.0)) < 1e-7
    with warnings.catch_warnings():  # warned once per reason
        warnings.simplefilter("error")
        assert open_session(linear_model(), backend="auto", rtol=1e-8, atol=1e-12).backend == "python"
    with pytest.raises(DaeclearError, match="no C compiler found"):
        open_session(linear_model(), backend="c", rtol=1e-8, atol=1e-12)


def test_fallback_when_compilation_fails(monkeypatch, tmp_path):
    monkeypatch.setenv("CC", "false")  # a compiler that always fails
    monkeypatch.setenv("DAECLEAR_CACHE_DIR", str(tmp_path))
    with pytest.warns(DaeclearWarning, match="compiling the model"):
        s = open_session(linear_model(k=1.5, name="failing"), backend="auto", rtol=1e-8, atol=1e-12)
    assert s.backend == "python"
    with pytest.raises(DaeclearError, match="compiling the model 'failing' failed"):
        open_session(linear_model(k=1.5, name="failing"), backend="c", rtol=1e-8, atol=1e-12)


# --------------------------------------------------------------------------- more behaviour


def test_continue_after_root_without_reinit():
    """A root the event logic ignores: advance again, IDA carries on with its history."""
    out = {}
    for backend in BACKENDS:
        s = open_session(ball_model(), backend=backend, rtol=1e-9, atol=np.array([1e-12, 1e-10]))
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [None])
        a = s.advance(1.0)
        assert a.status == "root" and a.roots_found.tolist() == [-1]
        b = s.advance(1.0)  # the ball falls through the floor: no more roots
        assert b.status == "tstop" and b.t == 1.0
        assert b.step_t[0] > a.t
        np.testing.assert_allclose(b.y, [1.0 - G / 2, -G], rtol=1e-7)
        out[backend] = (a, b, s.stats())
    np.testing.assert_array_equal(out["c"][1].step_t, out["python"][1].step_t)
    assert out["c"][2]["n_steps"] == out["python"][2]["n_steps"]


def test_term_without_parameters_and_several_terms():
    """Two terms, one with an empty parameter vector; only active terms contribute."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 1), ca.SX.sym("yp", 1), ca.SX.sym("cj")
    p0, p1 = ca.SX.sym("p", 0), ca.SX.sym("p", 2)
    r = yp + y
    r0 = 3 * y  # no parameters
    r1 = p1[0] * y + p1[1]
    funcs = DAEFunctions(
        1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
        (ca.Function("t0", [t, y, yp, p0], [r0]), ca.Function("t1", [t, y, yp, p1], [r1])),
        (ca.Function("t0J", [t, y, yp, p0, cj], [_J(r0, y, yp, cj)]),
         ca.Function("t1J", [t, y, yp, p1, cj], [_J(r1, y, yp, cj)])),
        None, "two_terms",
    )
    for backend in BACKENDS:
        s = open_session(funcs, backend=backend, rtol=1e-10, atol=1e-12)
        assert s.n_params == (0, 2)
        for active, k in [([False, False], 1.0), ([True, False], 4.0), ([True, True], 6.0)]:
            s.reinit(0.0, [1.0], [-k], active, [None, np.array([2.0, 0.0])])
            assert s.residual(0.0, np.array([1.0]), np.array([-k]))[0] == pytest.approx(0.0, abs=1e-14)
            assert s.jacobian(0.0, np.array([1.0]), np.array([0.0]), 10.0)[0, 0] == pytest.approx(k + 10.0)
            a = s.advance(0.5)
            assert a.y[0] == pytest.approx(np.exp(-k * 0.5), rel=1e-7)
            if backend == "c":  # the C loop's terms as a switch vector: flag, then parameters, per term
                expected = [float(active[0]), float(active[1]), 2.0, 0.0]
                np.testing.assert_array_equal(s.active_switch(), expected)
                flags, params = s.active_terms()
                assert flags == active and params[0].size == 0
                np.testing.assert_array_equal(params[1], [2.0, 0.0])


def test_continue_after_root_to_a_time_inside_the_last_step():
    """After a root, IDA has already stepped beyond it; a t_stop in between is interpolated."""
    out = {}
    for backend in BACKENDS:
        s = open_session(ball_model(), backend=backend, rtol=1e-9, atol=np.array([1e-12, 1e-10]))
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [None])
        a = s.advance(1.0)
        assert a.status == "root"
        t_mid = a.t + 1e-6  # well inside IDA's last step (h ~ 0.2 s in free fall)
        b = s.advance(t_mid, t_eval=[t_mid])
        assert b.status == "tstop" and b.t == t_mid, b.message
        np.testing.assert_allclose(b.y, [1 - G * t_mid**2 / 2, -G * t_mid], rtol=1e-8)
        np.testing.assert_allclose(b.eval_y[0], b.y, rtol=1e-12, atol=1e-12)
        assert b.step_t.tolist() == [t_mid]
        c = s.advance(1.0)
        assert c.status == "tstop" and c.step_t[0] > t_mid
        np.testing.assert_allclose(c.y, [1.0 - G / 2, -G], rtol=1e-7)
        out[backend] = c
    np.testing.assert_array_equal(out["c"].step_t, out["python"].step_t)


@pytest.mark.parametrize("backend", BACKENDS)
def test_tiny_initial_step_is_not_a_collapse(backend):
    """y' = 1e4 from y = 0 with atol 1e-18: IDA starts with h = 0.5/||y'||_wrms = 5e-23 and doubles."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 1), ca.SX.sym("yp", 1), ca.SX.sym("cj")
    r = yp - 1e4
    funcs = DAEFunctions(1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [_J(r, y, yp, cj)]),
                         (), (), None, "ramp")
    s = open_session(funcs, backend=backend, rtol=1e-10, atol=1e-18)
    s.reinit(0.0, [0.0], [1e4], [], [])
    a = s.advance(1.0)
    assert a.status == "tstop", a.message
    assert a.step_h[0] < 1e-22 and np.sum(a.step_h < 1e-14) > TINY_STEP_COUNT  # the start-up doubling
    assert a.y[0] == pytest.approx(1e4, rel=1e-9)


def test_extras_evaluate_over_points_like_casadi():
    """DAEFunctions.extras run in C over many points (stride 0 broadcasts) and match CasADi."""
    import casadi as ca
    import numpy as np

    from daeclear.engine.ida_session import DAEFunctions, open_session

    t, y, yp, c = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj")
    res = ca.vertcat(yp[0] - y[1], yp[1] + y[0])
    a, b = ca.SX.sym("a", 2), ca.SX.sym("b")
    extra = ca.Function("extra", [a, b], [ca.vertcat(ca.sin(a[0]) * b, a[1] ** 2, a[0] + a[1])])
    funcs = DAEFunctions(n=2, residual=ca.Function("r", [t, y, yp], [res]),
                         jacobian=ca.Function("j", [t, y, yp, c],
                                              [ca.densify(ca.jacobian(res, y) + c * ca.jacobian(res, yp))]),
                         term_residuals=(), term_jacobians=(), roots=None, name="extras_test", extras=(extra,))
    A = np.random.default_rng(1).normal(size=(50, 2))
    expected = np.array(extra.map(50)(A.T, 3.0)).T
    for backend in ("c", "python"):
        session = open_session(funcs, backend=backend, rtol=1e-8, atol=1e-10)
        got = session.eval_extra(0, [A, np.array([3.0])], 50)
        np.testing.assert_allclose(got, expected, rtol=1e-14, atol=1e-14)
        session.close()


# --------------------------------------------------------------------------- pooled C sessions


def _bounce(s, t_end=2.0):
    """Bounce the ball of ball_model to t_end or a failure: (status, t, root times, step times, y,
    the counters of stats)."""
    s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.ones(1)])
    roots, steps = [], []
    while True:
        a = s.advance(t_end)
        steps.append(a.step_t)
        if a.status != "root":
            break
        roots.append(a.t)
        s.reinit(a.t, a.y, a.yp, [a.y[1] < 0], [np.ones(1)])
    counters = {k: v for k, v in s.stats().items() if k.startswith("n_") or k == "first_step"}
    return a.status, a.t, roots, np.concatenate(steps), a.y, counters


def test_a_pooled_c_session_runs_step_for_step_as_a_new_one():
    """A closed session's C session is re-armed (dc_reset) for the next session of the same
    library: whatever the run before it set (tolerances, step limits, root directions, Newton
    hints, stall rule, a first-step choice) and however it ended, the next one runs exactly as a
    freshly opened one."""
    from daeclear.engine import c_handle

    model = ball_model()
    settings = dict(backend="c", rtol=1e-8, atol=np.array([1e-12, 1e-10]))
    c_handle._POOL.clear()
    fresh = open_session(model, **settings)
    status, t, roots, steps, y, counters = _bounce(fresh)
    assert status == "tstop" and t == 2.0 and len(roots) == 4
    fresh.close()
    c_handle._POOL.clear()  # the next session opens its own
    dirty = open_session(model, backend="c", rtol=1e-4, atol=1e-6, max_step=1e-3, max_steps=700,
                         root_directions=np.array([1]))
    dirty.set_hints(nonlin_conv_coef=0.01, jacobian_refresh=0.9, first_step=True)
    dirty.set_stall(1e-2, 3)
    assert _bounce(dirty)[0] == "error"  # the step cap, inside the flight
    dirty.close()
    assert dirty._hd.sy is None and dirty._hd.addr["sy"] is None  # pooled without the steps' state buffers
    pooled = open_session(model, **settings)
    assert pooled._hd is dirty._hd  # the same C session, reset
    # the closed session's handle now serves another session: every entry point refuses
    for call in (lambda: dirty.set_hints(jacobian_refresh=0.5), lambda: dirty.set_stall(1e-9, 5),
                 lambda: dirty.active_terms(), lambda: dirty.active_switch(), lambda: dirty.advance(3.0),
                 lambda: dirty.stats(),
                 lambda: dirty.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.ones(1)]),
                 lambda: dirty.report(np.zeros(1), np.zeros((1, 2)), np.zeros((1, 2))),
                 lambda: dirty.residual(0.0, np.zeros(2), np.zeros(2))):
        with pytest.raises(DaeclearError, match="closed"):
            call()
    again = _bounce(pooled)
    assert again[:3] == (status, t, roots)
    np.testing.assert_array_equal(again[3], steps)
    np.testing.assert_array_equal(again[4], y)
    assert again[5] == counters
    pooled.close()
    assert open_session(model, **settings)._hd is pooled._hd  # and again


def test_a_pooled_session_evaluates_extras_with_its_own_parameters():
    """The extras' sizes stay with a pooled C session (asked of CasADi once per library); the
    run-time parameters are each session's own: a session that took another's C session evaluates
    the channels of its own numbers, as CasADi does."""
    import daeclear as dc
    from daeclear.engine import c_handle

    first, second = (dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=c)) for c in (1e-4, 3e-4))
    assert first.functions is second.functions  # one library
    y = np.concatenate([first.q_guess, first.v_guess, np.zeros(first.n_states - 2 * first.n_q)])
    y[first.state_names.index("slider.x")] += 2e-4  # the journal off centre: the clearance shows
    t, yp = np.zeros(1), np.zeros_like(y)
    switch = first.switch_vector([False] * len(first.terms), [np.zeros(term.n_params) for term in first.terms])
    c_handle._POOL.clear()
    channels, handles = {}, []
    for model in (first, second):
        session = open_session(model.functions, backend="c", rtol=1e-6, atol=1e-9,
                               parameters=model.parameter_values)
        channels[id(model)] = model.channels(t, y[None, :], yp[None, :], switch[None, :], session)
        handles.append(session._hd)
        session.close()
        expected = model.channels(t, y[None, :], yp[None, :], switch[None, :])  # CasADi
        for name in ("clearance.penetration", "clearance.eccentricity"):
            np.testing.assert_allclose(channels[id(model)][name], expected[name], rtol=1e-12, atol=1e-15)
    assert handles[0] is handles[1] and handles[0].extra_meta  # the second took the first's, sizes kept
    difference = channels[id(first)]["clearance.penetration"] - channels[id(second)]["clearance.penetration"]
    np.testing.assert_allclose(difference, 2e-4, rtol=1e-9)  # the clearances' difference


def test_report_equals_the_models_python_evaluation_and_writes_into_given_arrays():
    """dc_report makes reported points consistent and evaluates the channels, one contiguous row per
    channel: equal to the model's own (CasADi) evaluation of the same points; written into the
    caller's arrays (``into``, the state array itself included) it gives the same numbers, and an
    array of another shape is refused before any work."""
    import daeclear as dc

    model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=1e-4), "index1")
    y0, yp0 = model.initial_state()
    s = open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values)
    assert s.set_layout(model.layout(project=False))
    active, params = [False] * len(model.terms), [np.full(term.n_params, 0.3) for term in model.terms]
    s.reinit(0.0, y0, yp0, active, params)  # the journal centred: free flight (its force is NaN at e = 0)
    times, rows = np.linspace(1e-4, 2e-3, 7), []
    for _ in range(20):  # on through the roots (a gap crossing zero), in free flight
        adv = s.advance(2e-3, t_eval=times)
        assert adv.status in ("root", "tstop"), adv.message
        rows.append((adv.eval_t, adv.eval_y))
        if adv.status == "tstop":
            break
    t, y = (np.concatenate(column) for column in zip(*rows))
    assert t.size == 7
    switch = np.tile(model.switch_vector(active, params), (t.size, 1))
    y_c, yp_c, channels = s.report(t, y, switch)
    assert channels.shape == (len(model.channel_names), t.size) and channels[0].flags.c_contiguous
    y_py, yp_py = model.consistent_state(t, y, model.term_forces_rows(t, y, switch, None), None)  # CasADi
    np.testing.assert_allclose(y_c, y_py, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(yp_c, yp_py, rtol=1e-9, atol=1e-9)
    by_model = model.channels(t, y_py, yp_py, switch, None)
    for name, row in zip(model.channel_names, channels):
        np.testing.assert_allclose(row, by_model[name], rtol=1e-9, atol=1e-12, err_msg=name)
    y_own, yp_own = y.copy(), np.full_like(y, np.nan)
    again = s.report(t, y_own, switch, into=(y_own, yp_own))
    assert again[0] is y_own and again[1] is yp_own
    for a, b in zip(again, (y_c, yp_c, channels)):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(ValueError, match="into"):
        s.report(t, y, switch, into=(y.copy(), np.empty((t.size + 1, model.n_states))))
    s.close()
