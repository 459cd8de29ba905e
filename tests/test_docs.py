"""The docs run as written: every block of README.md and docs/*.md (issue 45).

Each document's blocks run in their order, as a reader types them, in one scratch directory of
the document (with a copy of ``examples/``), so no command writes into the checkout: ``python``
blocks share one namespace, ``bash`` blocks run their commands (``daeclear ...`` through the
command line's ``main``, ``python <script>`` in a child process) and must exit 0, ``console``
blocks run their ``$`` commands and must print the lines under them, ``toml`` blocks parse.

Marked blocks (a first line ``# slow: <reason>`` or ``# placeholder: <reason>``, visible to the
reader) are checked too: a slow block runs shortened by the substitutions of ``SHORTENED``
(every slow block has one, and every substitution must apply), a placeholder block must hold a
placeholder (``...``, ``<name>``, ``[--option ...]``) and its names must still exist (its imports
run, its ``dc.`` names resolve, its command-line options are the parser's). Two kinds of command
are checked, not run, whatever their marker: ``python -m pip install`` (the suite's own
installation: the extras it names must exist) and ``python -m pytest`` (the suite itself: the
test files it names must exist).
"""

from __future__ import annotations

import argparse
import ast
import os
import re
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

import doc_blocks  # noqa: E402
from doc_blocks import ROOT, Block, Command  # noqa: E402

#: How the docs test runs each slow block: (document, the block's reason) -> its (old, new) substitutions.
SHORTENED: dict[tuple[str, str], tuple[tuple[str, str], ...]] = {
    ("README.md", "a study, a 25-point sweep, an animation and a figure family's full run (about 1 min)"): (
        ("--methods ida,DOP853,LSODA,rk4", "--methods ida,rk4 --t-end 0.002 --rtols 1e-6 --steps 1e-5 --repeats 1"),
        ("geom:1e-5:5e-4:25", "geom:1e-5:5e-4:2 --revolutions 3 --transient 1"),
        ("--slow-motion 400", "--slow-motion 40"),
        ("examples/revolute_fig4_15.py", "examples/revolute_fig4_15.py --quick")),
    ("docs/examples.md", "the full run of Fig. 4.15, 24 revolutions (about 20 s)"): (
        ("examples/revolute_fig4_15.py ", "examples/revolute_fig4_15.py --quick "),),
    ("docs/examples.md", "ten runs with their figures (about 30 s)"): (
        ("--t-end 0.072", "--t-end 0.004"), ("--name", "--no-figure --t-end 0.004 --name")),
    ("docs/user_guide.md", "100 s of motion, 8 300 crank revolutions (minutes)"): (
        ("100.0, save=save", "0.1, save=save"), ("t0=99.9", "t0=0.09")),
    ("docs/user_guide.md", "six runs with their figures, a study and an animation of 48 frames (about 30 s)"): (
        ("--slow-motion 400", "--slow-motion 40"), ("--t-end 0.06", "--t-end 0.02"), ("--t-end 0.2", "--t-end 0.02")),
    ("docs/user_guide.md", "renders 173 frames (about 15 s)"): (
        ('dc.animate(result, "run.gif")', 'dc.animate(result, "run.gif", fps=2)'), ("fps=20,", "fps=2,")),
}

BLOCKS = doc_blocks.all_blocks()
RUN = [b for b in BLOCKS if b.lang in ("python", "bash", "console") and b.marker != "placeholder"]
PLACEHOLDERS = [b for b in BLOCKS if b.marker == "placeholder"]
PLACEHOLDER = re.compile(r"\.\.\.|<[A-Za-z_][^<>]*>|\[--")


@dataclass
class Page:
    """A document's run so far: its scratch directory, the namespace of its python blocks, the blocks run."""

    scratch: Path
    namespace: dict[str, Any] = field(default_factory=dict)
    done: set[str] = field(default_factory=set)


@pytest.fixture(scope="module")
def pages() -> dict[Path, Page]:
    """Each document's run, shared by its blocks' tests (pytest runs them in the module's order)."""
    return {}


def page_of(block: Block, pages: dict[Path, Page], factory: pytest.TempPathFactory) -> Page:
    if block.path not in pages:
        scratch = factory.mktemp(block.path.stem)
        shutil.copytree(ROOT / "examples", scratch / "examples", ignore=shutil.ignore_patterns("__pycache__"))
        pages[block.path] = Page(scratch)
    return pages[block.path]


def shortened(block: Block) -> str:
    """The text the docs test runs: a slow block's with its substitutions applied."""
    if block.marker != "slow":
        return block.text
    key = (block.path.as_posix(), block.reason)
    assert key in SHORTENED, f"{block.id}: slow block without a shortened run: add {key!r} to SHORTENED"
    text = block.text
    for old, new in SHORTENED[key]:
        assert old in text, f"{block.id}: the shortened run replaces {old!r}, not in the block"
        text = text.replace(old, new)
    return text


