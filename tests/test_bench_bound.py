"""benchmarks/bench_bound.py: the all-C program replays simulate's run (same steps, events, end state).

A short window (2 ms, about 1300 steps and 13 events) of the Fig. 4.15 scene, both formulations;
skipped without a C compiler or the wheel's SUNDIALS (no compiled backend to compare with).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import daeclear as dc
from daeclear.engine.build import CompilerUnavailable, compiler_command
from daeclear.engine.sundials import sundials_info

T_END = 0.002


def _bench():
    """benchmarks/bench_bound.py as a module."""
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "bench_bound.py"
    spec = importlib.util.spec_from_file_location("bench_bound", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_bound"] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def bench():
    try:
        compiler_command()
        sundials_info()
    except CompilerUnavailable as exc:
        pytest.skip(f"no compiled backend: {exc}")
    return _bench()


@pytest.fixture(scope="module")
def compared(bench, tmp_path_factory):
    folder = tmp_path_factory.mktemp("bound")
    return folder, bench.compare(["index1", "ggl"], T_END, 1, folder)


def test_script_runs_and_finds_the_same_run(bench, capsys):
    assert bench.main(["--t-end", str(T_END), "--repeats", "1"]) == 0
    out = capsys.readouterr().out
    assert out.count("the same run") == 2, out
    assert "| index1 |" in out and "| ggl |" in out


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_c_program_counts_are_simulates(bench, compared, formulation):
    _, results = compared
    (r,) = [r for r in results if r.formulation == formulation]
    # an independent simulate call, not the one the setup was recorded from
    result = dc.simulate(bench.scene(), T_END, rtol=bench.RTOL, options=dc.SolverOptions(formulation=formulation))
    steps = len(result.step_t) - 1
    assert steps > 100 and len(result.events) > 0  # the window has contacts: events are compared
    assert r.bound.steps == steps
    assert r.bound.events == len(result.events)
    assert r.bound.t_end == result.t[-1] == T_END
    assert r.agree == []
    assert r.counters_equal  # the same IDA run, counter for counter
    np.testing.assert_array_equal(r.bound.y_end[:2 * r.n_q], result.y[-1, :2 * r.n_q])  # q and v, bit for bit


def test_standalone_program_prints_the_same_counts(bench, compared):
    folder, results = compared
    program = bench.Program(folder / "bound", folder / "libbound.so")
    for r in results:
        out = bench.run_executable(program, r.library, r.setup)
        m = re.search(r"steps (\d+) events (\d+)", out)
        assert m is not None, out
        assert (int(m.group(1)), int(m.group(2))) == (r.bound.steps, r.bound.events)


def test_agreement_names_what_differs(bench, compared):
    """The check can fail: a run with other counts or another end state is reported, item by item."""
    _, results = compared
    r = results[0]
    result = dc.simulate(bench.scene(), T_END, rtol=bench.RTOL, options=dc.SolverOptions(formulation=r.formulation))
    recorder = dataclasses.replace(bench.Recorder(1, 0, 0, 0, 0), stored=[len(result.step_t) - 1])
    assert bench.agreement(r.bound, recorder, result, r.n_q) == []
    y_end = r.bound.y_end.copy()
    y_end[r.n_q] += 1.0  # a velocity
    other = dataclasses.replace(r.bound, steps=r.bound.steps + 100, events=r.bound.events + 1, y_end=y_end)
    problems = bench.agreement(other, recorder, result, r.n_q)
    assert [p.split(":")[0].split(" (")[0] for p in problems] == ["steps", "events", "end state"], problems


def test_timings_are_recorded(compared):
    """One timed repeat each: the C run, the simulate call and its parts (no report pass inside the call:
    a run's states are made consistent when first read, after the call)."""
    _, results = compared
    for r in results:
        assert len(r.c_walls) == len(r.walls) == len(r.reports) == 1
        assert 0 < r.c_loops[0] <= r.c_walls[0]
        assert r.reports[0] == 0.0 < r.walls[0]
        assert 0 < r.solves[0] + r.setups[0] + r.reports[0] < r.walls[0]
