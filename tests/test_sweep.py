"""Parameter sweeps (daeclear.sweep): one HDF5 file, failures recorded, resume, Dask = process pool.

Runs are short (2 + 8 revolutions, no twins) and use the two revolute clearances of
test_analysis.py, so the compiled models are shared through the disk cache.
"""

import importlib.util
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import h5py
import numpy as np
import pytest

import daeclear as dc
from daeclear.cli import main
from daeclear.core.errors import DaeclearError, SceneError
from daeclear.studies.sweep import grid_points, load_sweep, run_key, sweep

FAST = dict(revolutions=8, transient=2, per_revolution=16, twin=False, progress=False)
FIXED = {"joint": "revolute"}
CLEARANCES = [0.01e-3, 0.5e-3]


def _datasets(group):
    """Every dataset and attribute under a run group, except the worker's timing and identity."""
    out = {}

    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            out[name] = obj[()]
        for key, value in obj.attrs.items():
            if name.startswith("info") and key in ("worker", "computed_at", "wall_time"):
                continue
            out[f"{name}@{key}"] = value

    group.visititems(visit)
    for key, value in group.attrs.items():
        out[f"@{key}"] = value
    return out


def _same(a, b):
    assert a.keys() == b.keys()
    for key in a:
        x, y = np.asarray(a[key]), np.asarray(b[key])
        if x.dtype.kind == "f":
            assert np.array_equal(x, y, equal_nan=True), key
        else:
            assert np.array_equal(x, y), key


def test_grid_points_and_run_keys():
    points = grid_points({"clearance": [1e-4, 5e-4], "friction": [None, 0.1]})
    assert points == [{"clearance": 1e-4, "friction": None}, {"clearance": 1e-4, "friction": 0.1},
                      {"clearance": 5e-4, "friction": None}, {"clearance": 5e-4, "friction": 0.1}]
    key = run_key({"clearance": 0.5e-3, "joint": "revolute"})
    assert key == run_key({"joint": "revolute", "clearance": 0.0005}) and key.startswith("run-")
    assert key != run_key({"joint": "revolute", "clearance": 0.0005, "friction": None})
    with pytest.raises(SceneError, match="grid"):
        grid_points({"clearance": 0.5e-3})
    with pytest.raises(SceneError, match="law"):
        run_key({"law": object()})


def test_sweep_gathers_runs_in_one_file(tmp_path):
    path = tmp_path / "clearance.h5"
    out = sweep(path, {"clearance": CLEARANCES}, fixed=FIXED, max_workers=2, keep="full", **FAST)
    assert out.n_computed == 2 and out.n_skipped == 0 and len(out) == 2
    assert [r.parameters["clearance"] for r in out.runs] == CLEARANCES
    assert all(r.ok for r in out.runs)
    assert out.run(clearance=0.01e-3).motion == "periodic"
    assert not _parts_left(path) and not path.with_name(path.name + ".lock").exists()
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == "daeclear-sweep"
        assert json.loads(f.attrs["options_json"])["revolutions"] == 8
        group = f["runs"][out.runs[1].key]
        assert group.attrs["clearance"] == 0.5e-3 and group.attrs["joint"] == "revolute"  # parameters as attributes
        assert group["info"].attrs["status"] == "done"
        assert group["motion"].attrs["label"] in dc.analysis.MOTION_LABELS
        assert group["section/points"].shape == (9, 2)
        assert set(group["channels"]) == {"t", "slider.vx", "slider.ax"}
        assert group["result"].attrs["format"] == "daeclear-result"  # the Result's own layout
    section = out.section(1)
    assert section.channels == ("slider.vx", "slider.ax") and len(section) == 9
    portrait = out.portrait(1)
    assert portrait.x.size == 8 * 16 + 1
    full = out.result(1)
    direct = dc.analysis.classify_motion(dc.mechanisms.slider_crank("revolute", clearance=0.5e-3),
                                         revolutions=8, transient=2, per_revolution=16, twin=False)
    assert np.array_equal(full["slider.vx"], direct.result["slider.vx"])  # same computation, bit for bit
    assert np.array_equal(section.points, direct.section.points)
    again = load_sweep(path)
    assert [r.key for r in again.runs] == [r.key for r in out.runs]
    assert again.runs[1].evidence == out.runs[1].evidence
    x, y, labels = again.bifurcation_data("clearance")
    assert x.size == y.size == len(labels) == 18


