"""The forward sensitivity system of a DAE as CasADi functions, ``W`` directions (columns) at once.

For F(t, y, y', P) = 0 and parameters p with dP/dp (``dP``, n_P x W), S = dy/dp satisfies between events
``F_y S + F_y' S' + F_P dP = 0`` (docs/sensitivities.md). Every function here is a forward-mode
directional derivative (CasADi ``jtimes``) of a function of :class:`DAEFunctions`: the residual, each
switchable term (its own parameters p_k, e.g. the latched approach speed, get their sensitivities
``Sk``) and any extra; the roots' Jacobian blocks give the event time's sensitivity.
:func:`augmented_functions` stacks [y; S] into one DAE: with ``block`` its Jacobian is the state's n x n
iteration matrix, which the session factors once and applies to each of the 1 + W blocks (what
``simulate`` runs); without, the (1 + W) n matrix itself (the reference the tests and
benchmarks/bench_sensitivity.py compare with).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from collections.abc import Sequence

import casadi

from .session_base import DAEFunctions

__all__ = ["SensitivityFunctions", "directional", "sensitivity_functions", "augmented_functions",
           "jacobian_blocks", "curvature_along"]


def _symbols(f: casadi.Function, sizes: Sequence[Any], names: Sequence[str]) -> list[Any]:
    """Fresh symbols of ``f``'s kind (SX or MX), one per size (an int or a (rows, cols) pair)."""
    sym = casadi.SX if f.is_a("SXFunction") else casadi.MX
    return [sym.sym(name, *(size if isinstance(size, tuple) else (size, 1))) for name, size in zip(names, sizes)]


def jacobian_blocks(f: casadi.Function, name: str, out: int = 0) -> casadi.Function:
    """(x_0, ..., x_m-1) -> [d out/d x_0 | ... | d out/d x_m-1] of output ``out`` of ``f`` (column-vector
    inputs), dense: (numel_out, sum of the inputs' numel)."""
    names = [f.name_in(k) for k in range(f.n_in())]
    xs = _symbols(f, [f.numel_in(k) for k in range(f.n_in())], names)
    value = casadi.vec(f.call([casadi.reshape(x, f.size_in(k)) for k, x in enumerate(xs)])[out])
    blocks = casadi.horzcat(*(casadi.jacobian(value, x) for x in xs))
    return casadi.Function(name, xs, [casadi.densify(blocks)], names, [f"J_{f.name_out(out)}"])


def curvature_along(f: casadi.Function, name: str) -> casadi.Function:
    """(t, y, yp, ypp, P) -> d^2/ds^2 of ``f(t + s, y + s yp + s^2/2 ypp, yp + s ypp, P)`` at s = 0 (f takes
    (t, y, yp, P)): the second time derivative of a root along a solution with derivatives yp and ypp."""
    t, y, yp, ypp, P, s = _symbols(f, [1, f.numel_in(1), f.numel_in(1), f.numel_in(1), f.numel_in(3), 1],
                                   ["t", "y", "yp", "ypp", "P", "s"])
    value = casadi.vec(f.call([t + s, y + s * yp + 0.5 * s * s * ypp, yp + s * ypp, P])[0])
    second = casadi.substitute(casadi.jacobian(casadi.jacobian(value, s), s), s, casadi.DM.zeros(1, 1))
    return casadi.Function(name, [t, y, yp, ypp, P], [casadi.densify(second)], ["t", "y", "yp", "ypp", "P"],
                           [f"d2{f.name_out(0)}"])


