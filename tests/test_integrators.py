"""The other integrators (daeclear.solvers.explicit): scipy RK45/DOP853/Radau/BDF/LSODA, fixed-step rk4/euler.

Measured (gcc 12, 2-core machine), ideal slider-crank without gravity, one crank revolution (12 ms),
largest slider.x error against the closed form at rtol 1e-8: RK45 9e-10, DOP853 2e-9, Radau 2e-10,
BDF 9e-9, LSODA 8e-9 (IDA 3e-8); rk4 h=1e-5: 3e-12; euler h=1e-6: 9e-5.
Clearance slider-crank, first impact at rtol 1e-10: onset 2.272860e-4 s, peak normal force 45872.27 N
and peak penetration 7.795222e-5 m agree between IDA (index1 and GGL) and DOP853 to 9 digits.
"""

import numpy as np
import pytest

import daeclear as dc
from daeclear.engine.codegen import clear_memos
from daeclear.solvers.ode_crossings import candidate as _candidate, cubic_extrema as _cubic_extrema
from daeclear.model.mechanisms import CRANK_LENGTH as R, ROD_LENGTH as L, rpm_to_rad_s

OMEGA = rpm_to_rad_s(5000.0)
REV = 2 * np.pi / OMEGA  # one crank revolution, 12 ms
ADAPTIVE = ["RK45", "DOP853", "Radau", "BDF", "LSODA"]


def slider_x(t):
    theta = OMEGA * np.asarray(t)
    return R * np.cos(theta) + np.sqrt(L**2 - R**2 * np.sin(theta) ** 2)


@pytest.fixture(scope="module")
def ideal():
    # the non-IDA methods integrate index-1
    return dc.assemble(dc.mechanisms.slider_crank("ideal", gravity=0.0), "index1")


@pytest.fixture(scope="module")
def clearance():
    return dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")


# ----------------------------------------------------------------------------- ideal mechanism


@pytest.mark.parametrize("method", ADAPTIVE)
def test_ideal_one_revolution_matches_closed_form(ideal, method):
    te = np.linspace(0.0, REV, 121)
    rtol = 1e-8
    result = dc.simulate(ideal, REV, method=method.lower(), rtol=rtol, save=dc.SaveAt(times=te))  # case-insensitive
    assert result.success, result.message
    assert result.method == method
    np.testing.assert_array_equal(result.t, te)
    assert np.max(np.abs(result["slider.x"] - slider_x(te))) < 50 * rtol * 0.17
    # the multipliers come from the same system as IDA's: the driving moment agrees
    ref = dc.simulate(ideal, REV, rtol=1e-10, save=dc.SaveAt(times=te))
    moment = ref["drive.moment"]
    assert np.max(np.abs(result["drive.moment"] - moment)) < 1e-5 * np.max(np.abs(moment))
    stats = result.stats
    for key in ("n_steps", "n_res_evals", "n_jac_evals", "n_root_evals", "n_events", "solve_time", "setup_time"):
        assert key in stats
    assert stats["n_steps"] > 0 and stats["n_res_evals"] > stats["n_steps"]
    if method in ("Radau", "BDF"):
        assert stats["n_jac_evals"] > 0 and stats["n_lu"] > 0
    elif method in ("RK45", "DOP853"):
        assert stats["n_jac_evals"] == 0
    assert stats["n_events"] == 0 and len(result.events) == 0


@pytest.mark.parametrize("method, step, bound", [("rk4", 1e-5, 1e-10), ("euler", 1e-6, 2e-4)])
def test_ideal_fixed_step_matches_closed_form(ideal, method, step, bound):
    result = dc.simulate(ideal, REV, options=dc.SolverOptions(method=method, step=step))
    assert result.success, result.message
    # every step is an output point; the last one lands on t_end
    assert result.t[-1] == REV and result.stats["n_steps"] == round(REV / step)
    np.testing.assert_allclose(np.diff(result.t)[:-1], step, rtol=1e-6)
    assert np.max(np.abs(result["slider.x"] - slider_x(result.t))) < bound


def test_fixed_step_orders_of_convergence(ideal):
    """Halving the step divides the error by 2^p: rk4 p = 4, euler p = 1."""
    t_end = REV / 4
    te = np.linspace(0.0, t_end, 7)
    exact = slider_x(te)

    def error(method, step):
        result = dc.simulate(ideal, t_end, options=dc.SolverOptions(method=method, step=step), save=dc.SaveAt(times=te))
        return np.max(np.abs(result["slider.x"] - exact))

    rk4 = [error("rk4", h) for h in (1e-4, 5e-5)]
    euler = [error("euler", h) for h in (4e-6, 2e-6)]
    assert 13 < rk4[0] / rk4[1] < 19, rk4
    assert 1.8 < euler[0] / euler[1] < 2.2, euler


# ----------------------------------------------------------------------------- clearance joint


