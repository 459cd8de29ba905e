"""The constants C and Python share (daeclear.engine.abi and its generated csrc/dc_abi.h), and the
size of the hand-written C: no file over 900 lines, no function over 120."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from daeclear.core import automaton
from daeclear.engine import abi, c_handle, codegen
from daeclear.engine.build import CSRC, CompilerUnavailable, compiler_command, driver_files

MAX_FILE_LINES = 900
MAX_FUNCTION_LINES = 120

#: the hand-written C (the vendored SUNDIALS headers under csrc/sundials are not ours)
C_FILES = sorted(p for p in CSRC.iterdir() if p.suffix in (".c", ".h"))

_DEFINE = re.compile(r"^#define[ \t]+(\w+)[ \t]+(\S+)", re.MULTILINE)
_DEFINED = re.compile(r"^[ \t]*#[ \t]*define[ \t]+(\w+)", re.MULTILINE)


def header_defines(text: str) -> dict[str, int | float]:
    """The ``#define NAME value`` lines of a header, values read as Python numbers."""
    out: dict[str, int | float] = {}
    for name, value in _DEFINE.findall(text):
        value = value.strip("()")
        out[name] = float(value) if any(c in value for c in ".e") else int(value)
    return out


def test_header_is_generated_from_the_table() -> None:
    assert abi.HEADER.read_text() == abi.header_text(), "run: python -m daeclear.engine.abi"


def test_every_constant_is_in_the_header_with_its_value() -> None:
    table = abi.table()
    defines = header_defines(abi.HEADER.read_text())
    assert set(defines) == set(table)
    for name, value in table.items():
        assert defines[name] == value, name
        assert type(defines[name]) is type(value), name
        assert getattr(abi, name) == value, f"daeclear.engine.abi.{name} is not the table's value"