def _parts_left(path):
    parts = path.with_name(path.name + ".parts")
    return sorted(p.name for p in parts.iterdir()) if parts.exists() else []


def test_failed_runs_are_recorded_and_resume_skips_them(tmp_path):
    path = tmp_path / "bad.h5"
    out = sweep(path, {"clearance": [0.5e-3, -1.0]}, fixed=FIXED, max_workers=2, **FAST)
    bad = out.run(clearance=-1.0)
    assert bad.status == "failed" and "clearance" in bad.error and "SceneError" in bad.error
    assert "Traceback" in bad.traceback
    assert out.run(clearance=0.5e-3).ok
    again = sweep(path, {"clearance": [0.5e-3, -1.0]}, fixed=FIXED, max_workers=2, **FAST)
    assert again.n_computed == 0 and again.n_skipped == 2
    retried = sweep(path, {"clearance": [0.5e-3, -1.0]}, fixed=FIXED, max_workers=2, retry_failed=True, **FAST)
    assert retried.n_computed == 1 and retried.run(clearance=-1.0).status == "failed"
    with pytest.raises(DaeclearError, match="revolutions: file 8, now 9"):
        sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, **{**FAST, "revolutions": 9})
    assert len(load_sweep(path)) == 2  # the refused call changed nothing


def test_interrupted_sweep_resumes_without_recomputing(tmp_path):
    path = tmp_path / "interrupted.h5"
    grid = {"clearance": CLEARANCES + [0.2e-3]}

    def stop_after_first(record):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(path, grid, fixed=FIXED, max_workers=1, on_run=stop_after_first, **FAST)
    first = load_sweep(path)
    assert len(first) == 1 and first.runs[0].ok  # the finished run was kept, merged into the file
    assert not path.with_name(path.name + ".lock").exists()
    resumed = sweep(path, grid, fixed=FIXED, max_workers=2, **FAST)
    assert resumed.n_skipped == 1 and resumed.n_computed == 2 and len(resumed) == 3
    kept = resumed.run(first.runs[0].key)
    assert (kept.computed_at, kept.worker) == (first.runs[0].computed_at, first.runs[0].worker)  # not recomputed
    assert [r.index for r in resumed.runs] == [0, 1, 2]


def test_killed_sweep_loses_no_finished_run(tmp_path):
    """SIGKILL (no cleanup at all) after the first run is journaled; the next call merges and resumes."""
    path = tmp_path / "killed.h5"
    script = textwrap.dedent(f"""
        import daeclear
        daeclear.sweep({str(path)!r}, {{"clearance": {CLEARANCES + [0.2e-3]!r}}}, fixed={FIXED!r},
                       max_workers=1, revolutions=8, transient=2, per_revolution=16, twin=False, progress=False)
    """)
    proc = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    parts = path.with_name(path.name + ".parts")
    deadline = time.time() + 120
    try:
        while time.time() < deadline and not (parts.is_dir() and any(parts.glob("run-*.h5"))):
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the sweep and its worker, mid-run
        proc.wait()
    journaled = load_sweep(path)
    assert len(journaled) >= 1
    done_before = {r.key: r.computed_at for r in journaled.runs}
    resumed = sweep(path, {"clearance": CLEARANCES + [0.2e-3]}, fixed=FIXED, max_workers=2, **FAST)
    assert len(resumed) == 3 and all(r.ok for r in resumed.runs)
    assert resumed.n_skipped == len(done_before) and resumed.n_computed == 3 - len(done_before)
    assert all(resumed.run(key).computed_at == stamp for key, stamp in done_before.items())
    assert not _parts_left(path)


