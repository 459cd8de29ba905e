"""Bad inputs through every entry (Python API, command line, scene files), one table.

Each case asserts the error class (or the command line's exit code 2, one line, no traceback)
and that the message names the field and the value. Nothing is computed: ``simulate`` (for
the command line, studies and sweeps) and the sweep's executor are replaced by a guard that
fails the test if a bad input got that far.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np
import pytest

import daeclear as dc
from daeclear.studies.accuracy import work_precision
from daeclear.cli import main
from daeclear.core.errors import OutputDirectoryMissing, OutputError, SceneError
from daeclear.model.scenefile import read_scene_file
from scene_texts import PENDULUM as PENDULUM_FILE

SCENE = dc.mechanisms.slider_crank("ideal")
REVOLUTE = dc.mechanisms.slider_crank("revolute")
TINY = 1e-4  # s


@pytest.fixture(autouse=True)
def no_work(monkeypatch):
    """A bad input must be refused before any run: the runs of the CLI, studies and sweeps are guarded."""
    import sys

    import daeclear.studies.accuracy
    import daeclear.solvers.dispatch

    sweep_module = sys.modules["daeclear.studies.sweep"]  # daeclear.sweep is the function

    def guard(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a bad input reached the computation")

    monkeypatch.setattr(daeclear.solvers.dispatch, "simulate", guard)
    monkeypatch.setattr(daeclear.studies.accuracy, "simulate", guard)
    monkeypatch.setattr(sweep_module, "_execute", guard)


@pytest.fixture(scope="module")
def tiny_result():
    return dc.simulate(SCENE, TINY)


# --------------------------------------------------------------------------- the Python API

NAN, INF = math.nan, math.inf

API_SIMULATE: list[tuple[str, dict[str, Any], str, str]] = [
    # (id, keywords of simulate(SCENE, ...), field, value as shown)
    ("t_end=0", {"t_end": 0}, "t_end", "t_end=0"),
    ("t_end<0", {"t_end": -1.0}, "t_end", "-1.0"),
    ("t_end=nan", {"t_end": NAN}, "t_end", "nan"),
    ("t_end=inf", {"t_end": INF}, "t_end", "inf"),
    ("t_end=str", {"t_end": "0.01"}, "t_end", "'0.01'"),
    ("t_end=None", {"t_end": None}, "t_end", "None"),
    ("t_end=bool", {"t_end": True}, "t_end", "True"),
    ("rtol=0", {"rtol": 0}, "rtol", "rtol=0"),
    ("rtol<0", {"rtol": -1e-6}, "rtol", "-1e-06"),
    ("rtol=1", {"rtol": 1.0}, "rtol", "1.0"),
    ("rtol=nan", {"rtol": NAN}, "rtol", "nan"),
    ("rtol tiny", {"rtol": 1e-20}, "rtol", "1e-20"),
    ("rtol=str", {"rtol": "1e-6"}, "rtol", "'1e-6'"),
    ("atol=0", {"atol": 0.0}, "atol", "0.0"),
    ("atol<0", {"atol": -1e-9}, "atol", "-1e-09"),
    ("atol=nan", {"atol": NAN}, "atol", "nan"),
    ("atol list<0", {"atol": [1e-9, -1e-9]}, "atol", "-1e-09"),
    ("atol=str", {"atol": "small"}, "atol", "'small'"),
    ("max_step<0", {"max_step": -1e-3}, "max_step", "-0.001"),
    ("max_step=nan", {"max_step": NAN}, "max_step", "nan"),
    ("max_step=inf", {"max_step": INF}, "max_step", "inf"),
    ("max_steps=0", {"max_steps": 0}, "max_steps", "max_steps=0"),
    ("max_steps<0", {"max_steps": -5}, "max_steps", "-5"),
    ("max_steps float", {"max_steps": 1.5}, "max_steps", "1.5"),
    ("times nan", {"times": [0.0, NAN, TINY]}, "times", "nan"),
    ("times inf", {"times": [0.0, INF]}, "times", "inf"),
    ("times empty", {"times": []}, "times", "[]"),
    ("times decreasing", {"times": [TINY, 0.0]}, "times", "0.0001"),
    ("times repeated", {"times": [0.0, 0.0]}, "times", "[0.0, 0.0]"),
    ("times negative", {"times": [-1.0, 0.0]}, "times", "-1.0"),
    ("times beyond t_end", {"times": [0.0, 1.0]}, "times", "1.0"),
    ("times str", {"times": "0.0,0.01"}, "times", "'0.0,0.01'"),
    ("method", {"method": "rk5"}, "method", "'rk5'"),
    ("method int", {"method": 4}, "method", "4"),
    ("formulation", {"formulation": "index3"}, "formulation", "'index3'"),
    ("backend", {"backend": "gpu"}, "backend", "'gpu'"),
    ("on_failure", {"on_failure": "ignore"}, "on_failure", "'ignore'"),
    ("linear_solver", {"linear_solver": "lu"}, "linear_solver", "'lu'"),
    ("rk4 step=0", {"method": "rk4", "step": 0.0}, "step", "0.0"),
    ("rk4 step<0", {"method": "rk4", "step": -1e-5}, "step", "-1e-05"),
    ("rk4 step=nan", {"method": "rk4", "step": NAN}, "step", "nan"),
    ("ida with step", {"step": 1e-5}, "step", "1e-05"),
    ("DOP853 times nan", {"method": "DOP853", "times": [0.0, NAN]}, "times", "nan"),
    ("DOP853 rtol=0", {"method": "DOP853", "rtol": 0.0}, "rtol", "0.0"),
    ("DOP853 t_end=0", {"method": "DOP853", "t_end": 0.0}, "t_end", "0.0"),
    ("progress text", {"progress": "no"}, "progress", "'no'"),
    ("steps None", {"steps": None}, "steps", "None"),
    ("track_work 1", {"track_work": 1}, "track_work", "1"),
    ("DOP853 progress text", {"method": "DOP853", "progress": "yes"}, "progress", "'yes'"),
    ("every 0", {"every": 0.0}, "every", "0.0"),
    ("every > t_end", {"every": 1.0}, "every", "1.0"),
    ("every nan", {"every": NAN}, "every", "nan"),
    ("every str", {"every": "1e-5"}, "every", "'1e-5'"),
    ("every with times", {"every": 1e-5, "times": [0.0, TINY]}, "every", "1e-05"),
    ("DOP853 every 0", {"method": "DOP853", "every": 0.0}, "every", "0.0"),
    ("keep_data False without stream_to", {"keep_data": False}, "keep_data", "False"),
    ("keep_data text", {"keep_data": "no"}, "keep_data", "'no'"),
    ("stream_to int", {"stream_to": 3}, "stream_to", "3"),
    # issue 31: contradictions that were silently accepted
    ("times 2-D", {"times": [[0.0, 5e-5], [6e-5, TINY]]}, "times", "shape (2, 2)"),
    ("times 3-D", {"times": np.zeros((1, 1, 2))}, "times", "shape (1, 1, 2)"),
    ("rk4 step longer than the run", {"method": "rk4", "step": 1.0}, "step", "step=1.0 s"),
    ("euler step longer than the run", {"method": "euler", "step": 0.5}, "step", "0.5"),
    ("rk4 step longer than t_end - t0", {"method": "rk4", "step": 8e-5, "t0": 5e-5}, "step", "8e-05"),
    # issue 31: output size checked before the run
    ("every too fine", {"t_end": 0.002, "every": 1e-12}, "every", "every=1e-12"),
    ("every above the cap", {"every": 1e-5, "max_points": 5}, "every", "11 output points"),
    ("times above the cap", {"times": np.linspace(0.0, TINY, 10), "max_points": 9}, "times",
     "array of 10 times"),
    ("rk4 every step above the cap", {"method": "rk4", "step": 1e-11}, "step", "1e-11"),
    ("DOP853 every too fine", {"method": "DOP853", "every": 1e-12}, "every", "1e+08 output points"),
    ("max_points 0", {"max_points": 0}, "max_points", "0"),
    ("max_points bool", {"max_points": True}, "max_points", "True"),
    ("max_points float", {"max_points": 1e6}, "max_points", "1000000.0"),
]


SIMULATE_KEYWORDS = ("t_end", "t0", "y0", "method", "rtol", "atol", "on_failure", "progress", "parameters")
SAVE_FIELDS = ("times", "every", "steps", "stream_to", "keep_data", "max_points")


@pytest.mark.parametrize("case, kwargs, field, shown", API_SIMULATE, ids=[c[0] for c in API_SIMULATE])
def test_simulate_refuses(case, kwargs, field, shown):
    """A call's keywords, its solver settings (SolverOptions) and its output (SaveAt): each refused."""
    kwargs = {"t_end": TINY, **kwargs}
    with pytest.raises(SceneError) as info:
        save = {k: kwargs.pop(k) for k in list(kwargs) if k in SAVE_FIELDS}
        settings = {k: kwargs.pop(k) for k in list(kwargs) if k not in SIMULATE_KEYWORDS}
        if "step" in settings and "method" in kwargs:  # a method and its step: one SolverOptions
            settings["method"] = kwargs.pop("method")
        dc.simulate(SCENE, kwargs.pop("t_end"), **kwargs, options=dc.SolverOptions(**settings) if settings else None,
                    save=dc.SaveAt(**save) if save else None)
    assert field in str(info.value) and shown in str(info.value)


