"""The package's layout: its stages are layers, no import circles, no private names across modules, the
old module paths gone.

The imports are read from the source (ast), not executed. Every import statement counts, the lazy ones
inside functions too (a circle through a lazy import is still a circle a reader has to untangle), and so
does an import by name: a literal ``"daeclear.x.y"`` or ``"daeclear.x.y:Name"`` (what ``import_module``,
``__import__`` and import paths read). ``from package import name`` is an edge to the module
``package.name`` when there is one, else to the package.

The stages and their order are written once, in docs/architecture.md (the line ``core < engine < ...``);
a stage imports only from itself and the stages before it, type-only imports (``if TYPE_CHECKING:``)
included: a layer names nothing of a layer above it. The circle check leaves type-only imports out (they
never run). ``python tests/test_layout.py [path/to/daeclear]`` prints the stages that form a cycle.
"""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

import pytest

import daeclear

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "daeclear"
ARCHITECTURE = ROOT / "docs" / "architecture.md"

#: Import edges inside circles (importer, imported) still to be untangled: none since phase 2.
KNOWN_CIRCLE_EDGES: set[tuple[str, str]] = set()
#: Private names imported from another module (importer, module, name) still to be untangled: none.
KNOWN_PRIVATE_IMPORTS: set[tuple[str, str, str]] = set()

#: The stage order's one line in docs/architecture.md: stage names joined by " < ", lowest first.
ORDER_LINE = re.compile(r"^\s*(\w+(?:\s*<\s*\w+)+)\s*$", re.MULTILINE)


class Import(NamedTuple):
    """One import read from the source: ``name`` is the name taken from ``module`` when that is not a
    module itself; ``how``: "import", "type" (under ``if TYPE_CHECKING:``) or "by name" (a literal)."""

    importer: str
    module: str
    name: str | None
    line: int
    how: str


def module_name(path: Path, package: Path = PACKAGE) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_files(package: Path = PACKAGE) -> dict[str, Path]:
    return {module_name(p, package): p for p in sorted(package.rglob("*.py")) if "__pycache__" not in p.parts}


def type_checking_nodes(tree: ast.AST) -> set[int]:
    """ids of the statements under ``if TYPE_CHECKING:`` (never executed)."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                out.update(id(n) for n in ast.walk(child))
    return out


def read_imports(package: Path = PACKAGE) -> list[Import]:
    """Every import of the package's modules of the package itself: statements (module level, inside
    functions, type-only) and imports by name (a string literal that is a module path of the package,
    ``"pkg.x.y"`` or ``"pkg.x.y:Name"``: ``importlib.import_module("pkg.x")``, ``__import__``, a path
    stored for later)."""
    files = package_files(package)
    top = package.name
    by_name = re.compile(rf"{re.escape(top)}(?:\.[A-Za-z_]\w*)+(?::[\w.]+)?")
    out = []
    for name, path in files.items():
        tree = ast.parse(path.read_text(), str(path))
        typing_only = type_checking_nodes(tree)
        own = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(tree):
            how = "type" if id(node) in typing_only else "import"
            if isinstance(node, ast.Import):
                out += [Import(name, a.name, None, node.lineno, how) for a in node.names
                        if a.name.split(".")[0] == top]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = own.split(".")[:len(own.split(".")) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if target.split(".")[0] != top:
                    continue
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    out.append(Import(name, full, None, node.lineno, how) if full in files
                               else Import(name, target, alias.name, node.lineno, how))
            elif isinstance(node, ast.Constant) and isinstance(node.value, str) and by_name.fullmatch(node.value):
                module, _, attribute = node.value.partition(":")
                out.append(Import(name, module, attribute or None, node.lineno, "by name"))
    return out


def imports() -> list[tuple[str, str, str | None]]:
    """(importer, imported module, imported name or None) for every executed import of the package."""
    return [(i.importer, i.module, i.name) for i in read_imports() if i.how != "type"]


def strongly_connected(graph: dict[str, set[str]]) -> dict[str, str]:
    """Each node's component (Tarjan): two nodes share one exactly when each reaches the other."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    component: dict[str, str] = {}

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component[w] = v
                if w == v:
                    break

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return component


