"""Channels computed when read (issue 35, item 6; issue 31: the file of two revolutions).

A run stores its states and each point's switch vector; its channels are the model's output
function at those rows, computed at the first read. Checked against an independent second
computation: the compiled loop's one-pass report (``dc_report`` with channels, what every run
did before) on the same rows, value for value; a saved and loaded file against the run in memory;
a file in the old layout (every channel stored, version 1); the size of the main job's file.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import daeclear as dc
from daeclear.engine.ida_session import open_session
from daeclear.assembly.dae_model import EXTRA_CHECKS
from daeclear.model.scenefile import scene_from_description
from daeclear.core.values import to_plain

RPM = 5000.0
TWO_REVOLUTIONS = 2 * 60.0 / RPM  # s


@pytest.fixture(scope="module")
def scene() -> dc.Scene:
    return dc.mechanisms.slider_crank("revolute")


@pytest.fixture(scope="module")
def runs(scene: dc.Scene) -> dict[str, dc.Result]:
    """Two revolutions of the Fig. 4.15 scene (51 impacts), both formulations, rtol 1e-8."""
    return {form: dc.simulate(scene, TWO_REVOLUTIONS, rtol=1e-8,
                              options=dc.SolverOptions(formulation=form)) for form in ("index1", "ggl")}


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_lazy_channels_equal_the_one_pass_report_value_for_value(runs, scene, formulation):
    """The channels read from a run equal, bit for bit, those of the compiled one-pass report (the run's
    former path: multipliers, accelerations and channels in one C pass) on the run's own rows."""
    result = runs[formulation]
    source = result.channel_source
    assert source is not None and len(result.events) > 20
    model = dc.assemble(scene, formulation)
    session = open_session(model.functions, rtol=1e-8, atol=1.0, parameters=model.parameter_values)
    try:
        assert session.set_layout(model.layout(project=formulation == "ggl"))
        y, yp, values = session.report(result.t, np.array(result.y), np.array(source.switch))
    finally:
        session.close()
    assert np.array_equal(y, result.y) and np.array_equal(yp, result.yp)  # the states are consistent already
    assert values.shape == (len(model.channel_names), result.n_times)
    for name, row in zip(model.channel_names, values):
        assert np.array_equal(result[name], row), name


@pytest.mark.parametrize("joint", ["revolute", "translational", "ideal"])
def test_the_checked_channels_are_the_outputs_own(joint):
    """The model's checks function (the penetrations and the constraint drift the physics checks read)
    equals, bit for bit, those channels of the whole output function at a run's rows, in the compiled
    library and in CasADi; a model without contact pairs checks the drift alone."""
    scene = dc.mechanisms.slider_crank(joint)
    result = dc.simulate(scene, TWO_REVOLUTIONS / 8, rtol=1e-8)
    model = dc.assemble(scene, "ggl")
    expected = [c for c in model.channel_names if c.endswith(".penetration") or c == "constraints.position"]
    assert model.checked_names == tuple(expected) and "constraints.position" in expected
    assert {f"{g}.penetration" for g in model.gap_names} <= set(expected)  # every contact pair's
    switch = np.array(result.channel_source.switch)
    whole = model.channels(result.t, result.y, result.yp, switch)
    session = open_session(model.functions, rtol=1e-8, atol=1.0, parameters=model.parameter_values)
    try:
        compiled = model.checks(result.t, result.y, switch, session)
    finally:
        session.close()
    # checks takes no yp (it passes zeros): the generated function reads none of it
    checks_function = model.functions.extras[EXTRA_CHECKS]
    assert checks_function.name_in(2) == "yp" and checks_function.sparsity_jac(2, 0).nnz() == 0
    assert checks_function.sparsity_jac(1, 0).nnz() > 0  # it reads y (q): the check can fail
    for checked in (compiled, model.checks(result.t, result.y, switch)):
        assert tuple(checked) == model.checked_names
        for name, values in checked.items():
            assert np.array_equal(values, whole[name]), name
    assert np.max(compiled["constraints.position"]) > 0.0  # values, not zeros: GGL's drift is round-off


def test_a_run_in_memory_computes_its_channels_when_read(scene):
    """simulate checks the run on its checked channels alone: the others wait for the first read."""
    result = dc.simulate(scene, TWO_REVOLUTIONS / 4, rtol=1e-8)
    assert result.channel_source is not None and not result.channel_source.computed
    assert result["clearance.normal_force"].max() > 1e3 and result.channel_source.computed


