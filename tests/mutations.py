"""Mutation check of the physics: each one-line bug of ``tests/mutations.toml`` must fail a test.

Each mutation replaces one piece of source text (``find``, which must occur exactly once in ``file``:
a refactor that moves or changes it fails loudly instead of disarming the mutation) by ``replace`` in a
copy of the repository, then runs there the test named ``caught_by`` and, if that one passes, the
tests of the mutation's area (``tests``), stopping at the first failure. A mutation is *caught* when
its ``caught_by`` test fails; *elsewhere* when only another test of the area fails (name that one in
the list); it *survives* when they all pass, which is a hole in the tests: write the test that
catches it. A new mutation may leave ``caught_by`` out: the run prints the test that caught it.

    python tests/mutations.py                  # every mutation (caught_by, then its area if needed)
    python tests/mutations.py --quick          # every mutation against its caught_by test alone
    python tests/mutations.py --only ID[,ID]   # some of them; --list prints the list
    python tests/mutations.py --jobs 2         # two copies at once

The copy lives in a fixed place (``--work``, default ``$TMPDIR/daeclear-mutants-<checkout>``) so that the compiled
model libraries of unchanged structures are found in ``$DAECLEAR_CACHE_DIR`` from one run to the next
(their cache key holds the driver's path); byte code is never written there, so a mutated file of the
same size is never read from a stale ``.pyc``. Exit status: 0 when every mutation is caught and the
unmutated tests pass, 1 otherwise. ``tests/test_mutations.py`` runs the ``ci = true`` ones in the suite.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIST = ROOT / "tests" / "mutations.toml"
#: What a copy holds: the package and everything its tests read (examples, benchmarks, docs).
COPIED = ("daeclear", "tests", "benchmarks", "examples", "docs", "pyproject.toml", "README.md", "CONTRIBUTING.md")
_BUILD_OUTPUT = shutil.ignore_patterns("__pycache__", "*.pyc", "*.so", "*.egg-info", ".pytest_cache")


def left_out_of_copy(directory: str, names: list[str]) -> set[str]:
    """What a copy leaves out: build output, and a run's ``results`` folder (not the package's
    ``results`` stage, which is a package: it has an ``__init__.py``)."""
    left_out = set(_BUILD_OUTPUT(directory, names))
    if "results" in names and not (Path(directory) / "results" / "__init__.py").exists():
        left_out.add("results")
    return left_out


#: pytest's exit statuses: 0 all passed, 1 some failed; anything else (interrupted, internal error,
#: usage error, nothing collected) is no verdict.
PASSED, FAILED = 0, 1
TIMEOUT = 1800.0  # s for one mutation's tests (the widest area takes a few minutes)
#: Where the copies live by default: one place per checkout (two checkouts never share a copy).
WORK = Path(tempfile.gettempdir()) / f"daeclear-mutants-{hashlib.sha256(str(ROOT).encode()).hexdigest()[:10]}"


class MutationListError(ValueError):
    """The mutation list is malformed or a mutation's text is not (exactly once) where it says."""


@dataclass(frozen=True)
class Mutation:
    """One physics-critical one-line change: ``find`` -> ``replace`` in ``file`` (relative to the
    repository), the area's ``tests`` (pytest arguments), the one test that catches it, and ``what``."""

    id: str
    file: str
    find: str
    replace: str
    what: str
    tests: tuple[str, ...]
    caught_by: str
    ci: bool = False

    def apply(self, source: str) -> str:
        """``source`` with the mutation made; MutationListError unless ``find`` occurs exactly once."""
        count = source.count(self.find)
        if count != 1:
            where = "not found" if count == 0 else f"found {count} times"
            raise MutationListError(
                f"mutation {self.id}: find={self.find!r} {where} in {self.file}, must occur exactly once "
                f"(the code moved or changed: update tests/mutations.toml{suggest(self.find, self.file)}).")
        return source.replace(self.find, self.replace)


@dataclass(frozen=True)
class Outcome:
    """A mutation's verdict: ``caught``, ``survived``, ``timeout`` or ``error`` (no verdict), with the
    tests that failed, the seconds it took and the end of pytest's output."""

    mutation: Mutation
    verdict: str
    failed: tuple[str, ...]
    seconds: float
    tail: str = ""


def suggest(find: str, file: str) -> str:
    """Where else in the package ``find`` occurs (a module moved), as a hint for the message."""
    hits = [str(p.relative_to(ROOT)) for p in sorted((ROOT / "daeclear").rglob("*.py")) + sorted(
        (ROOT / "daeclear").rglob("*.c")) if str(p.relative_to(ROOT)) != file and find in p.read_text()]
    return f"; the text is in {', '.join(hits)}" if hits else ""


