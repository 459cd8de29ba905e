"""Tests of daeclear.results.result: Result access, EventList, slicing and the HDF5 round trip."""

from __future__ import annotations

import json
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest

from daeclear.core.errors import DaeclearError, DaeclearWarning, MissingDependencyError
from daeclear.results.result import FORMAT_NAME, FORMAT_VERSION, ContactEvent, EventList, Result, load
from daeclear.core.values import to_plain

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
    with pytest.raises(DaeclearError, match=f"version {FORMAT_VERSION + 1}"):
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


def test_unknown_name_listsclose_matches() -> None:
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
    # deeper: list indices and a dataclass's fields are named on the way down
    with pytest.warns(DaeclearWarning, match=r"parameters\['a'\]\[1\]\['m'\]\['young'\]: a Law "):
        nested = make_result(parameters={"a": [0.5, {"m": Material(Law(), 0.3)}]})
    assert nested.parameters == {"a": [0.5, {"m": {"young": "Law(restitution=0.9)", "poisson": 0.3}}]}
    with pytest.raises(TypeError, match=r"parameters\['a'\]\[0\]: key 2.0 is a float"):
        make_result(parameters={"a": [{2.0: "x"}]})


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


def test_event_blocks_read_as_the_events_they_hold() -> None:
    """A solver's events given as ContactEvents and column blocks (the compiled loop's EventRows) read
    as one EventList in their order; a block makes its events only when read, with read-only states;
    the recorder counts every event of a block."""
    from daeclear.core.events import EventRows, flatten
    from daeclear.solvers.recorder import Recorder

    ys = np.arange(6.0).reshape(3, 2)
    ys.flags.writeable = False
    block = EventRows([0.2, 0.3, 0.3], ["C", "C", "D"], ["onset", "separation", "onset"], [0.5, math.nan, 0.1], ys)
    first = ContactEvent(0.1, "C", "separation", math.nan, np.zeros(2))
    assert len(block) == 3 and block._made is None  # nothing made by asking the length
    events = EventList.of_parts([first, block, ContactEvent(0.4, "D", "separation", math.nan, np.ones(2))])
    expected = [first, *(ContactEvent(t, p, k, a, y) for t, p, k, a, y in
                         zip([0.2, 0.3, 0.3], "CCD", ["onset", "separation", "onset"], [0.5, math.nan, 0.1], ys))]
    assert list(events)[:4] == expected and len(events) == 5 and events.t.tolist() == [0.1, 0.2, 0.3, 0.3, 0.4]
    assert events.of("D").kind == ["onset", "separation"] and events[2].y.tolist() == [2.0, 3.0]
    assert not events[1].y.flags.writeable and events[1:3] == expected[1:3]
    assert flatten([block, first]) == [*expected[1:], first]

    class _Model:
        state_names, channel_units, scene_name, formulation, n_states = ("a", "b"), {}, "s", "ggl", 2

    rec = Recorder(_Model(), parameters={}, method="ida")
    rec.events.append(first)
    rec.add_event_rows(block)
    assert rec.n_events == 4


def test_events_of_the_compiled_loop_equal_the_checked_constructor() -> None:
    """The compiled loop's columns of events make the same events as the constructor: equal fields, a
    float time and speed, and a state that cannot be changed through the event."""
    from daeclear.core.events import EventRows

    y = np.array([[1.0, 2.0, 3.0]])
    y.flags.writeable = False
    (made,) = EventRows([np.float64(0.25)], ["C"], ["onset"], [np.float64(0.5)], y)
    checked = ContactEvent(t=0.25, pair="C", kind="onset", approach_speed=0.5, y=y[0].copy())
    assert made == checked and repr(made) == repr(checked)
    assert type(made.t) is float and type(made.approach_speed) is float
    with pytest.raises(ValueError, match="read-only"):
        made.y[0] = 9.0
    with pytest.raises(AttributeError):
        made.t = 1.0  # type: ignore[misc]


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
    with pytest.raises(ValueError, match=r"t0=0.02 s, must be <= t1=0.01 s"):
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


# ----------------------------------------------------------------------------- hand-off: pandas, xarray


