"""Issue 31 (reliability and the command line, round 3): the README's commands, the ideal reference
of the command line, sweeps that fail early, fixed steps from scene files. The refusals themselves
are rows of tests/test_bad_inputs.py."""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
from daeclear.cli import main
from daeclear.model.mechanism_options import ideal_parameters, option_table
from scene_texts import PENDULUM


@pytest.mark.parametrize("sets", [["--set", "contact_model=section-4.3"], ["--set", "reading='section-4.3'"],
                                  ["--set", "pin_offset=(0.01, 0.0)"]])
def test_readme_translational_command_runs_with_its_ideal_reference(sets, tmp_path, capsys):
    """The README's `daeclear run slider_crank --joint translational --set contact_model=section-4.3` (and the
    other translational-only options) runs, and draws the ideal mechanism as its reference."""
    code = main(["run", "slider_crank", "--joint", "translational", *sets, "--t-end", "0.0005", "--out",
                 str(tmp_path), "--quiet"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "no ideal-mechanism reference" not in captured.err
    assert (tmp_path / "slider_crank_translational.png").stat().st_size > 10_000
    assert dc.load(tmp_path / "slider_crank_translational.h5").t[-1] == pytest.approx(0.0005)


def test_ideal_parameters_keep_only_what_the_ideal_mechanism_takes():
    params = {"joint": "translational", "contact_model": "section-4.3", "rpm": 3000.0, "pin_offset": (0.01, 0.0),
              "clearance": 1e-4, "friction": 0.1, "gravity": 0.0, "name": "mine"}
    assert ideal_parameters("slider_crank", params) == {"joint": "ideal", "rpm": 3000.0, "gravity": 0.0}
    assert ideal_parameters("four_bar", {"clearance_joints": "B,C", "law": "hertz", "rpm": 100.0}) == {
        "clearance_joints": (), "rpm": 100.0}
    assert ideal_parameters("slider_crank", {"rpm": 3000.0}) is None  # no clearance joint: no reference
    assert ideal_parameters("chain", {"n_links": 3}) is None
    # each result builds (the options left are the ideal mechanism's own)
    dc.mechanisms.slider_crank(**ideal_parameters("slider_crank", params))
    dc.mechanisms.four_bar(**ideal_parameters("four_bar", {"clearance_joints": "B,C", "law": "hertz"}))


def test_mechanism_help_lists_each_set_key_with_default_and_unit(capsys):
    rows = {name: (default, text) for name, default, text in option_table(dc.mechanisms.slider_crank)}
    assert rows["rpm"][0] == "5000.0" and "rev/min" in rows["rpm"][1]
    assert rows["gravity"][0] == "9.81" and "m/s^2" in rows["gravity"][1]
    assert rows["slider_mass"][0] == "0.14" and "kg" in rows["slider_mass"][1]
    assert rows["clearance"][0] == "0.0005" and ", m" in rows["clearance"][1]
    with pytest.raises(SystemExit) as info:
        main(["run", "four_bar", "--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for key in ("clearance_joints", "rpm", "crank_angle", "gravity", "clearance", "bearing_radius"):
        assert f"--set {key}=" in out, key
    assert "rev/min" in out


def test_rk4_from_a_scene_file(tmp_path, capsys):
    """method = "rk4" with its step in [simulate] runs (it used to ask for step, which [simulate] refused)."""
    path = tmp_path / "pendulum.toml"
    path.write_text(PENDULUM + '\n[simulate]\nt_end = 0.01\nmethod = "rk4"\nstep = 1e-4\n')
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet", "--no-figure"]) == 0
    result = dc.load(tmp_path / "out" / "pendulum.h5")
    assert result.method == "rk4"
    assert result.parameters["simulate"]["step"] == pytest.approx(1e-4)


def test_sweep_exits_non_zero_when_a_run_fails(tmp_path, capsys, monkeypatch):
    """A sweep whose runs fail says so and exits 1 (it used to exit 0)."""
    import daeclear.studies.sweep_workers as workers

    real = workers.run_task

    def fail_second(task):
        if task["parameters"]["clearance"] == 2e-4:
            raise RuntimeError("injected failure")
        return real(task)

    import concurrent.futures as cf

    import daeclear.studies.sweep as sweep_module

    monkeypatch.setattr(sweep_module, "run_task", fail_second)  # in threads: the patch reaches the runs
    monkeypatch.setattr(sweep_module.cf, "ProcessPoolExecutor",
                        lambda max_workers, **_: cf.ThreadPoolExecutor(max_workers=max_workers))
    code = main(["sweep", "slider_crank", str(tmp_path / "s.h5"), "--joint", "revolute", "--grid",
                 "clearance=1e-4,2e-4", "--revolutions", "2", "--transient", "0", "--twin", "never", "--workers",
                 "1", "--quiet", "--no-figure"])
    captured = capsys.readouterr()
    assert code == 1, captured.err
    assert "1 run(s) failed" in captured.err and "injected failure" in captured.out
    runs = dc.load_sweep(tmp_path / "s.h5").runs
    assert sorted(r.ok for r in runs) == [False, True]


@pytest.mark.parametrize("args, shown", [
    (["--t-end", "0.002", "--t-eval-step", "1e-12"], "2 000 000 001 output points"),
    (["--t-end", "0.002", "--t-eval-step", "1e-6", "--max-points", "1000"], "save.max_points=1000"),
])
def test_cli_refuses_an_output_too_large_before_the_run(args, shown, tmp_path, capsys):
    """The issue's `--t-end 0.002 --t-eval-step 1e-12` (2e9 points, ~1.7 TB) is refused at once with the
    estimate and the option that lifts the cap; nothing is written."""
    assert main(["run", "slider_crank", *args, "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "save.every" in err and shown in err and "--max-points" in err and " in the file" in err, err
    assert not list((tmp_path / "o").glob("*.h5"))


def test_output_estimate_matches_the_file_written(tmp_path):
    """The estimate (8 bytes for t, each state, derivative and channel of a point) bounds the streamed
    file's data, t and y, to within its fixed parts: measured on 20 001 points."""
    import re

    scene = dc.mechanisms.slider_crank("revolute")
    with pytest.raises(dc.SceneError) as info:
        dc.simulate(scene, 0.002, save=dc.SaveAt(every=1e-7, max_points=20_000, stream_to=tmp_path / "x.h5"))
    per_point = int(re.search(r"\((\d+) bytes a point", str(info.value)).group(1))
    model = dc.assemble(scene)
    assert per_point == 8 * (1 + 2 * model.n_states + len(model.channel_names))
    dc.simulate(scene, 0.002, save=dc.SaveAt(every=1e-7, stream_to=tmp_path / "x.h5", keep_data=False))
    size = (tmp_path / "x.h5").stat().st_size
    # the estimate counts what a run holds in memory (states, derivatives, channels): an upper bound of
    # its file, which keeps t and y alone (the channels and yp are computed when read)
    assert 0.9 * 20_001 * 8 * (1 + model.n_states) < size < 20_001 * 8 * (1 + model.n_states) + 2e6
    assert size < 20_001 * per_point + 2e6


# --------------------------------------------------------------------------- a full disk, damaged files


def _disk_fills_after(monkeypatch, calls: int) -> None:
    """shutil.disk_usage (what daeclear asks before each write) reports a full disk after ``calls`` calls."""
    import collections
    import shutil

    import daeclear.results.outputs as outputs

    real, count = shutil.disk_usage, [0]

    def usage(path):
        count[0] += 1
        total, used, free = real(path)
        return collections.namedtuple("usage", "total used free")(total, used, free if count[0] <= calls else 4096)

    monkeypatch.setattr(outputs.shutil, "disk_usage", usage)


def _enospc_after(monkeypatch, calls: int) -> None:
    """The streamed writer's datasets fail to grow with ENOSPC after ``calls`` appended writes (space the
    check before the write saw, taken meanwhile by another process); shrinking (the append's undo) works."""
    import errno

    import h5py

    real, count = h5py.Dataset.resize, [0]

    def resize(self, size, axis=None):
        if axis is not None and size > self.shape[axis]:
            count[0] += 1
            if count[0] > calls:
                raise OSError(errno.ENOSPC, "No space left on device", self.file.filename)
        return real(self, size, axis)

    monkeypatch.setattr(h5py.Dataset, "resize", resize)


@pytest.mark.parametrize("inject", [_disk_fills_after, _enospc_after])
def test_a_full_disk_during_a_streamed_run_keeps_a_readable_prefix(inject, tmp_path, monkeypatch):
    scene = dc.mechanisms.slider_crank("revolute")
    path = tmp_path / "run.h5"
    inject(monkeypatch, 3 if inject is _disk_fills_after else 40)
    with pytest.raises(dc.DiskFull) as info:
        dc.simulate(scene, 0.024, save=dc.SaveAt(every=1e-6, stream_to=path, keep_data=False))
    assert str(path) in str(info.value) and "no space left" in str(info.value)
    monkeypatch.undo()
    prefix = dc.load(path)  # what was flushed before: readable, marked incomplete
    assert not prefix.success and "DiskFull" in prefix.message
    assert 0 < prefix.n_times < 24_001 and prefix.t[-1] < 0.024
    full = dc.simulate(scene, prefix.t[-1], save=dc.SaveAt(times=prefix.t))  # the prefix is the run's own beginning
    assert np.allclose(prefix["slider.vx"], full["slider.vx"], rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("inject", [_disk_fills_after, _enospc_after])
def test_cli_run_on_a_full_disk_says_one_line_and_exits_1(inject, tmp_path, monkeypatch, capsys):
    inject(monkeypatch, 3 if inject is _disk_fills_after else 20)  # the whole run grows a dataset 33 times
    code = main(["run", "slider_crank", "--joint", "revolute", "--out", str(tmp_path), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "Traceback" not in err, err
    assert str(tmp_path / "slider_crank_revolute.h5") in err and "no space left" in err
    monkeypatch.undo()
    assert not dc.load(tmp_path / "slider_crank_revolute.h5").success


def test_save_on_a_full_disk_keeps_the_old_file(tmp_path, monkeypatch):
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.002)
    path = tmp_path / "run.h5"
    result.slice(0.0, 0.001).save(path)
    _disk_fills_after(monkeypatch, 0)
    with pytest.raises(dc.DiskFull, match="Result.save.*run.h5.*no space left"):
        result.save(path)
    monkeypatch.undo()
    assert dc.load(path).t[-1] == pytest.approx(0.001, abs=1e-5)  # the old file, whole
    assert [p.name for p in tmp_path.iterdir()] == ["run.h5"]  # no temporary file left


def test_cli_figure_on_a_full_disk_says_one_line(tmp_path, monkeypatch, capsys):
    import errno

    import matplotlib.figure

    def full(self, fname, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device", str(fname))

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", full)
    code = main(["run", "slider_crank", "--t-end", "0.001", "--out", str(tmp_path), "--quiet"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1, err
    assert str(tmp_path / "slider_crank.png") in err and "no space left" in err
    assert dc.load(tmp_path / "slider_crank.h5").success  # the result was written before


def _flip(path, dataset: str) -> None:
    """Flip 64 bytes in the middle of the data of ``dataset``'s first chunk."""
    import h5py

    with h5py.File(path, "r") as f:
        d = f[dataset]
        info = d.id.get_chunk_info(0)
        middle = min(d.chunks[0], d.shape[0]) * (d.dtype.itemsize * int(np.prod(d.shape[1:]))) // 2  # in the data
    with open(path, "r+b") as fh:
        fh.seek(info.byte_offset + middle)
        data = bytearray(fh.read(64))
        fh.seek(info.byte_offset + middle)
        fh.write(bytes(b ^ 0xFF for b in data))


@pytest.mark.parametrize("streamed", [False, True])
@pytest.mark.parametrize("dataset", ["y", "channels/slider.vx", "t"])
def test_load_refuses_a_damaged_dataset_by_name(streamed, dataset, tmp_path):
    path = tmp_path / "run.h5"
    scene = dc.mechanisms.slider_crank("revolute")
    if streamed and dataset.startswith("channels/"):  # a run streams its states only: a stored channel
        full = tmp_path / "full.h5"
        dc.simulate(scene, 0.002, save=dc.SaveAt(every=1e-6, stream_to=full, keep_data=False))
        dc.load(full).save(path, channels=True)
    elif streamed:
        dc.simulate(scene, 0.002, save=dc.SaveAt(every=1e-6, stream_to=path, keep_data=False))
    else:
        dc.simulate(scene, 0.002, save=dc.SaveAt(every=1e-6)).save(path, channels=dataset.startswith("channels/"))
    dc.load(path)  # whole: reads
    _flip(path, dataset)
    with pytest.raises(dc.DaeclearError) as info:
        dc.load(path)
    assert f"'/{dataset}'" in str(info.value) and str(path) in str(info.value), str(info.value)


def test_help_and_import_load_no_numerical_library():
    """`daeclear --help` and `import daeclear` import no CasADi, scipy, h5py or matplotlib (they took ~4 s):
    measured in a fresh interpreter by what is imported, not by the clock of a shared machine."""
    import subprocess
    import sys

    code = ("import sys, contextlib, io\nimport daeclear\nfrom daeclear.cli import main\n"
            "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n    main(['--help'])\n"
            "print(sorted(m for m in ('casadi', 'scipy', 'h5py', 'matplotlib', 'numpy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
    # the public names load on first use
    code = "import daeclear\nassert callable(daeclear.sweep) and daeclear.Scene.__name__ == 'Scene'"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_cli_figure_of_a_window_keeps_the_peaks(tmp_path, capsys, monkeypatch):
    """--window draws that part of the run; the curves are min-max decimated, so the largest |value|
    of the window is drawn (an impact's peak in a long run's figure)."""
    import matplotlib.axes

    drawn: list[np.ndarray] = []
    real = matplotlib.axes.Axes.plot

    def plot(self, *args, **kwargs):
        if len(args) >= 2:
            drawn.append(np.asarray(args[1], dtype=float))
        return real(self, *args, **kwargs)

    monkeypatch.setattr(matplotlib.axes.Axes, "plot", plot)
    code = main(["run", "slider_crank", "--joint", "revolute", "--t-end", "0.006", "--window", "0.002", "0.005",
                 "--out", str(tmp_path), "--quiet"])
    assert code == 0, capsys.readouterr().err
    result = dc.load(tmp_path / "slider_crank_revolute.h5")
    inside = result.window_mask(0.002, 0.005)
    peak = np.max(np.abs(result["slider.ax"][inside]))
    assert any(c.size <= 2000 + 2 and np.max(np.abs(c)) == peak for c in drawn if c.size)
    assert all(c.size <= 2000 + 2 for c in drawn)
