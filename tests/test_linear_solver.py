"""Dense, reduced, sparse and SuperLU_MT LU in the compiled IDA loop: the option, the union Jacobian
pattern the sparse solvers factor, and identical results of all on real mechanisms (the sparse LU's
plan and its factorisation: tests/test_sparse_lu.py).

Measured for the agreement tests (rtol 1e-8): slider-crank with a revolute clearance joint,
5 ms: the same 30 events within 2.5e-11 s, final state within 1.3e-8 relative; chain of 3
links, 20 ms: the same 11 events within 1.4e-12 s, final state within 2.4e-8 relative.
"""

from __future__ import annotations

import os

import casadi as ca
import numpy as np
import pytest

import daeclear as dc
from daeclear.engine import c_session, ida_session
from daeclear.core.errors import DaeclearError, SceneError
from daeclear.engine.ida_session import DAEFunctions, open_session
from daeclear.model.mechanisms import chain, slider_crank

G = 9.81


def ball_model() -> DAEFunctions:
    """Bouncing ball: the contact term adds an entry (dv'/dx) that the base Jacobian lacks."""
    t, y, yp, cj, p = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj"), ca.SX.sym("p", 1)
    r = ca.vertcat(yp[0] - y[1], yp[1] + G)
    rc = ca.vertcat(0, -1e7 * ca.fmax(-y[0], 0) ** 1.5 * (1 + p[0] * 0))

    def J(expr):
        return ca.jacobian(expr, y) + cj * ca.jacobian(expr, yp)

    return DAEFunctions(2, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [J(r)]),
                        (ca.Function("rc", [t, y, yp, p], [rc]),), (ca.Function("Jc", [t, y, yp, p, cj], [J(rc)]),),
                        ca.Function("g", [t, y, yp], [y[0]]), "ball_ls")


def dense_of(data, rows, colptr, n):
    out = np.zeros((n, n))
    for c in range(n):
        for k in range(colptr[c], colptr[c + 1]):
            out[rows[k], c] += data[k]
    return out


# --------------------------------------------------------------------------- option


def test_option_is_validated_with_a_clear_message():
    with pytest.raises(ValueError, match=r"linear_solver='banded' is not a linear solver: valid values are "
                                         r"'auto', 'reduced', 'dense', 'sparse', 'superlu'"):
        open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="banded")
    with pytest.raises(SceneError, match=r"linear_solver='lu', must be one of auto, reduced, dense, sparse, superlu"):
        dc.simulate(chain(1), 1e-3, options=dc.SolverOptions(linear_solver="lu"))
    s = open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="SPARSE")
    assert s.linear_solver == "sparse" and s.stats()["linear_solver"] == "sparse"
    s = open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="SuperLU")
    assert s.linear_solver == "superlu" and s.stats()["linear_solver"] == "superlu"


def test_auto_uses_the_measured_threshold(monkeypatch):
    s = open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8)
    assert s.linear_solver == "reduced" == s.stats()["linear_solver"] and ida_session.SPARSE_MIN_STATES > 2
    monkeypatch.setattr(c_session, "SPARSE_MIN_STATES", 2)
    assert open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8).linear_solver == "sparse"
    assert open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="dense").linear_solver == "dense"


def test_python_backend_stays_dense():
    s = open_session(ball_model(), backend="python", rtol=1e-6, atol=1e-8, linear_solver="sparse")
    assert s.linear_solver == "dense" and s.stats()["linear_solver"] == "dense"


def test_sparse_unavailable_is_a_clear_error():
    with pytest.raises(DaeclearError, match="linear_solver='superlu' is not available"):
        c_session._resolve_linear_solver("superlu", 100, has_superlu=False)
    with pytest.raises(DaeclearError, match="linear_solver='sparse' is not available for this model"):
        c_session._resolve_linear_solver("sparse", 100, has_superlu=True, has_plan=False)
    assert c_session._resolve_linear_solver("auto", 10_000, has_superlu=False) == "sparse"
    assert c_session._resolve_linear_solver("auto", 10_000, has_superlu=True, has_plan=False) == "reduced"


# --------------------------------------------------------------------------- union pattern


