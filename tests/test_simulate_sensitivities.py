"""``simulate(..., sensitivities=[...])``: forward sensitivities carried by the one run driver (issue 43).

Against independent references: the Kelvin-Voigt radial impact's closed form (differentiated by the complex
step, tests/test_sensitivity_radial_impact.py), and a file written and read back. The arguments are checked
before any work, each refusal naming the field, the value and what is allowed.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.solvers import driver
from test_sensitivity_radial_impact import (NAMES, P0, T, T_CONTACT, complex_step, kelvin_voigt_force,
                                            kelvin_voigt_radial, radial_scene)

D, K = P0[1], P0[0]


@pytest.fixture(scope="module")
def kv_model() -> dc.DAEModel:
    return dc.assemble(radial_scene(dcc.KelvinVoigt(stiffness=K, damping=D)))


def kv_run(model: dc.DAEModel, backend: str = "python", **keywords: object) -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)  # atol at round-off, raised
        return dc.simulate(model, T, rtol=1e-10, options=dc.SolverOptions(start="declared", backend=backend),
                           sensitivities=NAMES, **keywords)  # type: ignore[arg-type]


@pytest.mark.parametrize("backend", ["python", "c"])
def test_simulate_reproduces_the_closed_form(kv_model, backend: str) -> None:
    """S(T) of x and vx, each event time's sensitivity and a channel's (the normal force in contact, the
    chain rule through its function) from simulate, against the closed form's complex-step derivatives."""
    result = kv_run(kv_model, backend, save=dc.SaveAt(times=[0.0, T_CONTACT, T]))
    assert result.success and result.sensitivity_names == tuple(NAMES)
    want = complex_step(kelvin_voigt_radial, P0)
    x, vx, t_sep = kelvin_voigt_radial(P0)
    assert result["journal.x"][-1] == pytest.approx(x, abs=1e-9)
    assert result.sensitivity("journal.x").shape == (3, 3)
    assert result.sensitivity("journal.x")[-1] == pytest.approx(want[0], rel=1e-6, abs=0.0)
    assert result.sensitivity("journal.vx")[-1] == pytest.approx(want[1], rel=1e-6, abs=1e-9)
    assert result.sensitivity("journal.vx", "clearance.clearance")[-1] == pytest.approx(0.0, abs=1e-9)
    assert result.sensitivity("journal.x")[0] == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)  # x(0) = 0 for all p
    onset, separation = result.sensitivities.events
    assert (onset.kind, separation.kind) == ("onset", "separation")
    assert onset.dt_dp == pytest.approx([0.0, 0.0, 1.0], abs=1e-12)  # dt1/dz0 = 1/u
    assert separation.t == pytest.approx(t_sep, rel=1e-9, abs=0.0)
    assert separation.dt_dp == pytest.approx(want[2], rel=1e-6, abs=0.0)
    assert result.sensitivity("clearance.normal_force")[1] == pytest.approx(
        complex_step(kelvin_voigt_force, P0)[0], rel=1e-6, abs=0.0)
    assert np.array_equal(result.sensitivity("journal.vx"),
                          result.sensitivities.states[:, result.state_names.index("journal.vx"), :])


def test_every_step_as_output_keeps_a_row_of_sensitivities_per_point(kv_model) -> None:
    """Without output times each kept step has its row of S, and the end's row is the closed form's."""
    result = kv_run(kv_model)
    assert result.sensitivities.states.shape == (result.n_times, result.n_states, 3)
    assert result.sensitivity("journal.x")[-1] == pytest.approx(complex_step(kelvin_voigt_radial, P0)[0],
                                                                rel=1e-6, abs=0.0)
    # before the onset x = u t whatever the parameters: S of x is zero there
    free = result.t < 0.1 - 1e-9
    assert free.sum() > 2 and np.abs(result.sensitivity("journal.x")[free]).max() < 1e-12


def test_the_jump_is_the_drivers(kv_model, monkeypatch: pytest.MonkeyPatch) -> None:
    """The driver applies the jump at each event: with Driver.jump's carried call dropped, dx/dz0 at the
    end is wrong by over half (as the reference run without its jumps)."""
    original = driver.Driver.jump

    def without_carried(self: driver.Driver, jump: object) -> None:
        carried, self.carried = self.carried, None
        try:
            original(self, jump)  # type: ignore[arg-type]
        finally:
            self.carried = carried

    monkeypatch.setattr(driver.Driver, "jump", without_carried)
    result = kv_run(kv_model, save=dc.SaveAt(times=[0.0, T]))
    want = complex_step(kelvin_voigt_radial, P0)[0, 2]
    assert abs(result.sensitivity("journal.x", "clearance.clearance")[-1] - want) > 0.5 * abs(want)