def run_python(block: Block, text: str, page: Page) -> None:
    import matplotlib.pyplot as plt

    code = compile(text, block.id, "exec")
    try:
        exec(code, page.namespace)  # noqa: S102 - the docs' code, run as a reader would
    finally:
        plt.close("all")


def run_command(command: Command, page: Page, monkeypatch: pytest.MonkeyPatch,
                capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    """Run one command in the page's scratch directory; return its exit code and what it printed."""
    program = command.argv[0]
    if command.argv[:4] == ["python", "-m", "pip", "install"]:
        check_install(command)
        return 0, ""
    if command.argv[:3] == ["python", "-m", "pytest"]:
        check_pytest(command)
        return 0, ""
    if program == "daeclear":
        from daeclear.cli import main

        with monkeypatch.context() as patch:
            for name, value in command.env.items():
                patch.setenv(name, value)
            capsys.readouterr()
            try:
                code = main(command.argv[1:])
            except SystemExit as exc:  # argparse: --help, a usage error
                code = exc.code if isinstance(exc.code, int) else 1
            out = capsys.readouterr()
        return code, out.out + out.err
    if program == "python":
        env = {**os.environ, **command.env, "MPLBACKEND": "Agg"}
        done = subprocess.run([sys.executable, *command.argv[1:]], cwd=page.scratch, env=env,
                              capture_output=True, text=True, timeout=600)
        return done.returncode, done.stdout + done.stderr
    raise AssertionError(f"the docs test does not know how to run {program!r} in {command.text!r}")


def check_install(command: Command) -> None:
    """``python -m pip install .[extra]``: the checkout, with extras that pyproject.toml declares."""
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    for target in command.argv[4:]:
        match = re.fullmatch(r"(?:\.|daeclear)(?:\[(?P<extras>[a-z,]+)\])?", target)
        assert match is not None, f"{command.text!r}: installs {target!r}, not this package"
        for extra in (match["extras"] or "").split(","):
            assert not extra or extra in extras, f"{command.text!r}: no extra {extra!r} in pyproject.toml"


def check_pytest(command: Command) -> None:
    """``python -m pytest [paths]``: the suite runs these tests itself; each path must exist."""
    for word in command.argv[3:]:
        if not word.startswith("-"):
            path = word.split("::")[0]
            assert (ROOT / path).exists(), f"{command.text!r}: no {path}"


def run_bash(block: Block, text: str, page: Page, monkeypatch: pytest.MonkeyPatch,
             capsys: pytest.CaptureFixture[str]) -> None:
    for line in doc_blocks.logical_lines(text):
        for command in doc_blocks.commands(line):
            code, out = run_command(command, page, monkeypatch, capsys)
            assert code == 0, f"{block.id}: {command.text!r} exited {code}:\n{out[-3000:]}"


def same_output(expected: str, got: str) -> bool:
    """Whether ``got`` reads as ``expected``, whitespace and line breaks aside; ``...`` matches anything."""
    words = [re.escape(w) for w in expected.split()]
    pattern = r"\s+".join(words).replace(re.escape("..."), ".*?")
    return re.fullmatch(r"\s*" + pattern + r"\s*", got, re.S) is not None


def run_console(block: Block, page: Page, monkeypatch: pytest.MonkeyPatch,
                capsys: pytest.CaptureFixture[str]) -> None:
    for line, expected in doc_blocks.console_session(block.text):
        outputs = [run_command(c, page, monkeypatch, capsys)[1] for c in doc_blocks.commands(line)]
        got = "".join(outputs)
        assert same_output(expected, got), f"{block.id}: {line!r} printed\n{got}\nnot\n{expected}"


def execute(block: Block, page: Page, monkeypatch: pytest.MonkeyPatch,
            capsys: pytest.CaptureFixture[str]) -> None:
    page.done.add(block.id)  # tried: a failed block fails once, not again before each later one
    with monkeypatch.context() as patch:
        patch.chdir(page.scratch)
        patch.setenv("MPLBACKEND", "Agg")
        if block.lang == "python":
            run_python(block, shortened(block), page)
        elif block.lang == "bash":
            run_bash(block, shortened(block), page, monkeypatch, capsys)
        else:
            run_console(block, page, monkeypatch, capsys)


@pytest.mark.parametrize("block", RUN, ids=[b.id for b in RUN])
def test_block_runs(block: Block, pages: dict[Path, Page], tmp_path_factory: pytest.TempPathFactory,
                    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    page = page_of(block, pages, tmp_path_factory)
    for earlier in RUN:  # a block selected alone: the document's blocks before it run first
        if earlier.path == block.path and earlier.line < block.line and earlier.id not in page.done:
            execute(earlier, page, monkeypatch, capsys)
    execute(block, page, monkeypatch, capsys)


def test_every_block_has_a_known_language() -> None:
    untagged = [f"{b.id} [{b.lang or 'none'}]" for b in BLOCKS if b.lang not in doc_blocks.LANGUAGES]
    assert not untagged, f"tag each block with one of {', '.join(doc_blocks.LANGUAGES)}: {untagged}"


def test_markers_have_reasons_and_slow_blocks_a_shortened_run() -> None:
    for block in BLOCKS:
        first = block.text.split("\n", 1)[0]
        if block.lang in ("python", "bash") and not block.marker:  # "# Slow -" would run the whole block
            assert not re.match(r"(?i)#\s*(slow|placeholder)\b", first), (
                f"{block.id}: marker {first!r} not understood: write '# slow: <reason>' or '# placeholder: <reason>'")
        if block.marker:
            assert len(block.reason.split()) >= 3, f"{block.id}: # {block.marker}: needs a reason, not {block.reason!r}"
    slow = {(b.path.as_posix(), b.reason): b for b in BLOCKS if b.marker == "slow"}
    assert set(SHORTENED) == set(slow), (f"slow blocks without a shortened run: {sorted(set(slow) - set(SHORTENED))}; "
                                         f"shortened runs of no slow block: {sorted(set(SHORTENED) - set(slow))}")
    for block in slow.values():
        assert shortened(block) != block.text


@pytest.mark.parametrize("block", PLACEHOLDERS, ids=[b.id for b in PLACEHOLDERS])
def test_placeholder_blocks_hold_a_placeholder_and_names_that_exist(block: Block) -> None:
    assert PLACEHOLDER.search(block.text), (f"{block.id}: marked placeholder but holds none ('...', '<name>', "
                                            "'[--option]'): remove the marker so that it runs")
    if block.lang == "python":
        check_python_names(block)
    else:
        for line in doc_blocks.logical_lines(block.text):
            check_cli_options(block.id, line)


def check_python_names(block: Block) -> None:
    """Run the block's imports; every ``dc.a.b`` and ``daeclear.a.b`` it names must exist."""
    import daeclear

    tree = ast.parse(block.text, block.id)
    namespace: dict[str, Any] = {"dc": daeclear, "daeclear": daeclear}
    imports = [node for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom))]
    exec(compile(ast.Module(body=imports, type_ignores=[]), block.id, "exec"), namespace)  # noqa: S102
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute):
            chain = ast.unparse(node)
            if re.fullmatch(r"(dc|daeclear)(\.\w+)+", chain):
                value: Any = namespace[chain.split(".")[0]]
                for part in chain.split(".")[1:]:
                    assert hasattr(value, part), f"{block.id}: {chain} does not exist"
                    value = getattr(value, part)


