"""The constants C and Python share (daeclear.engine.abi and its generated csrc/dc_abi.h), the drivers'
entry points (daeclear.engine.c_api and its generated csrc/dc_api.h: every definition is its table entry,
a planted mismatch fails the build), and the size of the hand-written C: no file over 900 lines, no
function over 120."""

from __future__ import annotations

import ctypes
import hashlib
import re
import subprocess
from pathlib import Path

import pytest

from daeclear.core import automaton
from daeclear.engine import abi, c_api, c_handle, codegen, library, sundials
from daeclear.engine.build import CSRC, CompilerUnavailable, compiler_command, driver_files
from daeclear.engine.stall_guard import c_defines

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
    assert sorted(abi.LINEAR_SOLVER_CODES.values()) == sorted({abi.DC_LS_DENSE, abi.DC_LS_SPARSE, abi.DC_LS_REDUCED,
                                                               abi.DC_LS_SUPERLU})
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
    assert {CSRC / "dc_abi.h", c_api.HEADER, CSRC / "dc_common.h"} <= ida & ode  # a changed header recompiles
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


# ---------------------------------------------------------------- the entry points (c_api.py, dc_api.h)

DRIVERS = {"ida_driver.c": c_api.IDA_ENTRY_POINTS, "ode_driver.c": c_api.ODE_ENTRY_POINTS}

#: A DC_API function definition: the prototype up to its parameter list's ``)``, then the body's brace.
_DEFINITION = re.compile(r"\bDC_API\s+([^;{}=#]*?\))\s*\{")


def test_every_generated_header_is_the_tables() -> None:
    for path, text in abi.generated_headers().items():
        assert path.read_text() == text, f"{path.name}: run python -m daeclear.engine.abi"
    assert set(abi.generated_headers()) == {abi.HEADER, c_api.HEADER}


def definitions(sources: list[Path]) -> list[c_api.EntryPoint]:
    """The DC_API function definitions of C sources, read by the table's own signature parser."""
    text = "".join(strip_c(path.read_text()) for path in sources if path != c_api.HEADER)
    return [c_api.parse_signature(" ".join(sig.split())) for sig in _DEFINITION.findall(text)]


def test_the_definition_reader_sees_what_c_defines() -> None:
    text = ("DC_API const char dc_tag[] = \"x\";\n/* DC_API int dc_no(void) { */\n"
            "DC_API void* dc_a(const double* const* p,\n                   long long n) {\n  return 0;\n}\n"
            "DC_API int dc_b(void);\nstatic int f(void) { return 0; }\n")
    found = [c_api.parse_signature(" ".join(sig.split())) for sig in _DEFINITION.findall(strip_c(text))]
    assert [e.declaration for e in found] == ["void* dc_a(const double* const* p, long long n)"]


@pytest.mark.parametrize("driver", sorted(DRIVERS))
def test_every_definition_is_its_table_entry(driver: str) -> None:
    """Arity, types and names of each exported definition in the driver's sources are the table's."""
    entries = DRIVERS[driver]
    found = definitions(list(driver_files(driver)))
    names = [e.name for e in found]
    assert len(set(names)) == len(names), f"{driver}: a function defined twice"
    defined = {e.name: e for e in found}
    assert set(defined) == {e.name for e in entries}, f"{driver}: defined but not in c_api, or the reverse"
    for entry in entries:
        got = defined[entry.name]
        assert got == entry, f"{driver} defines {got.declaration}, c_api.py declares {entry.declaration}"
        _, argtypes = {**library.MODEL_PROTOTYPES, **library.ODE_PROTOTYPES}[entry.name]
        assert len(argtypes) == len(got.params), f"{entry.name}: ctypes passes another number of arguments"


def test_each_driver_has_its_own_prefix() -> None:
    assert all(e.name.startswith("dc_") for e in c_api.IDA_ENTRY_POINTS)
    assert all(e.name.startswith("dco_") for e in c_api.ODE_ENTRY_POINTS)
    assert len(c_api.IDA_ENTRY_POINTS) == len(library.MODEL_PROTOTYPES) == 41
    assert len(c_api.ODE_ENTRY_POINTS) == len(library.ODE_PROTOTYPES) == 16


