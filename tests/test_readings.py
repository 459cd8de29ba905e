"""Readings of the translational clearance joint (daeclear.model.readings) and the Fig. 4.28 metrics
(daeclear.studies.response_metrics).

Checked: every reading is selectable by name and resolves to the stiffness and exponent the
chapter's equations give by hand ((3.5) with R_c = 1 mm, (4.27) with a = 25 mm from Table 4.3);
an elastic flat drop under each reading reaches the peak penetration of its own closed form
(energy balance of its corner or face law), so the reading's law is what runs; bad names and
conflicting fields are rejected with the allowed list; the metrics give the known numbers of
constructed signals; the study runs every reading (5 ms each).
"""

import importlib.util
import json
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.model import readings
from daeclear.studies.response_metrics import (FIG_4_28, contact_periods, measure, onset_times, relative_rms,
                                       revolution_peaks, verdict)
from daeclear.results.result import ContactEvent, EventList
from daeclear.model.scene import TranslationalClearance

# Table 4.3: steel E = 207 GPa, nu = 0.3; slider 50 x 50 x 50 mm; corner radius 1 mm
SIGMA = (1.0 - 0.3 ** 2) / 207e9  # (3.4), 1/Pa (without pi, docs/contact_laws.md)
A_HALF = math.sqrt(0.050 * 0.050) / 2.0  # half side of the square of the face's area: 25 mm
K_SPHERE = 4.0 / (3.0 * 2.0 * SIGMA) * math.sqrt(1.0e-3)  # (3.5), sphere on a plane
K_PSEUDO = A_HALF / (0.475 * 2.0 * SIGMA)  # (4.27)
M, C = 0.14, 0.5e-3


def test_hand_values_of_the_stiffnesses():
    # the numbers themselves, worked out by hand: sigma = 0.91 / 207e9 = 4.3961e-12 1/Pa
    assert K_PSEUDO == pytest.approx(0.025 / (0.475 * 8.79227e-12), rel=1e-5)
    assert K_PSEUDO == pytest.approx(5.98612e9, rel=1e-5)
    assert K_SPHERE == pytest.approx(4.79554e9, rel=1e-5)


EXPECTED = {  # reading: (corner K, corner n, face law class or None, face K, face n)
    "corners": (K_SPHERE, 1.5, None, None, None),
    "pseudo-corners": (K_PSEUDO, 1.5, None, None, None),
    "pseudo-corners-linear": (K_PSEUDO, 1.0, None, None, None),
    "section-4.3": (K_SPHERE, 1.5, dcc.LankaraniPlane, K_PSEUDO, 1.0),
    "unified": (K_SPHERE, 1.5, dcc.LankaraniNikravesh, K_PSEUDO, 1.0),
    "unified-hertz": (K_SPHERE, 1.5, dcc.LankaraniNikravesh, K_PSEUDO, 1.5),
}


def test_every_reading_is_listed_and_documented():
    assert sorted(readings.JOINT_READINGS) == sorted(EXPECTED)
    for reading in list(readings.JOINT_READINGS.values()) + list(readings.MECHANISM_READINGS.values()):
        assert len(reading.source) > 40 and reading.note, reading.name


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_each_reading_resolves_to_its_equations(name):
    scene = readings.slider_crank_scene(name, restitution=0.8)
    scene.validate()
    joint = scene["clearance"]
    k, n, face_cls, k_face, n_face = EXPECTED[name]
    law = joint.resolved_law()
    assert isinstance(law, dcc.LankaraniNikravesh) and law.restitution == 0.8  # the joint's c_e is kept
    assert law.stiffness == pytest.approx(k, rel=1e-12) and law.effective_exponent == n
    assert joint.contact_model == ("corners" if face_cls is None else "section-4.3")
    face = joint.resolved_face_law()
    if face_cls is None:
        assert face is None
        return
    assert type(face) is face_cls and face.stiffness == pytest.approx(k_face, rel=1e-12)
    assert getattr(face, "effective_exponent", 1.0) == n_face
    if face_cls is dcc.LankaraniNikravesh:
        assert face.restitution == 0.8
    # the numbers are run-time parameters of the assembled model
    model = dc.assemble(scene)
    assert model.parameter("clearance.face_law.stiffness")[0] == pytest.approx(k_face, rel=1e-12)
    assert model.parameter("clearance.law.stiffness")[0] == pytest.approx(k, rel=1e-12)


