"""Poincaré sections, phase portraits and motion classification (daeclear.analysis).

Synthetic sections check each classification rule; short slider-crank runs check the
chapter's readings (section 4.4: c = 0.01 mm periodic, c = 0.5 mm non-periodic, friction 0.1
closer to periodic than 0.01) and that the labels do not depend on the sampling choices.
docs/nonlinear_dynamics.md has the full-length numbers.
"""

import math

import numpy as np
import pytest

import daeclear as dc
from daeclear.analysis import (
    Divergence,
    PoincareSection,
    classify_motion,
    classify_section,
    crank_period,
    phase_portrait,
    poincare_section,
    restart_model,
    sampling_times,
    twin_divergence,
)
from daeclear.errors import DaeclearError, SceneError
from daeclear.mechanisms import slider_crank

T = 0.012  # s, one crank revolution at the chapter's 5000 rpm
SPEED = 2 * math.pi / T


# --------------------------------------------------------------------------- synthetic data


def _result(t, channels, states=None):
    """A Result with the given channels (and optional unit-carrying states) and a 5000 rpm driver."""
    t = np.asarray(t, dtype=float)
    states = states or {}
    names = list(states)
    y = np.column_stack([states[n] for n in names]) if names else np.zeros((t.size, 0))
    units = {n: "m" for n in names}
    units.update({c: "m/s" for c in channels})
    return dc.Result(t=t, y=y, yp=np.zeros_like(y), state_names=names, channels=channels, units=units,
                     parameters={"scene": {"name": "synthetic", "elements": {
                         "drive": {"kind": "Driver", "speed": SPEED, "joint": "A"}}}})


def _section(points, size=1.0):
    points = np.asarray(points, dtype=float)
    if points.ndim == 1:
        points = points[:, None]
    d = points.shape[1]
    return PoincareSection(t=T * np.arange(len(points)), points=points, channels=tuple(f"c{i}" for i in range(d)),
                           units=("",) * d, period=T, size=np.full(d, size), center=np.zeros(d))


def _divergence(decorrelation, lyapunov):
    return Divergence(t=np.zeros(1), distance=np.zeros(1), restart_time=0.0, restart_in_contact=False,
                      perturbation=1e-8, d0=1e-8, d_start=1e-6, d_saturation=1e-2, amplification=1e4,
                      lyapunov=lyapunov, r_squared=0.9, fit_window=(0.0, 0.01), decorrelation=decorrelation,
                      period=T)


def test_crank_period_and_sampling_times():
    assert crank_period(slider_crank("revolute")) == pytest.approx(T)
    assert crank_period(slider_crank("ideal", rpm=3000)) == pytest.approx(0.02)
    t = sampling_times(T, 5, per_revolution=8)
    assert t[0] == 0 and t[-1] == pytest.approx(5 * T) and t.size == 41
    assert np.all(np.isin(T * np.arange(6), t))  # every whole period is an output time, exactly
    shifted = sampling_times(T, 3, per_revolution=4, offset=T / 3)
    assert np.all(np.diff(shifted) > 0)
    assert np.all(np.min(np.abs(shifted[:, None] - (T / 3 + T * np.arange(3))), axis=0) == 0)
    with pytest.raises(SceneError, match="offset"):
        sampling_times(T, 3, offset=T)
    with pytest.raises(DaeclearError, match="no driver"):
        crank_period({"name": "free", "elements": {}})


def test_poincare_section_picks_the_section_times_and_sizes_the_attractor():
    t = sampling_times(T, 10, per_revolution=16)
    phase = 2 * np.pi * t / T
    r = _result(t, {"a.v": np.cos(phase) + 0.1 * t / t[-1], "a.w": np.sin(phase)})
    sec = poincare_section(r, ("a.v", "a.w"), t0=2 * T)
    assert len(sec) == 9 and sec.t[0] == pytest.approx(2 * T)
    assert np.allclose(sec.points[:, 0], 1 + 0.1 * sec.t / t[-1])
    assert np.allclose(sec.points[:, 1], 0, atol=1e-12)
    assert sec.size[0] == pytest.approx(2.0, rel=0.05)  # 1%-99% range of a cosine over the window
    assert sec.units == ("m/s", "m/s")
    portrait = phase_portrait(r, "a.v", "a.w", t0=2 * T)
    assert portrait.x.size == 8 * 16 + 1 and portrait.names == ("a.v", "a.w")
    coarse = _result(np.linspace(0, 10 * T, 7), {"a.v": np.zeros(7)})
    with pytest.raises(DaeclearError, match="sampling_times"):
        poincare_section(coarse, ("a.v",))