def test_union_pattern_holds_every_term_and_fills_like_the_dense_matrix():
    model = dc.assemble(chain(2))
    s = open_session(model.functions, backend="c", rtol=1e-6, atol=1e-8, parameters=model.parameter_values,
                     linear_solver="sparse")
    n = model.n_states
    rng = np.random.default_rng(3)
    y, yp = rng.normal(size=n), rng.normal(size=n)
    active_sets = [[False] * len(model.terms), [True] * len(model.terms)]
    params = [np.full(term.n_params, 0.7) for term in model.terms]
    for active in active_sets:
        s.set_terms(active, params)
        data, rows, colptr = s.sparse_jacobian(0.01, y, yp, 1234.5)
        assert colptr[0] == 0 and colptr[-1] == len(data) == s.stats()["jac_nnz"] < n * n
        for c in range(n):  # rows strictly increasing in each column (CSC as the plan and SuperLU_MT want)
            assert np.all(np.diff(rows[colptr[c]:colptr[c + 1]]) > 0)
        J = s.jacobian(0.01, y, yp, 1234.5)
        np.testing.assert_array_equal(dense_of(data, rows, colptr, n), J)
    # every entry any part can make is in the pattern: the active terms' entries need no new slot
    assert np.count_nonzero(J) <= len(data)


# --------------------------------------------------------------------------- same results


def both(scene, t_end: float, rtol: float = 1e-8, solvers: tuple[str, str] = ("dense", "sparse"),
         formulation: str = "ggl") -> tuple[dc.Result, dc.Result]:
    out = [dc.simulate(scene, t_end, rtol=rtol,
                       options=dc.SolverOptions(backend="c", linear_solver=ls, formulation=formulation))
           for ls in solvers]
    assert [r.stats["linear_solver"] for r in out] == list(solvers)
    return out[0], out[1]


def assert_same_run(a: dc.Result, b: dc.Result, t_tol: float, y_rtol: float) -> None:
    assert a.success and b.success
    assert [(e.pair, e.kind) for e in a.events] == [(e.pair, e.kind) for e in b.events]
    np.testing.assert_allclose([e.t for e in a.events], [e.t for e in b.events], rtol=0, atol=t_tol)
    assert a.t[-1] == b.t[-1]
    scale = np.maximum(np.abs(a.y[-1]), 1e-3 * np.abs(a.y[-1]).max())
    assert np.max(np.abs(a.y[-1] - b.y[-1]) / scale) < y_rtol


# The slider-crank comparisons run 4 ms (22 events): after that the chaotic motion amplifies the
# solvers' different rounding (the 5 ms they used to run ended 2-5e-9 s and 1-3e-6 apart when the
# model was built with FMA contraction, 4e-10 s and 2e-7 without); up to 4 ms 2.6e-10 s and 2e-7.
# With the per-quantity tolerances the 12th event (t = 1.7 ms) is a near-graze that puts sparse and
# dense 1.4e-9 s apart (1.5e-11 s with the old uniform atol; 4e-12 s with a velocity atol of 1e-11
# instead of 8.9e-12): the chaos amplifies rounding by 1e2 there, hence t_tol 3e-9.
SLIDER_CRANK_WINDOW = 0.004


@pytest.mark.parametrize("solver", ["sparse", "superlu"])
def test_sparse_and_dense_agree_on_the_slider_crank(solver):
    a, b = both(slider_crank("revolute"), SLIDER_CRANK_WINDOW, solvers=("dense", solver))
    assert len(a.events) >= 20
    assert_same_run(a, b, t_tol=3e-9, y_rtol=1e-6)


@pytest.mark.parametrize("formulation", ["ggl", "index1"])
def test_reduced_agrees_with_the_whole_dense_lu_on_the_slider_crank(formulation):
    """The reduced solver changes only IDA's iteration matrix (GGL: the q-derivative of
    Phi_q^T mu dropped), never the equations: same events and states to the tolerance."""
    a, b = both(slider_crank("revolute"), SLIDER_CRANK_WINDOW, solvers=("reduced", "dense"), formulation=formulation)
    assert len(a.events) >= 20
    assert_same_run(a, b, t_tol=1e-9, y_rtol=1e-6)