API_CALLS: list[tuple[str, Callable[[], Any], type, str, str]] = [
    # (id, the call, error class, field, value as shown)
    ("simulate a name", lambda: dc.simulate("slider_crank", TINY), SceneError, "scene", "'slider_crank'"),
    ("simulate None", lambda: dc.simulate(None, TINY), SceneError, "scene", "None"),
    ("simulate y0 deep in the wall", lambda: dc.simulate(REVOLUTE, TINY, y0=np.zeros(dc.assemble(REVOLUTE).n_states)),
     dc.AssemblyError, "y0", "0.17 m"),
    ("rk4 y0 deep in the wall", lambda: dc.simulate(REVOLUTE, TINY,
                                                    y0=np.zeros(dc.assemble(REVOLUTE, "index1").n_states),
                                                        options=dc.SolverOptions(method="rk4", step=1e-5)),
     dc.AssemblyError, "y0", "of the clearance 0.0005 m"),
]


@pytest.mark.parametrize("case, call, exc, field, shown", API_CALLS, ids=[c[0] for c in API_CALLS])
def test_api_calls_refuse(case, call, exc, field, shown):
    with pytest.raises(exc) as info:
        call()
    assert field in str(info.value) and shown in str(info.value), str(info.value)


LOAD_WINDOWS: list[tuple[str, tuple[Any, Any], str]] = [
    ("after the run", (5.0, 6.0), "t0=5.0, t1=6.0"),
    ("before the run", (-2.0, -1.0), "t0=-2.0, t1=-1.0"),
    ("from after the end", (1.0, None), "t0=1.0, t1=None"),
    ("up to before the start", (None, -1e-3), "t0=None, t1=-0.001"),
]