def test_to_pandas_keeps_values_units_and_dtypes() -> None:
    pytest.importorskip("pandas")
    result = make_result()
    df = result.to_pandas()
    assert df.index.name == "t"
    np.testing.assert_array_equal(df.index.to_numpy(), result.t)
    one_dim = [n for n in result.channel_names if result[n].ndim == 1]
    assert set(df.columns) == {*one_dim, "C.point[0]", "C.point[1]"}
    for name in one_dim:
        np.testing.assert_array_equal(df[name].to_numpy(), result[name])
        assert df[name].dtype == result[name].dtype, name
        assert df.attrs["units"][name] == result.units[name]
    np.testing.assert_array_equal(df["C.point[1]"].to_numpy(), result["C.point"][:, 1])
    assert df.attrs["units"]["C.point[0]"] == "m" and df.attrs["units"]["t"] == "s"
    assert df.attrs["scene_name"] == "slider_crank" and df.attrs["method"] == "ida"
    # a copy: editing the frame leaves the result alone
    df.iloc[0, 0] = not df.iloc[0, 0] if df.dtypes.iloc[0].kind == "b" else df.iloc[0, 0] + 1
    assert result[df.columns[0]][0] != df.iloc[0, 0]


def test_to_pandas_with_states_adds_state_columns() -> None:
    pytest.importorskip("pandas")
    result = make_result(channels={"slider.vx": np.arange(41.0)}, units={"slider.vx": "m/s", "crank.x": "m"})
    df = result.to_pandas(states=True)
    assert list(df.columns) == ["slider.vx", "crank.x", "crank.vx", "slider.x", "lambda.A.x"]
    np.testing.assert_array_equal(df["slider.vx"].to_numpy(), np.arange(41.0))  # the channel wins
    np.testing.assert_array_equal(df["lambda.A.x"].to_numpy(), result["lambda.A.x"])
    assert df.attrs["units"]["crank.x"] == "m"


def test_events_frame_matches_events() -> None:
    pytest.importorskip("pandas")
    result = make_result()
    ev = result.events_frame(states=True)
    assert list(ev.columns[:4]) == ["t", "pair", "kind", "approach_speed"]
    np.testing.assert_array_equal(ev["t"].to_numpy(), result.events.t)
    assert list(ev["pair"]) == result.events.pair and list(ev["kind"]) == result.events.kind
    np.testing.assert_array_equal(ev["approach_speed"].to_numpy(), result.events.approach_speed)
    np.testing.assert_array_equal(ev[[f"y:{n}" for n in STATE_NAMES]].to_numpy(), [e.y for e in result.events])
    assert ev.attrs["units"]["approach_speed"] == "m/s"
    empty = make_result(events=[]).events_frame()
    assert len(empty) == 0 and list(empty.columns) == ["t", "pair", "kind", "approach_speed"]


def test_to_xarray_keeps_values_units_events_and_attributes() -> None:
    pytest.importorskip("xarray")
    result = make_result()
    ds = result.to_xarray()
    np.testing.assert_array_equal(ds["t"].to_numpy(), result.t)
    assert ds["t"].attrs["units"] == "s"
    for name in result.channel_names:
        np.testing.assert_array_equal(ds[name].to_numpy(), result[name])
        assert ds[name].dtype == result[name].dtype
        assert ds[name].attrs["units"] == result.units[name]
        assert ds[name].dims[0] == "t"
    assert ds["C.point"].dims == ("t", "C.point_dim_1")
    np.testing.assert_array_equal(ds["y"].to_numpy(), result.y)
    assert list(ds["state"].to_numpy()) == STATE_NAMES
    assert list(ds["state_units"].to_numpy()) == [result.units[n] for n in STATE_NAMES]
    assert ds.sizes["event"] == 2
    np.testing.assert_array_equal(ds["event_t"].to_numpy(), result.events.t)
    assert list(ds["event_pair"].to_numpy()) == result.events.pair
    assert list(ds["event_kind"].to_numpy()) == result.events.kind
    np.testing.assert_array_equal(ds["event_approach_speed"].to_numpy(), result.events.approach_speed)
    np.testing.assert_array_equal(ds["event_y"].to_numpy(), [e.y for e in result.events])
    assert [json.loads(m) for m in ds["segment_modes"].to_numpy()] == [s[2] for s in result.segments]
    assert ds.attrs["scene_name"] == "slider_crank" and ds.attrs["formulation"] == "index1"
    assert ds.attrs["success"] == 1 and ds.attrs["stats.n_steps"] == 57
    assert json.loads(ds.attrs["parameters_json"]) == result.parameters
    assert json.loads(ds.attrs["stats_json"]) == result.stats
    assert "y" not in result.to_xarray(states=False)