def test_reduced_agrees_with_sparse_on_a_chain_of_three():
    a, b = both(chain(3), 0.02, solvers=("reduced", "sparse"))
    assert {e.pair for e in a.events} == {"pin1", "pin2", "pin3"}
    assert_same_run(a, b, t_tol=1e-8, y_rtol=1e-6)


@pytest.mark.parametrize("formulation", ["ggl", "index1"])
def test_reduced_solve_equals_a_plain_lu(formulation):
    """J x = b by eliminating the n_q position rows equals numpy's LU of the whole J wherever the
    q-row block is diagonal: always for index1; for GGL where mu = 0 (every consistent state) and
    here also off it, because each body's angle enters Phi_q only through its own rotation, so
    d(Phi_q^T mu)/dq is diagonal. Eliminating fewer rows (none: a plain LU) gives the same."""
    model = dc.assemble(slider_crank("revolute"), formulation)
    y, yp = model.initial_state()
    s = open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values,
                     linear_solver="reduced")
    s.set_terms([False] * len(model.terms), [np.zeros(term.n_params) for term in model.terms])
    layout = model.layout(project=False)
    nq, mu = layout.n_q, slice(2 * layout.n_q + layout.n_constraints, None)
    rng = np.random.default_rng(7)
    b = rng.normal(size=model.n_states)
    for cj in (1e3, 1e7):
        J = s.jacobian(0.0, y, yp, cj)
        exact = np.linalg.solve(J, b)
        # every count of eliminated rows: the LU solve takes four columns at a time, so the factored
        # sizes n - nk cover every remainder of 4 (and nk = 0 is a plain LU)
        for nk in range(nq + 1):
            np.testing.assert_allclose(s.solve_reduced(0.0, y, yp, cj, b, nk), exact, rtol=1e-9,
                                       atol=1e-12 * np.abs(exact).max(), err_msg=f"nk={nk}")
    if formulation == "ggl":
        assert not np.any(y[mu])
        y_mu = y.copy()
        y_mu[mu] = 1e-3  # mu off the manifold: the q-row block is cj I + d(Phi_q^T mu)/dq
        J = s.jacobian(0.0, y_mu, yp, 1e3)
        block = J[:nq, :nq]
        assert np.any(np.diag(block) != 1e3) and not np.any(block - np.diag(np.diag(block)))
        exact = np.linalg.solve(J, b)
        np.testing.assert_allclose(s.solve_reduced(0.0, y_mu, yp, 1e3, b, nq), exact, rtol=1e-9,
                                   atol=1e-12 * np.abs(exact).max())


@pytest.mark.parametrize("formulation", ["ggl", "index1"])
def test_every_solver_solves_several_right_hand_sides_with_one_factorisation(formulation):
    """The one interface of the loop's solvers (csrc/dc_linsol.h): factor once, then solve_many with four
    right-hand sides at once, for the dense, reduced and sparse LU alike: each column is numpy's solution of
    the iteration matrix (the forward sensitivities will solve their right-hand sides this way)."""
    model = dc.assemble(slider_crank("revolute"), formulation)
    y, yp = model.initial_state()
    s = open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values)
    s.set_terms([False] * len(model.terms), [np.zeros(term.n_params) for term in model.terms])
    nq = model.layout(project=False).n_q
    B = np.random.default_rng(13).normal(size=(model.n_states, 4))
    J = s.jacobian(0.0, y, yp, 2e4)
    exact = np.linalg.solve(J, B)
    for solver, nk in (("dense", 0), ("reduced", nq), ("sparse", 0)):
        X, fallbacks = s.solve_linear(0.0, y, yp, 2e4, B, solver=solver, n_kinematic=nk)
        assert X.shape == B.shape and fallbacks == 0
        np.testing.assert_allclose(X, exact, rtol=0, atol=1e-10 * np.abs(exact).max(), err_msg=solver)


