"""One solver contract (issue 35): the registry of methods, the protocol, and a solver class given as ``method``."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

import daeclear as dc
from daeclear.core import options
from daeclear.core.errors import SceneError
from daeclear.solvers.base import Solver, step_rule
from daeclear.solvers.registry import SOLVERS

T = 2e-3  # s: a short run of the ideal slider-crank (the C library is cached per structure)


class WrappedEuler:
    """A user's solver: explicit Euler under its own name, delegating to the registered one."""

    name: ClassVar[str] = "wrapped-euler"
    formulation: ClassVar[str] = "index1"
    runs: ClassVar[int] = 0

    def check(self, settings: dc.SolverOptions) -> None:
        step_rule(self.name, settings.step, fixed=True)  # the rule of the fixed-step methods, under its name

    def run(self, model, t_end, t0, y0, save, settings, on_failure, progress) -> dc.Result:
        type(self).runs += 1
        return SOLVERS["euler"]().run(model, t_end, t0, y0, save, settings, on_failure, progress)


def test_every_method_name_has_a_registered_class_that_implements_the_protocol() -> None:
    assert tuple(SOLVERS) == options.METHODS  # the names checked by options.method, no more, no fewer
    for key, cls in SOLVERS.items():
        assert isinstance(cls(), Solver), key
        assert cls.name.lower() == key
        assert cls.formulation == options.default_formulation(key)


def test_a_solver_class_given_as_method_runs_as_the_method_it_wraps() -> None:
    scene = dc.mechanisms.slider_crank("ideal", gravity=0.0)
    save = dc.SaveAt(times=np.linspace(0.0, T, 21))
    builtin = dc.simulate(scene, T, options=dc.SolverOptions(method="EULER", step=1e-5), save=save)
    before = WrappedEuler.runs
    wrapped = dc.simulate(scene, T, options=dc.SolverOptions(method=WrappedEuler, step=1e-5), save=save)
    assert WrappedEuler.runs == before + 1
    assert wrapped.success and wrapped.method == builtin.method == "euler"
    np.testing.assert_array_equal(wrapped.t, builtin.t)
    np.testing.assert_array_equal(wrapped.y, builtin.y)
    # the class as simulate's keyword, the step from options: the same run
    keyword = dc.simulate(scene, T, method=WrappedEuler, options=dc.SolverOptions(method="euler", step=1e-5),
                          save=save)
    np.testing.assert_array_equal(keyword.y, builtin.y)


def test_each_solver_refuses_what_it_does_not_take_naming_the_method_and_the_option() -> None:
    with pytest.raises(SceneError, match=r"simulate: method='wrapped-euler' is a fixed-step scheme and needs step="):
        dc.SolverOptions(method=WrappedEuler)
    with pytest.raises(SceneError, match=r"simulate: step=1e-05 is only for the fixed-step methods .*method='ida'"):
        dc.SolverOptions(step=1e-5)
    with pytest.raises(SceneError, match=r"simulate: step=1e-05 is only for the fixed-step methods .*method='LSODA'"):
        dc.SolverOptions(method="lsoda", step=1e-5)
    with pytest.raises(SceneError, match=r"simulate: track_work=True is supported by method='ida' only, not by "
                                         r"method='RK45'"):
        dc.simulate(dc.mechanisms.slider_crank("ideal"), T, options=dc.SolverOptions(method="RK45", track_work=True))


def test_a_class_that_is_not_a_solver_is_refused() -> None:
    class NoRun:
        name, formulation = "no-run", "index1"

        def check(self, settings) -> None:
            pass

    with pytest.raises(SceneError, match=r"SolverOptions: method=<class .*NoRun'>, must be a registered method "
                                         r"name or a class implementing daeclear.solvers.base.Solver .*; it lacks run"):
        dc.SolverOptions(method=NoRun)
    with pytest.raises(SceneError, match=r"simulate: method=<class 'int'>, must be a registered method name"):
        dc.simulate(dc.mechanisms.slider_crank("ideal"), T, method=int)