def first_impact(result):
    onset = result.events.of("clearance", kind="onset")
    return (onset.t[0], np.max(result["clearance.normal_force"]), np.max(result["clearance.penetration"]))


def test_first_impact_agrees_across_methods(clearance):
    """Issue 4 "must show": IDA (index1 and GGL) and DOP853, all at rtol 1e-10, see the same first
    impact: onset time, peak normal force and peak penetration agree to at least 4 significant digits
    (9 measured)."""
    t_end = 4e-4  # the first impact starts at ~0.227 ms and ends at ~0.281 ms
    te = np.concatenate([[0.0], np.linspace(2.2e-4, 3.0e-4, 8001)])  # 10 ns resolution of the peaks
    ggl = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "ggl")
    runs = {
        "ida/index1": dc.simulate(clearance, t_end, rtol=1e-10, save=dc.SaveAt(times=te)),
        "ida/ggl": dc.simulate(ggl, t_end, rtol=1e-10, save=dc.SaveAt(times=te)),
        "DOP853": dc.simulate(clearance, t_end, method="DOP853", rtol=1e-10, save=dc.SaveAt(times=te)),
    }
    values = {name: first_impact(r) for name, r in runs.items()}
    onset, force, penetration = values["ida/index1"]
    assert 2.2e-4 < onset < 2.3e-4 and force > 1e4 and 1e-5 < penetration < 5e-4
    for name, (t0, f, p) in values.items():
        assert runs[name].success
        assert len(runs[name].events) == 2  # one onset, one separation
        assert abs(t0 - onset) < 5e-5 * onset, (name, t0, onset)
        assert abs(f - force) < 5e-5 * force, (name, f, force)
        assert abs(p - penetration) < 5e-5 * penetration, (name, p, penetration)


def test_same_event_sequence_as_ida_before_chaos(clearance):
    """Over the first 5 ms (15 events) every adaptive scheme at tight tolerance and rk4 at a fine step
    find the same onsets and separations as IDA, at the same times. (IDA at rtol 1e-11: at 1e-10 its
    last approach speed is 4.7e-5 off DOP853's at 1e-12, rk4's 5.4e-5 the other way, and the two
    sat on the 1e-4 tolerance.)"""
    t_end = 5e-3
    ref = dc.simulate(clearance, t_end, rtol=1e-11)
    assert len(ref.events) >= 10
    for settings in [dc.SolverOptions(method="DOP853", rtol=1e-10), dc.SolverOptions(method="LSODA", rtol=1e-9),
                     dc.SolverOptions(method="rk4", step=2e-7)]:
        method = settings.method
        result = dc.simulate(clearance, t_end, options=settings)
        assert result.success, result.message
        assert result.events.kind == ref.events.kind, method
        np.testing.assert_allclose(result.events.t, ref.events.t, rtol=0, atol=2e-8, err_msg=method)
        onsets = result.events.of(kind="onset")
        np.testing.assert_allclose(onsets.approach_speed, ref.events.of(kind="onset").approach_speed, rtol=1e-4)
        # segments alternate free / contact and tile the time span
        assert result.segments[0][0] == 0.0 and result.segments[-1][1] == t_end
        modes = [s[2]["clearance"] for s in result.segments]
        assert modes[0] == "free" and all(a != b for a, b in zip(modes, modes[1:]))


def test_event_times_are_not_quantised_to_the_step(clearance):
    result = dc.simulate(clearance, 4e-4, options=dc.SolverOptions(method="rk4", step=1e-5))
    t_onset = result.events.t[0]
    assert abs(t_onset / 1e-5 - round(t_onset / 1e-5)) > 1e-3  # not on the step grid
    # the event point is an output point of the run, with the state at the event
    k = int(np.flatnonzero(result.t == t_onset)[0])
    np.testing.assert_array_equal(result.y[k], result.events[0].y)
    assert abs(result["clearance.penetration"][k]) < 1e-12
    ida = dc.simulate(clearance, 4e-4, rtol=1e-10)
    assert abs(t_onset - ida.events.t[0]) < 1e-9  # rk4 at 1e-5 s is still accurate at the first onset


