"""dc.gradient and its objectives (daeclear/results/objectives.py, daeclear/studies/gradient.py) on issue 43's
radial impact, against the closed form (derivatives by the complex step) and against central differences.

A free journal (m = 1 kg) leaves the bearing's centre at u = 1 m/s; clearance z0 = 0.1 m, Kelvin-Voigt
K = 1e4 N/m, D = 20 N s/m, T = 0.25 s. In contact (s = t - z0/u) the penetration is d(s) = (u/w_d) e^(-a s)
sin(w_d s), the force F = K d + D d' (it jumps from 0 to D u at onset). References:

* Final x(T), EventTime of the separation: the closed form of the acceptance test;
* Integral of the normal force: the impulse m (u + v_z) (momentum); its z0-derivative is 0, which needs the
  onset's jump term (0 - D u) dt1/dz0 = -20 against the integral of S (+20);
* Peak of the normal force: the root s* of F'(s) = 0 by Newton (in complex arithmetic for the complex step);
  the peak does not move with z0 (it only shifts in time).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pytest

import daeclear as dc
import daeclear.contact as dcc
from daeclear.results.objectives import Gradient, evaluate

M, U, T = 1.0, 1.0, 0.25
P0 = np.array([1e4, 20.0, 0.1])  # K, D, z0
NAMES = ["clearance.law.stiffness", "clearance.law.damping", "clearance.clearance"]


def motion(p: np.ndarray) -> tuple:
    k, d, _ = p
    a = d / (2 * M)
    return k, d, a, np.sqrt(k / M - a * a)


def force(p: np.ndarray, s: complex) -> tuple[complex, complex, complex]:
    """F, F', F'' at s into the contact: F = K d + D d', d'' = -(K d + D d')/m."""
    k, d, a, wd = motion(p)
    e = np.exp(-a * s)
    depth = (U / wd) * e * np.sin(wd * s)
    rate = (U / wd) * e * (wd * np.cos(wd * s) - a * np.sin(wd * s))
    accel = -(k * depth + d * rate) / M
    jerk = -(k * rate + d * accel) / M
    snap = -(k * accel + d * jerk) / M
    return k * depth + d * rate, k * rate + d * accel, k * accel + d * jerk + 0 * snap


def peak_force(p: np.ndarray) -> np.ndarray:
    s = 0.005 + 0j  # the force's maximum lies a few ms into the contact: Newton on F'(s) = 0
    for _ in range(60):
        _, f1, f2 = force(p, s)
        s = s - f1 / f2
    return np.array([force(p, s)[0]])


def separation(p: np.ndarray) -> np.ndarray:
    """(x(T), t_separation, v_z)."""
    k, d, a, wd = motion(p)
    z0 = p[2]
    s_z = (np.pi - np.arctan(d * wd / (k - d * a))) / wd
    depth = (U / wd) * np.exp(-a * s_z) * np.sin(wd * s_z)
    v_z = -(U / wd) * np.exp(-a * s_z) * (wd * np.cos(wd * s_z) - a * np.sin(wd * s_z))
    t_sep = z0 / U + s_z + depth / v_z
    return np.array([z0 - v_z * (T - t_sep), t_sep, v_z])


def complex_step(f, p: np.ndarray) -> np.ndarray:
    steps = 1e-30 * np.abs(p)
    return np.stack([np.imag(f(p + 1j * steps[j] * np.eye(p.size)[j])) / steps[j] for j in range(p.size)], axis=1)


def radial_scene() -> dc.Scene:
    """Issue 43's radial impact: a free journal from the bearing's centre at U along x, Kelvin-Voigt (P0)."""
    scene = dc.Scene("radial", gravity=(0.0, 0.0))
    journal = scene.add(dc.Body("journal", mass=M, inertia=1.0, velocity=(U, 0.0)))
    scene.add(dc.RevoluteClearance("clearance", scene.ground, journal, at=(0, 0), bearing_radius=1.0,
                                   clearance=P0[2], law=dcc.KelvinVoigt(stiffness=P0[0], damping=P0[1])))
    return scene


@pytest.fixture(scope="module")
def scene() -> dc.Scene:
    return radial_scene()


def grad(scene: dc.Scene, of: object, **kw: object) -> Gradient:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)  # atol at round-off, raised
        return dc.gradient(scene, T, of=of, parameters=NAMES, rtol=1e-10, start="declared", **kw)


