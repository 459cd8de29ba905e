"""Inputs that were silently changed, ignored or misreported (issue 45), one table.

Each row is a call, the error it must raise, and the texts its message must hold: the field (or
option) and the value given, and for the errors of ``assembled`` the joints involved. The runs
these inputs used to start were wrong without a word: two contradictory joint speeds fitted by
least squares, ``baumgarte.alpha`` on a GGL model ignored, a custom solver whose ``run`` returned
None handed back as the result, ``dc.load(path, t0=nan)`` an empty "successful" result.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import daeclear as dc
from daeclear.cli import main
from daeclear.core.errors import AssemblyError, SceneError

IDEAL = dc.mechanisms.slider_crank()
REVOLUTE = dc.mechanisms.slider_crank("revolute")
FREE_FOUR_BAR = dc.mechanisms.four_bar().without("drive")
FREE_SLIDER_CRANK = dc.mechanisms.slider_crank().without("drive")
NAN = math.nan
T = 1e-4  # s


def solver_class(**members: Any) -> type:
    """A solver class wrapping IDA, with ``members`` replaced."""
    from daeclear.solvers.registry import SOLVERS

    class Wrapped:
        name, formulation = "wrapped", "ggl"

        def check(self, settings: Any) -> None:
            SOLVERS["ida"]().check(settings)

        def run(self, *args: Any) -> Any:
            return SOLVERS["ida"]().run(*args)

    for key, value in members.items():
        setattr(Wrapped, key, value)
    return Wrapped


def result_file(tmp_path: Path) -> Path:
    path = tmp_path / "run.h5"
    dc.simulate(IDEAL, 2e-3).save(path)
    return path


def from_a_module_raising_on_import(tmp_path: Path) -> dc.SolverOptions:
    """Options naming a solver class by the import path of a module that raises a RuntimeError when imported."""
    import sys

    (tmp_path / "broken_solvers.py").write_text("raise RuntimeError('no licence for the solver')\n")
    sys.path.insert(0, str(tmp_path))
    try:
        return dc.SolverOptions(method="broken_solvers:Solver")
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("broken_solvers", None)


def cli(*argv: str) -> Callable[[Path], Any]:
    """A command line that must exit 2 (its message on stderr checked by the test)."""
    def call(tmp_path: Path) -> None:
        code = main(list(argv))
        if code == 2:
            raise SystemExit(2)
        raise AssertionError(f"daeclear {' '.join(argv)} exited {code}, not 2")
    return call


CASES: list[tuple[str, Callable[[Path], Any], type[BaseException], tuple[str, ...]]] = [
    # (id, call(tmp_path), error, texts the message holds)
    # assembled(start=, speeds=): over-determined speeds no motion has, a dead-centre start that cannot reach
    ("four-bar two contradictory speeds",
     lambda p: dc.place(FREE_FOUR_BAR, start={"A": 0.5}, speeds={"A": 1.0, "B": 5.0}), AssemblyError,
     ("speeds={'A': 1.0, 'B': 5.0} contradict the joints", "B.rate = ", "(5 given)", "1 degree(s) of freedom")),
    ("slider-crank crank and slider speeds disagree",
     lambda p: dc.place(FREE_SLIDER_CRANK, start={"A": 1.0}, speeds={"A": 100.0, "D": 5.0}), AssemblyError,
     ("speeds={'A': 100.0, 'D': 5.0}", "D.speed = ", "(5 given)")),
    ("speed not finite", lambda p: dc.place(FREE_SLIDER_CRANK, start={"A": 1.0}, speeds={"A": math.inf}),
     SceneError, ("speeds['A']=inf", "finite")),
    ("start beyond the stroke from a dead centre",
     lambda p: dc.place(FREE_SLIDER_CRANK, start={"D": 0.2}), AssemblyError,
     ("start={'D': 0.2}", "D (displacement) is at a singular configuration", "D.displacement = ")),
    # options that do not apply to the formulation
    ("baumgarte.alpha on GGL at its default", lambda p: dc.assemble(REVOLUTE).with_parameters({"baumgarte.alpha": 5}),
     SceneError, ("baumgarte.alpha=5", "index1", "ggl")),
    ("baumgarte.beta on GGL", lambda p: dc.assemble(REVOLUTE).with_parameters({"baumgarte.beta": 2.0}),
     SceneError, ("baumgarte.beta=2.0", "index1")),
    ("simulate parameters baumgarte on GGL",
     lambda p: dc.simulate(REVOLUTE, T, parameters={"baumgarte.alpha": 5}), SceneError, ("baumgarte.alpha=5",)),
    ("assemble alpha with GGL", lambda p: dc.assemble(REVOLUTE, "ggl", alpha=5.0), SceneError,
     ("alpha=5.0", "formulation='ggl'")),
    ("assemble beta with GGL", lambda p: dc.assemble(REVOLUTE, beta=2.0), SceneError, ("beta=2.0", "index1")),
    ("assemble alpha nan", lambda p: dc.assemble(REVOLUTE, "index1", alpha=NAN), SceneError, ("alpha=nan",)),
    ("baumgarte.alpha negative on index1",
     lambda p: dc.assemble(REVOLUTE, "index1").with_parameters({"baumgarte.alpha": -1.0}), SceneError,
     ("alpha=-1.0",)),
    ("a model's formulation overridden by options",
     lambda p: dc.simulate(dc.assemble(REVOLUTE), T, options=dc.SolverOptions(formulation="index1")), SceneError,
     ("options.formulation='index1'", "'ggl'")),
    ("IDA's linear solver for RK45", lambda p: dc.SolverOptions(method="RK45", linear_solver="sparse"), SceneError,
     ("linear_solver='sparse'", "RK45")),
    ("IDA's linear solver for rk4", lambda p: dc.SolverOptions(method="rk4", step=1e-5, linear_solver="dense"),
     SceneError, ("linear_solver='dense'", "rk4")),
    # the custom-solver contract, checked where the class is given
    ("solver formulation index7", lambda p: dc.SolverOptions(method=solver_class(formulation="index7")), SceneError,
     ("method=", "'index7'", "ggl")),
    ("solver formulation None", lambda p: dc.simulate(IDEAL, T, method=solver_class(formulation=None)), SceneError,
     ("method=", "formulation is one of", "not None")),
    ("solver name empty", lambda p: dc.SolverOptions(method=solver_class(name="")), SceneError,
     ("method=", "name is a non-empty string", "not ''")),
    ("solver name a number", lambda p: dc.SolverOptions(method=solver_class(name=3)), SceneError,
     ("method=", "not 3")),
    ("solver run returns None", lambda p: dc.simulate(IDEAL, T, method=solver_class(run=lambda self, *a: None)),
     SceneError, ("method=", "run() returns a daeclear.Result", "returned NoneType")),
    ("solver run returns a dict", lambda p: dc.simulate(IDEAL, T, method=solver_class(run=lambda self, *a: {})),
     SceneError, ("returned dict",)),
    ("solver module raises on import", from_a_module_raising_on_import, SceneError,
     ("method='broken_solvers:Solver'", "RuntimeError: no licence for the solver")),
    # dc.load and Result windows
    ("load t0 nan", lambda p: dc.load(result_file(p), t0=NAN), SceneError, ("load: t0=nan", "None")),
    ("load t1 nan", lambda p: dc.load(result_file(p), t1=NAN), SceneError, ("load: t1=nan",)),
    ("load t0 text", lambda p: dc.load(result_file(p), t0="0.001"), SceneError, ("t0='0.001'",)),
    ("load t0 after t1", lambda p: dc.load(result_file(p), t0=0.002, t1=0.001), SceneError,
     ("t0=0.002 s", "t1=0.001")),
    ("load a directory", lambda p: dc.load(p), IsADirectoryError, ("is a directory", str(Path("run.h5")))),
    ("load_times of a directory", lambda p: dc.results.result.load_times(p), IsADirectoryError, ("is a directory",)),
    ("slice t0 nan", lambda p: dc.simulate(IDEAL, T).slice(NAN, None), SceneError, ("Result.slice: t0=nan",)),
    # tolerances: a table of atol is a shape error
    ("atol 2-D", lambda p: dc.simulate(IDEAL, T, atol=np.full((2, 9), 1e-6)), SceneError,
     ("atol=array of shape (2, 9)", "one-dimensional")),
    ("atol 2-D in SolverOptions", lambda p: dc.SolverOptions(atol=[[1e-6]]), SceneError, ("shape (1, 1)",)),
    # the output cap: the exact count (1 000 001 is over the cap of 1 000 000)
    ("100 s every 1e-4", lambda p: dc.simulate(IDEAL, 100.0, save=dc.SaveAt(every=1e-4)), SceneError,
     ("save.every=0.0001", "1 000 001 output points", "max_points=1000000")),
    # the command line: a --help for what does not exist
    ("run unknown --help", cli("run", "nonexistent", "--help"), SystemExit, ("'nonexistent'", "neither")),
    ("study unknown --help", cli("study", "five_bar", "--help"), SystemExit, ("'five_bar'",)),
    ("sweep unknown --help", cli("sweep", "five_bar", "s.h5", "--help"), SystemExit, ("'five_bar'",)),
]


@pytest.mark.parametrize("case, call, error, texts", CASES, ids=[c[0] for c in CASES])
def test_refused_with_the_field_and_the_value(case: str, call: Callable[[Path], Any], error: type[BaseException],
                                              texts: tuple[str, ...], tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(error) as info:
        call(tmp_path)
    message = str(info.value) if error is not SystemExit else capsys.readouterr().err
    for text in texts:
        assert text in message, f"{case}: {text!r} not in {message!r}"
    if error is SystemExit:
        assert message.startswith("daeclear: error: ") and message.count("\n") == 1  # one line, no traceback
