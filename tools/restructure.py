"""Move the flat daeclear package into sub-packages that follow the data flow (issue 13, phase 1).

Run from the repository root on a clean work tree (``python tools/restructure.py``). The script is
deterministic and meant to be re-run on the newest main instead of merging a hand-made move:

1. checks that every top-level module is known (a new module on main stops the script: add it
   to ``MOVES`` or ``STAY``);
2. ``git mv``s the modules (and ``csrc/``) to their sub-packages, so history follows the renames;
3. splits the revolute clearance module: the contact-pair machinery it shares with the
   translational joint goes to ``assembly/contact_pairs.py`` (this removes an import circle);
4. rewrites every import and module path (package, tests, examples, benchmarks, docs, README,
   pyproject): relative imports are recomputed from the new places, absolute ones mapped;
5. writes the sub-packages' ``__init__.py`` and ``daeclear/old_paths.py``: the old module paths
   that users import (those README.md or docs/ name, and ``REQUIRED_ALIASES``) stay importable as
   thin alias modules for one release, answered by one finder instead of a file at each old path
   (a file there would hide the rename from git, and later merges would not follow it);
6. fixes what no rule covers (explicit steps at the end: the package's ``__init__``, pyproject's
   package data).

It changes no code beyond import lines, module paths in text, and the split in step 3.
"""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path.cwd()
PKG = "daeclear"

#: old top-level module -> new module (dotted, under daeclear). Modules marked optional may be absent.
MOVES: dict[str, str] = {
    # model: what a user describes
    "scene": "model.scene", "loads": "model.loads", "readings": "model.readings",
    "mechanisms": "model.mechanisms", "scenefile": "model.scenefile", "profiles": "model.profiles",
    # assembly: scene -> symbolic DAE
    "symbolic": "assembly.symbolic", "parameters": "assembly.parameters", "assemble": "assembly.assemble",
    "clearance": "assembly.revolute_joint", "slider_guide": "assembly.translational_joint",
    "automaton": "assembly.automaton", "drivers": "assembly.drivers",
    # engine: the compiled path
    "codegen": "engine.codegen", "ida_session": "engine.ida_session",
    # solvers: DAEModel -> Result
    "solve": "solvers.ida", "integrators": "solvers.explicit", "physics": "solvers.physics",
    "recorder": "solvers.recorder",
    # results
    "result": "results.result", "outputs": "results.outputs",
    # studies over many runs
    "accuracy": "studies.accuracy", "analysis": "studies.analysis", "stability": "studies.stability",
    "sweep": "studies.sweep", "response_metrics": "studies.response_metrics",
    # figures
    "plot": "plot.figures", "style": "plot.style", "animate": "plot.animate",
}
OPTIONAL = {"profiles", "drivers", "recorder"}
#: Modules that stay at the top level (options: the argument rules every layer uses, a leaf like errors).
STAY = {"__init__", "__main__", "errors", "cli", "options"}
#: Sub-packages that stay as they are.
PACKAGES_STAY = {"contact"}
#: Directories moved with the module that uses them.
DIR_MOVES = {"csrc": "engine/csrc"}
#: Names of the revolute clearance module that move to the shared contact-pair module.
SPLIT_FROM = "clearance"
SPLIT_TO = "assembly.contact_pairs"
SPLIT_NAMES = ("PairLogic", "ContactBuild", "approach_floor")
#: Old paths that keep an alias even if no document names them.
REQUIRED_ALIASES = {"scene", "loads", "mechanisms", "result", "sweep", "analysis"}

SUBPACKAGE_DOCS = {
    "model": "Scenes and what they are made of: bodies, joints, drivers, loads, readings, the mechanism library and\n"
             "scene files. Nothing here builds equations; :mod:`daeclear.assembly` turns a scene into a DAE.",
    "assembly": "Scene -> symbolic DAE (:class:`~daeclear.assembly.assemble.DAEModel`): the parameter table, the\n"
                "symbolic helpers, the joints' contact builders (revolute and translational clearance, the shared\n"
                "contact-pair machinery) and the contact automaton.",
    "engine": "The compiled path: C generated from the DAE and its on-disk cache (codegen), the ctypes session over\n"
              "SUNDIALS IDA (ida_session), and csrc/ (hand-written drivers, vendored SUNDIALS headers).",
    "solvers": "DAEModel -> Result: the IDA loop (:func:`simulate`, ida), the explicit and scipy methods (explicit)\n"
               "and the run checks (physics).",
    "results": "A run's data: :class:`~daeclear.results.result.Result`, its HDF5 files, and safe writes of output\n"
               "files (outputs).",
    "studies": "Studies over many runs: accuracy (work-precision, energy balance), motion analysis, the stability\n"
               "suite, parameter sweeps and response metrics.",
    "plot": "Figures of runs and studies (figures), their shared style (style) and animations (animate).\n\n"
            "The figure functions are importable from here: ``from daeclear.plot import plot_channel``.",
}