@pytest.mark.parametrize("case, window, shown", LOAD_WINDOWS, ids=[c[0] for c in LOAD_WINDOWS])
def test_load_refuses_a_window_outside_the_run(case, window, shown, tmp_path, tiny_result):
    path = tmp_path / "run.h5"
    tiny_result.save(path)
    with pytest.raises(SceneError) as info:
        dc.load(path, *window)
    text = str(info.value)
    assert shown in text and str(path) in text and "[0, 0.0001]" in text, text


API_MECHANISMS: list[tuple[str, Callable[[], Any], str, str]] = [
    ("restitution with hertz", lambda: dc.mechanisms.slider_crank("revolute", law="hertz", restitution=0.5),
     "restitution", "0.5"),
    ("restitution with kelvin-voigt", lambda: dc.mechanisms.slider_crank("translational", law="kelvin-voigt",
                                                                         restitution=0.7), "restitution", "0.7"),
    ("restitution with a law object", lambda: dc.mechanisms.slider_crank(
        "revolute", law=dc.contact.LankaraniNikravesh(restitution=0.9), restitution=0.5), "restitution", "0.5"),
    ("chain restitution with hertz", lambda: dc.mechanisms.chain(2, law="hertz", restitution=0.3),
     "restitution", "0.3"),
    ("restitution > 1", lambda: dc.mechanisms.slider_crank("revolute", restitution=1.5), "restitution", "1.5"),
    ("rpm nan", lambda: dc.mechanisms.slider_crank("ideal", rpm=NAN), "rpm", "nan"),
    ("clearance 0", lambda: dc.mechanisms.slider_crank("revolute", clearance=0.0), "clearance", "0.0"),
    ("gravity < 0", lambda: dc.mechanisms.slider_crank("ideal", gravity=-9.81), "gravity", "-9.81"),
    ("joint", lambda: dc.mechanisms.slider_crank("cylindrical"), "joint", "'cylindrical'"),
    # issue 31: a bool is not a number; an option of a clearance joint the mechanism does not have
    ("gravity True", lambda: dc.mechanisms.slider_crank("ideal", gravity=True), "gravity", "True"),
    ("rpm True", lambda: dc.mechanisms.slider_crank("ideal", rpm=True), "rpm", "True"),
    ("crank_angle False", lambda: dc.mechanisms.slider_crank("ideal", crank_angle=False), "crank_angle", "False"),
    ("clearance True", lambda: dc.mechanisms.slider_crank("revolute", clearance=True), "clearance", "True"),
    ("translational clearance True", lambda: dc.mechanisms.slider_crank("translational", clearance=True),
     "clearance", "True"),
    ("pin_offset with a bool", lambda: dc.mechanisms.slider_crank("translational", pin_offset=(True, 0.0)),
     "pin_offset", "(True, 0.0)"),
    ("length True", lambda: dc.mechanisms.slider_crank("revolute", length=True), "length", "True"),
    ("four_bar length True", lambda: dc.mechanisms.four_bar("B", length=True), "length", "True"),
    ("chain length True", lambda: dc.mechanisms.chain(2, length=True), "length", "True"),
    ("body position bool", lambda: _validated(dc.Body("extra", mass=1.0, inertia=1.0, position=(True, 0.0))),
     "position", "(True, 0.0)"),
    ("body velocity bool", lambda: _validated(dc.Body("extra", mass=1.0, inertia=1.0, velocity=(0.0, False))),
     "velocity", "(0.0, False)"),
    ("revolute at bool", lambda: _validated(dc.Revolute("E", "ground", "slider", at=(True, 0.0))), "at",
     "(True, 0.0)"),
    ("ideal with clearance", lambda: dc.mechanisms.slider_crank("ideal", clearance=1e-4), "clearance", "0.0001"),
    ("ideal with friction", lambda: dc.mechanisms.slider_crank("ideal", friction=0.1), "friction", "0.1"),
    ("ideal with law", lambda: dc.mechanisms.slider_crank("ideal", law="hertz"), "law", "'hertz'"),
    ("ideal with restitution", lambda: dc.mechanisms.slider_crank("ideal", restitution=0.5), "restitution", "0.5"),
    ("ideal with bearing_radius", lambda: dc.mechanisms.slider_crank("ideal", bearing_radius=0.02),
     "bearing_radius", "0.02"),
    ("ideal with face_law", lambda: dc.mechanisms.slider_crank("ideal", face_law="hertz"), "face_law", "'hertz'"),
    ("ideal with contact_model", lambda: dc.mechanisms.slider_crank("ideal", contact_model="section-4.3"),
     "contact_model", "'section-4.3'"),
    ("ideal four_bar with clearance", lambda: dc.mechanisms.four_bar((), clearance=1e-4), "clearance", "0.0001"),
    ("ideal double_pendulum with friction", lambda: dc.mechanisms.double_pendulum(friction=0.2), "friction", "0.2"),
]


def _validated(element: Any) -> Any:
    """The ideal slider-crank with ``element`` added, validated (an element's problems are found there)."""
    scene = dc.mechanisms.slider_crank("ideal")
    scene.add(element)
    scene.validate()
    return scene


@pytest.mark.parametrize("case, build, field, shown", API_MECHANISMS, ids=[c[0] for c in API_MECHANISMS])
def test_mechanisms_refuse(case, build, field, shown):
    with pytest.raises(SceneError) as info:
        build()
    assert field in str(info.value) and shown in str(info.value)


API_STUDY: list[tuple[str, dict[str, Any], str, str]] = [
    ("t_end=0", {"t_end": 0.0}, "t_end", "0.0"),
    ("rtols empty", {"rtols": []}, "rtols", "[]"),
    ("rtols zero", {"rtols": [1e-6, 0.0]}, "rtols[1]", "0.0"),
    ("steps negative", {"steps": [-1e-5]}, "steps[0]", "-1e-05"),
    ("steps > t_end", {"steps": [1.0]}, "steps[0]", "1.0"),
    ("repeats < 0", {"repeats": -1}, "repeats", "-1"),
    ("n_eval 1", {"n_eval": 1}, "n_eval", "1"),
    ("method", {"methods": {"X": {"method": "rk5"}}}, "method", "'rk5'"),
]


