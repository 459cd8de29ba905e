"""The assembled index-1 model as an ODE in ``x = (q, v)``: the symbolic functions (an
:class:`~daeclear.engine.codegen.OdeSpec`, built once per structure) of the non-IDA methods."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np

from ..assembly.assemble import DAEModel
from ..engine.codegen import OdeSpec
from ..core.errors import SceneError

__all__ = ["ode_spec"]


def ode_spec(model: DAEModel) -> OdeSpec:
    """The model's index-1 equations (checked by the caller) as an ODE in x = (q, v); SceneError when the
    model has other states (track_work) or a gap function depends on anything but (t, q)."""
    if getattr(model, "track_work", False) or model.n_states != 2 * model.n_q + model.n_constraints:
        raise SceneError(f"simulate: model '{model.scene_name}' has states besides q, v and the multipliers "
                         "(track_work); only method='ida' integrates it.")
    compiled = model.compiled  # once per structure: the models of a structure share what it compiled
    spec = compiled.ode_spec
    if spec is None:
        spec = compiled.ode_spec = _symbolic_spec(model)
    return dataclasses.replace(spec, mass=tuple(float(mk) for mk in model.mass_diagonal),
                               parameters=tuple(float(x) for x in model.parameter_values))


def _symbolic_spec(model: DAEModel) -> OdeSpec:
    """The functions of :func:`ode_spec`, every number a run-time parameter (P last)."""
    n, m = model.n_q, model.n_constraints
    t = ca.SX.sym("t")
    q = ca.SX.sym("q", n)
    v = ca.SX.sym("v", n)
    P = ca.SX.sym("P", model.parameter_values.size)
    x = ca.vertcat(q, v)
    Phi, Phi_q, Phi_dot, gamma = model.kinematics(q, v, t, P)
    layout = model.parameter_layout
    offsets = dict(zip([name for name, _ in layout], np.cumsum([0] + [size for _, size in layout])))
    alpha, beta = P[int(offsets["baumgarte.alpha"])], P[int(offsets["baumgarte.beta"])]
    c = gamma - 2.0 * alpha * Phi_dot - beta ** 2 * Phi
    Q = model.base_force(t, q, v, P)
    # sparse outputs: the generated C keeps their nonzeros only (ode_driver.c scatters them)
    sys_f = ca.Function("sys", [t, q, v, P], [Q, Phi_q, c])
    a = ca.SX.sym("a", n)
    lam = ca.SX.sym("lam", m)
    r = ca.vertcat(ca.mtimes(Phi_q.T, lam) - Q, ca.mtimes(Phi_q, a) - c)
    sys_jac = ca.Function("sys_jac", [t, q, v, a, lam, P], [ca.jacobian(r, x)])
    forces, jacs, n_params = [], [], []
    for k, term in enumerate(model.terms):
        p = ca.SX.sym("p", term.n_params)
        F = term.force(t, q, v, p, P)
        forces.append(ca.Function(f"term{k}", [t, q, v, p, P], [F]))
        jacs.append(ca.Function(f"term{k}_jac", [t, q, v, p, P], [ca.jacobian(F, x)]))
        n_params.append(term.n_params)
    gaps = None
    if model.functions.roots is not None and model.gap_names:
        n_rest = model.n_states - 2 * n
        rest = ca.SX.sym("lam", n_rest)
        yp = ca.SX.sym("yp", model.n_states)
        g = model.functions.roots(t, ca.vertcat(q, v, rest), yp, P)
        for label, sym in (("velocities", v), ("multipliers", rest), ("derivatives", yp)):
            if sym.numel() and ca.depends_on(g, sym):
                raise SceneError(f"simulate: the gap functions of model '{model.scene_name}' depend on {label}; "
                                 "only method='ida' integrates such a model.")
        g_dot = ca.mtimes(ca.jacobian(g, q), v) + ca.jacobian(g, t)
        gaps = ca.Function("gaps", [t, q, v, P], [g, g_dot])
    return OdeSpec(n=n, m=m, mass=tuple(float(mk) for mk in model.mass_diagonal), sys=sys_f, sys_jac=sys_jac,
                   gaps=gaps, term_force=tuple(forces), term_jac=tuple(jacs), n_params=tuple(n_params),
                   name=model.functions.name, outputs=model.outputs, n_parameters=int(P.numel()))