def circle_edges() -> set[tuple[str, str]]:
    """The import edges that lie on a circle (both ends in one strongly connected component)."""
    graph: dict[str, set[str]] = {}
    for importer, module, _ in imports():
        if importer != module:
            graph.setdefault(importer, set()).add(module)
            graph.setdefault(module, set())
    component = strongly_connected(graph)
    return {(a, b) for a in graph for b in graph[a] if component[a] == component[b]}


# ----------------------------------------------------------------------------- the stages are layers

FACE = "daeclear"  # the package's __init__: the public face, above every stage


def stage(module: str) -> str:
    """A module's stage: its sub-package (``core``, ``solvers``), or its own name for a module at the
    top (``cli``); the package itself is the face."""
    parts = module.split(".")
    return FACE if len(parts) == 1 else parts[1]


def stage_order(text: str | None = None) -> list[str]:
    """The stages, lowest first, from docs/architecture.md's one ``a < b < ...`` line."""
    lines = ORDER_LINE.findall(ARCHITECTURE.read_text() if text is None else text)
    assert len(lines) == 1, f"docs/architecture.md must hold exactly one stage order line, found {lines}"
    return [s.strip() for s in lines[0].split("<")]


def backward_imports(package: Path = PACKAGE, order: list[str] | None = None) -> list[str]:
    """Every import of a stage after the importer's (and of a stage the order does not list), as
    ``importer:line -> module (how)``; empty when the stages are layers."""
    order = stage_order() if order is None else order
    rank = {s: k for k, s in enumerate(order)} | {FACE: len(order)}
    out = []
    for i in sorted(read_imports(package), key=lambda i: (i.importer, i.line)):
        low, high = stage(i.importer), stage(i.module)
        if low not in rank or high not in rank or rank[low] < rank[high]:
            out.append(f"{i.importer}:{i.line} -> {i.module}{':' + i.name if i.name else ''} ({i.how})")
    return out


def stages_in_cycles(package: Path = PACKAGE) -> list[str]:
    """The stages (sub-packages, modules at the top) that lie on an import cycle of stages, every
    import counted (type-only ones and by name too)."""
    graph: dict[str, set[str]] = {}
    for i in read_imports(package):
        a, b = stage(i.importer), stage(i.module)
        if FACE not in (a, b) and a != b:
            graph.setdefault(a, set()).add(b)
            graph.setdefault(b, set())
    component = strongly_connected(graph)
    return sorted(v for v in graph if sum(c == component[v] for c in component.values()) > 1)


def test_the_stage_order_names_every_stage():
    """The order in docs/architecture.md lists each sub-package and module at the top once."""
    order = stage_order()
    assert len(order) == len(set(order)), order
    present = {stage(m) for m in package_files()} - {FACE}
    assert set(order) == present, f"in the order only: {set(order) - present}; not in it: {present - set(order)}"


def test_no_stage_imports_a_later_one():
    assert backward_imports() == []


def test_no_stage_is_in_a_cycle():
    assert stages_in_cycles() == []


def plant(root: Path, module: str, code: str) -> None:
    path = root.joinpath(*module.split(".")).with_suffix(".py")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(code)


def test_the_layer_check_reads_every_kind_of_import(tmp_path):
    """A synthetic package: each kind of backward import is found (statement, lazy, relative, type-only,
    by name through import_module and __import__, an import path "pkg.x:Name"), forward ones are not."""
    pkg = tmp_path / "daeclear"
    for module in ("daeclear", "daeclear.core", "daeclear.plot", "daeclear.plot.figures"):
        plant(tmp_path, module + (".__init__" if module.count(".") < 2 else ""), '"""x"""\n')
    plant(tmp_path, "daeclear.core.rules", "\n".join([
        "from typing import TYPE_CHECKING",
        "from ..plot import figures",                        # 2: relative, a module
        "import daeclear.plot.figures",                      # 3: absolute
        "if TYPE_CHECKING:",
        "    from daeclear.plot.figures import Figure",      # 5: type-only
        "def f():",
        "    from ..plot.figures import g",                   # 7: lazy
        "    import importlib",
        "    importlib.import_module('daeclear.plot.figures')",  # 9: by name
        "    __import__('daeclear.plot')",                   # 10: by name
        "PATH = 'daeclear.plot.figures:Figure'",             # 11: an import path
        "NOT_A_PATH = 'see daeclear.plot.figures'",          # prose, not an import
    ]))
    plant(tmp_path, "daeclear.plot.use", "from ..core import rules\nfrom ..core.rules import f\n")
    found = backward_imports(pkg, ["core", "plot"])
    assert [line.split(" -> ")[0] for line in found] == [f"daeclear.core.rules:{n}" for n in (2, 3, 5, 7, 9, 10, 11)]
    assert stages_in_cycles(pkg) == ["core", "plot"]
    assert backward_imports(pkg, ["plot", "core"]) == [
        "daeclear.plot.use:1 -> daeclear.core.rules (import)", "daeclear.plot.use:2 -> daeclear.core.rules:f (import)"]
    assert "daeclear.plot.use:1 -> daeclear.core.rules (import)" in backward_imports(pkg, ["core"])  # unlisted stage


