"""A study's run file (daeclear.results.run_file): rows appended to named columns whole or not at all,
its header checked when a later call resumes it, the rows a killed process left half-written dropped.
The streamed result appends with the same append_rows (tests/test_streaming.py)."""

from __future__ import annotations

import os
import signal

import h5py
import numpy as np
import pytest

from daeclear.core.errors import OutputError, SceneError
from daeclear.results.run_file import RunFile, differences

UNITS = {"step": "", "profile": "m", "work": "N m"}
HEADER = {"scene": {"elements": {"joint": {"length": 0.02, "modes": 48}}}, "every": 1, "options": None}


def _file(path, header=HEADER):
    return RunFile(path, kind="test-run", version=3, header=header, units=UNITS, where="study", subject="settings")


def _row(k: int) -> dict:
    return {"step": float(k), "profile": np.arange(5.0) * k, "work": 10.0 * k}


def _written(path, n: int) -> None:
    with _file(path) as f:
        assert f.open() is None
        for k in range(n):
            f.append(_row(k))


def test_rows_are_read_back_with_their_units_and_header(tmp_path):
    path = tmp_path / "run.h5"
    _written(path, 3)
    with _file(path) as f:
        rows = f.open()
    assert rows["step"].tolist() == [0.0, 1.0, 2.0] and rows["work"].tolist() == [0.0, 10.0, 20.0]
    np.testing.assert_array_equal(rows["profile"], np.outer(np.arange(3.0), np.arange(5.0)))
    with h5py.File(path, "r") as h5:
        assert h5.attrs["format"] == "test-run" and h5.attrs["version"] == 3
        assert {name: h5[name].attrs["units"] for name in UNITS} == UNITS
        assert h5["header/scene/elements/joint"].attrs["modes"] == 48  # the browsable mirror
        assert h5["profile"].shape == (3, 5) and h5["profile"].fletcher32
    with _file(path) as f:  # resumed: the rows go on
        f.open()
        f.append(_row(3))
    with _file(path) as f:
        assert f.open()["step"].tolist() == [0.0, 1.0, 2.0, 3.0]


def test_a_resume_with_another_header_names_each_difference(tmp_path):
    path = tmp_path / "run.h5"
    _written(path, 1)
    other = {"scene": {"elements": {"joint": {"length": 0.03, "modes": 40}}}, "every": 1, "options": {"rtol": 1e-7}}
    with pytest.raises(SceneError) as info, _file(path, header=other) as f:
        f.open()
    text = str(info.value)
    assert text.startswith(f"study: {path} was written with another settings (")
    for words in ("scene.elements.joint.length=0.02, now 0.03", "scene.elements.joint.modes=48, now 40",
                  "options=None, now {'rtol': 1e-07}", "give a new path, or the same settings to resume"):
        assert words in text
    assert differences({"a": [1, 2]}, {"a": [1, 2]}) == []


def test_a_file_of_another_kind_or_version_is_refused(tmp_path):
    path = tmp_path / "run.h5"
    _written(path, 1)
    with pytest.raises(SceneError, match=r"is a test-run file of layout version 3, which this daeclear does not "
                                         r"resume \(it writes and resumes version 4\)"):
        RunFile(path, kind="test-run", version=4, header=HEADER, units=UNITS, where="study", subject="settings").open()
    with pytest.raises(SceneError, match=r"is not a other-run file \(its format is 'test-run'\); give a new path"):
        RunFile(path, kind="other-run", version=3, header=HEADER, units=UNITS, where="study", subject="settings").open()
    text = tmp_path / "notes.h5"
    text.write_text("not HDF5")
    with pytest.raises(SceneError, match="cannot be read as HDF5"), _file(text) as f:
        f.open()


def test_a_half_written_row_of_a_killed_process_is_dropped(tmp_path):
    """A process killed between two columns' writes leaves them a row apart: a resume keeps the rows
    every column has, and its next row lines up."""
    path = tmp_path / "run.h5"
    _written(path, 3)
    with h5py.File(path, "r+") as h5:  # the kill: the first column written, the others not
        h5["step"].resize(4, axis=0)
        h5["step"][3] = 99.0
    with _file(path) as f:
        assert f.open()["step"].tolist() == [0.0, 1.0, 2.0]
        f.append(_row(3))
    with _file(path) as f:
        rows = f.open()
    assert rows["step"].tolist() == [0.0, 1.0, 2.0, 3.0] and rows["work"].tolist() == [0.0, 10.0, 20.0, 30.0]


def test_a_failing_append_leaves_every_column_as_it_was(tmp_path, monkeypatch):
    path = tmp_path / "run.h5"
    _written(path, 2)
    real = h5py.Dataset.__setitem__

    def fails_on_work(self, key, value):
        if self.name == "/work":
            raise MemoryError("planted")
        return real(self, key, value)

    monkeypatch.setattr(h5py.Dataset, "__setitem__", fails_on_work)
    with pytest.raises(MemoryError), _file(path) as f:
        f.open()
        f.append(_row(2))
    monkeypatch.setattr(h5py.Dataset, "__setitem__", real)
    with h5py.File(path, "r") as h5:
        assert {name: h5[name].shape[0] for name in UNITS} == {name: 2 for name in UNITS}


@pytest.mark.usefixtures("sigint_as_a_terminal_sends_it")  # tests/conftest.py: also when started with &
def test_ctrl_c_during_an_append_arrives_once_the_row_is_whole(tmp_path, monkeypatch):
    path = tmp_path / "run.h5"
    _written(path, 1)
    real = h5py.Dataset.__setitem__

    def interrupted(self, key, value):
        if self.name == "/profile":
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C between two columns' writes
        return real(self, key, value)

    monkeypatch.setattr(h5py.Dataset, "__setitem__", interrupted)
    with pytest.raises(KeyboardInterrupt), _file(path) as f:
        f.open()
        f.append(_row(1))
    monkeypatch.setattr(h5py.Dataset, "__setitem__", real)
    with _file(path) as f:
        assert f.open()["work"].tolist() == [0.0, 10.0]


def test_an_unwritable_file_is_refused_before_its_rows_are_read(tmp_path, monkeypatch):
    path = tmp_path / "run.h5"
    _written(path, 1)
    real = h5py.File

    def read_only(name, mode="r", *args, **kwargs):
        if mode != "r":
            raise PermissionError(13, "Permission denied")
        return real(name, mode, *args, **kwargs)

    monkeypatch.setattr(h5py, "File", read_only)  # as a read-only file behaves for a user who is not root
    with pytest.raises(OutputError, match=rf"study: path='{path}', cannot be opened for writing \(Permission "
                                          r"denied\); must be a writable file"):
        _file(path).open()


def test_a_row_must_have_every_column(tmp_path):
    with pytest.raises(ValueError, match="must have the columns"), _file(tmp_path / "run.h5") as f:
        f.open()
        f.append({"step": 1.0})
