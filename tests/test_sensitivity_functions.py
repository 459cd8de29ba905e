"""The generated sensitivity functions (daeclear/engine/sensitivity_functions.py, issue 43 item 2) against
finite differences of the model's own functions, and their generated C against CasADi.

The references are independent of CasADi's forward mode: central differences of the residual, the terms
and the roots evaluated as numbers, with Richardson's extrapolation (error O(h^4)).
"""

from __future__ import annotations

import ctypes
import subprocess
from pathlib import Path

import casadi
import numpy as np
import pytest

import daeclear as dc
from daeclear.assembly.sensitivity import model_sensitivity_functions
from daeclear.engine.build import CSRC, CompilerUnavailable, compiler_command
from daeclear.engine.codegen import generate_source, normalize_model
from daeclear.engine.sensitivity_functions import augmented_functions, directional, sensitivity_functions

W = 3


@pytest.fixture(scope="module")
def crank() -> dc.DAEModel:
    """The chapter's slider-crank with its revolute clearance joint (Lankarani-Nikravesh: the term's
    parameter is the latched approach speed), index-1: constraints, multipliers, one contact term."""
    return dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="index1")


def a_point(model: dc.DAEModel, seed: int = 0) -> dict[str, np.ndarray]:
    """A state near the start, in contact (0.01 mm into the bearing, penetrating), and W directions
    scaled like the states (positions ~1e-3, velocities ~1, multipliers ~10) and the parameters."""
    rng = np.random.default_rng(seed)
    y, yp = model.initial_state()
    n, nq = model.n_states, model.n_q
    y = y.copy()
    y[3:6] += [0.51e-3, 0.0, 0.0]  # the rod (its journal end) moved: penetration 0.01 mm
    y[nq + 3] += 0.1  # and moving on at 0.1 m/s: the law's damping term is on
    scale = np.concatenate([np.full(nq, 1e-3), np.ones(nq), np.full(n - 2 * nq, 10.0)])
    P = model.parameter_values
    return dict(t=np.array([1e-3]), y=y, yp=yp + rng.normal(size=n) * scale, P=P,
                S=rng.normal(size=(n, W)) * scale[:, None], Sp=rng.normal(size=(n, W)) * scale[:, None],
                dP=rng.normal(size=(P.size, W)) * np.maximum(np.abs(P), 1e-3)[:, None] * 1e-2,
                p=np.array([0.7]), Sk=rng.normal(size=(1, W)))


def richardson(f, h: float) -> np.ndarray:
    """(4 D(h/2) - D(h)) / 3 of central differences of f(eps) at eps = 0."""
    def central(step: float) -> np.ndarray:
        return (np.asarray(f(step)) - np.asarray(f(-step))) / (2 * step)
    return (4 * central(h / 2) - central(h)) / 3


def differences(fun, inputs: list, seeds: list, h: float = 1e-4) -> np.ndarray:
    """The derivative of ``fun(*inputs)`` in each direction ``seeds`` (one matrix per input, None for an
    input that does not move): (n_out, W), column j by central differences along column j."""
    def along(j: int):
        def f(e: float) -> np.ndarray:
            return np.array(fun(*(x if d is None else x + e * d[:, j] for x, d in zip(inputs, seeds)))).ravel()
        return f
    width = next(d.shape[1] for d in seeds if d is not None)
    return np.stack([richardson(along(j), h) for j in range(width)], axis=1)


def test_residual_sensitivity_is_the_directional_derivative(crank) -> None:
    x = a_point(crank)
    sens = sensitivity_functions(crank.functions, W)
    got = np.array(sens.res(x["t"], x["y"], x["yp"], x["P"], x["S"], x["Sp"], x["dP"]))
    want = differences(crank.functions.residual, [x["t"], x["y"], x["yp"], x["P"]], [None, x["S"], x["Sp"], x["dP"]])
    assert np.allclose(got, want, rtol=1e-7, atol=1e-7 * np.max(np.abs(want)))


def test_term_sensitivity_sees_the_latched_value(crank) -> None:
    """The contact term's part, with its own parameter (the latched approach speed) moving as Sk."""
    x = a_point(crank, seed=1)
    sens = sensitivity_functions(crank.functions, W)
    got = np.array(sens.term_res[0](x["t"], x["y"], x["yp"], x["p"], x["P"], x["S"], x["Sp"], x["Sk"], x["dP"]))
    term = crank.functions.term_residuals[0]
    assert np.abs(got).max() > 0
    want = differences(term, [x["t"], x["y"], x["yp"], x["p"], x["P"]], [None, x["S"], x["Sp"], x["Sk"], x["dP"]])
    assert np.allclose(got, want, rtol=1e-7, atol=1e-7 * np.max(np.abs(want)))
    # the latched value alone: d r_k / d p_k
    only = np.array(sens.term_res[0](x["t"], x["y"], x["yp"], x["p"], x["P"], 0 * x["S"], 0 * x["Sp"],
                                     np.ones((1, W)), 0 * x["dP"]))[:, 0]
    want = richardson(lambda e: np.array(term(x["t"], x["y"], x["yp"], x["p"] + e, x["P"])).ravel(), 1e-2)
    assert np.allclose(only, want, rtol=1e-8, atol=1e-8 * np.max(np.abs(want))) and np.abs(want).max() > 0