def vector(g: Gradient) -> np.ndarray:
    return np.array([g.gradient[name] for name in NAMES])


def test_final_and_event_times_against_the_closed_form(scene: dc.Scene) -> None:
    want = complex_step(separation, P0)
    x, t_sep, _ = np.real(separation(P0))
    g = grad(scene, dc.Final("journal.x"))
    assert g.value == pytest.approx(x, abs=1e-9) and vector(g) == pytest.approx(want[0], rel=1e-6)
    g = grad(scene, dc.EventTime("clearance", "separation"))
    assert g.value == pytest.approx(t_sep, rel=1e-9) and vector(g) == pytest.approx(want[1], rel=1e-6)
    g = grad(scene, dc.EventTime("clearance", "onset", index=-1))
    assert g.value == pytest.approx(P0[2] / U, rel=1e-12)
    assert vector(g) == pytest.approx([0.0, 0.0, 1.0 / U], abs=1e-12)


def x_integral(p: np.ndarray) -> np.ndarray:
    """int_0^T x dt: u t1^2/2 before the contact, z0 s_z + int_0^s_z d(s) ds in it (force on), then the flight
    back at v_z from z0 + d(s_z)."""
    k, d, a, wd = motion(p)
    z0 = p[2]
    t1 = z0 / U
    s_z = (np.pi - np.arctan(d * wd / (k - d * a))) / wd

    def antiderivative(s: complex) -> complex:  # of (u/wd) e^(-a s) sin(wd s)
        return (U / wd) * np.exp(-a * s) * (-a * np.sin(wd * s) - wd * np.cos(wd * s)) / (a * a + wd * wd)

    depth = (U / wd) * np.exp(-a * s_z) * np.sin(wd * s_z)
    v_z = -(U / wd) * np.exp(-a * s_z) * (wd * np.cos(wd * s_z) - a * np.sin(wd * s_z))
    rest = T - t1 - s_z
    return np.array([U * t1 ** 2 / 2 + z0 * s_z + antiderivative(s_z) - antiderivative(0.0)
                     + (z0 + depth) * rest - v_z * rest ** 2 / 2])


def test_integral_of_a_smooth_channel_against_the_closed_form(scene: dc.Scene) -> None:
    """int x dt and its derivatives; the cubic quadrature over 2000 intervals (error O(dt^4))."""
    g = grad(scene, dc.Integral("journal.x"))
    assert g.value == pytest.approx(np.real(x_integral(P0))[0], rel=1e-9)
    assert vector(g) == pytest.approx(complex_step(x_integral, P0)[0], rel=1e-6)


def test_integral_of_the_force_is_the_impulse_with_the_onset_jump(scene: dc.Scene) -> None:
    """Value m (u + v_z), gradient m dv_z/dp, from the quadrature state integrated with the run (dc.gradient asks
    simulate for it): the clamped force's kink (no event there) is under IDA's error control, where the rows'
    cubic was first order (2 %). The z0-derivative is 0 only with the onset's jump of dQ, (0 - D u) dt1/dz0 =
    -20 against the integral of S (+20)."""
    g = grad(scene, dc.Integral("clearance.normal_force"))
    v_z = np.real(separation(P0)[2])
    want = M * complex_step(separation, P0)[2]
    assert g.value == pytest.approx(M * (U + v_z), rel=1e-8)
    assert vector(g)[:2] == pytest.approx(want[:2], rel=1e-6)
    assert abs(vector(g)[2]) < 1e-6 * P0[1] * U  # without the jump term: 20


def quadrature_run(scene: dc.Scene, channel: str, backend: str = "auto") -> dc.Result:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        return dc.simulate(scene, T, rtol=1e-10, options=dc.SolverOptions(start="declared", backend=backend),
                           save=dc.SaveAt(times=[0.0, 0.05, T], steps=False), sensitivities=NAMES,
                           integrals=[channel])