@pytest.mark.parametrize("case, kwargs, field, shown", API_STUDY, ids=[c[0] for c in API_STUDY])
def test_work_precision_refuses(case, kwargs, field, shown):
    kwargs = {"t_end": 0.002, **kwargs}
    with pytest.raises(SceneError) as info:
        work_precision(SCENE, kwargs.pop("t_end"), **kwargs)
    assert field in str(info.value) and shown in str(info.value)


API_SWEEP: list[tuple[str, dict[str, Any], type, str, str]] = [
    ("keep", {"keep": "all"}, SceneError, "keep", "'all'"),
    ("revolutions 0", {"revolutions": 0}, SceneError, "revolutions", "0"),
    ("transient < 0", {"transient": -1}, SceneError, "transient", "-1"),
    ("per_revolution 0", {"per_revolution": 0}, SceneError, "per_revolution", "0"),
    ("rtol 0", {"rtol": 0.0}, SceneError, "rtol", "0.0"),
    ("max_workers 0", {"max_workers": 0}, SceneError, "max_workers", "0"),
    ("twin", {"twin": "maybe"}, SceneError, "twin", "'maybe'"),
    ("channels empty", {"channels": []}, SceneError, "channels", "[]"),
    ("channels unknown", {"channels": ["slider.vz"]}, SceneError, "channels", "'slider.vz'"),
    ("store_channels unknown", {"store_channels": ["slider.vx", "rod.q"]}, SceneError, "store_channels", "'rod.q'"),
    ("grid for no joint", {"fixed": {"joint": "ideal"}}, SceneError, "clearance", "0.0001"),
    ("no driver", {"mechanism": "double_pendulum", "fixed": {"clearance_joints": "A"}}, SceneError, "driver",
     "double_pendulum_A"),
]


@pytest.mark.parametrize("case, kwargs, exc, field, shown", API_SWEEP, ids=[c[0] for c in API_SWEEP])
def test_sweep_refuses_options(case, kwargs, exc, field, shown, tmp_path):
    kwargs = {"fixed": {"joint": "revolute"}, **kwargs}
    with pytest.raises(exc) as info:
        dc.sweep(tmp_path / "s.h5", {"clearance": [1e-4]}, progress=False, **kwargs)
    assert field in str(info.value) and shown in str(info.value)
    assert list(tmp_path.iterdir()) == []  # nothing written


def _places(tmp_path: Path) -> dict[str, tuple[Path, type]]:
    """Bad output places: (path, error class) by case."""
    folder = tmp_path / "folder"
    folder.mkdir()
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    return {"a folder": (folder, OutputError),
            "missing folder": (tmp_path / "missing" / "x.h5", OutputDirectoryMissing),
            "under a file": (a_file / "x.h5", OutputError), "unwritable": (Path("/proc/daeclear-x.h5"), OutputError)}


@pytest.mark.parametrize("place", ["a folder", "missing folder", "under a file", "unwritable"])
def test_result_save_refuses_place(place, tmp_path, tiny_result):
    path, exc = _places(tmp_path)[place]
    with pytest.raises(exc) as info:
        tiny_result.save(path)
    assert "Result.save(path)" in str(info.value) and str(path) in str(info.value)


@pytest.mark.parametrize("place", ["a folder", "missing folder", "under a file", "unwritable"])
def test_sweep_refuses_place(place, tmp_path):
    path, exc = _places(tmp_path)[place]
    with pytest.raises(exc) as info:
        dc.sweep(path, {"clearance": [1e-4]}, fixed={"joint": "revolute"}, progress=False)
    assert "sweep(path)" in str(info.value) and str(path) in str(info.value)


@pytest.mark.parametrize("writer", ["to_csv", "to_markdown"])
@pytest.mark.parametrize("place", ["a folder", "under a file"])
def test_study_tables_refuse_place(writer, place, tmp_path):
    from daeclear.studies.accuracy import WorkPrecision

    study = WorkPrecision(rows=[], channels=["slider.vx"], window=(0.0, 1.0), window_reason="given",
                          reference=None, reference_options={}, assembly_time=0.0)  # type: ignore[arg-type]
    path, exc = _places(tmp_path)[place]
    with pytest.raises(exc) as info:
        getattr(study, writer)(path)
    assert f"WorkPrecision.{writer}(path)" in str(info.value) and str(path) in str(info.value)


def test_sweep_refuses_a_journal_that_is_a_file(tmp_path):
    (tmp_path / "s.h5.parts").write_text("x")
    with pytest.raises(OutputError, match=r"s\.h5\.parts"):
        dc.sweep(tmp_path / "s.h5", {"clearance": [1e-4]}, fixed={"joint": "revolute"}, progress=False)


# --------------------------------------------------------------------------- the command line