OLD_PATHS_TEMPLATE = '''"""Old module paths (before the sub-packages) as thin aliases for one release.

``import daeclear.scene`` (or ``from daeclear.scene import Body``) still works: a finder at the front
of ``sys.meta_path`` answers for each old path (no module lives there any more) with a module that
re-exports the public names of the module's new place and whose docstring says where it moved. At
the front, so that an editable install of an older tree cannot answer first. Written by
tools/restructure.py.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
import types

#: Old module path -> its new place.
OLD_PATHS: dict[str, str] = {
@MOVED@
}


class OldPathFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds and loads the alias modules of :data:`OLD_PATHS`."""

    def find_spec(self, fullname: str, path: object = None, target: object = None
                  ) -> importlib.machinery.ModuleSpec | None:
        return importlib.util.spec_from_loader(fullname, self) if fullname in OLD_PATHS else None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> None:
        return None  # a plain module

    def exec_module(self, module: types.ModuleType) -> None:
        new = importlib.import_module(OLD_PATHS[module.__name__])
        names = [name for name, value in vars(new).items()
                 if not name.startswith("_") and not isinstance(value, types.ModuleType)]
        module.__doc__ = f"Moved to {new.__name__}; this old path stays as a thin alias for one release."
        module.__dict__.update({name: getattr(new, name) for name in names})
        module.__all__ = names


if not any(isinstance(finder, OldPathFinder) for finder in sys.meta_path):
    sys.meta_path.insert(0, OldPathFinder())
'''


#: ``from daeclear.solvers import simulate`` without loading the IDA loop with the package: the assembly
#: uses solvers.physics (run checks), and the IDA loop imports the assembly.
SOLVERS_LAZY = '''
from __future__ import annotations

from typing import Any

__all__ = ["simulate"]


def __getattr__(name: str) -> Any:
    """``simulate`` on first use: importing the package must not load the IDA loop, which imports
    the assembly, which uses this package's run checks (physics)."""
    if name == "simulate":
        from .ida import simulate

        return simulate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
'''


def run(*cmd: str) -> str:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # this tree's package, not an installed one
    return subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True, env=env).stdout


# ----------------------------------------------------------------------------- inventory

def old_inventory() -> tuple[dict[str, str], set[str]]:
    """(old top-level module -> new module) for the modules present, and every old dotted module name."""
    pkg = ROOT / PKG
    tops = sorted(p.stem for p in pkg.glob("*.py"))
    unknown = [m for m in tops if m not in MOVES and m not in STAY]
    dirs = sorted(p.name for p in pkg.iterdir() if p.is_dir() and p.name != "__pycache__")
    unknown += [d + "/" for d in dirs if d not in PACKAGES_STAY and d not in DIR_MOVES]
    if unknown:
        sys.exit(f"restructure: unknown top-level modules or directories {unknown}: add them to MOVES or STAY")
    if (pkg / MOVES["scene"].split(".")[0]).exists():
        sys.exit("restructure: the tree is restructured already")
    missing = [m for m in MOVES if m not in OPTIONAL and m not in tops]
    if missing:
        print(f"restructure: modules {missing} are not there (nothing to move for them)")
    moves = {m: MOVES[m] for m in tops if m in MOVES}
    modules = {PKG}
    for p in pkg.rglob("*.py"):
        if "__pycache__" in p.parts or DIR_MOVES.keys() & set(p.relative_to(pkg).parts):
            continue
        rel = p.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules.add(".".join(parts))
    return moves, modules


