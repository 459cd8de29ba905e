"""Bad input to the lubricated joint, the worn profile and simulate_wear (issue 44, item 7): each case
the error type, and the message naming the field and the value (the shape of daeclear/options.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import daeclear as dc
from daeclear.cli import main
from daeclear.contact import HydrodynamicBearing
from daeclear.contact.wear import ArchardWear
from daeclear.core.errors import DaeclearError, Interrupted, OutputError, SceneError
from daeclear.studies.wear import simulate_wear

BEARING = HydrodynamicBearing(viscosity=0.04, length=0.02)
R, C = 0.01, 5e-5


@pytest.mark.parametrize("args, words", [
    ((0.5, float("nan"), 0.0), ["film_force: wedge_rate=nan", "must be a finite number"]),
    ((0.5, 10.0, float("inf")), ["squeeze_rate=inf", "must be a finite number"]),
    ((0.5, "10", 0.0), ["wedge_rate='10' is not a real number"]),
    ((0.5, 10.0, [1.0, "x"]), ["squeeze_rate=[1.0, 'x'] is not a real number"]),
])
def test_film_force_rates(args, words):
    with pytest.raises(SceneError) as info:
        BEARING.film_force(*args, radius=R, clearance=C)
    for word in words:
        assert word in str(info.value)


def test_film_force_clearance_larger_than_the_radius():
    with pytest.raises(SceneError, match=r"film_force: clearance=0.02 m, must be < radius=0.01 m"):
        BEARING.film_force(0.5, 10.0, 0.0, radius=R, clearance=0.02)


def flight(depth) -> dc.Scene:
    scene = dc.Scene("flight", gravity=(0.0, 0.0))
    journal = scene.add(dc.Body("journal", mass=0.1, inertia=1e-5))
    scene.add(dc.RevoluteClearance("bearing", scene.ground, journal, at=(0, 0), bearing_radius=R, clearance=5e-4,
                                   material=dc.Material(young=207e9, poisson=0.3),
                                   wear=ArchardWear(coefficient=1e-14, length=0.02, nodes=16, modes=4),
                                   wear_depth=depth))
    return scene


def _depth(k: int, value: float) -> list[float]:
    out = [0.0] * 16
    out[k] = value
    return out


@pytest.mark.parametrize("depth, words", [
    (_depth(3, 1.0), ["wear_depth[3]=1.0", "must be below 0.0005 m", "bearing radius"]),
    (_depth(5, float("nan")), ["wear_depth[5]=nan", "must be a finite depth >= 0"]),
    (_depth(0, float("inf")), ["wear_depth[0]=inf", "must be a finite depth >= 0"]),
    (_depth(7, -1e-6), ["wear_depth[7]=-1e-06", "must be a finite depth >= 0"]),
])
def test_wear_depth_entries(depth, words):
    with pytest.raises(SceneError) as info:
        flight(depth).validate()
    for word in words:
        assert word in str(info.value)


@pytest.fixture(scope="module")
def worn() -> dc.Scene:
    return dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02)})


@pytest.mark.parametrize("kwargs, error, words", [
    (dict(progress="yes"), SceneError, ["progress='yes'", "must be True or False"]),
    (dict(period=1e-9), SceneError, ["period=1e-09 s", "at least 0.001 of one turn"]),
    (dict(cycles=1e12), SceneError, ["cycles=1e+12", "blocks, must be at most 1e+07", "years", "GB"]),
    (dict(cycles=True), SceneError, ["cycles=True", "finite number > 0"]),
    (dict(options="fast"), SceneError, ["options='fast'", "SolverOptions"]),
    (dict(scene="slider_crank"), SceneError, ["scene='slider_crank'", "Scene or a model"]),
])
def test_simulate_wear_arguments(worn, kwargs, error, words):
    arguments = dict(scene=worn, cycles=2)
    arguments.update(kwargs)
    with pytest.raises(error) as info:
        simulate_wear(arguments.pop("scene"), arguments.pop("cycles"), **arguments)
    for word in words:
        assert word in str(info.value)


def test_simulate_wear_path_is_checked_before_any_work(worn, tmp_path, monkeypatch):
    import daeclear.studies.wear as study

    monkeypatch.setattr(study, "assemble", lambda *a, **k: pytest.fail("assembled before the path was checked"))
    with pytest.raises(OutputError, match="is a directory"):
        simulate_wear(worn, 2, path=tmp_path)
    with pytest.raises(DaeclearError, match="does not exist"):
        simulate_wear(worn, 2, path=tmp_path / "missing" / "wear.h5")


def test_a_resume_must_match_the_scene_and_the_settings(worn, tmp_path):
    """Another length, distribution, mode count or mechanism, or other solver settings: an error naming it."""
    path = tmp_path / "wear.h5"
    simulate_wear(worn, 1, path=path)
    changes = [
        ({"clearance.wear": ArchardWear(coefficient=1e-12, length=0.03)}, "scene.elements.clearance.wear.length=0.02, "
                                                                           "now 0.03"),
        ({"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02, distribution="hertz")},
         "wear.distribution='elastic-foundation', now 'hertz'"),
        ({"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02, modes=40)}, "wear.modes=48, now 40"),
        ({"crank.mass": 0.4}, "scene.elements.crank.mass=0.3, now 0.4"),
    ]
    for values, words in changes:
        with pytest.raises(SceneError, match="another scene or settings") as info:
            simulate_wear(worn.with_values(values), 2, path=path)
        assert words in str(info.value)
    with pytest.raises(SceneError, match=r"options=None, now \{"):
        simulate_wear(worn, 2, path=path, options=dc.SolverOptions(rtol=1e-7))
    for settings, words in ((dict(extrapolate=10), "extrapolate=1, now 10"),
                            (dict(update_every=2), "update_every=1, now 2"),
                            (dict(joint="clearance", period=0.02), "period=0.012, now 0.02")):
        with pytest.raises(SceneError, match="another scene or settings") as info:
            simulate_wear(worn, 20, path=path, **settings)
        assert words in str(info.value)
    resumed = simulate_wear(worn, 2, path=path)  # the same call resumes
    assert resumed.cycles.tolist() == [0.0, 1.0, 2.0]


def test_a_model_is_taken_as_its_scene(worn):
    by_scene = simulate_wear(worn, 2)
    by_model = simulate_wear(dc.assemble(worn), 2)
    np.testing.assert_array_equal(by_model.depth, by_scene.depth)


def test_ctrl_c_keeps_and_returns_the_history(worn, tmp_path, monkeypatch):
    """Ctrl-C in the third block: Interrupted with the two profiles made before it, and the file has them."""
    import daeclear.studies.wear as study

    real, calls = study.block_run, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(study, "block_run", interrupted)
    path = tmp_path / "wear.h5"
    with pytest.raises(Interrupted, match="interrupted by the user at 2 cycles") as info:
        simulate_wear(worn, 5, path=path)
    assert info.value.result.cycles.tolist() == [0.0, 1.0, 2.0]
    assert isinstance(info.value, KeyboardInterrupt)
    monkeypatch.setattr(study, "block_run", real)
    again = simulate_wear(worn, 2, path=path)  # the file has the two cycles: nothing to run
    np.testing.assert_array_equal(again.depth, info.value.result.depth)


@pytest.mark.parametrize("value, words", [
    ("hydrodynamic", ["law='hydrodynamic' needs its numbers", "give a table", "'viscosity': 0.1"]),
    ("{'name': 'hydrodynamic', 'viscosity': 0.1", ["--set law={'name'", "not a Python literal", "never closed"]),
    ("{'name': 'hydrodynamic', 'viscosity': x}", ["not a Python literal", "a bare name"]),
    ("{'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01, 'dry': 'hertzz'}",
     ["dry='hertzz'", "unknown name 'hertzz'"]),
    ("{'viscosity': 0.1}", ["name=None", "must be a law's name"]),
    ("{'name': 'hydrodynamic', 'viscosity': 0.1}", ["missing required parameter(s) length"]),
])
def test_command_line_law_tables(value, words, tmp_path, capsys):
    assert main(["run", "slider_crank", "--joint", "revolute", "--set", f"law={value}", "--t-end", "0.001",
                 "--out", str(tmp_path), "--no-figure", "--quiet"]) != 0
    err = capsys.readouterr().err
    for word in words:
        assert word in err


def test_restitution_given_to_a_lubricated_law():
    law = {"name": "hydrodynamic", "viscosity": 0.1, "length": 0.01}
    for given in (law, HydrodynamicBearing(viscosity=0.1, length=0.01)):
        with pytest.raises(SceneError, match="restitution=0.5, must be left out with a lubricated law"):
            dc.mechanisms.slider_crank("revolute", law=given, restitution=0.5)
    assert math.isfinite(BEARING.film_force(0.5, 10.0, 0.0, R, C)[0])
