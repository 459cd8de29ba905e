"""The wear history file (issue 42 item 5, issue 44 item 6): a run file of results' writer, its layout
as docs/hdf5_layout.md documents it, read with h5py alone, resumed after a killed append, refused when it
is of the former layout, of another kind or not writable (before any work)."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

import daeclear as dc
from daeclear.contact.wear import ArchardWear
from daeclear.core.errors import OutputError, SceneError
from daeclear.studies.wear import simulate_wear

LAYOUT_DOC = Path(__file__).resolve().parents[1] / "docs" / "hdf5_layout.md"
SECTION = "\n## The wear history file"


def _worn(surface: str = "bearing") -> dc.Scene:
    return dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-11, length=0.02, nodes=120, modes=20, surface=surface)})


@pytest.fixture(scope="module")
def worn() -> dc.Scene:
    return _worn()


def _documented() -> list[re.Pattern[str]]:
    text = LAYOUT_DOC.read_text(encoding="utf-8").split(SECTION)[1]
    items = re.findall(r"^\|\s*`(/[^`]*)`\s*\|", text, re.M)
    return [re.compile(re.escape(i).replace(re.escape("<column>"), r"[^/@]+").replace(re.escape("/**"), r"(?:[/@].*)?")
                       + r"\Z") for i in items]


def _items(path: Path) -> list[str]:
    with h5py.File(path, "r") as f:
        items = [f"/@{a}" for a in f.attrs]

        def visit(name: str, obj: h5py.HLObject) -> None:
            items.append(f"/{name}")
            items.extend(f"/{name}@{a}" for a in obj.attrs)

        f.visititems(visit)
    return items


@pytest.mark.parametrize("surface", ["bearing", "both"])
def test_the_layout_document_lists_every_item_of_the_file_and_only_those(tmp_path, surface):
    path = tmp_path / "wear.h5"
    scene = _worn(surface)
    history = simulate_wear(scene, 2, path=path)
    patterns = _documented()
    assert len(patterns) > 10
    items = _items(path)
    assert not [i for i in items if not any(p.match(i) for p in patterns)], "undocumented items"
    assert not [p.pattern for p in patterns if not any(p.match(i) for i in items)], "documented, not written"
    model = dc.assemble(scene)
    with h5py.File(path, "r") as f:
        assert f["depth"].shape == (3, len(scene["clearance"].wear.surfaces), 120)
        assert f["y"].shape == (3, model.n_states) and np.all(np.isnan(f["y"][0]))
        assert f["cycles"][()].tolist() == [0.0, 1.0, 2.0] and f["t"][0] == 0.0
        period = f["t"][1]
        assert f["t"][2] == pytest.approx(2 * period, rel=1e-12)
        peak = f["block_peak_force"][()]
    assert math.isnan(peak[0]) and np.array_equal(peak[1:], history.peak_force[:-1])


def test_the_documented_snippet_reads_the_file_with_h5py(worn, tmp_path, monkeypatch):
    text = LAYOUT_DOC.read_text(encoding="utf-8").split(SECTION)[1]
    snippet = re.search(r"```python\n(import json\n.*?)```", text, re.S)
    assert snippet, "the wear history's h5py snippet was not found"
    history = simulate_wear(worn, 2, path=tmp_path / "wear.h5")
    monkeypatch.chdir(tmp_path)
    ns: dict[str, object] = {}
    exec(compile(snippet.group(1), str(LAYOUT_DOC), "exec"), ns)
    np.testing.assert_array_equal(ns["cycles"], history.cycles)
    np.testing.assert_array_equal(ns["deepest"], history.max_depth)
    assert ns["wear"]["modes"] == 20 and ns["wear"]["nodes"] == 120


def test_a_resume_after_a_killed_append_equals_the_whole_run(worn, tmp_path):
    """Killed while writing the third row (its cycles written, nothing else): the resume drops that half
    row and runs the block again; the history equals an uninterrupted one value for value."""
    path = tmp_path / "wear.h5"
    simulate_wear(worn, 3, path=path)
    with h5py.File(path, "r+") as f:  # the kill: cut to two rows, then a third row of cycles alone
        for name in ("depth", "sliding_work", "block_peak_force", "t", "y"):
            f[name].resize(2, axis=0)
        f["cycles"].resize(3, axis=0)
    resumed = simulate_wear(worn, 3, path=path)
    read = simulate_wear(worn, 3, path=path)  # the file alone: nothing left to run
    whole = simulate_wear(worn, 3)
    for history in (resumed, read):
        assert history.cycles.tolist() == [0.0, 1.0, 2.0, 3.0]
        for field in ("depth", "sliding_work", "volume", "peak_force"):
            np.testing.assert_array_equal(getattr(history, field), getattr(whole, field))


def _former_layout(path: Path, settings: dict) -> None:
    """A history file as main wrote it before version 2 (no version; the state in /y0 and the attribute t0)."""
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "daeclear-wear"
        f.attrs["settings_json"] = json.dumps(settings)
        for name in ("cycles", "sliding_work", "peak_force"):
            f.create_dataset(name, data=np.zeros(1), maxshape=(None,), chunks=(256,))
        f.create_dataset("depth", data=np.zeros((1, 1, 120)), maxshape=(None, 1, 120), chunks=(16, 1, 120))
        f.attrs["t0"] = 0.0
        f.create_dataset("y0", data=np.zeros(0))


def test_a_file_of_the_former_layout_or_another_kind_is_refused(worn, tmp_path, monkeypatch):
    import daeclear.studies.wear as study

    former = tmp_path / "former.h5"
    _former_layout(former, {"joint": "clearance"})
    result = dc.simulate(dc.mechanisms.slider_crank("revolute"), 0.001).save(tmp_path / "run.h5")
    monkeypatch.setattr(study, "assemble", lambda *a, **k: pytest.fail("assembled before the file was checked"))
    with pytest.raises(SceneError, match=r"is a daeclear-wear file of layout version 1 \(none written\), which this "
                                         r"daeclear does not resume \(it writes and resumes version 3\); the file is "
                                         r"left as it is; give a new path"):
        simulate_wear(worn, 2, path=former)
    with pytest.raises(SceneError, match=r"is not a daeclear-wear file \(its format is 'daeclear-result'\)"):
        simulate_wear(worn, 2, path=result)
    assert h5py.File(former, "r").attrs["format"] == "daeclear-wear"  # left as it was


def test_an_unwritable_history_file_is_refused_before_any_work(worn, tmp_path, monkeypatch):
    import daeclear.studies.wear as study

    path = tmp_path / "wear.h5"
    simulate_wear(worn, 1, path=path)
    real = h5py.File

    def read_only(name, mode="r", *args, **kwargs):  # a read-only file, for a user who is not root
        if mode != "r":
            raise PermissionError(13, "Permission denied")
        return real(name, mode, *args, **kwargs)

    monkeypatch.setattr(h5py, "File", read_only)
    monkeypatch.setattr(study, "assemble", lambda *a, **k: pytest.fail("assembled before the file was checked"))
    with pytest.raises(OutputError, match=r"simulate_wear: path='.*wear.h5', cannot be opened for writing "
                                          r"\(Permission denied\); must be a writable file"):
        simulate_wear(worn, 2, path=path)
