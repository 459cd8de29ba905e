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