def test_bad_reading_names_are_rejected_with_the_allowed_list():
    allowed = "'corners', 'pseudo-corners', 'pseudo-corners-linear', 'section-4.3', 'unified', 'unified-hertz'"
    with pytest.raises(dc.SceneError, match="reading='corner' is not a reading; allowed: " + allowed):
        dc.mechanisms.slider_crank("translational", reading="corner").validate()
    with pytest.raises(dc.SceneError, match="reading='nope' is not a reading; allowed: 'corners'"):
        readings.slider_crank_scene("nope")
    with pytest.raises(dc.SceneError, match="mechanism reading='heavy' is not a reading; allowed: 'table-4.1', "
                                            "'no-gravity', 'steel-block', 'pin-rear', 'friction-0.01'"):
        readings.slider_crank_scene("corners", "steel-block+heavy")
    with pytest.raises(dc.SceneError, match="reading='corners', is for joint='translational' only"):
        dc.mechanisms.slider_crank("revolute", reading="corners")
    with pytest.raises(dc.SceneError, match=r"pin_offset=\(0.01, 0.0\), must be \(0, 0\) unless"):
        dc.mechanisms.slider_crank("revolute", pin_offset=(0.01, 0.0))
    with pytest.raises(dc.SceneError, match="pin_offset=.*must be two finite numbers"):
        dc.mechanisms.slider_crank("translational", pin_offset=(0.01, math.nan))


def _joint(**kwargs):
    fields = dict(point_i=(0.0, 0.0), point_j=(0.0, 0.0), length=0.05, width=0.05, corner_radius=1e-3,
                  clearance=C, material=dcc.Material(young=207e9, poisson=0.3))
    fields.update(kwargs)
    scene = dc.Scene("guide", gravity=(0.0, 0.0))
    slider = scene.add(dc.Body("slider", mass=M, inertia=1e-4))
    scene.add(TranslationalClearance("g", scene.ground, slider, **fields))
    return scene


@pytest.mark.parametrize("kwargs, match", [
    (dict(reading="corners", model="section-4.3"), "model='section-4.3' with reading='corners', whose model is "
                                                   "'corners'; give one of them"),
    (dict(reading="unified", face_law=dcc.KelvinVoigt(stiffness=1e9, damping=10.0)), "sets the face law"),
    (dict(reading="pseudo-corners", law=dcc.LankaraniNikravesh(restitution=0.9, stiffness=1e9)),
     "stiffness=1000000000.0, exponent=None; with a reading both come from the reading"),
    (dict(reading="corners", law=dcc.LankaraniPlane()), "LankaraniPlane has no stiffness and exponent"),
])
def test_fields_the_reading_sets_are_not_given_twice(kwargs, match):
    with pytest.raises(dc.SceneError, match=match):
        _joint(**kwargs).validate()
    _joint(reading=kwargs["reading"]).validate()  # the reading alone is fine


def _drop(reading, speed=0.1):
    """The slider 1 um above the lower surface falling flat at ``speed``, elastic (c_e = 1), no gravity."""
    scene = dc.Scene("drop", gravity=(0.0, 0.0))
    slider = scene.add(dc.Body("slider", mass=M, inertia=1e-4, position=(0.0, -C + 1e-6), velocity=(0.0, -speed)))
    scene.add(TranslationalClearance(
        "g", scene.ground, slider, point_i=(0.0, 0.0), point_j=(0.0, 0.0), length=0.05, width=0.05,
        corner_radius=1e-3, clearance=C, material=dcc.Material(young=207e9, poisson=0.3),
        law=dcc.LankaraniNikravesh(restitution=1.0), reading=reading))
    return scene


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_elastic_flat_drop_reaches_the_readings_closed_form_peak(name):
    """Energy balance m v^2 / 2 = (elastic energy at the peak): two corners k d^(n+1)/(n+1) each for
    a ``corners`` reading, one face K d^(n+1)/(n+1) on the average penetration otherwise."""
    v = 0.1
    k, n, face_cls, k_face, n_face = EXPECTED[name]
    if face_cls is None:
        peak = ((n + 1.0) * M * v ** 2 / (4.0 * k)) ** (1.0 / (n + 1.0))
    else:
        peak = ((n_face + 1.0) * M * v ** 2 / (2.0 * k_face)) ** (1.0 / (n_face + 1.0))
    t_end = 4e-4 if n > 1.0 and face_cls is None or n_face == 1.5 else 6e-5
    t = np.linspace(0.0, t_end, 40001)
    run = dc.simulate(_drop(name, v), t_end, rtol=1e-10, options=dc.SolverOptions(start="declared"),
                      save=dc.SaveAt(times=t))
    measured = np.max(run["g.C_lower.penetration"])
    assert measured == pytest.approx(peak, rel=1e-4), (measured, peak)
    onsets = {e.pair for e in run.events.of("g", "onset")}
    assert ("g.lower_face" in onsets) == (face_cls is not None)
    assert run["slider.vy"][-1] == pytest.approx(v, rel=1e-4)  # elastic: leaves at the landing speed