def map_module(name: str, moves: dict[str, str]) -> str:
    """New dotted name of an old module name (unchanged when it does not move)."""
    parts = name.split(".")
    if parts[0] != PKG or len(parts) < 2 or parts[1] not in moves:
        return name
    return ".".join([PKG, *moves[parts[1]].split("."), *parts[2:]])


def relative(from_package: str, target: str) -> str:
    """The relative module text for ``target`` seen from inside ``from_package``."""
    a, b = from_package.split("."), target.split(".")
    common = 0
    while common < min(len(a), len(b)) and a[common] == b[common]:
        common += 1
    return "." * (len(a) - common + 1) + ".".join(b[common:])


# ----------------------------------------------------------------------------- import statements

def line_offsets(text: str) -> list[int]:
    offsets, pos = [0], 0
    for line in text.splitlines(keepends=True):
        pos += len(line)
        offsets.append(pos)
    return offsets


def char_offset(text_lines: list[str], offsets: list[int], lineno: int, col_bytes: int) -> int:
    line = text_lines[lineno - 1]
    return offsets[lineno - 1] + len(line.encode()[:col_bytes].decode())


def rewrite_imports(text: str, old_package: str | None, new_package: str | None, moves: dict[str, str],
                    modules: set[str]) -> str:
    """Rewrite the ``from X import ...`` statements of one Python source.

    ``old_package``/``new_package``: the package the file is in before and after the move (None
    outside the package: only absolute imports are rewritten).
    """
    tree = ast.parse(text)
    lines = text.splitlines(keepends=True)
    offsets = line_offsets(text)
    edits: list[tuple[int, int, str]] = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            if old_package is None:
                continue
            base = old_package.split(".")
            if node.level > 1:
                base = base[:-(node.level - 1)]
            old_base = ".".join(base + ([node.module] if node.module else []))
        else:
            old_base = node.module or ""
        if old_base != PKG and not old_base.startswith(PKG + "."):
            continue
        groups: dict[str, list[str]] = {}
        for alias in node.names:
            full = f"{old_base}.{alias.name}"
            if full in modules:  # `from package import module`
                new_full = map_module(full, moves)
                parent, leaf = new_full.rsplit(".", 1)
                local = alias.asname or alias.name
                groups.setdefault(parent, []).append(leaf if leaf == local else f"{leaf} as {local}")
                continue
            target = map_module(old_base, moves)
            if old_base == f"{PKG}.{SPLIT_FROM}" and alias.name in SPLIT_NAMES:
                target = f"{PKG}.{SPLIT_TO}"
            if old_base == f"{PKG}.plot" and not any(a.name.startswith("_") for a in node.names):
                # the public home of the figure functions (private ones: plot.figures); the callers read
                # daeclear.plot's attributes as before, so a test that patches them still reaches them
                target = f"{PKG}.plot"
            groups.setdefault(target, []).append(alias.name + (f" as {alias.asname}" if alias.asname else ""))

        def render(module: str, relative_import: bool = bool(node.level)) -> str:
            return relative(new_package, module) if relative_import else module  # type: ignore[arg-type]

        start = char_offset(lines, offsets, node.lineno, node.col_offset)
        end = char_offset(lines, offsets, node.end_lineno, node.end_col_offset)  # type: ignore[arg-type]
        segment = text[start:end]
        if len(groups) == 1:
            (module, names), = groups.items()
            plain = [a.name + (f" as {a.asname}" if a.asname else "") for a in node.names]
            if names == plain:  # same names: change only the module text, keep the statement's layout
                m = re.match(r"from\s+([.\w]+)(\s+import)", segment)
                assert m, segment
                new = render(module)
                if new != m.group(1):
                    edits.append((start + m.start(1), start + m.end(1), new))
                continue
        indent = re.match(r"[ \t]*", lines[node.lineno - 1]).group(0)
        comment = re.search(r"#[^\n]*", segment)  # e.g. a noqa inside a parenthesized statement: on every line
        statements = [f"from {render(module)} import {', '.join(names)}" + (f"  {comment.group(0)}" if comment else "")
                      for module, names in groups.items()]
        edits.append((start, end, ("\n" + indent).join(statements)))
    for start, end, new in sorted(edits, reverse=True):
        text = text[:start] + new + text[end:]
    return text


# ----------------------------------------------------------------------------- text references