def test_a_solver_class_is_stored_by_its_import_path_and_read_back() -> None:
    """to_dict gives JSON (a sweep file, a result's parameters): a class as "module:Class", which
    from_dict, SolverOptions and simulate read back to the class; a path that does not import is refused."""
    import json

    given = dc.SolverOptions(method=WrappedEuler, step=1e-5)
    stored = json.loads(json.dumps(given.to_dict()))
    assert stored["method"] == f"{__name__}:WrappedEuler"
    assert dc.SolverOptions.from_dict(stored) == given and dc.SolverOptions.from_dict(stored).method is WrappedEuler
    assert dc.SolverOptions(method="daeclear.solvers.explicit:Euler", step=1e-5).method.name == "euler"
    assert dc.SolverOptions(method="lsoda").to_dict()["method"] == "lsoda"  # a name stays a name
    with pytest.raises(SceneError, match=r"SolverOptions: method='no_such_module:Solver', must be a registered "
                                         r"method name or the import path 'module:Class' of a solver class .*"
                                         r"ModuleNotFoundError"):
        dc.SolverOptions(method="no_such_module:Solver")
    with pytest.raises(SceneError, match=r"method='daeclear:NoSuchClass', .*AttributeError"):
        dc.SolverOptions(method="daeclear:NoSuchClass")
    with pytest.raises(SceneError, match=r"method='daeclear:__version__', must be an import path 'module:Class' "
                                         r"naming a class"):
        dc.SolverOptions(method="daeclear:__version__")


def test_simulate_takes_at_most_fourteen_parameters() -> None:
    import inspect

    assert len(inspect.signature(dc.simulate).parameters) <= 14


def custom_solver_example():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "custom_solver.py"
    spec = importlib.util.spec_from_file_location("custom_solver", path)
    assert spec is not None and spec.loader is not None
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    return example


def test_the_custom_solver_example_integrates_a_scipy_scheme_with_the_contact_events() -> None:
    """examples/custom_solver.py's RK23 (scipy's scheme, not registered): the driver finds the same
    impact sequence as IDA at rtol 1e-10 over a quarter revolution, the first onset to 1e-10 s."""
    example = custom_solver_example()
    events, first, largest = example.onset_gaps(example.REVOLUTION / 4)
    assert events >= 10 and first < 1e-10 and largest < 1e-7


def test_the_custom_solver_example_estimates_rk4s_error() -> None:
    """examples/custom_solver.py: a user's class (rk4 twice, Richardson) passed as method; its error
    estimate of the finer run agrees with the true error against DOP853 at rtol 1e-12."""
    example = custom_solver_example()
    assert example.main(["--quick"]) == 0
    span = example.REVOLUTION / 4
    model = dc.assemble(dc.mechanisms.slider_crank("ideal"), "index1")
    save = dc.SaveAt(every=span / 60)
    cls = example.RichardsonRK4
    fine = dc.simulate(model, span, options=dc.SolverOptions(method=cls, step=2e-4), save=save)
    direct = dc.simulate(model, span, options=dc.SolverOptions(method="rk4", step=1e-4), save=save)
    np.testing.assert_array_equal(fine.y, direct.y)  # the finer run is rk4 at half the step
    reference = dc.simulate(model, span, method="DOP853", rtol=1e-12, save=save)
    k = model.state_names.index("slider.x")
    true = np.max(np.abs(fine.y[:, k] - reference.y[:, k]))
    estimated = np.max(np.abs(cls.estimate[:, k]))
    assert true > 1e-10  # well above the reference's error
    assert 0.8 < estimated / true < 1.25
    with pytest.raises(SceneError, match=r"rk4-richardson: needs output times"):
        dc.simulate(model, span, options=dc.SolverOptions(method=cls, step=2e-4))