def test_lock_keeps_two_sweeps_apart(tmp_path):
    path = tmp_path / "locked.h5"
    lock = path.with_name(path.name + ".lock")
    import socket

    lock.write_text(json.dumps({"pid": os.getppid(), "host": socket.gethostname()}))  # a live process
    with pytest.raises(DaeclearError, match="in use"):
        sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, **FAST)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    lock.write_text(json.dumps({"pid": dead.pid, "host": socket.gethostname()}))  # a stale lock is taken over
    out = sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, max_workers=1, **FAST)
    assert len(out) == 1 and not lock.exists()


def test_process_pool_and_dask_give_identical_files(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    grid = {"clearance": CLEARANCES}
    with ProcessPoolExecutor(max_workers=2) as pool:
        sweep(tmp_path / "pool.h5", grid, fixed=FIXED, executor=pool, **FAST)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        out = sweep(tmp_path / "dask.h5", grid, fixed=FIXED, executor=client.get_executor(), **FAST)
    assert len(out) == 2 and all(r.ok for r in out.runs)
    with h5py.File(tmp_path / "pool.h5", "r") as a, h5py.File(tmp_path / "dask.h5", "r") as b:
        assert sorted(a["runs"]) == sorted(b["runs"])
        for key in a["runs"]:
            _same(_datasets(a["runs"][key]), _datasets(b["runs"][key]))


def test_cli_sweep_writes_file_and_figure_and_resumes(tmp_path, capsys):
    out = tmp_path / "cli.h5"
    argv = ["sweep", "slider_crank", str(out), "--joint", "revolute", "--grid", "clearance=0.01e-3,0.5e-3",
            "--revolutions", "8", "--transient", "2", "--per-revolution", "16", "--twin", "never", "--workers", "2",
            "--quiet"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "2 computed now" in text and "periodic (period 1)" in text
    assert (tmp_path / "cli_bifurcation.png").stat().st_size > 10_000
    assert main(argv + ["--no-figure"]) == 0
    assert "0 computed now, 2 already done" in capsys.readouterr().out
    assert main(["sweep", "slider_crank", str(out), "--grid", "clearance"]) == 2
    assert "NAME=v1,v2" in capsys.readouterr().err


def test_sweep_figures(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from daeclear.plot import plot_bifurcation, plot_motion_map

    out = sweep(tmp_path / "map.h5", {"clearance": CLEARANCES, "friction": [None, 0.1]}, fixed=FIXED,
                max_workers=2, keep="section", **FAST)
    assert len(out) == 4 and out.parameter_names() == ["clearance", "friction"]
    ax = plot_motion_map(out, "clearance", "friction", x_scale=1e3, x_unit="mm")
    assert [t.get_text() for t in ax.get_xticklabels()] == ["0.01", "0.5"]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["0.1", "None"]
    assert any(t.get_text() == "P1" for t in ax.texts)
    one = sweep(tmp_path / "bif.h5", {"clearance": CLEARANCES}, fixed=FIXED, max_workers=2, keep="section", **FAST)
    ax = plot_bifurcation(one, "clearance", scale=1e3, unit="mm")
    assert ax.get_xlabel() == "clearance (mm)" and sum(len(line.get_xdata()) for line in ax.lines) == 18
    with pytest.raises(DaeclearError, match="channels"):
        one.portrait(0)  # keep="section" stores no channels
    plt.close("all")


EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.mark.slow
@pytest.mark.parametrize("script, files", [
    ("bifurcation_revolute_clearance", ["bifurcation.h5", "bifurcation.png", "metrics.md", "metrics.json"]),
    ("sweep_revolute_clearance", ["revolute_clearance.h5", "sections.png", "evidence.png", "metrics.md"]),
    ("sweep_revolute_friction", ["revolute_friction.h5", "sections.png", "evidence.png", "metrics.md"]),
    ("sweep_translational_clearance", ["translational_clearance.h5", "sections.png", "evidence.png"]),
    ("sweep_translational_friction", ["translational_friction.h5", "sections.png", "evidence.png"]),
])
def test_sweep_examples_run_quick(script, files, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    spec = importlib.util.spec_from_file_location(f"example_{script}", EXAMPLES / f"{script}.py")
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(EXAMPLES))
    try:
        spec.loader.exec_module(module)
        assert module.main(["--quick", "--out", str(tmp_path), "--workers", "2"]) == 0
    finally:
        sys.path.remove(str(EXAMPLES))
    for name in files:
        assert (tmp_path / name).stat().st_size > 0, name
    table = load_sweep(next(tmp_path.glob("*.h5")))
    assert len(table) == 2 and all(r.ok for r in table.runs)


def test_a_sweep_builds_one_library_per_structure(tmp_path, monkeypatch):
    """Numbers are run-time data: a clearance x friction-coefficient sweep on two worker processes,
    from an empty compile cache, compiles one library (the friction law is the same structure for
    every coefficient), and every worker loads it."""
    from daeclear.engine.codegen import clear_memos

    cache = tmp_path / "cache"
    monkeypatch.setenv("DAECLEAR_CACHE_DIR", str(cache))
    clear_memos()
    out = sweep(tmp_path / "one.h5", {"clearance": [0.1e-3, 0.3e-3, 0.5e-3], "friction": [0.02, 0.1]},
                fixed=FIXED, max_workers=2, **FAST)
    assert len(out) == 6 and all(r.ok for r in out.runs)
    assert len(list(cache.glob("dc_*.so"))) == 1


def test_section_channels_follow_the_scene_without_a_slider(tmp_path):
    from daeclear.studies.analysis import section_channels

    assert section_channels(dc.mechanisms.slider_crank("revolute")) == ("slider.vx", "slider.ax")
    assert section_channels(dc.mechanisms.four_bar()) == ("rocker.omega", "rocker.alpha")
    assert section_channels(dc.assemble(dc.mechanisms.double_pendulum())) == ("link2.omega", "link2.alpha")
    out = dc.sweep(tmp_path / "four_bar.h5", {"clearance": [0.3e-3]}, mechanism="four_bar",
                   fixed={"clearance_joints": ["C"]}, revolutions=2, transient=0, per_revolution=8, twin=False,
                   max_workers=1, progress=False)
    assert out.options["channels"] == ["rocker.omega", "rocker.alpha"]
    run = out.runs[0]
    assert run.ok and set(out.channels(run)) >= {"rocker.omega", "rocker.alpha"}


# --------------------------------------------------------------------------- solver settings as one object


def test_sweep_with_options_is_the_keyword_form(tmp_path):
    """options=SolverOptions(...) gives the keyword form's file, bit for bit; the file stores the options
    (to_dict) and gives them back (from_dict); a resume in the other form is the same sweep."""
    options = dc.SolverOptions(rtol=1e-7, max_step=2e-4)
    by_keywords = sweep(tmp_path / "keywords.h5", {"clearance": CLEARANCES}, fixed=FIXED, max_workers=2, rtol=1e-7,
                        analysis={"max_step": 2e-4}, **FAST)
    by_options = sweep(tmp_path / "options.h5", {"clearance": CLEARANCES}, fixed=FIXED, max_workers=2,
                       options=options, **FAST)
    assert len(by_options) == 2 and all(r.ok for r in by_options.runs)
    assert by_options.solver_options == by_keywords.solver_options == options
    with h5py.File(tmp_path / "keywords.h5", "r") as a, h5py.File(tmp_path / "options.h5", "r") as b:
        assert json.loads(b.attrs["options_json"])["solver"] == options.to_dict()
        assert a.attrs["options_json"] == b.attrs["options_json"]
        assert sorted(a["runs"]) == sorted(b["runs"])
        for key in a["runs"]:
            _same(_datasets(a["runs"][key]), _datasets(b["runs"][key]))
    direct = dc.analysis.classify_motion(dc.mechanisms.slider_crank("revolute", clearance=0.5e-3), options=options,
                                         revolutions=8, transient=2, per_revolution=16, twin=False)
    assert np.array_equal(by_options.section(1).points, direct.section.points)  # the workers ran these settings
    default = dc.analysis.classify_motion(dc.mechanisms.slider_crank("revolute", clearance=0.5e-3),
                                          revolutions=8, transient=2, per_revolution=16, twin=False)
    assert not np.array_equal(default.section.points, direct.section.points)  # ... which change the numbers
    again = sweep(tmp_path / "keywords.h5", {"clearance": CLEARANCES}, fixed=FIXED, options=options, **FAST)
    assert again.n_computed == 0 and again.n_skipped == 2
    overridden = sweep(tmp_path / "options.h5", {"clearance": CLEARANCES}, fixed=FIXED,
                       options=options.replace(rtol=1e-3), rtol=1e-7, **FAST)  # the keyword wins, as in simulate
    assert overridden.n_computed == 0 and overridden.n_skipped == 2


def test_resume_with_other_solver_options_is_refused(tmp_path):
    path = tmp_path / "solver.h5"
    options = dc.SolverOptions(rtol=1e-7)
    sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, max_workers=1, options=options, **FAST)
    before = path.read_bytes()
    with pytest.raises(DaeclearError, match=r"solver\.max_step: file 0\.0, now 0\.0002") as info:
        sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, options=options.replace(max_step=2e-4), **FAST)
    assert "rtol" not in str(info.value)  # only what differs is named
    with pytest.raises(DaeclearError, match=r"solver\.method: file 'ida', now 'lsoda'; solver\.rtol: file 1e-07, now "
                                            r"1e-06"):
        sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, options=dc.SolverOptions(method="LSODA"), **FAST)
    with pytest.raises(DaeclearError, match=r"revolutions: file 8, now 9; solver\.rtol: file 1e-07, now 1e-08"):
        sweep(path, {"clearance": [0.5e-3]}, fixed=FIXED, options=options, **{**FAST, "revolutions": 9}, rtol=1e-8)
    assert path.read_bytes() == before  # the refused calls changed nothing
    with pytest.raises(SceneError, match="options"):
        sweep(tmp_path / "bad.h5", {"clearance": [0.5e-3]}, fixed=FIXED, options={"rtol": 1e-7}, **FAST)
    with pytest.raises(SceneError, match=r"sweep: rtol=2\.0"):
        sweep(tmp_path / "bad.h5", {"clearance": [0.5e-3]}, fixed=FIXED, rtol=2.0, **FAST)
    assert not (tmp_path / "bad.h5").exists()


