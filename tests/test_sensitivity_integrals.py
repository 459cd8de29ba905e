"""The integrals of ``simulate(..., integrals=[...])`` in the run's file and their absolute tolerance.

On issue 43's radial impact (tests/test_sensitivity_objectives.py): Q and dQ/dp of every output row written by
``Result.save`` and by a streamed run (``SaveAt(stream_to=...)``) and read back by ``dc.load`` as the run in
memory holds them; ``SolverOptions.quadrature_atol`` checked before any work, and a tighter one brings the
integral of x closer to its closed form.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

import daeclear as dc
from test_sensitivity_objectives import M, NAMES, P0, T, U, complex_step, radial_scene, separation, x_integral

CHANNELS = ["journal.x", "clearance.normal_force"]
TIMES = np.linspace(0.0, T, 26)


def run(scene: dc.Scene, save: dc.SaveAt, channels: list[str] = CHANNELS, rtol: float = 1e-10,
        **settings: object) -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)  # atol at round-off, raised
        return dc.simulate(scene, T, rtol=rtol, options=dc.SolverOptions(start="declared", **settings), save=save,
                           sensitivities=NAMES, integrals=channels)


@pytest.fixture(scope="module")
def scene() -> dc.Scene:
    """The radial impact of tests/test_sensitivity_objectives.py."""
    return radial_scene()


@pytest.fixture(scope="module")
def memory(scene: dc.Scene) -> dc.Result:
    return run(scene, dc.SaveAt(times=TIMES, steps=False))


def same_integrals(a: dc.Result, b: dc.Result, rows: slice = slice(None)) -> None:
    """b's integrals are a's (its ``rows``), bit for bit."""
    assert list(b.sensitivities.integrals) == CHANNELS
    for name in CHANNELS:
        Qa, dQa = a.sensitivities.integrals[name]
        Qb, dQb = b.sensitivities.integrals[name]
        assert Qb.shape == Qa[rows].shape and dQb.shape == dQa[rows].shape == (Qb.size, len(NAMES))
        assert np.array_equal(Qa[rows], Qb) and np.array_equal(dQa[rows], dQb)


def test_the_run_in_memory_is_the_closed_form(memory: dc.Result) -> None:
    """What the files below must keep: Q(T) and dQ/dp(T) of both integrals against the closed forms."""
    Q, dQ = memory.sensitivities.integrals["journal.x"]
    assert Q[-1] == pytest.approx(np.real(x_integral(P0))[0], rel=1e-9)
    assert dQ[-1] == pytest.approx(complex_step(x_integral, P0)[0], rel=1e-6)
    Q, dQ = memory.sensitivities.integrals["clearance.normal_force"]
    assert Q[-1] == pytest.approx(M * (U + np.real(separation(P0)[2])), rel=1e-8)
    assert dQ[-1, :2] == pytest.approx(M * complex_step(separation, P0)[2, :2], rel=1e-6)


def test_a_saved_run_keeps_its_integrals(memory: dc.Result, tmp_path: Path) -> None:
    """Result.save writes /sensitivities/integrals (names, Q, dQ at every output row); dc.load reads them back
    (a window: its rows), and the loaded result's Integral is the quadrature state's, not the rows' cubic."""
    path = memory.save(tmp_path / "run.h5")
    with h5py.File(path, "r") as f:
        assert list(f["sensitivities/integrals/names"].asstr()[()]) == CHANNELS
        assert f["sensitivities/integrals/Q"].shape == (TIMES.size, 2)
        assert f["sensitivities/integrals/dQ"].shape == (TIMES.size, 2, len(NAMES))
    back = dc.load(path)
    same_integrals(memory, back)
    of = dc.Integral("clearance.normal_force", window=(TIMES[2], TIMES[-3]))
    assert back.gradient(of) == memory.gradient(of)
    window = dc.load(path, TIMES[5], TIMES[12])
    same_integrals(memory, window, slice(5, 13))
    same_integrals(memory.slice(TIMES[5], TIMES[12]), window)