def rewrite_text(text: str, moves: dict[str, str], public_attrs: set[str]) -> str:
    """Dotted module paths (``daeclear.solve.simulate``) and file paths (``daeclear/solve.py``) in any text.

    Names the package exports as attributes (``daeclear.loads``, ``daeclear.analysis``, the
    functions ``daeclear.sweep`` and ``daeclear.assemble``) stay as written except in import
    statements and a string that is exactly the module path (``sys.modules["daeclear.sweep"]``).
    """
    names = sorted((m for m in moves if m != "plot"), key=len, reverse=True)
    pattern = re.compile(r"(?<![\w.])" + PKG + r"\.(" + "|".join(names) + r")(?![\w])")

    def dotted(m: re.Match[str]) -> str:
        old = m.group(1)
        before, after = text[max(0, m.start() - 5):m.start()], text[m.end():m.end() + 1]
        line_start = text.rfind("\n", 0, m.start()) + 1
        head = text[line_start:m.start()]
        in_import = bool(re.search(r"(^|\s)(import|from)\s+$", head))
        if old in public_attrs and not in_import:
            quoted = before[-1:] in "\"'" and after == before[-1:] and before[-1:] != ""
            if not quoted:
                return m.group(0)
        if old == SPLIT_FROM:
            rest = re.match(r"\.(\w+)", text[m.end():])
            if rest and rest.group(1) in SPLIT_NAMES:
                return f"{PKG}.{SPLIT_TO}"
        return f"{PKG}.{moves[old]}"

    text = pattern.sub(dotted, text)
    # `import daeclear as dc` ... `dc.result.load_times`: the attribute path of a moved module
    for local in sorted(set(re.findall(r"^\s*(?:>>> )?import " + PKG + r" as (\w+)", text, re.M))):
        attrs = sorted((m for m in moves if m != "plot" and m not in public_attrs), key=len, reverse=True)
        text = re.sub(r"(?<![\w.])" + local + r"\.(" + "|".join(attrs) + r")(?=\.\w)",
                      lambda m, local=local: f"{local}.{moves[m.group(1)]}", text)
    path_pattern = re.compile(r"(?<![\w/])" + PKG + r"/(" + "|".join(sorted(moves, key=len, reverse=True)) + r")\.py\b")
    text = path_pattern.sub(lambda m: f"{PKG}/{moves[m.group(1)].replace('.', '/')}.py", text)
    # a module named by its bare file name in backquotes (`solve.py`): its path under the package now
    text = re.sub(r"(?<=`)(" + "|".join(sorted(moves, key=len, reverse=True)) + r")\.py(?=`)",
                  lambda m: f"{moves[m.group(1)].replace('.', '/')}.py", text)
    for old, new in DIR_MOVES.items():
        text = re.sub(r"(?<![\w/])" + PKG + "/" + old + r"\b", f"{PKG}/{new}", text)
    return text


# ----------------------------------------------------------------------------- public names

def public_names(path: Path) -> list[str]:
    """The names a module offers: ``__all__``, its public top-level definitions and the public names it
    imports from inside the package (its re-exports); not modules, not TYPE_CHECKING imports."""
    tree = ast.parse(path.read_text())
    names: list[str] = []

    def add(name: str) -> None:
        if not name.startswith("_") and name not in names:
            names.append(name)

    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                for n in ast.walk(t):
                    if isinstance(n, ast.Name):
                        add(n.id)
                if isinstance(t, ast.Name) and t.id == "__all__" and isinstance(node.value, (ast.List, ast.Tuple)):
                    for elt in node.value.elts:
                        if isinstance(elt, ast.Constant) and isinstance(elt.value, str):
                            add(elt.value)
        elif isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith(PKG)):
            if node.module is None:  # `from . import module`
                continue
            for alias in node.names:
                add(alias.asname or alias.name)
    return [n for n in names if n != "__all__"]


def wrapped_import(module_text: str, names: list[str], comment: str = "") -> str:
    """``from X import a, b`` on one line when it fits in 110 characters, else parenthesized and wrapped."""
    line = f"from {module_text} import {', '.join(names)}{comment}"
    if len(line) <= 110:
        return line
    out, current = [f"from {module_text} import ({comment}"], "    "
    for i, name in enumerate(names):
        piece = name + (", " if i < len(names) - 1 else ")")
        if len(current) + len(piece.rstrip()) > 110:
            out.append(current.rstrip())
            current = "    "
        current += piece
    out.append(current)
    return "\n".join(out)