def directional(f: casadi.Function, width: int, wrt: Sequence[int] | None = None, name: str | None = None,
                out: int = 0) -> casadi.Function:
    """The forward derivative of output ``out`` of ``f`` in ``width`` directions at once.

    Returns ``(x_0, ..., x_m-1, dx_i for i in wrt) -> d`` with column-vector inputs ``x_k`` (numel of f's
    input k), seeds ``dx_i`` of shape (numel_i, width) and ``d`` (numel_out, width), dense: column j is
    the sum over ``wrt`` of d f/d x_i times column j of dx_i. ``wrt``: all inputs by default."""
    if width < 1:
        raise ValueError(f"directional: width={width!r}, must be an integer >= 1.")
    wrt = tuple(range(f.n_in())) if wrt is None else tuple(wrt)
    names = [f.name_in(k) for k in range(f.n_in())]
    xs = _symbols(f, [f.numel_in(k) for k in range(f.n_in())], names)
    seeds = _symbols(f, [(f.numel_in(k), width) for k in wrt], [f"d{names[k]}" for k in wrt])
    value = casadi.vec(f.call([casadi.reshape(x, f.size_in(k)) for k, x in enumerate(xs)])[out])
    if wrt:
        d = casadi.jtimes(value, casadi.vertcat(*(xs[k] for k in wrt)), casadi.vertcat(*seeds))
    else:
        d = casadi.DM.zeros(value.numel(), width)
    return casadi.Function(name or f"{f.name()}_fwd{width}", [*xs, *seeds], [casadi.densify(d)],
                           [*names, *(f"d{names[k]}" for k in wrt)], [f"d{f.name_out(out)}"])


@dataclass(frozen=True)
class SensitivityFunctions:
    """The sensitivity functions of a :class:`DAEFunctions`, ``width`` directions at once (every matrix
    input and output n x width, column-major in C):

    * ``res``: (t, y, yp, P, S, Sp, dP) -> F_y S + F_y' S' + F_P dP, the always-active part;
    * ``term_res[k]``: (t, y, yp, p_k, P, S, Sp, Sk, dP) -> the same of term k, added while it is active
      (``Sk`` = dp_k/dp, n_params_k x width: the latched values' sensitivities);
    * ``root_jacobian``: (t, y, yp, P) -> [g_t | g_y | g_y' | g_P] (n_roots x (1 + 2 n + n_P)): at an
      event the root's sensitivity g_y S + g_y' S' + g_P dP, its rate g_t + g_y y' (+ g_y' y'') and the
      magnitude of the terms of that rate (the grazing test);
    * ``root_curvature``: (t, y, yp, ypp, P) -> d^2 g/dt^2 along (y', y'') (:func:`curvature_along`, the
      grazing test near an apex);
    * ``extras[i]``: the directional derivative of ``DAEFunctions.extras[extra_index[i]]`` in all its
      inputs (:func:`directional`): consistent restarts, latched values, channels."""

    n: int
    n_parameters: int
    width: int
    n_params: tuple[int, ...]
    n_roots: int
    res: casadi.Function
    term_res: tuple[casadi.Function, ...]
    root_jacobian: casadi.Function | None
    root_curvature: casadi.Function | None
    extras: tuple[casadi.Function, ...] = ()
    extra_index: tuple[int, ...] = ()


def _with_parameters(f: casadi.Function, n_base: int, n_parameters: int) -> casadi.Function:
    """``f`` with the run-time parameters as its last input (an unused one added when it has none)."""
    if f.n_in() != n_base:
        return f
    xs = _symbols(f, [f.sparsity_in(k).shape for k in range(n_base)], [f.name_in(k) for k in range(n_base)])
    P = _symbols(f, [n_parameters], ["P"])[0]
    return casadi.Function(f.name(), [*xs, P], f.call(xs), [*(f.name_in(k) for k in range(n_base)), "P"],
                           [f.name_out(k) for k in range(f.n_out())])