def test_the_switch_rows_follow_the_segments(runs):
    """Each point's switch vector is its segment's: the contact term on inside contact segments only."""
    result = runs["ggl"]
    switch = result.channel_source.switch
    in_contact = switch[:, 0] > 0  # the clearance joint's one term: its on flag first
    for t0, t1, modes in result.segments:
        inside = (result.t > t0) & (result.t < t1)
        assert np.all(in_contact[inside] == (modes["clearance"] == "contact")), (t0, t1, modes)


def test_a_loaded_file_equals_the_run_in_memory(runs, tmp_path):
    result = runs["ggl"]
    path = result.save(tmp_path / "run.h5")
    with h5py.File(path, "r") as f:  # the states alone: no channel, no yp
        assert f.attrs["version"] == 2 and not list(f["channels"]) and "yp" not in f and "switch" in f
    again = dc.load(path)
    assert not again.channel_source.computed and not again.channel_source.has_yp
    assert again.channel_names == result.channel_names and again.units == result.units
    assert np.array_equal(again.t, result.t) and np.array_equal(again.y, result.y)
    assert np.array_equal(again.yp, result.yp)  # the consistency pass again, from y
    for name in result.channel_names:
        assert np.array_equal(again[name], result[name]), name
    assert again.channel_source.computed
    window = dc.load(path, 0.005, 0.01)  # a window: its rows alone, computed as the whole
    mask = result.window_mask(0.005, 0.01)
    assert np.array_equal(window.yp, result.yp[mask])
    assert np.array_equal(window["clearance.normal_force"], result["clearance.normal_force"][mask])


def test_a_file_in_the_old_layout_loads(runs, tmp_path):
    """Version 1: every channel and yp stored, no /switch and no /channel_names."""
    result = runs["index1"]
    path = result.save(tmp_path / "old.h5", channels=True)
    with h5py.File(path, "a") as f:
        del f["switch"]
        f.attrs["version"] = 1
        assert len(f["channels"]) == len(result.channel_names) and "channel_names" not in f
    old = dc.load(path)
    assert old.channel_source is None and old.channel_names == result.channel_names
    assert np.array_equal(old.yp, result.yp)
    for name in result.channel_names:
        assert np.array_equal(old[name], result[name]), name


def test_a_streamed_run_writes_states_and_reads_back_its_channels(scene, tmp_path):
    path = tmp_path / "s.h5"
    grid = np.linspace(0.0, 0.004, 4001)
    streamed = dc.simulate(scene, 0.004,
                           save=dc.SaveAt(times=grid, stream_to=path))  # keep_data: read back from the file
    memory = dc.simulate(scene, 0.004, save=dc.SaveAt(times=grid))
    assert np.array_equal(streamed.y, memory.y) and np.array_equal(streamed.yp, memory.yp)
    for name in memory.channel_names:
        assert np.array_equal(streamed[name], memory[name]), name
    assert streamed.warnings == memory.warnings


def test_the_main_jobs_file_is_a_few_mb(tmp_path, monkeypatch):
    """`daeclear run slider_crank --joint revolute` (README's first command): two revolutions on a 2 us
    grid, 12 001 points. The file holds t and y (8 bytes x (1 + 32 states) = 264 bytes a point: 3.2 MB),
    the steps, events and segments in small chunks; version 1 stored yp and 51 channels besides (864
    bytes a point), and chunks of 4096 events (0.6 MB for the run's 61)."""
    from daeclear.cli import main

    assert main(["run", "slider_crank", "--joint", "revolute", "--out", str(tmp_path), "--quiet",
                 "--no-figure"]) == 0
    path = tmp_path / "slider_crank_revolute.h5"
    result = dc.load(path)
    per_point = 8 * (1 + result.n_states)
    assert result.n_times == 12_001 and per_point == 264
    size = path.stat().st_size
    assert result.n_times * per_point < size < result.n_times * per_point + 0.25e6  # the fixed parts: < 0.25 MB
    assert size < 3.5e6 and 8 * (1 + 2 * result.n_states + len(result.channel_names)) * result.n_times > 3 * size


def test_a_scene_that_cannot_be_rebuilt_stores_its_channels(tmp_path):
    """An applied load written as a Python function: the description cannot rebuild it."""
    scene = dc.mechanisms.slider_crank("revolute")
    scene.add(dc.Torque("brake", body="crank", value=dc.Expression(lambda t, s, p: -p.k * t, k=1.0)))
    result = dc.simulate(scene, 0.002)
    assert not result.channel_source.can_rebuild()
    path = result.save(tmp_path / "callable.h5")
    with h5py.File(path, "r") as f:
        assert "yp" in f and len(f["channels"]) == len(result.channel_names) and "channel_names" not in f
    again = dc.load(path)
    for name in result.channel_names:
        assert np.array_equal(again[name], result[name]), name


