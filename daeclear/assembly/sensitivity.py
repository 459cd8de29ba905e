"""Forward sensitivities of an assembled model: parameters by name, consistent sensitivities, the
derivatives of its roots and latched values at an event (docs/sensitivities.md).

S = dy/dp for parameters p named as ``model.parameter_names`` lists them. A name moves the run-time
vector P by dP/dp (:func:`parameter_directions`: a unit column for a number that is an entry of P,
the derivative of the scene-to-P map for a number P is derived from). :class:`ModelSensitivity`
holds what a run with sensitivities asks of the model: the generated sensitivity functions
(:mod:`daeclear.engine.sensitivity_functions`), the algebraic sensitivities made consistent (the
derivative of :meth:`DAEModel.consistent_state`), and the pieces of the jump at an event.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..core.errors import SceneError
from ..core.options import close_matches
from ..engine.sensitivity_functions import SensitivityFunctions, directional, jacobian_blocks
from .dae_model import (EXTRA_ACCEL, EXTRA_KINEMATICS, EXTRA_OUTPUTS, EXTRA_START_KINEMATICS, EXTRA_TERM0, RANK_TOL,
                        DAEModel)

__all__ = ["parameter_value", "moved_parameter", "table_entry", "parameter_directions", "initial_sensitivities",
           "model_sensitivity_functions",
           "ModelSensitivity", "RootTerms", "STEP_BITS"]

#: Central differences of the scene-to-P map and of the start use the step 2**-STEP_BITS |p| (a power of
#: two: p +- h is exact) and h/2, combined by Richardson's extrapolation (error O(h^4) + eps/h, ~1e-12).
STEP_BITS = 10


def table_entry(model: DAEModel, name: str) -> int | None:
    """The index in P of ``"<key>[k]"``, element k of the parameter table's vector entry ``key`` (a worn
    profile's modes, ``"clearance.wear.bearing_cos[1]"``); None for any other name."""
    key, bracket, rest = name.rpartition("[")
    if not bracket or not rest.endswith("]") or not rest[:-1].isdigit():
        return None
    k = int(rest[:-1])
    offset = 0
    for entry, size in model.parameter_layout:
        if entry == key:
            return offset + k if k < size else None
        offset += size
    return None


def parameter_value(model: DAEModel, name: str) -> float:
    """The number a sensitivity parameter ``name`` stands for: a scene value (``"<element>.<field>..."``),
    ``"baumgarte.alpha"``/``"beta"``, an entry of the parameter table, or element k of a vector entry
    (``"<key>[k]"``, :func:`table_entry`); SceneError unless one scalar."""
    where = "sensitivities"
    if isinstance(name, str) and (index := table_entry(model, name)) is not None:
        return float(model.parameter_values[index])
    if not isinstance(name, str) or name not in model.parameter_names:
        close = close_matches(str(name), model.parameter_names)
        hint = f" Close matches: {', '.join(map(repr, close))}." if close else ""
        raise SceneError(f"{where}: parameter={name!r}, must be one of model.parameter_names "
                         f"({len(model.parameter_names)} names).{hint}")
    value: Any = _scene_value(model, name)
    if value is None:
        value = model.parameter(name)
    array = np.asarray(value, dtype=float)
    if array.size != 1 or not math.isfinite(float(array.ravel()[0])):
        raise SceneError(f"{where}: parameter={name!r} is {array.tolist()!r}, must be one finite number "
                         "(a vector value such as a point has no single derivative; name a scalar value, or an "
                         "element '<key>[k]' of a vector entry of model.parameter_layout).")
    return float(array.ravel()[0])


def _scene_value(model: DAEModel, name: str) -> Any:
    """The scene's value at ``name`` (``None`` when it is no scene value, e.g. a derived table entry)."""
    if name in ("baumgarte.alpha", "baumgarte.beta"):
        return model.alpha if name.endswith("alpha") else model.beta
    scene = model.scene
    if scene is None:
        return None
    if name == "gravity":
        return scene.gravity
    head, _, path = name.partition(".")
    try:
        value: Any = scene[head]
        for part in path.split("."):
            value = getattr(value, part)
    except (KeyError, AttributeError):
        return None
    return value


