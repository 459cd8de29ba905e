"""SolverOptions, restarts from a state (simulate(..., t0=, y0=)) and models that runs leave unchanged.

Restarts: a run 0 -> T and a run 0 -> t0 continued from its last state t0 -> T compute the same
trajectory to the integration tolerance (the second run starts a fresh BDF history, so not to
round-off). Measured at rtol 1e-9 on the chapter's slider-crank with a revolute clearance joint,
restarted in free flight: the same 51 contact events, slider x within 1e-6 and eccentricity within
8e-6 of their ranges. A restart in contact is no exact continuation (the approach speed latched at
the onset is run history, not state: the restart latches the penetration rate at t0), so the
contact case restarts in free flight; with the elastic Hertz law (no damping, nothing latched) a
restart anywhere keeps mechanical plus elastic energy constant.
"""

from __future__ import annotations

import dataclasses
import json
import threading

import h5py
import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import SceneError
from daeclear.model.mechanisms import chain, slider_crank

T = 0.024  # the chapter's slider-crank: two crank turns at 5000 rpm


@pytest.fixture(scope="module")
def ideal_model() -> dc.DAEModel:
    return dc.assemble(slider_crank())


@pytest.fixture(scope="module")
def clearance_model() -> dc.DAEModel:
    return dc.assemble(slider_crank("revolute"))


# --------------------------------------------------------------------------- SolverOptions


def test_options_are_checked_normalised_and_frozen() -> None:
    options = dc.SolverOptions(method="RK45", atol=[1e-9, 1e-8], rtol=1e-7)
    assert options.method == "rk45" and options.atol == (1e-9, 1e-8) and options.rtol == 1e-7
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.rtol = 1e-3  # type: ignore[misc]
    assert options.replace(rtol=1e-4).rtol == 1e-4 and options.rtol == 1e-7
    assert options.replace(method="rk4", step=1e-5).step == 1e-5


@pytest.mark.parametrize("changes, message", [
    ({"method": "rk5"}, "SolverOptions: method='rk5', must be one of ida, rk45"),
    ({"rtol": 0.5}, "SolverOptions: rtol=0.5, must be a finite number in [1e-14, 0.01]"),
    ({"atol": -1.0}, "SolverOptions: atol=-1.0, must be a finite number > 0"),
    ({"atol": [1e-9, float("nan")]}, "SolverOptions: atol="),
    ({"max_step": -1.0}, "SolverOptions: max_step=-1.0 s, must be a finite number >= 0"),
    ({"max_steps": 10.0}, "SolverOptions: max_steps=10.0, must be an integer >= 1"),
    ({"formulation": "index2"}, "SolverOptions: formulation='index2', must be one of index1, ggl"),
    ({"backend": "gpu"}, "SolverOptions: backend='gpu', must be one of auto, c, python"),
    ({"linear_solver": "lu"}, "SolverOptions: linear_solver='lu', must be one of auto, reduced, dense, sparse"),
    ({"start": "centred"}, "SolverOptions: start='centred', must be one of ideal, declared"),
    ({"allow_penetration": "no"}, "SolverOptions: allow_penetration='no', must be True or False"),
    ({"track_work": 1}, "SolverOptions: track_work=1, must be True or False"),
    ({"method": "rk4"}, "method='rk4' is a fixed-step scheme and needs step="),
    ({"step": 1e-5}, "step=1e-05 is only for the fixed-step methods"),
    ({"method": "euler", "step": 0.0}, "step=0.0 s, must be a finite number > 0"),
])
def test_bad_settings_name_field_value_and_rule(changes: dict, message: str) -> None:
    with pytest.raises(SceneError) as err:
        dc.SolverOptions(**changes)
    assert message in str(err.value)
    with pytest.raises(SceneError) as err:  # replace checks the same way
        dc.SolverOptions().replace(**changes)
    assert message in str(err.value)