def load(path: Path = LIST) -> list[Mutation]:
    """The mutations of the list file, each checked: fields present, ids unique, ``find`` exactly once
    in its file and different from ``replace``, the tests' files present."""
    data = tomllib.loads(path.read_text())
    out: list[Mutation] = []
    for i, entry in enumerate(data.get("mutation", [])):
        missing = [k for k in ("id", "file", "find", "replace", "what", "tests") if k not in entry]
        if missing:
            raise MutationListError(f"{path.name}: mutation {i} ({entry.get('id', '?')}) lacks {', '.join(missing)}.")
        extra = set(entry) - {"id", "file", "find", "replace", "what", "tests", "caught_by", "ci"}
        if extra:
            raise MutationListError(f"{path.name}: mutation {entry['id']}: unknown keys {sorted(extra)}.")
        m = Mutation(id=entry["id"], file=entry["file"], find=entry["find"], replace=entry["replace"],
                     what=entry["what"], tests=tuple(entry["tests"]), caught_by=entry.get("caught_by", ""),
                     ci=bool(entry.get("ci", False)))
        if m.find == m.replace:
            raise MutationListError(f"mutation {m.id}: replace is find, nothing would change.")
        source = ROOT / m.file
        if not source.is_file():
            raise MutationListError(f"mutation {m.id}: file={m.file!r} does not exist (update tests/mutations.toml"
                                    f"{suggest(m.find, m.file)}).")
        m.apply(source.read_text())
        for target in (*m.tests, *([m.caught_by] if m.caught_by else [])):
            if not (ROOT / target.split("::")[0]).is_file():
                raise MutationListError(f"mutation {m.id}: test {target!r}: no such file.")
        if "::" in m.caught_by:
            name = m.caught_by.split("::")[1].split("[")[0]
            if not re.search(rf"^def {re.escape(name)}\(", (ROOT / m.caught_by.split("::")[0]).read_text(), re.M):
                raise MutationListError(f"mutation {m.id}: caught_by={m.caught_by!r}: no test function {name}.")
        out.append(m)
    ids = [m.id for m in out]
    doubles = sorted({i for i in ids if ids.count(i) > 1})
    if doubles:
        raise MutationListError(f"{path.name}: ids used twice: {', '.join(doubles)}.")
    return out


def make_tree(where: Path) -> Path:
    """A fresh copy of the repository's tested parts at ``where`` (replaced if there)."""
    if where.exists():
        shutil.rmtree(where)
    where.mkdir(parents=True)
    for name in COPIED:
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, where / name, ignore=left_out_of_copy)
        elif src.is_file():
            shutil.copy2(src, where / name)
    return where


def environment(tree: Path) -> dict[str, str]:
    """The tests' environment in a copy: its package first on the path, no byte code written."""
    env = dict(os.environ)
    env.update({"PYTHONPATH": str(tree), "PYTHONDONTWRITEBYTECODE": "1", "MPLBACKEND": "Agg"})
    env.setdefault("DAECLEAR_CACHE_DIR", str(Path(tempfile.gettempdir()) / "daeclear-mutants-cache"))
    return env


def check_tree_is_imported(tree: Path) -> None:
    """The copy's package is the one its tests import (not the installed or editable one)."""
    out = subprocess.run([sys.executable, "-c", "import daeclear; print(daeclear.__file__)"], cwd=tree,
                         env=environment(tree), capture_output=True, text=True, check=True).stdout.strip()
    if not Path(out).resolve().is_relative_to(tree.resolve()):
        raise RuntimeError(f"the copy at {tree} imports daeclear from {out}: a mutation would test nothing.")


def run_pytest(tree: Path, targets: tuple[str, ...], timeout: float = TIMEOUT) -> tuple[int | None, str, float]:
    """(pytest's exit status or None on timeout, its output, seconds) of ``targets`` in ``tree``."""
    cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "--no-header", "-rf", *targets]
    start = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=tree, env=environment(tree), capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode(errors="replace") if isinstance(exc.stdout, bytes) else (exc.stdout or "")
        return None, out, time.perf_counter() - start
    return proc.returncode, proc.stdout + proc.stderr, time.perf_counter() - start


def failed_tests(output: str) -> tuple[str, ...]:
    """The node ids pytest reports as failed (its ``-rf`` summary)."""
    return tuple(dict.fromkeys(re.findall(r"^FAILED (\S+)", output, re.M)))