def _step(p: float) -> float:
    """The difference step of a parameter of value ``p``: a power of two near 2**-STEP_BITS |p|."""
    exponent = math.frexp(abs(p))[1] - 1 if p != 0.0 else -10
    return math.ldexp(1.0, exponent - STEP_BITS)


def moved_parameter(model: DAEModel, name: str, value: float) -> DAEModel:
    """``model`` with the parameter ``name`` at ``value`` (the scene's number, or the table entry itself)."""
    if (index := table_entry(model, name)) is not None:  # an element of a vector entry: that number alone
        P = model.parameter_values.copy()
        P[index] = value
        return dataclasses.replace(model, parameter_values=P)
    if _scene_value(model, name) is not None:
        try:
            return model.with_parameters({name: value})
        except SceneError as exc:
            raise SceneError(f"sensitivities: parameter={name!r} cannot be moved to {value!r} to differentiate "
                             f"the numbers derived from it ({exc}); it is at a bound of its range.") from None
    P = model.parameter_values.copy()
    offset = dict(_offsets(model))[name]
    P[offset] = value
    return dataclasses.replace(model, parameter_values=P)


def _offsets(model: DAEModel) -> list[tuple[str, int]]:
    out, offset = [], 0
    for key, size in model.parameter_layout:
        out.append((key, offset))
        offset += size
    return out


#: The moved values of a parameter p whose differences :func:`_richardson` combines: p + h, p - h, p + h/2, p - h/2.
STEPS = (1.0, -1.0, 0.5, -0.5)

#: A parameter's value p, its step h and the model at each of p + STEPS h: what the central differences of the
#: scene-to-P map and of the start both difference (made once per parameter by :func:`moved_models`).
Moved = tuple[float, float, list[DAEModel]]


def moved_models(model: DAEModel, name: str) -> Moved:
    """``model`` with the parameter ``name`` at each of p + STEPS h (:data:`Moved`)."""
    p = parameter_value(model, name)
    h = _step(p)
    return p, h, [moved_parameter(model, name, p + s * h) for s in STEPS]


def _richardson(f: Any, p: float, h: float) -> NDArray[np.float64]:
    """(4 D(h/2) - D(h)) / 3 of central differences D of ``f`` at ``p``, with the exact 0 and 1 of values
    that do not move or move as ``p`` itself (an entry of P that is the parameter); ``f`` is given the index
    of each moved value in :data:`STEPS`."""
    plus, minus, plus2, minus2 = (np.asarray(f(k), dtype=float) for k in range(len(STEPS)))
    d1, d2 = (plus - minus) / (2 * h), (plus2 - minus2) / h
    out = (4.0 * d2 - d1) / 3.0
    still = (plus == minus) & (plus2 == minus2)
    same = (plus == p + h) & (minus == p - h) & (plus2 == p + h / 2) & (minus2 == p - h / 2)
    out[still] = 0.0
    out[same] = 1.0
    return out


def parameter_directions(model: DAEModel, names: Sequence[str], moved: dict[str, Moved] | None = None
                         ) -> NDArray[np.float64]:
    """dP/dp, (n_P, Ns): how the run-time vector P moves with each named parameter (column j for
    ``names[j]``); exact 1 and 0 where P holds the number itself or not at all, else the derivative of
    the numbers derived from it (central differences with Richardson's extrapolation, ``STEP_BITS``).
    ``moved``: the moved models by name (:func:`moved_models`), made here for the names it lacks."""
    names = _checked_names(names)
    moved = {} if moved is None else moved
    columns = []
    for name in names:
        if name not in moved:
            moved[name] = moved_models(model, name)
        p, h, models = moved[name]
        columns.append(_richardson(lambda k, models=models: models[k].parameter_values, p, h))
    return np.stack(columns, axis=1) if columns else np.zeros((model.parameter_values.size, 0))