def test_unknown_settings_are_named_with_the_close_match() -> None:
    with pytest.raises(SceneError, match=r"SolverOptions.replace: rtl=\.\.\., must be left out.*did you mean rtol"):
        dc.SolverOptions().replace(rtl=1e-6)
    with pytest.raises(SceneError, match=r"SolverOptions.from_dict: t_eval=.*the settings are method, rtol"):
        dc.SolverOptions.from_dict({"t_eval": [0.0, 1.0]})


@pytest.mark.parametrize("options", [
    dc.SolverOptions(),
    dc.SolverOptions(method="rk4", step=1e-5, formulation="index1", backend="python", max_steps=1000),
    dc.SolverOptions(rtol=1e-9, atol=[1e-12, 2e-12, 3e-12], linear_solver="sparse", start="declared",
                     allow_penetration=True, track_work=True, max_step=1e-4),
    dc.SolverOptions(atol=1e-10),
])
def test_plain_dict_round_trips_through_json_and_hdf5(options: dc.SolverOptions, tmp_path) -> None:
    data = options.to_dict()
    assert json.loads(json.dumps(data)) == data  # JSON types only
    assert dc.SolverOptions.from_dict(json.loads(json.dumps(data))) == options
    with h5py.File(tmp_path / "options.h5", "w") as f:  # as a sweep stores its options
        f.attrs["options_json"] = json.dumps(data, sort_keys=True)
    with h5py.File(tmp_path / "options.h5", "r") as f:
        assert dc.SolverOptions.from_dict(json.loads(f.attrs["options_json"])) == options


def test_simulate_takes_the_options_object_and_an_explicit_keyword_overrides_it(ideal_model) -> None:
    loose, tight = dc.SolverOptions(rtol=1e-4), dc.SolverOptions(rtol=1e-8)
    by_keyword = dc.simulate(ideal_model, T / 4, rtol=1e-4)
    by_options = dc.simulate(ideal_model, T / 4, options=loose)
    assert by_options.stats["n_steps"] == by_keyword.stats["n_steps"]
    np.testing.assert_array_equal(by_options.y, by_keyword.y)
    overridden = dc.simulate(ideal_model, T / 4, options=loose, rtol=1e-8)
    reference = dc.simulate(ideal_model, T / 4, options=tight)
    assert overridden.parameters["simulate"]["rtol"] == 1e-8
    assert overridden.stats["n_steps"] == reference.stats["n_steps"] > 2 * by_keyword.stats["n_steps"]
    np.testing.assert_array_equal(overridden.y, reference.y)
    # a keyword given as the default value still overrides (it was given)
    assert dc.simulate(ideal_model, T / 4, options=loose, rtol=1e-6).parameters["simulate"]["rtol"] == 1e-6
    with pytest.raises(SceneError,
                       match=r"simulate: options=\{'rtol': 1e-06\}, must be None or a daeclear.SolverOptions"):
        dc.simulate(ideal_model, T, options={"rtol": 1e-6})  # type: ignore[arg-type]
    with pytest.raises(SceneError, match=r"simulate: rtol=2.0, must be a finite number in \[1e-14, 0.01\]"):
        dc.simulate(ideal_model, T, options=loose, rtol=2.0)  # a bad keyword: the rule, named as given
    with pytest.raises(SceneError, match=r"simulate: method='rk4' is a fixed-step scheme and needs step="):
        dc.simulate(ideal_model, T, options=loose, method="rk4")


def test_merged_options_of_the_same_plain_keywords_are_equal() -> None:
    """The same keywords merge to equal options (each call checks them: no memo, issue 35); a keyword
    of another type or value is checked (True and 1 are not the same flag)."""
    base = dc.SolverOptions(rtol=1e-4)
    first = base.merged(rtol=1e-7, track_work=True)
    assert first.rtol == 1e-7 and first.track_work is True and base.rtol == 1e-4
    assert base.merged(rtol=1e-7, track_work=True) == first
    assert base.merged(rtol=1e-8, track_work=True).rtol == 1e-8
    assert dc.SolverOptions(rtol=1e-5).merged(rtol=1e-7, track_work=True) == first  # rtol overridden
    assert dc.SolverOptions(rtol=1e-5, max_steps=10).merged(rtol=1e-7, track_work=True) != first
    with pytest.raises(SceneError, match=r"simulate: track_work=1, must be True or False"):
        base.merged(rtol=1e-7, track_work=1)
    with pytest.raises(SceneError, match=r"where: rtol=2.0, must be a finite number"):
        base.merged(where="where", rtol=2.0)
    with pytest.raises(SceneError, match=r"where: rtol=2.0, must be a finite number"):  # never stored
        base.merged(where="where", rtol=2.0)