def test_a_file_written_before_solver_options_is_read_and_resumed(tmp_path):
    """Files of the keyword era kept rtol (atol, max_step, ...) among the analysis options: they read as
    the SolverOptions they mean, and the same sweep resumes them without computing anything again."""
    path = tmp_path / "old.h5"
    sweep(path, {"clearance": CLEARANCES}, fixed=FIXED, max_workers=2, rtol=1e-7, analysis={"max_step": 2e-4}, **FAST)
    with h5py.File(path, "r+") as f:
        options = json.loads(f.attrs["options_json"])
        solver = options.pop("solver")
        f.attrs["options_json"] = json.dumps({**options, "rtol": solver["rtol"], "max_step": solver["max_step"]},
                                             sort_keys=True)
    old = load_sweep(path)
    assert old.solver_options == dc.SolverOptions(rtol=1e-7, max_step=2e-4) and "rtol" not in old.options
    resumed = sweep(path, {"clearance": CLEARANCES}, fixed=FIXED, rtol=1e-7, analysis={"max_step": 2e-4}, **FAST)
    assert resumed.n_computed == 0 and resumed.n_skipped == 2
    with h5py.File(path, "r") as f:  # merged in the current form
        assert json.loads(f.attrs["options_json"])["solver"] == dc.SolverOptions(rtol=1e-7, max_step=2e-4).to_dict()
    with pytest.raises(DaeclearError, match=r"solver\.rtol: file 1e-07, now 1e-06"):
        sweep(path, {"clearance": CLEARANCES}, fixed=FIXED, analysis={"max_step": 2e-4}, **FAST)