def event_roots(funcs: DAEFunctions) -> casadi.Function | None:
    """The roots a run with sensitivities watches, (t, y, yp, P) -> [g; k]: the model's roots g (the gaps),
    then its kinks k (``DAEFunctions.kinks``: where S' jumps, a restart without a jump; docs/sensitivities.md,
    "Kinks"); None without either."""
    parts = [_with_parameters(f, 3, int(funcs.n_parameters)) for f in (funcs.roots, funcs.kinks)
             if f is not None and f.numel_out(0) > 0]
    if len(parts) < 2:
        return parts[0] if parts else None
    xs = _symbols(parts[0], [parts[0].sparsity_in(k).shape for k in range(4)], ["t", "y", "yp", "P"])
    return casadi.Function("roots", xs, [casadi.vertcat(*(f(*xs) for f in parts))], ["t", "y", "yp", "P"], ["g"])


def root_functions(funcs: DAEFunctions) -> tuple[casadi.Function, casadi.Function] | None:
    """The roots' Jacobian (t, y, yp, P) -> [g_t | g_y | g_y' | g_P] and curvature (t, y, yp, ypp, P) ->
    d^2 g/dt^2 of the roots g of :func:`event_roots` (None without roots): the event's pieces
    (docs/sensitivities.md, section 4)."""
    g = event_roots(funcs)
    if g is None:
        return None
    return jacobian_blocks(g, "sens_root_jacobian"), curvature_along(g, "sens_root_curvature")


def sensitivity_functions(funcs: DAEFunctions, width: int, extras: Sequence[int] = ()) -> SensitivityFunctions:
    """The sensitivity functions of ``funcs`` for ``width`` directions at once, with the directional
    derivatives of ``funcs.extras[k]`` for k in ``extras``."""
    n_P = int(funcs.n_parameters)
    res = _with_parameters(funcs.residual, 3, n_P)
    r = directional(res, width, (1, 2, 3), "sens_res")
    term_res, n_params = [], []
    for k, fk in enumerate(funcs.term_residuals):
        fk = _with_parameters(fk, 4, n_P)
        term_res.append(directional(fk, width, (1, 2, 3, 4), f"sens_term{k}_res"))
        n_params.append(int(fk.numel_in(3)))
    roots, curvature = root_functions(funcs) or (None, None)
    n_roots = 0 if roots is None else int(roots.size_out(0)[0])
    bad = [k for k in extras if not 0 <= k < len(funcs.extras)]
    if bad:
        raise ValueError(f"sensitivity_functions: extras={list(extras)!r}, must be indices below "
                         f"{len(funcs.extras)} (the model's extras).")
    fwd = tuple(directional(funcs.extras[k], width, None, f"sens_extra{k}") for k in extras)
    return SensitivityFunctions(int(funcs.n), n_P, int(width), tuple(n_params), n_roots, r, tuple(term_res), roots,
                                curvature, fwd, tuple(int(k) for k in extras))


def stacked_extras(funcs: DAEFunctions, width: int, derivatives: Sequence[int]) -> tuple[casadi.Function, ...]:
    """The extras of the stacked DAE, whose parameter input is [P; vec(dP)]: the model's extras (same index,
    P taken from it), then the directional derivative (:func:`directional` in every input) of
    ``funcs.extras[k]`` for each k of ``derivatives``, at index ``len(funcs.extras) + i``, with inputs (the
    extra's inputs but P, their seeds but dP's, [P; vec(dP)]), then the roots' Jacobian and curvature
    (:func:`root_functions`) when the model has roots. A run with sensitivities evaluates its rows and events
    with them in the stacked session (the same functions, in C in a compiled session)."""
    n_P = int(funcs.n_parameters)

    def stacked(f: casadi.Function) -> casadi.Function:
        """``f`` (vector inputs, P last, one output) with [P; vec(dP)] for P."""
        xs = _symbols(f, [f.numel_in(k) for k in range(f.n_in())], [f.name_in(k) for k in range(f.n_in())])
        PA = _symbols(f, [n_P * (1 + width)], ["P"])[0]
        return casadi.Function(f"{f.name()}_stacked", [*xs[:-1], PA], f.call([*xs[:-1], PA[:n_P]]),
                               [*(f.name_in(k) for k in range(f.n_in() - 1)), "P"], [f.name_out(0)])

    out = [stacked(f) for f in funcs.extras]
    for k in derivatives:
        d = directional(funcs.extras[k], width, None, f"sens_d{k}")
        m = funcs.extras[k].n_in()  # d's inputs: m values (P last), m seeds (dP last)
        xs = _symbols(d, [d.numel_in(j) for j in range(2 * m)], [d.name_in(j) for j in range(2 * m)])
        PA = _symbols(d, [n_P * (1 + width)], ["P"])[0]
        dP = casadi.reshape(PA[n_P:], n_P, width)
        shaped = [casadi.reshape(x, d.size_in(j)) for j, x in enumerate(xs)]  # an extra's inputs are vectors
        value = d.call([*shaped[:m - 1], PA[:n_P], *shaped[m:2 * m - 1], dP])
        out.append(casadi.Function(f"sens_extra{k}", [*xs[:m - 1], *xs[m:2 * m - 1], PA], value,
                                   [*(d.name_in(j) for j in (*range(m - 1), *range(m, 2 * m - 1))), "P"],
                                   [d.name_out(0)]))
    return (*out, *(stacked(f) for f in root_functions(funcs) or ()))