def test_options_pick_the_method_of_a_run(ideal_model) -> None:
    scene = slider_crank()
    rk4 = dc.simulate(scene, T / 8, options=dc.SolverOptions(method="rk4", step=1e-5, formulation="index1"))
    assert rk4.parameters["simulate"]["method"] == "rk4" and rk4.stats["n_steps"] == round(T / 8 / 1e-5)


# --------------------------------------------------------------------------- restarts


def test_bad_start_time_and_state_are_refused_before_any_work(ideal_model) -> None:
    y = dc.simulate(ideal_model, T / 8).y[-1]
    with pytest.raises(SceneError, match=r"simulate: t0=0.024 s, must be a finite number >= 0 and < t_end=0.024 s"):
        dc.simulate(ideal_model, T, t0=T, y0=y)
    with pytest.raises(SceneError, match=r"simulate: t0=-0.001 s"):
        dc.simulate(ideal_model, T, t0=-1e-3)
    with pytest.raises(SceneError, match=r"simulate: t0=nan s"):
        dc.simulate(ideal_model, T, t0=float("nan"))
    n = ideal_model.n_states
    with pytest.raises(SceneError, match=rf"simulate: y0=.*must be {n} finite numbers .*not shape \({n - 1},\)"):
        dc.simulate(ideal_model, T, t0=T / 8, y0=y[:-1])
    bad = y.copy()
    bad[4] = np.nan
    with pytest.raises(SceneError, match=r"simulate: y0=.*\(nan at index 4\)"):
        dc.simulate(ideal_model, T, t0=T / 8, y0=bad)
    with pytest.raises(SceneError,
                       match=r"simulate: y0=array of shape \(2, 36\), must be 36 finite numbers .*not shape \(2, 36\)"):
        dc.simulate(ideal_model, T, y0=np.vstack([y, y]))
    with pytest.raises(SceneError, match=r"simulate: save.times=.*values in \[t0=0.003, t_end=0.024\]"):
        dc.simulate(ideal_model, T, t0=T / 8, y0=y, save=dc.SaveAt(times=[0.0, T]))
    with pytest.raises(SceneError, match=r"simulate: y0=.*must be 27 finite numbers"):  # a Scene: after assembly
        dc.simulate(slider_crank(), T, method="rk45", t0=T / 8, y0=np.zeros(3))


def test_a_bad_state_for_a_scene_is_refused_before_assembly(monkeypatch) -> None:
    from daeclear.solvers import driver  # every method's run is the driver's

    def no_assembly(*args, **kwargs):
        raise AssertionError("assembled before the state was checked")

    monkeypatch.setattr(driver, "assemble", no_assembly)
    with pytest.raises(SceneError, match=r"simulate: y0=\[0.0, inf\], must be finite numbers .*\(inf at index 1\)"):
        dc.simulate(slider_crank(), T, t0=T / 8, y0=[0.0, np.inf])
    with pytest.raises(SceneError, match=r"simulate: y0=\[\], must be finite numbers .*not shape \(0,\)"):
        dc.simulate(slider_crank(), T, y0=[])


