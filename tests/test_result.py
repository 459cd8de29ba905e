"""Tests of daeclear.result: Result access, EventList, slicing and the HDF5 round trip."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest

from daeclear.errors import DaeclearError, DaeclearWarning
from daeclear.result import FORMAT_NAME, FORMAT_VERSION, ContactEvent, EventList, Result, load

STATE_NAMES = ["crank.x", "crank.vx", "slider.x", "slider.vx", "lambda.A.x"]


def make_result(n_times: int = 41, seed: int = 0, **overrides: object) -> Result:
    """A Result with random arrays, two events, two segments, steps, nested parameters and stats."""
    rng = np.random.default_rng(seed)
    n_states = len(STATE_NAMES)
    t = np.linspace(0.0, 0.04, n_times)
    events = [
        ContactEvent(t=0.0125, pair="C", kind="onset", approach_speed=0.42, y=rng.standard_normal(n_states)),
        ContactEvent(t=0.0301, pair="C", kind="separation", approach_speed=math.nan,
                     y=rng.standard_normal(n_states)),
    ]
    kwargs: dict[str, object] = dict(
        t=t,
        y=rng.standard_normal((n_times, n_states)),
        yp=rng.standard_normal((n_times, n_states)),
        state_names=STATE_NAMES,
        channels={
            "slider.vx": rng.standard_normal(n_times),
            "slider.vy": rng.standard_normal(n_times),
            "motor.moment": rng.standard_normal(n_times),
            "C.in_contact": rng.integers(0, 2, n_times).astype(bool),
            "C.point": rng.standard_normal((n_times, 2)),
        },
        units={"slider.vx": "m/s", "slider.vy": "m/s", "motor.moment": "N m", "crank.x": "m",
               "C.point": "m"},
        events=events,
        segments=[(0.0, 0.0125, {"C": "free"}), (0.0125, 0.0301, {"C": "contact"}),
                  (0.0301, 0.04, {"C": "free"})],
        step_t=np.sort(rng.uniform(0.0, 0.04, 57)),
        step_h=rng.uniform(1e-6, 1e-3, 57),
        step_order=rng.integers(1, 6, 57),
        stats={"n_steps": 57, "n_res_evals": 321, "n_jac_evals": 12, "n_events": 2, "n_restarts": 2,
               "setup_time": 0.125, "solve_time": 0.5},
        success=True,
        status=0,
        message="reached t_end",
        parameters={
            "scene": {"name": "slider_crank", "clearance": 0.5e-3,
                      "C": {"law": "LankaraniNikravesh", "restitution": 0.9, "friction": False}},
            "simulate": {"rtol": 1e-6, "atol": [1e-8, 1e-6], "t_end": 0.04, "max_order": 5,
                         "dense": True, "names": ["a", "b"], "nothing": None},
            "seed": 7,
            "label": "round trip",
        },
        scene_name="slider_crank",
        method="ida",
        formulation="index1",
    )
    kwargs.update(overrides)
    return Result(**kwargs)  # type: ignore[arg-type]


def assert_results_equal(a: Result, b: Result) -> None:
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.y, b.y)
    np.testing.assert_array_equal(a.yp, b.yp)
    assert a.state_names == b.state_names
    assert a.channel_names == b.channel_names
    for name in a.channel_names:
        np.testing.assert_array_equal(a[name], b[name])
        assert a[name].dtype == b[name].dtype, name
    assert a.units == b.units
    assert len(a.events) == len(b.events)
    assert a.events == b.events
    assert a.segments == b.segments
    for field in ("step_t", "step_h", "step_order"):
        x, y = getattr(a, field), getattr(b, field)
        assert (x is None) == (y is None), field
        if x is not None:
            np.testing.assert_array_equal(x, y)
            assert x.dtype == y.dtype
    assert a.stats == b.stats
    assert a.parameters == b.parameters
    assert (a.success, a.status, a.message) == (b.success, b.status, b.message)
    assert (a.scene_name, a.method, a.formulation) == (b.scene_name, b.method, b.formulation)


# ----------------------------------------------------------------------------- round trip


def test_round_trip_keeps_every_field(tmp_path: Path) -> None:
    result = make_result()
    path = result.save(tmp_path / "run.h5")
    assert path == tmp_path / "run.h5"
    loaded = load(path)
    assert_results_equal(result, loaded)
    # spot checks independent of the helper, so a helper bug cannot hide a loss
    assert loaded.units["slider.vx"] == "m/s"
    assert loaded.units["crank.vx"] == ""  # no unit given: empty string
    assert loaded.parameters["simulate"]["atol"] == [1e-8, 1e-6]
    assert loaded.parameters["simulate"]["dense"] is True
    assert loaded.parameters["simulate"]["nothing"] is None
    assert loaded.parameters["scene"]["C"]["restitution"] == 0.9
    assert isinstance(loaded.stats["n_steps"], int) and loaded.stats["n_steps"] == 57
    assert loaded.events[0].kind == "onset" and loaded.events[0].approach_speed == 0.42
    assert math.isnan(loaded.events[1].approach_speed)
    assert loaded.segments[1] == (0.0125, 0.0301, {"C": "contact"})
    assert loaded["C.point"].shape == (41, 2)


def test_round_trip_of_failed_minimal_run(tmp_path: Path) -> None:
    """A failed run with one output time, no events, segments, steps or parameters still saves."""
    result = Result(t=[0.0], y=np.zeros((1, 2)), yp=np.ones((1, 2)), state_names=["b.x", "b.vx"],
                    channels={}, units={}, success=False, status=-1, message="IDA_CONV_FAIL at t=0")
    loaded = load(result.save(tmp_path / "failed.h5"))
    assert_results_equal(result, loaded)
    assert loaded.step_t is None and len(loaded.events) == 0 and loaded.segments == []
    assert loaded.success is False and loaded.status == -1


def test_file_layout_is_readable_by_plain_h5py(tmp_path: Path) -> None:
    n = 20000  # above the compression threshold
    force = np.zeros(n)
    force[100:200] = 1.0e3
    result = make_result(n_times=n, channels={"C.force_n": force, "C.mode": np.zeros(n, dtype=np.int8)},
                         units={"crank.x": "m", "C.force_n": "N"}, events=[])
    path = result.save(tmp_path / "run.h5")
    assert_results_equal(result, load(path))
    with h5py.File(path, "r") as f:
        assert f.attrs["format"] == FORMAT_NAME and f.attrs["version"] == FORMAT_VERSION
        assert f["channels/C.force_n"].attrs["units"] == "N"
        assert f["t"].attrs["units"] == "s"
        # cheap to compress: mostly-zero forces and integer modes; general floats are not
        assert f["channels/C.force_n"].compression == "gzip"
        assert f["channels/C.mode"].compression == "gzip"
        assert f["y"].compression is None and f["t"].compression is None
        assert f["events/y"].shape == (0, len(STATE_NAMES))
        assert f["segments/t_start"].shape == (3,)
        np.testing.assert_array_equal(f["steps/order"][()], result.step_order)
        # parameters mirrored as groups and attributes
        assert f["parameters"].attrs["seed"] == 7
        assert f["parameters"].attrs["label"] == "round trip"
        assert f["parameters/simulate"].attrs["rtol"] == 1e-6
        np.testing.assert_array_equal(f["parameters/simulate"].attrs["atol"], [1e-8, 1e-6])
        assert f["parameters/scene/C"].attrs["friction"] == False  # noqa: E712  (numpy bool)
        assert f["stats"].attrs["n_restarts"] == 2


# ----------------------------------------------------------------------------- atomic save


def test_event_table_in_file(tmp_path: Path) -> None:
    path = make_result().save(tmp_path / "run.h5")
    with h5py.File(path, "r") as f:
        assert f["events/y"].shape == (2, len(STATE_NAMES))
        assert list(f["events/kind"].asstr()[()]) == ["onset", "separation"]
        assert list(f["events/pair"].asstr()[()]) == ["C", "C"]
        assert f["channels/slider.vx"].attrs["units"] == "m/s"


def test_save_replaces_existing_file(tmp_path: Path) -> None:
    path = tmp_path / "run.h5"
    make_result(seed=1).save(path)
    second = make_result(seed=2, message="second")
    second.save(path)
    assert_results_equal(second, load(path))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]


@pytest.mark.parametrize("exc", [OSError("disk full"), KeyboardInterrupt()])
def test_failed_save_leaves_old_file_and_no_temp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                  exc: BaseException) -> None:
    path = tmp_path / "run.h5"
    old = make_result(seed=1)
    old.save(path)
    before = path.read_bytes()

    real_create = h5py.Group.create_dataset
    calls: list[str] = []

    def failing_create(self: h5py.Group, name: str, *args: object, **kwargs: object) -> h5py.Dataset:
        calls.append(name)
        if name == "yp":  # after /t and /y have been written
            raise exc
        return real_create(self, name, *args, **kwargs)

    monkeypatch.setattr(h5py.Group, "create_dataset", failing_create)
    with pytest.raises(type(exc)):
        make_result(seed=2).save(path)
    monkeypatch.undo()

    assert "y" in calls  # the write really was under way
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.h5"]
    assert_results_equal(old, load(path))


def test_save_into_missing_directory(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="does not exist"):
        make_result().save(tmp_path / "nowhere" / "run.h5")


# ----------------------------------------------------------------------------- load errors


def test_load_rejects_foreign_hdf5(tmp_path: Path) -> None:
    path = tmp_path / "foreign.h5"
    with h5py.File(path, "w") as f:
        f["t"] = np.arange(3.0)
    with pytest.raises(DaeclearError, match=r"foreign\.h5.*not a daeclear result.*'format'"):
        load(path)


def test_load_rejects_non_hdf5(tmp_path: Path) -> None:
    path = tmp_path / "notes.h5"
    path.write_text("not hdf5")
    with pytest.raises(DaeclearError, match=r"notes\.h5.*cannot be opened as HDF5"):
        load(path)


def test_load_names_missing_item(tmp_path: Path) -> None:
    path = make_result().save(tmp_path / "run.h5")
    with h5py.File(path, "a") as f:
        del f["events/y"]
    with pytest.raises(DaeclearError, match=r"run\.h5.*'/events/y' is missing"):
        load(path)


def test_load_rejects_newer_version(tmp_path: Path) -> None:
    path = make_result().save(tmp_path / "run.h5")
    with h5py.File(path, "a") as f:
        f.attrs["version"] = FORMAT_VERSION + 1
    with pytest.raises(DaeclearError, match="version 2"):
        load(path)


def test_load_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="missing.h5"):
        load(tmp_path / "missing.h5")


# ----------------------------------------------------------------------------- access


def test_getitem_channels_and_states() -> None:
    result = make_result()
    np.testing.assert_array_equal(result["slider.vx"], result.channels["slider.vx"])
    np.testing.assert_array_equal(result["crank.vx"], result.y[:, 1])
    assert "slider.vx" in result and "lambda.A.x" in result
    assert "slider.v" not in result and 3 not in result
    assert result.channel_names == ["C.in_contact", "C.point", "motor.moment", "slider.vx", "slider.vy"]
    assert result.units["motor.moment"] == "N m"


def test_unknown_name_lists_close_matches() -> None:
    result = make_result()
    with pytest.raises(KeyError) as info:
        result["slider.v"]
    assert str(info.value) == "no channel 'slider.v'. Close matches: 'slider.vx', 'slider.vy', 'slider.x'."
    with pytest.raises(KeyError, match="no channel 'zzz'. See result.channel_names"):
        result["zzz"]


def test_arrays_are_read_only_and_caller_arrays_untouched() -> None:
    y = np.zeros((3, 1))
    result = Result(t=[0.0, 1.0, 2.0], y=y, yp=y, state_names=["a.x"], channels={}, units={})
    with pytest.raises(ValueError):
        result.y[0, 0] = 1.0
    y[0, 0] = 2.0  # the caller's array stays writeable
    assert y.flags.writeable


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"y": np.zeros((3, 5))}, r"y has shape \(3, 5\), expected"),
        ({"channels": {"slider.vx": np.zeros(7)}}, "channel 'slider.vx' has shape"),
        ({"channels": {"a/b": np.zeros(41)}}, "channel name 'a/b' is invalid"),
        ({"units": {"slider.vz": "m/s"}}, "neither a channel nor a state"),
        ({"status": 2}, "status=2"),
        ({"success": True, "status": -1}, "contradicts"),
        ({"step_h": None}, "together"),
        ({"t": np.linspace(0.04, 0.0, 41)}, "non-decreasing"),
    ],
)
def test_inconsistent_input_raises(overrides: dict[str, object], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        make_result(**overrides)


def test_odd_parameter_values_are_kept_not_fatal(tmp_path: Path) -> None:
    @dataclass(frozen=True)
    class Material:
        young: float
        poisson: float

    class Law:
        def __repr__(self) -> str:
            return "Law(restitution=0.9)"

    with pytest.warns(DaeclearWarning, match=r"parameters\['scene'\]\['law'\]: a Law .*'Law\(restitution=0.9\)'"):
        result = make_result(parameters={"scene": {"material": Material(207e9, 0.3), "law": Law()}})
    assert result.parameters == {"scene": {"material": {"young": 207e9, "poisson": 0.3},
                                           "law": "Law(restitution=0.9)"}}
    assert load(result.save(tmp_path / "run.h5")).parameters == result.parameters
    with pytest.raises(TypeError, match=r"parameters\['scene'\]: key 1 is a int"):
        make_result(parameters={"scene": {1: "x"}})


def test_numpy_values_in_parameters_become_plain() -> None:
    result = make_result(parameters={"rtol": np.float64(1e-6), "n": np.int64(3), "v": np.array([1.0, 2.0]),
                                     "flag": np.bool_(True), "pair": (1, 2)})
    assert result.parameters == {"rtol": 1e-6, "n": 3, "v": [1.0, 2.0], "flag": True, "pair": [1, 2]}
    assert type(result.parameters["n"]) is int and type(result.parameters["flag"]) is bool


# ----------------------------------------------------------------------------- events


def test_event_list_filters_and_fields() -> None:
    y = np.zeros(2)
    events = EventList([
        ContactEvent(0.1, "clearance.A_upper", "onset", 0.3, y),
        ContactEvent(0.2, "clearance.A_upper", "separation", math.nan, y),
        ContactEvent(0.3, "clearance.B_lower", "onset", 0.1, y),
        ContactEvent(0.4, "clearance2", "onset", 0.2, y),
        ContactEvent(0.5, "C", "onset", 0.5, y),
    ])
    onsets = events.of(kind="onset")
    np.testing.assert_array_equal(onsets.t, [0.1, 0.3, 0.4, 0.5])
    np.testing.assert_array_equal(onsets.approach_speed, [0.3, 0.1, 0.2, 0.5])
    assert events.of("clearance").pair == ["clearance.A_upper", "clearance.A_upper", "clearance.B_lower"]
    assert events.of("clearance.A_upper", kind="separation").kind == ["separation"]
    assert events.of("C").t.tolist() == [0.5]
    assert len(events.of("D")) == 0 and events.of("D").t.shape == (0,)
    assert isinstance(events[1:3], EventList) and len(events[1:3]) == 2
    assert events[0].pair == "clearance.A_upper"
    with pytest.raises(ValueError, match="kind='impact'"):
        events.of(kind="impact")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="kind='impact'"):
        ContactEvent(0.0, "C", "impact", 0.0, y)  # type: ignore[arg-type]


def test_result_events_of_pair() -> None:
    result = make_result()
    np.testing.assert_array_equal(result.events.of("C", kind="onset").t, [0.0125])
    np.testing.assert_array_equal(result.events.t, [0.0125, 0.0301])


# ----------------------------------------------------------------------------- windows


def test_slice_keeps_consistency() -> None:
    result = make_result()
    part = result.slice(0.01, 0.02)
    mask = (result.t >= 0.01) & (result.t <= 0.02)
    assert part.n_times == mask.sum() > 0
    np.testing.assert_array_equal(part.window_mask(), np.ones(part.n_times, dtype=bool))
    np.testing.assert_array_equal(part.t, result.t[mask])
    np.testing.assert_array_equal(part.y, result.y[mask])
    np.testing.assert_array_equal(part.yp, result.yp[mask])
    for name in result.channel_names:
        assert part[name].shape[0] == part.n_times
        np.testing.assert_array_equal(part[name], result[name][mask])
    assert part.events.t.tolist() == [0.0125]  # the separation at 0.0301 is outside
    assert part.segments == [(0.01, 0.0125, {"C": "free"}), (0.0125, 0.02, {"C": "contact"})]
    assert part.step_t is not None and np.all((part.step_t >= 0.01) & (part.step_t <= 0.02))
    assert len(part.step_t) == len(part.step_h) == len(part.step_order) > 0
    assert part.stats == result.stats and part.parameters == result.parameters
    assert part.units == result.units


def test_window_mask_open_ends_and_errors() -> None:
    result = make_result()
    assert result.window_mask().all()
    np.testing.assert_array_equal(result.window_mask(t1=0.01), result.t <= 0.01)
    assert result.slice(1.0, 2.0).n_times == 0
    with pytest.raises(ValueError, match="t0=0.02 > t1=0.01"):
        result.window_mask(0.02, 0.01)


def test_to_dict_rebuilds() -> None:
    result = make_result()
    assert_results_equal(result, Result(**result.to_dict()))


# ----------------------------------------------------------------------------- summary


def test_summary() -> None:
    text = str(make_result())
    assert "success: True" in text
    assert "2 events (1 onset, 1 separation)" in text
    assert "slider_crank" in text and "41 output times" in text and "wall time: 0.625 s" in text
    assert repr(make_result()) == text
    failed = str(make_result(success=False, status=-1, message="IDA_CONV_FAIL", events=[]))
    assert "success: False" in failed and "0 events" in failed and "IDA_CONV_FAIL" in failed