def names_block(module_text: str, names: list[str]) -> str:
    """``from X import (a, b, ...)`` wrapped at 110 characters."""
    out, line = [f"from {module_text} import ("], "    "
    for i, name in enumerate(names):
        piece = name + (", " if i < len(names) - 1 else "")
        if len(line) + len(piece) > 110:
            out.append(line.rstrip())
            line = "    "
        line += piece
    out.append(line.rstrip() + ")  # noqa: F401")
    return "\n".join(out)


# ----------------------------------------------------------------------------- the split

def used_names(nodes: list[ast.stmt]) -> set[str]:
    used: set[str] = set()
    for node in nodes:
        for n in ast.walk(node):
            if isinstance(n, ast.Name):
                used.add(n.id)
            elif isinstance(n, ast.Constant) and isinstance(n.value, str):
                used.update(re.findall(r"\w+", n.value))
    return used


def pruned_header(header: list[ast.stmt], text: str, used: set[str], keep_reexports: bool) -> list[list[str]]:
    """The import statements of ``header`` that the body uses (each as in the source when kept whole),
    in the source's groups (blank-line separated)."""
    lines = text.splitlines()
    groups: list[list[str]] = [[]]
    previous_end = None
    for node in header:
        if previous_end is not None and any(not lines[i].strip() for i in range(previous_end, node.lineno - 1)):
            groups.append([])
        previous_end = node.end_lineno
        out = groups[-1]
        source = ast.get_source_segment(text, node, padded=False)
        line_end = lines[node.end_lineno - 1]
        comment = line_end[line_end.find("#"):] if "#" in line_end else ""
        if isinstance(node, ast.ImportFrom) and node.module == "__future__":
            out.append(source)
            continue
        if "noqa: F401" in comment:
            if keep_reexports:
                out.append(source + "  " + comment)
            continue
        kept = [a for a in node.names if (a.asname or a.name).split(".")[0] in used]
        if not kept:
            continue
        if len(kept) == len(node.names):
            out.append(source + ("  " + comment if comment else ""))
        elif isinstance(node, ast.ImportFrom):
            module = "." * node.level + (node.module or "")
            out.append(f"from {module} import " + ", ".join(a.name + (f" as {a.asname}" if a.asname else "")
                                                          for a in kept))
        else:
            out.extend("import " + a.name + (f" as {a.asname}" if a.asname else "") for a in kept)
    return [g for g in groups if g]


def join_groups(groups: list[list[str]]) -> str:
    return "\n\n".join("\n".join(g) for g in groups)


