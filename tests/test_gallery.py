"""Smoke test of the figure gallery: ``examples/gallery.py --quick`` writes every image, titled with its parameters.

The quick gallery runs every figure family for 5 ms (about 10 s warm, 30 s on an empty compile
cache); the titles are read back from the PNGs' ``Title`` text, which the gallery copies from
the figure objects. The committed gallery (``docs/figures/gallery/``) is checked against the
page that shows it, without running anything.
"""

from __future__ import annotations

import importlib.util
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
CLEARANCE_STUDIES = {"Figs. 4.16-4.18", "Figs. 4.29-4.31"}  # c varies: stated in the panel titles, not the title


def _load() -> ModuleType:
    spec = importlib.util.spec_from_file_location("example_gallery", EXAMPLES / "gallery.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture()
def gallery(monkeypatch: pytest.MonkeyPatch) -> Iterator[ModuleType]:
    monkeypatch.syspath_prepend(str(EXAMPLES))
    yield _load()
    import matplotlib.pyplot as plt

    plt.close("all")


def test_every_figure_family_is_in_the_gallery(gallery: ModuleType) -> None:
    chapters = [f.chapter for f in gallery.FAMILIES]
    assert chapters == ["Fig. 4.15", "Figs. 4.16-4.18", "Figs. 4.19-4.21", "Figs. 4.22-4.24", "Fig. 4.25",
                        "Fig. 4.26", "Fig. 4.28", "Figs. 4.29-4.31", "Figs. 4.32-4.34", "Figs. 4.35-4.36"]
    assert len({f.file for f in gallery.FAMILIES}) == len(gallery.FAMILIES)
    for family in gallery.FAMILIES:
        assert (EXAMPLES / f"{family.script}.py").is_file()


def test_quick_gallery_writes_every_png_titled_with_its_parameters(gallery: ModuleType, tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    assert gallery.main(["--quick", "--out", str(tmp_path)]) == 0
    assert "gallery: 10 images" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f.file for f in gallery.FAMILIES)
    assert not (tmp_path / "gallery.md").exists()
    for family in gallery.FAMILIES:
        path = tmp_path / family.file
        assert path.stat().st_size > 5_000, family.file
        title = gallery.png_title(path)
        assert title.startswith("Fig. 4."), title
        assert "5000 rpm" in title and "slider_crank_" in title, title
        if family.chapter not in CLEARANCE_STUDIES:
            assert "c = 0.5 mm" in title, title
    titles = {f.file: gallery.png_title(tmp_path / f.file) for f in gallery.FAMILIES}
    assert "Lankarani-Nikravesh $c_e$ = 0.9, frictionless" in titles["fig4_15_response.png"]
    assert "modified Coulomb" in titles["fig4_21_phase_portraits.png"]  # varied c_f: in the panels
    assert "$c_f$" not in titles["fig4_21_phase_portraits.png"]
    assert "c = " not in titles["fig4_17_journal_orbits.png"]  # varied clearance: in the panels


def test_shared_caption_keeps_what_every_case_has(gallery: ModuleType) -> None:
    import _common as cm

    import daeclear as dc
    from daeclear.model.mechanisms import slider_crank

    def Run(restitution: float, clearance: float) -> dc.Result:  # noqa: N802  (a 10 us run records the scene)
        return dc.simulate(slider_crank("revolute", clearance=clearance, restitution=restitution), 1e-5)

    runs = [Run(0.9, 0.5e-3), Run(1.0, 0.5e-3)]
    text = cm.shared_caption(runs)
    assert text == "slider_crank_revolute: c = 0.5 mm, 5000 rpm, Lankarani-Nikravesh, frictionless"
    assert cm.shared_caption([Run(0.9, 0.5e-3), Run(0.9, 0.2e-3)]).startswith(
        "slider_crank_revolute: 5000 rpm, Lankarani-Nikravesh $c_e$ = 0.9")


def test_committed_gallery_matches_its_page(gallery: ModuleType) -> None:
    page = (ROOT / "docs" / "gallery.md").read_text()
    shown = re.findall(r"\]\(figures/gallery/([^)]+\.png)\)", page)
    assert shown == [f.file for f in gallery.FAMILIES]
    total = 0
    for family in gallery.FAMILIES:
        path = gallery.COMMITTED / family.file
        assert 5_000 < path.stat().st_size < 200_000, family.file
        assert "5000 rpm" in gallery.png_title(path)
        assert f"python examples/{family.script}.py" in page
        total += path.stat().st_size
    assert total < 2_000_000


def test_gallery_without_options_writes_into_the_current_directory_only(
        gallery: ModuleType, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    # `python examples/gallery.py` (a README command) rewrote the 10 tracked files under docs/ (issue 45):
    # now only a command naming docs/ writes there
    calls: list[tuple[Path, Path | None]] = []
    monkeypatch.setattr(gallery, "build", lambda out, *, quick=False, doc=None: calls.append((out, doc)) or {})
    monkeypatch.chdir(tmp_path)
    assert gallery.main([]) == 0
    assert gallery.main(gallery.REGENERATE.split()[2:]) == 0
    out, doc = calls[0]
    assert (tmp_path / out).resolve() == tmp_path / "results" / "gallery" and doc is None
    assert calls[1] == (Path("docs/figures/gallery"), Path("docs/gallery.md"))
