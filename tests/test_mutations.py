"""The mutation check of the physics in the suite (tests/mutations.py, CONTRIBUTING.md "Mutation check").

Every mutation of tests/mutations.toml is armed: its source text is found exactly once where the list
says, its tests exist (a refactor that moves the text fails here, not silently). The mutations marked
``ci = true`` (the four bugs of issue 47, one line each, that once passed every test of their area) are
applied to a copy of the repository and their caught_by test must fail there (under a minute).
The whole list runs as ``python tests/mutations.py`` (every mutation must be caught).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent


def _mutations():
    spec = importlib.util.spec_from_file_location("mutations", HERE / "mutations.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["mutations"] = module  # dataclasses resolve their module by name
    spec.loader.exec_module(module)
    return module


mutations = _mutations()


def test_every_mutation_is_armed():
    listed = mutations.load()
    assert len(listed) >= 20 and len({m.file for m in listed}) >= 10
    ci = [m.id for m in listed if m.ci]
    assert set(ci) == {"revolute-force-at-centres", "wedge-bearing-rotation-sign", "wear-arc-too-wide",
                       "position-floor-unscaled"}
    assert all(m.caught_by for m in listed)


def test_a_mutation_whose_text_moved_fails_loudly(tmp_path):
    listed = tmp_path / "list.toml"
    listed.write_text('[[mutation]]\nid = "gone"\nfile = "daeclear/contact/wear.py"\nfind = "no such text"\n'
                      'replace = "x"\nwhat = "w"\ntests = ["tests/test_wear.py"]\n')
    with pytest.raises(mutations.MutationListError, match="find='no such text' not found in daeclear/contact/wear.py"):
        mutations.load(listed)
    listed.write_text(listed.read_text().replace('find = "no such text"', 'find = "np.clip("'))
    with pytest.raises(mutations.MutationListError,
                       match=r"find='np.clip\(' found \d+ times in daeclear/contact/wear.py, must occur exactly once"):
        mutations.load(listed)
    listed.write_text(listed.read_text().replace('file = "daeclear/contact/wear.py"\nfind = "np.clip("',
                                                 'file = "daeclear/contact/gone.py"\nfind = "def half_angle_overlap("'))
    with pytest.raises(mutations.MutationListError, match="gone.py' does not exist .*the text is in "
                                                          "daeclear/contact/wear.py"):
        mutations.load(listed)


def test_a_copy_holds_the_whole_package(tmp_path):
    """Every module of the package is in a copy, the ``results`` stage too (a run's output folder of
    that name is what a copy leaves out)."""
    tree = mutations.make_tree(tmp_path / "copy")
    package = mutations.ROOT / "daeclear"
    here = {p.relative_to(package) for p in package.rglob("*.py") if "__pycache__" not in p.parts}
    there = {p.relative_to(tree / "daeclear") for p in (tree / "daeclear").rglob("*.py")}
    assert Path("results/__init__.py") in here
    assert there == here
    assert mutations.left_out_of_copy(str(tmp_path), ["results", "a.pyc", "x.py"]) == {"results", "a.pyc"}


@pytest.mark.slow
def test_the_ci_mutations_are_caught():
    """Each ci mutation in a copy of the repository: its caught_by test fails there (and passes here,
    in the suite). The copy's package is the one its tests import (checked first)."""
    selected = [m for m in mutations.load() if m.ci]
    tree = mutations.make_tree(mutations.WORK / "ci")
    mutations.check_tree_is_imported(tree)
    outcomes = [mutations.run_mutation(m, tree, quick=True, timeout=300.0) for m in selected]
    missed = {o.mutation.id: o.tail for o in outcomes if o.verdict != "caught"}
    assert not missed, missed
    assert all(o.failed and o.failed[0].startswith(o.mutation.caught_by) for o in outcomes)
    for m in selected:  # the copy is restored after each mutation
        assert (tree / m.file).read_text() == (mutations.ROOT / m.file).read_text()