def test_to_xarray_writes_netcdf(tmp_path: Path) -> None:
    """The Dataset's attributes are netCDF-safe: it writes and reads back with units and events."""
    xr = pytest.importorskip("xarray")
    result = make_result(channels={"slider.vx": np.linspace(0.0, 1.0, 41)}, units={"slider.vx": "m/s"})
    try:
        result.to_xarray().to_netcdf(tmp_path / "run.nc")
    except (ImportError, ValueError) as exc:  # no netCDF backend installed
        pytest.skip(f"no netCDF backend: {exc}")
    with xr.open_dataset(tmp_path / "run.nc") as back:
        np.testing.assert_array_equal(back["slider.vx"].to_numpy(), result["slider.vx"])
        assert back["slider.vx"].attrs["units"] == "m/s"
        assert list(back["event_kind"].to_numpy()) == result.events.kind



def test_hand_off_of_a_loaded_file_equals_hand_off_of_the_result(tmp_path: Path) -> None:
    """Save, load, convert: the same frame and Dataset as converting the result directly."""
    pd = pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    result = make_result()
    loaded = load(result.save(tmp_path / "run.h5"))
    pd.testing.assert_frame_equal(loaded.to_pandas(states=True), result.to_pandas(states=True))
    pd.testing.assert_frame_equal(loaded.events_frame(), result.events_frame())
    assert loaded.to_xarray().identical(result.to_xarray())


def test_hand_off_keeps_a_repeated_event_time() -> None:
    """A restart repeats its time (state before and after): both rows survive, in order."""
    pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    t = np.linspace(0.0, 0.04, 41)
    t[10] = t[9]
    result = make_result(t=t)
    df = result.to_pandas()
    assert len(df) == 41 and not df.index.is_unique
    np.testing.assert_array_equal(df["slider.vx"].to_numpy()[9:11], result["slider.vx"][9:11])
    ds = result.to_xarray()
    assert ds.sizes["t"] == 41
    np.testing.assert_array_equal(ds["slider.vx"].isel(t=[9, 10]).to_numpy(), result["slider.vx"][9:11])

@pytest.mark.parametrize(("method", "module"), [("to_pandas", "pandas"), ("events_frame", "pandas"),
                                                ("to_xarray", "xarray")])
def test_missing_optional_dependency_names_the_extra(monkeypatch: pytest.MonkeyPatch, method: str,
                                                     module: str) -> None:
    monkeypatch.setitem(sys.modules, module, None)  # makes `import module` raise ImportError
    with pytest.raises(ImportError, match=r'daeclear\[data\]') as info:
        getattr(make_result(), method)()
    assert isinstance(info.value, MissingDependencyError)
    assert module in str(info.value) and f"Result.{method}" in str(info.value)


# ----------------------------------------------------------------------------- the documented HDF5 layout

LAYOUT_DOC = Path(__file__).resolve().parents[1] / "docs" / "hdf5_layout.md"
#: items of a run's file only: each point's switch vector and the names of the channels computed when read
STATES_ONLY = {"/switch", "/channel_names", "/channel_units"}
#: items of a run with sensitivities only (simulate(..., sensitivities=...))
SENSITIVITIES = {"/sensitivities", "/sensitivities/names", "/sensitivities/values",
                 "/sensitivities/states", "/sensitivities/channel_names",
                 "/sensitivities/channels", "/sensitivities/events", "/sensitivities/events/t",
                 "/sensitivities/events/pair", "/sensitivities/events/kind", "/sensitivities/events/dt_dp",
                 "/sensitivities/sides", *(f"/sensitivities/sides/{name}" for name in ("t", "y", "values", "states",
                                                                                      "channels")),
                 "/sensitivities/integrals", *(f"/sensitivities/integrals/{name}" for name in ("names", "Q", "dQ"))}