@pytest.mark.parametrize("backend", ["c", "python"])
def test_integrals_are_states_of_the_run(scene: dc.Scene, backend: str) -> None:
    """simulate(..., integrals=[...]) with three output rows: the quadrature state's Q(T) and dQ/dp(T) are the
    closed forms (no row could give them: the rows' cubic through 3 points misses by far), Q(0.05) = u t^2/2
    before the contact; the impulse's z0-derivative needs dQ's jump at the onset, read inside the contact
    (Kelvin-Voigt's force is 0 at delta = 0 exactly); both sessions."""
    r = quadrature_run(scene, "journal.x", backend)
    Q, dQ = r.sensitivities.integrals["journal.x"]
    assert Q == pytest.approx([0.0, U * 0.05 ** 2 / 2, np.real(x_integral(P0))[0]], rel=1e-9, abs=1e-15)
    assert dQ[-1] == pytest.approx(complex_step(x_integral, P0)[0], rel=1e-6)
    assert r.gradient(dc.Integral("journal.x", window=(0.05, T))).value == pytest.approx(
        np.real(x_integral(P0))[0] - U * 0.05 ** 2 / 2, rel=1e-9)
    impulse = quadrature_run(scene, "clearance.normal_force", backend)
    Q, dQ = impulse.sensitivities.integrals["clearance.normal_force"]
    assert Q[-1] == pytest.approx(M * (U + np.real(separation(P0)[2])), rel=1e-8)
    assert dQ[-1, :2] == pytest.approx(M * complex_step(separation, P0)[2, :2], rel=1e-6)
    assert abs(dQ[-1, 2]) < 1e-6 * P0[1] * U
    assert impulse.slice(0.0, 0.05).sensitivities.integrals["clearance.normal_force"][0].tolist() == [0.0, 0.0]


def test_integral_against_central_differences(scene: dc.Scene) -> None:
    """method="fd" (separate runs, each integrating the impulse as a state) agrees with the sensitivities."""
    of = dc.Integral("clearance.normal_force")
    fd, exact = grad(scene, of, method="fd"), grad(scene, of)
    assert vector(fd)[:2] == pytest.approx(vector(exact)[:2], rel=1e-5)
    assert abs(vector(fd)[2]) < 1e-4 * P0[1] * U


def test_bad_integrals(scene: dc.Scene) -> None:
    with pytest.raises(dc.SceneError, match=r"simulate: integrals=\['journal.x'\], must be None without sensitivities"):
        dc.simulate(scene, T, integrals=["journal.x"])
    with pytest.raises(dc.SceneError, match=r"simulate: integrals='journal.xx', must be one of model.channel_names "
                                            r"\(close matches: 'journal.x'"):
        dc.simulate(scene, T, sensitivities=NAMES, integrals=["journal.xx"])
    with pytest.raises(dc.SceneError, match=r"simulate: integrals='journal.x', must be None or a non-empty list"):
        dc.simulate(scene, T, sensitivities=NAMES, integrals="journal.x")
    # a streamed output keeps them too (tests/test_sensitivity_integrals.py)


def test_integral_window_and_peak_against_the_closed_form(scene: dc.Scene) -> None:
    """The force's peak (a few ms into the contact) and its derivatives; a window around it gives the same
    peak, a window before the contact a zero integral."""
    want = complex_step(peak_force, P0)[0]
    g = grad(scene, dc.Peak("clearance.normal_force"))
    assert g.value == pytest.approx(np.real(peak_force(P0))[0], rel=1e-8)
    assert vector(g)[:2] == pytest.approx(want[:2], rel=1e-6)
    assert abs(vector(g)[2]) < 1e-5 * P0[0] * U  # F' dt1/dz0 would be ~ K u were the peak's time fixed
    windowed = grad(scene, dc.Peak("clearance.normal_force", window=(0.1, 0.12), absolute=True))
    assert windowed.value == pytest.approx(g.value, rel=1e-8)
    before = grad(scene, dc.Integral("clearance.normal_force", window=(0.0, 0.05)))
    assert before.value == 0.0 and all(v == 0.0 for v in before.gradient.values())