@pytest.mark.parametrize("k", [1, 3])
def test_periodic_sections_give_their_period(k):
    rng = np.random.default_rng(1)
    cycle = rng.uniform(-0.5, 0.5, size=(k, 2))
    points = np.tile(cycle, (40 // k + 1, 1))[:40] + 1e-4 * rng.standard_normal((40, 2))
    motion = classify_section(_section(points))
    assert (motion.label, motion.period) == ("periodic", k)
    assert motion.evidence["n_clusters"] == k
    assert motion.evidence["periodicity_defect"] < 0.01
    assert f"{k} revolution" in motion.reason


def test_non_periodic_sections_are_split_by_the_twin_evidence():
    golden = (math.sqrt(5) - 1) / 2
    angle = 2 * math.pi * golden * np.arange(40)  # a quasi-periodic rotation on a closed curve
    torus = 0.4 * np.column_stack([np.cos(angle), np.sin(angle)])
    assert classify_section(_section(torus)).label == "non-periodic"  # no twins: cannot tell
    assert classify_section(_section(torus), _divergence(0.01, 0.0)).label == "quasi-periodic"
    x = [0.3]
    for _ in range(39):
        x.append(4 * x[-1] * (1 - x[-1]))  # logistic map: chaotic
    chaos = _section(np.array(x) - 0.5)
    motion = classify_section(chaos, _divergence(1.0, 300.0))
    assert motion.label == "chaotic" and motion.period == 0
    assert motion.evidence["lyapunov"] == 300.0 and "decorrelate" in motion.reason
    assert classify_section(chaos, _divergence(1.0, -5.0)).label == "non-periodic"  # contradictory evidence
    assert classify_section(_section(np.zeros(5))).label == "undetermined"
    with pytest.raises(SceneError, match="tol"):
        classify_section(chaos, tol=2.0)


def test_twin_divergence_fits_the_exponential_growth():
    lam = 400.0  # 1/s
    t = sampling_times(T, 20, per_revolution=32)
    d = np.minimum(1e-6 * np.exp(lam * t), 1e-2)  # grows from 1e-6, saturates at 1e-2
    base = np.sin(2 * np.pi * t / T)
    a = _result(t, {"s.v": base}, states={"s.x": base})
    b = _result(t, {"s.v": base + d}, states={"s.x": base + 2 * d})  # state range 2: normalised distance = d
    sec = poincare_section(a, ("s.v",), t0=2 * T)
    div = twin_divergence(a, b, sec, reference=a)
    assert div.lyapunov == pytest.approx(lam, rel=0.02)
    assert div.r_squared > 0.99 and div.d_saturation == pytest.approx(1e-2)
    assert div.amplification > 1e3
    assert div.lyapunov_per_revolution == pytest.approx(lam * T, rel=0.02)


# --------------------------------------------------------------------------- the chapter's slider-crank


SHORT = dict(transient=5, revolutions=20, twin_revolutions=10)


def test_chapter_small_clearance_is_periodic():
    """Fig. 4.18d: c = 0.01 mm, the journal follows the bearing wall: one point per revolution."""
    analysis = classify_motion(slider_crank("revolute", clearance=0.01e-3), **SHORT)
    motion = analysis.motion
    assert (motion.label, motion.period) == ("periodic", 1)
    assert motion.evidence["periodicity_defect"] < 0.01  # measured 1.0e-3 at rtol 1e-6
    assert len(analysis.section) == 21 and analysis.section.t[0] == pytest.approx(5 * T)
    assert analysis.divergence.amplification < 1e3  # the twins stay at the integration-noise level


def test_chapter_large_clearance_is_chaotic():
    """Fig. 4.18a: c = 0.5 mm, impacts and rebounds: no recurrence, twins decorrelate."""
    analysis = classify_motion(slider_crank("revolute", clearance=0.5e-3), **SHORT)
    motion = analysis.motion
    assert motion.label == "chaotic", motion
    assert motion.evidence["periodicity_defect"] > 0.2  # measured 0.3-0.6
    assert motion.evidence["decorrelation"] > 0.3
    assert motion.evidence["lyapunov"] > 0
    assert analysis.twins is not None and analysis.divergence.amplification > 100


def test_chapter_friction_makes_the_response_closer_to_periodic():
    """Fig. 4.21: with c = 0.5 mm, friction 0.1 gives a periodic map, 0.01 a spread one."""
    low = classify_motion(slider_crank("revolute", clearance=0.5e-3, friction=0.01), twin=False, **SHORT).motion
    high = classify_motion(slider_crank("revolute", clearance=0.5e-3, friction=0.1), twin=False, **SHORT).motion
    assert (high.label, high.period) == ("periodic", 1)
    assert low.label == "non-periodic"
    assert high.evidence["periodicity_defect"] < low.evidence["periodicity_defect"] / 10
    assert high.evidence["spread"] < low.evidence["spread"] / 10


def test_translational_chaos_small_in_the_section_is_caught_by_the_twins():
    """Section 4.5: with the translational joint the slider's lateral impacts hardly show in the
    x velocity and acceleration at the section (they recur within tol), but the twins separate
    by orders of magnitude: c = 0.5 mm is chaotic (Fig. 4.31a), c = 0.01 mm periodic (Fig. 4.31d)."""
    large = classify_motion(slider_crank("translational", clearance=0.5e-3), **SHORT).motion
    assert large.evidence["periodicity_defect"] < 0.05  # measured 0.02-0.03: recurs in slider.vx, slider.ax
    assert large.label == "chaotic" and "small in" in large.reason
    assert large.evidence["twin_amplification"] > 1e3  # measured 3e4-8e5
    small = classify_motion(slider_crank("translational", clearance=0.01e-3), **SHORT).motion
    assert (small.label, small.period) == ("periodic", 1)
    assert small.evidence["twin_amplification"] < 100  # measured 0.06-6


@pytest.mark.slow
@pytest.mark.parametrize("clearance, expected", [(0.01e-3, "periodic"), (0.5e-3, "non-periodic")])
def test_classification_is_stable_to_the_sampling_choices(clearance, expected):
    """Transient length, number of revolutions, samples per revolution, section phase, channel pair
    and tolerance change the numbers but not the label (docs/nonlinear_dynamics.md, full table)."""
    scene = dc.assemble(slider_crank("revolute", clearance=clearance))
    variants = [{}, {"transient": 10}, {"revolutions": 40}, {"per_revolution": 64}, {"phase": math.pi / 2},
                {"channels": ("slider.ax", "drive.moment")}, {"rtol": 1e-7}]
    labels = []
    for change in variants:
        options = {**SHORT, "twin": False, **change}
        labels.append(classify_motion(scene, **options).motion.label)
    assert labels == [expected] * len(variants), list(zip(variants, labels))


def test_restart_reproduces_the_continuous_run():
    """A restart from the state at t = 2T (angles unwound by whole turns) continues the same motion."""
    model = dc.assemble(slider_crank("ideal"))
    t = sampling_times(T, 4, per_revolution=16)
    run = dc.simulate(model, 4 * T, t_eval=t, rtol=1e-8)
    index = int(np.argmin(np.abs(t - 2 * T)))
    again = dc.simulate(restart_model(model, run, index), 2 * T, t_eval=t[t <= 2 * T + 1e-12], rtol=1e-8)
    for name in ("slider.x", "slider.vx", "rod.phi", "drive.moment"):
        ref = run[name][index:]
        assert np.allclose(again[name], ref, rtol=0, atol=1e-5 * np.ptp(ref)), name
    assert again["crank.phi"][0] == pytest.approx(run["crank.phi"][0])  # unwound by 2 turns
    with pytest.raises(DaeclearError, match="whole number of periods"):
        restart_model(model, run, index + 1)
    with pytest.raises(DaeclearError, match="no free position"):  # the ideal mechanism has no degree of freedom
        restart_model(model, run, index, perturbation=1e-6)


def test_twin_perturbation_stays_on_the_constraint_manifold():
    model = dc.assemble(slider_crank("revolute", clearance=0.5e-3))
    run = dc.simulate(model, T, t_eval=sampling_times(T, 1, per_revolution=8))
    base = restart_model(model, run, 8)
    phi0 = np.array(model.kinematics(np.array(base.start_state[: model.n_q]), np.zeros(model.n_q), 0.0, model.parameter_values)[0])
    for size in (1e-6, 1e-5):
        twin = restart_model(model, run, 8, perturbation=size, seed=3)
        q = np.array(twin.start_state[: model.n_q])
        assert np.linalg.norm(q - np.array(base.start_state[: model.n_q])) == pytest.approx(size)
        Phi = np.array(model.kinematics(q, np.zeros(model.n_q), 0.0, model.parameter_values)[0])
        assert np.max(np.abs(Phi - phi0)) < 1e-3 * size  # second order in the perturbation only


def test_classify_motion_rejects_bad_options():
    scene = slider_crank("revolute", clearance=0.5e-3)
    with pytest.raises(SceneError, match="twin"):
        classify_motion(scene, twin="sometimes")
    with pytest.raises(SceneError, match="t_eval"):
        classify_motion(scene, t_eval=[0.0, 0.1])
    with pytest.raises(SceneError, match="revolutions"):
        classify_motion(scene, revolutions=1)


def test_plot_poincare_section_draws_points_over_the_portrait():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from daeclear.plot import plot_poincare_section

    t = sampling_times(T, 6, per_revolution=16)
    phase = 2 * np.pi * t / T
    r = _result(t, {"a.v": np.cos(phase), "a.w": np.sin(phase)})
    sec = poincare_section(r, ("a.v", "a.w"), t0=T)
    ax = plot_poincare_section(sec, portrait=r)
    assert len(ax.lines) == 2 and len(ax.lines[-1].get_xdata()) == len(sec) == 6
    assert ax.get_xlabel() == "a.v (m/s)"
    ax2 = plot_poincare_section(sec, portrait=phase_portrait(r, "a.v", "a.w"))
    assert len(ax2.lines) == 2
    plt.close("all")