@pytest.mark.parametrize("backend", ["c", "python"])
def test_ida_restart_from_the_last_state_continues_the_run(ideal_model, backend: str) -> None:
    """Ideal joints (GGL): 0 -> T against 0 -> T/2 then T/2 -> T, compared on one output grid."""
    grid = np.linspace(0.0, T, 97)
    full = dc.simulate(ideal_model, T, rtol=1e-9, options=dc.SolverOptions(backend=backend), save=dc.SaveAt(times=grid))
    half = dc.simulate(ideal_model, T / 2, rtol=1e-9, options=dc.SolverOptions(backend=backend),
                       save=dc.SaveAt(times=grid[grid <= T / 2]))
    rest = dc.simulate(ideal_model, T, rtol=1e-9, t0=T / 2, y0=half.y[-1], options=dc.SolverOptions(backend=backend),
                       save=dc.SaveAt(times=grid[grid >= T / 2]))
    assert rest.t[0] == T / 2 and rest.t[-1] == T and rest.success
    if backend == "c":  # a restart is numbers only: nothing compiled
        assert rest.stats["compile_time"] == 0.0 and rest.stats["cache_hit"]
    assert rest.parameters["simulate"]["t0"] == T / 2 and rest.parameters["simulate"]["start"] == "state"
    np.testing.assert_array_equal(rest.y[0, :ideal_model.n_q], half.y[-1, :ideal_model.n_q])  # kept as given
    for channel in ("slider.x", "slider.vx", "rod.omega", "lambda.drive"):
        scale = np.ptp(full[channel])
        assert np.abs(rest[channel] - full[channel][grid >= T / 2]).max() < 1e-6 * scale, channel
    # the multipliers are recomputed at t0 (a stale or zero lambda would be off by the whole load)
    np.testing.assert_allclose(rest["lambda.drive"][0], full["lambda.drive"][48], rtol=1e-6)


@pytest.mark.parametrize("method, options", [("rk45", {}), ("lsoda", {}), ("rk4", {"step": 2e-5})])
def test_ode_methods_restart_from_the_last_state(method: str, options: dict) -> None:
    model = dc.assemble(slider_crank(), "index1")
    grid = np.linspace(0.0, T, 49)
    settings = dc.SolverOptions(method=method, rtol=1e-9, **options)
    full = dc.simulate(model, T, options=settings, save=dc.SaveAt(times=grid))
    half = dc.simulate(model, T / 2, options=settings, save=dc.SaveAt(times=grid[grid <= T / 2]))
    rest = dc.simulate(model, T, t0=T / 2, y0=half.y[-1], options=settings, save=dc.SaveAt(times=grid[grid >= T / 2]))
    assert rest.t[0] == T / 2 and rest.t[-1] == T
    if method == "rk4":  # the same fixed steps from T/2 on (T/2 is a whole number of steps): equal to round-off
        assert np.abs(rest["slider.x"] - full["slider.x"][grid >= T / 2]).max() < 1e-12
    else:
        assert np.abs(rest["slider.x"] - full["slider.x"][grid >= T / 2]).max() < 1e-6 * np.ptp(full["slider.x"])
    assert np.all(rest.step_t >= T / 2)


@pytest.mark.parametrize("method", ["ida", "rk45"])
def test_drivers_are_evaluated_at_the_true_start_time(method: str) -> None:
    """A restart at t0 from a state whose crank angle is off its driver: GGL projects it onto the
    driver at t0 (crank angle omega t0, not 0), and every later point has crank angle omega t."""
    formulation = "ggl" if method == "ida" else "index1"
    model = dc.assemble(slider_crank(), formulation)
    omega = float(model.parameter("drive.speed")[0])
    t0 = 0.37 * T
    y = dc.simulate(model, t0, rtol=1e-9, method=method).y[-1]
    rest = dc.simulate(model, T, t0=t0, y0=y, rtol=1e-9, method=method, save=dc.SaveAt(every=T / 50))
    assert rest.t[0] == t0 and rest.t[-1] == T
    np.testing.assert_allclose(np.diff(rest.t), (T - t0) / np.floor((T - t0) / (T / 50)), rtol=1e-9)
    np.testing.assert_allclose(rest["crank.phi"], omega * rest.t, rtol=1e-8, atol=1e-9)
    if method == "ida":  # off the driver by 0.01 rad: projected back onto it at the true time
        off = y.copy()
        off[model.state_names.index("crank.phi")] += 0.01
        moved = dc.simulate(model, T, t0=t0, y0=off, rtol=1e-9, save=dc.SaveAt(every=T / 50))
        np.testing.assert_allclose(moved["crank.phi"][0], omega * t0, rtol=1e-12)
        np.testing.assert_allclose(moved["slider.x"], rest["slider.x"], atol=1e-7)