def run_mutation(m: Mutation, tree: Path, quick: bool = False, timeout: float = TIMEOUT) -> Outcome:
    """Apply ``m`` in ``tree`` and run its ``caught_by`` test; unless ``quick``, when that one passes (or
    none is named yet), the area's tests. The file is restored whatever happens."""
    path = tree / m.file
    original = (ROOT / m.file).read_text()
    mutated = m.apply(original)
    if path.suffix == ".py":
        compile(mutated, str(path), "exec")  # a mutation is valid code: a syntax error would be caught trivially
    path.write_text(mutated)
    try:
        seconds, status, output = 0.0, PASSED, ""
        if m.caught_by:
            status, output, seconds = run_pytest(tree, (m.caught_by,), timeout)
        verdict = "caught"
        if status == PASSED and not quick:
            status, output, more = run_pytest(tree, m.tests, timeout)
            seconds += more
            verdict = "elsewhere"  # caught, but not by its caught_by test: the list needs the one that does
    finally:
        path.write_text(original)
    tail = "\n".join(output.strip().splitlines()[-15:])
    if status is None:
        return Outcome(m, "timeout", (), seconds, tail)
    verdict = {FAILED: verdict, PASSED: "survived"}.get(status, "error")
    return Outcome(m, verdict, failed_tests(output), seconds, tail)


def baseline(mutations: list[Mutation], tree: Path) -> tuple[bool, str]:
    """Whether the mutations' caught_by tests pass on the unmutated copy (else a catch would mean nothing)."""
    targets = tuple(dict.fromkeys(m.caught_by for m in mutations if m.caught_by))
    status, output, seconds = run_pytest(tree, targets)
    return status == PASSED, f"{len(targets)} test targets unmutated in {seconds:.0f} s: " + \
        (output.strip().splitlines() or ["no output"])[-1]


def table(outcomes: list[Outcome]) -> str:
    """A markdown table of the outcomes."""
    rows = ["| mutation | file | verdict | first failing test | s |", "|---|---|---|---|---:|"]
    for o in outcomes:
        first = o.failed[0] if o.failed else "-"
        rows.append(f"| {o.mutation.id} | {o.mutation.file} | {o.verdict} | {first} | {o.seconds:.0f} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="", help="comma-separated mutation ids")
    parser.add_argument("--ci", action="store_true", help="only the mutations marked ci = true")
    parser.add_argument("--quick", action="store_true", help="run each mutation's caught_by test alone")
    parser.add_argument("--list", action="store_true", help="print the mutations and exit")
    parser.add_argument("--no-baseline", action="store_true", help="skip the unmutated run of the tests")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--work", type=Path, default=WORK)
    parser.add_argument("--timeout", type=float, default=TIMEOUT)
    parser.add_argument("--verbose", action="store_true", help="print the end of pytest's output of each mutation")
    args = parser.parse_args(argv)
    try:
        mutations = load()
    except MutationListError as exc:
        print(f"mutations: {exc}", file=sys.stderr)
        return 1
    if args.only:
        wanted = args.only.split(",")
        unknown = sorted(set(wanted) - {m.id for m in mutations})
        if unknown:
            print(f"mutations: --only={args.only}: unknown ids {', '.join(unknown)}.", file=sys.stderr)
            return 1
        mutations = [m for m in mutations if m.id in wanted]
    if args.ci:
        mutations = [m for m in mutations if m.ci]
    if args.list:
        for m in mutations:
            print(f"{m.id:<34} {m.file}: {m.what}\n{'':<34} caught by {m.caught_by}")
        return 0
    jobs = max(1, min(args.jobs, len(mutations)))
    trees = [make_tree(args.work / f"tree{k}") for k in range(jobs)]
    check_tree_is_imported(trees[0])
    ok = True
    if not args.no_baseline:
        ok, note = baseline(mutations, trees[0])
        print(("baseline passes: " if ok else "BASELINE FAILS: ") + note, flush=True)
    free = list(trees)
    outcomes: list[Outcome] = []

    def work(m: Mutation) -> Outcome:
        tree = free.pop()
        try:
            outcome = run_mutation(m, tree, args.quick, args.timeout)
        finally:
            free.append(tree)
        first = outcome.failed[0] if outcome.failed else ""
        print(f"{outcome.verdict:<9} {m.id:<34} {outcome.seconds:6.0f} s  {first}", flush=True)
        if outcome.verdict == "elsewhere":
            print(f"    caught, but not by caught_by={m.caught_by!r}: name the test that failed above", flush=True)
        if outcome.verdict != "caught" or args.verbose:
            print("    " + outcome.tail.replace("\n", "\n    "), flush=True)
        return outcome

    with ThreadPoolExecutor(jobs) as pool:
        outcomes = list(pool.map(work, mutations))
    print()
    print(table(outcomes))
    missed = [o.mutation.id for o in outcomes if o.verdict != "caught"]
    print(f"\n{len(outcomes) - len(missed)} of {len(outcomes)} mutations caught"
          + (f"; not caught: {', '.join(missed)}" if missed else ""))
    return 0 if ok and not missed else 1


if __name__ == "__main__":
    sys.exit(main())
