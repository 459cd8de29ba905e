"""examples/sensitivity_study.py in its quick form: it writes its figure and its gradients, and the gradient of
the peak crank moment from the sensitivities agrees with the central differences of separate runs."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sensitivity_study.py"


def test_sensitivity_study_quick(tmp_path: Path) -> None:
    spec = importlib.util.spec_from_file_location("sensitivity_study", EXAMPLE)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "sensitivity_horizon.png").stat().st_size > 5_000
    got = json.loads((tmp_path / "gradients.json").read_text())["gradients"]
    for name, value in got["sensitivities"].items():
        assert value == pytest.approx(got["fd"][name], rel=1e-4), name
