"""Ctrl-C stops: a loop of runs, the command line, a study and a sweep; the partial result is saved once.

Interrupts are delivered deterministically: a KeyboardInterrupt raised from the progress line
of a run (with small step buffers, so the compiled loop returns to Python often), from a
study's timed run, or a real SIGINT sent to a command-line sweep in a subprocess.
"""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import numpy as np
import pytest

import daeclear as dc
from daeclear.studies.accuracy import WorkPrecision, work_precision
from daeclear.cli import main
from daeclear.core.errors import Interrupted
from daeclear.studies.sweep import load_sweep

T_END = 0.006



pytestmark = pytest.mark.usefixtures("sigint_as_a_terminal_sends_it")  # tests/conftest.py

@pytest.fixture
def ctrl_c_after(monkeypatch, ctrl_c_at_update):
    """``ctrl_c_after(n)``: the n-th progress update of a run raises KeyboardInterrupt (a Ctrl-C there), the
    session's buffer small (64 steps) so that a short run flushes rows before it."""
    import daeclear.solvers.ida as solve

    monkeypatch.setattr(solve, "open_session", functools.partial(solve.open_session, buffer_steps=64))
    return ctrl_c_at_update


def test_ctrl_c_stops_a_loop_of_runs_that_catches_failures(ctrl_c_after):
    """A loop that carries on after failed runs (except SolveError) stops on Ctrl-C, with the partial result."""
    ctrl_c_after(4)
    done, failed = [], []
    with pytest.raises(KeyboardInterrupt) as info:
        for clearance in (0.5e-3, 0.4e-3, 0.3e-3):
            try:
                done.append(dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=clearance), T_END,
                                        progress=True, on_failure="return"))
            except dc.SolveError as exc:  # pragma: no cover - must not happen
                failed.append(exc)
    assert isinstance(info.value, Interrupted) and not failed and not done
    partial = info.value.result
    assert not partial.success and "interrupted by the user" in partial.message
    assert 0 < partial.t[-1] < T_END and partial.t.size > 100 and len(partial.events) > 0
    assert np.all(np.isfinite(partial["slider.vx"]))


def test_ctrl_c_with_on_failure_raise_is_not_a_solve_error(ctrl_c_after):
    ctrl_c_after(3)
    with pytest.raises(Interrupted) as info:
        dc.simulate(dc.mechanisms.slider_crank("revolute"), T_END, progress=True)
    assert not isinstance(info.value, dc.SolveError) and info.value.result.t[-1] < T_END


def test_cli_run_ctrl_c_saves_the_partial_result_once(ctrl_c_after, tmp_path, capsys, monkeypatch):
    """The run streams to its file (daeclear.results.result.ResultWriter): the file is completed once, when the run
    stops, and not written again by Result.save."""
    from daeclear.results.result import ResultWriter

    saves, closes = [], []
    original = dc.Result.save
    monkeypatch.setattr(dc.Result, "save", lambda self, path: saves.append(path) or original(self, path))
    close = ResultWriter.close
    monkeypatch.setattr(ResultWriter, "close", lambda self, **kw: closes.append(self.path) or close(self, **kw))
    ctrl_c_after(4)
    code = main(["run", "slider_crank", "--joint", "revolute", "--t-end", str(T_END), "--out", str(tmp_path)])
    assert code == 130
    err = capsys.readouterr().err
    h5 = tmp_path / "slider_crank_revolute.h5"
    assert f"interrupted, partial result saved to {h5}" in err and "Traceback" not in err
    assert closes == [h5] and saves == []  # once
    partial = dc.load(h5)
    assert not partial.success and "interrupted" in partial.message and 0 < partial.t[-1] < T_END
    assert sorted(p.name for p in tmp_path.iterdir()) == [h5.name]  # no figure, no temporary file


def test_second_ctrl_c_during_the_save_does_not_lose_it(tmp_path, monkeypatch):
    """SIGINT arriving in the middle of the HDF5 write is held back until the file is complete and in place."""
    import daeclear.results.hdf5_write as write_module

    result = dc.simulate(dc.mechanisms.slider_crank("ideal"), 1e-3)
    original = write_module._write

    def write_then_ctrl_c(f, r):
        os.kill(os.getpid(), signal.SIGINT)  # a real Ctrl-C, mid-write
        time.sleep(0.01)
        original(f, r)

    monkeypatch.setattr(write_module, "_write", write_then_ctrl_c)
    path = tmp_path / "partial.h5"
    with pytest.raises(KeyboardInterrupt):
        result.save(path)
    again = dc.load(path)  # complete and readable
    assert np.array_equal(again.t, result.t)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["partial.h5"]