def test_saved_and_loaded_with_the_result(kv_model, tmp_path: Path) -> None:
    """The file keeps the names, every row's S of states and channels and the events' dt*/dp; a window
    reads its rows and events; Result.slice keeps them too."""
    result = kv_run(kv_model, save=dc.SaveAt(times=[0.0, 0.05, T_CONTACT, T]))
    back = dc.load(result.save(tmp_path / "run.h5"))
    assert back.sensitivity_names == result.sensitivity_names
    for name in ("journal.x", "journal.vx", "clearance.normal_force"):
        assert np.array_equal(back.sensitivity(name), result.sensitivity(name))
    assert [(e.t, e.pair, e.kind) for e in back.sensitivities.events] == [
        (e.t, e.pair, e.kind) for e in result.sensitivities.events]
    assert np.array_equal(np.array([e.dt_dp for e in back.sensitivities.events]),
                          np.array([e.dt_dp for e in result.sensitivities.events]))
    window = dc.load(tmp_path / "run.h5", 0.04, 0.12)
    assert np.array_equal(window.t, [0.05, T_CONTACT])
    assert np.array_equal(window.sensitivity("journal.x"), result.sensitivity("journal.x")[1:3])
    assert [e.kind for e in window.sensitivities.events] == ["onset"]
    sliced = result.slice(0.04, 0.12)
    assert np.array_equal(sliced.sensitivity("journal.x"), window.sensitivity("journal.x"))


STREAM_TIMES = np.linspace(0.0, T, 51)


def _same_sensitivities(a: dc.Result, b: dc.Result, rows: int | None = None) -> None:
    """b's rows (its first ``rows``) and events' sensitivities are a's, to the bit."""
    sa, sb = a.sensitivities, b.sensitivities
    k = a.n_times if rows is None else rows
    assert sa is not None and sb is not None and sa.names == sb.names
    assert np.array_equal(a.t, b.t[:k]) and np.array_equal(sa.states, sb.states[:k], equal_nan=True)
    assert np.array_equal(sa.channels, sb.channels[:k], equal_nan=True)
    assert [(e.t, e.pair, e.kind) for e in sa.events] == [(e.t, e.pair, e.kind) for e in sb.events][:len(sa.events)]
    dt_a, dt_b = (np.array([e.dt_dp for e in s.events]) for s in (sa, sb))
    assert np.array_equal(dt_a, dt_b[:len(sa.events)])
    assert sa.sides is not None and sb.sides is not None
    j = sa.sides.t.size
    for name in ("t", "y", "values", "states", "channels"):
        assert np.array_equal(getattr(sa.sides, name), getattr(sb.sides, name)[:j], equal_nan=True)


def test_a_streamed_run_writes_them_as_it_goes(kv_model, tmp_path: Path) -> None:
    """SaveAt(stream_to=...): the file holds S of the states and channels at every row, the events' dt*/dp and
    their rows, exactly the run in memory's; dc.load reads them and Result.gradient gives the same objectives;
    keep_data=False returns the outcome alone and the file holds the rest."""
    memory = kv_run(kv_model, save=dc.SaveAt(times=STREAM_TIMES))
    streamed = kv_run(kv_model, save=dc.SaveAt(times=STREAM_TIMES, stream_to=tmp_path / "run.h5"))
    back = dc.load(tmp_path / "run.h5")
    for result in (streamed, back):
        _same_sensitivities(memory, result)
        assert result.n_times == memory.n_times == STREAM_TIMES.size
    assert streamed.sensitivities.sides.t.size == 4  # onset and separation, before and after each
    of = dc.Integral("clearance.normal_force")
    assert back.gradient(of) == memory.gradient(of)
    want = complex_step(kelvin_voigt_radial, P0)
    assert back.sensitivity("journal.x")[-1] == pytest.approx(want[0], rel=1e-6)
    outcome = kv_run(kv_model, save=dc.SaveAt(times=STREAM_TIMES, stream_to=tmp_path / "alone.h5", keep_data=False))
    assert outcome.n_times == 0 and outcome.sensitivities is None
    _same_sensitivities(memory, dc.load(tmp_path / "alone.h5"))


