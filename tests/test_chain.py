"""The chain of N links with a clearance joint at every pin (``daeclear.mechanisms.chain``).

Measured (0.05 s from the horizontal, free chain): N = 1: 8 impacts (Lankarani-Nikravesh c_e = 0.9);
N = 3: 35, every pin hit. Elastic frictionless Hertz contact under gravity: mechanical plus elastic
contact energy constant to 1.0e-8 (N = 1) and 6.5e-9 (N = 3) of the peak kinetic energy at rtol 1e-8
(7e-7 and 1.0e-6 at rtol 1e-6), while the contact stores up to 3.3e-3 and 2.5e-3 of it: the
mechanical energy alone varies 2.5e-3..3.3e-3. A single link with 1 um clearance follows the ideal
pendulum to 1.5e-5 rad over 0.1 s (1.5 c/L; 1.5e-4 at 10 um, 1.5e-3 at 0.1 mm).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import daeclear as dc
from daeclear.core.errors import SceneError
from daeclear.model.mechanisms import CHAIN_LINK_INERTIA, CHAIN_LINK_LENGTH, CHAIN_LINK_MASS, chain
from daeclear.model.scenefile import MECHANISMS, read_scene_file


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_sizes_free_and_driven(n: int) -> None:
    """States are q 3N + v 3N + lambda m (index-1), + mu m (GGL, the default): no constraint when
    free, pin + driver (m = 3) when driven."""
    free = dc.assemble(chain(n), "index1").summary()
    assert free == {**free, "bodies": n, "states": 6 * n, "constraints": 0, "terms": n, "gaps": n}
    driven = dc.assemble(chain(n, rpm=600.0), "index1").summary()
    assert driven == {**driven, "bodies": n, "states": 6 * n + 3, "constraints": 3, "terms": n - 1, "gaps": n - 1}
    assert dc.assemble(chain(n)).summary()["states"] == 6 * n
    assert dc.assemble(chain(n, rpm=600.0)).summary()["states"] == 6 * n + 6


def test_scene_layout() -> None:
    scene = chain(3, angle=-np.pi / 2)  # hanging straight down
    assert [b.name for b in scene.bodies] == ["link1", "link2", "link3"]
    assert [j.name for j in scene.joints] == ["pin1", "pin2", "pin3"]
    assert all(isinstance(j, dc.RevoluteClearance) for j in scene.joints)
    assert scene["pin1"].body_i == "ground" and scene["pin3"].body_i == "link2" and scene["pin3"].body_j == "link3"
    np.testing.assert_allclose(scene["pin3"].at, (0.0, -2 * CHAIN_LINK_LENGTH), atol=1e-15)
    np.testing.assert_allclose(scene["link3"].position, (0.0, -2.5 * CHAIN_LINK_LENGTH), atol=1e-15)
    driven = chain(2, rpm=60.0)
    assert type(driven["pin1"]) is dc.Revolute and driven["drive"].joint == "pin1"
    np.testing.assert_allclose(driven["link2"].velocity, (0.0, 1.5 * CHAIN_LINK_LENGTH * 2 * np.pi), rtol=1e-12)


@pytest.mark.parametrize("n", [1, 3])
def test_simulates_with_contacts_at_every_pin(n: int) -> None:
    result = dc.simulate(chain(n), 0.05, rtol=1e-6)
    assert result.success
    for k in range(1, n + 1):
        assert len(result.events.of(f"pin{k}", kind="onset")) >= 1
        assert result[f"pin{k}.penetration"].max() > 0
    assert result["link1.phi"][-1] < -1e-3  # the chain swings down


@pytest.mark.parametrize("n", [1, 3])
def test_elastic_contact_conserves_mechanical_plus_elastic_energy(n: int) -> None:
    """Gravity only, frictionless Hertz: E_mech + sum K delta^(n+1)/(n+1) is constant.

    The tolerance 1e-6 of the peak kinetic energy is 100x the drift measured at rtol 1e-8 and
    2500x below the energy the contacts store, so a wrong contact force (direction, lever arm,
    stiffness) or a lost impact fails it.
    """
    scene = chain(n, law="hertz")
    result = dc.simulate(scene, 0.05, rtol=1e-8)
    assert len(result.events.of(kind="onset")) >= n
    elastic = np.zeros_like(result.t)
    for k in range(1, n + 1):
        law = scene[f"pin{k}"].resolved_law()
        delta = np.maximum(result[f"pin{k}.penetration"], 0.0)
        elastic += law.stiffness * delta ** (law.exponent + 1) / (law.exponent + 1)
    scale = result["energy.kinetic"].max()
    assert elastic.max() > 1e-3 * scale  # not vacuous: the contacts store energy
    assert np.ptp(result["energy.mechanical"] + elastic) < 1e-6 * scale


def test_tiny_clearance_follows_the_ideal_pendulum() -> None:
    """One link, 1 um clearance: within 5 c/L rad of the ideal pendulum (measured 1.5 c/L)."""
    ideal = dc.Scene("pendulum")
    link = ideal.add(dc.Body("link1", mass=CHAIN_LINK_MASS, inertia=CHAIN_LINK_INERTIA,
                             position=(0.5 * CHAIN_LINK_LENGTH, 0.0)))
    ideal.add(dc.Revolute("pin1", ideal.ground, link, at=(0.0, 0.0)))
    t_eval = np.linspace(0.0, 0.1, 201)
    reference = dc.simulate(ideal, 0.1, rtol=1e-8, save=dc.SaveAt(times=t_eval))
    clearance = 1e-6
    result = dc.simulate(chain(1, clearance=clearance), 0.1, rtol=1e-8, save=dc.SaveAt(times=t_eval))
    assert reference["link1.phi"][-1] < -0.5  # a large swing, not a small-angle check
    assert np.abs(result["link1.phi"] - reference["link1.phi"]).max() < 5 * clearance / CHAIN_LINK_LENGTH


@pytest.mark.parametrize("kwargs, field", [
    ({"n_links": 0}, "n_links"), ({"n_links": 2.0}, "n_links"), ({"n_links": True}, "n_links"),
    ({"n_links": "3"}, "n_links"), ({"n_links": 2, "clearance": 0.0}, "clearance"),
    ({"n_links": 2, "clearance": 0.02}, "clearance"), ({"n_links": 2, "rpm": float("nan")}, "rpm"),
    ({"n_links": 2, "gravity": -1.0}, "gravity"), ({"n_links": 2, "link_length": 0.015}, "bearing_radius"),
    ({"n_links": 2, "link_mass": 0}, "link_mass"), ({"n_links": 2, "joint": "revolute"}, "joint"),
])
def test_invalid_inputs_name_the_field(kwargs: dict, field: str) -> None:
    with pytest.raises(SceneError, match=rf"chain: .*{field}"):
        chain(**kwargs)


def test_registered_for_scene_files_and_command_line(tmp_path: Path) -> None:
    assert MECHANISMS["chain"] is chain
    path = tmp_path / "chain.toml"
    path.write_text('[mechanism]\nname = "chain"\nn_links = 2\nclearance = 0.2e-3\n\n[simulate]\nt_end = 0.01\n')
    spec = read_scene_file(path)
    assert [b.name for b in spec.scene.bodies] == ["link1", "link2"]
    assert spec.scene["pin2"].clearance == 0.2e-3 and spec.simulate == {"t_end": 0.01}
    path.write_text('[mechanism]\nname = "chain"\n')
    with pytest.raises(SceneError, match="n_links"):
        read_scene_file(path)


def test_command_line_runs_a_chain(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from daeclear.cli import main

    code = main(["run", "chain", "--set", "n_links=1", "--t-end", "0.01", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    assert dc.load(tmp_path / "chain1.h5").t[-1] == pytest.approx(0.01)
    assert (tmp_path / "chain1.png").stat().st_size > 10_000  # the link's motion and energy, no slider
    assert main(["run", "chain", "--set", "n_links=2", "--joint", "revolute", "--out", str(tmp_path)]) == 2
    assert main(["run", "chain", "--out", str(tmp_path)]) == 2
    assert "n_links" in capsys.readouterr().err


def test_generated_code_grows_linearly_and_sparse_outputs_are_scattered() -> None:
    """The terms' residuals and the extras keep CasADi's sparsity (a pin's force touches two bodies,
    the start kinematics a few coordinates per row): the generated instructions grow like N, not
    N^2 (dense outputs made them 9.9k, 21k, 44k + N^2 zeros at N = 8, 16, 32), and the compiled
    driver scatters the sparse outputs into the same dense vectors CasADi evaluates."""
    from daeclear.assembly.dae_model import EXTRA_START_KINEMATICS, EXTRA_TERM0
    from daeclear.engine.codegen import normalize_model
    from daeclear.engine.ida_session import open_session

    def instructions(n_links: int) -> int:
        nm = normalize_model(dc.assemble(chain(n_links)).functions)
        return sum(f.n_instructions() for f in (nm.res, nm.jac, nm.roots, *nm.extras, *nm.term_res, *nm.term_jac))

    small, large = instructions(4), instructions(16)
    assert 3.5 < large / small < 4.5  # measured 4.1 (N^1.02)
    model = dc.assemble(chain(3))
    nm = normalize_model(model.functions)
    start, force = nm.extras[EXTRA_START_KINEMATICS], nm.extras[EXTRA_TERM0 + 1]
    assert start.nnz_out(0) < start.numel_out(0) and force.nnz_out(0) == 6 < force.numel_out(0)  # links 1, 2
    assert nm.term_res[0].nnz_out(0) == 3  # the force on the one link of the ground pin
    session = open_session(model.functions, backend="c", rtol=1e-8, atol=1e-10,
                           parameters=model.parameter_values)
    try:
        rng = np.random.default_rng(3)
        q, v = rng.normal(size=(5, model.n_q)), rng.normal(size=(5, model.n_q))
        t = np.linspace(0.0, 1e-3, 5)
        compiled = model.evaluate(EXTRA_START_KINEMATICS, [q, v, t.reshape(-1, 1)], 5, session)
        symbolic = model.evaluate(EXTRA_START_KINEMATICS, [q, v, t.reshape(-1, 1)], 5)
        np.testing.assert_allclose(compiled, symbolic, rtol=1e-13, atol=1e-15)
        assert np.count_nonzero(compiled[0]) > 0 and compiled.shape == (5, start.numel_out(0))
        p = np.zeros(model.terms[1].n_params)
        inputs = [t.reshape(-1, 1), q, v, np.tile(p, (5, 1))]
        forces = model.evaluate(EXTRA_TERM0 + 1, inputs, 5, session)
        np.testing.assert_allclose(forces, model.evaluate(EXTRA_TERM0 + 1, inputs, 5), rtol=1e-13, atol=1e-15)
        counts = np.count_nonzero(forces, axis=1)  # a pin in contact pushes both links, else nothing
        assert set(counts.tolist()) <= {0, 6} and np.sum(counts == 6) >= 3
    finally:
        session.close()


def test_the_ode_library_keeps_sparsity_and_agrees_with_casadi() -> None:
    """The explicit methods' generated functions keep their sparsity too (a term's Jacobian has
    the columns of two links: dense, the code grew like N^3 on chains: 3.8k, 16k, 89k instructions
    at N = 4, 8, 16); the ODE driver scatters them, and its right-hand side, Jacobian and gaps agree
    with the CasADi evaluation of the same model, contacts switched on."""
    from daeclear.solvers.ode_evaluators import evaluator
    from daeclear.solvers.ode_model import _symbolic_spec

    def instructions(n_links: int) -> int:
        spec = _symbolic_spec(dc.assemble(chain(n_links), "index1"))
        return sum(f.n_instructions() for f in (spec.sys, spec.sys_jac, *spec.term_force, *spec.term_jac))

    assert 3.5 < instructions(16) / instructions(4) < 5.0  # measured 4.4 (N^1.07)
    model = dc.assemble(chain(3), "index1")
    compiled, symbolic = evaluator(model, "c"), evaluator(model, "python")
    assert compiled.backend == "c" and symbolic.backend == "python"
    rng = np.random.default_rng(5)
    params = [np.zeros(term.n_params) for term in model.terms]
    for active in ([False] * 3, [True] * 3):
        for ev in (compiled, symbolic):
            ev.set_terms(active, params)
        for _ in range(3):
            x = rng.normal(size=2 * model.n_q)
            np.testing.assert_allclose(compiled.rhs(0.01, x), symbolic.rhs(0.01, x), rtol=1e-11, atol=1e-9)
            jac = compiled.jac(0.01, x)
            np.testing.assert_allclose(jac, symbolic.jac(0.01, x), rtol=1e-10, atol=1e-6)
            assert np.count_nonzero(jac) > 0
            for mine, theirs in zip(compiled.gaps(0.01, x), symbolic.gaps(0.01, x)):
                np.testing.assert_allclose(mine, theirs, rtol=1e-12, atol=1e-15)