@pytest.mark.parametrize("failure", [OSError("disk full"), KeyboardInterrupt()])
def test_atomic_file_replaces_whole_or_leaves_the_old_file(tmp_path, failure):
    """outputs.atomic_file, the one temporary-file-and-rename write: a failure (an error or a Ctrl-C)
    in the middle of the write leaves the old file byte for byte and no temporary file; a completed
    write replaces it whole."""
    from daeclear.results.outputs import atomic_file, atomic_write_text

    target = tmp_path / "table.csv"
    target.write_text("old\n")
    with pytest.raises(type(failure)), atomic_file(target) as tmp:
        assert tmp.parent == tmp_path and tmp != target
        tmp.write_text("half of the new")
        raise failure
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]
    atomic_write_text(target, "new\n")
    assert target.read_text() == "new\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]


def test_cli_second_ctrl_c_during_the_partial_save(ctrl_c_after, tmp_path, capsys, monkeypatch):
    """A real SIGINT while the streamed file is completed (its statistics written): held back until it is."""
    import daeclear.results.hdf5_stream as stream_module

    original, close = stream_module.mirror, stream_module.ResultWriter.close
    closing, sent = [], []

    def mirror_then_ctrl_c(group, tree):
        if closing and not sent:
            sent.append(os.kill(os.getpid(), signal.SIGINT))
            time.sleep(0.01)
        original(group, tree)

    monkeypatch.setattr(stream_module, "mirror", mirror_then_ctrl_c)
    monkeypatch.setattr(stream_module.ResultWriter, "close", lambda self, **kw: closing.append(1) or close(self, **kw))
    ctrl_c_after(4)
    assert main(["run", "slider_crank", "--joint", "revolute", "--t-end", str(T_END), "--out", str(tmp_path)]) == 130
    assert sent and "partial result saved" in capsys.readouterr().err
    partial = dc.load(tmp_path / "slider_crank_revolute.h5")
    assert not partial.success and "interrupted" in partial.message and partial.stats["n_steps"] > 0


STUDY = ["study", "slider_crank", "--joint", "ideal", "--t-end", "0.002", "--methods", "ida,rk4", "--rtols", "1e-5",
         "--steps", "1e-5", "--repeats", "0", "--channels", "slider.vx"]


@pytest.fixture
def ctrl_c_in_second_study_run(monkeypatch):
    import daeclear.studies.accuracy as accuracy

    original = accuracy._timed
    calls = [0]

    def timed(*args, **kwargs):
        calls[0] += 1
        if calls[0] == 2:
            raise KeyboardInterrupt
        return original(*args, **kwargs)

    monkeypatch.setattr(accuracy, "_timed", timed)
    return calls


def test_study_stops_on_ctrl_c_with_its_finished_rows(ctrl_c_in_second_study_run):
    with pytest.raises(Interrupted) as info:
        work_precision(dc.mechanisms.slider_crank("ideal"), 0.002, methods={"ida": {"method": "ida"},
                       "rk4": {"method": "rk4"}}, rtols=[1e-5], steps=[1e-5], repeats=0)
    partial = info.value.result
    assert isinstance(partial, WorkPrecision) and [r["label"] for r in partial.rows] == ["ida"]
    assert partial.rows[0]["status"] == 0 and "Interrupted" in partial.notes[-1]


