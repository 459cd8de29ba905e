"""``SolverOptions(sensitivity_error_test=False)``: S out of IDA's error test, kept in its Newton test
(csrc/ida_newton.h; docs/sensitivities.md, section 2), on the Kelvin-Voigt radial impact's closed form.

With the option the run takes fewer steps and S(T) holds to the looser accuracy the docs state (30 sqrt(rtol)
in relative sensitivity |dS| |p| / scale, scale z0 for x and u for vx); by default to 100 rtol.
The Newton test keeps S: more Newton iterations on the same steps than with IDA's weights alone.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.engine.c_session import CSession
from test_sensitivity_radial_impact import NAMES, P0, T, complex_step, kelvin_voigt_radial, radial_scene


@pytest.fixture(scope="module")
def model() -> dc.DAEModel:
    return dc.assemble(radial_scene(dcc.KelvinVoigt(stiffness=P0[0], damping=P0[1])))


def run(model: dc.DAEModel, rtol: float, tested: bool, backend: str = "c") -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        options = dc.SolverOptions(start="declared", backend=backend, sensitivity_error_test=tested)
        return dc.simulate(model, T, rtol=rtol, options=options, save=dc.SaveAt(times=[0.0, T]), sensitivities=NAMES)


def relative_error(r: dc.Result) -> float:
    """max |S(T) - closed form| |p| / scale over x (scale z0) and vx (scale u) and the three parameters."""
    want = complex_step(kelvin_voigt_radial, P0)
    x = np.abs(r.sensitivity("journal.x")[-1] - want[0]) * P0 / P0[2]
    vx = np.abs(r.sensitivity("journal.vx")[-1] - want[1]) * P0 / 1.0
    return float(max(x.max(), vx.max()))


@pytest.mark.parametrize("rtol", [1e-6, 1e-10])
def test_fewer_steps_and_the_stated_accuracy(model: dc.DAEModel, rtol: float) -> None:
    on, off = run(model, rtol, True), run(model, rtol, False)
    assert off.stats["n_steps"] < 0.75 * on.stats["n_steps"]
    assert relative_error(on) < 100 * rtol  # in the error test: 1 to 20 rtol (atol at round-off at 1e-10)
    assert relative_error(off) < 30 * math.sqrt(rtol)
    assert off["journal.x"][-1] == pytest.approx(kelvin_voigt_radial(P0)[0], abs=1e-3 * P0[2])


def test_newton_keeps_the_sensitivities(model: dc.DAEModel, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same steps at rtol 1e-6; with S in the Newton test more iterations than with IDA's weights alone."""
    kept = run(model, 1e-6, False)
    original = CSession.set_newton_tolerances
    monkeypatch.setattr(CSession, "set_newton_tolerances", lambda self, atol: original(self, None))
    dropped = run(model, 1e-6, False)
    assert kept.stats["n_steps"] == dropped.stats["n_steps"]
    assert kept.stats["n_nonlin_iters"] > dropped.stats["n_nonlin_iters"]


def test_bad_option(model: dc.DAEModel) -> None:
    with pytest.raises(dc.SceneError, match=r"sensitivity_error_test='no', must be True or False"):
        dc.SolverOptions(sensitivity_error_test="no")
    with pytest.raises(dc.SceneError, match=r"simulate: options.sensitivity_error_test=False, must be True with "
                                            r"backend='python'"):
        run(model, 1e-6, False, backend="python")