def augmented_functions(funcs: DAEFunctions, width: int, coupled: bool = False, block: bool = False,
                        derivatives: Sequence[int] | None = None) -> DAEFunctions:
    """The DAE of [y; S_1; ...; S_width] as one :class:`DAEFunctions` (what IDA integrates for
    ``simulate(..., sensitivities=...)``): parameters [P; vec(dP)], term k's parameters [p_k; vec(Sk)],
    the roots those of y; with ``derivatives`` (indices of ``funcs.extras``) the extras of
    :func:`stacked_extras`, else none.

    Its Newton matrix: the state's iteration matrix on every diagonal block, nothing else (IDAS'
    simultaneous corrector: a modified Newton that converges since S's equations are linear in S).
    ``block``: the Jacobian functions give that n x n matrix once (``blocks = 1 + width``: the session
    factors it once and solves every block with it); else the (1 + width) n matrix itself, the reference.
    ``coupled``: the exact Newton matrix, block lower triangular: with ``block`` its blocks below the
    diagonal C_i = d(F_y S_i + F_y' S_i' + F_P dP_i)/dy + cj d(...)/dy' as directional derivatives
    (``DAEFunctions.coupling``: C dy0 for the block forward substitution); without, the whole (1 + width) n
    matrix. Where a force has no second derivative (Hertz's delta^1.5 at onset: delta^-0.5) C is not
    finite: the compiled session then drops it for that solve; the whole matrix fails."""
    n, n_P = int(funcs.n), int(funcs.n_parameters)
    res = _with_parameters(funcs.residual, 3, n_P)
    sym: Any = casadi.SX if res.is_a("SXFunction") else casadi.MX  # one kind at run time
    t, cj = sym.sym("t"), sym.sym("cj")
    Y, Yp = sym.sym("y", n * (1 + width)), sym.sym("yp", n * (1 + width))
    PA = sym.sym("P", n_P * (1 + width))
    y, yp, P = Y[:n], Yp[:n], PA[:n_P]
    S, Sp = casadi.reshape(Y[n:], n, width), casadi.reshape(Yp[n:], n, width)
    dP = casadi.reshape(PA[n_P:], n_P, width)
    sens = sensitivity_functions(funcs, width)

    def stacked(value: Any, derivative: Any) -> Any:
        return casadi.vertcat(value, casadi.vec(derivative))

    dy0 = sym.sym("dy0", n)
    seed = casadi.vertcat(dy0, casadi.DM.zeros(n * width, 1), cj * dy0, casadi.DM.zeros(n * width, 1))

    def below(r: Any) -> Any:
        """C dy0: the sensitivity rows' derivative in y (and y' = cj y) along the first block's solution."""
        return casadi.jtimes(r[n:], casadi.vertcat(Y, Yp), seed)

    def jacobian(r: Any) -> Any:
        if coupled and not block:
            return casadi.jacobian(r, Y) + cj * casadi.jacobian(r, Yp)
        state = casadi.jacobian(r[:n], y) + cj * casadi.jacobian(r[:n], yp)
        return state if block else casadi.diagcat(*([state] * (1 + width)))

    r = stacked(res(t, y, yp, P), sens.res(t, y, yp, P, S, Sp, dP))
    residual = casadi.Function("residual", [t, Y, Yp, PA], [r], ["t", "y", "yp", "P"], ["r"])
    jac = casadi.Function("jacobian", [t, Y, Yp, cj, PA], [jacobian(r)], ["t", "y", "yp", "cj", "P"], ["J"])
    with_coupling = coupled and block
    coupling = casadi.Function("coupling", [t, Y, Yp, cj, PA, dy0], [below(r)],
                               ["t", "y", "yp", "cj", "P", "dy0"], ["Cdy0"]) if with_coupling else None
    term_res, term_jac, term_cpl = [], [], []
    locked = funcs.locked_residuals
    for k, (fk, npk) in enumerate(zip(funcs.term_residuals, sens.n_params)):
        fk = _with_parameters(fk, 4, n_P)
        lk = locked[k] if k < len(locked) else None
        nl = 0 if lk is None else 1  # [p_k; piece; vec(Sk)]: S integrated on the friction law's piece
        pa = sym.sym("p", npk * (1 + width) + nl)
        Sk = casadi.reshape(pa[npk + nl:], npk, width)
        if lk is None:
            dk = sens.term_res[k](t, y, yp, pa[:npk], P, S, Sp, Sk, dP)
        else:  # the piece is a constant: its seed 0
            dlk = directional(_with_parameters(lk, 4, n_P), width, (1, 2, 3, 4), f"sens_term{k}_locked")
            dk = dlk(t, y, yp, pa[:npk + 1], P, S, Sp, casadi.vertcat(Sk, casadi.DM.zeros(1, width)), dP)
        # y's rows on the piece too: the whole residual smooth within a segment (the piece is the law there)
        yk = fk(t, y, yp, pa[:npk], P) if lk is None else _with_parameters(lk, 4, n_P)(t, y, yp, pa[:npk + 1], P)
        rk = stacked(yk, dk)
        term_res.append(casadi.Function(f"term{k}_res", [t, Y, Yp, pa, PA], [rk], ["t", "y", "yp", "p", "P"], ["r"]))
        term_jac.append(casadi.Function(f"term{k}_jac", [t, Y, Yp, pa, cj, PA], [jacobian(rk)],
                                        ["t", "y", "yp", "p", "cj", "P"], ["J"]))
        if with_coupling:
            term_cpl.append(casadi.Function(f"term{k}_cpl", [t, Y, Yp, pa, cj, PA, dy0], [below(rk)],
                                            ["t", "y", "yp", "p", "cj", "P", "dy0"], ["Cdy0"]))
    roots = None
    g = event_roots(funcs)  # the gaps and the kinks: a run with sensitivities restarts at both
    if g is not None:
        roots = casadi.Function("roots", [t, Y, Yp, PA], [g(t, y, yp, P)], ["t", "y", "yp", "P"], ["g"])
    return DAEFunctions(n=n * (1 + width), residual=residual, jacobian=jac, term_residuals=tuple(term_res),
                        term_jacobians=tuple(term_jac), roots=roots, n_parameters=n_P * (1 + width),
                        name=f"{funcs.name}_sens{width}{'c' if coupled else ''}{'b' if block else ''}",
                        blocks=1 + width if block else 1, coupling=coupling, term_couplings=tuple(term_cpl),
                        extras=() if derivatives is None else stacked_extras(funcs, width, derivatives))