def split_revolute(path: Path, shared: Path) -> None:
    """Move the contact-pair machinery (SPLIT_NAMES) of the revolute module into ``shared``."""
    text = path.read_text()
    tree = ast.parse(text)
    lines = text.splitlines(keepends=True)
    doc = tree.body[0]
    header = [n for n in tree.body[1:] if isinstance(n, (ast.Import, ast.ImportFrom))
              and n.lineno < min(m.lineno for m in tree.body[1:] if not isinstance(m, (ast.Import, ast.ImportFrom)))]

    def start(node: ast.stmt) -> int:
        return min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])])

    moved = [n for n in tree.body if getattr(n, "name", None) in SPLIT_NAMES]
    assert [n.name for n in moved] == list(SPLIT_NAMES), [n.name for n in moved]
    span = (start(moved[0]), moved[-1].end_lineno)
    inside = [n for n in tree.body if span[0] <= n.lineno <= span[1]]
    assert inside == moved, "the shared machinery is not one block"
    rest_nodes = [n for n in tree.body[1:] if n not in header and n not in moved]
    # the late import of the translational joint (E402) moves up to the header: nothing is circular now
    late = [n for n in rest_nodes if isinstance(n, ast.ImportFrom)]
    shared_body = "".join(lines[span[0] - 1:span[1]]).strip("\n")
    rest_lines = lines[span[1]:]
    for node in sorted(late, key=lambda n: n.lineno, reverse=True):
        a, b = node.lineno - span[1] - 1, node.end_lineno - span[1]
        del rest_lines[a:b]
        if a < len(rest_lines) and not rest_lines[a].strip() and a > 0 and not rest_lines[a - 1].strip():
            del rest_lines[a]
    rest_body = "".join(rest_lines).strip("\n")
    late_imports = [wrapped_import("." * n.level + n.module, [a.name for a in n.names]) for n in late]

    shared_text = (ast.get_source_segment(text, doc) + "\n\n"
                   + join_groups(pruned_header(header, text, used_names(moved), keep_reexports=False))
                   + "\n\n\n" + shared_body + "\n")
    rest = [n for n in rest_nodes if n not in late]
    used = used_names(rest)
    shared_used = [name for name in SPLIT_NAMES if name in used]
    groups = pruned_header(header, text, used, keep_reexports=True)
    # the shared module and the late import join the group of the package's own imports
    groups[-1] += [f"from .{SPLIT_TO.rsplit('.', 1)[1]} import {', '.join(shared_used)}", *late_imports]
    own_doc = ('"""The revolute clearance joint: a journal in a bearing as a contact pair (its parameters, force,\n'
               'gap, output channels and event logic), and the registry of the clearance joints\' builders.\n\n'
               f'The contact-pair machinery it shares with the translational joint is :mod:`{PKG}.{SPLIT_TO}`.\n"""')
    path.write_text(own_doc + "\n\n" + join_groups(groups) + "\n\n\n" + rest_body + "\n")
    shared.write_text(shared_text)


# ----------------------------------------------------------------------------- main