def _cli(argv: list[str], capsys) -> str:
    """Run the command line; it must exit 2 with one line on stderr and no traceback."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err


CLI_RUN: list[tuple[str, list[str], str, str]] = [
    ("--t-end 0", ["--t-end", "0"], "--t-end", "0.0"),
    ("--t-end -1", ["--t-end", "-1"], "--t-end", "-1.0"),
    ("--t-end nan", ["--t-end", "nan"], "--t-end", "nan"),
    ("--t-end inf", ["--t-end", "inf"], "--t-end", "inf"),
    ("--rtol 0", ["--rtol", "0"], "--rtol", "0.0"),
    ("--rtol 1", ["--rtol", "1"], "--rtol", "1.0"),
    ("--rtol nan", ["--rtol", "nan"], "--rtol", "nan"),
    ("--rtol -1e-6", ["--rtol=-1e-6"], "--rtol", "-1e-06"),
    ("--rtol 1e-20", ["--rtol", "1e-20"], "--rtol", "1e-20"),
    ("--name with a folder", ["--name", "a/b"], "--name", "'a/b'"),
    ("--name empty", ["--name", ""], "--name", "''"),
    ("--set rpm nan", ["--set", "rpm=nan"], "rpm", "'nan'"),
    ("--set clearance 0", ["--joint", "revolute", "--set", "clearance=0"], "clearance", "0"),
    ("--set restitution with hertz", ["--joint", "revolute", "--set", "law='hertz'", "--set", "restitution=0.5"],
     "restitution", "0.5"),
    ("--set restitution 2", ["--joint", "revolute", "--set", "restitution=2.0"], "restitution", "restitution=2"),
    ("--set gravity -1", ["--set", "gravity=-1"], "gravity", "-1"),
    ("--set unknown", ["--set", "rpmm=1"], "rpmm", "rpmm"),
    ("--joint", ["--joint", "cylindrical"], "joint", "'cylindrical'"),
    ("--t-eval-step 0", ["--t-eval-step", "0"], "--t-eval-step", "0.0"),
    ("--t-eval-step nan", ["--t-eval-step", "nan"], "--t-eval-step", "nan"),
    ("--t-eval-step > t_end", ["--t-eval-step", "1"], "--t-eval-step", "1.0"),
    ("--max-steps 0", ["--max-steps", "0"], "--max-steps", "0"),
    ("--max-steps -5", ["--max-steps=-5"], "--max-steps", "-5"),
    # issue 31: duplicates and contradictions
    ("--set twice", ["--set", "rpm=1000", "--set", "rpm=2000"], "rpm", "rpm=1000"),
    ("--set twice, same value", ["--set", "gravity=0", "--set", "gravity=0"], "gravity", "gravity=0"),
    ("--set joint and --joint", ["--joint", "revolute", "--set", "joint='translational'"], "joint", "'translational'"),
    ("--set clearance without --joint", ["--set", "clearance=1e-4"], "clearance", "0.0001"),
    ("--set friction without --joint", ["--set", "friction=0.1"], "friction", "0.1"),
    ("--set law without --joint", ["--set", "law='hertz'"], "law", "'hertz'"),
    ("--set bearing_radius without --joint", ["--set", "bearing_radius=0.02"], "bearing_radius", "0.02"),
    ("--set pin_offset with --joint revolute", ["--joint", "revolute", "--set", "pin_offset=(0.01,0.0)"],
     "pin_offset", "(0.01, 0.0)"),
    ("--set contact_model with --joint revolute", ["--joint", "revolute", "--set", "contact_model='section-4.3'"],
     "contact_model", "'section-4.3'"),
    ("--set gravity=True", ["--set", "gravity=True"], "gravity", "True"),
    ("--set rpm=True", ["--set", "rpm=True"], "rpm", "True"),
    ("--max-points 0", ["--max-points", "0"], "--max-points", "0"),
    ("--window reversed", ["--window", "0.01", "0.005"], "--window", "(0.01, 0.005)"),
    ("--window after the run", ["--t-end", "0.01", "--window", "0.02", "0.03"], "--window", "(0.02, 0.03)"),
    ("--window nan", ["--window", "nan", "0.01"], "--window", "nan"),
]


@pytest.mark.parametrize("case, args, field, shown", CLI_RUN, ids=[c[0] for c in CLI_RUN])
def test_cli_run_refuses(case, args, field, shown, tmp_path, capsys):
    err = _cli(["run", "slider_crank", "--out", str(tmp_path / "out"), "--quiet", *args], capsys)
    assert field in err and shown in err


@pytest.mark.parametrize("place", ["a file", "under a file", "unwritable", "h5 is a folder", "png is a folder"])
def test_cli_run_refuses_out_before_work(place, tmp_path, capsys):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    out = {"a file": a_file, "under a file": a_file / "sub", "unwritable": Path("/proc/daeclear-out"),
           "h5 is a folder": tmp_path / "o1", "png is a folder": tmp_path / "o2"}[place]
    if place == "h5 is a folder":
        (out / "slider_crank.h5").mkdir(parents=True)
    if place == "png is a folder":
        (out / "slider_crank.png").mkdir(parents=True)
    err = _cli(["run", "slider_crank", "--out", str(out), "--quiet"], capsys)
    assert "--out" in err and str(out) in err


CLI_OTHER: list[tuple[str, list[str], str, str]] = [
    # (id, the whole command line but --out, field, value as shown)
    ("run four_bar --joint", ["run", "four_bar", "--joint", "revolute"], "--joint", "four_bar"),
    ("study four_bar --joint", ["study", "four_bar", "--joint", "revolute"], "--joint", "four_bar"),
    ("run four_bar clearance without joints", ["run", "four_bar", "--set", "clearance=1e-4"], "clearance",
     "clearance_joints=()"),
    ("run double_pendulum friction without joints", ["run", "double_pendulum", "--set", "friction=0.1"], "friction",
     "0.1"),
    ("run --set name with a folder", ["run", "slider_crank", "--set", "name='a/b'"], "name", "'a/b'"),
]


@pytest.mark.parametrize("case, args, field, shown", CLI_OTHER, ids=[c[0] for c in CLI_OTHER])
def test_cli_other_mechanisms_refuse(case, args, field, shown, tmp_path, capsys):
    err = _cli([*args, "--out", str(tmp_path / "out")], capsys)
    assert field in err and shown in err


CLI_STUDY: list[tuple[str, list[str], str, str]] = [
    ("--t-end 0", ["--t-end", "0"], "--t-end", "0.0"),
    ("--t-end nan", ["--t-end", "nan"], "--t-end", "nan"),
    ("--repeats -1", ["--repeats", "-1"], "--repeats", "-1"),
    ("--methods unknown", ["--methods", "ida,rk5"], "--methods[1]", "'rk5'"),
    ("--methods empty", ["--methods", ","], "--methods", "[]"),
    ("--rtols 0", ["--rtols", "1e-6,0"], "--rtols[1]", "0.0"),
    ("--rtols 1", ["--rtols", "1"], "--rtols[0]", "1.0"),
    ("--rtols text", ["--rtols", "tight"], "--rtols", "'tight'"),
    ("--steps 0", ["--steps", "0"], "--steps[0]", "0.0"),
    ("--steps > t_end", ["--steps", "1"], "--steps[0]", "1.0"),
    ("--channels empty", ["--channels", ""], "--channels", "[]"),
    ("--set restitution with hertz", ["--set", "law='hertz'", "--set", "restitution=0.5"], "restitution", "0.5"),
]


@pytest.mark.parametrize("case, args, field, shown", CLI_STUDY, ids=[c[0] for c in CLI_STUDY])
def test_cli_study_refuses(case, args, field, shown, tmp_path, capsys):
    err = _cli(["study", "slider_crank", "--out", str(tmp_path / "out"), *args], capsys)
    assert field in err and shown in err


@pytest.mark.parametrize("place", ["a file", "csv is a folder"])
def test_cli_study_refuses_out_before_work(place, tmp_path, capsys):
    out = tmp_path / "o"
    if place == "a file":
        out.write_text("x")
    else:
        (out / "work_precision.csv").mkdir(parents=True)
    err = _cli(["study", "slider_crank", "--out", str(out)], capsys)
    assert "--out" in err and str(out) in err


CLI_SWEEP: list[tuple[str, list[str], str, str]] = [
    ("--revolutions 0", ["--revolutions", "0"], "--revolutions", "0"),
    ("--transient -1", ["--transient", "-1"], "--transient", "-1"),
    ("--per-revolution 0", ["--per-revolution", "0"], "--per-revolution", "0"),
    ("--rtol 0", ["--rtol", "0"], "--rtol", "0.0"),
    ("--rtol nan", ["--rtol", "nan"], "--rtol", "nan"),
    ("--workers 0", ["--workers", "0"], "--workers", "0"),
    ("--channels empty", ["--channels", ","], "--channels", "[]"),
    ("--grid geom 0", ["--grid", "friction=geom:0:1:3"], "--grid", "geom:0:1:3"),
    ("--grid lin N", ["--grid", "friction=lin:0:1:0"], "--grid", "lin:0:1:0"),
    ("--grid twice", ["--grid", "clearance=1e-4", "--grid", "clearance=2e-4,3e-4"], "clearance", "clearance=2e-4"),
    ("--grid over --set", ["--set", "clearance=2e-4"], "clearance", "--set clearance=0.0002"),
    ("--grid over --joint", ["--grid", "joint=revolute,translational"], "--joint", "revolute"),
    ("--grid kind unknown", ["--grid", "clearance=log:1e-5:1e-4:3"], "'log'", "geom:START:STOP:N"),
    ("--set twice", ["--set", "friction=0.1", "--set", "friction=0.2"], "friction", "friction=0.1"),
    ("--channels unknown", ["--channels", "slider.vx,slider.vz"], "channels", "'slider.vz'"),
]


@pytest.mark.parametrize("case, args, field, shown", CLI_SWEEP, ids=[c[0] for c in CLI_SWEEP])
def test_cli_sweep_refuses(case, args, field, shown, tmp_path, capsys):
    grid = [] if any(a == "--grid" for a in args) else ["--grid", "clearance=1e-4"]
    err = _cli(["sweep", "slider_crank", str(tmp_path / "s.h5"), "--joint", "revolute", *grid, *args], capsys)
    assert field in err and shown in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("place", ["a folder", "under a file", "unwritable", "not a sweep file"])
def test_cli_sweep_refuses_out_before_work(place, tmp_path, capsys):
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    folder = tmp_path / "folder"
    folder.mkdir()
    out = {"a folder": folder, "under a file": a_file / "s.h5", "unwritable": Path("/proc/daeclear-s.h5"),
           "not a sweep file": a_file}[place]
    err = _cli(["sweep", "slider_crank", str(out), "--joint", "revolute", "--grid", "clearance=1e-4", "--quiet"],
               capsys)
    assert str(out) in err
    assert ("OUT" in err) or ("not a daeclear sweep" in err)


# --------------------------------------------------------------------------- scene files

PENDULUM = PENDULUM_FILE

SCENE_FILE: list[tuple[str, str, str, str]] = [
    # (id, [simulate] lines (or a whole [mechanism] file), field, value as shown)
    ("t_end = 0", "t_end = 0", "t_end", "t_end=0"),
    ("t_end = 0.0", "t_end = 0.0", "t_end", "0.0"),
    ("t_end < 0", "t_end = -1.0", "t_end", "-1.0"),
    ("t_end = nan", "t_end = nan", "t_end", "nan"),
    ("t_end = inf", "t_end = inf", "t_end", "inf"),
    ("t_end text", 't_end = "1"', "t_end", "'1'"),
    ("rtol = 0", "rtol = 0.0", "rtol", "0.0"),
    ("rtol = 1", "rtol = 1.0", "rtol", "1.0"),
    ("rtol text", 'rtol = "tight"', "rtol", "'tight'"),
    ("atol = 0", "atol = 0.0", "atol", "0.0"),
    ("atol < 0", "atol = -1e-9", "atol", "-1e-09"),
    ("max_step < 0", "max_step = -1e-3", "max_step", "-0.001"),
    ("t_eval_step = 0", "t_end = 0.1\nt_eval_step = 0.0", "t_eval_step", "0.0"),
    ("t_eval_step < 0", "t_eval_step = -0.01", "t_eval_step", "-0.01"),
    ("t_eval_step > t_end", "t_end = 0.1\nt_eval_step = 0.5", "t_eval_step", "0.5"),
    ("t_eval_step = nan", "t_eval_step = nan", "t_eval_step", "nan"),
    ("method", 'method = "rk5"', "method", "'rk5'"),
    ("formulation", 'formulation = "index3"', "formulation", "'index3'"),
    ("backend", 'backend = "gpu"', "backend", "'gpu'"),
    ("rk4 step longer than t_end", 'method = "rk4"\nt_end = 0.1\nstep = 1.0', "step", "1.0"),
    ("rk4 step = 0", 'method = "rk4"\nstep = 0.0', "step", "0.0"),
    ("euler step text", 'method = "euler"\nstep = "1e-5"', "step", "'1e-5'"),
]

MECHANISM_FILE: list[tuple[str, str, str, str]] = [
    ("restitution with hertz", 'joint = "revolute"\nlaw = "hertz"\nrestitution = 0.5', "restitution", "0.5"),
    ("rpm nan", "rpm = nan", "rpm", "nan"),
    ("clearance 0", 'joint = "revolute"\nclearance = 0.0', "clearance", "0.0"),
]


def _scene_file(tmp_path: Path, simulate: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(PENDULUM + "\n[simulate]\n" + simulate + "\n")
    return path


def _mechanism_file(tmp_path: Path, lines: str) -> Path:
    path = tmp_path / "mechanism.toml"
    path.write_text('[mechanism]\nname = "slider_crank"\n' + lines + "\n")
    return path


@pytest.mark.parametrize("case, lines, field, shown", SCENE_FILE, ids=[c[0] for c in SCENE_FILE])
def test_scene_file_refuses(case, lines, field, shown, tmp_path):
    path = _scene_file(tmp_path, lines)
    with pytest.raises(SceneError) as info:
        read_scene_file(path)
    text = str(info.value)
    assert str(path) in text and "[simulate]" in text and field in text and shown in text


@pytest.mark.parametrize("case, lines, field, shown", SCENE_FILE, ids=[c[0] for c in SCENE_FILE])
def test_scene_file_refused_by_the_cli(case, lines, field, shown, tmp_path, capsys):
    path = _scene_file(tmp_path, lines)
    err = _cli(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"], capsys)
    assert field in err and shown in err


@pytest.mark.parametrize("case, lines, field, shown", MECHANISM_FILE, ids=[c[0] for c in MECHANISM_FILE])
def test_mechanism_file_refuses(case, lines, field, shown, tmp_path, capsys):
    path = _mechanism_file(tmp_path, lines)
    with pytest.raises(SceneError) as info:
        read_scene_file(path)
    assert field in str(info.value) and shown in str(info.value)
    err = _cli(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"], capsys)
    assert field in err and shown in err


FILES: list[tuple[str, bytes, str, str]] = [
    # (id, the file's bytes, field, value as shown): the file is named too
    ("binary", b"\x00\xff\xfe\x00 not text", "UTF-8", "byte 1"),
    ("latin-1", "[scene]\nname = 'p\xe9ndulum'\n".encode("latin-1"), "UTF-8", "byte"),
    ("name with a folder", (PENDULUM.replace('name = "pendulum"', 'name = "a/b"', 1)).encode(), "[scene] name",
     "'a/b'"),
]


@pytest.mark.parametrize("case, data, field, shown", FILES, ids=[c[0] for c in FILES])
def test_cli_refuses_a_file(case, data, field, shown, tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_bytes(data)
    err = _cli(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"], capsys)
    assert field in err and shown in err and str(path) in err, err


def test_cli_t_end_overrides_the_file_and_t_eval_step_is_checked_against_it(tmp_path, capsys):
    """The file's spacing fits its own t_end but not the end asked for on the command line."""
    path = _scene_file(tmp_path, "t_end = 0.5\nt_eval_step = 0.1")
    err = _cli(["run", str(path), "--t-end", "0.05", "--out", str(tmp_path / "out"), "--quiet"], capsys)
    assert "t_eval_step" in err and "0.1" in err