def _checked_names(names: Any) -> tuple[str, ...]:
    if isinstance(names, str) or not isinstance(names, Sequence) or not names:
        raise SceneError(f"sensitivities: parameters={names!r}, must be a non-empty list of names from "
                         "model.parameter_names, e.g. ['clearance.clearance'].")
    twice = sorted({n for n in names if list(names).count(n) > 1})
    if twice:
        raise SceneError(f"sensitivities: parameters={list(names)!r}, must name each parameter once "
                         f"({', '.join(map(repr, twice))} repeated).")
    return tuple(names)


def initial_sensitivities(model: DAEModel, names: Sequence[str], start: str = "ideal",
                          allow_penetration: bool = False, moved: dict[str, Moved] | None = None
                          ) -> NDArray[np.float64]:
    """dy0/dp of the start ``model.initial_state(start=...)``, (n_states, Ns): central differences with
    Richardson's extrapolation over models with the parameter moved (the start is a Newton solution
    from the declared state, not a formula); the algebraic rows are made consistent afterwards.
    ``moved``: the moved models by name (:func:`moved_models`; those of :func:`parameter_directions`), made
    here for the names it lacks (CasADi evaluates them: a session's extras read its own parameters)."""
    names = _checked_names(names)
    moved = {} if moved is None else moved
    columns = []
    for name in names:
        if name not in moved:
            moved[name] = moved_models(model, name)
        p, h, models = moved[name]

        def start_at(k: int, models: list[DAEModel] = models) -> NDArray[np.float64]:
            with warnings.catch_warnings():  # the start's notes were given for the run itself
                warnings.simplefilter("ignore")
                return models[k].initial_state(start=start, allow_penetration=allow_penetration)[0]
        columns.append(_richardson(start_at, p, h))
    return np.stack(columns, axis=1)


def model_sensitivity_functions(model: DAEModel, width: int) -> SensitivityFunctions:
    """The model's sensitivity functions for ``width`` parameters, with the directional derivatives of
    the accelerations, the constraints, each term's force and the simple pairs' gap rates (built once per
    structure and width, kept by the structure's compiled object)."""
    extras = (EXTRA_ACCEL, EXTRA_KINEMATICS, *(EXTRA_TERM0 + k for k in range(len(model.terms))),
              *(extra for _, _, extra, _, _ in model.auto_pairs))
    return model.compiled.sensitivity(width, extras)


@dataclass(frozen=True)
class Shared:
    """An input of :func:`mapped` that is the same at every point."""

    value: Any


def mapped(f: Any, N: int, *inputs: Any) -> NDArray[np.float64]:
    """``f`` (one matrix output) at N points in one call: each input either :class:`Shared` or stacked per
    point along its first axis ((N,) for a scalar, (N, r) for a vector, (N, r, c) for a matrix); returns
    (N, rows, cols) of the output. One point calls ``f`` itself (a map costs ~0.1 ms to build)."""
    cols = []
    for x in inputs:
        if isinstance(x, Shared):
            cols.append(np.asarray(x.value, dtype=float))
            continue
        a = np.asarray(x, dtype=float).reshape(N, x.shape[1] if np.ndim(x) > 1 else 1, -1)
        cols.append(a.transpose(1, 0, 2).reshape(a.shape[1], -1))  # point k's block in columns k c ... (k + 1) c
    out = np.array((f if N == 1 else f.map(N))(*cols), dtype=float)
    return out.reshape(out.shape[0], N, -1).transpose(1, 0, 2)


@dataclass(frozen=True)
class RootTerms:
    """The pieces of the jump at the model's roots (each (n_roots,) but ``g_p``): the root's sensitivity
    ``g_p`` = g_y S + g_y' S' + g_P dP (n_roots, Ns); its ``rate`` g_t + g_y y'; the magnitude of that rate's
    terms ``scale`` = |g_t| + |g_y| |y'|; its ``curvature`` d^2 g/dt^2; and its uncertainty ``error`` =
    |g_y| (atol + rtol |y|) (the grazing tests of :func:`daeclear.solvers.sensitivity_jumps.is_grazing`)."""

    g_p: NDArray[np.float64]
    rate: NDArray[np.float64]
    scale: NDArray[np.float64]
    curvature: NDArray[np.float64]
    error: NDArray[np.float64]


