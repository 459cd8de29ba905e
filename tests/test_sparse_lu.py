"""The sparse LU of the Newton matrix: its plan (daeclear/engine/sparse_plan.py: union pattern, pivot
order, the factors' pattern) and its factorisation in C (csrc/dc_sparse_lu.h), against numpy's dense
LU with partial pivoting, on mechanisms' Jacobians and on the ill-conditioned matrices its pivot tests
exist for."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import DaeclearError
from daeclear.engine import c_session
from daeclear.engine.codegen import normalize_model
from daeclear.engine.ida_session import DAEFunctions, open_session
from daeclear.engine.sparse_plan import make_plan, plan_of_model
from daeclear.model.mechanisms import chain, four_bar, slider_crank

#: mechanisms whose Newton matrices have multipliers (KKT-like zero diagonal blocks) and contact terms
MODELS = [(lambda: slider_crank("revolute"), "ggl"), (lambda: slider_crank("revolute"), "index1"),
          (lambda: four_bar(), "ggl"), (lambda: chain(5, rpm=300), "index1"), (lambda: chain(4), "ggl")]


def plan_and_model(make, formulation):
    model = dc.assemble(make(), formulation)
    return plan_of_model(normalize_model(model.functions)), model


def dense(plan, data):
    """The n x n matrix of union values ``data``."""
    A = np.zeros((plan.n, plan.n))
    for c in range(plan.n):
        A[plan.rowind[plan.colptr[c]:plan.colptr[c + 1]], c] = data[plan.colptr[c]:plan.colptr[c + 1]]
    return A


def static_lu(A, perm):
    """LU without pivoting of A[perm][:, perm] (numpy, dense): the factorisation the plan prescribes."""
    B = A[np.ix_(perm, perm)].copy()
    n = len(perm)
    for k in range(n):
        B[k + 1:, k] /= B[k, k]
        B[k + 1:, k + 1:] -= np.outer(B[k + 1:, k], B[k, k + 1:])
    return B


def static_solve(A, perm, b):
    F = static_lu(A, perm)
    L, U = np.tril(F, -1) + np.eye(len(perm)), np.triu(F)
    x = np.linalg.solve(U, np.linalg.solve(L, b[perm]))
    out = np.empty_like(x)
    out[perm] = x
    return out


def session(model, solver="sparse"):
    return open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values,
                        linear_solver=solver)


def jacobian_point(model, s, seed=1):
    """A state near the start (journals off centre: every contact term's Jacobian finite), every term on."""
    rng = np.random.default_rng(seed)
    y, yp = model.initial_state()
    s.set_terms([True] * len(model.terms), [np.full(t.n_params, 0.5) for t in model.terms])
    return y + 1e-5 * rng.normal(size=model.n_states), yp


# --------------------------------------------------------------------------- the plan


@pytest.mark.parametrize("make, formulation", MODELS[:4])
def test_multipliers_come_after_every_unknown_their_equations_touch(make, formulation):
    """A multiplier (structurally zero diagonal) is eliminated after every unknown with a diagonal that its
    row or column holds: its pivot is then its whole constraint's -b P b^T, not one coordinate's."""
    plan, model = plan_and_model(make, formulation)
    assert plan.available and sorted(plan.perm.tolist()) == list(range(plan.n))
    where = np.empty(plan.n, dtype=int)
    where[plan.perm] = np.arange(plan.n)
    A = dense(plan, np.ones(plan.nnz)) != 0
    multipliers = [i for i in range(plan.n) if not A[i, i]]
    names = model.state_names
    assert multipliers and all(names[i].startswith(("lambda", "mu")) for i in multipliers)
    for z in multipliers:
        touched = [u for u in np.nonzero(A[z, :] | A[:, z])[0] if A[u, u]]
        assert touched and all(where[u] < where[z] for u in touched), names[z]


@pytest.mark.parametrize("make, formulation", MODELS)
def test_the_factors_pattern_holds_every_nonzero_of_a_plain_lu(make, formulation):
    """numpy's LU without pivoting of the permuted matrix, with random values on the union pattern (every
    structural nonzero then numerically nonzero), has no nonzero outside the plan's pattern, and every
    diagonal entry of the plan is there."""
    plan, _ = plan_and_model(make, formulation)
    rng = np.random.default_rng(5)
    data = rng.uniform(0.5, 1.5, plan.nnz) * rng.choice([-1.0, 1.0], plan.nnz)
    A = dense(plan, data)
    A[np.diag_indices(plan.n)] += np.where(np.diag(A) != 0, 10.0 * plan.n, 0.0)  # a safe static LU
    F = static_lu(A, plan.perm)
    allowed = np.zeros((plan.n, plan.n), dtype=bool)
    for j in range(plan.n):
        allowed[plan.frow[plan.fcolptr[j]:plan.fcolptr[j + 1]], j] = True
        assert plan.frow[plan.fdiag[j]] == j
    assert not np.any((np.abs(F) > 1e-12 * np.abs(F).max()) & ~allowed)
    assert np.all(np.abs(np.diag(F)) > 0)


def test_a_free_chain_factors_without_fill_and_grows_linearly():
    """The links of a free chain touch their neighbours only: the minimum-degree order eliminates it end
    to end with no fill at all, so the factors have exactly the Jacobian's nonzeros, 9.6 per state."""
    for n_links in (2, 8, 32):
        plan, _ = plan_and_model(lambda n_links=n_links: chain(n_links), "ggl")
        assert plan.factor_nnz == plan.nnz == 60 * n_links - 36  # 10 per state, less the chain's two ends


def test_static_pivots_that_no_elimination_fills_have_no_plan():
    """y0 = 2, y1 = 1 (J = [[0, 1], [1, 0]], no diagonal at all): nonsingular, but no order of diagonal
    pivots can factor it. The sparse LU is refused with a clear error; "auto" takes the reduced LU."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 2), ca.SX.sym("yp", 2), ca.SX.sym("cj")
    r = ca.vertcat(y[1] - 1.0, y[0] - 2.0)
    funcs = DAEFunctions(2, ca.Function("r", [t, y, yp], [r]),
                         ca.Function("J", [t, y, yp, cj], [ca.jacobian(r, y) + cj * ca.jacobian(r, yp)]), (), (),
                         None, "swap_plan")
    assert not plan_of_model(normalize_model(funcs)).available
    assert not make_plan(2, [0, 1, 2], [1, 0]).available
    with pytest.raises(DaeclearError, match="linear_solver='sparse' is not available for this model"):
        open_session(funcs, backend="c", rtol=1e-6, atol=1e-8, linear_solver="sparse")
    assert open_session(funcs, backend="c", rtol=1e-6, atol=1e-8).linear_solver == "reduced"


def test_bad_patterns_are_refused():
    with pytest.raises(ValueError, match="make_plan: colptr/rowind are not an 2 x 2 CSC pattern"):
        make_plan(2, [0, 1, 3], [0, 2, 1])


# --------------------------------------------------------------------------- the factorisation in C


@pytest.mark.parametrize("make, formulation", MODELS)
def test_sparse_solve_equals_partial_pivoting(make, formulation):
    """J X = B for three right-hand sides at cj from 10 (a step of 0.1 s) to 1e6: numpy's LU with partial
    pivoting and the sparse LU agree to round-off times the condition number; no fallback."""
    model = dc.assemble(make(), formulation)
    s = session(model)
    y, yp = jacobian_point(model, s)
    rng = np.random.default_rng(2)
    for cj in (10.0, 1e3, 1e6):
        J = s.jacobian(0.0, y, yp, cj)
        B = rng.normal(size=(model.n_states, 3))
        X, fallbacks = s.solve_linear(0.0, y, yp, cj, B, solver="sparse")
        exact = np.linalg.solve(J, B)
        bound = max(1e-12, 1e-16 * np.linalg.cond(J))
        assert fallbacks == 0 and np.abs(X - exact).max() <= bound * np.abs(exact).max(), (cj, np.linalg.cond(J))
        X1, _ = s.solve_linear(0.0, y, yp, cj, B[:, 1], solver="sparse")
        np.testing.assert_array_equal(X1, X[:, 1])  # several right-hand sides: each as alone


def test_a_small_static_pivot_is_factored_by_partial_pivoting():
    """The four-bar's fourth pivot made 1e-13 of its row: the static LU's multipliers grow to 1e13 and its
    solution is wrong in the first digit (numpy, no pivoting); the sparse LU's growth test hands that
    Jacobian to dense LU with partial pivoting, whose solution is numpy's."""
    plan, model = plan_and_model(*MODELS[2])
    s = session(model)
    y, yp = jacobian_point(model, s)
    J = s.jacobian(0.0, y, yp, 1e3)
    p = plan.perm[3]
    J[p, p] = 1e-13 * np.abs(J[p]).max()
    b = np.random.default_rng(3).normal(size=plan.n)
    exact = np.linalg.solve(J, b)
    assert np.abs(static_solve(J, plan.perm, b) - exact).max() > 0.1 * np.abs(exact).max()
    x, fallbacks = s.solve_linear(0.0, y, yp, 1e3, b, solver="sparse", matrix=J)
    assert fallbacks == 1
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-10 * np.abs(exact).max())