def test_the_c_compiler_reads_the_same_values(tmp_path: Path) -> None:
    """An independent reading of the header: a C program prints every constant."""
    try:
        cc = compiler_command()
    except CompilerUnavailable as exc:
        pytest.skip(str(exc))
    table = abi.table()
    prints = "".join(f'  printf("{name} %.17g\\n", (double)({name}));\n' for name in table)
    src = tmp_path / "abi.c"
    src.write_text(f'#include <stdio.h>\n#include "dc_abi.h"\nint main(void) {{\n{prints}  return 0;\n}}\n')
    exe = tmp_path / "abi"
    subprocess.run([*cc, f"-I{CSRC}", str(src), "-o", str(exe)], check=True, capture_output=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    got = {name: float(value) for name, value in (line.split() for line in out.splitlines())}
    assert got == {name: float(value) for name, value in table.items()}


def test_slots_and_kinds_are_those_python_uses() -> None:
    assert (abi.DC_NONE, abi.DC_ONSET, abi.DC_SEPARATION) == (automaton.NONE, automaton.ONSET, automaton.SEPARATION)
    assert abi.DC_SAME_INSTANT == automaton.SAME_INSTANT
    assert len({abi.DC_NONE, abi.DC_ONSET, abi.DC_SEPARATION}) == 3
    assert not hasattr(c_handle, "STAT_KEYS")  # the handle's buffer is sized by the table (DC_ST_N), no copy
    assert len(abi.STAT_KEYS) == abi.DC_ST_N and abi.STAT_KEYS[abi.DC_ST_REINITS] == "n_reinits"
    assert len(abi.ODE_COUNTER_KEYS) == abi.DCO_CNT_N
    assert sorted(abi.LINEAR_SOLVER_CODES.values()) == sorted({abi.DC_LS_DENSE, abi.DC_LS_SPARSE, abi.DC_LS_REDUCED})
    for group, rows in abi.GROUPS:
        values = [value for name, value, _ in rows if not name.endswith("_N")]
        assert len(set(values)) == len(values), f"{group}: two constants share a value"


def test_no_constant_of_the_table_is_defined_twice() -> None:
    """C takes them from dc_abi.h only (no second #define of a table name in another file, the
    benchmarks' C programs included)."""
    table = set(abi.table())
    benchmarks = Path(__file__).resolve().parent.parent / "benchmarks"
    for path in [*C_FILES, *sorted(benchmarks.glob("*.c"))]:
        if path != abi.HEADER:
            again = table & set(_DEFINED.findall(path.read_text()))
            assert not again, f"{path.name} #defines {sorted(again)}, which dc_abi.h defines"
            enums = re.findall(r"\benum\s*\{([^}]*)\}", path.read_text())
            assert not table & set(re.findall(r"\w+", " ".join(enums))), path.name


def test_every_c_file_is_in_a_drivers_cache_key() -> None:
    ida, ode = set(driver_files("ida_driver.c")), set(driver_files("ode_driver.c"))
    assert ida | ode == set(C_FILES)
    assert {CSRC / "dc_abi.h", CSRC / "dc_common.h"} <= ida & ode
    assert tuple(p.name for p in sorted(ida)) == codegen.DRIVER_SOURCES
    assert tuple(p.name for p in sorted(ode)) == codegen.ODE_DRIVER_SOURCES


# ---------------------------------------------------------------- size of the C


def strip_c(text: str) -> str:
    """C text with comments, strings and character literals blanked (line breaks kept)."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(\\.|[^"\\\n])*"', '""', text)
    return re.sub(r"'(\\.|[^'\\\n])*'", "''", text)


def c_functions(text: str) -> list[tuple[str, int, int]]:
    """(name, first line, lines) of each function definition: a brace at file level whose head (the
    text since the previous ``;``, ``}`` or directive) ends with a parameter list's ``)``."""
    code = strip_c(text)
    out: list[tuple[str, int, int]] = []
    depth, head, start, name, line = 0, "", 0, "", 1
    for ch in code:
        if ch == "\n":
            line += 1
            head = "" if depth == 0 and head.lstrip().startswith("#") else head + ch
            continue
        if depth == 0 and ch == "{":
            m = re.search(r"(\w+)\s*\([^()]*(?:\([^()]*\)[^()]*)*\)\s*$", head)
            name, start = (m.group(1), line) if m else ("", line)
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
            if depth == 0:
                if name:
                    out.append((name, start, line - start + 1))
                name, head = "", ""
                continue
        if depth == 0:
            head = "" if ch == ";" else head + ch
    return out


def test_the_function_parser_counts_lines() -> None:
    text = ("#define X 1\n/* { */\nstatic int f(int a,\n             int b) {\n  if (a) { return '}'; }\n"
            "  return b;\n}\ntypedef struct {\n  int x;\n} s;\nint g(void) { return 0; }\n")
    assert c_functions(text) == [("f", 4, 4), ("g", 11, 1)]


@pytest.mark.parametrize("path", C_FILES, ids=lambda p: p.name)
def test_c_file_and_function_sizes(path: Path) -> None:
    text = path.read_text()
    assert len(text.splitlines()) <= MAX_FILE_LINES, f"{path.name}: split it by job"
    funcs = c_functions(text)
    if path.suffix == ".c":
        assert funcs, f"{path.name}: the parser found no function"
    long = [(name, n) for name, _, n in funcs if n > MAX_FUNCTION_LINES]
    assert not long, f"{path.name}: functions over {MAX_FUNCTION_LINES} lines: {long}"


def test_the_parser_finds_the_drivers_entry_points() -> None:
    """Every dc_* / dco_* function the Python side declares is found (the parser sees them all)."""
    from daeclear.engine.library import MODEL_PROTOTYPES, ODE_PROTOTYPES

    found = {name for path in C_FILES for name, _, _ in c_functions(path.read_text())}
    assert set(MODEL_PROTOTYPES) | set(ODE_PROTOTYPES) <= found
