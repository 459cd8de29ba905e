"""Sensitivities through a friction law's kinks (docs/sensitivities.md, "Kinks").

Modified Coulomb friction's correction c_d breaks at |v_T| = v0 and v1: the force is continuous there but its
slope in v_T jumps, so S' jumps with F_y. A run with sensitivities stops IDA at each kink (roots v_T - b of the
law's breakpoints b, watched in runs with sensitivities only) and integrates S on the piece of the law it is on;
S itself is continuous there. Before, the chapter's Fig. 4.15 scene with friction 0.05 failed at the first slip
reversal (t = 0.7255 ms, IDA_CONV_FAIL at h = 1e-25 s): every step across a kink failed S's error test.

* the law's pieces against its formula (hand values);
* a block on an incline, pressed by gravity onto the lower surface of a translational clearance joint and
  decelerated by friction through v1, v0 and -v0 (no contact event, only kinks): the Taylor remainder of
  y(p + h) ~ y(p) + S h falls as h^2, both backends; with the pieces never switched it falls as h;
* the Fig. 4.15 scene with friction 0.05: past the reversal against central differences, and through six
  reversals (10 ms).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.assembly.sensitivity import parameter_value
from daeclear.model.scene import TranslationalClearance
from daeclear.solvers import sensitivity_carrier
from sensitivity_runs import forward_sensitivities


def test_modified_coulomb_pieces_are_the_law_on_each_piece() -> None:
    """c_f = 0.1, F_N = 10 N, v0 = 1e-4, v1 = 2e-4 m/s: F_T = -c_f F_N c_d sign(v_T), by hand."""
    law = dcc.ModifiedCoulomb(coefficient=0.1, v0=1e-4, v1=2e-4)
    assert law.kinks == (1e-4, 2e-4)
    assert law.breakpoints == (-2e-4, -1e-4, 1e-4, 2e-4)
    # (piece, v_T, the force there): inside each piece and continued past its ends (the ramp is linear)
    for piece, v, force in [(0, -3e-4, 1.0), (1, -1.5e-4, 0.5), (2, 0.5e-4, 0.0), (3, 1.5e-4, -0.5), (4, 3e-4, -1.0),
                            (3, 3e-4, -2.0), (1, -3e-4, 2.0), (4, 0.5e-4, -1.0)]:
        assert law.piece(10.0, v, piece) == pytest.approx(force, abs=1e-12), (piece, v)
    for piece, v in [(0, -3e-4), (1, -1.5e-4), (2, 0.5e-4), (3, 1.5e-4), (4, 3e-4)]:
        assert law.piece(10.0, v, piece) == pytest.approx(law.friction_force(10.0, v), abs=1e-12)
    assert dcc.Coulomb(coefficient=0.1).kinks == () and dcc.NoFriction().kinks == ()


def block(coefficient: float = 0.3) -> dc.DAEModel:
    """A slider (0.14 kg) resting on the lower surface of a guide tilted by asin(0.1), at its corners' static
    penetration (Kelvin-Voigt, 1e6 N/m), sliding up at 2 mm/s: gravity and friction (0.3 > 0.1 / cos) stop it;
    its lower corners' sliding speeds cross v1, v0 and -v0 and it settles where c_d mu cos = sin."""
    length, clearance, K, m, s = 0.05, 0.5e-3, 1e6, 0.14, 0.1
    c = np.sqrt(1.0 - s * s)
    scene = dc.Scene("incline", gravity=(-9.81 * s, -9.81 * c))
    sink = m * 9.81 * c / (2.0 * K)
    slider = scene.add(dc.Body("slider", mass=m, inertia=1e-4, position=(0.0, -clearance - sink), velocity=(2e-3, 0.0)))
    scene.add(TranslationalClearance("g", scene.ground, slider, point_i=(0.0, 0.0), point_j=(0.0, 0.0),
                                     slider_axis=(1.0, 0.0), length=length, width=length, corner_radius=1e-3,
                                     clearance=clearance, law=dcc.KelvinVoigt(stiffness=K, damping=300.0),
                                     friction=dcc.ModifiedCoulomb(coefficient=coefficient)))
    return dc.assemble(scene)


T_BLOCK = 1.5e-3
BLOCK_NAMES = ["g.law.damping", "slider.inertia", "g.friction.coefficient"]
STEPS = (1e-2, 2.5e-3, 6.25e-4)  # relative to each parameter


def final_state(model: dc.DAEModel, values: dict[str, float] | None = None) -> tuple[np.ndarray, int]:
    moved = model.with_parameters(values) if values else model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(moved, T_BLOCK, options=dc.SolverOptions(start="declared", rtol=1e-12),
                             save=dc.SaveAt(times=[0.0, T_BLOCK], steps=False))
    return np.array([result[name][-1] for name in model.state_names[:2 * model.n_q]]), len(result.events)


def remainder_ratios(model: dc.DAEModel, S: np.ndarray) -> np.ndarray:
    """(n_params, 2): how much max |y(p + h) - y(p) - S h| over the positions and velocities at T falls per 4-fold h."""
    base, events = final_state(model)
    assert events == 0  # the lower corners stay in contact, the upper ones free: kinks only
    out = np.zeros((len(BLOCK_NAMES), len(STEPS)))
    for j, name in enumerate(BLOCK_NAMES):
        p = parameter_value(model, name)
        for k, step in enumerate(STEPS):
            moved, events = final_state(model, {name: p + step * p})
            assert events == 0
            out[j, k] = np.abs(moved - base - S[:, j] * step * p).max()
    return out[:, :-1] / out[:, 1:]