def test_python_backend_matches_compiled(clearance):
    settings, save = dc.SolverOptions(method="rk4", step=1e-6), dc.SaveAt(times=np.linspace(0.0, 3e-4, 31))
    c = dc.simulate(clearance, 3e-4, options=settings.replace(backend="c"), save=save)
    py = dc.simulate(clearance, 3e-4, options=settings.replace(backend="python"), save=save)
    assert c.stats["backend"] == "c" and py.stats["backend"] == "python"
    np.testing.assert_allclose(py.events.t, c.events.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(py.y, c.y, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(py["clearance.normal_force"], c["clearance.normal_force"], rtol=1e-8, atol=1e-6)


def test_t_eval_and_store_steps(clearance):
    te = np.linspace(0.0, 4e-4, 41)
    for settings in [dc.SolverOptions(method="RK45", rtol=1e-9), dc.SolverOptions(method="rk4", step=1e-6)]:
        result = dc.simulate(clearance, 4e-4, options=settings, save=dc.SaveAt(times=te))
        np.testing.assert_array_equal(result.t, te)
        assert result.step_t.size > te.size  # the steps are recorded too
        dense = dc.simulate(clearance, 4e-4, rtol=1e-10, save=dc.SaveAt(times=te))
        np.testing.assert_allclose(result["slider.vx"], dense["slider.vx"], rtol=0, atol=5e-5)  # |vx| < 10 m/s
    bare = dc.simulate(clearance, 4e-4, method="DOP853", save=dc.SaveAt(steps=False))
    np.testing.assert_array_equal(bare.t, [0.0])
    assert len(bare.events) == 2


# ----------------------------------------------------------------------------- input and failures


def test_bad_method_step_and_formulation(ideal):
    scene = dc.mechanisms.slider_crank("ideal", gravity=0.0)
    with pytest.raises(dc.SceneError, match="dop853.*rk4.*euler"):
        dc.simulate(scene, 0.01, method="rk5")
    with pytest.raises(dc.SceneError, match="step="):
        dc.simulate(ideal, 0.01, method="rk4")
    with pytest.raises(dc.SceneError, match="step="):
        dc.simulate(ideal, 0.01, options=dc.SolverOptions(method="euler", step=-1e-5))
    with pytest.raises(dc.SceneError, match="only for the fixed-step"):
        dc.simulate(ideal, 0.01, options=dc.SolverOptions(method="DOP853", step=1e-5))
    with pytest.raises(dc.SceneError, match="only for the fixed-step"):
        dc.simulate(ideal, 0.01, options=dc.SolverOptions(step=1e-5))  # IDA chooses its own steps
    with pytest.raises(dc.SceneError, match="IDA only"):
        dc.simulate(scene, 0.01, method="Radau", options=dc.SolverOptions(formulation="ggl"))
    with pytest.raises(dc.SceneError, match="IDA only"):
        dc.simulate(dc.assemble(scene, "ggl"), 0.01, options=dc.SolverOptions(method="rk4", step=1e-5))


def test_failing_run_returns_partial_result():
    # a model of its own: a run that ends in a blow-up may leave its contact logic in a storm state
    clearance = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")
    result = dc.simulate(clearance, 0.024, on_failure="return", options=dc.SolverOptions(method="euler", step=1e-4))
    assert not result.success and result.status == -1
    assert result.message.startswith("euler failed at t=")
    assert "'clearance' in contact" in result.message and "smaller step" in result.message
    assert 0.0 < result.t[-1] < 0.024 and len(result.events) >= 1
    with pytest.raises(dc.SolveError, match="euler failed") as info:
        dc.simulate(clearance, 0.024, options=dc.SolverOptions(method="euler", step=1e-4))
    assert info.value.result.success is False
    capped = dc.simulate(clearance, 0.024, method="DOP853", on_failure="return", options=dc.SolverOptions(max_steps=30))
    assert not capped.success and "max_steps=30" in capped.message
    assert capped.stats["n_steps"] == 30


def test_hermite_check_finds_a_crossing_inside_a_step():
    # G = -1 at both ends but rising then falling fast: the cubic has a maximum above zero mid-step
    s = _candidate(-1.0, 10.0, -1.0, -10.0, 1.0)
    assert s == pytest.approx(0.5)
    assert _candidate(-1.0, 10.0, -1.0, -10.0, 1.0, hermite=False) == -1.0
    assert _candidate(-1.0, 0.1, -1.0, -0.1, 1.0) == -1.0  # a small bump stays below zero
    assert _candidate(-1.0, 1.0, 2.0, 1.0, 1.0) == 1.0  # a sign change: the far end of the step
    assert _candidate(1e-3, -1.0, 2.0, 1.0, 1.0) == -1.0  # already past zero at the start
    (u, is_max, p), = _cubic_extrema(-1.0, 10.0, -1.0, -10.0, 1.0)
    assert is_max and u == pytest.approx(0.5) and p == pytest.approx(1.5)


def test_without_a_compiler_falls_back_to_python(monkeypatch, tmp_path):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    monkeypatch.setenv("DAECLEAR_CACHE_DIR", str(tmp_path))  # nothing cached there
    clear_memos()  # nor loaded in this process (models of one structure share their library)
    model = dc.assemble(dc.mechanisms.slider_crank("ideal", gravity=0.0), "index1")
    with pytest.warns(dc.DaeclearWarning, match="compiled right-hand side is unavailable"):
        result = dc.simulate(model, 1e-3, options=dc.SolverOptions(method="rk4", step=1e-5))
    assert result.success and result.stats["backend"] == "python"
    assert np.max(np.abs(result["slider.x"] - slider_x(result.t))) < 1e-10
    with pytest.raises(dc.DaeclearError, match="compiled ODE backend"):
        dc.simulate(model, 1e-3, options=dc.SolverOptions(method="rk4", step=1e-5, backend="c"))
