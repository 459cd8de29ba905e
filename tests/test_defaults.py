"""The defaults a run uses, the command line's help texts and the docs say the same (issue 45).

`--t-eval-step`'s help and docs/reliability.md said the default grid was 1 us while the run used 2 us.
The defaults now live in ``daeclear.core.defaults`` (and the dataclasses' fields); the help texts are made
from them, and these tests read the docs' tables and sentences back against them.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import math
import re
from pathlib import Path
from typing import Any

import pytest

import daeclear as dc
from daeclear.core import defaults
from daeclear.cli import build_parser, default_max_steps, default_t_eval_step

ROOT = Path(__file__).resolve().parent.parent


def text_of(name: str) -> str:
    """A document with its line breaks as spaces (a sentence may wrap anywhere)."""
    return re.sub(r"\s+", " ", (ROOT / name).read_text())


def count(n: int) -> str:
    return f"{n:,}".replace(",", " ")


def us(seconds: float) -> str:
    return f"{seconds * 1e6:g} us"


def test_the_code_uses_the_defaults() -> None:
    options, save = dc.SolverOptions(), dc.SaveAt()
    assert (options.rtol, options.max_steps, save.max_points) == (defaults.RTOL, defaults.MAX_STEPS,
                                                                 defaults.MAX_OUTPUT_POINTS)
    assert dc.assemble(dc.mechanisms.slider_crank()).formulation == defaults.FORMULATION
    # daeclear run's grid: t_end / CLI_POINTS, no finer than CLI_FINEST_STEP; its step cap
    assert default_t_eval_step(0.024) == defaults.CLI_FINEST_STEP
    assert default_t_eval_step(100.0) == 100.0 / defaults.CLI_POINTS
    assert default_max_steps(0.024) == defaults.MAX_STEPS
    assert default_max_steps(100.0) == 100 * defaults.CLI_STEPS_PER_SECOND


def subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_the_help_texts_state_the_defaults_the_code_uses() -> None:
    run = re.sub(r"\s+", " ", subparsers()["run"].format_help())
    for stated in (f"relative tolerance (default {defaults.RTOL:g})",
                   f"default: {count(defaults.CLI_STEPS_PER_SECOND)} per simulated second, at least "
                   f"{count(defaults.MAX_STEPS)}",
                   f"t_end / {defaults.CLI_POINTS} but no finer than {defaults.CLI_FINEST_STEP:g} s: at most "
                   f"{count(defaults.CLI_POINTS + 1)} points",
                   f"(default {count(defaults.MAX_OUTPUT_POINTS)},", f"(default {defaults.FORMULATION};",
                   f"decimated to {defaults.CLI_FIGURE_POINTS} points"):
        assert stated in run, stated
    # every option with a default of its own says it, rendered from that default
    for command, parser in subparsers().items():
        for action in parser._actions:
            if action.default in (None, False, [], argparse.SUPPRESS) or not action.help:
                continue
            shown = parser._get_formatter()._expand_help(action)
            value = action.default
            rendered = {f"{value:g}"} if isinstance(value, float) else {str(value), " ".join(map(str, value))} \
                if isinstance(value, tuple) else {str(value)}
            assert "default" in shown and any(r in shown for r in rendered), (command, action.dest, shown)


def test_the_help_texts_have_no_markup() -> None:
    import contextlib
    import io

    from daeclear.cli import main
    from daeclear.model.scenefile import MECHANISMS

    for mechanism in MECHANISMS:
        out = io.StringIO()
        with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
            main(["run", mechanism, "--help"])
        assert "--set keys of" in out.getvalue()
        assert "``" not in out.getvalue() and not re.search(r":[a-z]+:`", out.getvalue()), mechanism
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        main(["run", "slider_crank", "--help"])
    joint = next(line for line in out.getvalue().splitlines() if "--set joint=" in line)
    # the values slider_crank takes, not the joints' names
    assert all(f'"{kind}"' in joint for kind in ("ideal", "revolute", "translational")), joint


@pytest.mark.parametrize("document, stated", [
    ("docs/user_guide.md", f"by default `t_end / {defaults.CLI_POINTS}`, but no finer than "
                           f"{us(defaults.CLI_FINEST_STEP)}, so a run of any length writes at most "
                           f"{count(defaults.CLI_POINTS + 1)} points"),
    ("docs/user_guide.md", f"(default {count(defaults.CLI_STEPS_PER_SECOND)} per simulated second, at least "
                           f"{count(defaults.MAX_STEPS)})"),
    ("docs/user_guide.md", f"`--max-points N` lifts the cap on reported points (default "
                           f"{count(defaults.MAX_OUTPUT_POINTS)}"),
    ("docs/reliability.md", f"at most {count(defaults.CLI_POINTS + 1)} points (`--t-eval-step`, the scene file's "
                            f"`t_eval_step`, or `t_end / {defaults.CLI_POINTS}` but no finer than "
                            f"{us(defaults.CLI_FINEST_STEP)};"),
    ("docs/reliability.md", f"default {count(defaults.CLI_STEPS_PER_SECOND)} per simulated second, at least "
                            f"{count(defaults.MAX_STEPS)})"),
    ("docs/reliability.md", f"(`options.MAX_OUTPUT_POINTS` = {count(defaults.MAX_OUTPUT_POINTS)},"),
    ("docs/examples.md", f"at most {count(defaults.CLI_POINTS + 1)} points, no finer than "
                         f"{us(defaults.CLI_FINEST_STEP)}"),
    ("docs/hdf5_layout.md", f"`SaveAt.max_points` ({count(defaults.MAX_OUTPUT_POINTS)})"),
])
def test_the_docs_state_the_defaults_the_code_uses(document: str, stated: str) -> None:
    assert stated in text_of(document)


def cell_value(text: str) -> Any:
    """A default as the user guide's tables write it: None, True, "auto", 1e-6, 1 000 000, 5e6."""
    text = text.strip().strip("`")
    if text in ("None", "True", "False"):
        return {"None": None, "True": True, "False": False}[text]
    if text.startswith('"') and text.endswith('"'):
        return text[1:-1]
    return float(text.replace(" ", ""))