# --------------------------------------------------------------------------- metrics


def test_contact_periods_of_a_constructed_signal():
    dt = 5e-6
    t = np.arange(4800) * dt  # 24 ms: two revolutions at 5000 rpm
    on = np.zeros(t.size)
    for a, b in ((1e-3, 4e-3), (6e-3, 6.5e-3), (20e-3, 24e-3)):  # 3, 0.5 and 4 ms (the last cut by the end)
        on[(t >= a - dt / 2) & (t < b - dt / 2)] = 1.0
    periods = contact_periods(t, on)
    assert periods.count == 3
    np.testing.assert_allclose(periods.durations, [3e-3, 0.5e-3, 4e-3], rtol=1e-9)
    np.testing.assert_allclose(periods.starts, [1e-3, 6e-3, 20e-3], rtol=1e-9)
    assert periods.span == pytest.approx(24e-3)
    assert periods.fraction == pytest.approx(7.5 / 24.0)
    assert periods.long_fraction(1.5e-3) == pytest.approx(7.0 / 24.0)
    assert periods.longest() == pytest.approx(4e-3) and periods.median() == pytest.approx(3e-3)
    assert contact_periods(t, np.zeros(t.size)).fraction == 0.0
    assert contact_periods(t, np.ones(t.size)).long_fraction(24e-3) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="uniformly spaced"):
        contact_periods(np.r_[0.0, 1.0, 3.0], [0, 1, 0])


def test_distance_and_peaks_of_constructed_signals():
    t = np.linspace(0.0, 0.036, 7201)  # three revolutions
    ref = 10.0 * np.sin(2 * np.pi * t / 0.012)
    assert relative_rms(ref + 0.2, ref) == pytest.approx(0.2 / 20.0, rel=1e-3)
    x = ref.copy()
    x[(t > 0.013) & (t < 0.0131)] = 25.0  # a peak in the second revolution
    np.testing.assert_allclose(revolution_peaks(t, x, 0.012), [10.0, 25.0, 10.0], rtol=1e-3)
    assert revolution_peaks(t[:100], x[:100], 0.012).size == 1  # less than a revolution: one value


def _event(t, pair, kind="onset"):
    return ContactEvent(t=t, pair=f"j.{pair}", kind=kind, approach_speed=1.0, y=np.zeros(2))


def test_onsets_count_a_face_landing_once():
    events = EventList([_event(1e-3, "C_lower"), _event(1e-3, "D_lower"), _event(1e-3, "lower_face"),
                        _event(2e-3, "C_lower", "separation"), _event(5e-3, "A_upper")])
    np.testing.assert_allclose(onset_times(events, "j"), [1e-3, 5e-3])
    np.testing.assert_allclose(onset_times(events, "j", 2e-3, 1.0), [5e-3])


class _Run(SimpleNamespace):
    def __getitem__(self, name):
        return self.channels[name]