def test_same_rule_and_message_everywhere(tmp_path, capsys):
    """t_end = 0 gets the same rule through the API, the command line and a scene file."""
    rule = "must be a finite number > 0."
    with pytest.raises(SceneError, match="t_end=0 s, " + rule.replace(".", r"\.")):
        dc.simulate(SCENE, 0)
    assert rule in _cli(["run", "slider_crank", "--t-end", "0", "--out", str(tmp_path / "o")], capsys)
    with pytest.raises(SceneError, match=rule.replace(".", r"\.")):
        read_scene_file(_scene_file(tmp_path, "t_end = 0"))


def test_there_are_at_least_100_cases():
    n = (len(API_SIMULATE) + len(API_MECHANISMS) + len(API_STUDY) + len(API_SWEEP) + 4 + 4 + 4 + 1 + len(CLI_RUN) + 5
         + len(CLI_STUDY) + 2 + len(CLI_SWEEP) + 4 + 2 * len(SCENE_FILE) + len(MECHANISM_FILE) + 2)
    assert n >= 100, n
    issue_31 = (13 + len(API_CALLS) + len(LOAD_WINDOWS) + 21 + 4 + 15 + len(CLI_OTHER) + 6 + 2 * 3
                + len(FILES))
    assert issue_31 >= 40, issue_31