def test_contact_restart_in_free_flight_reproduces_the_events(clearance_model) -> None:
    full = dc.simulate(clearance_model, T, rtol=1e-9, save=dc.SaveAt(every=T / 240))
    free = [(a, b) for a, b, modes in full.segments if modes["clearance"] == "free" and b - a > 2e-4 and a > 2e-3]
    t0 = round(0.5 * (free[0][0] + free[0][1]), 5)  # the middle of the first long flight after the start
    head = dc.simulate(clearance_model, t0, rtol=1e-9)
    rest = dc.simulate(clearance_model, T, rtol=1e-9, t0=t0, y0=head.y[-1], save=dc.SaveAt(times=full.t[full.t >= t0]))
    after = [e for e in full.events if e.t > t0]
    assert len(after) >= 10 and len(rest.events) == len(after)
    assert all(a.kind == b.kind and b.t >= t0 for a, b in zip(after, rest.events))
    assert max(abs(a.t - b.t) for a, b in zip(after, rest.events)) < 1e-6  # s; contacts last ~30 us
    sel = full.t >= t0
    for channel, bound in (("slider.x", 1e-5), ("clearance.eccentricity", 1e-4)):
        assert np.abs(rest[channel] - full[channel][sel]).max() < bound * np.ptp(full[channel]), channel
    assert rest.segments[0][0] == t0 and rest.segments[0][2] == {"clearance": "free"}


def test_a_restart_starting_in_contact_sets_the_mode_from_the_gap(clearance_model) -> None:
    full = dc.simulate(clearance_model, T, rtol=1e-8)
    inside = [(a, b) for a, b, modes in full.segments if modes["clearance"] == "contact" and b - a > 1e-4]
    t0 = 0.5 * (inside[0][0] + inside[0][1])
    head = dc.simulate(clearance_model, t0, rtol=1e-8)
    rest = dc.simulate(clearance_model, t0 + 1e-5, rtol=1e-8, t0=t0, y0=head.y[-1])
    assert rest.segments[0][2] == {"clearance": "contact"}
    np.testing.assert_allclose(rest["clearance.penetration"][0], head["clearance.penetration"][-1], rtol=1e-9)
    assert rest["clearance.penetration"][0] > 0


def test_an_elastic_contact_restarted_in_contact_keeps_its_force() -> None:
    """Hertz: the force is the penetration's alone (nothing latched), so it is continuous at t0."""
    model = dc.assemble(chain(1, law="hertz"))
    full = dc.simulate(model, 0.05, rtol=1e-8)
    inside = [(a, b) for a, b, modes in full.segments if modes["pin1"] == "contact" and b - a > 1e-5]
    t0 = 0.5 * (inside[0][0] + inside[0][1])
    head = dc.simulate(model, t0, rtol=1e-8)
    rest = dc.simulate(model, t0 + 1e-5, rtol=1e-8, t0=t0, y0=head.y[-1])
    assert rest.segments[0][2] == {"pin1": "contact"} and head["pin1.normal_force"][-1] > 0
    np.testing.assert_allclose(rest["pin1.normal_force"][0], head["pin1.normal_force"][-1], rtol=1e-9)


