"""examples/sensitivity_study.py in its quick form: it writes its figure and its gradients, and the gradient of
the peak crank moment from the sensitivities agrees with the central differences of separate runs for each of
its variants (dry with friction, lubricated, worn bearing) and each of their parameters."""

from __future__ import annotations

import importlib.util
import json
import math
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
    variants = json.loads((tmp_path / "gradients.json").read_text())["gradients"]
    # issue 43's five: clearance, restitution, friction, the oil's viscosity and a worn profile's mode
    assert {name for got in variants.values() for name in got["values"]} == {
        "clearance.clearance", "clearance.law.restitution", "clearance.friction.coefficient",
        "clearance.law.viscosity", "clearance.wear.bearing_cos[1]"}
    for label, got in variants.items():
        for name, value in got["sensitivities"].items():
            assert value == pytest.approx(got["fd"][name], rel=1e-4), (label, name)
        peak = got["sensitivities"]["peak crank moment (N m)"]
        for name, relative in got["relative"].items():  # d ln(peak)/d ln p, the figure's bars
            assert relative == pytest.approx(got["sensitivities"][name] * got["values"][name] / peak, rel=1e-12)
    # the dry and the worn joint's gradients go through an impact (its onset's jump of S), the oil film holds
    for label in ("dry, friction 0.05", "worn bearing"):
        assert variants[label]["events"]["onset"] >= 1, label
    mode = variants["worn bearing"]["values"]["clearance.wear.bearing_cos[1]"]  # 20 um (1 + cos theta)'s first mode
    assert mode == pytest.approx(20e-6, rel=1e-9, abs=0.0)
    horizons = json.loads((tmp_path / "gradients.json").read_text())["horizons"]
    assert sorted(horizons) == ["0.1 mm", "0.5 mm"]
    for h in horizons.values():  # result.sensitivity_horizon's: t0 + ln(1/rtol) / lambda at the run's rtol 1e-8
        if h["lyapunov (1/s)"] > 0:
            assert h["horizon (s)"] == pytest.approx(math.log(1e8) / h["lyapunov (1/s)"], rel=1e-12)
        assert h["predictable"] == (h["horizon (s)"] > 2e-3)