def test_measure_and_verdict_on_a_constructed_run():
    period, dt = 0.012, 1e-5
    t = np.arange(0, 2 * period + dt / 2, dt)
    v_ideal = 20.0 * np.sin(2 * np.pi * t / period)
    moment_ideal = 100.0 * np.cos(2 * np.pi * t / period)
    contact = ((t % period) < 0.75 * period).astype(float)  # 9 ms of every 12 in contact
    run = _Run(t=t, events=EventList([_event(k * period + 1e-4, "A_upper") for k in range(2)]), channels={
        "slider.vx": v_ideal + 0.4, "drive.moment": 1.5 * moment_ideal, "j.in_contact": contact,
        "j.tilt": np.full(t.size, 1e-3), "j.eta": 0.5 * np.ones(t.size)})
    ideal = _Run(t=t, events=EventList(), channels={"slider.vx": v_ideal, "drive.moment": moment_ideal})
    m = measure(run, ideal, joint="j", period=period, t0=0.0, t1=2 * period)
    assert m["contact_fraction"] == pytest.approx(0.75, abs=1e-3)
    assert m["long_contact_fraction"] == pytest.approx(0.75, abs=1e-3)
    assert m["longest_contact_ms"] == pytest.approx(9.0, abs=0.02)
    assert m["velocity_rms_rel"] == pytest.approx(0.4 / 40.0, rel=1e-3)
    assert m["velocity_rms_rel_free"] == pytest.approx(0.4 / 40.0, rel=1e-3)
    assert m["impacts_per_rev"] == pytest.approx(1.0)
    assert m["moment_peak_ratio"] == pytest.approx(1.5, rel=1e-6)
    assert m["max_tilt_mrad"] == pytest.approx(1.0)
    assert verdict(m) == (True, [])
    m["contact_fraction"] = 0.14
    assert verdict(m) == (False, ["contact_fraction"])
    assert [c.key for c in FIG_4_28] == ["velocity_rms_rel", "contact_fraction", "long_contact_fraction",
                                         "impacts_per_rev", "moment_peak_ratio"]


# --------------------------------------------------------------------------- the study


def test_study_runs_every_reading_quick(tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    path = Path(__file__).resolve().parent.parent / "examples" / "translational_readings.py"
    spec = importlib.util.spec_from_file_location("example_translational_readings", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--quick", "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "metrics.json").read_text())["cases"]
    assert [r["joint_reading"] for r in rows][:len(EXPECTED)] == list(readings.JOINT_READINGS)
    assert {r["mechanism_reading"] for r in rows} >= set(readings.MECHANISM_READINGS)
    for row in rows:
        assert row["slider_in_guide"], row["case"]
        assert 0.0 < row["span.contact_fraction"] < 1.0 and row["span.impacts_per_rev"] > 0, row["case"]
        assert row["span.velocity_rms_rel"] < 0.05, row["case"]
    assert "| corners |" in (tmp_path / "metrics.md").read_text()


def test_a_scene_file_selects_a_reading(tmp_path):
    from daeclear.model.scenefile import read_scene_file

    path = tmp_path / "guide.toml"
    path.write_text('[scene]\nname = "guide"\n[[body]]\nname = "slider"\nmass = 0.14\ninertia = 1e-4\n'
                    '[[translational_clearance]]\nname = "g"\nbody_i = "ground"\nbody_j = "slider"\n'
                    'point_i = [0.0, 0.0]\npoint_j = [0.0, 0.0]\nlength = 0.05\nwidth = 0.05\n'
                    'corner_radius = 1e-3\nclearance = 0.5e-3\nmaterial = { young = 207e9, poisson = 0.3 }\n'
                    'law = { name = "lankarani-nikravesh", restitution = 0.9 }\nreading = "Unified"\n')
    joint = read_scene_file(path).scene["g"]
    assert joint.reading == "unified" and joint.contact_model == "section-4.3"
    assert joint.resolved_face_law().stiffness == pytest.approx(K_PSEUDO, rel=1e-12)
    path.write_text(path.read_text().replace('"Unified"', '"unify"'))
    with pytest.raises(dc.SceneError, match="reading='unify' is not a reading; allowed"):
        read_scene_file(path).scene.validate()


def test_the_reading_table_rejects_inconsistent_entries():
    with pytest.raises(ValueError, match="corner_stiffness='cone'"):
        readings.JointReading("x", "corners", "cone", 1.5, None, None, "s")
    with pytest.raises(ValueError, match="face law goes with the 'section-4.3' model"):
        readings.JointReading("x", "corners", "sphere", 1.5, "linear", None, "s")