def _documented_items() -> list[tuple[str, bool]]:
    """(item, optional) for every table row of docs/hdf5_layout.md's result file (before the wear history
    file's section, tests/test_wear_file.py) whose first cell is `/...`."""
    items = []
    text = LAYOUT_DOC.read_text(encoding="utf-8").split("\n## The wear history file")[0]
    for line in text.splitlines():
        m = re.match(r"\|\s*`(/[^`]*)`\s*\|([^|]*)\|", line)
        if m:
            items.append((m.group(1), "optional" in m.group(2)))
    return items


def _item_pattern(item: str) -> re.Pattern[str]:
    text = re.escape(item).replace(re.escape("<name>"), r"[^/@]+").replace(re.escape("/**"), r"(?:[/@].*)?")
    return re.compile(text + r"\Z")


def _file_items(f: h5py.File) -> list[str]:
    """Every object ("/t") and attribute ("/t@units", "/@format") of an HDF5 file."""
    items = [f"/@{a}" for a in f.attrs]

    def visit(name: str, obj: h5py.HLObject) -> None:
        items.append(f"/{name}")
        items.extend(f"/{name}@{a}" for a in obj.attrs)

    f.visititems(visit)
    return items


def test_hdf5_layout_document_lists_every_item_and_only_those(tmp_path: Path) -> None:
    documented = _documented_items()
    assert len(documented) > 30
    patterns = [(_item_pattern(item), item, optional) for item, optional in documented]
    path = make_result().save(tmp_path / "run.h5")
    with h5py.File(path, "r") as f:
        in_file = _file_items(f)
    undocumented = [i for i in in_file if not any(p.match(i) for p, _, _ in patterns)]
    assert not undocumented, f"items written by Result.save but missing from {LAYOUT_DOC.name}: {undocumented}"
    # a result built from arrays stores yp and its channels, not a run's switch rows (STATES_ONLY)
    absent = [item for p, item, _ in patterns
              if not any(p.match(i) for i in in_file) and item not in STATES_ONLY | SENSITIVITIES]
    assert not absent, f"items in {LAYOUT_DOC.name} that Result.save does not write: {absent}"
    # the optional items are the steps, which a result without recorded steps lacks
    path = make_result(step_t=None, step_h=None, step_order=None).save(tmp_path / "no_steps.h5")
    with h5py.File(path, "r") as f:
        in_file = _file_items(f)
    absent = {item for p, item, _ in patterns if not any(p.match(i) for i in in_file)} - STATES_ONLY - SENSITIVITIES
    assert absent == {"/steps", "/steps/t", "/steps/h", "/steps/order"}
    assert {item for item, optional in documented if optional} - STATES_ONLY - SENSITIVITIES - {"/yp"} == {"/steps"}
    assert SENSITIVITIES <= {item for item, optional in documented if optional}
    # a run's file: its states and switch rows, its channels and yp computed when read
    import daeclear as dc

    run = dc.simulate(dc.mechanisms.slider_crank("revolute"), t_end=0.002)
    with h5py.File(run.save(tmp_path / "run_states.h5"), "r") as f:
        in_file = _file_items(f)
    undocumented = [i for i in in_file if not any(p.match(i) for p, _, _ in patterns)]
    assert not undocumented, f"items of a run's file missing from {LAYOUT_DOC.name}: {undocumented}"
    absent = {item for p, item, _ in patterns if not any(p.match(i) for i in in_file)}
    assert absent == {"/yp", "/channels/<name>", "/channels/<name>@units"} | SENSITIVITIES
    assert STATES_ONLY <= {item for item, optional in documented if optional}
    # a run with sensitivities: every item of its file documented, and the sensitivities' items all present
    run = dc.simulate(dc.mechanisms.slider_crank("revolute"), t_end=0.4e-3, sensitivities=["clearance.clearance"])
    with h5py.File(run.save(tmp_path / "run_sensitivities.h5"), "r") as f:
        in_file = _file_items(f)
    undocumented = [i for i in in_file if not any(p.match(i) for p, _, _ in patterns)]
    assert not undocumented, f"items of a run's file missing from {LAYOUT_DOC.name}: {undocumented}"
    absent = {item for p, item, _ in patterns if not any(p.match(i) for i in in_file)}
    assert absent == {"/yp", "/channels/<name>", "/channels/<name>@units"}


