"""Structure compiles, numbers do not: run-time parameters of the assembled model.

Every number of a scene enters the generated functions as run-time parameter data. Checked
here: scenes that differ only in numbers share one symbolic template and one compiled
library; the shared template bound to new numbers gives the same equations as a template
built for those numbers from scratch (an independent second computation); structural
changes get their own template; every contact and friction law either runs with symbolic
parameters or is baked into the structure.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import daeclear as dc
from daeclear.engine.codegen import clear_memos
from daeclear.contact import FRICTION_LAWS, NORMAL_LAWS, HydrodynamicBearing, Material, friction_law, normal_law
from daeclear.assembly.parameters import is_parametric, law_values, symbolic_law
from daeclear.core.errors import SceneError

STEEL = Material(young=207e9, poisson=0.3)


def _functions_at(model: dc.DAEModel, seed: int) -> list[np.ndarray]:
    """Residual (every term on), Jacobian, roots and outputs at a random state."""
    rng = np.random.default_rng(seed)
    f = model.functions
    P = model.parameter_values
    y = np.concatenate([model.q_guess, model.v_guess, np.zeros(model.n_states - 2 * model.n_q)])
    y = y + 1e-4 * rng.standard_normal(y.size)
    yp = rng.standard_normal(y.size)
    t, cj = 1.3e-3, 2.5e3
    out = [np.array(f.residual(t, y, yp, P)), np.array(f.jacobian(t, y, yp, cj, P))]
    for term_res, term in zip(f.term_residuals, model.terms):
        out.append(np.array(term_res(t, y, yp, np.full(term.n_params, 0.7), P)))
    if f.roots is not None:
        out.append(np.array(f.roots(t, y, yp, P)))
    switch = np.concatenate([np.r_[1.0, np.full(term.n_params, 0.7)] for term in model.terms]) if model.terms \
        else np.zeros(0)
    out.append(np.array(model.outputs(t, y, yp, switch, P)))
    return out


# (scene built first, scene with other numbers and the same structure)
VARIANTS = {
    "revolute": (dict(joint="revolute", friction=0.2),
                 dict(joint="revolute", clearance=0.4e-3, rpm=3000.0, gravity=0.0, friction=0.05)),
    "revolute-hertz": (dict(joint="revolute", law="hertz"),
                       dict(joint="revolute", clearance=0.2e-3, law="hertz", bearing_radius=12e-3)),
    "translational": (dict(joint="translational", friction=0.3),
                      dict(joint="translational", clearance=0.3e-3, rpm=4000.0, friction=0.1)),
    "section-4.3": (dict(joint="translational", contact_model="section-4.3"),
                    dict(joint="translational", clearance=0.6e-3, contact_model="section-4.3", restitution=0.8)),
    "ideal": (dict(joint="ideal"), dict(joint="ideal", rpm=1234.0, gravity=3.0)),
    # the lubricated joint: viscosity, bearing length, film thresholds and the dry law's numbers
    "lubricated": (dict(joint="revolute", friction=0.1, law=HydrodynamicBearing(viscosity=0.04, length=0.02)),
                   dict(joint="revolute", friction=0.05, clearance=0.3e-3, rpm=3000.0,
                        law=HydrodynamicBearing(viscosity=0.01, length=0.015, roughness=2e-6, hysteresis=0.5,
                                                dry=normal_law("lankarani-nikravesh", restitution=0.7)))),
    # readings of the translational joint (daeclear.model.readings): their K, n, c_e, the slider's mass and
    # inertia and the pin's place on it are numbers
    "reading-unified": (dict(joint="translational", reading="unified"),
                        dict(joint="translational", reading="unified", clearance=0.3e-3, restitution=0.8,
                             slider_mass=0.9, slider_inertia=4e-4, pin_offset=(-0.02, 0.004))),
    "reading-pseudo-corners": (dict(joint="translational", reading="pseudo-corners", friction=0.1),
                               dict(joint="translational", reading="pseudo-corners", friction=0.01, gravity=0.0,
                                    pin_offset=(0.01, 0.0), slider_mass=0.5)),
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_shared_template_equals_a_fresh_build(variant):
    base, kwargs = VARIANTS[variant]
    first = dc.assemble(dc.mechanisms.slider_crank(**base))  # builds (or reuses) the template
    shared = dc.assemble(dc.mechanisms.slider_crank(**kwargs))
    assert shared.functions is first.functions, "numbers only: the template must be reused"
    assert not np.array_equal(shared.parameter_values, first.parameter_values)
    clear_memos()
    fresh = dc.assemble(dc.mechanisms.slider_crank(**kwargs))  # built from these numbers
    assert fresh.functions is not shared.functions
    for seed in (1, 2):
        for a, b in zip(_functions_at(shared, seed), _functions_at(fresh, seed)):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(shared.q_guess, fresh.q_guess)
    np.testing.assert_array_equal(shared.mass_diagonal, fresh.mass_diagonal)


# the other ready mechanisms: (builder, scene built first, other numbers with the same structure)
MECHANISM_VARIANTS = {
    "four_bar": (dc.mechanisms.four_bar, dict(clearance_joints=("B", "C")),
                 dict(clearance_joints=("B", "C"), clearance={"B": 0.2e-3, "C": 0.3e-3}, rpm=3000.0,
                      crank_angle=0.4, bearing_radius=12e-3, restitution=0.7)),
    "double_pendulum": (dc.mechanisms.double_pendulum, dict(clearance_joints=("A", "B")),
                        dict(clearance_joints=("A", "B"), clearance=0.3e-3, angles=(0.3, -0.2), link_mass=0.5,
                             gravity=3.0)),
}


@pytest.mark.parametrize("variant", sorted(MECHANISM_VARIANTS))
def test_ready_mechanisms_share_their_template(variant):
    build, base, kwargs = MECHANISM_VARIANTS[variant]
    first = dc.assemble(build(**base))
    shared = dc.assemble(build(**kwargs))
    assert shared.functions is first.functions, "numbers only: the template must be reused"
    assert not np.array_equal(shared.parameter_values, first.parameter_values)
    clear_memos()
    fresh = dc.assemble(build(**kwargs))
    assert fresh.functions is not shared.functions
    for a, b in zip(_functions_at(shared, 1), _functions_at(fresh, 1)):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def test_new_numbers_compile_nothing_and_keep_the_physics():
    runs = []
    for clearance in (0.5e-3, 0.25e-3):
        scene = dc.mechanisms.slider_crank("revolute", clearance=clearance, gravity=0.0)
        runs.append(dc.simulate(scene, t_end=0.003, rtol=1e-7))
    assert runs[1].stats["compile_time"] == 0.0
    for run, clearance in zip(runs, (0.5e-3, 0.25e-3)):
        # the first impact happens at the clearance the run was given
        onset = run.events.of("clearance", kind="onset")[0]
        i = int(np.searchsorted(run.t, onset.t))
        assert run["clearance.eccentricity"][i] == pytest.approx(clearance, rel=1e-3)
    assert runs[0].events.of("clearance", kind="onset")[0].t > runs[1].events.of("clearance", kind="onset")[0].t


def test_structure_changes_get_their_own_template():
    reference = dc.assemble(dc.mechanisms.slider_crank("revolute")).functions
    same = [dict(clearance=0.1e-3), dict(rpm=100.0), dict(gravity=0.0), dict(restitution=0.5),
            dict(bearing_radius=20e-3), dict(name="renamed")]
    for kwargs in same:
        assert dc.assemble(dc.mechanisms.slider_crank("revolute", **kwargs)).functions is reference, kwargs
    different = [dict(friction=0.1), dict(restitution=1.0), dict(law="hertz")]
    for kwargs in different:
        assert dc.assemble(dc.mechanisms.slider_crank("revolute", **kwargs)).functions is not reference, kwargs
    assert (dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="ggl").functions
            is not dc.assemble(dc.mechanisms.slider_crank("revolute"), formulation="index1").functions)
    assert dc.assemble(dc.mechanisms.slider_crank("revolute"), track_work=True).functions is not reference


def test_lubricated_joint_numbers_are_parameters_and_its_theory_is_structure():
    def scene(**law):
        return dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(**{"viscosity": 0.04, "length": 0.02,
                                                                                 **law}))

    reference = dc.assemble(scene())
    assert reference.parameter("clearance.law.viscosity")[0] == 0.04
    assert reference.parameter("clearance.law.length")[0] == 0.02
    assert reference.parameter("clearance.law.roughness")[0] == 1e-6
    assert reference.parameter("clearance.law.film_parameter")[0] == 1.0
    assert reference.parameter("clearance.law.hysteresis")[0] == 1.0
    assert reference.parameter("clearance.law.dry.restitution")[0] == 0.9
    for law in (dict(viscosity=0.002), dict(length=0.05), dict(roughness=3e-6, film_parameter=2.0, hysteresis=0.2)):
        assert dc.assemble(scene(**law)).functions is reference.functions, law
    for law in (dict(theory="long"), dict(cavitation="full"), dict(dry=normal_law("hertz"))):
        assert dc.assemble(scene(**law)).functions is not reference.functions, law


def test_translational_readings_change_the_structure_only_with_the_equations():
    base = dict(joint="translational", reading="pseudo-corners")
    reference = dc.assemble(dc.mechanisms.slider_crank(**base))
    for kwargs in (dict(slider_mass=0.98, slider_inertia=4.1e-4), dict(pin_offset=(-0.025, 0.0)), dict(gravity=0.0),
                   dict(restitution=0.7)):
        model = dc.assemble(dc.mechanisms.slider_crank(**base, **kwargs))
        assert model.functions is reference.functions, kwargs
    assert reference.parameter("clearance.law.stiffness")[0] == pytest.approx(5.98612e9, rel=1e-5)  # (4.27)
    assert reference.parameter("clearance.law.exponent")[0] == 1.5
    moved = dc.assemble(dc.mechanisms.slider_crank(**base, pin_offset=(-0.025, 0.003), slider_mass=0.98))
    assert moved.parameter("C.s_i").tolist() == pytest.approx([-0.025, 0.003])  # the pin, slider coordinates
    assert moved.parameter("slider.mass")[0] == 0.98
    linear = dc.assemble(dc.mechanisms.slider_crank(joint="translational", reading="pseudo-corners-linear"))
    assert linear.functions is not reference.functions  # n = 1: the law's linear branch
    faces = dc.assemble(dc.mechanisms.slider_crank(joint="translational", reading="unified"))
    assert faces.functions is not reference.functions  # face terms
    # a reading's name is not structure: corners ((3.5)) and pseudo-corners ((4.27)) differ in K only
    corners = dc.assemble(dc.mechanisms.slider_crank(joint="translational"))
    assert corners.functions is reference.functions
    assert corners.parameter("clearance.law.stiffness")[0] != reference.parameter("clearance.law.stiffness")[0]
    # while the model a reading selects is (section-4.3: face terms, like 'unified')
    section = dc.assemble(dc.mechanisms.slider_crank(joint="translational", reading="section-4.3"))
    assert section.functions is not reference.functions


def test_named_parameters():
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.3e-3, rpm=6000.0), "index1", alpha=7.0)
    assert model.parameter("clearance.clearance")[0] == pytest.approx(0.3e-3)
    assert model.parameter("drive.speed")[0] == pytest.approx(6000.0 * np.pi / 30.0)
    assert model.parameter("baumgarte.alpha")[0] == 7.0
    assert model.parameter("gravity").tolist() == [0.0, -9.81]
    with pytest.raises(KeyError, match="clearance.clearance"):
        model.parameter("clearance.nope")


def _resolved(law):
    for kind, radii in (("internal_cylinder", (0.01, 0.0095)), ("sphere_plane", (1e-3,)), ("plane_face", None)):
        try:
            return law.resolve(kind, radii=radii, materials=STEEL, face_half_width=0.025)
        except dc.SceneError:
            continue
    raise AssertionError(f"{law!r} resolves for no kind")


@pytest.mark.parametrize("name", sorted(NORMAL_LAWS))
def test_normal_laws_run_with_symbolic_numbers_or_are_baked(name):
    import casadi as ca

    extra = {"restitution": 0.8} if name in ("lankarani-nikravesh", "hunt-crossley", "flores") else {}
    if name in ("dubowsky-freudenstein", "esdu-78035", "goldsmith"):
        extra = {"length": 0.02}
    law = _resolved(normal_law(name, **extra))
    values = law_values(law)
    if not is_parametric(law):
        assert values == {}  # baked: its numbers are structure (a new value, a new template)
        return
    names = sorted(values)
    P = ca.SX.sym("P", len(names))
    twin = symbolic_law(law, {f"law.{k}": P[i:i + 1] for i, k in enumerate(names)}, "law")
    d, r, v = ca.SX.sym("d"), ca.SX.sym("r"), ca.SX.sym("v")
    f = ca.Function("f", [d, r, v, P], [twin.force(d, r, v) if law.needs_approach_speed else twin.force(d, r)])
    for delta, rate in ((2e-6, 0.4), (4e-5, -0.3), (-1e-6, 0.2)):
        expected = law.force(delta, rate, 0.9) if law.needs_approach_speed else law.force(delta, rate)
        assert float(f(delta, rate, 0.9, [values[k] for k in names])) == pytest.approx(expected, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("name", sorted(FRICTION_LAWS))
def test_friction_laws_are_parametric(name):
    law = friction_law(name, **({} if name == "none" else {"coefficient": 0.2}))
    assert is_parametric(law)


def test_drift_against_the_smallest_clearance_is_reported():
    """index-1 with Baumgarte drifts (multipliers are out of the error test): at c = 0.01 mm and
    rtol 1e-6 the drift over a revolution (12 ms) is about 2e-7 m (1e-8 after 2 ms, where it
    sits on the warning's threshold), far above 1e-3 of the clearance: a warning names it; the
    drift-free GGL formulation stays far below it, and so does the chapter's 0.5 mm clearance
    over 4 ms."""
    scene = dc.mechanisms.slider_crank("revolute", clearance=1e-5)
    with pytest.warns(dc.DaeclearWarning, match="constraints drifted"):
        drifting = dc.simulate(scene, t_end=0.012, rtol=1e-6, options=dc.SolverOptions(formulation="index1"))
    assert drifting.stats["max_constraint_drift"] > 5e-8
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", dc.DaeclearWarning)
        exact = dc.simulate(scene, t_end=0.012, rtol=1e-6, options=dc.SolverOptions(formulation="ggl"))
        chapter = dc.simulate(dc.mechanisms.slider_crank("revolute"), t_end=0.004, rtol=1e-6,
                              options=dc.SolverOptions(formulation="index1"))
    assert exact.stats["max_constraint_drift"] < 1e-2 * drifting.stats["max_constraint_drift"]
    assert chapter.stats["max_constraint_drift"] < 1e-3 * 0.5e-3


def test_a_scene_changed_in_place_is_assembled_anew():
    """An unchanged scene object skips validation and parameter extraction; replacing an element,
    reassigning gravity or adding an element is seen (the numbers and the structure follow)."""
    import dataclasses

    scene = dc.mechanisms.slider_crank("revolute", clearance=0.3e-3)
    first = dc.assemble(scene)
    assert dc.assemble(scene).parameter("clearance.clearance")[0] == pytest.approx(0.3e-3)
    i = next(k for k, e in enumerate(scene.elements) if e.name == "clearance")
    scene.elements[i] = dataclasses.replace(scene.elements[i], clearance=0.2e-3)
    assert dc.assemble(scene).parameter("clearance.clearance")[0] == pytest.approx(0.2e-3)
    scene.gravity = (0.0, -1.0)
    assert dc.assemble(scene).parameter("gravity").tolist() == [0.0, -1.0]
    scene.add(dc.Body("extra", mass=1.0, inertia=0.1, position=(1.0, 1.0)))
    grown = dc.assemble(scene)
    assert grown.n_q == first.n_q + 3 and grown.functions is not first.functions
    scene.elements[i] = dataclasses.replace(scene.elements[i], clearance=-1.0)
    with pytest.raises(dc.SceneError, match="clearance"):
        dc.assemble(scene)  # validated again


def test_a_scene_seen_before_reuses_its_model_and_start():
    """assemble(scene) of an unchanged scene binds the same structure again; a model remembers its
    consistent start, which equals one computed anew, and a model with new numbers starts afresh."""
    scene = dc.mechanisms.slider_crank("revolute", clearance=0.4e-3, gravity=0.0)
    model = dc.assemble(scene)
    # (no memo of scenes seen, issue 35): the same scene assembles to an equal value on the same structure
    rebuilt = dc.assemble(scene)
    assert rebuilt.structure is model.structure and rebuilt.functions is model.functions
    np.testing.assert_array_equal(rebuilt.parameter_values, model.parameter_values)
    memo = model.structure.starts  # the structure's: the models keep none
    assert rebuilt.structure.starts is memo and dc.assemble(scene, "index1").structure is not model.structure
    memo.clear()  # shared by every model of this structure (other tests filled it)
    first = dc.simulate(model, 1e-4, rtol=1e-7)
    assert len(memo) == 1  # the run filled its structure's memo
    y0, yp0 = model.initial_state()  # python evaluation: its own entry
    y0[:] = np.nan  # the caller's copy: the memo stays as it was
    again = model.initial_state()
    fresh = _fresh_start(model)
    np.testing.assert_array_equal(again[0], fresh[0])
    np.testing.assert_array_equal(again[1], fresh[1])
    second = dc.simulate(model, 1e-4, rtol=1e-7)
    np.testing.assert_array_equal(first.y, second.y)
    # one structure, one memo: another clearance reads the same start (the start does not depend
    # on it), which equals one computed anew for that clearance
    other = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.3e-3, gravity=0.0))
    assert other.structure.starts is memo
    entries = len(memo)
    shared = other.initial_state()
    assert len(memo) == entries  # read, not computed
    fresh_other = _fresh_start(other)
    np.testing.assert_array_equal(shared[0], fresh_other[0])
    np.testing.assert_array_equal(shared[1], fresh_other[1])
    # a copy with other numbers shares the filled memo but never reads a start of the old numbers
    slower = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.4e-3, gravity=0.0, rpm=4000.0))
    copied = dataclasses.replace(model, parameter_values=slower.parameter_values)
    assert copied.structure.starts is memo and memo
    y_copied = copied.initial_state()[0]
    np.testing.assert_allclose(y_copied, slower.initial_state()[0], rtol=1e-9, atol=1e-12)
    assert not np.allclose(y_copied, again[0])  # the crank turns slower: other velocities


def _fresh_start(model):
    """``model.initial_state()`` computed anew: its structure's memo of starts emptied for the call, then restored."""
    memo = model.structure.starts
    kept = dict(memo)
    memo.clear()
    try:
        return model.initial_state()
    finally:
        memo.clear()
        memo.update(kept)


def test_the_start_depends_on_the_numbers_its_functions_read():
    """The memo key of the chapter's start holds exactly the parameters that the kinematics and
    accelerations read (CasADi's sparsity): not the clearance joint's clearance, radii and law;
    a new mass or driver speed computes a new start, a declared start keys on every number."""
    from daeclear.assembly.dae_model import start_parameters

    model = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.4e-3, friction=0.1))
    names = [name for name, size in model.parameter_layout for _ in range(size)]
    read = {names[i] for i in model.start_parameters}
    unread = set(names) - read
    assert {"clearance.clearance", "clearance.bearing_radius", "clearance.journal_radius",
            "clearance.law.stiffness", "clearance.law.restitution"} <= unread
    assert all(name.startswith("clearance.") for name in unread)  # only the clearance joint's numbers
    assert {"crank.mass", "rod.inertia", "slider.mass", "gravity", "drive.speed"} <= read
    np.testing.assert_array_equal(model.start_parameters, start_parameters(model.functions))
    memo = model.structure.starts
    memo.clear()
    model.initial_state()
    heavier = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.4e-3, friction=0.1, slider_mass=1.5))
    assert heavier.structure.starts is memo
    y_heavy, yp_heavy = heavier.initial_state()
    assert len(memo) == 2  # a new mass: a new start
    assert not np.allclose(y_heavy, model.initial_state()[0])  # other multipliers (the motion is driven)
    wider = dc.assemble(dc.mechanisms.slider_crank("revolute", clearance=0.5e-3, friction=0.1))
    wider.initial_state(start="declared")
    model.initial_state(start="declared")
    assert len(memo) == 4  # declared: the clearance is part of the key