def test_central_differences_cross_check(scene: dc.Scene) -> None:
    """method="fd" (separate runs) agrees with the sensitivities and the closed form on the peak's K and D."""
    fd = grad(scene, dc.Peak("clearance.normal_force"), method="fd")
    assert fd.method == "fd"
    assert vector(fd)[:2] == pytest.approx(complex_step(peak_force, P0)[0, :2], rel=1e-5)
    assert vector(fd)[:2] == pytest.approx(vector(grad(scene, dc.Peak("clearance.normal_force")))[:2], rel=1e-5)


@dataclass
class Line:
    """A synthetic trajectory: f(t) = p t, an event at 0.5 s where f jumps by +1 and whose time moves with p."""

    names: tuple[str, ...] = ("p",)
    t: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.25, 0.5, 0.5, 0.75, 1.0]))
    events: list = field(default_factory=lambda: [type("E", (), dict(t=0.5, pair="a", kind="onset",
                                                                      dt_dp=np.array([0.5])))()])

    def values(self, name: str) -> np.ndarray:
        return 2.0 * self.t + np.array([0, 0, 0, 1, 1, 1])

    def sensitivity(self, name: str, parameter: str | None = None) -> np.ndarray:
        return self.t[:, None]


def test_evaluate_on_a_synthetic_trajectory() -> None:
    """I(p) = int_0^1 p t dt + (1 - t*(p)) with t* moving at 0.5 per unit p: dI/dp = 1/2 - 0.5; the peak at the
    end moves as t; the event time is the event's."""
    line = Line()
    g = evaluate(dc.Integral("f"), line)
    assert g.value == pytest.approx(1.0 + 0.5) and g.gradient["p"] == pytest.approx(0.5 - 0.5, abs=1e-15)
    assert evaluate(dc.Peak("f"), line).gradient["p"] == pytest.approx(1.0)
    assert evaluate(dc.EventTime("a"), line).gradient == {"p": 0.5}


@pytest.mark.parametrize(("make", "match"), [
    (lambda: dc.Final(""), r"Final: channel='', must be a state's or channel's name"),
    (lambda: dc.Integral("x", window=(1.0, 0.5)), r"Integral: window=\(1.0, 0.5\), must be None or two finite"),
    (lambda: dc.Peak("x", window=3.0), r"Peak: window=3.0, must be None or two times"),
    (lambda: dc.Peak("x", absolute="yes"), r"Peak: absolute='yes', must be True or False"),
    (lambda: dc.EventTime("c", kind="impact"), r"EventTime: kind='impact', must be one of 'onset', 'separation'"),
    (lambda: dc.EventTime("c", index=1.0), r"EventTime: index=1.0, must be an integer"),
])
def test_bad_objectives(make, match: str) -> None:
    with pytest.raises(dc.SceneError, match=match):
        make()


def test_bad_gradient_calls(scene: dc.Scene) -> None:
    with pytest.raises(dc.SceneError, match=r"gradient: method='adjoint', must be one of sensitivities, fd"):
        dc.gradient(scene, T, of=dc.Final("journal.x"), parameters=NAMES, method="adjoint")
    with pytest.raises(dc.SceneError, match=r"gradient: of='journal.x', must be an objective"):
        dc.gradient(scene, T, of="journal.x", parameters=NAMES)  # type: ignore[arg-type]
    with pytest.raises(dc.SceneError, match=r"gradient: parameters='clearance.clearance', must be a non-empty list"):
        dc.gradient(scene, T, of=dc.Final("journal.x"), parameters="clearance.clearance")
    with pytest.raises(dc.SceneError, match=r"gradient: formulation='index1', must be None or the model's own"):
        dc.gradient(dc.assemble(scene, "ggl"), T, of=dc.Final("journal.x"), parameters=NAMES, formulation="index1")
    with pytest.raises(dc.SceneError, match=r"parameter='clearance.stiffness', must be one of model.parameter_names"):
        dc.gradient(scene, T, of=dc.Final("journal.x"), parameters=["clearance.stiffness"])
    with pytest.raises(dc.SceneError, match=r"Peak: window=\(0.1, 0.5\), must be inside the run"):
        dc.gradient(scene, T, of=dc.Peak("journal.x", window=(0.1, 0.5)), parameters=NAMES)
    with pytest.raises(dc.SceneError, match=r"objective: channel='journal.z', must be a state or channel of the run"):
        grad(scene, dc.Final("journal.z"))
    with pytest.raises(dc.SceneError, match=r"EventTime: index=3, must be within the run's 1 onset event"):
        grad(scene, dc.EventTime("clearance", index=3))


