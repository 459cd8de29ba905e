"""A run with forward sensitivities (``simulate(..., sensitivities=...)``) on the chapter's slider-crank with
its revolute clearance joint (Fig. 4.15's scene, c = 0.5 mm, 5000 rpm) over its first 2 ms (13 impacts), and
with its translational clearance joint (corner pairs) over 5 ms (16): constraints and multipliers, the latched
approach speed; every position's and velocity's sensitivity to the clearance and the restitution against
central differences of ordinary runs (issue 43's validation), both formulations.

Differences need a step that keeps the impacts' sequence: at 1e-3 of the clearance the runs have 15
impacts, not 13 (the derivative of a run whose events change is no derivative); at 1e-4 they keep it.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import daeclear as dc
from sensitivity_runs import forward_sensitivities

NAMES = ["clearance.clearance", "clearance.law.restitution"]
STEP = 1e-4  # relative: keeps the 13 impacts


def final_states(model: dc.DAEModel, values: dict[str, float], T: float) -> tuple[np.ndarray, int]:
    result = dc.simulate(model.with_parameters(values), T, options=dc.SolverOptions(rtol=1e-11),
                         save=dc.SaveAt(times=[0.0, T], steps=False))
    return np.array([result[name][-1] for name in model.state_names[:2 * model.n_q]]), len(result.events)


@pytest.mark.slow
@pytest.mark.parametrize(("joint", "T", "impacts"), [("revolute", 2e-3, 13), ("translational", 5e-3, 16)])
@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_every_state_sensitivity_against_differences(joint: str, T: float, impacts: int, formulation: str) -> None:
    model = dc.assemble(dc.mechanisms.slider_crank(joint), formulation=formulation)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        run = forward_sensitivities(model, T, NAMES, rtol=1e-10, backend="auto")
    assert run.success and len(run.events) == impacts
    n = 2 * model.n_q
    for j, name in enumerate(NAMES):
        p = model.parameter(name)[0]
        (plus, n_plus), (minus, n_minus) = (final_states(model, {name: p + s * STEP * p}, T) for s in (1, -1))
        assert n_plus == n_minus == impacts
        fd = (plus - minus) / (2 * STEP * p)
        S = run.S[-1, :n, j]
        for kind in (slice(0, n // 2), slice(n // 2, n)):  # positions, velocities: each against its own scale
            assert S[kind] == pytest.approx(fd[kind], rel=1e-3, abs=1e-4 * np.abs(fd[kind]).max()), (name, kind)


def test_ggl_restarts_keep_the_sensitivities_on_the_constraints() -> None:
    """GGL at rtol 1e-6 and 1e-8 failed to converge right after the first impact when S (and y) restarted as
    IDA left them, off its index-2 constraints by its tolerance; projected as the run's restarts are, it
    goes on."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="ggl")
    for rtol in (1e-6, 1e-8):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", dc.DaeclearWarning)
            run = forward_sensitivities(model, 0.4e-3, NAMES, rtol=rtol, backend="auto")
        assert run.success and len(run.events) == 2, (rtol, run.message)


@pytest.mark.slow
def test_a_chaotic_run_goes_on_while_its_sensitivities_grow() -> None:
    """Two crank revolutions (24 ms, 51 impacts) of GGL at rtol 1e-8: the sensitivities grow over 100-fold
    (relative), and the stacked run goes on; with GGL's tight Newton coefficient (1e-3) S's corrections did
    not converge in IDA's iterations after 10 ms."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="ggl")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        run = forward_sensitivities(model, 24e-3, NAMES, rtol=1e-8, backend="auto")
    assert run.success and len(run.events) == 51, run.message
    n = 2 * model.n_q
    relative = np.abs(run.S[-1, :n, 0]) * model.parameter("clearance.clearance")[0] / np.abs(run.y[:, :n]).max(axis=0)
    assert relative.max() > 1e2


def test_a_grazing_event_leaves_nan_and_the_run_going_on() -> None:
    """The Fig. 4.15 scene at rtol 1e-6 with the sensitivity to the crank's speed (the driven joint's velocity
    constraint reads it: F_P dP is not zero). The onset at 1.2 ms is grazing at that tolerance (its rate known
    to less than 1 % of itself), so its sensitivities are NaN from there; the run goes on (the NaN column is
    restarted from a consistent S: zeros alone violate the linearised drive constraint, and IDA's error test
    failed at every step size there). Before it the crank's angle and speed have S = t and 1 exactly."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = dc.simulate(model, 2e-3, rtol=1e-6, sensitivities=["drive.speed"], on_failure="return")
    assert result.success, result.message
    grazing = [w for w in caught if issubclass(w.category, dc.PhysicsWarning) and "is grazing" in str(w.message)]
    assert grazing and "'clearance' onset at t=0.0012033" in str(grazing[0].message)
    t = np.asarray(result.t)
    before, after = t < 1.2033e-3, t > 1.2034e-3
    assert before.sum() > 100 and after.sum() > 100
    np.testing.assert_allclose(result.sensitivity("crank.phi", "drive.speed")[before], t[before], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(result.sensitivity("crank.omega", "drive.speed")[before], 1.0, rtol=1e-6)
    assert np.isnan(result.sensitivity("crank.phi", "drive.speed")[after]).all()
