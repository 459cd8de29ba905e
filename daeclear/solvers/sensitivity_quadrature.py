"""Integrals of channels as quadrature states of a run with sensitivities (``simulate(..., integrals=[...])``).

``dc.Integral(channel)`` under IDA's error control: each named channel ch gets a differential state Q with
Q' = ch(t, y, y', switch, P) appended to the DAE, so the stacked [y; Q; S; dQ/dp] integrates the integral and
its sensitivity dQ'/dp = ch_y S + ch_y' S' + ch_switch S_switch + ch_P dP/dp with the states, in IDA's error
test (docs/sensitivities.md, section 7). The channel reads the contact terms' switches (a contact force), so
its row is one extra switchable term that is always on, whose parameters are the model's whole switch
vector (its sensitivity: the latched values'): the quadrature row is exact in every mode, without assuming
the channel adds up term by term. Between events nothing else changes; at an event Q is continuous and its
sensitivity jumps by (ch- - ch+) dt*/dp (a differential state whose rate jumps, section 4).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi
import numpy as np
from numpy.typing import NDArray

from ..assembly.dae_model import EXTRA_OUTPUTS, DAEModel
from ..core import options
from ..engine.session_base import DAEFunctions

__all__ = ["QUADRATURE_ATOL", "Quadratures", "quadrature_functions", "checked_integrals"]

#: The quadratures' default absolute tolerance per unit of rtol (in the channel's unit times s): an integral
#: below it in magnitude is held to this absolute error, above it to rtol relative
#: (``SolverOptions.quadrature_atol`` sets another).
QUADRATURE_ATOL = 1e-3


def checked_integrals(value: object, model: DAEModel) -> list[str]:
    """``simulate``'s ``integrals``: a non-empty list of distinct channel names of ``model`` (SceneError naming
    the bad one, with close matches)."""
    if isinstance(value, str) or not isinstance(value, Sequence) or not value:
        options.fail("simulate", "integrals", value, "None or a non-empty list of channel names, e.g. "
                     "['clearance.normal_force']")
    names = list(value)
    if len(set(map(str, names))) != len(names):
        options.fail("simulate", "integrals", value, "a list naming each channel once")
    known = model.channel_names
    for name in names:
        if name not in known:
            close = options.close_matches(str(name), known)
            hint = f"close matches: {', '.join(map(repr, close))}" if close else (
                f"e.g. {', '.join(map(repr, list(known)[:4]))}")
            options.fail("simulate", "integrals", name, f"one of model.channel_names ({hint})")
    return names


def quadrature_functions(funcs: DAEFunctions, outputs: casadi.Function, channels: Sequence[int]) -> DAEFunctions:
    """``funcs`` with one state Q_c per channel index c of ``outputs`` ((t, y, yp, switch, P) -> channels),
    after y: residual rows Q_c' - ch_c(t, y, y', switch, P). The channel rows are term ``len(funcs.term_residuals)``,
    always on, whose parameters are the switch vector; without contact terms (no switch) they are in the
    residual itself."""
    n, nQ, nP = int(funcs.n), len(channels), int(funcs.n_parameters)
    if funcs.residual.n_in() != 4 or outputs.n_in() != 5:
        raise ValueError("quadrature_functions: the model's functions must take the parameters P (t, y, yp, P)")
    sym: Any = casadi.SX if funcs.residual.is_a("SXFunction") else casadi.MX  # one kind at run time
    t, cj, P = sym.sym("t"), sym.sym("cj"), sym.sym("P", nP)
    Y, Yp = sym.sym("y", n + nQ), sym.sym("yp", n + nQ)
    y, yp = Y[:n], Yp[:n]
    n_switch = int(outputs.numel_in(3))
    switch = sym.sym("switch", n_switch)
    picked = casadi.vertcat(*(outputs(t, y, yp, switch, P)[int(c)] for c in channels))

    def jacobian(r: Any) -> Any:
        return casadi.jacobian(r, Y) + cj * casadi.jacobian(r, Yp)

    base = casadi.vertcat(funcs.residual(t, y, yp, P), Yp[n:] - (picked if n_switch == 0 else 0))
    residual = casadi.Function("residual", [t, Y, Yp, P], [base], ["t", "y", "yp", "P"], ["r"])
    jac = casadi.Function("jacobian", [t, Y, Yp, cj, P], [jacobian(base)], ["t", "y", "yp", "cj", "P"], ["J"])
    term_res, term_jac = [], []
    for k, fk in enumerate(funcs.term_residuals):
        p = sym.sym("p", fk.numel_in(3))
        rk = casadi.vertcat(fk(t, y, yp, p, P), sym(nQ, 1))
        term_res.append(casadi.Function(f"term{k}_res", [t, Y, Yp, p, P], [rk], ["t", "y", "yp", "p", "P"], ["r"]))
        term_jac.append(casadi.Function(f"term{k}_jac", [t, Y, Yp, p, cj, P], [jacobian(rk)],
                                        ["t", "y", "yp", "p", "cj", "P"], ["J"]))
    if n_switch:
        rq = casadi.vertcat(sym(n, 1), -picked)
        term_res.append(casadi.Function("quadrature_res", [t, Y, Yp, switch, P], [rq],
                                        ["t", "y", "yp", "p", "P"], ["r"]))
        term_jac.append(casadi.Function("quadrature_jac", [t, Y, Yp, switch, cj, P], [jacobian(rq)],
                                        ["t", "y", "yp", "p", "cj", "P"], ["J"]))
    roots = None
    if funcs.roots is not None:
        roots = casadi.Function("roots", [t, Y, Yp, P], [funcs.roots(t, y, yp, P)], ["t", "y", "yp", "P"], ["g"])
    tag = "_".join(str(int(c)) for c in channels)
    return DAEFunctions(n=n + nQ, residual=residual, jacobian=jac, term_residuals=tuple(term_res),
                        term_jacobians=tuple(term_jac), roots=roots, n_parameters=nP, name=f"{funcs.name}_q{tag}",
                        extras=funcs.extras)  # the model's own: the stacked session evaluates the rows with them


class Quadratures:
    """The integrals of ``channels`` carried by one run with sensitivities (``width`` parameters): their
    values Q and sensitivities dQ at the run's output rows, the current Q and dQ between restarts."""

    def __init__(self, model: DAEModel, channels: Sequence[str], width: int) -> None:
        self.model, self.channels, self.width = model, tuple(channels), width
        self.index = [model.channel_names.index(c) for c in self.channels]
        self.size = len(self.index)
        self.with_term = bool(model.functions.extras[EXTRA_OUTPUTS].numel_in(3))
        self.Q = np.zeros(self.size)
        self.dQ = np.zeros((self.size, width))
        self.rows_Q: list[NDArray] = []
        self.rows_dQ: list[NDArray] = []

    def functions(self, funcs: DAEFunctions) -> DAEFunctions:
        """The model's functions with the quadrature states appended."""
        return quadrature_functions(funcs, self.model.functions.extras[EXTRA_OUTPUTS], self.index)

    def atol(self, rtol: float, given: float | None = None) -> NDArray[np.float64]:
        """The quadratures' absolute tolerances: ``given`` (``SolverOptions.quadrature_atol``), or
        :data:`QUADRATURE_ATOL` times ``rtol`` when None."""
        return np.full(self.size, QUADRATURE_ATOL * rtol if given is None else given)

    def term(self, switch: NDArray, S_switch: NDArray) -> list[NDArray]:
        """The quadrature term's stacked parameters (none without contact terms): the switch vector and its
        sensitivity."""
        return [np.concatenate([switch, S_switch.ravel(order="F")])] if self.with_term else []

    def rates(self, channels: NDArray, channel_S: NDArray) -> tuple[NDArray, NDArray]:
        """Q' and dQ'/dp from a row's channel values and their sensitivities (NaN, a poisoned parameter, as 0)."""
        return channels[self.index], np.nan_to_num(channel_S[self.index], nan=0.0)

    def jump(self, before: NDArray, after: NDArray, dt_dp: NDArray) -> None:
        """dQ's jump at an event: (ch- - ch+) dt*/dp (Q is continuous; its rate jumps with the channel)."""
        change = before[self.index] - after[self.index]
        step = change[:, None] * np.asarray(dt_dp, dtype=float)[None, :]
        step[change == 0.0] = 0.0  # a channel continuous there: no jump, whatever dt*/dp is
        self.dQ = np.nan_to_num(self.dQ + step, nan=0.0)  # a poisoned parameter: integrated as 0, reported NaN

    def row(self, Q: NDArray, dQ: NDArray, poisoned: NDArray) -> None:
        """Keep an output row's Q and dQ (size,), (size, width); NaN in the ``poisoned`` parameters' columns."""
        self.rows_Q.append(np.array(Q, dtype=float))
        self.rows_dQ.append(np.where(poisoned[None, :], np.nan, np.asarray(dQ, dtype=float)))

    def collected(self, n: int) -> dict[str, tuple[NDArray, NDArray]]:
        """The first ``n`` rows: {channel: (Q (n,), dQ (n, width))}."""
        Q = np.stack(self.rows_Q[:n]) if n else np.zeros((0, self.size))
        dQ = np.stack(self.rows_dQ[:n]) if n else np.zeros((0, self.size, self.width))
        return {c: (Q[:, i], dQ[:, i, :]) for i, c in enumerate(self.channels)}