def test_an_interrupted_streamed_run_keeps_what_it_computed(kv_model, tmp_path: Path, ctrl_c_at_update) -> None:
    """Ctrl-C as the run reaches its separation root, before deciding it (the progress line's second update: the
    run restarts at each of its two events): the file holds the rows before it with their S, the onset's dt*/dp
    and rows, those of the complete run; the Interrupted's result is the file's."""
    from daeclear.core.errors import Interrupted

    full = kv_run(kv_model, save=dc.SaveAt(times=STREAM_TIMES))
    ctrl_c_at_update(2)
    with pytest.raises(Interrupted) as info:
        kv_run(kv_model, save=dc.SaveAt(times=STREAM_TIMES, stream_to=tmp_path / "run.h5"))
    partial = dc.load(tmp_path / "run.h5")
    assert not partial.success and "interrupted" in partial.message
    assert 0 < partial.n_times < full.n_times and partial.t[-1] < 0.1316 < partial.t[-1] + T / 50
    assert [e.kind for e in partial.sensitivities.events] == ["onset"] and partial.sensitivities.sides.t.size == 2
    _same_sensitivities(partial, full, rows=partial.n_times)
    _same_sensitivities(partial, info.value.result)


def test_a_run_without_sensitivities_says_how_to_get_them(kv_model) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(kv_model, 0.01, options=dc.SolverOptions(start="declared"))
    assert result.sensitivity_names == ()
    with pytest.raises(KeyError, match="sensitivities="):
        result.sensitivity("journal.x")


def test_a_name_or_parameter_the_run_does_not_hold(kv_model) -> None:
    result = kv_run(kv_model, save=dc.SaveAt(times=[0.0, T]))
    with pytest.raises(KeyError, match="name='journal.z'"):
        result.sensitivity("journal.z")
    with pytest.raises(KeyError, match="parameter='journal.mass'.*clearance.clearance"):
        result.sensitivity("journal.x", "journal.mass")


@pytest.mark.parametrize(("value", "message"), [
    ("clearance.clearance", r"sensitivities='clearance.clearance', must be None or a non-empty list"),
    ([], r"sensitivities=\[\], must be None or a non-empty list"),
    ([1.0], r"sensitivities=\[1.0\], must be a list of names \(strings\)"),
    (["clearance.clearance", "clearance.clearance"],
     r"sensitivities=\['clearance.clearance', 'clearance.clearance'\], must be a list naming each parameter once"),
    (["clearance.clearence"], r"sensitivities='clearance.clearence', must be one of model.parameter_names "
                              r"\(\d+ names; close matches: 'clearance.clearance'"),
])
def test_bad_names_are_refused_before_any_run(kv_model, monkeypatch: pytest.MonkeyPatch, value: object,
                                             message: str) -> None:
    monkeypatch.setattr(driver, "run", _no_run)
    with pytest.raises(dc.SceneError, match=f"simulate: {message}"):
        dc.simulate(kv_model, T, sensitivities=value)  # type: ignore[arg-type]


