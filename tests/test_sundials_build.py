"""The SUNDIALS build the compiled backend depends on: version and index size detected in the
wheel, equal to those of the vendored SUNDIALS headers, handed to the compiler, kept in the cache
key, and checked before a library is used.

Libraries built for a faked SUNDIALS (``sundials.sundials_info`` monkeypatched, with a copy of the
vendored headers made to describe that SUNDIALS: :func:`fake`) must be refused or rebuilt, never
run: a wrong ``sunindextype`` width would be silent memory corruption.
"""

from __future__ import annotations

import dataclasses
import hashlib
import logging
import os
import re
import shutil
import subprocess
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from daeclear.engine import codegen, sundials
from daeclear.engine.build import driver_files
from daeclear.core.errors import DaeclearWarning
from daeclear.engine.ida_session import DAEFunctions, open_session
from daeclear.engine.library import ModelLibrary


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
    pxi = sundials._sksundae_dir() / "c_config.pxi"
    assert info.index_size == codegen.parse_index_size(pxi.read_text()) == sundials._probe_index_size(libs)
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
    monkeypatch.setattr(sundials, "_probe_index_size", lambda libs: 64)
    with pytest.raises(codegen.SundialsMismatch, match="declares a 32-bit sunindextype but .* use 64-bit"):
        detect()
    # no c_config.pxi: the probe decides alone ...
    monkeypatch.setattr(sundials, "_sksundae_dir", lambda: tmp_path)
    assert detect().index_size == 64
    # ... and nothing is guessed when it cannot
    monkeypatch.setattr(sundials, "_probe_index_size", lambda libs: None)
    with pytest.raises(codegen.CompilerUnavailable, match="cannot determine the SUNDIALS index size"):
        detect()
    # the file name and the library disagree on the version
    monkeypatch.setattr(sundials, "_version_from_library", lambda core: "7.8.3")
    with pytest.raises(codegen.SundialsMismatch, match="named for SUNDIALS 7.9.0 but reports version 7.8.3"):
        detect()


# --------------------------------------------------------------------------- compile time


def headers_for(root: Path, version: str, index_size: int) -> Path:
    """A copy of the vendored SUNDIALS folder under ``root`` whose sundials_config.h describes
    another SUNDIALS build (version, index width); returns its include directory."""
    target = root / f"sundials-{version}-{index_size}"
    if not target.exists():
        shutil.copytree(codegen.SUNDIALS_INCLUDE.parent, target)
    config = target / "include" / "sundials" / "sundials_config.h"
    text = config.read_text()
    for part, value in zip(("MAJOR", "MINOR", "PATCH"), version.split(".")):
        text = re.sub(rf"(#define SUNDIALS_VERSION_{part}) \d+", rf"\g<1> {value}", text)
    text = re.sub(r"#define SUNDIALS_INT(32|64)_T 1", f"#define SUNDIALS_INT{index_size}_T 1", text)
    text = re.sub(r"#define SUNDIALS_INDEX_TYPE int(32|64)_t", f"#define SUNDIALS_INDEX_TYPE int{index_size}_t", text)
    text = re.sub(r"DC_INDEX_SIZE != (32|64)", f"DC_INDEX_SIZE != {index_size}", text)
    config.write_text(text)
    return target / "include"


def fake(monkeypatch, *, headers: bool = True, **changes) -> codegen.SundialsInfo:
    """Pretend the wheel has another SUNDIALS build; with ``headers``, daeclear also vendors the
    matching headers (a copy made by headers_for in the test's temporary directory)."""
    info = dataclasses.replace(codegen.sundials_info(), **changes)
    monkeypatch.setattr(sundials, "sundials_info", lambda: info)
    if headers:
        root = Path(os.environ["DAECLEAR_CACHE_DIR"]).parent / "headers"
        monkeypatch.setattr(sundials, "SUNDIALS_INCLUDE", headers_for(root, info.version, info.index_size))
    return info


