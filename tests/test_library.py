"""Loading compiled libraries (daeclear.engine.library): one loader for both kinds of library, each
opened once per path, with its interface version checked and a library of the other kind refused."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import casadi as ca
import pytest

from daeclear.assembly.assemble import assemble
from daeclear.engine import c_api, codegen, library
from daeclear.engine.library import MODEL_PROTOTYPES, ODE_PROTOTYPES, ModelLibrary, OdeLibrary, StaleLibrary
from daeclear.engine.session_base import DAEFunctions
from daeclear.core.errors import DaeclearError
from daeclear.model.mechanisms import slider_crank
from daeclear.solvers.explicit import ode_spec


def decay_model() -> DAEFunctions:
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 1), ca.SX.sym("yp", 1), ca.SX.sym("cj")
    r = yp + 0.75 * y
    jac = ca.jacobian(r, y) + cj * ca.jacobian(r, yp)
    return DAEFunctions(1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [jac]),
                        (), (), None, "library_decay")


@pytest.fixture(scope="module")
def paths():
    """(IDA model library, ODE library), built (or found in the cache) once."""
    model = codegen.build_model_library(decay_model()).path
    ode = codegen.build_ode_library(ode_spec(assemble(slider_crank(), "index1"))).path
    return model, ode


def test_each_kind_is_loaded_once_per_path_with_its_prototypes(paths):
    model_path, ode_path = paths
    m, o = ModelLibrary.load(model_path), OdeLibrary.load(ode_path)
    assert ModelLibrary.load(model_path) is m and OdeLibrary.load(ode_path) is o
    assert ModelLibrary._cache is not OdeLibrary._cache  # one cache per kind
    assert m.lib.dc_abi_version() == library.DRIVER_ABI and o.lib.dco_abi_version() == library.ODE_DRIVER_ABI
    for lib, table in ((m.lib, MODEL_PROTOTYPES), (o.lib, ODE_PROTOTYPES)):
        for name, (restype, argtypes) in table.items():
            fn = getattr(lib, name)
            assert fn.restype is restype and fn.argtypes == list(argtypes), name
    assert m.model_info(0) == (1, 0, 0, [])


def exported(path: Path) -> dict[str, str]:
    """The symbols a shared library defines for others (``nm -D --defined-only``) and their kinds."""
    nm = shutil.which("nm")
    if nm is None:
        pytest.skip("no nm (binutils) to list a library's symbols")
    out = subprocess.run([nm, "-D", "--defined-only", str(path)], check=True, capture_output=True, text=True).stdout
    rows = [line.split()[-2:] for line in out.splitlines() if line.strip()]
    return {name: kind for kind, name in rows if not name.startswith("_")}  # not the linker's _edata, _end, ...


def test_each_library_exports_exactly_its_table(paths):
    """Every symbol a built library exports has an entry in c_api's table, and every entry is exported:
    the functions as code, the build tag as read-only data; the other driver's names not at all."""
    model_path, ode_path = paths
    for path, entries, data in ((model_path, c_api.IDA_ENTRY_POINTS, c_api.IDA_DATA),
                                (ode_path, c_api.ODE_ENTRY_POINTS, ())):
        symbols = exported(path)
        assert {name for name, kind in symbols.items() if kind == "T"} == {e.name for e in entries}, path.name
        assert {name: kind for name, kind in symbols.items() if kind != "T"} == {name: "R" for _, name in data}
    assert len(exported(model_path)) == 41 + 1 and len(exported(ode_path)) == 16


def test_other_interface_versions_are_refused(paths, monkeypatch):
    model_path, ode_path = paths
    monkeypatch.setattr(library, "ODE_DRIVER_ABI", library.ODE_DRIVER_ABI + 1)
    with pytest.raises(DaeclearError, match=rf"ODE driver ABI version {library.ODE_DRIVER_ABI - 1} != "
                                            rf"{library.ODE_DRIVER_ABI}"):
        OdeLibrary(ode_path)
    monkeypatch.setattr(library, "DRIVER_ABI", library.DRIVER_ABI + 1)
    with pytest.raises(StaleLibrary, match=rf"driver ABI version {library.DRIVER_ABI - 1} != {library.DRIVER_ABI}"):
        ModelLibrary(model_path)


def test_an_ode_library_is_no_model_library(paths):
    with pytest.raises(StaleLibrary, match="no daeclear build tag"):
        ModelLibrary(paths[1])


def test_a_bounded_memo_drops_its_oldest_entries() -> None:
    """The in-process memos of templates, seen scenes, starts and options stay bounded: the oldest
    entries go first, the newest is always kept, and a memo over its limit shrinks back to it."""
    from daeclear.engine.build import memo_put_bounded

    table: dict = {}
    for k in range(10):
        memo_put_bounded(table, k, str(k), 4)
    assert list(table) == [6, 7, 8, 9] and table[9] == "9"
    memo_put_bounded(table, 6, "again", 4)  # an old key put again: the oldest other entries make room
    assert len(table) == 4 and table[6] == "again"
    big = {k: k for k in range(10)}
    memo_put_bounded(big, "new", 0, 3)
    assert list(big) == [8, 9, "new"]
