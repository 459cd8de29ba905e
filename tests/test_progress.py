"""The progress display (daeclear/core/progress.py): plain rate-limited lines off a terminal, tqdm on one, nothing
when off."""

from __future__ import annotations

import io
import re

import pytest

import daeclear as dc
import daeclear.core.progress as progress_module
from daeclear.cli import main
from daeclear.core.progress import PLAIN_STEPS, Progress

T_END = 0.006


class Terminal(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def _percents(text: str) -> list[float]:
    return [float(m) for m in re.findall(r"([\d.]+) % \|", text)]


def test_plain_mode_writes_a_bounded_number_of_lines_for_a_long_run():
    out = io.StringIO()
    bar = Progress(2.0, unit="s", desc="simulate", stream=out)
    assert bar.mode == "plain"
    n = 200_000
    for k in range(n + 1):
        bar.update(2.0 * k / n, f"events {k // 1000}")
    bar.close()
    text = out.getvalue()
    lines = text.splitlines()
    assert "\r" not in text
    assert len(lines) == PLAIN_STEPS + 1  # 0 %, 10 %, ..., 100 %: the final state is not repeated by close
    percents = _percents(text)
    assert percents == [10.0 * k for k in range(PLAIN_STEPS + 1)]
    assert lines[-1].startswith("  simulate: 2/2 s  100.0 %") and lines[-1].endswith("| events 200")


def test_plain_mode_writes_a_line_after_a_long_silence(monkeypatch):
    """Between two tenths, a line at most every `interval` seconds (a fake clock)."""
    now = [0.0]
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: now[0])
    out = io.StringIO()
    bar = Progress(100, unit="runs", stream=out, interval=30.0)
    bar.update(0)
    for k in range(1, 10):  # 1 % .. 9 %: no tenth reached; 10 s apart
        now[0] += 10.0
        bar.update(k, f"run {k}")
    lines = out.getvalue().splitlines()
    assert [line.rsplit("| ", 1)[-1] for line in lines[1:]] == ["run 3", "run 6", "run 9"]
    assert "0:01:30 elapsed, ~0:15:10 left" in lines[-1]  # 90 s for 9 %: 910 s left


def test_close_prints_the_final_note_and_twice_is_once():
    out = io.StringIO()
    bar = Progress(3, unit="runs", desc="sweep", stream=out)
    bar.update(0)
    bar.update(1, "a=1 -> periodic")
    bar.close("1 failed")
    bar.close("again")
    bar.update(2, "after close")
    lines = out.getvalue().splitlines()
    assert len(lines) == 3 and lines[-1].endswith("| 1 failed") and "1/3 runs" in lines[-1]


def test_an_empty_total_is_complete():
    out = io.StringIO()
    bar = Progress(0, unit="runs", desc="sweep", stream=out)
    bar.close("nothing to do")
    assert out.getvalue() == "  sweep: 0/0 runs  100.0 % | 0:00:00 elapsed | nothing to do\n"


@pytest.mark.parametrize("stream", [io.StringIO, Terminal])
def test_disabled_prints_nothing(stream):
    out = stream()
    bar = Progress(1.0, unit="s", enabled=False, stream=out)
    assert bar.mode == "off" and bar.bar is None
    for k in range(11):
        bar.update(k / 10, "note")
    bar.close("done")
    assert out.getvalue() == ""


def test_a_terminal_gets_a_tqdm_bar_that_closes_cleanly():
    from tqdm import tqdm

    out = Terminal()
    bar = Progress(0.5, unit="s", desc="simulate", stream=out)
    assert bar.mode == "tty" and isinstance(bar.bar, tqdm)
    assert bar.bar.monitor_interval == 0  # no monitor thread (sweeps fork their workers)
    for k in range(1001):
        bar.update(0.5 * k / 1000, f"events {k}")
    bar.close()
    bar.close()
    text = out.getvalue()
    assert bar.bar.disable  # tqdm's state once closed
    assert text.endswith("\n") and "\r" in text  # rewritten in place, then left on its own line
    last = text.rstrip("\n").rsplit("\r", 1)[-1]
    assert "simulate: 100%" in last and "0.5/0.5 s" in last and "events 1000" in last


