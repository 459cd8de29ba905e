"""SaveAt: the output of a run as one checked value; its checks at construction and against the run (issue 35)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import daeclear as dc
from daeclear.core import options
from daeclear.core.errors import SceneError

NAN, INF = math.nan, math.inf

#: (id, fields of SaveAt, the message's start, a part of it): each refused when the SaveAt is made
BAD_FIELDS: list[tuple[str, dict, str, str]] = [
    ("times nan", {"times": [0.0, NAN]}, "SaveAt: times=", "(nan at index 1)"),
    ("times inf", {"times": [0.0, INF]}, "SaveAt: times=", "(inf at index 1)"),
    ("times decreasing", {"times": [1e-3, 0.0]}, "SaveAt: times=", "strictly increasing values >= 0"),
    ("times negative", {"times": [-1.0, 0.0]}, "SaveAt: times=", "values >= 0"),
    ("times empty", {"times": []}, "SaveAt: times=[]", "at least one time"),
    ("times 2-D", {"times": [[0.0, 1e-4], [2e-4, 3e-4]]}, "SaveAt: times=array of shape (2, 2)", "a 1-D sequence"),
    ("times text", {"times": "0, 1"}, "SaveAt: times='0, 1'", "strictly increasing"),
    ("every 0", {"every": 0.0}, "SaveAt: every=0.0 s", "a finite number > 0"),
    ("every < 0", {"every": -1.0}, "SaveAt: every=-1.0 s", "a finite number > 0"),
    ("every nan", {"every": NAN}, "SaveAt: every=nan s", "a finite number > 0"),
    ("every inf", {"every": INF}, "SaveAt: every=inf s", "a finite number > 0"),
    ("every text", {"every": "1e-5"}, "SaveAt: every='1e-5' s", "a finite number > 0"),
    ("every and times", {"every": 1e-5, "times": [0.0]}, "SaveAt: every=1e-05", "left out when times is given"),
    ("steps text", {"steps": "no"}, "SaveAt: steps='no'", "True or False"),
    ("steps 0", {"steps": 0}, "SaveAt: steps=0", "True or False"),
    ("keep_data without stream_to", {"keep_data": False}, "SaveAt: keep_data=False", "True when stream_to is not"),
    ("keep_data text", {"keep_data": "no", "stream_to": "x.h5"}, "SaveAt: keep_data='no'", "True or False"),
    ("stream_to number", {"stream_to": 3}, "SaveAt: stream_to=3", "None or the path of an HDF5 file"),
    ("max_points 0", {"max_points": 0}, "SaveAt: max_points=0", "an integer >= 1"),
    ("max_points float", {"max_points": 1e6}, "SaveAt: max_points=1000000.0", "an integer >= 1"),
    ("max_points bool", {"max_points": True}, "SaveAt: max_points=True", "an integer >= 1"),
]


@pytest.mark.parametrize("case, fields, start, part", BAD_FIELDS, ids=[c[0] for c in BAD_FIELDS])
def test_a_bad_field_is_refused_when_the_value_is_made(case, fields, start, part) -> None:
    with pytest.raises(SceneError) as info:
        dc.SaveAt(**fields)
    message = str(info.value)
    assert message.startswith(start) and part in message, message


#: (id, SaveAt fields, t0, t_end, the message's start, a part of it): refused by simulate, before any work
BAD_FOR_THE_RUN: list[tuple[str, dict, float, float, str, str]] = [
    ("times beyond t_end", {"times": [0.0, 1e-3]}, 0.0, 5e-4, "simulate: save.times=[0.0, 0.001]", "t_end=0.0005"),
    ("times before t0", {"times": [0.0, 1e-4]}, 5e-5, 5e-4, "simulate: save.times=[0.0, 0.0001]", "[t0=5e-05, "),
    ("every longer than the run", {"every": 1e-3}, 0.0, 5e-4, "simulate: save.every=0.001 s", "<= 0.0005"),
    ("every longer than t_end - t0", {"every": 3e-4}, 3e-4, 5e-4, "simulate: save.every=0.0003 s", "<= 0.0002"),
    ("points beyond max_points", {"every": 1e-5, "max_points": 10}, 0.0, 5e-4, "simulate: save.every=1e-05",
     "51 output points"),
    ("stream_to a directory", {"stream_to": "."}, 0.0, 5e-4, "simulate: save.stream_to", "directory"),
]


@pytest.mark.parametrize("case, fields, t0, t_end, start, part", BAD_FOR_THE_RUN,
                         ids=[c[0] for c in BAD_FOR_THE_RUN])
def test_what_needs_the_run_is_refused_by_simulate_before_any_work(case, fields, t0, t_end, start, part,
                                                                    monkeypatch) -> None:
    import daeclear.solvers.driver as driver
    import daeclear.solvers.ida as ida

    save = dc.SaveAt(**fields)  # fine on its own
    if case != "points beyond max_points":  # the size needs the model: checked after assembly, before the session
        monkeypatch.setattr(driver, "assemble", lambda *a, **k: pytest.fail("assembled despite a bad output"))
    monkeypatch.setattr(ida, "open_session", lambda *a, **k: pytest.fail("a session opened despite a bad output"))
    with pytest.raises(dc.DaeclearError) as info:  # a SceneError; an OutputError for the file's place
        dc.simulate(dc.mechanisms.slider_crank("ideal"), t_end, t0=t0, save=save)
    message = str(info.value)
    assert message.startswith(start) and part in message, message


def test_a_save_at_is_an_immutable_value_that_keeps_its_own_times() -> None:
    times = np.linspace(0.0, 1e-3, 11)
    save = dc.SaveAt(times=times)
    times[3] = 5.0  # the caller's array changes afterwards: the checked copy does not
    assert save.times is not None and save.times[3] == np.linspace(0.0, 1e-3, 11)[3]
    with pytest.raises(ValueError):
        save.times[0] = 1.0  # type: ignore[index]  # read-only
    with pytest.raises(dataclasses.FrozenInstanceError):
        save.every = 1e-5  # type: ignore[misc]
    default = dc.SaveAt()
    assert (default.times, default.every, default.steps, default.stream_to, default.keep_data) == (
        None, None, True, None, True)
    assert default.max_points == options.MAX_OUTPUT_POINTS
    with pytest.raises(SceneError, match=r"simulate: save=\{'every': 1e-05\}, must be None or a daeclear.SaveAt"):
        dc.simulate(dc.mechanisms.slider_crank("ideal"), 1e-3, save={"every": 1e-5})  # type: ignore[arg-type]


def test_the_grid_of_every_equals_the_given_times_value_for_value() -> None:
    """``every`` is ``times=uniform_times(every, t_end, t0)``: the same points, and the same run."""
    model = dc.assemble(dc.mechanisms.slider_crank("ideal"))
    t0, t_end, spacing = 1e-3, 4e-3, 1e-4
    grid = dc.simulate(model, t_end, t0=t0, y0=dc.simulate(model, t0).y[-1], save=dc.SaveAt(every=spacing))
    given = dc.simulate(model, t_end, t0=t0, y0=dc.simulate(model, t0).y[-1],
                        save=dc.SaveAt(times=options.uniform_times(spacing, t_end, t0)))
    assert grid.t.size == 31 and grid.t[0] == t0 and grid.t[-1] == t_end
    np.testing.assert_array_equal(grid.t, given.t)
    np.testing.assert_array_equal(grid.y, given.y)