def test_root_jacobian_blocks(crank) -> None:
    """[g_t | g_y | g_y' | g_P] of the gap against differences in each input."""
    x = a_point(crank, seed=2)
    sens = sensitivity_functions(crank.functions, W)
    J = np.array(sens.root_jacobian(x["t"], x["y"], x["yp"], x["P"]))
    n, nP = crank.n_states, x["P"].size
    assert J.shape == (1, 1 + 2 * n + nP)
    dt = np.ones((1, W))
    want = differences(crank.functions.roots, [x["t"], x["y"], x["yp"], x["P"]], [dt, x["S"], x["Sp"], x["dP"]])
    assert J @ np.vstack([dt, x["S"], x["Sp"], x["dP"]]) == pytest.approx(want, rel=1e-7)
    assert np.all(J[:, 1 + n:1 + 2 * n] == 0.0)  # the gap reads q only: its rate needs no y''


def test_directional_of_an_extra_in_every_input() -> None:
    """A closed form: f(a, b) = [a0 b; sin(a1)] in directions (da, db)."""
    a, b = casadi.SX.sym("a", 2), casadi.SX.sym("b")
    f = casadi.Function("f", [a, b], [casadi.vertcat(a[0] * b, casadi.sin(a[1]))], ["a", "b"], ["out"])
    d = directional(f, 2)
    da, db = np.array([[1.0, 0.5], [2.0, -1.0]]), np.array([[3.0, 0.25]])
    got = np.array(d([0.3, 0.7], 1.5, da, db))
    want = np.array([[1.5 * da[0, j] + 0.3 * db[0, j], np.cos(0.7) * da[1, j]] for j in range(2)]).T
    assert np.allclose(got, want, rtol=1e-15)
    with pytest.raises(ValueError, match="width=0, must be an integer >= 1"):
        directional(f, 0)


@pytest.mark.parametrize("coupled", [False, True])
def test_augmented_system_stacks_the_sensitivities(crank, coupled: bool) -> None:
    """[y; S] as one DAE: its residual is (F, F_y S + F_y' S' + F_P dP); its Jacobian has the state's iteration
    matrix on every diagonal block, nothing else (IDAS' simultaneous corrector), or (``coupled``) the exact
    one, block lower triangular, its blocks below the diagonal by differences of the residual."""
    x = a_point(crank, seed=3)
    f, n = crank.functions, crank.n_states
    aug = augmented_functions(f, W, coupled=coupled)
    Y, Yp = np.concatenate([x["y"], x["S"].ravel(order="F")]), np.concatenate([x["yp"], x["Sp"].ravel(order="F")])
    PA = np.concatenate([x["P"], x["dP"].ravel(order="F")])
    r = np.array(aug.residual(x["t"], Y, Yp, PA)).ravel()
    sens = sensitivity_functions(f, W)
    assert np.array_equal(r[:n], np.array(f.residual(x["t"], x["y"], x["yp"], x["P"])).ravel())
    assert np.allclose(r[n:], np.array(sens.res(x["t"], x["y"], x["yp"], x["P"], x["S"], x["Sp"], x["dP"])).ravel(
        order="F"), rtol=1e-14, atol=1e-12)
    cj = 1234.0
    J = np.array(casadi.densify(aug.jacobian(x["t"], Y, Yp, cj, PA)))
    J0 = np.array(casadi.densify(f.jacobian(x["t"], x["y"], x["yp"], cj, x["P"])))
    for i in range(1 + W):
        assert np.allclose(J[i * n:(i + 1) * n, i * n:(i + 1) * n], J0, rtol=1e-14, atol=1e-9)
        assert not np.any(J[i * n:(i + 1) * n, (i + 1) * n:])
    below = J[n:, :n]
    if not coupled:
        assert not below.any()
        return
    seed = np.zeros(n)
    seed[3] = 1e-3  # the rod's x: d(F_y S + ...)/d y along it, by differences

    def moved(e: float) -> np.ndarray:
        return np.array(aug.residual(x["t"], Y + e * np.concatenate([seed, np.zeros(n * W)]), Yp, PA)).ravel()[n:]
    want = richardson(moved, 1e-3)
    assert np.allclose(below @ seed, want, rtol=1e-6, atol=1e-6 * np.abs(want).max()) and np.abs(want).max() > 0


