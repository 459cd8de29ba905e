"""The symbolic terms of a scene's applied loads (:mod:`daeclear.model.loads`): generalized forces,
elastic energy, power and channels, as CasADi expressions of (t, q, v) and the parameters P."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any
from collections.abc import Iterable

import casadi as ca

from ..model.elements import GROUND
from ..model.load_values import Expression, LoadState, Table, interpolate
from ..model.loads import BetweenBodies, Force, Load, Motor, SpringDamper, Torque
from .symbolic import Channel, rotation

__all__ = ["LoadBuild", "build_loads"]


@dataclass(frozen=True)
class LoadBuild:
    """The symbolic contribution of a scene's loads: generalized force, elastic energy,
    non-conservative power (W) and output channels."""

    force: Any
    potential: Any
    power: Any
    channels: tuple[Any, ...]


def build_loads(ctx: Any, loads: Iterable[Load]) -> LoadBuild:
    """Symbolic generalized forces (length n_q), energies and channels of ``loads`` (CasADi SX)."""
    Q = ca.SX.zeros(ctx.n_q)
    potential, power = ca.SX(0.0), ca.SX(0.0)
    channels: list[Any] = []
    for load in loads:
        name = load.name
        if isinstance(load, Force):
            frame = ctx.frames[load.body]
            s = ctx.p(name, "point")
            state = _state(frame, None)
            f = ca.vertcat(_value(ctx, name, "fx", load.fx, state), _value(ctx, name, "fy", load.fy, state))
            if load.frame == "body":
                f = ca.mtimes(rotation(frame.phi), f)
            Q += ctx.generalized_force([(load.body, f, frame.point(s))])
            p = ca.dot(f, frame.point_velocity(s))
            channels += [Channel(f"{name}.fx", "N", f[0]), Channel(f"{name}.fy", "N", f[1])]
        elif isinstance(load, SpringDamper):
            bi, bj = ctx.frames[load.body_i], ctx.frames[load.body_j]
            si, sj = ctx.p(name, "s_i"), ctx.p(name, "s_j")
            d = bj.point(sj) - bi.point(si)
            length = ca.sqrt(ca.dot(d, d))
            u = d / length
            rate = ca.dot(u, bj.point_velocity(sj) - bi.point_velocity(si))
            k, c = ctx.p(name, "stiffness"), ctx.p(name, "damping")
            stretch = length - ctx.p(name, "free_length")
            tension = k * stretch + c * rate
            Q += ctx.generalized_force([(load.body_i, tension * u, bi.point(si)),
                                        (load.body_j, -tension * u, bj.point(sj))])
            elastic = 0.5 * k * stretch**2
            potential += elastic
            p = -c * rate**2
            channels += [Channel(f"{name}.length", "m", length), Channel(f"{name}.elongation", "m", stretch),
                         Channel(f"{name}.force", "N", tension), Channel(f"{name}.elastic_energy", "J", elastic)]
        else:  # torques between a body and another body (or the ground)
            if isinstance(load, Torque):
                body, other = load.body, load.reaction or GROUND
            elif isinstance(load, BetweenBodies):
                body, other = load.body_j, load.body_i
            else:
                raise TypeError(f"build_loads: {load.kind} '{load.name}' is not a known load kind")
            fj, fi = ctx.frames[body], ctx.frames[other]
            speed = fj.omega - fi.omega
            if isinstance(load, Torque):
                torque = _value(ctx, name, "value", load.value, _state(fj, fi))
                p = torque * speed
            elif isinstance(load, Motor):
                torque = ctx.p(name, "stall_torque") * (1.0 - speed / ctx.p(name, "no_load_speed"))
                p = torque * speed
                channels.append(Channel(f"{name}.speed", "rad/s", speed))
            else:
                k, c = ctx.p(name, "stiffness"), ctx.p(name, "damping")
                deflection = fj.phi - fi.phi - ctx.p(name, "free_angle")
                torque = -k * deflection - c * speed
                elastic = 0.5 * k * deflection**2
                potential += elastic
                p = -c * speed**2
                channels += [Channel(f"{name}.deflection", "rad", deflection),
                             Channel(f"{name}.elastic_energy", "J", elastic)]
            for frame, moment in ((fj, torque), (fi, -torque)):  # the ground's is dropped
                if frame.index is not None:
                    Q[3 * frame.index + 2] += moment
            channels.append(Channel(f"{name}.torque", "N m", torque))
        power += p
        channels.append(Channel(f"{name}.power", "W", p))
    return LoadBuild(force=Q, potential=potential, power=power, channels=tuple(channels))


def _state(frame: Any, reaction: Any) -> LoadState:
    angle = frame.phi if reaction is None else frame.phi - reaction.phi
    speed = frame.omega if reaction is None else frame.omega - reaction.omega
    return LoadState(frame.r[0], frame.r[1], frame.phi, frame.v[0], frame.v[1], frame.omega, angle, speed)


def _value(ctx: Any, owner: str, field_name: str, value: Any, state: LoadState) -> Any:
    """A load value as an expression of (t, q, v) and the parameters ``<owner>.<field>[.<key>]``."""
    if isinstance(value, Table):
        times, values = ctx.params[f"{owner}.{field_name}.times"], ctx.params[f"{owner}.{field_name}.values"]
        n = len(value.times)
        return interpolate([times[k] for k in range(n)], [values[k] for k in range(n)], ctx.t)
    if isinstance(value, Expression):
        numbers = {key: ctx.p(owner, f"{field_name}.{key}") for key in value.names}
        return value(ctx.t, state, numbers)
    return ctx.p(owner, field_name)