class ModelSensitivity:
    """What a run with sensitivities to ``names`` asks of ``model``, evaluated in CasADi (the python
    path; the compiled loop calls the same functions generated in C): every contact element, whose rule
    says which roots make its events and how its terms' parameters follow its pairs' latched speeds
    (``event_roots``, ``term_sensitivities`` of :class:`~daeclear.assembly.contact_pairs.PairLogic`)."""

    #: The extras whose directional derivatives a run's rows and events evaluate (consistent S, the channels'
    #: S): in a stacked session they follow the model's extras in this order (``stacked_extras``).
    @staticmethod
    def row_derivatives(model: DAEModel) -> tuple[int, ...]:
        return (EXTRA_ACCEL, *(EXTRA_TERM0 + k for k in range(len(model.terms))), EXTRA_OUTPUTS, EXTRA_KINEMATICS,
                EXTRA_START_KINEMATICS)

    def __init__(self, model: DAEModel, names: Sequence[str]) -> None:
        self.model = model
        self.names = _checked_names(names)
        #: the models with each parameter moved: differenced for dP here, for the start's S by initial_sensitivities
        self.moved: dict[str, Moved] = {}
        self.dP = parameter_directions(model, self.names, self.moved)
        self.functions = model_sensitivity_functions(model, len(self.names))
        self._extra = {k: f for k, f in zip(self.functions.extra_index, self.functions.extras)}
        #: the stacked session whose extras (:meth:`row_derivatives`) evaluate the rows (None: CasADi here)
        self.session: Any = None
        # each contact element's gap rates' Jacobian [r_q | r_v | r_P]: the latched approach speed's derivative
        self._rate_jacobians = [jacobian_blocks(logic.rate.function, f"rate_jacobian{i}", out=logic.rate_output)
                                for i, logic in enumerate(model.contacts)]

    @property
    def width(self) -> int:
        return len(self.names)

    def residual(self, t: float, y: NDArray, yp: NDArray, S: NDArray, Sp: NDArray, active: Sequence[bool],
                 params: Sequence[NDArray], S_params: Sequence[NDArray]) -> NDArray[np.float64]:
        """F_y S + F_y' S' + F_P dP of the model with its ``active`` terms, (n_states, Ns)."""
        f, P, dP = self.functions, self.model.parameter_values, self.dP
        out = np.array(f.res(t, y, yp, P, S, Sp, dP))
        for k, on in enumerate(active):
            if on:
                out += np.array(f.term_res[k](t, y, yp, params[k], P, S, Sp, S_params[k].reshape(-1, self.width), dP))
        return out

    def consistent(self, t: float, y: NDArray, S: NDArray, active: Sequence[bool], params: Sequence[NDArray],
                   S_params: Sequence[NDArray]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(S, S') consistent with the mode (``active`` terms, their ``params`` and their sensitivities
        ``S_params``): S_q and S_v kept, the multipliers' and the derivatives' sensitivities the derivative
        of :meth:`DAEModel.consistent_state` (its accelerations' solve) in the direction (S_q, S_v, dP);
        GGL's mu has sensitivity 0 (mu is 0 on the solution for every p)."""
        S_out, Sp = self.consistent_rows(np.array([t], dtype=float), np.asarray(y, dtype=float)[None],
                                         np.asarray(S, dtype=float)[None], active, params, S_params)
        return S_out[0], Sp[0]

    def consistent_rows(self, t: NDArray, y: NDArray, S: NDArray, active: Sequence[bool], params: Sequence[NDArray],
                        S_params: Sequence[NDArray]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`consistent` at N points of one mode at once: ``t`` (N,), ``y`` (N, n_states), ``S``
        (N, n_states, Ns) -> (S, S'), each (N, n_states, Ns); one mapped call per function for all rows."""
        model, W = self.model, self.width
        n, m = model.n_q, model.n_constraints
        N = t.size
        q, v = y[:, :n], y[:, n:2 * n]
        Sq, Sv = S[:, :n], S[:, n:2 * n]
        zero_t = Shared(np.zeros((1, W)))
        forces = model.term_forces(t if N > 1 else t[0], y if N > 1 else y[0], active, params, self.session)
        Qc = np.zeros((N, n)) if forces is None else np.asarray(forces, dtype=float).reshape(N, n)
        dQc = np.zeros((N, n, W))
        for k, on in enumerate(active):
            if on:
                dQc += self.derivative(EXTRA_TERM0 + k, N, [t, q, v, Shared(params[k])],
                                       [zero_t, Sq, Sv, Shared(S_params[k].reshape(-1, W))])
        d = self.derivative(EXTRA_ACCEL, N, [t, q, v, Qc], [zero_t, Sq, Sv, dQc])
        S_out, Sp = np.array(S, dtype=float), np.zeros((N, model.n_states, W))
        S_out[:, 2 * n:2 * n + m] = d[:, n:n + m]
        if model.formulation == "ggl":
            S_out[:, 2 * n + m:2 * n + 2 * m] = 0.0
        Sp[:, :n] = Sv
        Sp[:, n:2 * n] = d[:, :n]
        if model.track_work:
            Sp[:, -1] = d[:, n + m]
        return S_out, Sp

    def switch_sensitivity(self, S_params: Sequence[NDArray]) -> NDArray[np.float64]:
        """The sensitivity of :meth:`DAEModel.switch_vector` (n_switch, Ns): 0 for each term's on/off flag,
        its parameters' sensitivities (the latched values') after it."""
        rows = [np.zeros((1, self.width))]
        out = []
        for S_k in S_params:
            out += [rows[0], np.asarray(S_k, dtype=float).reshape(-1, self.width)]
        return np.vstack(out) if out else np.zeros((0, self.width))

    def channels(self, t: float, y: NDArray, yp: NDArray, S: NDArray, Sp: NDArray, switch: NDArray,
                 S_switch: NDArray) -> NDArray[np.float64]:
        """Every output channel's sensitivity at one point, (n_channels, Ns): d ch/dy S + d ch/dy' S'
        + d ch/d switch S_switch + d ch/dP dP (the chain rule through the channels' functions)."""
        return self.channels_rows(np.array([t], dtype=float), y[None], yp[None], S[None], Sp[None], switch,
                                  S_switch)[0]

    def channels_rows(self, t: NDArray, y: NDArray, yp: NDArray, S: NDArray, Sp: NDArray, switch: NDArray,
                      S_switch: NDArray) -> NDArray[np.float64]:
        """:meth:`channels` at N points of one mode (``switch``, ``S_switch``) at once, (N, n_channels, Ns)."""
        return self.derivative(EXTRA_OUTPUTS, t.size, [t, y, yp, Shared(switch)],
                               [Shared(np.zeros((1, self.width))), S, Sp, Shared(S_switch)])

    def outputs_rows(self, t: NDArray, y: NDArray, yp: NDArray, switch: NDArray) -> NDArray[np.float64]:
        """The channels' values at N points of one mode at once, (N, n_channels)."""
        N = t.size
        return self.model.evaluate(EXTRA_OUTPUTS, [t.reshape(N, 1), y, yp, switch], N, self.session)

    def derivative(self, k: int, N: int, values: Sequence[Any], seeds: Sequence[Any]) -> NDArray[np.float64]:
        """The directional derivative of the model's extra ``k`` at N points, (N, numel_out, Ns): ``values`` its
        inputs but P, ``seeds`` their directions but dP's (each :class:`Shared` or stacked per point); in the
        stacked session's C when there is one (:meth:`row_derivatives`), else in CasADi."""
        if self.session is None:
            if k not in self._extra:  # the channels': made when first asked for
                self._extra[k] = directional(self.model.functions.extras[k], self.width, None, f"sens_extra{k}")
            P, dP = Shared(self.model.parameter_values), Shared(self.dP)
            return mapped(self._extra[k], N, *values, P, *seeds, dP)
        index = len(self.model.functions.extras) + self.row_derivatives(self.model).index(k)
        flat = [np.asarray(x.value, dtype=float).ravel(order="F") if isinstance(x, Shared) else
                np.asarray(x, dtype=float).reshape(N, x.shape[1] if np.ndim(x) > 1 else 1, -1).transpose(0, 2, 1
                                                                                                   ).reshape(N, -1)
                for x in (*values, *seeds)]  # column-major per point, as CasADi's matrices
        out = self.session.eval_extra(index, flat, N)
        return out.reshape(N, self.width, -1).transpose(0, 2, 1)

    def start(self, start: str = "ideal", allow_penetration: bool = False) -> NDArray[np.float64]:
        """dy0/dp of the start ``model.initial_state(start=...)``, (n_states, Ns): :meth:`constrained_start`
        where the start's constraints fix it, else :func:`initial_sensitivities` (central differences of the
        moved models' starts)."""
        S0 = self.constrained_start(allow_penetration) if start == "ideal" else None
        if S0 is None:
            return initial_sensitivities(self.model, self.names, start, allow_penetration, self.moved)
        return S0

    def constrained_start(self, allow_penetration: bool = False) -> NDArray[np.float64] | None:
        """dy0/dp of the chapter's start (``start="ideal"``) where its constraints fix it: as many independent
        constraints (the clearance joints ideal) as coordinates. Then the assembled q solves Phi(q, P) = 0 and
        v solves Phi_q v + Phi_t = 0 whatever the guess, and differentiating them,

            Phi_q S_q = -Phi_P dP,    Phi_q S_v = -(d(Phi_q v + Phi_t)/dq S_q + d(Phi_q v + Phi_t)/dP dP)

        (one directional derivative of the start's kinematics each). None where they do not fix it (fewer
        constraints than coordinates: an open chain; or dependent ones): the start is then the end of the
        Newton path from the guess, differenced instead. The multipliers' rows are 0: made consistent after."""
        model, W = self.model, self.width
        n, m = model.n_q, len(model.start_constraint_names)
        if m != n or n == 0:
            return None
        with warnings.catch_warnings():  # the run's own start (kept by the structure); its notes were given
            warnings.simplefilter("ignore")
            y0 = model.initial_state(start="ideal", allow_penetration=allow_penetration)[0]
        q, v, t = y0[None, :n], y0[None, n:2 * n], np.zeros(1)
        Phi_q = model.constraints(q[0], v[0], 0.0, self.session, ideal=True)[1]
        singular = np.linalg.svd(Phi_q, compute_uv=False)
        if not singular[-1] > RANK_TOL * singular[0]:
            return None
        zero, zero_t = np.zeros((1, n, W)), Shared(np.zeros((1, W)))
        S = np.zeros((model.n_states, W))
        d_P = self.derivative(EXTRA_START_KINEMATICS, 1, [q, v, t], [zero, zero, zero_t])[0]  # along dP: Phi_P dP
        S[:n] = -np.linalg.solve(Phi_q, d_P[:m])
        d_qP = self.derivative(EXTRA_START_KINEMATICS, 1, [q, v, t], [S[None, :n], zero, zero_t])[0]
        S[n:2 * n] = -np.linalg.solve(Phi_q, d_qP[m + m * n:])  # along (S_q, dP): d(Phi_q v + Phi_t)
        return S

    def projected(self, t: float, y: NDArray, S: NDArray) -> NDArray[np.float64]:
        """S with S_q and S_v moved (least norm) onto the linearised constraints, d Phi = Phi_q S_q + Phi_P dP
        = 0 and d(Phi_q v + Phi_t) = 0: what :meth:`DAEModel.consistent_state` with ``project`` does to q and v
        at a GGL restart (IDA's S holds them only to its tolerance; GGL's index-2 rows need them exact)."""
        model, W = self.model, self.width
        n, m = model.n_q, model.n_constraints
        if not m:
            return np.array(S, dtype=float)
        S = np.array(S, dtype=float)
        q, v = y[:n], y[n:2 * n]
        Phi_q = model.constraints(q, v, t, self.session)[1]
        zero_t = Shared(np.zeros((1, W)))
        for rows, level in ((slice(0, n), slice(0, m)), (slice(n, 2 * n), slice(m + m * n, 2 * m + m * n))):
            d = self.derivative(EXTRA_KINEMATICS, 1, [q[None], v[None], np.array([t])], [S[None, :n], S[None, n:2 * n],
                                                                                          zero_t])[0][level]
            S[rows] -= np.linalg.lstsq(Phi_q, d, rcond=None)[0]
        return S

    def roots(self, t: float, y: NDArray, yp: NDArray, S: NDArray, Sp: NDArray, rtol: float = 0.0,
              atol: NDArray | None = None) -> RootTerms:
        """What the jump at each root needs of it (:class:`RootTerms`), at a point of the mode before the
        switch; ``rtol``/``atol`` the run's tolerances (the gap's uncertainty)."""
        model, n = self.model, self.model.n_states
        f = self.functions.root_jacobian
        if f is None or self.functions.root_curvature is None:
            raise ValueError("ModelSensitivity.roots: the model has no roots")
        P = model.parameter_values
        n_roots = f.size_out(0)[0]
        # in the stacked session (its last two extras: stacked_extras), else CasADi's
        index = len(model.functions.extras) + len(self.row_derivatives(model))
        if self.session is not None:
            J = self.session.eval_extra(index, [np.array([t]), y, yp], 1)[0].reshape(-1, n_roots).T
        else:
            J = np.array(f(t, y, yp, P))
        g_t, g_y, g_yp, g_P = J[:, :1], J[:, 1:1 + n], J[:, 1 + n:1 + 2 * n], J[:, 1 + 2 * n:]
        if np.any(g_yp != 0.0):
            raise ValueError("ModelSensitivity.roots: a root reads y' (its rate would need y''): not supported")
        ypp = np.zeros(n)
        ypp[:model.n_q] = yp[model.n_q:2 * model.n_q]  # q'' = v' (GGL: mu is 0 on the solution)
        tolerance = (np.zeros(n) if atol is None else np.asarray(atol, dtype=float)) + rtol * np.abs(y)
        return RootTerms(g_p=g_y @ S + g_yp @ Sp + g_P @ self.dP, rate=g_t[:, 0] + g_y @ yp,
                         scale=np.abs(g_t[:, 0]) + np.abs(g_y) @ np.abs(yp),
                         curvature=(self.session.eval_extra(index + 1, [np.array([t]), y, yp, ypp], 1)[0]
                                    if self.session is not None else
                                    np.array(self.functions.root_curvature(t, y, yp, ypp, P)).ravel()),
                         error=np.abs(g_y) @ tolerance)

    def approach_rate(self, root: int, y: NDArray, yp: NDArray, S: NDArray
                      ) -> tuple[float, NDArray[np.float64], float]:
        """The penetration rate of the pair of gap ``root`` (the approach speed an onset latches), its
        sensitivity r_q S_q + r_v S_v + r_P dP (Ns,) and its rate along y' (before the switch)."""
        model, n = self.model, self.model.n_q
        for i, logic in enumerate(model.contacts):
            if root in logic.roots:
                j = logic.rate_index(root)
                P = model.parameter_values
                q, v = y[:n], y[n:2 * n]
                rate = float(np.array(logic.rate.function(q, v, P)[logic.rate_output]).ravel()[j])
                J = np.array(self._rate_jacobians[i](q, v, P))[j]
                r_q, r_v, r_P = J[:n], J[n:2 * n], J[2 * n:]
                return rate, r_q @ S[:n] + r_v @ S[n:2 * n] + r_P @ self.dP, float(r_q @ yp[:n] + r_v @ yp[n:2 * n])
        raise IndexError(f"no contact pair watches root {root}")