def _evaluate_c(lib: ctypes.CDLL, name: str, inputs: list[np.ndarray], n_out: int) -> np.ndarray:
    """Call the generated C function ``name`` (CasADi's calling convention) on column-major inputs."""
    sizes = [ctypes.c_longlong() for _ in range(4)]
    getattr(lib, f"{name}_work")(*(ctypes.byref(s) for s in sizes))
    arrays = [np.ascontiguousarray(np.asarray(x, dtype=float).ravel(order="F")) for x in inputs]
    arg = (ctypes.POINTER(ctypes.c_double) * max(sizes[0].value, len(arrays)))(
        *(a.ctypes.data_as(ctypes.POINTER(ctypes.c_double)) for a in arrays))
    out = np.zeros(n_out)
    pointer = ctypes.POINTER(ctypes.c_double)
    res = (pointer * max(sizes[1].value, 1))(out.ctypes.data_as(pointer))
    iw = (ctypes.c_longlong * max(sizes[2].value, 1))()
    w = (ctypes.c_double * max(sizes[3].value, 1))()
    assert getattr(lib, name)(arg, res, iw, w, 0) == 0
    return out


def test_generated_c_agrees_with_casadi(crank, tmp_path: Path) -> None:
    """generate_source(model, sensitivity=...) compiles with the model's functions (one CodeGenerator: no
    clash of CasADi's helpers) and its dcs_* functions give CasADi's numbers; the dc_sens table is there."""
    try:
        cc = compiler_command()
    except CompilerUnavailable as exc:
        pytest.skip(str(exc))
    sens = model_sensitivity_functions(crank, W)
    src = tmp_path / "model.c"
    src.write_text(generate_source(normalize_model(crank.functions), sens))
    lib_path = tmp_path / "model.so"
    subprocess.run([*cc, "-O1", "-fPIC", "-shared", f"-I{CSRC}", str(src), "-o", str(lib_path), "-lm"], check=True,
                   capture_output=True)
    lib = ctypes.CDLL(str(lib_path))
    x = a_point(crank, seed=4)
    n = crank.n_states
    args = [x["t"], x["y"], x["yp"], x["P"], x["S"], x["Sp"], x["dP"]]
    assert np.allclose(_evaluate_c(lib, "dcs_res", args, n * W), np.array(sens.res(*args)).ravel(order="F"),
                       rtol=1e-13, atol=1e-13 * np.abs(np.array(sens.res(*args))).max())
    targs = [x["t"], x["y"], x["yp"], x["p"], x["P"], x["S"], x["Sp"], x["Sk"], x["dP"]]
    want = np.array(sens.term_res[0](*targs)).ravel(order="F")
    assert np.allclose(_evaluate_c(lib, "dcs_term0_res", targs, n * W), want, rtol=1e-13,
                       atol=1e-13 * np.abs(want).max())
    jac = np.array(sens.root_jacobian(*args[:4])).ravel(order="F")
    assert np.allclose(_evaluate_c(lib, "dcs_root_jac", args[:4], jac.size), jac, rtol=1e-13, atol=1e-300)
    width = ctypes.c_int.in_dll(lib, "dc_sens")  # the table's first field
    assert width.value == W


def test_the_exponents_sensitivity_is_zero_out_of_contact(crank) -> None:
    """d/dn of K max(delta, 0)^n is log(delta) delta^n: 0 at delta <= 0, where CasADi's pow gave 0 * log(0) =
    NaN (a slider-crank run with sensitivities stopped at its first onset, its residual NaN); the law keeps
    its power behind a branch."""
    y, yp = crank.initial_state()
    sens = sensitivity_functions(crank.functions, 1)
    dP = np.zeros((crank.parameter_values.size, 1))
    dP[entries_of(crank).index("clearance.law.exponent")] = 1.0
    n = crank.n_states
    for shift, free in ((0.4e-3, True), (0.5e-3 - 1e-12, True), (0.50001e-3, False)):  # delta -1e-4, -1e-12, 1e-8 m
        y1 = y.copy()
        y1[3] += shift  # the rod's end towards the bearing's wall
        out = np.array(sens.term_res[0](0.0, y1, yp, [0.5], crank.parameter_values, np.zeros((n, 1)),
                                        np.zeros((n, 1)), np.zeros((1, 1)), dP))
        assert np.all(out == 0.0) if free else (np.all(np.isfinite(out)) and np.any(out != 0.0)), shift


def entries_of(model: dc.DAEModel) -> list[str]:
    return [name for name, size in model.parameter_layout for _ in range(size)]