def test_a_loaded_result_gives_the_same_objectives(scene: dc.Scene, tmp_path) -> None:
    """The file keeps each event's rows before and after its switch: Result.gradient on the loaded result equals
    the run's (the impulse's onset jump term and the peak need them), and both equal the closed form; a window
    keeps the rows of its events."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        run = dc.simulate(scene, T, rtol=1e-10, options=dc.SolverOptions(start="declared"),
                          save=dc.SaveAt(times=np.linspace(0.0, T, 2001), steps=False), sensitivities=NAMES)
    back = dc.load(run.save(tmp_path / "run.h5"))
    assert back.sensitivities.sides is not None and back.sensitivities.sides.t.size == 4  # onset, separation
    for of in (dc.Integral("clearance.normal_force"), dc.Peak("clearance.normal_force"), dc.Final("journal.x"),
               dc.EventTime("clearance", "separation")):
        here, there = run.gradient(of), back.gradient(of)
        assert there.value == pytest.approx(here.value, rel=1e-12, abs=1e-15)
        assert vector(there) == pytest.approx(vector(here), rel=1e-10, abs=1e-12)
    impulse = back.gradient(dc.Integral("clearance.normal_force"))
    assert impulse.value == pytest.approx(M * (U + np.real(separation(P0)[2])), rel=1e-5)
    assert abs(vector(impulse)[2]) < 2e-2 * P0[1] * U  # the onset's jump term read from the file: else 20
    peak = back.gradient(dc.Peak("clearance.normal_force"))
    assert vector(peak)[:2] == pytest.approx(complex_step(peak_force, P0)[0, :2], rel=1e-6)
    window = dc.load(tmp_path / "run.h5", 0.05, 0.12)  # the onset (0.1 s) inside, the separation outside
    assert window.sensitivities.sides.t == pytest.approx([P0[2] / U] * 2, rel=1e-12)
    assert window.gradient(dc.Integral("clearance.normal_force", window=(0.05, 0.12))).value == pytest.approx(
        run.gradient(dc.Integral("clearance.normal_force", window=(0.05, 0.12))).value, rel=1e-9)  # end nodes one-sided
    assert run.slice(0.05, 0.12).sensitivities.sides.t.size == 2
    with pytest.raises(KeyError, match="Result.gradient: this run has no sensitivities"):
        dc.Result(t=[0.0], y=[[0.0]], yp=[[0.0]], state_names=["x"], channels={}, units={}).gradient(dc.Final("x"))


def test_integral_without_contact_terms() -> None:
    """A model without contact terms (ideal joints: no switch vector) has the quadrature row in its residual:
    the driven crank's angle phi = phi0 + w t integrates to phi0 T + w T^2/2, its derivative in w is T^2/2."""
    model = dc.assemble(dc.mechanisms.slider_crank())
    end = 2e-3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", dc.DaeclearWarning)
        r = dc.simulate(model, end, rtol=1e-8, options=dc.SolverOptions(backend="python"),
                        save=dc.SaveAt(times=[0.0, end], steps=False), sensitivities=["drive.speed"],
                        integrals=["crank.phi"])
    w = r.sensitivities.values[0]
    Q, dQ = r.sensitivities.integrals["crank.phi"]
    assert Q[-1] == pytest.approx(r["crank.phi"][0] * end + w * end ** 2 / 2, rel=1e-8, abs=0.0)
    assert dQ[-1, 0] == pytest.approx(end ** 2 / 2, rel=1e-8, abs=0.0)
