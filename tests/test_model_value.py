"""The model is a value (issue 42, item 3): its structure and one scene's numbers, made by its constructor
(``with_parameters`` too); it keeps no cache. What a process keeps of a structure, the libraries its functions
were compiled and loaded into and the consistent starts found, is the structure's, shared by its models."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import daeclear as dc
from daeclear.assembly.dae_model import DAEModel
from daeclear.engine import compiled as compiled_module
from daeclear.engine.codegen import clear_memos
from daeclear.engine.ida_session import open_session

#: the fields of a model: its structure, then the numbers of one scene bound to it
VALUE_FIELDS = ["structure", "scene", "alpha", "beta", "parameter_values", "q_guess", "v_guess", "mass_diagonal",
                "parameters", "contacts", "auto_pairs", "clearance_joints"]


@pytest.fixture
def model() -> DAEModel:
    return dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")


def test_a_model_is_its_structure_and_numbers(model):
    assert [f.name for f in dataclasses.fields(model)] == VALUE_FIELDS
    for name in VALUE_FIELDS:  # nothing a run could fill: read-only arrays, tuples, the description
        value = getattr(model, name)
        assert not isinstance(value, (list, set)), name
        assert not isinstance(value, dict) or name == "parameters", name
        assert not isinstance(value, np.ndarray) or not value.flags.writeable, name
    # the structure's functions and names are read through the model, not copied into it
    structure = model.structure
    assert model.functions is structure.functions and model.state_names is structure.state_names
    assert model.parameter_layout is structure.layout and model.compiled is structure.compiled
    assert model.scene_name == model.scene.name == "slider_crank_revolute"
    # a copy by the constructor is the same mechanism
    copy = dataclasses.replace(model)
    assert copy.structure is structure and copy.contacts == model.contacts
    np.testing.assert_array_equal(copy.parameter_values, model.parameter_values)


def test_with_parameters_builds_a_model_by_its_constructor(model, monkeypatch):
    made = []
    original = DAEModel.__post_init__

    def counted(self: DAEModel) -> None:
        made.append(self)
        original(self)

    monkeypatch.setattr(DAEModel, "__post_init__", counted)
    new = model.with_parameters({"crank.mass": 0.4, "baumgarte.alpha": 7.0})
    assert made == [new]  # the constructor, once: no copy around it
    assert new.structure is model.structure and new.alpha == 7.0 and new.parameter("crank.mass")[0] == 0.4
    assert model.alpha == 5.0 and model.parameter("crank.mass")[0] != 0.4  # the model it came from is unchanged
    for name in ("q_guess", "parameter_values"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(new, name)[0] = 1.0


def test_structures_compare_by_identity(model):
    again = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0), "index1")
    assert again.structure is model.structure and again.structure == model.structure
    ggl = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0))
    assert ggl.structure != model.structure and ggl.compiled is not model.compiled


def test_what_a_structure_compiled_is_kept_by_the_structure(monkeypatch):
    """Sessions of a structure's models load its library once (the structure's CompiledDAE); a session on
    bare functions makes its own and leaves the structure's as it was."""
    clear_memos()  # a structure of its own
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0, clearance=0.35e-3), "index1")
    other = model.with_parameters({"clearance.clearance": 0.25e-3})
    assert other.compiled is model.compiled
    loads = []
    real = compiled_module._load_library
    monkeypatch.setattr(compiled_module, "_load_library", lambda *args: loads.append(args) or real(*args))
    settings = dict(backend="c", rtol=1e-6, atol=1e-8, parameters=model.parameter_values)
    for target, expected in ((model.functions, 1), (model.functions, 2), (model.compiled, 3), (model.compiled, 3),
                             (other.compiled, 3)):
        open_session(target, **settings).close()
        assert len(loads) == expected
    clib = model.compiled.library()[0]
    run = dc.simulate(other, 2e-4, options=dc.SolverOptions(backend="c"))
    assert len(loads) == 3 and run.stats["cache_hit"] and model.compiled.library()[0] is clib
    # the explicit methods' ODE spec and library: made once, for every model of the structure
    assert model.compiled.ode_spec is None and model.compiled.ode_library is None
    dc.simulate(model, 2e-4, options=dc.SolverOptions(method="rk45"))
    spec, library = model.compiled.ode_spec, model.compiled.ode_library
    assert spec is not None and library is not None
    dc.simulate(other, 2e-4, options=dc.SolverOptions(method="rk45"))
    assert other.compiled.ode_spec is spec and other.compiled.ode_library is library


def test_open_session_takes_functions_or_their_compiled_library():
    clear_memos()
    model = dc.assemble(dc.mechanisms.slider_crank("revolute", gravity=0.0, clearance=0.45e-3))
    y0, yp0 = model.initial_state()
    ends = []
    for target in (model.functions, model.compiled):
        session = open_session(target, backend="c", rtol=1e-8, atol=1e-10, parameters=model.parameter_values)
        session.reinit(0.0, y0, yp0, [False] * len(model.terms), [np.zeros(t.n_params) for t in model.terms])
        ends.append(session.advance(1e-4, store_steps=False).y)
        session.close()
    np.testing.assert_array_equal(ends[0], ends[1])  # the same library, the same run