def main() -> None:
    if run("git", "status", "--porcelain", "--untracked-files=no").strip():
        sys.exit("restructure: the work tree has changes; commit or stash them first")
    moves, modules = old_inventory()
    public_attrs = set()
    init_tree = ast.parse((ROOT / PKG / "__init__.py").read_text())
    for node in init_tree.body:  # names the package binds: `from . import analysis`, `from .sweep import sweep`
        if isinstance(node, ast.ImportFrom):
            public_attrs.update(a.asname or a.name for a in node.names)
    public_attrs &= set(moves)

    docs = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    named = set()
    for doc in docs:
        named.update(re.findall(PKG + r"\.(\w+)", doc.read_text()))
    aliases = sorted(((named & set(moves)) | (REQUIRED_ALIASES & set(moves))) - {"plot"})
    loaded = run(sys.executable, "-c", f"import sys, {PKG}; print(' '.join(sorted(sys.modules)))").split()
    eager = [m for m in aliases if f"{PKG}.{m}" in loaded]
    print("aliases:", ", ".join(aliases))
    print("loaded by `import daeclear` (aliases imported eagerly):", ", ".join(eager))

    # 2. git mv
    file_map: dict[Path, tuple[str, str]] = {}  # new path -> (old module, new module)
    for sub in sorted({new.split(".")[0] for new in moves.values()}):
        (ROOT / PKG / sub).mkdir(exist_ok=True)
    for old, new in moves.items():
        dest = ROOT / PKG / (new.replace(".", "/") + ".py")
        run("git", "mv", f"{PKG}/{old}.py", str(dest.relative_to(ROOT)))
        file_map[dest] = (f"{PKG}.{old}", f"{PKG}.{new}")
    for old, new in DIR_MOVES.items():
        run("git", "mv", f"{PKG}/{old}", f"{PKG}/{new}")
    for p in sorted((ROOT / PKG).rglob("*.py")):
        if p in file_map or set(DIR_MOVES.values()) & {str(q) for q in p.relative_to(ROOT / PKG).parents}:
            continue
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        file_map[p] = (name, name)

    # 4. rewrite imports and paths
    skip = {ROOT / "tools" / "restructure.py", ROOT / "tests" / "test_layout.py"}
    for p, (old_mod, new_mod) in sorted(file_map.items()):
        is_init = p.name == "__init__.py"
        old_pkg = old_mod if is_init else old_mod.rsplit(".", 1)[0]
        new_pkg = new_mod if is_init else new_mod.rsplit(".", 1)[0]
        text = p.read_text()
        new = rewrite_text(rewrite_imports(text, old_pkg, new_pkg, moves, modules), moves, public_attrs)
        if new != text:
            p.write_text(new)
    others = [p for d in ("tests", "examples", "benchmarks", "tools") if (ROOT / d).is_dir()
              for p in sorted((ROOT / d).rglob("*.py")) if p not in skip]
    for p in others:
        text = p.read_text()
        new = rewrite_text(rewrite_imports(text, None, None, moves, modules), moves, public_attrs)
        if new != text:
            p.write_text(new)
    for p in docs + [ROOT / "pyproject.toml"]:
        text = p.read_text()
        new = rewrite_text(text, moves, public_attrs)
        if new != text:
            p.write_text(new)

    # 3. the split (after the rewrite: the module's imports already name the new places)
    revolute = ROOT / PKG / (moves[SPLIT_FROM].replace(".", "/") + ".py")
    shared = ROOT / PKG / (SPLIT_TO.replace(".", "/") + ".py")
    split_revolute(revolute, shared)

    # 5. sub-packages and aliases
    for sub, doc in SUBPACKAGE_DOCS.items():
        init = ROOT / PKG / sub / "__init__.py"
        body = f'"""{doc}\n"""\n'
        if sub == "solvers":
            body += SOLVERS_LAZY
        if sub == "plot":
            names = public_names(ROOT / PKG / "plot" / "figures.py")
            body += ("\n" + names_block(".figures", names).replace("  # noqa: F401", "") + "\n\n__all__ = [\n"
                     + "".join(f'    "{name}",\n' for name in names) + "]\n")
        init.write_text(body)
    aliases_text = OLD_PATHS_TEMPLATE.replace("@MOVED@", "\n".join(
        f'    "{PKG}.{old}": "{PKG}.{moves[old]}",' for old in aliases))
    (ROOT / PKG / "old_paths.py").write_text(aliases_text)

    # 6. fix-ups no rule covers
    # 6a. the package's __init__: load the aliases that `import daeclear` loaded before the move first, so
    # that `daeclear.<old>.<name>` keeps working after `import daeclear` and the names bound below (the
    # function `sweep` over the module `daeclear.sweep`, the moved modules) win over the aliases.
    init = ROOT / PKG / "__init__.py"
    text = init.read_text()
    marker = "from __future__ import annotations\n"
    assert marker in text
    block = ("\n# Old module paths, thin aliases for one release (daeclear.old_paths): those `import daeclear` loaded\n"
             "# before the move are imported first, so that `daeclear.<old>.<name>` keeps working after\n"
             "# `import daeclear` and the names bound below win over the aliases (the function `sweep` over the\n"
             "# module `daeclear.sweep`).\n"
             "from . import old_paths  # noqa: F401  (installs the finder of the old paths)\n"
             + wrapped_import(".", eager, "  # noqa: F401") + "\n")
    init.write_text(text.replace(marker, marker + block, 1))
    # 6b. pyproject: the package data (csrc) moved with the engine and is now the engine package's data
    pyproject = ROOT / "pyproject.toml"
    text = pyproject.read_text()
    block = re.search(r"^" + PKG + r" = \[(.*?)\]\n", text, re.S | re.M)
    assert block and all(DIR_MOVES.keys() & {item.strip('"').split("/")[0]}
                         for item in re.findall(r'"[^"]*"', block.group(1))), "package data outside csrc"
    owner = f'"{PKG}.engine"'
    items = re.findall(r'"[^"]*"', block.group(1))
    wrapped, line = [], f"{owner} = ["
    for i, item in enumerate(items):
        piece = item + (", " if i < len(items) - 1 else "]")
        if len(line) + len(piece.rstrip()) > 110:
            wrapped.append(line.rstrip())
            line = " " * len(f"{owner} = [")
        line += piece
    wrapped.append(line)
    text = text[:block.start()] + "\n".join(wrapped) + "\n" + text[block.end():]
    pyproject.write_text(text)

    run("git", "add", "-A", PKG, "tests", "examples", "benchmarks", "docs", "README.md", "pyproject.toml")
    # 7. every file still parses, and the package imports
    for p in sorted((ROOT / PKG).rglob("*.py")):
        ast.parse(p.read_text(), str(p))
    print(run(sys.executable, "-c", f"import {PKG}; print('import {PKG}: ok')").strip())


if __name__ == "__main__":
    main()