def test_reduced_solve_of_general_matrices():
    """The reduced solver on random matrices whose first nk rows have a diagonal block: exact
    (to round-off) for every nk, so for every size of the factored part and every remainder of
    the four-column blocks of its substitutions (a mechanism's Jacobian leaves many of the
    factors' entries zero; the dense matrices leave none), and on sparse ones (the solver keeps
    the nonzeros of J_rq in lists)."""
    model = dc.assemble(slider_crank("revolute"), "ggl")
    y, yp = model.initial_state()
    n = model.n_states
    s = open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values,
                     linear_solver="reduced")
    rng = np.random.default_rng(11)
    for nk in range(n):
        for sparse in (False, True):  # True: most of J_rq, J_qr and J_rr zero, as a mechanism's are
            A = rng.normal(size=(n, n))
            if sparse:
                A *= rng.uniform(size=(n, n)) < 0.2
            A += n * np.eye(n)
            A[:nk, :nk] = np.diag(rng.uniform(1.0, 2.0, nk))
            b = rng.normal(size=n)
            exact = np.linalg.solve(A, b)
            np.testing.assert_allclose(s.solve_reduced(0.0, y, yp, 1.0, b, nk, matrix=A), exact, rtol=1e-10,
                                       atol=1e-12 * np.abs(exact).max(), err_msg=f"nk={nk} sparse={sparse}")


@pytest.mark.parametrize("solver", ["sparse", "superlu"])
def test_sparse_and_dense_agree_on_a_chain_of_three(solver):
    a, b = both(chain(3), 0.02, solvers=("dense", solver))
    assert {e.pair for e in a.events} == {"pin1", "pin2", "pin3"}
    assert_same_run(a, b, t_tol=1e-8, y_rtol=1e-6)


def jacobian_not_finite_model(part: str) -> DAEFunctions:
    """y' = -y (two states) whose base Jacobian (part "base": entry (1, 1) inf from t = 0.5) or
    whose one term's Jacobian (part "term": entry (0, 1) NaN from t = 0.2) is not finite."""
    t, y, yp, cj, p = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj"), ca.SX.sym("p", 1)
    bad = ca.if_else(t > 0.5, ca.inf, 1) if part == "base" else 1
    rc = ca.vertcat(p[0] * y[1], 0)
    term_bad = ca.if_else(t > 0.2, np.nan, 1) if part == "term" else 1
    return DAEFunctions(2, ca.Function("res", [t, y, yp], [yp + y]),
                        ca.Function("Jac", [t, y, yp, cj], [ca.diag(ca.vertcat(cj + 1, cj + bad))]),
                        (ca.Function("rc", [t, y, yp, p], [rc]),),
                        (ca.Function("Jc", [t, y, yp, p, cj], [ca.jacobian(rc, y) * term_bad]),), None,
                        f"jac_not_finite_{part}")


def test_a_jacobian_entry_that_is_not_finite_is_named_by_every_solver():
    """The loop checks the assembled Jacobian at the positions of the base and active terms'
    patterns (the rest is zero): an inf of the base Jacobian and a NaN of an active term's are
    each found and named by row and column, and the run stops with that message."""
    for part, entry, value, after in (("base", "(1, 1)", "inf", 0.5), ("term", "(0, 1)", "nan", 0.2)):
        funcs = jacobian_not_finite_model(part)
        for ls in ("reduced", "dense", "sparse", "superlu"):
            s = open_session(funcs, backend="c", rtol=1e-6, atol=1e-8, linear_solver=ls)
            s.reinit(0.0, [1.0, 1.0], [-1.0, -1.0], [True], [np.full(1, 0.1)])
            a = s.advance(1.0)
            assert a.status == "error" and after < a.t < 1.0, (part, ls, a.status, a.t)
            assert f"Jacobian entry {entry} is {value}" in a.message, (part, ls, a.message)