def test_an_explicit_methods_result_stores_its_channels(tmp_path):
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.002, method="DOP853", rtol=1e-6)
    path = result.save(tmp_path / "dop.h5")
    with h5py.File(path, "r") as f:
        assert len(f["channels"]) == len(result.channel_names)
    assert np.array_equal(dc.load(path)["slider.vx"], result["slider.vx"])


def test_a_slice_stays_lazy_and_equal(runs, tmp_path):
    result = dc.load(runs["ggl"].save(tmp_path / "r.h5"))
    part = result.slice(0.002, 0.004)
    assert part.channel_source is not None and not part.channel_source.computed
    mask = runs["ggl"].window_mask(0.002, 0.004)
    assert np.array_equal(part["rod.alpha"], runs["ggl"]["rod.alpha"][mask])


@pytest.mark.parametrize("make", [
    lambda: dc.mechanisms.slider_crank("revolute", friction=0.05),
    lambda: dc.mechanisms.slider_crank("translational"),
    lambda: dc.mechanisms.four_bar(),
    lambda: dc.mechanisms.chain(n_links=3),
])
def test_a_scene_description_rebuilds_the_scene(make):
    scene = make()
    description = to_plain(scene.to_dict(), "scene")
    rebuilt = scene_from_description(description)
    assert to_plain(rebuilt.to_dict(), "scene") == description
    assert np.array_equal(dc.assemble(rebuilt).parameter_values, dc.assemble(scene).parameter_values)


def test_a_result_pickles_with_its_channels(runs, tmp_path):
    """A result sent to another process (sweeps, parallel studies) carries its channels and yp, not the
    compiled functions that computed them."""
    import pickle

    loaded = dc.load(runs["index1"].save(tmp_path / "p.h5"))
    for result in (runs["index1"], loaded):
        again = pickle.loads(pickle.dumps(result))
        assert again.channel_source.computed and np.array_equal(again.yp, runs["index1"].yp)
        assert np.array_equal(again["clearance.normal_force"], runs["index1"]["clearance.normal_force"])
        assert np.array_equal(again.slice(0.001, 0.002)["slider.vx"], result.slice(0.001, 0.002)["slider.vx"])


def test_a_runs_states_are_made_consistent_when_first_read(scene, tmp_path):
    """A run kept in memory stores IDA's own states: its multipliers and yp are made consistent at the
    first read, equal bit for bit to those a streamed run makes consistent before writing them."""
    kept = dc.simulate(scene, TWO_REVOLUTIONS / 4)
    source = kept.channel_source
    assert source is not None and source.raw and not source.has_yp  # the run made nothing consistent
    idas = np.array(source._y)
    streamed = dc.simulate(scene, TWO_REVOLUTIONS / 4, save=dc.SaveAt(stream_to=tmp_path / "s.h5"))
    assert np.array_equal(kept.y, streamed.y) and np.array_equal(kept.yp, streamed.yp)
    assert not source.raw and source.has_yp
    multipliers = np.array([name.startswith("lambda.") for name in kept.state_names])
    assert np.array_equal(idas[:, ~multipliers], kept.y[:, ~multipliers])  # q, v (and GGL's mu) are IDA's
    assert not np.array_equal(idas[:, multipliers], kept.y[:, multipliers])  # the multipliers are not


def test_a_state_the_pass_keeps_is_read_without_it(scene):
    """Reading q, v (or GGL's mu) of a run does not run the consistency pass and gives the consistent
    column; reading a multiplier runs it. The columns the pass recomputes are the multipliers'."""
    kept = dc.simulate(scene, TWO_REVOLUTIONS / 8)
    source = kept.channel_source
    assert source is not None and source.raw
    multipliers = [j for j, name in enumerate(kept.state_names) if name.startswith("lambda.")]
    assert list(range(kept.n_states))[source.recomputed] == multipliers
    others = [name for name in kept.state_names if not name.startswith("lambda.")]
    assert "crank.x" in others and any(name.startswith("mu.") for name in others)  # GGL's default
    read = {name: np.array(kept[name]) for name in others}
    assert source.raw and not kept[others[0]].flags.writeable  # nothing made consistent yet, read-only
    first_multiplier = kept[kept.state_names[multipliers[0]]]
    assert not source.raw  # the pass ran
    assert np.array_equal(first_multiplier, kept.y[:, multipliers[0]])
    assert not source.computed
    for name, values in read.items():
        assert np.array_equal(values, kept.y[:, kept.state_names.index(name)]), name
        if name in kept.channel_names:  # a body's coordinate or velocity: the channel of that name is the column
            assert np.array_equal(values, kept.channels[name]), name
            assert np.array_equal(values, kept[name]), name
    assert source.computed and sum(name in kept.channel_names for name in read) == 18