# --------------------------------------------------------------------------- loads (daeclear.loads)

API_LOADS: list[tuple[str, Callable[[], Any], str, str]] = [
    # (id, the load added to the ideal slider-crank, field, value as shown)
    ("force fx nan", lambda: dc.Force("f", "slider", fx=NAN), "fx", "nan"),
    ("force fy text", lambda: dc.Force("f", "slider", fy="10"), "fy", "'10'"),
    ("force on the ground", lambda: dc.Force("f", "ground", fx=1.0), "body", "'ground'"),
    ("force frame", lambda: dc.Force("f", "slider", fx=1.0, frame="local"), "frame", "'local'"),
    ("force at", lambda: dc.Force("f", "slider", fx=1.0, at=(1.0,)), "at", "(1.0,)"),
    ("force unknown body", lambda: dc.Force("f", "slidr", fx=1.0), "body", "'slidr'"),
    ("table decreasing", lambda: dc.Torque("t", "crank", dc.Table((1.0, 0.5), (0.0, 1.0))), "times", "[1.0, 0.5]"),
    ("table lengths", lambda: dc.Torque("t", "crank", dc.Table((0.0, 0.5, 1.0), (0.0, 1.0))), "value", "3 times"),
    ("table inf", lambda: dc.Torque("t", "crank", dc.Table((0.0, INF), (0.0, 1.0))), "times", "inf"),
    ("expression number", lambda: dc.Torque("t", "crank", dc.Expression(lambda t, s, p: p.a, a=NAN)), "a", "nan"),
    ("expression math", lambda: dc.Torque("t", "crank", dc.Expression(lambda t, s, p: math.exp(-t))), "value",
     "does not run on CasADi"),
    ("expression if", lambda: dc.Torque("t", "crank", dc.Expression(lambda t, s, p: 1.0 if s.speed > 0 else 0.0)),
     "value", "does not run on CasADi"),
    ("expression raises", lambda: dc.Torque("t", "crank", dc.Expression(lambda t, s, p: p.missing)), "value",
     "missing"),
    ("torque reaction itself", lambda: dc.Torque("t", "crank", 1.0, reaction="crank"), "reaction", "'crank'"),
    ("spring stiffness < 0", lambda: dc.SpringDamper("s", "ground", "slider", at_i=(0.0, 0.0), at_j=(0.17, 0.0),
                                                     stiffness=-5.0), "stiffness", "-5.0"),
    ("spring damping nan", lambda: dc.SpringDamper("s", "ground", "slider", at_i=(0.0, 0.0), at_j=(0.17, 0.0),
                                                   damping=NAN), "damping", "nan"),
    ("spring points coincide", lambda: dc.SpringDamper("s", "ground", "slider", at_i=(0.17, 0.0),
                                                       at_j=(0.17, 0.0), stiffness=1.0), "at_i", "(0.17, 0.0)"),
    ("spring free length < 0", lambda: dc.SpringDamper("s", "ground", "slider", at_i=(0.0, 0.0), at_j=(0.17, 0.0),
                                                       free_length=-0.1), "free_length", "-0.1"),
    ("torsion same body", lambda: dc.RotationalSpringDamper("r", "rod", "rod", stiffness=1.0), "body_j", "'rod'"),
    ("torsion free angle inf", lambda: dc.RotationalSpringDamper("r", "crank", "rod", free_angle=INF), "free_angle",
     "inf"),
    ("motor stall 0", lambda: dc.Motor("m", "ground", "crank", stall_torque=0.0, no_load_speed=300.0),
     "stall_torque", "0.0"),
    ("motor signs", lambda: dc.Motor("m", "ground", "crank", stall_torque=2.0, no_load_speed=-300.0),
     "no_load_speed", "-300.0"),
    ("motor unknown body", lambda: dc.Motor("m", "gound", "crank", stall_torque=2.0, no_load_speed=300.0),
     "body_i", "'gound'"),
    # a point of application is a world point or a body-fixed point, never both (issue 34)
    ("force at and point", lambda: dc.Force("f", "slider", fx=1.0, at=(0.17, 0.0), point=(0.0, 0.01)),
     "point", "(0.0, 0.01)"),
    ("force point", lambda: dc.Force("f", "slider", fx=1.0, point=(NAN, 0.0)), "point", "(nan, 0.0)"),
    ("spring at_j and point_j", lambda: dc.SpringDamper("s", "ground", "slider", at_i=(0.0, 0.0), at_j=(0.17, 0.0),
                                                        point_j=(0.01, 0.0), stiffness=1.0), "point_j", "(0.01, 0.0)"),
    ("spring end i missing", lambda: dc.SpringDamper("s", "ground", "slider", point_j=(0.0, 0.0), stiffness=1.0),
     "at_i=None and point_i", "must give one"),
    ("revolute at and point_i", lambda: dc.Revolute("E", "crank", "rod", at=(0.05, 0.0), point_i=(0.05, 0.0),
                                                    point_j=(-0.06, 0.0)), "at=(0.05, 0.0) and point_i", "point_j"),
]


@pytest.mark.parametrize("case, build, field, shown", API_LOADS, ids=[c[0] for c in API_LOADS])
def test_loads_refuse(case, build, field, shown):
    scene = dc.mechanisms.slider_crank("ideal")
    scene.add(build())
    with pytest.raises(SceneError) as info:
        dc.assemble(scene)
    text = str(info.value)
    assert field in text and shown in text, text