def test_ball_bounces_alike():
    """A term whose Jacobian entry lies outside the base pattern: the sparse matrix has its slot."""
    out = {}
    for ls in ("dense", "sparse", "superlu"):
        s = open_session(ball_model(), backend="c", rtol=1e-9, atol=np.array([1e-12, 1e-10]), linear_solver=ls)
        s.reinit(0.0, [1.0, 0.0], [0.0, -G], [False], [np.zeros(1)])
        a = s.advance(1.0)
        assert a.status == "root"
        s.reinit(a.t, a.y, a.yp, [True], [np.zeros(1)], root_directions=[1])
        b = s.advance(1.0)
        out[ls] = (a.t, b.t, b.y, s.stats())
    for ls in ("sparse", "superlu"):
        assert out[ls][3]["jac_nnz"] == 4 and out[ls][3]["n_jac_evals"] > 0
        np.testing.assert_allclose(out["dense"][0], out[ls][0], rtol=1e-12)
        np.testing.assert_allclose(out["dense"][1], out[ls][1], rtol=1e-7)
        np.testing.assert_allclose(out["dense"][2], out[ls][2], rtol=1e-5, atol=1e-9)


# --------------------------------------------------------------------------- SuperLU_MT lifetime


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc")
def test_restarts_reuse_the_factorization_storage():
    """SUNDIALS' SuperLU_MT solver, reinitialized by IDA at every restart, would recompute its
    ordering and allocate new L/U storage each time without freeing the old: 100 kB per event
    here (60 MB over this run). The driver keeps the first factorization's storage (and the sparse
    LU's plan and storage are fixed from dc_open on)."""
    scene = chain(8)
    for solver in ("superlu", "sparse"):
        run = dict(rtol=1e-6, options=dc.SolverOptions(backend="c", linear_solver=solver),
                   save=dc.SaveAt(steps=False, times=[0.1]))
        dc.simulate(scene, 0.1, **run)  # warm: compiled, first allocations done
        before = _rss_mb()
        result = dc.simulate(scene, 0.1, **run)
        assert result.stats["n_reinits"] > 500 and result.stats["linear_solver"] == solver
        assert _rss_mb() - before < 10.0


def test_sessions_closed_before_any_step_free_cleanly():
    """A SuperLU_MT solver that never factorized cannot be freed as is (SUNDIALS reads its
    uninitialized options): the driver factors an identity first. Must not crash."""
    for _ in range(3):
        s = open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="superlu")
        s.close()
    s = open_session(ball_model(), backend="c", rtol=1e-6, atol=1e-8, linear_solver="superlu")
    del s


# --------------------------------------------------------------------------- first step


def test_first_step_is_the_second_order_estimate(plain_ida):
    """The run's first step is h = 1/sqrt(|q''|_wrms) from the consistent accelerations (never
    below IDA's 0.5/|y'|_wrms), computed here again in numpy; IDA's own estimate is 1e-16 s on
    the four-bar, and GGL's Newton iteration failed from it at rtol 1e-9 (ida_driver.c)."""
    from daeclear.model import mechanisms as M
    from daeclear.solvers import ida
    from daeclear.solvers.tolerances import tolerance_vector

    model, rtol = dc.assemble(M.four_bar()), 1e-9
    y, yp = model.initial_state()
    w = 1.0 / (rtol * np.abs(y) + tolerance_vector(model, rtol, None))
    nq, n = model.layout(project=False).n_q, model.n_states
    h_ida = 0.5 / np.sqrt(np.sum((w * yp) ** 2) / n)
    expected = max(1.0 / np.sqrt(np.sqrt(np.sum((w[:nq] * yp[nq:2 * nq]) ** 2) / n)), h_ida)
    plain = dc.simulate(model, 1e-4, rtol=rtol, options=dc.SolverOptions(backend="c", linear_solver=plain_ida))
    # IDA's estimate: 1e-16 s with the old uniform atol (1e-3 rtol), 1e-14 s with the per-quantity defaults
    assert plain.stats["first_step"] == pytest.approx(h_ida, rel=1e-6, abs=0.0) and h_ida < 1e-13
    ida.FIRST_STEP_ESTIMATE = True  # undone by plain_ida's monkeypatch
    run = dc.simulate(model, 1e-4, rtol=rtol, options=dc.SolverOptions(backend="c", linear_solver=plain_ida))
    assert not run.events and run.stats["first_step"] == pytest.approx(expected, rel=1e-9, abs=0.0) and expected > 1e-9