def test_the_start_memo_keeps_the_latest_starts(monkeypatch):
    """A structure's start memo is bounded (a long sweep of masses): beyond START_MEMO_LIMIT the
    oldest start goes, and a start computed again equals the one it replaces."""
    from daeclear.assembly import dae_model

    monkeypatch.setattr(dae_model, "START_MEMO_LIMIT", 2)
    models = [dc.assemble(dc.mechanisms.slider_crank("revolute", slider_mass=mass)) for mass in (1.0, 1.5, 2.0)]
    memo = models[0].structure.starts
    memo.clear()
    first = models[0].initial_state()
    models[1].initial_state()
    models[2].initial_state()
    assert len(memo) == 2
    again = models[0].initial_state()  # evicted, computed anew
    assert len(memo) == 2
    np.testing.assert_array_equal(first[0], again[0])
    np.testing.assert_array_equal(first[1], again[1])


def test_a_damaged_cached_library_is_built_again(tmp_path):
    """A cached library truncated after its build (a full disk, a killed copy) is detected by its
    digest and rebuilt by the next process, never loaded (loading it could crash the interpreter).
    Each step runs in its own process, as it would in life: a library loaded in this process must
    not be changed under it."""
    import os
    import subprocess
    import sys

    script = ("import warnings, daeclear as dc; warnings.simplefilter('ignore'); "
              "r = dc.simulate(dc.mechanisms.slider_crank('revolute'), t_end=5e-4); "
              "print(r.success, r.stats['compile_time'] > 0)")
    env = {**os.environ, "DAECLEAR_CACHE_DIR": str(tmp_path)}

    def run() -> str:
        out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout.split()[-2:]

    assert run() == ["True", "True"]  # built
    assert run() == ["True", "False"]  # loaded from the cache
    (library,) = tmp_path.glob("dc_*.so")
    library.write_bytes(library.read_bytes()[: library.stat().st_size * 9 // 10])  # keeps its build tag
    assert run() == ["True", "True"]  # built again, not loaded


def _loaded_crank(scale: float) -> dc.Scene:
    """The revolute-clearance slider-crank with every kind of load (daeclear.loads), its numbers
    multiplied by ``scale``: the structure does not change with ``scale``."""
    scene = dc.mechanisms.slider_crank("revolute", rpm=3000.0 * scale)
    ramp = dc.Table((0.0, 1e-3 * scale, 2e-3), (0.0, 5.0 * scale, 2.0))
    wave = dc.Expression(lambda t, s, p: p.F * dc.loads.sin(p.w * t) - p.c * s.vx,
                         F=3.0 * scale, w=900.0, c=0.1 * scale)
    scene.add(dc.Force("push", "slider", fx=wave, fy=ramp, at=(0.17, 0.01 * scale)))
    scene.add(dc.Force("follower", "rod", fx=1.0 * scale, frame="body"))
    scene.add(dc.Torque("twist", "rod", dc.Expression(lambda t, s, p: -p.k * s.angle, k=0.2 * scale),
                        reaction="crank"))
    scene.add(dc.SpringDamper("spring", "ground", "slider", at_i=(0.3, 0.0), at_j=(0.17, 0.0),
                              stiffness=100.0 * scale, damping=0.5 * scale, free_length=0.1 * scale))
    scene.add(dc.RotationalSpringDamper("torsion", "crank", "rod", stiffness=0.5 * scale, damping=1e-3 * scale))
    scene.add(dc.Motor("motor", "ground", "crank", stall_torque=2.0 * scale, no_load_speed=300.0 * scale))
    return scene


def test_loads_are_parameters_new_numbers_compile_nothing():
    first = dc.assemble(_loaded_crank(1.0), track_work=True)
    shared = dc.assemble(_loaded_crank(1.7), track_work=True)
    assert shared.functions is first.functions, "numbers only: the template must be reused"
    assert shared.parameter("spring.stiffness")[0] == pytest.approx(170.0)
    assert shared.parameter("push.fy.times").tolist() == pytest.approx([0.0, 1.7e-3, 2e-3])
    assert shared.parameter("push.fx.F")[0] == pytest.approx(5.1)
    assert shared.parameter("motor.no_load_speed")[0] == pytest.approx(510.0)
    clear_memos()
    fresh = dc.assemble(_loaded_crank(1.7), track_work=True)
    assert fresh.functions is not shared.functions
    for seed in (1, 2):
        for a, b in zip(_functions_at(shared, seed), _functions_at(fresh, seed)):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    base = dc.simulate(_loaded_crank(1.0), t_end=2e-4, rtol=1e-6)
    again = dc.simulate(_loaded_crank(1.3), t_end=2e-4, rtol=1e-6)
    assert base.stats["compile_time"] >= 0.0 and again.stats["compile_time"] == 0.0


def test_load_structure_changes_get_their_own_template():
    reference = dc.assemble(_loaded_crank(1.0)).functions
    scene = _loaded_crank(1.0)
    i = next(k for k, e in enumerate(scene.elements) if e.name == "push")
    scene.elements[i] = dataclasses.replace(scene.elements[i], fy=dc.Table((0.0, 1e-3), (0.0, 5.0)))  # 2 points
    assert dc.assemble(scene).functions is not reference
    scene = _loaded_crank(1.0)
    scene.elements[i] = dataclasses.replace(scene.elements[i], fy=4.0)  # a number, not a table
    assert dc.assemble(scene).functions is not reference
    scene = _loaded_crank(1.0)
    j = next(k for k, e in enumerate(scene.elements) if e.name == "follower")
    scene.elements[j] = dataclasses.replace(scene.elements[j], frame="world")
    assert dc.assemble(scene).functions is not reference


def _driven(kind: str, second: bool) -> dc.Scene:
    """Driven scenes (tests/test_drivers.py) in two versions that differ only in numbers."""
    from daeclear.model.profiles import Harmonic, Ramp, Tabulated
    from test_drivers import crank_bearing_clearance, disc_scene, inclined_block

    if kind == "ramp":
        return disc_scene(Ramp(time=0.2 if second else 0.05), speed=3.0 if second else 10.0)
    if kind == "harmonic":
        return disc_scene(Harmonic(amplitude=0.1, frequency=3.0, phase=-1.0) if second else
                          Harmonic(amplitude=0.4, frequency=20.0, phase=0.7))
    if kind == "tabulated":
        values = (0.0, 1.0, 1.5, 4.0) if second else (0.3, 0.5, 0.2, 0.9)
        return disc_scene(Tabulated(times=(0.0, 0.01, 0.05, 0.06) if second else (0.0, 0.03, 0.07, 0.1),
                                    values=values), speed=None)
    if kind == "translational":
        scene = inclined_block("clearance")
        if second:
            k = next(i for i, e in enumerate(scene.elements) if e.name == "push")
            scene.elements[k] = dataclasses.replace(scene.elements[k], speed=-0.8, initial_position=0.0,
                                                    profile=Harmonic(amplitude=0.5, frequency=1.0))
        return scene
    return crank_bearing_clearance(0.1e-3 if second else 0.4e-3)


@pytest.mark.parametrize("kind", ["ramp", "harmonic", "tabulated", "translational", "crank-bearing"])
def test_driver_numbers_compile_nothing(kind):
    """Drivers (profiles, translational and clearance joints driven): numbers share the template, and
    the shared template equals a fresh build for the second numbers."""
    first = dc.assemble(_driven(kind, False))
    shared = dc.assemble(_driven(kind, True))
    assert shared.functions is first.functions, "numbers only: the template must be reused"
    assert not np.array_equal(shared.parameter_values, first.parameter_values)
    clear_memos()
    fresh = dc.assemble(_driven(kind, True))
    assert fresh.functions is not shared.functions
    for seed in (1, 2):
        for a, b in zip(_functions_at(shared, seed), _functions_at(fresh, seed)):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def test_driver_structure_changes_get_their_own_template():
    """The profile kind and a table's number of points are structure."""
    from daeclear.model.profiles import Harmonic, Ramp, Tabulated
    from test_drivers import disc_scene

    ramp = dc.assemble(disc_scene(Ramp(time=0.1))).functions
    assert dc.assemble(disc_scene(Harmonic(amplitude=0.1, frequency=1.0))).functions is not ramp
    assert dc.assemble(disc_scene(None)).functions is not ramp
    four = dc.assemble(disc_scene(Tabulated(times=(0, 1, 2, 3), values=(0, 1, 2, 3)), speed=None)).functions
    assert dc.assemble(disc_scene(Tabulated(times=(0, 1, 2, 3), values=(0, 2, 1, 3)), speed=None)).functions is four
    assert dc.assemble(disc_scene(Tabulated(times=(0, 1, 2, 3, 4), values=(0, 1, 2, 3, 4)),
                                  speed=None)).functions is not four


def test_a_sweeps_scenes_differ_in_the_elements_that_changed():
    """The scenes of new clearances have equal elements but the clearance joint, and equal laws (they
    are made anew for each call: keeping them by their values to share them gained less than the noise
    of a sweep, docs/engine.md); other numbers, or the same number as an int, make other elements;
    equal elements, shared or not, have one structure."""
    from daeclear.assembly.parameters import structure_key

    a, b = (dc.mechanisms.slider_crank("revolute", clearance=c) for c in (1e-4, 2e-4))
    for x, y in zip(a.elements, b.elements):
        assert (x == y) == (x.name != "clearance"), x.name
    assert a["clearance"].law == b["clearance"].law
    other = dc.mechanisms.slider_crank("revolute", clearance=1e-4, rpm=3000.0)
    assert other["crank"] is not a["crank"]
    assert other["crank"].angular_velocity == pytest.approx(3000.0 * 2.0 * np.pi / 60.0)
    assert type(dc.mechanisms.slider_crank(slider_mass=1)["slider"].mass) is int
    assert type(dc.mechanisms.slider_crank(slider_mass=1.0)["slider"].mass) is float
    assert structure_key(a.elements, ["ggl"]) == structure_key(b.elements, ["ggl"])
    unshared = [dataclasses.replace(e) for e in a.elements]  # new objects: nothing kept on them yet
    assert structure_key(unshared, ["ggl"]) == structure_key(a.elements, ["ggl"])
    assert structure_key(other.elements, ["ggl"]) == structure_key(a.elements, ["ggl"])  # numbers only
    assert structure_key(a.elements, ["index1"]) != structure_key(a.elements, ["ggl"])


def test_values_are_kept_on_frozen_elements_only():
    """elements.kept computes once on a frozen element, every time on a mutable one (its fields can change)."""
    from daeclear.model.elements import kept

    @dataclasses.dataclass
    class Mutable:
        x: float

    calls: list[float] = []

    def compute(element) -> float:
        calls.append(element.x)
        return element.x

    loose = Mutable(1.0)
    assert kept(loose, "_x", compute) == 1.0
    loose.x = 2.0
    assert kept(loose, "_x", compute) == 2.0 and calls == [1.0, 2.0]
    body = dc.Body("b", mass=1.0, inertia=0.1)
    calls.clear()
    assert [kept(body, "_mass", lambda e: compute(Mutable(e.mass))) for _ in range(3)] == [1.0] * 3
    assert calls == [1.0]
    assert dataclasses.replace(body) == body and "_mass" not in dataclasses.replace(body).__dict__

    @dataclasses.dataclass(frozen=True, slots=True)
    class Slotted:  # frozen, but nowhere to keep a value: computed every time
        x: float

    calls.clear()
    assert [kept(Slotted(3.0), "_x", compute) for _ in range(2)] == [3.0, 3.0] and calls == [3.0, 3.0]


def test_values_kept_with_other_objects_follow_those_objects():
    """elements.kept_with reuses a value while the element is given the very same (frozen) objects,
    and computes it anew for other objects, equal or not, or for a mutable element or input."""
    from daeclear.model.elements import kept_with

    @dataclasses.dataclass
    class Mutable:
        x: float

    joint = dc.Revolute("A", "b", "ground", at=(0.0, 0.0))
    b1, b2 = dc.Body("b", mass=1.0, inertia=0.1), dc.Body("b", mass=1.0, inertia=0.1)
    calls: list[str] = []

    def compute(tag: str) -> str:
        calls.append(tag)
        return tag

    assert kept_with(joint, "_v", (b1,), lambda _: compute("first")) == "first"
    assert kept_with(joint, "_v", (b1,), lambda _: compute("again")) == "first"
    assert kept_with(joint, "_v", (b2,), lambda _: compute("equal, not the same")) == "equal, not the same"
    assert kept_with(joint, "_v", (b2, b1), lambda _: compute("more")) == "more"
    loose = Mutable(1.0)
    assert kept_with(joint, "_w", (loose,), lambda _: compute("mutable input")) == "mutable input"
    assert kept_with(joint, "_w", (loose,), lambda _: compute("mutable input again")) == "mutable input again"
    assert kept_with(loose, "_v", (b1,), lambda _: compute("mutable element")) == "mutable element"
    assert "_v" not in vars(loose)
    assert calls == ["first", "equal, not the same", "more", "mutable input", "mutable input again",
                     "mutable element"]


def test_kept_parameter_entries_follow_the_bodies_they_were_read_from():
    """A joint given by a world point has body-fixed points that depend on where its bodies are
    declared: a scene that shares the joint but moves a body gets the points of its own bodies (the
    values kept on the joint are the first scene's), equal to those of a scene of new objects."""
    from daeclear.assembly.assemble import scene_parameters

    def scene(x_link: float, joint: dc.Revolute | None = None) -> dc.Scene:
        link = dc.Body("link", mass=1.0, inertia=0.01, position=(x_link, 0.0))
        pin = joint or dc.Revolute("A", "ground", "link", at=(0.0, 0.0))
        return dc.Scene("pendulum", elements=[link, pin])

    first = scene(0.5)
    pin = first["A"]
    table, key, _ = scene_parameters(first, "ggl", 5.0, 5.0, False)
    np.testing.assert_array_equal(table.value("A.s_j"), [-0.5, 0.0])
    moved, key2, _ = scene_parameters(scene(0.3, pin), "ggl", 5.0, 5.0, False)
    np.testing.assert_array_equal(moved.value("A.s_j"), [-0.3, 0.0])
    fresh, key3, _ = scene_parameters(scene(0.3), "ggl", 5.0, 5.0, False)
    np.testing.assert_array_equal(moved.vector, fresh.vector)
    assert key == key2 == key3  # numbers only
    again, _, _ = scene_parameters(first, "ggl", 5.0, 5.0, False)
    np.testing.assert_array_equal(again.vector, table.vector)


def test_each_element_reads_its_own_bodies_only():
    """An element's kept parameter entries are checked against the bodies it joins (a driver: its joint and
    that joint's bodies), not against every body: a scene's set-up grows like N, not N^2. A chain that
    shares every element but one moved link gets new entries for the two pins on that link and its
    driver, the very same ones for everything else, and the parameter vector of a scene of new objects."""
    from daeclear.assembly.assemble import scene_parameters

    first = dc.mechanisms.chain(4, rpm=120.0)
    table, key, _ = scene_parameters(first, "ggl", 5.0, 5.0, False)
    link1 = dataclasses.replace(first["link1"], position=(0.06, 0.01))
    moved = dc.Scene(first.name, gravity=first.gravity, ground=first.ground,
                     elements=[link1 if e.name == "link1" else e for e in first.elements])
    before = {e.name: e.__dict__["_parameter_entries"][1] for e in first.elements}
    table2, key2, _ = scene_parameters(moved, "ggl", 5.0, 5.0, False)
    after = {e.name: e.__dict__["_parameter_entries"][1] for e in moved.elements}
    renewed = {name for name in after if after[name] is not before[name]}
    assert renewed == {"link1", "pin1", "pin2", "drive"} and key2 == key
    fresh = dc.Scene(first.name, gravity=first.gravity, ground=first.ground,
                     elements=[dataclasses.replace(e) for e in moved.elements])
    np.testing.assert_array_equal(scene_parameters(fresh, "ggl", 5.0, 5.0, False)[0].vector, table2.vector)
    assert not np.array_equal(table2.vector, table.vector)


def test_a_models_scene_description_is_the_scene_as_it_was_assembled():
    """model.parameters["scene"] equals Scene.to_dict() at assembly, whatever happens to the scene
    later (it is made at its first read from the elements the scene had); with a mutable element it
    is made at once, so a later change of that element does not show either."""
    scene = dc.mechanisms.slider_crank("revolute", clearance=1e-4)
    expected = scene.to_dict()
    model = dc.assemble(scene)
    scene.name = "renamed"
    scene.elements[0] = dataclasses.replace(scene.elements[0], mass=9.0)
    described = model.parameters["scene"]
    assert described == expected and dict(described) == expected
    assert described["elements"]["crank"]["mass"] != 9.0

    from daeclear.model.elements import Element

    @dataclasses.dataclass
    class Marker(Element):  # a mutable element (of a user's own)
        name: str
        value: float

    loose = dc.Scene("loose", elements=[Marker("m", 1.0), dc.Body("link", mass=1.0, inertia=0.01)])
    description = loose.description()
    loose.elements[0].value = 2.0
    assert description["elements"]["m"] == {"kind": "Marker", "name": "m", "value": 1.0}


def test_a_clearance_joints_checks_run_once(monkeypatch):
    """clearance_joint checks the new joint (a bad value raises at once) and keeps the findings, so
    the scene's validation (and the assembly) does not check the joint again."""
    from daeclear.model.clearance_joints import RevoluteClearance

    with pytest.raises(dc.SceneError, match="clearance"):
        dc.mechanisms.slider_crank("revolute", clearance=0.02)  # larger than the bearing radius
    scene = dc.mechanisms.slider_crank("revolute", clearance=1.5e-4)
    calls: list[str] = []
    original = RevoluteClearance.problems
    monkeypatch.setattr(RevoluteClearance, "problems", lambda self: calls.append(self.name) or original(self))
    scene.validate()
    dc.assemble(scene)
    assert calls == []
    fresh = dataclasses.replace(scene["clearance"])  # a new object: nothing kept on it
    scene.elements[scene.elements.index(scene["clearance"])] = fresh
    scene.validate()
    assert calls == ["clearance"]


# ---- the one name space (issue 42 item 3, issue 44 item 5) ------------------------------------------
def _loads_and_profiles() -> dc.Scene:
    """Every load kind, a table in time, and a driver with a motion profile."""
    from daeclear.model.profiles import Ramp

    scene = dc.Scene("loaded", gravity=(0.0, -9.81))
    link = scene.add(dc.Body("link", mass=1.0, inertia=0.01, position=(0.5, 0.0)))
    arm = scene.add(dc.Body("arm", mass=0.5, inertia=0.005, position=(1.5, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, link, at=(0.0, 0.0)))
    scene.add(dc.Revolute("B", link, arm, at=(1.0, 0.0)))
    scene.add(dc.Driver("drive", "A", speed=2.0, profile=Ramp(time=0.05)))
    scene.add(dc.Force("push", "arm", fx=1.0, fy=dc.Table((0.0, 0.1, 0.2), (0.0, 2.0, 0.0)), at=(2.0, 0.0)))
    scene.add(dc.Torque("twist", "arm", dc.Table((0.0, 0.5), (0.0, 0.3)), reaction="link"))
    scene.add(dc.SpringDamper("spring", "ground", "arm", at_i=(2.0, 0.5), at_j=(2.0, 0.0), stiffness=40.0,
                              damping=0.2))
    scene.add(dc.RotationalSpringDamper("torsion", "link", "arm", stiffness=3.0, damping=0.01, free_angle=0.1))
    return scene


def _motor() -> dc.Scene:
    scene = dc.Scene("motor", gravity=(0.0, 0.0))
    crank = scene.add(dc.Body("crank", mass=1.0, inertia=0.01, position=(0.0, 0.0)))
    scene.add(dc.Revolute("A", scene.ground, crank, at=(0.0, 0.0)))
    scene.add(dc.Motor("motor", "ground", "crank", stall_torque=0.5, no_load_speed=10.0))
    return scene


NAME_SPACE_SCENES = {
    "revolute-ln-friction": lambda: dc.mechanisms.slider_crank("revolute", friction=0.1),
    "revolute-hunt-crossley-coulomb": lambda: dc.mechanisms.slider_crank("revolute", law="hunt-crossley",
                                                                          friction=dc.contact.Coulomb(coefficient=0.1)),
    **{f"revolute-{name}": (lambda name=name: dc.mechanisms.slider_crank("revolute", law=name))
       for name in ("hertz", "flores")},
    **{f"revolute-{name}": (lambda name=name: dc.mechanisms.slider_crank("revolute", law=name, length=0.02))
       for name in ("dubowsky-freudenstein", "goldsmith", "esdu-78035")},
    "revolute-kelvin-voigt": lambda: dc.mechanisms.slider_crank(
        "revolute", law=normal_law("kelvin-voigt", stiffness=5e8, damping=1e3)),
    "lubricated-short": lambda: dc.mechanisms.slider_crank(
        "revolute", friction=0.1, law=HydrodynamicBearing(viscosity=0.04, length=0.02, dry=normal_law("hertz"))),
    "lubricated-finite": lambda: dc.mechanisms.slider_crank(
        "revolute", law=HydrodynamicBearing(viscosity=0.04, length=0.015, theory="finite", asperity_modulus=1e11)),
    "worn-both": lambda: dc.mechanisms.slider_crank("revolute", friction=0.1).with_values(
        {"clearance.wear": dc.contact.wear.ArchardWear(coefficient=1e-13, length=0.02, surface="both")}),
    "translational-corners": lambda: dc.mechanisms.slider_crank("translational", friction=0.1),
    "translational-section-4.3": lambda: dc.mechanisms.slider_crank("translational", contact_model="section-4.3"),
    "translational-reading": lambda: dc.mechanisms.slider_crank("translational", reading="unified"),
    "four-bar": lambda: dc.mechanisms.four_bar(clearance_joints=("B", "C")),
    "double-pendulum": lambda: dc.mechanisms.double_pendulum(clearance_joints=("A",)),
    "loads-and-profile": _loads_and_profiles,
    "motor": _motor,
}


def _scene_value(scene: dc.Scene, name: str):
    if name == "gravity":
        return scene.gravity
    element, *path = name.split(".")
    value = scene[element]
    for field in path:
        value = getattr(value, field)
    return value


def _nudged(value):
    """A slightly different value of the same kind (every number x (1 - 1e-3); an ordered table stays ordered)."""
    if isinstance(value, (tuple, list)):
        return type(value)(_nudged(v) for v in value)
    return value * (1.0 - 1e-3) if isinstance(value, float) else value


@pytest.mark.parametrize("label", sorted(NAME_SPACE_SCENES))
@pytest.mark.parametrize("formulation", ["ggl", "index1"])
def test_every_listed_name_round_trips(label, formulation):
    """Every name model.parameter_names lists is accepted by with_parameters, compiles nothing, and gives
    the model assembled from the scene with that value (an independent build); its value read back from
    the new model's scene is the one given. The structural names are refused, read-only."""
    scene = NAME_SPACE_SCENES[label]()
    model = dc.assemble(scene, formulation)
    names = model.parameter_names
    assert names and not set(names) & set(model.structural_names)
    assert ("baumgarte.alpha" in names) == (formulation == "index1")
    for name in names:
        if name.startswith("baumgarte."):
            value = getattr(model, name.split(".")[1]) * (1.0 - 1e-3)
            new = model.with_parameters({name: value})
            assert new.functions is model.functions and new.parameter(name)[0] == value
            continue
        same = model.with_parameters({name: _scene_value(scene, name)})
        assert same.functions is model.functions, name
        np.testing.assert_array_equal(same.parameter_values, model.parameter_values, err_msg=name)
        value = _nudged(_scene_value(scene, name))
        new = model.with_parameters({name: value})
        assert new.functions is model.functions, name
        assert _scene_value(new.scene, name) == value, name
        built = dc.assemble(scene.with_values({name: value}), formulation)
        np.testing.assert_array_equal(new.parameter_values, built.parameter_values, err_msg=name)
    for name in model.structural_names:
        with pytest.raises(SceneError, match=f"{name!r} is structure of the model .read-only"):
            model.with_parameters({name: _scene_value(scene, name)})


def test_the_names_the_issue_named():
    """clearance.s_i (derived) and clearance.film.viscosity are not names; clearance.law.viscosity and, for the
    dry law inside a bearing, clearance.law.dry.restitution are; a restitution of the bearing itself is none."""
    plain = dc.assemble(dc.mechanisms.slider_crank("revolute"))
    assert "clearance.s_i" not in plain.parameter_names and plain.parameter("clearance.s_i").size == 2
    assert "clearance.law.restitution" in plain.parameter_names
    lubricated = dc.assemble(dc.mechanisms.slider_crank("revolute", law=HydrodynamicBearing(viscosity=0.04,
                                                                                             length=0.02)))
    names = lubricated.parameter_names
    assert {"clearance.law.viscosity", "clearance.law.dry.restitution"} <= set(names)
    assert not {"clearance.film.viscosity", "clearance.law.restitution", "clearance.s_i"} & set(names)
    with pytest.raises(SceneError, match="HydrodynamicBearing has no field 'restitution'"):
        lubricated.with_parameters({"clearance.law.restitution": 0.5})
    with pytest.raises(SceneError, match="'clearance.law.dry' is structure of the model"):
        lubricated.with_parameters({"clearance.law.dry": normal_law("hertz")})
    with pytest.raises(SceneError, match="'clearance.law.stiffness' is not one of the model's numbers"):
        plain.with_parameters({"clearance.law.stiffness": 1e10})  # derived here: give it in the scene


def test_a_run_of_floats_is_numbers_as_its_entries_are():
    """is_numbers reads a flat run of floats (a worn profile) at once: the same answer as entry by entry."""
    from daeclear.assembly.parameter_names import is_numbers

    assert is_numbers((1e-6,) * 360) and is_numbers([0.5, 2]) and is_numbers(((0.1, 0.2), (0.3, 0.4)))
    assert not is_numbers((0.5, True)) and not is_numbers((0.5, "a")) and not is_numbers(()) and not is_numbers(
        (0.5, None))
    scene = dc.mechanisms.slider_crank("revolute").with_values(
        {"clearance.wear": dc.contact.wear.ArchardWear(coefficient=1e-13, length=0.02)})
    floats = dc.assemble(scene.with_values({"clearance.wear_depth": (1e-6,) * 360}))
    mixed = dc.assemble(scene.with_values({"clearance.wear_depth": (1e-6,) * 359 + (0,)}))
    assert floats.structure is mixed.structure  # a worn profile's numbers are masked alike in the structure key