def test_a_scene_is_assembled_to_check_the_names(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(driver, "run", _no_run)
    with pytest.raises(dc.SceneError,
                       match="sensitivities='clearance.stiffness', must be one of model.parameter_names"):
        dc.simulate(radial_scene(dcc.KelvinVoigt(stiffness=K, damping=D)), T, sensitivities=["clearance.stiffness"])


def test_runs_that_cannot_carry_them_are_refused(kv_model, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(driver, "run", _no_run)
    with pytest.raises(dc.SceneError, match=r"sensitivities=\['clearance.clearance'\], must be None with "
                                            r"method='RK45': only method='ida' carries sensitivities"):
        dc.simulate(kv_model, T, method="RK45", sensitivities=["clearance.clearance"])
    with pytest.raises(dc.SceneError, match=r"must be None when y0 is given"):
        dc.simulate(kv_model, T, y0=np.zeros(kv_model.n_states), sensitivities=["clearance.clearance"])


def _no_run(*args: object, **keywords: object) -> None:
    raise AssertionError("the run started: the argument was not checked before any work")


# ---------------------------------------------------------------- the chapter's slider-crank

CRANK_T = 0.4e-3  # two impacts of the revolute clearance joint


@pytest.mark.parametrize("formulation", ["index1", "ggl"])
def test_slider_crank_clearance_by_its_taylor_remainder(formulation: str) -> None:
    """d(every position and velocity at T)/d(clearance) of Fig. 4.15's slider-crank (c = 0.5 mm, two impacts)
    against separate runs at rtol 1e-12 with the clearance moved by h: the first-order prediction's error
    |y(c + h) - y(c) - h S| falls as h^2 (quartered when h is halved) while h S itself only halves, which
    a wrong S (off by more than the remainder) cannot do."""
    model = dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation=formulation)
    name = "clearance.clearance"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(model, CRANK_T, rtol=1e-10, save=dc.SaveAt(times=[0.0, CRANK_T]),
                             sensitivities=[name, "clearance.law.restitution"])
    assert result.success and len(result.events) == 2
    n = 2 * model.n_q
    S = result.sensitivity_names.index(name)
    S = result.sensitivities.states[-1, :n, S]
    c = model.parameter(name)[0]

    def final(value: float) -> np.ndarray:
        run = dc.simulate(model.with_parameters({name: value}), CRANK_T, rtol=1e-12,
                          save=dc.SaveAt(times=[0.0, CRANK_T], steps=False))
        assert len(run.events) == 2  # the same events: a derivative exists
        return run.y[-1, :n]

    base = final(c)
    remainders = []
    for rel in (2e-3, 1e-3, 5e-4):
        h = rel * c
        error = final(c + h) - base - h * S
        remainders.append([np.linalg.norm(error[:n // 2]), np.linalg.norm(error[n // 2:])])
        assert np.linalg.norm(error[n // 2:]) < 0.01 * np.linalg.norm(h * S[n // 2:])
    ratios = np.array(remainders[:-1]) / np.array(remainders[1:])
    assert ratios == pytest.approx(4.0, rel=0.1), ratios


def test_handed_to_pandas_and_xarray(kv_model) -> None:
    """to_pandas(sensitivities=True): a column d(name)/d(parameter) per state or channel and parameter; to_xarray:
    S over (t, state, parameter), each channel's over (t, parameter), the events' dt*/dp; both hold the closed
    form's derivatives at T and the separation's."""
    pytest.importorskip("pandas")
    pytest.importorskip("xarray")
    result = kv_run(kv_model, save=dc.SaveAt(times=[0.0, 0.05, T_CONTACT, T]))
    want = complex_step(kelvin_voigt_radial, P0)  # rows x(T), vx(T), t_sep; columns K, D, z0
    df = result.to_pandas(states=True, sensitivities=True)
    for j, parameter in enumerate(NAMES):
        column = df[f"d(journal.x)/d({parameter})"].to_numpy()
        assert np.array_equal(column, result.sensitivity("journal.x", parameter))
        assert column[-1] == pytest.approx(want[0, j], rel=1e-6)
        assert np.array_equal(df[f"d(clearance.normal_force)/d({parameter})"].to_numpy(),
                              result.sensitivity("clearance.normal_force", parameter))
    assert df.attrs["units"]["d(journal.x)/d(clearance.clearance)"] == "m per unit of clearance.clearance"
    assert not any(c.startswith("d(") for c in result.to_pandas().columns)
    ds = result.to_xarray()
    assert list(ds["parameter"].values) == NAMES and ds["parameter_value"].values == pytest.approx(P0, rel=1e-15)
    vx = ds["sensitivity_y"].sel(state="journal.vx").values[-1]
    assert vx == pytest.approx(want[1], rel=1e-6, abs=1e-9)
    assert np.array_equal(ds["sensitivity_clearance.normal_force"].values, result.sensitivity("clearance.normal_force"))
    assert list(ds["sensitivity_event_kind"].values) == ["onset", "separation"]
    assert ds["sensitivity_event_dt_dp"].values[1] == pytest.approx(want[2], rel=1e-6)
    assert "sensitivity_y" not in result.to_xarray(sensitivities=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        plain = dc.simulate(kv_model, 0.01, options=dc.SolverOptions(start="declared"))
    assert "parameter" not in plain.to_xarray().coords
    with pytest.raises(dc.SceneError, match=r"Result.to_pandas: sensitivities=True, must be False for a run without"):
        plain.to_pandas(sensitivities=True)


def _work_run(law: object, track_work: bool) -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        return dc.simulate(radial_scene(law), T, rtol=1e-10, options=dc.SolverOptions(start="declared",
                           track_work=track_work), save=dc.SaveAt(times=np.linspace(0.0, T, 26)), sensitivities=NAMES)


def test_track_work_carries_the_work_state_and_keeps_the_derivatives() -> None:
    """track_work=True adds the work state beside S: with Lankarani-Nikravesh (a force continuous at onset) the
    journal's S is the run's without it, and the balance mechanical energy - work, constant in time, has a
    sensitivity constant in time too (its start's) through the impact, to 1e-6 m u^2 for relative changes of the
    parameters, while the work's to the restitution is of order (1 - e^2) m u^2 / e."""
    law = dcc.LankaraniNikravesh(restitution=0.8, stiffness=1e7)
    names = ["clearance.law.stiffness", "clearance.law.restitution", "clearance.clearance"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        runs = [dc.simulate(radial_scene(law), T, rtol=1e-10, options=dc.SolverOptions(start="declared", track_work=w),
                            save=dc.SaveAt(times=np.linspace(0.0, T, 26)), sensitivities=names) for w in (False, True)]
    plain, r = runs
    assert "work.input" in r.state_names and len(r.sensitivities.events) == 2
    for name in ("journal.x", "journal.vx"):
        scale = np.max(np.abs(plain.sensitivity(name)), axis=0)
        assert np.max(np.abs(r.sensitivity(name) - plain.sensitivity(name)), axis=0) == pytest.approx(
            [0, 0, 0], abs=1e-6 * max(scale))
    p = np.array([1e7, 0.8, 0.1])  # each parameter's value: relative changes, energies against m u^2
    balance = (r.sensitivity("energy.mechanical") - r.sensitivity("energy.work")) * p
    assert np.max(np.abs(balance - balance[0])) <= 1e-6 * M_U2
    assert np.max(np.abs(r.sensitivity("energy.work", "clearance.law.restitution"))) * 0.8 > 0.1 * M_U2  # 1 - e^2


def test_track_work_through_a_force_that_jumps_at_onset() -> None:
    """With track_work IDA's onset root lands exactly on delta = 0: the term reads Kelvin-Voigt's force there from
    inside the contact (``contact_force``: D u, not the law's 0 out of contact), so the jump's y'+ has it (before the
    fix dx/dz0 came out 3.51, the jumpless value, instead of 1.74)."""
    r = _work_run(dcc.KelvinVoigt(stiffness=K, damping=D), True)
    assert r.sensitivity("journal.x")[-1] == pytest.approx(complex_step(kelvin_voigt_radial, P0)[0], rel=1e-6)


M_U2 = 1.0  # m u^2 of the radial impact (J): the energies' scale


def test_output_times_at_the_events_report_the_row_before_the_switch(kv_model) -> None:
    """Output times exactly at the onset and separation times: the row there is the event's row before its
    switch (the normal force 0 before the onset's jump to D u), S(T) the closed form's, the objectives those of
    the run without those rows."""
    first = kv_run(kv_model, save=dc.SaveAt(times=[0.0, T]))
    onset, separation = (e.t for e in first.sensitivities.events)
    times = [0.0, 0.05, onset, 0.12, separation, 0.2, T]
    r = kv_run(kv_model, save=dc.SaveAt(times=times))
    assert r.t[2] == onset and r.t[4] == separation
    sides = r.sensitivities.sides
    assert sides.t.tolist() == [onset, onset, separation, separation]
    assert np.array_equal(r.sensitivities.states[2], sides.states[0])
    assert np.array_equal(r.sensitivities.channels[2], sides.channels[0])
    force = r.sensitivities.channel_names.index("clearance.normal_force")
    assert r["clearance.normal_force"][2] == 0.0 and sides.values[1, force] == pytest.approx(D * 1.0, rel=1e-9)
    assert np.array_equal(r.sensitivities.states[4], sides.states[2])
    assert r.sensitivity("journal.x")[-1] == pytest.approx(complex_step(kelvin_voigt_radial, P0)[0], rel=1e-6)
    for of in (dc.EventTime("clearance", "separation"), dc.Final("journal.vx")):
        assert r.gradient(of).gradient == pytest.approx(first.gradient(of).gradient, rel=1e-9, abs=1e-12)


def _worn_scene() -> dc.Scene:
    """A free journal flying obliquely (0.5 rad) under gravity into a bearing whose worn profile has 4 modes
    (unworn: every mode 0), Lankarani-Nikravesh: one impact and its separation."""
    from daeclear.contact.wear import ArchardWear

    scene = dc.Scene("worn", gravity=(0.0, -2.0))
    journal = scene.add(dc.Body("journal", mass=1.0, inertia=1.0, velocity=(np.cos(0.5), np.sin(0.5))))
    scene.add(dc.RevoluteClearance("clearance", scene.ground, journal, at=(0, 0), bearing_radius=1.0, clearance=0.1,
                                   law=dcc.LankaraniNikravesh(restitution=0.8, stiffness=1e7),
                                   wear=ArchardWear(coefficient=1e-12, length=0.02, nodes=36, modes=4)))
    return scene


@pytest.mark.parametrize("name", ["clearance.wear.bearing_cos[1]", "clearance.wear.bearing_sin[1]"])
def test_a_worn_profile_mode_by_its_taylor_remainder(name: str) -> None:
    """A worn profile's mode (element k of the parameter table's vector entry, "<key>[k]") as a sensitivity
    parameter: d(position and velocity at T)/d(mode) against separate runs at rtol 1e-12 with the mode moved by h
    (4, 2, 1, 0.5 mm of depth): the first-order prediction's error quarters when h halves, the same events."""
    from daeclear.assembly.sensitivity import moved_parameter

    model, t_end = dc.assemble(_worn_scene()), 0.2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        result = dc.simulate(model, t_end, rtol=1e-10, options=dc.SolverOptions(start="declared"),
                             save=dc.SaveAt(times=[0.0, t_end]), sensitivities=[name])
    assert [e.kind for e in result.sensitivities.events] == ["onset", "separation"]
    assert result.sensitivities.values.tolist() == [0.0]  # unworn
    S = result.sensitivities.states[-1, :6, 0]

    def final(value: float) -> np.ndarray:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", dc.DaeclearWarning)
            run = dc.simulate(moved_parameter(model, name, value), t_end, rtol=1e-12, save=dc.SaveAt(
                times=[0.0, t_end], steps=False), options=dc.SolverOptions(start="declared"))
        assert len(run.events) == 2
        return run.y[-1, :6]

    base = final(0.0)
    remainders = []
    for h in (4e-3, 2e-3, 1e-3, 5e-4):
        error = final(h) - base - h * S
        remainders.append([np.linalg.norm(error[:3]), np.linalg.norm(error[3:])])
    assert remainders[-1][1] < 0.02 * np.linalg.norm(5e-4 * S[3:])
    ratios = np.array(remainders[:-1]) / np.array(remainders[1:])
    assert ratios == pytest.approx(4.0, rel=0.1), ratios


def test_a_worn_profile_mode_moves_the_onset_as_the_clearance() -> None:
    """Flying along x the journal meets the bearing at angle 0, where a cos mode adds its own value to the gap
    and a sine mode nothing: dt_onset/d(cos_k) = dt_onset/dc = 1/u, dt_onset/d(sin_k) = 0; an element beyond the
    entry's size is refused before any run, naming the entry form."""
    from daeclear.contact.wear import ArchardWear

    scene = radial_scene(dcc.LankaraniNikravesh(restitution=0.8, stiffness=1e7)).with_values(
        {"clearance.wear": ArchardWear(coefficient=1e-12, length=0.02, nodes=36, modes=4)})
    names = ["clearance.clearance", "clearance.wear.bearing_cos[0]", "clearance.wear.bearing_cos[2]",
             "clearance.wear.bearing_sin[1]"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        r = dc.simulate(scene, 0.11, rtol=1e-10, options=dc.SolverOptions(start="declared"), sensitivities=names)
    assert r.sensitivities.events[0].dt_dp == pytest.approx([1.0, 1.0, 1.0, 0.0], rel=1e-9, abs=1e-9)
    with pytest.raises(dc.SceneError, match=r"sensitivities='clearance.wear.bearing_cos\[9\]', must be one of"):
        dc.simulate(scene, 0.11, sensitivities=["clearance.wear.bearing_cos[9]"])