#: Defaults that a table describes in words: (table, name) -> the words.
DESCRIBED = {("simulate", "atol"): "per quantity, from the mechanism's scales"}


def default_tables() -> dict[str, dict[str, str]]:
    """The user guide's tables of defaults (simulate's keywords, SolverOptions' and SaveAt's fields):
    name -> default cell, each table named by whose defaults it lists."""
    lines = (ROOT / "docs" / "user_guide.md").read_text().splitlines()
    fields = {"SolverOptions": {f.name for f in dataclasses.fields(dc.SolverOptions)},
              "SaveAt": {f.name for f in dataclasses.fields(dc.SaveAt)}}
    tables: dict[str, dict[str, str]] = {}
    for i, line in enumerate(lines):
        if re.match(r"^\| (keyword|field) \| default \| meaning \|$", line):
            rows = {}
            for row in lines[i + 2:]:
                if not row.startswith("|"):
                    break
                cells = [c.strip() for c in row.strip("|").split("|")]
                rows[cells[0].strip("`")] = cells[1]
            owner = "simulate" if line.startswith("| keyword") else next(
                name for name, known in fields.items() if set(rows) <= known)
            tables[owner] = rows
    return tables


def test_the_user_guides_tables_of_defaults_are_the_code_s() -> None:
    tables = default_tables()
    assert set(tables) == {"simulate", "SolverOptions", "SaveAt"}
    options = dc.SolverOptions()
    expected = {
        "SolverOptions": {f.name: getattr(options, f.name) for f in dataclasses.fields(dc.SolverOptions)},
        "SaveAt": {f.name: f.default for f in dataclasses.fields(dc.SaveAt)},
        # simulate's keywords; those given as UNSET take the SolverOptions' value
        "simulate": {name: getattr(options, name) if name in ("method", "rtol", "atol") else p.default
                     for name, p in inspect.signature(dc.simulate).parameters.items() if name not in ("scene",)},
    }
    for table, rows in tables.items():
        assert set(rows) <= set(expected[table]), (table, set(rows) - set(expected[table]))
        for name, cell in rows.items():
            if (table, name) in DESCRIBED:
                assert cell == DESCRIBED[(table, name)] and expected[table][name] is None
                continue
            value, code = cell_value(cell), expected[table][name]
            if isinstance(code, float) or (isinstance(code, int) and not isinstance(code, bool)):
                assert math.isclose(value, code), (table, name, cell, code)
            else:
                assert value == code, (table, name, cell, code)
    # every SolverOptions and SaveAt field is in its table
    assert set(tables["SolverOptions"]) | {"method", "rtol", "atol"} == set(expected["SolverOptions"])
    assert set(tables["SaveAt"]) == set(expected["SaveAt"])
