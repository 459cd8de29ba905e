"""The SUNDIALS build the compiled backend depends on: version and index size detected in the
wheel, handed to the compiler, kept in the cache key, and checked before a library is used.

Libraries built for a faked SUNDIALS (``codegen.sundials_info`` monkeypatched) must be refused
or rebuilt, never run: a wrong ``sunindextype`` width would be silent memory corruption.
"""

from __future__ import annotations

import dataclasses
import logging
import os
import shutil

import casadi as ca
import numpy as np
import pytest

from daeclear import codegen
from daeclear.errors import DaeclearError, DaeclearWarning
from daeclear.ida_session import DAEFunctions, _CLib, open_session


@pytest.fixture(autouse=True)
def _cache_dir(tmp_path, monkeypatch):
    """Every test builds into its own empty cache."""
    monkeypatch.setenv("DAECLEAR_CACHE_DIR", str(tmp_path / "cache"))


def decay_model(k: float, name: str) -> DAEFunctions:
    """y' = -k y (a distinct k gives a distinct library)."""
    t, y, yp, cj = ca.SX.sym("t"), ca.SX.sym("y", 1), ca.SX.sym("yp", 1), ca.SX.sym("cj")
    r = yp + k * y
    jac = ca.jacobian(r, y) + cj * ca.jacobian(r, yp)
    return DAEFunctions(1, ca.Function("res", [t, y, yp], [r]), ca.Function("Jac", [t, y, yp, cj], [jac]),
                        (), (), None, name)


def runs(session, k: float) -> None:
    session.reinit(0.0, [1.0], [-k], [], [])
    assert abs(session.advance(1.0).y[0] - np.exp(-k)) < 1e-6


# --------------------------------------------------------------------------- detection


def test_detection_matches_the_wheel():
    info = codegen.sundials_info()
    _, libs = codegen.sundials_libraries()
    core = libs["sundials_core"]
    assert core.name.endswith(".so." + info.version)  # file name and SUNDIALSGetVersionNumber agree
    assert info.version_tuple[0] == codegen.SUNDIALS_MAJOR
    pxi = codegen._sksundae_dir() / "c_config.pxi"
    assert info.index_size == codegen.parse_index_size(pxi.read_text()) == codegen._probe_index_size(libs)
    assert info.has_sparse == all(name in libs for name in codegen.SPARSE_LIBS)
    major, minor, patch = info.version_tuple
    assert info.compile_flags() == [f"-DDC_SUNDIALS_MAJOR={major}", f"-DDC_SUNDIALS_MINOR={minor}",
                                    f"-DDC_SUNDIALS_PATCH={patch}", f"-DDC_INDEX_SIZE={info.index_size}",
                                    f"-DDC_HAVE_SPARSE={int(info.has_sparse)}"]


@pytest.mark.parametrize("text, bits", [
    ("cimport numpy as np\nctypedef double sunrealtype\nctypedef int sunindextype\n", 32),
    ("ctypedef  long int   sunindextype  # 64-bit build\n", 64),
    ("ctypedef int64_t sunindextype\n", 64),
    ("ctypedef int32_t sunindextype\n", 32),
    ("ctypedef double sunrealtype\n", None),
])
def test_parse_index_size(text, bits):
    assert codegen.parse_index_size(text) == bits


def test_unknown_index_type_fails_clearly():
    with pytest.raises(codegen.CompilerUnavailable, match="sunindextype as 'unsigned short'"):
        codegen.parse_index_size("ctypedef unsigned short sunindextype\n", "c_config.pxi")


def test_undeterminable_or_contradictory_build_fails_clearly(monkeypatch, tmp_path):
    codegen.sundials_libraries()  # cached with the real wheel before _sksundae_dir is faked
    detect = codegen.sundials_info.__wrapped__  # the detection itself, not its per-process cache
    # c_config.pxi and the libraries disagree
    monkeypatch.setattr(codegen, "_probe_index_size", lambda libs: 64)
    with pytest.raises(codegen.SundialsMismatch, match="declares a 32-bit sunindextype but .* use 64-bit"):
        detect()
    # no c_config.pxi: the probe decides alone ...
    monkeypatch.setattr(codegen, "_sksundae_dir", lambda: tmp_path)
    assert detect().index_size == 64
    # ... and nothing is guessed when it cannot
    monkeypatch.setattr(codegen, "_probe_index_size", lambda libs: None)
    with pytest.raises(codegen.CompilerUnavailable, match="cannot determine the SUNDIALS index size"):
        detect()
    # the file name and the library disagree on the version
    monkeypatch.setattr(codegen, "_version_from_library", lambda core: "7.8.3")
    with pytest.raises(codegen.SundialsMismatch, match="named for SUNDIALS 7.9.0 but reports version 7.8.3"):
        detect()