def test_stderr_as_a_terminal_chooses_tqdm(monkeypatch):
    """The default stream is sys.stderr: a terminal there (isatty patched) means a tqdm bar."""
    monkeypatch.setattr(progress_module.sys.stderr, "isatty", lambda: True, raising=False)
    bar = Progress(10, unit="frames")
    try:
        assert bar.mode == "tty"
    finally:
        bar.close()
    monkeypatch.setattr(progress_module.sys.stderr, "isatty", lambda: False, raising=False)
    assert Progress(10).mode == "plain"


@pytest.mark.parametrize("method", ["ida", "rk4"])
def test_a_run_shows_simulated_time_percent_and_events_in_a_few_lines(method, capsys, monkeypatch):
    """Many updates (every rk4 step; every 64-step buffer of the compiled IDA loop), a few lines."""
    import functools

    import daeclear.solvers.ida as solve

    monkeypatch.setattr(solve, "open_session", functools.partial(solve.open_session, buffer_steps=64))
    settings = dc.SolverOptions(method="rk4", step=1e-6) if method == "rk4" else None
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), T_END, progress=True, options=settings)
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith("  simulate:")]
    assert "\r" not in err and 2 <= len(lines) <= PLAIN_STEPS + 2
    assert float(lines[0].split()[1].split("/")[0]) < 0.1 * T_END  # the first update comes early
    assert lines[-1].startswith("  simulate: 0.006/0.006 s  100.0 %")
    assert lines[-1].endswith(f"| events {len(result.events)}") and len(result.events) > 0
    percents = _percents("\n".join(lines))
    assert percents == sorted(percents)


def test_a_run_without_progress_prints_nothing(capsys):
    dc.simulate(dc.mechanisms.slider_crank("revolute"), T_END)
    assert capsys.readouterr().err == ""


def test_cli_run_quiet_prints_no_progress(tmp_path, capsys):
    args = ["run", "slider_crank", "--joint", "revolute", "--t-end", str(T_END), "--no-figure"]
    assert main(args + ["--out", str(tmp_path / "loud")]) == 0
    assert "simulate:" in capsys.readouterr().err
    assert main(args + ["--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    assert "simulate:" not in capsys.readouterr().err


def test_a_sweep_shows_done_failed_already_done_and_the_last_label(tmp_path, capsys):
    from daeclear.studies.sweep import sweep

    path = tmp_path / "clearance.h5"
    fast = dict(revolutions=8, transient=2, per_revolution=16, twin=False, max_workers=1, fixed={"joint": "revolute"})
    out = sweep(path, {"clearance": [0.01e-3, 0.5e-3]}, progress=True, **fast)
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("  sweep: 0/2 runs    0.0 %")
    assert lines[-1].startswith("  sweep: 2/2 runs  100.0 %")
    assert re.search(r"\| clearance=(1e-05|0\.0005) -> ([\w-]+)$", lines[-1]).group(2) in {r.motion for r in out.runs}
    # again, with one more point: the finished runs are skipped and said so
    sweep(path, {"clearance": [0.01e-3, 0.5e-3, 0.02e-3]}, progress=True, **fast)
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1].startswith("  sweep: 1/1 runs  100.0 %") and "| 2 already done | clearance=2e-05 -> " in lines[-1]
    sweep(path, {"clearance": [0.01e-3, 0.5e-3, 0.02e-3]}, progress=True, **fast)
    assert capsys.readouterr().err.splitlines()[-1].endswith("| 3 already done | nothing to do")
    sweep(path, {"clearance": [0.01e-3, 0.5e-3, 0.02e-3]}, progress=False, **fast)
    assert capsys.readouterr().err == ""


def test_a_work_precision_study_names_each_run_as_it_starts(capsys):
    from daeclear.studies.accuracy import work_precision

    study = work_precision(dc.mechanisms.slider_crank("ideal"), 0.002, methods={"ida": {"method": "ida"},
                           "rk4": {"method": "rk4"}}, rtols=[1e-5], steps=[1e-5], repeats=0, progress=True)
    assert [r["label"] for r in study.rows] == ["ida", "rk4"]
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert lines == [lines[0], lines[1], lines[2]] and "work-precision" not in captured.out
    assert lines[0].startswith("  work-precision: 0/2 runs    0.0 %") and lines[0].endswith("| ida rtol=1e-05 ...")
    assert lines[1].startswith("  work-precision: 1/2 runs   50.0 %") and lines[1].endswith("| rk4 step=1e-05 ...")
    assert lines[2].startswith("  work-precision: 2/2 runs  100.0 %")