def test_hdf5_layout_document_snippet_reads_a_file_with_plain_h5py(tmp_path: Path,
                                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    text = LAYOUT_DOC.read_text(encoding="utf-8")
    snippet = re.search(r"## Reading with h5py\s.*?```python\n(import json\n.*?)```", text, re.S)
    assert snippet, "the h5py snippet of docs/hdf5_layout.md was not found"
    result = make_result()
    result.save(tmp_path / "run.h5")
    monkeypatch.chdir(tmp_path)
    ns: dict[str, object] = {}
    exec(compile(snippet.group(1), str(LAYOUT_DOC), "exec"), ns)  # the document's code, as written
    np.testing.assert_array_equal(ns["t"], result.t)
    np.testing.assert_array_equal(ns["y"], result.y)
    assert ns["state_names"] == result.state_names
    channels = ns["channels"]
    assert isinstance(channels, dict) and sorted(channels) == result.channel_names
    for name in result.channel_names:
        np.testing.assert_array_equal(channels[name], result[name])
        assert ns["units"][name] == result.units[name]  # type: ignore[index]
    events = ns["events"]
    assert isinstance(events, list) and len(events) == len(result.events)
    for (t, pair, kind, speed), e in zip(events, result.events):
        assert (t, pair, kind) == (e.t, e.pair, e.kind)
        assert speed == e.approach_speed or (math.isnan(speed) and math.isnan(e.approach_speed))
    assert ns["parameters"] == result.parameters and ns["stats"] == result.stats
    assert [e[0] for e in ns["onsets"]] == list(result.events.of(kind="onset").t)  # type: ignore[attr-defined]


def test_a_run_result_is_what_the_checked_constructor_makes() -> None:
    """Result.of_run (the solvers' path, without the constructor's checks) gives the same fields,
    types and read-only arrays as Result(...) given the same data, and the data pass its checks."""
    import daeclear as dc

    run = dc.simulate(dc.mechanisms.slider_crank("revolute", clearance=0.2e-3), 2e-3, rtol=1e-6)
    assert len(run.events) >= 2
    checked = Result(**run.to_dict())
    assert checked.state_names == run.state_names and checked.units == run.units
    assert list(checked.units) == list(run.units)  # the same order: states, then sorted channels
    assert checked.channel_names == run.channel_names
    for name in run.channel_names:
        assert run[name].dtype == checked[name].dtype and not run[name].flags.writeable
        np.testing.assert_array_equal(run[name], checked[name])
    for mine, theirs in ((run.t, checked.t), (run.y, checked.y), (run.step_t, checked.step_t),
                         (run.step_order, checked.step_order)):
        assert mine.dtype == theirs.dtype and not mine.flags.writeable
        np.testing.assert_array_equal(mine, theirs)
    assert run.step_order.dtype == np.int64
    assert list(checked.events) == list(run.events) and checked.segments == run.segments
    assert all(type(a) is float and type(b) is float for a, b, _ in run.segments)
    assert checked.stats == run.stats and checked.parameters == run.parameters


def test_a_run_results_parameters_are_its_own_plain_copy() -> None:
    """A solver's Result makes its parameters at their first read: plain data (dicts, lists, numbers,
    strings) equal to the scene's description and the run's options, and its own copy (changing it
    changes no other result of the same model)."""
    import daeclear as dc

    scene = dc.mechanisms.slider_crank("revolute", clearance=0.2e-3)
    model = dc.assemble(scene)
    first, second = (dc.simulate(model, 1e-3, rtol=1e-6) for _ in range(2))

    def plain(value: object) -> bool:
        if isinstance(value, dict):
            return type(value) is dict and all(type(k) is str and plain(v) for k, v in value.items())
        if isinstance(value, list):
            return type(value) is list and all(plain(v) for v in value)
        return value is None or type(value) in (bool, int, float, str)

    assert plain(first.parameters)
    assert first.parameters["scene"] == json.loads(json.dumps(to_plain(scene.to_dict(), "scene")))
    assert first.parameters["simulate"]["rtol"] == 1e-6 and first.parameters["formulation"] == "ggl"
    first.parameters["scene"]["elements"]["clearance"]["clearance"] = 1.0
    assert second.parameters["scene"]["elements"]["clearance"]["clearance"] == 0.2e-3
    assert model.parameters["scene"]["elements"]["clearance"]["clearance"] == 0.2e-3
    assert second.parameters is second.parameters  # copied once