# --------------------------------------------------------------------------- the journal's atomic writes


def _failed_outcome(key, index=0):
    return {"key": key, "index": index, "parameters": {"clearance": -1.0 - index}, "status": "failed",
            "error": "SceneError: bad", "traceback": "Traceback ...", "worker": "here:1", "wall_time": 0.1,
            "computed_at": "2026-01-01T00:00:00+00:00"}


def test_journal_writes_go_through_the_one_atomic_write(tmp_path, monkeypatch):
    """write_part and consolidate write through results.outputs.atomic_file; a Ctrl-C (or any error)
    while they write leaves the old file byte for byte, the journal in place and no temporary file."""
    import contextlib

    from daeclear.studies import sweep_journal
    from daeclear.results import outputs

    used = []

    @contextlib.contextmanager
    def recording(path):
        used.append(Path(path).name)
        with outputs.atomic_file(path) as tmp:
            yield tmp

    monkeypatch.setattr(sweep_journal, "atomic_file", recording)
    path = tmp_path / "journal.h5"
    parts = path.with_name(path.name + ".parts")
    first = sweep_journal.write_part(parts, _failed_outcome("run-a"), "slider_crank", {"revolutions": 8})
    sweep_journal.consolidate(path, mechanism="slider_crank", options={"revolutions": 8}, order={"run-a": 0})
    assert used == ["run-a.h5", "journal.h5"] and not first.exists() and not parts.exists()
    assert [r.key for r in load_sweep(path).runs] == ["run-a"]
    before = path.read_bytes()

    def interrupted(group, outcome, mechanism, options):  # Ctrl-C half-way through a write
        group.attrs["half"] = 1
        raise KeyboardInterrupt

    real_write_run = sweep_journal.write_run
    monkeypatch.setattr(sweep_journal, "write_run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        sweep_journal.write_part(parts, _failed_outcome("run-b", 1), "slider_crank", {"revolutions": 8})
    assert _parts_left(path) == []  # neither the part nor its temporary file
    monkeypatch.setattr(sweep_journal, "write_run", real_write_run)
    sweep_journal.write_part(parts, _failed_outcome("run-b", 1), "slider_crank", {"revolutions": 8})

    def header_interrupted(f, mechanism, options):
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_journal, "write_header", header_interrupted)
    with pytest.raises(KeyboardInterrupt):
        sweep_journal.consolidate(path, mechanism="slider_crank", options={"revolutions": 8},
                                  order={"run-a": 0, "run-b": 1})
    assert path.read_bytes() == before and _parts_left(path) == ["run-b.h5"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["journal.h5", "journal.h5.parts"]  # no temporary file
    assert [r.key for r in load_sweep(path).runs] == ["run-a", "run-b"]  # the journal's run is still read
    monkeypatch.undo()
    sweep_journal.consolidate(path, mechanism="slider_crank", options={"revolutions": 8},
                              order={"run-a": 0, "run-b": 1})
    assert [r.key for r in load_sweep(path).runs] == ["run-a", "run-b"] and not parts.exists()


def test_a_sweep_over_scene_values(tmp_path):
    """A grid parameter with a dot is a value of the built scene (Scene.with_values): the run is
    the run of the scene with that value, bit for bit (here the same as the mechanism's option)."""
    from daeclear.studies.sweep_workers import build_scene

    scene = build_scene("slider_crank", {"joint": "revolute", "clearance.law.restitution": 0.6})
    assert scene["clearance"].law.restitution == 0.6
    with pytest.raises(SceneError, match="no field 'restitutio'"):
        build_scene("slider_crank", {"joint": "revolute", "clearance.law.restitutio": 0.6})
    out = dc.sweep(tmp_path / "restitution.h5", {"clearance.law.restitution": [0.6]}, fixed=FIXED, max_workers=1,
                   keep="full", revolutions=2, transient=0, per_revolution=8, twin=False, progress=False)
    assert out.runs[0].ok and out.runs[0].parameters["clearance.law.restitution"] == 0.6
    direct = dc.analysis.classify_motion(dc.mechanisms.slider_crank("revolute", restitution=0.6),
                                         revolutions=2, transient=0, per_revolution=8, twin=False)
    assert np.array_equal(out.result(0)["slider.vx"], direct.result["slider.vx"])