def test_cli_study_ctrl_c_exits_130_and_saves_the_rows(ctrl_c_in_second_study_run, tmp_path, capsys):
    assert main(STUDY + ["--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err
    assert "interrupted, partial result saved to" in err
    lines = (tmp_path / "work_precision.csv").read_text().strip().splitlines()
    assert len(lines) == 2 and lines[1].startswith("ida,ida,1e-05")  # the finished row, no "interrupted" row
    assert "interrupted" not in lines[1].lower()
    assert "Interrupted by the user" in (tmp_path / "work_precision.md").read_text()
    assert not (tmp_path / "work_precision.png").exists()


# --------------------------------------------------------------------------- sweeps, with real signals

SWEEP = ["sweep", "slider_crank", "--joint", "revolute", "--grid", "clearance=0.01e-3,0.5e-3,0.2e-3,0.3e-3",
         "--revolutions", "8", "--transient", "2", "--per-revolution", "16", "--twin", "never", "--workers", "1",
         "--no-figure"]


def _children(pid: int) -> list[int]:
    out = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return out


def _running(pid: int) -> bool:
    """The process exists and is not a zombie."""
    try:
        state = [line for line in Path(f"/proc/{pid}/status").read_text().splitlines() if line.startswith("State:")]
    except OSError:
        return False
    return bool(state) and "Z" not in state[0].split()[1]


def _start_sweep(path: Path) -> subprocess.Popen:
    """``daeclear sweep`` in its own process group; its stderr goes to ``<path>.err`` (read after it ends)."""
    env = {**os.environ, "PYTHONPATH": str(Path(dc.__file__).resolve().parent.parent)}
    with open(path.with_suffix(".err"), "w") as err:
        return subprocess.Popen([sys.executable, "-m", "daeclear.cli", SWEEP[0], SWEEP[1], str(path), *SWEEP[2:]],
                                stdout=subprocess.DEVNULL, stderr=err, env=env, start_new_session=True)


def _wait_for_first_run(proc: subprocess.Popen, path: Path) -> list[int]:
    parts = path.with_name(path.name + ".parts")
    deadline = time.time() + 180
    while time.time() < deadline and not (parts.is_dir() and any(parts.glob("run-*.h5"))):
        assert proc.poll() is None, path.with_suffix(".err").read_text()
        time.sleep(0.05)
    workers = _children(proc.pid)
    assert workers, "the sweep has no worker process"
    return workers


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and process groups")
def test_cli_sweep_ctrl_c_exits_130_keeps_the_journal_and_leaves_no_worker(tmp_path):
    path = tmp_path / "sweep.h5"
    proc = _start_sweep(path)
    try:
        workers = _wait_for_first_run(proc, path)
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C in a terminal: the whole foreground group
        proc.wait(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    err = path.with_suffix(".err").read_text()
    assert proc.returncode == 130, err
    assert "interrupted, partial result saved to" in err and "Traceback" not in err
    kept = load_sweep(path)
    assert 1 <= len(kept) < 4 and all(r.ok for r in kept.runs)
    assert not path.with_name(path.name + ".lock").exists()
    deadline = time.time() + 10
    while time.time() < deadline and any(_running(w) for w in workers):
        time.sleep(0.1)
    assert not any(_running(w) for w in workers)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and PR_SET_PDEATHSIG")
def test_sweep_killed_hard_leaves_no_worker(tmp_path):
    """SIGKILL to the sweep's process alone (no cleanup possible): its workers die with it."""
    path = tmp_path / "sweep.h5"
    proc = _start_sweep(path)
    try:
        workers = _wait_for_first_run(proc, path)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
        deadline = time.time() + 10
        while time.time() < deadline and any(_running(w) for w in workers):
            time.sleep(0.1)
        assert not any(_running(w) for w in workers)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    assert len(load_sweep(path)) >= 1  # the journal of finished runs survives; the next call resumes


def test_a_ctrl_c_python_drops_is_still_latched(monkeypatch):
    """Python drops a KeyboardInterrupt raised inside a weakref callback ("Exception ignored"):
    the sweep's loop checks the latch between runs, so such a Ctrl-C still stops it."""
    import gc
    import weakref

    from daeclear.results.outputs import sigint_latch

    dropped: list[type] = []
    monkeypatch.setattr(sys, "unraisablehook", lambda unraisable: dropped.append(unraisable.exc_type))

    class Target:
        pass

    def fail() -> None:
        raise ValueError("another error a callback drops")

    with sigint_latch() as received:
        target = Target()
        weakref.finalize(target, signal.raise_signal, signal.SIGINT)
        del target  # the callback runs now; Python drops its KeyboardInterrupt
        gc.collect()
        assert received == [signal.SIGINT]
        other = Target()
        weakref.finalize(other, fail)
        del other
        gc.collect()
    # Only the latch remembers the Ctrl-C (not printed as "Exception ignored ... Traceback"); any other
    # dropped error still reaches the hook that was there before.
    assert dropped == [ValueError]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored
    sys.unraisablehook(types.SimpleNamespace(exc_type=RuntimeError))  # the previous hook is back
    assert dropped == [ValueError, RuntimeError]