@pytest.mark.parametrize("planted", [
    "from ..results.result import Result\n",
    "def later():\n    import importlib\n    return importlib.import_module('daeclear.results.result')\n",
])
def test_the_layer_check_fails_on_a_backward_import_planted_in_the_package(tmp_path, planted):
    """The real package copied, one backward import planted in the core (one by statement, one by name):
    the check names it and nothing else; the copy as it is passes."""
    copy = tmp_path / "daeclear"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "csrc"))
    assert backward_imports(copy) == [] and stages_in_cycles(copy) == []
    errors = copy / "core" / "errors.py"
    lines = errors.read_text().count("\n")
    errors.write_text(errors.read_text() + planted)
    found = backward_imports(copy)
    assert len(found) == 1 and found[0].startswith(f"daeclear.core.errors:{lines + planted.count(chr(10))} -> "
                                                   "daeclear.results.result"), found
    assert stages_in_cycles(copy) != []


def test_the_import_reader_sees_lazy_imports_and_skips_type_checking():
    """The reader itself: clearance_joints imports joint_readings inside a method; style's Result
    import is typing only."""
    edges = {(a, b) for a, b, _ in imports()}
    assert ("daeclear.model.clearance_joints", "daeclear.model.joint_readings") in edges
    assert ("daeclear.plot.style", "daeclear.results.result") not in edges
    assert ("daeclear", "daeclear.studies.sweep") in edges


def test_no_circles_beyond_the_known_ones():
    assert circle_edges() <= KNOWN_CIRCLE_EDGES


def test_no_import_circles():
    assert circle_edges() == set()


def private_imports() -> set[tuple[str, str, str]]:
    """Private names imported from another module; a private module of the importer's own package
    (``from . import _backend`` in daeclear.contact) is the package's business and allowed."""
    files = package_files()
    out = set()
    for importer, module, name in imports():
        own_package = importer if files[importer].name == "__init__.py" else importer.rsplit(".", 1)[0]
        if name is not None and name.startswith("_") and module != importer:
            out.add((importer, module, name))
        private_parts = [p for p in module.split(".") if p.startswith("_")]
        if private_parts and not module.startswith(own_package + "."):
            out.add((importer, module, private_parts[0]))
    return out


def test_no_private_imports_beyond_the_known_ones():
    assert private_imports() <= KNOWN_PRIVATE_IMPORTS


def test_no_private_imports_across_modules():
    assert private_imports() == set()


# ----------------------------------------------------------------------------- old paths and public API

OLD_PATHS = ("accuracy", "analysis", "automaton", "codegen", "ida_session", "recorder", "result", "scene",
             "style", "sweep",
             # moved into the layers by issue 42 (docs/layout.md)
             "errors", "options", "progress", "save_at", "solver_options", "assembly.automaton", "results.events",
             "results.values", "solvers.physics", "solvers.channel_eval")


