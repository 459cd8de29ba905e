"""Every tool takes lubricated and worn joints (issue 44, item 5): results saved, streamed and read
back with every channel and event; sweeps and the command line over their numbers compile nothing."""

from __future__ import annotations

import numpy as np
import pytest

import daeclear as dc
from daeclear.contact import HydrodynamicBearing
from daeclear.contact.wear import ArchardWear


def worn_scene() -> dc.Scene:
    scene = dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-13, length=0.02)})
    depth = 1e-5 * np.exp(-((np.arange(360) - 90) / 20.0) ** 2)  # a worn spot at 90 degrees
    return scene.with_values({"clearance.wear_depth": tuple(depth.tolist())})


def lubricated_scene() -> dc.Scene:
    return dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(viscosity=1e-3, length=0.01))


@pytest.mark.parametrize("make", [worn_scene, lubricated_scene])
def test_saved_and_streamed_runs_read_back_whole(make, tmp_path):
    scene = make()
    run = dc.simulate(scene, 0.004)
    assert len(run.events) > 2
    run.save(tmp_path / "saved.h5")
    dc.simulate(scene, 0.004, save=dc.SaveAt(stream_to=tmp_path / "streamed.h5"))
    for path in ("saved.h5", "streamed.h5"):
        back = dc.load(tmp_path / path)
        assert back.channel_names == run.channel_names
        np.testing.assert_array_equal(back.t, run.t)
        for name in run.channel_names:
            np.testing.assert_array_equal(back[name], run[name], err_msg=f"{path}: {name}")
        assert [(e.t, e.pair, e.kind) for e in back.events] == [(e.t, e.pair, e.kind) for e in run.events]
        joint = back.parameters["scene"]["elements"]["clearance"]
        assert joint["law"] == run.parameters["scene"]["elements"]["clearance"]["law"]


SWEPT = [  # (scene maker, swept name, two values): the numbers item 5 of issue 44 names
    (lubricated_scene, "clearance.law.viscosity", (0.01, 0.1)),
    (lubricated_scene, "clearance.law.length", (0.008, 0.012)),
    (lubricated_scene, "clearance.law.roughness", (0.5e-6, 2e-6)),
    (lubricated_scene, "clearance.law.film_parameter", (1.0, 2.0)),
    (lubricated_scene, "clearance.law.hysteresis", (0.5, 1.5)),
    (lubricated_scene, "clearance.law.dry.restitution", (0.5, 0.8)),
    (worn_scene, "clearance.wear.coefficient", (1e-14, 1e-12)),
    (worn_scene, "clearance.wear_depth", (tuple([0.0] * 360), tuple([1e-6] * 360))),
]


@pytest.mark.parametrize("make, name, values", SWEPT, ids=[s[1] for s in SWEPT])
def test_sweep_points_over_oil_and_wear_numbers_share_one_compiled_model(make, name, values):
    """A sweep's points (built as its workers build them) differ only in numbers: one model, new numbers."""
    from daeclear.studies.sweep_workers import build_scene

    law = {"name": "hydrodynamic", "viscosity": 1e-3, "length": 0.01}
    fixed = ({"joint": "revolute", "law": law} if make is lubricated_scene else  # tables, as --set gives them
             {"joint": "revolute", "friction": 0.1, "clearance.wear": {"coefficient": 1e-13, "length": 0.02}})
    models = [dc.assemble(build_scene("slider_crank", {**fixed, name: value})) for value in values]
    assert models[1].scene[name.split(".")[0]] != models[0].scene[name.split(".")[0]]
    assert models[0].functions is models[1].functions
    base = dc.assemble(make())
    reused = base.with_parameters({name: values[1]})  # the same name in the one name space
    assert reused.functions is base.functions


def test_a_viscosity_sweep_from_the_command_line_compiles_nothing(tmp_path):
    from daeclear.cli import main
    from daeclear.engine.build import cache_dir
    from daeclear.studies.sweep import load_sweep

    law = "law={'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01}"
    dc.assemble(dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(viscosity=0.1, length=0.01)))
    libraries = sorted(cache_dir().glob("*.so"))  # the structure is built (or was): the sweep adds none
    out = tmp_path / "viscosity.h5"
    assert main(["sweep", "slider_crank", str(out), "--joint", "revolute", "--set", law, "--grid",
                 "clearance.law.viscosity=0.01,0.03,0.1", "--revolutions", "2", "--transient", "1", "--workers", "1",
                 "--no-figure", "--quiet"]) == 0
    assert sorted(cache_dir().glob("*.so")) == libraries
    records = load_sweep(out).runs
    assert [r.parameters["clearance.law.viscosity"] for r in records] == [0.01, 0.03, 0.1]
    assert all(r.ok for r in records)


def test_the_command_line_figure_of_a_lubricated_joint(tmp_path):
    """daeclear run's figure of a lubricated joint: the film force and the eccentricity ratio beside the dry
    force, and a title naming the oil's viscosity, the bearing's length and the theory."""
    from daeclear.cli import main
    from daeclear.plot.figures import default_channels
    from daeclear.plot.style import caption

    law = "law={'name': 'hydrodynamic', 'viscosity': 0.1, 'length': 0.01, 'theory': 'long'}"
    assert main(["run", "slider_crank", "--joint", "revolute", "--set", law, "--t-end", "0.003", "--out",
                 str(tmp_path), "--quiet"]) == 0
    assert (tmp_path / "slider_crank_revolute.png").stat().st_size > 20_000
    result = dc.load(tmp_path / "slider_crank_revolute.h5")
    channels = default_channels(result)
    assert {"clearance.film_radial", "clearance.normal_force", "clearance.eccentricity_ratio"} <= set(channels)
    assert "oil $\\mu$ = 0.1 Pa s, L = 10 mm, long bearing" in caption(result)
    dry = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.001)
    assert "clearance.film_radial" not in default_channels(dry) and "Lankarani" in caption(dry)