def cli_options(command: str) -> set[str]:
    """The option strings of ``daeclear <command>``, read from its help."""
    from daeclear.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return set(re.findall(r"--[a-z][a-z-]*", sub.choices[command].format_help()))


def check_cli_options(where: str, text: str) -> None:
    """Every ``--option`` of a ``daeclear <command> ...`` text is an option of that command."""
    match = re.match(r"^daeclear\s+(run|study|sweep|animate)\b", text)
    if match is None:
        return
    known = cli_options(match[1])
    unknown = sorted(set(re.findall(r"(?<![\w-])--[a-z][a-z-]*", text)) - known)
    assert not unknown, f"{where}: daeclear {match[1]} has no option {', '.join(unknown)}"


INLINE = re.compile(r"`((?:daeclear|python) [^`]+)`")


def test_inline_commands_name_scripts_and_options_that_exist() -> None:
    """The commands quoted in the text (``daeclear run ... --max-points N``, ``python examples/x.py``):
    their scripts exist and their options are the command line's."""
    checked = 0
    for path in doc_blocks.documents():
        for number, line in enumerate((ROOT / path).read_text().split("\n"), 1):
            for text in INLINE.findall(line):
                where = f"{path}:{number}"
                script = re.match(r"python (?:-m \S+ )?((?:examples|benchmarks|tests)/\S+\.py)", text)
                if script is not None:
                    assert (ROOT / script[1]).exists(), f"{where}: {text!r}: no {script[1]}"
                    checked += 1
                elif text.startswith("daeclear "):
                    check_cli_options(where, text)
                    checked += 1
    assert checked > 50


@pytest.mark.parametrize("block", [b for b in BLOCKS if b.lang == "toml"],
                         ids=[b.id for b in BLOCKS if b.lang == "toml"])
def test_toml_blocks_parse(block: Block) -> None:
    tomllib.loads(block.text)


def checkout_files() -> dict[str, tuple[int, int]]:
    """(size, mtime) of the files a doc command could write: the documents, examples/, docs/figures/."""
    paths = [ROOT / "README.md", *(ROOT / "docs").rglob("*"), *(ROOT / "examples").rglob("*")]
    return {str(p.relative_to(ROOT)): (p.stat().st_size, p.stat().st_mtime_ns) for p in paths
            if p.is_file() and "__pycache__" not in p.parts}


BEFORE = checkout_files()


def test_the_docs_commands_wrote_nothing_into_the_checkout() -> None:
    """Runs after the blocks (pytest keeps a module's order): they ran in scratch directories."""
    after = checkout_files()
    changed = sorted(name for name in set(BEFORE) | set(after) if BEFORE.get(name) != after.get(name))
    assert not changed, f"the docs' commands changed files of the checkout: {changed}"