@pytest.mark.parametrize("old", OLD_PATHS)
def test_old_module_paths_are_gone(old):
    """The flat module paths of before the sub-packages are not importable: no import hook serves them
    (the public names stay at ``daeclear.<name>``; the modules live in their sub-package)."""
    code = (f"import importlib, daeclear\ntry:\n    importlib.import_module('daeclear.{old}')\n"
            f"except ModuleNotFoundError:\n    pass\nelse:\n    raise SystemExit('daeclear.{old} still imports')")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_public_names_in_a_fresh_interpreter():
    """``import daeclear`` then the public names and the sub-packages' paths; ``__all__`` is the public API."""
    code = "\n".join([
        "import daeclear",
        "assert daeclear.analysis.classify_motion and daeclear.mechanisms.slider_crank",
        "assert callable(daeclear.sweep) and daeclear.sweep.__name__ == 'sweep'",
        "from daeclear.studies.sweep import load_sweep",
        "assert load_sweep is daeclear.load_sweep",
        "from daeclear.model.scene import Scene, RevoluteClearance",
        "assert Scene is daeclear.Scene and RevoluteClearance is daeclear.RevoluteClearance",
        "from daeclear.solvers import simulate",
        "assert simulate is daeclear.simulate",
        "import daeclear.plot, daeclear.plot.figures as figures",
        "names = [n for n in vars(figures) if n.startswith('plot_')]",
        "assert names and all(getattr(daeclear.plot, n) is getattr(figures, n) for n in names)",
        "assert daeclear.plot.save_response_figure is figures.save_response_figure",
        "from daeclear.contact import LankaraniNikravesh",
        "assert all(not n.startswith('_') for n in daeclear.__all__)",
        "assert not any(n in daeclear.__all__ for n in ('codegen', 'automaton', 'recorder', 'old_paths'))",
        "from daeclear.assembly.placement import place",
        "from daeclear.plot.animate import animate",
        "assert daeclear.place is place and daeclear.animate is animate",
        "assert not hasattr(daeclear.Scene, 'assembled') and not hasattr(daeclear.Result, 'animate')",
    ])
    subprocess.run([sys.executable, "-c", code], check=True)


def test_public_api_unchanged():
    """What ``daeclear`` exports is there and is the object of its new home."""
    from daeclear.assembly.assemble import DAEModel, assemble
    from daeclear.model.scene import Scene
    from daeclear.results.result import Result
    from daeclear.solvers.dispatch import simulate
    from daeclear.studies.sweep import sweep

    for name in daeclear.__all__:
        assert hasattr(daeclear, name), name
    assert (daeclear.DAEModel, daeclear.assemble, daeclear.Scene, daeclear.Result, daeclear.simulate,
            daeclear.sweep) == (DAEModel, assemble, Scene, Result, simulate, sweep)


def test_every_sub_package_is_a_regular_package():
    """A folder of modules without __init__.py would import as a namespace package and be left out
    of the wheel (a .gitignore pattern once dropped daeclear/results/__init__.py)."""
    root = Path(__file__).resolve().parents[1]
    tracked = set(subprocess.run(["git", "ls-files", "daeclear"], cwd=root, capture_output=True, text=True,
                                 check=True).stdout.split())
    folders = {str(Path(f).parent) for f in tracked if f.endswith(".py")}
    assert folders, "no tracked modules found"
    missing = sorted(d for d in folders if f"{d}/__init__.py" not in tracked)
    assert not missing, f"folders of modules without a tracked __init__.py: {missing}"


#: Issue 13: every module "under about 600 lines with one job a newcomer can name from its path".
MODULE_LINE_LIMIT = 650


def test_every_module_is_short_and_says_its_job():
    """Each module of the package stays under the line limit and opens with a docstring that says
    its one job (the first line of the docstring is what docs/layout.md's table is made of)."""
    too_long, undocumented = [], []
    for name, path in package_files().items():
        text = path.read_text()
        if len(text.splitlines()) > MODULE_LINE_LIMIT:
            too_long.append(f"{name}: {len(text.splitlines())} lines")
        if not (ast.get_docstring(ast.parse(text)) or "").strip():
            undocumented.append(name)
    assert not too_long, f"modules over {MODULE_LINE_LIMIT} lines: {too_long}"
    assert not undocumented, f"modules without a docstring: {undocumented}"


if __name__ == "__main__":
    target = Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else PACKAGE
    cycle = stages_in_cycles(target)
    print(f"stages in a cycle: {len(cycle)} {cycle}")
