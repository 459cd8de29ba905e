"""The package's layout: import circles, private names across modules, and the old module paths.

The imports are read from the source (ast), not executed. Every import statement counts, the
lazy ones inside functions too (a circle through a lazy import is still a circle a reader has to
untangle), except those under ``if TYPE_CHECKING:``, which never run. ``from package import name``
is an edge to the module ``package.name`` when there is one, else to the package. Old module paths
(``daeclear.old_paths``) are edges to the module they stand for.

The lists of what is still to be untangled are empty since phase 2 of issue 13: any import circle
or private import across modules fails.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import daeclear

PACKAGE = Path(daeclear.__file__).resolve().parent

#: Import edges inside circles (importer, imported) still to be untangled: none since phase 2.
KNOWN_CIRCLE_EDGES: set[tuple[str, str]] = set()
#: Private names imported from another module (importer, module, name) still to be untangled: none.
KNOWN_PRIVATE_IMPORTS: set[tuple[str, str, str]] = set()


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_files() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(PACKAGE.rglob("*.py")) if "__pycache__" not in p.parts}


def type_checking_nodes(tree: ast.AST) -> set[int]:
    """ids of the statements under ``if TYPE_CHECKING:`` (never executed)."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                out.update(id(n) for n in ast.walk(child))
    return out


def imports() -> list[tuple[str, str, str | None]]:
    """(importer, imported module, imported name or None) for every executed import of the package."""
    files = package_files()
    out = []
    for name, path in files.items():
        tree = ast.parse(path.read_text(), str(path))
        skip = type_checking_nodes(tree)
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            if isinstance(node, ast.Import):
                out += [(name, a.name, None) for a in node.names if a.name.split(".")[0] == "daeclear"]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[:len(package.split(".")) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                if target.split(".")[0] != "daeclear":
                    continue
                for alias in node.names:
                    full = f"{target}.{alias.name}"
                    if full in files:
                        out.append((name, full, None))
                    else:
                        out.append((name, target, alias.name))
    return out


def circle_edges() -> set[tuple[str, str]]:
    """The import edges that lie on a circle (both ends in one strongly connected component)."""
    graph: dict[str, set[str]] = {}
    for importer, module, _ in imports():
        if importer != module:
            graph.setdefault(importer, set()).add(module)
            graph.setdefault(module, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    component: dict[str, str] = {}

    def visit(v: str) -> None:  # Tarjan
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
    return {(a, b) for a in graph for b in graph[a] if component[a] == component[b]}


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


def test_no_private_imports_beyond_the_known_ones():
    assert private_imports() <= KNOWN_PRIVATE_IMPORTS


def test_no_private_imports_across_modules():
    assert private_imports() == set()


# ----------------------------------------------------------------------------- old paths and public API

OLD_PATHS = ("accuracy", "analysis", "automaton", "codegen", "ida_session", "recorder", "result", "scene",
             "style", "sweep")


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