def test_a_run_without_integrals_writes_empty_columns(scene: dc.Scene, tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        plain = dc.simulate(scene, T, rtol=1e-6, options=dc.SolverOptions(start="declared"),
                            save=dc.SaveAt(times=TIMES, steps=False), sensitivities=NAMES)
    path = plain.save(tmp_path / "plain.h5")
    with h5py.File(path, "r") as f:
        assert f["sensitivities/integrals/Q"].shape == (TIMES.size, 0)
    assert dict(dc.load(path).sensitivities.integrals) == {}


def test_a_streamed_run_writes_its_integrals_as_it_goes(scene: dc.Scene, memory: dc.Result, tmp_path: Path) -> None:
    """SaveAt(stream_to=...): the integrals' rows go with the output rows; the streamed result, the file read
    back and a run kept only in its file (keep_data=False) hold the run in memory's integrals exactly."""
    streamed = run(scene, dc.SaveAt(times=TIMES, steps=False, stream_to=tmp_path / "run.h5"))
    same_integrals(memory, streamed)
    same_integrals(memory, dc.load(tmp_path / "run.h5"))
    outcome = run(scene, dc.SaveAt(times=TIMES, steps=False, stream_to=tmp_path / "alone.h5", keep_data=False))
    assert outcome.n_times == 0
    back = dc.load(tmp_path / "alone.h5")
    same_integrals(memory, back)
    of = dc.Integral("journal.x")
    assert back.gradient(of) == memory.gradient(of)


@pytest.mark.parametrize("value", [0.0, -1e-9, float("nan"), float("inf"), "1e-9", True])
def test_a_bad_quadrature_atol_is_refused_before_any_work(scene: dc.Scene, value: object,
                                                          monkeypatch: pytest.MonkeyPatch) -> None:
    from daeclear.solvers import sensitivity_ida

    def no_run(*args: object, **kw: object) -> None:
        raise AssertionError("a run started")

    monkeypatch.setattr(sensitivity_ida.SensitivityIntegrator, "__init__", no_run)
    with pytest.raises(dc.SceneError, match=rf"SolverOptions: quadrature_atol={value!r}, must be None or a finite "
                                            r"number > 0 \(the integrals' absolute tolerance"):
        dc.SolverOptions(quadrature_atol=value)
    with pytest.raises(dc.SceneError, match=rf"gradient: quadrature_atol={value!r}, must be None or a finite"):
        dc.gradient(scene, T, of=dc.Integral("journal.x"), parameters=NAMES, quadrature_atol=value)


def test_quadrature_atol_is_a_setting() -> None:
    options = dc.SolverOptions(quadrature_atol=1e-12)
    assert options.quadrature_atol == 1e-12 and dc.SolverOptions().quadrature_atol is None
    assert dc.SolverOptions.from_dict(options.to_dict()) == options
    assert options.replace(quadrature_atol=None) == dc.SolverOptions()


def test_a_tighter_quadrature_atol_tightens_the_integral(scene: dc.Scene) -> None:
    """int_0^T x dt (about 8e-3 m s) at rtol 1e-6: with the integral's absolute tolerance at 1e-3 (far above the
    integral itself) its error test says nothing and Q is only as good as the states' steps make it; at 1e-12 it
    is held to rtol relative. The error against the closed form falls at least tenfold, and below 10 rtol (as with
    the default, 1e-3 rtol = 1e-9: then the states' errors dominate)."""
    want = np.real(x_integral(P0))[0]
    errors = {}
    for atol in (1e-3, None, 1e-12):
        r = run(scene, dc.SaveAt(times=[0.0, T], steps=False), ["journal.x"], rtol=1e-6, quadrature_atol=atol)
        errors[atol] = abs(r.sensitivities.integrals["journal.x"][0][-1] - want) / abs(want)
    assert errors[1e-12] < errors[1e-3] / 10, errors
    assert errors[1e-12] < 10 * 1e-6 and errors[None] < 10 * 1e-6, errors


def test_an_interrupted_streamed_run_keeps_its_integrals(scene: dc.Scene, memory: dc.Result, tmp_path: Path,
                                                         ctrl_c_at_update) -> None:
    """Ctrl-C at the progress line's second update (the run restarts at each of its two events): the file holds
    the rows before it with their integrals, the complete run's, and the Interrupted's result is the file's."""
    from daeclear.core.errors import Interrupted
    ctrl_c_at_update(2)
    with pytest.raises(Interrupted) as info:
        run(scene, dc.SaveAt(times=TIMES, steps=False, stream_to=tmp_path / "run.h5"))
    partial = dc.load(tmp_path / "run.h5")
    assert not partial.success and 0 < partial.n_times < TIMES.size
    same_integrals(memory, partial, slice(0, partial.n_times))
    same_integrals(partial, info.value.result)


def test_a_file_written_before_the_integrals_were_kept(memory: dc.Result, tmp_path: Path) -> None:
    """A file without /sensitivities/integrals (written before they were kept) loads with no integrals, its
    sensitivities otherwise whole."""
    path = memory.save(tmp_path / "old.h5")
    with h5py.File(path, "r+") as f:
        del f["sensitivities/integrals"]
    back = dc.load(path)
    assert dict(back.sensitivities.integrals) == {}
    assert np.array_equal(back.sensitivities.states, memory.sensitivities.states)