def test_elastic_frictionless_contact_keeps_its_energy_across_a_restart() -> None:
    """Hertz (no damping, nothing latched): E_mech + elastic is one constant over both runs."""
    scene = chain(1, law="hertz")
    law = scene["pin1"].resolved_law()
    model = dc.assemble(scene)

    def total(result: dc.Result) -> np.ndarray:
        delta = np.maximum(result["pin1.penetration"], 0.0)
        return result["energy.mechanical"] + law.stiffness * delta ** (law.exponent + 1) / (law.exponent + 1)

    first = dc.simulate(model, 0.025, rtol=1e-8)
    second = dc.simulate(model, 0.05, rtol=1e-8, t0=0.025, y0=first.y[-1])
    assert len(first.events.of(kind="onset")) >= 1 and len(second.events.of(kind="onset")) >= 1
    energy = np.concatenate([total(first), total(second)])
    scale = max(first["energy.kinetic"].max(), second["energy.kinetic"].max())
    assert np.ptp(energy) < 1e-6 * scale
    assert abs(total(second)[0] - total(first)[-1]) < 1e-9 * scale  # the restart itself changes nothing


# --------------------------------------------------------------------------- immutable models


def _snapshot(model: dc.DAEModel) -> dict:
    """Every field of a model, arrays copied, contact logic as its fields' values."""
    out = {}
    for f in dataclasses.fields(model):
        value = getattr(model, f.name)
        if isinstance(value, np.ndarray):
            value = value.copy()
        elif f.name == "contacts":
            value = [repr(vars(logic)) for logic in value]
        out[f.name] = value
    return out


def _same(a: dict, b: dict) -> bool:
    return all(np.array_equal(a[k], b[k]) if isinstance(a[k], np.ndarray) else a[k] == b[k] for k in a)


def test_model_arrays_are_read_only(ideal_model) -> None:
    # a model bound to other numbers of a known structure, and one with new parameters, are made by the
    # constructor like any: their arrays are read-only too, and the bound numbers are theirs
    bound = dc.assemble(dc.mechanisms.slider_crank(rpm=4000.0, slider_mass=0.2))
    assert bound.functions is dc.assemble(dc.mechanisms.slider_crank()).functions  # one template
    for model in (ideal_model, bound, bound.with_parameters({"crank.mass": 0.4})):
        for name in ("q_guess", "v_guess", "mass_diagonal", "parameter_values"):
            with pytest.raises(ValueError, match="read-only"):
                getattr(model, name)[0] = 1.0
    assert bound.mass_diagonal[6] == 0.2 and bound.parameter("drive.speed")[0] == pytest.approx(4000.0 * np.pi / 30)


