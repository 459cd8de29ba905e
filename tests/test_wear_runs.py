"""The wear study's blocks in one IDA session (issue 44, item 6's speed): a session re-armed for the next
run of the same structure runs it step for step as a new session would, and a history whose blocks share
one session equals, bit for bit, the history whose blocks each open their own."""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
from daeclear.contact.wear import ArchardWear
from daeclear.core.errors import Interrupted
from daeclear.model.mechanisms import slider_crank
from daeclear.solvers import driver
from daeclear.solvers.ida import IDA
from daeclear.solvers.save_at import save_value
from daeclear.studies import wear as study
from daeclear.studies.wear import BlockRuns, simulate_wear

T_END = 0.004


def _run(model: dc.DAEModel, settings: dc.SolverOptions, integrator=None) -> dc.Result:
    save = save_value(None).plan(0.0, T_END)
    return driver.run(IDA(), model, T_END, 0.0, None, save, settings, "return", False, integrator=integrator)


def _same_run(a: dc.Result, b: dc.Result) -> None:
    assert len(a.events) >= 4
    assert [(e.t, e.kind) for e in a.events] == [(e.t, e.kind) for e in b.events]
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.y, b.y)
    counters = [k for k in a.stats if k.startswith("n_")]
    assert {k: a.stats[k] for k in counters} == {k: b.stats[k] for k in counters}


def test_a_rearmed_session_runs_the_next_model_as_a_new_session():
    """A run of one model (other clearance and restitution: other impacts) in an integrator, then that
    integrator re-armed with another model of the same structure: its run equals the run of that model
    in a new session, step for step; the integrator stays open (the caller closes it)."""
    settings = dc.SolverOptions(backend="c", rtol=1e-7)
    first = dc.assemble(slider_crank("revolute", clearance=3e-4, restitution=0.5))
    second = dc.assemble(slider_crank("revolute", clearance=1e-4))
    assert first.compiled is second.compiled
    fresh = _run(second, settings)
    integrator = IDA().integrator(first, T_END, save_value(None).plan(0.0, T_END), settings)
    try:
        before = _run(first, settings, integrator)
        assert before.success and not integrator.session._closed  # left open for the caller
        assert [e.t for e in before.events] != [e.t for e in fresh.events]
        assert integrator.rearm(second, T_END, save_value(None).plan(0.0, T_END))
        again = _run(second, settings, integrator)
    finally:
        integrator.close()
    assert again.success
    _same_run(again, fresh)


def test_a_session_is_not_rearmed_for_another_structure_or_the_python_backend():
    """rearm refuses (False) a model of another structure, and the python session, which cannot."""
    settings = dc.SolverOptions(backend="c")
    crank = dc.assemble(slider_crank("revolute"))
    other = dc.assemble(slider_crank("revolute", friction=0.1))  # friction: another structure
    assert crank.compiled is not other.compiled
    save = save_value(None).plan(0.0, T_END)
    integrator = IDA().integrator(crank, T_END, save, settings)
    try:
        assert not integrator.rearm(other, T_END, save)
    finally:
        integrator.close()
    python = IDA().integrator(crank, T_END, save, dc.SolverOptions(backend="python"))
    try:
        assert not python.rearm(crank, T_END, save)
    finally:
        python.close()


def test_blocks_in_one_session_equal_blocks_each_in_its_own(monkeypatch):
    """simulate_wear's blocks run in one re-armed session; each block in a session of its own (the
    driver's) gives the same history bit for bit: depth, sliding work, peak force and each block's last
    state (made consistent in the shared session; ``Result.state(-1)`` in its own)."""
    worn = slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02)})
    states: list[list[np.ndarray]] = [[], []]  # each block's last state (the next start, the file's y)
    real_row = study.WearRow

    def row(**kwargs):
        if kwargs["y"] is not None:  # not the unworn start's row
            states[phase[0]].append(kwargs["y"])
        return real_row(**kwargs)

    opened: list[int] = []
    phase = [0]
    monkeypatch.setattr(study, "WearRow", row)
    shared = simulate_wear(worn, 3)
    phase[0] = 1

    def own_session(self, solver, model, t_end, save, settings):
        opened.append(1)
        return None  # the driver opens (and closes) the block's own session

    monkeypatch.setattr(BlockRuns, "integrator", own_session)
    alone = simulate_wear(worn, 3)
    assert len(opened) == 3
    assert len(states[0]) == len(states[1]) == 3
    for mine, own in zip(*states):
        np.testing.assert_array_equal(mine, own)
    for field in ("depth", "sliding_work", "peak_force", "volume"):
        np.testing.assert_array_equal(getattr(shared, field), getattr(alone, field))
    assert shared.max_depth[-1] > 0


def test_the_blocks_session_is_closed_when_the_history_ends(monkeypatch):
    """The session the blocks share is closed at the end, also when a block fails or Ctrl-C stops it."""
    worn = slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02)})
    closed = []
    real_close = BlockRuns.close

    def close(self):
        closed.append(self.open is not None)
        real_close(self)

    monkeypatch.setattr(BlockRuns, "close", close)
    simulate_wear(worn, 2)
    assert closed[-1] and closed.count(True) == 1  # the open session, closed once at the end
    real_run, calls = study.block_run, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real_run(*args, **kwargs)

    monkeypatch.setattr(study, "block_run", interrupted)
    with pytest.raises(Interrupted):
        simulate_wear(worn, 3)
    assert closed[-1] and closed.count(True) == 2