@pytest.mark.parametrize("backend", ["c", "python"])
def test_taylor_remainder_across_kinks_falls_as_h_squared(backend: str) -> None:
    model = block()
    assert model.kink_pairs.count("g.C_lower") == 4 and len(model.kink_pairs) == 4 * len(model.terms)
    run = forward_sensitivities(model, T_BLOCK, BLOCK_NAMES, rtol=1e-11, start="declared", backend=backend)
    assert run.success and not run.events
    crossed = [e for e in run.kinks if e.pair == "g.C_lower"]
    assert len(crossed) >= 3 and all(np.all(np.isfinite(e.dt_dp)) for e in crossed)  # v1, v0, -v0
    assert run.result.stats["n_kinks"] == len(run.kinks)
    ratios = remainder_ratios(model, run.S[-1, :2 * model.n_q])
    assert np.all((10.0 < ratios) & (ratios < 20.0)), ratios


def test_pieces_never_switched_leave_a_first_order_remainder() -> None:
    """The test double: S integrated on the start's pieces all along (the carrier's switch at each kink left out)
    finishes, but its remainder falls only as h: the switch is tested, not only present."""
    model = block()
    pieces_at = sensitivity_carrier.SensitivityCarrier.pieces_at

    def frozen(self: sensitivity_carrier.SensitivityCarrier, t: float, y: np.ndarray, yp: np.ndarray,
               found: np.ndarray | None) -> dict[int, int]:
        return self.pieces or pieces_at(self, t, y, yp, None)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(sensitivity_carrier.SensitivityCarrier, "pieces_at", frozen)
        run = forward_sensitivities(model, T_BLOCK, BLOCK_NAMES, rtol=1e-11, start="declared", backend="c")
    assert run.success
    ratios = remainder_ratios(model, run.S[-1, :2 * model.n_q])
    assert np.all(ratios < 8.0), ratios


def test_plain_runs_watch_no_kinks() -> None:
    """The kinks are roots of the stacked DAE of a run with sensitivities only: a plain run's roots are the gaps."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    roots = model.functions.roots
    assert roots is not None and roots.numel_out(0) == len(model.gap_names) == 1
    assert model.kink_pairs == ("clearance",) * 4
    stacked = model.compiled.stacked(1, True, True, ()).functions.roots
    assert stacked is not None and stacked.numel_out(0) == 5


FIG415 = ["clearance.clearance", "clearance.friction.coefficient"]


def fig415_final(model: dc.DAEModel, T: float, values: dict[str, float]) -> tuple[np.ndarray, list[tuple[str, str]]]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(model.with_parameters(values), T, options=dc.SolverOptions(rtol=1e-13),
                             save=dc.SaveAt(times=[0.0, T], steps=False))
    return (np.array([result[name][-1] for name in model.state_names[:2 * model.n_q]]),
            [(e.pair, e.kind) for e in result.events])


@pytest.mark.slow
def test_fig415_with_friction_past_the_slip_reversal_against_central_differences() -> None:
    """Failed before at t = 0.7255 ms (IDA_CONV_FAIL). The slip reverses in the second impact (0.6949 to
    0.7516 ms): four kinks; at 1 ms every position's and velocity's S against central differences (step 1e-4
    relative, rtol 1e-13: the same six events; at 1e-12 their own error reaches 1e-4), 1e-4 of each group's
    largest (measured: 1.5e-5 at most)."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    T = 1e-3
    run = forward_sensitivities(model, T, FIG415, rtol=1e-11, backend="c")
    assert run.success, run.message
    assert [e.kind for e in run.events] == ["onset", "separation"] * 3
    onset, separation = run.events[2].t, run.events[3].t
    assert len([e for e in run.kinks if onset < e.t < separation]) == 4
    n = 2 * model.n_q
    for j, name in enumerate(FIG415):
        p = parameter_value(model, name)
        (plus, seen_plus), (minus, seen_minus) = (fig415_final(model, T, {name: p + s * 1e-4 * p}) for s in (1, -1))
        assert seen_plus == seen_minus == [(e.pair, e.kind) for e in run.events]
        fd = (plus - minus) / (2e-4 * p)
        S = run.S[-1, :n, j]
        for kind in (slice(0, n // 2), slice(n // 2, n)):  # positions, velocities: each against its own scale
            assert np.abs(S[kind] - fd[kind]).max() <= 1e-4 * np.abs(fd[kind]).max(), (name, kind)


def test_fig415_with_friction_through_six_reversals() -> None:
    """10 ms of the same scene (rtol 1e-8): every slip reversal in contact crosses four kinks; the crossings in
    free flight are no restarts and no events."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    run = forward_sensitivities(model, 10e-3, FIG415[:1], rtol=1e-8, backend="c")
    assert run.success, run.message
    contact, inside = False, 0
    for e in sorted(run.events + run.kinks, key=lambda e: e.t):
        contact = {"onset": True, "separation": False}.get(e.kind, contact)
        inside += e.kind == "kink" and contact
    assert inside >= 24 and inside == len(run.kinks) == run.result.stats["n_kinks"]
    assert np.all(np.isfinite(run.S[-1]))


def test_fig415_with_friction_past_the_reversal_at_rtol_1e_12() -> None:
    """With only S's rows on the law's piece (y's on the law itself) the run failed at the reversal at rtol 1e-12
    (IDA_CONV_FAIL at 0.7255 ms): the whole term on the piece passes it."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", friction=0.05))
    run = forward_sensitivities(model, 0.8e-3, FIG415[1:], rtol=1e-12, backend="c")
    assert run.success, run.message
    assert len(run.kinks) == 4 and all(0.7255e-3 < e.t < 0.7256e-3 for e in run.kinks)
