"""A few channels of a run read from its stored rows (results.channel_eval.RunChannels) and one state
made consistent alone (Result.state): what the wear study reads every block, without the consistency
pass over every row. Checked against the run's own channels and states (the pass and the output
function over every row, themselves checked against the compiled one-pass report in
tests/test_lazy_channels.py), value for value, on a second identical run.
"""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import SceneError
from daeclear.results.channel_eval import RunChannels

T_END = 0.006  # s: the start's impacts


@pytest.fixture(scope="module")
def scene() -> dc.Scene:
    return dc.mechanisms.slider_crank("revolute", friction=0.1)


def _kinds(model: dc.DAEModel) -> tuple[list[str], list[str]]:
    """The model's channels that read only positions and velocities, and those that read a multiplier or yp
    (by the output function's sparsity)."""
    y = np.array(model.outputs.jac_sparsity(0, 1), dtype=bool)
    yp = np.array(model.outputs.jac_sparsity(0, 2), dtype=bool)
    lam = slice(2 * model.n_q, 2 * model.n_q + model.n_constraints)
    other = y[:, lam].any(axis=1) | yp.any(axis=1)
    names = list(model.channel_names)
    return [n for n, o in zip(names, other) if not o], [n for n, o in zip(names, other) if o]


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_kinematic_channels_are_read_without_the_pass_bit_for_bit(scene, formulation):
    model = dc.assemble(scene, formulation)
    kinematic, dynamic = _kinds(model)
    assert "clearance.normal_force" in kinematic and "clearance.sliding_velocity" in kinematic
    assert any(name.startswith("drive.") for name in dynamic)  # the driver's moment is a multiplier's
    first, second = (dc.simulate(model, T_END, rtol=1e-8) for _ in range(2))  # one run twice (deterministic)
    assert len(first.events) > 3
    read = RunChannels(model, kinematic)(first, model)
    assert first.channel_source.raw  # no consistency pass was made
    for name in kinematic:
        assert np.array_equal(read[name], second[name], equal_nan=True), name
    both = RunChannels(model, [kinematic[0], dynamic[0]])(first, model)  # a multiplier's channel: the pass
    assert not first.channel_source.raw
    for name in (kinematic[0], dynamic[0]):
        assert np.array_equal(both[name], second[name], equal_nan=True), name
    computed = first[dynamic[0]]  # every channel computed: RunChannels takes them
    assert RunChannels(model, dynamic[:1])(first, model)[dynamic[0]] is computed


def test_one_state_is_made_consistent_alone(scene):
    model = dc.assemble(scene)
    first, second = (dc.simulate(model, T_END) for _ in range(2))
    middle = first.n_times // 2
    rows = {k: first.state(k) for k in (-1, middle, 0)}
    assert first.channel_source.raw  # the rows alone: no pass over the run
    for k, row in rows.items():
        assert np.array_equal(row, second.y[k]), k
    assert not np.array_equal(first.channel_source.stored_y[-1], second.y[-1])  # IDA's multipliers differ
    with pytest.raises(IndexError):
        first.state(first.n_times)
    assert np.array_equal(second.state(-1), second.y[-1])  # after the pass: its row


def test_run_channels_refuse_unknown_names_and_other_structures(scene):
    model = dc.assemble(scene)
    with pytest.raises(SceneError, match=r"names=\['clearance.nope'\], must be channels of the model"):
        RunChannels(model, ["clearance.nope"])
    reader = RunChannels(model, ["clearance.penetration"])
    other = dc.assemble(dc.mechanisms.slider_crank("translational"))
    run = dc.simulate(other, 0.001)
    with pytest.raises(SceneError, match="another structure"):
        reader(run, other)
    renumbered = model.with_parameters({"clearance.clearance": 4e-4})  # new numbers, the same structure
    run = dc.simulate(renumbered, 0.002)
    assert np.array_equal(reader(run, renumbered)["clearance.penetration"],
                          dc.simulate(renumbered, 0.002)["clearance.penetration"])


def test_the_python_backend_reads_them_alike(scene):
    """A run of the python backend (scikit-sundae, CasADi's evaluation): its channels read in that backend."""
    model = dc.assemble(scene)
    options = dc.SolverOptions(backend="python")
    first, second = (dc.simulate(model, 0.002, options=options) for _ in range(2))
    assert first.parameters["simulate"]["backend"] == "python" and len(first.events) > 3
    names = ["clearance.normal_force", "clearance.penetration", "clearance.sliding_velocity"]
    read = RunChannels(model, names)(first, model, "python")
    assert first.channel_source.raw
    for name in names:
        assert np.array_equal(read[name], second[name], equal_nan=True), name
