"""Smoke test: every section 4.5 example (``examples/translational_fig*.py``) runs with --quick."""

import importlib.util
import json
from pathlib import Path

import pytest

import daeclear as dc

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
SCRIPTS = sorted(EXAMPLES.glob("translational_fig*.py"))
FIGURES = {
    "translational_fig4_28": ["fig4_28.png", "phase_portrait.png"],
    "translational_fig4_29_31": ["fig4_29.png", "fig4_30.png", "fig4_31.png"],
    "translational_fig4_32_34": ["fig4_32.png", "fig4_33.png", "fig4_34.png"],
    "translational_fig4_35_36": ["fig4_35.png", "fig4_36.png"],
}


def _load(path: Path):
    spec = importlib.util.spec_from_file_location(f"example_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_figure_family_has_a_script():
    assert sorted(p.stem for p in SCRIPTS) == sorted(FIGURES)


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.stem)
def test_example_runs_quick(script, tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    assert _load(script).main(["--quick", "--out", str(tmp_path)]) == 0
    for name in FIGURES[script.stem]:
        assert (tmp_path / name).stat().st_size > 10_000, name
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["cases"] and all(row["span_slider_in_guide"] for row in metrics["cases"])
    files = sorted(tmp_path.glob("*.h5"))
    assert len(files) == len(metrics["cases"]) + 1  # the cases and the ideal joint
    result = dc.load(files[0])
    assert result.success and result.n_times > 0