# --------------------------------------------------------------------------- compile time


def fake(monkeypatch, **changes) -> codegen.SundialsInfo:
    info = dataclasses.replace(codegen.sundials_info(), **changes)
    monkeypatch.setattr(codegen, "sundials_info", lambda: info)
    return info


def test_version_and_index_size_are_in_the_cache_key_and_the_library(monkeypatch):
    real = codegen.build_model_library(decay_model(1.25, "keyed"))
    assert codegen.read_build_tag(real.path) == (codegen.DRIVER_ABI, codegen.sundials_info())
    with monkeypatch.context() as m:
        info = fake(m, index_size=64)
        wide = codegen.build_model_library(decay_model(1.25, "keyed"))
    assert not wide.cache_hit and wide.key != real.key  # compiled again, kept apart
    assert codegen.read_build_tag(wide.path) == (codegen.DRIVER_ABI, info)
    with monkeypatch.context() as m:
        fake(m, version="7.9.1")
        assert codegen.build_model_library(decay_model(1.25, "keyed")).key not in (real.key, wide.key)


def test_another_major_version_is_refused_by_the_header(monkeypatch):
    fake(monkeypatch, version="8.0.0")
    with pytest.raises(DaeclearError, match="declares the SUNDIALS 7.x API"):
        open_session(decay_model(1.5, "major8"), backend="c", rtol=1e-8, atol=1e-10)


# --------------------------------------------------------------------------- load time


def test_stale_library_is_rebuilt_not_loaded(monkeypatch, caplog):
    """A library built for another SUNDIALS version and index width sits where the current
    build is expected (as after the wheel changed under a cache): it is deleted and rebuilt."""
    with monkeypatch.context() as m:
        fake(m, version="7.8.1", index_size=64)
        stale = codegen.build_model_library(decay_model(2.5, "stale"))
    real = codegen.build_model_library(decay_model(2.5, "stale"))
    assert real.path != stale.path and str(real.path) not in _CLib._cache
    shutil.copyfile(stale.path, real.path)  # the stale library under the current key,
    shutil.copyfile(stale.path.with_suffix(".sha256"), real.path.with_suffix(".sha256"))  # intact
    funcs = decay_model(2.5, "stale")
    with caplog.at_level(logging.INFO, logger="daeclear"):
        s = open_session(funcs, backend="c", rtol=1e-9, atol=1e-12)
    assert "built for SUNDIALS 7.8.1 with 64-bit indices, but the wheel has SUNDIALS" in caplog.text
    assert s.library_path == real.path and s.stats()["cache_hit"] is False  # compiled again
    assert codegen.read_build_tag(real.path) == (codegen.DRIVER_ABI, codegen.sundials_info())
    assert s._clib.build_info == codegen.sundials_info()
    runs(s, 2.5)


def test_library_without_tag_or_for_another_abi_is_rebuilt():
    funcs = decay_model(3.5, "untagged")
    build = codegen.build_model_library(funcs)
    data = build.path.read_bytes()
    build.path.write_bytes(data.replace(b"daeclear-build:abi=", b"daeclear-bUILD:abi="))
    s = open_session(funcs, backend="c", rtol=1e-9, atol=1e-12)
    assert s.stats()["cache_hit"] is False
    runs(s, 3.5)


def test_library_that_loads_another_sundials_is_refused(monkeypatch, tmp_path):
    """Compiled for 7.9.99 (consistently detected), but the SUNDIALS it loads says 7.9.x: a
    rebuild cannot help, so the compiled backend is refused with both versions named."""
    real = codegen.sundials_info().version
    fake(monkeypatch, version="7.9.99")
    cache = tmp_path / "cache"
    with pytest.raises(codegen.SundialsMismatch,
                       match=rf"built for SUNDIALS 7\.9\.99, but the SUNDIALS it loads reports version '{real}'"):
        open_session(decay_model(4.5, "elsewhere"), backend="c", rtol=1e-8, atol=1e-10)
    assert not list(cache.glob("*.so"))  # never left for the next process
    with pytest.warns(DaeclearWarning, match="7.9.99"):
        s = open_session(decay_model(4.5, "elsewhere"), backend="auto", rtol=1e-8, atol=1e-10)
    assert s.backend == "python"
    runs(s, 4.5)
    assert os.environ["DAECLEAR_CACHE_DIR"] == str(cache)