def test_runs_leave_the_model_unchanged_and_are_independent(clearance_model) -> None:
    before = _snapshot(clearance_model)
    first = dc.simulate(clearance_model, T / 2, rtol=1e-7, save=dc.SaveAt(every=T / 200))
    assert first.stats["n_events"] >= 10  # the contact logic did work
    assert _same(_snapshot(clearance_model), before)
    second = dc.simulate(clearance_model, T / 2, rtol=1e-7, save=dc.SaveAt(every=T / 200))
    np.testing.assert_array_equal(first.y, second.y)
    assert [(e.t, e.kind) for e in first.events] == [(e.t, e.kind) for e in second.events]
    for e in first.events:  # the compiled loop's events: plain floats, a read-only state of their own run
        assert type(e.t) is float and type(e.approach_speed) is float and not e.y.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            e.y[0] = 1.0
    for backend in ("python", "c"):  # two runs at the same time in threads, from one assembled model
        results: dict[int, dc.Result] = {}

        def run(k: int, backend: str, results: dict[int, dc.Result]) -> None:
            results[k] = dc.simulate(clearance_model, T / 4, rtol=1e-7, options=dc.SolverOptions(backend=backend),
                                     save=dc.SaveAt(every=T / 200))

        threads = [threading.Thread(target=run, args=(k, backend, results)) for k in range(2)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        alone = dc.simulate(clearance_model, T / 4, rtol=1e-7, options=dc.SolverOptions(backend=backend),
                            save=dc.SaveAt(every=T / 200))
        for k in range(2):
            np.testing.assert_array_equal(results[k].y, alone.y)
            assert [(e.t, e.kind) for e in results[k].events] == [(e.t, e.kind) for e in alone.events]
    assert _same(_snapshot(clearance_model), before)


def test_a_buffered_function_gives_each_thread_its_own_buffer() -> None:
    """The contact logic's gap function is shared by the runs of a model (a run copies none of
    it): threads calling it at the same time each get their own inputs' results, a pickled copy
    (a process pool's) evaluates the same, and two models of one structure (one CasADi function,
    other numbers) sharing a thread's buffer each evaluate with their own numbers."""
    import pickle

    import casadi as ca

    from daeclear.assembly.symbolic import BufferedFunction

    x, p = ca.SX.sym("x", 2), ca.SX.sym("p")
    function = BufferedFunction(ca.Function("f", [x, p], [x * p, ca.sum1(x)]), bound=(np.array([3.0]),))
    failures: list[str] = []

    def hammer(k: int) -> None:
        for i in range(2000):
            value = np.array([k, i], dtype=float)
            scaled, total = function(value)
            if not (np.array_equal(scaled, 3.0 * value) and total[0] == k + i):
                failures.append(f"thread {k}, call {i}: {scaled}, {total}")
                return

    threads = [threading.Thread(target=hammer, args=(k,)) for k in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    copied = pickle.loads(pickle.dumps(function))
    np.testing.assert_array_equal(copied(np.array([1.0, 2.0]))[0], [3.0, 6.0])
    # two models of one structure share the thread's buffer, each with its own bound numbers
    other = BufferedFunction(function.function, bound=(np.array([-2.0]),))
    for _ in range(3):
        np.testing.assert_array_equal(function(np.array([1.0, 2.0]))[0], [3.0, 6.0])
        np.testing.assert_array_equal(other(np.array([1.0, 2.0]))[0], [-2.0, -4.0])


def test_ode_methods_leave_the_model_unchanged() -> None:
    model = dc.assemble(slider_crank("revolute"), "index1")
    before = _snapshot(model)
    result = dc.simulate(model, T / 4, method="rk45", rtol=1e-7)
    assert result.stats["n_events"] >= 2
    assert _same(_snapshot(model), before)


# --------------------------------------------------------------------------- studies


def test_work_precision_takes_solver_options() -> None:
    from daeclear.studies.accuracy import work_precision

    span = T / 8
    study = work_precision(
        slider_crank(), span, channels=["slider.vx"], rtols=(1e-5,), steps=(2e-5,), n_eval=51, repeats=0,
        window=(0.0, span), reference=dc.SolverOptions(method="dop853", rtol=1e-11),
        methods={"IDA options": dc.SolverOptions(formulation="index1", rtol=1e-3),
                 "IDA dict": {"method": "ida", "formulation": "index1"},
                 "RK4 options": dc.SolverOptions(method="rk4", step=1e-5)})
    rows = {r["label"]: r for r in study.rows}
    assert rows["IDA options"]["tolerance"] == 1e-5  # the study's rtol replaces the entry's
    assert rows["IDA options"]["error"] == rows["IDA dict"]["error"] < 1e-3
    assert rows["IDA options"]["n_steps"] == rows["IDA dict"]["n_steps"]
    assert rows["RK4 options"]["tolerance"] == 2e-5 and rows["RK4 options"]["n_steps"] == round(span / 2e-5)
    assert study.reference_options == dc.SolverOptions(method="dop853", rtol=1e-11).to_dict()
    assert study.reference.parameters["simulate"]["method"] == "DOP853"


def test_stability_cases_take_solver_options() -> None:
    from daeclear.studies.stability import CASES, run_case

    case = next(c for c in CASES if c.name == "clearance 0.5 mm")
    loose = run_case(case, n_eval=201, options=dc.SolverOptions(rtol=1e-4))
    tight = run_case(case, n_eval=201, options=dc.SolverOptions(rtol=1e-7))
    # rtol 1e-7 against 1e-4: measured 2.0-2.4 times the steps
    assert loose["finished"] and tight["finished"] and tight["n_steps"] > 1.5 * loose["n_steps"]
    overridden = run_case(case, rtol=1e-7, n_eval=201, options=dc.SolverOptions(rtol=1e-4))  # rtol wins
    assert overridden["n_steps"] == tight["n_steps"]


def test_the_restart_example_runs(capsys) -> None:
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parent.parent / "examples" / "restart_from_state.py"
    spec = importlib.util.spec_from_file_location("restart_from_state", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick"]) == 0
    out = capsys.readouterr().out
    assert "in free flight, from rtol 1e-06 to rtol 1e-09" in out
    restart_alone = float(out.split("the restart alone")[1].split("(")[2].split(" of the stroke")[0])
    assert restart_alone < 1e-4  # a restart continues the run (measured 2e-6 on the full example)


def test_the_work_state_carries_over_a_restart() -> None:
    """track_work: the integrated work is part of the state, so a restart continues it (the energy
    balance E - E0 - W stays closed over both parts)."""
    model = dc.assemble(slider_crank(), track_work=True)
    k = model.state_names.index("work.input")
    grid = np.linspace(0.0, T, 49)
    full = dc.simulate(model, T, rtol=1e-9, save=dc.SaveAt(times=grid))
    head = dc.simulate(model, T / 2, rtol=1e-9, save=dc.SaveAt(times=grid[grid <= T / 2]))
    rest = dc.simulate(model, T, rtol=1e-9, t0=T / 2, y0=head.y[-1], save=dc.SaveAt(times=grid[grid >= T / 2]))
    assert rest.y[0, k] == head.y[-1, k] and abs(head.y[-1, k]) > 0
    scale = np.ptp(full.y[:, k])
    assert np.abs(rest.y[:, k] - full.y[grid >= T / 2, k]).max() < 1e-6 * scale
    balance = np.concatenate([head["energy.mechanical"] - head.y[:, k], rest["energy.mechanical"] - rest.y[:, k]])
    assert np.ptp(balance) < 1e-6 * np.ptp(full["energy.mechanical"])


@pytest.mark.parametrize("linear_solver", ["reduced", "dense", "sparse"])
def test_a_run_on_a_pooled_c_session_equals_a_run_on_a_new_one(linear_solver: str) -> None:
    """simulate closes its compiled session into a pool, and the next run of the same structure
    and linear solver takes it (dc_reset): after a run with other numbers and settings that
    failed, a run equals the same run on a newly opened session, step for step (the sparse LU
    keeps its symbolic factorization, which depends on the pattern alone)."""
    from daeclear.engine import c_handle

    def handles() -> list:
        return [h for pooled in c_handle._POOL.values() for h in pooled]

    scene, t_end = slider_crank("revolute", clearance=1e-4), 0.004
    settings = dict(t_end=t_end, save=dc.SaveAt(times=np.linspace(0.0, t_end, 41)), rtol=1e-7,
                    options=dc.SolverOptions(backend="c", linear_solver=linear_solver))
    c_handle._POOL.clear()
    fresh = dc.simulate(scene, **settings)
    c_handle._POOL.clear()  # the next run opens its own session
    failed = dc.simulate(slider_crank("revolute", clearance=3e-4, restitution=0.5), t_end=t_end, rtol=1e-5,
                         on_failure="return",
                         options=dc.SolverOptions(max_step=1e-6, max_steps=300, backend="c",
                                                  linear_solver=linear_solver))
    assert not failed.success and "max_steps" in failed.message
    (handle,) = handles()
    again = dc.simulate(scene, **settings)
    assert handles() == [handle]  # taken and given back
    assert again.stats["linear_solver"] == fresh.stats["linear_solver"] == linear_solver
    assert len(fresh.events) >= 4
    assert [(e.t, e.kind) for e in again.events] == [(e.t, e.kind) for e in fresh.events]
    np.testing.assert_array_equal(again.step_t, fresh.step_t)
    np.testing.assert_array_equal(again.y, fresh.y)
    counters = [k for k in fresh.stats if k.startswith("n_")]
    assert {k: again.stats[k] for k in counters} == {k: fresh.stats[k] for k in counters}
