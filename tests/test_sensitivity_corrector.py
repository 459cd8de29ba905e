"""The stacked sensitivity run's linear solver: the state's n x n iteration matrix factored once (by the
solver the state's run uses) and applied to each of the 1 + Ns diagonal blocks, against the reference
that factors the (1 + Ns) n block-diagonal matrix whole (docs/sensitivities.md, section 2)."""

from __future__ import annotations

import warnings

import casadi
import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import AssemblyError
from daeclear.engine.codegen import normalize_model
from daeclear.engine.ida_session import open_session
from daeclear.engine.sensitivity_functions import augmented_functions
from daeclear.engine.session_base import DAEFunctions
from daeclear.solvers.sensitivity_ida import stacked_reference

CRANK_T = 0.4e-3  # two impacts of the revolute clearance joint
NAMES = ["clearance.clearance", "clearance.law.restitution"]


def _run(model: dc.DAEModel, t_end: float, names: list[str], *, reference: bool, rtol: float = 1e-10,
         backend: str = "c") -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        save = dc.SaveAt(times=np.linspace(0.0, t_end, 9), steps=False)
        opts = dc.SolverOptions(backend=backend)
        if reference:
            with stacked_reference():
                return dc.simulate(model, t_end, rtol=rtol, options=opts, save=save, sensitivities=names)
        return dc.simulate(model, t_end, rtol=rtol, options=opts, save=save, sensitivities=names)


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_slider_crank_sensitivities_agree_with_the_stacked_factorisation(formulation: str) -> None:
    """Fig. 4.15's slider-crank (c = 0.5 mm, two impacts): S of every position and velocity at 9 output times
    from the state's factorisation equals the reference's to the integration's accuracy (rtol 1e-10), the
    events' dt*/dp too; the stacked session factors the state's n x n matrix with the state run's solver."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation=formulation)
    new, ref = (_run(model, CRANK_T, NAMES, reference=r) for r in (False, True))
    plain = dc.simulate(model, CRANK_T, rtol=1e-10, options=dc.SolverOptions(backend="c"))
    assert new.success and ref.success and len(new.events) == len(ref.events) == 2
    n = 2 * model.n_q
    a, b = new.sensitivities.states[:, :n], ref.sensitivities.states[:, :n]
    scale = np.abs(b).max(axis=(0, 1))  # per parameter
    assert np.all(scale > 0)
    diff = np.abs(a - b).max(axis=(0, 1)) / scale
    assert np.all(diff < 1e-6), diff
    for e_new, e_ref in zip(new.sensitivities.events, ref.sensitivities.events):
        # GGL's second onset: the reference's own dt*/dp moves by 1e-5 between rtol 1e-10 and 1e-12
        assert e_new.dt_dp == pytest.approx(e_ref.dt_dp, rel=2e-5, abs=1e-12)
    # the state's matrix, the state's solver: same pattern and solver as the run without sensitivities
    assert new.stats["linear_solver"] == plain.stats["linear_solver"] == "reduced"
    assert new.stats["jac_nnz"] == plain.stats["jac_nnz"]
    assert ref.stats["jac_nnz"] > 2 * plain.stats["jac_nnz"]  # the reference's (1 + 2) n matrix
    # Newton converges alike: no convergence failure in either
    assert new.stats["n_nonlin_conv_fails"] == 0 == ref.stats["n_nonlin_conv_fails"]


def test_a_sparse_chain_uses_the_sparse_lu_of_its_state() -> None:
    """A driven chain of 10 links (63 states: the sparse LU's size): the stacked session factors the state's
    63 x 63 matrix with the sparse LU, as the plain run does, and agrees with the reference."""
    model = dc.assemble(dc.mechanisms.chain(10, rpm=300.0))
    names = ["pin2.clearance"]
    t_end = 2e-3
    new, ref = (_run(model, t_end, names, reference=r, rtol=1e-8) for r in (False, True))
    plain = dc.simulate(model, t_end, rtol=1e-8, options=dc.SolverOptions(backend="c"))
    assert new.success and ref.success
    assert new.stats["linear_solver"] == plain.stats["linear_solver"] == "sparse"
    assert new.stats["jac_nnz"] == plain.stats["jac_nnz"]
    n = 2 * model.n_q
    a, b = new.sensitivities.states[:, :n, 0], ref.sensitivities.states[:, :n, 0]
    assert np.abs(b).max() > 0
    assert np.abs(a - b).max() < 1e-4 * np.abs(b).max(), np.abs(a - b).max() / np.abs(b).max()


def test_the_block_session_solves_every_block_with_the_state_matrix(crank_index1: dc.DAEModel) -> None:
    """One Newton solve of the block session on [y; S_1; S_2] (its jacobian() is the state's n x n matrix)
    against numpy's solve of the block-diagonal (3 n) matrix: a solver that skipped a block, or used another
    block's matrix, fails."""
    model = crank_index1
    n, W = model.n_states, 2
    funcs = augmented_functions(model.functions, W, block=True)
    P = np.concatenate([model.parameter_values, np.zeros(model.parameter_values.size * W)])
    rng = np.random.default_rng(7)
    y = np.concatenate([model.initial_state()[0], rng.standard_normal(n * W)])
    yp = np.zeros(n * (1 + W))
    session = open_session(funcs, backend="c", rtol=1e-8, atol=1e-10, parameters=P)
    try:
        J = session.jacobian(0.0, y, yp, 1e4)
        assert J.shape == (n, n)
        want = np.array(casadi.densify(model.functions.jacobian(0.0, y[:n], yp[:n], 1e4, model.parameter_values)))
        assert np.allclose(J, want, rtol=1e-14, atol=0)
        B = rng.standard_normal((n, 3))
        X, _ = session.solve_linear(0.0, y, yp, 1e4, B, solver="dense")
        assert np.allclose(want @ X, B, rtol=1e-9, atol=1e-9)
    finally:
        session.close()


def test_blocks_must_divide_the_states() -> None:
    """A DAEFunctions whose blocks do not divide n is refused with the field, the value and the rule."""
    x, xp, t, cj = casadi.SX.sym("y", 3), casadi.SX.sym("yp", 3), casadi.SX.sym("t"), casadi.SX.sym("cj")
    res = casadi.Function("r", [t, x, xp], [xp - x])
    jac = casadi.Function("j", [t, x, xp, cj], [casadi.SX.eye(1)])
    with pytest.raises(AssemblyError, match=r"DAEFunctions.blocks=2, must be an integer >= 1 dividing n=3"):
        normalize_model(DAEFunctions(3, res, jac, (), (), None, blocks=2))


def _central(f, h: float) -> np.ndarray:
    """Richardson's extrapolation of central differences of f(eps) at eps = 0: (4 D(h/2) - D(h)) / 3."""
    def d(step: float) -> np.ndarray:
        return (np.asarray(f(step)) - np.asarray(f(-step))) / (2 * step)
    return (4 * d(h / 2) - d(h)) / 3


def test_the_coupling_is_the_newton_matrix_below_the_diagonal(crank_index1: dc.DAEModel) -> None:
    """C dy0 of the block session (the blocks below the first block column times dy0) against central differences
    of the stacked residual's sensitivity rows moved along y += e dy0, y' += e cj dy0 (what the Newton matrix
    dR/dY + cj dR/dY' does to the direction), for the base residual and for the contact term in contact."""
    model = crank_index1
    f, n, W = model.functions, model.n_states, 2
    aug = augmented_functions(f, W, coupled=True, block=True)
    assert aug.coupling is not None and len(aug.term_couplings) == len(f.term_residuals) == 1
    rng = np.random.default_rng(3)
    nq = model.n_q
    y, yp = model.initial_state()
    y = y.copy()
    y[3] += 0.51e-3  # the rod's journal end 0.01 mm into the bearing: the term's force is on
    y[nq + 3] += 0.1
    scale = np.concatenate([np.full(nq, 1e-3), np.ones(nq), np.full(n - 2 * nq, 10.0)])
    Y = np.concatenate([y, (rng.normal(size=(n, W)) * scale[:, None]).ravel(order="F")])
    Yp = np.concatenate([yp, (rng.normal(size=(n, W)) * scale[:, None]).ravel(order="F")])
    PA = np.concatenate([model.parameter_values, rng.normal(size=model.parameter_values.size * W) * 1e-3])
    pa = np.concatenate([[0.7], rng.normal(size=W)])
    dy0, cj, t = rng.normal(size=n) * scale, 3.0e3, 1e-3
    move = np.concatenate([dy0, np.zeros(n * W)])
    cases = [(aug.coupling, lambda Yk, Ypk: aug.residual(t, Yk, Ypk, PA), [t, Y, Yp, cj, PA, dy0]),
             (aug.term_couplings[0], lambda Yk, Ypk: aug.term_residuals[0](t, Yk, Ypk, pa, PA),
              [t, Y, Yp, pa, cj, PA, dy0])]
    for coupling, residual, args in cases:
        got = np.array(coupling(*args)).ravel()
        want = _central(lambda e, r=residual: np.array(r(Y + e * move, Yp + e * cj * move)).ravel()[n:], 1e-4)
        assert np.abs(want).max() > 0
        assert np.allclose(got, want, rtol=1e-6, atol=1e-7 * np.abs(want).max())


def test_the_coupling_makes_newton_converge_where_the_block_diagonal_part_stalls() -> None:
    """The slider-crank's sensitivities to the rod's and the slider's masses at rtol 1e-5 (13 impacts in 2 ms):
    with the blocks below the diagonal (block forward substitution) Newton never fails to converge, as with the
    exact (1 + Ns) n matrix; with the block-diagonal part alone (IDAS' simultaneous corrector) it fails
    thousands of times and IDA takes 20 times the steps. A wrong coupling fails like the missing one."""
    from daeclear.solvers.sensitivity_ida import SensitivityIntegrator
    scene = dc.mechanisms.slider_crank("revolute")
    names, t_end = ["rod.mass", "slider.mass"], 2e-3
    save = dc.SaveAt(times=np.linspace(0.0, t_end, 5), steps=False)
    stats = {}
    with warnings.catch_warnings(), pytest.MonkeyPatch.context() as patch:
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        for coupling in (True, False):
            patch.setattr(SensitivityIntegrator, "coupling", coupling)
            r = dc.simulate(scene, t_end, rtol=1e-5, save=save, sensitivities=names,
                            options=dc.SolverOptions(backend="c"))
            assert r.success and len(r.events) == 13
            stats[coupling] = r.stats
    assert stats[True]["n_nonlin_conv_fails"] <= 5, stats[True]
    assert stats[False]["n_nonlin_conv_fails"] > 1000
    assert stats[False]["n_steps"] > 5 * stats[True]["n_steps"]


@pytest.fixture(scope="module")
def crank_index1() -> dc.DAEModel:
    return dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="index1")
