"""Smoke tests: every scene file under examples/scenes reads, and runs through ``daeclear run``
(shortened with --t-end) to its HDF5 file and figure, with the [simulate] options it declares."""

from __future__ import annotations

from pathlib import Path

import pytest

import daeclear as dc
from daeclear.cli import main
from daeclear.model.scenefile import read_scene_file

SCENES = sorted((Path(__file__).resolve().parent.parent / "examples" / "scenes").glob("*.toml"))


def test_there_are_example_scenes():
    assert len(SCENES) >= 4  # a [mechanism] file per joint kind, an element-by-element scene, a fixed-step run


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_example_scene_runs(path, tmp_path, capsys):
    spec = read_scene_file(path)
    assert spec.simulate.get("t_end", 0) > 0.002  # the file's own run is longer than the smoke test's
    assert main(["run", str(path), "--t-end", "0.002", "--out", str(tmp_path), "--quiet"]) == 0, \
        capsys.readouterr().err
    h5 = next(tmp_path.glob("*.h5"))
    result = dc.load(h5)
    assert result.success and result.t[-1] == pytest.approx(0.002)
    assert result.method.lower() == spec.simulate.get("method", "ida").lower()
    assert next(tmp_path.glob("*.png")).stat().st_size > 10_000


def test_the_format_pages_whole_files_read(tmp_path):
    """docs/scene_files.md's two whole files (a mechanism with [simulate], a scene element by element) read."""
    import re

    page = (Path(__file__).resolve().parent.parent / "docs" / "scene_files.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", page, re.S)
    whole = [b for b in blocks if b.startswith(("[mechanism]", "[scene]"))]
    assert len(whole) == 2
    for i, text in enumerate(whole):
        path = tmp_path / f"page{i}.toml"
        path.write_text(text)
        spec = read_scene_file(path)
        assert spec.scene.bodies
    assert read_scene_file(tmp_path / "page0.toml").simulate == {"t_end": 0.024, "rtol": 1e-6}