def test_vendored_headers_are_the_wheels_sundials(tmp_path):
    """A C program compiled with the driver's include path sees the SUNDIALS version and index
    width detected in the wheel, and SUNDIALSGetVersion of the linked library says the same."""
    info = codegen.sundials_info()
    assert codegen.vendored_sundials() == (info.version, info.index_size)
    major, minor, patch = info.version_tuple
    (tmp_path / "probe.c").write_text(f"""
#include <stdio.h>
#include <string.h>
#include <idas/idas.h>
#include <sundials/sundials_version.h>
#if SUNDIALS_VERSION_MAJOR != {major} || SUNDIALS_VERSION_MINOR != {minor} || SUNDIALS_VERSION_PATCH != {patch}
#error "vendored headers are not SUNDIALS {info.version}"
#endif
_Static_assert(sizeof(sunindextype) * 8 == {info.index_size}, "index width");
_Static_assert(sizeof(sunrealtype) == sizeof(double), "precision");
int main(void) {{
  char v[32];
  if (SUNDIALSGetVersion(v, 32) != 0) return 2;
  printf("%s %s %d\\n", v, SUNDIALS_VERSION, (int)(8 * sizeof(sunindextype)));
  return strcmp(v, SUNDIALS_VERSION) != 0;
}}
""")
    _, libs = codegen.sundials_libraries()
    exe = tmp_path / "probe"
    cc = codegen.compiler_command()
    build = subprocess.run([*cc, *info.compile_flags(), f"-I{codegen.SUNDIALS_INCLUDE}", str(tmp_path / "probe.c"),
                            "-o", str(exe), str(libs["sundials_core"]), str(libs["sundials_ida"]),
                            f"-Wl,-rpath,{libs['sundials_core'].parent}"], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    out = subprocess.run([str(exe)], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.split() == [info.version, info.version, str(info.index_size)]


def test_no_hand_written_prototypes_left():
    """The driver declares nothing of SUNDIALS itself but the SuperLU_MT constructor (whose real
    header needs SuperLU_MT's own headers, which no wheel ships); sundials_min.h is gone."""
    assert not (codegen.CSRC / "sundials_min.h").exists()
    driver = "".join(path.read_text() for path in driver_files("ida_driver.c"))  # the driver and its parts
    declared = re.findall(r"^(?:SUNDIALS_EXPORT )?[A-Za-z_][\w ]*\*? ?\b((?:IDA|SUN|N_V)\w*)\(", driver, re.MULTILINE)
    assert declared == ["SUNLinSol_SuperLUMT"]


def test_vendored_files_are_the_releases_bytes():
    """Every vendored file but the two written for the wheel's build is byte for byte the
    SUNDIALS release's (SHA256SUMS, recorded from it), and every header is listed or written."""
    root = codegen.SUNDIALS_INCLUDE.parent
    sums = dict(reversed(line.split("  ", 1)) for line in (root / "SHA256SUMS").read_text().splitlines())
    for name, digest in sums.items():
        assert hashlib.sha256((root / name).read_bytes()).hexdigest() == digest, name
    headers = {p.relative_to(root).as_posix() for p in root.rglob("*.h")}
    written = {"include/sundials/sundials_config.h", "include/sundials/sundials_export.h"}
    assert headers == set(sums) - {"LICENSE", "NOTICE"} | written


def test_config_lists_only_modules_the_wheel_has():
    """sundials_config.h says which modules the wheel's SUNDIALS was built with: each has its
    library in the wheel, and each library the driver links is among them."""
    text = (codegen.SUNDIALS_INCLUDE / "sundials" / "sundials_config.h").read_text()
    define = r"^#define SUNDIALS_((?:CVODE|IDA|NVECTOR|SUNMATRIX|SUNLINSOL)\w*) 1$"
    modules = set(re.findall(define, text, re.MULTILINE))
    libdir, libs = codegen.sundials_libraries()
    names = {p.name.split("-")[0].removeprefix("libsundials_") for p in libdir.glob("libsundials_*.so*")}
    spelled = {m.lower().replace("nvector_", "nvec").replace("_", "") for m in modules}
    assert spelled == names - {"core"}
    assert {name.removeprefix("sundials_") for name in libs} - {"core"} <= spelled


def test_link_refuses_a_function_the_ida_library_lacks(tmp_path):
    """The driver gets IDA's API from IDAS' header; -z defs makes a call to an IDAS-only
    function (sensitivities) a link error instead of a crash when the library is loaded."""
    src = tmp_path / "uses_idas.c"
    src.write_text("#include <idas/idas.h>\nint f(void* m) { return IDASensToggleOff(m) + IDASetMaxOrd(m, 2); }\n")
    _, libs = codegen.sundials_libraries()
    base = [*codegen.compiler_command(), *codegen.CFLAGS, f"-I{codegen.SUNDIALS_INCLUDE}", str(src), "-o",
            str(tmp_path / "lib.so"), str(libs["sundials_ida"]), str(libs["sundials_core"])]
    failed = subprocess.run(base, capture_output=True, text=True)
    assert failed.returncode != 0 and "IDASensToggleOff" in failed.stderr
    src.write_text("#include <idas/idas.h>\nint f(void* m) { return IDASetMaxOrd(m, 2); }\n")
    assert subprocess.run(base, capture_output=True, text=True).returncode == 0


def test_header_change_rebuilds(monkeypatch, tmp_path):
    """Any byte of a vendored header is in the cache key."""
    before = codegen.build_model_library(decay_model(1.75, "headers"))
    copy = headers_for(tmp_path, codegen.sundials_info().version, codegen.sundials_info().index_size)
    monkeypatch.setattr(sundials, "SUNDIALS_INCLUDE", copy)
    same_bytes = codegen.build_model_library(decay_model(1.75, "headers"))
    assert not same_bytes.cache_hit and same_bytes.key != before.key  # other path, other command
    types = copy / "sundials" / "sundials_types.h"
    types.write_text(types.read_text() + "\n/* edited */\n")
    edited = codegen.build_model_library(decay_model(1.75, "headers"))
    assert not edited.cache_hit and edited.key not in (before.key, same_bytes.key)


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
    """A wheel with another SUNDIALS than the vendored headers: refused before compiling, with
    both versions named; and if that check is bypassed, the header's #error stops the build."""
    fake(monkeypatch, version="8.0.0", headers=False)
    with pytest.raises(codegen.SundialsMismatch,
                       match=r"SUNDIALS 8\.0\.0 with a 32-bit .* vendored SUNDIALS headers .* are version 7\.9\.0"):
        open_session(decay_model(1.5, "major8"), backend="c", rtol=1e-8, atol=1e-10)
    monkeypatch.setattr(sundials, "check_vendored", lambda info: None)
    with pytest.raises(codegen.CompileError, match=r"#error .*are not version 7\.9\.0, the version of the vendored"):
        open_session(decay_model(1.5, "major8"), backend="c", rtol=1e-8, atol=1e-10)


def test_mismatched_index_size_stops_the_build(monkeypatch):
    fake(monkeypatch, index_size=64, headers=False)
    with pytest.raises(codegen.SundialsMismatch, match="64-bit sunindextype, but .* 32-bit sunindextype"):
        codegen.build_model_library(decay_model(1.5, "wide"))
    monkeypatch.setattr(sundials, "check_vendored", lambda info: None)
    with pytest.raises(codegen.CompileError, match="#error .*do not use the 32-bit sunindextype"):
        codegen.build_model_library(decay_model(1.5, "wide"))


# --------------------------------------------------------------------------- load time


def test_stale_library_is_rebuilt_not_loaded(monkeypatch, caplog):
    """A library built for another SUNDIALS version and index width sits where the current
    build is expected (as after the wheel changed under a cache): it is deleted and rebuilt."""
    with monkeypatch.context() as m:
        fake(m, version="7.8.1", index_size=64)
        stale = codegen.build_model_library(decay_model(2.5, "stale"))
    real = codegen.build_model_library(decay_model(2.5, "stale"))
    assert real.path != stale.path and str(real.path) not in ModelLibrary._cache
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