def test_ctypes_types_follow_the_c_types() -> None:
    assert c_api.ctype_of("void") is None
    assert c_api.ctype_of("int") is ctypes.c_int and c_api.ctype_of("double") is ctypes.c_double
    assert c_api.ctype_of("long") is ctypes.c_long and c_api.ctype_of("long long") is ctypes.c_longlong
    for string in ("char*", "const char*"):
        assert c_api.ctype_of(string) is ctypes.c_char_p
    for address in ("void*", "double*", "const int*", "const double* const*", "char**", "long long*"):
        assert c_api.ctype_of(address) is ctypes.c_void_p
    assert c_api.parse_signature("const char * dc_x( const  double *const* a , long   long b )").declaration == \
        "const char* dc_x(const double* const* a, long long b)"
    assert c_api.parse_signature("int dc_y(void)").params == ()
    res, args = c_api.prototypes((c_api.parse_signature("double dc_z(int* a, char* s, long n)"),))["dc_z"]
    assert res is ctypes.c_double and args == (ctypes.c_void_p, ctypes.c_char_p, ctypes.c_long)


@pytest.mark.parametrize("signature, message", [
    ("int dc_x(float a)", r"type='float' of dc_x's a, must be int, long, long long, double or a pointer to one"),
    ("int dc_x(unsigned int a)", r"type='unsigned int' of dc_x's a"),
    ("float dc_x(int a)", r"type='float' of dc_x's result, must be void \(a result\), int"),
    ("int dc_x(void a)", r"type='void' of dc_x's a"),
    ("int dc_x(int)", r"parameter='int' of dc_x, must be '<type> <name>'"),
    ("int dc_x(int a, double a)", r"parameters=\['a', 'a'\] of dc_x, must have distinct names"),
    ("dc_x", r"signature='dc_x', must be '<type> <name>\(<type> <name>, ...\)'"),
])
def test_a_bad_table_entry_is_refused(signature: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        c_api.parse_signature(signature)


def test_the_ctypes_sizes_are_the_c_compilers(tmp_path: Path) -> None:
    """Each C type of the table has, for the C compiler, the size of the ctypes type Python passes."""
    try:
        cc = compiler_command()
    except CompilerUnavailable as exc:
        pytest.skip(str(exc))
    types = sorted({t for entries in DRIVERS.values() for e in entries for t in (e.restype, *(c for c, _ in e.params))}
                   - {"void"})
    prints = "".join(f'  printf("%zu\\n", sizeof({t}));\n' for t in types)
    src = tmp_path / "sizes.c"
    src.write_text(f"#include <stdio.h>\nint main(void) {{\n{prints}  return 0;\n}}\n")
    subprocess.run([*cc, str(src), "-o", str(tmp_path / "sizes")], check=True, capture_output=True)
    out = subprocess.run([str(tmp_path / "sizes")], check=True, capture_output=True, text=True).stdout.split()
    assert {t: int(n) for t, n in zip(types, out, strict=True)} == {t: ctypes.sizeof(c_api.ctype_of(t)) for t in types}
    assert {"int", "long long", "double", "void*", "char*", "const double* const*"} <= set(types)


#: The signatures (types, no parameter names) each driver ABI version has: a signature changed with the
#: same version would let a library of the old one pass the version check. sha256 of signature_text.
SIGNATURES = {("ida_driver.c", 9): "24addb9ef553a5ac", ("ida_driver.c", 10): "c318ee4977ca7011",
              ("ode_driver.c", 3): "84648e05a08e107f"}


def signature_text(entries: tuple[c_api.EntryPoint, ...]) -> str:
    return "\n".join(f"{e.restype} {e.name}({', '.join(c for c, _ in e.params)})"
                     for e in sorted(entries, key=lambda e: e.name))


def test_a_changed_signature_comes_with_a_new_abi_version() -> None:
    for driver, version in (("ida_driver.c", library.DRIVER_ABI), ("ode_driver.c", library.ODE_DRIVER_ABI)):
        digest = hashlib.sha256(signature_text(DRIVERS[driver]).encode()).hexdigest()[:16]
        assert SIGNATURES.get((driver, version)) == digest, (
            f"{driver}: the entry points' signatures changed: bump its ABI version in daeclear/engine/library.py "
            f"(DRIVER_ABI also in benchmarks/bound_main.c and bench_bound.py) and record ({driver!r}, <version>): "
            f"{digest!r} here")


def syntax_check(csrc: Path, driver: str, sparse: bool = True) -> subprocess.CompletedProcess[str]:
    """The compiler's verdict on ``csrc/<driver>`` and its parts, with the flags codegen builds it with
    (-fsyntax-only: nothing linked), read from the folder ``csrc`` (a planted copy or the package's)."""
    try:
        cc = compiler_command()
        if driver == "ida_driver.c":
            info = sundials.sundials_info()
            wheel = [f for f in info.compile_flags() if not f.startswith("-DDC_HAVE_SPARSE=")]
            flags = [*codegen.CFLAGS, *c_defines(), f"-I{sundials.SUNDIALS_INCLUDE}", *wheel,
                     f"-DDC_HAVE_SPARSE={int(sparse)}"]  # both branches checked, whatever the wheel has
        else:
            flags = [f"-DDCO_ABI_VERSION={library.ODE_DRIVER_ABI}", "-Werror=incompatible-pointer-types"]
    except CompilerUnavailable as exc:
        pytest.skip(str(exc))
    return subprocess.run([*cc, *flags, "-fsyntax-only", f"-I{csrc}", str(csrc / driver)],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("driver, sparse", [("ida_driver.c", False), ("ida_driver.c", True), ("ode_driver.c", True)])
def test_the_drivers_compile_against_the_generated_declarations(driver: str, sparse: bool) -> None:
    """The control of the planted mismatches below: the sources as they are compile without a word."""
    proc = syntax_check(CSRC, driver, sparse)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr


def planted_copy(tmp_path: Path, file: str, old: str, new: str) -> Path:
    """The hand-written C copied to ``tmp_path`` with ``old`` replaced by ``new`` (once) in ``file``."""
    for path in C_FILES:
        (tmp_path / path.name).write_text(path.read_text())
    text = (tmp_path / file).read_text()
    assert text.count(old) == 1, f"{file}: the text to plant over is not there once: {old!r}"
    (tmp_path / file).write_text(text.replace(old, new))
    return tmp_path


@pytest.mark.parametrize("driver, file, old, new, error", [
    # a parameter's type (definition)
    ("ida_driver.c", "ida_events.h", "DC_API int dc_take_events(void* sp, int cap,",
     "DC_API int dc_take_events(void* sp, long cap,", "conflicting types for .dc_take_events"),
    # a pointer's const
    ("ida_driver.c", "ida_open.h", "const double* params, const int* rootdir) {",
     "const double* params, int* rootdir) {", "conflicting types for .dc_reinit"),
    # the return type
    ("ida_driver.c", "ida_driver.c", "DC_API double dc_first_step(void* sp) {",
     "DC_API float dc_first_step(void* sp) {", "conflicting types for .dc_first_step"),
    # the arity
    ("ode_driver.c", "ode_driver.c", "DC_API void dco_set_hermite(void* sp, int on) {",
     "DC_API void dco_set_hermite(void* sp, int on, int extra) {", "conflicting types for .dco_set_hermite"),
    # an exported function the table lacks
    ("ode_driver.c", "ode_driver.c", "DC_API int dco_abi_version(void) {",
     "DC_API int dco_unlisted(void) { return 0; }\nDC_API int dco_abi_version(void) {",
     "no previous prototype for .dco_unlisted"),
    ("ida_driver.c", "ida_report.h", "DC_API int dc_report(",
     "DC_API int dc_unlisted(void* sp) { return sp != 0; }\nDC_API int dc_report(",
     "no previous prototype for .dc_unlisted"),
    # the table changed, the definition not (the header as c_api.py would write it)
    ("ode_driver.c", "dc_api.h", "DC_API int dco_rhs(void* sp, double t, const double* x, double* xdot);",
     "DC_API int dco_rhs(void* sp, double t, const double* x, const double* xdot);", "conflicting types for .dco_rhs"),
])
def test_a_planted_mismatch_fails_the_build(tmp_path: Path, driver: str, file: str, old: str, new: str,
                                            error: str) -> None:
    proc = syntax_check(planted_copy(tmp_path, file, old, new), driver)
    assert proc.returncode != 0
    assert re.search(error, proc.stderr), proc.stderr


def test_a_changed_table_writes_a_header_the_definitions_contradict(tmp_path: Path, monkeypatch) -> None:
    """Through the table itself: an entry given another parameter type, the header generated from it."""
    old = c_api.parse_signature("int dc_set_stall(void* sp, double stall_step, int count)")
    assert old in c_api.IDA_ENTRY_POINTS
    new = c_api.parse_signature("int dc_set_stall(void* sp, double stall_step, long long count)")
    groups = tuple((heading, tuple(new if e == old else e for e in entries)) for heading, entries in c_api.IDA_GROUPS)
    monkeypatch.setattr(c_api, "IDA_GROUPS", groups)
    text = c_api.header_text()
    assert "long long count" in text and text != c_api.HEADER.read_text()
    copy = planted_copy(tmp_path, "dc_api.h", c_api.HEADER.read_text(), text)
    proc = syntax_check(copy, "ida_driver.c")
    assert proc.returncode != 0 and re.search("conflicting types for .dc_set_stall", proc.stderr), proc.stderr