@pytest.mark.parametrize("make, formulation", MODELS[:3])
def test_a_pivot_lost_to_cancellation_is_factored_by_partial_pivoting(make, formulation):
    """The diagonal entry of a late pivot moved so that its pivot keeps 1e-10 of what it is formed from
    (J near singular, condition about 1e10 and more): the cancellation test hands the Jacobian to dense
    LU with partial pivoting, whose solution agrees with numpy's as far as the condition allows."""
    plan, model = plan_and_model(make, formulation)
    s = session(model)
    y, yp = jacobian_point(model, s)
    J = s.jacobian(0.0, y, yp, 1e4)
    has_diagonal = np.diag(dense(plan, np.ones(plan.nnz))) != 0
    j = max(k for k in range(plan.n) if has_diagonal[plan.perm[k]])  # the last pivot with a diagonal entry
    i = plan.perm[j]
    u = np.diag(static_lu(J, plan.perm))[j]
    J[i, i] -= u * (1.0 - 1e-10)
    assert abs(np.diag(static_lu(J, plan.perm))[j]) < 1e-9 * abs(u)
    b = np.random.default_rng(4).normal(size=plan.n)
    x, fallbacks = s.solve_linear(0.0, y, yp, 1e4, b, solver="sparse", matrix=J)
    assert fallbacks == 1
    exact = np.linalg.solve(J, b)
    np.testing.assert_allclose(x, exact, rtol=0, atol=1e-16 * np.linalg.cond(J) * np.abs(exact).max())


def test_a_matrix_off_the_pattern_is_refused():
    plan, model = plan_and_model(*MODELS[1])
    s = session(model)
    y, yp = jacobian_point(model, s)
    A = np.eye(plan.n)
    A[0, plan.n - 1] = 1.0
    with pytest.raises(DaeclearError, match="nonzero outside the union pattern"):
        s.solve_linear(0.0, y, yp, 1.0, np.ones(plan.n), solver="sparse", matrix=A)


def test_runs_count_no_fallback_on_mechanisms(monkeypatch):
    """A whole run of the chain and of the slider-crank (GGL, index-1): every Jacobian factored on the plan;
    "auto" takes the sparse LU from SPARSE_MIN_STATES states on."""
    monkeypatch.setattr(c_session, "SPARSE_MIN_STATES", 20)
    for scene, formulation in ((chain(4), "ggl"), (slider_crank("revolute"), "ggl"), (slider_crank("revolute"),
                                                                                      "index1")):
        r = dc.simulate(scene, 0.004, options=dc.SolverOptions(formulation=formulation))
        assert r.success and r.stats["linear_solver"] == "sparse" and r.stats["n_lin_setups"] > 10
        assert r.stats["n_lu_fallbacks"] == 0
